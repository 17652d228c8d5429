"""Switch-time polish (`ocp.refine.switch_times`, `polish_switches(method=...)`): the arc
durations of a bang-bang solution solved directly, against closed forms and Bilimoria & Wie
(1993); the moving-knot fallback on singular and constrained arcs."""
import math

import casadi as ca
import numpy as np
import pytest

from appdyn.dynamics.model import Model
from appdyn.ocp import Problem, RadauConstantControl, find_switches, polish_switches, solve
from appdyn.ocp.refine.switch_times import bang_arcs, optimize_switch_times
from appdyn.problems import slew
from appdyn.ocp.status import (STATUS_BOUND_VIOLATION, STATUS_MAX_ITER, STATUS_SUCCESS,
                               STATUS_WALL_TIME, STATUS_WORSE)

from .reference import STRICT, bang_bang, double_integrator, min_energy

# Bilimoria & Wie (1993), J = E, |u_i| <= 1, rest to rest by 180 deg about z: best known
# T = 3.2431 (3.24308 to the digits of the literature); the eigenaxis maneuver takes 2 sqrt(pi)
BW_T = 3.2430833


@pytest.mark.parametrize("distance, accel", [(1.0, 1.0), (2.0, 0.5)])
def test_double_integrator_closed_form_in_a_few_iterations(distance, accel):
    """x'' = u, |u| <= a, rest to rest over d: T = 2 sqrt(d/a), one switch at T/2."""
    problem, truth = bang_bang(distance, accel)
    T_star = truth["T"]
    start = solve(problem, N=7)  # odd N: the switch is smeared inside an interval
    # (its control polynomial overshoots the bound there: not a success, still a start)
    assert start.status == STATUS_BOUND_VIOLATION and abs(start.T - T_star) > 1e-4
    sol = polish_switches(problem, start)
    assert sol.success and sol.status == STATUS_SUCCESS, sol.message
    assert sol.info["method"] == "switch-times" and "fallback" not in sol.info
    assert sol.iterations <= 8
    assert abs(sol.T - T_star) < 1e-10
    np.testing.assert_allclose(sol.info["switch_times"], [T_star / 2], atol=1e-10)
    np.testing.assert_allclose(find_switches(sol), [T_star / 2], atol=1e-10)
    assert isinstance(sol.transcription, RadauConstantControl)
    np.testing.assert_allclose(np.abs(sol.u), accel, rtol=0, atol=1e-14)  # bang values exactly
    assert sol.constraint_violation < 1e-9 and sol.propagation_error < 1e-9
    # costates of H = 1 + l1 v + l2 u: l1 constant, l2 linear, changing sign at the switch
    lam = sol.costates
    assert lam.shape == sol.x.shape
    np.testing.assert_allclose(lam[0], lam[0, 0], atol=1e-8)
    assert np.all(lam[1][sol.t < T_star / 2 - 1e-9] < 0) and np.all(lam[1][sol.t > T_star / 2 + 1e-9] > 0)
    x, _ = sol.sample(sol.t0 + T_star)
    np.testing.assert_allclose(x, [distance, 0.0], atol=1e-12)


@pytest.mark.slow
def test_bilimoria_wie_switch_times_under_30_iterations():
    # the polynomial-control seed (its control overshoots |u| <= 1 between the nodes: not a
    # success as an answer, the polish's start all the same)
    start = slew.time_optimal(np.eye(3), angle=np.pi, axis=[0, 0, 1], u_max=1.0, polish=False,
                              control="polynomial")
    assert start.status == STATUS_BOUND_VIOLATION and abs(start.T - BW_T) < 1e-3
    problem = start.problem
    arcs, why = bang_arcs(start)
    assert why == "" and arcs.durations.size == 6 and arcs.switch_times.size == 5
    np.testing.assert_array_equal(np.abs(arcs.controls), 1.0)
    sol = polish_switches(problem, start, degree=5, ipopt_options={"tol": 1e-9})
    assert sol.success and sol.status == STATUS_SUCCESS, sol.message
    assert sol.info["method"] == "switch-times"
    assert sol.iterations < 30
    assert abs(sol.T - BW_T) < 1e-6 and round(sol.T, 5) == 3.24308
    assert sol.T < 3.2431 < 2 * math.sqrt(math.pi)  # the literature value and the eigenaxis
    assert sol.T < start.T
    assert sol.info["integration_error"] < 1e-10
    # Pontryagin: u_i = -sign(lambda_w,i) (H = 1 + lambda . f, J = E) away from the switches
    away = np.min(np.abs(sol.t[:, None] - sol.info["switch_times"][None, :]), axis=1) > 1e-3
    assert np.all(sol.u[:, away] * sol.costates[4:, away] < 0)
    graded = slew.verify(sol)  # re-simulated: pointing and rate within 1e-6
    assert graded.success, graded.message
    assert graded.info["pointing_error"] < 1e-8 and graded.info["final_rate_error"] < 1e-8
    # integration error: twice the segments move T by less than 1e-10
    finer = optimize_switch_times(problem, start, N=2 * sol.info["N"], degree=5)
    assert finer.success and abs(finer.T - sol.T) < 1e-10
    # the symmetric structure of the optimum: arcs 1 = 3 = 4 = 6 and 2 = 5
    d = sol.info["durations"]
    np.testing.assert_allclose(d[[2, 3, 5]], d[0], rtol=1e-7)
    np.testing.assert_allclose(d[4], d[1], rtol=1e-7)


@pytest.mark.slow
def test_time_optimal_uses_the_switch_time_polish():
    sol = slew.time_optimal(np.eye(3), angle=np.pi, axis=[0, 0, 1], u_max=1.0)
    assert sol.success and sol.status == STATUS_SUCCESS, sol.message
    assert sol.info["method"] == "switch-times" and sol.info["nlp_iterations"][-1] < 30
    assert abs(sol.T - BW_T) < 1e-6 and sol.info["pointing_error"] < 1e-8
    # the eigenaxis start alone ends at the eigenaxis local optimum: x and y torques idle
    # (zero throughout), z bang-bang: the switch-time polish holds x and y at zero and gives
    # the eigenaxis time 2 sqrt(pi) exactly (it was refused as not bang-bang, the moving
    # knots tried and not kept)
    eig = slew.time_optimal(np.eye(3), angle=np.pi, axis=[0, 0, 1], u_max=1.0, starts=1)
    assert eig.success and eig.T == pytest.approx(2 * math.sqrt(math.pi), rel=1e-10)
    arcs, _ = bang_arcs(slew.time_optimal(np.eye(3), angle=np.pi, axis=[0, 0, 1], u_max=1.0,
                                          starts=1, polish=False))
    np.testing.assert_array_equal(arcs.controls[:2], 0.0)
    np.testing.assert_array_equal(arcs.controls[2], [1.0, -1.0])
    assert eig.info["polish"]["method"] == "switch-times" and eig.info["polish"]["used"]


def _singular():
    """x' = u, |u| <= 1, x(0) = 1, T = 2, min int x^2 / 2: u = -1 on [0, 1], then the
    singular arc x = u = 0; J = 1/6."""
    xs, us, ps = ca.SX.sym("x"), ca.SX.sym("u"), ca.SX.sym("p", 0)
    model = Model(ca.Function("f", [xs, us, ps], [us], ["x", "u", "p"], ["xdot"]), ("x",), ("u",))
    return Problem(model, T=2.0, x_initial=[1.0], u_bounds=(-1.0, 1.0),
                   lagrange=lambda x, u, p: 0.5 * x ** 2)


def test_singular_arc_falls_back_to_moving_knots():
    problem = _singular()
    start = solve(problem, N=16, ipopt_options=STRICT, backoff=False)
    # the control polynomial rings on the singular arc, past |u| <= 1: not a success
    assert start.status == STATUS_BOUND_VIOLATION
    arcs, why = bang_arcs(start)
    assert arcs is None and "singular" in why
    sol = polish_switches(problem, start)
    assert sol.info["method"] == "moving-knots" and "not bang-bang" in sol.info["fallback"]
    assert sol.success, sol.message
    assert sol.cost == pytest.approx(1 / 6, abs=1e-7)
    with pytest.raises(ValueError, match="bang-bang"):
        polish_switches(problem, start, method="switch-times")
    with pytest.raises(ValueError, match="bang-bang"):
        optimize_switch_times(problem, start)


def test_bang_coast_bang_falls_back_to_moving_knots():
    """|v| <= v_max as a path constraint: bang, coast (u = 0), bang."""
    v_max, d = 0.6, 1.0
    problem = Problem(double_integrator(), T=(0.1, 10.0), x_initial=[0, 0], x_final=[d, 0],
                      u_bounds={"u": (-1, 1)}, path=lambda x, u, p: x[1] - v_max,
                      mayer=lambda xf, p, T: T)
    sol = polish_switches(problem, solve(problem, N=10))
    assert sol.success and sol.info["method"] == "moving-knots"
    assert "interior" in sol.info["fallback"] or "singular" in sol.info["fallback"]
    assert abs(sol.T - (2 * v_max + (d - v_max ** 2) / v_max)) < 1e-8


def test_failed_switch_time_nlp_falls_back_or_reports():
    problem, truth = bang_bang()
    start = solve(problem, N=7)
    failed = polish_switches(problem, start, method="switch-times", ipopt_options={"max_iter": 1})
    assert not failed.success and failed.status == STATUS_MAX_ITER
    assert failed.info["method"] == "switch-times"
    rescued = polish_switches(problem, start, N=8, ipopt_options={"max_iter": 1})
    assert rescued.info["method"] == "moving-knots"
    assert "switch-time NLP failed" in rescued.info["fallback"]
    assert not rescued.info["switch_time_solution"].success
    knots = polish_switches(problem, start, method="moving-knots")
    assert knots.success and knots.info["method"] == "moving-knots" and "fallback" not in knots.info
    assert abs(knots.T - truth["T"]) < 1e-8


def test_bang_arcs_refusals_and_arguments():
    problem, _ = min_energy()  # unbounded control
    arcs, why = bang_arcs(solve(problem, N=4))
    assert arcs is None and "not bounded" in why
    problem, _ = bang_bang()
    start = solve(problem, N=7)
    with pytest.raises(ValueError, match="`method`"):
        polish_switches(problem, start, method="newton")
    with pytest.raises(ValueError, match="`N`"):
        optimize_switch_times(problem, start, N=3)
    with pytest.raises(TypeError, match="`solution`"):
        optimize_switch_times(problem, None)


def test_fixed_horizon_maximize_and_mayer_on_the_state():
    """x'' = u, |u| <= 1, from rest, T = 2 fixed, stop at T: max x(T) = 1, switch at t = 1."""
    problem = Problem(double_integrator(), T=2.0, x_initial=[0.0, 0.0], x_final=[None, 0.0],
                      u_bounds=(-1.0, 1.0), mayer=lambda xf, p, T: xf[0], maximize=True)
    start = solve(problem, N=9)
    sol = polish_switches(problem, start)
    assert sol.success and sol.info["method"] == "switch-times", sol.message
    assert sol.T == 2.0 and abs(sol.cost - 1.0) < 1e-12
    np.testing.assert_allclose(sol.info["switch_times"], [1.0], atol=1e-12)


def test_running_cost_and_a_free_parameter():
    """x'' = a u, |u| <= 1, a in [0.5, 2] free, min int 1 dt over rest to rest by 1: a = 2,
    T = sqrt(2), switch at T/2; the costates agree with those of the Mayer statement."""
    xs, us, ps = ca.SX.sym("x", 2), ca.SX.sym("u"), ca.SX.sym("a")
    model = Model(ca.Function("f", [xs, us, ps], [ca.vertcat(xs[1], ps * us)], ["x", "u", "p"],
                              ["xdot"]), ("x", "v"), ("u",), ("a",), p_default=[1.0])
    kw = dict(T=(0.1, 10.0), x_initial=[0.0, 0.0], x_final=[1.0, 0.0], u_bounds=(-1.0, 1.0),
              p_bounds={"a": (0.5, 2.0)})
    by_L = Problem(model, lagrange=lambda x, u, p: 1.0 + 0 * u, **kw)
    by_phi = Problem(model, mayer=lambda xf, p, T: T, **kw)
    out = []
    for problem in (by_L, by_phi):
        sol = polish_switches(problem, solve(problem, N=9, ipopt_options=STRICT))
        assert sol.success and sol.info["method"] == "switch-times", sol.message
        assert abs(sol.T - math.sqrt(2)) < 1e-10 and abs(sol.cost - math.sqrt(2)) < 1e-10
        assert abs(sol.p[0] - 2.0) < 1e-10
        np.testing.assert_allclose(sol.info["switch_times"], [math.sqrt(2) / 2], atol=1e-10)
        out.append(sol)
    np.testing.assert_allclose(out[0].costates, out[1].costates, atol=1e-7)


@pytest.mark.slow
def test_an_arc_too_short_to_detect_is_tried_second():
    """J = diag(1, 1.5, 2), 2 rad about (1, 2, 3): the optimum ends with a 2.5e-4 s arc of
    all three torques at -1, inside the last mesh interval of the start (N = 30): the
    five detected arcs cannot meet the six end conditions (IPOPT: infeasible); the second
    guess inserts the short arc and converges at once."""
    J, angle, axis = np.diag([1.0, 1.5, 2.0]), 2.0, [1, 2, 3]
    start = slew.time_optimal(J, angle=angle, axis=axis, polish=False, control="polynomial")
    assert start.status == STATUS_BOUND_VIOLATION  # the polynomial seed (see above)
    plain, _ = bang_arcs(start)
    more, _ = bang_arcs(start, short_arcs=True)
    assert more.durations.size > plain.durations.size
    sol = polish_switches(start.problem, start, degree=5, ipopt_options={"tol": 1e-9})
    assert sol.success and sol.info["method"] == "switch-times", sol.message
    assert sol.info["durations"].size == 6 and sol.info["durations"][-1] < 1e-3
    assert sol.iterations < 30 and abs(sol.T - 3.0123147841) < 1e-8 and sol.T < start.T
    graded = slew.verify(sol)
    assert graded.success and graded.info["pointing_error"] < 1e-8


@pytest.mark.slow
def test_an_arc_smeared_within_one_mesh_interval_still_gives_the_switch_structure():
    """J = diag(1, 2, 3), 1 rad about (1, 1, 1): a 0.049 s arc at the start sits inside one
    mesh interval (0.079 s) of the first solve, where the control polynomial smears it. It
    is read by its median side; the switch-time optimum agrees with the moving-knot polish
    (a second formulation) to its collocation error and is not slower."""
    sol = slew.time_optimal(np.diag([1.0, 2.0, 3.0]), angle=1.0, axis=[1, 1, 1], u_max=1.0)
    assert sol.success and sol.info["method"] == "switch-times"
    problem = slew.slew_problem(np.diag([1.0, 2.0, 3.0]), objective="time", angle=1.0,
                                axis=[1, 1, 1], u_max=1.0)
    knots = polish_switches(problem, solve(problem, N=30, guess=slew.attitude_guess(problem)),
                            method="moving-knots", degree=5)
    assert knots.success
    assert sol.T <= knots.T + 1e-9
    assert abs(sol.T - knots.T) < 1e-6


@pytest.mark.slow
def test_another_target_reuses_the_switch_time_nlp_and_matches_a_fresh_build():
    """The switch-time NLP is built once per switching structure, the target and scales
    as parameters: a slew to another target with the same arcs builds nothing, and gives
    the same answer as an NLP built afresh for it (cache emptied)."""
    from appdyn.dynamics import cache, clear_caches

    def first_and_problem(axis):
        start = slew.time_optimal(np.eye(3), angle=2.0, axis=axis, u_max=1.0, polish=False,
                                  control="polynomial", starts=1)
        assert start.status == STATUS_BOUND_VIOLATION  # the polynomial seed (see above)
        return start.problem, start

    p1, s1 = first_and_problem([0.2, 1.0, 0.5])
    p2, s2 = first_and_problem([0.25, 1.0, 0.45])  # a neighbour: the same switching structure
    a1, a2 = bang_arcs(s1)[0], bang_arcs(s2)[0]
    assert a1.durations.size == a2.durations.size
    np.testing.assert_array_equal(a1.controls, a2.controls)
    one = optimize_switch_times(p1, s1, N=30)
    entries = cache.info().kinds.get("appdyn.ocp.switch_times_nlp", 0)
    two = optimize_switch_times(p2, s2, N=30)
    assert cache.info().kinds.get("appdyn.ocp.switch_times_nlp", 0) == entries  # nothing new built
    assert two.build_time < 0.25 * one.build_time
    clear_caches()
    fresh = optimize_switch_times(p2, s2, N=30)
    assert one.success and two.success and fresh.success
    assert abs(two.T - fresh.T) < 1e-12 and two.T != one.T
    np.testing.assert_allclose(two.info["switch_times"], fresh.info["switch_times"], atol=1e-12)
    # the target is met (independently of the NLP): re-simulated pointing error
    assert two.pointing_error < 1e-8


# ------------------------------------------------- never worse, a budget, quiet stdout
def test_a_polish_worse_than_its_start_is_not_a_success():
    """The brachistochrone's start is the cycloid to 1e-8 (closed form); a piecewise-constant
    angle on 2 free intervals cannot get within 1e-3 of it: not a success, and it says so."""
    from .reference import brachistochrone

    problem, truth = brachistochrone()
    start = solve(problem, N=20, guess=truth["guess"])
    assert start.success and start.T == pytest.approx(truth["T"], rel=1e-7)
    coarse = polish_switches(problem, start, N=2)
    assert coarse.T > truth["T"] * (1 + 1e-3)  # worse than the exact optimum, by physics
    assert not coarse.success and coarse.status == STATUS_WORSE, coarse.message
    assert "worse than the start" in coarse.message
    assert coarse.info["gain"] == pytest.approx(start.T - coarse.T) and coarse.info["gain"] < 0
    # as fine as the start: within the slack of the exact optimum, a success
    fine = polish_switches(problem, start)
    assert fine.success, fine.message
    assert abs(fine.T - truth["T"]) <= 1e-3 * truth["T"]


def test_budget_stops_the_polish_and_says_so():
    problem, truth = bang_bang()
    start = solve(problem, N=7)
    free = polish_switches(problem, start)
    assert free.success and free.info["budget"] is None
    assert free.info["gain"] == pytest.approx(start.T - truth["T"], abs=1e-9)  # T exact
    ample = polish_switches(problem, start, budget=60.0)
    assert ample.success and ample.T == pytest.approx(free.T, abs=1e-12)
    assert ample.info["wall_time"] <= 60.0
    spent = polish_switches(problem, start, budget=1e-6)  # over before IPOPT's first iteration
    assert not spent.success and spent.status == STATUS_WALL_TIME, spent.message
    assert "budget" in spent.message
    with pytest.raises(ValueError, match="`budget`"):
        polish_switches(problem, start, budget=0.0)
    # not bang-bang (the brachistochrone's angle is smooth): the moving knots, out of time
    from .reference import brachistochrone

    smooth, truth = brachistochrone()
    first = solve(smooth, N=20, guess=truth["guess"])
    cut = polish_switches(smooth, first, budget=1e-6)
    assert not cut.success and cut.status == STATUS_WALL_TIME, cut.message
    assert cut.info["budget_spent"] and "budget" in cut.message


def test_verbose_polish_prints_labelled_lines_to_stderr_only(capfd):
    problem, _ = bang_bang()
    start = solve(problem, N=7)
    capfd.readouterr()
    sol = polish_switches(problem, start, verbose=True)
    out, err = capfd.readouterr()
    assert sol.success and sol.info["method"] == "switch-times"
    assert out == ""  # no IPOPT output on stdout (it printed its own banner and table there)
    lines = err.strip().splitlines()
    assert lines and all(line.startswith("[polish] ") for line in lines)
    assert len(lines) == 1 + sum(n + 1 for n in sol.info["nlp_iterations"])  # header + iterates
