"""The physical pendulum whose hinge is shaken sinusoidally (seed 000, Example 6.9), built
with Euler's law about an arbitrary body point, and its closed forms: the natural frequency,
the Kapitza frequency that makes the inverted position stable and the first
parametric-resonance tongue of the hanging position (both from Mathieu's characteristic
values).

Plane of motion ``x`` (horizontal), ``y`` (vertically **up**); ``theta`` from the hanging
position, counter-clockwise. Hinge at ``r_h(t) = (amp_x, amp_y) sin(freq t)``; mass centre
at ``r_h + s`` with ``s = length (sin th, -cos th)``.
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from .. import cache, validate
from ..model import Model
from .common import GRAVITY, assemble, nonnegative, symbols, with_parameters

__all__ = ["shaken_pendulum", "natural_frequency", "equivalent_length", "kapitza_frequency",
           "resonance_tongue", "SHAKEN_DEFAULTS"]

_PARAMS = ("mass", "inertia", "length", "gravity", "amp_y", "amp_x", "freq", "damping")
_UNITS = {"mass": "kg", "inertia": "kg m^2", "length": "m", "gravity": "m/s^2", "amp_y": "m",
          "amp_x": "m", "freq": "rad/s", "damping": "N m s"}
#: default parameters: a uniform rod 0.5 m long of 1 kg hinged at one end (so
#: ``l_eff = 1/3`` m), shaken vertically by 2 cm at 200 rad/s (above the Kapitza frequency,
#: about 128 rad/s)
SHAKEN_DEFAULTS = {"mass": 1.0, "inertia": 1.0 / 48.0, "length": 0.25, "gravity": GRAVITY,
                   "amp_y": 0.02, "amp_x": 0.0, "freq": 200.0, "damping": 0.0}


@cache.memoize
def _shaken() -> Model:
    s = symbols(("theta",), _PARAMS, clock=True)
    m, inertia, l, g, amp_y, amp_x, freq, c = (s.par[k] for k in _PARAMS)
    th, w, t = s.q[0], s.qd[0], s.t
    shake = ca.sin(freq * t)
    a_h = -freq ** 2 * shake * ca.vertcat(amp_x, amp_y, 0)       # hinge acceleration
    s_vec = l * ca.vertcat(ca.sin(th), -ca.cos(th), 0)            # hinge -> mass centre
    g_vec = ca.vertcat(0, -g, 0)
    ez = ca.vertcat(0, 0, 1)
    inertia_hinge = inertia + m * l ** 2                          # parallel axes
    # Euler's law about the hinge (Eq. 6.45): I_h w' = m_h - m s x a_h
    moment_hinge = ca.cross(s_vec, m * g_vec) - c * w * ez
    qdd = ca.dot(moment_hinge - m * ca.cross(s_vec, a_h), ez) / inertia_hinge
    s_ddot = l * (qdd * ca.vertcat(ca.cos(th), ca.sin(th), 0)
                  - w ** 2 * ca.vertcat(ca.sin(th), -ca.cos(th), 0))
    hinge_force = m * (a_h + s_ddot - g_vec)                      # Newton: m a_c = R + m g
    return assemble(s, [qdd], name="shaken_pendulum", param_units=_UNITS,
                    p_default=[SHAKEN_DEFAULTS[k] for k in _PARAMS],
                    invariants={"hinge_force": hinge_force[:2]})


_D = SHAKEN_DEFAULTS


def shaken_pendulum(*, mass=_D["mass"], inertia=_D["inertia"], length=_D["length"],
                    gravity=_D["gravity"], amp_y=_D["amp_y"], amp_x=_D["amp_x"], freq=_D["freq"],
                    damping=_D["damping"]) -> Model:
    """Physical pendulum on a hinge shaken by ``(amp_x, amp_y) sin(freq t)`` (seed 000).

    Derivation by Euler's law about an arbitrary body point (seed 000, Eq. 6.45, after
    Grubin): about the hinge ``h``, a body point that is not the mass centre,
    ``D(I_h w) = m_h - m s x a_h`` with ``s`` from the hinge to the mass centre and ``a_h``
    the hinge's inertial acceleration. (Check: the moment about the mass centre is
    ``m_c = m_h - s x m a_c`` and ``a_c = a_h + s''`` with ``s x s'' = l^2 th'' e_z``; so
    ``I_c th'' = m_h - m s x a_h - m l^2 th''``, i.e. the law with ``I_h = I_c + m l^2``.)
    In the plane, with ``m_h = s x m g - c th' e_z`` (gravity and a viscous hinge) and
    ``a_h = -freq^2 sin(freq t) (amp_x, amp_y)``::

        I_h th'' = -m g l sin th + m l freq^2 sin(freq t) (amp_y sin th + amp_x cos th) - c th'

    The seed's case is the horizontal shake (``amp_x = A``):
    ``I th'' + m g l sin th = m l A w^2 sin(w t) cos th`` (its ``I`` is ``I_h``), reproduced
    here. The vertical shake (``amp_y``) multiplies gravity by ``1 - amp_y freq^2
    sin(freq t) / g``: a Mathieu equation about ``th = 0`` and ``th = pi``, both of which
    stay periodic orbits (see `kapitza_frequency`, `resonance_tongue`).

    Parameters
    ----------
    mass : float [kg]
        ``> 0``.
    inertia : float [kg m^2]
        Central moment about the hinge axis (the seed's ``I2``), ``>= 0``.
    length : float [m]
        Hinge to mass centre ``l``, ``> 0``.
    gravity : float [m/s^2]
        ``>= 0``.
    amp_y, amp_x : float [m]
        Vertical and horizontal shaking amplitudes.
    freq : float [rad/s]
        Shaking frequency ``Omega``.
    damping : float [N m s]
        Viscous hinge ``c``, ``>= 0``.

    Returns
    -------
    Model
        ``x = [theta, theta_dot, t]`` [rad, rad/s, s] with the clock ``t`` of
        `dynamics.clock` (start it at the first output time), no controls, the eight
        parameters above (defaults: the arguments; `SHAKEN_DEFAULTS`), and the monitored
        quantity ``hinge_force`` [N] (shape 2: the
        force of the hinge on the pendulum, ``m (a_c - g)``, inertial ``x, y``).

    Raises
    ------
    TypeError
        Naming a parameter that is not a real number.
    ValueError
        Naming the parameter out of range or not finite.

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import shaken_pendulum
    >>> model = shaken_pendulum(amp_y=0.0)
    >>> model.states, model.params[:4]
    (('theta', 'theta_dot', 't'), ('mass', 'inertia', 'length', 'gravity'))
    >>> round(float(model.rhs([0.5, 0.0, 0.0])[1]), 6)   # -g sin(0.5) / l_eff, l_eff = 1/3 m
    -14.104675
    """
    values = dict(mass=mass, inertia=inertia, length=length, gravity=gravity, amp_y=amp_y,
                  amp_x=amp_x, freq=freq, damping=damping)
    checked = {k: validate.finite_scalar(values[k], k) for k in _PARAMS}
    validate.positive(checked["mass"], "mass")
    validate.positive(checked["length"], "length")
    for key in ("inertia", "gravity", "damping"):
        nonnegative(checked[key], key)
    return with_parameters(_shaken(), checked)


def _constants(mass, inertia, length, gravity) -> tuple[float, float]:
    """``(w0, l_eff)``: natural frequency [rad/s] and equivalent simple-pendulum length [m]."""
    m, l = validate.positive(mass, "mass"), validate.positive(length, "length")
    inertia_hinge = nonnegative(inertia, "inertia") + m * l * l
    l_eff = inertia_hinge / (m * l)
    return float(np.sqrt(validate.positive(gravity, "gravity") / l_eff)), float(l_eff)


def _mathieu_q(amp_y, l_eff) -> float:
    """Mathieu's ``q = 2 amp_y / l_eff``, checked to lie where the closed forms hold."""
    q = 2.0 * validate.positive(amp_y, "amp_y") / l_eff
    if q >= 0.9:
        raise ValueError(f"`amp_y` must be below 0.45 l_eff = {0.45 * l_eff:g} m (Mathieu "
                         f"q = 2 amp_y / l_eff < 0.9), got {amp_y!r}")
    return q


def natural_frequency(*, mass=_D["mass"], inertia=_D["inertia"], length=_D["length"],
                      gravity=GRAVITY) -> float:
    """Small-oscillation frequency ``w0 = sqrt(m g l / I_h) = sqrt(g / l_eff)`` [rad/s].

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import natural_frequency
    >>> round(natural_frequency(gravity=3.0), 12)    # l_eff = 1/3 m
    3.0
    """
    return _constants(mass, inertia, length, gravity)[0]


def equivalent_length(*, mass=_D["mass"], inertia=_D["inertia"], length=_D["length"]) -> float:
    """``l_eff = I_h / (m l) = (I_c + m l^2) / (m l)`` [m]: the simple pendulum of the same
    frequency.

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import equivalent_length
    >>> round(equivalent_length(), 12)               # a rod hinged at its end: 2/3 of 0.5 m
    0.333333333333
    """
    return _constants(mass, inertia, length, 1.0)[1]


def kapitza_frequency(amp_y, *, mass=_D["mass"], inertia=_D["inertia"], length=_D["length"],
                      gravity=GRAVITY, exact=True) -> float:
    """Least vertical shaking frequency that makes the inverted pendulum stable [rad/s].

    About ``th = pi + u`` the undamped model is ``u'' + (-w0^2 + (amp_y freq^2 / l_eff)
    sin(freq t)) u = 0``. With ``tau = freq t / 2`` (and a shift of time) this is Mathieu's
    ``u'' + (a - 2 q cos 2 tau) u = 0`` with ``a = -4 w0^2 / freq^2``, ``q = 2 amp_y / l_eff``;
    it is stable between the characteristic curves ``a0(q)`` and ``b1(q)``. So

    * ``exact=True``: ``freq* = 2 w0 / sqrt(-a0(q))`` (``scipy.special.mathieu_a(0, q)``);
      stable for every ``freq > freq*`` while ``b1(q) > 0``, i.e. ``q < 0.908``;
    * ``exact=False``: Kapitza's averaging, ``a0 ~ -q^2 / 2``:
      ``amp_y^2 freq^2 > 2 g l_eff``, ``freq* = sqrt(2 g l_eff) / amp_y``: the ratio of the
      shaking term to the gravity term ``amp_y^2 freq^2 / (2 g l_eff)`` exceeds 1.

    Parameters
    ----------
    amp_y : float [m]
        Vertical amplitude, ``> 0``; ``q = 2 amp_y / l_eff < 0.9``.
    mass, inertia, length, gravity : float
        As for `shaken_pendulum`.
    exact : bool, optional

    Returns
    -------
    float [rad/s]

    Raises
    ------
    ValueError
        Naming ``amp_y`` (not positive, or ``q >= 0.9``) or another parameter out of range.

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import kapitza_frequency
    >>> round(kapitza_frequency(0.02, exact=False), 3), round(kapitza_frequency(0.02), 3)
    (127.845, 127.946)
    """
    w0, l_eff = _constants(mass, inertia, length, gravity)
    q = _mathieu_q(amp_y, l_eff)
    if not exact:
        return float(np.sqrt(2.0 * gravity * l_eff) / amp_y)
    from scipy.special import mathieu_a  # a heavy import, only here

    return float(2.0 * w0 / np.sqrt(-mathieu_a(0, q)))


def resonance_tongue(amp_y, *, mass=_D["mass"], inertia=_D["inertia"], length=_D["length"],
                     gravity=GRAVITY) -> tuple[float, float]:
    """Shaking frequencies bounding the first parametric-resonance tongue of the hanging
    position (undamped) [rad/s].

    About ``th = 0``: Mathieu's equation with ``a = 4 w0^2 / freq^2``, ``q = 2 amp_y / l_eff``
    (see `kapitza_frequency`); the first tongue ``b1(q) < a < a1(q)`` (multipliers real and
    negative, the response at half the shaking frequency) is
    ``2 w0 / sqrt(a1(q)) < freq < 2 w0 / sqrt(b1(q))``, around ``freq = 2 w0``; its width is
    ``~ q`` (``a1, b1 = 1 +- q - q^2/8 + ...``). With hinge damping the tongue only opens
    above an amplitude (``amp_y > c l_eff / (2 I_h w0)`` at ``freq = 2 w0``, to first order).

    Parameters
    ----------
    amp_y : float [m]
        ``> 0`` with ``q = 2 amp_y / l_eff < 0.9``.
    mass, inertia, length, gravity : float
        As for `shaken_pendulum`.

    Returns
    -------
    (float, float) [rad/s]
        Lower and upper edge.

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import natural_frequency, resonance_tongue
    >>> low, high = resonance_tongue(0.02)
    >>> bool(low < 2 * natural_frequency() < high), round(low, 4), round(high, 4)
    (True, 10.2588, 11.5757)
    """
    w0, l_eff = _constants(mass, inertia, length, gravity)
    q = _mathieu_q(amp_y, l_eff)
    from scipy.special import mathieu_a, mathieu_b  # a heavy import, only here

    return float(2.0 * w0 / np.sqrt(mathieu_a(1, q))), float(2.0 * w0 / np.sqrt(mathieu_b(1, q)))
