"""Per-call overhead of `dynamics.simulate`: Python time around the compiled loop.

A repeated short call on a cached model (the torque-free rigid body, J = diag(1, 2, 3), a
2-point grid ``[0, 1]`` s, ``x0`` a list) for ``rk8`` and ``rk4`` with ``steps=1`` and for
``auto``. For each: the time per `simulate` call, the time of the compiled call alone (the
chunk's buffer triggered with the same inputs already in place; for ``auto``, the call of its
compiled dense pass, `dynamics.integrate.dense`, replayed with the workspace `simulate`
filled: the floor no Python wrapper can go under), and their difference, the overhead; for the
fixed-step methods also the Python time before the compiled call starts (`before_compiled`,
what the per-call target of issue "Simulation at compiled-C speed" counts). The two
are timed in 15 interleaved rounds of 2,000 calls each (3 of 1,000 with ``--quick``); each
time is the median over the rounds, the overhead the median of the per-round differences.

Writes ``overhead.csv`` into the output folder and returns the summary rows (`run`).
Run: ``appdyn bench overhead`` or ``python bench/overhead.py [--quick]``.
"""
from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from appdyn.dynamics import rigid_body, simulate
from appdyn.dynamics.integrate import dense, evaluate
from appdyn.dynamics.integrate.api import call_plan
from appdyn.dynamics.integrate.loops import CHUNK, _chunk_shapes, chunk_function

from _common import Row, script_main, write_csv

INERTIA = [1.0, 2.0, 3.0]
X0 = [0, 0, 0, 1, 1.0, 0.1, 0.8]
GRID = np.array([0.0, 1.0])
CASES = (("rk8", dict(method="rk8", steps=1)), ("rk4", dict(method="rk4", steps=1)),
         ("auto", dict(method="auto")))


def batch_time(fun, calls: int) -> float:
    """The mean time of one of ``calls`` calls of ``fun()`` [s]."""
    t0 = time.perf_counter()
    for _ in range(calls):
        fun()
    return (time.perf_counter() - t0) / calls


def paired_per_call(total, floor, calls: int, batches: int) -> tuple[float, float, float]:
    """Medians over ``batches`` rounds, each a batch of ``calls`` calls of ``total()`` then
    of ``floor()``: ``(total, floor, overhead)`` [s], the overhead the median of the
    per-round differences. Interleaved, because this VM's speed drifts by 20-60% within
    seconds: timed one after the other, the two medians once differed by 8 to 32 us for
    the same call."""
    tt, ff = [], []
    for _ in range(batches):
        tt.append(batch_time(total, calls))
        ff.append(batch_time(floor, calls))
    diff = [a - b for a, b in zip(tt, ff)]
    return statistics.median(tt), statistics.median(ff), statistics.median(diff)


_KEEP: list = []


def compiled_call(model, method: str):
    """``trigger()`` of a buffer of the (cached, compiled) chunk Function of ``method``,
    its inputs set as `simulate` sets them for one step over ``GRID``."""
    fun, compiled = chunk_function(model, method, "linear", True)
    ins = [np.zeros(shape) for shape in _chunk_shapes(model, method, "linear")]
    ins[0][:] = X0
    ins[1][0] = 1.0
    ins[2][0] = GRID[1] - GRID[0]
    ins[-1][:] = model.p_default
    out = np.empty((CHUNK, model.nx))
    buf, trigger = fun.buffer()
    for i, a in enumerate(ins):
        buf.set_arg(i, memoryview(a))
    buf.set_res(0, memoryview(out))
    _KEEP.append((buf, ins, out))  # the buffer points into these arrays: keep them alive
    return trigger, compiled


def dense_pass_call(model, x0, t):
    """The call of ``auto``'s compiled dense pass (`dynamics.integrate.dense`: ``rk8_auto``,
    or ``rk8_auto_v`` once the model's vector lanes are loaded) that ``simulate(model, x0,
    t)`` at the defaults makes, captured and replayed with the workspace as `simulate`
    filled it (restored before each call: one copy of ~100 doubles): the floor no Python
    wrapper can go under. Returns ``(call, True)``."""
    plan = dense.pass_plan(model)
    work = dense._workspace(plan, len(t) - 1)  # (this thread's: the one `simulate` fills)
    seen = []

    def spying(fun):
        def spy(*args):
            seen.append((fun, args, work.ws.copy()))
            return fun(*args)
        return spy

    simulate(model, x0, t)  # (the common call keeps the plan in the model's `call_plan`)
    slots = call_plan(model).passes
    real, vector = slots[0], plan.single[1]  # (the vector lanes, once loaded)
    slots[0] = plan._replace(auto=spying(plan.auto))
    if vector is not None:
        plan.single[1] = SimpleNamespace(address=vector.address, cont=vector.cont,
                                         auto_v=spying(vector.auto_v))
    try:
        res = simulate(model, x0, t)
    finally:
        slots[0], plan.single[1] = real, vector
    fun, args, filled = seen[-1]
    ws = work.ws

    def call():
        ws[:] = filled
        return fun(*args)

    _KEEP.append((res, work, filled))
    return call, True


def before_compiled(model, kwargs, calls: int, batches: int) -> float:
    """Median over ``batches`` rounds of the mean Python time of a `simulate` call BEFORE
    its compiled call starts (what the issue's per-call target counts) [s], for the
    fixed-step methods: the thread's bound buffer of the chunk Function gets a ``trigger``
    that notes the time and then calls the real one."""
    fun, _ = chunk_function(model, kwargs["method"], "linear", True)
    simulate(model, X0, GRID, **kwargs)
    entry = evaluate._thread_table("bound")[id(fun)]
    real, stamp = entry.trigger, [0.0]

    def noted():
        stamp[0] = time.perf_counter()
        real()

    entry.trigger = noted
    rounds = []
    try:
        for _ in range(batches):
            spent = 0.0
            for _ in range(calls):
                t0 = time.perf_counter()
                simulate(model, X0, GRID, **kwargs)
                spent += stamp[0] - t0
            rounds.append(spent / calls)
    finally:
        entry.trigger = real
    return statistics.median(rounds)


def run(quick: bool, out: Path) -> list[Row]:
    calls, batches = (1000, 3) if quick else (2000, 15)
    model = rigid_body(INERTIA)
    detail, summary = [], []
    print(f"simulate on a 2-point grid, torque-free body; medians of {batches} interleaved "
          f"rounds of {calls} calls each")
    for name, kwargs in CASES:
        res = simulate(model, X0, GRID, **kwargs)  # warm: compiles once
        n = calls
        trigger, compiled = (dense_pass_call(model, X0, GRID) if name == "auto"
                             else compiled_call(model, res.method))
        trigger()
        total, chunk, over = paired_per_call(lambda: simulate(model, X0, GRID, **kwargs),
                                             trigger, n, batches)
        print(f"  {name:5s} total {1e6 * total:8.2f} us   compiled call {1e6 * chunk:6.2f} us   "
              f"overhead {1e6 * over:8.2f} us   (n_steps {res.n_steps}, compiled {compiled})")
        detail.append(dict(method=name, calls=n, batches=batches, total_us=1e6 * total,
                           compiled_call_us=1e6 * chunk, overhead_us=1e6 * over,
                           n_steps=res.n_steps, compiled=compiled))
        case = f"repeated call, 2-point grid, {name}"
        note = "steps 1" if name != "auto" else "one compiled pass (answer and check run)"
        summary += [Row("overhead", case, "per call", 1e6 * total, "us", note),
                    Row("overhead", case, "compiled call", 1e6 * chunk, "us", note),
                    Row("overhead", case, "Python overhead", 1e6 * over, "us", note)]
        if name != "auto":
            before = before_compiled(model, kwargs, n, batches)
            print(f"        Python before the compiled call {1e6 * before:6.2f} us")
            detail[-1]["before_us"] = 1e6 * before
            summary.append(Row("overhead", case, "Python before the compiled call",
                               1e6 * before, "us", note))
    write_csv(detail, Path(out) / "overhead.csv")
    return summary


def main(argv=None) -> int:
    return script_main(run, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
