"""``auto`` on non-smooth right-hand sides (appdyn issue 27, item 5c): a reaction-wheel
spacecraft under a saturated PD law (``fmin``/``fmax`` on the torque) and a bang-bang
callable torque are verified by DOP853 with step rejection, against independent references
(scipy's DOP853 with the law applied from numpy; the closed form of a spherical body spun
about a fixed axis); where the tolerance cannot be verified the result says why (order
loss at kinks), never "round-off"."""
import casadi as ca
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from appdyn.dynamics import closed_loop, rigid_body, simulate
from appdyn.dynamics.attitude import quat_conj, quat_mul
from appdyn.dynamics.integrate.smoothness import nonsmooth_operations
from appdyn.dynamics.momentum.wheels import wheel_spacecraft

INERTIA = np.array([[12.0, 0.3, -0.2], [0.3, 10.0, 0.1], [-0.2, 0.1, 8.0]])
TARGET = np.array([0.3, -0.4, 0.2, 0.0])
TARGET[3] = np.sqrt(1 - TARGET[:3] @ TARGET[:3])
KP, KD, LMAX = 4.0, 6.0, 0.2  # PD gains and the torque limit [N m]
X0 = np.r_[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
T = np.linspace(0.0, 60.0, 121)


def saturated_pd_wheel_loop():
    """Hub torque L = sat(-kp q4e e - kd w), |L_i| <= LMAX, made by the wheels (tau = -L)."""
    model = wheel_spacecraft(INERTIA, np.eye(3), 0.05)
    x = ca.SX.sym("x", model.nx)
    qe = quat_mul(x[0:4], ca.DM(quat_conj(TARGET)))
    L = ca.fmin(ca.fmax(-KP * qe[3] * qe[0:3] - KD * x[4:7], -LMAX), LMAX)
    return closed_loop(model, ca.Function("sat_pd", [x], [-L], ["x"], ["tau"]))


def law_numpy(x):
    qe = quat_mul(x[:4], quat_conj(TARGET))
    return -np.clip(-KP * qe[3] * qe[:3] - KD * x[4:7], -LMAX, LMAX)


@pytest.fixture(scope="module")
def slew_reference():
    """scipy's DOP853 at rtol 1e-13, atol 1e-16 on the open-loop model with the law from
    numpy (an independent formulation of the closed loop)."""
    model = wheel_spacecraft(INERTIA, np.eye(3), 0.05)
    ref = solve_ivp(lambda _, x: model.rhs(x, law_numpy(x)), (T[0], T[-1]), X0, t_eval=T,
                    method="DOP853", rtol=1e-13, atol=1e-16)
    assert ref.success
    return ref.y


def test_the_graph_scan_finds_kinks_and_only_kinks():
    x = ca.SX.sym("x", 2)
    smooth = ca.Function("f", [x], [ca.sin(x[0]) * x[1] ** 2])
    assert nonsmooth_operations(smooth) == ()
    assert nonsmooth_operations(rigid_body(INERTIA).f) == ()
    assert nonsmooth_operations(wheel_spacecraft(INERTIA, np.eye(3), 0.05).f) == ()
    assert nonsmooth_operations(saturated_pd_wheel_loop().f) == ("fmax", "fmin")
    switch = ca.Function("g", [x], [ca.if_else(x[0] > 0, x[1], -x[1]) + ca.fabs(x[1])])
    assert {"if_else_zero", "fabs"} <= set(nonsmooth_operations(switch))
    xm = ca.MX.sym("x", 2)  # an MX Function is expanded before the scan
    assert nonsmooth_operations(ca.Function("h", [xm], [ca.fmax(xm[0], xm[1])])) == ("fmax",)


@pytest.mark.parametrize("rtol", [1e-6, 1e-8])
@pytest.mark.slow
def test_saturated_pd_wheel_slew_is_verified(rtol, slew_reference):
    loop = saturated_pd_wheel_loop()
    assert np.max(np.abs(law_numpy(X0))) >= LMAX  # (the premise: the law starts saturated)
    res = simulate(loop, X0, T, rtol=rtol)
    assert res.success and res.status == 0 and res.method == "dop853", res.message
    assert "non-smooth" in res.message and res.error_estimate <= 1.0
    ratio = np.abs(res.x - slew_reference) / (1e-10 + rtol * np.abs(slew_reference))
    assert ratio.max() <= 1.0, ratio.max()
    # the slew reaches the target and rests there
    assert np.linalg.norm(quat_mul(res.x[:4, -1], quat_conj(TARGET))[:3]) < 1e-5


@pytest.mark.slow
def test_without_the_stepper_the_failure_names_order_loss_not_round_off(slew_reference):
    """jit=False leaves auto its Richardson search (rk8 runs of different step counts): on
    the saturated law they do not converge at order 8; the old verdict was status 2, "it
    lies at the round-off floor"."""
    res = simulate(saturated_pd_wheel_loop(), X0, T, rtol=1e-6, jit=False)
    if res.success:  # (verified after all: then it must be right)
        ratio = np.abs(res.x - slew_reference) / (1e-10 + 1e-6 * np.abs(slew_reference))
        assert ratio.max() <= 1.0
    else:
        assert res.status == 5, res.message
        assert "non-smooth right-hand side" in res.message and "order loss" in res.message
        assert "not round-off" in res.message and "remedy" in res.message


# ------------------------------------------------------- a bang-bang torque from Python
SPHERE = 10.0                                   # a spherical body: I = 10 kg m^2 on every axis
AXIS = np.array([1.0, -1.0, 0.5]) / 1.5         # unit torque axis (|(1, -1, 0.5)| = 1.5)
L0, PERIOD = 0.1, 7.0                           # |L| [N m], switching every PERIOD / 2 s


def bang(t):
    return L0 * np.sign(np.sin(2 * np.pi * t / PERIOD)) * AXIS


def spin_angle(t):
    """Rotation angle about AXIS from rest: w = (L0 / I) s(t), s the triangle wave that
    integrates the sign, the angle (L0 / I) times its integral (piecewise quadratic)."""
    n, r = np.floor(t / PERIOD), np.mod(t, PERIOD)
    half = PERIOD / 2
    area = np.where(r <= half, r ** 2 / 2,
                    half ** 2 / 2 + PERIOD * (r - half) - (r ** 2 - half ** 2) / 2)
    return L0 / SPHERE * (n * half ** 2 + area)


@pytest.mark.slow
def test_bang_bang_callable_torque_is_verified_against_the_closed_form():
    res = simulate(rigid_body([SPHERE] * 3), [0, 0, 0, 1, 0, 0, 0], T, u=bang, rtol=1e-6)
    assert res.success and res.status == 0, res.message
    assert "callable u" in res.message
    angle = spin_angle(T)
    q = np.vstack([np.outer(AXIS, np.sin(angle / 2)), np.cos(angle / 2)])
    w = np.outer(AXIS, L0 / SPHERE * (PERIOD / 2 - np.abs(np.mod(T, PERIOD) - PERIOD / 2)))
    truth = np.vstack([q, w])
    ratio = np.abs(res.x - truth) / (1e-10 + 1e-6 * np.abs(truth))
    assert ratio.max() <= 1.0, ratio.max()


@pytest.mark.slow
def test_a_batch_of_saturated_slews_is_verified_run_by_run(slew_reference):
    """x0 of shape (nx, K): each run of the non-smooth loop gets its own step control; run 0
    is the slew above, run 1 starts at the target at rest (stays there)."""
    rest = np.r_[TARGET, np.zeros(6)]
    res = simulate(saturated_pd_wheel_loop(), np.stack([X0, rest], axis=1), T, rtol=1e-6)
    assert res.all_success and list(res.status) == [0, 0] and res.method == "dop853", res.message
    ratio = np.abs(res.x[:, :, 0] - slew_reference) / (1e-10 + 1e-6 * np.abs(slew_reference))
    assert ratio.max() <= 1.0
    np.testing.assert_allclose(res.x[:, :, 1], np.repeat(rest[:, None], T.size, axis=1),
                               rtol=0, atol=1e-12)


@pytest.mark.parametrize("rtol", [1e-6, 1e-10])
def test_smooth_callable_torque_estimate_bounds_the_true_error(rtol):
    """A callable u may jump, so auto steps it with step control too; on a smooth one the
    steps are set by the output grid, not the tolerance, and a tighter local tolerance
    alone would repeat them: the error estimate must still bound the true error. Sphere,
    L = 0.01 sin(t) along AXIS: w = 0.001 (1 - cos t) AXIS, angle 0.001 (t - sin t)."""
    u = lambda t: 0.01 * np.sin(t) * AXIS  # noqa: E731
    res = simulate(rigid_body([SPHERE] * 3), [0, 0, 0, 1, 0, 0, 0], T, u=u, rtol=rtol)
    assert res.success and res.status == 0, res.message
    angle = 0.01 / SPHERE * (T - np.sin(T))
    truth = np.vstack([np.outer(AXIS, np.sin(angle / 2)), np.cos(angle / 2),
                       np.outer(AXIS, 0.01 / SPHERE * (1 - np.cos(T)))])
    ratio = np.abs(res.x - truth) / (1e-10 + rtol * np.abs(truth))
    assert ratio.max() <= res.error_estimate <= 1.0, (ratio.max(), res.error_estimate)


@pytest.mark.slow
def test_step_budget_on_a_non_smooth_model_is_status_3_not_a_failure():
    res = simulate(saturated_pd_wheel_loop(), X0, T, rtol=1e-6, max_steps=500)
    assert not res.success and res.status == 3, res.message
    assert "max_steps" in res.message and "non-smooth" in res.message
