"""Attitude kinematics: quaternions, direction cosines, Euler angles, principal axes.

Conventions (seed: Rheinfurth & Wilson, NASA RP-1262, Sec. 4.3):

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
"""
from __future__ import annotations

import itertools

import casadi as ca
import numpy as np

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


def _vec(x, n, name):
    """Validate a length-``n`` vector (or components-first batch) argument."""
    if isinstance(x, _CA_TYPES):
        if x.shape != (n, 1):
            raise ValueError(f"`{name}` must be a {n}x1 CasADi column, got shape {x.shape}")
        return x
    a = np.asarray(x, dtype=float)
    if a.ndim == 0 or a.shape[0] != n:
        raise ValueError(f"`{name}` must have shape ({n},) or ({n}, ...), got {a.shape}")
    return a


def _mat3(A, name="A"):
    if isinstance(A, _CA_TYPES):
        if A.shape != (3, 3):
            raise ValueError(f"`{name}` must be a 3x3 CasADi matrix, got shape {A.shape}")
        return A
    a = np.asarray(A, dtype=float)
    if a.ndim < 2 or a.shape[:2] != (3, 3):
        raise ValueError(f"`{name}` must have shape (3, 3) or (3, 3, ...), got {a.shape}")
    return a


def _scalar(x, name):
    if isinstance(x, _CA_TYPES):
        if x.numel() != 1:
            raise ValueError(f"`{name}` must be a scalar, got shape {x.shape}")
        return x
    return np.asarray(x, dtype=float)


# ----------------------------------------------------------------------- quaternions
def skew(v):
    """Cross-product matrix ``[v x]`` so that ``skew(v) @ x = v x x``.

    Parameters
    ----------
    v : array_like, shape (3,) or (3, n), or CasADi 3x1

    Returns
    -------
    shape (3, 3) or (3, 3, n)
    """
    v = _vec(v, 3, "v")
    o = _ops(v)
    z = 0 * v[0]
    return o.matrix([[z, -v[2], v[1]], [v[2], z, -v[0]], [-v[1], v[0], z]])


def quat_mul(q, p):
    """Quaternion product with ``A(quat_mul(q, p)) = A(q) @ A(p)`` (rotate by ``p``, then ``q``).

    ``quat_mul(q, p) = [q4 pv + p4 qv - qv x pv, q4 p4 - qv . pv]``.

    Parameters
    ----------
    q, p : array_like, shape (4,) or (4, n), or CasADi 4x1

    Returns
    -------
    shape (4,) or (4, n)
    """
    q, p = _vec(q, 4, "q"), _vec(p, 4, "p")
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
    """Conjugate (inverse rotation of a unit quaternion): ``[-qv, q4]``."""
    q = _vec(q, 4, "q")
    return _ops(q).stack([-q[0], -q[1], -q[2], q[3]])


def quat_normalize(q):
    """Scale ``q`` to unit norm. Raises ``ValueError`` for a numeric zero quaternion."""
    q = _vec(q, 4, "q")
    o = _ops(q)
    n = o.sqrt(o.sumsq(q))
    if o is _NumpyOps and np.any(n == 0):
        raise ValueError("`q` must be non-zero to normalize")
    return q / n


def quat_kinematics_matrix(w):
    """The 4x4 matrix ``Wbar(w)`` of Eq. 4.70, ``qdot = -1/2 Wbar(w) q``.

    ``Wbar = [[skew(w), -w], [w^T, 0]]``; it is skew-symmetric with ``Wbar^2 = -|w|^2 E``.

    Parameters
    ----------
    w : array_like, shape (3,), or CasADi 3x1 — body angular velocity [rad/s]

    Returns
    -------
    shape (4, 4)
    """
    w = _vec(w, 3, "w")
    o = _ops(w)
    w1, w2, w3 = w[0], w[1], w[2]
    z = 0 * w1
    return o.matrix(
        [[z, -w3, w2, -w1], [w3, z, -w1, -w2], [-w2, w1, z, -w3], [w1, w2, w3, z]]
    )


def quat_rate(q, w):
    """Quaternion derivative ``qdot = -1/2 Wbar(w) q`` (Eq. 4.70), written out.

    Parameters
    ----------
    q : shape (4,) or (4, n) — attitude quaternion
    w : shape (3,) or (3, n) — body angular velocity [rad/s]

    Returns
    -------
    shape (4,) or (4, n) [1/s]
    """
    q, w = _vec(q, 4, "q"), _vec(w, 3, "w")
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

    For a non-unit ``q`` the result is ``|q|^2`` times a rotation (no normalization).

    Parameters
    ----------
    q : array_like, shape (4,) or (4, n), or CasADi 4x1

    Returns
    -------
    A : shape (3, 3) or (3, 3, n)
    """
    q = _vec(q, 4, "q")
    q1, q2, q3, q4 = q[0], q[1], q[2], q[3]
    return _ops(q).matrix(
        [
            [q1 * q1 - q2 * q2 - q3 * q3 + q4 * q4, 2 * (q1 * q2 + q3 * q4), 2 * (q1 * q3 - q2 * q4)],
            [2 * (q1 * q2 - q3 * q4), -q1 * q1 + q2 * q2 - q3 * q3 + q4 * q4, 2 * (q2 * q3 + q1 * q4)],
            [2 * (q1 * q3 + q2 * q4), 2 * (q2 * q3 - q1 * q4), -q1 * q1 - q2 * q2 + q3 * q3 + q4 * q4],
        ]
    )


def quat_from_dcm(A):
    """Quaternion from a rotation matrix by the seed's largest-diagonal algorithm.

    Sec. 4.3 E, steps 1-5 (re-derived from Eqs. 4.79-4.80; the OCR of step 1 is garbled):
    with ``T = tr A`` and ``p = 2 q`` the symmetric matrix ``P = p p^T`` is

    ``P = [[1+2A11-T, A12+A21, A13+A31, A23-A32],
           [A12+A21, 1+2A22-T, A23+A32, A31-A13],
           [A13+A31, A23+A32, 1+2A33-T, A12-A21],
           [A23-A32, A31-A13, A12-A21, 1+T]]``.

    The row ``k`` of the largest diagonal element gives ``q = P[k] / (2 sqrt(P[k, k]))`` up to
    sign, chosen so that ``q4 >= 0``.

    Parameters
    ----------
    A : array_like, shape (3, 3) or (3, 3, n), or CasADi 3x3 — a rotation matrix

    Returns
    -------
    q : shape (4,) or (4, n), unit norm, ``q4 >= 0``
    """
    A = _mat3(A)
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
    axis = _vec(axis, 3, name)
    o = _ops(axis)
    n = o.sqrt(o.sumsq(axis))
    if o is _NumpyOps and np.any(n == 0):
        raise ValueError(f"`{name}` must be a non-zero vector")
    return axis / n


def dcm_from_axis_angle(axis, angle):
    """Rotation matrix of Eq. 4.45: frame rotated by ``angle`` about ``axis``.

    ``A = E cos(d) + e e^T (1 - cos d) - [e x] sin(d)`` (elements 4.46-4.54).

    Parameters
    ----------
    axis : array_like, shape (3,) — rotation axis (normalized here)
    angle : float [rad]

    Returns
    -------
    A : shape (3, 3)
    """
    e = _unit_axis(axis)
    d = _scalar(angle, "angle")
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
    axis : array_like, shape (3,) — rotation axis (normalized here)
    angle : float or array (n,) [rad]

    Returns
    -------
    q : shape (4,) or (4, n)
    """
    e = _unit_axis(axis)
    d = _scalar(angle, "angle")
    o = _ops(e, d)
    s, c = o.sin(d / 2), o.cos(d / 2)
    return o.stack([e[0] * s, e[1] * s, e[2] * s, c])


def rotation_angle(q):
    """Rotation angle ``delta`` in ``[0, pi]`` of a unit quaternion (``q`` and ``-q`` agree).

    Computed as ``2 atan2(|qv|, |q4|)``, accurate also near 0 and pi.
    """
    q = _vec(q, 4, "q")
    o = _ops(q)
    nv = o.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2])
    return 2 * o.arctan2(nv, o.fabs(q[3]))


def axis_angle_from_quat(q):
    """Axis and angle of a unit quaternion, with the angle in ``[0, pi]``.

    Parameters
    ----------
    q : array_like, shape (4,) — numpy only

    Returns
    -------
    axis : ndarray, shape (3,) — unit vector (``[1, 0, 0]`` for the identity)
    angle : float [rad]
    """
    q = np.asarray(_vec(q, 4, "q"), dtype=float)
    if q.ndim != 1:
        raise ValueError(f"`q` must have shape (4,), got {q.shape}")
    q = q / np.linalg.norm(q)
    if q[3] < 0:
        q = -q
    nv = np.linalg.norm(q[:3])
    if nv == 0:
        return np.array([1.0, 0.0, 0.0]), 0.0
    return q[:3] / nv, float(2 * np.arctan2(nv, q[3]))


def propagate_quat(q, w, h):
    """Closed-form quaternion update for a constant body rate (seed, "Integration of Quaternions").

    ``q(h) = (E cos(|w| h/2) - Wbar(w)/|w| sin(|w| h/2)) q`` — exact for constant ``w``, norm
    preserving to round-off. Written with ``sin(x)/x`` so that ``w -> 0`` is smooth (also
    under CasADi differentiation).

    Parameters
    ----------
    q : shape (4,) or CasADi 4x1 — quaternion at the start of the step
    w : shape (3,) or CasADi 3x1 — constant body angular velocity [rad/s]
    h : float — step [s]

    Returns
    -------
    shape (4,) — quaternion after the step
    """
    q, w = _vec(q, 4, "q"), _vec(w, 3, "w")
    h = _scalar(h, "h")
    o = _ops(q, w, h)
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
    angle : float [rad]

    Returns
    -------
    shape (3, 3)
    """
    if axis not in (1, 2, 3):
        raise ValueError(f"`axis` must be 1, 2 or 3, got {axis!r}")
    d = _scalar(angle, "angle")
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
    a = _vec(angles, 3, name)
    return a[0], a[1], a[2]


def dcm_from_euler313(angles):
    """DCM from classical 3-1-3 Euler angles ``(psi, theta, phi)``: ``A3(phi) A1(theta) A3(psi)``.

    Parameters
    ----------
    angles : array_like, shape (3,) or (3, n) [rad]

    Returns
    -------
    A : shape (3, 3) or (3, 3, n)
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
    """
    A = _mat3(A)
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
    """
    psi, th, phi = _angles(angles)
    o = _ops(psi)
    st, ct = o.sin(th / 2), o.cos(th / 2)
    dm, dp = (psi - phi) / 2, (psi + phi) / 2
    return o.stack([st * o.cos(dm), st * o.sin(dm), ct * o.sin(dp), ct * o.cos(dp)])


def euler313_from_quat(q):
    """Classical 3-1-3 angles from a unit quaternion (via the DCM)."""
    return euler313_from_dcm(dcm_from_quat(q))


def dcm_from_euler321(angles):
    """DCM from modern 3-2-1 angles ``(psi, theta, phi)`` (yaw, pitch, roll): ``A1(phi) A2(theta) A3(psi)``.

    Parameters
    ----------
    angles : array_like, shape (3,) or (3, n) [rad]

    Returns
    -------
    A : shape (3, 3) or (3, 3, n)
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
    """
    A = _mat3(A)
    o = _ops(A)
    psi = o.arctan2(A[0, 1], A[0, 0])
    c, s = o.cos(psi), o.sin(psi)
    theta = o.arctan2(-A[0, 2], c * A[0, 0] + s * A[0, 1])
    phi = o.arctan2(s * A[2, 0] - c * A[2, 1], c * A[1, 1] - s * A[1, 0])
    return o.stack([psi, theta, phi])


def quat_from_euler321(angles):
    """Quaternion from modern 3-2-1 angles (Sec. 4.3 d D); ``q4`` may be negative."""
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
    """Modern 3-2-1 angles from a unit quaternion (via the DCM)."""
    return euler321_from_dcm(dcm_from_quat(q))


# --------------------------------------------------------------------- principal axes
def principal_axes(inertia, *, order="nearest"):
    """Principal moments and the principal-axes rotation (seed Sec. 4.4 D, Gemini example).

    The eigenvectors of ``inertia`` form the modal matrix ``Phi`` (columns); the rotation is
    ``A = Phi^T`` so that ``A @ inertia @ A.T = diag(moments)`` and ``x_principal = A @ x_ref``.
    Eigenvector signs are chosen so that ``det A = +1`` and the rotation angle
    (``tr A = 1 + 2 cos delta``) is the smallest, as in the seed.

    Parameters
    ----------
    inertia : array_like, shape (3, 3) [kg m^2] — symmetric positive definite
    order : {"nearest", "ascending", "descending"}
        ``"nearest"`` (default) also chooses which principal axis is called 1, 2, 3: among
        all 24 proper assignments the smallest rotation wins, so each principal axis keeps the
        label of the reference axis it lies closest to (the seed's Gemini ordering).
        ``"ascending"``/``"descending"`` fix the order of the moments and choose signs only.

    Returns
    -------
    moments : ndarray, shape (3,) [kg m^2]
    A : ndarray, shape (3, 3) — rotation from reference to principal axes (rows = axes)

    Raises
    ------
    ValueError
        If ``inertia`` is not a finite, symmetric, positive definite 3x3 matrix, or ``order``
        is unknown.
    """
    from .rigid_body import check_inertia  # local import: rigid_body imports this module

    inertia = check_inertia(inertia, triangle=False)
    if order not in ("nearest", "ascending", "descending"):
        raise ValueError(f"`order` must be 'nearest', 'ascending' or 'descending', got {order!r}")
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
