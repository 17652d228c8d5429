"""The ``appdyn`` command line.

    appdyn simulate torque-free --inertia 1,2,3 --w0 -1,0.1,0.8 --t-final 50 [--plot F.png]
    appdyn slew --inertia 1,1,1 --u-max 1 --axis 0,0,1 --angle 180 --time-optimal
    appdyn stability spin|heavy-top|projectile|rotor|gyrostat|sweep ... [--json F] [--plot F.png]
    appdyn demo
    appdyn bench [NAME ...]

Exit status: 0 done (and verified where the command checks its answer: ``simulate`` against
the closed form, ``slew`` against the solver's success and the rest-to-rest time bound);
1 numerical failure or failed check (a one-line reason on stderr); 2 bad input (argparse-style
usage and a one-line ``error: argument --OPTION: ...``, before any computation where the input
can be checked up front: values, conflicting options, output paths). Option values may start
with a minus sign (``--w0 -1,0,0``, ``--values -1:1:5``). JSON output is strict (non-finite
numbers as ``null``). ``APPDYN_TRACEBACK=1`` shows the traceback of an unexpected error.

Library code never prints; this module is the one place that does.
"""
from __future__ import annotations

import argparse
import os
import re
import runpy
import sys
from pathlib import Path

import numpy as np

from problems.cli_common import PLOT_SUFFIXES, Progress, attach_negative_values
from problems.cli_common import integer as _integer
from problems.cli_common import number as _number
from problems.cli_common import output_file as _output_file
from problems.cli_common import positive as _positive
from problems.cli_common import progress_enabled
from problems.cli_common import strict_json
from problems.cli_common import vector as _vector
from problems.cli_common import write_outputs

__all__ = ["main", "build_parser"]

BENCH_DIR = Path(__file__).resolve().parents[1] / "bench"
FIXED_STEP = ("rk4", "rk8", "lie")


def _inertia(values):
    return values if values.size == 3 else values.reshape(3, 3)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="appdyn", description="Aerospace vehicle dynamics and optimal control on CasADi.",
        epilog="exit status: 0 done (and verified), 1 numerical failure or failed check, "
               "2 bad input")
    sub = parser.add_subparsers(dest="command", required=True)

    sim = sub.add_parser("simulate", help="simulate a model and check it against a truth")
    sim_sub = sim.add_subparsers(dest="case", required=True)
    tf = sim_sub.add_parser(
        "torque-free", help="torque-free rigid body vs the Jacobi-elliptic solution",
        description="Integrate a torque-free rigid body and compare the body rates with the "
                    "Jacobi-elliptic solution. Exit status 1 when the integrator fails or the "
                    "truth check fails: |w - w_exact| <= atol + rtol |w_exact| at every "
                    "output time and axis (plus a round-off floor 10 eps |w0| (1 + |w0| "
                    "t_final)), or max |w - w_exact| <= tol |w0| with --tol. Fixed-step "
                    "methods (rk4, rk8, lie) do not use rtol/atol, but the check does.")
    tf.set_defaults(_parser=tf)
    tf.add_argument("--inertia", type=_vector((3, 9)), required=True,
                    help="principal moments I1,I2,I3 or 9 matrix entries [kg m^2]")
    tf.add_argument("--w0", type=_vector((3,)), required=True, help="initial body rates [rad/s]")
    tf.add_argument("--t-final", type=_positive, default=50.0, help="final time [s] (50)")
    tf.add_argument("--points", type=_integer(2), default=1001, help="output points (1001)")
    tf.add_argument("--method", default="auto",
                    choices=["auto", "cvodes", *FIXED_STEP], help="integrator (auto)")
    tf.add_argument("--steps", type=_integer(1),
                    help="steps per output interval, fixed-step methods only (1)")
    tf.add_argument("--rtol", type=_positive, default=1e-10,
                    help="relative tolerance; also the accuracy the truth check asks (1e-10)")
    tf.add_argument("--atol", type=_positive, default=1e-12,
                    help="absolute tolerance [rad/s]; also used by the truth check (1e-12)")
    tf.add_argument("--tol", type=_positive,
                    help="truth check: require max |w - w_exact| <= TOL |w0| instead")
    tf.add_argument("--plot", metavar="FILE.png", type=_output_file(PLOT_SUFFIXES),
                    help="save rates, polhode and drift plot (.png, .pdf or .svg)")
    tf.add_argument("--json", metavar="FILE", type=_output_file(),
                    help="write the summary as JSON")
    tf.add_argument("--progress", action="store_true",
                    help="progress lines on stderr (default: only when stderr is a terminal)")
    tf.add_argument("--quiet", action="store_true", help="no progress lines")

    sl = sub.add_parser("slew", help="optimal rigid-body attitude slew (direct collocation)",
                        description="Rest-to-rest optimal slew. Exit status 1 when the solver "
                                    "fails or the answer fails a check (time-optimal: T below "
                                    "the rest-to-rest bound 2 sqrt(J_min theta / |u|max)).")
    sl.set_defaults(_parser=sl)
    sl.add_argument("--inertia", type=_vector((3, 9)), required=True,
                    help="principal moments I1,I2,I3 or 9 matrix entries [kg m^2]")
    sl.add_argument("--u-max", "--umax", dest="umax", type=_vector((1, 3)),
                    help="torque bound [N m], scalar or per axis (time-optimal: 1; "
                         "min-effort: none)")
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

    from problems.stability_cli import add_stability_parser

    add_stability_parser(sub)

    demo = sub.add_parser("demo", help="a short tour of the toolkit's main jobs (< 1 min)")
    demo.set_defaults(_parser=demo)

    bench = sub.add_parser("bench", help="run benchmarks from the bench/ folder")
    bench.set_defaults(_parser=bench)
    bench.add_argument("names", nargs="*", help="benchmark names (default: all), e.g. simulate")
    return parser


# ------------------------------------------------------------------ checks after parsing
def _check_torque_free(p, args) -> None:
    if args.steps is not None and args.method not in FIXED_STEP:
        p.error(f"argument --steps: only with a fixed-step --method ({', '.join(FIXED_STEP)}), "
                f"got --method {args.method}")
    if args.plot and args.json and Path(args.plot).resolve() == Path(args.json).resolve():
        p.error("argument --json: the same file as --plot")


def _check_slew(p, args) -> None:
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
    if args.umax is not None and np.any(args.umax <= 0):
        p.error(f"argument --u-max: expected positive values, got {','.join(map(str, args.umax))}")
    if args.norm_bound and (args.umax is None and args.min_effort is not None):
        p.error("argument --norm-bound: needs --u-max with --min-effort")
    if args.norm_bound and args.umax is not None and args.umax.size != 1:
        p.error("argument --norm-bound: needs a scalar --u-max")
    if args.starts is not None and not args.time_optimal:
        p.error("argument --starts: only with --time-optimal")
    if args.plot and args.json and Path(args.plot).resolve() == Path(args.json).resolve():
        p.error("argument --json: the same file as --plot")


# ------------------------------------------------------------------------------ commands
def _cmd_torque_free(args) -> int:
    from problems.torque_free import torque_free

    progress = Progress("simulate torque-free: steps", enabled=progress_enabled(args))
    try:
        report = torque_free(_inertia(args.inertia), args.w0, t_final=args.t_final,
                             n_points=args.points, method=args.method, rtol=args.rtol,
                             atol=args.atol, steps=args.steps, tol=args.tol,
                             progress=progress if progress.enabled else None)
    finally:
        progress.close()
    print(report)
    write_outputs(report, plot=args.plot, json=args.json)
    if not report.integrator_success:
        print(f"appdyn simulate torque-free: integrator failed: {report.message}",
              file=sys.stderr)
    elif not report.verified:
        print(f"appdyn simulate torque-free: {report.check_text}", file=sys.stderr)
    return 0 if report.success else 1


def _slew_target(args):
    if args.qf is not None:
        return dict(qf=args.qf)
    return dict(axis=args.axis, angle=np.radians(args.angle))


def _target_angle(args) -> float:
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


def _cmd_slew(args) -> int:
    from problems import slew

    if args.umax is None:
        u_max = 1.0 if args.time_optimal else None
    else:
        u_max = float(args.umax[0]) if args.umax.size == 1 else args.umax
    common = dict(u_max=u_max, norm_bound=args.norm_bound, verbose=not args.quiet,
                  **_slew_target(args))
    inertia = _inertia(args.inertia)
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
        bound = rest_to_rest_bound(inertia, _target_angle(args), u_norm)
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
        Path(args.json).write_text(strict_json(data) + "\n")
        print(f"summary written to {args.json}")
    if not success:
        print(f"appdyn slew: failed: {why}", file=sys.stderr)
    return 0 if success else 1


def _cmd_stability(args) -> int:
    from problems.stability_cli import run

    return run(args)


def _cmd_demo(args) -> int:
    from problems.torque_free import torque_free

    print("== 1. Torque-free asymmetric body, 100 s, checked against the exact solution ==")
    report = torque_free([1.0, 2.0, 3.0], [1.0, 0.1, 0.8], t_final=100.0, rtol=1e-12, atol=1e-12)
    print(report)

    from problems import slew

    print("\n== 2. Time-optimal 180 deg slew, J = E, |u_i| <= 1 (Bilimoria & Wie 1993) ==")
    sol = slew.time_optimal(np.eye(3), angle=np.pi, axis=[0, 0, 1], u_max=1.0)
    eig = slew.eigenaxis_time(np.eye(3), np.pi, [0, 0, 1])
    print(slew.format_summary(slew.summary(sol, eigenaxis=eig)))
    print("  (best known T = 3.2430; the eigenaxis maneuver is a local optimum)")

    from problems import stability

    print("\n== 3. Stability: Explorer I's lesson (Kelvin-Tait-Chetaev, seed Sec. 4.5 NOTE) ==")
    # a point mass on a spring along the spin axis, mounted off-axis: it moves with nutation
    for axis, mount, label in (([1, 0, 0], [0, 0.6, 0], "minor"), ([0, 0, 1], [0.6, 0, 0], "major")):
        rigid = stability.spin([2.0, 3.0, 4.5], axis, 4.0)
        damper = stability.PointMassDamper(mass=0.5, stiffness=60.0, damping=0.8,
                                           position=mount, direction=axis)
        damped = stability.spin([2.0, 3.0, 4.5], axis, 4.0, damper=damper)
        print(f"  spin about the {label} axis at 4 rad/s: rigid {rigid.verdict}, "
              f"with a nutation damper {damped.verdict}")
    print("\n== 4. Sleeping top: stability boundary located by bisection (Eq. 4.128) ==")
    res = stability.sweep("heavy_top", "rate", np.linspace(0, 60, 7), axial_inertia=0.002,
                          transverse_inertia=0.005, mass=0.3, length=0.04)
    b = res.boundaries[0]
    print(f"  {b.before} -> {b.after} at w0 = {b.value:.9f} rad/s; closed form "
          f"(2/I1) sqrt(m g l I2) = {2 / 0.002 * np.sqrt(0.3 * 9.80665 * 0.04 * 0.005):.9f}")
    return 0 if report.success and sol.success else 1


def _cmd_bench(args) -> int:
    if not BENCH_DIR.is_dir():
        print(f"appdyn: error: no bench/ folder next to the package ({BENCH_DIR}); "
              "benchmarks run from a source checkout", file=sys.stderr)
        return 2
    available = sorted(p.stem for p in BENCH_DIR.glob("*.py") if not p.stem.startswith("_"))
    names = args.names or available
    unknown = sorted(set(names) - set(available))
    if unknown:
        print(f"appdyn: error: unknown benchmark(s) {unknown}; available: {available}",
              file=sys.stderr)
        return 2
    for name in names:
        print(f"== bench/{name}.py ==", flush=True)
        runpy.run_path(str(BENCH_DIR / f"{name}.py"), run_name="__main__")
    return 0


COMMANDS = {
    ("simulate", "torque-free"): _cmd_torque_free,
    ("slew", None): _cmd_slew,
    **{("stability", case): _cmd_stability
       for case in ("spin", "heavy-top", "projectile", "rotor", "gyrostat", "sweep")},
    ("demo", None): _cmd_demo,
    ("bench", None): _cmd_bench,
}
CHECKS = {("simulate", "torque-free"): _check_torque_free, ("slew", None): _check_slew}


def _one_line(exc) -> str:
    text = " ".join(str(exc).split())
    return (text[:400] + " ...") if len(text) > 400 else text or type(exc).__name__


def _name_option(parser, message) -> str:
    """Library messages name the argument (```rtol` must be ...``): name the option too."""
    m = re.match(r"`(\w+)`", message)
    if m:
        flag = "--" + m.group(1).replace("_", "-")
        if any(flag in a.option_strings for a in parser._actions):
            return f"argument {flag}: {message}"
    return message


def main(argv=None) -> int:
    """Run the command line; returns the exit status (argparse errors raise SystemExit(2)).

    Exit status: 0 done (and verified where the command checks its answer); 1 numerical
    failure, failed verification or failure while computing/writing; 2 bad input (a one-line
    message naming the option, before the computation where it can be checked up front).
    """
    parser = build_parser()
    argv = sys.argv[1:] if argv is None else list(argv)
    args = parser.parse_args(attach_negative_values(parser, argv))
    key = (args.command, getattr(args, "case", None))
    sub = getattr(args, "_parser", parser)
    if key in CHECKS:
        CHECKS[key](sub, args)
    elif args.command == "stability":
        from problems.stability_cli import check_args

        check_args(sub, args)
    handler = COMMANDS[key]
    try:
        return handler(args)
    except ValueError as exc:  # bad input reaching the library (argparse checked the types)
        sub.exit(2, f"{sub.prog}: error: {_name_option(sub, _one_line(exc))}\n")
    except KeyboardInterrupt:
        sub.exit(130, f"{sub.prog}: interrupted\n")
    except BrokenPipeError:  # `appdyn ... | head`: the reader left; stop quietly
        try:
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        except (OSError, ValueError, AttributeError):
            pass
        return 1
    except Exception as exc:  # numerical failure or an unexpected error: no traceback
        if os.environ.get("APPDYN_TRACEBACK"):
            raise
        sub.exit(1, f"{sub.prog}: error: {type(exc).__name__}: {_one_line(exc)} "
                    "(APPDYN_TRACEBACK=1 shows the traceback)\n")


if __name__ == "__main__":
    sys.exit(main())
