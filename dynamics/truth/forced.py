"""Coning of a spinner and forced motion by Methods I and II (closed forms, numpy only).

Rheinfurth & Wilson, NASA RP-1262, Sec. 4.5 C (Eqs. 4.101-4.111) and Sec. 4.6 (Eqs.
4.112-4.119), re-derived:

* `coning_angle` -- the complex cone angle ``alpha = psi + i theta`` of a spin about a major or
  minor principal axis (first order in the cone angle), with the control-axis misalignment
  term of Eq. 4.111;
* `misaligned_thrust` -- Method I: an axisymmetric spinner with a constant body-fixed torque
  about ``x2`` (thrust misalignment): ``w2, w3`` exactly (linear Euler equations) and
  ``alpha`` to first order (Eqs. 4.112-4.113);
* `floating_frame_accelerations` -- Method II: Euler's law of an axisymmetric body in the
  floating (node) frame, ``I (w0' + wF') + wF x I (w0 + wF) = L`` (Eq. 4.119), as the
  classical 3-1-3 angle accelerations (exact, nonlinear);
* `horizontal_gyroscope` -- Method II's example: the heavy top (or gyroscope) with its axis
  near the horizontal, ``psi(t), theta(t)`` and the mean precession ``omega_p = L1/(I3 w0)``.

Conventions as in `dynamics.truth`: principal body axes, DCM inertial -> body, SI units. The
seed labels the spin axis differently in the two methods and so do these functions: in
Sec. 4.5 C and Method I the spin is about body axis 1 (``inertia_diag[0]``) and the small
angles are the modern 3-2-1 ``(psi, theta)`` of that axis; in Method II the symmetry (spin)
axis is body axis 3 and the angles are the classical 3-1-3 ``(psi, theta, phi)``.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .. import validate
from .common import EQUAL_RTOL, check_moments, check_times
from .cones import small_asymmetry_rates

__all__ = ["coning_angle", "MisalignedThrust", "misaligned_thrust",
           "floating_frame_accelerations", "HorizontalGyroscope", "horizontal_gyroscope"]


def _spin_rates(w0, name="w0"):
    w = validate.finite_array(w0, name, (3,))
    if w[0] == 0:
        raise ValueError(f"`{name}` must have a non-zero spin w0[0] about body axis 1, got "
                         f"{w.tolist()}")
    return w


def coning_angle(inertia_diag, w0, t, *, misalignment=(0.0, 0.0)):
    """Complex cone angle ``alpha(t) = psi + i theta`` of a nearly steady spin (Sec. 4.5 C).

    Body axis 1 spins at ``w0[0]`` about a major or minor axis; the small 3-2-1 angles
    ``(psi, theta)`` of that axis are measured from the angular momentum (inertial x along
    ``H``). With ``lambda1, lambda2`` of `small_asymmetry_rates` and ``lam = sqrt(lambda1
    lambda2)``, the linearized rates are ``w3 + i w2 = P cos(lam t) + Q sin(lam t)`` (Eqs.
    4.99-4.100 with any ``w2(0)``), ``alpha' = (w3 + i w2) e^{-i w0 t}`` (Eq. 4.103), hence
    (Eq. 4.108, both cases A and B at once)::

        alpha = i [B1/(w0 - lam) e^{-i(w0 - lam)t} + B2/(w0 + lam) e^{-i(w0 + lam)t}]
              + (b2 - i b3) e^{-i w0 t}

    with ``B1 = (P - iQ)/2``, ``B2 = (P + iQ)/2``, ``P = w3(0) + i w2(0)``,
    ``Q = (lambda2 w2(0) - i lambda1 w3(0))/lam``. (Re-derived: the seed's Eq. 4.110 drops
    the ``i`` of its second exponent, and its proof of ``lam < w0`` (4.109) compares
    ``lambda1 lambda2`` with ``w0`` where ``w0^2`` is meant.) The last term is the control-axis
    misalignment (Eq. 4.111): a control axis along ``e1 + b2 e2 + b3 e3`` (``b`` small); the
    seed's real ``beta`` is ``b = (0, -beta)``. For ``w2(0) = 0`` the minimum and maximum cone
    angles are ``|A1 + A2| = I3 w3(0) / (I1 w0)`` and ``|A1 - A2|``. First order in the
    cone angle: the neglected terms are quadratic and the motion is odd in the perturbation, so
    the error is ``O(alpha^3)`` (measured: 1/8 when the cone angle halves; 0.4 % of a 0.013 rad
    cone of a disk over 30 spin radians).

    Parameters
    ----------
    inertia_diag : array_like, shape (3,) [kg m^2]
        Principal moments ``(I1, I2, I3)``; axis 1 the largest or the smallest.
    w0 : array_like, shape (3,) [rad/s]
        Body rates at ``t = 0``: the spin ``w0[0] > 0`` and small ``w0[1], w0[2]``.
    t : float or array_like, shape (n,) [s]
    misalignment : array_like, shape (2,), optional
        ``(b2, b3)`` [rad]: the control axis relative to the principal axis 1.

    Returns
    -------
    ndarray, shape (n,), complex [rad]
        ``psi + i theta`` of the spin (or control) axis; ``psi = Re``, ``theta = Im``.

    Raises
    ------
    TypeError
        If an argument is not real numbers.
    ValueError
        If the moments are not physical, the spin is not positive, or axis 1 is the
        intermediate axis (unstable: ``lambda1 lambda2 < 0``) or ``lam >= w0``.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.truth import coning_angle
    >>> I, w = [3.0, 2.0, 2.0], [1.0, 0.0, 0.01]  # symmetric disk: steady coning
    >>> alpha = coning_angle(I, w, [0.0, 1.0])
    >>> np.round(np.abs(alpha), 6)  # the cone angle I3 w3(0) / (I1 w0)
    array([0.006667, 0.006667])
    >>> round(float(-np.angle(alpha[1] / alpha[0])), 6)  # turned by I1/I2 w0 = 1.5 rad (clockwise)
    1.5
    """
    I = check_moments(inertia_diag)
    w = _spin_rates(w0)
    if w[0] < 0:
        raise ValueError(f"`w0[0]` must be a positive spin (turn the body axes), got {w[0]!r}")
    b = validate.finite_array(misalignment, "misalignment", (2,))
    tt = check_times(t)
    spin = w[0]
    lam1, lam2 = small_asymmetry_rates(I, spin)
    if lam1 * lam2 <= 0:
        raise ValueError(f"`inertia_diag` makes axis 1 the intermediate (or a degenerate) axis: "
                         f"lambda1 lambda2 = {lam1 * lam2!r} <= 0 and there is no coning "
                         f"(the linearized motion diverges); got {I.tolist()}")
    lam = np.sqrt(lam1 * lam2)
    if lam >= spin:
        raise ValueError(f"`inertia_diag` gives a nutation frequency {lam!r} >= the spin "
                         f"{spin!r} (Eq. 4.109 fails; the moments are not those of a body)")
    P = w[2] + 1j * w[1]
    Q = (lam2 * w[1] - 1j * lam1 * w[2]) / lam
    B1, B2 = (P - 1j * Q) / 2, (P + 1j * Q) / 2
    return (1j * (B1 / (spin - lam) * np.exp(-1j * (spin - lam) * tt)
                  + B2 / (spin + lam) * np.exp(-1j * (spin + lam) * tt))
            + (b[0] - 1j * b[1]) * np.exp(-1j * spin * tt))


class MisalignedThrust(NamedTuple):
    """Method I: an axisymmetric spinner under a constant body torque ``L2`` (`misaligned_thrust`).

    Attributes
    ----------
    w2, w3 : ndarray, shape (n,) [rad/s]
        Transverse body rates (exact for the linear Euler equations, ``w1 = w0``).
    alpha : ndarray, shape (n,), complex [rad]
        Cone angle ``psi + i theta`` of the spin axis (3-2-1 angles; first order), Eq. 4.113.
    precession_rate : float [rad/s]
        ``w0 + lam = I1 w0 / I2``: the frequency of the free coning term.
    steady_w3 : float [rad/s]
        ``L2 / (lam I2)``: the mean of ``w3``; its term in ``alpha`` turns at the spin rate.
    """

    w2: np.ndarray
    w3: np.ndarray
    alpha: np.ndarray
    precession_rate: float
    steady_w3: float


def misaligned_thrust(inertia_diag, w0, torque, t):
    """Spinning body with a thrust-misalignment torque about body ``x2`` (Sec. 4.6, Method I).

    Euler's equations with ``I2 = I3`` and a constant body torque ``L2``: ``w1 = w0``,
    ``w2' + lam w3 = L2/I2``, ``w3' - lam w2 = 0`` with ``lam = (I1 - I2) w0 / I2``, so with
    ``s = L2 / (lam I2)``::

        w3 + i w2 = s + (w3(0) - s + i w2(0)) e^{-i lam t}

    (the seed's ``w2 = -[w3(0) - s] sin(lam t)``, ``w3 = [w3(0) - s] cos(lam t) + s`` for
    ``w2(0) = 0``), and from ``alpha' = (w3 + i w2) e^{-i w0 t}`` (Eq. 4.112)::

        alpha = i s / w0 e^{-i w0 t} + i (w3(0) - s + i w2(0)) / (w0 + lam) e^{-i(w0 + lam) t}

    (Eq. 4.113; the integration constant is zero: the mean spin axis is inertial x). ``w2, w3``
    are exact; ``alpha`` is first order in the cone angle, with an ``O(alpha^3)`` error as in
    `coning_angle`.

    Parameters
    ----------
    inertia_diag : array_like, shape (3,) [kg m^2]
        ``(I1, I2, I3)`` with ``I2 = I3`` (to 1e-12 relative); ``I1 != I2``.
    w0 : array_like, shape (3,) [rad/s]
        Body rates at ``t = 0``: spin ``w0[0] > 0``, small ``w0[1], w0[2]``.
    torque : float [N m]
        ``L2``: the constant torque about body ``x2``.
    t : float or array_like, shape (n,) [s]

    Returns
    -------
    MisalignedThrust

    Raises
    ------
    TypeError
        If an argument is not real numbers.
    ValueError
        If ``I2 != I3``, ``I1 = I2`` (no gyroscopic stiffness), or the spin is not positive.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.truth import misaligned_thrust
    >>> r = misaligned_thrust([2.0, 1.0, 1.0], [10.0, 0.0, 0.0], 0.5, [0.0, np.pi / 20])
    >>> r.precession_rate, r.steady_w3  # I1 w0 / I2, L2 / (lam I2)
    (20.0, 0.05)
    >>> np.round(r.w3, 12)  # from rest: w3 = s (1 - cos(lam t)), lam t = pi/2
    array([0.  , 0.05])
    """
    I = check_moments(inertia_diag)
    if abs(I[1] - I[2]) > EQUAL_RTOL * max(I[1], I[2]):
        raise ValueError(f"`inertia_diag` must have I2 = I3 (an axisymmetric spinner about "
                         f"axis 1), got {I.tolist()}")
    w = _spin_rates(w0)
    if w[0] < 0:
        raise ValueError(f"`w0[0]` must be a positive spin, got {w[0]!r}")
    L2 = validate.finite_scalar(torque, "torque")
    tt = check_times(t)
    spin = w[0]
    lam = (I[0] - I[1]) / I[1] * spin
    if lam == 0:
        raise ValueError(f"`inertia_diag` has I1 = I2 = I3: no gyroscopic stiffness (the "
                         f"torque integrates to a growing rate), got {I.tolist()}")
    s = L2 / (lam * I[1])
    free = w[2] - s + 1j * w[1]
    rates = s + free * np.exp(-1j * lam * tt)
    alpha = (1j * s / spin * np.exp(-1j * spin * tt)
             + 1j * free / (spin + lam) * np.exp(-1j * (spin + lam) * tt))
    return MisalignedThrust(rates.imag, rates.real, alpha, float(spin + lam), float(s))


def floating_frame_accelerations(transverse, axial, angles, angle_rates, torque):
    """Classical 3-1-3 angle accelerations of an axisymmetric body (Sec. 4.6, Method II, Eq. 4.119).

    The floating (node) frame is the 3-1-3 sequence without the spin (``phi = 0``); it turns at
    ``wF = (theta', psi' sin(theta), psi' cos(theta))`` and the body at ``w = wF + phi' e3``.
    With ``I = diag(I1, I1, I3)`` constant in that frame, ``I w' + wF x I w = L`` reads, with
    the total spin ``w3 = psi' cos(theta) + phi'``::

        I1 theta'' + I3 w3 psi' sin(theta) - I1 psi'^2 sin(theta) cos(theta) = L1
        I1 (psi'' sin(theta) + 2 psi' theta' cos(theta)) - I3 w3 theta' = L2
        I3 w3' = L3

    (about ``theta = pi/2`` and with ``w3 = w0`` these are the seed's horizontal-gyroscope pair
    ``I1 psi'' - I3 w0 theta' = 0``, ``I1 theta'' + I3 w0 psi' = L1``). Exact, singular at
    ``sin(theta) = 0`` like the 3-1-3 angles.

    Parameters
    ----------
    transverse, axial : float [kg m^2]
        ``I1 = I2`` and ``I3`` about the reference point (mass centre or fixed pivot).
    angles : array_like, shape (3,) [rad]
        ``(psi, theta, phi)``, classical 3-1-3 (`dynamics.attitude.dcm_from_euler313`).
    angle_rates : array_like, shape (3,) [rad/s]
    torque : array_like, shape (3,) [N m]
        ``L`` in floating-frame components (node line ``e1``, ``e2``, symmetry axis ``e3``).

    Returns
    -------
    ndarray, shape (3,) [rad/s^2]
        ``(psi'', theta'', phi'')``.

    Raises
    ------
    TypeError
        If an argument is not real numbers.
    ValueError
        If a moment is not positive, ``axial > 2 transverse`` (triangle inequality), an array
        has the wrong shape, or ``|sin(theta)| < validate.EULER_LOCK_TOL``.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.truth import floating_frame_accelerations
    >>> # steady precession of a horizontal gyroscope: psi' = L1 / (I3 w0), no accelerations
    >>> I1, I3, w0, L1 = 2.0, 1.0, 50.0, 5.0
    >>> np.round(floating_frame_accelerations(I1, I3, [0, np.pi / 2, 0], [L1 / (I3 * w0), 0, w0],
    ...                                       [L1, 0, 0]), 12)
    array([0., 0., 0.])
    """
    I1, I3 = _symmetric_moments(transverse, axial)
    psi, th, phi = validate.finite_array(angles, "angles", (3,))
    dpsi, dth, dphi = validate.finite_array(angle_rates, "angle_rates", (3,))
    L = validate.finite_array(torque, "torque", (3,))
    s, c = np.sin(th), np.cos(th)
    if abs(s) < validate.EULER_LOCK_TOL:
        raise ValueError(f"`angles` is at the 3-1-3 gimbal lock (sin(theta) = {s!r}): psi and "
                         f"phi are not separable there; use a quaternion model")
    w3 = dpsi * c + dphi
    ddth = (L[0] - I3 * w3 * dpsi * s + I1 * dpsi * dpsi * s * c) / I1
    ddpsi = ((L[1] + I3 * w3 * dth) / I1 - 2 * dpsi * dth * c) / s
    dw3 = L[2] / I3
    ddphi = dw3 - ddpsi * c + dpsi * dth * s  # w3' = psi'' c - psi' theta' s + phi''
    return np.array([ddpsi, ddth, ddphi])


def _symmetric_moments(transverse, axial):
    I1 = validate.positive(transverse, "transverse")
    I3 = validate.positive(axial, "axial")
    if I3 > 2 * I1 * (1 + EQUAL_RTOL):
        raise ValueError(f"`axial` {I3!r} exceeds 2 `transverse` ({2 * I1!r}): the triangle "
                         f"inequality of principal moments fails (Sec. 4.4 A)")
    return I1, I3


class HorizontalGyroscope(NamedTuple):
    """Method II's heavy top about the horizontal (`horizontal_gyroscope`).

    Attributes
    ----------
    psi, theta : ndarray, shape (n,) [rad]
        Classical 3-1-3 precession and nutation angles (``theta`` from the vertical).
    precession_rate : float [rad/s]
        ``omega_p = L1 / (I3 w0)``: the mean precession.
    nutation_frequency : float [rad/s]
        ``p = I3 w0 / I1``.
    """

    psi: np.ndarray
    theta: np.ndarray
    precession_rate: float
    nutation_frequency: float


def horizontal_gyroscope(transverse, axial, rate, torque, t, *, precession_rate0=0.0):
    """Gyroscope with its spin axis near the horizontal under a tilting torque (Sec. 4.6, Method II).

    Linearizing `floating_frame_accelerations` about ``theta = pi/2`` with the spin
    ``w3 = w0``: ``I1 psi'' - I3 w0 theta' = 0``, ``I1 theta'' + I3 w0 psi' = L1`` (for the
    heavy top ``L1 = m g l sin(theta) ~ m g l``). With ``p = I3 w0 / I1``,
    ``omega_p = L1 / (I3 w0)`` and ``psi(0) = 0``, ``theta(0) = pi/2``, ``theta'(0) = 0``,
    ``psi'(0) = psi0'``::

        psi   = (psi0' - omega_p) / p sin(p t) + omega_p t
        theta = pi/2 + (psi0' - omega_p) / p (cos(p t) - 1)

    (the seed prints the ``theta`` constant as ``pi/2 - (psi0' - omega_p)/p``, i.e. the same).
    The spin axis precesses about the vertical at the mean rate ``omega_p``, nodding at ``p``.
    First order in ``eps = omega_p / p`` (the neglected terms are ``I1 psi'^2 cos(theta)`` and
    the change of ``L1`` with ``theta``): the error relative to the nodding amplitude is
    ``O(eps^2)`` (measured 2.7 % at ``eps = 0.016``, 0.7 % at half of it).

    Parameters
    ----------
    transverse, axial : float [kg m^2]
        ``I1`` about the pivot (transverse) and ``I3`` (spin axis).
    rate : float [rad/s]
        ``w0``: the spin ``w3`` (non-zero).
    torque : float [N m]
        ``L1``: the torque about the node line (``m g l`` for the heavy top).
    t : float or array_like, shape (n,) [s]
    precession_rate0 : float [rad/s], optional
        ``psi'(0)``; ``omega_p`` starts a steady precession without nodding.

    Returns
    -------
    HorizontalGyroscope

    Raises
    ------
    TypeError
        If an argument is not real numbers.
    ValueError
        If a moment is not positive (or ``axial > 2 transverse``) or ``rate`` is zero.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.truth import horizontal_gyroscope
    >>> g = horizontal_gyroscope(0.02, 0.01, 200.0, 0.5, [0.0, 1.0])  # I1, I3, w0, m g l
    >>> g.precession_rate, g.nutation_frequency  # L1 / (I3 w0), I3 w0 / I1
    (0.25, 100.0)
    """
    I1, I3 = _symmetric_moments(transverse, axial)
    w0 = validate.finite_scalar(rate, "rate")
    if w0 == 0:
        raise ValueError("`rate` must be a non-zero spin (the gyroscope falls without one)")
    L1 = validate.finite_scalar(torque, "torque")
    dpsi0 = validate.finite_scalar(precession_rate0, "precession_rate0")
    tt = check_times(t)
    p = I3 * w0 / I1
    wp = L1 / (I3 * w0)
    amp = (dpsi0 - wp) / p
    return HorizontalGyroscope(amp * np.sin(p * tt) + wp * tt,
                               np.pi / 2 + amp * (np.cos(p * tt) - 1), float(wp), float(p))
