"""`launch_vehicle_response`: the closed-loop time response of the launch-vehicle autopilot
(RP-1262, Sec. 5.4) to an initial attitude error and a lateral wind gust.

The nonlinear model of `dynamics.launch_vehicle` with the autopilot closed inside (and the
parts given) is integrated by `dynamics.simulate`: ``method='auto'`` (the compiled rk8 loop
with a verified global error), or ``'cvodes'`` when the actuator has limits (their clamps put
kinks in the right-hand side, which spoil the rk8 error estimates; cvodes controls its local
error step by step). With `Aero` the wind enters as a time-dependent input
(``Aero(wind='control')``): a "1 - cosine" gust along ``Y``,
``wind_y = gust_speed / 2 (1 - cos(2 pi (t - gust_start) / gust_duration))`` within the gust
window, zero outside; the window's ends are output times, so every step sees a smooth input.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field, replace

import numpy as np

from appdyn.dynamics.figures import finish_figure, panel_axes
from appdyn.dynamics.integrate import SimulationResult, simulate
from appdyn.dynamics.launch_vehicle import launch_vehicle as vehicle_model
from appdyn.dynamics.serialize import jsonable, plain, text_table

from .common import check_number
from .launch_vehicle import flight_speed, frozen_state
from appdyn.dynamics.results import Result

__all__ = ["AutopilotResponse", "launch_vehicle_response", "gust"]


def gust(t, speed, start, duration):
    """The "1 - cosine" lateral gust [m/s] at times ``t`` [s] (module notes).

    Examples
    --------
    >>> from appdyn.problems.stability.launch_vehicle_response import gust
    >>> gust([0.0, 1.5, 2.0, 3.0], speed=10.0, start=1.0, duration=1.0).tolist()
    [0.0, 10.0, 0.0, 0.0]
    """
    t = np.asarray(t, dtype=float)
    inside = (t >= start) & (t <= start + duration)
    return np.where(inside, 0.5 * speed * (1 - np.cos(2 * np.pi * (t - start) / duration)), 0.0)


@dataclass(frozen=True, repr=False)
class AutopilotResponse(Result):
    """Time response of the launch-vehicle autopilot (`launch_vehicle_response`).

    Attributes
    ----------
    t : ndarray, shape (n,) [s]
    series : dict of str -> ndarray, shape (n,)
        ``psi``, ``psi_sensed``, ``delta`` (the engine deflection: the actuator state, or
        the command), ``delta_command`` [rad], ``y_dot`` [m/s]; with aero ``wind_y`` [m/s]
        and ``alpha`` [rad]; ``theta_s`` [rad] or ``r_s`` [m] (slosh); ``eta`` [m] (bending).
    units : dict of str -> str
    parameters : dict
        The inputs as plain Python values.
    simulation : SimulationResult
        The run (all states by name, counters, wall time).
    success, status, message, wall_time
        Those of ``simulation`` (properties).
    """

    t: np.ndarray
    series: dict
    units: dict
    parameters: dict
    simulation: SimulationResult = field(repr=False)

    _repr_fields = ('t', 'series')

    @property
    def success(self) -> bool:
        """The integrator met its tolerance (`dynamics.simulate`)."""
        return bool(self.simulation.success)

    @property
    def status(self) -> int:
        return int(self.simulation.status)

    @property
    def message(self) -> str:
        return self.simulation.message

    @property
    def wall_time(self) -> float:
        return self.simulation.wall_time

    def peak(self, name: str) -> float:
        """``max |series[name]|`` over the run."""
        return float(np.max(np.abs(self.series[name])))

    def to_dict(self) -> dict:
        """JSON-ready summary and time histories (non-finite numbers as ``None``)."""
        sim = self.simulation
        return jsonable({"success": self.success, "status": self.status,
                         "message": self.message, "method": sim.method,
                         "n_steps": sim.n_steps, "wall_time": self.wall_time,
                         "parameters": self.parameters, "units": self.units,
                         "peaks": {k: self.peak(k) for k in self.series}, "t": self.t,
                         "series": self.series})

    def __str__(self) -> str:
        sim = self.simulation
        rows = [("success", f"{self.success} (status {self.status}: {self.message})"),
                ("integrator", f"{sim.method}, {sim.n_steps} steps, "
                               f"{1e3 * sim.wall_time:.1f} ms"),
                ("grid", f"{self.t.size} points, t = 0 .. {self.t[-1]:g} s")]
        for name, values in self.series.items():
            unit = self.units[name]
            scale, shown = (180 / math.pi, "deg") if unit == "rad" else (1.0, unit)
            rows.append((f"{name} [{shown}]", f"max |.| {scale * self.peak(name):.6g}, "
                         f"final {scale * values[-1]:+.6g}"))
        return text_table("Launch-vehicle autopilot response (RP-1262, Sec. 5.4)", rows)

    def plot(self, ax=None):
        """Attitude, deflection, slosh, bending and gust panels against time.

        Parameters
        ----------
        ax : matplotlib.axes.Axes or matplotlib.figure.Figure, optional
            Draw the panels in this axes' slot (divided into the panels) or on this figure
            (cleared); by default on a new `matplotlib.figure.Figure` (no pyplot).

        Returns
        -------
        matplotlib.figure.Figure
        """
        panels = [("attitude", ("psi", "psi_sensed")),
                  ("engine deflection", ("delta", "delta_command")),
                  ("slosh", ("theta_s", "r_s")), ("bending", ("eta",)),
                  ("gust and angle of attack", ("wind_y", "alpha"))]
        panels = [(title, [n for n in names if n in self.series]) for title, names in panels]
        panels = [(title, names) for title, names in panels if names]
        fig, axes = panel_axes(ax, len(panels), 1, (8.0, 2.1 * len(panels) + 0.8))
        axes = axes[:, 0]
        for ax, (title, names) in zip(axes, panels):
            for name in names:
                target = ax.twinx() if name == "alpha" else ax
                deg = self.units[name] == "rad"
                target.plot(self.t, self.series[name] * (180 / math.pi if deg else 1.0),
                            label=name, color="tab:orange" if name in ("alpha", "psi_sensed",
                                                                        "delta_command")
                            else "tab:blue", ls="--" if name.endswith(("sensed", "command"))
                            else "-")
                target.set_ylabel(f"{'alpha ' if name == 'alpha' else ''}"
                                  f"[{'deg' if deg else self.units[name]}]", fontsize=8)
                target.legend(fontsize=8, loc="upper right" if name == "alpha" else "upper left")
            ax.set_title(title, fontsize=9)
            ax.grid(True, alpha=0.3)
        axes[-1].set_xlabel("t [s]")
        return finish_figure(fig)


def _atol(model, rtol, speed, t_final, mass) -> np.ndarray:
    """1e-10 on the attitude, slosh, bending and actuator states; ``rtol`` times the flight's
    own scale on the translation (``speed t_final``, ``speed``) and the mass, which start
    at or pass through zero where an absolute 1e-10 sits below their round-off."""
    scale = {"x": speed * t_final, "y": speed * t_final, "x_dot": speed, "y_dot": speed,
             "mass": mass}
    return np.array([max(rtol * scale[s], 1e-10) if s in scale else 1e-10
                     for s in model.states])


def launch_vehicle_response(*, thrust, inertia, arm, mass, k_psi, k_psidot, aero=None,
                            velocity=None, slosh=None, bending=None, actuator=None,
                            mass_flow=None, psi0=0.0, gust_speed=0.0, gust_start=0.0,
                            gust_duration=1.0, t_final=10.0, points=1001, rtol=1e-8,
                            progress=None) -> AutopilotResponse:
    """Simulate the autopilot flying the vehicle from an attitude error through a gust.

    Parameters
    ----------
    thrust, inertia, arm, mass, k_psi, k_psidot, aero, velocity, slosh, bending, actuator, mass_flow
        As `problems.stability.launch_vehicle` (actuator limits act here).
    psi0 : float [rad]
        Initial attitude error (everything else at the operating point).
    gust_speed : float [m/s]
        Peak lateral wind of the "1 - cosine" gust (module notes); needs ``aero``.
    gust_start : float [s]
        ``>= 0``.
    gust_duration : float [s]
        ``> 0``.
    t_final : float [s]
        ``> 0``.
    points : int
        Output times (``>= 2``; the gust window's ends are added).
    rtol : float
        Relative tolerance of `dynamics.simulate` (``atol`` 1e-10 on the attitude, slosh,
        bending and actuator states, ``rtol`` times the flight's scale on the translation and
        the mass; module notes).
    progress : callable, optional
        ``progress(done, total)`` of `dynamics.simulate`.

    Returns
    -------
    AutopilotResponse

    Raises
    ------
    ValueError
        Naming the argument: those of `problems.stability.launch_vehicle`, a gust without
        ``aero``, a non-positive ``gust_duration`` or ``t_final``, a negative
        ``gust_start``, ``points < 2``, a burn that empties the vehicle before ``t_final``.

    Examples
    --------
    >>> import math
    >>> from appdyn.problems.stability import launch_vehicle_response
    >>> res = launch_vehicle_response(thrust=2e6, inertia=4e7, arm=20.0, mass=1e5, k_psi=2.0,
    ...                               k_psidot=2.0, psi0=0.05, t_final=10.0, points=201)
    >>> res.success, float(res.series["psi"][0])
    (True, 0.05)
    >>> bool(abs(res.series["psi"][-1]) < 1e-5)  # zeta = 0.707, omega_n = 1.414 rad/s
    True
    """
    V = flight_speed(aero, velocity)
    psi0 = check_number(psi0, "psi0")
    w = check_number(gust_speed, "gust_speed")
    start = check_number(gust_start, "gust_start", nonnegative=True)
    duration = check_number(gust_duration, "gust_duration", positive=True)
    t_final = check_number(t_final, "t_final", positive=True)
    if w != 0 and aero is None:
        raise ValueError("`gust_speed` needs `aero`: the wind acts through the angle of attack")
    if isinstance(points, bool) or not isinstance(points, (int, np.integer)) or points < 2:
        raise ValueError(f"`points` must be an integer >= 2, got {points!r}")
    if mass_flow is not None and mass_flow.rate * t_final >= mass:
        raise ValueError(f"`t_final` = {t_final!r} s: the mass flow empties the vehicle "
                         f"(rate * t_final >= `mass`)")
    model = vehicle_model(thrust=thrust, inertia=inertia, arm=arm, mass=mass, k_psi=k_psi,
                          k_psidot=k_psidot, aero=aero and replace(aero, wind="control"),
                          slosh=slosh, bending=bending, actuator=actuator, mass_flow=mass_flow)
    x0 = frozen_state(model, V, float(mass))
    x0[model.states.index("psi")] = psi0
    t = np.linspace(0.0, t_final, int(points))
    if w != 0:
        t = np.union1d(t, [s for s in (start, start + duration) if 0 < s < t_final])
    u = None if aero is None else (lambda tk: [0.0, float(gust(tk, w, start, duration))])
    limited = actuator is not None and (actuator.deflection_limits or actuator.rate_limit)
    sim = simulate(model, x0, t, u=u, method="cvodes" if limited else "auto", rtol=rtol,
                   atol=_atol(model, rtol, (V or 0.0) + thrust / mass * t_final, t_final, mass),
                   invariants=["psi_sensed", "delta_command"], progress=progress)
    X = dict(zip(model.states, sim.x))
    series = {"psi": X["psi"], "psi_sensed": sim.invariants["psi_sensed"],
              "delta": X.get("delta", sim.invariants["delta_command"]),
              "delta_command": sim.invariants["delta_command"], "y_dot": X["y_dot"]}
    units = {"psi": "rad", "psi_sensed": "rad", "delta": "rad", "delta_command": "rad",
             "y_dot": "m/s"}
    if aero is not None:
        wind = gust(t, w, start, duration)
        c, s = np.cos(X["psi"]), np.sin(X["psi"])
        vy = X["y_dot"] - wind
        series.update(wind_y=wind, alpha=np.arctan2(s * X["x_dot"] - c * vy,
                                                    c * X["x_dot"] + s * vy))
        units.update(wind_y="m/s", alpha="rad")
    for name in ("theta_s", "r_s", "eta"):
        if name in X:
            series[name], units[name] = X[name], model.units[name]
    params = {"thrust": thrust, "inertia": inertia, "arm": arm, "mass": mass, "k_psi": k_psi,
              "k_psidot": k_psidot, "velocity": V, "aero": aero, "slosh": slosh,
              "bending": bending, "actuator": actuator, "mass_flow": mass_flow, "psi0": psi0,
              "gust_speed": w, "gust_start": start, "gust_duration": duration,
              "t_final": t_final, "rtol": rtol}
    return AutopilotResponse(t=sim.t, series=series, units=units,
                             parameters=plain({k: v for k, v in params.items()
                                               if v is not None}), simulation=sim)
