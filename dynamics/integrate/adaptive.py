"""``auto``'s one-pass path: rk8 with DOP853's embedded error control and a global check,
in one compiled C loop per model.

Each output interval is integrated twice, side by side:

* a check run: ``b`` rk8 steps, ``b`` predicted from its embedded error estimate in the
  interval before (error per unit time aimed at ``theta``), the interval redone once with
  more steps when its own estimate exceeds the target; it is carried on its own from a start
  2 ulp away (so that the amplification of representation errors shows as well);
* the answer: ``n = 2 b + 1`` steps (2 for ``b = 1``), so at least twice as many.

The scaled difference ``d`` of the two runs at the output times bounds the global error of
the answer by ``d`` whenever the answer is at least twice as accurate as the check (2^8-fold
in the asymptotic range of an 8th-order method with ``n / b >= 2``). `run_pass` returns
both runs and the statistics `dynamics.integrate.auto.one_pass` decides on; it falls back to
the multi-run Richardson search when they do not suffice.

The loop is plain C (`dynamics.integrate.cpass`) around the casadi-generated steps
(`kernels.kernel` with and without the estimate) and right-hand side, compiled once per
model for this machine and loaded with ``ctypes``; one call covers `INTERVALS` output
intervals. An accepted ``auto``
call is one pass of compiled C: on the 100 s benchmark body at rtol 1e-3, 315 steps in
about 0.1 ms (the multi-run search took 1.3 ms).
"""
from __future__ import annotations

import contextlib
import math
import threading
from typing import NamedTuple

import numpy as np

from ..executors import run_claiming
from ..interrupts import check_interrupt, deferred_interrupts
from .cpass import BMAX, NOISE, pass_library
from .estimates import signs, table
from .inputs import Problem

__all__ = ["INTERVALS", "Pass", "PassBatch", "run_pass", "run_pass_many"]

#: Output intervals per call of the compiled pass (Ctrl-C is looked at between calls).
INTERVALS = 256


class Pass(NamedTuple):
    """What `run_pass` measured.

    ``x``, ``xc`` ``(nx, n)``: the answer and the check run (NaN past a stop);
    ``stats (intervals done, 4)``: per interval the answer's steps, its embedded estimate (of
    the interval's first step; -1 where not taken), the check run's and the steps taken;
    ``n_steps`` every step taken, ``answer_steps`` the answer's, ``n_range`` its least and
    most per interval, ``ratio`` the least ``n / b`` of an interval; ``d`` the largest
    ``|x - xc| / (atol + rtol |x|)``; ``ec`` the check run's largest estimate;
    ``orders = (shown, measured)``: of the intervals where both estimates were measured
    clear of rounding, how many showed ``log(ec / e) / log(n / b)`` in [5, 10]; ``ulp`` the
    largest ``eps max_t |x_i| / min_t (atol_i + rtol |x_i|)`` (one ulp of a state's size in
    tolerance units); ``smin (nx)`` the least tolerance ``atol_i + rtol |x_i|`` of each
    state over the outputs, ``rounding (nx)`` the largest change of ``f_i`` when the answer's
    state moves by one ulp (every fourth output; the model's rounding noise); ``ok`` False when a state became non-finite, an interval needed more
    than ``2 BMAX + 1`` steps, a tolerance came within the ``ulps`` of `run_pass` or
    ``max_steps`` was passed (the pass then stops: ``reason`` says which).
    """

    x: np.ndarray
    xc: np.ndarray
    stats: np.ndarray
    n_steps: int
    answer_steps: int
    n_range: tuple
    ratio: float
    d: float
    ec: float
    orders: tuple
    ulp: float
    smin: np.ndarray
    rounding: np.ndarray
    ok: bool
    reason: str = ""


_ST = 13  # accumulators of the C `state` before max |x| and min scale (see `cpass._DRIVER`)
_STATE0 = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, math.inf, 0.0, 0.0, math.inf, 0.0)


def _state0(nx: int) -> np.ndarray:
    """The C `state` at the start: the accumulators, then max |x| (0), min scale (inf) and
    rounding noise (0) of each state (read-only; kept in `estimates.table`)."""
    known = table("pass_state0")
    out = known.get(nx)
    if out is None:
        out = np.concatenate([_STATE0, np.zeros(nx), np.full(nx, math.inf), np.zeros(nx)])
        out.setflags(write=False)
        known[nx] = out
    return out


class _Work:
    """The inputs of the compiled pass that need no fresh memory (one workspace per thread
    and shape, its addresses taken once): ``xf, xc, state, H, ua, ud, p, atol, stats,
    signs, par`` (see ``rk8_pass_ws`` in `cpass._DRIVER`)."""

    __slots__ = ("arrays", "base", "offsets", "off_addr", "key")

    def __init__(self, key, sizes):
        self.key = key
        offsets = [0]
        for size in sizes:
            offsets.append(offsets[-1] + size)
        work = np.zeros(offsets[-1])
        self.arrays = [work[offsets[i]:offsets[i + 1]] for i in range(len(sizes))]
        self.arrays[9][:] = signs(1, sizes[0])  # (`_perturbed`'s pattern for m = 1)
        self.base = work.ctypes.data
        self.offsets = np.array(offsets[:-1], dtype=np.int64)
        self.off_addr = self.offsets.ctypes.data


_LOCAL = threading.local()




def _borrow_work(key, sizes) -> _Work:
    """This thread's workspace of ``key`` (taken out until `_return_work`)."""
    table = getattr(_LOCAL, "work", None)
    if table is None:
        table = _LOCAL.work = {}
    work = table.pop(key, None)
    return _Work(key, sizes) if work is None else work


def _return_work(work: _Work) -> None:
    table = _LOCAL.work
    if len(table) >= 8:
        table.clear()
    table[work.key] = work


def run_pass(problem: Problem, rtol: float, atol: np.ndarray, theta: float, max_steps: int,
             progress, *, bmin: int = 1, ulps: float = math.inf) -> Pass | None:
    """The pass over ``problem`` (linear control) with the check run's embedded estimate
    aimed at ``theta`` tolerances per unit time, at least ``bmin >= 1`` check steps per
    interval; the check run starts from ``x0 (1 + 2 eps s)`` (``s`` a fixed pattern of
    signs: the amplification of a representation error shows as well). It stops (``ok`` False) as soon as a
    state's tolerance ``atol + rtol |x|`` comes within ``ulps`` ulps of the state's size.
    None when there is no compiled pass for the model (`pass_library`)."""
    model, t = problem.model, problem.t
    fun = pass_library(model)
    if fun is None:
        return None
    nx, nu, nint = model.nx, model.nu, problem.nint
    ctrl = problem.control
    const = bool(ctrl.constant)
    nctl = nu if const else nu * nint
    key = (nx, nctl, nint, model.np)
    work = _borrow_work(key, (nx, nx, _ST + 3 * nx, nint, nctl, nctl, model.np, nx, 4 * nint,
                              nx, 8))
    xf, xc, state, H, ua, ud, p, at, stats, signs, par = work.arrays
    xf[:], p[:], at[:] = problem.x0, problem.p, atol
    state[:] = _state0(nx)
    state[0] = bmin
    np.abs(problem.x0, out=state[_ST:_ST + nx])
    np.subtract(t[1:], t[:-1], out=H)
    ua[:], ud[:], _ = _controls(ctrl, H, nu)
    par[:] = (rtol, theta, BMAX, bmin, NOISE * _EPS / rtol,
              math.inf if ulps == math.inf else 1.0 / (_EPS * ulps), 0 if const else nu,
              nint + 1)
    XX = np.empty((2, nx, nint + 1))
    ax = XX.ctypes.data
    axc = ax + 8 * nx * (nint + 1)
    done, reason = 0, ""
    with deferred_interrupts() if nint > INTERVALS else contextlib.nullcontext():
        while done < nint:
            check_interrupt()
            k = min(INTERVALS, nint - done)
            before = state[2]
            got = fun(work.base, work.off_addr, done, k, ax, axc)
            if progress.fun is not None:
                progress.step(int(state[2] - before), (done + got) / nint)
            done += got
            reason = _stop_reason(state[7], state[2], max_steps)
            if reason:
                break
    out = _pass_of(XX[0], XX[1], state, stats.reshape(nint, 4), done, reason)
    _return_work(work)
    return out


def _pass_of(x: np.ndarray, xcheck: np.ndarray, state: np.ndarray, stats: np.ndarray,
             done: int, reason: str) -> Pass:
    """The `Pass` of a pass that did ``done`` intervals: its answer and check ``x``,
    ``xcheck (nx, n)`` (made NaN past a stop, in place), the C ``state`` and ``stats (nint,
    4)`` (copied), ``reason`` why it stopped ("" when it finished)."""
    nx = x.shape[0]
    if reason:
        x[:, done + 1:] = np.nan
        xcheck[:, done + 1:] = np.nan
    st = state[:_ST].tolist()
    return Pass(x, xcheck, stats[:done].copy(), int(st[2]), int(st[10]),
                (int(st[8]), int(st[9])), st[11], st[3], st[6], (int(st[4]), int(st[5])),
                _EPS * st[12], state[_ST + nx:_ST + 2 * nx].copy(), state[_ST + 2 * nx:].copy(),
                not reason, reason)


def _stop_reason(flag: float, steps: float, max_steps: int) -> str:
    """Why a pass stopped after a call: its C flag, or more than ``max_steps`` steps; ""
    when it goes on."""
    if flag:
        return _REASONS[int(flag)]
    return f"more than max_steps = {max_steps} steps" if steps > max_steps else ""


#: Steps after which a loop of `run_pass_many` takes no further run (it returns, the
#: caller looks at Ctrl-C and calls it again).
PASSES_BUDGET = 200_000


def run_pass_many(model, x0: np.ndarray, t: np.ndarray, ua: np.ndarray, ub: np.ndarray,
                  p: np.ndarray, rtol: float, atol: np.ndarray, theta: float, max_steps: int,
                  *, ulps: float = math.inf, threads: int = 1,
                  meanwhile=None) -> "PassBatch | None":
    """`run_pass` (``bmin`` 1) of K runs on one grid, each the same bits as alone, every
    run inside one compiled loop over the runs (`cpass` ``rk8_pass_many``: the calls of
    the pass a run alone makes, `INTERVALS` intervals to a call) on ``threads`` threads (the
    caller's and those of `executors.worker_pool`) that take the runs one at a time through
    a shared counter; each loop returns after about `PASSES_BUDGET` steps, so that a
    deferred Ctrl-C stops the threads taking runs (raised once the runs taken have finished).

    The inputs are `stepcontrol.run_stepped_many`'s (``x0 (K, nx)``, the grid ``t (n,)``,
    each run's controls at the ends of its intervals ``ua, ub (K, n - 1, nu)``, varying
    over the run: a run under one value takes the dense pass; ``p (K, np)``, ``atol
    (nx,)``), with ``theta``, ``max_steps`` and ``ulps`` as `run_pass`'s; ``meanwhile``
    Python for the calling thread while the others step (`executors.run_claiming`). Returns
    the runs' `PassBatch`, or None without the model's compiled pass.
    """
    fun = pass_library(model)
    if fun is None:
        return None
    K, nx, nu, nint = len(x0), model.nx, model.nu, t.size - 1
    nctl = nu * nint
    sizes = (nx, nx, _ST + 3 * nx, nint, nctl, nctl, model.np, nx, 4 * nint, nx, 8)
    ends = np.cumsum((0,) + sizes)
    W = np.zeros((K, int(ends[-1])))
    xf, _, state, H, uas, uds, ps, at, stats, sg, par = (
        W[:, ends[i]:ends[i + 1]] for i in range(len(sizes)))
    xf[:], ps[:], at[:], sg[:] = x0, p, atol, signs(1, nx)
    state[:] = _state0(nx)
    state[:, 0] = 1  # (bmin)
    np.abs(x0, out=state[:, _ST:_ST + nx])
    step = np.subtract(t[1:], t[:-1])
    H[:] = step
    uas[:] = ua.reshape(K, nctl)
    uds[:] = ((ub - ua) / step[None, :, None]).reshape(K, nctl)  # (as `_controls`)
    par[:] = (rtol, theta, BMAX, 1, NOISE * _EPS / rtol,
              math.inf if ulps == math.inf else 1.0 / (_EPS * ulps), nu, nint + 1)
    off = np.array(ends[:-1], dtype=np.int64)
    XX = np.empty((K, 2, nx, nint + 1))
    done = np.zeros(K, dtype=np.int64)
    cursor = np.zeros(1, np.int64)  # (the next run, shared by the threads' compiled loops)
    args = (K, cursor.ctypes.data, PASSES_BUDGET, W.ctypes.data, W.shape[1], off.ctypes.data,
            nint, INTERVALS, float(max_steps), XX.ctypes.data,
            XX.ctypes.data + 8 * nx * (nint + 1), 2 * nx * (nint + 1), done.ctypes.data)
    run_claiming(fun.pass_many, args, threads, K, meanwhile=meanwhile)
    stats = stats.reshape(K, nint, 4)
    flags, steps = state[:, 7].tolist(), state[:, 2].tolist()
    return PassBatch([_pass_of(XX[k, 0], XX[k, 1], state[k], stats[k], int(done[k]),
                               _stop_reason(flags[k], steps[k], max_steps)) for k in range(K)],
                     (fun, W, off, XX, stats, threads))


class PassBatch:
    """The passes of `run_pass_many`: ``passes[k]`` run k's `Pass`, and `replay_checks`."""

    def __init__(self, passes: list, work: tuple):
        self.passes = passes
        self._work = work  # (the library, workspaces, layout, states, stats, threads)

    def replay_checks(self, runs, *, threads: int | None = None) -> np.ndarray:
        """`replay_check` of the finished passes ``runs`` (indices), the same bits: ``(len(runs),
        nx, n)``, NaN past a non-finite state, in one compiled loop over them (`cpass`
        ``rk8_replay_many``) on ``threads`` threads (None: the batch's)."""
        fun, W, off, XX, stats, mine = self._work
        threads = mine if threads is None else threads
        runs = np.asarray(runs, dtype=np.int64)
        m, nx, n = runs.size, XX.shape[2], XX.shape[3]
        B = np.ascontiguousarray(_check_steps(stats[runs, :, 0]))
        R = np.full((m, nx, n), np.nan)
        if m:
            cursor = np.zeros(1, np.int64)
            run_claiming(fun.replay_many, (m, cursor.ctypes.data, runs.ctypes.data,
                                           W.ctypes.data, W.shape[1], off.ctypes.data, n - 1,
                                           B.ctypes.data, XX.ctypes.data, 2 * nx * n,
                                           R.ctypes.data), threads, m)
        return R

def _controls(ctrl, H: np.ndarray, nu: int) -> tuple[np.ndarray, np.ndarray, int]:
    """The pass's controls over the intervals of lengths ``H``: ``(ua, ud, stride)``, each
    interval's start value and slope (flat, C-contiguous), one of each (stride 0) for a
    constant control."""
    if ctrl.constant:
        return np.array(ctrl.ua[0], dtype=float), np.zeros(nu), 0
    k = H.size
    return (np.ascontiguousarray(ctrl.ua[:k], dtype=float).ravel(),
            ((ctrl.ub[:k] - ctrl.ua[:k]) / H[:, None]).ravel(), nu)


def check_steps(got: Pass) -> np.ndarray:
    """The check run's steps ``b`` per interval of the pass ``got`` (from the answer's
    ``n = 2 b + 1``, or 2 for ``b = 1``), as floats."""
    return _check_steps(got.stats[:, 0])


def _check_steps(n: np.ndarray) -> np.ndarray:
    """The check run's steps ``b`` from the answer's ``n = 2 b + 1`` (or 2 for ``b = 1``)."""
    return np.where(n <= 2, 1.0, (n - 1) // 2)


def replay_check(problem: Problem, got: Pass) -> np.ndarray | None:
    """The check run of the pass ``got`` over ``problem`` replayed on its own steps
    (`check_steps`) from the exact start ``x0`` (the check's started 2 ulp away): ``x (nx,
    intervals done + 1)``, NaN past a non-finite state; its difference from ``got.xc`` is
    what the flow made of those 2 ulp, truncation alike (`auto._amplified`). None without
    a compiled pass."""
    fun = pass_library(problem.model)
    if fun is None:
        return None
    model, done = problem.model, got.stats.shape[0]
    b = np.ascontiguousarray(check_steps(got))
    H = np.ascontiguousarray(np.diff(problem.t)[:done])
    ua, ud, ustride = _controls(problem.control, H, model.nu)
    ua, ud = np.resize(ua, max(ua.size, 1)), np.resize(ud, max(ud.size, 1))
    x = np.array(problem.x0, dtype=float)
    X = np.full((model.nx, done + 1), np.nan)
    X[:, 0] = x
    p = np.ascontiguousarray(problem.p, dtype=float)
    atol = np.ones(model.nx)
    fun.replay(x.ctypes.data, done, H.ctypes.data, ua.ctypes.data, ud.ctypes.data, ustride,
               p.ctypes.data, atol.ctypes.data, b.ctypes.data, X.ctypes.data, done + 1)
    return X


_EPS = float(np.finfo(float).eps)
_REASONS = ("", "a state became non-finite",
            f"an output interval needs more than {2 * BMAX + 1} steps",
            "the tolerance of a state came near its round-off")
