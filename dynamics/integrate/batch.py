"""Batched simulation: K runs of one model on one output grid, in compiled loops over the
runs spread over the cores.

`simulate` comes here when ``x0`` has shape ``(nx, K)``. Every run shares the grid and the
method; each has its own initial state, parameters (``p`` of shape ``(np, K)``) and control
samples (``u`` of shape ``(nu, n, K)``). The runs are independent: the threads of the
process's pool (``simulate(..., threads=)``, default the cores this process may use,
`batch_fixed.batch_threads`) take them as they finish, in contiguous parts
(`batch_fixed.spread_runs`) or one run at a time (`dense.dense_many`), each filling its own
runs' slices of the result, so the answers are the same bits for every thread count.
``auto`` on a smooth model under controls constant over each run: every run's answer,
check run and verdict in one compiled loop (`dense.dense_many`), each run with its own
steps and its own check; the runs in
two rounds (`dense_rounds`, each spread over the batch), the first round's runs the single
call's answers to the last bit, the second round's first answers at the local tolerance
the first round's runs show to cost the fewest steps (`first_factor`: over-delivery weighed
against retries), each of its runs the single call's answer at that first tolerance;
under controls that vary within a run, every run's one-pass answer and check (the single
call's `auto.one_pass`) in one compiled loop over the runs (`auto_pass_batch`), each judged
as its single call judges it, a run not answered there alone as a single call; otherwise
auto's multi-run error control over the whole batch (one step count for all runs; a stiff
or non-smooth batch goes run by run as single runs do). The fixed-step
methods: under constant controls, compiled rk8 is a plain C loop over each run's steps
(`lanes`: four runs per vector step where the model's step allows); otherwise the model's
compiled chunk loop mapped over the parts (`dynamics.integrate.batch_fixed`). ``cvodes``
(a variable-step integrator per run) is a loop of single runs.
"""
from __future__ import annotations

import math
import time
from functools import partial
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

from .. import cache
from ..model import Model
from ..validate import integer
from .adaptive import run_pass_many
from .auto import (PASS_MEASURED, PASS_THETA, PASS_ULPS, STIFF_STEPS, Single, auto_jit,
                   auto_runs, dense_outcome, pass_verdict, rounding_bounds,
                   sizes_over_tolerance, solve_auto)
from .batch_fixed import (BATCH_THREADS, batch_threads, fixed_batch, fixed_message,
                          run_fixed_batch)
from .cvodes import run_cvodes
from .dense import HEADER as DENSE_HEADER
from .dense import FIELDS as DENSE_FIELDS
from .dense import FIRST, TRIES, dense_many, outcome_of
from .estimates import AUTO_ACCEPT, EPS, FLOOR_ULPS, jacobian_x, rho_sigma
from .evaluate import map_eval
from .inputs import Batch, RunOptions, check_batch
from .lanes import dense_lanes
from .loops import Progress
from ..figures import plot_signals
from ..results import Result
from .result import (FAILED, OK, OK_STIFF, ROUNDOFF, UNVERIFIED, VIOLATED, Dense,
                     Run, SimulationResult)
from .smoothness import nonsmooth_operations
from .sanity import remedy, violations
from .stepcontrol import LOCAL_RTOL_MIN, run_dop853, run_stepped_many

__all__ = ["Batch", "BatchResult", "check_batch", "simulate_batch", "BATCH_THREADS",
           "first_factor", "dense_rounds"]  # (Batch,
# check_batch: `inputs`, here for the callers that import them from this module)

class BatchTarget:
    """`dynamics.integrate.auto`'s view of a batch: flat states stacked run by run
    (``x0 (K nx,)``, a run's ``x (K nx, n)``), one step count for all runs."""

    def __init__(self, batch: Batch, threads: int | None = None):
        self.batch, self.t, self.runs, self.threads = batch, batch.t, batch.K, threads
        self.nonsmooth = nonsmooth_operations(batch.model.f)  # (as `Single.nonsmooth`)
        self.x0 = np.ascontiguousarray(batch.x0.T).reshape(-1)

    def _unstack(self, flat: np.ndarray) -> np.ndarray:
        return flat.reshape(self.batch.K, self.batch.model.nx).T

    def run(self, x0: np.ndarray, m: int, jit: bool, progress) -> Run:
        return run_fixed_batch(self.batch, "rk8", m, jit, x0=self._unstack(x0),
                               progress=progress, threads=self.threads)[2]

    def spectrum(self, rtol, atol):
        b = self.batch
        nx = b.model.nx
        J = _jacobians(b, np.arange(b.K))
        found = rho_sigma(J)
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


def simulate_batch(batch: Batch, options: RunOptions, *, start: float) -> "BatchResult":
    """`simulate` for a batch (see the module docstring); ``options`` checked (its
    ``progress`` a `Progress`), ``start`` the `time.perf_counter` of the call."""
    method, steps, rtol, atol = options.method, options.steps, options.rtol, options.atol
    max_steps, jit, cvodes_options = options.max_steps, options.jit, options.cvodes_options
    progress: Progress = options.progress
    K, nx = batch.K, batch.model.nx
    estimate = np.full(K, math.nan)
    if method in ("rk4", "rk8", "lie"):
        x, ok, n_steps, compiled = fixed_batch(batch, method, steps,
                                               cache.should_compile(jit, math.inf),
                                               progress=progress, threads=options.threads)
        status = np.where(ok, OK, FAILED)
        used, message = method, fixed_message(method, steps, n_steps, ok)
        status, message = _sane(batch, x, ok, status, message, method)
    elif method in ("cvodes", "dop853"):
        compile_ = cache.should_compile(jit, math.inf)
        plain = dop853_dense_batch(batch, rtol, atol, max_steps, threads=options.threads) \
            if method == "dop853" and compile_ else None
        stepped = run_stepped_many(batch.model, batch.x0.T, batch.t, batch.ua, batch.ub,
                                   batch.p.T, rtol, atol, max_steps,
                                   threads=batch_threads(options.threads)) \
            if plain is None and method == "dop853" and compile_ else None
        if plain is not None or stepped is not None:
            if plain is not None:  # (one compiled loop over the runs)
                x, ok, each, failed = plain
                how = "in one compiled loop"
            else:  # (the compiled stepper per run, in one loop: steps ending on the grid)
                X, runs = stepped
                x, ok, each = X.transpose(1, 2, 0), runs.ok, runs.steps
                failed = "" if ok.all() else runs(int(np.argmin(ok))).message
                how = "each by the compiled stepper, its steps ending on the grid"
            compiled, n_steps = True, int(each.max())
            progress.step(int(each.sum()), 1.0)  # (the loops tell no one: once, at the end)
        else:
            runs = [run_cvodes(batch.problem(k), rtol, atol, cvodes_options) if method == "cvodes"
                    else run_dop853(batch.problem(k), rtol, atol, max_steps, compiled=compile_,
                                    progress=progress) for k in range(K)]
            x = np.stack([r.x for r in runs], axis=2)
            ok = np.array([r.ok for r in runs])
            n_steps, how = max(r.n_steps for r in runs), "one after another"
            compiled = method == "dop853" and all(r.compiled for r in runs)
            failed = "" if ok.all() else runs[int(np.argmin(ok))].message
        status, used = np.where(ok, OK, FAILED), method
        message = f"{method}: {K} runs, {how}" + (
            "" if ok.all() else f"; {int((~ok).sum())} failed: {failed}")
        if method == "dop853":
            status, message = _sane(batch, x, ok, status, message, method)
    else:
        target = BatchTarget(batch, options.threads)
        dense = None if target.nonsmooth else (
            auto_dense_batch(batch, rtol, atol, max_steps, jit, cvodes_options, progress,
                             threads=options.threads)
            or auto_pass_batch(batch, rtol, atol, max_steps, jit, cvodes_options, progress,
                               threads=options.threads))
        if dense is not None:
            x, ok, status, estimate, used, n_steps, message = dense
            compiled = True
            run = None
        elif target.nonsmooth:  # each run with its own step control (`stepcontrol`)
            run, st, reason = None, 0, "non-smooth"
        else:
            run, value, st, reason, n_steps, _ = auto_runs(target, rtol, np.tile(atol, K),
                                                       max_steps, jit, progress)
        if dense is not None:
            pass
        elif run is None and reason.startswith(("stiff", "non-smooth")):
            # as single runs: auto's cvodes, or its step control, per run
            outs = [solve_auto(batch.problem(k), rtol, atol, max_steps, jit, cvodes_options,
                               progress) for k in range(K)]
            x = np.stack([o[0].x for o in outs], axis=2)
            ok = np.array([o[0].ok for o in outs])
            status = np.array([o[2] if o[0].ok else FAILED for o in outs])
            estimate[:] = [o[3] for o in outs]
            used = ", ".join(sorted({o[1] for o in outs}))
            compiled = all(o[0].compiled for o in outs)
            n_steps = max(o[0].n_steps for o in outs)
            worst = int(np.argmax(~np.isin(status, (OK, OK_STIFF))))
            message = f"auto, run by run ({K} runs): {outs[worst][0].message}"
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
    return BatchResult(t=batch.t, x=x, success=ok & ((status == OK) | (status == OK_STIFF)),
                       status=status, message=message, method=used,
                       wall_time=time.perf_counter() - start, n_steps=int(n_steps),
                       error_estimate=estimate, compiled=bool(compiled), _batch=batch)


def auto_dense_batch(batch: Batch, rtol: float, atol: np.ndarray, max_steps: int, jit,
                     cvodes_options, progress: Progress, *, threads: int | None = None):
    """``auto`` on a batch of smooth runs, each under a control constant over its run: the
    answer, check run and verdict of `dense.dense_auto` for every run in one compiled loop
    over the runs (`dense.dense_many`: on ``threads`` threads, each taking the next run
    as soon as it has room, its answer and header written in place), each run with its
    own steps; round by round (`dense_rounds`, each spread over the batch), each later
    round's first answers at the factor `first_factor` learns from the runs before it (each
    run's answer does not depend on its neighbours, so the bits do not depend on the
    threads or the lanes). A run not verified there goes alone through `solve_auto` (as a
    single call would). Returns ``(x (nx, n, K), ok, status, estimate, method, n_steps,
    message)``, or None (no compiled pass, a control that varies within a run, jit off)."""
    if not auto_jit(jit):
        return None
    K, model, t = batch.K, batch.model, batch.t
    nx = model.nx
    inputs = _constant_inputs(batch)
    if inputs is None:
        return None
    x0, u, p = inputs
    X = np.empty((K, nx, t.size))
    head = np.empty((K, DENSE_HEADER))
    vector = dense_lanes(model, build=K >= LANES_MIN)
    cores = batch_threads(threads)
    factor, factors, done = FIRST, [], []
    for pieces in dense_rounds(K):  # (the rounds do not depend on `threads`: same bits)
        if done:
            factor = _learned(head[np.concatenate(done)], factor, rtol)
        factors.append(factor)
        runs = np.concatenate([np.arange(k0, k1) for k0, k1 in pieces])
        # (every run of the round handed out in turn to the loops of every thread, each
        # writing its rows of X and head in place)
        if dense_many(model, x0, t, u, p, rtol, atol, max_steps, STIFF_STEPS, runs,
                      out=(X, head), factor=factor, vector=vector, threads=cores) is None:
            return None
        done.append(runs)
    result = head[:, DENSE_FIELDS.index("result")]  # (each run's header read as columns)
    estimate = head[:, DENSE_FIELDS.index("estimate")].copy()
    steps = head[:, DENSE_FIELDS.index("spent")].astype(int)
    worst = np.max(estimate[result == 1], initial=-math.inf)
    status = np.full(K, OK)
    redo = np.flatnonzero(result != 1)
    used = {"rk8"} if redo.size < K else set()
    floored = 0
    for k in redo:  # not verified in the loop: alone, by every path of `solve_auto` (below
        # its rounding floor at once: `solve_auto` would make the same pass to say so)
        out = dense_outcome(outcome_of(X[k], head[k]), rtol)
        if out is not None:
            (run, est, st), method = out, "rk8"
            floored += 1
        else:
            run, method, st, est = solve_auto(batch.problem(int(k)), rtol, atol, max_steps,
                                              jit, cvodes_options, progress)
        X[k] = run.x
        status[k] = st if run.ok else FAILED
        estimate[k] = est
        used.add(method)
        steps[k] = run.n_steps
    x = X.transpose(1, 2, 0)
    # (a run verified in the loop has finite outputs: `cpass` ``au_diff`` counts a
    # non-finite one as an infinite error, which no gate accepts; the others are looked at)
    ok = result == 1
    ok[redo] = np.isfinite(X[redo]).all(axis=(1, 2))
    status = np.where(ok, status, FAILED)
    message = (f"auto: DOP853 with dense output per run ({K} runs, each with its own steps, "
               f"checked against its own steps merged in pairs): "
               f"{steps.min()}-{steps.max()} steps per run; estimated error up to "
               f"{worst if worst > -math.inf else math.nan:.2g} of tolerance")
    if len(factors) > 1:
        message += (f"; first answers at {factors[0]:.2g} of the tolerance, then at "
                    + ", ".join(f"{f:.2g}" for f in factors[1:]) + " (learned from the runs "
                    "before: `first_factor`)")
    if redo.size > floored:
        message += f"; {redo.size - floored} run(s) alone through auto's other paths"
    if floored:
        message += (f"; {floored} run(s) not verified: the tolerance lies below the round-off "
                    "floor of double precision for their states (see `status`)")
    return x, ok, status, estimate, ", ".join(sorted(used)), int(steps.max()), message


#: A sampled `auto` batch's runs go in at most this many groups of at least `PASS_GROUP_MIN`
#: runs, each group's verdicts judged in Python while the other threads step the next: 1,000
#: runs on two threads spent 40 ms in the compiled loop and 33 ms in verdicts after it.
PASS_GROUPS, PASS_GROUP_MIN = 4, 128


def auto_pass_batch(batch: Batch, rtol: float, atol: np.ndarray, max_steps: int, jit,
                    cvodes_options, progress: Progress, *, threads: int | None = None):
    """``auto`` on a batch of smooth runs whose controls vary within a run: the single call's
    one-pass path (`auto.one_pass`: the rk8 answer under DOP853's embedded error control
    beside its check run) for every run in one compiled loop over the runs
    (`adaptive.run_pass_many`, on ``threads`` threads taking the runs one at a time), each
    pass judged as a single call judges its first (`auto.pass_verdict`; the rounding bounds
    it needs near the states' round-off, `_bounds`, and the checks it divides replayed from
    their exact starts, `adaptive.PassBatch.replay_checks`, made for all runs at once). A run
    under one control throughout (the dense pass's), one whose tolerance lies near its
    states' round-off, and one whose first pass is not accepted go alone through
    `solve_auto`, as their single calls: every run's answer is its single call's. Returns
    as `auto_dense_batch`, or None (no compiled pass, jit off, or no run for the pass: the
    multi-run search then takes the batch)."""
    if not auto_jit(jit):
        return None
    K, model, t = batch.K, batch.model, batch.t
    ua, ub = batch.ua, batch.ub
    x0 = np.ascontiguousarray(batch.x0.T)
    held = (ua == ua[:, :1]).all(axis=(1, 2)) & (ub == ua[:, :1]).all(axis=(1, 2))
    near = sizes_over_tolerance(model, x0, rtol, atol) * EPS * PASS_ULPS > 1.0
    runs = np.flatnonzero(~held & ~near)
    if not runs.size:
        return None
    horizon = float(t[-1] - t[0])
    X = np.empty((K, model.nx, t.size))
    status, estimate = np.full(K, OK), np.full(K, math.nan)
    steps = np.zeros(K, dtype=int)
    alone = np.flatnonzero(held | near).tolist()
    cores = batch_threads(threads)

    def judge(group, made, fraction):  # (the verdicts of a group: its answers into X, ...)
        passes = made.passes
        # (the loop tells no one: once a group, ``fraction`` of the runs stepped)
        progress.step(sum(got.n_steps for got in passes), fraction)
        bounds = _bounds(batch, group, passes, rtol, atol)
        # the checks a verdict may need replayed from the exact start (`auto._amplified`:
        # where the Richardson division decides), replayed at once (on this thread: the
        # others step the next group); a run missed here replays alone
        amplify = [j for j, (got, bound) in enumerate(zip(passes, bounds)) if got.ok
                   and 2 * got.d + max(got.ulp * FLOOR_ULPS, bound or 0.0) > 1.0
                   and got.d / (got.ratio ** 6 - 1) <= AUTO_ACCEPT]
        replayed = dict(zip(amplify, made.replay_checks(amplify, threads=1)))
        for j, (k, got, bound) in enumerate(zip(group.tolist(), passes, bounds)):
            est, extra, _ = pass_verdict(batch.problem(k), got, rtol, atol, 0.0, progress,
                                         bound=bound, replayed=replayed.get(j))
            if est is None:
                alone.append(k)
                continue
            X[k], estimate[k], steps[k] = got.x, est, got.n_steps + extra

    # the runs in groups, each group's verdicts (Python) judged while the other threads
    # step the next group (`executors.run_claiming`'s ``meanwhile``)
    groups = np.array_split(runs, min(PASS_GROUPS, max(1, runs.size // PASS_GROUP_MIN))
                            if cores > 1 else 1)
    pending, stepped = None, 0
    for group in groups:
        made = run_pass_many(model, x0[group], t, ua[group], ub[group],
                             np.ascontiguousarray(batch.p.T[group]), rtol, atol,
                             PASS_THETA / horizon, max_steps, ulps=PASS_ULPS, threads=cores,
                             meanwhile=pending)
        if made is None:
            return None
        stepped += group.size
        pending = partial(judge, group, made, stepped / runs.size)
    pending()
    used = {"rk8"} if len(alone) < K else set()
    failed = ""
    ok = np.ones(K, bool)  # (a pass answers finite states)
    for k in sorted(alone):  # (not answered by its first pass: alone, as a single call)
        run, method, st, est = solve_auto(batch.problem(k), rtol, atol, max_steps, jit,
                                          cvodes_options, progress)
        X[k], estimate[k], steps[k], ok[k] = run.x, est, run.n_steps, run.ok
        status[k] = st if run.ok else FAILED
        used.add(method)
        if not failed and status[k] not in (OK, OK_STIFF):
            failed = f"; run {k}: {run.message}"
    worst = np.max(estimate[status == OK], initial=-math.inf)
    message = (f"auto: rk8 with embedded error control per run ({K} runs in one compiled "
               f"loop, each checked against a run with fewer than half the steps): "
               f"{steps.min()}-{steps.max()} steps per run; estimated error up to "
               f"{worst if worst > -math.inf else math.nan:.2g} of tolerance"
               + (f"; {len(alone)} run(s) alone through auto's other paths" if alone else "")
               + failed)
    return X.transpose(1, 2, 0), ok, status, estimate, ", ".join(sorted(used)), \
        int(steps.max()), message


def _bounds(batch: Batch, runs: np.ndarray, passes: list, rtol: float,
            atol: np.ndarray) -> list:
    """`auto.rounding_bound` of each run ``runs[j]`` whose pass ``passes[j]`` lies near its
    states' round-off (where `auto.pass_verdict` needs it), the same bits: the Jacobians
    at ``x0`` found at once (`_jacobians`), the bounds by `auto.rounding_bounds` with what
    each verdict adds anyway as ``below`` (a run whose spectral radius is not finite alone,
    as `Single.spectrum`); None for the others."""
    out = [None] * len(runs)
    need = [j for j, got in enumerate(passes) if got.ok and got.ulp * PASS_MEASURED > 1.0]
    if not need:
        return out
    horizon = float(batch.t[-1] - batch.t[0])
    bound = rounding_bounds(
        _jacobians(batch, runs[need]), np.array([passes[j].rounding for j in need]),
        np.array([passes[j].smin for j in need]), horizon,
        np.minimum([passes[j].ulp * FLOOR_ULPS for j in need], 0.1 * AUTO_ACCEPT),
        lambda i: Single(batch.problem(int(runs[need[i]]))).spectrum(rtol, atol)[0])
    for j, b in zip(need, bound.tolist()):
        out[j] = b
    return out


def _jacobians(batch: Batch, runs: np.ndarray) -> np.ndarray:
    """``df/dx`` at the runs' ``x0``, first control and parameters, shape ``(len(runs), nx,
    nx)`` (`estimates.jacobian_x` mapped over the runs)."""
    nx = batch.model.nx
    J = map_eval(jacobian_x(batch.model), [batch.x0[:, runs], batch.ua[runs, 0].T,
                                           batch.p[:, runs]])  # (nx nx, m)
    return J.T.reshape(len(runs), nx, nx).transpose(0, 2, 1)


def _constant_inputs(batch: Batch):
    """``(x0 (K, nx), u (K, max(nu, 1)), p (K, max(np, 1)))``, C-contiguous, of a batch
    whose runs each hold one control throughout (`dense.dense_many`'s inputs); None when a
    run's control varies."""
    K, model, ua = batch.K, batch.model, batch.ua
    nu, np_ = model.nu, model.np
    if not batch.constant and ua.size and not (np.all(ua == ua[:, :1]) and
                                               np.all(batch.ub == ua[:, :1])):
        return None
    x0 = np.ascontiguousarray(batch.x0.T)
    u = np.zeros((K, max(nu, 1)))
    if nu and ua.shape[1]:
        u[:, :nu] = ua[:, 0]
    p = np.zeros((K, max(np_, 1)))
    p[:, :np_] = batch.p.T
    return x0, u, p


def dop853_dense_batch(batch: Batch, rtol: float, atol: np.ndarray, max_steps: int, *,
                       threads: int | None = None):
    """``method='dop853'`` on a batch whose runs each hold one control throughout: every
    run's DOP853 answer alone (`stepcontrol.plain_run`'s, no check) in one compiled loop
    over the runs (`dense.dense_many` with ``check=False``), spread over ``threads`` as
    `auto_dense_batch` spreads its runs. Returns ``(x (nx, n, K), ok (K,), steps (K,) each
    run's, failed)``: a run that failed is made again alone by
    `stepcontrol.run_dop853` (NaN from where it stopped), and ``failed`` is the first such
    run's message ("" for none); or None (no compiled pass, a control that varies within a
    run)."""
    K, model, t = batch.K, batch.model, batch.t
    inputs = _constant_inputs(batch)
    if inputs is None:
        return None
    x0, u, p = inputs
    X, head = np.empty((K, model.nx, t.size)), np.empty((K, DENSE_HEADER))
    if dense_many(model, x0, t, u, p, rtol, atol, max_steps, math.inf, slice(0, K),
                  out=(X, head), check=False, vector=dense_lanes(model, build=K >= LANES_MIN),
                  threads=batch_threads(threads)) is None:
        return None
    ok = head[:, DENSE_FIELDS.index("result")] == 2
    steps = head[:, DENSE_FIELDS.index("spent")].astype(int)
    failed = ""
    for k in np.flatnonzero(~ok):  # (alone: where and why)
        run = run_dop853(batch.problem(int(k)), rtol, atol, max_steps)
        X[k], steps[k], failed = run.x, run.n_steps, failed or run.message
    return X.transpose(1, 2, 0), ok, steps, failed


#: Runs of a dense batch from which its vector-lane step is compiled (`lanes.dense_lanes`:
#: in the background, ~0.5 s once per model and machine; the batch does not wait for it,
#: a later one takes it): for the rigid body, 256 runs of 41 outputs are ~20 ms of the
#: scalar loop, which the lanes cut about 2x. A smaller batch takes the lanes once built.
LANES_MIN = 256
#: A dense batch runs in two rounds (`dense_rounds`): the batch cut into `STRATA`
#: contiguous strata, the first `PILOT` runs of each answer first at `dense.FIRST` of the
#: tolerance, as single calls do; the rest, at the factor `first_factor` learns from them.
#: Each round ends when its slowest run does (its lanes empty meanwhile) and learns in
#: Python: on the 1,000-run torque-free batch of `bench/simulate.py` four rounds (16, 48,
#: 192 and 744 runs, each learning from all before) took 18.4 ms on two threads (minimum
#: of 30, median 20.1), two (32 and 968 runs) 17.4 ms (median 19.1); one round costs
#: ~0.2 ms of Python and one slowest run (~0.3 ms). The factor is chosen on a grid of 8
#: per decade, never looser than `dense.FIRST`, and a run it misjudges retries alone.
STRATA = 16
PILOT = 2
#: DOP853's order: a run's steps grow as its local tolerance to the power -1/8 (measured:
#: -0.10..-0.12 per run on `bench/simulate.py`'s torque-free batch, factors 1e-4..0.3).
ORDER = 8
#: A retry of `cpass._AUTO` (``AU_AIM``, ``AU_LADDER``): the next answer's local tolerance
#: aims at 0.2 tolerances from the estimate, scaled by at most 0.5 and at least 1e-2.
RETRY_AIM, RETRY_LADDER = 0.2, 1e-2
#: How far from the factors the runs done were measured at a later round's factor may go,
#: either way: the estimate's proportionality to the factor (slope 0.35-1.8 per run over
#: 3x, median 1.0, measured on the batch above) is not carried further than a decade.
REACH = 10.0
#: How far a run's error per unit of factor moves when its factor changes: 2x either way
#: (the slope above over 3x of factor), so each run done counts as three, at its ratio
#: (weight 1/2) and at 2x either side (1/4 each).
SPREAD = 2.0


def dense_rounds(K: int) -> list[tuple[tuple[int, int], ...]]:
    """The rounds of a dense batch of ``K`` runs, each a tuple of slices ``(k0, k1)``: the
    batch cut into `STRATA` near-equal contiguous strata, round 0 takes the first `PILOT`
    runs of each, round 1 the rest. The runs of the first round are thus spread over the
    whole batch (a batch sorted by a parameter, easy runs first, would otherwise teach the
    second round the wrong first tolerance). One round for a batch under ``2 STRATA
    PILOT`` runs.

    Examples
    --------
    >>> from appdyn.dynamics.integrate.batch import dense_rounds
    >>> [sum(k1 - k0 for k0, k1 in r) for r in dense_rounds(1000)]
    [32, 968]
    >>> dense_rounds(1000)[0][:3]
    ((0, 2), (62, 64), (125, 127))
    >>> dense_rounds(12)
    [((0, 12),)]
    """
    if K < 2 * STRATA * PILOT:
        return [((0, K),)]
    edges = [K * i // STRATA for i in range(STRATA + 1)]
    return [tuple((a, a + PILOT) for a in edges[:-1]),
            tuple((a + PILOT, b) for a, b in zip(edges[:-1], edges[1:]))]


def first_factor(estimate, factor, steps, gate, *, current: float, rtol: float) -> float:
    """The first answer's local tolerance over the requested one (the factor) for the next
    runs of a batch: the one that minimises their expected steps under what the runs done
    showed, on a grid of 8 per decade through ``current`` within `REACH` of the factors the
    runs were measured at (at least ``LOCAL_RTOL_MIN / rtol``, at most `dense.FIRST`, a
    single call's: the check is the single call's, and at looser factors, with fewer and
    longer steps, its Richardson ratio left 2^8 on short runs of random linear systems,
    where runs at learned factors 0.004-0.07 were verified with errors of 1.2-3.7
    tolerances; tighter is learned from runs that would retry).

    Each run done is a draw of how the batch behaves: its global error per unit of local
    factor (``estimate / factor``: the error follows the local tolerance about linearly,
    within `SPREAD`) and its steps (answer and check, growing as factor^(-1/`ORDER`)). At a
    candidate factor a run is accepted at once when its predicted estimate is within its
    ``gate``; otherwise it pays a retry as ``cpass._AUTO`` makes one (`RETRY_AIM`,
    `RETRY_LADDER`, at most `dense.TRIES` answers; a run still not accepted counts double,
    for auto's other paths).
    Too tight a factor over-delivers on every run, too loose one pays retries: the sum
    weighs both, so a lone chaotic run retries alone rather than tightening all. Every run
    is still verified by its own check.

    Parameters
    ----------
    estimate, factor, steps, gate : array_like, shape (m,)
        Of each verified run done: its estimate [tolerances], its accepted answer's factor,
        that answer's and its check's steps, its acceptance [tolerances] (0.5 or 1).
        Entries not finite or not positive are left out.
    current : float
        The factor of the last round.
    rtol : float
        The requested relative tolerance.

    Returns
    -------
    float
        ``current`` when no run is usable.

    Examples
    --------
    >>> from appdyn.dynamics.integrate.batch import first_factor
    >>> f = first_factor([0.01] * 4, [0.003] * 4, [150] * 4, [0.5] * 4, current=0.003,
    ...                  rtol=1e-8)
    >>> round(f, 4)  # (runs 50x inside the gate: no looser than a single call's)
    0.003
    >>> round(first_factor([0.2] * 9 + [400.0], [0.003] * 10, [150] * 10, [0.5] * 10,
    ...                    current=0.003, rtol=1e-8), 4)  # (one run 2000x worse: it retries alone)
    0.003
    >>> round(first_factor([2.0] * 4, [0.003] * 4, [150] * 4, [0.5] * 4, current=0.003,
    ...                    rtol=1e-8), 5)  # (every run would retry: tighter, with a margin)
    0.0003
    """
    e, f, n, g = (np.asarray(a, float).ravel() for a in (estimate, factor, steps, gate))
    use = np.isfinite(e) & np.isfinite(f) & np.isfinite(n) & np.isfinite(g) & (e > 0) & \
        (f > 0) & (n > 0) & (g > 0)
    if not use.any():
        return float(current)
    e, f, n, g = e[use], f[use], n[use], g[use]
    # (8 per decade through `current`, within `REACH` of the factors the runs were measured at)
    cap = max(FIRST, LOCAL_RTOL_MIN / rtol)  # (a single call's, or the floor above it)
    low, high = max(f.min() / REACH, LOCAL_RTOL_MIN / rtol), min(f.max() * REACH, cap)
    if low > high:  # (measured far above the cap: at it; far below the floor: at the floor)
        return float(cap if f.min() / REACH > cap else min(LOCAL_RTOL_MIN / rtol, 1.0))
    j = np.arange(math.floor(8 * math.log10(low / current)),
                  math.ceil(8 * math.log10(high / current)) + 1)
    grid = current * 10.0 ** (j / 8.0)
    grid = grid[(grid >= low * (1 - 1e-12)) & (grid <= high * (1 + 1e-12))]
    if grid.size == 0:
        return float(current)
    # each run's steps scale as factor^(-1/ORDER) from its own; its ratio spread by `SPREAD`
    # (what it would be at another factor); the runs binned by ratio (1/32 decade) and gate
    scale = n * f ** (1.0 / ORDER)
    ratio = np.concatenate([e / f / SPREAD, e / f, e / f * SPREAD])
    weight = np.concatenate([0.25 * scale, 0.5 * scale, 0.25 * scale])
    # (the bins of every gate, 0.5 or 1, in one: bin = key - lo + span * the gate's index)
    gate, which = np.unique(np.concatenate([g, g, g]), return_inverse=True)
    key = np.round(32 * np.log10(ratio)).astype(int)
    lo, span = key.min(), key.max() - key.min() + 1
    w = np.bincount(key - lo + span * which, weights=weight)
    used = np.flatnonzero(w)
    # (a sum, not a matrix product: no BLAS call, whose threads would then spin on the
    # cores the batch's loops run on)
    cost = (_expected_steps(grid, 10.0 ** ((used % span + lo) / 32), gate[used // span]) *
            w[used]).sum(axis=1)
    return float(grid[int(np.argmin(cost))])


def _expected_steps(grid: np.ndarray, ratio: np.ndarray, gate: np.ndarray) -> np.ndarray:
    """The steps ``(c, m)`` of runs of unit steps at factor 1 (steps ``factor^(-1/ORDER)``),
    of estimates ``ratio (m,)`` per unit factor and acceptances ``gate (m,)``, had their first
    answer been at each factor of ``grid (c,)``: the answers until one is accepted (a
    retry as `cpass._AUTO` makes one), double when none of `dense.TRIES` is."""
    at = np.repeat(grid[:, None], ratio.size, axis=1)
    total = np.zeros_like(at)
    live = np.ones(at.shape, bool)
    for _ in range(TRIES):
        total += np.where(live, at ** (-1.0 / ORDER), 0.0)
        est = ratio * at
        live &= est > gate
        at = np.where(live, at * np.minimum(np.maximum(RETRY_AIM / est, RETRY_LADDER), 0.5),
                      at)
    return np.where(live, 2 * total, total)


def _learned(head: np.ndarray, current: float, rtol: float) -> float:
    """`first_factor` from the headers ``head (m, HEADER)`` of the runs done."""
    col = lambda name: head[:, DENSE_FIELDS.index(name)]
    ok = col("result") == 1
    return first_factor(col("estimate")[ok], col("factor")[ok],
                        (col("answer_steps") + col("check_steps"))[ok], col("gate")[ok],
                        current=current, rtol=rtol)


def _sane(batch: Batch, x: np.ndarray, ok: np.ndarray, status: np.ndarray, message: str,
          method: str):
    """``(status, message)`` of a fixed-step batch with its finished runs checked by
    `sanity.violations`: ``VIOLATED`` for runs whose invariants are grossly off."""
    good = np.flatnonzero(ok)
    if good.size == 0:
        return status, message
    U = lambda: np.concatenate([batch.ua[good], batch.ub[good, -1:]], axis=1).transpose(2, 1, 0)
    every = good.size == ok.size  # (then no copy of the states)
    found = violations(batch.model, batch.t, x if every else x[:, :, good], U,
                       batch.p if every else batch.p[:, good], method)
    if not any(found):
        return status, message
    bad = [(int(k), why) for k, why in zip(good, found) if why]
    status = status.copy()
    status[[k for k, _ in bad]] = VIOLATED
    return status, (f"{message}; {len(bad)} run(s) not a solution (run {bad[0][0]}: "
                    f"{bad[0][1]}); {remedy(method)}")


@dataclass(frozen=True, repr=False)
class BatchResult(Result):
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
        3 not verified, 4 a fixed-step run whose invariants are grossly violated,
        5 not verified on a non-smooth right-hand side, -1 failed).
    message : str
    method : str
        The method used.
    wall_time : float [s]
    n_steps : int
        Steps per run (``auto``: summed over its runs; cvodes: the most of any run).
    error_estimate : ndarray, shape (K,)
        ``auto``: each run's estimated global error in units of the tolerance (the largest
        over the batch where one step count serves all runs: auto's multi-run error
        control); NaN for the other methods.
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

    _repr_fields = ("method", "t", "x", "n_steps")

    def __len__(self) -> int:
        return self.x.shape[2]

    @property
    def all_success(self) -> bool:
        """Whether every run succeeded."""
        return bool(np.all(self.success))

    def to_dict(self) -> dict:
        """Summary and trajectories as plain Python: counters, ``t``, and per state name the
        runs' histories, shape (n, K) (JSON-ready through `to_json`)."""
        names = self._batch.model.states
        return {"success": self.success, "status": self.status, "message": self.message,
                "method": self.method, "wall_time": self.wall_time, "n_steps": self.n_steps,
                "error_estimate": self.error_estimate, "compiled": self.compiled,
                "t": self.t, "x": dict(zip(names, self.x))}

    def plot(self, ax=None, *, states=None):
        """Every run's states against time, one labelled subplot per unit (`Model.units`),
        bounds as dashed lines (see `SimulationResult.plot`).

        Parameters
        ----------
        ax : matplotlib.axes.Axes or sequence of Axes, optional
            Draw on these; by default on a new `matplotlib.figure.Figure`.
        states : sequence of str, optional
            The states to draw (default all).

        Returns
        -------
        matplotlib.figure.Figure
        """
        model = self._batch.model
        names = tuple(model.states) if states is None else tuple(states)
        unknown = [s for s in names if s not in model.states]
        if unknown:
            raise ValueError(f"`states` names unknown states {unknown}; "
                             f"the states are {tuple(model.states)}")
        ok = int(np.sum(self.success))
        return plot_signals(self.t, {n: self.x[model.states.index(n)] for n in names},
                            model.units, bounds=model.bounds, ax=ax,
                            title=f"{model.name}: {len(self)} runs ({self.method}, "
                                  f"{ok} verified)")

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
            _dense=Dense(b.model, problem.p, lambda: problem.control.grid(problem.t),
                         problem.control.left_grid(problem.t)))
