"""closed_loop against independent truths: the same law applied from Python by scipy's DOP853,
and the matrix exponential of A - B K for a linear loop."""
import doctest

import casadi as ca
import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.linalg import expm

import appdyn.dynamics.feedback as closed_loop_module
from appdyn.dynamics import Model, rigid_body, simulate
from appdyn.dynamics.attitude import quat_conj, quat_mul, rotation_angle
from appdyn.dynamics import closed_loop
from appdyn.dynamics.momentum.wheels import wheel_spacecraft

INERTIA = np.array([[12.0, 0.3, -0.2], [0.3, 10.0, 0.1], [-0.2, 0.1, 8.0]])
TARGET = np.array([0.3, -0.4, 0.2, 0.0])
TARGET[3] = np.sqrt(1 - TARGET[:3] @ TARGET[:3])
KP, KD = 4.0, 6.0


def pd_law_casadi():
    """L = -kp q4e e - kd w, with the error quaternion q_e = q (x) q_target^-1 = [e, q4e]."""
    x = ca.SX.sym("x", 7)
    qe = quat_mul(x[0:4], ca.DM(quat_conj(TARGET)))
    return ca.Function("pd", [x], [-KP * qe[3] * qe[0:3] - KD * x[4:7]], ["x"], ["L"])


def pd_law_numpy(x):
    qe = quat_mul(x[:4], quat_conj(TARGET))
    return -KP * qe[3] * qe[:3] - KD * x[4:7]


def linear_model(A, B):
    n, m = B.shape
    x, u, p = ca.SX.sym("x", n), ca.SX.sym("u", m), ca.SX.sym("p", 0)
    f = ca.Function("linear", [x, u, p], [ca.mtimes(ca.DM(A), x) + ca.mtimes(ca.DM(B), u)],
                    ["x", "u", "p"], ["xdot"])
    return Model(f, tuple(f"x{i + 1}" for i in range(n)), tuple(f"u{i + 1}" for i in range(m)),
                 units={"x1": "m"}, name="linear")


def random_system(seed=0, n=4, m=2):
    rng = np.random.default_rng(seed)
    return rng.normal(size=(n, n)), rng.normal(size=(n, m)), rng.normal(size=(m, n))


# ------------------------------------------------------------------------------ truths
@pytest.mark.slow
def test_pd_attitude_loop_matches_the_law_applied_from_python():
    model = rigid_body(INERTIA)
    loop = closed_loop(model, pd_law_casadi())
    x0 = np.r_[0.0, 0.0, 0.0, 1.0, 0.1, -0.05, 0.02]
    t = np.linspace(0.0, 60.0, 121)
    res = simulate(loop, x0, t, method="rk8", steps=20)
    assert res.success and res.compiled
    ref = solve_ivp(lambda _, x: model.rhs(x, pd_law_numpy(x)), (t[0], t[-1]), x0, t_eval=t,
                    method="DOP853", rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(res.x, ref.y, atol=1e-9)
    # and the law does its job: the body comes to rest at the target attitude
    qe = quat_mul(res.x[:4, -1], quat_conj(TARGET))
    assert rotation_angle(qe) < 1e-6 and np.linalg.norm(res.x[4:, -1]) < 1e-6


def test_linear_loop_is_the_matrix_exponential_of_a_minus_bk():
    A, B, K = random_system()
    x = ca.SX.sym("x", 4)
    law = ca.Function("lqr_like", [x], [-ca.mtimes(ca.DM(K), x)], ["x"], ["u"])
    loop = closed_loop(linear_model(A, B), law)
    x0 = np.array([1.0, -0.5, 0.3, 0.2])
    t = np.linspace(0.0, 2.0, 11)
    res = simulate(loop, x0, t, method="rk8", steps=50)
    exact = np.stack([expm((A - B @ K) * tk) @ x0 for tk in t], axis=1)
    np.testing.assert_allclose(res.x, exact, rtol=1e-10, atol=1e-10 * np.max(np.abs(exact)))


def test_reference_and_parameter_inputs():
    """u = -K x + N r (r: a new control); a second law reads the model parameter k of
    x'' = -k x + u through its input named 'p'."""
    A, B, K = random_system(1)
    N = np.array([[1.0, 0.5], [0.0, 2.0]])
    x, r = ca.SX.sym("x", 4), ca.SX.sym("r", 2)
    law = ca.Function("tracking", [x, r], [-ca.mtimes(ca.DM(K), x) + ca.mtimes(ca.DM(N), r)],
                      ["x", "r"], ["u"])
    loop = closed_loop(linear_model(A, B), law, units={"r1": "m", "r2": "m"})
    assert loop.controls == ("r1", "r2") and loop.units["r1"] == "m"
    x0, r0 = np.array([0.2, 0.0, -0.1, 0.4]), np.array([0.3, -0.2])
    t = np.linspace(0.0, 1.5, 7)
    res = simulate(loop, x0, t, u=r0, method="rk8", steps=50)
    M = A - B @ K
    forced = np.linalg.solve(M, B @ N @ r0)
    exact = np.stack([expm(M * tk) @ (x0 + forced) - forced for tk in t], axis=1)
    np.testing.assert_allclose(res.x, exact, rtol=1e-10, atol=1e-10 * np.max(np.abs(exact)))

    xs, us, ps = ca.SX.sym("x", 2), ca.SX.sym("u", 1), ca.SX.sym("p", 1)
    f = ca.Function("oscillator", [xs, us, ps], [ca.vertcat(xs[1], -ps[0] * xs[0] + us[0])],
                    ["x", "u", "p"], ["xdot"])
    oscillator = Model(f, ("y", "ydot"), ("force",), ("k",), p_default=[4.0])
    damping = ca.Function("damp", [xs, ps], [-ps[0] * xs[1]], ["x", "p"], ["u"])  # c = k
    damped = closed_loop(oscillator, damping)
    assert damped.params == ("k",) and damped.controls == ()
    for k in (4.0, 9.0):
        res = simulate(damped, [1.0, 0.0], t, p=[k], method="rk8", steps=50)
        exact = np.stack([expm(np.array([[0, 1], [-k, -k]]) * tk) @ [1.0, 0.0] for tk in t], 1)
        np.testing.assert_allclose(res.x, exact, atol=1e-11)


def test_keeps_model_metadata_and_is_cached():
    model = wheel_spacecraft(INERTIA, np.eye(3), 0.05)
    x = ca.SX.sym("x", model.nx)
    law = ca.Function("spin_down", [x], [-0.1 * x[7:10]], ["x"], ["tau"])
    loop = closed_loop(model, law)
    assert loop.states == model.states and loop.params == model.params
    assert loop.controls == () and loop.attitude == model.attitude
    assert loop.invariants == model.invariants
    assert loop.name == "wheel_spacecraft+spin_down"
    assert loop.units["W1"] == "rad/s" and "tau1" not in loop.units
    assert closed_loop(model, law) is loop
    assert closed_loop(model, law, units={}) is loop
    # the wheels spin down against the hub; total inertial momentum stays put
    res = simulate(loop, np.r_[0, 0, 0, 1, 0.1, 0.0, 0.0, 20.0, -10.0, 5.0],
                   np.linspace(0.0, 50.0, 51), method="rk8", steps=10,
                   invariants=["momentum_inertial"])
    H = res.invariants["momentum_inertial"]
    assert np.max(np.abs(H - H[:, :1])) < 1e-12 * np.linalg.norm(H[:, 0])
    assert np.max(np.abs(res.x[7:, -1])) < 0.2 * 20.0


# ------------------------------------------------------------------------------ bad inputs
def test_bad_controllers_name_the_argument():
    model = rigid_body(INERTIA)
    x, y = ca.SX.sym("x", 7), ca.SX.sym("y", 6)
    with pytest.raises(TypeError, match="`controller` must be a casadi.Function"):
        closed_loop(model, pd_law_numpy)
    with pytest.raises(TypeError, match="`model`"):
        closed_loop("rigid body", pd_law_casadi())
    cases = [
        (ca.Function("short", [y], [y[0:3]]), r"input 0 \('i0'\) of `controller` is the state"),
        (ca.Function("wide", [x], [x[0:4]]), "output of `controller`.*3 elements"),
        (ca.Function("two", [x], [x[0:3], x[3:6]]), "exactly one output"),
        (ca.Function("params", [x, ca.SX.sym("p", 2)], [x[0:3]], ["x", "p"], ["u"]),
         r"\('p'\) of `controller` is the parameters p and must have 0 elements"),
        (ca.Function("none", [], [ca.DM.zeros(3)]), "at least one input"),
    ]
    for law, match in cases:
        with pytest.raises(ValueError, match=match):
            closed_loop(model, law)
    with pytest.raises(ValueError, match="`units` names"):
        closed_loop(model, pd_law_casadi(), units={"w1": "rad/s"})


def test_docstring_examples():
    result = doctest.testmod(closed_loop_module,
                             optionflags=doctest.NORMALIZE_WHITESPACE | doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0
