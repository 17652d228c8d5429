"""`GainDesign`: the result of every gain design in `problems.gains`."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping

import numpy as np

from appdyn.dynamics.serialize import jsonable, text_table, to_json
from appdyn.dynamics.results import Result
from appdyn.ocp import status as _status
from appdyn.ocp.status import describe

__all__ = ["GainDesign", "STATUS_UNSTABLE", "STATUS_LIMITS"]

#: status 108 (`ocp.status`): the NLP converged but the designed loop is not stable
STATUS_UNSTABLE = _status.STATUS_UNSTABLE
#: status 109: the limits (deflection, rate, torque) cannot be met by any gains of the form
STATUS_LIMITS = _status.STATUS_LIMITS


# signal -> (axis label, scale to the shown unit, shown unit, verification key of its limit)
_SIGNALS = {"psi": ("attitude psi", 180 / np.pi, "deg", None),
            "delta": ("deflection delta", 180 / np.pi, "deg", "delta_max"),
            "delta_rate": ("deflection rate", 180 / np.pi, "deg/s", "delta_rate_max"),
            "alpha": ("angle of attack", 180 / np.pi, "deg", None),
            "angle": ("attitude error", 180 / np.pi, "deg", None),
            "x": ("states", 1.0, "state units", None),
            "u": ("controls", 1.0, "control units", None)}


@dataclass(frozen=True, eq=False, repr=False)
class GainDesign(Result):
    """Feedback gains designed by multi-scenario collocation, and their verification.

    Attributes
    ----------
    success : bool
        The NLP was solved (`ocp.Solution.success`) *and* the verification passed (a stable
        closed loop; the limits met in every scenario).
    status : int
        0 for a success; else `ocp.solve`'s status (`ocp.status.CODES`), `STATUS_UNSTABLE`
        (108), `STATUS_LIMITS` (109) or 110 ``Simulation_Failed``; a success with a warning
        carries 120 ``Short_Horizon`` or 121 ``Initial_States_Not_Spanning``
        (`state_feedback_gains`).
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
    solver_status : str
        IPOPT's return status text of ``solution`` (property; ``''`` without one).
    """

    success: bool
    status: int
    message: str
    gains: Mapping[str, float]
    units: Mapping[str, str]
    cost: float
    scenarios: list
    verification: Mapping
    solution: object = field(repr=False, default=None)

    _repr_fields = ('gains', 'cost')

    @property
    def solver_status(self) -> str:
        """IPOPT's return status text of the design's NLP (``''`` without a solution)."""
        return str(getattr(self.solution, "solver_status", ""))

    @property
    def wall_time(self) -> float:
        """Time of the design [s]: ``verification['design_time']`` (or the NLP's
        ``'solve_time'``); NaN when neither was recorded."""
        v = self.verification
        return float(v.get("design_time", v.get("solve_time", float("nan"))))

    def plot(self, ax=None):
        """Every re-simulated scenario against time, one panel per signal, limits dashed.

        Angles are drawn in degrees (``psi``, ``delta``, ``alpha``, the error ``angle``),
        rates in deg/s (``delta_rate``); state and control histories (``x``, ``u``) one
        curve per component.

        Parameters
        ----------
        ax : matplotlib.axes.Axes or matplotlib.figure.Figure, optional
            Draw the panels in this axes' slot (divided into the panels) or on this figure
            (cleared); by default on a new `matplotlib.figure.Figure` (no pyplot).

        Returns
        -------
        matplotlib.figure.Figure
            With no scenario (a failed design), one empty panel saying so.
        """
        from appdyn.dynamics.figures import finish_figure, panel_axes

        keys = [k for k in _SIGNALS if any(k in sc for sc in self.scenarios)]
        fig, axes = panel_axes(ax, max(len(keys), 1), 1, (8.0, 1.2 + 2.2 * max(len(keys), 1)))
        axes = axes[:, 0]
        for key, a in zip(keys, axes):
            label, scale, unit, limit = _SIGNALS[key]
            for i, sc in enumerate(self.scenarios):
                if key not in sc:
                    continue
                y = np.atleast_2d(np.asarray(sc[key], dtype=float)) * scale
                name = sc.get("name") or f"scenario {i}"
                for j, row in enumerate(y):
                    a.plot(sc["t"], row, color=f"C{(i if len(y) == 1 else j) % 10}",
                           lw=1.0, label=(name if len(y) == 1 else f"{key}{j + 1}")
                           if i == 0 or len(y) == 1 else None)
            bound = self.verification.get(limit) if limit else None
            if bound is not None and np.isfinite(bound):
                for b in (bound, -bound):
                    a.axhline(b * scale, ls="--", color="k", lw=0.8)
            a.set_ylabel(f"{label} [{unit}]")
            a.grid(True, alpha=0.3)
            a.legend(fontsize=7, ncol=3)
        if not keys:
            axes[0].text(0.5, 0.5, f"no scenario to draw: {self.message}", ha="center",
                         va="center", transform=axes[0].transAxes, wrap=True, fontsize=8)
        axes[-1].set_xlabel("t [s]")
        gains = ", ".join(f"{k} = {v:.4g} {self.units.get(k, '').strip('-')}".rstrip()
                          for k, v in self.gains.items())
        fig.suptitle(f"Gain design ({'verified' if self.success else 'not verified'}): "
                     f"{gains}", fontsize=9)
        return finish_figure(fig)

    def __str__(self) -> str:
        rows = [("success", f"{self.success} ({describe(self.status, solver_status=self.solver_status)})")]
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
        return jsonable({"success": self.success, "status": int(self.status),
                         "solver_status": self.solver_status, "message": self.message,
                         "gains": dict(self.gains), "units": dict(self.units), "cost": self.cost,
                         "scenarios": [{"peak": dict(s.get("peak", {}))} for s in self.scenarios],
                         "verification": dict(self.verification)})

