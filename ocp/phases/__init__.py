"""Multi-phase optimal control: phases (each a single-phase `ocp.Problem` with its own model,
mesh, bounds and horizon) flown back to back, tied by state links and events over the phase
ends, with a cost over the ends (`problem`); their NLPs stacked with assembled derivatives
(`nlp`); solved and refined per phase (`solve`) into a `MultiPhaseSolution` (`solution`)."""
from __future__ import annotations

from .problem import Link, MultiPhaseProblem, Phase, PhaseEnd
from .solution import MultiPhaseSolution
from .solve import solve_phases

__all__ = ["Phase", "Link", "MultiPhaseProblem", "PhaseEnd", "MultiPhaseSolution", "solve_phases"]
