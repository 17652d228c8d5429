"""Friendlier entry points: models from expressions, trajectories by name."""
import pickle

import casadi as ca
import numpy as np
import pytest

from appdyn import ocp
from appdyn.dynamics import Model, rigid_body, simulate
from appdyn.dynamics.model import model_from_expressions
from appdyn.ocp.examples import double_integrator, min_energy

RNG = np.random.default_rng(7)


def _pendulum_by_hand():
    x, u, p = ca.SX.sym("x", 2), ca.SX.sym("u"), ca.SX.sym("p", 2)
    xdot = ca.vertcat(x[1], -p[0] / p[1] * ca.sin(x[0]) + u)
    f = ca.Function("f", [x, u, p], [xdot], ["x", "u", "p"], ["xdot"])
    return Model(f, ("theta", "omega"), ("u",), ("g", "l"), p_default=[9.81, 1.0])


def _pendulum_from_expressions(**kw):
    th, om, u, g, l = (ca.SX.sym(n) for n in ("theta", "omega", "u", "g", "l"))
    return Model.from_expressions([("theta", th), ("omega", om)],
                                  {"omega": -g / l * ca.sin(th) + u, "theta": om},
                                  {"u": u}, {"g": g, "l": l}, p_default={"l": 1.0, "g": 9.81},
                                  invariants={"energy": 0.5 * l**2 * om**2 + g * l * (1 - ca.cos(th))},
                                  name="pendulum", **kw)


def _same_function(a: Model, b: Model, n=20):
    assert (a.states, a.controls, a.params) == (b.states, b.controls, b.params)
    for _ in range(n):
        x, u, p = RNG.normal(size=a.nx), RNG.normal(size=a.nu), RNG.uniform(0.5, 2, size=a.np)
        np.testing.assert_allclose(a.rhs(x, u, p), b.rhs(x, u, p), rtol=1e-14, atol=1e-14)


def test_double_integrator_equals_the_hand_built_one():
    x, v, u = ca.SX.sym("x"), ca.SX.sym("v"), ca.SX.sym("u")
    model = model_from_expressions({"x": x, "v": v}, [v, u], {"u": u}, name="di")
    assert model.np == 0 and model.p_default.shape == (0,)
    assert model.f.name_in() == ["x", "u", "p"] and model.f.name_out() == ["xdot"]
    _same_function(model, double_integrator())


def test_pendulum_equals_the_hand_built_one_and_keeps_its_metadata():
    model = _pendulum_from_expressions()
    _same_function(model, _pendulum_by_hand())
    np.testing.assert_array_equal(model.p_default, [9.81, 1.0])
    assert model.name == "pendulum"
    assert model.invariant("energy", [0.0, 2.0]) == pytest.approx(2.0)
    # the energy is conserved along a simulated swing
    res = simulate(model, [0.5, 0.0], np.linspace(0.0, 2.0, 5), invariants=["energy"])
    e = res.invariants["energy"]
    assert np.ptp(e) < 1e-8 * abs(e[0])


def test_model_from_expressions_pickles():
    model = pickle.loads(pickle.dumps(_pendulum_from_expressions()))
    _same_function(model, _pendulum_by_hand())
    assert model.invariant("energy", [0.0, 2.0]) == pytest.approx(2.0)


def test_no_controls_and_attitude_by_name():
    th, om = ca.SX.sym("th"), ca.SX.sym("om")
    model = Model.from_expressions({"theta": th, "omega": om}, {"theta": om, "omega": -th})
    assert model.nu == 0 and model.np == 0
    np.testing.assert_array_equal(model.rhs([1.0, 2.0]), [2.0, -1.0])
    syms = {n: ca.SX.sym(n) for n in ("q1", "q2", "q3", "q4", "w1", "w2", "w3")}
    body = Model.from_expressions(syms, {n: 0 for n in syms}, attitude=("q1", "w1"))
    assert body.attitude == (0, 4)


@pytest.mark.parametrize("case, match", [
    ("missing_xdot", r"`xdot`.*\['v'\]"),
    ("unknown_xdot", r"`xdot`.*unknown state.*\['y'\]"),
    ("undeclared", r"`xdot`\['v'\].*undeclared.*\['k'\]"),
    ("invariant_control", r"`invariants`\['e'\].*undeclared.*\['u'\]"),
    ("xdot_length", r"`xdot` must have 2"),
    ("duplicate_name", r"'x'.*`states`.*`controls`"),
    ("shared_symbol", r"'u'.*distinct symbols"),
    ("no_p_default", r"`p_default`"),
    ("p_default_unknown", r"`p_default`.*\['c'\]"),
    ("vector_symbol", r"`states`\['x'\].*scalar"),
])
def test_bad_input_raises_value_error_naming_it(case, match):
    x, v, u, k = (ca.SX.sym(n) for n in ("x", "v", "u", "k"))
    states = {"x": x, "v": v}
    kwargs = {
        "missing_xdot": dict(states=states, xdot={"x": v}),
        "unknown_xdot": dict(states=states, xdot={"x": v, "v": u, "y": 0}, controls={"u": u}),
        "undeclared": dict(states=states, xdot={"x": v, "v": -k * x}),
        "invariant_control": dict(states=states, xdot=[v, u], controls={"u": u},
                                  invariants={"e": v * u}),
        "xdot_length": dict(states=states, xdot=[v]),
        "duplicate_name": dict(states=states, xdot=[v, u], controls={"x": u}),
        "shared_symbol": dict(states=states, xdot=[v, u], controls={"u": x}),
        "no_p_default": dict(states=states, xdot=[v, -k * x], params={"k": k}),
        "p_default_unknown": dict(states=states, xdot=[v, -k * x], params={"k": k},
                                  p_default={"k": 1.0, "c": 2.0}),
        "vector_symbol": dict(states={"x": ca.SX.sym("x", 2)}, xdot=[0]),
    }[case]
    with pytest.raises(ValueError, match=match):
        model_from_expressions(**kwargs)


def test_bad_types_raise_type_error():
    x = ca.SX.sym("x")
    with pytest.raises(TypeError, match="`states`"):
        model_from_expressions({"x": ca.MX.sym("x")}, [0])
    with pytest.raises(TypeError, match="`xdot`"):
        model_from_expressions({"x": x}, 1.0)
    with pytest.raises(TypeError, match=r"`xdot`\['x'\]"):
        model_from_expressions({"x": x}, ["fast"])


# ------------------------------------------------------------ trajectories by name
def test_simulation_result_reads_states_by_name():
    res = simulate(rigid_body([1.0, 2.0, 3.0]), [0, 0, 0, 1, 1.0, 0.1, 0.8],
                   np.linspace(0.0, 2.0, 5))
    assert res["w1"].shape == res.t.shape
    np.testing.assert_array_equal(res["w1"], res.x[4])
    np.testing.assert_array_equal(res["q4"], res.x[3])
    with pytest.raises(KeyError, match=r"'w4'.*'w1', 'w2', 'w3'"):
        res["w4"]


def test_solution_reads_states_and_controls_by_name():
    sol = ocp.solve(min_energy(), N=10)
    assert sol.success
    np.testing.assert_array_equal(sol["v"], sol.x[1])
    np.testing.assert_array_equal(sol["x"], sol.x[0])
    np.testing.assert_array_equal(sol["u"], sol.u[0])
    assert sol["u"].shape == sol.t.shape
    np.testing.assert_allclose(sol["u"], 6.0 - 12.0 * sol.t, atol=1e-6)  # Bryson & Ho
    with pytest.raises(KeyError, match=r"'w'.*\('x', 'v'\).*\('u',\)"):
        sol["w"]


# ------------------------------------------------------------------ guesses by name
def _nodes(problem, guess):
    from appdyn.ocp.guess import initial_guess
    tr, mesh = ocp.Radau(3), ocp.Mesh.uniform(5)
    return initial_guess(problem, tr, mesh, guess=guess), tr.state_tau(mesh), tr.control_tau(mesh)


@pytest.mark.parametrize("x_guess", [
    {"x": lambda t: 3 * t**2 - 2 * t**3},                       # a callable of t
    {"x": 3 * np.linspace(0, 1, 201)**2 - 2 * np.linspace(0, 1, 201)**3},  # samples on t
])
def test_a_guess_may_name_some_states_the_others_keep_the_default(x_guess):
    """Bryson & Ho's optimum x = 3t^2 - 2t^3 for the named state; the unnamed v keeps the
    default (linear between its boundary values 0 and 0), the control its default 0."""
    problem = min_energy()
    t = np.linspace(0.0, 1.0, 201)
    g, tau, _ = _nodes(problem, {"t": t, "x": x_guess})
    np.testing.assert_allclose(g.X[0], 3 * tau**2 - 2 * tau**3, atol=1e-4)
    np.testing.assert_array_equal(g.X[1], 0.0)
    np.testing.assert_array_equal(g.U, 0.0)


def test_naming_every_state_and_control_gives_the_exact_solution():
    """The optimum by name (u = 6 - 12 t, x = 3t^2 - 2t^3, v = 6t - 6t^2) is already optimal."""
    problem = min_energy()
    guess = {"x": {"x": lambda t: 3 * t**2 - 2 * t**3, "v": lambda t: 6 * t - 6 * t**2},
             "u": {"u": lambda t: 6 - 12 * t}}
    g, tau, tau_u = _nodes(problem, guess)
    np.testing.assert_allclose(g.X[1], 6 * tau - 6 * tau**2, atol=1e-15)
    np.testing.assert_allclose(g.U[0], 6 - 12 * tau_u, atol=1e-14)
    sol = ocp.solve(problem, N=5, guess=guess,
                    ipopt_options={"tol": 1e-12, "bound_relax_factor": 0.0})
    assert sol.success and sol.iterations <= 1 and sol.cost == pytest.approx(6.0, abs=1e-9)


def test_a_named_constant_and_the_default_elsewhere():
    problem = min_energy().replace(x_final=[1.0, np.nan], u_bounds={"u": (-1, 1)})
    g, tau, _ = _nodes(problem, {"x": {"v": 0.25}, "u": {"u": 3.0}})
    np.testing.assert_allclose(g.X[1, 1:], 0.25)         # v free at the end: the constant
    np.testing.assert_allclose(g.X[0], tau)              # x linear from 0 to 1 (default)
    np.testing.assert_allclose(g.U, 1.0)                 # clipped into the bounds


@pytest.mark.parametrize("guess, match", [
    ({"x": {"w": 1.0}}, r"`guess\['x'\]` names unknown state 'w'.*\('x', 'v'\)"),
    ({"u": {"thrust": 1.0}}, r"`guess\['u'\]` names unknown control 'thrust'.*\('u',\)"),
    ({"x": {"v": "fast"}}, r"`guess\['x'\]\['v'\]`"),
    ({"x": {"v": np.ones((2, 2))}}, r"`guess\['x'\]\['v'\]`"),
    ({"t": [0.0, 0.5, 1.0], "x": {"v": [1.0, 2.0]}}, r"`guess\['x'\]\['v'\]`.*2 columns.*3 times"),
])
def test_bad_named_guess_raises_naming_it(guess, match):
    with pytest.raises(ValueError, match=match):
        _nodes(min_energy(), guess)
