"""The work of one sample: `run_sample` of a `SampleTask` (module-level, picklable).

How draws reach a sample: a callable (the model factory, an ``x0`` callable, an output)
receives the draws it names as keyword arguments (all of them if it takes ``**kwargs``;
`accepted`). The other draws are *applied*: to the state of that name in ``x0``, to the
model parameter of that name in ``p``, or, for `ATTITUDE`, as a quaternion error composed
with x0's quaternion (``quat_mul(dq, q0)``).

A `SampleTask` pickles when its callables do: a `dynamics.Model` does (CasADi
serialization); a factory, ``x0`` callable, output or control ``u`` must be a module-level
function (or a ``functools.partial`` of one, a picklable instance), not a lambda or closure.
"""
from __future__ import annotations

import inspect
import time
from dataclasses import dataclass
from typing import Callable

import numpy as np

from appdyn.dynamics import cache, simulate, validate
from appdyn.dynamics.attitude import quat_mul
from appdyn.dynamics.model import Model, check_model
from appdyn.dynamics.scene import Scene

__all__ = ["SampleTask", "SampleOutcome", "run_sample", "run_samples", "accepted", "picked", "check_callable",
           "ATTITUDE", "NOT_SIMULATED", "as_model"]

ATTITUDE = "attitude"  # the params name of an attitude error (a quaternion composed with x0's)
NOT_SIMULATED = -2  # sample_status of a sample that failed outside the simulation


def as_model(model, name: str = "model") -> Model:
    """The `Model` of a `dynamics.scene.Scene` (``scene.model()``), or ``model`` checked.

    Raises
    ------
    TypeError
        Naming ``name`` if it is neither a Model nor a Scene.

    Examples
    --------
    >>> from appdyn.dynamics.scene import RigidHub, Scene
    >>> as_model(Scene(RigidHub([1.0, 2.0, 3.0]))).states
    ('q1', 'q2', 'q3', 'q4', 'w1', 'w2', 'w3')
    """
    return model.model() if isinstance(model, Scene) else check_model(model, name)


@dataclass(frozen=True)
class SampleTask:
    """Everything one sample needs (picklable when its callables are module-level)."""

    index: int
    values: dict
    model: object
    x0: object
    t: np.ndarray
    outputs: dict
    applied: tuple
    drift: object
    simulate_kwargs: dict


@dataclass(frozen=True)
class SampleOutcome:
    """What one sample returns: its outputs (arrays) and whether it succeeded."""

    index: int
    success: bool
    status: int
    message: str
    outputs: dict
    wall_time: float


def accepted(fun: Callable, names, *, skip: int = 0) -> tuple:
    """The ``names`` that ``fun`` takes as keyword arguments (all of them with ``**kwargs``),
    after its first ``skip`` positional parameters."""
    try:
        sig = inspect.signature(fun)
    except (TypeError, ValueError):
        return ()
    params = list(sig.parameters.values())
    if any(p.kind is p.VAR_KEYWORD for p in params):
        return tuple(names)
    takes = {p.name for p in params[skip:] if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)}
    return tuple(n for n in names if n in takes)


def check_callable(fun, values, name: str, skip: int = 0) -> None:
    """``TypeError`` naming ``name`` when ``fun`` cannot take the draws it is given (after
    ``skip`` positional placeholders): a required argument that ``params`` does not draw."""
    try:
        sig = inspect.signature(fun)
    except (TypeError, ValueError):
        return
    try:
        sig.bind(*([None] * skip), **picked(fun, values, skip))
    except TypeError as exc:
        raise TypeError(f"`{name}` cannot be called with the drawn params "
                        f"{list(values)}: {exc}") from None


def picked(fun, values, skip=0) -> dict:
    """The draws of ``values`` that ``fun`` takes (`accepted`), by name."""
    return {k: values[k] for k in accepted(fun, values, skip=skip)}


def _initial(task: SampleTask, model: Model, p_base):
    """``x0`` and ``p`` of the sample: the nominal ones with the applied draws set."""
    x0 = task.x0(**picked(task.x0, task.values)) if callable(task.x0) else task.x0
    x0 = np.array(validate.finite_array(x0, "x0"), dtype=float).reshape(-1)
    p = np.array(model.resolve_p(p_base), dtype=float)
    for name in task.applied:
        value = task.values[name]
        if name == ATTITUDE:
            if model.attitude is None:
                raise ValueError(f"`params` entry {ATTITUDE!r} needs a model with an attitude")
            iq = model.attitude[0]
            dq = validate.unit_quaternion(value, f"params[{ATTITUDE!r}]")
            x0[iq:iq + 4] = quat_mul(dq, x0[iq:iq + 4])
        elif name in model.states:
            x0[model.states.index(name)] = validate.finite_scalar(value, f"params[{name!r}]")
        elif name in model.params:
            p[model.params.index(name)] = validate.finite_scalar(value, f"params[{name!r}]")
        else:
            raise ValueError(f"`params` entry {name!r} is not taken by the model factory, the "
                             f"x0 callable or an output, and is not a state {model.states}, "
                             f"a parameter {model.params} or {ATTITUDE!r}")
    return x0, p


def _evaluate(task: SampleTask, res) -> dict:
    out = {}
    for name, spec in task.outputs.items():
        value = res[spec] if isinstance(spec, str) else spec(res, **picked(spec, task.values, 1))
        out[name] = np.array(value, dtype=float)
    if task.drift:
        drift = res.invariant_drift
        names = tuple(drift) if task.drift is True else task.drift
        for name in names:
            out[f"{name}_drift"] = np.array(drift[name], dtype=float)
    return out


@cache.constructs
def _built(factory, values) -> Model:
    """The factory's model of one sample, built under the construction lock: a factory
    builds CasADi symbols (``model_from_expressions``, a scene), and samples run on threads
    (`dynamics.cache`)."""
    return as_model(factory(**picked(factory, values)), "model (returned by the factory)")


def run_sample(task: SampleTask) -> SampleOutcome:
    """One sample: build the model, set ``x0`` and ``p``, simulate, evaluate the outputs.

    Any ``Exception`` (of the factory, ``x0``, ``simulate`` or an output) makes the sample a
    failure with the exception's text; ``KeyboardInterrupt`` propagates.

    Raises
    ------
    TypeError
        If ``task`` is not a `SampleTask` (a programming error, not a failed sample).
    """
    if not isinstance(task, SampleTask):
        raise validate.ArgumentTypeError(f"`task` must be a SampleTask, got {type(task).__name__}")
    start = time.perf_counter()
    status = NOT_SIMULATED
    try:
        kwargs = dict(task.simulate_kwargs)
        model = task.model if isinstance(task.model, Model) else _built(task.model, task.values)
        x0, p = _initial(task, model, kwargs.pop("p", None))
        res = simulate(model, x0, task.t, p=p, **kwargs)
        status = int(res.status)
        if not res.success:
            return SampleOutcome(task.index, False, status, f"simulate: {res.message}", {},
                                 time.perf_counter() - start)
        outputs = _evaluate(task, res)
    except Exception as exc:  # noqa: BLE001 -- a failing sample is data, not a crash
        return SampleOutcome(task.index, False, status, f"{type(exc).__name__}: {exc}", {},
                             time.perf_counter() - start)
    return SampleOutcome(task.index, True, status, "", outputs, time.perf_counter() - start)


def run_batch(tasks) -> list:
    """All ``tasks`` (samples of one fixed `Model`) in ONE batched `simulate` call (x0 of
    shape (nx, K): `dynamics.integrate.batch`), then each sample's outputs; outcomes as
    `run_sample`'s. A sample whose inputs fail is a failure and left out of the batch."""
    start = time.perf_counter()
    model = check_model(tasks[0].model)
    kwargs = dict(tasks[0].simulate_kwargs)
    p_base = kwargs.pop("p", None)
    outcomes, ready = {}, []
    for task in tasks:
        try:
            ready.append((task, *_initial(task, model, p_base)))
        except Exception as exc:  # noqa: BLE001 -- a failing sample is data, not a crash
            outcomes[task.index] = SampleOutcome(task.index, False, NOT_SIMULATED,
                                                 f"{type(exc).__name__}: {exc}", {}, 0.0)
    if len(ready) == 1:  # a batch needs K >= 2: the one sample alone
        outcomes[ready[0][0].index] = run_sample(ready[0][0])
    elif ready:
        res = simulate(model, np.stack([r[1] for r in ready], axis=1), tasks[0].t,
                       p=np.stack([r[2] for r in ready], axis=1), **kwargs)
        share = (time.perf_counter() - start) / len(ready)
        for k, (task, _, _) in enumerate(ready):
            one = res.run(k)
            status = int(one.status)
            if not one.success:
                outcome = SampleOutcome(task.index, False, status, f"simulate: {one.message}",
                                        {}, share)
            else:
                try:
                    outcome = SampleOutcome(task.index, True, status, "", _evaluate(task, one),
                                            share)
                except Exception as exc:  # noqa: BLE001 -- an output that raises is data
                    outcome = SampleOutcome(task.index, False, status,
                                            f"{type(exc).__name__}: {exc}", {}, share)
            outcomes[task.index] = outcome
    return [outcomes[task.index] for task in tasks]


def run_samples(tasks) -> list:
    """`run_sample` of each task in turn: one executor job for a chunk of samples (a model
    in the chunk is pickled and unpickled once, so its built loops are reused)."""
    return [run_sample(task) for task in tasks]
