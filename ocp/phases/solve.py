"""`solve_phases`: transcribe every phase of a `MultiPhaseProblem`, solve the stacked NLP
(`ocp.phases.nlp`) with IPOPT, optionally refine each phase's mesh, and return a
`MultiPhaseSolution`.

Success means verified, as for `ocp.solve`: IPOPT's ``Solve_Succeeded`` and the largest
violation of any phase row, link or event row and variable bound (NLP units) at most
``constraint_tol``.
"""
from __future__ import annotations

import time
from dataclasses import replace
from typing import Mapping, Sequence

import numpy as np

from appdyn.dynamics.cache import construction_lock
from appdyn.dynamics.interrupts import check_interrupt, interruptible

from ..cached import cached, checkout
from ..assembly import structure_key
from ..guess import initial_guess
from ..nlp import Discretization
from ..progress import LOGGER, IterationCallback, iteration_sink
from ..refine.errors import interval_errors
from ..refine.mesh_update import local_order, new_mesh
from ..scaling import auto_scaling
from ..solve import (WARM_START_OPTIONS, NlpOutcome, check_constraint_tol, default_mesh,
                     make_solution, nlp_numbers, read_result, run_ipopt, solver_ipopt_options)
from ..transcription import get_transcription
from .nlp import PhasedDiscretization, event_row_scales
from .problem import MultiPhaseProblem
from .solution import MultiPhaseSolution

__all__ = ["solve_phases"]

#: IPOPT's ``tol`` of a refinement round relative to ``refine_tol`` (`_refinement_ipopt_options`)
NLP_TOL_PER_REFINE_TOL = 0.1


def _phase_guesses(problem: MultiPhaseProblem, guess) -> list:
    """The guess of each phase: ``guess`` (a `MultiPhaseSolution` or a sequence, one item per
    phase) over the phases' own ``guess``; ``None`` where neither gives one."""
    if guess is None:
        return [ph.guess for ph in problem.phases]
    if isinstance(guess, MultiPhaseSolution):
        if len(guess.phases) != problem.n_phases:
            raise ValueError(f"`guess` has {len(guess.phases)} phases, the problem {problem.n_phases}")
        return list(guess.phases)
    if isinstance(guess, Sequence) and not isinstance(guess, (str, bytes)):
        if len(guess) != problem.n_phases:
            raise ValueError(f"`guess` must give one guess per phase ({problem.n_phases}), got {len(guess)}")
        return [g if g is not None else ph.guess for g, ph in zip(guess, problem.phases)]
    raise ValueError("`guess` must be None, a MultiPhaseSolution or a sequence of per-phase guesses, "
                     f"got {type(guess).__name__}")


def _discretize(problem: MultiPhaseProblem, meshes, guesses, expand, codegen, scalings=None):
    """Per phase ``(transcription, mesh, node guess, Discretization)``; ``scalings``: the
    phases' `ocp.scaling.Scaling` to keep (a refinement round keeps those of its first solve:
    the same problem in the same units), else each from its guess."""
    out = []
    for i, ph in enumerate(problem.phases):
        tr = get_transcription(ph.transcription, degree=ph.degree)
        m = meshes[i] if meshes is not None else default_mesh(ph.N, ph.mesh)
        pb = _started_at(ph.problem, 0.0)
        try:
            # (a Solution is read in normalized time)
            ng = initial_guess(pb, tr, m, guess=guesses[i])
        except ValueError as exc:
            raise ValueError(f"phases[{i}]: {exc}") from exc
        scaling = scalings[i] if scalings is not None else auto_scaling(pb, ng, overrides=ph.scale)
        out.append((tr, m, ng, Discretization(pb, tr, m, scaling, expand, codegen)))
    return out


@interruptible
def solve_phases(problem: MultiPhaseProblem, *, guess=None, objective_scale: float = 1.0,
                 refine_tol: float | None = None, max_rounds: int = 4, max_intervals: int = 200,
                 verbose=False, progress=None, ipopt_options: Mapping | None = None,
                 constraint_tol: float | None = None, expand: bool = True,
                 codegen: bool = False) -> MultiPhaseSolution:
    """Solve a multi-phase problem by direct collocation (every phase its own transcription
    and mesh) and IPOPT.

    Parameters
    ----------
    problem : MultiPhaseProblem
    guess : None, MultiPhaseSolution or sequence, optional
        A previous solution (each phase's solution becomes that phase's guess; primal and dual
        values, and its scalings, when it solved the same NLP up to its bounds, e.g. with a
        path constraint's band narrowed; on other meshes of Radau phases, the dual values from its costates, see
        ``refine_tol``), or one guess per phase (``None`` items take the
        phase's own ``Phase.guess``). A phase guess is what `ocp.solve` takes, its times from
        the phase's start.
    objective_scale : float, optional
        ``d_J``: IPOPT sees ``J / d_J`` (default 1).
    refine_tol : float, optional
        Refine each phase's mesh until its largest estimated interval error
        (`ocp.refine.interval_errors`) is below this (as `ocp.refine` does for one phase),
        re-solving warm after each round: primal values interpolated onto the new meshes,
        defect multipliers from the interpolated costates (Radau), link and event multipliers
        carried over, IPOPT's barrier restarted where the last solve ended (``mu_init = tol /
        10``), to IPOPT ``tol <= refine_tol / 10`` unless ``ipopt_options`` sets ``tol``
        (the error estimates cannot fall below the NLP's own accuracy); default: no
        refinement.
    max_rounds, max_intervals : int, optional
        Refinement limits (rounds; intervals per phase).
    verbose, progress, ipopt_options, constraint_tol, expand, codegen
        As for `ocp.solve`.

    Returns
    -------
    MultiPhaseSolution
        ``success=False`` with IPOPT's status on a failure; never raises for one.

    Raises
    ------
    TypeError
        If ``problem`` is not a `MultiPhaseProblem`.
    ValueError
        Naming the argument: a bad ``guess``, ``objective_scale``, ``refine_tol``,
        ``max_rounds``, ``max_intervals``, ``constraint_tol`` or IPOPT option, or a phase's
        mesh/guess (``phases[i]: ...``).

    Examples
    --------
    Rest at 0 to rest at 1 in 2 s with minimum ``integral u^2 / 2``, split at t = 1 s (the
    merged problem's optimum is ``6 d^2 / T^3 = 0.75``):

    >>> from appdyn import ocp
    >>> from appdyn.ocp.examples import double_integrator
    >>> di, energy = double_integrator(), (lambda u: 0.5 * u**2)
    >>> first = ocp.Problem(di, T=1.0, x_initial=[0, 0], lagrange=energy)
    >>> second = ocp.Problem(di, T=1.0, x_final=[1, 0], lagrange=energy)
    >>> two = ocp.MultiPhaseProblem([ocp.Phase(first, N=10), ocp.Phase(second, N=10)],
    ...                             links=[ocp.Link(0, 1)])
    >>> sol = ocp.solve_phases(two)
    >>> sol.success, round(sol.cost, 9), sol.tf.tolist()
    (True, 0.75, [1.0, 2.0])
    """
    if not isinstance(problem, MultiPhaseProblem):
        raise TypeError(f"`problem` must be an ocp.MultiPhaseProblem, got {type(problem).__name__}")
    objective_scale = _positive(objective_scale, "objective_scale")
    if refine_tol is not None:
        refine_tol = _positive(refine_tol, "refine_tol")
    for name, v in (("max_rounds", max_rounds), ("max_intervals", max_intervals)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < (0 if name == "max_rounds" else 1):
            raise ValueError(f"`{name}` must be an int >= {0 if name == 'max_rounds' else 1}, got {v!r}")
    ctol = check_constraint_tol(constraint_tol)
    opts = solver_ipopt_options(ipopt_options, ctol)
    sink = iteration_sink(verbose, progress)
    guesses = _phase_guesses(problem, guess)

    sol = _solve_once(problem, None, guesses, guess if isinstance(guess, MultiPhaseSolution) else None,
                      objective_scale, opts, ipopt_options, ctol, sink, expand, codegen,
                      scalings=_kept_scalings(problem, guess, expand, codegen))
    if refine_tol is None:
        return sol
    rounds, totals = [], [0.0, 0.0, 0]
    round_opts = _refinement_ipopt_options(opts, ipopt_options, refine_tol)
    for _ in range(max_rounds + 1):
        totals = [totals[0] + sol.solve_time, totals[1] + sol.build_time, totals[2] + sol.iterations]
        ests = [interval_errors(s) if sol.success else None for s in sol.phases]
        errors = [e.max_error if e is not None else float("inf") for e in ests]
        rounds.append((tuple(s.mesh.N for s in sol.phases), tuple(errors), sol.cost, sol.iterations))
        LOGGER.info("solve_phases %s: intervals %s, errors %s", problem.name,
                    rounds[-1][0], ", ".join(f"{e:.2g}" for e in errors))
        if not sol.success or max(errors) <= refine_tol or len(rounds) > max_rounds:
            break
        meshes = []
        for s, e, est in zip(sol.phases, errors, ests):
            new = None
            if e > refine_tol:
                new = new_mesh(s.mesh, est, s.T, s.t0, refine_tol, local_order(s.transcription),
                               max_intervals)
            meshes.append(new or s.mesh)
        if all(m is s.mesh for m, s in zip(meshes, sol.phases)):
            break
        sol = _solve_once(problem, meshes, list(sol.phases), sol, objective_scale, round_opts,
                          ipopt_options, ctol, sink, expand, codegen,
                          scalings=sol.nlp_point.get("scalings") if sol.nlp_point else None)
    converged = sol.success and max(rounds[-1][1]) <= refine_tol
    note = "" if converged or not sol.success else (
        f"; mesh refinement stopped above refine_tol {refine_tol:g} (largest interval error "
        f"{max(rounds[-1][1]):.2g})")
    return replace(sol, message=sol.message + note,
                   info={"rounds": tuple(rounds), "converged": converged, "solve_time": totals[0],
                         "build_time": totals[1], "iterations": totals[2]})


def _refinement_ipopt_options(opts: Mapping, ipopt_options: Mapping | None, refine_tol: float) -> dict:
    """IPOPT's options of a refinement round: ``opts`` with ``tol`` at most
    ``NLP_TOL_PER_REFINE_TOL * refine_tol`` unless the caller set ``tol``.

    An interval's estimated error (`ocp.refine.interval_errors`) has a floor set by how
    well the NLP was solved, not by the mesh: at IPOPT's default ``tol = 1e-8`` the Delta III
    phases floor at 3e-10 to 1e-9 however finely they are split, so a ``refine_tol`` of 1e-9
    took one more round to move 1.008e-9 to 9.4e-10. Solved to ``refine_tol / 10`` the
    round ends at 1.8e-10 to 8.6e-10 (one IPOPT iteration more, one round fewer). Not
    tighter: at ``refine_tol / 100`` (``tol = 1e-12`` for ``refine_tol = 1e-10``) IPOPT
    stopped at its acceptable level on the two-stage rocket of the tests.
    """
    if "tol" in (ipopt_options or {}):
        return dict(opts)
    return {**opts, "tol": min(float(opts.get("tol", 1e-8)), NLP_TOL_PER_REFINE_TOL * refine_tol)}


def _kept_scalings(problem, guess, expand, codegen):
    """The phases' scalings of ``guess`` when it is a `MultiPhaseSolution` of the same NLP
    structure on the same meshes up to bounds (e.g. a relaxed path band narrowed) with the
    same scale overrides: the same variables and rows in the same units, kept rather than
    derived again from the guess; else ``None``."""
    point = getattr(guess, "nlp_point", None) if isinstance(guess, MultiPhaseSolution) else None
    if not point or "scalings" not in point or len(guess.phases) != problem.n_phases:
        return None
    keys = point["key"][1]
    for i, ph in enumerate(problem.phases):
        tr = get_transcription(ph.transcription, degree=ph.degree)
        key = structure_key(_started_at(ph.problem, 0.0), tr, default_mesh(ph.N, ph.mesh).N,
                            expand, codegen=codegen)
        if (key != keys[i] or guess.phases[i].mesh != default_mesh(ph.N, ph.mesh)
                or guess.problem.phases[i].scale != ph.scale):
            return None
    return point["scalings"]


def _started_at(problem, t0: float):
    """``problem`` with its start time ``t0`` (a phase's NLP starts at 0, its solution at the
    phase start), built once per problem object and start time in the one cache: a
    `Problem` re-checks every argument when copied, milliseconds per phase and solve."""
    t0 = float(t0)
    if problem.t0 == t0:
        return problem
    return cached("phase_started_at", (id(problem), t0), lambda: replace(problem, t0=t0),
                  keepalive=problem)


def _positive(value, name: str) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"`{name}` must be a finite number > 0, got {value!r}") from None
    if isinstance(value, bool) or not (0 < v < np.inf):
        raise ValueError(f"`{name}` must be a finite number > 0, got {value!r}")
    return v


def _solve_once(problem, meshes, guesses, warm_from, objective_scale, opts, ipopt_options, ctol,
                sink, expand, codegen, scalings=None) -> MultiPhaseSolution:
    t_build = time.perf_counter()
    parts = _discretize(problem, meshes, guesses, expand, codegen, scalings)
    discs = [p[3] for p in parts]
    node_guesses = [p[2] for p in parts]
    ends0 = np.concatenate([np.concatenate([ng.X[:, 0], ng.X[:, -1], ng.p, [ng.T]])
                            for ng in node_guesses])
    scale_e = event_row_scales(problem, ends0, discs)
    disc = PhasedDiscretization(problem, discs, objective_scale, scale_e)
    start = {"x0": disc.pack(node_guesses)}
    warm = _warm_point(warm_from, disc)
    cross = None
    if warm is None:
        warm = cross = _interpolated_duals(warm_from, disc, start["x0"])
    if warm is not None:
        start = warm
        opts = {**WARM_START_OPTIONS, **opts}
        if cross is not None and "mu_init" not in (ipopt_options or {}):
            # continue on the central path where the previous solve ended (its final barrier
            # parameter: IPOPT stops near tol / 10)
            opts["mu_init"] = 0.1 * float(opts.get("tol", 1e-8))
    nlp_opts = {"ipopt": opts, "print_time": False, "error_on_fail": False}

    def build(options=nlp_opts):
        options = dict(options)
        options["iteration_callback"] = IterationCallback(disc.structure.w.size, disc.structure.g.size,
                                                          disc.violation if sink else None, sink)
        with construction_lock():
            return disc.structure.nlpsol("ocp_phases", options), options

    bounds = dict(lbx=disc.lbx, ubx=disc.ubx, lbg=disc.lbg, ubg=disc.ubg, p=disc.P)

    def run(solver):
        check_interrupt()
        build_time = time.perf_counter() - t_build
        t_solve = time.perf_counter()
        out = run_ipopt(solver, start, bounds, opts, lambda again: disc.structure.nlpsol(
            "ocp_phases_resolve", {**nlp_opts, "ipopt": again}))
        return out, build_time + out[5], time.perf_counter() - t_solve - out[5]

    if sink is None:
        with checkout("phased_nlpsol", (disc.key, repr(sorted(opts.items()))),
                      lambda: build(), keepalive=disc.structure) as built:
            (res, error, status, iterations, note, _), build_time, solve_time = run(built[0])
    else:
        (res, error, status, iterations, note, _), build_time, solve_time = run(build()[0])
    w, lam_g, lam_x, g, success, status, solver_status, message = read_result(
        res, error, status, iterations, note, start["x0"], disc.lbg.size, disc.violation, ctol)
    LOGGER.info("solve_phases %s (%d phases): %s; %.3g s", problem.name, problem.n_phases, message,
                solve_time)
    return _solution(problem, disc, parts, w, lam_g, lam_x, g, success, status, message,
                     iterations, solve_time, build_time, solver_status)


def _solution(problem, disc, parts, w, lam_g, lam_x, g, success, status, message, iterations,
              solve_time, build_time, solver_status) -> MultiPhaseSolution:
    ws = disc.split_w(w)
    lgs, _ = disc.split_g(lam_g)
    gs, ge = disc.split_g(g)
    ends = disc.ends(w)
    finite = bool(np.all(np.isfinite(g)))
    phase_viols, _ = disc.violations(g, w) if finite else ([None] * len(parts), 0.0)
    t0s, phases, start = [], [], problem.t0
    for i, ((tr, m, _, d), wi, li, gi) in enumerate(zip(parts, ws, lgs, gs)):
        T = float(d.unpack(wi)["T"])
        pb = _started_at(d.problem, start)
        d_t = _Shifted(d, pb, phase_viols[i])
        phases.append(make_solution(pb, tr, m, d_t, NlpOutcome(
            w=wi, lam_g=li, g=gi, success=success, status=status, message=message,
            iterations=iterations, solve_time=solve_time, build_time=build_time,
            solver_status=solver_status)))
        t0s.append(start)
        start += T
    t0 = np.array(t0s)
    tf = np.array([s.t0 + s.T for s in phases])
    lo, hi = problem.event_bounds()
    ev = ge * disc.event_scale
    ev_viol = float(np.max(np.maximum(0.0, np.maximum(lo - ev, ev - hi)), initial=0.0)) \
        if np.all(np.isfinite(ev)) else float("nan")
    viol = disc.violation(g, w) if finite else float("nan")
    sw, sg, dJ = _phys_scales(disc)
    point = {"key": disc.key, "numbers": _phased_numbers(disc), "x_phys": w * sw,
             "g_sizes": tuple(d.g.size for d in disc.discs),
             "scalings": tuple(d.scaling for d in disc.discs),
             "lam_x_phys": lam_x * dJ / sw, "lam_g_phys": lam_g * dJ / sg}
    return MultiPhaseSolution(
        success=bool(success), status=int(status), message=message, cost=disc.cost(w),
        phases=tuple(phases), t0=t0, tf=tf, ends=ends, events=ev, event_violation=ev_viol,
        constraint_violation=viol, iterations=int(iterations), solve_time=float(solve_time),
        build_time=float(build_time), problem=problem, nlp_point=point,
        solver_status=str(solver_status))


class _Shifted:
    """A phase `Discretization` seen with its problem's ``t0`` set to the phase start (for
    `make_solution`; the NLP is that of the phase started at 0), its violation at the
    solve's end point already measured (`PhasedDiscretization.violations`; ``None``: not
    measured, the phase's own `violation` measures it)."""

    def __init__(self, disc, problem, violation: float | None = None):
        self._disc, self.problem, self._violation = disc, problem, violation

    def violation(self, g, w=None) -> float:
        """The phase's violation at the end point (``g``, ``w`` are that point's)."""
        return self._disc.violation(g, w) if self._violation is None else self._violation

    def __getattr__(self, name):
        return getattr(self._disc, name)


def _phys_scales(disc) -> tuple[np.ndarray, np.ndarray, float]:
    """``(s_w, s_g, d_J)`` of the stacked NLP: physical = scale x scaled."""
    parts = [d.scales() for d in disc.discs]
    return (np.concatenate([p[0] for p in parts]),
            np.concatenate([*[p[1] for p in parts], disc.event_scale]), disc.objective_scale)


def _phased_numbers(disc) -> bytes:
    """Digest of the phases' parameter values and meshes (`ocp.solve.nlp_numbers` without
    the bounds): a solution of an NLP that differs from this one in its bounds only (a
    bound homotopy) still gives a warm start."""
    import hashlib
    parts = [nlp_numbers(d, bounds=False) for d in disc.discs]
    return hashlib.blake2b(b"".join(parts), digest_size=16).digest()


def _warm_point(sol, disc) -> dict | None:
    """Primal and dual start values from a `MultiPhaseSolution` of the same NLP up to its
    bounds (same phase structures, parameter values and meshes), in this NLP's scaling and
    clipped into its bounds; ``None`` otherwise."""
    point = getattr(sol, "nlp_point", None)
    if not point or point.get("key") != disc.key or point.get("numbers") != _phased_numbers(disc):
        return None
    sw, sg, dJ = _phys_scales(disc)
    return {"x0": np.clip(point["x_phys"] / sw, disc.lbx, disc.ubx),
            "lam_x0": point["lam_x_phys"] * sw / dJ, "lam_g0": point["lam_g_phys"] * sg / dJ}


def _interpolated_duals(sol, disc, x0) -> dict | None:
    """Primal and dual start values on the meshes of ``disc`` from a `MultiPhaseSolution`
    of the same problem on other meshes (a refinement round, a coarse-to-fine start), or
    ``None`` when ``sol`` is not one or a phase's transcription gives no costates.

    The primal values ``x0`` are the solution interpolated onto the new nodes (`ocp.guess`).
    The defect multipliers follow from the phases' costate estimates (Radau:
    ``lambda_i = -nu_i / w_i``, `ocp.transcription.Radau.costates`), interpolated linearly
    in time onto the new collocation points and mapped back by ``nu_i = -w_i lambda(t_i)``;
    the link and event rows are the same rows, their multipliers are copied; path and
    bound multipliers start at zero (IPOPT's warm start pushes them off zero). Only from a
    successful solve."""
    point = getattr(sol, "nlp_point", None)
    if (not point or not sol.success or "g_sizes" not in point
            or len(sol.phases) != len(disc.discs) or len(point["g_sizes"]) != len(disc.discs)):
        return None  # (the multipliers of a failed solve are no start)
    lam_old = np.asarray(point["lam_g_phys"], dtype=float)
    if not np.all(np.isfinite(lam_old)):
        return None
    n_e = disc.event_scale.size
    if lam_old.size != sum(point["g_sizes"]) + n_e:
        return None
    nu = np.zeros(disc.lbg.size)
    start = 0
    for i, (d, old, size) in enumerate(zip(disc.discs, sol.phases, point["g_sizes"])):
        tr = d.transcription
        if type(tr) is not type(old.transcription) or old.x.shape[0] != d.problem.model.nx:
            return None
        rows = _old_defects(old, lam_old[start:start + size])
        lam = old.transcription.costates(rows, old.mesh) if rows is not None else None
        if lam is None or lam.shape[1] != old.t.size:
            return None
        new = _defect_multipliers(tr, d.mesh, old.t - old.t[0], old.T, lam)
        o = disc.structure.g.offset(str(i)) + d.g.offset("defect")
        nu[o:o + new.size] = new.reshape(-1, order="F")
        start += size
    if n_e:
        nu[-n_e:] = lam_old[-n_e:]
    sw, sg, dJ = _phys_scales(disc)
    return {"x0": x0, "lam_g0": nu * sg / dJ, "lam_x0": np.zeros(disc.lbx.size)}


def _old_defects(old, lam_g_phys):
    """The defect block ``(nx, N m_d)`` of one phase's physical constraint multipliers
    ``lam_g_phys`` (its NLP's row order), or ``None`` when the sizes disagree."""
    from ..nlp import structure
    pb = _started_at(old.problem, 0.0)
    st = structure(pb, old.transcription, old.mesh.N)
    if st.g.size != lam_g_phys.size:
        return None
    return st.g.split(lam_g_phys)["defect"]


def _defect_multipliers(tr, mesh, t_old, T, lam) -> np.ndarray:
    """``nu`` (nx, N d) on ``mesh`` (phase duration ``T``) for the costates ``lam`` (nx, n)
    given at the phase-relative times ``t_old``: ``nu = -w lambda(t)`` at the collocation
    points."""
    c, w = tr.points, tr.weights
    b, h = mesh.breaks[:-1], mesh.fractions
    t_new = ((b[:, None] + h[:, None] * c[None, :]) * T).reshape(-1)
    out = np.vstack([np.interp(t_new, t_old, row) for row in lam])
    return -out * np.tile(w, mesh.N)[None, :]
