"""The spherical pendulum of Rheinfurth & Wilson, NASA RP-1262, Ch. 6 Example 1, in its two
formulations: classical 3-1-3 Euler angles (near-singular at the bottom when
``I << m l^2``) and modern 3-2-1 angles (regular there).

The pendulum, as the seed has it: a bob of mass ``m`` at distance ``l`` from the pivot on
the body's 3-axis, rigidly joined to a body whose central inertia is ``I`` about every axis,
so that about the pivot ``I1 = I2 = m l^2 + I`` and ``I3 = I``. Inertial axes: 1 and 2
horizontal, 3 vertically **down** (the seed's gravity ``m g k``), so ``theta = 0`` hangs.
The third Euler angle of each sequence is held at zero by a two-axis gimbal (the seed's
constraint ``B omega = 0``, eliminated with its multiplier); the two gimbals differ, so for
``I > 0`` the two models are two slightly different mechanisms and only for ``I -> 0``
both become the point-mass spherical pendulum.

* ``"3-1-3"``: ``A = A1(theta) A3(psi)`` (``phi = 0``), body rates
  ``w = [theta', psi' sin th, psi' cos th]``, bob at ``l (sin th sin psi, -sin th cos psi,
  cos th)``. (The seed writes this sequence with ``theta`` about axis 2, i.e. 3-2-3: the
  same equations with the azimuth shifted by 90 deg.)
* ``"3-2-1"``: ``A = A1(phi) A2(theta)`` (``psi = 0``), ``w = [phi', theta' cos phi,
  -theta' sin phi]``, bob at ``l (sin th cos phi, -sin phi, cos th cos phi)``.
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from .. import cache, validate
from ..model import Model
from .common import GRAVITY, assemble, nonnegative, symbols, with_parameters

__all__ = ["SEQUENCES", "spherical_pendulum", "conical_rate", "spherical_mass_matrix"]

#: the two formulations
SEQUENCES = ("3-1-3", "3-2-1")
_PARAMS = ("mass", "length", "inertia", "gravity")
_UNITS = {"mass": "kg", "length": "m", "inertia": "kg m^2", "gravity": "m/s^2"}
_COORDS = {"3-1-3": ("psi", "theta"), "3-2-1": ("theta", "phi")}


def _mass_matrix_diag(sequence, q, m, l, inertia, cos, sin):
    """Diagonal of the 2x2 mass matrix (the matrix is diagonal in both formulations)."""
    if sequence == "3-1-3":
        return m * l ** 2 * sin(q[1]) ** 2 + inertia, m * l ** 2 + inertia
    return m * l ** 2 * cos(q[1]) ** 2 + inertia, m * l ** 2 + inertia


@cache.memoize
def _spherical(sequence: str) -> Model:
    s = symbols(_COORDS[sequence], _PARAMS)
    m, l, inertia, g = (s.par[k] for k in _PARAMS)
    ml2, mgl = m * l ** 2, m * g * l
    m11, m22 = _mass_matrix_diag(sequence, s.q, m, l, inertia, ca.cos, ca.sin)
    if sequence == "3-1-3":
        (psi, th), (dpsi, dth) = s.q, s.qd
        st, ct = ca.sin(th), ca.cos(th)
        qdd = [-2 * ml2 * st * ct * dth * dpsi / m11,
               (ml2 * st * ct * dpsi ** 2 - mgl * st) / m22]
        position = l * ca.vertcat(st * ca.sin(psi), -st * ca.cos(psi), ct)
        height = ct
        momentum = m11 * dpsi
    else:
        (th, phi), (dth, dphi) = s.q, s.qd
        st, ct, sp, cp = ca.sin(th), ca.cos(th), ca.sin(phi), ca.cos(phi)
        qdd = [(2 * ml2 * sp * cp * dphi * dth - mgl * st * cp) / m11,
               (-ml2 * sp * cp * dth ** 2 - mgl * ct * sp) / m22]
        position = l * ca.vertcat(st * cp, -sp, ct * cp)
        height = ct * cp
        momentum = -m22 * st * dphi + ml2 * sp * cp * ct * dth
    energy = 0.5 * (m11 * s.qd[0] ** 2 + m22 * s.qd[1] ** 2) - mgl * height
    return assemble(s, qdd, name=f"spherical_pendulum_{sequence.replace('-', '')}",
                    param_units=_UNITS,
                    p_default=[1.0, 1.0, 0.01, GRAVITY],
                    invariants={"energy": energy, "momentum_vertical": momentum,
                                "position": position})


def spherical_pendulum(sequence: str, *, mass=1.0, length=1.0, inertia=0.01,
                       gravity=GRAVITY) -> Model:
    """Spherical pendulum in the 3-1-3 or the 3-2-1 formulation (Ch. 6 Example 1).

    Derivation (Lagrange, checked against the seed's multiplier elimination). With
    ``T = 1/2 w . diag(m l^2 + I, m l^2 + I, I) w`` and ``V = -m g (bob depth)``:

    * 3-1-3 (``q = (psi, theta)``): ``T = 1/2 [(m l^2 s^2 + I) psi'^2 + (m l^2 + I) th'^2]``,
      ``V = -m g l cos th``::

          (I + m l^2 sin^2 th) psi'' + 2 m l^2 psi' th' sin th cos th = 0
          (I + m l^2) th'' - m l^2 psi'^2 sin th cos th + m g l sin th = 0

      as in the seed. ``psi`` is cyclic: ``p_psi = (m l^2 sin^2 th + I) psi'`` is the
      vertical angular momentum. Near ``th = 0`` the ``psi`` inertia falls to ``I``: for
      ``I << m l^2`` a swing through the bottom spins ``psi`` up to ``p_psi / I``.
    * 3-2-1 (``q = (theta, phi)``): ``T = 1/2 [(m l^2 cos^2 phi + I) th'^2 +
      (m l^2 + I) phi'^2]``, ``V = -m g l cos th cos phi``::

          (m l^2 cos^2 phi + I) th'' - 2 m l^2 th' phi' sin phi cos phi = -m g l cos phi sin th
          (m l^2 + I) phi'' + m l^2 th'^2 sin phi cos phi = -m g l sin phi cos th

      The seed's OCR prints ``m l^2 cos phi + I``; Lagrange (and its own small-angle
      limit) needs ``cos^2 phi``. Regular at the bottom; singular at ``phi = +-90 deg``
      only when ``I = 0``.

    Parameters
    ----------
    sequence : {'3-1-3', '3-2-1'}
    mass : float [kg]
        Bob mass ``m``, ``> 0``.
    length : float [m]
        Pivot to bob ``l``, ``> 0``.
    inertia : float [kg m^2]
        Central moment ``I`` of the body, ``>= 0`` (``0``: point mass; the 3-1-3 equations
        are then singular at ``theta = 0``).
    gravity : float [m/s^2]
        ``>= 0``.

    Returns
    -------
    Model
        ``x = [psi, theta, psi_dot, theta_dot]`` (3-1-3) or
        ``[theta, phi, theta_dot, phi_dot]`` (3-2-1) [rad, rad/s]; no controls; parameters
        ``(mass, length, inertia, gravity)``; invariants ``energy`` [J],
        ``momentum_vertical`` [kg m^2/s] (the whole body's angular momentum about the
        downward vertical through the pivot: conserved by the 3-1-3 model; by the 3-2-1
        model only for ``inertia = 0``, since its outer gimbal axis is horizontal and
        exerts a vertical torque on a body with ``I > 0``) and ``position`` [m] (the bob,
        shape 3, inertial axes with 3 down).

    Raises
    ------
    ValueError
        Naming ``sequence`` (not one of `SEQUENCES`) or the parameter that is out of range.

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import spherical_pendulum
    >>> model = spherical_pendulum("3-2-1", inertia=0.0, gravity=9.81)
    >>> model.states
    ('theta', 'phi', 'theta_dot', 'phi_dot')
    >>> x = [0.3, 0.0, 0.0, 0.0]
    >>> (model.invariant("position", x).round(6) + 0.0).tolist()  # l (sin th, 0, cos th)
    [0.29552, 0.0, 0.955336]
    """
    sequence = validate.one_of(sequence, "sequence", SEQUENCES)
    args = {"mass": validate.positive(mass, "mass"), "length": validate.positive(length, "length"),
            "inertia": nonnegative(inertia, "inertia"), "gravity": nonnegative(gravity, "gravity")}
    return with_parameters(_spherical(sequence), args)


def conical_rate(cone_angle, *, length=1.0, gravity=GRAVITY) -> float:
    """Steady precession rate of the conical pendulum [rad/s].

    In the 3-1-3 equations ``th = alpha`` constant, ``psi' = Omega`` constant solve the
    ``psi`` equation; the ``th`` equation leaves ``m l^2 Omega^2 sin a cos a = m g l sin a``::

        Omega = sqrt(g / (l cos alpha))

    for any ``m`` and ``I`` of the 3-1-3 model, whose gimbal turns about the vertical. (In the
    3-2-1 model a cone is a steady motion only for ``I = 0``: the point-mass pendulum.)

    Parameters
    ----------
    cone_angle : float [rad]
        Half-angle ``alpha`` of the cone, ``0 <= alpha < pi/2``.
    length : float [m]
        ``> 0``.
    gravity : float [m/s^2]
        ``> 0``.

    Returns
    -------
    float [rad/s]

    Raises
    ------
    ValueError
        Naming the argument out of range.

    Examples
    --------
    >>> import math
    >>> from appdyn.dynamics.mechanisms import conical_rate
    >>> round(conical_rate(math.pi / 3, length=2.0, gravity=9.81), 6)   # sqrt(9.81)
    3.132092
    """
    alpha = validate.finite_scalar(cone_angle, "cone_angle")
    if not 0.0 <= alpha < np.pi / 2:
        raise ValueError(f"`cone_angle` must be in [0, pi/2) [rad], got {cone_angle!r}")
    return float(np.sqrt(validate.positive(gravity, "gravity")
                         / (validate.positive(length, "length") * np.cos(alpha))))


def spherical_mass_matrix(sequence: str, q, *, mass=1.0, length=1.0, inertia=0.01) -> np.ndarray:
    """The 2x2 mass matrix ``M(q)`` of `spherical_pendulum` [kg m^2] (diagonal).

    3-1-3: ``diag(m l^2 sin^2 th + I, m l^2 + I)``; 3-2-1: ``diag(m l^2 cos^2 phi + I,
    m l^2 + I)``. Its condition number ``(m l^2 + I) / I`` at the bottom of the 3-1-3 form is
    the seed's near-singularity.

    Parameters
    ----------
    sequence : {'3-1-3', '3-2-1'}
    q : array_like, shape (2,) [rad]
        ``(psi, theta)`` or ``(theta, phi)``.
    mass, length, inertia : float
        As for `spherical_pendulum`.

    Returns
    -------
    numpy.ndarray, shape (2, 2)

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.mechanisms import spherical_mass_matrix
    >>> [float(np.linalg.cond(spherical_mass_matrix(s, [0.0, 0.0], inertia=1e-4)))
    ...  for s in ("3-1-3", "3-2-1")]
    [10001.0, 1.0]
    """
    sequence = validate.one_of(sequence, "sequence", SEQUENCES)
    q = validate.finite_array(q, "q", (2,))
    m, l = validate.positive(mass, "mass"), validate.positive(length, "length")
    return np.diag(_mass_matrix_diag(sequence, q, m, l, nonnegative(inertia, "inertia"),
                                     np.cos, np.sin))
