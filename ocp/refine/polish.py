"""`polish_switches`: exact switch times for bang-bang / time-optimal problems.

Two methods. ``'switch-times'`` (`ocp.refine.switch_times`): when every control component is
bang-bang on every arc of the starting solution (`bang_arcs`), the arc durations are the only
decision variables, the control held at its bang value on each arc, the arcs integrated by
fixed-step RK8 multiple shooting with exact sensitivities -- a small well-posed NLP that IPOPT
solves in a handful of iterations. ``'moving-knots'`` (below) handles everything else
(singular, coast and constrained arcs); ``'auto'`` (the default) tries the first and falls
back to the second.

The moving-knot polish is a re-solve with a piecewise-constant control
(`ocp.RadauConstantControl`) on a *free* mesh whose interval lengths are decision
variables, so switch times land exactly on knots: the
switching structure no longer costs accuracy (on a fixed mesh a switch inside an interval of
length ``h`` leaves an ``O(h^2)`` error in ``T``).

The free mesh is built without touching the engine: the problem is restated in a pseudo
time ``sigma in [0, 1]`` on a fixed mesh, with the physical time ``t`` an extra state and
the time dilation ``v = dt/dsigma`` an extra control, piecewise constant per interval::

    dx/dsigma = v f(x, u, p),    dt/dsigma = v,     v_lower <= v <= v_upper

Within an interval ``t`` is affine in ``sigma``, so Radau collocation of the restated
problem is exactly Radau collocation of the original one on the mesh of the physical
interval lengths ``h_k = v_k dsigma_k``; the result is returned as a `Solution` of the
original problem on that mesh (`Solution.from_arrays`).
"""
from __future__ import annotations

import math
import time
from typing import Mapping

import casadi as ca
import numpy as np

from appdyn.config import param
from appdyn.dynamics.model import Model
from appdyn.dynamics.interrupts import interruptible

from ..cached import cached, function_key
from ..ipopt_options import check_ipopt_options
from ..progress import stage_sink
from appdyn.dynamics.validate import integer
from ..mesh import Mesh, sorted_union
from ..problem import Constraint, Problem
from ..solution import Solution
from ..status import STATUS_WALL_TIME
from ..solve import solve
from ..functions import sx_compatible
from ..transcription import RadauConstantControl
from .result import STATUS_WORSE, RefinedSolution, annotate, graded
from .switch_times import bang_arcs, optimize_switch_times
from .switches import find_switches

__all__ = ["polish_switches", "STATUS_BUDGET"]

METHODS = ("auto", "switch-times", "moving-knots")


#: ``status`` of a polish stopped by its ``budget`` (IPOPT's -5 ``Maximum_WallTime_Exceeded``).
STATUS_BUDGET = STATUS_WALL_TIME
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


def _free_mesh_rhs(f: ca.Function) -> ca.Function:
    """``(x, t), (u, v) -> (v f(x, u, p), v)``: the right-hand side in pseudo time."""
    nx, nu, np_ = f.numel_in(0), f.numel_in(1), f.numel_in(2)
    sym = ca.SX if sx_compatible(f) else ca.MX
    xa, ua, p = sym.sym("x", nx + 1), sym.sym("u", nu + 1), sym.sym("p", np_)
    v = ua[nu]
    rhs = ca.vertcat(v * f(xa[:nx], ua[:nu], p), v)
    return ca.Function(f"{f.name()}_free_mesh", [xa, ua, p], [rhs], ["x", "u", "p"], ["xdot"])


def _free_mesh_problem(problem: Problem, T_ref: float, stretch) -> Problem:
    """The problem in pseudo time ``sigma`` with the clock ``t`` as an extra state and the
    dilation ``v = dt/dsigma`` as an extra control, ``stretch[0] T_ref <= v <=
    stretch[1] T_ref`` (see the module docstring)."""
    model = problem.model
    nx, nu = model.nx, model.nu
    fa = cached("free_mesh_rhs", (function_key(model.f),), lambda: _free_mesh_rhs(model.f),
                keepalive=model.f)
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
                   name=f"{problem.name}_free_mesh", maximize=problem.maximize)


def _out_of_budget(out: RefinedSolution, budget: float, what: str) -> RefinedSolution:
    """``out`` failed with `STATUS_BUDGET`: the ``budget`` [s] ran out before ``what``."""
    return annotate(out, {"budget_spent": True}, success=False, status=STATUS_BUDGET,
                    message=f"{out.message}; the polish budget of {budget:.3g} s was spent "
                            f"before {what}")


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


@interruptible
def polish_switches(problem: Problem, solution: Solution, *, N: int | None = None, degree: int = 3,
                    verbose=False, stretch=(0.05, 5.0), method: str = "auto",
                    budget: float | None = None, **solve_kwargs) -> RefinedSolution:
    """Re-solve a bang-bang / time-optimal problem with exact switch times.

    ``method='switch-times'``: when ``solution`` is bang-bang (`bang_arcs`: every control
    component at a bound on every arc between switches), optimize the arc durations directly
    (`ocp.refine.switch_times.optimize_switch_times`: the control fixed at its bang value per
    arc, RK8 multiple shooting with exact sensitivities; a few IPOPT iterations, ``T`` to the
    integration error, about 1e-12). ``method='moving-knots'``: the free-mesh re-solve
    described below, which also handles singular, coast and constrained arcs.
    ``method='auto'`` (default): switch times when the solution is bang-bang, else -- or
    when that NLP fails, or ends with a cost worse than that of ``solution`` (a structure
    read wrongly) -- moving knots (``info['fallback']`` says why).

    Never worse as a success: a polished cost worse than ``solution.cost`` by more than
    `ocp.refine.result.WORSE_SLACK` = 1e-3 relative (the start's own discretization error:
    a fixed mesh can put a minimum time slightly *below* the exact optimum) is returned
    with ``success=False``, ``status`` 105 ``Worse_Than_Start`` and a message saying so
    (`ocp.refine.result.graded`); the caller keeps ``solution``.

    Moving knots:
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
    method : {'auto', 'switch-times', 'moving-knots'}
        See above. ``'switch-times'`` raises ``ValueError`` when ``solution`` is not
        bang-bang. The switch-time NLP reads ``N`` (its number of RK8 segments, when at
        least 2 per arc), ``degree``, ``ipopt_options``, ``scale`` and ``constraint_tol``.
    budget : float, optional
        Wall-time budget [s] of the whole call (default: none). Each NLP is stopped at the
        first IPOPT iteration past it (the switch-time NLP through its iteration callback,
        the moving knots through IPOPT's ``max_wall_time``), no further NLP (a finer RK8
        grid, a second structure, the moving knots) is started once it is spent, and a
        polish cut short is ``success=False`` with ``status`` -5 ``Maximum_WallTime_Exceeded``
        (``info['budget_spent']``). The NLP builds count against it but are not
        interrupted.
    **solve_kwargs
        Passed to `ocp.solve` (``ipopt_options`` is merged over the defaults
        ``{'tol': 1e-10, 'bound_relax_factor': 0, 'max_iter': 3000}``; ``scale`` may name the
        extra state ``'t_clock'`` and control ``'t_stretch'``).

    Returns
    -------
    RefinedSolution
        A solution of ``problem`` with transcription `RadauConstantControl` on the optimized
        mesh. ``info``: ``'method'`` (``'switch-times'`` or ``'moving-knots'``, the one
        returned), ``'switch_times'`` (where the control jumps, on knots),
        ``'initial_switch_times'``, ``'initial_T'``, ``'N'``,
        ``'stretch_active'`` (indices of intervals at a ``stretch`` bound; empty for switch
        times), ``'free_mesh_solution'`` (the solution of the restated problem; ``None`` for
        switch times), ``'wall_time'`` (of the whole call); after a fallback ``'fallback'``
        (why the switch-time NLP was not used) and ``'switch_time_solution'`` (its result,
        when one was solved); for switch times ``'short_arcs'`` (whether the structure is
        the second guess, with the arcs too short to be detected inserted: `bang_arcs`
        with ``short_arcs=True``, tried when the first fails), ``'attempt_iterations'``
        (IPOPT iterations of each switch-time structure tried; also after a fallback) and
        the keys of
        `optimize_switch_times`
        (``'durations'``, ``'arc_controls'``, ``'segments'``, ``'integration_error'``,
        ``'nlp_iterations'``, ``'nlp_status'``); always ``'initial_cost'`` and ``'gain'``
        (``solution.cost`` minus the returned cost, with the objective's sign: positive is
        better), ``'budget'``.
        ``success=False`` (never an exception) if IPOPT failed, the budget ran out, or the
        result is worse than ``solution`` (above).

    Notes
    -----
    Path constraints are imposed at the interval ends only. ``T`` of the result is not
    necessarily below that of ``solution``: both carry their own discretization errors.

    Examples
    --------
    The bang-bang double integrator: the switch moves onto its exact time T/2 = 1 s.

    >>> from appdyn import ocp
    >>> from appdyn.ocp.examples import min_time
    >>> fastest = min_time()  # x'' = u, |u| <= 1, from rest at 0 to rest at 1
    >>> sol = ocp.polish_switches(fastest, ocp.solve(fastest, N=10))
    >>> sol.success, round(sol.T, 8), ocp.find_switches(sol).round(8), sol.info["method"]
    (True, 2.0, array([1.]), 'switch-times')
    """
    if not isinstance(problem, Problem):
        raise TypeError(f"`problem` must be an ocp.Problem, got {type(problem).__name__}")
    if not isinstance(solution, Solution):
        raise TypeError(f"`solution` must be an ocp.Solution, got {type(solution).__name__}")
    if solution.problem.model.nx != problem.model.nx or solution.problem.model.nu != problem.model.nu:
        raise ValueError("`solution` must solve a problem with the states and controls of `problem`")
    if N is not None:
        N = integer(N, "N", minimum=1)
    try:
        lo_s, hi_s = (float(v) for v in stretch)
    except (TypeError, ValueError):
        raise ValueError(f"`stretch` must be a pair (lower, upper), got {stretch!r}") from None
    if not (0 < lo_s < 1 < hi_s < math.inf):
        raise ValueError(f"`stretch` must satisfy 0 < lower < 1 < upper < inf, got {stretch!r}")
    if method not in METHODS:
        raise ValueError(f"`method` must be one of {METHODS}, got {method!r}")
    if budget is not None:
        if isinstance(budget, (bool, np.bool_)) or not isinstance(
                budget, (int, float, np.integer, np.floating)) or not float(budget) > 0:
            raise ValueError(f"`budget` must be a number > 0 [s] or None, got {budget!r}")
        budget = float(budget)
    verbose = stage_sink(verbose, "polish")
    degree = integer(degree, "degree", minimum=1)
    tr = RadauConstantControl(degree)
    kw = dict(solve_kwargs)
    for bad in ("transcription", "mesh", "guess", "N", "degree"):
        if bad in kw:
            raise ValueError(f"polish_switches chooses `{bad}` itself; got {bad}={kw[bad]!r}")
    user_ipopt = kw.pop("ipopt_options", None) or {}
    if not isinstance(user_ipopt, Mapping):
        raise ValueError(f"`ipopt_options` must be a mapping, got {type(user_ipopt).__name__}")
    ipopt = {**param("ocp.ipopt_strict"), **check_ipopt_options(user_ipopt)}

    t_start = time.perf_counter()

    def left() -> float | None:  # seconds of the budget left (None: no budget)
        return None if budget is None else budget - (time.perf_counter() - t_start)

    def finish(out: RefinedSolution, info: dict, message: str) -> RefinedSolution:
        info = {**info, "budget": budget, "wall_time": time.perf_counter() - t_start}
        out = annotate(out, info, message=message)
        if out.status == STATUS_BUDGET:
            out = _out_of_budget(out, budget, "the NLP converged")
        return graded(problem, solution, out)

    fallback = {}
    if method != "moving-knots":
        arcs, why = bang_arcs(solution)
        if arcs is None and method == "switch-times":
            raise ValueError(f"method='switch-times' needs a bang-bang solution: {why}")
        if arcs is not None:
            ctol = kw.get("constraint_tol")

            def attempt(a):
                n_sw = N if N is not None and N >= 2 * a.durations.size else None
                st = optimize_switch_times(problem, solution, arcs=a, N=n_sw, degree=degree,
                                           verbose=verbose, ipopt_options=ipopt,
                                           scale=kw.get("scale"),
                                           constraint_tol=1e-6 if ctol is None else ctol,
                                           max_wall_time=None if budget is None
                                           else max(left(), 1e-9))
                # an optimum worse than the start: the structure read from it is suspect
                # (a missed arc); the moving knots may find the better one
                worse = st.status == STATUS_WORSE  # `optimize_switch_times` graded it
                return st, worse, (st.success and not worse) or method == "switch-times"

            st, worse, done = attempt(arcs)
            short, tried = False, [st.iterations]
            spent = budget is not None and left() <= 0
            if spent and not done:  # no time for a second structure or the moving knots
                info = {"stretch_active": np.zeros(0, dtype=int), "free_mesh_solution": None,
                        "short_arcs": False, "attempt_iterations": tried}
                out = finish(st, info, "polish_switches: " + st.message)
                if out.status == STATUS_BUDGET:
                    return out
                return annotate(out, {"budget_spent": True}, message=(
                    f"{out.message}; the polish budget of {budget:.3g} s was spent before a "
                    "second structure or the moving knots could be tried"))
            if not done and method == "auto":  # second guess: arcs too short to be detected
                more, _ = bang_arcs(solution, short_arcs=True)
                if more is not None and more.durations.size > arcs.durations.size:
                    st2, worse2, done = attempt(more)
                    tried.append(st2.iterations)
                    if done:
                        st, worse, short = st2, worse2, True
            if done:
                info = {"stretch_active": np.zeros(0, dtype=int), "free_mesh_solution": None,
                        "short_arcs": short, "attempt_iterations": tried}
                return finish(st, info, "polish_switches: " + st.message)
            why = (f"the switch-time optimum {st.cost:.10g} is worse than the start's "
                   f"{solution.cost:.10g} (the structure read from it is suspect)" if worse
                   else f"the switch-time NLP failed: {st.message}")
            fallback = {"fallback": why, "switch_time_solution": st, "attempt_iterations": tried}
        else:
            fallback = {"fallback": f"not bang-bang: {why}"}

    if budget is not None and left() <= 0:  # no time left for the moving knots
        last = fallback.get("switch_time_solution", solution)
        info = {"method": last.info.get("method") if last is not solution else None, **fallback}
        return _out_of_budget(annotate(last, {**info, "budget": budget, "initial_cost": float(
            solution.cost), "gain": 0.0, "wall_time": time.perf_counter() - t_start}),
            budget, "the moving-knot re-solve")
    mesh, sw0 = _aligned_mesh(solution, N)
    T0 = float(solution.T)
    nx, nu, np_ = problem.model.nx, problem.model.nu, problem.model.np
    b = mesh.breaks
    aug = _free_mesh_problem(problem, T0, (lo_s, hi_s))
    # guess in pseudo time sigma (= t / T0 initially): states and clock at the nodes, the
    # interval-mean control of `solution`, v = T0
    sig = sorted_union(tr.state_tau(mesh), b)
    xg = np.vstack([solution.sample(solution.t0 + T0 * sig)[0], T0 * sig])
    m = 16
    tm = (b[:-1, None] + (np.arange(m)[None, :] + 0.5) / m * np.diff(b)[:, None]).reshape(-1)
    um = solution.sample(solution.t0 + T0 * tm)[1].reshape(nu, mesh.N, m).mean(axis=2)
    um = np.clip(um, problem.u_bounds[0][:, None], problem.u_bounds[1][:, None])
    um = np.vstack([um, np.full((1, mesh.N), T0)])

    def u_guess(t):
        return um[:, int(np.clip(np.searchsorted(b, t, side="left") - 1, 0, mesh.N - 1))]

    guess = {"t": sig, "x": xg, "u": u_guess, "p": np.asarray(solution.p, dtype=float)}
    wall = {} if budget is None else {"max_wall_time": min(
        float(ipopt.get("max_wall_time", math.inf)), max(left(), 1e-3))}
    sa = solve(aug, transcription=tr, mesh=mesh, guess=guess, verbose=verbose,
               ipopt_options={**ipopt, **wall}, **kw)

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
    out = Solution.from_arrays(
        problem, tr, phys_mesh, sa.x[:nx], sa.dense.Uo[:nu, :, 0], np.asarray(sa.p)[:np_], T,
        cost=sa.cost, success=sa.success, status=sa.status, message=sa.message,
        iterations=sa.iterations, solve_time=sa.solve_time, build_time=sa.build_time,
        constraint_violation=sa.constraint_violation, multipliers=mult,
        solver_status=sa.solver_status)
    v = sa.dense.Uo[nu, :, 0]
    active = np.flatnonzero((v <= lo_s * T0 * (1 + 1e-6)) | (v >= hi_s * T0 * (1 - 1e-6)))
    info = {"method": "moving-knots", "switch_times": find_switches(out),
            "initial_switch_times": sw0, "initial_T": T0, "N": mesh.N, "stretch_active": active,
            "free_mesh_solution": sa, **fallback}
    prefix = "polish_switches (constant control and free length per interval): "
    return finish(out, info, prefix + sa.message)
