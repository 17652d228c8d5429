"""Euler angles: elementary rotations and the classical 3-1-3 and modern 3-2-1 sequences.

3-1-3 ``(psi, theta, phi)`` with ``A = A3(phi) A1(theta) A3(psi)``; 3-2-1 ``(psi, theta, phi)``
(yaw, pitch, roll) with ``A = A1(phi) A2(theta) A3(psi)`` (Sec. 4.3 d). See `dynamics.attitude`
for the conventions and input checks shared by all attitude functions.
"""
from __future__ import annotations

import warnings

from .. import validate
from .backend import checked, finite3, finite_any, ops_for, rotation_matrix
from .dcm import dcm_from_quat

__all__ = [
    "dcm_axis", "dcm_from_euler313", "euler313_from_dcm", "quat_from_euler313",
    "euler313_from_quat", "dcm_from_euler321", "euler321_from_dcm", "quat_from_euler321",
    "euler321_from_quat",
]


def dcm_axis(component=None, angle=None, *, axis=None):
    """Elementary frame rotation ``A1``, ``A2`` or ``A3`` (Eq. 4.45 about a coordinate axis).

    Parameters
    ----------
    component : {1, 2, 3}
        The coordinate axis, 1-based as in ``A1, A2, A3`` and the Euler sequences' digits
        (``3-1-3``): an int (numpy integers too; not a float or bool).
    angle : float or array (n,) [rad], or CasADi scalar
    axis : {1, 2, 3}, optional
        Deprecated name of ``component`` (warns; ``axis`` is a 3-vector elsewhere).

    Returns
    -------
    shape (3, 3) or (3, 3, n)

    Raises
    ------
    TypeError
        If ``component`` is not an integer.
    ValueError
        If ``component`` is not 1, 2 or 3, or ``angle`` is not finite.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import dcm_axis
    >>> np.round(dcm_axis(3, np.pi / 2), 6)  # A3: frame rotation about the third axis
    array([[ 0.,  1.,  0.],
           [-1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    """
    name = "component"
    if axis is not None:
        if component is not None:
            raise TypeError("pass `component` only; `axis` is its deprecated name")
        warnings.warn("the keyword `axis` of dcm_axis is deprecated (`axis` is a 3-vector; "
                      "a coordinate index is `component`); use `component=`",
                      DeprecationWarning, stacklevel=2)
        component, name = axis, "axis"
    axis = validate.one_of(component, name, (1, 2, 3))
    d = checked(angle, "angle", (), finite_any)
    o = ops_for(d)
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
    a = checked(angles, name, (3,), finite3)
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

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import dcm_axis, dcm_from_euler313
    >>> psi, theta, phi = 0.3, 0.2, 0.1
    >>> A = dcm_from_euler313([psi, theta, phi])
    >>> bool(np.allclose(A, dcm_axis(3, phi) @ dcm_axis(1, theta) @ dcm_axis(3, psi)))
    True
    """
    psi, th, phi = _angles(angles)
    o = ops_for(psi)
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

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import dcm_from_euler313, euler313_from_dcm
    >>> np.round(euler313_from_dcm(dcm_from_euler313([0.3, 0.2, 0.1])), 6)
    array([0.3, 0.2, 0.1])
    """
    return _euler313(checked(A, "A", (3, 3), rotation_matrix))


def _euler313(A):
    """`euler313_from_dcm` without the input check."""
    o = ops_for(A)
    psi = o.arctan2(A[2, 0], -A[2, 1])
    c, s = o.cos(psi), o.sin(psi)
    theta = o.arctan2(s * A[2, 0] - c * A[2, 1], A[2, 2])
    phi = o.arctan2(-(c * A[1, 0] + s * A[1, 1]), c * A[0, 0] + s * A[0, 1])
    return o.stack([psi, theta, phi])


def quat_from_euler313(angles):
    """Quaternion from classical 3-1-3 angles (Sec. 4.3 d C)::

        q = [sin(t/2) cos((psi-phi)/2), sin(t/2) sin((psi-phi)/2),
             cos(t/2) sin((psi+phi)/2), cos(t/2) cos((psi+phi)/2)]

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

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import quat_from_euler313
    >>> np.round(quat_from_euler313([np.pi / 2, 0.0, 0.0]), 6)  # psi = 90 deg about z
    array([0.      , 0.      , 0.707107, 0.707107])
    """
    psi, th, phi = _angles(angles)
    o = ops_for(psi)
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

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import euler313_from_quat, quat_from_euler313
    >>> np.round(euler313_from_quat(quat_from_euler313([0.3, 0.2, 0.1])), 6)
    array([0.3, 0.2, 0.1])
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

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import dcm_axis, dcm_from_euler321
    >>> yaw, pitch, roll = 0.3, 0.2, 0.1
    >>> A = dcm_from_euler321([yaw, pitch, roll])
    >>> bool(np.allclose(A, dcm_axis(1, roll) @ dcm_axis(2, pitch) @ dcm_axis(3, yaw)))
    True
    """
    psi, th, phi = _angles(angles)
    o = ops_for(psi)
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

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import dcm_from_euler321, euler321_from_dcm
    >>> np.round(euler321_from_dcm(dcm_from_euler321([0.3, -0.2, 0.1])), 6)
    array([ 0.3, -0.2,  0.1])
    """
    return _euler321(checked(A, "A", (3, 3), rotation_matrix))


def _euler321(A):
    """`euler321_from_dcm` without the input check."""
    o = ops_for(A)
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

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import quat_from_euler321
    >>> np.round(quat_from_euler321([0.0, 0.0, np.pi / 2]), 6)  # roll 90 deg about x
    array([0.707107, 0.      , 0.      , 0.707107])
    """
    psi, th, phi = _angles(angles)
    o = ops_for(psi)
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

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import euler321_from_quat, quat_from_euler321
    >>> np.round(np.degrees(euler321_from_quat(quat_from_euler321(np.radians([30, 20, 10])))), 6)
    array([30., 20., 10.])
    """
    return _euler321(dcm_from_quat(q))
