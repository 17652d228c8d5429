"""Stability reports: the mode table, margins, the closed-form check, text, JSON, pole maps.

`build_report` turns a ``control.StateSpace`` into a `StabilityReport` (the verdict comes
from `problems.stability.verdict`); `analyze` does it for any linear model.

Status of a report (``report.status``), the check of the eigenvalues against the case's
closed forms (Rheinfurth & Wilson, NASA RP-1262, Secs. 4.5-4.6):

* `STATUS_VERIFIED` (0): closed forms known, every eigenvalue matched within
  ``CLOSED_FORM_RTOL`` of the spectral radius;
* `STATUS_UNCHECKED` (1): no closed form for this case and parameters;
* `STATUS_MISMATCH` (2): a closed-form eigenvalue is further off (``success`` is False).
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Mapping, Sequence

import numpy as np

from appdyn.dynamics.linearize import Linearization

from .common import (axes_or_new_figure, finish_figure, format_number, jsonable, param_line,
                     plain)
from .verdict import ZERO_RTOL, classify, least_damped
from appdyn.dynamics.results import Result, clean_number, quantity, timed

__all__ = ["Mode", "Margins", "Quantity", "StabilityReport", "build_report", "analyze",
           "STATUS_VERIFIED", "STATUS_UNCHECKED", "STATUS_MISMATCH", "CLOSED_FORM_RTOL",
           "closed_form_status", "status_message"]

#: status: the eigenvalues agree with the closed forms
STATUS_VERIFIED = 0
#: status: no closed form to check against
STATUS_UNCHECKED = 1
#: status: the eigenvalues disagree with the closed forms (``success`` is False)
STATUS_MISMATCH = 2
#: largest ``|lambda - closed form| / rho`` of a verified report
CLOSED_FORM_RTOL = 1e-6


def closed_form_status(error) -> int:
    """Status of a closed-form error ``max |lambda - closed form| / rho`` (None: no check)."""
    if error is None:
        return STATUS_UNCHECKED
    return STATUS_VERIFIED if error <= CLOSED_FORM_RTOL else STATUS_MISMATCH


def status_message(status: int, error=None) -> str:
    """One line saying what ``status`` means (with the error, when there is one)."""
    if status == STATUS_UNCHECKED:
        return "no closed form to check the eigenvalues against"
    text = "" if error is None else f" (max |lambda - closed form| / rho = {error:.1e})"
    if status == STATUS_VERIFIED:
        return f"eigenvalues agree with the closed forms{text}"
    return f"eigenvalues DISAGREE with the closed forms beyond {CLOSED_FORM_RTOL:g}{text}"


@dataclass(frozen=True)
class Mode:
    """One real eigenvalue or one complex-conjugate pair (shown with ``Im > 0``).

    Attributes
    ----------
    eigenvalue : complex [1/s]
    wn : float [rad/s]
        Natural frequency ``|lambda|``.
    zeta : float
        Damping ratio ``-Re(lambda)/|lambda|`` (nan for ``lambda = 0``).
    label : str
        What moves (from the case's closed forms or the participation factors).
    pair : bool
        ``True`` for a complex-conjugate pair.
    closed_form : complex or None
        The matching closed-form eigenvalue.
    error : float or None
        ``|lambda - closed_form| / rho``.
    """

    eigenvalue: complex
    wn: float
    zeta: float
    label: str = ""
    pair: bool = False
    closed_form: complex | None = None
    error: float | None = None


@dataclass(frozen=True)
class Margins:
    """Classical loop margins of a single-loop system (``control.stability_margins``).

    Attributes
    ----------
    gain_margin : float
        Factor (``inf``: no phase crossover).
    gain_margin_db : float [dB]
    phase_margin : float [deg] (``inf``: no gain crossover)
    stability_margin : float
        Minimum distance of the Nyquist curve to -1 (``inf`` when python-control finds
        no finite minimum).
    phase_crossover : float [rad/s] (nan if none)
    gain_crossover : float [rad/s] (nan if none)
    stability_margin_frequency : float [rad/s] (nan where ``stability_margin`` is ``inf``)
    """

    gain_margin: float
    gain_margin_db: float
    phase_margin: float
    stability_margin: float
    phase_crossover: float
    gain_crossover: float
    stability_margin_frequency: float


@dataclass(frozen=True)
class Quantity:
    """A derived number: its value from the linear model and its closed form, if known.

    Attributes
    ----------
    name : str
    value : float or None
        From the computed model (``None`` when only a formula exists).
    closed_form : float or None
    unit : str
    equation : str
        Where the closed form comes from (equation of Rheinfurth & Wilson,
        NASA RP-1262, unless another source is named)
    """

    name: str
    value: float | None
    closed_form: float | None = None
    unit: str = ""
    equation: str = ""


@dataclass(frozen=True, repr=False)
class StabilityReport(Result):
    """Linear stability of one case.

    Attributes
    ----------
    case : str
        The case function's name.
    title : str
    parameters : dict
        The case's inputs as plain Python values (``to_dict`` makes them JSON).
    ss : control.StateSpace
        The analysed linear model (named states, inputs, outputs).
    eigenvalues : ndarray of complex, shape (n,) [1/s]
        Of ``ss.A``, sorted by (Re, Im).
    verdict : {'unstable', 'marginally stable', 'asymptotically stable'}
    reason : str
        Why (the deciding eigenvalue and the tolerance).
    tolerance : float [1/s]
        ``ZERO_RTOL * rho``.
    modes : tuple of Mode
    margins : Margins or None
        For `loop`.
    quantities : tuple of Quantity
    closed_form : ndarray of complex or None
        Closed-form eigenvalues, if known.
    closed_form_error : float or None
        ``max |lambda - closed form| / rho`` after matching.
    notes : tuple of str
    linearization : Linearization or None
        The full linearization before reduction.
    wall_time : float [s]
        Time of the call that made the report (NaN when built directly).
    success : bool
        ``status != STATUS_MISMATCH`` (property).
    status : int
        `STATUS_VERIFIED` (0), `STATUS_UNCHECKED` (1) or `STATUS_MISMATCH` (2)
        (property)
    message : str
        The status in words (property).

    Examples
    --------
    >>> from appdyn.problems import stability
    >>> rep = stability.spin([2.0, 3.0, 4.5], axis=[1, 0, 0], rate=10.0)
    >>> rep.verdict, rep.success, rep.status
    ('marginally stable', True, 0)
    >>> [round(m.wn, 4) for m in rep.modes]
    [4.3033]
    >>> sorted(rep.to_dict())[:4]
    ['A', 'case', 'closed_form', 'closed_form_error']
    """

    case: str
    title: str
    parameters: dict
    ss: object
    eigenvalues: np.ndarray
    verdict: str
    reason: str
    tolerance: float
    modes: tuple = ()
    margins: Margins | None = None
    quantities: tuple = ()
    closed_form: np.ndarray | None = None
    closed_form_error: float | None = None
    notes: tuple = ()
    linearization: Linearization | None = field(default=None, repr=False, compare=False)
    wall_time: float = field(default=math.nan, compare=False)

    _repr_fields = ('case', 'verdict', 'eigenvalues')

    def __getstate__(self) -> dict:
        """Pickled state: the fields, ``ss`` as its matrices and names (python-control's
        `StateSpace` holds a local lambda and does not pickle); rebuilt on load."""
        state = dict(self.__dict__)
        state["ss"] = _ss_data(self.ss)
        return state

    def __setstate__(self, state: dict) -> None:
        state = dict(state)
        state["ss"] = _ss_from_data(state["ss"])
        for key, value in state.items():
            object.__setattr__(self, key, value)

    @property
    def status(self) -> int:
        """`STATUS_VERIFIED`, `STATUS_UNCHECKED` or `STATUS_MISMATCH` (closed-form check)."""
        return closed_form_status(self.closed_form_error)

    @property
    def success(self) -> bool:
        """``False`` only when the eigenvalues disagree with the case's closed forms."""
        return self.status != STATUS_MISMATCH

    @property
    def message(self) -> str:
        """The closed-form check in words."""
        return status_message(self.status, self.closed_form_error)

    @property
    def spectral_scale(self) -> float:
        """``rho`` of the verdict rule [1/s]."""
        return self.tolerance / ZERO_RTOL

    def least_damped(self) -> complex:
        """The eigenvalue with the largest real part (``Im >= 0`` of a pair) [1/s]."""
        return least_damped(self.eigenvalues)

    def quantity(self, name_start: str) -> Quantity:
        """The first quantity whose name starts with ``name_start`` (``KeyError`` if none)."""
        for q in self.quantities:
            if q.name.startswith(name_start):
                return q
        raise KeyError(f"no quantity named {name_start!r}...; "
                       f"have {[q.name for q in self.quantities]}")

    def to_dict(self) -> dict:
        """JSON-ready summary: complex numbers as ``[re, im]``, non-finite numbers as ``None``."""
        return jsonable({
            "case": self.case,
            "title": self.title,
            "success": self.success,
            "status": self.status,
            "message": self.message,
            "parameters": self.parameters,
            "verdict": self.verdict,
            "reason": self.reason,
            "tolerance": self.tolerance,
            "states": list(self.ss.state_labels),
            "inputs": list(self.ss.input_labels),
            "A": np.asarray(self.ss.A),
            "eigenvalues": self.eigenvalues,
            "modes": [asdict(m) for m in self.modes],
            "margins": asdict(self.margins) if self.margins else None,
            "quantities": [asdict(q) for q in self.quantities],
            "closed_form": self.closed_form,
            "closed_form_error": self.closed_form_error,
            "notes": list(self.notes),
        })

    def __str__(self) -> str:
        lines = [self.title]
        width = max([len(k) for k in self.parameters] + [5])
        for k, v in self.parameters.items():
            lines.append(f"  {k:<{width}}  {param_line(k, v)}")
        lines.append("  states  " + ", ".join(self.ss.state_labels))
        lines.append(f"verdict: {self.verdict.upper()} — {self.reason}")
        lines.append(f"modes (|Re| <= {self.tolerance:.2e} 1/s counts as zero):")
        head = (f"  {'eigenvalue [1/s]':<31} {'wn [rad/s]':>11} {'zeta':>8}  {'label':<28}"
                f"{'closed form':<31} {'|err|/rho':>9}")
        lines.append(head)
        for m in self.modes:
            ev = _fmt_mode(m.eigenvalue, m.pair)
            cf = "-" if m.closed_form is None else _fmt_mode(m.closed_form, m.pair)
            err = "-" if m.error is None else f"{m.error:.1e}"
            zeta = "nan" if math.isnan(m.zeta) else quantity(m.zeta, "", 3)
            lines.append(f"  {ev:<31} {m.wn:>11.5e} {zeta:>8}  {m.label:<28}{cf:<31} {err:>9}")
        if self.quantities:
            w = max(len(q.name) for q in self.quantities)
            lines.append(f"{'quantities:':<{w + 2}}  {'linear model':>17}  {'closed form':>17}  "
                         f"{'unit':<9} source")
            for q in self.quantities:
                lines.append(f"  {q.name:<{w}}  {format_number(q.value, spec='.10g'):>17}  "
                             f"{format_number(q.closed_form, spec='.10g'):>17}  {q.unit:<9} "
                             f"{q.equation}")
        if self.margins is not None:
            mg = self.margins
            lines.append("margins:")
            lines.append("  gain margin   " + (
                "inf (no phase crossover: the loop gain may grow without bound)"
                if not math.isfinite(mg.phase_crossover) else
                f"{format_number(mg.gain_margin)} ({format_number(mg.gain_margin_db, spec='.4g')} "
                f"dB) at {format_number(mg.phase_crossover)} rad/s"))
            lines.append("  phase margin  " + (
                "inf (no gain crossover)" if not math.isfinite(mg.gain_crossover) else
                f"{format_number(mg.phase_margin, spec='.6g')} deg at "
                f"{format_number(mg.gain_crossover)} rad/s"))
            where = (f" at {format_number(mg.stability_margin_frequency)} rad/s"
                     if math.isfinite(mg.stability_margin_frequency) else "")
            lines.append(f"  stability margin {format_number(mg.stability_margin, spec='.6g')} "
                         f"(least |1 + L|, unitless){where}")
        if self.closed_form_error is not None:
            lines.append(f"closed-form check: max |lambda - closed form| / rho = "
                         f"{self.closed_form_error:.2e}")
        for n in self.notes:
            lines.append(f"note: {n}")
        return "\n".join(lines)

    def plot(self, ax=None):
        """Pole map: eigenvalues, closed forms and mode labels.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Draw on these axes; by default on a new `matplotlib.figure.Figure` (no pyplot,
            the backend is left alone).

        Returns
        -------
        matplotlib.figure.Figure
        """
        fig, ax = axes_or_new_figure(ax, (7.0, 5.5))
        ev = self.eigenvalues
        ax.axhline(0, color="0.6", lw=0.8)
        ax.axvline(0, color="0.6", lw=0.8)
        ax.plot(ev.real, ev.imag, "x", ms=10, mew=2, color="tab:blue", label="eigenvalues")
        if self.closed_form is not None and len(self.closed_form):
            cf = np.asarray(self.closed_form)
            ax.plot(cf.real, cf.imag, "o", ms=14, mfc="none", color="tab:orange",
                    label="closed form")
        for m in self.modes:
            if m.label:
                ax.annotate(m.label, (m.eigenvalue.real, m.eigenvalue.imag),
                            textcoords="offset points", xytext=(8, 6), fontsize=8)
        span = max(np.max(np.abs(ev.real), initial=0.0), np.max(np.abs(ev.imag), initial=0.0),
                   1e-12)
        ax.set_xlim(-1.15 * span, 1.15 * span)
        ax.set_ylim(-1.15 * span, 1.15 * span)
        ax.set_xlabel("Re [1/s]")
        ax.set_ylabel("Im [rad/s]")
        ax.set_title(f"{self.title}\n{self.verdict}", fontsize=10)
        ax.grid(True, alpha=0.3)
        ax.legend(loc="lower left", fontsize=8)
        return finish_figure(fig)


def _ss_data(ss) -> dict:
    """A python-control ``StateSpace`` as plain data (see `_ss_from_data`)."""
    if not hasattr(ss, "A"):  # not a StateSpace: pickled as it is
        return {"object": ss}
    return {"A": np.array(ss.A), "B": np.array(ss.B), "C": np.array(ss.C),
            "D": np.array(ss.D), "dt": ss.dt, "states": list(ss.state_labels),
            "inputs": list(ss.input_labels), "outputs": list(ss.output_labels),
            "name": ss.name}


def _ss_from_data(data: dict):
    """The ``StateSpace`` of `_ss_data` again."""
    if "object" in data:
        return data["object"]
    import control

    return control.ss(data["A"], data["B"], data["C"], data["D"], data["dt"],
                      states=data["states"], inputs=data["inputs"],
                      outputs=data["outputs"], name=data["name"])


def _fmt_mode(z: complex, pair: bool) -> str:
    re = clean_number(z.real, abs(z))  # round-off (|Re| <= 1e-12 |lambda|) shown as 0
    return f"{re:+.6e} ± {abs(z.imag):.6e}j" if pair else f"{re:+.6e}"


# --------------------------------------------------------------- mode bookkeeping
def _participation(A: np.ndarray):
    """Eigenvalues, right eigenvectors and participation factors ``|V_ki W_ik|`` (columns)."""
    ev, V = np.linalg.eig(A)
    try:
        W = np.linalg.inv(V)
        P = np.abs(V * W.T)
        if not np.all(np.isfinite(P)) or np.linalg.cond(V) > 1e10:
            raise np.linalg.LinAlgError
    except np.linalg.LinAlgError:  # defective: fall back to eigenvector magnitudes
        P = np.abs(V) ** 2
    P = P / np.maximum(P.sum(axis=0, keepdims=True), 1e-300)
    return ev, V, P


def _match(ev: np.ndarray, cf: np.ndarray):
    """Pair each closed-form value with a distinct computed eigenvalue (min total distance)."""
    from scipy.optimize import linear_sum_assignment

    cost = np.abs(ev[:, None] - cf[None, :])
    rows, cols = linear_sum_assignment(cost)
    return dict(zip(rows.tolist(), cols.tolist()))


def _modes(A, rho, *, groups=None, labeler=None, closed_form=None):
    """The mode table (one entry per real eigenvalue or conjugate pair) and the largest
    closed-form error ``|lambda - closed form| / rho`` (None without closed forms)."""
    n = A.shape[0]
    if n == 0:
        return (), None
    ev, V, P = _participation(A)
    names_groups = groups or {}
    match = _match(ev, closed_form) if closed_form is not None and len(closed_form) else {}
    errs = {i: abs(ev[i] - closed_form[j]) / rho for i, j in match.items()}
    im_tol = 1e-12 * rho
    modes = []
    for i in np.argsort([(-z.imag if z.imag > im_tol else 0.0) for z in ev], kind="stable"):
        z = ev[i]
        if z.imag < -im_tol:
            continue  # the Im > 0 member represents the pair
        pair = bool(z.imag > im_tol)
        label = ""
        if labeler is not None:
            label = labeler(z, V[:, i]) or ""
        if not label and names_groups:
            share = {g: float(P[idx, i].sum()) for g, idx in names_groups.items()}
            label = max(share, key=share.get)
        wn = abs(z)
        zeta = -z.real / wn + 0.0 if wn > 0 else float("nan")
        cf = complex(closed_form[match[i]]) if i in match else None
        if pair and cf is not None and cf.imag < 0:
            cf = cf.conjugate()
        err = errs.get(i)
        if pair:  # the error of the pair: the worse of both members
            for k, zk in enumerate(ev):
                if k != i and abs(zk - z.conjugate()) <= 1e-9 * rho and k in errs:
                    err = max(err or 0.0, errs[k])
        modes.append(Mode(eigenvalue=complex(z.real, abs(z.imag) if pair else 0.0),
                          wn=float(wn), zeta=float(zeta), label=label, pair=pair,
                          closed_form=cf, error=err))
    modes.sort(key=lambda m: (m.wn, m.eigenvalue.real))
    worst = max(errs.values()) if errs else None
    return tuple(modes), worst


def build_report(case, title, parameters, ss, *, lin=None, groups=None, labeler=None,
                 closed_form=None, quantities=(), notes=(), margins=None) -> StabilityReport:
    """Assemble a `StabilityReport` for the linear model ``ss`` (used by every case).

    Parameters
    ----------
    case, title : str
    parameters : dict
        The inputs, shown and serialized.
    ss : control.StateSpace
        The model judged.
    lin : Linearization, optional
        Kept for reference.
    groups : mapping of label -> state names, optional
        Participation labels.
    labeler : callable ``(eigenvalue, eigenvector) -> str``, optional
        Takes precedence.
    closed_form : array_like of complex, optional
        Matched to the eigenvalues.
    quantities : sequence of Quantity
    notes : sequence of str
    margins : Margins, optional
    """
    A = np.asarray(ss.A, dtype=float)
    verdict, reason, tol, ev = classify(A)
    rho = tol / ZERO_RTOL
    cf = None if closed_form is None else np.asarray(closed_form, dtype=complex)
    groups_idx = None
    if groups:
        labels = list(ss.state_labels)
        groups_idx = {g: [labels.index(s) for s in names if s in labels]
                      for g, names in groups.items()}
        groups_idx = {g: idx for g, idx in groups_idx.items() if idx}
    modes, worst = _modes(A, rho, groups=groups_idx, labeler=labeler, closed_form=cf)
    return StabilityReport(case=case, title=title, parameters=plain(parameters), ss=ss,
                           eigenvalues=ev, verdict=verdict, reason=reason, tolerance=tol,
                           modes=modes, margins=margins, quantities=tuple(quantities),
                           closed_form=cf, closed_form_error=worst,
                           notes=tuple(notes), linearization=lin)


@timed
def analyze(sys, *, title: str = "Linear system",
            groups: Mapping[str, Sequence[str]] | None = None,
            closed_form=None) -> StabilityReport:
    """Stability report of any linear model.

    Parameters
    ----------
    sys : control.StateSpace, control.TransferFunction or Linearization
    title : str
    groups : mapping of label -> state names, optional
        Each mode is labelled with the group of largest participation.
    closed_form : array_like of complex, optional
        Expected eigenvalues, matched and checked.

    Returns
    -------
    StabilityReport

    Raises
    ------
    ValueError
        Naming ``sys`` when it is not a linear model.

    Examples
    --------
    A torque-free spin about the minor axis, linearized by `dynamics.linearize`:

    >>> from appdyn.dynamics import linearize, rigid_body
    >>> from appdyn.problems import stability
    >>> sys = linearize(rigid_body([2.0, 3.0, 4.5]), [0, 0, 0, 1, 10.0, 0, 0])
    >>> rep = stability.analyze(sys, groups={"attitude": ["dth1", "dth2", "dth3"],
    ...                                      "rates": ["w1", "w2", "w3"]})
    >>> rep.verdict, rep.status  # the full state: the spin phase drifts (a Jordan block at 0)
    ('unstable', 1)
    """
    import control

    lin = None
    if isinstance(sys, Linearization):
        lin, sys = sys, sys.ss
    elif isinstance(sys, control.TransferFunction):
        sys = control.ss(sys)
    if not isinstance(sys, control.StateSpace):
        raise ValueError(f"`sys` must be a control.StateSpace, TransferFunction or "
                         f"Linearization, got {type(sys).__name__}")
    return build_report("analyze", title, {"system": sys.name}, sys, lin=lin, groups=groups,
                        closed_form=closed_form, notes=lin.notes if lin else ())
