"""A particle in a noninertial frame (seed 002 Sec. 2.2, Eq. 2.1) and the seed's examples of
Sec. 2.4, against their closed forms and an inertial simulation of the same particle."""
import casadi as ca
import numpy as np
import pytest

from appdyn.dynamics import simulate
from appdyn.dynamics.mechanisms import (accelerometer, accelerometer_offset, foucault_pendulum,
                                        foucault_precession_rate, foucault_swing,
                                        noninertial_particle, skater_rate, skater_work,
                                        turntable, turntable_path, twirling_skater)


def _run(model, x0, t, steps=2000):
    res = simulate(model, x0, t, method="rk8", steps=steps, jit=False)
    assert res.success
    return res.x


def test_turntable_archimedean_spiral():
    w, v0 = 0.7, 0.3
    t = np.linspace(0.0, 10.0, 51)
    x = _run(turntable(w, mass=2.0), [0, 0, 0, v0, 0, 0], t, steps=1000)
    xs, ys = turntable_path(t, rate=w, speed=v0)
    np.testing.assert_allclose(x[0], xs, atol=1e-10)
    np.testing.assert_allclose(x[1], ys, atol=1e-10)
    r, phi = np.hypot(x[0], x[1]), np.unwrap(np.arctan2(x[1], x[0]))
    np.testing.assert_allclose(r[1:], -(v0 / w) * (phi[1:] - phi[1] - w * t[1]), atol=1e-9)


def test_turntable_free_particle_moves_straight_in_inertial_space():
    w, v0 = 0.7, 0.3
    t = np.linspace(0.0, 10.0, 11)
    x = _run(turntable(w), [0, 0, 0, v0, 0, 0], t, steps=500)
    X = np.cos(w * t) * x[0] - np.sin(w * t) * x[1]            # turntable -> inertial
    Y = np.sin(w * t) * x[0] + np.cos(w * t) * x[1]
    np.testing.assert_allclose(X, v0 * t, atol=1e-10)
    np.testing.assert_allclose(Y, 0.0, atol=1e-10)


def test_radial_groove_traces_an_archimedean_spiral_in_inertial_space():
    """Held in a radial groove at constant relative speed ``c`` (the groove's reaction
    ``(-m w^2 x, 2 m w x', 0)`` cancels the centrifugal and Coriolis forces): in inertial
    space ``r = c t``, ``phi = w t``, i.e. ``r = (c / w) phi``."""
    m, w, c = 0.5, 1.3, 0.2
    model = noninertial_particle(mass=m, rate=(0, 0, w),
                                 force=lambda r, v, t: m * ca.vertcat(-w ** 2 * r[0],
                                                                      2 * w * v[0], 0))
    t = np.linspace(0.0, 8.0, 17)
    x = _run(model, [0, 0, 0, c, 0, 0], t, steps=200)
    Z = (x[0] + 1j * x[1]) * np.exp(1j * w * t)                # turntable -> inertial
    np.testing.assert_allclose(np.abs(Z), c * t, atol=1e-12)
    np.testing.assert_allclose(np.abs(Z[1:]), c / w * np.unwrap(np.angle(Z[1:])), atol=1e-12)


def test_foucault_pendulum_precesses_at_omega_sin_latitude():
    args = dict(length=2.0, latitude=np.radians(40.0), earth_rate=0.05, gravity=9.80665)
    u, p = foucault_precession_rate(args["latitude"], earth_rate=0.05), np.sqrt(9.80665 / 2.0)
    periods = np.arange(0, 9)
    t = 2 * np.pi / p * periods                             # whole swings: z = a e^{-i u t}
    x = _run(foucault_pendulum(**args), [0.1, 0, 0, 0, 0, 0], t, steps=4000)
    xs, ys = foucault_swing(t, amplitude=0.1, **args)
    np.testing.assert_allclose(x[0], xs, atol=1e-11)
    np.testing.assert_allclose(x[1], ys, atol=1e-11)
    np.testing.assert_allclose(np.unwrap(np.arctan2(x[1], x[0])), -u * t, atol=1e-9)
    np.testing.assert_allclose(x[2], 0.0, atol=0)


@pytest.mark.parametrize("rate", [(0.0, 0.0, 0.0), (0.3, -0.5, 2.0)])
def test_accelerometer_rests_at_its_offset_whatever_the_gravity(rate):
    kw = dict(mass=0.02, stiffness=50.0, specific_force=(30.0, -4.0, 2.0), rate=rate,
              neutral=(0.1, 0.05, -0.02))
    d = accelerometer_offset(**kw)
    x = np.r_[np.array(kw["neutral"]) + d, 0, 0, 0]
    for g in ([0.0, 0.0, -9.8], [3.0, 1.0, -20.0]):
        np.testing.assert_allclose(accelerometer(gravity=g, damping=0.1, **kw).rhs(x), 0.0,
                                   atol=1e-12)
    if not any(rate):
        np.testing.assert_allclose(d, -0.02 * np.array(kw["specific_force"]) / 50.0, rtol=1e-14)


def test_accelerometer_spin_along_its_axis_closed_form():
    m, k, w, b, f = 0.02, 50.0, 12.0, 0.1, 30.0
    d = accelerometer_offset(mass=m, stiffness=k, specific_force=(f, 0, 0), rate=(0, 0, w),
                             neutral=(b, 0, 0))
    np.testing.assert_allclose(d, [(m * w ** 2 * b - m * f) / (k - m * w ** 2), 0, 0],
                               rtol=1e-13)
    with pytest.raises(ValueError, match="`rate`"):
        accelerometer_offset(mass=m, stiffness=k, rate=(0, 0, 60.0))


def test_twirling_skater_conserves_w_r2_and_the_work_is_the_energy_gained():
    m, w0, r0, c = 1.5, 2.0, 1.0, 0.1
    t = np.linspace(0.0, 6.0, 31)
    model = twirling_skater(mass=m, rate0=w0, radius0=r0, pull_speed=c)
    x = _run(model, [r0, 0, 0, -c, 0, 0, 0.0], t, steps=1000)
    np.testing.assert_allclose(x[0], r0 - c * t, atol=1e-11)
    np.testing.assert_allclose(x[1], 0.0, atol=1e-11)
    w = skater_rate(t, rate0=w0, radius0=r0, pull_speed=c)
    np.testing.assert_allclose(w * x[0] ** 2, w0 * r0 ** 2, rtol=1e-11)
    T = 0.5 * m * ((x[3] ** 2 + x[4] ** 2) + (w * x[0]) ** 2)  # inertial: radial + w r
    np.testing.assert_allclose(T - T[0], [skater_work(r, mass=m, rate0=w0, radius0=r0)
                                          for r in x[0]], rtol=1e-10, atol=1e-12)
    # the frame spins up, w' = 2 w c / r: the Euler force -m w' r along -y balances Coriolis
    euler = model.invariant("euler_force", x[:, 10]).ravel()
    np.testing.assert_allclose(euler, [0, -m * 2 * w[10] * c, 0], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(euler + model.invariant("coriolis_force", x[:, 10]).ravel(), 0.0,
                               atol=1e-9)


AXIS = np.array([1.0, 2.0, 2.0]) / 3.0


def _rotation(theta, lib):
    """Frame -> inertial: a turn ``theta`` about the fixed axis ``AXIS`` (Rodrigues)."""
    n = AXIS
    K = np.array([[0.0, -n[2], n[1]], [n[2], 0.0, -n[0]], [-n[1], n[0], 0.0]])
    if lib is ca:
        return ca.DM.eye(3) + ca.sin(theta) * ca.DM(K) + (1 - ca.cos(theta)) * ca.DM(K @ K)
    return np.eye(3) + np.sin(theta) * K + (1 - np.cos(theta)) * K @ K


def test_rotating_frame_simulation_equals_the_inertial_one_transformed():
    """Same particle, a spring to a fixed inertial point, seen from a frame spun up about a
    tilted axis (``w = (a + b t) n``) whose origin accelerates: every term of Eq. 2.1."""
    m, k, a, b = 0.7, 3.0, 0.4, 0.15
    a0 = np.array([0.2, -0.1, 0.3])                  # origin: R0 = 1/2 a0 t^2 (inertial)
    P = np.array([1.0, -0.5, 0.2])                   # the spring's inertial anchor

    def theta(t):
        return a * t + 0.5 * b * t ** 2

    def frame_force(r, v, t):
        Rt = _rotation(theta(t), ca).T
        return -k * (r + ca.mtimes(Rt, ca.DM(0.5 * a0) * t ** 2 - ca.DM(P)))

    rot = noninertial_particle(mass=m, rate=lambda t: (a + b * t) * ca.DM(AXIS),
                               origin_acceleration=lambda t: ca.mtimes(
                                   _rotation(theta(t), ca).T, ca.DM(a0)),
                               force=frame_force)
    fixed = noninertial_particle(mass=m, force=lambda r, v, t: -k * (r - ca.DM(P)))
    r0, v0 = np.array([0.3, 0.1, -0.4]), np.array([0.05, 0.2, 0.0])
    t = np.linspace(0.0, 4.0, 21)
    xr = _run(rot, np.r_[r0, v0, 0.0], t, steps=400)
    xi = _run(fixed, np.r_[r0, v0 + a * np.cross(AXIS, r0)], t, steps=400)  # V = v + w x r
    for j, tj in enumerate(t):
        R = _rotation(theta(tj), np)
        np.testing.assert_allclose(xr[0:3, j], R.T @ (xi[0:3, j] - 0.5 * a0 * tj ** 2),
                                   atol=1e-10)
        w = (a + b * tj) * AXIS
        np.testing.assert_allclose(R @ (xr[3:6, j] + np.cross(w, xr[0:3, j])) + a0 * tj,
                                   xi[3:6, j], atol=1e-10)


def test_bad_arguments_are_named():
    with pytest.raises(ValueError, match="`rate`"):
        noninertial_particle(rate=[1.0, 2.0])
    with pytest.raises(ValueError, match="`origin_acceleration`"):
        noninertial_particle(origin_acceleration=lambda t: [t, t])
    with pytest.raises(TypeError, match="`force`"):
        noninertial_particle(force=3.0)
    with pytest.raises(ValueError, match="`mass`"):
        noninertial_particle(mass=0.0)
    with pytest.raises(TypeError, match="`rate`"):
        noninertial_particle(rate=lambda t: "x")


def test_rate_as_a_casadi_function_and_a_given_rate_dot():
    t = ca.SX.sym("t")
    spun = noninertial_particle(rate=ca.Function("w", [t], [ca.vertcat(0, 0, 0.1 * t)]))
    x = [1.0, 0, 0, 0, 0, 0, 0.0]
    np.testing.assert_allclose(spun.rhs(x)[4], -0.1, rtol=1e-15)       # Euler: -w' x r
    held = noninertial_particle(rate=lambda t: [0, 0, 0.1 * t], rate_dot=[0.0, 0.0, 0.0])
    np.testing.assert_allclose(held.rhs(x)[3:6], 0.0, atol=0)
