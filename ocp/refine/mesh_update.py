"""`refine`: ``hp``-style mesh refinement driven by `interval_errors`, and the mesh update
it applies each round (split inaccurate intervals, bracket switches, merge very accurate
neighbours)."""
from __future__ import annotations

import dataclasses
import math
import sys
import time
import warnings

import numpy as np

from appdyn.dynamics.validate import integer, positive
from appdyn.dynamics.interrupts import interruptible
from appdyn.dynamics.progress import accepts_round_bar
from ..checks import (STATUS_BOUND_VIOLATION, STATUS_RESIMULATION, interval_bound_violation,
                      periodic_jumps)
from ..mesh import Mesh, sorted_union
from ..problem import Problem
from ..progress import LOGGER, stage_sink
from ..solution import Solution
from ..status import STATUS_STALLED, status_name
from ..solve import back_off, solve
from ..transcription import Radau, Transcription, get_transcription
from ..backoff import backoff_note
from .errors import IntervalErrors, interval_errors
from .result import RefinedSolution, RefinementRound, annotate

__all__ = ["refine", "STATUS_STALLED", "local_order", "new_mesh"]

_BRACKET = 1.0 / 16.0  # width of the new switch interval relative to the old one



def local_order(tr: Transcription) -> int:
    """The local order of accuracy of a transcription's interval error (the power of the
    interval length in its estimate): ``degree + 1`` for Radau, 3 for the trapezoid, 4
    otherwise (Hermite-Simpson).

    Examples
    --------
    >>> from appdyn.ocp.refine.mesh_update import local_order
    >>> from appdyn.ocp.transcription import get_transcription
    >>> local_order(get_transcription("radau", degree=3))
    4
    """
    if isinstance(tr, Radau):
        return tr.degree + 1
    return {"trapezoid": 3}.get(tr.name, 4)


def new_mesh(mesh: Mesh, est: IntervalErrors, T: float, t0: float, tol: float, q: int,
             max_intervals: int) -> Mesh | None:
    """The next mesh of a refinement round: split inaccurate intervals, bracket switches,
    merge very accurate neighbours.

    Parameters
    ----------
    mesh : Mesh
    est : IntervalErrors
        Of a solution on ``mesh`` (`ocp.refine.interval_errors`).
    T, t0 : float [s]
        Horizon and start time of that solution.
    tol : float
        Target interval error.
    q : int
        Local order of the transcription (`local_order`).
    max_intervals : int

    Returns
    -------
    Mesh or None
        None when nothing changes.
    """
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
    new = sorted_union(*pieces, [1.0])
    new[0], new[-1] = 0.0, 1.0
    new = new[np.concatenate([[True], np.diff(new) > 1e-14])]
    new[-1] = 1.0
    if new.size == b.size and np.array_equal(new, b):
        return None
    if not any(c.size for c in cuts):
        return None  # nothing to split (budget exhausted): merging alone does not help
    return Mesh(new)


def _stalled(history: list, q: int, max_intervals: int, window: int) -> bool:
    """Whether the error estimate stalled: over the last ``window`` rounds (each on a mesh
    that grew and stayed below ``max_intervals``) the largest estimated error fell by less
    than ``2**q``, the gain a single round makes on a smooth solution (see `refine`)."""
    if len(history) < window + 1:
        return False
    last = history[-(window + 1):]
    errors = [r.max_error for r in last]
    sizes = [r.n_intervals for r in last]
    if not all(np.isfinite(errors)):
        return False
    grew = all(b > a for a, b in zip(sizes, sizes[1:])) and sizes[-1] < max_intervals
    return bool(grew and errors[-1] > errors[0] / 2.0 ** q)


def _refinable(sol: Solution) -> bool:
    """Whether a failed round is one refinement is the remedy for: the NLP converged but the
    dense output leaves a bound between the nodes or its re-simulation disagrees
    (`ocp.checks`), and no unbounded angle control jumps by ``2 pi k`` (finer meshes would
    only pile intervals on those jumps)."""
    return (sol.status in (STATUS_BOUND_VIOLATION, STATUS_RESIMULATION)
            and not periodic_jumps(sol))


def _sim(sol: Solution) -> float:
    """The objective ``sol`` achieves re-simulated (`Solution.simulated_cost`; the collocated
    one where the re-simulation failed)."""
    v = sol.simulated_cost
    return v if np.isfinite(v) else sol.cost


def _better_round(problem: Problem, best, current, tol: float):
    """The round to return if later rounds get worse: ``current`` ``(round, solution,
    errors)`` unless ``best`` (an earlier successful round) achieves a re-simulated objective
    better by more than ``max(tol, its own largest scaled re-simulation error)`` relative to
    ``max(|J|, 1)`` (a coarse round's re-simulated trajectory may miss the constraints by that
    much, and gain objective from it); only successful (verified) rounds count."""
    if not current[1].success:
        return best
    if best is None:
        return current
    a, b = _sim(best[1]), _sim(current[1])
    rel = best[1].propagation.relative_error
    slack = max(tol, float(np.max(rel)) if rel.size and np.all(np.isfinite(rel)) else 0.0)
    if problem.better(a, b) and abs(a - b) > slack * max(abs(a), 1.0):
        return best
    return current


def _overshoot_message(history: list, window: int, tol: float, sol: Solution) -> str:
    """The message of a refinement that met ``tol`` while the dense output of its last round
    still leaves a bound (where a bound is active, the interpolant between the nodes
    overshoots by an amount that refining barely changes: a wheel-speed bound of
    `slew.wheel_slew`, 1e-5 of its scale on 123, 234 and 400 intervals)."""
    bv = sol.bound_violation
    sizes = ", ".join(str(r.n_intervals) for r in history[-(window + 1):])
    return (f"refine: the error estimate meets tol ({history[-1].max_error:.2e} <= {tol:g}), "
            f"but on {sizes} intervals the dense output still leaves a bound: `{bv.name}` by "
            f"{bv.max:.3g} of its scale at t = {bv.time:.6g} s. Where a bound is active the "
            f"interpolant overshoots it between the nodes by about the same amount on finer "
            f"meshes. Remedy: accept an overshoot of this size (bound_tol of ocp.solve and "
            f"ocp.refine, e.g. {2 * bv.max:.1g}), with the bound tightened by as much where the "
            f"original must hold. {sol.message}")


def _estimate(sol: Solution, tol: float) -> IntervalErrors:
    """`interval_errors` of ``sol`` for a refinement to ``tol``: re-integrated at
    ``1e-4 tol``, within [1e-13, 1e-10] (CVODES fails below ~1e-14)."""
    itol = float(np.clip(1e-4 * tol, 1e-13, 1e-10))
    return interval_errors(sol, rtol=itol, atol=itol)


def _backed_off(sol: Solution, backed: Solution, info: dict, tol: float, verbose, progress,
                t_round: float, history: list) -> RefinedSolution:
    """The result of a refinement whose last round overshot an active bound and was re-solved
    on the same mesh with the bound moved inwards (`back_off`)."""
    est = _estimate(backed, tol)
    history.append(RefinementRound(backed.mesh.N, est.max_error, backed.cost, backed.iterations,
                                   time.perf_counter() - t_round))
    _report(len(history) - 1, history[-1], verbose, progress)
    converged = bool(est.max_error <= tol)
    message = (f"refine: {backoff_note(sol, backed)} (refining barely changes such an "
               f"overshoot); estimated error {est.max_error:.2e} {'<=' if converged else '>'} "
               f"tol {tol:g}; {backed.message}")
    info = dict(info, refinement=history, errors=est, converged=converged,
                backoff=backed.backoff)
    return annotate(backed, info, message=message)


def _stall_message(history: list, q: int, window: int, sol: Solution) -> str:
    errors = ", ".join(f"{r.max_error:.2e}" for r in history[-(window + 1):])
    sizes = ", ".join(str(r.n_intervals) for r in history[-(window + 1):])
    sim = sol.simulated_cost
    return (f"refine: the error estimate stalled after {len(history) - 1} rounds ({errors} on "
            f"{sizes} intervals: less than the factor 2^{q} = {2 ** q} in {window} rounds that "
            f"one round gains on a smooth solution). This is typical of a singular arc or a "
            f"non-smooth / chattering control, where collocation converges slowly and the "
            f"collocated cost can beat the true optimum: trust the re-simulated cost "
            f"{sim:.10g} (Solution.simulated_cost, what the returned control achieves) rather "
            f"than the collocated cost {sol.cost:.10g}. Remedy: regularize the control (add "
            f"eps * integral u^2 to the objective with the sign that penalizes it, or penalize "
            f"control differences) and refine again, or impose the arc structure; see "
            f"ocp.refine and ocp.examples.goddard_rocket (a tol below the NLP tolerance also "
            f"stalls; stall_rounds=None refines on). {sol.message}")


def _transcription(transcription, degree) -> Transcription:
    if isinstance(transcription, Transcription):
        return transcription
    if transcription == "radau":
        return get_transcription("radau", degree=degree)
    return get_transcription(transcription)


def _report(rnd: int, r: RefinementRound, verbose, progress) -> None:
    line = (f"refine round {rnd}: N = {r.n_intervals}, max error {r.max_error:.3e}, "
            f"cost {r.cost:.12g}, {r.iterations} iterations")
    LOGGER.info(line)
    if verbose is True:
        print(f"[refine] {line}", file=sys.stderr, flush=True)
    if progress is not None:
        progress(r)


@accepts_round_bar("refine", lambda kwargs: kwargs.get("max_rounds", 6) + 1)
@interruptible
def refine(problem: Problem, solution: Solution | None = None, *, tol: float = 1e-6,
           max_rounds: int = 6, max_intervals: int = 400, transcription="radau",
           N: int | None = None, degree: int | None = None, verbose=False, progress=None,
           stall_rounds: int | None = 2, backoff: bool = True, **solve_kwargs) -> RefinedSolution:
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
    It stops when the largest estimated error is ``<= tol``, when the estimate stalls (below),
    after ``max_rounds`` rounds, when the mesh would exceed ``max_intervals`` intervals, or
    when a solve fails. A round that converged but fails `ocp.solve`'s checks of the dense
    output (``'Bound_Violation'``, ``'Resimulation_Mismatch'``) is refined further (a finer
    mesh is their remedy) and the last round's status stands -- except when an unbounded
    angle control jumps by ``2 pi k`` between nodes (`ocp.checks.periodic_jumps`): no mesh
    resolves those, and refinement stops at once with that round's message naming the
    control. Note that a switch inside an interval makes the ``'radau'`` control polynomial
    overshoot however small the interval: refine bang-bang problems with
    ``control='linear'`` or ``'constant'``.

    *Stall.* Every interval above ``tol`` is cut into at least two pieces each round, which
    gains a factor ``2**q`` in its error where the solution is smooth (a switch bracket gains
    16). When over ``stall_rounds`` consecutive rounds (default 2), the mesh growing, the
    largest estimated error falls by less than ``2**q`` in all (an observed order below
    ``q / stall_rounds``), refinement stops with ``success=False``, status `STATUS_STALLED`
    (104 ``Refinement_Stalled``), ``info['stop'] == 'stalled'`` and a message saying so. This
    is typical of *singular arcs* and of non-smooth or chattering controls (also of a ``tol``
    below what the NLP tolerance resolves): the collocated control rings around the singular
    value, the estimate creeps down (or plateaus and drops late) and more rounds mostly cost
    time. On such a solution the collocated `Solution.cost` can even beat the true optimum;
    trust the re-simulated `Solution.simulated_cost`, the objective the returned control
    achieves (the message quotes both).

    *Remedy for singular arcs.* Regularize the control: add a small ``eps * integral u^2``
    to the objective with the sign that penalizes it (``- eps * u**2`` in ``lagrange`` when
    maximizing), or penalize control differences; the Hamiltonian becomes strictly convex in
    ``u``, the control continuous, and refinement converges. The optimum moves by a small,
    measurable amount. Goddard rocket (`ocp.examples.goddard_rocket`, singular optimum
    ``h(tf) = 1.0128369``): unregularized, ``refine(tol=1e-6)`` stalls after 2 rounds (errors
    4.2e-2, 9.1e-3, 7.7e-3 on 20, 39, 70 intervals; collocated cost 1.0128424, re-simulated
    1.0128361); with ``eps = 1e-4`` it converges in 3 rounds (62 intervals) to a re-simulated
    altitude 1.0128361, 7.7e-7 below the singular optimum -- a ``'Bound_Violation'``
    though: the Radau thrust polynomial overshoots ``[0, 3.5]`` at the arc junctions;
    with ``control='linear'`` it converges within the bounds on 33 intervals; ``eps = 1e-3`` costs 1.4e-5 of
    altitude. Smaller ``eps`` sharpens the junctions and needs more rounds (``1e-5``: 8
    rounds, with ``stall_rounds=None, max_rounds=8``). The exact alternative imposes the arc
    structure (phases with the singular control law).

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
    transcription, degree : see `ocp.solve` (``degree``, default 3, applies to ``'radau'``
        given by name only; given otherwise it is ignored with a warning).
    N : int, optional
        Number of uniform intervals of the initial mesh (default 20); ignored with a warning
        when ``solution`` or ``mesh`` gives the mesh.
    verbose : bool or callable
        Passed to `ocp.solve`; ``True`` also prints one line per round to ``sys.stderr``.
    progress : bool or callable, optional
        ``True``: a bar of the rounds on stderr (`dynamics.progress`). A callable receives
        each `RefinementRound` as it completes (IPOPT iterations are not passed
        on; give ``verbose`` a callable for those). Each round is also logged (INFO) to the
        logger ``"appdyn.ocp"``.
    stall_rounds : int or None
        Window of the stall test (above): stop when the largest error fell by less than
        ``2**q`` over this many consecutive rounds (default 2); ``None`` never stops for a
        stall (a pre-asymptotic plateau can end late: unregularized Goddard, given
        ``max_rounds=9``, reaches 1e-6 after 9 rounds on 304 intervals, its estimate
        erratic on the way: 1.5e-3, 1.2e-4, 9.0e-4, 8.3e-7 in the last four).
    backoff : bool
        When the last round meets ``tol`` but its dense output leaves a bound by at most
        `ocp.backoff.BACKOFF_MAX` of the variable's scale (the interpolant bulging past
        an *active* bound between the nodes, which refining barely changes): re-solve on the
        same mesh with that bound moved inwards by twice the overshoot (up to 3 times), graded
        against the original bounds (`ocp.solve.back_off`; default True). The
        objective pays for the margin to first order in its size; ``info['backoff']`` gives
        the margins and the objective without them. ``False`` returns the overshooting
        round as a failure that names the overshoot (status `STATUS_STALLED` after a stall).
    **solve_kwargs
        Passed to `ocp.solve` (``ipopt_options``, ``scale``, ``expand``; ``guess`` and
        ``mesh`` for the initial solve only).

    Returns
    -------
    RefinedSolution
        The last solution -- unless its re-simulated objective (`Solution.simulated_cost`)
        is worse than that of an earlier verified round by more than ``max(tol, that
        round's scaled re-simulation error)`` relative: then that round, with
        ``info['returned_round']`` and a message quoting both objectives (refinement never
        returns a worse objective than its input as a success) -- with ``info['refinement']`` (also ``.refinement``): one
        `RefinementRound` ``(n_intervals, max_error, cost, iterations, time)`` per NLP
        solved, and ``info['converged']``, ``info['errors']``, ``info['meshes']``,
        ``info['stop']``. ``success`` is that of the last NLP (its message says so); not
        reaching ``tol`` within the limits keeps ``success=True`` with
        ``info['converged'] = False`` and a note in the message; a stalled estimate gives
        ``success=False``, status `STATUS_STALLED` and ``info['stop'] = 'stalled'``.

    Raises
    ------
    TypeError
        If ``problem`` is not a `Problem`, ``solution`` not a `Solution`, ``progress``
        not callable, or ``backoff`` not a bool.
    ValueError
        Naming the argument: ``tol`` not positive, ``max_rounds`` < 0, ``max_intervals`` or
        ``stall_rounds`` < 1.

    Examples
    --------
    >>> from appdyn import ocp
    >>> from appdyn.ocp.examples import min_energy
    >>> energy = min_energy()  # x'' = u from rest at 0 to rest at 1 in T = 1 s
    >>> first = ocp.solve(energy, N=10, transcription="trapezoid")
    >>> sol = ocp.refine(energy, first, tol=1e-8)
    >>> sol.success, sol.info["converged"], round(sol.cost, 6)
    (True, True, 6.0)

    A singular arc stalls; a small regularization converges:

    >>> from appdyn.ocp.examples import goddard_rocket
    >>> rocket = ocp.refine(goddard_rocket(), tol=1e-6)
    >>> rocket.status, rocket.info["stop"], len(rocket.refinement) - 1
    (104, 'stalled', 2)
    >>> smooth = ocp.refine(goddard_rocket(regularization=1e-4), tol=1e-6, control="linear")
    >>> smooth.success, smooth.info["converged"], round(float(smooth.propagation.x[0, -1]), 6)
    (True, True, 1.012836)
    """
    if not isinstance(problem, Problem):
        raise TypeError(f"`problem` must be an ocp.Problem, got {type(problem).__name__}")
    if solution is not None and not isinstance(solution, Solution):
        raise TypeError(f"`solution` must be an ocp.Solution or None, got {type(solution).__name__}")
    positive(tol, "tol")
    max_rounds = integer(max_rounds, "max_rounds", minimum=0)
    max_intervals = integer(max_intervals, "max_intervals", minimum=1)
    if stall_rounds is not None:
        stall_rounds = integer(stall_rounds, "stall_rounds", minimum=1)
    if not isinstance(backoff, (bool, np.bool_)):
        raise TypeError(f"`backoff` must be True or False, got {type(backoff).__name__}")
    if progress is not None and not callable(progress):
        raise TypeError(f"`progress` must be a callable or None, got {type(progress).__name__}")
    kw = dict(solve_kwargs, backoff=False)  # the rounds: backed off once at the end
    guess0 = kw.pop("guess", None)
    mesh0 = kw.pop("mesh", None)
    control = kw.pop("control", None)
    if degree is not None and transcription != "radau":
        warnings.warn(f"`degree` is ignored: it applies to transcription 'radau' given by "
                      f"name, not {transcription!r}", UserWarning, stacklevel=2)
    if N is not None and (solution is not None or mesh0 is not None):
        warnings.warn("`N` is ignored: the mesh comes from "
                      f"{'`solution`' if solution is not None else '`mesh`'}", UserWarning,
                      stacklevel=2)
    N = 20 if N is None else N
    tr = get_transcription(_transcription(transcription, 3 if degree is None else degree),
                           degree=None, control=control)
    q = local_order(tr)

    t_round = time.perf_counter()
    if solution is not None and solution.problem is problem and solution.transcription == tr:
        sol = solution
    elif solution is not None:
        sol = solve(problem, transcription=tr, mesh=solution.mesh,
                    guess=solution if guess0 is None else guess0,
                    verbose=stage_sink(verbose, "refine round 0"), **kw)
    else:
        sol = solve(problem, transcription=tr, N=None if mesh0 is not None else N, mesh=mesh0,
                    guess=guess0, verbose=stage_sink(verbose, "refine round 0"), **kw)
    history, meshes = [], []
    stop, est, best = "", None, None
    for rnd in range(max_rounds + 1):
        meshes.append(sol.mesh)
        if not (sol.success or _refinable(sol)):
            history.append(RefinementRound(sol.mesh.N, float("nan"), sol.cost, sol.iterations,
                                           time.perf_counter() - t_round))
            stop = f"the solve of round {rnd} failed ({status_name(sol.status)})"
            break
        est = _estimate(sol, tol)
        history.append(RefinementRound(sol.mesh.N, est.max_error, sol.cost, sol.iterations,
                                       time.perf_counter() - t_round))
        _report(rnd, history[-1], verbose, progress)
        best = _better_round(problem, best, (rnd, sol, est), tol)
        outside = sol.status == STATUS_BOUND_VIOLATION
        if est.max_error <= tol and not outside:
            stop = "tolerance reached"
            break
        if stall_rounds is not None and _stalled(history, q, max_intervals, stall_rounds):
            stop = "stalled"
            break
        if outside:  # the intervals whose dense output leaves a bound are split too
            est = dataclasses.replace(est, error=np.where(
                interval_bound_violation(sol) > 0, np.maximum(est.error, 4.0 * tol), est.error))
        if rnd == max_rounds:
            stop = f"max_rounds = {max_rounds} reached"
            break
        mesh = new_mesh(sol.mesh, est, sol.T, sol.t0, tol, q, max_intervals)
        if mesh is None:
            stop = f"max_intervals = {max_intervals} reached"
            break
        t_round = time.perf_counter()
        sol = solve(problem, transcription=tr, mesh=mesh, guess=sol,
                    verbose=stage_sink(verbose, f"refine round {rnd + 1}"), **kw)
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
    if best is not None and best[1] is not sol and sol.success:
        # never a worse objective than an earlier verified round: that round is returned
        rnd, earlier, est_b = best
        note = (f"refine: the last round's re-simulated objective {_sim(sol):.10g} is worse "
                f"than round {rnd}'s {_sim(earlier):.10g} (by more than tol {tol:g} relative"
                f"{'' if sol.success else '; the last round failed: ' + sol.message[:300]}); "
                f"returned round {rnd} ({earlier.mesh.N} intervals, estimated error "
                f"{est_b.max_error:.2e}); {earlier.message}")
        info.update(converged=bool(est_b.max_error <= tol), errors=est_b, returned_round=rnd)
        return annotate(earlier, info, message=note)
    if backoff and est is not None and est.max_error <= tol and sol.status == STATUS_BOUND_VIOLATION:
        backed = back_off(problem, sol, kw, transcription=tr,
                          verbose=stage_sink(verbose, "refine back-off"))
        if backed is not None:
            return _backed_off(sol, backed, info, tol, verbose, progress, t_round, history)
    if stop == "stalled" and (sol.success or _refinable(sol)):
        if est.max_error <= tol and sol.status == STATUS_BOUND_VIOLATION:
            message = _overshoot_message(history, stall_rounds, tol, sol)
        else:
            message = _stall_message(history, q, stall_rounds, sol)
            if not sol.success:  # the last round also failed a check of its dense output
                message += (f" The last round also failed ({status_name(sol.status)}): "
                            f"{sol.message}")
        return annotate(sol, info, success=False, status=STATUS_STALLED, message=message)
    return annotate(sol, info, message=message)
