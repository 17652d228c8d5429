"""Maneuver tables: the optimal slew to every target of a catalogue, on any executor.

`maneuver_table` checks the arguments and every target up front, hands one task per target
to the executor (the work is the module-level `solve_target`: `time_optimal` or
`min_effort` of `problems.slew.maneuvers`), collects the solutions by target index and
assembles a `ManeuverTable`. Serial, thread-pool and process-pool runs give the same table
(each task runs the serial code; only the wall times differ). A process pool receives the
inertia, the target and the options pickled (numbers, arrays, a `KeepOut`, a guess
`Solution` all pickle) and sends the `ocp.Solution` back.
"""
from __future__ import annotations

import csv
import inspect
import io
import time
from collections.abc import Mapping, Sequence
from concurrent.futures import Executor
from dataclasses import dataclass
from typing import Callable

import numpy as np

from appdyn.dynamics.attitude import axis_angle_from_quat, quat_conj, quat_mul
from appdyn.dynamics.executors import check_executor, gather
from appdyn.dynamics.progress import accepts_progress_bar
from appdyn.dynamics.interrupts import check_interrupt, interruptible
from appdyn.dynamics.serialize import jsonable, text_table, to_json
from appdyn.dynamics.validate import check_inertia, finite_array, one_of, positive, unit_quaternion
from appdyn.ocp.status import status_name
from appdyn.problems.dispersion.result import ALL_FAILED, ALL_OK, SOME_FAILED

from .maneuvers import min_effort, time_optimal
from .targets import check_u_max
from .targets import targets as target_attitude
from appdyn.dynamics.results import Result

__all__ = ["maneuver_table", "ManeuverTable", "Target", "check_targets", "example_targets",
           "solve_target", "OBJECTIVES", "ALL_OK", "SOME_FAILED", "ALL_FAILED"]

#: objective -> the slew solved per target
OBJECTIVES = {"time": time_optimal, "effort": min_effort}
_OWN = ("inertia", "angle", "axis", "qf", "T", "u_max")  # set by maneuver_table itself
_KEYS = {"name", "angle", "axis", "qf"}


# ---------------------------------------------------------------------------- targets
@dataclass(frozen=True)
class Target:
    """One target of a table, checked.

    Attributes
    ----------
    name : str
    kwargs : dict
        What the slew function receives: ``{'angle', 'axis'}`` or ``{'qf'}``.
    qf : ndarray, shape (4,)
        The target quaternion (scalar-last).
    angle : float [rad]
        The rotation angle as given, else that of ``qf`` relative to ``q0``, in ``[0, pi]``.
    axis : ndarray, shape (3,)
        The unit rotation axis (body frame at the start), given or that of ``qf``.
    """

    name: str
    kwargs: dict
    qf: np.ndarray
    angle: float
    axis: np.ndarray


def _one_target(k, spec, q0) -> Target:
    where = f"targets[{k}]"
    if isinstance(spec, Mapping):
        unknown = set(spec) - _KEYS
        if unknown:
            raise ValueError(f"`{where}` has unknown keys {sorted(map(str, unknown))}; a target "
                             f"takes {sorted(_KEYS)}")
        name = spec.get("name", f"target {k}")
        if not isinstance(name, str):
            raise TypeError(f"`{where}['name']` must be a string, got {type(name).__name__}")
        kwargs = {key: spec[key] for key in ("angle", "axis", "qf") if key in spec}
    else:
        name, kwargs = f"target {k}", {"qf": spec}
    try:
        start, qf = target_attitude(q0, kwargs.get("qf"), kwargs.get("angle"), kwargs.get("axis"))
    except (TypeError, ValueError) as exc:
        raise type(exc)(f"`{where}` ({name!r}): {exc}") from None
    if "qf" in kwargs:
        kwargs = {"qf": qf}
        axis, angle = axis_angle_from_quat(quat_mul(qf, quat_conj(start)))
    else:
        angle = float(kwargs["angle"])
        axis = np.asarray(kwargs["axis"], dtype=float) / np.linalg.norm(kwargs["axis"])
        kwargs = {"angle": angle, "axis": axis}
    return Target(name, kwargs, qf, float(angle), np.asarray(axis, dtype=float))


def check_targets(targets, q0=None) -> list:
    """The `Target` list of ``targets`` (see `maneuver_table`), each checked.

    Raises
    ------
    TypeError, ValueError
        Naming ``targets`` (and the entry ``targets[k]``): not a sequence or an array of
        shape (K, 4), empty, an entry that is neither a mapping nor a quaternion, unknown
        keys, a bad angle, axis or quaternion, duplicate names.
    """
    if isinstance(targets, (str, bytes, Mapping)) or not isinstance(targets, (Sequence, np.ndarray)):
        raise TypeError(f"`targets` must be a sequence of mappings (angle and axis, or qf) or "
                        f"an array of quaternions, shape (K, 4); got {type(targets).__name__}")
    if len(targets) == 0:
        raise ValueError("`targets` must hold at least one target")
    if not any(isinstance(t, Mapping) for t in targets):
        arr = finite_array(targets, "targets")
        if arr.ndim != 2 or arr.shape[1] != 4:
            raise ValueError(f"`targets` as an array must have shape (K, 4) (one scalar-last "
                             f"quaternion per row), got {arr.shape}")
        targets = list(arr)
    q0 = None if q0 is None else unit_quaternion(q0, "q0")
    checked = [_one_target(k, spec, q0) for k, spec in enumerate(targets)]
    names = [t.name for t in checked]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise ValueError(f"`targets` names must be unique, repeated: {twice}")
    return checked


def example_targets() -> list:
    """A catalogue of 8 targets (angles [rad] about body axes, and one quaternion): the
    ``appdyn slew --example-targets`` table and the benchmark's.

    Examples
    --------
    >>> from appdyn.problems.slew import example_targets
    >>> [t["name"] for t in example_targets()][:3]
    ['x 30', 'y 60', 'z 90']
    """
    d = np.pi / 180.0
    s = np.sqrt(0.5)
    return [{"name": "x 30", "angle": 30 * d, "axis": [1.0, 0.0, 0.0]},
            {"name": "y 60", "angle": 60 * d, "axis": [0.0, 1.0, 0.0]},
            {"name": "z 90", "angle": 90 * d, "axis": [0.0, 0.0, 1.0]},
            {"name": "xy 45", "angle": 45 * d, "axis": [1.0, 1.0, 0.0]},
            {"name": "yz 75", "angle": 75 * d, "axis": [0.0, 1.0, 1.0]},
            {"name": "xyz 120", "angle": 120 * d, "axis": [1.0, 1.0, 1.0]},
            {"name": "x -20", "angle": -20 * d, "axis": [1.0, 0.0, 0.0]},
            {"name": "z 90 (q)", "qf": [0.0, 0.0, s, s]}]


# ---------------------------------------------------------------------------- result
@dataclass(frozen=True, eq=False, repr=False)
class ManeuverTable(Result):
    """Outcome of `maneuver_table`: one row per finished target, in catalogue order.

    Arrays are **targets first**: row ``k`` belongs to target ``index[k]``.

    Attributes
    ----------
    objective : str
        ``'time'`` or ``'effort'``.
    inertia : ndarray, shape (3, 3) [kg m^2]
    u_max : ndarray, shape (3,) [N m], or None
        The torque bound per axis (``None``: unbounded, minimum effort only).
    T_fixed : float [s] or None
        The maneuver time of a minimum-effort table.
    index : ndarray of int, shape (m,)
        Target numbers, increasing (``arange(total)`` unless interrupted).
    names : tuple of str, length m
    angles : ndarray, shape (m,) [rad]
        Rotation angle of each target (as given, or that of its ``qf``).
    axes : ndarray, shape (m, 3)
        Unit rotation axes (body frame at the start).
    qf : ndarray, shape (m, 4)
        Target quaternions (scalar-last).
    T : ndarray, shape (m,) [s]
        Maneuver times (the optimum of a time-optimal table).
    cost : ndarray, shape (m,)
        The objective: [s] (time) or [N^2 m^2 s] (``1/2 integral |u|^2 dt``).
    row_success : ndarray of bool, shape (m,)
        ``Solution.success`` of each slew (verified by re-simulation).
    row_status : tuple of int, length m
        ``Solution.status`` of each slew (0 a success; `ocp.status`).
    messages : tuple of str, length m
    iterations : ndarray of int, shape (m,)
        IPOPT iterations of each returned solution (``Solution.iterations``).
    wall_times : ndarray, shape (m,) [s]
        Time of each target's work (in its worker).
    solutions : tuple of ocp.Solution, length m
    total : int
        Targets asked for.
    executor : str
        ``"serial"`` or the executor's class name.
    wall_time : float [s]
        Time of the whole `maneuver_table` call.
    complete : bool
        False for the partial table of an interrupted run (``KeyboardInterrupt.partial``).
    success : bool
        Every target asked for finished and succeeded (property).
    status : int
        `ALL_OK` (0), `SOME_FAILED` (1) or `ALL_FAILED` (2) over the finished rows (property).
    message : str
        ``status`` in words, with the first failures (property).
    """

    objective: str
    inertia: np.ndarray
    u_max: np.ndarray | None
    T_fixed: float | None
    index: np.ndarray
    names: tuple
    angles: np.ndarray
    axes: np.ndarray
    qf: np.ndarray
    T: np.ndarray
    cost: np.ndarray
    row_success: np.ndarray
    row_status: tuple
    messages: tuple
    iterations: np.ndarray
    wall_times: np.ndarray
    solutions: tuple
    total: int
    executor: str = "serial"
    wall_time: float = 0.0
    complete: bool = True

    # ------------------------------------------------------------------ verdict
    _repr_fields = ('objective', 'names', 'T')

    @property
    def status(self) -> int:
        """`ALL_OK`, `SOME_FAILED` or `ALL_FAILED` over the finished rows."""
        failed = int(np.count_nonzero(~self.row_success))
        return ALL_OK if not failed else (ALL_FAILED if failed == len(self.index) else SOME_FAILED)

    success = property(lambda self: self.complete and bool(np.all(self.row_success)),
                       doc="Every target asked for finished and succeeded.")

    @property
    def message(self) -> str:
        """``status`` in words, with up to three failures."""
        m = len(self.index)
        bad = [f"{n}: {msg}" for n, ok, msg in zip(self.names, self.row_success, self.messages)
               if not ok]
        text = f"all {m} slews succeeded" if not bad else \
            f"{len(bad)} of {m} slews failed ({'; '.join(bad[:3])}{', ...' if len(bad) > 3 else ''})"
        if not self.complete:
            text += f"; interrupted after {m} of {self.total} targets"
        return text

    # ------------------------------------------------------------------- output
    def rows(self) -> list:
        """One plain dict per row (JSON- and CSV-ready): ``name, angle [rad], axis1..3,
        q1..q4, T [s], cost, success, status, iterations, wall_time [s], message``."""
        out = []
        for k in range(len(self.index)):
            row = {"name": self.names[k], "angle": self.angles[k]}
            row.update({f"axis{i + 1}": self.axes[k, i] for i in range(3)})
            row.update({f"q{i + 1}": self.qf[k, i] for i in range(4)})
            row.update({"T": self.T[k], "cost": self.cost[k], "success": self.row_success[k],
                        "status": self.row_status[k], "iterations": self.iterations[k],
                        "wall_time": self.wall_times[k], "message": self.messages[k]})
            out.append(jsonable(row))
        return out

    def to_csv(self, path=None) -> str:
        """`rows` as CSV text (header first); also written to ``path`` when given."""
        buf = io.StringIO()
        rows = self.rows()
        writer = csv.DictWriter(buf, fieldnames=list(rows[0]) if rows else ["name"],
                                lineterminator="\n")
        writer.writeheader()
        writer.writerows(rows)
        if path is not None:
            with open(path, "w", newline="") as f:
                f.write(buf.getvalue())
        return buf.getvalue()

    def to_dict(self) -> dict:
        """Everything but the solutions as plain Python (JSON-ready through `to_json`)."""
        return jsonable({
            "success": self.success, "status": self.status, "message": self.message,
            "objective": self.objective, "inertia": self.inertia, "u_max": self.u_max,
            "T_fixed": self.T_fixed, "total": self.total, "complete": self.complete,
            "executor": self.executor, "wall_time": self.wall_time, "rows": self.rows()})

    def format(self) -> str:
        """The table as text: a header, then one line per target (angles in degrees)."""
        what = "minimum time" if self.objective == "time" else \
            f"minimum effort over T = {self.T_fixed:g} s"
        text = text_table(f"Maneuver table ({what})", [
            ("success", f"{self.success} (status {self.status})"),
            ("targets", f"{len(self.index)} of {self.total} solved"),
            ("executor", self.executor), ("wall time", f"{self.wall_time:.3f} s"),
            ("message", self.message)])
        cost = "T [s]" if self.objective == "time" else "cost [N^2 m^2 s]"
        head = ["target", "angle [deg]", "axis", cost, "ok", "status", "iter", "wall [s]"]
        lines = [[n, f"{np.degrees(a):.3f}", ",".join(f"{v:.3f}" for v in e),
                  f"{(t if self.objective == 'time' else c):.9g}", "yes" if ok else "NO",
                  status_name(s), str(it), f"{w:.3f}"]
                 for n, a, e, t, c, ok, s, it, w in zip(
                     self.names, self.angles, self.axes, self.T, self.cost, self.row_success,
                     self.row_status, self.iterations, self.wall_times)]
        width = [max(len(r[j]) for r in [head] + lines) for j in range(len(head))]
        body = [f"  {r[0]:<{width[0]}}" + "".join(f"  {c:>{w}}" for c, w in zip(r[1:], width[1:]))
                for r in [head] + lines]
        return text + "\n" + "\n".join(line.rstrip() for line in body)

    __str__ = format

    def plot(self, ax=None):
        """The maneuver time (or cost) of each target against its rotation angle [deg],
        failed rows marked; a time-optimal table of a bang-bang body follows
        ``T = 2 sqrt(theta / alpha)``.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Draw on these axes; by default on a new `matplotlib.figure.Figure` (no pyplot).

        Returns
        -------
        matplotlib.figure.Figure
        """
        from appdyn.dynamics.figures import axes_or_new_figure, finish_figure

        fig, ax = axes_or_new_figure(ax, (7.0, 4.5))
        y = self.T if self.objective == "time" else self.cost
        ok = np.asarray(self.row_success, dtype=bool)
        deg = np.degrees(self.angles)
        ax.plot(deg[ok], y[ok], "o", color="tab:blue", label="solved")
        if not ok.all():
            ax.plot(deg[~ok], y[~ok], "x", color="tab:red", ms=9, label="failed")
        for name, a, v in zip(self.names, deg, y):
            ax.annotate(name, (a, v), textcoords="offset points", xytext=(5, 4), fontsize=8)
        what = "minimum time" if self.objective == "time" else \
            f"minimum effort over T = {self.T_fixed:g} s"
        ax.set(xlabel="rotation angle [deg]",
               ylabel="T [s]" if self.objective == "time" else "cost [N^2 m^2 s]",
               title=f"Maneuver table ({what}): {int(ok.sum())} of {self.total} solved")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
        return finish_figure(fig)


# ---------------------------------------------------------------------------- driver
def solve_target(objective: str, inertia, target: dict, T, u_max, options: dict):
    """One target's slew: ``(solution, wall time [s])``; the executor task of
    `maneuver_table` (module level, so that a process pool can run it)."""
    start = time.perf_counter()
    fun = OBJECTIVES[objective]
    args = (inertia,) if objective == "time" else (inertia, T)
    sol = fun(*args, u_max=u_max, **target, **options)
    return sol, time.perf_counter() - start


def _check_options(objective, options: dict) -> dict:
    fun = OBJECTIVES[objective]
    known = [p for p in inspect.signature(fun).parameters if p not in _OWN]
    for name in options:
        if name not in known:
            raise TypeError(f"`{name}` is not an option of maneuver_table or {fun.__name__} "
                            f"(it takes {known}; the targets give angle/axis or qf)")
    return dict(options)


@accepts_progress_bar("maneuver_table")
@interruptible
def maneuver_table(inertia, targets, *, objective: str = "time", T=None, u_max=1.0,
                   executor: Executor | None = None,
                   progress: Callable[[int, int], None] | None = None,
                   **options) -> ManeuverTable:
    """Optimal rest-to-rest slews of one body to every target of a catalogue.

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2]
    targets : sequence of mapping, or array_like, shape (K, 4)
        Each a mapping with ``angle`` [rad] and ``axis`` (3,) (body frame at the start), or
        with ``qf`` (4,) (scalar-last unit quaternion), and optionally a unique ``name``
        (default ``'target k'``); or the K target quaternions as rows.
    objective : {'time', 'effort'}
        `time_optimal` per target, or `min_effort` over the fixed time ``T``.
    T : float [s], optional
        The maneuver time of every ``'effort'`` slew (required there; not with ``'time'``,
        which finds T: bound it by ``T_max``).
    u_max : float or array_like, shape (3,) [N m], or None
        Torque bound (default 1). ``None`` only with ``'effort'``: unbounded.
    executor : concurrent.futures.Executor, optional
        Runs the targets, one task each (a ``ThreadPoolExecutor``, a
        ``ProcessPoolExecutor``, dask.distributed's ``client.get_executor()``, ...). The
        table is the serial one (same T, costs and statuses; only the wall times differ).
        The executor stays the caller's. ``None`` (default): serial, in the calling thread.
        A process pool pickles the inertia, each target and ``options`` (numbers, arrays,
        a `KeepOut` and a guess `ocp.Solution` pickle); each worker builds its own NLPs.
        With the ``spawn`` start method the calling script needs the usual
        ``if __name__ == "__main__":`` guard.
    progress : bool or callable, optional
        ``True``: a bar on stderr (`dynamics.progress`); a callable: ``progress(done,
        total)`` in this thread after each finished target.
    **options
        Passed to `time_optimal` or `min_effort` for every target: ``N``, ``starts``,
        ``ipopt_options``, ``q0``, ``norm_bound``, ``keep_out``, ``pointing_tol``, ...

    Returns
    -------
    ManeuverTable

    Raises
    ------
    TypeError
        Naming the argument: ``targets`` not a sequence or an entry of the wrong kind,
        ``executor`` not an Executor, ``progress`` not callable, an unknown option.
    ValueError
        Naming the argument: ``inertia``, ``objective``, ``T``, ``u_max``, an entry
        ``targets[k]`` (unknown keys, both or neither of qf and angle/axis, a bad axis or
        quaternion), duplicate names. Raised before any slew is solved.
    KeyboardInterrupt
        On Ctrl-C; when targets had finished, ``exc.partial`` is their `ManeuverTable`
        (``complete=False``). Pending targets of an executor are cancelled; running ones
        finish in the background (threads) or in their worker (processes).

    Notes
    -----
    A slew that fails (``success=False``) is a row with its status; it does not stop the
    others. For a rest-to-rest rotation by ``theta`` about a principal axis of moment ``J``:
    time-optimal ``T = 2 sqrt(J theta / u_max)`` (bang-bang), minimum-effort cost
    ``6 J^2 theta^2 / T^3`` (cubic angle, no active bound).

    Examples
    --------
    Two small slews of a unit-inertia body (bang-bang: ``T = 2 sqrt(theta)``):

    >>> import numpy as np
    >>> from appdyn.problems.slew import maneuver_table
    >>> table = maneuver_table(np.eye(3), [{"name": "roll", "angle": 0.1, "axis": [1, 0, 0]},
    ...                                    {"name": "yaw", "angle": 0.2, "axis": [0, 0, 1]}],
    ...                        N=10, starts=1)
    >>> table.success, table.names, np.round(table.T, 6).tolist()
    (True, ('roll', 'yaw'), [0.632456, 0.894427])
    >>> bool(np.allclose(table.T, 2 * np.sqrt(table.angles), rtol=1e-8))
    True
    >>> table.rows()[1]["name"], round(table.rows()[1]["T"], 6)
    ('yaw', 0.894427)
    """
    start = time.perf_counter()
    inertia = check_inertia(inertia)
    objective = one_of(objective, "objective", tuple(OBJECTIVES))
    if objective == "effort":
        if T is None:
            raise ValueError("`T` [s] is required with objective='effort'")
        T = positive(T, "T")
    elif T is not None:
        raise ValueError("`T` is only for objective='effort' (a time-optimal slew finds T; "
                         "bound it with `T_max`)")
    if u_max is None and objective == "time":
        raise ValueError("`u_max` must be given (a positive scalar or 3 values [N m]) with "
                         "objective='time'")
    bound = None if u_max is None else check_u_max(u_max)
    options = _check_options(objective, options)
    rows = check_targets(targets, options.get("q0"))
    check_executor(executor)
    if progress is not None and not callable(progress):
        raise TypeError(f"`progress` must be None or a callable (done, total), got "
                        f"{type(progress).__name__}")
    tasks = [(objective, inertia, row.kwargs, T, u_max, options) for row in rows]
    done: dict = {}

    def finished(k, out):
        done[k] = out
        if progress is not None:
            progress(len(done), len(tasks))

    def result(complete: bool) -> ManeuverTable:
        index = sorted(done)
        sols = [done[k][0] for k in index]
        picked = [rows[k] for k in index]
        return ManeuverTable(
            objective=objective, inertia=inertia, u_max=bound, T_fixed=T,
            index=np.array(index, dtype=int), names=tuple(r.name for r in picked),
            angles=np.array([r.angle for r in picked], dtype=float),
            axes=np.array([r.axis for r in picked], dtype=float).reshape(-1, 3),
            qf=np.array([r.qf for r in picked], dtype=float).reshape(-1, 4),
            T=np.array([s.T for s in sols], dtype=float),
            cost=np.array([s.cost for s in sols], dtype=float),
            row_success=np.array([s.success for s in sols], dtype=bool),
            row_status=tuple(int(s.status) for s in sols),
            messages=tuple("" if s.success else str(s.message) for s in sols),
            iterations=np.array([s.iterations for s in sols], dtype=int),
            wall_times=np.array([done[k][1] for k in index], dtype=float),
            solutions=tuple(sols), total=len(tasks),
            executor="serial" if executor is None else type(executor).__name__,
            wall_time=time.perf_counter() - start, complete=complete)

    try:
        if executor is None:
            for k, task in enumerate(tasks):
                check_interrupt()
                finished(k, solve_target(*task))
        else:
            gather(executor, solve_target, tasks, finished)
    except KeyboardInterrupt as exc:
        if done:
            exc.partial = result(False)
        raise
    return result(True)
