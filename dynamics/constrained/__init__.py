"""Lagrange multipliers: accelerations, multipliers and reaction forces of constrained systems,
with constraint drift control (Rheinfurth & Wilson, NASA RP-1262, Sec. 5.5, Eqs. 5.56-5.67;
Ch. 6, Eqs. 6.15-6.17; Appendix A).

Derivation
----------
Generalized velocities ``v`` (n: coordinate rates, or quasi-velocities such as body rates,
Eq. 6.2), a generalized mass matrix ``M`` (n x n, symmetric positive definite), the applied
plus inertial forces ``Q = Q_A + Q_I`` (Eq. 5.61) and ``m`` constraints in velocity form
(Eq. 5.62; Eq. 6.16 for quasi-velocities)::

    B v + b = 0                  holonomic rows: B v + b = d/dt phi(q, t)

The reactions do no work on any virtual displacement the constraints allow. Adding
``lam_j`` times each virtual constraint row to the virtual work (Eqs. 5.57-5.58, the
multiplier rule of Appendix A) gives::

    Q_R = -B^T lam                                                   (5.59, 5.63)

(authors who subtract the rows get ``+B^T lam``: the seed's note after Eq. 5.59). One time
derivative of the constraint::

    B vdot + c = 0,      c = Bdot v + bdot                           (5.64)

``c`` is everything but the acceleration term; for holonomic rows ``c = d/dt (B v + b)`` at
fixed ``v``. Inserting ``vdot = M^-1 (Q - B^T lam)`` (5.61) gives ``B M^-1 (Q - B^T lam) =
-c`` (5.65), hence::

    lam = (B M^-1 B^T)^-1 (B M^-1 Q + c)                             (5.66)
    vdot = M^-1 (Q - B^T lam),     Q_R = -B^T lam                    (5.67)

re-derived here: the OCR of 5.67 prints ``(C M^-1)^-1`` for ``(C M^-1 C^T)^-1``. It is the
KKT system ``[[M, B^T], [B, 0]] [vdot; lam] = [Q; -c]``. Sign check: a particle of mass
``m`` on a circle of radius ``r``, ``phi = (x.x - r^2)/2``, ``B = x^T``, ``c = v.v``,
``Q = 0``: ``lam = m v.v / r^2 > 0`` and ``Q_R = -lam x``, the centripetal force ``m v^2/r``
-- a positive multiplier pulls the particle in (a tension).

No explicit inverse is formed: numerically ``M`` and ``S = B M^-1 B^T`` are factored by
Cholesky; symbolically (CasADi SX/MX) ``casadi.solve`` (QR) solves with ``M`` and ``S``.

Drift control (`dynamics.constrained.drift`): Baumgarte stabilization with a time constant
``tau`` (`baumgarte`, default `DEFAULT_TIME_CONSTANT` = 1 s), projections of positions and
velocities onto the constraints (`project_positions`, `project_velocities`), and the model
invariant ``constraint_residual`` (`residual_invariant`).

Modules: `solve` (the multiplier solve: `constrained_accelerations`, `reaction_forces`),
`terms` (symbolic constraints of a model: `constraint_terms`, `residual_invariant`), `drift`
(`baumgarte`, projections), `checks` (the numeric checks of mass matrix and constraints).

Numeric input is checked (a singular or indefinite ``M``, rank-deficient ``B`` -- redundant
or inconsistent constraints -- raise ``ValueError`` naming the problem); SX/MX symbols cannot
be checked and are solved as given (numeric parts of a mixed call are still checked).
"""
from __future__ import annotations

from .drift import (DEFAULT_TIME_CONSTANT, Projection, baumgarte, project_positions,
                    project_velocities)
from .solve import ConstrainedAccelerations, constrained_accelerations, reaction_forces
from .terms import ConstraintTerms, constraint_terms, residual_invariant

__all__ = ["DEFAULT_TIME_CONSTANT", "ConstrainedAccelerations", "ConstraintTerms", "Projection",
           "constrained_accelerations", "reaction_forces", "constraint_terms", "baumgarte",
           "project_velocities", "project_positions", "residual_invariant"]
