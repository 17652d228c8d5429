"""The maneuvers: `time_optimal`, `min_effort`, and `verify` (the re-simulation grade)."""
from __future__ import annotations

import math
import time
import warnings
from typing import Mapping

import casadi as ca
import numpy as np

from appdyn.config import param
from appdyn.ocp import (CONTROLS, DEFAULT_CONSTRAINT_TOL, STATUS_BOUND_VIOLATION, STATUS_RESIMULATION,
                 Problem, Solution, annotate, bang_arcs, polish_switches, refine, rest_solution, solve,
                 solve_multistart)
from appdyn.ocp.refine.arcs import IDLE_TOL
from appdyn.ocp.status import STATUS_INFEASIBLE
from appdyn.ocp.refine.result import WORSE_SLACK
from appdyn.ocp.backoff import BACKOFF_MAX
from appdyn.ocp.solve import verified
from appdyn.ocp.ipopt_options import IPOPT_TOL, iteration_budget
from appdyn.dynamics.validate import integer
from appdyn.dynamics.interrupts import interruptible
from appdyn.ocp.progress import stage_sink

from .problem import (attitude_blocks, attitude_guess, inertia_of, is_rest_to_rest, rough_time, seeded_guesses,
                      slew_angle, slew_problem)
from .report import polish_text
from .targets import (ARCSEC, MIN_REFINE_TOL, POINTING_TOL, RATE_TOL, STATUS_POINTING,
                      STATUS_REFINE, check_tol)

__all__ = ["time_optimal", "min_effort", "verify", "bounded", "DEFAULT_STARTS_TIME",
           "DEFAULT_STARTS_EFFORT", "POLISH_ITER_FACTOR", "POLISH_MIN_ITER", "SEED_OPTIONS",
           "RACE_N", "RACE_AGREE",
           "RACE_IPOPT", "BOUNDED_ITER_FACTOR", "BOUNDED_MIN_ITER", "START_BUDGET",
           "BOUNDED_TOL_FACTOR", "minimum_time_text", "restarted",
           "with_minimum_time"]

DEFAULT_STARTS_TIME = 3  # seeded starts of time_optimal without a user guess
DEFAULT_STARTS_EFFORT = 4  # seeded starts of min_effort with a keep-out cone


def verify(solution: Solution, *, pointing_tol: float = POINTING_TOL, rate_tol: float = RATE_TOL):
    """Re-simulate a slew solution and grade it (see the module docstring).

    Parameters
    ----------
    solution : ocp.Solution
        A solution of a `slew_problem`.
    pointing_tol : float [rad]
        Largest accepted `ocp.Solution.pointing_error` (default 1e-6).
    rate_tol : float [rad/s]
        Largest accepted final rate error, ``max_i |w_sim,i(tf) - wf_i|`` (default 1e-6),
        over every final state given after the quaternion (device slews: also the wheel
        speeds [rad/s] or gimbal angles [rad] where their final values are fixed).

    Returns
    -------
    ocp.RefinedSolution
        ``solution`` with ``info['pointing_error']`` [rad], ``info['final_rate_error']``
        [rad/s], ``info['pointing_tol']``, ``info['rate_tol']``; ``success`` stays ``True``
        only if it was and both errors are within their tolerances (else ``status``
        `STATUS_POINTING` and a message with the numbers).

    Raises
    ------
    TypeError
        If ``solution`` is not an `ocp.Solution` or a tolerance is not a number.
    ValueError
        If a tolerance is not a finite number > 0.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.problems import slew
    >>> sol = slew.min_effort(np.eye(3), 2.0, angle=0.1, axis=[1, 0, 0], N=10)
    >>> strict = slew.verify(sol, pointing_tol=1e-15)  # re-simulated, graded again
    >>> strict.success, strict.status
    (False, 106)
    """
    if not isinstance(solution, Solution):
        raise TypeError(f"`solution` must be an ocp.Solution, got {type(solution).__name__}")
    ptol = check_tol("pointing_tol", pointing_tol, POINTING_TOL)
    rtol = check_tol("rate_tol", rate_tol, RATE_TOL)
    perr = solution.pointing_error
    perr = float("nan") if perr is None else perr
    # every fixed final state after the quaternion: body rates, and wheel speeds or gimbal
    # angles of the device slews where their final values are given
    fixed = np.isfinite(np.asarray(solution.problem.x_final, dtype=float))
    fixed[attitude_blocks(solution.problem.model)[0]] = False
    term = solution.terminal_error[fixed]
    rerr = float(np.max(term, initial=0.0)) if np.all(np.isfinite(term)) else float("nan")
    info = {"pointing_error": perr, "final_rate_error": rerr, "pointing_tol": ptol, "rate_tol": rtol}
    if not solution.success:
        return annotate(solution, info)
    if perr <= ptol and rerr <= rtol:
        return annotate(solution, info, message=(
            f"{solution.message}; verified by re-simulation: pointing error "
            f"{perr * ARCSEC:.3g} arcsec, final rate error {rerr:.2g} rad/s"))
    return annotate(solution, info, success=False, status=STATUS_POINTING, message=(
        f"{solution.message}; NOT verified: the re-simulated control ends {perr:.3g} rad "
        f"({perr * ARCSEC:.3g} arcsec) from the target (pointing_tol {ptol:g}) with a final "
        f"rate error {rerr:.3g} rad/s (rate_tol {rtol:g})"))


def _symmetric(guess, problem) -> bool:
    """Whether a torque component of ``guess`` (an `attitude_guess`) is zero throughout
    (within `ocp.refine.arcs.IDLE_TOL` of its bound): the eigenaxis path of a slew about a
    body axis that is a principal axis."""
    u = np.asarray(guess["u"], dtype=float)
    hi = np.asarray(problem.u_bounds[1], dtype=float)[:, None]
    return bool(np.any(np.all(np.abs(u) <= IDLE_TOL * hi, axis=1)))


def _warn_ignored(*, why: str, **given) -> None:
    """A `UserWarning` naming the arguments of ``given`` that are not None: ignored ``why``."""
    names = [f"`{k}`" for k, v in given.items() if v is not None]
    if names:
        warnings.warn(f"{' and '.join(names)} {'is' if len(names) == 1 else 'are'} ignored {why}",
                      stacklevel=3)


def _rest(problem, T, pointing_tol, rate_tol):
    """Zero-angle rest-to-rest slews: the exact answer, no NLP (or None)."""
    if not (is_rest_to_rest(problem) and slew_angle(problem) <= 8 * np.finfo(float).eps):
        return None
    return verify(rest_solution(problem, T=T), pointing_tol=pointing_tol, rate_tol=rate_tol)


def _tiny_scale(problem, T_est):
    """Scale overrides for small rest-to-rest angles: horizon and objective in units of the
    bang-bang time (IPOPT then sees O(1) numbers however small the angle)."""
    if slew_angle(problem) >= 1e-2 or not is_rest_to_rest(problem):
        return None
    d = float(2.0 ** round(math.log2(T_est)))
    return {"T": d, "objective": d}


@interruptible
def time_optimal(inertia, *, angle=None, axis=None, q0=None, qf=None, u_max=1.0,
                 norm_bound=False, w0=None, wf=None, keep_out=None, T_max=None, guess=None,
                 starts=None, seed=None, N=None, transcription="radau", polish=None,
                 verbose=False, ipopt_options=None, pointing_tol=POINTING_TOL,
                 rate_tol=RATE_TOL, control="constant") -> Solution:
    """Minimum-time rigid-body slew under torque bounds.

    The engine of `slew` for this scene; prefer
    ``slew(Scene(RigidHub(inertia), ExternalTorque(u_max=u_max)), objective="time", ...)``.

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2]
    angle : float [rad]
        Rotation from ``q0`` about the body axis ``axis``.
    axis : array_like, shape (3,)
        The rotation axis in the body frame.
    q0, qf : array_like, shape (4,)
        Initial (default identity) and target quaternions
    u_max : float or array_like, shape (3,) [N m]
        Per-axis bound (or the norm bound)
    norm_bound : bool
        ``|u| <= u_max`` instead of per-axis bounds
    w0, wf : array_like, shape (3,) [rad/s]
        End rates (default rest to rest)
    keep_out : KeepOut, optional
    T_max : float [s], optional
        Upper bound on the final time
    guess : None, ocp.Solution or mapping
        A user guess (then a single start is solved). ``None``: multi-start.
    starts : int, optional
        Number of seeded starts without a user guess (eigenaxis +
        tilted; default 3). Ignored, with a warning, when ``guess`` is given. Without a
        ``keep_out`` cone and for ``N`` above `RACE_N` = 10 the starts are raced on
        `RACE_N` intervals, in turn until two converged ones agree on ``T`` to `RACE_AGREE`
        (the rest skipped; ``info['race']``), and only the best goes on: polished at once
        by switch times when bang-bang (``polish`` below; kept when verified and at most
        1e-3 relative slower than its coarse ``T``), else re-solved on ``N`` intervals warm
        from it. An eigenaxis path with an idle torque component (a slew about a body axis
        that is a principal axis: the start stays on the eigenaxis maneuver by symmetry) is
        raced last.
    seed : int, optional
        Seed of the tilt axes (default 0; results are reproducible).
        Ignored, with a warning, when ``guess`` is given.
    N : int, optional
        Intervals of the first solve (default ``appdyn.config`` ``problems.slew_N``, 30)
    transcription : str
        Of the first solve (any of ``ocp.TRANSCRIPTIONS``)
    control : {'constant', 'linear', 'polynomial'}
        The control of the returned solution when the pipeline's own (below) leaves the
        torque bounds between its nodes (`bounded`). The first solve is a *seed*: Radau's
        degree ``d - 1`` control polynomial (``transcription``), whose switch structure the
        polish reads (`SEED_OPTIONS`: its bounds and re-simulation are not checked). On the
        bang-bang and singular arcs of a general inertia that polynomial rings and
        overshoots the bounds (measured: 1.7, 1.6, 1.9 times ``u_max`` on a 90 deg slew, I
        = [[10, 1.2, -0.8], [1.2, 8, 0.5], [-0.8, 0.5, 6]]). The polished results (switch
        times, moving knots) hold a constant torque per arc or interval; where the pipeline
        returns the seed or a refinement of it instead, that is re-solved with this control
        on its mesh, warm (default ``'constant'``, one torque per interval:
        `ocp.RadauConstantControl`; ``'linear'``: `ocp.RadauLinearControl`), and graded
        again; ``'polynomial'`` returns it as it is, a ``'Bound_Violation'`` failure.
        ``'constant'`` rather than ``'linear'`` (measured at N = 30): Bilimoria-Wie
        without polish T = 3.24391 against 3.24729 (optimum 3.24308), its eigenaxis start
        2 sqrt(pi) + 6e-8 against + 2.6e-3 (a switch on a mesh point is exact).
    polish : bool, optional
        Default True where it applies: not with ``norm_bound`` or ``keep_out`` (their
        optimal torques are not bang-bang per axis), where ``polish=True`` is ignored with a
        warning. Polish the switch times (`ocp.polish_switches`, IPOPT ``tol`` 1e-9 unless
        ``ipopt_options`` says otherwise) when the first solution is bang-bang on every axis
        (`ocp.bang_arcs`, read from a few samples before anything is built; an axis whose
        torque is zero throughout, as off the axis of a principal-axis slew, is held at
        zero): the arc durations are solved for directly (``'switch-times'``: a few IPOPT
        iterations, ``T`` exact to about 1e-12 s; 3 iterations on Bilimoria-Wie; should that
        fail, the moving-knot re-solve at Radau degree 5). Each NLP of the polish has an
        iteration budget: `POLISH_ITER_FACTOR` = 10 times the first solution's IPOPT
        iterations, at least `POLISH_MIN_ITER` = 200 (``max_iter`` of ``ipopt_options``
        wins), so the answer does not depend on the machine's load. A first solution that is
        not bang-bang (a
        singular arc) is not polished (the moving-knot re-solve took 6-70 s there, 20-200
        times the first solve, and was rarely kept). The polished result is returned only
        if it is verified and not slower than the first (a switch-time result may be slower
        by 1e-4 relative: the first's fixed mesh can put T below the exact optimum by its
        discretization error); otherwise the first solution. ``info['polish']`` records
        what happened: ``ran``, ``used``, ``why``, ``method``, ``wall_time`` [s], ``budget``
        (IPOPT iterations per NLP), ``T_before``, ``T_polished``, ``T_after`` [s] and
        ``gain`` (``T_before - T_after`` [s] when used, else 0); the message ends with the
        same in words (`polish_text`) and ``info['wall_time']`` is the wall time of the
        whole call. Should
        neither be verified (the first's fixed mesh can smear the switches beyond
        ``pointing_tol``), the first is mesh-refined (`ocp.refine`, tol 1e-6, at most 4
        rounds) and verified again; should that stall too (its error estimates do not
        shrink on the switches of a general inertia), the problem is re-solved once on a
        uniform mesh twice as fine, warm from the first (``info['fallback']``); should that
        miss too (a singular arc: the collocated control rings on every mesh), a
        regularized problem, ``T + REGULARIZATION * 1/2 integral |u / u_max|^2 dt``, is
        refined warm from the first and returned if verified (``info['fallback']`` quotes
        its ``T`` and the unregularized one; ``cost`` is its ``T``).
    verbose : bool
        IPOPT progress lines, to stderr, labelled by stage (``[slew: start 2/3]``,
        ``[polish]``)
    ipopt_options : dict, optional
    pointing_tol : float [rad]
        Largest re-simulated final attitude error of a success
    rate_tol : float [rad/s]
        Largest re-simulated final rate error of a success

    Returns
    -------
    ocp.RefinedSolution
        ``T`` is the optimal time [s]; ``success`` as in the module docstring; ``info``
        records the starts, the polish, ``pointing_error`` [rad] and ``final_rate_error``
        [rad/s]. A zero-angle rest-to-rest slew returns ``T = 0`` at once.

    Examples
    --------
    A 0.1 rad rest-to-rest slew of a unit-inertia body about its third axis, ``|u_i| <= 1``:
    bang-bang, ``T = 2 sqrt(0.1)`` (small N and one start to keep it quick):

    >>> import numpy as np
    >>> from appdyn.problems import slew
    >>> sol = slew.time_optimal(np.eye(3), angle=0.1, axis=[0, 0, 1], N=10, starts=1)
    >>> sol.success, round(sol.T, 6), round(slew.eigenaxis_time(np.eye(3), 0.1, [0, 0, 1]), 6)
    (True, 0.632456, 0.632456)
    """
    N = param("problems.slew_N", N)
    ptol = check_tol("pointing_tol", pointing_tol, POINTING_TOL)
    rtol = check_tol("rate_tol", rate_tol, RATE_TOL)
    problem = slew_problem(inertia, objective="time", angle=angle, axis=axis, q0=q0, qf=qf,
                           u_max=u_max, norm_bound=norm_bound, w0=w0, wf=wf,
                           keep_out=keep_out, T_max=T_max)
    if guess is None:
        starts = integer(DEFAULT_STARTS_TIME if starts is None else starts, "starts", minimum=1)
    else:
        _warn_ignored(starts=starts, seed=seed, why="with a user `guess` (a single start is solved)")
    seed = 0 if seed is None else seed
    if polish and (norm_bound or keep_out is not None):
        _warn_ignored(polish=polish, why="with `norm_bound` or `keep_out` (not bang-bang per axis)")
    polish = True if polish is None else bool(polish)
    rest = _rest(problem, 0.0, ptol, rtol)
    if rest is not None:
        return rest
    q0 = problem.x_initial[attitude_blocks(problem.model)[0]]
    T_est = rough_time(inertia_of(problem.model), q0, problem.q_final,
                        problem.u_bounds[1], floor=1e-14 if is_rest_to_rest(problem) else 1e-3)
    if control not in CONTROLS:
        raise ValueError(f"`control` must be one of {CONTROLS}, got {control!r}")
    opts = dict(transcription=transcription, N=N, verbose=verbose, ipopt_options=ipopt_options,
                scale=_tiny_scale(problem, T_est), **SEED_OPTIONS)
    guesses = None if guess is not None else seeded_guesses(problem, int(starts), seed,
                                                             eigenaxis=keep_out is None)
    start_options = None
    if guesses is not None and keep_out is None:
        # the eigenaxis start: the exact Hessian, at most EIGENAXIS_EXACT iterations (most
        # slews: 15-20), then a limited-memory Hessian (where the exact one creeps along the
        # singular eigenaxis optimum -- Bilimoria-Wie: 126 iterations, the limited-memory one
        # 16), then the exact one without the cap
        tries = [{"ipopt_options": {**EIGENAXIS_EXACT, **(ipopt_options or {})}},
                 {"ipopt_options": {**EIGENAXIS_START, **(ipopt_options or {})}}, {}]
        start_options = [tries] + [{}] * (len(guesses) - 1)
        if len(guesses) >= 3 and _symmetric(guesses[0], problem):
            # the eigenaxis start of a slew whose eigenaxis path leaves torque components
            # idle (a body-axis slew of a principal-axis body, as Bilimoria-Wie's) keeps them
            # idle by symmetry and converges to the eigenaxis maneuver, a local optimum; it
            # goes last, so that two tilted starts that agree end the race before it
            guesses, start_options = guesses[1:] + guesses[:1], start_options[1:] + start_options[:1]
    t_start = time.perf_counter()
    sol = solve_time_optimal(problem, guess, guesses, opts,
                             polish=polish and not norm_bound and keep_out is None,
                             pointing_tol=ptol, rate_tol=rtol, ipopt_options=ipopt_options,
                             verbose=verbose, start_options=start_options,
                             race_N=RACE_N if keep_out is None else None)
    out = bounded(problem, sol, control=control, pointing_tol=ptol, rate_tol=rtol,
                  ipopt_options=ipopt_options, scale=opts["scale"])
    # the whole pipeline's wall time, a bounded re-solve included
    return out if out is sol else annotate(out, {"wall_time": time.perf_counter() - t_start})


#: `ocp.solve` options of the seed of the time-optimal pipeline (the first, polynomial-
#: control solve whose switch structure the polish reads): its dense control may overshoot
#: the bounds, and the pipeline grades by its own re-simulation (`verify`); what is
#: returned is checked again (`bounded`).
SEED_OPTIONS = {"bound_tol": math.inf, "verify": False}


#: Factor on IPOPT's ``tol`` (the user's or IPOPT's 1e-8, the tighter) of `bounded`'s warm
#: re-solve of a small control overshoot, before any change of the control.
BOUNDED_TOL_FACTOR = 1e-2

#: IPOPT iteration budget of `bounded`'s re-solve: this many times the iterations of the
#: solution it starts from, and at least `BOUNDED_MIN_ITER`
BOUNDED_ITER_FACTOR = 10
BOUNDED_MIN_ITER = 200

#: IPOPT iteration budget of the seeded starts after one has converged
#: (`ocp.solve_multistart`'s ``start_budget``): this many times the converged start's
#: iterations, at least `ocp.ipopt_options.BUDGET_MIN_ITER`. A CMG slew's (pyramid, 0.3 rad
#: about z) two other starts ran 1,053 and 3,000 iterations, 117 s, to no solution, where
#: the converged one took 16 (0.18 s).
START_BUDGET = 10


def bounded(problem, solution, *, control="constant", pointing_tol=POINTING_TOL,
            rate_tol=RATE_TOL, ipopt_options=None, scale=None):
    """``solution`` if its dense output keeps the bounds (`ocp.Solution.bound_violation`
    within `ocp.DEFAULT_CONSTRAINT_TOL`) or it is no success; else re-solved with ``control``
    (``'constant'`` or ``'linear'``) on its mesh, warm from it, within
    `BOUNDED_ITER_FACTOR` times its IPOPT iterations (at least `BOUNDED_MIN_ITER`), and
    graded (`verify`; a miss is mesh-refined once more, `ocp.refine` tol 1e-6, 4 rounds).
    A control that overshoots by at most `ocp.backoff.BACKOFF_MAX` of its scale is first
    re-solved warm with its own control on its mesh at IPOPT's ``tol`` times
    `BOUNDED_TOL_FACTOR` (an interior-point iterate a hair inside a bound next to a switch),
    and returned when graded a success.

    Parameters
    ----------
    problem : ocp.Problem
        The slew ``solution`` solves.
    solution : ocp.Solution
    control : {'constant', 'linear', 'polynomial'}
        ``'polynomial'``: no re-solve, the failure at once.
    pointing_tol, rate_tol, ipopt_options, scale
        As in `time_optimal` (``scale``: `ocp.solve` scale overrides).

    Returns
    -------
    ocp.Solution
        The bounded solution if graded a success, else ``solution`` as a
        ``'Bound_Violation'`` failure whose message names the variable, the time and what
        the bounded re-solve gave.

    Raises
    ------
    TypeError
        If ``problem`` is not an `ocp.Problem` or ``solution`` not an `ocp.Solution`.
    ValueError
        If ``control`` is not one of `ocp.CONTROLS`.
    """
    if not isinstance(problem, Problem):
        raise TypeError(f"`problem` must be an ocp.Problem, got {type(problem).__name__}")
    if not isinstance(solution, Solution):
        raise TypeError(f"`solution` must be an ocp.Solution, got {type(solution).__name__}")
    if control not in CONTROLS:
        raise ValueError(f"`control` must be one of {CONTROLS}, got {control!r}")
    sol = solution
    if not sol.success or sol.bound_violation.max <= DEFAULT_CONSTRAINT_TOL:
        return sol
    failed = verified(sol, DEFAULT_CONSTRAINT_TOL, None)
    if control == "polynomial":
        return failed
    kw = dict(ipopt_options=ipopt_options, scale=scale)
    keep = {k: v for k, v in getattr(sol, "info", {}).items()
            if k in ("starts", "best", "race", "polish", "fallback")}
    bv = sol.bound_violation
    why = (f"the {sol.transcription.name} solution (T = {sol.T:.10g} s) leaves the bounds "
           f"between its nodes (`{bv.name}` by {bv.max:.3g} of its scale at t = {bv.time:.6g} "
           f"s)")
    said = f"; {polish_text(keep['polish'])}" if "polish" in keep else ""
    # warm from a converged neighbour: the re-solves of the tests take 8-44 IPOPT iterations;
    # a CMG slew's took 1861 (35 s) to end in Restoration_Failed, so the budget of each
    # re-solve is `BOUNDED_ITER_FACTOR` times the first solve's iterations, at least
    # `BOUNDED_MIN_ITER` (the user's ``max_iter`` wins)
    limited, budget = iteration_budget(ipopt_options, sol.iterations, BOUNDED_ITER_FACTOR,
                                       minimum=BOUNDED_MIN_ITER)
    # a small control overshoot (at most `ocp.backoff.BACKOFF_MAX` of its scale) comes from
    # IPOPT's iterate a hair inside a bound next to a switch and shrinks with the barrier
    # parameter: first a warm re-solve on the same mesh and control at a tighter tol
    # (`BOUNDED_TOL_FACTOR`; `ocp.solve` backs off what overshoot remains). J = E, 1 rad
    # about (1, 1, 0): 2.3e-5 at IPOPT's tol 1e-8 (9.5e-6 after a warm re-solve at 1e-8),
    # 1e-7 after 2 iterations at 1e-10 (0.04 s), where the constant-control re-solve ran out
    # of its 200 iterations (1.9 s, a failure)
    if bv.kind == "control" and bv.max <= BACKOFF_MAX:
        tol = min(float((ipopt_options or {}).get("tol", IPOPT_TOL)), IPOPT_TOL) * BOUNDED_TOL_FACTOR
        tight = solve(problem, transcription=sol.transcription, mesh=sol.mesh, guess=sol,
                      ipopt_options={**limited, "tol": tol}, scale=scale)
        tight = verify(tight, pointing_tol=pointing_tol, rate_tol=rate_tol)
        if tight.success:
            why = f"{why}: re-solved warm on its mesh at IPOPT tol {tol:g}"
            return annotate(tight, {**keep, "bounded": why}, message=f"{tight.message}; {why}{said}")
    again = solve(problem, transcription="radau", control=control, mesh=sol.mesh, guess=sol,
                  ipopt_options=limited, scale=scale)
    again = verify(again, pointing_tol=pointing_tol, rate_tol=rate_tol)
    if not again.success and np.isfinite(again.T) and (
            again.status != STATUS_BOUND_VIOLATION or again.bound_violation.kind != "control"):
        # a state or a path constraint (a keep-out cone) crossed between the collocation
        # points by more than `ocp.solve` backs off: a finer mesh there is the remedy
        # (`ocp.refine` splits those intervals)
        finer = refine(problem, again, tol=1e-6, max_rounds=4, transcription=again.transcription,
                       **kw)
        finer = verify(finer, pointing_tol=pointing_tol, rate_tol=rate_tol)
        again = finer if finer.success else again
    why = f"{why}: re-solved with control={control!r}"
    if again.success:
        return annotate(again, {**keep, "bounded": why}, message=f"{again.message}; {why}{said}")
    why = f"{why} (a budget of {budget} IPOPT iterations; ipopt_options max_iter sets it)"
    return annotate(failed, {"bounded": f"{why}, which failed: {again.message[:300]}"},
                    message=f"{failed.message}; {why}, which failed: {again.message[:300]}")


#: IPOPT options of the first attempt at the eigenaxis start of `time_optimal`: the exact
#: Hessian with an iteration cap (a 2 rad slew about (0.2, 1, 0.5), J = E: 17 iterations,
#: 0.03 s, where the limited-memory attempt ran out of its 20 iterations first).
EIGENAXIS_EXACT = {"max_iter": 25}

#: IPOPT options of the second attempt at the eigenaxis start of `time_optimal` (then the
#: exact Hessian without a cap if it does not converge): Bilimoria-Wie 0.69 s -> 0.41 s (16
#: iterations instead of 126); on 8 test slews the same T (a cap of 50 iterations: slower,
#: the limited-memory start being slower than the exact one on some slews).
EIGENAXIS_START = {"hessian_approximation": "limited-memory", "max_iter": 20}

#: Relative amount by which a switch-time polished T (integrated to ~1e-13) may exceed the
#: fixed-mesh T and still replace it (the fixed mesh's own discretization error, measured
#: up to 2.4e-6 relative on the slews of the tests).
_EXACT_SLACK = 1e-4


#: IPOPT iteration budget of each NLP of the switch-time polish of `solve_time_optimal`
#: (`ocp.polish_switches`: the switch-time NLP, then should it fail the moving-knot
#: re-solve): this many times the first solution's iterations, at least `POLISH_MIN_ITER`
#: (the user's ``max_iter`` wins). A budget in iterations, not in seconds: the pipeline's
#: answer is the same on a loaded machine (it once had the first solve's wall time, at least
#: 0.5 s, which the first build of a new structure's NLP could spend under load, and the
#: unpolished T came back). Bilimoria-Wie's polish takes 3 iterations.
POLISH_ITER_FACTOR = 10
POLISH_MIN_ITER = 200

#: Intervals of the coarse race of `time_optimal`'s seeded starts (`_raced`): every start
#: is solved on this mesh, only the best again on ``N`` (warm from it). Measured at N = 30
#: (iterations of the three starts, then of the fine re-solve; the starts on the fine mesh
#: before): Bilimoria-Wie 47 + 38 + 45, 23 (41 + 68 + 28); 2 rad about (0.2, 1, 0.5) 13 +
#: 15 + 16, 15 (17 + 21 + 20); the new user's slew 17 + 18 + 18, 19 (18 + 21 + 21); the
#: same best T on the fine mesh (to 5e-10 relative) in each.
RACE_N = 10

#: Relative agreement of the ``T`` of two converged starts of the coarse race (`_race`,
#: `ocp.solve_multistart`'s ``agree``) after which the remaining starts are skipped: two
#: starts from different guesses (the eigenaxis and a tilted one) reaching the same optimum.
#: Where they do not (Bilimoria-Wie: the eigenaxis local optimum 3.5449 against 3.2442 on
#: 10 intervals) every start runs. Measured: the three starts of the 2 rad slew about
#: (0.2, 1, 0.5) and of the new user's slew each agree to 1e-9 on 10 intervals.
RACE_AGREE = 1e-6


#: IPOPT options of the starts of the coarse race (`_race`; the user's ``ipopt_options``
#: override them): the adaptive barrier update. Measured (iterations of the race, the
#: monotone default first): Bilimoria-Wie 83 -> 47, 2 rad about (0.2, 1, 0.5) 28 -> 26,
#: J = diag(1, 2, 3) 1 rad about (1, 1, 0) 64 -> 39, the new user's slew 35 -> 32, each
#: with the same polished T (to 1e-10).
RACE_IPOPT = {"mu_strategy": "adaptive"}


def _labelled_starts(start_options, n: int, verbose):
    """``start_options`` (one entry per start: a mapping or a list of attempts) with each
    start's IPOPT lines labelled ``[slew: start i/n]`` when ``verbose`` is True."""
    if verbose is not True:
        return start_options
    entries = [{}] * n if start_options is None else list(start_options)
    out = []
    for i, entry in enumerate(entries):
        label = {"verbose": stage_sink(True, f"slew: start {i + 1}/{n}")}
        out.append({**entry, **label} if isinstance(entry, Mapping) else
                   [{**attempt, **label} for attempt in entry])
    return out


def _polish_record(ran: bool, why: str, *, wall_time=0.0, budget=None, method=None,
                   T_before=None, T_polished=None, T_after=None, used=False) -> dict:
    """``info['polish']`` of `solve_time_optimal`: whether the polish ran and was used,
    why, its wall time [s] and iteration budget (per NLP), ``T`` before, of the polished
    result and after (the polished one when used, else the first's) [s], and the gain
    ``T_before - T_after`` [s] (0 when not used)."""
    gain = float(T_before) - float(T_after) if used else 0.0
    return {"ran": ran, "used": used, "why": why, "method": method, "wall_time": wall_time,
            "budget": budget, "T_before": T_before, "T_polished": T_polished,
            "T_after": T_after, "gain": gain}


def _race(problem, guesses, opts, start_options, race_N):
    """The coarse race: the starts solved in turn on ``race_N`` intervals (`solve_multistart`;
    about a third of the cost per iteration at N = 30) until two converged ones agree on
    ``T`` to `RACE_AGREE` relative (the rest skipped); the best of them, or ``None`` if none
    converged. ``info['race']`` records ``N``, the best ``T``, the ``iterations`` of all
    starts solved and how many were ``skipped``."""
    ipopt = {**RACE_IPOPT, **(opts.get("ipopt_options") or {})}
    coarse = solve_multistart(problem, guesses, start_options=_labelled_starts(
        start_options, len(guesses), opts.get("verbose")), agree=RACE_AGREE,
        start_budget=START_BUDGET, **{**opts, "N": race_N, "ipopt_options": ipopt})
    if not coarse.success:
        return None
    race = {"N": race_N, "T": float(coarse.T),
            "iterations": int(sum(r["iterations"] for r in coarse.info["starts"])),
            "skipped": int(coarse.info["skipped"])}
    return annotate(coarse, {"race": race})


def _fine(problem, coarse, opts):
    """The best start of the race re-solved on the mesh of ``opts``, warm from it (with its
    ``starts``, ``best`` and ``race`` records), or ``None`` if that fails."""
    fine = solve(problem, guess=coarse, **{**opts, "verbose": stage_sink(opts.get("verbose"),
                                                                         "slew: fine")})
    if not fine.success:
        return None
    keep = {k: coarse.info[k] for k in ("starts", "best", "race")}
    return annotate(fine, keep, message=(
        f"best of {len(keep['starts'])} starts on {keep['race']['N']} intervals: start "
        f"{keep['best']}, re-solved on {fine.mesh.N}; {fine.message}"))


def _polish(problem, seed, opts, *, verbose, ipopt_options, ptol, rtol, method="auto"):
    """``(polished and verified, record fields)``: `ocp.polish_switches` of ``seed`` (Radau
    degree 5 for the moving knots; IPOPT tol 1e-9 unless ``ipopt_options`` says otherwise),
    each of its NLPs within the iteration budget `POLISH_ITER_FACTOR` x ``seed``'s
    iterations, at least `POLISH_MIN_ITER` (the record's ``budget``)."""
    # a bang-bang first solution: switch-time optimization (arc durations only, RK8 shooting;
    # Bilimoria-Wie: 3 IPOPT iterations, T = 3.2430832775, re-simulated pointing error 8e-10
    # rad). Otherwise the moving-knot fallback, at degree 5: at degree 3 the ~4 intervals per
    # arc under-resolve the states and the free knots exploit the collocation error (T below
    # the best known); at degree 4 the re-simulated pointing error of Bilimoria-Wie is 4e-7
    # rad, at degree 5 3e-10 (measured)
    polish_opts, budget = iteration_budget({"tol": 1e-9, **(ipopt_options or {})},
                                           seed.iterations, POLISH_ITER_FACTOR,
                                           minimum=POLISH_MIN_ITER)
    pscale = None if opts["scale"] is None else {"objective": opts["scale"]["objective"],
                                                 "t_clock": opts["scale"]["T"]}
    t_polish = time.perf_counter()
    polished = polish_switches(problem, seed, degree=5, verbose=verbose, ipopt_options=polish_opts,
                               scale=pscale, method=method)
    polished = verify(polished, pointing_tol=ptol, rate_tol=rtol)
    ran = dict(wall_time=time.perf_counter() - t_polish, budget=budget,
               method=polished.info.get("method"), T_before=float(seed.T),
               T_polished=float(polished.T))
    return polished, ran


def _kept(polished, seed, ran, t_start, why):
    """``polished`` with the seed's ``starts``, ``best`` and ``race`` records and the polish
    record (used)."""
    first = {k: v for k, v in getattr(seed, "info", {}).items() if k in ("starts", "best", "race")}
    record = _polish_record(True, why, used=True, T_after=float(polished.T), **ran)
    return _finish(annotate(polished, first), record, t_start)


def solve_time_optimal(problem, guess, guesses, opts, *, polish, pointing_tol, rate_tol,
                       ipopt_options, verbose, start_options=None, race_N=None):
    """The time-optimal pipeline shared by the rigid-body and the device slews: solve from
    ``guess`` (or the best of ``guesses``), verify by re-simulation, polish the switch
    times when ``polish`` (kept only if verified and not slower), else refine the mesh
    (`_refined_fallback`). ``opts`` are `ocp.solve` keywords.

    The polish runs only when the first solution is bang-bang (`ocp.refine.arcs.bang_arcs`,
    a few samples: decided before anything is built), each of its NLPs within an iteration
    budget (`POLISH_ITER_FACTOR` times the first solution's IPOPT iterations, at least
    `POLISH_MIN_ITER`; a budget in iterations gives the same answer on any load). The
    result records it in
    ``info['polish']`` (`_polish_record`: ran, used, why, method, wall_time, budget,
    T_before, T_polished, T_after, gain) and in its message (`polish_text`);
    ``info['wall_time']`` is the wall time of the whole pipeline [s]. With ``verbose`` the
    IPOPT lines go to stderr labelled ``[slew: start i/n]`` and ``[polish]``.

    ``race_N`` (an int below ``opts['N']``, several ``guesses``): the starts are raced on
    ``race_N`` intervals (`_race`) and only the best goes on. If it is bang-bang, its
    switch times are polished at once (``method='switch-times'``: exact, so the coarse
    mesh costs no accuracy) and kept when verified and at most `ocp.refine.result.WORSE_SLACK`
    relative slower than the coarse ``T`` (that mesh's discretization error can put it
    below the exact optimum: 1.6e-4 relative measured); otherwise the best is re-solved on
    ``opts['N']`` intervals warm from it (`_fine`) and the pipeline goes on from there as
    above. ``info['race']`` records the race (``N``, ``T``, ``iterations``)."""
    ptol, rtol = pointing_tol, rate_tol
    t_start = time.perf_counter()
    sol = None
    if guess is not None:
        sol = solve(problem, guess=guess, **{**opts, "verbose": stage_sink(verbose, "slew")})
    elif race_N is not None and len(guesses) > 1 and race_N < opts["N"]:
        coarse = _race(problem, guesses, opts, start_options, race_N)
        arcs = None if not (polish and coarse is not None) else bang_arcs(coarse)[0]
        if arcs is not None:
            polished, ran = _polish(problem, coarse, opts, verbose=verbose,
                                    ipopt_options=ipopt_options, ptol=ptol, rtol=rtol,
                                    method="switch-times")
            if polished.success and polished.T <= coarse.T * (1.0 + WORSE_SLACK):
                return _kept(polished, coarse, ran, t_start,
                             f"verified, from the best start on {race_N} intervals")
        sol = None if coarse is None else _fine(problem, coarse, opts)
    if sol is None:
        sol = solve_multistart(problem, guesses, start_options=_labelled_starts(
            start_options, len(guesses), opts.get("verbose")), start_budget=START_BUDGET,
            **opts)
    first = sol
    arcs, not_bang = (None, "") if not (polish and first.success) else bang_arcs(first)
    if arcs is None:
        why = ("polish=False (or not applicable)" if not polish else
               "the first solve failed" if not first.success else f"not bang-bang: {not_bang}")
        out = _refined_fallback(problem, first, verify(sol, pointing_tol=ptol, rate_tol=rtol),
                                ptol, rtol, ipopt_options, opts["scale"])
        return _finish(out, _polish_record(False, why, T_before=float(first.T),
                                           T_after=float(first.T)), t_start)
    polished, ran = _polish(problem, sol, opts, verbose=verbose, ipopt_options=ipopt_options,
                            ptol=ptol, rtol=rtol)
    # switch times are integrated to ~1e-13 while a fixed-mesh T can sit below the exact
    # optimum by its discretization error (J = diag(1, 2, 3), 1 rad: 2.2075331 against
    # 2.2075385, 2.4e-6 relative), so an exact polish may come out a hair slower and is kept
    exact = polished.info.get("method") == "switch-times"
    slack = _EXACT_SLACK * sol.T if exact else 1e-9
    if not (polished.success and polished.T <= sol.T + slack):  # then the first is graded
        sol = verify(sol, pointing_tol=ptol, rate_tol=rtol)
    if polished.success and (polished.T <= sol.T + slack or not sol.success):
        why = "verified, not slower" if sol.success else "verified where the first is not"
        return _kept(polished, sol, ran, t_start, why)
    why = (polished.message if not polished.success else
           f"its T = {polished.T:.10g} s is not below {sol.T:.10g} s (the first kept)")
    record = _polish_record(True, why, T_after=float(sol.T), **ran)
    out = _refined_fallback(problem, first, annotate(sol, {"polish": record}), ptol, rtol,
                            ipopt_options, opts["scale"])
    return _finish(out, record, t_start)


def _finish(solution, record: dict, t_start: float):
    """``solution`` with ``info['polish'] = record``, its line appended to the message, and
    ``info['wall_time']`` since ``t_start``."""
    return annotate(solution, {"polish": record, "wall_time": time.perf_counter() - t_start},
                    message=f"{solution.message}; {polish_text(record)}")


def _refined_fallback(problem, first, verified, ptol, rtol, ipopt_options, scale):
    """When the first NLP solution converged but its re-simulation misses the target (the
    fixed mesh smears the switches): refine the mesh (`ocp.refine`, 4 rounds, tol 1e-6)
    and verify again; failing that, re-solve on the uniform mesh twice as fine; failing
    that, refine the regularized problem (`_regularized`). The first of these verified by
    re-simulation is returned (``info['fallback']`` names the last two), else ``verified``
    unchanged -- also if it already is a success or the NLP itself failed. For
    minimum-time problems (the pipeline of `solve_time_optimal`)."""
    if verified.success or not first.success:
        return verified
    ref = refine(problem, first, tol=1e-6, max_rounds=4, ipopt_options=ipopt_options, scale=scale,
                 transcription=first.transcription, **SEED_OPTIONS)
    ref = verify(ref, pointing_tol=ptol, rate_tol=rtol)
    keep = {k: first.info[k] for k in ("starts", "best", "race", "polish") if k in first.info}
    keep.update({k: verified.info[k] for k in ("polish",) if k in verified.info})
    if ref.success:
        return annotate(ref, keep)
    # the refinement stalls on the switches of a general inertia (estimates 0.11, 0.10, 0.03
    # on 30, 53, 82 intervals) where the uniform mesh twice as fine is verified (measured: 4
    # of 80 random inertias missed pointing_tol 1e-6 by 1.0-15x at N = 30, all verified at 60)
    n = first.mesh.N
    finer = solve(problem, transcription=first.transcription, N=2 * n, guess=first,
                  ipopt_options=ipopt_options, scale=scale, **SEED_OPTIONS)
    finer = verify(finer, pointing_tol=ptol, rate_tol=rtol)
    if finer.success:
        return annotate(finer, {**keep, "fallback": f"uniform mesh of {2 * n} intervals "
                                                    f"(refine: {ref.message[:200]})"})
    # a singular arc (a CMG gimbal rate inside its bounds: the collocated control rings
    # there, the estimate stalls however fine the mesh) is the one case left: regularize
    if problem.lagrange is not None:  # not a pure minimum-time problem: nothing to add to
        return verified
    reg = _regularized(problem, first, ipopt_options=ipopt_options, scale=scale)
    reg = verify(reg, pointing_tol=ptol, rate_tol=rtol)
    if reg.success:
        return annotate(reg, {**keep, "fallback": (
            f"regularized: {REGULARIZATION:g} * 1/2 integral |u / u_max|^2 dt added to T, "
            f"refined to {reg.mesh.N} intervals (T {reg.T:.10g} s; unregularized, collocated "
            f"on {ref.mesh.N} intervals: {ref.T:.10g} s; {ref.message[:200]})")})
    return verified


#: Weight of the control regularization of the last fallback of the time-optimal pipeline
#: (`_regularized`), relative to ``T``. CMG slew of the tests (a gimbal on a singular arc;
#: 1 rad, pyramid 0.9553, general inertia): unregularized the refinement stalls (interval
#: errors ~1e-2 on 30 to 204 intervals, re-simulated pointing error 1.7e-6 to 7.6e-5 rad on
#: every mesh tried); 1e-3 converges in 4 rounds (74 intervals, pointing error 4.5e-7 rad)
#: at a T 1.1e-5 relative above the unregularized collocated one; 1e-4 and 1e-5 still stall.
#: (A second draw, 2.78 s: the regularized refinement even settles in a better local optimum,
#: 1.9% below the stalled unregularized one, pointing error 2.1e-7 rad on 63 intervals.)
REGULARIZATION = 1e-3


def _regularized(problem, first, *, ipopt_options, scale):
    """``problem`` (minimum time) with ``REGULARIZATION * 1/2 integral |u / u_max|^2 dt``
    added to the objective, refined (`ocp.refine`, tol 1e-6) warm from ``first``: the
    control becomes continuous on a singular arc and collocation converges. Returned as a
    solution of ``problem`` (``cost`` = ``T``)."""
    lo, hi = np.asarray(problem.u_bounds, dtype=float)
    u_max = np.fmax(np.abs(lo), np.abs(hi))
    u_max = np.where(np.isfinite(u_max) & (u_max > 0), u_max, 1.0)
    w = ca.DM(0.5 * REGULARIZATION / u_max ** 2)
    regularized = problem.replace(lagrange=lambda x, u, p: ca.dot(w, u * u),
                                  name=f"{problem.name}, regularized {REGULARIZATION:g}")
    sol = refine(regularized, first, tol=1e-6, max_rounds=6, ipopt_options=ipopt_options,
                 scale=scale, transcription=first.transcription, **SEED_OPTIONS)
    return annotate(sol, {"regularization": REGULARIZATION}, problem=problem, cost=sol.T,
                    nlp_point=None)


@interruptible
def min_effort(inertia, T, *, angle=None, axis=None, q0=None, qf=None, u_max=None,
               norm_bound=False, w0=None, wf=None, keep_out=None, guess=None, N=None,
               tol=1e-7, starts=None, seed=None, verbose=False, ipopt_options=None,
               pointing_tol=POINTING_TOL, rate_tol=RATE_TOL) -> Solution:
    """Minimum-effort (``1/2 integral |u|^2 dt``) rigid-body slew over a fixed time ``T``.

    The engine of `slew` for this scene; prefer
    ``slew(Scene(RigidHub(inertia), ExternalTorque(u_max=u_max)), objective="effort", T=T, ...)``.

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2]
    T : float [s]
        Maneuver time
    angle, axis, q0, qf, w0, wf, keep_out : as in `time_optimal`
    u_max : float or array_like, shape (3,) [N m], optional
        Torque bound (default none)
    norm_bound : bool
    guess : None, ocp.Solution or mapping
        Default: eigenaxis SLERP (with a keep-out cone:
        multi-start from ``starts`` seeded tilted paths, best kept)
    N : int, optional
        Intervals of the first mesh (default ``appdyn.config`` ``problems.effort_N``, 20)
    starts : int, optional
        Seeded tilted starts with a ``keep_out`` cone and no ``guess``
        (default 4); ignored otherwise, with a warning
    seed : int, optional
        Seed of their tilt axes (default 0); ignored, with a warning,
        where ``starts`` is
    tol : float
        Mesh-refinement target for the relative re-integration error (`ocp.refine`), at
        least `MIN_REFINE_TOL` = 1e-12 (the CVODES reference of the error estimate is good
        to about 1e-13). ``success`` requires it to be met.
    verbose, ipopt_options, pointing_tol, rate_tol : as in `time_optimal`

    Returns
    -------
    ocp.RefinedSolution
        ``cost`` in [N^2 m^2 s]; ``success`` as in the module docstring (``status``
        `STATUS_REFINE` when the refinement stopped above ``tol``). For a rest-to-rest
        rotation by ``theta`` about a principal axis with moment ``J`` and no active bound:
        ``u = J theta (6/T^2 - 12 t/T^3)``, cost ``6 J^2 theta^2 / T^3``. With ``u_max``,
        a first solve that IPOPT finds infeasible is checked against the time-optimal slew
        of the same scene (`time_optimal`; ``info['minimum_time']`` [s], None if it failed):
        ``T`` below that minimum time is a failure that says so; otherwise the slew is
        re-solved from the time-optimal one, stretched to ``T`` (its torque times
        ``(T_min / T)^2``: feasible), as for Bilimoria-Wie at ``T`` between 3.243 s and the
        eigenaxis start's 3.545 s.

    Raises
    ------
    TypeError, ValueError
        Bad input, naming the argument (``tol`` below 1e-12 among them).

    Examples
    --------
    A 0.1 rad rest-to-rest slew about a principal axis in T = 2 s: the cubic profile, cost
    ``6 J^2 theta^2 / T^3 = 0.0075``:

    >>> import numpy as np
    >>> from appdyn.problems import slew
    >>> sol = slew.min_effort(np.eye(3), 2.0, angle=0.1, axis=[1, 0, 0], N=10)
    >>> sol.success, round(sol.cost, 8)
    (True, 0.0075)
    """
    N = param("problems.effort_N", N)
    ptol = check_tol("pointing_tol", pointing_tol, POINTING_TOL)
    rtol = check_tol("rate_tol", rate_tol, RATE_TOL)
    tol = check_tol("tol", tol, 1e-7)
    if tol < MIN_REFINE_TOL:
        raise ValueError(f"`tol` must be at least {MIN_REFINE_TOL:g} (what the re-integration "
                         f"reference can resolve in double precision), got {tol:g}")
    if guess is not None or keep_out is None:
        _warn_ignored(starts=starts, seed=seed,
                      why="without a `keep_out` cone or with a user `guess` (a single start)")
    problem = slew_problem(inertia, objective="effort", T=T, angle=angle, axis=axis, q0=q0,
                           qf=qf, u_max=u_max, norm_bound=norm_bound, w0=w0, wf=wf,
                           keep_out=keep_out)
    rest = _rest(problem, problem.T, ptol, rtol)
    if rest is not None:
        return rest
    scale = None
    if is_rest_to_rest(problem) and slew_angle(problem) < 1e-2:
        # the cost of the single-axis cubic profile, 6 (J theta)^2 / T^3, as its scale
        J = float(np.max(np.linalg.eigvalsh(inertia_of(problem.model))))
        d = 6.0 * (J * slew_angle(problem)) ** 2 / problem.T ** 3
        scale = {"objective": float(2.0 ** round(math.log2(d)))}
    opts = dict(N=N, verbose=stage_sink(verbose, "slew"), ipopt_options=ipopt_options,
                scale=scale)
    if guess is not None:
        first = solve(problem, guess=guess, **opts)
    elif keep_out is None:
        first = solve(problem, guess=attitude_guess(problem), **opts)
    else:
        # the eigenaxis path may cross the cone's centre, a symmetric saddle between the two
        # ways around: start from seeded tilted paths instead and keep the best
        starts = integer(DEFAULT_STARTS_EFFORT if starts is None else starts, "starts", minimum=1)
        guesses = seeded_guesses(problem, starts, 0 if seed is None else seed, eigenaxis=False)
        first = solve_multistart(problem, guesses, start_budget=START_BUDGET, **opts)
    fastest = None
    if u_max is not None:
        def fastest():
            return time_optimal(inertia, angle=angle, axis=axis, q0=q0, qf=qf, u_max=u_max,
                                norm_bound=norm_bound, w0=w0, wf=wf, keep_out=keep_out,
                                pointing_tol=ptol, rate_tol=rtol, ipopt_options=ipopt_options)
    first, fast = restarted(problem, first, fastest, opts)
    sol = refine_and_verify(problem, first, tol=tol, scale=scale, pointing_tol=ptol,
                            rate_tol=rtol, ipopt_options=ipopt_options, verbose=verbose)
    return with_minimum_time(sol, problem.T, fast)


def restarted(problem, first, fastest, opts: dict):
    """``(first, time-optimal solution or None)`` of a minimum-effort slew whose first solve
    ``first`` may be infeasible: with a bounded control, IPOPT's "local infeasibility" is a
    ``T`` below the slew's minimum time, or a start path too slow for ``T`` (Bilimoria-Wie's
    eigenaxis path needs 3.545 s where 3.243 s is the minimum). ``fastest()`` (None: no
    bound) gives the time-optimal slew of the same scene; stretched to ``T`` it is feasible
    (a rigid body's torque scales by ``(T_min / T)^2``), so when it fits in ``T`` the slew is
    re-solved from it (`ocp.solve` with ``opts``)."""
    if first.status != STATUS_INFEASIBLE or fastest is None:
        return first, None
    fast = fastest()
    if fast.success and fast.T <= problem.T:
        first = solve(problem, guess=fast, **opts)
    return first, fast


def with_minimum_time(sol, T: float, fast):
    """``sol`` with ``info['minimum_time']`` [s] (None if the time-optimal slew failed) and
    `minimum_time_text` appended to its message, when `restarted` ran ``fast``."""
    if fast is None:
        return sol
    return annotate(sol, {"minimum_time": float(fast.T) if fast.success else None},
                    message=f"{sol.message}; {minimum_time_text(T, fast)}")


def minimum_time_text(T: float, fastest: Solution) -> str:
    """The sentence on a minimum-effort slew over ``T`` [s] whose first solve IPOPT found
    infeasible, given ``fastest``, the time-optimal slew of the same scene (`time_optimal`)."""
    if not fastest.success:
        return (f"its first solve was infeasible and the time-optimal slew of the same scene "
                f"did not converge either ({fastest.message[:200]}): check the control bound "
                f"and the target")
    if fastest.T > T:
        return (f"T = {T:.6g} s is below this slew's minimum time {fastest.T:.6g} s under its "
                f"control bounds (the time-optimal slew, verified): no control within the "
                f"bounds reaches the target in T; ask T >= {fastest.T:.6g} s")
    return (f"its first solve was infeasible from its start path; re-solved from the "
            f"time-optimal slew (minimum time {fastest.T:.6g} s, stretched to T = {T:.6g} s)")


def refine_and_verify(problem, first, *, tol, scale, pointing_tol, rate_tol, ipopt_options,
                      verbose):
    """The minimum-effort pipeline after the first solve (shared with the device slews):
    refine the mesh to ``tol`` (`ocp.refine`; not meeting it is `STATUS_REFINE`) and verify
    by re-simulation. A first solve that converged but fails `ocp.solve`'s checks of its
    dense output is refined too (the remedy); a result whose control polynomial still
    leaves a bound the optimum rides (a torque or gimbal-rate limit: a kink the polynomial
    overshoots however fine the mesh) is refined again with a piecewise-linear control
    (``control='linear'``; path constraints, a keep-out cone or a singularity measure, are
    imposed at its collocation points and checked on its dense output like the bounds)."""
    if not (first.success or first.status in (STATUS_BOUND_VIOLATION, STATUS_RESIMULATION)):
        return verify(first, pointing_tol=pointing_tol, rate_tol=rate_tol)
    kw = dict(tol=tol, verbose=verbose, ipopt_options=ipopt_options, scale=scale)
    sol = refine(problem, first, transcription=first.transcription, **kw)
    bv = sol.bound_violation
    if not sol.success and bv.name in problem.model.controls and bv.max > DEFAULT_CONSTRAINT_TOL:
        sol = refine(problem, sol, control="linear", **kw)
    checks = (STATUS_BOUND_VIOLATION, STATUS_RESIMULATION)
    if (sol.success or sol.status in checks) and not sol.info.get("converged", False):
        sol = annotate(sol, {}, success=False, status=STATUS_REFINE,
                       message=f"{sol.message}; the requested refinement tol {tol:g} was not met")
    return verify(sol, pointing_tol=pointing_tol, rate_tol=rate_tol)
