"""Cost and constraint functions that take the model's states, controls and parameters by
name (`ocp.Problem`, Notes): the same problems as their positional forms, checked against
closed-form optima and against the positional Functions themselves."""
from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest

from appdyn.dynamics.model import Model
from appdyn.ocp import Constraint, Problem, solve

from .reference import STRICT, bang_bang, bryson_denham, double_integrator, static_parameter

RNG = np.random.default_rng(11)


def _same(a: ca.Function, b: ca.Function, n: int = 10):
    """Two Functions of the same inputs agree at random points (a second formulation)."""
    assert a.name_in() == b.name_in() and a.size_out(0) == b.size_out(0)
    for _ in range(n):
        args = [RNG.normal(size=a.size_in(i)) for i in range(a.n_in())]
        np.testing.assert_allclose(np.asarray(a(*args)), np.asarray(b(*args)), rtol=1e-14,
                                   atol=1e-14)


def _di(**kw):
    base = dict(T=1.0, x_initial=[0.0, 0.0], x_final=[1.0, 0.0])
    base.update(kw)
    return Problem(double_integrator(), **base)


# ------------------------------------------------------------------ equivalence
def test_named_lagrange_is_the_positional_one_and_solves_to_bryson_ho():
    """min int u^2/2, rest to rest over 1 in T = 1: J = 6 (Bryson & Ho 1975)."""
    named = _di(lagrange=lambda u: 0.5 * u**2)
    positional = _di(lagrange=lambda x, u, p: 0.5 * u**2)
    assert named.lagrange.name_in() == ["x", "u", "p"] and named.lagrange.name_out() == ["L"]
    _same(named.lagrange, positional.lagrange)
    sol = solve(named, N=10, ipopt_options=STRICT)
    assert sol.success and sol.cost == pytest.approx(6.0, abs=1e-8)


def test_named_mayer_minimum_time_is_bang_bang():
    """|u| <= 1, rest to rest over 1: T* = 2 (Bryson & Ho 1975)."""
    base, truth = bang_bang()
    for mayer in (lambda T: T, lambda T, x_f: T + 0.0 * x_f):
        prob = base.replace(mayer=mayer)
        _same(prob.mayer, base.mayer)
        sol = solve(prob, N=20, control="constant")  # bang-bang
        assert sol.success and sol.T == pytest.approx(truth["T"], abs=1e-6)


def test_mayer_reads_final_states_with_or_without_suffix():
    a = _di(mayer=lambda x, v: x + 2 * v)
    b = _di(mayer=lambda x_f, v_f: x_f + 2 * v_f)
    c = _di(mayer=lambda xf, p, T: xf[0] + 2 * xf[1])
    _same(a.mayer, c.mayer)
    _same(b.mayer, c.mayer)


def test_named_path_constraint_is_bryson_denham():
    """x <= l with l = 1/9: J = 4 / (9 l) = 4 (Bryson, Denham & Dreyfus 1963)."""
    base, truth = bryson_denham()
    prob = base.replace(path=lambda x: x - truth["l"])
    _same(prob.path[0].fun, base.path[0].fun)
    sol = solve(prob, N=40, bound_tol=1e-5)
    assert sol.success and sol.cost == pytest.approx(truth["J"], rel=2e-3)
    # the dense position crosses l between the collocation points (6.4e-6 of its scale at
    # N = 40): checked on the path row as on the same bound stated as a state bound
    as_bound = solve(bryson_denham(as_bound=True)[0], N=40, bound_tol=1e-5)
    assert sol.bound_violation.kind == "path" and sol.bound_violation.by_name["path"] > 1e-6
    assert sol.bound_violation.by_name["path"] == pytest.approx(
        as_bound.bound_violation.by_name["x"], rel=1e-6)
    assert not solve(prob, N=40, backoff=False).success  # beyond the default 1e-6
    backed = solve(prob, N=40)  # x <= l moved in by twice the overshoot: within it
    assert backed.success and backed.bound_violation.max == 0.0
    assert backed.backoff["margins"]["path"][1] > 0 and backed.cost > sol.cost


def test_named_boundary_constraints_replace_the_boundary_values():
    """The final state given as boundary rows ``x_f = 1, v_f = 0`` (and the initial one as
    ``x_0 = v_0 = 0``) is the same problem: J = 6."""
    prob = Problem(double_integrator(), T=1.0, lagrange=lambda u: 0.5 * u**2,
                   boundary=[lambda x_0, v_0: [x_0, v_0],
                             Constraint(lambda x_f, v_f: ca.vertcat(x_f, v_f), [1, 0], [1, 0])])
    ref = Problem(double_integrator(), T=1.0, lagrange=lambda u: 0.5 * u**2,
                  boundary=[lambda x0, xf, p: x0,
                            Constraint(lambda x0, xf, p: xf, [1, 0], [1, 0])])
    for a, b in zip(prob.boundary, ref.boundary):
        _same(a.fun, b.fun)
        assert a.size == 2
    sol = solve(prob, N=10, ipopt_options=STRICT)
    assert sol.success and sol.cost == pytest.approx(6.0, abs=1e-8)
    np.testing.assert_allclose(sol.x[:, -1], [1.0, 0.0], atol=1e-9)


def test_named_parameters_in_cost_and_constraints():
    """Gain k as a free parameter: J = 6/k^2 + 3k^2/2 is least at k = sqrt(2), J = 6."""
    base, truth = static_parameter()
    prob = base.replace(lagrange=lambda u: 0.5 * u**2, mayer=lambda k: 1.5 * k**2)
    _same(prob.mayer, base.mayer)
    sol = solve(prob, N=10, ipopt_options=STRICT)
    assert sol.success and sol.cost == pytest.approx(truth["J"], abs=1e-7)
    assert sol.p[0] == pytest.approx(truth["k"], abs=1e-6)
    # a parameter by name in a path constraint: u k <= 100 (inactive)
    again = prob.replace(path=Constraint(lambda u, k: u * k, -100, 100))
    _same(again.path[0].fun, prob.replace(
        path=Constraint(lambda x, u, p: u * p, -100, 100)).path[0].fun)


def test_a_named_path_list_is_stacked_into_rows():
    prob = _di(lagrange=lambda u: 0.5 * u**2, path=Constraint(lambda x, v, u: [x, v, u], -9, 9))
    ref = _di(path=Constraint(lambda x, u, p: ca.vertcat(x, u), -9, 9))
    assert prob.path[0].size == 3
    _same(prob.path[0].fun, ref.path[0].fun)


def test_constant_running_cost_is_minimum_time():
    base, truth = bang_bang()
    prob = base.replace(mayer=None, lagrange=lambda: 1.0)
    sol = solve(prob, N=20, control="constant")  # bang-bang
    assert sol.success and sol.T == pytest.approx(truth["T"], abs=1e-6)


# ------------------------------------------------------ positional forms unchanged
@pytest.mark.parametrize("kw", [
    dict(lagrange=lambda x, u, p: 0.5 * u**2),
    dict(lagrange=lambda a, b, c: 0.5 * b**2),          # any names, three parameters
    dict(lagrange=lambda x, u, p=None: 0.5 * u**2),     # a default does not matter
    dict(lagrange=lambda *args: 0.5 * args[1]**2),
    dict(mayer=lambda xf_, p_, T: xf_[0]),
    dict(path=lambda x, u, pp: x[1] - 5),               # 'x', 'u' are model names too
    dict(boundary=lambda x0, xf, p: xf[0] - 1),
])
def test_positional_forms_keep_their_meaning(kw):
    """A callable that is not all names, or is exactly the positional convention, is called
    with the vectors (x, u, p), (xf, p, T) or (x0, xf, p)."""
    prob = _di(**kw)
    key = next(iter(kw))
    fun = getattr(prob, key)
    fun = fun[0].fun if isinstance(fun, tuple) else fun
    x = np.array([0.3, -0.7])
    if key == "lagrange":
        assert float(fun(x, 2.0, [])) == pytest.approx(2.0)
    elif key == "mayer":
        assert float(fun(x, [], 3.0)) == pytest.approx(0.3)
    elif key == "path":
        assert float(fun(x, 2.0, [])) == pytest.approx(-5.7)
    else:
        assert float(fun([0, 0], x, [])) == pytest.approx(-0.7)


def test_casadi_functions_are_positional():
    x, u, p = ca.SX.sym("v", 2), ca.SX.sym("w"), ca.SX.sym("q", 0)
    f = ca.Function("L", [x, u, p], [u**2])
    assert float(_di(lagrange=f).lagrange([1, 2], 3.0, [])) == 9.0


# ------------------------------------------------------------------------ errors
@pytest.mark.parametrize("kw, match", [
    (dict(lagrange=lambda w: w),
     r"`lagrange`: argument 'w'.*states \['x', 'v'\].*controls \['u'\]"),
    (dict(lagrange=lambda u, speed: u), r"`lagrange`: argument 'speed'"),
    (dict(mayer=lambda u: u), r"`mayer`: argument 'u'.*'T'"),
    (dict(mayer=lambda xf, p: 1.0), r"`mayer`: argument 'xf'"),
    (dict(path=lambda v_f: v_f), r"`path`: argument 'v_f'"),
    (dict(path=[lambda x, u, p: x[0], lambda y: y]), r"`path\[1\]`: argument 'y'"),
    (dict(path=Constraint(lambda x, vv: x, -1, 1)), r"`path`: argument 'vv'"),
    (dict(boundary=lambda v: v), r"`boundary`: argument 'v' is ambiguous.*'v_0' or 'v_f'"),
    (dict(boundary=lambda x_0, u_f: x_0), r"`boundary`: argument 'u_f'.*\['x_0', 'v_0'\]"),
])
def test_bad_names_raise_naming_the_argument(kw, match):
    with pytest.raises(ValueError, match=match):
        _di(**kw)


def test_a_name_for_two_inputs_is_ambiguous():
    """A model with a state named 'T': in `mayer`, 'T' is both that state's final value
    and the horizon; 'T_f' is the state alone."""
    T, q = ca.SX.sym("T"), ca.SX.sym("q")
    model = Model.from_expressions({"T": T}, {"T": -T + q}, {"q": q})
    with pytest.raises(ValueError, match=r"`mayer`: argument 'T' is ambiguous"):
        Problem(model, T=(0.1, 2.0), x_initial=[1.0], mayer=lambda T: T)
    prob = Problem(model, T=(0.1, 2.0), x_initial=[1.0], mayer=lambda T_f: T_f**2)
    assert float(prob.mayer([3.0], [], 0.5)) == 9.0
    # the state 'T' by name in a running cost is the state
    prob = Problem(model, T=1.0, x_initial=[1.0], lagrange=lambda T, q: T * q)
    assert float(prob.lagrange([3.0], [2.0], [])) == 6.0


def test_named_problem_pickles_and_replaces():
    import pickle

    prob = _di(lagrange=lambda u: 0.5 * u**2, boundary=lambda x_f: x_f - 1)
    again = pickle.loads(pickle.dumps(prob))
    _same(again.lagrange, prob.lagrange)
    same = prob.replace(T=2.0)
    _same(same.boundary[0].fun, prob.boundary[0].fun)
    assert math.isclose(float(same.boundary[0].fun([0, 0], [3, 0], [])), 2.0)
