"""``appdyn simulate torque-free``: integrate a torque-free rigid body and check it against
the Jacobi-elliptic solution (`problems.torque_free`). ``appdyn simulate launch-vehicle``: the
launch-vehicle autopilot's response to an attitude error and a wind gust
(`problems.stability.launch_vehicle_response`)."""
from __future__ import annotations

import sys

from problems.cli.common import PLOT_SUFFIXES, Progress, inertia_matrix, progress_enabled
from problems.cli.common import integer as _integer
from problems.cli.common import number as _number
from problems.cli.common import output_file as _output_file
from problems.cli.common import positive as _positive
from problems.cli.common import same_file
from problems.cli.common import vector as _vector
from problems.cli.common import write_outputs
from problems.cli.stability import (add_launch_vehicle_options, call_naming_parts, check_flight,
                                   launch_vehicle_kwargs)

__all__ = ["add_parser", "check", "run", "FIXED_STEP"]

#: methods that take ``--steps``
FIXED_STEP = ("rk4", "rk8", "lie")


def add_parser(subparsers):
    """Add ``simulate`` (with its case ``torque-free``) to ``subparsers``."""
    sim = subparsers.add_parser("simulate", help="simulate a model and check it against a truth")
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
    _add_launch_vehicle(sim_sub)
    return sim


def _add_launch_vehicle(sim_sub) -> None:
    lv = sim_sub.add_parser(
        "launch-vehicle", help="launch-vehicle autopilot: response to an attitude error and a gust",
        description="Simulate the launch vehicle with its attitude/rate autopilot (RP-1262 "
                    "Sec. 5.4) from an attitude error --psi0, optionally through a '1 - cosine' "
                    "lateral gust (needs --aero): attitude, deflection, slosh, bending. Exit "
                    "status 1 when the integrator fails or cannot verify its tolerance.")
    lv.set_defaults(_parser=lv)
    add_launch_vehicle_options(lv)
    lv.add_argument("--deflection-limit", type=_positive, metavar="DEG",
                    help="actuator deflection limit +-DEG, with --actuator")
    lv.add_argument("--rate-limit", type=_positive, metavar="DEG_S",
                    help="actuator rate limit [deg/s], with --actuator")
    lv.add_argument("--psi0", type=_number, default=0.0, metavar="DEG",
                    help="initial attitude error [deg] (0)")
    lv.add_argument("--gust", type=_number, metavar="SPEED",
                    help="peak lateral wind of a '1 - cosine' gust [m/s], with --aero")
    lv.add_argument("--gust-start", type=_number, metavar="T", help="gust start [s] (1)")
    lv.add_argument("--gust-duration", type=_positive, metavar="T",
                    help="gust duration [s] (2)")
    lv.add_argument("--t-final", type=_positive, default=10.0, help="final time [s] (10)")
    lv.add_argument("--points", type=_integer(2), default=1001, help="output points (1001)")
    lv.add_argument("--rtol", type=_positive, default=1e-8, help="relative tolerance (1e-8)")
    lv.add_argument("--plot", metavar="FILE.png", type=_output_file(PLOT_SUFFIXES),
                    help="save attitude, deflection, slosh, bending and gust plots "
                         "(.png, .pdf or .svg)")
    lv.add_argument("--json", metavar="FILE", type=_output_file(),
                    help="write the summary and time histories as JSON")
    lv.add_argument("--progress", action="store_true",
                    help="progress lines on stderr (default: only when stderr is a terminal)")
    lv.add_argument("--quiet", action="store_true", help="no progress lines")


def _check_launch_vehicle(parser, args) -> None:
    check_flight(parser, args)
    for flag in ("deflection_limit", "rate_limit"):
        if getattr(args, flag) is not None and args.actuator is None:
            parser.error(f"argument --{flag.replace('_', '-')}: only with --actuator")
    if args.gust is not None and args.aero is None:
        parser.error("argument --gust: needs --aero (the wind acts through the angle of attack)")
    for flag in ("gust_start", "gust_duration"):
        if getattr(args, flag) is not None and args.gust is None:
            parser.error(f"argument --{flag.replace('_', '-')}: only with --gust")
    if args.gust_start is not None and args.gust_start < 0:
        parser.error(f"argument --gust-start: expected a number >= 0, got {args.gust_start}")
    if args.psi0 == 0 and not args.gust:
        parser.error("argument --psi0: nothing excites the vehicle; give --psi0 or --gust")


def check(parser, args) -> None:
    """Checks across options, as argparse errors on ``parser`` (exit status 2)."""
    if args.case == "launch-vehicle":
        _check_launch_vehicle(parser, args)
    elif args.steps is not None and args.method not in FIXED_STEP:
        parser.error(f"argument --steps: only with a fixed-step --method "
                     f"({', '.join(FIXED_STEP)}), got --method {args.method}")
    if same_file(args.plot, args.json):
        parser.error("argument --json: the same file as --plot")


def _run_launch_vehicle(args) -> int:
    import math
    from dataclasses import replace

    from problems.stability import launch_vehicle_response

    kwargs = launch_vehicle_kwargs(args)
    if args.deflection_limit or args.rate_limit:  # degrees on the command line
        limit, rate = (None if v is None else math.radians(v)
                       for v in (args.deflection_limit, args.rate_limit))
        kwargs["actuator"] = replace(kwargs["actuator"], rate_limit=rate,
                                     deflection_limits=None if limit is None else (-limit, limit))
    progress = Progress("simulate launch-vehicle: steps", enabled=progress_enabled(args))
    try:
        result = call_naming_parts(
            launch_vehicle_response, **kwargs, psi0=math.radians(args.psi0),
            gust_speed=args.gust or 0.0,
            gust_start=1.0 if args.gust_start is None else args.gust_start,
            gust_duration=args.gust_duration or 2.0, t_final=args.t_final, points=args.points,
            rtol=args.rtol, progress=progress if progress.enabled else None)
    finally:
        progress.close()
    print(result)
    write_outputs(result, plot=args.plot, json=args.json)
    if not result.success:
        print(f"appdyn simulate launch-vehicle: {result.message}", file=sys.stderr)
    return 0 if result.success else 1


def run(args) -> int:
    """Simulate, print the report, write ``--plot``/``--json``; 0 when verified, else 1."""
    from problems.torque_free import torque_free

    if args.case == "launch-vehicle":
        return _run_launch_vehicle(args)

    progress = Progress("simulate torque-free: steps", enabled=progress_enabled(args))
    try:
        report = torque_free(inertia_matrix(args.inertia), args.w0, t_final=args.t_final,
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
