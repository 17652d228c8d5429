"""The public functions of appdyn and a valid example value for each of their parameters.

Shared by the garbage sweep (`test_public_inputs`) and the random valid-input sweep
(`test_valid_inputs`): the public plain functions (``inspect.isfunction``) in ``__all__`` of
``MODULES``, their required parameters, and ``VALID`` example values by parameter name
(``OVERRIDES`` per function, ``EXTRA`` optional keywords that make a call valid).
"""
from __future__ import annotations

import functools
import importlib
import inspect

import casadi as ca
import numpy as np

MODULES = (
    "appdyn.dynamics", "appdyn.dynamics.attitude", "appdyn.dynamics.truth", "appdyn.dynamics.momentum",
    "appdyn.dynamics.mass",
    "appdyn.dynamics.constrained", "appdyn.dynamics.launch_vehicle", "appdyn.dynamics.mechanisms", "appdyn.ocp",
    "appdyn.problems.slew", "appdyn.problems.stability", "appdyn.problems.gains", "appdyn.problems.dispersion",
    "appdyn.problems.ascent",
)


def _enumerate():
    out = {}
    for modname in MODULES:
        mod = importlib.import_module(modname)
        for name in mod.__all__:
            obj = getattr(mod, name)
            if inspect.isfunction(obj):
                out[f"{modname}.{name}"] = obj
    return out


FUNCTIONS = _enumerate()


#: parameters required although they have a default (the default serves another call form:
#: ``state_feedback_gains(sys, Q, R, initial_states, horizon)`` shifts the arguments)
ALSO_REQUIRED = {"state_feedback_gains": ("horizon",)}


def _required(fn):
    return [p.name for p in inspect.signature(fn).parameters.values()
            if (p.default is inspect.Parameter.empty
                or p.name in ALSO_REQUIRED.get(fn.__name__, ()))
            and p.kind not in (inspect.Parameter.VAR_POSITIONAL, inspect.Parameter.VAR_KEYWORD)]


# --------------------------------------------------------------------------------------------
# valid example values: by parameter name, overridden per function
# --------------------------------------------------------------------------------------------


@functools.cache
def _rigid():
    from appdyn import dynamics
    return dynamics.rigid_body(np.diag([1.0, 2.0, 3.0]))


@functools.cache
def _min_energy():
    from appdyn.ocp import examples
    return examples.min_energy()


@functools.cache
def _solution():
    from appdyn import ocp
    return ocp.solve(_min_energy(), N=5)


@functools.cache
def _slew_problem():
    from appdyn.problems import slew
    return slew.slew_problem(np.diag([1.0, 2.0, 3.0]), objective="time", angle=1.0,
                             axis=[0.0, 0.0, 1.0])


@functools.cache
def _slew_solution():
    from appdyn import ocp
    return ocp.rest_solution(_slew_problem())


@functools.cache
def _pyramid():
    from appdyn.dynamics import momentum
    return momentum.pyramid(0.9553)


def _jacobian():
    from appdyn.dynamics import momentum
    return momentum.cluster_jacobian(_pyramid(), np.full(4, 0.3))


@functools.cache
def _spinner_run():
    from appdyn import dynamics
    from appdyn.problems import dispersion
    m = dispersion.spinner(1000.0, 1500.0)
    return dynamics.simulate(m, [0, 0, 0, 1, 0.02, 0.0, 1.0], np.linspace(0, 1, 3))


@functools.cache
def _constrained_symbols():
    """``(x, p, terms)`` of a point on a line: ``x = (q, v)``, ``q' = v``, ``q1 = 1``."""
    from appdyn.dynamics import constrained
    q, v = ca.SX.sym("q", 2), ca.SX.sym("v", 2)
    return ca.vertcat(q, v), ca.SX.sym("p", 0), constrained.constraint_terms(
        q, v, v, position=q[0] - 1)


def _terms():
    return _constrained_symbols()[2]


def _controller():
    x = ca.SX.sym("x", 7)
    return ca.Function("k", [x], [-x[4:7]], ["x"], ["u"])


def _lv_kwargs():
    return dict(thrust=1.0e6, inertia=2.0e6, arm=10.0, mass=5.0e4)


@functools.cache
def _lv_report():
    from appdyn.problems import stability
    return stability.launch_vehicle(**_lv_kwargs(), k_psi=2.0, k_psidot=0.5)


@functools.cache
def _slew_optimal():
    """A solved time-optimal slew (bang-bang torques): ``(problem, solution)``."""
    from appdyn.problems import slew
    res = slew.time_optimal(np.diag([1.0, 2.0, 3.0]), angle=1.0, axis=[0.0, 0.0, 1.0], N=20)
    return _slew_problem(), res


@functools.cache
def _planar_ascent():
    from appdyn.problems import ascent
    return ascent.planar_ascent(target_altitude=65e3, target_gamma=np.radians(40.0),
                                q_max=45e3, qalpha_max=2000.0, N=30)


@functools.cache
def _gain_design():
    from appdyn.problems import gains
    return gains.launch_vehicle_gains(_lv_kwargs(), [{"psi0": 0.05}], delta_max=0.1, delta_rate_max=0.5)


def _config_path():
    import appdyn.problems.gains  # noqa: F401
    from appdyn import problems
    from pathlib import Path
    return Path(problems.gains.__file__).with_name("launch_vehicle.toml")


def _config_data():
    import tomllib
    return tomllib.loads(_config_path().read_text())


def _split_energy():
    """Rest at 0 to rest at 1 in 2 s, minimum integral u^2/2, as two 1 s phases."""
    from appdyn import ocp
    from appdyn.ocp.examples import double_integrator
    energy = lambda x, u, p: 0.5 * u ** 2  # noqa: E731
    first = ocp.Problem(double_integrator(), T=1.0, x_initial=[0.0, 0.0], lagrange=energy)
    second = ocp.Problem(double_integrator(), T=1.0, x_final=[1.0, 0.0], lagrange=energy)
    return ocp.MultiPhaseProblem([ocp.Phase(first, N=6), ocp.Phase(second, N=6)],
                                 links=[ocp.Link(0, 1)])


def _sample_task():
    from appdyn.problems.dispersion.sample import SampleTask
    return SampleTask(0, {}, _rigid(), np.array([0.0, 0.0, 0.0, 1.0, 0.1, 0.2, 0.3]),
                      np.linspace(0.0, 1.0, 3), {"w1": "w1"}, (), None, {})


VALID = {
    # attitude and rigid bodies
    "inertia": lambda: np.diag([1.0, 2.0, 3.0]),
    "inertia_diag": lambda: np.array([1.0, 2.0, 3.0]),
    "q": lambda: np.array([0.0, 0.0, 0.0, 1.0]),
    "p": lambda: np.array([0.0, 0.0, 0.0, 1.0]),
    "q0": lambda: np.array([0.0, 0.0, 0.0, 1.0]),
    "w": lambda: np.array([0.1, 0.2, 0.3]),
    "w0": lambda: np.array([0.1, 0.2, 0.3]),
    "v": lambda: np.array([0.1, 0.2, 0.3]),
    "t": lambda: np.linspace(0.0, 1.0, 3),
    "A": lambda: np.eye(3),
    "axis": lambda: np.array([0.0, 0.0, 1.0]),
    "angle": lambda: 0.5,
    "angles": lambda: np.array([0.1, 0.2, 0.3]),
    "angle_rates": lambda: np.array([0.1, 0.2, 0.3]),
    "transverse": lambda: 2.0,
    "axial": lambda: 1.0,
    "offset": lambda: np.array([0.1, 0.2, 0.3]),
    "mass_flow": lambda: 10.0,
    "initial_mass": lambda: 2.0,
    "final_mass": lambda: 1.0,
    "pellet_mass": lambda: 0.1,
    "exhaust_velocity": lambda: 3000.0,
    "l1": lambda: 0.0,
    "l2": lambda: 1.0,
    "h": lambda: 0.1,
    "model": _rigid,
    "scene": lambda: __import__("appdyn.dynamics.scene", fromlist=["Scene"]).Scene(
        __import__("appdyn.dynamics.scene", fromlist=["RigidHub"]).RigidHub([1.0, 2.0, 3.0]),
        __import__("appdyn.dynamics.scene", fromlist=["ExternalTorque"]).ExternalTorque(u_max=1.0)),
    "x0": lambda: np.array([0.0, 0.0, 0.0, 1.0, 0.1, 0.2, 0.3]),
    "x": lambda: np.array([0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0]),
    "controller": _controller,
    # momentum exchange
    "axes": lambda: np.eye(3),
    "wheel_inertia": lambda: np.array([0.01, 0.01, 0.01]),
    "gimbal_axes": lambda: np.eye(3),
    "spin_axes0": lambda: np.column_stack([[0, 1, 0], [0, 0, 1], [1, 0, 0]]).astype(float),
    "beta": lambda: 0.9553,
    "geometry": _pyramid,
    "delta": lambda: np.full(4, 0.3),
    "C": _jacobian,
    "torque": lambda: np.array([0.1, 0.0, 0.0]),
    "gradient": lambda: np.full(4, 0.1),
    "count": lambda: 10,
    "directions": lambda: np.array([1.0, 0.0, 0.0]),
    "signs": lambda: np.ones(4),
    "wheel_accel": lambda: np.array([0.0, 0.0, 1.0]),
    "gimbal_rate_vector": lambda: np.array([0.1, 0.0, 0.0]),
    "rotor_momentum": lambda: np.array([0.0, 1.0, 0.0]),
    "Omega": lambda: np.array([0.0, 0.0, 1.0]),
    "omega": lambda: np.array([0.1, 0.0, 0.0]),
    "yaw_rate": lambda: 0.5,
    "spin_rate": lambda: 10.0,
    "H": lambda: np.array([0.0, 1.0, 0.0]),
    # constrained
    "M": lambda: np.eye(2),
    "Q": lambda: np.array([1.0, 0.0]),
    "B": lambda: np.array([[1.0, 1.0]]),
    "c": lambda: np.array([0.0]),
    "lam": lambda: np.array([1.0]),
    "residual": lambda: np.array([0.0]),
    "jacobian": lambda: (lambda x: 2.0 * np.asarray(x)[None, :]),
    "terms": _terms,
    "slosh": lambda: None,
    "m": lambda: 1000.0,
    "I": lambda: 500.0,
    # mechanisms
    "r0": lambda: 0.1,
    "r0_dot": lambda: 0.0,
    "rate": lambda: 1.0,
    "r": lambda: 0.1,
    "r_dot": lambda: 0.0,
    "rate_dot": lambda: 0.0,
    "theta": lambda: 0.3,
    "psi_dot": lambda: 1.0,
    "phi_dot": lambda: 10.0,
    "path_radius": lambda: 0.5,
    "cone_angle": lambda: 0.3,
    "alpha": lambda: 0.1,
    "alpha_T": lambda: 0.2,
    "phi_R": lambda: 1.0,
    "v_body": lambda: np.array([100.0, 5.0, -3.0]),
    "alpha_dot": lambda: 0.0,
    "amp_y": lambda: 0.02,
    "theta0": lambda: 0.3,
    "theta_dot": lambda: 0.0,
    "sequence": lambda: "3-2-1",
    # ocp
    "problem": _min_energy,
    "options": lambda: {"tol": 1e-6},
    "solution": _solution,
    "guesses": lambda: [None],
    "u": lambda: np.array([0.0]),
    "x_initial": lambda: np.array([0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]),
    "T": lambda: 1.0,
    "K": lambda: 2,
    # slew
    "objective": lambda: "time",
    "targets": lambda: [{"angle": 1.0, "axis": [0.0, 0.0, 1.0]}],
    "data": lambda: {},
    # stability
    "sys": lambda: None,
    "axial_inertia": lambda: 1.0,
    "transverse_inertia": lambda: 2.0,
    "mass": lambda: 1.0,
    "length": lambda: 0.5,
    "dynamic_pressure": lambda: 1.0e4,
    "area": lambda: 0.01,
    "cn_alpha": lambda: 2.0,
    "cp_offset": lambda: 0.05,
    "stiffness": lambda: 1.0e4,
    "bearing_distance": lambda: 0.5,
    "wheel_momentum": lambda: 1.0,
    "thrust": lambda: 1.0e6,
    "arm": lambda: 10.0,
    "k_psi": lambda: 2.0,
    "k_psidot": lambda: 0.5,
    "case": lambda: "spin",
    "parameter": lambda: "rate",
    "values": lambda: np.array([0.5, 1.0]),
    "freq": lambda: 200.0,
    "m1": lambda: 1.0,
    "m2": lambda: 1.0,
    # impacts (dynamics.mechanisms.impacts) and the rolling sphere
    "mass_matrix": lambda: np.diag([2.0, 1.0]),
    "normal": lambda: np.array([-1.0, 1.0]),
    "u1": lambda: 2.0,
    "u2": lambda: 0.0,
    "v1": lambda: 300.0,
    "v0": lambda: 2.0,
    "u0": lambda: 1.0,
    "x1_dot": lambda: 2.0,
    "velocity": lambda: np.array([1.0, 0.5]),
    "I1": lambda: np.diag([1.0, 2.0, 3.0]),
    "I2": lambda: np.diag([1.0, 2.0, 3.0]),
    "inertia1": lambda: np.diag([1.0, 2.0, 3.0]),
    "inertia2": lambda: np.diag([1.0, 2.0, 3.0]),
    "r1": lambda: np.array([0.0, 0.0, 1.0]),
    "r2": lambda: np.array([0.0, 0.0, -1.0]),
    # gains
    "R": lambda: np.array([[1.0]]),
    "initial_states": lambda: np.eye(2),
    "horizon": lambda: 10.0,
    "scenarios": lambda: [{"angle": 0.5, "axis": [0.0, 0.0, 1.0]}],
    "u_max": lambda: 1.0,
    "vehicle": lambda: dict(_lv_kwargs()),
    "delta_max": lambda: 0.1,
    "delta_rate_max": lambda: 0.5,
    # dispersion
    "samples": lambda: 2,
    "seed": lambda: 0,
    "outputs": lambda: {"w1": "w1"},
    "params": lambda: {},
    "res": _spinner_run,
    # ascent
    "phase": lambda: 1,
    "a": lambda: 2.4e7,
    "e": lambda: 0.7,
    "i": lambda: 0.5,
    "raan": lambda: 1.0,
    "argp": lambda: 2.0,
    "nu": lambda: 0.5,
    "speed": lambda: 50.0,
    "target_altitude": lambda: 2.0e5,
    "target_gamma": lambda: 0.0,
    "q_max": lambda: 5.0e4,
    "qalpha_max": lambda: 1.0e5,
}

_ASC_R = lambda: np.array([6.4e6, 0.0, 0.0])  # noqa: E731
_ASC_V = lambda: np.array([0.0, 7.5e3, 0.0])  # noqa: E731

@functools.cache
def _lagrange_symbols():
    """A unit mass on a spring in symbols: Lagrange's and Hamel's builders' example."""
    q, v = ca.SX.sym("q"), ca.SX.sym("v")
    return {"q": q, "v": v, "u": v, "T": 0.5 * v ** 2, "coords": {"q": q}, "rates": {"v": v},
            "speeds": {"v": v}, "W": ca.SX(1.0), "forces": [(-q, q)]}


def _lagrange(*params):
    return {k: (lambda k=k: _lagrange_symbols()[k]) for k in params}


OVERRIDES = {
    "appdyn.dynamics.mechanisms.generalized_forces": _lagrange("forces", "q"),
    "appdyn.dynamics.mechanisms.lagrange_model": _lagrange("coords", "rates", "T"),
    "appdyn.dynamics.mechanisms.hamel_terms": _lagrange("T", "q", "u", "W"),
    "appdyn.dynamics.mechanisms.hamel_model": _lagrange("coords", "speeds", "T", "W"),
    "appdyn.problems.stability.vehicle_loops": {"scene": lambda: __import__(
        "appdyn.dynamics.scene", fromlist=["x"]).launch_vehicle_scene(
            thrust=2.0e6, inertia=4.0e7, arm=20.0, mass=1.0e5)},
    "appdyn.dynamics.launch_vehicle": {"inertia": lambda: 2.0e6, "mass": lambda: 5.0e4},
    "appdyn.dynamics.launch_vehicle.launch_vehicle": {"inertia": lambda: 2.0e6, "mass": lambda: 5.0e4},
    "appdyn.problems.stability.launch_vehicle": {"inertia": lambda: 2.0e6, "mass": lambda: 5.0e4},
    "appdyn.problems.stability.launch_vehicle_response": {"inertia": lambda: 2.0e6,
                                                   "mass": lambda: 5.0e4},
    "appdyn.dynamics.cmg_spacecraft": {"h": lambda: 1.0},
    "appdyn.dynamics.momentum.cmg_spacecraft": {"h": lambda: 1.0},
    "appdyn.dynamics.momentum.rotor_dynamics": {"w": lambda: ca.DM([0.1, 0.2, 0.3]),
                                         "h": lambda: np.array([0.1, 0.1, 0.1])},
    "appdyn.dynamics.momentum.wheel_torque": {"wheel_inertia": lambda: 0.01},
    "appdyn.dynamics.momentum.propeller_torque": {"inertia": lambda: 0.5},
    "appdyn.dynamics.momentum.steer": {"torque": lambda: np.array([0.1, 0.0, 0.0])},
    "appdyn.dynamics.constrained.constraint_terms": {"q": lambda: ca.SX.sym("q", 2),
                                              "qdot": lambda: ca.SX.sym("v", 2),
                                              "v": lambda: ca.SX.sym("v", 2)},
    "appdyn.dynamics.constrained.project_velocities": {"v": lambda: np.array([1.0, 0.0])},
    "appdyn.dynamics.constrained.project_positions": {
        "residual": lambda: (lambda x: np.array([np.dot(x, x) - 1.0])),
        "x": lambda: np.array([1.1, 0.0])},
    "appdyn.dynamics.constrained.residual_invariant": {"x": lambda: _constrained_symbols()[0],
                                                "p": lambda: _constrained_symbols()[1]},
    "appdyn.dynamics.truth.axisymmetric": {"inertia_diag": lambda: np.array([1.0, 1.0, 2.0])},
    "appdyn.dynamics.truth.symmetric_precession": {"inertia_diag": lambda: np.array([1.0, 1.0, 2.0])},
    "appdyn.dynamics.truth.misaligned_thrust": {"inertia_diag": lambda: np.array([1.0, 2.0, 2.0]),
                                                "torque": lambda: 0.1},
    "appdyn.dynamics.truth.horizontal_gyroscope": {"torque": lambda: 0.1},
    "appdyn.dynamics.mass.jet_damping_torque": {"rate": lambda: 0.1},
    "appdyn.ocp.scenario_problem": {"T": lambda: 1.0, "x_initial": lambda: np.tile(
        np.array([[0.0], [0.0], [0.0], [1.0], [0.0], [0.0], [0.0]]), (1, 2))},
    "appdyn.dynamics.mechanisms.bead_motion": {"t": lambda: np.linspace(0.0, 1.0, 3)},
    "appdyn.dynamics.mechanisms.dumbbell_disk_state": {"w": lambda: np.array([0.0, 0.0, 1.0])},
    "appdyn.dynamics.mechanisms.lagrange_terms": {
        "T": lambda: 0.5 * ca.SX.sym("v") ** 2, "V": lambda: ca.SX(0),
        "q": lambda: ca.SX.sym("q"), "v": lambda: ca.SX.sym("v")},
    "appdyn.dynamics.mechanisms.spherical_mass_matrix": {"q": lambda: np.array([0.1, 0.2])},
    "appdyn.dynamics.mechanisms.impact": {"v": lambda: np.array([1.0, 0.0])},
    "appdyn.dynamics.mechanisms.contact_jump": {
        "mass_matrix": lambda: (lambda q, p: np.eye(1)), "normal": lambda: (lambda q, p: [1.0]),
        "nq": lambda: 1},
    "appdyn.dynamics.mechanisms.sphere_constraint_matrix": {"q": lambda: np.full(5, 0.1)},
    "appdyn.ocp.unstack": {"x": lambda: np.zeros((4, 3))},
    "appdyn.ocp.state_scale": {"x": lambda: np.zeros((2, 5))},
    "appdyn.problems.slew.min_effort": {"T": lambda: 5.0},
    "appdyn.problems.slew.eigenaxis_time": {"angle": lambda: 1.0},
    "appdyn.problems.slew.attitude_guess": {"problem": _slew_problem},
    "appdyn.problems.slew.switch_times": {"solution": _slew_solution},
    "appdyn.problems.slew.verify": {"solution": _slew_solution},
    "appdyn.problems.slew.polish_text": {"record": lambda: {
        "ran": True, "used": True, "why": "verified, not slower", "method": "switch-times",
        "wall_time": 0.4, "budget": 0.5, "T_before": 3.2431, "T_after": 3.2430833,
        "gain": 1.7e-5}},
    "appdyn.problems.slew.summary": {"solution": _slew_solution},
    "appdyn.problems.slew.plot_slew": {"solution": _slew_solution},
    "appdyn.problems.slew.format_summary": {
        "data": lambda: __import__("appdyn.problems.slew", fromlist=["summary"]).summary(
            _slew_solution())},
    "appdyn.problems.stability.classify": {"A": lambda: np.array([[0.0, 1.0], [-1.0, -0.1]])},
    "appdyn.problems.stability.spin": {"axis": lambda: np.array([0.0, 0.0, 1.0])},
    "appdyn.problems.stability.heavy_top": {"rate": lambda: 20.0},
    "appdyn.problems.stability.spinning_projectile": {"axial_inertia": lambda: 0.01,
                                               "transverse_inertia": lambda: 0.1,
                                               "rate": lambda: 100.0},
    "appdyn.problems.stability.rotor": {"rate": lambda: 10.0},
    "appdyn.problems.stability.loop": {"plant": lambda: __import__("control").tf([1.0], [1.0, 0.0, 0.0]),
                                "controller": lambda: np.array([[1.0]])},
    "appdyn.problems.stability.shaken_pendulum": {"inertia": lambda: 0.0208, "length": lambda: 0.25},
    "appdyn.problems.stability.conical_pendulum": {"length": lambda: 1.0},
    "appdyn.problems.gains.state_feedback_gains": {
        "A": lambda: np.array([[0.0, 1.0], [0.0, 0.0]]), "B": lambda: np.array([[0.0], [1.0]]),
        "Q": lambda: np.eye(2)},
    "appdyn.problems.gains.launch_vehicle_gains": {"scenarios": lambda: [{"psi0": 0.1}]},
    "appdyn.problems.dispersion.nutation_history": {"transverse_inertia": lambda: 1000.0,
                                             "axial_inertia": lambda: 1500.0},
    "appdyn.problems.dispersion.nutation_max": {"transverse_inertia": lambda: 1000.0,
                                         "axial_inertia": lambda: 1500.0},
    "appdyn.problems.dispersion.spinner": {"transverse_inertia": lambda: 1000.0,
                                    "axial_inertia": lambda: 1500.0},
    "appdyn.problems.dispersion.nutation_closed_form": {"transverse_inertia": lambda: 1000.0,
                                                 "axial_inertia": lambda: 1500.0,
                                                 "w0": lambda: np.array([0.02, 0.0, 1.0])},
    "appdyn.problems.dispersion.draw_samples": {
        "params": lambda: {"a": __import__("appdyn.problems.dispersion", fromlist=["Normal"]).Normal(0.0, 1.0)}},
    "appdyn.problems.dispersion.statistics": {"values": lambda: np.array([1.0, 2.0, 3.0])},
    "appdyn.problems.ascent.drag_force": {"r": _ASC_R, "v": _ASC_V},
    "appdyn.problems.ascent.dynamic_pressure": {"r": _ASC_R, "v": _ASC_V},
    "appdyn.problems.ascent.orbit_residuals": {"r": _ASC_R, "v": _ASC_V},
    "appdyn.problems.ascent.orbital_elements": {"r": _ASC_R, "v": _ASC_V},
    "appdyn.problems.ascent.vertical_rise": {"vehicle": lambda: None},
    "appdyn.problems.ascent.pitch_model": {"vehicle": lambda: None, "k_theta": lambda: 2.0,
                                           "k_thetadot": lambda: 0.5},
    "appdyn.problems.ascent.fly_pitch_program": {"ascent": _planar_ascent},
    "appdyn.problems.dispersion.run_sample": {"task": _sample_task},
    "appdyn.problems.gains.load_config": {"path": _config_path},
    "appdyn.problems.gains.parse_config": {"data": _config_data},
    "appdyn.problems.gains.plot_design": {"design": _gain_design},
    "appdyn.problems.stability.bode_plot": {"report": _lv_report},
    "appdyn.problems.stability.nichols_plot": {"report": _lv_report},
    "appdyn.problems.stability.loop_transfer": {"report": _lv_report},
    "appdyn.problems.stability.analyze": {"sys": lambda: __import__("appdyn.dynamics", fromlist=["x"]).linearize(
        _rigid(), np.array([0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0]))},
    "appdyn.ocp.solve_phases": {"problem": _split_energy},
    "appdyn.ocp.rest_solution": {"problem": lambda: __import__(
        "appdyn.problems.slew", fromlist=["slew_problem"]).slew_problem(
            np.diag([1.0, 2.0, 3.0]), objective="effort", T=2.0, angle=0.0, axis=[0, 0, 1])},
    "appdyn.ocp.polish_switches": {"problem": lambda: _slew_optimal()[0],
                            "solution": lambda: _slew_optimal()[1]},
    "appdyn.ocp.optimize_switch_times": {"problem": lambda: _slew_optimal()[0],
                                  "solution": lambda: _slew_optimal()[1]},
    "appdyn.problems.slew.verify": {"solution": lambda: _slew_optimal()[1]},
    "appdyn.problems.slew.bounded": {"problem": lambda: _slew_optimal()[0],
                              "solution": lambda: _slew_optimal()[1]},
}

# optional keywords that make the all-valid call valid (a target, a spin rate, ...)
EXTRA = {
    "appdyn.dynamics.constrained.constraint_terms": lambda: {"position": ca.SX.sym("q", 2)[0]},
    "appdyn.dynamics.truth.small_asymmetry_rates": lambda: {"rate": 1.0},
    "appdyn.dynamics.truth.small_asymmetry_frequency": lambda: {"rate": 1.0},
    "appdyn.problems.slew.slew_problem": lambda: {"angle": 1.0, "axis": [0.0, 0.0, 1.0]},
    "appdyn.problems.slew.time_optimal": lambda: {"angle": 1.0, "axis": [0.0, 0.0, 1.0]},
    "appdyn.problems.slew.min_effort": lambda: {"angle": 1.0, "axis": [0.0, 0.0, 1.0]},
    "appdyn.problems.slew.wheel_slew": lambda: {"angle": 1.0, "axis": [0.0, 0.0, 1.0]},
    "appdyn.problems.slew.cmg_slew": lambda: {"angle": 1.0, "axis": [0.0, 0.0, 1.0]},
    "appdyn.problems.slew.slew": lambda: {"angle": 1.0, "axis": [0.0, 0.0, 1.0]},
    "appdyn.problems.slew.scene_problem": lambda: {"angle": 1.0, "axis": [0.0, 0.0, 1.0], "T": 2.0},
    "appdyn.dynamics.mass.delta_v": lambda: {"exhaust_velocity": 3000.0},
    "appdyn.dynamics.mass.radius_of_gyration": lambda: {"axis": np.array([0.0, 0.0, 1.0])},
    "appdyn.problems.stability.sweep": lambda: {"inertia": np.diag([1.0, 2.0, 3.0]),
                                         "axis": np.array([0.0, 0.0, 1.0])},
}

_NO_VALID = object()


def _valid(func, param):
    table = OVERRIDES.get(func, {})
    factory = table.get(param, VALID.get(param))
    if factory is None:
        return _NO_VALID
    return factory()


# Functions whose all-valid call solves an NLP or runs many simulations: not run by
# ``test_valid_examples`` (their garbage cases are cheap refusals before any solve).
EXPENSIVE = {
    "appdyn.ocp.solve", "appdyn.ocp.solve_phases", "appdyn.ocp.refine", "appdyn.ocp.solve_multistart",
    "appdyn.ocp.polish_switches", "appdyn.ocp.optimize_switch_times", "appdyn.problems.slew.time_optimal",
    "appdyn.problems.slew.min_effort", "appdyn.problems.slew.wheel_slew", "appdyn.problems.slew.cmg_slew",
    "appdyn.problems.slew.slew",
    "appdyn.problems.slew.maneuver_table", "appdyn.problems.gains.state_feedback_gains",
    "appdyn.problems.gains.attitude_gains", "appdyn.problems.gains.launch_vehicle_gains",
    "appdyn.problems.ascent.planar_ascent", "appdyn.problems.dispersion.dispersion",
    "appdyn.problems.stability.sweep", "appdyn.dynamics.momentum.momentum_envelope",
}
