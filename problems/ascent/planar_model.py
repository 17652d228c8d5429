"""Pitch-plane ascent of appdyn's thrust-vectored launch vehicle: the optimal pitch program
(`planar_ascent`) and that program flown through the vehicle's attitude autopilot
(`fly_pitch_program`).

The vehicle and where its numbers come from
-------------------------------------------
`AscentVehicle.default()` reads the vehicle of the launch-vehicle autopilot design,
``problems/gains/launch_vehicle.toml`` (`problems.gains.EXAMPLE_CONFIG`, the RP-1262
Sec. 5.4 vehicle of `dynamics.launch_vehicle`): thrust ``F = 2.0e6 N``, mass ``1.0e5 kg``
(taken here as the lift-off mass), pitch inertia ``4.0e7 kg m^2`` at that mass, gimbal arm
``l = 20 m``, reference area ``S = 10 m^2``, normal-force slope ``C_N_alpha = 3 /rad``,
centre of pressure ``l_cp = 5 m`` ahead of the mass centre (unstable airframe), gimbal servo
time constant ``0.08 s`` and the deflection limit ``6 deg``. The data hold no propulsion
budget, axial force or atmosphere; these are assumptions, named constants of this module:

* `MASS_FLOW_RATE` = 700 kg/s: the ``MassFlow(rate=700.0)`` that appdyn's own tests give this
  vehicle (``tests/dynamics/test_launch_vehicle.py``), so ``v_e = F / mdot = 2857 m/s``
  (``Isp = 291 s``);
* `BURN_TIME` = 100 s: 70 t of propellant, burnout mass 30 t (ideal ``Delta V = v_e ln(1/0.3)
  = 3440 m/s``);
* `AXIAL_COEFFICIENT` = 0.5: the drag coefficient of the Delta III ascent benchmark (DESIGN.md
  truth catalogue), used as the axial-force coefficient ``C_A``;
* the exponential atmosphere ``rho = RHO0 exp(-h / SCALE_HEIGHT)`` with `RHO0` = 1.225
  kg/m^3 and `SCALE_HEIGHT` = 7200 m, and `G0` = 9.80665 m/s^2, `EARTH_RADIUS` = 6378145 m
  (the same benchmark's constants).

Point-mass model (`planar_model`)
---------------------------------
A round, non-rotating Earth of radius ``R`` with inverse-square gravity
``g(h) = g0 (R / (R + h))^2`` (``mu = g0 R^2``). The vehicle moves in a plane through the
Earth's centre; ``r = R + h`` and ``phi`` (central angle) locate it, ``x = R phi`` is the
downrange distance over the surface. The velocity ``V`` makes the flight-path angle
``gamma`` with the local horizontal. With unit vectors ``v`` (along the velocity) and ``n``
(``v`` turned +90 deg, "up" for ``gamma = 0``), the acceleration in polar coordinates is
``V' v + V (gamma' + phi') n`` because the local horizontal itself turns at
``phi' = V cos(gamma) / r``. The forces: thrust ``F`` along the body axis (pitch ``theta``
from the local horizontal, angle of attack ``alpha = theta - gamma``), the aerodynamic
normal force ``N = q S C_N_alpha alpha`` (normal to the body axis, as `dynamics.launch_vehicle`'s
`~dynamics.launch_vehicle.Aero`) and axial force ``A = q S C_A`` (along the body axis,
aft), ``q = 1/2 rho V^2``, and gravity ``-m g`` along the local vertical. Resolved on ``(v, n)``
with the full trigonometry (lift ``L = N cos(alpha) - A sin(alpha)``, drag
``D = A cos(alpha) + N sin(alpha)``)::

    h'     = V sin(gamma)
    x'     = V cos(gamma) R / (R + h)
    V'     = (F cos(alpha) - D) / m - g(h) sin(gamma)
    gamma' = (F sin(alpha) + L) / (m V) - (g(h) / V - V / (R + h)) cos(gamma)
    m'     = -mdot

The parameters ``rho0``, ``g0``, ``radius`` are model parameters: ``rho0 = 0`` removes the
atmosphere, a huge ``radius`` gives flat-Earth constant gravity (the vertical-flight check
of the tests: ``V = V0 - g0 t + v_e ln(m0 / m)``).

Pitch dynamics (`pitch_model`)
------------------------------
The rigid vehicle of `dynamics.launch_vehicle` in the pitch plane, flying the point-mass
translation above with its actual attitude: the gimbal deflection ``delta`` turns the
thrust clockwise from the body axis (library convention: thrust ``F (cos delta, -sin delta)``
in body axes at the gimbal ``l`` aft), so the thrust makes the angle ``alpha - delta`` with
the velocity. With ``omega`` the inertial pitch rate (what the rate gyro reads)::

    theta' = omega - V cos(gamma) / (R + h)          (theta from the local horizontal)
    I(m) omega' = F l sin(delta) + N l_cp - mdot l^2 omega
    I(m) = I_ref m / m_ref                             (constant radius of gyration)

``N l_cp`` is the destabilizing moment of the normal force at the centre of pressure ahead
of the mass centre; ``-mdot l^2 omega`` is the jet damping of Eq. 3.49 with the flow from the
mass centre to the gimbal (the defaults of `~dynamics.launch_vehicle.MassFlow`), whose
Coriolis force ``2 mdot l omega`` along the body normal is included in the translation as
well. (The brief's ``-F l sin(delta)`` has the opposite deflection sign; with the
library's sign the autopilot below is stabilizing, as in Sec. 5.4.) The autopilot is
``delta_c = -(k_theta (theta - theta_c) + k_thetadot (theta' - theta_c'))`` and the gimbal a
first-order servo ``delta' = (delta_c - delta) / tau``. The command ``theta_c(t)`` and its
rate are the optimal pitch program through a C1 monotone cubic (PCHIP) through the
collocation nodes.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import casadi as ca

from appdyn.dynamics import cache
from appdyn.dynamics.model import Model, model_from_expressions
from appdyn.dynamics.validate import finite_scalar, positive

# the atmosphere, gravity and Earth of the Delta III benchmark (one place for them)
from .delta3 import G0, H_SCALE as SCALE_HEIGHT, RE as EARTH_RADIUS, RHO0

__all__ = ["check_vehicle", "RHO0", "SCALE_HEIGHT", "G0", "EARTH_RADIUS", "AXIAL_COEFFICIENT", "MASS_FLOW_RATE",
           "BURN_TIME", "STATES", "TRACKING_STATES", "AscentVehicle", "planar_model", "pitch_model",
           "vertical_rise"]

# ----------------------------------------------------------------- data (assumed)
AXIAL_COEFFICIENT = 0.5  #: axial-force coefficient C_A [-] (Delta III benchmark's C_D)
MASS_FLOW_RATE = 700.0   #: [kg/s] (tests/dynamics/test_launch_vehicle.py)
BURN_TIME = 100.0        #: [s] from lift-off to burnout

STATES = ("h", "x", "V", "gamma", "m")
TRACKING_STATES = STATES + ("theta", "omega", "delta")
_UNITS = {"h": "m", "x": "m", "V": "m/s", "gamma": "rad", "m": "kg", "theta": "rad",
          "omega": "rad/s", "delta": "rad", "theta_cmd": "rad", "theta_cmd_dot": "rad/s",
          "rho0": "kg/m^3", "g0": "m/s^2", "radius": "m"}


@dataclass(frozen=True)
class AscentVehicle:
    """The vehicle of the ascent (module docstring for the sources of `default`).

    Parameters
    ----------
    thrust : float [N]
    mass : float [kg]
        Lift-off mass.
    mass_flow_rate : float [kg/s]
    burn_time : float [s]
        Lift-off to burnout; ``mass_flow_rate * burn_time < mass``.
    area : float [m^2]
    normal_force_slope : float [1/rad]
    axial_coefficient : float [-]
        ``>= 0``.
    inertia : float [kg m^2]
        Pitch inertia at ``inertia_mass``.
    inertia_mass : float [kg]
        The mass at which ``inertia`` holds (scaled as ``I m / inertia_mass``).
    arm : float [m]
        Mass centre to gimbal.
    cp_arm : float [m]
        Centre of pressure ahead of the mass centre (> 0 unstable).
    actuator_time_constant : float [s]
    delta_max : float [rad]
        Gimbal deflection limit.
    """

    thrust: float
    mass: float
    mass_flow_rate: float
    burn_time: float
    area: float
    normal_force_slope: float
    axial_coefficient: float
    inertia: float
    inertia_mass: float
    arm: float
    cp_arm: float
    actuator_time_constant: float
    delta_max: float

    def __post_init__(self):
        for name in ("thrust", "mass", "mass_flow_rate", "burn_time", "area",
                     "normal_force_slope", "inertia", "inertia_mass", "arm",
                     "actuator_time_constant", "delta_max"):
            object.__setattr__(self, name, positive(getattr(self, name), name))
        for name in ("axial_coefficient", "cp_arm"):
            object.__setattr__(self, name, finite_scalar(getattr(self, name), name))
        if self.axial_coefficient < 0:
            raise ValueError(f"`axial_coefficient` must be >= 0, got {self.axial_coefficient!r}")
        if not self.mass_flow_rate * self.burn_time < self.mass:
            raise ValueError(f"`burn_time`: mass_flow_rate * burn_time = "
                             f"{self.mass_flow_rate * self.burn_time!r} kg empties the vehicle "
                             f"(`mass` = {self.mass!r} kg)")

    @classmethod
    def default(cls) -> "AscentVehicle":
        """The vehicle of ``problems/gains/launch_vehicle.toml`` plus this module's
        propulsion and axial-force assumptions (module docstring)."""
        return _default_vehicle()

    @property
    def exhaust_velocity(self) -> float:
        """``v_e = F / mdot`` [m/s]."""
        return self.thrust / self.mass_flow_rate

    @property
    def burnout_mass(self) -> float:
        """``mass - mdot burn_time`` [kg]."""
        return self.mass - self.mass_flow_rate * self.burn_time


@cache.memoize
def _default_vehicle() -> AscentVehicle:
    from appdyn.problems.gains import EXAMPLE_CONFIG, load_config

    cfg = load_config(EXAMPLE_CONFIG)
    v = cfg.vehicle
    return AscentVehicle(thrust=v.thrust, mass=v.mass, mass_flow_rate=MASS_FLOW_RATE,
                         burn_time=BURN_TIME, area=v.aero.area,
                         normal_force_slope=v.aero.normal_force_slope,
                         axial_coefficient=AXIAL_COEFFICIENT, inertia=v.inertia,
                         inertia_mass=v.mass, arm=v.arm, cp_arm=v.aero.cp_arm,
                         actuator_time_constant=v.actuator.time_constant,
                         delta_max=cfg.options["delta_max"])


def check_vehicle(vehicle) -> AscentVehicle:
    """``vehicle``, or `AscentVehicle.default` for None; TypeError naming ``vehicle`` for
    anything else.

    Examples
    --------
    >>> from appdyn.problems.ascent.planar_model import AscentVehicle, check_vehicle
    >>> check_vehicle(None) == AscentVehicle.default()
    True
    """
    if vehicle is None:
        return AscentVehicle.default()
    if not isinstance(vehicle, AscentVehicle):
        raise TypeError(f"`vehicle` must be an AscentVehicle or None, got "
                        f"{type(vehicle).__name__}")
    return vehicle


# ------------------------------------------------------------------------ models
def _translation(veh: AscentVehicle, S, thrust_angle, extra_normal=0):
    """``(xdot dict, q, alpha)`` of the point mass (module docstring); ``thrust_angle`` is the
    thrust direction from the velocity, ``extra_normal`` a body-normal force [N]."""
    h, V, gam, m = S["h"], S["V"], S["gamma"], S["m"]
    rho0, g0, R = S["rho0"], S["g0"], S["radius"]
    alpha = S["alpha"]
    r = R + h
    g = g0 * (R / r) ** 2
    q = 0.5 * rho0 * ca.exp(-h / SCALE_HEIGHT) * V ** 2
    N = q * veh.area * veh.normal_force_slope * alpha + extra_normal
    A = q * veh.area * veh.axial_coefficient
    lift = N * ca.cos(alpha) - A * ca.sin(alpha)
    drag = A * ca.cos(alpha) + N * ca.sin(alpha)
    F = veh.thrust
    xdot = {"h": V * ca.sin(gam), "x": V * ca.cos(gam) * R / r,
            "V": (F * ca.cos(thrust_angle) - drag) / m - g * ca.sin(gam),
            "gamma": (F * ca.sin(thrust_angle) + lift) / (m * V) - (g / V - V / r) * ca.cos(gam),
            "m": ca.SX(-veh.mass_flow_rate)}
    return xdot, q, N


def _params():
    P = {n: ca.SX.sym(n) for n in ("rho0", "g0", "radius")}
    return P, {"rho0": RHO0, "g0": G0, "radius": EARTH_RADIUS}


@cache.memoize_values
def planar_model(vehicle: AscentVehicle | None = None) -> Model:
    """The point-mass pitch-plane ascent model (module docstring), cached by ``vehicle``.

    Parameters
    ----------
    vehicle : AscentVehicle, optional
        Default `AscentVehicle.default`.

    Returns
    -------
    dynamics.Model
        States ``h`` [m], ``x`` [m], ``V`` [m/s], ``gamma`` [rad], ``m`` [kg]; control
        ``theta`` [rad] (pitch from the local horizontal); parameters ``rho0`` [kg/m^3]
        (default `RHO0`), ``g0`` [m/s^2] (`G0`), ``radius`` [m] (`EARTH_RADIUS`).
        Invariant ``q`` [Pa].

    Examples
    --------
    >>> import numpy as np
    >>> m = planar_model()
    >>> xdot = m.rhs([0.0, 0.0, 50.0, np.pi / 2, 1e5], [np.pi / 2], [0.0, 9.80665, 1e15])
    >>> round(float(xdot[2]), 6)  # F / m - g0 with no air, flat Earth
    10.19335
    """
    veh = check_vehicle(vehicle)
    X = {n: ca.SX.sym(n) for n in STATES}
    theta = ca.SX.sym("theta")
    P, defaults = _params()
    S = {**X, **P, "alpha": theta - X["gamma"]}
    xdot, q, _ = _translation(veh, S, S["alpha"])
    return model_from_expressions([(n, X[n]) for n in STATES], [xdot[n] for n in STATES],
                                  {"theta": theta}, P, p_default=defaults,
                                  units={n: _UNITS[n] for n in (*STATES, "theta", *P)},
                                  invariants={"q": q}, name="planar_ascent")


@cache.memoize_values
def pitch_model(vehicle: AscentVehicle | None, k_theta: float, k_thetadot: float) -> Model:
    """The rigid vehicle's pitch dynamics on the point-mass translation, closed by the
    autopilot and a first-order gimbal (module docstring), cached by its arguments.

    Parameters
    ----------
    vehicle : AscentVehicle or None
    k_theta : float [rad/rad]
    k_thetadot : float [rad/(rad/s)]

    Returns
    -------
    dynamics.Model
        States `TRACKING_STATES`: ``h, x, V, gamma, m`` as `planar_model`, ``theta`` [rad]
        (pitch from the local horizontal), ``omega`` [rad/s] (inertial pitch rate),
        ``delta`` [rad] (gimbal); controls ``theta_cmd`` [rad], ``theta_cmd_dot`` [rad/s];
        parameters as `planar_model`. Invariants ``q`` [Pa], ``alpha`` [rad] and
        ``delta_dot`` [rad/s] are not given (they need the controls); see `PitchTracking`.
    """
    veh = check_vehicle(vehicle)
    kt, kd = finite_scalar(k_theta, "k_theta"), finite_scalar(k_thetadot, "k_thetadot")
    X = {n: ca.SX.sym(n) for n in TRACKING_STATES}
    U = {n: ca.SX.sym(n) for n in ("theta_cmd", "theta_cmd_dot")}
    P, defaults = _params()
    d = X["theta"] - X["gamma"]
    alpha = ca.atan2(ca.sin(d), ca.cos(d))  # wrapped: a tumbling open loop stays bounded
    S = {**X, **P, "alpha": alpha}
    mdot, l = veh.mass_flow_rate, veh.arm
    coriolis = 2 * mdot * l * X["omega"]  # body-normal force of the internal flow
    xdot, _, N = _translation(veh, S, alpha - X["delta"], coriolis)
    N_aero = N - coriolis
    r = P["radius"] + X["h"]
    frame_rate = X["V"] * ca.cos(X["gamma"]) / r
    theta_dot = X["omega"] - frame_rate
    inertia = veh.inertia * X["m"] / veh.inertia_mass
    xdot["theta"] = theta_dot
    xdot["omega"] = (veh.thrust * l * ca.sin(X["delta"]) + N_aero * veh.cp_arm
                     - mdot * l ** 2 * X["omega"]) / inertia
    command = -(kt * (X["theta"] - U["theta_cmd"]) + kd * (theta_dot - U["theta_cmd_dot"]))
    xdot["delta"] = (command - X["delta"]) / veh.actuator_time_constant
    return model_from_expressions([(n, X[n]) for n in TRACKING_STATES],
                                  [xdot[n] for n in TRACKING_STATES], U, P, p_default=defaults,
                                  units={n: _UNITS[n] for n in (*TRACKING_STATES, *U, *P)},
                                  name="pitch_tracking")


def vertical_rise(vehicle: AscentVehicle | None, speed: float, g0: float = G0):
    """The vertical rise from rest to ``speed``, drag-free in constant gravity (closed form).

    ``V(t) = -v_e ln(1 - a t) - g0 t`` and ``h(t) = v_e (s ln s - s + 1) / a - g0 t^2 / 2``
    with ``a = mdot / m0``, ``s = 1 - a t`` (Tsiolkovsky with gravity loss). Drag is left out:
    below 100 m/s at sea level it is under 1.6 % of the thrust here; inverse-square gravity
    differs from ``g0`` by ``2 h / R``, under 1e-4 over the rise.

    Parameters
    ----------
    vehicle : AscentVehicle or None
    speed : float [m/s]
        ``> 0``, reached before burnout.
    g0 : float [m/s^2]

    Returns
    -------
    t [s], h [m], m [kg]
        Time after lift-off, altitude and mass when ``V = speed``.

    Examples
    --------
    >>> t, h, m = vertical_rise(None, 50.0)
    >>> round(t, 3), round(h, 2), round(m, 1)
    (4.747, 117.38, 96677.2)
    """
    veh = check_vehicle(vehicle)
    V1 = positive(speed, "speed")
    ve, a = veh.exhaust_velocity, veh.mass_flow_rate / veh.mass
    if veh.thrust <= veh.mass * g0:
        raise ValueError(f"`vehicle`: thrust {veh.thrust!r} N does not lift the mass "
                         f"{veh.mass!r} kg")
    vel = lambda t: -ve * math.log(1.0 - a * t) - g0 * t  # noqa: E731
    if not V1 < vel(veh.burn_time):
        raise ValueError(f"`initial_speed` = {V1!r} m/s is not reached before burnout")
    lo, hi = 0.0, veh.burn_time
    for _ in range(200):  # bisection: V(t) is increasing while thrust > weight
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if vel(mid) < V1 else (lo, mid)
    t = 0.5 * (lo + hi)
    s = 1.0 - a * t
    h = ve * (s * math.log(s) - s + 1.0) / a - 0.5 * g0 * t * t
    return t, h, veh.mass * s
