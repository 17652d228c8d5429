"""Multi-scenario problems (`ocp.scenarios`): K trajectories sharing the parameters."""
import casadi as ca
import control
import numpy as np
import pytest

from appdyn import ocp
from appdyn.dynamics import Model

from .reference import double_integrator


def _loop(A, B):
    """``x' = (A - B k^T) x``, the gains ``k`` as parameters (single input)."""
    n = A.shape[0]
    x, k = ca.SX.sym("x", n), ca.SX.sym("k", n)
    xdot = ca.mtimes(ca.DM(A), x) - ca.mtimes(ca.DM(B), ca.mtimes(k.T, x))
    f = ca.Function("loop", [x, ca.SX.sym("u", 0), k], [xdot], ["x", "u", "p"], ["xdot"])
    return Model(f, tuple(f"x{i}" for i in range(n)), (), tuple(f"k{i}" for i in range(n)),
                 p_default=np.ones(n))


def test_stack_is_k_copies_with_shared_parameters():
    m = double_integrator()
    big = ocp.stack(m, 3)
    assert big.states == ("x[0]", "v[0]", "x[1]", "v[1]", "x[2]", "v[2]")
    assert big.controls == ("u[0]", "u[1]", "u[2]") and big.params == m.params
    X = np.random.default_rng(1).normal(size=(2, 3))
    U = np.array([[0.5, -1.0, 2.0]])
    got = np.asarray(big.f(X.reshape(-1, order="F"), U.reshape(-1), [])).ravel()
    want = np.concatenate([np.asarray(m.f(X[:, k], U[:, k], [])).ravel() for k in range(3)])
    np.testing.assert_array_equal(got, want)
    np.testing.assert_array_equal(ocp.unstack(X.reshape(-1, 1, order="F"), 3)[:, 0, :], X)


def test_shared_gains_of_several_initial_conditions_are_the_lqr_gains():
    """Double integrator, Q = I, R = 1: minimizing the summed cost of u = -k.x from two
    spanning initial states over a horizon 26x the slowest closed-loop time constant gives
    ``control.lqr`` to the collocation error (1.9e-5 at N = 80)."""
    A, B = np.array([[0.0, 1.0], [0.0, 0.0]]), np.array([[0.0], [1.0]])
    K, _, _ = control.lqr(A, B, np.eye(2), np.eye(1))
    cost = lambda x, u, p: ca.sumsqr(x) + ca.mtimes(p.T, x) ** 2  # noqa: E731
    pr = ocp.scenario_problem(_loop(A, B), np.eye(2), T=30.0, lagrange=cost,
                              p_bounds={"k0": (0, 50), "k1": (0, 50)})
    sol = ocp.solve(pr, N=80, ipopt_options={"tol": 1e-12})
    assert sol.success
    np.testing.assert_allclose(sol.p, K.ravel(), rtol=1e-4)


@pytest.mark.slow
def test_path_constraints_hold_in_every_scenario_and_weights_weigh():
    """A bound on the feedback torque binds only for the larger initial state; weighting
    that scenario by 0 removes its influence (the gains of the other one alone)."""
    A, B = np.array([[0.0, 1.0], [0.0, 0.0]]), np.array([[0.0], [1.0]])
    cost = lambda x, u, p: ca.sumsqr(x) + ca.mtimes(p.T, x) ** 2  # noqa: E731
    limit = ocp.Constraint(lambda x, u, p: ca.mtimes(p.T, x), -1.0, 1.0)
    X0 = np.array([[0.2, 2.0], [0.0, 0.0]])
    pr = ocp.scenario_problem(_loop(A, B), X0, T=20.0, lagrange=cost, path=[limit],
                              p_bounds={"k0": (0, 50), "k1": (0, 50)})
    exact = {"bound_relax_factor": 0.0, "tol": 1e-10}  # bounds as given (IPOPT relaxes 1e-8)
    sol = ocp.solve(pr, N=60, ipopt_options=exact)
    assert sol.success
    x = ocp.unstack(sol.x, 2)
    u = np.einsum("i,ijk->jk", sol.p, x)  # k . x per node and scenario
    assert np.max(np.abs(u)) <= 1.0 + 1e-9  # at every node, t0 included (closed loop)
    assert np.max(np.abs(u[:, 1])) > 0.99  # binding in the large scenario
    alone = ocp.solve(ocp.scenario_problem(_loop(A, B), X0, T=20.0, lagrange=cost, weights=[1, 0],
                                           p_bounds={"k0": (0, 50), "k1": (0, 50)}), N=60)
    single = ocp.solve(ocp.scenario_problem(_loop(A, B), X0[:, :1], T=20.0, lagrange=cost,
                                            p_bounds={"k0": (0, 50), "k1": (0, 50)}), N=60)
    assert alone.success and single.success
    assert alone.cost == pytest.approx(single.cost, rel=1e-8)


@pytest.mark.parametrize("kwargs, match", [
    ({"x_initial": np.ones((3, 2))}, "x_initial"),
    ({"x_initial": [[np.nan, 0], [0, 0]]}, "x_initial"),
    ({"weights": [1, -1]}, "weights"),
    ({"x_final": np.zeros((2, 3))}, "x_final"),
])
def test_bad_scenario_arguments_name_the_argument(kwargs, match):
    args = {"x_initial": np.eye(2), "T": 1.0, **kwargs}
    with pytest.raises(ValueError, match=match):
        ocp.scenario_problem(double_integrator(), **args)
    with pytest.raises(ValueError, match="K"):
        ocp.stack(double_integrator(), 0)
    with pytest.raises(TypeError, match="model"):
        ocp.stack("model", 2)
