"""Euler-angle and DCM kinematics (seed Sec. 4.3, Eqs. 4.33, 4.36-4.37, 4.39-4.40).

Independent truths: the derivative of the DCM built from the angles (a 5-point finite
difference of ``dcm_from_euler*``, no rate formula involved), the derivative of the quaternion
built from the angles against the quaternion kinematics ``quat_rate`` (Eq. 4.70), and the
closed-form quaternion propagation for the Poisson equation.
"""
import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from appdyn.dynamics.attitude import (body_rates_from_euler313,
                                      body_rates_from_euler321, dcm_from_euler313,
                                      dcm_from_euler321, dcm_from_quat, dcm_rate, euler313_rates,
                                      euler321_rates, propagate_quat, quat_from_euler313,
                                      quat_from_euler321, quat_rate)
from appdyn.dynamics.validate import EULER_LOCK_TOL

SEQ = {
    "321": (dcm_from_euler321, quat_from_euler321, euler321_rates, body_rates_from_euler321),
    "313": (dcm_from_euler313, quat_from_euler313, euler313_rates, body_rates_from_euler313),
}
angle = st.floats(-np.pi, np.pi, allow_nan=False)
rate = st.floats(-2.0, 2.0, allow_nan=False)
triples = st.tuples(angle, angle, angle).map(np.array)
rates3 = st.tuples(rate, rate, rate).map(np.array)


def _away_from_lock(seq, angles):
    th = angles[1]
    return abs(np.cos(th)) > 0.05 if seq == "321" else abs(np.sin(th)) > 0.05


def _d_dt(f, a0, r, h=1e-3):
    """5-point central difference of f(a0 + r t) at t = 0 (error ~ h^4)."""
    return (-f(a0 + 2 * h * r) + 8 * f(a0 + h * r) - 8 * f(a0 - h * r) + f(a0 - 2 * h * r)) / (12 * h)


def _vee(S):
    """The vector of a skew matrix S = [w x]."""
    return np.array([S[2, 1], S[0, 2], S[1, 0]])


@pytest.mark.parametrize("seq", sorted(SEQ))
@settings(max_examples=60, deadline=None)
@given(angles=triples, r=rates3)
def test_body_rates_equal_the_derivative_of_the_dcm(seq, angles, r):
    # A' A^T = -[w x] (Eq. 4.33) with A built from the angles: w from the DCM alone
    dcm, _, _, body = SEQ[seq]
    A = dcm(angles)
    S = -_d_dt(dcm, angles, r) @ A.T
    np.testing.assert_allclose(S, -S.T, atol=1e-9)
    np.testing.assert_allclose(body(angles, r), _vee(S), rtol=0, atol=1e-9)


@pytest.mark.parametrize("seq", sorted(SEQ))
@settings(max_examples=60, deadline=None)
@given(angles=triples, r=rates3)
def test_dcm_rate_and_quat_rate_are_the_derivatives_of_dcm_and_quat_built_from_the_angles(
        seq, angles, r):
    # A' = dcm_rate(A, w) (Eq. 4.33) and q' = quat_rate(q, w) (Eq. 4.70), w = the body rates
    dcm, quat, _, body = SEQ[seq]
    w = body(angles, r)
    np.testing.assert_allclose(dcm_rate(dcm(angles), w), _d_dt(dcm, angles, r), rtol=0,
                               atol=1e-9)
    np.testing.assert_allclose(quat_rate(quat(angles), w), _d_dt(quat, angles, r), rtol=0,
                               atol=1e-9)


@pytest.mark.parametrize("seq", sorted(SEQ))
@settings(max_examples=100, deadline=None)
@given(angles=triples, r=rates3, w=rates3)
def test_round_trips(seq, angles, r, w):
    _, _, rates, body = SEQ[seq]
    if not _away_from_lock(seq, angles):
        return
    # 1/cos or 1/sin >= 0.05: condition number <= ~20
    np.testing.assert_allclose(body(angles, rates(angles, w)), w, rtol=0, atol=1e-13 * 40)
    np.testing.assert_allclose(rates(angles, body(angles, r)), r, rtol=0, atol=1e-13 * 400)


@settings(max_examples=60, deadline=None)
@given(q=st.tuples(*[st.floats(-1, 1)] * 4).filter(lambda v: np.linalg.norm(v) > 0.1),
       w=rates3)
def test_dcm_rate_against_the_closed_form_quaternion_propagation(q, w):
    q = np.array(q) / np.linalg.norm(q)
    f = lambda h: dcm_from_quat(propagate_quat(q, w, h))  # exact for constant w
    h = 1e-3
    fd = (-f(2 * h) + 8 * f(h) - 8 * f(-h) + f(-2 * h)) / (12 * h)
    np.testing.assert_allclose(dcm_rate(dcm_from_quat(q), w), fd, rtol=0, atol=1e-10)


def test_seed_component_forms():
    # the component equations printed under Eq. 4.36 and Eq. 4.39, at one generic point
    psi, th, phi = 0.7, -0.4, 1.9
    dpsi, dth, dphi = 0.3, -0.8, 1.1
    s, c = np.sin, np.cos
    np.testing.assert_allclose(
        body_rates_from_euler313([psi, th, phi], [dpsi, dth, dphi]),
        [dpsi * s(th) * s(phi) + dth * c(phi), dpsi * s(th) * c(phi) - dth * s(phi),
         dpsi * c(th) + dphi], rtol=1e-15, atol=1e-15)
    np.testing.assert_allclose(
        body_rates_from_euler321([psi, th, phi], [dpsi, dth, dphi]),
        [dphi - dpsi * s(th), dth * c(phi) + dpsi * c(th) * s(phi),
         dpsi * c(th) * c(phi) - dth * s(phi)], rtol=1e-15, atol=1e-15)
    # Eq. 4.37 and Eq. 4.40 as matrices
    w = np.array([0.2, -0.5, 0.9])
    M313 = np.array([[s(phi), c(phi), 0], [s(th) * c(phi), -s(th) * s(phi), 0],
                     [-c(th) * s(phi), -c(th) * c(phi), s(th)]]) / s(th)
    M321 = np.array([[0, s(phi), c(phi)], [0, c(phi) * c(th), -s(phi) * c(th)],
                     [c(th), s(phi) * s(th), c(phi) * s(th)]]) / c(th)
    np.testing.assert_allclose(euler313_rates([psi, th, phi], w), M313 @ w, rtol=1e-14)
    np.testing.assert_allclose(euler321_rates([psi, th, phi], w), M321 @ w, rtol=1e-14)


@pytest.mark.parametrize("seq", sorted(SEQ))
def test_batches_and_casadi_agree_with_single_numpy_calls(seq):
    dcm, _, rates, body = SEQ[seq]
    rng = np.random.default_rng(3)
    angles = rng.uniform(0.2, 1.3, (3, 5))
    w = rng.normal(size=(3, 5))
    batch = rates(angles, w)
    assert batch.shape == (3, 5)
    for k in range(5):
        np.testing.assert_array_equal(batch[:, k], rates(angles[:, k], w[:, k]))
    np.testing.assert_allclose(rates(angles, w[:, 0]), rates(angles, np.repeat(w[:, :1], 5, 1)))
    A = dcm(angles)
    assert dcm_rate(A, w).shape == (3, 3, 5)
    np.testing.assert_allclose(dcm_rate(A, w)[:, :, 2], dcm_rate(A[:, :, 2], w[:, 2]))
    e, x = ca.SX.sym("e", 3), ca.SX.sym("x", 3)
    Am = ca.SX.sym("A", 3, 3)
    f = ca.Function("f", [e, x, Am], [rates(e, x), body(e, x), dcm_rate(Am, x)])
    r_, b_, d_ = f(angles[:, 1], w[:, 1], A[:, :, 1])
    np.testing.assert_allclose(np.array(r_).ravel(), rates(angles[:, 1], w[:, 1]), rtol=1e-15)
    np.testing.assert_allclose(np.array(b_).ravel(), body(angles[:, 1], w[:, 1]), rtol=1e-15)
    np.testing.assert_allclose(np.array(d_), dcm_rate(A[:, :, 1], w[:, 1]), rtol=1e-15)
    dm = rates(ca.DM(angles[:, 1]), ca.DM(w[:, 1]))  # DM in, DM out
    assert isinstance(dm, ca.DM)


@pytest.mark.parametrize("seq, theta", [("321", np.pi / 2), ("321", -np.pi / 2),
                                        ("313", 0.0), ("313", np.pi), ("313", -np.pi)])
def test_gimbal_lock_is_refused_for_numbers_with_the_remedy(seq, theta):
    _, _, rates, body = SEQ[seq]
    with pytest.raises(ValueError, match=r"`angles` is at the .* gimbal lock.*quaternion"):
        rates([0.1, theta, 0.2], [0.1, 0.2, 0.3])
    with pytest.raises(ValueError, match=r"column 1"):
        rates(np.array([[0.1, 0.1], [0.5, theta], [0.2, 0.2]]), [0.1, 0.2, 0.3])
    with pytest.raises(ValueError, match="gimbal lock"):
        rates(ca.DM([0.1, theta, 0.2]), ca.DM([0.1, 0.2, 0.3]))
    assert np.all(np.isfinite(body([0.1, theta, 0.2], [0.1, 0.2, 0.3])))  # defined everywhere
    # just outside the tolerance the formula is used (and large)
    off = theta + (2 * EULER_LOCK_TOL if theta <= 0 else -2 * EULER_LOCK_TOL)
    assert np.max(np.abs(rates([0.1, off, 0.2], [0.1, 0.2, 0.3]))) > 1e7
    # symbolic: the formula as it stands; at the lock its value is huge (cos(pi/2) = 6e-17
    # in floating point) or not finite
    e, x = ca.SX.sym("e", 3), ca.SX.sym("x", 3)
    out = np.array(ca.Function("f", [e, x], [rates(e, x)])([0.1, theta, 0.2], [0.1, 0.2, 0.3]))
    assert not np.all(np.isfinite(out)) or np.max(np.abs(out)) > 1e14


@pytest.mark.parametrize("call, name", [
    (lambda: euler321_rates([0, 0], [0, 0, 0]), "angles"),
    (lambda: euler313_rates([0, 0.5, 0], [0, np.nan, 0]), "w"),
    (lambda: body_rates_from_euler321([0, 0, 0], [0, 0]), "angle_rates"),
    (lambda: dcm_rate(np.eye(2), [0, 0, 1]), "A"),
    (lambda: dcm_rate(ca.SX.sym("A", 3, 2), ca.SX.sym("w", 3)), "A"),
])
def test_bad_input_names_the_argument(call, name):
    with pytest.raises(ValueError, match=f"`{name}`"):
        call()
    with pytest.raises(TypeError):
        euler321_rates("abc", [0, 0, 0])
