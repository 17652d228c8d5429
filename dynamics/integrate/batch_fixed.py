"""The fixed-step engine of a batch (`dynamics.integrate.batch`): the runs of each chunk of
steps in contiguous parts, each part one call of the model's compiled chunk loop of
``loops.BATCH_CHUNK`` steps mapped serially over its runs, the parts spread over the
machine's cores (`batch_threads` threads, `dynamics.executors.run_split`; a compiled call
releases the GIL), each thread taking the next part as it finishes, through arrays it keeps
bound to the mapped call between chunks and calls (`_Lane`). The runs are independent and
each is computed alone whatever part or thread takes it: the answers are the same bits for
every thread count."""
from __future__ import annotations

import contextlib
import os
from dataclasses import dataclass
import numpy as np

from appdyn.config import param

from .. import cache
from ..validate import integer
from ..executors import run_split
from ..interrupts import check_interrupt, deferred_interrupts
from .cpass import pass_library
from .evaluate import borrow_state, return_state
from .inputs import Batch
from .lanes import lanes_library
from .loops import BATCH_CHUNK as CHUNK
from .loops import Progress, chunk_function, interval_ends
from .result import Run
from .tableaux import TABLEAUX

__all__ = ["fixed_batch", "run_fixed_batch", "fixed_message", "batch_threads", "spread_runs",
           "BATCH_THREADS", "PART_RUNS", "PART_STEPS", "PARALLEL_STEPS"]

#: The cores this process may use (``os.sched_getaffinity``; the CPU count where there is
#: none): the threads of a batch unless told otherwise (`batch_threads`).
BATCH_THREADS = max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
                    else os.cpu_count() or 1)


def batch_threads(threads: int | None) -> int:
    """The threads a batch of runs is spread over: ``threads`` if given, else the registered
    default ``appdyn.config`` ``"dynamics.threads"``, else `BATCH_THREADS` (the cores this
    process may use). ``1`` runs the batch in the calling thread alone.

    Raises
    ------
    TypeError, ValueError
        Naming ``threads`` when it is not an integer ``>= 1`` (nor None).

    Examples
    --------
    >>> from appdyn import config
    >>> from appdyn.dynamics.integrate.batch_fixed import batch_threads
    >>> batch_threads(3)
    3
    >>> with config.using("dynamics", threads=1):
    ...     batch_threads(None)
    1
    """
    value = param("dynamics.threads", threads)
    return BATCH_THREADS if value is None else integer(value, "threads", minimum=1)


#: Run-steps of a constant-control rk8 batch from which its vector-lane loop is compiled
#: (`lanes.lanes_library`, ~0.4 s once per model on an idle machine, then kept on disk):
#: about 25 ms of the scalar loop, which the lanes cut 2-3x.
LANES_BUILD = 1 << 16

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


def _mapped(fun, runs: int):
    """``fun`` mapped serially over ``runs`` runs (cached; no compile)."""
    key = ("batch_map", cache.function_key(fun), runs)
    return cache.get(key, lambda: fun.map(runs, "serial"), keepalive=fun)


def _parts(K: int, steps: int, threads: int) -> tuple[list[slice], int]:
    """The runs of a batch in contiguous parts (sizes differing by at most one run) of about
    `PART_STEPS` run-steps of a chunk of ``steps`` steps, and at most `PART_RUNS` runs; and
    the threads (at most ``threads``) that take them one after another as they finish (a
    thread slowed by other work on the machine takes fewer): one below `PARALLEL_STEPS`
    run-steps per chunk."""
    threads = min(threads, K) if K * steps >= PARALLEL_STEPS else 1
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


def fixed_batch(batch: Batch, method: str, m: int, jit: bool, *, x0: np.ndarray | None = None,
                progress: Progress | None = None,
                threads: int | None = None) -> tuple[np.ndarray, np.ndarray, int, bool]:
    """``m`` steps of ``method`` per output interval for every run of ``batch`` (from
    ``x0 (nx, K)``, default ``batch.x0``), chunk by chunk; each chunk in one mapped call per
    part of the runs, the parts spread over ``threads`` threads (`batch_threads`,
    `run_split`). Compiled ``rk8`` under constant controls without a progress callback:
    every run in one plain C loop over its steps (`cpass._FIXED`, parts of the runs spread
    over the threads by `spread_runs`).

    Returns ``(x (nx, n, K), ok (K,), steps done per run, compiled)``: a run whose state
    became non-finite has its later columns NaN and ``ok`` False.
    """
    model, K = batch.model, batch.K
    threads = batch_threads(threads)
    total = m * batch.nint
    progress = Progress(None) if progress is None else progress
    progress.start(total)
    state = _FixedBatch(batch, m, batch.x0 if x0 is None else x0)
    if method == "rk8" and jit and state.constant and progress.fun is None:
        # (a progress callback is told after every chunk: the chunk loop below)
        lib = pass_library(model)
        if lib is not None:  # one plain C loop over the runs (`cpass._FIXED`), its runs
            # in the lanes of the vector registers when the step allows (`lanes`)
            # (compiled for a batch of `LANES_BUILD` run-steps or more; a smaller one uses
            # it once built: the same bits either way)
            lanes = lanes_library(model, build=K * total >= LANES_BUILD) if K > 1 else None
            _c_loop(lib.fixed_many if lanes is None else lanes, state, m, threads)
            progress.advance(total)
            x, ok = _nan_after_failure(state.x)
            return x, ok, total, True
    fun, compiled = chunk_function(model, method, "linear", jit, size=CHUNK)
    parts, threads = _parts(K, min(CHUNK, total), threads)
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


#: Most run-steps of one call of a compiled loop over the runs (`spread_runs`: ~10 ms on
#: the rigid body, so that a Ctrl-C is seen within a second on two threads).
C_PART_STEPS = 1 << 15

#: Parts of a batch per thread at least (a thread slowed by other work takes fewer).
PARTS_PER_THREAD = 8

#: Parts per thread between two looks at Ctrl-C.
GROUP = 16


def spread_runs(call, K: int, threads: int, part: int) -> None:
    """``call(k0, k1)`` (a compiled loop over the runs ``k0 <= k < k1`` that releases the
    GIL and writes only those runs' slices of its outputs) for every run of a batch of
    ``K``: the runs in contiguous parts of at most ``part`` runs, and at most ``K / (threads
    PARTS_PER_THREAD)`` when spread, taken one after another by ``threads`` threads of the
    process's pool as they finish (`run_split`); Ctrl-C is looked at between groups of
    `GROUP` parts per thread (`deferred_interrupts`). ``threads=1``: every part in the
    calling thread, in order."""
    if threads > 1:
        part = min(part, -(-K // (threads * PARTS_PER_THREAD)))
    part = max(1, part)
    parts = [(a, min(a + part, K)) for a in range(0, K, part)]
    threads = min(threads, len(parts))

    def work(todo):
        for k0, k1 in iter(lambda: next(todo, None), None):
            call(k0, k1)

    with deferred_interrupts():
        for i in range(0, len(parts), GROUP * threads):
            check_interrupt()
            group = iter(parts[i:i + GROUP * threads])  # (its `next` is atomic)
            run_split(work, [group] * threads)


def _c_loop(fixed_many, state: "_FixedBatch", m: int, threads: int) -> None:
    """Every run of ``state`` (constant controls) by the compiled ``rk8_fixed_many`` into
    ``state.x``, the runs in parts of at most `C_PART_STEPS` run-steps spread over
    ``threads`` threads (`spread_runs`; one when the batch has fewer than
    `PARALLEL_STEPS` run-steps)."""
    batch = state.batch
    K, nu, np_ = batch.K, batch.model.nu, batch.model.np
    H = np.ascontiguousarray(np.diff(batch.t))
    x0 = np.ascontiguousarray(state.xk)
    u = np.zeros((K, max(nu, 1)))
    u[:, :nu] = state.ua0
    p = np.zeros((K, max(np_, 1)))
    p[:, :np_] = state.P
    X = state.x
    addr = (H.ctypes.data, x0.ctypes.data, u.ctypes.data, p.ctypes.data, X.ctypes.data)
    steps = m * batch.nint
    spread_runs(lambda k0, k1: fixed_many(k0, k1, batch.nint, m, *addr), K,
                threads if K * steps >= PARALLEL_STEPS else 1, C_PART_STEPS // steps)


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


def fixed_message(method: str, m: int, done: int, ok: np.ndarray) -> str:
    """The message of a fixed-step batch."""
    return (f"{method}: {m} step(s) per output interval, {done} steps per run, {ok.size} runs"
            + ("" if ok.all() else f"; {int((~ok).sum())} run(s) became non-finite"))


def run_fixed_batch(batch: Batch, method: str, m: int, jit: bool, *, x0: np.ndarray | None = None,
                    progress: Progress | None = None,
                    threads: int | None = None) -> tuple[np.ndarray, np.ndarray, Run]:
    """`fixed_batch` with its counts as a `Run` of one run (steps per run, right-hand sides
    per run) whose ``x`` is the batch stacked run by run ``(K nx, n)``: returns
    ``(x (nx, n, K), ok (K,), run)``."""
    x, ok, done, compiled = fixed_batch(batch, method, m, jit, x0=x0, progress=progress,
                                        threads=threads)
    K, nx, n = batch.K, batch.model.nx, batch.t.size
    stages = 4 if method == "lie" else TABLEAUX[method].stages
    stacked = np.ascontiguousarray(x.transpose(2, 0, 1).reshape(K * nx, n))
    return x, ok, Run(stacked, done, stages * done, m, compiled, bool(ok.all()),
                      fixed_message(method, m, done, ok))
