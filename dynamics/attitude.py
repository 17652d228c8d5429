"""Attitude kinematics: quaternions, direction cosines, Euler angles, principal axes.

Conventions (Rheinfurth & Wilson, NASA RP-1262, Sec. 4.3):

* Quaternion **scalar-last** ``q = [q1, q2, q3, q4]`` with ``q4 = cos(delta/2)`` (Eqs. 4.55-4.58).
* The direction cosine matrix ``A(q)`` (Eq. 4.63) maps inertial components to body components,
  ``x_body = A @ x_inertial``. Its rows are the body unit vectors in inertial components.
* Kinematics ``qdot = -1/2 Wbar(w) q`` (Eq. 4.70) with the body angular velocity ``w``.
* ``quat_mul(q, p)`` is defined so that ``A(quat_mul(q, p)) = A(q) @ A(p)``: ``p`` is applied
  first, then ``q`` (successive frame rotations).
* Euler angles: classical 3-1-3 ``(psi, theta, phi)`` with ``A = A3(phi) A1(theta) A3(psi)``;
  modern 3-2-1 ``(psi, theta, phi)`` (yaw, pitch, roll) with ``A = A1(phi) A2(theta) A3(psi)``.
  ``A1, A2, A3`` are frame rotations (Eq. 4.45 with the axis along a coordinate axis).

Every function works on numpy arrays and on CasADi ``SX``/``MX``/``DM`` alike. Arrays are
**components first**: a quaternion is shape ``(4,)`` or, for a batch, ``(4, n)``; a DCM is
``(3, 3)`` or ``(3, 3, n)``; Euler angle triples are ``(3,)`` or ``(3, n)``. CasADi inputs are
column vectors (``4x1``, ``3x1``) and ``3x3`` matrices.

Input checks (`dynamics.validate`): numeric arguments (numpy arrays, lists, numbers and CasADi
``DM``) are checked on every call; symbolic ``SX``/``MX`` arguments pass through untouched
(only their shape is checked), so the functions keep working inside CasADi graphs. A wrong
kind of object (string, dict, ``None``, complex, boolean) raises ``TypeError``; a wrong shape
or value raises ``ValueError`` naming the argument (for a batch, the first bad column, e.g.
``q[:, 3]``). What each function accepts:

* every number must be finite (no NaN, no infinity);
* a quaternion that stands for an *attitude* (``dcm_from_quat``, ``rotation_angle``,
  ``axis_angle_from_quat``, ``propagate_quat``, ``euler313_from_quat``,
  ``euler321_from_quat``) must have unit norm to ``validate.QUAT_NORM_TOL`` (1e-6); it is
  then normalized before use;
* quaternion *algebra* (``quat_mul``, ``quat_conj``, ``quat_rate``) accepts any finite
  quaternion, since it also acts on rates ``qdot`` and on states off the unit sphere;
  ``quat_normalize`` accepts any finite non-zero quaternion;
* a DCM argument must be a proper rotation: orthogonal to ``validate.DCM_ORTHO_TOL`` (1e-6,
  ``max |A A^T - E|``) with ``det A = +1``;
* a rotation axis must be a finite non-zero 3-vector (normalized here); angles, rates and
  time steps must be finite.
"""
from __future__ import annotations

import itertools

import casadi as ca
import numpy as np

from . import validate

__all__ = [
    "skew",
    "quat_mul",
    "quat_conj",
    "quat_normalize",
    "quat_kinematics_matrix",
    "quat_rate",
    "dcm_from_quat",
    "quat_from_dcm",
    "dcm_from_axis_angle",
    "quat_from_axis_angle",
    "axis_angle_from_quat",
    "rotation_angle",
    "propagate_quat",
    "dcm_axis",
    "dcm_from_euler313",
    "euler313_from_dcm",
    "quat_from_euler313",
    "euler313_from_quat",
    "dcm_from_euler321",
    "euler321_from_dcm",
    "quat_from_euler321",
    "euler321_from_quat",
    "principal_axes",
]

_CA_TYPES = (ca.SX, ca.MX, ca.DM)


# ---------------------------------------------------------------------------- backend
class _NumpyOps:
    sin, cos, sqrt, arctan2, arccos = np.sin, np.cos, np.sqrt, np.arctan2, np.arccos
    fabs = np.abs

    @staticmethod
    def stack(items):
        return np.stack(np.broadcast_arrays(*items), axis=0)

    @classmethod
    def matrix(cls, rows):
        return cls.stack([cls.stack(r) for r in rows])

    @staticmethod
    def where(cond, a, b):
        return np.where(cond, a, b)

    @staticmethod
    def sumsq(x):
        return np.sum(x * x, axis=0)


class _CasadiOps:
    sin, cos, sqrt, arctan2, arccos = ca.sin, ca.cos, ca.sqrt, ca.atan2, ca.acos
    fabs = ca.fabs

    @staticmethod
    def stack(items):
        return ca.vertcat(*items)

    @staticmethod
    def matrix(rows):
        return ca.vertcat(*[ca.horzcat(*r) for r in rows])

    @staticmethod
    def where(cond, a, b):
        return ca.if_else(cond, a, b)

    @staticmethod
    def sumsq(x):
        return ca.sumsqr(x)


def _ops(*args):
    return _CasadiOps if any(isinstance(a, _CA_TYPES) for a in args) else _NumpyOps


def _arg(x, name, shape, check):
    """Validate one argument: numbers by ``check(x, name)``, CasADi by shape.

    ``SX``/``MX`` symbols pass through untouched (only their shape is checked); a ``DM`` holds
    numbers, so its values are checked by ``check`` too, and it is returned as a DM (CasADi in,
    CasADi out). ``shape`` is the numpy shape of one item: ``(n,)`` means an ``n x 1`` CasADi
    column, ``()`` a ``1 x 1`` scalar.
    """
    if isinstance(x, _CA_TYPES):
        want = shape if len(shape) == 2 else ((shape[0], 1) if shape else (1, 1))
        if x.shape != want:
            kind = {(1, 1): "scalar (1x1)"}.get(want, f"{want[0]}x{want[1]} CasADi "
                                                     + ("column" if want[1] == 1 else "matrix"))
            raise ValueError(f"`{name}` must be a {kind}, got shape {x.shape}")
        if isinstance(x, ca.DM):
            check(x, name)
        return x
    return check(x, name)


# numeric checks of the argument kinds used below (components first, batches allowed)
def _finite3(x, name):
    return validate.finite_array(x, name, (3,), batch=True)


def _finite4(x, name):
    return validate.finite_array(x, name, (4,), batch=True)


def _unit_q(x, name):
    return validate.unit_quaternions(x, name, normalize=True)


def _rotation(x, name):
    return validate.rotation_matrix(x, name, batch=True)


def _finite_any(x, name):
    return validate.finite_array(x, name)


def _nonzero3(x, name):
    return validate.unit_vector(x, name, batch=True)


def _nonzero4(x, name):
    return validate.unit_vector(x, name, size=4, batch=True)


# ----------------------------------------------------------------------- quaternions
def skew(v):
    """Cross-product matrix ``[v x]`` so that ``skew(v) @ x = v x x``.

    Parameters
    ----------
    v : array_like, shape (3,) or (3, n), or CasADi 3x1

    Returns
    -------
    shape (3, 3) or (3, 3, n)

    Raises
    ------
    TypeError
        If an argument is not real numbers (e.g. a string, a dict or ``None``).
    ValueError
        If ``v`` does not have 3 components or is not finite.
    """
    v = _arg(v, "v", (3,), _finite3)
    o = _ops(v)
    z = 0 * v[0]
    return o.matrix([[z, -v[2], v[1]], [v[2], z, -v[0]], [-v[1], v[0], z]])


def quat_mul(q, p):
    """Quaternion product with ``A(quat_mul(q, p)) = A(q) @ A(p)`` (rotate by ``p``, then ``q``).

    ``quat_mul(q, p) = [q4 pv + p4 qv - qv x pv, q4 p4 - qv . pv]``.

    Any finite quaternions are accepted (not only unit ones): the product is also used on
    quaternion rates, e.g. ``w = 2 vec(quat_mul(qdot, quat_conj(q)))``.

    Parameters
    ----------
    q, p : array_like, shape (4,) or (4, n), or CasADi 4x1

    Returns
    -------
    shape (4,) or (4, n)

    Raises
    ------
    TypeError
        If an argument is not real numbers (e.g. a string, a dict or ``None``).
    ValueError
        If ``q`` or ``p`` does not have 4 components or is not finite.
    """
    q, p = _arg(q, "q", (4,), _finite4), _arg(p, "p", (4,), _finite4)
    o = _ops(q, p)
    q1, q2, q3, q4 = q[0], q[1], q[2], q[3]
    p1, p2, p3, p4 = p[0], p[1], p[2], p[3]
    return o.stack(
        [
            q4 * p1 + p4 * q1 - (q2 * p3 - q3 * p2),
            q4 * p2 + p4 * q2 - (q3 * p1 - q1 * p3),
            q4 * p3 + p4 * q3 - (q1 * p2 - q2 * p1),
            q4 * p4 - (q1 * p1 + q2 * p2 + q3 * p3),
        ]
    )


def quat_conj(q):
    """Conjugate (inverse rotation of a unit quaternion): ``[-qv, q4]``.

    Parameters
    ----------
    q : array_like, shape (4,) or (4, n), or CasADi 4x1
        Any finite quaternion

    Returns
    -------
    shape (4,) or (4, n)

    Raises
    ------
    TypeError
        If an argument is not real numbers (e.g. a string, a dict or ``None``).
    ValueError
        If ``q`` does not have 4 components or is not finite.
    """
    q = _arg(q, "q", (4,), _finite4)
    return _ops(q).stack([-q[0], -q[1], -q[2], q[3]])


def quat_normalize(q):
    """Scale ``q`` to unit norm (column by column for a batch).

    Parameters
    ----------
    q : array_like, shape (4,) or (4, n), or CasADi 4x1
        Any finite non-zero quaternion

    Returns
    -------
    shape (4,) or (4, n), unit norm

    Raises
    ------
    TypeError
        If an argument is not real numbers (e.g. a string, a dict or ``None``).
    ValueError
        If ``q`` does not have 4 components, is not finite, or is zero (numeric input).
    """
    if isinstance(q, _CA_TYPES):
        q = _arg(q, "q", (4,), _nonzero4)
        return q / ca.sqrt(ca.sumsqr(q))
    return validate.unit_vector(q, "q", size=4, batch=True)


def quat_kinematics_matrix(w):
    """The 4x4 matrix ``Wbar(w)`` of Eq. 4.70, ``qdot = -1/2 Wbar(w) q``.

    ``Wbar = [[skew(w), -w], [w^T, 0]]``; it is skew-symmetric with ``Wbar^2 = -|w|^2 E``.

    Parameters
    ----------
    w : array_like, shape (3,), or CasADi 3x1
        Body angular velocity [rad/s]

    Returns
    -------
    shape (4, 4)

    Raises
    ------
    TypeError
        If an argument is not real numbers (e.g. a string, a dict or ``None``).
    ValueError
        If ``w`` does not have 3 components or is not finite.
    """
    w = _arg(w, "w", (3,), _finite3)
    o = _ops(w)
    w1, w2, w3 = w[0], w[1], w[2]
    z = 0 * w1
    return o.matrix(
        [[z, -w3, w2, -w1], [w3, z, -w1, -w2], [-w2, w1, z, -w3], [w1, w2, w3, z]]
    )


def quat_rate(q, w):
    """Quaternion derivative ``qdot = -1/2 Wbar(w) q`` (Eq. 4.70), written out.

    A linear map of ``q``: any finite ``q`` is accepted (integrators evaluate it off the unit
    sphere, too).

    Parameters
    ----------
    q : shape (4,) or (4, n), or CasADi 4x1
        Attitude quaternion
    w : shape (3,) or (3, n), or CasADi 3x1
        Body angular velocity [rad/s]

    Returns
    -------
    shape (4,) or (4, n) [1/s]

    Raises
    ------
    TypeError
        If an argument is not real numbers (e.g. a string, a dict or ``None``).
    ValueError
        If ``q`` or ``w`` has the wrong number of components or is not finite.
    """
    q, w = _arg(q, "q", (4,), _finite4), _arg(w, "w", (3,), _finite3)
    o = _ops(q, w)
    q1, q2, q3, q4 = q[0], q[1], q[2], q[3]
    w1, w2, w3 = w[0], w[1], w[2]
    return o.stack(
        [
            0.5 * (q4 * w1 + q2 * w3 - q3 * w2),
            0.5 * (q4 * w2 + q3 * w1 - q1 * w3),
            0.5 * (q4 * w3 + q1 * w2 - q2 * w1),
            -0.5 * (q1 * w1 + q2 * w2 + q3 * w3),
        ]
    )


def dcm_from_quat(q):
    """Direction cosine matrix of Eq. 4.63 (inertial -> body components).

    A numeric ``q`` must be a unit quaternion (to ``validate.QUAT_NORM_TOL``); it is
    normalized before use, so the result is orthogonal to round-off. For a CasADi symbol the
    formula is applied as it stands: for a non-unit ``q`` its value is ``|q|^2`` times a
    rotation (no normalization).

    Parameters
    ----------
    q : array_like, shape (4,) or (4, n), or CasADi 4x1

    Returns
    -------
    A : shape (3, 3) or (3, 3, n)

    Raises
    ------
    TypeError
        If an argument is not real numbers (e.g. a string, a dict or ``None``).
    ValueError
        If ``q`` does not have 4 components, or (numeric) a column is not finite or not of
        unit norm.
    """
    q = _arg(q, "q", (4,), _unit_q)
    q1, q2, q3, q4 = q[0], q[1], q[2], q[3]
    return _ops(q).matrix(
        [
            [q1 * q1 - q2 * q2 - q3 * q3 + q4 * q4, 2 * (q1 * q2 + q3 * q4), 2 * (q1 * q3 - q2 * q4)],
            [2 * (q1 * q2 - q3 * q4), -q1 * q1 + q2 * q2 - q3 * q3 + q4 * q4, 2 * (q2 * q3 + q1 * q4)],
            [2 * (q1 * q3 + q2 * q4), 2 * (q2 * q3 - q1 * q4), -q1 * q1 - q2 * q2 + q3 * q3 + q4 * q4],
        ]
    )


def quat_from_dcm(A):
    """Quaternion from a rotation matrix by the largest-diagonal algorithm [1]_.

    Steps 1-5 of [1]_ (re-derived from Eqs. 4.79-4.80; the OCR of step 1 is garbled):
    with ``T = tr A`` and ``p = 2 q`` the symmetric matrix ``P = p p^T`` is

    ``P = [[1+2A11-T, A12+A21, A13+A31, A23-A32],
           [A12+A21, 1+2A22-T, A23+A32, A31-A13],
           [A13+A31, A23+A32, 1+2A33-T, A12-A21],
           [A23-A32, A31-A13, A12-A21, 1+T]]``.

    The row ``k`` of the largest diagonal element gives ``q = P[k] / (2 sqrt(P[k, k]))`` up to
    sign, chosen so that ``q4 >= 0``.

    Parameters
    ----------
    A : array_like, shape (3, 3) or (3, 3, n), or CasADi 3x3
        A rotation matrix

    Returns
    -------
    q : shape (4,) or (4, n), unit norm (to the orthogonality of ``A``), ``q4 >= 0``

    Raises
    ------
    TypeError
        If an argument is not real numbers (e.g. a string, a dict or ``None``).
    ValueError
        If ``A`` is not 3x3, or (numeric) not finite, not orthogonal to
        ``validate.DCM_ORTHO_TOL`` or not of determinant +1.

    References
    ----------
    .. [1] Rheinfurth & Wilson, NASA RP-1262, Sec. 4.3 E, steps 1-5 and Eqs. 4.79-4.80.
    """
    A = _arg(A, "A", (3, 3), _rotation)
    o = _ops(A)
    a = [[A[i, j] for j in range(3)] for i in range(3)]
    tr = a[0][0] + a[1][1] + a[2][2]
    P = [
        [1 + 2 * a[0][0] - tr, a[0][1] + a[1][0], a[0][2] + a[2][0], a[1][2] - a[2][1]],
        [a[0][1] + a[1][0], 1 + 2 * a[1][1] - tr, a[1][2] + a[2][1], a[2][0] - a[0][2]],
        [a[0][2] + a[2][0], a[1][2] + a[2][1], 1 + 2 * a[2][2] - tr, a[0][1] - a[1][0]],
        [a[1][2] - a[2][1], a[2][0] - a[0][2], a[0][1] - a[1][0], 1 + tr],
    ]
    # candidate quaternion from each row; the one with the largest pivot is best conditioned
    cands = []
    for k in range(4):
        pivot = 2 * o.sqrt(o.where(P[k][k] > 0, P[k][k], 1.0))
        qk = [P[k][j] / pivot for j in range(4)]
        sign = o.where(qk[3] < 0, -1.0, 1.0)
        cands.append([sign * c for c in qk])
    best, best_val = cands[0], P[0][0]
    for k in range(1, 4):
        better = P[k][k] > best_val
        best = [o.where(better, c, b) for c, b in zip(cands[k], best)]
        best_val = o.where(better, P[k][k], best_val)
    return o.stack(best)


def _unit_axis(axis, name="axis"):
    if isinstance(axis, _CA_TYPES):
        axis = _arg(axis, name, (3,), _nonzero3)
        return axis / ca.sqrt(ca.sumsqr(axis))
    return validate.unit_vector(axis, name, batch=True)


def dcm_from_axis_angle(axis, angle):
    """Rotation matrix of Eq. 4.45: frame rotated by ``angle`` about ``axis``.

    ``A = E cos(d) + e e^T (1 - cos d) - [e x] sin(d)`` (elements 4.46-4.54).

    Parameters
    ----------
    axis : array_like, shape (3,), or CasADi 3x1
        Rotation axis (normalized here)
    angle : float [rad], or CasADi scalar

    Returns
    -------
    A : shape (3, 3)

    Raises
    ------
    TypeError
        If an argument is not real numbers (e.g. a string, a dict or ``None``).
    ValueError
        If ``axis`` is not 3 finite numbers or is zero, or ``angle`` is not finite.
    """
    e = _unit_axis(axis)
    d = _arg(angle, "angle", (), _finite_any)
    o = _ops(e, d)
    c, s = o.cos(d), o.sin(d)
    ca_, cb, cg = e[0], e[1], e[2]  # direction cosines cos(alpha), cos(beta), cos(gamma)
    return o.matrix(
        [
            [c + ca_ * ca_ * (1 - c), ca_ * cb * (1 - c) + cg * s, ca_ * cg * (1 - c) - cb * s],
            [ca_ * cb * (1 - c) - cg * s, c + cb * cb * (1 - c), cb * cg * (1 - c) + ca_ * s],
            [ca_ * cg * (1 - c) + cb * s, cb * cg * (1 - c) - ca_ * s, c + cg * cg * (1 - c)],
        ]
    )


def quat_from_axis_angle(axis, angle):
    """Euler parameters of Eqs. 4.55-4.58: ``[e sin(d/2), cos(d/2)]``.

    Parameters
    ----------
    axis : array_like, shape (3,), or CasADi 3x1
        Rotation axis (normalized here)
    angle : float or array (n,) [rad], or CasADi scalar

    Returns
    -------
    q : shape (4,) or (4, n)

    Raises
    ------
    TypeError
        If an argument is not real numbers (e.g. a string, a dict or ``None``).
    ValueError
        If ``axis`` is not 3 finite numbers or is zero, or ``angle`` is not finite.
    """
    e = _unit_axis(axis)
    d = _arg(angle, "angle", (), _finite_any)
    o = _ops(e, d)
    s, c = o.sin(d / 2), o.cos(d / 2)
    return o.stack([e[0] * s, e[1] * s, e[2] * s, c])


def rotation_angle(q):
    """Rotation angle ``delta`` in ``[0, pi]`` of a unit quaternion (``q`` and ``-q`` agree).

    Computed as ``2 atan2(|qv|, |q4|)``, accurate also near 0 and pi.

    Parameters
    ----------
    q : array_like, shape (4,) or (4, n), or CasADi 4x1
        Unit quaternion

    Returns
    -------
    float or shape (n,) [rad]

    Raises
    ------
    TypeError
        If an argument is not real numbers (e.g. a string, a dict or ``None``).
    ValueError
        If ``q`` does not have 4 components, or (numeric) a column is not finite or not of
        unit norm.
    """
    q = _arg(q, "q", (4,), _unit_q)
    o = _ops(q)
    nv = o.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2])
    return 2 * o.arctan2(nv, o.fabs(q[3]))


def axis_angle_from_quat(q):
    """Axis and angle of a unit quaternion, with the angle in ``[0, pi]``.

    Parameters
    ----------
    q : array_like, shape (4,)
        Numpy only

    Returns
    -------
    axis : ndarray, shape (3,)
        Unit vector (``[1, 0, 0]`` for the identity)
    angle : float [rad]

    Raises
    ------
    TypeError
        If ``q`` is symbolic or not numbers.
    ValueError
        If ``q`` is not 4 finite numbers of unit norm (to ``validate.QUAT_NORM_TOL``).
    """
    q = validate.finite_array(q, "q", (4,))
    q = validate.unit_quaternions(q, "q", normalize=True)
    if q[3] < 0:
        q = -q
    nv = np.linalg.norm(q[:3])
    if nv == 0:
        return np.array([1.0, 0.0, 0.0]), 0.0
    return q[:3] / nv, float(2 * np.arctan2(nv, q[3]))


def propagate_quat(q, w, h):
    """Closed-form quaternion update for a constant body rate [1]_.

    ``q(h) = (E cos(|w| h/2) - Wbar(w)/|w| sin(|w| h/2)) q`` — exact for constant ``w``, norm
    preserving to round-off. Written with ``sin(x)/x`` so that ``w -> 0`` is smooth (also
    under CasADi differentiation).

    Parameters
    ----------
    q : shape (4,) or CasADi 4x1
        Unit quaternion at the start of the step
    w : shape (3,) or CasADi 3x1
        Constant body angular velocity [rad/s]
    h : float or CasADi scalar
        Step [s]

    Returns
    -------
    shape (4,)
        Quaternion after the step

    Raises
    ------
    TypeError
        If an argument is not real numbers (e.g. a string, a dict or ``None``).
    ValueError
        If (numeric) ``q`` is not a finite unit quaternion, ``w`` or ``h`` is not finite,
        or ``|w| h`` is too large to represent.

    References
    ----------
    .. [1] Rheinfurth & Wilson, NASA RP-1262, Sec. 4.3, "Integration of Quaternions" (Eq. 4.70 for constant ``w``).
    """
    q, w = _arg(q, "q", (4,), _unit_q), _arg(w, "w", (3,), _finite3)
    h = _arg(h, "h", (), _finite_any)
    o = _ops(q, w, h)
    if o is _NumpyOps:
        with np.errstate(over="ignore", invalid="ignore"):
            big = ~np.isfinite(np.sum(w * w, axis=0) * h * h)
        if np.any(big):
            raise ValueError(f"`w` and `h` are too large: |w|^2 h^2 is not representable "
                             f"(max |w_i| = {np.max(np.abs(w)):.3g} rad/s, "
                             f"max |h| = {np.max(np.abs(h)):.3g} s)")
    wn2 = o.sumsq(w)
    x2 = wn2 * h * h / 4  # (|w| h / 2)^2
    small = x2 < 1e-8
    x = o.sqrt(o.where(small, 1.0, x2))
    c = o.where(small, 1 - x2 / 2 + x2 * x2 / 24, o.cos(x))
    sinc = o.where(small, 1 - x2 / 6 + x2 * x2 / 120, o.sin(x) / x)
    k = sinc * h / 2  # sin(|w| h/2) / |w|
    dq = quat_rate(q, w)  # -1/2 Wbar q
    return o.stack([c * q[i] + k * 2 * dq[i] for i in range(4)])


# ---------------------------------------------------------------------- Euler angles
def dcm_axis(axis: int, angle):
    """Elementary frame rotation ``A1``, ``A2`` or ``A3`` (Eq. 4.45 about a coordinate axis).

    Parameters
    ----------
    axis : {1, 2, 3}
        An int (numpy integers too; not a float or bool)
    angle : float or array (n,) [rad], or CasADi scalar

    Returns
    -------
    shape (3, 3) or (3, 3, n)

    Raises
    ------
    TypeError
        If ``axis`` is not an integer.
    ValueError
        If ``axis`` is not 1, 2 or 3, or ``angle`` is not finite.
    """
    axis = validate.one_of(axis, "axis", (1, 2, 3))
    d = _arg(angle, "angle", (), _finite_any)
    o = _ops(d)
    c, s = o.cos(d), o.sin(d)
    one, z = 1 + 0 * d, 0 * d
    if axis == 1:
        rows = [[one, z, z], [z, c, s], [z, -s, c]]
    elif axis == 2:
        rows = [[c, z, -s], [z, one, z], [s, z, c]]
    else:
        rows = [[c, s, z], [-s, c, z], [z, z, one]]
    return o.matrix(rows)


def _angles(angles, name="angles"):
    a = _arg(angles, name, (3,), _finite3)
    return a[0], a[1], a[2]


def dcm_from_euler313(angles):
    """DCM from classical 3-1-3 Euler angles ``(psi, theta, phi)``: ``A3(phi) A1(theta) A3(psi)``.

    Parameters
    ----------
    angles : array_like, shape (3,) or (3, n) [rad]

    Returns
    -------
    A : shape (3, 3) or (3, 3, n)

    Raises
    ------
    TypeError
        If an argument is not real numbers (e.g. a string, a dict or ``None``).
    ValueError
        If ``angles`` does not have 3 components or is not finite.
    """
    psi, th, phi = _angles(angles)
    o = _ops(psi)
    cps, sps, cth, sth, cph, sph = o.cos(psi), o.sin(psi), o.cos(th), o.sin(th), o.cos(phi), o.sin(phi)
    return o.matrix(
        [
            [cph * cps - sph * cth * sps, cph * sps + sph * cth * cps, sph * sth],
            [-sph * cps - cph * cth * sps, -sph * sps + cph * cth * cps, cph * sth],
            [sth * sps, -sth * cps, cth],
        ]
    )


def euler313_from_dcm(A):
    """Classical 3-1-3 angles ``(psi, theta, phi)`` from a DCM.

    Sec. 4.3 d A with the quadrant rules applied by ``atan2``: ``theta in [0, pi]``,
    ``psi = atan2(A31, -A32)`` (the OCR's ``A31/A32`` drops the sign of ``A32 = -sin(theta)
    cos(psi)``), ``psi, phi in (-pi, pi]``. ``theta`` and ``phi`` are then taken from
    ``A A3(psi)^T = A3(phi) A1(theta)``, which stays accurate near gimbal lock
    (``theta -> 0, pi``), where only ``psi +/- phi`` is defined and ``psi = 0`` is returned.

    Parameters
    ----------
    A : shape (3, 3) or (3, 3, n)

    Returns
    -------
    shape (3,) or (3, n) [rad]

    Raises
    ------
    TypeError
        If an argument is not real numbers (e.g. a string, a dict or ``None``).
    ValueError
        If ``A`` is not 3x3, or (numeric) not finite, not orthogonal to
        ``validate.DCM_ORTHO_TOL`` or not of determinant +1.
    """
    return _euler313(_arg(A, "A", (3, 3), _rotation))


def _euler313(A):
    """`euler313_from_dcm` without the input check."""
    o = _ops(A)
    psi = o.arctan2(A[2, 0], -A[2, 1])
    c, s = o.cos(psi), o.sin(psi)
    theta = o.arctan2(s * A[2, 0] - c * A[2, 1], A[2, 2])
    phi = o.arctan2(-(c * A[1, 0] + s * A[1, 1]), c * A[0, 0] + s * A[0, 1])
    return o.stack([psi, theta, phi])


def quat_from_euler313(angles):
    """Quaternion from classical 3-1-3 angles (Sec. 4.3 d C).

    ``q = [sin(t/2) cos((psi-phi)/2), sin(t/2) sin((psi-phi)/2),
           cos(t/2) sin((psi+phi)/2), cos(t/2) cos((psi+phi)/2)]``
    (not sign-normalized: ``q4`` may be negative).

    Parameters
    ----------
    angles : array_like, shape (3,) or (3, n) [rad], or CasADi 3x1

    Returns
    -------
    q : shape (4,) or (4, n)

    Raises
    ------
    TypeError
        If an argument is not real numbers (e.g. a string, a dict or ``None``).
    ValueError
        If ``angles`` does not have 3 components or is not finite.
    """
    psi, th, phi = _angles(angles)
    o = _ops(psi)
    st, ct = o.sin(th / 2), o.cos(th / 2)
    dm, dp = (psi - phi) / 2, (psi + phi) / 2
    return o.stack([st * o.cos(dm), st * o.sin(dm), ct * o.sin(dp), ct * o.cos(dp)])


def euler313_from_quat(q):
    """Classical 3-1-3 angles from a unit quaternion (via the DCM).

    Parameters
    ----------
    q : array_like, shape (4,) or (4, n), or CasADi 4x1
        Unit quaternion

    Returns
    -------
    shape (3,) or (3, n) [rad]

    Raises
    ------
    TypeError
        If an argument is not real numbers (e.g. a string, a dict or ``None``).
    ValueError
        If ``q`` does not have 4 components, or (numeric) a column is not finite or not of
        unit norm.
    """
    return _euler313(dcm_from_quat(q))


def dcm_from_euler321(angles):
    """DCM from modern 3-2-1 angles ``(psi, theta, phi)`` (yaw, pitch, roll): ``A1(phi) A2(theta) A3(psi)``.

    Parameters
    ----------
    angles : array_like, shape (3,) or (3, n) [rad]

    Returns
    -------
    A : shape (3, 3) or (3, 3, n)

    Raises
    ------
    TypeError
        If an argument is not real numbers (e.g. a string, a dict or ``None``).
    ValueError
        If ``angles`` does not have 3 components or is not finite.
    """
    psi, th, phi = _angles(angles)
    o = _ops(psi)
    cps, sps, cth, sth, cph, sph = o.cos(psi), o.sin(psi), o.cos(th), o.sin(th), o.cos(phi), o.sin(phi)
    return o.matrix(
        [
            [cth * cps, cth * sps, -sth],
            [-cph * sps + sph * sth * cps, cph * cps + sph * sth * sps, sph * cth],
            [sph * sps + cph * sth * cps, -sph * cps + cph * sth * sps, cph * cth],
        ]
    )


def euler321_from_dcm(A):
    """Modern 3-2-1 angles ``(psi, theta, phi)`` from a DCM.

    Sec. 4.3 d B with the quadrant rules applied by ``atan2``: ``psi = atan2(A12, A11)``,
    ``theta = asin(-A13)`` in ``[-pi/2, pi/2]`` (the OCR's ``-A33`` is a glitch), ``phi`` from
    ``A A3(psi)^T = A1(phi) A2(theta)``, which stays accurate near gimbal lock
    (``theta -> +/- pi/2``), where ``psi = 0`` is returned.

    Parameters
    ----------
    A : shape (3, 3) or (3, 3, n)

    Returns
    -------
    shape (3,) or (3, n) [rad]

    Raises
    ------
    TypeError
        If an argument is not real numbers (e.g. a string, a dict or ``None``).
    ValueError
        If ``A`` is not 3x3, or (numeric) not finite, not orthogonal to
        ``validate.DCM_ORTHO_TOL`` or not of determinant +1.
    """
    return _euler321(_arg(A, "A", (3, 3), _rotation))


def _euler321(A):
    """`euler321_from_dcm` without the input check."""
    o = _ops(A)
    psi = o.arctan2(A[0, 1], A[0, 0])
    c, s = o.cos(psi), o.sin(psi)
    theta = o.arctan2(-A[0, 2], c * A[0, 0] + s * A[0, 1])
    phi = o.arctan2(s * A[2, 0] - c * A[2, 1], c * A[1, 1] - s * A[1, 0])
    return o.stack([psi, theta, phi])


def quat_from_euler321(angles):
    """Quaternion from modern 3-2-1 angles (Sec. 4.3 d D); ``q4`` may be negative.

    Parameters
    ----------
    angles : array_like, shape (3,) or (3, n) [rad], or CasADi 3x1

    Returns
    -------
    q : shape (4,) or (4, n)

    Raises
    ------
    TypeError
        If an argument is not real numbers (e.g. a string, a dict or ``None``).
    ValueError
        If ``angles`` does not have 3 components or is not finite.
    """
    psi, th, phi = _angles(angles)
    o = _ops(psi)
    s1, c1 = o.sin(psi / 2), o.cos(psi / 2)
    s2, c2 = o.sin(th / 2), o.cos(th / 2)
    s3, c3 = o.sin(phi / 2), o.cos(phi / 2)
    return o.stack(
        [
            s3 * c1 * c2 - s1 * s2 * c3,
            s2 * c1 * c3 + s1 * s3 * c2,
            s1 * c2 * c3 - s2 * s3 * c1,
            s1 * s2 * s3 + c1 * c2 * c3,
        ]
    )


def euler321_from_quat(q):
    """Modern 3-2-1 angles from a unit quaternion (via the DCM).

    Parameters
    ----------
    q : array_like, shape (4,) or (4, n), or CasADi 4x1
        Unit quaternion

    Returns
    -------
    shape (3,) or (3, n) [rad]

    Raises
    ------
    TypeError
        If an argument is not real numbers (e.g. a string, a dict or ``None``).
    ValueError
        If ``q`` does not have 4 components, or (numeric) a column is not finite or not of
        unit norm.
    """
    return _euler321(dcm_from_quat(q))


# --------------------------------------------------------------------- principal axes
def principal_axes(inertia, *, order="nearest"):
    """Principal moments and the principal-axes rotation [1]_.

    The eigenvectors of ``inertia`` form the modal matrix ``Phi`` (columns); the rotation is
    ``A = Phi^T`` so that ``A @ inertia @ A.T = diag(moments)`` and ``x_principal = A @ x_ref``.
    Eigenvector signs are chosen so that ``det A = +1`` and the rotation angle
    (``tr A = 1 + 2 cos delta``) is the smallest, as in [1]_.

    Parameters
    ----------
    inertia : array_like, shape (3, 3) [kg m^2]
        Symmetric positive definite
    order : {"nearest", "ascending", "descending"}
        ``"nearest"`` (default) also chooses which principal axis is called 1, 2, 3: among
        all 24 proper assignments the smallest rotation wins, so each principal axis keeps the
        label of the reference axis it lies closest to (the Gemini ordering of [1]_).
        ``"ascending"``/``"descending"`` fix the order of the moments and choose signs only.

    Returns
    -------
    moments : ndarray, shape (3,) [kg m^2]
    A : ndarray, shape (3, 3)
        Rotation from reference to principal axes (rows = axes)

    Raises
    ------
    TypeError
        If ``inertia`` is not numbers or ``order`` is not a string.
    ValueError
        If ``inertia`` is not a finite, symmetric, positive definite 3x3 matrix, or ``order``
        is unknown.

    References
    ----------
    .. [1] Rheinfurth & Wilson, NASA RP-1262, Sec. 4.4 D (the Gemini example).
    """

    inertia = validate.check_inertia(validate.finite_array(inertia, "inertia"), triangle=False)
    order = validate.one_of(order, "order", ("nearest", "ascending", "descending"))
    vals, vecs = np.linalg.eigh(inertia)  # ascending
    perms = list(itertools.permutations(range(3)))
    if order == "ascending":
        perms = [(0, 1, 2)]
    elif order == "descending":
        perms = [(2, 1, 0)]
    best = None
    for perm in perms:
        for signs in itertools.product((1.0, -1.0), repeat=3):
            phi = vecs[:, perm] * np.array(signs)
            if np.linalg.det(phi) < 0:
                continue
            tr = np.trace(phi)
            if best is None or tr > best[0] + 1e-12:
                best = (tr, vals[list(perm)], phi.T.copy())
    return best[1], best[2]
