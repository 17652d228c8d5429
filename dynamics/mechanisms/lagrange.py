"""Lagrange's equations with multipliers for the worked mechanisms: the mass matrix and
forces from ``T`` and ``V`` by automatic differentiation (`lagrange_terms`), and the assembly
of a constrained `Model` from them (`constrained_model`, on `dynamics.constrained`).
"""
from __future__ import annotations

import casadi as ca

from .. import validate
from ..clock import CLOCK_STATE, CLOCK_UNIT
from ..constrained import baumgarte, constrained_accelerations, constraint_terms, residual_invariant
from ..model import Model
from .common import nonnegative

__all__ = ["lagrange_terms", "stabilization", "constrained_model", "checked_constants"]


def lagrange_terms(T, V, q, v):
    """Mass matrix and forces of Lagrange's equations ``M v' = Q`` (before constraints).

    For ``L = T - V`` with ``T`` quadratic in the rates ``v = q'`` (no explicit time)::

        M = d^2 T / dv^2,     Q = dL/dq - (d/dq dT/dv) v

    (Eq. 5.61: applied plus inertial forces ``Q_A + Q_I``).

    Parameters
    ----------
    T, V : casadi.SX
        Kinetic and potential energy (scalars); ``V`` may also be a finite number.
    q, v : casadi.SX
        Coordinates and their rates (symbols).

    Returns
    -------
    (casadi.SX, casadi.SX)
        ``M`` (n x n) and ``Q`` (n x 1).

    Raises
    ------
    TypeError
        If ``T``, ``q`` or ``v`` is not a CasADi SX/MX expression, or ``V`` is neither one
        nor a real number.
    ValueError
        If ``T`` or ``V`` is not a scalar (1 x 1), or a numeric ``V`` is not finite.

    Examples
    --------
    >>> import casadi as ca
    >>> from appdyn.dynamics.mechanisms import lagrange_terms
    >>> q, v = ca.SX.sym("q"), ca.SX.sym("v")
    >>> M, Q = lagrange_terms(0.5 * 2.0 * v ** 2, 0.5 * 8.0 * q ** 2, q, v)
    >>> float(M), ca.Function("Q", [q], [Q])(0.5)
    (2.0, DM(-4))
    """
    V = V if validate.is_symbolic(V) else validate.finite_scalar(V, "V")
    for name, a in (("T", T), ("V", V), ("q", q), ("v", v)):
        if name == "V" and not validate.is_symbolic(V):
            continue
        if not validate.is_symbolic(a):
            raise validate.ArgumentTypeError(f"`{name}` must be a casadi SX/MX expression, "
                                             f"got {type(a).__name__}")
        if name in ("T", "V") and a.shape != (1, 1):
            raise ValueError(f"`{name}` must be a scalar (1x1) expression, got shape {a.shape}")
    M = ca.hessian(T, v)[0]
    Q = ca.gradient(T - V, q) - ca.jtimes(ca.gradient(T, v), q, v)
    return M, Q


def stabilization(time_constant):
    """The Baumgarte time constant [s] checked (``None``: no drift control)."""
    if time_constant is None:
        return None
    return validate.positive(time_constant, "time_constant")


def constrained_model(name, coords, coord_units, rate_units, q, v, t, p, params, param_units, p_default,
           M, Q, *, position=None, velocity=None, time_constant=None, extra=None, qdot=None,
           rates=None, attitude=None) -> Model:
    """Assemble ``x = [q, v, (t)]`` with ``x' = [qdot (default v), v', (1)]`` and the
    invariants."""
    qdot = v if qdot is None else qdot
    terms = constraint_terms(q, qdot, v, position=position, velocity=velocity, t=t)
    c = terms.c
    if time_constant is not None:
        c = baumgarte(c, terms.residual, terms.position, time_constant=time_constant)
    sol = constrained_accelerations(M, Q, terms.B, c)
    x = ca.vertcat(q, v, *([t] if t is not None else []))
    xdot = ca.vertcat(qdot, sol.vdot, *([ca.SX(1)] if t is not None else []))
    f = ca.Function(name, [x, ca.SX.sym("u", 0), p], [xdot], ["x", "u", "p"], ["xdot"])
    exprs = {"multipliers": sol.lam, **(extra(sol.lam) if extra else {})}
    inv = {k: ca.Function(k, [x, p], [e], ["x", "p"], [k]) for k, e in exprs.items()}
    inv["constraint_residual"] = residual_invariant(x, p, terms)
    rates = tuple(f"{k}_dot" for k in coords) if rates is None else tuple(rates)
    clock = (CLOCK_STATE,) if t is not None else ()
    units = {**dict(zip(coords, coord_units)), **dict(zip(rates, rate_units)),
             **({CLOCK_STATE: CLOCK_UNIT} if clock else {}), **param_units}
    return Model(f, tuple(coords) + rates + clock, (), tuple(params), p_default=p_default,
                 units=units, invariants=inv, name=name, attitude=attitude)


def checked_constants(values: dict, positive=(), nonneg=()) -> dict:
    """Physical constants by name as floats: finite, and > 0 / >= 0 where listed."""
    out = {k: validate.finite_scalar(v, k) for k, v in values.items()}
    for k in positive:
        validate.positive(out[k], k)
    for k in nonneg:
        nonnegative(out[k], k)
    return out
