"""The seeds' worked mechanisms against closed forms and independent formulations.

Every right-hand side is checked against a *different* derivation written here (Newton with
the constraint forces solved by hand, or Euler's equations with the seed's Lagrange
multiplier), and every run against a closed form or a conservation law.
"""
import math
import pickle

import numpy as np
import pytest
from scipy.integrate import cumulative_simpson, solve_ivp
from scipy.linalg import eigh

from appdyn.dynamics import simulate
from appdyn.dynamics.clock import clock_index
from appdyn.dynamics.linearize import linearization
from appdyn.dynamics.mechanisms import (GRAVITY, conical_rate, double_pendulum, double_pendulum_modes,
                                 equivalent_length, kapitza_frequency, natural_frequency,
                                 pendulum_period, pendulum_swing, resonance_tongue,
                                 shaken_pendulum, spherical_mass_matrix, spherical_pendulum,
                                 variable_length_pendulum)

G = 9.81


# ------------------------------------------------------------------ double pendulum
def double_pendulum_newton(x, m1, m2, l1, l2, g):
    """Accelerations by Newton's law on each mass with the two rod tensions as unknowns.

    y down; e_i = (sin th_i, cos th_i) along rod i, n_i = (cos th_i, -sin th_i) normal;
    a1 = l1 (th1'' n1 - th1'^2 e1), a2 = a1 + l2 (th2'' n2 - th2'^2 e2);
    m1 a1 = -T1 e1 + T2 e2 + m1 g j,  m2 a2 = -T2 e2 + m2 g j.  Unknowns th1'', th2'', T1, T2.
    """
    th1, th2, w1, w2 = x
    e1, e2 = np.array([math.sin(th1), math.cos(th1)]), np.array([math.sin(th2), math.cos(th2)])
    n1, n2 = np.array([math.cos(th1), -math.sin(th1)]), np.array([math.cos(th2), -math.sin(th2)])
    j = np.array([0.0, 1.0])
    M = np.zeros((4, 4))
    rhs = np.zeros(4)
    # mass 1: m1 l1 n1 th1'' + T1 e1 - T2 e2 = m1 g j + m1 l1 th1'^2 e1
    M[0:2, 0], M[0:2, 2], M[0:2, 3] = m1 * l1 * n1, e1, -e2
    rhs[0:2] = m1 * g * j + m1 * l1 * w1 ** 2 * e1
    # mass 2: m2 (l1 n1 th1'' + l2 n2 th2'') + T2 e2 = m2 g j + m2 (l1 w1^2 e1 + l2 w2^2 e2)
    M[2:4, 0], M[2:4, 1], M[2:4, 3] = m2 * l1 * n1, m2 * l2 * n2, e2
    rhs[2:4] = m2 * g * j + m2 * (l1 * w1 ** 2 * e1 + l2 * w2 ** 2 * e2)
    return np.linalg.solve(M, rhs)[:2]


def test_double_pendulum_matches_newton_with_rod_tensions():
    rng = np.random.default_rng(1)
    for _ in range(20):
        m1, m2, l1, l2 = rng.uniform(0.3, 3.0, 4)
        model = double_pendulum(mass1=m1, mass2=m2, length1=l1, length2=l2, gravity=G)
        x = rng.uniform(-3, 3, 4)
        acc = model.rhs(x)[2:]
        np.testing.assert_allclose(acc, double_pendulum_newton(x, m1, m2, l1, l2, G),
                                   rtol=1e-12, atol=1e-12 * np.abs(acc).max())


def test_double_pendulum_conserves_energy_in_chaotic_motion():
    model = double_pendulum(mass1=1.0, mass2=0.7, length1=1.0, length2=0.6, gravity=G)
    t = np.linspace(0.0, 20.0, 2001)
    res = simulate(model, [2.0, -1.0, 0.0, 3.0], t, method="rk8", steps=8, invariants=True)
    E = res.invariants["energy"]
    assert np.max(np.abs(E - E[0])) / abs(E[0]) < 1e-11
    assert np.ptp(res.x[1]) > 6.0  # the lower rod went over the top: a hard run


@pytest.mark.parametrize("m1, m2, l1, l2", [(1.0, 1.0, 1.0, 1.0), (2.0, 0.5, 0.7, 1.3),
                                            (0.1, 3.0, 1.5, 0.4)])
def test_double_pendulum_normal_modes(m1, m2, l1, l2):
    """Eigenvalues of the exact linearization = +-i w of the closed form = the generalized
    eigenvalues of (K, M) written here; equal masses and lengths: w^2 = (2 -+ sqrt 2) g/l."""
    model = double_pendulum(mass1=m1, mass2=m2, length1=l1, length2=l2, gravity=G)
    lin = linearization(model, np.zeros(4))
    assert lin.is_equilibrium
    ev = np.linalg.eigvals(lin.A)
    np.testing.assert_allclose(np.abs(ev.real), 0.0, atol=1e-12)
    w_lin = np.sort(ev.imag[ev.imag > 0])
    w_closed = double_pendulum_modes(mass1=m1, mass2=m2, length1=l1, length2=l2, gravity=G)
    M = np.array([[(m1 + m2) * l1 ** 2, m2 * l1 * l2], [m2 * l1 * l2, m2 * l2 ** 2]])
    K = np.diag([(m1 + m2) * G * l1, m2 * G * l2])
    w_eigh = np.sqrt(eigh(K, M, eigvals_only=True))
    np.testing.assert_allclose(w_lin, w_closed, rtol=1e-12)
    np.testing.assert_allclose(w_eigh, w_closed, rtol=1e-12)
    if (m1, m2, l1, l2) == (1.0, 1.0, 1.0, 1.0):
        special = np.sqrt([(2 - math.sqrt(2)) * G, (2 + math.sqrt(2)) * G])
        np.testing.assert_allclose(w_closed, special, rtol=1e-14)


# ------------------------------------------------------------ variable-length pendulum
LAW = dict(length=1.0, length_rate=-0.05, length_amp=0.1, length_freq=2.5)


def length_law(t):
    L0, v, a, nu = LAW["length"], LAW["length_rate"], LAW["length_amp"], LAW["length_freq"]
    return (L0 + v * t + a * np.sin(nu * t), v + a * nu * np.cos(nu * t),
            -a * nu ** 2 * np.sin(nu * t))


def test_variable_length_matches_cartesian_newton_with_the_string_force():
    """Newton in Cartesian coordinates, the string force S solved from the second derivative
    of |r|^2 = l(t)^2: r.r'' + |r'|^2 = l l'' + l'^2 with m r'' = m g j - S r/|r| gives
    S = m (g y + |r'|^2 - l l'' - l'^2) / l. The angle atan2(x, y) agrees with Eq. 5.51."""
    m = 2.0
    model = variable_length_pendulum(mass=m, gravity=G, **LAW)

    def cartesian(t, z):
        x, y, vx, vy = z
        l, ld, ldd = length_law(t)
        S = m * (G * y + vx * vx + vy * vy - l * ldd - ld * ld) / l
        r = math.hypot(x, y)
        return [vx, vy, -S * x / (r * m), G - S * y / (r * m)]

    th0, w0 = 1.0, 0.3
    l, ld, _ = length_law(0.0)
    z0 = [l * math.sin(th0), l * math.cos(th0), ld * math.sin(th0) + l * math.cos(th0) * w0,
          ld * math.cos(th0) - l * math.sin(th0) * w0]
    t = np.linspace(0.0, 6.0, 61)
    ref = solve_ivp(cartesian, (0.0, 6.0), z0, method="DOP853", rtol=1e-13, atol=1e-13, t_eval=t)
    res = simulate(model, [th0, w0, 0.0], t, method="rk8", steps=100, invariants=["tension"])
    np.testing.assert_allclose(res.x[0], np.arctan2(ref.y[0], ref.y[1]), rtol=0, atol=1e-10)
    l, ld, ldd = length_law(t)
    S_ref = m * (G * ref.y[1] + ref.y[2] ** 2 + ref.y[3] ** 2 - l * ldd - ld ** 2) / l
    np.testing.assert_allclose(res.invariants["tension"], S_ref, rtol=1e-9)


def test_variable_length_energy_change_is_the_work_of_the_string():
    """E(t) - E(0) = int_0^t -S l' dt (derived in the model's docstring), with E and S
    written here from the state; and d/dt (m l^2 th') = -m g l sin th."""
    m = 2.0
    model = variable_length_pendulum(mass=m, gravity=G, **LAW)
    t = np.linspace(0.0, 6.0, 6001)
    res = simulate(model, [1.0, 0.3, 0.0], t, method="rk8", steps=2, invariants=True)
    th, w = res.x[0], res.x[1]
    l, ld, ldd = length_law(res.x[2])  # the model's clock (it carries 1e-13 of round-off)
    E = 0.5 * m * (ld ** 2 + l ** 2 * w ** 2) - m * G * l * np.cos(th)
    S = m * (G * np.cos(th) + l * w ** 2 - ldd)
    work = cumulative_simpson(-S * ld, x=t, initial=0.0)
    assert np.ptp(E) > 5.0  # the string did work
    np.testing.assert_allclose(E - E[0], work, rtol=0, atol=1e-10 * np.ptp(E))
    np.testing.assert_allclose(res.invariants["energy"], E, rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(res.invariants["string_power"], -S * ld, rtol=1e-12, atol=1e-12)
    h = m * l ** 2 * w
    impulse = cumulative_simpson(-m * G * l * np.sin(th), x=t, initial=0.0)
    np.testing.assert_allclose(h - h[0], impulse, rtol=0, atol=1e-10 * np.ptp(h))
    np.testing.assert_allclose(res.invariants["momentum"], h, rtol=1e-13, atol=1e-13)


def test_constant_length_is_the_exact_simple_pendulum():
    """Large swing (2 rad) against the Jacobi-elliptic solution over three periods."""
    model = variable_length_pendulum(length=0.8, gravity=G)
    T = pendulum_period(2.0, length=0.8, gravity=G)
    t = np.linspace(0.0, 3 * T, 301)
    res = simulate(model, [2.0, 0.0, 0.0], t, method="rk8", steps=20, invariants=["energy"])
    np.testing.assert_allclose(res.x[0], pendulum_swing(t, 2.0, length=0.8, gravity=G),
                               rtol=0, atol=1e-10)
    E = res.invariants["energy"]
    assert np.max(np.abs(E - E[0])) < 1e-12 * abs(E[0])
    # small amplitude: the period tends to 2 pi sqrt(l/g)
    small = pendulum_period(1e-6, length=0.8, gravity=G)
    assert abs(small / (2 * math.pi * math.sqrt(0.8 / G)) - 1) < 1e-12


def test_slowly_reeled_pendulum_keeps_its_action():
    """Adiabatic invariant of the small swing: J = E_osc / w with w = sqrt(g/l) stays
    constant to O(eps), eps = |l'| / (l w), while E_osc grows by l^(-1/2) (amplitude
    ~ l^(-3/4)): reeling in from 1 m to 0.5 m."""
    rate = -0.01
    model = variable_length_pendulum(length=1.0, length_rate=rate, gravity=G)
    t = np.linspace(0.0, 50.0, 20001)
    res = simulate(model, [0.01, 0.0, 0.0], t, method="rk8", steps=1)
    l = 1.0 + rate * t
    w = np.sqrt(G / l)
    E_osc = 0.5 * l ** 2 * res.x[1] ** 2 + 0.5 * G * l * res.x[0] ** 2
    J = E_osc / w
    eps = np.max(abs(rate) / (l * w))
    assert np.max(np.abs(J / J[0] - 1)) < eps
    assert E_osc[-1] / E_osc[0] > 1.4


# ---------------------------------------------------------------- spherical pendulum
def multiplier_accelerations(sequence, x, m, l, I, g):
    """The seed's route (Ch. 6 Ex. 1): Euler's equations about the pivot with the gimbal's
    constraint torque B^T lambda, solved with the two angle accelerations as one linear
    system. Body rates w = J(q) q' (``w' = J q'' + b``), gravity torque l e3 x m g k."""
    Ip = np.diag([m * l * l + I, m * l * l + I, I])
    if sequence == "3-1-3":
        psi, th, dpsi, dth = x
        st, ct = math.sin(th), math.cos(th)
        w = np.array([dth, dpsi * st, dpsi * ct])
        J = np.array([[0.0, 1.0], [st, 0.0], [ct, 0.0]])            # columns psi'', th''
        b = np.array([0.0, dpsi * dth * ct, -dpsi * dth * st])
        k_body = np.array([0.0, st, ct])
        B = np.array([0.0, -ct, st])                                 # phi' = 0
    else:
        th, phi, dth, dphi = x
        sp, cp = math.sin(phi), math.cos(phi)
        w = np.array([dphi, dth * cp, -dth * sp])
        J = np.array([[0.0, 1.0], [cp, 0.0], [-sp, 0.0]])            # columns th'', phi''
        b = np.array([0.0, -dth * dphi * sp, -dth * dphi * cp])
        k_body = np.array([-math.sin(th), sp * math.cos(th), cp * math.cos(th)])
        B = np.array([0.0, sp, cp])                                  # psi' = 0
    L = m * g * l * np.cross([0.0, 0.0, 1.0], k_body)
    A = np.column_stack([Ip @ J, -B])
    sol = np.linalg.solve(A, L - np.cross(w, Ip @ w) - Ip @ b)
    return sol[:2]


@pytest.mark.parametrize("sequence", ["3-1-3", "3-2-1"])
def test_spherical_pendulum_matches_euler_equations_with_the_multiplier(sequence):
    rng = np.random.default_rng(4)
    for _ in range(20):
        m, l, I = rng.uniform(0.5, 2.0), rng.uniform(0.5, 2.0), rng.uniform(0.0, 0.5)
        model = spherical_pendulum(sequence, mass=m, length=l, inertia=I, gravity=G)
        x = np.concatenate([rng.uniform(-1.2, 1.2, 2), rng.normal(size=2)])
        acc = model.rhs(x)[2:]
        np.testing.assert_allclose(acc, multiplier_accelerations(sequence, x, m, l, I, G),
                                   rtol=1e-12, atol=1e-12 * np.abs(acc).max())


def bob_position(sequence, q, l):
    if sequence == "3-1-3":
        psi, th = q
        return l * np.array([np.sin(th) * np.sin(psi), -np.sin(th) * np.cos(psi), np.cos(th)])
    th, phi = q
    return l * np.array([np.sin(th) * np.cos(phi), -np.sin(phi), np.cos(th) * np.cos(phi)])


@pytest.mark.parametrize("inertia", [0.0, 0.05])
def test_conical_motion_of_the_313_form(inertia):
    """theta = alpha, psi' = sqrt(g / (l cos alpha)) is a steady motion for any I."""
    alpha, l = 0.7, 1.3
    rate = conical_rate(alpha, length=l, gravity=G)
    assert rate == pytest.approx(math.sqrt(G / (l * math.cos(alpha))), rel=1e-15)
    model = spherical_pendulum("3-1-3", mass=0.8, length=l, inertia=inertia, gravity=G)
    t = np.linspace(0.0, 10.0, 101)
    res = simulate(model, [0.0, alpha, rate, 0.0], t, method="rk8", steps=10)
    np.testing.assert_allclose(res.x[1], alpha, rtol=0, atol=1e-12)
    np.testing.assert_allclose(res.x[0], rate * t, rtol=1e-13)


def test_conical_motion_of_the_321_form_point_mass():
    """For I = 0 the 3-2-1 model is the point-mass pendulum: the bob circles at depth
    l cos alpha with the conical rate, though theta and phi both oscillate."""
    alpha, l = 0.7, 1.3
    rate = conical_rate(alpha, length=l, gravity=G)
    model = spherical_pendulum("3-2-1", mass=0.8, length=l, inertia=0.0, gravity=G)
    t = np.linspace(0.0, 10.0, 101)
    res = simulate(model, [alpha, 0.0, 0.0, -math.sin(alpha) * rate], t, method="rk8", steps=20)
    pos = bob_position("3-2-1", res.x[:2], l)
    circle = l * np.array([math.sin(alpha) * np.cos(rate * t), math.sin(alpha) * np.sin(rate * t),
                           np.full_like(t, math.cos(alpha))])
    np.testing.assert_allclose(pos, circle, rtol=0, atol=1e-10)
    np.testing.assert_allclose(model.invariant("position", res.x), pos, rtol=0, atol=1e-15)


@pytest.mark.parametrize("sequence, inertia", [("3-1-3", 0.02), ("3-2-1", 0.0), ("3-2-1", 0.02)])
def test_spherical_pendulum_invariants(sequence, inertia):
    """Energy is conserved by both; the vertical angular momentum by the 3-1-3 gimbal
    (about the vertical) always, by the 3-2-1 gimbal (horizontal outer axis) only for I = 0."""
    model = spherical_pendulum(sequence, mass=1.1, length=0.9, inertia=inertia, gravity=G)
    x0 = [0.3, 0.8, 1.5, -0.4] if sequence == "3-1-3" else [0.8, 0.3, -0.4, 1.5]
    t = np.linspace(0.0, 20.0, 401)
    res = simulate(model, x0, t, method="rk8", steps=20, invariants=True)
    E, H = res.invariants["energy"], res.invariants["momentum_vertical"]
    assert np.max(np.abs(E - E[0])) < 1e-12 * np.max(np.abs(E))
    if sequence == "3-2-1" and inertia > 0:
        assert np.ptp(H) > 1e-4 * np.max(np.abs(H))      # the gimbal's vertical torque
    else:
        assert np.ptp(H) < 1e-12 * np.max(np.abs(H))


def test_spherical_pendulums_are_simple_pendulums_at_small_angles():
    """Seed: (I + m l^2) q'' + m g l q = 0 for both angles of the 3-2-1 form."""
    m, l, I = 1.2, 0.7, 0.03
    lin = linearization(spherical_pendulum("3-2-1", mass=m, length=l, inertia=I, gravity=G),
                        np.zeros(4))
    ev = np.linalg.eigvals(lin.A)
    np.testing.assert_allclose(np.sort(np.abs(ev.imag)), math.sqrt(m * G * l / (I + m * l * l)),
                               rtol=1e-14)
    np.testing.assert_allclose(ev.real, 0.0, atol=1e-14)


def pole_passage(inertia):
    """The same physical start for both forms: bob at 0.5 rad from the vertical with a small
    sideways speed, so that it swings within a few mm of the bottom."""
    eps, th0 = 0.02, 0.5
    a = spherical_pendulum("3-1-3", inertia=inertia, gravity=G)
    b = spherical_pendulum("3-2-1", inertia=inertia, gravity=G)
    xa = [0.0, th0, eps, 0.0]
    xb = [0.0, th0, math.sin(th0) * eps / math.cos(th0), 0.0]
    np.testing.assert_allclose(a.invariant("position", xa), b.invariant("position", xb), atol=1e-15)
    return (a, xa), (b, xb)


@pytest.mark.slow
def test_313_form_degrades_near_the_bottom_when_I_is_small_and_321_does_not():
    """Ch. 6 Ex. 1: 'for I << m l^2 these equations become almost singular for small
    theta'. Measured on a swing through the bottom (I / m l^2 = 1e-4 and 1e-6):
    * the 3-1-3 mass matrix has condition (m l^2 + I) / I at theta = 0, the 3-2-1 one 1;
    * the stiffest Jacobian eigenvalue along the run is ~40x the 3-2-1 form's;
    * a fixed rk8 step of 10 ms loses 1e-3 of the energy (3-1-3) against round-off (3-2-1);
    * 'auto' needs ever more steps as I shrinks for 3-1-3 and at I / m l^2 = 1e-6 cannot
      verify rtol 1e-10 at all (status 2: the tolerance lies below that form's round-off
      floor), while 3-2-1 is verified with the same few steps at both (counted as every
      step of every run it makes, ``n_steps``: per output interval is not a step count on
      the dense path, whose steps follow the error estimate)."""
    for sequence, cond in (("3-1-3", 1e4 + 1), ("3-2-1", 1.0)):
        matrix = spherical_mass_matrix(sequence, [0.0, 0.0], inertia=1e-4)
        assert np.linalg.cond(matrix) == pytest.approx(cond, rel=1e-12)
    t = np.linspace(0.0, 2.0, 201)
    substeps, drift, status = {}, {}, {}
    for inertia in (1e-4, 1e-6):
        for model, x0 in pole_passage(inertia):
            key = (model.name, inertia)
            fixed = simulate(model, x0, t, method="rk8", steps=1, invariants=["energy"])
            E = fixed.invariants["energy"]
            drift[key] = np.nanmax(np.abs(E - E[0])) if np.all(np.isfinite(E)) else np.inf
            auto = simulate(model, x0, t, method="auto", rtol=1e-10, atol=1e-10)
            assert auto.success or model.name == "spherical_pendulum_313"
            substeps[key] = auto.n_steps
            status[key] = auto.status
            if inertia == 1e-4:
                rho = max(np.max(np.abs(np.linalg.eigvals(
                    linearization(model, x, allow_non_equilibrium=True).A))) for x in auto.x.T)
                drift[key + ("rho",)] = rho
    a, b = "spherical_pendulum_313", "spherical_pendulum_321"
    assert drift[(a, 1e-4)] > 1e-3 and drift[(b, 1e-4)] < 1e-13
    assert drift[(a, 1e-6)] > 1.0 and drift[(b, 1e-6)] < 1e-13
    assert drift[(a, 1e-4, "rho")] > 30 * drift[(b, 1e-4, "rho")]
    assert substeps[(a, 1e-6)] > substeps[(a, 1e-4)] and status[(a, 1e-6)] == 2
    assert status[(b, 1e-6)] == status[(b, 1e-4)] == 0
    assert substeps[(a, 1e-4)] > 3 * substeps[(b, 1e-4)]
    assert substeps[(b, 1e-6)] == substeps[(b, 1e-4)]


# -------------------------------------------------------------------- shaken pendulum
SHAKE = dict(mass=1.3, inertia=0.02, length=0.3, gravity=G, amp_y=0.03, amp_x=0.02,
             freq=17.0, damping=0.01)


def newton_euler_about_mass_centre(t, z, mass, inertia, length, gravity, amp_y, amp_x, freq,
                                   damping):
    """Newton for the mass centre and Euler about it, the hinge force R = (Rx, Ry) as an
    unknown: m (a_h + l (th'' n - th'^2 e)) - R = m g_vec, I_c th'' + (s x R)_z = -c th',
    with s = l e from the hinge to the mass centre (so the hinge is at -s from it),
    e = (sin th, -cos th), n = (cos th, sin th); unknowns (th'', Rx, Ry)."""
    th, w = z
    e, n = np.array([math.sin(th), -math.cos(th)]), np.array([math.cos(th), math.sin(th)])
    a_h = -freq ** 2 * math.sin(freq * t) * np.array([amp_x, amp_y])
    s = length * e
    M = np.zeros((3, 3))
    rhs = np.zeros(3)
    M[0:2, 0], M[0:2, 1:3] = mass * length * n, -np.eye(2)
    rhs[0:2] = mass * np.array([0.0, -gravity]) - mass * a_h + mass * length * w ** 2 * e
    # moment of R (acting at the hinge, at -s from the mass centre): (-s) x R
    M[2, 0], M[2, 1], M[2, 2] = inertia, -s[1], s[0]
    rhs[2] = -damping * w
    thdd, Rx, Ry = np.linalg.solve(M, rhs)
    return thdd, np.array([Rx, Ry])


def test_shaken_pendulum_euler_law_agrees_with_newton_euler_to_1e_10():
    model = shaken_pendulum(**SHAKE)
    t = np.linspace(0.0, 3.0, 61)
    res = simulate(model, [0.8, -1.0, 0.0], t, method="rk8", steps=200, invariants=True)

    def rhs(tt, z):
        return [z[1], newton_euler_about_mass_centre(tt, z, **SHAKE)[0]]

    ref = solve_ivp(rhs, (0.0, 3.0), [0.8, -1.0], method="DOP853", rtol=1e-13, atol=1e-14,
                    t_eval=t)
    assert np.max(np.abs(res.x[:2] - ref.y)) < 1e-10
    assert np.ptp(res.x[0]) > 1.0
    forces = np.array([newton_euler_about_mass_centre(tt, z, **SHAKE)[1]
                       for tt, z in zip(res.x[2], res.x[:2].T)]).T
    np.testing.assert_allclose(res.invariants["hinge_force"], forces, rtol=1e-12,
                               atol=1e-12 * np.abs(forces).max())


def test_shaken_pendulum_is_the_seeds_equation_for_a_horizontal_shake():
    """Seed 000: I theta'' + m g l sin theta = m l A w^2 sin(w t) cos theta (I about the hinge)."""
    m, Ic, l, A, w = 0.9, 0.015, 0.2, 0.05, 12.0
    model = shaken_pendulum(mass=m, inertia=Ic, length=l, gravity=G, amp_y=0.0, amp_x=A, freq=w)
    rng = np.random.default_rng(7)
    for th, thd, t in rng.uniform(-3, 3, (10, 3)):
        Ih = Ic + m * l * l
        forcing = m * l * A * w ** 2 * math.sin(w * t) * math.cos(th)
        expected = (forcing - m * G * l * math.sin(th)) / Ih
        assert model.rhs([th, thd, t])[1] == pytest.approx(expected, rel=1e-13, abs=1e-13)


def test_shaken_pendulum_closed_forms():
    m, Ic, l = 1.3, 0.02, 0.3
    Ih = Ic + m * l * l
    assert equivalent_length(mass=m, inertia=Ic, length=l) == pytest.approx(Ih / (m * l), rel=1e-15)
    w0 = natural_frequency(mass=m, inertia=Ic, length=l, gravity=G)
    assert w0 == pytest.approx(math.sqrt(m * G * l / Ih), rel=1e-15)
    model = shaken_pendulum(mass=m, inertia=Ic, length=l, gravity=G, amp_y=0.0)
    lin = linearization(model, [0.0, 0.0, 0.0], allow_non_equilibrium=True)
    ev = np.linalg.eigvals(lin.A[:2, :2])
    np.testing.assert_allclose(np.sort(ev.imag), [-w0, w0], rtol=1e-14)
    # Kapitza: a0(q) = -q^2/2 + 7 q^4/128 - 29 q^6/2304 + O(q^8), q = 2 a / l_eff
    a = 0.01
    q = 2 * a * m * l / Ih
    a0 = -q ** 2 / 2 + 7 * q ** 4 / 128 - 29 * q ** 6 / 2304
    exact = kapitza_frequency(a, mass=m, inertia=Ic, length=l, gravity=G)
    assert exact == pytest.approx(2 * w0 / math.sqrt(-a0), rel=1e-8)
    approx = kapitza_frequency(a, mass=m, inertia=Ic, length=l, gravity=G, exact=False)
    assert approx == pytest.approx(math.sqrt(2 * G * Ih / (m * l)) / a, rel=1e-15)
    assert abs(exact / approx - 1) < q ** 2  # averaging is first order in q^2
    # first tongue: a1, b1 = 1 +- q - q^2/8 -+ q^3/64 + O(q^4)
    low, high = resonance_tongue(a, mass=m, inertia=Ic, length=l, gravity=G)
    assert low == pytest.approx(2 * w0 / math.sqrt(1 + q - q ** 2 / 8 - q ** 3 / 64), rel=1e-6)
    assert high == pytest.approx(2 * w0 / math.sqrt(1 - q - q ** 2 / 8 + q ** 3 / 64), rel=1e-6)


# ------------------------------------------------------------------------ plumbing
def test_models_pickle_and_share_one_function_per_kind():
    a, b = shaken_pendulum(freq=10.0), shaken_pendulum(freq=20.0)
    assert a.f is b.f and a.p_default[6] == 10.0 and b.p_default[6] == 20.0
    loaded = pickle.loads(pickle.dumps(a))
    x = [0.3, 0.2, 0.1]
    np.testing.assert_array_equal(loaded.rhs(x), a.rhs(x))
    assert clock_index(loaded) == 2 and loaded.params == a.params
    assert double_pendulum().p_default[-1] == GRAVITY


@pytest.mark.parametrize("call, exc, name", [
    (lambda: double_pendulum(mass1=0.0), ValueError, "mass1"),
    (lambda: double_pendulum(length2=-1.0), ValueError, "length2"),
    (lambda: double_pendulum(gravity=math.nan), ValueError, "gravity"),
    (lambda: double_pendulum_modes(mass2="heavy"), TypeError, "mass2"),
    (lambda: variable_length_pendulum(length=0.0), ValueError, "length"),
    (lambda: variable_length_pendulum(length_rate=math.inf), ValueError, "length_rate"),
    (lambda: spherical_pendulum("3-2-3"), ValueError, "sequence"),
    (lambda: spherical_pendulum(313), TypeError, "sequence"),
    (lambda: spherical_pendulum("3-1-3", inertia=-0.1), ValueError, "inertia"),
    (lambda: spherical_mass_matrix("3-1-3", [0.0]), ValueError, "q"),
    (lambda: conical_rate(math.pi / 2), ValueError, "cone_angle"),
    (lambda: shaken_pendulum(damping=-1.0), ValueError, "damping"),
    (lambda: shaken_pendulum(mass=0.0), ValueError, "mass"),
    (lambda: shaken_pendulum(freq=None), TypeError, "freq"),
    (lambda: shaken_pendulum(omega=3.0), TypeError, "omega"),
    (lambda: kapitza_frequency(0.0), ValueError, "amp_y"),
    (lambda: kapitza_frequency(0.2), ValueError, "amp_y"),
    (lambda: resonance_tongue(-0.01), ValueError, "amp_y"),
    (lambda: pendulum_swing([0.0, 1.0], math.pi), ValueError, "theta0"),
    (lambda: pendulum_swing([0.0, math.nan], 1.0), ValueError, "`t`"),
    (lambda: pendulum_period(1.0, length=0.0), ValueError, "length"),
])
def test_bad_inputs_name_the_argument(call, exc, name):
    with pytest.raises(exc, match=name):
        call()
