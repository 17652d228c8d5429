"""The pieces of the back-off of `ocp.solve` (`ocp.solve.back_off`): keep the dense output
of a solution inside an active bound that its interpolant overshoots between the nodes.

The NLP imposes the bounds at the nodes only. On a boundary arc the nodes sit on the bound
and the interpolant through them bulges past it near the junctions, by an amount that mesh
refinement barely changes (the junction moves with the mesh): a wheel-speed bound of
`problems.slew.wheel_slew`, 1e-5 of its scale on 30 to 400 intervals, while the error
estimate met its tolerance. Re-solving on the same mesh with that bound moved inwards by
twice the measured overshoot leaves the shape of the bulge (and so its size) nearly unchanged
but puts it inside the original bound; the result is graded against the user's bounds. The
objective pays for the margin to first order in its size (reported). Inequality path
constraints are backed off the same way (a keep-out cone that the state interpolant crosses
between the collocation points).
"""
from __future__ import annotations

import dataclasses

import numpy as np

from .checks import bound_excess, row_names

__all__ = ["backoff_note", "overshoots", "tightened", "BACKOFF_MAX", "BACKOFF_TRIES", "MARGIN"]

BACKOFF_MAX = 1e-3   # the largest overshoot backed off, in units of the variable's scale
BACKOFF_TRIES = 3    # re-solves, each widening the margin by twice the remaining overshoot
MARGIN = 2.0         # margin per measured overshoot


def overshoots(sol, btol: float):
    """``(over (2, n), scale (n,), names)``: how far the dense states, controls and path
    constraint rows of ``sol`` go below / above their bounds [their units], those within
    ``btol`` (scaled) zeroed; ``None`` when nothing exceeds ``btol``."""
    out = bound_excess(sol)
    if out is None:
        return None
    bounds, scale, values, names = out
    over = np.stack([np.max(np.maximum(bounds[0][:, None] - values, 0.0), axis=1),
                     np.max(np.maximum(values - bounds[1][:, None], 0.0), axis=1)])
    over[:, np.max(over, axis=0) <= btol * scale] = 0.0
    return (over, scale, names) if np.any(over > 0) else None


def tightened(problem, tight: np.ndarray, names: list):
    """``problem`` with the bounds ``tight`` (2, n) of the rows ``names`` of `bound_excess`:
    its states, controls and inequality path rows."""
    nx, nu = problem.model.nx, problem.model.nu
    at = {name: i for i, name in enumerate(names)}
    path = []
    for con in problem.path:
        rows = [at.get(name) for name in row_names(con)]
        lo = np.array([con.lower[j] if i is None else tight[0, i] for j, i in enumerate(rows)])
        hi = np.array([con.upper[j] if i is None else tight[1, i] for j, i in enumerate(rows)])
        path.append(dataclasses.replace(con, lower=lo, upper=hi))
    return problem.replace(x_bounds=tight[:, :nx], u_bounds=tight[:, nx:nx + nu],
                           path=tuple(path) if path else problem.path)


def backoff_note(sol, backed) -> str:
    """The sentence on a back-off: ``sol`` overshot, ``backed`` (`back_off`) is within."""
    bv, rec = sol.bound_violation, backed.backoff
    margins = "; ".join(
        f"`{name}` " + " and ".join(f"{side} by {m:.3g}" for side, m in zip(("lower", "upper"), lm) if m > 0)
        for name, lm in rec["margins"].items())
    tries = rec["tries"]
    return (f"the dense output overshot an active bound between the nodes (`{bv.name}` by "
            f"{bv.max:.3g} of its scale at t = {bv.time:.6g} s on {sol.mesh.N} intervals); "
            f"re-solved on the same mesh with the bound moved inwards ({margins}; {tries} "
            f"re-solve{'s' if tries > 1 else ''}): the dense output is within the original "
            f"bounds, the objective {backed.cost:.10g} against {sol.cost:.10g} without the margin")
