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
from scipy.optimize import brentq

__all__ = ["clamped_free_roots", "ClampedFreeModes", "gauss_legendre"]


def _frequency_function(lam: float, mu: float) -> float:
    """The frequency equation divided by ``cosh(lam)`` (finite for any ``lam``)."""
    return (1.0 / math.cosh(lam) if lam < 700 else 0.0) + math.cos(lam) + mu * lam * (
        math.cos(lam) * math.tanh(lam) - math.sin(lam))


def clamped_free_roots(modes: int, tip_mass_ratio: float = 0.0) -> np.ndarray:
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
    >>> clamped_free_roots(1, 1.0).round(4)   # a tip mass equal to the beam's
    array([1.2479])
    """
    from ..validate import integer, nonnegative
    n = integer(modes, "modes", minimum=1)
    mu = nonnegative(tip_mass_ratio, "tip_mass_ratio")
    out = np.empty(n)
    for k in range(1, n + 1):
        lo, hi = (k - 1) * math.pi + (1e-9 if k == 1 else 0.0), k * math.pi
        out[k - 1] = brentq(_frequency_function, lo, hi, args=(mu,), xtol=1e-15, rtol=8.9e-16,
                            maxiter=500)
    return out


@functools.lru_cache(maxsize=16)
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
        return clamped_free_roots(self.modes, self.tip_mass / (self.mass_per_length * self.length))

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
