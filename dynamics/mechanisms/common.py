"""Shared pieces of the mechanism builders: symbols, assembly of a second-order model,
parameter defaults and checks.

Every mechanism has generalized coordinates ``q`` [rad], the state
``x = [q..., q_dot..., (t)]`` (the clock ``t`` [s] of `dynamics.clock` last, only for
time-dependent systems), no controls, and its physical constants as parameters ``p``, so
that one built (and compiled) right-hand side serves every parameter value.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Mapping

import casadi as ca
import numpy as np

from .. import validate
from ..clock import CLOCK_STATE, CLOCK_UNIT
from ..model import Model

__all__ = ["GRAVITY", "Symbols", "symbols", "assemble", "with_parameters", "nonnegative"]

#: standard gravity [m/s^2], the default ``gravity`` of every mechanism
GRAVITY = 9.80665


@dataclass(frozen=True)
class Symbols:
    """The CasADi symbols of a mechanism: ``x = [q, q_dot, (t)]``, ``u`` (empty), ``p``.

    Attributes
    ----------
    x, u, p : casadi.SX
        Column vectors of the Function's inputs.
    q, qd : tuple of casadi.SX
        Coordinates [rad] and their rates [rad/s].
    t : casadi.SX or None
        The clock state [s] (``None`` for an autonomous system).
    par : mapping of str to casadi.SX
        The parameters by name.
    coords, params : tuple of str
    """

    x: ca.SX
    u: ca.SX
    p: ca.SX
    q: tuple
    qd: tuple
    t: ca.SX | None
    par: Mapping[str, ca.SX]
    coords: tuple
    params: tuple


def symbols(coords, params, *, clock: bool = False) -> Symbols:
    """Symbols for a mechanism with coordinates ``coords`` and parameters ``params``.

    Parameters
    ----------
    coords, params : sequence of str
    clock : bool, optional
        Append the clock state ``t`` (time-dependent systems).

    Returns
    -------
    Symbols

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms.common import symbols
    >>> s = symbols(("theta",), ("mass",), clock=True)
    >>> s.x.shape, s.t is not None, tuple(s.par)
    ((3, 1), True, ('mass',))
    """
    n = len(coords)
    x = ca.SX.sym("x", 2 * n + int(clock))
    p = ca.SX.sym("p", len(params))
    return Symbols(x=x, u=ca.SX.sym("u", 0), p=p, q=tuple(x[i] for i in range(n)),
                   qd=tuple(x[n + i] for i in range(n)), t=x[2 * n] if clock else None,
                   par={k: p[i] for i, k in enumerate(params)}, coords=tuple(coords),
                   params=tuple(params))


def assemble(sym: Symbols, qdd, *, name: str, param_units: Mapping[str, str],
             p_default, invariants: Mapping | None = None) -> Model:
    """The `Model` ``x' = [q_dot, qdd, (1)]`` of accelerations ``qdd`` (SX in ``sym``).

    Parameters
    ----------
    sym : Symbols
    qdd : sequence of casadi.SX
        One acceleration [rad/s^2] per coordinate.
    name : str
    param_units : mapping of str to str
        Unit of each parameter.
    p_default : array_like, shape (np,)
    invariants : mapping of str to casadi.SX, optional
        Expressions in ``sym.x`` and ``sym.p``; each becomes a Function ``(x, p) -> key``.

    Returns
    -------
    Model
        States ``q..., q_dot..., (t)`` (units rad, rad/s, s), no controls.

    Examples
    --------
    >>> import casadi as ca
    >>> from appdyn.dynamics.mechanisms.common import assemble, symbols
    >>> s = symbols(("theta",), ("w0",))
    >>> m = assemble(s, [-s.par["w0"] ** 2 * ca.sin(s.q[0])], name="pendulum",
    ...              param_units={"w0": "rad/s"}, p_default=[2.0])
    >>> m.states, m.rhs([0.5, 0.0]).round(4).tolist()
    (('theta', 'theta_dot'), [0.0, -1.9177])
    """
    rates = tuple(f"{c}_dot" for c in sym.coords)
    clock = (CLOCK_STATE,) if sym.t is not None else ()
    xdot = ca.vertcat(*sym.qd, *qdd, *([ca.SX(1)] if clock else []))
    f = ca.Function(name, [sym.x, sym.u, sym.p], [xdot], ["x", "u", "p"], ["xdot"])
    funs = {k: ca.Function(k, [sym.x, sym.p], [expr], ["x", "p"], [k])
            for k, expr in (invariants or {}).items()}
    units = {**{c: "rad" for c in sym.coords}, **{r: "rad/s" for r in rates},
             **({CLOCK_STATE: CLOCK_UNIT} if clock else {}), **dict(param_units)}
    return Model(f, sym.coords + rates + clock, (), sym.params, p_default=p_default,
                 units=units, invariants=funs, name=name)


def with_parameters(model: Model, values: Mapping[str, float]) -> Model:
    """``model`` with the defaults of the named parameters replaced (same Functions).

    Parameters
    ----------
    model : Model
    values : mapping of str to float
        New default values; every key must be one of ``model.params``.

    Returns
    -------
    Model

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import double_pendulum
    >>> from appdyn.dynamics.mechanisms.common import with_parameters
    >>> with_parameters(double_pendulum(), {"mass2": 3.0}).p_default.tolist()
    [1.0, 3.0, 1.0, 1.0, 9.80665]
    """
    p = np.array(model.p_default)
    for key, value in values.items():
        p[model.params.index(key)] = value
    return dataclasses.replace(model, p_default=p)


def nonnegative(value, name: str) -> float:
    """A finite number ``>= 0`` (`validate.finite_scalar` plus the sign).

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms.common import nonnegative
    >>> nonnegative(0, "damping")
    0.0
    >>> nonnegative(-1.0, "damping")
    Traceback (most recent call last):
        ...
    ValueError: `damping` must be a finite number >= 0, got -1.0
    """
    v = validate.finite_scalar(value, name)
    if v < 0:
        raise ValueError(f"`{name}` must be a finite number >= 0, got {value!r}")
    return v
