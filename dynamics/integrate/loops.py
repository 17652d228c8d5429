"""Fixed-step runs: the chunk Function of a model (`chunks`, optionally jit-compiled; the
compiled pass's for a model whose right-hand side is called: `cpass.pass_chunk`) and the
Python loop over chunks that runs it."""
from __future__ import annotations

import math
from typing import Callable

import numpy as np

from .. import cache
from ..interrupts import check_interrupt, deferred_interrupts
from ..model import Model
from .chunks import BATCH_CHUNK, CHUNK, build_chunk, chunk_compile_job, chunk_job, chunk_key
from .cpass import pass_chunk
from .evaluate import borrow_bound, return_bound
from .inputs import Problem
from .result import Run
from .tableaux import TABLEAUX, unique_nodes

__all__ = ["CHUNK", "BATCH_CHUNK", "Progress", "chunk_compile_job", "chunk_function",
           "chunk_key", "interval_ends", "run_fixed", "run_short"]


def chunk_function(model: Model, method: str, mode: str, jit: bool, *, size: int = CHUNK):
    """The chunk Function of ``model`` and ``method`` (cached); returns (Function, compiled).

    ``size`` steps per chunk (default `CHUNK`; batches use the shorter `BATCH_CHUNK`, a
    second compiled Function per model and method).

    Inputs ``mode == 'linear'``: ``x0 (nx)``, ``n`` the number of steps to take (the rest
    are skipped), ``h (1 x B)`` step sizes, ``ua (nu x B)`` control at the start of each
    step, ``ud (nu x B)`` its slope [1/s], ``p (np)``. ``mode == 'stages'``: ``x0``, ``n``,
    ``h``, ``us (nu*s x B)`` control at the distinct stage nodes of each step, ``p``.
    Output ``X (nx x B)``: the state after each step.
    """
    base_key = chunk_key(model, method, mode)
    if size != CHUNK:
        base_key += (size,)
    if not jit or cache.compiler() is None:
        return cache.get(base_key + (False,),
                         lambda: (build_chunk(model, method, mode, size=size), False),
                         keepalive=model.f)

    def build_compiled():
        if method == "rk8" and mode == "linear":  # (None: not a model whose rhs is called)
            result = pass_chunk(model, size)
            if result is not None:
                return result, True
        result = cache.compile_parallel([chunk_job(model, method, mode, size)])[0]
        if result is None or isinstance(result, RuntimeError):  # e.g. a right-hand side
            return build_chunk(model, method, mode, size=size), False  # that is not generated
        return result, True

    return cache.get(base_key + (True,), build_compiled, keepalive=model.f)


def _stage_samples(problem: Problem, method: str, m: int) -> np.ndarray:
    """Callable control at the distinct stage nodes of every step: shape (nint, m, s, nu)."""
    nodes = np.array(unique_nodes(method))
    t = problem.t
    h = np.diff(t) / m
    offsets = np.arange(m)[None, :, None] + nodes[None, None, :]
    times = t[:-1, None, None] + offsets * h[:, None, None]
    fun, nu = problem.control.fun, problem.model.nu
    values = np.empty(times.shape + (nu,))
    flat_t, flat_v = times.reshape(-1), values.reshape(-1, nu)
    for i, ti in enumerate(flat_t):
        flat_v[i] = fun(float(ti))
    return values


class _Steps:
    """Per-step data of a fixed-step run, written a chunk at a time (padded to ``CHUNK``)
    into the input arrays of the chunk Function's `BoundBuffer`.

    Step ``s`` is substep ``j = s mod m`` of output interval ``k = s // m``: size
    ``h = H_k / m``; linear control ``ua = u_k + j h ud_k`` with slope ``ud_k``; or, for a
    callable control, its samples at the step's stage times.
    """

    def __init__(self, problem: Problem, method: str, m: int):
        self.m, self.total = m, m * problem.nint
        t = problem.t
        H = t[1:] - t[:-1]
        self.hm = H if m == 1 else H / m  # H / 1 is H
        ctrl = problem.control
        self.mode = ctrl.mode
        if self.mode == "linear":
            self.ua = ctrl.ua
            self.constant = ctrl.constant or _constant(ctrl, H)
            if self.constant:
                self._ua0 = ctrl.ua[0]
                self._tag = self._ua0.tobytes()  # the constant's bits (never None)
            else:
                self.ud = (ctrl.ub - ctrl.ua) / H[:, None]
        else:
            s = _stage_samples(problem, method, m)  # (nint, m, nodes, nu)
            self.us = s.reshape(self.total, -1)

    def fill(self, s0: int, buffer) -> int:
        """Write the data of steps ``s0 .. s0 + CHUNK - 1`` into ``buffer.args[2:-1]``
        (``h`` and the control data; zero past the run's end, a constant control on every
        row); returns the number of steps ``n`` of the chunk.

        ``buffer.tag`` is ``[steps written into h, control written]``: ``h`` past the
        chunk is zeroed only where a longer chunk left values, and a constant control
        already in the buffer is not written again."""
        n = min(CHUNK, self.total - s0)
        if self.m == 1:
            _put_h(buffer, self.hm[s0:s0 + n], n)
        else:
            _put_h(buffer, self.hm[np.arange(s0, s0 + n) // self.m], n)
        args, tag, h = buffer.args, buffer.tag, buffer.args[2]
        if self.mode != "linear":
            us = args[3]
            us[:n] = self.us[s0:s0 + n]
            us[n:] = 0.0
            tag[1] = None
        elif self.constant:
            _put_constant(buffer, self._ua0, self._tag)
        else:
            ua, ud = args[3], args[4]
            s = np.arange(s0, s0 + n)
            k = s // self.m
            ud[:n] = self.ud[k]
            ud[n:] = 0.0
            ua[:n] = self.ua[k] + ((s - k * self.m) * h[:n])[:, None] * ud[:n]
            ua[n:] = 0.0
            tag[1] = None
        return n


def _put_h(buffer, hvals, n: int) -> None:
    """``h`` of a chunk of ``n`` steps into ``buffer`` (zero past ``n``; see `_Steps.fill`)."""
    tag = buffer.tag
    if tag is None:
        tag = buffer.tag = [CHUNK, None]
    h = buffer.args[2]
    if hvals is not None:  # (None: the caller writes h[:n])
        h[:n] = hvals
    if tag[0] > n:
        h[n:tag[0]] = 0.0
    tag[0] = n


def _put_constant(buffer, ua0, bits: bytes) -> None:
    """A constant control ``ua0`` (its ``bits``) on every row of ``buffer``'s ``ua``, zero
    slope; not written again when the buffer already holds it."""
    tag = buffer.tag
    if tag[1] != bits:
        args = buffer.args
        args[3][:] = ua0
        args[4][:] = 0.0
        tag[1] = bits


def _constant(ctrl, H: np.ndarray) -> bool:
    """Whether a linear control is one value on every interval (zero slope)."""
    return (not np.any((ctrl.ub - ctrl.ua) / H[:, None])
            and bool(np.all(ctrl.ua == ctrl.ua[:1])))


def interval_ends(s0: int, n: int, m: int) -> tuple[slice, slice]:
    """Which output columns a chunk of steps ``s0 .. s0 + n - 1`` (``m`` per output
    interval) completes, and the chunk's steps that end them: ``(outputs, steps)``."""
    k_lo, k_hi = (s0 + m) // m - 1, (s0 + n) // m  # intervals ending in this chunk
    return slice(k_lo + 1, k_hi + 1), slice(m - 1 - s0 % m, n, m)


class Progress:
    """Counts steps for a ``progress(done, total)`` callback across all runs of one call:
    ``total`` grows by each run's step count when the run starts, plus ``ahead`` (the steps a
    caller that may start another run, as ``auto`` does, expects next), so ``done`` reaches
    the reported total once, at `finish`, and the reported total never falls."""

    def __init__(self, fun: Callable | None):
        self.fun, self.done, self.total, self.ahead, self.shown = fun, 0, 0, 0, 0
        self.stepped = 0  # steps of the adaptive passes (`step`)

    def start(self, n: int):
        self.total += n

    def advance(self, n: int):
        self.done += n
        if self.fun is not None:
            self.shown = max(self.shown, self.total + self.ahead,
                             self.done + (1 if self.ahead else 0))
            self.fun(self.done, self.shown)

    def step(self, n: int, fraction: float):
        """``n`` steps of an adaptive pass done, ``fraction`` of its output intervals reached:
        the steps still ahead are extrapolated from the rate so far."""
        self.stepped += n
        self.start(n)
        if fraction > 0:  # (at least 1 until `finish`: a run may follow the pass)
            self.ahead = max(1, int(self.stepped * (1.0 - min(fraction, 1.0)) / fraction))
        self.advance(n)

    def abandon(self, n: int):
        self.total -= n

    def finish(self):
        """Report the end of the call: ``(done, done)`` where steps were counted."""
        if self.fun is not None and self.done and self.shown != self.done:
            self.shown = self.done
            self.fun(self.done, self.done)


def run_fixed(problem: Problem, method: str, m: int, jit: bool,
              *, progress: Progress | None = None) -> Run:
    """``m`` steps of ``method`` per output interval, chunk by chunk; stops at a non-finite
    state (the columns not reached are NaN)."""
    model, nint, t = problem.model, problem.nint, problem.t
    mode = problem.control.mode
    fun, compiled = chunk_function(model, method, mode, jit)
    steps = _Steps(problem, method, m)
    progress = Progress(None) if progress is None else progress
    progress.start(steps.total)
    nx = model.nx
    x = np.empty((nx, nint + 1))
    x.fill(np.nan)  # (`np.full` costs twice as much)
    x[:, 0] = problem.x0
    stages = 4 if method == "lie" else TABLEAUX[method].stages
    done = 0
    buffer = borrow_bound(fun, lambda: (_chunk_shapes(model, method, mode), (CHUNK, nx)))
    buffer.args[0][:] = problem.x0
    buffer.args[-1][:] = problem.p
    # Ctrl-C is deferred to the next chunk of a run of several chunks (a one-chunk run is
    # over in well under a second and skips the ~13 us of handler switching)
    if steps.total > CHUNK:
        with deferred_interrupts():
            done = _chunks(steps, buffer, x, m, progress)
    else:
        done = _chunks(steps, buffer, x, m, progress)
    # given back only after a run that ended normally: after an exception (a Ctrl-C between
    # two writes) its contents may not be what its tag says, and the next run makes another
    return_bound(fun, buffer)
    progress.abandon(steps.total - done)
    n_steps = done
    if done < steps.total or not _all_finite(x):
        k = int(np.argmax(~np.isfinite(x).all(axis=0)))
        x[:, k:] = np.nan
        return Run(x, n_steps, stages * n_steps, m, compiled, False,
                   f"{method}: the state became non-finite before t = {t[k]:.6g}")
    return Run.new(x, n_steps, stages * n_steps, m, compiled, True,
                   f"{method}: {m} step(s) per output interval, {n_steps} steps")


def run_short(model: Model, x0: np.ndarray, t: np.ndarray, p: np.ndarray, method: str,
              m: int, jit: bool) -> Run | None:
    """`run_fixed` of the common short run, without its general machinery: zero control
    (``u=None``), all ``m (len(t) - 1)`` steps in one chunk, no progress callback. The same
    compiled call on the same inputs, so the same ``x`` to the bit; ``None`` when the run is
    not such a run or its state became non-finite (`run_fixed` then runs and tells)."""
    nint = t.size - 1
    total = m * nint
    if total > CHUNK:
        return None
    fun, compiled = chunk_function(model, method, "linear", jit)
    nx = model.nx
    buffer = borrow_bound(fun, lambda: (_chunk_shapes(model, method, "linear"), (CHUNK, nx)))
    args = buffer.args
    args[0][:] = x0
    args[1][0] = total
    args[-1][:] = p
    if m == 1:  # h = t[1:] - t[:-1], as `_Steps` (a float difference, the same in Python)
        _put_h(buffer, None, total)
        h = args[2]
        if total <= 4:
            v = t.tolist()
            for i in range(total):
                h[i] = v[i + 1] - v[i]
        else:
            np.subtract(t[1:], t[:-1], out=h[:total])
    else:
        _put_h(buffer, ((t[1:] - t[:-1]) / m)[np.arange(total) // m], total)
    _put_constant(buffer, 0.0, bytes(8 * model.nu))  # == zeros(nu).tobytes(), as `_Steps`
    check_interrupt()
    buffer.trigger()
    x = np.empty((nx, nint + 1))
    x[:, 0] = x0
    x[:, 1:] = buffer.out[m - 1:total:m].T  # the steps that end the intervals
    return_bound(fun, buffer)
    if not _all_finite(x):
        return None
    stages = 4 if method == "lie" else TABLEAUX[method].stages
    return Run.new(x, total, stages * total, m, compiled, True,
                   f"{method}: {m} step(s) per output interval, {total} steps")


def _chunks(steps: _Steps, buffer, x: np.ndarray, m: int, progress: Progress) -> int:
    """`run_fixed`'s loop over chunks (``buffer`` holds ``x0`` and ``p``): fills ``x``;
    returns the steps done (fewer than planned after a non-finite state)."""
    args, X, trigger = buffer.args, buffer.out, buffer.trigger
    done = 0
    for s0 in range(0, steps.total, CHUNK):
        check_interrupt()
        n = steps.fill(s0, buffer)
        args[1][0] = n
        trigger()
        outputs, ends = interval_ends(s0, n, m)
        x[:, outputs] = X[ends].T
        xk = X[n - 1]
        args[0][:] = xk
        done = s0 + n
        progress.advance(n)
        if done < steps.total and not np.isfinite(xk).all():
            break  # (after the last chunk, the check of x in `run_fixed` tells)
    return done


def _all_finite(x: np.ndarray) -> bool:
    """``np.isfinite(x).all()``, for a small ``x`` in Python (a third of the time)."""
    if x.size <= 64:
        return all(map(math.isfinite, x.ravel().tolist()))
    return bool(np.isfinite(x).all())


def _chunk_shapes(model: Model, method: str, mode: str) -> list:
    """numpy shapes of the chunk Function's inputs (casadi's column-major layout)."""
    if mode == "linear":
        data = [(CHUNK, model.nu), (CHUNK, model.nu)]
    else:
        data = [(CHUNK, model.nu * len(unique_nodes(method)))]
    return [(model.nx,), (1,), (CHUNK,)] + data + [(model.np,)]
