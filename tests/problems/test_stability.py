"""Stability reports against closed forms (seed Secs. 4.5-4.6), verdicts, sweeps and the CLI.

Closed forms are written out here independently of the library: eigenvalue sets are compared
after pairing each closed-form value with its nearest computed eigenvalue, relative to the
spectral radius rho; boundaries located by bisection are compared with their formulas.
"""
import argparse
import json

import control
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as hs
from numpy.polynomial import Polynomial as Poly
from scipy.optimize import linear_sum_assignment

from appdyn.dynamics import simulate
from appdyn.dynamics.attitude import dcm_from_quat, principal_axes
from appdyn.dynamics.spinning import tilt_torque_body
from appdyn.problems import stability as st
from appdyn.problems.stability import (PointMassDamper, SphericalDamper, classify, gyrostat,
                                heavy_top, loop, rotor, spin, spinning_projectile, sweep)
from appdyn.problems.cli.stability import add_parser as add_stability_parser
from appdyn.problems.cli.stability import main as cli_main
from appdyn.problems.cli.stability import run as cli_run
from tests.bodies import GEMINI

TOL = 1e-9  # eigenvalues vs closed forms, relative to the spectral radius
G0 = 9.80665


def max_pair_error(computed, expected):
    computed, expected = np.asarray(computed, complex), np.asarray(expected, complex)
    assert computed.shape == expected.shape, (computed, expected)
    rows, cols = linear_sum_assignment(np.abs(computed[:, None] - expected[None, :]))
    return np.max(np.abs(computed[rows] - expected[cols])) / np.max(np.abs(expected))


def assert_eigenvalues(report, expected):
    err = max_pair_error(report.eigenvalues, expected)
    assert err < TOL, (err, report.eigenvalues, expected)
    return err


def method3_roots(I1, I2, kappa, w0, D=0.0):
    """Roots of I2 s^2 + (D - i G w0) s + K = 0 (Eqs. 4.124-4.125 with damping D) and their
    conjugates; K = (I1 - I2) w0^2 - kappa, G = 2 I2 - I1."""
    G, K = 2 * I2 - I1, (I1 - I2) * w0 ** 2 - kappa
    r = np.roots([I2, D - 1j * G * w0, K])
    return np.concatenate([r, np.conj(r)])


# ------------------------------------------------------------------ torque-free spin
@pytest.mark.parametrize("axis_index, verdict", [(0, "marginally stable"), (1, "unstable"),
                                                 (2, "marginally stable")])
@pytest.mark.parametrize("rate", [10.0, -3.0])
def test_spin_rate_eigenvalues_closed_form(axis_index, verdict, rate):
    I = np.array([2.0, 3.0, 4.5])
    a = np.eye(3)[axis_index]
    rep = spin(I, a, rate)
    Ia, Ib, Ic = I[axis_index], *np.delete(I, axis_index)
    lam = 1j * rate * np.sqrt(complex((Ia - Ib) * (Ia - Ic) / (Ib * Ic)))  # +/- i rate sqrt(...)
    assert_eigenvalues(rep, [lam, -lam])
    assert rep.verdict == verdict
    assert rep.ss.nstates == 2 and rep.closed_form_error < TOL


def test_spin_full_inertia_principal_axis():
    moments, A = principal_axes(GEMINI)
    for k in range(3):
        rep = spin(GEMINI, A[k], 0.2)
        Ia, Ib, Ic = moments[k], *np.delete(moments, k)
        lam = 0.2j * np.sqrt(complex((Ia - Ib) * (Ia - Ic) / (Ib * Ic)))
        assert_eigenvalues(rep, [lam, -lam])
    assert spin(GEMINI, A[0], 0.2).verdict == "unstable"  # 4530: intermediate
    assert spin(GEMINI, A[2], 0.2).verdict == "marginally stable"  # minor axis


@settings(max_examples=30, deadline=None)
@given(moments=hs.tuples(*[hs.floats(1.0, 10.0)] * 2), third=hs.floats(0.0, 1.0),
       angles=hs.tuples(*[hs.floats(-np.pi, np.pi)] * 3), which=hs.integers(0, 2),
       rate=hs.floats(0.1, 100.0))
@pytest.mark.slow
def test_spin_closed_form_for_any_body_and_principal_axis(moments, third, angles, which, rate):
    """Random principal moments (triangle inequality held) in random body axes."""
    a, b = moments
    c = abs(a - b) + third * (a + b - abs(a - b))  # |a - b| <= c <= a + b
    I_p = np.array([a, b, max(c, 0.05)])
    R = dcm_from_quat(np.array([*np.sin(angles[0] / 2) * np.array(
        [np.cos(angles[1]) * np.cos(angles[2]), np.sin(angles[1]) * np.cos(angles[2]),
         np.sin(angles[2])]), np.cos(angles[0] / 2)]))
    inertia = R.T @ np.diag(I_p) @ R
    inertia = 0.5 * (inertia + inertia.T)
    rep = spin(inertia, R[which], rate)  # rows of R: the principal axes in body components
    Ia, Ib, Ic = I_p[which], *np.delete(I_p, which)
    lam = 1j * rate * np.sqrt(complex((Ia - Ib) * (Ia - Ic) / (Ib * Ic)))
    if abs(lam) < 1e-6 * rate:
        return  # (nearly) equal moments: a double eigenvalue at 0, judged separately
    assert_eigenvalues(rep, [lam, -lam])
    assert rep.verdict == ("unstable" if lam.imag == 0 else "marginally stable")


def spherical_closed_form(It, Ia, Jd, c, W, h=0.0, wd=None):
    """Symmetric body + spherical damper, derived by hand in complex transverse rates
    z = dw2 + i dw3, zeta = dwd2 + i dwd3 (e1 x v <-> i v):
        It z' = -i (W It - Ia W - h) z + c (zeta - z)
        zeta' = -(c/Jd)(zeta - z) - i W zeta + i wd z
    so with sigma = s + i W: It sigma^2 + (c (It + Jd)/Jd - i Ha) sigma - i c (Ha/Jd + wd) = 0,
    Ha = Ia W + h; axial: s = -c (1/Ia + 1/Jd)."""
    wd = W if wd is None else wd
    Ha = Ia * W + h
    sig = np.roots([It, c * (It + Jd) / Jd - 1j * Ha, -1j * c * (Ha / Jd + wd)])
    s = sig - 1j * W
    return np.concatenate([s, np.conj(s), [-c * (1 / Ia + 1 / Jd)]])


@pytest.mark.parametrize("Ia, verdict", [(3.0, "asymptotically stable"), (1.5, "unstable")])
def test_spin_spherical_damper_kelvin_tait_chetaev(Ia, verdict):
    It, Jd, c, W = 2.0, 0.05, 0.02, 10.0
    rep = spin([It, It, Ia], [0, 0, 1], W, damper=SphericalDamper(Jd, c))
    assert rep.verdict == verdict
    assert_eigenvalues(rep, spherical_closed_form(It, Ia, Jd, c, W))
    assert rep.closed_form_error < TOL
    assert {m.label for m in rep.modes} == {"nutation", "damper"}


def point_mass_polynomial(I1, I2, I3, mu, r, k, c, W, h=0.0):
    """Spin about e1, mass at r e2 sliding along e1 (composite moments I1..I3, s = 0 at rest).
    Linearized by hand: I2 dw2' + (I1 W + h - I3 W) dw3 = 0;
    I3 dw3' + (I2 W - I1 W - h) dw2 - mu r (z'' + W^2 z) = 0;
    mu (z'' - r dw3' + W r dw2) + k z + c z' = 0.  Determinant of the Laplace matrix."""
    s = Poly([0, 1])
    M = [[I2 * s, Poly([(I1 - I3) * W + h]), Poly([0])],
         [Poly([(I2 - I1) * W - h]), I3 * s, -mu * r * (s ** 2 + W ** 2)],
         [Poly([mu * W * r]), -mu * r * s, mu * s ** 2 + c * s + k]]
    det = (M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1])
           - M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0])
           + M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0]))
    return det.roots()


@pytest.mark.parametrize("I1, verdict", [(5.0, "asymptotically stable"), (2.0, "unstable")])
@pytest.mark.parametrize("body_mass", [np.inf, 40.0])
def test_spin_point_mass_damper_closed_form_and_verdict(I1, verdict, body_mass):
    I2, I3, m, k, c, r, W = 3.0, 4.0, 0.5, 60.0, 0.8, 0.6, 4.0
    damper = PointMassDamper(m, k, c, position=(0, r, 0), direction=(1, 0, 0),
                             body_mass=body_mass)
    rep = spin([I1, I2, I3], [1, 0, 0], W, damper=damper)
    mu = m * body_mass / (m + body_mass) if np.isfinite(body_mass) else m
    expected = point_mass_polynomial(I1 + mu * r * r, I2, I3 + mu * r * r, mu, r, k, c, W)
    assert rep.verdict == verdict
    assert_eigenvalues(rep, expected)
    assert rep.ss.state_labels == ["w2", "w3", "s", "s_dot"]


def test_damper_that_breaks_the_steady_spin_is_refused_with_the_residual():
    damper = PointMassDamper(0.5, 60.0, 0.8, position=(0.3, 0.4, 0), direction=(0, 1, 0))
    with pytest.raises(ValueError, match=r"`damper`: no steady spin.*not an equilibrium.*d\(w"):
        spin([2.0, 3.0, 4.0], [1, 0, 0], 4.0, damper=damper)


# --------------------------------------------------------------- Method III cases
def top(rate):
    return heavy_top(0.002, 0.005, 0.3, 0.04, rate)


def test_heavy_top_roots_4_127_and_precession_4_130_4_131():
    I1, I2, mgl = 0.002, 0.005, 0.3 * G0 * 0.04
    w_sleep = 2 / I1 * np.sqrt(mgl * I2)  # Eq. 4.128
    for w0 in (1.5 * w_sleep, 3 * w_sleep, -2 * w_sleep):
        rep = top(w0)
        a = I1 * w0 / (2 * I2)
        root = np.sqrt(a * a - mgl / I2)
        lam = [(2 * I2 - I1) * w0 / (2 * I2) + sgn * root for sgn in (1, -1)]  # Eq. 4.127
        assert_eigenvalues(rep, [1j * lam[0], 1j * lam[1], -1j * lam[0], -1j * lam[1]])
        assert rep.verdict == "marginally stable"
        low, high = -(a - root), -(a + root)  # Eqs. 4.130, 4.131 (for w0 > 0)
        low, high = sorted((low, high), key=abs)  # slow = the smaller magnitude, any sign of w0
        for name, value in (("slow precession rate", low), ("fast precession rate", high)):
            q = rep.quantity(name)
            assert abs(q.value - value) <= TOL * abs(value)
            assert abs(q.closed_form - value) <= TOL * abs(value)
        labels = sorted(m.label for m in rep.modes)
        assert labels == ["fast forward precession", "slow forward precession"]


def test_heavy_top_matches_the_second_order_equations_4_122():
    """Independent route: Eq. 4.122 as a first-order system in (theta, psi, theta', psi')."""
    I1, I2, mgl, w0 = 0.002, 0.005, 0.3 * G0 * 0.04, 30.0
    K, G = (I1 - I2) * w0 ** 2 - mgl, 2 * I2 - I1
    A = np.array([[0, 0, 1, 0], [0, 0, 0, 1],
                  [-K / I2, 0, 0, G * w0 / I2], [0, -K / I2, -G * w0 / I2, 0]])
    assert_eigenvalues(top(w0), np.linalg.eigvals(A))


def test_heavy_top_not_sleeping_and_high_spin_approximation():
    I1, I2, mgl = 0.002, 0.005, 0.3 * G0 * 0.04
    w_sleep = 2 / I1 * np.sqrt(mgl * I2)
    rep = top(0.7 * w_sleep)
    assert rep.verdict == "unstable"
    a = I1 * 0.7 * w_sleep / (2 * I2)
    growth = np.sqrt(mgl / I2 - a * a)
    assert abs(rep.least_damped().real - growth) <= TOL * np.max(np.abs(rep.eigenvalues))
    assert_eigenvalues(rep, method3_roots(I1, I2, mgl, 0.7 * w_sleep))
    # Eq. 4.132: slow precession -> -m g l / (I1 w0) (relative error ~ m g l I2 / (I1 w0)^2)
    w0 = 100 * w_sleep
    slow = top(w0).quantity("slow precession rate").value
    approx = -mgl / (I1 * w0)
    assert abs(slow / approx - 1) < 2 * mgl * I2 / (I1 * w0) ** 2
    assert abs(slow / approx - 1) > 0.1 * mgl * I2 / (I1 * w0) ** 2  # it is an approximation


def test_heavy_top_precession_sense_from_a_nonlinear_simulation():
    """Start the nonlinear top on its slow mode (amplitude 1e-5) and measure the inertial
    precession of the symmetry axis: the angle of psi + i theta, with e1 = (1, psi, -theta)
    in inertial axes, must advance at Eq. 4.130's rate, sign included."""
    I1, I2, mgl, w0 = 0.002, 0.005, 0.3 * G0 * 0.04, 40.0
    rep = top(w0)
    a = I1 * w0 / (2 * I2)
    slow = -(a - np.sqrt(a * a - mgl / I2))  # Eq. 4.130
    assert abs(rep.quantity("slow precession rate").value - slow) <= TOL * abs(slow)
    ev, V = np.linalg.eig(rep.ss.A)
    k = int(np.argmin(np.abs(np.abs(ev.imag) - abs(slow + w0))))  # spinning frame: slow + w0
    v = V[:, k] / np.max(np.abs(V[:, k]))
    dth2, dth3, dw2, dw3 = 1e-5 * np.real(v)
    dq = np.array([0, dth2 / 2, dth3 / 2, np.sqrt(1 - (dth2 ** 2 + dth3 ** 2) / 4)])
    x0 = np.concatenate([dq, [w0, dw2, dw3]])
    model = tilt_torque_body([I1, I2, I2], mgl)
    t = np.linspace(0, 2 * np.pi / abs(slow), 201)
    res = simulate(model, x0, t, rtol=1e-11, atol=1e-13)
    axis_inertial = np.einsum("ijk,i->jk", dcm_from_quat(res.x[:4]), [1.0, 0, 0])
    phase = np.unwrap(np.angle(axis_inertial[1] - 1j * axis_inertial[2]))
    measured = np.polyfit(t, phase, 1)[0]
    assert abs(measured / slow - 1) < 1e-9, (measured, slow)  # measured: 3e-12


def test_spinning_projectile_is_the_heavy_top_with_M_alpha():
    I1, I2, q, S, cna, l = 0.002, 0.02, 2e5, 1e-3, 2.0, 0.03
    Ma = q * S * cna * l
    w_min = 2 / I1 * np.sqrt(Ma * I2)
    for w0, verdict in ((1.2 * w_min, "marginally stable"), (0.9 * w_min, "unstable")):
        rep = spinning_projectile(I1, I2, w0, dynamic_pressure=q, area=S, cn_alpha=cna, cp_offset=l)
        assert rep.verdict == verdict
        assert_eigenvalues(rep, method3_roots(I1, I2, Ma, w0))
        sg = rep.quantity("gyroscopic stability factor").closed_form
        assert abs(sg - (w0 / w_min) ** 2) < 1e-12 * sg  # S_g = (w0 / w_min)^2
    stable_cp_behind = spinning_projectile(I1, I2, 10.0, dynamic_pressure=q, area=S,
                                           cn_alpha=cna, cp_offset=-l)
    assert stable_cp_behind.verdict == "marginally stable"


def test_rotor_whirl_4_134_4_135_and_damped_roots():
    I1, I2, k, l = 0.01, 0.05, 1e4, 0.1
    for w0 in (30.0, 100.0):
        rep = rotor(I1, I2, k, l, w0)
        a = I1 * w0 / (2 * I2)
        root = np.sqrt(a * a + 2 * k * l * l / I2)
        assert_eigenvalues(rep, method3_roots(I1, I2, -2 * k * l * l, w0))
        assert rep.verdict == "marginally stable"
        backward, forward = -(a - root), -(a + root)  # Eqs. 4.134, 4.135
        assert abs(rep.quantity("backward whirl").value - backward) <= TOL * backward
        assert abs(rep.quantity("forward whirl").value - forward) <= TOL * abs(forward)
        assert backward > 0 > forward
    w_crit = np.sqrt(2 * k * l * l / (I2 - I1))
    for w0, verdict in ((0.9 * w_crit, "asymptotically stable"), (1.1 * w_crit, "unstable")):
        rep = rotor(I1, I2, k, l, w0, internal_damping=0.02)
        assert rep.verdict == verdict
        assert_eigenvalues(rep, method3_roots(I1, I2, -2 * k * l * l, w0, D=0.02))
    assert rotor(I1, I2, k, l, 10 * w_crit, internal_damping=0.02).modes[0].label.endswith(
        "forward whirl")  # the forward whirl is the one destabilized
    # a disk-like rotor (I1 > I2) stays stable at any speed
    assert rotor(0.08, 0.05, k, l, 1e3, internal_damping=0.02).verdict == "asymptotically stable"


# ----------------------------------------------------------------------- gyrostat
def test_gyrostat_undamped_closed_form():
    Ia, Ib, Ic, W = 3.0, 4.0, 5.0, 2.0
    for h in (-1.0, 3.0, 6.0):
        rep = gyrostat([Ia, Ib, Ic], [1, 0, 0], W, h)
        lam2 = -(Ia * W + h - Ib * W) * (Ia * W + h - Ic * W) / (Ib * Ic)
        lam = np.sqrt(complex(lam2))
        assert_eigenvalues(rep, [lam, -lam])
        unstable = (Ib - Ia) * W < h < (Ic - Ia) * W
        assert rep.verdict == ("unstable" if unstable else "marginally stable")
    # despun platform: the wheel alone stabilizes
    assert gyrostat([Ia, Ib, Ic], [1, 0, 0], 0.0, 2.0).verdict == "marginally stable"


@pytest.mark.parametrize("damper_on", ["platform", "rotor"])
def test_gyrostat_spherical_damper_closed_form(damper_on):
    Ia, It, Jd, c, W, Jr, h = 3.0, 4.0, 0.1, 0.05, 2.0, 0.5, 1.3
    rep = gyrostat([Ia, It, It], [1, 0, 0], W, h, wheel_inertia=Jr,
                   damper=SphericalDamper(Jd, c), damper_on=damper_on)
    wd = W + (h / Jr if damper_on == "rotor" else 0.0)
    assert_eigenvalues(rep, spherical_closed_form(It, Ia, Jd, c, W, h=h, wd=wd))


def test_gyrostat_point_mass_damper_with_wheel_closed_form():
    I1, I2, I3, m, k, c, r, W, h = 3.0, 4.0, 4.5, 0.4, 50.0, 0.6, 0.5, 2.0, 3.5
    rep = gyrostat([I1, I2, I3], [1, 0, 0], W, h,
                   damper=PointMassDamper(m, k, c, position=(0, r, 0), direction=(1, 0, 0)))
    expected = point_mass_polynomial(I1 + m * r * r, I2, I3 + m * r * r, m, r, k, c, W, h=h)
    assert_eigenvalues(rep, expected)
    assert rep.verdict == "asymptotically stable"  # Ia + h/W = 4.85 > both transverse


# ------------------------------------------------------------------------- loops
def launch_vehicle():
    I, F, l = 1000.0, 2e4, 10.0  # Ch. 5: I psi'' = F l delta
    P = control.ss([[0, 1], [0, 0]], [[0], [F * l / I]], np.eye(2), np.zeros((2, 1)),
                   states=["psi", "psi_dot"], inputs=["delta"], outputs=["psi", "psi_dot"],
                   name="launch_vehicle")
    return P, I, F * l


def test_loop_launch_vehicle_eigenvalues_and_margins():
    """delta = -(k_psi psi + k_psidot psi'): I psi'' + F l k_psidot psi' + F l k_psi psi = 0.
    Loop L = F l (k_psi + k_psidot s) / (I s^2): |L(i wc)| = 1 at
    wc^2 = (a^2 kd^2 + sqrt(a^4 kd^4 + 4 I^2 a^2 kp^2)) / (2 I^2), PM = atan(kd wc / kp)."""
    P, I, a = launch_vehicle()
    kp, kd = 0.8, 0.3
    rep = loop(P, [[kp, kd]])
    assert_eigenvalues(rep, np.roots([I, a * kd, a * kp]))
    assert rep.verdict == "asymptotically stable"
    wc = np.sqrt((a * a * kd * kd + np.sqrt(a ** 4 * kd ** 4 + 4 * I * I * a * a * kp * kp))
                 / (2 * I * I))
    pm = np.degrees(np.arctan2(kd * wc, kp))
    assert abs(rep.margins.gain_crossover - wc) <= TOL * wc
    assert abs(rep.margins.phase_margin - pm) <= TOL * pm
    assert rep.margins.gain_margin == np.inf
    assert loop(P, [[-kp, kd]]).verdict == "unstable"


def test_loop_dynamic_controller_and_mimo_note():
    plant = control.tf([1], [1, 2, 1, 0])  # 1 / (s (s + 1)^2)
    rep = loop(plant, 0.5)
    assert rep.verdict == "asymptotically stable"
    assert abs(rep.margins.gain_margin - 4.0) < 1e-9 * 4  # 2 / 0.5: phase crossover at 1 rad/s
    assert abs(rep.margins.phase_crossover - 1.0) < 1e-9
    assert loop(plant, 2.5).verdict == "unstable"
    assert loop(plant, 2.0).verdict == "marginally stable"  # poles +/- i on the axis
    mimo = control.ss(-np.eye(2), np.eye(2), np.eye(2), np.zeros((2, 2)))
    rep = loop(mimo, np.eye(2))
    assert rep.margins is None and "single loop" in rep.notes[0]
    with pytest.raises(ValueError, match="`controller` gain must be finite with shape"):
        loop(mimo, np.eye(3))


def test_loop_gain_margin_ignores_a_crossover_at_an_undamped_zero():
    """L = k (s^2 + 4) / (s^3 + s^2 + 5 s + 1): closed loop s^3 + (1 + k) s^2 + 5 s + 1 + 4 k,
    Routh-stable for every k > 0 ((1 + k) 5 > 1 + 4 k), so no gain margin. python-control
    finds a phase crossover at the zero 2 rad/s (the phase flips there with |L| = 0) and a
    gain margin of ~1e15 that rounding set; `loop` drops it. With s^3 + 2 s^2 + 2 s + 1 the
    closed loop s^3 + (2 + k) s^2 + 2 s + 1 + 4 k is stable only for k < 3/2 (Routh): that
    margin, at w^2 = 2 (where 2 w - w^3 = 0), stays."""
    plant = control.tf([1.0, 0.0, 4.0], [1.0, 1.0, 5.0, 1.0])
    assert control.stability_margins(plant)[0] > 1e12  # (the crossover `loop` drops)
    m = loop(plant, 1.0).margins
    assert m.gain_margin == np.inf and np.isnan(m.phase_crossover)
    m = loop(control.tf([1.0, 0.0, 4.0], [1.0, 2.0, 2.0, 1.0]), 1.0).margins
    assert abs(m.gain_margin - 1.5) <= 1e-9 and abs(m.phase_crossover - np.sqrt(2.0)) <= 1e-9


# ------------------------------------------------------------------------ verdict
def test_classify_rules():
    assert classify([[0, 1], [0, 0]])[0] == "unstable"  # Jordan block at 0
    assert classify(np.zeros((2, 2)))[0] == "marginally stable"
    assert classify([[0, 1], [-1, 0]])[0] == "marginally stable"
    assert classify([[0, 1], [-1, -0.1]])[0] == "asymptotically stable"
    assert classify([[1e-3, 1], [-1, 0]])[0] == "unstable"
    rot = np.array([[0, 1], [-1, 0]])
    assert classify(np.block([[rot, np.eye(2)], [np.zeros((2, 2)), rot]]))[0] == "unstable"
    for scale in (1e-6, 1.0, 1e6):  # the tolerance scales with the spectrum
        assert classify(scale * np.array([[0, 1], [-1, -1e-7]]))[0] == "asymptotically stable"
        assert classify(scale * np.array([[0, 1], [-1, -1e-11]]))[0] == "marginally stable"


# --------------------------------------------------------------------------- sweep
def test_sweep_locates_the_sleeping_top_boundary():
    I1, I2, m, l = 0.002, 0.005, 0.3, 0.04
    res = sweep("heavy-top", "rate", np.linspace(0, 60, 7), axial_inertia=I1,
                transverse_inertia=I2, mass=m, length=l)
    exact = 2 / I1 * np.sqrt(m * G0 * l * I2)  # Eq. 4.128
    assert len(res.boundaries) == 1
    b = res.boundaries[0]
    assert (b.before, b.after) == ("unstable", "marginally stable")
    assert abs(b.value - exact) <= 1e-8 * exact
    assert abs(b.upper - b.lower) <= 1e-8 * exact
    assert res.verdicts[0] == "unstable" and res.verdicts[-1] == "marginally stable"
    assert res.least_damped.shape == (7,) and res.eigenvalues.shape == (7, 4)


def test_sweep_rotor_internal_damping_instability_speed():
    I1, I2, k, l = 0.01, 0.05, 1e4, 0.1
    res = sweep(rotor, "rate", np.linspace(10, 150, 8), axial_inertia=I1, transverse_inertia=I2,
                stiffness=k, bearing_distance=l, internal_damping=0.01)
    exact = np.sqrt(2 * k * l * l / (I2 - I1))
    assert [(b.before, b.after) for b in res.boundaries] == [("asymptotically stable", "unstable")]
    assert abs(res.boundaries[0].value - exact) <= 1e-8 * exact


@pytest.mark.slow
def test_sweep_gyrostat_boundaries():
    Ia, Ib, Ic, W = 3.0, 4.0, 5.0, 2.0
    res = sweep("gyrostat", "wheel_momentum", np.linspace(-2, 8, 6), inertia=[Ia, Ib, Ic],
                axis=[1, 0, 0], rate=W)
    assert [(b.before, b.after) for b in res.boundaries] == [
        ("marginally stable", "unstable"), ("unstable", "marginally stable")]
    for b, exact in zip(res.boundaries, ((Ib - Ia) * W, (Ic - Ia) * W)):
        assert abs(b.value - exact) <= 1e-8 * exact
    # spherical damper on the platform: stable iff Ia + h/W > It; the grid hits h* exactly
    It, damper = 4.0, SphericalDamper(0.1, 0.05)
    res = sweep("gyrostat", "wheel_momentum", np.linspace(-2, 4, 7), inertia=[Ia, It, It],
                axis=[1, 0, 0], rate=W, damper=damper)
    exact = (It - Ia) * W
    assert [(b.before, b.after) for b in res.boundaries] == [("unstable", "asymptotically stable")]
    assert abs(res.boundaries[0].value - exact) <= 1e-8 * exact
    # on the rotor: housing at the nutation rate when (Ia - It) W + (Jr - It) h / Jr = 0
    Jr = 0.5
    res = sweep("gyrostat", "wheel_momentum", np.linspace(-2, 2, 5), inertia=[Ia, It, It],
                axis=[1, 0, 0], rate=W, damper=damper, damper_on="rotor", wheel_inertia=Jr)
    exact = Jr * (Ia - It) * W / (It - Jr)
    assert len(res.boundaries) == 1
    assert abs(res.boundaries[0].value - exact) <= 1e-8 * abs(exact)


def test_sweep_argument_errors():
    kw = dict(axial_inertia=0.002, transverse_inertia=0.005, mass=0.3, length=0.04)
    with pytest.raises(ValueError, match="`case` must be one of"):
        sweep("top", "rate", [1, 2], **kw)
    with pytest.raises(ValueError, match="`parameter` must be an argument of heavy_top"):
        sweep("heavy_top", "spin", [1, 2], **kw)
    with pytest.raises(ValueError, match="`values` must be finite and strictly increasing"):
        sweep("heavy_top", "rate", [2, 1], **kw)
    with pytest.raises(ValueError, match=r"spin at rate = 0.0: `rate` must be non-zero"):
        sweep("spin", "rate", [-1.0, 0.0], inertia=[1, 2, 3], axis=[1, 0, 0])


# ---------------------------------------------------------------------- bad input
@pytest.mark.parametrize("call, name", [
    (lambda: spin([1, 2, 3, 4], [1, 0, 0], 1.0), "`inertia` must have shape"),
    (lambda: spin([[1, 0.5, 0], [0, 2, 0], [0, 0, 3]], [1, 0, 0], 1.0),
     "`inertia` must be symmetric"),
    (lambda: spin([1, -2, 3], [1, 0, 0], 1.0), "`inertia` must be symmetric positive definite"),
    (lambda: spin([1, 1, 3], [0, 0, 1], 1.0), "`inertia` violates the triangle inequality"),
    (lambda: spin([1, 2, 3], [0, 0, 0], 1.0), "`axis` must be a finite non-zero 3-vector"),
    (lambda: spin([1, 2, 3], [1, 1, 0], 1.0), "`axis` must be a principal axis of `inertia`"),
    (lambda: spin([1, 2, 3], [1, 0], 1.0), "`axis` must be a finite non-zero 3-vector"),
    (lambda: spin([1, 2, 3], [1, 0, 0], 0.0), "`rate` must be non-zero"),
    (lambda: spin([1, 2, 3], [1, 0, 0], np.nan), "`rate` must be finite"),
    (lambda: spin([1, 2, 3], [1, 0, 0], np.inf), "`rate` must be finite"),
    (lambda: spin([1, 2, 3], [1, 0, 0], 1.0, damper="fluid"), "`damper` must be None"),
    (lambda: PointMassDamper(-1, 1, 1), "`damper.mass` must be positive"),
    (lambda: PointMassDamper(1, 1, 1, direction=(0, 0, 0)), "`damper.direction` must be"),
    (lambda: SphericalDamper(0.1, -1), "`damper.damping` must be non-negative"),
    (lambda: heavy_top(0.02, 0.005, 0.3, 0.04, 10), "`axial_inertia` 0.02 exceeds 2"),
    (lambda: heavy_top(0.002, 0.005, 0.0, 0.04, 10), "`mass` must be positive"),
    (lambda: heavy_top(0.002, -0.005, 0.3, 0.04, 10), "`transverse_inertia` must be positive"),
    (lambda: rotor(0.01, 0.05, -1, 0.1, 10), "`stiffness` must be non-negative"),
    (lambda: gyrostat([3, 4, 5], [1, 0, 0], 0.0, 0.0), "`rate` and `wheel_momentum` are both zero"),
    (lambda: gyrostat([3, 4, 4], [1, 0, 0], 1.0, 1.0, damper=SphericalDamper(0.1, 0.1),
                      damper_on="rotor"), "`wheel_inertia` is needed"),
    (lambda: gyrostat([3, 4, 4], [1, 0, 0], 1.0, 1.0, damper=PointMassDamper(1, 1, 1),
                      damper_on="rotor", wheel_inertia=0.5), "`damper_on`='rotor' needs"),
])
def test_invalid_input_names_the_argument(call, name):
    with pytest.raises(ValueError, match=name.replace("(", r"\(").replace(")", r"\)")):
        call()


# -------------------------------------------------------------------- report I/O
@pytest.fixture(scope="module")
def reports():
    P, _, _ = launch_vehicle()
    damper = PointMassDamper(0.5, 60, 0.8, (0.6, 0, 0), (0, 0, 1))
    return [spin([2, 3, 4.5], [0, 0, 1], 5.0, damper=damper),
            top(40.0), top(10.0), rotor(0.01, 0.05, 1e4, 0.1, 100.0, internal_damping=0.01),
            gyrostat([3, 4, 4], [1, 0, 0], 2.0, 1.0, damper=SphericalDamper(0.1, 0.05)),
            loop(P, [[0.8, 0.3]])]


def test_report_to_dict_is_strict_json(reports):
    for rep in reports:
        d = json.loads(json.dumps(rep.to_dict(), allow_nan=False))
        assert d["verdict"] == rep.verdict in st.VERDICTS
        assert len(d["eigenvalues"]) == len(rep.eigenvalues)
        assert all(len(z) == 2 for z in d["eigenvalues"])
        assert d["eigenvalues"][0] == [rep.eigenvalues[0].real, rep.eigenvalues[0].imag]
        assert d["states"] == list(rep.ss.state_labels)
        assert json.loads(rep.to_json()) == d
    assert json.loads(reports[-1].to_json())["margins"]["gain_margin"] is None  # inf


def test_report_text_is_a_table(reports):
    text = str(reports[1])
    assert "verdict: MARGINALLY STABLE" in text
    assert "slow forward precession" in text and "Eq. 4.130" in text
    assert "eigenvalue [1/s]" in text and "wn [rad/s]" in text and "zeta" in text
    assert "phase margin" in str(reports[-1])
    for rep in reports:
        for m in rep.modes:
            assert m.wn == pytest.approx(abs(m.eigenvalue), rel=1e-15)
            if m.wn > 0:
                assert m.zeta == pytest.approx(-m.eigenvalue.real / m.wn, rel=1e-15, abs=1e-300)


@pytest.mark.slow
def test_plots_write_png(tmp_path, reports):
    path = tmp_path / "poles.png"
    reports[0].plot().savefig(path)  # the library builds, the caller saves
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000
    res = sweep("rotor", "rate", [30.0, 90.0], axial_inertia=0.01, transverse_inertia=0.05,
                stiffness=1e4, bearing_distance=0.1, internal_damping=0.01)
    res.plot().savefig(tmp_path / "sweep.png")
    data = (tmp_path / "sweep.png").read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000
    assert json.loads(res.to_json())["boundaries"][0]["after"] == "unstable"


# ----------------------------------------------------------------------------- CLI
def test_cli_spin_with_damper_json_and_plot(tmp_path, capsys):
    out, png = tmp_path / "spin.json", tmp_path / "spin.png"
    code = cli_main(["spin", "--inertia", "2,3,4.5", "--axis", "0,0,1", "--rate", "5",
                     "--damper", "point", "mass=0.5", "stiffness=60", "damping=0.8",
                     "position=0.6,0,0", "direction=0,0,1", "--json", str(out), "--plot", str(png)])
    assert code == 0
    text = capsys.readouterr().out
    assert "verdict: ASYMPTOTICALLY STABLE" in text and "nutation" in text and "damper" in text
    assert json.loads(out.read_text())["verdict"] == "asymptotically stable"
    assert png.stat().st_size > 10_000


@pytest.mark.slow
def test_cli_through_an_argparse_tree_like_appdyn(capsys):
    parser = argparse.ArgumentParser(prog="appdyn")
    sub = parser.add_subparsers(dest="command", required=True)
    add_stability_parser(sub)
    args = parser.parse_args(["stability", "heavy-top", "--axial-inertia", "0.002",
                              "--transverse-inertia", "0.005", "--mass", "0.3", "--length",
                              "0.04", "--rate", "40"])
    assert (args.command, args.case) == ("stability", "heavy-top")
    assert cli_run(args) == 0
    assert "slow forward precession" in capsys.readouterr().out
    args = parser.parse_args(["stability", "sweep", "gyrostat", "--parameter", "wheel-momentum",
                              "--values=-2:8:6", "--inertia", "3,4,5", "--axis", "1,0,0",
                              "--rate", "2"])
    assert cli_run(args) == 0
    text = capsys.readouterr().out
    assert "wheel_momentum = 1.99999999" in text and "wheel_momentum = 4.0000000" in text


@pytest.mark.parametrize("argv, message", [
    (["spin", "--inertia", "1,2,3", "--axis", "1,1,0", "--rate", "1"], "principal axis"),
    (["spin", "--inertia", "1,2,3", "--axis", "1,0,0", "--rate", "0"], "`rate` must be non-zero"),
    (["spin", "--inertia", "1,2,3", "--axis", "1,0,0", "--rate", "1", "--damper", "ring"],
     "`--damper` kind must be"),
    (["spin", "--inertia", "1,2,3", "--axis", "1,0,0", "--rate", "1", "--damper", "sphere",
      "inertia=0.1"], "`--damper sphere` needs"),
    (["sweep", "rotor", "--parameter", "rate", "--values", "1:2:3", "--axial-inertia", "0.01"],
     "sweep rotor needs --transverse-inertia"),
    (["sweep", "rotor", "--parameter", "rate", "--values", "1:2", "--axial-inertia", "0.01",
      "--transverse-inertia", "0.05", "--stiffness", "1", "--bearing-distance", "1"],
     "`--values` must be START:STOP:NUM"),
])
def test_cli_bad_input_exits_2(argv, message, capsys):
    with pytest.raises(SystemExit) as exc:
        cli_main(argv)
    assert exc.value.code == 2
    assert message in capsys.readouterr().err


# ------------------------------------------------------- statuses, figures, examples
def test_report_status_success_message(reports):
    for rep in reports:
        assert rep.status in (st.STATUS_VERIFIED, st.STATUS_UNCHECKED, st.STATUS_MISMATCH)
        assert rep.success is (rep.status != st.STATUS_MISMATCH)
        d = rep.to_dict()
        assert (d["success"], d["status"], d["message"]) == (rep.success, rep.status, rep.message)
    assert reports[1].status == st.STATUS_VERIFIED  # heavy top: Eq. 4.127
    assert reports[0].status == st.STATUS_UNCHECKED  # point-mass damper: no closed form here
    assert "no closed form" in reports[0].message
    expected_wrong = st.loop(launch_vehicle()[0], [[0.8, 0.3]], closed_form=[-1.0, -2.0])
    assert expected_wrong.status == st.STATUS_MISMATCH and not expected_wrong.success
    assert "DISAGREE" in expected_wrong.message


def test_sweep_status_is_the_worst_along_the_grid():
    res = sweep("heavy_top", "rate", [10.0, 40.0], axial_inertia=0.002,
                transverse_inertia=0.005, mass=0.3, length=0.04)
    assert res.statuses == (st.STATUS_VERIFIED, st.STATUS_VERIFIED)
    assert res.success and res.status == st.STATUS_VERIFIED
    d = json.loads(res.to_json())
    assert d["success"] is True and d["status"] == 0 and d["statuses"] == [0, 0]


@pytest.mark.slow
def test_plots_return_figures_without_pyplot(reports):
    from matplotlib.figure import Figure

    fig = reports[1].plot()
    assert isinstance(fig, Figure) and len(fig.axes) == 1
    other = Figure()
    ax = other.add_subplot(1, 1, 1)
    assert reports[1].plot(ax=ax) is other
    res = sweep("rotor", "rate", [30.0, 90.0], axial_inertia=0.01, transverse_inertia=0.05,
                stiffness=1e4, bearing_distance=0.1, internal_damping=0.01)
    assert len(res.plot().axes) == 2
    import pathlib

    import appdyn.problems.torque_free  # noqa: F401

    from appdyn import problems

    for path in [*pathlib.Path(st.__file__).parent.glob("*.py"),
                 pathlib.Path(problems.torque_free.__file__)]:
        text = path.read_text()
        assert "matplotlib.use(" not in text and "import matplotlib.pyplot" not in text, path


def test_one_case_table_serves_library_and_cli():
    from appdyn.problems.cli.stability import _OPTIONS

    for cli_name in _OPTIONS:
        name, fun = st.resolve_case(cli_name)
        assert st.CASES[name] is fun


@pytest.mark.parametrize("module", ["__init__", "verdict", "report", "closed_forms", "spin",
                                    "spin_scene", "common", "tilt", "loop", "cases", "sweep"])
def test_docstring_examples_run(module):
    """The Examples sections of problems.stability, printed values included."""
    import doctest
    import importlib

    mod = importlib.import_module("appdyn.problems.stability" + ("" if module == "__init__"
                                                         else f".{module}"))
    result = doctest.testmod(mod, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.failed == 0
    assert result.attempted > 0
