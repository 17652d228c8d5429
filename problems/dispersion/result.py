"""`DispersionResult` (the outcome of `dispersion`) and `Statistics` (of one output)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from appdyn.dynamics.figures import finish_figure, panel_grid
from appdyn.dynamics.serialize import jsonable, text_table, to_json
from appdyn.dynamics.validate.base import real_array

from .distributions import describe
from appdyn.dynamics.results import Result

__all__ = ["Statistics", "DispersionResult", "statistics", "assemble", "ALL_OK", "SOME_FAILED",
           "ALL_FAILED"]

# status codes of DispersionResult (documented in its docstring)
ALL_OK, SOME_FAILED, ALL_FAILED = 0, 1, 2


@dataclass(frozen=True)
class Statistics:
    """Statistics of one output over the successful samples, elementwise.

    Attributes
    ----------
    count : int
        Successful samples used.
    mean, std, min, max : ndarray, shape of the output (a float for a scalar output)
        ``std`` is the sample standard deviation (``ddof=1``; NaN for fewer than 2 samples).
    percentiles : dict of float to ndarray
        ``numpy.percentile`` (linear interpolation) at each requested percentile [%].
    """

    count: int
    mean: object
    std: object
    min: object
    max: object
    percentiles: dict


def _num(a):
    a = np.asarray(a, dtype=float)
    return float(a) if a.ndim == 0 else a


def statistics(values, *, percentiles=(1.0, 50.0, 99.0)) -> Statistics:
    """`Statistics` of ``values`` along axis 0 (the samples); NaN everywhere when empty.

    Parameters
    ----------
    values : array_like, shape (m, ...)
        Real numbers, samples first (NaN entries are not refused: they propagate).
    percentiles : sequence of float in [0, 100]

    Raises
    ------
    TypeError
        If ``values`` is not real numbers (a string, ``None``, ...).
    ValueError
        If ``values`` is a scalar (it must have the sample axis 0).

    Examples
    --------
    >>> from appdyn.problems.dispersion import statistics
    >>> s = statistics([1.0, 2.0, 3.0, 4.0], percentiles=(50,))
    >>> s.count, s.mean, round(s.std, 6), s.min, s.max, s.percentiles
    (4, 2.5, 1.290994, 1.0, 4.0, {50.0: 2.5})
    """
    v = real_array(values, "values")
    if v.ndim == 0:
        raise ValueError(f"`values` must have shape (m, ...) (samples first), got a scalar "
                         f"{values!r}")
    m = v.shape[0]
    if m == 0:
        nan = _num(np.full(v.shape[1:], np.nan))
        return Statistics(0, nan, nan, nan, nan, {float(p): nan for p in percentiles})
    std = np.std(v, axis=0, ddof=1) if m > 1 else np.full(v.shape[1:], np.nan)
    return Statistics(m, _num(np.mean(v, axis=0)), _num(std), _num(np.min(v, axis=0)),
                      _num(np.max(v, axis=0)),
                      {float(p): _num(np.percentile(v, p, axis=0)) for p in percentiles})


@dataclass(frozen=True, eq=False, repr=False)
class DispersionResult(Result):
    """Outcome of `dispersion`: inputs, outputs and success of every sample, and statistics.

    Arrays are **samples first**: row ``k`` belongs to sample ``index[k]``.

    Attributes
    ----------
    index : ndarray of int, shape (m,)
        Sample numbers, increasing (``arange(samples)`` unless interrupted).
    inputs : dict of str to ndarray, shape (m, ...)
        The drawn value of each entry of ``params`` per sample (the samples' inputs).
    outputs : dict of str to ndarray, shape (m, ...)
        Each output per sample; NaN rows for failed samples (an output is absent when no
        sample succeeded: its shape is unknown). Invariant drifts appear as
        ``"<invariant>_drift"`` (``SimulationResult.invariant_drift``).
    sample_success : ndarray of bool, shape (m,)
        Whether the sample built its model, simulated with ``success`` and evaluated every
        output.
    sample_status : ndarray of int, shape (m,)
        ``SimulationResult.status`` of each run; ``-2`` when the sample failed before or
        after the simulation (the factory, ``x0`` or an output raised).
    sample_messages : tuple of str, length m
        Why each sample failed (``""`` for a success).
    wall_times : ndarray, shape (m,) [s]
        Time of each sample's work (model, simulation, outputs).
    statistics : dict of str to Statistics
        Per output, over the successful samples.
    t : ndarray, shape (n,) [s]
        The time grid of every simulation.
    seed : int
        The seed of the draws (the entropy drawn when ``seed=None`` was given).
    samples : int
        Samples asked for.
    params : dict
        The specs as plain data (`describe`).
    units : dict of str to str
        Units of outputs and inputs, where given.
    executor : str
        ``"serial"`` or the executor's class name.
    wall_time : float [s]
        Time of the whole `dispersion` call.
    complete : bool
        False for the partial result of an interrupted run (``KeyboardInterrupt.partial``).
    percentiles : tuple of float
        The percentiles [%] in ``statistics``.
    n_failed : int
        Finished samples that failed (property; `failures` gives their messages).
    success : bool
        Every sample asked for finished and succeeded (property).
    status : int
        ``0`` (`ALL_OK`) every finished sample succeeded, ``1`` (`SOME_FAILED`), ``2``
        (`ALL_FAILED`) (property).
    message : str
        ``status`` in words, with the first failures (property).
    """

    index: np.ndarray
    inputs: dict
    outputs: dict
    sample_success: np.ndarray
    sample_status: np.ndarray
    sample_messages: tuple
    wall_times: np.ndarray
    t: np.ndarray
    seed: int
    samples: int
    params: dict = field(default_factory=dict)
    units: dict = field(default_factory=dict)
    executor: str = "serial"
    wall_time: float = 0.0
    complete: bool = True
    percentiles: tuple = (1.0, 50.0, 99.0)
    statistics: dict = field(default_factory=dict)

    def __post_init__(self):
        if not self.statistics:
            ok = self.sample_success
            stats = {name: statistics(v[ok], percentiles=self.percentiles) for name, v in self.outputs.items()}
            object.__setattr__(self, "statistics", stats)

    # ------------------------------------------------------------------ verdict
    @property
    def n_failed(self) -> int:
        """Finished samples that failed."""
        return int(np.count_nonzero(~self.sample_success))

    @property
    def status(self) -> int:
        """`ALL_OK`, `SOME_FAILED` or `ALL_FAILED` over the finished samples."""
        if self.n_failed == 0:
            return ALL_OK
        return ALL_FAILED if self.n_failed == len(self.index) else SOME_FAILED

    @property
    def success(self) -> bool:
        """Every sample asked for finished and succeeded."""
        return self.complete and self.status == ALL_OK

    @property
    def message(self) -> str:
        """``status`` in words, with up to three failures."""
        m = len(self.index)
        if self.status == ALL_OK:
            text = f"all {m} samples succeeded"
        else:
            bad = [f"sample {i}: {msg}" for i, ok, msg in
                   zip(self.index, self.sample_success, self.sample_messages) if not ok]
            text = f"{self.n_failed} of {m} samples failed ({'; '.join(bad[:3])}" + \
                   (", ..." if len(bad) > 3 else "") + ")"
        if not self.complete:
            text += f"; interrupted after {m} of {self.samples} samples"
        return text

    def failures(self) -> dict:
        """``{sample: message}`` of the failed samples."""
        return {int(i): msg for i, ok, msg in
                zip(self.index, self.sample_success, self.sample_messages) if not ok}

    # ------------------------------------------------------------------- output
    def to_dict(self) -> dict:
        """Everything as plain Python (JSON-ready through `to_json`)."""
        return jsonable({
            "success": self.success, "status": self.status, "message": self.message,
            "samples": self.samples, "seed": self.seed, "complete": self.complete,
            "executor": self.executor, "wall_time": self.wall_time, "params": self.params,
            "units": self.units, "t": self.t, "index": self.index, "inputs": self.inputs,
            "outputs": self.outputs, "sample_success": self.sample_success,
            "sample_status": self.sample_status, "sample_messages": list(self.sample_messages),
            "wall_times": self.wall_times, "percentiles": list(self.percentiles),
            "statistics": {k: {"count": s.count, "mean": s.mean, "std": s.std, "min": s.min,
                               "max": s.max,
                               "percentiles": {f"{p:g}": v for p, v in s.percentiles.items()}}
                           for k, s in self.statistics.items()},
        })

    def _unit(self, name: str) -> str:
        unit = self.units.get(name)
        return f" [{unit}]" if unit else ""

    def __str__(self) -> str:
        m = len(self.index)
        rows = [("success", f"{self.success} (status {self.status})"),
                ("samples", f"{m} of {self.samples} run, {self.n_failed} failed, seed {self.seed}"),
                ("executor", self.executor),
                ("wall time", f"{self.wall_time:.3f} s ({1e3 * np.mean(self.wall_times):.2f} ms "
                              f"per sample)" if m else f"{self.wall_time:.3f} s"),
                ("message", self.message)]
        text = text_table("Dispersion", rows)
        pct = [f"p{p:g}" for p in self.percentiles]
        head = ["output", "mean", "std", "min", *pct, "max"]
        lines = []
        for name, s in self.statistics.items():
            if np.ndim(s.mean) == 0:
                vals = [s.mean, s.std, s.min, *s.percentiles.values(), s.max]
                lines.append([name + self._unit(name)] + [f"{v:.6g}" for v in vals])
            else:
                lines.append([name + self._unit(name), f"shape {np.shape(s.mean)}"]
                             + [""] * (len(head) - 2))
        if lines:
            width = [max(len(r[j]) for r in [head] + lines) for j in range(len(head))]
            fmt = [f"  {r[0]:<{width[0]}}" + "".join(f"  {c:>{w}}" for c, w in
                                                     zip(r[1:], width[1:]))
                   for r in [head] + lines]
            text += (f"\nStatistics over {int(np.count_nonzero(self.sample_success))} "
                     f"successful samples\n" + "\n".join(line.rstrip() for line in fmt))
        return text

    def plot(self, ax=None, *, outputs=None):
        """Histograms of scalar outputs and envelopes of time histories, one panel each.

        A time history is an output of shape ``(n,)`` on the grid ``t``: drawn as its
        median, the band between the lowest and highest requested percentiles, and the
        min-max band, over the successful samples.

        Parameters
        ----------
        ax : matplotlib.axes.Axes or matplotlib.figure.Figure, optional
            Draw the panels in this axes' slot (divided into the panels) or on this figure
            (cleared); by default on a new `matplotlib.figure.Figure` (no pyplot).
        outputs : sequence of str, optional
            The outputs to draw (default: every scalar output and time history).

        Returns
        -------
        matplotlib.figure.Figure

        Raises
        ------
        ValueError
            If ``outputs`` names an unknown output or one that is neither a scalar nor a
            time history.
        """
        drawable = [k for k, v in self.outputs.items()
                    if v.ndim == 1 or v.shape[1:] == self.t.shape]
        names = drawable if outputs is None else list(outputs)
        bad = [k for k in names if k not in drawable]
        if bad:
            raise ValueError(f"`outputs` must name scalar outputs or time histories {drawable}, "
                             f"got {bad}")
        ncol = 1 if len(names) <= 1 else 2
        nrow = max(1, -(-len(names) // ncol))
        fig, grid = panel_grid(ax, nrow, ncol, (5.0 * ncol, 3.2 * nrow))
        ok = self.sample_success
        for k, name in enumerate(names):
            ax = fig.add_subplot(grid[k // ncol, k % ncol])
            v = self.outputs[name][ok]
            if v.ndim == 1:
                finite = v[np.isfinite(v)]
                ax.hist(finite, bins=max(5, min(50, int(np.sqrt(max(finite.size, 1))) * 2)),
                        color="tab:blue", alpha=0.8)
                s = self.statistics[name]
                ax.axvline(s.mean, color="k", lw=1, label="mean")
                ax.set(xlabel=name + self._unit(name), ylabel="samples")
                ax.legend(fontsize=8)
            else:
                s = self.statistics[name]
                ax.fill_between(self.t, s.min, s.max, color="tab:blue", alpha=0.15,
                                label="min-max")
                if s.percentiles:
                    lo, hi = min(s.percentiles), max(s.percentiles)
                    ax.fill_between(self.t, s.percentiles[lo], s.percentiles[hi],
                                    color="tab:blue", alpha=0.35, label=f"p{lo:g}-p{hi:g}")
                ax.plot(self.t, np.median(v, axis=0) if len(v) else self.t * np.nan,
                        color="tab:blue", lw=1.2, label="median")
                ax.set(xlabel="t [s]", ylabel=name + self._unit(name))
                ax.legend(fontsize=8)
            ax.grid(True, alpha=0.3)
        fig.suptitle(f"Dispersion: {int(np.count_nonzero(ok))} successful of "
                     f"{len(self.index)} samples (seed {self.seed})", fontsize=10)
        return finish_figure(fig)


def assemble(done, draws, t, seed, samples, params, units, executor, wall_time, complete,
             percentiles) -> DispersionResult:
    """The `DispersionResult` of the finished samples ``done`` (``{index: SampleOutcome}``),
    their ``draws`` and the call's arguments; a successful sample whose output has another
    shape than the others' becomes a failure."""
    index = np.array(sorted(done), dtype=int)
    outcomes = [done[i] for i in index]
    success = [o.success for o in outcomes]
    messages = [o.message for o in outcomes]
    outputs = {}
    names = list(dict.fromkeys(k for o in outcomes if o.success for k in o.outputs))
    for name in names:
        shape = next(o.outputs[name].shape for o in outcomes if o.success and name in o.outputs)
        rows = np.full((len(index),) + shape, np.nan)
        for k, o in enumerate(outcomes):
            if not success[k]:
                continue
            value = o.outputs.get(name)
            if value is None or value.shape != shape:
                success[k] = False
                messages[k] = (f"output {name!r} has shape "
                               f"{None if value is None else value.shape}, others {shape}")
            else:
                rows[k] = value
        outputs[name] = rows
    for name in outputs:  # rows of samples failed above
        outputs[name][~np.array(success, dtype=bool)] = np.nan
    inputs = {}
    for name in params:
        try:
            inputs[name] = np.array([draws[i][name] for i in index], dtype=float)
        except (TypeError, ValueError):
            inputs[name] = np.array([draws[i][name] for i in index], dtype=object)
    name = "serial" if executor is None else type(executor).__name__
    return DispersionResult(
        index=index, inputs=inputs, outputs=outputs,
        sample_success=np.array(success, dtype=bool),
        sample_status=np.array([o.status for o in outcomes], dtype=int),
        sample_messages=tuple(messages),
        wall_times=np.array([o.wall_time for o in outcomes], dtype=float), t=t, seed=seed,
        samples=samples, params={k: describe(v) for k, v in params.items()}, units=units,
        executor=name, wall_time=wall_time, complete=complete, percentiles=percentiles)
