"""The hand-written `dynamics.spinning` models before they became scenes, copied verbatim
(test-only): the independent reference the scene wrappers `gyrostat_model` and
`tilt_torque_body` are checked against (tests/dynamics/scene/test_dampers.py)."""
from __future__ import annotations

import math

import casadi as ca
import numpy as np

from appdyn.dynamics import cache, validate
from appdyn.dynamics.attitude import dcm_from_quat, quat_rate
from appdyn.dynamics.model import Model
from appdyn.dynamics.momentum.wheels import rotor_dynamics
from appdyn.dynamics.rigid_body import RIGID_BODY_STATES
from appdyn.dynamics.spinning import PointMassDamper, SphericalDamper
from appdyn.dynamics.validate import check_inertia

_TORQUES = ("L1", "L2", "L3")
_BASE_UNITS = {**{k: "-" for k in RIGID_BODY_STATES[:4]},
               **{k: "rad/s" for k in RIGID_BODY_STATES[4:]}, **{k: "N m" for k in _TORQUES}}


def unit_vector(v, name: str) -> np.ndarray:
    """`validate.unit_vector` of a 3-vector, with the one message the stability reports show:
    "`name` must be a finite non-zero 3-vector" for a wrong shape, a non-finite or a zero
    vector (a `validate.ArgumentTypeError` when ``v`` holds no numbers)."""
    try:
        return validate.unit_vector(v, name)
    except ValueError as exc:
        raise type(exc)(f"`{name}` must be a finite non-zero 3-vector, got {v!r}") from None


def _finite(value, name, *, positive=False, nonnegative=False, allow_inf=False) -> float:
    """A real number (`validate.finite_scalar`), optionally positive or non-negative;
    ``allow_inf`` also accepts ``+inf`` (an infinitely heavy body)."""
    if allow_inf and isinstance(value, (int, float, np.floating)) and value == math.inf:
        return math.inf
    v = validate.finite_scalar(value, name)
    if positive and not v > 0:
        raise ValueError(f"`{name}` must be positive, got {v}")
    if nonnegative and v < 0:
        raise ValueError(f"`{name}` must be non-negative, got {v}")
    return v


# -------------------------------------------------------------------- tilt torque
@cache.memoize
def _tilt_torque_body(inertia_key, axis_key, direction_key, overturning, damping) -> Model:
    inertia = np.array(inertia_key).reshape(3, 3)
    a = ca.DM(axis_key)
    d_in = ca.DM(direction_key)
    x = ca.SX.sym("x", 7)
    u = ca.SX.sym("u", 3)
    p = ca.SX.sym("p", 0)
    q, w = x[0:4], x[4:7]
    I = ca.DM(inertia)
    n = ca.mtimes(dcm_from_quat(q), d_in)  # the fixed direction in body axes
    M = ca.mtimes(n, a.T) - ca.dot(a, n) * ca.DM.eye(3)  # tau' = M w, tau = a x n
    torque = u - overturning * ca.cross(a, n) - damping * ca.mtimes(M.T, ca.mtimes(M, w))
    wdot = ca.solve(I, torque - ca.cross(w, ca.mtimes(I, w)))
    f = ca.Function("tilt_torque_body", [x, u, p], [ca.vertcat(quat_rate(q, w), wdot)],
                    ["x", "u", "p"], ["xdot"])
    h = ca.mtimes(I, w)
    invariants = {
        "energy": ca.Function("energy", [x, p], [0.5 * ca.dot(w, h) + overturning * ca.dot(a, n)],
                              ["x", "p"], ["energy"]),
        "momentum_inertial": ca.Function("momentum_inertial", [x, p],
                                         [ca.mtimes(dcm_from_quat(q).T, h)], ["x", "p"],
                                         ["momentum_inertial"]),
        "quat_norm": ca.Function("quat_norm", [x, p], [ca.norm_2(q)], ["x", "p"], ["quat_norm"]),
    }
    return Model(f=f, states=RIGID_BODY_STATES, controls=_TORQUES, units=_BASE_UNITS,
                 invariants=invariants, name="tilt_torque_body", attitude=(0, 4))


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
        ``momentum_inertial`` [N m s] and ``quat_norm``. Cached by its arguments.

    Raises
    ------
    ValueError
        Naming the argument: bad ``inertia`` (see `check_inertia`), non-finite
        ``overturning``, zero ``axis``/``direction``, negative ``internal_damping``.

    References
    ----------
    .. [1] Rheinfurth & Wilson, NASA RP-1262, Sec. 4.6, Method III and its Example 1.
    """
    I = check_inertia(inertia)
    kappa = _finite(overturning, "overturning")
    a = unit_vector(axis, "axis")
    d = unit_vector(direction, "direction")
    damping = _finite(internal_damping, "internal_damping", nonnegative=True)
    return _tilt_torque_body(tuple(I.reshape(-1).tolist()), tuple(a.tolist()), tuple(d.tolist()),
                             kappa, damping)


# ------------------------------------------------------------------------ gyrostat
@cache.memoize
def _gyrostat(inertia_key, wheel_axis, wheel_momentum, damper, damper_on, wheel_rate) -> Model:
    I = ca.DM(np.array(inertia_key).reshape(3, 3))
    aw = ca.DM(wheel_axis)
    h = wheel_momentum
    nd = {None: 0, PointMassDamper: 2, SphericalDamper: 3}[type(damper) if damper else None]
    x = ca.SX.sym("x", 7 + nd)
    u = ca.SX.sym("u", 3)
    p = ca.SX.sym("p", 0)
    q, w = x[0:4], x[4:7]
    extra_states, extra_units = (), {}
    if damper is None:  # a wheel spacecraft whose wheel is held at constant relative speed
        H, wdot, _ = rotor_dynamics(I, aw, w, [h], u)
        rest = []
        energy = 0.5 * ca.dot(w, ca.mtimes(I, w))
    elif isinstance(damper, PointMassDamper):
        s, sd = x[7], x[8]
        mu, k, c = damper.reduced_mass, damper.stiffness, damper.damping
        b, d = ca.DM(damper.position), ca.DM(damper.direction)
        rho = b + s * d
        g = ca.cross(rho, d)
        E3 = ca.DM.eye(3)
        J = I + mu * (ca.dot(rho, rho) * E3 - ca.mtimes(rho, rho.T))
        Jdot = mu * sd * (2 * ca.dot(rho, d) * E3 - ca.mtimes(d, rho.T) - ca.mtimes(rho, d.T))
        H = ca.mtimes(J, w) + mu * sd * g + h * aw
        mass = ca.vertcat(ca.horzcat(J, mu * g), ca.horzcat(mu * g.T, mu))
        rhs = ca.vertcat(u - ca.mtimes(Jdot, w) - ca.cross(w, H),
                         -k * s - c * sd - mu * ca.dot(d, ca.cross(w, ca.cross(w, rho))))
        acc = ca.solve(mass, rhs)
        wdot = acc[0:3]
        rest = [sd, acc[3]]
        energy = (0.5 * ca.dot(w, ca.mtimes(J, w)) + mu * sd * ca.dot(g, w) + 0.5 * mu * sd ** 2
                  + 0.5 * k * s ** 2)
        extra_states, extra_units = ("s", "s_dot"), {"s": "m", "s_dot": "m/s"}
    else:
        wd = x[7:10]
        Jd, c = damper.inertia, damper.damping
        wh = w + (wheel_rate * aw if damper_on == "rotor" else 0)
        H = ca.mtimes(I, w) + h * aw + Jd * wd
        wdot = ca.solve(I, u - ca.cross(w, ca.mtimes(I, w) + h * aw) + c * (wd - wh))
        rest = [-(c / Jd) * (wd - wh) - ca.cross(w, wd)]
        energy = 0.5 * ca.dot(w, ca.mtimes(I, w)) + 0.5 * Jd * ca.dot(wd, wd)
        extra_states = ("wd1", "wd2", "wd3")
        extra_units = {k: "rad/s" for k in extra_states}
    xdot = ca.vertcat(quat_rate(q, w), wdot, *rest)
    f = ca.Function("gyrostat", [x, u, p], [xdot], ["x", "u", "p"], ["xdot"])
    invariants = {
        "energy": ca.Function("energy", [x, p], [energy], ["x", "p"], ["energy"]),
        "momentum_inertial": ca.Function("momentum_inertial", [x, p],
                                         [ca.mtimes(dcm_from_quat(q).T, H)], ["x", "p"],
                                         ["momentum_inertial"]),
        "quat_norm": ca.Function("quat_norm", [x, p], [ca.norm_2(q)], ["x", "p"], ["quat_norm"]),
    }
    return Model(f=f, states=RIGID_BODY_STATES + extra_states, controls=_TORQUES,
                 units={**_BASE_UNITS, **extra_units}, invariants=invariants, name="gyrostat",
                 attitude=(0, 4))


def _check_damper(damper, damper_on):
    if damper is not None and not isinstance(damper, (PointMassDamper, SphericalDamper)):
        raise ValueError("`damper` must be None, a PointMassDamper or a SphericalDamper, got "
                         f"{type(damper).__name__}")
    if damper_on not in ("platform", "rotor"):
        raise ValueError(f"`damper_on` must be 'platform' or 'rotor', got {damper_on!r}")
    if damper_on == "rotor" and isinstance(damper, PointMassDamper):
        raise ValueError("`damper_on`='rotor' needs an axisymmetric damper (SphericalDamper): a "
                         "point mass on the spinning rotor makes the motion time-periodic")


def gyrostat_model(inertia, *, wheel_axis=(1.0, 0.0, 0.0), wheel_momentum: float = 0.0,
                   damper=None, damper_on: str = "platform", wheel_rate: float = 0.0) -> Model:
    """Gyrostat (rigid body + wheel of constant relative speed) with an optional damper.

    The wheel spins relative to the platform about ``a`` (body axes) at a rate held constant
    by its motor; its relative angular momentum is ``h a``, and ``inertia`` includes the
    wheel as if locked. Torque-free apart from ``u`` (about the system mass center):
    ``H' + w x H = u`` in body axes, with

    * no damper: ``H = I w + h a``, ``I w' = u - w x H`` -- a wheel spacecraft whose wheel
      is held at constant speed (`dynamics.momentum.wheels.rotor_dynamics`, shared).
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
      or ``w + wheel_rate a`` (rotor), hence ``I w' = u - w x (I w + h a) + c (w_d - w_h)``.
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
        invariants ``energy`` [J], ``momentum_inertial`` [N m s], ``quat_norm``. Cached.

    Raises
    ------
    ValueError
        Naming the argument (inertia, axis, momentum, damper type or placement).
    """
    I = check_inertia(inertia)
    a = unit_vector(wheel_axis, "wheel_axis")
    h = _finite(wheel_momentum, "wheel_momentum")
    rate = _finite(wheel_rate, "wheel_rate")
    _check_damper(damper, damper_on)
    if not isinstance(damper, SphericalDamper) or damper_on != "rotor":
        rate = 0.0  # only a rotor-mounted damper sees the wheel speed
    return _gyrostat(tuple(I.reshape(-1).tolist()), tuple(a.tolist()), h, damper, damper_on, rate)
