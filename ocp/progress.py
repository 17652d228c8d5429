"""Progress reporting of the ocp engine: quiet unless asked.

Library code never prints on its own. Progress goes

* to an optional callable (``progress=`` of `ocp.solve`, `ocp.refine`, ...), which receives
  a `Progress` per IPOPT iteration (`ocp.refine` also hands it each `RefinementRound`), and
* to the `logging` module, logger ``"appdyn.ocp"`` (`LOGGER`): one INFO record per solve
  and refinement round, one DEBUG record per IPOPT iteration (only when DEBUG is enabled).

``verbose=True`` still prints IPOPT iteration lines to ``sys.stdout`` for a caller (the CLI)
that asks for it.
"""
from __future__ import annotations

import logging
import sys
from typing import Callable

import casadi as ca
import numpy as np

from appdyn.dynamics.interrupts import interrupt_pending

__all__ = ["LOGGER", "Progress", "IterationCallback", "printer", "iteration_sink"]

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
    ``KeyboardInterrupt``), and, given a ``sink``, hands every iterate to ``sink(Progress)``;
    ``violation(g)`` measures the constraint violation of an iterate. Without a sink it
    receives no data (empty inputs): about 1 us per iteration.
    """

    def __init__(self, nx: int, ng: int, violation: Callable | None = None,
                 sink: Callable | None = None):
        ca.Callback.__init__(self)
        self._nx, self._ng, self._violation, self._sink = nx, ng, violation, sink
        self._count = 0
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
        return [1 if interrupt_pending() else 0]


def printer(stream):
    """A progress sink printing a header and one `Progress` line per iteration to ``stream``."""
    state = {"header": False}

    def sink(progress: Progress):
        if not state["header"]:
            print(" iter   objective (scaled)  inf_pr", file=stream, flush=True)
            state["header"] = True
        print(str(progress), file=stream, flush=True)

    return sink



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
        sinks.append(printer(sys.stdout))
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
