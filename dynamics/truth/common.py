"""Shared pieces of the closed-form truths: input checks, tolerances and private-to-truth kernels.

The quaternion product and the direction cosine matrix are written out here rather than
imported from `dynamics.attitude`, so that a bug there cannot hide itself in the tests that
use these truths as references. Only the input checks are shared (`dynamics.validate`).
"""
from __future__ import annotations

import warnings

import numpy as np

from .. import validate

__all__ = [
    "TRIANGLE_RTOL", "EQUAL_RTOL", "FLUSH", "check_moments", "check_rates", "check_times",
    "quat_mul", "axis_quat", "dcm", "pow2", "proper_sort", "axis_index_arg", "deprecated_field",
]


# Relative tolerance of the triangle inequality (same as dynamics.validate.check_inertia)
# and of "equal moments" in `axisymmetric`.
TRIANGLE_RTOL = 1e-12
EQUAL_RTOL = 1e-12
# Rate components below this fraction of the largest are flushed to zero (see
# `torque_free.torque_free_parameters`).
FLUSH = 1e-140


def check_moments(inertia_diag, name="inertia_diag"):
    """Three positive principal moments that satisfy the triangle inequality."""
    a = validate.finite_array(inertia_diag, name, (3,))
    if np.any(a <= 0):
        raise ValueError(f"`{name}` must be positive principal moments, got {a.tolist()}")
    s = np.sort(a)
    if s[0] + s[1] < s[2] * (1 - TRIANGLE_RTOL):
        raise ValueError(
            f"`{name}` violates the triangle inequality I_i + I_j >= I_k of principal "
            f"moments (Rheinfurth & Wilson, NASA RP-1262, Sec. 4.4 A), got {a.tolist()}"
        )
    return a


def check_rates(w, name="w"):
    """Body rates, shape (3,) or (3, n)."""
    a = validate.finite_array(w, name, (3,), batch=True)
    if a.ndim > 2:
        raise ValueError(f"`{name}` must have shape (3,) or (3, n), got {a.shape}")
    return a


def check_times(t, name="t"):
    """A time or a 1-D array of times, as a 1-D array."""
    a = validate.finite_array(t, name)
    if a.ndim > 1:
        raise ValueError(f"`{name}` must be a scalar or 1-D array of times, got shape {a.shape}")
    return np.atleast_1d(a)


def quat_mul(q, p):
    """``[q4 pv + p4 qv - qv x pv, q4 p4 - qv . pv]``; shapes (4,) / (4, n) broadcast."""
    qv, q4 = q[:3], q[3]
    pv, p4 = p[:3], p[3]
    vec = q4 * pv + p4 * qv - np.cross(qv, pv, axis=0)
    sca = q4 * p4 - np.sum(qv * pv, axis=0)
    return np.concatenate([vec, np.expand_dims(sca, 0)], axis=0)


def axis_quat(e, angle):
    """``[e sin(angle/2), cos(angle/2)]``, shape (4, n); ``A(q) = Rot(e, angle)^T``."""
    half = 0.5 * np.asarray(angle, dtype=float)
    return np.concatenate([np.outer(e, np.sin(half)), np.cos(half)[None, :]], axis=0)


def dcm(q):
    """Eq. 4.63, ``A = (q4^2 - |qv|^2) E + 2 qv qv^T - 2 q4 [qv x]``, for one unit ``q``."""
    qv, q4 = q[:3], q[3]
    cross = np.array([[0.0, -qv[2], qv[1]], [qv[2], 0.0, -qv[0]], [-qv[1], qv[0], 0.0]])
    return (q4 * q4 - qv @ qv) * np.eye(3) + 2.0 * np.outer(qv, qv) - 2.0 * q4 * cross


def pow2(x):
    """The power of two nearest above ``x > 0`` (scaling by it is exact)."""
    return float(np.ldexp(1.0, int(np.frexp(x)[1])))


def proper_sort(inertia):
    """Signed permutation ``S`` (det +1) with ``S diag(I) S^T`` ascending, and the order."""
    order = np.argsort(inertia, kind="stable")
    perm = np.zeros((3, 3))
    perm[np.arange(3), order] = 1.0
    # An odd permutation reverses cross products; -perm is then proper, and Euler's
    # equations (invariant under proper rotations) keep their form for w_s = S w.
    return perm * np.linalg.det(perm), order


def axis_index_arg(axis_index, axis, default):
    """Resolve ``axis_index`` and its deprecated keyword ``axis``: ``(value, name)``.

    ``name`` is the keyword the caller used, so that error messages name it. Passing
    ``axis=`` warns (``DeprecationWarning``, pointing at the caller of the public function).
    """
    if axis is None:
        return (default if axis_index is None else axis_index), "axis_index"
    if axis_index is not None:
        raise TypeError("pass `axis_index` only; `axis` is its deprecated name")
    warnings.warn("the keyword `axis` is deprecated (an integer component is `axis_index`; "
                  "`axis` is a 3-vector); use `axis_index=`", DeprecationWarning, stacklevel=3)
    return axis, "axis"


def deprecated_field(value):
    """``value``, with a `DeprecationWarning` for reading a result's old ``.axis`` field."""
    warnings.warn("the field `axis` is deprecated; use `axis_index`", DeprecationWarning,
                  stacklevel=3)
    return value
