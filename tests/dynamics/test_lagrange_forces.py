"""Lagrange's equations with generalized forces, explicit time and velocity-dependent
potentials (seed 002 Eqs. 5.20-5.29, 5.39-5.47): against the seed's closed forms and the
hand-written models."""
import casadi as ca
import numpy as np
import pytest

from appdyn.dynamics import simulate
from appdyn.dynamics.mechanisms import (double_pendulum, generalized_forces, lagrange_model,
                                        lagrange_terms, shaken_pendulum)

RNG = np.random.default_rng(34)


def _double_pendulum_forces(m1, m2, l1, l2, g):
    th, w = ca.SX.sym("th", 2), ca.SX.sym("w", 2)
    r1 = l1 * ca.vertcat(ca.sin(th[0]), ca.cos(th[0]))            # y down (seed Fig. 5.3)
    r2 = r1 + l2 * ca.vertcat(ca.sin(th[1]), ca.cos(th[1]))
    v1, v2 = ca.jtimes(r1, th, w), ca.jtimes(r2, th, w)
    T = 0.5 * m1 * ca.sumsqr(v1) + 0.5 * m2 * ca.sumsqr(v2)
    forces = [(ca.vertcat(0, m1 * g), r1), (ca.vertcat(0, m2 * g), r2)]
    return th, w, T, forces


def test_double_pendulum_generalized_forces_are_the_seeds():
    m1, m2, l1, l2, g = 1.3, 0.7, 0.9, 1.4, 9.80665
    th, w, T, forces = _double_pendulum_forces(m1, m2, l1, l2, g)
    Q = ca.Function("Q", [th], [generalized_forces(forces, th)])
    for _ in range(20):
        a = RNG.uniform(-np.pi, np.pi, 2)
        want = [-(m1 + m2) * g * l1 * np.sin(a[0]), -m2 * g * l2 * np.sin(a[1])]  # Sec. 5.3
        np.testing.assert_allclose(np.array(Q(a)).ravel(), want, rtol=1e-14, atol=1e-13)


def test_double_pendulum_by_forces_equals_the_hand_written_model():
    m1, m2, l1, l2, g = 1.3, 0.7, 0.9, 1.4, 9.80665
    th, w, T, forces = _double_pendulum_forces(m1, m2, l1, l2, g)
    model = lagrange_model({"theta1": th[0], "theta2": th[1]},
                           {"theta1_dot": w[0], "theta2_dot": w[1]}, T, forces=forces)
    ref = double_pendulum(mass1=m1, mass2=m2, length1=l1, length2=l2, gravity=g)
    for _ in range(20):
        x = RNG.uniform(-3, 3, 4)
        a, b = model.rhs(x), ref.rhs(x)
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12 * np.abs(b).max())


def test_rheonomic_shaken_point_pendulum_equals_the_shaken_pendulum():
    """``r = h(t) + l (sin th, -cos th)``: ``T`` depends on time explicitly (Eq. 5.33)."""
    m, l, g, ax, ay, om = 0.8, 0.6, 9.80665, 0.05, 0.03, 7.0
    th, w, t = ca.SX.sym("theta"), ca.SX.sym("theta_dot"), ca.SX.sym("t")
    r = ca.sin(om * t) * ca.vertcat(ax, ay) + l * ca.vertcat(ca.sin(th), -ca.cos(th))
    rdot = ca.jtimes(r, th, w) + ca.jacobian(r, t)
    model = lagrange_model({"theta": th}, {"theta_dot": w}, 0.5 * m * ca.sumsqr(rdot),
                           m * g * r[1], t=t)
    ref = shaken_pendulum(mass=m, inertia=0.0, length=l, gravity=g, amp_x=ax, amp_y=ay,
                          freq=om, damping=0.0)
    assert model.states == ref.states
    for _ in range(20):
        x = RNG.uniform(-3, 3, 3)
        np.testing.assert_allclose(model.rhs(x), ref.rhs(x), rtol=1e-12, atol=1e-12)


def _hoop(R, Om, g, m=0.4):
    """Bead on a hoop turning at ``Om`` about the vertical, in inertial coordinates (explicit
    time in ``r``), gravity as an applied force."""
    th, w, t = ca.SX.sym("theta"), ca.SX.sym("theta_dot"), ca.SX.sym("t")
    r = R * ca.vertcat(ca.sin(th) * ca.cos(Om * t), ca.sin(th) * ca.sin(Om * t), -ca.cos(th))
    rdot = ca.jtimes(r, th, w) + ca.jacobian(r, t)
    return lagrange_model({"theta": th}, {"theta_dot": w}, 0.5 * m * ca.sumsqr(rdot), t=t,
                          forces=[(ca.vertcat(0, 0, -m * g), r)])


def test_bead_on_rotating_hoop_equilibrium_and_frequency():
    """Equilibrium ``cos th = g / (R Om^2)``, small oscillation ``Om sin th`` about it."""
    R, Om, g = 0.5, 6.0, 9.80665
    model = _hoop(R, Om, g)
    th_e = np.arccos(g / (R * Om ** 2))
    for t0 in (0.0, 0.37, 2.1):  # the explicit time drops out of the equation
        np.testing.assert_allclose(model.rhs([th_e, 0.0, t0])[1], 0.0, atol=1e-12)
        np.testing.assert_allclose(model.rhs([-th_e, 0.0, t0])[1], 0.0, atol=1e-12)
        J = ca.Function("J", [model.f.sx_in(0)], [ca.jacobian(model.f(model.f.sx_in(0), [], [])
                                                              , model.f.sx_in(0))])
        k = float(np.array(J([th_e, 0.0, t0]))[1, 0])
        np.testing.assert_allclose(np.sqrt(-k), Om * np.sin(th_e), rtol=1e-12)
        # the bottom is unstable above the critical rate: th'' = th (Om^2 - g / R) near 0
        np.testing.assert_allclose(float(np.array(J([0.0, 0.0, t0]))[1, 0]), Om ** 2 - g / R,
                                   rtol=1e-12)


def _charge(e, m, B):
    x, v = ca.SX.sym("r", 3), ca.SX.sym("v", 3)
    A = 0.5 * ca.cross(ca.DM(B), x)                               # uniform field: B = curl A
    names = ("x", "y", "z")
    return x, v, lagrange_model(dict(zip(names, ca.vertsplit(x))),
                                dict(zip(("vx", "vy", "vz"), ca.vertsplit(v))),
                                0.5 * m * ca.sumsqr(v), velocity_potential=-e * ca.dot(v, A))


def test_velocity_potential_gives_the_lorentz_force():
    e, m, B = 1.7, 0.6, np.array([0.3, -0.8, 1.1])
    _, _, model = _charge(e, m, B)
    for _ in range(10):
        x = RNG.uniform(-2, 2, 6)
        np.testing.assert_allclose(model.rhs(x)[3:], e / m * np.cross(x[3:], B), rtol=1e-13,
                                   atol=1e-13)


def test_cyclotron_circle():
    """Gyration at ``e B / m`` on a circle of radius ``m v / (e B)``; speed (Jacobi) kept."""
    e, m, Bz, v0 = 2.0, 0.5, 1.5, 0.8
    _, _, model = _charge(e, m, [0.0, 0.0, Bz])
    wc, rc = e * Bz / m, m * v0 / (e * Bz)
    t = np.linspace(0.0, 2.0, 41)
    res = simulate(model, [0, 0, 0, v0, 0, 0.1], t, method="rk8", steps=400, jit=False)
    # from the origin moving along +x, the force e v x B = -e v0 Bz y: centre at (0, -rc)
    np.testing.assert_allclose(res.x[0], rc * np.sin(wc * t), atol=1e-10)
    np.testing.assert_allclose(res.x[1], -rc * (1 - np.cos(wc * t)), atol=1e-10)
    np.testing.assert_allclose(res.x[2], 0.1 * t, atol=1e-12)
    h = np.array([float(model.invariant("jacobi", res.x[:, k])) for k in (0, -1)])
    np.testing.assert_allclose(h, 0.5 * m * (v0 ** 2 + 0.01), rtol=1e-12)


def test_bad_arguments_are_named():
    q, v = ca.SX.sym("q"), ca.SX.sym("v")
    with pytest.raises(ValueError, match="`forces`\\[0\\]"):
        lagrange_terms(0.5 * v ** 2, 0.0, q, v, forces=[(ca.vertcat(1, 2), q)])
    with pytest.raises(TypeError, match="`forces`\\[0\\]"):
        lagrange_terms(0.5 * v ** 2, 0.0, q, v, forces=[("F", q)])
    with pytest.raises(TypeError, match="`t`"):
        lagrange_terms(0.5 * v ** 2, 0.0, q, v, t=1.0)
    with pytest.raises(ValueError, match="`velocity_potential`"):
        lagrange_terms(0.5 * v ** 2, 0.0, q, v, velocity_potential=ca.vertcat(v, v))
    with pytest.raises(ValueError, match="`rates`"):
        lagrange_model({"q": q}, {}, 0.5 * v ** 2)
