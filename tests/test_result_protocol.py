"""Every public result follows one protocol (`dynamics.results.Result`): a repr of at most ten
lines, strict JSON (no NaN/Infinity tokens), a notebook view, and ``plot(ax)`` drawing on the
axes it is given (the library builds figures; only the CLI saves them)."""
import json
import math

import numpy as np
import pytest
from matplotlib.figure import Figure

from appdyn.dynamics import rigid_body, simulate
from appdyn.dynamics.results import Result, clean_number, quantity


def strict(text):
    def refuse(token):
        raise ValueError(f"non-strict JSON token {token}")
    return json.loads(text, parse_constant=refuse)


def check_protocol(res, *, nonfinite=False):
    """The shared surface; returns the parsed JSON."""
    assert isinstance(res, Result)
    text = repr(res)
    lines = text.splitlines()
    assert lines[0] == type(res).__name__ and 2 <= len(lines) <= 10, text
    assert all(len(line) <= 100 for line in lines), text
    assert "<table>" in res._repr_html_()
    data = strict(res.to_json())
    assert all(v in (True, False) for v in np.atleast_1d(data["success"]))  # a batch: per run
    if hasattr(res, "status"):  # an int everywhere (a batch: an int array, one per run)
        status = np.asarray(res.status)
        assert status.dtype.kind == "i" and not isinstance(res.status, bool), repr(res.status)
        values = data["status"] if isinstance(data["status"], list) else [data["status"]]
        assert all(type(v) is int for v in values), data["status"]
    if nonfinite:
        assert "null" in res.to_json()
    return data


def check_plot(res, *args, **kwargs):
    """``plot(ax)`` draws in the figure of the axes given and returns that figure."""
    fig = Figure()
    ax = fig.add_subplot(1, 1, 1)
    out = res.plot(ax, *args, **kwargs)
    assert out is fig
    drawn = [a for a in fig.axes if a.lines or a.collections or a.patches]
    assert drawn, "nothing drawn"
    return fig


RIGID = ([1.0, 2.0, 3.0], [0, 0, 0, 1, 1.0, 0.1, 0.8])


def test_simulation_result_and_its_batch():
    model = rigid_body(RIGID[0])
    t = np.linspace(0.0, 2.0, 41)
    res = simulate(model, RIGID[1], t, method="rk8", steps=4, jit=False)
    data = check_protocol(res, nonfinite=True)  # error_estimate of rk8 is NaN -> null
    assert data["error_estimate"] is None and data["status"] == 0
    check_plot(res)
    x0 = np.tile(np.array(RIGID[1], dtype=float)[:, None], (1, 3))
    x0[4] = [1.0, 0.5, -0.5]
    batch = simulate(model, x0, t, method="rk4", steps=2, jit=False)
    data = check_protocol(batch)
    assert np.shape(data["x"]["w1"]) == (41, 3) and data["status"] == [0, 0, 0]
    fig = check_plot(batch)
    assert len(fig.axes[0].lines) == 3 * 7  # every run of every state on the one axes given


def test_simulate_accepts_progress_true(capsys):
    res = simulate(rigid_body(RIGID[0]), RIGID[1], np.linspace(0.0, 20.0, 11), method="rk4",
                   steps=200, jit=False, progress=True)
    assert res.success
    out, err = capsys.readouterr()
    assert out == ""  # a bar goes to stderr, never stdout
    assert err.rstrip().endswith("s") and "100% 2000/2000" in err


@pytest.mark.slow
def test_progress_of_auto_reaches_its_total_once():
    seen = []  # auto: adaptive passes, then rk8 runs at growing step counts
    res = simulate(rigid_body(RIGID[0]), RIGID[1], np.linspace(0.0, 2000.0, 2001), rtol=1e-10,
                   progress=lambda done, total: seen.append((done, total)))
    assert res.success and len(seen) > 2
    assert [k for k, (d, t) in enumerate(seen) if d >= t] == [len(seen) - 1]  # no restarts
    totals = [t for _, t in seen[:-1]]
    assert totals == sorted(totals) and seen[-1][0] == seen[-1][1]


def test_step_counter_extrapolates_and_finishes_once():
    from appdyn.dynamics.integrate.loops import Progress

    seen = []
    counter = Progress(lambda done, total: seen.append((done, total)))
    counter.step(100, 0.25)  # a quarter of the intervals in 100 steps: ~300 more expected
    counter.step(100, 0.5)
    counter.start(400)  # a fixed-step run of 400 steps follows, and maybe one of 800
    counter.ahead = 800
    counter.advance(400)
    counter.finish()
    assert seen == [(100, 400), (200, 400), (600, 1400), (600, 600)]


@pytest.mark.slow
def test_floquet_and_periodic_report():
    from appdyn.problems import stability as st

    rep = st.shaken_pendulum(mass=1.0, inertia=1.0 / 48.0, length=0.25, amp_y=0.02, freq=200.0,
                             position="inverted", damping=0.002)
    check_protocol(rep)
    check_protocol(rep.floquet)
    check_plot(rep)
    check_plot(rep.floquet)


@pytest.mark.slow
def test_stability_report_and_sweep():
    from appdyn.problems import stability as st

    rep = st.spin([2.0, 3.0, 4.5], axis=[0, 0, 1], rate=5.0)
    check_protocol(rep)
    check_plot(rep)
    sw = st.sweep("rotor", "rate", [30.0, 90.0], axial_inertia=0.01, transverse_inertia=0.05,
                  stiffness=1e4, bearing_distance=0.1, internal_damping=0.01)
    check_protocol(sw)
    fig = check_plot(sw)
    assert len(fig.axes) == 2  # the slot of the axes given holds both panels


@pytest.mark.slow
def test_autopilot_response_and_torque_free_report():
    from appdyn.problems import stability as st
    from appdyn.problems.torque_free import torque_free

    res = st.launch_vehicle_response(thrust=2e6, inertia=4e7, arm=20.0, mass=1e5, k_psi=2.0,
                                     k_psidot=2.0, psi0=0.05, t_final=5.0, points=101)
    check_protocol(res)
    check_plot(res)
    tf = torque_free(RIGID[0], RIGID[1][4:], t_final=5.0, n_points=51)
    check_protocol(tf)
    check_plot(tf)


def test_cmg_steering_and_envelope():
    from appdyn.dynamics.momentum import momentum_envelope, pyramid, steer

    geo = pyramid(np.deg2rad(54.74))
    res = steer(geo, [0.0, 0.0, -0.2], np.linspace(0, 2, 21), law="pinv")
    check_protocol(res)
    check_plot(res)
    env = momentum_envelope(geo, directions=50)
    assert check_protocol(env)["status"] == 0
    assert len(repr(env).splitlines()) <= 10
    check_plot(env)
    with pytest.raises(TypeError, match="`ax`"):
        env.plot("env.png")  # the library saves nothing: the CLI does


def test_gain_design_draws_any_design_and_nan_is_null():
    from appdyn.problems.gains import GainDesign, plot_design

    t = np.linspace(0.0, 1.0, 11)
    lv = GainDesign(True, 0, "ok", {"k_psi": 2.0}, {"k_psi": "rad/rad"},
                    math.nan, [{"t": t, "psi": 0.1 * t, "delta": 0.01 * t,
                                "delta_rate": 0.01 + 0 * t, "peak": {"psi": 0.1}}],
                    {"delta_max": 0.05, "delta_rate_max": math.inf})
    data = check_protocol(lv, nonfinite=True)
    assert data["cost"] is None and data["verification"]["delta_rate_max"] is None
    fig = check_plot(lv)
    assert [a.get_ylabel() for a in fig.axes] == ["attitude psi [deg]", "deflection delta [deg]",
                                                  "deflection rate [deg/s]"]
    # an attitude design has no 'psi' (plot_design raised KeyError 'psi')
    att = GainDesign(True, 0, "ok", {"kp": 1.0}, {}, 1.0,
                     [{"t": t, "x": np.zeros((7, 11)), "u": np.ones((3, 11)), "angle": t,
                       "peak": {"angle": 1.0}}], {})
    assert len(plot_design(att).axes) == 3


def test_solutions_of_the_collocation_engine():
    from appdyn import ocp
    from appdyn.ocp.examples import min_energy

    sol = ocp.solve(min_energy(), N=10)
    check_protocol(sol)
    assert sol.wall_time == pytest.approx(sol.build_time + sol.solve_time)
    check_plot(sol)


def test_dispersion_result(capsys):
    from appdyn.problems.dispersion import Normal, dispersion, spinner

    res = dispersion(spinner, [0, 0, 0, 1, 0.0, 0.0, 1.0], np.linspace(0.0, 2.0, 5), samples=4,
                     progress=True,
                     seed=0, params={"w1": Normal(0.02, 0.004),
                                     "transverse_inertia": Normal(1000.0, 20.0),
                                     "axial_inertia": Normal(1500.0, 30.0)},
                     outputs={"w1_final": lambda res: res["w1"][-1]})
    check_protocol(res)
    check_plot(res)
    out, err = capsys.readouterr()
    assert out == "" and "dispersion |" in err and "100% 4/4" in err  # progress=True: a bar


@pytest.mark.slow
def test_maneuver_table():
    from appdyn.problems.slew import maneuver_table

    table = maneuver_table(np.eye(3), [{"name": "roll", "angle": 0.1, "axis": [1, 0, 0]}],
                           N=10, starts=1)
    check_protocol(table)
    check_plot(table)
    check_plot(table.solutions[0])  # a slew draws itself


def test_quantity_cleans_round_off_and_keeps_significant_digits():
    assert quantity(2.9e-5, "", 4) == "2.9e-05"  # was "+0.0000"
    assert quantity(-7.2e-71 - 1.5j, "1/s", 5) == "0-1.5j 1/s"
    assert quantity(math.inf, "dB", 4) == "inf dB"
    assert clean_number(-0.0) == 0.0 and math.copysign(1, clean_number(-0.0) + 0.0) == 1


@pytest.mark.slow
def test_planar_ascent_and_its_tracking():
    from appdyn.problems.ascent import fly_pitch_program, planar_ascent

    asc = planar_ascent(target_altitude=65e3, target_gamma=math.radians(40.0), q_max=45e3,
                        qalpha_max=2e3, N=30)
    check_protocol(asc)
    check_plot(asc)
    track = fly_pitch_program(asc)
    check_protocol(track)
    check_plot(track)


def test_multi_phase_solution():
    from appdyn import ocp
    from tests.ocp.test_phases import split_energy

    sol = ocp.solve_phases(split_energy())
    check_protocol(sol)
    assert sol.wall_time == pytest.approx(sol.build_time + sol.solve_time)
    fig = check_plot(sol)
    assert sum(1 for ln in fig.axes[0].lines if ln.get_linestyle() == ":") == 1  # the boundary


def test_refine_accepts_progress_true(capsys):
    from appdyn import ocp
    from appdyn.ocp.examples import min_energy

    sol = ocp.refine(min_energy(), N=6, tol=1e-6, progress=True)
    assert sol.success
    out, err = capsys.readouterr()
    rounds = len(sol.refinement)
    assert out == "" and f"100% {rounds}/{rounds}" in err  # a bar of the rounds, on stderr


def test_impact_result():
    from appdyn.dynamics.mechanisms import central_collision, falling_bar_impact
    res = central_collision(1.0, 2.0, 3.0, -1.0, e=0.5)
    data = check_protocol(res)
    assert data["status"] == 0 and data["regime"] == res.regime
    text = str(res)
    assert "[N s]" in text or "N s" in text
    jam = falling_bar_impact(1.0, 1.0, -5.0, 1.0, e=0.0, mu=math.inf)
    assert not jam.success and jam.status == -1 and strict(jam.to_json())["status"] == -1


def test_every_public_result_class_follows_the_protocol():
    """Enumerated from the packages' public names: a class named like a result, report or
    solution inherits `Result` (so a new one cannot be written by hand)."""
    import inspect

    seen = set()
    for mod in _library_modules():
        for name in getattr(mod, "__all__", ()):
            obj = getattr(mod, name, None)
            if inspect.isclass(obj) and name.endswith(("Result", "Report", "Solution")):
                seen.add(obj)
    assert len(seen) >= 15, seen
    outside = sorted(c.__qualname__ for c in seen if not issubclass(c, Result))
    assert not outside, outside


def _library_modules():
    """The public modules of appdyn.dynamics, appdyn.ocp and appdyn.problems (the CLI aside)."""
    import importlib
    import pkgutil

    mods = []
    for pkg in ("appdyn.dynamics", "appdyn.ocp", "appdyn.problems"):
        root = importlib.import_module(pkg)
        mods += [root] + [importlib.import_module(m.name) for m in
                          pkgutil.walk_packages(root.__path__, pkg + ".")
                          if not m.name.split(".")[-1].startswith("_") and ".cli" not in m.name]
    return mods


def _result_classes():
    """Every `Result` subclass defined in the library's modules (the CLI's printouts aside)."""
    import inspect

    return {obj for mod in _library_modules() for obj in vars(mod).values()
            if inspect.isclass(obj) and issubclass(obj, Result) and obj is not Result}


def test_every_result_class_declares_an_int_status():
    """``status`` is declared an int by every result class (a field annotated ``int`` or a
    property returning ``int``); the batched simulate result holds one int per run. No
    string statuses: IPOPT's text is ``solver_status`` (issue 33)."""
    import dataclasses
    import inspect
    import typing

    from appdyn.dynamics.integrate.batch import BatchResult

    classes = _result_classes()
    assert len(classes) >= 20, classes
    declared = {}
    for cls in classes:
        attr = inspect.getattr_static(cls, "status", None)
        if isinstance(attr, property):
            declared[cls.__qualname__] = typing.get_type_hints(attr.fget).get("return")
        elif dataclasses.is_dataclass(cls) and "status" in {f.name
                                                             for f in dataclasses.fields(cls)}:
            declared[cls.__qualname__] = typing.get_type_hints(cls).get("status")
    expected = {name: (np.ndarray if name == BatchResult.__qualname__ else int)
                for name in declared}
    assert declared == expected
    missing = sorted(c.__qualname__ for c in classes if c.__qualname__ not in declared)
    assert not missing, missing  # every result has a status


def test_optimal_control_statuses_are_one_table_of_ints():
    """`ocp.status`: IPOPT's return statuses keep IPOPT's numbers (``IpReturnCodes_inc.h``),
    appdyn's own codes do not collide with them, and a solve carries both the int and
    IPOPT's text."""
    from appdyn import ocp
    from appdyn.ocp import status as st
    from appdyn.ocp.examples import min_energy
    from tests.ocp.reference import brachistochrone

    # IPOPT's enum ApplicationReturnStatus (independent truth: IPOPT's header)
    names = ("Solve_Succeeded", "Solved_To_Acceptable_Level", "Infeasible_Problem_Detected",
             "User_Requested_Stop", "Maximum_Iterations_Exceeded", "Maximum_WallTime_Exceeded",
             "Invalid_Number_Detected", "Internal_Error")
    assert [st.status_code(n) for n in names] == [0, 1, 2, 5, -1, -5, -13, -199]
    codes = list(st.CODES.values())
    assert len(set(codes)) == len(codes) and all(type(c) is int for c in codes)
    assert not set(st.APPDYN_CODES.values()) & set(st.IPOPT_CODES.values())
    assert all(st.status_name(st.status_code(n)) == n for n in st.CODES)
    assert st.status_code("Not_A_Status") == st.STATUS_UNKNOWN
    sol = ocp.solve(min_energy(), N=10)
    assert sol.success and sol.status == 0 and type(sol.status) is int
    assert sol.solver_status == "Solve_Succeeded"
    data = strict(sol.to_json())
    assert data["status"] == 0 and data["solver_status"] == "Solve_Succeeded"
    problem, truth = brachistochrone()
    failed = ocp.solve(problem, N=8, guess=truth["guess"], ipopt_options={"max_iter": 2})
    assert not failed.success and failed.status == st.STATUS_MAX_ITER == -1
    assert failed.solver_status == "Maximum_Iterations_Exceeded"
    assert strict(failed.to_json())["status"] == -1
