"""`solve_multistart`: solve from several guesses, keep the best converged solution."""
from __future__ import annotations

import time
from typing import Mapping, Sequence

import numpy as np

from dynamics.interrupts import interruptible
from ..problem import Problem
from ..progress import LOGGER
from ..solution import Solution
from ..solve import solve
from .result import RefinedSolution, annotate

__all__ = ["solve_multistart"]


@interruptible
def solve_multistart(problem: Problem, guesses: Sequence, *, start_options: Sequence | None = None,
                     **solve_kwargs) -> RefinedSolution:
    """Solve ``problem`` from each guess and keep the best converged solution.

    Parameters
    ----------
    problem : Problem
    guesses : sequence
        Anything ``solve(guess=...)`` accepts: ``None``, a `Solution`, a mapping.
    start_options : sequence, optional
        One entry per guess: a mapping of `ocp.solve` keywords for that start (over
        ``solve_kwargs``), or a sequence of such mappings tried in order until one
        converges (e.g. a cheap limited-memory attempt, then the exact Hessian). The start's
        record counts the iterations and time of all its attempts.
    **solve_kwargs
        Passed to `ocp.solve` (quiet unless ``verbose`` or ``progress`` is given).

    Returns
    -------
    RefinedSolution
        The converged solution of best cost (least, or largest for a ``maximize`` problem:
        `Problem.better`; ``info['best']`` is its index), or, if no start
        converged, the one of least constraint violation with ``success=False``.
        ``info['starts']`` (also ``.starts``) lists every start: ``index, success, status,
        cost, T, constraint_violation, iterations, time``.

    Raises
    ------
    ValueError
        If ``guesses`` is empty or not a sequence, or a guess is malformed (as `ocp.solve`).

    Examples
    --------
    >>> import ocp
    >>> from ocp.examples import min_time
    >>> fastest = min_time()  # x'' = u, |u| <= 1, from rest at 0 to rest at 1
    >>> sol = ocp.solve_multistart(fastest, [None, {"T": 5.0}], N=10)
    >>> sol.success, round(sol.T, 6), len(sol.info["starts"])
    (True, 2.0, 2)
    """
    if isinstance(guesses, (str, bytes, Mapping, Solution)) or not isinstance(guesses, Sequence):
        raise ValueError(f"`guesses` must be a sequence of guesses (None, Solution or mapping), "
                         f"got {type(guesses).__name__}")
    if len(guesses) == 0:
        raise ValueError("`guesses` must hold at least one guess")
    if "guess" in solve_kwargs:
        raise ValueError("pass the guesses as `guesses`, not `guess`")
    kw = dict(solve_kwargs)
    if start_options is not None and (isinstance(start_options, (str, bytes, Mapping))
                                      or len(start_options) != len(guesses)):
        raise ValueError(f"`start_options` must hold one entry per guess ({len(guesses)})")
    sols, starts = [], []
    for i, g in enumerate(guesses):
        t = time.perf_counter()
        tries = [{}] if start_options is None else start_options[i]
        tries = [tries] if isinstance(tries, Mapping) else list(tries)
        iterations = 0
        for extra in tries:
            sol = solve(problem, guess=g, **{**kw, **extra})
            iterations += sol.iterations
            if sol.success:
                break
        sols.append(sol)
        starts.append({"index": i, "success": sol.success, "status": sol.status, "cost": sol.cost,
                       "T": sol.T, "constraint_violation": sol.constraint_violation,
                       "iterations": iterations, "time": time.perf_counter() - t})
        LOGGER.info("multistart %d/%d: %s, cost %.12g", i + 1, len(guesses), sol.status, sol.cost)
    ok = [i for i, s in enumerate(sols) if s.success and np.isfinite(s.cost)]
    if ok:
        best = ok[0]
        for i in ok[1:]:
            if problem.better(sols[i].cost, sols[best].cost):
                best = i
        message = (f"best of {len(sols)} starts: start {best} ({len(ok)} converged); "
                   f"{sols[best].message}")
    else:
        viol = [s.constraint_violation if np.isfinite(s.constraint_violation) else np.inf for s in sols]
        best = int(np.argmin(viol))
        message = (f"none of {len(sols)} starts converged; returning start {best}, the least "
                   f"infeasible: {sols[best].message}")
    return annotate(sols[best], {"starts": starts, "best": best}, message=message,
                     success=bool(ok) and sols[best].success)
