"""Problem statement: normalization, immutability, and errors that name the argument."""
from __future__ import annotations

import dataclasses
import math

import casadi as ca
import numpy as np
import pytest

from appdyn.dynamics.rigid_body import rigid_body
from appdyn.ocp import Constraint, Problem, solve

from .reference import double_integrator, min_energy


def _di(**kw):
    base = dict(T=1.0, x_initial=[0.0, 0.0], x_final=[1.0, 0.0], lagrange=lambda x, u, p: 0.5 * u ** 2)
    base.update(kw)
    return Problem(double_integrator(), **base)


# ------------------------------------------------------------------- normalization
def test_normalized_fields_and_immutability():
    pr = _di(x_initial={"x": 0.0, "v": 0.0}, x_final={"x": 1.0}, x_bounds={"v": (None, 2.0)},
             u_bounds=([-3.0], [3.0]), T=(0.5, 4.0))
    assert np.array_equal(pr.x_initial, [0.0, 0.0])
    assert pr.x_final[0] == 1.0 and math.isnan(pr.x_final[1])
    assert np.array_equal(pr.x_bounds, [[-np.inf, -np.inf], [np.inf, 2.0]])
    assert np.array_equal(pr.u_bounds, [[-3.0], [3.0]])
    assert pr.free_time and pr.T_bounds == (0.5, 4.0)
    assert isinstance(pr.lagrange, ca.Function) and pr.lagrange.name_in() == ["x", "u", "p"]
    with pytest.raises(dataclasses.FrozenInstanceError):
        pr.T = 2.0
    with pytest.raises(ValueError):
        pr.x_bounds[0, 0] = 1.0  # read-only arrays
    assert pr.replace(T=2.0).T == 2.0 and pr.T == (0.5, 4.0)


def test_array_boundary_values_with_none_and_nan_mark_free_components():
    pr = _di(x_final=[1.0, None])
    assert math.isnan(pr.x_final[1])
    pr = _di(x_final=np.array([1.0, np.nan]))
    assert math.isnan(pr.x_final[1])


def test_parameters_fixed_unless_bounded():
    x, u, p = ca.SX.sym("x", 2), ca.SX.sym("u"), ca.SX.sym("p", 2)
    from appdyn.dynamics.model import Model
    m = Model(ca.Function("f", [x, u, p], [ca.vertcat(x[1], p[0] * u + p[1])], ["x", "u", "p"], ["xdot"]),
              ("x", "v"), ("u",), ("k", "g"), p_default=[1.0, 0.0])
    pr = Problem(m, T=1.0, p={"g": -0.5}, p_bounds={"k": (0.5, 2.0)})
    assert np.array_equal(pr.p, [1.0, -0.5])
    assert np.array_equal(pr.free_params, [0])
    assert np.array_equal(pr.p_bounds, [[0.5, -0.5], [2.0, -0.5]])
    # no p_bounds: every parameter fixed (it once freed them all)
    pr = Problem(m, T=1.0, p={"g": -0.5})
    assert pr.free_params.size == 0
    assert np.array_equal(pr.p_bounds, [[1.0, -0.5], [1.0, -0.5]])


def test_q_final_and_initial_quaternion_are_normalized():
    q = np.array([0.0, 0.0, math.sin(0.5), math.cos(0.5)])
    pr = Problem(rigid_body(np.eye(3)), T=1.0, x_initial=[0, 0, 0, 1 + 5e-7, 0, 0, 0],
                 q_final=q * (1 + 5e-7))
    assert np.linalg.norm(pr.q_final) == pytest.approx(1.0, abs=1e-15)
    assert np.linalg.norm(pr.x_initial[:4]) == pytest.approx(1.0, abs=1e-15)
    assert not pr.quaternion_norm_at_t0  # the initial quaternion is given
    free = Problem(rigid_body(np.eye(3)), T=1.0, q_final=q)
    assert free.quaternion_norm_at_t0


def test_functions_accepted_as_casadi_functions():
    x, u, p, T = ca.SX.sym("x", 2), ca.SX.sym("u"), ca.SX.sym("p", 0), ca.SX.sym("T")
    L = ca.Function("L", [x, u, p], [0.5 * u ** 2])
    phi = ca.Function("phi", [x, p, T], [T])
    g = ca.Function("g", [x, u, p], [ca.vertcat(x[0] - 2, u - 10)])
    pr = _di(lagrange=L, mayer=phi, path=Constraint(g, lower=-np.inf, upper=0.0, name="box"))
    assert pr.path[0].size == 2 and pr.path[0].name == "box"
    assert pr.mayer.name_in() == ["xf", "p", "T"]


# ------------------------------------------------------------------------ errors
def _fun(*sizes):
    syms = [ca.SX.sym(f"a{i}", n) for i, n in enumerate(sizes)]
    return ca.Function("fun", syms, [ca.sum1(syms[0])])


BAD_PROBLEMS = [
    (dict(T=-1.0), "`T`"),
    (dict(T=(2.0, 1.0)), "`T`"),
    (dict(T=(1.0, 2.0, 3.0)), "`T`"),
    (dict(T="long"), "`T`"),
    (dict(x_initial=[0.0]), "`x_initial`"),
    (dict(x_initial={"z": 1.0}), "`x_initial`"),
    (dict(x_final=[1.0, np.inf]), "`x_final`"),
    (dict(x_bounds={"x": (1.0, 0.0)}), "`x_bounds`"),
    (dict(x_bounds={"x": 3.0}), "`x_bounds`"),
    (dict(x_bounds={"x": (None, 0.5)}), "`x_final`"),  # x_final = 1 outside
    (dict(u_bounds=([0.0, 1.0], [1.0, 2.0])), "`u_bounds"),
    (dict(p_bounds={"k": (0.0, 1.0)}), "`p_bounds`"),
    (dict(lagrange=lambda x, u, p: u * ca.DM([1, 1])), "`lagrange`"),
    (dict(lagrange=_fun(3)), "`lagrange`"),
    (dict(mayer=lambda xf, p: 1.0), "`mayer`"),
    (dict(path=lambda x, u, p: x[0] + u, ), None),  # fine: g <= 0
    (dict(path=Constraint(lambda x, u, p: x[0], lower=-np.inf, upper=np.inf)), "`path`"),
    (dict(path=Constraint(lambda x, u, p: x[0], lower=1.0, upper=0.0)), "`path`"),
    (dict(path=Constraint(lambda x, u, p: x[0], scale=-1.0)), "`path.scale`"),
    (dict(boundary=_fun(2, 3)), "`boundary`"),
    (dict(lagrange="u^2"), "`lagrange`"),
    (dict(q_final=[0, 0, 0, 1]), "`q_final`"),
    (dict(t0=math.inf), "`t0`"),
]


@pytest.mark.parametrize("kw, name", BAD_PROBLEMS)
def test_bad_problem_raises_naming_argument(kw, name):
    if name is None:
        _di(**kw)
        return
    with pytest.raises(ValueError, match=name.replace("(", r"\(").replace(".", r"\.")):
        _di(**kw)


def test_model_must_be_a_model():
    with pytest.raises(TypeError, match="`model`"):
        Problem("double integrator", T=1.0)


@pytest.mark.parametrize("kw, name", [
    (dict(q_final=[0, 0, 0.5, 0.5]), "`q_final`"),
    (dict(x_initial=[0, 0, 0, 0.9, 0, 0, 0]), "`x_initial`"),
    (dict(x_final=[0, 0, 0, 1, 0, 0, 0]), "`x_final`"),
    (dict(q_final_tol=0.1), "`q_final_tol`"),
    (dict(q_final=[0, 0, 0, 1], q_final_tol=-0.1), "`q_final_tol`"),
    (dict(q_final=[0, 0, 0, 1], q_final_tol=4.0), "`q_final_tol`"),
])
def test_attitude_inputs(kw, name):
    with pytest.raises(ValueError, match=name):
        Problem(rigid_body(np.eye(3)), T=1.0, **kw)


@pytest.mark.parametrize("kw, name, exc", [
    (dict(transcription="euler"), "`transcription`", ValueError),
    (dict(N=0), "`N`", ValueError),
    (dict(N=2.5), "`N`", ValueError),
    (dict(transcription="trapezoid", degree=3), "`degree`", ValueError),
    (dict(degree=0), "`degree`", ValueError),
    (dict(mesh=[0.0, 0.6, 0.5, 1.0]), "`mesh`", ValueError),
    (dict(mesh=[0.0, 0.5, 0.9]), "`mesh`", ValueError),
    (dict(mesh=[0.0, 0.5, 1.0], N=3), "`N`", ValueError),
    (dict(guess=[1, 2, 3]), "`guess`", ValueError),
    (dict(guess={"y": 1}), "`guess`", ValueError),
    (dict(guess={"x": np.zeros((3, 4))}), "`guess\\['x'\\]`", ValueError),
    (dict(guess={"T": 2.0}), "`guess\\['T'\\]`", ValueError),  # T is fixed at 1
    (dict(scale={"q": 1.0}), "`scale`", ValueError),
    (dict(scale={"x": 0.0}), "`scale`", ValueError),
    (dict(ipopt_options=["tol"]), "`ipopt_options`", TypeError),  # not a mapping: a type
    (dict(verbose="loud"), "`verbose`", ValueError),
])
def test_bad_solve_arguments_raise_naming_argument(kw, name, exc):
    problem, _ = min_energy()
    with pytest.raises(exc, match=name):
        solve(problem, **{"verbose": False, **kw})


def test_solve_needs_a_problem():
    with pytest.raises(TypeError, match="`problem`"):
        solve("problem")


def test_several_path_constraints_are_accepted():
    """A sequence of constraints gets per-item labels; they must be valid Function names."""
    import casadi as ca

    from appdyn.dynamics import rigid_body
    from appdyn.ocp import Problem

    x, u, p = ca.SX.sym("x", 7), ca.SX.sym("u", 3), ca.SX.sym("p", 0)
    g1 = ca.Function("g1", [x, u, p], [ca.sumsqr(u) - 1])
    prob = Problem(rigid_body([1.0, 1.0, 1.0]), T=1.0, x_initial=[0, 0, 0, 1, 0, 0, 0],
                   path=(g1, lambda x, u, p: x[4] - 1.0))
    assert len(prob.path) == 2
