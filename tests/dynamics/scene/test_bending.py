"""`BendingMode` and the launch vehicle with its body bending mode, against independent
truths: mean axes (Kane's sum is ``M_b eta''`` and the hub's motion does not see the mode),
the yaw-plane model `dynamics.launch_vehicle(..., bending=...)` on random planar states (with
aero, mass flow, actuator, and with slosh), its closed loop flown by the planar autopilot, the
planar stability case `problems.stability.launch_vehicle(..., bending=...)`, and the energy-
work balance with the thrust on the mode."""
import casadi as ca
import numpy as np
import pytest

from appdyn.dynamics.attitude import dcm_from_quat
from appdyn.dynamics.launch_vehicle import Actuator, Aero, Bending, MassFlow, launch_vehicle
from appdyn.dynamics.launch_vehicle import Slosh as PlanarSlosh
from appdyn.dynamics.scene import (BendingMode, Engine, RigidHub, Scene, attitude_autopilot,
                                   launch_vehicle_scene, sensed_attitude)

from .test_engine_aero import _planar_rates, _planar_state, _rel

F, I, L, M = 2.0e6, 4.0e7, 20.0, 1.0e5
BEND = Bending(frequency=12.0, generalized_mass=5.0e3, damping_ratio=0.02, slope_sensor=0.03,
               deflection_gimbal=1.4, slope_gimbal=-0.05)
I_HUB = np.array([[10.0, 1.2, -0.8], [1.2, 12.0, 0.6], [-0.8, 0.6, 8.0]])


def _random_hub_state(scene, rng):
    x = scene.state()
    q = rng.normal(size=4)
    x[0:4] = q / np.linalg.norm(q)
    x[4:] = rng.normal(size=x.size - 4)
    return x


# ------------------------------------------------------------------------------ mean axes
def test_mean_axes_the_mode_is_uncoupled_from_the_hub():
    """Hub alone and hub + mode: the same hub accelerations whatever the mode does; the mode
    obeys M_b (eta'' + 2 zeta w eta' + w^2 eta) = 0 (no load on it): Kane's sum is M_b eta''."""
    Mb, w, z = 3.0, 4.0, 0.1
    hub = RigidHub(I_HUB, mass=7.0, reference=(0.1, -0.2, 0.3))
    alone = Scene(hub).model()
    scene = Scene(hub, BendingMode(Mb, w, damping_ratio=z, station=(-1.0, 0.2, 0.0),
                                   deflection=0.7, slope=0.3, sensor_slope=0.2))
    model = scene.model()
    rng = np.random.default_rng(1)
    for _ in range(10):
        x = _random_hub_state(scene, rng)
        xdot = model.rhs(x, [])
        _rel(xdot[:13], alone.rhs(x[:13], []), 1e-13)
        eta, eta_d = x[13:15], x[15:17]
        _rel(xdot[13:15], eta_d, 1e-15)
        _rel(xdot[15:17], -w ** 2 * eta - 2 * z * w * eta_d, 1e-13)
        E = float(model.invariants["energy"](x, []))
        T_hub = float(alone.invariants["energy"](x[:13], []))
        _rel(E, T_hub + 0.5 * Mb * (eta_d @ eta_d) + 0.5 * Mb * w ** 2 * (eta @ eta), 1e-13)
        for key in ("momentum_inertial", "momentum_linear"):
            _rel(model.invariants[key](x, []), alone.invariants[key](x[:13], []), 1e-13)


def test_a_force_on_the_mode_excites_it_through_its_partial_velocity():
    """A thrust F on the section: eta_i'' M_b = F . (phi_g d_i + sigma_g n_i x 0) (the point
    is the section's origin), and the hub feels F at the displaced point, turned by the
    slope (Newton-Euler with the deflected thrust)."""
    Mb, w, phi, sig = 3.0, 4.0, 0.7, 0.3
    hub = RigidHub(I_HUB, mass=7.0)
    station = np.array([-1.0, 0.2, 0.1])
    scene = Scene(hub, BendingMode(Mb, w, station=tuple(station), deflection=phi, slope=sig),
                  Engine(5.0, (0.0, 0.0, 0.0), parent="bending"))
    model = scene.model()
    rng = np.random.default_rng(2)
    for _ in range(10):
        x = _random_hub_state(scene, rng)
        x[13:15] *= 0.3
        xdot = model.rhs(x, [])
        e1, e2 = x[13:15]
        # direction: x turned sig e1 about z, then sig e2 about -y (in that order)
        Rz = np.array([[np.cos(sig * e1), -np.sin(sig * e1), 0], [np.sin(sig * e1),
                       np.cos(sig * e1), 0], [0, 0, 1]])
        a = -sig * e2
        Ry = np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])
        force = 5.0 * Rz @ Ry @ [1.0, 0.0, 0.0]
        point = station + phi * np.array([0.0, e1, e2])
        _rel(xdot[15:17], (force[1:] * phi - Mb * w ** 2 * x[13:15]) / Mb, 1e-13)
        wv = x[4:7]
        w_dot = np.linalg.solve(I_HUB, np.cross(point, force) - np.cross(wv, I_HUB @ wv))
        _rel(xdot[4:7], w_dot, 1e-12)
        _rel(xdot[10:13], force / 7.0 - np.cross(wv, x[10:13]), 1e-12)


def test_bending_mode_arguments():
    with pytest.raises(ValueError, match="generalized_mass"):
        BendingMode(0.0, 1.0)
    with pytest.raises(ValueError, match="damping_ratio"):
        BendingMode(1.0, 1.0, damping_ratio=-0.1)
    with pytest.raises(ValueError, match="directions"):
        BendingMode(1.0, 1.0, directions=((1.0, 0.0, 0.0),))
    with pytest.raises(ValueError, match="directions"):
        BendingMode(1.0, 1.0, directions=((0.0, 1.0, 0.0), (0.0, 0.6, 0.8)))
    with pytest.raises(ValueError, match="directions"):
        BendingMode(1.0, 1.0, directions="y")
    with pytest.raises(TypeError, match="bending"):
        launch_vehicle_scene(thrust=F, inertia=I, arm=L, mass=M, bending=1.0)
    one = Scene(RigidHub(I_HUB, mass=1.0), BendingMode(1.0, 1.0, directions=(0.0, 0.0, 1.0)))
    assert one.model().states[13:] == ("eta", "eta_dot")


# -------------------------------------------------------------- the yaw-plane launch vehicle
def _set(model, x, **values):
    for k, v in values.items():
        x[model.states.index(k)] = v
    return x


def _scene_x(scene, s, **parts):
    """The scene state of the planar rigid state ``s`` (mass centre = O) and named parts."""
    x = scene.state()
    psi = s[2]
    q = [0.0, 0.0, np.sin(psi / 2), np.cos(psi / 2)]
    A = np.asarray(dcm_from_quat(q))
    x[0:4], x[6] = q, s[5]
    model = scene.model()
    _set(model, x, r1=s[0], r2=s[1])
    x[model.states.index("v1"):model.states.index("v3") + 1] = A @ [s[3], s[4], 0.0]
    return _set(model, x, **parts)


@pytest.mark.parametrize("with_flow", [False, True])
def test_yaw_plane_restriction_equals_the_planar_model_with_bending(with_flow):
    """Thrust on the mode, aero (wind controls), actuator, (mass flow): random planar
    states with the yaw-plane mode, the pitch-plane mode at rest (it stays there)."""
    V = 400.0
    parts = dict(aero=Aero(3.0e4, 10.0, 3.0, 5.0, wind="control"), bending=BEND,
                 actuator=Actuator(0.05, rate_limit=0.3))
    if with_flow:
        parts["mass_flow"] = MassFlow(rate=700.0, flow_start=-5.0, nozzle_exit=22.0)
    planar = launch_vehicle(thrust=F, inertia=I, arm=L, mass=M, **parts)
    scene = launch_vehicle_scene(thrust=F, inertia=I, arm=L, mass=M, velocity=V, **parts)
    model = scene.model()
    pidx = {n: i for i, n in enumerate(planar.states)}
    rng = np.random.default_rng(20)
    for _ in range(10):
        s = _planar_state(rng)
        wind = rng.normal(size=2)
        gamma = 0.05 * rng.normal()
        s[3:5] = wind + V * np.array([np.cos(gamma), np.sin(gamma)])
        delta, cmd = rng.uniform(-0.1, 0.1, size=2)
        eta, eta_d = rng.normal(scale=0.2), rng.normal(scale=0.5)
        x = _scene_x(scene, s, dy=delta, eta1=eta, eta1_dot=eta_d)
        rates, xdot = _planar_rates(model, x, [0.0, cmd, wind[0], wind[1], 0.0])
        px = np.concatenate([s, [M] if with_flow else [], [eta, eta_d, delta]])
        ref = planar.rhs(px, [cmd, *wind])
        _rel(rates, ref[:6])
        mine = {n: xdot[model.states.index(n)] for n in ("eta1", "eta1_dot", "dy")}
        _rel([mine["eta1"], mine["eta1_dot"], mine["dy"]],
             ref[[pidx["eta"], pidx["eta_dot"], pidx["delta"]]])
        if with_flow:
            _rel(xdot[model.states.index("m_p")], ref[pidx["mass"]])
        for n in ("eta2", "eta2_dot", "dp", "w1", "w2"):
            assert abs(xdot[model.states.index(n)]) < 1e-12 * max(1.0, abs(ref).max())


def test_yaw_plane_restriction_with_slosh_and_bending():
    """Slosh pendulum, actuator, mass flow and the mode together: the planar mass centre is
    read from the scene's linear momentum (as test_engine_aero's slosh case), theta_s =
    -theta1, the mode and the deflection as they are."""
    sl = PlanarSlosh(mass=8.0e3, hinge=6.0, length=2.5, damping_ratio=0.03)
    rate = 700.0
    parts = dict(slosh=sl, actuator=Actuator(0.05), bending=BEND,
                 mass_flow=MassFlow(rate=rate, flow_start=-5.0))
    planar = launch_vehicle(thrust=F, inertia=I, arm=L, mass=M, **parts)
    scene = launch_vehicle_scene(thrust=F, inertia=I, arm=L, mass=M, **parts)
    model = scene.model()
    xs, us = ca.SX.sym("x", model.nx), ca.SX.sym("u", model.nu)
    P = model.invariants["momentum_linear"](xs, ca.DM(0, 1))
    Pdot = ca.Function("Pd", [xs, us], [P, ca.mtimes(ca.jacobian(P, xs),
                                                      model.f(xs, us, ca.DM(0, 1)))])
    ms, Ls = sl.mass, sl.length
    idx = {n: i for i, n in enumerate(model.states)}
    pidx = {n: i for i, n in enumerate(planar.states)}
    rng = np.random.default_rng(21)
    for _ in range(10):
        s = _planar_state(rng)
        th, thd = rng.normal(scale=0.2), rng.normal(scale=0.3)
        eta, eta_d = rng.normal(scale=0.2), rng.normal(scale=0.5)
        delta, cmd = rng.uniform(-0.1, 0.1, size=2)
        psi, psid = s[2], s[5]
        e, e_t = np.array([-np.cos(th), -np.sin(th), 0.0]), np.array([np.sin(th), -np.cos(th),
                                                                      0.0])
        Delta = ms / M * Ls * (e - [-1.0, 0.0, 0.0])
        Delta_dot = ms / M * Ls * e_t * thd
        w = np.array([0.0, 0.0, psid])
        x = _scene_x(scene, s, theta1=-th, theta1_dot=-thd, dy=delta, eta1=eta,
                     eta1_dot=eta_d)
        A = np.asarray(dcm_from_quat(x[0:4]))
        x[idx["r1"]:idx["r3"] + 1] = np.array([s[0], s[1], 0.0]) - A.T @ Delta
        v_cm = A @ np.array([s[3], s[4], 0.0])
        x[idx["v1"]:idx["v3"] + 1] = v_cm - np.cross(w, Delta) - Delta_dot
        u = [0.0, cmd]
        p_in, p_dot = (v.full().ravel() for v in Pdot(x, u))
        xdot = model.rhs(x, u)
        ref = planar.rhs(np.concatenate([s, [M, th, thd, eta, eta_d, delta]]), [cmd])
        v_O = x[idx["v1"]:idx["v3"] + 1]
        p_dot = p_dot + rate * A.T @ (v_O + np.cross(w, -np.asarray(scene.hub.reference)))
        _rel(np.concatenate([p_in[:2] / M, [psid], p_dot[:2] / M, [xdot[6]]]), ref[:6])
        _rel(xdot[idx["m_p"]], ref[pidx["mass"]])
        _rel([-xdot[idx["theta1"]], -xdot[idx["theta1_dot"]], xdot[idx["eta1"]],
              xdot[idx["eta1_dot"]], xdot[idx["dy"]]],
             ref[[pidx["theta_s"], pidx["theta_s_dot"], pidx["eta"], pidx["eta_dot"],
                  pidx["delta"]]])
        assert abs(xdot[idx["theta2_dot"]]) < 1e-12 and abs(xdot[idx["eta2_dot"]]) < 1e-12


def test_sensed_attitude_is_the_planar_gyro_reading():
    """The yaw plane's psi + sigma_s eta and psi' + sigma_s eta' (the planar invariants), and
    in pitch the same law turned a quarter about the axis (eta2 towards z: -sigma_s eta2
    about y)."""
    planar = launch_vehicle(thrust=F, inertia=I, arm=L, mass=M, bending=BEND)
    scene = launch_vehicle_scene(thrust=F, inertia=I, arm=L, mass=M, bending=BEND)
    sensed = sensed_attitude(scene)
    rng = np.random.default_rng(22)
    for _ in range(5):
        s = _planar_state(rng)
        eta, eta_d, e2, e2d = rng.normal(size=4)
        x = _scene_x(scene, s, eta1=eta, eta1_dot=eta_d, eta2=e2, eta2_dot=e2d)
        px = np.concatenate([s, [eta, eta_d]])
        got = sensed(x).full().ravel()
        _rel(got[[1, 3]], [float(planar.invariants[k](px, [])) for k in ("psi_sensed",
                                                                          "psi_dot_sensed")])
        _rel(got[[0, 2]], [-BEND.slope_sensor * e2, -BEND.slope_sensor * e2d], 1e-15)


@pytest.mark.slow
def test_flown_by_the_autopilot_equals_the_planar_closed_loop():
    """Slosh, actuator and the mode, the autopilot on the gyros on both axes, a yaw error,
    rate and bending at t = 0: yaw angle, slosh, mode and deflection follow the planar closed
    loop (both rk8, same steps); the pitch plane stays at rest."""
    from appdyn.dynamics import closed_loop, simulate
    parts = dict(slosh=PlanarSlosh(mass=8.0e3, hinge=6.0, length=2.5, damping_ratio=0.05),
                 actuator=Actuator(0.05, deflection_limits=(-0.08, 0.08), rate_limit=0.3),
                 bending=BEND)
    planar = launch_vehicle(thrust=F, inertia=I, arm=L, mass=M, k_psi=2.0, k_psidot=1.5,
                            **parts)
    scene = launch_vehicle_scene(thrust=F, inertia=I, arm=L, mass=M, **parts)
    loop = closed_loop(scene.model(), attitude_autopilot(scene, k_psi=2.0, k_psidot=1.5))
    psi0, psid0, eta0, etad0 = 0.12, -0.05, 0.3, -0.5
    x0 = scene.state(q=[0.0, 0.0, np.sin(psi0 / 2), np.cos(psi0 / 2)], w=[0.0, 0.0, psid0],
                     v=[300.0 * np.cos(psi0), -300.0 * np.sin(psi0), 0.0])
    _set(loop, x0, eta1=eta0, eta1_dot=etad0)
    pidx = {s: i for i, s in enumerate(planar.states)}
    p0 = np.zeros(planar.nx)
    p0[[2, 3, 5, pidx["eta"], pidx["eta_dot"]]] = psi0, 300.0, psid0, eta0, etad0
    t = np.linspace(0.0, 4.0, 9)
    mine = simulate(loop, x0, t, method="rk8", steps=800)
    ref = simulate(planar, p0, t, method="rk8", steps=800)
    assert mine.success and ref.success
    X, R = np.asarray(mine.x), np.asarray(ref.x)
    idx = {s: i for i, s in enumerate(loop.states)}
    psi = 2 * np.arctan2(X[idx["q3"]], X[idx["q4"]])
    np.testing.assert_allclose(psi, R[pidx["psi"]], rtol=0, atol=1e-10)
    for mine_k, ref_k, sign in (("theta1", "theta_s", -1), ("dy", "delta", 1),
                                ("eta1", "eta", 1), ("eta1_dot", "eta_dot", 1)):
        np.testing.assert_allclose(sign * X[idx[mine_k]], R[pidx[ref_k]], rtol=0, atol=1e-10)
    rest = [idx[n] for n in ("q1", "q2", "theta2", "dp", "eta2", "eta2_dot")]
    assert np.max(np.abs(X[rest])) < 1e-13
    assert abs(psi[-1]) < 0.5 * psi0


# the stability report (pitch and yaw loops) equals the planar case's:
# tests/problems/stability/test_vehicle_loops.py, its CASES "bending*"


# ------------------------------------------------------------------ energy and work
def test_energy_work_balance_with_the_thrust_on_the_mode():
    """Undamped mode, engine on the section: E' = F d . v_section (the thrust's power at the
    moving, turning section), and E' = 0 with the thrust off."""
    Mb, w, phi, sig = 3.0, 4.0, 0.7, 0.3
    station = np.array([-1.0, 0.2, 0.1])
    for thrust in (0.0, 5.0):
        scene = Scene(RigidHub(I_HUB, mass=7.0, reference=(0.1, 0.0, -0.2)),
                      BendingMode(Mb, w, station=tuple(station), deflection=phi, slope=sig),
                      Engine(thrust, (0.0, 0.0, 0.0), gimbal=0.2, parent="bending"))
        model = scene.model()
        grad = model.invariants["energy"].jacobian()
        rng = np.random.default_rng(23)
        for _ in range(5):
            x = _random_hub_state(scene, rng)
            u = rng.uniform(-0.2, 0.2, size=2)
            dE = float(grad(x, [], 0)[0].full().ravel() @ model.rhs(x, u))
            e, ed = x[13:15], x[15:17]
            n1, n2 = np.array([0.0, 0.0, 1.0]), np.array([0.0, -1.0, 0.0])
            Rz = np.asarray(ca.DM(_rot(n1, sig * e[0])))
            Ry = np.asarray(ca.DM(_rot(n2, sig * e[1])))
            dp, dy = u
            d = Rz @ Ry @ [np.cos(dp) * np.cos(dy), -np.cos(dp) * np.sin(dy), np.sin(dp)]
            point = station - [0.1, 0.0, -0.2] + phi * np.array([0.0, e[0], e[1]])
            v_pt = x[10:13] + np.cross(x[4:7], point) + phi * np.array([0.0, ed[0], ed[1]])
            power = thrust * float(d @ v_pt)
            assert abs(dE - power) <= 1e-11 * max(1.0, abs(power)), (dE, power)


def _rot(n, angle):
    from appdyn.dynamics.scene.bending import axis_rotation
    return axis_rotation(tuple(n), angle)
