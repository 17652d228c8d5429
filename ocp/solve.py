"""`solve`: transcribe a `Problem`, solve the NLP with IPOPT, return a `Solution`."""
from __future__ import annotations

import sys
import time
from typing import Callable, Mapping

import casadi as ca
import numpy as np

from .guess import initial_guess
from .mesh import Mesh, _check_N
from .problem import Problem
from .scaling import auto_scaling
from .solution import Solution, _Dense
from .transcription import get_transcription

__all__ = ["solve", "Progress"]

_SUCCESS = ("Solve_Succeeded", "Solved_To_Acceptable_Level")
_DEFAULT_N = 20


class Progress:
    """One IPOPT iteration as reported to a progress callable.

    Attributes
    ----------
    iteration : int
    objective : float
        Scaled NLP objective ``J / d_J``.
    infeasibility : float
        Largest violation of the scaled NLP constraints.
    """

    __slots__ = ("iteration", "objective", "infeasibility")

    def __init__(self, iteration: int, objective: float, infeasibility: float):
        self.iteration, self.objective, self.infeasibility = iteration, objective, infeasibility

    def __str__(self) -> str:
        return f"{self.iteration:5d}  {self.objective: .10e}  {self.infeasibility:.3e}"


class _IterationCallback(ca.Callback):
    """Hands every IPOPT iterate to ``sink(Progress)``; never stops the solver."""

    def __init__(self, nx: int, ng: int, violation: Callable, sink: Callable):
        ca.Callback.__init__(self)
        self._nx, self._ng, self._violation, self._sink = nx, ng, violation, sink
        self._count = 0
        self.construct("ocp_progress", {})

    def get_n_in(self):
        return ca.nlpsol_n_out()

    def get_n_out(self):
        return 1

    def get_name_in(self, i):
        return ca.nlpsol_out(i)

    def get_name_out(self, i):
        return "ret"

    def get_sparsity_in(self, i):
        name = ca.nlpsol_out(i)
        if name == "f":
            return ca.Sparsity.dense(1)
        if name in ("x", "lam_x"):
            return ca.Sparsity.dense(self._nx)
        if name in ("g", "lam_g"):
            return ca.Sparsity.dense(self._ng)
        return ca.Sparsity(0, 0)

    def eval(self, arg):
        g = np.asarray(arg[2]).reshape(-1)
        self._sink(Progress(self._count, float(arg[1]), self._violation(g)))
        self._count += 1
        return [0]


def _printer(stream):
    state = {"header": False}

    def sink(progress: Progress):
        if not state["header"]:
            print(" iter   objective (scaled)  inf_pr", file=stream, flush=True)
            state["header"] = True
        print(str(progress), file=stream, flush=True)

    return sink


def _mesh(N, mesh) -> Mesh:
    if mesh is None:
        return Mesh.uniform(_DEFAULT_N if N is None else N)
    m = mesh if isinstance(mesh, Mesh) else Mesh(mesh)
    if N is not None and _check_N(N) != m.N:
        raise ValueError(f"`N` = {N} conflicts with `mesh`, which has {m.N} intervals")
    return m


def _ipopt_options(ipopt_options) -> dict:
    opts = {"print_level": 0, "sb": "yes"}
    if ipopt_options is None:
        return opts
    if not isinstance(ipopt_options, Mapping):
        raise ValueError(f"`ipopt_options` must be a mapping, got {type(ipopt_options).__name__}")
    for key, value in ipopt_options.items():
        if not isinstance(key, str):
            raise ValueError(f"`ipopt_options` keys must be IPOPT option names, got {key!r}")
        opts[key[len("ipopt."):] if key.startswith("ipopt.") else key] = value
    return opts


def _message(status: str, iterations: int) -> str:
    text = {
        "Solve_Succeeded": "optimal solution found",
        "Solved_To_Acceptable_Level": "solved to IPOPT's acceptable level only (tol not met, acceptable_tol met)",
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


def solve(problem: Problem, *, transcription="radau", N: int | None = None, degree: int | None = None,
          mesh=None, guess=None, scale: Mapping | None = None, verbose=True,
          ipopt_options: Mapping | None = None, expand: bool = True) -> Solution:
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
        Radau collocation degree (default 3); only with ``'radau'``.
    mesh : Mesh or array_like, shape (N + 1,), optional
        Interval breakpoints in normalized time, 0 to 1 (non-uniform meshes, refinement).
    guess : None, Solution or mapping, optional
        Initial guess (see `ocp.guess`): default linear/SLERP between boundary values, a
        previous Solution (warm start, any transcription or mesh), or a mapping with ``'t'``,
        ``'x'``, ``'u'``, ``'T'``, ``'p'``.
    scale : mapping of str to float, optional
        Scale overrides by state/control/parameter name, ``'T'``, ``'objective'`` (see
        `ocp.scaling`).
    verbose : bool or callable, optional
        ``True`` prints one line per IPOPT iteration (iteration, scaled objective, largest
        scaled constraint violation) to ``sys.stdout`` as it runs; a callable receives a
        `Progress` per iteration instead; ``False`` prints nothing.
    ipopt_options : mapping, optional
        IPOPT options (``{'tol': 1e-10, 'max_iter': 500, 'print_level': 5}``), with or
        without the ``'ipopt.'`` prefix. Defaults: ``print_level 0``, IPOPT's own otherwise
        (``tol = 1e-8``; note ``bound_relax_factor = 1e-8``: IPOPT relaxes every bound by
        1e-8 relative, which moves a bound-limited optimum by that much — pass
        ``{'bound_relax_factor': 0}`` for bound-exact solutions).
    expand : bool, optional
        Expand the whole NLP to SX before solving (default). Evaluation is about 3x faster
        per IPOPT iteration, construction costs about 5 ms per Radau(3) interval of a rigid
        body (measured): ``expand=False`` builds faster and pays off for easy problems on
        fine meshes. Falls back to MX when the functions cannot be expanded.

    Returns
    -------
    Solution
        A non-converged IPOPT run returns ``success=False`` with IPOPT's ``status``; it does
        not raise.

    Raises
    ------
    TypeError
        If ``problem`` is not a `Problem`.
    ValueError
        Naming the argument: unknown ``transcription``, bad ``N``/``degree``/``mesh``,
        ``guess``, ``scale`` or ``ipopt_options``.
    """
    if not isinstance(problem, Problem):
        raise TypeError(f"`problem` must be an ocp.Problem, got {type(problem).__name__}")
    tr = get_transcription(transcription, degree)
    m = _mesh(N, mesh)
    if not (verbose is True or verbose is False or callable(verbose)):
        raise ValueError(f"`verbose` must be True, False or a callable, got {verbose!r}")
    if expand not in (True, False):
        raise ValueError(f"`expand` must be True or False, got {expand!r}")
    opts = _ipopt_options(ipopt_options)

    t_build = time.perf_counter()
    node_guess = initial_guess(problem, tr, m, guess)
    scaling = auto_scaling(problem, node_guess, scale)
    disc = tr.build(problem, m, scaling)
    w0 = disc.pack(node_guess)
    nlp_opts = {"ipopt": opts, "print_time": False, "error_on_fail": False, "expand": expand}
    if verbose is not False:
        sink = verbose if callable(verbose) else _printer(sys.stdout)
        callback = _IterationCallback(disc.w.size, disc.g.size, disc.violation, sink)
        nlp_opts["iteration_callback"] = callback
    try:
        solver = ca.nlpsol("ocp", "ipopt", disc.nlp, nlp_opts)
    except RuntimeError:
        if not expand:
            raise
        # e.g. a model holding an integrator or a Callback cannot be expanded to SX
        solver = ca.nlpsol("ocp", "ipopt", disc.nlp, {**nlp_opts, "expand": False})
    build_time = time.perf_counter() - t_build

    t_solve = time.perf_counter()
    error = None
    try:
        res = solver(x0=w0, lbx=disc.lbx, ubx=disc.ubx, lbg=disc.lbg, ubg=disc.ubg)
    except RuntimeError as exc:  # an evaluation error inside CasADi: report, do not raise
        res, error = None, exc
    solve_time = time.perf_counter() - t_solve
    stats = solver.stats()
    status = str(stats.get("return_status", "Unknown"))
    iterations = int(stats.get("iter_count", 0))
    if res is None:
        w, lam_g, g = w0, np.zeros(disc.g.size), np.full(disc.g.size, np.nan)
        status = status if status != "Unknown" else "Exception"
        message = f"IPOPT stopped by an error: {error}"
        success = False
    else:
        w = np.asarray(res["x"]).reshape(-1)
        lam_g = np.asarray(res["lam_g"]).reshape(-1)
        g = np.asarray(res["g"]).reshape(-1)
        success = status in _SUCCESS
        message = _message(status, iterations)
    return _make_solution(problem, tr, m, disc, w, lam_g, g, success, status, message,
                          iterations, solve_time, build_time)


def _make_solution(problem, tr, mesh, disc, w, lam_g, g, success, status, message,
                   iterations, solve_time, build_time) -> Solution:
    phys = disc.unpack(w)
    X, U, p, T = phys["X"], phys["U"], phys["p"], phys["T"]
    dense = _Dense(tr, mesh, problem.model, X, U, p, T, problem.t0)
    N = mesh.N
    sig = tr.node_sigma
    n_owned = sig.size
    k = np.concatenate([[0], np.repeat(np.arange(N), n_owned)])
    s = np.concatenate([[0.0], np.tile(sig, N)])
    x, u = dense.eval(k, s)
    # decision variables exactly where they exist
    x[:, 0] = X[:, 0]
    xpos = np.flatnonzero(np.isin(sig, tr.x_sigma))
    xcols = 1 + np.arange(N)[:, None] * n_owned + xpos[None, :]
    x[:, xcols.reshape(-1)] = X[:, 1:]
    upos = np.flatnonzero(np.isin(sig, tr.u_sigma))
    ucols = 1 + np.arange(N)[:, None] * n_owned + upos[None, :]
    u[:, ucols.reshape(-1)] = U[:, int(tr.u_at_start):]
    if tr.u_at_start:
        u[:, 0] = U[:, 0]
    t = problem.t0 + T * tr.node_tau(mesh)
    t[-1] = problem.t0 + T
    mult = disc.multipliers(lam_g)
    costates = tr.costates(mult["defect"], mesh)
    for a in (t, x, u, p):
        a.setflags(write=False)
    if costates is not None:
        costates.setflags(write=False)
    return Solution(
        success=bool(success), status=status, message=message, T=T, t0=problem.t0,
        cost=disc.cost(w), t=t, x=x, u=u, p=p, iterations=iterations, solve_time=solve_time,
        build_time=build_time, costates=costates, transcription=tr, mesh=mesh, problem=problem,
        constraint_violation=disc.violation(g) if np.all(np.isfinite(g)) else float("nan"),
        multipliers=mult, _dense=dense,
    )
