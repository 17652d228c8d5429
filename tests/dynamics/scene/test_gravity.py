"""GravityGradient against closed forms: pitch libration about the local-vertical
local-horizontal frame (nonlinear pendulum and its small-angle frequency), the torque as a
direct sum over point masses, and the conservation laws of each formulation."""
import casadi as ca
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from appdyn.dynamics import simulate
from appdyn.dynamics.attitude import dcm_axis, dcm_from_quat, quat_from_dcm
from appdyn.dynamics.scene import GravityGradient, HingedPanel, RigidHub, Scene

MU, RADIUS = 3.986004418e14, 7.0e6
N = np.sqrt(MU / RADIUS**3)
IX, IY, IZ = 100.0, 80.0, 40.0
#: inertial -> local-vertical local-horizontal at t = 0 (orbit starting on inertial x,
#: counter-clockwise about +z): rows along track (y), against the orbit normal (-z), nadir (-x)
LVLH0 = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, -1.0], [-1.0, 0.0, 0.0]])


def lvlh(t):
    return LVLH0 @ dcm_axis(3, N * t)


def pitch_scene(six_dof):
    I = [IX, IY, IZ]
    if six_dof:
        return Scene(RigidHub(I, mass=500.0), GravityGradient(MU))
    return Scene(RigidHub(I), GravityGradient(MU, RADIUS))


def pitch_start(scene, theta0):
    A = dcm_axis(2, theta0) @ LVLH0
    blocks = dict(q=quat_from_dcm(A), w=[0.0, -N, 0.0])
    if scene.hub.translates:  # on the circular orbit: r = R x, inertial velocity n R y
        blocks.update(r=[RADIUS, 0.0, 0.0], v=A @ [0.0, N * RADIUS, 0.0])
    return scene.state(**blocks)


def pitch_of(model, x, t):
    """Pitch angle from the local-vertical local-horizontal frame, and the off-pitch part."""
    C = dcm_from_quat(x[:4]) @ lvlh(t).T  # = A2(theta)
    return np.arctan2(C[2, 0], C[0, 0]), np.linalg.norm(C[1] - [0.0, 1.0, 0.0])


@pytest.mark.parametrize("six_dof", [False, True])
def test_pitch_libration_is_the_gravity_gradient_pendulum(six_dof):
    """``I_y theta'' = -3/2 n^2 (I_x - I_z) sin 2 theta`` at 0.5 rad; at 1e-4 rad the
    closed form ``theta0 cos(n sqrt(3 (I_x - I_z) / I_y) t)`` (to 1e-7 of the amplitude: the
    nonlinear frequency shift, theta0^2 / 4, moves the phase by 4e-8 over 2.5 periods)."""
    scene = pitch_scene(six_dof)
    model = scene.model()
    omega = N * np.sqrt(3 * (IX - IZ) / IY)
    t = np.linspace(0.0, 2.5 * 2 * np.pi / omega, 61)
    pendulum = solve_ivp(lambda _, y: [y[1], -1.5 * N**2 * (IX - IZ) / IY * np.sin(2 * y[0])],
                         (t[0], t[-1]), [0.5, 0.0], t_eval=t, rtol=1e-13, atol=1e-14)
    atol = np.full(model.nx, 1e-12)
    if six_dof:  # position to a millimetre, velocity to a micrometre per second (of 7 Mm, 7.5 km/s)
        atol[model.layout["hub"].states][7:] = [1e-3] * 3 + [1e-6] * 3
    cases = ((0.5, pendulum.y[0], 1e-8), (1e-4, 1e-4 * np.cos(omega * t), 1e-11))
    for theta0, reference, tol in cases:
        res = simulate(model, pitch_start(scene, theta0), t, rtol=1e-10, atol=atol, jit=False)
        assert res.success
        clock = res.x[-1] if not six_dof else t
        pitch, off = np.array([pitch_of(model, res.x[:, k], clock[k]) for k in range(t.size)]).T
        assert np.max(np.abs(pitch - reference)) < tol, np.max(np.abs(pitch - reference))
        assert np.max(off) < 1e-9


def point_cloud(I, scale):
    """Six point masses (pairs on the principal axes) with inertia ``I`` about their centre."""
    lam, V = np.linalg.eigh(I)
    mass = 1.0
    half = (np.trace(I) / 2 - lam) / 2  # 2 m a_j^2 = tr I / 2 - lam_j, per pair
    points = [s * np.sqrt(h / mass) * V[:, j] for j, h in enumerate(half) for s in (1, -1)]
    cloud = np.array(points) * scale
    return cloud, mass / scale**2


def test_torque_is_the_sum_over_point_masses():
    I = np.array([[100.0, 4.0, -3.0], [4.0, 80.0, 2.0], [-3.0, 2.0, 40.0]])
    scene = Scene(RigidHub(I), GravityGradient(MU, RADIUS))
    model = scene.model()
    cloud, m = point_cloud(I, 1.0)
    Icloud = sum(m * (p @ p * np.eye(3) - np.outer(p, p)) for p in cloud)
    np.testing.assert_allclose(Icloud, I, rtol=1e-13)
    rng = np.random.default_rng(5)
    for _ in range(5):
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        t = rng.uniform(0.0, 6000.0)
        A = dcm_from_quat(q)
        centre = A @ (RADIUS * np.array([np.cos(N * t), np.sin(N * t), 0.0]))  # hub axes
        direct = sum(np.cross(p, -MU * m * (centre + p) / np.linalg.norm(centre + p) ** 3)
                     for p in cloud)
        x = scene.state(q=q, t=t)
        torque = I @ model.rhs(x)[4:7]  # w = 0
        # the pairs cancel the odd orders: relative error (size / R)^2 ~ 1e-13
        np.testing.assert_allclose(torque, direct, rtol=0, atol=1e-9 * np.max(np.abs(direct)))


def rate_of(model, expr):
    """``(d e / dt, sum_i |de/dx_i xdot_i|)`` along the model's rhs for ``e = expr(x)`` (the
    second is the size of the terms that cancel), as a Function of ``x``."""
    x = ca.SX.sym("x", model.nx)
    terms = ca.jacobian(expr(x), x).T * model.f(x, [], [])
    return ca.Function("rate", [x], [ca.sum1(terms), ca.sum1(ca.fabs(terms))])


PANEL = HingedPanel(20.0, [3.0, 1.0, 3.5], hinge_point=[0.0, 1.2, 0.1], cm_offset=[0.1, 1.5, 0.0],
                    axis=[1.0, 0.0, 0.0], stiffness=2.0)
BALL = HingedPanel(10.0, [1.0, 0.8, 1.5], hinge_point=[0.5, 0.0, -1.0], cm_offset=[0.0, 0.3, -0.8],
                   stiffness=1.0)


def random_state(scene, rng, translates):
    q = rng.normal(size=4)
    blocks = dict(q=q / np.linalg.norm(q), w=rng.normal(scale=0.01, size=3),
                  panel=[rng.uniform(-1, 1), rng.normal(scale=0.01)])
    p = rng.normal(size=4)
    blocks["panel_2"] = np.r_[p / np.linalg.norm(p), rng.normal(scale=0.01, size=3)]
    if translates:
        blocks.update(r=RADIUS * rng.normal(size=3) / np.sqrt(3), v=7.5e3 * rng.normal(size=3) / 3)
    else:
        blocks["t"] = rng.uniform(0.0, 6000.0)
    return scene.state(**blocks)


def test_six_dof_gravity_conserves_energy_and_momentum_about_the_centre():
    """Point-mass gravity with the second-order force: exact conservation, rhs level."""
    I = np.array([[100.0, 4.0, -3.0], [4.0, 80.0, 2.0], [-3.0, 2.0, 40.0]])
    scene = Scene(RigidHub(I, mass=500.0, reference=[0.2, -0.1, 0.3]), PANEL, BALL,
                  GravityGradient(MU))
    model = scene.model()
    rng = np.random.default_rng(11)
    for key in ("energy", "momentum_inertial"):
        for i in range(1 if key == "energy" else 3):
            rate = rate_of(model, lambda x: model.invariants[key](x, [])[i])
            for _ in range(5):
                total, size = (float(v) for v in rate(random_state(scene, rng, True)))
                assert abs(total) < 1e-13 * size, (key, i, total, size)


def test_attitude_only_gravity_keeps_the_jacobi_integral():
    """The field turns uniformly at n about inertial z: ``E - n H_z`` is constant (tidal
    forces on the panels' mass centres and torques on every body), rhs level."""
    I = np.array([[100.0, 4.0, -3.0], [4.0, 80.0, 2.0], [-3.0, 2.0, 40.0]])
    scene = Scene(RigidHub(I), PANEL, BALL, GravityGradient(MU, RADIUS))
    model = scene.model()
    jacobi = rate_of(model, lambda x: model.invariants["energy"](x, [])
                     - N * model.invariants["momentum_inertial"](x, [])[2])
    energy = rate_of(model, lambda x: model.invariants["energy"](x, []))
    rng = np.random.default_rng(13)
    for _ in range(5):
        x = random_state(scene, rng, False)
        total, size = (float(v) for v in jacobi(x))
        assert abs(total) < 1e-13 * size, (total, size)
        total, size = (float(v) for v in energy(x))
        assert abs(total) > 1e-10 * size  # the energy alone is not kept (3e-7 of the terms)


def test_gravity_refuses_a_radius_it_cannot_use():
    with pytest.raises(ValueError, match="`radius` applies to an attitude-only hub"):
        Scene(RigidHub([1.0, 1.0, 1.0], mass=1.0), GravityGradient(MU, RADIUS)).model()
    with pytest.raises(ValueError, match="needs `radius`"):
        Scene(RigidHub([1.0, 1.0, 1.0]), GravityGradient(MU)).model()
    with pytest.raises(ValueError, match="mu"):
        GravityGradient(-1.0)


@pytest.mark.parametrize("six_dof", [False, True])
def test_loads_on_a_body_are_the_sums_over_its_point_masses(six_dof):
    """One body (six point masses, 10 m from the hub's centre): the force on its mass centre
    and the torque about it equal the sums of the point masses' exact gravity (attitude-only
    hub: less the hub centre's own acceleration, the tidal force)."""
    from appdyn.dynamics.scene import Body, Frame
    I = np.array([[3.0, 0.2, -0.1], [0.2, 2.0, 0.3], [-0.1, 0.3, 4.0]])
    cloud, m = point_cloud(I, 1.0)
    mass = m * len(cloud)
    rng = np.random.default_rng(29)
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    A = dcm_from_quat(q)
    t = 1234.0
    rho = np.array([6.0, -5.0, 6.0])  # the body's mass centre from the hub's centre, hub axes
    if six_dof:
        gravity, r = GravityGradient(MU), np.array([3.0e6, -5.0e6, 4.0e6])
    else:
        gravity = GravityGradient(MU, RADIUS)
        r = RADIUS * np.array([np.cos(N * t), np.sin(N * t), 0.0])
    frame = Frame(q=ca.DM(q), dcm=ca.DM(A), w=ca.DM.zeros(3), v=ca.DM.zeros(3),
                  r=ca.DM(r) if six_dof else None, reference=(0.0, 0.0, 0.0),
                  mass=1.0 if six_dof else None)
    speeds = ca.SX.sym("nu", 6)  # the body's velocity and angular velocity, to tell the loads apart
    body = Body.rigid(mass, I, ca.DM(rho), speeds[:3], speeds[3:])

    class Own:
        coords = ca.DM([t])

    loads = gravity.field_loads(frame, [body], Own()).loads
    generalized = sum(ca.mtimes(ca.jacobian(ld.velocity, speeds).T, ld.vector) for ld in loads)
    generalized = np.asarray(ca.DM(ca.evalf(generalized))).ravel()
    centre = A @ r  # the hub's centre from the central body, hub axes
    pull = lambda R: -MU * R / np.linalg.norm(R) ** 3  # noqa: E731
    forces = [m * (pull(centre + rho + p) - (0.0 if six_dof else pull(centre))) for p in cloud]
    force, torque = sum(forces), sum(np.cross(p, f) for p, f in zip(cloud, forces))
    # tidal: the expansion's error |rho| / R = 1.4e-6 (measured 1.9e-6 and 1.4e-6); point
    # mass: exact force (5e-16), torque to the round-off of the cancelling sum (7e-10)
    tol_force, tol_torque = (1e-13, 1e-8) if six_dof else (5e-6, 5e-6)
    np.testing.assert_allclose(generalized[:3], force, rtol=0,
                               atol=tol_force * np.linalg.norm(force))
    np.testing.assert_allclose(generalized[3:], torque, rtol=0,
                               atol=tol_torque * np.linalg.norm(torque))


def test_gravity_gradient_sees_the_wheels_axial_inertia():
    """Hub (inertia without the wheels' axial moments) and wheels at rest: the rate of the
    total angular momentum is the torque on the whole inertia ``I_hub + sum J a a^T``."""
    from appdyn.dynamics.scene import ReactionWheels
    I_hub, J = np.diag([100.0, 80.0, 40.0]), np.array([2.0, 3.0, 4.0])
    axes = np.array([[1.0, 0.0, 0.0], [0.0, 0.6, 0.8], [0.0, -0.8, 0.6]]).T
    scene = Scene(RigidHub(I_hub), ReactionWheels(axes, J), GravityGradient(MU, RADIUS))
    model = scene.model()
    q = np.array([0.3, -0.5, 0.2, 0.0])
    q[3] = np.sqrt(1 - q @ q)
    t = 800.0
    x = scene.state(q=q, t=t)
    xs = ca.SX.sym("x", model.nx)
    H = model.invariants["momentum_inertial"](xs, [])
    rate = ca.Function("r", [xs], [ca.mtimes(ca.jacobian(H, xs), model.f(xs, [], []))])
    rate = np.asarray(rate(x)).ravel()
    A = dcm_from_quat(q)
    o = A @ -np.array([np.cos(N * t), np.sin(N * t), 0.0])
    whole = I_hub + sum(Ji * np.outer(a, a) for Ji, a in zip(J, axes.T))
    expected = A.T @ (3 * N**2 * np.cross(o, whole @ o))
    np.testing.assert_allclose(rate, expected, rtol=0, atol=1e-13 * np.linalg.norm(expected))
