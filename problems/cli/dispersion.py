"""``appdyn dispersion ...``: Monte Carlo dispersions (`problems.dispersion`).

    appdyn dispersion spin [--samples N] [--seed S] [--spin-rate W] [--duration T]
                           [--workers N | --scheduler ADDRESS] [--plot FILE.png] [--json FILE]

``spin`` runs `problems.dispersion.nutation_spread`: a spinning spacecraft with uncertain
inertias (``I_t ~ N(1000, 20)``, ``I_a ~ N(1500, 30)`` kg m^2) and transverse rate
(``N(0.02, 0.004)`` rad/s), and prints the statistics of the nutation angle (each sample
checked against the axisymmetric closed form). Progress goes to stderr (``--progress``, or
when stderr is a terminal; ``--quiet`` silences it). Exit status 0 when every sample
succeeded, 1 when some failed, 2 for bad options.
"""
from __future__ import annotations

import argparse

from appdyn.problems.cli.common import (Progress, add_executor_options, executor_from, finish,
                                 integer, output_file, positive, progress_enabled, same_file,
                                 PLOT_SUFFIXES)

__all__ = ["add_parser", "check", "run"]


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Add ``dispersion`` (with its case ``spin``) to ``subparsers``."""
    disp = subparsers.add_parser("dispersion", help="Monte Carlo dispersions",
                                 description="Run a model over drawn initial conditions and "
                                             "parameters and report the spread of its outputs.")
    disp.set_defaults(_parser=disp)
    cases = disp.add_subparsers(dest="case", required=True)
    spin = cases.add_parser("spin", help="nutation spread of a spinning spacecraft",
                            description="Nutation angle of a spinning spacecraft under inertia "
                                        "and transverse-rate uncertainty (problems.dispersion."
                                        "nutation_spread), every sample checked against the "
                                        "axisymmetric closed form.")
    spin.set_defaults(_parser=spin)
    spin.add_argument("--samples", type=integer(1), default=200, help="number of runs (200)")
    spin.add_argument("--seed", type=integer(0), default=0, help="seed of the draws (0)")
    spin.add_argument("--spin-rate", type=positive, default=1.0, metavar="RAD_S",
                      help="spin rate about the symmetry axis [rad/s] (1)")
    spin.add_argument("--duration", type=positive, default=30.0, metavar="S",
                      help="simulated time [s] (30)")
    add_executor_options(spin)
    spin.add_argument("--plot", metavar="FILE.png", type=output_file(PLOT_SUFFIXES),
                      help="histograms and the envelope of the nutation angle")
    spin.add_argument("--json", metavar="FILE", type=output_file(), help="the statistics as JSON")
    spin.add_argument("--progress", action="store_true",
                      help="progress lines on stderr (default: only when stderr is a terminal)")
    spin.add_argument("--quiet", action="store_true", help="no progress lines")
    return disp


def check(parser, args) -> None:
    """Output files must differ."""
    if same_file(args.plot, args.json):
        parser.error("argument --json: the same file as --plot")


def run(args) -> int:
    """Run the dispersion, print its statistics, write ``--plot``/``--json``; 0 when every
    sample succeeded."""
    from appdyn.problems.dispersion import nutation_spread

    progress = Progress(f"dispersion spin ({args.samples} samples)", enabled=progress_enabled(args))
    try:
        with executor_from(args) as executor:
            result = nutation_spread(args.samples, args.seed, spin_rate=args.spin_rate,
                                     duration=args.duration, executor=executor,
                                     progress=progress if progress.enabled else None)
    finally:
        progress.close()
    return finish(result, "dispersion spin", plot=args.plot, json=args.json)
