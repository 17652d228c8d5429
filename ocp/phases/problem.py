"""Statement of a multi-phase optimal-control problem (no transcription, no solver).

A `MultiPhaseProblem` is a sequence of `Phase`\\ s flown back to back, each a single-phase
`ocp.Problem` (its own model, horizon -- fixed or free --, bounds, boundary values, path and
boundary constraints and cost) with its own transcription and mesh, tied together by

* **links** (`Link`): ``x_b(t0_b)[s] = x_a(tf_a)[s] + jump[s]`` for chosen states ``s``
  (continuity, or a jump such as the mass dropped at staging);
* **events** (`ocp.Constraint` over the phase ends): ``lower <= e(ends) <= upper``;
* an **objective** over the phase ends, ``Phi(ends)``, added to the phases' own costs::

      J = Phi(ends) + sum_i [ phi_i(xf_i, p_i, T_i) + integral L_i dt ]   (maximize=True: -J)

Times
-----
Phase ``i`` starts where phase ``i - 1`` ends: ``t0_0 = t0`` and ``t0_i = t0_{i-1} + T_{i-1}``.
The dynamics are time-invariant (as in `ocp.Problem`), so time continuity is a definition,
not a constraint: only the durations ``T_i`` are variables (a fixed event time, such as a
booster jettisoned at 75.2 s, is a fixed duration). An event may still constrain the times
``t0``/``tf`` of any phase (a total-time limit).

Phase ends
----------
``objective`` and each event's ``fun`` are callables of one argument, the list ``ends`` of
one `PhaseEnd` per phase, holding CasADi symbols: ``ends[i].x0``, ``.xf`` (nx_i, 1),
``.p`` (np_i, 1), ``.T``, ``.t0``, ``.tf``, and by name ``ends[i]["m_f"]`` (final value
of state ``m``), ``ends[i]["h_0"]`` (initial value), ``ends[i]["k"]`` (parameter ``k``),
``ends[i]["T"]``. They are evaluated once on symbols and become one CasADi Function.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Mapping, Sequence

import casadi as ca
import numpy as np

from ..mesh import Mesh
from ..problem import Constraint, Problem
from ..transcription import Transcription

__all__ = ["Phase", "Link", "MultiPhaseProblem", "PhaseEnd"]


@dataclass(frozen=True, eq=False)
class Phase:
    """One phase: a single-phase problem and how it is transcribed.

    Parameters
    ----------
    problem : ocp.Problem
        The phase's dynamics, horizon ``T`` (its duration; fixed or free), bounds, boundary
        values, path/boundary constraints and cost. ``maximize`` must be False (the
        multi-phase problem has the sign); ``problem.t0`` is ignored (phases run back to back).
    N : int, optional
        Uniform mesh intervals (default 20), unless ``mesh`` is given.
    transcription : str or Transcription, optional
        As in `ocp.solve` (default ``'radau'``).
    degree : int, optional
        Radau degree (default 3).
    mesh : ocp.Mesh or array_like, optional
        Breakpoints in normalized time (0 to 1).
    guess : None, ocp.Solution or mapping, optional
        The phase's initial guess, as `ocp.solve` takes it (times from the phase's start).
    scale : mapping, optional
        Scale overrides of the phase (`ocp.scaling`).
    name : str, optional
        Label (default: the problem's name, else ``'phase i'``).
    """

    problem: Problem
    N: int | None = None
    transcription: object = "radau"
    degree: int | None = None
    mesh: object = None
    guess: object = None
    scale: Mapping | None = None
    name: str = ""


@dataclass(frozen=True)
class Link:
    """``x_b(t0_b)[s] - x_a(tf_a)[s] = jump[s]`` for the states ``s`` of ``states``.

    Parameters
    ----------
    a, b : int
        Phase indices, ``a < b`` (usually ``b = a + 1``).
    states : sequence of str, optional
        Linked state names (present in both phases' models); default: every state of
        phase ``b``'s model.
    jump : mapping of str to float, optional
        Jumps by state name (default 0): ``{'m': -4164.0}`` drops 4164 kg at the link.
    """

    a: int
    b: int
    states: Sequence[str] | None = None
    jump: Mapping[str, float] = field(default_factory=dict)


class PhaseEndNameError(KeyError, ValueError):
    """An unknown name asked of a `PhaseEnd` (a ``KeyError`` and a ``ValueError``)."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""


class PhaseEnd:
    """The ends of one phase as CasADi symbols (see the module docstring)."""

    def __init__(self, problem: Problem, x0, xf, p, T, t0):
        self.x0, self.xf, self.p, self.T, self.t0 = x0, xf, p, T, t0
        self.tf = t0 + T
        model = problem.model
        names = {"T": T, "t0": t0, "tf": self.tf}
        for i, s in enumerate(model.states):
            names[f"{s}_0"], names[f"{s}_f"] = x0[i], xf[i]
        for i, q in enumerate(model.params):
            names[q] = p[i]
        self._names = names

    def __getitem__(self, name: str):
        try:
            return self._names[name]
        except KeyError:
            raise PhaseEndNameError(f"unknown phase-end name {name!r}; valid: "
                                    f"{sorted(self._names)}") from None


def _check_index(value, name: str, n: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"`{name}` must be an int, got {type(value).__name__}")
    if not 0 <= value < n:
        raise ValueError(f"`{name}` must be a phase index in 0..{n - 1}, got {value}")
    return int(value)


def _check_link(link, k: int, phases) -> tuple[int, int, tuple[int, ...], tuple[int, ...], np.ndarray]:
    """``(a, b, rows of a, rows of b, jump)`` of ``links[k]``."""
    arg = f"links[{k}]"
    if not isinstance(link, Link):
        raise TypeError(f"`{arg}` must be an ocp.Link, got {type(link).__name__}")
    a, b = _check_index(link.a, f"{arg}.a", len(phases)), _check_index(link.b, f"{arg}.b", len(phases))
    if a >= b:
        raise ValueError(f"`{arg}` must link an earlier phase to a later one (a < b), got a={a}, b={b}")
    ma, mb = phases[a].problem.model, phases[b].problem.model
    states = tuple(mb.states) if link.states is None else tuple(link.states)
    if not states:
        raise ValueError(f"`{arg}.states` must name at least one state")
    for s in states:
        if not isinstance(s, str) or s not in ma.states or s not in mb.states:
            raise ValueError(f"`{arg}.states` names {s!r}, which is not a state of both phases "
                             f"{a} {list(ma.states)} and {b} {list(mb.states)}")
    if not isinstance(link.jump, Mapping):
        raise TypeError(f"`{arg}.jump` must be a mapping state -> float, got {type(link.jump).__name__}")
    jump = np.zeros(len(states))
    for s, v in link.jump.items():
        if s not in states:
            raise ValueError(f"`{arg}.jump` names {s!r}, which is not a linked state {list(states)}")
        v = float(v)
        if not math.isfinite(v):
            raise ValueError(f"`{arg}.jump[{s!r}]` must be finite, got {v}")
        jump[states.index(s)] = v
    return (a, b, tuple(ma.states.index(s) for s in states),
            tuple(mb.states.index(s) for s in states), jump)


def _check_phase(phase, i: int) -> Phase:
    if not isinstance(phase, Phase):
        raise TypeError(f"`phases[{i}]` must be an ocp.Phase, got {type(phase).__name__}")
    if not isinstance(phase.problem, Problem):
        raise TypeError(f"`phases[{i}].problem` must be an ocp.Problem, got "
                        f"{type(phase.problem).__name__}")
    if phase.problem.maximize:
        raise ValueError(f"`phases[{i}].problem` maximizes: give the sign to the multi-phase "
                         "problem (`maximize=True`) and keep the phases minimizing")
    if phase.transcription is not None and not isinstance(phase.transcription, (str, Transcription)):
        raise TypeError(f"`phases[{i}].transcription` must be a name or a Transcription")
    if phase.mesh is not None and not isinstance(phase.mesh, (Mesh, np.ndarray, list, tuple)):
        raise TypeError(f"`phases[{i}].mesh` must be an ocp.Mesh or breakpoints")
    return phase


@dataclass(frozen=True, eq=False)
class MultiPhaseProblem:
    """A multi-phase optimal-control problem (validated on creation; see the module
    docstring).

    Parameters
    ----------
    phases : sequence of Phase
        At least one, flown in order.
    links : sequence of Link, optional
        State links between phase ends.
    objective : callable, optional
        ``Phi(ends)`` (scalar), added to the phases' own costs.
    events : Constraint or sequence of Constraint, optional
        Constraints whose ``fun`` is a callable of ``ends``; default bounds ``fun <= 0``
        as for `ocp.Constraint` (give ``lower=upper=0`` for equalities).
    t0 : float, optional [s]
        Start of the first phase.
    maximize : bool, optional
        Maximize ``J`` instead of minimizing it.
    name : str, optional

    Attributes
    ----------
    link_rows : tuple
        ``(a, b, states of a, states of b, jump)`` per link (indices).
    event_sizes : tuple of int
        Rows of each event.

    Raises
    ------
    TypeError
        A phase that is not an `ocp.Phase` (with an `ocp.Problem`), a link that is not an
        `ocp.Link`, an objective or event function that is not callable.
    ValueError
        Naming the argument: no phases, a maximizing phase, a link between unknown phases
        or states, a non-scalar objective, an event whose bounds do not match its rows,
        ``t0`` not finite, ``maximize`` not a bool.
    """

    phases: Sequence[Phase]
    links: Sequence[Link] = ()
    objective: Callable | None = None
    events: object = ()
    t0: float = 0.0
    maximize: bool = False
    name: str = ""
    link_rows: tuple = field(init=False, repr=False)
    event_sizes: tuple = field(init=False, repr=False)
    ends_function: ca.Function = field(init=False, repr=False)

    def __post_init__(self):
        phases = self.phases
        if isinstance(phases, Phase) or not isinstance(phases, Sequence) or not phases:
            raise ValueError("`phases` must be a non-empty sequence of ocp.Phase")
        phases = tuple(_check_phase(p, i) for i, p in enumerate(phases))
        links = (self.links,) if isinstance(self.links, Link) else tuple(self.links)
        events = (self.events,) if isinstance(self.events, Constraint) else tuple(self.events)
        for k, ev in enumerate(events):
            if not isinstance(ev, Constraint):
                raise TypeError(f"`events[{k}]` must be an ocp.Constraint, got {type(ev).__name__}")
            if not callable(ev.fun):
                raise TypeError(f"`events[{k}].fun` must be a callable of the phase ends")
        if self.objective is not None and not callable(self.objective):
            raise TypeError(f"`objective` must be a callable of the phase ends or None, got "
                            f"{type(self.objective).__name__}")
        if self.maximize not in (True, False):
            raise ValueError(f"`maximize` must be True or False, got {self.maximize!r}")
        t0 = float(self.t0)
        if not math.isfinite(t0):
            raise ValueError(f"`t0` must be finite, got {self.t0!r}")
        set_ = object.__setattr__
        set_(self, "phases", phases)
        set_(self, "links", links)
        set_(self, "t0", t0)
        set_(self, "link_rows", tuple(_check_link(l, k, phases) for k, l in enumerate(links)))
        fun, sizes, bounded = _ends_function(phases, self.link_rows, self.objective, events)
        set_(self, "ends_function", fun)
        set_(self, "event_sizes", sizes)
        set_(self, "events", bounded)

    @property
    def n_phases(self) -> int:
        return len(self.phases)

    @property
    def objective_sign(self) -> float:
        """``+1.0`` (minimize) or ``-1.0`` (maximize)."""
        return -1.0 if self.maximize else 1.0

    def phase_name(self, i: int) -> str:
        """Label of phase ``i``."""
        ph = self.phases[i]
        return ph.name or f"phase {i}"

    def event_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """``(lower, upper)`` of every event row: the link rows (``jump``, ``jump``) first, then
        the events in order."""
        lo = [l[4] for l in self.link_rows] + [c.lower for c in self.events]
        hi = [l[4] for l in self.link_rows] + [c.upper for c in self.events]
        return (np.concatenate(lo) if lo else np.zeros(0), np.concatenate(hi) if hi else np.zeros(0))


def ends_sizes(phases) -> list[int]:
    """Entries of each phase in the flat ends vector ``E``: ``x0, xf, p, T``."""
    return [2 * ph.problem.model.nx + ph.problem.model.np + 1 for ph in phases]


def phase_ends(phases, E, t0) -> list[PhaseEnd]:
    """The `PhaseEnd` of every phase from the flat ends vector ``E`` (symbols)."""
    out, k, start = [], 0, t0
    for ph in phases:
        m = ph.problem.model
        x0, xf = E[k:k + m.nx], E[k + m.nx:k + 2 * m.nx]
        p, T = E[k + 2 * m.nx:k + 2 * m.nx + m.np], E[k + 2 * m.nx + m.np]
        out.append(PhaseEnd(ph.problem, x0, xf, p, T, start))
        start = start + T
        k += 2 * m.nx + m.np + 1
    return out


def _ends_function(phases, link_rows, objective, events):
    """``(Function E -> (phi, e), event sizes, events with array bounds)``: the objective
    and the link rows (`MultiPhaseProblem.link_rows`), then the event rows over the flat ends vector ``E`` (`ends_sizes`)."""
    n = sum(ends_sizes(phases))
    for sym in (ca.SX, ca.MX):
        E = sym.sym("E", n)
        ends = phase_ends(phases, E, 0.0)
        try:
            phi = _scalar(objective(ends), "objective") if objective is not None else sym(0)
            rows, sizes, bounded = [], [], []
            for k, ev in enumerate(events):
                r = _rows(ev.fun(ends), f"events[{k}]", sym)
                sizes.append(r.numel())
                bounded.append(_bounded(ev, r.numel(), k))
                rows.append(r)
        except (RuntimeError, NotImplementedError, TypeError) as exc:
            if sym is ca.MX:
                raise ValueError(f"`objective`/`events` could not be evaluated on the phase ends: "
                                 f"{exc}") from exc
            continue
        links = [ends[b].x0[list(ib)] - ends[a].xf[list(ia)] for a, b, ia, ib, _ in link_rows]
        rows = links + rows
        return (ca.Function("phase_ends", [E], [phi, ca.vertcat(*rows) if rows else sym(0, 1)],
                            ["E"], ["phi", "e"]), tuple(sizes), tuple(bounded))
    raise AssertionError("unreachable")


def _scalar(value, argname: str):
    value = value[0] if isinstance(value, (list, tuple)) and len(value) == 1 else value
    try:
        n = value.numel()
    except AttributeError:
        n = np.size(value)
    if n != 1:
        raise ValueError(f"`{argname}` must return a scalar, got {n} elements")
    return value


def _rows(value, argname: str, sym):
    if isinstance(value, (list, tuple)):
        value = ca.vertcat(*[v if isinstance(v, (ca.SX, ca.MX)) else sym(float(v)) for v in value])
    elif not isinstance(value, (ca.SX, ca.MX)):
        value = sym(np.asarray(value, dtype=float).reshape(-1, 1))
    return ca.vec(value)


def _bounded(ev: Constraint, m: int, k: int) -> Constraint:
    """``ev`` with its bounds (and scale) as arrays of ``m`` rows."""
    out = {}
    for attr in ("lower", "upper", "scale"):
        v = getattr(ev, attr)
        if v is None:
            out[attr] = None
            continue
        arr = np.broadcast_to(np.asarray(v, dtype=float).reshape(-1), (m,)) if np.size(v) in (1, m) else None
        if arr is None:
            raise ValueError(f"`events[{k}].{attr}` must have 1 or {m} elements, got {np.size(v)}")
        out[attr] = np.array(arr)
    if np.any(out["lower"] > out["upper"]):
        raise ValueError(f"`events[{k}]`: lower > upper")
    if out["scale"] is not None and not np.all((out["scale"] > 0) & np.isfinite(out["scale"])):
        raise ValueError(f"`events[{k}].scale` must be finite and > 0")
    return Constraint(ev.fun, out["lower"], out["upper"], out["scale"], ev.name)
