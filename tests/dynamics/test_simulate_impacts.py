"""`simulate(impacts=...)`: a guard's crossing applies the impulse map and the integration
continues. Checked on the bouncing ball (impact times and apex heights in closed form, the
Zeno guard) and on the falling bar of seed Sec. 3.5 Example 5."""
import math

import casadi as ca
import numpy as np
import pytest

from appdyn.dynamics import Event, Impact, Model, simulate
from appdyn.dynamics.mechanisms import contact_jump, falling_bar_impact

G = 9.81


def _ball():
    x, u, p, t = ca.SX.sym("x", 2), ca.SX.sym("u", 1), ca.SX.sym("p", 0), ca.SX.sym("t")
    model = Model(f=ca.Function("ball", [x, u, p], [ca.vertcat(x[1], -G + u)],
                                ["x", "u", "p"], ["xdot"]), states=("h", "v"), controls=("a",))
    floor = ca.Function("floor", [t, x, u, p], [x[0]])
    return model, floor


def _bounces(e, h0, rest_speed=0.0, max_impacts=1000):
    model, floor = _ball()
    jump = contact_jump(lambda q, p: [[2.0]], lambda q, p: [1.0], e=e, nq=1)
    return model, Impact(floor, jump, rest_speed=rest_speed, max_impacts=max_impacts)


def _ball_truth(e, h0, n):
    """Impact times and rebound speeds of the first n impacts."""
    v1 = math.sqrt(2 * G * h0)
    times = [math.sqrt(2 * h0 / G)]
    for k in range(1, n):
        times.append(times[-1] + 2 * e ** k * v1 / G)
    return np.array(times), v1 * e ** np.arange(1, n + 1)


@pytest.mark.parametrize("e", [0.9, 0.5])
def test_bouncing_ball_times_heights_and_grid(e):
    h0 = 2.0
    model, floor = _bounces(e, h0, max_impacts=8)
    t = np.linspace(0.0, 20.0, 201)
    res = simulate(model, [h0, 0.0], t, method="rk8", impacts=floor)
    times, speeds = _ball_truth(e, h0, 8)
    got = np.array([r.t for r in res.impacts])
    assert len(res.impacts) == 8
    assert np.max(np.abs(got - times)) < 1e-12 * times[-1]
    after = np.array([r.x_after[1] for r in res.impacts])
    assert np.max(np.abs(after / speeds - 1)) < 1e-12
    apex = after ** 2 / (2 * G)                      # = e^(2n) h0
    assert np.allclose(apex, e ** (2 * np.arange(1, 9)) * h0, rtol=1e-12, atol=0)
    assert all(r.normal_impulse == pytest.approx(2.0 * (1 + e) * s / e) for r, s
               in zip(res.impacts, speeds))          # m (1 + e) |v-|
    # the grid between impacts: free flight from the last impact
    for j in range(1, res.t.size):
        tj = res.t[j]
        k = np.searchsorted(got, tj, side="right") - 1
        if k < 0:
            want = h0 - G * tj ** 2 / 2
        else:
            s = tj - got[k]
            want = speeds[k] * s - G * s * s / 2
        assert res.x[0, j] == pytest.approx(want, abs=1e-11)
    assert res.success and res.status == 6 and "max_impacts = 8" in res.message
    assert res.t[-1] == got[-1] and res.x[1, -1] == after[-1]


def test_zeno_guard_stops_at_rest():
    e, h0, rest = 0.6, 1.0, 0.05
    model, floor = _bounces(e, h0, rest_speed=rest)
    res = simulate(model, [h0, 0.0], np.linspace(0.0, 10.0, 11), method="rk8", impacts=floor)
    v1 = math.sqrt(2 * G * h0)
    n = math.ceil(math.log(rest / v1) / math.log(e))   # first with e^n v1 <= rest
    assert len(res.impacts) == n
    assert res.impacts[-1].rebound_speed == pytest.approx(e ** n * v1, rel=1e-9)
    assert res.impacts[-2].rebound_speed > rest
    zeno = math.sqrt(2 * h0 / G) + 2 * v1 * e / (G * (1 - e))
    assert res.t[-1] < zeno and res.status == 6 and res.success
    assert "came to rest" in res.message


def test_plastic_impact_stops_at_once():
    model, floor = _bounces(0.0, 1.0)
    res = simulate(model, [1.0, 0.0], np.linspace(0.0, 3.0, 4), method="rk8", impacts=floor)
    assert len(res.impacts) == 1 and res.x[1, -1] == 0.0 and res.status == 6


def test_auto_and_sampled_controls():
    """auto meets its tolerance between impacts; a sampled constant control acts as the
    constant (re-sampled at each restart)."""
    e, h0 = 0.8, 1.5
    model, floor = _bounces(e, h0, max_impacts=3)
    t = np.linspace(0.0, 5.0, 11)
    res = simulate(model, [h0, 0.0], t, impacts=floor)
    times, _ = _ball_truth(e, h0, 3)
    assert res.success and len(res.impacts) == 3
    assert np.max(np.abs(np.array([r.t for r in res.impacts]) - times)) < 1e-7
    lift = 1.0                                            # effective gravity G - 1
    const = simulate(model, [h0, 0.0], t, u=[lift], method="rk8", impacts=floor)
    sampled = simulate(model, [h0, 0.0], t, u=np.full((1, t.size), lift), method="rk8",
                       impacts=floor)
    assert np.allclose([r.t for r in const.impacts], [r.t for r in sampled.impacts],
                       rtol=0, atol=1e-13)
    assert const.impacts[0].t == pytest.approx(math.sqrt(2 * h0 / (G - lift)), rel=1e-13)


def test_falling_bar_touchdown_matches_example_5():
    m, l, e, mu, g = 1.0, 1.0, 0.5, 0.8, G
    x, u, p, t = ca.SX.sym("x", 6), ca.SX.sym("u", 0), ca.SX.sym("p", 0), ca.SX.sym("t")
    bar = Model(f=ca.Function("bar", [x, u, p], [ca.vertcat(x[3:], 0, -g, 0)],
                              ["x", "u", "p"], ["xdot"]),
                states=("x", "y", "phi", "x_dot", "y_dot", "phi_dot"), controls=())
    lowest = ca.Function("lowest_end", [t, x, u, p], [x[1] + l / 2 * ca.sin(x[2])])
    jump = contact_jump(lambda q, p: np.diag([m, m, m * l * l / 12]),
                        lambda q, p: [0.0, 1.0, l / 2 * math.cos(q[2])],
                        tangent=lambda q, p: [[1.0, 0.0, -l / 2 * math.sin(q[2])]],
                        e=e, mu=mu, nq=3)
    u0, drop, th = 1.0, 0.5, math.pi / 4
    y0 = l / 2 * math.sin(th) + drop
    res = simulate(bar, [0.0, y0, -th, u0, 0.0, 0.0], np.linspace(0.0, 0.4, 9), method="rk8",
                   impacts=Impact(lowest, jump, max_impacts=1), invariants=False)
    (hit,) = res.impacts
    assert hit.t == pytest.approx(math.sqrt(2 * drop / g), rel=1e-13)
    v0 = g * hit.t
    want = falling_bar_impact(m, l, u0, v0, e=e, mu=mu)
    assert np.allclose(hit.x_after[3:], want.v, rtol=0, atol=1e-12)
    assert hit.info.regime == want.regime and hit.normal_impulse == pytest.approx(
        want.normal_impulse, rel=1e-12)


@pytest.mark.parametrize("kwargs, error, match", [
    (dict(impacts="floor"), TypeError, "`impacts`"),
    (dict(impacts="EV"), ValueError, "`events`"),
    (dict(x0=np.array([[1.0, 2.0], [0.0, 0.0]])), ValueError, "single runs"),
])
def test_bad_impacts(kwargs, error, match):
    model, floor = _bounces(0.5, 1.0)
    args = dict(x0=[1.0, 0.0], impacts=floor)
    args.update(kwargs)
    events = None
    if args["impacts"] == "EV":
        args["impacts"], events = floor, Event(lambda t, x, u, p: x[0] - 0.5)
    with pytest.raises(error, match=match):
        simulate(model, args["x0"], [0.0, 1.0], impacts=args["impacts"], events=events)


def test_a_failed_run_is_reported_not_continued():
    model, floor = _bounces(0.8, 1.5, max_impacts=3)
    res = simulate(model, [1.5, 0.0], np.linspace(0.0, 5.0, 11), impacts=floor, rtol=1e-10,
                   atol=1e-12)                        # below auto's round-off floor here
    assert not res.success and res.status == 2 and len(res.impacts) <= 1
    assert "round-off" in res.message


def test_bad_jump_and_options():
    model, floor = _ball()
    with pytest.raises(ValueError, match="rest_speed"):
        Impact(floor, lambda t, x, u, p: x, rest_speed=-1.0)
    with pytest.raises(TypeError, match="`jump`"):
        Impact(floor, 3.0)
    bad = Impact(floor, lambda t, x, u, p: np.zeros(3))
    with pytest.raises(ValueError, match="2 finite states"):
        simulate(model, [1.0, 0.0], [0.0, 1.0], method="rk8", impacts=bad)


def test_docking_two_carts_central_collision():
    """A docking on a line (Example 1 in a simulation): impact time gap / (u1 - u2), the
    velocities after as `central_collision`, momentum conserved across the run; the result
    pickles with its records."""
    import pickle
    from appdyn.dynamics.mechanisms import central_collision
    m1, m2, u1, u2, e, gap = 3.0, 1.0, 2.0, -0.5, 0.3, 1.25
    x, u, p, t = ca.SX.sym("x", 4), ca.SX.sym("u", 0), ca.SX.sym("p", 0), ca.SX.sym("t")
    carts = Model(f=ca.Function("carts", [x, u, p], [ca.vertcat(x[2], x[3], 0, 0)],
                                ["x", "u", "p"], ["xdot"]),
                  states=("x1", "x2", "v1", "v2"), controls=())
    dock = Impact(ca.Function("gap", [t, x, u, p], [x[1] - x[0] - gap]),
                  contact_jump(lambda q, p: np.diag([m1, m2]), lambda q, p: [-1.0, 1.0], e=e,
                               nq=2, names=("v1", "v2")))
    grid = np.linspace(0.0, 2.0, 5)
    res = simulate(carts, [0.0, 0.0 + gap + 1.0, u1, u2], grid, method="rk4", impacts=dock)
    (hit,) = res.impacts
    assert hit.t == pytest.approx(1.0 / (u1 - u2), rel=1e-14)
    want = central_collision(m1, m2, u1, u2, e=e)
    assert hit.x_after[2:] == pytest.approx([want["v1"], want["v2"]], rel=1e-14)
    assert np.allclose(m1 * res["v1"] + m2 * res["v2"], m1 * u1 + m2 * u2, rtol=1e-14)
    assert res.success and res.status == 0 and res.t.tolist() == grid.tolist()
    back = pickle.loads(pickle.dumps(res))
    assert back.impacts[0].info["v2"] == want["v2"]
