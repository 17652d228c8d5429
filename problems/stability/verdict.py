"""The verdict rule: is ``x' = A x`` unstable, marginally or asymptotically stable?

With ``rho`` the spectral radius (``|A|_2`` if every eigenvalue is 0; 1 if ``A = 0``), an
eigenvalue counts as on the imaginary axis when ``|Re| <= ZERO_RTOL * rho`` (1e-9: well above
the ~1e-16 rho round-off of LAPACK for the conservative cases, well below any physical
damping considered here). Then:

* ``"unstable"``: some ``Re > ZERO_RTOL rho``, or an eigenvalue on the axis is defective
  (a Jordan block: perturbations grow like ``t^k``);
* ``"asymptotically stable"``: every ``Re < -ZERO_RTOL rho``;
* ``"marginally stable"``: otherwise (axis eigenvalues all semisimple).

Eigenvalues on the axis within ``1e-6 rho`` of each other are grouped; a group of ``m`` is
semisimple when ``A - lambda I`` has ``m`` singular values below ``1e-5 rho`` (a Jordan
coupling weaker than that is not resolved).
"""
from __future__ import annotations

import numpy as np

from appdyn.dynamics.floquet import VERDICTS  # the three verdicts, worst first (one tuple)
from appdyn.dynamics.validate.base import real_array

from .common import format_complex

__all__ = ["ZERO_RTOL", "VERDICTS", "classify", "least_damped", "spectral_scale"]

#: eigenvalues with ``|Re| <= ZERO_RTOL * rho`` count as on the imaginary axis
ZERO_RTOL = 1e-9
_CLUSTER_RTOL = 1e-6
_RANK_RTOL = 1e-5


def spectral_scale(A: np.ndarray, ev: np.ndarray) -> float:
    """``rho`` of the verdict rule: the spectral radius, ``|A|_2`` if every eigenvalue is 0,
    1 if ``A = 0`` [1/s]."""
    rho = float(np.max(np.abs(ev), initial=0.0))
    if rho == 0.0 and A.size:
        rho = float(np.linalg.norm(A, 2))
    return rho if rho > 0 else 1.0


def least_damped(ev: np.ndarray) -> complex:
    """The eigenvalue with the largest real part (of a pair, the one with ``Im > 0``)."""
    if len(ev) == 0:
        return complex("nan")
    return complex(max(ev, key=lambda z: (z.real, z.imag)))


def classify(A, *, rtol: float = ZERO_RTOL):
    """Verdict of the linear system ``x' = A x`` (see the module notes).

    Parameters
    ----------
    A : array_like, shape (n, n) [1/s]
        The system matrix.
    rtol : float, optional
        Zero tolerance relative to the spectral scale (default `ZERO_RTOL`).

    Returns
    -------
    verdict : str
        One of `VERDICTS`.
    reason : str
        The deciding eigenvalue and the tolerance, in words.
    tolerance : float [1/s]
        ``rtol * rho``.
    eigenvalues : ndarray of complex, shape (n,)
        Sorted by (Re, Im).

    Raises
    ------
    ValueError
        Naming ``A`` (not a finite square matrix) or ``rtol`` (not in (0, 1)).

    Examples
    --------
    >>> from appdyn.problems.stability import classify
    >>> classify([[0.0, 1.0], [-1.0, 0.0]])[0]
    'marginally stable'
    >>> classify([[0.0, 1.0], [0.0, 0.0]])[0]  # a Jordan block at 0: grows like t
    'unstable'
    >>> classify([[0.0, 1.0], [-1.0, -0.1]])[0]
    'asymptotically stable'
    """
    A = real_array(A, "A")
    if A.ndim != 2 or A.shape[0] != A.shape[1] or not np.all(np.isfinite(A)):
        raise ValueError(f"`A` must be a finite square matrix, got shape {A.shape}")
    if not (np.isfinite(rtol) and 0 < rtol < 1):
        raise ValueError(f"`rtol` must be in (0, 1), got {rtol}")
    n = A.shape[0]
    ev = np.linalg.eigvals(A).astype(complex) if n else np.zeros(0, complex)
    ev = np.asarray(sorted(ev, key=lambda z: (z.real, z.imag)), dtype=complex)
    rho = spectral_scale(A, ev)
    tol = rtol * rho
    if n == 0:
        return "asymptotically stable", "no states", tol, ev
    top = least_damped(ev)
    if top.real > tol:
        return ("unstable", f"eigenvalue {format_complex(top)} has Re > {tol:.2e} (growth time "
                f"{1 / top.real:.4g} s)", tol, ev)
    axis = ev[np.abs(ev.real) <= tol]
    if len(axis) == 0:
        return ("asymptotically stable", f"every Re < -{tol:.2e}; least damped "
                f"{format_complex(top)} (time constant {-1 / top.real:.4g} s)", tol, ev)
    # group the eigenvalues on the axis and test each group for a Jordan block
    axis = axis[np.argsort(axis.imag)]
    groups, current = [], [axis[0]]
    for z in axis[1:]:
        if abs(z - current[-1]) <= _CLUSTER_RTOL * rho:
            current.append(z)
        else:
            groups.append(current)
            current = [z]
    groups.append(current)
    for g in groups:
        center = complex(0.0, float(np.mean(np.imag(g))))
        sv = np.linalg.svd(A - center * np.eye(n), compute_uv=False)
        nullity = int(np.sum(sv <= _RANK_RTOL * rho))
        if nullity < len(g):
            return ("unstable", f"eigenvalue {format_complex(center)} on the imaginary axis has "
                    f"multiplicity {len(g)} but {nullity} eigenvector(s): a Jordan block, "
                    "perturbations grow secularly", tol, ev)
    rest = n - len(axis)
    return ("marginally stable", f"{len(axis)} eigenvalue(s) with |Re| <= {tol:.2e}, all "
            "semisimple" + (f"; the other {rest} have Re < -{tol:.2e}" if rest else ""), tol, ev)


