"""`shaken_pendulum`: Floquet stability of the hanging or inverted pendulum on a shaken hinge
(seed 000; `dynamics.mechanisms.shaken_pendulum`), checked against Mathieu's equation.

The operating point is time-periodic, so the report is a `PeriodicStabilityReport`: the
Floquet multipliers ``mu`` of the monodromy matrix over one shaking period
``T = 2 pi / freq`` (`dynamics.floquet`) take the place of eigenvalues. Its
``eigenvalues`` are the exponents ``log(mu) / T`` (``Re = log|mu| / T`` [1/s]), so
`problems.stability.sweep` bisects its verdict boundaries like any other case's.

Closed form. About ``theta = 0`` (sign ``s = +1``) or ``pi`` (``s = -1``) with a vertical
shake the perturbation obeys ``I_h u'' + c u' + s (m g l - m l amp_y freq^2 sin(freq t)) u
= 0``. With ``u = exp(-gamma t) v``, ``gamma = c / (2 I_h)``, and ``tau = freq t / 2``
this is Mathieu's ``v'' + (a - 2 q cos 2 tau) v = 0`` (up to a shift of time) with
``a = 4 (s w0^2 - gamma^2) / freq^2`` and ``q = 2 amp_y / l_eff``: ``v`` is stable exactly
when ``a_n(q) < a < b_(n+1)(q)`` for some ``n >= 0`` (``scipy.special.mathieu_a``,
``mathieu_b``), and then every ``|mu| = exp(-gamma T)``. Undamped, that decides the verdict
everywhere (the Kapitza threshold is the edge ``a = a0``, the first resonance tongue
``b1 < a < a1``); damped, where ``v`` grows, the verdict needs the characteristic exponent
and is not predicted. By Liouville ``mu1 mu2 = exp(-c T / I_h)`` always.

Status: `STATUS_VERIFIED` when verdict and moduli agree with a Mathieu prediction made
further than `BOUNDARY_RTOL` (relative, in ``a``) from every edge and, inside a tongue,
with an estimated growth ``pi sqrt((a - b_n)(a_n - a)) / (2 n)`` per period above
`GROWTH_MIN`; `STATUS_UNCHECKED` without one (near an edge, a horizontal shake);
`STATUS_MISMATCH` when they disagree or Liouville's product is off by ``CLOSED_FORM_RTOL``.
"""
from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field

import numpy as np

from appdyn.dynamics.floquet import TOL, classify_multipliers, floquet, variational_model
from appdyn.dynamics.integrate import simulate
from appdyn.dynamics.mechanisms import kapitza_frequency, resonance_tongue
from appdyn.dynamics.mechanisms import shaken_pendulum as shaken_model

from appdyn.dynamics.results import Result

from .common import (STANDARD_GRAVITY, check_number, finish_figure, format_number, jsonable,
                     param_line, plain)
from .report import (CLOSED_FORM_RTOL, STATUS_MISMATCH, STATUS_UNCHECKED, STATUS_VERIFIED,
                     Quantity, StabilityReport)

__all__ = ["FloquetMode", "PeriodicStabilityReport", "shaken_pendulum", "mathieu_region",
           "BOUNDARY_RTOL", "GROWTH_MIN", "POSITIONS"]

#: the two operating points and their ``theta`` [rad]
POSITIONS = {"hanging": 0.0, "inverted": math.pi}
#: a point closer than this (relative, in Mathieu's ``a``) to a stability edge is not checked
BOUNDARY_RTOL = 1e-6
#: least estimated growth ``log|mu|`` per period inside a tongue that is checked
GROWTH_MIN = 10 * TOL
_MAX_ORDER = 60  # Mathieu orders searched (a ~ n^2): slower shaking is not predicted


@dataclass(frozen=True)
class FloquetMode:
    """One Floquet multiplier ``mu``, its modulus (growth per period), its exponent
    ``log(mu) / T`` [1/s] (``Im`` defined modulo ``2 pi / T``) and a label."""

    multiplier: complex
    modulus: float
    exponent: complex
    label: str = ""


@dataclass(frozen=True, repr=False)
class PeriodicStabilityReport(Result):
    """Floquet stability of a time-periodic operating point, in the format of
    `StabilityReport` (same verdicts, statuses, quantities, text, JSON, plot).

    Attributes
    ----------
    case, title, reason, message : str
    parameters : dict
    verdict : {'unstable', 'marginally stable', 'asymptotically stable'}
    tolerance : float
        A multiplier with ``| |mu| - 1 | <= tolerance`` counts as on the unit circle.
    period : float [s]
    states : tuple of str
        Perturbed states (the clock excluded), the order of ``monodromy`` (shape (n, n)).
    modes : tuple of FloquetMode
        By decreasing modulus (``multipliers``: the same as an array).
    eigenvalues : ndarray of complex, shape (n,) [1/s]
        The exponents, sorted by (Re, Im): what `sweep` tracks.
    quantities, notes : tuple of Quantity, tuple of str
    predicted : str or None
        The closed-form verdict, if there is one.
    closed_form_error : float or None
        Largest error of the multiplier moduli and product against their closed forms.
    status : int
        `STATUS_VERIFIED`, `STATUS_UNCHECKED` or `STATUS_MISMATCH`.
    closure : float
        ``max |x(T) - x(0)|`` of the orbit.
    wall_time : float [s]
    integrated : bool
        The Floquet integration succeeded (and the orbit was found).
    success : bool
        ``integrated`` and ``status != STATUS_MISMATCH`` (property).
    floquet : dynamics.floquet.FloquetResult
    """

    case: str
    title: str
    parameters: dict
    verdict: str
    reason: str
    tolerance: float
    period: float
    states: tuple
    monodromy: np.ndarray
    modes: tuple
    eigenvalues: np.ndarray
    quantities: tuple = ()
    predicted: str | None = None
    closed_form_error: float | None = None
    status: int = STATUS_UNCHECKED
    message: str = ""
    closure: float = 0.0
    notes: tuple = ()
    wall_time: float = 0.0
    integrated: bool = True
    floquet: object = field(default=None, repr=False, compare=False)

    _repr_fields = ('case', 'verdict', 'period', 'multipliers')

    @property
    def success(self) -> bool:
        """``False`` when the integration failed or the closed forms disagree."""
        return self.integrated and self.status != STATUS_MISMATCH

    @property
    def multipliers(self) -> np.ndarray:
        """The multipliers, by decreasing modulus."""
        return np.array([m.multiplier for m in self.modes], dtype=complex)

    @property
    def spectral_radius(self) -> float:
        """``max |mu|``."""
        return float(max((m.modulus for m in self.modes), default=0.0))

    # the same contract as StabilityReport's (they read only quantities and eigenvalues)
    least_damped = StabilityReport.least_damped
    quantity = StabilityReport.quantity

    def to_dict(self) -> dict:
        """JSON-ready summary: complex numbers as ``[re, im]``, non-finite numbers as ``None``."""
        return jsonable({
            "case": self.case, "title": self.title, "success": self.success,
            "status": self.status, "message": self.message, "parameters": self.parameters,
            "verdict": self.verdict, "reason": self.reason, "predicted": self.predicted,
            "tolerance": self.tolerance, "period": self.period, "states": list(self.states),
            "monodromy": self.monodromy, "multipliers": self.multipliers,
            "eigenvalues": self.eigenvalues, "modes": [asdict(m) for m in self.modes],
            "quantities": [asdict(q) for q in self.quantities],
            "closed_form_error": self.closed_form_error, "closure": self.closure,
            "notes": list(self.notes), "wall_time": self.wall_time})

    def __str__(self) -> str:
        lines = [self.title]
        lines += [f"  {k:<9}  {param_line(k, v)}" for k, v in self.parameters.items()]
        lines.append(f"  period     {self.period:.10g} s; states {', '.join(self.states)}")
        lines.append(f"verdict: {self.verdict.upper()} — {self.reason} (closed-form "
                     f"prediction: {self.predicted or '-'})")
        lines.append(f"Floquet multipliers (| |mu| - 1 | <= {self.tolerance:.1e} counts as on "
                     "the unit circle):")
        lines.append(f"  {'multiplier':<33} {'|mu|':>14}  {'exponent [1/s]':<33} label")
        for m in self.modes:
            mu, s = m.multiplier, m.exponent
            lines.append(f"  {mu.real:+.8e} {mu.imag:+.8e}j {m.modulus:>14.10f}  "
                         f"{s.real:+.6e} {s.imag:+.6e}j  {m.label}")
        w = max([len(q.name) for q in self.quantities] + [10])
        lines.append(f"{'quantities:':<{w + 2}}  {'computed':>17}  {'closed form':>17}  unit")
        for q in self.quantities:
            lines.append(f"  {q.name:<{w}}  {format_number(q.value, spec='.10g'):>17}  "
                         f"{format_number(q.closed_form, spec='.10g'):>17}  {q.unit:<7} "
                         f"{q.equation}")
        lines.append(f"status {self.status}: {self.message}")
        lines += [f"note: {n}" for n in self.notes]
        return "\n".join(lines)

    def plot(self, ax=None):
        """The multipliers on the unit circle (`dynamics.floquet.FloquetResult.plot`); dashed,
        the closed-form ``|mu|`` of a damped system.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Draw on these axes; by default on a new `matplotlib.figure.Figure` (no pyplot).

        Returns
        -------
        matplotlib.figure.Figure
        """
        fig = self.floquet.plot(ax=ax)
        ax = ax if ax is not None else fig.axes[0]
        r = self.quantity("largest |mu|").closed_form
        if r is not None and abs(r - 1.0) > self.tolerance:
            phase = np.linspace(0.0, 2 * np.pi, 361)
            ax.plot(r * np.cos(phase), r * np.sin(phase), "--", color="tab:orange", lw=0.8,
                    label=f"closed form |mu| = {r:.6g}")
            ax.legend(loc="lower left", fontsize=8)
        ax.set_title(f"{self.title}\n{self.verdict}", fontsize=9)
        return finish_figure(fig)


# ----------------------------------------------------------------- Mathieu prediction
def mathieu_region(a: float, q: float):
    """Where ``(a, q)`` lies in Mathieu's stability chart (``q >= 0``).

    Parameters
    ----------
    a, q : float
        Of ``v'' + (a - 2 q cos 2 tau) v = 0``.

    Returns
    -------
    stable : bool or None
        ``None`` beyond the Mathieu orders searched (``a`` above about 3600).
    distance : float
        To the nearest edge, in ``a``, relative to ``max(|a|, |edge|)``.
    growth : float or None
        In tongue ``n``: ``pi sqrt((a - b_n)(a_n - a)) / (2 n)``, the leading-order
        ``log|mu|`` per period.
    text : str

    Examples
    --------
    >>> from appdyn.problems.stability.periodic import mathieu_region
    >>> mathieu_region(-0.5, 0.2)[0], mathieu_region(1.0, 0.2)[0], mathieu_region(2.0, 0.2)[0]
    (False, False, True)
    """
    from scipy.special import mathieu_a, mathieu_b  # a heavy import, only here

    def rel(e):
        return abs(a - e) / max(abs(a), abs(e), 1e-300)

    edge = float(mathieu_a(0, q))
    if a <= edge:
        return False, rel(edge), None, f"a = {a:.10g} <= a0(q) = {edge:.10g}"
    for n in range(1, _MAX_ORDER + 1):
        lo, hi = float(mathieu_b(n, q)), float(mathieu_a(n, q))
        if a < lo:
            return (True, min(rel(edge), rel(lo)), None,
                    f"a = {a:.10g} in the stable interval (a{n - 1}, b{n}) = "
                    f"({edge:.10g}, {lo:.10g})")
        if a <= hi:
            growth = math.pi * math.sqrt(max((a - lo) * (hi - a), 0.0)) / (2 * n)
            return (False, min(rel(lo), rel(hi)), growth,
                    f"a = {a:.10g} in tongue {n} (b{n}, a{n}) = ({lo:.10g}, {hi:.10g})")
        edge = hi
    return None, math.inf, None, f"a = {a:.6g} beyond Mathieu order {_MAX_ORDER}"


def _prediction(s, w0, gamma, q, freq, period, amp_x):
    """``(verdict or None, |mu| closed form or None, why)`` of the Mathieu closed form."""
    if amp_x != 0.0:
        return None, None, "a horizontal shake (amp_x != 0) has no Mathieu closed form"
    a = 4.0 * (s * w0 ** 2 - gamma ** 2) / freq ** 2
    stable, distance, growth, text = mathieu_region(a, q)
    why = f"Mathieu q = {q:.10g}: {text}"
    if stable is None:
        return None, None, why
    if distance <= BOUNDARY_RTOL:
        return None, None, why + f"; within {BOUNDARY_RTOL:g} of an edge: not checked"
    if not stable and growth is not None and growth < GROWTH_MIN:
        return None, None, why + (f"; estimated growth {growth:.1e} per period < "
                                  f"{GROWTH_MIN:g}: not checked")
    if not stable:
        if gamma > 0:
            return None, None, why + "; v grows: whether damping wins needs the exponent"
        return "unstable", None, why
    radius = math.exp(-gamma * period)
    return classify_multipliers([radius])[0], radius, why


# ---------------------------------------------------------------------- the orbit
def _periodic_orbit(model, theta_ref, s, w0, l_eff, amp_x, freq, period, p):
    """Initial state of the ``period``-periodic orbit near ``theta_ref`` (Newton shooting on
    ``x(T) = x(0)``, started from the linear forced response); ``(x0, converged)``."""
    x = np.array([theta_ref, 0.0, 0.0])
    if amp_x == 0.0:
        return x, True
    x[1] = s * amp_x * freq ** 3 / l_eff / (s * w0 ** 2 - freq ** 2)
    aug = variational_model(model)
    for _ in range(12):
        res = simulate(aug, np.concatenate([x, np.eye(2).ravel(order="F")]), [0.0, period],
                       p=p, method="auto", rtol=1e-11, atol=1e-11)
        end = res.x[:, -1]
        gap = end[:2] - x[:2]
        if not res.success or not np.all(np.isfinite(end)):
            return x, False
        if np.max(np.abs(gap)) <= 1e-10 * max(1.0, abs(x[1])):
            return x, True
        try:
            x[:2] -= np.linalg.solve(end[3:].reshape(2, 2, order="F") - np.eye(2), gap)
        except np.linalg.LinAlgError:
            return x, False
    return x, False


def _mode_label(mu: complex, tol: float) -> str:
    where = ("on the unit circle" if abs(abs(mu) - 1) <= tol else
             "outside: grows" if abs(mu) > 1 else "inside: decays")
    if abs(mu.imag) > 1e-12 * max(abs(mu), 1e-300):
        return f"complex, {where}"
    return where + (", real < 0: response at freq/2" if mu.real < 0 else ", real > 0")


def shaken_pendulum(*, mass, inertia, length, amp_y, freq, amp_x=0.0, damping=0.0,
                    gravity=STANDARD_GRAVITY, position="hanging") -> PeriodicStabilityReport:
    """Floquet stability of the hanging or inverted pendulum on a shaken hinge.

    Parameters
    ----------
    mass, inertia, length : float [kg, kg m^2, m]
        ``m > 0``; central moment about the hinge axis ``>= 0``; hinge to mass centre ``> 0``.
    amp_y, freq : float [m, rad/s]
        Vertical shaking amplitude ``>= 0`` and frequency ``> 0`` (period ``2 pi / freq``).
    amp_x : float [m], optional
        Horizontal amplitude: the orbit then swings and is found by shooting (no closed form).
    damping, gravity : float [N m s, m/s^2], optional
        Viscous hinge ``>= 0``; gravity ``> 0``.
    position : {'hanging', 'inverted'}, optional
        ``theta = 0`` or ``pi``.

    Returns
    -------
    PeriodicStabilityReport
        Multipliers, exponents, verdict, period; the Kapitza frequency (inverted) or the
        first tongue (hanging) as quantities while ``q = 2 amp_y / l_eff < 0.9``.

    Raises
    ------
    ValueError
        Naming the argument out of range.

    Examples
    --------
    A uniform rod 0.5 m long (``l_eff = 1/3`` m) shaken by 2 cm, whose Kapitza frequency is
    127.946 rad/s:

    >>> from appdyn.problems import stability
    >>> rod = dict(mass=1.0, inertia=1 / 48, length=0.25, amp_y=0.02)
    >>> rep = stability.shaken_pendulum(**rod, freq=200.0, position="inverted")
    >>> rep.verdict, rep.status, round(rep.quantity("Kapitza frequency (M").closed_form, 3)
    ('marginally stable', 0, 127.946)
    >>> stability.shaken_pendulum(**rod, freq=100.0, position="inverted").verdict
    'unstable'
    >>> stability.shaken_pendulum(**rod, freq=11.0).verdict   # inside the first tongue
    'unstable'
    """
    start = time.perf_counter()
    m, l, freq, g = (check_number(v, k, positive=True) for v, k in (
        (mass, "mass"), (length, "length"), (freq, "freq"), (gravity, "gravity")))
    inertia, amp_y, c = (check_number(v, k, nonnegative=True) for v, k in (
        (inertia, "inertia"), (amp_y, "amp_y"), (damping, "damping")))
    amp_x = check_number(amp_x, "amp_x")
    if position not in POSITIONS:
        raise ValueError(f"`position` must be one of {list(POSITIONS)}, got {position!r}")
    params = dict(mass=m, inertia=inertia, length=l, amp_y=amp_y, freq=freq, amp_x=amp_x,
                  damping=c, gravity=g, position=position)
    i_h = inertia + m * l * l
    l_eff, s = i_h / (m * l), (1.0 if position == "hanging" else -1.0)
    w0, gamma, q = math.sqrt(g / l_eff), c / (2.0 * i_h), 2.0 * amp_y / l_eff
    period = 2.0 * math.pi / freq
    model = shaken_model(mass=m, inertia=inertia, length=l, gravity=g, amp_y=amp_y, amp_x=amp_x,
                         freq=freq, damping=c)
    p = model.resolve_p()
    x0, found = _periodic_orbit(model, POSITIONS[position], s, w0, l_eff, amp_x, freq, period, p)
    res = floquet(model, x0, period, p=p)
    mu = res.multipliers
    predicted, radius, why = _prediction(s, w0, gamma, q, freq, period, amp_x)
    liouville, product = math.exp(-c * period / i_h), complex(np.prod(mu))
    error = float(max([abs(product - liouville)]
                      + ([abs(abs(z) - radius) for z in mu] if radius is not None else [])))
    quantities = [Quantity("natural frequency w0 = sqrt(g / l_eff)", None, w0, "rad/s"),
                  Quantity("Mathieu q = 2 amp_y / l_eff", None, q),
                  Quantity("Mathieu a = 4 (s w0^2 - gamma^2) / freq^2", None,
                           4.0 * (s * w0 ** 2 - gamma ** 2) / freq ** 2, "",
                           f"s = {s:+g}, gamma = c / (2 I_h) = {gamma:.6g} 1/s"),
                  Quantity("multiplier product (Liouville)", product.real, liouville, "",
                           "mu1 mu2 = exp(-c T / I_h)"),
                  Quantity("largest |mu|", res.spectral_radius, radius, "",
                           "exp(-gamma T) where Mathieu's v is stable")]
    if 0.0 < q < 0.9:
        shape = dict(mass=m, inertia=inertia, length=l, gravity=g)
        if position == "inverted":
            quantities += [
                Quantity("Kapitza frequency (Mathieu a0)", None,
                         kapitza_frequency(amp_y, **shape), "rad/s", "freq* = 2 w0 / sqrt(-a0)"),
                Quantity("Kapitza frequency (averaging)", None,
                         kapitza_frequency(amp_y, **shape, exact=False), "rad/s",
                         "sqrt(2 g l_eff) / amp_y")]
        else:
            low, high = resonance_tongue(amp_y, **shape)
            quantities += [Quantity("first tongue, lower edge (a1)", None, low, "rad/s",
                                    "2 w0 / sqrt(a1(q)), undamped"),
                           Quantity("first tongue, upper edge (b1)", None, high, "rad/s",
                                    "2 w0 / sqrt(b1(q)), undamped")]
    if amp_x != 0.0:
        quantities += [Quantity("orbit theta(0)", float(x0[0]), None, "rad", "shooting"),
                       Quantity("orbit theta_dot(0)", float(x0[1]), None, "rad/s", "shooting")]
    if error > CLOSED_FORM_RTOL or (predicted is not None and predicted != res.verdict):
        status = STATUS_MISMATCH
        message = (f"the Floquet verdict {res.verdict!r} or the multipliers DISAGREE with the "
                   f"closed form ({predicted or 'no verdict'}; max error {error:.1e})")
    elif predicted is None:
        status, message = STATUS_UNCHECKED, f"verdict not checked: {why}"
    else:
        status = STATUS_VERIFIED
        message = (f"verdict agrees with Mathieu's chart; multipliers with the closed forms "
                   f"to {error:.1e}")
    notes = [why, "the clock state t is excluded from the monodromy (multiplier 1)",
             f"integration: {res.message}"]
    if amp_x != 0.0:
        notes.append(f"horizontal shake: periodic orbit by shooting, closure {res.closure:.1e}"
                     if found else "NO periodic orbit found by shooting: multipliers of x0 only")
    modes = tuple(FloquetMode(complex(z), float(abs(z)), complex(e), _mode_label(z, res.tol))
                  for z, e in zip(mu, res.exponents))
    ev = np.asarray(sorted(res.exponents, key=lambda z: (z.real, z.imag)), dtype=complex)
    title = f"Shaken pendulum, {position} (seed 000): Floquet multipliers over T = 2 pi / freq"
    return PeriodicStabilityReport(
        case="shaken_pendulum", title=title, parameters=plain(params), verdict=res.verdict,
        reason=res.reason, tolerance=res.tol, period=period, states=res.states,
        monodromy=res.monodromy, modes=modes, eigenvalues=ev, quantities=tuple(quantities),
        predicted=predicted, closed_form_error=error, status=status, message=message,
        closure=res.closure, notes=tuple(notes), wall_time=time.perf_counter() - start,
        integrated=bool(res.success and found), floquet=res)
