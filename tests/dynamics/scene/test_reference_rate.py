"""``RigidHub(reference_rate=Omega)``: attitude (and position) referred to a frame turning at
a constant rate (seed 000 Eq. 6.42), against the inertial simulation transformed."""
import numpy as np
import pytest

from appdyn.dynamics import simulate
from appdyn.dynamics.attitude import dcm_from_quat
from appdyn.dynamics.scene import ExternalTorque, ReactionWheels, RigidHub, Scene

J = np.array([[10.0, 0.4, -0.2], [0.4, 12.0, 0.3], [-0.2, 0.3, 8.0]])
OMEGA = np.array([0.02, -0.05, 0.1])


def _frame_dcm(t):
    """Inertial -> reference frame, the frame turning at OMEGA (its own and inertial axes)."""
    n, th = OMEGA / np.linalg.norm(OMEGA), np.linalg.norm(OMEGA) * t
    K = np.array([[0.0, -n[2], n[1]], [n[2], 0.0, -n[0]], [-n[1], n[0], 0.0]])
    return (np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * K @ K).T


def _quat(rng):
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


def _run(model, x0, t, u=None):
    res = simulate(model, x0, t, u=u, method="rk8", steps=400, jit=False)
    assert res.success
    return res.x


def test_at_rest_in_the_turning_frame_keeps_its_attitude():
    """``w = A Omega`` held by the torque ``w x J w``: ``q`` stays, ``w`` stays."""
    rng = np.random.default_rng(6)
    q0 = _quat(rng)
    w0 = dcm_from_quat(q0) @ OMEGA
    scene = Scene(RigidHub(J, reference_rate=OMEGA), ExternalTorque())
    t = np.linspace(0.0, 100.0, 11)
    x = _run(scene.model(), scene.state(q=q0, w=w0), t, u=np.cross(w0, J @ w0))
    np.testing.assert_allclose(x[0:4] - q0[:, None], 0.0, atol=1e-13)
    np.testing.assert_allclose(x[4:7] - w0[:, None], 0.0, atol=1e-13)


def test_torque_free_spin_about_a_principal_axis_along_omega():
    Jd = np.diag([10.0, 12.0, 8.0])
    Om = np.array([0.0, 0.0, 0.3])
    scene = Scene(RigidHub(Jd, reference_rate=Om))
    x = _run(scene.model(), scene.state(w=Om), np.linspace(0.0, 50.0, 6))
    np.testing.assert_allclose(x[0:4], np.array([0, 0, 0, 1.0])[:, None] + 0 * x[0:4], atol=1e-13)


@pytest.mark.parametrize("mass, wheels", [(None, False), (50.0, False), (None, True)])
def test_turning_reference_equals_the_inertial_simulation_transformed(mass, wheels):
    rng = np.random.default_rng(7 if mass is None else 8)
    q0, w0 = _quat(rng), rng.normal(scale=0.2, size=3)
    parts = (ReactionWheels(np.eye(3), 0.05),) if wheels else ()
    inertial = Scene(RigidHub(J, mass=mass), *parts)
    turning = Scene(RigidHub(J, mass=mass, reference_rate=OMEGA), *parts)
    extra = {} if mass is None else {"r": [100.0, -20.0, 5.0], "v": [1.0, 2.0, -0.5]}
    if wheels:
        extra["wheels"] = [30.0, -10.0, 5.0]
    t = np.linspace(0.0, 30.0, 7)
    xi = _run(inertial.model(), inertial.state(q=q0, w=w0, **extra), t)
    xr = _run(turning.model(), turning.state(q=q0, w=w0, **extra), t)  # frames agree at t = 0
    Hr = turning.model().invariant("momentum_inertial", xr)
    Hi = inertial.model().invariant("momentum_inertial", xi)
    for j, tj in enumerate(t):
        R = _frame_dcm(tj)
        np.testing.assert_allclose(dcm_from_quat(xr[0:4, j]), dcm_from_quat(xi[0:4, j]) @ R.T,
                                   atol=1e-11)
        np.testing.assert_allclose(xr[4:7, j], xi[4:7, j], atol=1e-12)
        np.testing.assert_allclose(xr[7:, j] if wheels else 0, xi[7:, j] if wheels else 0,
                                   rtol=1e-12)                         # wheel speeds
        if mass is not None:
            np.testing.assert_allclose(xr[7:10, j], R @ xi[7:10, j], rtol=1e-12, atol=1e-10)
            np.testing.assert_allclose(xr[10:13, j], xi[10:13, j], atol=1e-12)
        # inertial momentum conserved: the reference-axes invariant turned back is constant
        np.testing.assert_allclose(R.T @ np.ravel(Hr[:, j]), np.ravel(Hi[:, 0]), rtol=1e-11,
                                   atol=1e-11)
    E = turning.model().invariant("energy", xr)
    np.testing.assert_allclose(np.ravel(E), float(np.ravel(E)[0]), rtol=1e-12)


def test_reference_rate_is_checked_and_part_of_the_scene():
    with pytest.raises(ValueError, match="reference_rate"):
        RigidHub(J, reference_rate=[0.0, 1.0])
    assert RigidHub(J, reference_rate=OMEGA) != RigidHub(J)
    assert Scene(RigidHub(J, reference_rate=OMEGA)).model() is not Scene(RigidHub(J)).model()


def test_gravity_gradient_in_the_orbit_frame_equals_the_inertial_simulation_transformed():
    """``reference_rate = (0, 0, n)``: the attitude from the local-vertical frame; the orbit
    stays inertial, so the run is the inertial one seen from the turning frame."""
    from appdyn.dynamics.scene import GravityGradient
    mu, radius = 3.986004418e14, 7.0e6
    n = np.sqrt(mu / radius ** 3)
    Om = np.array([0.0, 0.0, n])
    rng = np.random.default_rng(11)
    q0, w0 = _quat(rng), rng.normal(scale=2e-3, size=3)
    inertial = Scene(RigidHub(J), GravityGradient(mu, radius))
    lvlh = Scene(RigidHub(J, reference_rate=Om), GravityGradient(mu, radius))
    t = np.linspace(0.0, 3000.0, 7)
    xi = _run(inertial.model(), inertial.state(q=q0, w=w0), t)
    xr = _run(lvlh.model(), lvlh.state(q=q0, w=w0), t)
    for j, tj in enumerate(t):
        th = n * tj
        R = np.array([[np.cos(th), np.sin(th), 0.0], [-np.sin(th), np.cos(th), 0.0],
                      [0.0, 0.0, 1.0]])                       # inertial -> orbit frame
        np.testing.assert_allclose(dcm_from_quat(xr[0:4, j]), dcm_from_quat(xi[0:4, j]) @ R.T,
                                   atol=1e-10)
        np.testing.assert_allclose(xr[4:7, j], xi[4:7, j], atol=1e-12)
    # the nadir is fixed in the orbit frame: a body held along it feels the same torque at
    # every time (the torque of the inertial scene at t = 0)
    f_r, f_i = lvlh.model().rhs, inertial.model().rhs
    x = lvlh.state(q=q0, w=w0)
    for tj in (0.0, 700.0, 2900.0):
        x[-1] = tj
        np.testing.assert_allclose(np.ravel(f_r(x)[4:7]),
                                   np.ravel(f_i(inertial.state(q=q0, w=w0))[4:7]),
                                   rtol=1e-12, atol=1e-18)


def test_air_at_rest_in_the_turning_frame_gives_no_aerodynamic_force():
    """A vehicle at rest in an Earth-fixed frame (``w = A Omega``, ``v = A (Omega x r)``)
    sees no air velocity: its rates equal those of the same hub without air."""
    from appdyn.dynamics.attitude import dcm_from_quat as dq
    from appdyn.dynamics.scene import Aerodynamics
    Om = np.array([0.0, 0.0, 7.2921159e-5])
    hub = RigidHub(J, mass=1000.0, reference_rate=Om)
    air = Scene(hub, Aerodynamics(2.0, 3.5, axial_force=0.3, centre_of_pressure=(1.5, 0.0, 0.0)))
    vacuum = Scene(hub)
    rng = np.random.default_rng(3)
    q0, r0 = _quat(rng), np.array([6.4e6, 1.0e5, 3.0e5])
    A = dq(q0)
    x = dict(q=q0, w=A @ Om, r=r0, v=A @ np.cross(Om, r0))
    np.testing.assert_allclose(np.ravel(air.model().rhs(air.state(**x))),
                               np.ravel(vacuum.model().rhs(vacuum.state(**x))),
                               rtol=1e-12, atol=1e-15)
    # moving through that air at 10 m/s along body x: drag opposes the motion
    x["v"] = x["v"] + np.array([10.0, 0.0, 0.0])
    d = np.ravel(air.model().rhs(air.state(**x)) - vacuum.model().rhs(vacuum.state(**x)))
    assert d[-3] < 0.0
