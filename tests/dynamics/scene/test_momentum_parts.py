"""The momentum parts and the builders wrapped over scenes.

* `rigid_body`, `wheel_spacecraft`, `cmg_spacecraft` (now scenes) equal the hand-written
  models they replaced (tests/dynamics/scene/legacy_momentum.py, copied verbatim): right-hand
  side, d xdot/dx, d xdot/du and every invariant to 1e-13 relative (floor 1e-13) on
  Hypothesis-drawn vehicles, states and controls; same names, units and caching.
* Work and energy: with the motors on, ``E' = sum_i tau_i W_i + L.w`` (reaction wheels) and
  ``E' = sum_i tg_i d_i' + L.w`` (torque-driven CMGs) exactly at random states; momentum
  conserved with ``L = 0`` over 100 s to 1e-10.
* The torque drive has exactly the gimbal-acceleration torque the rate drive leaves out.
"""
import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from appdyn.dynamics import rigid_body, simulate
from appdyn.dynamics.momentum import cmg_spacecraft, pyramid, wheel_spacecraft
from appdyn.dynamics.scene import CMGCluster, ExternalTorque, ReactionWheels, RigidHub, Scene

from . import legacy_momentum as legacy

TOL = 1e-13
SETTINGS = settings(max_examples=25, deadline=None)


# ------------------------------------------------------------------------------ strategies
def unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


@st.composite
def directions(draw):
    v = np.array(draw(st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3)))
    if np.linalg.norm(v) < 0.1:
        v = v + np.array([0.3, -0.2, 0.5])
    return unit(v)


@st.composite
def inertias(draw):
    """A symmetric positive definite inertia meeting the triangle inequality, rotated."""
    a, b = draw(st.floats(1.0, 10.0)), draw(st.floats(1.0, 10.0))
    c = draw(st.floats(abs(a - b) + 0.05, a + b - 0.05))
    axis, angle = draw(directions()), draw(st.floats(-np.pi, np.pi))
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    R = np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K
    I = R @ np.diag([a, b, c]) @ R.T
    return 0.5 * (I + I.T)


@st.composite
def states(draw, n_extra, scale=1.0):
    q = draw(directions())
    q = unit(np.r_[q, draw(st.floats(-1.0, 1.0))])
    w = draw(st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3))
    extra = draw(st.lists(st.floats(-scale, scale), min_size=n_extra, max_size=n_extra))
    return np.r_[q, w, extra]


def controls(n):
    return st.lists(st.floats(-1.0, 1.0), min_size=n, max_size=n).map(np.array)


@st.composite
def cmg_units(draw, n):
    """``n`` unit gimbal axes and unit spin axes perpendicular to them, as (3, n) arrays."""
    g = np.stack([draw(directions()) for _ in range(n)], 1)
    s = np.stack([unit(np.cross(g[:, i], draw(directions()) + [0.01, 0.02, 0.03]))
                  for i in range(n)], 1)
    return g, s


positives = st.floats(0.05, 2.0)


# ------------------------------------------------------------------------------ comparison
_jacobians = {}


def jacobians(model):
    """``(xdot, d xdot/dx, d xdot/du)`` as a Function of ``(x, u)`` (cached per model)."""
    if id(model) not in _jacobians:
        x, u = ca.SX.sym("x", model.nx), ca.SX.sym("u", model.nu)
        xdot = model.f(x=x, u=u, p=ca.DM.zeros(0))["xdot"]
        _jacobians[id(model)] = (model, ca.Function(
            "rhs_and_jacobians", [x, u], [xdot, ca.jacobian(xdot, x), ca.jacobian(xdot, u)]))
    return _jacobians[id(model)][1]


def assert_close(actual, expected, what):
    actual, expected = np.asarray(actual, float), np.asarray(expected, float)
    assert actual.shape == expected.shape, what
    bound = TOL * max(float(np.max(np.abs(expected), initial=0.0)), 1.0)
    err = float(np.max(np.abs(actual - expected), initial=0.0))
    assert err <= bound, f"{what}: error {err:.3g} > {bound:.3g}"


def assert_same_model(new, old, x, u):
    assert (new.states, new.controls, new.params) == (old.states, old.controls, old.params)
    assert new.name == old.name and new.attitude == old.attitude
    assert new.f.name() == new.name  # (the hand-written CMG models were both "cmg_spacecraft")
    assert dict(new.units) == dict(old.units)
    assert set(new.invariants) == set(old.invariants)
    for name, a, b in zip(("xdot", "d xdot/dx", "d xdot/du"), jacobians(new)(x, u),
                          jacobians(old)(x, u)):
        assert_close(a, b, name)
    for key in old.invariants:
        assert_close(new.invariant(key, x), old.invariant(key, x), key)


# ------------------------------------------------------------------------ wrappers = legacy
@SETTINGS
@given(inertias(), states(0), controls(3))
def test_rigid_body_equals_the_hand_written_model(I, x, u):
    new = rigid_body(I)
    assert_same_model(new, legacy.rigid_body(I), x, u)
    assert rigid_body(I.tolist()) is new


@SETTINGS
@given(st.data())
@pytest.mark.slow
def test_wheel_spacecraft_equals_the_hand_written_model(data):
    n = data.draw(st.integers(1, 4))
    I = data.draw(inertias())
    axes = np.stack([data.draw(directions()) for _ in range(n)], 1)
    J = np.array(data.draw(st.lists(positives, min_size=n, max_size=n)))
    torque = data.draw(st.booleans())
    x = data.draw(states(n, 50.0))
    u = data.draw(controls(n + 3 * torque))
    new = wheel_spacecraft(I, axes, J, external_torque=torque)
    assert_same_model(new, legacy.wheel_spacecraft(I, axes, J, external_torque=torque), x, u)
    assert wheel_spacecraft(I.tolist(), axes.tolist(), J.tolist(), external_torque=torque) is new


@SETTINGS
@given(st.data())
@pytest.mark.slow
def test_cmg_spacecraft_equals_the_hand_written_model(data):
    n = data.draw(st.integers(1, 4))
    I = data.draw(inertias())
    g, s = data.draw(cmg_units(n))
    h = np.array(data.draw(st.lists(st.floats(0.1, 5.0), min_size=n, max_size=n)))
    fidelity = data.draw(st.sampled_from(["exact", "torque"]))
    kw = {}
    if fidelity == "exact":
        for key in ("rotor_inertia", "gimbal_inertia"):
            if data.draw(st.booleans()):
                kw[key] = np.array(data.draw(st.lists(positives, min_size=n, max_size=n)))
    torque = data.draw(st.booleans())
    x = data.draw(states(n, np.pi))
    u = data.draw(controls(n + 3 * torque))
    new = cmg_spacecraft(I, g, s, h, fidelity=fidelity, external_torque=torque, **kw)
    old = legacy.cmg_spacecraft(I, g, s, h, fidelity=fidelity, external_torque=torque, **kw)
    assert_same_model(new, old, x, u)
    assert cmg_spacecraft(I, g, s, h, fidelity=fidelity, external_torque=torque, **kw) is new


# -------------------------------------------------------------------------- work and energy
def energy_rate(model):
    """``dE/dt = dE/dx . f(x, u)`` as a Function of ``(x, u)``."""
    x, u = ca.SX.sym("x", model.nx), ca.SX.sym("u", model.nu)
    xdot = model.f(x=x, u=u, p=ca.DM.zeros(0))["xdot"]
    E = model.invariants["energy"](x, ca.DM.zeros(0))
    return ca.Function("Edot", [x, u], [ca.jtimes(E, x, xdot)])


I_HUB = np.array([[12.0, 0.3, -0.2], [0.3, 10.0, 0.1], [-0.2, 0.1, 8.0]])
WHEELS = Scene(RigidHub(I_HUB), ReactionWheels(np.c_[np.eye(3), unit([1, 1, 1])], [0.05, 0.06, 0.04, 0.08]),
               ExternalTorque())
GEO = pyramid(np.arccos(1 / np.sqrt(3)), 2.0)
H_ROTOR = np.array([2.0, 2.0, 2.5, 1.5])
J_ROTOR, J_GIMBAL = np.array([0.3, 0.2, 0.3, 0.25]), np.array([0.1, 0.2, 0.3, 0.4])


def cmgs(drive, **kw):
    return CMGCluster(GEO.gimbal_axes, GEO.spin_axes0, H_ROTOR, rotor_inertia=J_ROTOR,
                      gimbal_inertia=J_GIMBAL, drive=drive, **kw)


CMG_TORQUE = Scene(RigidHub(I_HUB), cmgs("torque"), ExternalTorque())


@settings(max_examples=50, deadline=None)
@given(states(4, 50.0), controls(7))
def test_wheel_energy_changes_by_the_motor_and_external_work(x, u):
    model = WHEELS.model()
    w, W, tau, L = x[4:7], x[7:], u[:4], u[4:]
    power = np.r_[tau * W, L * w]
    rate = float(energy_rate(model)(x, u))
    assert abs(rate - power.sum()) <= 1e-13 * max(np.abs(power).sum(), 1.0)


@settings(max_examples=50, deadline=None)
@given(states(8, 3.0), controls(7))
def test_cmg_energy_changes_by_the_gimbal_motor_and_external_work(x, u):
    model = CMG_TORQUE.model()
    lay = CMG_TORQUE.layout["cmgs"]
    w, rates, tg, L = x[4:7], x[lay.speeds], u[:4], u[4:]
    power = np.r_[tg * rates, L * w]
    rate = float(energy_rate(model)(x, u))
    assert abs(rate - power.sum()) <= 1e-13 * max(np.abs(power).sum(), 1.0)


def test_cmg_torque_drive_adds_exactly_the_gimbal_acceleration_torque():
    """At one state, the rate drive fed the torque drive's gimbal rates misses exactly
    ``-sum_i J_g,i d_i'' g_i``: ``I(d) (w'_torque - w'_rate) = -sum_i J_g,i d_i'' g_i``."""
    rate_model = Scene(RigidHub(I_HUB), cmgs("rate")).model()
    torque_model = Scene(RigidHub(I_HUB), cmgs("torque")).model()
    rng = np.random.default_rng(3)
    for _ in range(5):
        q = unit(rng.normal(size=4))
        w, d, dd, tg = rng.normal(size=3), rng.normal(size=4), rng.normal(size=4), rng.normal(size=4)
        xt = torque_model.rhs(np.r_[q, w, d, dd], tg)
        xr = rate_model.rhs(np.r_[q, w, d], dd)
        s = np.cos(d) * GEO.spin_axes0 + np.sin(d) * np.cross(GEO.gimbal_axes, GEO.spin_axes0, axis=0)
        I_d = I_HUB + (s * J_ROTOR) @ s.T
        np.testing.assert_allclose(I_d @ (xt[4:7] - xr[4:7]), -GEO.gimbal_axes @ (J_GIMBAL * xt[11:]),
                                   rtol=0, atol=1e-13 * np.abs(xt[11:]).max())
        np.testing.assert_array_equal(xt[7:11], dd)  # the angles' rates are the speeds


def motor_torques(t):
    k = np.arange(1, 5)
    return 0.01 * np.sin(0.1 * k * t + k)


@pytest.mark.parametrize("scene, x0", [
    (Scene(RigidHub(I_HUB), WHEELS.parts[0]), np.r_[0.1, -0.2, 0.3, 0.9, 0.03, -0.02, 0.04, 5.0, -3.0, 2.0, 1.0]),
    (Scene(RigidHub(I_HUB), cmgs("torque")), np.r_[0.1, -0.2, 0.3, 0.9, 0.03, -0.02, 0.04, 0.1, -0.2, 0.3, 0.0,
                                                   0.05, 0.0, -0.02, 0.01]),
], ids=["wheels", "cmgs_torque_drive"])
def test_momentum_conserved_over_100_s_with_the_motors_on(scene, x0):
    model = scene.model()
    x0 = x0.copy()
    x0[:4] /= np.linalg.norm(x0[:4])
    t = np.linspace(0.0, 100.0, 201)
    res = simulate(model, x0, t, u=motor_torques, method="rk8", steps=10)
    assert res.success
    H = model.invariant("momentum_inertial", res.x)
    drift = np.max(np.linalg.norm(H - H[:, :1], axis=0)) / np.linalg.norm(H[:, 0])
    assert drift < 1e-10
    speeds = res.x[scene.layout[scene.part_names[0]].speeds]
    assert np.ptp(speeds, axis=1).min() > 0.05  # the motors really drove the part
    assert np.ptp(res.x[4:7], axis=1).max() > 0.01  # and moved the body


# ------------------------------------------------------------------------------ CMGCluster
def test_cmg_cluster_names_bounds_and_layout():
    scene = Scene(RigidHub(I_HUB), cmgs("torque", u_max=0.5))
    model = scene.model()
    assert model.states[7:] == ("d1", "d2", "d3", "d4", "d1_dot", "d2_dot", "d3_dot", "d4_dot")
    assert model.controls == ("tg1", "tg2", "tg3", "tg4")
    assert model.units["tg2"] == "N m" and model.units["d2_dot"] == "rad/s"
    assert model.bounds["tg4"] == (-0.5, 0.5)
    assert scene.layout["cmgs"].coords == slice(7, 11) and scene.layout["cmgs"].speeds == slice(11, 15)
    assert set(model.invariants) == {"energy", "momentum_inertial", "quat_norm", "cmg_momentum"}
    rate = Scene(RigidHub(I_HUB), cmgs("rate", u_max=[0.1, 0.2, 0.3, 0.4])).model()
    assert rate.controls == ("d1_dot", "d2_dot", "d3_dot", "d4_dot")
    assert rate.bounds["d3_dot"] == (-0.3, 0.3)


@pytest.mark.parametrize("kwargs, error, match", [
    (dict(drive="torque", gimbal_inertia=None), ValueError, "`drive='torque'` needs `gimbal_inertia`"),
    (dict(drive="torque", fidelity="torque", rotor_inertia=None, gimbal_inertia=None), ValueError,
     "needs fidelity='exact'"),
    (dict(drive="servo"), ValueError, "`drive` must be 'rate' or 'torque'"),
    (dict(fidelity="torque"), ValueError, "`rotor_inertia` is not used"),
    (dict(u_max=-1.0), ValueError, "u_max"),
    (dict(gimbal_inertia=[0.1, 0.2]), ValueError, "`gimbal_inertia` must be a scalar or have shape"),
    (dict(h=[1.0, 2.0]), ValueError, r"`h` must be a scalar or have shape \(4,\)"),
])
def test_cmg_cluster_bad_input_names_the_argument(kwargs, error, match):
    args = dict(gimbal_axes=GEO.gimbal_axes, spin_axes0=GEO.spin_axes0, h=H_ROTOR,
                rotor_inertia=J_ROTOR, gimbal_inertia=J_GIMBAL)
    args.update(kwargs)
    with pytest.raises(error, match=match):
        CMGCluster(**args)


def test_wrapped_builders_read_by_layout():
    """The wrapped builders are scenes: their parts' slices are in ``layout``."""
    assert rigid_body(I_HUB).layout["torque"].controls == slice(0, 3)
    wheels = wheel_spacecraft(I_HUB, np.eye(3), 0.05, external_torque=True)
    assert wheels.layout["wheels"].states == slice(7, 10)
    assert wheels.layout["torque"].controls == slice(3, 6)
    cmg = cmg_spacecraft(I_HUB, GEO.gimbal_axes, GEO.spin_axes0, H_ROTOR)
    assert cmg.layout["cmgs"].coords == slice(7, 11) and cmg.layout["cmgs"].controls == slice(0, 4)
