"""A particle in a noninertial frame (Rheinfurth & Wilson, NASA RP-1262, Sec. 2.2, Eq. 2.1;
seed 000 Eq. 6.42) and the seed's examples of Sec. 2.4.

In a frame whose origin accelerates at ``R0''`` and which turns at ``w(t)`` (both given in
the frame's axes), Newton's law for the relative motion ``r, v = r'`` (derivatives taken in
the frame) is Eq. 2.1 re-derived from Eq. 1.4::

    m a = F + A + E + C + K,    A = -m R0''                  (d'Alembert force)
                                E = -m w' x r                (Euler force)
                                C = -m w x (w x r)           (centrifugal force)
                                K = -2 m w x v               (Coriolis force)

(``w'`` is the rate of change of ``w``; it has the same components in either frame.)

The examples: the particle on a frictionless turntable (`turntable`, Example 2: an
Archimedean spiral, `turntable_path`), the Foucault pendulum (`foucault_pendulum`, Example 4:
precession at ``Omega sin(latitude)``), the accelerometer in a rocket (`accelerometer`,
Example 1: gravity cancels) and the twirling skater (`twirling_skater`, Example 6: ``w r^2``
conserved, the work against the centrifugal force is the kinetic energy gained).
"""
from __future__ import annotations

from typing import Callable

import casadi as ca
import numpy as np

from .. import validate
from ..clock import CLOCK_STATE, CLOCK_UNIT
from ..model import Model, model_from_expressions
from .common import GRAVITY, nonnegative

__all__ = ["noninertial_particle", "turntable", "turntable_path", "foucault_pendulum",
           "foucault_precession_rate", "foucault_swing", "accelerometer",
           "accelerometer_offset", "twirling_skater", "skater_rate", "skater_work",
           "EARTH_RATE"]

#: Earth's sidereal rotation rate [rad/s]
EARTH_RATE = 7.2921159e-5

_NAMES = ("x", "y", "z", "vx", "vy", "vz")
_UNITS = {"x": "m", "y": "m", "z": "m", "vx": "m/s", "vy": "m/s", "vz": "m/s"}


def _of_time(value, t: ca.SX, name: str) -> ca.SX:
    """A 3-vector of time: constants, or a callable ``t -> expression`` (a casadi.Function)."""
    if callable(value):
        try:
            out = value(t)
            out = ca.vec(ca.vertcat(*out) if isinstance(out, (list, tuple)) else ca.SX(out))
        except Exception as exc:  # a user callable: say which argument failed
            raise validate.ArgumentTypeError(
                f"`{name}` must be 3 numbers or a callable t -> 3-vector of casadi "
                f"expressions; calling it with a casadi symbol failed: {exc}") from exc
        if out.numel() != 3:
            raise ValueError(f"`{name}` must give 3 components, got {out.numel()}")
        return out
    return ca.SX(ca.DM(validate.finite_array(value, name, (3,))))


def noninertial_particle(*, mass=1.0, rate=(0.0, 0.0, 0.0), rate_dot=None,
                         origin_acceleration=(0.0, 0.0, 0.0),
                         force: Callable | None = None, name: str = "noninertial_particle"
                         ) -> Model:
    """A particle moving in a frame with prescribed motion (seed Eq. 2.1).

    Parameters
    ----------
    mass : float [kg]
        ``> 0``.
    rate : array_like, shape (3,), or callable [rad/s]
        The frame's angular velocity ``w`` (frame axes): constants, or ``t -> w(t)``
        returning CasADi expressions of the time symbol (``lambda t: [0, 0, 0.1 * t]``).
    rate_dot : array_like, shape (3,), or callable, optional [rad/s^2]
        ``w'``; by default the derivative of ``rate`` (zero for constants).
    origin_acceleration : array_like, shape (3,), or callable [m/s^2]
        Inertial acceleration of the frame's origin ``R0''`` in frame axes.
    force : callable, optional
        ``(r, v, t) -> F`` [N]: the applied force in frame axes from the relative position
        ``r`` [m], relative velocity ``v`` [m/s] (3x1 casadi.SX) and the time ``t`` [s].
    name : str, optional

    Returns
    -------
    Model
        ``x = [x, y, z, vx, vy, vz]`` (relative position [m] and velocity [m/s], frame
        axes) and the clock ``t`` last when anything depends on time; no controls or
        parameters; invariants (each 3 [N], seed Eq. 2.2) ``dalembert_force``
        ``-m R0''``, ``euler_force`` ``-m w' x r``, ``centrifugal_force``
        ``-m w x (w x r)``, ``coriolis_force`` ``-2 m w x v``.

    Raises
    ------
    ValueError
        Naming the argument: a non-positive ``mass``, a vector not of 3 finite numbers.
    TypeError
        If ``force`` is not callable, or a callable argument does not take a casadi symbol.

    Examples
    --------
    At rest on a turntable at 2 rad/s, 0.5 m from the axis: the centrifugal force
    ``m w^2 r`` pushes it out:

    >>> from appdyn.dynamics.mechanisms import noninertial_particle
    >>> model = noninertial_particle(mass=3.0, rate=[0.0, 0.0, 2.0])
    >>> model.states
    ('x', 'y', 'z', 'vx', 'vy', 'vz')
    >>> model.rhs([0.5, 0.0, 0.0, 0.0, 0.0, 0.0]).tolist()
    [0.0, 0.0, 0.0, 2.0, 0.0, 0.0]
    >>> model.invariant("centrifugal_force", [0.5, 0, 0, 0, 0, 0]).ravel().tolist()
    [6.0, 0.0, 0.0]

    A frame spun up at ``w = 0.1 t``: the Euler force needs the clock:

    >>> model = noninertial_particle(rate=lambda t: [0.0, 0.0, 0.1 * t])
    >>> model.states[-1], model.rhs([1.0, 0, 0, 0, 0, 0, 0.0]).round(3).tolist()
    ('t', [0.0, 0.0, 0.0, 0.0, -0.1, 0.0, 1.0])
    """
    m = validate.positive(mass, "mass")
    if force is not None and not callable(force):
        raise validate.ArgumentTypeError(f"`force` must be a callable (r, v, t) -> 3-vector, "
                                         f"got {type(force).__name__}")
    x = ca.SX.sym("x", 6)
    t = ca.SX.sym(CLOCK_STATE)
    r, v = x[0:3], x[3:6]
    w = _of_time(rate, t, "rate")
    wd = ca.jacobian(w, t) if rate_dot is None else _of_time(rate_dot, t, "rate_dot")
    a0 = _of_time(origin_acceleration, t, "origin_acceleration")
    F = ca.SX.zeros(3) if force is None else _of_time(lambda tt: force(r, v, tt), t, "force")
    inertial = {"dalembert_force": -m * a0, "euler_force": -m * ca.cross(wd, r),
                "centrifugal_force": -m * ca.cross(w, ca.cross(w, r)),
                "coriolis_force": -2 * m * ca.cross(w, v)}
    acc = (F + sum(inertial.values(), ca.SX.zeros(3))) / m
    clock = bool(ca.depends_on(ca.vertcat(acc, *inertial.values()), t))
    states = [(n, x[i]) for i, n in enumerate(_NAMES)] + ([(CLOCK_STATE, t)] if clock else [])
    xdot = ca.vertsplit(v) + ca.vertsplit(acc) + ([1.0] if clock else [])
    return model_from_expressions(states, xdot, units={**_UNITS, CLOCK_STATE: CLOCK_UNIT},
                                  invariants=inertial, name=name)


# ------------------------------------------------------------------ Example 2: turntable
def turntable(rate=1.0, *, mass=1.0) -> Model:
    """A particle sliding freely on a turntable turning at ``rate`` (seed Sec. 2.4, Ex. 2).

    In the turntable's axes (``z`` up the axis) only the centrifugal and Coriolis forces
    act: ``x'' = 2 w y' + w^2 x``, ``y'' = -2 w x' + w^2 y``.

    Parameters
    ----------
    rate : float [rad/s]
        Turntable rate ``w`` about ``z`` (counterclockwise positive).
    mass : float [kg]

    Returns
    -------
    Model
        `noninertial_particle` with ``rate = (0, 0, w)``.

    See Also
    --------
    turntable_path : the closed form.

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import turntable
    >>> turntable(2.0).rhs([0.0, 0.0, 0.0, 1.0, 0.0, 0.0]).tolist()  # Coriolis: -2 w x'
    [1.0, 0.0, 0.0, 0.0, -4.0, 0.0]
    """
    w = validate.finite_scalar(rate, "rate")
    return noninertial_particle(mass=mass, rate=(0.0, 0.0, w), name="turntable")


def turntable_path(t, *, rate=1.0, speed=1.0):
    """The seed's closed form: from the centre at ``speed`` along ``x``, an Archimedean spiral.

    ``z = x + i y = v0 t exp(-i w t)`` (repeated root ``s = -i w``): ``r = v0 t``, the polar
    angle ``-w t``, so ``r = -(v0 / w) phi``. (In inertial space the particle moves on a
    straight line; the spiral is what the turntable sees.)

    Parameters
    ----------
    t : array_like [s]
    rate : float [rad/s]
    speed : float [m/s]
        ``v0``, the initial relative velocity along ``x``.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        ``x, y`` [m] in the turntable's axes.

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import turntable_path
    >>> x, y = turntable_path([0.0, 1.0], rate=0.5 * 3.141592653589793, speed=2.0)
    >>> x.round(12).tolist(), y.round(12).tolist()
    ([0.0, 0.0], [0.0, -2.0])
    """
    t = validate.finite_array(t, "t")
    w = validate.finite_scalar(rate, "rate")
    v0 = validate.finite_scalar(speed, "speed")
    z = v0 * t * np.exp(-1j * w * t)
    return z.real, z.imag


# ------------------------------------------------------------------ Example 4: Foucault
def foucault_precession_rate(latitude, *, earth_rate=EARTH_RATE) -> float:
    """Precession rate of the Foucault pendulum's swing plane, ``u = Omega sin(latitude)``.

    Clockwise seen from above in the northern hemisphere (seed Sec. 2.4, Ex. 4).

    Parameters
    ----------
    latitude : float [rad]
    earth_rate : float [rad/s]

    Returns
    -------
    float [rad/s]

    Examples
    --------
    >>> import math
    >>> from appdyn.dynamics.mechanisms import foucault_precession_rate
    >>> round(2 * math.pi / foucault_precession_rate(math.radians(48.85)) / 3600, 2)  # Paris
    31.79
    """
    return validate.finite_scalar(earth_rate, "earth_rate") * float(np.sin(
        validate.finite_scalar(latitude, "latitude")))


def foucault_pendulum(*, length=67.0, latitude=np.radians(48.85), earth_rate=EARTH_RATE,
                      gravity=GRAVITY, mass=1.0) -> Model:
    """The seed's Foucault pendulum: the bob's small horizontal motion on the turning Earth.

    Local axes ``x`` east, ``y`` north, ``z`` up; only the vertical component
    ``u = Omega sin(latitude)`` of the Earth's rate turns the horizontal plane (the seed's
    model, Ex. 4), and the string's tension is ``-m g r / l`` for small swings::

        x'' = 2 u y' + u^2 x - g x / l,     y'' = -2 u x' + u^2 y - g y / l

    so ``z'' + 2 i u z' + (g / l - u^2) z = 0``: ``s = i (-u -+ sqrt(g / l))``.

    Parameters
    ----------
    length : float [m]
        ``> 0``.
    latitude : float [rad]
    earth_rate : float [rad/s]
    gravity : float [m/s^2]
        ``> 0``.
    mass : float [kg]

    Returns
    -------
    Model
        `noninertial_particle` with ``rate = (0, 0, u)`` and the tension force (``z`` stays
        0 from a horizontal start).

    See Also
    --------
    foucault_swing : the closed form; foucault_precession_rate.

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import foucault_pendulum
    >>> m = foucault_pendulum(length=9.80665, latitude=0.0)   # equator: no precession
    >>> (m.rhs([1.0, 0.0, 0.0, 0.0, 0.0, 0.0]) + 0.0).tolist()
    [0.0, 0.0, 0.0, -1.0, 0.0, 0.0]
    """
    l = validate.positive(length, "length")
    g = validate.positive(gravity, "gravity")
    m = validate.positive(mass, "mass")
    u = foucault_precession_rate(latitude, earth_rate=earth_rate)
    return noninertial_particle(mass=m, rate=(0.0, 0.0, u), name="foucault_pendulum",
                                force=lambda r, v, t: -m * g / l * ca.vertcat(r[0], r[1], 0))


def foucault_swing(t, *, amplitude=1.0, length=67.0, latitude=np.radians(48.85),
                   earth_rate=EARTH_RATE, gravity=GRAVITY):
    """The closed-form swing of `foucault_pendulum` released at rest at ``x = amplitude``.

    ``z = a exp(-i u t) (cos p t + i (u / p) sin p t)``, ``p = sqrt(g / l)``: a swing at
    ``p`` whose plane turns at ``-u`` (from ``z(0) = a``, ``z'(0) = 0`` in the general
    solution ``(A1 e^{i p t} + A2 e^{-i p t}) e^{-i u t}``).

    Parameters
    ----------
    t : array_like [s]
    amplitude : float [m]
    length, latitude, earth_rate, gravity
        As `foucault_pendulum`.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        ``x, y`` [m] (east, north).

    Examples
    --------
    >>> import math
    >>> from appdyn.dynamics.mechanisms import foucault_swing
    >>> x, y = foucault_swing([0.0], amplitude=0.5)
    >>> float(x[0]), float(y[0])
    (0.5, 0.0)
    """
    t = validate.finite_array(t, "t")
    u = foucault_precession_rate(latitude, earth_rate=earth_rate)
    p = np.sqrt(validate.positive(gravity, "gravity") / validate.positive(length, "length"))
    a = validate.finite_scalar(amplitude, "amplitude")
    z = a * np.exp(-1j * u * t) * (np.cos(p * t) + 1j * (u / p) * np.sin(p * t))
    return z.real, z.imag


# ------------------------------------------------------------------ Example 1: accelerometer
def accelerometer(*, mass=0.01, stiffness=100.0, damping=0.0, specific_force=(0.0, 0.0, 0.0),
                  gravity=(0.0, 0.0, -GRAVITY), rate=(0.0, 0.0, 0.0), neutral=(0.0, 0.0, 0.0)
                  ) -> Model:
    """A spring-mass accelerometer in a rocket (seed Sec. 2.4, Ex. 1).

    The frame is fixed in the rocket with its origin at the rocket's mass centre, which
    accelerates at ``R0'' = g + f`` (``f = (F_A + F_r) / M``, the specific force); the proof
    mass hangs on a spring of stiffness ``k`` (and a dashpot ``c``) anchored so that it rests
    at ``neutral``::

        m a = -k (R - neutral) - c v + m g - m [R0'' + w x (w x R) + w' x R + 2 w x v]

    and ``m g`` cancels against the ``m g`` in ``m R0''``: the instrument reads ``f`` only.

    Parameters
    ----------
    mass, stiffness : float [kg], [N/m]
        ``> 0``.
    damping : float [N s/m]
        ``>= 0``.
    specific_force, gravity : array_like, shape (3,) [m/s^2]
        Rocket axes.
    rate : array_like, shape (3,) [rad/s]
        The rocket's (constant) angular velocity.
    neutral : array_like, shape (3,) [m]
        The spring's rest position from the rocket's mass centre.

    Returns
    -------
    Model
        `noninertial_particle` (no clock).

    See Also
    --------
    accelerometer_offset : the steady deflection.

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import accelerometer
    >>> m = accelerometer(specific_force=[20.0, 0.0, 0.0], gravity=[0.0, 0.0, -9.8])
    >>> (m.rhs([0.0, 0, 0, 0, 0, 0]) + 0.0).tolist()      # gravity cancels: only -f
    [0.0, 0.0, 0.0, -20.0, 0.0, 0.0]
    """
    m = validate.positive(mass, "mass")
    k = validate.positive(stiffness, "stiffness")
    c = nonnegative(damping, "damping")
    f = validate.finite_array(specific_force, "specific_force", (3,))
    g = validate.finite_array(gravity, "gravity", (3,))
    b = ca.DM(validate.finite_array(neutral, "neutral", (3,)))
    return noninertial_particle(mass=m, rate=rate, origin_acceleration=g + f,
                                force=lambda r, v, t: -k * (r - b) - c * v + m * ca.DM(g),
                                name="accelerometer")


def accelerometer_offset(*, mass=0.01, stiffness=100.0, specific_force=(0.0, 0.0, 0.0),
                         rate=(0.0, 0.0, 0.0), neutral=(0.0, 0.0, 0.0)) -> np.ndarray:
    """Steady deflection of `accelerometer`'s proof mass from its neutral point [m].

    At rest in the rocket, ``k (R - b) = -m f - m w x (w x R)``: with ``w = 0`` the
    deflection is ``-m f / k`` whatever the gravity (the seed's "gravity cancels"); a
    spinning rocket adds the centrifugal term, ``(k - m w^2) d = m w^2 b - m f`` along an
    axis normal to ``w``.

    Parameters
    ----------
    mass, stiffness, specific_force, rate, neutral
        As `accelerometer`.

    Returns
    -------
    numpy.ndarray, shape (3,) [m]
        ``R - neutral``.

    Raises
    ------
    ValueError
        If the spin reaches the spring's own frequency (``m |w|^2 >= k``: no steady rest).

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import accelerometer_offset
    >>> d = accelerometer_offset(mass=0.01, stiffness=100.0, specific_force=[20.0, 0, 0])
    >>> (d + 0.0).tolist()
    [-0.002, 0.0, 0.0]
    """
    m, k = validate.positive(mass, "mass"), validate.positive(stiffness, "stiffness")
    f = validate.finite_array(specific_force, "specific_force", (3,))
    w = validate.finite_array(rate, "rate", (3,))
    b = validate.finite_array(neutral, "neutral", (3,))
    if m * float(w @ w) >= k:
        raise ValueError(f"`rate`: m |w|^2 = {m * float(w @ w):g} N/m reaches the stiffness "
                         f"{k:g} N/m; the proof mass has no steady rest (spin slower or "
                         f"stiffen the spring)")
    W = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
    R = np.linalg.solve(k * np.eye(3) + m * W @ W, k * b - m * f)
    return R - b


# ------------------------------------------------------------------ Example 6: skater
def skater_rate(t, *, rate0=1.0, radius0=1.0, pull_speed=0.1):
    """Angular rate of the twirling skater's particle pulled in at constant speed [rad/s].

    The tangential equation ``m w' r + 2 m w r' = 0`` integrates to ``w r^2 = w0 r0^2``
    (angular momentum), with ``r = r0 - c t``.

    Parameters
    ----------
    t : array_like [s]
        Before ``r0 / c``.
    rate0 : float [rad/s]
    radius0 : float [m]
        ``> 0``.
    pull_speed : float [m/s]
        ``c``.

    Returns
    -------
    numpy.ndarray or casadi.SX
        ``w0 r0^2 / (r0 - c t)^2`` (symbolic for a CasADi ``t``).

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import skater_rate
    >>> float(skater_rate(5.0, rate0=2.0, radius0=1.0, pull_speed=0.1))  # half the radius
    8.0
    """
    w0 = validate.finite_scalar(rate0, "rate0")
    r0 = validate.positive(radius0, "radius0")
    c = validate.finite_scalar(pull_speed, "pull_speed")
    t = t if validate.is_symbolic(t) else validate.finite_array(t, "t")
    return w0 * r0 ** 2 / (r0 - c * t) ** 2


def skater_work(radius, *, mass=1.0, rate0=1.0, radius0=1.0) -> float:
    """Work done pulling the skater's particle in to ``radius`` against the centrifugal force.

    ``W = 1/2 m (w0 r0^2)^2 (1 / r^2 - 1 / r0^2)``: the gain of kinetic energy (seed
    Ex. 6, Q.E.D.).

    Parameters
    ----------
    radius : float [m]
    mass, rate0, radius0
        [kg], [rad/s], [m].

    Returns
    -------
    float [J]

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import skater_work
    >>> skater_work(0.5, mass=2.0, rate0=1.0, radius0=1.0)
    3.0
    """
    r = validate.positive(radius, "radius")
    r0 = validate.positive(radius0, "radius0")
    h = validate.finite_scalar(rate0, "rate0") * r0 ** 2
    return 0.5 * validate.positive(mass, "mass") * h ** 2 * (1 / r ** 2 - 1 / r0 ** 2)


def twirling_skater(*, mass=1.0, rate0=1.0, radius0=1.0, pull_speed=0.1) -> Model:
    """The twirling skater in the frame that turns with the string (seed Sec. 2.4, Ex. 6).

    The frame turns at the particle's own rate ``w(t) = w0 r0^2 / r(t)^2`` (`skater_rate`,
    so ``w'`` is not zero: the Euler force acts) and the string pulls with the tension
    ``m w^2 r`` that holds the relative radial acceleration at zero. Released at
    ``(r0, 0, 0)`` with relative velocity ``(-c, 0, 0)``, the particle moves in along the
    string at ``c``: the Euler and Coriolis forces cancel (``w' r + 2 w r' = 0``).

    Parameters
    ----------
    mass : float [kg]
    rate0 : float [rad/s]
    radius0 : float [m]
    pull_speed : float [m/s]
        ``c``; the model holds until ``t = r0 / c``.

    Returns
    -------
    Model
        `noninertial_particle` with the clock ``t``.

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import twirling_skater
    >>> (twirling_skater(radius0=2.0).rhs([2.0, 0, 0, -0.1, 0, 0, 0.0]).round(12) + 0.0).tolist()
    [-0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]
    """
    m = validate.positive(mass, "mass")

    def w(t):
        return ca.vertcat(0, 0, skater_rate(t, rate0=rate0, radius0=radius0,
                                            pull_speed=pull_speed))

    return noninertial_particle(mass=m, rate=w, name="twirling_skater",
                                force=lambda r, v, t: -m * w(t)[2] ** 2 * r)
