"""`sweep`: run a case along one parameter and locate each verdict boundary by bisection."""
from __future__ import annotations

import inspect
import json
from dataclasses import asdict, dataclass

import numpy as np

from dynamics.interrupts import check_interrupt, interruptible

from .cases import resolve_case
from .common import finish_figure, format_complex, jsonable, param_text, plain
from .report import STATUS_MISMATCH, STATUS_UNCHECKED, status_message

__all__ = ["Boundary", "SweepResult", "sweep"]

_STABLE_UNSTABLE = {"asymptotically stable", "unstable"}
_BAND_RTOL = 1e-4  # a "marginally stable" stretch this narrow between the two is a zero band


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


@dataclass(frozen=True)
class SweepResult:
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

    def to_json(self) -> str:
        """`to_dict` as strict JSON text."""
        return json.dumps(self.to_dict(), indent=2, allow_nan=False)

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

    def plot(self, path=None, *, fig=None):
        """Real and imaginary parts of every eigenvalue versus the parameter.

        Parameters
        ----------
        path : str or path-like, optional
            Also save the figure there (format from the suffix; PNG without one).
        fig : matplotlib.figure.Figure, optional
            Draw two axes on this figure; by default on a new one (no pyplot).

        Returns
        -------
        matplotlib.figure.Figure
        """
        if fig is None:
            from matplotlib.figure import Figure

            fig = Figure(figsize=(8.0, 6.5))
        ax1, ax2 = fig.add_subplot(2, 1, 1), fig.add_subplot(2, 1, 2)
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
        ax1.set_title(f"{self.case}: eigenvalues vs {self.parameter} (dashed: boundaries)")
        ax1.legend(fontsize=8)
        for ax in (ax1, ax2):
            ax.grid(True, alpha=0.3)
        return finish_figure(fig, path)


@interruptible
def sweep(case, parameter: str, values, *, rtol: float = 1e-8, progress=None,
          **case_kwargs) -> SweepResult:
    """Run ``case`` for each value of ``parameter`` and locate the verdict boundaries.

    Between consecutive values with different verdicts the boundary is bisected until the
    bracket is within ``rtol`` of its magnitude (1e-8 by default). Between "asymptotically
    stable" and "unstable" the sign of the largest real part is bisected instead of the
    verdict: it crosses zero continuously, while the verdict's zero band around the crossing
    (``|Re| <= ZERO_RTOL rho``, about ``ZERO_RTOL rho / |d Re / d parameter|`` wide) would
    give two boundaries. The same holds when a grid value falls inside that band: a
    "marginally stable" stretch narrower than 1e-4 relative between "unstable" and
    "asymptotically stable" is reported as one boundary at the crossing.

    Parameters
    ----------
    case : str or callable
        A name in `CASES` or `CASE_ALIASES` (``'heavy-top'``, ``'projectile'``), or the case
        function.
    parameter : str
        The keyword swept, e.g. ``'rate'`` or ``'wheel_momentum'``.
    values : array_like, shape (n,)
        Strictly increasing, finite, ``n >= 1``.
    rtol : float, optional
        Relative bracket width of the bisection.
    progress : callable, optional
        ``progress(done, total)`` after each grid value (``total = len(values)``; the
        bisections that follow are not counted).
    **case_kwargs
        The case's other arguments (by keyword).

    Returns
    -------
    SweepResult

    Raises
    ------
    ValueError
        Naming ``case``, ``parameter``, ``values`` or ``rtol``; a ValueError of the case at
        one value is re-raised with that value.
    KeyboardInterrupt
        On Ctrl-C (within one case evaluation, `dynamics.interrupts`). When some grid values
        were finished, the exception's ``partial`` attribute is their `SweepResult`
        (``complete=False``, with the boundaries located before the interrupt)::

            try:
                res = stability.sweep(...)
            except KeyboardInterrupt as exc:
                res = getattr(exc, "partial", None)

    Examples
    --------
    The sleeping top (RP-1262, Sec. 4.6, Eq. 4.128: ``w0 = (2 / I1) sqrt(m g l I2)``):

    >>> import numpy as np
    >>> from problems import stability
    >>> res = stability.sweep("heavy_top", "rate", np.linspace(0, 60, 7), axial_inertia=0.002,
    ...                       transverse_inertia=0.005, mass=0.3, length=0.04)
    >>> res.verdicts[0], res.verdicts[-1]
    ('unstable', 'marginally stable')
    >>> b = res.boundaries[0]
    >>> print(f"{b.value:.6f}: {b.before} -> {b.after}")
    24.256937: unstable -> marginally stable
    """
    name, fun = resolve_case(case)
    sig = inspect.signature(fun)
    if parameter not in sig.parameters:
        raise ValueError(f"`parameter` must be an argument of {name}: {list(sig.parameters)}, "
                         f"got {parameter!r}")
    if parameter in case_kwargs:
        raise ValueError(f"`{parameter}` is swept; do not pass it in case_kwargs")
    try:
        vals = np.array(values, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise ValueError(f"`values` must be numbers, got {values!r}") from None
    if vals.size < 1 or not np.all(np.isfinite(vals)) or np.any(np.diff(vals) <= 0):
        raise ValueError(f"`values` must be finite and strictly increasing, got {vals.tolist()}")
    if not (np.isfinite(rtol) and 1e-15 <= rtol < 1):
        raise ValueError(f"`rtol` must be in [1e-15, 1), got {rtol}")
    try:
        sig.bind(**{parameter: vals[0]}, **case_kwargs)
    except TypeError as exc:
        raise ValueError(f"`case_kwargs` do not fit {name}{sig}: {exc}") from None

    count = [0]

    def run(v):
        check_interrupt()
        count[0] += 1
        try:
            return fun(**{parameter: float(v)}, **case_kwargs)
        except ValueError as exc:
            raise ValueError(f"{name} at {parameter} = {float(v)!r}: {exc}") from None

    def narrow(lo, hi):
        return abs(hi - lo) > rtol * max(abs(lo), abs(hi)) and lo < 0.5 * (lo + hi) < hi

    def crossing(lo, hi, unstable_at_lo):
        """Bisect the sign of the largest real part (continuous through the crossing)."""
        while narrow(lo, hi):
            mid = 0.5 * (lo + hi)
            if (run(mid).least_damped().real > 0) == unstable_at_lo:
                lo = mid
            else:
                hi = mid
        return lo, hi

    def locate(a, va, b, vb):
        if {va, vb} == _STABLE_UNSTABLE:
            lo, hi = crossing(a, b, va == "unstable")
            return [Boundary(0.5 * (lo + hi), lo, hi, va, vb)]
        lo, hi, vhi = a, b, vb
        while narrow(lo, hi):
            mid = 0.5 * (lo + hi)
            vm = run(mid).verdict
            if vm == va:
                lo = mid
            else:
                hi, vhi = mid, vm
        here = [Boundary(0.5 * (lo + hi), lo, hi, va, vhi)]
        if vhi != vb:
            here += locate(hi, vhi, b, vb)
        return here

    reports, found = [], []

    def result(boundaries, complete=True):
        return _result(name, parameter, vals[:len(reports)], reports, boundaries, rtol, count[0],
                       case_kwargs, complete)

    try:
        for v in vals:
            reports.append(run(v))
            if progress is not None:
                progress(len(reports), len(vals))
        verdicts = tuple(r.verdict for r in reports)
        for i in range(len(vals) - 1):
            if verdicts[i] != verdicts[i + 1]:
                found += locate(vals[i], verdicts[i], vals[i + 1], verdicts[i + 1])
        return result(_merged(found, rtol, crossing))
    except KeyboardInterrupt as exc:
        if reports:  # what was finished rides on the interrupt
            exc.partial = result(tuple(found), complete=False)
        raise



def _merged(found, rtol, crossing) -> tuple:
    """Boundaries in sweep order, a verdict's zero band around a crossing (or brackets
    closer than ``rtol``) merged into one boundary."""
    boundaries = []
    for bnd in found:
        prev = boundaries[-1] if boundaries else None
        if prev is not None and prev.after == bnd.before:
            gap = abs(bnd.upper - prev.lower)
            scale = max(abs(prev.value), abs(bnd.value))
            if {prev.before, bnd.after} == _STABLE_UNSTABLE and gap <= _BAND_RTOL * scale:
                # a zero band of the verdict around a crossing: one boundary, at the crossing
                lo, hi = crossing(prev.lower, bnd.upper, prev.before == "unstable")
                boundaries[-1] = Boundary(0.5 * (lo + hi), lo, hi, prev.before, bnd.after)
                continue
            if gap <= rtol * scale and prev.before != bnd.after:
                boundaries[-1] = Boundary(0.5 * (prev.lower + bnd.upper), prev.lower, bnd.upper,
                                          prev.before, bnd.after)
                continue
        boundaries.append(bnd)
    return tuple(boundaries)


def _result(name, parameter, vals, reports, boundaries, rtol, evaluations, case_kwargs,
            complete) -> SweepResult:
    """The `SweepResult` of ``reports`` at the grid values ``vals``."""
    m = max(len(r.eigenvalues) for r in reports)
    ev = np.full((len(vals), m), np.nan + 1j * np.nan, dtype=complex)
    for i, r in enumerate(reports):
        ev[i, :len(r.eigenvalues)] = r.eigenvalues
    return SweepResult(case=name, parameter=parameter, values=np.array(vals),
                       verdicts=tuple(r.verdict for r in reports),
                       least_damped=np.array([r.least_damped() for r in reports], dtype=complex),
                       eigenvalues=ev, boundaries=tuple(boundaries), rtol=float(rtol),
                       evaluations=evaluations, case_kwargs=plain(case_kwargs),
                       statuses=tuple(r.status for r in reports), complete=complete)
