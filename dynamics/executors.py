"""Spreading independent pieces of work over a `concurrent.futures.Executor`.

`check_executor` validates an ``executor=`` argument (``None`` = serial in the calling
thread); `gather` runs tasks on it and hands each result back in the calling thread as it
finishes, with the error and Ctrl-C behaviour of a serial loop (`dynamics.interrupts`). Used
by `problems.stability.sweep` and `ocp.solve_multistart`.
"""
from __future__ import annotations

from concurrent.futures import FIRST_COMPLETED, Executor, wait
from typing import Callable, Sequence

from .interrupts import check_interrupt

__all__ = ["check_executor", "gather", "POLL"]

POLL = 0.1  # [s] how often the wait on an executor looks for a deferred Ctrl-C


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
