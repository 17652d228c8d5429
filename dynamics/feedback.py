"""Feedback: `closed_loop`, a `Model` with its controls given by a state-feedback law.

The law is a ``casadi.Function`` inserted into the right-hand side, so the closed loop is an
ordinary model: `dynamics.simulate` runs it in its compiled fixed-step loops (no Python per
step), `dynamics.linearize` and the collocation engine differentiate through the law.
"""
from __future__ import annotations

from typing import Mapping

import casadi as ca

from . import cache
from .model import Model, check_model

__all__ = ["closed_loop"]


def _controller_inputs(model: Model, controller: ca.Function) -> list[tuple[str, int]]:
    """``(name, size)`` of the controller's inputs after ``x``; checks every shape."""
    if not isinstance(controller, ca.Function):
        raise TypeError(f"`controller` must be a casadi.Function u = k(x[, p][, r...]), got "
                        f"{type(controller).__name__}")
    if controller.n_in() < 1 or controller.n_out() != 1:
        raise ValueError(f"`controller` must have at least one input (the state x) and exactly "
                         f"one output (the control u), got {controller.n_in()} inputs and "
                         f"{controller.n_out()} outputs")
    expected = {0: ("the state x", model.nx)}
    names = controller.name_in()
    for i, name in enumerate(names[1:], start=1):
        if name == "p":
            expected[i] = ("the parameters p", model.np)
    for i in range(controller.n_in()):
        if not controller.sparsity_in(i).is_dense():
            raise ValueError(f"input {names[i]!r} of `controller` must be dense")
        if i in expected and controller.numel_in(i) != expected[i][1]:
            raise ValueError(f"input {i} ({names[i]!r}) of `controller` is {expected[i][0]} and "
                             f"must have {expected[i][1]} elements, got {controller.numel_in(i)}")
    if controller.numel_out(0) != model.nu:
        raise ValueError(f"the output of `controller` is the control of `model` and must have "
                         f"{model.nu} elements {model.controls}, got {controller.numel_out(0)}")
    return [(names[i], controller.numel_in(i)) for i in range(1, controller.n_in())
            if i not in expected]


def _build(model: Model, controller: ca.Function, extra: list, units: dict) -> Model:
    x = ca.MX.sym("x", model.nx)
    p = ca.MX.sym("p", model.np)
    r = [ca.MX.sym(name, size) for name, size in extra]
    pending = iter(r)
    args = []
    for i, name in enumerate(controller.name_in()):
        value = x if i == 0 else p if name == "p" else next(pending)
        args.append(ca.reshape(value, controller.size_in(i)))
    u = ca.reshape(controller.call(args)[0], model.nu, 1)
    xdot = model.f(x=x, u=u, p=p)["xdot"]
    f = ca.Function("closed_loop", [x, ca.vertcat(*r) if r else ca.MX(0, 1), p], [xdot],
                    ["x", "u", "p"], ["xdot"])
    try:
        f = f.expand()  # SX where every part allows it: faster and compiles smaller
    except RuntimeError:
        pass
    controls = tuple(name if size == 1 else f"{name}{k + 1}"
                     for name, size in extra for k in range(size))
    unknown = sorted(set(units) - set(controls))
    if unknown:
        raise ValueError(f"`units` names {unknown}, which are not controls of the closed loop "
                         f"{controls}")
    kept = {k: v for k, v in model.units.items() if k in model.states or k in model.params}
    return Model(f=f, states=model.states, controls=controls, params=model.params,
                 p_default=model.p_default, units={**kept, **units},
                 invariants=model.invariants, name=f"{model.name}+{controller.name()}",
                 attitude=model.attitude)


def closed_loop(model: Model, controller: ca.Function, *,
                units: Mapping[str, str] | None = None) -> Model:
    """Close the loop ``u = controller(x, ...)`` around ``model``.

    Parameters
    ----------
    model : Model
        The open-loop system ``x' = f(x, u, p)``.
    controller : casadi.Function
        The law, one output (``u``, ``model.nu`` elements, any dense shape). Inputs, matched
        by position and name: the first is the state ``x`` (``model.nx`` elements); an input
        named ``'p'`` receives the model's parameters (``model.np`` elements); every other
        input (a reference, a setpoint, a gain to vary) becomes a control of the closed loop.
    units : mapping of str to str, optional
        Units of the closed loop's controls, by name.

    Returns
    -------
    Model
        Same states, parameters (and defaults), state and parameter units, invariants and
        ``attitude`` as ``model``; its controls are the controller's extra inputs, named after
        them (``r`` for a scalar input ``r``, ``r1, r2, ...`` for a vector), none for a pure
        state feedback. Named ``f"{model.name}+{controller.name()}"``. Cached by the
        identity of ``model`` and ``controller``: closing the same loop again returns the same
        model, so `dynamics.simulate` reuses its compiled loop.

    Raises
    ------
    TypeError
        If ``model`` is not a `Model` or ``controller`` not a ``casadi.Function``.
    ValueError
        Naming ``controller``: not exactly one output, a sparse input, the state (or ``p``)
        input or the output of the wrong size; naming ``units``: a name that is not a
        control of the closed loop.

    Examples
    --------
    >>> import casadi as ca
    >>> import numpy as np
    >>> from appdyn.dynamics import rigid_body, simulate
    >>> from appdyn.dynamics import closed_loop
    >>> x = ca.SX.sym("x", 7)
    >>> damper = ca.Function("rate_damper", [x], [-2.0 * x[4:7]], ["x"], ["u"])  # L = -2 w
    >>> loop = closed_loop(rigid_body([1.0, 1.0, 1.0]), damper)
    >>> loop.name, loop.controls
    ('rigid_body+rate_damper', ())
    >>> res = simulate(loop, [0, 0, 0, 1, 0.1, 0.0, 0.0], [0.0, 1.0], method="rk8", steps=50)
    >>> round(float(res.x[4, -1]), 9)  # w1' = -2 w1
    0.013533528
    """
    model = check_model(model)
    extra = _controller_inputs(model, controller)
    units = dict(units or {})
    key = ("closed_loop", cache.function_key(model.f), id(model), cache.function_key(controller),
           tuple(sorted(units.items())))
    return cache.get(key, lambda: _build(model, controller, extra, units),
                     keepalive=(model, controller))
