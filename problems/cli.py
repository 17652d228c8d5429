"""The ``appdyn`` command line.

    appdyn simulate torque-free --inertia 1,2,3 --w0 1,0.1,0.8 --t-final 50 [--plot F.png]
    appdyn slew --inertia 1,1,1 --umax 1 --axis 0,0,1 --angle 180 --time-optimal
    appdyn stability spin|heavy-top|projectile|rotor|gyrostat|sweep ... [--json F] [--plot F.png]
    appdyn demo
    appdyn bench [NAME ...]

Library code never prints; this module is the one place that does.
"""
from __future__ import annotations

import argparse
import runpy
import sys
from pathlib import Path

import numpy as np

from problems.cli_common import positive as _positive
from problems.cli_common import vector as _vector
from problems.cli_common import write_outputs

__all__ = ["main", "build_parser"]

BENCH_DIR = Path(__file__).resolve().parents[1] / "bench"


def _inertia(values):
    return values if values.size == 3 else values.reshape(3, 3)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="appdyn", description="Aerospace vehicle dynamics and optimal control on CasADi."
    )
    sub = parser.add_subparsers(dest="command", required=True)

    sim = sub.add_parser("simulate", help="simulate a model and check it against a truth")
    sim_sub = sim.add_subparsers(dest="case", required=True)
    tf = sim_sub.add_parser(
        "torque-free", help="torque-free rigid body vs the Jacobi-elliptic solution"
    )
    tf.add_argument("--inertia", type=_vector((3, 9)), required=True,
                    help="principal moments I1,I2,I3 or 9 matrix entries [kg m^2]")
    tf.add_argument("--w0", type=_vector((3,)), required=True, help="initial body rates [rad/s]")
    tf.add_argument("--t-final", type=_positive, default=50.0, help="final time [s] (50)")
    tf.add_argument("--points", type=int, default=1001, help="output points (1001)")
    tf.add_argument("--method", default="auto",
                    choices=["auto", "cvodes", "rk4", "rk8", "lie"], help="integrator (auto)")
    tf.add_argument("--rtol", type=_positive, default=1e-10, help="relative tolerance (1e-10)")
    tf.add_argument("--atol", type=_positive, default=1e-12, help="absolute tolerance (1e-12)")
    tf.add_argument("--plot", metavar="FILE.png", help="save rates, polhode and drift plot")
    tf.add_argument("--json", metavar="FILE", help="write the summary as JSON")

    sl = sub.add_parser("slew", help="optimal rigid-body attitude slew (direct collocation)")
    sl.add_argument("--inertia", type=_vector((3, 9)), required=True,
                    help="principal moments I1,I2,I3 or 9 matrix entries [kg m^2]")
    sl.add_argument("--umax", type=_vector((1, 3)),
                    help="torque bound [N m], scalar or per axis (time-optimal: 1; "
                         "min-effort: none)")
    sl.add_argument("--norm-bound", action="store_true", help="bound |u| instead of each axis")
    sl.add_argument("--axis", type=_vector((3,)), help="rotation axis (body frame)")
    sl.add_argument("--angle", type=float, help="rotation angle [deg]")
    sl.add_argument("--qf", type=_vector((4,)), help="target quaternion (scalar-last), instead of axis/angle")
    kind = sl.add_mutually_exclusive_group(required=True)
    kind.add_argument("--time-optimal", action="store_true", help="minimize the maneuver time")
    kind.add_argument("--min-effort", type=_positive, metavar="T",
                      help="minimize 1/2 int |u|^2 dt over the given time T [s]")
    sl.add_argument("--starts", type=int, default=3, help="multi-start count, time-optimal (3)")
    sl.add_argument("--plot", metavar="FILE.png", help="save quaternion, rates, torques, path")
    sl.add_argument("--json", metavar="FILE", help="write the summary as JSON")
    sl.add_argument("--quiet", action="store_true", help="no solver progress lines")

    from problems.stability_cli import add_stability_parser

    add_stability_parser(sub)

    sub.add_parser("demo", help="a short tour of the toolkit's main jobs (< 1 min)")

    bench = sub.add_parser("bench", help="run benchmarks from the bench/ folder")
    bench.add_argument("names", nargs="*", help="benchmark names (default: all), e.g. simulate")
    return parser


def _cmd_torque_free(args) -> int:
    from problems.torque_free import torque_free

    report = torque_free(_inertia(args.inertia), args.w0, t_final=args.t_final,
                         n_points=args.points, method=args.method, rtol=args.rtol,
                         atol=args.atol)
    print(report)
    write_outputs(report, plot=args.plot, json=args.json)
    return 0 if report.success else 1


def _slew_target(args):
    if args.qf is not None:
        return dict(qf=args.qf)
    if args.axis is None or args.angle is None:
        raise ValueError("`slew` needs --axis and --angle [deg], or --qf")
    return dict(axis=args.axis, angle=np.radians(args.angle))


def _cmd_slew(args) -> int:
    import json

    from problems import slew

    if args.umax is None:
        u_max = 1.0 if args.time_optimal else None
    else:
        u_max = float(args.umax[0]) if args.umax.size == 1 else args.umax
    common = dict(u_max=u_max, norm_bound=args.norm_bound, verbose=not args.quiet,
                  **_slew_target(args))
    inertia = _inertia(args.inertia)
    eig = None
    if args.time_optimal:
        sol = slew.time_optimal(inertia, starts=args.starts, **common)
        if args.axis is not None and not args.norm_bound:
            try:
                eig = slew.eigenaxis_time(inertia, np.radians(args.angle), args.axis, u_max)
            except ValueError:
                eig = None  # not a principal axis: no closed-form eigenaxis time
    else:
        sol = slew.min_effort(inertia, args.min_effort, **common)
    data = slew.summary(sol, eigenaxis=eig)
    print(slew.format_summary(data))
    if args.plot and sol.success:
        slew.plot_slew(sol, args.plot)
        print(f"plot written to {args.plot}")
    if args.json:
        Path(args.json).write_text(json.dumps(data, indent=2))
        print(f"summary written to {args.json}")
    return 0 if sol.success else 1


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


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    handler = COMMANDS[(args.command, getattr(args, "case", None))]
    try:
        return handler(args)
    except ValueError as exc:  # bad input reaching the library: report it like argparse does
        parser.exit(2, f"appdyn: error: {exc}\n")


if __name__ == "__main__":
    sys.exit(main())
