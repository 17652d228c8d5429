"""Two hinged bodies (dynamics.hinged) against independent formulations.

Truths: conservation of energy and of linear and angular momentum (no external forces); a
reduced Newton-Euler model of the ball hinge written here (relative position eliminated, the
hinge force solved by hand with the rotational accelerations); for a revolute hinge carrying
an axisymmetric rotor, the free-wheel spacecraft of `dynamics.momentum.wheel_spacecraft`; the
kinematic formulas of the hinge against automatic differentiation; Newton's and Euler's laws
for body 2 under the reported hinge force and torque.
"""
import functools
import pickle

import casadi as ca
import numpy as np
import pytest

from appdyn.dynamics import hinged_bodies, simulate, wheel_spacecraft
from appdyn.dynamics.attitude import dcm_from_quat, quat_from_axis_angle, quat_mul, quat_rate, skew
from appdyn.dynamics.constrained import constraint_terms
from appdyn.dynamics.hinged import HINGED_STATES, Hinge, hinge_terms

BODIES = dict(m1=10.0, I1=[[2.0, 0.1, 0.0], [0.1, 3.0, -0.2], [0.0, -0.2, 4.0]], m2=4.0,
              I2=[0.5, 0.6, 0.7], r1=[0.5, 0.1, -0.2], r2=[-0.3, 0.05, 0.1])
AXIS = np.array([1.0, 2.0, 2.0]) / 3.0
Q1 = quat_from_axis_angle([1, 2, 3], 0.4)
W1, V1 = np.array([0.3, -0.2, 0.5]), np.array([0.1, 0.0, -0.05])
T_LONG = np.linspace(0.0, 1000.0, 11)
STEPS_LONG = 1000  # h = 0.1 s with rk8 (interpreted: ~40 us a step)


def _model(kind="ball", stabilization=1.0):
    axis = AXIS if kind == "revolute" else None
    return hinged_bodies(**BODIES, kind=kind, axis=axis, stabilization=stabilization)


def _x0(model):
    if model.hinge.kind == "ball":
        return model.initial_state(Q1, W1, V1, quat_from_axis_angle([-1, 0.5, 2], 1.1),
                                   [-0.4, 0.6, 0.2], position=[1.0, -2.0, 0.5])
    q2 = quat_mul(quat_from_axis_angle(AXIS, 0.7), Q1)
    C = dcm_from_quat(q2) @ dcm_from_quat(Q1).T
    return model.initial_state(Q1, W1, V1, q2, C @ (W1 + 0.8 * AXIS))


@functools.lru_cache(maxsize=None)
def _long_run(kind, stabilization):
    model = _model(kind, stabilization)
    return simulate(model, _x0(model), T_LONG, method="rk8", steps=STEPS_LONG, jit=False,
                    invariants=True)


def _relative_drift(values):
    values = np.asarray(values)
    first = values[..., :1]
    return float(np.max(np.abs(values - first)) / np.max(np.abs(first)))


# --------------------------------------------------------------- conservation
@pytest.mark.parametrize("kind", ["ball", "revolute"])
@pytest.mark.slow
def test_momentum_and_energy_conserved_and_hinge_held_over_1000_s(kind):
    res = _long_run(kind, 1.0)
    assert res.success
    for name in ("energy", "momentum_linear", "momentum_angular"):
        assert _relative_drift(res.invariants[name]) < 1e-10, name
    assert np.max(res.invariants["constraint_residual"]) < 1e-10
    for name in ("quat_norm", "quat_norm_2"):
        assert np.max(np.abs(res.invariants[name] - 1.0)) < 1e-12


@pytest.mark.slow
def test_residual_grows_without_stabilization():
    held = _long_run("ball", 1.0).invariants["constraint_residual"]
    free = _long_run("ball", None).invariants["constraint_residual"]
    # without Baumgarte the position residual grows (about like t^2), with it it stays flat
    assert free[0, -1] > 30 * free[0, 1]
    assert free[0, -1] > 100 * np.max(held)


# ------------------------------------------------------ independent formulations
def _reduced_ball(m1, I1, m2, I2, r1, r2):
    """Rotations only (14 states): the hinge force F on body 2 (inertial) solved with the
    rotational accelerations from F = mu d'' (d = R2 - R1 = A1^T r1 - A2^T r2) and Euler's law
    for each body; the mass centre moves uniformly."""
    y = ca.SX.sym("y", 14)
    q1, w1, q2, w2 = y[0:4], y[4:7], y[7:11], y[11:14]
    A1, A2 = dcm_from_quat(q1), dcm_from_quat(q2)
    I1, I2 = ca.DM(np.array(I1)), ca.DM(np.diag(I2))
    S1, S2 = ca.DM(skew(np.array(r1))), ca.DM(skew(np.array(r2)))
    r1, r2 = ca.DM(r1), ca.DM(r2)
    mu = m1 * m2 / (m1 + m2)
    Z, E = ca.DM.zeros(3, 3), ca.DM.eye(3)
    K = ca.vertcat(ca.horzcat(mu * A1.T @ S1, -mu * A2.T @ S2, E),
                   ca.horzcat(I1, Z, S1 @ A1),
                   ca.horzcat(Z, I2, -S2 @ A2))
    rhs = ca.vertcat(mu * (A1.T @ ca.cross(w1, ca.cross(w1, r1)) - A2.T @ ca.cross(w2, ca.cross(w2, r2))),
                     -ca.cross(w1, I1 @ w1), -ca.cross(w2, I2 @ w2))
    z = ca.solve(K, rhs)
    ydot = ca.vertcat(quat_rate(q1, w1), z[0:3], quat_rate(q2, w2), z[3:6])
    from appdyn.dynamics import Model
    f = ca.Function("reduced", [y, ca.SX.sym("u", 0), ca.SX.sym("p", 0)], [ydot],
                    ["x", "u", "p"], ["xdot"])
    return Model(f, tuple(f"y{i}" for i in range(14)), ())


def _full_from_reduced(y, t, centre0, centre_rate, b):
    m1, m2, r1, r2 = b["m1"], b["m2"], np.array(b["r1"]), np.array(b["r2"])
    m = m1 + m2
    out = []
    for k in range(y.shape[1]):
        q1, w1, q2, w2 = y[0:4, k], y[4:7, k], y[7:11, k], y[11:14, k]
        A1, A2 = dcm_from_quat(q1), dcm_from_quat(q2)
        d = A1.T @ r1 - A2.T @ r2
        ddot = A1.T @ np.cross(w1, r1) - A2.T @ np.cross(w2, r2)
        Rc = centre0 + centre_rate * t[k]
        v1 = A1 @ (centre_rate - m2 / m * ddot)
        v2 = A2 @ (centre_rate + m1 / m * ddot)
        out.append(np.r_[q1, w1, v1, Rc - m2 / m * d, q2, w2, v2, Rc + m1 / m * d])
    return np.array(out).T


@pytest.mark.slow
def test_ball_hinge_equals_reduced_newton_euler_model():
    model = _model("ball")
    x0 = _x0(model)
    t = np.linspace(0.0, 30.0, 31)
    res = simulate(model, x0, t, method="rk8", steps=100, jit=False)
    red = simulate(_reduced_ball(**BODIES), np.r_[x0[0:7], x0[13:20]], t, method="rk8",
                   steps=100, jit=False)
    m1, m2 = BODIES["m1"], BODIES["m2"]
    A1, A2 = dcm_from_quat(x0[0:4]), dcm_from_quat(x0[13:17])
    centre0 = (m1 * x0[10:13] + m2 * x0[23:26]) / (m1 + m2)
    centre_rate = (m1 * A1.T @ x0[7:10] + m2 * A2.T @ x0[20:23]) / (m1 + m2)
    full = _full_from_reduced(red.x, t, centre0, centre_rate, BODIES)
    np.testing.assert_allclose(res.x, full, rtol=0, atol=1e-10)
    assert np.ptp(res.x[4:7], axis=1).max() > 0.1  # the bodies really tumble


@pytest.mark.slow
def test_revolute_rotor_equals_free_wheel_spacecraft():
    """Body 2 an axisymmetric rotor on the axis through its own mass centre (r2 = 0): the
    pair is a hub with a free wheel (zero motor torque)."""
    m1, m2, r1, a = 10.0, 2.0, np.array([0.2, -0.1, 0.4]), np.array([0.0, 0.0, 1.0])
    I1 = np.array(BODIES["I1"])
    It, J = 0.3, 0.5
    model = hinged_bodies(m1, I1, m2, [It, It, J], r1, [0.0, 0.0, 0.0], kind="revolute", axis=a)
    m = m1 + m2
    d1, d2 = -m2 / m * r1, m1 / m * r1  # from the system mass centre
    shift = lambda d: np.eye(3) * (d @ d) - np.outer(d, d)  # noqa: E731
    hub = I1 + m1 * shift(d1) + np.diag([It, It, 0.0]) + m2 * shift(d2)
    W0 = 2.0
    q2 = quat_mul(quat_from_axis_angle(a, 0.3), Q1)
    C = dcm_from_quat(q2) @ dcm_from_quat(Q1).T
    x0 = model.initial_state(Q1, W1, V1, q2, C @ (W1 + W0 * a))
    t = np.linspace(0.0, 30.0, 31)
    res = simulate(model, x0, t, method="rk8", steps=100, jit=False)
    ref = simulate(wheel_spacecraft(hub, a, J), np.r_[Q1, W1, W0], t, method="rk8", steps=100,
                   jit=False)
    np.testing.assert_allclose(res.x[0:7], ref.x[0:7], rtol=0, atol=1e-10)
    rel = [a @ (dcm_from_quat(res.x[0:4, k]) @ dcm_from_quat(res.x[13:17, k]).T @ res.x[17:20, k]
                - res.x[4:7, k]) for k in range(t.size)]
    np.testing.assert_allclose(rel, ref.x[7], rtol=0, atol=1e-10)
    assert np.ptp(ref.x[4:7], axis=1).max() > 0.05  # the hub nutates


@pytest.mark.slow
def test_revolute_hinge_turns_about_the_axis_only():
    res = _long_run("revolute", 1.0)
    model = _model("revolute")
    for k in range(T_LONG.size):
        x = res.x[:, k]
        A1, A2 = dcm_from_quat(x[0:4]), dcm_from_quat(x[13:17])
        Ct = A1 @ A2.T  # body 2 -> body 1 axes
        assert np.linalg.norm(Ct @ AXIS - AXIS) < 1e-10
        w_rel = Ct @ x[17:20] - x[4:7]
        assert np.linalg.norm(w_rel - (AXIS @ w_rel) * AXIS) < 1e-10
        torque = model.invariant("hinge_torque", x)  # frictionless: none about the axis
        assert abs(torque @ (A1.T @ AXIS)) < 1e-12 * max(1.0, np.linalg.norm(torque))
    n1 = np.cross([1.0, 0.0, 0.0], AXIS) / np.linalg.norm(np.cross([1.0, 0.0, 0.0], AXIS))
    n2 = np.cross(AXIS, n1)
    angle = []
    for k in range(T_LONG.size):  # C = A2 A1^T turns n1 into cos(angle) n1 - sin(angle) n2
        C = dcm_from_quat(res.x[13:17, k]) @ dcm_from_quat(res.x[0:4, k]).T
        angle.append(np.arctan2(-n2 @ C @ n1, n1 @ C @ n1))
    assert np.ptp(np.unwrap(angle)) > 1.0  # and it does turn


# ------------------------------------------------------------- hinge reactions
@pytest.mark.parametrize("kind", ["ball", "revolute"])
def test_hinge_force_and_torque_obey_newton_and_euler_for_body_2(kind):
    model = _model(kind)
    x = _x0(model)
    xdot = model.rhs(x)
    A2 = dcm_from_quat(x[13:17])
    w2, v2 = x[17:20], x[20:23]
    force, torque = model.invariant("hinge_force", x), model.invariant("hinge_torque", x)
    np.testing.assert_allclose(BODIES["m2"] * A2.T @ (xdot[20:23] + np.cross(w2, v2)), force,
                               atol=1e-12)
    I2 = np.diag(BODIES["I2"])
    euler = I2 @ xdot[17:20] + np.cross(w2, I2 @ w2)
    np.testing.assert_allclose(euler, np.cross(BODIES["r2"], A2 @ force) + A2 @ torque, atol=1e-12)
    if kind == "ball":
        np.testing.assert_allclose(torque, 0.0, atol=1e-13)
    else:
        assert np.linalg.norm(torque) > 1e-3


@pytest.mark.parametrize("kind, axis", [("ball", None), ("revolute", tuple(AXIS))])
def test_hand_written_terms_equal_automatic_differentiation(kind, axis):
    b = BODIES
    h = Hinge(b["m1"], tuple(np.ravel(b["I1"])), b["m2"], tuple(np.ravel(np.diag(b["I2"]))),
              tuple(b["r1"]), tuple(b["r2"]), kind, axis, None)
    xs = [ca.SX.sym(n, k) for n, k in (("q1", 4), ("w1", 3), ("v1", 3), ("R1", 3),
                                       ("q2", 4), ("w2", 3), ("v2", 3), ("R2", 3))]
    q1, w1, v1, R1, q2, w2, v2, R2 = xs
    phi, B, c = hinge_terms(h, *xs)
    A1, A2 = dcm_from_quat(q1), dcm_from_quat(q2)
    rates = ca.vertcat(quat_rate(q1, w1), A1.T @ v1, quat_rate(q2, w2), A2.T @ v2)
    auto = constraint_terms(ca.vertcat(q1, R1, q2, R2), rates, ca.vertcat(v1, w1, v2, w2), position=phi)
    f = ca.Function("f", [ca.vertcat(*xs)], [B - auto.B, c - auto.c, auto.b])
    rng = np.random.default_rng(4)
    for scale in (1.0, 1.0 + 1e-3):  # exact also off unit quaternion norm
        x = rng.normal(size=26)
        for o in (0, 13):
            x[o:o + 4] *= scale / np.linalg.norm(x[o:o + 4])
        for diff in f(x):
            assert np.max(np.abs(np.asarray(diff))) < 1e-13


def test_ball_formulas_of_the_docstring():
    model = _model("ball")
    x = _x0(model)
    A1, A2 = dcm_from_quat(x[0:4]), dcm_from_quat(x[13:17])
    r1, r2 = np.array(BODIES["r1"]), np.array(BODIES["r2"])
    phi, B, residual = (np.asarray(a) for a in model.constraints(x, []))
    B_doc = np.hstack([A1.T, -A1.T @ skew(r1), -A2.T, A2.T @ skew(r2)])
    np.testing.assert_allclose(B, B_doc, atol=1e-15)
    np.testing.assert_allclose(phi.ravel(), x[10:13] + A1.T @ r1 - x[23:26] - A2.T @ r2, atol=1e-15)
    np.testing.assert_allclose(residual.ravel(), 0.0, atol=1e-15)


# ------------------------------------------------------------ assembly helpers
def test_initial_state_completes_body_2():
    model = _model("ball")
    x = _x0(model)
    assert x.shape == (26,) and model.states == HINGED_STATES
    np.testing.assert_allclose(x[10:13], [1.0, -2.0, 0.5])
    np.testing.assert_allclose(model.invariant("constraint_residual", x), 0.0, atol=1e-15)
    assert model.attitude == (0, 4) and model.nu == 0


def test_revolute_initial_state_checks_q2_and_w2():
    model = _model("revolute")
    q2 = quat_mul(quat_from_axis_angle(AXIS, 0.7), Q1)
    C = dcm_from_quat(q2) @ dcm_from_quat(Q1).T
    with pytest.raises(ValueError, match="`q2`"):
        model.initial_state(Q1, W1, V1, quat_from_axis_angle([1, 0, 0], 0.7), W1)
    with pytest.raises(ValueError, match="`w2`"):
        model.initial_state(Q1, W1, V1, q2, C @ W1 + [0.01, 0.0, 0.0])
    x = model.initial_state(Q1, W1, V1, -q2, C @ (W1 + 0.5 * AXIS) + 1e-12)  # round-off: projected
    np.testing.assert_allclose(model.invariant("constraint_residual", x), 0.0, atol=1e-14)
    assert x[13:17] @ q2 < 0  # the sign given is kept
    with pytest.raises(ValueError, match="`q1`"):
        model.initial_state([0, 0, 0, 2.0], W1, V1, q2, W1)
    with pytest.raises(ValueError, match="`position`"):
        model.initial_state(Q1, W1, V1, q2, C @ W1, position=[0.0, np.nan, 0.0])


@pytest.mark.parametrize("kind", ["ball", "revolute"])
def test_project_closes_the_hinge_and_keeps_momentum(kind):
    model = _model(kind)
    x = _x0(model).copy()
    x[23:26] += [1e-3, -2e-3, 5e-4]  # open the hinge
    x[13:17] += 1e-4                 # tilt body 2 (and leave its quaternion off unit norm)
    x[20:23] += [0.01, 0.0, -0.02]   # and give it a velocity across the hinge
    res = model.project(x)
    assert res.success and res.residual < 1e-12
    assert abs(np.linalg.norm(res.x[13:17]) - 1.0) < 1e-15
    m1, m2 = BODIES["m1"], BODIES["m2"]
    centre = lambda x: (m1 * x[10:13] + m2 * x[23:26]) / (m1 + m2)  # noqa: E731
    np.testing.assert_allclose(centre(res.x), centre(x), atol=1e-15)  # mass-weighted moves
    # the velocity step is an internal impulse: the momenta of the projected positions with
    # the velocities given are kept
    y = res.x.copy()
    velocities = np.r_[4:10, 17:23]
    y[velocities] = x[velocities]
    for name in ("momentum_linear", "momentum_angular"):
        np.testing.assert_allclose(model.invariant(name, res.x), model.invariant(name, y), atol=1e-13)


def test_pickle_round_trip_keeps_the_helpers():
    model = _model("revolute")
    back = pickle.loads(pickle.dumps(model))
    assert back.hinge == model.hinge
    np.testing.assert_allclose(back.rhs(_x0(back)), model.rhs(_x0(model)), atol=0)


def test_models_are_cached_by_their_arguments():
    assert _model("ball") is _model("ball")
    assert _model("ball") is not _model("ball", None)


# --------------------------------------------------------------------- bad input
@pytest.mark.parametrize("change, name", [
    (dict(m1=0.0), "`m1`"), (dict(m2=-1.0), "`m2`"), (dict(I1=[1.0, 1.0, -1.0]), "`I1`"),
    (dict(I2=[1.0, 1.0, 3.0]), "`I2`"), (dict(r1=[0.0, 1.0]), "`r1`"),
    (dict(r2=[0.0, np.inf, 0.0]), "`r2`"), (dict(kind="hinge"), "`kind`"),
    (dict(kind="revolute"), "`axis`"), (dict(kind="revolute", axis=[0.0, 0.0, 2.0]), "`axis"),
    (dict(axis=[0.0, 0.0, 1.0]), "`axis`"), (dict(stabilization=0.0), "`stabilization`"),
])
def test_bad_arguments_are_named(change, name):
    with pytest.raises(ValueError, match=name):
        hinged_bodies(**{**BODIES, **change})
