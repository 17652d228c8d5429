"""Plane pendulums of Rheinfurth & Wilson, NASA RP-1262, Sec. 5.4 (Lagrange's equations):
the double pendulum (example a, scleronomic) and the pendulum on a string of prescribed
length (example b, rheonomic, Eq. 5.51), with their closed forms.

Frame: ``x`` horizontal, ``y`` vertically *down* (the seed's Fig. 5.4), angles from the
downward vertical, potential energy zero at the pivot's level.
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from .. import cache, validate
from ..model import Model
from .common import GRAVITY, assemble, nonnegative, symbols, with_parameters

__all__ = ["double_pendulum", "double_pendulum_modes", "variable_length_pendulum",
           "pendulum_swing", "pendulum_period"]

_DOUBLE = ("mass1", "mass2", "length1", "length2", "gravity")
_STRING = ("mass", "gravity", "length", "length_rate", "length_amp", "length_freq")
_UNITS = {"mass1": "kg", "mass2": "kg", "mass": "kg", "length1": "m", "length2": "m",
          "length": "m", "gravity": "m/s^2", "length_rate": "m/s", "length_amp": "m",
          "length_freq": "rad/s"}


# ------------------------------------------------------------------ double pendulum
@cache.memoize
def _double_pendulum() -> Model:
    s = symbols(("theta1", "theta2"), _DOUBLE)
    m1, m2, l1, l2, g = (s.par[k] for k in _DOUBLE)
    (th1, th2), (w1, w2) = s.q, s.qd
    c, sn = ca.cos(th2 - th1), ca.sin(th2 - th1)
    m11, m12, m22 = (m1 + m2) * l1 ** 2, m2 * l1 * l2 * c, m2 * l2 ** 2
    r1 = m2 * l1 * l2 * sn * w2 ** 2 - (m1 + m2) * g * l1 * ca.sin(th1)
    r2 = -m2 * l1 * l2 * sn * w1 ** 2 - m2 * g * l2 * ca.sin(th2)
    det = m11 * m22 - m12 ** 2  # = m2 l1^2 l2^2 (m1 + m2 sin^2): > 0 for m1 > 0
    qdd = [(m22 * r1 - m12 * r2) / det, (m11 * r2 - m12 * r1) / det]
    kinetic = 0.5 * m11 * w1 ** 2 + m12 * w1 * w2 + 0.5 * m22 * w2 ** 2
    potential = -(m1 + m2) * g * l1 * ca.cos(th1) - m2 * g * l2 * ca.cos(th2)
    return assemble(s, qdd, name="double_pendulum", param_units=_UNITS, p_default=[1.0] * 5,
                    invariants={"energy": kinetic + potential})


def _double_args(mass1, mass2, length1, length2, gravity) -> dict:
    return {"mass1": validate.positive(mass1, "mass1"), "mass2": validate.positive(mass2, "mass2"),
            "length1": validate.positive(length1, "length1"),
            "length2": validate.positive(length2, "length2"),
            "gravity": nonnegative(gravity, "gravity")}


def double_pendulum(*, mass1=1.0, mass2=1.0, length1=1.0, length2=1.0,
                    gravity=GRAVITY) -> Model:
    """Double pendulum of two point masses on massless rods in a vertical plane (Sec. 5.4 a).

    Derivation (Lagrange, Eq. 5.44). Mass 1 at ``(l1 sin th1, l1 cos th1)``, mass 2 at
    ``(l1 sin th1 + l2 sin th2, l1 cos th1 + l2 cos th2)`` (``y`` down; the OCR's
    ``x2 = l2 sin th1 + ...`` is a misprint for ``l1 sin th1``)::

        T = 1/2 (m1 + m2) l1^2 th1'^2 + 1/2 m2 l2^2 th2'^2 + m2 l1 l2 th1' th2' cos(th2 - th1)
        V = -(m1 + m2) g l1 cos th1 - m2 g l2 cos th2
        (m1 + m2) l1^2 th1'' + m2 l1 l2 cos(th2 - th1) th2''
            - m2 l1 l2 sin(th2 - th1) th2'^2 + (m1 + m2) g l1 sin th1 = 0
        m2 l2^2 th2'' + m2 l1 l2 cos(th2 - th1) th1''
            + m2 l1 l2 sin(th2 - th1) th1'^2 + m2 g l2 sin th2 = 0

    (the seed's equations, confirmed term by term; the ``th1' th2'`` terms of
    ``d/dt dT/dth'`` and ``dT/dth`` cancel). The 2x2 mass matrix is inverted in closed form.

    Parameters
    ----------
    mass1, mass2 : float [kg]
        Point masses, ``> 0``.
    length1, length2 : float [m]
        Rod lengths, ``> 0``.
    gravity : float [m/s^2]
        ``>= 0``.

    Returns
    -------
    Model
        ``x = [theta1, theta2, theta1_dot, theta2_dot]`` [rad, rad/s] (angles of the rods from
        the downward vertical), no controls, parameters ``(mass1, mass2, length1, length2,
        gravity)`` defaulting to the arguments, invariant ``energy`` [J] (``T + V``).

    Raises
    ------
    ValueError
        Naming the argument that is not finite or not positive (``gravity``: negative).

    See Also
    --------
    double_pendulum_modes : the small-oscillation frequencies.

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import double_pendulum
    >>> model = double_pendulum(mass2=2.0)
    >>> model.states
    ('theta1', 'theta2', 'theta1_dot', 'theta2_dot')
    >>> round(float(model.invariant("energy", [0.0, 0.0, 0.0, 0.0])), 3)  # -(m1 + 2 m2) g l
    -49.033
    """
    args = _double_args(mass1, mass2, length1, length2, gravity)
    return with_parameters(_double_pendulum(), args)


def double_pendulum_modes(*, mass1=1.0, mass2=1.0, length1=1.0, length2=1.0,
                          gravity=GRAVITY) -> np.ndarray:
    """Small-oscillation (normal-mode) frequencies of the double pendulum.

    Linearized about the hanging position, ``M q'' + K q = 0`` with
    ``M = [[(m1 + m2) l1^2, m2 l1 l2], [m2 l1 l2, m2 l2^2]]``,
    ``K = diag((m1 + m2) g l1, m2 g l2)``; ``det(K - w^2 M) = 0`` divided by ``m2 l1 l2``:
    ``m1 l1 l2 w^4 - (m1 + m2) g (l1 + l2) w^2 + (m1 + m2) g^2 = 0``, so::

        w^2 = g (m1 + m2) / (2 m1 l1 l2) * [l1 + l2 -+ sqrt((l1 + l2)^2 - 4 m1 l1 l2 / (m1 + m2))]

    (equal masses and lengths: ``w^2 = (2 -+ sqrt 2) g / l``).

    Parameters
    ----------
    mass1, mass2, length1, length2, gravity : float
        As for `double_pendulum` [kg, kg, m, m, m/s^2].

    Returns
    -------
    numpy.ndarray, shape (2,) [rad/s]
        The two frequencies, slow (in-phase) mode first.

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import double_pendulum_modes
    >>> double_pendulum_modes(gravity=1.0).round(6)   # sqrt(2 -+ sqrt 2)
    array([0.765367, 1.847759])
    """
    a = _double_args(mass1, mass2, length1, length2, gravity)
    m1, m2, l1, l2, g = (a[k] for k in _DOUBLE)
    root = np.sqrt((l1 + l2) ** 2 - 4 * m1 * l1 * l2 / (m1 + m2))
    w2 = g * (m1 + m2) / (2 * m1 * l1 * l2) * (l1 + l2 + np.array([-root, root]))
    return np.sqrt(w2)


# -------------------------------------------------------- pendulum on a moving string
@cache.memoize
def _variable_length_pendulum() -> Model:
    s = symbols(("theta",), _STRING, clock=True)
    m, g, l0, rate, amp, freq = (s.par[k] for k in _STRING)
    th, w, t = s.q[0], s.qd[0], s.t
    length = l0 + rate * t + amp * ca.sin(freq * t)
    ldot = rate + amp * freq * ca.cos(freq * t)
    lddot = -amp * freq ** 2 * ca.sin(freq * t)
    qdd = -(2 * ldot * w + g * ca.sin(th)) / length                          # Eq. 5.51
    tension = m * (g * ca.cos(th) + length * w ** 2 - lddot)
    energy = 0.5 * m * (ldot ** 2 + length ** 2 * w ** 2) - m * g * length * ca.cos(th)
    return assemble(s, [qdd], name="variable_length_pendulum", param_units=_UNITS,
                    p_default=[1.0, GRAVITY, 1.0, 0.0, 0.0, 0.0],
                    invariants={"energy": energy, "momentum": m * length ** 2 * w,
                                "tension": tension, "string_power": -tension * ldot,
                                "length": length})


def variable_length_pendulum(*, mass=1.0, gravity=GRAVITY, length=1.0, length_rate=0.0,
                             length_amp=0.0, length_freq=0.0) -> Model:
    """Pendulum on a string whose free length is prescribed, ``l(t)`` (Sec. 5.4 b, Eq. 5.51).

    The length law is ``l(t) = length + length_rate t + length_amp sin(length_freq t)``,
    read from the clock state ``t`` (`dynamics.clock`): constant, reeled at a constant rate,
    or pumped periodically. It must stay positive over the run (not checked by the model;
    the ``length`` invariant shows it).

    Derivation. The mass at ``l (sin th, cos th)`` (``y`` down) with ``l = l(t)`` given:
    ``T = 1/2 m (l'^2 + l^2 th'^2)``, ``V = -m g l cos th``; Lagrange's equation in the one
    coordinate ``th`` (Eq. 5.44) gives Eq. 5.51 of the seed::

        m l^2 th'' + 2 m l l' th' + m g l sin th = 0

    which is also the angular-momentum law about the pivot,
    ``d/dt (m l^2 th') = -m g l sin th`` (the string force is central). The radial Newton
    equation ``m (l'' - l th'^2) = m g cos th - S`` gives the string tension
    ``S = m (g cos th + l th'^2 - l'')``, and the mechanical energy
    ``E = 1/2 m (l'^2 + l^2 th'^2) - m g l cos th`` changes by the work of the string:
    ``E' = -S l'`` (differentiate ``E`` and substitute Eq. 5.51: the ``sin th`` terms cancel
    and ``m l' l'' - m l l' th'^2 - m g l' cos th`` remains). Reeling in (``l' < 0``) pumps
    energy in -- the seed's "negative damping" of Eq. 5.52.

    Parameters
    ----------
    mass : float [kg]
        ``> 0`` (it only scales the invariants).
    gravity : float [m/s^2]
        ``>= 0``.
    length : float [m]
        Length at ``t = 0``, ``> 0``.
    length_rate : float [m/s]
    length_amp : float [m]
    length_freq : float [rad/s]

    Returns
    -------
    Model
        ``x = [theta, theta_dot, t]`` [rad, rad/s, s], no controls, the six parameters above
        (defaults: the arguments), invariants ``energy`` [J], ``momentum`` [kg m^2/s]
        (``m l^2 th'`` about the pivot), ``tension`` [N], ``string_power`` [W] (``-S l'``,
        the rate of ``energy``) and ``length`` [m].

    Raises
    ------
    ValueError
        Naming the argument: ``mass`` or ``length`` not positive, ``gravity`` negative,
        anything not finite.

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import variable_length_pendulum
    >>> model = variable_length_pendulum(length=2.0, length_rate=-0.1)
    >>> model.states
    ('theta', 'theta_dot', 't')
    >>> x = [0.0, 1.0, 0.0]      # at the bottom, swinging at 1 rad/s, being reeled in
    >>> model.rhs(x).round(6).tolist()   # th'' = -2 l' th' / l
    [1.0, 0.1, 1.0]
    >>> round(float(model.invariant("string_power", x)), 6)   # -S l' = m (g + l th'^2) 0.1
    1.180665
    """
    args = {"mass": validate.positive(mass, "mass"), "gravity": nonnegative(gravity, "gravity"),
            "length": validate.positive(length, "length"),
            "length_rate": validate.finite_scalar(length_rate, "length_rate"),
            "length_amp": validate.finite_scalar(length_amp, "length_amp"),
            "length_freq": validate.finite_scalar(length_freq, "length_freq")}
    return with_parameters(_variable_length_pendulum(), args)


# ------------------------------------------------------------ simple pendulum (l const)
def pendulum_swing(t, theta0, *, length=1.0, gravity=GRAVITY) -> np.ndarray:
    """Exact angle of a simple pendulum released from rest at ``theta0`` (constant length).

    ``th'' = -(g/l) sin th`` from ``th(0) = theta0``, ``th'(0) = 0``:
    ``sin(th/2) = k cd(w0 t | k^2)`` with ``k = sin(theta0/2)``, ``w0 = sqrt(g/l)``,
    ``cd = cn/dn`` (Jacobi elliptic functions; ``cd(u) = sn(K - u)``).

    Parameters
    ----------
    t : float or array_like, shape (n,) [s]
    theta0 : float [rad]
        Release angle, ``|theta0| < pi``.
    length : float [m]
        ``> 0``.
    gravity : float [m/s^2]
        ``> 0``.

    Returns
    -------
    numpy.ndarray, shape of ``t`` [rad]

    Raises
    ------
    ValueError
        Naming ``t`` (not finite, or not a scalar or 1-D array), ``theta0`` (not finite,
        ``|theta0| >= pi``), ``length`` or ``gravity``.
    TypeError
        If an argument is not real numbers (a string, ``None``, ...).

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.mechanisms import pendulum_period, pendulum_swing
    >>> T = pendulum_period(2.0, length=1.0, gravity=9.81)
    >>> np.round(pendulum_swing([0.0, T / 4, T / 2], 2.0, length=1.0, gravity=9.81), 12) + 0.0
    array([ 2.,  0., -2.])
    """
    t = validate.finite_array(t, "t")
    if t.ndim > 1:
        raise ValueError(f"`t` must be a scalar or have shape (n,), got {t.shape}")
    k, w0 = _swing_constants(theta0, length, gravity)
    from scipy.special import ellipj  # a heavy import, only here

    sn, cn, dn, _ = ellipj(w0 * t, k * k)
    return 2.0 * np.arcsin(np.clip(k * cn / dn, -1.0, 1.0))


def pendulum_period(theta0, *, length=1.0, gravity=GRAVITY) -> float:
    """Exact period ``4 K(k^2) / w0`` [s] of a simple pendulum of amplitude ``theta0``.

    Parameters and errors as for `pendulum_swing`.

    Examples
    --------
    >>> import math
    >>> from appdyn.dynamics.mechanisms import pendulum_period
    >>> round(pendulum_period(1e-8, length=1.0, gravity=1.0) / (2 * math.pi), 12)
    1.0
    """
    k, w0 = _swing_constants(theta0, length, gravity)
    from scipy.special import ellipk  # a heavy import, only here

    return float(4.0 * ellipk(k * k) / w0)


def _swing_constants(theta0, length, gravity) -> tuple[float, float]:
    theta0 = validate.finite_scalar(theta0, "theta0")
    if not abs(theta0) < np.pi:
        raise ValueError(f"`theta0` must satisfy |theta0| < pi [rad], got {theta0!r}")
    w0 = np.sqrt(validate.positive(gravity, "gravity") / validate.positive(length, "length"))
    return float(np.sin(theta0 / 2)), float(w0)
