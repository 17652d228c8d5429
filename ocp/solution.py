"""The result of `ocp.solve`: a `Solution` in the manner of scipy's ``OdeResult``."""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import Mapping

import numpy as np

from appdyn.dynamics.attitude import quat_conj, quat_mul
from appdyn.dynamics.figures import plot_attitude, plot_signals
from appdyn.dynamics.results import Result
from appdyn.dynamics.serialize import text_table

from .checks import BoundViolation, bound_violation
from .dense import DenseOutput
from .status import describe, status_name
from .propagation import (SCALE_FLOOR, Propagation, interval_integrator, propagate,
                          stack_interval_controls, state_scale)

__all__ = ["Solution", "Propagation", "DenseOutput", "BoundViolation", "interval_integrator",
           "stack_interval_controls", "state_scale", "SCALE_FLOOR", "draw_bounds"]


def draw_bounds(ax, lines, bounds) -> None:
    """Dashed horizontal lines at the finite bounds of plotted variables, each in the colour
    of its curve.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    lines : sequence of matplotlib.lines.Line2D
        The curves, one per variable (as returned by ``ax.plot``).
    bounds : array_like, shape (2, n)
        Lower and upper bounds of the ``n`` variables (``-inf``/``inf`` for none).
    """
    lo, hi = np.asarray(bounds, dtype=float)
    for line, a, b in zip(lines, lo, hi):
        for v in (a, b):
            if np.isfinite(v):
                ax.axhline(v, color=line.get_color(), linestyle="--", linewidth=0.8, alpha=0.7)


@dataclass(eq=False, repr=False)
class Solution(Result):
    """Outcome of `ocp.solve`.

    Build one from arrays with `Solution.from_arrays` (drivers that solve a restated
    problem, e.g. `ocp.polish_switches`). The re-simulation `propagation` (and what derives
    from it: `simulated_cost`, `propagation_errors`, `propagation_error`, `pointing_error`,
    `terminal_error`; also ``str()`` and `to_dict`) is computed on first use and cached on
    the instance (``functools.cached_property``); treat the fields as read-only (the arrays
    are).

    Which numbers to trust: `cost` is the collocated objective, `simulated_cost` the one the
    returned control achieves when re-simulated; they agree on a resolved solution. Judge
    the trajectory by `propagation_errors` (per state, absolute and relative to the state's
    magnitude), not by the mixed-unit `propagation_error`.

    Attributes
    ----------
    success : bool
        Verified: IPOPT returned ``Solve_Succeeded`` (its ``tol`` met; an acceptable-level
        stop counts only if a warm re-solve then succeeds), ``constraint_violation`` is at
        most the ``constraint_tol`` of `ocp.solve` (default 1e-6), so is the dense output's
        `bound_violation`, and the re-simulation agrees with the collocation to
        ``verify_tol`` (unless ``verify=False``; `ocp.checks`). A failure still carries
        IPOPT's last iterate.
    status : int
        0 for a success, else the code of the failure in `ocp.status.CODES`: IPOPT's return
        status by IPOPT's number (1 ``Solved_To_Acceptable_Level``, 2
        ``Infeasible_Problem_Detected``, -1 ``Maximum_Iterations_Exceeded``, ...) or one of
        `ocp.solve`'s own verification failures (101 ``Constraint_Tol_Not_Met``, 102
        ``Bound_Violation``, 103 ``Resimulation_Mismatch``, -200 ``Exception``); drivers on
        top add theirs (see `ocp.refine`, `problems.slew`). `ocp.status.status_name` names it.
    message : str
        What happened, in words.
    T : float [s]
        Horizon length (optimized when free).
    t0 : float [s]
    cost : float
        Objective ``phi + integral L`` of the discrete solution (unscaled), with the user's
        sign: the maximized value for a ``maximize`` problem (compare with `Problem.better`).
        The *collocated* value: on unresolved solutions (singular arcs, smeared switches) it
        can beat the true optimum; compare `simulated_cost`.
    t : ndarray, shape (n,) [s]
        Node times: ``t0`` and every state or control node of the transcription.
    x : ndarray, shape (nx, n)
        States at ``t`` (decision variables where they exist; the transcription's
        interpolant at the Hermite-Simpson-compressed midpoints).
    u : ndarray, shape (nu, n)
        Controls at ``t`` (decision variables where they exist; for Radau at ``t0`` the
        first interval's control polynomial, extrapolated).
    p : ndarray, shape (np,)
        Parameters (optimized ones and fixed ones).
    iterations : int
        IPOPT iterations.
    solve_time : float [s]
        Wall time of the IPOPT call.
    build_time : float [s]
        Wall time spent on the guess, the scaling, the NLP and the solver (the NLP and the
        solver are reused from `dynamics.cache` when a problem is solved again on the same
        mesh with the same scaling and options: `ocp.solve`).
    costates : ndarray, shape (nx, n), or None
        Costate estimates ``lambda(t)`` (``H = L + lambda . f``) at ``t`` from the defect
        multipliers (Radau only; ``None`` for the other transcriptions). They belong to the
        minimized objective: for a ``maximize`` problem ``H = -L + lambda . f``.
    transcription : Transcription
    mesh : Mesh
    problem : Problem
    constraint_violation : float
        Largest violation of any NLP constraint row or variable bound at the returned
        point, in the units of the NLP handed to IPOPT (IPOPT's "unscaled" violation: rows
        and variables divided by the scales of `ocp.scaling` — defects relative to the
        state scale, the attitude target relative to its row scale; IPOPT's internal
        scaling not applied). NaN after an evaluation error.
    multipliers : mapping of str to ndarray
        Multipliers of the unscaled constraints by block (``'defect'``, ``'path'``,
        ``'boundary'``, ``'quat_norm'``, ``'q_final'``), for ``J + nu . g`` (CasADi's sign).
    dense : DenseOutput
        Interval data and interpolant behind `sample`.
    solver_status : str
        IPOPT's return status text (``'Solve_Succeeded'``, ``'Maximum_Iterations_Exceeded'``,
        ...; ``'Exception'`` or ``'Unknown'`` when IPOPT gave none, ``'Rest_Solution'`` from
        `ocp.rest_solution`, ``''`` when no solver ran), kept when appdyn's verification turns a converged solve into a
        failure.
    backoff : mapping or None
        When `ocp.solve` (or `ocp.refine`) backed off an overshoot of its dense output
        (`ocp.solve.back_off`): ``{'margins': {name: (lower, upper)}, 'tries',
        'overshoot', 'cost_without'}`` -- the bounds moved in [their units], the re-solves,
        the overshoot that was backed off [scaled] and the objective before; else ``None``.
    nlp_point : mapping or None
        The NLP point IPOPT returned (``'key'``: the structure of the NLP it belongs to,
        ``'x'``, ``'lam_x'``, ``'lam_g'``: scaled primal and dual values), used by `ocp.solve`
        to warm start a solve of the same structure with primal *and* dual values; ``None``
        when the solution did not come from an NLP of `ocp.solve`.
    """

    success: bool
    status: int
    message: str
    T: float
    t0: float
    cost: float
    t: np.ndarray
    x: np.ndarray
    u: np.ndarray
    p: np.ndarray
    iterations: int
    solve_time: float
    build_time: float
    costates: np.ndarray | None
    transcription: object
    mesh: object
    problem: object
    constraint_violation: float
    multipliers: Mapping[str, np.ndarray]
    dense: DenseOutput = field(repr=False)
    nlp_point: Mapping | None = field(default=None, repr=False)
    solver_status: str = ""
    backoff: Mapping | None = field(default=None, repr=False)

    def __getstate__(self) -> dict:
        state = dict(self.__dict__)
        state["multipliers"] = dict(self.multipliers)
        return state

    def __setstate__(self, state: dict) -> None:
        for key in ("t", "x", "u", "p", "costates"):
            value = state.get(key)
            if isinstance(value, np.ndarray):
                value.setflags(write=False)
        self.__dict__.update(state)

    _repr_fields = ("transcription", "cost", "T", "constraint_violation", "iterations")

    @property
    def wall_time(self) -> float:
        """``build_time + solve_time`` [s]: the time `ocp.solve` spent."""
        return float(self.build_time + self.solve_time)

    def __str__(self) -> str:
        sim = self.simulated_cost
        errs = self.propagation_errors
        rows = [("success", f"{self.success} ({describe(self.status, solver_status=self.solver_status)})"),
                ("cost (collocated)", f"{self.cost:.10g}"),
                ("cost (re-simulated)", f"{sim:.10g} (re-simulated - collocated: "
                                        f"{sim - self.cost:.3g})"),
                ("propagation error (scaled)", _worst_state(errs)),
                ("bound violation (scaled)", _worst_bound(self.bound_violation)),
                ("T [s]", f"{self.T:.10g}"),
                ("mesh", f"{self.transcription.name}, N = {self.mesh.N}"),
                ("constraint violation", f"{self.constraint_violation:.3g}"),
                ("IPOPT iterations", f"{self.iterations}"),
                ("build / solve time [s]", f"{self.build_time:.3g} / {self.solve_time:.3g}"),
                ("message", self.message)]
        return text_table("Optimal control solution", rows)

    def __getitem__(self, name: str) -> np.ndarray:
        """The trajectory of a state or control by name, at the node times ``t``.

        A state name gives its row of ``x``; a control name its row of ``u``. Both are
        sampled at ``t`` (the node times): ``u`` holds the controls there (decision
        variables at the transcription's control nodes, its interpolant at the other
        nodes; see the ``u`` attribute). Use `sample` for other times.

        Parameters
        ----------
        name : str
            One of ``problem.model.states`` or ``problem.model.controls``.

        Returns
        -------
        ndarray, shape (n,)

        Raises
        ------
        KeyError
            If ``name`` is neither a state nor a control (the message lists them).

        Examples
        --------
        >>> from appdyn import ocp
        >>> from appdyn.ocp.examples import min_energy
        >>> sol = ocp.solve(min_energy(), N=10)  # x'' = u, rest to rest: u = 6 - 12 t
        >>> sol["v"].shape == sol.t.shape, round(float(sol["u"][0]), 6), round(float(sol["x"][-1]), 6)
        (True, 6.0, 1.0)
        """
        model = self.problem.model
        if isinstance(name, str):
            if name in model.states:
                return self.x[model.states.index(name)]
            if name in model.controls:
                return self.u[model.controls.index(name)]
        raise KeyError(f"no state or control named {name!r}; the states are {model.states}, "
                       f"the controls {model.controls}")

    def to_dict(self) -> dict:
        """Summary and trajectories as plain Python (``x``, ``u`` by name at the nodes ``t``);
        JSON-ready through `to_json`.

        Besides the fields, ``'simulated_cost'`` (`simulated_cost`) and
        ``'propagation_errors'`` (`propagation_errors`: ``{state: {'absolute': ...,
        'scaled': ...}}``) from the re-simulation, which is run (once, `propagation`) for it,
        and ``'bound_violation'`` (`bound_violation`: ``{'max': ..., 'by_name': {...},
        'name': ..., 'time': ...}``).
        """
        model = self.problem.model
        errs = self.propagation_errors
        return {
            "success": bool(self.success), "status": int(self.status),
            "solver_status": self.solver_status, "message": self.message, "cost": self.cost,
            "simulated_cost": self.simulated_cost,
            "propagation_errors": {k: {"absolute": a, "scaled": r} for k, (a, r) in errs.items()},
            "bound_violation": {"max": self.bound_violation.max,
                                "by_name": dict(self.bound_violation.by_name),
                                "name": self.bound_violation.name,
                                "time": self.bound_violation.time},
            "T": self.T, "t0": self.t0,
            "constraint_violation": self.constraint_violation,
            "transcription": self.transcription.name, "N": int(self.mesh.N),
            "iterations": int(self.iterations), "solve_time": self.solve_time,
            "build_time": self.build_time, "t": self.t,
            "x": dict(zip(model.states, self.x)), "u": dict(zip(model.controls, self.u)),
            "p": dict(zip(model.params, self.p)),
        }

    def plot(self, ax=None, *, n: int = 400):
        """The solution against time from the dense output: states and controls in one
        labelled subplot per unit (`Model.units`), the finite bounds dashed; an attitude
        model (a slew) as quaternion, body rates, controls and the rotation path
        (`dynamics.figures.plot_attitude`).

        Parameters
        ----------
        ax : matplotlib.axes.Axes or matplotlib.figure.Figure, optional
            Draw on these axes (an attitude figure divides its slot into panels) or on this
            figure; by default on a new `matplotlib.figure.Figure` (no pyplot).
        n : int, optional
            Samples of the dense output.

        Returns
        -------
        matplotlib.figure.Figure
        """
        model = self.problem.model
        ts = np.linspace(self.t0, self.t0 + self.T, n) if self.T > 0 else np.array([self.t0])
        xs, us = (np.atleast_2d(v) for v in self.sample(ts))
        verdict = "" if self.success else f" (not converged: {status_name(self.status)})"
        title = (f"{model.name}: {self.transcription.name}, N = {self.mesh.N}, "
                 f"T = {self.T:.6g} s, cost {self.cost:.6g}{verdict}")
        if model.attitude is not None:
            return plot_attitude(ts, xs, us, model, u_bounds=self.problem.u_bounds, ax=ax,
                                 title=title)
        lo, hi = np.asarray(self.problem.u_bounds, dtype=float)
        bounds = {**dict(model.bounds), **{c: (a, b) for c, a, b in zip(model.controls, lo, hi)}}
        series = {**dict(zip(model.states, xs)), **dict(zip(model.controls, us))}
        return plot_signals(ts, series, model.units, bounds=bounds, ax=ax, title=title)

    # ----------------------------------------------------------- construction
    @classmethod
    def from_arrays(cls, problem, transcription, mesh, X, U, p, T, *, cost: float,
                    success: bool = True, status: int = 0, message: str = "",
                    iterations: int = 0, solve_time: float = 0.0, build_time: float = 0.0,
                    constraint_violation: float = float("nan"),
                    multipliers: Mapping[str, np.ndarray] | None = None, solver_status: str = "",
                    **extra) -> "Solution":
        """A solution of ``problem`` from the values at the transcription's nodes.

        Parameters
        ----------
        problem : Problem
        transcription : Transcription
        mesh : Mesh
        X : array_like, shape (nx, 1 + N m_x)
            States at the state nodes (``t0``, then each interval's own state nodes).
        U : array_like, shape (nu, n_u)
            Controls at the control nodes (a start value first when the transcription has
            one, then each interval's own control nodes).
        p : array_like, shape (np,)
        T : float [s]
        cost, success, status, message, iterations, solve_time, build_time, constraint_violation
            As the attributes of the same name (``status`` an int).
        solver_status : str, optional
            IPOPT's return status text (default ``''``: no solver ran).
        multipliers : mapping of str to ndarray, optional
            By block, as `ocp.nlp.Discretization.multipliers`; costates follow from its
            ``'defect'`` entry (Radau). Default: none (empty mapping, no costates).
        **extra
            Further fields of a subclass (``info`` of `ocp.RefinedSolution`).

        Returns
        -------
        Solution (or the subclass it is called on)
        """
        X, U = np.asarray(X, dtype=float), np.asarray(U, dtype=float)
        p, T, tr = np.array(p, dtype=float).reshape(-1), float(T), transcription
        dense = DenseOutput(tr, mesh, problem.model, X, U, p, T, problem.t0)
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
        mult = dict(multipliers) if multipliers is not None else {}
        costates = tr.costates(mult["defect"], mesh) if "defect" in mult else None
        for a in (t, x, u, p):
            a.setflags(write=False)
        if costates is not None:
            costates.setflags(write=False)
        return cls(success=bool(success), status=int(status), message=str(message), T=T,
                   t0=problem.t0, cost=float(cost), t=t, x=x, u=u, p=p, iterations=int(iterations),
                   solve_time=float(solve_time), build_time=float(build_time), costates=costates,
                   transcription=tr, mesh=mesh, problem=problem,
                   constraint_violation=float(constraint_violation), multipliers=mult,
                   dense=dense, solver_status=str(solver_status), **extra)

    # ----------------------------------------------------------------- dense
    def sample(self, t):
        """States and controls at arbitrary times, interpolated like the transcription.

        Radau: Lagrange polynomials of the interval (degree ``d`` for ``x``, ``d - 1`` for
        ``u``); trapezoid: linear ``x`` and ``u``; Hermite-Simpson: cubic Hermite ``x``,
        quadratic ``u``. At a mesh point the interval on the left is used (controls may jump
        there in Radau).

        Parameters
        ----------
        t : float or array_like, shape (m,) [s]
            Times in ``[t0, t0 + T]``.

        Returns
        -------
        x : ndarray, shape (nx,) or (nx, m)
        u : ndarray, shape (nu,) or (nu, m)

        Raises
        ------
        ValueError
            If ``t`` is not finite or outside the horizon (no extrapolation).

        Examples
        --------
        >>> from appdyn import ocp
        >>> from appdyn.ocp.examples import min_energy
        >>> energy = min_energy()  # x'' = u from rest at 0 to rest at 1 in T = 1 s
        >>> sol = ocp.solve(energy, N=10)
        >>> t = [0.0, 0.5, 1.0]
        >>> x, u = sol.sample(t)  # x = 3 t^2 - 2 t^3, v = 6 t - 6 t^2, u = 6 - 12 t
        >>> x.round(6) + 0.0, u.round(6) + 0.0
        (array([[0. , 0.5, 1. ],
               [0. , 1.5, 0. ]]), array([[ 6.,  0., -6.]]))
        """
        tq = np.asarray(t, dtype=float)
        scalar = tq.ndim == 0
        tq = tq.reshape(-1)
        if not np.all(np.isfinite(tq)):
            raise ValueError("`t` must be finite")
        lo, hi = self.t0, self.t0 + self.T
        slack = 1e-12 * max(abs(lo), abs(hi), self.T)
        if tq.size and (tq.min() < lo - slack or tq.max() > hi + slack):
            raise ValueError(f"`t` must lie in the horizon [{lo}, {hi}], got [{tq.min()}, {tq.max()}]")
        k, s = self.dense.locate(tq)
        x, u = self.dense.eval(k, s)
        return (x[:, 0], u[:, 0]) if scalar else (x, u)

    # ----------------------------------------------------------- diagnostics
    @cached_property
    def bound_violation(self) -> BoundViolation:
        """Largest violation of the state and control bounds and of the path constraints by
        the dense output, per variable (path-constraint row) in units of its scale, and where
        it is worst (`ocp.checks.BoundViolation`).

        Evaluated on `ocp.checks.bound_grid`: in every mesh interval 17 equally spaced points
        (``sigma = 0, 1/16, ..., 1``; both one-sided limits at a mesh point) and the
        transcription's nodes -- the interpolant `sample` returns and `propagate` replays.
        The scale of a variable is ``max(|finite bounds|, max_n |v(t_n)|, 1e-6)``, of a path
        row ``max(|finite bounds|, its largest |g| on the grid, 1e-6)``. `ocp.solve`
        requires ``bound_violation.max <= constraint_tol`` for a success. Computed on first
        use and cached.

        Examples
        --------
        >>> from appdyn import ocp
        >>> from appdyn.ocp.examples import min_time
        >>> sol = ocp.solve(min_time(), N=10, control="linear")  # |u| <= 1: bang-bang
        >>> sol.bound_violation.max, sorted(sol.bound_violation.by_name)
        (0.0, ['u'])
        """
        return bound_violation(self.dense, self.problem, self.x, self.u, p=self.p)

    @property
    def quaternion_norm_error(self) -> float | None:
        """``max | |q| - 1 |`` over the nodes (attitude models), else ``None``."""
        att = self.problem.model.attitude
        if att is None:
            return None
        q = self.x[att[0]:att[0] + 4]
        return float(np.max(np.abs(np.linalg.norm(q, axis=0) - 1.0)))

    def propagate(self, *, rtol: float = 1e-12, atol: float = 1e-12) -> Propagation:
        """Re-simulate the dense control from the initial state with CVODES.

        The control is the transcription's own interpolant (as in `sample`): polynomial
        within each mesh interval, possibly jumping at the mesh points (Radau, bang-bang
        solutions). Each interval is therefore integrated by a fresh CVODES solve (one
        CasADi ``mapaccum`` over the intervals, the state handed on), so no integrator steps
        across a jump. CVODES runs its Adams-Moulton method (the re-simulated flow is not
        stiff; BDF where Adams fails: `ocp.propagation.METHODS`). ``rtol``/``atol`` are
        CVODES' local tolerances: the global integration error is typically 10-100x larger,
        still far below the collocation errors this is meant to reveal.

        The running cost ``L`` (``problem.lagrange``) is integrated along as a CVODES
        quadrature and the terminal cost ``phi`` (``problem.mayer``) is evaluated at the
        re-simulated final state: `Propagation.cost` is the objective the returned control
        achieves, to compare with the collocated `cost` (`simulated_cost`).

        Parameters
        ----------
        rtol, atol : float
            CVODES tolerances, in (0, 1).

        Returns
        -------
        Propagation
            ``success=False`` (with NaN states and cost) if CVODES fails; never raises for
            that.

        Raises
        ------
        ValueError
            If ``rtol`` or ``atol`` is not a float in (0, 1).

        Examples
        --------
        >>> from appdyn import ocp
        >>> from appdyn.ocp.examples import min_energy
        >>> sol = ocp.solve(min_energy(), N=4)  # Bryson & Ho: J = 6
        >>> prop = sol.propagate()
        >>> prop.success, round(prop.cost, 8), bool(prop.relative_error.max() < 1e-9)
        (True, 6.0, True)
        """
        return propagate(self, rtol=rtol, atol=atol)

    @cached_property
    def propagation(self) -> Propagation:
        """`propagate` with its default tolerances, computed on first use and cached (the
        one re-simulation behind `propagation_error`, `pointing_error` and
        `terminal_error`)."""
        return self.propagate()

    @property
    def pointing_error(self) -> float | None:
        """Attitude error at the end of the *re-simulated* trajectory [rad].

        The rotation angle ``2 atan2(|v|, |s|)`` of ``q_final^* (x) q_sim(tf) / |q_sim(tf)|``
        (``v``, ``s`` its vector and scalar parts), with ``q_sim`` from `propagation`: the
        returned control applied to the initial state, integrated independently of the
        collocation. ``None`` without a ``q_final``; NaN if the re-simulation failed.
        """
        if self.problem.q_final is None:
            return None
        prop = self.propagation
        if not prop.success:
            return float("nan")
        iq = self.problem.model.attitude[0]
        q = prop.x[iq:iq + 4, -1]
        n = np.linalg.norm(q)
        if not (np.isfinite(n) and n > 0):
            return float("nan")
        e = np.asarray(quat_mul(quat_conj(np.asarray(self.problem.q_final, dtype=float)), q / n),
                       dtype=float)
        return float(2.0 * np.arctan2(np.linalg.norm(e[:3]), abs(e[3])))

    @property
    def terminal_error(self) -> np.ndarray:
        """``|x_sim(tf) - x_final|`` per state, shape (nx,) [state units], from the
        re-simulated trajectory (`propagation`); NaN for final states the problem leaves free
        (and everywhere if the re-simulation failed)."""
        prop = self.propagation
        xf = np.asarray(self.problem.x_final, dtype=float)
        if not prop.success:
            return np.full(xf.size, np.nan)
        return np.abs(prop.x[:, -1] - xf)

    @property
    def propagation_error(self) -> float:
        """``max |x_propagated - x|`` over states and nodes, from `propagate` with its default
        tolerances (computed on first access).

        The maximum is taken over states of *different units* (an error of 0.34 m on an
        altitude of 1e5 m and one of 1e-3 rad/s on a rate are compared as numbers): use
        `propagation_errors` (per state, absolute and relative to the state's magnitude) or
        `Propagation.relative_error` to judge accuracy. 0.0 without states.
        """
        err = self.propagation.error
        return float(np.max(err)) if err.size else 0.0

    @property
    def propagation_errors(self) -> dict:
        """Per-state propagation error: ``{state name: (absolute, scaled)}``.

        ``absolute`` is ``max_n |x_sim,i(t_n) - x_i(t_n)|`` [state units] (`Propagation.error`),
        ``scaled`` is that divided by the state's typical magnitude
        ``max(max_n |x_i(t_n)|, SCALE_FLOOR)`` [-] (`Propagation.relative_error`; `SCALE_FLOOR`
        = 1e-6 state units), so 0.34 m on a 1e5 m altitude reads 3.4e-6. Both NaN if the
        re-simulation failed.

        Returns
        -------
        dict of str to (float, float)
        """
        prop = self.propagation
        rel = prop.relative_error
        return {name: (float(prop.error[i]), float(rel[i]))
                for i, name in enumerate(self.problem.model.states)}

    @property
    def simulated_cost(self) -> float:
        """The objective achieved by re-simulating the returned control (`Propagation.cost`)
        [cost units], with the user's sign like `cost`; NaN if the re-simulation failed.

        `cost` is the collocated objective (the discrete NLP's value); this one integrates
        the dynamics and the running cost of the dense control with CVODES from ``x(t0)``
        and evaluates the terminal cost at the re-simulated final state. On a well
        resolved solution the two agree to the discretization error; where they differ
        (singular arcs, chattering, unresolved switches: the collocated cost may even beat
        the true optimum) this is the value the returned control actually achieves, provided
        the re-simulated trajectory still meets the constraints (`terminal_error`,
        `propagation_errors`).
        """
        prop = self.propagation
        return float(prop.cost) if prop.success else float("nan")


def _worst_bound(bv: BoundViolation) -> str:
    """``'0.93 (u1 at t = 3.21 s)'`` or ``'0 (within bounds)'``."""
    if bv.name is None:
        return "0 (within bounds)" if bv.by_name else "none (no bounds)"
    return f"{bv.max:.3g} ({bv.name} at t = {bv.time:.6g} s)"


def _worst_state(errs: Mapping[str, tuple]) -> str:
    """``'3.4e-06 (h; absolute 0.34)'``: the largest scaled propagation error and its state."""
    if not errs:
        return "none (no states)"
    name, (ab, rel) = max(errs.items(), key=lambda kv: -np.inf if np.isnan(kv[1][1]) else kv[1][1])
    if np.isnan(rel):
        return "nan (re-simulation failed)"
    return f"{rel:.3g} ({name}; absolute {ab:.3g})"


