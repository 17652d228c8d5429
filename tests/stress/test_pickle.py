"""Pickling of the result and model objects, and models shipped to worker processes.

Every check compares the unpickled object's behaviour against the original object (or a
serial run): the original is the independent truth.
"""
from __future__ import annotations

import concurrent.futures
import multiprocessing
import pickle
from types import MappingProxyType

import casadi as ca
import numpy as np
import pytest

from appdyn import dynamics
from appdyn.dynamics import Model, simulate

X0 = [0.0, 0.0, 0.0, 1.0, 0.1, 0.2, 0.3]
T = np.linspace(0.0, 1.0, 6)


def _round_trip(obj, protocol=pickle.HIGHEST_PROTOCOL):
    return pickle.loads(pickle.dumps(obj, protocol=protocol))


def _oscillator() -> Model:
    x, u, p = ca.SX.sym("x", 2), ca.SX.sym("u", 1), ca.SX.sym("p", 1)
    f = ca.Function("oscillator", [x, u, p], [ca.vertcat(x[1], -p[0] * x[0] + u[0])],
                    ["x", "u", "p"], ["xdot"])
    xi, pi = ca.SX.sym("x", 2), ca.SX.sym("p", 1)
    energy = ca.Function("energy", [xi, pi], [0.5 * xi[1] ** 2 + 0.5 * pi[0] * xi[0] ** 2],
                         ["x", "p"], ["energy"])
    return Model(f, ("y", "ydot"), ("force",), ("k",), p_default=[4.0],
                 units={"y": "m", "ydot": "m/s", "force": "N/kg", "k": "1/s^2"},
                 invariants={"energy": energy}, name="oscillator")


def _same_model_data(a: Model, b: Model):
    assert b is not a
    assert (b.states, b.controls, b.params, b.name, b.attitude) == \
        (a.states, a.controls, a.params, a.name, a.attitude)
    assert np.array_equal(b.p_default, a.p_default) and not b.p_default.flags.writeable
    assert isinstance(b.units, MappingProxyType) and dict(b.units) == dict(a.units)
    assert isinstance(b.invariants, MappingProxyType)
    assert sorted(b.invariants) == sorted(a.invariants)
    assert b.f.name_in() == a.f.name_in() and b.f.name_out() == a.f.name_out()


# ----------------------------------------------------------------------------- Model
@pytest.mark.parametrize("protocol", range(2, pickle.HIGHEST_PROTOCOL + 1))
def test_rigid_body_round_trips(protocol):
    model = dynamics.rigid_body([1.0, 2.0, 3.0])
    loaded = _round_trip(model, protocol)
    _same_model_data(model, loaded)
    x = np.array(X0)
    assert np.array_equal(loaded.rhs(x, [0.1, 0.0, -0.2]), model.rhs(x, [0.1, 0.0, -0.2]))
    for key in model.invariants:
        assert np.array_equal(loaded.invariant(key, x), model.invariant(key, x))


@pytest.mark.parametrize("kwargs", [dict(method="rk8", steps=4), dict()], ids=["rk8", "auto"])
def test_unpickled_rigid_body_simulates_bitwise(kwargs):
    model = dynamics.rigid_body([1.0, 2.0, 3.0])
    loaded = _round_trip(model)
    a, b = simulate(model, X0, T, **kwargs), simulate(loaded, X0, T, **kwargs)
    assert a.success and b.success and a.method == b.method
    assert np.array_equal(a.x, b.x)
    # loading twice gives two independent, working models
    again = _round_trip(model)
    assert again is not loaded
    assert np.array_equal(simulate(again, X0, T, **kwargs).x, a.x)


@pytest.mark.slow
def test_hand_built_sx_model_round_trips():
    model = _oscillator()
    loaded = _round_trip(model)
    _same_model_data(model, loaded)
    assert loaded.f.is_a("SXFunction")
    t = np.linspace(0.0, 2.0, 9)
    for kwargs in (dict(method="rk8", steps=4), dict()):
        a = simulate(model, [1.0, 0.0], t, u=0.5, invariants=True, **kwargs)
        b = simulate(loaded, [1.0, 0.0], t, u=0.5, invariants=True, **kwargs)
        assert np.array_equal(a.x, b.x)
        assert np.array_equal(a.invariants["energy"], b.invariants["energy"])


def test_unpickled_model_is_still_validated():
    model = _oscillator()
    loaded = _round_trip(model)
    with pytest.raises(ValueError, match="`p`"):
        loaded.resolve_p([1.0, 2.0])


# ------------------------------------------------------------------ SimulationResult
def _check_result(a, b):
    assert np.array_equal(b.t, a.t) and np.array_equal(b.x, a.x)
    assert not b.x.flags.writeable and not b.t.flags.writeable
    assert isinstance(b.invariants, MappingProxyType)
    for key in a.invariants:
        assert np.array_equal(b.invariants[key], a.invariants[key])
    assert np.array_equal(b.xdot, a.xdot) and not b.xdot.flags.writeable
    assert isinstance(b.invariant_drift, MappingProxyType)
    assert dict(b.invariant_drift) == dict(a.invariant_drift)
    tq = np.linspace(a.t[0], a.t[-1], 23)
    assert np.array_equal(b.sample(tq), a.sample(tq))
    assert b.to_json() == a.to_json().replace(repr(a.wall_time), repr(b.wall_time))
    assert b.states == a.states and str(b) == str(a)
    fig = b.plot()  # one subplot per unit; every state drawn once, labelled
    assert [ln.get_label() for ax in fig.axes for ln in ax.lines] == list(a.states)


@pytest.mark.parametrize("use_first", [False, True], ids=["fresh", "used"])
def test_simulation_result_round_trips(use_first):
    model = dynamics.rigid_body([1.0, 2.0, 3.0])
    u = np.vstack([np.sin(T), np.cos(T), T]) * 0.1
    a = simulate(model, X0, T, u=u, method="rk8", steps=4, invariants=True)
    if use_first:  # caches filled before pickling travel along
        a.xdot, a.invariant_drift
    b = _round_trip(a)
    _check_result(a, b)


def test_simulation_result_with_callable_control_round_trips():
    model = _oscillator()
    t = np.linspace(0.0, 1.0, 11)
    a = simulate(model, [1.0, 0.0], t, u=lambda s: [np.sin(3.0 * s)], method="rk4", steps=3)
    b = _round_trip(a)  # the control is stored as its samples on the grid
    _check_result(a, b)


def test_simulation_result_without_model_round_trips():
    a = simulate(dynamics.rigid_body([1.0, 2.0, 3.0]), X0, T, method="rk4", steps=2)
    import dataclasses
    bare = dataclasses.replace(a, _dense=None)
    b = _round_trip(bare)
    assert np.array_equal(b.x, a.x) and b.states == bare.states
    assert dict(b.invariant_drift) == {}


# --------------------------------------------------------------------- ocp.Solution
def _check_solution(a, b):
    assert b.problem is not a.problem and b.mesh == a.mesh
    assert not b.x.flags.writeable and not b.mesh.breaks.flags.writeable
    assert not b.problem.x_initial.flags.writeable
    assert b.dense._interp is None  # the cached interpolant is rebuilt, not pickled
    tq = np.linspace(a.t0, a.t0 + a.T, 37)
    for va, vb in zip(a.sample(tq), b.sample(tq)):
        assert np.array_equal(va, vb)
    da, db = a.to_dict(), b.to_dict()
    assert da.keys() == db.keys()
    assert repr(da) == repr(db)
    assert str(a) == str(b) and repr(a) == repr(b)
    assert b.propagation_error == a.propagation_error
    fig, ref = b.plot(n=50), a.plot(n=50)
    assert [ax.get_ylabel() for ax in fig.axes] == [ax.get_ylabel() for ax in ref.axes]
    assert [len(ax.lines) for ax in fig.axes] == [len(ax.lines) for ax in ref.axes]


def test_min_energy_solution_round_trips():
    from appdyn import ocp
    from appdyn.ocp.examples import min_energy

    a = ocp.solve(min_energy(), N=10)
    assert a.success
    b = _round_trip(a)
    _check_solution(a, b)
    # the solution re-solved from the unpickled problem is the same
    c = ocp.solve(b.problem, N=10)
    assert np.array_equal(c.x, a.x)


def test_slew_solution_round_trips():
    from appdyn.problems import slew

    a = slew.min_effort(np.eye(3), 2.0, angle=0.5, axis=[0, 0, 1])
    b = _round_trip(a)
    assert type(b) is type(a)
    _check_solution(a, b)
    assert b.pointing_error == a.pointing_error


# --------------------------------------------------------------------- stability
def test_stability_report_round_trips():
    from appdyn.problems import stability

    a = stability.spin([2.0, 3.0, 4.5], axis=[1, 0, 0], rate=10.0)
    b = _round_trip(a)
    assert str(b) == str(a) and b.to_json() == a.to_json()
    for m in "ABCD":
        assert np.array_equal(getattr(b.ss, m), getattr(a.ss, m))
    assert (b.ss.state_labels, b.ss.input_labels, b.ss.output_labels, b.ss.dt, b.ss.name) == \
        (a.ss.state_labels, a.ss.input_labels, a.ss.output_labels, a.ss.dt, a.ss.name)
    assert np.array_equal(b.eigenvalues, a.eigenvalues)
    fig = b.plot()
    assert fig.axes


def test_sweep_result_round_trips():
    from appdyn.problems import stability

    a = stability.sweep("spin", "rate", [1.0, 5.0], inertia=[2.0, 3.0, 4.5], axis=[1, 0, 0])
    b = _round_trip(a)
    assert str(b) == str(a) and b.to_json() == a.to_json()
    fig = b.plot()
    assert fig.axes


# -------------------------------------------------------------- worker processes
def _simulate_task(model, x0, t):
    """Top level, so that spawn workers can import it."""
    return np.array(simulate(model, x0, t, method="rk8", steps=4).x)


@pytest.mark.parametrize("start", ["spawn", "fork"])
@pytest.mark.slow
def test_models_travel_to_process_pool(start):
    if start not in multiprocessing.get_all_start_methods():
        pytest.skip(f"no {start} start method here")
    models = [dynamics.rigid_body([1.0, 2.0, 3.0]), _oscillator()]
    starts = [X0, [1.0, 0.0]]
    serial = [_simulate_task(m, x0, T) for m, x0 in zip(models, starts)]
    context = multiprocessing.get_context(start)
    with concurrent.futures.ProcessPoolExecutor(max_workers=2, mp_context=context) as pool:
        parallel = list(pool.map(_simulate_task, models, starts, [T, T]))
    for a, b in zip(serial, parallel):
        assert np.array_equal(a, b)
