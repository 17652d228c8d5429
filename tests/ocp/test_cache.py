"""The engine keeps what it builds repeatedly in the one cache (`dynamics.cache`)."""
from __future__ import annotations

import numpy as np

from appdyn import ocp
from appdyn.dynamics import cache, clear_caches
from tests.ocp.reference import bang_bang, min_energy


def _ocp_kinds():
    return {k: n for k, n in cache.info().kinds.items() if k.startswith("appdyn.ocp.")}


def test_per_model_functions_are_built_once_and_cleared():
    clear_caches()
    problem, _ = min_energy()
    tr = ocp.get_transcription("radau")
    f, L = problem.model.f, problem.lagrange
    assert tr.kernel(f, L) is tr.kernel(f, L)
    assert tr.interpolant(f) is tr.interpolant(f)
    assert tr.kernel(f, L) is not ocp.get_transcription("trapezoid").kernel(f, L)
    sol = ocp.solve(problem, N=8)
    assert sol.propagation.success
    kinds = _ocp_kinds()
    for kind in ("appdyn.ocp.kernel", "appdyn.ocp.interpolant", "appdyn.ocp.interval_integrator", "appdyn.ocp.propagator",
                 "appdyn.ocp.nlpsol"):
        assert kinds.get(kind, 0) >= 1, kinds
    ocp.interval_errors(sol)
    assert _ocp_kinds().get("appdyn.ocp.interval_check", 0) == 1
    clear_caches()
    assert _ocp_kinds() == {}


def test_second_solve_with_another_guess_reuses_the_solver():
    clear_caches()
    problem, truth = bang_bang()
    # bang-bang: a piecewise-constant control (the Radau polynomial overshoots |u| <= 1)
    first = ocp.solve(problem, N=12, control="constant")
    hits = cache.info().hits
    again = ocp.solve(problem, N=12, guess={"T": 4.5}, control="constant")  # another start
    assert first.success and again.success
    assert _ocp_kinds()["appdyn.ocp.nlpsol"] == 1 and cache.info().hits > hits
    assert abs(again.T - truth["T"]) < 1e-6 and abs(first.T - again.T) < 1e-7
    # another mesh, options or a progress listener build their own
    seen = []
    other = ocp.solve(problem, N=12, progress=seen.append, control="constant")
    assert other.success and seen
    assert ocp.solve(problem, N=12, ipopt_options={"tol": 1e-9}, control="constant").success
    assert _ocp_kinds()["appdyn.ocp.nlpsol"] == 2


def test_cached_solver_gives_the_same_answer_as_a_fresh_one():
    problem, truth = min_energy()
    clear_caches()
    cold = ocp.solve(problem, N=10, guess={"T": 1.0})
    warm = ocp.solve(problem, N=10, guess={"T": 1.0})
    np.testing.assert_array_equal(cold.x, warm.x)
    np.testing.assert_array_equal(cold.u, warm.u)
    assert abs(warm.cost - truth["J"]) < 1e-8
