"""`solve_multistart`: solve from several guesses, keep the best converged solution."""
from __future__ import annotations

import hashlib
import pickle
import threading
import time
from collections import OrderedDict
from concurrent.futures import ThreadPoolExecutor
from typing import Mapping, Sequence

import numpy as np

from appdyn.dynamics.executors import check_executor, gather
from appdyn.dynamics.interrupts import interruptible
from ..ipopt_options import IPOPT_MAX_ITER, iteration_budget
from ..problem import Problem
from ..progress import LOGGER
from ..solution import Solution
from ..solve import solve
from .result import RefinedSolution, annotate

__all__ = ["solve_multistart"]

_RECEIVED: OrderedDict = OrderedDict()  # in a worker: digest -> Problem, the latest few
_RECEIVED_MAX = 4
_RECEIVED_LOCK = threading.Lock()


@interruptible
def solve_multistart(problem: Problem, guesses: Sequence, *, start_options: Sequence | None = None,
                     executor=None, agree: float | None = None,
                     start_budget: float | None = None, **solve_kwargs) -> RefinedSolution:
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
    executor : concurrent.futures.Executor, optional
        Run the starts as tasks of this executor (a ``ThreadPoolExecutor``, a
        ``ProcessPoolExecutor``, dask.distributed's ``client.get_executor()``, ...), one
        task per start (its ``start_options`` attempts included). The outcome is the serial
        one: the same best start (same ranking, ties to the lower index) and the same
        ``info['starts']`` records but their ``time``. The executor stays the caller's (not
        shut down). ``None`` (default): serial, in the calling thread.

        A process pool pickles ``problem`` (an `ocp.Problem` pickles, its CasADi functions
        included), each guess (``None``, a mapping of arrays and numbers, a `Solution`) and
        ``solve_kwargs``: a callable in them (a guess function, ``progress``) must be
        picklable, i.e. defined at module level, not a lambda. The problem is pickled once
        and unpickled once per worker process, so that the starts a worker runs share its
        NLP and solver (`dynamics.cache` is per process: each worker builds its own, a cost
        a serial run pays once). The returned solution's ``problem`` is ``problem`` itself
        (the copy the worker solved is swapped back). Workers import CasADi on first use
        (about a second with ``spawn``); any start method works, with ``spawn`` the calling
        script needs the usual ``if __name__ == "__main__":`` guard. A ``ThreadPoolExecutor``
        shares ``problem`` as it is (concurrent solves are safe: `ocp.solve`).
    agree : float, optional
        Serial runs only (ignored with an ``executor``): stop once two converged starts have
        costs within ``agree`` relative of each other (``|a - b| <= agree max(|a|, |b|,
        1)``): the starts after are not solved (``info['skipped']`` counts them; they have
        no record). Two starts from different guesses reaching the same optimum is taken
        as enough evidence that it is the best the guesses lead to. ``None`` (default):
        every start is solved.
    start_budget : float, optional
        Serial runs only (ignored with an ``executor``): once a start has converged, every
        later start may take at most ``start_budget`` times the IPOPT iterations of the
        converged start that needed fewest, and at least `ocp.ipopt_options.BUDGET_MIN_ITER`
        (`ocp.ipopt_options.iteration_budget`; a ``max_iter`` in ``ipopt_options`` or in a
        start's options wins). A start stopped at its budget whose objective still beats
        the best converged one goes on, warm from where it stopped, one budget at a time
        (up to the caller's ``max_iter``, default IPOPT's 3000, in all); one that does not is
        left there: it is heading for no solution or a worse one. Seeded starts of a CMG
        slew ran 1,053 and 3,000 iterations (117 s, the horizon drifting to 68 s) to no
        solution where the converged one took 16 (T = 2.0 s); the tilted starts of a wheel
        slew converge to Bilimoria-Wie's optimum in 238 and 265 iterations where the
        eigenaxis start reached its worse local optimum in 14 (their T at 200 iterations,
        3.26, already beats its 3.54). A start's record's ``budget`` is the limit it ran
        under (``None``: none). ``None`` (default): no budget.
    **solve_kwargs
        Passed to `ocp.solve` (quiet unless ``verbose`` or ``progress`` is given).

    Returns
    -------
    RefinedSolution
        The converged solution of best cost (least, or largest for a ``maximize`` problem:
        `Problem.better`; ``info['best']`` is its index), or, if no start
        converged, the one of least constraint violation with ``success=False``.
        ``info['starts']`` (also ``.starts``) lists every start: ``index, success, status,
        cost, T, constraint_violation, iterations, time, budget``; ``info['skipped']`` the number
        of starts ``agree`` left out (0 without it).

    Raises
    ------
    ValueError
        If ``guesses`` is empty or not a sequence, or a guess is malformed (as `ocp.solve`;
        with an ``executor``: the error of the lowest failing start, the starts after it
        cancelled).
    TypeError
        If ``executor`` is not a ``concurrent.futures.Executor``.
    KeyboardInterrupt
        On Ctrl-C. With an ``executor`` the wait looks for it every 0.1 s and cancels the
        starts not yet begun; running starts cannot be stopped from here and finish in
        the background (threads) or in their worker (processes), and shutting the executor
        down waits for them.

    Examples
    --------
    >>> from appdyn import ocp
    >>> from appdyn.ocp.examples import min_time
    >>> fastest = min_time()  # x'' = u, |u| <= 1, from rest at 0 to rest at 1
    >>> sol = ocp.solve_multistart(fastest, [None, {"T": 5.0}], N=10, control="constant")
    >>> sol.success, round(sol.T, 6), len(sol.info["starts"])
    (True, 2.0, 2)

    The same starts on two threads (a ``ProcessPoolExecutor`` is used the same way):

    >>> from concurrent.futures import ThreadPoolExecutor
    >>> with ThreadPoolExecutor(max_workers=2) as pool:
    ...     again = ocp.solve_multistart(fastest, [None, {"T": 5.0}], N=10, executor=pool,
    ...                                 control="constant")
    >>> again.T == sol.T, again.info["best"] == sol.info["best"]
    (True, True)
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
    check_executor(executor)
    # to another process the problem travels pickled once, and is unpickled once per worker
    sent = problem if executor is None or isinstance(executor, ThreadPoolExecutor) \
        else _Shipped(problem)
    tasks = [(sent, g, [{}] if start_options is None else start_options[i], kw)
             for i, g in enumerate(guesses)]
    sols, starts = [None] * len(guesses), [None] * len(guesses)

    budgets = [None] * len(guesses)

    def record(i, out):
        sol, iterations, elapsed = out
        sols[i] = sol
        starts[i] = {"index": i, "success": sol.success, "status": sol.status, "cost": sol.cost,
                     "T": sol.T, "constraint_violation": sol.constraint_violation,
                     "iterations": iterations, "time": elapsed, "budget": budgets[i]}
        LOGGER.info("multistart %d/%d: %s, cost %.12g", i + 1, len(guesses), sol.status, sol.cost)

    if agree is not None and (isinstance(agree, bool) or not isinstance(agree, (int, float))
                              or not agree >= 0):
        raise ValueError(f"`agree` must be None or a number >= 0, got {agree!r}")
    if start_budget is not None and (isinstance(start_budget, bool)
                                     or not isinstance(start_budget, (int, float))
                                     or not 1 <= start_budget < np.inf):
        raise ValueError(f"`start_budget` must be None or a finite number >= 1, got {start_budget!r}")
    if executor is None:
        for i, task in enumerate(tasks):
            converged = [st["iterations"] for st in starts[:i] if st["success"]]
            if start_budget is not None and converged:
                cap = _cap(task)
                task, budgets[i] = _budgeted(task, min(converged), start_budget)
                best_cost = _best_cost(problem, sols[:i])
                record(i, _continued(problem, task, budgets[i], cap, best_cost))
            else:
                record(i, _start(*task))
            if agree is not None and _agreeing(sols[:i + 1], agree):
                sols, starts = sols[:i + 1], starts[:i + 1]
                break
    else:
        gather(executor, _start, tasks, record)
    ok = [i for i, s in enumerate(sols) if s.success and np.isfinite(s.cost)]
    if ok:
        best = ok[0]
        for i in ok[1:]:
            if problem.better(sols[i].cost, sols[best].cost):
                best = i
        cut = [i for i, st in enumerate(starts) if st["budget"] is not None and not st["success"]
               and st["iterations"] >= st["budget"]]
        cut = (f", start{'s' if len(cut) > 1 else ''} {', '.join(map(str, cut))} stopped at "
               f"{'their' if len(cut) > 1 else 'its'} iteration budget" if cut else "")
        message = (f"best of {len(sols)} starts: start {best} ({len(ok)} converged{cut}); "
                   f"{sols[best].message}")
    else:
        viol = [s.constraint_violation if np.isfinite(s.constraint_violation) else np.inf for s in sols]
        best = int(np.argmin(viol))
        message = (f"none of {len(sols)} starts converged; returning start {best}, the least "
                   f"infeasible: {sols[best].message}")
    same = {} if sols[best].problem is problem else {"problem": problem}  # from a process
    return annotate(sols[best], {"starts": starts, "best": best,
                                 "skipped": len(guesses) - len(sols)}, message=message,
                    success=bool(ok) and sols[best].success, **same)


def _budgeted(task, iterations: int, factor: float):
    """``(task, budget)``: the start ``task`` with each attempt's IPOPT ``max_iter`` set to
    `iteration_budget` of ``iterations`` (a ``max_iter`` of the caller's or the attempt's
    wins), and the largest budget of its attempts."""
    problem, guess, tries, kw = task
    tries = [tries] if isinstance(tries, Mapping) else list(tries)
    limited, budgets = [], []
    for extra in tries:
        options = {**(kw.get("ipopt_options") or {}), **(extra.get("ipopt_options") or {})}
        options, budget = iteration_budget(options, iterations, factor)
        limited.append({**extra, "ipopt_options": options})
        budgets.append(budget)
    return (problem, guess, limited, kw), max(budgets)


def _cap(task) -> int:
    """The ``max_iter`` the caller set for the last attempt of ``task`` (before any budget),
    else IPOPT's default: a continued start (`_continued`) never goes past it."""
    _, _, tries, kw = task
    last = tries[-1] if not isinstance(tries, Mapping) else tries
    options = {**(kw.get("ipopt_options") or {}), **(last.get("ipopt_options") or {})}
    return int(options.get("max_iter", IPOPT_MAX_ITER))


def _best_cost(problem, sols) -> float:
    """The best cost of the converged ``sols``."""
    costs = [float(s.cost) for s in sols if s.success and np.isfinite(s.cost)]
    best = costs[0]
    for c in costs[1:]:
        best = c if problem.better(c, best) else best
    return best


def _continued(problem, task, budget: int, cap: int, best_cost: float):
    """A budgeted start (`_budgeted`), continued budget after budget -- warm from where it
    stopped -- while it stops at its budget with an objective that still beats
    ``best_cost`` (an iterate worse than a converged start after so many iterations is not
    worth finishing: the multistart keeps the best), up to ``cap`` iterations in all (the
    caller's ``max_iter``, `_cap`); ``(solution, iterations, wall time)`` as `_start`."""
    t = time.perf_counter()
    sol, iterations, _ = _start(*task)
    problem_, guess, tries, kw = task
    while (not sol.success and sol.iterations >= budget and iterations + budget <= cap
           and np.isfinite(sol.cost) and problem.better(float(sol.cost), best_cost)):
        sol, more, _ = _start(problem_, sol, tries[-1:], kw)
        iterations += more
    return sol, iterations, time.perf_counter() - t


def _agreeing(sols, agree: float) -> bool:
    """Whether the last of ``sols`` converged to a cost within ``agree`` (relative) of an
    earlier converged one."""
    last = sols[-1]
    if not (last.success and np.isfinite(last.cost)):
        return False
    a = float(last.cost)
    return any(s.success and abs(float(s.cost) - a) <= agree * max(abs(float(s.cost)), abs(a), 1.0)
               for s in sols[:-1])


class _Shipped:
    """A `Problem` pickled once for the tasks of a process executor.

    `get` unpickles it once per worker process (kept by digest, the latest `_RECEIVED_MAX`),
    so that the starts a worker runs share one problem, and with it the NLP and solver that
    `ocp.solve` caches by the identity of the problem's functions.
    """

    def __init__(self, problem):
        self.data = pickle.dumps(problem, protocol=pickle.HIGHEST_PROTOCOL)
        self.digest = hashlib.sha256(self.data).hexdigest()

    def get(self) -> Problem:
        with _RECEIVED_LOCK:
            problem = _RECEIVED.get(self.digest)
            if problem is None:
                problem = _RECEIVED[self.digest] = pickle.loads(self.data)
                while len(_RECEIVED) > _RECEIVED_MAX:
                    _RECEIVED.popitem(last=False)
            _RECEIVED.move_to_end(self.digest)
        return problem


def _start(problem, guess, tries, kw):
    """One start: ``(solution, iterations of all attempts, wall time)``; an executor task."""
    t = time.perf_counter()
    if isinstance(problem, _Shipped):
        problem = problem.get()
    tries = [tries] if isinstance(tries, Mapping) else list(tries)
    iterations = 0
    for extra in tries:
        sol = solve(problem, guess=guess, **{**kw, **extra})
        iterations += sol.iterations
        if sol.success:
            break
    return sol, iterations, time.perf_counter() - t
