"""``appdyn gains ...``: feedback-gain design by direct collocation (`problems.gains`).

    appdyn gains launch-vehicle (--config lv.toml | --example) [--plot FILE.png] [--json FILE]

``launch-vehicle`` designs the attitude/rate autopilot gains of a thrust-vectored launch
vehicle (`problems.gains.launch_vehicle.launch_vehicle_gains`) from a TOML file
(`problems.gains.config`; an example ships as ``problems/gains/launch_vehicle.toml``) and
prints the gains, the closed-loop modes and margins (python-control) and every scenario's
peak deflection and rate against the limits. Exit status 0 when the design succeeded and
verified (stable loop, limits held in every re-simulated scenario), 1 when not (the reason on
stderr), 2 for a bad configuration (the field named) or bad options.
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

from appdyn.problems.cli.common import PLOT_SUFFIXES, finish, same_file
from appdyn.problems.cli.common import output_file as _output_file

__all__ = ["add_parser", "check", "run", "DesignPrintout"]


def _config_file(text):
    """argparse type: an existing file (its content is checked by `check`)."""
    path = Path(text).expanduser()
    if not path.is_file():
        raise argparse.ArgumentTypeError(f"no such file: {text!r}")
    return str(path)


def _example() -> str:
    """Path of the example configuration installed with the package
    (`problems.gains.config.EXAMPLE_CONFIG`, found without importing the gains package)."""
    return str(Path(__file__).resolve().parents[1] / "gains" / "launch_vehicle.toml")


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Add ``gains`` (with its case ``launch-vehicle``) to ``subparsers``."""
    gains = subparsers.add_parser("gains", help="feedback-gain design by direct collocation",
                                  description="Design feedback gains over several scenarios "
                                              "at once (multi-scenario collocation), verified "
                                              "by the closed-loop poles, margins and a "
                                              "re-simulation against the limits.")
    gains.set_defaults(_parser=gains)
    cases = gains.add_subparsers(dest="case", required=True)
    lv = cases.add_parser(
        "launch-vehicle", help="attitude/rate autopilot of a thrust-vectored launch vehicle",
        description="Design k_psi, k_psidot of delta_c = -(k_psi psi + k_psidot psi_dot) "
                    "for an aerodynamically unstable launch vehicle under gimbal deflection "
                    "and rate limits, from a TOML configuration (example: "
                    "problems/gains/launch_vehicle.toml). Exit status 1 when the design "
                    "fails (infeasible limits, unstable loop), 2 for a bad configuration.")
    lv.set_defaults(_parser=lv)
    source = lv.add_mutually_exclusive_group(required=True)
    source.add_argument("--config", metavar="FILE.toml", type=_config_file,
                        help="the design: [vehicle], [limits], [[scenarios]], optional [weights], "
                             "[design] (problems/gains/config.py)")
    source.add_argument("--example", dest="config", action="store_const", const=_example(),
                        help="the example design shipped with appdyn "
                             "(problems/gains/launch_vehicle.toml: a start for your own)")
    lv.add_argument("--plot", metavar="FILE.png", type=_output_file(PLOT_SUFFIXES),
                    help="save attitude, deflection and rate of every scenario "
                         "(.png, .pdf or .svg)")
    lv.add_argument("--json", metavar="FILE", type=_output_file(),
                    help="write the design (gains, margins, peaks) as JSON")
    return gains


def check(parser, args) -> None:
    """Read and check the configuration before any computation (argparse error, exit 2,
    naming the field), and the output files."""
    from appdyn.problems.gains.config import load_config

    if same_file(args.plot, args.json):
        parser.error("argument --json: the same file as --plot")
    try:
        args._config = load_config(args.config)
    except ValueError as exc:
        parser.error(f"argument --config: {args.config}: {exc}")


class DesignPrintout:
    """What ``appdyn gains launch-vehicle`` prints and writes for a `GainDesign`: the gains,
    margins and per-scenario peaks in degrees (``__str__``), ``to_dict`` (the design's, plus
    the configuration file and the scenarios' names and peaks in degrees), ``plot``."""

    def __init__(self, design, source: str):
        self.design, self.source = design, source
        self.success, self.status, self.message = design.success, design.status, design.message

    def __str__(self) -> str:
        from appdyn.ocp.status import describe  # the CLI imports the engine only when it runs

        d, v = self.design, self.design.verification
        verdict = "success" if d.success else "FAILED"
        lines = [f"Launch-vehicle autopilot gains ({self.source})",
                 f"  status    {verdict} ({describe(d.status, solver_status=d.solver_status)})"]
        note = "" if "verdict" in v else "  (the solver's last iterate)"
        lines += [f"  {k:<8}  {val:.6g} {d.units.get(k, '')}{note}" for k, val in d.gains.items()]
        if "verdict" in v:
            lines.append(f"  closed loop: {v['verdict']}")
            for m in v.get("modes", []):
                lines.append(f"    {m['label']:<16} wn {m['wn']:9.4g} rad/s  zeta "
                             f"{m['zeta']:7.4f}")
            lines.append("  margins (loop broken at the deflection command):")
            lines.append(f"    phase margin      {v['phase_margin_deg']:.2f} deg at "
                         f"{v['gain_crossover']:.4g} rad/s")
            lo, hi = v["gain_margin_lower"], v["gain_margin_upper"]
            lo_text = f"x{lo:.4g} ({20 * math.log10(lo):.2f} dB)" if lo > 0 else "none"
            hi_text = f"x{hi:.4g} ({20 * math.log10(hi):.2f} dB)" if math.isfinite(hi) else "inf"
            lines.append(f"    gain margin       lower {lo_text}, upper {hi_text}")
        if d.scenarios:
            dmax, rmax = math.degrees(v["delta_max"]), math.degrees(v["delta_rate_max"])
            width = max(8, *(len(s.get("name") or "") for s in d.scenarios))
            lines.append(f"  {'scenario':<{width}}  peak |delta| [deg]  peak |delta_dot| [deg/s]"
                         f"  peak |psi| [deg]")
            for i, s in enumerate(d.scenarios):
                p = s["peak"]
                lines.append(f"  {s.get('name') or str(i):<{width}}  "
                             f"{math.degrees(p['delta']):8.4g} / {dmax:<7.4g}"
                             f"  {math.degrees(p['delta_rate']):10.4g} / {rmax:<11.4g}"
                             f"  {math.degrees(p['psi']):10.4g}")
        if "solve_time" in v:
            lines.append(f"  solve     {v['solve_time']:.2f} s, {v['iterations']} IPOPT "
                         "iterations")
        lines.append(f"  message   {d.message}")
        return "\n".join(lines)

    def to_dict(self) -> dict:
        """`GainDesign.to_dict` with ``config`` and per-scenario ``name`` and ``peak_deg``."""
        out = self.design.to_dict()
        out["config"] = self.source
        for s, data in zip(self.design.scenarios, out["scenarios"]):
            data["name"] = s.get("name", "")
            data["peak_deg"] = {k: math.degrees(v) for k, v in s["peak"].items()}
        return out

    def plot(self):
        """`GainDesign.plot`."""
        return self.design.plot()


def run(args) -> int:
    """Design, print, write ``--plot``/``--json``; 0 when verified, else 1."""
    config = getattr(args, "_config", None)
    if config is None:  # run() called without check()
        from appdyn.problems.gains.config import load_config

        config = load_config(args.config)
    design = config.design()
    return finish(DesignPrintout(design, config.source), "gains launch-vehicle",
                  plot=args.plot, json=args.json)
