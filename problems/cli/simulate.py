"""``appdyn simulate torque-free``: integrate a torque-free rigid body and check it against
the Jacobi-elliptic solution (`problems.torque_free`)."""
from __future__ import annotations

import sys

from problems.cli.common import PLOT_SUFFIXES, Progress, inertia_matrix, progress_enabled
from problems.cli.common import integer as _integer
from problems.cli.common import output_file as _output_file
from problems.cli.common import positive as _positive
from problems.cli.common import same_file
from problems.cli.common import vector as _vector
from problems.cli.common import write_outputs

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
    return sim


def check(parser, args) -> None:
    """Checks across options, as argparse errors on ``parser`` (exit status 2)."""
    if args.steps is not None and args.method not in FIXED_STEP:
        parser.error(f"argument --steps: only with a fixed-step --method "
                     f"({', '.join(FIXED_STEP)}), got --method {args.method}")
    if same_file(args.plot, args.json):
        parser.error("argument --json: the same file as --plot")


def run(args) -> int:
    """Simulate, print the report, write ``--plot``/``--json``; 0 when verified, else 1."""
    from problems.torque_free import torque_free

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
