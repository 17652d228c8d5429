"""Shared pieces of the input checks: the error class, symbol detection, array helpers."""
from __future__ import annotations

import math

import casadi as ca
import numpy as np

__all__ = ["ArgumentTypeError", "is_symbolic", "real_array", "short_repr", "shape_text",
           "member", "first_index", "norm", "dot3", "cross3", "check_shape", "check_finite"]


class ArgumentTypeError(TypeError, ValueError):
    """A wrong kind of argument (a string, ``None``, a symbol where numbers are needed).

    A ``TypeError``, as the convention asks; also a ``ValueError``, so that code written when
    appdyn raised ``ValueError`` for every bad input (``except ValueError`` in a CLI, tests)
    still catches it -- the way numpy's ``AxisError`` is both a ``ValueError`` and an
    ``IndexError``.
    """


def is_symbolic(x) -> bool:
    """Whether ``x`` is a symbolic CasADi expression (``SX`` or ``MX``; not ``DM``).

    Parameters
    ----------
    x : object

    Returns
    -------
    bool

    Examples
    --------
    >>> import casadi as ca
    >>> from appdyn.dynamics.validate import is_symbolic
    >>> is_symbolic(ca.SX.sym("x")), is_symbolic(ca.DM(1.0)), is_symbolic([1.0])
    (True, False, False)
    """
    return isinstance(x, (ca.SX, ca.MX))


def real_array(x, name: str) -> np.ndarray:
    """``x`` as a float64 array; ``TypeError`` unless it holds real numbers."""
    if type(x) is np.ndarray and x.dtype == np.float64:  # fast path: the common case
        return x
    if is_symbolic(x):
        raise ArgumentTypeError(
            f"`{name}` must be numeric here, got a symbolic CasADi {type(x).__name__}")
    if isinstance(x, ca.DM):
        a = x.full()
        return a.ravel() if a.shape[1] == 1 else a
    try:
        a = np.asarray(x)
    except ValueError:  # ragged nested sequences
        raise ValueError(f"`{name}` must be a regular (non-ragged) array of numbers, "
                         f"got {short_repr(x)}") from None
    kind = a.dtype.kind
    if kind in "fiu":
        return a.astype(np.float64, copy=False)
    if kind == "O" and not any(e is None for e in a.flat):  # astype would make None a NaN
        try:
            return a.astype(np.float64)
        except Exception:  # noqa: BLE001 - any failure to convert means "not numbers"
            pass
    what = {"b": "booleans", "c": "complex numbers", "U": "a string", "S": "bytes"}.get(
        kind, type(x).__name__)
    raise ArgumentTypeError(f"`{name}` must be real numbers, got {what}: {short_repr(x)}")


def short_repr(x, *, limit: int = 80) -> str:
    r = repr(x)
    return r if len(r) <= limit else r[: limit - 3] + "..."


def shape_text(shape: tuple, batch: bool) -> str:
    one = "(" + ", ".join(str(s) for s in shape) + ("," if len(shape) == 1 else "") + ")"
    if not batch:
        return one
    if not shape:
        return "a scalar or an array"
    return f"{one} or ({', '.join(str(s) for s in shape)}, n) (components first)"


def member(name: str, ncomp: int, index) -> str:
    """``q[:, 3]`` for member 3 of a batch with one component axis; ``name`` when single."""
    if index is None:
        return name
    idx = tuple(int(i) for i in index)
    return f"{name}[{', '.join([':'] * ncomp + [str(i) for i in idx])}]"


def first_index(mask: np.ndarray):
    """Batch index of the first True in ``mask`` (``None`` for a 0-d mask)."""
    if mask.ndim == 0:
        return None
    return np.unravel_index(int(np.argmax(mask)), mask.shape)


def norm(a: np.ndarray) -> float:
    """Euclidean norm of a finite 1-D array, without under- or overflow."""
    m = float(np.max(np.abs(a)))
    return m * float(np.sqrt(np.sum((a / m) ** 2))) if m > 0 else 0.0


def dot3(u, w) -> float:
    return u[0] * w[0] + u[1] * w[1] + u[2] * w[2]


def cross3(u, w) -> list:
    return [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]]


def check_shape(a: np.ndarray, name: str, shape: tuple, batch: bool) -> None:
    k = len(shape)
    if a.shape[:k] != shape or (not batch and a.ndim != k):
        raise ValueError(f"`{name}` must have shape {shape_text(shape, batch)}, got {a.shape}")


def check_finite(a: np.ndarray, name: str) -> None:
    if a.size <= 16 and all(map(math.isfinite, a.ravel().tolist())):  # fast path, small input
        return
    ok = np.isfinite(a)
    if not ok.all():
        idx = tuple(int(i) for i in np.argwhere(~ok)[0])
        where = f" at index {list(idx)}" if idx else ""
        raise ValueError(f"`{name}` must be finite, got {a[idx]}{where}")
