"""Direction cosine matrices: DCM <-> quaternion (Eq. 4.63, Sec. 4.3 E) and axis-angle (Eq. 4.45).

``A(q)`` maps inertial components to body components, ``x_body = A @ x_inertial``. See
`dynamics.attitude` for the conventions and input checks shared by all attitude functions.
"""
from __future__ import annotations

import numpy as np

from .. import validate
from .backend import (checked, finite_scalar, finite_vector, ops_for, rotation_matrix, unit_axis,
                      unit_quat)

__all__ = [
    "dcm_from_quat", "quat_from_dcm", "dcm_from_axis_angle", "quat_from_axis_angle",
    "axis_angle_from_quat",
]


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

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import dcm_from_quat
    >>> A = dcm_from_quat([0.0, 0.0, np.sin(np.pi / 4), np.cos(np.pi / 4)])  # 90 deg about z
    >>> np.round(A @ [1.0, 0.0, 0.0], 6)  # inertial x seen in the rotated body frame
    array([ 0., -1.,  0.])
    """
    q = checked(q, "q", (4,), unit_quat)
    q1, q2, q3, q4 = q[0], q[1], q[2], q[3]
    return ops_for(q).matrix(
        [
            [q1 * q1 - q2 * q2 - q3 * q3 + q4 * q4, 2 * (q1 * q2 + q3 * q4), 2 * (q1 * q3 - q2 * q4)],
            [2 * (q1 * q2 - q3 * q4), -q1 * q1 + q2 * q2 - q3 * q3 + q4 * q4, 2 * (q2 * q3 + q1 * q4)],
            [2 * (q1 * q3 + q2 * q4), 2 * (q2 * q3 - q1 * q4), -q1 * q1 - q2 * q2 + q3 * q3 + q4 * q4],
        ]
    )


def quat_from_dcm(A):
    """Quaternion from a rotation matrix by the largest-diagonal algorithm [1]_.

    Steps 1-5 of [1]_ (re-derived from Eqs. 4.79-4.80; the OCR of step 1 is garbled):
    with ``T = tr A`` and ``p = 2 q`` the symmetric matrix ``P = p p^T`` is::

        P = [[1+2A11-T, A12+A21, A13+A31, A23-A32],
             [A12+A21, 1+2A22-T, A23+A32, A31-A13],
             [A13+A31, A23+A32, 1+2A33-T, A12-A21],
             [A23-A32, A31-A13, A12-A21, 1+T]]

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

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import quat_from_dcm
    >>> A = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # 90 deg about z
    >>> np.round(quat_from_dcm(A), 6)
    array([0.      , 0.      , 0.707107, 0.707107])
    """
    A = checked(A, "A", (3, 3), rotation_matrix)
    o = ops_for(A)
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
        If ``axis`` is not 3 finite numbers or is zero, or ``angle`` is not one finite number
        (an array of angles is refused: use `quat_from_axis_angle` for a batch).

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import dcm_from_axis_angle
    >>> np.round(dcm_from_axis_angle([0, 0, 2], np.pi / 2), 6)  # the axis is normalized
    array([[ 0.,  1.,  0.],
           [-1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    """
    e = unit_axis(axis)
    d = checked(angle, "angle", (), finite_scalar)
    o = ops_for(e, d)
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
        If ``axis`` is not 3 finite numbers or is zero, or ``angle`` is not finite or not
        a scalar or 1-D array.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import quat_from_axis_angle
    >>> np.round(quat_from_axis_angle([1, 0, 0], np.pi), 6)
    array([1., 0., 0., 0.])
    """
    e = unit_axis(axis)
    d = checked(angle, "angle", (), finite_vector)
    o = ops_for(e, d)
    s, c = o.sin(d / 2), o.cos(d / 2)
    return o.stack([e[0] * s, e[1] * s, e[2] * s, c])


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

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import axis_angle_from_quat
    >>> axis, angle = axis_angle_from_quat([0.0, 0.6, 0.0, 0.8])
    >>> axis, round(float(np.degrees(angle)), 6)
    (array([0., 1., 0.]), 73.739795)
    """
    q = validate.finite_array(q, "q", (4,))
    q = validate.unit_quaternions(q, "q", normalize=True)
    if q[3] < 0:
        q = -q
    nv = np.linalg.norm(q[:3])
    if nv == 0:
        return np.array([1.0, 0.0, 0.0]), 0.0
    return q[:3] / nv, float(2 * np.arctan2(nv, q[3]))
