"""Batched simulation: K runs of one model on one output grid, chunk by chunk in mapped calls.

`simulate` comes here when ``x0`` has shape ``(nx, K)``. Every run shares the grid, the
method and the step count; each has its own initial state, parameters (``p`` of shape
``(np, K)``) and control samples (``u`` of shape ``(nu, n, K)``). The fixed-step methods
call the model's one compiled chunk loop of ``loops.BATCH_CHUNK`` steps
(`dynamics.integrate.loops.chunk_function`: compiled once per model and method, never per
call) mapped serially over parts of the runs. The parts of a chunk are spread over the
machine's cores (`BATCH_THREADS` threads, `dynamics.executors.run_split`; a compiled call
releases the GIL), each thread taking the next part as it finishes, through arrays it keeps
bound to the mapped call between chunks and calls (`_Lane`). ``auto`` runs the same error
control as a single run (`dynamics.integrate.auto`) on the whole batch: one step count for
all runs, chosen until the global error estimate of every run meets the tolerance (a stiff
batch goes, run by run, to auto's cvodes as a single run does). ``cvodes`` (a
variable-step integrator per run) is a loop of single runs.
"""
from __future__ import annotations

import contextlib
import math
import os
import time
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

from .. import cache
from ..executors import run_split
from ..interrupts import check_interrupt, deferred_interrupts
from ..model import Model
from ..validate import finite_array, integer, unit_quaternion
from ..validate.rotations import QUAT_NORM_TOL
from .auto import Single, auto_runs, jacobian_x, rho_sigma, solve_auto
from .cvodes import run_cvodes
from .evaluate import borrow_state, map_eval, return_state
from .inputs import Control, Problem
from .loops import BATCH_CHUNK as CHUNK
from .loops import Progress, chunk_function, interval_ends
from .result import FAILED, OK, OK_STIFF, ROUNDOFF, UNVERIFIED, Dense, Run, SimulationResult
from .tableaux import TABLEAUX

__all__ = ["Batch", "BatchResult", "check_batch", "fixed_batch", "run_fixed_batch",
           "simulate_batch", "BATCH_THREADS", "PART_RUNS"]

#: Threads over which the runs of a batch are spread (the cores this process may use, at
#: most 8).
BATCH_THREADS = max(1, min(8, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
                           else os.cpu_count() or 1))

#: Most runs of one mapped call of the chunk Function (a part of a batch): bounds the
#: arrays each thread keeps per model and method (`_Lane`; for 256 runs of the rigid
#: body's 64-step chunk, 1.8 MB) and keeps a call's data in the core's cache.
PART_RUNS = 256

#: Run-steps of a chunk from which its parts are spread over the threads: below, the
#: hand-over to another thread (tens of microseconds) costs more than it saves.
PARALLEL_STEPS = 4096

#: Run-steps of a part of a chunk spread over threads: the threads take parts as they
#: finish, and small parts end them together (a part costs ~20 us of Python besides).
PART_STEPS = 2048


@dataclass(frozen=True)
class Batch:
    """K runs on one grid: ``x0 (nx, K)``, ``p (np, K)``, controls ``ua, ub (K, nint, nu)``
    (the values at the start and end of each output interval, linear in between);
    ``constant`` when each run's control is known to be one value throughout (``False``
    leaves it to be found from the values)."""

    model: Model
    x0: np.ndarray
    t: np.ndarray
    p: np.ndarray
    ua: np.ndarray
    ub: np.ndarray
    constant: bool = False

    @property
    def K(self) -> int:
        return self.x0.shape[1]

    @property
    def nint(self) -> int:
        return self.t.size - 1

    def problem(self, k: int) -> Problem:
        """Run ``k`` as a single-run `Problem`."""
        return Problem(self.model, self.x0[:, k].copy(), self.t,
                       Control("linear", self.ua[k], self.ub[k]), self.p[:, k].copy())


def check_batch(model: Model, x0, t: np.ndarray, u, p) -> Batch:
    """The batch of ``x0 (nx, K)`` with ``p`` ``(np,)`` or ``(np, K)`` and ``u`` None,
    ``(nu,)``, ``(nu, n)`` (shared) or ``(nu, n, K)`` (per run); raises naming the argument."""
    nx, nu, n = model.nx, model.nu, t.size
    X0 = np.array(finite_array(x0, "x0"), dtype=float)
    if X0.ndim != 2 or X0.shape[0] != nx or X0.shape[1] < 1:
        raise ValueError(f"`x0` must have shape ({nx},) or ({nx}, K) for a batch of K runs, "
                         f"got {X0.shape}")
    K = X0.shape[1]
    if model.attitude is not None:
        iq = model.attitude[0]
        bad = np.abs(np.linalg.norm(X0[iq:iq + 4], axis=0) - 1.0) > QUAT_NORM_TOL
        if bad.any():  # the message of the single-run check, naming the run
            k = int(np.argmax(bad))
            unit_quaternion(X0[iq:iq + 4, k], f"x0[{iq}:{iq + 4}, {k}] (the attitude quaternion)")
    if p is None:
        P = np.repeat(model.resolve_p(None)[:, None], K, axis=1)
    else:
        a = np.asarray(finite_array(p, "p"), dtype=float)
        if a.ndim == 2 and a.shape == (model.np, K):
            P = np.array(a)
        elif a.ndim <= 1:
            P = np.repeat(model.resolve_p(a)[:, None], K, axis=1)
        else:
            raise ValueError(f"`p` must have shape ({model.np},) or ({model.np}, {K}) for a "
                             f"batch of {K} runs, got {a.shape}")
    if callable(u):
        raise ValueError("`u` must be None or an array for a batch of runs (x0 of shape "
                         f"({nx}, K)): give samples of shape ({nu}, {n}) or ({nu}, {n}, K)")
    if u is None:  # (zeros cost nothing until written: no copies)
        return Batch(model, X0, t, P, np.zeros((K, n - 1, nu)), np.zeros((K, n - 1, nu)), True)
    a = np.asarray(finite_array(u, "u"), dtype=float)
    if a.shape == (nu,):
        U = np.broadcast_to(a, (K, n, nu))
    elif a.shape == (nu, n):
        U = np.broadcast_to(a.T, (K, n, nu))
    elif a.shape == (nu, n, K):
        U = a.transpose(2, 1, 0)
    else:
        raise ValueError(f"`u` must be None, ({nu},), ({nu}, {n}) or ({nu}, {n}, {K}) for "
                         f"a batch of {K} runs, got {a.shape}")
    return Batch(model, X0, t, P, np.ascontiguousarray(U[:, :-1]), np.ascontiguousarray(U[:, 1:]),
                 a.shape == (nu,))


def _mapped(fun, runs: int):
    """``fun`` mapped serially over ``runs`` runs (cached; no compile)."""
    key = ("batch_map", cache.function_key(fun), runs)
    return cache.get(key, lambda: fun.map(runs, "serial"), keepalive=fun)


def _parts(K: int, steps: int) -> tuple[list[slice], int]:
    """The runs of a batch in contiguous parts (sizes differing by at most one run) of about
    `PART_STEPS` run-steps of a chunk of ``steps`` steps, and at most `PART_RUNS` runs; and
    the threads that take them one after another as they finish (a thread slowed by other
    work on the machine takes fewer): one below `PARALLEL_STEPS` run-steps per chunk."""
    threads = min(BATCH_THREADS, K) if K * steps >= PARALLEL_STEPS else 1
    count = max(-(-K // PART_RUNS), threads if threads > 1 else 1,
                min(K, K * steps // PART_STEPS) if threads > 1 else 1)
    size, extra = divmod(K, count)
    edges = np.cumsum([0] + [size + 1] * extra + [size] * (count - extra))
    return [slice(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:])], threads


class _Lane:
    """One thread's arrays for the parts of a batch chunk: the inputs of the chunk
    Function mapped over up to ``capacity`` runs (runs first, casadi's column-major layout)
    and its output, bound to one buffer per map size, kept between chunks and calls (got
    with `borrow_state`: dropped with the chunk Function, which it does not hold).

    ``h_bits`` and ``u_bits`` are the bytes of the step sizes and of the constant control
    the arrays hold (None: not known), so that a repeated chunk writes neither again.
    """

    __slots__ = ("ref", "shapes", "capacity", "args", "out", "buffers", "h_bits", "u_bits")

    def __init__(self, ref, fun, capacity: int):
        self.ref = ref
        self.shapes = ([_run_shape(fun.size_in(i)) for i in range(fun.n_in())],
                       _run_shape(fun.size_out(0)))
        self.resize(capacity)

    def resize(self, capacity: int) -> None:
        """New arrays for ``capacity`` runs (the buffers bound to the old ones dropped)."""
        ins, out = self.shapes
        self.capacity = capacity
        self.args = [np.zeros((capacity,) + shape) for shape in ins]
        self.out = np.empty((capacity,) + out)
        self.buffers, self.h_bits, self.u_bits = {}, None, None

    def trigger(self, fun, runs: int):
        """The call of the chunk Function ``fun`` mapped over the first ``runs`` runs of
        the arrays (its buffer made and bound on first use)."""
        if runs > self.capacity:
            self.resize(runs)
        entry = self.buffers.get(runs)
        if entry is None:
            buf, trigger = _mapped(fun, runs).buffer()
            for i, a in enumerate(self.args):
                buf.set_arg(i, memoryview(a[:runs]))
            buf.set_res(0, memoryview(self.out[:runs]))
            entry = self.buffers[runs] = (buf, trigger)
        return entry[1]

    def put_h(self, h: np.ndarray) -> None:
        """The step sizes ``h (CHUNK,)`` of a chunk, the same for every run."""
        bits = h.tobytes()
        if bits != self.h_bits:
            self.args[2][:] = h[:, None]
            self.h_bits = bits


def _run_shape(size: tuple) -> tuple:
    """numpy shape of one run's slice of a casadi ``(rows, cols)`` matrix (column-major)."""
    rows, cols = size
    return (rows,) if cols == 1 else (cols, rows)  # (x0, n, p; h, controls, states)


@dataclass
class _Chunk:
    """Steps ``s0 .. s0 + n - 1`` of every run: substep ``s - k m`` of interval ``k = s // m``
    with sizes ``h (CHUNK,)`` (zero past ``n``); ``outputs`` the output columns they complete
    and ``ends`` the steps that end them (`interval_ends`)."""

    s0: int
    n: int
    s: np.ndarray
    k: np.ndarray
    h: np.ndarray
    outputs: slice
    ends: slice


class _FixedBatch:
    """The state of a fixed-step batch between chunks: ``x (K, n, nx)`` filled chunk by
    chunk, ``xk (K, nx)`` the states after the last chunk; and the runs' data by run."""

    def __init__(self, batch: Batch, m: int, x0: np.ndarray):
        K, nint, nx = batch.K, batch.nint, batch.model.nx
        self.batch, self.m = batch, m
        self.hm = np.diff(batch.t) / m
        self.x = np.empty((K, nint + 1, nx))
        self.x[:, 0] = x0.T
        self.xk = np.ascontiguousarray(x0.T)
        self.P = np.ascontiguousarray(batch.p.T)
        self.ua0 = np.ascontiguousarray(batch.ua[:, 0])  # (K, nu)
        self.slope = None if batch.constant else (  # (K, nint, nu)
            (batch.ub - batch.ua) / np.diff(batch.t)[None, :, None])
        self.constant = batch.constant or (not np.any(self.slope)
                                           and bool(np.all(batch.ua == batch.ua[:, :1])))

    def chunk(self, s0: int, n: int) -> _Chunk:
        """The data of the chunk of steps ``s0 .. s0 + n - 1`` shared by every run."""
        s = np.arange(s0, s0 + n)
        k = s // self.m
        h = np.zeros(CHUNK)
        h[:n] = self.hm[k]
        return _Chunk(s0, n, s, k, h, *interval_ends(s0, n, self.m))

    def advance(self, fun, lane: _Lane, runs: slice, c: _Chunk) -> None:
        """Chunk ``c`` of the runs ``runs`` (a contiguous part) by the chunk Function
        ``fun`` through ``lane``."""
        r = runs.stop - runs.start
        trigger = lane.trigger(fun, r)
        args = lane.args
        args[0][:r] = self.xk[runs]
        args[1][:r] = c.n
        lane.put_h(c.h)
        self._put_control(lane, runs, c)
        args[-1][:r] = self.P[runs]
        trigger()
        X = lane.out[:r]  # (r, CHUNK, nx)
        self.x[runs, c.outputs] = X[:, c.ends]
        self.xk[runs] = X[:, c.n - 1]

    def _put_control(self, lane: _Lane, runs: slice, c: _Chunk) -> None:
        """The control data of chunk ``c`` for ``runs`` into ``lane`` (a constant control:
        once, while the lane holds it)."""
        ua, ud = lane.args[3], lane.args[4]
        r, n = runs.stop - runs.start, c.n
        if self.constant:
            bits = self.ua0[runs].tobytes()
            if bits != lane.u_bits:
                ua[:r] = self.ua0[runs, None, :]
                ud[:r] = 0.0
                lane.u_bits = bits
            return
        lane.u_bits = None
        ud[:r, :n] = self.slope[runs, c.k]
        ua[:r, :n] = (self.batch.ua[runs, c.k]
                      + ((c.s - c.k * self.m) * c.h[:n])[None, :, None] * ud[:r, :n])
        ua[:r, n:] = 0.0
        ud[:r, n:] = 0.0


def fixed_batch(batch: Batch, method: str, m: int, jit: bool, x0: np.ndarray | None = None,
                progress: Progress | None = None) -> tuple[np.ndarray, np.ndarray, int, bool]:
    """``m`` steps of ``method`` per output interval for every run of ``batch`` (from
    ``x0 (nx, K)``, default ``batch.x0``), chunk by chunk; each chunk in one mapped call per
    part of the runs, the parts spread over `BATCH_THREADS` threads (`run_split`).

    Returns ``(x (nx, n, K), ok (K,), steps done per run, compiled)``: a run whose state
    became non-finite has its later columns NaN and ``ok`` False.
    """
    model, K = batch.model, batch.K
    fun, compiled = chunk_function(model, method, "linear", jit, CHUNK)
    total = m * batch.nint
    progress = Progress(None) if progress is None else progress
    progress.start(total)
    state = _FixedBatch(batch, m, batch.x0 if x0 is None else x0)
    parts, threads = _parts(K, min(CHUNK, total))
    capacity = parts[0].stop - parts[0].start

    def work(task):  # a thread's share of a chunk: the parts left, one at a time
        chunk, todo = task
        lane = borrow_state(fun, lambda ref: _Lane(ref, fun, capacity))
        for runs in iter(lambda: next(todo, None), None):
            state.advance(fun, lane, runs, chunk)
        return_state(fun, lane)  # (after an error, the next call makes another)

    done = 0
    with deferred_interrupts() if total > CHUNK else contextlib.nullcontext():
        for s0 in range(0, total, CHUNK):
            check_interrupt()
            chunk = state.chunk(s0, min(CHUNK, total - s0))
            # the threads share one list iterator of the parts (its `next` is atomic)
            run_split(work, [(chunk, iter(parts))] * threads)
            done = s0 + chunk.n
            progress.advance(chunk.n)
    progress.abandon(total - done)
    x, ok = _nan_after_failure(state.x)
    return x, ok, done, compiled


def _nan_after_failure(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``x (K, n, nx)`` as ``(nx, n, K)`` (a view) with NaN in every column of a run from
    its first non-finite one, and ``ok (K,)``: whether the run stayed finite."""
    K = x.shape[0]
    with np.errstate(over="ignore", invalid="ignore"):  # (a finite sum has finite terms)
        ok = np.isfinite(x.reshape(K, -1).sum(axis=1))
    for j in np.flatnonzero(~ok):
        finite = np.isfinite(x[j]).all(axis=1)
        ok[j] = finite.all()  # (or finite terms whose sum overflowed)
        if not ok[j]:
            x[j, int(np.argmax(~finite)):] = np.nan
    return x.transpose(2, 1, 0), ok


def _fixed_message(method: str, m: int, done: int, ok: np.ndarray) -> str:
    """The message of a fixed-step batch."""
    return (f"{method}: {m} step(s) per output interval, {done} steps per run, {ok.size} runs"
            + ("" if ok.all() else f"; {int((~ok).sum())} run(s) became non-finite"))


def run_fixed_batch(batch: Batch, method: str, m: int, jit: bool, x0: np.ndarray | None = None,
                    progress: Progress | None = None) -> tuple[np.ndarray, np.ndarray, Run]:
    """`fixed_batch` with its counts as a `Run` of one run (steps per run, right-hand sides
    per run) whose ``x`` is the batch stacked run by run ``(K nx, n)``: returns
    ``(x (nx, n, K), ok (K,), run)``."""
    x, ok, done, compiled = fixed_batch(batch, method, m, jit, x0, progress)
    K, nx, n = batch.K, batch.model.nx, batch.t.size
    stages = 4 if method == "lie" else TABLEAUX[method].stages
    stacked = np.ascontiguousarray(x.transpose(2, 0, 1).reshape(K * nx, n))
    return x, ok, Run(stacked, done, stages * done, m, compiled, bool(ok.all()),
                      _fixed_message(method, m, done, ok))


class BatchTarget:
    """`dynamics.integrate.auto`'s view of a batch: flat states stacked run by run
    (``x0 (K nx,)``, a run's ``x (K nx, n)``), one step count for all runs."""

    def __init__(self, batch: Batch):
        self.batch, self.t, self.runs = batch, batch.t, batch.K
        self.x0 = np.ascontiguousarray(batch.x0.T).reshape(-1)

    def _unstack(self, flat: np.ndarray) -> np.ndarray:
        return flat.reshape(self.batch.K, self.batch.model.nx).T

    def run(self, x0: np.ndarray, m: int, jit: bool, progress) -> Run:
        return run_fixed_batch(self.batch, "rk8", m, jit, self._unstack(x0), progress)[2]

    def spectrum(self, rtol, atol):
        b = self.batch
        J = map_eval(jacobian_x(b.model), [b.x0, b.ua[:, 0].T, b.p])  # (nx nx, K)
        nx = b.model.nx
        found = rho_sigma(J.T.reshape(b.K, nx, nx).transpose(0, 2, 1)) if np.all(np.isfinite(J)) else None
        if found is not None:
            return found
        return max(Single(b.problem(k)).spectrum(rtol, atol[k * nx:(k + 1) * nx])[0]
                   for k in range(b.K)), 0.0

    def rhs(self, X: np.ndarray, cols: np.ndarray) -> np.ndarray:
        b = self.batch
        K, nx, c = b.K, b.model.nx, cols.size
        U = np.concatenate([b.ua, b.ub[:, -1:]], axis=1)[:, cols]  # (K, c, nu)
        F = map_eval(b.model.f, [X.reshape(K, nx, c).transpose(1, 0, 2).reshape(nx, K * c),
                                 U.transpose(2, 0, 1).reshape(-1, K * c),
                                 np.repeat(b.p, c, axis=1)])
        return F.reshape(nx, K, c).transpose(1, 0, 2).reshape(K * nx, c)


def simulate_batch(batch: Batch, method: str, steps: int, rtol: float, atol: np.ndarray,
                   max_steps: int, jit, cvodes_options, progress: Progress, start: float
                   ) -> "BatchResult":
    """`simulate` for a batch (see the module docstring)."""
    K, nx = batch.K, batch.model.nx
    estimate = np.full(K, math.nan)
    if method in ("rk4", "rk8", "lie"):
        x, ok, n_steps, compiled = fixed_batch(batch, method, steps,
                                               cache.should_compile(jit, math.inf),
                                               progress=progress)
        status = np.where(ok, OK, FAILED)
        used, message = method, _fixed_message(method, steps, n_steps, ok)
    elif method == "cvodes":
        runs = [run_cvodes(batch.problem(k), rtol, atol, cvodes_options) for k in range(K)]
        x = np.stack([r.x for r in runs], axis=2)
        ok = np.array([r.ok for r in runs])
        status = np.where(ok, OK, FAILED)
        used, n_steps, compiled = "cvodes", max(r.n_steps for r in runs), False
        message = f"cvodes: {K} runs, one after another" + (
            "" if ok.all() else f"; {int((~ok).sum())} failed: {runs[int(np.argmin(ok))].message}")
    else:
        target = BatchTarget(batch)
        run, value, st, reason, n_steps, _ = auto_runs(target, rtol, np.tile(atol, K), max_steps,
                                                   jit, progress)
        if run is None and reason.startswith("stiff"):  # as a single run: auto's cvodes, per run
            outs = [solve_auto(batch.problem(k), rtol, atol, max_steps, jit, cvodes_options,
                               progress) for k in range(K)]
            x = np.stack([o[0].x for o in outs], axis=2)
            ok = np.array([o[0].ok for o in outs])
            status = np.array([o[2] if o[0].ok else FAILED for o in outs])
            estimate[:] = [o[3] for o in outs]
            used, compiled = "cvodes", False
            n_steps = max(o[0].n_steps for o in outs)
            message = f"auto, run by run ({K} runs): {outs[int(np.argmax(status != OK_STIFF))][0].message}"
        elif run is None:  # too many steps: no rk8 run was made
            x = np.full((nx, batch.t.size, K), np.nan)
            x[:, 0] = batch.x0
            ok, status = np.zeros(K, bool), np.full(K, st if st else UNVERIFIED)
            used, message, compiled = "rk8", f"auto: tolerance not verified: {reason}", False
        else:
            x = run.x.reshape(K, nx, -1).transpose(1, 2, 0).copy()
            ok = np.isfinite(x).all(axis=(0, 1))
            status = np.where(ok, st, FAILED)
            estimate[:] = value
            used, compiled = "rk8", run.compiled
            verdict = {OK: f"estimated error {value:.2g} of tolerance (the largest over the runs)",
                       ROUNDOFF: "tolerance not verified: at the round-off floor of fixed-step runs",
                       UNVERIFIED: f"tolerance not verified: {reason}",
                       FAILED: "a run became non-finite"}.get(st, "")
            message = f"auto: {run.message}; {verdict}"
    x.setflags(write=False)
    return BatchResult(t=batch.t, x=x, success=ok & np.isin(status, (OK, OK_STIFF)),
                       status=status, message=message, method=used,
                       wall_time=time.perf_counter() - start, n_steps=int(n_steps),
                       error_estimate=estimate, compiled=bool(compiled), _batch=batch)


@dataclass(frozen=True)
class BatchResult:
    """What `simulate` returns for a batch of K runs (``x0`` of shape ``(nx, K)``).

    Attributes
    ----------
    t : ndarray, shape (n,) [s]
    x : ndarray, shape (nx, n, K)
        Run ``k`` is ``x[:, :, k]`` (read-only).
    success : ndarray of bool, shape (K,)
        Run ``k`` finished with finite states and, for ``auto``, its error estimate meets
        the tolerance.
    status : ndarray of int, shape (K,)
        `SimulationResult`'s codes per run (0 ok, 1 ok with cvodes, 2 round-off floor,
        3 not verified, -1 failed).
    message : str
    method : str
        The method used.
    wall_time : float [s]
    n_steps : int
        Steps per run (``auto``: summed over its runs; cvodes: the most of any run).
    error_estimate : ndarray, shape (K,)
        ``auto``: the estimated global error in units of the tolerance, the largest over
        the batch (one step count serves all runs; a stiff batch, run by run with cvodes:
        each run's own); NaN for the other methods.
    compiled : bool
    """

    t: np.ndarray
    x: np.ndarray
    success: np.ndarray
    status: np.ndarray
    message: str
    method: str
    wall_time: float
    n_steps: int
    error_estimate: np.ndarray
    compiled: bool
    _batch: Batch

    def __len__(self) -> int:
        return self.x.shape[2]

    @property
    def all_success(self) -> bool:
        """Whether every run succeeded."""
        return bool(np.all(self.success))

    def run(self, k: int) -> SimulationResult:
        """Run ``k`` as a `SimulationResult` (dense output, invariants, drift)."""
        k = integer(k, "k", minimum=0)
        if k >= len(self):
            raise ValueError(f"`k` must be below the number of runs {len(self)}, got {k}")
        b = self._batch
        problem = b.problem(k)
        x = self.x[:, :, k]
        return SimulationResult(
            t=self.t, x=x, success=bool(self.success[k]), status=int(self.status[k]),
            message=self.message, method=self.method, wall_time=self.wall_time,
            n_steps=self.n_steps, n_rhs=0, substeps=0, error_estimate=float(self.error_estimate[k]),
            compiled=self.compiled, invariants=MappingProxyType({}),
            _dense=Dense(b.model, problem.p, lambda: problem.control.grid(problem.t)))
