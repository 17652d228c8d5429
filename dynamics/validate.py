"""The one set of input checks shared by every appdyn package.

Each check takes the value and the *name of the argument* it came from, and raises
``TypeError`` (wrong kind of object: a string, a dict, ``None``, complex or boolean numbers, a
symbolic CasADi expression) or ``ValueError`` (wrong shape or value) with a message that names
the argument and says what was expected. They return the value as a float numpy array (the
input object itself when it already is a float64 array: do not modify it in place).

Arrays are **components first**, as everywhere in appdyn: a quaternion is ``(4,)`` or, for a
batch, ``(4, n)``; a rotation matrix is ``(3, 3)`` or ``(3, 3, n)``. ``batch=True`` accepts the
single shape and the single shape followed by batch axes; errors about one member of a batch
name it by index, e.g. ``q[:, 3]``.

Numbers only: callers that also accept CasADi symbols test `is_symbolic` first and skip the
check for ``SX``/``MX``. A ``casadi.DM`` holds numbers and is checked like an array (a ``n x 1``
DM is a vector of length ``n``).
"""
from __future__ import annotations

import math

import casadi as ca
import numpy as np

__all__ = [
    "ArgumentTypeError",
    "QUAT_NORM_TOL",
    "DCM_ORTHO_TOL",
    "is_symbolic",
    "finite_array",
    "finite_scalar",
    "unit_vector",
    "unit_quaternion",
    "unit_quaternions",
    "rotation_matrix",
    "one_of",
    "integer",
    "positive",
    "check_inertia",
]

#: How far a quaternion argument may deviate from unit norm before it is refused.
QUAT_NORM_TOL = 1e-6

#: Largest accepted ``max |A A^T - E|`` of a rotation-matrix argument.
DCM_ORTHO_TOL = 1e-6



class ArgumentTypeError(TypeError, ValueError):
    """A wrong kind of argument (a string, ``None``, a symbol where numbers are needed).

    A ``TypeError``, as the convention asks; also a ``ValueError``, so that code written when
    appdyn raised ``ValueError`` for every bad input (``except ValueError`` in a CLI, tests)
    still catches it -- the way numpy's ``AxisError`` is both a ``ValueError`` and an
    ``IndexError``.
    """


# ------------------------------------------------------------------------- helpers
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
    >>> from dynamics.validate import is_symbolic
    >>> is_symbolic(ca.SX.sym("x")), is_symbolic(ca.DM(1.0)), is_symbolic([1.0])
    (True, False, False)
    """
    return isinstance(x, (ca.SX, ca.MX))


def _real_array(x, name: str) -> np.ndarray:
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
                         f"got {_short(x)}") from None
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
    raise ArgumentTypeError(f"`{name}` must be real numbers, got {what}: {_short(x)}")


def _short(x, limit: int = 80) -> str:
    r = repr(x)
    return r if len(r) <= limit else r[: limit - 3] + "..."


def _shape_text(shape: tuple, batch: bool) -> str:
    one = "(" + ", ".join(str(s) for s in shape) + ("," if len(shape) == 1 else "") + ")"
    if not batch:
        return one
    if not shape:
        return "a scalar or an array"
    return f"{one} or ({', '.join(str(s) for s in shape)}, n) (components first)"


def _member(name: str, ncomp: int, index) -> str:
    """``q[:, 3]`` for member 3 of a batch with one component axis; ``name`` when single."""
    if index is None:
        return name
    idx = tuple(int(i) for i in index)
    return f"{name}[{', '.join([':'] * ncomp + [str(i) for i in idx])}]"


def _first(mask: np.ndarray):
    """Batch index of the first True in ``mask`` (``None`` for a 0-d mask)."""
    if mask.ndim == 0:
        return None
    return np.unravel_index(int(np.argmax(mask)), mask.shape)


def _norm(a: np.ndarray) -> float:
    """Euclidean norm of a finite 1-D array, without under- or overflow."""
    m = float(np.max(np.abs(a)))
    return m * float(np.sqrt(np.sum((a / m) ** 2))) if m > 0 else 0.0


def _dot3(u, w) -> float:
    return u[0] * w[0] + u[1] * w[1] + u[2] * w[2]


def _cross3(u, w) -> list:
    return [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]]


def _check_shape(a: np.ndarray, name: str, shape: tuple, batch: bool) -> None:
    k = len(shape)
    if a.shape[:k] != shape or (not batch and a.ndim != k):
        raise ValueError(f"`{name}` must have shape {_shape_text(shape, batch)}, got {a.shape}")


def _check_finite(a: np.ndarray, name: str) -> None:
    if a.size <= 16 and all(map(math.isfinite, a.ravel().tolist())):  # fast path, small input
        return
    ok = np.isfinite(a)
    if not ok.all():
        idx = tuple(int(i) for i in np.argwhere(~ok)[0])
        where = f" at index {list(idx)}" if idx else ""
        raise ValueError(f"`{name}` must be finite, got {a[idx]}{where}")


# -------------------------------------------------------------------------- checks
def finite_array(x, name: str, shape: tuple | None = None, *, batch: bool = False) -> np.ndarray:
    """Check an array of finite real numbers, optionally of a given shape.

    Parameters
    ----------
    x : array_like
        The value to check (list, tuple, number, numpy array or ``casadi.DM``).
    name : str
        Argument name used in the error message.
    shape : tuple of int, optional
        Required shape, e.g. ``(3,)`` or ``(3, 3)``; ``None`` accepts any shape.
    batch : bool, optional
        Also accept ``shape`` followed by batch axes, e.g. ``(3, n)`` for ``shape=(3,)``.

    Returns
    -------
    ndarray, shape ``shape`` or ``shape + (n, ...)``
        ``x`` as a float array.

    Raises
    ------
    TypeError
        If ``x`` does not hold real numbers (string, dict, ``None``, complex, boolean, symbolic).
    ValueError
        If the shape is wrong or an entry is NaN or infinite.

    Examples
    --------
    >>> from dynamics.validate import finite_array
    >>> finite_array([1, 2, 3], "w0", (3,))
    array([1., 2., 3.])
    >>> finite_array([1.0, float("nan"), 3.0], "w0", (3,))
    Traceback (most recent call last):
        ...
    ValueError: `w0` must be finite, got nan at index [1]
    """
    a = _real_array(x, name)
    if shape is not None:
        _check_shape(a, name, tuple(shape), batch)
    _check_finite(a, name)
    return a


def finite_scalar(x, name: str) -> float:
    """Check one finite real number (an angle, a time step, a rate).

    Parameters
    ----------
    x : float or 0-d array_like (a ``1x1`` DM is accepted)
    name : str
        Argument name used in the error message.

    Returns
    -------
    float

    Raises
    ------
    TypeError
        If ``x`` is not a real number.
    ValueError
        If ``x`` is an array of more than one element, NaN or infinite.

    Examples
    --------
    >>> from dynamics.validate import finite_scalar
    >>> finite_scalar(2, "rate")
    2.0
    >>> finite_scalar("fast", "rate")
    Traceback (most recent call last):
        ...
    dynamics.validate.ArgumentTypeError: `rate` must be real numbers, got a string: 'fast'
    """
    a = _real_array(x, name)
    if a.ndim != 0 and not (isinstance(x, ca.DM) and a.size == 1):
        raise ValueError(f"`{name}` must be a scalar, got shape {a.shape}")
    v = float(a.reshape(()))
    if not np.isfinite(v):
        raise ValueError(f"`{name}` must be finite, got {v}")
    return v


def unit_vector(v, name: str, *, size: int = 3, batch: bool = False) -> np.ndarray:
    """Check a finite non-zero vector (an axis, a direction) and return it scaled to unit length.

    The length is computed with scaling, so tiny (``1e-300``) and huge (``1e300``) vectors are
    normalized without under- or overflow.

    Parameters
    ----------
    v : array_like, shape (size,) or, with ``batch``, (size, n)
    name : str
        Argument name used in the error message.
    size : int, optional
        Number of components (3 for an axis, 4 to normalize a quaternion).
    batch : bool, optional
        Accept a components-first batch; each column is normalized.

    Returns
    -------
    ndarray, same shape as ``v``
        ``v / |v|`` (column by column for a batch).

    Raises
    ------
    TypeError
        If ``v`` does not hold real numbers.
    ValueError
        If the shape is wrong, an entry is not finite, or a vector is zero.

    Examples
    --------
    >>> from dynamics.validate import unit_vector
    >>> unit_vector([0, 3, 4], "axis")
    array([0. , 0.6, 0.8])
    """
    a = finite_array(v, name, (size,), batch=batch)
    m = np.max(np.abs(a), axis=0)
    zero = m == 0
    if np.any(zero):
        idx = _first(zero)
        raise ValueError(f"`{_member(name, 1, idx)}` must be a non-zero vector, got "
                         f"{(a if idx is None else a[(slice(None), *idx)]).tolist()}")
    if np.all((m > 1e-150) & (m < 1e150)):  # |v|^2 neither under- nor overflows
        return a / np.sqrt(np.sum(a * a, axis=0))
    s = a / m
    return s / np.sqrt(np.sum(s * s, axis=0))


def unit_quaternion(q, name: str, *, tol: float = QUAT_NORM_TOL) -> np.ndarray:
    """Check a scalar-last unit quaternion and return it normalized.

    Parameters
    ----------
    q : array_like, shape (4,)
        The quaternion ``[q1, q2, q3, q4]`` (any array of 4 numbers, e.g. a ``4x1`` column).
    name : str
        Argument name used in the error message.
    tol : float, optional
        Largest accepted ``| |q| - 1 |``.

    Returns
    -------
    ndarray, shape (4,)
        ``q / |q|``.

    Raises
    ------
    TypeError
        If ``q`` does not hold real numbers.
    ValueError
        If ``q`` is not 4 finite numbers or its norm differs from 1 by more than ``tol``.

    Examples
    --------
    >>> from dynamics.validate import unit_quaternion
    >>> unit_quaternion([0.0, 0.6, 0.0, 0.8], "q0")
    array([0. , 0.6, 0. , 0.8])
    >>> unit_quaternion([0.0, 0.0, 0.0, 2.0], "q0")
    Traceback (most recent call last):
        ...
    ValueError: `q0` must be a unit quaternion (norm 1 to 1e-06), got norm 2
    """
    a = _real_array(q, name).reshape(-1)
    if a.shape != (4,) or not np.all(np.isfinite(a)):
        raise ValueError(
            f"`{name}` must be 4 finite numbers (scalar-last quaternion), got {_short(q)}")
    n = _norm(a)
    if not abs(n - 1.0) <= tol:
        raise ValueError(
            f"`{name}` must be a unit quaternion (norm 1 to {tol:g}), got norm {n:.9g}")
    return a / n


def unit_quaternions(q, name: str, *, tol: float = QUAT_NORM_TOL,
                     normalize: bool = False) -> np.ndarray:
    """Check one or a batch of scalar-last unit quaternions.

    Parameters
    ----------
    q : array_like, shape (4,) or (4, n)
        Quaternions as columns, components first.
    name : str
        Argument name used in the error message.
    tol : float, optional
        Largest accepted ``| |q| - 1 |`` of every column.
    normalize : bool, optional
        Return ``q / |q|`` (column by column); by default ``q`` is returned as given.

    Returns
    -------
    ndarray, shape (4,) or (4, n)

    Raises
    ------
    TypeError
        If ``q`` does not hold real numbers.
    ValueError
        If the shape is wrong, or a column is not finite, is zero, or has a norm that differs
        from 1 by more than ``tol``; the message names the first bad column (``q[:, j]``)
        and its norm.

    Examples
    --------
    >>> from dynamics.validate import unit_quaternions
    >>> unit_quaternions([[0.0, 0.0], [0.0, 0.6], [0.0, 0.0], [1.0, 0.8]], "q")  # (4, n)
    array([[0. , 0. ],
           [0. , 0.6],
           [0. , 0. ],
           [1. , 0.8]])
    """
    a = _real_array(q, name)
    _check_shape(a, name, (4,), True)
    if a.ndim == 1:  # fast path for one quaternion (Python floats: no numpy warnings)
        n = math.sqrt(sum(x * x for x in a.tolist()))
        if abs(n - 1.0) <= tol:  # False for NaN and inf
            return a / n if normalize else a
        bad = np.array(True)
    else:
        with np.errstate(over="ignore", invalid="ignore"):
            n = np.sqrt(np.einsum("i...,i...->...", a, a))
            bad = ~(np.abs(n - 1.0) <= tol)  # NaN and inf fail too
    if bad.any():
        idx = _first(bad)
        col = a if idx is None else a[(slice(None), *idx)]
        label = _member(name, 1, idx)
        if not np.all(np.isfinite(col)):
            raise ValueError(f"`{label}` must be finite, got {col.tolist()}")
        raise ValueError(f"`{label}` must be a unit quaternion (norm 1 to {tol:g}), "
                         f"got norm {_norm(col):.9g}")
    return a / n if normalize else a


def rotation_matrix(A, name: str, *, tol: float = DCM_ORTHO_TOL, batch: bool = False) -> np.ndarray:
    """Check a proper rotation matrix (direction cosine matrix) or a batch of them.

    Parameters
    ----------
    A : array_like, shape (3, 3) or, with ``batch``, (3, 3, n)
    name : str
        Argument name used in the error message.
    tol : float, optional
        Largest accepted ``max |A A^T - E|`` (element-wise).
    batch : bool, optional
        Accept a components-first batch ``(3, 3, n)``.

    Returns
    -------
    ndarray, same shape as ``A``
        ``A`` as given.

    Raises
    ------
    TypeError
        If ``A`` does not hold real numbers.
    ValueError
        If the shape is wrong, an entry is not finite, ``A`` is not orthogonal to ``tol``,
        or ``det A`` is not ``+1`` (a reflection); the message names the first bad matrix
        (``A[:, :, j]``).

    Examples
    --------
    >>> import numpy as np
    >>> from dynamics.validate import rotation_matrix
    >>> rotation_matrix(2 * np.eye(3), "A")
    Traceback (most recent call last):
        ...
    ValueError: `A` must be a rotation matrix (orthogonal to 1e-06), got max |A A^T - E| = 3
    """
    a = _real_array(A, name)
    _check_shape(a, name, (3, 3), batch)
    if a.ndim == 2:  # fast path for one matrix, in Python floats (no numpy warnings)
        r = a.tolist()
        err = max(abs(_dot3(r[i], r[j]) - (i == j)) for i in range(3) for j in range(i, 3))
        if err <= tol and _dot3(r[0], _cross3(r[1], r[2])) > 0:  # False for NaN
            return a
    # all matrices at once, and the diagnosis of a refused single matrix
    r0, r1, r2 = a[0], a[1], a[2]  # rows, each (3,) or (3, n, ...)
    with np.errstate(over="ignore", invalid="ignore"):
        err = np.abs(np.einsum("k...,k...->...", r0, r0) - 1)
        for g in (np.einsum("k...,k...->...", r1, r1) - 1,
                  np.einsum("k...,k...->...", r2, r2) - 1,
                  np.einsum("k...,k...->...", r0, r1), np.einsum("k...,k...->...", r0, r2),
                  np.einsum("k...,k...->...", r1, r2)):
            err = np.maximum(err, np.abs(g))  # NaN propagates
    bad = ~(err <= tol)
    if bad.any():
        idx = _first(bad)
        m = a if idx is None else a[(slice(None), slice(None), *idx)]
        label = _member(name, 2, idx)
        if not np.all(np.isfinite(m)):
            raise ValueError(f"`{label}` must be finite, got {m.tolist()}")
        e = float(err if idx is None else err[idx])
        raise ValueError(f"`{label}` must be a rotation matrix (orthogonal to {tol:g}), "
                         f"got max |A A^T - E| = {e:.3g}")
    det = (r0[0] * (r1[1] * r2[2] - r1[2] * r2[1]) + r0[1] * (r1[2] * r2[0] - r1[0] * r2[2])
           + r0[2] * (r1[0] * r2[1] - r1[1] * r2[0]))
    neg = ~(det > 0)
    if np.any(neg):
        idx = _first(neg)
        raise ValueError(f"`{_member(name, 2, idx)}` must be a proper rotation (det +1), got "
                         f"det {float(det if idx is None else det[idx]):.9g} (a reflection)")
    return a


def one_of(value, name: str, choices: tuple):
    """Check that ``value`` is one of a few allowed options (strings or integers).

    Parameters
    ----------
    value : object
    name : str
        Argument name used in the error message.
    choices : tuple
        The allowed values; their types are the allowed types (a ``bool`` is not an ``int``
        here, and a numpy integer is).

    Returns
    -------
    object
        ``value`` (a numpy integer as a Python ``int``).

    Raises
    ------
    TypeError
        If ``value`` is not of the type of any choice.
    ValueError
        If it is of the right type but not among ``choices``.

    Examples
    --------
    >>> from dynamics.validate import one_of
    >>> one_of("rk4", "method", ("rk4", "rk8"))
    'rk4'
    >>> one_of("rk5", "method", ("rk4", "rk8"))
    Traceback (most recent call last):
        ...
    ValueError: `method` must be 'rk4' or 'rk8', got 'rk5'
    """
    names = [repr(c) for c in choices]
    text = names[0] if len(names) == 1 else ", ".join(names[:-1]) + " or " + names[-1]
    ints = any(type(c) is int for c in choices)
    if isinstance(value, (bool, np.bool_)) and not any(type(c) is bool for c in choices):
        ok = False
    elif ints and isinstance(value, np.integer):
        value, ok = int(value), True
    else:
        ok = any(type(value) is type(c) for c in choices)
    if not ok:
        raise ArgumentTypeError(
            f"`{name}` must be {text}, got {type(value).__name__} {_short(value)}")
    if value not in choices:
        raise ValueError(f"`{name}` must be {text}, got {_short(value)}")
    return value


def integer(value, name: str, *, minimum: int | None = None) -> int:
    """Check an integer count (steps, a run budget, an index), optionally ``>= minimum``.

    Parameters
    ----------
    value : int
        A Python or numpy integer (``bool`` is refused).
    name : str
        Argument name used in the error message.
    minimum : int, optional
        Least accepted value.

    Returns
    -------
    int

    Raises
    ------
    TypeError
        If ``value`` is not an integer (a string, ``None``, a ``bool``, an array, ``2.5`` or
        ``3.0``); raised as `ArgumentTypeError`, which is also a ``ValueError``.
    ValueError
        If it is below ``minimum``.

    Examples
    --------
    >>> import numpy as np
    >>> from dynamics.validate import integer
    >>> integer(np.int64(3), "steps", minimum=1)
    3
    >>> integer(0, "steps", minimum=1)
    Traceback (most recent call last):
        ...
    ValueError: `steps` must be an integer >= 1, got 0
    """
    bound = "" if minimum is None else f" >= {minimum}"
    number = isinstance(value, (int, np.integer, float, np.floating))
    if isinstance(value, (bool, np.bool_)) or not number:
        raise ArgumentTypeError(
            f"`{name}` must be an integer{bound}, got {type(value).__name__} {_short(value)}")
    if not isinstance(value, (int, np.integer)):
        raise ArgumentTypeError(f"`{name}` must be an integer{bound}, got {value!r}")
    if minimum is not None and value < minimum:
        raise ValueError(f"`{name}` must be an integer{bound}, got {value!r}")
    return int(value)


def positive(value, name: str) -> float:
    """Check a finite number ``> 0`` and return it as a float.

    Parameters
    ----------
    value : float
    name : str
        Argument name used in the error message.

    Returns
    -------
    float

    Raises
    ------
    TypeError
        If ``value`` is not a real number.
    ValueError
        If it is not finite or not ``> 0``.

    Examples
    --------
    >>> from dynamics.validate import positive
    >>> positive(2, "u_max")
    2.0
    >>> positive(0.0, "u_max")
    Traceback (most recent call last):
        ...
    ValueError: `u_max` must be a finite number > 0, got 0.0
    """
    v = finite_scalar(value, name)
    if not v > 0:
        raise ValueError(f"`{name}` must be a finite number > 0, got {value!r}")
    return v


def check_inertia(inertia, *, name="inertia", triangle=True):
    """Validate an inertia matrix and return it as a float array.

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2]
        Full symmetric matrix, or the three principal moments (a diagonal matrix).
    name : str
        Argument name used in error messages.
    triangle : bool
        Also require the triangle inequality of the principal moments, ``I_i + I_j >= I_k``
        (Rheinfurth & Wilson, NASA RP-1262, Sec. 4.4 A), which every physical body satisfies.

    Returns
    -------
    ndarray, shape (3, 3)

    Raises
    ------
    ArgumentTypeError
        (a ``TypeError`` and ``ValueError``) If ``inertia`` does not hold numbers.
    ValueError
        Naming the argument and the violated requirement: shape, finiteness, symmetry,
        positive definiteness (eigenvalues shown), triangle inequality (moments shown).

    Examples
    --------
    >>> from dynamics.validate import check_inertia
    >>> check_inertia([1.0, 2.0, 3.0])  # principal moments become a diagonal matrix
    array([[1., 0., 0.],
           [0., 2., 0.],
           [0., 0., 3.]])
    >>> check_inertia([1.0, 1.0, 3.0])
    Traceback (most recent call last):
        ...
    ValueError: `inertia` violates the triangle inequality I1 + I2 >= I3 ...
    """
    try:
        a = np.array(inertia, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ArgumentTypeError(f"`{name}` must be a 3x3 matrix of numbers: {exc}") from None
    if a.shape == (3,):
        a = np.diag(a)
    if a.shape != (3, 3):
        raise ValueError(f"`{name}` must have shape (3, 3) or (3,), got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"`{name}` must be finite, got {a.tolist()}")
    scale = np.max(np.abs(a))
    if np.max(np.abs(a - a.T)) > 1e-12 * max(scale, 1e-300):
        raise ValueError(f"`{name}` must be symmetric, got {a.tolist()}")
    a = 0.5 * (a + a.T)
    eig = np.linalg.eigvalsh(a)
    if eig[0] <= 0:
        raise ValueError(
            f"`{name}` must be symmetric positive definite, got eigenvalues {tuple(eig)}")
    if triangle and eig[0] + eig[1] < eig[2] * (1 - 1e-12):
        raise ValueError(
            f"`{name}` violates the triangle inequality I1 + I2 >= I3 of rigid-body principal "
            f"moments (Rheinfurth & Wilson, NASA RP-1262, Sec. 4.4 A): principal moments "
            f"{tuple(eig)}"
        )
    return a
