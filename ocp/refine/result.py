"""Result types of the drivers on top of `ocp.solve` (`refine`, `solve_multistart`,
`polish_switches`) and `annotate`, which turns any `Solution` into one."""
from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Mapping, NamedTuple

import numpy as np

from ..solution import Solution
from ..status import STATUS_WORSE

__all__ = ["RefinementRound", "RefinedSolution", "annotate", "graded", "worse_than",
           "WORSE_SLACK", "STATUS_WORSE"]

#: Relative slack by which a polished cost may be worse than the cost of the solution it
#: started from and still be a success: the start's own discretization error. A fixed mesh
#: can put a minimum time *below* the exact optimum: 2.4e-6 relative on the slews of the
#: tests (J = diag(1, 2, 3), 1 rad: 2.2075331 s against the exact 2.2075385 s), 1.8e-4 on
#: the bang-coast-bang double integrator on 10 intervals (its path constraint met at the
#: nodes only: 2.2662682 s against the exact 2.2666667 s); 1e-3 leaves a margin of 5 over
#: the larger. (The user's case that asked for this check: 39.997 s from 39.655 s, 8.6e-3.)
WORSE_SLACK = 1e-3


_TRAJECTORY = frozenset({"x", "u", "p", "T", "t0", "t", "mesh", "transcription", "problem", "dense"})


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


@dataclass(eq=False, repr=False)
class RefinedSolution(Solution):
    """A `Solution` plus ``info`` (returned by `refine`, `solve_multistart`, `polish_switches`).

    It is a `Solution` in every respect (``isinstance`` holds, it warm-starts `solve`).

    Attributes
    ----------
    info : mapping of str to object
        What the driver did. `refine`: ``'refinement'`` (list of `RefinementRound`, one per
        NLP solved, first the initial one), ``'converged'`` (max error <= tol), ``'errors'``
        (the final `IntervalErrors`), ``'meshes'`` (the mesh of each round),
        ``'tol'``, ``'stop'`` (why it stopped: ``'tolerance reached'``, ``'stalled'`` (the
        error estimate stopped falling, status 104 ``Refinement_Stalled``, see `refine`),
        ``'max_rounds = ... reached'``, ``'max_intervals = ... reached'``, ``'the NLP of
        round ... failed'``). `solve_multistart`: ``'starts'`` (list of
        dicts with ``index, success, status, cost, T, constraint_violation, iterations,
        time``) and ``'best'`` (index of the start returned). `polish_switches`:
        ``'switch_times'`` (knots where the control jumps), ``'initial_switch_times'``,
        ``'initial_T'``, ``'N'``, ``'stretch_active'`` (intervals whose length sits at a
        bound of ``stretch``; empty for switch times), ``'free_mesh_solution'`` (the
        solution of the restated problem; ``None`` for switch times), ``'wall_time'``,
        ``'method'`` (``'switch-times'`` or ``'moving-knots'``), ``'fallback'`` (why the
        moving knots ran), ``'switch_time_solution'``, ``'short_arcs'``,
        ``'attempt_iterations'`` and those of `optimize_switch_times` (``'durations'``,
        ``'arc_controls'``, ``'integration_error'``, ``'nlp_iterations'``,
        ``'nlp_status'``).
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
    fields in ``changes`` (e.g. ``success``, ``status``, ``message``) replaced; the cached
    re-simulation (`Solution.propagation`) is shared when the trajectory is unchanged. For drivers that verify or post-process a result
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
    kw = {f.name: getattr(solution, f.name) for f in fields(Solution)}
    kw.update(changes)
    merged = dict(getattr(solution, "info", {}) or {})
    merged.update(info or {})
    out = RefinedSolution(**kw, info=merged)
    # the cached re-simulation (`Solution.propagation`) is shared unless the trajectory changed
    if "propagation" in vars(solution) and not (_TRAJECTORY & set(changes)):
        vars(out)["propagation"] = solution.propagation
    return out


def worse_than(problem, cost: float, start: float, *, slack: float = WORSE_SLACK) -> bool:
    """Whether ``cost`` is worse than ``start`` by more than ``slack |start|`` (the
    direction of `Problem.better`; a NaN ``cost`` is worse, a NaN ``start`` is not beaten).

    Examples
    --------
    >>> from appdyn.ocp.examples import min_time
    >>> from appdyn.ocp.refine.result import worse_than
    >>> worse_than(min_time(), 2.01, 2.0), worse_than(min_time(), 2.001, 2.0)
    (True, False)
    """
    if not np.isfinite(start):
        return False
    return problem.better(start, cost - problem.objective_sign * slack * abs(start))


def graded(problem, start: Solution, out: Solution) -> RefinedSolution:
    """``out`` with ``info['initial_cost']`` and ``info['gain']`` (how much better than
    ``start``, in the objective's units: positive is better), failed (`STATUS_WORSE`, a
    message with both costs) if a success worse than ``start`` beyond `WORSE_SLACK`: a
    refinement of ``start`` (`polish_switches`, `optimize_switch_times`) is never returned
    worse than its start as a success.

    Parameters
    ----------
    problem : Problem
    start : Solution
        What was refined.
    out : Solution
        The refined result.

    Returns
    -------
    RefinedSolution
    """
    gain = problem.objective_sign * (float(start.cost) - float(out.cost))
    info = {"initial_cost": float(start.cost), "gain": gain}
    if out.success and worse_than(problem, out.cost, start.cost):
        return annotate(out, info, success=False, status=STATUS_WORSE, message=(
            f"{out.message}; NOT used: the polished cost {out.cost:.10g} is worse than the "
            f"start's {start.cost:.10g} by {-gain:.3g} (more than {WORSE_SLACK:g} relative, "
            f"the start's discretization error): keep the start, or refine it (ocp.refine)"))
    return annotate(out, info)
