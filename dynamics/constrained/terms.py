"""Symbolic constraints of a model: the velocity form ``B v + b`` and the term ``c`` by
automatic differentiation, and the model invariant ``constraint_residual``.
"""
from __future__ import annotations

from typing import NamedTuple

import casadi as ca

from ..validate import ArgumentTypeError, is_symbolic

__all__ = ["ConstraintTerms", "constraint_terms", "residual_invariant"]


class ConstraintTerms(NamedTuple):
    """Symbolic constraint terms: ``position`` (``phi``, or ``None``), ``residual``
    (``B v + b``), ``B``, ``b`` and ``c`` (``B vdot + c = 0``)."""

    position: object
    residual: object
    B: object
    b: object
    c: object


def constraint_terms(q, qdot, v, *, position=None, velocity=None, t=None) -> ConstraintTerms:
    """The velocity form ``B v + b`` and the term ``c`` of symbolic constraints, by
    automatic differentiation (CasADi SX/MX only).

    Holonomic rows ``phi(q, t) = 0`` give ``B v + b = dphi/dq qdot + dphi/dt``; velocity
    rows (nonholonomic) are given as their residual ``B v + b``; ``c = d/dt (B v + b)`` at
    fixed ``v`` (``d/dq (B v + b) qdot + d/dt (B v + b)``). The rows are stacked holonomic
    first.

    Parameters
    ----------
    q : casadi SX/MX, k x 1
        Coordinates (symbols, or a vertcat of symbols).
    qdot : casadi, k x 1
        Their rates as functions of ``(q, v)``, affine in ``v`` (e.g. ``-1/2 Wbar(w) q``).
    v : casadi, n x 1
        Generalized velocities (symbols).
    position : casadi, optional
        Holonomic constraints ``phi(q, t)``.
    velocity : casadi, optional
        Velocity-form (nonholonomic) residuals, affine in ``v``.
    t : casadi scalar symbol, optional
        Time, for rheonomic constraints.

    Returns
    -------
    ConstraintTerms
        ``position`` (``phi`` or ``None``), ``residual`` (``B v + b``), ``B`` (m x n),
        ``b`` (m) and ``c`` (m).

    Raises
    ------
    TypeError
        If an argument is not symbolic, or neither ``position`` nor ``velocity`` is given.

    Examples
    --------
    A pendulum point ``(x, y)`` at distance ``l``, with ``v = (xdot, ydot)``:

    >>> import casadi as ca
    >>> from appdyn.dynamics.constrained import constraint_terms
    >>> q, v, l = ca.SX.sym("q", 2), ca.SX.sym("v", 2), 1.5
    >>> terms = constraint_terms(q, v, v, position=(ca.sumsqr(q) - l**2) / 2)
    >>> terms.B
    SX([[q_0, q_1]])
    >>> ca.Function("c", [q, v], [terms.c])([1.5, 0.0], [0.0, 2.0])  # c = v.v
    DM(4)
    """
    for name, a in (("q", q), ("qdot", qdot), ("v", v)):
        if not is_symbolic(a):
            raise ArgumentTypeError(f"`{name}` must be a casadi SX/MX expression, "
                                    f"got {type(a).__name__}")
    if position is None and velocity is None:
        raise ArgumentTypeError("give `position` (holonomic) or `velocity` (nonholonomic) "
                                "constraints")
    rows = []
    if position is not None:
        rate = ca.jacobian(position, t) if t is not None else 0
        rows.append(ca.jtimes(position, q, qdot) + rate)
    if velocity is not None:
        rows.append(velocity)
    r = ca.vertcat(*rows)
    B = ca.jacobian(r, v)
    b = ca.substitute(r, v, type(v).zeros(v.shape))
    c = ca.jtimes(r, q, qdot) + (ca.jacobian(r, t) if t is not None else 0)
    return ConstraintTerms(position, r, B, b, c)


def residual_invariant(x, p, terms: ConstraintTerms) -> ca.Function:
    """The invariant ``constraint_residual`` of a constrained model: ``[|phi|, |B v + b|]``.

    Parameters
    ----------
    x, p : casadi SX/MX
        The model's state and parameter symbols.
    terms : ConstraintTerms
        From `constraint_terms` (``position`` may be ``None``: its norm is then 0).

    Returns
    -------
    casadi.Function
        ``(x, p) -> constraint_residual`` (2 x 1: position-level, velocity-level norm).

    Raises
    ------
    TypeError
        If ``x`` or ``p`` is not a casadi SX/MX symbol, or ``terms`` is not a
        `ConstraintTerms`.

    Examples
    --------
    >>> import casadi as ca
    >>> from appdyn.dynamics.constrained import constraint_terms, residual_invariant
    >>> x, p = ca.SX.sym("x", 4), ca.SX.sym("p", 0)
    >>> terms = constraint_terms(x[:2], x[2:], x[2:], position=(ca.sumsqr(x[:2]) - 1) / 2)
    >>> residual_invariant(x, p, terms)(ca.DM([2.0, 0.0, 1.0, 0.0]), [])
    DM([1.5, 2])
    """
    for name, a in (("x", x), ("p", p)):
        if not is_symbolic(a):
            raise ArgumentTypeError(f"`{name}` must be a casadi SX/MX symbol, "
                                    f"got {type(a).__name__}")
    if not isinstance(terms, ConstraintTerms):
        raise ArgumentTypeError(f"`terms` must be a ConstraintTerms (from `constraint_terms`), "
                                f"got {type(terms).__name__}")
    pos = 0 if terms.position is None else ca.norm_2(terms.position)
    value = ca.vertcat(pos, ca.norm_2(terms.residual))
    return ca.Function("constraint_residual", [x, p], [value], ["x", "p"], ["constraint_residual"])
