"""Small problems with known optima, for the docstring Examples and first experiments.

The double integrator ``x'' = u`` (states ``x``, ``v``; control ``u``), rest to rest over
a distance ``d``:

* `min_energy`: minimize ``integral u^2 / 2`` over a fixed ``T``; the optimum is
  ``u = (6 - 12 t / T) d / T^2``, ``J = 6 d^2 / T^3`` (Bryson & Ho, *Applied Optimal
  Control*, 1975);
* `min_time`: minimize ``T`` under ``|u| <= u_max``; bang-bang with one switch at ``T / 2``,
  ``T = 2 sqrt(d / u_max)``.

Examples
--------
>>> import ocp
>>> from ocp.examples import min_energy, min_time
>>> round(ocp.solve(min_energy(), N=10).cost, 6)
6.0
>>> round(ocp.solve(min_time(distance=4.0), N=10).T, 6)
4.0
"""
from __future__ import annotations

import casadi as ca

from dynamics.model import Model

from .problem import Problem

__all__ = ["double_integrator", "min_energy", "min_time"]


def double_integrator() -> Model:
    """The model ``x' = v``, ``v' = u`` (one Function per process: `dynamics.cache` reuse).

    Returns
    -------
    dynamics.Model
        States ``('x', 'v')``, control ``('u',)``, no parameters.
    """
    return _DOUBLE_INTEGRATOR


def _build() -> Model:
    x, u, p = ca.SX.sym("x", 2), ca.SX.sym("u"), ca.SX.sym("p", 0)
    f = ca.Function("double_integrator", [x, u, p], [ca.vertcat(x[1], u)],
                    ["x", "u", "p"], ["xdot"])
    return Model(f, ("x", "v"), ("u",), name="double_integrator")


_DOUBLE_INTEGRATOR = _build()


def min_energy(distance: float = 1.0, T: float = 1.0) -> Problem:
    """Minimum ``integral u^2 / 2`` [m^2/s^3], rest to rest over ``distance`` [m] in ``T`` [s].

    Returns
    -------
    ocp.Problem
        Optimum ``J = 6 distance^2 / T^3``.
    """
    return Problem(double_integrator(), T=float(T), x_initial=[0.0, 0.0],
                   x_final=[float(distance), 0.0], lagrange=lambda x, u, p: 0.5 * u**2,
                   name="double integrator, minimum energy")


def min_time(distance: float = 1.0, u_max: float = 1.0, T_max: float = 10.0) -> Problem:
    """Minimum time, rest to rest over ``distance`` [m] under ``|u| <= u_max`` [m/s^2].

    Returns
    -------
    ocp.Problem
        Free ``T`` in ``[0.1, T_max]`` s; optimum ``T = 2 sqrt(distance / u_max)``.
    """
    return Problem(double_integrator(), T=(0.1, float(T_max)), x_initial=[0.0, 0.0],
                   x_final=[float(distance), 0.0], u_bounds={"u": (-u_max, u_max)},
                   mayer=lambda xf, p, T: T, name="double integrator, minimum time")
