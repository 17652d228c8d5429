"""What `ocp.solve` verifies in a returned solution besides IPOPT's own convergence: the
bounds held by the dense output, and the agreement of the re-simulation with the collocation.

Bounds (`bound_violation`)
--------------------------
The NLP imposes state and control bounds at the nodes only, path constraints at the
transcription's path points only (`ocp.Transcription.path_sigma`). The dense output the user gets
(`ocp.Solution.sample`) and that the re-simulation replays (`ocp.Solution.propagate`) is the
transcription's interpolant, which can leave the bounds between the nodes: the degree
``d - 1`` Radau control polynomial on a bang-bang or singular arc overshoots (measured up to
1.9 times a torque bound on a time-optimal slew). `bound_violation` evaluates the dense
output on `bound_grid` -- in every mesh interval ``BOUND_SAMPLES + 1`` equally spaced points
``sigma = 0, 1/16, ..., 1`` (both ends: the one-sided limits at each mesh point, where a
Radau control may jump) and the transcription's own nodes -- and measures every violation of
a finite bound in units of the variable's scale (`bound_scale`), and of every inequality
path constraint ``lower <= g(x, u, p) <= upper`` evaluated there (a keep-out cone held at the
mesh points by a piecewise-constant control was crossed by 5.9e-4 at a collocation point
in between, and reported a success).

Re-simulation (`resimulation_mismatch`)
---------------------------------------
CVODES integrates the returned dense control from ``x(t0)`` (`ocp.Solution.propagation`);
the largest deviation of each state from the collocated one at the nodes, relative to the
state's magnitude (`ocp.Propagation.relative_error`), and the deviation of the re-simulated
cost from the collocated one (relative to ``max(|cost|, objective scale)``) must both be at
most ``verify_tol`` (default `default_verify_tol`: 3e-3, 0.1 for the trapezoid; measured
margins at `DEFAULT_VERIFY_TOL`). A mismatch means the discrete solution
is not a trajectory of the model under the control it returns: an unresolved switch or
singular arc, a too coarse mesh, or a control that exploits the collocation -- e.g. an
unbounded angle control jumping by ``2 pi k`` between nodes (`periodic_jumps`), which the
collocation cannot see (``sin``/``cos`` of the nodes are unchanged) but the interpolant
sweeps through every direction in between.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping

import numpy as np

from .mesh import sorted_union
from .propagation import SCALE_FLOOR
from .status import STATUS_BOUND_VIOLATION, STATUS_RESIMULATION

__all__ = ["BoundViolation", "bound_excess", "bound_grid", "bound_scale", "bound_violation",
           "interval_bound_violation", "periodic_jumps", "row_names",
           "resimulation_mismatch", "BOUND_SAMPLES", "DEFAULT_VERIFY_TOL",
           "DEFAULT_VERIFY_TOL_LOW_ORDER", "default_verify_tol",
           "STATUS_BOUND_VIOLATION", "STATUS_RESIMULATION", "check_verify_tol"]

#: Equally spaced sub-intervals per mesh interval of `bound_grid`.
BOUND_SAMPLES = 16
#: Default ``verify_tol`` of `ocp.solve` for transcriptions of order 3 and up (Radau,
#: Hermite-Simpson): largest scaled re-simulation error (states relative to their magnitude,
#: cost relative to ``max(|cost|, objective scale)``) of a success. Measured (verify off) on
#: the reference problems of the tests at their test meshes: min energy, static parameter,
#: Bryson-Denham 1e-11 to 2e-7; brachistochrone N = 8 1.2e-5; rigid-body slew N = 8 1.1e-5;
#: free-flying robot (linear control, N = 40) 8.5e-6; orbit raising with a bounded angle
#: 9.3e-4 at N = 20, 1.4e-4 at N = 40 (a fast rotation of the thrust in mid-course). The
#: failures it is meant to catch: orbit raising with an unbounded angle jumping by 2 pi k
#: between nodes 2.7e-2 (N = 40) to 0.2 (N = 20); a HS control overshooting on a bang-bang
#: arc 2.6e-3 (caught by the bound check first). 3e-3 passes the resolved cases with a
#: factor 3 over the coarsest (orbit raising at N = 20) and fails the 2 pi jumps by 9x.
DEFAULT_VERIFY_TOL = 3e-3
#: Default ``verify_tol`` for second-order transcriptions (trapezoid): its linear dense state
#: and control, re-simulated, deviate by O(h^2) -- measured 2.3e-3 to 5.7e-2 on the
#: reference problems at N = 4 to 20 (Bryson-Denham N = 9: 5.7e-2; the cost 4.7e-2) --
#: so it only catches gross failures (a model that is not what was collocated, 2 pi jumps).
DEFAULT_VERIFY_TOL_LOW_ORDER = 1e-1


def default_verify_tol(transcription) -> float:
    """`DEFAULT_VERIFY_TOL`, or `DEFAULT_VERIFY_TOL_LOW_ORDER` for a transcription of order
    below 3 (trapezoid)."""
    return DEFAULT_VERIFY_TOL if transcription.order >= 3 else DEFAULT_VERIFY_TOL_LOW_ORDER


def check_verify_tol(verify_tol, transcription) -> float:
    """``verify_tol`` of `ocp.solve` checked: a finite number > 0 (``None``: the default of
    ``transcription``, `default_verify_tol`)."""
    if verify_tol is None:
        return default_verify_tol(transcription)
    if (isinstance(verify_tol, (bool, np.bool_))
            or not isinstance(verify_tol, (int, float, np.integer, np.floating))
            or not (0 < verify_tol < np.inf)):
        raise ValueError(f"`verify_tol` must be a finite number > 0, got {verify_tol!r}")
    return float(verify_tol)


@dataclass(frozen=True)
class BoundViolation:
    """Violations of the state and control bounds by a solution's dense output.

    Attributes
    ----------
    by_name : mapping of str to float
        Every state and control with a finite bound: its largest violation on `bound_grid`
        in units of its scale (`bound_scale`) [-]; 0.0 inside its bounds.
    max : float
        The largest of them (0.0 without bounds) [-].
    name : str or None
        The variable of ``max`` (``None`` when nothing is violated).
    time : float [s]
        Where it is worst (NaN when nothing is violated).
    value, lower, upper, scale : float
        Its value there, its bounds and its scale [variable units].
    kind : str
        ``'state'``, ``'control'`` or ``'path'`` (a path-constraint row, named by its
        constraint's name, ``name[i]`` for row ``i`` of several); ``''`` when nothing is
        violated.
    """

    by_name: Mapping[str, float] = field(default_factory=dict)
    max: float = 0.0
    name: str | None = None
    time: float = float("nan")
    value: float = float("nan")
    lower: float = float("nan")
    upper: float = float("nan")
    scale: float = float("nan")
    kind: str = ""

    def __float__(self) -> float:
        return float(self.max)

    def describe(self, *, controls: tuple = ()) -> str:
        """A sentence on the worst violation and its remedy."""
        if self.name is None:
            return "within bounds"
        kind = self.kind or ("control" if self.name in controls else "state")
        what = "path constraint" if kind == "path" else kind
        text = (f"the dense {what} `{self.name}` leaves its bounds [{self.lower:g}, {self.upper:g}] "
                f"at t = {self.time:.6g} s: {self.value:.10g} ({self.max:.3g} in units of its "
                f"scale {self.scale:g})")
        if kind == "path":
            return text + ("; the NLP imposes it at the collocation points (the control "
                           "nodes of the trapezoid and Hermite-Simpson), the state "
                           "interpolant crosses it between them: refine the mesh "
                           "(ocp.refine, which also backs off a small overshoot)")
        if kind == "control" and self.max < 1e-3:
            return text + ("; a small overshoot of the interpolant through nodes that IPOPT's "
                           "interior point keeps a hair inside the bound next to a switch: "
                           "tighten IPOPT's tol (ipopt_options={'tol': 1e-10}) or solve with "
                           "transcription='radau' and control='constant' or 'linear'")
        if kind == "control":
            return text + ("; the control interpolant overshoots between the nodes (bang-bang or "
                           "singular arc): solve with transcription='radau' and control='linear' or "
                           "'constant' (piecewise-linear/constant: within box bounds) or refine "
                           "the mesh (ocp.refine)")
        return text + "; the state interpolant overshoots between the nodes: refine the mesh (ocp.refine)"


def bound_grid(dense) -> tuple[np.ndarray, np.ndarray]:
    """``(k, sigma)``, shape (M,) each: where `bound_violation` evaluates the dense output
    ``dense`` (`ocp.DenseOutput`): in every interval ``sigma = j / BOUND_SAMPLES``, ``j = 0
    .. BOUND_SAMPLES``, and the transcription's owned nodes."""
    tr = dense.transcription
    sig = sorted_union(np.linspace(0.0, 1.0, BOUND_SAMPLES + 1), tr.node_sigma)
    return np.repeat(np.arange(dense.N), sig.size), np.tile(sig, dense.N)


def bound_scale(bounds: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """Scale of each variable in `bound_violation`: ``max(|finite bounds|, max_n |v(t_n)|,
    SCALE_FLOOR)``.

    Parameters
    ----------
    bounds : ndarray, shape (2, n)
    nodes : ndarray, shape (n, m)
        The variables at the node times [variable units].

    Returns
    -------
    ndarray, shape (n,)
    """
    b = np.where(np.isfinite(bounds), np.abs(bounds), 0.0).max(axis=0)
    v = np.max(np.abs(nodes), axis=1) if nodes.shape[1] else np.zeros(nodes.shape[0])
    return np.maximum(np.maximum(b, np.where(np.isfinite(v), v, 0.0)), SCALE_FLOOR)


def row_names(con) -> list[str]:
    """The names of the rows of the path constraint ``con`` in `BoundViolation`: its name,
    or ``name[i]`` for row ``i`` of several."""
    return [con.name] if con.size == 1 else [f"{con.name}[{i}]" for i in range(con.size)]


def _path_rows(problem, x: np.ndarray, u: np.ndarray, p) -> tuple | None:
    """``(bounds (2, m), values (m, M), names)`` of ``problem``'s inequality path constraints
    at the states ``x`` (nx, M) and controls ``u`` (nu, M), ``p`` the parameters; ``None``
    without any. Rows of a constraint of several rows are named ``name[i]``.

    Equality rows (``lower == upper``) are left out: they hold at the collocation points,
    and no interpolant keeps them in between (the Radau control of orbit raising through
    unit vectors has ``|u|^2 = 1.72`` between two nodes at N = 20); the re-simulation check
    (`resimulation_mismatch`) judges what that deviation does to the trajectory."""
    if not any(np.any(np.asarray(c.lower) < np.asarray(c.upper)) for c in problem.path):
        return None
    pv = np.zeros((0, 1)) if p is None or np.size(p) == 0 else np.asarray(p, float).reshape(-1, 1)
    M = x.shape[1]
    vals, lo, hi, names = [], [], [], []
    for con in problem.path:
        a, b = con.fun.size_out(0)
        g = np.asarray(con.fun(x, u, pv), dtype=float).reshape(a, M, b)  # implicit map
        vals.append(g.transpose(1, 2, 0).reshape(M, a * b).T)  # column-major rows per point
        lo.append(np.broadcast_to(con.lower, (con.size,)))
        hi.append(np.broadcast_to(con.upper, (con.size,)))
        names += row_names(con)
    bounds, values = np.stack([np.concatenate(lo), np.concatenate(hi)]), np.concatenate(vals)
    keep = bounds[0] < bounds[1]
    return bounds[:, keep], values[keep], [n for n, k in zip(names, keep) if k]


def _excess(dense, problem, x_nodes, u_nodes, p=None):
    """``(bounds (2, n), scale (n,), k, s, values (n, M), excess (n, M), names, kinds)`` of
    the states, controls and path-constraint rows (in that order) on `bound_grid`, or
    ``None`` without finite bounds. A path row's scale is ``max(|finite bounds|, max |g|
    on the grid, SCALE_FLOOR)``."""
    model = problem.model
    bounds = np.concatenate([problem.x_bounds, problem.u_bounds], axis=1)
    if dense.N == 0 or not (np.any(np.isfinite(bounds)) or problem.path):
        return None
    k, s = bound_grid(dense)
    x, u = dense.eval(k, s)
    values = np.concatenate([x, u], axis=0)
    scale = bound_scale(bounds, np.concatenate([x_nodes, u_nodes], axis=0))
    names = list(model.states) + list(model.controls)
    kinds = ["state"] * len(model.states) + ["control"] * len(model.controls)
    path = _path_rows(problem, x, u, problem.p if p is None else p)
    if path is not None:
        pb, pv, pn = path
        bounds = np.concatenate([bounds, pb], axis=1)
        values = np.concatenate([values, pv], axis=0)
        scale = np.concatenate([scale, bound_scale(pb, pv)])
        names += pn
        kinds += ["path"] * len(pn)
    if not np.any(np.isfinite(bounds)):
        return None
    lo, hi = bounds[0][:, None], bounds[1][:, None]
    excess = np.maximum(np.maximum(lo - values, values - hi), 0.0) / scale[:, None]
    excess[~np.isfinite(values)] = np.inf
    return bounds, scale, k, s, values, excess, names, kinds


def bound_excess(solution) -> tuple | None:
    """``(bounds, scale, values, names)`` of ``solution``'s states, controls and path
    constraint rows (in that order) on `bound_grid`: their bounds, shape (2, n), scales
    (`bound_scale`), shape (n,), dense values, shape (n, M) [their units], and names;
    ``None`` without finite bounds."""
    out = _excess(solution.dense, solution.problem, solution.x, solution.u, solution.p)
    return None if out is None else (out[0], out[1], out[4], out[6])


def interval_bound_violation(solution) -> np.ndarray:
    """Largest scaled bound violation of ``solution``'s dense output in each mesh interval
    (`bound_violation` per interval, path constraints included), shape (N,) [-]: where
    `ocp.refine` splits a mesh whose dense output leaves a bound."""
    d = solution.dense
    out = _excess(d, solution.problem, solution.x, solution.u, solution.p)
    if out is None:
        return np.zeros(d.N)
    k, excess = out[2], out[5]
    per = np.zeros(d.N)
    np.maximum.at(per, k, np.max(excess, axis=0))
    return per


def bound_violation(dense, problem, x_nodes: np.ndarray, u_nodes: np.ndarray, *,
                    p=None) -> BoundViolation:
    """The `BoundViolation` of the dense output ``dense`` of a solution of ``problem`` on
    `bound_grid`, its path constraints included (``x_nodes``, ``u_nodes``: the solution's
    ``x`` and ``u``, for the scales; ``p``: its parameters, default ``problem.p``)."""
    out = _excess(dense, problem, x_nodes, u_nodes, p)
    if out is None:
        return BoundViolation()
    bounds, scale, k, s, values, excess, names, kinds = out
    finite = np.any(np.isfinite(bounds), axis=0)
    worst = np.max(excess, axis=1)
    by_name = {n: float(worst[i]) for i, n in enumerate(names) if finite[i]}
    i = int(np.argmax(worst))
    if not worst[i] > 0:
        return BoundViolation(by_name)
    j = int(np.argmax(excess[i]))
    t = float(dense.t_breaks[k[j]] + s[j] * dense.h[k[j]])
    return BoundViolation(by_name, float(worst[i]), names[i], t, float(values[i, j]),
                          float(bounds[0, i]), float(bounds[1, i]), float(scale[i]), kinds[i])


def periodic_jumps(solution) -> list[tuple[str, float, int]]:
    """Controls that behave like an unbounded angle: jumps by about ``2 pi k`` (``k != 0``,
    within ``pi/2``) between adjacent nodes of a control whose bounds span more than
    ``2 pi`` (or are absent).

    Returns
    -------
    list of (str, float, int)
        ``(control name, time of the first such jump [s], k)`` per such control.
    """
    lo, hi = solution.problem.u_bounds
    out = []
    for j, name in enumerate(solution.problem.model.controls):
        if hi[j] - lo[j] <= 2 * np.pi:
            continue
        du = np.diff(solution.u[j])
        k = np.round(du / (2 * np.pi))
        hit = np.flatnonzero((k != 0) & (np.abs(du - 2 * np.pi * k) < np.pi / 2))
        if hit.size:
            out.append((name, float(solution.t[hit[0]]), int(k[hit[0]])))
    return out


def resimulation_mismatch(solution, verify_tol: float, *,
                          objective_scale: float = 1.0) -> str | None:
    """Why the re-simulation of ``solution`` disagrees with its collocation beyond
    ``verify_tol`` (module docstring), or ``None`` when it agrees.

    Parameters
    ----------
    solution : ocp.Solution
    verify_tol : float
        Largest scaled state and cost error [-].
    objective_scale : float
        Floor of the cost's magnitude in the relative cost error [cost units].

    Returns
    -------
    str or None
        The message: the worst state, the costs, and the likely cause with its remedy.
    """
    prop = solution.propagation
    if not prop.success:
        what = f"the re-simulation failed ({prop.message})"
    else:
        rel = prop.relative_error
        states = solution.problem.model.states
        i = int(np.argmax(rel)) if rel.size else 0
        dJ = abs(prop.cost - solution.cost) / max(abs(solution.cost), abs(objective_scale))
        if (not rel.size or rel[i] <= verify_tol) and dJ <= verify_tol:
            return None
        worst = (f"state `{states[i]}` off by {prop.error[i]:.3g} ({rel[i]:.3g} of its "
                 f"magnitude)") if rel.size else "no states"
        what = (f"the re-simulation of the returned control disagrees with the collocation "
                f"beyond verify_tol {verify_tol:g}: {worst}; cost re-simulated "
                f"{prop.cost:.10g} against collocated {solution.cost:.10g} ({dJ:.3g} relative)")
    jumps = periodic_jumps(solution)
    if jumps:
        name, t, k = jumps[0]
        cause = (f"likely cause: unbounded periodic (angle) control `{name}` jumps by "
                 f"{k} x 2 pi between nodes (first at t = {t:.6g} s), which the collocation "
                 f"cannot see but the dense control sweeps through: bound it (e.g. u_bounds "
                 f"{{'{name}': (-pi, pi)}}, or another turn such as (0, 2 pi) that holds "
                 f"its range without a wrap) or use a unit vector")
    else:
        cause = ("likely cause: the mesh does not resolve the solution (a switch or singular "
                 "arc smeared over an interval, or too few intervals): refine the mesh "
                 "(ocp.refine), use more intervals, or control='linear'/'constant' on bang-bang "
                 "arcs; or pass verify=False to accept the collocated solution")
    return f"{what}; {cause}"
