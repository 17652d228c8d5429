"""Spreading independent pieces of work over a `concurrent.futures.Executor`.

`check_executor` validates an ``executor=`` argument (``None`` = serial in the calling
thread); `gather` runs tasks on it and hands each result back in the calling thread as it
finishes, with the error and Ctrl-C behaviour of a serial loop (`dynamics.interrupts`). Used
by `problems.stability.sweep` and `ocp.solve_multistart`. `worker_pool` is the process's own
pool of threads for appdyn's internal parallel loops and `run_split` hands work to it (the
runs of a batched `simulate`). `process_pool` makes a process pool whose workers are started
by a fork server, not forked from this (threaded) process: forking a process that runs
threads can leave a child waiting forever on a lock or a pipe another thread held.
"""
from __future__ import annotations

import os
import threading
from concurrent.futures import FIRST_COMPLETED, Executor, ThreadPoolExecutor, wait
from typing import TYPE_CHECKING, Callable, Sequence

from .interrupts import check_interrupt, deferred_interrupts, stop_requested

if TYPE_CHECKING:
    from concurrent.futures import ProcessPoolExecutor

__all__ = ["check_executor", "gather", "worker_pool", "run_split", "run_claiming", "process_pool",
           "POLL"]

POLL = 0.1  # [s] how often the wait on an executor looks for a deferred Ctrl-C


def process_pool(max_workers: int | None = None) -> ProcessPoolExecutor:
    """A `concurrent.futures.ProcessPoolExecutor` whose workers start from a fork server
    (``'forkserver'``; the platform's default where there is none), safe to make in a process
    that runs threads.

    Parameters
    ----------
    max_workers : int, optional
        Worker processes (default: the CPU count).

    Returns
    -------
    concurrent.futures.ProcessPoolExecutor

    Examples
    --------
    >>> from appdyn.dynamics.executors import process_pool
    >>> with process_pool(2) as pool:
    ...     print(sorted(pool.map(abs, [-2, 1])))
    [1, 2]
    """
    import multiprocessing  # with the process pool (it brings subprocess, tempfile, ...)
    from concurrent.futures import ProcessPoolExecutor

    methods = multiprocessing.get_all_start_methods()
    context = multiprocessing.get_context("forkserver" if "forkserver" in methods else None)
    return ProcessPoolExecutor(max_workers, mp_context=context)


def check_executor(executor, name: str = "executor"):
    """``executor`` if it is ``None`` or a `concurrent.futures.Executor`.

    Raises
    ------
    TypeError
        Naming ``name`` for anything else.
    """
    if executor is not None and not isinstance(executor, Executor):
        raise TypeError(f"`{name}` must be a concurrent.futures.Executor or None, "
                        f"got {type(executor).__name__}")
    return executor


def gather(executor: Executor, fun: Callable, tasks: Sequence[tuple], on_done: Callable) -> None:
    """Run ``fun(*args)`` for each ``args`` in ``tasks`` on ``executor``; ``on_done(i,
    value)`` in the calling thread as task ``i`` finishes.

    A failed task cancels the tasks after it; once the tasks before it have finished, the
    error of the first failed task is raised (what a serial loop raises). A Ctrl-C (checked
    every `POLL` seconds) or a task ended by ``KeyboardInterrupt`` cancels the pending tasks
    and raises ``KeyboardInterrupt``; tasks already running finish in the background.
    """
    futures = {executor.submit(fun, *args): i for i, args in enumerate(tasks)}
    pending, errors = set(futures), {}
    try:
        while pending:
            finished, pending = wait(pending, timeout=POLL, return_when=FIRST_COMPLETED)
            check_interrupt()
            for fut in sorted(finished, key=futures.get):
                if fut.cancelled():
                    continue
                exc = fut.exception()
                if exc is None:
                    on_done(futures[fut], fut.result())
                elif isinstance(exc, KeyboardInterrupt):
                    raise KeyboardInterrupt
                else:
                    errors[futures[fut]] = exc
            if errors:
                first = min(errors)
                for fut in [f for f in pending if futures[f] > first]:
                    fut.cancel()
                    pending.discard(fut)
        check_interrupt()  # a Ctrl-C during the last wait
    except BaseException:
        for fut in futures:
            fut.cancel()
        raise
    if errors:
        raise errors[min(errors)]


_POOL: dict = {"pid": None, "pool": None, "workers": 0}
_POOL_LOCK = threading.Lock()


def worker_pool(workers: int) -> ThreadPoolExecutor:
    """The process's shared pool of at least ``workers`` threads for appdyn's own loops.

    Made on first use and kept (its idle threads cost nothing); made again in a child
    process after ``os.fork`` (the parent's threads do not exist there) or when more workers
    are asked for (the smaller pool ends once unused). Tasks given to it must not wait on
    other tasks of the pool.

    Parameters
    ----------
    workers : int
        Threads wanted, ``>= 1``.

    Returns
    -------
    concurrent.futures.ThreadPoolExecutor
    """
    pool = _POOL["pool"]
    if pool is not None and _POOL["pid"] == os.getpid() and _POOL["workers"] >= workers:
        return pool
    with _POOL_LOCK:
        if _POOL["pool"] is None or _POOL["pid"] != os.getpid() or _POOL["workers"] < workers:
            _POOL.update(pid=os.getpid(), workers=workers,
                         pool=ThreadPoolExecutor(workers, thread_name_prefix="appdyn"))
        return _POOL["pool"]


def run_split(fun: Callable, tasks: Sequence) -> None:
    """``fun(task)`` for every task: the first in the calling thread, the others at the same
    time on `worker_pool`; returns when all have finished.

    For work that releases the GIL (compiled CasADi calls). An error is raised once every
    task has finished, so that no task still runs on the caller's data after the call: the
    calling thread's own, else the first (in the order of ``tasks``) of the others. Tasks
    the pool no longer takes (while the interpreter exits) run in the calling thread.
    """
    futures = []
    if len(tasks) > 1:
        pool = worker_pool(len(tasks) - 1)
        for task in tasks[1:]:
            try:
                futures.append(pool.submit(fun, task))
            except RuntimeError:  # no new threads after the interpreter's shutdown began
                break
    try:
        for task in [tasks[0], *tasks[1 + len(futures):]]:
            fun(task)
    finally:
        wait(futures)
    for fut in futures:
        fut.result()


def run_claiming(call: Callable, args: tuple, threads: int, runs: int, *,
                 meanwhile: Callable[[], None] | None = None) -> None:
    """The compiled loop ``call(*args)`` over a batch's ``runs`` on ``threads`` threads (at
    most one per run: the caller's and those of `worker_pool`), each calling it again until
    it returns true: every run handed out through the counter the loops share (`cpass`'s
    ``rk8_adaptive_many``, ``rk8_pass_many``; a loop returns false once its runs made its
    step budget). ``meanwhile``: Python the calling thread runs first, while the other
    threads take runs (the loops release the GIL), before it takes runs too. Ctrl-C is
    deferred: a thread that sees it takes no further run, and it is raised once every loop
    has finished."""
    def loop(first):
        if first and meanwhile is not None:
            meanwhile()
        while not stop_requested() and not call(*args):
            pass

    with deferred_interrupts():
        run_split(loop, [True] + [False] * (max(1, min(threads, runs)) - 1))
        check_interrupt()
