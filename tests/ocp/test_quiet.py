"""The library is quiet by default: progress goes to a callable and to logging."""
import logging

import numpy as np
import pytest

from appdyn.ocp import (LOGGER, Progress, RadauConstantControl, RefinementRound, Solution, get_transcription,
                 refine, solve, solve_multistart)

from .reference import STRICT, bang_bang, min_energy


def test_solve_and_refine_print_nothing_by_default(capfd):
    problem, _ = min_energy()
    refine(problem, N=3, tol=1e-8)
    solve_multistart(problem, [None, None])
    out, err = capfd.readouterr()
    assert out == "" and err == ""


def test_progress_callable_and_logging(caplog):
    problem, _ = min_energy()
    seen = []
    with caplog.at_level(logging.DEBUG, logger=LOGGER.name):
        sol = solve(problem, N=5, progress=seen.append)
    assert LOGGER.name == "appdyn.ocp"
    assert [p.iteration for p in seen] == list(range(sol.iterations + 1))
    assert all(isinstance(p, Progress) for p in seen)
    messages = [r.getMessage() for r in caplog.records if r.name == "appdyn.ocp"]
    assert sum(m.startswith("ipopt") for m in messages) == sol.iterations + 1
    assert any(m.startswith("solve") for m in messages)


def test_refine_progress_receives_rounds(caplog):
    problem, _ = bang_bang()
    rounds = []
    with caplog.at_level(logging.INFO, logger=LOGGER.name):
        sol = refine(problem, N=7, tol=1e-4, max_rounds=2, progress=rounds.append)
    assert rounds == sol.refinement and all(isinstance(r, RefinementRound) for r in rounds)
    assert sum("refine round" in r.getMessage() for r in caplog.records) == len(rounds)


def test_bad_progress_raises():
    problem, _ = min_energy()
    with pytest.raises(TypeError, match="`progress`"):
        solve(problem, N=3, progress="loud")
    with pytest.raises(TypeError, match="`progress`"):
        refine(problem, N=3, progress=1)


def test_constant_control_transcription_is_registered_by_name():
    tr = get_transcription("radau-constant-control", degree=4)
    assert isinstance(tr, RadauConstantControl) and tr.degree == 4
    problem, _ = bang_bang()
    sol = solve(problem, N=8, transcription="radau-constant-control", ipopt_options=STRICT)
    assert sol.success and sol.transcription == RadauConstantControl(3)


def test_solution_from_arrays_reproduces_a_solution():
    problem, _ = min_energy()
    sol = solve(problem, N=4, ipopt_options=STRICT)
    d = sol.dense
    X = np.concatenate([sol.x[:, :1], d.Xo.reshape(problem.model.nx, -1)], axis=1)
    U = d.Uo.reshape(problem.model.nu, -1)
    again = Solution.from_arrays(problem, sol.transcription, sol.mesh, X, U, sol.p, sol.T,
                                 cost=sol.cost, multipliers=sol.multipliers)
    np.testing.assert_allclose(again.x, sol.x, atol=1e-14)
    np.testing.assert_allclose(again.u, sol.u, atol=1e-14)
    np.testing.assert_allclose(again.costates, sol.costates, atol=1e-12)
    assert again.success and again.cost == sol.cost
    t = np.linspace(0, 1, 7)
    np.testing.assert_allclose(again.sample(t)[0], sol.sample(t)[0], atol=1e-14)
    assert again.propagation_error == pytest.approx(sol.propagation_error, abs=1e-12)


def test_propagation_is_computed_once_and_cached():
    problem, _ = min_energy()
    sol = solve(problem, N=4, verify=False)  # (a verified solve has run it already)
    assert "propagation" not in vars(sol)
    first = sol.propagation
    assert sol.propagation is first and vars(sol)["propagation"] is first
