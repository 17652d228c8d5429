"""`fly_pitch_program`: an optimal pitch program (`problems.ascent.planar`) flown through the
vehicle's attitude autopilot and gimbal servo in simulation (the pitch model:
`problems.ascent.planar_model`)."""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from appdyn.dynamics import simulate
from appdyn.dynamics.figures import finish_figure, panel_axes
from appdyn.dynamics.results import Result
from appdyn.dynamics.serialize import text_table
from appdyn.dynamics.validate import finite_scalar, positive
from appdyn.ocp.status import STATUS_DEFLECTION, STATUS_SIMULATION, STATUS_TRACKING, describe

from .planar import PlanarAscent
from .planar_model import (SCALE_HEIGHT, STATES, TRACKING_STATES, AscentVehicle, check_vehicle,
                           pitch_model)

__all__ = ["fly_pitch_program", "PitchTracking", "default_gains"]

# ------------------------------------------------------------------------ tracking
def default_gains(vehicle: AscentVehicle | None = None, q: float = 3.0e4) -> dict:
    """Autopilot gains from the vehicle data: ``problems.gains``' starting rule
    (`problems.gains.lv_data.guess_gains`): ``k_theta = max(1, 3 M / (F l))`` with
    ``M = q S C_N_alpha l_cp`` at the data's design dynamic pressure ``q``, and
    ``k_thetadot`` for damping ratio 0.7 of ``I s^2 + F l k_thetadot s + (F l k_theta - M)``
    at the reference inertia.

    Returns
    -------
    dict
        ``{'k_theta': [rad/rad], 'k_thetadot': [rad/(rad/s)]}``.
    """
    veh = check_vehicle(vehicle)
    Fl = veh.thrust * veh.arm
    M = positive(q, "q") * veh.area * veh.normal_force_slope * veh.cp_arm
    k = max(1.0, 3.0 * M / Fl)
    kd = 1.4 * math.sqrt(veh.inertia * max(Fl * k - M, 1e-9)) / Fl
    return {"k_theta": k, "k_thetadot": kd}


def _gains(gains, veh) -> tuple[float, float]:
    if gains is None:
        g = default_gains(veh)
        return g["k_theta"], g["k_thetadot"]
    if hasattr(gains, "gains") and isinstance(getattr(gains, "gains"), Mapping):
        gains = gains.gains  # a problems.gains.GainDesign
    if not isinstance(gains, Mapping):
        raise TypeError(f"`gains` must be a mapping, a GainDesign or None, got "
                        f"{type(gains).__name__}")
    alias = {"k_psi": "k_theta", "k_psidot": "k_thetadot"}
    g = {alias.get(k, k): v for k, v in gains.items() if k != "k_i"}
    unknown = sorted(set(g) - {"k_theta", "k_thetadot"})
    if unknown or len(g) != 2:
        raise ValueError(f"`gains` must give 'k_theta' and 'k_thetadot' (or 'k_psi', "
                         f"'k_psidot'), got keys {sorted(gains)}")
    return (finite_scalar(g["k_theta"], "gains['k_theta']"),
            finite_scalar(g["k_thetadot"], "gains['k_thetadot']"))


@dataclass(eq=False, repr=False)
class PitchTracking(Result):
    """Result of `fly_pitch_program`.

    Attributes
    ----------
    success : bool
        The simulation succeeded, the tracking error stayed within ``error_max`` and the
        peak commanded and actual deflection stayed within ``delta_max`` (the loop never
        asked the gimbal for more).
    status : int
        0 for a success, else (the table of `ocp.status`) 110 ``Simulation_Failed``, 115
        ``Tracking_Error_Exceeded`` or 116 ``Deflection_Limit_Exceeded``.
    message : str
    t : ndarray, shape (n,) [s]
    x : ndarray, shape (8, n)
        `TRACKING_STATES` at ``t``.
    theta_cmd : ndarray, shape (n,) [rad]
    delta_cmd : ndarray, shape (n,) [rad]
    max_error, rms_error : float [rad]
        ``max`` and RMS of ``|theta - theta_cmd|`` (NaN after a failed simulation).
    peak_delta, delta_max : float [rad]
        ``max |delta|`` and the limit.
    peak_delta_cmd : float [rad]
    final, optimal : mapping of str to float
        ``h`` [m], ``gamma`` [rad], ``V`` [m/s] reached and of the optimal solution.
    gains : mapping of str to float
    wall_time : float [s]
    """

    success: bool
    status: int
    message: str
    t: np.ndarray
    x: np.ndarray
    theta_cmd: np.ndarray
    delta_cmd: np.ndarray
    max_error: float
    rms_error: float
    peak_delta: float
    delta_max: float
    peak_delta_cmd: float
    final: Mapping
    optimal: Mapping
    gains: Mapping
    wall_time: float

    def __getitem__(self, name):
        return self.x[TRACKING_STATES.index(name)]

    def to_dict(self) -> dict:
        return {k: getattr(self, k) for k in (
            "success", "status", "message", "max_error", "rms_error", "peak_delta",
            "delta_max", "peak_delta_cmd", "final", "optimal", "gains", "wall_time", "t",
            "theta_cmd", "delta_cmd")} | {"x": {n: self.x[i] for i, n in enumerate(TRACKING_STATES)}}

    def __str__(self) -> str:
        d = math.degrees
        rows = [("success", f"{self.success} ({describe(self.status)})"),
                ("gains", ", ".join(f"{k} = {v:.4g}" for k, v in self.gains.items())),
                ("max |theta - cmd|", f"{d(self.max_error):.4f} deg"),
                ("rms |theta - cmd|", f"{d(self.rms_error):.4f} deg"),
                ("peak |delta|", f"{d(self.peak_delta):.3f} deg (limit {d(self.delta_max):.3f})")]
        for k, unit, f in (("h", "m", 1.0), ("gamma", "deg", 180 / math.pi), ("V", "m/s", 1.0)):
            rows.append((f"final {k}", f"{self.final[k] * f:.4f} {unit} "
                                       f"(optimal {self.optimal[k] * f:.4f})"))
        rows.append(("message", self.message))
        return text_table("Pitch program flown through the autopilot", rows)

    _repr_fields = ("max_error", "peak_delta", "gains", "t")

    def plot(self, ax=None):
        """Pitch and command, tracking error and gimbal deflection against time (on ``ax``'s
        slot, a Figure, or a new `matplotlib.figure.Figure`); returns the figure."""
        fig, axes = panel_axes(ax, 3, 1, (8.0, 7.0))
        d = np.degrees
        panels = [(d(np.vstack([self["theta"], self.theta_cmd])), "theta, cmd [deg]"),
                  (d(self["theta"] - self.theta_cmd), "error [deg]"),
                  (d(self["delta"]), "delta [deg]")]
        for ax, (y, label) in zip(axes[:, 0], panels):
            ax.plot(self.t, np.atleast_2d(y).T)
            ax.set_ylabel(label)
            ax.grid(True, alpha=0.3)
        ax.set_xlabel("t [s]")
        return finish_figure(fig)


def fly_pitch_program(ascent: PlanarAscent, *, gains=None, dt: float = 0.02,
                      method: str = "rk8", delta_max: float | None = None,
                      error_max: float = math.radians(5.0)) -> PitchTracking:
    """Fly the optimal pitch program through the vehicle's autopilot (module docstring).

    Parameters
    ----------
    ascent : PlanarAscent
        From `planar_ascent` (its vehicle and initial state are used).
    gains : mapping or problems.gains.GainDesign, optional
        ``{'k_theta', 'k_thetadot'}`` (or a `launch_vehicle_gains` design's ``k_psi``,
        ``k_psidot``); default `default_gains`. Zero gains fly open loop.
    dt : float [s]
        Output and step interval of the fixed-step integration, ``> 0`` (at most
        ``tau / 2``, the gimbal's time constant, is sensible; 8th order, so 0.02 s is
        accurate to well below the tracking errors).
    method : {'rk8', 'rk4', 'auto', 'cvodes'}
        `dynamics.simulate` method.
    delta_max : float [rad], optional
        Deflection limit; default the vehicle's.
    error_max : float [rad]
        Largest tracking error ``|theta - theta_cmd|`` of a successful flight (default
        5 deg): an open loop that tumbles without asking the gimbal for anything is not a
        success.

    Returns
    -------
    PitchTracking

    Raises
    ------
    TypeError
        ``ascent`` not a `PlanarAscent`, ``gains`` of the wrong type.
    ValueError
        Naming the argument: bad ``dt``, ``delta_max``, ``error_max``, gain keys.
    """
    start = time.perf_counter()
    if not isinstance(ascent, PlanarAscent):
        raise TypeError(f"`ascent` must be a PlanarAscent, got {type(ascent).__name__}")
    veh = ascent.vehicle
    kt, kd = _gains(gains, veh)
    dt = positive(dt, "dt")
    dmax = veh.delta_max if delta_max is None else positive(delta_max, "delta_max")
    emax = positive(error_max, "error_max")
    from scipy.interpolate import PchipInterpolator

    sol = ascent.solution
    spline = PchipInterpolator(sol.t, sol.u[0])
    rate = spline.derivative()
    t0, tf = float(sol.t[0]), float(sol.t[-1])
    n = max(int(math.ceil((tf - t0) / dt)), 2) + 1
    t = np.linspace(t0, tf, n)
    cmd, cmd_dot = spline(t), rate(t)
    x0 = sol.x[:, 0]
    rho0, g0, R = (float(v) for v in sol.p)
    model = pitch_model(veh, kt, kd)
    h, V, gam = x0[0], x0[2], x0[3]
    alpha0 = cmd[0] - gam
    q0 = 0.5 * rho0 * math.exp(-h / SCALE_HEIGHT) * V ** 2
    trim = math.asin(max(-1.0, min(1.0, -q0 * veh.area * veh.normal_force_slope * alpha0
                                   * veh.cp_arm / (veh.thrust * veh.arm))))
    omega0 = cmd_dot[0] + V * math.cos(gam) / (R + h)
    res = simulate(model, np.r_[x0, cmd[0], omega0, trim], t, u=np.vstack([cmd, cmd_dot]),
                   p=sol.p, method=method, jit=False)
    X = np.asarray(res.x)
    th, om, dl = X[5], X[6], X[7]
    theta_dot = om - X[2] * np.cos(X[3]) / (R + X[0])
    dcmd = -(kt * (th - cmd) + kd * (theta_dot - cmd_dot))
    err = np.abs(th - cmd)
    finite = np.all(np.isfinite(X))
    opt = {"h": ascent.final["h"], "gamma": ascent.final["gamma"], "V": ascent.final["V"]}
    final = {k: float(X[STATES.index(k), -1]) for k in ("h", "gamma", "V")}
    kw = dict(t=t, x=X, theta_cmd=cmd, delta_cmd=dcmd,
              max_error=float(np.max(err)) if finite else math.nan,
              rms_error=float(np.sqrt(np.mean(err ** 2))) if finite else math.nan,
              peak_delta=float(np.max(np.abs(dl))) if finite else math.nan, delta_max=dmax,
              peak_delta_cmd=float(np.max(np.abs(dcmd))) if finite else math.nan,
              final=final, optimal=opt, gains={"k_theta": kt, "k_thetadot": kd})
    if not (res.success and finite):
        return PitchTracking(False, STATUS_SIMULATION, f"simulation failed: {res.message}",
                             wall_time=time.perf_counter() - start, **kw)
    if not kw["max_error"] <= emax:
        msg = (f"tracking lost: max |theta - theta_cmd| {math.degrees(kw['max_error']):.4g} deg "
               f"> {math.degrees(emax):.4g} deg")
        return PitchTracking(False, STATUS_TRACKING, msg,
                             wall_time=time.perf_counter() - start, **kw)
    if max(kw["peak_delta"], kw["peak_delta_cmd"]) > dmax:
        msg = (f"gimbal limit exceeded: peak |delta| {math.degrees(kw['peak_delta']):.3f} deg, "
               f"peak |delta_c| {math.degrees(kw['peak_delta_cmd']):.3f} deg > "
               f"{math.degrees(dmax):.3f} deg")
        return PitchTracking(False, STATUS_DEFLECTION, msg,
                             wall_time=time.perf_counter() - start, **kw)
    msg = (f"tracked to {math.degrees(kw['max_error']):.3g} deg max; peak |delta| "
           f"{math.degrees(kw['peak_delta']):.3g} deg within {math.degrees(dmax):.3g} deg")
    return PitchTracking(True, 0, msg, wall_time=time.perf_counter() - start, **kw)
