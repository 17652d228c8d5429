"""Coning and forced motion (seed Secs. 4.5 C and 4.6, Methods I and II) against the rigid body.

Each closed form of `dynamics.truth.forced` is compared with a simulation of the rigid body
(`rigid_body`, the scene RigidHub + ExternalTorque; the heavy top is `tilt_torque_body`, the
scene RigidHub + TiltTorque) within the closed form's stated order: exact parts to the
integrator's accuracy, first-order parts with an error that falls by ~4 when the small
parameter is halved. The floating-frame equations are exact and checked against Euler's law
in body axes through the 3-1-3 kinematics.
"""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from appdyn.dynamics import rigid_body, simulate
from appdyn.dynamics.attitude import (body_rates_from_euler313, dcm_axis, dcm_from_quat,
                                      euler313_from_quat, euler313_rates, euler321_from_quat,
                                      quat_from_euler313, quat_from_euler321)
from appdyn.dynamics.spinning import tilt_torque_body
from appdyn.dynamics.truth import (coning_angle, floating_frame_accelerations,
                                   horizontal_gyroscope, misaligned_thrust)

TOL = dict(method="cvodes", rtol=1e-10, atol=1e-12)  # ~1e-8: far below the errors measured
EXACT = dict(method="rk8", steps=20)  # fixed-step 8th order: ~1e-13 on these runs


def _alpha_321(q):
    """psi + i theta of the 3-2-1 angles of each column of q (4, n)."""
    e = euler321_from_quat(q)
    return e[0] + 1j * e[1]


def _start(alpha0, w):
    return np.r_[quat_from_euler321([alpha0.real, alpha0.imag, 0.0]), w]


def _coning_error(I, w, t, b=(0.0, 0.0)):
    res = simulate(rigid_body(I), _start(coning_angle(I, w, 0.0)[0], w), t, **TOL)
    assert res.success, res.message
    if b == (0.0, 0.0):
        sim = _alpha_321(res.x[:4])
    else:  # the control axis e1 + b2 e2 + b3 e3 in inertial axes: alpha = Y - i Z
        c = np.array([1.0, *b]) / np.linalg.norm([1.0, *b])
        ci = np.einsum("jik,j->ik", dcm_from_quat(res.x[:4]), c)  # A^T c
        sim = ci[1] - 1j * ci[2]
    return np.max(np.abs(sim - coning_angle(I, w, t, misalignment=b)))


@pytest.mark.parametrize("I", [[3.0, 2.2, 1.9], [1.0, 2.6, 3.1]], ids=["disk", "rod"])
def test_coning_angle_is_first_order_in_the_cone_angle(I):
    t = np.linspace(0.0, 30.0, 301)
    eps = 0.02
    errs = [_coning_error(I, [1.0, 0.0, eps / k], t) for k in (1, 2)]
    amp = eps * I[2] / I[0]  # the initial (minimum) cone angle
    # measured 5.5e-5 (disk) and 1.4e-3 (rod) of cones 0.0127 and 0.062 rad over 30 s; the
    # neglected terms are quadratic and the motion is odd in the perturbation, so the error is
    # O(alpha^3): /8 when the cone halves (measured 8.0)
    assert errs[0] < 0.05 * amp
    assert 6.0 < errs[0] / errs[1] < 10.0
    # w2(0) != 0 (any phase of the nutation) and the misalignment term of Eq. 4.111
    errs = [_coning_error(I, [1.0, 0.7 * eps / k, eps / k], t, b=(0.01 / k, -0.02 / k))
            for k in (1, 2)]
    assert errs[0] < 0.05 * amp and 6.0 < errs[0] / errs[1] < 10.0  # measured 1.8 %, 4.2 %


def test_coning_angle_matches_the_seed_cone_limits():
    # Sec. 4.5 C: alpha_min = I3 w3(0) / (I1 w0), alpha_max = sqrt(I2 (I3 - I1)/(I3 (I2 - I1))) alpha_min
    I, w0, w3 = np.array([1.0, 2.6, 3.1]), 1.0, 0.01
    a = coning_angle(I, [w0, 0.0, w3], np.linspace(0.0, 400.0, 200001))
    amin = I[2] * w3 / (I[0] * w0)
    amax = np.sqrt(I[1] * (I[2] - I[0]) / (I[2] * (I[1] - I[0]))) * amin
    assert np.min(np.abs(a)) == pytest.approx(amin, rel=1e-6)
    assert np.max(np.abs(a)) == pytest.approx(amax, rel=1e-6)


def test_misaligned_thrust_rates_exact_and_cone_angle_first_order():
    I = [0.5, 4.0, 4.0]  # a spinning missile: spin about the minimum axis (lam < 0)
    t = np.linspace(0.0, 20.0, 401)
    errs = []
    for k in (1, 2):
        w0, L2 = [10.0, 0.0, 0.002 / k], 0.3 / k
        ref = misaligned_thrust(I, w0, L2, t)
        res = simulate(rigid_body(I), _start(ref.alpha[0], w0), t, u=[0.0, L2, 0.0], **EXACT)
        assert res.success, res.message
        # the linear Euler equations are exact for I2 = I3: w2, w3 to the integrator's accuracy
        np.testing.assert_allclose(res.x[5], ref.w2, rtol=0, atol=1e-9)
        np.testing.assert_allclose(res.x[6], ref.w3, rtol=0, atol=1e-9)
        np.testing.assert_allclose(res.x[4], 10.0, rtol=0, atol=1e-12)
        errs.append(np.max(np.abs(_alpha_321(res.x[:4]) - ref.alpha)))
        amp = np.max(np.abs(ref.alpha))
    assert errs[0] < 0.005 * amp  # measured 8.9e-6 of 4.7e-3 rad
    assert 6.0 < errs[0] / errs[1] < 10.0  # O(alpha^3) as for the free coning
    assert ref.precession_rate == pytest.approx(0.5 / 4.0 * 10.0)  # I1 w0 / I2


def test_horizontal_gyroscope_precesses_at_L1_over_I3_w0():
    I1, I3, w0 = 0.02, 0.012, 150.0
    t = np.linspace(0.0, 2.0, 401)
    errs = []
    for k in (1, 2):
        mgl = 0.9 / k
        ref = horizontal_gyroscope(I1, I3, w0, mgl, t)
        model = tilt_torque_body([I1, I1, I3], mgl, axis=(0, 0, 1), direction=(0, 0, 1))
        angles = [0.0, np.pi / 2, 0.0]
        w = body_rates_from_euler313(angles, [0.0, 0.0, w0])
        res = simulate(model, np.r_[quat_from_euler313(angles), w], t, **TOL)
        assert res.success, res.message
        e = euler313_from_quat(res.x[:4])
        err = max(np.max(np.abs(np.unwrap(e[0]) - ref.psi)), np.max(np.abs(e[1] - ref.theta)))
        errs.append(err / (ref.precession_rate / ref.nutation_frequency))  # / the nod amplitude
        # the mean precession over the run: psi(T) / T -> omega_p
        assert e[0][-1] / t[-1] == pytest.approx(mgl / (I3 * w0), rel=0.02)
    assert errs[0] < 0.05  # measured 0.027 of the nod amplitude omega_p / p
    assert 3.0 < errs[0] / errs[1] < 5.0  # relative error O((omega_p/p)^2): /4 (measured 4.0)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**31 - 1))
def test_floating_frame_equations_equal_euler_in_body_axes(seed):
    rng = np.random.default_rng(seed)
    I1, I3 = rng.uniform(1.0, 2.0), rng.uniform(0.3, 1.9)
    angles = np.array([rng.uniform(-3, 3), rng.uniform(0.3, 2.8), rng.uniform(-3, 3)])
    rates = rng.normal(size=3)
    L_F = rng.normal(size=3)
    acc = floating_frame_accelerations(I1, I3, angles, rates, L_F)
    # Euler's law in body axes: I w' = L - w x I w, L in body axes = A3(phi) L_F
    I = np.diag([I1, I1, I3])
    w = body_rates_from_euler313(angles, rates)
    wdot = np.linalg.solve(I, dcm_axis(3, angles[2]) @ L_F - np.cross(w, I @ w))
    # angle accelerations = d/dt euler313_rates(angles(t), w(t)) along angles' = rates, w' = wdot
    f = lambda h: euler313_rates(angles + h * rates, w + h * wdot)
    h = 1e-4  # 1/sin(theta) makes the high derivatives large: a small step, error ~1e-12
    fd = (-f(2 * h) + 8 * f(h) - 8 * f(-h) + f(-2 * h)) / (12 * h)
    np.testing.assert_allclose(acc, fd, rtol=0, atol=1e-10 * max(1.0, np.max(np.abs(fd))))


@pytest.mark.parametrize("call, match", [
    (lambda: coning_angle([1.0, 2.0, 3.0], [1.0, 0, 0.01], 0.0, misalignment=[0.0]), "misalignment"),
    (lambda: coning_angle([2.0, 1.0, 3.0], [1.0, 0, 0.01], 0.0), "intermediate"),
    (lambda: coning_angle([1.0, 2.0, 3.0], [0.0, 0, 0.01], 0.0), "w0"),
    (lambda: misaligned_thrust([1.0, 2.0, 3.0], [1.0, 0, 0], 0.1, 0.0), "I2 = I3"),
    (lambda: misaligned_thrust([2.0, 2.0, 2.0], [1.0, 0, 0], 0.1, 0.0), "no gyroscopic"),
    (lambda: horizontal_gyroscope(1.0, 0.5, 0.0, 1.0, 0.0), "`rate`"),
    (lambda: horizontal_gyroscope(1.0, 2.5, 1.0, 1.0, 0.0), "triangle"),
    (lambda: floating_frame_accelerations(1.0, 0.5, [0, 0, 0], [0, 0, 1], [0, 0, 0]), "gimbal lock"),
])
def test_bad_input_names_the_argument(call, match):
    with pytest.raises(ValueError, match=match):
        call()
