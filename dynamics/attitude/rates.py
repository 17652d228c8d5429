"""Kinematical differential equations: Euler-angle rates and the DCM (Poisson) equation.

Rheinfurth & Wilson, NASA RP-1262, Sec. 4.3 (re-derived; the OCR's matrices were checked term
by term against the angle-rate sums 4.34-4.35 and 4.39):

* the Poisson equation ``A' = -[w x] A`` (Eq. 4.33) for the DCM ``A`` that maps inertial to
  body components (``x_body = A x_inertial``; its rows are the body unit vectors), with the
  body angular velocity ``w``;
* classical 3-1-3 ``(psi, theta, phi)``, ``A = A3(phi) A1(theta) A3(psi)`` (Eqs. 4.36-4.37)::

      w1 = psi' sin(theta) sin(phi) + theta' cos(phi)
      w2 = psi' sin(theta) cos(phi) - theta' sin(phi)
      w3 = psi' cos(theta) + phi'

  singular (gimbal lock) at ``sin(theta) = 0``, i.e. ``theta = 0`` or ``pi``;
* modern 3-2-1 ``(psi, theta, phi)`` (yaw, pitch, roll), ``A = A1(phi) A2(theta) A3(psi)``
  (Eqs. 4.39-4.40)::

      w1 = phi' - psi' sin(theta)
      w2 = theta' cos(phi) + psi' cos(theta) sin(phi)
      w3 = psi' cos(theta) cos(phi) - theta' sin(phi)

  singular at ``cos(theta) = 0``, i.e. ``theta = +/- pi/2``.

Body rates from angle rates are defined everywhere; the angle rates from body rates divide by
``sin(theta)`` (3-1-3) or ``cos(theta)`` (3-2-1). For numeric input a configuration within
``validate.EULER_LOCK_TOL`` (1e-9) of the singularity raises ``ValueError`` naming ``angles``
with the remedy (propagate quaternions, `quat_rate`). For CasADi ``SX``/``MX`` input no check
can be made: the expression is the formula as it stands, so at the singularity its value is
``inf``/``nan``
(a division by zero) or, where the floating-point ``cos(pi/2)`` is ``6e-17``, about ``1e16``
times the body rates; an optimizer or integrator near it sees huge rates.

Shapes as everywhere in `dynamics.attitude`: angles and rates ``(3,)`` or ``(3, n)`` (components
first; a ``(3,)`` argument broadcasts against a ``(3, n)`` one), a DCM ``(3, 3)`` or
``(3, 3, n)``; CasADi inputs are ``3x1`` columns and ``3x3`` matrices.
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from .. import validate
from .backend import checked, finite3, ops_for

__all__ = ["euler321_rates", "body_rates_from_euler321", "euler313_rates",
           "body_rates_from_euler313", "dcm_rate"]

def _pair(angles, rates, rates_name):
    a = checked(angles, "angles", (3,), finite3)
    r = checked(rates, rates_name, (3,), finite3)
    return a, r, ops_for(a, r)


def _refuse_lock(divisor, theta, sequence, where):
    """ValueError when a numeric ``divisor`` (sin or cos of ``theta``) is at gimbal lock."""
    if isinstance(divisor, (ca.SX, ca.MX)):
        return
    d = np.abs(np.asarray(divisor, dtype=float)).ravel()
    bad = np.flatnonzero(d < validate.EULER_LOCK_TOL)
    if bad.size:
        k = bad[0]
        th = float(np.asarray(theta, dtype=float).ravel()[k])
        at = "" if d.size == 1 else f" (column {k})"
        raise ValueError(
            f"`angles` is at the {sequence} gimbal lock{at}: theta = {th!r} rad "
            f"({np.degrees(th):.6g} deg) has {where} < {validate.EULER_LOCK_TOL:g}, where the "
            f"angle rates are undefined; propagate a quaternion instead (quat_rate, or a scene's "
            f"attitude state) and convert to angles afterwards")


def body_rates_from_euler321(angles, angle_rates):
    """Body angular velocity from modern 3-2-1 angles and their rates (Sec. 4.3, Eq. 4.39).

    ``w = [phi' - psi' s(theta), theta' c(phi) + psi' c(theta) s(phi),
    psi' c(theta) c(phi) - theta' s(phi)]``; defined for every attitude.

    Parameters
    ----------
    angles : array_like, shape (3,) or (3, n) [rad], or CasADi 3x1
        ``(psi, theta, phi)``: yaw, pitch, roll with ``A = A1(phi) A2(theta) A3(psi)``.
    angle_rates : array_like, shape (3,) or (3, n) [rad/s], or CasADi 3x1
        ``(psi', theta', phi')``.

    Returns
    -------
    w : shape (3,) or (3, n) [rad/s]
        Body angular velocity (body components).

    Raises
    ------
    TypeError
        If an argument is not real numbers (e.g. a string, a dict or ``None``).
    ValueError
        If an argument does not have 3 components or is not finite.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import body_rates_from_euler321
    >>> body_rates_from_euler321([0.0, 0.0, 0.0], [0.1, 0.2, 0.3])  # level: (roll', pitch', yaw')
    array([0.3, 0.2, 0.1])
    >>> # a yaw rate at pitch 90 deg is a rate about the body x axis
    >>> np.round(body_rates_from_euler321([0.0, np.pi / 2, 0.0], [1.0, 0.0, 0.0]), 12)
    array([-1.,  0.,  0.])
    """
    a, r, o = _pair(angles, angle_rates, "angle_rates")
    th, phi = a[1], a[2]
    dpsi, dth, dphi = r[0], r[1], r[2]
    cth, sth, cph, sph = o.cos(th), o.sin(th), o.cos(phi), o.sin(phi)
    return o.stack([dphi - dpsi * sth,
                    dth * cph + dpsi * cth * sph,
                    dpsi * cth * cph - dth * sph])


def euler321_rates(angles, w):
    """Rates of the modern 3-2-1 angles from the body angular velocity (Sec. 4.3, Eq. 4.40).

    ``psi' = (s(phi) w2 + c(phi) w3) / c(theta)``, ``theta' = c(phi) w2 - s(phi) w3``,
    ``phi' = w1 + s(theta) psi'``: the inverse of `body_rates_from_euler321`, singular at
    ``theta = +/- pi/2``.

    Parameters
    ----------
    angles : array_like, shape (3,) or (3, n) [rad], or CasADi 3x1
        ``(psi, theta, phi)``: yaw, pitch, roll with ``A = A1(phi) A2(theta) A3(psi)``.
    w : array_like, shape (3,) or (3, n) [rad/s], or CasADi 3x1
        Body angular velocity (body components).

    Returns
    -------
    angle_rates : shape (3,) or (3, n) [rad/s]
        ``(psi', theta', phi')``.

    Raises
    ------
    TypeError
        If an argument is not real numbers (e.g. a string, a dict or ``None``).
    ValueError
        If an argument does not have 3 components or is not finite, or (numeric input)
        ``|cos(theta)| < validate.EULER_LOCK_TOL`` (gimbal lock; the message gives the
        remedy: propagate a quaternion). A CasADi ``SX``/``MX`` expression is not checked: at
        the lock its value is ``inf``/``nan`` or huge (``~1e16`` times the body rates).

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import body_rates_from_euler321, euler321_rates
    >>> angles = [0.3, 0.2, 0.1]
    >>> np.round(euler321_rates(angles, body_rates_from_euler321(angles, [0.1, 0.2, 0.3])), 12)
    array([0.1, 0.2, 0.3])
    >>> euler321_rates([0.0, np.pi / 2, 0.0], [0.0, 0.0, 0.1])
    Traceback (most recent call last):
        ...
    ValueError: `angles` is at the 3-2-1 gimbal lock: theta = 1.5707963267948966 rad (90 deg) has |cos(theta)| < 1e-09, ...
    """
    a, w, o = _pair(angles, w, "w")
    th, phi = a[1], a[2]
    cth, sth, cph, sph = o.cos(th), o.sin(th), o.cos(phi), o.sin(phi)
    _refuse_lock(cth, th, "3-2-1", "|cos(theta)|")
    dpsi = (sph * w[1] + cph * w[2]) / cth
    return o.stack([dpsi, cph * w[1] - sph * w[2], w[0] + sth * dpsi])


def body_rates_from_euler313(angles, angle_rates):
    """Body angular velocity from classical 3-1-3 angles and their rates (Sec. 4.3, Eq. 4.36).

    ``w = [psi' s(theta) s(phi) + theta' c(phi), psi' s(theta) c(phi) - theta' s(phi),
    psi' c(theta) + phi']``; defined for every attitude.

    Parameters
    ----------
    angles : array_like, shape (3,) or (3, n) [rad], or CasADi 3x1
        ``(psi, theta, phi)``: precession, nutation, spin with ``A = A3(phi) A1(theta) A3(psi)``.
    angle_rates : array_like, shape (3,) or (3, n) [rad/s], or CasADi 3x1
        ``(psi', theta', phi')``.

    Returns
    -------
    w : shape (3,) or (3, n) [rad/s]
        Body angular velocity (body components).

    Raises
    ------
    TypeError
        If an argument is not real numbers (e.g. a string, a dict or ``None``).
    ValueError
        If an argument does not have 3 components or is not finite.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import body_rates_from_euler313
    >>> body_rates_from_euler313([0.0, 0.0, 0.0], [0.1, 0.0, 0.2])  # theta = 0: psi' + phi' only
    array([0. , 0. , 0.3])
    >>> np.round(body_rates_from_euler313([0.0, np.pi / 2, 0.0], [1.0, 0.0, 0.0]), 12)  # precession
    array([0., 1., 0.])
    """
    a, r, o = _pair(angles, angle_rates, "angle_rates")
    th, phi = a[1], a[2]
    dpsi, dth, dphi = r[0], r[1], r[2]
    cth, sth, cph, sph = o.cos(th), o.sin(th), o.cos(phi), o.sin(phi)
    return o.stack([dpsi * sth * sph + dth * cph,
                    dpsi * sth * cph - dth * sph,
                    dpsi * cth + dphi])


def euler313_rates(angles, w):
    """Rates of the classical 3-1-3 angles from the body angular velocity (Sec. 4.3, Eq. 4.37).

    ``psi' = (s(phi) w1 + c(phi) w2) / s(theta)``, ``theta' = c(phi) w1 - s(phi) w2``,
    ``phi' = w3 - c(theta) psi'``: the inverse of `body_rates_from_euler313`, singular at
    ``theta = 0`` and ``theta = pi``.

    Parameters
    ----------
    angles : array_like, shape (3,) or (3, n) [rad], or CasADi 3x1
        ``(psi, theta, phi)``: precession, nutation, spin with ``A = A3(phi) A1(theta) A3(psi)``.
    w : array_like, shape (3,) or (3, n) [rad/s], or CasADi 3x1
        Body angular velocity (body components).

    Returns
    -------
    angle_rates : shape (3,) or (3, n) [rad/s]
        ``(psi', theta', phi')``.

    Raises
    ------
    TypeError
        If an argument is not real numbers (e.g. a string, a dict or ``None``).
    ValueError
        If an argument does not have 3 components or is not finite, or (numeric input)
        ``|sin(theta)| < validate.EULER_LOCK_TOL`` (gimbal lock; the message gives the
        remedy: propagate a quaternion). A CasADi ``SX``/``MX`` expression is not checked: at
        the lock its value is ``inf``/``nan`` or huge (``~1e16`` times the body rates).

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import body_rates_from_euler313, euler313_rates
    >>> angles = [0.3, 0.2, 0.1]
    >>> np.round(euler313_rates(angles, body_rates_from_euler313(angles, [0.1, 0.2, 0.3])), 12)
    array([0.1, 0.2, 0.3])
    >>> import casadi as ca
    >>> e, w = ca.SX.sym("e", 3), ca.SX.sym("w", 3)  # symbolic: no check, formula as it stands
    >>> euler313_rates(e, w).shape
    (3, 1)
    """
    a, w, o = _pair(angles, w, "w")
    th, phi = a[1], a[2]
    cth, sth, cph, sph = o.cos(th), o.sin(th), o.cos(phi), o.sin(phi)
    _refuse_lock(sth, th, "3-1-3", "|sin(theta)|")
    dpsi = (sph * w[0] + cph * w[1]) / sth
    return o.stack([dpsi, cph * w[0] - sph * w[1], w[2] - cth * dpsi])


def dcm_rate(A, w):
    """Time derivative of the DCM by the Poisson equation ``A' = -[w x] A`` (Sec. 4.3, Eq. 4.33).

    ``A`` maps inertial to body components (``x_body = A x_inertial``, rows = body unit vectors
    in inertial components) and ``w`` is the body angular velocity in body components. Linear
    in ``A``: any finite 3x3 is accepted (an integrator evaluates it off the rotation group).

    Parameters
    ----------
    A : array_like, shape (3, 3) or (3, 3, n), or CasADi 3x3
        Direction cosine matrix (inertial -> body).
    w : array_like, shape (3,) or (3, n) [rad/s], or CasADi 3x1
        Body angular velocity.

    Returns
    -------
    A_dot : shape (3, 3) or (3, 3, n) [1/s]

    Raises
    ------
    TypeError
        If an argument is not real numbers (e.g. a string, a dict or ``None``).
    ValueError
        If ``A`` is not 3x3 (or 3x3xn), ``w`` does not have 3 components, or either is not
        finite.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import dcm_axis, dcm_rate
    >>> psi, rate = 0.4, 0.5  # a frame turning about z: A = A3(rate t), A' = rate dA3/dpsi
    >>> Adot = dcm_rate(dcm_axis(3, psi), [0.0, 0.0, rate])
    >>> bool(np.allclose(Adot, rate * np.array([[-np.sin(psi), np.cos(psi), 0],
    ...                                         [-np.cos(psi), -np.sin(psi), 0], [0, 0, 0]])))
    True
    """
    A = checked(A, "A", (3, 3), lambda x, n: validate.finite_array(x, n, (3, 3), batch=True))
    w = checked(w, "w", (3,), finite3)
    o = ops_for(A, w)
    # -[w x] A row by row: w3 A[1] - w2 A[2], w1 A[2] - w3 A[0], w2 A[0] - w1 A[1]
    rows = [[w[2] * A[1, j] - w[1] * A[2, j] for j in range(3)],
            [w[0] * A[2, j] - w[2] * A[0, j] for j in range(3)],
            [w[1] * A[0, j] - w[0] * A[1, j] for j in range(3)]]
    return o.matrix(rows)
