"""``appdyn stability ...``: the command-line face of `problems.stability`.

    appdyn stability spin --inertia 1,2,3 --axis 1,0,0 --rate 10 [--damper ...] \\
        [--json F] [--plot F]
    appdyn stability heavy-top --axial-inertia 0.002 --transverse-inertia 0.005 --mass 0.3 \\
        --length 0.04 --rate 40
    appdyn stability projectile --axial-inertia ... --dynamic-pressure ... --area ... \\
        --cn-alpha ... --cp-offset ... --rate ...
    appdyn stability rotor --axial-inertia ... --transverse-inertia ... --stiffness ... \\
        --bearing-distance ... --rate ... [--internal-damping D]
    appdyn stability gyrostat --inertia 3,4,4 --axis 1,0,0 --rate 2 --wheel-momentum 3 \\
        [--wheel-inertia J] [--damper ...] [--damper-on platform|rotor]
    appdyn stability launch-vehicle --thrust 2e6 --inertia 4e7 --arm 20 --mass 1e5 \\
        --k-psi 2 --k-psidot 2 [--aero Q,S,CNA,LCP --velocity V] [--slosh KEY=V,...] \\
        [--bending KEY=V,...] [--actuator TAU]
    appdyn stability shaken-pendulum --mass 1 --inertia 0.0208 --length 0.25 --amp-y 0.02 \\
        --freq 200 [--position hanging|inverted] [--damping C] [--amp-x A] [--gravity G]
    appdyn stability conical-pendulum --mass 1 --length 1 --cone-angle 60 [--inertia I] \\
        [--sequence 3-2-1|3-1-3] [--gravity G]
    appdyn stability sweep CASE --parameter NAME --values START:STOP:NUM  [CASE options]
                           [--workers N | --scheduler ADDRESS]

``--damper`` takes a kind and ``key=value`` items (vectors comma-separated):

    --damper point mass=0.05 stiffness=20 damping=0.3 position=0,0.5,0 direction=1,0,0 [body_mass=M]
    --damper sphere inertia=0.05 damping=0.02

``launch-vehicle`` parts: ``--aero`` dynamic pressure [Pa], reference area [m^2], normal-force
slope [1/rad], centre of pressure ahead of the mass centre [m]; ``--slosh`` and ``--bending``
take the fields of `dynamics.launch_vehicle.Slosh` / `~dynamics.launch_vehicle.Bending` as
``key=value`` items joined by commas; ``--actuator`` the time constant [s].

``conical-pendulum --cone-angle`` is in degrees (also when swept: ``--values`` in degrees);
the report shows the library's radians.

`add_parser` adds the ``stability`` command to an argparse sub-parser group (its cases land
in ``args.case``); `check` checks across options; `run` executes parsed arguments; `main` is
a standalone entry taking the arguments after ``stability`` (from a shell:
``python -m appdyn.problems.cli stability spin ...``). Case names are mapped to
the library's functions by `problems.stability.resolve_case` (its one alias table). This
module prints; the library does not.
"""
from __future__ import annotations

import argparse
import re
import sys

import numpy as np

from appdyn.problems.cli.common import Progress, attach_negative_values, inertia_matrix
from appdyn.problems.cli.common import number as _number
from appdyn.problems.cli.common import output_file as _output_file
from appdyn.problems.cli.common import positive as _positive
from appdyn.problems.cli.common import (add_executor_options, executor_from, progress_enabled, same_file,
                                 save_figure)
from appdyn.problems.cli.common import vector as _floats
from appdyn.problems.cli.common import finish

__all__ = ["add_parser", "check", "run", "main", "parse_damper", "sweep_parameters",
           "add_launch_vehicle_options", "launch_vehicle_kwargs", "check_flight",
           "call_naming_parts"]


def parse_damper(tokens):
    """``['point', 'mass=0.05', ...]`` -> `PointMassDamper` / `SphericalDamper`.

    Raises
    ------
    ValueError
        Naming ``--damper`` for an unknown kind, key or malformed item.
    """
    if not tokens:
        raise ValueError("`--damper` needs a kind: 'point' or 'sphere'")
    kind, items = tokens[0].lower(), tokens[1:]
    fields = {"point": ("mass", "stiffness", "damping", "position", "direction", "body_mass"),
              "sphere": ("inertia", "damping")}
    if kind not in fields:
        raise ValueError(f"`--damper` kind must be 'point' or 'sphere', got {tokens[0]!r}")
    kwargs = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or key not in fields[kind]:
            raise ValueError(f"`--damper {kind}` items are key=value with keys "
                             f"{', '.join(fields[kind])}; got {item!r}")
        try:
            nums = [float(v) for v in value.split(",") if v != ""]
        except ValueError:
            raise ValueError(f"`--damper` {key} must be numbers, got {value!r}") from None
        kwargs[key] = tuple(nums) if key in ("position", "direction") else (
            nums[0] if len(nums) == 1 else value)
    from appdyn.dynamics.spinning import PointMassDamper, SphericalDamper

    try:
        return PointMassDamper(**kwargs) if kind == "point" else SphericalDamper(**kwargs)
    except TypeError as exc:
        needed = fields[kind][:3] if kind == "point" else fields[kind]
        raise ValueError(f"`--damper {kind}` needs {', '.join(needed)}: {exc}") from None


def _argument_type(build):
    """argparse type calling ``build(text)``; its ValueError/TypeError is the message."""
    def parse(text):
        try:
            return build(text)
        except (TypeError, ValueError) as exc:
            raise argparse.ArgumentTypeError(" ".join(str(exc).split())) from None
    return parse


def _items(fields):
    """``key=value,...`` -> dict of floats, keys among ``fields``."""
    def parse(text):
        items = [item.partition("=") for item in text.replace(" ", "").split(",")]
        bad = [k + sep + v for k, sep, v in items if not sep or k not in fields]
        if bad:
            raise ValueError(f"expected key=value items joined by commas, keys "
                             f"{', '.join(fields)}; got {bad[0]!r}")
        return {k: _number(v) for k, _, v in items}
    return parse


def _part(name):
    """The launch-vehicle part class ``name``, imported when an option value is parsed (not
    when the parser is built: ``appdyn --help`` stays light)."""
    import importlib

    launch_vehicle = importlib.import_module("appdyn.dynamics.launch_vehicle")

    return getattr(launch_vehicle, name)


def _launch_vehicle_parts():
    slosh = _items(("mass", "hinge", "length", "frequency", "damping_ratio"))
    bending = _items(("frequency", "generalized_mass", "damping_ratio", "slope_sensor",
                      "deflection_gimbal", "slope_gimbal"))
    return [
        ("velocity", "--velocity", _number, "flight speed along X [m/s], with --aero"),
        ("aero", "--aero", _argument_type(lambda text: _part("Aero")(*_floats((4,))(text))),
         "dynamic pressure [Pa], reference area [m^2], normal-force slope [1/rad], centre "
         "of pressure ahead of the mass centre [m]"),
        ("slosh", "--slosh", _argument_type(lambda text: _part("Slosh")(**slosh(text))),
         "slosh mode: mass=KG,hinge=M and length=M (pendulum) or frequency=RAD_S "
         "(spring-mass), optional damping_ratio=Z"),
        ("bending", "--bending", _argument_type(lambda text: _part("Bending")(**bending(text))),
         "bending mode: frequency=RAD_S,generalized_mass=KG, optional damping_ratio, "
         "slope_sensor [rad/m], deflection_gimbal [-], slope_gimbal [rad/m]"),
        ("actuator", "--actuator", _argument_type(lambda text: _part("Actuator")(_positive(text))),
         "gimbal actuator time constant [s]"),
    ]


_METAVARS = {"aero": "Q,S,CNA,LCP", "slosh": "KEY=V,...", "bending": "KEY=V,...",
             "actuator": "TAU"}


# (dest, flags, type, help); required in a plain case, optional under 'sweep'
_OPTIONS = {
    "spin": [
        ("inertia", "--inertia", _floats((3, 9)), "principal moments or 9 matrix entries [kg m^2]"),
        ("axis", "--axis", _floats((3,)), "spin axis, body frame (a principal axis)"),
        ("rate", "--rate", _number, "spin rate [rad/s]"),
    ],
    "heavy-top": [
        ("axial_inertia", "--axial-inertia", _number, "I1 about the symmetry axis [kg m^2]"),
        ("transverse_inertia", "--transverse-inertia", _number,
         "I2 about a transverse axis through the pivot [kg m^2]"),
        ("mass", "--mass", _number, "mass [kg]"),
        ("length", "--length", _number, "pivot to mass center [m]"),
        ("rate", "--rate", _number, "spin rate [rad/s]"),
    ],
    "projectile": [
        ("axial_inertia", "--axial-inertia", _number, "I1 [kg m^2]"),
        ("transverse_inertia", "--transverse-inertia", _number,
         "I2 about the mass center [kg m^2]"),
        ("rate", "--rate", _number, "spin rate [rad/s]"),
        ("dynamic_pressure", "--dynamic-pressure", _number, "q [Pa]"),
        ("area", "--area", _number, "reference area S [m^2]"),
        ("cn_alpha", "--cn-alpha", _number, "normal-force slope C_N_alpha [1/rad]"),
        ("cp_offset", "--cp-offset", _number, "center of pressure ahead of the mass center [m]"),
    ],
    "rotor": [
        ("axial_inertia", "--axial-inertia", _number, "polar moment I1 [kg m^2]"),
        ("transverse_inertia", "--transverse-inertia", _number, "transverse moment I2 [kg m^2]"),
        ("stiffness", "--stiffness", _number, "bearing stiffness k [N/m]"),
        ("bearing_distance", "--bearing-distance", _number, "mass center to bearing l [m]"),
        ("rate", "--rate", _number, "spin rate [rad/s]"),
    ],
    "gyrostat": [
        ("inertia", "--inertia", _floats((3, 9)), "platform + wheel (locked) [kg m^2]"),
        ("axis", "--axis", _floats((3,)), "wheel and spin axis, body frame"),
        ("rate", "--rate", _number, "platform spin rate [rad/s]"),
        ("wheel_momentum", "--wheel-momentum", _number,
         "wheel momentum relative to the platform [N m s]"),
    ],
    "launch-vehicle": [
        ("thrust", "--thrust", _number, "thrust F [N]"),
        ("inertia", "--inertia", _number, "pitch/yaw moment of inertia I [kg m^2]"),
        ("arm", "--arm", _number, "mass centre to the gimbal l [m]"),
        ("mass", "--mass", _number, "mass m [kg]"),
        ("k_psi", "--k-psi", _number, "attitude gain [rad/rad]"),
        ("k_psidot", "--k-psidot", _number, "rate gain [rad/(rad/s)]"),
    ],
    "shaken-pendulum": [
        ("mass", "--mass", _number, "mass m [kg]"),
        ("inertia", "--inertia", _number, "central moment about the hinge axis [kg m^2]"),
        ("length", "--length", _number, "hinge to mass centre l [m]"),
        ("amp_y", "--amp-y", _number, "vertical shaking amplitude [m]"),
        ("freq", "--freq", _number, "shaking frequency [rad/s]"),
    ],
    "conical-pendulum": [
        ("mass", "--mass", _number, "mass m [kg]"),
        ("length", "--length", _number, "pivot to bob l [m]"),
        ("cone_angle", "--cone-angle", _number, "cone half-angle, 0 < DEG < 90 [deg]"),
    ],
}
_EXTRA = {
    "spin": [("damper", "--damper", None, "energy damper: point KEY=V ... | sphere KEY=V ...")],
    "heavy-top": [("gravity", "--gravity", _number, "gravity [m/s^2] (9.80665)")],
    "projectile": [],
    "rotor": [("internal_damping", "--internal-damping", _number, "rotating damping D [N m s]")],
    "gyrostat": [("wheel_inertia", "--wheel-inertia", _number, "wheel axial inertia [kg m^2]"),
                 ("damper", "--damper", None, "energy damper: point KEY=V ... | sphere KEY=V ..."),
                 ("damper_on", "--damper-on", None, "platform (default) or rotor")],
    "launch-vehicle": _launch_vehicle_parts(),
    "shaken-pendulum": [
        ("position", "--position", None, "hanging (default) or inverted"),
        ("damping", "--damping", _number, "viscous hinge damping [N m s] (0)"),
        ("amp_x", "--amp-x", _number, "horizontal shaking amplitude [m] (0; no closed form)"),
        ("gravity", "--gravity", _number, "gravity [m/s^2] (9.80665)")],
    "conical-pendulum": [
        ("inertia", "--inertia", _number, "central moment of the body [kg m^2] (0: point "
                                          "mass; > 0 needs --sequence 3-1-3)"),
        ("sequence", "--sequence", None, "Euler sequence of the formulation: 3-2-1 (default) "
                                         "or 3-1-3"),
        ("gravity", "--gravity", _number, "gravity [m/s^2] (9.80665)")],
}
#: options taking one of a few words (dest -> choices)
_CHOICES = {"damper_on": ["platform", "rotor"], "position": ["hanging", "inverted"],
            "sequence": ["3-2-1", "3-1-3"]}
#: options given in degrees on the command line, radians in the library
_DEGREES = ("cone_angle",)


def _add_inputs(parser, case, *, required):
    for dest, flag, typ, help_ in _OPTIONS[case]:
        parser.add_argument(flag, dest=dest, type=typ, required=required, help=help_)
    for dest, flag, typ, help_ in _EXTRA[case]:
        if dest == "damper":
            parser.add_argument(flag, dest=dest, nargs="+", metavar="ITEM", help=help_)
        elif dest in _CHOICES:
            parser.add_argument(flag, dest=dest, choices=_CHOICES[dest], help=help_)
        else:
            parser.add_argument(flag, dest=dest, type=typ, metavar=_METAVARS.get(dest),
                                help=help_)


def _add_case_options(parser, case, *, sweeping):
    _add_inputs(parser, case, required=not sweeping)
    parser.add_argument("--json", metavar="FILE", type=_output_file(),
                        help="write the report as JSON")
    parser.add_argument("--plot", metavar="FILE.png", type=_output_file((".png",)),
                        help="save the Bode plot of the loop with its margins and the pole "
                             "map, PNG" if case == "launch-vehicle" and not sweeping else
                        "save the pole map (sweep: eigenvalues vs the parameter), PNG")
    parser.set_defaults(_parser=parser)


def add_launch_vehicle_options(parser) -> None:
    """The vehicle, autopilot and part options of ``launch-vehicle`` (also used by
    ``appdyn simulate launch-vehicle``); `launch_vehicle_kwargs` reads them back."""
    _add_inputs(parser, "launch-vehicle", required=True)


def launch_vehicle_kwargs(args) -> dict:
    """Keyword arguments of `problems.stability.launch_vehicle` from parsed options."""
    return _case_kwargs(args, "launch-vehicle")


def call_naming_parts(fun, **kwargs):
    """``fun(**kwargs)``; a ValueError about a part's field (```slosh.mass`` ...``) is
    re-raised naming the part's option (``argument --slosh: ...``)."""
    try:
        return fun(**kwargs)
    except ValueError as exc:
        part = re.match(r"`(aero|slosh|bending|actuator)\.", str(exc))
        if part is None:
            raise
        raise ValueError(f"argument --{part.group(1)}: {exc}") from None


def sweep_parameters(case) -> list:
    """The options of ``case`` that `sweep` can vary: its scalar numbers (CLI spelling)."""
    return [flag[2:] for dest, flag, typ, _ in _OPTIONS[case] + _EXTRA[case]
            if typ is _number]


def _parameter(case):
    """argparse type for ``--parameter`` of ``sweep CASE``: a scalar option of the case."""
    valid = sweep_parameters(case)

    def parse(text):
        name = text.strip().lstrip("-").replace("_", "-")
        if name not in valid:
            raise argparse.ArgumentTypeError(
                f"{case} can sweep {', '.join(valid)}; got {text!r}")
        return name

    return parse


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Add ``stability`` to ``subparsers`` (from ``parser.add_subparsers(dest="command")``).

    The chosen case lands in ``args.case`` (``spin``, ``heavy-top``, ``projectile``,
    ``rotor``, ``gyrostat``, ``launch-vehicle``, ``shaken-pendulum``, ``conical-pendulum``,
    ``sweep``); under ``sweep`` the swept case
    is ``args.sweep_case``.
    Hand the parsed arguments to `run`.
    """
    stab = subparsers.add_parser("stability", help="linear stability reports of spinning bodies and mechanisms")
    cases = stab.add_subparsers(dest="case", required=True)
    helps = {"spin": "torque-free spin about a principal axis (optional damper)",
             "heavy-top": "heavy top, NASA RP-1262 Sec. 4.6 Method III (sleeping top, precession)",
             "projectile": "spin-stabilized projectile (aerodynamic overturning moment)",
             "rotor": "rotor in elastic bearings: whirl and internal-damping instability",
             "gyrostat": "dual-spin gyrostat vs wheel momentum (optional damper)",
             "launch-vehicle": "launch-vehicle attitude autopilot (RP-1262 Sec. 5.4): margins "
                               "at the engine deflection, named modes",
             "shaken-pendulum": "pendulum on a shaken hinge: Floquet multipliers vs Mathieu "
                                "(Kapitza's inverted pendulum, resonance tongues)",
             "conical-pendulum": "conical pendulum (RP-1262 Ch. 6 Ex. 1): nutation about the "
                                 "steady cone vs the closed form"}
    for case, help_ in helps.items():
        _add_case_options(cases.add_parser(case, help=help_), case, sweeping=False)
    sw = cases.add_parser("sweep", help="verdict and least-damped eigenvalue along a parameter")
    sw_cases = sw.add_subparsers(dest="sweep_case", required=True)
    for case, help_ in helps.items():
        p = sw_cases.add_parser(case, help=help_)
        p.add_argument("--parameter", required=True, type=_parameter(case),
                       help="option to sweep: " + ", ".join(sweep_parameters(case)))
        p.add_argument("--values", required=True,
                       metavar="START:STOP:NUM|V1,V2,...",
                       help="NUM evenly spaced values from START to STOP, or a list")
        p.add_argument("--rtol", type=_positive, default=1e-8,
                       help="relative bracket of the boundary bisection (1e-8)")
        p.add_argument("--progress", action="store_true",
                       help="progress lines on stderr (default: only when stderr is a terminal)")
        p.add_argument("--quiet", action="store_true", help="no progress lines")
        add_executor_options(p)
        _add_case_options(p, case, sweeping=True)
    return stab


def _values(text):
    """``--values``: ``START:STOP:NUM`` or ``V1,V2,...`` -> finite, strictly increasing array.

    Raises
    ------
    ValueError
        Naming ``--values``.
    """
    if ":" in text:
        parts = text.split(":")
        if len(parts) != 3:
            raise ValueError(f"`--values` must be START:STOP:NUM, got {text!r}")
        try:
            a, b, n = float(parts[0]), float(parts[1]), int(parts[2])
        except ValueError:
            raise ValueError(f"`--values` must be START:STOP:NUM, got {text!r}") from None
        if n < 1:
            raise ValueError(f"`--values` NUM must be at least 1, got {n}")
        vals = np.linspace(a, b, n)
    else:
        try:
            vals = np.array([float(v) for v in text.split(",") if v != ""])
        except ValueError:
            raise ValueError(f"`--values` must be numbers, got {text!r}") from None
        if vals.size == 0:
            raise ValueError(f"`--values` must be numbers, got {text!r}")
    if not np.all(np.isfinite(vals)):
        raise ValueError(f"`--values` must be finite, got {text!r}")
    if np.any(np.diff(vals) <= 0):
        raise ValueError(f"`--values` must be strictly increasing, got {text!r}")
    return vals


def check(parser, args) -> None:
    """Checks across options, as argparse errors on ``parser`` (exit status 2)."""
    if getattr(args, "damper_on", None) is not None and getattr(args, "damper", None) is None:
        parser.error("argument --damper-on: only with --damper")
    if args.case == "sweep":
        try:
            _values(args.values)
        except ValueError as exc:
            parser.error(str(exc))
        dest = args.parameter.replace("-", "_")
        if getattr(args, dest, None) is not None:
            parser.error(f"argument --{args.parameter}: not allowed with --parameter "
                         f"{args.parameter} (it is swept over --values)")
        case = args.sweep_case
        missing = [flag for d, flag, *_ in _OPTIONS[case]
                   if getattr(args, d, None) is None and d != dest]
        if missing:
            parser.error(f"sweep {case} needs {', '.join(missing)} (all but the swept "
                         f"--{args.parameter})")
    if "launch-vehicle" in (args.case, getattr(args, "sweep_case", None)):
        check_flight(parser, args)
    if same_file(args.plot, args.json):
        parser.error("argument --json: the same file as --plot")


def check_flight(parser, args) -> None:
    """``--velocity`` goes with ``--aero`` (unless swept), as argparse errors."""
    swept = getattr(args, "parameter", None) == "velocity"
    if args.aero is not None and args.velocity is None and not swept:
        parser.error("argument --velocity: needed with --aero (alpha = psi - y_dot / V)")
    if args.aero is None and (args.velocity is not None or swept):
        parser.error("argument --velocity: only with --aero")


def _case_kwargs(args, case) -> dict:
    kwargs = {}
    for dest, *_ in _OPTIONS[case] + _EXTRA[case]:
        value = getattr(args, dest, None)
        if value is None:
            continue
        if dest == "inertia" and isinstance(value, np.ndarray):
            value = inertia_matrix(value)
        elif dest == "damper":
            value = parse_damper(value)
        elif dest in _DEGREES:
            value = np.radians(value)
        kwargs[dest] = value
    return kwargs


def run(args) -> int:
    """Execute parsed ``stability`` arguments: print the report, write ``--json``/``--plot``.

    Returns 0, or 1 when the eigenvalues disagree with the case's closed forms (the verdict
    is in the report, not the exit status). Call `check` first
    (``problems.cli.main`` does). ``ValueError`` from bad input propagates
    (``problems.cli.main`` turns it into exit status 2).
    """
    from appdyn.problems import stability as st  # imported on use: building the parser stays light

    if args.case == "sweep":
        case = args.sweep_case
        kwargs = _case_kwargs(args, case)
        parameter = args.parameter.replace("-", "_")
        progress = Progress(f"sweep {case} over {args.parameter}",
                            enabled=progress_enabled(args))
        try:
            values = _values(args.values)
            if parameter in _DEGREES:
                values = np.radians(values)
            with executor_from(args) as executor:
                result = st.sweep(case, parameter, values, rtol=args.rtol, executor=executor,
                                  progress=progress if progress.enabled else None, **kwargs)
        finally:
            progress.close()
    else:
        _, case_function = st.resolve_case(args.case)
        result = call_naming_parts(case_function, **_case_kwargs(args, args.case))
    if args.case == "launch-vehicle" and args.plot:  # the Bode plot with the pole map
        status = finish(result, f"stability {args.case}", json=args.json)
        save_figure(st.bode_plot(result, pole_map=True), args.plot)
        print(f"plot written to {args.plot}")
        return status
    return finish(result, f"stability {args.case}", plot=args.plot, json=args.json)


def main(argv=None) -> int:
    """Standalone entry: ``main(["spin", "--inertia", ...])`` (the arguments after
    ``stability``); returns the exit status."""
    parser = argparse.ArgumentParser(prog="appdyn")
    sub = parser.add_subparsers(dest="command", required=True)
    add_parser(sub)
    argv = ["stability", *(sys.argv[1:] if argv is None else argv)]
    args = parser.parse_args(attach_negative_values(parser, argv))
    check(args._parser, args)
    try:
        return run(args)
    except ValueError as exc:
        args._parser.exit(2, f"{args._parser.prog}: error: {' '.join(str(exc).split())}\n")

