"""The switching structure of a bang-bang solution: `BangArcs` and `bang_arcs`.

Every control component sits at one of its (finite) bounds on every arc between
consecutive switches; the arcs of all components are merged. `ocp.refine.switch_times`
optimizes their durations. With ``short_arcs=True`` arcs too short for the starting mesh to
show (an interval whose mean control falls short of its bound) are inserted as guesses.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..mesh import sorted_union
from ..solution import Solution
from .switches import control_switches

__all__ = ["BangArcs", "bang_arcs", "IDLE_TOL"]

#: Largest ``|u_j|`` relative to the half-range of its bounds of an idle component
#: (`bang_arcs`): collocation leaves the unused torques of a principal-axis slew at 0 to
#: round-off (measured: exactly 0.0 at 400 samples, N = 10).
IDLE_TOL = 1e-8


@dataclass(frozen=True)
class BangArcs:
    """The switching structure of a bang-bang solution (`bang_arcs`).

    Attributes
    ----------
    switch_times : ndarray, shape (m,) [s]
        Switches of all components, merged and sorted (strictly inside the horizon).
    durations : ndarray, shape (m + 1,) [s]
        Arc lengths between ``t0``, the switches and ``t0 + T``.
    controls : ndarray, shape (nu, m + 1)
        The bang value (a bound) of every component on every arc.
    """

    switch_times: np.ndarray
    durations: np.ndarray
    controls: np.ndarray

    def _replace_durations(self, durations) -> "BangArcs":
        """The same arcs with other durations (switch times moved accordingly)."""
        d = np.array(durations, dtype=float)
        t0 = float(self.switch_times[0] - self.durations[0]) if self.switch_times.size else 0.0
        sw = t0 + np.cumsum(d)[:-1]
        for a in (d, sw):
            a.setflags(write=False)
        return BangArcs(sw, d, self.controls)


def bang_arcs(solution: Solution, *, samples: int = 9,
              short_arcs: bool = False) -> tuple[BangArcs | None, str]:
    """The bang-bang switching structure of ``solution``, or ``None`` and why not.

    Every control component must have finite bounds and, on each of its own arcs between
    the switches `control_switches` finds, stay near one bound: at least 75% of the samples
    of the arc's central 80% in the outer quarter of the range on one side (an arc shorter
    than two mesh intervals, smeared by the collocation, takes the side of its median), and
    consecutive arcs on opposite bounds (a jump). A singular, coast or constrained arc (an arc in
    between), an unbounded component, or a component that returns to the bound it left
    (an interior arc in between) is refused. The one exception, an *idle* component: zero
    (within `IDLE_TOL` of its half-range) over the whole horizon, with no switch and zero
    inside its bounds (the torques off the axis of a principal-axis slew), is held at 0 on
    every arc (``controls`` row of zeros).

    Parameters
    ----------
    solution : Solution
    samples : int
        Samples per interval of `control_switches` (the arcs are sampled at 41 points).
    short_arcs : bool
        Also insert the arcs too short for `control_switches` (under 1% of the horizon, or
        inside one mesh interval): where a component's mean over a mesh interval away from
        its switches falls short of its bang value, an arc at the opposite bound of the
        same impulse (centred in the interval; at the end of the horizon in the first and
        last intervals), if longer than 1e-3 of the interval; the two longest per
        component. A guess of a structure to try when the plain one fails
        (`polish_switches`).

    Returns
    -------
    (BangArcs or None, str)
        The structure (and ``""``), or ``None`` and the reason.

    Raises
    ------
    TypeError
        If ``solution`` is not a `Solution` or ``samples`` not an integer.

    Examples
    --------
    >>> from appdyn import ocp
    >>> from appdyn.ocp.examples import min_time
    >>> from appdyn.ocp.refine.switch_times import bang_arcs
    >>> arcs, why = bang_arcs(ocp.solve(min_time(), N=10))  # x'' = u, |u| <= 1
    >>> arcs.switch_times.round(6), arcs.controls
    (array([1.]), array([[ 1., -1.]]))
    """
    if not isinstance(solution, Solution):
        raise TypeError(f"`solution` must be an ocp.Solution, got {type(solution).__name__}")
    # kept on the solution (read-only, as its other derived values): a pipeline that decides
    # on the structure and then polishes reads it once (about 12 ms a reading)
    if type(samples) is not int:  # noqa: E721 (checked, and named, by control_switches)
        return _bang_arcs(solution, samples, short_arcs)
    memo = vars(solution).setdefault("_bang_arcs", {})
    key = (samples, bool(short_arcs))
    if key not in memo:
        memo[key] = _bang_arcs(solution, samples, short_arcs)
    return memo[key]


def _bang_arcs(solution: Solution, samples: int, short_arcs: bool):
    """`bang_arcs` of ``solution``, computed."""
    problem = solution.problem
    lo, hi = (np.asarray(b, dtype=float) for b in problem.u_bounds)
    nu = lo.size
    if nu == 0:
        return None, "the problem has no controls"
    bad = ~(np.isfinite(lo) & np.isfinite(hi) & (hi > lo))
    if np.any(bad):
        return None, f"control components {np.flatnonzero(bad).tolist()} are not bounded on both sides"
    t0, T = float(solution.t0), float(solution.T)
    if not (np.isfinite(T) and T > 0):
        return None, f"the horizon T = {T!r} is not positive"
    per = control_switches(solution, samples=samples)
    mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    tb, hmesh = solution.dense.t_breaks, solution.dense.h
    own = []  # per component: (edges, sides) of its own arcs
    idle = _idle(solution, per, lo, hi)
    all_edges = [np.concatenate([[t0], per[j], [t0 + T]]) for j in range(nu)]
    for j, edges in enumerate(all_edges):
        if np.any(np.diff(edges) <= 0):
            return None, f"component {j}: switches out of order"
    # every arc's 41 samples of its central 80 %, read at once (one interpolation)
    frac = np.linspace(0.1, 0.9, 41)
    ts = np.concatenate([(e[:-1, None] + np.diff(e)[:, None] * frac).reshape(-1)
                         for e in all_edges])
    u_all = solution.sample(ts)[1]
    first = np.cumsum([0] + [41 * (e.size - 1) for e in all_edges])
    for j, edges in enumerate(all_edges):
        if idle[j]:
            own.append((edges, None))
            continue
        sides = []
        zj = ((u_all[j, first[j]:first[j + 1]] - mid[j]) / half[j]).reshape(-1, 41)
        for (a, b), z in zip(zip(edges[:-1], edges[1:]), zj):
            L = b - a
            s = 1.0 if np.count_nonzero(z >= 0) > z.size / 2 else -1.0  # median's sign (41: odd)
            # an arc within two mesh intervals is smeared by the collocation (the control
            # polynomial of the interval holding a switch): its side is that of its median,
            # and the switch-time NLP checks the guess
            k0, k1 = np.searchsorted(tb, [a, b])
            smeared = L < 2.0 * float(np.max(hmesh[max(k0 - 1, 0):max(k1, k0 + 1)]))
            if not smeared and np.mean(s * z > 0.5) < 0.75:
                return None, (f"component {j} is not at a bound on [{a:.6g}, {b:.6g}] s "
                              "(a singular or interior arc)")
            sides.append(s)
        if any(x == y for x, y in zip(sides[:-1], sides[1:])):
            return None, f"component {j} leaves a bound and returns to it (an interior arc)"
        if short_arcs:
            edges, sides = _with_short_arcs(solution, j, edges, sides, mid[j], half[j])
        own.append((edges, np.asarray(sides)))
    merged = sorted_union(*[e[1:-1] for e, _ in own])
    if merged.size > 1:
        merged = merged[np.concatenate([[True], np.diff(merged) > 1e-9 * max(T, 1.0)])]
    merged = merged[(merged > t0) & (merged < t0 + T)]
    edges = np.concatenate([[t0], merged, [t0 + T]])
    centres = 0.5 * (edges[:-1] + edges[1:])
    U = np.empty((nu, centres.size))
    for j, (e, sides) in enumerate(own):
        if sides is None:  # idle: held at zero
            U[j] = 0.0
            continue
        k = np.clip(np.searchsorted(e, centres) - 1, 0, sides.size - 1)  # own arc of each merged arc
        U[j] = np.where(sides[k] > 0, hi[j], lo[j])
    keep = np.concatenate([[True], np.any(U[:, 1:] != U[:, :-1], axis=0)])  # no repeated arc
    starts = edges[:-1][keep]
    edges = np.concatenate([starts, [t0 + T]])
    out = BangArcs(edges[1:-1].copy(), np.diff(edges), U[:, keep].copy())
    for a in (out.switch_times, out.durations, out.controls):
        a.setflags(write=False)
    return out, ""


def _idle(solution: Solution, per, lo: np.ndarray, hi: np.ndarray,
          n: int = 401) -> np.ndarray:
    """Per component: idle (`bang_arcs`): no switch, zero strictly inside the bounds, and
    ``|u| <= IDLE_TOL (hi - lo) / 2`` at ``n`` samples over the horizon."""
    t = float(solution.t0) + float(solution.T) * np.linspace(0.0, 1.0, n)
    u = np.asarray(solution.sample(t)[1], dtype=float).reshape(lo.size, n)
    small = np.max(np.abs(u), axis=1) <= IDLE_TOL * 0.5 * (hi - lo)
    return small & (lo < 0) & (hi > 0) & np.array([len(s) == 0 for s in per])


def _with_short_arcs(solution, j, edges, sides, mid, half, m=16, max_new=2):
    """Component ``j``'s own arcs (``edges``, ``sides``) with the short arcs of `bang_arcs`
    (``short_arcs=True``) inserted."""
    d = solution.dense
    tb, h = d.t_breaks, d.h
    N = h.size
    s = (np.arange(m) + 0.5) / m
    _, u = d.eval(np.repeat(np.arange(N), m), np.tile(s, N))
    z = ((u[j] - mid) / half).reshape(N, m).mean(axis=1)  # interval means, bounds at +-1
    T = float(tb[-1] - tb[0])
    near = np.zeros(N, bool)  # intervals holding or next to a switch of this component
    for t in edges[1:-1]:
        k = int(np.clip(np.searchsorted(tb, t) - 1, 0, N - 1))
        near[max(k - 1, 0):k + 2] = True
    edges, sides = list(edges), list(sides)
    cand = []
    for k in np.flatnonzero(~near):
        a = int(np.clip(np.searchsorted(edges, 0.5 * (tb[k] + tb[k + 1])) - 1, 0, len(sides) - 1))
        dur = h[k] * (1.0 - sides[a] * z[k]) / 2.0  # impulse short of the bound, at the other one
        if dur > max(1e-3 * h[k], 1e-6 * T):
            cand.append((dur, k))
    for dur, k in sorted(cand, reverse=True)[:max_new]:  # the largest ones
        c = 0.5 * (tb[k] + tb[k + 1])
        a = int(np.clip(np.searchsorted(edges, c) - 1, 0, len(sides) - 1))
        side = sides[a]
        dur = min(dur, 0.5 * h[k])
        if k == N - 1:
            lo_, hi_ = tb[k + 1] - dur, tb[k + 1]
        elif k == 0:
            lo_, hi_ = tb[0], tb[0] + dur
        else:
            lo_, hi_ = c - dur / 2, c + dur / 2
        # split own arc a = [edges[a], edges[a + 1]] around [lo_, hi_] at the other bound
        pieces = [(edges[a], lo_, side), (lo_, hi_, -side), (hi_, edges[a + 1], side)]
        pieces = [q for q in pieces if q[1] > q[0]]
        edges[a:a + 2] = [q[0] for q in pieces] + [pieces[-1][1]]
        sides[a:a + 1] = [q[2] for q in pieces]
    return np.asarray(edges), sides
