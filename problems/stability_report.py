"""Stability reports: the verdict rule, the mode table, margins, text, JSON and pole maps.

Used by `problems.stability` (the cases) and usable on any linear model through `analyze`.

Verdict
-------
With ``rho`` the spectral radius (``|A|_2`` if every eigenvalue is 0; 1 if ``A = 0``), an
eigenvalue counts as on the imaginary axis when ``|Re| <= ZERO_RTOL * rho`` (1e-9: well above
the ~1e-16 rho round-off of LAPACK for the conservative cases, well below any physical
damping considered here). Then:

* ``"unstable"``: some ``Re > ZERO_RTOL rho``, or an eigenvalue on the axis is defective
  (a Jordan block: perturbations grow like ``t^k``);
* ``"asymptotically stable"``: every ``Re < -ZERO_RTOL rho``;
* ``"marginally stable"``: otherwise (axis eigenvalues all semisimple).

Eigenvalues on the axis within ``1e-6 rho`` of each other are grouped; a group of ``m`` is
semisimple when ``A - lambda I`` has ``m`` singular values below ``1e-5 rho`` (a Jordan
coupling weaker than that is not resolved).
"""
from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field
from typing import Mapping, Sequence

import numpy as np

from dynamics.linearize import Linearization

__all__ = ["ZERO_RTOL", "VERDICTS", "Mode", "Margins", "Quantity", "StabilityReport",
           "classify", "analyze", "build_report", "plain", "jsonable", "format_complex",
           "param_text", "least_damped"]

ZERO_RTOL = 1e-9
VERDICTS = ("unstable", "marginally stable", "asymptotically stable")
_CLUSTER_RTOL = 1e-6
_RANK_RTOL = 1e-5


# ------------------------------------------------------------------------- helpers
def plain(v, *, strict=False):
    """Plain-Python copy: arrays -> lists, complex -> [re, im], dataclasses -> dicts; with
    ``strict`` also non-finite floats -> None (JSON-ready)."""
    if isinstance(v, dict):
        return {str(k): plain(x, strict=strict) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [plain(x, strict=strict) for x in v]
    if isinstance(v, np.ndarray):
        return plain(v.tolist(), strict=strict)
    if isinstance(v, (complex, np.complexfloating)):
        return [plain(float(v.real), strict=strict), plain(float(v.imag), strict=strict)]
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, (int, np.integer)):
        return int(v)
    if isinstance(v, (float, np.floating)):
        return None if strict and not math.isfinite(v) else float(v)
    if hasattr(v, "__dataclass_fields__"):
        return {"type": type(v).__name__, **plain(asdict(v), strict=strict)}
    return v


def jsonable(v):
    """JSON-ready copy: complex -> [re, im], arrays -> lists, non-finite floats -> None."""
    return plain(v, strict=True)


def format_complex(z, width=13) -> str:
    """``+1.234560e+00 + 5.000000e-01j`` (``-`` for None); ``width - 7`` decimals."""
    if z is None:
        return "-"
    z = complex(z)
    if z.imag == 0:
        return f"{z.real:+.{width - 7}e}"
    return f"{z.real:+.{width - 7}e} {'+-'[z.imag < 0]} {abs(z.imag):.{width - 7}e}j"


def _fmt(v, spec=".6g") -> str:
    if v is None:
        return "-"
    if isinstance(v, float) and math.isinf(v):
        return "inf"
    return format(v, spec)


# --------------------------------------------------------------------- the report
@dataclass(frozen=True)
class Mode:
    """One real eigenvalue or one complex-conjugate pair (shown with ``Im > 0``).

    Attributes
    ----------
    eigenvalue : complex [1/s]
    wn : float [rad/s] — natural frequency ``|lambda|``
    zeta : float — damping ratio ``-Re(lambda)/|lambda|`` (nan for ``lambda = 0``)
    label : str — what moves (from the case's closed forms or the participation factors)
    pair : bool — ``True`` for a complex-conjugate pair
    closed_form : complex or None — the matching closed-form eigenvalue
    error : float or None — ``|lambda - closed_form| / rho``
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
    gain_margin : float — factor (``inf``: no phase crossover)
    gain_margin_db : float [dB]
    phase_margin : float [deg] (``inf``: no gain crossover)
    stability_margin : float — minimum distance of the Nyquist curve to -1
    phase_crossover : float [rad/s] (nan if none)
    gain_crossover : float [rad/s] (nan if none)
    stability_margin_frequency : float [rad/s]
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
    value : float or None — from the computed model (``None`` when only a formula exists)
    closed_form : float or None
    unit : str
    equation : str — where the closed form comes from (seed equation number)
    """

    name: str
    value: float | None
    closed_form: float | None = None
    unit: str = ""
    equation: str = ""


@dataclass(frozen=True)
class StabilityReport:
    """Linear stability of one case.

    Attributes
    ----------
    case : str — the case function's name
    title : str
    parameters : dict — the case's inputs as plain Python values (``to_dict`` makes them JSON)
    ss : control.StateSpace — the analysed linear model (named states, inputs, outputs)
    eigenvalues : ndarray of complex, shape (n,) [1/s] — of ``ss.A``, sorted by (Re, Im)
    verdict : {'unstable', 'marginally stable', 'asymptotically stable'}
    reason : str — why (the deciding eigenvalue and the tolerance)
    tolerance : float [1/s] — ``ZERO_RTOL * rho``
    modes : tuple of Mode
    margins : Margins or None — for `loop`
    quantities : tuple of Quantity
    closed_form : ndarray of complex or None — closed-form eigenvalues, if known
    closed_form_error : float or None — ``max |lambda - closed form| / rho`` after matching
    notes : tuple of str
    linearization : Linearization or None — the full linearization before reduction
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

    def to_json(self) -> str:
        """`to_dict` as strict JSON text."""
        return json.dumps(self.to_dict(), indent=2, allow_nan=False)

    def __str__(self) -> str:
        lines = [self.title]
        width = max([len(k) for k in self.parameters] + [5])
        for k, v in self.parameters.items():
            lines.append(f"  {k:<{width}}  {param_text(v)}")
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
            zeta = "nan" if math.isnan(m.zeta) else f"{round(m.zeta, 4) + 0.0:+.4f}"
            lines.append(f"  {ev:<31} {m.wn:>11.5e} {zeta:>8}  {m.label:<28}{cf:<31} {err:>9}")
        if self.quantities:
            w = max(len(q.name) for q in self.quantities)
            lines.append(f"{'quantities:':<{w + 2}}  {'linear model':>17}  {'closed form':>17}  "
                         f"{'unit':<9} source")
            for q in self.quantities:
                lines.append(f"  {q.name:<{w}}  {_fmt(q.value, '.10g'):>17}  "
                             f"{_fmt(q.closed_form, '.10g'):>17}  {q.unit:<9} {q.equation}")
        if self.margins is not None:
            mg = self.margins
            lines.append("margins:")
            lines.append(f"  gain margin   {_fmt(mg.gain_margin)} "
                         f"({_fmt(mg.gain_margin_db, '.4g')} dB) at "
                         f"{_fmt(mg.phase_crossover)} rad/s")
            lines.append(f"  phase margin  {_fmt(mg.phase_margin, '.6g')} deg at "
                         f"{_fmt(mg.gain_crossover)} rad/s")
            lines.append(f"  stability margin {_fmt(mg.stability_margin, '.6g')} at "
                         f"{_fmt(mg.stability_margin_frequency)} rad/s")
        if self.closed_form_error is not None:
            lines.append(f"closed-form check: max |lambda - closed form| / rho = "
                         f"{self.closed_form_error:.2e}")
        for n in self.notes:
            lines.append(f"note: {n}")
        return "\n".join(lines)

    def plot(self, path) -> None:
        """Write a pole map (eigenvalues, closed forms, the zero band) as a PNG to ``path``."""
        from matplotlib.figure import Figure

        fig = Figure(figsize=(7.0, 5.5))
        ax = fig.add_subplot(1, 1, 1)
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
        fig.tight_layout()
        fig.savefig(path, dpi=110, format="png")


def _fmt_mode(z: complex, pair: bool) -> str:
    return f"{z.real:+.6e} ± {abs(z.imag):.6e}j" if pair else f"{z.real:+.6e}"


def param_text(v) -> str:
    """Compact text of a parameter value (dicts as ``k=v``, lists in brackets)."""
    if isinstance(v, dict):
        return ", ".join(f"{k}={param_text(x)}" for k, x in v.items())
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(param_text(x) for x in v) + "]"
    if isinstance(v, float):
        return f"{v:.10g}"
    return str(v)


# ------------------------------------------------------------------- the verdict
def _spectral_scale(A: np.ndarray, ev: np.ndarray) -> float:
    rho = float(np.max(np.abs(ev), initial=0.0))
    if rho == 0.0 and A.size:
        rho = float(np.linalg.norm(A, 2))
    return rho if rho > 0 else 1.0


def least_damped(ev: np.ndarray) -> complex:
    """The eigenvalue with the largest real part (of a pair, the one with ``Im > 0``)."""
    if len(ev) == 0:
        return complex("nan")
    return complex(max(ev, key=lambda z: (z.real, z.imag)))


def classify(A, *, rtol: float = ZERO_RTOL):
    """Verdict of the linear system ``x' = A x`` (see the module notes).

    Parameters
    ----------
    A : array_like, shape (n, n) [1/s]
    rtol : float — zero tolerance relative to the spectral scale (default `ZERO_RTOL`)

    Returns
    -------
    verdict : str — one of `VERDICTS`
    reason : str
    tolerance : float [1/s] — ``rtol * rho``
    eigenvalues : ndarray of complex, shape (n,), sorted by (Re, Im)
    """
    A = np.asarray(A, dtype=float)
    if A.ndim != 2 or A.shape[0] != A.shape[1] or not np.all(np.isfinite(A)):
        raise ValueError(f"`A` must be a finite square matrix, got shape {A.shape}")
    if not (np.isfinite(rtol) and 0 < rtol < 1):
        raise ValueError(f"`rtol` must be in (0, 1), got {rtol}")
    n = A.shape[0]
    ev = np.linalg.eigvals(A).astype(complex) if n else np.zeros(0, complex)
    ev = np.asarray(sorted(ev, key=lambda z: (z.real, z.imag)), dtype=complex)
    rho = _spectral_scale(A, ev)
    tol = rtol * rho
    if n == 0:
        return "asymptotically stable", "no states", tol, ev
    top = least_damped(ev)
    if top.real > tol:
        return ("unstable", f"eigenvalue {format_complex(top)} has Re > {tol:.2e} (growth time "
                f"{1 / top.real:.4g} s)", tol, ev)
    axis = ev[np.abs(ev.real) <= tol]
    if len(axis) == 0:
        return ("asymptotically stable", f"every Re < -{tol:.2e}; least damped "
                f"{format_complex(top)} (time constant {-1 / top.real:.4g} s)", tol, ev)
    # group the eigenvalues on the axis and test each group for a Jordan block
    axis = axis[np.argsort(axis.imag)]
    groups, current = [], [axis[0]]
    for z in axis[1:]:
        if abs(z - current[-1]) <= _CLUSTER_RTOL * rho:
            current.append(z)
        else:
            groups.append(current)
            current = [z]
    groups.append(current)
    for g in groups:
        center = complex(0.0, float(np.mean(np.imag(g))))
        sv = np.linalg.svd(A - center * np.eye(n), compute_uv=False)
        nullity = int(np.sum(sv <= _RANK_RTOL * rho))
        if nullity < len(g):
            return ("unstable", f"eigenvalue {format_complex(center)} on the imaginary axis has "
                    f"multiplicity {len(g)} but {nullity} eigenvector(s): a Jordan block, "
                    "perturbations grow secularly", tol, ev)
    rest = n - len(axis)
    return ("marginally stable", f"{len(axis)} eigenvalue(s) with |Re| <= {tol:.2e}, all "
            "semisimple" + (f"; the other {rest} have Re < -{tol:.2e}" if rest else ""), tol, ev)


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
    """Assemble a `StabilityReport` for the linear model ``ss``.

    Parameters
    ----------
    case, title : str
    parameters : dict — the inputs, shown and serialized
    ss : control.StateSpace — the model judged
    lin : Linearization, optional — kept for reference
    groups : mapping of label -> state names, optional — participation labels
    labeler : callable ``(eigenvalue, eigenvector) -> str``, optional — takes precedence
    closed_form : array_like of complex, optional — matched to the eigenvalues
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
    closed_form : array_like of complex, optional — expected eigenvalues, matched and checked

    Returns
    -------
    StabilityReport
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
