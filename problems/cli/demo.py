"""``appdyn demo``: a short tour of the toolkit's main jobs, each checked against a truth."""
from __future__ import annotations

import numpy as np

__all__ = ["add_parser", "check", "run"]


def add_parser(subparsers):
    """Add ``demo`` to ``subparsers``."""
    demo = subparsers.add_parser("demo", help="a short tour of the toolkit's main jobs (< 1 min)")
    demo.set_defaults(_parser=demo)
    return demo


def check(parser, args) -> None:
    """Nothing to check across options."""


def run(args) -> int:
    """Run the tour; 0 when the simulation and the slew are verified, else 1."""
    from appdyn.problems.torque_free import torque_free

    print("== 1. Torque-free asymmetric body, 100 s, checked against the exact solution ==")
    report = torque_free([1.0, 2.0, 3.0], [1.0, 0.1, 0.8], t_final=100.0, rtol=1e-12, atol=1e-12)
    print(report)

    from appdyn.problems import slew

    print("\n== 2. Time-optimal 180 deg slew, J = E, |u_i| <= 1 (Bilimoria & Wie 1993) ==")
    sol = slew.time_optimal(np.eye(3), angle=np.pi, axis=[0, 0, 1], u_max=1.0)
    eig = slew.eigenaxis_time(np.eye(3), np.pi, [0, 0, 1])
    print(slew.format_summary(slew.summary(sol, eigenaxis=eig)))
    print("  (best known T = 3.2430; the eigenaxis maneuver is a local optimum)")

    from appdyn.problems import stability

    print("\n== 3. Stability: Explorer I's lesson (Kelvin-Tait-Chetaev; Rheinfurth & Wilson, "
          "NASA RP-1262, Sec. 4.5 NOTE) ==")
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
