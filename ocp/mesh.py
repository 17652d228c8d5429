"""The collocation mesh: interval breakpoints in normalized time.

Time on the horizon ``[t0, t0 + T]`` is written ``t = t0 + T tau`` with ``tau`` in ``[0, 1]``;
the mesh holds the breakpoints ``0 = tau_0 < tau_1 < ... < tau_N = 1``. It is independent of
``T``, so the same mesh serves a free final time, and mesh refinement only changes it.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Mesh", "check_N", "sorted_union"]


@dataclass(frozen=True, eq=False)
class Mesh:
    """Interval breakpoints ``tau`` in normalized time.

    Parameters
    ----------
    breaks : array_like, shape (N + 1,)
        Strictly increasing, ``breaks[0] == 0`` and ``breaks[-1] == 1``.

    Raises
    ------
    ValueError
        If ``breaks`` has fewer than two points, is not strictly increasing, or does not run
        from 0 to 1.
    """

    breaks: np.ndarray

    def __post_init__(self):
        try:
            b = np.array(self.breaks, dtype=float).reshape(-1)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"`mesh` must be an array of breakpoints: {exc}") from None
        if b.size < 2 or not np.all(np.isfinite(b)):
            raise ValueError(f"`mesh` must hold at least 2 finite breakpoints, got {b.tolist()}")
        if b[0] != 0.0 or b[-1] != 1.0 or np.any(np.diff(b) <= 0):
            raise ValueError(
                "`mesh` breakpoints must increase strictly from 0 to 1 (normalized time), got "
                f"{b.tolist()}"
            )
        b.setflags(write=False)
        object.__setattr__(self, "breaks", b)

    @classmethod
    def uniform(cls, N: int) -> "Mesh":
        """``N`` equal intervals."""
        N = check_N(N)
        b = np.linspace(0.0, 1.0, N + 1)
        return cls(b)

    @property
    def N(self) -> int:
        """Number of intervals."""
        return self.breaks.size - 1

    @property
    def fractions(self) -> np.ndarray:
        """Interval lengths in normalized time, shape (N,)."""
        return np.diff(self.breaks)

    def __reduce__(self):
        return (type(self), (np.array(self.breaks),))

    def __eq__(self, other) -> bool:
        return isinstance(other, Mesh) and np.array_equal(self.breaks, other.breaks)

    def __hash__(self) -> int:
        return hash(self.breaks.tobytes())

    def __repr__(self) -> str:
        h = self.fractions
        kind = "uniform" if np.allclose(h, h[0], rtol=1e-12, atol=0) else "non-uniform"
        return f"Mesh(N={self.N}, {kind})"


def check_N(N) -> int:
    """``N`` (number of mesh intervals) as an int >= 1, else ValueError naming `N`."""
    if isinstance(N, (bool, np.bool_)) or not isinstance(N, (int, np.integer)) or N < 1:
        raise ValueError(f"`N` (number of mesh intervals) must be an integer >= 1, got {N!r}")
    return int(N)


def sorted_union(*arrays) -> np.ndarray:
    """The sorted distinct values of all ``arrays`` together (``numpy.union1d`` of any
    number of arrays).

    Written out (a sort and a neighbour test) because ``numpy.unique`` imports
    ``numpy.ma`` on its first plain call: about 25 ms in a fresh process, paid by the first
    solve of a session.

    Parameters
    ----------
    *arrays : array_like
        Any shapes; flattened.

    Returns
    -------
    ndarray, shape (n,)
        Sorted, without repeats (float unless all inputs are integer).

    Examples
    --------
    >>> from appdyn.ocp.mesh import sorted_union
    >>> sorted_union([0.5, 0.0, 1.0], [0.25, 0.5])
    array([0.  , 0.25, 0.5 , 1.  ])
    """
    a = np.sort(np.concatenate([np.ravel(np.asarray(x)) for x in arrays]) if arrays else np.zeros(0))
    if a.size < 2:
        return a
    keep = np.empty(a.size, dtype=bool)
    keep[0] = True
    np.not_equal(a[1:], a[:-1], out=keep[1:])
    return a[keep]

