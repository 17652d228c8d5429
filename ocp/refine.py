"""Mesh refinement, multistart and switch polishing on top of `ocp.solve`.

Three entry points, each returning a `RefinedSolution` (a `Solution` with an ``info``
mapping; it never raises on a solver failure, it returns ``success=False``):

* `refine` — ``hp``-style mesh refinement driven by an error estimate. Per mesh interval the
  dynamics are re-integrated (CVODES) from the collocated state at the interval start under
  the solution's own dense control, and compared with the collocated states at the
  interval's nodes, relative to the state scale ``max(1, max_t |x_i|)`` (`interval_errors`).
  Intervals where a bounded control jumps between its bounds (bang-bang switches) get a
  second estimate: the state increment the smeared polynomial control misses compared with
  the bang-bang control with the same impulse. Bad intervals are split (into as many pieces
  as the local order predicts, switch intervals tightly around the estimated switch time),
  very accurate neighbours are merged, and each round is warm-started from the last.
* `solve_multistart` — solve from several guesses, keep the best converged one.
* `polish_switches` — for bang-bang / time-optimal problems: a re-solve with a
  piecewise-constant control (`RadauConstantControl`) on a *free* mesh whose interval
  lengths are decision variables ("moving knots"), so switch times land exactly on knots:
  the switching structure no longer costs accuracy (on a fixed mesh a switch inside an
  interval of length ``h`` leaves an ``O(h^2)`` error in ``T``).

The free mesh is built without touching the engine: the problem is restated in a pseudo
time ``sigma in [0, 1]`` on a fixed mesh, with the physical time ``t`` an extra state and
the time dilation ``v = dt/dsigma`` an extra control, piecewise constant per interval::

    dx/dsigma = v f(x, u, p),    dt/dsigma = v,     v_lower <= v <= v_upper

Within an interval ``t`` is affine in ``sigma``, so Radau collocation of the restated
problem is exactly Radau collocation of the original one on the mesh of the physical
interval lengths ``h_k = v_k dsigma_k``; the result is returned as a `Solution` of the
original problem on that mesh.
"""
from __future__ import annotations

import math
import sys
import time
from dataclasses import dataclass, field, fields
from typing import Mapping, NamedTuple, Sequence

import casadi as ca
import numpy as np

from dynamics.model import Model

from .mesh import Mesh
from .problem import Constraint, Problem
from .solution import Solution, _stack_U, interval_integrator
from .solve import _make_solution, solve
from .transcription import Radau, Transcription, _f_cols, _L_cols, _sx_ok, get_transcription

__all__ = ["refine", "solve_multistart", "polish_switches", "RefinedSolution", "RefinementRound",
           "RadauConstantControl", "IntervalErrors", "interval_errors", "find_switches", "annotate"]

_STRICT = {"tol": 1e-10, "bound_relax_factor": 0.0, "max_iter": 3000}
_BRACKET = 1.0 / 16.0  # width of the new switch interval relative to the old one (refine)


# ================================================================================ results
class RefinementRound(NamedTuple):
    """One round of `refine`: the NLP solved on a mesh and the error estimated on it.

    Attributes
    ----------
    n_intervals : int
    max_error : float
        Largest estimated relative interval error (NaN when the NLP failed).
    cost : float
    iterations : int
        IPOPT iterations of the round.
    time : float [s]
        Wall time of the round: NLP build + solve + error estimate.
    """

    n_intervals: int
    max_error: float
    cost: float
    iterations: int
    time: float


@dataclass(frozen=True, eq=False, repr=False)
class RefinedSolution(Solution):
    """A `Solution` plus ``info`` (returned by `refine`, `solve_multistart`, `polish_switches`).

    It is a `Solution` in every respect (``isinstance`` holds, it warm-starts `solve`).

    Attributes
    ----------
    info : mapping of str to object
        What the driver did. `refine`: ``'refinement'`` (list of `RefinementRound`, one per
        NLP solved, first the initial one), ``'converged'`` (max error <= tol), ``'errors'``
        (the final `IntervalErrors`), ``'meshes'`` (the mesh of each round),
        ``'tol'``, ``'stop'`` (why it stopped). `solve_multistart`: ``'starts'`` (list of
        dicts with ``index, success, status, cost, T, constraint_violation, iterations,
        time``) and ``'best'`` (index of the start returned). `polish_switches`:
        ``'switch_times'`` (knots where the control jumps), ``'initial_switch_times'``,
        ``'initial_T'``, ``'N'``, ``'stretch_active'`` (intervals whose length sits at a
        bound of ``stretch``), ``'free_mesh_solution'`` (the solution of the restated
        problem) and ``'wall_time'``.
    """

    info: Mapping = field(default_factory=dict)

    @property
    def refinement(self) -> list | None:
        """`refine` history: list of `RefinementRound` (``None`` from the other drivers)."""
        return self.info.get("refinement")

    @property
    def starts(self) -> list | None:
        """`solve_multistart` record of all starts (``None`` from the other drivers)."""
        return self.info.get("starts")


def annotate(solution: Solution, info: Mapping | None = None, **changes) -> RefinedSolution:
    """A copy of ``solution`` as a `RefinedSolution`, ``info`` merged over its own and the
    fields in ``changes`` (e.g. ``success``, ``status``, ``message``) replaced; the lazily
    computed re-simulation is shared. For drivers that verify or post-process a result
    (`problems.slew`).

    Raises
    ------
    TypeError
        If ``solution`` is not a `Solution`.
    ValueError
        If ``changes`` names a field a `Solution` does not have.
    """
    if not isinstance(solution, Solution):
        raise TypeError(f"`solution` must be an ocp.Solution, got {type(solution).__name__}")
    names = {f.name for f in fields(Solution)}
    bad = sorted(set(changes) - names)
    if bad:
        raise ValueError(f"unknown Solution fields {bad}")
    return _annotate(solution, info or {}, **changes)


def _annotate(sol: Solution, info: Mapping, **changes) -> RefinedSolution:
    kw = {f.name: getattr(sol, f.name) for f in fields(Solution)}
    kw.pop("info", None)
    kw.update(changes)
    # the lazily computed re-simulation is shared unless the trajectory itself changed
    same = not ({"x", "u", "p", "T", "t0", "t", "mesh", "transcription", "problem", "_dense"} & set(changes))
    kw["_lazy"] = sol._lazy if same else {}
    merged = dict(getattr(sol, "info", {}) or {})
    merged.update(info)
    return RefinedSolution(**kw, info=merged)


# ============================================================ piecewise-constant control
@dataclass(frozen=True)
class RadauConstantControl(Radau):
    """Radau collocation of degree ``d`` with one constant control per mesh interval.

    The state is collocated exactly as in `Radau`; the control is a single value per
    interval (``u_sigma = [1]``), held at every collocation point, so a bang-bang control
    can only switch at mesh points. Path constraints are imposed at the interval ends.
    Use it with ``solve(..., transcription=RadauConstantControl(3))``; `polish_switches`
    uses it on a free mesh.
    """

    name = "radau-constant-control"

    @property
    def u_sigma(self):
        return np.array([1.0])

    def _kernel(self, f, L, xs, X, us, U, h, p):
        Uc = ca.repmat(U[:, 0], 1, self.degree)
        Xall = ca.horzcat(xs, X)
        defect = ca.mtimes(Xall, ca.DM(self.D.T)) - h * _f_cols(f, X, Uc, p)
        quad = 0 if L is None else h * ca.mtimes(_L_cols(L, X, Uc, p), ca.DM(self.weights))
        return defect, X[:, -1], quad

    def _interpolate(self, f, xs, X, us, U, h, p, s):
        x, _ = super()._interpolate(f, xs, X, us, ca.repmat(U[:, 0], 1, self.degree), h, p, s)
        return x, U[:, 0]


# ========================================================================= error estimate
@dataclass(frozen=True)
class IntervalErrors:
    """Per-interval error estimate of a solution (see `interval_errors`).

    Attributes
    ----------
    error : ndarray, shape (N,)
        ``max(defect, switch)`` per interval (``inf`` where the re-integration failed).
    defect : ndarray, shape (N,)
        ``max_i max_points |x_integrated - x_solution|_i / max(1, max_t |x_i|)`` over the
        interval's nodes and quarter points, the integration restarted from the collocated
        state at each interval start.
    switch : ndarray, shape (N,)
        For intervals where a control jumps (bang-bang switch inside the interval):
        ``max_i integral |f_i(x, u_bang) - f_i(x, u)| dt / max(1, max_t |x_i|)``, with
        ``u_bang`` the two-level control of the same impulse; 0 elsewhere.
    switching : ndarray of bool, shape (N,)
    switch_time : ndarray, shape (N,) [s]
        Estimated switch time inside switching intervals (NaN elsewhere).
    scale : ndarray, shape (nx,)
        ``max(1, max_t |x_i|)``.
    """

    error: np.ndarray
    defect: np.ndarray
    switch: np.ndarray
    switching: np.ndarray
    switch_time: np.ndarray
    scale: np.ndarray

    @property
    def max_error(self) -> float:
        return float(np.max(self.error)) if self.error.size else 0.0


def _check_sigma(tr: Transcription) -> np.ndarray:
    """Where the re-integrated state is compared inside an interval: the owned nodes and the
    quarter points (the dense output between nodes counts too: for the trapezoid its linear
    interpolant is only second-order accurate, while its mesh points are third-order
    locally)."""
    return np.union1d(tr.node_sigma, [0.25, 0.5, 0.75])


def _interval_integrator(sol: Solution, rtol: float, atol: float) -> ca.Function:
    """``(x0 (nx, N), data) -> x at the check points of every interval`` by CVODES."""
    integ = interval_integrator(sol, _check_sigma(sol.transcription), rtol, atol)
    nx = sol.problem.model.nx
    x0, dat = ca.MX.sym("x0", nx), ca.MX.sym("data", integ.numel_in("p"))
    step = ca.Function("interval_step", [x0, dat], [ca.vec(integ(x0=x0, p=dat)["xf"])])
    return step.map(sol._dense.N)


def _simpson(n: int) -> np.ndarray:
    """Simpson weights on ``n`` (odd) equally spaced points of [0, 1]."""
    w = np.ones(n)
    w[1:-1:2], w[2:-1:2] = 4.0, 2.0
    return w / (3.0 * (n - 1))


def interval_errors(solution: Solution, *, rtol: float = 1e-11, atol: float = 1e-12,
                    samples: int = 33) -> IntervalErrors:
    """Estimate the error of each mesh interval of ``solution``.

    *Defect*: the dynamics are integrated by CVODES over each interval from the collocated
    state at its start, under the transcription's dense control, and compared with the
    solution's states at the interval's nodes and at its quarter points (the dense output,
    `Solution.sample`), relative to ``max(1, max_t |x_i|)``; the largest deviation counts.

    *Switches*: a control component "switches" in an interval when the levels ``A`` before
    and ``B`` after it differ by at least 0.4 of its range (``u_upper - u_lower`` for a
    bounded control, the span over the horizon otherwise, then with a sign change) and the
    control in the interval is neither all at ``A`` nor all at ``B`` (within 5% of the range):
    a smeared jump (a polynomial control crossing over, a constant control in between).
    ``A`` is the control at the last control node of the previous interval, ``B`` at the
    first control node of the next one, each taken as the bound itself when within 10% of
    the range of it. The switch time matches the impulse,
    ``s* = (mean(u) - B) / (A - B)`` (fraction of the interval). The error is the state
    increment that the smeared control misses, ``integral |f(x, u_bang) - f(x, u)| dt`` with
    ``u_bang = A`` before ``s*`` and ``B`` after, relative as above. It is ``O(h)``, while the
    error of ``T`` or of the cost from a smeared switch is ``O(h^2)``.

    Parameters
    ----------
    solution : Solution
    rtol, atol : float
        CVODES tolerances of the re-integration.
    samples : int
        Odd number of sample points per interval for the switch analysis.

    Returns
    -------
    IntervalErrors
    """
    if not isinstance(solution, Solution):
        raise TypeError(f"`solution` must be an ocp.Solution, got {type(solution).__name__}")
    if samples < 3 or samples % 2 == 0:
        raise ValueError(f"`samples` must be an odd integer >= 3, got {samples!r}")
    sol, d = solution, solution._dense
    problem, model = sol.problem, sol.problem.model
    nx, nu, N = model.nx, model.nu, d.N
    scale = np.maximum(1.0, np.max(np.abs(sol.x), axis=1))

    # ---------------------------------------------------------------- defects
    try:
        run = _interval_integrator(sol, rtol, atol)
        pars = np.concatenate([d.us, _stack_U(d.Uo, np.arange(N)), d.h[None, :],
                               np.repeat(sol.p[:, None], N, axis=1)], axis=0)
        sig = _check_sigma(sol.transcription)
        xi = np.asarray(run(d.xs, pars)).reshape(nx, sig.size, N, order="F")
        xc, _ = d.eval(np.repeat(np.arange(N), sig.size), np.tile(sig, N))
        xc = xc.reshape(nx, N, sig.size).transpose(0, 2, 1)
        dev = np.abs(xi - xc) / scale[:, None, None]
        defect = np.max(dev, axis=(0, 1))
        defect[~np.isfinite(defect)] = np.inf
    except RuntimeError:
        defect = np.full(N, np.inf)

    # ---------------------------------------------------------------- switches
    s = np.linspace(0.0, 1.0, samples)
    k_all = np.repeat(np.arange(N), samples)
    xs_, us_ = d.eval(k_all, np.tile(s, N))
    xs_ = xs_.reshape(nx, N, samples)
    us_ = us_.reshape(nu, N, samples)
    lo, hi = problem.u_bounds
    tr = sol.transcription
    # the control at the last control node of each interval (sigma = 1 in every
    # transcription) and at the first one (where a Radau polynomial is not extrapolated)
    s_first = 0.0 if tr.u_at_start else float(tr.u_sigma[0])
    _, u_first = d.eval(np.arange(N), np.full(N, s_first))
    switching = np.zeros(N, bool)
    s_star = np.full(N, np.nan)
    u_bang = us_.copy()
    for j in range(nu):
        uj = us_[j]
        bounded = np.isfinite(lo[j]) and np.isfinite(hi[j]) and hi[j] > lo[j]
        span = (hi[j] - lo[j]) if bounded else float(np.ptp(uj))
        if not span > 0:
            continue
        last = uj[:, -1]
        A = np.concatenate([[u_first[j, 0]], last[:-1]])  # level before interval k
        B = np.concatenate([u_first[j, 1:], [last[-1]]])  # level after it
        if bounded:  # levels within 10% of the range of a bound are taken as that bound
            for level in (A, B):
                level[level <= lo[j] + 0.1 * span] = lo[j]
                level[level >= hi[j] - 0.1 * span] = hi[j]
        else:
            A, B = np.where(A * B < 0, A, 0.0), np.where(A * B < 0, B, 0.0)  # sign changes only
        at_A = np.all(np.abs(uj - A[:, None]) <= 0.05 * span, axis=1)
        at_B = np.all(np.abs(uj - B[:, None]) <= 0.05 * span, axis=1)
        flag = (np.abs(A - B) >= 0.4 * span) & ~at_A & ~at_B
        mean = uj @ _simpson(samples)
        with np.errstate(divide="ignore", invalid="ignore"):
            frac = np.clip((mean - B) / (A - B), 0.0, 1.0)
        for k in np.flatnonzero(flag):
            switching[k] = True
            sk = frac[k]
            s_star[k] = sk if np.isnan(s_star[k]) else 0.5 * (s_star[k] + sk)
            u_bang[j, k] = np.where(s < sk, A[k], B[k])
    switch = np.zeros(N)
    ks = np.flatnonzero(switching)
    if ks.size:
        M = ks.size * samples
        X = xs_[:, ks].reshape(nx, M)
        args = (np.repeat(sol.p[:, None], M, axis=1),)
        fmap = model.f.map(M)
        diff = np.abs(np.asarray(fmap(X, u_bang[:, ks].reshape(nu, M), *args))
                      - np.asarray(fmap(X, us_[:, ks].reshape(nu, M), *args)))
        incr = diff.reshape(nx, ks.size, samples) @ _simpson(samples) * d.h[ks][None, :]
        switch[ks] = np.max(incr / scale[:, None], axis=0)
    switch_time = np.full(N, np.nan)
    switch_time[ks] = d.t_breaks[ks] + s_star[ks] * d.h[ks]
    error = np.maximum(defect, switch)
    for a in (error, defect, switch, switching, switch_time, scale):
        a.setflags(write=False)
    return IntervalErrors(error, defect, switch, switching, switch_time, scale)


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


def find_switches(solution: Solution, *, samples: int = 9) -> np.ndarray:
    """Switch times [s] of the controls of ``solution``, sorted.

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
    ndarray, shape (m,) [s]
        Switch times of all components (times closer than ``1e-9 T`` merged).
    """
    if not isinstance(solution, Solution):
        raise TypeError(f"`solution` must be an ocp.Solution, got {type(solution).__name__}")
    samples = _check_int("samples", samples, 2)
    d = solution._dense
    N = d.N
    s = np.linspace(0.0, 1.0, samples)
    _, u = d.eval(np.repeat(np.arange(N), samples), np.tile(s, N))
    t = (d.t_breaks[:-1, None] + s[None, :] * d.h[:, None]).reshape(-1)
    lo, hi = solution.problem.u_bounds
    times = []
    for j in range(u.shape[0]):
        uj = u[j]
        if np.isfinite(lo[j]) and np.isfinite(hi[j]) and hi[j] > lo[j]:
            y, band = uj - 0.5 * (lo[j] + hi[j]), 0.25 * (hi[j] - lo[j])
        else:
            y, band = uj, 0.25 * float(np.max(np.abs(uj)))
            if not band > 0:
                continue
        inner = (np.abs(y) <= band).reshape(N, samples)
        full = np.repeat(np.all(inner, axis=1), samples)  # sample lies in a fully interior interval
        times += _component_switches(t, y, band, full, 0.01 * solution.T)
    out = np.sort(np.asarray(times, dtype=float))
    if out.size > 1:  # several components switching at one time
        out = out[np.concatenate([[True], np.diff(out) > 1e-9 * max(solution.T, 1.0)])]
    return out


# ==================================================================================== refine
def _local_order(tr: Transcription) -> int:
    if isinstance(tr, Radau):
        return tr.degree + 1
    return {"trapezoid": 3}.get(tr.name, 4)


def _new_mesh(mesh: Mesh, est: IntervalErrors, T: float, t0: float, tol: float, q: int,
              max_intervals: int) -> Mesh | None:
    """Split inaccurate intervals, bracket switches, merge very accurate neighbours."""
    b, h = mesh.breaks, mesh.fractions
    N = mesh.N
    err = np.minimum(np.where(np.isfinite(est.error), est.error, np.inf), 1e12 * tol)
    cuts: list[np.ndarray] = [np.zeros(0)] * N  # interior knots per interval, in sigma
    priority = np.zeros(N)
    for k in range(N):
        if err[k] <= tol:
            continue
        priority[k] = err[k] / tol
        if est.switching[k] and est.switch[k] >= est.defect[k]:
            s = (est.switch_time[k] - t0) / T - b[k]
            s = s / h[k]
            # a bracket 1/16 of the interval wide around the impulse-matched switch time
            knots = np.array([s - _BRACKET / 2, s + _BRACKET / 2])
            cuts[k] = knots[(knots > 0.02) & (knots < 0.98)]
            if cuts[k].size == 0:
                cuts[k] = np.array([0.5])
            priority[k] = np.inf
        else:
            n = int(np.clip(math.ceil((err[k] / (0.25 * tol)) ** (1.0 / q)), 2, 8))
            cuts[k] = np.arange(1, n) / n
    # budget: most important splits first
    n_new = N + sum(c.size for c in cuts)
    if n_new > max_intervals:
        order = np.argsort(-priority, kind="stable")
        budget = max_intervals - N
        for k in order:
            if cuts[k].size == 0:
                continue
            if cuts[k].size <= budget:
                budget -= cuts[k].size
            elif budget >= 1:
                cuts[k] = np.arange(1, budget + 1) / (budget + 1)
                budget = 0
            else:
                cuts[k] = np.zeros(0)
    # merge pairs of very accurate, unsplit, non-switching neighbours
    drop = np.zeros(N + 1, bool)
    merge_ok = (err * 2.0 ** (q + 1) <= 1e-3 * tol) & ~est.switching
    k = 0
    while k < N - 1:
        if (merge_ok[k] and merge_ok[k + 1] and cuts[k].size == 0 and cuts[k + 1].size == 0):
            drop[k + 1] = True
            k += 2
        else:
            k += 1
    pieces = [b[:-1][~drop[:-1]]]
    for k in range(N):
        if cuts[k].size:
            pieces.append(b[k] + cuts[k] * h[k])
    new = np.unique(np.concatenate(pieces + [[1.0]]))
    new[0], new[-1] = 0.0, 1.0
    new = new[np.concatenate([[True], np.diff(new) > 1e-14])]
    new[-1] = 1.0
    if new.size == b.size and np.array_equal(new, b):
        return None
    if not any(c.size for c in cuts):
        return None  # nothing to split (budget exhausted): merging alone does not help
    return Mesh(new)


def _check_positive(name, v):
    if isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer)) or not v > 0:
        raise ValueError(f"`{name}` must be a number > 0, got {v!r}")


def _check_int(name, v, low):
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer)) or v < low:
        raise ValueError(f"`{name}` must be an integer >= {low}, got {v!r}")
    return int(v)


def _transcription(transcription, degree) -> Transcription:
    if isinstance(transcription, Transcription):
        return transcription
    if transcription == "radau":
        return get_transcription("radau", degree)
    return get_transcription(transcription)


def refine(problem: Problem, solution: Solution | None = None, *, tol: float = 1e-6,
           max_rounds: int = 6, max_intervals: int = 400, transcription="radau", N: int = 20,
           degree: int = 3, verbose=False, **solve_kwargs) -> RefinedSolution:
    """Solve ``problem`` and refine the mesh until the estimated error is below ``tol``.

    Each round estimates the error of every interval (`interval_errors`: re-integration of
    the dynamics from each interval's collocated initial state under the solution's control,
    relative to the state scale ``max(1, max_t |x_i|)``; plus, where a control switches between
    its bounds inside an interval, the state increment the smeared control misses). Then:

    * an interval with a switch is cut just around the estimated switch time (a bracket
      1/16 of the interval wide), so intervals concentrate geometrically there (the error of
      ``T`` from a switch smeared over an interval ``h`` is ``O(h^2)``: 1/256 per round);
    * any other interval with error ``e > tol`` is cut into ``n = ceil((4 e/tol)^(1/q))``
      equal pieces (2 to 8), ``q`` the local order (``d + 1`` for Radau of degree ``d``);
    * two neighbours with ``e 2^(q+1) <= 1e-3 tol`` and no switch are merged;

    and the problem is solved again on the new mesh, warm-started from the last solution.
    It stops when the largest estimated error is ``<= tol``, after ``max_rounds`` rounds, when
    the mesh would exceed ``max_intervals`` intervals, or when an NLP fails.

    Parameters
    ----------
    problem : Problem
    solution : Solution, optional
        Start from this solution (its mesh; reused as round 0 if it solves ``problem`` with
        the same transcription, else re-solved on its mesh with it as the guess).
    tol : float
        Target relative interval error.
    max_rounds : int
        Largest number of re-solves after the initial solve.
    max_intervals : int
        Largest number of mesh intervals.
    transcription, degree : see `ocp.solve` (``degree`` applies to ``'radau'`` only).
    N : int
        Number of uniform intervals of the initial mesh (without ``solution`` or ``mesh``).
    verbose : bool or callable
        Passed to `ocp.solve`; ``True`` also prints one line per round.
    **solve_kwargs
        Passed to `ocp.solve` (``ipopt_options``, ``scale``, ``expand``; ``guess`` and
        ``mesh`` for the initial solve only).

    Returns
    -------
    RefinedSolution
        The last solution, with ``info['refinement']`` (also ``.refinement``): one
        `RefinementRound` ``(n_intervals, max_error, cost, iterations, time)`` per NLP
        solved, and ``info['converged']``, ``info['errors']``, ``info['meshes']``,
        ``info['stop']``. ``success`` is that of the last NLP (its message says so); not
        reaching ``tol`` within the limits keeps ``success=True`` with
        ``info['converged'] = False`` and a note in the message.
    """
    if not isinstance(problem, Problem):
        raise TypeError(f"`problem` must be an ocp.Problem, got {type(problem).__name__}")
    if solution is not None and not isinstance(solution, Solution):
        raise TypeError(f"`solution` must be an ocp.Solution or None, got {type(solution).__name__}")
    _check_positive("tol", tol)
    max_rounds = _check_int("max_rounds", max_rounds, 0)
    max_intervals = _check_int("max_intervals", max_intervals, 1)
    tr = _transcription(transcription, degree)
    q = _local_order(tr)
    kw = dict(solve_kwargs)
    guess0 = kw.pop("guess", None)
    mesh0 = kw.pop("mesh", None)
    say = (lambda text: print(text, file=sys.stdout, flush=True)) if verbose is True else None

    t_round = time.perf_counter()
    if solution is not None and solution.problem is problem and solution.transcription == tr:
        sol = solution
    elif solution is not None:
        sol = solve(problem, transcription=tr, mesh=solution.mesh,
                    guess=solution if guess0 is None else guess0, verbose=verbose, **kw)
    else:
        sol = solve(problem, transcription=tr, N=None if mesh0 is not None else N, mesh=mesh0,
                    guess=guess0, verbose=verbose, **kw)
    history, meshes = [], []
    stop, est = "", None
    for rnd in range(max_rounds + 1):
        meshes.append(sol.mesh)
        if not sol.success:
            history.append(RefinementRound(sol.mesh.N, float("nan"), sol.cost, sol.iterations,
                                           time.perf_counter() - t_round))
            stop = f"the NLP of round {rnd} failed"
            break
        itol = float(np.clip(1e-4 * tol, 1e-13, 1e-10))  # CVODES fails below ~1e-14
        est = interval_errors(sol, rtol=itol, atol=itol)
        history.append(RefinementRound(sol.mesh.N, est.max_error, sol.cost, sol.iterations,
                                       time.perf_counter() - t_round))
        if say:
            say(f"refine round {rnd}: N = {sol.mesh.N}, max error {est.max_error:.3e}, "
                f"cost {sol.cost:.12g}, {sol.iterations} iterations")
        if est.max_error <= tol:
            stop = "tolerance reached"
            break
        if rnd == max_rounds:
            stop = f"max_rounds = {max_rounds} reached"
            break
        mesh = _new_mesh(sol.mesh, est, sol.T, sol.t0, tol, q, max_intervals)
        if mesh is None:
            stop = f"max_intervals = {max_intervals} reached"
            break
        t_round = time.perf_counter()
        sol = solve(problem, transcription=tr, mesh=mesh, guess=sol, verbose=verbose, **kw)
    converged = est is not None and sol.success and est.max_error <= tol
    if not sol.success:
        message = f"refine: {stop}: {sol.message}"
    elif converged:
        message = (f"refine: estimated error {est.max_error:.2e} <= tol {tol:g} on {sol.mesh.N} "
                   f"intervals after {len(history) - 1} rounds; {sol.message}")
    else:
        message = (f"refine: {stop}; estimated error {est.max_error:.2e} > tol {tol:g} on "
                   f"{sol.mesh.N} intervals; {sol.message}")
    info = {"refinement": history, "converged": bool(converged), "errors": est, "meshes": meshes,
            "tol": tol, "stop": stop}
    return _annotate(sol, info, message=message)


# ============================================================================ multistart
def solve_multistart(problem: Problem, guesses: Sequence, **solve_kwargs) -> RefinedSolution:
    """Solve ``problem`` from each guess and keep the best converged solution.

    Parameters
    ----------
    problem : Problem
    guesses : sequence
        Anything ``solve(guess=...)`` accepts: ``None``, a `Solution`, a mapping.
    **solve_kwargs
        Passed to `ocp.solve` (``verbose`` defaults to ``False`` here).

    Returns
    -------
    RefinedSolution
        The converged solution of least cost (``info['best']`` is its index), or, if no start
        converged, the one of least constraint violation with ``success=False``.
        ``info['starts']`` (also ``.starts``) lists every start: ``index, success, status,
        cost, T, constraint_violation, iterations, time``.

    Raises
    ------
    ValueError
        If ``guesses`` is empty or not a sequence, or a guess is malformed (as `ocp.solve`).
    """
    if isinstance(guesses, (str, bytes, Mapping, Solution)) or not isinstance(guesses, Sequence):
        raise ValueError(f"`guesses` must be a sequence of guesses (None, Solution or mapping), "
                         f"got {type(guesses).__name__}")
    if len(guesses) == 0:
        raise ValueError("`guesses` must hold at least one guess")
    if "guess" in solve_kwargs:
        raise ValueError("pass the guesses as `guesses`, not `guess`")
    kw = dict(solve_kwargs)
    kw.setdefault("verbose", False)
    sols, starts = [], []
    for i, g in enumerate(guesses):
        t = time.perf_counter()
        sol = solve(problem, guess=g, **kw)
        sols.append(sol)
        starts.append({"index": i, "success": sol.success, "status": sol.status, "cost": sol.cost,
                       "T": sol.T, "constraint_violation": sol.constraint_violation,
                       "iterations": sol.iterations, "time": time.perf_counter() - t})
    ok = [i for i, s in enumerate(sols) if s.success and np.isfinite(s.cost)]
    if ok:
        best = min(ok, key=lambda i: sols[i].cost)
        message = (f"best of {len(sols)} starts: start {best} ({len(ok)} converged); "
                   f"{sols[best].message}")
    else:
        viol = [s.constraint_violation if np.isfinite(s.constraint_violation) else np.inf for s in sols]
        best = int(np.argmin(viol))
        message = (f"none of {len(sols)} starts converged; returning start {best}, the least "
                   f"infeasible: {sols[best].message}")
    return _annotate(sols[best], {"starts": starts, "best": best}, message=message,
                     success=bool(ok) and sols[best].success)


# ========================================================================= free-mesh polish
_CLOCK, _STRETCH = "t_clock", "t_stretch"


def _fresh_name(name: str, taken) -> str:
    while name in taken:
        name += "_"
    return name


def _merged(constraints, wrap, extra=()) -> Constraint | None:
    """Constraints of ``problem`` restated through ``wrap`` (plus ``extra`` ones, each
    ``(fun, lower, upper)`` of one row), stacked into a single `Constraint`. Row scales
    are kept when every constraint has one. (One Constraint, not a list: it keeps the
    Function names valid.)"""
    funs = [wrap(c.fun) for c in constraints] + [e[0] for e in extra]
    if not funs:
        return None
    lower = np.concatenate([np.asarray(c.lower, float) for c in constraints] + [[e[1]] for e in extra])
    upper = np.concatenate([np.asarray(c.upper, float) for c in constraints] + [[e[2]] for e in extra])
    scale = None
    if not extra and all(c.scale is not None for c in constraints):
        scale = np.concatenate([np.asarray(c.scale, float) for c in constraints])
    name = "+".join(c.name for c in constraints) or "horizon"
    return Constraint(lambda *a: ca.vertcat(*[f(*a) for f in funs]), lower, upper, scale, name)


def _free_mesh_problem(problem: Problem, T_ref: float, stretch) -> Problem:
    """The problem in pseudo time ``sigma`` with the clock ``t`` as an extra state and the
    dilation ``v = dt/dsigma`` as an extra control, ``stretch[0] T_ref <= v <=
    stretch[1] T_ref`` (see the module docstring)."""
    model = problem.model
    nx, nu, np_ = model.nx, model.nu, model.np
    sym = ca.SX if _sx_ok(model.f) else ca.MX
    xa, ua, p = sym.sym("x", nx + 1), sym.sym("u", nu + 1), sym.sym("p", np_)
    v = ua[nu]
    rhs = ca.vertcat(v * model.f(xa[:nx], ua[:nu], p), v)
    fa = ca.Function(f"{model.f.name()}_free_mesh", [xa, ua, p], [rhs], ["x", "u", "p"], ["xdot"])
    aug = Model(fa, model.states + (_fresh_name(_CLOCK, model.states),),
                model.controls + (_fresh_name(_STRETCH, model.controls),), model.params,
                p_default=model.p_default, name=f"{model.name}_free_mesh", attitude=model.attitude)
    T_lo, T_hi = problem.T_bounds
    x_initial = np.concatenate([problem.x_initial, [0.0]])
    x_final = np.concatenate([problem.x_final, [np.nan if problem.free_time else problem.T]])
    x_bounds = (np.concatenate([problem.x_bounds[0], [0.0]]),
                np.concatenate([problem.x_bounds[1], [T_hi]]))
    u_bounds = (np.concatenate([problem.u_bounds[0], [stretch[0] * T_ref]]),
                np.concatenate([problem.u_bounds[1], [stretch[1] * T_ref]]))
    lagrange = mayer = None
    if problem.lagrange is not None:
        L = problem.lagrange
        lagrange = lambda x, u, p_: u[nu] * L(x[:nx], u[:nu], p_)  # noqa: E731
    if problem.mayer is not None:
        phi = problem.mayer
        mayer = lambda xf, p_, T: phi(xf[:nx], p_, xf[nx])  # noqa: E731
    path = _merged(problem.path, lambda c: (lambda x, u, p_: c(x[:nx], u[:nu], p_)))
    extra = [(lambda x0, xf, p_: xf[nx], T_lo, T_hi)] if problem.free_time else []
    boundary = _merged(problem.boundary, lambda c: (lambda x0, xf, p_: c(x0[:nx], xf[:nx], p_)), extra)
    fixed = problem.p_bounds[0] == problem.p_bounds[1]
    p_bounds = {name: (problem.p_bounds[0][i], problem.p_bounds[1][i])
                for i, name in enumerate(model.params) if not fixed[i]}
    return Problem(aug, T=1.0, x_initial=x_initial, x_final=x_final, x_bounds=x_bounds,
                   u_bounds=u_bounds, p=problem.p, p_bounds=p_bounds, lagrange=lagrange, mayer=mayer,
                   path=() if path is None else path, boundary=() if boundary is None else boundary,
                   q_final=problem.q_final, q_final_tol=problem.q_final_tol, t0=0.0,
                   name=f"{problem.name}_free_mesh")


def _aligned_mesh(solution: Solution, N: int | None) -> tuple[Mesh, np.ndarray]:
    """A mesh with knots at the detected switches (also returned [s]), the arcs between them
    cut evenly."""
    T, t0 = solution.T, solution.t0
    sw = (find_switches(solution) - t0) / T
    sw = sw[(sw > 1e-6) & (sw < 1 - 1e-6)]
    edges = np.concatenate([[0.0], sw, [1.0]])
    lengths = np.diff(edges)
    n_arcs = lengths.size
    if N is None:
        N = 4 * n_arcs if n_arcs > 1 else solution.mesh.N
    N = max(N, n_arcs)
    # largest-remainder allocation, at least one interval per arc
    share = lengths / lengths.sum() * N
    n = np.maximum(1, np.floor(share).astype(int))
    while n.sum() < N:
        n[np.argmax(share - n)] += 1
    while n.sum() > N and np.any(n > 1):
        cand = np.where(n > 1, share - n, np.inf)
        n[np.argmin(cand)] -= 1
    breaks = np.concatenate([np.linspace(edges[a], edges[a + 1], n[a] + 1)[:-1] for a in range(n_arcs)]
                            + [[1.0]])
    return Mesh(breaks), sw * T + t0


class _FreeMeshDiscretization:
    """Stand-in for `ocp.nlp.Discretization` that hands a free-mesh result to `_make_solution`."""

    def __init__(self, X, U, p, T, cost, multipliers, violation):
        self._phys = {"X": X, "U": U, "p": p, "T": T}
        self._cost, self._mult, self._viol = cost, multipliers, violation

    def unpack(self, w):
        return dict(self._phys)

    def cost(self, w):
        return self._cost

    def multipliers(self, lam_g):
        return self._mult

    def violation(self, g, w=None):
        return self._viol


def polish_switches(problem: Problem, solution: Solution, *, N: int | None = None, degree: int = 3,
                    verbose=False, stretch=(0.05, 5.0), **solve_kwargs) -> RefinedSolution:
    """Re-solve a bang-bang / time-optimal problem with moving knots.

    The control is constant within each mesh interval (`RadauConstantControl` of ``degree``)
    and the interval lengths are decision variables: ``h_k = v_k dsigma_k`` on a mesh
    ``dsigma`` of pseudo time, ``stretch[0] T0 <= v_k <= stretch[1] T0`` (``T0`` the horizon
    of ``solution``), so an interval may shrink to ``stretch[0]`` or grow to ``stretch[1]``
    times its initial length (``sum h_k = T`` holds by construction). Switch times then sit
    exactly on knots and the switching structure costs no accuracy: a fixed mesh leaves an
    ``O(h^2)`` error in ``T``; here what remains is the state's collocation error within the
    arcs (zero when the state is polynomial, e.g. the double integrator; ``O(h^(2d-1))``
    otherwise) and the NLP tolerance. The initial mesh puts knots at the switches detected in
    ``solution`` (`find_switches`) and cuts the arcs between them evenly; the guess is
    ``solution`` with its interval-mean control.

    Parameters
    ----------
    problem : Problem
    solution : Solution
        A solution of ``problem`` (any transcription and mesh) to start from.
    N : int, optional
        Number of intervals; default 4 per control arc (``solution.mesh.N`` without switches).
    degree : int
        Radau degree of the state.
    verbose : bool or callable
        Passed to `ocp.solve`.
    stretch : (float, float)
        Bounds of the interval lengths relative to their initial lengths.
    **solve_kwargs
        Passed to `ocp.solve` (``ipopt_options`` is merged over the defaults
        ``{'tol': 1e-10, 'bound_relax_factor': 0, 'max_iter': 3000}``; ``scale`` may name the
        extra state ``'t_clock'`` and control ``'t_stretch'``).

    Returns
    -------
    RefinedSolution
        A solution of ``problem`` with transcription `RadauConstantControl` on the optimized
        mesh. ``info``: ``'switch_times'`` (where the control jumps, on knots),
        ``'initial_switch_times'``, ``'initial_T'``, ``'N'``,
        ``'stretch_active'`` (indices of intervals at a ``stretch`` bound),
        ``'free_mesh_solution'`` (the solution of the restated problem), ``'wall_time'``.
        ``success=False`` (never an exception) if IPOPT failed.

    Notes
    -----
    Path constraints are imposed at the interval ends only. ``T`` of the result is not
    necessarily below that of ``solution``: both carry their own discretization errors.
    """
    if not isinstance(problem, Problem):
        raise TypeError(f"`problem` must be an ocp.Problem, got {type(problem).__name__}")
    if not isinstance(solution, Solution):
        raise TypeError(f"`solution` must be an ocp.Solution, got {type(solution).__name__}")
    if solution.problem.model.nx != problem.model.nx or solution.problem.model.nu != problem.model.nu:
        raise ValueError("`solution` must solve a problem with the states and controls of `problem`")
    if N is not None:
        N = _check_int("N", N, 1)
    try:
        lo_s, hi_s = (float(v) for v in stretch)
    except (TypeError, ValueError):
        raise ValueError(f"`stretch` must be a pair (lower, upper), got {stretch!r}") from None
    if not (0 < lo_s < 1 < hi_s < math.inf):
        raise ValueError(f"`stretch` must satisfy 0 < lower < 1 < upper < inf, got {stretch!r}")
    tr = RadauConstantControl(degree)
    kw = dict(solve_kwargs)
    for bad in ("transcription", "mesh", "guess", "N", "degree"):
        if bad in kw:
            raise ValueError(f"polish_switches chooses `{bad}` itself; got {bad}={kw[bad]!r}")
    user_ipopt = kw.pop("ipopt_options", None) or {}
    if not isinstance(user_ipopt, Mapping):
        raise ValueError(f"`ipopt_options` must be a mapping, got {type(user_ipopt).__name__}")
    ipopt = {**_STRICT, **{k[len("ipopt."):] if k.startswith("ipopt.") else k: v
                           for k, v in user_ipopt.items()}}

    t_start = time.perf_counter()
    mesh, sw0 = _aligned_mesh(solution, N)
    T0 = float(solution.T)
    nx, nu, np_ = problem.model.nx, problem.model.nu, problem.model.np
    b = mesh.breaks
    aug = _free_mesh_problem(problem, T0, (lo_s, hi_s))
    # guess in pseudo time sigma (= t / T0 initially): states and clock at the nodes, the
    # interval-mean control of `solution`, v = T0
    sig = np.unique(np.concatenate([tr.state_tau(mesh), b]))
    xg = np.vstack([solution.sample(solution.t0 + T0 * sig)[0], T0 * sig])
    m = 16
    tm = (b[:-1, None] + (np.arange(m)[None, :] + 0.5) / m * np.diff(b)[:, None]).reshape(-1)
    um = solution.sample(solution.t0 + T0 * tm)[1].reshape(nu, mesh.N, m).mean(axis=2)
    um = np.clip(um, problem.u_bounds[0][:, None], problem.u_bounds[1][:, None])
    um = np.vstack([um, np.full((1, mesh.N), T0)])

    def u_guess(t):
        return um[:, int(np.clip(np.searchsorted(b, t, side="left") - 1, 0, mesh.N - 1))]

    guess = {"t": sig, "x": xg, "u": u_guess, "p": np.asarray(solution.p, dtype=float)}
    sa = solve(aug, transcription=tr, mesh=mesh, guess=guess, verbose=verbose,
               ipopt_options=ipopt, **kw)

    # ---- back to the original problem on the mesh of physical interval lengths
    d = degree
    clock = sa.x[nx, ::d]  # at the sigma breaks (state columns 0, d, 2d, ...)
    T = float(clock[-1])
    frac = np.diff(clock)
    if not (np.isfinite(T) and T > 0 and np.all(np.isfinite(frac))):
        frac, T = mesh.fractions * T0, T0
    frac = np.maximum(frac, 1e-14 * T) / T
    breaks = np.concatenate([[0.0], np.cumsum(frac)])
    breaks = breaks / breaks[-1]
    breaks[-1] = 1.0
    phys_mesh = Mesh(breaks)
    mult = dict(sa.multipliers)
    mult["defect"] = mult["defect"][:nx]
    if problem.free_time:
        mult["boundary"] = mult["boundary"][:-1]
    disc = _FreeMeshDiscretization(sa.x[:nx], sa._dense.Uo[:nu, :, 0], np.asarray(sa.p)[:np_], T,
                                   sa.cost, mult, sa.constraint_violation)
    out = _make_solution(problem, tr, phys_mesh, disc, None, None, np.zeros(0), sa.success, sa.status,
                         sa.message, sa.iterations, sa.solve_time, sa.build_time)
    v = sa._dense.Uo[nu, :, 0]
    active = np.flatnonzero((v <= lo_s * T0 * (1 + 1e-6)) | (v >= hi_s * T0 * (1 - 1e-6)))
    info = {"switch_times": find_switches(out), "initial_switch_times": sw0, "initial_T": T0,
            "N": mesh.N, "stretch_active": active, "free_mesh_solution": sa,
            "wall_time": time.perf_counter() - t_start}
    prefix = "polish_switches (constant control and free length per interval): "
    return _annotate(out, info, message=prefix + sa.message)
