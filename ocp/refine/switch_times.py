"""Switch-time optimization of a bang-bang solution: the arc durations as the only controls.

Once the switching structure of a bang-bang solution is known (`bang_arcs`: every control
component at one of its bounds on every arc between consecutive switches), the optimal
control problem reduces to a small, well-posed NLP in the arc durations ``d_0 .. d_m >= 0``
(the control on each arc fixed at its bang value). `optimize_switch_times` states it by
direct multiple shooting with exact sensitivities:

* arc ``k`` is cut into ``n`` equal segments of length ``h_k = d_k / n`` (the same ``n`` on
  every arc, so that the NLP's structure depends only on the number of arcs);
* each segment is one step of the explicit 8th-order Runge-Kutta method of Dormand & Prince
  (the 12-stage DOP853 tableau, fixed step, with the running cost integrated alongside),
  built once per model as an SX casadi Function (`ocp.cached`) and differentiated exactly
  (casadi AD: exact Jacobians and Hessians of the step, including with respect to ``h_k``);
* the states at the segment ends are NLP variables; continuity defects, the problem's
  boundary values, boundary constraints, attitude target (`ocp.attitude.attitude_error`,
  met up to sign; one inequality with a pointing tolerance), state bounds at the segment
  ends, path constraints at the segment ends, the horizon bounds ``T_min <= sum d_k <=
  T_max`` (or ``= T``);
* the objective is the problem's own (``phi(x(tf), p, T) + integral L``), with its sign.

The decision variables are the durations, the free parameters and the segment-end states:
no control variables, no singular directions (the free-mesh polish of `polish_switches`
carries one dilation per interval, most of which the objective does not see). IPOPT
(``casadi.nlpsol``, the derivatives assembled per segment: `ocp.refine.arc_nlp`) then
converges in a handful of iterations to
``Solve_Succeeded`` (Bilimoria & Wie's slew: 3 iterations, 0.03 s of IPOPT, ``T =
3.2430832775``); the answer carries only the integration error of the RK8 steps
(``O(h^8)``, estimated by step doubling: ``info['integration_error']``, about 3e-13 on
Bilimoria & Wie with the default 28 segments) and the NLP tolerance.

The NLP is built once per problem structure (`ocp.assembly.structure_key`: the model, cost
and constraint functions by content) and number of arcs and segments, with every number --
the arc controls, fixed parameter values, scales and the target quaternion -- an NLP
parameter; it and its IPOPT instance (pooled, one caller at a time) live in the one cache
(`ocp.cached`). A slew to another target with as many arcs builds nothing (a 2 rad slew
after Bilimoria & Wie's: 0.4 ms instead of 55 ms).

A structure read wrongly shows as an infeasible NLP: too few arcs cannot meet the end
conditions (`polish_switches` then tries `bang_arcs` with ``short_arcs=True``, then the
moving knots); surplus arcs shrink to zero length.

The result is a `Solution` of the original problem with transcription
`ocp.RadauConstantControl` on the mesh of the segments (knots exactly at the switches, the
bang value held on each interval); its states at the Radau nodes come from the same RK8
step (one step of length ``tau h`` from the segment start), its costates from the
multipliers of the continuity defects propagated through the step's Jacobian.
"""
from __future__ import annotations

import contextlib
import math
import time
from dataclasses import dataclass
from typing import Mapping

import casadi as ca
import numpy as np

from appdyn.config import param
from appdyn.dynamics.cache import construction_lock
from appdyn.dynamics.interrupts import check_interrupt
from appdyn.dynamics.validate import integer

from ..attitude import attitude_error
from ..cached import checkout
from ..ipopt_options import check_ipopt_options, ipopt_solver
from ..progress import IterationCallback, iteration_sink
from ..mesh import Mesh
from ..problem import Problem
from ..solution import Solution
from ..status import status_code
from ..transcription import RadauConstantControl
from .arc_nlp import arc_nlp, constraint_bounds
from .arcs import BangArcs, bang_arcs
from .result import RefinedSolution, annotate, graded
from .rk8_step import step_adjoint, step_function

__all__ = ["BangArcs", "bang_arcs", "optimize_switch_times"]



# --------------------------------------------------------------------------- helpers
def _pow2(v) -> float:
    v = float(abs(v))
    if not (math.isfinite(v) and v > 0):
        return 1.0
    return float(2.0 ** round(math.log2(v)))


def _segments(durations: np.ndarray, N: int | None) -> np.ndarray:
    """Segments per arc: the same number on every arc, ``ceil(N / arcs)`` (``N`` default
    ``max(24, 4 arcs)``), at least 2. Not in proportion to the durations: then the NLP's
    structure depends only on the number of arcs, and a slew to another target with as many
    arcs reuses the built NLP (`arc_nlp`); the step-doubling loop of
    `optimize_switch_times` looks after the accuracy of the longer arcs."""
    n_arcs = durations.size
    N = max(24, 4 * n_arcs) if N is None else int(N)
    return np.full(n_arcs, max(2, -(-N // n_arcs)), dtype=int)


def _read_only(a: np.ndarray) -> np.ndarray:
    a.setflags(write=False)
    return a


@dataclass
class _Result:
    """One switch-time NLP solved (`_solve_arcs`)."""

    solution: RefinedSolution
    durations: np.ndarray
    status: str
    iterations: int
    integration_error: float


# ------------------------------------------------------------------------------ solve
def optimize_switch_times(problem: Problem, solution: Solution, *, arcs: BangArcs | None = None,
                          N: int | None = None, degree: int = 3, verbose=False,
                          ipopt_options: Mapping | None = None, scale: Mapping | None = None,
                          constraint_tol: float = 1e-6, integration_tol: float = 1e-10,
                          max_wall_time: float | None = None) -> RefinedSolution:
    """Optimize the switch times of a bang-bang ``solution`` of ``problem`` (module
    docstring): the arc durations are the decision variables, the control on each arc is
    held at its bang value.

    Parameters
    ----------
    problem : Problem
    solution : Solution
        A solution of ``problem`` with a bang-bang control (the structure is read from it
        with `bang_arcs` unless ``arcs`` is given; its states are the guess).
    arcs : BangArcs, optional
        The switching structure (default: ``bang_arcs(solution)``).
    N : int, optional
        About the number of RK8 segments (mesh intervals of the result) in all, the same
        number ``ceil(N / arcs)`` on every arc, at least 2. Default ``max(24, 4 arcs)``, doubled (at most three times, each NLP warm started from the
        last) until the estimated integration error is below ``integration_tol``.
    degree : int
        Radau degree of the result's transcription (`RadauConstantControl`): the number of
        state nodes per interval, each filled by an RK8 step.
    verbose : bool or callable
        One line per IPOPT iteration to stderr (``True``; `ocp.progress.StagePrinter`), or
        each `ocp.progress.Progress` to a callable. Never IPOPT's own output on stdout.
    ipopt_options : mapping, optional
        Merged over ``{'tol': 1e-10, 'bound_relax_factor': 0, 'max_iter': 3000}``.
    scale : mapping, optional
        Overrides of the automatic scales (powers of two as in `ocp.scaling`: states by
        bounds or largest magnitude, durations by ``T``, the objective by the start's cost),
        by state or parameter name, ``'T'`` (also read as ``'t_clock'``), ``'objective'``,
        ``'q_final'``.
    constraint_tol : float
        Largest scaled constraint violation of a success.
    integration_tol : float
        Target of the integration error estimate (sum over the segments of the step-doubling
        estimate of the RK8 local error, relative to the state scales); only steers the
        default ``N``.
    max_wall_time : float, optional
        Wall-time budget [s] of the whole call: IPOPT is stopped at the first iteration
        past it (``status`` -5 ``Maximum_WallTime_Exceeded``, not a success; through the
        iteration callback, so that the pooled solver is reused whatever the budget), and
        no finer NLP is started once it is spent (the last success is returned, its
        ``integration_error`` saying how accurate it is). Default: none.

    Returns
    -------
    RefinedSolution
        ``success`` when IPOPT returned ``Solve_Succeeded``, the violation is at most
        ``constraint_tol`` and the cost is not worse than that of ``solution`` by more than
        `ocp.refine.result.WORSE_SLACK` relative (else ``status`` 105 ``Worse_Than_Start``;
        ``info['initial_cost']``, ``info['gain']``). Transcription `RadauConstantControl` on the mesh of the RK8
        segments (knots at the switches). ``iterations`` and ``solve_time`` sum over the NLPs
        solved. ``info``: ``'method'`` (``'switch-times'``), ``'switch_times'`` [s],
        ``'initial_switch_times'``, ``'durations'`` (arc lengths [s]), ``'arc_controls'``
        (nu, arcs), ``'initial_T'``, ``'N'``, ``'segments'`` (per arc),
        ``'integration_error'``, ``'nlp_iterations'`` and ``'nlp_status'`` (one per NLP
        solved), ``'wall_time'``.

    Raises
    ------
    TypeError
        If ``problem`` or ``solution`` is of the wrong type.
    ValueError
        If ``solution`` is not bang-bang (the reason from `bang_arcs`), or ``N`` is too
        small for the arcs.

    Examples
    --------
    >>> from appdyn import ocp
    >>> from appdyn.ocp.examples import min_time
    >>> from appdyn.ocp.refine.switch_times import optimize_switch_times
    >>> fastest = min_time()  # x'' = u, |u| <= 1, from rest at 0 to rest at 1
    >>> sol = optimize_switch_times(fastest, ocp.solve(fastest, N=9))
    >>> sol.success, round(sol.T, 12), sol.info["switch_times"].round(12)
    (True, 2.0, array([1.]))
    """
    if not isinstance(problem, Problem):
        raise TypeError(f"`problem` must be an ocp.Problem, got {type(problem).__name__}")
    if not isinstance(solution, Solution):
        raise TypeError(f"`solution` must be an ocp.Solution, got {type(solution).__name__}")
    t_start = time.perf_counter()
    if arcs is None:
        arcs, why = bang_arcs(solution)
        if arcs is None:
            raise ValueError(f"the solution is not bang-bang: {why}")
    if not isinstance(arcs, BangArcs):
        raise TypeError(f"`arcs` must be a BangArcs, got {type(arcs).__name__}")
    D = np.asarray(arcs.durations, float)
    if arcs.controls.shape != (problem.model.nu, D.size) or not np.all(D >= 0) or not D.sum() > 0:
        raise ValueError("`arcs` must hold non-negative durations (not all zero) and one "
                         f"control per component and arc, shape ({problem.model.nu}, {D.size})")
    degree = integer(degree, "degree", minimum=1)
    if N is not None:
        N = integer(N, "N", minimum=1)
        if N < 2 * D.size:
            raise ValueError(f"`N` must be at least 2 per arc ({2 * D.size}), got {N}")
    if max_wall_time is not None and not (isinstance(max_wall_time, (int, float, np.integer,
                                                                        np.floating))
                                          and float(max_wall_time) > 0):
        raise ValueError(f"`max_wall_time` must be a number > 0 [s] or None, got {max_wall_time!r}")
    nseg = _segments(D, N)
    guess, runs = solution, []
    while True:
        run = _solve_arcs(problem, guess, arcs._replace_durations(D), nseg, degree=degree,
                          verbose=verbose, ipopt_options=ipopt_options, scale=scale,
                          constraint_tol=constraint_tol,
                          deadline=None if max_wall_time is None else t_start + max_wall_time)
        runs.append(run)
        spent = max_wall_time is not None and time.perf_counter() - t_start >= max_wall_time
        if (N is not None or not run.solution.success or len(runs) == 4
                or run.integration_error <= integration_tol or spent):
            break
        guess, D, nseg = run.solution, run.durations, 2 * nseg
    ok = [r for r in runs if r.solution.success]
    out = ok[-1].solution if ok else runs[-1].solution  # a failed finer NLP: the last success
    info = {"initial_switch_times": np.asarray(arcs.switch_times, float),
            "initial_T": float(solution.T),
            "nlp_iterations": [r.iterations for r in runs], "nlp_status": [r.status for r in runs],
            "wall_time": time.perf_counter() - t_start}
    return graded(problem, solution, annotate(
        out, info, iterations=sum(r.iterations for r in runs),
        solve_time=sum(r.solution.solve_time for r in runs),
        build_time=sum(r.solution.build_time for r in runs)))


def _solve_arcs(problem: Problem, guess: Solution, arcs: BangArcs, nseg: np.ndarray, *, degree,
                verbose, ipopt_options, scale, constraint_tol, deadline=None) -> _Result:
    """The switch-time NLP with ``nseg[k]`` RK8 segments on arc ``k``, from the states of
    ``guess`` and the durations of ``arcs``."""
    scale = dict(scale or {})
    model = problem.model
    nx = model.nx
    sign = problem.objective_sign
    tr = RadauConstantControl(degree)
    D0 = np.asarray(arcs.durations, float)
    n_arcs = D0.size
    S = int(nseg.sum())
    arc_of = np.repeat(np.arange(n_arcs), nseg)
    T0 = float(D0.sum())
    t0 = float(guess.t0)
    step = step_function(model, problem.lagrange)
    free_p = problem.free_params
    p0 = np.asarray(guess.p, float).copy()
    Ucols = np.asarray(arcs.controls, float)[:, arc_of]

    # ---- scales (powers of two, as `ocp.scaling`)
    seg_t = np.concatenate([[0.0], np.cumsum(np.repeat(D0 / nseg, nseg))])
    seg_t[-1] = T0
    Xg = np.asarray(guess.sample(t0 + seg_t)[0], float).reshape(nx, S + 1)
    xlo, xhi = (np.asarray(b, float) for b in problem.x_bounds)
    sx = np.ones(nx)
    for i, name in enumerate(model.states):
        if name in scale:
            sx[i] = float(scale[name])
        elif np.isfinite(xlo[i]) and np.isfinite(xhi[i]):
            sx[i] = _pow2(max(abs(xlo[i]), abs(xhi[i])))
        else:
            ends = [v for v in (problem.x_initial[i], problem.x_final[i]) if np.isfinite(v)]
            sx[i] = _pow2(np.max(np.abs(np.concatenate([Xg[i], ends]))))
    sT = float(scale.get("T", scale.get("t_clock", _pow2(T0))))
    sp = np.array([float(scale.get(model.params[i], _pow2(p0[i]))) for i in free_p])
    sJ = float(scale["objective"]) if "objective" in scale else _pow2(guess.cost)

    sq = 1.0
    if problem.q_final is not None:
        if "q_final" in scale:
            sq = float(scale["q_final"])
        else:  # as `ocp.scaling`: about the half-angle still to turn, in [1e-8, 1]
            iq = model.attitude[0]
            e0 = float(np.linalg.norm(attitude_error(problem.q_final, Xg[iq:iq + 4, 0])))
            sq = _pow2(min(max(16 * e0, 1e-8), 1.0))

    # ---- the NLP: one built structure (and IPOPT instance) per switching structure, the
    # numbers as parameters and bounds
    t_build = time.perf_counter()
    nlp = arc_nlp(problem, step, n_arcs, nseg)
    fixed_p = p0.copy()
    fixed_p[free_p] = 0.0
    qf = np.zeros(4) if problem.q_final is None else np.asarray(problem.q_final, float)
    par = np.concatenate([Ucols.reshape(-1, order="F"), fixed_p, sx, [sT], sp, [sJ], qf, [sq]])
    lbg, ubg = constraint_bounds(problem, nlp.blocks, sT, sq)

    # ---- bounds and guess
    T_hi = problem.T_bounds[1]
    plo, phi = problem.p_bounds[0][free_p] / sp, problem.p_bounds[1][free_p] / sp
    XL = np.repeat((xlo / sx)[:, None], S + 1, axis=1)
    XU = np.repeat((xhi / sx)[:, None], S + 1, axis=1)
    for col, given in ((0, problem.x_initial), (S, problem.x_final)):
        fixed = np.isfinite(given)
        XL[fixed, col] = XU[fixed, col] = given[fixed] / sx[fixed]
    lbw = np.concatenate([np.zeros(n_arcs), plo, XL.reshape(-1, order="F")])
    ubw = np.concatenate([np.full(n_arcs, T_hi / sT), phi, XU.reshape(-1, order="F")])
    Xg0 = np.clip(Xg / sx[:, None], XL, XU)
    w0 = np.concatenate([D0 / sT, p0[free_p] / sp, Xg0.reshape(-1, order="F")])

    user = check_ipopt_options(ipopt_options)
    ipopt = {**param("ocp.ipopt_strict"), "print_level": 0, "sb": "yes", **user}
    # verbose: IPOPT's iterations through a callback to the sink (stderr), never IPOPT's own
    # printing on the C stdout
    sink = iteration_sink(verbose, None)
    # inputs_check off: the bounds are built consistent here, and casadi's count of
    # equalities (fixed variables included) against variables would print a warning for the
    # structurally over-determined end conditions of a symmetric slew, which IPOPT solves
    # (a quiet library)
    nlp_opts = {"ipopt": ipopt, "print_time": False, "error_on_fail": False, "inputs_check": False,
                **(nlp.derivatives or {})}  # assembled derivatives (`arc_nlp`) where built
    if sink is None:  # pooled with its (data-less) callback, which carries the deadline
        def build():
            callback = IterationCallback(0, 0)
            return ipopt_solver("switch_times", nlp.nlp,
                                {**nlp_opts, "iteration_callback": callback}), callback

        lend = checkout("switch_times_nlpsol", (nlp.key, repr(sorted(ipopt.items()))), build,
                        keepalive=nlp)
    else:  # a solver of its own, with the callback of this sink
        def violation(g):
            return float(np.max(np.concatenate([[0.0], lbg - g, g - ubg])))

        callback = IterationCallback(w0.size, lbg.size, violation, sink)
        with construction_lock():
            lend = contextlib.nullcontext((ipopt_solver(
                "switch_times", nlp.nlp, {**nlp_opts, "iteration_callback": callback}),
                callback))
    with lend as (solver, callback):
        build_time = time.perf_counter() - t_build
        check_interrupt()
        t_solve = time.perf_counter()
        error = None
        callback.deadline = deadline
        try:
            res = solver(x0=w0, p=par, lbx=lbw, ubx=ubw, lbg=lbg, ubg=ubg)
        except RuntimeError as exc:  # an evaluation error inside CasADi: report it
            res, error = None, exc
        finally:
            callback.deadline = None
        solve_time = time.perf_counter() - t_solve
        stats = solver.stats()
    check_interrupt()
    status = solver_status = str(stats.get("return_status", "Unknown"))
    if status == "User_Requested_Stop" and deadline is not None and time.perf_counter() >= deadline:
        status = "Maximum_WallTime_Exceeded"  # stopped by the callback at the deadline
    iterations = int(stats.get("iter_count", 0))
    if res is None:
        wopt, lam_g, gval = w0, np.full(lbg.size, np.nan), np.full(lbg.size, np.nan)
        status = solver_status = "Exception"
    else:
        wopt = np.asarray(res["x"], float).reshape(-1)
        lam_g = np.asarray(res["lam_g"], float).reshape(-1)
        gval = np.asarray(res["g"], float).reshape(-1)
    if np.all(np.isfinite(gval)) and np.all(np.isfinite(wopt)):
        viol = float(np.max(np.concatenate([[0.0], lbg - gval, gval - ubg, lbw - wopt, wopt - ubw])))
    else:
        viol = float("nan")

    # ---- back to physical values
    dopt = wopt[:n_arcs] * sT
    popt = p0.copy()
    popt[free_p] = wopt[n_arcs:n_arcs + free_p.size] * sp
    Xopt = wopt[n_arcs + free_p.size:].reshape(nx, S + 1, order="F") * sx[:, None]
    Topt = float(dopt.sum())
    cost = float(nlp.cost(wopt, par)) if np.all(np.isfinite(wopt)) else float("nan")
    success = status == "Solve_Succeeded" and np.isfinite(viol) and viol <= constraint_tol
    if not (np.all(np.isfinite(dopt)) and np.all(np.isfinite(Xopt)) and Topt > 0):
        dopt, Xopt, Topt, success = D0.copy(), Xg.copy(), T0, False
    hseg = (dopt / nseg)[arc_of]
    keep = hseg > 1e-13 * Topt  # segments of arcs that did not vanish
    segs = np.flatnonzero(keep)
    N_out = segs.size
    P = np.repeat(popt[:, None], 2 * S + 1, axis=1)

    # integration error: step doubling of every segment (RK8: |x_h - x_h/2,h/2| ~ 255/256 err)
    taus = np.asarray(tr.x_sigma, float)
    m = taus.size
    js = np.repeat(segs, m)
    tt = np.tile(taus, N_out)
    with construction_lock():
        step_S, step_nodes = step.map(S), step.map(js.size)
        adjoint_nodes = step_adjoint(step).map(js.size + 1)
    half = np.asarray(step_S(Xopt[:, :-1], Ucols, P[:, :S], hseg[None, :] / 2)[0], float).reshape(nx, S)
    two = np.asarray(step_S(half, Ucols, P[:, :S], hseg[None, :] / 2)[0], float).reshape(nx, S)
    full = np.asarray(step_S(Xopt[:, :-1], Ucols, P[:, :S], hseg[None, :])[0], float).reshape(nx, S)
    int_err = float(np.sum(np.max(np.abs(full - two) / sx[:, None], axis=0)))

    # states at the Radau nodes: one RK8 step of tau h from the segment start
    Pn = np.repeat(popt[:, None], js.size + 1, axis=1)
    Xnodes = np.asarray(step_nodes(Xopt[:, js], Ucols[:, js], Pn[:, :-1],
                                          (hseg[js] * tt)[None, :])[0], float).reshape(nx, js.size)
    last = np.flatnonzero(tt == 1.0)
    Xnodes[:, last] = Xopt[:, js[last] + 1]
    Xcols = np.hstack([Xopt[:, :1], Xnodes])
    breaks = np.concatenate([[0.0], np.cumsum(hseg[segs])]) / Topt
    breaks[-1] = 1.0
    mesh = Mesh(breaks)

    # costates (H = sign L + lambda . f): the continuity multipliers, unscaled, are the
    # costates at the segment ends; inside a segment lambda(t) = (dx_end/dx(t))^T lambda_end
    # + sign dq/dx(t) (the running cost of the rest of the step)
    costates = None
    n_defect = nx * S
    if res is not None and np.all(np.isfinite(lam_g[:n_defect])):
        lam_end = lam_g[:n_defect].reshape(nx, S, order="F") * (sJ / sx[:, None])
        n_in = js.size + 1  # the nodes inside the kept segments, then t0
        xs_in = np.hstack([Xnodes, Xopt[:, segs[:1]]])
        hs_in = np.concatenate([hseg[js] * (1.0 - tt), hseg[segs[:1]]])
        u_in = np.hstack([Ucols[:, js], Ucols[:, segs[:1]]])
        ends = np.concatenate([js, segs[:1]])
        lam = np.asarray(adjoint_nodes(xs_in, u_in, Pn, hs_in[None, :], lam_end[:, ends],
                                       np.full((1, n_in), float(sign))), float).reshape(nx, n_in)
        costates = _read_only(np.hstack([lam[:, -1:], lam[:, :-1]]))

    message = (f"switch-time optimization ({n_arcs} arcs, {S} RK8 segments): IPOPT {status} "
               f"after {iterations} iterations")
    if error is not None:
        message += f" ({error})"
    out_status = status
    if status == "Solve_Succeeded" and not success:
        out_status = "Constraint_Tol_Not_Met"
        message += f"; constraint violation {viol:.3g} above constraint_tol {constraint_tol:g}"
    out = Solution.from_arrays(problem, tr, mesh, Xcols, Ucols[:, segs], popt, Topt, cost=cost,
                               success=success, status=status_code(out_status), message=message,
                               iterations=iterations, solve_time=solve_time, build_time=build_time,
                               constraint_violation=viol, solver_status=solver_status)
    edges = t0 + np.concatenate([[0.0], np.cumsum(dopt)])
    live = np.flatnonzero(dopt > 1e-13 * Topt)
    U_live = np.asarray(arcs.controls, float)[:, live]
    jumps = np.flatnonzero(np.any(U_live[:, 1:] != U_live[:, :-1], axis=0))
    sw = edges[live[jumps + 1]]  # where a surviving arc starts with another control
    info = {"method": "switch-times", "switch_times": _read_only(sw),
            "durations": _read_only(dopt.copy()), "arc_controls": np.asarray(arcs.controls, float),
            "N": N_out, "segments": nseg.copy(), "integration_error": int_err}
    changes = {} if costates is None else {"costates": costates}
    return _Result(annotate(out, info, **changes), dopt, status, iterations, int_err)
