"""`SimulationResult` (the public outcome of `simulate`), its dense output, and `Run`
(the outcome of one integration run inside a call)."""
from __future__ import annotations

import math
import threading
from dataclasses import dataclass, field, fields
from types import MappingProxyType
from typing import Callable, Mapping

import numpy as np

from ..figures import plot_signals
from ..model import Model
from ..results import Result
from ..serialize import text_table
from .evaluate import map_eval

__all__ = ["SimulationResult", "make_result", "result_fields", "new_result", "Dense", "Run", "OK",
           "OK_STIFF", "ROUNDOFF", "UNVERIFIED", "VIOLATED", "NONSMOOTH", "FAILED",
           "TERMINAL_EVENT"]

# status codes of SimulationResult (documented in its docstring)
OK, OK_STIFF, ROUNDOFF, UNVERIFIED, VIOLATED, NONSMOOTH, FAILED = 0, 1, 2, 3, 4, 5, -1
TERMINAL_EVENT = 6  # a terminal event stopped the solution (`simulate(events=...)`)


class Dense:
    """What `SimulationResult.sample` needs: the model, ``p`` and ``u`` on the grid; caches xdot.

    ``u_grid`` is the control on the output grid, shape (nu, n), or a callable returning it
    (evaluated on first use); ``u_left`` its left limits there, shape (nu, n), when they
    differ (a zero-order hold jumps at the grid times): the dense output then takes the
    derivative at an interval's end from them. Pickling stores the evaluated array, never the callable, and
    leaves the lock out (a new one is made on load).
    """

    def __init__(self, model: Model, p: np.ndarray,
                 u_grid: Callable[[], np.ndarray] | np.ndarray, u_left: np.ndarray | None = None):
        self._model, self._p = model, p
        self._u_grid = u_grid if callable(u_grid) else None
        self._u = None if callable(u_grid) else np.asarray(u_grid, dtype=float)
        self._u_left = u_left  # (nu, n) left limits of a control that jumps on the grid
        self._xdot = None
        self._xdot_left = None
        self._drift = None
        self._lock = threading.Lock()

    @property
    def model(self) -> Model:
        return self._model

    def _controls(self) -> np.ndarray:
        # the caller holds self._lock
        if self._u is None:
            self._u = np.asarray(self._u_grid(), dtype=float)
            self._u_grid = None
        return self._u

    def drift(self, x: np.ndarray) -> Mapping[str, float]:
        with self._lock:
            if self._drift is None:
                self._drift = MappingProxyType(_drift(self._model, x, self._p))
            return self._drift

    def xdot(self, x: np.ndarray) -> np.ndarray:
        with self._lock:
            if self._xdot is None:
                xdot = map_eval(self._model.f, [x, self._controls(), self._p])
                xdot.setflags(write=False)
                self._xdot = xdot
            return self._xdot

    def xdot_left(self, x: np.ndarray) -> np.ndarray:
        """The state derivative's left limits at the grid times (`xdot` where the control
        does not jump)."""
        if self._u_left is None:
            return self.xdot(x)
        with self._lock:
            if self._xdot_left is None:
                xdot = map_eval(self._model.f, [x, self._u_left, self._p])
                xdot.setflags(write=False)
                self._xdot_left = xdot
            return self._xdot_left

    def __getstate__(self) -> dict:
        with self._lock:
            return {"model": self._model, "p": self._p, "u": self._controls(),
                    "u_left": self._u_left, "xdot": self._xdot,
                    "drift": None if self._drift is None else dict(self._drift)}

    def __setstate__(self, state: dict) -> None:
        self._model, self._p = state["model"], state["p"]
        self._u_grid, self._u = None, state["u"]
        self._u_left, self._xdot_left = state.get("u_left"), None
        self._xdot = state["xdot"]
        if self._xdot is not None:
            self._xdot.setflags(write=False)
        drift = state["drift"]
        self._drift = None if drift is None else MappingProxyType(drift)
        self._lock = threading.Lock()


@dataclass(frozen=True, eq=False, repr=False)
class SimulationResult(Result):
    """Outcome of `simulate`, in the manner of scipy's ``OdeResult``.

    Attributes
    ----------
    t : ndarray, shape (n,) [s]
        The output grid.
    x : ndarray, shape (nx, n)
        States at ``t`` (``x[:, 0]`` is ``x0``). After a failure the columns the integrator
        did not reach are NaN.
    success : bool
        True only when the answer was verified against what was asked: ``auto`` met the
        tolerance by its global error estimate (status 0 or 1); a fixed-step method reached
        ``t[-1]`` with finite states that keep the model's invariants sane (status 4
        otherwise), ``cvodes`` with finite states (they take no global tolerance; see
        ``invariant_drift`` for a measure of a fixed-step run's accuracy).
    status : int
        ``0`` success (``auto``: the estimated global error of the rk8 run is within
        tolerance); ``1`` success of ``auto`` on a stiff problem through cvodes, its global
        error estimated from runs at tightened local tolerances; ``2`` not verified: the
        tolerance lies below the round-off floor of fixed-step runs on this grid (more steps
        no longer reduce the differences between runs); ``3`` not verified: ``max_steps``
        or the run budget was reached first; ``4`` a fixed-step run (``rk4``, ``rk8``,
        ``lie``) whose invariants are grossly violated at an output time: the attitude
        quaternion's norm off 1 by more than 1e-3, or an invariant the flow conserves along
        the run (energy or momentum of a torque-free body) changed by more than its own size
        (`dynamics.integrate.sanity`; an ``rk4``/``rk8`` run of a model with an attitude
        is checked by the quaternion's norm, which those methods do not keep): the step is too large for the motion, ``x`` is not a
        solution (remedy: more ``steps`` or ``method='auto'``); ``5`` not verified: the
        right-hand side is non-smooth (kinks or jumps: ``fmin``/``fmax``/``if_else`` in the
        model, or a callable control) and the runs lost their order there, so the
        tolerance could not be verified (not a round-off floor; the message gives the
        remedy); ``6`` success, stopped by a terminal event (``events``): ``t`` ends at
        the event time; ``-1`` failure (integrator error, or a non-finite state). With 2 and 3 ``x`` is the finest run made and
        ``error_estimate`` says how far off it is thought to be.
    message : str
        What happened, in words.
    method : str
        The method that produced ``x`` (``auto`` reports ``rk8``, ``cvodes``, or
        ``dop853`` for DOP853 with step rejection on a non-smooth right-hand side).
    wall_time : float [s]
        Time spent in `simulate`, validation and any compilation included.
    n_steps, n_rhs : int
        Steps taken and right-hand-side evaluations made, summed over every run the call made
        (``auto`` makes several).
    substeps : int
        Fixed-step methods: steps per output interval of the returned solution (``auto``'s
        one-pass path: the most in any interval); a run with dense output (``auto`` or
        ``dop853`` under a constant control): the longest output interval over its smallest
        step, a bound the event search steps with, not a step count; 0 for cvodes.
    error_estimate : float
        ``auto``: estimated max over states and output times of ``|error| / (atol + rtol
        |x|)`` (1.0 is exactly the tolerance), for every path (rk8, cvodes on a stiff
        problem, dop853 on a non-smooth one); NaN for the other methods.
    compiled : bool
        Whether the loop that produced ``x`` ran as jit-compiled C.
    invariants : mapping of str to ndarray
        Each requested invariant along ``x``: shape ``(n,)`` for a scalar, ``(m, n)`` for a
        vector invariant. Empty unless asked for.
    t_events : list of ndarray, shape (k_i,) [s], or None
        With ``events``: for each event function, the times of its occurrences (as scipy's
        ``solve_ivp``); ``None`` without ``events``.
    x_events : list of ndarray, shape (k_i, nx), or None
        The states at those times (scipy's ``y_events``).
    impacts : tuple of ImpactRecord, or None
        With ``impacts``: every impact in time order (time, states before and after, rebound
        speed, impulse; `dynamics.integrate.impacts`); ``None`` without.
    """

    t: np.ndarray
    x: np.ndarray
    success: bool
    status: int
    message: str
    method: str
    wall_time: float
    n_steps: int
    n_rhs: int
    substeps: int = 0
    error_estimate: float = float("nan")
    compiled: bool = False
    invariants: Mapping[str, np.ndarray] = field(default_factory=dict)
    _dense: Dense | None = field(default=None, repr=False)
    t_events: list | None = None
    x_events: list | None = None
    impacts: tuple | None = None

    _repr_fields = ("method", "t", "x", "n_steps", "error_estimate")

    def __getattr__(self, name: str):
        # (reached only for an attribute not set: a ``message`` made on first use, from the
        # ``_message`` callable `new_result` was given; the first thread's text is kept)
        lazy = self.__dict__.get("_message") if name == "message" else None
        if lazy is None:
            raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")
        return self.__dict__.setdefault("message", lazy())

    def __getstate__(self) -> dict:
        state = result_fields(self)
        state["invariants"] = dict(self.invariants)
        return state

    def __setstate__(self, state: dict) -> None:
        state = dict(state)
        state["invariants"] = MappingProxyType(dict(state["invariants"]))
        for key in ("t", "x"):
            value = np.array(state[key])
            value.setflags(write=False)
            state[key] = value
        for key, value in state.items():
            object.__setattr__(self, key, value)

    @property
    def xdot(self) -> np.ndarray:
        """State derivative at ``t``, shape (nx, n); evaluated on first use."""
        if self._dense is None:
            raise ValueError("this result carries no model to evaluate xdot")
        return self._dense.xdot(self.x)

    @property
    def states(self) -> tuple:
        """Names of the state components (``x0, x1, ...`` without a model)."""
        if self._dense is None:
            return tuple(f"x{i}" for i in range(self.x.shape[0]))
        return tuple(self._dense.model.states)

    def __getitem__(self, name: str) -> np.ndarray:
        """The trajectory of state ``name`` at ``t``: the row of ``x``, shape (n,).

        Raises
        ------
        KeyError
            If ``name`` is not a state name (the message lists them).

        Examples
        --------
        >>> import numpy as np
        >>> from appdyn.dynamics import rigid_body, simulate
        >>> res = simulate(rigid_body([1.0, 2.0, 3.0]), [0, 0, 0, 1, 1.0, 0.0, 0.0],
        ...                np.linspace(0.0, 1.0, 3))
        >>> res["w1"]  # a pure spin about a principal axis stays put
        array([1., 1., 1.])
        """
        names = self.states
        if not isinstance(name, str) or name not in names:
            raise KeyError(f"no state named {name!r}; the states are {names}")
        return self.x[names.index(name)]

    def to_dict(self) -> dict:
        """Summary and trajectory as plain Python: counters, ``t``, ``x`` by state name,
        ``invariants`` (JSON-ready through `to_json`)."""
        return {
            "success": bool(self.success), "status": int(self.status), "message": self.message,
            "method": self.method, "wall_time": self.wall_time, "n_steps": int(self.n_steps),
            "n_rhs": int(self.n_rhs), "substeps": int(self.substeps),
            "error_estimate": self.error_estimate, "compiled": bool(self.compiled),
            "t": self.t, "x": dict(zip(self.states, self.x)),
            "invariants": dict(self.invariants),
            "t_events": self.t_events, "x_events": self.x_events,
            "impacts": None if self.impacts is None else [
                {"t": r.t, "x_before": r.x_before, "x_after": r.x_after,
                 "rebound_speed": r.rebound_speed, "normal_impulse": r.normal_impulse}
                for r in self.impacts],
        }

    def __str__(self) -> str:
        # (a dense-output run's ``substeps`` bounds its steps per interval for the event
        # search; its steps follow the error, so the report gives its step count alone)
        per = self.substeps and "dense output" not in self.message
        rows = [("success", f"{self.success} (status {self.status})"),
                ("method", f"{self.method}" + (f", {self.substeps} step(s) per interval"
                                               if per else "")),
                ("grid", f"{self.t.size} points, t = {self.t[0]:g} .. {self.t[-1]:g} s"),
                ("steps / rhs", f"{self.n_steps} / {self.n_rhs}"),
                ("error estimate", f"{self.error_estimate:.3g} of tolerance"
                 if math.isfinite(self.error_estimate) else "not estimated (method='auto' does)"),
                ("wall time", f"{1e3 * self.wall_time:.3f} ms"),
                ("message", self.message)]
        if self.impacts is not None:
            rows.insert(-1, ("impacts", f"{len(self.impacts)}"))
        if self.t_events is not None:
            rows.insert(-1, ("events", ", ".join(str(te.size) for te in self.t_events)
                             + " occurrence(s)"))
        return text_table("Simulation", rows)

    def plot(self, ax=None, *, states=None):
        """The states against time, one labelled subplot per unit (`Model.units`), bounds
        (`Model.bounds`) as dashed lines.

        Parameters
        ----------
        ax : matplotlib.axes.Axes or sequence of Axes, optional
            Draw on these (one axes takes every unit group; a sequence needs one per unit);
            by default on a new `matplotlib.figure.Figure` (no pyplot, the backend untouched).
        states : sequence of str, optional
            The states to draw (default all).

        Returns
        -------
        matplotlib.figure.Figure
        """
        names = self.states if states is None else tuple(states)
        unknown = [s for s in names if s not in self.states]
        if unknown:
            raise ValueError(f"`states` names unknown states {unknown}; "
                             f"the states are {self.states}")
        model = None if self._dense is None else self._dense.model
        verdict = "verified" if self.success else "NOT verified"
        return plot_signals(self.t, {n: self.x[self.states.index(n)] for n in names},
                            {} if model is None else model.units,
                            bounds=None if model is None else model.bounds, ax=ax,
                            title=f"{getattr(model, 'name', 'simulation')} ({self.method}, "
                                  f"{verdict}, status {self.status})")

    @property
    def invariant_drift(self) -> Mapping[str, float]:
        """Largest change of each of the model's invariants along ``x`` (evaluated on first use).

        ``max_t |I(t) - I(t[0])| / |I(t[0])|`` (Euclidean norm for a vector invariant;
        absolute where ``I(t[0]) = 0``), NaN when ``x`` has non-finite columns. For a quantity
        conserved by the model under the given ``u`` (energy and inertial angular momentum of
        a torque-free body, a unit quaternion's norm) this is a measured error of the
        solution; a fixed-step run that went unstable shows it as a drift of order 1 or more.
        """
        if self._dense is None:
            return MappingProxyType({})
        return self._dense.drift(self.x)

    def sample(self, t) -> np.ndarray:
        """Dense output: cubic Hermite interpolation of ``x`` and ``xdot`` on the grid.

        Exact at the grid points; between them the error is ``O(dt^4)`` in the grid spacing
        ``dt`` (not the integrator's accuracy: refine ``t`` for accurate dense output).

        Parameters
        ----------
        t : float or array_like, shape (m,) [s]
            Times within ``[self.t[0], self.t[-1]]``.

        Returns
        -------
        ndarray, shape (nx,) for a scalar ``t``, else (nx, m)

        Raises
        ------
        ValueError
            If ``t`` is not finite or lies outside the grid (no extrapolation).
        """
        tq = np.asarray(t, dtype=float)
        scalar = tq.ndim == 0
        tq = tq.reshape(-1)
        if not np.all(np.isfinite(tq)):
            raise ValueError("`t` must be finite")
        if tq.size and (tq.min() < self.t[0] or tq.max() > self.t[-1]):
            raise ValueError(
                f"`t` must lie within the simulated interval [{self.t[0]}, {self.t[-1]}], "
                f"got [{tq.min()}, {tq.max()}]"
            )
        left = self.xdot if self._dense is None else self._dense.xdot_left(self.x)
        out = _hermite(self.t, self.x, self.xdot, left, tq)
        return out[:, 0] if scalar else out


_RESULT_FIELDS = frozenset(f.name for f in fields(SimulationResult))


def make_result(**values) -> SimulationResult:
    """A `SimulationResult` from a value for every field (keywords), the same object its
    constructor makes, without the frozen dataclass's per-field ``object.__setattr__``
    (about 5 us of a repeated short `simulate` call)."""
    if values.keys() != _RESULT_FIELDS:
        raise TypeError(f"make_result needs exactly the fields {sorted(_RESULT_FIELDS)}, "
                        f"got {sorted(values)}")
    result = object.__new__(SimulationResult)
    result.__dict__.update(values)
    return result


def result_fields(result: SimulationResult) -> dict:
    """Every field of ``result`` by name, the keywords of `make_result` (a ``message`` made
    on first use is made now).

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics import rigid_body, simulate
    >>> from appdyn.dynamics.integrate.result import make_result, result_fields
    >>> res = simulate(rigid_body([1.0, 2.0, 3.0]), [0, 0, 0, 1, 1.0, 0.1, 0.8], [0.0, 1.0])
    >>> make_result(**result_fields(res)).message == res.message
    True
    """
    values = dict(result.__dict__)
    if values.pop("_message", None) is not None:
        values["message"] = result.message
    return values


def new_result(t, x, run: "Run", *, success, status, method, wall_time, error_estimate,
               invariants, dense) -> SimulationResult:
    """`make_result` of the states ``x`` on ``t`` of ``run`` (its message and counts), without
    the check of the keyword names (`simulate`'s one call site; about 0.3 us less). A
    ``run.message`` that is a callable makes the result's ``message`` on first use."""
    result = object.__new__(SimulationResult)
    message = run.message
    result.__dict__.update(
        t=t, x=x, success=success, status=status, method=method,
        wall_time=wall_time, n_steps=run.n_steps, n_rhs=run.n_rhs, substeps=run.substeps,
        error_estimate=error_estimate, compiled=run.compiled, invariants=invariants,
        _dense=dense, t_events=None, x_events=None, impacts=None)
    if type(message) is str:
        result.__dict__["message"] = message
    else:
        result.__dict__["_message"] = message
    return result


def _hermite(t, x, xdot, xdot_left, tq):
    """Cubic Hermite interpolation at ``tq``: on interval ``i`` from ``x``, ``xdot`` at its
    start and ``x``, ``xdot_left`` at its end."""
    i = np.clip(np.searchsorted(t, tq, side="right") - 1, 0, t.size - 2)
    dt = t[i + 1] - t[i]
    s = (tq - t[i]) / dt
    s2, s3 = s * s, s * s * s
    h00, h10, h01, h11 = 2 * s3 - 3 * s2 + 1, s3 - 2 * s2 + s, 3 * s2 - 2 * s3, s3 - s2
    return (h00 * x[:, i] + h10 * dt * xdot[:, i] + h01 * x[:, i + 1]
            + h11 * dt * xdot_left[:, i + 1])


@dataclass(frozen=True)
class Run:
    """One integration run inside a call: ``x (nx, n)``, its counts, whether it ran compiled
    and reached the end, and its ``message`` (a str, or a callable making it: the verified
    dense pass's, made only when the result's ``message`` is read); ``quat_off`` the most
    its attitude quaternion's norm is off 1 on ``x`` where the run measured it (the
    compiled pass's answer alone: `sanity.violation` reads it), else None."""

    x: np.ndarray  # (nx, n)
    n_steps: int
    n_rhs: int
    substeps: int
    compiled: bool
    ok: bool
    message: str | Callable[[], str]
    quat_off: float | None = None

    @classmethod
    def new(cls, x, n_steps, n_rhs, substeps, compiled, ok, message, *,
            quat_off=None) -> "Run":
        """``Run(...)`` without the frozen dataclass's per-field ``object.__setattr__``."""
        run = object.__new__(cls)
        run.__dict__.update(x=x, n_steps=n_steps, n_rhs=n_rhs, substeps=substeps,
                            compiled=compiled, ok=ok, message=message, quat_off=quat_off)
        return run


def _drift(model: Model, x: np.ndarray, p: np.ndarray) -> dict:
    """``max_t |I(t) - I(t[0])|`` relative to ``|I(t[0])|`` for each invariant of ``model``."""
    out = {}
    if not np.all(np.isfinite(x)):
        return {name: math.nan for name in model.invariants}
    for name, fun in model.invariants.items():
        v = map_eval(fun, [x, p])
        diff = np.linalg.norm(v - v[:, :1], axis=0)
        ref = float(np.linalg.norm(v[:, 0]))
        out[name] = float(np.max(diff)) / ref if ref > 0 else float(np.max(diff))
    return out
