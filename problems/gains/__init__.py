"""Feedback-gain design by direct collocation (multi-scenario parameter optimization).

The gains are static parameters of an optimal control problem whose dynamics are the closed
loop, over several scenarios at once that share one gain set (`ocp.scenarios`). Every design
returns a `GainDesign` checked against what was asked: a stable loop (poles, damping,
margins from python-control) and the limits met in every scenario.

* `state_feedback_gains` (`state_feedback`): ``u = -K x`` for a linear plant and a quadratic
  cost over several initial states; the cross-check of the machinery: it reproduces
  ``control.lqr`` (to 1e-6 relative on the tests' plants) without solving a Riccati equation.
* `attitude_gains` (`spacecraft`, loop in `attitude_loop`): PD gains of a rigid spacecraft
  under torque limits, compared with the time-optimal slew.
* `launch_vehicle_gains` (`launch_vehicle`; data in `lv_data`, design model in `lv_model`,
  verification in `lv_verify`; TOML configs in `config`, example `launch_vehicle.toml`):
  the attitude/rate autopilot of a thrust-vectored vehicle with an unstable airframe, under
  gimbal deflection and rate limits, verified by the stability report and re-simulation.
"""
from __future__ import annotations

from .config import EXAMPLE_CONFIG, LaunchVehicleConfig, load_config, parse_config
from .launch_vehicle import (LaunchScenario, LaunchVehicle, launch_vehicle_gains,
                             plot_design)
from .result import STATUS_LIMITS, STATUS_UNSTABLE, GainDesign
from .spacecraft import attitude_gains
from .state_feedback import (HORIZON_RATIO_MIN, STATUS_NOT_SPANNING, STATUS_SHORT_HORIZON,
                             state_feedback_gains)

__all__ = ["GainDesign", "STATUS_UNSTABLE", "STATUS_LIMITS", "STATUS_NOT_SPANNING",
           "STATUS_SHORT_HORIZON", "HORIZON_RATIO_MIN", "state_feedback_gains", "attitude_gains",
           "launch_vehicle_gains", "LaunchVehicle", "LaunchScenario", "plot_design",
           "load_config", "parse_config", "LaunchVehicleConfig", "EXAMPLE_CONFIG"]
