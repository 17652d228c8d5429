"""The result of `problems.stability.sweep`: `SweepResult` and its `Boundary` entries."""
from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np

from appdyn.dynamics.figures import panel_axes

from .common import finish_figure, format_complex, jsonable, param_text
from .report import STATUS_MISMATCH, STATUS_UNCHECKED, status_message
from appdyn.dynamics.results import Result

__all__ = ["Boundary", "SweepResult"]


@dataclass(frozen=True)
class Boundary:
    """A change of verdict located by bisection.

    Attributes
    ----------
    value : float
        Midpoint of the final bracket.
    lower, upper : float
        The bracket, ``|upper - lower| <= rtol * |value|``.
    before, after : str
        Verdicts at ``lower`` and ``upper`` (in sweep order).
    """

    value: float
    lower: float
    upper: float
    before: str
    after: str


@dataclass(frozen=True, repr=False)
class SweepResult(Result):
    """Verdicts and least-damped eigenvalues of a case along one parameter.

    Attributes
    ----------
    case : str
        The case's name in `CASES`.
    parameter : str
        The swept keyword.
    values : ndarray, shape (n,)
        The grid.
    verdicts : tuple of str, length n
        The verdict at each grid value.
    least_damped : ndarray of complex, shape (n,) [1/s]
        The eigenvalue with the largest real part at each grid value.
    eigenvalues : ndarray of complex, shape (n, m)
        Sorted by (Re, Im); nan-padded.
    boundaries : tuple of Boundary
        The verdict changes, in sweep order.
    rtol : float
        Relative bracket width of the bisection.
    evaluations : int
        Case evaluations, bisection included.
    case_kwargs : dict
        The fixed arguments as plain Python values.
    statuses : tuple of int, length n
        The report status at each grid value (`STATUS_VERIFIED`, ...).
    complete : bool
        False for the partial result of an interrupted sweep (`sweep`, Ctrl-C): the grid
        values evaluated before the interrupt, and the boundaries located by then.
    wall_time : float [s]
        Time of the `sweep` call (NaN when built directly).
    success : bool
        False when some report disagreed with its closed forms (property).
    status : int
        The worst of ``statuses`` (property).
    message : str
        ``status`` in words (property).
    """

    case: str
    parameter: str
    values: np.ndarray
    verdicts: tuple
    least_damped: np.ndarray
    eigenvalues: np.ndarray
    boundaries: tuple
    rtol: float
    evaluations: int
    case_kwargs: dict
    statuses: tuple = ()
    complete: bool = True
    wall_time: float = field(default=float("nan"), compare=False)

    _repr_fields = ('case', 'parameter', 'values', 'boundaries')

    @property
    def status(self) -> int:
        """The worst report status along the grid (`STATUS_MISMATCH` > `STATUS_UNCHECKED` >
        `STATUS_VERIFIED`)."""
        return max(self.statuses, default=STATUS_UNCHECKED)

    @property
    def success(self) -> bool:
        """``False`` when a report along the grid disagreed with its closed forms."""
        return self.status != STATUS_MISMATCH

    @property
    def message(self) -> str:
        """``status`` in words."""
        text = status_message(self.status)
        if self.status == STATUS_MISMATCH:
            bad = [float(v) for v, s in zip(self.values, self.statuses) if s == STATUS_MISMATCH]
            text += f" at {self.parameter} = {bad}"
        if not self.complete:
            text += (f"; interrupted after {len(self.values)} grid values "
                     f"(boundaries located by then only)")
        return text

    def to_dict(self) -> dict:
        """JSON-ready summary (complex as ``[re, im]``)."""
        return jsonable({"case": self.case, "parameter": self.parameter,
                          "success": self.success, "status": self.status,
                          "message": self.message, "statuses": list(self.statuses),
                          "values": self.values, "verdicts": list(self.verdicts),
                          "least_damped": self.least_damped, "eigenvalues": self.eigenvalues,
                          "boundaries": [asdict(b) for b in self.boundaries],
                          "rtol": self.rtol, "evaluations": self.evaluations,
                          "case_kwargs": self.case_kwargs, "complete": self.complete})

    def __str__(self) -> str:
        lines = [f"Sweep of {self.case} over {self.parameter} ({len(self.values)} values, "
                 f"{self.evaluations} evaluations{'' if self.complete else ', interrupted'})"]
        if self.case_kwargs:
            lines.append("  fixed: " + param_text(self.case_kwargs))
        lines.append(f"  {self.parameter:>16}  {'verdict':<22} "
                     f"{'least-damped eigenvalue [1/s]':>33}")
        for v, verdict, z in zip(self.values, self.verdicts, self.least_damped):
            lines.append(f"  {v:>16.8g}  {verdict:<22} {format_complex(z):>33}")
        if self.boundaries:
            lines.append(f"boundaries (bisection to {self.rtol:.0e} relative):")
            for b in self.boundaries:
                lines.append(f"  {self.parameter} = {b.value:.12g}   {b.before} -> {b.after}")
        else:
            lines.append("no verdict change along the sweep")
        return "\n".join(lines)

    def plot(self, ax=None):
        """Real and imaginary parts of every eigenvalue versus the parameter.

        Parameters
        ----------
        ax : matplotlib.axes.Axes or matplotlib.figure.Figure, optional
            Draw the panels in this axes' slot (divided into the panels) or on this figure
            (cleared); by default on a new `matplotlib.figure.Figure` (no pyplot).

        Returns
        -------
        matplotlib.figure.Figure
        """
        fig, axes = panel_axes(ax, 2, 1, (8.0, 6.5))
        ax1, ax2 = axes[:, 0]
        ev = self.eigenvalues
        for j in range(ev.shape[1]):
            ax1.plot(self.values, ev[:, j].real, ".", ms=3, color="tab:blue")
            ax2.plot(self.values, ev[:, j].imag, ".", ms=3, color="tab:blue")
        ax1.plot(self.values, self.least_damped.real, "-", color="tab:red", lw=1,
                 label="least damped")
        for b in self.boundaries:
            for ax in (ax1, ax2):
                ax.axvline(b.value, color="k", ls="--", lw=0.8)
        ax1.axhline(0, color="0.5", lw=0.8)
        ax1.set_ylabel("Re [1/s]")
        ax2.set_ylabel("Im [rad/s]")
        ax2.set_xlabel(self.parameter)
        ax1.set_title(f"{self.case}: eigenvalues vs {self.parameter} (dashed: boundaries)",
                      fontsize=10)
        ax1.legend(fontsize=8)
        for ax in (ax1, ax2):
            ax.grid(True, alpha=0.3)
        return finish_figure(fig)
