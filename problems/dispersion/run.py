"""`dispersion`: Monte Carlo runs of `dynamics.simulate` over drawn inputs, on any executor.

The driver checks the arguments, draws every sample's inputs up front (in this process,
`problems.dispersion.distributions`), hands one `SampleTask` per sample to the executor
(the work is the module-level `run_sample` of `problems.dispersion.sample`), collects the
outcomes by sample index and assembles the `DispersionResult`. With a
``ProcessPoolExecutor`` everything a task carries must pickle: the model factory, an ``x0``
callable, the output callables and a callable control ``u`` must be module-level functions
(checked up front: a ``TypeError`` names the argument that does not pickle).
"""
from __future__ import annotations

import inspect
import math
import os
import pickle
import sys
import time
from concurrent.futures import Executor
from typing import Callable, Mapping

import numpy as np

from appdyn.dynamics import simulate, validate
from appdyn.dynamics.integrate import METHODS
from appdyn.dynamics.integrate.inputs import check_t
from appdyn.dynamics.executors import check_executor, gather
from appdyn.dynamics.progress import accepts_progress_bar
from appdyn.dynamics.interrupts import check_interrupt, interruptible
from appdyn.dynamics.model import Model
from appdyn.dynamics.scene import Scene

from .distributions import check_spec, draw_samples
from .result import DispersionResult, assemble
from .sample import (ATTITUDE, SampleTask, accepted, as_model, check_callable, picked,
                     run_batch, run_sample, run_samples)

__all__ = ["dispersion"]

_OWN = ("model", "x0", "t", "progress")  # simulate's arguments that dispersion sets itself


# ---------------------------------------------------------------------------- checks
def _is_process_pool(executor) -> bool:
    """Whether ``executor`` is a ``ProcessPoolExecutor`` (there is none unless its module, heavy
    to import, was imported)."""
    module = sys.modules.get("concurrent.futures.process")
    return module is not None and isinstance(executor, module.ProcessPoolExecutor)


def _check_outputs(outputs) -> dict:
    if not isinstance(outputs, Mapping):
        raise TypeError(f"`outputs` must be a mapping of names to callables (res, **draws) or "
                        f"state names, got {type(outputs).__name__}")
    for name, spec in outputs.items():
        if not isinstance(name, str):
            raise TypeError(f"`outputs` keys must be strings, got {name!r}")
        if not (callable(spec) or isinstance(spec, str)):
            raise TypeError(f"`outputs[{name!r}]` must be a callable (res, **draws) or a state "
                            f"name, got {type(spec).__name__}")
    return dict(outputs)


def _check_params(params) -> dict:
    if params is None:
        return {}
    if not isinstance(params, Mapping):
        raise TypeError(f"`params` must be a mapping of names to specs, got "
                        f"{type(params).__name__}")
    for name in params:
        if not isinstance(name, str):
            raise TypeError(f"`params` keys must be strings, got {name!r}")
    return {name: check_spec(spec, f"params[{name!r}]") for name, spec in params.items()}


def _check_drift(drift):
    if drift is True or drift is False:
        return drift
    if isinstance(drift, str) or not all(isinstance(d, str) for d in np.atleast_1d(drift)):
        raise TypeError(f"`invariant_drift` must be a bool or a sequence of invariant names, "
                        f"got {drift!r}")
    return tuple(drift)


def _check_simulate_kwargs(kwargs: dict, factory: bool) -> dict:
    known = set(inspect.signature(simulate).parameters) - set(_OWN)
    for name in kwargs:
        if name not in known:
            raise TypeError(f"`{name}` is not an argument of dispersion or simulate "
                            f"(simulate takes {sorted(known)})")
    if "method" in kwargs:
        validate.one_of(kwargs["method"], "method", METHODS)
    if factory and "jit" not in kwargs:
        kwargs["jit"] = False  # every sample is a new model: compiling each costs ~0.4 s
    return kwargs


def _check_model_names(model: Model, applied, outputs, drift) -> None:
    """Names that a model fixes up front: applied draws, state outputs, invariants."""
    for name in applied:
        if name != ATTITUDE and name not in model.states and name not in model.params:
            raise ValueError(f"`params` entry {name!r} is not taken by the model factory, the "
                             f"x0 callable or an output, and is not a state {model.states}, "
                             f"a parameter {model.params} or {ATTITUDE!r}")
        if name == ATTITUDE and model.attitude is None:
            raise ValueError(f"`params` entry {ATTITUDE!r} needs a model with an attitude")
    for name, spec in outputs.items():
        if isinstance(spec, str) and spec not in model.states:
            raise ValueError(f"`outputs[{name!r}]` names no state: {spec!r} (states "
                             f"{model.states})")
    if drift not in (True, False):
        unknown = [d for d in drift if d not in model.invariants]
        if unknown:
            raise ValueError(f"`invariant_drift` names unknown invariants {unknown}; the model "
                             f"has {tuple(model.invariants)}")


def _check_picklable(items: dict) -> None:
    for name, obj in items.items():
        try:
            pickle.dumps(obj)
        except Exception as exc:  # noqa: BLE001 -- pickling raises many kinds
            raise TypeError(
                f"`{name}` must be picklable for a ProcessPoolExecutor (a module-level "
                f"function, not a lambda or closure): {type(exc).__name__}: {exc}") from None


# ---------------------------------------------------------------------------- driver
@accepts_progress_bar("dispersion")
@interruptible
def dispersion(model, x0, t, *, samples: int, seed: int | None, outputs: Mapping,
               params: Mapping | None = None, invariant_drift=False,
               executor: Executor | None = None,
               progress: Callable[[int, int], None] | None = None,
               percentiles=(1.0, 50.0, 99.0), units: Mapping | None = None,
               chunksize: int | None = None, batch: bool = False,
               **simulate_kwargs) -> DispersionResult:
    """Simulate ``samples`` draws of the inputs and collect statistics of named outputs.

    Parameters
    ----------
    model : Model, Scene or callable
        The dynamics (a `dynamics.scene.Scene` stands for ``scene.model()``), or a factory
        ``model(**draws) -> Model or Scene`` called in each sample with the drawn ``params``
        it names as keywords (all of them if it takes ``**kwargs``), e.g. an inertia that
        `dynamics.rigid_body` or a scene's hub bakes into its model. For a process pool, a
        module-level function. A factory runs under the construction lock of
        `dynamics.cache` (it builds CasADi symbols, and samples may run on threads): keep
        heavy numeric work out of it.
    x0 : array_like, shape (nx,), or callable
        Nominal initial state, or ``x0(**draws) -> (nx,)`` (keywords as for the factory).
    t : array_like, shape (n,) [s]
        Output grid of every simulation (strictly increasing, ``n >= 2``).
    samples : int
        Number of samples, ``>= 1``.
    seed : int or None
        ``>= 0``; sample ``i`` draws from ``default_rng(SeedSequence(seed).spawn(samples)[i])``
        (see `problems.dispersion.distributions`). ``None`` draws fresh entropy, kept in
        ``result.seed`` to reproduce the run.
    outputs : mapping of str to callable or str
        Per sample, ``f(res, **draws) -> float or array`` of the `SimulationResult` ``res``
        and the draws ``f`` names as keywords after ``res``; a state name gives its time
        history ``res[name]`` (n,). Same shape in every sample.
    params : mapping of str to spec, optional
        What is dispersed: each a number/array (fixed), a `Distribution` or a callable
        ``rng -> value``, drawn in mapping order. A name that no callable (factory, ``x0``,
        outputs) takes sets the state of that name in ``x0``, the model parameter of that
        name in ``p``, or, for ``"attitude"`` (e.g. `SmallRotation`), composes a quaternion
        ``dq`` with x0's: ``quat_mul(dq, q0)``.
    invariant_drift : bool or sequence of str, optional
        Also output ``"<name>_drift"``: ``res.invariant_drift[name]`` of all (``True``) or the
        named model invariants.
    executor : concurrent.futures.Executor, optional
        Runs the samples (default: serially, here). Results are identical to a serial run
        and ordered by sample; only ``wall_times`` differ.
    progress : bool or callable, optional
        ``True``: a bar on stderr (`dynamics.progress`); a callable: ``progress(done,
        total)`` in this thread after each finished sample.
    percentiles : sequence of float, optional
        Percentiles [%] of the statistics (in ``[0, 100]``).
    units : mapping of str to str, optional
        Units of outputs and inputs for the table and plots.
    chunksize : int, optional
        Samples per executor job (``>= 1``). Default: 1, and for a ``ProcessPoolExecutor``
        ``ceil(samples / (4 * os.cpu_count()))``: a fixed `Model` crosses to the worker once
        per job, and a model unpickled in a worker is new to its cache (its integration
        loop is rebuilt, ~20 ms for a rigid body), so small jobs waste that per sample.
    batch : bool, optional
        With a fixed `Model` (not a factory) and no executor: all samples in ONE batched
        `dynamics.simulate` call (``x0`` of shape ``(nx, K)``, one compiled loop over the
        samples on the cores). ``method='auto'`` then runs each sample with its own DOP853
        steps, check and verdict, as a single call does (`dynamics.integrate.batch`); from
        64 samples on, most samples' first local tolerance is learned from the first ones
        (`dynamics.integrate.batch.first_factor`), so their results differ from per-sample
        runs within the tolerance, the same bits on any number of threads. ``progress`` is
        called once, when all are done; a Ctrl-C keeps no partial result.
    **simulate_kwargs
        Passed to `dynamics.simulate` (``method``, ``rtol``, ``atol``, ``u``, ``p``,
        ``steps``, ``jit``, ...). With a factory, ``jit`` defaults to ``False`` (each sample
        is a new model; compiling each costs about 0.4 s).

    Returns
    -------
    DispersionResult

    Raises
    ------
    TypeError
        Naming the argument: ``model`` neither a Model nor callable, ``outputs``/``params``
        not mappings or of the wrong kinds, ``executor`` not an Executor, ``progress`` not
        callable, an unknown keyword, or, with a ``ProcessPoolExecutor``, something that
        does not pickle.
    ValueError
        Naming the argument: ``samples``, ``seed``, ``t``, ``x0``, ``percentiles``,
        ``chunksize``, ``method``, a ``params`` entry that nothing takes, an output naming
        no state, an unknown invariant.
    KeyboardInterrupt
        On Ctrl-C; when samples had finished, ``exc.partial`` is their `DispersionResult`
        (``complete=False``). Pending samples of an executor are cancelled.

    Notes
    -----
    A failing sample (the factory or an output raises, ``simulate`` returns
    ``success=False``) is recorded as such with its message; it does not stop the others.

    Examples
    --------
    A decay ``y' = -k y`` with a dispersed rate ``k``; the truth is ``y(1) = exp(-k)``:

    >>> import casadi as ca
    >>> import numpy as np
    >>> from appdyn.dynamics.model import model_from_expressions
    >>> from appdyn.problems.dispersion import Uniform, dispersion
    >>> y, k = ca.SX.sym("y"), ca.SX.sym("k")
    >>> decay = model_from_expressions({"y": y}, {"y": -k * y}, params={"k": k}, p_default=[1.0])
    >>> res = dispersion(decay, [1.0], [0.0, 1.0], samples=50, seed=0,
    ...                  params={"k": Uniform(0.5, 1.5)},  # sets the model parameter k
    ...                  outputs={"y1": lambda r: r["y"][-1]})
    >>> bool(np.allclose(res.outputs["y1"], np.exp(-res.inputs["k"]), rtol=1e-7))
    True
    >>> s = res.statistics["y1"]
    >>> s.count, bool(s.min <= s.percentiles[50.0] <= s.max)
    (50, True)
    """
    start = time.perf_counter()
    if isinstance(model, Scene):
        model = model.model()
    if not (isinstance(model, Model) or callable(model)):
        raise TypeError(f"`model` must be a Model, a Scene or a factory callable, got "
                        f"{type(model).__name__}")
    samples = validate.integer(samples, "samples", minimum=1)
    seed = int(np.random.SeedSequence().entropy) if seed is None else \
        validate.integer(seed, "seed", minimum=0)
    t = check_t(t)
    if not callable(x0):
        x0 = np.array(validate.finite_array(x0, "x0"), dtype=float)
        if x0.ndim != 1:
            raise ValueError(f"`x0` must have shape (nx,), got {x0.shape}")
    outputs = _check_outputs(outputs)
    params = _check_params(params)
    drift = _check_drift(invariant_drift)
    check_executor(executor)
    if progress is not None and not callable(progress):
        raise TypeError(f"`progress` must be None or a callable (done, total), got "
                        f"{type(progress).__name__}")
    pct = validate.finite_array(percentiles, "percentiles")
    if pct.ndim != 1 or np.any((pct < 0) | (pct > 100)):
        raise ValueError(f"`percentiles` must be a sequence of numbers in [0, 100], got "
                         f"{percentiles!r}")
    units = {} if units is None else {str(k): str(v) for k, v in dict(units).items()}
    if chunksize is None:
        chunksize = math.ceil(samples / (4 * (os.cpu_count() or 1))) \
            if _is_process_pool(executor) else 1
    chunksize = validate.integer(chunksize, "chunksize", minimum=1)
    factory = not isinstance(model, Model)
    kwargs = _check_simulate_kwargs(dict(simulate_kwargs), factory)
    if batch not in (True, False):
        raise TypeError(f"`batch` must be True or False, got {batch!r}")
    if batch and (factory or executor is not None):
        raise ValueError("`batch=True` needs a fixed Model (not a factory) and no executor: "
                         "the batch is one simulate call in this process")

    if factory:
        check_callable(model, params, "model")
    if callable(x0):
        check_callable(x0, params, "x0")
    for name, spec in outputs.items():
        if callable(spec):
            check_callable(spec, params, f"outputs[{name!r}]", skip=1)
    taken = set()
    for fun, skip in [(model, 0)] * factory + [(x0, 0)] * callable(x0) + \
            [(f, 1) for f in outputs.values() if callable(f)]:
        taken.update(accepted(fun, params, skip=skip))
    applied = tuple(n for n in params if n not in taken)
    draws = draw_samples(params, seed, samples)
    probe = model if not factory else _probe(model, draws[0])
    if probe is not None:
        _check_model_names(probe, applied, outputs, drift)
        if not callable(x0) and x0.shape != (probe.nx,):
            raise ValueError(f"`x0` must have shape ({probe.nx},), got {x0.shape}")
    if _is_process_pool(executor):
        _check_picklable({"model": model, "x0": x0, "outputs": outputs, "simulate_kwargs": kwargs})
    tasks = [SampleTask(i, draws[i], model, x0, t, outputs, applied, drift, kwargs)
             for i in range(samples)]

    done: dict = {}

    def result(complete: bool) -> DispersionResult:
        return assemble(done, draws, t, seed, samples, params, units, executor,
                         time.perf_counter() - start, complete, tuple(float(p) for p in pct))

    try:
        if batch:
            done.update((o.index, o) for o in run_batch(tasks))
            if progress is not None:
                progress(len(done), samples)
        else:
            _execute(tasks, executor, progress, done, chunksize)
    except BaseException as exc:
        if done and isinstance(exc, KeyboardInterrupt):
            exc.partial = result(False)
        raise
    return result(True)


def _probe(factory, values):
    """The factory's model for one draw (to check names up front), or None if it fails."""
    try:
        return as_model(factory(**picked(factory, values)))
    except Exception:  # noqa: BLE001 -- that sample will report it
        return None


def _execute(tasks, executor, progress, done: dict, chunksize: int) -> None:
    """Run ``tasks`` (``chunksize`` per executor job), filling ``done[index] = outcome`` as
    they finish."""
    total = len(tasks)

    def finished(outcome):
        done[outcome.index] = outcome
        if progress is not None:
            progress(len(done), total)

    if executor is None:
        for task in tasks:
            check_interrupt()
            finished(run_sample(task))
        return
    chunks = [(tasks[k:k + chunksize],) for k in range(0, total, chunksize)]
    gather(executor, run_samples, chunks, lambda _, outcomes: [finished(o) for o in outcomes])
