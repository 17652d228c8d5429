"""Systems held by Lagrange multipliers (dynamics.mechanisms.multipliers) against closed forms
and against independent formulations (Euler's law about the hinge for the shaken pendulum).
"""
import math

import numpy as np
import pytest

from appdyn.dynamics import simulate
from appdyn.dynamics.mechanisms import (bead_motion, bead_torque, coin_state, coin_steady_rates,
                                 dumbbell_disk, dumbbell_disk_frequency, dumbbell_disk_state,
                                 rod_pendulum, rod_reaction, rolling_coin,
                                 shaken_multiplier_state, shaken_pendulum,
                                 shaken_pendulum_multipliers, sliding_bead)

G = 9.81


# ------------------------------------------------------------------ rod pendulum
def test_rod_tension_along_a_swing_and_energy():
    m, l = 1.7, 0.8
    model = rod_pendulum(mass=m, length=l, gravity=G)
    th0, w0 = 2.0, 1.5
    x0 = [l * math.sin(th0), -l * math.cos(th0), l * w0 * math.cos(th0), l * w0 * math.sin(th0)]
    t = np.linspace(0.0, 5.0, 501)
    res = simulate(model, x0, t, method="rk8", steps=10, invariants=True)
    x, y, xd, yd = res.x
    th = np.arctan2(x, -y)
    w = (x * yd - y * xd) / (x * x + y * y)
    R = res.invariants["rod_force"].ravel()
    closed = rod_reaction(th, w, mass=m, length=l, gravity=G)
    assert np.max(np.abs(R - closed)) < 1e-9 * np.max(np.abs(closed))
    assert closed.min() < 0 < closed.max()  # a rod: pulls low in the swing, pushes near the top
    np.testing.assert_allclose(res.invariants["multipliers"].ravel(), -R, rtol=0, atol=1e-14)
    E = res.invariants["energy"].ravel()
    assert np.max(np.abs(E - E[0])) < 1e-10 * m * G * l
    assert np.max(res.invariants["constraint_residual"]) < 1e-10


def test_rod_pendulum_is_the_simple_pendulum():
    model = rod_pendulum(length=2.0, gravity=G, time_constant=None)
    th, w = 0.7, -1.2
    x = [2.0 * math.sin(th), -2.0 * math.cos(th), 2.0 * w * math.cos(th), 2.0 * w * math.sin(th)]
    ax, ay = model.rhs(x)[2:]
    # a = l (th'' n - w^2 e_r), n = (cos, sin): th'' = a.n / l
    thdd = (ax * math.cos(th) + ay * math.sin(th)) / 2.0
    assert abs(thdd + G / 2.0 * math.sin(th)) < 1e-13


# ------------------------------------------------------------------ shaken pendulum
@pytest.mark.parametrize("amp_x, amp_y, damping", [(0.0, 0.02, 0.0), (0.015, 0.01, 0.003)])
def test_shaken_pendulum_two_formulations_agree(amp_x, amp_y, damping):
    kw = dict(amp_x=amp_x, amp_y=amp_y, damping=damping, freq=150.0)
    euler = shaken_pendulum(**kw)
    lagrange = shaken_pendulum_multipliers(**kw)
    th0, w0, t0 = 2.5, 0.3, 0.0
    t = np.linspace(t0, 1.0, 1001)
    a = simulate(euler, [th0, w0, t0], t, method="rk8", steps=4, invariants=["hinge_force"])
    x0 = shaken_multiplier_state(th0, w0, t0, amp_x=amp_x, amp_y=amp_y, freq=150.0)
    b = simulate(lagrange, x0, t, method="rk8", steps=4, invariants=True)
    assert np.max(np.abs(a.x[0] - b.x[2])) < 1e-10
    assert np.max(np.abs(a.x[1] - b.x[5])) < 1e-10 * np.max(np.abs(a.x[1]))
    Fa, Fb = a.invariants["hinge_force"], b.invariants["hinge_force"]  # (2, len(t)) each
    assert np.max(np.abs(Fa - Fb)) < 1e-10 * np.max(np.abs(Fa))
    assert np.max(b.invariants["constraint_residual"]) < 1e-11


def test_shaken_multipliers_rhs_equals_euler_at_random_states():
    rng = np.random.default_rng(3)
    for _ in range(10):
        kw = dict(mass=rng.uniform(0.5, 2), inertia=rng.uniform(0, 0.1),
                  length=rng.uniform(0.1, 1), amp_x=rng.uniform(-0.05, 0.05),
                  amp_y=rng.uniform(-0.05, 0.05), freq=rng.uniform(1, 100),
                  damping=rng.uniform(0, 0.1))
        th, w, t = rng.uniform(-3, 3), rng.uniform(-5, 5), rng.uniform(0, 2)
        x = shaken_multiplier_state(th, w, t, length=kw["length"], amp_x=kw["amp_x"],
                                    amp_y=kw["amp_y"], freq=kw["freq"])
        lag, eul = shaken_pendulum_multipliers(**kw), shaken_pendulum(**kw)
        thdd = eul.rhs([th, w, t])[1]
        assert abs(lag.rhs(x)[5] - thdd) < 1e-11 * max(1.0, abs(thdd))
        np.testing.assert_allclose(lag.invariant("hinge_force", x).ravel(),
                                   eul.invariant("hinge_force", [th, w, t]).ravel(),
                                   rtol=1e-11, atol=1e-11)


# ------------------------------------------------------------------ sliding bead
def test_bead_torque_eq_5_79_with_a_varying_rate():
    m, w0, w1, nu = 0.4, 1.2, 0.5, 3.0
    model = sliding_bead(mass=m, rate=w0, rate_amp=w1, rate_freq=nu)
    t = np.linspace(0.0, 2.0, 201)
    res = simulate(model, [0.3, 0.0, 0.1, w0, 0.0], t, method="rk8", steps=10, invariants=True)
    r, phi, rd, phid, clock = res.x
    f = w0 + w1 * np.sin(nu * clock)
    fd = w1 * nu * np.cos(nu * clock)
    np.testing.assert_allclose(phid, f, rtol=0, atol=1e-12)
    torque = res.invariants["torque"].ravel()
    closed = bead_torque(r, rd, f, fd, mass=m)
    assert np.max(np.abs(torque - closed)) < 1e-10 * np.max(np.abs(closed))
    # the work of the torque is the kinetic energy gained
    T = 0.5 * m * (rd ** 2 + (r * phid) ** 2)
    power = torque * phid
    work = np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(t))])
    assert np.max(np.abs(T - T[0] - work)) < 1e-3 * np.max(np.abs(work))


def test_bead_on_a_wire_at_constant_rate():
    m, w = 2.0, 1.5
    model = sliding_bead(mass=m, rate=w)
    t = np.linspace(0.0, 2.0, 101)
    res = simulate(model, [0.2, 0.0, -0.1, w, 0.0], t, method="rk8", steps=10, invariants=True)
    r, rd = bead_motion(t, 0.2, -0.1, w)
    assert np.max(np.abs(res.x[0] - r)) < 1e-10 * np.max(r)
    assert np.max(np.abs(res.x[2] - rd)) < 1e-10 * np.max(np.abs(rd))
    np.testing.assert_allclose(res.invariants["torque"].ravel(), 2 * m * r * rd * w,
                               rtol=1e-9, atol=1e-10)


# ------------------------------------------------------------------ rolling coin
@pytest.mark.parametrize("theta, a", [(math.pi / 3, 0.5), (1.2, 0.2), (2.0, -0.3)])
def test_coin_steady_rolling_in_a_circle(theta, a):
    R = 0.1
    W, s = coin_steady_rates(theta, a, radius=R, gravity=G)
    model = rolling_coin(radius=R, gravity=G)
    x0 = coin_state(theta, W, s, radius=R)
    t = np.linspace(0.0, 2 * math.pi / W, 201)
    res = simulate(model, x0, t, method="rk8", steps=10, invariants=True)
    assert np.max(np.abs(res.x[4] - theta)) < 1e-9
    assert np.max(np.abs(res.x[9] - W)) < 1e-9 * W
    # the centre circles O = C0 - a h0 at radius |a|, speed |a W|
    h0 = np.array([math.sin(x0[3]), -math.cos(x0[3])])
    O = x0[:2] - a * h0
    rho = np.hypot(res.x[0] - O[0], res.x[1] - O[1])
    assert np.max(np.abs(rho - abs(a))) < 1e-9
    assert np.max(np.abs(np.hypot(res.x[6], res.x[7]) - abs(a * W))) < 1e-9
    assert np.max(res.invariants["constraint_residual"]) < 1e-10


def test_coin_conserves_energy_and_rolls():
    model = rolling_coin(mass=0.3, radius=0.05, gravity=G)
    x0 = coin_state(1.3, 1.0, 25.0, radius=0.05, theta_dot=0.4)
    t = np.linspace(0.0, 3.0, 601)
    res = simulate(model, x0, t, method="rk8", steps=10, invariants=True)
    E = res.invariants["energy"].ravel()
    assert np.max(np.abs(E - E[0])) < 1e-10 * abs(E[0])
    assert np.ptp(res.x[4]) > 0.05  # the tilt nutates: not a steady case
    assert np.max(res.invariants["constraint_residual"]) < 1e-9
    F = np.asarray(res.invariants["contact_force"]).reshape(-1)
    assert F.size == 3 * len(t)


def test_coin_upright_rolls_straight_with_weight_on_the_floor():
    model = rolling_coin(mass=2.0, gravity=G)
    x0 = coin_state(math.pi / 2, 0.0, 20.0)
    np.testing.assert_allclose(model.invariant("contact_force", x0).ravel(), [0, 0, 2 * G],
                               atol=1e-12)


# ------------------------------------------------------------------ bad input
@pytest.mark.parametrize("build, kwargs, name", [
    (rod_pendulum, {"mass": -1.0}, "mass"),
    (rod_pendulum, {"length": 0.0}, "length"),
    (rod_pendulum, {"time_constant": 0.0}, "time_constant"),
    (shaken_pendulum_multipliers, {"damping": -0.1}, "damping"),
    (sliding_bead, {"mass": float("nan")}, "mass"),
    (rolling_coin, {"radius": -0.1}, "radius"),
    (rolling_coin, {"inertia_axial": 0.0}, "inertia_axial"),
])
def test_bad_input_names_the_argument(build, kwargs, name):
    with pytest.raises(ValueError, match=name):
        build(**kwargs)


def test_closed_form_bad_input():
    with pytest.raises(ValueError, match="theta"):
        coin_steady_rates(0.0, 0.5)
    with pytest.raises(ValueError, match="path_radius"):
        coin_steady_rates(1.0, -0.5)
    with pytest.raises(ValueError, match="rate"):
        bead_motion(1.0, 1.0, 0.0, 0.0)


# ------------------------------------------------------------------ dumbbell on a disk
def _alpha_acc(model, x):
    """``(a, a', a'')`` and ``w'`` from the state and the model's right-hand side:
    ``rho = A r``, ``rho' = -w x rho + A r'``, ``rho'' = -w' x rho - w x rho' - w x A r'
    + A r''``, ``a = atan2(rho1, rho3)``, ``a'' = (rho3 rho1'' - rho1 rho3'') / l^2``."""
    from appdyn.dynamics.attitude import dcm_from_quat
    xd = model.rhs(x)
    A = dcm_from_quat(x[:4])
    r, w, rd = x[4:7], x[7:10], x[10:13]
    wd, rdd = xd[7:10], xd[10:13]
    rho = A @ r
    rho_d = -np.cross(w, rho) + A @ rd
    rho_dd = -np.cross(wd, rho) - np.cross(w, rho_d) - np.cross(w, A @ rd) + A @ rdd
    l2 = rho @ rho
    a = math.atan2(rho[0], rho[2])
    ad = (rho[2] * rho_d[0] - rho[0] * rho_d[2]) / l2
    add = (rho[2] * rho_dd[0] - rho[0] * rho_dd[2]) / l2
    return a, ad, add, wd


def test_dumbbell_disk_obeys_the_seed_flexibility_equation():
    """Seed: I0 (a'' + W2') - I0 (W3 sin a - W1 cos a)(W3 cos a + W1 sin a) + k a = 0."""
    rng = np.random.default_rng(7)
    for _ in range(10):
        m, l, k = rng.uniform(0.2, 2.0, 3)
        J = rng.uniform(0.5, 3.0, 3)
        model = dumbbell_disk(mass=m, arm=l, inertia=J, stiffness=k, time_constant=None)
        x = dumbbell_disk_state(rng.uniform(-1.2, 1.2), rng.uniform(-2, 2),
                                rng.uniform(-2, 2, 3), arm=l)
        a, ad, add, wd = _alpha_acc(model, x)
        W1, W2, W3 = x[7:10]
        I0 = 2 * m * l * l
        res = (I0 * (add + wd[1]) - I0 * (W3 * math.sin(a) - W1 * math.cos(a))
               * (W3 * math.cos(a) + W1 * math.sin(a)) + k * a)
        assert abs(res) < 1e-11 * max(1.0, k, I0 * abs(add))


def test_dumbbell_disk_planar_swing_is_harmonic_at_large_amplitude():
    kw = dict(mass=0.8, arm=0.6, inertia=(1.0, 1.3, 2.0), stiffness=3.0)
    model = dumbbell_disk(**kw)
    w = dumbbell_disk_frequency(mass=0.8, arm=0.6, inertia2=1.3, stiffness=3.0)
    a0, ad0 = 1.0, 0.4
    t = np.linspace(0.0, 3 * 2 * math.pi / w, 301)
    res = simulate(model, dumbbell_disk_state(a0, ad0, [0.0, 0.7, 0.0], arm=0.6), t,
                   method="rk8", steps=10, invariants=True)
    a = res.invariants["alpha"].ravel()
    closed = a0 * np.cos(w * t) + ad0 / w * np.sin(w * t)
    assert np.max(np.abs(a - closed)) < 1e-9
    assert np.max(np.abs(res.x[[7, 9]])) < 1e-12  # stays planar


def test_dumbbell_disk_tumbling_conserves_momentum_and_energy():
    model = dumbbell_disk(mass=0.5, arm=0.7, inertia=(1.0, 1.4, 2.2), stiffness=1.5)
    x0 = dumbbell_disk_state(0.5, -0.8, [0.6, -0.4, 1.1], arm=0.7)
    t = np.linspace(0.0, 10.0, 1001)
    res = simulate(model, x0, t, method="rk8", steps=10, invariants=True)
    H = np.asarray(res.invariants["angular_momentum"]).reshape(3, -1)
    E = res.invariants["energy"].ravel()
    assert np.max(np.abs(H - H[:, :1])) < 1e-10 * np.linalg.norm(H[:, 0])
    assert np.max(np.abs(E - E[0])) < 1e-10 * abs(E[0])
    assert np.max(res.invariants["constraint_residual"]) < 1e-10
    assert np.ptp(res.invariants["alpha"]) > 0.5


def test_dumbbell_disk_bad_input():
    with pytest.raises(ValueError, match="inertia"):
        dumbbell_disk(inertia=(1.0, -1.0, 2.0))
    with pytest.raises(ValueError, match="stiffness"):
        dumbbell_disk(stiffness=-1.0)
    with pytest.raises(ValueError, match="w"):
        dumbbell_disk_state(0.1, 0.0, [1.0, 2.0])
