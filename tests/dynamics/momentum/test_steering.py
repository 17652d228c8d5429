"""CMG steering laws and null motion.

Independent truths: the body torque of the gimbal motion summed unit by unit from Eq. 4.150
(`cmg_torque`, ``-w_c x H_m`` with ``w_c = delta_dot_i g_i``), numpy's minimum-norm least
squares (``lstsq``), the damped least-squares problem ``min |C x + tau|^2 + lam |x|^2`` solved as
a stacked least-squares system, the singular-value bound ``sigma / (sigma^2 + lam) <=
1 / (2 sqrt(lam))``, the first-order growth ``sigma_min ~ eps |N^T P v|`` of the smallest
singular value along a path leaving a singular state, and CasADi's automatic gradient.
"""
import doctest

import casadi as ca
import numpy as np
import pytest

from appdyn.dynamics.momentum import (cluster_jacobian, cluster_momentum, cmg_torque, gram_determinant,
                               gsr_inverse_steering, null_motion, pseudo_inverse_steering, pyramid,
                               singular_direction, sr_inverse_steering, steering)

BETA = np.deg2rad(54.74)
GEO = pyramid(BETA, [1.0, 2.0, 1.5, 0.5])
ELLIPTIC = np.deg2rad([-90, 0, 90, 0])
RNG = np.random.default_rng(7)


def states(count):
    """Random gimbal states, kept away from singular ones."""
    out = []
    while len(out) < count:
        d = RNG.uniform(-np.pi, np.pi, 4)
        if gram_determinant(cluster_jacobian(GEO, d)) > 0.1:
            out.append(d)
    return out


def body_torque(geo, delta, rate):
    """Sum of Eq. 4.150 over the units: w_c = rate_i g_i turns H_m = h_i s_i."""
    spin = np.cos(delta) * geo.spin_axes0 + np.sin(delta) * geo.transverse_axes0
    return sum(cmg_torque(rate[i] * geo.gimbal_axes[:, i], geo.h[i] * spin[:, i])
               for i in range(geo.n))


def sr_gain(C, lam0=0.01, mu=10.0):
    return lam0 * np.exp(-mu * np.linalg.det(C @ C.T))


# ------------------------------------------------------------------------- sign convention
@pytest.mark.parametrize("law", [pseudo_inverse_steering, sr_inverse_steering,
                                 gsr_inverse_steering])
def test_laws_command_the_body_torque(law):
    """tau = -C delta_dot, checked against the unit-by-unit torque of Eq. 4.150."""
    for d in states(5):
        C = cluster_jacobian(GEO, d)
        tau = RNG.normal(size=3)
        rate = law(C, tau)
        assert rate.shape == (4,)
        np.testing.assert_allclose(body_torque(GEO, d, rate), -C @ rate, atol=1e-13)
        if law is pseudo_inverse_steering:  # (lam ~ 1e-40 here: the damped laws too)
            np.testing.assert_allclose(body_torque(GEO, d, rate), tau, atol=1e-12)


def test_sr_torque_error_is_bounded_by_the_damping():
    """-C delta_dot - tau = -lam (C C^T + lam I)^-1 tau: |error| <= lam / (sigma_min^2 + lam)."""
    geo = pyramid(BETA)
    for offset in (1e-3, 1e-2, 0.1, 0.5):
        d = ELLIPTIC + offset * RNG.normal(size=4)
        C = cluster_jacobian(geo, d)
        tau = RNG.normal(size=3)
        err = np.linalg.norm(body_torque(geo, d, sr_inverse_steering(C, tau)) - tau)
        s_min, lam = np.linalg.svd(C, compute_uv=False)[-1], sr_gain(C)
        assert err <= (lam / (s_min ** 2 + lam) + 1e-14) * np.linalg.norm(tau)


def test_pseudo_inverse_is_the_minimum_norm_solution():
    for d in states(5):
        C = cluster_jacobian(GEO, d)
        tau = RNG.normal(size=3)
        x = np.linalg.lstsq(C, -tau, rcond=None)[0]
        np.testing.assert_allclose(pseudo_inverse_steering(C, tau), x, atol=1e-13)


def test_sr_inverse_is_damped_least_squares():
    """C^T (C C^T + lam I)^-1 = argmin |C x + tau|^2 + lam |x|^2 (push-through identity)."""
    for d in [*states(4), ELLIPTIC + 0.01]:
        C = cluster_jacobian(GEO, d)
        tau = RNG.normal(size=3)
        for lam0, mu in [(0.01, 10.0), (0.3, 0.0), (1e-3, 2.0)]:
            lam = sr_gain(C, lam0, mu)
            stacked = np.vstack([C, np.sqrt(lam) * np.eye(4)])
            x = np.linalg.lstsq(stacked, np.concatenate([-tau, np.zeros(4)]), rcond=None)[0]
            np.testing.assert_allclose(sr_inverse_steering(C, tau, lam0=lam0, mu=mu), x, atol=1e-11)


def test_sr_without_damping_is_the_pseudo_inverse():
    for d in states(3):
        C = cluster_jacobian(GEO, d)
        tau = RNG.normal(size=3)
        np.testing.assert_allclose(sr_inverse_steering(C, tau, lam0=0.0),
                                   pseudo_inverse_steering(C, tau), atol=1e-12)


# ------------------------------------------------------------------------- near a singularity
def test_pseudo_inverse_blows_up_and_sr_stays_bounded_near_a_singularity():
    """Leave the elliptic singular state along v; command torque along the singular direction u.

    sigma_min(C(d0 + eps v)) = eps |N^T P v| + O(eps^2) (N: null space of C(d0), P = diag(u .
    h_i s_i)), so the pseudo-inverse rate is |tau| / (eps |N^T P v|) to first order; the SR
    rate is at most |tau| / (2 sqrt(lam)) for every state.
    """
    geo = pyramid(BETA)
    u = singular_direction(geo, ELLIPTIC)
    C0 = cluster_jacobian(geo, ELLIPTIC)
    assert np.linalg.norm(u @ C0) <= 1e-15
    units = np.cos(ELLIPTIC) * geo.spin_axes0 + np.sin(ELLIPTIC) * geo.transverse_axes0
    N = np.linalg.svd(C0)[2][2:].T
    v = np.array([0.3, -0.5, 0.7, 0.4]) / np.linalg.norm([0.3, -0.5, 0.7, 0.4])
    slope = np.linalg.norm(N.T @ ((u @ units) * v))
    eps = np.logspace(-6, -1, 11)
    pinv, sr, bound = [], [], []
    for e in eps:
        C = cluster_jacobian(geo, ELLIPTIC + e * v)
        pinv.append(np.linalg.norm(pseudo_inverse_steering(C, u)))
        sr.append(np.linalg.norm(sr_inverse_steering(C, u)))
        bound.append(1 / (2 * np.sqrt(sr_gain(C))))
    pinv, sr, bound = map(np.array, (pinv, sr, bound))
    small = eps <= 1e-3
    assert np.polyfit(np.log(eps[small]), np.log(pinv[small]), 1)[0] == pytest.approx(-1, abs=1e-3)
    assert pinv[0] * eps[0] * slope == pytest.approx(1.0, abs=1e-5)  # O(eps) from the limit
    assert np.all(sr <= bound)
    assert np.all(bound <= 1 / (2 * np.sqrt(0.01 * np.exp(-10 * 1.0))))  # det <= 1 on the path
    assert pinv[0] > 1e5 and sr.max() < 5.1


def test_sr_locks_and_gsr_moves_at_the_singular_state():
    """At the singular state with torque along u, C^T u = 0 makes the SR rates vanish; the
    dither couples u with the other directions: to first order in lam / sigma^2 the GSR rate
    is C^+ (E - I) u."""
    geo = pyramid(BETA)
    C = cluster_jacobian(geo, ELLIPTIC)
    u = singular_direction(geo, ELLIPTIC)
    assert np.linalg.norm(sr_inverse_steering(C, u)) <= 1e-13
    sigma = np.linalg.svd(C, compute_uv=False)
    for t in (0.0, 0.5, 1.0, 1.7, 3.2):
        e1, e2, e3 = 0.01 * np.sin(np.pi / 2 * t + np.array([0.0, np.pi / 2, np.pi]))  # Wie's
        E = np.array([[1, e3, e2], [e3, 1, e1], [e2, e1, 1]])
        rate = gsr_inverse_steering(C, u, t)
        first_order = np.linalg.pinv(C) @ ((E - np.eye(3)) @ u)
        rel = np.linalg.norm(rate - first_order) / np.linalg.norm(first_order)
        assert rel <= 0.01 / sigma[1] ** 2 + 0.01 ** 2
        assert np.linalg.norm(rate) > 1e-3


def test_gsr_without_dither_is_sr():
    for d in [*states(3), ELLIPTIC]:
        C = cluster_jacobian(GEO, d)
        tau = RNG.normal(size=3)
        sr = sr_inverse_steering(C, tau)
        np.testing.assert_allclose(gsr_inverse_steering(C, tau), sr, atol=1e-14)
        np.testing.assert_allclose(gsr_inverse_steering(C, tau, t=2.0, eps0=0.0), sr, atol=1e-14)


# ------------------------------------------------------------------------- null motion
def measure_gradient(geo):
    d = ca.SX.sym("d", geo.n)
    det = gram_determinant(cluster_jacobian(geo, d))
    return ca.Function("grad", [d], [ca.gradient(det, d)])


def test_null_motion_keeps_momentum_and_raises_the_measure():
    grad = measure_gradient(GEO)
    for d in [*states(5), ELLIPTIC + 0.05]:
        C = cluster_jacobian(GEO, d)
        g = grad(d).full().ravel()
        n = null_motion(C, g)
        np.testing.assert_allclose(C @ n, 0.0, atol=1e-13)
        assert g @ n == pytest.approx(n @ n, rel=1e-12)  # dm/dt = |(I - C^+ C) g|^2 >= 0
        k = 1e-4 / max(np.linalg.norm(n), 1e-300)
        H0, m0 = cluster_momentum(GEO, d), gram_determinant(C)
        assert gram_determinant(cluster_jacobian(GEO, d + k * n)) > m0
        for step in (k, k / 10):  # H changes only to second order in the step
            dH = np.linalg.norm(cluster_momentum(GEO, d + step * n) - H0)
            assert dH <= np.sum(GEO.h) * (step * np.linalg.norm(n)) ** 2


# ------------------------------------------------------------------------- CasADi, inputs, docs
@pytest.mark.parametrize("sym", [ca.SX, ca.MX])
def test_casadi_laws_agree_with_numpy(sym):
    d, tau, t, g = sym.sym("d", 4), sym.sym("tau", 3), sym.sym("t"), sym.sym("g", 4)
    C = cluster_jacobian(GEO, d)
    f = ca.Function("f", [d, tau, t, g], [
        pseudo_inverse_steering(C, tau), sr_inverse_steering(C, tau),
        gsr_inverse_steering(C, tau, t), null_motion(C, g)])
    for x in states(3):
        tv, tt, gv = RNG.normal(size=3), RNG.uniform(0, 5), RNG.normal(size=4)
        Cn = cluster_jacobian(GEO, x)
        ref = [pseudo_inverse_steering(Cn, tv), sr_inverse_steering(Cn, tv),
               gsr_inverse_steering(Cn, tv, tt), null_motion(Cn, gv)]
        for got, want in zip(f(x, tv, tt, gv), ref):
            np.testing.assert_allclose(got.full().ravel(), want, atol=1e-12)


@pytest.mark.parametrize("call, exc, name", [
    (lambda C: pseudo_inverse_steering(C.T, [1, 0, 0]), ValueError, "C"),
    (lambda C: pseudo_inverse_steering(C[:, 0], [1, 0, 0]), ValueError, "C"),
    (lambda C: sr_inverse_steering(C, [1, 0]), ValueError, "torque"),
    (lambda C: sr_inverse_steering(C, [1, 0, np.nan]), ValueError, "torque"),
    (lambda C: sr_inverse_steering(C, [1, 0, 0], lam0=-1.0), ValueError, "lam0"),
    (lambda C: sr_inverse_steering(C, [1, 0, 0], mu=np.inf), ValueError, "mu"),
    (lambda C: gsr_inverse_steering(C, [1, 0, 0], t="now"), TypeError, "t"),
    (lambda C: gsr_inverse_steering(C, [1, 0, 0], t=1.0, phase=[0, 1]), ValueError, "phase"),
    (lambda C: gsr_inverse_steering(C, [1, 0, 0], t=1.0, eps0=-0.1), ValueError, "eps0"),
    (lambda C: null_motion(C, [1.0, 2.0, 3.0]), ValueError, "gradient"),
    (lambda C: null_motion("C", [1.0, 2.0, 3.0, 4.0]), TypeError, "C"),
    (lambda C: pseudo_inverse_steering(C, None), TypeError, "torque"),
])
def test_bad_inputs_name_the_argument(call, exc, name):
    with pytest.raises(exc, match=f"`{name}`"):
        call(cluster_jacobian(GEO, np.zeros(4)))


def test_docstring_examples_run():
    result = doctest.testmod(steering, optionflags=doctest.NORMALIZE_WHITESPACE | doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0
