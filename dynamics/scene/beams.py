"""Clamped-free (cantilever) Euler-Bernoulli beam modes, pure numpy: roots, shapes, quadrature.

A uniform beam (length ``L``, mass per length ``m``, bending stiffness ``EI``) clamped at
``x = 0`` (``w = w' = 0``) and free at ``x = L`` (``w'' = 0``; shear balancing an optional
tip point mass ``M_t``: ``EI w''' = M_t w..``) has the normal modes of ``EI w'''' + m w.. = 0``
(Rheinfurth & Wilson, NASA RP-1262, Ch. 6, Example 6)::

    phi(x) = cosh(b x) - cos(b x) - sigma (sinh(b x) - sin(b x)),
    sigma  = (cosh(bL) + cos(bL)) / (sinh(bL) + sin(bL)),
    omega  = (bL)^2 sqrt(EI / (m L^4)),

with ``lam = bL`` the roots of the frequency equation (``mu = M_t / (m L)``)::

    1 + cos(lam) cosh(lam) + mu lam (cos(lam) sinh(lam) - sin(lam) cosh(lam)) = 0,

1.8751, 4.6941, 7.8548, 10.9955, ... without a tip mass. The roots are found by Brent's method
in ``((k - 1) pi, k pi)`` (one per interval), so any number of modes works; the shapes are
evaluated in a form free of the cancellation of ``cosh - sigma sinh`` (exponentials
``exp(b x - lam)`` and ``exp(-b x)`` only), and scaled to be mass-orthonormal:
``int m phi_i phi_j dx + M_t phi_i(L) phi_j(L) = delta_ij`` (their unit is kg^-1/2).
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from .. import cache

__all__ = ["clamped_free_roots", "ClampedFreeModes", "TabulatedModes", "gauss_legendre"]


def _frequency_function(lam: float, mu: float) -> float:
    """The frequency equation divided by ``cosh(lam)`` (finite for any ``lam``)."""
    return (1.0 / math.cosh(lam) if lam < 700 else 0.0) + math.cos(lam) + mu * lam * (
        math.cos(lam) * math.tanh(lam) - math.sin(lam))


def clamped_free_roots(modes: int, *, tip_mass_ratio: float = 0.0) -> np.ndarray:
    """The first ``modes`` roots ``lam = beta L`` of the clamped-free frequency equation.

    Parameters
    ----------
    modes : int
        Number of roots, >= 1.
    tip_mass_ratio : float, optional
        ``mu = M_t / (m L)`` >= 0, the tip mass over the beam mass.

    Returns
    -------
    numpy.ndarray, shape (modes,)
        Increasing; one in each interval ``((k - 1) pi, k pi)``, to about 1e-15 relative.

    Examples
    --------
    >>> from appdyn.dynamics.scene.beams import clamped_free_roots
    >>> clamped_free_roots(4).round(4)
    array([ 1.8751,  4.6941,  7.8548, 10.9955])
    >>> clamped_free_roots(1, tip_mass_ratio=1.0).round(4)   # a tip mass equal to the beam's
    array([1.2479])
    """
    from scipy.optimize import brentq  # a heavy import, only here

    from ..validate import integer, nonnegative
    n = integer(modes, "modes", minimum=1)
    mu = nonnegative(tip_mass_ratio, "tip_mass_ratio")
    out = np.empty(n)
    for k in range(1, n + 1):
        lo, hi = (k - 1) * math.pi + (1e-9 if k == 1 else 0.0), k * math.pi
        out[k - 1] = brentq(_frequency_function, lo, hi, args=(mu,), xtol=1e-15, rtol=8.9e-16,
                            maxiter=500)
    return out


@cache.memoize
def _leggauss(n: int) -> tuple:
    return np.polynomial.legendre.leggauss(n)


def gauss_legendre(a: float, b: float, n: int) -> tuple:
    """Gauss-Legendre nodes and weights on ``[a, b]`` (``n`` points, exact to degree 2n-1).

    Examples
    --------
    >>> from appdyn.dynamics.scene.beams import gauss_legendre
    >>> x, w = gauss_legendre(0.0, 2.0, 3)
    >>> round(float(w @ x**5), 12)      # 2**6 / 6
    10.666666666667
    """
    t, w = _leggauss(int(n))
    return 0.5 * (b - a) * t + 0.5 * (b + a), 0.5 * (b - a) * w


@dataclass(frozen=True)
class ClampedFreeModes:
    """The mass-orthonormal clamped-free modes of a uniform beam with an optional tip mass.

    Parameters
    ----------
    length : float [m]
    mass_per_length : float [kg/m]
    modes : int
        Number of modes.
    tip_mass : float [kg], optional
        A point mass at the free end.

    Attributes
    ----------
    roots : numpy.ndarray, shape (modes,)
        ``lam_i = beta_i L`` (`clamped_free_roots`).
    scale : numpy.ndarray, shape (modes,) [kg^-1/2]
        The factors that make the shapes mass-orthonormal.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.scene.beams import ClampedFreeModes
    >>> beam = ClampedFreeModes(2.0, 0.5, 3)
    >>> beam.frequencies(10.0).round(4)            # rad/s, EI = 10 N m^2
    array([ 3.931 , 24.6353, 68.9796])
    >>> x, w = beam.nodes()
    >>> phi = beam.shape(x)
    >>> bool(np.allclose(0.5 * (phi * w) @ phi.T, np.eye(3), atol=1e-12))
    True
    """

    length: float
    mass_per_length: float
    modes: int
    tip_mass: float = 0.0

    def __post_init__(self):
        from ..validate import integer, nonnegative, positive
        object.__setattr__(self, "length", positive(self.length, "length"))
        object.__setattr__(self, "mass_per_length",
                           positive(self.mass_per_length, "mass_per_length"))
        object.__setattr__(self, "modes", integer(self.modes, "modes", minimum=1))
        object.__setattr__(self, "tip_mass", nonnegative(self.tip_mass, "tip_mass"))

    @functools.cached_property
    def roots(self) -> np.ndarray:
        return clamped_free_roots(self.modes, tip_mass_ratio=self.tip_mass / (self.mass_per_length * self.length))

    @functools.cached_property
    def scale(self) -> np.ndarray:
        x, w = self.nodes()
        raw = self._raw(x, 0)
        tip = self._raw(np.array([self.length]), 0)[:, 0]
        return 1.0 / np.sqrt(self.mass_per_length * (raw ** 2) @ w + self.tip_mass * tip ** 2)

    def nodes(self, n: int | None = None) -> tuple:
        """Gauss-Legendre nodes and weights on ``[0, L]``, enough for products of four
        shapes or their derivatives (``n`` points; default ``48 + 16 modes``)."""
        return gauss_legendre(0.0, self.length, n or 48 + 16 * self.modes)

    def frequencies(self, bending_stiffness: float) -> np.ndarray:
        """Natural frequencies ``lam_i^2 sqrt(EI / (m L^4))`` [rad/s] for ``EI`` [N m^2]."""
        return self.roots ** 2 * math.sqrt(
            bending_stiffness / (self.mass_per_length * self.length ** 4))

    def _raw(self, x, derivative: int) -> np.ndarray:
        lam = self.roots[:, None]
        t = lam * np.asarray(x, dtype=float)[None, :] / self.length
        E = np.exp(-lam)
        sl, cl = np.sin(lam), np.cos(lam)
        D = 1.0 - E ** 2 + 2.0 * E * sl
        sigma = (1.0 + E ** 2 + 2.0 * E * cl) / D
        a, b = (sl - cl - E) / D, (1.0 + E * (cl + sl)) / D   # cosh t - sigma sinh t = a e^(t-lam) + b e^-t
        grow, decay = a * np.exp(t - lam), b * np.exp(-t)
        hyper = grow + decay if derivative % 2 == 0 else grow - decay
        s, c = np.sin(t), np.cos(t)
        trig = (-c + sigma * s, s + sigma * c, c - sigma * s, -s - sigma * c)[derivative % 4]
        return (lam / self.length) ** derivative * (hyper + trig)

    def slope_integrals(self, xs, pairs) -> np.ndarray:
        """``G_ij(x) = int_0^x phi_i' phi_j'`` for each ``(i, j)`` of ``pairs`` at each of
        ``xs``: shape (len(pairs), len(xs)) [kg^-1 m^-1] (the foreshortening's coefficients)."""
        xs = np.atleast_1d(np.asarray(xs, float))
        G = np.empty((len(pairs), xs.size))
        n = self.nodes()[0].size
        for k, xk in enumerate(xs):
            t, wt = gauss_legendre(0.0, xk, n)
            d1 = self.shape(t, 1)
            G[:, k] = [(d1[i] * d1[j]) @ wt for i, j in pairs]
        return G

    def shape(self, x, derivative: int = 0) -> np.ndarray:
        """The mass-orthonormal shapes (or their ``derivative``-th x-derivative) at ``x``.

        Parameters
        ----------
        x : array_like, shape (k,) [m]
        derivative : int, optional
            0 to 4.

        Returns
        -------
        numpy.ndarray, shape (modes, k) [kg^-1/2 m^-derivative]
        """
        return self.scale[:, None] * self._raw(np.atleast_1d(x), int(derivative))


@dataclass(frozen=True)
class TabulatedModes:
    """Assumed modes of a uniform cantilever from a user's shape table, made Ritz modes.

    Each column of ``shapes`` samples an admissible shape ``psi_k(x)`` (zero deflection at
    the clamped root ``x = 0``) at the stations ``x``; it is interpolated by a cubic spline
    with zero slope at the root (the clamp) and the not-a-knot condition at the tip, so a
    cubic polynomial is reproduced exactly. The shapes are then combined into the Ritz
    modes of the beam (Rayleigh-Ritz: ``K v = lam M v`` with ``M = int m psi psi^T +
    M_t psi(L) psi(L)^T`` and ``K = int psi'' psi''^T``), which are mass-orthonormal with
    diagonal stiffness: ``omega_k = sqrt(EI lam_k)``.

    Parameters
    ----------
    length : float [m]
    mass_per_length : float [kg/m]
    x : array_like, shape (n,) [m]
        Increasing stations from ``0`` to ``length`` (n >= 4).
    shapes : array_like, shape (n, modes)
        The shapes at the stations (any scale; linearly independent).
    tip_mass : float [kg], optional

    Raises
    ------
    ValueError
        Naming ``x`` or ``shapes``: stations not increasing from 0 to ``length``, a shape
        not zero at the root, shapes that are not independent.

    Examples
    --------
    Two polynomial shapes ``x^2, x^3``: the classical two-term Ritz estimate of the first
    cantilever frequency, ``3.5327 sqrt(EI / (m L^4))`` (exact: ``1.8751^2 = 3.516``):

    >>> import numpy as np
    >>> from appdyn.dynamics.scene.beams import TabulatedModes
    >>> x = np.linspace(0.0, 1.0, 11)
    >>> beam = TabulatedModes(1.0, 1.0, x, np.column_stack([x**2, x**3]))
    >>> beam.frequencies(1.0).round(4)
    array([ 3.5327, 34.8069])
    """

    length: float
    mass_per_length: float
    x: tuple
    shapes: tuple
    tip_mass: float = 0.0

    def __post_init__(self):
        from ..validate import finite_array, nonnegative, positive
        L = positive(self.length, "length")
        x = finite_array(self.x, "x")
        if x.ndim != 1 or x.size < 4:
            raise ValueError(f"`x` must be a 1-D array of at least 4 stations, got shape "
                             f"{x.shape}")
        if np.any(np.diff(x) <= 0) or abs(x[0]) > 1e-12 * L or abs(x[-1] - L) > 1e-12 * L:
            raise ValueError(f"`x` must increase from 0 to `length` ({L}), got "
                             f"{x[0]} ... {x[-1]}")
        S = finite_array(self.shapes, "shapes")
        if S.ndim == 1:
            S = S[:, None]
        if S.ndim != 2 or S.shape[0] != x.size:
            raise ValueError(f"`shapes` must have shape ({x.size}, modes), got {S.shape}")
        if np.any(np.abs(S[0]) > 1e-12 * np.abs(S).max(axis=0)):
            raise ValueError("`shapes` must be zero at the clamped root (x = 0), got "
                             f"{S[0].tolist()}")
        object.__setattr__(self, "length", L)
        object.__setattr__(self, "mass_per_length",
                           positive(self.mass_per_length, "mass_per_length"))
        object.__setattr__(self, "x", tuple(x.tolist()))
        object.__setattr__(self, "shapes", tuple(map(tuple, S.tolist())))
        object.__setattr__(self, "tip_mass", nonnegative(self.tip_mass, "tip_mass"))
        lam = self._ritz[0]
        if not np.all(lam > 0):
            raise ValueError("`shapes` must be linearly independent and bend (a straight "
                             "or repeated shape has no strain energy)")

    @property
    def modes(self) -> int:
        """The number of modes (the table's columns)."""
        return len(self.shapes[0])

    @functools.cached_property
    def _spline(self):
        from scipy.interpolate import CubicSpline
        return CubicSpline(np.asarray(self.x), np.asarray(self.shapes),
                           bc_type=((1, np.zeros(self.modes)), "not-a-knot"), axis=0)

    def nodes(self, n: int | None = None) -> tuple:
        """Gauss-Legendre nodes and weights on ``[0, L]``: 4 per spline interval (exact for
        products of two cubics), or ``n`` on the whole span."""
        if n is not None:
            return gauss_legendre(0.0, self.length, n)
        knots = np.asarray(self.x)
        parts = [gauss_legendre(a, b, 4) for a, b in zip(knots[:-1], knots[1:])]
        return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])

    @functools.cached_property
    def _ritz(self) -> tuple:
        from scipy.linalg import eigh
        x, w = self.nodes()
        psi, d2 = self._spline(x).T, self._spline(x, 2).T
        tip = self._spline(self.length)
        M = self.mass_per_length * (psi * w) @ psi.T + self.tip_mass * np.outer(tip, tip)
        K = (d2 * w) @ d2.T
        try:
            lam, V = eigh(0.5 * (K + K.T), 0.5 * (M + M.T))
        except np.linalg.LinAlgError:
            return np.zeros(self.modes), np.eye(self.modes)
        return lam, V

    def slope_integrals(self, xs, pairs) -> np.ndarray:
        """``G_ij(x) = int_0^x phi_i' phi_j'`` at ``xs`` (as `ClampedFreeModes`), exact for
        the spline: whole intervals, then the part of the last one (3-point Gauss)."""
        xs = np.atleast_1d(np.asarray(xs, float))
        knots = np.asarray(self.x)
        whole = np.zeros((len(pairs), knots.size))
        for m, (a, b) in enumerate(zip(knots[:-1], knots[1:])):
            t, wt = gauss_legendre(a, b, 3)
            d1 = self.shape(t, 1)
            whole[:, m + 1] = whole[:, m] + [(d1[i] * d1[j]) @ wt for i, j in pairs]
        G = np.empty((len(pairs), xs.size))
        for k, xk in enumerate(xs):
            m = int(np.clip(np.searchsorted(knots, xk, side="right") - 1, 0, knots.size - 2))
            t, wt = gauss_legendre(knots[m], xk, 3)
            d1 = self.shape(t, 1)
            G[:, k] = whole[:, m] + [(d1[i] * d1[j]) @ wt for i, j in pairs]
        return G

    def frequencies(self, bending_stiffness: float) -> np.ndarray:
        """The Ritz frequencies ``sqrt(EI lam_k)`` [rad/s] for ``EI`` [N m^2], ascending."""
        return np.sqrt(bending_stiffness * self._ritz[0])

    def shape(self, x, derivative: int = 0) -> np.ndarray:
        """The mass-orthonormal Ritz shapes (or their ``derivative``-th x-derivative, 0 to 2)
        at ``x``: shape (modes, k) [kg^-1/2 m^-derivative]."""
        raw = self._spline(np.atleast_1d(np.asarray(x, float)), int(derivative))
        return self._ritz[1].T @ raw.T
