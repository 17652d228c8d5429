"""Build any vehicle from parts: ``Scene(hub, *parts).model()``.

A `Scene` is a `RigidHub` carrying parts; it assembles into one `Model` (named states and
controls, units, bounds, invariants, and ``layout``: each part's slices). The part contract
-- what a part declares and contributes, and the rules for adding one -- is the docstring of
`dynamics.scene.contract`; the assembly (Kane's method on the symbols, one block solve) is
`dynamics.scene.assembly`.

Parts
-----
=====================  =====================================================================
`ReactionWheels`       wheels driven by motor torques (states ``W``, controls ``tau``)
`HeldRotor`            a rotor at constant relative speed (the gyrostat's wheel)
`CMGCluster`           single-gimbal CMGs (states ``d``; controls gimbal rates ``d_dot``, or
                       gimbal torques ``tg`` with the rates as states)
`ExternalTorque`       body torque controls ``L1..L3``
`ExternalForce`        force controls ``F1..F3`` at a hub point
`PointMassDamper`      a mass on a spring and dashpot sliding along a hub line (``s, s_dot``)
`SphericalDamper`      a viscously coupled spherical core (core rate ``wd1..wd3``)
`Slosh`                slosh as a pendulum (two angles) or a spring-mass (``s, s_dot``)
`TiltTorque`           a torque from the tilt of a hub axis (heavy top, projectile, bearings)
`HingedPanel`          a rigid panel on a revolute (``theta``) or ball (``p1..p4``) hinge
`GravityGradient`      gravity on every body: forces and gravity-gradient torques
`FlexibleAppendage`    a flexible cantilever by clamped-free modes (``eta``, ``xi``), with
                       geometric stiffening; `flexible_antenna_satellite`: seed Example 6
`Engine`               gimbaled thrust (controls ``dp, dy`` or an actuator), mass flow
                       (state ``m_p``), internal-flow Coriolis force and jet damping
`Aerodynamics`         normal and axial air force at a centre of pressure (6-DoF hub; wind
                       controls ``wind1..wind3`` optional)
`BendingMode`          a free-free body bending mode per transverse plane in mean axes
                       (``eta, eta_dot``); carries parts at a station (an engine on the
                       gimbal), gyro invariants ``gyro_tilt``, ``gyro_tilt_rate``
=====================  =====================================================================

``RigidHub(inertia, reference_rate=Omega)`` refers the attitude to a frame turning at a
constant rate (Earth-fixed, LVLH) instead of inertial space.

Parts sit on the hub, or on a part that carries parts (a `HingedPanel`, a `BendingMode`)
named by their ``parent`` keyword: ``ReactionWheels(axes, 0.05, parent="panel")``.

`launch_vehicle_scene` builds the launch vehicle of `dynamics.launch_vehicle` from these (six
degrees of freedom; its yaw plane is the planar model); `attitude_autopilot` flies it.

Examples
--------
>>> from appdyn.dynamics.scene import ExternalTorque, RigidHub, Scene
>>> model = Scene(RigidHub([1.0, 2.0, 3.0]), ExternalTorque(u_max=1.0)).model()
>>> model.nx, model.controls
(7, ('L1', 'L2', 'L3'))
"""
from .aero import Aerodynamics
from .assembly import PartLayout
from .bending import BendingMode
from .cmgs import CMGCluster
from .contract import Body, Contribution, Frame, Load, Part, PartVariables, Variable
from .dampers import PointMassDamper, Slosh, SphericalDamper
from .engine import Engine
from .fields import TiltTorque
from .flexible import FlexibleAppendage, flexible_antenna_satellite
from .gravity import GravityGradient
from .hubs import RigidHub
from .loads import ExternalForce, ExternalTorque
from .panels import HingedPanel
from .rocket import attitude_autopilot, launch_vehicle_scene, sensed_attitude
from .scene import Scene, check_scene
from .wheels import HeldRotor, ReactionWheels

__all__ = ["Scene", "check_scene", "RigidHub", "Part", "PartLayout", "Variable", "PartVariables", "Body", "Load",
           "Contribution", "Frame", "ReactionWheels", "HeldRotor", "ExternalTorque",
           "ExternalForce", "PointMassDamper", "SphericalDamper", "Slosh", "TiltTorque",
           "HingedPanel", "GravityGradient", "CMGCluster", "Aerodynamics", "Engine",
           "launch_vehicle_scene", "attitude_autopilot", "FlexibleAppendage",
           "flexible_antenna_satellite", "BendingMode", "sensed_attitude"]
