"""Variable mass (Sec. 3.4): specific impulse, the rocket equation, the discrete rocket, jet damping."""
from __future__ import annotations

import numpy as np

from .. import validate
from ..attitude.backend import finite_vector

__all__ = ["G0", "isp", "delta_v", "rocket_steps", "jet_damping_torque"]

#: Standard gravity [m/s^2] of the specific impulse (Eq. 3.40; the seed rounds it to 9.81).
G0 = 9.80665


def isp(thrust, mass_flow, *, g0=G0):
    """Specific impulse ``Is = F_T / (mdot g0) = C / g0`` (Sec. 3.4, Eq. 3.40).

    Parameters
    ----------
    thrust : float or array_like, shape (n,) [N]
    mass_flow : float or array_like, shape (n,) [kg/s]
        Propellant flow rate ``mdot > 0`` (the magnitude, as in Eq. 3.39).
    g0 : float [m/s^2], optional
        Standard gravity (`G0`).

    Returns
    -------
    float or ndarray [s]

    Raises
    ------
    TypeError
        If an argument is not real numbers.
    ValueError
        If ``mass_flow`` or ``g0`` is not positive or ``thrust`` is not finite.

    Examples
    --------
    >>> from appdyn.dynamics.mass import G0, isp
    >>> round(isp(628500.0, 17010.0 / 75.2), 3)  # a Delta III solid booster
    283.334
    """
    F = finite_vector(thrust, "thrust")
    md = finite_vector(mass_flow, "mass_flow")
    if np.any(md <= 0):
        raise ValueError(f"`mass_flow` must be positive (the flow magnitude), got {md.tolist()}")
    out = F / (md * validate.positive(g0, "g0"))
    return float(out) if out.ndim == 0 else out


def delta_v(initial_mass, final_mass, *, isp=None, exhaust_velocity=None, g0=G0):
    """Ideal velocity gain of a rocket in free space, ``V = C ln(M0 / M)`` (Sec. 3.4).

    The limit of `rocket_steps` for infinitely many infinitesimal firings (Tsiolkovsky), with
    the effective exhaust velocity ``C = Is g0`` (Eq. 3.40).

    Parameters
    ----------
    initial_mass, final_mass : float or array_like, shape (n,) [kg]
        ``M0 >= M > 0``.
    isp : float [s], optional
        Specific impulse; give exactly one of ``isp`` and ``exhaust_velocity``.
    exhaust_velocity : float [m/s], optional
        ``C``.
    g0 : float [m/s^2], optional

    Returns
    -------
    float or ndarray [m/s]

    Raises
    ------
    TypeError
        If an argument is not real numbers.
    ValueError
        If the masses are not positive with ``M0 >= M``, or not exactly one of ``isp`` and
        ``exhaust_velocity`` is given, or it is not positive.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.mass import delta_v
    >>> round(delta_v(np.e, 1.0, exhaust_velocity=3000.0), 9)  # one e-fold of mass: V = C
    3000.0
    >>> round(delta_v(1000.0, 400.0, isp=300.0), 3)
    2695.723
    """
    C = _exhaust_velocity(isp, exhaust_velocity, g0)
    M0 = finite_vector(initial_mass, "initial_mass")
    M = finite_vector(final_mass, "final_mass")
    if np.any(M <= 0) or np.any(M0 < M):
        raise ValueError(f"need `initial_mass` >= `final_mass` > 0, got {M0.tolist()} and "
                         f"{M.tolist()}")
    out = C * np.log(M0 / M)
    return float(out) if out.ndim == 0 else out


def _exhaust_velocity(isp_, exhaust_velocity, g0):
    if (isp_ is None) == (exhaust_velocity is None):
        raise ValueError("give exactly one of `isp` [s] and `exhaust_velocity` [m/s]")
    if isp_ is not None:
        return validate.positive(isp_, "isp") * validate.positive(g0, "g0")
    return validate.positive(exhaust_velocity, "exhaust_velocity")


def rocket_steps(mass, pellet_mass, exhaust_velocity, count, *, simultaneous=False):
    """Velocity of a vehicle that fires ``count`` pellets backwards (Sec. 3.4, the discrete rocket).

    The seed's preliminary example: a vehicle of mass ``M`` (without the pellets) rolls on
    frictionless rails and fires pellets of mass ``m`` at the muzzle velocity ``C`` relative to
    the barrel. Momentum conservation at each firing gives, in sequence,
    ``V_k = C sum_{j=1..k} m / (M + (N - j + 1) m)``, the final speed
    ``V_N = C sum_{k=1..N} m / (M + k m)``; fired all at once ``V = N m C / (M + N m)`` (case
    (a), smaller). As ``N -> inf`` with ``N m`` fixed, ``V_N -> C ln(M0 / M)`` (`delta_v`).

    Parameters
    ----------
    mass : float [kg]
        ``M``: the vehicle without the pellets (positive).
    pellet_mass : float [kg]
        ``m`` (positive).
    exhaust_velocity : float [m/s]
        ``C``: the muzzle velocity relative to the barrel (positive).
    count : int
        ``N >= 1`` pellets.
    simultaneous : bool, optional
        Fire all at once (case (a)) instead of one after another.

    Returns
    -------
    ndarray, shape (count,) [m/s], or float
        In sequence: the speed after each firing; at once: the speed.

    Raises
    ------
    TypeError
        If an argument is not real numbers (``count`` not an integer).
    ValueError
        If a mass or the velocity is not positive or ``count < 1``.

    Examples
    --------
    >>> from appdyn.dynamics.mass import rocket_steps
    >>> rocket_steps(8.0, 1.0, 10.0, 2)  # the seed's two bullets: mC/(M+2m), + mC/(M+m)
    array([1.        , 2.11111111])
    >>> rocket_steps(8.0, 1.0, 10.0, 2, simultaneous=True)  # 2 m C / (M + 2 m)
    2.0
    """
    M = validate.positive(mass, "mass")
    m = validate.positive(pellet_mass, "pellet_mass")
    C = validate.positive(exhaust_velocity, "exhaust_velocity")
    N = validate.integer(count, "count", minimum=1)
    if simultaneous:
        return N * m * C / (M + N * m)
    remaining = M + m * np.arange(N, 0, -1)  # mass before each firing: M + N m, ..., M + m
    return np.cumsum(C * m / remaining)


def jet_damping_torque(mass_flow, rate, l1, l2):
    """Coriolis (jet-damping) torque of an axial mass flow, ``L_C = -mdot w (l2^2 - l1^2)`` (Eq. 3.49).

    A uniform flow ``mdot`` along the body x axis from ``x = l1`` to the nozzle exit
    ``x = l2`` of a body turning at ``w`` about a transverse axis through the mass centre
    (Eq. 3.48, ``L_C = -2 int mdot r x (w x dr)``); the torque is about the same axis.
    ``l1 = 0`` gives the textbook ``-mdot w l2^2``; ``l1 = -l2`` gives zero.

    Parameters
    ----------
    mass_flow : float [kg/s]
        ``mdot >= 0``.
    rate : float or array_like, shape (n,) [rad/s]
        ``w``.
    l1, l2 : float [m]
        Start and end (nozzle exit) of the flow along x.

    Returns
    -------
    float or ndarray [N m]

    Raises
    ------
    TypeError
        If an argument is not real numbers.
    ValueError
        If ``mass_flow`` is negative or an argument is not finite.

    Examples
    --------
    >>> from appdyn.dynamics.mass import jet_damping_torque
    >>> jet_damping_torque(2.0, 0.1, 0.0, 3.0)  # -mdot w l2^2
    -1.8
    """
    md = validate.nonnegative(mass_flow, "mass_flow")
    w = finite_vector(rate, "rate")
    a, b = validate.finite_scalar(l1, "l1"), validate.finite_scalar(l2, "l2")
    out = -md * w * (b * b - a * a)
    return float(out) if out.ndim == 0 else out
