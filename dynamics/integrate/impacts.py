"""Impacts as events of `simulate` (``impacts=``): when a contact's guard crosses zero
downwards (a touchdown, a docking), the state jumps by an impulse map and the integration
restarts from the new state.

How it runs
-----------
The solution is integrated from ``t[0]`` with the guard as a terminal event (direction
``-1``, located as `dynamics.integrate.events` locates events, to a few ulps of ``t``). At
the event time ``te`` the jump ``x+ = jump(te, x-, u, p)`` is applied and a new run starts
at ``(te, x+)`` on the output times after ``te`` (its guard taken as positive at ``te``, where
it is zero to round-off: the contact separates); the runs are joined on the output grid
(``t`` is the grid asked for; at an output time that is an impact time ``x`` holds the state
after the jump). Each run is a full `simulate` call with the same method and tolerances, so
its accuracy is that of a run without impacts between the impact times.

After a jump the guard's rate ``dg/dt = dg/dt + dg/dx . f(x+)`` (central differences along
the flow: exact for a guard linear in ``t`` and ``x``) is the rebound speed. The **Zeno
guard**: when it is at most ``rest_speed`` (a ball whose bounces shrink geometrically would
otherwise bounce infinitely often before a finite time) the solution stops there: ``t``
ends at the impact time with ``x+``, ``status`` `TERMINAL_EVENT`, ``success`` True and the
message says the contact came to rest. ``max_impacts`` bounds the number of impacts the
same way. As for events, a zero of the guard at ``t[0]`` is no impact: start apart.

The result's ``impacts`` lists every impact (`ImpactRecord`: time, states before and after,
the rebound speed and what the jump map reported, e.g. the `dynamics.mechanisms.impact`
result with its impulses). `SimulationResult.sample` interpolates between output times: over
an interval that holds an impact it interpolates across the jump (put an output time at the
impact, or read the records).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from types import MappingProxyType
from typing import Callable

import casadi as ca
import numpy as np

from .. import validate
from ..model import Model
from .events import Event, controls_at
from .inputs import RunOptions, check_u
from .result import OK, TERMINAL_EVENT, Dense, SimulationResult, make_result

__all__ = ["Impact", "ImpactRecord", "check_impact", "simulate_impacts"]

#: Relative step of the central difference of the guard's rate after a jump.
_RATE_STEP = 6e-6


class Impact:
    """A contact of `simulate` (``impacts=``): a guard whose downward zero crossing applies
    an impulse map and continues.

    Parameters
    ----------
    guard : casadi.Function or callable
        ``g(t, x, u, p) -> scalar`` [m]: the contact distance (positive while apart).
    jump : callable
        ``jump(t, x, u, p) -> x_plus`` (``(nx,)``) or ``(x_plus, info)``: the state just
        after the impact; ``info`` (e.g. the `dynamics.mechanisms.ImpactResult` that
        `dynamics.mechanisms.contact_jump` returns) is kept in the record.
    rest_speed : float, optional
        Zeno guard [guard units/s], ``>= 0``: stop when the guard's rate after a jump is at
        most this (default 0: stop only when the contact does not separate).
    max_impacts : int, optional
        Most impacts before the solution stops (default 1000).
    name : str, optional
        Named in messages (default the guard's name).

    Examples
    --------
    A ball dropped from 1 m with ``e = 0.5`` bounces at ``t1 = sqrt(2 h0 / g)`` and then after
    flights of ``2 e^k sqrt(2 g h0) / g``; its apex after ``n`` bounces is ``e^(2n) h0``:

    >>> import casadi as ca
    >>> import numpy as np
    >>> from appdyn.dynamics import Impact, Model, simulate
    >>> from appdyn.dynamics.mechanisms import contact_jump
    >>> x, u, p, t = ca.SX.sym("x", 2), ca.SX.sym("u", 0), ca.SX.sym("p", 0), ca.SX.sym("t")
    >>> ball = Model(f=ca.Function("ball", [x, u, p], [ca.vertcat(x[1], -9.81)],
    ...                            ["x", "u", "p"], ["xdot"]), states=("h", "v"), controls=())
    >>> floor = Impact(ca.Function("floor", [t, x, u, p], [x[0]]),
    ...                contact_jump(lambda q, p: [[1.0]], lambda q, p: [1.0], e=0.5, nq=1),
    ...                rest_speed=0.1)
    >>> res = simulate(ball, [1.0, 0.0], np.linspace(0.0, 2.0, 21), method="rk8", impacts=floor)
    >>> t1 = float(np.sqrt(2 / 9.81))
    >>> len(res.impacts), abs(res.impacts[0].t - t1) < 1e-14
    (6, True)
    >>> abs(res.impacts[2].t - (t1 + 2 * (0.5 + 0.25) * 9.81 * t1 / 9.81)) < 1e-14
    True
    >>> res.status, bool(res.t[-1] == res.impacts[-1].t), round(res.impacts[-1].rebound_speed, 6)
    (6, True, 0.06921)
    """

    def __init__(self, guard, jump: Callable, *, rest_speed: float = 0.0,
                 max_impacts: int = 1000, name: str | None = None):
        if not callable(guard):
            raise TypeError(f"`guard` must be a callable g(t, x, u, p) or a casadi Function, "
                            f"got {type(guard).__name__}")
        if not callable(jump):
            raise TypeError(f"`jump` must be a callable (t, x, u, p) -> x_plus, got "
                            f"{type(jump).__name__}")
        self.guard, self.jump = guard, jump
        self.rest_speed = validate.nonnegative(rest_speed, "rest_speed")
        self.max_impacts = validate.integer(max_impacts, "max_impacts", minimum=1)
        self.name = name or getattr(guard, "__name__", None) or (
            guard.name() if hasattr(guard, "name") else "impact")

    def __repr__(self) -> str:
        return (f"Impact({self.name!r}, rest_speed={self.rest_speed!r}, "
                f"max_impacts={self.max_impacts!r})")


@dataclass(frozen=True)
class ImpactRecord:
    """One impact of a simulation with ``impacts=``.

    Attributes
    ----------
    t : float [s]
        Impact time (the guard's zero).
    x_before, x_after : ndarray, shape (nx,)
        The states just before and after the jump.
    rebound_speed : float
        The guard's rate just after the jump [guard units/s].
    normal_impulse : float [N s]
        ``info.normal_impulse`` when the jump map reports one, else NaN.
    info : object
        What the jump map returned besides the state (None if nothing).

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics import ImpactRecord
    >>> r = ImpactRecord(0.5, np.array([0.0, -2.0]), np.array([0.0, 1.0]), 1.0, 3.0)
    >>> r.t, r.x_after[1], r.info is None
    (0.5, np.float64(1.0), True)
    """

    t: float
    x_before: np.ndarray
    x_after: np.ndarray
    rebound_speed: float
    normal_impulse: float
    info: object = None


def check_impact(impacts) -> Impact:
    """``impacts`` of `simulate` checked: one `Impact`.

    Raises
    ------
    TypeError
        If ``impacts`` is not an `Impact`.
    """
    if not isinstance(impacts, Impact):
        raise TypeError("`impacts` must be an Impact(guard, jump, ...), got "
                        f"{type(impacts).__name__}")
    return impacts


def _jumped(impact: Impact, te: float, x: np.ndarray, u: np.ndarray, p: np.ndarray, nx: int):
    out = impact.jump(te, x.copy(), u.copy(), p.copy())
    info = None
    if isinstance(out, tuple):
        if len(out) != 2:
            raise ValueError(f"`{impact.name}` jump must return x_plus or (x_plus, info), got "
                             f"a tuple of {len(out)}")
        out, info = out
    x_plus = np.asarray(out, dtype=float).reshape(-1)
    if x_plus.size != nx or not np.all(np.isfinite(x_plus)):
        raise ValueError(f"`{impact.name}` jump must return {nx} finite states, got "
                         f"{x_plus.size} ({x_plus})")
    return x_plus, info


def _guard_rate(impact: Impact, model: Model, te: float, x: np.ndarray, u: np.ndarray,
                p: np.ndarray) -> float:
    """``dg/dt`` along the flow at ``(te, x)`` by central differences."""
    f = np.asarray(model.f(x, u, p), dtype=float).reshape(-1)
    h = _RATE_STEP * max(1.0, abs(te)) / max(1.0, float(np.max(np.abs(f))))
    ev = Event(impact.guard)
    return (ev(te + h, x + h * f, u, p) - ev(te - h, x - h * f, u, p)) / (2 * h)


def _restarted(guard, t_start: float, model: Model):
    """The guard of a run restarted at ``t_start`` on its zero: ``+1`` at ``t_start`` (the
    contact separates there: the rebound speed exceeds ``rest_speed``), the guard after it,
    so that a round-off value of either sign at the restart is neither an event nor hides
    the next one."""
    if isinstance(guard, ca.Function):
        t, x = ca.SX.sym("t"), ca.SX.sym("x", model.nx)
        u, p = ca.SX.sym("u", model.nu), ca.SX.sym("p", model.np)
        g = guard(t, x, u, p)
        return ca.Function(guard.name(), [t, x, u, p], [ca.if_else(t == t_start, 1.0, g)])

    def restarted(tau, x, u, p):
        return 1.0 if tau == t_start else guard(tau, x, u, p)
    return restarted


def _segment_u(u, control, t: np.ndarray, te: float, k: int, nu: int):
    """``u`` for a run on ``[te, t[k:]]`` (``t[k:]`` when ``te = t[k]``): samples re-sampled (the control at ``te``, then
    the samples from ``t[k]`` on), anything else as given."""
    if u is None or callable(u) or np.ndim(u) < 2:
        return u
    if t[k] == te:
        return np.asarray(u, dtype=float)[:, k:]
    u_te = controls_at(control, t, np.array([te]), nu)
    return np.concatenate([u_te, np.asarray(u, dtype=float)[:, k:]], axis=1)


def simulate_impacts(simulate: Callable, model: Model, x0: np.ndarray, t: np.ndarray,
                     impact: Impact, u, p: np.ndarray, *, hold: str, invariants,
                     options: RunOptions) -> SimulationResult:
    """`simulate` with ``impacts=impact``: runs between impacts joined on the grid ``t``.

    ``simulate`` is `dynamics.simulate` (called without impacts for each run); ``options``
    its options for each run (a `RunOptions`: method, tolerances, steps, jit, ...);
    ``invariants`` the checked names to evaluate on the joined solution.
    """
    start = time.perf_counter()
    control = check_u(u, model.nu, t, hold=hold)
    nx = model.nx
    ev = Event(impact.guard, terminal=True, direction=-1, name=impact.name)
    X = np.full((nx, t.size), np.nan)
    records: list[ImpactRecord] = []
    n_steps = n_rhs = 0
    estimates, compiled = [], True
    t_start, x_start, k = float(t[0]), np.asarray(x0, dtype=float), 0
    stop_message, end = "", None
    while True:
        grid = t[k:] if t[k] == t_start else np.r_[t_start, t[k:]]
        if records:  # a restart on the guard's zero: apart there (the rebound separates)
            ev = Event(_restarted(impact.guard, t_start, model), terminal=True, direction=-1,
                       name=impact.name)
        run = simulate(model, x_start, grid, u=_segment_u(u, control, t, t_start, k, model.nu),
                       p=p, hold=hold, events=ev, **options.keywords())
        n_steps, n_rhs = n_steps + run.n_steps, n_rhs + run.n_rhs
        estimates.append(run.error_estimate)
        compiled = compiled and run.compiled
        stopped = run.t_events[0].size > 0  # (then the run ends at the impact)
        te = float(run.t_events[0][0]) if stopped else math.inf
        on_grid = (run.t >= t[k]) & (run.t < te)
        X[:, k:k + int(on_grid.sum())] = np.asarray(run.x)[:, on_grid]
        k += int(on_grid.sum())
        if not stopped or run.status != TERMINAL_EVENT:  # the end, or a failure
            last = run
            break
        x_minus = np.asarray(run.x[:, -1], dtype=float)
        u_te = controls_at(control, t, np.array([te]), model.nu)[:, 0]
        x_plus, info = _jumped(impact, te, x_minus, u_te, p, nx)
        rate = _guard_rate(impact, model, te, x_plus, u_te, p)
        records.append(ImpactRecord(te, x_minus, x_plus, rate,
                                    float(getattr(info, "normal_impulse", math.nan)), info))
        if k < t.size and t[k] == te:
            X[:, k] = x_plus
            k += 1
        if rate <= impact.rest_speed or len(records) >= impact.max_impacts or k >= t.size:
            if k < t.size:
                why = (f"max_impacts = {impact.max_impacts} reached" if rate > impact.rest_speed
                       else f"the contact came to rest (rebound speed {rate:.6g} <= rest_speed "
                       f"{impact.rest_speed:g})" if rate >= 0
                       else f"the contact does not separate after the jump (guard rate "
                       f"{rate:.6g} < 0)")
                stop_message = (f"stopped at impact {len(records)} ({impact.name}) at t = "
                                f"{te:.15g} s: {why}")
                end = (te, x_plus)
            last = run
            break
        t_start, x_start = te, x_plus
    return _joined(model, t, X, k, end, last, records, stop_message, control, p, invariants,
                   n_steps, n_rhs, estimates, compiled, time.perf_counter() - start)


def _joined(model, t, X, k, end, last, records, stop_message, control, p, names, n_steps,
            n_rhs, estimates, compiled, wall) -> SimulationResult:
    """The result of the joined runs (``X`` filled up to column ``k``; ``end``: the stop)."""
    if end is not None:
        t_out = np.append(t[:k], end[0])
        x_out = np.concatenate([X[:, :k], end[1][:, None]], axis=1)
    else:
        t_out, x_out = t, X
    success, status, message = last.success, last.status, last.message
    if status == TERMINAL_EVENT:  # the last run ended at an impact
        success, status = True, (OK if end is None else TERMINAL_EVENT)
        message = stop_message or "impact at the last output time"
    message += f"; {len(records)} impact(s)"
    for a in (t_out, x_out):
        a.setflags(write=False)
    values = {}
    for name in names:
        value = np.asarray(model.invariant(name, x_out, p))
        value.setflags(write=False)
        values[name] = value
    finite = [e for e in estimates if not math.isnan(e)]
    return make_result(
        t=t_out, x=x_out, success=bool(success), status=status, message=message,
        method=last.method, wall_time=wall, n_steps=n_steps, n_rhs=n_rhs,
        substeps=last.substeps, error_estimate=max(finite) if finite else math.nan,
        compiled=compiled, invariants=MappingProxyType(values),
        _dense=Dense(model, p, lambda: controls_at(control, t, t_out, model.nu)),
        t_events=None, x_events=None, impacts=tuple(records))
