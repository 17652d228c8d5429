"""The multiplier solve (Eqs. 5.61-5.67): accelerations, Lagrange multipliers and reaction
forces from ``M``, ``Q``, ``B`` and ``c``, for numbers (Cholesky) and CasADi symbols (QR).
"""
from __future__ import annotations

from typing import NamedTuple

import casadi as ca
import numpy as np

from ..validate import ArgumentTypeError, finite_array, is_symbolic
from .checks import CASADI_TYPES, check_constraints, column, factor_mass, is_casadi, matrix, vector

__all__ = ["ConstrainedAccelerations", "constrained_accelerations", "reaction_forces"]


class ConstrainedAccelerations(NamedTuple):
    """``vdot`` (n), multipliers ``lam`` (m) and reactions ``reaction = -B^T lam`` (n)."""

    vdot: object
    lam: object
    reaction: object


def _numeric(M, Q, B, c):
    M = finite_array(M, "M")
    chol = factor_mass(M)
    n = M.shape[0]
    Q, B = vector(Q, "Q", n), matrix(B, "B", n)
    c = vector(c, "c", B.shape[0])
    check_constraints(B, c)
    from scipy import linalg  # on first numeric solve (a heavy import)

    a0 = linalg.cho_solve(chol, Q)
    if B.shape[0] == 0:
        return a0, np.zeros(0), np.zeros(n)
    Y = linalg.cho_solve(chol, B.T)  # M^-1 B^T
    lam = linalg.cho_solve(linalg.cho_factor(B @ Y, lower=True), B @ a0 + c)
    return a0 - Y @ lam, lam, -B.T @ lam



def _symbolic(M, Q, B, c):
    kinds = {type(a) for a in (M, Q, B, c) if is_symbolic(a)}
    if len(kinds) > 1:
        raise ArgumentTypeError("`M`, `Q`, `B` and `c` must not mix casadi SX and MX")
    kind = kinds.pop()
    if not is_symbolic(M):  # numbers: check them, solve with the constant matrix
        M = finite_array(M, "M")
        factor_mass(M)
    n = M.shape[0]
    if not is_symbolic(B):
        B = matrix(B, "B", n)
        if not is_symbolic(c):
            check_constraints(B, vector(c, "c", B.shape[0]))
        else:
            check_constraints(B, None)
    M, Q, B, c = (a if is_symbolic(a) else kind(ca.DM(np.atleast_1d(finite_array(a, name))))
                  for a, name in ((M, "M"), (Q, "Q"), (B, "B"), (c, "c")))
    m = B.shape[0]
    Q, c = (ca.reshape(a, a.numel(), 1) for a in (Q, c))
    for name, a, shape in (("M", M, (n, n)), ("Q", Q, (n, 1)), ("B", B, (m, n)), ("c", c, (m, 1))):
        if a.shape != shape:
            raise ValueError(f"`{name}` must have shape {shape}, got {a.shape}")
    Y = ca.solve(M, ca.horzcat(Q, B.T))
    a0, MB = Y[:, 0], Y[:, 1:]
    if m == 0:
        return a0, kind(0, 1), kind.zeros(n, 1)
    lam = _solve_spd(ca.mtimes(B, MB), ca.mtimes(B, a0) + c)
    return a0 - ca.mtimes(MB, lam), lam, -ca.mtimes(B.T, lam)


def _solve_spd(S, r):
    """``S^-1 r`` for the symmetric positive definite ``S = B M^-1 B^T``: SX by a symbolic
    Cholesky factorization of its upper triangle (a third of QR's instructions for 5 rows),
    MX by ``casadi.solve``."""
    if isinstance(S, ca.MX):
        return ca.solve(S, r)
    R = ca.chol(ca.triu(S) + ca.triu(S, False).T)  # S = R^T R, R upper triangular
    return ca.solve(R, ca.solve(R.T, r))


def constrained_accelerations(M, Q, B, c) -> ConstrainedAccelerations:
    """Accelerations, Lagrange multipliers and reactions of ``M vdot = Q - B^T lam``,
    ``B vdot + c = 0`` (Eqs. 5.61-5.67; module docstring).

    Parameters
    ----------
    M : array_like, shape (n, n), or casadi SX/MX
        Generalized mass matrix, symmetric positive definite [kg, kg m^2, ...].
    Q : array_like, shape (n,), or casadi
        Applied plus inertial generalized forces ``Q_A + Q_I`` [N, N m, ...].
    B : array_like, shape (m, n) (or (n,) for one row), or casadi
        Constraint matrix of the velocity form ``B v + b = 0`` (holonomic or not); ``m = 0``
        is allowed.
    c : array_like, shape (m,), or casadi
        The acceleration-level term ``c = Bdot v + bdot`` of ``B vdot + c = 0`` (plus the
        Baumgarte terms, see `baumgarte`) [units of ``B vdot``].

    Returns
    -------
    ConstrainedAccelerations
        ``vdot`` (n), ``lam`` (m: ``(B M^-1 B^T)^-1 (B M^-1 Q + c)``, Eq. 5.66) and
        ``reaction`` (n: ``Q_R = -B^T lam``, Eq. 5.67). Numbers in: 1-D numpy arrays (casadi
        ``DM`` columns if an input was a ``DM``); SX/MX in: columns of that type.

    Raises
    ------
    TypeError
        If an input is not numbers or symbols, or SX and MX are mixed.
    ValueError
        Numeric input only: wrong shapes, non-finite entries, ``M`` not symmetric positive
        definite (singular, or a non-positive mass), redundant constraints (``B`` of rank
        below ``m``) or inconsistent ones (rank-deficient and ``c`` outside the range of ``B``).
        Symbolic parts cannot be checked.

    Examples
    --------
    A particle (m = 2 kg) on a circle of radius 0.5 m at 3 m/s: tension ``m v^2 / r``.

    >>> import numpy as np
    >>> from appdyn.dynamics.constrained import constrained_accelerations
    >>> x, v = np.array([0.5, 0.0]), np.array([0.0, 3.0])
    >>> res = constrained_accelerations(2.0 * np.eye(2), [0.0, 0.0], x, v @ v)
    >>> res.vdot, res.lam  # centripetal -v^2/r; lam = m v^2 / r^2 = 72
    (array([-18.,   0.]), array([72.]))
    >>> res.reaction  # Q_R = -B^T lam: 36 N toward the centre
    array([-36.,   0.])
    >>> import casadi as ca
    >>> s = ca.SX.sym("s")
    >>> B = ca.horzcat(ca.sin(s), -ca.cos(s))  # symbolic: a Function of s can be built
    >>> constrained_accelerations(np.eye(2), ca.vertcat(0, -9.81), B, 0.0).lam.shape
    (1, 1)
    """
    if any(is_symbolic(a) for a in (M, Q, B, c)):
        return ConstrainedAccelerations(*_symbolic(M, Q, B, c))
    out = _numeric(M, Q, B, c)
    if any(isinstance(a, ca.DM) for a in (M, Q, B, c)):
        out = tuple(ca.DM(o) for o in out)
    return ConstrainedAccelerations(*out)


def reaction_forces(B, lam):
    """Generalized reaction forces ``Q_R = -B^T lam`` (Eqs. 5.59, 5.63).

    Parameters
    ----------
    B : array_like, shape (m, n), or casadi
    lam : array_like, shape (m,), or casadi

    Returns
    -------
    shape (n,) (numpy) or n x 1 (casadi)

    Examples
    --------
    >>> from appdyn.dynamics.constrained import reaction_forces
    >>> reaction_forces([[1.0, 0.5, 2.0]], [3.0])
    array([-3. , -1.5, -6. ])
    """
    if is_casadi(B, lam):
        B = B if isinstance(B, CASADI_TYPES) else ca.DM(matrix(B, "B"))
        return -ca.mtimes(B.T, column(lam, "lam"))
    B = matrix(B, "B")
    return -B.T @ vector(lam, "lam", B.shape[0])
