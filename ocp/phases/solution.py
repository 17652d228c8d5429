"""`MultiPhaseSolution`: the result of `ocp.solve_phases`."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping

import numpy as np

from appdyn.dynamics.figures import plot_signals
from appdyn.dynamics.results import Result

from ..status import status_name

__all__ = ["MultiPhaseSolution"]


@dataclass(frozen=True, eq=False, repr=False)
class MultiPhaseSolution(Result):
    """The solution of a `MultiPhaseProblem`.

    Attributes
    ----------
    success : bool
        ``True`` only when IPOPT returned ``Solve_Succeeded`` and the largest violation of
        any row -- every phase's rows, every link and event row -- and of every variable
        bound, in NLP units, is at most ``constraint_tol`` (as for `ocp.solve`).
    status : int
        0 for a success, else the failure's code in `ocp.status.CODES` (as `ocp.Solution`).
    message : str
    cost : float
        ``J = Phi(ends) + sum of the phases' own costs`` (the user's sign).
    phases : tuple of ocp.Solution
        One per phase, on its own mesh, with absolute times (``phases[i].t0`` = start of
        phase i); each carries the overall ``success``/``status``.
    t0, tf : ndarray, shape (n_phases,) [s]
        Start and end of each phase.
    ends : ndarray, shape (n_E,)
        Physical phase ends ``[x0, xf, p, T]`` of every phase.
    events : ndarray, shape (n_e,)
        Values of the link rows, then the event rows (physical units).
    event_violation : float
        Largest violation of the link and event bounds, physical units.
    constraint_violation : float
        Largest violation in NLP units (what ``success`` checks).
    iterations : int
    solve_time, build_time : float [s]
    info : mapping
        Refinement record when refined: ``'rounds'`` (per NLP solved: ``(intervals per
        phase, largest estimated interval error per phase, cost, iterations)``),
        ``'converged'``, and the totals over the rounds ``'solve_time'``, ``'build_time'``,
        ``'iterations'`` (the attributes of those names are the last round's).
    problem : MultiPhaseProblem
    solver_status : str
        IPOPT's return status text (as `ocp.Solution.solver_status`).
    """

    success: bool
    status: int
    message: str
    cost: float
    phases: tuple
    t0: np.ndarray
    tf: np.ndarray
    ends: np.ndarray
    events: np.ndarray
    event_violation: float
    constraint_violation: float
    iterations: int
    solve_time: float
    build_time: float
    problem: object = field(repr=False)
    info: Mapping = field(default_factory=dict, repr=False)
    nlp_point: Mapping | None = field(default=None, repr=False)
    solver_status: str = ""

    _repr_fields = ("cost", "phases", "tf", "constraint_violation", "iterations")

    @property
    def wall_time(self) -> float:
        """``build_time + solve_time`` of the last round [s]."""
        return float(self.build_time + self.solve_time)

    def __str__(self) -> str:
        lines = [f"{self.problem.name or 'multi-phase problem'}: {self.message}",
                 f"  cost {self.cost:.10g}; constraint violation {self.constraint_violation:.2g}; "
                 f"{self.iterations} iterations, build {self.build_time:.3g} s, "
                 f"solve {self.solve_time:.3g} s"]
        for i, sol in enumerate(self.phases):
            lines.append(f"  {self.problem.phase_name(i)}: t = {self.t0[i]:.6g} .. {self.tf[i]:.6g} s, "
                         f"N = {sol.mesh.N}")
        return "\n".join(lines)

    @property
    def T(self) -> np.ndarray:
        """Duration of each phase [s], shape (n_phases,)."""
        return self.tf - self.t0

    def __getitem__(self, name: str) -> np.ndarray:
        """A state or control by name over all phases (node times of `t` concatenated),
        shape (sum of the phases' node counts,); every phase's model must have it."""
        parts = []
        for i, sol in enumerate(self.phases):
            try:
                parts.append(sol[name])
            except (KeyError, ValueError) as exc:
                raise KeyError(f"{name!r} is not a state or control of phase {i} "
                               f"({self.problem.phase_name(i)})") from exc
        return np.concatenate(parts)

    @property
    def t(self) -> np.ndarray:
        """Node times of all phases, concatenated (a phase boundary appears twice)."""
        return np.concatenate([sol.t for sol in self.phases])

    def phase_at(self, t: float) -> int:
        """Index of the phase that holds time ``t`` (the later one at a boundary)."""
        t = float(t)
        if not self.t0[0] <= t <= self.tf[-1]:
            raise ValueError(f"`t` = {t} lies outside [{self.t0[0]}, {self.tf[-1]}]")
        return int(min(np.searchsorted(self.t0, t, side="right") - 1, len(self.phases) - 1))

    def sample(self, name: str, t) -> np.ndarray:
        """State or control ``name`` at times ``t`` (each time in its phase), shape ``t``'s."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        out = np.empty(t.shape)
        for k, tk in np.ndenumerate(t):
            sol = self.phases[self.phase_at(tk)]
            x, u = sol.sample(np.array([tk]))
            model = sol.problem.model
            if name in model.states:
                out[k] = x[model.states.index(name), 0]
            elif name in model.controls:
                out[k] = u[model.controls.index(name), 0]
            else:
                raise KeyError(f"{name!r} is not a state or control at t = {tk}")
        return out

    def to_dict(self) -> dict:
        """Plain-data summary (JSON-ready): status, cost, times, and per phase its nodes."""
        return {
            "success": self.success, "status": int(self.status),
            "solver_status": self.solver_status, "message": self.message,
            "cost": self.cost, "iterations": self.iterations, "solve_time": self.solve_time,
            "build_time": self.build_time, "constraint_violation": self.constraint_violation,
            "event_violation": self.event_violation,
            "phases": [{"name": self.problem.phase_name(i), "t0": float(self.t0[i]),
                        "tf": float(self.tf[i]), "N": int(sol.mesh.N),
                        "states": list(sol.problem.model.states),
                        "controls": list(sol.problem.model.controls),
                        "t": sol.t.tolist(), "x": sol.x.tolist(), "u": sol.u.tolist()}
                       for i, sol in enumerate(self.phases)],
        }

    def plot(self, ax=None, *, n: int = 200):
        """The states and controls every phase shares, against time, one labelled subplot per
        unit (the first phase's `Model.units`), the phase boundaries dotted.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, sequence of Axes or matplotlib.figure.Figure, optional
            Draw on these (see `dynamics.figures.plot_signals`); by default on a new
            `matplotlib.figure.Figure`.
        n : int, optional
            Samples of each phase's dense output.

        Returns
        -------
        matplotlib.figure.Figure
        """
        models = [sol.problem.model for sol in self.phases]
        names = [v for v in (*models[0].states, *models[0].controls)
                 if all(v in m.states or v in m.controls for m in models)]
        times, parts = [], {v: [] for v in names}
        for sol, a, b in zip(self.phases, self.t0, self.tf):
            ts = np.linspace(a, b, n)
            x, u = (np.atleast_2d(v) for v in sol.sample(ts))
            model = sol.problem.model
            rows = {**dict(zip(model.states, x)), **dict(zip(model.controls, u))}
            times.append(ts)
            for v in names:
                parts[v].append(rows[v])
        t = np.concatenate(times)
        series = {v: np.concatenate(parts[v]) for v in names}
        verdict = "" if self.success else f" (not converged: {status_name(self.status)})"
        fig = plot_signals(t, series, models[0].units, ax=ax,
                           title=f"{self.problem.name or 'multi-phase problem'}: "
                                 f"{len(self.phases)} phases, cost {self.cost:.6g}{verdict}")
        for a in fig.axes:
            for tb in self.tf[:-1]:
                a.axvline(tb, color="0.5", ls=":", lw=0.8)
        return fig
