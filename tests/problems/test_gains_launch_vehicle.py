"""Launch-vehicle autopilot gains by multi-scenario collocation (`problems.gains.launch_vehicle`)
and their configuration file (`problems.gains.config`)."""
import copy
import doctest
import importlib
import math
import tomllib

import casadi as ca
import control
import numpy as np
import pytest

from appdyn.dynamics import simulate
from appdyn.dynamics.launch_vehicle import Actuator, Aero
from appdyn.dynamics.launch_vehicle import launch_vehicle as vehicle_model
from appdyn.problems.gains import STATUS_LIMITS, GainDesign
from appdyn.problems.gains.config import EXAMPLE_CONFIG, load_config, parse_config
from appdyn.problems.gains.launch_vehicle import (LaunchScenario, LaunchVehicle, design_model,
                                           launch_vehicle_gains)
from appdyn.ocp.status import STATUS_UNSTABLE

F, I, L, M, V = 2.0e6, 4.0e7, 20.0, 1.0e5, 300.0
AERO = Aero(dynamic_pressure=3.0e4, area=10.0, normal_force_slope=3.0, cp_arm=5.0)
DMAX, RMAX = math.radians(6.0), math.radians(25.0)
SCENARIOS = [LaunchScenario(psi0=math.radians(1.0), name="attitude"),
             LaunchScenario(psi_dot0=math.radians(1.0), name="rate"),
             LaunchScenario(gust_alpha=math.radians(4.0), name="gust")]


@pytest.fixture(scope="module")
def with_actuator():
    """The shipped example (actuator tau = 0.08 s)."""
    return load_config(EXAMPLE_CONFIG).design()


@pytest.fixture(scope="module")
def rigid_gimbal():
    """No actuator: delta = -(k_psi psi + k_psidot psi') and its rate from the dynamics."""
    veh = {"thrust": F, "inertia": I, "arm": L, "mass": M, "aero": AERO, "velocity": V}
    return launch_vehicle_gains(veh, SCENARIOS[::2], delta_max=DMAX, delta_rate_max=RMAX,
                                N=30)


def _loop_transfer(k, kd, tau):
    """L(s) = (k + kd s) Npsi / ((tau s + 1) D), the closed forms of RP-1262 Sec. 5.4 with
    aero (``alpha = psi - y_dot / V``), written here from the vehicle numbers."""
    N = AERO.dynamic_pressure * AERO.area * AERO.normal_force_slope
    Ma = N * AERO.cp_arm
    s = control.tf("s")
    D = (I * s**2 - Ma) * (M * s + N / V) + Ma * (F + N) / V
    Npsi = F * L * (M * s + N / V) + F * Ma / V
    return (k + kd * s) * Npsi / ((tau * s + 1) * D)


@pytest.mark.parametrize("which", ["with_actuator", "rigid_gimbal"])
@pytest.mark.slow
def test_margins_agree_with_python_control_on_the_closed_form_loop(which, request):
    d = request.getfixturevalue(which)
    assert isinstance(d, GainDesign) and d.success, d.message
    tau = 0.08 if which == "with_actuator" else 0.0
    Ls = _loop_transfer(d.gains["k_psi"], d.gains["k_psidot"], tau)
    gm, pm, wcg, wcp = control.margin(Ls)
    v = d.verification
    assert v["phase_margin_deg"] == pytest.approx(pm, rel=1e-6)
    assert v["gain_crossover"] == pytest.approx(wcp, rel=1e-6)
    assert v["gain_margin"] == pytest.approx(gm, rel=1e-6)
    assert v["gain_margin_lower"] == pytest.approx(gm, rel=1e-6) and gm < 1  # unstable airframe
    # the closed loop's poles are the roots of D (tau s + 1) + (k + kd s) Npsi
    cl = control.feedback(Ls, 1)
    poles = np.sort_complex(np.asarray(control.poles(cl)))
    ours = np.array(v["poles"])
    got = np.sort_complex(ours[np.abs(ours) > 1e-9])
    np.testing.assert_allclose(got, poles, rtol=1e-6)
    assert np.all(poles.real < -0.01)  # min_decay
    assert v["verdict"] == "asymptotically stable" and 0.3 < v["least_damping_ratio"] <= 1.0 + 1e-12


@pytest.mark.parametrize("which", ["with_actuator", "rigid_gimbal"])
@pytest.mark.slow
def test_resimulated_scenarios_are_stable_and_hold_the_limits(which, request):
    d = request.getfixturevalue(which)
    k, kd = d.gains["k_psi"], d.gains["k_psidot"]
    actuator = Actuator(0.08) if which == "with_actuator" else None
    loop = vehicle_model(thrust=F, inertia=I, arm=L, mass=M, k_psi=k, k_psidot=kd, aero=AERO,
                         actuator=actuator)
    scs = SCENARIOS if which == "with_actuator" else SCENARIOS[::2]
    assert len(d.scenarios) == len(scs)
    t = np.linspace(0.0, 8.0, 2001)
    for sc, run in zip(scs, d.scenarios):
        x0 = np.zeros(loop.nx)
        x0[2], x0[3], x0[5] = sc.psi0, V, sc.psi_dot0
        p = [0.0, V * math.tan(sc.gust_alpha)]
        res = simulate(loop, x0, t, p=p)
        assert res.success
        x = np.asarray(res.x)
        if actuator is not None:
            delta = x[6]
            rate = np.asarray(loop.f.map(t.size)(x, ca.DM(0, t.size), ca.repmat(ca.DM(p), 1,
                                                                                  t.size)))[6]
        else:
            delta = -(k * x[2] + kd * x[5])
            rate = np.gradient(delta, t)  # finite differences, only to check the derivation
            np.testing.assert_allclose(np.interp(t, run["t"], run["delta_rate"])[1:-1],
                                       rate[1:-1], atol=1e-4 * RMAX)  # central differences
        assert np.max(np.abs(delta)) <= DMAX * 1.005 and np.max(np.abs(rate)) <= RMAX * 1.005
        assert run["peak"]["delta"] == pytest.approx(np.max(np.abs(delta)), rel=1e-3)
        # stable: the attitude error decays, also after the gust (a slow drift mode, the
        # vehicle turning into the wind, slower as the thrust speeds it up: 150 s)
        late = simulate(loop, x0, np.linspace(0.0, 150.0, 301), p=p)
        assert late.success
        assert abs(late.x[2, -1]) < 0.05 * np.max(np.abs(late.x[2]))
    # the rate limit binds in the example (a 1 deg/s rate error into a 0.08 s servo)
    if which == "with_actuator":
        assert d.scenarios[1]["peak"]["delta_rate"] == pytest.approx(RMAX, rel=1e-3)


def test_design_model_rate_is_the_derivative_of_the_deflection():
    """Without actuator delta' = -(k_psi psi' + k_psidot psi''), psi'' from the dynamics."""
    model, out = design_model(LaunchVehicle(F, I, L, M, aero=AERO, velocity=V))
    x = ca.SX.sym("x", model.nx)
    k = ca.DM([1.3, 0.7])
    d, r, _ = out(x, k)
    chain = ca.Function("chain", [x], [ca.jtimes(d, x, model.f(x, ca.DM(0, 1), k)) - r])
    xs = np.array([0.02, -0.01, V, 3.0, 5.0])
    assert abs(float(chain(xs))) < 1e-14


def _solve_infeasible(**limits):
    veh = LaunchVehicle(F, I, L, M, aero=AERO, velocity=V)
    return launch_vehicle_gains(veh, [LaunchScenario(gust_alpha=math.radians(3.0))],
                                horizon=6.0, N=16, **limits)


@pytest.mark.slow
def test_gimbal_too_weak_for_the_gust_names_the_deflection_limit():
    d = _solve_infeasible(delta_max=math.radians(0.1), delta_rate_max=RMAX)
    assert not d.success and d.status == STATUS_LIMITS
    assert "gimbal deflection |delta| <= 0.1 deg" in d.message
    assert d.verification["violated"] == ["delta"]


@pytest.mark.slow
def test_unreachable_rate_limit_names_the_rate_limit():
    d = _solve_infeasible(delta_max=DMAX, delta_rate_max=math.radians(0.01))
    assert not d.success and d.status == STATUS_LIMITS
    assert "deflection rate |delta_dot| <= 0.01 deg/s" in d.message
    assert d.verification["violated"] == ["delta_rate"]


# --------------------------------------------------------------------------- config
def _example():
    return tomllib.loads(EXAMPLE_CONFIG.read_text())


def test_example_config_parses_to_the_library_arguments():
    cfg = load_config(EXAMPLE_CONFIG)
    assert cfg.vehicle == LaunchVehicle(F, I, L, M, aero=AERO, velocity=V,
                                        actuator=Actuator(0.08))
    assert [(s.psi0, s.psi_dot0, s.gust_alpha) for s in cfg.scenarios] == \
        [(s.psi0, s.psi_dot0, s.gust_alpha) for s in SCENARIOS]
    assert [s.name for s in cfg.scenarios] == ["attitude error", "rate error", "wind gust"]
    assert cfg.options["delta_max"] == pytest.approx(DMAX)
    assert cfg.options["N"] == 40 and cfg.options["weights"] == {"psi": 1.0, "delta": 1.0}
    data = _example()
    data["design"].update(integral=True, k_i_bounds=[0.0, 2.0], filter_time_constant=0.1)
    opts = parse_config(data).options
    assert opts["integral"] is True and opts["filter_time_constant"] == 0.1
    assert opts["gain_bounds"] == {"k_i": (0.0, 2.0)}


def _set(data, dotted, value):
    keys = dotted.replace("[", ".").replace("]", "").split(".")
    node = data
    for key in keys[:-1]:
        node = node[int(key)] if key.isdigit() else node[key]
    if value is _DELETE:
        del node[keys[-1]]
    else:
        node[keys[-1]] = value


_DELETE = object()


@pytest.mark.parametrize("field, value, match", [
    ("vehicle.thrust", -2.0e6, r"vehicle\.thrust must be > 0"),
    ("vehicle.inertia", "big", r"vehicle\.inertia must be a number"),
    ("vehicle.mass", _DELETE, r"vehicle\.mass is required"),
    ("vehicle.colour", "red", r"unknown key vehicle\.colour"),
    ("vehicle.aero.cp_arm", float("nan"), r"vehicle\.aero\.cp_arm must be finite"),
    ("vehicle.aero.mach", 0.9, r"unknown key vehicle\.aero\.mach"),
    ("vehicle.velocity", _DELETE, r"vehicle\.velocity is required"),
    ("vehicle.actuator.time_constant", 0.0, r"vehicle\.actuator\.time_constant must be > 0"),
    ("limits.delta_max_deg", -6.0, r"limits\.delta_max_deg must be > 0"),
    ("limits.delta_rate_max_deg", _DELETE, r"limits\.delta_rate_max_deg is required"),
    ("weights.psi", -1.0, r"weights\.psi must be >= 0"),
    ("design.intervals", 2, r"design\.intervals must be >= 4"),
    ("design.intervals", 40.5, r"design\.intervals must be an integer"),
    ("design.k_psi_bounds", [5.0, 1.0], r"design\.k_psi_bounds must be finite with lower"),
    ("design.integral", "yes", r"design\.integral must be true or false"),
    ("design.k_i_bounds", [0.0, 1.0], r"design\.k_i_bounds needs design\.integral"),
    ("design.filter_time_constant", -0.1, r"design\.filter_time_constant must be > 0"),
    ("scenarios[1].psi0_deg", True, r"scenarios\[1\]\.psi0_deg must be a number"),
    ("scenarios[2].gust_alpha_deg", 95.0, r"scenarios\[2\]\.gust_alpha_deg must be within"),
    ("scenarios[0].wind", 3.0, r"unknown key scenarios\[0\]\.wind"),
    ("scenarios", [], r"scenarios must be a non-empty array"),
    ("extra", {}, r"unknown key extra"),
])
def test_bad_configs_raise_value_error_naming_the_field(field, value, match):
    data = copy.deepcopy(_example())
    _set(data, field, value)
    with pytest.raises(ValueError, match=match):
        parse_config(data)


def test_bad_config_files_name_the_path(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[vehicle\nthrust = 1")
    with pytest.raises(ValueError, match="not valid TOML"):
        load_config(bad)
    with pytest.raises(ValueError, match="cannot read"):
        load_config(tmp_path / "missing.toml")


@pytest.mark.parametrize("kwargs, error, match", [
    ({"delta_max": 0.0}, ValueError, "delta_max"),
    ({"delta_rate_max": -1.0}, ValueError, "delta_rate_max"),
    ({"weights": {"attitude": 1.0}}, ValueError, "weights"),
    ({"weights": [1.0]}, TypeError, "weights"),
    ({"N": 2}, ValueError, "`N`"),
    ({"gain_bounds": {"k_psi": (1.0, 0.5)}}, ValueError, "gain_bounds"),
    ({"vehicle": {"thrust": F, "inertia": I, "arm": L, "mass": M, "fins": 4}}, ValueError,
     "fins"),
    ({"vehicle": {"thrust": F, "inertia": I, "arm": L, "mass": M, "aero": AERO}}, ValueError,
     "velocity"),
    ({"scenarios": [{"psi0": 0.1, "theta0": 0.2}]}, ValueError, r"scenarios\[0\]"),
    ({"scenarios": "gust"}, TypeError, "scenarios"),
    ({"vehicle": {"thrust": F, "inertia": I, "arm": L, "mass": M},
      "scenarios": [{"gust_alpha": 0.05}]}, ValueError, "aero"),
])
def test_bad_arguments_name_the_argument(kwargs, error, match):
    args = {"vehicle": LaunchVehicle(F, I, L, M, aero=AERO, velocity=V),
            "scenarios": SCENARIOS[:1], "delta_max": DMAX, "delta_rate_max": RMAX, **kwargs}
    with pytest.raises(error, match=match):
        launch_vehicle_gains(args.pop("vehicle"), args.pop("scenarios"), **args)


@pytest.mark.parametrize("module_name", ["appdyn.problems.gains.launch_vehicle", "appdyn.problems.gains.config",
                                         "appdyn.problems.cli.gains"])
@pytest.mark.slow
def test_docstring_examples_run_as_written(module_name):
    module = importlib.import_module(module_name)
    runner = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE | doctest.ELLIPSIS)
    for test in doctest.DocTestFinder(exclude_empty=True).find(module, module_name):
        runner.run(test)
    result = runner.summarize(verbose=False)
    assert result.failed == 0


@pytest.mark.slow
def test_integral_gain_and_command_filter_verified_on_the_closed_form_loop():
    """delta_c = -(k_psi psi + k_psidot psi' + k_i int psi) / (tau_f s + 1): the margins and
    poles of the report agree with python-control on C(s) Npsi / ((tau s + 1) D)."""
    veh = LaunchVehicle(F, I, L, M, aero=AERO, velocity=V, actuator=Actuator(0.08))
    d = launch_vehicle_gains(veh, SCENARIOS, delta_max=DMAX, delta_rate_max=RMAX, N=20,
                             integral=True, filter_time_constant=0.1)
    assert d.success, d.message
    assert set(d.gains) == {"k_psi", "k_psidot", "k_i"} and d.gains["k_i"] > 0
    assert d.units["k_i"] == "rad/(rad s)"
    k, kd, ki = d.gains["k_psi"], d.gains["k_psidot"], d.gains["k_i"]
    s = control.tf("s")
    Ls = (k + kd * s + ki / s) / (0.1 * s + 1) * _loop_transfer(1.0, 0.0, 0.08)
    gm, pm, wcg, wcp = control.margin(Ls)
    v = d.verification
    assert v["phase_margin_deg"] == pytest.approx(pm, rel=1e-5)
    assert v["gain_margin"] == pytest.approx(gm, rel=1e-5)
    poles = np.sort_complex(np.asarray(control.poles(control.feedback(Ls, 1))))
    ours = np.array(v["poles"])
    np.testing.assert_allclose(np.sort_complex(ours[np.abs(ours) > 1e-9]), poles, rtol=1e-5)
    assert np.all(poles.real < -0.01)
    for run in d.scenarios:
        assert run["peak"]["delta"] <= DMAX * 1.005 and run["peak"]["delta_rate"] <= RMAX * 1.005


def test_unconstrained_rigid_vehicle_gives_the_lqr_gains():
    """No air, limits far away, cost psi^2 + delta^2: the static gains optimal for every
    initial state are the LQR gains of I psi'' = F l delta (control.lqr), to the horizon's
    truncation."""
    A, B = np.array([[0.0, 1.0], [0.0, 0.0]]), np.array([[0.0], [F * L / I]])
    K, _, _ = control.lqr(A, B, np.diag([1.0, 0.0]), np.eye(1))
    d = launch_vehicle_gains({"thrust": F, "inertia": I, "arm": L, "mass": M},
                             [LaunchScenario(psi0=0.02), LaunchScenario(psi_dot0=0.02)],
                             delta_max=0.5, delta_rate_max=5.0, horizon=12.0, N=30)
    assert d.success, d.message
    np.testing.assert_allclose([d.gains["k_psi"], d.gains["k_psidot"]], K.ravel(), rtol=2e-3)
    assert d.verification["least_damping_ratio"] == pytest.approx(math.sqrt(0.5), rel=2e-3)


def test_gain_bounds_that_cannot_stabilize_the_airframe_say_so():
    """k_psi <= 0.05 < q S C_N_alpha l_cp / (F l) = 0.1125: no stable loop at all."""
    veh = LaunchVehicle(F, I, L, M, aero=AERO, velocity=V)
    d = launch_vehicle_gains(veh, SCENARIOS[:1], delta_max=DMAX, delta_rate_max=RMAX, N=16,
                             horizon=6.0, gain_bounds={"k_psi": (0.0, 0.05)})
    assert not d.success and d.status == STATUS_UNSTABLE
    assert "gain_bounds" in d.message and "k_psi in [0, 0.05]" in d.message
