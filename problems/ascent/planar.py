"""`planar_ascent`: the optimal pitch program of the thrust-vectored launch vehicle to a target
altitude and flight-path angle under dynamic-pressure and aerodynamic-load limits (the model
and its derivation: `problems.ascent.planar_model`)."""
from __future__ import annotations

import math
import time
import dataclasses
from dataclasses import dataclass, field
from typing import Literal, Mapping

import casadi as ca
import numpy as np

from appdyn.config import param
from appdyn import ocp
from appdyn.dynamics.figures import finish_figure, panel_axes
from appdyn.dynamics.results import Result
from appdyn.dynamics.serialize import text_table
from appdyn.dynamics.validate import finite_scalar, integer, one_of, positive
from appdyn.ocp import status as _status
from appdyn.ocp.checks import bound_violation
from appdyn.ocp.status import describe

from .planar_model import (RHO0, SCALE_HEIGHT, STATES, AscentVehicle, check_vehicle, planar_model,
                           vertical_rise)

__all__ = ["planar_ascent", "PlanarAscent", "STATUS_TERMINAL", "STATUS_LIMITS", "STATUS_PROPAGATION"]

#: status 111 of a `PlanarAscent` (`ocp.status`): solved, but the re-propagated end misses
#: the target
STATUS_TERMINAL = _status.STATUS_TERMINAL
#: status 112: solved, but the re-propagated trajectory exceeds q_max or qalpha_max
STATUS_LIMITS = _status.STATUS_PATH_LIMITS
#: status 113: solved, but the re-propagation failed
STATUS_PROPAGATION = _status.STATUS_PROPAGATION


# ------------------------------------------------------------------------ results
def _rows_table(title, rows):
    return text_table(title, rows)


@dataclass(eq=False, repr=False)
class PlanarAscent(Result):
    """Result of `planar_ascent`.

    Attributes
    ----------
    success : bool
        The NLP was solved (`ocp.Solution.success`) *and* the re-propagated trajectory
        (`ocp.Solution.propagate`: the returned control integrated by CVODES from the initial
        state) meets the terminal conditions to ``tolerances`` and the path limits to
        ``limit_tol`` relative.
    status : int
        0 for a success; else the solver's (`ocp.Solution.status`), `STATUS_TERMINAL` (111),
        `STATUS_LIMITS` (112) or `STATUS_PROPAGATION` (113).
    message : str
    solution : ocp.Solution
    objective : {'velocity', 'mass'}
    t : ndarray, shape (n,) [s]
        Node times after lift-off.
    burnout_speed : float [m/s]
        ``V(tf)`` (re-propagated).
    burnout_mass : float [kg]
        ``m(tf)``.
    final : mapping of str to float
        Re-propagated final ``h`` [m], ``gamma`` [rad], ``V`` [m/s], ``m`` [kg], ``x`` [m].
    targets : mapping of str to float
        ``h`` [m], ``gamma`` [rad] (and ``V`` [m/s] for ``objective='mass'``).
    peak_q, q_max : float [Pa]
        Largest dynamic pressure of the re-propagated nodes and of the dense collocated
        trajectory, and its limit.
    peak_qalpha, qalpha_max : float [Pa rad]
        The same for ``|q alpha|``.
    tolerances : mapping
        ``h`` [m], ``gamma`` [rad], ``V`` [m/s], ``limit_tol`` [-].
    wall_time : float [s]
    initial : mapping
        ``t`` [s] after lift-off, ``h``, ``V``, ``gamma``, ``m`` at the start of the
        collocated phase.
    vehicle : AscentVehicle
    solver_status : str
        IPOPT's return status text of ``solution`` (property).
    """

    success: bool
    status: int
    message: str
    solution: object = field(repr=False)
    objective: str
    t: np.ndarray
    burnout_speed: float
    burnout_mass: float
    final: Mapping
    targets: Mapping
    peak_q: float
    q_max: float
    peak_qalpha: float
    qalpha_max: float
    tolerances: Mapping
    wall_time: float
    initial: Mapping
    vehicle: AscentVehicle = field(repr=False)

    @property
    def solver_status(self) -> str:
        """IPOPT's return status text of the collocation (`ocp.Solution.solver_status`)."""
        return self.solution.solver_status

    def theta(self, t):
        """The optimal pitch program [rad] at times ``t`` [s] after lift-off (the
        transcription's control interpolant; ``t`` within the collocated phase)."""
        return self.solution.sample(t)[1][0]

    def to_dict(self) -> dict:
        return {"success": self.success, "status": int(self.status),
                "solver_status": self.solver_status, "message": self.message,
                "objective": self.objective, "burnout_speed": self.burnout_speed,
                "burnout_mass": self.burnout_mass, "final": dict(self.final),
                "targets": dict(self.targets), "peak_q": self.peak_q, "q_max": self.q_max,
                "peak_qalpha": self.peak_qalpha, "qalpha_max": self.qalpha_max,
                "tolerances": dict(self.tolerances), "initial": dict(self.initial),
                "wall_time": self.wall_time, "t": self.t, "theta": self.solution.u[0],
                "x": {n: self.solution.x[i] for i, n in enumerate(STATES)}}

    def __str__(self) -> str:
        f = self.final
        return _rows_table("Planar ascent (" + self.objective + ")", [
            ("success", f"{self.success} ({describe(self.status, solver_status=self.solver_status)})"),
            ("burnout speed", f"{self.burnout_speed:.2f} m/s"),
            ("burnout mass", f"{self.burnout_mass:.1f} kg"),
            ("final altitude", f"{f['h']:.1f} m (target {self.targets['h']:.1f})"),
            ("final gamma", f"{math.degrees(f['gamma']):.4f} deg "
                            f"(target {math.degrees(self.targets['gamma']):.4f})"),
            ("peak q", f"{self.peak_q:.1f} Pa (limit {self.q_max:.1f})"),
            ("peak |q alpha|", f"{self.peak_qalpha:.1f} Pa rad (limit {self.qalpha_max:.1f})"),
            ("burn", f"t = {self.initial['t']:.3f} .. {self.t[-1]:.3f} s"),
            ("wall time", f"{self.wall_time:.2f} s"), ("message", self.message)])

    _repr_fields = ("objective", "burnout_speed", "burnout_mass", "t")

    def plot(self, ax=None):
        """Altitude, speed, pitch / flight-path angle and q, q alpha against time (on ``ax``'s
        slot, a Figure, or a new `matplotlib.figure.Figure`); returns the figure."""
        fig, axes = panel_axes(ax, 4, 1, (8.0, 8.0))
        tt = np.linspace(self.t[0], self.t[-1], 400)
        x, u = self.solution.sample(tt)
        q, qa = _loads(x, u[0])
        panels = [(x[0] / 1e3, "h [km]"), (x[2], "V [m/s]"),
                  (np.degrees(np.vstack([u[0], x[3]])), "theta, gamma [deg]"),
                  (np.vstack([q / self.q_max, np.abs(qa) / self.qalpha_max]),
                   "q / q_max, |q alpha| / limit")]
        for ax, (y, label) in zip(axes[:, 0], panels):
            ax.plot(tt, np.atleast_2d(y).T)
            ax.set_ylabel(label)
            ax.grid(True, alpha=0.3)
        ax.set_xlabel("t [s]")
        return finish_figure(fig)


def _loads(x, theta, rho0=RHO0):
    """``q`` [Pa] and ``q alpha`` [Pa rad] of states ``x`` (5, n) and pitch ``theta`` (n,)."""
    q = 0.5 * rho0 * np.exp(-x[0] / SCALE_HEIGHT) * x[2] ** 2
    return q, q * (theta - x[3])


# ------------------------------------------------------------------------ the ascent
def planar_ascent(*, target_altitude, target_gamma, q_max, qalpha_max,
                  objective: Literal["velocity", "mass"] = "velocity", target_speed=None,
                  N: int | None = None, vehicle: AscentVehicle | None = None,
                  initial_speed: float = 50.0, kick: float = math.radians(1.0),
                  theta_bounds=(-0.2, math.pi / 2 + 0.2),
                  tolerances: Mapping | None = None, ipopt_options: Mapping | None = None,
                  guess=None) -> PlanarAscent:
    """Optimal pitch program of the pitch-plane ascent (module docstring for the model).

    The flight starts with the closed-form vertical rise (`vertical_rise`) from rest on the
    pad to ``initial_speed``; there the vehicle is pitched over by ``kick``
    (``gamma0 = 90 deg - kick``: a pure vertical start is singular, ``gamma`` is undefined at
    ``V = 0`` and stays at 90 deg for ever at ``theta = gamma``), and the collocated phase
    begins. ``objective='velocity'`` maximizes the burnout speed ``V(tf)`` with the burn to
    depletion: a *fixed* final time `AscentVehicle.burn_time` after lift-off (the engine is
    not throttled and there is no coast). ``objective='mass'`` maximizes the final mass with
    ``V(tf) = target_speed`` over a *free* final time up to burnout (engine cut-off when the
    target is reached; same as minimum time at constant mass flow).

    Parameters
    ----------
    target_altitude : float [m]
        ``h(tf)``, above the start altitude.
    target_gamma : float [rad]
        ``gamma(tf)`` in ``[0, gamma0]``.
    q_max : float [Pa]
        Path limit ``1/2 rho V^2 <= q_max``, ``> 0``.
    qalpha_max : float [Pa rad]
        Path limit ``|q (theta - gamma)| <= qalpha_max``, ``> 0``.
    objective : {'velocity', 'mass'}
    target_speed : float [m/s]
        Required with ``objective='mass'`` (only there).
    N : int
        Radau (degree 3) intervals, ``>= 4``.
    vehicle : AscentVehicle, optional
    initial_speed : float [m/s]
        End of the vertical rise, ``> 0``.
    kick : float [rad]
        Pitch-over at the start, in ``(0, pi/2)``.
    theta_bounds : (float, float) [rad]
        Bounds on the pitch control.
    tolerances : mapping, optional
        Verification tolerances: ``'h'`` [m] (default 10), ``'gamma'`` [rad] (2e-4),
        ``'V'`` [m/s] (0.5), ``'limit_tol'`` [-] (relative excess of the path limits, 0.01).
        Changing them changes only the verdict, not the solution.
    ipopt_options : mapping, optional
        Passed to `ocp.solve`.
    guess : ocp.Solution or mapping, optional
        Initial guess (default: linear states to the targets, ``theta = gamma``).

    Returns
    -------
    PlanarAscent

    Notes
    -----
    The engine is not throttled, so the dynamic pressure cannot be lowered at will: flying
    straight up (the quickest way out of the air) this vehicle still peaks at about
    41.2 kPa (gravity turns from a 0.3-2 deg kick: 41.2-42.2 kPa), and with a
    ``qalpha_max`` of a few kPa rad the problem becomes infeasible below about 43 kPa
    (IPOPT then reports ``Infeasible_Problem_Detected``). The solve is a continuation: the
    problem without path limits first (from a linear guess), its optimum then starts the
    limited one. The path limits are imposed at the collocation nodes; the verification
    also samples the collocated trajectory densely between them.

    Raises
    ------
    ValueError
        Naming the argument: non-positive limits or speeds, ``N < 4``, an unknown
        ``objective``, ``target_speed`` missing or superfluous, ``target_gamma`` outside
        ``[0, gamma0]``, ``target_altitude`` not above the start, ``kick`` out of range,
        bad ``tolerances`` keys or values, a vehicle that does not lift off.

    Examples
    --------
    >>> import math
    >>> res = planar_ascent(target_altitude=65e3, target_gamma=math.radians(40),
    ...                     q_max=45e3, qalpha_max=2e3, N=30)
    >>> res.success, round(res.burnout_speed), round(res.peak_q / 1e3, 1)
    (True, 2454, 45.0)
    """
    start = time.perf_counter()
    veh = check_vehicle(vehicle)
    one_of(objective, "objective", ("velocity", "mass"))
    qmax = positive(q_max, "q_max")
    qamax = positive(qalpha_max, "qalpha_max")
    N = integer(param("problems.N", N), "N", minimum=4)
    kick = positive(kick, "kick")
    if not kick < math.pi / 2:
        raise ValueError(f"`kick` must be in (0, pi/2) rad, got {kick!r}")
    if objective == "mass":
        if target_speed is None:
            raise ValueError("`target_speed` is needed with objective='mass'")
        Vf = positive(target_speed, "target_speed")
    elif target_speed is not None:
        raise ValueError("`target_speed` is only taken with objective='mass' (the velocity "
                         "objective maximizes the burnout speed)")
    tol = _tolerances(tolerances)
    lo_th, hi_th = (finite_scalar(v, "theta_bounds") for v in theta_bounds)
    if not lo_th < hi_th:
        raise ValueError(f"`theta_bounds` must be (lower, upper) with lower < upper, got "
                         f"{theta_bounds!r}")
    initial_speed = positive(initial_speed, "initial_speed")
    t0, h0, m0 = vertical_rise(veh, initial_speed)
    V0, gamma0 = float(initial_speed), math.pi / 2 - kick
    hf = finite_scalar(target_altitude, "target_altitude")
    if not hf > h0:
        raise ValueError(f"`target_altitude` must be above the start altitude {h0:.1f} m, "
                         f"got {hf!r}")
    gf = finite_scalar(target_gamma, "target_gamma")
    if not 0.0 <= gf <= gamma0:
        raise ValueError(f"`target_gamma` must be in [0, {gamma0!r}] rad (90 deg minus the "
                         f"kick), got {gf!r}")

    model = planar_model(veh)
    T_burn = veh.burn_time - t0
    x_final = {"h": hf, "gamma": gf}
    if objective == "velocity":
        T, mayer = T_burn, (lambda V: V)
    else:
        x_final["V"] = Vf
        T, mayer = (0.05 * T_burn, T_burn), (lambda m: m)
    qcon = ocp.Constraint(lambda h, V, rho0: 0.5 * rho0 * ca.exp(-h / SCALE_HEIGHT) * V ** 2,
                          -math.inf, qmax, qmax, "dynamic pressure")
    qacon = ocp.Constraint(lambda h, V, gamma, theta, rho0:
                           0.5 * rho0 * ca.exp(-h / SCALE_HEIGHT) * V ** 2 * (theta - gamma),
                           -qamax, qamax, qamax, "aerodynamic load q alpha")
    problem = ocp.Problem(
        model, T=T, t0=t0, x_initial=[h0, 0.0, V0, gamma0, m0], x_final=x_final,
        x_bounds={"h": (0.0, None), "V": (1.0, None), "gamma": (-0.2, math.pi / 2),
                  "m": (veh.burnout_mass, veh.mass)},
        u_bounds={"theta": (lo_th, hi_th)}, p_bounds={}, mayer=mayer, maximize=True,
        path=[qcon, qacon], name=f"planar ascent, maximum {'burnout speed' if objective == 'velocity' else 'final mass'}")
    scale = {"h": max(hf, 1e3), "x": max(hf, 1e3), "V": 1e3, "gamma": 1.0, "m": veh.mass,
             "theta": 1.0}
    if guess is None:  # continuation: the optimum without path limits starts the real one
        guess = _default_guess(veh, problem, T_burn, t0, h0, V0, gamma0, m0, hf, gf)
        free = ocp.solve(problem.replace(path=()), N=N, guess=guess, scale=scale,
                         ipopt_options=ipopt_options)
        if free.success:
            guess = free
    # the loads are graded by `_verify` against the limits with ``limit_tol`` (the dense
    # trajectory and the re-propagation); the bounds of the states and the control here
    sol = ocp.solve(problem, N=N, guess=guess, scale=scale, ipopt_options=ipopt_options,
                    bound_tol=math.inf)
    plain = bound_violation(sol.dense, problem.replace(path=()), sol.x, sol.u, p=sol.p)
    if sol.success and plain.max > ocp.DEFAULT_CONSTRAINT_TOL:
        sol = dataclasses.replace(
            sol, success=False, status=ocp.STATUS_BOUND_VIOLATION,
            message=f"{sol.message}; but {plain.describe(controls=problem.model.controls)}")
    return _verify(sol, veh, objective, x_final, qmax, qamax, tol, start,
                   {"t": t0, "h": h0, "V": V0, "gamma": gamma0, "m": m0})


def _tolerances(tolerances) -> dict:
    out = {"h": 10.0, "gamma": 2e-4, "V": 0.5, "limit_tol": 0.01}
    if tolerances is None:
        return out
    if not isinstance(tolerances, Mapping):
        raise TypeError(f"`tolerances` must be a mapping, got {type(tolerances).__name__}")
    for key, value in tolerances.items():
        if key not in out:
            raise ValueError(f"`tolerances` has unknown key {key!r}; known: {sorted(out)}")
        out[key] = positive(value, f"tolerances[{key!r}]")
    return out


def _default_guess(veh, problem, T_burn, t0, h0, V0, gamma0, m0, hf, gf) -> dict:
    T = T_burn if not problem.free_time else 0.8 * T_burn
    s = np.linspace(0.0, 1.0, 41)
    dv = veh.exhaust_velocity * math.log(m0 / (m0 - veh.mass_flow_rate * T))
    V = V0 + (0.6 * dv - V0) * s
    gam = gamma0 + (gf - gamma0) * s
    h = h0 + (hf - h0) * s ** 1.5
    x = np.cumsum(np.r_[0.0, np.diff(s) * T * 0.5 * (V[1:] + V[:-1]) / 2
                        * np.cos(0.5 * (gam[1:] + gam[:-1]))])
    m = m0 - veh.mass_flow_rate * T * s
    return {"t": t0 + T * s, "x": {"h": h, "x": x, "V": V, "gamma": gam, "m": m},
            "u": {"theta": gam}, "T": T}


def _verify(sol, veh, objective, x_final, qmax, qamax, tol, start, initial) -> PlanarAscent:
    targets = dict(x_final)
    prop = sol.propagation if sol.success else None
    ok_prop = prop is not None and prop.success
    xf = prop.x[:, -1] if ok_prop else sol.x[:, -1]
    final = {n: float(xf[i]) for i, n in enumerate(STATES)}
    rho0 = float(sol.p[0])
    # path loads: re-propagated states at the nodes with the node controls, and the dense
    # collocated trajectory between them
    tt = np.linspace(sol.t[0], sol.t[-1], 20 * sol.t.size)
    xd, ud = sol.sample(tt)
    xs = [(xd, ud[0])] + ([(prop.x, sol.u[0])] if ok_prop else [])
    loads = [_loads(x, th, rho0) for x, th in xs]
    peak_q = max(float(np.max(q)) for q, _ in loads)
    peak_qa = max(float(np.max(np.abs(qa))) for _, qa in loads)
    kw = dict(solution=sol, objective=objective, t=sol.t, burnout_speed=final["V"],
              burnout_mass=final["m"], final=final, targets=targets, peak_q=peak_q,
              q_max=qmax, peak_qalpha=peak_qa, qalpha_max=qamax, tolerances=tol,
              wall_time=time.perf_counter() - start, initial=initial, vehicle=veh)
    if not sol.success:
        return PlanarAscent(False, sol.status, sol.message, **kw)
    if not ok_prop:
        return PlanarAscent(False, STATUS_PROPAGATION,
                            f"re-propagation failed: {prop.message}", **kw)
    misses = [f"{k} off by {abs(final[k] - v):.3g} (tol {tol[k]:g})"
              for k, v in targets.items() if not abs(final[k] - v) <= tol[k]]
    if misses:
        return PlanarAscent(False, STATUS_TERMINAL, "re-propagated end: " + "; ".join(misses),
                            **kw)
    over = [f"{name} peak {p:.4g} > limit {lim:.4g}" for name, p, lim in
            (("q", peak_q, qmax), ("|q alpha|", peak_qa, qamax))
            if p > lim * (1 + tol["limit_tol"])]
    if over:
        return PlanarAscent(False, STATUS_LIMITS, "; ".join(over), **kw)
    msg = (f"optimal ({sol.iterations} IPOPT iterations, {sol.solve_time:.2f} s); "
           f"re-propagated end within tolerance, peak q {peak_q:.0f} Pa and |q alpha| "
           f"{peak_qa:.0f} Pa rad within the limits")
    return PlanarAscent(True, sol.status, msg, **kw)
