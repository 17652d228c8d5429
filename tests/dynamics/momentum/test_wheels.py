"""Reaction-wheel spacecraft against conservation laws, the work-energy balance and second
formulations (a rigid body, the gyrostat)."""
import doctest

import casadi as ca
import numpy as np
import pytest

from appdyn.dynamics import Model, rigid_body, simulate
from appdyn.dynamics.attitude import dcm_from_quat
from appdyn.dynamics import closed_loop
from appdyn.dynamics.momentum import wheels
from appdyn.dynamics.momentum.wheels import rotor_dynamics, wheel_spacecraft
from appdyn.dynamics.spinning import gyrostat_model

HUB = np.array([[12.0, 0.3, -0.2], [0.3, 10.0, 0.1], [-0.2, 0.1, 8.0]])
AXES = np.column_stack([np.eye(3), np.ones(3) / np.sqrt(3)])  # three orthogonal + one skew
J = np.array([0.05, 0.05, 0.05, 0.08])
W0 = np.array([0.5, -0.3, 0.4])
SPEEDS0 = np.array([10.0, -5.0, 3.0, 0.0])


def random_state(rng, n):
    q = rng.normal(size=4)
    return np.concatenate([q / np.linalg.norm(q), rng.normal(size=3), 10 * rng.normal(size=n)])


def motor_torques(t):
    """Smooth, time-varying torques on the four wheels [N m]."""
    k = np.arange(1, 5)
    return 0.02 * np.sin(0.05 * k * t + k) + 0.01 * np.cos(0.13 * t) * (k % 2)


def locked(hub, axes, J):
    return hub + axes @ np.diag(J) @ axes.T


def momentum_inertial(x, hub=HUB, axes=AXES, J=J):
    """``A(q)^T H`` written out from the definition ``H = I w + sum J_i a_i (a_i.w + W_i)``."""
    w, W = x[4:7], x[7:]
    H = hub @ w + axes @ (J * (axes.T @ w + W))
    return dcm_from_quat(x[:4]).T @ H


# ------------------------------------------------------------------------------ structure
def test_metadata_and_cache():
    model = wheel_spacecraft(HUB, AXES, J)
    assert model.states == ("q1", "q2", "q3", "q4", "w1", "w2", "w3", "W1", "W2", "W3", "W4")
    assert model.controls == ("tau1", "tau2", "tau3", "tau4") and model.params == ()
    assert model.attitude == (0, 4)
    assert model.units["W2"] == "rad/s" and model.units["tau4"] == "N m"
    assert set(model.invariants) == {"energy", "momentum_inertial", "quat_norm", "wheel_momentum"}
    assert wheel_spacecraft(HUB.tolist(), AXES, J.tolist()) is model
    forced = wheel_spacecraft(HUB, AXES, 0.05, external_torque=True)
    assert forced.controls[-3:] == ("L1", "L2", "L3") and forced.units["L1"] == "N m"
    single = wheel_spacecraft([1.0, 2.0, 2.5], [0.0, 0.0, 1.0], 0.1)  # one (3,) axis
    assert single.nx == 8 and single.controls == ("tau1",)


def test_invariants_match_their_definitions():
    model = wheel_spacecraft(HUB, AXES, J)
    rng = np.random.default_rng(0)
    for _ in range(5):
        x = random_state(rng, 4)
        w, W = x[4:7], x[7:]
        spin = J * (AXES.T @ w + W)  # absolute axial momenta of the wheels
        np.testing.assert_allclose(model.invariant("wheel_momentum", x), spin, rtol=1e-13)
        np.testing.assert_allclose(model.invariant("momentum_inertial", x), momentum_inertial(x),
                                   rtol=1e-13, atol=1e-13)
        energy = 0.5 * w @ HUB @ w + 0.5 * np.sum(J * (AXES.T @ w + W) ** 2)
        assert float(model.invariant("energy", x)) == pytest.approx(energy, rel=1e-13)


def test_invariant_rates_along_the_flow():
    """Exactly: d(A^T H)/dt = A^T L and dE/dt = sum_i tau_i W_i + L.w, at random states."""
    model = wheel_spacecraft(HUB, AXES, J, external_torque=True)
    x, u = ca.SX.sym("x", model.nx), ca.SX.sym("u", model.nu)
    xdot = model.f(x=x, u=u, p=ca.DM.zeros(0))["xdot"]
    rate = {k: ca.Function(k, [x, u], [ca.jtimes(fun(x, ca.DM.zeros(0)), x, xdot)])
            for k, fun in model.invariants.items()}
    rng = np.random.default_rng(1)
    for _ in range(10):
        xv, uv = random_state(rng, 4), rng.normal(size=7)
        tau, L = uv[:4], uv[4:]
        A = dcm_from_quat(xv[:4])
        np.testing.assert_allclose(rate["momentum_inertial"](xv, uv).full().ravel(), A.T @ L,
                                   atol=1e-12)
        assert float(rate["energy"](xv, uv)) == pytest.approx(tau @ xv[7:] + L @ xv[4:7], rel=1e-11)
        np.testing.assert_allclose(rate["wheel_momentum"](xv, uv).full().ravel(), tau, atol=1e-13)


# --------------------------------------------------------------------- long-run conservation
@pytest.mark.slow
def test_momentum_conserved_over_100_s_with_time_varying_torques():
    model = wheel_spacecraft(HUB, AXES, J)
    t = np.linspace(0.0, 100.0, 201)
    x0 = np.r_[0.1, -0.2, 0.3, 0.0, W0, SPEEDS0]
    x0[:4] /= np.linalg.norm(x0[:4])
    res = simulate(model, x0, t, u=motor_torques, method="rk8", steps=10)
    assert res.success
    H = np.stack([momentum_inertial(res.x[:, k]) for k in range(t.size)], axis=1)
    drift = np.max(np.linalg.norm(H - H[:, :1], axis=0)) / np.linalg.norm(H[:, 0])
    assert drift < 1e-10
    # the model's own invariant says the same, and the wheels really exchanged momentum
    np.testing.assert_allclose(model.invariant("momentum_inertial", res.x), H, atol=1e-13)
    assert np.max(np.abs(res.x[7:] - SPEEDS0[:, None])) > 10.0


@pytest.mark.slow
def test_energy_changes_by_the_motor_work():
    """E(t) - E(0) = int_0^t sum_i tau_i W_i dt, the work integrated as an extra state."""
    model = wheel_spacecraft(HUB, AXES, J)
    x, u = ca.SX.sym("x", model.nx + 1), ca.SX.sym("u", model.nu)
    p = ca.SX.sym("p", 0)
    xdot = model.f(x=x[:-1], u=u, p=p)["xdot"]
    power = ca.dot(u, x[7:11])
    f = ca.Function("with_work", [x, u, p], [ca.vertcat(xdot, power)], ["x", "u", "p"], ["xdot"])
    augmented = Model(f, model.states + ("work",), model.controls, attitude=(0, 4))
    t = np.linspace(0.0, 100.0, 201)
    x0 = np.r_[0.0, 0.0, 0.0, 1.0, W0, SPEEDS0, 0.0]
    res = simulate(augmented, x0, t, u=motor_torques, method="rk8", steps=10)
    assert res.success
    E = model.invariant("energy", res.x[:-1])
    work = res.x[-1]
    assert np.max(np.abs(work)) > 0.1 * E[0]  # the motors did real work
    assert np.max(np.abs((E - E[0]) - work)) < 1e-9 * np.max(np.abs(work))


# ---------------------------------------------------------------------- second formulations
def test_free_wheels_at_zero_inertial_spin_leave_the_hub_a_rigid_body():
    """tau = 0 and W_i = -a_i.w: the wheels do not turn inertially about their axes (that
    axial momentum stays 0), so the hub moves as the rigid body of inertia ``I`` alone."""
    model = wheel_spacecraft(HUB, AXES, J)
    t = np.linspace(0.0, 50.0, 101)
    w0 = np.array([0.3, -0.2, 0.25])
    res = simulate(model, np.r_[0, 0, 0, 1, w0, -AXES.T @ w0], t, method="rk8", steps=20)
    ref = simulate(rigid_body(HUB), np.r_[0, 0, 0, 1, w0], t, method="rk8", steps=20)
    np.testing.assert_allclose(res.x[:7], ref.x, atol=1e-12)
    np.testing.assert_allclose(res.x[7:], -AXES.T @ res.x[4:7], atol=1e-12)


def holding_torque(model, x, L=np.zeros(0)):
    """The motor torques that make W' = 0 at state x (W' is affine in tau)."""
    n = model.nu - L.size
    base = model.rhs(x, np.r_[np.zeros(n), L])[7:]
    M = np.column_stack([model.rhs(x, np.r_[e, L])[7:] - base for e in np.eye(n)])
    return np.linalg.solve(M, -base)


def test_wheels_held_at_rest_give_the_locked_rigid_body():
    """W = 0 held by the motors: Euler's equations of the inertia I + sum J a a^T."""
    model = wheel_spacecraft(HUB, AXES, J, external_torque=True)
    body = rigid_body(locked(HUB, AXES, J))
    rng = np.random.default_rng(2)
    for _ in range(10):
        x = random_state(rng, 4)
        x[7:] = 0.0
        L = rng.normal(size=3)
        xdot = model.rhs(x, np.r_[holding_torque(model, x, L), L])
        np.testing.assert_allclose(xdot[7:], 0.0, atol=1e-13)
        np.testing.assert_allclose(xdot[:7], body.rhs(x[:7], L), rtol=1e-12, atol=1e-13)


@pytest.mark.parametrize("axis, h", [((1.0, 0.0, 0.0), 1.5), ((0.2, 0.3, 1.0), 400.0),
                                     ((0.0, 1.0, 0.0), -2.0)])
def test_gyrostat_is_the_speed_held_wheel(axis, h):
    """gyrostat_model(inertia, a, h) = wheel spacecraft with hub inertia - J a a^T, W = h/J,
    the motor holding W (driven-wheel equations solved for the holding torque)."""
    inertia = np.array([[4560.7, 31.2, -43.4], [31.2, 4545.0, -270.7], [-43.4, -270.7, 1567.4]])
    a = np.array(axis) / np.linalg.norm(axis)
    Jw = 3.0
    gyro = gyrostat_model(inertia, wheel_axis=axis, wheel_momentum=h)
    wheel = wheel_spacecraft(inertia - Jw * np.outer(a, a), a, Jw)
    rng = np.random.default_rng(3)
    for _ in range(10):
        q = rng.normal(size=4)
        x = np.r_[q / np.linalg.norm(q), rng.normal(size=3)]
        xw = np.r_[x, h / Jw]
        xdot = wheel.rhs(xw, holding_torque(wheel, xw))
        np.testing.assert_allclose(gyro.rhs(x), xdot[:7], rtol=1e-10, atol=1e-14)
        np.testing.assert_allclose(gyro.invariant("momentum_inertial", x),
                                   wheel.invariant("momentum_inertial", xw), rtol=1e-12)


def test_gyrostat_equals_the_rotor_derivation_with_the_wheel_held():
    """The gyrostat (a scene: hub, held rotor, torque) is `rotor_dynamics` with the wheel held,
    to 1e-13 (the scene assembles the same law by Kane's method; 4e-16 measured)."""
    inertia, a, h = np.diag([2.0, 3.0, 4.5]), np.array([[0.0], [0.6], [0.8]]), 1.5
    gyro = gyrostat_model(inertia, wheel_axis=a.ravel(), wheel_momentum=h)
    w, L = ca.SX.sym("w", 3), ca.SX.sym("L", 3)
    _, wdot, _ = rotor_dynamics(inertia, a, w, [h], L)
    fun = ca.Function("held", [w, L], [wdot])
    rng = np.random.default_rng(4)
    for _ in range(5):
        x, L0 = random_state(rng, 0), rng.normal(size=3)
        np.testing.assert_allclose(gyro.rhs(x, L0)[4:], fun(x[4:], L0).full().ravel(),
                                   rtol=1e-13, atol=1e-13)


@pytest.mark.slow
def test_locking_loop_reproduces_gyrostat_and_locked_body_trajectories():
    """Closed loop with the holding torque written in CasADi: W stays put, and the motion is
    the gyrostat's (W != 0) or the locked rigid body's (W = 0)."""
    a = np.array([0.0, 0.6, 0.8])
    hub, Jw = np.diag([3.0, 4.0, 5.0]), 0.2
    model = wheel_spacecraft(hub, a, Jw)
    IL = locked(hub, a[:, None], [Jw])
    x = ca.SX.sym("x", 8)
    H = ca.mtimes(ca.DM(IL), x[4:7]) + Jw * x[7] * ca.DM(a)
    wdot = ca.solve(ca.DM(IL), -ca.cross(x[4:7], H))
    law = ca.Function("hold", [x], [Jw * ca.dot(ca.DM(a), wdot)], ["x"], ["u"])
    loop = closed_loop(model, law)
    t = np.linspace(0.0, 40.0, 81)
    w0 = np.array([0.4, -0.3, 0.2])
    for speed, ref in ((5.0, gyrostat_model(IL, wheel_axis=a, wheel_momentum=Jw * 5.0)),
                       (0.0, rigid_body(IL))):
        res = simulate(loop, np.r_[0, 0, 0, 1, w0, speed], t, method="rk8", steps=20)
        expected = simulate(ref, np.r_[0, 0, 0, 1, w0], t, method="rk8", steps=20)
        np.testing.assert_allclose(res.x[7], speed, atol=1e-12)
        np.testing.assert_allclose(res.x[:7], expected.x, atol=1e-11)


# ------------------------------------------------------------------------------ bad inputs
@pytest.mark.parametrize("kwargs, error, match", [
    (dict(inertia=[1.0, 1.0, 3.0]), ValueError, "`inertia`.*triangle"),
    (dict(inertia="big"), TypeError, "`inertia`"),
    (dict(axes=np.ones((2, 3))), ValueError, r"`axes` must have shape \(3, n\)"),
    (dict(axes=np.zeros((3, 0))), ValueError, r"`axes` must have shape \(3, n\)"),
    (dict(axes=[[2.0], [0.0], [0.0]]), ValueError, r"`axes\[:, 0\]` must be a unit vector"),
    (dict(axes=np.c_[[1.0, 0, 0], [0, 0, 0]]), ValueError, r"`axes\[:, 1\]` must be a non-zero"),
    (dict(axes=[[np.nan], [0], [1]]), ValueError, "`axes` must be finite"),
    (dict(wheel_inertia=0.0), ValueError, r"`wheel_inertia` must be a finite number > 0"),
    (dict(wheel_inertia=[0.1, 0.1]), ValueError, r"`wheel_inertia` must be a scalar or have shape \(3,\)"),
    (dict(wheel_inertia="heavy"), TypeError, "`wheel_inertia`"),
    (dict(external_torque="yes"), TypeError, "`external_torque`"),
])
def test_bad_inputs_name_the_argument(kwargs, error, match):
    args = dict(inertia=HUB, axes=np.eye(3), wheel_inertia=0.05)
    args.update(kwargs)
    external = args.pop("external_torque", False)
    with pytest.raises(error, match=match):
        wheel_spacecraft(**args, external_torque=external)


def test_rotor_dynamics_needs_wheel_inertia_to_drive():
    with pytest.raises(ValueError, match="`wheel_inertia`"):
        rotor_dynamics(np.eye(3), np.eye(3)[:, :1], ca.DM.zeros(3), [0.0], motor=[1.0])


def test_docstring_examples():
    result = doctest.testmod(wheels, optionflags=doctest.NORMALIZE_WHITESPACE | doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0
