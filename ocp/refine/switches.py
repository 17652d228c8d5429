"""The one switch detector of the engine: where a control jumps between its bounds or
leaves them for an interior (singular, coast, constrained) arc.

`control_switches` is the definition; `find_switches` (all components, merged),
`ocp.interval_errors` (which intervals hold a smeared switch), `problems.slew.switch_times`
and the bang-bang structure of the switch-time polish (`ocp.refine.switch_times.bang_arcs`)
all call it, so their answers agree.
"""
from __future__ import annotations

import numpy as np

from appdyn.dynamics.validate import integer
from ..solution import Solution

__all__ = ["control_switches", "find_switches"]


def _crossing(t, y, i, level) -> float:
    """Time where ``y`` crosses ``level`` between samples ``i - 1`` and ``i`` (linear)."""
    dy = y[i] - y[i - 1]
    w = 0.5 if dy == 0 else float(np.clip((level - y[i - 1]) / dy, 0.0, 1.0))
    return float(t[i - 1] + w * (t[i] - t[i - 1]))


def _component_switches(t, y, band, full, min_arc) -> list:
    """Switch times of one control component, ``y`` centred (bounds at ``+-2 band``)."""
    cls = np.where(y > band, 1, np.where(y < -band, -1, 0))
    cut = np.flatnonzero(np.diff(cls) != 0) + 1
    runs = [(int(cls[a]), int(a), int(b)) for a, b in zip(np.r_[0, cut], np.r_[cut, cls.size])]
    out = []
    for r, (c, a, b) in enumerate(runs):
        prev = runs[r - 1][0] if r > 0 else None
        nxt = runs[r + 1][0] if r + 1 < len(runs) else None
        if c != 0:
            if nxt is not None and nxt != 0:  # jump from bound to bound
                out.append(_crossing(t, y, b, 0.0))
            continue
        persistent = (t[b - 1] - t[a] >= min_arc) and bool(np.any(full[a:b]))
        if persistent:  # an interior (singular, coast, constrained) arc: both ends
            if prev is not None:
                out.append(_crossing(t, y, a, band * prev))
            if nxt is not None:
                out.append(_crossing(t, y, b, band * nxt))
        elif prev is not None and nxt is not None and prev != nxt:  # a smeared switch
            i = next((i for i in range(a, b + 1) if (y[i] > 0) != (y[a - 1] > 0)), b)
            out.append(_crossing(t, y, i, 0.0))
    return out


def control_switches(solution: Solution, *, samples: int = 9) -> list[np.ndarray]:
    """Switch times [s] of each control component of ``solution``.

    The dense control of each interval is sampled at ``samples`` points including both ends
    (a jump at a mesh point shows as two samples at one time). Each component is classified
    as near its lower bound (lowest quarter of the range), near its upper bound (highest
    quarter) or in between; an unbounded component by its sign, with "in between" for
    magnitudes below a quarter of its largest one. A switch is

    * a change between the two bounds, at the crossing of the middle of the range (a jump
      at a mesh point is found exactly; a switch smeared over one or several small
      intervals is found once);
    * each end of an arc in between that lasts at least 1% of the horizon and covers a mesh
      interval (a singular, coast or constrained arc), where the control leaves the quarter
      band of the bound.

    Parameters
    ----------
    solution : Solution
    samples : int
        Sample points per interval (>= 2).

    Returns
    -------
    list of ndarray, one per control component, each shape (m_j,) [s], sorted

    Raises
    ------
    TypeError
        If ``solution`` is not a `Solution` or ``samples`` not an integer.
    ValueError
        If ``samples < 2``.

    Examples
    --------
    >>> from appdyn import ocp
    >>> from appdyn.ocp.examples import min_time
    >>> fastest = min_time()  # x'' = u, |u| <= 1, from rest at 0 to rest at 1
    >>> sol = ocp.solve(fastest, N=10)
    >>> [s.round(6) for s in ocp.control_switches(sol)]  # u = +1, then -1 from t = T/2
    [array([1.])]
    """
    if not isinstance(solution, Solution):
        raise TypeError(f"`solution` must be an ocp.Solution, got {type(solution).__name__}")
    samples = integer(samples, "samples", minimum=2)
    d = solution.dense
    N = d.N
    s = np.linspace(0.0, 1.0, samples)
    _, u = d.eval(np.repeat(np.arange(N), samples), np.tile(s, N))
    t = (d.t_breaks[:-1, None] + s[None, :] * d.h[:, None]).reshape(-1)
    lo, hi = solution.problem.u_bounds
    out = []
    for j in range(u.shape[0]):
        uj = u[j]
        if np.isfinite(lo[j]) and np.isfinite(hi[j]) and hi[j] > lo[j]:
            y, band = uj - 0.5 * (lo[j] + hi[j]), 0.25 * (hi[j] - lo[j])
        else:
            y, band = uj, 0.25 * float(np.max(np.abs(uj))) if uj.size else 0.0
            if not band > 0:
                out.append(np.zeros(0))
                continue
        inner = (np.abs(y) <= band).reshape(N, samples)
        full = np.repeat(np.all(inner, axis=1), samples)  # sample lies in a fully interior interval
        out.append(np.sort(np.asarray(_component_switches(t, y, band, full, 0.01 * solution.T),
                                      dtype=float)))
    return out


def find_switches(solution: Solution, *, samples: int = 9) -> np.ndarray:
    """Switch times [s] of all controls of ``solution``, sorted and merged: `control_switches`
    of every component, times closer than ``1e-9 max(T, 1)`` counted once.

    Returns
    -------
    ndarray, shape (m,) [s]

    Examples
    --------
    >>> from appdyn.ocp import examples, find_switches, solve
    >>> find_switches(solve(examples.min_time(), N=10)).round(6)  # x'' = u, |u| <= 1
    array([1.])
    """
    per = control_switches(solution, samples=samples)
    out = np.sort(np.concatenate(per)) if per else np.zeros(0)
    if out.size > 1:  # several components switching at one time
        out = out[np.concatenate([[True], np.diff(out) > 1e-9 * max(solution.T, 1.0)])]
    return out
