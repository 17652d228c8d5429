"""``appdyn slew``: a rest-to-rest optimal rigid-body slew (`problems.slew`), checked against
the solver's success and, when time-optimal, the rest-to-rest time bound."""
from __future__ import annotations

import argparse
import sys

import numpy as np

from problems.cli.common import PLOT_SUFFIXES, inertia_matrix
from problems.cli.common import integer as _integer
from problems.cli.common import number as _number
from problems.cli.common import output_file as _output_file
from problems.cli.common import positive as _positive
from problems.cli.common import same_file
from problems.cli.common import vector as _vector
from problems.cli.common import write_json

__all__ = ["add_parser", "check", "run", "rest_to_rest_bound", "target_angle"]


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
    sl.add_argument("--quiet", action="store_true", help="no solver progress lines")
    return sl


def check(parser, args) -> None:
    """Checks across options, as argparse errors on ``parser`` (exit status 2)."""
    p = parser
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
    from problems import slew

    if args.u_max is None:
        u_max = 1.0 if args.time_optimal else None
    else:
        u_max = float(args.u_max[0]) if args.u_max.size == 1 else args.u_max
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
    why = f"{data.get('status', '')}: {data.get('message', '')}".strip(": ")
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
            slew.plot_slew(sol, args.plot)
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
