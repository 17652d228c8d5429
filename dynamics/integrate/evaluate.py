"""Numeric evaluation of CasADi Functions without per-element data conversion."""
from __future__ import annotations

import casadi as ca
import numpy as np

from .. import cache

__all__ = ["call_buffered", "map_eval"]


def call_buffered(fun: ca.Function, args, out_shape) -> np.ndarray:
    """Evaluate ``fun`` through a buffer: numpy in, numpy out, no per-element conversion.

    Arrays are passed in casadi's column-major layout: a C-ordered ``(ncol, nrow)`` numpy
    array is the casadi ``nrow x ncol`` matrix.
    """
    args = [np.ascontiguousarray(a, dtype=float) for a in args]
    out = np.empty(out_shape)
    buf, trigger = fun.buffer()
    for i, a in enumerate(args):
        buf.set_arg(i, memoryview(a))
    buf.set_res(0, memoryview(out))
    trigger()
    return out


def map_eval(fun: ca.Function, args) -> np.ndarray:
    """Evaluate a Function column by column over ``n`` columns (cached ``map``); (m, n) out.

    ``args`` are arrays of shape (size_i, n) (or 1-D for inputs broadcast to all columns).
    """
    n = next(a.shape[1] for a in args if np.ndim(a) == 2)
    key = ("map", cache.function_key(fun), n)
    mapped = cache.get(key, lambda: fun.map(n, "serial"), keepalive=fun)
    cols = []
    for a in args:
        a = np.asarray(a, dtype=float)
        cols.append(np.repeat(a.reshape(-1, 1), n, axis=1).T if a.ndim == 1 else a.T)
    out = call_buffered(mapped, cols, (n, fun.numel_out(0)))
    return out.T
