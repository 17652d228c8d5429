"""Linearization: exact Jacobians, the minimal attitude error, spinning references, residuals."""
import casadi as ca
import numpy as np
import pytest
from scipy.linalg import expm

from appdyn.dynamics import Model, rigid_body, simulate
from appdyn.dynamics.attitude import (principal_axes, propagate_quat, quat_conj, quat_from_axis_angle,
                               quat_mul, quat_rate, skew)
from appdyn.dynamics.linearize import ANGLE_STATES, error_dynamics, linearization, linearize
from appdyn.dynamics.spinning import PointMassDamper, gyrostat_model, tilt_torque_body
from tests.bodies import GEMINI



def error_rhs(model, q_ref, w_ref, xr, u, p=None):
    """Independent numpy evaluation of the error-state derivative used by `linearization`.

    q = dq(dth) (x) q_ref with dq = [dth/2, sqrt(1 - |dth|^2/4)]; dth' = 2 vec(d/dt(q q_ref*)).
    """
    iq = model.attitude[0]
    dth = xr[iq:iq + 3]
    dq = np.concatenate([dth / 2, [np.sqrt(1 - dth @ dth / 4)]])
    q = quat_mul(dq, q_ref)
    x = np.concatenate([xr[:iq], q, xr[iq + 3:]])
    xdot = model.rhs(x, u, p)
    qref_dot = quat_rate(q_ref, w_ref)
    dq_dot = quat_mul(xdot[iq:iq + 4], quat_conj(q_ref)) + quat_mul(q, quat_conj(qref_dot))
    return np.concatenate([xdot[:iq], 2 * dq_dot[:3], xdot[iq + 4:]])


def central_jacobian(fun, x0, h):
    cols = []
    for j in range(len(x0)):
        e = np.zeros(len(x0))
        e[j] = h[j]
        cols.append((fun(x0 + e) - fun(x0 - e)) / (2 * h[j]))
    return np.array(cols).T


def random_quat(rng):
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    return q * np.sign(q[3])


# ------------------------------------------------------------------- exactness
@pytest.mark.parametrize("case", ["gyrostat_point_mass", "tilt_torque"])
def test_exact_jacobians_match_central_differences(case):
    """At a general (non-equilibrium) point, A and B equal central differences of an
    independent numpy evaluation of the error dynamics (FD truncation ~1e-10 relative)."""
    rng = np.random.default_rng(3)
    if case == "gyrostat_point_mass":
        model = gyrostat_model(GEMINI, wheel_axis=(0.2, 0.3, 1.0), wheel_momentum=400.0,
                               damper=PointMassDamper(30.0, 2e3, 40.0, (0.4, 0.9, 0.3),
                                                      (0.3, 1.0, -0.2), body_mass=3000.0))
        x = np.concatenate([random_quat(rng), rng.normal(size=3) * 0.3, [0.05, -0.1]])
    else:
        model = tilt_torque_body([2.0, 3.0, 3.5], 4.0, axis=(1, 0.2, 0.1),
                                 direction=(0.3, -0.2, 1.0), internal_damping=0.7)
        x = np.concatenate([random_quat(rng), rng.normal(size=3)])
    u = rng.normal(size=3)
    lin = linearization(model, x, u, allow_non_equilibrium=True)
    assert not lin.is_equilibrium
    q_ref, w_ref = x[0:4], x[4:7]
    xr0 = np.concatenate([np.zeros(3), x[4:]])
    np.testing.assert_allclose(lin.residual, error_rhs(model, q_ref, w_ref, xr0, u),
                               rtol=1e-13, atol=1e-13 * np.max(np.abs(lin.residual)))
    fun = error_dynamics(model, q_ref, w_ref)
    np.testing.assert_allclose(np.asarray(fun(xr0, u, model.resolve_p())).reshape(-1),
                               lin.residual, rtol=1e-14, atol=1e-14 * np.max(np.abs(lin.residual)))
    hx = 1e-5 * np.maximum(1.0, np.abs(xr0))
    A_fd = central_jacobian(lambda z: error_rhs(model, q_ref, w_ref, z, u), xr0, hx)
    # f is affine in u (torques enter linearly): a large step leaves only round-off
    B_fd = central_jacobian(lambda v: error_rhs(model, q_ref, w_ref, xr0, v), u, 10 * np.ones(3))
    err_A = np.max(np.abs(lin.A - A_fd)) / np.max(np.abs(lin.A))
    err_B = np.max(np.abs(lin.B - B_fd)) / np.max(np.abs(lin.B))
    assert err_A < 1e-8 and err_B < 1e-8, (err_A, err_B)


def test_model_without_attitude_plain_jacobian():
    """A damped pendulum: A from the closed-form derivative, and central differences agree."""
    x = ca.SX.sym("x", 2)
    u = ca.SX.sym("u", 1)
    p = ca.SX.sym("p", 2)
    f = ca.Function("pend", [x, u, p], [ca.vertcat(x[1], -p[0] * ca.sin(x[0]) - p[1] * x[1] + u)],
                    ["x", "u", "p"], ["xdot"])
    model = Model(f=f, states=("th", "om"), controls=("tau",), params=("g_l", "c"),
                  p_default=[9.81, 0.3], name="pendulum")
    lin = linearization(model, [np.pi, 0.0])  # inverted: an equilibrium
    assert lin.frame == "none" and lin.is_equilibrium
    np.testing.assert_allclose(lin.A, [[0, 1], [9.81, -0.3]], rtol=1e-15, atol=1e-15)
    np.testing.assert_array_equal(lin.B, [[0], [1]])
    ss = linearize(model, [np.pi, 0.0], p=[4.0, 0.0])
    np.testing.assert_allclose(np.sort(np.linalg.eigvals(ss.A).real), [-2.0, 2.0], rtol=1e-15)
    with pytest.raises(ValueError, match="`frame`='rates' needs an attitude model"):
        linearization(model, [0.0, 0.0], frame="rates")


# ------------------------------------------------------------ attitude error
def test_no_spurious_mode_non_spinning_body():
    """Torque-free body at rest: 3 angles + 3 rates, all six eigenvalues 0 and no seventh
    (the raw quaternion Jacobian has 7 zero eigenvalues, one of them the norm direction)."""
    model = rigid_body(GEMINI)
    q0 = quat_from_axis_angle([0.3, -0.5, 0.8], 1.1)
    ss = linearize(model, np.concatenate([q0, np.zeros(3)]))
    assert ss.nstates == 6
    assert list(ss.state_labels) == list(ANGLE_STATES) + ["w1", "w2", "w3"]
    assert list(ss.input_labels) == ["L1", "L2", "L3"]
    assert list(ss.output_labels) == list(ss.state_labels)
    ev = np.linalg.eigvals(ss.A)
    assert np.count_nonzero(np.abs(ev) == 0.0) == 6
    assert np.linalg.matrix_rank(ss.A) == 3  # dth' = dw: three 2x2 Jordan blocks
    np.testing.assert_array_equal(ss.A, np.block([[np.zeros((3, 3)), np.eye(3)],
                                                  [np.zeros((3, 6))]]))
    np.testing.assert_allclose(ss.B[3:], np.linalg.inv(GEMINI), rtol=1e-13)
    # the naive 7-state quaternion Jacobian carries the extra zero mode
    xs = ca.SX.sym("x", 7)
    J = ca.Function("J", [xs], [ca.jacobian(model.f(xs, ca.DM.zeros(3), ca.DM.zeros(0)), xs)])
    assert np.count_nonzero(np.abs(np.linalg.eigvals(np.asarray(J(np.r_[q0, 0, 0, 0])))) == 0) == 7


def test_spinning_frame_kinematics_independent_of_reference_attitude():
    """dth' = dw - w_ref x dth exactly (body-frame error), at any reference attitude."""
    moments, Ap = principal_axes(GEMINI)
    axis = Ap[2]  # the minor principal axis, in reference axes
    rate = 0.7
    rng = np.random.default_rng(5)
    A0 = None
    for _ in range(3):
        x = np.concatenate([random_quat(rng), rate * axis])
        lin = linearization(rigid_body(GEMINI), x)
        assert lin.is_equilibrium and lin.frame == "spinning"
        np.testing.assert_allclose(lin.A[:3, :3], -skew(rate * axis), rtol=0, atol=1e-15)
        np.testing.assert_allclose(lin.A[:3, 3:], np.eye(3), rtol=0, atol=1e-15)
        if A0 is not None:
            np.testing.assert_allclose(lin.A, A0, rtol=0, atol=1e-12 * np.max(np.abs(A0)))
        A0 = lin.A


def test_rates_frame_is_the_euler_equation_jacobian():
    I1, I2, I3, W = 2.0, 3.0, 4.5, 10.0
    lin = linearization(rigid_body([I1, I2, I3]), [0, 0, 0, 1, W, 0, 0], frame="rates")
    assert lin.states == ("w1", "w2", "w3")
    expected = [[0, 0, 0], [0, 0, (I3 - I1) * W / I2], [0, (I1 - I2) * W / I3, 0]]
    np.testing.assert_allclose(lin.A, expected, rtol=1e-15, atol=0)
    ev = np.sort_complex(lin.eigenvalues())
    lam = W * np.sqrt((I1 - I2) * (I1 - I3) / (I2 * I3))
    np.testing.assert_allclose(ev, [-1j * lam, 0, 1j * lam], rtol=0, atol=1e-15 * W)


def test_linear_model_predicts_the_nonlinear_motion():
    """Heavy top spinning upright: a 1e-6 perturbation simulated with the nonlinear model and
    mapped back through dth = 2 vec(q (x) q_ref(t)*) follows expm(A t) dx0 to O(eps^2).
    This fixes the sign conventions of the error angles, which eigenvalues cannot see."""
    I1, I2, mgl, W = 0.002, 0.005, 0.3 * 9.80665 * 0.04, 40.0
    model = tilt_torque_body([I1, I2, I2], mgl)
    x0 = np.array([0, 0, 0, 1, W, 0, 0.0])
    lin = linearization(model, x0)
    eps = 1e-6
    d0 = eps * np.array([0.3, -0.8, 0.5, 0.2, 0.9, -0.4])  # dth1..3, dw1..3
    dq = np.concatenate([d0[:3] / 2, [np.sqrt(1 - d0[:3] @ d0[:3] / 4)]])
    start = np.concatenate([quat_mul(dq, x0[:4]), x0[4:] + d0[3:]])
    t = np.linspace(0.0, 0.5, 26)
    res = simulate(model, start, t, method="rk8", steps=200)
    worst = 0.0
    for k, tk in enumerate(t):
        q_ref = np.asarray(propagate_quat(x0[:4], x0[4:], tk)).reshape(-1)
        dqk = quat_mul(res.x[:4, k], quat_conj(q_ref))
        dx = np.concatenate([2 * dqk[:3] * np.sign(dqk[3]), res.x[4:, k] - x0[4:]])
        worst = max(worst, np.max(np.abs(dx - expm(lin.A * tk) @ d0)))
    assert worst < 1e-4 * eps, worst  # quadratic terms: ~ eps^2 * |A| t


# ------------------------------------------------------------ (non-)equilibria
def test_non_equilibrium_raises_and_shows_the_residual():
    model = rigid_body([1.0, 2.0, 3.0])
    x = [0, 0, 0, 1, 1.0, 1.0, 0.0]
    with pytest.raises(ValueError) as exc:
        linearize(model, x)
    text = str(exc.value)
    assert "not an equilibrium" in text and "allow_non_equilibrium" in text
    assert "d(w3)/dt = -3.333333e-01 rad/s/s" in text  # (I1 - I2) w1 w2 / I3
    lin = linearization(model, x, allow_non_equilibrium=True)
    assert not lin.is_equilibrium
    np.testing.assert_allclose(lin.residual[3:], model.rhs(x)[4:], rtol=1e-15)


def test_phase_dependent_torque_is_not_a_relative_equilibrium():
    """Torque-free at spin angle 0 (tilt axis along the fixed direction), but the spin about
    e3 turns the tilt axis away: the spinning linearization would be time-varying."""
    model = tilt_torque_body([2.0, 3.0, 4.0], 1.5, axis=(1, 0, 0), direction=(1, 0, 0))
    x = [0, 0, 0, 1, 0, 0, 5.0]
    with pytest.raises(ValueError, match="not a relative equilibrium: at spin angle 2 rad"):
        linearization(model, x)
    # spin about the tilt axis itself is fine, and the rates frame is refused
    lin = linearization(model, [0, 0, 0, 1, 5.0, 0, 0])
    assert lin.is_equilibrium
    with pytest.raises(ValueError, match="`frame`='rates' drops the attitude"):
        linearization(model, [0, 0, 0, 1, 5.0, 0, 0], frame="rates")


@pytest.mark.parametrize("x, message", [
    ([0, 0, 0, 1, 1, 0], "`x` must be 7 finite numbers"),
    ([0, 0, 0, 1, np.nan, 0, 0], "`x` must be 7 finite numbers"),
    ([0, 0, 0, 2, 0, 0, 0], r"`x\[0:4\] \(the attitude quaternion.*must be a unit quaternion"),
])
def test_bad_operating_point(x, message):
    with pytest.raises(ValueError, match=message):
        linearize(rigid_body([1.0, 2.0, 3.0]), x)


def test_bad_options():
    model = rigid_body([1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="`frame` must be one of"):
        linearize(model, [0, 0, 0, 1, 0, 0, 0], frame="inertial")
    with pytest.raises(ValueError, match="`u` must be 3 finite numbers"):
        linearize(model, [0, 0, 0, 1, 0, 0, 0], u=[1.0, 2.0])
    with pytest.raises(TypeError, match="`model` must be a dynamics.Model"):
        linearize("rigid_body", [0, 0, 0, 1, 0, 0, 0])


# ------------------------------------------------------------------ reductions
def test_quotient_and_restrict_remove_exactly_the_neutral_zero():
    I1, I2, mgl, W = 0.002, 0.005, 0.1, 50.0
    lin = linearization(tilt_torque_body([I1, I2, I2], mgl), [0, 0, 0, 1, W, 0, 0])
    full = lin.eigenvalues()
    assert np.count_nonzero(np.abs(full) <= 1e-12 * W) == 2  # spin phase and spin rate
    red = lin.quotient("dth1").restrict("w1")
    assert red.states == ("dth2", "dth3", "w2", "w3")
    nonzero = full[np.abs(full) > 1e-12 * W]
    by_imag = lambda z: z[np.argsort(z.imag)]  # noqa: E731
    np.testing.assert_allclose(by_imag(red.eigenvalues()), by_imag(nonzero), rtol=0,
                               atol=1e-12 * W)
    assert len(red.notes) == 2
    with pytest.raises(ValueError, match="not a null vector"):
        lin.quotient("w2")
    with pytest.raises(ValueError, match="not a left null vector"):
        lin.restrict("w2")
    with pytest.raises(ValueError, match="`state` must be one of"):
        lin.quotient("q1")


def test_reference_rate_is_the_deprecated_name_of_w_ref():
    """Vocabulary: a rate vector is ``w_*``; the old field name still reads, with a warning."""
    import warnings as _warnings

    from appdyn.dynamics import linearization, rigid_body

    lin = linearization(rigid_body([2.0, 3.0, 4.5]), [0, 0, 0, 1, 10.0, 0, 0])
    np.testing.assert_allclose(lin.w_ref, [10.0, 0.0, 0.0])
    with _warnings.catch_warnings(record=True) as seen:
        _warnings.simplefilter("always")
        np.testing.assert_array_equal(lin.reference_rate, lin.w_ref)
    assert any(issubclass(w.category, DeprecationWarning) for w in seen)
