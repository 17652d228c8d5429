"""`conical_pendulum`: stability of the steady conical motion of the spherical pendulum
(Rheinfurth & Wilson, NASA RP-1262, Ch. 6 Example 1; `dynamics.mechanisms.spherical_pendulum`)
in either formulation, reduced by its symmetry about the vertical.

Reduction
---------
The conical motion ``theta = alpha``, azimuth ``Omega t`` is not an equilibrium but a
*relative* one: rotations about the vertical are a symmetry, with generator ``xi`` on the
state space (configuration part from the bob position ``r(q)``: ``J xi_q = e3 x r``,
``J = dr/dq``; velocity part ``(d xi_q / dq) q'``). In the frame turning at ``Omega`` the
motion is an equilibrium of ``x' = f(x) - Omega xi(x)``, which is linearized exactly
(`dynamics.linearize.linearization`, which checks the residual). Its four eigenvalues are
``+-i omega`` and a **double 0 with one eigenvector** (a Jordan block): ``xi`` itself
(the cone turned about the vertical) and the neighbouring cones of other vertical momentum
``p``, which precess at other rates and so drift in azimuth in the turning frame. Both go:
`~dynamics.linearize.Linearization.quotient` by ``xi`` removes the azimuth, and
`~dynamics.linearize.Linearization.restrict` to a level set of ``p`` (a first integral,
``dp . xi = 0``) removes its rate -- Routh's reduction of the cyclic coordinate. What is left
is ``(theta, theta_dot)``: the nutation of the cone angle.

Closed form (Routhian ``V_eff = -m g l cos th + p^2 / (2 (m l^2 sin^2 th + I))``,
``p = (m l^2 sin^2 a + I) Omega``, ``Omega^2 = g / (l cos a)``)::

    (m l^2 + I) omega^2 = m g l c - m l^2 Omega^2 (c^2 - s^2)
                          + 4 m^2 l^4 s^2 c^2 Omega^2 / (m l^2 s^2 + I)

with ``s, c = sin a, cos a``; for a point mass ``omega^2 = (g / (l cos a)) (1 + 3 cos^2 a)``,
and the azimuth advances by ``2 pi Omega / omega = 2 pi / sqrt(1 + 3 cos^2 a)`` per nutation.
"""
from __future__ import annotations

import math

import casadi as ca
import numpy as np

from appdyn.dynamics import cache
from appdyn.dynamics.linearize import linearization
from appdyn.dynamics.mechanisms import SEQUENCES, conical_rate, spherical_pendulum
from appdyn.dynamics.model import Model
from appdyn.dynamics.results import timed

from .common import STANDARD_GRAVITY, check_number, spectrum_text
from .report import Quantity, StabilityReport, build_report

__all__ = ["conical_pendulum", "conical_nutation_frequency", "AZIMUTH"]

#: the coordinate eliminated with the azimuth (the one ``xi`` moves at the cone) per form
AZIMUTH = {"3-1-3": "psi", "3-2-1": "phi"}


@cache.memoize
def _turning(form: str):
    """``(model, xi, dp)``: the spherical pendulum in the frame turning at the parameter
    ``rate`` about the vertical, the generator ``xi(x, p)`` and ``grad p_vertical(x, p)``."""
    base = spherical_pendulum(form)
    x, u, p = ca.SX.sym("x", 4), ca.SX.sym("u", 0), ca.SX.sym("p", 5)
    q, qd, pb = x[:2], x[2:], p[:4]
    r = base.invariants["position"](x, pb)
    jac = ca.jacobian(r, q)
    xi_q = ca.solve(ca.mtimes(jac.T, jac), ca.mtimes(jac.T, ca.vertcat(-r[1], r[0], 0)))
    xi = ca.vertcat(xi_q, ca.mtimes(ca.jacobian(xi_q, q), qd))
    f = ca.Function(f"{base.f.name()}_turning", [x, u, p], [base.f(x, u, pb) - p[4] * xi],
                    ["x", "u", "p"], ["xdot"])
    momentum = base.invariants["momentum_vertical"](x, pb)
    model = Model(f, base.states, (), base.params + ("rate",),
                  p_default=np.append(base.p_default, 0.0),
                  units={**dict(base.units), "rate": "rad/s"}, name=f"{base.name}_turning",
                  invariants={"momentum_vertical": ca.Function(
                      "momentum_vertical", [x, p], [momentum], ["x", "p"],
                      ["momentum_vertical"])})
    return (model, ca.Function("xi", [x, p], [xi]),
            ca.Function("dp", [x, p], [ca.gradient(momentum, x)]))


def conical_nutation_frequency(cone_angle, *, mass=1.0, length=1.0, inertia=0.0,
                               gravity=STANDARD_GRAVITY) -> float:
    """Small-oscillation frequency ``omega`` of the cone angle about a steady cone [rad/s].

    Parameters
    ----------
    cone_angle : float [rad]
        ``alpha`` in ``(0, pi/2)``.
    mass, length, inertia, gravity : float
        As for `conical_pendulum`.

    Returns
    -------
    float [rad/s]
        The module's closed form; ``sqrt((g / (l cos a)) (1 + 3 cos^2 a))`` for ``inertia=0``.

    Examples
    --------
    >>> import math
    >>> from appdyn.problems.stability.constrained import conical_nutation_frequency
    >>> round(conical_nutation_frequency(math.pi / 3, length=9.80665), 12)   # sqrt(2 * 7/4)
    1.870828693387
    """
    m, l, I, g, a = _check(mass, length, inertia, gravity, cone_angle)
    s, c = math.sin(a), math.cos(a)
    rate2 = g / (l * c)
    stiff = (m * g * l * c - m * l * l * rate2 * (c * c - s * s)
             + 4 * m * m * l ** 4 * s * s * c * c * rate2 / (m * l * l * s * s + I))
    return math.sqrt(stiff / (m * l * l + I))


def _check(mass, length, inertia, gravity, cone_angle):
    m = check_number(mass, "mass", positive=True)
    l = check_number(length, "length", positive=True)
    I = check_number(inertia, "inertia", nonnegative=True)
    g = check_number(gravity, "gravity", positive=True)
    a = check_number(cone_angle, "cone_angle")
    if not 0.0 < a < math.pi / 2:
        raise ValueError(f"`cone_angle` must be in (0, pi/2) [rad] (0: hanging at rest, pi/2: "
                         f"the cone flattens at infinite rate), got {cone_angle!r}")
    return m, l, I, g, a


@timed
def conical_pendulum(*, mass, length, cone_angle, inertia=0.0, gravity=STANDARD_GRAVITY,
                     sequence="3-2-1") -> StabilityReport:
    """Stability of the conical pendulum: steady precession at the cone half-angle
    ``cone_angle``, reduced by the symmetry about the vertical (see the module notes).

    Parameters
    ----------
    mass : float [kg]
        ``> 0``.
    length : float [m]
        Pivot to bob, ``> 0``.
    cone_angle : float [rad]
        Half-angle ``alpha`` of the cone, ``0 < alpha < pi/2``.
    inertia : float [kg m^2], optional
        Central moment of the body (0: point mass). Only the 3-1-3 form, whose gimbal turns
        about the vertical, has steady cones for ``inertia > 0``.
    gravity : float [m/s^2], optional
        ``> 0``.
    sequence : {'3-2-1', '3-1-3'}, optional
        The formulation of `dynamics.mechanisms.spherical_pendulum` (its ``sequence``).

    Returns
    -------
    StabilityReport
        States ``theta, theta_dot`` (in the turning frame, azimuth and its rate reduced);
        eigenvalues ``+-i omega`` checked against the closed form; quantities: the
        precession rate, the vertical momentum, ``omega`` and the azimuth advance per
        nutation.

    Raises
    ------
    ValueError
        Naming ``cone_angle`` (not in ``(0, pi/2)``), ``sequence``, ``inertia`` (``> 0`` with
        the 3-2-1 form) or another argument out of range.

    Examples
    --------
    >>> import math
    >>> from appdyn.problems import stability
    >>> rep = stability.conical_pendulum(mass=1.0, length=1.0, cone_angle=math.pi / 3)
    >>> rep.verdict, rep.status, rep.ss.state_labels
    ('marginally stable', 0, ['theta', 'theta_dot'])
    >>> round(rep.quantity("nutation").value, 9)   # sqrt((g / (l cos a)) (1 + 3 cos^2 a))
    5.858606916
    """
    m, l, I, g, a = _check(mass, length, inertia, gravity, cone_angle)
    if sequence not in SEQUENCES:
        raise ValueError(f"`sequence` must be one of {list(SEQUENCES)}, got {sequence!r}")
    form = sequence
    if form == "3-2-1" and I > 0:
        raise ValueError(f"`inertia` must be 0 with sequence='3-2-1' (its outer gimbal axis is "
                         f"horizontal: no steady cone for a body with inertia), got {inertia!r}; "
                         "use sequence='3-1-3'")
    rate = conical_rate(a, length=l, gravity=g)
    model, xi_fun, dp_fun = _turning(form)
    p = [m, l, I, g, rate]
    q = [0.0, a] if form == "3-1-3" else [a, 0.0]
    x = np.concatenate([q, rate * np.asarray(xi_fun(q + [0.0, 0.0], p)).ravel()[:2]])
    lin = linearization(model, x, p=p)
    xi = np.asarray(xi_fun(x, p)).ravel()
    grad = np.asarray(dp_fun(x, p)).ravel()
    az = AZIMUTH[form]
    turned = lin.quotient(xi, eliminate=az, reason="turning the cone about the vertical is a "
                          "symmetry: its eigenvalue 0 (the azimuth) goes")
    red = turned.restrict(np.delete(grad, lin.index(az)), eliminate=f"{az}_dot",
                          reason="the vertical angular momentum is conserved (Routh): it fixes "
                          "the azimuth rate; the drift of cones of other momentum goes")
    omega = conical_nutation_frequency(a, mass=m, length=l, inertia=I, gravity=g)
    computed = float(max(abs(z.imag) for z in red.eigenvalues()))
    momentum = float(model.invariants["momentum_vertical"](x, p))
    s = math.sin(a)
    quantities = [
        Quantity("precession rate Omega", None, rate, "rad/s", "sqrt(g / (l cos a))"),
        Quantity("vertical angular momentum p", abs(momentum), (m * l * l * s * s + I) * rate,
                 "kg m^2/s", "(m l^2 sin^2 a + I) Omega"),
        Quantity("nutation frequency omega", computed, omega, "rad/s",
                 "Routhian; point mass: (g / (l cos a)) (1 + 3 cos^2 a)"),
        Quantity("azimuth advance per nutation", 2 * math.pi * rate / computed,
                 2 * math.pi * rate / omega, "rad", "2 pi Omega / omega")]
    full = spectrum_text(lin.eigenvalues())
    notes = [f"{form} form; conical state {dict(zip(lin.states, np.round(x, 12).tolist()))} "
             f"is an equilibrium of f - Omega xi (turning frame, max |residual| "
             f"{np.max(np.abs(lin.residual)):.1e})",
             f"unreduced spectrum: {full}: a double 0 with one eigenvector (Jordan block: "
             "azimuth and momentum)", *red.notes]
    title = (f"Conical pendulum, {form} form (RP-1262 Ch. 6 Ex. 1): cone "
             f"{math.degrees(a):.6g} deg")
    params = dict(mass=m, length=l, cone_angle=a, inertia=I, gravity=g, sequence=form)
    return build_report("conical_pendulum", title, params, red.ss, lin=lin,
                        closed_form=[1j * omega, -1j * omega],
                        groups={"nutation (cone angle)": ["theta", "theta_dot"]},
                        quantities=quantities, notes=notes)
