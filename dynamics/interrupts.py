"""Ctrl-C that arrives as a plain ``KeyboardInterrupt``, at a safe point.

A SIGINT that lands while CasADi (or numpy) runs C code can be raised inside a conversion
callback and lost there (``SystemError: DM.__array__ returned a result with an exception
set``) or swallowed. Long loops therefore defer it: inside `deferred_interrupts` a SIGINT
only sets a flag, and the loop calls `check_interrupt` between evaluations, which raises
``KeyboardInterrupt`` from Python. A second SIGINT while one is pending raises at once
(the way out of a single long evaluation).

Only the main thread handles signals, and only when SIGINT has Python's default handler
(a program that installed its own keeps it): elsewhere both functions do nothing.
"""
from __future__ import annotations

import contextlib
import functools
import signal
import threading

__all__ = ["deferred_interrupts", "check_interrupt", "interrupt_pending", "stop_requested",
           "interruptible"]

_lock = threading.Lock()
_state = {"depth": 0, "pending": False, "previous": None}


def _handler(signum, frame):
    if _state["pending"]:
        raise KeyboardInterrupt
    _state["pending"] = True


@contextlib.contextmanager
def deferred_interrupts():
    """Defer SIGINT to the next `check_interrupt` (or the end of the block).

    Nested blocks share one deferral. A SIGINT still pending when the outermost block ends
    is raised there.

    Examples
    --------
    >>> from appdyn.dynamics.interrupts import check_interrupt, deferred_interrupts
    >>> with deferred_interrupts():
    ...     for k in range(3):
    ...         check_interrupt()  # raises KeyboardInterrupt here after a Ctrl-C
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    with _lock:
        outer = _state["depth"] == 0
        if outer and signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
            installed = False
        else:
            installed = True
            if outer:
                _state["previous"] = signal.signal(signal.SIGINT, _handler)
            _state["depth"] += 1
    if not installed:
        yield
        return
    try:
        yield
    finally:
        with _lock:
            _state["depth"] -= 1
            pending = False
            if _state["depth"] == 0:
                signal.signal(signal.SIGINT, _state["previous"])
                pending, _state["pending"] = _state["pending"], False
        if pending:
            raise KeyboardInterrupt


def interrupt_pending() -> bool:
    """Whether a SIGINT deferred by `deferred_interrupts` waits for `check_interrupt`.

    True only in the main thread (where signals arrive); for C code that can stop early on
    request (an IPOPT iteration callback: `ocp.progress.IterationCallback`), which the
    caller then follows by `check_interrupt`.
    """
    return bool(_state["pending"]) and threading.current_thread() is threading.main_thread()


def stop_requested() -> bool:
    """Whether a SIGINT deferred by `deferred_interrupts` waits, seen from any thread: the
    workers of a loop the main thread waits on (`executors.run_split`) stop taking work,
    and the main thread then raises it by `check_interrupt`."""
    return bool(_state["pending"])


def check_interrupt() -> None:
    """Raise ``KeyboardInterrupt`` if a SIGINT arrived inside `deferred_interrupts`."""
    if _state["pending"] and threading.current_thread() is threading.main_thread():
        _state["pending"] = False
        raise KeyboardInterrupt


def interruptible(fun):
    """Decorator: run ``fun`` inside `deferred_interrupts` (it calls `check_interrupt`)."""
    @functools.wraps(fun)
    def wrapper(*args, **kwargs):
        with deferred_interrupts():
            return fun(*args, **kwargs)
    return wrapper
