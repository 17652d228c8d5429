"""Launch-vehicle ascent trajectories.

* `delta3`: the Delta III-class four-phase ascent to a geostationary transfer orbit (Benson
  2005; Betts 2010; GPOPS-II): data, one `dynamics.Model` per phase, target orbit, orbital
  elements, bounds and guesses.
* `delta3_ascent`: that ascent as a multi-phase optimal-control problem (`ocp.phases`),
  solved with per-phase mesh refinement and checked independently (`delta3_ascent`).
* `planar_model`: the thrust-vectored launch vehicle of `dynamics.launch_vehicle` in the
  pitch plane: point-mass ascent model and rigid pitch model with gimbal and autopilot.
* `planar`: its optimal pitch program to a target altitude and flight-path angle under
  dynamic-pressure and ``q alpha`` limits (`planar_ascent`).
* `pitch_tracking`: that program flown through the attitude autopilot in simulation
  (`fly_pitch_program`: tracking error, peak gimbal deflection).
"""
from __future__ import annotations

from .delta3 import (PHASES, TARGET_ORBIT, OrbitalElements, PhaseData, delta3_model, drag_force,
                     guess, initial_state, orbit_residuals, orbital_elements, phase_bounds,
                     state_from_elements)
from .delta3_ascent import AscentResult, PhaseRow, delta3_ascent, delta3_problem, dynamic_pressure
from .pitch_tracking import PitchTracking, default_gains, fly_pitch_program
from .planar import (STATUS_LIMITS, STATUS_PROPAGATION, STATUS_TERMINAL, PlanarAscent,
                     planar_ascent)
from .planar_model import (AXIAL_COEFFICIENT, BURN_TIME, EARTH_RADIUS, G0, MASS_FLOW_RATE, RHO0,
                           SCALE_HEIGHT, STATES, TRACKING_STATES, AscentVehicle, pitch_model,
                           planar_model, vertical_rise)

__all__ = ["AscentResult", "OrbitalElements", "PHASES", "PhaseData", "PhaseRow", "TARGET_ORBIT",
           "delta3_ascent", "delta3_model", "delta3_problem", "drag_force", "dynamic_pressure",
           "guess", "initial_state", "orbit_residuals", "orbital_elements", "phase_bounds",
           "state_from_elements", "PitchTracking", "default_gains", "fly_pitch_program",
           "STATUS_LIMITS", "STATUS_PROPAGATION", "STATUS_TERMINAL", "PlanarAscent",
           "planar_ascent", "AXIAL_COEFFICIENT", "BURN_TIME", "EARTH_RADIUS", "G0",
           "MASS_FLOW_RATE", "RHO0", "SCALE_HEIGHT", "STATES", "TRACKING_STATES",
           "AscentVehicle", "pitch_model", "planar_model", "vertical_rise"]
