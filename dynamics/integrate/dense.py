"""``auto`` for a smooth right-hand side under a control constant over the run, in ONE
compiled call: DOP853 stepping by its error estimate alone with dense output of order 7
(the answer), its check (the answer's steps merged in pairs), their comparison and the verdict
(`cpass._AUTO`, ``rk8_auto``), with no Python between; and the same for every run of a
batch in one compiled loop over the runs (``rk8_auto_many``), each run with its own steps,
check and verdict.

The rules (as `dynamics.integrate.auto.dense_pass` states them): the answer runs at the
local tolerance ``(rtol, atol) f`` (``f = FIRST``, at least the factor that keeps it one
ulp above the states' size), in at least 12 steps (no step longer than a twelfth of the
run: on fewer, longer steps the check below is blind to the error of the answer's
continuous extension, `cpass` ``RI_STEPS_MIN``); its check is Richardson's on the answer's
own steps: alongside the answer, each pair of its accepted steps is taken again as one step
of their sum (a lone last step alone), no step rejected, the outputs from that step's
continuous extension (about half the answer's steps). ``d`` is their scaled difference (max
over the outputs, in units of ``atol + rtol |x|``). In the method's asymptotic range the
check's error is 2^8 times the answer's (order 8); the range is shown by the embedded
estimates: the sum of the check's over the answer's, doubled, is ``2^p`` with ``p`` between
5 and 11 (6-8 measured on smooth problems). Then the estimate is ``d / (2^7 - 1)`` (2x
conservative) plus 1000 ulps of each state's size, accepted at most 0.5; otherwise ``d``
plus the ulps, accepted at most 1. Within 1e6 ulps of a state's size the rounding of the
model's formulas (measured on the way) is carried over the horizon (`estimates.carried`)
and its screening bound (`estimates.screen`) added when at most 0.05; otherwise the flow's
real amplification is measured: the answer is repeated with each accepted state rounded at
random (stochastic arithmetic, as Vignes' CESTAC: every state moved by ``eps |x_i|``, twice
the most a rounding to nearest moves it, plus the step times the right-hand side's measured
rounding, of a random sign per state and step from a fixed stream), and the largest of its
difference from the answer, the carried rounding and the ulps replaces the ulps; the
estimate is then accepted at most 1 (as the multi-run search accepts its estimate with its
floor on top). One draw may fall 30x below another, so a second draw (its own stream; the
floor is the larger) is made unless the first already refuses the answer or accepts it with
that spread to spare. A draw's rounding rates are its own measure of the right-hand side's
rounding so far, so it needs nothing of the answer: where the floor is likely measured (a
retried answer whose local tolerance lies within 1e4 ulps of a state's size, or the
rounding at x0 carried over the horizon within 10x of the bound that asks for a
measurement), both draws run alongside the answer in the two lanes of its vector steps that
its check leaves free (`cpass` ``au_step_spec``, once the model's lanes are loaded): the
same bits as the reruns after it, which the step function makes, in vector steps the answer
takes anyway (a draw's steps are counted when it is judged). The bench body at rtol 1e-6
and 1e-10 took 20 % and 25 % less time, the hinged scene at rtol 1e-8 51 % less. Each
step's rounding enters where it arises: the start moved by the rounding of the whole
horizon (`estimates.measured_floor`, which the multi-run search keeps) put it all where the
flow amplifies it longest, 20-70x too much on the 39-state scene of
``tests/dynamics/scene/registry.py``. Not accepted, the answer is redone with its local
tolerance predicted from the part of the estimate it controls (the estimate less the ulps
and the carried rounding, which no tighter tolerance lowers): DOP853's global error follows
its local tolerance about linearly, so the first retry scales it by ``aim / part`` and a
later one by the slope measured between the last two answers; the aim is 0.2 (less where
the rounding takes more of the acceptance), at most 100x tighter per answer, never below
the factor that keeps the local tolerance an ulp above the states' size (`TRIES` answers at
most; none after a floor was measured, nor when the rounding alone takes 90 % of the
acceptance: the tolerance then lies at the rounding floor, and
`dynamics.integrate.auto.dense_pass` answers with ``ROUNDOFF`` when those ulps exceed the
tolerance).

Per call the Python is a look-up of the model's plan (its library and the workspace
layout, `_plan`), a thread's reused workspace, one ``ctypes`` call and the result's array.
What a loop over the outputs finds is found in C: whether the grid is finite and strictly
increasing (`simulate`'s common call hands it over unchecked: result -4, and `check_t`
words the error), the longest output interval over the smallest step (``substeps``), and,
for an answer alone, its quaternion's drift (``qoff``, the sanity check of ``dop853``).
"""
from __future__ import annotations

import math
import struct
import threading
from typing import NamedTuple

import numpy as np

from .. import cache
from ..executors import run_split
from ..interrupts import check_interrupt, deferred_interrupts, stop_requested
from .cpass import pass_library
from .lanes import LANES, dense_lanes
from .inputs import Problem

__all__ = ["FIELDS", "HEADER", "FIRST", "CHECK", "TRIES", "DenseAuto", "dense_auto", "dense_run",
           "pass_plan", "dense_many", "outcome_of", "constant_control"]

#: The first answer's local tolerance over the requested one. Its global error, in units
#: of the requested tolerance, was 10-1500 times this on the torque-free bodies and 300 on
#: the wheel spacecraft of ``bench/integrate_peers.py`` (rtol 1e-4..1e-8; the most near a
#: separatrix): 0.003 meets the tolerance at once on most of them, and a
#: retry aims at 0.2 from the estimate.
FIRST = 0.003
#: The check's local tolerance over the answer's (it steps the answer's steps merged in
#: pairs, with the answer's error norm).
CHECK = 1.0
TRIES = 3       # answers (each aimed tighter) before the other paths of ``auto``
#: Most steps of one compiled call (Ctrl-C is looked at between calls).
BUDGET = 1 << 15

#: The slots of a run's header (``AU_*`` of `cpass._AUTO`, in order; `HEADER` of them).
FIELDS = ("rtol", "factor", "loose", "max_steps", "stiff_steps", "t0", "iq", "tries", "phase",
          "spent", "check_steps", "answer_steps", "result", "estimate", "d", "flag", "try",
          "accepted", "rejected", "hmin", "interpolated", "lipschitz", "ratio", "bound",
          "nout", "substeps", "gate", "floor", "order", "ulps", "prev_factor", "prev_part",
          "factor_min", "draws", "drawn", "qoff")
_DRAWS, _QOFF = FIELDS.index("draws"), FIELDS.index("qoff")
(_RTOL, _FACTOR, _LOOSE, _MAXSTEPS, _STIFF, _T0, _IQ, _TRIES, _PHASE, _SPENT, _NCHK, _NANS,
 _RESULT, _EST, _D, _FLAG, _TRY, _ACC, _REJ, _HMIN, _INTERP, _LIP, _RATIO, _BOUND,
 _NOUT, _SUB, _GATE, _FLOOR, _ORDER, _ULPS) = range(FIELDS.index("prev_factor"))
#: Doubles of a run's header.
HEADER = len(FIELDS)
_REASONS = ("", "a state became non-finite", "the step size underflowed",
            "more than max_steps steps", "stiff (stability alone would need too many steps)")


class DenseAuto(NamedTuple):
    """The outcome of `dense_auto` (one run) or of a run of `dense_many`.

    ``x (nx, n)`` the answer (NaN after a failure); ``result`` 1 verified, 0 not verified
    (``estimate`` > acceptance or not finite), 2 answered and not checked (``check`` False:
    ``estimate`` NaN), -2 a requested tolerance below one ulp of a
    state's size (no run made), -3 a run failed (``reason``), -4 an output grid not finite
    and strictly increasing (no run made: a caller that hands over an unchecked grid leaves
    it to `inputs.check_t` to word); ``estimate`` [tolerances]; ``spent`` steps of
    all runs; ``answer_steps``, ``check_steps`` (accepted and rejected), ``rejected`` of the
    answer, ``hmin`` its smallest step [s], ``interpolated`` its steps that filled outputs,
    ``ratio`` the check's steps over the answer's (2: merged in pairs), ``factor`` the
    answer's local tolerance over the requested, ``bound`` the rounding bound included in
    ``estimate`` (or ``floor``, the rounding floor measured by ``draws`` reruns of the
    answer with each step's rounding emulated at random, when that bound was not small),
    ``substeps`` the
    longest output interval over ``hmin`` (equal steps of that many per interval are no
    longer than any the answer took), ``reason`` why a run failed, ``ulps`` 1000 ulps of the
    largest state's size over its least tolerance at the outputs (part of ``estimate``: the
    rounding no answer is verified below), ``qoff`` of an answer alone (``result`` 2) the
    most its attitude quaternion's norm is off 1 at the outputs (0: no quaternion, or a
    checked answer; the test of `sanity.violation`, made in the compiled pass)."""

    x: np.ndarray
    result: int
    estimate: float
    spent: int
    answer_steps: int
    check_steps: int
    rejected: int
    hmin: float
    interpolated: int
    ratio: float
    factor: float
    bound: float
    floor: float
    substeps: int
    reason: str
    ulps: float
    draws: int
    qoff: float


def constant_control(ctrl) -> bool:
    """Whether the linear control ``ctrl`` (`inputs.Control`) is one value over the whole run.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.integrate.dense import constant_control
    >>> from appdyn.dynamics.integrate.inputs import check_u
    >>> t = np.linspace(0.0, 1.0, 3)
    >>> constant_control(check_u([0.1, 0, 0], 3, t)), constant_control(check_u(np.eye(3), 3, t))
    (True, False)
    """
    if ctrl.constant or ctrl.ua.size == 0:
        return True
    return bool(np.all(ctrl.ua == ctrl.ua[0]) and np.all(ctrl.ub == ctrl.ua[0]))


class _Plan(NamedTuple):
    """What a model's calls share: the compiled functions (the pass's first build: the
    steps in vector lanes come with `lanes.dense_lanes`), the sizes, the index of the
    attitude quaternion (-1: none), and ``single`` ``[calls, vector]``: the single calls
    made before the model's vector lanes were loaded, then the lanes (`_single_lanes`)."""

    auto: object
    many: object
    single: list
    nx: int
    nu: int
    np: int
    iq: int


def pass_plan(model) -> _Plan | None:
    """The model's call plan (cached with its compiled pass); None without one. (`simulate`'s
    common call keeps it in the model's `api.CallPlan`, and hands it to `dense_run`.)"""
    def build():
        lib = pass_library(model)
        return None if lib is None else _Plan(
            lib.auto, lib.auto_many, [0, None], model.nx,
            model.nu, model.np, -1 if model.attitude is None else model.attitude[0])

    return cache.get(("dense_plan", cache.function_key(model.f)), build, keepalive=model.f)


def _size(plan: _Plan, nout: int) -> int:
    """Doubles of the workspace (``AU_SIZE`` of `cpass._AUTO`)."""
    return HEADER + 11 * plan.nx + plan.nu + plan.np + nout + 38


def _alongside(plan: _Plan, nout: int) -> int:
    """The workspace's slot ``AU_SPEC`` of `cpass._AUTO`: 2 when the last answer's floor
    draws ran alongside it in the lanes of its vector steps (``au_step_spec``)."""
    return HEADER + 7 * plan.nx + plan.nu + plan.np + nout + 17


_LOCAL = threading.local()


class _Work(NamedTuple):
    """A thread's workspace for ``nout`` outputs: ``ws`` (`_size` doubles), the check-run
    scratch ``XC (nx, nout + 1)`` (``XL (LANES, nx, nout + 1)``: a lane's each, for
    ``rk8_auto_lanes``), the answer's buffer ``X (nx, nout + 1)`` (copied out after a
    call), their addresses and the arguments of the single run's call ``args``."""

    ws: np.ndarray
    XC: np.ndarray
    ws_addr: int
    xc_addr: int
    X: np.ndarray
    args: tuple
    XL: np.ndarray
    xl_addr: int


def _workspace(plan: _Plan, nout: int) -> _Work:
    """This thread's workspace for ``nout`` outputs (reused between calls; at most 8
    shapes kept)."""
    table = getattr(_LOCAL, "work", None)
    if table is None:
        table = _LOCAL.work = {}
    key = (plan.nx, plan.nu, plan.np, nout)
    got = table.get(key)
    if got is None:
        if len(table) >= 8:
            table.clear()
        ws, XC, X = np.zeros(_size(plan, nout)), np.empty((plan.nx, nout + 1)), \
            np.empty((plan.nx, nout + 1))
        XL = np.empty((LANES, plan.nx, nout + 1))
        ws[_TRIES], ws[_NOUT] = TRIES, nout
        got = table[key] = _Work(ws, XC, ws.ctypes.data, XC.ctypes.data, X,
                                 (ws.ctypes.data, nout, BUDGET, X.ctypes.data, XC.ctypes.data),
                                 XL, XL.ctypes.data)
    return got


#: The header's inputs (its first slots, `FIELDS` from ``rtol`` to ``phase``), written by
#: one `struct` call (about a tenth of the cost of nine numpy item assignments).
_INPUTS = struct.Struct(f"{_PHASE + 1}d")


def _fill(ws: np.ndarray, plan: _Plan, t: np.ndarray, rtol: float, atol,
          max_steps: float, stiff_steps: float, factor: float | None = None,
          check: bool = True) -> None:
    """The inputs shared by the runs: header (the first answer at local tolerance ``factor``
    times the requested one), tolerances (``atol`` a float or ``(nx,)``) and output times
    (the C code resets the outputs of the header); ``factor`` None: `FIRST`. ``check``
    False: the answer alone at the requested tolerance (``tries`` 0), not checked."""
    factor = (FIRST if check else 1.0) if factor is None else factor
    _INPUTS.pack_into(ws, 0, rtol, factor, factor * CHECK, max_steps, stiff_steps, t[0],
                      plan.iq, TRIES if check else 0, 0.0)
    o = HEADER + plan.nx + plan.nu + plan.np
    ws[o:o + plan.nx] = atol
    ws[o + plan.nx:o + plan.nx + t.size - 1] = t[1:]


def _outcome(x: np.ndarray, head) -> DenseAuto:
    """The `DenseAuto` of a finished run from its header ``head`` (a sequence)."""
    result = int(head[_RESULT])
    return _NEW(DenseAuto, (x, result, head[_EST], int(head[_SPENT]), int(head[_NANS]),
                            int(head[_NCHK]), int(head[_REJ]), head[_HMIN],
                            int(head[_INTERP]), head[_RATIO], head[_FACTOR], head[_BOUND],
                            head[_FLOOR], int(head[_SUB]),
                            _REASONS[int(head[_FLAG])] if result == -3 else "", head[_ULPS],
                            int(head[_DRAWS]), head[_QOFF]))


#: ``DenseAuto`` from a tuple of every field, without its ``__new__``'s argument parsing.
_NEW = tuple.__new__


def dense_auto(problem: Problem, rtol: float, atol: np.ndarray, max_steps: float,
               stiff_steps: float, *, progress=None) -> DenseAuto | None:
    """The answer, its check run and verdict for ``problem`` in one compiled call (see the
    module docstring); None without a compiled pass or for a control that is not constant
    over the run.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics import rigid_body
    >>> from appdyn.dynamics.integrate.dense import dense_auto
    >>> from appdyn.dynamics.integrate.inputs import Problem, check_u
    >>> from appdyn.dynamics.truth.torque_free import torque_free_omega
    >>> model, t = rigid_body([1.5, 2.5, 3.2]), np.linspace(0.0, 60.0, 121)
    >>> x0 = np.r_[0.0, 0.0, 0.0, 1.0, 0.5, 0.0, 1.0]
    >>> problem = Problem.new(model, x0, t, check_u(None, 3, t), np.zeros(0))
    >>> got = dense_auto(problem, 1e-8, np.full(7, 1e-10), 1e8, 1e6)
    >>> w = torque_free_omega([1.5, 2.5, 3.2], x0[4:], t)
    >>> bool(got.result == 1 and np.abs(got.x[4:] - w).max() < 1e-8)
    True
    """
    ctrl = problem.control
    if ctrl.mode != "linear" or not constant_control(ctrl):
        return None
    u = ctrl.ua[0] if ctrl.ua.shape[0] else None
    return dense_run(problem.model, problem.x0, problem.t, rtol, atol, max_steps, stiff_steps,
                     u=u, p=problem.p, progress=progress)


def dense_run(model, x0: np.ndarray, t: np.ndarray, rtol: float, atol, max_steps: float,
              stiff_steps: float, *, u=None, p=None, progress=None,
              check: bool = True, plan: _Plan | None = None) -> DenseAuto | None:
    """`dense_auto` of checked inputs: ``x0 (nx,)``, the grid ``t (n,)``, ``atol`` a float or
    ``(nx,)``, the constant control ``u (nu,)`` (None: zero) and ``p (np,)``; None without a
    compiled pass, or for a grid ``t`` that is not finite and strictly increasing (the pass
    looks, so a caller may hand over a grid `inputs.check_t` has not seen: `check_t` then
    words the error). Per call: the model's plan looked up, the thread's workspace filled, one
    ``ctypes`` call with arguments built with the workspace, the answer copied out.
    ``check`` False: DOP853's answer alone at the tolerance asked, no check and no verdict
    (``result`` 2; ``method='dop853'``); a failed run's outputs after ``filled`` are NaN.
    ``plan``: the model's `pass_plan` when the caller has it (else looked up).

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics import rigid_body
    >>> from appdyn.dynamics.integrate.dense import dense_run
    >>> model = rigid_body([1.5, 2.5, 3.2])
    >>> got = dense_run(model, np.r_[0.0, 0.0, 0.0, 1.0, 0.5, 0.0, 1.0],
    ...                 np.array([0.0, 10.0]), 1e-8, 1e-10, 1e8, 1e6)
    >>> got.result, got.x.shape
    (1, (7, 2))
    """
    if plan is None:
        plan = pass_plan(model)
        if plan is None:
            return None
    nout = t.size - 1
    work = _workspace(plan, nout)
    ws = work.ws
    _fill(ws, plan, t, rtol, atol, max_steps, stiff_steps, check=check)
    nx, nu = plan.nx, plan.nu
    ws[HEADER:HEADER + nx] = x0
    if nu:
        ws[HEADER + nx:HEADER + nx + nu] = 0.0 if u is None else u
    if plan.np:
        ws[HEADER + nx + nu:HEADER + nx + nu + plan.np] = p
    if progress is not None and progress.fun is None:
        progress = None  # (nobody is told: no counting)
    auto, args = plan.auto, work.args
    vector = _single_lanes(model, plan) if check else None
    if vector is not None:  # (the check's steps in a lane of the answer's, a retry's floor
        # drawn in the others, into XL: the same bits)
        auto, args = vector.auto_v, args + (vector.address, vector.cont, work.xl_addr)
    if auto(*args) != 3:  # a long run: interrupts looked at between calls
        # (the steps made so far: of the runs ended, and of the run in progress)
        count = HEADER + 3 * nx + nu + plan.np + nout + 2
        told = 0
        with deferred_interrupts():
            while True:
                check_interrupt()
                told = _tell(progress, int(ws[_SPENT] + ws[count] + ws[count + 1]), told)
                if auto(*args) == 3:
                    break
        _tell(progress, int(ws[_SPENT]), told)
    elif progress is not None:
        _tell(progress, int(ws[_SPENT]), 0)
    head = ws[:HEADER].tolist()  # (Python floats: read once, cheaper than items of ws)
    if head[_RESULT] == -4:  # (a grid handed over unchecked: `check_t` words what is wrong)
        return None
    x = work.X.copy()
    if head[_RESULT] == -3:  # (the outputs filled before the failure; NaN after)
        x[:, 1 + int(ws[HEADER + 3 * nx + nu + plan.np + nout + 2 + 5]):] = np.nan
    return _outcome(x, head)


#: Single checked calls of a model in a process after which its vector lanes are asked for
#: (`lanes.dense_lanes`: loaded from disk, or compiled in the background while the calls go
#: on without them), and again every as many calls until they are there: a model called
#: this often is worth the one compile per machine (~0.5 s), a script's few calls are not.
SINGLE_LANES_AFTER = 16


def _single_lanes(model, plan: _Plan):
    """The vector lanes a single checked call of ``model`` takes (`lanes.dense_lanes`), or
    None (not loaded yet: asked for every `SINGLE_LANES_AFTER` calls)."""
    single = plan.single
    if single[1] is None:
        single[0] += 1
        if single[0] % SINGLE_LANES_AFTER == 0:
            single[1] = dense_lanes(model)
    return single[1]


def _tell(progress, steps: int, told: int) -> int:
    """``progress`` (a `loops.Progress` or None) told of the ``steps - told`` steps made
    since it was last told; returns ``steps``."""
    if progress is not None and steps > told:
        # the steps still ahead are unknown (the check run, maybe a retry): expect as many
        # again, so the total is reached only at the end (`Progress.finish`)
        progress.ahead = max(progress.ahead, steps)
        progress.start(steps - told)
        progress.advance(steps - told)
    return max(steps, told)


def dense_many(model, x0: np.ndarray, t: np.ndarray, u: np.ndarray, p: np.ndarray,
               rtol: float, atol: np.ndarray, max_steps: float, stiff_steps: float,
               runs, *, out: tuple[np.ndarray, np.ndarray] | None = None,
               factor: float | None = None, check: bool = True,
               vector=None, threads: int = 1) -> tuple[np.ndarray, np.ndarray] | None:
    """`dense_auto` for the runs ``runs`` of a batch in one compiled loop: ``x0 (K, nx)``,
    ``u (K, max(nu, 1))`` (each run's constant control), ``p (K, max(np, 1))``, all
    C-contiguous; ``runs`` a slice or integer indices of their rows; each run's first
    answer at local tolerance ``factor`` times the requested
    one (None: `FIRST`, as a single call; a batch learns its own,
    `dynamics.integrate.batch.first_factor`), a retry as in a single call; ``check`` False:
    each run's answer alone (as `dense_run`'s; a failed run's outputs past its failure are
    not written); ``vector`` (`lanes.dense_lanes` of the model, or None): the runs stepped
    `lanes.LANES` at a time in its vector lanes (``rk8_auto_lanes``: the same bits).

    The runs are handed out one at a time, in their order, through one counter that
    ``threads`` compiled loops share (`cpass` ``au_claim``: each thread, the caller's and
    those of `executors.worker_pool`, takes the next run as soon as it has room, so they
    finish together, and a thread that wakes late takes fewer); each loop returns to
    Python after about `MANY_BUDGET` steps to look at Ctrl-C (a deferred SIGINT: no run is
    taken after it, `KeyboardInterrupt` once the runs taken have finished). A run's answer
    depends on nothing but its inputs: the same bits on any number of threads, in any lane.

    Returns ``(X (r, nx, n), head (r, HEADER))``: the answers and each run's header
    (`outcome_of` reads it), in the order of ``runs``; None without a compiled pass.
    ``out``: C-contiguous ``(X (K, nx, n), head (K, HEADER))`` of the whole batch, whose
    rows ``runs`` the loops fill in place; those two arrays are then returned.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics import rigid_body
    >>> from appdyn.dynamics.integrate.dense import dense_many, outcome_of
    >>> model, t = rigid_body([1.5, 2.5, 3.2]), np.linspace(0.0, 20.0, 41)
    >>> x0 = np.array([[0, 0, 0, 1, 0.5, 0, 1.0], [0, 0, 0, 1, 0.1, 0.9, 0.2]])
    >>> X, head = dense_many(model, x0, t, np.zeros((2, 3)), np.zeros((2, 1)), 1e-8,
    ...                      np.full(7, 1e-10), 1e8, 1e6, slice(0, 2))
    >>> runs = [outcome_of(X[k], head[k]) for k in range(2)]
    >>> [r.result for r in runs]  # (each verified by its own check run)
    [1, 1]
    """
    plan = pass_plan(model)
    if plan is None:
        return None
    nout, K = t.size - 1, len(x0)
    index = np.arange(K, dtype=np.int64)[runs] if isinstance(runs, slice) else \
        np.ascontiguousarray(runs, dtype=np.int64)
    if index.size and not (0 <= index.min() and index.max() < K):  # (C reads these rows)
        raise ValueError(f"`runs` must index the {K} rows of `x0`, got indices from "
                         f"{index.min()} to {index.max()}")
    if out is None:
        X, head = np.empty((K, plan.nx, nout + 1)), np.empty((K, HEADER))
        if dense_many(model, x0, t, u, p, rtol, atol, max_steps, stiff_steps, index,
                      out=(X, head), factor=factor, check=check, vector=vector,
                      threads=threads) is None:
            return None
        return X[index], head[index]
    X, head = out
    if not (X.flags.c_contiguous and head.flags.c_contiguous and X.shape[1:] == (
            plan.nx, nout + 1) and head.shape[1:] == (HEADER,) and len(X) >= K and
            len(head) >= K):
        raise ValueError("`out` must be C-contiguous (X (K, nx, n), head (K, HEADER)) "
                         "covering the runs")
    cursor = np.zeros(1, np.int64)
    shared = (index.ctypes.data, index.size, cursor.ctypes.data, MANY_BUDGET,
              x0.ctypes.data, u.ctypes.data, p.ctypes.data, X.ctypes.data)
    lanes = vector is not None and index.size > 1

    def loop(_):  # (a thread's: its own workspace, calls until every run is handed out)
        work = _workspace(plan, nout)
        _fill(work.ws, plan, t, rtol, atol, max_steps, stiff_steps, factor, check)
        while not stop_requested():
            if lanes:
                done = vector.auto_lanes(work.ws_addr, nout, *shared, work.xl_addr,
                                         head.ctypes.data, vector.address, vector.cont)
            else:
                done = plan.many(work.ws_addr, nout, *shared, work.xc_addr, head.ctypes.data)
            if done < 0:
                raise MemoryError("the compiled loop over the runs could not allocate its "
                                  "workspace")
            if done:
                return

    threads = max(1, min(threads, -(-index.size // LANES) if lanes else index.size))
    with deferred_interrupts():
        run_split(loop, [None] * threads)
        check_interrupt()
    return X, head


#: Steps (lane-steps in vector lanes) after which a compiled loop of `dense_many` takes no
#: further run and returns, so that Ctrl-C is looked at: about 50 ms on the rigid body (a
#: second on a model 20 times its cost); each return lets the loop's lanes empty (~0.5 ms
#: on the torque-free batch of `bench/simulate.py`, 1 % of that time).
MANY_BUDGET = float(1 << 18)


def outcome_of(x: np.ndarray, head: np.ndarray) -> DenseAuto:
    """The `DenseAuto` of one run of `dense_many` (its answer ``x (nx, n)`` and header)."""
    return _outcome(x, head.tolist())
