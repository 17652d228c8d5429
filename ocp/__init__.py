"""appdyn ocp: direct-collocation optimal control on CasADi and IPOPT.

State a `Problem` (dynamics, bounds, boundary conditions, constraints, cost), pick a
transcription (`Trapezoid`, `HermiteSimpson`, `Radau`), and `solve` it::

    from appdyn.ocp import Problem, solve
    sol = solve(Problem(model, T=1.0, x_initial=..., x_final=..., lagrange=...),
                transcription="radau", N=20)
    sol.success, sol.cost, sol.sample(t)

The library prints nothing unless asked (``verbose=True``): progress goes to an optional
``progress`` callable and to the logger ``"appdyn.ocp"`` (`ocp.progress`). Mesh refinement,
multistart and moving-knot polishing are in `ocp.refine`; attitude targets, quaternion norm
handling and SLERP guesses in `ocp.attitude`. What the engine builds repeatedly (interval
kernels, integrators, the NLP and its solver) is kept in `dynamics.cache` (`ocp.cached`);
`ocp.examples` holds the small problems of the docstring Examples. Every result's
``status`` is an int (0 success; the table of codes, IPOPT's and appdyn's, is `ocp.status`)
and IPOPT's return status text is its ``solver_status``.

Built once, solved many times: every number of a problem is an NLP bound or parameter, so
the NLP of a *structure* (`ocp.assembly`: derivatives of one interval placed by index maps)
and its IPOPT solver serve every problem of that structure (`ocp.solve`'s module
docstring). Several scenarios sharing the parameters go into one NLP with
`scenario_problem` (`ocp.scenarios`: gain design, robust plans).
"""
from __future__ import annotations

from .guess import guess_from_simulation
from .mesh import Mesh
from .problem import Constraint, Problem
from .phases import Link, MultiPhaseProblem, MultiPhaseSolution, Phase, PhaseEnd, solve_phases
from .ipopt_options import check_ipopt_options, ipopt_option_table
from .refine import (STATUS_STALLED, BangArcs, IntervalErrors, RefinedSolution, RefinementRound,
                     annotate, bang_arcs, control_switches, find_switches, interval_errors,
                     optimize_switch_times, polish_switches, refine, solve_multistart)
from .scaling import Scaling
from .scenarios import scenario_problem, stack, unstack
from .progress import LOGGER
from .propagation import SCALE_FLOOR, state_scale
from .solution import Propagation, Solution
from .rest import STATUS_REST, rest_solution
from .status import CODES as STATUS_CODES, status_code, status_name
from .checks import (DEFAULT_VERIFY_TOL, STATUS_BOUND_VIOLATION, STATUS_RESIMULATION,
                     BoundViolation)
from .solve import DEFAULT_CONSTRAINT_TOL, STATUS_CONSTRAINT_TOL, STATUS_EXCEPTION, Progress, solve
from .transcription import (CONTROLS, TRANSCRIPTIONS, HermiteSimpson, Radau, RadauConstantControl,
                            RadauLinearControl, Transcription, Trapezoid, get_transcription)

__all__ = [
    "Problem",
    "Constraint",
    "Phase",
    "Link",
    "MultiPhaseProblem",
    "MultiPhaseSolution",
    "PhaseEnd",
    "solve_phases",
    "Solution",
    "Propagation",
    "Progress",
    "LOGGER",
    "solve",
    "rest_solution",
    "DEFAULT_CONSTRAINT_TOL",
    "STATUS_CONSTRAINT_TOL",
    "STATUS_EXCEPTION",
    "STATUS_REST",
    "STATUS_CODES",
    "status_code",
    "status_name",
    "check_ipopt_options",
    "ipopt_option_table",
    "annotate",
    "Mesh",
    "Scaling",
    "Transcription",
    "Trapezoid",
    "HermiteSimpson",
    "Radau",
    "TRANSCRIPTIONS",
    "get_transcription",
    "refine",
    "solve_multistart",
    "polish_switches",
    "RefinedSolution",
    "RefinementRound",
    "RadauConstantControl",
    "RadauLinearControl",
    "CONTROLS",
    "BoundViolation",
    "STATUS_BOUND_VIOLATION",
    "STATUS_RESIMULATION",
    "DEFAULT_VERIFY_TOL",
    "IntervalErrors",
    "interval_errors",
    "find_switches",
    "control_switches",
    "guess_from_simulation",
    "STATUS_STALLED",
    "scenario_problem",
    "stack",
    "unstack",
    "optimize_switch_times",
    "bang_arcs",
    "BangArcs",
    "SCALE_FLOOR",
    "state_scale",
]
