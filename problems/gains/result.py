"""`GainDesign`: the result of every gain design in `problems.gains`."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping

import numpy as np

from appdyn.dynamics.serialize import jsonable, text_table, to_json
from appdyn.dynamics.results import Result

__all__ = ["GainDesign", "STATUS_UNSTABLE", "STATUS_LIMITS"]

#: status: the NLP converged but the designed loop is not stable (verification failed)
STATUS_UNSTABLE = "Closed_Loop_Unstable"
#: status: the limits (deflection, rate, torque) cannot be met by any gains of the form
STATUS_LIMITS = "Limits_Not_Met"


@dataclass(frozen=True, eq=False, repr=False)
class GainDesign(Result):
    """Feedback gains designed by multi-scenario collocation, and their verification.

    Attributes
    ----------
    success : bool
        The NLP was solved (`ocp.Solution.success`) *and* the verification passed (a stable
        closed loop; the limits met in every scenario).
    status : str
        IPOPT's / `ocp.solve`'s status, or `STATUS_UNSTABLE`, `STATUS_LIMITS`.
    message : str
        What happened; on failure, which constraint or check failed.
    gains : mapping of str to float
        The designed gains by name [their units in ``units``].
    units : mapping of str to str
    cost : float
        The summed objective over the scenarios.
    scenarios : list of dict
        Per scenario: ``'t'`` (n,) [s], ``'x'`` (nx, n), named outputs (e.g. ``'delta'``
        [rad]) and peak values (``'peak'``: mapping name -> float).
    verification : mapping
        What the design was checked against: closed-loop poles, damping ratios, margins
        (python-control), a reference (LQR gains, the time-optimal maneuver time), ...
    solution : ocp.Solution
        The multi-scenario solution (`ocp.scenarios`).
    """

    success: bool
    status: str
    message: str
    gains: Mapping[str, float]
    units: Mapping[str, str]
    cost: float
    scenarios: list
    verification: Mapping
    solution: object = field(repr=False, default=None)

    _repr_fields = ('gains', 'cost')

    def __str__(self) -> str:
        rows = [("success", f"{self.success} ({self.status})")]
        rows += [(f"{k} [{self.units.get(k, '-')}]", f"{v:.6g}") for k, v in self.gains.items()]
        rows.append(("cost", f"{self.cost:.6g}"))
        for i, sc in enumerate(self.scenarios):
            peaks = ", ".join(f"{k} {v:.4g}" for k, v in dict(sc.get("peak", {})).items())
            if peaks:
                rows.append((f"scenario {i} peaks", peaks))
        for k, v in self.verification.items():
            if isinstance(v, (int, float, np.floating, str, bool)):
                rows.append((k, f"{v:.6g}" if isinstance(v, (float, np.floating)) else str(v)))
        rows.append(("message", self.message))
        return text_table("Gain design", rows)

    def to_dict(self) -> dict:
        """Plain data (no Solution): success, status, message, gains, units, cost,
        scenarios' peaks and the verification."""
        return jsonable({"success": self.success, "status": self.status, "message": self.message,
                         "gains": dict(self.gains), "units": dict(self.units), "cost": self.cost,
                         "scenarios": [{"peak": dict(s.get("peak", {}))} for s in self.scenarios],
                         "verification": dict(self.verification)})

