"""Singular surfaces and the momentum envelope of a single-gimbal CMG cluster (Wie, *Space
Vehicle Dynamics and Control*, Sec. 7.3).

At a singular state every transverse axis ``t_i`` is perpendicular to the singular direction
``u`` (``u^T C = 0``, `dynamics.momentum.cluster`), so each spin axis lies in the plane of
``g_i`` and ``u``:

    ``s_i = eps_i (u - (u.g_i) g_i) / |u - (u.g_i) g_i|``,   ``eps_i = +-1``,
    ``H(u, eps) = sum_i h_i s_i``.

Sweeping ``u`` over the unit sphere maps each sign pattern ``eps`` onto a singular surface
(`singular_surface`). The all-positive pattern maximizes ``u.H``: it is the saturation
envelope, the outer surface; the pattern with ``k`` negative signs and the one with ``n - k``
give the same surface mirrored (``H -> -H``), so the surfaces are grouped by
``k = min(#negative, #positive)`` (`momentum_envelope`). The gimbal angles of a point are
``delta_i = atan2(s_i.(g_i x s0_i), s_i.s0_i)``.
"""
from __future__ import annotations

import itertools
import time
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from .. import validate
from ..figures import finish_figure, panel_grid
from ..serialize import to_json
from .cluster import SINGULAR_TOL, ClusterGeometry
from ..results import Result

__all__ = ["PARALLEL_TOL", "MIN_DIRECTIONS", "KINDS", "SurfacePoints", "fibonacci_directions",
           "singular_surface", "classify_singularities", "momentum_envelope",
           "MomentumEnvelope"]

#: Directions ``u`` with ``|u - (u.g_i) g_i| <= PARALLEL_TOL`` for some unit are skipped
#: (``u`` along a gimbal axis leaves that spin axis undetermined).
PARALLEL_TOL = 1e-8
#: Fewest directions `momentum_envelope` accepts.
MIN_DIRECTIONS = 50
#: The kinds `classify_singularities` returns (those of `classify_singularity`).
KINDS = ("elliptic", "hyperbolic", "degenerate", "nonsingular")


def _geometry(geometry) -> ClusterGeometry:
    if not isinstance(geometry, ClusterGeometry):
        raise validate.ArgumentTypeError(
            f"`geometry` must be a ClusterGeometry, got {type(geometry).__name__}")
    return geometry


def fibonacci_directions(count: int) -> np.ndarray:
    """``count`` deterministic, nearly uniform unit directions (Fibonacci sphere).

    Parameters
    ----------
    count : int
        Number of directions, ``>= 1``.

    Returns
    -------
    ndarray, shape (3, count)

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.momentum import fibonacci_directions
    >>> u = fibonacci_directions(500)
    >>> u.shape, bool(np.allclose(np.linalg.norm(u, axis=0), 1.0)), bool(abs(u[2].mean()) < 1e-12)
    ((3, 500), True, True)
    """
    count = validate.integer(count, "count", minimum=1)
    i = np.arange(count) + 0.5
    z = 1.0 - 2.0 * i / count
    r = np.sqrt(np.maximum(1.0 - z * z, 0.0))
    phi = np.pi * (3.0 - np.sqrt(5.0)) * i
    return np.array([r * np.cos(phi), r * np.sin(phi), z])


class SurfacePoints(NamedTuple):
    """Points of one singular surface (`singular_surface`).

    Attributes
    ----------
    H : ndarray, shape (3, m) [N m s]
        Cluster momentum at the singular states.
    delta : ndarray, shape (n, m) [rad]
        Gimbal angles of those states, in ``(-pi, pi]``.
    index : ndarray of int, shape (m,)
        The columns of ``directions`` they come from (parallel directions are skipped).
    """

    H: np.ndarray
    delta: np.ndarray
    index: np.ndarray


def singular_surface(geometry: ClusterGeometry, directions, signs) -> SurfacePoints:
    """Singular states with the singular directions ``directions`` and spin signs ``signs``.

    ``s_i = eps_i (u - (u.g_i) g_i) / |u - (u.g_i) g_i|`` and ``H = sum_i h_i s_i`` (module
    docstring); ``C(delta)^T u = 0`` at every returned state.

    Parameters
    ----------
    geometry : ClusterGeometry
    directions : array_like, shape (3,) or (3, m)
        Singular directions ``u`` (non-zero; normalized here), body frame.
    signs : array_like, shape (n,)
        ``eps_i``, each ``+1`` or ``-1``; all ``+1`` gives the saturation envelope.

    Returns
    -------
    SurfacePoints
        ``H (3, m')``, ``delta (n, m')`` and ``index (m',)``; directions within
        `PARALLEL_TOL` of a gimbal axis are left out.

    Raises
    ------
    TypeError
        If ``geometry`` is not a `ClusterGeometry` or an argument does not hold numbers.
    ValueError
        Naming ``directions`` (shape, non-finite, zero) or ``signs`` (length, values).

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.momentum import pyramid, singular_surface
    >>> geo = pyramid(np.arccos(1 / np.sqrt(3)))
    >>> pts = singular_surface(geo, [1.0, 0.0, 0.0], [1, 1, 1, 1])  # saturation along x
    >>> np.round(pts.H[:, 0], 6) + 0.0, np.round(np.degrees(pts.delta[:, 0]), 6) + 0.0
    (array([3.154701, 0.      , 0.      ]), array([-90., 180.,  90.,   0.]))
    """
    geo = _geometry(geometry)
    u = validate.unit_vector(directions, "directions", batch=True).reshape(3, -1)
    eps = validate.finite_array(signs, "signs", (geo.n,))
    if not np.all(np.abs(eps) == 1.0):
        raise ValueError(f"`signs` must hold +1 or -1 for each unit, got {eps.tolist()}")
    G = geo.gimbal_axes
    perp = u.T[:, :, None] - (u.T @ G)[:, None, :] * G[None]  # (m, 3, n)
    size = np.linalg.norm(perp, axis=1)  # (m, n)
    index = np.flatnonzero(np.all(size > PARALLEL_TOL, axis=1))
    spin = perp[index] / size[index][:, None, :] * eps  # (m', 3, n)
    H = np.einsum("kin,n->ik", spin, geo.h)
    delta = np.arctan2(np.einsum("kin,in->nk", spin, geo.transverse_axes0),
                       np.einsum("kin,in->nk", spin, geo.spin_axes0))
    return SurfacePoints(H, delta, index)


def classify_singularities(geometry: ClusterGeometry, delta, *, tol=SINGULAR_TOL) -> np.ndarray:
    """`classify_singularity` for a batch of gimbal states at once (same rules, vectorised).

    Parameters
    ----------
    geometry : ClusterGeometry
    delta : array_like, shape (n, m) [rad]
    tol : float, optional
        Relative tolerance of the rank and definiteness decisions.

    Returns
    -------
    ndarray of str, shape (m,)
        ``"elliptic"``, ``"hyperbolic"``, ``"degenerate"`` or ``"nonsingular"`` per column.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.momentum import pyramid, classify_singularities
    >>> geo = pyramid(np.deg2rad(54.74))
    >>> states = np.deg2rad([[-90, 0, 90, 0], [90, -90, 90, -90], [0, 0, 0, 0]]).T
    >>> classify_singularities(geo, states).tolist()
    ['elliptic', 'hyperbolic', 'nonsingular']
    """
    geo = _geometry(geometry)
    d = validate.finite_array(delta, "delta", (geo.n,), batch=True).reshape(geo.n, -1)
    tol = validate.positive(tol, "tol") * float(np.max(geo.h))
    s0h, t0h = geo.spin_axes0 * geo.h, geo.transverse_axes0 * geo.h
    c, s = np.cos(d).T[:, None, :], np.sin(d).T[:, None, :]  # (m, 1, n)
    units = s0h * c + t0h * s  # (m, 3, n): h_i s_i
    U, S, Vt = np.linalg.svd(t0h * c - s0h * s)  # of C, (m, 3, n)
    rank = np.sum(S > tol, axis=1)
    P = np.einsum("ki,kin->kn", U[:, :, 2], units)  # u . h_i s_i
    N = np.swapaxes(Vt[:, 2:, :], 1, 2)  # null space of a rank-2 C, (m, n, n - 2)
    eig = np.linalg.eigvalsh(np.einsum("kia,ki,kib->kab", N, P, N)) if geo.n > 2 \
        else np.ones((d.shape[1], 1))
    pos, neg = np.any(eig > tol, axis=1), np.any(eig < -tol, axis=1)
    definite = np.all(np.abs(eig) > tol, axis=1)
    kind = np.where(pos & neg, "hyperbolic", np.where(definite, "elliptic", "degenerate"))
    kind = np.where(rank <= 1, "degenerate", kind)
    return np.where(rank >= 3, "nonsingular", kind).astype("<U11")


def momentum_envelope(geometry: ClusterGeometry, *, directions: int = 2000) -> "MomentumEnvelope":
    """All singular surfaces of a cluster, grouped and classified: the momentum envelope.

    Every sign pattern ``eps`` (``2^n``) is swept over ``directions`` Fibonacci directions
    (`fibonacci_directions`, deterministic); the patterns are grouped by
    ``k = min(#negative, #positive)`` (group 0 is the saturation envelope) and every point is
    classified (`classify_singularities`).

    Parameters
    ----------
    geometry : ClusterGeometry
    directions : int, optional
        Number of singular directions, ``>= MIN_DIRECTIONS`` (2000: 32 000 points for four
        units, about 0.1 s).

    Returns
    -------
    MomentumEnvelope

    Raises
    ------
    TypeError
        If ``geometry`` is not a `ClusterGeometry` or ``directions`` not an integer.
    ValueError
        If ``directions < MIN_DIRECTIONS``.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.momentum import pyramid, momentum_envelope
    >>> env = momentum_envelope(pyramid(np.arccos(1 / np.sqrt(3))), directions=500)
    >>> round(env.max_momentum([1, 0, 0]), 9), round(float(2 * (1 + 1 / np.sqrt(3))), 9)
    (3.154700538, 3.154700538)
    >>> sorted(env.points), env.kinds[0].tolist() == ["elliptic"] * env.kinds[0].size
    ([0, 1, 2], True)
    """
    start = time.perf_counter()
    geo = _geometry(geometry)
    count = validate.integer(directions, "directions", minimum=MIN_DIRECTIONS)
    u = fibonacci_directions(count)
    collected = {}
    for signs in itertools.product((1, -1), repeat=geo.n):
        k = min(signs.count(-1), signs.count(1))
        collected.setdefault(k, []).append(singular_surface(geo, u, signs))
    points, delta, kinds = {}, {}, {}
    for k in sorted(collected):
        points[k] = np.concatenate([p.H for p in collected[k]], axis=1)
        delta[k] = np.concatenate([p.delta for p in collected[k]], axis=1)
        kinds[k] = classify_singularities(geo, delta[k])
    outer = collected[0][0]
    return MomentumEnvelope(geometry=geo, directions=count, points=points, delta=delta,
                            kinds=kinds, outer_directions=u[:, outer.index],
                            wall_time=time.perf_counter() - start)


def _outer_value(geo, axis, v):
    """``axis . H_outer(v / |v|)`` and its gradient with respect to ``v`` (3,)."""
    n = np.linalg.norm(v)
    u = v / n
    G = geo.gimbal_axes
    perp = u[:, None] - G * (u @ G)  # (3, n)
    size = np.linalg.norm(perp, axis=0)
    s = perp / size
    value = float(axis @ s @ geo.h)
    a_t = axis[:, None] - s * (axis @ s)  # (I - s s^T) a per unit
    grad_u = ((a_t - G * (G.T @ axis - np.sum(G * s, axis=0) * (s.T @ axis))) / size) @ geo.h
    return value, (grad_u - u * (u @ grad_u)) / n


@dataclass(frozen=True, eq=False, repr=False)
class MomentumEnvelope(Result):
    """Singular surfaces of a CMG cluster (`momentum_envelope`).

    Attributes
    ----------
    geometry : ClusterGeometry
    directions : int
        Singular directions sampled per sign pattern.
    points : dict of int to ndarray, shape (3, m_k) [N m s]
        Surface points per group ``k`` (0: the saturation envelope, the outer surface).
    delta : dict of int to ndarray, shape (n, m_k) [rad]
        Gimbal angles of the points.
    kinds : dict of int to ndarray of str, shape (m_k,)
        ``"elliptic"``, ``"hyperbolic"``, ``"degenerate"`` (``"nonsingular"`` never, but
        kept in the counts as a check).
    outer_directions : ndarray, shape (3, m_0')
        The singular directions of the all-positive pattern's points (the first of group 0).
    wall_time : float [s]
    """

    geometry: ClusterGeometry
    directions: int
    points: dict
    delta: dict
    kinds: dict
    outer_directions: np.ndarray
    wall_time: float = field(default=float("nan"))

    _repr_fields = ('directions', 'extent')

    @property
    def success(self) -> bool:
        """The saturation envelope has points and every point is finite."""
        return bool(self.points.get(0, np.zeros((3, 0))).size
                    and all(np.all(np.isfinite(p)) for p in self.points.values()))

    @property
    def status(self) -> int:
        """0 when `success`, -1 otherwise."""
        return 0 if self.success else -1

    @property
    def message(self) -> str:
        """`status` in words."""
        n = sum(p.shape[1] for p in self.points.values())
        return (f"{n} singular points in {len(self.points)} group(s)" if self.success else
                "the saturation envelope has no points or non-finite ones")

    def max_momentum(self, axis) -> float:
        """Largest projection ``max axis.H`` of the envelope along a unit ``axis`` [N m s].

        The best sampled direction of the saturation surface is refined by a BFGS search on
        the sphere of singular directions (analytic gradient), so the value is accurate to
        round-off, not to the sampling.

        Parameters
        ----------
        axis : array_like, shape (3,)
            Body-frame direction (non-zero; normalized here).

        Returns
        -------
        float [N m s]

        Examples
        --------
        >>> import numpy as np
        >>> from appdyn.dynamics.momentum import pyramid, momentum_envelope
        >>> env = momentum_envelope(pyramid(np.deg2rad(54.74)), directions=200)
        >>> bool(abs(env.max_momentum([0, 0, 1]) - 4 * np.sin(np.deg2rad(54.74))) < 1e-12)
        True
        """
        from scipy.optimize import minimize

        a = validate.unit_vector(axis, "axis")
        geo = self.geometry
        outer = self.points[0][:, :self.outer_directions.shape[1]]
        best = int(np.argmax(a @ outer))
        u0 = self.outer_directions[:, best]
        sampled = float(a @ outer[:, best])

        def negative(v):
            value, grad = _outer_value(geo, a, v)
            return -value, -grad

        res = minimize(negative, u0, jac=True, method="BFGS", options={"gtol": 1e-13})
        refined = -float(res.fun) if np.isfinite(res.fun) else -np.inf
        return max(sampled, refined)

    @property
    def extent(self) -> dict:
        """``max_momentum`` along ``x``, ``y``, ``z`` [N m s] (the envelope is symmetric
        under ``H -> -H``)."""
        return {name: self.max_momentum(e) for name, e in zip("xyz", np.eye(3))}

    def counts(self) -> dict:
        """Per group ``k``: number of points and of each kind (`KINDS`)."""
        return {k: {"points": int(v.size), **{kind: int(np.sum(v == kind)) for kind in KINDS}}
                for k, v in self.kinds.items()}

    @staticmethod
    def label(k: int) -> str:
        """Name of group ``k``: ``"k=0 (saturation)"``, ``"k=1"``, ..."""
        return "k=0 (saturation)" if k == 0 else f"k={k}"

    def to_dict(self) -> dict:
        """Geometry, extent, and per group ``k``: counts, largest ``|H|`` and the points
        ``H`` [N m s] by kind, each (3, m) (JSON-ready through `to_json`)."""
        geo = self.geometry
        groups = {}
        for k, c in self.counts().items():
            norms = np.linalg.norm(self.points[k], axis=0)
            by_kind = {kind: self.points[k][:, self.kinds[k] == kind] for kind in KINDS
                       if c[kind]}
            groups[str(k)] = {**c, "max_norm": float(norms.max()) if norms.size else None,
                              "H": by_kind}
        return {"success": self.success, "status": self.status, "message": self.message,
                "n": geo.n, "h": geo.h, "gimbal_axes": geo.gimbal_axes,
                "spin_axes0": geo.spin_axes0, "directions": self.directions,
                "extent": self.extent, "wall_time": self.wall_time, "groups": groups}

    def __str__(self) -> str:
        geo = self.geometry
        lines = [f"Momentum envelope: {geo.n} CMGs, h = {np.array2string(geo.h, precision=4)}"
                 f" N m s, {self.directions} singular directions per sign pattern",
                 f"  {'surface':<17}{'points':>8}{'elliptic':>10}{'hyperbolic':>12}"
                 f"{'degenerate':>12}{'max |H| [N m s]':>17}"]
        for k, c in self.counts().items():
            m = max(c["points"], 1)
            top = np.linalg.norm(self.points[k], axis=0).max() if c["points"] else np.nan
            lines.append(f"  {self.label(k):<17}{c['points']:>8}"
                         f"{100 * c['elliptic'] / m:>9.1f}%{100 * c['hyperbolic'] / m:>11.1f}%"
                         f"{100 * c['degenerate'] / m:>11.1f}%{top:>17.6f}")
        ext = self.extent
        lines.append("  extent along x, y, z [N m s]: "
                     + ", ".join(f"{ext[a]:.9f}" for a in "xyz"))
        lines.append(f"  wall time {self.wall_time:.3f} s")
        return "\n".join(lines)

    def plot(self, ax=None):
        """Sections near the x-z and x-y planes and a 3D view of the envelope (translucent)
        with the internal surfaces coloured by kind (blue elliptic, red hyperbolic).

        Parameters
        ----------
        ax : matplotlib.axes.Axes or matplotlib.figure.Figure, optional
            Draw the panels in this axes' slot (divided into the panels) or on this figure
            (cleared); by default on a new `matplotlib.figure.Figure` (no pyplot).

        Returns
        -------
        matplotlib.figure.Figure
        """
        from scipy.spatial import ConvexHull

        fig, grid = panel_grid(ax, 1, 3, (15.0, 5.2))
        ax3 = fig.add_subplot(grid[0, 2], projection="3d")  # last: its z label at the edge
        outer = self.points[0][:, :self.outer_directions.shape[1]]
        tri = ConvexHull(self.outer_directions.T).simplices
        ax3.plot_trisurf(*outer, triangles=tri, color="tab:gray", alpha=0.12, linewidth=0)
        colours = {"elliptic": "tab:blue", "hyperbolic": "tab:red", "degenerate": "k"}
        inner = [k for k in self.points if k > 0]
        for kind, colour in colours.items():
            H = np.concatenate([self.points[k][:, self.kinds[k] == kind] for k in inner]
                               or [np.zeros((3, 0))], axis=1)
            if H.size:
                step = max(1, H.shape[1] // 4000)
                ax3.scatter(*H[:, ::step], s=1, color=colour, alpha=0.5, label=kind)
        ax3.set_box_aspect((1.0, 1.0, 1.0))
        ax3.set(xlabel="H_x [N m s]", ylabel="H_y [N m s]", zlabel="H_z [N m s]",
                title="internal singular surfaces in the envelope")
        ax3.legend(fontsize=7, loc="upper left", markerscale=6)
        extent = max(float(np.max(np.abs(p))) for p in self.points.values())
        band = 0.02 * extent
        for panel, (i, j, normal, name) in enumerate([(0, 2, 1, "x-z"), (0, 1, 2, "x-y")]):
            ax = fig.add_subplot(grid[0, panel])
            for k, H in self.points.items():
                near = np.abs(H[normal]) <= band
                if k == 0:
                    ax.scatter(H[i, near], H[j, near], s=3, color="tab:gray",
                               label="saturation envelope")
                    continue
                for kind, colour in colours.items():
                    sel = near & (self.kinds[k] == kind)
                    ax.scatter(H[i, sel], H[j, sel], s=2, color=colour,
                               label=f"{kind} (internal)" if k == 1 and sel.any() else None)
            ax.set(xlabel=f"H_{'xyz'[i]} [N m s]", ylabel=f"H_{'xyz'[j]} [N m s]",
                   title=f"near the {name} plane (|H_{'xyz'[normal]}| <= {band:.2f})",
                   aspect="equal")
            ax.grid(True, alpha=0.3)
            ax.legend(fontsize=7, loc="upper right", markerscale=3)
        return finish_figure(fig)
