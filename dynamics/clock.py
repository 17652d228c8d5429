"""The one way a model depends on time: an explicit clock state ``t`` [s] with ``t' = 1``.

A time-dependent model (a prescribed motion, a shaken hinge, a pendulum whose string is
reeled in) carries its time as one of its states, named `CLOCK_STATE` (``"t"``, unit
``"s"``), whose derivative is exactly 1. The right-hand side ``f(x, u, p)`` then stays
autonomous, so `dynamics.simulate`, `dynamics.linearize`, the collocation engine and
`dynamics.floquet` take such models unchanged: they integrate, differentiate and
transcribe the clock like any other state.

The convention, for a model author:

* name the state ``"t"`` with unit ``"s"`` and derivative ``1``; build every prescribed
  input from that symbol (``a sin(Omega t)``), never from a Python float;
* put it after the mechanical states (``[theta, theta_dot, t]``): the mechanical states then
  keep their indices in the reduced (clock-free) matrices of `dynamics.floquet`;
* the user starts the clock at the first output time: ``x0[clock_index(model)] == t[0]``;
  `check_clock_start` checks that (a clock started elsewhere shifts every prescribed
  motion in time).

What it means for the other tools: simulating over ``t`` integrates ``t' = 1`` exactly
(every Runge-Kutta method is exact on it, up to the round-off of summing the steps: about
1e-13 s after 10^4 steps, so evaluate time laws at the clock state, not at the grid); a
linearization holds the clock's row ``[0 ... 0]`` and its column ``d f / d t`` (the
explicit time dependence) -- a time-dependent model is rarely at equilibrium, which the
residual reports; the Floquet monodromy drops the clock's row and column (its multiplier
is trivially 1).

Examples
--------
A mass on a spring whose anchor is driven by ``a sin(t)``; the clock is the third state:

>>> import casadi as ca
>>> import numpy as np
>>> from appdyn.dynamics import Model, simulate
>>> from appdyn.dynamics.clock import CLOCK_STATE, check_clock_start, clock_index
>>> x, u, p = ca.SX.sym("x", 3), ca.SX.sym("u", 0), ca.SX.sym("p", 1)
>>> y, ydot, t = x[0], x[1], x[2]
>>> xdot = ca.vertcat(ydot, -(y - p[0] * ca.sin(t)), 1)      # clock: t' = 1
>>> f = ca.Function("driven", [x, u, p], [xdot], ["x", "u", "p"], ["xdot"])
>>> model = Model(f, ("y", "ydot", CLOCK_STATE), (), ("a",), p_default=[0.1],
...               units={"y": "m", "ydot": "m/s", "t": "s", "a": "m"})
>>> clock_index(model)
2
>>> grid = np.linspace(2.0, 3.0, 5)
>>> x0 = check_clock_start(model, [0.0, 0.0, 2.0], grid[0])   # starts at t[0] = 2 s
>>> res = simulate(model, x0, grid, method="rk8", steps=4, jit=False)
>>> float(res.x[2, -1])                                       # the clock kept time
3.0
>>> check_clock_start(model, [0.0, 0.0, 0.0], grid[0])
Traceback (most recent call last):
    ...
ValueError: `x0` sets the clock state 't' (index 2) to 0.0 s, but the time grid starts ...
"""
from __future__ import annotations

import numpy as np

from . import validate
from .model import check_model

__all__ = ["CLOCK_STATE", "CLOCK_UNIT", "CLOCK_RTOL", "clock_index", "check_clock_start"]

#: name of the clock state of every time-dependent model
CLOCK_STATE = "t"
#: its unit
CLOCK_UNIT = "s"
#: relative tolerance of `check_clock_start` (of ``max(1, |t0|)``): a clock read from a
#: previous run's output grid may differ from ``t[0]`` by round-off, not by more
CLOCK_RTOL = 1e-12


def clock_index(model) -> int | None:
    """Index of the clock state ``"t"`` in ``model.states``, or ``None`` if it has none.

    Parameters
    ----------
    model : Model

    Returns
    -------
    int or None

    Raises
    ------
    TypeError
        If ``model`` is not a `dynamics.Model`.

    Examples
    --------
    >>> from appdyn.dynamics import rigid_body
    >>> from appdyn.dynamics.clock import clock_index
    >>> from appdyn.dynamics.mechanisms import shaken_pendulum
    >>> clock_index(shaken_pendulum()), clock_index(rigid_body([1.0, 2.0, 3.0])) is None
    (2, True)
    """
    model = check_model(model)
    return model.states.index(CLOCK_STATE) if CLOCK_STATE in model.states else None


def check_clock_start(model, x0, t0) -> np.ndarray:
    """Check that the clock state of ``x0`` equals the start time ``t0``.

    Parameters
    ----------
    model : Model
        Any model; one without a clock state only has ``x0`` checked for shape.
    x0 : array_like, shape (nx,)
        Initial state, in the model's units.
    t0 : float [s]
        The first output time ``t[0]`` of the run.

    Returns
    -------
    numpy.ndarray, shape (nx,)
        ``x0`` as a float array.

    Raises
    ------
    TypeError
        If ``model`` is not a `dynamics.Model` or ``x0``/``t0`` do not hold real numbers.
    ValueError
        Naming ``x0`` when it has the wrong shape, is not finite, or its clock differs from
        ``t0`` by more than ``CLOCK_RTOL * max(1, |t0|)``; naming ``t0`` when it is not a
        finite scalar.

    Examples
    --------
    >>> from appdyn.dynamics.clock import check_clock_start
    >>> from appdyn.dynamics.mechanisms import shaken_pendulum
    >>> check_clock_start(shaken_pendulum(), [0.1, 0.0, 5.0], 5.0)
    array([0.1, 0. , 5. ])
    """
    model = check_model(model)
    x0 = validate.finite_array(x0, "x0", (model.nx,))
    t0 = validate.finite_scalar(t0, "t0")
    i = clock_index(model)
    if i is not None and abs(x0[i] - t0) > CLOCK_RTOL * max(1.0, abs(t0)):
        raise ValueError(
            f"`x0` sets the clock state {CLOCK_STATE!r} (index {i}) to {float(x0[i])!r} s, but the "
            f"time grid starts at t[0] = {t0!r} s; start the clock at t[0]")
    return x0
