"""What the ocp engine builds repeatedly, kept in the one cache (`dynamics.cache`).

Per-model Functions -- a transcription's interval kernel and interpolant, the per-interval
CVODES integrators of the re-simulation and of the error estimates, the moving-knot
right-hand side of `ocp.polish_switches`, the RK8 step and its Jacobian of the switch-time
polish (``rk8_step``, ``rk8_step_jacobian``), the NLP structures of `ocp.assembly`
(``nlp_structure``, keyed by content) and their IPOPT solvers (``nlpsol``, pooled: `checkout`),
the switch-time NLPs (``switch_times_nlp``, by content and arc count) and their solvers
(``switch_times_nlpsol``, pooled) -- are built once per model right-hand side and
defining arguments and reused by every solve, refinement round and `Solution` of that
model. Keys are ``("appdyn.ocp.<kind>", ...)`` tuples holding `dynamics.cache.function_key` of the
model Functions (which are kept alive with the entry); `dynamics.clear_caches` empties
them with everything else.

Threads (see `dynamics.cache`): entries holding CVODES integrators -- kinds in
`PER_THREAD`: ``interval_integrator``, and ``interval_check`` and ``propagator``, which call
one -- are kept once per thread (the thread id is part of the key), since a plain call of
an integrator runs in state shared by all its callers. A finished thread's entries age out
of the LRU cache (or serve a later thread that gets the same id). An IPOPT solver is lent to one
caller at a time with `checkout`. Every other entry (kernels, interpolants, right-hand
sides) is a pure Function, shared by all threads.

Examples
--------
>>> import casadi as ca
>>> from appdyn.dynamics import cache, clear_caches
>>> from appdyn.ocp.cached import cached
>>> x = ca.SX.sym("x")
>>> f = ca.Function("f", [x], [2 * x])
>>> g = cached("double", (cache.function_key(f),), lambda: f.map(3), keepalive=f)
>>> g is cached("double", (cache.function_key(f),), lambda: f.map(3), keepalive=f)
True
>>> clear_caches()
>>> cache.contains(("appdyn.ocp.double", cache.function_key(f)))
False
"""
from __future__ import annotations

import contextlib
import threading
from typing import Callable, Hashable

from appdyn.dynamics import cache

__all__ = ["cached", "checkout", "function_key", "PER_THREAD"]

#: Kinds whose entries run a CVODES integrator: one entry per thread.
PER_THREAD = frozenset({"interval_integrator", "interval_check", "propagator"})

function_key = cache.function_key


def cached(kind: str, parts: tuple, build: Callable[[], object], *, keepalive=None):
    """``build()`` kept in `dynamics.cache` under ``("appdyn.ocp." + kind, *parts)``.

    Parameters
    ----------
    kind : str
        What is built (the key's first item is ``"appdyn.ocp." + kind``).
    parts : tuple
        The defining arguments: `function_key` of every Function the entry is built from,
        transcriptions (frozen dataclasses), grids as tuples of floats, tolerances.
    build : callable
        ``build()`` returns the entry on a miss.
    keepalive : object, optional
        The Function(s) whose keys are in ``parts`` (held with the entry).

    Returns
    -------
    object
        The cached entry, or a fresh ``build()`` when ``parts`` is not hashable (e.g. a
        user-defined transcription with mutable fields).
    """
    key: Hashable = ("appdyn.ocp." + kind,) + tuple(parts)
    if kind in PER_THREAD:
        key += (("thread", threading.get_ident()),)
    try:
        hash(key)
    except TypeError:
        with cache.construction_lock():
            return build()
    return cache.get(key, build, keepalive=keepalive)


@contextlib.contextmanager
def checkout(kind: str, parts: tuple, build: Callable[[], object], *, keepalive=None):
    """Like `cached`, for an entry that must not run in two threads at once (an IPOPT
    solver): a context manager lending an instance to this caller alone, from a pool kept in
    `dynamics.cache` (`dynamics.cache.checkout`); a fresh ``build()`` for unhashable parts."""
    key: Hashable = ("appdyn.ocp." + kind,) + tuple(parts)
    try:
        hash(key)
    except TypeError:
        with cache.construction_lock():
            value = build()
        yield value
        return
    with cache.checkout(key, build, keepalive=keepalive) as value:
        yield value
