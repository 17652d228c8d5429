"""`back_off`: keep the dense output of a refined solution inside an active bound that its
interpolant overshoots between the nodes.

The NLP imposes the bounds at the nodes only. On a boundary arc the nodes sit on the bound
and the interpolant through them bulges past it near the junctions, by an amount that mesh
refinement barely changes (the junction moves with the mesh): a wheel-speed bound of
`problems.slew.wheel_slew`, 1e-5 of its scale on 30 to 400 intervals, while the error
estimate met its tolerance. Re-solving on the same mesh with that bound moved inwards by
twice the measured overshoot leaves the shape of the bulge (and so its size) nearly unchanged
but puts it inside the original bound; the result is graded against the user's bounds. The
objective pays for the margin to first order in its size (reported).
"""
from __future__ import annotations

import dataclasses

import numpy as np

from ..checks import STATUS_BOUND_VIOLATION, bound_excess
from ..solve import check_constraint_tol, solve, verified

__all__ = ["back_off", "BACKOFF_MAX", "BACKOFF_TRIES"]

BACKOFF_MAX = 1e-3   # the largest margin tried, in units of the variable's scale
BACKOFF_TRIES = 3    # re-solves, each widening the margin by twice the remaining overshoot
_MARGIN = 2.0        # margin per measured overshoot


def _shifts(sol, btol: float) -> np.ndarray | None:
    """``(2, n)`` overshoots of the states and controls below / above their bounds [variable
    units], those within ``btol`` (scaled) zeroed; ``None`` when nothing exceeds ``btol``."""
    out = bound_excess(sol)
    if out is None:
        return None
    bounds, scale, values = out
    over = np.stack([np.max(np.maximum(bounds[0][:, None] - values, 0.0), axis=1),
                     np.max(np.maximum(values - bounds[1][:, None], 0.0), axis=1)])
    over[:, np.max(over, axis=0) <= btol * scale] = 0.0
    return over if np.any(over > 0) else None


def back_off(problem, sol, solve_kwargs: dict, *, transcription, verbose=False):
    """``(solution, margins, tries)`` of ``problem`` on ``sol``'s mesh with the dense output
    within the bounds, or ``None`` when backing off does not apply or does not succeed.

    Parameters
    ----------
    problem : ocp.Problem
        The user's problem: the result is graded against its bounds.
    sol : ocp.Solution
        A solution of ``problem`` whose only fault is `STATUS_BOUND_VIOLATION` by at most
        `BACKOFF_MAX` of each variable's scale.
    solve_kwargs : dict
        The options of `ocp.solve` used for ``sol`` (``bound_tol``/``constraint_tol`` give
        the grading tolerance).
    transcription : ocp.Transcription

    Returns
    -------
    tuple or None
        The verified `Solution` (its ``problem`` is ``problem``), a dict ``{name: (lower
        margin, upper margin)}`` of the bounds moved [variable units], and the number of
        re-solves.
    """
    if sol.status != STATUS_BOUND_VIOLATION or not np.isfinite(sol.cost):
        return None
    kw = dict(solve_kwargs)
    btol = check_constraint_tol(kw.get("constraint_tol"))
    btol = btol if kw.pop("bound_tol", None) is None else float(solve_kwargs["bound_tol"])
    names = tuple(problem.model.states) + tuple(problem.model.controls)
    bounds = np.concatenate([problem.x_bounds, problem.u_bounds], axis=1)
    n = len(problem.model.states)
    margin = np.zeros_like(bounds)
    current = sol
    for tries in range(1, BACKOFF_TRIES + 1):
        over = _shifts(current, btol)
        if over is None:
            return None
        margin = margin + _MARGIN * over
        scale = bound_excess(current)[1]
        if np.any(margin > BACKOFF_MAX * scale) or np.any(bounds[0] + margin[0] > bounds[1] - margin[1]):
            return None
        tight = np.stack([bounds[0] + margin[0], bounds[1] - margin[1]])
        try:
            shifted = problem.replace(x_bounds=tight[:, :n], u_bounds=tight[:, n:])
        except ValueError:  # a fixed boundary value on the bound: no room to back off
            return None
        # the tightened problem's own bound check is the original's, done below
        trial = solve(shifted, transcription=transcription, mesh=sol.mesh, guess=current,
                      verbose=verbose, bound_tol=np.inf, **kw)
        if not trial.success:
            return None
        regraded = dataclasses.replace(trial, problem=problem)
        if "propagation" in vars(trial):  # verified by the solve: same model, same trajectory
            vars(regraded)["propagation"] = trial.propagation
        graded = verified(regraded, btol, None)
        if graded.success:
            moved = {names[i]: (float(margin[0, i]), float(margin[1, i]))
                     for i in np.flatnonzero(np.any(margin > 0, axis=0))}
            return graded, moved, tries
        current = graded
    return None
