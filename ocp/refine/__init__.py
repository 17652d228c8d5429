"""Drivers on top of `ocp.solve`, each returning a `RefinedSolution` (a `Solution` with an
``info`` mapping; never raising on a solver failure, returning ``success=False``):

* `refine` (`mesh_update`) — ``hp``-style mesh refinement driven by the per-interval error
  estimate of `interval_errors` (`errors`): re-integration defects, plus the state
  increment a smeared bang-bang switch misses.
* `solve_multistart` (`multistart`) — solve from several guesses, keep the best.
* `polish_switches` (`polish`) — exact switch times of a bang-bang solution: the arc
  durations solved for directly (`optimize_switch_times` in `switch_times`, structure from
  `bang_arcs` in `arcs`, RK8 steps from `rk8_step`, the cached NLP from `arc_nlp`), else
  moving knots (switch times on free mesh points).

`find_switches` / `control_switches` (`switches`) are the engine's one switch detector;
`RefinedSolution`, `RefinementRound` and `annotate` live in `result`.
"""
from __future__ import annotations

from ..transcription import RadauConstantControl
from .errors import IntervalErrors, interval_errors
from .mesh_update import STATUS_STALLED, refine
from .multistart import solve_multistart
from .polish import polish_switches
from .result import RefinedSolution, RefinementRound, annotate
from .switches import control_switches, find_switches
from .arcs import BangArcs, bang_arcs
from .switch_times import optimize_switch_times

__all__ = ["refine", "optimize_switch_times", "bang_arcs", "BangArcs", "STATUS_STALLED", "solve_multistart", "polish_switches", "RefinedSolution", "RefinementRound",
           "RadauConstantControl", "IntervalErrors", "interval_errors", "find_switches",
           "control_switches", "annotate"]
