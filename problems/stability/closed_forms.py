"""Closed forms of the stability cases (Rheinfurth & Wilson, NASA RP-1262, Secs. 4.5-4.6).

Pure numerical kernels, no models: the cases in `problems.stability` compare their computed
eigenvalues with these, and the tests check both against independent derivations.
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["principal_moments", "axis_kind", "complex_quadratic_roots", "with_conjugates",
           "rigid_spin_lambda2", "gyrostat_lambda2", "spherical_damper_roots", "method3_roots",
           "sleeping_rate"]


def principal_moments(inertia: np.ndarray, axis: np.ndarray):
    """The moment about a principal axis and the two others.

    Parameters
    ----------
    inertia : ndarray, shape (3, 3) [kg m^2]
        Symmetric positive definite.
    axis : ndarray, shape (3,)
        Unit vector, body frame; must be a principal axis of ``inertia``.

    Returns
    -------
    (Ia, Ib, Ic) : tuple of float [kg m^2]
        ``Ia = axis . inertia axis``; ``Ib <= Ic`` the moments about the two axes normal to it.

    Raises
    ------
    ValueError
        "```axis`` must be a principal axis of ``inertia``", with the residual
        ``I a - (a.I a) a`` and the principal moments and axes.

    Examples
    --------
    >>> import numpy as np
    >>> principal_moments(np.diag([2.0, 3.0, 4.5]), np.array([0.0, 1.0, 0.0]))
    (3.0, 2.0, 4.5)
    """
    I, a = inertia, axis
    v = I @ a
    Ia = float(a @ v)
    off = v - Ia * a
    if np.linalg.norm(off) > 1e-9 * np.linalg.norm(I, 2):
        vals, vecs = np.linalg.eigh(I)
        axes = "; ".join(f"{vals[k]:.6g} about [{', '.join(f'{c:.6g}' for c in vecs[:, k])}]"
                         for k in range(3))
        raise ValueError(f"`axis` must be a principal axis of `inertia`: I a - (a.I a) a = "
                         f"{off.tolist()} for a = {a.tolist()}; principal moments and axes: {axes}")
    # orthonormal basis of the plane normal to a, then the two other principal moments
    helper = np.eye(3)[int(np.argmin(np.abs(a)))]
    e1 = np.cross(a, helper)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(a, e1)
    Bm = np.array([e1, e2])
    vals = np.linalg.eigvalsh(Bm @ I @ Bm.T)
    return Ia, float(vals[0]), float(vals[1])


def axis_kind(Ia, Ib, Ic) -> str:
    """``'major'``, ``'minor'``, ``'intermediate'`` or ``'degenerate (equal moments)'``: where
    ``Ia`` lies relative to ``Ib`` and ``Ic`` (relative tolerance 1e-12)."""
    scale = max(Ia, Ib, Ic)
    lo, hi = min(Ib, Ic), max(Ib, Ic)
    if Ia > hi + 1e-12 * scale:
        return "major"
    if Ia < lo - 1e-12 * scale:
        return "minor"
    if lo + 1e-12 * scale < Ia < hi - 1e-12 * scale:
        return "intermediate"
    return "degenerate (equal moments)"


def complex_quadratic_roots(a2, a1, a0):
    """Roots of ``a2 s^2 + a1 s + a0 = 0`` with complex coefficients (stable formula).

    Returns
    -------
    (r1, r2) : tuple of complex
    """
    disc = np.sqrt(complex(a1) ** 2 - 4 * complex(a2) * complex(a0))
    sgn = 1.0 if (np.conj(a1) * disc).real >= 0 else -1.0
    qq = -0.5 * (a1 + sgn * disc)
    r1 = qq / a2
    r2 = a0 / qq if qq != 0 else -a1 / a2 - r1
    return complex(r1), complex(r2)


def with_conjugates(roots) -> np.ndarray:
    """``roots`` followed by their complex conjugates, as a complex array."""
    return np.array([*roots, *[complex(r).conjugate() for r in roots]], dtype=complex)


def rigid_spin_lambda2(Ia, Ib, Ic, rate) -> float:
    """``lambda^2 = -rate^2 (Ia - Ib)(Ia - Ic) / (Ib Ic)`` [1/s^2] of a torque-free spin about
    the principal axis of moment ``Ia`` (RP-1262, Sec. 4.5 C, Eqs. 4.94-4.95)."""
    return -rate ** 2 * (Ia - Ib) * (Ia - Ic) / (Ib * Ic)


def gyrostat_lambda2(Ia, Ib, Ic, rate, wheel_momentum) -> float:
    """``lambda^2 = -(Ia W + h - Ib W)(Ia W + h - Ic W) / (Ib Ic)`` [1/s^2] of a gyrostat
    spinning at ``W = rate`` with wheel momentum ``h`` along the axis of moment ``Ia``."""
    Ha = Ia * rate + wheel_momentum
    return -(Ha - Ib * rate) * (Ha - Ic * rate) / (Ib * Ic)


def spherical_damper_roots(It, Jd, c, Ha_rigid, Omega, wd_axial, Ia) -> np.ndarray:
    """Eigenvalues of a symmetric spinner with a spherical damper.

    Transverse (complex, ``sigma = s + i Omega``):
    ``It Jd sigma^2 + (c (It + Jd) - i Ha Jd) sigma - i c (Ha + Jd wd) = 0`` with
    ``Ha = Ia Omega + h`` (rigid part), plus conjugates; axial: ``-c (1/Ia + 1/Jd)``.

    Parameters
    ----------
    It : float [kg m^2]
        Transverse moment of the body.
    Jd : float [kg m^2]
        Damper inertia.
    c : float [N m s]
        Damper viscous coefficient.
    Ha_rigid : float [N m s]
        Axial momentum of the rigid part, ``Ia Omega + h``.
    Omega : float [rad/s]
        Spin rate of the body.
    wd_axial : float [rad/s]
        Axial rate of the damper housing.
    Ia : float [kg m^2]
        Axial moment of the body.

    Returns
    -------
    ndarray of complex, shape (5,) [1/s]
    """
    s1, s2 = complex_quadratic_roots(It * Jd, c * (It + Jd) - 1j * Ha_rigid * Jd,
                                     -1j * c * (Ha_rigid + Jd * wd_axial))
    roots = [s1 - 1j * Omega, s2 - 1j * Omega]
    return np.array([*with_conjugates(roots), -c * (1 / Ia + 1 / Jd)], dtype=complex)


def method3_roots(I1, I2, kappa, rate, *, damping=0.0):
    """Roots of ``I2 s^2 + (D - i G w0) s + K = 0`` (RP-1262, Sec. 4.6 Method III,
    Eqs. 4.122-4.127), ``G = 2 I2 - I1``, ``K = (I1 - I2) w0^2 - kappa``.

    Parameters
    ----------
    I1 : float [kg m^2]
        Axial (spin) moment.
    I2 : float [kg m^2]
        Transverse moment about the pivot or mass center.
    kappa : float [N m]
        Overturning stiffness: ``m g l`` (heavy top), ``M_alpha`` (projectile),
        ``-2 k l^2`` (rotor).
    rate : float [rad/s]
        Spin ``w0``.
    damping : float [N m s], optional
        Rotating damping ``D``.

    Returns
    -------
    (r1, r2) : tuple of complex [1/s]
        In the frame spinning at ``w0`` (their conjugates are roots too).
    G : float [kg m^2]
    K : float [N m/rad]
    """
    G = 2 * I2 - I1
    K = (I1 - I2) * rate ** 2 - kappa
    r1, r2 = complex_quadratic_roots(I2, damping - 1j * G * rate, K)
    return (r1, r2), G, K


def sleeping_rate(I1, I2, kappa) -> float:
    """Minimum spin rate ``(2 / I1) sqrt(kappa I2)`` [rad/s] of a sleeping top
    (RP-1262, Sec. 4.6, Eq. 4.128); ``kappa > 0``.

    Examples
    --------
    >>> round(sleeping_rate(0.002, 0.005, 0.3 * 9.80665 * 0.04), 6)
    24.256937
    """
    return 2 / I1 * math.sqrt(kappa * I2)
