"""Aerodynamic (direction) angles of the body-frame air velocity (seed Sec. 4.3 E).

A direction takes two angles. With ``v = (v_x, v_y, v_z)`` the air-relative velocity in body
axes and ``V = |v|``:

Type I, angle of attack ``alpha`` and sideslip ``beta`` (a turn ``beta`` about ``z``, then a
clockwise turn ``alpha`` about the new ``y``)::

    v_x = V cos(alpha) cos(beta),  v_y = V sin(beta),  v_z = V sin(alpha) cos(beta)
    tan(alpha) = v_z / v_x  (quadrant from the signs, -pi <= alpha <= pi),
    sin(beta)  = v_y / V    (-pi/2 <= beta <= pi/2).

Type II, total angle of attack ``alpha_T`` and aerodynamic roll angle ``phi_R`` (the last two
rotations of the modern 3-2-1 sequence: pitch ``alpha_T``, then roll ``phi_R``)::

    v_x = V cos(alpha_T),  v_y = V sin(alpha_T) sin(phi_R),  v_z = V sin(alpha_T) cos(phi_R)
    cos(alpha_T) = v_x / V  (0 <= alpha_T <= pi),
    tan(phi_R) = v_y / v_z  (quadrant from the signs, 0 <= phi_R < 2 pi).

The conversions (the seed's four formulas, here quadrant-safe by going through the direction)::

    I -> II:  cos(alpha_T) = cos(alpha) cos(beta),   tan(phi_R) = tan(beta) / sin(alpha)
    II -> I:  tan(alpha) = cos(phi_R) tan(alpha_T),  sin(beta) = sin(phi_R) sin(alpha_T)

Indeterminate cases
-------------------
``phi_R`` is indeterminate when ``v_y = v_z = 0`` (flight along the body ``x`` axis, forwards or
backwards): `total_aoa` then returns ``phi_R = 0`` by convention -- never NaN, in numpy and in
CasADi, and neither are CasADi's derivatives there (they are set to zero: ``alpha_T`` has a
cone point) -- and ``return_defined=True`` also returns the flag ``defined`` (False there).
Likewise ``alpha`` is taken as 0 when ``v_x = v_z = 0`` (pure sideslip, ``beta = +-pi/2``).
A zero velocity has no direction: a ``ValueError`` naming ``v_body`` (numbers and CasADi
``DM``; a symbolic argument cannot be checked and gives the conventions above at zero).

See `dynamics.attitude` for the numpy/CasADi conventions (components first, batches
``(3, n)``) and the input checks.
"""
from __future__ import annotations

import math

import numpy as np

from .. import validate
from .backend import checked, finite_vector, ops_for

__all__ = ["aero_angles", "total_aoa", "aero_angles_from_total", "total_aoa_from_aero_angles",
           "velocity_direction", "velocity_direction_total"]


def _nonzero_velocity(x, name):
    a = validate.finite_array(x, name, (3,), batch=True)
    validate.unit_vector(a, name, batch=True)  # raises for a zero column, naming it
    return a


def _components(v_body):
    v = checked(v_body, "v_body", (3,), _nonzero_velocity)
    return ops_for(v), v[0], v[1], v[2]


def _safe_atan2(o, y, x):
    """``atan2(y, x)``, 0 (and a zero derivative) at ``y = x = 0``."""
    defined = (o.fabs(y) + o.fabs(x)) > 0
    return o.where(defined, o.arctan2(y, o.where(defined, x, 1.0)), 0.0 * x), defined


def _safe_hypot(o, a, b):
    """``sqrt(a^2 + b^2)`` with a zero (not infinite) derivative at ``a = b = 0``."""
    r2 = a * a + b * b
    defined = r2 > 0
    return o.where(defined, o.sqrt(o.where(defined, r2, 1.0)), 0.0 * r2)


def aero_angles(v_body):
    """Type I angles: angle of attack and sideslip of the body-frame air velocity.

    ``alpha = atan2(v_z, v_x)``, ``beta = asin(v_y / |v|)`` (module docstring; computed as
    ``atan2(v_y, sqrt(v_x^2 + v_z^2))`` for accuracy near ``+-pi/2``).

    Parameters
    ----------
    v_body : array_like, shape (3,) or (3, n) [m/s], or CasADi 3x1
        Air-relative velocity in body axes (any non-zero length).

    Returns
    -------
    alpha : float or ndarray (n,) [rad], or CasADi scalar
        Angle of attack, ``-pi <= alpha <= pi`` (``-pi`` for a signed ``v_z = -0.0``; 0 when
        ``v_x = v_z = 0``).
    beta : float or ndarray (n,) [rad], or CasADi scalar
        Sideslip, ``-pi/2 <= beta <= pi/2`` (positive for the wind from the right, ``v_y > 0``).

    Raises
    ------
    TypeError
        If ``v_body`` is not real numbers.
    ValueError
        If ``v_body`` does not have 3 components, is not finite, or is zero.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import aero_angles
    >>> alpha, beta = aero_angles([100.0, 10.0, 5.0])
    >>> round(float(np.degrees(alpha)), 4), round(float(np.degrees(beta)), 4)
    (2.8624, 5.7035)
    """
    o, vx, vy, vz = _components(v_body)
    alpha, _ = _safe_atan2(o, vz, vx)
    beta = o.arctan2(vy, _safe_hypot(o, vx, vz))
    return _plain(alpha), _plain(beta)


def total_aoa(v_body, *, return_defined=False):
    """Type II angles: total angle of attack and aerodynamic roll angle.

    ``alpha_T`` is the angle between the body ``x`` axis and the air velocity,
    ``cos(alpha_T) = v_x / |v|``; ``phi_R`` is the roll angle of the plane holding both,
    ``tan(phi_R) = v_y / v_z`` (measured from ``+z`` towards ``+y``), so that
    ``v = |v| (cos alpha_T, sin alpha_T sin phi_R, sin alpha_T cos phi_R)``.

    Parameters
    ----------
    v_body : array_like, shape (3,) or (3, n) [m/s], or CasADi 3x1
        Air-relative velocity in body axes (any non-zero length).
    return_defined : bool, optional
        Also return whether ``phi_R`` is defined (``v_y, v_z`` not both zero).

    Returns
    -------
    alpha_T : float or ndarray (n,) [rad], or CasADi scalar
        ``0 <= alpha_T <= pi``.
    phi_R : float or ndarray (n,) [rad], or CasADi scalar
        ``0 <= phi_R < 2 pi``; 0 where indeterminate (``v_y = v_z = 0``), never NaN.
    defined : bool or ndarray of bool (n,), or CasADi scalar (1/0)
        Only with ``return_defined=True``.

    Raises
    ------
    TypeError
        If ``v_body`` is not real numbers.
    ValueError
        If ``v_body`` does not have 3 components, is not finite, or is zero.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import total_aoa
    >>> alpha_T, phi_R = total_aoa([1.0, -1.0, 0.0])  # wind from the left, in the x-y plane
    >>> float(np.degrees(alpha_T)), float(np.degrees(phi_R))
    (45.0, 270.0)
    >>> total_aoa([3.0, 0.0, 0.0], return_defined=True)  # roll angle indeterminate: 0, flagged
    (0.0, 0.0, False)
    """
    if not isinstance(return_defined, bool):
        raise TypeError(f"`return_defined` must be a bool, got {type(return_defined).__name__}")
    o, vx, vy, vz = _components(v_body)
    alpha_T = o.arctan2(_safe_hypot(o, vy, vz), vx)
    phi, defined = _safe_atan2(o, vy, vz)
    phi_R = o.where(phi < 0, phi + 2 * math.pi, phi)
    phi_R = o.where(phi_R < 2 * math.pi, phi_R, 0.0 * phi_R)  # -1e-300 + 2 pi rounds to 2 pi
    if not return_defined:
        return _plain(alpha_T), _plain(phi_R)
    return _plain(alpha_T), _plain(phi_R), _plain(defined)


def _plain(x):
    """A numpy 0-d result as a Python scalar; arrays and CasADi pass through."""
    if isinstance(x, np.generic) or (isinstance(x, np.ndarray) and x.ndim == 0):
        return x.item()
    return x


def velocity_direction(alpha, beta):
    """Unit air-velocity direction in body axes from the Type I angles.

    Parameters
    ----------
    alpha, beta : float or array (n,) [rad], or CasADi scalars
        Angle of attack and sideslip.

    Returns
    -------
    shape (3,) or (3, n), or CasADi 3x1
        ``(cos alpha cos beta, sin beta, sin alpha cos beta)``.

    Raises
    ------
    TypeError
        If an angle is not real numbers.
    ValueError
        If an angle is not finite.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import velocity_direction
    >>> np.round(velocity_direction(np.pi / 2, 0.0), 12) + 0.0
    array([0., 0., 1.])
    """
    a = checked(alpha, "alpha", (), finite_vector)
    b = checked(beta, "beta", (), finite_vector)
    o = ops_for(a, b)
    cb = o.cos(b)
    return o.stack([o.cos(a) * cb, o.sin(b) + 0 * a, o.sin(a) * cb])


def velocity_direction_total(alpha_T, phi_R):
    """Unit air-velocity direction in body axes from the Type II angles.

    Parameters
    ----------
    alpha_T, phi_R : float or array (n,) [rad], or CasADi scalars
        Total angle of attack and aerodynamic roll angle.

    Returns
    -------
    shape (3,) or (3, n), or CasADi 3x1
        ``(cos alpha_T, sin alpha_T sin phi_R, sin alpha_T cos phi_R)``.

    Raises
    ------
    TypeError
        If an angle is not real numbers.
    ValueError
        If an angle is not finite.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import velocity_direction_total
    >>> np.round(velocity_direction_total(np.pi / 2, np.pi / 2), 12) + 0.0
    array([0., 1., 0.])
    """
    a = checked(alpha_T, "alpha_T", (), finite_vector)
    p = checked(phi_R, "phi_R", (), finite_vector)
    o = ops_for(a, p)
    sa = o.sin(a)
    return o.stack([o.cos(a) + 0 * p, sa * o.sin(p), sa * o.cos(p)])


def aero_angles_from_total(alpha_T, phi_R):
    """Type I ``(alpha, beta)`` from Type II ``(alpha_T, phi_R)``.

    ``tan(alpha) = cos(phi_R) tan(alpha_T)``, ``sin(beta) = sin(phi_R) sin(alpha_T)`` (seed Sec.
    4.3 E), each angle in its quadrant (through `velocity_direction_total` and `aero_angles`).

    Parameters
    ----------
    alpha_T, phi_R : float or array (n,) [rad], or CasADi scalars

    Returns
    -------
    alpha, beta : as `aero_angles`

    Raises
    ------
    TypeError
        If an angle is not real numbers.
    ValueError
        If an angle is not finite.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import aero_angles_from_total
    >>> alpha, beta = aero_angles_from_total(np.radians(10.0), np.radians(30.0))
    >>> round(float(np.degrees(alpha)), 4), round(float(np.degrees(beta)), 4)
    (8.6822, 4.9809)
    """
    return aero_angles(velocity_direction_total(alpha_T, phi_R))


def total_aoa_from_aero_angles(alpha, beta, *, return_defined=False):
    """Type II ``(alpha_T, phi_R)`` from Type I ``(alpha, beta)``.

    ``cos(alpha_T) = cos(alpha) cos(beta)``, ``tan(phi_R) = tan(beta) / sin(alpha)`` (seed Sec.
    4.3 E), each angle in its quadrant (through `velocity_direction` and `total_aoa`, whose
    convention ``phi_R = 0`` holds where ``alpha = beta = 0`` or ``alpha = pi, beta = 0``).

    Parameters
    ----------
    alpha, beta : float or array (n,) [rad], or CasADi scalars
    return_defined : bool, optional
        As in `total_aoa`.

    Returns
    -------
    alpha_T, phi_R[, defined] : as `total_aoa`

    Raises
    ------
    TypeError
        If an angle is not real numbers.
    ValueError
        If an angle is not finite.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import total_aoa_from_aero_angles
    >>> alpha_T, phi_R = total_aoa_from_aero_angles(np.radians(8.0), np.radians(6.0))
    >>> round(float(np.degrees(alpha_T)), 4), round(float(np.degrees(phi_R)), 4)
    (9.9883, 37.0603)
    """
    return total_aoa(velocity_direction(alpha, beta), return_defined=return_defined)
