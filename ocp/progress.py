"""Progress reporting of the ocp engine: quiet unless asked.

Library code never prints on its own. Progress goes

* to an optional callable (``progress=`` of `ocp.solve`, `ocp.refine`, ...), which receives
  a `Progress` per IPOPT iteration (`ocp.refine` also hands it each `RefinementRound`), and
* to the `logging` module, logger ``"appdyn.ocp"`` (`LOGGER`): one INFO record per solve
  and refinement round, one DEBUG record per IPOPT iteration (only when DEBUG is enabled).

``verbose=True`` prints one line per IPOPT iteration to ``sys.stderr`` (never stdout: a
CLI's stdout stays its summary) for a caller that asks for it; a pipeline of several NLPs
labels each stage's lines (`StagePrinter`, `stage_sink`: ``[slew: start 2/3]``,
``[polish]``).
"""
from __future__ import annotations

import logging
import sys
import time
from typing import Callable

import casadi as ca
import numpy as np

from appdyn.dynamics.interrupts import interrupt_pending

__all__ = ["LOGGER", "Progress", "IterationCallback", "printer", "iteration_sink",
           "StagePrinter", "stage_sink"]

LOGGER = logging.getLogger("appdyn.ocp")


class Progress:
    """One IPOPT iteration as reported to a progress callable.

    Attributes
    ----------
    iteration : int
    objective : float
        Scaled NLP objective ``J / d_J``.
    infeasibility : float
        Largest violation of the scaled NLP constraints.
    """

    __slots__ = ("iteration", "objective", "infeasibility")

    def __init__(self, iteration: int, objective: float, infeasibility: float):
        self.iteration, self.objective, self.infeasibility = iteration, objective, infeasibility

    def __str__(self) -> str:
        return f"{self.iteration:5d}  {self.objective: .10e}  {self.infeasibility:.3e}"


class IterationCallback(ca.Callback):
    """A CasADi callback for ``nlpsol(..., {"iteration_callback": ...})``, attached to every
    IPOPT solver `ocp.solve` builds.

    It stops IPOPT (``User_Requested_Stop``) at the first iteration after a Ctrl-C deferred
    by `dynamics.interrupts.deferred_interrupts` (`ocp.solve` then raises
    ``KeyboardInterrupt``) or past ``deadline`` (a `time.perf_counter` value, ``None`` for
    none; an attribute the owner of a pooled solver sets before each solve: a wall-time
    budget that does not rebuild the solver), and, given a ``sink``, hands every iterate to ``sink(Progress)``;
    ``violation(g)`` measures the constraint violation of an iterate. Without a sink it
    receives no data (empty inputs): about 1 us per iteration.
    """

    def __init__(self, nx: int, ng: int, violation: Callable | None = None,
                 sink: Callable | None = None):
        ca.Callback.__init__(self)
        self._nx, self._ng, self._violation, self._sink = nx, ng, violation, sink
        self._count = 0
        self.deadline = None
        self.construct("ocp_progress" if sink is not None else "ocp_interrupt", {})

    def get_n_in(self):
        return ca.nlpsol_n_out()

    def get_n_out(self):
        return 1

    def get_name_in(self, i):
        return ca.nlpsol_out(i)

    def get_name_out(self, i):
        return "ret"

    def get_sparsity_in(self, i):
        name = ca.nlpsol_out(i)
        if self._sink is None:
            return ca.Sparsity(0, 0)
        if name == "f":
            return ca.Sparsity.dense(1)
        if name in ("x", "lam_x"):
            return ca.Sparsity.dense(self._nx)
        if name in ("g", "lam_g"):
            return ca.Sparsity.dense(self._ng)
        return ca.Sparsity(0, 0)

    def eval(self, arg):
        if self._sink is not None:
            g = np.asarray(arg[2]).reshape(-1)
            self._sink(Progress(self._count, float(arg[1]), self._violation(g)))
            self._count += 1
        late = self.deadline is not None and time.perf_counter() > self.deadline
        return [1 if late or interrupt_pending() else 0]


_HEADER = " iter   objective (scaled)  inf_pr"


class StagePrinter:
    """A progress sink printing a header and one `Progress` line per iteration, prefixed by
    ``[label] `` when a label is given, to ``stream`` (default ``sys.stderr``, looked up at
    each call). Picklable without a stream (a start of `ocp.solve_multistart` on a process
    pool).

    Parameters
    ----------
    label : str, optional
        The stage, e.g. ``'slew: start 2/3'`` or ``'polish'``.
    stream : file-like, optional
    """

    def __init__(self, label: str | None = None, stream=None):
        self.label, self.stream, self._header = label, stream, False

    def __call__(self, progress: Progress) -> None:
        stream = sys.stderr if self.stream is None else self.stream
        prefix = "" if self.label is None else f"[{self.label}] "
        if not self._header:
            print(prefix + _HEADER, file=stream, flush=True)
            self._header = True
        print(prefix + str(progress), file=stream, flush=True)


def printer(stream):
    """A progress sink printing a header and one `Progress` line per iteration to ``stream``
    (`StagePrinter` without a label)."""
    return StagePrinter(None, stream)


def stage_sink(verbose, label: str):
    """``verbose`` for one stage of a pipeline: ``True`` becomes a `StagePrinter` of
    ``label`` (to stderr); ``False``, a callable or an existing `StagePrinter` are returned
    unchanged.

    Examples
    --------
    >>> from appdyn.ocp.progress import stage_sink
    >>> stage_sink(True, "polish").label, stage_sink(False, "polish")
    ('polish', False)
    """
    return StagePrinter(label) if verbose is True else verbose



def iteration_sink(verbose, progress) -> Callable | None:
    """The per-iteration sink for `ocp.solve`'s ``verbose`` and ``progress`` arguments (and
    DEBUG logging), or ``None`` when nobody listens (no callback is then attached).

    Raises
    ------
    ValueError
        If ``verbose`` is not True, False or a callable.
    TypeError
        If ``progress`` is neither None nor callable.
    """
    if not (verbose is True or verbose is False or callable(verbose)):
        raise ValueError(f"`verbose` must be True, False or a callable, got {verbose!r}")
    if progress is not None and not callable(progress):
        raise TypeError(f"`progress` must be a callable or None, got {type(progress).__name__}")
    sinks = []
    if verbose is True:
        sinks.append(StagePrinter())
    elif callable(verbose):
        sinks.append(verbose)
    if progress is not None:
        sinks.append(progress)
    if LOGGER.isEnabledFor(logging.DEBUG):
        sinks.append(lambda it: LOGGER.debug("ipopt %s", it))
    if not sinks:
        return None
    if len(sinks) == 1:
        return sinks[0]

    def sink(it: Progress):
        for f in sinks:
            f(it)

    return sink
