"""Quaternion algebra and kinematics: products, conjugate, normalization, rates, propagation.

Scalar-last ``q = [q1, q2, q3, q4]``, ``q4 = cos(delta/2)``; ``qdot = -1/2 Wbar(w) q`` (Eq. 4.70)
with the body angular velocity ``w``; ``A(quat_mul(q, p)) = A(q) @ A(p)``. See `dynamics.attitude`
for the conventions and input checks shared by all attitude functions.
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from .. import validate
from .backend import (CA_TYPES, NumpyOps, checked, finite3, finite4, finite_scalar,
                      nonzero4, ops_for, unit_quat)

__all__ = [
    "skew", "quat_mul", "quat_conj", "quat_normalize", "quat_kinematics_matrix", "quat_rate",
    "rotation_angle", "propagate_quat",
]


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

    Examples
    --------
    >>> from appdyn.dynamics.attitude import skew
    >>> skew([1.0, 2.0, 3.0]) @ [0.0, 0.0, 1.0]  # [1, 2, 3] x e3
    array([ 2., -1.,  0.])
    """
    v = checked(v, "v", (3,), finite3)
    o = ops_for(v)
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

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import dcm_from_quat, quat_from_axis_angle, quat_mul
    >>> q = quat_from_axis_angle([0, 0, 1], np.pi / 2)
    >>> p = quat_from_axis_angle([1, 0, 0], np.pi / 2)
    >>> np.round(quat_mul(q, p), 6)
    array([ 0.5, -0.5,  0.5,  0.5])
    >>> bool(np.allclose(dcm_from_quat(quat_mul(q, p)), dcm_from_quat(q) @ dcm_from_quat(p)))
    True
    """
    q, p = checked(q, "q", (4,), finite4), checked(p, "p", (4,), finite4)
    o = ops_for(q, p)
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

    Examples
    --------
    >>> from appdyn.dynamics.attitude import quat_conj, quat_mul
    >>> q = [0.5, 0.5, 0.5, 0.5]
    >>> quat_conj(q)
    array([-0.5, -0.5, -0.5,  0.5])
    >>> quat_mul(q, quat_conj(q))  # the identity
    array([0., 0., 0., 1.])
    """
    q = checked(q, "q", (4,), finite4)
    return ops_for(q).stack([-q[0], -q[1], -q[2], q[3]])


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

    Examples
    --------
    >>> from appdyn.dynamics.attitude import quat_normalize
    >>> quat_normalize([0.0, 0.0, 3.0, 4.0])
    array([0. , 0. , 0.6, 0.8])
    """
    if isinstance(q, CA_TYPES):
        q = checked(q, "q", (4,), nonzero4)
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

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import quat_kinematics_matrix
    >>> W = quat_kinematics_matrix([1.0, 2.0, 2.0])
    >>> W.shape, bool(np.allclose(W @ W, -9 * np.eye(4)))  # Wbar^2 = -|w|^2 E
    ((4, 4), True)
    """
    w = checked(w, "w", (3,), finite3)
    o = ops_for(w)
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

    Examples
    --------
    >>> import casadi as ca
    >>> from appdyn.dynamics.attitude import quat_rate
    >>> quat_rate([0.0, 0.0, 0.0, 1.0], [0.2, 0.0, 0.0])  # spin about body x at 0.2 rad/s
    array([ 0.1,  0. ,  0. , -0. ])
    >>> q, w = ca.SX.sym("q", 4), ca.SX.sym("w", 3)  # symbolic, for a CasADi model
    >>> quat_rate(q, w).shape
    (4, 1)
    """
    q, w = checked(q, "q", (4,), finite4), checked(w, "w", (3,), finite3)
    o = ops_for(q, w)
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

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import quat_from_axis_angle, rotation_angle
    >>> round(float(np.degrees(rotation_angle(quat_from_axis_angle([1, 1, 0], np.radians(120))))), 6)
    120.0
    """
    q = checked(q, "q", (4,), unit_quat)
    o = ops_for(q)
    nv = o.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2])
    return 2 * o.arctan2(nv, o.fabs(q[3]))


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
        If (numeric) ``q`` is not a finite unit quaternion, ``w`` is not finite, ``h`` is not
        one finite number, or ``|w| h`` is too large to represent.

    References
    ----------
    .. [1] Rheinfurth & Wilson, NASA RP-1262, Sec. 4.3, "Integration of Quaternions" (Eq. 4.70 for constant ``w``).

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import propagate_quat
    >>> q = propagate_quat([0.0, 0.0, 0.0, 1.0], [0.0, 0.0, np.pi], 0.5)  # 90 deg about z
    >>> np.round(q, 6)
    array([0.      , 0.      , 0.707107, 0.707107])
    """
    q, w = checked(q, "q", (4,), unit_quat), checked(w, "w", (3,), finite3)
    h = checked(h, "h", (), finite_scalar)
    o = ops_for(q, w, h)
    if o is NumpyOps:
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
