"""Reports of a slew solution: switch times, a JSON-ready summary, a table, a figure."""
from __future__ import annotations

import warnings
from collections.abc import Mapping

import numpy as np

from appdyn.ocp import Solution, control_switches
from appdyn.ocp.status import describe

from .problem import attitude_blocks
from .targets import ARCSEC

__all__ = ["switch_times", "polish_text", "summary", "format_summary", "plot_slew"]


def switch_times(solution: Solution, *, component=None, axis=None) -> list:
    """Switch times [s] of each torque component: the engine's one switch detector
    (`ocp.control_switches`: bound-to-bound jumps at the middle of the range, and both ends
    of interior arcs), so they agree with `ocp.find_switches` and `ocp.interval_errors`.

    Parameters
    ----------
    solution : ocp.Solution of a slew
    component : int, optional
        One torque component (0, 1, 2); default all.
    axis : int, optional
        Deprecated name of ``component`` (``axis`` is a 3-vector everywhere else); warns
        with a `DeprecationWarning`.

    Returns
    -------
    list of ndarray, or ndarray
        One array of switch times per component, or the array of ``component``.

    Raises
    ------
    TypeError
        If ``component`` is not an integer, or both ``component`` and ``axis`` are given.
    ValueError
        If ``component`` is out of range.

    Examples
    --------
    A 0.1 rad rest-to-rest slew about the third body axis switches once, at half time:

    >>> import numpy as np
    >>> from appdyn.problems import slew
    >>> sol = slew.time_optimal(np.eye(3), angle=0.1, axis=[0, 0, 1], N=10, starts=1)
    >>> t_s = slew.switch_times(sol, component=2)
    >>> t_s.round(4), round(sol.T / 2, 4)
    (array([0.3162]), 0.3162)
    """
    if axis is not None:
        if component is not None:
            raise TypeError("give `component`, not both `component` and its old name `axis`")
        warnings.warn("`switch_times(axis=...)` is deprecated: use `component=` (an integer "
                      "torque component; `axis` is a 3-vector elsewhere)", DeprecationWarning,
                      stacklevel=2)
        component, name = axis, "axis"
    else:
        name = "component"
    per = control_switches(solution)
    if component is None:
        return per
    if isinstance(component, (bool, np.bool_)) or not isinstance(component, (int, np.integer)):
        raise TypeError(f"`{name}` must be a component index 0, 1 or 2, got {component!r}")
    if not 0 <= component < len(per):
        raise ValueError(f"`{name}` must be a component index in [0, {len(per)}), "
                         f"got {component!r}")
    return per[int(component)]


# ----------------------------------------------------------------------- reporting
def polish_text(record: Mapping) -> str:
    """One line for a message or summary from a `solve_time_optimal` ``info['polish']``
    record.

    Parameters
    ----------
    record : mapping
        ``info['polish']`` of a time-optimal slew: ``ran``, ``why`` and, when it ran,
        ``used``, ``method``, ``wall_time`` [s], ``budget`` (IPOPT iterations per NLP),
        ``T_before``, ``T_after`` [s], ``gain`` [s].

    Returns
    -------
    str

    Raises
    ------
    TypeError
        If ``record`` is not a mapping.
    ValueError
        If ``record`` lacks a key the line needs.

    Examples
    --------
    >>> from appdyn.problems.slew import polish_text
    >>> polish_text({"ran": False, "used": False, "why": "polish=False"})
    'polish skipped: polish=False'
    """
    if not isinstance(record, Mapping):
        raise TypeError(f"`record` must be a mapping (a slew's info['polish']), got "
                        f"{type(record).__name__}")
    need = ("ran", "why") + (("used", "wall_time", "budget") if record.get("ran") else ())
    need += ("T_before", "T_after", "gain") if record.get("ran") and record.get("used") else ()
    missing = [key for key in need if key not in record]
    if missing:
        raise ValueError(f"`record` lacks {missing}: pass a time-optimal slew's info['polish']")
    if not record["ran"]:
        return f"polish skipped: {record['why']}"
    head = (f"polish ({record.get('method') or 'none'}, {record['wall_time']:.3g} s, at most "
            f"{record['budget']} IPOPT iterations per NLP)")
    if record.get("used"):
        return (f"{head}: T {record['T_before']:.10g} -> {record['T_after']:.10g} s, gain "
                f"{record['gain']:.3g} s")
    return f"{head} not used: {record['why']}"


def summary(solution: Solution, *, eigenaxis=None) -> dict:
    """JSON-ready summary of a slew solution.

    Keys: success, status (an int, `ocp.status`), solver_status (IPOPT's text), message,
    T [s], cost, switch_times [s] (per torque axis),
    controls (their names, the model's: ``L1..L3`` for a body torque),
    iterations, solve_time [s], constraint_violation (NLP units, see `ocp.solve`),
    pointing_error_arcsec (final attitude error of the re-simulated control [arcsec]),
    final_rate_error [rad/s] (same re-simulation), propagation_error (largest deviation of
    the re-integrated trajectory from the collocated states), quaternion_norm_error;
    ``polish`` (what the switch-time polish did, `polish_text`) and ``wall_time`` [s] (the
    whole pipeline, multi-start, polish and checks included) of a time-optimal slew; and
    ``eigenaxis_T`` [s] when given. Re-simulation numbers are NaN when it failed.

    Raises
    ------
    TypeError
        If ``solution`` is not an `ocp.Solution`.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.problems import slew
    >>> sol = slew.time_optimal(np.eye(3), angle=0.1, axis=[0, 0, 1], N=10, starts=1)
    >>> data = slew.summary(sol, eigenaxis=slew.eigenaxis_time(np.eye(3), 0.1, [0, 0, 1]))
    >>> data["success"], data["status"], round(data["T"], 6), round(data["eigenaxis_T"], 6)
    (True, 0, 0.632456, 0.632456)
    >>> [np.round(s, 4).tolist() for s in data["switch_times"]]
    [[], [], [0.3162]]
    """
    if not isinstance(solution, Solution):
        raise TypeError(f"`solution` must be an ocp.Solution, got {type(solution).__name__}")
    sw = switch_times(solution) if solution.success else [np.array([])] * 3
    info = getattr(solution, "info", {}) or {}
    perr = info.get("pointing_error", solution.pointing_error)
    rerr = info.get("final_rate_error")
    if rerr is None:
        term = solution.terminal_error[attitude_blocks(solution.problem.model)[1]]
        rerr = float(np.max(term)) if np.all(np.isfinite(term)) else float("nan")
    out = dict(
        success=bool(solution.success),
        status=int(solution.status),
        solver_status=str(solution.solver_status),
        message=str(solution.message),
        T=float(solution.T),
        cost=float(solution.cost),
        switch_times=[s.tolist() for s in sw],
        controls=list(solution.problem.model.controls),
        iterations=int(solution.iterations),
        solve_time=float(solution.solve_time),
        constraint_violation=float(solution.constraint_violation),
        pointing_error_arcsec=float("nan") if perr is None else float(perr) * ARCSEC,
        final_rate_error=float(rerr),
        propagation_error=float(solution.propagation_error),
        quaternion_norm_error=float(solution.quaternion_norm_error),
    )
    if "polish" in info:  # time-optimal: whether the switch-time polish ran, what it gained
        out["polish"] = dict(info["polish"])
    if "wall_time" in info:
        out["wall_time"] = float(info["wall_time"])
    if eigenaxis is not None:
        out["eigenaxis_T"] = float(eigenaxis)
    return out


_SUMMARY_KEYS = ("success", "status", "T", "cost", "switch_times", "iterations", "solve_time",
                 "constraint_violation", "pointing_error_arcsec", "final_rate_error",
                 "propagation_error", "quaternion_norm_error")


def format_summary(data: dict) -> str:
    """A readable table of `summary` output.

    Raises
    ------
    TypeError
        If ``data`` is not a mapping (a `summary` dict).
    ValueError
        If ``data`` lacks a key of `summary`.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.problems import slew
    >>> sol = slew.time_optimal(np.eye(3), angle=0.1, axis=[0, 0, 1], N=10, starts=1)
    >>> print(slew.format_summary(slew.summary(sol)))  # doctest: +ELLIPSIS
    Optimal slew
      success                   True (status 0 Solve_Succeeded)
      maneuver time T [s]       0.632456
      cost                      0.6324555...
      switch times L1 [s]       -
      switch times L2 [s]       -
      switch times L3 [s]       0.3162
      IPOPT iterations          ...
    """
    if not isinstance(data, Mapping):
        raise TypeError(f"`data` must be a dict from `summary`, got {type(data).__name__}")
    missing = [k for k in _SUMMARY_KEYS if k not in data]
    if missing:
        raise ValueError(f"`data` must be a dict from `summary`; missing keys {missing}")
    rows = [
        ("success",
         f"{data['success']} ({describe(data['status'], solver_status=data.get('solver_status', ''))})"),
        ("maneuver time T [s]", f"{data['T']:.6f}"),
    ]
    if "eigenaxis_T" in data:
        rows.append(("eigenaxis maneuver T [s]", f"{data['eigenaxis_T']:.6f}"))
    rows.append(("cost", f"{data['cost']:.8g}"))
    names = data.get("controls") or [f"L{i + 1}" for i in range(len(data["switch_times"]))]
    for name, s in zip(names, data["switch_times"]):
        rows.append((f"switch times {name} [s]", ", ".join(f"{v:.4f}" for v in s) or "-"))
    rows += [
        ("IPOPT iterations", f"{data['iterations']}"),
        ("solve time [s]", f"{data['solve_time']:.3f}"),
        ("constraint violation", f"{data['constraint_violation']:.2e}"),
        ("pointing error [arcsec]", f"{data['pointing_error_arcsec']:.3g}"),
        ("final rate error [rad/s]", f"{data['final_rate_error']:.2e}"),
        ("propagation error", f"{data['propagation_error']:.2e}"),
        ("|q| - 1 (max)", f"{data['quaternion_norm_error']:.2e}"),
    ]
    if "polish" in data:
        rows.append(("switch-time polish", polish_text(data["polish"])))
    if "wall_time" in data:
        rows.append(("wall time, total [s]", f"{data['wall_time']:.3f}"))
    width = max(len(k) for k, _ in rows)
    return "\n".join(["Optimal slew"] + [f"  {k:<{width}}  {v}" for k, v in rows])


def plot_slew(solution: Solution, ax=None):
    """`ocp.Solution.plot` of a slew (kept as a function for existing callers): quaternion,
    rates, torques (the bounds ``+-u_max`` dashed) and the rotation path.

    Parameters
    ----------
    solution : ocp.Solution of a slew
    ax : matplotlib.axes.Axes or matplotlib.figure.Figure, optional

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    TypeError
        If ``solution`` is not an `ocp.Solution`.
    """
    if not isinstance(solution, Solution):
        raise TypeError(f"`solution` must be an ocp.Solution, got {type(solution).__name__}")
    return solution.plot(ax)
