"""`rest_solution`: the trajectory that holds the initial state, checked against the problem's
own NLP constraints (the exact answer of a slew by a zero angle)."""
from __future__ import annotations

import time

import numpy as np

from .guess import NodeGuess
from .mesh import Mesh
from .nlp import Discretization
from .problem import Problem
from .scaling import auto_scaling
from .solution import Solution
from .solve import STATUS_CONSTRAINT_TOL, NlpOutcome, check_constraint_tol, make_solution
from .status import SOLVER_REST
from .transcription import get_transcription

__all__ = ["rest_solution", "STATUS_REST"]

#: ``solver_status`` of `rest_solution` (no NLP solved; its ``status`` is 0 on success)
STATUS_REST = SOLVER_REST



def rest_solution(problem: Problem, *, T: float | None = None, transcription="radau",
                  constraint_tol: float | None = None) -> Solution:
    """The trajectory that holds the initial state under zero control, checked against the
    problem's own NLP constraints.

    For a rest-to-rest problem whose target is the initial state (a slew by a zero angle),
    this is the exact optimum: with a free final time ``T = T_min`` (default, usually 0),
    with a fixed one the zero control over the whole horizon. Nothing is optimized: the
    point ``x(t) = x_initial``, ``u = 0``, ``T`` is transcribed on one mesh interval and its
    `Solution.constraint_violation` (defects, path and boundary constraints, the attitude
    target, bounds; NLP units, see the module docstring) decides ``success``.

    Parameters
    ----------
    problem : Problem
        With every initial state given.
    T : float, optional [s]
        The horizon (default: the lower bound of a free ``T``, the fixed ``T`` otherwise).
    transcription : str or Transcription, optional
        The transcription of the returned solution (default ``'radau'``).
    constraint_tol : float, optional
        As in `solve` (default `DEFAULT_CONSTRAINT_TOL`).

    Returns
    -------
    Solution
        ``status`` 0 and ``success=True`` when the held state satisfies every constraint to
        ``constraint_tol``, else ``success=False`` and `STATUS_CONSTRAINT_TOL` (101); its
        ``solver_status`` is `STATUS_REST` (``'Rest_Solution'``: no NLP solved).
        ``iterations = 0``; with ``T = 0`` every node time is ``t0`` and `Solution.sample`
        accepts ``t0`` only.

    Raises
    ------
    TypeError
        If ``problem`` is not a `Problem`.
    ValueError
        If an initial state is free, or ``T`` is not a finite horizon within the bounds of ``T``.

    Examples
    --------
    Holding the state is the exact answer when the target is the initial state:

    >>> from appdyn import ocp
    >>> from appdyn.ocp.examples import double_integrator
    >>> model = double_integrator()  # x'' = u
    >>> stay = ocp.Problem(model, T=1.0, x_initial=[0, 0], x_final=[0, 0],
    ...                    lagrange=lambda x, u, p: 0.5 * u**2)
    >>> sol = ocp.rest_solution(stay)
    >>> sol.success, sol.status, sol.solver_status, sol.cost, sol.iterations
    (True, 0, 'Rest_Solution', 0.0, 0)
    """
    if not isinstance(problem, Problem):
        raise TypeError(f"`problem` must be an ocp.Problem, got {type(problem).__name__}")
    if np.any(np.isnan(problem.x_initial)):
        raise ValueError("`problem` must give every initial state for a rest solution")
    lo, hi = problem.T_bounds
    if T is None:
        T = lo if problem.free_time else problem.T
    if isinstance(T, (bool, np.bool_)) or not isinstance(T, (int, float, np.integer, np.floating)):
        raise ValueError(f"`T` must be a number [s], got {T!r}")
    T = float(T)
    if not (np.isfinite(T) and lo <= T <= hi):
        raise ValueError(f"`T` must be a finite horizon in [{lo}, {hi}] s, got {T}")
    ctol = check_constraint_tol(constraint_tol)
    t_build = time.perf_counter()
    tr = get_transcription(transcription)
    mesh = Mesh.uniform(1)
    nu = problem.model.nu
    n_x = 1 + tr.x_sigma.size
    n_u = tr.u_sigma.size + int(tr.u_at_start)
    x0 = np.asarray(problem.x_initial, dtype=float)
    p = np.asarray(problem.p, dtype=float)
    node = NodeGuess(X=np.repeat(x0[:, None], n_x, axis=1), U=np.zeros((nu, n_u)),
                     Xu=np.repeat(x0[:, None], n_u, axis=1), p=p, T=T)
    scaling = auto_scaling(problem, node, overrides={"T": 1.0} if T == 0 else None)
    disc = Discretization(problem, tr, mesh, scaling)
    free = problem.free_params
    sc = scaling
    w = disc.w.join({"X": node.X / sc.x[:, None], "U": node.U / sc.u[:, None],
                     "P": (p[free] / sc.p[free])[:, None],
                     "T": np.full((int(problem.free_time), 1), T / sc.T)})
    g = disc.constraints(w)
    viol = disc.violation(g, w) if np.all(np.isfinite(g)) else float("nan")
    success = bool(viol <= ctol)
    if success:
        status = 0
        message = (f"rest solution: the initial state held under zero control for T = {T:g} s meets "
                   f"every constraint (violation {viol:.2g} <= constraint_tol {ctol:g})")
    else:
        status = STATUS_CONSTRAINT_TOL
        message = (f"the initial state held under zero control for T = {T:g} s violates the "
                   f"constraints by {viol:.3g} > constraint_tol {ctol:g}: not a solution")
    return make_solution(problem, tr, mesh, disc, NlpOutcome(
        w=w, lam_g=np.zeros(disc.g.size), g=g, success=success, status=status, message=message,
        iterations=0, solve_time=0.0, build_time=time.perf_counter() - t_build,
        solver_status=STATUS_REST))
