"""Parsing of the numeric arguments of `Problem`: vectors, boundary values, bounds, the
horizon and the parameters.

Each function checks one argument and returns it in the stored form documented in
`Problem` (arrays of floats, NaN for a free boundary value, ``-inf``/``inf`` for no bound),
raising ValueError that names the argument.
"""
from __future__ import annotations

import math
from typing import Mapping

import numpy as np

from appdyn.dynamics.model import Model
from appdyn.dynamics.validate.base import real_array

__all__ = ["as_vector", "index", "boundary_values", "bounds", "horizon", "parameters",
           "row_bounds"]


def as_vector(value, n: int, argname: str, *, allow_nan: bool = False) -> np.ndarray:
    """``value`` as a float array of shape (n,) (a scalar is repeated).

    Parameters
    ----------
    value : float or array_like
    n : int
    argname : str
        Name in messages.
    allow_nan : bool, optional
        Accept NaN components.

    Returns
    -------
    ndarray, shape (n,)

    Raises
    ------
    ValueError
        Not numeric, of another size, or NaN (unless ``allow_nan``).
    """
    try:
        a = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"`{argname}` must be numeric: {exc}") from None
    if a.ndim == 0:
        a = np.full(n, float(a))
    a = a.reshape(-1) if a.ndim == 1 or a.size == n else a
    if a.shape != (n,):
        raise ValueError(f"`{argname}` must have shape ({n},), got {np.shape(value)}")
    if not allow_nan and np.any(np.isnan(a)):
        raise ValueError(f"`{argname}` must not contain NaN, got {a.tolist()}")
    return a


def index(names: tuple[str, ...], key, argname: str) -> int:
    """Position of component ``key`` in ``names`` (ValueError naming ``argname`` if
    unknown)."""
    if key not in names:
        raise ValueError(f"`{argname}` names unknown component {key!r}; expected one of {names}")
    return names.index(key)


def boundary_values(arg, names: tuple[str, ...], argname: str) -> np.ndarray:
    """Boundary values: mapping name -> value (others free), or array with NaN = free.

    Parameters
    ----------
    arg : None, mapping of str to float or None, or array_like, shape (n,)
        ``None`` (in a mapping or an array) marks a free component, as does NaN.
    names : tuple of str
        Component names, ``n`` of them.
    argname : str

    Returns
    -------
    ndarray, shape (n,)
        NaN for a free component.
    """
    n = len(names)
    out = np.full(n, np.nan)
    if arg is None:
        return out
    if isinstance(arg, Mapping):
        for key, value in arg.items():
            i = index(names, key, argname)
            if value is None:
                continue
            v = float(value)
            if not math.isfinite(v):
                raise ValueError(f"`{argname}`[{key!r}] must be finite or None, got {value!r}")
            out[i] = v
        return out
    if isinstance(arg, (list, tuple)):
        arg = [np.nan if v is None else v for v in arg]
    a = as_vector(arg, n, argname, allow_nan=True)
    if np.any(np.isinf(a)):
        raise ValueError(f"`{argname}` must be finite (NaN or None marks a free component), got {a.tolist()}")
    return a


def bounds(arg, names: tuple[str, ...], argname: str) -> np.ndarray:
    """Bounds: mapping name -> (lo, hi), or a pair (lower (n,), upper (n,)).

    Parameters
    ----------
    arg : None, mapping of str to (lower, upper), or (lower, upper)
        ``None`` for no bound (also as a whole).
    names : tuple of str
        Component names, ``n`` of them.
    argname : str

    Returns
    -------
    ndarray, shape (2, n)
        Lower and upper bounds, read-only.
    """
    n = len(names)
    out = np.array([np.full(n, -np.inf), np.full(n, np.inf)])
    if arg is None:
        return out
    if isinstance(arg, Mapping):
        for key, pair in arg.items():
            i = index(names, key, argname)
            try:
                lo, hi = pair
            except (TypeError, ValueError):
                raise ValueError(f"`{argname}`[{key!r}] must be a pair (lower, upper), got {pair!r}") from None
            out[0, i] = -np.inf if lo is None else float(lo)
            out[1, i] = np.inf if hi is None else float(hi)
    else:
        try:
            lo, hi = arg
        except (TypeError, ValueError):
            raise ValueError(
                f"`{argname}` must be a mapping name -> (lower, upper) or a pair (lower, upper) "
                f"of arrays of shape ({n},)"
            ) from None
        lo = -np.inf if lo is None else lo
        hi = np.inf if hi is None else hi
        out[0] = as_vector(lo, n, f"{argname}[0]")
        out[1] = as_vector(hi, n, f"{argname}[1]")
    if np.any(np.isnan(out)):
        raise ValueError(f"`{argname}` must not contain NaN")
    bad = np.flatnonzero(out[0] > out[1])
    if bad.size:
        raise ValueError(
            f"`{argname}`: lower bound exceeds upper bound for {[names[i] for i in bad]}: "
            f"{out[0, bad].tolist()} > {out[1, bad].tolist()}"
        )
    out.setflags(write=False)
    return out


def horizon(T):
    """The horizon argument ``T`` of `Problem`: a fixed length or a free range.

    Parameters
    ----------
    T : float or pair (T_min, T_max) [s]

    Returns
    -------
    float or tuple of two floats
        ``T > 0`` finite, or ``(T_min, T_max)`` with ``0 <= T_min < T_max`` (``T_max`` may
        be ``inf``).
    """
    if isinstance(T, (tuple, list, np.ndarray)):
        if len(T) != 2:
            raise ValueError(f"`T` must be a float or a pair (T_min, T_max), got {T!r}")
        lo, hi = (float(real_array(v, "T")) if np.ndim(v) == 0 else math.nan for v in T)
        if not (math.isfinite(lo) and lo >= 0 and hi > lo) or math.isnan(hi):
            raise ValueError(f"`T` bounds must satisfy 0 <= T_min < T_max, got ({lo}, {hi})")
        return (lo, hi)
    if np.ndim(T) != 0:
        raise ValueError(f"`T` must be a float or a pair (T_min, T_max), got {T!r}")
    T = float(real_array(T, "T"))  # (refuses strings and booleans, naming `T`)
    if not (math.isfinite(T) and T > 0):
        raise ValueError(f"`T` (horizon length) must be finite and > 0, got {T}")
    return T


def parameters(p, p_bounds, model: Model) -> tuple[np.ndarray, np.ndarray]:
    """The parameter values and bounds of `Problem`, fixed parameters pinned at their value.

    Parameters
    ----------
    p : None, mapping of str to float, or array_like, shape (np,)
        Values; default (and for parameters a mapping leaves out) ``model.p_default``.
    p_bounds : None, mapping of str to (lower, upper), or (lower, upper)
        ``None`` fixes every parameter; a mapping frees the parameters it lists; in the
        array form, components with ``lower == upper`` are fixed.
    model : dynamics.Model

    Returns
    -------
    p : ndarray, shape (np,)
    p_bounds : ndarray, shape (2, np)
        Both read-only; a fixed parameter has ``lower == upper == p``.
    """
    np_ = model.np
    if p is None:
        p_out = np.array(model.p_default, dtype=float)
    elif isinstance(p, Mapping):
        p_out = np.array(model.p_default, dtype=float)
        for key, value in p.items():
            p_out[index(model.params, key, "p")] = float(value)
    else:
        p_out = as_vector(p, np_, "p")
    if not np.all(np.isfinite(p_out)):
        raise ValueError(f"`p` must be finite, got {p_out.tolist()}")
    pb = np.array(bounds(p_bounds, model.params, "p_bounds"))
    if p_bounds is None:  # nothing listed: every parameter fixed at `p`
        fixed = np.ones(np_, bool)
    elif isinstance(p_bounds, Mapping):
        listed = np.zeros(np_, bool)
        for key in p_bounds:
            listed[model.params.index(key)] = True
        fixed = ~listed
    else:  # a pair of arrays: components with lower == upper are fixed at `p`
        fixed = pb[0] == pb[1]
    pb[0, fixed] = p_out[fixed]
    pb[1, fixed] = p_out[fixed]
    outside = (p_out < pb[0]) | (p_out > pb[1])
    if np.any(outside):
        i = np.flatnonzero(outside)
        raise ValueError(f"`p` lies outside `p_bounds` for {[model.params[j] for j in i]}")
    p_out.setflags(write=False)
    pb.setflags(write=False)
    return p_out, pb


def row_bounds(lower, upper, scale, m: int, label: str):
    """The bounds and row scale of a `Constraint` of ``m`` rows.

    Parameters
    ----------
    lower, upper : float or array_like, shape (m,)
        At least one finite bound, ``lower <= upper``.
    scale : None, float or array_like, shape (m,)
        Finite and > 0.
    m : int
    label : str
        Name of the constraint in messages (``'path[0]'``).

    Returns
    -------
    lower, upper : ndarray, shape (m,)
    scale : ndarray, shape (m,), or None
        Read-only.
    """
    lo = as_vector(lower, m, f"{label}.lower")
    hi = as_vector(upper, m, f"{label}.upper")
    if np.any(lo > hi):
        raise ValueError(f"`{label}`: lower bound exceeds upper bound ({lo.tolist()} > {hi.tolist()})")
    if np.all(np.isinf(lo)) and np.all(np.isinf(hi)):
        raise ValueError(f"`{label}` has no finite bound")
    if scale is not None:
        scale = as_vector(scale, m, f"{label}.scale")
        if not np.all(np.isfinite(scale) & (scale > 0)):
            raise ValueError(f"`{label}.scale` must be finite and > 0, got {scale.tolist()}")
        scale.setflags(write=False)
    lo.setflags(write=False)
    hi.setflags(write=False)
    return lo, hi, scale
