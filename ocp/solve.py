"""`solve`: transcribe a `Problem`, solve the NLP with IPOPT, return a `Solution`.

Success means verified
----------------------
A `Solution` says ``success=True`` only when

1. IPOPT returned ``Solve_Succeeded`` (its ``tol`` met, not merely ``acceptable_tol``),
2. the returned point's `Solution.constraint_violation` is at most ``constraint_tol``
   (default `DEFAULT_CONSTRAINT_TOL` = 1e-6),
3. the dense output (`Solution.sample`, what `Solution.propagate` replays) keeps the state
   and control bounds between the nodes too: `Solution.bound_violation` (scaled, on the
   grid of `ocp.checks.bound_grid`) is at most ``constraint_tol``; else status
   `STATUS_BOUND_VIOLATION` (102 ``Bound_Violation``) and a message naming the variable,
   the time and the remedy (``control='linear'`` or ``'constant'``, mesh refinement), and
4. unless ``verify=False``: the re-simulation of the returned control (CVODES,
   `Solution.propagation`) agrees with the collocated states (relative to their
   magnitudes) and cost to ``verify_tol`` (default `ocp.checks.default_verify_tol`: 3e-3,
   0.1 for the second-order trapezoid; the measurements behind them are in `ocp.checks`);
   else status `STATUS_RESIMULATION` (103 ``Resimulation_Mismatch``) and a message with the
   worst state, both costs and the likely cause (an unbounded angle control jumping by
   ``2 pi k`` between nodes is named as such). The re-simulation is cached on the
   solution, so `Solution.simulated_cost` and the propagation errors then cost nothing
   more. It adds 4-30 ms to a solve of the reference problems (median of 7, CVODES chains
   cached: brachistochrone N = 10 14.9 -> 18.5 ms, Bryson-Denham N = 40 36 -> 65 ms, min
   energy N = 40 8.6 -> 34.6 ms; a running cost is integrated by a second CVODES chain of
   its own), which matters only for many tiny solves: pass ``verify=False`` there.

``constraint_violation`` is the largest violation of any NLP constraint row *or* variable
bound, measured in the units of the NLP as handed to IPOPT (what IPOPT calls "unscaled"):
defect rows of state ``i`` divided by its scale ``d_x[i]``, path and boundary rows by their
row scales, attitude-target rows by their scale, variables in units of their scales (see
`ocp.scaling`). It is a relative measure for every row whose scale is its typical magnitude.
IPOPT's ``constr_viol_tol`` is set to ``constraint_tol`` unless given.

IPOPT's ``Solved_To_Acceptable_Level`` (which admits constraint violations up to
``acceptable_constr_viol_tol`` = 1e-2) is not a success: the NLP is re-solved once, warm
started from the acceptable point with the acceptable-level exit disabled
(``acceptable_iter = 0``, ``mu_init = 1e-9``) and at most 200 more iterations (within
``max_iter``). If that reaches
``Solve_Succeeded`` it counts (``iterations`` covers both runs, the message says so);
otherwise the result has ``success=False``.

``status`` is an int (the table in `ocp.status`: 0 success, IPOPT's return statuses by
IPOPT's numbers); IPOPT's text is kept in ``solver_status``. Status values besides IPOPT's
own: `STATUS_CONSTRAINT_TOL` (101 ``Constraint_Tol_Not_Met``: IPOPT succeeded but the
violation exceeds ``constraint_tol``), `STATUS_BOUND_VIOLATION` (102),
`STATUS_RESIMULATION` (103, above), `STATUS_EXCEPTION` (-200 ``Exception``: an evaluation
error inside CasADi). `ocp.rest_solution` returns status 0 with ``solver_status``
``'Rest_Solution'``.

Reuse: build once, solve many
-----------------------------
The symbolic NLP and its derivatives belong to the problem's *structure*
(`ocp.assembly`): model, cost and constraint functions (by content), transcription, number
of intervals, which parameters are free, a free or fixed horizon, the kind of attitude
target. Everything numeric -- boundary values and bounds, fixed parameter values, a fixed
horizon, the target attitude, the mesh spacing, the scale factors -- is a bound or an NLP
parameter. So a structure and its IPOPT solver are built once and kept in `dynamics.cache`
(`ocp.cached`): multistart, refinement rounds that keep the number of intervals, and a slew
to another target with the same inertia and torque bounds build nothing. Construction takes
derivatives of one interval only (0.14 s at N = 800 for a rigid-body slew, against 3.6 s
for the expanded whole NLP of earlier versions; measured on a 2-core machine);
`Solution.build_time` and `Solution.solve_time` record both parts.

Warm starts: a ``guess`` that is a `Solution` of the *same* NLP (same structure, numbers and
mesh) starts IPOPT from its primal and dual values (``lam_x``, ``lam_g``) with IPOPT's
warm-start options (`WARM_START_OPTIONS`); a Solution of another problem gives primal
values (`ocp.guess`).

``expand=True`` (the default) builds the interval functions in SX when the model and the
cost and constraint functions allow it (faster evaluation); ``expand=False`` keeps them in
MX. `dynamics.clear_caches` drops every built structure and solver.

Threads: `solve` may run in several threads at once, on the same problem. A cached IPOPT
solver (with its NLP) is lent to one solve at a time (`ocp.cached.checkout`): a second
concurrent solve of the same structure builds its own instance once, and both are reused
afterwards. Every ``casadi.nlpsol`` construction holds `dynamics.cache.construction_lock`.
"""
from __future__ import annotations

import dataclasses
import hashlib
import time
from typing import Mapping

import numpy as np

from appdyn.config import param
from appdyn.dynamics.cache import construction_lock
from appdyn.dynamics.interrupts import check_interrupt, interruptible

from .backoff import BACKOFF_MAX, BACKOFF_TRIES, MARGIN, backoff_note, overshoots, tightened
from .cached import checkout
from .checks import (STATUS_BOUND_VIOLATION, STATUS_RESIMULATION, bound_excess, check_verify_tol,
                     resimulation_mismatch)
from .guess import initial_guess
from .ipopt_options import IPOPT_MAX_ITER, check_ipopt_options
from .mesh import Mesh, check_N
from .nlp import Discretization
from .problem import Problem
from .progress import LOGGER, IterationCallback, Progress, iteration_sink
from .scaling import auto_scaling
from .solution import Solution
from .status import STATUS_CONSTRAINT_TOL, STATUS_EXCEPTION, status_code
from .transcription import get_transcription

__all__ = ["solve", "Progress", "DEFAULT_CONSTRAINT_TOL", "STATUS_CONSTRAINT_TOL", "STATUS_EXCEPTION",
           "STATUS_BOUND_VIOLATION", "STATUS_RESIMULATION", "check_constraint_tol", "verified", "make_solution",
           "NlpOutcome", "WARM_START_OPTIONS", "run_ipopt",
           "read_result", "default_mesh", "solver_ipopt_options", "nlp_numbers", "back_off"]

_SUCCESS = ("Solve_Succeeded",)
_ACCEPTABLE = "Solved_To_Acceptable_Level"
_RESOLVE_ITER = 200  # iteration budget of the warm re-solve after an acceptable-level stop
DEFAULT_CONSTRAINT_TOL = 1e-6
#: IPOPT options of a warm start with primal and dual values (`Solution` of the same structure
#: on the same mesh as ``guess``); options the caller passes take precedence.
WARM_START_OPTIONS = {"warm_start_init_point": "yes", "warm_start_bound_push": 1e-9,
                      "warm_start_bound_frac": 1e-9, "warm_start_slack_bound_push": 1e-9,
                      "warm_start_slack_bound_frac": 1e-9, "warm_start_mult_bound_push": 1e-9,
                      "mu_init": 1e-6}


def default_mesh(N, mesh) -> Mesh:
    """The mesh of a solve: ``mesh`` (a `Mesh` or its breaks) or ``N`` uniform intervals
    (20 when both are None); ValueError naming ``N`` when the two disagree.

    Examples
    --------
    >>> from appdyn.ocp.solve import default_mesh
    >>> default_mesh(4, None).N, default_mesh(None, None).N
    (4, 20)
    """
    if mesh is None:
        return Mesh.uniform(param("ocp.N", N))
    m = mesh if isinstance(mesh, Mesh) else Mesh(mesh)
    if N is not None and check_N(N) != m.N:
        raise ValueError(f"`N` = {N} conflicts with `mesh`, which has {m.N} intervals")
    return m


def solver_ipopt_options(ipopt_options, constraint_tol: float) -> dict:
    """IPOPT's options of a solve: silent, ``constr_viol_tol = constraint_tol``, then the
    user's ``ipopt_options`` (checked by `ocp.ipopt_options.check_ipopt_options`).

    Examples
    --------
    >>> from appdyn.ocp.solve import solver_ipopt_options
    >>> solver_ipopt_options({"max_iter": 5}, 1e-6)["max_iter"]
    5
    """
    opts = {"print_level": 0, "sb": "yes", "constr_viol_tol": constraint_tol}
    opts.update(check_ipopt_options(ipopt_options))
    return opts


def check_constraint_tol(constraint_tol) -> float:
    if constraint_tol is None:
        return DEFAULT_CONSTRAINT_TOL
    if (isinstance(constraint_tol, (bool, np.bool_))
            or not isinstance(constraint_tol, (int, float, np.integer, np.floating))
            or not (0 < constraint_tol < np.inf)):
        raise ValueError(f"`constraint_tol` must be a finite number > 0, got {constraint_tol!r}")
    return float(constraint_tol)


def _message(status: str, iterations: int) -> str:
    text = {
        "Solve_Succeeded": "optimal solution found",
        "Solved_To_Acceptable_Level": ("stopped at IPOPT's acceptable level (tol not met, acceptable_tol "
                                       "met; constraints may be violated up to 1e-2): not a verified "
                                       "solution"),
        "Infeasible_Problem_Detected": "IPOPT converged to a point of local infeasibility: the problem may be infeasible",
        "Maximum_Iterations_Exceeded": "IPOPT reached max_iter",
        "Restoration_Failed": "IPOPT's feasibility restoration failed",
        "Search_Direction_Becomes_Too_Small": "IPOPT's search direction became too small",
        "Diverging_Iterates": "IPOPT's iterates diverged",
        "Maximum_CpuTime_Exceeded": "IPOPT reached max_cpu_time",
        "Maximum_WallTime_Exceeded": "IPOPT reached max_wall_time",
        "Invalid_Number_Detected": "the NLP functions returned NaN or Inf",
        "Error_In_Step_Computation": "IPOPT could not compute a step",
    }.get(status, "see IPOPT's documentation of this return status")
    return f"IPOPT {status} after {iterations} iterations: {text}"


def _default_guess_hint(problem: Problem, node_guess) -> str:
    """The sentence added to the message of a failed solve from the default guess."""
    if node_guess.source:  # a free T chosen by simulating the default control (ocp.guess)
        what = node_guess.source
    else:
        horizon = f", T = {node_guess.T:g} s for the free horizon" if problem.free_time else ""
        what = f"states by linear/SLERP interpolation of the boundary values, controls at zero{horizon}"
    return (f" The default initial guess ({what}) may be the cause: pass a better one as `guess=`, "
            f"a mapping with 't', 'x', 'u', 'T' (see `ocp.guess`) or a previous Solution.")


@interruptible
def solve(problem: Problem, *, transcription="radau", N: int | None = None, degree: int | None = None,
          mesh=None, guess=None, scale: Mapping | None = None, verbose=False,
          progress=None, ipopt_options: Mapping | None = None, expand: bool = True,
          constraint_tol: float | None = None, codegen: bool = False, control: str | None = None,
          verify: bool = True, verify_tol: float | None = None,
          bound_tol: float | None = None, backoff: bool = True) -> Solution:
    """Solve ``problem`` by direct collocation and IPOPT.

    Parameters
    ----------
    problem : Problem
    transcription : {'radau', 'trapezoid', 'hermite-simpson', 'hermite-simpson-compressed'} or Transcription
        The discretization (see `ocp.transcription`).
    N : int, optional
        Number of uniform mesh intervals (default 20). Mutually exclusive with a ``mesh`` of
        another size.
    degree : int, optional
        Radau collocation degree (default 3); only with the Radau transcriptions.
    control : {'polynomial', 'linear', 'constant'}, optional
        The control interpolant (`ocp.transcription`, `get_transcription`); default the
        transcription's own (``'polynomial'`` for ``'radau'``: degree ``d - 1`` through the
        collocation points, which can overshoot the bounds between them on bang-bang and
        singular arcs). ``'linear'`` (continuous, piecewise linear: `RadauLinearControl`)
        and ``'constant'`` (one value per interval: `RadauConstantControl`) stay within box
        bounds. `sample`, `propagate` and everything derived use exactly this interpolant.
    mesh : Mesh or array_like, shape (N + 1,), optional
        Interval breakpoints in normalized time, 0 to 1 (non-uniform meshes, refinement).
    guess : None, Solution or mapping, optional
        Initial guess (see `ocp.guess`): default linear/SLERP between boundary values, a
        previous Solution (warm start, any transcription or mesh; primal and dual values
        when it solved the same NLP), or a mapping with ``'t'``,
        ``'x'``, ``'u'``, ``'T'``, ``'p'`` (states and controls by name allowed). A free
        ``T`` without a guess is chosen by simulating the default control (`ocp.guess`). A
        failed solve from the default guess says in its message that the guess may be the
        cause.
    scale : mapping of str to float, optional
        Scale overrides by state/control/parameter name, ``'T'``, ``'objective'``,
        ``'q_final'`` (see `ocp.scaling`).
    verbose : bool or callable, optional
        ``False`` (default) prints nothing. ``True`` prints one line per IPOPT iteration
        (iteration, scaled objective, largest scaled constraint violation) to
        ``sys.stderr`` as it runs; a callable is taken as ``progress``.
    progress : callable, optional
        Receives a `Progress` per IPOPT iteration. Independently, every solve logs one INFO
        record (and, when enabled, one DEBUG record per iteration) to the logger
        ``"appdyn.ocp"`` (`ocp.progress`).
    ipopt_options : mapping, optional
        IPOPT options (``{'tol': 1e-10, 'max_iter': 500, 'print_level': 5}``), with or
        without the ``'ipopt.'`` prefix, checked against the installed IPOPT's option list
        before the solver is built (`ocp.ipopt_options`). Defaults: ``print_level 0``,
        ``constr_viol_tol = constraint_tol``, IPOPT's own otherwise (``tol = 1e-8``; note
        ``bound_relax_factor = 1e-8``: IPOPT relaxes every bound by 1e-8 relative, which
        moves a bound-limited optimum by that much — pass ``{'bound_relax_factor': 0}`` for
        bound-exact solutions).
    expand : bool, optional
        Build the per-interval functions in SX (default; faster evaluation), falling back
        to MX when a function cannot be expanded (e.g. it holds an integrator);
        ``expand=False`` keeps them in MX (module docstring).
    codegen : bool, optional
        Compile the interval functions and their derivatives to C once per structure (kept
        in the cache with it): for solvers that will be reused many times on models whose
        evaluation dominates an iteration. ``False`` (default) when IPOPT's own linear
        algebra dominates, as on the slews of `problems.slew` (module docstring).
    constraint_tol : float, optional
        Largest `Solution.constraint_violation` (NLP units, see the module docstring) and
        largest `Solution.bound_violation` (units of the variables' scales) of a successful
        result; default `DEFAULT_CONSTRAINT_TOL` = 1e-6.
    verify : bool, optional
        Re-simulate the returned control (CVODES) and require agreement with the
        collocation for a success (default ``True``; module docstring). ``False`` skips it
        (a driver that verifies by its own criterion, or a deliberately coarse solve); the
        bound check stays.
    verify_tol : float, optional
        Largest scaled re-simulation error of a success (module docstring); default
        `ocp.checks.default_verify_tol` (3e-3; 0.1 for the trapezoid).
    bound_tol : float, optional
        Largest `Solution.bound_violation` of a success; default ``constraint_tol``.
        ``math.inf`` skips the check: for a seed that another solve will replace (the
        time-optimal slews solve a polynomial-control seed for the switch detection of
        their polish, then return a solution within the bounds).
    backoff : bool
        When the dense output leaves a bound (or an inequality path constraint) between the
        nodes by more than ``bound_tol`` but at most `ocp.backoff.BACKOFF_MAX` of its scale --
        the interpolant bulging past an *active* bound, e.g. a keep-out cone crossed by 5e-4
        of its scale between the collocation points of a piecewise-constant torque -- re-solve
        on the same mesh with that bound moved in by twice the overshoot (up to 3 times),
        graded against the original bounds (`back_off`; default True). The result's
        `Solution.backoff` records the margins and the objective without them; its message
        says so. ``False``: the ``'Bound_Violation'`` failure.

    Returns
    -------
    Solution
        ``success=True`` only when verified (module docstring). A non-converged IPOPT run
        returns ``success=False`` with IPOPT's ``status``; it does not raise.

    Raises
    ------
    TypeError
        If ``problem`` is not a `Problem`.
    ValueError
        Naming the argument: unknown ``transcription``, bad ``N``/``degree``/``mesh``,
        ``guess``, ``scale``, ``constraint_tol``, or an ``ipopt_options`` key that is not an
        IPOPT option (with the closest name) or a value of the wrong type or range.

    Examples
    --------
    Minimum energy of the double integrator over a unit distance in T = 1 s (Bryson & Ho:
    u = 6 - 12 t, J = 6):

    >>> from appdyn import ocp
    >>> from appdyn.ocp.examples import min_energy
    >>> energy = min_energy()  # x'' = u from rest at 0 to rest at 1 in T = 1 s
    >>> sol = ocp.solve(energy, N=10)
    >>> sol.success, sol.status, round(sol.cost, 6)
    (True, 0, 6.0)
    """
    if not isinstance(problem, Problem):
        raise TypeError(f"`problem` must be an ocp.Problem, got {type(problem).__name__}")
    tr = get_transcription(transcription, degree=degree, control=control)
    m = default_mesh(N, mesh)
    sink = iteration_sink(verbose, progress)
    for name, flag in (("expand", expand), ("codegen", codegen), ("verify", verify),
                       ("backoff", backoff)):
        if flag not in (True, False):
            raise ValueError(f"`{name}` must be True or False, got {flag!r}")
    ctol = check_constraint_tol(constraint_tol)
    vtol = check_verify_tol(verify_tol, tr) if verify else None
    btol = ctol if bound_tol is None else _check_bound_tol(bound_tol)
    opts = solver_ipopt_options(ipopt_options, ctol)

    t_build = time.perf_counter()
    node_guess = initial_guess(problem, tr, m, guess=guess)
    scaling = auto_scaling(problem, node_guess, overrides=scale)
    disc = Discretization(problem, tr, m, scaling, expand, codegen)  # structure from the cache
    warm = _warm_point(guess, disc)
    if warm is not None:
        opts = {**WARM_START_OPTIONS, **opts, **check_ipopt_options(ipopt_options)}
    nlp_opts = {"ipopt": opts, "print_time": False, "error_on_fail": False}
    if sink is None:
        # one built solver per structure and options, lent to this call alone (a pool:
        # threads never share a running IPOPT)
        with checkout("nlpsol", (disc.key, repr(sorted(opts.items()))),
                      lambda: _build_solver(disc, nlp_opts, None), keepalive=disc.structure) as built:
            sol = _solve_built(problem, tr, m, node_guess, opts, ctol, disc, *built, t_build,
                               default_guess=guess is None, warm=warm)
    else:
        sol = _solve_built(problem, tr, m, node_guess, opts, ctol, disc,
                           *_build_solver(disc, nlp_opts, sink), t_build,
                           default_guess=guess is None, warm=warm)
    out = verified(sol, btol, vtol, objective_scale=disc.scaling.objective)
    if backoff and out.status == STATUS_BOUND_VIOLATION:
        kw = dict(scale=scale, verbose=verbose, progress=progress, ipopt_options=ipopt_options,
                  expand=expand, constraint_tol=constraint_tol, codegen=codegen, verify=verify,
                  verify_tol=verify_tol, bound_tol=bound_tol)
        backed = back_off(problem, out, kw, transcription=tr)
        if backed is not None:
            return _replaced(backed, message=f"{backed.message}; {backoff_note(out, backed)}")
    return out


def back_off(problem, sol, solve_kwargs: dict, *, transcription, verbose=False):
    """The solution of ``problem`` on ``sol``'s mesh with the dense output within the bounds,
    or ``None`` when backing off does not apply or does not succeed.

    Parameters
    ----------
    problem : ocp.Problem
        The user's problem: the result is graded against its bounds.
    sol : ocp.Solution
        A solution of ``problem`` whose only fault is `STATUS_BOUND_VIOLATION`: states,
        controls or path-constraint rows past their bounds by at most `BACKOFF_MAX` of
        their scale each (in all, over the re-solves).
    solve_kwargs : dict
        The options of `ocp.solve` used for ``sol`` (``bound_tol``/``constraint_tol`` give
        the grading tolerance).
    transcription : ocp.Transcription

    Returns
    -------
    Solution or None
        Verified against ``problem``'s bounds (its ``problem`` is ``problem``); its
        ``backoff`` is the record ``{'margins': {name: (lower, upper)}, 'tries',
        'overshoot', 'cost_without'}``: the bounds moved in [their units; path rows by
        their names, `ocp.checks.BoundViolation`], the re-solves, the overshoot backed off
        [scaled] and the objective before.
    """
    if sol.status != STATUS_BOUND_VIOLATION or not np.isfinite(sol.cost):
        return None
    kw = dict(solve_kwargs, backoff=False)
    verbose = kw.pop("verbose", verbose)
    btol = check_constraint_tol(kw.get("constraint_tol"))
    btol = btol if kw.pop("bound_tol", None) is None else float(solve_kwargs["bound_tol"])
    bounds = bound_excess(sol)[0]
    margin = np.zeros_like(bounds)
    current = sol
    for tries in range(1, BACKOFF_TRIES + 1):
        found = overshoots(current, btol)
        if found is None:
            return None
        over, scale, names = found
        margin = margin + MARGIN * over
        if (np.any(margin > MARGIN * BACKOFF_MAX * scale)
                or np.any(bounds[0] + margin[0] > bounds[1] - margin[1])):
            return None
        try:
            shifted = tightened(problem, np.stack([bounds[0] + margin[0], bounds[1] - margin[1]]),
                                 names)
        except ValueError:  # a fixed boundary value on the bound: no room to back off
            return None
        # the tightened problem's own bound check is the original's, done below
        trial = solve(shifted, transcription=transcription, mesh=sol.mesh, guess=current,
                      verbose=verbose, bound_tol=np.inf, **kw)
        if not trial.success:
            return None
        # the re-simulation verified by the solve is the same (same model and trajectory);
        # the bounds are graded again against the original problem
        graded = verified(_replaced(trial, ("propagation",), problem=problem), btol, None)
        if graded.success:
            moved = {names[i]: (float(margin[0, i]), float(margin[1, i]))
                     for i in np.flatnonzero(np.any(margin > 0, axis=0))}
            return _replaced(graded, backoff={"margins": moved, "tries": tries,
                                              "overshoot": float(sol.bound_violation.max),
                                              "cost_without": float(sol.cost)})
        current = graded
    return None


def _replaced(solution: Solution, carried=("bound_violation", "propagation"),
              **changes) -> Solution:
    """``dataclasses.replace(solution, **changes)`` with the cached checks named in
    ``carried`` (`Solution.bound_violation`, `Solution.propagation`) carried over when
    computed: for changes that leave what they measure as it was."""
    out = dataclasses.replace(solution, **changes)
    for name in carried:
        if name in vars(solution):
            vars(out)[name] = vars(solution)[name]
    return out


def _check_bound_tol(bound_tol) -> float:
    if (isinstance(bound_tol, (bool, np.bool_))
            or not isinstance(bound_tol, (int, float, np.integer, np.floating))
            or not bound_tol > 0 or np.isnan(bound_tol)):
        raise ValueError(f"`bound_tol` must be a number > 0 (inf allowed), got {bound_tol!r}")
    return float(bound_tol)


def verified(solution: Solution, constraint_tol: float, verify_tol: float | None,
             *, objective_scale: float = 1.0) -> Solution:
    """``solution`` if it is no success or passes the checks 3 and 4 of the module docstring
    (bounds of the dense output within ``constraint_tol`` (the bound tolerance, ``inf``
    skips it); re-simulation within
    ``verify_tol``, skipped when it is ``None``), else a copy with ``success=False``,
    status `STATUS_BOUND_VIOLATION` or `STATUS_RESIMULATION` and the reason appended to the
    message. For `solve` and the drivers that build solutions themselves."""
    if not solution.success:
        return solution
    bv = solution.bound_violation if np.isfinite(constraint_tol) else None
    if bv is not None and not bv.max <= constraint_tol:
        why = (f"but {bv.describe(controls=solution.problem.model.controls)}; exceeds "
               f"constraint_tol {constraint_tol:g}: not verified")
        return _failed(solution, STATUS_BOUND_VIOLATION, why)
    if verify_tol is not None:
        why = resimulation_mismatch(solution, verify_tol, objective_scale=objective_scale)
        if why is not None:
            return _failed(solution, STATUS_RESIMULATION, f"but {why}")
    return solution


def _failed(solution: Solution, status: int, why: str) -> Solution:
    """A copy of ``solution`` with ``success=False``, ``status`` and ``why`` appended to the
    message; its cached checks (bounds, re-simulation) carried over."""
    out = _replaced(solution, success=False, status=status, message=f"{solution.message}; {why}")
    LOGGER.info("solve %s: %s", solution.problem.name, why)
    return out


def nlp_numbers(disc, *, bounds: bool = True) -> bytes:
    """Digest of everything numeric in the NLP of ``disc`` (an `ocp.nlp.Discretization`)
    besides its structure: the parameter values, the mesh and (``bounds=True``) the variable
    and constraint bounds (physical); 16 bytes. Two NLPs with equal structure keys and equal
    digests are the same NLP (a warm start may reuse primal and dual values)."""
    sw, sg, _ = disc.scales()
    P = disc.structure.params.split(disc.P)  # not the scale factors: they depend on the guess
    parts = (P["pval"], P["Tfix"], P["qf"], P["frac"])
    if bounds:
        parts += (disc.lbx * sw, disc.ubx * sw, disc.lbg * sg, disc.ubg * sg)
    return hashlib.blake2b(b"".join(np.asarray(a, dtype=float).tobytes() for a in parts),
                           digest_size=16).digest()


def _warm_point(guess, disc) -> dict | None:
    """Primal and dual start values from a `Solution` of the same NLP (`Solution.nlp_point`:
    same structure, parameter values, bounds and mesh), converted to this NLP's scaling;
    ``None`` otherwise.

    Only the same NLP: started from the solution of a *different* problem of the same
    structure (a slew to a nearby target), IPOPT's warm start took more iterations than a
    cold start from the same primal values (55 against 24 on a time-optimal slew at
    N = 40), so those get the primal values only (`ocp.guess`)."""
    point = getattr(guess, "nlp_point", None)
    if not point or point.get("key") != disc.key or point.get("numbers") != nlp_numbers(disc):
        return None
    sw, sg, dJ = disc.scales()
    x = np.clip(point["x_phys"] / sw, disc.lbx, disc.ubx)
    return {"x0": x, "lam_x0": point["lam_x_phys"] * sw / dJ, "lam_g0": point["lam_g_phys"] * sg / dJ}


def _solve_built(problem, tr, m, node_guess, opts, ctol, disc, solver, nlp_opts, t_build, *,
                 default_guess=False, warm=None):
    """IPOPT on the transcribed NLP ``disc`` with ``solver`` (used by this call alone);
    ``default_guess``: ``node_guess`` is the default one (a failure's message says so);
    ``warm``: primal and dual start values (`_warm_point`)."""
    check_interrupt()  # a Ctrl-C during the build (C++ construction cannot be interrupted)
    start = warm if warm is not None else {"x0": disc.pack(node_guess)}
    w0 = start["x0"]
    build_time = time.perf_counter() - t_build

    t_solve = time.perf_counter()
    bounds = dict(lbx=disc.lbx, ubx=disc.ubx, lbg=disc.lbg, ubg=disc.ubg, p=disc.P)
    res, error, status, iterations, note, t_re = run_ipopt(
        solver, start, bounds, opts, lambda again: disc.structure.nlpsol(
            "ocp_resolve", {**nlp_opts, "ipopt": again}))
    build_time += t_re
    solve_time = time.perf_counter() - t_solve - t_re
    w, lam_g, lam_x, g, success, status, solver_status, message = read_result(
        res, error, status, iterations, note, w0, disc.g.size, disc.violation, ctol)
    if not success and default_guess:
        message += _default_guess_hint(problem, node_guess)
    LOGGER.info("solve %s (%s, N=%d): %s; %.3g s", problem.name, tr.name, m.N, message, solve_time)
    return make_solution(problem, tr, m, disc, NlpOutcome(
        w=w, lam_g=lam_g, g=g, success=success, status=status, message=message,
        iterations=iterations, solve_time=solve_time, build_time=build_time, lam_x=lam_x,
        solver_status=solver_status))


def run_ipopt(solver, start: dict, bounds: dict, opts: dict, resolver):
    """One IPOPT solve, and the warm re-solve an acceptable-level stop gets (module
    docstring). ``resolver(options)`` builds the re-solving IPOPT on the same NLP.

    Returns ``(result or None, error, status, iterations, note, build_time)``: ``note`` is
    the sentence the message gets about a re-solve, ``build_time`` [s] the re-solver's
    construction time."""
    res, error, status, iterations = _run(solver, dict(**start, **bounds))
    note, t_build = "", 0.0
    if res is not None and status == _ACCEPTABLE:
        # not verified: one warm re-solve from the acceptable point, acceptable exit disabled
        budget = min(max(int(opts.get("max_iter", IPOPT_MAX_ITER)) - iterations, 0), _RESOLVE_ITER)
        if budget > 0:
            t_re = time.perf_counter()
            again = {**opts, "acceptable_iter": 0, "max_iter": budget,
                     "warm_start_init_point": "yes", "mu_init": 1e-9}
            with construction_lock():
                re_solver = resolver(again)
            t_build = time.perf_counter() - t_re
            res2, error2, status2, it2 = _run(re_solver, dict(
                x0=res["x"], lam_x0=res["lam_x"], lam_g0=res["lam_g"], **bounds))
            if res2 is not None and status2 in _SUCCESS:
                note = (f" (after {_ACCEPTABLE} in {iterations} iterations, a warm re-solve "
                        f"reached {status2} in {it2} more)")
                res, status = res2, status2
            else:
                note = (f"; a warm re-solve without the acceptable-level exit ended with "
                        f"{status2} after {it2} iterations")
            iterations += it2
    return res, error, status, iterations, note, t_build


def read_result(res, error, status: str, iterations: int, note: str, w0, n_g: int,
                violation, ctol: float):
    """``(w, lam_g, lam_x, g, success, status, solver_status, message)`` of a `run_ipopt`
    result (``status`` an int of `ocp.status`, ``solver_status`` IPOPT's text ``status``):
    success only for ``Solve_Succeeded`` with ``violation(g, w) <= ctol`` (module
    docstring); the start ``w0`` and NaN constraints when IPOPT stopped by an error."""
    if res is None:
        status = status if status != "Unknown" else "Exception"
        return (np.asarray(w0, dtype=float), np.zeros(n_g), np.zeros(np.size(w0)),
                np.full(n_g, np.nan), False, status_code(status), status,
                f"IPOPT stopped by an error: {error}")
    w = np.asarray(res["x"]).reshape(-1)
    lam_g = np.asarray(res["lam_g"]).reshape(-1)
    lam_x = np.asarray(res["lam_x"]).reshape(-1)
    g = np.asarray(res["g"]).reshape(-1)
    success = status in _SUCCESS
    message = _message(status, iterations) + note
    viol = violation(g, w)
    if success and not viol <= ctol:
        success = False
        message = (f"{message}; but the constraint violation {viol:.3g} exceeds "
                   f"constraint_tol {ctol:g}: not verified")
        return w, lam_g, lam_x, g, False, STATUS_CONSTRAINT_TOL, status, message
    return w, lam_g, lam_x, g, success, status_code(status), status, message


def _build_solver(disc, nlp_opts, sink):
    """``(IPOPT solver, the nlpsol options used)`` on the structure of ``disc``. Holds
    `dynamics.cache.construction_lock` (casadi construction is not thread-safe)."""
    nlp_opts = dict(nlp_opts)
    # always attached: stops IPOPT at the next iteration after a (deferred) Ctrl-C; the
    # options dict returned with the solver keeps the Python callback alive
    nlp_opts["iteration_callback"] = IterationCallback(disc.w.size, disc.g.size,
                                                       disc.violation if sink else None, sink)
    with construction_lock():
        return disc.structure.nlpsol("ocp", nlp_opts), nlp_opts


def _run(solver, args):
    """``(result or None, error, status, iterations)`` of one IPOPT call; raises only
    ``KeyboardInterrupt`` (a Ctrl-C deferred during the call stops IPOPT at its next
    iteration through the `IterationCallback`, and is raised here)."""
    error = None
    try:
        res = solver(**args)
    except RuntimeError as exc:  # an evaluation error inside CasADi: report, do not raise
        res, error = None, exc
    check_interrupt()
    stats = solver.stats()
    return res, error, str(stats.get("return_status", "Unknown")), int(stats.get("iter_count", 0))


@dataclasses.dataclass(frozen=True)
class NlpOutcome:
    """What one NLP solve left (an IPOPT run, or the rest point of `ocp.rest_solution`): the
    input of `make_solution`, carried as one object instead of a long positional list.

    Attributes
    ----------
    w : numpy.ndarray
        The scaled NLP point, ``(n_w,)``.
    lam_g : numpy.ndarray
        Constraint multipliers of the scaled NLP, ``(n_g,)``.
    g : numpy.ndarray
        Scaled constraint values at ``w``, ``(n_g,)`` (NaN after an evaluation error).
    success : bool
        Whether the solve met its tests so far.
    status : int
        The status (a code of `ocp.status`).
    message : str
        What happened, with the remedy on a failure.
    iterations : int
        IPOPT iterations (0: no NLP solved).
    solve_time, build_time : float
        Seconds in IPOPT and in building the NLP and solver.
    lam_x : numpy.ndarray or None
        Bound multipliers ``(n_w,)``; with them the `Solution` keeps its NLP point for a
        warm start.
    solver_status : str
        IPOPT's return status as text (``'Rest_Solution'`` when no NLP was solved).

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.ocp.solve import NlpOutcome
    >>> out = NlpOutcome(w=np.zeros(3), lam_g=np.zeros(1), g=np.zeros(1), success=True,
    ...                  status=0, message="ok", iterations=5,
    ...                  solve_time=0.01, build_time=0.1)
    >>> out.iterations, out.lam_x is None
    (5, True)
    """

    w: np.ndarray
    lam_g: np.ndarray
    g: np.ndarray
    success: bool
    status: int
    message: str
    iterations: int
    solve_time: float
    build_time: float
    lam_x: np.ndarray | None = None
    solver_status: str = "Solve_Succeeded"


def make_solution(problem, tr, mesh, disc, outcome: NlpOutcome) -> Solution:
    """The `Solution` of ``problem`` transcribed by ``tr`` on ``mesh`` (NLP ``disc``) at the
    scaled point of ``outcome`` (an `NlpOutcome`)."""
    w, lam_g, g, lam_x = outcome.w, outcome.lam_g, outcome.g, outcome.lam_x
    phys = disc.unpack(w)
    viol = disc.violation(g, w) if np.all(np.isfinite(g)) else float("nan")
    point = None
    if lam_x is not None:
        sw, sg, dJ = disc.scales()
        point = {"key": disc.key, "numbers": nlp_numbers(disc), "x_phys": w * sw,
                 "lam_x_phys": lam_x * dJ / sw, "lam_g_phys": np.asarray(lam_g) * dJ / sg}
    return Solution.from_arrays(
        problem, tr, mesh, phys["X"], phys["U"], phys["p"], phys["T"], cost=disc.cost(w),
        success=outcome.success, status=outcome.status, message=outcome.message,
        iterations=outcome.iterations, solve_time=outcome.solve_time,
        build_time=outcome.build_time, constraint_violation=viol,
        multipliers=disc.multipliers(lam_g), nlp_point=point,
        solver_status=str(outcome.solver_status))
