"""Optimal attitude slews: time-optimal and minimum-effort, of any scene.

The entry point is `slew`: ``slew(scene, objective="time" | "effort", angle=..., axis=...,
q_final=..., T=..., w0=..., wf=..., **options)`` for any `dynamics.scene.Scene` -- bounds
from its parts, settings in one `SlewOptions` (or as keywords). A scene that is exactly a
proven pipeline goes to it (a hub with an `ExternalTorque`: `time_optimal` / `min_effort`;
with reaction wheels: `wheel_slew`; with a CMG cluster: `cmg_slew`); any other scene is
solved by the generic path on its assembled model (`scene_slew`). The four engines below keep
their signatures; prefer ``slew(scene)``.

>>> import numpy as np
>>> from appdyn.dynamics.scene import ExternalTorque, RigidHub, Scene
>>> from appdyn.problems.slew import slew
>>> sol = slew(Scene(RigidHub(np.eye(3)), ExternalTorque(u_max=1.0)), angle=0.1,
...            axis=[0, 0, 1], N=10, starts=1)
>>> sol.success, round(sol.T, 6)  # the eigenaxis bang-bang 2 sqrt(0.1)
(True, 0.632456)

The rigid-body engines build an `ocp.Problem` on `dynamics.rigid_body` (state ``[q1..q4,
w1..w3]``, control body torque) and return an `ocp.Solution`:

* `time_optimal` minimizes the final time under per-axis torque bounds ``|u_i| <= u_max_i``
  or a norm bound ``|u| <= u_max``. Time-optimal slews have local optima (the eigenaxis
  maneuver is one, Bilimoria & Wie 1993), so without a user guess it solves from several
  seeded guesses (the eigenaxis SLERP and SLERPs tilted by a sinusoidal rotation about
  seeded random axes), raced on a coarse mesh until two agree, keeps the best, and polishes
  the bang-bang switch times (`ocp.polish_switches`).
* `min_effort` minimizes ``1/2 integral |u|^2 dt`` over a fixed time, refined until the
  re-integrated trajectory matches the collocated one (`ocp.refine`).

The target attitude is ``qf`` or a rotation by ``angle`` about ``axis`` (body frame at the
start) from ``q0``; it is met up to sign (``q`` and ``-q`` are the same attitude). End rates
default to rest. An optional keep-out cone keeps a body-fixed boresight more than a given
angle away from an inertial direction throughout.

Verified results
----------------
Every slew result says ``success=True`` only when

1. the NLP is verified (`ocp.solve`: IPOPT's ``Solve_Succeeded`` and a constraint violation
   below ``constraint_tol``; for `min_effort` also the refinement ``tol`` met), and
2. re-simulating the returned control from ``q0``, ``w0`` (`ocp.Solution.propagation`,
   CVODES at rtol = atol = 1e-12) ends within ``pointing_tol`` [rad] of the target attitude
   (`ocp.Solution.pointing_error`, the rotation angle between the re-simulated final
   quaternion and ``qf``) and within ``rate_tol`` [rad/s] of the final rates ``wf``
   (largest component of `ocp.Solution.terminal_error`). Defaults: ``pointing_tol`` =
   `POINTING_TOL` = 1e-6 rad (0.2 arcsec), ``rate_tol`` = `RATE_TOL` = 1e-6 rad/s.

Otherwise ``success=False`` with ``status`` `STATUS_POINTING` (106 ``Pointing_Tol_Not_Met``),
`STATUS_REFINE` (107 ``Refinement_Tol_Not_Met``) or the engine's own status (ints, the table
of `ocp.status`). A rest-to-rest
slew by a zero angle (``q0 = +/- qf``) is answered exactly without an NLP:
`ocp.rest_solution` with ``T = 0`` (time-optimal) or zero torque over ``T`` (minimum
effort), ``status = 0`` and ``solver_status = 'Rest_Solution'``. Tiny angles are solved in
well-conditioned units: the
horizon and the objective are scaled by the bang-bang time ``2 sqrt(angle / alpha)``, the
target rows by the initial attitude error (`ocp.scaling`).

Modules
-------
`scene_slew` (`slew`, `scene_problem`: the generic path), `options` (`SlewOptions`),
`targets` (input checks, the target attitude, `KeepOut`, defaults and statuses),
`problem` (`slew_problem`, `eigenaxis_time`, guesses), `maneuvers` (`time_optimal`,
`min_effort`, `verify`, `bounded`), `table` (`maneuver_table`: the slew to every target of a
catalogue, on any executor, as a `ManeuverTable`), `devices` (`wheel_slew`, `cmg_slew`: the same slews by reaction
wheels or CMGs, momentum exchanged inside the spacecraft), `report` (`switch_times`, `summary`, `format_summary`, `plot_slew`).
"""
from __future__ import annotations

from .devices import cmg_slew, wheel_slew
from .maneuvers import bounded, min_effort, time_optimal, verify
from .options import SlewOptions
from .scene_slew import scene_problem, slew
from .problem import attitude_guess, eigenaxis_time, slew_problem
from .report import format_summary, plot_slew, polish_text, summary, switch_times
from .table import ManeuverTable, example_targets, maneuver_table
from .targets import (MIN_REFINE_TOL, POINTING_TOL, RATE_TOL, STATUS_POINTING, STATUS_REFINE,
                      KeepOut)

__all__ = ["slew", "SlewOptions", "scene_problem", "KeepOut", "slew_problem", "time_optimal", "min_effort", "wheel_slew", "cmg_slew", "eigenaxis_time",
           "switch_times", "attitude_guess", "verify", "bounded", "polish_text", "summary", "format_summary", "plot_slew",
           "maneuver_table", "ManeuverTable", "example_targets",
           "POINTING_TOL", "RATE_TOL", "MIN_REFINE_TOL", "STATUS_POINTING", "STATUS_REFINE"]
