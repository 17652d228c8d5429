"""Closed-form truth models of torque-free rigid-body rotation (numpy/scipy only).

These functions are *independent references* for the tests and benchmarks of the simulation
code: they use no integrator and none of appdyn's model code, only closed forms (Rheinfurth & Wilson, NASA RP-1262,
Sec. 4.5; Landau & Lifshitz, Mechanics, Sec. 37). Even the quaternion product and the
direction cosine matrix they need are written out here rather than imported from
``dynamics.attitude``, so that a bug there cannot hide itself. (Only the input checks are
shared: `dynamics.validate`.)

Conventions (the project's):

* Principal body axes; ``inertia_diag`` holds the three principal moments in **any** order
  (equal moments allowed). Euler's torque-free equations ``I1 w1' = (I2 - I3) w2 w3``
  (cyclic), i.e. ``I w' = (I w) x w``.
* Quaternion scalar-last ``q = [q1, q2, q3, q4]``, ``q4 = cos(delta/2)``. The DCM
  ``A(q) = (q4^2 - |qv|^2) E + 2 qv qv^T - 2 q4 [qv x]`` maps inertial to body components.
  Kinematics ``qv' = 1/2 (q4 w + qv x w)``, ``q4' = -1/2 w . qv`` with body rates ``w``.
  ``quat_mul(q, p) = [q4 pv + p4 qv - qv x pv, q4 p4 - qv . pv]``, so that
  ``A(quat_mul(q, p)) = A(q) A(p)``.
* Arrays are components first: rates ``(3, n)``, quaternions ``(4, n)``. A time argument
  ``t`` is a scalar or a 1-D array of ``n`` times [s]; a scalar gives ``n = 1``. Times need not
  be sorted and may be negative (the closed forms hold for all real ``t``).
* SI units, radians.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
from scipy.special import elliprf, ellipkm1

from . import validate

__all__ = [
    "TorqueFreeParameters",
    "torque_free_parameters",
    "torque_free_omega",
    "axisymmetric",
    "constant_rate_quat",
    "energy",
    "momentum_magnitude",
    "ConeAngles",
    "cone_angles",
    "small_asymmetry_rates",
    "small_asymmetry_frequency",
    "SymmetricPrecession",
    "symmetric_precession",
]

# Relative tolerance of the triangle inequality (same as dynamics.validate.check_inertia)
# and of "equal moments" in `axisymmetric`.
_TRIANGLE_RTOL = 1e-12
_EQUAL_RTOL = 1e-12
# Rate components below this fraction of the largest are flushed to zero (see below).
_FLUSH = 1e-140


# ------------------------------------------------------------------ input validation
def _moments(inertia_diag, name="inertia_diag"):
    """Three positive principal moments that satisfy the triangle inequality."""
    a = validate.finite_array(inertia_diag, name, (3,))
    if np.any(a <= 0):
        raise ValueError(f"`{name}` must be positive principal moments, got {a.tolist()}")
    s = np.sort(a)
    if s[0] + s[1] < s[2] * (1 - _TRIANGLE_RTOL):
        raise ValueError(
            f"`{name}` violates the triangle inequality I_i + I_j >= I_k of principal "
            f"moments (Rheinfurth & Wilson, NASA RP-1262, Sec. 4.4 A), got {a.tolist()}"
        )
    return a


def _rates(w, name="w"):
    """Body rates, shape (3,) or (3, n)."""
    a = validate.finite_array(w, name, (3,), batch=True)
    if a.ndim > 2:
        raise ValueError(f"`{name}` must have shape (3,) or (3, n), got {a.shape}")
    return a


def _times(t, name="t"):
    """A time or a 1-D array of times, as a 1-D array."""
    a = validate.finite_array(t, name)
    if a.ndim > 1:
        raise ValueError(f"`{name}` must be a scalar or 1-D array of times, got shape {a.shape}")
    return np.atleast_1d(a)


# --------------------------------------------------- private quaternion / DCM kernels
def _quat_mul(q, p):
    """``[q4 pv + p4 qv - qv x pv, q4 p4 - qv . pv]``; shapes (4,) / (4, n) broadcast."""
    qv, q4 = q[:3], q[3]
    pv, p4 = p[:3], p[3]
    vec = q4 * pv + p4 * qv - np.cross(qv, pv, axis=0)
    sca = q4 * p4 - np.sum(qv * pv, axis=0)
    return np.concatenate([vec, np.expand_dims(sca, 0)], axis=0)


def _axis_quat(e, angle):
    """``[e sin(angle/2), cos(angle/2)]``, shape (4, n); ``A(q) = Rot(e, angle)^T``."""
    half = 0.5 * np.asarray(angle, dtype=float)
    return np.concatenate([np.outer(e, np.sin(half)), np.cos(half)[None, :]], axis=0)


def _dcm(q):
    """Eq. 4.63, ``A = (q4^2 - |qv|^2) E + 2 qv qv^T - 2 q4 [qv x]``, for one unit ``q``."""
    qv, q4 = q[:3], q[3]
    cross = np.array([[0.0, -qv[2], qv[1]], [qv[2], 0.0, -qv[0]], [-qv[1], qv[0], 0.0]])
    return (q4 * q4 - qv @ qv) * np.eye(3) + 2.0 * np.outer(qv, qv) - 2.0 * q4 * cross


# ------------------------------------------------------------------ simple invariants
def energy(inertia_diag, w):
    """Rotational kinetic energy ``T = 1/2 sum_i I_i w_i^2``.

    Parameters
    ----------
    inertia_diag : array_like, shape (3,) [kg m^2]
        Principal moments, any order.
    w : array_like, shape (3,) or (3, n) [rad/s]
        Body rates in the same principal axes.

    Returns
    -------
    float or ndarray, shape (n,) [J]
    """
    inertia = _moments(inertia_diag)
    w = _rates(w)
    col = inertia if w.ndim == 1 else inertia[:, None]
    return 0.5 * np.sum(col * w * w, axis=0)


def momentum_magnitude(inertia_diag, w):
    """Magnitude of the angular momentum ``|H| = |diag(I) w|``.

    Parameters
    ----------
    inertia_diag : array_like, shape (3,) [kg m^2]
        Principal moments, any order.
    w : array_like, shape (3,) or (3, n) [rad/s]
        Body rates in the same principal axes.

    Returns
    -------
    float or ndarray, shape (n,) [kg m^2/s]
    """
    inertia = _moments(inertia_diag)
    w = _rates(w)
    col = inertia if w.ndim == 1 else inertia[:, None]
    return np.linalg.norm(col * w, axis=0)


# ------------------------------------------------------ general torque-free solution
class TorqueFreeParameters(NamedTuple):
    """Constants of the Jacobi-elliptic solution of Euler's torque-free equations.

    The solution is ``w_i(t) = amplitudes[i] * f_i(u0 + lam t | m)`` with ``f_i`` the Jacobi
    function named ``functions[i]`` (``'sn'``, ``'cn'`` or ``'dn'``) of parameter ``m = k^2``.
    Components are in the caller's axis order.

    Attributes
    ----------
    branch : str
        ``'major'`` when ``D >= I_mid`` (the polhode encircles the axis of the largest
        moment; includes the separatrix ``D == I_mid``), ``'minor'`` when ``D < I_mid``
        (it encircles the axis of the smallest moment), ``'steady'`` for a constant rate
        (zero rate, spin about a principal axis, a sphere, or an axisymmetric body turning
        about a transverse axis).
    axis : int or None
        Index (caller's order) of the principal axis the polhode encircles; ``None`` when
        ``branch == 'steady'``.
    lam : float [rad/s]
        Rate of the elliptic argument ``u`` (``>= 0``; ``0`` for a steady rate).
    m : float
        Parameter ``k^2`` in ``[0, 1]`` (``1`` on the separatrix; ``0`` when steady).
    m1 : float
        Complementary parameter ``1 - m``, computed separately to full relative accuracy
        (it matters near the separatrix, where ``1 - m`` in floating point loses digits).
    u0 : float
        Elliptic argument at ``t = 0``, ``F(phi0 | m)`` with ``phi0`` in ``[-pi/2, pi/2]``.
    amplitudes : ndarray, shape (3,) [rad/s]
        Signed amplitudes per axis (caller's order).
    functions : tuple of str, length 3
        Jacobi function per axis (caller's order); ``('dn', 'dn', 'dn')`` when steady.
    D : float [kg m^2]
        ``H^2 / (2 T)``, between the smallest and largest moment (``nan`` for zero rate).
    period : float [s]
        Period of ``w(t)``, ``4 K(m) / lam``; ``inf`` on the separatrix and when steady.
    """

    branch: str
    axis: int | None
    lam: float
    m: float
    m1: float
    u0: float
    amplitudes: np.ndarray
    functions: tuple
    D: float
    period: float


def _jacobi(u, m, m1):
    """Jacobi ``sn, cn, dn`` of argument ``u`` (array) and parameter ``m``, ``m1 = 1 - m``.

    Arithmetic-geometric mean method (Abramowitz & Stegun 16.4) started from
    ``b0 = sqrt(m1)`` with the *given* complementary parameter, so that ``m`` close to 1
    (near the separatrix) keeps full relative accuracy of ``1 - m``, which
    ``scipy.special.ellipj(u, m)`` cannot since it only receives ``m``.
    """
    u = np.asarray(u, dtype=float)
    if m1 == 0.0:
        return np.tanh(u), 1.0 / np.cosh(u), 1.0 / np.cosh(u)
    if m == 0.0:
        return np.sin(u), np.cos(u), np.ones_like(u)
    a, b, c = 1.0, np.sqrt(m1), np.sqrt(m)
    ratios = []
    while abs(c) > 1e-17 * a and len(ratios) < 64:
        a, b, c = 0.5 * (a + b), np.sqrt(a * b), 0.25 * c * c / (0.5 * (a + b))
        ratios.append(c / a)
    phi = np.ldexp(a * u, len(ratios))
    for ratio in reversed(ratios):
        phi = 0.5 * (phi + np.arcsin(ratio * np.sin(phi)))
    sn, cn = np.sin(phi), np.cos(phi)
    return sn, cn, np.sqrt(cn * cn + m1 * sn * sn)


def _elliptic_f(sn, cn, m1):
    """Incomplete integral ``F(phi | m)`` from ``sin(phi) = sn`` and ``cos(phi) = cn >= 0``
    (``phi`` in ``[-pi/2, pi/2]``), via Carlson's ``R_F(cn^2, cn^2 + m1 sn^2, 1)``, which
    keeps full accuracy for ``m`` near 1 and ``phi`` near ``+-pi/2``."""
    norm = np.hypot(sn, cn)
    sn, cn = sn / norm, cn / norm
    return float(sn * elliprf(cn * cn, cn * cn + m1 * sn * sn, 1.0))


def _parameters(num, comp, den):
    """``m = num / den`` and ``m1 = 1 - m = comp / den``, each to full relative accuracy."""
    m, m1 = num / den, comp / den
    return min(max(m, 0.0), 1.0), min(max(m1, 0.0), 1.0)


def _sorted_solution(inertia, w):
    """Elliptic solution for ascending moments ``I1 <= I2 <= I3`` (scaled to order 1) and
    rates ``w`` scaled to order 1. Returns ``(branch, amplitudes, functions, lam, m, m1, u0)``
    in the sorted axes."""
    i1, i2, i3 = inertia
    w1, w2, w3 = w
    if (i2 - i3) * w2 * w3 == 0 and (i3 - i1) * w3 * w1 == 0 and (i1 - i2) * w1 * w2 == 0:
        # Euler's right-hand side vanishes: the rate is constant.
        return "steady", w.copy(), ("dn", "dn", "dn"), 0.0, 0.0, 1.0, 0.0
    d21, d31, d32 = i2 - i1, i3 - i1, i3 - i2  # d31 > 0: a sphere is always steady
    # Differences of the invariants, written without cancellation (sums of non-negatives):
    p = i1 * d31 * w1**2 + i2 * d32 * w2**2  # 2T I3 - H^2 >= 0
    q = i2 * d21 * w2**2 + i3 * d31 * w3**2  # H^2 - 2T I1 >= 0
    r = i3 * d32 * w3**2 - i1 * d21 * w1**2  # H^2 - 2T I2, sign selects the branch
    amp1 = np.sqrt(w1**2 + i2 * d32 * w2**2 / (i1 * d31))  # |w1| at sn = 0
    amp3 = np.sqrt(w3**2 + i2 * d21 * w2**2 / (i3 * d31))  # |w3| at sn = 0
    s1 = 1.0 if w1 >= 0 else -1.0
    s3 = 1.0 if w3 >= 0 else -1.0
    # Oblate-symmetric (I1 == I2) bodies have D >= I2 always, prolate (I2 == I3) D <= I2;
    # choosing the branch this way keeps every formula below free of 0/0.
    major = d21 == 0 or (d32 != 0 and r >= 0)
    if major:
        # w = (a1 cn, a2 sn, a3 dn): Euler's equations give a1 lam = d32/I1 a2 a3,
        # a2 lam = d31/I2 a1 a3, a3 lam m = d21/I3 a1 a2, so sign(a2) = sign(a1 a3).
        amp2 = np.sqrt(w2**2 + i1 * d31 * w1**2 / (i2 * d32))  # |w2| at sn = +-1
        lam = np.sqrt(d32 * q / (i1 * i2 * i3))
        m, m1 = _parameters(d21 * p, d31 * r, d32 * q)
        # cn0 = |w1|/amp1 >= 0 and sn0 = w2 / (s1 s3 amp2): phi0 in [-pi/2, pi/2].
        sn0, cn0 = s1 * s3 * w2 * amp1, abs(w1) * amp2  # both times amp1 amp2 > 0
        functions = ("cn", "sn", "dn")
    else:
        # w = (b1 dn, b2 sn, b3 cn): b1 lam m = d32/I1 b2 b3, b2 lam = d31/I2 b1 b3,
        # b3 lam = d21/I3 b1 b2, so again sign(b2) = sign(b1 b3).
        amp2 = np.sqrt(w2**2 + i3 * d31 * w3**2 / (i2 * d21))
        lam = np.sqrt(d21 * p / (i1 * i2 * i3))
        m, m1 = _parameters(d32 * q, -d31 * r, d21 * p)
        sn0, cn0 = s1 * s3 * w2 * amp3, abs(w3) * amp2
        functions = ("dn", "sn", "cn")
    amplitudes = np.array([s1 * amp1, s1 * s3 * amp2, s3 * amp3])
    u0 = _elliptic_f(sn0, cn0, m1)
    return ("major" if major else "minor"), amplitudes, functions, float(lam), m, m1, u0


def _pow2(x):
    """The power of two nearest above ``x > 0`` (scaling by it is exact)."""
    return float(np.ldexp(1.0, int(np.frexp(x)[1])))


def _proper_sort(inertia):
    """Signed permutation ``S`` (det +1) with ``S diag(I) S^T`` ascending, and the order."""
    order = np.argsort(inertia, kind="stable")
    perm = np.zeros((3, 3))
    perm[np.arange(3), order] = 1.0
    # An odd permutation reverses cross products; -perm is then proper, and Euler's
    # equations (invariant under proper rotations) keep their form for w_s = S w.
    return perm * np.linalg.det(perm), order


def torque_free_parameters(inertia_diag, w0):
    """Constants of the exact (Jacobi-elliptic) torque-free solution for initial rates ``w0``.

    Parameters
    ----------
    inertia_diag : array_like, shape (3,) [kg m^2]
        Principal moments in any order; equal moments allowed. Must be positive and satisfy
        the triangle inequality.
    w0 : array_like, shape (3,) [rad/s]
        Body rates at ``t = 0`` in the same principal axes.

    Returns
    -------
    TorqueFreeParameters
        ``w_i(t) = amplitudes[i] * f_i(u0 + lam t | m)``; see the class for the fields.

    Raises
    ------
    ValueError
        Naming ``inertia_diag`` or ``w0`` for a wrong shape, non-finite values, non-positive
        moments or a violated triangle inequality.

    Notes
    -----
    The moments are reduced to ascending order ``I1 <= I2 <= I3`` by a *proper* signed
    permutation ``S`` (``S = -P`` for an odd permutation ``P``), under which Euler's
    equations keep their form. With ``P = 2T I3 - H^2``, ``Q = H^2 - 2T I1``,
    ``R = H^2 - 2T I2`` (``D = H^2/(2T)``):

    * ``D >= I2``: ``w = (a1 cn, a2 sn, a3 dn)``, ``lam^2 = (I3-I2) Q / (I1 I2 I3)``,
      ``m = (I2-I1) P / ((I3-I2) Q)``;
    * ``D < I2``: ``w = (b1 dn, b2 sn, b3 cn)``, ``lam^2 = (I2-I1) P / (I1 I2 I3)``,
      ``m = (I3-I2) Q / ((I2-I1) P)``;

    with ``a1^2 = b1^2 = P / (I1 (I3-I1))``, ``a3^2 = b3^2 = Q / (I3 (I3-I1))``,
    ``a2^2 = P / (I2 (I3-I2))``, ``b2^2 = Q / (I2 (I2-I1))`` and signs
    ``sign(a1) = sign(w1(0))``, ``sign(a3) = sign(w3(0))``, ``sign(a2) = sign(a1 a3)``
    (likewise for ``b``), which keeps ``cn(u0) >= 0`` and hence ``phi0`` in
    ``[-pi/2, pi/2]``; this also covers the separatrix ``m = 1`` where ``cn = dn = sech``
    never change sign. ``P``, ``Q``, ``R`` are evaluated from ``w0`` without cancellation
    (``P = I1 (I3-I1) w1^2 + I2 (I3-I2) w2^2`` etc.), which keeps axisymmetric and
    nearly axisymmetric bodies free of 0/0. Oblate bodies (``I1 == I2``) always use the
    first branch, prolate ones (``I2 == I3``) the second.
    """
    inertia = _moments(inertia_diag)
    w0 = validate.finite_array(w0, "w0", (3,))
    if not np.any(w0):
        return TorqueFreeParameters(
            "steady", None, 0.0, 0.0, 1.0, 0.0, w0.copy(), ("dn", "dn", "dn"), float("nan"),
            float("inf"),
        )
    # Scale moments and rates by powers of two (exact, so e.g. an exactly representable
    # separatrix stays exact) to keep squares and products far from over/underflow.
    scale, rate = _pow2(inertia.max()), _pow2(np.abs(w0).max())
    sign_perm, order = _proper_sort(inertia)
    w_sorted = sign_perm @ (w0 / rate)
    # Components below 1e-140 of the largest would underflow when squared; they are zero to
    # working precision (their influence stays below 1e-140 |w| unless amplified by the
    # unstable intermediate-axis spin over more than ~300 / lam seconds).
    w_sorted[np.abs(w_sorted) < _FLUSH] = 0.0
    branch, amp, funcs, lam, m, m1, u0 = _sorted_solution(inertia[order] / scale, w_sorted)
    amplitudes = rate * (sign_perm.T @ amp)
    functions = [None] * 3
    for i_sorted, i_user in enumerate(order):
        functions[i_user] = funcs[i_sorted]
    lam *= rate
    if branch == "steady":
        axis, period = None, float("inf")
    else:
        axis = int(order[2] if branch == "major" else order[0])
        period = float(4.0 * ellipkm1(m1) / lam) if m1 > 0.0 else float("inf")
    wn, inn = w0 / rate, inertia / scale
    d_eff = scale * float(np.sum(inn**2 * wn**2) / np.sum(inn * wn**2))
    return TorqueFreeParameters(
        branch, axis, lam, m, m1, u0, amplitudes, tuple(functions), d_eff, period
    )


def torque_free_omega(inertia_diag, w0, t):
    """Exact body rates of a torque-free rigid body (Jacobi-elliptic solution, Euler 1758).

    Solves ``I1 w1' = (I2 - I3) w2 w3`` (cyclic) in closed form for any initial rates and
    any ordering of the principal moments, including equal moments.

    Parameters
    ----------
    inertia_diag : array_like, shape (3,) [kg m^2]
        Principal moments in any order; equal moments allowed. Positive, triangle inequality.
    w0 : array_like, shape (3,) [rad/s]
        Body rates at ``t = 0`` in the same principal axes.
    t : float or array_like, shape (n,) [s]
        Times; a scalar gives ``n = 1``. Any real times, sorted or not.

    Returns
    -------
    w : ndarray, shape (3, n) [rad/s]
        Body rates at ``t``.

    Raises
    ------
    ValueError
        Naming ``inertia_diag``, ``w0`` or ``t`` for a wrong shape, non-finite values,
        non-positive moments or a violated triangle inequality.

    See Also
    --------
    torque_free_parameters : the constants ``lam``, ``m``, ``u0``, amplitudes and the
        derivation notes.

    Notes
    -----
    Seed 002, Sec. 4.5 B gives one special case (spin near the axis of the smallest moment
    with ``w2(0) = 0``); its OCR is garbled, and the branches, signs and phase used here were
    re-derived from Euler's equations with ``sn' = cn dn``, ``cn' = -sn dn``,
    ``dn' = -m sn cn``. The phase is ``u0 = F(phi0 | m)`` with ``phi0 = atan2(sn0, cn0)``,
    kept in ``[-pi/2, pi/2]`` by the sign choice of the amplitudes (``cn0 >= 0``).
    ``F`` is evaluated as ``sn0 R_F(cn0^2, cn0^2 + m1 sn0^2, 1)`` (Carlson;
    ``scipy.special.elliprf``) and ``sn, cn, dn`` by the arithmetic-geometric mean started
    from ``sqrt(m1)``: both take the complementary parameter ``m1 = 1 - m`` computed from
    ``w0`` without cancellation, so the solution keeps its accuracy near the separatrix and
    for starts close to the intermediate axis, where ``scipy.special.ellipj(u, m)`` and
    ``ellipkinc(phi, m)``, which only receive ``m``, lose accuracy (measured: 4e-7 after
    20 s from a start 1e-7 off the intermediate axis; 3e-6 after two periods from 1e-5). (For
    reference: ``ellipkinc`` does handle ``|phi| > pi/2`` by quasi-periodicity when
    ``m < 1``; it is not needed here.) Degenerate cases: zero rate, spin about a principal
    axis (including the unstable intermediate one), a sphere, and an axisymmetric body
    turning about a transverse axis give a constant rate; axisymmetric bodies otherwise
    give ``m = 0`` (circular functions); the separatrix ``D = I_mid`` gives ``m = 1`` (``tanh``/``sech``).
    """
    t = _times(t)
    prm = torque_free_parameters(inertia_diag, w0)
    if prm.branch == "steady":
        return np.repeat(prm.amplitudes[:, None], t.size, axis=1)
    sn, cn, dn = _jacobi(prm.u0 + prm.lam * t, prm.m, prm.m1)
    table = {"sn": sn, "cn": cn, "dn": dn}
    return np.stack([prm.amplitudes[i] * table[prm.functions[i]] for i in range(3)])


# ------------------------------------------------------------------ axisymmetric body
def _symmetry_axis(inertia, axis):
    tol = _EQUAL_RTOL * inertia.max()

    def equal(i, j):
        return abs(inertia[i] - inertia[j]) <= tol

    if axis is None:
        if equal(0, 1) and equal(1, 2) and equal(0, 2):
            return 0  # sphere: every axis is a symmetry axis
        candidates = [a for a in range(3) if equal((a + 1) % 3, (a + 2) % 3)]
        if len(candidates) != 1:
            raise ValueError(
                "`inertia_diag` must have two equal moments (an axisymmetric body), "
                f"got {inertia.tolist()}"
            )
        return candidates[0]
    a = validate.one_of(axis, "axis", (0, 1, 2))
    if not equal((a + 1) % 3, (a + 2) % 3):
        raise ValueError(
            f"`inertia_diag` must have equal transverse moments for symmetry `axis` {a}, "
            f"got {inertia.tolist()}"
        )
    return a


def axisymmetric(inertia_diag, w0, q0, t, *, axis=None):
    """Exact rates and attitude of a torque-free axisymmetric body.

    Parameters
    ----------
    inertia_diag : array_like, shape (3,) [kg m^2]
        Principal moments; the two transverse ones must be equal (relative ``1e-12``;
        their mean is used). Positive, triangle inequality.
    w0 : array_like, shape (3,) [rad/s]
        Body rates at ``t = 0``.
    q0 : array_like, shape (4,)
        Attitude quaternion at ``t = 0`` (scalar last, ``A(q0)`` maps inertial to body).
        Must have unit norm within ``1e-6``; it is normalized.
    t : float or array_like, shape (n,) [s]
        Times; a scalar gives ``n = 1``. Any real times.
    axis : int, optional
        Index of the symmetry axis. Inferred when ``None`` (``0`` for a sphere).

    Returns
    -------
    w : ndarray, shape (3, n) [rad/s]
        Body rates.
    q : ndarray, shape (4, n)
        Attitude quaternions, a smooth function of ``t`` with ``q[:, t == 0] == q0``; the
        sign of ``q4`` is not normalized (``q`` and ``-q`` are the same attitude).

    Raises
    ------
    ValueError
        Naming ``inertia_diag`` (bad moments, or not axisymmetric about ``axis``), ``axis``,
        ``w0``, ``q0`` or ``t``.

    Notes
    -----
    With symmetry axis ``e``, axial moment ``I_a``, transverse ``I_t``, axial rate ``n``:
    Euler's equations give ``n = const`` and ``w_perp' = lam e x w_perp`` with
    ``lam = (I_a - I_t) / I_t * n``, so the transverse rate turns about ``+e`` at ``lam``.
    Since ``h = I w = I_t w + (I_a - I_t) n e``, ``w = omega_p h_hat - lam e`` with
    ``omega_p = |H| / I_t``. With ``R = A^T`` (body to inertial) and ``R' = R [w x]``,
    ``R(t) = Rot(h_in, omega_p t) R0 Rot(e, -lam t)`` solves the kinematics (``h_in`` the
    inertially fixed unit momentum, ``Rot`` an active rotation), because
    ``R^T h_in = Rot(e, lam t) h_b(0)`` is the body momentum direction at ``t``. In
    quaternions, with ``A([e sin(a/2), cos(a/2)]) = Rot(e, a)^T``:
    ``q(t) = quat_mul(quat_mul([e sin(-lam t/2), cos(lam t/2)], q0),
    [h_in sin(omega_p t/2), cos(omega_p t/2)])``.
    """
    inertia = _moments(inertia_diag)
    a = _symmetry_axis(inertia, axis)
    w0 = validate.finite_array(w0, "w0", (3,))
    q0 = validate.unit_quaternion(q0, "q0")
    t = _times(t)
    i_ax = inertia[a]
    i_tr = 0.5 * (inertia[(a + 1) % 3] + inertia[(a + 2) % 3])
    e = np.zeros(3)
    e[a] = 1.0
    n = w0[a]
    w_perp = w0 - n * e
    lam = (i_ax - i_tr) / i_tr * n
    c, s = np.cos(lam * t), np.sin(lam * t)
    w = n * e[:, None] + np.outer(w_perp, c) + np.outer(np.cross(e, w_perp), s)
    h_body = i_tr * w0 + (i_ax - i_tr) * n * e
    h_mag = float(np.linalg.norm(h_body))
    if h_mag == 0.0:
        return w, np.repeat(q0[:, None], t.size, axis=1)
    h_in = _dcm(q0).T @ (h_body / h_mag)
    omega_p = h_mag / i_tr
    q = _quat_mul(_quat_mul(_axis_quat(e, -lam * t), q0[:, None]), _axis_quat(h_in, omega_p * t))
    return w, q


def constant_rate_quat(q0, w, t):
    """Attitude under a constant body rate: ``q(t) = quat_mul(q_rot(t), q0)``.

    Parameters
    ----------
    q0 : array_like, shape (4,)
        Attitude at ``t = 0`` (scalar last); unit norm within ``1e-6``, normalized.
    w : array_like, shape (3,) [rad/s]
        Constant body angular velocity.
    t : float or array_like, shape (n,) [s]
        Times; a scalar gives ``n = 1``. Any real times.

    Returns
    -------
    q : ndarray, shape (4, n)
        ``q_rot = [e sin(|w| t/2), cos(|w| t/2)]`` with ``e = w/|w|`` applied after ``q0``;
        ``q0`` for all ``t`` when ``w = 0``. Continuous in ``t``; ``q4`` may be negative.

    Raises
    ------
    ValueError
        Naming ``q0``, ``w`` or ``t``.

    Notes
    -----
    ``A' = -[w x] A`` with constant ``w`` gives ``A(t) = exp(-[w x] t) A0
    = Rot(e, |w| t)^T A0 = A(q_rot) A(q0)``.
    """
    q0 = validate.unit_quaternion(q0, "q0")
    w = validate.finite_array(w, "w", (3,))
    t = _times(t)
    rate = float(np.linalg.norm(w))
    if rate == 0.0:
        return np.repeat(q0[:, None], t.size, axis=1)
    return _quat_mul(_axis_quat(w / rate, rate * t), q0[:, None])


# ------------------------------------------------------------- small-motion formulas
class ConeAngles(NamedTuple):
    """Bounds of the angle between ``H`` and the principal axis its polhode encircles.

    Attributes
    ----------
    theta_min, theta_max : float [rad]
        Smallest and largest angle in ``[0, pi/2]``.
    axis : int
        Index (caller's order) of the encircled axis: largest moment if ``D >= I_mid``,
        smallest if ``D < I_mid``.
    """

    theta_min: float
    theta_max: float
    axis: int


def cone_angles(inertia_diag, w0):
    """Nutation limits of a torque-free body (Poinsot construction) [1]_.

    Parameters
    ----------
    inertia_diag : array_like, shape (3,) [kg m^2]
        Principal moments in any order; not all equal.
    w0 : array_like, shape (3,) [rad/s]
        Body rates (any point of the motion); non-zero.

    Returns
    -------
    ConeAngles
        For ascending ``I1 <= I2 <= I3``: if ``D < I2`` (about axis 1)
        ``tan^2 theta_min = I3 (D - I1) / (I1 (I3 - D))`` (where ``H2 = 0``) and
        ``tan^2 theta_max = I2 (D - I1) / (I1 (I2 - D))`` (where ``H3 = 0``); if ``D >= I2``
        (about axis 3) ``tan^2 theta_min = I1 (I3 - D) / (I3 (D - I1))`` and
        ``tan^2 theta_max = I2 (I3 - D) / (I3 (D - I2))``. On the separatrix
        ``theta_max = pi/2`` (approached asymptotically); a steady spin about the
        intermediate axis gets the values of the separatrix through it.

    Raises
    ------
    ValueError
        Naming ``inertia_diag`` (bad moments, or a sphere, where ``H`` keeps its body
        direction and no axis is singled out) or ``w0`` (bad, or zero).

    References
    ----------
    .. [1] Rheinfurth & Wilson, NASA RP-1262, Sec. 4.5 A.
    """
    inertia = _moments(inertia_diag)
    w0 = validate.finite_array(w0, "w0", (3,))
    if not np.any(w0):
        raise ValueError("`w0` must be non-zero for cone angles (H = 0 has no direction)")
    if inertia.max() == inertia.min():
        raise ValueError(f"`inertia_diag` must not be a sphere for cone angles, got {inertia.tolist()}")
    sign_perm, order = _proper_sort(inertia)
    i1, i2, i3 = inertia[order] / _pow2(inertia.max())
    w1, w2, w3 = sign_perm @ (w0 / _pow2(np.abs(w0).max()))
    d21, d31, d32 = i2 - i1, i3 - i1, i3 - i2
    p = i1 * d31 * w1**2 + i2 * d32 * w2**2  # 2T (I3 - D)
    q = i2 * d21 * w2**2 + i3 * d31 * w3**2  # 2T (D - I1)
    r = i3 * d32 * w3**2 - i1 * d21 * w1**2  # 2T (D - I2)
    if d21 == 0 or (d32 != 0 and r >= 0):
        th_min = np.arctan2(np.sqrt(i1 * p), np.sqrt(i3 * q))
        th_max = np.arctan2(np.sqrt(i2 * p), np.sqrt(i3 * r))
        axis = int(order[2])
    else:
        th_min = np.arctan2(np.sqrt(i3 * q), np.sqrt(i1 * p))
        th_max = np.arctan2(np.sqrt(i2 * q), np.sqrt(-i1 * r))
        axis = int(order[0])
    return ConeAngles(float(th_min), float(th_max), axis)


def small_asymmetry_rates(inertia_diag, spin_rate, *, axis=0):
    """Coefficients of the linearized motion about a steady spin [1]_.

    With spin axis ``a`` and the other axes ``b, c`` in cyclic order (``a, b, c`` =
    ``0, 1, 2``; ``1, 2, 0``; ``2, 0, 1``), Euler's equations linearized about
    ``w = spin_rate e_a`` read ``w_b' + lambda1 w_c = 0``, ``w_c' - lambda2 w_b = 0``.

    Parameters
    ----------
    inertia_diag : array_like, shape (3,) [kg m^2]
        Principal moments (caller's order).
    spin_rate : float [rad/s]
        Nominal spin ``w0`` about ``axis``.
    axis : int, optional
        Spin axis index, default 0 (axis 1 of [1]_).

    Returns
    -------
    lambda1, lambda2 : float [rad/s]
        ``lambda1 = (I_a - I_c) / I_b * w0``, ``lambda2 = (I_a - I_b) / I_c * w0``.

    Raises
    ------
    ValueError
        Naming ``inertia_diag``, ``spin_rate`` or ``axis``.

    References
    ----------
    .. [1] Rheinfurth & Wilson, NASA RP-1262, Sec. 4.5 C.
    """
    inertia = _moments(inertia_diag)
    w0 = validate.finite_scalar(spin_rate, "spin_rate")
    a = validate.one_of(axis, "axis", (0, 1, 2))
    b, c = (a + 1) % 3, (a + 2) % 3
    return (inertia[a] - inertia[c]) / inertia[b] * w0, (inertia[a] - inertia[b]) / inertia[c] * w0


def small_asymmetry_frequency(inertia_diag, spin_rate, *, axis=0):
    """Nutation frequency ``sqrt(lambda1 lambda2)`` of a spin about a major or minor axis.

    It is the limit of the exact elliptic rate ``lam`` as the nutation goes to zero
    [1]_. See :func:`small_asymmetry_rates` for the parameters.

    Returns
    -------
    float [rad/s]
        ``sqrt(lambda1 lambda2) >= 0``.

    Raises
    ------
    ValueError
        Naming ``axis`` if it is the intermediate axis (``lambda1 lambda2 < 0``: the
        linearized motion grows like ``exp(sqrt(-lambda1 lambda2) t)``), or the arguments
        as in :func:`small_asymmetry_rates`.

    References
    ----------
    .. [1] Rheinfurth & Wilson, NASA RP-1262, Sec. 4.5 C.
    """
    lam1, lam2 = small_asymmetry_rates(inertia_diag, spin_rate, axis=axis)
    prod = lam1 * lam2
    if prod < 0:
        raise ValueError(
            f"`axis` {axis} is the intermediate principal axis: the spin is unstable "
            f"(lambda1 lambda2 = {prod!r} < 0) and has no nutation frequency"
        )
    return float(np.sqrt(prod))


class SymmetricPrecession(NamedTuple):
    """Rates and nutation angle of a torque-free axisymmetric body.

    Attributes
    ----------
    omega_p : float [rad/s]
        Inertial precession rate ``|H| / I_t`` of the symmetry axis about ``H``; for small
        nutation ``~ I_a / I_t * n = n + lam`` (Rheinfurth & Wilson, NASA RP-1262, Sec. 4.5 C, note).
    lam : float [rad/s]
        Body-frame rate ``(I_a - I_t) / I_t * n`` at which the transverse rate turns about the
        symmetry axis (positive: counter-clockwise about ``+e``).
    nutation : float [rad]
        Constant angle between ``H`` and the symmetry axis, in ``[0, pi]``.
    axis : int
        Symmetry axis index.
    """

    omega_p: float
    lam: float
    nutation: float
    axis: int


def symmetric_precession(inertia_diag, w0, *, axis=None):
    """Precession rate, body nutation rate and nutation angle of an axisymmetric body.

    Parameters
    ----------
    inertia_diag : array_like, shape (3,) [kg m^2]
        Principal moments with two equal transverse moments (see :func:`axisymmetric`).
    w0 : array_like, shape (3,) [rad/s]
        Body rates.
    axis : int, optional
        Symmetry axis index; inferred when ``None``.

    Returns
    -------
    SymmetricPrecession

    Raises
    ------
    ValueError
        Naming ``inertia_diag``, ``axis`` or ``w0``.
    """
    inertia = _moments(inertia_diag)
    a = _symmetry_axis(inertia, axis)
    w0 = validate.finite_array(w0, "w0", (3,))
    i_ax = inertia[a]
    i_tr = 0.5 * (inertia[(a + 1) % 3] + inertia[(a + 2) % 3])
    n = w0[a]
    transverse = float(np.hypot(w0[(a + 1) % 3], w0[(a + 2) % 3]))
    h_mag = float(np.hypot(i_ax * n, i_tr * transverse))
    return SymmetricPrecession(
        h_mag / i_tr, (i_ax - i_tr) / i_tr * n, float(np.arctan2(i_tr * transverse, i_ax * n)), a
    )
