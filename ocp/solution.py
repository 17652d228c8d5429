"""The result of `ocp.solve`: a `Solution` in the manner of scipy's ``OdeResult``."""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import Mapping

import casadi as ca
import numpy as np

from dynamics.attitude import quat_conj, quat_mul
from dynamics.figures import finish_figure, new_figure
from dynamics.serialize import text_table, to_json

from .cached import cached, function_key

__all__ = ["Solution", "Propagation", "DenseOutput", "interval_integrator", "stack_interval_controls"]


@dataclass(frozen=True)
class Propagation:
    """Re-simulation of a solution's control (see `Solution.propagate`).

    Attributes
    ----------
    t : ndarray, shape (n,) [s]
        The solution's node times.
    x : ndarray, shape (nx, n)
        States integrated from ``x[:, 0]`` of the solution under its dense control.
    error : ndarray, shape (nx,)
        Largest ``|x_propagated - x_collocated|`` of each state over the nodes [state units]
        (NaN after a failure).
    success : bool
    message : str
    """

    t: np.ndarray
    x: np.ndarray
    error: np.ndarray
    success: bool
    message: str


class DenseOutput:
    """Interval data of a solution and the transcription's interpolant (its dense output).

    Attributes
    ----------
    xs : ndarray, shape (nx, N)
        State at each interval start.
    Xo : ndarray, shape (nx, N, m_x)
        States at the interval's own state nodes.
    us : ndarray, shape (nu, N)
        Control at each interval start (zeros when the transcription has none there).
    Uo : ndarray, shape (nu, N, m_u)
        Controls at the interval's own control nodes.
    p : ndarray, shape (np,)
    h : ndarray, shape (N,) [s]
        Interval lengths.
    t_breaks : ndarray, shape (N + 1,) [s]
        Mesh points in time.
    """

    def __init__(self, transcription, mesh, model, X, U, p, T, t0):
        N = mesh.N
        tr = transcription
        m_x, m_u = tr.x_sigma.size, tr.u_sigma.size
        self.transcription, self.mesh, self.model = tr, mesh, model
        self.nx, self.nu, self.N, self.m_x, self.m_u = model.nx, model.nu, N, m_x, m_u
        self.xs = X[:, 0:N * m_x:m_x]
        self.Xo = X[:, 1:].reshape(model.nx, N, m_x)
        if tr.u_at_start:
            self.us, Uo = U[:, 0:N * m_u:m_u], U[:, 1:]
        else:
            self.us, Uo = np.zeros((model.nu, N)), U
        self.Uo = Uo.reshape(model.nu, N, m_u)
        self.p = p
        self.h = T * mesh.fractions
        self.t_breaks = t0 + T * mesh.breaks
        self.t_breaks[-1] = t0 + T
        self._interp = tr.interpolant(model.f)

    @property
    def interp(self) -> ca.Function:
        """The transcription's interpolant Function (`Transcription.interpolant`; rebuilt on
        first use after unpickling, from the cache when present)."""
        fun = self._interp
        if fun is None:
            fun = self._interp = self.transcription.interpolant(self.model.f)
        return fun

    def __getstate__(self) -> dict:
        state = dict(self.__dict__)
        state["_interp"] = None  # a cached CasADi Function: rebuilt on load
        return state

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)

    def eval(self, k: np.ndarray, s: np.ndarray):
        """``(x (nx, M), u (nu, M))`` in intervals ``k`` at ``sigma = s``."""
        M = k.size
        if M == 0:
            return np.zeros((self.nx, 0)), np.zeros((self.nu, 0))
        args = [self.xs[:, k], self.Xo[:, k, :].reshape(self.nx, M * self.m_x),
                self.us[:, k], self.Uo[:, k, :].reshape(self.nu, M * self.m_u),
                self.h[k][None, :], self.p[:, None], s[None, :]]
        fun = self.interp.map(M, [False] * 5 + [True, False], [False, False]) if M > 1 else self.interp
        x, u = fun(*args)
        return np.asarray(x).reshape(self.nx, M), np.asarray(u).reshape(self.nu, M)

    def locate(self, t: np.ndarray):
        """Interval index (intervals are ``(t_k, t_k+1]``, ``t0`` in the first) and sigma."""
        k = np.clip(np.searchsorted(self.t_breaks, t, side="left") - 1, 0, self.N - 1)
        h = self.h[k]
        s = np.divide(t - self.t_breaks[k], h, out=np.zeros(np.shape(t)), where=h > 0)
        return k, np.clip(s, 0.0, 1.0)


@dataclass(eq=False)
class Solution:
    """Outcome of `ocp.solve`.

    Build one from arrays with `Solution.from_arrays` (drivers that solve a restated
    problem, e.g. `ocp.polish_switches`). The re-simulation `propagation` (and what derives
    from it: `propagation_error`, `pointing_error`, `terminal_error`) is computed on first
    use and cached on the instance (``functools.cached_property``); treat the fields as
    read-only (the arrays are).

    Attributes
    ----------
    success : bool
        Verified: IPOPT returned ``Solve_Succeeded`` (its ``tol`` met; an acceptable-level
        stop counts only if a warm re-solve then succeeds) *and* ``constraint_violation``
        is at most the ``constraint_tol`` of `ocp.solve` (default 1e-6). A failure still
        carries IPOPT's last iterate.
    status : str
        IPOPT's return status (``'Solve_Succeeded'``, ``'Solved_To_Acceptable_Level'``,
        ``'Infeasible_Problem_Detected'``, ``'Maximum_Iterations_Exceeded'``, ...) or one of
        `ocp.solve`'s own: ``'Constraint_Tol_Not_Met'``, ``'Exception'``,
        ``'Rest_Solution'``; drivers on top add theirs (see `ocp.refine`,
        `problems.slew`).
    message : str
        What happened, in words.
    T : float [s]
        Horizon length (optimized when free).
    t0 : float [s]
    cost : float
        Objective ``phi + integral L`` of the discrete solution (unscaled), with the user's
        sign: the maximized value for a ``maximize`` problem (compare with `Problem.better`).
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
    nlp_point : mapping or None
        The NLP point IPOPT returned (``'key'``: the structure of the NLP it belongs to,
        ``'x'``, ``'lam_x'``, ``'lam_g'``: scaled primal and dual values), used by `ocp.solve`
        to warm start a solve of the same structure with primal *and* dual values; ``None``
        when the solution did not come from an NLP of `ocp.solve`.
    """

    success: bool
    status: str
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

    def __repr__(self) -> str:
        return (f"{type(self).__name__}(success={self.success}, status={self.status!r}, "
                f"cost={self.cost:.10g}, T={self.T:.10g}, "
                f"constraint_violation={self.constraint_violation:.3g}, "
                f"transcription={self.transcription.name!r}, N={self.mesh.N}, "
                f"iterations={self.iterations}, solve_time={self.solve_time:.3g} s)")

    def __str__(self) -> str:
        rows = [("success", f"{self.success} ({self.status})"),
                ("cost", f"{self.cost:.10g}"),
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
        >>> import ocp
        >>> from ocp.examples import min_energy
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
        JSON-ready through `to_json`. The re-simulation is not run for it."""
        model = self.problem.model
        return {
            "success": bool(self.success), "status": self.status, "message": self.message,
            "cost": self.cost, "T": self.T, "t0": self.t0,
            "constraint_violation": self.constraint_violation,
            "transcription": self.transcription.name, "N": int(self.mesh.N),
            "iterations": int(self.iterations), "solve_time": self.solve_time,
            "build_time": self.build_time, "t": self.t,
            "x": dict(zip(model.states, self.x)), "u": dict(zip(model.controls, self.u)),
            "p": dict(zip(model.params, self.p)),
        }

    def to_json(self) -> str:
        """`to_dict` as strict JSON (non-finite numbers as ``null``)."""
        return to_json(self.to_dict())

    def plot(self, path=None, *, fig=None, n=400):
        """States (top) and controls (bottom) against time, from the dense output.

        Parameters
        ----------
        path : str, optional
            Also save the figure there (PNG unless the suffix is .pdf or .svg).
        fig : matplotlib.figure.Figure, optional
            Draw on this figure; by default a new one (no pyplot, the backend untouched).
        n : int, optional
            Samples of the dense output.

        Returns
        -------
        matplotlib.figure.Figure
        """
        model = self.problem.model
        fig = new_figure((8.0, 6.5)) if fig is None else fig
        top, bottom = fig.subplots(2, 1, sharex=True)
        ts = np.linspace(self.t0, self.t0 + self.T, n) if self.T > 0 else np.array([self.t0])
        xs, us = self.sample(ts)
        for name, row in zip(model.states, np.atleast_2d(xs)):
            top.plot(ts, row, label=name)
        for name, row in zip(model.controls, np.atleast_2d(us)):
            bottom.plot(ts, row, label=name)
        top.set(ylabel="states", title=f"{self.transcription.name}, N = {self.mesh.N}: "
                f"cost {self.cost:.6g}, success {self.success}")
        bottom.set(xlabel="t [s]", ylabel="controls")
        for ax in (top, bottom):
            ax.grid(True, alpha=0.3)
            ax.legend(fontsize=8)
        return finish_figure(fig, path)

    # ----------------------------------------------------------- construction
    @classmethod
    def from_arrays(cls, problem, transcription, mesh, X, U, p, T, *, cost: float,
                    success: bool = True, status: str = "Solve_Succeeded", message: str = "",
                    iterations: int = 0, solve_time: float = 0.0, build_time: float = 0.0,
                    constraint_violation: float = float("nan"),
                    multipliers: Mapping[str, np.ndarray] | None = None, **extra) -> "Solution":
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
            As the attributes of the same name.
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
        return cls(success=bool(success), status=str(status), message=str(message), T=T,
                   t0=problem.t0, cost=float(cost), t=t, x=x, u=u, p=p, iterations=int(iterations),
                   solve_time=float(solve_time), build_time=float(build_time), costates=costates,
                   transcription=tr, mesh=mesh, problem=problem,
                   constraint_violation=float(constraint_violation), multipliers=mult,
                   dense=dense, **extra)

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
        >>> import ocp
        >>> from ocp.examples import min_energy
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
        across a jump. ``rtol``/``atol`` are CVODES' local tolerances: the global integration
        error is typically 10-100x larger, still far below the collocation errors this is
        meant to reveal.

        Parameters
        ----------
        rtol, atol : float
            CVODES tolerances, in (0, 1).

        Returns
        -------
        Propagation
            ``success=False`` (with NaN states) if CVODES fails; never raises for that.
        """
        for name, v in (("rtol", rtol), ("atol", atol)):
            if isinstance(v, bool) or not (isinstance(v, (int, float)) and 0 < v < 1):
                raise ValueError(f"`{name}` must be a float in (0, 1), got {v!r}")
        d = self.dense
        nx = self.problem.model.nx
        try:
            run = _propagator(self, rtol, atol)
            pars = np.concatenate([d.us, stack_interval_controls(d.Uo, np.arange(d.N)), d.h[None, :],
                                   np.repeat(self.p[:, None], d.N, axis=1)], axis=0)
            _, xall = run(self.x[:, 0], pars)
            xp = np.concatenate([self.x[:, :1], np.asarray(xall)], axis=1)
        except RuntimeError as exc:
            nan = np.full((nx, self.t.size), np.nan)
            return Propagation(self.t, nan, np.full(nx, np.nan), False, f"cvodes failed: {exc}")
        if not np.all(np.isfinite(xp)):
            return Propagation(self.t, xp, np.full(nx, np.nan), False, "cvodes: non-finite state")
        err = np.max(np.abs(xp - self.x), axis=1)
        return Propagation(self.t, xp, err, True, f"cvodes per mesh interval, rtol {rtol:g}, atol {atol:g}")

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
        """``max |x_propagated - x|`` over states and nodes [mixed state units], from
        `propagate` with its default tolerances (computed on first access)."""
        err = self.propagation.error
        return float(np.max(err)) if err.size else 0.0


def interval_integrator(sol: "Solution", grid, rtol: float, atol: float) -> ca.Function:
    """CVODES over one mesh interval in normalized time ``s in [0, 1]`` under the solution's
    own control polynomial, with outputs at the normalized times ``grid``.

    Inputs ``x0`` (nx,) and ``p`` = ``[u_start, vec(U_interval), h, p_model]``; output ``xf``
    (nx, len(grid)). Shared by `Solution.propagate` and mesh refinement (`ocp.refine`);
    built once per transcription, model right-hand side, grid and tolerances (`ocp.cached`).
    """
    tr, f = sol.transcription, sol.problem.model.f
    grid = tuple(float(v) for v in grid)
    return cached("interval_integrator", (tr, function_key(f), grid, float(rtol), float(atol)),
                  lambda: _build_interval_integrator(sol, grid, rtol, atol), keepalive=f)


def _build_interval_integrator(sol, grid, rtol, atol):
    d = sol.dense
    model = sol.problem.model
    nx, nu = model.nx, model.nu
    sym = ca.SX if d.interp.is_a("SXFunction") else ca.MX
    x, s = sym.sym("x", nx), sym.sym("s")
    us, U = sym.sym("us", nu), sym.sym("U", nu, d.m_u)
    h, p = sym.sym("h"), sym.sym("p", model.np)
    _, u = d.interp(sym.zeros(nx), sym.zeros(nx, d.m_x), us, U, h, p, s)
    data = ca.vertcat(us, ca.vec(U), h, p)
    return ca.integrator("interval", "cvodes", {"x": x, "p": data, "t": s, "ode": h * model.f(x, u, p)},
                         0.0, [float(v) for v in grid],
                         {"abstol": atol, "reltol": rtol, "max_num_steps": 100000})


def _propagator(sol: "Solution", rtol: float, atol: float) -> ca.Function:
    """``(x0 (nx,), data (.., N)) -> (xf, x at the owned nodes of every interval)``: the
    interval integrators chained by ``mapaccum`` over the ``N`` intervals (cached)."""
    tr, f, N = sol.transcription, sol.problem.model.f, sol.dense.N

    def build():
        integ = interval_integrator(sol, tr.node_sigma, rtol, atol)
        x0 = ca.MX.sym("x0", f.numel_in(0))
        dat = ca.MX.sym("data", integ.numel_in("p"))
        xs = integ(x0=x0, p=dat)["xf"]
        return ca.Function("step", [x0, dat], [xs[:, -1], xs]).mapaccum("propagate", N)

    return cached("propagator", (tr, function_key(f), N, float(rtol), float(atol)), build,
                  keepalive=f)


def stack_interval_controls(Uo: np.ndarray, k: np.ndarray) -> np.ndarray:
    """``vec(U_k)`` (column-major, as ``casadi.vec``) of intervals ``k``: shape (nu m_u, len(k))."""
    nu, _, m_u = Uo.shape
    blocks = Uo[:, k, :]  # (nu, K, m_u)
    return blocks.transpose(2, 0, 1).reshape(m_u * nu, k.size)
