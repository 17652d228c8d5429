"""``appdyn slew``: a rest-to-rest optimal rigid-body slew (`problems.slew`), checked against
the solver's success and, when time-optimal, the rest-to-rest time bound.

With ``--targets FILE.csv`` or ``--example-targets`` it solves a maneuver table instead
(`problems.slew.maneuver_table`: one slew per target, ``--workers N``/``--scheduler ADDRESS``
to spread them, a progress line on stderr), exit status 0 when every slew is verified."""
from __future__ import annotations

import argparse
import csv
import sys
import time

import numpy as np

from appdyn.problems.cli.common import PLOT_SUFFIXES, inertia_matrix
from appdyn.problems.cli.common import integer as _integer
from appdyn.problems.cli.common import number as _number
from appdyn.problems.cli.common import output_file as _output_file
from appdyn.problems.cli.common import positive as _positive
from appdyn.problems.cli.common import same_file
from appdyn.problems.cli.common import vector as _vector
from appdyn.problems.cli.common import save_figure, write_json
from appdyn.problems.cli.common import (Progress, add_executor_options, executor_from, finish,
                                 progress_enabled)

__all__ = ["add_parser", "check", "run", "run_table", "read_targets", "rest_to_rest_bound",
           "target_angle"]


def add_parser(subparsers):
    """Add ``slew`` to ``subparsers``."""
    sl = subparsers.add_parser(
        "slew", help="optimal rigid-body attitude slew (direct collocation)",
        description="Rest-to-rest optimal slew. Exit status 1 when the solver fails or the "
                    "answer fails a check (time-optimal: T below the rest-to-rest bound "
                    "2 sqrt(J_min theta / |u|max)).")
    sl.set_defaults(_parser=sl)
    sl.add_argument("--inertia", type=_vector((3, 9)), required=True,
                    help="principal moments I1,I2,I3 or 9 matrix entries [kg m^2]")
    sl.add_argument("--u-max", dest="u_max", type=_vector((1, 3)),
                    help="torque bound [N m], scalar or per axis (time-optimal: 1; "
                         "min-effort: none)")
    sl.add_argument("--umax", dest="u_max", type=_vector((1, 3)), help=argparse.SUPPRESS)
    sl.add_argument("--norm-bound", action="store_true",
                    help="bound |u| <= u_max (scalar --u-max) instead of each axis")
    sl.add_argument("--axis", type=_vector((3,)), help="rotation axis (body frame), with --angle")
    sl.add_argument("--angle", type=_number, help="rotation angle [deg], with --axis")
    sl.add_argument("--qf", type=_vector((4,)),
                    help="target quaternion (scalar-last), instead of --axis/--angle")
    kind = sl.add_mutually_exclusive_group(required=True)
    kind.add_argument("--time-optimal", action="store_true", help="minimize the maneuver time")
    kind.add_argument("--min-effort", type=_positive, metavar="T",
                      help="minimize 1/2 int |u|^2 dt over the given time T [s]")
    sl.add_argument("--starts", type=_integer(1),
                    help="multi-start count, --time-optimal only (3)")
    sl.add_argument("--plot", metavar="FILE.png", type=_output_file(PLOT_SUFFIXES),
                    help="save quaternion, rates, torques, path (.png, .pdf or .svg)")
    sl.add_argument("--json", metavar="FILE", type=_output_file(),
                    help="write the summary as JSON")
    sl.add_argument("--quiet", action="store_true", help="no solver or table progress lines")
    table = sl.add_mutually_exclusive_group()
    table.add_argument("--targets", metavar="FILE.csv",
                       help="a maneuver table instead of one slew: a CSV with a header and "
                            "columns name (optional), angle [deg], axis1, axis2, axis3, or "
                            "q1, q2, q3, q4 (problems.slew.maneuver_table)")
    table.add_argument("--example-targets", action="store_true",
                       help="a maneuver table of the 8 targets of problems.slew.example_targets")
    add_executor_options(sl)
    sl.add_argument("--progress", action="store_true",
                    help="table progress lines on stderr (default: when stderr is a terminal)")
    return sl


def read_targets(path) -> list:
    """The targets of a ``--targets`` CSV file (angles in degrees there, radians here)."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    out = []
    for k, row in enumerate(rows):
        row = {key.strip(): (v or "").strip() for key, v in row.items() if key}
        target = {"name": row["name"]} if row.get("name") else {}
        try:
            if row.get("q1"):
                target["qf"] = [float(row[f"q{i}"]) for i in range(1, 5)]
            else:
                target["angle"] = np.radians(float(row["angle"]))
                target["axis"] = [float(row[f"axis{i}"]) for i in range(1, 4)]
        except (KeyError, TypeError, ValueError):
            raise ValueError(f"`targets` row {k + 1}: expected numbers in columns angle, "
                             f"axis1..3 or q1..4, got {row}") from None
        out.append(target)
    return out


def check(parser, args) -> None:
    """Checks across options, as argparse errors on ``parser`` (exit status 2)."""
    p = parser
    if args.targets is not None or args.example_targets:
        from appdyn.problems.slew.table import check_targets, example_targets

        flag = "--targets" if args.targets is not None else "--example-targets"
        for other, value in (("--axis", args.axis), ("--angle", args.angle), ("--qf", args.qf),
                             ("--plot", args.plot), ("--norm-bound", args.norm_bound or None)):
            if value is not None:
                p.error(f"argument {flag}: not allowed with argument {other}")
        try:
            args._targets = example_targets() if args.example_targets else \
                read_targets(args.targets)
            check_targets(args._targets)
        except OSError as exc:
            p.error(f"argument --targets: cannot read {args.targets!r}: {exc.strerror}")
        except ValueError as exc:
            p.error(f"argument {flag}: {exc}")
        if args.starts is not None and not args.time_optimal:
            p.error("argument --starts: only with --time-optimal")
        return
    if args.workers is not None or args.scheduler is not None:
        p.error("argument --workers/--scheduler: only with --targets or --example-targets")
    if args.qf is not None:
        for flag, value in (("--axis", args.axis), ("--angle", args.angle)):
            if value is not None:
                p.error(f"argument --qf: not allowed with argument {flag} (give --qf, or "
                        "--axis and --angle)")
        n = float(np.linalg.norm(args.qf))
        if abs(n - 1) > 1e-6:
            p.error(f"argument --qf: expected a unit quaternion (norm 1 to 1e-6), got norm {n:.9g}")
    elif args.axis is None and args.angle is None:
        p.error("the target needs --axis and --angle [deg], or --qf")
    elif args.angle is None:
        p.error("argument --axis: needs --angle [deg]")
    elif args.axis is None:
        p.error("argument --angle: needs --axis")
    elif not np.any(args.axis):
        p.error("argument --axis: expected a non-zero vector, got 0,0,0")
    if args.u_max is not None and np.any(args.u_max <= 0):
        p.error(f"argument --u-max: expected positive values, got "
                f"{','.join(map(str, args.u_max))}")
    if args.norm_bound and (args.u_max is None and args.min_effort is not None):
        p.error("argument --norm-bound: needs --u-max with --min-effort")
    if args.norm_bound and args.u_max is not None and args.u_max.size != 1:
        p.error("argument --norm-bound: needs a scalar --u-max")
    if args.starts is not None and not args.time_optimal:
        p.error("argument --starts: only with --time-optimal")
    if same_file(args.plot, args.json):
        p.error("argument --json: the same file as --plot")


def _slew_target(args):
    if args.qf is not None:
        return dict(qf=args.qf)
    return dict(axis=args.axis, angle=np.radians(args.angle))


def target_angle(args) -> float:
    """Rotation angle [rad] in [0, pi] from the identity to the target (sign-free)."""
    if args.qf is not None:
        q = args.qf / np.linalg.norm(args.qf)
    else:
        half = 0.5 * np.radians(args.angle)
        q = np.append(np.sin(half) * args.axis / np.linalg.norm(args.axis), np.cos(half))
    return float(2.0 * np.arctan2(np.linalg.norm(q[:3]), abs(q[3])))


def rest_to_rest_bound(inertia, theta, u_norm) -> float:
    """Lower bound [s] on a rest-to-rest slew by ``theta`` [rad] with ``|u| <= u_norm``.

    ``|w| <= |H| / J_min`` and ``|dH/dt| = |u| <= u_norm`` (inertial frame) with ``H = 0`` at
    both ends give ``theta <= int |w| dt <= u_norm T^2 / (4 J_min)``, i.e.
    ``T >= 2 sqrt(J_min theta / u_norm)``.
    """
    j_min = float(np.min(np.linalg.eigvalsh(np.atleast_2d(inertia) if np.ndim(inertia) == 2
                                            else np.diag(inertia))))
    return 2.0 * float(np.sqrt(j_min * theta / u_norm))


def run(args) -> int:
    """Solve, print the summary, write ``--plot``/``--json``; 0 when verified, else 1."""
    from appdyn.problems import slew

    if getattr(args, "_targets", None) is not None:
        return run_table(args)
    if args.u_max is None:
        u_max = 1.0 if args.time_optimal else None
    else:
        u_max = float(args.u_max[0]) if args.u_max.size == 1 else args.u_max
    t_start = time.perf_counter()
    common = dict(u_max=u_max, norm_bound=args.norm_bound, verbose=not args.quiet,
                  **_slew_target(args))
    inertia = inertia_matrix(args.inertia)
    eig = None
    check = None
    if args.time_optimal:
        sol = slew.time_optimal(inertia, starts=3 if args.starts is None else args.starts,
                                **common)
        if args.axis is not None and not args.norm_bound:
            try:
                eig = slew.eigenaxis_time(inertia, np.radians(args.angle), args.axis, u_max)
            except ValueError:
                eig = None  # not a principal axis: no closed-form eigenaxis time
        u_norm = float(u_max) if args.norm_bound else float(
            np.linalg.norm(np.broadcast_to(np.asarray(u_max, dtype=float), (3,))))
        bound = rest_to_rest_bound(inertia, target_angle(args), u_norm)
        check = (float(sol.T) >= bound * (1 - 1e-6), bound)
    else:
        sol = slew.min_effort(inertia, args.min_effort, **common)
    data = slew.summary(sol, eigenaxis=eig)
    success = bool(data.get("success", sol.success))
    from appdyn.ocp.status import describe  # the CLI imports the engine only when it runs

    why = f"{describe(data['status'], solver_status=data.get('solver_status', ''))}: {data.get('message', '')}"
    rows = []
    if check is not None:
        data["T_lower_bound"] = check[1]
        rows.append(("lower bound on T [s]", f"{check[1]:.6f}"))
        if success and not check[0]:
            why = (f"check FAILED: T = {float(sol.T):.6g} s is below the rest-to-rest bound "
                   f"2 sqrt(J_min theta / |u|max) = {check[1]:.6g} s")
            success = data["success"] = False
            data["message"] = why
            rows.append(("check", "FAILED: T below the lower bound"))
    # the whole command's wall time (the summary's polish row says what the polish did)
    data["wall_time"] = time.perf_counter() - t_start
    text = slew.format_summary(data)
    if "pointing_error_arcsec" in data and "pointing" not in text:
        rows.append(("pointing error [arcsec]", f"{data['pointing_error_arcsec']:.3g}"))
    if "constraint_violation" in data and "constraint" not in text:
        rows.append(("constraint violation", f"{data['constraint_violation']:.2e}"))
    if rows:
        width = max([len(k) for k, _ in rows]
                    + [len(line[2:].split("  ")[0]) for line in text.splitlines()[1:]])
        text += "\n" + "\n".join(f"  {k:<{width}}  {v}" for k, v in rows)
    print(text)
    if args.plot:
        if success:
            save_figure(sol.plot(), args.plot)
            print(f"plot written to {args.plot}")
        else:
            print(f"appdyn slew: --plot {args.plot} skipped: the slew failed ({why})",
                  file=sys.stderr)
    if args.json:
        write_json(data, args.json)
        print(f"summary written to {args.json}")
    if not success:
        print(f"appdyn slew: failed: {why}", file=sys.stderr)
    return 0 if success else 1


def run_table(args) -> int:
    """``--targets``/``--example-targets``: solve the maneuver table, print it, write
    ``--json``; 0 when every slew is verified, else 1."""
    from appdyn.problems.slew import maneuver_table

    if args.u_max is None:
        u_max = 1.0 if args.time_optimal else None
    else:
        u_max = float(args.u_max[0]) if args.u_max.size == 1 else args.u_max
    kind = dict(objective="time") if args.time_optimal else \
        dict(objective="effort", T=args.min_effort)
    if args.starts is not None:
        kind["starts"] = args.starts
    progress = Progress(f"slew table ({len(args._targets)} targets)",
                        enabled=progress_enabled(args))
    try:
        with executor_from(args) as executor:
            table = maneuver_table(inertia_matrix(args.inertia), args._targets, u_max=u_max,
                                   executor=executor,
                                   progress=progress if progress.enabled else None, **kind)
    finally:
        progress.close()
    return finish(table, "slew", json=args.json)
