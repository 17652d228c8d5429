"""Simulation of a `Model` on a time grid: compiled fixed-step loops, a Lie-group integrator,
SUNDIALS CVODES, and an ``auto`` mode that meets a requested global tolerance.

The public entry points are `dynamics.simulate`, `dynamics.SimulationResult`,
`dynamics.BatchResult`, `dynamics.Event` and `dynamics.METHODS`; the modules of this package are its internals, one job each:

===============  ===========================================================================
``api``          `simulate`: checks the inputs, runs the method, builds the result
``inputs``       normalisation and checks of ``t``, ``x0``, ``u``, tolerances -> `Problem`
``tableaux``     Butcher tableaux (data only) and stage nodes
``kernels``      one step of a method as a CasADi Function (explicit RK, Lie group CF4)
``loops``        the chunk Function (``mapaccum`` of steps, jit) and the fixed-step runner
``cvodes``       SUNDIALS CVODES through ``casadi.integrator``
``auto``         Richardson global-error estimates, round-off floor, stiffness test
``result``       `SimulationResult` and its dense output; `Run`, one run's outcome
``evaluate``     buffered numeric evaluation of Functions (no per-element conversion)
``events``       event functions (``events=``): zero crossings located on the solution,
                 `Event`; a terminal event truncates the result
``impacts``      impacts (``impacts=``): a guard's zero crossing applies a jump map and the
                 integration restarts; `Impact`, `ImpactRecord`, the Zeno guard
``batch``        K runs at once (``x0`` of shape (nx, K)): compiled loops over the runs,
                 spread over threads (``threads=``); `BatchResult`
``lanes``        a batch's runs four at a time in vector registers: fixed-step rk8, and
                 the DOP853 step and extension of ``auto``/``dop853`` batches
``sanity``       fixed-step runs checked against the model's invariants (status 4)
``smoothness``   the non-smooth operations (kinks, jumps) of a model's expression graph
``stepcontrol``  DOP853 with step rejection for non-smooth right-hand sides, and stepping
                 by its error estimate alone with dense output (`stepcontrol.plain_run`)
``dense``        ``auto`` for a smooth right-hand side under a constant control in ONE
                 compiled call: the dense-output answer, its check and the verdict
                 (`dense.dense_auto`); a batch's runs in one compiled loop, each with its
                 own steps and check (`dense.dense_many`)
``estimates``    the numbers ``auto`` rests on: scaled differences, round-off floors,
                 the spectrum at ``x0``, sign patterns
===============  ===========================================================================

Every fixed-step integration (``rk4``, ``rk8``, ``lie`` and the runs ``auto`` makes) calls
ONE CasADi Function per (model, method, control mode): a ``mapaccum`` of 512 steps, each
with its own step size and control data, wrapped in an MX Function (so the generated code is
a loop, never an unrolled SX graph) and jit-compiled to C under the policy of
`dynamics.cache`. A run of any length is a Python loop over such chunks, so neither the
generated code nor the compile time (about 0.25 s at -O1 for the rigid body, once per model and method) depends on the
grid length or the step count: 1e7 steps cost only their arithmetic. Built Functions are
kept in `dynamics.cache` by their defining arguments and called through
``Function.buffer()``, so a call costs microseconds of Python, not a data conversion per
element; the steps of a short last chunk past its length are skipped by a conditional
inside the loop.

Costs measured on a 2-core machine (rigid body, 7 states): per step about 55 ns (rk4),
140 ns (lie), 180-250 ns (rk8) compiled, 2-3 us interpreted, plus a few us of Python per
chunk of 512 steps. The default ``max_steps`` of ``auto`` (1e8 rk8 steps) is thus
about 20 s of compiled work. Compiling a model's chunk takes about 0.25-0.4 s, once; after it a
100 s torque-free run at rtol 1e-10 takes 3-4 ms (23 ms interpreted).

Controls
--------
``u`` is ``None`` (zero), a constant ``(nu,)`` vector, samples ``(nu, n)`` on the grid ``t``
(linear between samples: within interval ``k`` the control is
``u_k + (tau - t_k) (u_{k+1} - u_k) / (t_{k+1} - t_k)``, evaluated at every Runge-Kutta stage
time; or, with ``hold='zoh'``, ``u_k`` on the whole interval; the kinks and jumps sit on the
grid, where steps start and end, so no order is lost), or a
callable ``u(t) -> (nu,)`` evaluated at every stage time (fixed-step methods; the calls are
made from Python before the compiled loop runs) or at every right-hand-side evaluation
(``cvodes``, through a ``casadi.Callback``).

For a smooth right-hand side under a control constant over the run, ``auto`` steps DOP853
by its embedded error estimate alone and fills the outputs from its continuous extension of
order 7 (`auto.dense_pass`): its work follows the solution, never the output grid; the answer
is checked against its own steps merged in pairs (Richardson: that run's error is 2^8 times
the answer's), both runs and the comparison in one compiled call (`dense`), and a batch of such runs is one compiled loop over the runs,
each run with its own steps, check and verdict. Otherwise:
the error of a fixed-step run is controlled by the number of substeps; ``auto`` chooses it
per output interval from DOP853's embedded error estimate in one compiled pass and checks the
*global* error at the output times against a run with half the steps (`adaptive`), or, when
that check fails, from Richardson estimates of runs with different step counts (`auto`; see
`simulate`): the global error is what a tolerance should mean to a user. ``cvodes`` tolerances are local
error controls: they are not errors (on a 100 s tumbling body, rtol = 1e-10 gives 1e-7).

Adding a method
---------------
The contract a new method meets (as scipy's ``integrate/_ivp/base.py`` states its own):

1. **Name.** Add it to ``METHODS`` (and ``Method``) in ``api``; a fixed-step method also
   to ``_FIXED_STEP``, which makes it take ``steps`` and run through `loops.run_fixed`.
2. **An explicit Runge-Kutta method is data only**: a `tableaux.Tableau` (strictly lower
   ``a``, ``b``, ``c``, ``order``) registered in ``TABLEAUX``. `kernels.kernel` builds its step
   ``(x, h, u-data, p) -> x_next`` and `loops` its chunk; nothing else changes. Test its
   order conditions and its observed order (``tests/dynamics/test_simulate.py``).
3. **Any other one-step method** adds a step builder to `kernels` with the same inputs:
   ``x (nx)``, ``h``, then for control mode ``'linear'`` ``ua (nu)`` and ``ud (nu)`` (the
   control at the step start and its slope) or for ``'stages'`` ``us (nu * s)`` (the control
   at the method's distinct stage nodes, `tableaux.unique_nodes`), then ``p``; one output,
   the state after the step. It must be a pure function of these (no Python per step) and
   evaluable on MX; SX where the model allows. Register its nodes in ``tableaux``.
4. **A run** returns a `result.Run`: ``x (nx, n)`` on the output grid with ``x[:, 0] = x0``
   and NaN columns after a failure, the counters, ``ok`` and a ``message``. A numerical
   failure is ``ok=False``, never an exception; bad input is refused before the run (in
   ``inputs``) with an error naming the argument.
5. **Built Functions** go through `dynamics.cache.get`, keyed by
   ``(kind, cache.function_key(model.f), ...)`` with ``keepalive=model.f``; whether to compile
   is `dynamics.cache.should_compile`, never a count of earlier calls.
6. **Accuracy is proved, not claimed**: every method is checked against a closed form
   (``dynamics.truth``) in ``tests/dynamics``; ``success`` means verified.
"""
from __future__ import annotations

from .api import METHODS, Method, simulate
from .batch import BatchResult
from .events import Event
from .impacts import Impact, ImpactRecord
from .result import SimulationResult
from .. import diskcache

# The hash of the code that turns a model into C is taken now, as that code is imported:
# a library this process compiles later is keyed by the code it runs, even when the files
# on disk change in between (an upgrade or a checkout while a kernel keeps running).
diskcache.code_version()

__all__ = ["METHODS", "BatchResult", "Event", "Impact", "ImpactRecord", "Method", "SimulationResult", "simulate"]
