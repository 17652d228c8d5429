"""Mass properties and variable mass (seed Sec. 4.4 B-E, Sec. 3.4).

Truths: inertia sums over clouds of point masses, ``sum m (r^2 E - r r^T)`` (Eq. 4.16 sign),
computed about the point and in the axes asked for; momentum conservation for the discrete
rocket; Tsiolkovsky's logarithm as its limit; the quadrature of Eq. 3.48.
"""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from appdyn.dynamics.attitude import dcm_from_quat
from appdyn.dynamics.mass import (G0, delta_v, inertia_about_axis, isp, jet_damping_torque,
                                  parallel_axis, radius_of_gyration, rocket_steps,
                                  rotate_inertia)


def _cloud_inertia(m, r):
    """sum m (r^2 E - r r^T) of point masses m (n,) at r (n, 3)."""
    return sum(mi * (ri @ ri * np.eye(3) - np.outer(ri, ri)) for mi, ri in zip(m, r))


clouds = st.integers(0, 2**31 - 1).map(lambda s: np.random.default_rng(s))


@settings(max_examples=50, deadline=None)
@given(rng=clouds)
def test_parallel_axis_equals_the_sum_over_point_masses(rng):
    m = rng.uniform(0.1, 3.0, 6)
    r = rng.normal(size=(6, 3))  # about O
    c = m @ r / m.sum()  # mass centre relative to O
    I_cm = _cloud_inertia(m, r - c)
    I_O = _cloud_inertia(m, r)
    scale = np.max(np.abs(I_O))
    np.testing.assert_allclose(parallel_axis(I_cm, m.sum(), c), I_O, rtol=0, atol=1e-13 * scale)
    np.testing.assert_allclose(parallel_axis(I_O, m.sum(), c, inverse=True), I_cm, rtol=0,
                               atol=1e-13 * scale)


@settings(max_examples=50, deadline=None)
@given(rng=clouds)
def test_rotated_axes_and_moment_about_an_axis_equal_the_sums(rng):
    m = rng.uniform(0.1, 3.0, 5)
    r = rng.normal(size=(5, 3))
    q = rng.normal(size=4)
    A = dcm_from_quat(q / np.linalg.norm(q))
    I = _cloud_inertia(m, r)
    scale = np.max(np.abs(I))
    np.testing.assert_allclose(rotate_inertia(I, A), _cloud_inertia(m, r @ A.T), rtol=0,
                               atol=1e-13 * scale)
    e = rng.normal(size=3)
    u = e / np.linalg.norm(e)
    dist2 = [np.sum(np.cross(ri, u) ** 2) for ri in r]  # squared distance from the axis
    assert inertia_about_axis(I, e) == pytest.approx(m @ dist2, rel=1e-13)
    assert radius_of_gyration(I, m.sum(), axis=e) == pytest.approx(np.sqrt(m @ dist2 / m.sum()),
                                                                   rel=1e-13)


def test_seed_component_forms_and_a_ring():
    # I11 = I11c + M (d2^2 + d3^2), I12 = I12c - M d1 d2 (Sec. 4.4 B)
    Ic = np.array([[5.0, 0.3, -0.2], [0.3, 4.0, 0.1], [-0.2, 0.1, 3.0]])
    d, M = np.array([0.5, -1.0, 2.0]), 2.0
    I = parallel_axis(Ic, M, d)
    assert I[0, 0] == pytest.approx(5.0 + M * (1.0 + 4.0))
    assert I[0, 1] == pytest.approx(0.3 - M * 0.5 * -1.0)
    assert I[1, 2] == pytest.approx(0.1 - M * -1.0 * 2.0)
    # a ring of radius R about its axis: k = R; about a diameter: R / sqrt(2)
    phi = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    r = 1.5 * np.c_[np.cos(phi), np.sin(phi), 0 * phi]
    I = _cloud_inertia(np.full(12, 0.25), r)
    assert radius_of_gyration(I, 3.0, axis=[0, 0, 1]) == pytest.approx(1.5, rel=1e-14)
    assert radius_of_gyration(I, 3.0, axis=[1, 0, 0]) == pytest.approx(1.5 / np.sqrt(2), rel=1e-14)
    assert radius_of_gyration(I[2, 2], 3.0) == pytest.approx(1.5, rel=1e-14)


def test_seed_two_bullets_and_momentum_conservation():
    M, m, C = 500.0, 2.0, 800.0
    # seed: V1 = 2 m C / (M + 2 m) at once; m C / (M + 2 m), then + m C / (M + m)
    assert rocket_steps(M, m, C, 2, simultaneous=True) == pytest.approx(2 * m * C / (M + 2 * m))
    np.testing.assert_allclose(rocket_steps(M, m, C, 2),
                               [m * C / (M + 2 * m), m * C * (1 / (M + m) + 1 / (M + 2 * m))],
                               rtol=1e-15)
    # every firing conserves momentum: vehicle + pellets fired so far, each at V_k - C
    N = 7
    V = rocket_steps(M, m, C, N)
    for k in range(1, N + 1):
        p = (M + (N - k) * m) * V[k - 1] + m * np.sum(V[:k] - C)
        assert p == pytest.approx(0.0, abs=1e-9 * M * C)
    assert V[-1] > rocket_steps(M, m, C, N, simultaneous=True)


def test_discrete_rocket_tends_to_tsiolkovsky():
    M, propellant, C = 100.0, 150.0, 3000.0
    exact = delta_v(M + propellant, M, exhaust_velocity=C)
    assert exact == pytest.approx(C * np.log(2.5), rel=1e-15)
    errors = []
    for N in (10, 100, 1000):
        V = rocket_steps(M, propellant / N, C, N)[-1]
        err = exact - V  # the sum is a right Riemann sum of C dm/m: below the integral
        bound = C * (propellant / N) * (1 / M - 1 / (M + propellant))  # trapezoid-rule gap x 2
        assert 0 < err <= bound
        errors.append(err)
    assert errors[1] / errors[0] == pytest.approx(0.1, rel=0.05)  # first order in 1/N
    assert errors[2] / errors[1] == pytest.approx(0.1, rel=0.01)


def test_isp_and_exhaust_velocity():
    # Eq. 3.40: Is = F / (mdot g0) = C / g0; the SSME's 410 s is C = 4020.7 m/s
    mdot = 400.0
    F = mdot * 410 * G0
    assert isp(F, mdot) == pytest.approx(410.0, rel=1e-15)
    assert delta_v(3.0, 1.0, isp=410.0) == pytest.approx(delta_v(3.0, 1.0, exhaust_velocity=F / mdot))
    np.testing.assert_allclose(isp([F, 2 * F], mdot), [410.0, 820.0], rtol=1e-15)


def test_jet_damping_equals_the_quadrature_of_eq_3_48():
    # L_C = -2 mdot int r x (w x dr), r = x i, w = w k, flow from l1 to l2 (per unit flow)
    md, w, l1, l2 = 3.0, 0.4, -0.5, 2.5
    x = np.linspace(l1, l2, 2001)
    integrand = np.cross(np.c_[x, 0 * x, 0 * x], np.cross([0, 0, w], [1.0, 0, 0]))[:, 2]
    quad = -2 * md * np.sum((integrand[1:] + integrand[:-1]) / 2 * np.diff(x))
    assert jet_damping_torque(md, w, l1, l2) == pytest.approx(quad, rel=1e-12)
    assert jet_damping_torque(md, w, -l2, l2) == 0.0  # case (c)


@pytest.mark.parametrize("call, match", [
    (lambda: parallel_axis([[1, 2, 0], [0, 1, 0], [0, 0, 1]], 1.0, [0, 0, 1]), "`inertia` must be symmetric"),
    (lambda: parallel_axis([1, 1, 1], 0.0, [0, 0, 1]), "`mass`"),
    (lambda: parallel_axis([1, 1, 1], 1.0, [0, 1]), "`offset`"),
    (lambda: parallel_axis([1, 1, 1], 1.0, [0, 0, 2], inverse=True), "positive semi-definite"),
    (lambda: rotate_inertia([1, 2, 3], 2 * np.eye(3)), "`A`"),
    (lambda: inertia_about_axis([1, 2, 3], [0, 0, 0]), "`axis`"),
    (lambda: radius_of_gyration([1, 2, 3], 1.0), "`axis` is required"),
    (lambda: radius_of_gyration(1.0, 1.0, axis=[1, 0, 0]), "`axis` is only"),
    (lambda: delta_v(1.0, 2.0, isp=300.0), "initial_mass"),
    (lambda: delta_v(2.0, 1.0), "exactly one"),
    (lambda: delta_v(2.0, 1.0, isp=300.0, exhaust_velocity=3000.0), "exactly one"),
    (lambda: isp(1.0, 0.0), "`mass_flow`"),
    (lambda: rocket_steps(1.0, 1.0, 1.0, 0), "`count`"),
    (lambda: jet_damping_torque(-1.0, 1.0, 0.0, 1.0), "`mass_flow`"),
])
def test_bad_input_names_the_argument(call, match):
    with pytest.raises(ValueError, match=match):
        call()
