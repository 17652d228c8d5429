"""Checks of directions and rotations: unit vectors, unit quaternions, rotation matrices."""
from __future__ import annotations

import math

import numpy as np

from .base import check_shape, cross3, dot3, first_index, member, norm, real_array, short_repr
from .numbers import finite_array

__all__ = ["QUAT_NORM_TOL", "DCM_ORTHO_TOL", "AXIS_NORM_TOL", "EULER_LOCK_TOL", "unit_vector",
           "unit_axes",
           "check_unit_quaternion", "unit_quaternion", "unit_quaternions", "rotation_matrix"]

#: How far a quaternion argument may deviate from unit norm before it is refused.
QUAT_NORM_TOL = 1e-6

#: Largest accepted ``max |A A^T - E|`` of a rotation-matrix argument.
DCM_ORTHO_TOL = 1e-6

#: Largest accepted ``| |axis| - 1 |`` of a device axis (wheel spin axes, CMG gimbal and
#: spin axes): they define the device, so they are refused, not normalized, when off.
AXIS_NORM_TOL = 1e-9

#: Smallest accepted ``|cos(theta)|`` (3-2-1) or ``|sin(theta)|`` (3-1-3) of a numeric
#: ``angles`` argument of ``attitude.euler321_rates`` / ``attitude.euler313_rates``: closer to
#: gimbal lock the angle rates exceed ``1e9`` times the body rates and mean nothing.
EULER_LOCK_TOL = 1e-9




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
    >>> from appdyn.dynamics.validate import unit_vector
    >>> unit_vector([0, 3, 4], "axis")
    array([0. , 0.6, 0.8])
    """
    a = finite_array(v, name, (size,), batch=batch)
    m = np.max(np.abs(a), axis=0)
    zero = m == 0
    if np.any(zero):
        idx = first_index(zero)
        raise ValueError(f"`{member(name, 1, idx)}` must be a non-zero vector, got "
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
    >>> from appdyn.dynamics.validate import unit_quaternion
    >>> unit_quaternion([0.0, 0.6, 0.0, 0.8], "q0")
    array([0. , 0.6, 0. , 0.8])
    >>> unit_quaternion([0.0, 0.0, 0.0, 2.0], "q0")
    Traceback (most recent call last):
        ...
    ValueError: `q0` must be a unit quaternion (norm 1 to 1e-06), got norm 2
    """
    a = real_array(q, name).reshape(-1)
    if a.shape != (4,) or not np.all(np.isfinite(a)):
        raise ValueError(
            f"`{name}` must be 4 finite numbers (scalar-last quaternion), got {short_repr(q)}")
    n = norm(a)
    if not abs(n - 1.0) <= tol:
        raise ValueError(
            f"`{name}` must be a unit quaternion (norm 1 to {tol:g}), got norm {n:.9g}")
    return a / n


def check_unit_quaternion(q, name: str, *, tol: float = QUAT_NORM_TOL) -> None:
    """`unit_quaternion`'s check alone (same errors), without building ``q / |q|``.

    A float64 ``(4,)`` array whose sum of squares is within ``tol`` of 1 (less a margin for
    rounding) has ``|q|`` within about ``tol / 2`` of 1: it passes at once, the common case
    (under a microsecond); any other ``q`` goes through `unit_quaternion`, which decides
    and words the error.

    Examples
    --------
    >>> from appdyn.dynamics.validate import check_unit_quaternion
    >>> check_unit_quaternion([0.0, 0.6, 0.0, 0.8], "q0")
    >>> check_unit_quaternion([0.0, 0.0, 0.0, 2.0], "q0")
    Traceback (most recent call last):
        ...
    ValueError: `q0` must be a unit quaternion (norm 1 to 1e-06), got norm 2
    """
    if type(q) is np.ndarray and q.shape == (4,) and q.dtype == np.float64:
        q1, q2, q3, q4 = q.tolist()
        if abs(q1 * q1 + q2 * q2 + q3 * q3 + q4 * q4 - 1.0) <= tol - 1e-15:  # not NaN
            return
    unit_quaternion(q, name, tol=tol)


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
    >>> from appdyn.dynamics.validate import unit_quaternions
    >>> unit_quaternions([[0.0, 0.0], [0.0, 0.6], [0.0, 0.0], [1.0, 0.8]], "q")  # (4, n)
    array([[0. , 0. ],
           [0. , 0.6],
           [0. , 0. ],
           [1. , 0.8]])
    """
    a = real_array(q, name)
    check_shape(a, name, (4,), True)
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
        idx = first_index(bad)
        col = a if idx is None else a[(slice(None), *idx)]
        label = member(name, 1, idx)
        if not np.all(np.isfinite(col)):
            raise ValueError(f"`{label}` must be finite, got {col.tolist()}")
        raise ValueError(f"`{label}` must be a unit quaternion (norm 1 to {tol:g}), "
                         f"got norm {norm(col):.9g}")
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
    >>> from appdyn.dynamics.validate import rotation_matrix
    >>> rotation_matrix(2 * np.eye(3), "A")
    Traceback (most recent call last):
        ...
    ValueError: `A` must be a rotation matrix (orthogonal to 1e-06), got max |A A^T - E| = 3
    """
    a = real_array(A, name)
    check_shape(a, name, (3, 3), batch)
    if a.ndim == 2:  # fast path for one matrix, in Python floats (no numpy warnings)
        r = a.tolist()
        err = max(abs(dot3(r[i], r[j]) - (i == j)) for i in range(3) for j in range(i, 3))
        if err <= tol and dot3(r[0], cross3(r[1], r[2])) > 0:  # False for NaN
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
        idx = first_index(bad)
        m = a if idx is None else a[(slice(None), slice(None), *idx)]
        label = member(name, 2, idx)
        if not np.all(np.isfinite(m)):
            raise ValueError(f"`{label}` must be finite, got {m.tolist()}")
        e = float(err if idx is None else err[idx])
        raise ValueError(f"`{label}` must be a rotation matrix (orthogonal to {tol:g}), "
                         f"got max |A A^T - E| = {e:.3g}")
    det = (r0[0] * (r1[1] * r2[2] - r1[2] * r2[1]) + r0[1] * (r1[2] * r2[0] - r1[0] * r2[2])
           + r0[2] * (r1[0] * r2[1] - r1[1] * r2[0]))
    neg = ~(det > 0)
    if np.any(neg):
        idx = first_index(neg)
        raise ValueError(f"`{member(name, 2, idx)}` must be a proper rotation (det +1), got "
                         f"det {float(det if idx is None else det[idx]):.9g} (a reflection)")
    return a


def unit_axes(axes, name: str, *, n: int | None = None, tol: float = AXIS_NORM_TOL) -> np.ndarray:
    """Check unit axes given as the columns of a ``(3, n)`` array (or one ``(3,)`` axis).

    Parameters
    ----------
    axes : array_like, shape (3, n) or (3,)
        Unit vectors as columns, components first.
    name : str
        Argument name used in error messages.
    n : int, optional
        Required number of columns.
    tol : float, optional
        Largest accepted ``| |axis| - 1 |`` (default `AXIS_NORM_TOL`).

    Returns
    -------
    ndarray, shape (3, n)
        The axes scaled to exactly unit length.

    Raises
    ------
    TypeError
        If ``axes`` does not hold real numbers.
    ValueError
        Naming ``name`` (and the column): wrong shape, not finite, no columns, a zero column
        or one not of unit length to ``tol``.

    Examples
    --------
    >>> from appdyn.dynamics.validate import unit_axes
    >>> unit_axes([[1.0, 0.0], [0.0, 0.6], [0.0, 0.8]], "axes")
    array([[1. , 0. ],
           [0. , 0.6],
           [0. , 0.8]])
    >>> unit_axes([[2.0], [0.0], [0.0]], "axes")
    Traceback (most recent call last):
        ...
    ValueError: `axes[:, 0]` must be a unit vector (norm 1 to 1e-09), got norm 2
    """
    a = finite_array(axes, name)
    if a.shape == (3,):
        a = a.reshape(3, 1)
    if a.ndim != 2 or a.shape[0] != 3 or a.shape[1] == 0:
        raise ValueError(f"`{name}` must have shape (3, n) with n >= 1 (components first, one "
                         f"unit axis per column), got {a.shape}")
    if n is not None and a.shape[1] != n:
        raise ValueError(f"`{name}` must have shape (3, {n}), got {a.shape}")
    norms = np.linalg.norm(a, axis=0)
    for j, nj in enumerate(norms):
        if not abs(nj - 1.0) <= tol:
            what = "a non-zero unit vector" if nj == 0 else f"a unit vector (norm 1 to {tol:g})"
            raise ValueError(f"`{member(name, 1, (j,))}` must be {what}, got norm {nj:.12g}")
    return a / norms
