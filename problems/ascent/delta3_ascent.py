"""The Delta III-class ascent as a four-phase optimal-control problem, solved and checked.

`delta3_problem` states it on the multi-phase engine (`ocp.MultiPhaseProblem`): one phase per
burn (`problems.ascent.delta3`: models, data, bounds, guesses), ``|u| = 1`` and ``|r| >= R_E``
as path constraints, position and velocity continuous across the stagings, the dropped dry
masses as jumps of the mass, the five terminal orbital elements (`orbit_residuals`) as
events, and the final mass maximized. `delta3_ascent` solves it and checks the answer
independently: the final orbit is recomputed from the final state with
`orbital_elements` (the standard quadrant rules, not the residual form the NLP used), every
phase is re-simulated from its collocated start under its collocated thrust direction, and
the mass budget is compared with the rocket equation.

Published optimum: 7529.712412 kg at 924.139 s (Betts 2010), 7529.712287 kg (yapss);
`bench/ascent.py` runs appdyn and yapss side by side.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Mapping

import numpy as np

from appdyn import ocp
from appdyn.dynamics.results import Result
from appdyn.dynamics import cache
from appdyn.dynamics.validate import finite_array
from appdyn.ocp import nlp as ocp_nlp
from appdyn.ocp.status import STATUS_CHECK, status_name
from appdyn.ocp.transcription import get_transcription

from .delta3 import (FINAL_MASS_BETTS, H_SCALE, OMEGA_E, PHASES, RE, RHO0,
                     TARGET_ORBIT, delta3_model, guess, initial_state, orbit_residuals,
                     orbital_elements, phase_bounds)

__all__ = ["delta3_problem", "delta3_ascent", "AscentResult", "PhaseRow", "dynamic_pressure",
           "RELAXED_U_NORM", "START_IPOPT_OPTIONS"]

_ELEMENTS = ("a", "e", "i", "raan", "argp")

#: ASSET's band ``0.5 <= |u| <= 1.5`` on the control whose direction is the thrust's: the
#: first solve of `delta3_ascent`.
RELAXED_U_NORM = (0.5, 1.5)

#: IPOPT's push of the start into the bounds in `delta3_ascent`: 1e-6 of the range instead of
#: IPOPT's 1e-2 (the guessed mass starts and ends each phase on its bounds, and a push of 1 %
#: of a phase's mass range breaks the guess's mass budget). Over 9 starts (4-6 intervals,
#: 9-21 guess samples): 18-25 IPOPT iterations, against 19-33 with IPOPT's defaults.
START_IPOPT_OPTIONS = MappingProxyType({"bound_push": 1e-6, "bound_frac": 1e-6})


def dynamic_pressure(r, v) -> np.ndarray:
    """``q = rho |v_rel|^2 / 2`` [Pa] of the rotating exponential atmosphere at positions
    ``r`` and inertial velocities ``v`` (shape (3,) or (3, n)) [m, m/s]."""
    r, v = finite_array(r, "r"), finite_array(v, "v")
    if r.shape[:1] != (3,) or v.shape != r.shape or r.ndim > 2:
        raise ValueError(f"`r` and `v` must both have shape (3,) or (3, n), got {r.shape} and {v.shape}")
    v_rel = v - np.cross(np.array([0.0, 0.0, OMEGA_E]), r, axis=0)
    rho = RHO0 * np.exp(-(np.linalg.norm(r, axis=0) - RE) / H_SCALE)
    return 0.5 * rho * np.sum(v_rel**2, axis=0)


def _unit_thrust(ux, uy, uz):
    return ux**2 + uy**2 + uz**2


def _radius_sq(rx, ry, rz):
    return (rx**2 + ry**2 + rz**2) / RE**2


def _phase_problem(k: int, u_norm: tuple) -> ocp.Problem:
    data = PHASES[k]
    xb, ub = phase_bounds(k)
    lo, hi = u_norm
    if data.t_end is None:  # the last phase: free duration up to the stage's burn-out
        T = (1.0, data.t_end_max - data.t_start)
    else:
        T = data.t_end - data.t_start
    return ocp.Problem(
        delta3_model(k, normalized=True), T=T, x_initial=initial_state() if k == 0 else None,
        x_bounds=(xb[0], xb[1]), u_bounds=(hi * ub[0], hi * ub[1]),
        path=[ocp.Constraint(_unit_thrust, lo**2, hi**2,
                             name="|u| = 1" if lo == hi == 1.0 else f"{lo:g} <= |u| <= {hi:g}"),
              ocp.Constraint(_radius_sq, 1.0, math.inf, name="|r| >= R_E")],
        name=data.name)


def _phase_guess(k: int, n: int = 21) -> dict:
    g = guess(k, n)
    out = {"t": g["t"] - g["t"][0], "x": g["x"], "u": g["u"]}
    if PHASES[k].t_end is None:  # the free duration: the guess's own (else the middle of its range)
        out["T"] = float(out["t"][-1])
    return out


def delta3_problem(*, N: int | tuple = 8, degree: int = 4, target=TARGET_ORBIT,
                   guess_samples: int = 21, u_norm=(1.0, 1.0)) -> ocp.MultiPhaseProblem:
    """The Delta III ascent as a `ocp.MultiPhaseProblem` (module docstring).

    Parameters
    ----------
    N : int or tuple of 4 ints, optional
        Mesh intervals per phase (uniform).
    degree : int, optional
        Radau collocation degree of every phase.
    target : mapping, optional
        Target elements ``a`` [m], ``e``, ``i``, ``raan``, ``argp`` [rad].
    guess_samples : int, optional
        Samples per phase of the initial guess (`problems.ascent.delta3.guess`), which the
        engine interpolates linearly onto the nodes.
    u_norm : (float, float), optional
        Bounds ``lo <= |u| <= hi`` of the control; the thrust direction is ``u / |u|``
        (`problems.ascent.delta3.delta3_model` with ``normalized=True``). ``(1, 1)``
        (default): the classical ``|u| = 1``. ``RELAXED_U_NORM`` = ``(0.5, 1.5)``: ASSET's
        band, the same optimal trajectory without the nonconvex equality (IPOPT needs about
        half the iterations from the same guess).

    Returns
    -------
    ocp.MultiPhaseProblem
    """
    Ns = (N,) * len(PHASES) if isinstance(N, (int, np.integer)) else tuple(N)
    if len(Ns) != len(PHASES) or any(isinstance(n, bool) or not isinstance(n, (int, np.integer))
                                     or n < 1 for n in Ns):
        raise ValueError(f"`N` must be a positive int or {len(PHASES)} of them, got {N!r}")
    try:
        lo, hi = (float(v) for v in u_norm)
    except (TypeError, ValueError):
        raise ValueError(f"`u_norm` must be two numbers (lo, hi), got {u_norm!r}") from None
    if not 0 < lo <= 1.0 <= hi < math.inf:
        raise ValueError(f"`u_norm` must satisfy 0 < lo <= 1 <= hi < inf, got {u_norm!r}")
    missing = [k for k in _ELEMENTS if k not in target]
    if missing:
        raise ValueError(f"`target` must give {list(_ELEMENTS)}; missing {missing}")
    elements = tuple(float(target[k]) for k in _ELEMENTS)
    return _delta3_problem(tuple(int(n) for n in Ns), degree, elements, guess_samples, lo, hi)


@cache.memoize
def _delta3_problem(Ns: tuple, degree, elements: tuple, guess_samples, lo: float,
                    hi: float) -> ocp.MultiPhaseProblem:
    """`delta3_problem` on checked arguments, kept in the one cache (a problem is immutable;
    `delta3_ascent` states two per call)."""
    target = dict(zip(_ELEMENTS, elements))
    phases = [ocp.Phase(_phase_problem(k, (lo, hi)), N=n, degree=degree,
                        guess=_phase_guess(k, guess_samples), name=PHASES[k].name)
              for k, n in enumerate(Ns)]
    links = [ocp.Link(k, k + 1, jump={"m": -PHASES[k].dry_mass_dropped})
             for k in range(len(PHASES) - 1)]
    last = len(PHASES) - 1

    def orbit(ends):
        xf = ends[last].xf
        return orbit_residuals(xf[0:3], xf[3:6], target)

    return ocp.MultiPhaseProblem(
        phases, links=links, objective=lambda ends: ends[last]["m_f"], maximize=True,
        events=ocp.Constraint(orbit, 0.0, 0.0, name="terminal orbit"),
        name="Delta III ascent to GTO")


@dataclass(frozen=True)
class PhaseRow:
    """One row of the phase table: a phase's times [s], masses [kg], altitude [m] and
    inertial speed [m/s] at its start and end."""

    name: str
    t0: float
    tf: float
    m0: float
    mf: float
    h0: float
    hf: float
    v0: float
    vf: float


@dataclass(frozen=True, eq=False, repr=False)
class AscentResult(Result):
    """Result of `delta3_ascent`.

    Attributes
    ----------
    success : bool
        The NLP solved (`ocp.MultiPhaseSolution.success`) *and* the checks passed: the final
        orbit recomputed from the final state within ``orbit_tol`` of the target (``a``
        relative, ``e`` absolute, angles in rad), every phase's re-simulation within
        ``propagation_tol`` (relative) of the collocated trajectory.
    status : int
        0 for a success; else the solver's (`ocp.MultiPhaseSolution.status`) or 114
        ``Check_Failed`` (`ocp.status`) when the orbit or re-simulation check failed.
    message : str
    final_mass : float [kg]
    final_time : float [s]
    elements : OrbitalElements
        Of the final state (independently of the NLP's residual rows).
    orbit_error : dict
        Per element: ``a`` relative, ``e`` absolute, angles [rad].
    propagation_error : float
        Largest relative state error of the per-phase re-simulation.
    table : tuple of PhaseRow
    solution : ocp.MultiPhaseSolution
    solve_time, build_time : float [s]
        Over every NLP solved (the relaxed start and the refinement rounds included).
    iterations : int
        IPOPT iterations over every NLP solved.
    reference_mass : float [kg]
        Betts (2010): 7529.712412.
    solver_status : str
        IPOPT's return status text of ``solution`` (property).
    """

    success: bool
    status: int
    message: str
    final_mass: float
    final_time: float
    elements: object
    orbit_error: dict
    propagation_error: float
    table: tuple
    solution: object = field(repr=False)
    solve_time: float = 0.0
    build_time: float = 0.0
    reference_mass: float = FINAL_MASS_BETTS
    iterations: int = 0

    def format_table(self) -> str:
        """The phase table as text (times, masses, altitude and speed at each staging)."""
        head = (f"{'phase':<18}{'t0 [s]':>9}{'tf [s]':>10}{'m0 [kg]':>11}{'mf [kg]':>11}"
                f"{'h0 [km]':>10}{'hf [km]':>10}{'v0 [m/s]':>10}{'vf [m/s]':>10}")
        rows = [head, "-" * len(head)]
        for r in self.table:
            rows.append(f"{r.name:<18}{r.t0:>9.3f}{r.tf:>10.3f}{r.m0:>11.2f}{r.mf:>11.2f}"
                        f"{r.h0 / 1e3:>10.2f}{r.hf / 1e3:>10.2f}{r.v0:>10.1f}{r.vf:>10.1f}")
        return "\n".join(rows)

    def summary(self) -> str:
        el = self.elements
        return "\n".join([
            f"Delta III ascent to GTO: {'success' if self.success else 'FAILED'} ({self.message})",
            f"  final mass {self.final_mass:.6f} kg at t = {self.final_time:.3f} s "
            f"(Betts 2010: {self.reference_mass:.6f} kg; difference {self.final_mass - self.reference_mass:+.2e} kg)",
            f"  final orbit: a = {el.a / 1e3:.3f} km, e = {el.e:.6f}, i = {math.degrees(el.i):.4f} deg, "
            f"RAAN = {math.degrees(el.raan):.4f} deg, argp = {math.degrees(el.argp):.4f} deg",
            f"  largest orbit error {max(self.orbit_error.values()):.2g}; re-simulation error "
            f"{self.propagation_error:.2g}; build {self.build_time:.2f} s, solve {self.solve_time:.2f} s",
            self.format_table()])

    def __str__(self) -> str:
        return self.summary()

    _repr_fields = ("final_mass", "final_time")

    @property
    def solver_status(self) -> str:
        """IPOPT's return status text of the last NLP (`ocp.MultiPhaseSolution.solver_status`)."""
        return self.solution.solver_status

    @property
    def wall_time(self) -> float:
        """``build_time + solve_time`` [s]."""
        return float(self.build_time + self.solve_time)

    def plot(self, ax=None, n: int = 60):
        """Altitude, inertial speed, mass, thrust direction and dynamic pressure against time,
        the phase boundaries marked, on ``ax``'s slot, a Figure, or a new
        `matplotlib.figure.Figure`; returns the figure (library habit: no pyplot)."""
        from appdyn.dynamics.figures import panel_axes

        fig, axes = panel_axes(ax, 3, 2, (10.0, 8.0))
        axes = axes.ravel()
        labels = ("altitude [km]", "inertial speed [km/s]", "mass [t]",
                  "thrust direction u", "dynamic pressure [kPa]", "flight-path angle [deg]")
        for k, sol in enumerate(self.solution.phases):
            t = np.linspace(sol.t[0], sol.t[-1], n)
            x, u = sol.sample(t)
            r, v = x[:3], x[3:6]
            rn = np.linalg.norm(r, axis=0)
            color = f"C{k}"
            axes[0].plot(t, (rn - RE) / 1e3, color=color, label=self.table[k].name)
            axes[1].plot(t, np.linalg.norm(v, axis=0) / 1e3, color=color)
            axes[2].plot(t, x[6] / 1e3, color=color)
            for j, ls in enumerate(("-", "--", ":")):
                axes[3].plot(t, u[j], color=color, ls=ls, label=("ux", "uy", "uz")[j] if k == 0 else None)
            axes[4].plot(t, dynamic_pressure(r, v) / 1e3, color=color)
            axes[5].plot(t, np.degrees(np.arcsin(np.sum(r * v, axis=0) / (rn * np.linalg.norm(v, axis=0)))),
                         color=color)
        for ax, label in zip(axes, labels):
            ax.set_ylabel(label)
            ax.grid(True, alpha=0.3)
            for row in self.table[1:]:
                ax.axvline(row.t0, color="0.5", lw=0.8, ls="--")
        for ax in axes[4:]:
            ax.set_xlabel("t [s]")
        axes[0].legend(fontsize=8)
        axes[3].legend(fontsize=8)
        fig.suptitle(f"Delta III ascent: {self.final_mass:.4f} kg to GTO at t = {self.final_time:.2f} s")
        fig.tight_layout()
        return fig

    def to_dict(self) -> dict:
        el = self.elements
        return {"success": self.success, "status": int(self.status),
                "solver_status": self.solver_status, "message": self.message,
                "final_mass": self.final_mass, "final_time": self.final_time,
                "reference_mass": self.reference_mass,
                "elements": {k: float(getattr(el, k)) for k in (*_ELEMENTS, "nu")},
                "orbit_error": self.orbit_error, "propagation_error": self.propagation_error,
                "solve_time": self.solve_time, "build_time": self.build_time,
                "iterations": self.iterations,
                "table": [vars(r) for r in self.table],
                "solution": self.solution.to_dict()}


def delta3_ascent(*, N: int | tuple = 5, degree: int = 5, refine_tol: float | None = 1e-9,
                  orbit_tol: float = 1e-7, propagation_tol: float = 1e-6,
                  guess_samples=(21, 9, 15), ipopt_options=None,
                  relaxed_start: bool = True) -> AscentResult:
    """Solve the Delta III ascent (maximum mass in the target orbit) and check it.

    With ``relaxed_start`` (default), the problem is first solved with ASSET's band
    ``0.5 <= |u| <= 1.5`` (`RELAXED_U_NORM`; the thrust direction is ``u / |u|``, so the
    optimal trajectory is the same) from the interpolated guess, then with ``|u| = 1``
    warm-started from that solution's primal and dual values, its controls scaled to unit
    length (the two NLPs differ in the bounds of the ``|u|`` row only, and the scaled point
    is optimal for both). On the default mesh this takes 18 + 0 IPOPT iterations, against
    37 for ``|u| = 1`` from the guess.

    Parameters
    ----------
    N, degree : see `delta3_problem`; default 5 intervals of Radau degree 5 per phase
        (verified without refinement, 1.7e-5 kg from the refined mass, with 26 state nodes
        per phase against 33 for 8 intervals of degree 4, which end 2.7e-5 kg off).
    refine_tol : float or None, optional
        Per-phase mesh refinement target (`ocp.solve_phases`); None: no refinement.
    orbit_tol : float, optional
        Largest accepted error of the recomputed final orbit (``a`` relative, ``e``, angles
        [rad]).
    propagation_tol : float, optional
        Largest accepted relative error of the per-phase re-simulation.
    guess_samples : sequence of int, optional
        Starts, tried in order until one solves: the samples per phase of the interpolated
        guess (`delta3_problem`). IPOPT's path from a guess this far from the optimum is
        sensitive to its details: over meshes of 6-12 intervals per phase and 5-21 samples,
        2 of 24 starts ended in ``Infeasible_Problem_Detected`` (none of those with 9 or 21).
    ipopt_options : mapping, optional
        Over `START_IPOPT_OPTIONS` (IPOPT's push of the start into the bounds).
    relaxed_start : bool, optional
        Start from the solution of the relaxed problem (above); False: solve ``|u| = 1``
        from the interpolated guess.

    Returns
    -------
    AscentResult
    """
    for name, v in (("orbit_tol", orbit_tol), ("propagation_tol", propagation_tol)):
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not 0 < v < math.inf:
            raise ValueError(f"`{name}` must be a finite number > 0, got {v!r}")
    starts = [guess_samples] if isinstance(guess_samples, (int, np.integer)) else list(guess_samples)
    if not starts or any(isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 2
                         for n in starts):
        raise ValueError(f"`guess_samples` must be ints >= 2, got {guess_samples!r}")
    if ipopt_options is None or isinstance(ipopt_options, Mapping):  # else solve_phases says why
        ipopt_options = {**START_IPOPT_OPTIONS, **(ipopt_options or {})}
    failed, spent = [], [0.0, 0.0, 0]
    for n in starts:
        start = None
        if relaxed_start:
            start = ocp.solve_phases(delta3_problem(N=N, degree=degree, guess_samples=int(n),
                                                    u_norm=RELAXED_U_NORM),
                                     objective_scale=1e4, ipopt_options=ipopt_options)
            spent = _add_costs(spent, start)
            start = _unit_directions(start) if start.success else None
        problem = delta3_problem(N=N, degree=degree, guess_samples=int(n))
        sol = ocp.solve_phases(problem, guess=start, refine_tol=refine_tol, objective_scale=1e4,
                               ipopt_options=ipopt_options)
        spent = _add_costs(spent, sol)
        if sol.success:
            break
        failed.append(f"{n} guess samples: {status_name(sol.status)}")
    last = sol.phases[-1]
    xf = last.x[:, -1]
    el = orbital_elements(xf[0:3], xf[3:6])
    err = {"a": abs(el.a - TARGET_ORBIT["a"]) / TARGET_ORBIT["a"], "e": abs(el.e - TARGET_ORBIT["e"])}
    for name in _ELEMENTS[2:]:
        err[name] = abs(math.remainder(getattr(el, name) - TARGET_ORBIT[name], 2 * math.pi))
    prop = 0.0
    for ph in sol.phases:
        p = ph.propagate()
        scale = np.maximum(np.abs(ph.x).max(axis=1), 1.0)
        prop = max(prop, float(np.max(np.abs(p.x - ph.x) / scale[:, None])) if p.success else math.inf)
    table = tuple(PhaseRow(problem.phase_name(i), float(s.t[0]), float(s.t[-1]), float(s.x[6, 0]),
                           float(s.x[6, -1]), float(np.linalg.norm(s.x[:3, 0]) - RE),
                           float(np.linalg.norm(s.x[:3, -1]) - RE), float(np.linalg.norm(s.x[3:6, 0])),
                           float(np.linalg.norm(s.x[3:6, -1]))) for i, s in enumerate(sol.phases))
    checks_ok = max(err.values()) <= orbit_tol and prop <= propagation_tol
    message = sol.message + (f" (after failed starts: {'; '.join(failed)})" if failed else "")
    if sol.success and not checks_ok:
        message += (f"; but the check failed: orbit error {max(err.values()):.2g} (tol {orbit_tol:g}), "
                    f"re-simulation error {prop:.2g} (tol {propagation_tol:g})")
    return AscentResult(
        success=bool(sol.success and checks_ok), status=sol.status if checks_ok else STATUS_CHECK,
        message=message, final_mass=float(xf[6]), final_time=float(sol.tf[-1]), elements=el,
        orbit_error=err, propagation_error=prop, table=table, solution=sol,
        solve_time=spent[0], build_time=spent[1], iterations=spent[2])


def _unit_directions(sol):
    """``sol`` (a solution of the relaxed problem) with every control column scaled to
    ``|u| = 1`` in its NLP point: the thrust ``T u / |u|`` and so the trajectory are
    unchanged, and the point is feasible for ``|u| = 1`` (the warm start of the second solve
    then needs next to no iterations instead of about 13)."""
    x = np.array(sol.nlp_point["x_phys"], dtype=float)
    offset = 0
    for ph in sol.problem.phases:
        pb = replace(ph.problem, t0=0.0) if ph.problem.t0 != 0.0 else ph.problem
        tr = get_transcription(ph.transcription, degree=ph.degree)
        layout = ocp_nlp.structure(pb, tr, ph.N).w
        cols = offset + layout.indices("U")
        x[cols] = x[cols] / np.linalg.norm(x[cols], axis=0)
        offset += layout.size
    return replace(sol, nlp_point={**sol.nlp_point, "x_phys": x})


def _add_costs(spent, sol) -> list:
    """``spent`` (solve time, build time, iterations) plus those of ``sol`` (its refinement
    rounds included)."""
    return [spent[0] + sol.info.get("solve_time", sol.solve_time),
            spent[1] + sol.info.get("build_time", sol.build_time),
            spent[2] + sol.info.get("iterations", sol.iterations)]
