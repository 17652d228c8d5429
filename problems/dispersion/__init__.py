"""Monte Carlo dispersions: many simulations of drawn initial conditions and parameters.

`dispersion` draws every input of ``params`` per sample (seeded, reproducible, independent
of the executor), builds each sample's model (a `dynamics.Model`, or a factory of the
draws, e.g. an inertia that `dynamics.rigid_body` bakes in), runs `dynamics.simulate`,
evaluates named outputs, and returns a `DispersionResult`: the inputs, outputs and
success of every sample, `Statistics` (mean, std, min, max, percentiles) of each output,
``__str__``, ``to_dict``/``to_json`` and ``plot()``. Any ``concurrent.futures.Executor``
runs the samples (the result is identical to a serial run); for a process pool the model
factory, an ``x0`` callable and the output callables must be module-level functions
(see `problems.dispersion.run`).

Modules: `distributions` (`Normal`, `Uniform`, `SmallRotation`, `RandomRotation`; seeded
draws), `run` (the driver `dispersion`), `sample` (the per-sample work `run_sample`), `result`
(`DispersionResult`, `Statistics`), `spin` (the worked example below).

Example: a spinning spacecraft
------------------------------
A near-axisymmetric body spinning about its axis of largest inertia, ``I_t ~ N(1000, 20)``,
``I_a ~ N(1500, 30)`` kg m^2, ``w1 ~ N(0.02, 0.004)`` rad/s, ``w3 = 1`` rad/s. For an
axisymmetric torque-free body the nutation angle between the symmetry axis and ``H`` is
constant, ``theta = atan(I_t |w_t| / (I_a w3))``: each sample matches it, and the spread
of theta over the samples is the spread of that closed form over the draws.

>>> import numpy as np
>>> from appdyn.problems.dispersion import Normal, dispersion, nutation_history, spinner
>>> res = dispersion(
...     spinner, [0, 0, 0, 1, 0.0, 0.0, 1.0], np.linspace(0.0, 30.0, 31),
...     samples=20, seed=0,
...     params={"transverse_inertia": Normal(1000.0, 20.0),   # taken by spinner(...)
...             "axial_inertia": Normal(1500.0, 30.0),
...             "w1": Normal(0.02, 0.004)},                   # sets x0's state "w1"
...     outputs={"nutation": nutation_history,                # f(res, **draws it names)
...              "w1_final": lambda res: res["w1"][-1]})
>>> res.success, res.outputs["nutation"].shape
(True, (20, 31))
>>> theta = np.arctan2(res.inputs["transverse_inertia"] * np.abs(res.inputs["w1"]),
...                    res.inputs["axial_inertia"] * 1.0)
>>> bool(np.max(np.abs(res.outputs["nutation"] - theta[:, None])) < 1e-8)
True
>>> s = res.statistics["nutation"]
>>> bool(np.allclose(s.mean[-1], theta.mean(), rtol=0, atol=1e-8))
True
>>> fig = res.plot()  # histogram of w1_final, envelope of the nutation history

`nutation_spread` packages this example (with the closed form of each sample as an
output, and invariant drifts).
"""
from __future__ import annotations

from .distributions import (Distribution, Normal, RandomRotation, SmallRotation, Uniform,
                            draw_samples)
from .result import ALL_FAILED, ALL_OK, SOME_FAILED, DispersionResult, Statistics, statistics
from .run import dispersion
from .sample import ATTITUDE, NOT_SIMULATED, SampleOutcome, SampleTask, run_sample
from .spin import (nutation_closed_form, nutation_history, nutation_max, nutation_spread,
                   spinner)

__all__ = [
    "dispersion", "DispersionResult", "Statistics", "statistics",
    "Distribution", "Normal", "Uniform", "SmallRotation", "RandomRotation", "draw_samples",
    "run_sample", "SampleTask", "SampleOutcome", "ATTITUDE", "NOT_SIMULATED",
    "ALL_OK", "SOME_FAILED", "ALL_FAILED",
    "spinner", "nutation_history", "nutation_max", "nutation_closed_form", "nutation_spread",
]
