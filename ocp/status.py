"""The ``status`` codes of the optimal-control results: one table, ints everywhere.

Every result of `appdyn.ocp` and of the jobs built on it (`Solution`, `MultiPhaseSolution`,
`RefinedSolution`, the slews, `GainDesign`, `PlanarAscent`, the Delta III `AscentResult`)
carries

- ``status``: an **int**, 0 for a success (what `appdyn.dynamics.results.Result` asks);
- ``solver_status``: the text IPOPT returned (its ``ApplicationReturnStatus`` name, e.g.
  ``'Solve_Succeeded'``), ``'Exception'`` or ``'Unknown'`` when IPOPT reported none, or
  ``'Rest_Solution'`` when no NLP was solved (`ocp.rest_solution`); it keeps what the solver
  said when appdyn's own verification turned a converged solve into a failure;
- ``message``: why, in words.

(`PitchTracking`, which solves no NLP, takes its int codes from the same table.) The codes
(`CODES`, `status_code`, `status_name`):

- IPOPT's return statuses keep IPOPT's own numbers (``IpReturnCodes_inc.h``): 0
  ``Solve_Succeeded``; 1 to 6 a stop short of a verified optimum (1
  ``Solved_To_Acceptable_Level``, 2 ``Infeasible_Problem_Detected``, 5
  ``User_Requested_Stop``, ...); -1 to -199 IPOPT's errors (-1
  ``Maximum_Iterations_Exceeded``, -5 ``Maximum_WallTime_Exceeded``, -13
  ``Invalid_Number_Detected``, ...).
- 101 to 119: appdyn's verification failed (``success`` is False) although the solver ended:
  a tolerance not met, a bound left between the nodes, a re-simulation mismatch, a stalled
  refinement, an unstable designed loop, ...
- 120 to 129: warnings of a success (``success`` stays True): `GainDesign`'s
  ``'Short_Horizon'`` and ``'Initial_States_Not_Spanning'``.
- -200 ``'Exception'`` (an evaluation error inside CasADi, no IPOPT status), -201
  ``'Unknown'`` (a status text not in the table).

Examples
--------
>>> from appdyn.ocp.status import status_code, status_name, STATUS_BOUND_VIOLATION
>>> status_code("Solve_Succeeded"), status_code("Maximum_Iterations_Exceeded")
(0, -1)
>>> STATUS_BOUND_VIOLATION, status_name(STATUS_BOUND_VIOLATION)
(102, 'Bound_Violation')
"""
from __future__ import annotations

import numpy as np

__all__ = ["CODES", "IPOPT_CODES", "APPDYN_CODES", "status_code", "status_name",
           "STATUS_SUCCESS", "STATUS_ACCEPTABLE", "STATUS_INFEASIBLE", "STATUS_USER_STOP",
           "STATUS_MAX_ITER", "STATUS_WALL_TIME", "STATUS_CONSTRAINT_TOL",
           "STATUS_BOUND_VIOLATION", "STATUS_RESIMULATION", "STATUS_STALLED", "STATUS_WORSE",
           "STATUS_POINTING", "STATUS_REFINE", "STATUS_UNSTABLE", "STATUS_LIMITS",
           "STATUS_SIMULATION", "STATUS_TERMINAL", "STATUS_PATH_LIMITS", "STATUS_PROPAGATION",
           "STATUS_CHECK", "STATUS_TRACKING", "STATUS_DEFLECTION", "STATUS_SHORT_HORIZON",
           "STATUS_NOT_SPANNING", "STATUS_EXCEPTION",
           "STATUS_UNKNOWN", "SOLVER_REST", "describe"]

#: IPOPT's ``ApplicationReturnStatus`` names and numbers (IPOPT's ``IpReturnCodes_inc.h``).
IPOPT_CODES = {
    "Solve_Succeeded": 0,
    "Solved_To_Acceptable_Level": 1,
    "Infeasible_Problem_Detected": 2,
    "Search_Direction_Becomes_Too_Small": 3,
    "Diverging_Iterates": 4,
    "User_Requested_Stop": 5,
    "Feasible_Point_Found": 6,
    "Maximum_Iterations_Exceeded": -1,
    "Restoration_Failed": -2,
    "Error_In_Step_Computation": -3,
    "Maximum_CpuTime_Exceeded": -4,
    "Maximum_WallTime_Exceeded": -5,
    "Not_Enough_Degrees_Of_Freedom": -10,
    "Invalid_Problem_Definition": -11,
    "Invalid_Option": -12,
    "Invalid_Number_Detected": -13,
    "Unrecoverable_Exception": -100,
    "NonIpopt_Exception_Thrown": -101,
    "Insufficient_Memory": -102,
    "Internal_Error": -199,
}

#: appdyn's own statuses: verification failures (101-119), warnings of a success (120-129),
#: failures without a solver status (-200, -201).
APPDYN_CODES = {
    "Constraint_Tol_Not_Met": 101,  # the solver converged, the violation > constraint_tol
    "Bound_Violation": 102,  # the dense output leaves a bound between the nodes
    "Resimulation_Mismatch": 103,  # the re-simulated control disagrees with the collocation
    "Refinement_Stalled": 104,  # mesh refinement: the error estimate stopped falling
    "Worse_Than_Start": 105,  # a polish ended with a cost worse than its start's
    "Pointing_Tol_Not_Met": 106,  # slew: final attitude or rate error above its tolerance
    "Refinement_Tol_Not_Met": 107,  # slew: refinement did not reach its tolerance
    "Closed_Loop_Unstable": 108,  # gains: the designed loop is not stable
    "Limits_Not_Met": 109,  # gains: no gains of the form meet the limits
    "Simulation_Failed": 110,  # gains: the verifying simulation failed
    "Terminal_Conditions_Not_Met": 111,  # ascent: the re-propagated end misses the target
    "Path_Limits_Exceeded": 112,  # ascent: the re-propagation exceeds q_max or qalpha_max
    "Propagation_Failed": 113,  # ascent: the re-propagation failed
    "Check_Failed": 114,  # a job's own check of the solution failed
    "Tracking_Error_Exceeded": 115,  # ascent: the flown pitch loop left its error bound
    "Deflection_Limit_Exceeded": 116,  # ascent: the flown loop asked for more deflection
    "Short_Horizon": 120,  # gains warning (success stays True): horizon short
    "Initial_States_Not_Spanning": 121,  # gains warning: initial states do not span R^n
    "Exception": -200,  # an evaluation error inside CasADi: no IPOPT status
    "Unknown": -201,  # a status text not in this table
}

#: Every status name and its int code.
CODES = {**IPOPT_CODES, **APPDYN_CODES}
_NAMES = {code: name for name, code in CODES.items()}

#: 0: IPOPT's ``Solve_Succeeded`` and every check of appdyn passed (a success).
STATUS_SUCCESS = CODES["Solve_Succeeded"]
#: 1: IPOPT stopped at its acceptable level (not a verified solution).
STATUS_ACCEPTABLE = CODES["Solved_To_Acceptable_Level"]
#: 2: IPOPT converged to a point of local infeasibility.
STATUS_INFEASIBLE = CODES["Infeasible_Problem_Detected"]
#: 5: stopped by a callback (a Ctrl-C, a progress callable).
STATUS_USER_STOP = CODES["User_Requested_Stop"]
#: -1: IPOPT reached ``max_iter``.
STATUS_MAX_ITER = CODES["Maximum_Iterations_Exceeded"]
#: -5: IPOPT reached ``max_wall_time`` (or a polish its ``budget``).
STATUS_WALL_TIME = CODES["Maximum_WallTime_Exceeded"]
#: 101: the solver converged but the constraint violation exceeds ``constraint_tol``.
STATUS_CONSTRAINT_TOL = CODES["Constraint_Tol_Not_Met"]
#: 102: the dense output leaves a bound by more than ``constraint_tol``.
STATUS_BOUND_VIOLATION = CODES["Bound_Violation"]
#: 103: the re-simulation of the control disagrees with the collocation.
STATUS_RESIMULATION = CODES["Resimulation_Mismatch"]
#: 104: mesh refinement stopped because its error estimate stalled.
STATUS_STALLED = CODES["Refinement_Stalled"]
#: 105: a polish ended with a cost worse than its start's.
STATUS_WORSE = CODES["Worse_Than_Start"]
#: 106: a slew's re-simulated final attitude or rate error exceeds its tolerance.
STATUS_POINTING = CODES["Pointing_Tol_Not_Met"]
#: 107: a slew's mesh refinement did not reach its tolerance.
STATUS_REFINE = CODES["Refinement_Tol_Not_Met"]
#: 108: a gain design converged but the designed loop is not stable.
STATUS_UNSTABLE = CODES["Closed_Loop_Unstable"]
#: 109: no gains of the designed form meet the limits.
STATUS_LIMITS = CODES["Limits_Not_Met"]
#: 110: the verifying simulation failed.
STATUS_SIMULATION = CODES["Simulation_Failed"]
#: 111: an ascent's re-propagated end misses the target.
STATUS_TERMINAL = CODES["Terminal_Conditions_Not_Met"]
#: 112: an ascent's re-propagation exceeds ``q_max`` or ``qalpha_max``.
STATUS_PATH_LIMITS = CODES["Path_Limits_Exceeded"]
#: 113: an ascent's re-propagation failed.
STATUS_PROPAGATION = CODES["Propagation_Failed"]
#: 114: a job's own check of the solution failed.
STATUS_CHECK = CODES["Check_Failed"]
#: 115: a flown pitch program left its tracking-error bound.
STATUS_TRACKING = CODES["Tracking_Error_Exceeded"]
#: 116: a flown pitch program asked for more deflection than allowed.
STATUS_DEFLECTION = CODES["Deflection_Limit_Exceeded"]
#: 120 (a success's warning): the design horizon is short.
STATUS_SHORT_HORIZON = CODES["Short_Horizon"]
#: 121 (a success's warning): the initial states do not span ``R^n``.
STATUS_NOT_SPANNING = CODES["Initial_States_Not_Spanning"]
#: -200: an evaluation error inside CasADi (no IPOPT status).
STATUS_EXCEPTION = CODES["Exception"]
#: -201: a status text not in `CODES`.
STATUS_UNKNOWN = CODES["Unknown"]
#: ``solver_status`` of `ocp.rest_solution` (no NLP solved; its ``status`` is 0 on success).
SOLVER_REST = "Rest_Solution"


def status_code(name: str) -> int:
    """The int ``status`` of a status name (IPOPT's return status or appdyn's own).

    Parameters
    ----------
    name : str
        E.g. ``'Solve_Succeeded'``, ``'Bound_Violation'``.

    Returns
    -------
    int
        The code in `CODES`; `STATUS_UNKNOWN` (-201) for a name not in the table (a
        solver status text is reported, never raised on).

    Raises
    ------
    TypeError
        If ``name`` is not a string.

    Examples
    --------
    >>> from appdyn.ocp.status import status_code
    >>> status_code("Infeasible_Problem_Detected"), status_code("Something_New")
    (2, -201)
    """
    if not isinstance(name, str):
        raise TypeError(f"`name` must be a status name (a str), got {type(name).__name__}")
    return CODES.get(name, STATUS_UNKNOWN)


def status_name(code: int) -> str:
    """The name of an int ``status`` (the inverse of `status_code`).

    Parameters
    ----------
    code : int

    Returns
    -------
    str
        The name in `CODES`, or ``'status <code>'`` for a code not in the table.

    Raises
    ------
    TypeError
        If ``code`` is not an integer (a bool neither).

    Examples
    --------
    >>> from appdyn.ocp.status import status_name
    >>> status_name(0), status_name(-5), status_name(7)
    ('Solve_Succeeded', 'Maximum_WallTime_Exceeded', 'status 7')
    """
    if isinstance(code, bool) or not isinstance(code, (int, np.integer)):
        raise TypeError(f"`code` must be an int status, got {type(code).__name__}")
    return _NAMES.get(int(code), f"status {int(code)}")


def describe(status: int, *, solver_status: str = "") -> str:
    """``status`` for a report: the code and its name, then the solver's text when it says
    something else.

    Parameters
    ----------
    status : int
    solver_status : str, optional
        The result's ``solver_status``.

    Returns
    -------
    str

    Examples
    --------
    >>> from appdyn.ocp.status import describe
    >>> describe(0, solver_status="Solve_Succeeded")
    'status 0 Solve_Succeeded'
    >>> describe(102, solver_status="Solve_Succeeded")
    'status 102 Bound_Violation (solver: Solve_Succeeded)'
    """
    name = status_name(status)
    extra = f" (solver: {solver_status})" if solver_status and solver_status != name else ""
    return f"status {int(status)} {name}{extra}"
