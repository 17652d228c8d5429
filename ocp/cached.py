"""What the ocp engine builds repeatedly, kept in the one cache (`dynamics.cache`).

Per-model Functions -- a transcription's interval kernel and interpolant, the per-interval
CVODES integrators of the re-simulation and of the error estimates, the moving-knot
right-hand side of `ocp.polish_switches` -- are built once per model right-hand side and
defining arguments and reused by every solve, refinement round and `Solution` of that
model. Keys are ``("ocp.<kind>", ...)`` tuples holding `dynamics.cache.function_key` of the
model Functions (which are kept alive with the entry); `dynamics.clear_caches` empties
them with everything else.

Examples
--------
>>> import casadi as ca
>>> from dynamics import cache, clear_caches
>>> from ocp.cached import cached
>>> x = ca.SX.sym("x")
>>> f = ca.Function("f", [x], [2 * x])
>>> g = cached("double", (cache.function_key(f),), lambda: f.map(3), keepalive=f)
>>> g is cached("double", (cache.function_key(f),), lambda: f.map(3), keepalive=f)
True
>>> clear_caches()
>>> cache.contains(("ocp.double", cache.function_key(f)))
False
"""
from __future__ import annotations

from typing import Callable, Hashable

from dynamics import cache

__all__ = ["cached", "function_key"]

function_key = cache.function_key


def cached(kind: str, parts: tuple, build: Callable[[], object], *, keepalive=None):
    """``build()`` kept in `dynamics.cache` under ``("ocp." + kind, *parts)``.

    Parameters
    ----------
    kind : str
        What is built (the key's first item is ``"ocp." + kind``).
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
    key: Hashable = ("ocp." + kind,) + tuple(parts)
    try:
        hash(key)
    except TypeError:
        return build()
    return cache.get(key, build, keepalive=keepalive)
