"""Spinning-vehicle models for stability studies (Rheinfurth & Wilson, NASA RP-1262,
Secs. 4.5-4.6).

* `tilt_torque_body` — a rigid body with a torque that depends only on the tilt of a body
  axis from an inertially fixed direction (Sec. 4.6 Method III): the heavy top
  (``overturning = m g l``), the spinning projectile (``q S C_N_alpha l``), a rotor in
  elastic bearings (``-2 k l^2``), with an optional *internal* (rotating) damping.
* `gyrostat_model` — a rigid body carrying a wheel of constant relative speed (dual spin)
  and, optionally, an energy damper: a spring-mass point mass sliding along a body line
  (`PointMassDamper`) or a viscously coupled spherical core (`SphericalDamper`), mounted
  on the platform or (spherical only) on the rotor. With zero wheel momentum it is a
  rigid body with a nutation damper (Kelvin-Tait-Chetaev, Sec. 4.5 NOTE).

All models have the state ``[q1, q2, q3, q4, w1, w2, w3, ...]`` (scalar-last quaternion,
inertial -> body, and body rates [rad/s]), ``attitude = (0, 4)``, and external body torques
``u = [L1, L2, L3]`` [N m]. Both are scenes (`dynamics.scene`): ``Scene(RigidHub(I),
[HeldRotor], [damper], ExternalTorque())`` and ``Scene(RigidHub(I), TiltTorque, ExternalTorque())``,
so they carry ``layout``; the dampers are the scene parts of `dynamics.scene.dampers`, re-exported
here. Their equations are derived in the docstrings; the tests check them against the former
hand-written models, conservation laws (energy, inertial angular momentum) and closed forms.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from . import cache
from .model import Model
from .scene import (ExternalTorque, HeldRotor, PointMassDamper, RigidHub, Scene,
                    SphericalDamper, TiltTorque)
from .scene.dampers import real_number, unit_vector
from .validate import check_inertia

__all__ = ["PointMassDamper", "SphericalDamper", "tilt_torque_body", "tilt_torque_scene",
           "gyrostat_model", "gyrostat_scene", "steady_spin_state", "point_mass_offset",
           "unit_vector"]


# -------------------------------------------------------------------- tilt torque
@cache.memoize_values
def tilt_torque_body(inertia, overturning, *, axis=(1.0, 0.0, 0.0), direction=(1.0, 0.0, 0.0),
                     internal_damping: float = 0.0) -> Model:
    """Rigid body about a fixed point with a tilt-dependent torque ([1]_, Method III).

    With ``a`` the body axis, ``n = A(q) d`` the inertially fixed unit direction ``d`` in body
    axes and ``tau = a x n`` the tilt vector, the torque about the fixed point is

        L = u - kappa a x n - D M^T M w,        M = n a^T - (a . n) E,

    * ``-kappa a x n`` derives from the potential ``V = kappa (a . n)``: for the heavy top
      (``a`` from the pivot to the mass center at distance ``l``, ``d`` pointing up,
      gravity ``-m g d``) ``L = l a x (-m g n)``, so ``kappa = m g l``; Example 1 of [1]_ gives
      the same ``L = m g l (theta e2 + psi e3)`` to first order. The spinning projectile has
      ``kappa = q S C_N_alpha l`` (Example 2); a rotor in bearings of stiffness ``k`` at
      ``+/- l``, ``V = -2 k l^2 cos(tilt)``, has ``kappa = -2 k l^2`` (Example 3).
    * ``-D M^T M w`` is internal (rotating) damping: ``M w = tau'`` is the rate of the tilt
      seen in the body, and the torque derives from the Rayleigh function
      ``R = D |tau'|^2 / 2``, so the power is ``-D |tau'|^2``. To first order about a spin
      ``w0 a`` it is ``-D (theta', psi')`` in Method III's deviation angles.

    Euler's law about the fixed point: ``I w' + w x I w = L``; ``q' = -1/2 Wbar(w) q``.

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2]
        About the fixed point (pivot) or, for a free body whose translation decouples, the
        mass center.
    overturning : float [N m]
        ``kappa``: positive tips the axis away from ``d`` (heavy top, projectile), negative
        restores it (rotor bearings).
    axis : array_like, shape (3,), optional
        Body axis ``a`` (normalized; default e1)
    direction : array_like, shape (3,), optional
        Inertial direction ``d`` (default x)
    internal_damping : float [N m s], optional
        ``D >= 0``

    Returns
    -------
    Model
        ``x = [q1..q4, w1..w3]``, ``u = [L1, L2, L3]`` [N m], invariants ``energy``
        (``1/2 w.Iw + kappa a.n`` [J], conserved for ``D = 0``, ``u = 0``),
        ``momentum_inertial`` [N m s] and ``quat_norm``; ``layout`` (parts ``tilt``,
        ``torque``). The model of ``Scene(RigidHub(I), TiltTorque(kappa, ...),
        ExternalTorque(), name="tilt_torque_body")``, cached by value.

    Raises
    ------
    ValueError
        Naming the argument: bad ``inertia`` (see `check_inertia`), non-finite
        ``overturning``, zero ``axis``/``direction``, negative ``internal_damping``.

    References
    ----------
    .. [1] Rheinfurth & Wilson, NASA RP-1262, Sec. 4.6, Method III and its Example 1.
    """
    return tilt_torque_scene(inertia, overturning, axis=axis, direction=direction,
                             internal_damping=internal_damping).model()


def tilt_torque_scene(inertia, overturning, *, axis=(1.0, 0.0, 0.0), direction=(1.0, 0.0, 0.0),
                      internal_damping: float = 0.0) -> Scene:
    """The `Scene` of `tilt_torque_body` (same arguments and errors).

    Examples
    --------
    >>> from appdyn.dynamics.spinning import tilt_torque_scene
    >>> tilt_torque_scene([0.002, 0.005, 0.005], 0.1).part_names
    ('tilt', 'torque')
    """
    hub = RigidHub(check_inertia(inertia))
    tilt = TiltTorque(overturning, axis=axis, direction=direction,
                      internal_damping=internal_damping)
    return Scene(hub, tilt, ExternalTorque(), name="tilt_torque_body")


# ------------------------------------------------------------------------ gyrostat
def _check_damper(damper, damper_on):
    if damper is not None and not isinstance(damper, (PointMassDamper, SphericalDamper)):
        raise ValueError("`damper` must be None, a PointMassDamper or a SphericalDamper, got "
                         f"{type(damper).__name__}")
    if damper_on not in ("platform", "rotor"):
        raise ValueError(f"`damper_on` must be 'platform' or 'rotor', got {damper_on!r}")
    if damper_on == "rotor" and isinstance(damper, PointMassDamper):
        raise ValueError("`damper_on`='rotor' needs an axisymmetric damper (SphericalDamper): a "
                         "point mass on the spinning rotor makes the motion time-periodic")


@cache.memoize_values
def gyrostat_model(inertia, *, wheel_axis=(1.0, 0.0, 0.0), wheel_momentum: float = 0.0,
                   damper=None, damper_on: str = "platform", wheel_rate: float = 0.0) -> Model:
    """Gyrostat (rigid body + wheel of constant relative speed) with an optional damper.

    The wheel spins relative to the platform about ``a`` (body axes) at a rate held constant
    by its motor; its relative angular momentum is ``h a``, and ``inertia`` includes the
    wheel as if locked. Torque-free apart from ``u`` (about the system mass center):
    ``H' + w x H = u`` in body axes, with

    * no damper: ``H = I w + h a``, ``I w' = u - w x H`` -- a wheel spacecraft whose wheel
      is held at constant speed (`HeldRotor`; `dynamics.momentum.wheels.rotor_dynamics`).
    * `PointMassDamper` (on the platform): with ``rho = b + s d``, ``g = rho x d``,
      ``mu`` the reduced mass and ``J(s) = I + mu (|rho|^2 E - rho rho^T)``, the angular
      momentum about the system mass center is ``H = J(s) w + mu s' g + h a``; the mass
      obeys ``mu d.a_rel = -k s - c s'`` with ``a_rel = s'' d + 2 w x s' d + w' x rho +
      w x (w x rho)``, i.e. ``mu (s'' + g.w' + d.(w x (w x rho))) = -k s - c s'``. Together::

          [[J, mu g], [mu g^T, mu]] [w'; s''] = [u - J' w - w x H;
                                                 -k s - c s' - mu d.(w x (w x rho))]

      with ``J' = mu s' (2 (rho.d) E - d rho^T - rho d^T)``; the energy
      ``1/2 w.Jw + mu s' g.w + 1/2 mu s'^2 + 1/2 k s^2`` decays at ``-c s'^2`` (u = 0).
    * `SphericalDamper`: ``H = I w + h a + J_d w_d``; the core obeys
      ``J_d (w_d' + w x w_d) = -c (w_d - w_h)`` with the housing rate ``w_h = w`` (platform)
      or ``w + wheel_rate a`` (rotor: the damper's ``housing_rate``), hence
      ``I w' = u - w x (I w + h a) + c (w_d - w_h)``.
      The energy ``1/2 w.Iw + 1/2 J_d |w_d|^2`` decays at ``-c |w_d - w|^2`` when the damper
      is on the platform (u = 0).

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2]
        Rigid part about its mass center (wheel locked; without the point mass and without
        the spherical core's own rotational inertia ``J_d``).
    wheel_axis : array_like, shape (3,), optional
        ``a`` (normalized; default e1)
    wheel_momentum : float [N m s], optional
        ``h``, relative to the platform (0: no wheel)
    damper : PointMassDamper or SphericalDamper, optional
    damper_on : {'platform', 'rotor'}
        Where the damper is mounted (rotor: spherical only)
    wheel_rate : float [rad/s], optional
        Wheel speed relative to the platform; used only for a damper on the rotor.

    Returns
    -------
    Model
        ``x = [q1..q4, w1..w3]`` plus ``[s, s_dot]`` [m, m/s] (point mass) or
        ``[wd1, wd2, wd3]`` [rad/s] (core rate, body axes); ``u = [L1, L2, L3]``;
        invariants ``energy`` [J], ``momentum_inertial`` [N m s], ``quat_norm``; ``layout``
        (parts ``rotor`` when ``h != 0``, ``damper``, ``torque``). The model of
        ``Scene(RigidHub(I), HeldRotor(a, h), damper, ExternalTorque(), name="gyrostat")``,
        cached by value.

    Raises
    ------
    ValueError
        Naming the argument (inertia, axis, momentum, damper type or placement).
    """
    return gyrostat_scene(inertia, wheel_axis=wheel_axis, wheel_momentum=wheel_momentum,
                          damper=damper, damper_on=damper_on, wheel_rate=wheel_rate).model()


def gyrostat_scene(inertia, *, wheel_axis=(1.0, 0.0, 0.0), wheel_momentum: float = 0.0,
                   damper=None, damper_on: str = "platform", wheel_rate: float = 0.0) -> Scene:
    """The `Scene` of `gyrostat_model` (same arguments and errors): ``Scene(RigidHub(I),
    HeldRotor(a, h) if h != 0, damper (on the rotor: housing_rate = wheel_rate a),
    ExternalTorque(), name="gyrostat")``.

    Examples
    --------
    >>> from appdyn.dynamics.spinning import SphericalDamper, gyrostat_scene
    >>> gyrostat_scene([3.0, 4.0, 4.0], wheel_momentum=1.0,
    ...                damper=SphericalDamper(0.1, 0.05)).part_names
    ('rotor', 'damper', 'torque')
    """
    I = check_inertia(inertia)
    a = unit_vector(wheel_axis, "wheel_axis")
    h = real_number(wheel_momentum, "wheel_momentum")
    rate = real_number(wheel_rate, "wheel_rate")
    _check_damper(damper, damper_on)
    parts = [HeldRotor(a, h)] if h != 0.0 else []
    if isinstance(damper, SphericalDamper) and damper_on == "rotor":
        damper = dataclasses.replace(damper, housing_rate=tuple((rate * a).tolist()))
    if damper is not None:
        parts.append(damper)
    return Scene(RigidHub(I), *parts, ExternalTorque(), name="gyrostat")


def point_mass_offset(damper: PointMassDamper, axis, rate: float) -> float:
    """Displacement ``s`` [m] of a point-mass damper in a steady spin ``w = rate * axis``.

    From the mass equation with ``s' = s'' = w' = 0``: ``k s + mu d.(w x (w x rho)) = 0``,
    linear in ``s``: ``s (k - mu W^2 (1 - (d.a)^2)) = mu W^2 (d.b - (d.a)(a.b))``.

    Raises
    ------
    ValueError
        If the centrifugal stiffness cancels the spring (no isolated steady state).
    """
    a = unit_vector(axis, "axis")
    d, b = np.asarray(damper.direction), np.asarray(damper.position)
    mu, W2 = damper.reduced_mass, float(rate) ** 2
    stiff = damper.stiffness - mu * W2 * (1 - (d @ a) ** 2)
    if stiff <= 1e-12 * damper.stiffness:
        raise ValueError(f"`damper` spring is too soft for this spin: k = {damper.stiffness} N/m "
                         f"<= mu W^2 (1 - (d.a)^2) = {damper.stiffness - stiff:.6g} N/m, the mass "
                         "has no stable resting point")
    return float(mu * W2 * (d @ b - (d @ a) * (a @ b)) / stiff)


def steady_spin_state(axis, rate: float, *, damper=None, damper_on: str = "platform",
                      wheel_rate: float = 0.0) -> np.ndarray:
    """State of a `gyrostat_model` in the steady spin ``w = rate * axis`` at identity attitude.

    The point mass rests at `point_mass_offset`; a spherical core turns with its housing.
    Whether this is a relative equilibrium (``axis`` principal for the loaded body) is left
    to `dynamics.linearize.linearization`, which shows the residual if not.

    Returns
    -------
    ndarray, shape (7,), (9,) or (10,)
    """
    a = unit_vector(axis, "axis")
    rate = real_number(rate, "rate")
    _check_damper(damper, damper_on)
    x = [0.0, 0.0, 0.0, 1.0, *(rate * a)]
    if isinstance(damper, PointMassDamper):
        x += [point_mass_offset(damper, a, rate), 0.0]
    elif isinstance(damper, SphericalDamper):
        spin = rate + (wheel_rate if damper_on == "rotor" else 0.0)
        x += list(spin * a)
    return np.array(x)
