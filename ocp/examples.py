"""Small problems with known optima, for the docstring Examples and first experiments.

The double integrator ``x'' = u`` (states ``x``, ``v``; control ``u``), rest to rest over
a distance ``d``:

* `min_energy`: minimize ``integral u^2 / 2`` over a fixed ``T``; the optimum is
  ``u = (6 - 12 t / T) d / T^2``, ``J = 6 d^2 / T^3`` (Bryson & Ho, *Applied Optimal
  Control*, 1975);
* `min_time`: minimize ``T`` under ``|u| <= u_max``; bang-bang with one switch at ``T / 2``,
  ``T = 2 sqrt(d / u_max)``.

The Goddard rocket (`goddard_rocket`), a problem with a *singular arc*: maximize the final
altitude of a vertical ascent with drag, normalized as in COPS 3.0 (Dolan, More & Munson,
*Benchmarking optimization software with COPS 3.0*, ANL/MCS-TM-273, 2004) and Betts,
*Practical Methods for Optimal Control* (2010). COPS reports ``h(tf) = 1.01283``. The
optimal thrust is maximal, then singular (on the surface where the switching function and
its first two derivatives vanish), then zero until the apogee; integrating that structure
(thrust 3.5 until the singular surface at ``t1 = 0.0235097``, the singular feedback law until
the fuel is spent at ``t2 = 0.0726707``, coasting to ``v = 0``) gives
``h(tf) = 1.0128369183`` at ``tf = 0.1988562621`` (`GODDARD_OPTIMUM`; reproduced in the
tests).

Singular arcs and collocation
-----------------------------
On a singular arc the Hamiltonian does not determine the control: the discrete problem has
nearly flat directions, the collocated control rings around the singular value, and its
junctions with the bang arcs are not smooth. Consequences, measured on `goddard_rocket`
(Radau degree 3):

* the collocated objective can *beat* the true optimum (N = 20: 1.0128648 against
  1.0128369; a collocation solution is not a feasible trajectory), while the control
  re-simulated by `Solution.propagate` achieves 1.0128174 (`Solution.simulated_cost`, the
  value to trust: it is what the control does);
* `ocp.refine` cannot drive its error estimate down (4.2e-2, 9.1e-3, 7.7e-3 on 20, 39, 70
  intervals, where a smooth problem gains 16x per round) and stops with status
  104 ``Refinement_Stalled`` after two rounds, the re-simulated cost then 1.0128361.

The remedy is a small regularization of the control, here ``regularization * integral
thrust^2 dt`` subtracted from the maximized altitude (penalized with the sign of the
optimization): the Hamiltonian becomes strictly concave in the thrust, the control
continuous, and `ocp.refine` converges. It changes the optimum by a measured amount:
with ``regularization = 1e-4`` refine(tol=1e-6) converges in 3 rounds (62 intervals), the
re-simulated altitude 1.0128361 is 7.7e-7 below the singular optimum and agrees with the
collocated one to 4e-8 (the penalty ``eps * integral thrust^2 dt`` is 5.6e-5); with 1e-3 the
altitude is 1.0128227 (1.4e-5 below), with 3e-4 1.0128345 (2.5e-6 below). Smaller weights
sharpen the junctions and take more rounds (1e-5: 8). The altitude of a regularized
solution is ``sol.propagation.x[0, -1]`` (re-simulated) or ``sol["h"][-1]``; ``sol.cost``
includes the penalty. The exact alternative imposes the structure (phases bang / singular /
coast, the singular control law on the middle one), as the tests do to compute the optimum.

Examples
--------
>>> from appdyn import ocp
>>> from appdyn.ocp.examples import min_energy, min_time
>>> round(ocp.solve(min_energy(), N=10).cost, 6)
6.0
>>> round(ocp.solve(min_time(distance=4.0), N=10).T, 6)
4.0
"""
from __future__ import annotations

import math
import numbers
from types import MappingProxyType

import casadi as ca

from appdyn.dynamics import cache
from appdyn.dynamics.model import Model

from .problem import Constraint, Problem

__all__ = ["double_integrator", "min_energy", "min_time", "goddard_rocket", "GODDARD_OPTIMUM",
           "orbit_raising", "ORBIT_RAISING_OPTIMUM", "shuttle_reentry", "shuttle_reentry_guess",
           "SHUTTLE_REENTRY_OPTIMUM"]


def double_integrator() -> Model:
    """The model ``x' = v``, ``v' = u`` (one Function per process: `dynamics.cache` reuse).

    Returns
    -------
    dynamics.Model
        States ``('x', 'v')``, control ``('u',)``, no parameters.
    """
    return _build()


@cache.memoize  # built on first use, once per process (until `clear_caches`)
def _build() -> Model:
    x, u, p = ca.SX.sym("x", 2), ca.SX.sym("u"), ca.SX.sym("p", 0)
    f = ca.Function("double_integrator", [x, u, p], [ca.vertcat(x[1], u)],
                    ["x", "u", "p"], ["xdot"])
    return Model(f, ("x", "v"), ("u",), name="double_integrator")


def min_energy(*, distance: float = 1.0, T: float = 1.0) -> Problem:
    """Minimum ``integral u^2 / 2`` [m^2/s^3], rest to rest over ``distance`` [m] in ``T`` [s].

    Returns
    -------
    ocp.Problem
        Optimum ``J = 6 distance^2 / T^3``.
    """
    return Problem(double_integrator(), T=float(T), x_initial=[0.0, 0.0],
                   x_final=[float(distance), 0.0], lagrange=lambda x, u, p: 0.5 * u**2,
                   name="double integrator, minimum energy")


def min_time(*, distance: float = 1.0, u_max: float = 1.0, T_max: float = 10.0) -> Problem:
    """Minimum time, rest to rest over ``distance`` [m] under ``|u| <= u_max`` [m/s^2].

    Returns
    -------
    ocp.Problem
        Free ``T`` in ``[0.1, T_max]`` s; optimum ``T = 2 sqrt(distance / u_max)``.
    """
    return Problem(double_integrator(), T=(0.1, float(T_max)), x_initial=[0.0, 0.0],
                   x_final=[float(distance), 0.0], u_bounds={"u": (-u_max, u_max)},
                   mayer=lambda xf, p, T: T, name="double integrator, minimum time")


#: The Goddard rocket's optimal final altitude and time (normalized units, `goddard_rocket`
#: with ``regularization = 0``): from the bang / singular / coast structure integrated to
#: 1e-13 (the module docstring); COPS 3.0 reports ``h(tf) = 1.01283``.
GODDARD_OPTIMUM = MappingProxyType({"h_f": 1.0128369183, "T": 0.1988562621})


@cache.memoize  # built on first use, once per process (until `clear_caches`)
def _goddard_model() -> Model:
    h0, g0, m0, c = 1.0, 1.0, 1.0, 0.5  # c = 0.5 sqrt(g0 h0)
    Dc, hc = 0.5 * 620.0 * m0 / g0, 500.0  # Dc = 0.5 vc m0 / g0, vc = 620
    x, u, p = ca.SX.sym("x", 3), ca.SX.sym("thrust"), ca.SX.sym("p", 0)
    h, v, m = x[0], x[1], x[2]
    drag = Dc * v ** 2 * ca.exp(-hc * (h - h0) / h0)
    gravity = g0 * (h0 / h) ** 2
    f = ca.Function("goddard_rocket", [x, u, p],
                    [ca.vertcat(v, (u - drag) / m - gravity, -u / c)], ["x", "u", "p"], ["xdot"])
    return Model(f, ("h", "v", "m"), ("thrust",), name="goddard_rocket",
                 units={"h": "h0", "v": "sqrt(g0 h0)", "m": "m0", "thrust": "g0 m0"})


def goddard_rocket(*, regularization: float = 0.0) -> Problem:
    """Goddard rocket, maximum final altitude (COPS 3.0 / Betts, normalized units).

    States ``h`` (altitude [h0]), ``v`` (velocity [sqrt(g0 h0)]), ``m`` (mass [m0]); control
    ``thrust`` [g0 m0] in ``[0, 3.5]``; free horizon ``T`` in ``[0.1, 1]`` [sqrt(h0/g0)]::

        h' = v,  v' = (thrust - D(h, v)) / m - g(h),  m' = -thrust / c,
        D = Dc v^2 exp(-hc (h - h0) / h0),  g = g0 (h0 / h)^2,

    with ``h0 = g0 = m0 = 1``, ``c = 0.5 sqrt(g0 h0)``, ``Dc = 0.5 vc m0 / g0``, ``vc = 620``,
    ``hc = 500``; from ``(h, v, m) = (1, 0, 1)`` to a final mass ``0.6 m0``, ``h >= 1``,
    ``v >= 0``, ``0.6 <= m <= 1``. Maximizes ``J = h(T) - regularization * integral
    thrust^2 dt`` (``maximize=True``: `Solution.cost` is ``J`` itself).

    The optimal thrust has a singular arc (module docstring): without regularization
    `ocp.refine` stalls (status 104 ``Refinement_Stalled``) and the re-simulated cost
    `Solution.simulated_cost` is the number to trust; a small ``regularization`` (1e-4:
    the re-simulated altitude 7.7e-7 below the optimum) lets refinement converge. The
    ``'radau'`` thrust polynomial overshoots its bounds on this arc (a ``'Bound_Violation'``
    failure of `ocp.solve`); solve with ``control='linear'``.

    Parameters
    ----------
    regularization : float, optional
        Weight ``eps >= 0`` of the penalty ``eps * integral thrust^2 dt`` [h0 / (g0^2 m0^2
        sqrt(h0/g0))]; 0 (default) is the original problem.

    Returns
    -------
    ocp.Problem
        Optimum ``h(tf) = 1.0128369183`` at ``tf = 0.1988562621`` for ``regularization = 0``
        (`GODDARD_OPTIMUM`).

    Raises
    ------
    ValueError
        If ``regularization`` is negative or not finite.
    TypeError
        If ``regularization`` is not a real number.

    Examples
    --------
    >>> from appdyn import ocp
    >>> from appdyn.ocp.examples import goddard_rocket, GODDARD_OPTIMUM
    >>> sol = ocp.solve(goddard_rocket(), N=20)  # the Radau thrust polynomial overshoots [0, 3.5]
    >>> sol.status, round(sol.cost, 5), round(sol.simulated_cost, 5), GODDARD_OPTIMUM["h_f"]
    (102, 1.01286, 1.01282, 1.0128369183)
    >>> linear = ocp.solve(goddard_rocket(), N=20, control="linear")  # stays within the bounds
    >>> linear.success, round(linear.cost, 5), round(linear.simulated_cost, 5)
    (True, 1.01283, 1.01283)
    """
    if isinstance(regularization, bool) or not isinstance(regularization, numbers.Real):
        raise TypeError(f"`regularization` must be a real number, got {type(regularization).__name__}")
    eps = float(regularization)
    if not (math.isfinite(eps) and eps >= 0.0):
        raise ValueError(f"`regularization` must be finite and >= 0, got {regularization!r}")
    kw = {}
    if eps > 0.0:
        kw["lagrange"] = lambda x, u, p: -eps * u[0] ** 2
    name = "Goddard rocket, maximum altitude" + (f", regularized {eps:g}" if eps > 0.0 else "")
    return Problem(_goddard_model(), T=(0.1, 1.0), x_initial=[1.0, 0.0, 1.0], x_final={"m": 0.6},
                   x_bounds={"h": (1.0, None), "v": (0.0, None), "m": (0.6, 1.0)},
                   u_bounds={"thrust": (0.0, 3.5)}, mayer=lambda xf, p, T: xf[0],
                   maximize=True, name=name, **kw)


#: Bryson & Ho's orbit raising: the largest final radius [r0], to the four digits the
#: literature agrees on (Bryson & Ho 1975; Betts 2010: 1.52526; collocation refined to
#: interval errors of 1e-9 here: 1.5252777).
ORBIT_RAISING_OPTIMUM = MappingProxyType({"r_f": 1.5253})


@cache.memoize  # built on first use, once per process (until `clear_caches`)
def _orbit_raising_model() -> Model:
    thrust, mdot = 0.1405, 0.0749
    x, u, p = ca.SX.sym("x", 4), ca.SX.sym("u", 2), ca.SX.sym("p", 0)
    r, vr, vt, m = x[0], x[1], x[2], x[3]
    f = ca.Function("orbit_raising", [x, u, p],
                    [ca.vertcat(vr, vt ** 2 / r - 1 / r ** 2 + thrust * u[0] / m,
                                -vr * vt / r + thrust * u[1] / m, -mdot)],
                    ["x", "u", "p"], ["xdot"])
    return Model(f, ("r", "vr", "vt", "m"), ("ur", "ut"), name="orbit_raising",
                 units={"r": "r0", "vr": "sqrt(mu/r0)", "vt": "sqrt(mu/r0)", "m": "m0",
                        "ur": "-", "ut": "-"})


def _unit(ur, ut):
    return ur ** 2 + ut ** 2


def _circular(r_f, vt_f):
    return vt_f - 1 / ca.sqrt(r_f)


def _radius(r_f):
    return r_f


def orbit_raising() -> Problem:
    """Bryson & Ho's low-thrust orbit raising (*Applied Optimal Control*, 1975, sec. 2.5),
    the thrust direction a unit vector: maximum final radius in a fixed time.

    States ``r`` [r0], radial and tangential velocity ``vr``, ``vt`` [sqrt(mu/r0)], mass
    ``m`` [m0]; controls ``ur``, ``ut``, the radial and tangential components of the thrust
    direction with ``ur^2 + ut^2 = 1`` (a path constraint; no angle, so no 2 pi jumps)::

        r' = vr,  vr' = vt^2 / r - 1 / r^2 + 0.1405 ur / m,
        vt' = -vr vt / r + 0.1405 ut / m,  m' = -0.0749,

    ``mu = 1``, from ``(1, 0, 1, 1)`` over ``T = 3.32`` to a circular orbit (``vr = 0``,
    ``vt = 1 / sqrt(r)``); ``0.5 <= r <= 5``, ``0.1 <= m <= 1``.

    Returns
    -------
    ocp.Problem
        Maximizes ``r(T)``; optimum 1.5253 (`ORBIT_RAISING_OPTIMUM`).

    Examples
    --------
    >>> from appdyn.ocp import solve
    >>> from appdyn.ocp.examples import orbit_raising
    >>> sol = solve(orbit_raising(), N=20)
    >>> sol.success, round(sol.cost, 4), round(sol.simulated_cost, 4)
    (True, 1.5253, 1.5253)
    """
    return Problem(_orbit_raising_model(), T=3.32, x_initial=[1.0, 0.0, 1.0, 1.0], x_final={"vr": 0.0},
                   x_bounds={"r": (0.5, 5.0), "m": (0.1, 1.0)},
                   path=Constraint(_unit, 1.0, 1.0, name="|u| = 1"),
                   boundary=Constraint(_circular, 0.0, 0.0, name="circular"),
                   mayer=_radius, maximize=True, name="orbit raising")


#: Betts' shuttle reentry without a heating limit: the largest crossrange (final latitude)
#: [deg] and the final time [s] (Betts 2010, *Practical Methods for Optimal Control*, 2nd
#: ed., example 6.1: 34.1412 deg at 2008.6 s).
SHUTTLE_REENTRY_OPTIMUM = MappingProxyType({"theta_f_deg": 34.1412, "T": 2008.6})

# units of the reentry: 1e5 ft, 60 s, the vehicle's mass (as ASSET's example states it)
_L, _T = 1.0e5, 60.0
_REENTRY_START = (260000.0 / _L, 0.0, 25600.0 / (_L / _T), math.radians(-1.0), math.radians(90.0))
_REENTRY_END = {"h": 80000.0 / _L, "v": 2500.0 / (_L / _T), "gamma": math.radians(-5.0)}


@cache.memoize  # built on first use, once per process (until `clear_caches`)
def _reentry_model() -> Model:
    g0, weight = 32.2, 203000.0
    m_star = weight / g0
    re, area = 20902900.0 / _L, 2690.0 / _L ** 2
    mass, mu = weight / g0 / m_star, 0.140765e17 / (_L ** 3 / _T ** 2)
    rho0, h_ref = 0.002378 / (m_star / _L ** 3), 23800.0 / _L
    x, u, p = ca.SX.sym("x", 5), ca.SX.sym("u", 2), ca.SX.sym("p", 0)
    h, theta, v, gamma, psi = (x[i] for i in range(5))
    alpha, beta = u[0], u[1]
    a = alpha * 180.0 / math.pi
    cl = -0.20704 + 0.029244 * a
    cd = 0.07854 - 0.61592e-2 * a + 0.621408e-3 * a ** 2
    q = 0.5 * rho0 * ca.exp(-h / h_ref) * v ** 2 * area
    lift, drag = cl * q, cd * q
    r = h + re
    g = mu / r ** 2
    rhs = ca.vertcat(v * ca.sin(gamma),
                     v / r * ca.cos(gamma) * ca.cos(psi),
                     -drag / mass - g * ca.sin(gamma),
                     lift / (mass * v) * ca.cos(beta) + ca.cos(gamma) * (v / r - g / v),
                     lift * ca.sin(beta) / (mass * v * ca.cos(gamma))
                     + v / r * ca.cos(gamma) * ca.sin(psi) * ca.tan(theta))
    f = ca.Function("shuttle_reentry", [x, u, p], [rhs], ["x", "u", "p"], ["xdot"])
    return Model(f, ("h", "theta", "v", "gamma", "psi"), ("alpha", "beta"),
                 name="shuttle_reentry",
                 units={"h": "1e5 ft", "theta": "rad", "v": "1e5 ft / 60 s", "gamma": "rad",
                        "psi": "rad", "alpha": "rad", "beta": "rad"})


def _latitude(theta_f):
    return theta_f


def shuttle_reentry() -> Problem:
    """Betts' space shuttle reentry, maximum crossrange, without a heating limit (Betts
    2010, example 6.1; the problem of ASSET's and dymos' reentry examples).

    States altitude ``h`` [1e5 ft], latitude ``theta`` [rad] (the crossrange), speed ``v``
    [1e5 ft per 60 s], flight-path angle ``gamma`` and azimuth ``psi`` [rad]; controls angle
    of attack ``alpha`` and bank ``beta`` [rad]; time in units of 60 s. Point mass over a
    spherical non-rotating Earth with an exponential atmosphere; ``C_L = -0.20704 +
    0.029244 a``, ``C_D = 0.07854 - 0.61592e-2 a + 0.621408e-3 a^2`` (``a`` = ``alpha`` in
    degrees); W = 203000 lb, S = 2690 ft^2, R_E = 20902900 ft, mu = 0.140765e17 ft^3/s^2,
    rho0 = 0.002378 slug/ft^3, H = 23800 ft. From 260000 ft, 25600 ft/s, ``gamma = -1``
    deg, ``psi = 90`` deg at ``theta = 0`` to 80000 ft, 2500 ft/s, ``gamma = -5`` deg in a
    free time ``T <= 2500`` s; ``|theta|, |gamma| <= 89`` deg, ``|alpha| <= 90`` deg,
    ``-90 <= beta <= 1`` deg. Solve from `shuttle_reentry_guess`.

    Returns
    -------
    ocp.Problem
        Maximizes ``theta(T)``; optimum 34.1412 deg at T = 2008.6 s
        (`SHUTTLE_REENTRY_OPTIMUM`).

    Examples
    --------
    >>> import math
    >>> from appdyn.ocp import solve
    >>> from appdyn.ocp.examples import shuttle_reentry, shuttle_reentry_guess
    >>> sol = solve(shuttle_reentry(), N=20, degree=5, guess=shuttle_reentry_guess())
    >>> sol.success, round(math.degrees(sol.cost), 4), round(sol.T * 60, 1)
    (True, 34.1414, 2008.6)

    (Radau degree 3 on 20 or 40 intervals collocates 34.1416 and 34.1414 deg, but the
    flight-path angle re-simulated from the control drifts 0.4-0.05 % of its size, above the
    verification tolerance: not verified.)
    """
    lim = math.radians(89.0)
    return Problem(_reentry_model(), T=(0.1, 2500.0 / _T), x_initial=list(_REENTRY_START),
                   x_final=dict(_REENTRY_END),
                   x_bounds={"h": (0.0, 3.0), "theta": (-lim, lim), "v": (0.01, 20.0),
                             "gamma": (-lim, lim), "psi": (-math.pi, 2 * math.pi)},
                   u_bounds={"alpha": (-math.pi / 2, math.pi / 2),
                             "beta": (-math.pi / 2, math.radians(1.0))},
                   mayer=_latitude, maximize=True, name="shuttle reentry")


def shuttle_reentry_guess(*, n: int = 21) -> dict:
    """The start of ASSET's reentry example: over T = 1000 s, ``h``, ``v`` and ``gamma``
    straight from their initial to their final values, ``theta = 0``, ``psi = 90`` deg,
    ``alpha = beta = 0``; ``n`` samples (a guess for `shuttle_reentry`, in its units).

    Examples
    --------
    >>> from appdyn.ocp.examples import shuttle_reentry_guess
    >>> shuttle_reentry_guess(n=5)["x"].shape
    (5, 5)
    """
    import numpy as np

    if isinstance(n, bool) or not isinstance(n, numbers.Integral) or n < 2:
        raise ValueError(f"`n` must be an int >= 2, got {n!r}")
    T = 1000.0 / _T
    f = np.linspace(0.0, 1.0, n)
    h0, _, v0, g0, psi0 = _REENTRY_START
    end = _REENTRY_END
    x = np.vstack([h0 + f * (end["h"] - h0), np.zeros(n), v0 + f * (end["v"] - v0),
                   g0 + f * (end["gamma"] - g0), np.full(n, psi0)])
    return {"t": f * T, "x": x, "u": np.zeros((2, n)), "T": T}
