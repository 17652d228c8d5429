"""The thrust-vectored launch vehicle against Eqs. 5.53-5.54 and 3.49 written out here, the
closed-loop oscillator, Newton-Euler for the vehicle and its slosh mass, and closed-form poles
derived by hand (slosh, bending, aerodynamics, actuator)."""
import pickle

import numpy as np
import pytest

from appdyn.dynamics import launch_vehicle, linearization, simulate
from appdyn.dynamics.launch_vehicle import Actuator, Aero, Bending, MassFlow, Slosh

F, I, L, M = 2.0e6, 4.0e7, 20.0, 1.0e5  # thrust [N], inertia [kg m^2], arm [m], mass [kg]
RIGID = dict(thrust=F, inertia=I, arm=L, mass=M)
EPS = np.finfo(float).eps
PENDULUM = Slosh(mass=3000.0, hinge=6.0, length=2.5, damping_ratio=0.02)
SPRING = Slosh(mass=3000.0, hinge=-4.0, frequency=3.0, damping_ratio=0.02)
AERO = Aero(dynamic_pressure=3.0e4, area=10.0, normal_force_slope=3.0, cp_arm=6.0)
BENDING = Bending(frequency=12.0, generalized_mass=5000.0, damping_ratio=0.01,
                  slope_sensor=0.02, deflection_gimbal=1.2, slope_gimbal=0.03)


def rhs(model, x, u=(), p=None):
    return model.rhs(np.asarray(x, float), np.asarray(u, float), p)


def eq_5_54(x, delta, m=M, inertia=I):
    """Eqs. 5.53-5.54 through Lagrange: m x'' = F cos(psi - delta), m y'' = F sin(psi - delta),
    I psi'' = F l sin(delta)."""
    psi = x[2]
    return np.array([x[3], x[4], x[5], F * np.cos(psi - delta) / m, F * np.sin(psi - delta) / m,
                     F * L * np.sin(delta) / inertia])


def block(lin, rows, cols=None):
    idx = [lin.index(s) for s in rows]
    cidx = idx if cols is None else [lin.index(s) for s in cols]
    return lin.A[np.ix_(idx, cidx)]


def others(lin, rows, cols):
    """A[rows, every column not in cols]: zero when ``rows`` form a closed subsystem."""
    rest = [s for s in lin.states if s not in cols]
    return block(lin, rows, rest)


# ---------------------------------------------------------------------------- rigid vehicle
def test_rigid_right_hand_side_is_eq_5_54_at_random_states():
    model = launch_vehicle(**RIGID)
    assert model.states == ("x", "y", "psi", "x_dot", "y_dot", "psi_dot")
    assert model.controls == ("delta",) and model.params == ()
    rng = np.random.default_rng(1)
    for _ in range(50):
        x = np.concatenate([rng.normal(0, 1e3, 2), rng.uniform(-np.pi, np.pi, 1),
                            rng.normal(0, 300, 2), rng.normal(0, 0.5, 1)])
        delta = rng.uniform(-0.6, 0.6)
        scale = np.array([1, 1, 1, F / M, F / M, F * L / I]) * np.abs(x).max(initial=1.0)
        err = np.abs(rhs(model, x, [delta]) - eq_5_54(x, delta))
        assert np.all(err <= 4 * EPS * scale)


def test_metadata_units_cache_and_pickle():
    full = launch_vehicle(**RIGID, k_psi=1.0, k_psidot=0.4, aero=AERO, slosh=PENDULUM,
                          mass_flow=MassFlow(rate=700.0), bending=BENDING,
                          actuator=Actuator(0.05, (-0.1, 0.1), 0.5))
    assert full.states == ("x", "y", "psi", "x_dot", "y_dot", "psi_dot", "mass", "theta_s",
                           "theta_s_dot", "eta", "eta_dot", "delta")
    assert full.controls == () and full.params == ("wind_x", "wind_y")
    assert set(full.units) == set(full.states + full.params)
    assert full.units["theta_s"] == "rad" and full.units["eta"] == "m"
    assert set(full.invariants) == {"mass", "psi_sensed", "psi_dot_sensed", "delta_command",
                                    "alpha"}
    spring = launch_vehicle(**RIGID, slosh=SPRING, actuator=Actuator(0.05),
                            aero=Aero(3.0e4, 10.0, 3.0, 6.0, wind="control"))
    assert spring.states[6:] == ("r_s", "r_s_dot", "delta")
    assert spring.controls == ("delta_command", "wind_x", "wind_y") and spring.params == ()
    assert set(spring.units) == set(spring.states + spring.controls)
    assert "alpha" not in spring.invariants  # it needs the wind controls
    again = launch_vehicle(thrust=int(F), inertia=I, arm=L, mass=M, slosh=SPRING,
                           actuator=Actuator(0.05), aero=Aero(3.0e4, 10, 3, 6, wind="control"))
    assert again is spring
    loaded = pickle.loads(pickle.dumps(full))
    x = np.r_[0, 0, 0.1, 300, 5, 0.02, 9.0e4, 0.1, -0.2, 0.01, 0.1, 0.02]
    assert np.array_equal(loaded.rhs(x, [], [3.0, -4.0]), full.rhs(x, [], [3.0, -4.0]))
    assert loaded.invariants.keys() == full.invariants.keys()


# ------------------------------------------------------------------------------- autopilot
@pytest.mark.parametrize("k_psi, k_psidot", [(2.0, 0.5), (0.7, 1.5)])
def test_closed_loop_psi_mode_frequency_and_damping(k_psi, k_psidot):
    """I psi'' + F l k_psidot psi' + F l k_psi psi = 0 (Sec. 5.4)."""
    model = launch_vehicle(**RIGID, k_psi=k_psi, k_psidot=k_psidot)
    assert model.controls == ()
    lin = linearization(model, np.zeros(6), allow_non_equilibrium=True)
    assert not np.any(others(lin, ["psi", "psi_dot"], ["psi", "psi_dot"]))
    A = block(lin, ["psi", "psi_dot"])
    wn, zeta = np.sqrt(np.linalg.det(A)), -np.trace(A) / (2 * np.sqrt(np.linalg.det(A)))
    assert wn == pytest.approx(np.sqrt(F * L * k_psi / I), rel=1e-10)
    assert zeta == pytest.approx(k_psidot * np.sqrt(F * L) / (2 * np.sqrt(I * k_psi)), rel=1e-10)


def test_closed_loop_simulation_is_the_damped_oscillation():
    k_psi, k_psidot, psi0 = 2.0, 0.5, 1e-7  # sin(delta) = delta to 1e-14 relative
    model = launch_vehicle(**RIGID, k_psi=k_psi, k_psidot=k_psidot)
    t = np.linspace(0.0, 10.0, 101)
    res = simulate(model, [0, 0, psi0, 0, 0, 0], t, method="rk8", steps=10, jit=False)
    wn = np.sqrt(F * L * k_psi / I)
    zeta = k_psidot * np.sqrt(F * L) / (2 * np.sqrt(I * k_psi))
    wd = wn * np.sqrt(1 - zeta ** 2)
    exact = psi0 * np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta * wn / wd * np.sin(wd * t))
    assert res.success
    assert np.max(np.abs(res.x[2] - exact)) < 1e-10 * psi0
    assert np.allclose(model.invariant("delta_command", res.x),
                       -(k_psi * res.x[2] + k_psidot * res.x[5]), rtol=0, atol=1e-22)


def test_autopilot_is_the_rigid_vehicle_with_the_law_as_control():
    rigid, loop = launch_vehicle(**RIGID), launch_vehicle(**RIGID, k_psi=1.3, k_psidot=0.4)
    rng = np.random.default_rng(2)
    for _ in range(20):
        x = rng.normal(size=6)
        assert np.array_equal(rhs(loop, x), rhs(rigid, x, [-(1.3 * x[2] + 0.4 * x[5])]))


# ------------------------------------------------------------------ mass flow, jet damping
@pytest.mark.parametrize("l1, l2", [(0.0, None), (-3.0, None), (4.0, 25.0), (-20.0, 20.0)])
def test_jet_damping_is_eq_3_49_and_the_coriolis_force_eq_3_47(l1, l2):
    rate = 700.0
    model = launch_vehicle(**RIGID, mass_flow=MassFlow(rate, flow_start=l1, nozzle_exit=l2))
    rigid = launch_vehicle(**RIGID)
    exit_ = L if l2 is None else l2
    rng = np.random.default_rng(3)
    for _ in range(10):
        x = rng.normal(size=6) * [10, 10, 1, 100, 100, 0.3]
        delta = rng.uniform(-0.2, 0.2)
        got = rhs(model, np.r_[x, M], [delta])
        ref = rhs(rigid, x, [delta])
        assert got[6] == -rate
        jet = -rate * x[5] * (exit_ ** 2 - l1 ** 2) / I  # Eq. 3.49 over I
        assert got[5] - ref[5] == pytest.approx(jet, rel=1e-9, abs=1e-15)
        # Eq. 3.47: m R'' = -2 w x (integral of mdot dr), the flow running aft from l1 to l2
        e1 = np.array([np.cos(x[2]), np.sin(x[2]), 0.0])
        coriolis = -2 * np.cross([0, 0, x[5]], rate * (-exit_ * e1 + l1 * e1))
        assert got[3:5] - ref[3:5] == pytest.approx(coriolis[:2] / M, rel=1e-9, abs=1e-12)
    if l1 == -exit_:  # the seed's case (c): no jet damping
        assert rhs(model, np.r_[0, 0, 0, 0, 0, 0.3, M], [0.0])[5] == 0.0


def test_mass_flow_thrust_mass_and_inertia_scaling():
    flow = MassFlow(rate=800.0, exhaust_velocity=F / 800.0, burn_time=60.0)
    model = launch_vehicle(**RIGID, mass_flow=flow)
    x = np.r_[0, 0, 0.2, 10, 0, 0, 0.5 * M]
    got = rhs(model, x, [0.1])
    assert got[:6] == pytest.approx(eq_5_54(x, 0.1, m=0.5 * M, inertia=0.5 * I), rel=1e-14)
    res = simulate(model, np.r_[0, 0, 0, 0, 0, 0, M], np.linspace(0, 50, 6), method="rk4",
                   jit=False)
    assert np.allclose(res.x[6], M - 800.0 * res.t, rtol=1e-14)
    assert np.array_equal(model.invariant("mass", res.x), res.x[6])


# --------------------------------------------------------------- parts change what they should
def random_state(rng, extra):
    return np.concatenate([rng.normal(0, 10, 2), rng.uniform(-3, 3, 1), rng.normal(0, 300, 2),
                           rng.normal(0, 0.3, 1), rng.normal(0, 0.3, extra)])


@pytest.mark.parametrize("slosh", [PENDULUM, SPRING])
def test_slosh_leaves_the_mass_centre_equations_unchanged(slosh):
    rigid = launch_vehicle(**RIGID, aero=AERO)
    model = launch_vehicle(**RIGID, aero=AERO, slosh=slosh)
    rng = np.random.default_rng(4)
    for _ in range(20):
        x, u, p = random_state(rng, 2), [rng.uniform(-0.3, 0.3)], rng.normal(0, 20, 2)
        got, ref = rhs(model, x, u, p), rhs(rigid, x[:6], u, p)
        assert np.array_equal(got[:5], ref[:5])
        assert got[6] == x[7]


@pytest.mark.parametrize("kind", ["pendulum", "spring"])
def test_zero_slosh_mass_is_the_rigid_vehicle_plus_slosh_states_that_follow(kind):
    slosh = (Slosh(0.0, 6.0, length=2.5, damping_ratio=0.1) if kind == "pendulum"
             else Slosh(0.0, -4.0, frequency=3.0, damping_ratio=0.1))
    rigid, model = launch_vehicle(**RIGID), launch_vehicle(**RIGID, slosh=slosh)
    rng = np.random.default_rng(5)
    for _ in range(20):
        x, u = random_state(rng, 2), [rng.uniform(-0.3, 0.3)]
        got = rhs(model, x, u)
        assert np.array_equal(got[:6], rhs(rigid, x[:6], u))
        newton_euler_residuals(model, slosh, x, u, got)  # the slosh rows, per unit slosh mass


def test_zero_coupling_bending_leaves_the_rigid_vehicle_and_adds_a_free_mode():
    bending = Bending(frequency=12.0, generalized_mass=5000.0, damping_ratio=0.05,
                      slope_sensor=0.02)
    rigid, model = launch_vehicle(**RIGID), launch_vehicle(**RIGID, bending=bending)
    rng = np.random.default_rng(6)
    x, u = random_state(rng, 2), [0.1]
    got = rhs(model, x, u)
    assert np.array_equal(got[:6], rhs(rigid, x[:6], u))
    assert got[7] == pytest.approx(-144.0 * x[6] - 2 * 0.05 * 12.0 * x[7], rel=1e-15)
    lin = linearization(model, np.zeros(8), [0.0], allow_non_equilibrium=True)
    assert not np.any(others(lin, ["eta", "eta_dot"], ["eta", "eta_dot"]))
    poles = np.linalg.eigvals(block(lin, ["eta", "eta_dot"]))
    exact = -0.6 + 12.0j * np.sqrt(1 - 0.05 ** 2)
    assert poles[np.argmax(poles.imag)] == pytest.approx(exact, rel=1e-12)
    assert model.invariant("psi_sensed", x) == x[2] + 0.02 * x[6]
    assert model.invariant("psi_dot_sensed", x) == x[5] + 0.02 * x[7]


def test_actuator_is_the_rigid_vehicle_driven_by_its_state():
    rigid = launch_vehicle(**RIGID)
    model = launch_vehicle(**RIGID, actuator=Actuator(0.05))
    x = np.r_[1, 2, 0.3, 100, 10, 0.1, 0.04]
    got = rhs(model, x, [0.1])
    assert np.array_equal(got[:6], rhs(rigid, x[:6], [0.04]))
    assert got[6] == pytest.approx((0.1 - 0.04) / 0.05, rel=1e-15)
    lin = linearization(model, np.zeros(7), [0.0], allow_non_equilibrium=True)
    assert lin.A[6, 6] == pytest.approx(-20.0, rel=1e-15)
    assert lin.B[6, 0] == pytest.approx(20.0, rel=1e-15)


def test_actuator_limits_clamp_command_then_rate():
    model = launch_vehicle(**RIGID, actuator=Actuator(0.1, (-0.05, 0.08), rate_limit=0.5))
    x = np.r_[0, 0, 0, 0, 0, 0, 0.07]
    assert rhs(model, x, [1.0])[6] == pytest.approx((0.08 - 0.07) / 0.1, rel=1e-14)  # position
    assert rhs(model, x, [-1.0])[6] == -0.5  # (-0.05 - 0.07)/0.1 = -1.2 clamps to -0.5
    loop = launch_vehicle(**RIGID, k_psi=2.0, k_psidot=0.5,
                          actuator=Actuator(0.1, (-0.05, 0.08), rate_limit=0.5))
    assert loop.controls == ()
    y = np.r_[0, 0, 0.01, 0, 0, 0.02, 0.0]  # command -(0.02 + 0.01) = -0.03 inside the limits
    assert rhs(loop, y)[6] == pytest.approx(-0.3, rel=1e-14)
    res = simulate(loop, np.r_[0, 0, 0.5, 0, 0, 0, 0], np.linspace(0, 2, 21), method="rk4",
                   steps=20, jit=False)
    assert res.x[6].min() >= -0.05 - 1e-15 and res.x[6].max() <= 0.08 + 1e-15


# ------------------------------------------------------------------ slosh: Newton-Euler, poles
def cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


def newton_euler_residuals(model, slosh, x, u, xdot, *, aero=None, flow=None, bending=None,
                           wind=(0.0, 0.0)):
    """Check the model's accelerations against Newton (slosh mass) and Euler (the rest about
    its own centre), with every force written out here from the definitions."""
    s, d = dict(zip(model.states, x)), dict(zip(model.states, xdot))
    xi_name = "theta_s" if slosh.kind == "pendulum" else "r_s"
    psi, psid, xi, xid = s["psi"], s["psi_dot"], s[xi_name], s[xi_name + "_dot"]
    delta = u[0]
    m = s["mass"] if flow else M
    inertia = I * m / M if flow else I
    ms, h, Lp = slosh.mass, slosh.hinge, slosh.length
    mr = m - ms
    if slosh.kind == "pendulum":
        rho = np.array([h - Lp * np.cos(xi), -Lp * np.sin(xi)])
        d_rho, dd_rho = Lp * np.array([np.sin(xi), -np.cos(xi)]), Lp * np.array(
            [np.cos(xi), np.sin(xi)])
    else:
        rho, d_rho, dd_rho = np.array([h, xi]), np.array([0.0, 1.0]), np.zeros(2)
    rho0 = np.array([h - (Lp or 0.0), 0.0])
    rho_r = -ms / mr * rho0
    I_r = inertia - mr * rho_r @ rho_r - ms * rho0 @ rho0  # parallel axes
    C = np.array([[np.cos(psi), -np.sin(psi)], [np.sin(psi), np.cos(psi)]])
    J = np.array([[0.0, -1.0], [1.0, 0.0]])
    # the slosh mass is at R + C w, w = rho - (ms/m)(rho - rho0), R the mass centre
    w, dw, ddw = mr / m * rho + ms / m * rho0, mr / m * d_rho, mr / m * dd_rho
    psidd, xidd = d["psi_dot"], d[xi_name + "_dot"]
    R_dd = np.array([d["x_dot"], d["y_dot"]])
    a_s = (C.T @ R_dd + psidd * J @ w - psid ** 2 * w + 2 * psid * xid * J @ dw
           + ddw * xid ** 2 + dw * xidd)  # body components
    eta = s.get("eta", 0.0)
    sg, pg = (bending.slope_gimbal, bending.deflection_gimbal) if bending else (0.0, 0.0)
    ang = sg * eta - delta
    forces = [(np.array([-L, pg * eta]), F * np.array([np.cos(ang), np.sin(ang)]))]
    couple = 0.0
    if aero:
        v = C.T @ (np.array([s["x_dot"], s["y_dot"]]) - np.asarray(wind))
        alpha = np.arctan2(-v[1], v[0])
        q = aero.dynamic_pressure * aero.area * aero.normal_force_slope
        forces.append((np.array([aero.cp_arm, 0.0]), np.array([0.0, q * alpha])))
    if flow:
        l1, l2 = flow.flow_start, L if flow.nozzle_exit is None else flow.nozzle_exit
        forces.append((np.zeros(2), np.array([0.0, 2 * flow.rate * psid * (l2 - l1)])))
        couple = -flow.rate * psid * (l2 ** 2 - l1 ** 2)
    total = sum(f for _, f in forces)
    assert C.T @ R_dd == pytest.approx(total / m, rel=1e-13, abs=1e-13 * F / m)
    zeta = slosh.damping_ratio
    if slosh.kind == "pendulum":  # hinge torque -c theta', c = 2 zeta ms L^2 sqrt(a/L)
        c_per_mass = 2 * zeta * Lp ** 2 * np.sqrt(F / (m * Lp))
        tangential = a_s @ np.array([np.sin(xi), -np.cos(xi)])
        assert tangential == pytest.approx(-c_per_mass * xid / Lp, rel=1e-11,
                                           abs=1e-11 * F / m)
        reaction = [(np.array([h, 0.0]), -ms * a_s)]  # the rod on the hinge
        couple += ms * c_per_mass * xid
    else:  # the spring and damper along e2; the rail carries the axial force
        ws = slosh.frequency
        assert a_s[1] == pytest.approx(-ws ** 2 * xi - 2 * zeta * ws * xid, rel=1e-11,
                                       abs=1e-11 * F / m)
        reaction = [(rho, -ms * a_s)]
    torques = [cross(p - rho_r, f) for p, f in forces + reaction] + [couple]
    assert I_r * psidd == pytest.approx(sum(torques), rel=1e-11,
                                        abs=1e-11 * max(map(abs, torques)))


@pytest.mark.parametrize("slosh", [PENDULUM, SPRING])
def test_slosh_model_obeys_newton_euler_at_random_states(slosh):
    flow = MassFlow(rate=700.0, flow_start=-3.0)
    model = launch_vehicle(**RIGID, aero=AERO, mass_flow=flow, slosh=slosh, bending=BENDING)
    rng = np.random.default_rng(7)
    for _ in range(30):
        x = np.concatenate([random_state(rng, 0), [rng.uniform(0.6, 1.0) * M],
                            rng.normal(0, 0.5, 2), rng.normal(0, 0.05, 2)])
        wind, u = rng.normal(0, 20, 2), [rng.uniform(-0.3, 0.3)]
        newton_euler_residuals(model, slosh, x, u, rhs(model, x, u, wind), aero=AERO,
                               flow=flow, bending=BENDING, wind=wind)


def slosh_poles(slosh):
    model = launch_vehicle(**RIGID, slosh=slosh)
    lin = linearization(model, np.r_[0, 0, 0, 300.0, 0, 0, 0, 0], [0.0],
                        allow_non_equilibrium=True)
    names = list(model.states[6:])
    rot = ["psi", "psi_dot"] + names
    assert not np.any(others(lin, rot, rot))  # rotation + slosh: a closed subsystem
    assert not np.any(block(lin, ["psi_dot"] + names[1:], ["psi", "psi_dot"]))
    return np.linalg.eigvals(block(lin, names))  # psi, psi' do not act back: these are poles


def test_pendulum_slosh_frequency_closed_form():
    s = Slosh(mass=3000.0, hinge=6.0, length=2.5)
    ms, h, Lp, a = s.mass, s.hinge, s.length, F / M
    mr = M - ms
    rho_r = -ms / mr * (h - Lp)
    I_r = I - mr * rho_r ** 2 - ms * (h - Lp) ** 2
    d = h - rho_r
    w2 = a / Lp * (M / mr + ms * d * (d - Lp) / I_r)
    poles = slosh_poles(s)
    assert np.max(poles.imag) == pytest.approx(np.sqrt(w2), rel=1e-10)
    assert np.max(np.abs(poles.real)) <= 4 * EPS * np.sqrt(w2)
    held = slosh_poles(Slosh(mass=0.0, hinge=6.0, length=2.5, damping_ratio=0.03))
    top = held[np.argmax(held.imag)]
    assert abs(top) == pytest.approx(np.sqrt(a / Lp), rel=1e-10)  # sqrt(a/L), vehicle unaffected
    assert -top.real / abs(top) == pytest.approx(0.03, rel=1e-10)


def test_spring_mass_slosh_frequency_closed_form():
    s = Slosh(mass=3000.0, hinge=-4.0, frequency=3.0)
    ms, h, ws, a = s.mass, s.hinge, s.frequency, F / M
    mr = M - ms
    rho_r = -ms / mr * h
    I_r = I - mr * rho_r ** 2 - ms * h ** 2
    d = h - rho_r
    k = s.stiffness
    w2 = k * M / (ms * mr) + d * (k * d + ms * a) / I_r
    assert np.max(slosh_poles(s).imag) == pytest.approx(np.sqrt(w2), rel=1e-10)
    held = slosh_poles(Slosh(mass=0.0, hinge=-4.0, frequency=3.0))  # the vehicle unaffected
    assert np.max(held.imag) == pytest.approx(np.sqrt(k / ms), rel=1e-10)  # sqrt(k/m_s) = 3


# --------------------------------------------------------------------------------- bending
def test_bending_linear_coupling_matches_the_modal_equations():
    b = BENDING
    model = launch_vehicle(**RIGID, bending=b)
    lin = linearization(model, np.r_[0, 0, 0, 300, 0, 0, 0, 0], [0.0],
                        allow_non_equilibrium=True)
    # I psi'' = F l (delta - sigma_g eta) - F phi_g eta
    # M_b (eta'' + 2 zeta w eta' + w^2 eta) = F phi_g (sigma_g eta - delta)
    # m y'' = F (psi + sigma_g eta - delta)
    A, B, i = lin.A, lin.B[:, 0], lin.index
    w, Mb = b.frequency, b.generalized_mass
    expect = {("psi_dot", "eta"): -F * (L * b.slope_gimbal + b.deflection_gimbal) / I,
              ("eta_dot", "eta"): F * b.deflection_gimbal * b.slope_gimbal / Mb - w ** 2,
              ("eta_dot", "eta_dot"): -2 * b.damping_ratio * w,
              ("y_dot", "eta"): F * b.slope_gimbal / M, ("y_dot", "psi"): F / M}
    for (r, c_), value in expect.items():
        assert A[i(r), i(c_)] == pytest.approx(value, rel=1e-13)
    assert B[i("psi_dot")] == pytest.approx(F * L / I, rel=1e-13)
    assert B[i("eta_dot")] == pytest.approx(-F * b.deflection_gimbal / Mb, rel=1e-13)
    assert B[i("y_dot")] == pytest.approx(-F / M, rel=1e-13)
    loop = launch_vehicle(**RIGID, bending=b, k_psi=2.0, k_psidot=0.5)
    Ac = linearization(loop, np.zeros(8), allow_non_equilibrium=True).A
    gain = np.zeros(8)  # delta = -(k_psi (psi + s_s eta) + k_psidot (psi' + s_s eta'))
    gain[[2, 5, 6, 7]] = [-2.0, -0.5, -2.0 * b.slope_sensor, -0.5 * b.slope_sensor]
    assert Ac == pytest.approx(A + np.outer(B, gain), rel=1e-13, abs=1e-13)


# ------------------------------------------------------------------------------------ aero
def test_aero_attitude_poles_and_lateral_cubic():
    c_ = AERO.dynamic_pressure * AERO.area * AERO.normal_force_slope * AERO.cp_arm / I
    b_ = AERO.dynamic_pressure * AERO.area * AERO.normal_force_slope / M
    V = 300.0
    model = launch_vehicle(**RIGID, aero=AERO)
    lin = linearization(model, np.r_[0, 0, 0, V, 0, 0], [0.0], allow_non_equilibrium=True)
    held = np.linalg.eigvals(block(lin, ["psi", "psi_dot"]))  # flight path held
    assert np.max(held.real) == pytest.approx(np.sqrt(c_), rel=1e-12)
    assert np.max(np.abs(held.imag)) == 0.0
    lat = ["y_dot", "psi", "psi_dot"]
    assert not np.any(others(lin, lat, lat))
    free = np.sort_complex(np.linalg.eigvals(block(lin, lat)))
    cubic = np.sort_complex(np.roots([1.0, b_ / V, -c_, F * c_ / (M * V)]))
    assert free == pytest.approx(cubic, rel=1e-10)
    stable = launch_vehicle(**RIGID, aero=Aero(3.0e4, 10.0, 3.0, -6.0))
    lin = linearization(stable, np.r_[0, 0, 0, V, 0, 0], [0.0], allow_non_equilibrium=True)
    held = np.linalg.eigvals(block(lin, ["psi", "psi_dot"]))
    assert np.max(held.imag) == pytest.approx(np.sqrt(c_), rel=1e-12)
    assert np.max(np.abs(held.real)) <= 4 * EPS * np.sqrt(c_)


def test_aero_angle_of_attack_wind_and_normal_force():
    model = launch_vehicle(**RIGID, aero=AERO)
    gust = launch_vehicle(**RIGID, aero=Aero(3.0e4, 10.0, 3.0, 6.0, wind="control"))
    rigid = launch_vehicle(**RIGID)
    rng = np.random.default_rng(8)
    qsc = AERO.dynamic_pressure * AERO.area * AERO.normal_force_slope
    for _ in range(20):
        x, wind, delta = random_state(rng, 0), rng.normal(0, 30, 2), rng.uniform(-0.2, 0.2)
        gamma = np.arctan2(x[4] - wind[1], x[3] - wind[0])  # air-relative flight path
        alpha = np.angle(np.exp(1j * (x[2] - gamma)))
        assert model.invariant("alpha", x, wind) == pytest.approx(alpha, rel=1e-13, abs=1e-15)
        got = rhs(model, x, [delta], wind)
        ref = rhs(rigid, x, [delta])
        normal = qsc * alpha * np.array([-np.sin(x[2]), np.cos(x[2])])  # along e2
        assert got[3:5] - ref[3:5] == pytest.approx(normal / M, rel=1e-9, abs=1e-12)
        assert got[5] - ref[5] == pytest.approx(qsc * alpha * AERO.cp_arm / I, rel=1e-9,
                                                abs=1e-15)
        assert np.array_equal(rhs(gust, x, [delta, *wind]), got)


def test_gust_input_linear_truth_and_step_gust_simulation():
    """alpha = psi - atan2(y' - wind_y, x' - wind_x): a side gust enters like -y'/V."""
    V = 300.0
    gust = launch_vehicle(**RIGID, k_psi=2.0, k_psidot=0.5,
                          aero=Aero(3.0e4, 10.0, 3.0, -6.0, wind="control"))
    lin = linearization(gust, np.r_[0, 0, 0, V, 0, 0], [0.0, 0.0], allow_non_equilibrium=True)
    qsc = 3.0e4 * 10.0 * 3.0
    assert lin.B[lin.index("psi_dot"), 1] == pytest.approx(qsc * -6.0 / (I * V), rel=1e-12)
    assert lin.B[lin.index("y_dot"), 1] == pytest.approx(qsc / (M * V), rel=1e-12)
    assert not np.any(lin.B[:, 0])  # a head wind does not turn the vehicle at alpha = 0
    steady = launch_vehicle(**RIGID, k_psi=2.0, k_psidot=0.5, aero=Aero(3.0e4, 10.0, 3.0, -6.0))
    t = np.linspace(0.0, 5.0, 11)
    a = simulate(gust, np.r_[0, 0, 0, V, 0, 0], t, u=[0.0, 20.0], method="rk8", steps=10,
                 jit=False)
    b = simulate(steady, np.r_[0, 0, 0, V, 0, 0], t, p=[0.0, 20.0], method="rk8", steps=10,
                 jit=False)
    assert a.success and b.success and np.array_equal(a.x, b.x)
    assert np.all(np.abs(b.x[2]) < np.arctan(20.0 / V))  # the loop holds psi inside the gust angle


# ------------------------------------------------------------------------------ bad inputs
@pytest.mark.parametrize("kwargs, name", [
    (dict(thrust=0.0), "thrust"), (dict(thrust=-1.0), "thrust"), (dict(mass=0.0), "mass"),
    (dict(inertia=-4.0), "inertia"), (dict(arm=0.0), "arm"), (dict(thrust=np.inf), "thrust"),
    (dict(k_psi=1.0), "k_psidot"), (dict(k_psidot=1.0), "k_psi"),
    (dict(k_psi=1.0, k_psidot=np.nan), "k_psidot"),
    (dict(mass_flow=MassFlow(rate=700.0, exhaust_velocity=3000.0)), "mass_flow"),
    (dict(mass_flow=MassFlow(rate=700.0, burn_time=143.0)), "mass_flow"),
    (dict(mass_flow=MassFlow(rate=700.0, flow_start=21.0)), "mass_flow.flow_start"),
    (dict(slosh=Slosh(mass=M, hinge=0.0, length=1.0)), "slosh.mass"),
    (dict(slosh=Slosh(mass=5.0e4, hinge=40.0, length=1.0)), "slosh"),
    (dict(slosh=Slosh(mass=5.0e4, hinge=2.0, length=1.0),
          mass_flow=MassFlow(rate=700.0, burn_time=72.0)), "slosh.mass"),
])
def test_bad_values_raise_value_error_naming_the_argument(kwargs, name):
    with pytest.raises(ValueError, match=f"`{name}"):
        launch_vehicle(**{**RIGID, **kwargs})


@pytest.mark.parametrize("make, name", [
    (lambda: Aero(0.0, 10.0, 3.0, 1.0), "Aero.dynamic_pressure"),
    (lambda: Aero(1.0, 10.0, 3.0, 1.0, wind="gust"), "Aero.wind"),
    (lambda: MassFlow(rate=-1.0), "MassFlow.rate"),
    (lambda: MassFlow(rate=1.0, burn_time=0.0), "MassFlow.burn_time"),
    (lambda: MassFlow(rate=1.0, flow_start=2.0, nozzle_exit=1.0), "MassFlow.nozzle_exit"),
    (lambda: Slosh(mass=-1.0, hinge=0.0, length=1.0), "Slosh.mass"),
    (lambda: Slosh(mass=1.0, hinge=0.0, length=1.0, damping_ratio=-0.1), "Slosh.damping_ratio"),
    (lambda: Slosh(mass=1.0, hinge=0.0), "Slosh"),
    (lambda: Slosh(mass=1.0, hinge=0.0, length=1.0, frequency=2.0), "Slosh"),
    (lambda: Slosh(mass=1.0, hinge=0.0, length=0.0), "Slosh.length"),
    (lambda: Bending(frequency=0.0, generalized_mass=1.0), "Bending.frequency"),
    (lambda: Bending(frequency=1.0, generalized_mass=1.0, damping_ratio=-0.01),
     "Bending.damping_ratio"),
    (lambda: Actuator(0.0), "Actuator.time_constant"),
    (lambda: Actuator(0.1, deflection_limits=(0.1, -0.1)), "Actuator.deflection_limits"),
    (lambda: Actuator(0.1, deflection_limits=(0.1, 0.1)), "Actuator.deflection_limits"),
    (lambda: Actuator(0.1, rate_limit=-1.0), "Actuator.rate_limit"),
    (lambda: Actuator(0.1, rate_limit=0.0), "Actuator.rate_limit"),
])
def test_bad_part_fields_raise_value_error_naming_the_field(make, name):
    with pytest.raises(ValueError, match=f"`{name}"):
        make()


@pytest.mark.parametrize("kwargs, name", [
    (dict(thrust="big"), "thrust"), (dict(mass=None), "mass"),
    (dict(k_psi="1", k_psidot=1.0), "k_psi"),
    (dict(aero=(1.0, 2.0, 3.0, 4.0)), "aero"), (dict(slosh={"mass": 1.0}), "slosh"),
    (dict(actuator=0.05), "actuator"), (dict(bending=Slosh(1.0, 0.0, length=1.0)), "bending"),
])
def test_wrong_types_raise_type_error(kwargs, name):
    with pytest.raises(TypeError, match=f"`{name}"):
        launch_vehicle(**{**RIGID, **kwargs})


@pytest.mark.parametrize("make, name", [
    (lambda: Aero(1.0, 1.0, 1.0, 1.0, wind=3), "Aero.wind"),
    (lambda: Slosh(mass="heavy", hinge=0.0, length=1.0), "Slosh.mass"),
    (lambda: Actuator(0.1, deflection_limits="wide"), "Actuator.deflection_limits"),
])
def test_wrong_part_field_types_raise_type_error(make, name):
    with pytest.raises(TypeError, match=f"`{name}"):
        make()
