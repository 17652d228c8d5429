"""Event detection for `simulate` (``events=``): zero crossings of ``g(t, x, u, p)`` located
on the solution to the integrator's accuracy, reported as scipy's ``solve_ivp`` does.

An event function is a callable or a CasADi Function ``g(t, x, u, p) -> scalar`` with
scipy's attributes ``terminal`` (bool, or the number of occurrences after which the solution
stops) and ``direction`` (``0`` every crossing, ``+1`` from negative to positive, ``-1``
from positive to negative); `Event` attaches them to a Function, which cannot carry
attributes.

What is detected
----------------
The sign of ``g`` is looked at on a scan of the solution finer than the output grid, in
blocks of about 4096 points (a terminal event ends the scan at its block):

* ``rk4``, ``rk8``, ``lie``: at every step (``steps`` per output interval), the answer's
  own steps, re-taken from the answer at the start of each block (with one step per
  interval the answer itself is scanned: nothing is re-run);
* ``auto`` with rk8: at ``min(substeps, SUBGRID)`` equal parts of every output interval,
  with rk8 steps between them no longer than the answer's (``substeps`` of the result:
  after the one-pass path the most it took in any interval), re-integrated from the answer
  at the start of each block; ``auto`` through cvodes as ``cvodes`` below at 1e-3 of the
  asked tolerances (those of its accepted run or looser);
* ``cvodes``: at ``min(ceil(n_steps / (n - 1)), SUBGRID)`` equal parts of every output
  interval, integrated by cvodes at the same tolerances from the answer at the start of each
  block.

The answer's states are used at the output points. A change of sign between two
neighbouring points (upwards ``g < 0`` then ``g >= 0``, downwards ``g > 0`` then ``g <= 0``;
a zero at ``t[0]`` is no event) is then located by Brent's method (scipy's ``brentq``, to
a few ulps of ``t``) on the solution itself: the state at a trial time is integrated from
the point before by the same method at the same accuracy (fixed step: equal steps no
longer than the scan's, one step between neighbouring points of a scan on every step;
cvodes: a run at the same tolerances), never an interpolant of the output grid. A crossing
and re-crossing between two neighbouring points, or a zero that only touches, is not seen
(as with scipy, whose points are its own steps).

Cost: a Function ``g`` is evaluated mapped over a block; a Python callable once a point.
``auto`` and cvodes pay about one more run for the scan, plus a few short runs a located
event (Brent takes 5-10 trial times on smooth problems).

The solution is integrated over the whole grid first; a terminal event then truncates it:
``t`` ends at the event time (the output times before it, then the event time), ``status``
is `TERMINAL_EVENT` and ``success`` True. Events are looked for only up to the last output
time before a failure (a non-finite state). A run of a fixed-step method or cvodes that
failed after a terminal event is that success too (e.g. a stop before a singularity);
``auto``'s is not (its error control covers the whole grid and did not succeed: the
result keeps ``success=False`` and its status, truncated at the event; simulate again on a
grid that ends near the event).
"""
from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass
from types import MappingProxyType

import casadi as ca
import numpy as np

from .. import cache
from ..model import Model
from .cvodes import ControlCallback, integrator_options, run_cvodes
from .evaluate import call_buffered, map_eval
from .inputs import Control, Problem
from .loops import run_fixed
from .result import (FAILED, OK, OK_STIFF, TERMINAL_EVENT, Dense, SimulationResult, make_result,
                     result_fields)
from .stepcontrol import LOCAL_RTOL_MIN, run_stepped, run_stepped_callable
from .tableaux import TABLEAUX

__all__ = ["Event", "EventSpec", "SUBGRID", "scan_times", "check_events", "controls_at",
           "apply_events"]

#: Most scan points per output interval of ``auto`` and ``cvodes`` (fixed-step methods are
#: scanned at every step).
SUBGRID = 64

#: Local tolerances of the event scan of ``auto``'s step-controlled runs (non-smooth
#: right-hand sides), relative to the asked ones: those of its second run (`stepcontrol`:
#: ``_FIRST * _TIGHTEN``), the tighter of the two that verify the least-refined answers.
_STEPPED_TIGHTEN = 1e-3
#: Most steps of one such run (a hop or a block of the scan).
_STEPPED_MAX = 10_000_000

#: Internal points per block of the scan (bounds the memory of a long run's scan; a
#: terminal event ends the scan at its block).
_BLOCK_POINTS = 4096

#: ``auto`` through cvodes: the event scan's tolerances relative to the asked ones (the
#: accepted run of `auto._auto_cvodes` is at 1e-3 of them or tighter).
_AUTO_CVODES_TIGHTEN = 1e-3

_EPS = np.finfo(float).eps


class Event:
    """An event function with scipy's attributes, for a CasADi Function (which cannot carry
    attributes) or any callable.

    Parameters
    ----------
    fun : casadi.Function or callable
        ``g(t, x, u, p) -> scalar``: ``t`` [s] a float, ``x (nx,)``, ``u (nu,)``, ``p (np,)``
        (a Function: four inputs of these sizes and one scalar output).
    terminal : bool or int, optional
        ``False``/``0``: only record; ``True``: stop the solution at the first occurrence;
        an integer ``k >= 1``: at the ``k``-th.
    direction : float, optional
        ``0`` every crossing; ``> 0`` only from negative to positive; ``< 0`` only from
        positive to negative.
    name : str, optional
        Named in the result's message (default the Function's name or the callable's
        ``__name__``).

    Examples
    --------
    >>> import casadi as ca
    >>> import numpy as np
    >>> from appdyn.dynamics import Event, Model, simulate
    >>> x, u, p, t = ca.SX.sym("x", 2), ca.SX.sym("u", 0), ca.SX.sym("p", 0), ca.SX.sym("t")
    >>> fall = Model(f=ca.Function("fall", [x, u, p], [ca.vertcat(x[1], -9.81)],
    ...                            ["x", "u", "p"], ["xdot"]), states=("h", "v"), controls=())
    >>> ground = Event(ca.Function("ground", [t, x, u, p], [x[0]]), terminal=True, direction=-1)
    >>> res = simulate(fall, [10.0, 0.0], np.linspace(0.0, 5.0, 6), events=ground)
    >>> res.status, bool(abs(res.t[-1] - np.sqrt(2 * 10.0 / 9.81)) < 1e-12)
    (6, True)
    """

    def __init__(self, fun, terminal: bool | int = False, direction: float = 0.0,
                 name: str | None = None):
        self.fun = fun
        self.terminal = terminal
        self.direction = direction
        self.name = name
        _occurrences(terminal, "`Event` `terminal`")
        _direction(direction, "`Event` `direction`")

    def __call__(self, t, x, u, p) -> float:
        """``g(t, x, u, p)`` as a float."""
        value = self.fun(t, x, u, p)
        return float(np.asarray(value, dtype=float).reshape(-1)[0])

    def __repr__(self) -> str:
        return (f"Event({self.name or _name_of(self.fun, 'g')!r}, terminal={self.terminal!r}, "
                f"direction={self.direction!r})")


@dataclass(frozen=True)
class EventSpec:
    """One checked event function: ``fun`` (a Function when ``function``), ``count`` the
    occurrences that stop the solution (0: never), ``direction`` in {-1, 0, 1}, ``name``,
    ``label`` (``events[i]``, for messages)."""

    fun: object
    function: bool
    count: int
    direction: int
    name: str
    label: str


def _occurrences(terminal, what: str) -> int:
    """``terminal`` as a count of occurrences (0: not terminal)."""
    if isinstance(terminal, (bool, np.bool_)):
        return int(terminal)
    if isinstance(terminal, (int, np.integer)) and terminal >= 0:
        return int(terminal)
    raise ValueError(f"{what} must be a bool or an integer >= 0 (occurrences before the "
                     f"solution stops), got {terminal!r}")


def _direction(direction, what: str) -> int:
    """``direction`` as its sign."""
    try:
        value = float(direction)
    except (TypeError, ValueError):
        value = math.nan
    if not math.isfinite(value) or isinstance(direction, (bool, np.bool_, str, bytes)):
        raise ValueError(f"{what} must be a finite number (0, > 0 or < 0), got {direction!r}")
    return int(np.sign(value))


def _name_of(fun, default: str) -> str:
    if isinstance(fun, ca.Function):
        return fun.name()
    return getattr(fun, "__name__", default)


def check_events(events, model: Model, t: np.ndarray, x0: np.ndarray, control: Control | None,
                 p: np.ndarray) -> tuple[EventSpec, ...]:
    """``events`` of `simulate` checked: a callable, a CasADi Function or an `Event`, or a
    sequence of them; each evaluated once at ``(t[0], x0)``.

    Returns
    -------
    tuple of EventSpec

    Raises
    ------
    TypeError
        ``events`` (or an item of it) is neither callable nor a sequence of callables.
    ValueError
        A Function without the inputs ``(t (1), x (nx), u (nu), p (np))`` and one scalar
        output; a ``terminal`` or ``direction`` of the wrong kind; a value at ``t[0]``
        that is not one finite number.
    """
    if callable(events) or isinstance(events, Event):
        items = [events]
    elif isinstance(events, (str, bytes)):
        items = None
    else:
        try:
            items = list(events)
        except TypeError:
            items = None
    if items is None:
        raise TypeError("`events` must be a callable g(t, x, u, p), a casadi Function, an "
                        f"Event or a sequence of them, got {type(events).__name__}")
    u0 = controls_at(control, t, t[:1], model.nu)[:, 0]
    specs = tuple(_spec(item, f"events[{i}]", model) for i, item in enumerate(items))
    for spec in specs:
        value = _value(spec, float(t[0]), x0, u0, p)
        if not math.isfinite(value):
            raise ValueError(f"`{spec.label}` ({spec.name}) must return a finite number, "
                             f"got {value} at t = {t[0]}")
    return specs


def _spec(item, label: str, model: Model) -> EventSpec:
    fun = item.fun if isinstance(item, Event) else item
    if isinstance(fun, ca.Function):
        sizes = tuple(fun.numel_in(i) for i in range(fun.n_in()))
        outs = tuple(fun.numel_out(i) for i in range(fun.n_out()))
        want = (1, model.nx, model.nu, model.np)
        if sizes != want or outs != (1,):
            raise ValueError(
                f"`{label}` must be a Function (t, x, u, p) -> g with input sizes {want} and "
                f"one scalar output; {fun.name()!r} has input sizes {sizes} and output sizes "
                f"{outs}")
    elif not callable(fun):
        raise TypeError(f"`{label}` must be a callable g(t, x, u, p), a casadi Function or an "
                        f"Event, got {type(fun).__name__}")
    count = _occurrences(getattr(item, "terminal", False), f"`{label}.terminal`")
    direction = _direction(getattr(item, "direction", 0), f"`{label}.direction`")
    name = (item.name if isinstance(item, Event) else None) or _name_of(fun, label)
    return EventSpec(fun, isinstance(fun, ca.Function), count, direction, name, label)


def _value(spec: EventSpec, t: float, x: np.ndarray, u: np.ndarray, p: np.ndarray) -> float:
    """``g(t, x, u, p)`` as a float; ValueError naming the event when it is not a scalar."""
    if spec.function:
        return float(call_buffered(spec.fun, [np.array([t]), x, u, p], (1,))[0])
    value = np.asarray(spec.fun(t, x.copy(), u.copy(), p.copy()), dtype=float)
    if value.size != 1:
        raise ValueError(f"`{spec.label}` ({spec.name}) must return a scalar, got shape "
                         f"{value.shape} at t = {t}")
    return float(value.reshape(()))


def _values(spec: EventSpec, ts: np.ndarray, X: np.ndarray, U: np.ndarray,
            p: np.ndarray) -> np.ndarray:
    """``g`` at the points ``ts (N,)``, ``X (nx, N)``, ``U (nu, N)``: shape (N,) (a Function
    mapped over the points, a callable called at each)."""
    if spec.function:
        return map_eval(spec.fun, [ts[None, :], X, U, p])[0]
    return np.array([_value(spec, float(ts[j]), X[:, j], U[:, j], p) for j in range(ts.size)])


def controls_at(control: Control | None, t: np.ndarray, ts: np.ndarray, nu: int,
                *, side: str = "right") -> np.ndarray:
    """The control of `simulate` (``None``: zero) at the times ``ts (N,)`` within the grid
    ``t``: shape (nu, N), linear between samples (or held: ``hold='zoh'``) or the callable's
    values. At a grid time, ``side='right'`` gives the value from that time on, ``'left'``
    the limit from before (they differ where a held control jumps)."""
    if control is None:
        return np.zeros((nu, ts.size))
    if control.mode == "stages":
        return np.stack([control.fun(float(tj)) for tj in ts], axis=1).reshape(nu, ts.size)
    k = np.clip(np.searchsorted(t, ts, side=side) - 1, 0, t.size - 2)
    w = ((ts - t[k]) / (t[k + 1] - t[k]))[:, None]
    return (control.ua[k] + w * (control.ub[k] - control.ua[k])).T


# ----------------------------------------------------------------- solutions between points
class _FixedSteps:
    """The solution of a fixed-step method between the output points: ``per`` scan points
    per output interval, ``r`` steps of the method between neighbouring points (``per r``
    at least the answer's steps per interval), and from any point a run of steps no longer
    than those to any later time."""

    def __init__(self, problem: Problem, method: str, per: int, r: int, jit: bool):
        self.problem, self.method, self.r, self.jit = problem, method, r, jit
        self.per_interval = per
        self.n_steps = 0
        self.stages = 4 if method == "lie" else TABLEAUX[method].stages

    def points(self, i0: int, i1: int, x: np.ndarray, carry: np.ndarray):
        """Times (N,) and states (nx, N) of the scan points ``i0 .. i1`` (point ``i``:
        ``i mod per`` of output interval ``i // per``), integrated from the answer ``x``
        (nx, n) when ``i0`` is an output point, else from ``carry`` (the state at point
        ``i0``); the answer is kept at the output points."""
        t, per = self.problem.t, self.per_interval
        ts, outputs = scan_times(t, per, i0, i1)
        if per == 1 and self.r == 1:
            return ts, x[:, i0:i1 + 1]
        start = x[:, i0 // per] if i0 % per == 0 else carry
        run = run_fixed(on_grid(self.problem, ts, start), self.method, self.r, self.jit)
        self.n_steps += run.n_steps
        return ts, _with_outputs(run.x, x, i0, per, outputs)

    def hop(self, xa: np.ndarray, ta: float, tb: float) -> np.ndarray:
        """The state at ``tb`` from ``(ta, xa)``: the fewest equal steps of the method no
        longer than the scan's steps in that output interval (one, between neighbouring
        points of a scan on the answer's own steps)."""
        problem, t = self.problem, self.problem.t
        k = min(max(int(np.searchsorted(t, ta, side="right")) - 1, 0), t.size - 2)
        h = (t[k + 1] - t[k]) / (self.per_interval * self.r)
        n = max(1, math.ceil((tb - ta) / h * (1 - 1e-12)))
        run = run_fixed(on_grid(problem, np.array([ta, tb]), xa), self.method, n, self.jit)
        self.n_steps += run.n_steps
        return run.x[:, 1]

    @property
    def n_rhs(self) -> int:
        return self.stages * self.n_steps


def on_grid(problem: Problem, ts: np.ndarray, x0: np.ndarray) -> Problem:
    """``problem`` from ``x0`` on the grid ``ts`` (increasing, within ``problem.t``), with
    the same control (samples: the same piecewise-linear function, sampled on ``ts``)."""
    ctrl, t, nu = problem.control, problem.t, problem.model.nu
    if ctrl.mode == "linear":  # each piece from the value at its start to the limit at its end
        ctrl = Control("linear", controls_at(ctrl, t, ts[:-1], nu).T,
                       controls_at(ctrl, t, ts[1:], nu, side="left").T, constant=ctrl.constant)
    return Problem.new(problem.model, x0, ts, ctrl, problem.p)


def _with_outputs(X: np.ndarray, x: np.ndarray, i0: int, per: int,
                  outputs: np.ndarray) -> np.ndarray:
    """The scan's states ``X`` (a copy) with the answer ``x`` at the output points
    (``outputs``: their positions in a block starting at scan point ``i0``)."""
    X = np.array(X)
    X[:, outputs] = x[:, (i0 + outputs) // per]
    return X


def scan_times(t: np.ndarray, per: int, i0: int, i1: int) -> tuple[np.ndarray, np.ndarray]:
    """Scan points ``i0 .. i1`` of ``per`` equal parts of every interval of the grid ``t``:
    their times (N,) (the grid's own at its points) and the positions of the grid points
    among them."""
    i = np.arange(i0, i1 + 1)
    k = np.minimum(i // per, t.size - 2)
    ts = t[k] + (i - k * per) * ((t[k + 1] - t[k]) / per)
    outputs = np.flatnonzero(i % per == 0)
    ts[outputs] = t[(i0 + outputs) // per]
    return ts, outputs


class _CvodesSteps:
    """The solution of cvodes between the output points: ``sub`` scan points per output
    interval (one cvodes run over a block of them from the answer at its start), and from
    any point a cvodes run to any later time (time scaled to ``[0, 1]``: one integrator for
    every such hop), both at the same tolerances."""

    def __init__(self, problem: Problem, rtol, atol, extra, sub: int):
        self.problem, self.sub = problem, sub
        self.rtol, self.atol, self.extra = rtol, atol, extra
        self.per_interval = sub  # points per output interval
        self.opts = integrator_options(rtol, atol, extra)
        self.n_steps = self.n_rhs = 0
        self.callback = self.own = None  # a callable control: this call's own integrator
        if problem.control.mode == "stages":
            with cache.construction_lock():
                self.callback = ControlCallback(problem.control.fun, problem.model.nu)

    def points(self, i0: int, i1: int, x: np.ndarray, carry: np.ndarray):
        """As `_FixedSteps.points`, for ``i0`` an output point."""
        ts, outputs = scan_times(self.problem.t, self.sub, i0, i1)
        if self.sub == 1:
            return ts, x[:, i0:i1 + 1]
        run = run_cvodes(on_grid(self.problem, ts, x[:, i0 // self.sub]), self.rtol, self.atol,
                         self.extra, pooled=False)
        self.n_steps += run.n_steps
        self.n_rhs += run.n_rhs
        return ts, _with_outputs(run.x, x, i0, self.sub, outputs)

    def hop(self, xa: np.ndarray, ta: float, tb: float) -> np.ndarray:
        """The state at ``tb`` from ``(ta, xa)`` (NaN when cvodes fails)."""
        problem = self.problem
        model, ctrl, t = problem.model, problem.control, problem.t
        params = [problem.p, [ta, tb - ta]]
        if ctrl.mode == "linear":
            k = min(max(int(np.searchsorted(t, ta, side="right")) - 1, 0), t.size - 2)
            params += [ctrl.ua[k], (ctrl.ub[k] - ctrl.ua[k]) / (t[k + 1] - t[k]), [t[k]]]
        P = np.concatenate([np.asarray(v, dtype=float).reshape(-1) for v in params])
        if self.callback is None:
            key = ("event-cvodes", cache.function_key(model.f),
                   repr(sorted(self.opts.items(), key=str)))
            with cache.checkout(key, lambda: _scaled_integrator(model, self.opts),
                                keepalive=model.f) as integ:
                return self._call(integ, xa, P)
        if self.own is None:
            self.own = _scaled_integrator(model, self.opts, self.callback)
        return self._call(self.own, xa, P)

    def _call(self, integ, xa, P) -> np.ndarray:
        try:
            out = np.asarray(integ(x0=xa, p=P)["xf"], dtype=float).reshape(-1)
        except RuntimeError:
            if self.callback is not None and self.callback.error is not None:
                raise self.callback.error from None
            out = np.full(xa.size, np.nan)
        stats = integ.stats()
        self.n_steps += int(stats.get("nsteps", 0))
        self.n_rhs += int(stats.get("nfevals", 0))
        return out


class _SteppedSteps:
    """The solution of a step-controlled DOP853 run (``method='dop853'``, or ``auto`` on a
    non-smooth right-hand side: `dynamics.integrate.stepcontrol`) between the output points: ``sub`` scan points per
    output interval (one DOP853 run with step rejection over a block of them from the answer
    at its start), and from any point such a run to any later time, both at the local
    tolerances ``rtol``, ``atol`` (for ``auto``: tighter than those of the answer's runs)."""

    def __init__(self, problem: Problem, rtol, atol, sub: int):
        self.problem, self.sub, self.per_interval = problem, sub, sub
        self.rtol, self.atol = rtol, atol
        self.n_steps = self.n_rhs = 0
        self.stepped = run_stepped_callable if problem.control.mode == "stages" else run_stepped

    def _run(self, problem: Problem) -> np.ndarray:
        got = self.stepped(problem, self.rtol, self.atol, _STEPPED_MAX)
        if got is None:  # (no compiled stepper: the same controller from Python)
            got = run_stepped_callable(problem, self.rtol, self.atol, _STEPPED_MAX)
        run = got[0]
        self.n_steps += run.n_steps
        self.n_rhs += run.n_rhs
        return run.x  # NaN from a failure on

    def points(self, i0: int, i1: int, x: np.ndarray, carry: np.ndarray):
        """As `_FixedSteps.points`, for ``i0`` an output point."""
        ts, outputs = scan_times(self.problem.t, self.sub, i0, i1)
        if self.sub == 1:
            return ts, x[:, i0:i1 + 1]
        X = self._run(on_grid(self.problem, ts, x[:, i0 // self.sub]))
        return ts, _with_outputs(X, x, i0, self.sub, outputs)

    def hop(self, xa: np.ndarray, ta: float, tb: float) -> np.ndarray:
        """The state at ``tb`` from ``(ta, xa)`` (NaN when the run fails)."""
        return self._run(on_grid(self.problem, np.array([ta, tb]), xa))[:, 1]


def _scaled_integrator(model: Model, opts: dict, callback=None):
    """cvodes on ``dx/ds = h f(x, u(ta + s h), p)`` from ``s = 0`` to 1; its ``p`` is
    ``[p, ta, h]`` and, for a linear control, the control at the interval's start ``ua``,
    its slope ``ud`` and the start ``tk``."""
    with cache.construction_lock():
        sym = ca.SX if callback is None else ca.MX
        x, s = sym.sym("x", model.nx), sym.sym("s")
        p, ta, h = sym.sym("p", model.np), sym.sym("ta"), sym.sym("h")
        tau = ta + s * h
        extra = []
        if callback is None:
            ua, ud, tk = sym.sym("ua", model.nu), sym.sym("ud", model.nu), sym.sym("tk")
            u, extra = ua + (tau - tk) * ud, [ua, ud, tk]
        else:
            u = callback(tau)
        ode = h * model.f.call([x, u, p])[0]
        dae = {"x": x, "t": s, "p": ca.vertcat(p, ta, h, *extra), "ode": ode}
        return ca.integrator("event_cvodes", "cvodes", dae, 0.0, [1.0], opts)


def _stepper(result: SimulationResult, problem: Problem, method: str, rtol, atol, extra,
             jit: bool):
    """The solution between the output points for the method that made ``result``."""
    nint = problem.t.size - 1
    if result.method == "cvodes":
        if method == "auto":
            rtol, atol = max(rtol * _AUTO_CVODES_TIGHTEN, 100 * _EPS), atol * _AUTO_CVODES_TIGHTEN
        sub = min(SUBGRID, max(1, math.ceil(result.n_steps / nint)))
        return _CvodesSteps(problem, rtol, atol, extra, sub)
    if result.method == "dop853":  # method='dop853', or auto on a non-smooth right-hand side
        steps_per = math.ceil(result.n_steps / nint)
        tighten = 1.0 if method == "dop853" else _STEPPED_TIGHTEN  # (auto's: its runs' tol)
        return _SteppedSteps(problem, max(rtol * tighten, LOCAL_RTOL_MIN), atol * tighten,
                             min(SUBGRID, max(1, steps_per)))
    m = max(1, result.substeps)
    if method != "auto":
        return _FixedSteps(problem, result.method, m, 1, jit)  # every step
    r = math.ceil(m / SUBGRID)
    return _FixedSteps(problem, "rk8", math.ceil(m / r), r, jit)


# ------------------------------------------------------------------------------ the scan
def _sign_changes(g: np.ndarray, direction: int) -> np.ndarray:
    """Indices ``j`` where ``g`` changes sign from point ``j`` to ``j + 1`` in ``direction``."""
    a, b = g[:-1], g[1:]
    up, down = (a < 0) & (b >= 0), (a > 0) & (b <= 0)
    return np.flatnonzero(up if direction > 0 else down if direction < 0 else up | down)


def _locate(spec: EventSpec, stepper, problem: Problem, ta: float, tb: float, ga: float,
            gb: float, xa: np.ndarray, xb: np.ndarray):
    """The event time in ``(ta, tb]`` (``ga``, ``gb`` of opposite signs or ``gb = 0``) and
    the state there, by Brent's method on the solution from ``(ta, xa)``."""
    if gb == 0.0:
        return tb, xb
    nu, p = problem.model.nu, problem.p

    def g(tau: float) -> float:
        if tau == ta:
            return ga
        if tau == tb:
            return gb
        x = stepper.hop(xa, ta, tau)
        value = _value(spec, tau, x, controls_at(problem.control, problem.t,
                                                  np.array([tau]), nu)[:, 0], p)
        if not math.isfinite(value):
            raise _LocationFailed(f"`{spec.label}` ({spec.name}) is not finite at t = {tau:.15g}"
                                  " on the solution between the points")
        return value

    from scipy.optimize import brentq  # only when an event is located (a heavy import)

    try:
        te = brentq(g, ta, tb, xtol=4 * _EPS * max(abs(ta), abs(tb)) + 1e-300, rtol=4 * _EPS,
                    maxiter=200)
    except RuntimeError as exc:  # (not converged)
        raise _LocationFailed(f"`{spec.label}` ({spec.name}): {exc}") from None
    return te, (xb if te == tb else stepper.hop(xa, ta, te))


class _LocationFailed(Exception):
    """The solution between two points could not be evaluated (a numerical failure)."""


@dataclass
class _Found:
    times: list            # per event function, the occurrence times
    states: list           # per event function, the states
    stop: tuple | None = None  # (event index, time, state) of the terminal occurrence
    failure: str = ""


def _scan(specs, stepper, problem: Problem, x: np.ndarray) -> _Found:
    """Every occurrence of every event on the answer ``x`` (nx, n) up to its last finite
    column, in time order, until a terminal one."""
    found = _Found([[] for _ in specs], [[] for _ in specs])
    finite = np.isfinite(x).all(axis=0)
    last = x.shape[1] - 1 if finite.all() else int(np.argmin(finite)) - 1
    per = stepper.per_interval
    block = per * (_BLOCK_POINTS // per) if per <= _BLOCK_POINTS else _BLOCK_POINTS
    counts = [0] * len(specs)
    carry = x[:, 0]
    for i0 in range(0, last * per, block):
        ts, X = stepper.points(i0, min(last * per, i0 + block), x, carry)
        carry = X[:, -1]
        U = controls_at(problem.control, problem.t, ts, problem.model.nu)
        G = [_values(spec, ts, X, U, problem.p) for spec in specs]
        hits = sorted((j, i) for i, spec in enumerate(specs)
                      for j in _sign_changes(G[i], spec.direction))
        for j, group in itertools.groupby(hits, key=lambda hit: hit[0]):
            try:  # every crossing between points j and j + 1, then in time order
                located = sorted(
                    [_locate(specs[i], stepper, problem, float(ts[j]), float(ts[j + 1]),
                             float(G[i][j]), float(G[i][j + 1]), X[:, j], X[:, j + 1]) + (i,)
                     for _, i in group], key=lambda item: (item[0], item[2]))
            except _LocationFailed as exc:
                found.failure = str(exc)
                return found
            for te, xe, i in located:
                found.times[i].append(te)
                found.states[i].append(xe)
                counts[i] += 1
                if counts[i] == specs[i].count:
                    found.stop = (i, te, xe)
                    return found
    return found


# ------------------------------------------------------------------------------- result
def apply_events(result: SimulationResult, specs: tuple[EventSpec, ...], problem: Problem,
                 method: str, rtol: float, atol: np.ndarray, cvodes_options: dict,
                 jit: bool) -> SimulationResult:
    """``result`` of `simulate` with the occurrences of ``specs`` (``t_events``,
    ``x_events``), truncated at a terminal one (``status`` `TERMINAL_EVENT`).

    ``problem``: the simulated problem; ``method`` the one asked for (``result.method`` the
    one used); ``jit`` whether fixed-step runs compile.
    """
    start = time.perf_counter()
    stepper = _stepper(result, problem, method, rtol, atol, cvodes_options, jit)
    found = _scan(specs, stepper, problem, np.asarray(result.x))
    nx = problem.model.nx
    t_events = [_frozen(np.array(times, dtype=float)) for times in found.times]
    x_events = [_frozen(np.array(states, dtype=float).reshape(len(states), nx))
                for states in found.states]
    values = dict(result_fields(result), t_events=t_events, x_events=x_events,
                  n_steps=result.n_steps + stepper.n_steps, n_rhs=result.n_rhs + stepper.n_rhs)
    if found.failure:
        values.update(success=False, status=FAILED,
                      message=f"{result.message}; event location failed: {found.failure} "
                              "(a numerical failure of the solution; try a tighter tolerance "
                              "or another method)")
    elif found.stop is not None:
        values.update(_truncated(result, specs, found.stop, problem, method))
    values["wall_time"] = result.wall_time + time.perf_counter() - start
    return make_result(**values)


def _truncated(result: SimulationResult, specs, stop: tuple, problem: Problem,
               method: str) -> dict:
    """The fields of ``result`` that change when the terminal occurrence ``stop`` ends it."""
    i, te, xe = stop
    t = problem.t
    kk = int(np.searchsorted(t, te, side="left"))  # t[:kk] < te
    t_new = _frozen(np.append(t[:kk], te))
    x_new = _frozen(np.concatenate([result.x[:, :kk], np.asarray(xe)[:, None]], axis=1))
    model, p, control = problem.model, problem.p, problem.control
    invariants = {name: _frozen(np.asarray(model.invariant(name, x_new, p)))
                  for name in result.invariants}
    # a failure after the event is past the returned solution; auto's unverified or failed
    # error control is not
    verified = result.status in (OK, OK_STIFF) or (result.status == FAILED and method != "auto")
    spec = specs[i]
    what = (f"terminal event {i} ({spec.name}) at t = {te:.15g} s"
            + (f" (occurrence {spec.count})" if spec.count > 1 else ""))
    if not verified:
        message = f"{result.message}; the solution was stopped by {what}"
    elif result.status == FAILED:
        message = (f"stopped by {what}; {result.message} (past the event: not part of the "
                   "returned solution)")
    else:
        message = f"stopped by {what}; {result.message}"
    out = dict(t=t_new, x=x_new, invariants=MappingProxyType(invariants), message=message,
               _dense=Dense(model, p, lambda: controls_at(control, t, t_new, model.nu)))
    if verified:
        out.update(success=True, status=TERMINAL_EVENT)
    return out


def _frozen(a: np.ndarray) -> np.ndarray:
    a.setflags(write=False)
    return a
