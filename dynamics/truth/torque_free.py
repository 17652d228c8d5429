"""The general torque-free rigid body: invariants and the exact Jacobi-elliptic solution.

Euler's torque-free equations ``I1 w1' = (I2 - I3) w2 w3`` (cyclic) solved in closed form for
any initial rates and any ordering of the principal moments (Rheinfurth & Wilson, NASA
RP-1262, Sec. 4.5 B; Landau & Lifshitz, Mechanics, Sec. 37).
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
from scipy.special import elliprf, ellipkm1

from .. import validate
from .common import (FLUSH, check_moments, check_rates, check_times, deprecated_field, pow2,
                     proper_sort)

__all__ = [
    "energy", "momentum_magnitude", "TorqueFreeParameters", "torque_free_parameters",
    "torque_free_omega",
]


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

    Examples
    --------
    >>> from appdyn.dynamics.truth import energy
    >>> round(float(energy([1.0, 2.0, 3.0], [1.0, 1.0, 1.0])), 6)  # (1 + 2 + 3) / 2
    3.0
    """
    inertia = check_moments(inertia_diag)
    w = check_rates(w)
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

    Examples
    --------
    >>> from appdyn.dynamics.truth import momentum_magnitude
    >>> round(float(momentum_magnitude([1.0, 2.0, 3.0], [1.0, 1.0, 1.0])), 6)  # sqrt(14)
    3.741657
    """
    inertia = check_moments(inertia_diag)
    w = check_rates(w)
    col = inertia if w.ndim == 1 else inertia[:, None]
    return np.linalg.norm(col * w, axis=0)


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
    axis_index : int or None
        Index (caller's order) of the principal axis the polhode encircles; ``None`` when
        ``branch == 'steady'`` (``.axis`` is its deprecated name).
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
    axis_index: int | None
    lam: float
    m: float
    m1: float
    u0: float
    amplitudes: np.ndarray
    functions: tuple
    D: float
    period: float

    @property
    def axis(self):
        """Deprecated name of `axis_index` (``axis`` is a 3-vector in this project)."""
        return deprecated_field(self.axis_index)


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


def _jacobi_central(u, m, m1):
    """`_jacobi` for ``|u| <= K/2`` (about), where ``m1 < 1e-16`` takes the expansion below.

    For ``m1 < 1e-16`` the AGM's last ``arcsin`` (of a ratio close to 1) leaves ``cn`` and
    ``dn`` only about ``1e-11`` absolute accuracy, while the first-order expansion in ``m1``
    (Abramowitz & Stegun 16.15) is exact to round-off as long as ``m1 sinh(u)^2 <= 1e-8``,
    which ``|u| <= K/2`` ensures (``sinh(K/2)^2 ~ 1/sqrt(m1)``).
    """
    if m1 >= 1e-16:
        return _jacobi(u, m, m1)
    tanh, sech = np.tanh(u), 1.0 / np.cosh(u)
    sc = np.sinh(u) * np.cosh(u)
    return (tanh + 0.25 * m1 * (sc - u) * sech * sech, sech - 0.25 * m1 * (sc - u) * tanh * sech,
            sech + 0.25 * m1 * (sc + u) * tanh * sech)


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
    rates ``w`` scaled to order 1. Returns ``(branch, amplitudes, functions, lam, m, m1, u0,
    quarter)`` in the sorted axes; ``quarter`` is `_quarter_phase`'s ``(s, x0)`` or ``None``."""
    i1, i2, i3 = inertia
    w1, w2, w3 = w
    if (i2 - i3) * w2 * w3 == 0 and (i3 - i1) * w3 * w1 == 0 and (i1 - i2) * w1 * w2 == 0:
        # Euler's right-hand side vanishes: the rate is constant.
        return "steady", w.copy(), ("dn", "dn", "dn"), 0.0, 0.0, 1.0, 0.0, None
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
    quarter = _quarter_phase(sn0, cn0, m, m1)
    return ("major" if major else "minor"), amplitudes, functions, float(lam), m, m1, u0, quarter


def _quarter_phase(sn0, cn0, m, m1):
    """``(s, x0)``: the phase ``x0 = u0 - s K`` from the quarter period ``s K``, ``s = sign(sn0)``.

    Where ``u`` is close to ``+-K`` (starts near the intermediate axis: ``m`` close to 1,
    ``K`` large), ``sn, cn, dn`` of ``u`` itself carry an absolute error ``eps K``, while
    ``cn`` and ``dn`` may be far smaller. With ``sn(sK + x) = s cd(x)``,
    ``cn(sK + x) = -s sqrt(m1) sd(x)`` (Abramowitz & Stegun 16.8.1) the amplitude of ``x0``
    has ``tan = -s cn0 / (sqrt(m1) |sn0|)``, so ``x0`` follows from ``sn0``, ``cn0`` (with
    any common positive factor) to full accuracy. ``None`` when ``m`` is 0 or 1.
    """
    if not 0.0 < m1 < 1.0 or m == 0.0:
        return None
    s = 1.0 if sn0 >= 0 else -1.0
    return s, _elliptic_f(-s * cn0, np.sqrt(m1) * abs(sn0), m1)


def _reduced_jacobi(u, quarter, lam_t, m, m1):
    """``sn, cn, dn`` at ``u = u0 + lam t``, from the offset ``r`` to the nearest ``j K``.

    ``r`` is ``x0 + lam t`` for ``j = s`` (`_quarter_phase`; accurate where ``u`` itself has
    lost the small ``cn`` and ``dn``) and ``u - j K`` otherwise. With ``j = 2l`` or
    ``2l + 1``: ``((-1)^l sn(r), (-1)^l cn(r), dn(r))`` for even ``j`` and
    ``((-1)^l cd(r), -(-1)^l sqrt(m1) sd(r), sqrt(m1) nd(r))`` for odd ``j`` (Abramowitz &
    Stegun 16.8; ``|r| <= K/2`` keeps ``dn(r) >= m1^(1/4)``). For ``m1 >= 1e-16`` only
    ``j = s`` is treated so; elsewhere `_jacobi` of ``u`` itself is as accurate as ``u``.
    """
    s, x0 = quarter
    k = float(ellipkm1(m1))
    j = np.rint(u / k)
    use = np.ones(u.shape, bool) if m1 < 1e-16 else (j == s)
    sn, cn, dn = (np.empty_like(u) for _ in range(3)) if np.all(use) else _jacobi(u, m, m1)
    if np.any(use):
        ju = j[use]
        r = np.where(ju == s, x0 + lam_t[use], u[use] - ju * k)
        snr, cnr, dnr = _jacobi_central(r, m, m1)
        odd = np.mod(ju, 2) == 1
        sign = np.where(np.mod(np.floor(ju / 2), 2) == 1, -1.0, 1.0)
        k1 = np.sqrt(m1)
        sn[use] = sign * np.where(odd, cnr / dnr, snr)
        cn[use] = sign * np.where(odd, -k1 * snr / dnr, cnr)
        dn[use] = np.where(odd, k1 / dnr, dnr)
    return sn, cn, dn


def _solve(inertia_diag, w0):
    """`torque_free_parameters` and `_quarter_phase`'s ``(s, x0)`` (or ``None``)."""
    inertia = check_moments(inertia_diag)
    w0 = validate.finite_array(w0, "w0", (3,))
    if not np.any(w0):
        return TorqueFreeParameters(
            "steady", None, 0.0, 0.0, 1.0, 0.0, w0.copy(), ("dn", "dn", "dn"), float("nan"),
            float("inf"),
        ), None
    # Scale moments and rates by powers of two (exact, so e.g. an exactly representable
    # separatrix stays exact) to keep squares and products far from over/underflow.
    scale, rate = pow2(inertia.max()), pow2(np.abs(w0).max())
    sign_perm, order = proper_sort(inertia)
    w_sorted = sign_perm @ (w0 / rate)
    # Components below 1e-140 of the largest would underflow when squared; they are zero to
    # working precision (their influence stays below 1e-140 |w| unless amplified by the
    # unstable intermediate-axis spin over more than ~300 / lam seconds).
    w_sorted[np.abs(w_sorted) < FLUSH] = 0.0
    branch, amp, funcs, lam, m, m1, u0, quarter = _sorted_solution(inertia[order] / scale, w_sorted)
    amplitudes = rate * (sign_perm.T @ amp)
    functions = [None] * 3
    for i_sorted, i_user in enumerate(order):
        functions[i_user] = funcs[i_sorted]
    lam *= rate
    if branch == "steady":
        axis_index, period = None, float("inf")
    else:
        axis_index = int(order[2] if branch == "major" else order[0])
        period = float(4.0 * ellipkm1(m1) / lam) if m1 > 0.0 else float("inf")
    wn, inn = w0 / rate, inertia / scale
    d_eff = scale * float(np.sum(inn**2 * wn**2) / np.sum(inn * wn**2))
    return TorqueFreeParameters(
        branch, axis_index, lam, m, m1, u0, amplitudes, tuple(functions), d_eff, period
    ), quarter



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

    Examples
    --------
    >>> from appdyn.dynamics.truth import torque_free_parameters
    >>> prm = torque_free_parameters([1.0, 2.0, 3.0], [0.1, 0.2, 0.3])
    >>> prm.branch, prm.axis_index, prm.functions
    ('major', 2, ('cn', 'sn', 'dn'))
    >>> round(float(prm.m), 6), round(prm.period, 6)
    (0.16129, 20.41488)
    """
    return _solve(inertia_diag, w0)[0]


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
    give ``m = 0`` (circular functions); the separatrix ``D = I_mid`` gives ``m = 1``
    (``tanh``/``sech``).

    ``w(0)`` is ``w0`` exactly. Near a quarter period ``u = +-K`` (where the small rates of
    a start near the intermediate axis live) the functions are evaluated from the offset to
    ``+-K`` computed directly from ``w0`` (`_quarter_phase`), and for ``1 - m < 1e-16``
    from every multiple of ``K`` by the expansion of Abramowitz & Stegun 16.15, so that
    e.g. a spin of 5 rad/s about the intermediate axis of ``(1, 2, 3)`` with a transverse
    rate of ``2.7e-83`` keeps every component to about 1e-15 of itself, not of ``|w|``.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.truth import torque_free_omega, torque_free_parameters
    >>> inertia, w0 = [1.0, 2.0, 3.0], [0.1, 0.2, 0.3]
    >>> np.round(torque_free_omega(inertia, w0, [0.0, 10.0]), 6)
    array([[ 0.1     , -0.112273],
           [ 0.2     , -0.193377],
           [ 0.3     ,  0.301444]])
    >>> period = torque_free_parameters(inertia, w0).period
    >>> np.round(torque_free_omega(inertia, w0, period)[:, 0], 6)  # back after one period
    array([0.1, 0.2, 0.3])
    """
    t = check_times(t)
    prm, quarter = _solve(inertia_diag, w0)
    if prm.branch == "steady":
        w = np.repeat(prm.amplitudes[:, None], t.size, axis=1)
    else:
        lam_t = prm.lam * t
        if quarter is None:
            sn, cn, dn = _jacobi(prm.u0 + lam_t, prm.m, prm.m1)
        else:
            sn, cn, dn = _reduced_jacobi(prm.u0 + lam_t, quarter, lam_t, prm.m, prm.m1)
        table = {"sn": sn, "cn": cn, "dn": dn}
        w = np.stack([prm.amplitudes[i] * table[prm.functions[i]] for i in range(3)])
    w[:, t == 0] = np.asarray(w0, dtype=float)[:, None]  # the initial value, exactly
    return w
