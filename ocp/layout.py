"""Named blocks of a flat vector: the one place that knows NLP offsets.

The NLP decision vector ``w`` and constraint vector ``g`` are stacks of matrices (states on
the node grid, controls, parameters, ...). `Layout` records the blocks' names and shapes and
converts between the flat vector and the named matrices, column-major (CasADi's order), for
symbols and numbers alike, so no other code indexes a flat NLP vector by hand.
"""
from __future__ import annotations

from types import MappingProxyType
from typing import Mapping

import casadi as ca
import numpy as np

__all__ = ["Layout"]


class Layout:
    """Ordered named matrix blocks stacked column-major into one vector.

    Parameters
    ----------
    blocks : mapping of str to tuple (rows, cols)
        Block names and shapes in stacking order. Empty blocks are allowed.

    Examples
    --------
    >>> lay = Layout({"X": (2, 3), "T": (1, 1)})
    >>> lay.size
    7
    >>> parts = lay.split(np.arange(7.0))
    >>> parts["X"]
    array([[0., 2., 4.],
           [1., 3., 5.]])
    """

    def __init__(self, blocks: Mapping[str, tuple[int, int]]):
        shapes, offsets, n = {}, {}, 0
        for name, (rows, cols) in blocks.items():
            shapes[name] = (int(rows), int(cols))
            offsets[name] = n
            n += int(rows) * int(cols)
        self.shapes = MappingProxyType(shapes)
        self._offsets = offsets
        self.size = n

    def __repr__(self) -> str:
        inner = ", ".join(f"{k}: {r}x{c}" for k, (r, c) in self.shapes.items())
        return f"Layout({inner}; size {self.size})"

    def offset(self, name: str) -> int:
        """Position of block ``name``'s first element in the flat vector."""
        return self._offsets[name]

    def indices(self, name: str) -> np.ndarray:
        """Flat positions of block ``name`` as an integer array of the block's shape
        (column-major, like the block itself)."""
        r, c = self.shapes[name]
        return self._offsets[name] + np.arange(r * c).reshape((r, c), order="F")

    def split(self, v) -> dict:
        """Split a flat vector into its named blocks.

        Parameters
        ----------
        v : casadi.MX/SX/DM column of length ``size``, or array_like, shape (size,)

        Returns
        -------
        dict of str to matrix
            CasADi matrices for CasADi input, numpy arrays of the block shapes otherwise.
        """
        symbolic = isinstance(v, (ca.MX, ca.SX))
        if not symbolic:
            v = np.asarray(v, dtype=float).reshape(-1)
        if (v.numel() if symbolic else v.size) != self.size:
            got = v.numel() if symbolic else v.size
            raise ValueError(f"vector of length {self.size} expected by {self!r}, got {got}")
        out = {}
        for name, (r, c) in self.shapes.items():
            o = self._offsets[name]
            if symbolic:
                out[name] = ca.reshape(v[o:o + r * c], r, c)
            else:
                out[name] = v[o:o + r * c].reshape((r, c), order="F")
        return out

    def join(self, parts: Mapping[str, object], *, symbolic: bool = False):
        """Stack named blocks into one flat vector (inverse of `split`).

        Parameters
        ----------
        parts : mapping of str to matrix
            One entry per block, each of the block's shape (a scalar fills the whole block).
        symbolic : bool
            Return a CasADi column (``vertcat`` of the vectorized blocks) instead of numpy.

        Returns
        -------
        casadi column or numpy.ndarray, shape (size,)
        """
        missing = set(self.shapes) - set(parts)
        extra = set(parts) - set(self.shapes)
        if missing or extra:
            raise ValueError(f"blocks {sorted(self.shapes)} expected, missing {sorted(missing)}, "
                             f"unknown {sorted(extra)}")
        if symbolic:
            items = []
            for name, (r, c) in self.shapes.items():
                m = parts[name]
                if m.shape != (r, c):
                    raise ValueError(f"block {name!r} must be {r}x{c}, got {m.shape}")
                items.append(ca.vec(m))
            return ca.vertcat(*items) if items else ca.DM(0, 1)
        out = np.empty(self.size)
        for name, (r, c) in self.shapes.items():
            o = self._offsets[name]
            m = np.asarray(parts[name], dtype=float)
            if m.shape != (r, c):  # a scalar or a broadcastable block
                m = np.broadcast_to(m, (r, c))
            out[o:o + r * c] = m.reshape(-1, order="F")
        return out
