"""Closed forms of an axisymmetric body and of a constant body rate: rates, attitude, precession.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .. import validate
from .common import (EQUAL_RTOL, axis_index_arg, axis_quat, check_moments, check_times, dcm,
                     deprecated_field, quat_mul)

__all__ = ["axisymmetric", "constant_rate_quat", "SymmetricPrecession", "symmetric_precession"]


def _symmetry_axis(inertia, axis_index, name="axis_index"):
    """Index of the symmetry axis: ``axis_index`` checked, or inferred when ``None``."""
    tol = EQUAL_RTOL * inertia.max()

    def equal(i, j):
        return abs(inertia[i] - inertia[j]) <= tol

    if axis_index is None:
        if equal(0, 1) and equal(1, 2) and equal(0, 2):
            return 0  # sphere: every axis is a symmetry axis
        candidates = [a for a in range(3) if equal((a + 1) % 3, (a + 2) % 3)]
        if len(candidates) != 1:
            raise ValueError(
                "`inertia_diag` must have two equal moments (an axisymmetric body), "
                f"got {inertia.tolist()}"
            )
        return candidates[0]
    a = validate.one_of(axis_index, name, (0, 1, 2))
    if not equal((a + 1) % 3, (a + 2) % 3):
        raise ValueError(
            f"`inertia_diag` must have equal transverse moments for symmetry `{name}` {a}, "
            f"got {inertia.tolist()}"
        )
    return a


def axisymmetric(inertia_diag, w0, q0, t, *, axis_index=None, axis=None):
    """Exact rates and attitude of a torque-free axisymmetric body.

    Parameters
    ----------
    inertia_diag : array_like, shape (3,) [kg m^2]
        Principal moments; the two transverse ones must be equal (relative ``1e-12``;
        their mean is used). Positive, triangle inequality.
    w0 : array_like, shape (3,) [rad/s]
        Body rates at ``t = 0``.
    q0 : array_like, shape (4,)
        Attitude quaternion at ``t = 0`` (scalar last, ``A(q0)`` maps inertial to body).
        Must have unit norm within ``1e-6``; it is normalized.
    t : float or array_like, shape (n,) [s]
        Times; a scalar gives ``n = 1``. Any real times.
    axis_index : {0, 1, 2}, optional
        Index of the symmetry axis. Inferred when ``None`` (``0`` for a sphere).
    axis : int, optional
        Deprecated name of ``axis_index`` (warns).

    Returns
    -------
    w : ndarray, shape (3, n) [rad/s]
        Body rates.
    q : ndarray, shape (4, n)
        Attitude quaternions, a smooth function of ``t`` with ``q[:, t == 0] == q0``; the
        sign of ``q4`` is not normalized (``q`` and ``-q`` are the same attitude).

    Raises
    ------
    ValueError
        Naming ``inertia_diag`` (bad moments, or not axisymmetric about ``axis_index``),
        ``axis_index``,
        ``w0``, ``q0`` or ``t``.

    Notes
    -----
    With symmetry axis ``e``, axial moment ``I_a``, transverse ``I_t``, axial rate ``n``:
    Euler's equations give ``n = const`` and ``w_perp' = lam e x w_perp`` with
    ``lam = (I_a - I_t) / I_t * n``, so the transverse rate turns about ``+e`` at ``lam``.
    Since ``h = I w = I_t w + (I_a - I_t) n e``, ``w = omega_p h_hat - lam e`` with
    ``omega_p = |H| / I_t``. With ``R = A^T`` (body to inertial) and ``R' = R [w x]``,
    ``R(t) = Rot(h_in, omega_p t) R0 Rot(e, -lam t)`` solves the kinematics (``h_in`` the
    inertially fixed unit momentum, ``Rot`` an active rotation), because
    ``R^T h_in = Rot(e, lam t) h_b(0)`` is the body momentum direction at ``t``. In
    quaternions, with ``A([e sin(a/2), cos(a/2)]) = Rot(e, a)^T``:
    ``q(t) = quat_mul(quat_mul([e sin(-lam t/2), cos(lam t/2)], q0),
    [h_in sin(omega_p t/2), cos(omega_p t/2)])``.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.truth import axisymmetric
    >>> w, q = axisymmetric([1.0, 1.0, 2.0], [0.1, 0.0, 0.5], [0, 0, 0, 1], [0.0, np.pi])
    >>> np.round(w, 6)  # the transverse rate turns at lam = (2 - 1) / 1 * 0.5 rad/s
    array([[0.1, 0. ],
           [0. , 0.1],
           [0.5, 0.5]])
    >>> np.round(q[:, 1], 6)
    array([0.070358, 0.070358, 0.709116, 0.698036])
    """
    inertia = check_moments(inertia_diag)
    a = _symmetry_axis(inertia, *axis_index_arg(axis_index, axis, None))
    w0 = validate.finite_array(w0, "w0", (3,))
    q0 = validate.unit_quaternion(q0, "q0")
    t = check_times(t)
    i_ax = inertia[a]
    i_tr = 0.5 * (inertia[(a + 1) % 3] + inertia[(a + 2) % 3])
    e = np.zeros(3)
    e[a] = 1.0
    n = w0[a]
    w_perp = w0 - n * e
    lam = (i_ax - i_tr) / i_tr * n
    c, s = np.cos(lam * t), np.sin(lam * t)
    w = n * e[:, None] + np.outer(w_perp, c) + np.outer(np.cross(e, w_perp), s)
    h_body = i_tr * w0 + (i_ax - i_tr) * n * e
    h_mag = float(np.linalg.norm(h_body))
    if h_mag == 0.0:
        return w, np.repeat(q0[:, None], t.size, axis=1)
    h_in = dcm(q0).T @ (h_body / h_mag)
    omega_p = h_mag / i_tr
    q = quat_mul(quat_mul(axis_quat(e, -lam * t), q0[:, None]), axis_quat(h_in, omega_p * t))
    return w, q


def constant_rate_quat(q0, w, t):
    """Attitude under a constant body rate: ``q(t) = quat_mul(q_rot(t), q0)``.

    Parameters
    ----------
    q0 : array_like, shape (4,)
        Attitude at ``t = 0`` (scalar last); unit norm within ``1e-6``, normalized.
    w : array_like, shape (3,) [rad/s]
        Constant body angular velocity.
    t : float or array_like, shape (n,) [s]
        Times; a scalar gives ``n = 1``. Any real times.

    Returns
    -------
    q : ndarray, shape (4, n)
        ``q_rot = [e sin(|w| t/2), cos(|w| t/2)]`` with ``e = w/|w|`` applied after ``q0``;
        ``q0`` for all ``t`` when ``w = 0``. Continuous in ``t``; ``q4`` may be negative.

    Raises
    ------
    ValueError
        Naming ``q0``, ``w`` or ``t``.

    Notes
    -----
    ``A' = -[w x] A`` with constant ``w`` gives ``A(t) = exp(-[w x] t) A0
    = Rot(e, |w| t)^T A0 = A(q_rot) A(q0)``.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.truth import constant_rate_quat
    >>> np.round(constant_rate_quat([0, 0, 0, 1], [0.0, 0.0, np.pi], 0.5)[:, 0], 6)  # 90 deg
    array([0.      , 0.      , 0.707107, 0.707107])
    """
    q0 = validate.unit_quaternion(q0, "q0")
    w = validate.finite_array(w, "w", (3,))
    t = check_times(t)
    rate = float(np.linalg.norm(w))
    if rate == 0.0:
        return np.repeat(q0[:, None], t.size, axis=1)
    return quat_mul(axis_quat(w / rate, rate * t), q0[:, None])


class SymmetricPrecession(NamedTuple):
    """Rates and nutation angle of a torque-free axisymmetric body.

    Attributes
    ----------
    omega_p : float [rad/s]
        Inertial precession rate ``|H| / I_t`` of the symmetry axis about ``H``; for small
        nutation ``~ I_a / I_t * n = n + lam`` (Rheinfurth & Wilson, NASA RP-1262, Sec. 4.5 C, note).
    lam : float [rad/s]
        Body-frame rate ``(I_a - I_t) / I_t * n`` at which the transverse rate turns about the
        symmetry axis (positive: counter-clockwise about ``+e``).
    nutation : float [rad]
        Constant angle between ``H`` and the symmetry axis, in ``[0, pi]``.
    axis_index : int
        Index of the symmetry axis (``.axis`` is its deprecated name).
    """

    omega_p: float
    lam: float
    nutation: float
    axis_index: int

    @property
    def axis(self):
        """Deprecated name of `axis_index` (``axis`` is a 3-vector in this project)."""
        return deprecated_field(self.axis_index)


def symmetric_precession(inertia_diag, w0, *, axis_index=None, axis=None):
    """Precession rate, body nutation rate and nutation angle of an axisymmetric body.

    Parameters
    ----------
    inertia_diag : array_like, shape (3,) [kg m^2]
        Principal moments with two equal transverse moments (see :func:`axisymmetric`).
    w0 : array_like, shape (3,) [rad/s]
        Body rates.
    axis_index : {0, 1, 2}, optional
        Symmetry axis index; inferred when ``None``.
    axis : int, optional
        Deprecated name of ``axis_index`` (warns).

    Returns
    -------
    SymmetricPrecession

    Raises
    ------
    ValueError
        Naming ``inertia_diag``, ``axis_index`` or ``w0``.

    Examples
    --------
    >>> from appdyn.dynamics.truth import symmetric_precession
    >>> prec = symmetric_precession([1.0, 1.0, 2.0], [0.1, 0.0, 0.5])
    >>> round(float(prec.omega_p), 6), round(float(prec.lam), 6), prec.axis_index
    (1.004988, 0.5, 2)
    """
    inertia = check_moments(inertia_diag)
    a = _symmetry_axis(inertia, *axis_index_arg(axis_index, axis, None))
    w0 = validate.finite_array(w0, "w0", (3,))
    i_ax = inertia[a]
    i_tr = 0.5 * (inertia[(a + 1) % 3] + inertia[(a + 2) % 3])
    n = w0[a]
    transverse = float(np.hypot(w0[(a + 1) % 3], w0[(a + 2) % 3]))
    h_mag = float(np.hypot(i_ax * n, i_tr * transverse))
    return SymmetricPrecession(
        h_mag / i_tr, (i_ax - i_tr) / i_tr * n, float(np.arctan2(i_tr * transverse, i_ax * n)), a
    )
