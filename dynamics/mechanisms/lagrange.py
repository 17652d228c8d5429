"""Lagrange's equations with multipliers for the worked mechanisms: the mass matrix and
forces from ``T`` and ``V`` by automatic differentiation (`lagrange_terms`), and the assembly
of a constrained `Model` from them (`constrained_model`, on `dynamics.constrained`).
"""
from __future__ import annotations

import casadi as ca

from .. import validate
from ..clock import CLOCK_STATE, CLOCK_UNIT
from ..constrained import baumgarte, constrained_accelerations, constraint_terms, residual_invariant
from ..model import Model, model_from_expressions, named_symbols
from .common import nonnegative

__all__ = ["lagrange_terms", "generalized_forces", "lagrange_model", "stabilization", "constrained_model", "checked_constants"]


def lagrange_terms(T, V, q, v, *, t=None, forces=(), velocity_potential=None):
    """Mass matrix and forces of Lagrange's equations ``M v' = Q`` (before constraints).

    For ``L = T - V - U`` (``U(q, v, t)`` a velocity-dependent potential, seed Eq. 5.47)
    and applied forces ``F_i`` at points ``r_i(q, t)`` (seed Eqs. 5.21-5.26)::

        d/dt dL/dv - dL/dq = Q_F,    Q_F,k = sum_i F_i . dr_i/dq_k
        M = d^2 L / dv^2,   Q = dL/dq - (d/dq dL/dv) v - d/dt|_explicit dL/dv + Q_F

    (Eq. 5.61: applied plus inertial forces ``Q_A + Q_I``; the explicit-time term is the
    rheonomic part of ``T``, seed Eqs. 5.31-5.33; Eq. 5.47 is the same as putting ``U`` in
    ``L``).

    Parameters
    ----------
    T, V : casadi.SX
        Kinetic and potential energy (scalars); ``V`` may also be a finite number.
    q, v : casadi.SX
        Coordinates and their rates (symbols).
    t : casadi.SX, optional
        The time symbol (the clock) when ``T``, ``V``, ``U`` or a force depends on time
        explicitly (rheonomic system).
    forces : sequence of (casadi.SX, casadi.SX), optional
        Applied forces and their points: pairs ``(F_i, r_i)`` of equal-length columns (a force
        [N] in any fixed axes, its point's position [m] in the same axes as a function of
        ``q`` and ``t``); ``F_i`` may depend on ``q``, ``v``, ``t``. See `generalized_forces`.
    velocity_potential : casadi.SX, optional
        ``U(q, v, t)`` [J], e.g. ``U = e (phi - v . A)`` for a charge in an electromagnetic
        field (its generalized force ``d/dt dU/dv - dU/dq`` is the Lorentz force).

    Returns
    -------
    (casadi.SX, casadi.SX)
        ``M`` (n x n) and ``Q`` (n x 1).

    Raises
    ------
    TypeError
        If ``T``, ``q``, ``v``, ``t``, ``velocity_potential`` or a force is not a CasADi SX/MX
        expression, or ``V`` is neither one nor a real number.
    ValueError
        If ``T``, ``V`` or ``velocity_potential`` is not a scalar (1 x 1), a numeric ``V`` is
        not finite, or a force and its point differ in length.

    Examples
    --------
    >>> import casadi as ca
    >>> from appdyn.dynamics.mechanisms import lagrange_terms
    >>> q, v = ca.SX.sym("q"), ca.SX.sym("v")
    >>> M, Q = lagrange_terms(0.5 * 2.0 * v ** 2, 0.5 * 8.0 * q ** 2, q, v)
    >>> float(M), ca.Function("Q", [q], [Q])(0.5)
    (2.0, DM(-4))

    A force ``-c v`` on the point ``r = 2 q`` adds ``Q = -4 c v``:

    >>> M, Q = lagrange_terms(0.5 * v ** 2, 0.0, q, v, forces=[(-0.5 * 2 * v, 2 * q)])
    >>> ca.Function("Q", [v], [Q])(1.0)
    DM(-2)
    """
    V = V if validate.is_symbolic(V) else validate.finite_scalar(V, "V")
    U = velocity_potential
    for name, a in (("T", T), ("V", V), ("q", q), ("v", v), ("t", t),
                    ("velocity_potential", U)):
        if (name == "V" and not validate.is_symbolic(V)) or (name in ("t", "velocity_potential")
                                                             and a is None):
            continue
        if not validate.is_symbolic(a):
            raise validate.ArgumentTypeError(f"`{name}` must be a casadi SX/MX expression, "
                                             f"got {type(a).__name__}")
        if name in ("T", "V", "velocity_potential") and a.shape != (1, 1):
            raise ValueError(f"`{name}` must be a scalar (1x1) expression, got shape {a.shape}")
    if U is None:
        M = ca.hessian(T, v)[0]
        Q = ca.gradient(T - V, q) - ca.jtimes(ca.gradient(T, v), q, v)
        p = ca.gradient(T, v)
    else:
        p = ca.gradient(T - U, v)
        M = ca.jacobian(p, v)
        Q = ca.gradient(T - V - U, q) - ca.jtimes(p, q, v)
    if t is not None:
        Q = Q - ca.jacobian(p, t)
    if len(forces):
        Q = Q + generalized_forces(forces, q)
    return M, Q


def generalized_forces(forces, q):
    """Generalized forces of applied forces, ``Q_k = sum_i F_i^T dr_i/dq_k`` (seed Eq. 5.26).

    Parameters
    ----------
    forces : sequence of (casadi.SX, casadi.SX)
        Pairs ``(F_i, r_i)``: a force [N] and the position [m] of its point of application
        (columns of equal length, components in the same fixed axes), ``r_i`` a function of
        ``q`` (and time); a torque pairs with an angle in the same way (``(L, phi)``).
    q : casadi.SX
        The generalized coordinates (symbols), n x 1.

    Returns
    -------
    casadi.SX, n x 1
        The virtual work of the forces per unit virtual displacement of each coordinate.

    Raises
    ------
    TypeError
        If ``forces`` is not a sequence of pairs of CasADi expressions.
    ValueError
        If a force and its point differ in length.

    Examples
    --------
    The seed's double pendulum (Sec. 5.3): gravity ``m g`` along ``y`` (down) on two masses:

    >>> import casadi as ca
    >>> from appdyn.dynamics.mechanisms.lagrange import generalized_forces
    >>> th = ca.SX.sym("th", 2)
    >>> r1 = ca.vertcat(ca.sin(th[0]), ca.cos(th[0]))
    >>> r2 = r1 + ca.vertcat(ca.sin(th[1]), ca.cos(th[1]))
    >>> Q = generalized_forces([(ca.vertcat(0, 9.0), r1), (ca.vertcat(0, 1.0), r2)], th)
    >>> ca.Function("Q", [th], [Q])([ca.pi / 2, ca.pi / 2]).T  # -(m1 + m2) g l1, -m2 g l2
    DM([[-10, -1]])
    """
    if not validate.is_symbolic(q):
        raise validate.ArgumentTypeError(f"`q` must be a casadi SX column of coordinate "
                                         f"symbols, got {type(q).__name__}")
    try:
        pairs = [tuple(pair) for pair in forces]
    except TypeError:
        raise validate.ArgumentTypeError(f"`forces` must be a sequence of (force, point) pairs, "
                                         f"got {type(forces).__name__}") from None
    Q = ca.SX.zeros(q.numel())
    for k, pair in enumerate(pairs):
        if len(pair) != 2 or not all(validate.is_symbolic(a) or isinstance(a, (ca.DM, float, int))
                                     for a in pair):
            raise validate.ArgumentTypeError(f"`forces`[{k}] must be a pair (force, point) of "
                                             f"casadi expressions, got {pair!r}")
        F, r = ca.vec(ca.SX(pair[0])), ca.vec(ca.SX(pair[1]))
        if F.numel() != r.numel():
            raise ValueError(f"`forces`[{k}]: the force has {F.numel()} components and its "
                             f"point {r.numel()}; they must match")
        Q = Q + ca.mtimes(ca.jacobian(r, q).T, F)
    return Q


def lagrange_model(coords, rates, T, V=0.0, *, t=None, forces=(), velocity_potential=None,
                   params=None, p_default=None, units=None, name: str = "lagrange") -> Model:
    """A `Model` from Lagrange's equations with generalized forces (seed Eqs. 5.39-5.47).

    ``x = [q, q', (t)]`` with ``M q'' = Q`` of `lagrange_terms` (solved symbolically):
    applied forces at points, explicit time (rheonomic ``T``, moving supports) and a
    velocity-dependent potential.

    Parameters
    ----------
    coords, rates : mapping of str to casadi.SX, or sequence of (str, casadi.SX)
        The coordinates and their rates: names and scalar symbols, in order (as many rates
        as coordinates).
    T, V : casadi.SX (V also a number)
        Kinetic and potential energy [J] in the coordinates, rates, parameters (and ``t``).
    t : casadi.SX, optional
        The time symbol: the model then carries the clock state ``t`` last
        (`dynamics.clock`).
    forces, velocity_potential
        As `lagrange_terms`.
    params : mapping of str to casadi.SX, or sequence of (str, casadi.SX), optional
        Parameters, with ``p_default`` (by name or in order), as
        `dynamics.model.model_from_expressions`.
    units : mapping of str to str, optional
    name : str, optional

    Returns
    -------
    Model
        States: the coordinates, the rates (and ``t``); no controls; invariant ``jacobi``
        [J], Jacobi's integral ``h = q' . dL/dq' - L`` (``T + V`` for a natural system:
        conserved when ``L`` has no explicit time and there are no applied forces).

    Raises
    ------
    ValueError
        If ``coords`` and ``rates`` differ in length; the errors of `lagrange_terms` and
        `dynamics.model.model_from_expressions`.

    Examples
    --------
    A charge ``e`` in a uniform field ``B`` along ``z``: ``U = -e v . A``, ``A = 1/2 B x r``
    gives the Lorentz force ``e v x B`` (gyration at ``e B / m``):

    >>> import casadi as ca
    >>> from appdyn.dynamics.mechanisms import lagrange_model
    >>> x, y, vx, vy = (ca.SX.sym(n) for n in ("x", "y", "vx", "vy"))
    >>> A = 0.5 * 2.0 * ca.vertcat(-y, x)                       # B = 2 T, e = m = 1
    >>> model = lagrange_model({"x": x, "y": y}, {"vx": vx, "vy": vy},
    ...                        0.5 * (vx ** 2 + vy ** 2),
    ...                        velocity_potential=-ca.dot(ca.vertcat(vx, vy), A))
    >>> model.rhs([0.0, 0.0, 1.0, 0.0]).tolist()               # e v x B = (0, -2)
    [1.0, 0.0, 0.0, -2.0]
    """
    q_named = dict(zip(*named_symbols(coords, "coords", required=True)))
    v_named = dict(zip(*named_symbols(rates, "rates", required=True)))
    if len(q_named) != len(v_named):
        raise ValueError(f"`rates` must name one rate per coordinate ({len(q_named)}), got "
                         f"{len(v_named)}")
    q, v = ca.vertcat(*q_named.values()), ca.vertcat(*v_named.values())
    M, Q = lagrange_terms(T, V, q, v, t=t, forces=forces, velocity_potential=velocity_potential)
    vdot = ca.solve(M, Q)
    U = 0.0 if velocity_potential is None else velocity_potential
    L = T - V - U
    states = [*q_named.items(), *v_named.items()] + ([(CLOCK_STATE, t)] if t is not None else [])
    xdot = [*v_named.values(), *ca.vertsplit(vdot)] + ([1.0] if t is not None else [])
    units = {**({CLOCK_STATE: CLOCK_UNIT} if t is not None else {}), **dict(units or {})}
    return model_from_expressions(states, xdot, params=params, p_default=p_default,
                                  units=units, name=name,
                                  invariants={"jacobi": ca.dot(v, ca.gradient(L, v)) - L})


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
