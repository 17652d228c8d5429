"""Worked systems held together by Lagrange multipliers (Rheinfurth & Wilson, NASA RP-1262,
Sec. 5.5, Eqs. 5.60-5.67 and its examples; Ch. 6 Example 4; seed 000's shaken pendulum),
each built with `dynamics.constrained` and checked against a closed form.

Every model here has redundant coordinates ``q`` held by constraints: its mass matrix
``M = d^2 T / dv^2`` and forces ``Q = dL/dq - (d/dq dT/dv) v`` come from the Lagrangian by
automatic differentiation (`lagrange_terms`), the constraint terms ``B``, ``c`` from
`dynamics.constrained.constraint_terms`, the accelerations and multipliers ``lam`` from
`dynamics.constrained.constrained_accelerations` (Eq. 5.66, reaction ``Q_R = -B^T lam``),
and drift is held by `dynamics.constrained.baumgarte` (time constant ``time_constant``;
``None`` switches it off). Each model has the invariants ``multipliers`` (``lam``) and
``constraint_residual`` (``[|phi|, |B v + b|]``), plus its own physical reading of ``lam``.

* `rod_pendulum` -- a mass on a massless rod (Sec. 5.5 b, Eqs. 5.74-5.76) in Cartesian
  coordinates: ``lam`` is the radial reaction ``R = -m l th'^2 - m g cos th``
  (`rod_reaction`);
* `shaken_pendulum_multipliers` -- the pendulum on a shaken hinge (seed 000) in mass-centre
  coordinates plus angle: its ``lam`` is the hinge force of `shaken_pendulum`;
* `sliding_bead` -- a bead on a wire driven at a prescribed rate (Sec. 5.5 c): the torque
  that drives the wire, Eq. 5.79;
The rolling coin and the dumbbell on a disk, with rigid-body attitudes, are in
`dynamics.mechanisms.bodies`; the shared Lagrange machinery in `dynamics.mechanisms.lagrange`.
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from .. import cache, validate
from ..constrained import DEFAULT_TIME_CONSTANT
from ..model import Model
from .common import GRAVITY, with_parameters
from .lagrange import checked_constants, constrained_model, lagrange_terms, stabilization
from .shaken import SHAKEN_DEFAULTS, shaken_pendulum

#: the parameters of `shaken_pendulum`, in its order
_SHAKEN_PARAMS = tuple(SHAKEN_DEFAULTS)

__all__ = ["rod_pendulum", "rod_reaction", "shaken_pendulum_multipliers",
           "shaken_multiplier_state", "sliding_bead", "bead_motion", "bead_torque"]


# ------------------------------------------------------------------ rod pendulum
_ROD = ("mass", "length", "gravity")


@cache.memoize
def _rod(tau) -> Model:
    x = ca.SX.sym("x", 4)
    p = ca.SX.sym("p", 3)
    m, l, g = p[0], p[1], p[2]
    q, v = x[:2], x[2:]
    M, Q = lagrange_terms(0.5 * m * ca.sumsqr(v), m * g * q[1], q, v)
    energy = 0.5 * m * ca.sumsqr(v) + m * g * q[1]
    return constrained_model("rod_pendulum", ("x", "y"), ("m", "m"), ("m/s", "m/s"), q, v, None, p, _ROD,
                  {"mass": "kg", "length": "m", "gravity": "m/s^2"}, [1.0, 1.0, GRAVITY],
                  M, Q, position=ca.norm_2(q) - l, time_constant=tau,
                  extra=lambda lam: {"rod_force": -lam[0], "energy": energy})


def rod_pendulum(*, mass=1.0, length=1.0, gravity=GRAVITY,
                 time_constant=DEFAULT_TIME_CONSTANT) -> Model:
    """A point mass on a massless rod from a fixed pivot, in Cartesian coordinates with the
    rod length as a constraint (Sec. 5.5 b, Eqs. 5.74-5.76).

    Pivot at the origin, ``y`` up, ``theta`` from the hanging position:
    ``(x, y) = l (sin th, -cos th)``. The constraint ``phi = |r| - l`` has ``B = e_r^T``
    (the unit radial row), so the reaction ``Q_R = -B^T lam = -lam e_r`` is radial and its
    outward component is ``R = -lam``. The seed's polar form (coordinates ``th, l``,
    constraint ``l' = 0``) has the same ``B`` row for ``l`` and reads
    ``m l'' - m l th'^2 - m g cos th + lam = 0``, so with ``l'' = 0``::

        R = -lam = -m l th'^2 - m g cos th

    negative: the rod pulls (tension ``-R``), from the centrifugal force and the weight's
    component along the rod.

    Parameters
    ----------
    mass : float [kg]
        ``> 0``.
    length : float [m]
        ``> 0``.
    gravity : float [m/s^2]
        ``>= 0``.
    time_constant : float or None [s]
        Baumgarte time constant (`dynamics.constrained.baumgarte`); ``None``: none.

    Returns
    -------
    Model
        ``x = [x, y, x_dot, y_dot]`` [m, m/s]; parameters ``mass, length, gravity``;
        invariants ``multipliers`` (``lam`` [N]), ``rod_force`` (``R = -lam`` [N]),
        ``energy`` [J] and ``constraint_residual``.

    Raises
    ------
    ValueError
        Naming ``mass``, ``length`` (not positive), ``gravity`` (negative) or
        ``time_constant`` (not positive).

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.mechanisms import rod_pendulum, rod_reaction
    >>> model = rod_pendulum(length=2.0, gravity=9.81)
    >>> x0 = [0.0, -2.0, 3.0, 0.0]           # hanging, moving at 3 m/s: th' = 1.5 rad/s
    >>> round(float(model.invariant("rod_force", x0)), 9), rod_reaction(0.0, 1.5, length=2.0,
    ...                                                                  gravity=9.81)
    (-14.31, -14.31)
    """
    tau = stabilization(time_constant)
    vals = checked_constants(dict(mass=mass, length=length, gravity=gravity), ("mass", "length"),
                    ("gravity",))
    return with_parameters(_rod(tau), vals)


def rod_reaction(theta, theta_dot, *, mass=1.0, length=1.0, gravity=GRAVITY):
    """The radial rod reaction ``R = -m l th'^2 - m g cos th`` [N] (negative: tension).

    Parameters
    ----------
    theta, theta_dot : array_like [rad, rad/s]
    mass, length, gravity : float

    Returns
    -------
    numpy.ndarray or float

    Raises
    ------
    TypeError
        If ``theta`` or ``theta_dot`` is not real numbers (a string, ``None``, a symbol).
    ValueError
        If ``theta`` or ``theta_dot`` has a NaN or infinite entry (refused rather than
        propagated), or the two do not broadcast.

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import rod_reaction
    >>> rod_reaction(0.0, 0.0, gravity=9.81)
    -9.81
    """
    th, w = validate.finite_array(theta, "theta"), validate.finite_array(theta_dot, "theta_dot")
    out = -mass * length * w ** 2 - mass * gravity * np.cos(th)
    return float(out) if out.ndim == 0 else out


# ------------------------------------------------------------------ shaken pendulum
@cache.memoize
def _shaken_lam(tau) -> Model:
    x = ca.SX.sym("x", 7)
    p = ca.SX.sym("p", len(_SHAKEN_PARAMS))
    m, inertia, l, g, amp_y, amp_x, freq, damp = (p[i] for i in range(8))
    q, v, t = x[:3], x[3:6], x[6]
    units = {k: shaken_pendulum().units[k] for k in _SHAKEN_PARAMS}
    T = 0.5 * m * ca.sumsqr(v[:2]) + 0.5 * inertia * v[2] ** 2
    M, Q = lagrange_terms(T, m * g * q[1], q, v)
    Q = Q - ca.vertcat(0, 0, damp * v[2])
    hinge = ca.vertcat(amp_x, amp_y) * ca.sin(freq * t)
    s = l * ca.vertcat(ca.sin(q[2]), -ca.cos(q[2]))
    energy = T + m * g * q[1]
    return constrained_model("shaken_pendulum_multipliers", ("x", "y", "theta"), ("m", "m", "rad"),
                  ("m/s", "m/s", "rad/s"), q, v, t, p, _SHAKEN_PARAMS, units,
                  [SHAKEN_DEFAULTS[k] for k in _SHAKEN_PARAMS], M, Q,
                  position=hinge + s - q[:2], time_constant=tau,
                  extra=lambda lam: {"hinge_force": lam, "energy": energy})


def shaken_pendulum_multipliers(*, mass=SHAKEN_DEFAULTS["mass"],
                                inertia=SHAKEN_DEFAULTS["inertia"],
                                length=SHAKEN_DEFAULTS["length"], gravity=GRAVITY,
                                amp_y=SHAKEN_DEFAULTS["amp_y"], amp_x=SHAKEN_DEFAULTS["amp_x"],
                                freq=SHAKEN_DEFAULTS["freq"], damping=0.0,
                                time_constant=DEFAULT_TIME_CONSTANT) -> Model:
    """The physical pendulum on a shaken hinge (seed 000) with Lagrange multipliers: the
    second formulation of `dynamics.mechanisms.shaken_pendulum`.

    Coordinates: the mass centre ``(x, y)`` (``y`` up) and the angle ``theta`` from the
    hanging position; ``T = 1/2 m (x'^2 + y'^2) + 1/2 I_c th'^2``, ``V = m g y``, a viscous
    hinge ``-c th'``. The hinge moves as ``r_h(t) = (amp_x, amp_y) sin(freq t)`` (the clock
    state ``t``), and the two hinge constraints are::

        phi = r_h(t) + l (sin th, -cos th) - (x, y) = 0

    ``B = [[-1, 0, l cos th], [0, -1, l sin th]]``, so the reaction ``-B^T lam`` on the mass
    centre is ``+lam`` with the moment ``(s x lam)`` about it: ``lam`` is the force of the
    hinge on the pendulum, the invariant ``hinge_force`` of `shaken_pendulum`.

    Parameters
    ----------
    mass, inertia, length, gravity, amp_y, amp_x, freq, damping : float
        As for `shaken_pendulum` (``inertia`` is the central moment ``I_c``).
    time_constant : float or None [s]
        Baumgarte time constant; ``None``: none.

    Returns
    -------
    Model
        ``x = [x, y, theta, x_dot, y_dot, theta_dot, t]``; the parameters of
        `shaken_pendulum`; invariants ``multipliers`` and ``hinge_force`` (both ``lam`` [N],
        inertial ``x, y``), ``energy`` [J] (not conserved when shaken) and
        ``constraint_residual``. Start on the constraints with `shaken_multiplier_state`.

    Raises
    ------
    ValueError
        Naming the parameter out of range (as `shaken_pendulum`) or ``time_constant``.

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import (shaken_multiplier_state, shaken_pendulum,
    ...                                  shaken_pendulum_multipliers)
    >>> lagrange, euler = shaken_pendulum_multipliers(), shaken_pendulum()
    >>> x0 = shaken_multiplier_state(0.5, 1.0, 0.01)
    >>> a, b = lagrange.rhs(x0)[5], euler.rhs([0.5, 1.0, 0.01])[1]
    >>> bool(abs(a - b) < 1e-12)
    True
    """
    tau = stabilization(time_constant)
    vals = checked_constants(dict(mass=mass, inertia=inertia, length=length, gravity=gravity,
                         amp_y=amp_y, amp_x=amp_x, freq=freq, damping=damping),
                    ("mass", "length"), ("inertia", "gravity", "damping"))
    return with_parameters(_shaken_lam(tau), vals)


def shaken_multiplier_state(theta, theta_dot, t=0.0, *, length=SHAKEN_DEFAULTS["length"],
                            amp_y=SHAKEN_DEFAULTS["amp_y"], amp_x=SHAKEN_DEFAULTS["amp_x"],
                            freq=SHAKEN_DEFAULTS["freq"]) -> np.ndarray:
    """The state of `shaken_pendulum_multipliers` on its constraints for the angle state
    ``(theta, theta_dot, t)`` of `shaken_pendulum`.

    Returns
    -------
    numpy.ndarray, shape (7,)

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import shaken_multiplier_state
    >>> shaken_multiplier_state(0.0, 2.0, amp_y=0.0).round(6).tolist()
    [0.0, -0.25, 0.0, 0.5, 0.0, 2.0, 0.0]
    """
    th = validate.finite_scalar(theta, "theta")
    w = validate.finite_scalar(theta_dot, "theta_dot")
    t = validate.finite_scalar(t, "t")
    l = validate.positive(length, "length")
    amp = np.array([validate.finite_scalar(amp_x, "amp_x"), validate.finite_scalar(amp_y, "amp_y")])
    freq = validate.finite_scalar(freq, "freq")
    r = amp * np.sin(freq * t) + l * np.array([np.sin(th), -np.cos(th)])
    v = amp * freq * np.cos(freq * t) + l * w * np.array([np.cos(th), np.sin(th)])
    return np.array([r[0], r[1], th, v[0], v[1], w, t])


# ------------------------------------------------------------------ sliding bead
_BEAD = ("mass", "rate", "rate_amp", "rate_freq")


@cache.memoize
def _bead(tau) -> Model:
    x = ca.SX.sym("x", 5)
    p = ca.SX.sym("p", 4)
    m, w0, w1, nu = (p[i] for i in range(4))
    q, v, t = x[:2], x[2:4], x[4]
    M, Q = lagrange_terms(0.5 * m * (v[0] ** 2 + q[0] ** 2 * v[1] ** 2), 0, q, v)
    drive = w0 + w1 * ca.sin(nu * t)
    return constrained_model("sliding_bead", ("r", "phi"), ("m", "rad"), ("m/s", "rad/s"), q, v, t, p,
                  _BEAD, {"mass": "kg", "rate": "rad/s", "rate_amp": "rad/s",
                          "rate_freq": "rad/s"}, [1.0, 1.0, 0.0, 0.0], M, Q,
                  velocity=v[1] - drive, time_constant=tau,
                  extra=lambda lam: {"torque": -lam[0]})


def sliding_bead(*, mass=1.0, rate=1.0, rate_amp=0.0, rate_freq=0.0,
                 time_constant=DEFAULT_TIME_CONSTANT) -> Model:
    """A bead sliding without friction along a straight wire that turns in a horizontal plane
    about one end at the prescribed rate ``f(t) = rate + rate_amp sin(rate_freq t)``
    (Sec. 5.5 c, Eqs. 5.77-5.79).

    Polar coordinates ``(r, phi)``, ``T = 1/2 m (r'^2 + r^2 phi'^2)`` (the OCR of 5.77 drops
    the square of ``r``), the rheonomic constraint in velocity form ``phi' - f(t) = 0``
    (``B = [0, 1]``, ``c = -f'(t)``). Lagrange::

        m r'' - m r phi'^2 = 0,     m r^2 phi'' + 2 m r r' phi' + lam = 0

    and the reaction torque of the wire on the bead (the torque that drives the wire)::

        Q_phi^R = -lam = m r^2 f'(t) + 2 m r r' f(t)                    (5.79)

    (the second term the Coriolis torque). For constant ``f = w``:
    ``r = r0 cosh(w t) + (r0'/w) sinh(w t)`` (`bead_motion`).

    Parameters
    ----------
    mass : float [kg]
        ``> 0``.
    rate, rate_amp, rate_freq : float [rad/s]
        The prescribed rate law.
    time_constant : float or None [s]
        Baumgarte time constant of the velocity constraint; ``None``: none.

    Returns
    -------
    Model
        ``x = [r, phi, r_dot, phi_dot, t]``; invariants ``multipliers`` (``lam`` [N m]),
        ``torque`` (``-lam`` [N m]) and ``constraint_residual``.

    Raises
    ------
    ValueError
        Naming ``mass`` (not positive), a rate argument that is not finite, or
        ``time_constant``.

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import bead_torque, sliding_bead
    >>> model = sliding_bead(mass=2.0, rate=3.0)
    >>> x0 = [0.5, 0.0, 1.0, 3.0, 0.0]
    >>> round(float(model.invariant("torque", x0)), 12), bead_torque(0.5, 1.0, 3.0, 0.0, mass=2.0)
    (6.0, 6.0)
    """
    tau = stabilization(time_constant)
    vals = checked_constants(dict(mass=mass, rate=rate, rate_amp=rate_amp, rate_freq=rate_freq),
                    ("mass",))
    return with_parameters(_bead(tau), vals)


def bead_torque(r, r_dot, rate, rate_dot, *, mass=1.0):
    """Eq. 5.79: ``m r^2 f' + 2 m r r' f`` [N m] for the rate ``f`` and its derivative.

    Parameters
    ----------
    r, r_dot, rate, rate_dot : float or array_like [m, m/s, rad/s, rad/s^2]
        Element-wise (arrays broadcast).
    mass : float [kg]

    Returns
    -------
    numpy.ndarray or float

    Raises
    ------
    TypeError
        If an argument is not real numbers (a string, ``None``, a symbol).
    ValueError
        If an argument has a NaN or infinite entry (refused rather than propagated).

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import bead_torque
    >>> bead_torque(1.0, 0.0, 2.0, 0.5)
    0.5
    """
    r, rd = validate.finite_array(r, "r"), validate.finite_array(r_dot, "r_dot")
    f, fd = validate.finite_array(rate, "rate"), validate.finite_array(rate_dot, "rate_dot")
    mass = validate.finite_scalar(mass, "mass")
    out = mass * r ** 2 * fd + 2 * mass * r * rd * f
    return float(out) if out.ndim == 0 else out


def bead_motion(t, r0, r0_dot, rate):
    """``(r, r')`` of the bead on a wire turning at the constant ``rate``:
    ``r = r0 cosh(w t) + (r0'/w) sinh(w t)``.

    Parameters
    ----------
    t, r0, r0_dot : float or array_like [s, m, m/s]
        Element-wise (arrays broadcast).
    rate : float [rad/s]
        Nonzero.

    Returns
    -------
    r, r_dot : numpy.ndarray or float

    Raises
    ------
    TypeError
        If an argument is not real numbers (a string, ``None``, a symbol).
    ValueError
        If an argument has a NaN or infinite entry (refused rather than propagated), or
        ``rate`` is zero or not a scalar.

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import bead_motion
    >>> [round(float(a), 6) for a in bead_motion(1.0, 1.0, 0.0, 1.0)]
    [1.543081, 1.175201]
    """
    w = validate.finite_scalar(rate, "rate")
    if w == 0.0:
        raise ValueError(f"`rate` must be nonzero, got {rate!r}")
    t = validate.finite_array(t, "t")
    r0, r0_dot = validate.finite_array(r0, "r0"), validate.finite_array(r0_dot, "r0_dot")
    ch, sh = np.cosh(w * t), np.sinh(w * t)
    return r0 * ch + r0_dot / w * sh, r0 * w * sh + r0_dot * ch
