"""Mesh refinement, multistart and moving-knot polishing against closed forms.

* Minimum-time rest-to-rest double integrator, |u| <= 1, distance d: T* = 2 sqrt(d), one
  switch at T*/2 (Bryson & Ho 1975).
* The same with a speed limit v <= v_max (bang-coast-bang): T* = 2 v_max + (d - v_max^2)/v_max,
  switches at v_max and T* - v_max.
* Smooth problems: brachistochrone (cycloid), rigid-body minimum-effort slew (cubic timing).
* Bilimoria & Wie (1993): time-optimal 180 deg rest-to-rest slew about z of a body with
  J = I, |u_i| <= 1: T* ~ 3.243 (3.2430833 from `refine` here); the eigenaxis maneuver,
  T = 2 sqrt(pi) = 3.5449, is a local optimum.
"""
from __future__ import annotations

import math
import time

import numpy as np
import pytest

from appdyn.dynamics import rigid_body
from appdyn.dynamics.attitude import quat_from_axis_angle
from appdyn.ocp import (Problem, RadauConstantControl, RefinedSolution, RefinementRound, Solution,
                 find_switches, interval_errors, polish_switches, refine, solve, solve_multistart)
from appdyn.ocp.status import STATUS_BOUND_VIOLATION, STATUS_INFEASIBLE, STATUS_MAX_ITER

from .reference import STRICT, bang_bang, brachistochrone, double_integrator, min_energy, rigid_slew


def _knots(sol):
    return sol.t0 + sol.T * sol.mesh.breaks


# ------------------------------------------------------------------- Bilimoria-Wie slew
def bilimoria_wie():
    return Problem(rigid_body(np.eye(3)), T=(0.5, 10.0), x_initial=[0, 0, 0, 1, 0, 0, 0],
                   x_final={"w1": 0.0, "w2": 0.0, "w3": 0.0}, q_final=[0.0, 0.0, 1.0, 0.0],
                   u_bounds=((-1, -1, -1), (1, 1, 1)), mayer=lambda xf, p, T: T)


def axis_guess(axis, T=3.5, n=61):
    """A 180 deg rotation about a fixed ``axis`` with cubic timing (the prototype's guess):
    about z it is the eigenaxis maneuver, about a tilted axis it leads to the true optimum."""
    ax = np.asarray(axis, float) / np.linalg.norm(axis)
    s = np.linspace(0.0, 1.0, n)
    angle = math.pi * (3 * s ** 2 - 2 * s ** 3)
    q = np.stack([quat_from_axis_angle(ax, a) for a in angle], axis=1)
    w = np.gradient(angle, s * T)[None, :] * ax[:, None]
    u = np.clip(np.gradient(w, s * T, axis=1), -1, 1)
    return {"t": s * T, "x": np.vstack([q, w]), "u": u, "T": T}


TILTED = (0.3, -0.4, 1.0)


# ============================================================================= refine
def test_refine_bang_bang_reduces_T_error_and_concentrates_at_the_switch():
    problem, truth = bang_bang()
    T_star = truth["T"]
    # odd N: switch inside an interval. A linear control: the Radau polynomial overshoots
    # the bound around a switch inside an interval however small (a Bound_Violation)
    sol = refine(problem, N=7, tol=1e-6, ipopt_options=STRICT, control="linear")
    assert isinstance(sol, RefinedSolution) and isinstance(sol, Solution)
    assert sol.success and sol.info["converged"], sol.message
    hist = sol.refinement
    assert all(isinstance(h, RefinementRound) for h in hist)
    assert len(hist) >= 4 and hist[0].n_intervals == 7
    errors = [abs(h.cost - T_star) for h in hist]
    assert errors[0] > 1e-3 and errors[-1] < 1e-10
    for a, b in zip(errors, errors[1:]):  # monotone, down to the NLP tolerance
        assert b < a or b < 1e-10
    assert hist[-1].max_error <= 1e-6 < hist[0].max_error
    # the smallest intervals sit at the switch, the interval holding it is tiny
    t = _knots(sol)
    h = np.diff(t)
    k = np.searchsorted(t, T_star / 2) - 1
    assert h[k] < 1e-5 * sol.T
    smallest = np.argsort(h)[:6]
    assert np.all(np.abs(t[smallest] - T_star / 2) < 0.01 * sol.T)
    assert np.median(h) > 1e3 * h[k]
    assert sol.mesh.N <= 25
    np.testing.assert_allclose(find_switches(sol), [T_star / 2], atol=1e-5)


def test_refine_smooth_problem_reaches_tolerance_of_propagation():
    problem, truth = brachistochrone()
    tol = 1e-6
    sol = refine(problem, N=4, tol=tol, guess=truth["guess"], ipopt_options=STRICT)
    assert sol.success and sol.info["converged"]
    assert len(sol.refinement) >= 2 and sol.mesh.N > 4
    assert sol.info["errors"].max_error <= tol
    assert sol.propagation_error < tol
    assert abs(sol.T - truth["T"]) < 1e-8
    assert not np.any(sol.info["errors"].switching)


def test_refine_rigid_slew_with_quaternions():
    problem, truth = rigid_slew(theta_f=1.0, T=2.0)
    sol = refine(problem, N=4, tol=1e-6, ipopt_options=STRICT)
    assert sol.success and sol.info["converged"]
    assert sol.propagation_error < 1e-6
    assert abs(sol.cost - truth["J"]) < 1e-8


def test_refine_keeps_an_accurate_solution_and_reuses_it():
    problem, truth = min_energy()  # cubic state: Radau(3) is exact on any mesh
    first = solve(problem, N=3, verbose=False, ipopt_options=STRICT)
    sol = refine(problem, first, tol=1e-8)
    assert sol.success and sol.info["converged"] and sol.mesh == first.mesh
    assert len(sol.refinement) == 1 and sol.refinement[0].iterations == first.iterations
    assert abs(sol.cost - truth["J"]) < 1e-9


def test_refine_other_transcriptions_and_limits():
    problem, truth = brachistochrone()
    hs = refine(problem, N=4, tol=1e-6, transcription="hermite-simpson", guess=truth["guess"],
                ipopt_options=STRICT)
    assert hs.success and hs.info["converged"] and hs.transcription.name == "hermite-simpson"
    assert hs.propagation_error < 1e-6
    # trapezoid needs far more intervals than allowed: stops at the limit, still a solution
    tz = refine(problem, N=4, tol=1e-8, transcription="trapezoid", guess=truth["guess"],
                max_intervals=40, ipopt_options=STRICT)
    assert tz.success and not tz.info["converged"]
    assert tz.mesh.N <= 40 and "max_intervals" in tz.message
    assert "max_intervals" in tz.info["stop"]
    one = refine(problem, N=4, tol=1e-12, max_rounds=1, guess=truth["guess"])
    assert one.success and not one.info["converged"] and len(one.refinement) == 2
    assert "max_rounds" in one.message


def test_refine_failure_returns_success_false():
    # |u| <= 0.1 cannot move the mass 1 in T = 1
    problem = Problem(double_integrator(), T=1.0, x_initial=[0, 0], x_final=[1, 0],
                      u_bounds={"u": (-0.1, 0.1)}, lagrange=lambda x, u, p: u ** 2)
    sol = refine(problem, N=6, tol=1e-6)
    assert isinstance(sol, RefinedSolution)
    assert sol.success is False and sol.status == STATUS_INFEASIBLE
    assert "refine" in sol.message and sol.solver_status in sol.message
    assert len(sol.refinement) == 1 and math.isnan(sol.refinement[0].max_error)
    assert not sol.info["converged"]


def test_refine_rejects_bad_arguments():
    problem, _ = min_energy()
    with pytest.raises(ValueError, match="`tol`"):
        refine(problem, tol=0.0)
    with pytest.raises(ValueError, match="`max_rounds`"):
        refine(problem, max_rounds=-1)
    with pytest.raises(ValueError, match="`max_intervals`"):
        refine(problem, max_intervals=0)
    with pytest.raises(TypeError, match="`problem`"):
        refine("problem")
    with pytest.raises(TypeError, match="`backoff`"):
        refine(problem, backoff="yes")


@pytest.mark.parametrize("l", [1 / 9, 1 / 12])
def test_an_overshoot_at_an_active_state_bound_is_backed_off_to_the_closed_form(l):
    """Bryson-Denham with x <= l a state bound, checked to 1e-10 of its scale: the
    position interpolant bulges past l between the nodes at the ends of the boundary arc
    (1e-8 of its scale, on 20 to 43 intervals alike) while the error estimate meets tol.
    Without the back-off that is a stalled failure naming the overshoot; with it, the bound
    moved in by twice the overshoot gives a success whose dense position never exceeds l
    (sampled on a grid of its own), at the closed-form cost J = 4 / (9 l) of the tightened
    bound (to the collocation's accuracy) and above the untightened round's."""
    from .reference import bryson_denham
    problem, truth = bryson_denham(l, as_bound=True)
    kw = dict(tol=1e-7, bound_tol=1e-10, ipopt_options={"tol": 1e-12})
    stalled = refine(problem, backoff=False, **kw)
    assert not stalled.success and "meets tol" in stalled.message
    assert "leaves a bound: `x`" in stalled.message and stalled.bound_violation.max > 1e-9
    sol = refine(problem, **kw)
    assert sol.success, sol.message
    assert sol.problem is problem and sol.bound_violation.max == 0.0
    x, _ = sol.sample(np.linspace(0.0, 1.0, 100001))
    assert np.max(x[0]) <= l
    bo = sol.info["backoff"]
    margin = bo["margins"]["x"][1]
    assert bo["margins"]["x"][0] == 0.0 and 0 < margin < 1e-3 * l
    assert bo["cost_without"] < sol.cost
    assert abs(sol.cost - 4.0 / (9.0 * (l - margin))) < 1e-6
    assert "moved inwards" in sol.message and sol.info["converged"]


# ===================================================================== error estimate
def test_interval_errors_flag_the_switch_interval():
    problem, truth = bang_bang()
    sol = solve(problem, N=7, verbose=False, ipopt_options=STRICT)
    est = interval_errors(sol)
    assert est.error.shape == (7,)
    assert list(np.flatnonzero(est.switching)) == [3]
    assert abs(est.switch_time[3] - sol.T / 2) < 0.01  # impulse-matched estimate
    assert est.switch[3] > 1e-2 and np.all(est.defect[[0, 1, 2, 4, 5, 6]] < 1e-8)
    exact = interval_errors(solve(min_energy()[0], N=3, verbose=False, ipopt_options=STRICT))
    assert exact.max_error < 1e-9 and not np.any(exact.switching)


# ==================================================================== polish_switches
def test_polish_switches_double_integrator_exact_time_and_switch():
    problem, truth = bang_bang()
    T_star = truth["T"]
    start = solve(problem, N=7, verbose=False)  # switch inside an interval: T off by 2e-3
    assert abs(start.T - T_star) > 1e-3
    sol = polish_switches(problem, start)
    assert isinstance(sol, RefinedSolution) and sol.success, sol.message
    assert isinstance(sol.transcription, RadauConstantControl)
    assert abs(sol.T - T_star) < 1e-8
    assert np.min(np.abs(_knots(sol) - T_star / 2)) < 1e-8  # a knot at the switch
    np.testing.assert_allclose(sol.info["switch_times"], [T_star / 2], atol=1e-8)
    np.testing.assert_allclose(np.abs(sol.u), 1.0, atol=1e-8)  # bang-bang, no smearing
    assert sol.propagation_error < 1e-8
    assert sol.x.shape == (2, sol.t.size) and sol.costates is not None


def test_polish_switches_bang_coast_bang_with_path_constraint():
    v_max, d = 0.6, 1.0
    problem = Problem(double_integrator(), T=(0.1, 10.0), x_initial=[0, 0], x_final=[d, 0],
                      u_bounds={"u": (-1, 1)}, path=lambda x, u, p: x[1] - v_max,
                      mayer=lambda xf, p, T: T)
    T_star = 2 * v_max + (d - v_max ** 2) / v_max
    sol = polish_switches(problem, solve(problem, N=10, verbose=False))
    assert sol.success
    assert abs(sol.T - T_star) < 1e-8
    np.testing.assert_allclose(sol.info["switch_times"], [v_max, T_star - v_max], atol=1e-8)


def test_polish_switches_bilimoria_wie_from_a_tilted_start():
    t = time.perf_counter()
    problem = bilimoria_wie()
    start = solve(problem, N=20, guess=axis_guess(TILTED), verbose=False)
    # its Radau control polynomials overshoot |u| <= 1 between the nodes (a Bound_Violation,
    # which also lets its T sit below the polished one); a start for the polish all the same
    assert start.status == STATUS_BOUND_VIOLATION and 3.2428 < start.T < 3.2440
    sol = polish_switches(problem, start)
    elapsed = time.perf_counter() - t
    assert sol.success, sol.message
    assert 3.2428 <= sol.T <= 3.2435
    assert sol.T < start.T
    assert len(sol.info["switch_times"]) >= 5
    assert sol.quaternion_norm_error < 1e-3  # collocation error of 4 intervals per arc
    assert elapsed < 10.0


def test_polish_switches_failure_and_bad_arguments():
    problem, _ = bang_bang()
    start = solve(problem, N=7, verbose=False)
    sol = polish_switches(problem, start, ipopt_options={"max_iter": 2})
    assert sol.success is False and sol.status == STATUS_MAX_ITER
    assert sol.solver_status in sol.message
    with pytest.raises(ValueError, match="`stretch`"):
        polish_switches(problem, start, stretch=(2.0, 5.0))
    with pytest.raises(ValueError, match="`mesh`"):
        polish_switches(problem, start, mesh=[0.0, 1.0])
    with pytest.raises(TypeError, match="`solution`"):
        polish_switches(problem, None)


def test_constant_control_transcription_on_a_fixed_mesh():
    problem, truth = bang_bang()
    sol = solve(problem, N=8, transcription=RadauConstantControl(3), verbose=False,
                ipopt_options=STRICT)  # even N: the switch is a knot
    assert sol.success and abs(sol.T - truth["T"]) < 1e-9
    _, u = sol.sample(np.linspace(sol.t0, sol.t0 + sol.T, 41))
    np.testing.assert_allclose(np.abs(u), 1.0, atol=1e-9)


# ========================================================================= multistart
def test_multistart_picks_the_better_local_optimum():
    problem = bilimoria_wie()
    # None: eigenaxis SLERP. A piecewise-constant control (bang-bang; the Radau polynomial
    # overshoots the bounds): feasible, so T stays above the optimum 3.2430833 (switch-time
    # polish) by its O(h) discretization error (measured 3.24623)
    sol = solve_multistart(problem, [None, axis_guess(TILTED)], N=20, control="constant")
    assert isinstance(sol, RefinedSolution) and sol.success
    starts = sol.starts
    assert [s["index"] for s in starts] == [0, 1] and all(s["success"] for s in starts)
    assert abs(starts[0]["cost"] - 2 * math.sqrt(math.pi)) < 1e-3  # eigenaxis local optimum
    assert 3.24308 < starts[1]["cost"] < 3.2470
    assert sol.info["best"] == 1 and sol.T == pytest.approx(starts[1]["T"])
    assert all(s["time"] > 0 and s["iterations"] > 0 for s in starts)


def test_multistart_start_budget_limits_the_starts_after_a_converged_one():
    """After start 0 converges in k iterations, each later start may take max(200, 10 k)
    (`iteration_budget`); a ``max_iter`` of a start's own options wins (start 1: 3, too few
    to converge: stopped at its budget, and said so); starts that converge within it are
    the unbudgeted ones, bit for bit; with an executor there is no budget."""
    from concurrent.futures import ThreadPoolExecutor
    from appdyn.ocp.ipopt_options import BUDGET_MIN_ITER, iteration_budget

    problem = bilimoria_wie()
    guesses = [None, axis_guess(TILTED), axis_guess(TILTED)]
    tries = [{}, {"ipopt_options": {"max_iter": 3}}, {}]
    kw = dict(N=20, control="constant", start_options=tries)
    sol = solve_multistart(problem, guesses, start_budget=10, **kw)
    free = solve_multistart(problem, guesses, **kw)
    k = sol.starts[0]["iterations"]
    assert sol.starts[0]["success"] and sol.starts[0]["budget"] is None
    assert sol.starts[1]["budget"] == 3 and not sol.starts[1]["success"]
    assert sol.starts[1]["iterations"] == 3 and "start 1 stopped at its iteration budget" in sol.message
    assert sol.starts[2]["budget"] == max(BUDGET_MIN_ITER, 10 * k) == iteration_budget(None, k, 10)[1]
    assert sol.starts[2]["success"] and sol.starts[2]["iterations"] < sol.starts[2]["budget"]
    assert sol.T == free.T and sol.info["best"] == free.info["best"] == 2
    assert all(st["budget"] is None for st in free.starts)
    with ThreadPoolExecutor(max_workers=2) as pool:
        par = solve_multistart(problem, guesses, start_budget=10, executor=pool, **kw)
    assert [st["budget"] for st in par.starts] == [None, None, None] and par.T == free.T
    for bad in (0.5, True, float("inf"), "10"):
        with pytest.raises(ValueError, match="`start_budget`"):
            solve_multistart(problem, guesses, start_budget=bad, **kw)


def test_multistart_without_success_returns_least_infeasible():
    problem = Problem(double_integrator(), T=1.0, x_initial=[0, 0], x_final=[1, 0],
                      u_bounds={"u": (-0.1, 0.1)}, lagrange=lambda x, u, p: u ** 2)
    sol = solve_multistart(problem, [None, {"u": [0.1]}], N=6)
    assert sol.success is False
    assert "none of 2 starts converged" in sol.message
    viol = [s["constraint_violation"] for s in sol.starts]
    assert sol.constraint_violation == pytest.approx(min(viol))
    assert not any(s["success"] for s in sol.starts)


def test_multistart_rejects_bad_guesses():
    problem, _ = min_energy()
    with pytest.raises(ValueError, match="`guesses`"):
        solve_multistart(problem, [])
    with pytest.raises(ValueError, match="`guesses`"):
        solve_multistart(problem, {"T": 1.0})


def test_ignored_mesh_arguments_warn():
    """`N` with a solution and `degree` with a non-Radau transcription are ignored: say so."""
    problem, _ = min_energy()
    first = solve(problem, N=6, verbose=False)
    with pytest.warns(UserWarning, match="`N` is ignored"):
        refine(problem, first, N=50, tol=1e-3, max_rounds=0)
    with pytest.warns(UserWarning, match="`degree` is ignored"):
        refine(problem, N=4, tol=1e-3, max_rounds=0, transcription="trapezoid", degree=5)
