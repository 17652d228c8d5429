"""Thrust-vectored launch vehicle in the yaw plane (Rheinfurth & Wilson, NASA RP-1262,
Sec. 5.4) with opt-in parts: aerodynamics, variable mass and jet damping, propellant slosh,
a bending mode, a gimbal actuator and the attitude/rate autopilot.

Modules: `parts` (the part classes `Aero`, `MassFlow`, `Slosh`, `Bending`, `Actuator`) and
`vehicle` (the derivation, in its docstring, and the builder `launch_vehicle`).
"""
from __future__ import annotations

from .parts import WIND_MODES, Actuator, Aero, Bending, MassFlow, Slosh
from .vehicle import RIGID_STATES, launch_vehicle, rigid_part

__all__ = ["launch_vehicle", "Aero", "MassFlow", "Slosh", "Bending", "Actuator", "WIND_MODES",
           "RIGID_STATES", "rigid_part"]
