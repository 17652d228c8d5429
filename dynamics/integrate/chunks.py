"""The chunk Function of the fixed-step runs (`dynamics.integrate.loops`): a ``mapaccum`` of
step kernels wrapped in MX, its compile job and its key. (A model whose right-hand side is
called runs its rk8 chunk in its compiled pass instead: `cpass.pass_chunk`.)"""
from __future__ import annotations

import casadi as ca
import numpy as np

from .. import cache
from ..model import Model
from .kernels import kernel
from .tableaux import unique_nodes

__all__ = ["CHUNK", "BATCH_CHUNK", "chunk_compile_job", "chunk_job", "chunk_key", "chunk_name",
           "build_chunk"]

_BASE = 4  # unroll base of mapaccum: casadi's construction cost grows ~5x from base 4 to 10

# Every fixed-step run calls ONE compiled Function per (model, method, control mode): a
# `mapaccum` of `CHUNK` steps, each with its own step size and control data. A run of any
# length is a Python loop over chunks (a few microseconds each), so neither the code nor the
# compile time grows with the grid length or the step count, and 1e7 steps are as easy as 1e3.
# The steps of a short last chunk past its length are skipped (a conditional in the loop).
CHUNK = 512

#: Steps per chunk of a batch (`dynamics.integrate.batch`): K runs of a short chunk keep
#: the per-call data small (a 512-step chunk wrote 28 MB per call for 1,000 runs).
BATCH_CHUNK = 64


def chunk_compile_job(model: Model, method: str, mode: str) -> cache.Job | None:
    """The compile of the (default-size) compiled chunk Function as `chunk_function` would
    run it (for `cache.compile_ahead`), or None when that Function is built already or
    would not be compiled."""
    if cache.compiler() is None or cache.contains(chunk_key(model, method, mode) + (True,)):
        return None
    return chunk_job(model, method, mode, CHUNK)


def chunk_job(model: Model, method: str, mode: str, size: int) -> cache.Job:
    """The `cache.Job` compiling the chunk Function (built only when the persistent cache
    does not have it)."""
    name = chunk_name(method, size)
    att = model.attitude if method == "lie" else None
    return cache.Job(lambda: ([build_chunk(model, method, mode, size=size, compiled=True)], ""),
                     _OPT, lambda library: ca.external(name, library),
                     cache.recipe("chunk", model.f, att, method, mode, size, _BLOCK, _BASE))


def chunk_name(method: str, size: int) -> str:
    return f"simulate_{method}" + ("" if size == CHUNK else f"_{size}")


def chunk_key(model: Model, method: str, mode: str) -> tuple:
    return ("chunk", cache.function_key(model.f), model.attitude if method == "lie" else None,
            method, mode)


#: C optimization of the chunk loops. The rigid body's 512-step rk8 chunk compiles in 0.25 s
#: at -O1 against 0.41 s at -O3 and runs as fast (242 against 242 ns per step); rk4 and lie
#: steps are 5-6% slower at -O1 (100 against 95 ns, 148 against 140 ns). The first call of
#: a model pays the compile, so -O1 keeps it within 0.5 s.
_OPT = "-O1"

_BLOCK = 16  # steps per block of a chunk: a chunk is `CHUNK // _BLOCK` blocks


def build_chunk(model, method, mode, *, size: int = CHUNK,
                compiled: bool = False) -> ca.Function:
    """``mapaccum`` of ``size`` (default `CHUNK`) steps that takes only the first ``n``: the chunk is a
    ``mapaccum`` of blocks of `_BLOCK` steps, each block and each step inside a block a
    ``Function.conditional`` that skips (copies the state) past step ``n``. A short run
    then costs its own steps plus about 25 us, not the 512 steps of a full chunk.
    ``compiled``: built to generate C from (`kernels.kernel`)."""
    step = kernel(model, method, mode, compiled=compiled)
    args = [ca.MX.sym(step.name_in(i), step.sparsity_in(i)) for i in range(step.n_in())]
    gated = _gated(step, args, "step")
    inner = gated.mapaccum("steps", _BLOCK, {"base": _BASE})
    blk = [ca.MX.sym(inner.name_in(i), inner.sparsity_in(i)) for i in range(inner.n_in())]
    states = inner.call(blk)[0]
    run = ca.Function("block", blk, [states[:, -1], states])
    skip = ca.Function("skip_block", blk, [blk[0], ca.repmat(blk[0], 1, _BLOCK)])
    block_on = ca.MX.sym("block_on")
    gated_block = ca.Function("gated_block", [blk[0], block_on] + blk[1:],
                              ca.Function.conditional("maybe_block", [skip], run)
                              .call([block_on] + blk))
    loop = gated_block.mapaccum("blocks", size // _BLOCK, 1, {"base": _BASE})
    x0, n = ca.MX.sym("x0", model.nx), ca.MX.sym("n")
    ins = [x0, n, ca.MX.sym("h", 1, size)]
    if mode == "linear":
        ins += [ca.MX.sym("ua", model.nu, size), ca.MX.sym("ud", model.nu, size)]
    else:
        ins += [ca.MX.sym("us", model.nu * len(unique_nodes(method)), size)]
    ins.append(ca.MX.sym("p", model.np))
    step_on = ca.DM(np.arange(size, dtype=float)).T < n
    block_on = ca.DM(np.arange(0, size, _BLOCK, dtype=float)).T < n
    out = loop.call([x0, block_on, step_on] + ins[2:-1] + [ca.repmat(ins[-1], 1, size)])
    return ca.Function(chunk_name(method, size), ins, [out[1]])


def _gated(step: ca.Function, args: list, name: str) -> ca.Function:
    """``(x, on, *rest) -> step(x, *rest)`` when ``on`` else ``x``."""
    skip = ca.Function(f"skip_{name}", args, [args[0]])
    on = ca.MX.sym("on")
    return ca.Function(f"gated_{name}", [args[0], on] + args[1:],
                       ca.Function.conditional(f"maybe_{name}", [skip], step).call([on] + args))
