"""`simulate(events=...)` against closed forms: a body falling onto the ground, the zeros of a
harmonic oscillator and of a torque-free body's rate (the Jacobi-elliptic solution), a
pointing error under a constant spin, and driven double integrators with sampled and
callable controls."""
import functools
import math
import pickle

import casadi as ca
import numpy as np
import pytest
from scipy.optimize import brentq

from appdyn.dynamics import Event, Model, rigid_body, simulate
from appdyn.dynamics.integrate.result import TERMINAL_EVENT
from appdyn.dynamics.truth import constant_rate_quat, torque_free_omega
from appdyn.dynamics.truth.common import quat_mul

G = 9.81
H0 = 10.0
IMPACT = math.sqrt(2 * H0 / G)  # the falling body's closed-form impact time [s]
TOL = 1e-10  # located-time error asked of default tolerances on smooth problems

T_SYM, X_SYM, U0, P0 = ca.SX.sym("t"), ca.SX.sym("x", 2), ca.SX.sym("u", 0), ca.SX.sym("p", 0)


def _model(name, xdot, nu=0, u=U0):
    f = ca.Function(name, [X_SYM, u, P0], [xdot], ["x", "u", "p"], ["xdot"])
    return Model(f=f, states=("y", "v"), controls=tuple(f"u{i}" for i in range(nu)), name=name)


@functools.lru_cache(maxsize=None)
def falling() -> Model:
    """y'' = -g: y = H0 - g t^2 / 2 from rest."""
    return _model("falling", ca.vertcat(X_SYM[1], -G))


@functools.lru_cache(maxsize=None)
def oscillator() -> Model:
    """y'' = -y: y = cos t from (1, 0), zeros at pi/2 + k pi."""
    return _model("oscillator", ca.vertcat(X_SYM[1], -X_SYM[0]))


@functools.lru_cache(maxsize=None)
def driven() -> Model:
    """y'' = u (one control)."""
    u = ca.SX.sym("u", 1)
    return _model("driven", ca.vertcat(X_SYM[1], u), nu=1, u=u)


def height(t, x, u, p):
    return x[0]


@functools.lru_cache(maxsize=None)
def ground_function() -> ca.Function:
    return ca.Function("ground", [T_SYM, X_SYM, U0, P0], [X_SYM[0]])


def with_attributes(fun, terminal=False, direction=0):
    """A plain callable carrying scipy's event attributes."""
    def g(t, x, u, p):
        return fun(t, x, u, p)
    g.terminal, g.direction = terminal, direction
    return g


# ------------------------------------------------------------------ the falling body
@pytest.mark.parametrize("method, kwargs", [("auto", {}), ("rk8", {}), ("rk4", {}),
                                            ("cvodes", {"rtol": 1e-12, "atol": 1e-12})])
def test_falling_body_stops_at_the_ground_at_the_closed_form_time(method, kwargs):
    t = np.linspace(0.0, 3.0, 7)  # the impact (1.428 s) lies between outputs 1.0 and 1.5
    ground = Event(ground_function(), terminal=True, direction=-1)
    res = simulate(falling(), [H0, 0.0], t, method=method, events=ground, **kwargs)
    assert res.success and res.status == TERMINAL_EVENT == 6
    assert "terminal event 0 (ground)" in res.message
    # rk4 and rk8 integrate the quadratic exactly; cvodes to its tolerance
    tol = 1e-9 if method == "cvodes" else 1e-13
    assert abs(res.t[-1] - IMPACT) < tol
    np.testing.assert_array_equal(res.t[:-1], t[t < res.t[-1]])
    assert res.x.shape == (2, res.t.size) and res.x[0, -1] == pytest.approx(0.0, abs=1e-9)
    assert res.x[1, -1] == pytest.approx(-G * IMPACT, abs=1e-8)
    np.testing.assert_allclose(res.x[0, :-1], H0 - G * res.t[:-1] ** 2 / 2, atol=1e-9)
    assert len(res.t_events) == 1 and res.t_events[0].shape == (1,)
    assert res.x_events[0].shape == (1, 2) and res.t_events[0][0] == res.t[-1]
    np.testing.assert_array_equal(res.x_events[0][0], res.x[:, -1])
    assert res.sample(res.t[-1])[0] == pytest.approx(0.0, abs=1e-9)


def test_an_upward_only_event_does_not_stop_the_fall():
    ground = Event(ground_function(), terminal=True, direction=+1)
    res = simulate(falling(), [H0, 0.0], np.linspace(0.0, 3.0, 7), events=ground)
    assert res.status == 0 and res.t[-1] == 3.0 and res.t_events[0].size == 0
    assert res.x_events[0].shape == (0, 2)


# ------------------------------------------------------------------ harmonic oscillator
def oscillator_zeros(t_end, first=0, step=1):
    k = np.arange(first, int(t_end / np.pi) + 2, step)
    z = np.pi / 2 + k * np.pi
    return z[z < t_end]


@pytest.mark.parametrize("method, kwargs, tol", [
    ("auto", {}, TOL), ("rk8", {"steps": 80}, TOL),
    ("rk4", {"steps": 1000}, 1e-8),  # 4th order at h = 0.01 s: about 1e-9 [s]
    ("cvodes", {"rtol": 1e-12, "atol": 1e-12}, 1e-9)])
def test_zeros_between_coarse_outputs_are_all_found(method, kwargs, tol):
    # three output points over 20 s: y = cos t changes sign six times, but only twice
    # between the outputs (cos 0 > 0, cos 10 < 0, cos 20 > 0): the four others are seen
    # on the internal steps (fixed step, auto) or the sub-grid (cvodes)
    t = np.array([0.0, 10.0, 20.0])
    res = simulate(oscillator(), [1.0, 0.0], t, method=method, events=height, **kwargs)
    assert res.success and res.status == 0
    np.testing.assert_array_equal(res.t, t)
    zeros = oscillator_zeros(20.0)
    assert res.t_events[0].shape == zeros.shape == (6,)
    assert np.max(np.abs(res.t_events[0] - zeros)) < tol
    np.testing.assert_allclose(res.x_events[0][:, 1], -np.sin(zeros), atol=tol)
    assert np.max(np.abs(res.x_events[0][:, 0])) < tol


@pytest.mark.parametrize("direction, first", [(+1, 1), (-1, 0)])
def test_direction_keeps_only_crossings_the_right_way(direction, first):
    g = with_attributes(height, direction=direction)
    res = simulate(oscillator(), [1.0, 0.0], np.linspace(0.0, 20.0, 5), events=g)
    zeros = oscillator_zeros(20.0, first, 2)  # cos t rises through 0 at 3 pi/2 + 2 k pi
    assert res.t_events[0].size == zeros.size == 3
    assert np.max(np.abs(res.t_events[0] - zeros)) < TOL
    assert np.all(np.sign(res.x_events[0][:, 1]) == direction)


def test_terminal_2_stops_at_the_second_occurrence():
    g = with_attributes(height, terminal=2)
    res = simulate(oscillator(), [1.0, 0.0], np.linspace(0.0, 20.0, 21), events=g)
    zeros = oscillator_zeros(20.0)[:2]
    assert res.status == TERMINAL_EVENT and res.success
    assert res.t_events[0].size == 2 and np.max(np.abs(res.t_events[0] - zeros)) < TOL
    assert abs(res.t[-1] - 3 * np.pi / 2) < TOL and res.t.size == 6  # 0..4, then 4.712
    assert "occurrence 2" in res.message


def test_several_events_are_ordered_and_the_first_terminal_one_stops():
    level = with_attributes(lambda t, x, u, p: x[0] - 0.5)     # y = 1/2 at pi/3, 5pi/3, ...
    stop = Event(lambda t, x, u, p: x[1] - 0.5, terminal=True, direction=1, name="rising")
    res = simulate(oscillator(), [1.0, 0.0], np.linspace(0.0, 20.0, 4),
                   events=[level, height, stop])
    # v = -sin t rises through 1/2 first at 7 pi / 6
    assert abs(res.t[-1] - 7 * np.pi / 6) < TOL and "(rising)" in res.message
    assert np.max(np.abs(res.t_events[0] - [np.pi / 3])) < TOL
    assert np.max(np.abs(res.t_events[1] - [np.pi / 2])) < TOL
    assert res.t_events[2].size == 1


def test_the_same_crossing_twice_is_recorded_by_both_and_stops_at_the_terminal_one():
    stop = Event(ground_function(), terminal=True)
    res = simulate(oscillator(), [1.0, 0.0], np.linspace(0.0, 20.0, 4), events=[height, stop])
    assert res.t_events[0].size == res.t_events[1].size == 1
    assert res.t_events[0][0] == res.t_events[1][0] == res.t[-1]
    assert abs(res.t[-1] - np.pi / 2) < TOL


def test_non_terminal_events_leave_the_solution_as_without_them():
    t = np.linspace(0.0, 20.0, 9)
    plain = simulate(oscillator(), [1.0, 0.0], t)
    res = simulate(oscillator(), [1.0, 0.0], t, events=[height])
    np.testing.assert_array_equal(res.x, plain.x)
    assert res.status == plain.status and plain.t_events is None
    assert res.n_steps > plain.n_steps  # the scan's steps are counted
    assert res.to_dict()["t_events"][0].size == 6 and "events" in str(res)
    back = pickle.loads(pickle.dumps(res))
    np.testing.assert_array_equal(back.t_events[0], res.t_events[0])
    np.testing.assert_array_equal(back.x_events[0], res.x_events[0])


@functools.lru_cache(maxsize=None)
def blow_up() -> Model:
    """x' = x^2: x = 1 / (1 - t) from 1, infinite at t = 1."""
    x = ca.SX.sym("x", 1)
    f = ca.Function("blow_up", [x, U0, P0], [x ** 2], ["x", "u", "p"], ["xdot"])
    return Model(f=f, states=("x",), controls=(), name="blow_up")


@pytest.mark.parametrize("method, kwargs", [("rk8", {"steps": 100}),
                                            ("cvodes", {"rtol": 1e-12, "atol": 1e-12})])
def test_a_terminal_event_before_a_singularity_is_a_success(method, kwargs):
    level = Event(lambda t, x, u, p: x[0] - 8.0, terminal=True, name="level")
    res = simulate(blow_up(), [1.0], np.linspace(0.0, 2.0, 21), method=method, events=level,
                   **kwargs)
    assert res.success and res.status == TERMINAL_EVENT
    # cvodes's global error: 1.1e-9 relative in x at t = 0.8 (growth amplifies the local
    # 1e-12), i.e. 2.3e-10 in the time x reaches 8
    tol = 1e-9 if method == "cvodes" else TOL
    assert abs(res.t[-1] - 0.875) < tol and res.x[0, -1] == pytest.approx(8.0, abs=1e-9)
    assert np.all(np.isfinite(res.x)) and "not part of the returned solution" in res.message


def test_auto_failing_after_a_terminal_event_stays_a_failure():
    level = Event(lambda t, x, u, p: x[0] - 8.0, terminal=True, name="level")
    res = simulate(blow_up(), [1.0], np.linspace(0.0, 2.0, 21), events=level)
    assert not res.success and res.status == -1
    assert "stopped by terminal event 0 (level)" in res.message and res.t[-1] < 1.0


# ------------------------------------------------------------------ the rigid body
def test_torque_free_w1_zeros_match_the_elliptic_solution():
    inertia, w0 = [1.0, 2.0, 3.0], [0.1, 0.5, 0.3]  # w1 oscillates through zero
    t = np.linspace(0.0, 60.0, 4)
    w1 = Event(lambda t, x, u, p: x[4])
    res = simulate(rigid_body(inertia), [0, 0, 0, 1, *w0], t, events=w1)

    def truth(s):
        return torque_free_omega(inertia, w0, np.array([s]))[0, 0]

    grid = np.linspace(0.0, 60.0, 6001)
    values = torque_free_omega(inertia, w0, grid)[0]
    brackets = np.flatnonzero(np.sign(values[:-1]) != np.sign(values[1:]))
    zeros = np.array([brentq(truth, grid[j], grid[j + 1], xtol=1e-15) for j in brackets])
    assert zeros.size >= 4
    assert res.t_events[0].shape == zeros.shape
    assert np.max(np.abs(res.t_events[0] - zeros)) < TOL


@pytest.mark.parametrize("method, kwargs", [("auto", {}), ("rk8", {"steps": 20}),
                                            ("lie", {"steps": 40}),
                                            ("cvodes", {"rtol": 1e-12, "atol": 1e-12})])
def test_stop_when_the_pointing_error_is_small(method, kwargs):
    rate, t_target = 0.3, 8.0  # spin about the principal axis 3 at a constant rate
    w = np.array([0.0, 0.0, rate])
    target = constant_rate_quat([0, 0, 0, 1], w, t_target)[:, 0]

    def pointing_error(t, x, u, p):  # the angle of the rotation from the target
        rel = quat_mul(x[:4, None], (target * [-1, -1, -1, 1])[:, None])[:, 0]
        return 2 * math.atan2(np.linalg.norm(rel[:3]), abs(rel[3])) - 0.01

    pointing_error.terminal, pointing_error.direction = True, -1
    res = simulate(rigid_body([1.0, 2.0, 3.0]), [0, 0, 0, 1, *w], np.linspace(0.0, 10.0, 3),
                   method=method, events=pointing_error, invariants=["energy"], **kwargs)
    assert res.success and res.status == TERMINAL_EVENT
    np.testing.assert_allclose(res.invariants["energy"], np.full(res.t.size, 1.5 * rate ** 2),
                               rtol=1e-12)  # 1/2 I3 w3^2 along the truncated solution
    expected = t_target - 0.01 / rate  # the angle is rate * t
    tol = {"lie": 1e-9, "cvodes": 1e-9}.get(method, TOL)
    assert abs(res.t[-1] - expected) < tol
    np.testing.assert_allclose(res.x[:4, -1], constant_rate_quat([0, 0, 0, 1], w, expected)[:, 0],
                               atol=tol)


# ------------------------------------------------------------------ controls
def cubic_root(coefs, lo, hi):
    roots = np.roots(coefs)
    real = roots[np.abs(roots.imag) < 1e-12].real
    return float(real[(real > lo) & (real < hi)].min())


@pytest.mark.parametrize("method, kwargs", [("auto", {}), ("rk8", {}), ("rk4", {}),
                                            ("cvodes", {"rtol": 1e-12, "atol": 1e-12})])
def test_sampled_control_event_at_the_root_of_the_cubic(method, kwargs):
    # y'' = u = 1 - 0.6 t sampled on the grid (linear between samples: exact), y(0) = -1:
    # y = -1 + t^2 / 2 - 0.1 t^3 crosses 0 upwards, then downwards
    t = np.linspace(0.0, 6.0, 4)
    u = (1.0 - 0.6 * t)[None, :]
    res = simulate(driven(), [-1.0, 0.0], t, u=u, method=method, events=height, **kwargs)
    up = cubic_root([-0.1, 0.5, 0.0, -1.0], 0.0, 6.0)
    down = cubic_root([-0.1, 0.5, 0.0, -1.0], up + 1e-6, 6.0)
    tol = 1e-9 if method == "cvodes" else TOL
    assert res.t_events[0].size == 2
    assert np.max(np.abs(res.t_events[0] - [up, down])) < tol


@pytest.mark.parametrize("method, kwargs", [("auto", {}), ("rk8", {"steps": 20}),
                                            ("rk4", {"steps": 400}),
                                            ("cvodes", {"rtol": 1e-12, "atol": 1e-12})])
def test_callable_control_event(method, kwargs):
    # y'' = cos t from y = -0.5, v = 0.2: y = -0.5 + 0.2 t + 1 - cos t
    def u(t):
        return [math.cos(t)]

    def y(s):
        return 0.5 + 0.2 * s - math.cos(s)

    stop = Event(height, terminal=True)
    res = simulate(driven(), [-0.5, 0.2], np.linspace(0.0, 4.0, 3), u=u, method=method,
                   events=stop, **kwargs)
    expected = brentq(y, 0.0, 2.0, xtol=1e-15)
    tol = {"cvodes": 1e-9, "rk4": 1e-9}.get(method, TOL)
    assert res.status == TERMINAL_EVENT and abs(res.t[-1] - expected) < tol
    assert res.sample(res.t).shape == (2, res.t.size)


@pytest.mark.parametrize("method", ["auto", "rk8", "cvodes", "dop853"])
def test_an_event_on_the_control_and_the_parameters(method):
    # y'' = -w^2 y with w = p = 2 from (1, 0): y = cos 2t; u = t / 4 sampled on the grid.
    # g1 = u - 0.3 crosses at t = 1.2; g2 = y - p / 4 (y = 1/2) at t = pi / 6
    x, u, p = ca.SX.sym("x", 2), ca.SX.sym("u", 1), ca.SX.sym("p", 1)
    f = ca.Function("spring", [x, u, p], [ca.vertcat(x[1], -p[0] ** 2 * x[0])],
                    ["x", "u", "p"], ["xdot"])
    model = Model(f=f, states=("y", "v"), controls=("u",), params=("w",), p_default=[2.0])
    on_u = Event(ca.Function("on_u", [T_SYM, x, u, p], [u[0] - 0.3]))
    t = np.linspace(0.0, 2.0, 3)
    kwargs = {"auto": {}, "rk8": {"steps": 20}, "cvodes": {"rtol": 1e-12, "atol": 1e-12},
              "dop853": {"rtol": 1e-12, "atol": 1e-12}}[method]
    res = simulate(model, [1.0, 0.0], t, u=(t / 4)[None, :], method=method,
                   events=[on_u, lambda t, x, u, p: x[0] - p[0] / 4], **kwargs)
    assert abs(res.t_events[0][0] - 1.2) < 1e-13 and res.t_events[0].size == 1
    assert abs(res.t_events[1][0] - np.pi / 6) < (1e-9 if method == "cvodes" else TOL)


def test_fixed_steps_are_scanned_at_every_internal_step():
    # one output interval of 20 s, 200 rk8 steps: six zeros, all inside the interval
    res = simulate(oscillator(), [1.0, 0.0], [0.0, 20.0], method="rk8", steps=200,
                   events=height)
    assert np.max(np.abs(res.t_events[0] - oscillator_zeros(20.0))) < TOL


# ------------------------------------------------------------------ bad inputs
def test_bad_events_are_refused_naming_the_argument():
    args = (oscillator(), [1.0, 0.0], [0.0, 1.0])
    with pytest.raises(TypeError, match="`events` must be a callable"):
        simulate(*args, events=3.0)
    with pytest.raises(TypeError, match=r"`events\[1\]` must be a callable"):
        simulate(*args, events=[height, "x"])
    wrong_io = ca.Function("g", [X_SYM], [X_SYM[0]])
    with pytest.raises(ValueError, match=r"`events\[0\]` must be a Function \(t, x, u, p\)"):
        simulate(*args, events=wrong_io)
    vector_out = ca.Function("g", [T_SYM, X_SYM, U0, P0], [X_SYM])
    with pytest.raises(ValueError, match="one scalar output"):
        simulate(*args, events=Event(vector_out))
    with pytest.raises(ValueError, match=r"`events\[0\]` \(<lambda>\) must return a scalar"):
        simulate(*args, events=lambda t, x, u, p: x)
    with pytest.raises(ValueError, match="must return a finite number"):
        simulate(*args, events=lambda t, x, u, p: math.nan)
    with pytest.raises(ValueError, match=r"terminal` must be a bool or an integer >= 0"):
        simulate(*args, events=with_attributes(height, terminal=-1))
    with pytest.raises(ValueError, match="`Event` `direction` must be a finite number"):
        Event(height, direction="up")
    with pytest.raises(ValueError, match="`events` are located for single runs only"):
        simulate(oscillator(), np.ones((2, 3)), [0.0, 1.0], events=height)


@pytest.mark.parametrize("method, kwargs", [("auto", {}), ("rk8", {"steps": 4}),
                                            ("cvodes", {"rtol": 1e-12, "atol": 1e-12})])
def test_event_under_a_held_control(method, kwargs):
    # y'' = u held (zoh) at 1, -1, 1 on [0, 1), [1, 2), [2, 3): y = 1/2 + s - s^2 / 2 on
    # [1, 2] (s = t - 1) reaches 0.995 at s = 0.9, in the last scan piece before the jump at
    # t = 2 (a piece that must hold -1 to its end, not ramp to the next sample)
    t = np.array([0.0, 1.0, 2.0, 3.0])
    u = np.array([[1.0, -1.0, 1.0, 0.0]])
    near_top = Event(lambda t, x, u, p: x[0] - 0.995, terminal=True)
    res = simulate(driven(), [0.0, 0.0], t, u=u, hold="zoh", method=method, events=near_top,
                   **kwargs)
    tol = 1e-9 if method == "cvodes" else TOL
    assert res.status == TERMINAL_EVENT and abs(res.t[-1] - 1.9) < tol


def test_event_on_a_non_smooth_right_hand_side():
    # y'' = -sat(4 y, 1) from y = 2: |4y| >= 1 for y >= 1/4, so y = 2 - t^2 / 2 until y = 1/4
    # at t = sqrt(7/2); auto integrates the kink (fmin/fmax) by DOP853 with step rejection
    y = X_SYM[0]
    model = _model("saturated", ca.vertcat(X_SYM[1], -ca.fmin(ca.fmax(4 * y, -1), 1)))
    quarter = Event(lambda t, x, u, p: x[0] - 0.25, terminal=True, direction=-1)
    res = simulate(model, [2.0, 0.0], np.linspace(0.0, 4.0, 3), events=quarter)
    assert res.method == "dop853"
    assert res.status == TERMINAL_EVENT and abs(res.t[-1] - np.sqrt(3.5)) < TOL
