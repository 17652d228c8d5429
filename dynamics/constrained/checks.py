"""Numeric checks of the multiplier solve: a symmetric positive definite mass matrix, full-rank
(not redundant) and consistent constraints, and array shapes named by argument.

Symbolic (SX/MX) arguments cannot be checked; callers skip them (`is_casadi` tells the kinds
apart).
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from ..validate import finite_array

__all__ = ["CASADI_TYPES", "is_casadi", "column", "matrix", "vector", "factor_mass",
           "check_constraints"]

CASADI_TYPES = (ca.SX, ca.MX, ca.DM)


def is_casadi(*args) -> bool:
    """Whether any argument is a casadi SX, MX or DM."""
    return any(isinstance(a, CASADI_TYPES) for a in args)


def column(a, name):
    """``a`` as a casadi column (numbers checked, as a DM)."""
    if isinstance(a, (ca.SX, ca.MX)):
        return ca.reshape(a, -1, 1)
    return ca.DM(np.atleast_1d(finite_array(a, name)).reshape(-1))


def matrix(a, name, n=None):
    """A finite ``(m, n)`` array (a 1-D ``(n,)`` is one row); ``ValueError`` naming ``name``."""
    a = finite_array(a, name)
    if a.ndim == 1 and n is not None and a.size == n:  # one constraint row
        a = a.reshape(1, n)
    if a.ndim != 2 or (n is not None and a.shape[1] != n):
        cols = "n" if n is None else str(n)
        raise ValueError(f"`{name}` must be a matrix of shape (m, {cols}), got {a.shape}")
    return a


def vector(a, name, size):
    """A finite 1-D array of ``size`` entries; ``ValueError`` naming ``name``."""
    a = finite_array(a, name).reshape(-1)
    if a.size != size:
        raise ValueError(f"`{name}` must have {size} entries, got {a.size}")
    return a


def factor_mass(M):
    """Cholesky factor of a checked mass matrix; ``ValueError`` naming ``M`` otherwise."""
    if M.ndim != 2 or M.shape[0] != M.shape[1]:
        raise ValueError(f"`M` must be a square matrix (n, n), got shape {M.shape}")
    scale = float(np.max(np.abs(M))) if M.size else 0.0
    if np.max(np.abs(M - M.T), initial=0.0) > 1e-12 * scale:
        raise ValueError(f"`M` must be symmetric, got {M.tolist()}")
    eig = np.linalg.eigvalsh(M)
    if M.size == 0 or not eig[0] > M.shape[0] * np.finfo(float).eps * max(eig[-1], 0.0):
        raise ValueError("`M` must be symmetric positive definite (a singular mass matrix, or "
                         "a zero or negative mass or inertia), got eigenvalues "
                         f"{tuple(eig.tolist())}")
    from scipy import linalg  # on first numeric solve (a heavy import)

    return linalg.cho_factor(M, lower=True)


def check_constraints(B, c):
    """``ValueError`` for redundant (rank-deficient) or inconsistent constraint rows."""
    m, n = B.shape
    if m == 0:
        return
    U, s, _ = np.linalg.svd(B)
    rank = int(np.sum(s > max(m, n) * np.finfo(float).eps * s[0])) if s[0] > 0 else 0
    if rank == m:
        return
    off = c - U[:, :rank] @ (U[:, :rank].T @ c) if c is not None else None
    if off is not None and np.linalg.norm(off) > 1e-9 * np.linalg.norm(c):
        raise ValueError(f"the constraints are inconsistent: `B` has rank {rank} < {m} rows and "
                         f"`c` is not in its range (off by {np.linalg.norm(off):.3g}); no "
                         f"acceleration satisfies B vdot + c = 0")
    raise ValueError(f"the constraints are redundant: `B` has rank {rank} < {m} rows (singular "
                     f"values {', '.join(f'{v:.3g}' for v in s)}); the multipliers are not "
                     "unique -- remove the dependent rows")
