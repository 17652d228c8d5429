"""The seed's gyroscopic torques (Sec. 4.7, Eqs. 4.148-4.152) against point-mass kinematics.

Independent truth: a rotor made of point masses, moved by exact rotations (``scipy.linalg.expm``
of the angular velocities, not the project's attitude code). The torque that drives the masses
is ``T = sum m x x xddot`` about the fixed system mass center, with ``xddot`` from a fourth-order
finite-difference stencil; the reaction on the body is ``-T``. For a body turning at ``Omega``
and a rotor turning at ``omega`` relative to it, the part of ``T`` bilinear in
``(Omega, omega)``, ``T(Omega, omega) - T(Omega, 0) - T(0, omega)``, is the Coriolis term of
Eq. 4.140. Stencil error: truncation ~ h^4 |x^(6)| / 90, round-off ~ 3 eps |x| / h^2; with
``h = 3e-3`` and rates of order 1 both are below 1e-9 of the size ``sum m |r|^2 (|Omega| +
|omega|)^2`` of the torques that are differenced (`fd_tolerance`).
"""
import doctest

import casadi as ca
import numpy as np
import pytest
from scipy.linalg import expm

from appdyn.dynamics.momentum import (cmg_torque, coriolis_torque, gyroscope_reaction_torque, gyroscopic,
                               propeller_torque, wheel_torque)

RNG = np.random.default_rng(1729)
H_STEP = 3e-3
TOL = 1e-9  # relative to the torque scale, from the stencil error above


def hat(w):
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def second_derivative(f, h=H_STEP):
    return (-f(2 * h) + 16 * f(h) - 30 * f(0.0) + 16 * f(-h) - f(-2 * h)) / (12 * h * h)


def first_derivative(f, h=H_STEP):
    return (-f(2 * h) + 8 * f(h) - 8 * f(-h) + f(-2 * h)) / (12 * h)


def drive_torque(masses, positions):
    """sum m x x xddot at t = 0 for inertial positions ``positions(t)`` (3, K)."""
    acc = second_derivative(positions)
    return np.sum(masses * np.cross(positions(0.0), acc, axis=0), axis=1)


def coriolis_truth(masses, r0, ell, Omega, omega):
    """Minus the bilinear part of the drive torque: the Coriolis reaction on the body."""
    def torque(Om, om):
        return drive_torque(masses, lambda t: expm(hat(Om) * t)
                            @ (ell[:, None] + expm(hat(om) * t) @ r0))
    zero = np.zeros(3)
    return -(torque(Omega, omega) - torque(Omega, zero) - torque(zero, omega))


def fd_tolerance(masses, r, *rates):
    """TOL times the size of the drive torques whose difference is the truth."""
    return TOL * np.sum(masses * np.sum(r ** 2, axis=0)) * sum(map(np.linalg.norm, rates)) ** 2


def inertia_of(masses, r):
    return sum(m * (x @ x * np.eye(3) - np.outer(x, x)) for m, x in zip(masses, r.T))


def random_rotor(count=7):
    masses = RNG.uniform(0.5, 2.0, count)
    r = RNG.normal(size=(3, count))
    r -= (r @ masses / masses.sum())[:, None]  # about its own mass center (Eq. 4.142)
    return masses, r


def ring(axis, radius, count, mass=1.0):
    """``count`` equal masses on a circle about the unit ``axis`` (an axisymmetric rotor)."""
    e1 = np.cross(axis, [1.0, 0.0, 0.0] if abs(axis[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(axis, e1)
    a = 2 * np.pi * np.arange(count) / count + 0.3
    return np.full(count, mass), radius * (np.outer(e1, np.cos(a)) + np.outer(e2, np.sin(a)))


def unit(v):
    return np.asarray(v, float) / np.linalg.norm(v)


# ------------------------------------------------------------------------- Eq. 4.148
def test_wheel_torque_is_the_reaction_to_spinning_up_a_ring():
    axis = unit(RNG.normal(size=3))
    masses, r0 = ring(axis, 0.3, 5, mass=0.4)
    spin, alpha = 4.0, 3.0  # [rad/s], [rad/s^2]

    def positions(t):
        return expm(hat(axis) * (spin * t + 0.5 * alpha * t * t)) @ r0
    truth = -drive_torque(masses, positions)
    axial = np.sum(masses) * 0.3 ** 2
    # stencil truncation: h^4 / 90 * |d^6/dt^6 of cos(spin t + alpha t^2 / 2)| at t = 0 (Faa di
    # Bruno), per unit radius, times sum m rho^2; plus round-off
    sixth = spin ** 6 + 15 * spin ** 4 * alpha + 45 * spin ** 2 * alpha ** 2 + 15 * alpha ** 3
    tol = H_STEP ** 4 / 90 * sixth * axial + 1e-12
    np.testing.assert_allclose(wheel_torque(axial, alpha * axis), truth, atol=tol)
    np.testing.assert_allclose(wheel_torque(inertia_of(masses, r0), alpha * axis), truth, atol=tol)
    assert np.linalg.norm(truth) == pytest.approx(axial * alpha, rel=1e-8)


def test_wheel_torque_batch():
    accel = RNG.normal(size=(3, 4))
    np.testing.assert_allclose(wheel_torque(0.2, accel), -0.2 * accel)


# ------------------------------------------------------------------------- Eq. 4.150
def test_cmg_torque_is_the_reaction_to_turning_the_rotor_momentum():
    for _ in range(5):
        w_c, H0 = RNG.normal(size=3), 10 * RNG.normal(size=3)
        truth = -first_derivative(lambda t: expm(hat(w_c) * t) @ H0, h=1e-3)
        scale = np.linalg.norm(w_c) * np.linalg.norm(H0)
        np.testing.assert_allclose(cmg_torque(w_c, H0), truth, atol=1e-10 * scale)


# ------------------------------------------------------------------------- Eqs. 4.144-4.151
@pytest.mark.slow
def test_coriolis_torque_from_point_masses():
    for _ in range(4):
        masses, r0 = random_rotor()
        ell = RNG.normal(size=3)  # rotor offset from the system mass center: drops out
        Omega, omega = RNG.normal(size=3), RNG.normal(size=3)
        truth = coriolis_truth(masses, r0, ell, Omega, omega)
        np.testing.assert_allclose(coriolis_torque(Omega, omega, inertia_of(masses, r0)), truth,
                                   atol=fd_tolerance(masses, r0, Omega, omega))


def test_coriolis_component_form_of_the_seed():
    for _ in range(5):
        I1, I2, I3 = RNG.uniform(0.5, 2.0, 3)
        (O1, O2, O3), (w1, w2, w3) = RNG.normal(size=3), RNG.normal(size=3)
        seed = [O3 * w2 * (I1 + I2 - I3) - O2 * w3 * (I1 - I2 + I3),
                O1 * w3 * (I2 + I3 - I1) - O3 * w1 * (I1 + I2 - I3),
                O2 * w1 * (I1 - I2 + I3) - O1 * w2 * (I2 + I3 - I1)]
        np.testing.assert_allclose(coriolis_torque([O1, O2, O3], [w1, w2, w3], [I1, I2, I3]),
                                   seed, rtol=1e-13, atol=1e-13)


# ------------------------------------------------------------------------- propeller example
def blades_model(n, length=2.0, mass=3.0, points=40):
    """Slender blades of length/2 from the hub as point masses; angles phi_k = 2 pi k / n.
    Returns masses, distances along the blade and blade angles."""
    s = (np.arange(points) + 0.5) / points * length / 2
    return np.full(points, mass / (2 * points)), s, 2 * np.pi * np.arange(n) / n


def propeller_truth(n, yaw_rate, spin, t):
    """Minus the Coriolis integrand 2 m r x (Omega x (omega x r)) summed over blade points,
    airplane axes (X shaft, Z yaw); blade direction b = -sin(phi) Y + cos(phi) Z."""
    masses, s, angles = blades_model(n)
    Omega, omega = np.array([0.0, 0.0, yaw_rate]), np.array([spin, 0.0, 0.0])
    total = np.zeros(3)
    for a in angles:
        phi = spin * t + a
        b = np.array([0.0, -np.sin(phi), np.cos(phi)])
        for m, dist in zip(masses, s):
            r = dist * b
            total -= 2 * m * np.cross(r, np.cross(Omega, np.cross(omega, r)))
    inertia = n * np.sum(masses * s ** 2)  # polar moment of the propeller
    return total, inertia


@pytest.mark.slow
def test_two_blade_propeller_matches_the_seed_and_oscillates_at_twice_the_spin():
    yaw_rate, spin = 0.2, 30.0
    times = np.arange(64) / 64 * 2 * np.pi / spin  # one revolution
    truth = np.column_stack([propeller_truth(2, yaw_rate, spin, t)[0] for t in times])
    inertia = propeller_truth(2, yaw_rate, spin, 0.0)[1]
    phi = spin * times
    seed = np.array([0 * phi, -2 * inertia * yaw_rate * spin * np.cos(phi) ** 2,
                     -2 * inertia * yaw_rate * spin * np.sin(phi) * np.cos(phi)])
    scale = inertia * yaw_rate * spin
    np.testing.assert_allclose(truth, seed, atol=1e-12 * scale)
    np.testing.assert_allclose(propeller_torque(yaw_rate, spin, inertia, times), truth,
                               atol=1e-12 * scale)
    spectrum = np.abs(np.fft.rfft(truth[1:], axis=1)) / 64
    assert spectrum[0, 0] == pytest.approx(scale)  # mean -I yaw_rate spin along Y
    for component in spectrum:  # nothing but the mean and twice the spin frequency
        others = np.delete(component, [0, 2])
        assert component[2] == pytest.approx(0.5 * scale) and np.all(others < 1e-12 * scale)


@pytest.mark.parametrize("n", [3, 4, 5])
def test_propeller_with_three_or_more_blades_has_no_cyclic_torque(n):
    yaw_rate, spin = 0.2, 30.0
    for t in np.linspace(0.0, 0.3, 7):
        truth, inertia = propeller_truth(n, yaw_rate, spin, t)
        scale = inertia * yaw_rate * spin
        steady = gyroscope_reaction_torque([0, 0, yaw_rate], [inertia * spin, 0, 0])
        np.testing.assert_allclose(truth, steady, atol=1e-12 * scale)  # -Omega x H
        np.testing.assert_allclose(propeller_torque(yaw_rate, spin, inertia, t, blades=n),
                                   truth, atol=1e-12 * scale)


def test_propeller_phase_shifts_time():
    a = propeller_torque(0.2, 30.0, 1.5, 0.1, phase=0.6)
    np.testing.assert_allclose(a, propeller_torque(0.2, 30.0, 1.5, 0.1 + 0.6 / 30.0), atol=1e-13)


# ------------------------------------------------------------------------- Eq. 4.152
@pytest.mark.parametrize("ratio", [1.0, 1e-3])  # |Omega| / omega_0: exact for any ratio
@pytest.mark.slow
def test_symmetric_gyroscope_reaction_from_point_masses(ratio):
    axis = unit(RNG.normal(size=3))
    masses, r0 = ring(axis, 0.5, 3, mass=2.0)  # three masses: I2 = I3
    spin = 1.5
    for _ in range(3):
        Omega = ratio * RNG.normal(size=3)
        truth = coriolis_truth(masses, r0, np.zeros(3), Omega, spin * axis)
        H = np.sum(masses) * 0.5 ** 2 * spin * axis  # I1 omega_0
        np.testing.assert_allclose(gyroscope_reaction_torque(Omega, H), truth,
                                   atol=fd_tolerance(masses, r0, Omega, spin * axis))
        scale = np.linalg.norm(Omega) * np.linalg.norm(H)
        assert np.linalg.norm(truth) > 0.1 * scale  # the tolerance is far below the torque
        np.testing.assert_allclose(coriolis_torque(Omega, spin * axis, inertia_of(masses, r0)),
                                   gyroscope_reaction_torque(Omega, H), atol=1e-13 * scale)


# ------------------------------------------------------------------------- CasADi and inputs
@pytest.mark.parametrize("sym", [ca.SX, ca.MX])
def test_casadi_expressions_agree_with_numpy(sym):
    a, b, J, s = sym.sym("a", 3), sym.sym("b", 3), sym.sym("J", 3, 3), sym.sym("s")
    f = ca.Function("f", [a, b, J, s], [
        wheel_torque(s, a), wheel_torque(J, a), cmg_torque(a, b), coriolis_torque(a, b, J),
        propeller_torque(s, 2 * s, 3.0, s, blades=3), gyroscope_reaction_torque(a, b)])
    av, bv, sv = RNG.normal(size=3), RNG.normal(size=3), 0.7
    Jv = inertia_of(*random_rotor())
    ref = [wheel_torque(sv, av), wheel_torque(Jv, av), cmg_torque(av, bv),
           coriolis_torque(av, bv, Jv), propeller_torque(sv, 2 * sv, 3.0, sv, blades=3),
           gyroscope_reaction_torque(av, bv)]
    for got, want in zip(f(av, bv, Jv, sv), ref):
        np.testing.assert_allclose(got.full().ravel(), want, atol=1e-13)


@pytest.mark.parametrize("call, exc, name", [
    (lambda: wheel_torque(0.1, [1.0, 2.0]), ValueError, "wheel_accel"),
    (lambda: wheel_torque(np.eye(2), [1.0, 2.0, 3.0]), ValueError, "wheel_inertia"),
    (lambda: wheel_torque("heavy", [1.0, 2.0, 3.0]), TypeError, "wheel_inertia"),
    (lambda: cmg_torque([1.0, np.nan, 0.0], [1.0, 2.0, 3.0]), ValueError, "gimbal_rate_vector"),
    (lambda: cmg_torque([1.0, 0.0, 0.0], None), TypeError, "rotor_momentum"),
    (lambda: coriolis_torque([1, 2, 3], [1, 2, 3], np.eye(2)), ValueError, "inertia"),
    (lambda: coriolis_torque([1, 2], [1, 2, 3], np.eye(3)), ValueError, "Omega"),
    (lambda: coriolis_torque([1, 2, 3], "fast", np.eye(3)), TypeError, "omega"),
    (lambda: propeller_torque(0.1, 30.0, 1.0, 0.0, blades=1), ValueError, "blades"),
    (lambda: propeller_torque(0.1, 30.0, 1.0, 0.0, blades=2.5), TypeError, "blades"),
    (lambda: propeller_torque(0.1, np.inf, 1.0, 0.0), ValueError, "spin_rate"),
    (lambda: propeller_torque(0.1, 30.0, 1.0, 0.0, phase="up"), TypeError, "phase"),
    # a 3x3 inertia once broadcast against a 3-sample t into a silent wrong answer
    (lambda: propeller_torque(0.1, 30.0, np.eye(3), [0.0, 0.1, 0.2]), ValueError, "inertia"),
    (lambda: propeller_torque(0.1, 30.0, -1.0, 0.0), ValueError, "inertia"),
    (lambda: propeller_torque([0.1, 0.2], 30.0, 1.0, 0.0), ValueError, "yaw_rate"),
    (lambda: propeller_torque(0.1, 30.0, 1.0, np.zeros((2, 2))), ValueError, "t"),
    (lambda: gyroscope_reaction_torque([1, 2, 3], [[1, 2, 3]]), ValueError, "H"),
    (lambda: gyroscope_reaction_torque(ca.SX.sym("w", 2), [1, 2, 3]), ValueError, "Omega"),
])
def test_bad_inputs_name_the_argument(call, exc, name):
    with pytest.raises(exc, match=f"`{name}`"):
        call()


def test_docstring_examples_run():
    result = doctest.testmod(gyroscopic,
                             optionflags=doctest.NORMALIZE_WHITESPACE | doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0


def test_seed_bicycle_wheel_and_ore_crusher():
    """Sec. 4.7 b Examples 2 and 3, from Eq. 4.152 ``L_R = -Omega x H``."""
    # bicycle (x forward, y left, z up): the wheel's momentum points left; turning the
    # handlebar to the left (Omega up) gives a torque about +x, which lifts the left side:
    # the bicycle tilts to the right (homologous parallelism)
    L = gyroscope_reaction_torque([0.0, 0.0, 0.5], [0.0, 2.0, 0.0])
    np.testing.assert_allclose(L, [1.0, 0.0, 0.0], atol=1e-15)
    # ore crusher: a roller of radius r on an arm l driven at Omega about the vertical rolls at
    # w0 = Omega l / r about the arm; |L_R| = I1 Omega^2 l / r, pressing it onto the track
    I1, Omega, arm, r = 40.0, 1.5, 1.2, 0.4
    w0 = Omega * arm / r
    # arm along +x, roller centre moving at Omega l along +y; rolling without slip on the floor
    # (contact point at rest: w x (-r z) + Omega l y = 0) spins it about -x
    L = gyroscope_reaction_torque([0.0, 0.0, Omega], [-I1 * w0, 0.0, 0.0])
    assert np.linalg.norm(L) == pytest.approx(I1 * Omega**2 * arm / r, rel=1e-15)
    assert L[1] > 0  # about +y: turns the arm's outer end (the roller) down, onto the track
