"""The ``appdyn`` command line::

    appdyn simulate torque-free --inertia 1,2,3 --w0 -1,0.1,0.8 --t-final 50 [--plot F.png]
    appdyn simulate launch-vehicle --thrust F --inertia I --arm L --mass M --k-psi K --k-psidot KD
                                   [--aero ...] --psi0 DEG [--gust V ...] [--plot F.png]
    appdyn simulate hinged --m1 M --inertia1 a,b,c --m2 M --inertia2 a,b,c --r1 x,y,z --r2 x,y,z
                           [--kind ball|revolute --axis x,y,z] --w1 ... --w2 ... [--v1 ...]
                           --t-final T [--steps N] [--no-stabilization] [--plot F.png] [--json F]
    appdyn slew --inertia 1,1,1 --u-max 1 --axis 0,0,1 --angle 180 --time-optimal
    appdyn stability spin|heavy-top|projectile|rotor|gyrostat|launch-vehicle|shaken-pendulum|
                     conical-pendulum|sweep ...
                     [--json F] [--plot F.png]
    appdyn cmg envelope --beta 54.74 [--h 1] [--directions N] [--plot F.png] [--json F]
    appdyn cmg steer --beta 54.74 --torque 0,0,0.5 --law sr|pinv|gsr --t-final 10 [--delta0 ...]
    appdyn gains launch-vehicle --config lv.toml [--plot F.png] [--json F]
    appdyn dispersion spin [--samples N] [--seed S] [--workers N | --scheduler ADDR] [--plot F.png]
    appdyn ascent delta3 [--N N] [--refine-tol TOL | --no-refine] [--plot F.png] [--json F]
    appdyn demo
    appdyn bench [NAME ...] [--quick] [--out DIR] [--docs]
    appdyn cache info|clear

One module per command (`simulate`, `slew`, `stability`, `cmg`, `gains`, `dispersion`, `ascent`, `demo`,
`bench`, `cache`), each with
``add_parser(subparsers)``, ``check(parser, args)`` (checks across options, before any
computation) and ``run(args) -> exit status``; `common` holds what they share.

Exit status: 0 done (and verified where the command checks its answer: ``simulate`` against
the closed form, ``slew`` against the solver's success and the rest-to-rest time bound);
1 numerical failure or failed check (a one-line reason on stderr); 2 bad input (argparse-style
usage and a one-line ``error: argument --OPTION: ...``, before any computation where the input
can be checked up front: values, conflicting options, output paths). Option values may start
with a minus sign (``--w0 -1,0,0``, ``--values -1:1:5``). JSON output is strict (non-finite
numbers as ``null``). ``APPDYN_TRACEBACK=1`` shows the traceback of an unexpected error.

Library code never prints or saves files; this package is the one place that does.
"""
from __future__ import annotations

import argparse
import importlib
import os
import re
import sys
from collections.abc import Mapping

__all__ = ["main", "build_parser", "COMMANDS", "HELP", "rest_to_rest_bound"]

#: command name -> its one-line help, in the order of ``--help`` (the modules are imported
#: only for the command run: ``appdyn --help`` imports neither numpy nor the library)
HELP = {
    "simulate": "simulate a model and check it against a truth",
    "slew": "optimal rigid-body attitude slew (direct collocation)",
    "stability": "linear stability reports of spinning bodies and mechanisms",
    "cmg": "CMG pyramid: momentum envelope, steering laws",
    "gains": "feedback-gain design by direct collocation",
    "dispersion": "Monte Carlo dispersions",
    "ascent": "launch-vehicle ascent trajectories",
    "demo": "a short tour of the toolkit's main jobs (< 1 min)",
    "bench": "run benchmarks from the bench/ folder",
    "cache": "the compile cache: where it is and what it holds, or empty it",
}


class _Commands(Mapping):
    """command name -> its module (``add_parser``, ``check``, ``run``), imported on access."""

    def __getitem__(self, name):
        if name not in HELP:
            raise KeyError(name)
        return importlib.import_module(f"{__name__}.{name}")

    def __iter__(self):
        return iter(HELP)

    def __len__(self):
        return len(HELP)


#: command name -> its module, in the order of ``--help`` (each imported on first access)
COMMANDS = _Commands()


def __getattr__(name):  # `rest_to_rest_bound` without importing the slew command up front
    if name == "rest_to_rest_bound":
        return COMMANDS["slew"].rest_to_rest_bound
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


class _Version(argparse.Action):
    """``--version``: the installed version, looked up only when asked."""

    def __init__(self, option_strings, dest=argparse.SUPPRESS, default=argparse.SUPPRESS,
                 help="show the version and exit"):
        super().__init__(option_strings, dest, nargs=0, default=default, help=help)

    def __call__(self, parser, namespace, values, option_string=None):
        import appdyn

        sys.stdout.write(f"appdyn {appdyn.__version__}\n")
        parser.exit()


def build_parser(command: str | None = "all") -> argparse.ArgumentParser:
    """The ``appdyn`` parser.

    Parameters
    ----------
    command : str or None
        ``"all"``: every command's full parser (its module imported); a command name: that
        command's in full and one-line entries for the others; ``None``: one-line entries
        only (enough for ``appdyn --help``).
    """
    parser = argparse.ArgumentParser(
        prog="appdyn", description="Aerospace vehicle dynamics and optimal control on CasADi.",
        epilog="exit status: 0 done (and verified), 1 numerical failure or failed check, "
               "2 bad input")
    parser.add_argument("--version", action=_Version)
    sub = parser.add_subparsers(dest="command", required=True)
    for name, help_ in HELP.items():
        if command == "all" or name == command:
            COMMANDS[name].add_parser(sub)
        else:
            sub.add_parser(name, help=help_, add_help=False)
    return parser


def _command_of(argv) -> str | None:
    """The command named in ``argv`` (the first word that is one), else None."""
    for word in argv:
        if word in HELP:
            return word
        if not word.startswith("-"):
            return None
    return None


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
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = build_parser(_command_of(argv))
    from appdyn.problems.cli.common import attach_negative_values

    args = parser.parse_args(attach_negative_values(parser, argv))
    sub = getattr(args, "_parser", parser)
    command = COMMANDS[args.command]
    command.check(sub, args)
    try:
        return command.run(args)
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
