"""Small-motion formulas: nutation cone angles and the linearized motion about a steady spin.

Rheinfurth & Wilson, NASA RP-1262, Sec. 4.5 A (Poinsot construction) and 4.5 C (small asymmetry).
"""
from __future__ import annotations

import warnings

from typing import NamedTuple

import numpy as np

from .. import validate
from .common import axis_index_arg, check_moments, deprecated_field, pow2, proper_sort

__all__ = ["ConeAngles", "cone_angles", "small_asymmetry_rates", "small_asymmetry_frequency"]


class ConeAngles(NamedTuple):
    """Bounds of the angle between ``H`` and the principal axis its polhode encircles.

    Attributes
    ----------
    theta_min, theta_max : float [rad]
        Smallest and largest angle in ``[0, pi/2]``.
    axis_index : int
        Index (caller's order) of the encircled axis: largest moment if ``D >= I_mid``,
        smallest if ``D < I_mid`` (``.axis`` is its deprecated name).
    """

    theta_min: float
    theta_max: float
    axis_index: int

    @property
    def axis(self):
        """Deprecated name of `axis_index` (``axis`` is a 3-vector in this project)."""
        return deprecated_field(self.axis_index)


def cone_angles(inertia_diag, w0):
    """Nutation limits of a torque-free body (Poinsot construction) [1]_.

    Parameters
    ----------
    inertia_diag : array_like, shape (3,) [kg m^2]
        Principal moments in any order; not all equal.
    w0 : array_like, shape (3,) [rad/s]
        Body rates (any point of the motion); non-zero.

    Returns
    -------
    ConeAngles
        For ascending ``I1 <= I2 <= I3``: if ``D < I2`` (about axis 1)
        ``tan^2 theta_min = I3 (D - I1) / (I1 (I3 - D))`` (where ``H2 = 0``) and
        ``tan^2 theta_max = I2 (D - I1) / (I1 (I2 - D))`` (where ``H3 = 0``); if ``D >= I2``
        (about axis 3) ``tan^2 theta_min = I1 (I3 - D) / (I3 (D - I1))`` and
        ``tan^2 theta_max = I2 (I3 - D) / (I3 (D - I2))``. On the separatrix
        ``theta_max = pi/2`` (approached asymptotically); a steady spin about the
        intermediate axis gets the values of the separatrix through it.

    Raises
    ------
    ValueError
        Naming ``inertia_diag`` (bad moments, or a sphere, where ``H`` keeps its body
        direction and no axis is singled out) or ``w0`` (bad, or zero).

    References
    ----------
    .. [1] Rheinfurth & Wilson, NASA RP-1262, Sec. 4.5 A.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.truth import cone_angles
    >>> cones = cone_angles([1.0, 2.0, 3.0], [0.1, 0.2, 0.3])
    >>> np.round(np.degrees([cones.theta_min, cones.theta_max]), 6), cones.axis_index
    (array([13.054453, 26.856271]), 2)
    """
    inertia = check_moments(inertia_diag)
    w0 = validate.finite_array(w0, "w0", (3,))
    if not np.any(w0):
        raise ValueError("`w0` must be non-zero for cone angles (H = 0 has no direction)")
    if inertia.max() == inertia.min():
        raise ValueError(f"`inertia_diag` must not be a sphere for cone angles, got {inertia.tolist()}")
    sign_perm, order = proper_sort(inertia)
    i1, i2, i3 = inertia[order] / pow2(inertia.max())
    w1, w2, w3 = sign_perm @ (w0 / pow2(np.abs(w0).max()))
    d21, d31, d32 = i2 - i1, i3 - i1, i3 - i2
    p = i1 * d31 * w1**2 + i2 * d32 * w2**2  # 2T (I3 - D)
    q = i2 * d21 * w2**2 + i3 * d31 * w3**2  # 2T (D - I1)
    r = i3 * d32 * w3**2 - i1 * d21 * w1**2  # 2T (D - I2)
    if d21 == 0 or (d32 != 0 and r >= 0):
        th_min = np.arctan2(np.sqrt(i1 * p), np.sqrt(i3 * q))
        th_max = np.arctan2(np.sqrt(i2 * p), np.sqrt(i3 * r))
        axis_index = int(order[2])
    else:
        th_min = np.arctan2(np.sqrt(i3 * q), np.sqrt(i1 * p))
        th_max = np.arctan2(np.sqrt(i2 * q), np.sqrt(-i1 * r))
        axis_index = int(order[0])
    return ConeAngles(float(th_min), float(th_max), axis_index)


def _rate_arg(rate, spin_rate):
    """Resolve ``rate`` and its deprecated keyword ``spin_rate``: ``(value, name used)``."""
    if spin_rate is None:
        if rate is None:
            raise TypeError("missing the spin `rate` [rad/s]")
        return rate, "rate"
    if rate is not None:
        raise TypeError("pass `rate` only; `spin_rate` is its deprecated name")
    warnings.warn("the keyword `spin_rate` is deprecated (a scalar spin rate is `rate`); use "
                  "`rate=`", DeprecationWarning, stacklevel=3)
    return spin_rate, "spin_rate"


def small_asymmetry_rates(inertia_diag, rate=None, *, axis_index=None, axis=None,
                          spin_rate=None):
    """Coefficients of the linearized motion about a steady spin [1]_.

    With spin axis ``a`` and the other axes ``b, c`` in cyclic order (``a, b, c`` =
    ``0, 1, 2``; ``1, 2, 0``; ``2, 0, 1``), Euler's equations linearized about
    ``w = rate e_a`` read ``w_b' + lambda1 w_c = 0``, ``w_c' - lambda2 w_b = 0``.

    Parameters
    ----------
    inertia_diag : array_like, shape (3,) [kg m^2]
        Principal moments (caller's order).
    rate : float [rad/s]
        Nominal spin ``w0`` about the axis ``axis_index``.
    axis_index : {0, 1, 2}, optional
        Spin axis index; ``None`` (default) means 0 (axis 1 of [1]_).
    axis : int, optional
        Deprecated name of ``axis_index`` (warns).
    spin_rate : float, optional
        Deprecated name of ``rate`` (warns).

    Returns
    -------
    lambda1, lambda2 : float [rad/s]
        ``lambda1 = (I_a - I_c) / I_b * w0``, ``lambda2 = (I_a - I_b) / I_c * w0``.

    Raises
    ------
    ValueError
        Naming ``inertia_diag``, ``rate`` or ``axis_index``.

    References
    ----------
    .. [1] Rheinfurth & Wilson, NASA RP-1262, Sec. 4.5 C.

    Examples
    --------
    >>> from appdyn.dynamics.truth import small_asymmetry_rates
    >>> lam1, lam2 = small_asymmetry_rates([1.0, 2.0, 3.0], 2.0, axis_index=2)  # major axis
    >>> float(lam1), float(lam2)  # (3 - 2) / 1 * 2, (3 - 1) / 2 * 2
    (2.0, 2.0)
    """
    inertia = check_moments(inertia_diag)
    rate, rate_name = _rate_arg(rate, spin_rate)
    w0 = validate.finite_scalar(rate, rate_name)
    a = validate.one_of(*axis_index_arg(axis_index, axis, 0), (0, 1, 2))
    b, c = (a + 1) % 3, (a + 2) % 3
    return (inertia[a] - inertia[c]) / inertia[b] * w0, (inertia[a] - inertia[b]) / inertia[c] * w0


def small_asymmetry_frequency(inertia_diag, rate=None, *, axis_index=None, axis=None,
                              spin_rate=None):
    """Nutation frequency ``sqrt(lambda1 lambda2)`` of a spin about a major or minor axis.

    It is the limit of the exact elliptic rate ``lam`` as the nutation goes to zero
    [1]_. See :func:`small_asymmetry_rates` for the parameters.

    Returns
    -------
    float [rad/s]
        ``sqrt(lambda1 lambda2) >= 0``.

    Raises
    ------
    ValueError
        Naming ``axis_index`` if it is the intermediate axis (``lambda1 lambda2 < 0``: the
        linearized motion grows like ``exp(sqrt(-lambda1 lambda2) t)``), or the arguments
        as in :func:`small_asymmetry_rates`.

    References
    ----------
    .. [1] Rheinfurth & Wilson, NASA RP-1262, Sec. 4.5 C.

    Examples
    --------
    >>> from appdyn.dynamics.truth import small_asymmetry_frequency
    >>> small_asymmetry_frequency([1.0, 2.0, 3.0], 2.0, axis_index=2)
    2.0
    """
    a, name = axis_index_arg(axis_index, axis, 0)
    rate, rate_name = _rate_arg(rate, spin_rate)
    try:
        lam1, lam2 = small_asymmetry_rates(inertia_diag, rate, axis_index=a)
    except ValueError as exc:
        raise type(exc)(str(exc).replace("`rate`", f"`{rate_name}`")) from None
    prod = lam1 * lam2
    if prod < 0:
        raise ValueError(
            f"`{name}` {a} is the intermediate principal axis: the spin is unstable "
            f"(lambda1 lambda2 = {prod!r} < 0) and has no nutation frequency"
        )
    return float(np.sqrt(prod))
