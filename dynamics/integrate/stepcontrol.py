"""``auto`` for a non-smooth right-hand side: DOP853 with local error control and step
rejection, its global error estimated from runs at tightened local tolerances.

A kink of the right-hand side (``fmin``/``fmax`` of a saturation, an ``if_else``; found by
`dynamics.integrate.smoothness`) costs an 8th-order method its order on the step that
straddles it, so the Richardson estimates of `dynamics.integrate.auto` (which assume order
8 on every interval) neither converge nor mean anything there. A step-size controller needs
no order: the embedded estimate of a step across a kink is large, the step is rejected and
shrunk until its local error meets the tolerance, so the steps crowd at each kink and stay
long elsewhere (the kinks are localized to the precision the tolerance asks for).

The *global* error at the output times is then estimated as for auto's stiff path: runs at
local tolerances ``tol * f``, ``tol * f / 100``, ... (`_TIGHTEN`) until two successive runs
differ by at most the tolerance; the tighter run is returned with that difference as its
error estimate. Each run also takes no step longer than half the longest step of the run
before in the same output interval: where the output grid, not the tolerance, limits the
steps, the tighter tolerance alone would repeat the same steps. The estimate is
conservative: a run at a 100x tighter local tolerance with steps at most half as long is
many times more accurate (error proportional to the local tolerance to the power 7/8 for
DOP853 on a smooth stretch, 2^8-fold smaller for halved steps, at least proportional where
a kink limits the step), so the difference bounds the tighter run's error with a wide
margin. The runs are plain compiled C (`cpass._STEPPER`, in the model's compiled pass
library, no extra compile); a callable control steps from Python with the same controller
(`next_step`).

Measured: a reaction-wheel slew under a saturated PD law (60 s, 121 outputs, rtol 1e-6)
verifies in 7357 steps, about 16 ms; error 2e-3 of the tolerance against scipy's DOP853 at
rtol 1e-13. A bang-bang callable torque: 4725 steps, about 0.7 s.
"""
from __future__ import annotations

import contextlib
import math
from functools import partial

import casadi as ca
import numpy as np

from .. import cache
from ..executors import run_claiming
from ..interrupts import check_interrupt, deferred_interrupts
from .adaptive import INTERVALS
from .cpass import pass_library
from .dense import constant_control, dense_run
from .estimates import initial_step, initial_steps, tightened
from .evaluate import call_buffered
from .inputs import Problem
from .kernels import kernel
from .loops import Progress
from .result import Run
from .tableaux import DOP853, unique_nodes

__all__ = ["LOCAL_RTOL_MIN", "next_step", "plain_answer", "plain_run", "run_dop853",
           "run_stepped", "run_stepped_callable", "run_stepped_many", "solve_stepped"]

_EPS = float(np.finfo(float).eps)

_FIRST = 0.1      # the first run's local tolerance, relative to the requested one
_TIGHTEN = 1e-2   # the local tolerance of each further run, relative to the one before
#: Tightest local rtol of a run (below it the runs meet the states' rounding).
LOCAL_RTOL_MIN = 1e-14
_REASONS = ("", "a state became non-finite", "the step size underflowed",
            "more than max_steps steps", "stiff (stability alone would need too many steps)")


def run_stepped(problem: Problem, rtol: float, atol: np.ndarray, max_steps: int,
                *, progress=None, hmax: np.ndarray | None = None):
    """One DOP853 run with step rejection at the local tolerances ``rtol``, ``atol``
    (linear control), no step of output interval ``k`` longer than ``hmax[k]`` [s]
    (default: the interval). Returns ``(run, longest)``, ``longest (nint,)`` [s] the longest
    accepted step of each interval; None without the model's compiled library
    (`cpass.pass_library`).
    The run's message gives the steps, rejections and the smallest step."""
    lib = pass_library(problem.model)
    if lib is None or problem.control.mode != "linear":
        return None
    stepper = lib.stepper
    model, t = problem.model, problem.t
    nx, nu, nint = model.nx, model.nu, problem.nint
    ctrl = problem.control
    H = np.ascontiguousarray(t[1:] - t[:-1])
    hmax = H if hmax is None else np.ascontiguousarray(hmax, dtype=float)
    ua = np.ascontiguousarray(ctrl.ua, dtype=float).reshape(nint, nu)
    ud = np.ascontiguousarray((ctrl.ub - ctrl.ua) / H[:, None], dtype=float).reshape(nint, nu)
    x = np.array(problem.x0, dtype=float)
    p = np.ascontiguousarray(problem.p, dtype=float)
    at = np.ascontiguousarray(atol, dtype=float)
    h = np.array([_first_step(problem, rtol, atol)])
    X = np.full((nx, nint + 1), np.nan)
    X[:, 0] = x
    out = X[:, 1:].copy()  # (nx, nint), row stride nint
    longest = np.zeros(nint)
    count = np.array([0.0, 0.0, 0.0, math.inf])
    progress = Progress(None) if progress is None else progress
    with deferred_interrupts() if nint > INTERVALS else contextlib.nullcontext():
        done = _intervals(stepper, x, h, H, hmax, ua, ud, p, rtol, at, max_steps, out,
                          longest, count, progress)
    X[:, 1:done + 1] = out[:, :done]
    return _stepped_run(X, t, count, done, rtol, True), longest


def _intervals(stepper, x, h, H, hmax, ua, ud, p, rtol, at, max_steps, out, longest, count,
               progress=None) -> int:
    """One run's calls of the compiled stepper (``cpass`` ``rk8_adaptive``) over its
    ``nint = H.size`` output intervals, `INTERVALS` to a call (between them Ctrl-C is
    looked at and ``progress`` told): ``x (nx,)`` and ``h (1,)`` updated in place, the
    outputs into ``out (nx, nint)``, ``longest (nint,)`` and ``count (4,)`` as the stepper
    writes them; ``ua, ud (nint, nu)`` C-contiguous. Returns the intervals done."""
    nint, nu = H.size, ua.shape[1]
    addr = lambda a, off=0: a.ctypes.data + 8 * off  # noqa: E731
    done = 0
    while done < nint and not count[2]:
        check_interrupt()
        k = min(INTERVALS, nint - done)
        before = count[0] + count[1]
        done += stepper(addr(x), addr(h), k, addr(H, done), addr(hmax, done),
                        addr(ua, done * nu), addr(ud, done * nu), nu, addr(p), rtol,
                        addr(at), float(max_steps), addr(out, done), nint,
                        addr(longest, done), addr(count))
        if progress is not None:
            progress.step(int(count[0] + count[1] - before), done / nint)
    return done


#: Steps (accepted and rejected) after which a compiled loop of `run_stepped_many` takes no
#: further run and returns, so that Ctrl-C is looked at (about 0.1 s on the rigid body).
STEPPED_BUDGET = float(1 << 18)


def run_stepped_many(model, x0: np.ndarray, t: np.ndarray, ua: np.ndarray, ub: np.ndarray,
                     p: np.ndarray, rtol: float, atol: np.ndarray, max_steps: int, *,
                     threads: int = 1):
    """`run_stepped` of K runs on one grid, each the same bits as alone: their first steps
    found together (`estimates.initial_steps`), then every run stepped inside one compiled
    loop over the runs (`cpass` ``rk8_adaptive_many``: the calls of the stepper a run alone
    makes, `_intervals`), on ``threads`` threads (the caller's and those of
    `executors.worker_pool`) that take the runs one at a time through a shared counter; each
    loop returns after about `STEPPED_BUDGET` steps, so that a deferred Ctrl-C stops the
    threads taking runs (raised once the runs taken have finished). No Python runs per run:
    a loop that called the stepper once per run from Python took 41.6 ms for 1,000
    rigid-body runs on one thread and 56 ms on two, the threads waiting on the GIL.

    Parameters
    ----------
    model : Model
    x0 : ndarray, shape (K, nx)
    t : ndarray, shape (n,) [s]
    ua, ub : ndarray, shape (K, n - 1, nu)
        Each run's control at the start and end of each output interval (linear between).
    p : ndarray, shape (K, np)
    rtol : float
    atol : ndarray, shape (nx,)
    max_steps : int
        Most steps (accepted and rejected) of a run.
    threads : int, optional

    Returns
    -------
    tuple or None
        ``(X (K, nx, n), runs)``: the states (NaN after a run's failure) and each run's
        `Run` made lazily by ``runs(k)``; ``steps (K,)`` its steps and ``ok (K,)`` are
        the attributes of ``runs``. None without the model's compiled library.
    """
    lib = pass_library(model)
    if lib is None:
        return None
    K, nint = len(x0), t.size - 1
    H = np.ascontiguousarray(t[1:] - t[:-1])
    ua = np.ascontiguousarray(ua, dtype=float)
    ud = np.ascontiguousarray((ub - ua) / H[None, :, None], dtype=float)
    x = np.array(x0, dtype=float, order="C")  # (C-contiguous rows, updated in place)
    p = np.ascontiguousarray(p, dtype=float)
    at = np.ascontiguousarray(atol, dtype=float)
    t0, H0 = float(t[0]), float(H[0])
    u0 = ua[:, 0]
    first = initial_steps(model, x, p, rtol, at, 8, t0, H0,
                          lambda tt: u0 + ((tt - t0) / H0)[:, None] * (ub[:, 0] - u0))[0]
    h = np.array([_proposal(v, H0) for v in first])
    out = np.full((K, x.shape[1], nint), np.nan)
    longest = np.zeros((K, nint))
    count = np.tile([0.0, 0.0, 0.0, math.inf], (K, 1))
    done = np.zeros(K, dtype=np.int64)
    cursor = np.zeros(1, np.int64)  # (the next run, shared by the threads' compiled loops)
    args = (K, cursor.ctypes.data, STEPPED_BUDGET, nint, INTERVALS, H.ctypes.data,
            x.ctypes.data, h.ctypes.data, ua.ctypes.data, ud.ctypes.data, ua.shape[2],
            p.ctypes.data, p.shape[1], rtol, at.ctypes.data, float(max_steps),
            out.ctypes.data, longest.ctypes.data, count.ctypes.data, done.ctypes.data)
    run_claiming(lib.stepper_many, args, threads, K)
    X = np.concatenate([x0[:, :, None], out], axis=2)
    for k in np.flatnonzero(done < nint):  # (NaN from the failure on, as a run alone)
        X[k, :, done[k] + 1:] = np.nan
    return X, _SteppedRuns(X, t, count, done, rtol)


class _SteppedRuns:
    """The runs of `run_stepped_many`: ``runs(k)`` run k's `Run` (as `run_stepped`'s),
    ``steps (K,)`` each run's steps (accepted and rejected), ``ok (K,)`` those finished."""

    def __init__(self, X, t, count, done, rtol):
        self._X, self._t, self._count, self._done, self._rtol = X, t, count, done, rtol
        self.steps = (count[:, 0] + count[:, 1]).astype(int)
        self.ok = count[:, 2] == 0

    def __call__(self, k: int) -> Run:
        return _stepped_run(self._X[k], self._t, self._count[k], int(self._done[k]),
                            self._rtol, True)


def _first_step(problem: Problem, rtol: float, atol: np.ndarray) -> float:
    """The first step proposed [s]: Hairer's heuristic (`estimates.initial_step`), or a
    hundredth of the first interval where it is degenerate (`_proposal`)."""
    return _proposal(initial_step(problem, rtol, atol, 8)[0],
                     float(problem.t[1] - problem.t[0]))


def _proposal(h0: float | None, H0: float) -> float:
    """A run's first proposed step [s] from Hairer's heuristic ``h0`` (None: degenerate)
    and its first output interval ``H0``: ``h0``, else ``H0 / 100``."""
    return h0 if h0 is not None and h0 > 0 else H0 / 100.0


def _stepped_run(X: np.ndarray, t: np.ndarray, count, done: int, rtol: float,
                 compiled: bool) -> Run:
    """The `Run` of a stepped run from its counters ``(accepted, rejected, flag, smallest
    step)`` and the intervals ``done``."""
    steps, rejects = int(count[0]), int(count[1])
    n_rhs = DOP853.stages * (steps + rejects)
    if count[2]:
        return Run.new(X, steps + rejects, n_rhs, 0, compiled, False,
                       f"dop853: {_REASONS[int(count[2])]} before "
                       f"t = {t[min(done + 1, t.size - 1)]:.6g}")
    return Run.new(X, steps + rejects, n_rhs, 0, compiled, True,
                   f"dop853 with step rejection: {steps} steps, {rejects} rejected, smallest "
                   f"step {count[3]:.3g} s (local rtol {rtol:.3g})")


#: The step-size controller of `cpass._STEPPER` (Hairer's DOP853): safety, and the least
#: and most factor of a step change.
_SAFETY, _SHRINK, _GROW = 0.9, 1.0 / 3.0, 6.0


def next_step(h: float, err: float, rejected: bool) -> tuple[bool, float]:
    """The controller of `cpass._STEPPER` in Python: whether a step ``h`` with embedded
    estimate ``err`` (tolerance units) is accepted, and the next step (no growth right after
    a rejection; a non-finite ``err`` is a rejection by the largest factor)."""
    if not math.isfinite(err):
        return False, h * _SHRINK
    fac = err ** 0.125 / _SAFETY
    if err <= 1.0:
        new = h / max(1.0 / _GROW, min(1.0 / _SHRINK, fac))
        return True, min(h, new) if rejected else new
    return False, h / min(1.0 / _SHRINK, fac)


def _callable_step(model) -> ca.Function:
    """``(x, h, us, p, rtol, atol) -> [x_next; err]``: one rk8 step with DOP853's estimate,
    the control given at the distinct stage nodes (cached per model)."""
    def build():
        step = kernel(model, "rk8", "stages", error=True)
        sym = ca.SX if step.is_a("SXFunction") else ca.MX
        ins = [sym.sym(step.name_in(i), step.sparsity_in(i)) for i in range(step.n_in())]
        x_next, err = step.call(ins)
        return ca.Function("rk8_step_err_stages", ins, [ca.vertcat(x_next, err)])

    return cache.get(("rk8_step_err_stages", cache.function_key(model.f)), build,
                     keepalive=model.f)


def run_stepped_callable(problem: Problem, rtol: float, atol: np.ndarray, max_steps: int,
                         *, progress=None, hmax: np.ndarray | None = None):
    """`run_stepped` stepping from Python: for a callable control (``problem.control.mode
    == 'stages'``, called at each step's stage times: a jump of the control shrinks the
    steps that straddle it, as a kink does) or any control without a compiled stepper
    (`Control.at`); the same controller (`next_step`)."""
    model, t, ctrl = problem.model, problem.t, problem.control
    nx, nint = model.nx, problem.nint
    H = t[1:] - t[:-1]
    hmax = H if hmax is None else hmax
    nodes = np.array(unique_nodes("rk8"))
    step = _callable_step(model)
    X = np.full((nx, t.size), np.nan)
    X[:, 0] = problem.x0
    x = np.array(problem.x0, dtype=float)
    h = _first_step(problem, rtol, atol)
    longest = np.zeros(nint)
    count = [0, 0, 0, math.inf]  # as `cpass._STEPPER`'s
    rt = np.array([rtol])
    progress = Progress(None) if progress is None else progress
    for k in range(nint):
        check_interrupt()
        before = count[0] + count[1]
        tk, Hk, tau, rejected = float(t[k]), float(H[k]), 0.0, False
        while tau < Hk:
            hp = min(h, float(hmax[k]))
            last = tau + 1.01 * hp >= Hk
            hs = Hk - tau if last else hp
            us = np.concatenate([ctrl.at(tk + tau + c * hs, k, tk, Hk) for c in nodes])
            out = call_buffered(step, [x, np.array([hs]), us, problem.p, rt, atol], (nx + 1,))
            err = float(out[nx]) if np.isfinite(out[:nx]).all() else math.nan
            ok, hn = next_step(hs, err, rejected)
            if ok:
                x[:] = out[:nx]
                tau = Hk if last else tau + hs
                count[0] += 1
                longest[k] = max(longest[k], hs)
                count[3] = min(count[3], hs)
                h = h if hs < h and hn < h else hn
            else:
                count[1] += 1
                h = hn
            rejected = not ok
            if count[0] + count[1] > max_steps:
                count[2] = 3
            elif not h > 64 * _EPS * Hk:
                count[2] = 2 if math.isfinite(err) else 1
            if count[2]:
                return _stepped_run(X, t, count, k, rtol, False), longest
        X[:, k + 1] = x
        progress.step(int(count[0] + count[1] - before), (k + 1) / nint)
    return _stepped_run(X, t, count, nint, rtol, False), longest


def run_dop853(problem: Problem, rtol: float, atol: np.ndarray, max_steps: int, *,
               compiled: bool = True, progress=None) -> Run:
    """``simulate(..., method='dop853')``: ONE DOP853 run at the local tolerances ``rtol``,
    ``atol``, as scipy's ``solve_ivp(method='DOP853')`` or numbalsoda's ``dop853`` make it:
    each step's embedded estimate within the tolerance, nothing said of the global error
    (``auto`` verifies that). Under a control constant over the run, the steps follow the
    error estimate alone and the outputs come from the continuous extension of order 7
    (`plain_run`: the work does not grow with the outputs); under a sampled control the
    steps end on the grid, where the control may kink (`run_stepped`); both compiled C in
    the model's pass library. A callable control, or ``compiled=False`` (``jit=False``, no
    C compiler), steps from Python with the same controller (`run_stepped_callable`).

    Returns
    -------
    Run
        ``ok`` False (NaN from the failure on) when a state became non-finite, the step
        size underflowed or more than ``max_steps`` steps (accepted and rejected) were
        needed; its message says which and where.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics import rigid_body
    >>> from appdyn.dynamics.integrate.inputs import Problem, check_u
    >>> from appdyn.dynamics.integrate.stepcontrol import run_dop853
    >>> from appdyn.dynamics.truth.torque_free import torque_free_omega
    >>> model, t = rigid_body([1.5, 2.5, 3.2]), np.linspace(0.0, 60.0, 121)
    >>> x0 = np.r_[0.0, 0.0, 0.0, 1.0, 0.5, 0.0, 1.0]
    >>> run = run_dop853(Problem.new(model, x0, t, check_u(None, 3, t), np.zeros(0)),
    ...                  1e-10, np.full(7, 1e-12), 10**6)
    >>> w = torque_free_omega([1.5, 2.5, 3.2], x0[4:], t)
    >>> bool(run.ok and np.abs(run.x[4:] - w).max() < 1e-8)
    True
    """
    ctrl = problem.control
    if compiled and ctrl.mode == "linear":
        if constant_control(ctrl):
            run = plain_run(problem.model, problem.x0, problem.t, rtol, atol, max_steps,
                            u=ctrl.ua[0] if ctrl.ua.shape[0] else None, p=problem.p,
                            progress=progress)
            if run is not None:
                return run
        got = run_stepped(problem, rtol, atol, max_steps, progress=progress)
        if got is not None:
            return got[0]
    return run_stepped_callable(problem, rtol, atol, max_steps, progress=progress)[0]


def plain_run(model, x0: np.ndarray, t: np.ndarray, rtol: float, atol, max_steps: int, *,
              u=None, p=None, progress=None, plan=None) -> Run | None:
    """DOP853's answer alone under a control constant over the run (``u (nu,)``, None:
    zero), its steps by the error estimate, the outputs from the continuous extension: the
    compiled call of ``auto``'s dense path without its check (`dense.dense_run` with
    ``check=False``: the model's plan, the thread's workspace, one ``ctypes`` call). None
    without the model's compiled pass. The run's ``substeps`` is the longest output interval
    over the smallest step taken (but a last one cut short): equal steps of that many per
    interval are no longer than any the run took (`dynamics.integrate.events` re-integrates
    with them). ``plan``: the model's `dense.pass_plan` when the caller has it.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics import rigid_body
    >>> from appdyn.dynamics.integrate.stepcontrol import plain_run
    >>> from appdyn.dynamics.truth.torque_free import torque_free_omega
    >>> model, t = rigid_body([1.5, 2.5, 3.2]), np.linspace(0.0, 60.0, 121)
    >>> x0 = np.r_[0.0, 0.0, 0.0, 1.0, 0.5, 0.0, 1.0]
    >>> run = plain_run(model, x0, t, 1e-10, np.full(7, 1e-12), 10**6)
    >>> w = torque_free_omega([1.5, 2.5, 3.2], x0[4:], t)
    >>> bool(run.ok and np.abs(run.x[4:] - w).max() < 1e-8 and run.n_steps < 240)
    True
    """
    got = dense_run(model, x0, t, rtol, atol, float(max_steps), math.inf, u=u, p=p,
                    progress=progress, check=False, plan=plan)
    return None if got is None else plain_answer(got, t, rtol)


def plain_answer(got, t: np.ndarray, rtol: float) -> Run:
    """The `Run` of DOP853's answer alone (`dense.DenseAuto` ``got`` of ``check=False``) on
    the grid ``t``: its steps and right-hand-side calls, its substeps and quaternion drift
    (found in the pass), its message made on first use; a failed run (NaN from the first
    output it did not reach) says why and where."""
    steps = got.spent  # (the answer's: accepted and rejected; a failed run's too)
    n_rhs = DOP853.stages * steps + 4 * got.interpolated
    if got.result != 2:  # (a failed run: NaN from the first output it did not reach)
        done = int(np.argmin(np.isfinite(got.x).all(axis=0))) - 1
        return Run.new(got.x, steps, n_rhs, 0, True, False,
                       f"dop853: {got.reason} before t = {t[min(done + 1, t.size - 1)]:.6g}")
    return Run.new(got.x, steps, n_rhs, got.substeps, True, True,
                   partial(_plain_message, got, rtol), quat_off=got.qoff)


def _plain_message(got, rtol: float) -> str:
    """The message of `plain_run`'s answer (made when the result's message is read)."""
    return (f"dop853 with dense output: {got.answer_steps - got.rejected} steps, "
            f"{got.rejected} rejected, smallest step {got.hmin:.3g} s (local rtol {rtol:.3g}), "
            f"{got.interpolated} steps interpolated; global error not estimated "
            "(method='auto' verifies it)")


def solve_stepped(problem: Problem, rtol: float, atol: np.ndarray, max_steps: int,
                  *, progress=None):
    """Step-controlled runs at local tolerances ``rtol * _FIRST``, then ``_TIGHTEN`` times
    tighter each, until two successive runs differ by at most the tolerance
    (`estimates.tightened`). No step of a run is longer than half the longest step of the
    one before in the same output interval: where the grid, not the tolerance, limits the
    steps (a smooth stretch), a tighter tolerance alone would repeat the same steps and
    their difference would tell nothing. Returns ``(run, verdict, estimate, n_steps, n_rhs)`` as `tightened`
    does (``verdict`` None: no compiled stepper for this model or control)."""
    stepped = run_stepped_callable if problem.control.mode == "stages" else run_stepped
    H = problem.t[1:] - problem.t[:-1]
    state = {"spent": 0, "hmax": H}

    def run_at(local_rtol, local_atol):
        got = stepped(problem, local_rtol, local_atol, max_steps - state["spent"],
                      progress=progress, hmax=state["hmax"])
        if got is None:
            return None
        run, longest = got
        state["spent"] += run.n_steps
        state["hmax"] = np.where(longest > 0, longest, H) / 2.0
        return run

    return tightened(run_at, rtol, atol, _FIRST, _TIGHTEN, LOCAL_RTOL_MIN)
