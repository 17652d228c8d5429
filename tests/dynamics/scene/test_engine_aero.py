"""`Aerodynamics` and `Engine` on the six-degree-of-freedom hub, against independent truths:
Newton-Euler with the Type II angles (`attitude.total_aoa`), the linear airframe poles
(`dynamics.launch_vehicle` docstring), jet damping and the internal-flow Coriolis force of seed
Eqs. 3.47-3.49, the control-volume law (no ``m' v`` term), energy and momentum balances with
the mass flow on, and the yaw-plane launch vehicle (`dynamics.launch_vehicle`) on random
planar states."""
import casadi as ca
import numpy as np
import pytest

from appdyn.dynamics.launch_vehicle import Actuator, Aero, MassFlow, launch_vehicle
from appdyn.dynamics.attitude import dcm_from_quat, total_aoa
from appdyn.dynamics.scene import Aerodynamics, Engine, RigidHub, Scene
from appdyn.dynamics.scene.engine import G0

I_HUB = np.diag([40.0, 300.0, 320.0])
MASS = 150.0


def _rel(a, b, tol=1e-12):
    a, b = np.asarray(a, float), np.asarray(b, float)
    scale = max(float(np.max(np.abs(b))), 1.0)
    assert float(np.max(np.abs(a - b))) <= tol * scale, (a, b)


def _random_state(scene, rng, v_axial=200.0):
    x = scene.state()
    q = rng.normal(size=4)
    x[0:4] = q / np.linalg.norm(q)
    x[4:7] = rng.normal(scale=0.3, size=3)
    x[7:10] = rng.normal(scale=10.0, size=3)
    x[10:13] = [v_axial, 0.0, 0.0] + rng.normal(scale=15.0, size=3)
    return x


def _aero_force(v_air, rho, S, cna, ca_):
    """Type II form: X = -qbar S C_A, N = -qbar S C_Na alpha_T (0, sin phi_R, cos phi_R)."""
    aT, phi = total_aoa(v_air)
    qS = 0.5 * rho * float(v_air @ v_air) * S
    return np.array([-qS * ca_, -qS * cna * aT * np.sin(phi), -qS * cna * aT * np.cos(phi)])


def _newton_euler(x, force, torque, mass=MASS, inertia=I_HUB):
    w, v = x[4:7], x[10:13]
    w_dot = np.linalg.solve(inertia, torque - np.cross(w, inertia @ w))
    v_dot = force / mass - np.cross(w, v)
    return w_dot, v_dot


# ------------------------------------------------------------------------------ aerodynamics
CP = np.array([1.5, 0.1, -0.2])
AERO = dict(area=0.8, normal_force_slope=2.7, axial_force=0.3, centre_of_pressure=CP)


def test_aero_force_is_the_type_two_normal_and_axial_force():
    scene = Scene(RigidHub(I_HUB, mass=MASS), Aerodynamics(**AERO, density=0.9))
    model = scene.model()
    rng = np.random.default_rng(1)
    for _ in range(20):
        x = _random_state(scene, rng)
        w, v = x[4:7], x[10:13]
        v_cp = v + np.cross(w, CP)
        F = _aero_force(v_cp, 0.9, 0.8, 2.7, 0.3)
        w_dot, v_dot = _newton_euler(x, F, np.cross(CP, F))
        xdot = model.rhs(x, [])
        _rel(xdot[4:7], w_dot)
        _rel(xdot[10:13], v_dot)


def test_aero_energy_changes_at_the_power_of_the_air_force():
    scene = Scene(RigidHub(I_HUB, mass=MASS, reference=[0.3, 0.0, 0.1]),
                  Aerodynamics(**AERO))
    model = scene.model()
    xs = ca.SX.sym("x", model.nx)
    E = model.invariants["energy"](xs, ca.DM(0, 1))
    power = ca.Function("P", [xs], [ca.mtimes(ca.jacobian(E, xs), model.f(xs, ca.DM(0, 1),
                                                                            ca.DM(0, 1)))])
    rng = np.random.default_rng(2)
    for _ in range(10):
        x = _random_state(scene, rng)
        w, v = x[4:7], x[10:13]
        v_cp = v + np.cross(w, CP - [0.3, 0.0, 0.1])
        F = _aero_force(v_cp, 1.225, 0.8, 2.7, 0.3)
        _rel(float(power(x)), F @ v_cp)


def test_linear_airframe_poles_in_pitch_and_yaw():
    """Straight flight at V along x: m (v' + w x v) = N, I w' = l_cp x N with the normal force
    of the centre of pressure's crossflow (v_y + l w3, v_z - l w2) give per plane
    s^2 + ((b + c l) / V) s - c = 0, b = qbar S C_Na / m, c = qbar S C_Na l / I (the planar
    model's s^2 + (b/V) s - c without the rotational crossflow, the aerodynamic damping)."""
    V, rho, S, cna, l = 250.0, 0.7, 0.8, 2.7, 1.5
    scene = Scene(RigidHub(I_HUB, mass=MASS),
                  Aerodynamics(S, cna, centre_of_pressure=(l, 0.0, 0.0), density=rho))
    model = scene.model()
    x0 = scene.state(v=[V, 0.0, 0.0])
    xs = ca.SX.sym("x", model.nx)
    J = np.array(ca.Function("J", [xs], [ca.jacobian(model.f(xs, ca.DM(0, 1), ca.DM(0, 1)),
                                                      xs)])(x0))
    poles = np.linalg.eigvals(J)
    qS = 0.5 * rho * V ** 2 * S
    b = qS * cna / MASS
    for inertia in (I_HUB[1, 1], I_HUB[2, 2]):
        c = qS * cna * l / inertia
        for root in np.roots([1.0, (b + c * l) / V, -c]):
            assert np.min(np.abs(poles - root)) < 1e-9 * abs(root), (root, poles)


def test_wind_controls_shift_the_air_velocity():
    scene = Scene(RigidHub(I_HUB, mass=MASS), Aerodynamics(**AERO, wind="control"))
    still = Scene(RigidHub(I_HUB, mass=MASS), Aerodynamics(**AERO))
    assert scene.model().controls == ("wind1", "wind2", "wind3")
    rng = np.random.default_rng(3)
    for _ in range(10):
        x = _random_state(scene, rng)
        x[4:7] = 0.0  # no rotation: the air velocity is v - A wind at every point
        wind = rng.normal(scale=20.0, size=3)
        y = x.copy()
        y[10:13] = x[10:13] - np.asarray(dcm_from_quat(x[0:4])) @ wind
        _rel(scene.model().rhs(x, wind)[4:7], still.model().rhs(y, [])[4:7])
        _rel(scene.model().rhs(x, wind)[10:13], still.model().rhs(y, [])[10:13])


def test_exponential_atmosphere_is_the_constant_density_at_the_altitude():
    H, rho0 = 7200.0, 1.2
    rng = np.random.default_rng(4)
    up = np.array([0.0, 0.6, 0.8])
    air = Scene(RigidHub(I_HUB, mass=MASS), Aerodynamics(**AERO, density=rho0, scale_height=H,
                                                         up=up))
    for _ in range(5):
        x = _random_state(air, rng)
        x[7:10] = rng.normal(scale=5000.0, size=3)
        flat = Scene(RigidHub(I_HUB, mass=MASS),
                     Aerodynamics(**AERO, density=rho0 * np.exp(-(up @ x[7:10]) / H)))
        _rel(air.model().rhs(x, []), flat.model().rhs(x, []))


def test_aero_needs_a_translating_hub_and_checks_its_arguments():
    with pytest.raises(ValueError, match="six-degree-of-freedom hub"):
        Scene(RigidHub(I_HUB), Aerodynamics(1.0, 2.0)).model()
    with pytest.raises(ValueError, match="area"):
        Aerodynamics(0.0, 2.0)
    with pytest.raises(ValueError, match="normal_force_slope"):
        Aerodynamics(1.0, -2.0)
    with pytest.raises(ValueError, match="centre_of_pressure"):
        Aerodynamics(1.0, 2.0, centre_of_pressure=(1.0, 2.0))
    with pytest.raises(ValueError, match="wind"):
        Aerodynamics(1.0, 2.0, wind="gust")
    with pytest.raises(ValueError, match="up"):
        Aerodynamics(1.0, 2.0, up=(0.0, 0.0, 0.0))


def test_aero_derivatives_are_finite_and_exact_at_zero_crossflow():
    scene = Scene(RigidHub(I_HUB, mass=MASS), Aerodynamics(**AERO))
    model = scene.model()
    xs = ca.SX.sym("x", model.nx)
    jac = ca.Function("J", [xs], [ca.jacobian(model.f(xs, ca.DM(0, 1), ca.DM(0, 1)), xs)])
    x = scene.state(v=[-50.0, 0.0, 0.0])  # backwards: alpha_T = pi, no normal direction
    assert np.all(np.isfinite(np.array(jac(x)))) and np.all(np.isfinite(model.rhs(x, [])))
    for v in ([120.0, 0.0, 0.0], [120.0, 1e-9, 0.0], [120.0, 0.0, 0.05], [120.0, 30.0, -20.0]):
        x = scene.state(v=v)
        J = np.array(jac(x))
        assert np.all(np.isfinite(J))
        h = 1e-4
        fd = np.column_stack([(model.rhs(x + h * e, []) - model.rhs(x - h * e, [])) / (2 * h)
                              for e in np.eye(model.nx)])
        np.testing.assert_allclose(J, fd, rtol=1e-6, atol=1e-8)


# ------------------------------------------------------------------------------------ engine
def _jet_scene(l1, l2, mdot=4.0, thrust=3000.0, propellant=30.0):
    return Scene(RigidHub(I_HUB, mass=MASS),
                 Engine(thrust, (-l2, 0.0, 0.0), mass_flow=mdot, propellant=propellant,
                        flow_start=(-l1, 0.0, 0.0)))


@pytest.mark.parametrize("l1, l2", [(1.0, 3.0), (0.0, 2.5), (-2.0, 2.0), (2.0, 2.0)])
@pytest.mark.parametrize("axis", [1, 2])
def test_jet_damping_and_coriolis_force_of_the_seed(l1, l2, axis):
    """Seed Eq. 3.49: I w' = -mdot w (l2^2 - l1^2); Eq. 3.47: m R'' = -2 mdot w x (r_B - r_A)."""
    mdot, thrust, mp, omega = 4.0, 3000.0, 30.0, 0.4
    scene = _jet_scene(l1, l2, mdot, thrust, mp)
    w = np.zeros(3)
    w[axis] = omega
    xdot = scene.model().rhs(scene.state(w=w), [])
    m = MASS + mp
    expected_w = np.zeros(3)
    expected_w[axis] = -mdot * omega * (l2 ** 2 - l1 ** 2) / I_HUB[axis, axis]
    _rel(xdot[4:7], expected_w)
    F_C = -2 * mdot * np.cross(w, [-(l2 - l1), 0.0, 0.0])
    _rel(xdot[10:13], (np.array([thrust, 0.0, 0.0]) + F_C) / m)
    assert xdot[13] == -mdot


def test_control_volume_law_has_no_mdot_v_term():
    """Moving at v without rotation the burning vehicle accelerates at F/m: the momentum the
    leaving mass carries is in the thrust, not a -m' v force (the frozen mass coordinate)."""
    scene = _jet_scene(1.0, 3.0)
    for v in ([0.0, 0.0, 0.0], [300.0, -40.0, 25.0]):
        xdot = scene.model().rhs(scene.state(v=v), [])
        _rel(xdot[10:13], [3000.0 / (MASS + 30.0), 0.0, 0.0], 1e-14)


REF = np.array([0.2, -0.1, 0.05])
TANK = np.array([0.8, 0.1, -0.05])
GIMBAL = np.array([-3.0, 0.05, 0.0])
EXIT = np.array([-3.6, 0.05, 0.0])
START = np.array([0.5, 0.0, 0.0])


def _burning(actuator=None, gimbal=0.1):
    return Scene(RigidHub(I_HUB, mass=MASS, reference=REF),
                 Engine(2500.0, GIMBAL, gimbal=gimbal, isp=250.0, propellant=40.0, tank=TANK,
                        flow_start=START, nozzle_exit=EXIT, actuator=actuator))


def _thrust_direction(dp, dy):
    return np.array([np.cos(dp) * np.cos(dy), -np.cos(dp) * np.sin(dy), np.sin(dp)])


def test_energy_and_momentum_balance_with_the_engine_burning():
    """T' = F d . v_g + F_C . v_M - mdot |v_tank|^2 / 2 and P' = A^T (F d + F_C - mdot v_tank)
    (the momentum the propellant takes with it), at random states and deflections."""
    scene = _burning()
    model = scene.model()
    mdot = 2500.0 / (250.0 * G0)
    xs, us = ca.SX.sym("x", model.nx), ca.SX.sym("u", model.nu)
    f = model.f(xs, us, ca.DM(0, 1))
    rates = {k: ca.Function(k, [xs, us], [ca.mtimes(ca.jacobian(
        model.invariants[k](xs, ca.DM(0, 1)), xs), f)]) for k in ("energy", "momentum_linear")}
    rng = np.random.default_rng(5)
    for _ in range(10):
        x = _random_state(scene, rng)
        x[13] = rng.uniform(5.0, 40.0)
        u = rng.uniform(-0.1, 0.1, size=2)
        w, v = x[4:7], x[10:13]
        A = np.asarray(dcm_from_quat(x[0:4]))

        def vel(p):
            return v + np.cross(w, p - REF)
        F_T = 2500.0 * _thrust_direction(*u)
        F_C = -2 * mdot * np.cross(w, EXIT - START)
        v_t = vel(TANK)
        power = F_T @ vel(GIMBAL) + F_C @ vel(0.5 * (START + EXIT)) - 0.5 * mdot * v_t @ v_t
        _rel(float(rates["energy"](x, u)), power, 1e-11)
        _rel(np.asarray(rates["momentum_linear"](x, u)).ravel(), A.T @ (F_T + F_C - mdot * v_t), 1e-11)


def test_engine_without_mass_flow_is_a_force_at_the_gimbal():
    scene = Scene(RigidHub(I_HUB, mass=MASS), Engine(1000.0, GIMBAL, gimbal=0.2))
    model = scene.model()
    assert model.states[13:] == () and model.controls == ("dp", "dy")
    assert model.bounds["dp"] == (-0.2, 0.2)
    rng = np.random.default_rng(6)
    for _ in range(5):
        x = _random_state(scene, rng)
        u = rng.uniform(-0.2, 0.2, size=2)
        F = 1000.0 * _thrust_direction(*u)
        w_dot, v_dot = _newton_euler(x, F, np.cross(GIMBAL, F))
        xdot = model.rhs(x, u)
        _rel(xdot[4:7], w_dot)
        _rel(xdot[10:13], v_dot)


def test_actuator_states_follow_the_commands():
    act = Actuator(0.05, deflection_limits=(-0.08, 0.08), rate_limit=0.5)
    scene = _burning(actuator=act)
    model = scene.model()
    assert model.states[13:] == ("dp", "dy", "m_p") and model.controls == ("dp_c", "dy_c")
    x = scene.state(dp=0.01, dy=-0.02)
    xdot = model.rhs(x, [0.012, 0.5])
    # (0.012 - 0.01) / 0.05 = 0.04; (min(0.5, 0.08) + 0.02) / 0.05 = 2 -> rate limit 0.5
    _rel(xdot[13:15], [0.04, 0.5], 1e-14)
    _rel(xdot[15], -2500.0 / (250.0 * G0), 1e-14)


def test_engine_arguments():
    with pytest.raises(ValueError, match="thrust"):
        Engine(-1.0, (0.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="mass_flow"):
        Engine(1.0, (0.0, 0.0, 0.0), mass_flow=1.0, isp=200.0, propellant=1.0)
    with pytest.raises(ValueError, match="propellant"):
        Engine(1.0, (0.0, 0.0, 0.0), isp=200.0)
    with pytest.raises(ValueError, match="gimbal"):
        Engine(1.0, (0.0, 0.0, 0.0), actuator=Actuator(0.1))
    with pytest.raises(TypeError, match="actuator"):
        Engine(1.0, (0.0, 0.0, 0.0), gimbal=0.1, actuator=0.1)
    with pytest.raises(ValueError, match="position"):
        Engine(1.0, (0.0, 0.0))
    with pytest.raises(ValueError, match="axis"):
        Engine(1.0, (0.0, 0.0, 0.0), axis=(0.0, 0.0, 0.0))


# -------------------------------------------------------------- the yaw-plane launch vehicle
def _planar_state(rng, mass=None):
    s = rng.normal(size=6) * [50.0, 50.0, 0.3, 30.0, 30.0, 0.2]
    s[3] += 300.0
    return s


def _scene_state(scene, s, extra=()):
    x, y, psi, xd, yd, psid = s
    q = [0.0, 0.0, np.sin(psi / 2), np.cos(psi / 2)]
    A = np.asarray(dcm_from_quat(q))
    return np.concatenate([q, [0.0, 0.0, psid], [x, y, 0.0], A @ [xd, yd, 0.0], extra])


def _planar_rates(model, x, u):
    """The scene's rhs as the yaw-plane derivatives (x, y, psi, x', y', psi')'."""
    xdot = model.rhs(x, u)
    A = np.asarray(dcm_from_quat(x[0:4]))
    acc = A.T @ (xdot[10:13] + np.cross(x[4:7], x[10:13]))
    return np.concatenate([xdot[7:9], [x[6]], acc[:2], [xdot[6]]]), xdot


@pytest.mark.parametrize("actuator", [None, Actuator(0.05, deflection_limits=(-0.1, 0.1),
                                                         rate_limit=0.4)])
def test_yaw_plane_restriction_equals_the_launch_vehicle_with_mass_flow(actuator):
    F, I, l, m, l1, rate = 2.0e6, 4.0e7, 20.0, 1.0e5, -5.0, 700.0
    planar = launch_vehicle(thrust=F, inertia=I, arm=l, mass=m, actuator=actuator,
                               mass_flow=MassFlow(rate=rate, flow_start=l1))
    mp = 3.0e4  # the propellant at the mass centre: I(m) = I at m = mass, as the planar model
    scene = Scene(RigidHub([1.0e6, I, I], mass=m - mp),
                  Engine(F, (-l, 0.0, 0.0), gimbal=0.2, mass_flow=rate, propellant=mp,
                         flow_start=(-l1, 0.0, 0.0), actuator=actuator))
    model = scene.model()
    rng = np.random.default_rng(8)
    for _ in range(10):
        s = _planar_state(rng)
        delta = rng.uniform(-0.1, 0.1)
        if actuator is None:
            x, u = _scene_state(scene, s, [mp]), [0.0, delta]
            px, pu = np.concatenate([s, [m]]), [delta]
        else:
            cmd = rng.uniform(-0.15, 0.15)
            x, u = _scene_state(scene, s, [0.0, delta, mp]), [0.0, cmd]
            px, pu = np.concatenate([s, [m, delta]]), [cmd]
        rates, xdot = _planar_rates(model, x, u)
        ref = planar.rhs(px, pu)
        _rel(rates, ref[:6])
        _rel(xdot[-1], ref[6])  # mass rate
        if actuator is not None:
            _rel(xdot[-2], ref[7])  # the yaw deflection's rate
            assert xdot[-3] == 0.0  # pitch deflection at rest with a zero command


@pytest.mark.parametrize("air_velocity", ["mass_centre", "centre_of_pressure"])
def test_yaw_plane_restriction_equals_the_launch_vehicle_with_aero(air_velocity):
    """Aero of the planar model: alpha of the mass centre's air velocity at a fixed dynamic
    pressure (the density here gives it at each state). With the centre of pressure's air
    velocity (the 3-D default) the states do not turn (psi' = 0): it adds the rotational
    crossflow psi' l_cp, which the planar model leaves out."""
    F, I, l, m = 2.0e6, 4.0e7, 20.0, 1.0e5
    qbar, S, cna, lcp = 3.0e4, 10.0, 3.0, 5.0
    planar = launch_vehicle(thrust=F, inertia=I, arm=l, mass=m,
                            aero=Aero(qbar, S, cna, lcp, wind="control"))
    rng = np.random.default_rng(9)
    for _ in range(10):
        s = _planar_state(rng)
        if air_velocity == "centre_of_pressure":
            s[5] = 0.0
        wind = rng.normal(scale=20.0, size=2)
        v_air = s[3:5] - wind
        scene = Scene(RigidHub([1.0e6, I, I], mass=m), Engine(F, (-l, 0.0, 0.0), gimbal=0.2),
                      Aerodynamics(S, cna, centre_of_pressure=(lcp, 0.0, 0.0),
                                   density=2 * qbar / float(v_air @ v_air), wind="control",
                                   air_velocity=air_velocity))
        delta = rng.uniform(-0.1, 0.1)
        rates, _ = _planar_rates(scene.model(), _scene_state(scene, s),
                                 [0.0, delta, wind[0], wind[1], 0.0])
        _rel(rates, planar.rhs(s, [delta, *wind]))


def test_launch_vehicle_scene_yaw_plane_equals_the_planar_model():
    """The builder: thrust, aero (wind controls), mass flow and actuator together, random
    planar states at the reference mass (the dynamic pressure at the flight speed)."""
    from appdyn.dynamics.scene import launch_vehicle_scene
    F, I, l, m, V = 2.0e6, 4.0e7, 20.0, 1.0e5, 400.0
    parts = dict(aero=Aero(3.0e4, 10.0, 3.0, 5.0, wind="control"),
                 mass_flow=MassFlow(rate=700.0, flow_start=-5.0, nozzle_exit=22.0),
                 actuator=Actuator(0.05, rate_limit=0.3))
    planar = launch_vehicle(thrust=F, inertia=I, arm=l, mass=m, **parts)
    scene = launch_vehicle_scene(thrust=F, inertia=I, arm=l, mass=m, velocity=V, **parts)
    model = scene.model()
    assert model.controls == ("dp_c", "dy_c", "wind1", "wind2", "wind3")
    mp = scene.state()[-1]
    rng = np.random.default_rng(10)
    for _ in range(10):
        s = _planar_state(rng)
        wind = rng.normal(size=2)
        gamma = 0.05 * rng.normal()  # air speed V: the planar dynamic pressure
        s[3:5] = wind + V * np.array([np.cos(gamma), np.sin(gamma)])
        delta, cmd = rng.uniform(-0.1, 0.1, size=2)
        rates, xdot = _planar_rates(model, _scene_state(scene, s, [0.0, delta, mp]),
                                    [0.0, cmd, wind[0], wind[1], 0.0])
        ref = planar.rhs(np.concatenate([s, [m, delta]]), [cmd, *wind])
        _rel(rates, ref[:6])
        _rel(xdot[-2:][::-1], ref[6:8])


@pytest.mark.parametrize("with_flow", [False, True])
def test_launch_vehicle_scene_with_slosh_yaw_plane_equals_the_planar_model(with_flow):
    """A slosh pendulum: the planar states are the vehicle's mass centre, the scene's the
    point O of the rigid hub; the mass centre's velocity and acceleration are read from the
    scene's linear momentum (P / m, and (P' + mdot v_tank) / m: P' loses the momentum the
    propellant takes with it), theta_s = -theta1."""
    from appdyn.dynamics.launch_vehicle import Slosh as PlanarSlosh
    from appdyn.dynamics.scene import launch_vehicle_scene
    F, I, l, m = 2.0e6, 4.0e7, 20.0, 1.0e5
    sl = PlanarSlosh(mass=8.0e3, hinge=6.0, length=2.5, damping_ratio=0.03)
    parts = dict(slosh=sl, actuator=Actuator(0.05))
    if with_flow:
        parts["mass_flow"] = MassFlow(rate=700.0, flow_start=-5.0)
    planar = launch_vehicle(thrust=F, inertia=I, arm=l, mass=m, **parts)
    scene = launch_vehicle_scene(thrust=F, inertia=I, arm=l, mass=m, **parts)
    model = scene.model()
    n = model.nx
    xs, us = ca.SX.sym("x", n), ca.SX.sym("u", model.nu)
    P = model.invariants["momentum_linear"](xs, ca.DM(0, 1))
    Pdot = ca.Function("Pd", [xs, us], [P, ca.mtimes(ca.jacobian(P, xs),
                                                      model.f(xs, us, ca.DM(0, 1)))])
    ms, L, h = sl.mass, sl.length, sl.hinge
    rng = np.random.default_rng(11)
    idx = {s: model.states.index(s) for s in model.states}
    for _ in range(10):
        s = _planar_state(rng)
        th, thd = rng.normal(scale=0.2), rng.normal(scale=0.3)
        delta, cmd = rng.uniform(-0.1, 0.1, size=2)
        psi, psid = s[2], s[5]
        # the mass centre's shift from O and its rate (body axes): Delta = ms/m (rho_s - rho0)
        e, e_t = np.array([-np.cos(th), -np.sin(th), 0.0]), np.array([np.sin(th), -np.cos(th), 0.0])
        Delta = ms / m * L * (e - [-1.0, 0.0, 0.0])
        Delta_dot = ms / m * L * e_t * thd
        w = np.array([0.0, 0.0, psid])
        x = scene.state()
        x[0:4] = [0.0, 0.0, np.sin(psi / 2), np.cos(psi / 2)]
        A = np.asarray(dcm_from_quat(x[0:4]))
        x[6] = psid
        x[idx["r1"]:idx["r3"] + 1] = np.array([s[0], s[1], 0.0]) - A.T @ Delta
        v_cm = A @ np.array([s[3], s[4], 0.0])
        x[idx["v1"]:idx["v3"] + 1] = v_cm - np.cross(w, Delta) - Delta_dot
        x[idx["theta1"]], x[idx["theta1_dot"]] = -th, -thd
        x[idx["dy"]] = delta
        u = [0.0, cmd]
        p_in, p_dot = (np.asarray(v).ravel() for v in Pdot(x, u))
        xdot = model.rhs(x, u)
        mass_state = [m] if with_flow else []
        ref = planar.rhs(np.concatenate([s, mass_state, [th, thd, delta]]), [cmd])
        if with_flow:  # the propellant leaves from the rigid part's mass centre
            v_O = x[idx["v1"]:idx["v3"] + 1]
            p_dot = p_dot + 700.0 * A.T @ (v_O + np.cross(w, -np.asarray(scene.hub.reference)))
        mine = np.concatenate([p_in[:2] / m, [psid], p_dot[:2] / m, [xdot[6]]])
        _rel(mine, ref[:6])
        k = 6
        if with_flow:
            _rel(xdot[idx["m_p"]], ref[6])
            k = 7
        _rel([-xdot[idx["theta1"]], -xdot[idx["theta1_dot"]], xdot[idx["dy"]]], ref[k:k + 3])
        assert abs(xdot[idx["theta2_dot"]]) < 1e-12 and xdot[idx["dp"]] == 0.0


@pytest.mark.slow
def test_flown_by_the_autopilot_equals_the_planar_closed_loop():
    """Slosh and actuator, the autopilot closed on both axes, a yaw error and rate at t = 0:
    the scene stays in the yaw plane and its yaw angle, the slosh angle and the deflection
    follow the planar model with the same gains (both rk8, same steps)."""
    from appdyn.dynamics import closed_loop, simulate
    from appdyn.dynamics.launch_vehicle import Slosh as PlanarSlosh
    from appdyn.dynamics.scene import attitude_autopilot, launch_vehicle_scene
    F, I, l, m = 2.0e6, 4.0e7, 20.0, 1.0e5
    parts = dict(slosh=PlanarSlosh(mass=8.0e3, hinge=6.0, length=2.5, damping_ratio=0.05),
                 actuator=Actuator(0.05, deflection_limits=(-0.08, 0.08), rate_limit=0.3))
    planar = launch_vehicle(thrust=F, inertia=I, arm=l, mass=m, k_psi=2.0, k_psidot=1.5,
                            **parts)
    scene = launch_vehicle_scene(thrust=F, inertia=I, arm=l, mass=m, **parts)
    loop = closed_loop(scene.model(), attitude_autopilot(scene, k_psi=2.0, k_psidot=1.5))
    psi0, psid0 = 0.12, -0.05
    x0 = scene.state(q=[0.0, 0.0, np.sin(psi0 / 2), np.cos(psi0 / 2)], w=[0.0, 0.0, psid0],
                     v=[300.0 * np.cos(psi0), -300.0 * np.sin(psi0), 0.0])
    # O moves with the rigid part; slosh at rest: the mass centre is O (Delta = 0)
    p0 = np.zeros(planar.nx)
    p0[[2, 3, 5]] = psi0, 300.0, psid0
    t = np.linspace(0.0, 4.0, 9)
    mine = simulate(loop, x0, t, method="rk8", steps=400)
    ref = simulate(planar, p0, t, method="rk8", steps=400)
    assert mine.success and ref.success
    X = np.asarray(mine.x)
    idx = {s: i for i, s in enumerate(loop.states)}
    psi = 2 * np.arctan2(X[idx["q3"]], X[idx["q4"]])
    R = np.asarray(ref.x)
    pidx = {s: i for i, s in enumerate(planar.states)}
    np.testing.assert_allclose(psi, R[pidx["psi"]], rtol=0, atol=1e-10)
    np.testing.assert_allclose(-X[idx["theta1"]], R[pidx["theta_s"]], rtol=0, atol=1e-10)
    np.testing.assert_allclose(X[idx["dy"]], R[pidx["delta"]], rtol=0, atol=1e-10)
    assert np.max(np.abs(X[[idx["q1"], idx["q2"], idx["theta2"], idx["dp"]]])) < 1e-13
    assert abs(psi[-1]) < 0.3 * psi0  # the autopilot brings the yaw error down


def test_energy_work_balance_with_motors_engine_and_air():
    """Wheels driven by their motors, the engine burning and the air on one scene:
    E' = sum tau_i W_i + F d . v_g + F_C . v_M - mdot |v_tank|^2 / 2 + F_air . v_cp."""
    from appdyn.dynamics.scene import ReactionWheels
    scene = Scene(RigidHub(I_HUB, mass=MASS, reference=REF),
                  ReactionWheels(np.eye(3), [0.05, 0.04, 0.06]),
                  Engine(2500.0, GIMBAL, gimbal=0.1, isp=250.0, propellant=40.0, tank=TANK,
                         flow_start=START, nozzle_exit=EXIT),
                  Aerodynamics(**AERO))
    model = scene.model()
    assert model.controls == ("tau1", "tau2", "tau3", "dp", "dy")
    mdot = 2500.0 / (250.0 * G0)
    xs, us = ca.SX.sym("x", model.nx), ca.SX.sym("u", model.nu)
    E = model.invariants["energy"](xs, ca.DM(0, 1))
    Edot = ca.Function("Ed", [xs, us], [ca.mtimes(ca.jacobian(E, xs),
                                                   model.f(xs, us, ca.DM(0, 1)))])
    rng = np.random.default_rng(12)
    for _ in range(10):
        x = _random_state(scene, rng)
        x[13:16] = rng.normal(scale=20.0, size=3)  # wheel speeds
        x[16] = rng.uniform(5.0, 40.0)
        u = np.concatenate([rng.normal(scale=0.2, size=3), rng.uniform(-0.1, 0.1, size=2)])
        w, v = x[4:7], x[10:13]

        def vel(p):
            return v + np.cross(w, p - REF)
        F_T = 2500.0 * _thrust_direction(*u[3:])
        F_C = -2 * mdot * np.cross(w, EXIT - START)
        v_t, v_cp = vel(TANK), vel(CP)
        power = (u[:3] @ x[13:16] + F_T @ vel(GIMBAL) + F_C @ vel(0.5 * (START + EXIT))
                 - 0.5 * mdot * v_t @ v_t + _aero_force(v_cp, 1.225, 0.8, 2.7, 0.3) @ v_cp)
        _rel(float(Edot(x, u)), power, 1e-11)
