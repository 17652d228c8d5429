"""``appdyn ascent ...``: launch-vehicle ascent trajectories (`problems.ascent`).

    appdyn ascent delta3 [--N N] [--degree D] [--refine-tol TOL | --no-refine]
                         [--plot FILE.png] [--json FILE]

``delta3`` solves the four-phase Delta III ascent to GTO (`problems.ascent.delta3_ascent`:
maximum final mass, multi-phase direct collocation with per-phase mesh refinement), prints
the phase table (times, masses, altitude and speed at each staging) and the final orbit
recomputed from the final state, and plots altitude, speed, mass, thrust direction, dynamic
pressure and flight-path angle against time with the phase boundaries marked. Exit status 0
when the solution is verified (NLP solved, final orbit and re-simulation within tolerance),
1 when not, 2 for bad options.
"""
from __future__ import annotations

import argparse

from appdyn.problems.cli.common import PLOT_SUFFIXES, finish, integer, output_file, positive, same_file

__all__ = ["add_parser", "check", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Add ``ascent`` (with its case ``delta3``) to ``subparsers``."""
    ascent = subparsers.add_parser("ascent", help="launch-vehicle ascent trajectories",
                                   description="Optimal ascent trajectories (multi-phase "
                                               "direct collocation).")
    ascent.set_defaults(_parser=ascent)
    cases = ascent.add_subparsers(dest="case", required=True)
    d3 = cases.add_parser("delta3", help="Delta III four-phase ascent to GTO",
                          description="The Delta III-class ascent (Benson 2005, Betts 2010, "
                                      "GPOPS-II): six + three solid boosters, two stages, "
                                      "maximum mass in the target orbit.")
    d3.set_defaults(_parser=d3)
    d3.add_argument("--N", type=integer(2), default=5, help="mesh intervals per phase (5)")
    d3.add_argument("--degree", type=integer(1), default=5, help="Radau degree (5)")
    d3.add_argument("--refine-tol", type=positive, default=1e-9, metavar="TOL",
                    help="per-phase mesh refinement target (1e-9)")
    d3.add_argument("--no-refine", action="store_true", help="solve on the initial mesh only")
    d3.add_argument("--plot", metavar="FILE.png", type=output_file(PLOT_SUFFIXES),
                    help="altitude, speed, mass, thrust direction, dynamic pressure vs time")
    d3.add_argument("--json", metavar="FILE", type=output_file(), help="the result as JSON")
    return ascent


def check(parser, args) -> None:
    """Output files must differ."""
    if same_file(args.plot, args.json):
        parser.error("argument --json: the same file as --plot")


def run(args) -> int:
    """Solve, print the phase table, write ``--plot``/``--json``; 0 when verified."""
    from appdyn.problems.ascent import delta3_ascent

    result = delta3_ascent(N=args.N, degree=args.degree,
                           refine_tol=None if args.no_refine else args.refine_tol)
    return finish(result, "ascent delta3", plot=args.plot, json=args.json)
