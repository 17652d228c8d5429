"""``appdyn cmg ...``: the momentum envelope and steering-law runs of a pyramid CMG cluster
(`dynamics.momentum.momentum_envelope`, `dynamics.momentum.steer`).

    appdyn cmg envelope --beta 54.74 [--h 1] [--directions N] [--plot env.png] [--json F]
    appdyn cmg steer --beta 54.74 --torque 0,0,0.5 --law sr|pinv|gsr --t-final 10 \\
        [--delta0 deg,deg,deg,deg] [--points 201] [--rate-limit DEG/S] [--torque-tol FRAC]
        [--plot F] [--json F]

Angles on the command line are in degrees (``--beta``, ``--delta0``, ``--rate-limit`` in
deg/s). ``envelope`` checks the computed envelope against the pyramid's closed forms
(`pyramid_extent`) and exits 1 when they differ by more than `CHECK_TOL`; ``steer`` exits 1
when the run is not a success (non-finite, above the rate limit, the momentum balance
broken by a step across a singular state, or the commanded torque not delivered within
``--torque-tol``).
"""
from __future__ import annotations

import sys

import numpy as np

from appdyn.problems.cli.common import PLOT_SUFFIXES, finish, same_file, save_figure, write_json
from appdyn.problems.cli.common import integer as _integer
from appdyn.problems.cli.common import number as _number
from appdyn.problems.cli.common import output_file as _output_file
from appdyn.problems.cli.common import positive as _positive
from appdyn.problems.cli.common import vector as _vector

__all__ = ["add_parser", "check", "run", "pyramid_extent", "CHECK_TOL"]

#: Largest difference [N m s] (relative above 1 N m s) between the computed envelope extent
#: and the closed form that ``envelope`` accepts.
CHECK_TOL = 1e-6


def pyramid_extent(beta, h) -> dict:
    """Closed-form envelope extent of a pyramid along x, y, z [N m s]: ``max_H axis.H``.

    The support of the reachable momentum along a unit ``a`` is ``sum_i h_i |a - (a.g_i)
    g_i|``; for the pyramid of `dynamics.momentum.pyramid` this is ``cb (h1 + h3) + h2 +
    h4`` along x, ``h1 + h3 + cb (h2 + h4)`` along y and ``sb (h1 + h2 + h3 + h4)`` along z
    (``2 h (1 + cos beta)`` and ``4 h sin beta`` for equal rotors).

    Parameters
    ----------
    beta : float [rad]
    h : float or array_like, shape (4,) [N m s]

    Returns
    -------
    dict of str to float

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.problems.cli.cmg import pyramid_extent
    >>> {k: round(v, 4) for k, v in pyramid_extent(np.deg2rad(54.74), 1.0).items()}
    {'x': 3.1546, 'y': 3.1546, 'z': 3.2662}
    """
    h1, h2, h3, h4 = np.broadcast_to(np.asarray(h, dtype=float), (4,))
    cb, sb = np.cos(beta), np.sin(beta)
    return {"x": float(cb * (h1 + h3) + h2 + h4), "y": float(h1 + h3 + cb * (h2 + h4)),
            "z": float(sb * (h1 + h2 + h3 + h4))}


def _common(parser, plot_help):
    parser.add_argument("--beta", type=_number, required=True,
                        help="pyramid skew angle [deg], 0 < beta <= 90 (54.74: nearly spherical)")
    parser.add_argument("--h", type=_vector((1, 4)), default=np.ones(1),
                        help="rotor momentum [N m s], one value or four (1)")
    parser.add_argument("--plot", metavar="FILE.png", type=_output_file(PLOT_SUFFIXES),
                        help=plot_help + " (.png, .pdf or .svg)")
    parser.add_argument("--json", metavar="FILE", type=_output_file(), help="write JSON")
    parser.set_defaults(_parser=parser)


def add_parser(subparsers):
    """Add ``cmg`` (cases ``envelope`` and ``steer``) to ``subparsers``."""
    cmg = subparsers.add_parser("cmg", help="CMG pyramid: momentum envelope, steering laws")
    cases = cmg.add_subparsers(dest="cmg_case", required=True)
    env = cases.add_parser(
        "envelope", help="singular surfaces and momentum envelope, checked in closed form",
        description="Sample every singular surface of a four-CMG pyramid, classify the points "
                    "(elliptic / hyperbolic) and compare the envelope extent along x, y, z "
                    "with the closed forms (2h(1 + cos beta) along x, y; 4h sin beta along z). "
                    f"Exit status 1 when they differ by more than {CHECK_TOL:g} N m s.")
    env.add_argument("--directions", type=_integer(50), default=2000,
                     help="singular directions per sign pattern, >= 50 (2000)")
    _common(env, "save the sections and 3D view of the singular surfaces")
    st = cases.add_parser(
        "steer", help="gimbal angles under a commanded torque and a steering law",
        description="Integrate the gimbal angles of a four-CMG pyramid under a constant "
                    "commanded body torque (rk8) and report the singularity measure, gimbal "
                    "rates and torque error. Angles in degrees. Exit status 1 when the run "
                    "fails: non-finite, above --rate-limit, momentum balance broken (the "
                    "rates blew up at a singular state), or the torque not delivered within "
                    "--torque-tol (a singular state, a saturated cluster).")
    st.add_argument("--torque", type=_vector((3,)), required=True,
                    help="commanded body torque T1,T2,T3 [N m] (the cluster momentum changes "
                         "by -torque per second)")
    st.add_argument("--law", choices=["sr", "pinv", "gsr"], default="sr",
                    help="steering law: singularity-robust, pseudo-inverse, generalized SR (sr)")
    st.add_argument("--t-final", type=_positive, default=10.0, help="final time [s] (10)")
    st.add_argument("--delta0", type=_vector((4,)), help="initial gimbal angles [deg] (0,0,0,0)")
    st.add_argument("--points", type=_integer(2), default=201, help="output points (201)")
    st.add_argument("--steps", type=_integer(1), default=20,
                    help="rk8 steps per output interval (20)")
    st.add_argument("--rate-limit", type=_positive,
                    help="largest gimbal rate [deg/s]; a run above it fails (no limit)")
    st.add_argument("--torque-tol", type=float, default=0.01, metavar="FRAC",
                    help="largest torque error, as a fraction of |torque|; a run beyond it "
                         "fails (0.01; inf accepts any)")
    _common(st, "save angles, measure, rates and torque error against time")
    return cmg


def check(parser, args) -> None:
    """Checks across options, as argparse errors on ``parser`` (exit status 2)."""
    if not 0 < args.beta <= 90:
        parser.error(f"argument --beta: expected 0 < beta <= 90 [deg], got {args.beta:g}")
    if np.any(args.h <= 0):
        parser.error(f"argument --h: rotor momenta must be positive, got {args.h.tolist()}")
    if same_file(args.plot, args.json):
        parser.error("argument --json: the same file as --plot")


def _geometry(args):
    from appdyn.dynamics.momentum import pyramid

    return pyramid(np.radians(args.beta), args.h if args.h.size == 4 else float(args.h[0]))


def _envelope(args) -> int:
    from appdyn.dynamics.momentum import momentum_envelope

    env = momentum_envelope(_geometry(args), directions=args.directions)
    computed, closed = env.extent, pyramid_extent(np.radians(args.beta), args.h)
    equal = args.h.size == 1 or np.all(args.h == args.h[0])
    formulas = ({"x": "2 h (1 + cos beta)", "y": "2 h (1 + cos beta)", "z": "4 h sin beta"}
                if equal else {"x": "cos beta (h1 + h3) + h2 + h4",
                               "y": "h1 + h3 + cos beta (h2 + h4)",
                               "z": "sin beta (h1 + h2 + h3 + h4)"})
    errors = {a: abs(computed[a] - closed[a]) for a in "xyz"}
    passed = all(errors[a] <= CHECK_TOL * max(1.0, closed[a]) for a in "xyz")
    print(env)
    print(f"Closed-form check (pyramid, beta = {args.beta:g} deg, tolerance {CHECK_TOL:g}):")
    print(f"  {'axis':<6}{'max axis.H [N m s]':>20}{'closed form':>15}{'error':>11}  formula")
    for a in "xyz":
        print(f"  {a:<6}{computed[a]:>20.12f}{closed[a]:>15.12f}{errors[a]:>11.1e}  {formulas[a]}")
    print(f"  check {'passed' if passed else 'FAILED'}")
    if args.plot:
        save_figure(env.plot(), args.plot)
        print(f"plot written to {args.plot}")
    if args.json:
        check_data = {"tolerance": CHECK_TOL, "passed": passed, "computed": computed,
                      "closed_form": closed, "error": errors}
        write_json({**env.to_dict(), "beta_deg": args.beta, "closed_form_check": check_data},
                   args.json)
        print(f"report written to {args.json}")
    if not passed:
        print(f"appdyn cmg envelope: closed-form check failed: errors {errors}", file=sys.stderr)
    return 0 if passed else 1


def _steer(args) -> int:
    from appdyn.dynamics.momentum import steer

    t = np.linspace(0.0, args.t_final, args.points)
    res = steer(_geometry(args), args.torque, t, law=args.law,
                delta0=None if args.delta0 is None else np.radians(args.delta0),
                steps=args.steps,
                rate_limit=None if args.rate_limit is None else np.radians(args.rate_limit),
                torque_tol=args.torque_tol)
    return finish(res, "cmg steer", plot=args.plot, json=args.json)


def run(args) -> int:
    """Execute parsed ``cmg`` arguments: print the report, write ``--plot``/``--json``;
    0 when verified (envelope: closed forms; steer: success), else 1."""
    return _envelope(args) if args.cmg_case == "envelope" else _steer(args)
