"""Linear stability reports about spin states and operating points (Rheinfurth & Wilson,
NASA RP-1262, Secs. 4.5-4.6).

Every case returns a `StabilityReport`: the analysed ``control.StateSpace`` (``.ss``), its
eigenvalues, a verdict, a mode table with natural frequencies, damping ratios, labels and
closed-form values where they are known, derived quantities (precession and whirl rates,
stability boundaries), gain/phase margins for feedback loops, and ``success`` / ``status``
/ ``message`` of the check against the closed forms.

Cases
-----
=====================  ======================================================================
`spin`                 spin of any `dynamics.scene.Scene` about a hub axis, its parts at rest on
                       the hub (mode labels by part); or torque-free spin of a rigid body
                       about a principal axis, optionally with an energy damper
`heavy_top`            Method III, Example 1 (Eqs. 4.122-4.132)
`spinning_projectile`  Example 2: aerodynamic overturning moment in place of ``m g l``
`rotor`                Example 3: whirl (4.134-4.135) and internal-damping instability
`gyrostat`             body + wheel of constant relative speed, optional damper
`launch_vehicle`       thrust-vectored vehicle under the attitude/rate autopilot (Sec. 5.4):
                       margins at the engine deflection, named modes; `bode_plot`,
                       `nichols_plot`, `launch_vehicle_response` (time response)
`vehicle_loops`        pitch and yaw autopilot loops of a thrust-vectored vehicle scene (an
                       `Engine` on a six-degree-of-freedom hub): margins per axis
`loop`                 any plant with a feedback law: margins via ``control.stability_margins``
`shaken_pendulum`      hanging / inverted pendulum on a shaken hinge: Floquet multipliers
                       (a `PeriodicStabilityReport`), checked against Mathieu's chart
`conical_pendulum`     steady cone of the spherical pendulum (3-1-3 or 3-2-1 form), reduced by
                       its symmetry about the vertical (Routh)
`hinged_spin`          two hinged bodies spinning together about a common axis (ball or
                       revolute hinge), reduced to the independent tilt coordinates;
                       `hinged_scene` its scene (a six-degree-of-freedom hub and a panel)
`analyze`              any ``StateSpace`` (e.g. from `dynamics.linearize.linearize`)
=====================  ======================================================================

`sweep` runs a case along one parameter and locates each verdict boundary by bisection.

Modules: `verdict` (the rule: an eigenvalue with ``|Re| <= ZERO_RTOL * rho`` counts as on
the imaginary axis; "marginally stable" needs those to be semisimple), `report` (the report,
its statuses, `analyze`), `closed_forms`, `spin`, `tilt` and `launch_vehicle` (the cases),
`spin_scene` (a scene's relative equilibrium, linearization and reduction),
`launch_vehicle_plots` (Bode, Nichols), `launch_vehicle_response` (time response), `loop`,
`periodic` (time-periodic operating points), `constrained` (relative equilibria),
`cases` (the table of names), `sweep`, `common` (shared conversions and checks).

Spin cases report the *reduced* motion: the spin phase about the axis (cyclic) and the
conserved spin-axis momentum (a first integral, whose steady spins form a one-parameter
family with eigenvalue 0), and a scene's further first integrals (a free wheel's axial
momentum), are factored out by `Linearization.quotient` and `Linearization.restrict`; the
notes say which states went. A scene's six-degree-of-freedom hub is reduced to its attitude
with the system mass centre at rest (`spin_scene.attitude_subsystem`). The launch vehicle's
translation (rigid-body drift, for guidance to correct) is factored out the same way.

Examples
--------
>>> from appdyn.problems import stability
>>> stability.spin([2.0, 3.0, 4.5], axis=[0, 0, 1], rate=5.0).verdict
'marginally stable'
>>> from appdyn.dynamics.scene import PointMassDamper, RigidHub, Scene
>>> scene = Scene(RigidHub([5.0, 3.0, 4.0]),
...               PointMassDamper(0.5, 60.0, 0.8, position=(0, 0.6, 0), direction=(1, 0, 0)))
>>> stability.spin(scene, axis=[1, 0, 0], rate=4.0).verdict  # major axis, energy damper
'asymptotically stable'
"""
from appdyn.dynamics.spinning import PointMassDamper, SphericalDamper

from .cases import CASE_ALIASES, CASES, resolve_case
from .common import STANDARD_GRAVITY
from .constrained import conical_pendulum
from .hinged import hinged_scene, hinged_spin
from .launch_vehicle import launch_vehicle
from .launch_vehicle_plots import bode_plot, loop_transfer, nichols_plot
from .launch_vehicle_response import AutopilotResponse, launch_vehicle_response
from .loop import loop
from .periodic import FloquetMode, PeriodicStabilityReport, shaken_pendulum
from .report import (CLOSED_FORM_RTOL, STATUS_MISMATCH, STATUS_UNCHECKED, STATUS_VERIFIED,
                     Margins, Mode, Quantity, StabilityReport, analyze)
from .spin import gyrostat, spin
from .sweep import Boundary, SweepResult, sweep
from .tilt import heavy_top, rotor, spinning_projectile
from .vehicle_loops import vehicle_loops
from .verdict import VERDICTS, ZERO_RTOL, classify

__all__ = [
    "ZERO_RTOL", "VERDICTS", "Mode", "Margins", "Quantity", "StabilityReport", "Boundary",
    "SweepResult", "PointMassDamper", "SphericalDamper", "classify", "analyze", "spin",
    "heavy_top", "spinning_projectile", "rotor", "gyrostat", "launch_vehicle", "loop_transfer",
    "bode_plot", "nichols_plot", "launch_vehicle_response", "AutopilotResponse", "loop",
    "sweep", "CASES",
    "CASE_ALIASES", "resolve_case", "STANDARD_GRAVITY", "STATUS_VERIFIED", "STATUS_UNCHECKED",
    "STATUS_MISMATCH", "CLOSED_FORM_RTOL", "shaken_pendulum", "conical_pendulum",
    "PeriodicStabilityReport", "FloquetMode", "hinged_spin", "hinged_scene", "vehicle_loops",
]
