"""Start-up time of the command line: ``appdyn --help`` against a bare interpreter.

Each round starts, in fresh processes and one right after the other, ``python -c pass`` (the
interpreter alone) and ``python -m appdyn.problems.cli --help``; the time of ``--help`` is
the median over the rounds, its cost the median of the per-round differences (this VM's
speed drifts within seconds: the pair is timed together). The budget of issue 33 is
``--help`` <= 0.3 s (it was 1.1-1.3 s when every command and scipy.signal were imported up
front); also reported: whether ``--help`` imported numpy or the library (it must not), and
the in-process time of building the parser and printing the help.

Writes ``cli.csv`` into the output folder and returns the summary rows (`run`).
Run: ``appdyn bench cli`` or ``python bench/cli.py [--quick]``.
"""
from __future__ import annotations

import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

from _common import Row, script_main, write_csv

ROOT = Path(__file__).resolve().parents[1]
BUDGET = 0.3  # [s] issue 33: `appdyn --help` <= 0.3 s
PROBE = ("import sys, io, contextlib, time\n"
         "t = time.perf_counter()\n"
         "from appdyn.problems.cli import main\n"
         "try:\n"
         "    with contextlib.redirect_stdout(io.StringIO()):\n"
         "        main(['--help'])\n"
         "except SystemExit:\n"
         "    pass\n"
         "print(time.perf_counter() - t, 'numpy' in sys.modules, 'appdyn.dynamics' in sys.modules)")


def _env() -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    return env


def _wall(args, env) -> float:
    t0 = time.perf_counter()
    subprocess.run([sys.executable, *args], env=env, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - t0


def run(quick: bool, out: Path) -> list[Row]:
    rounds = 5 if quick else 21
    env = _env()
    bare, helps = [], []
    for _ in range(rounds):
        bare.append(_wall(["-c", "pass"], env))
        helps.append(_wall(["-m", "appdyn.problems.cli", "--help"], env))
    probe = subprocess.run([sys.executable, "-c", PROBE], env=env, check=True,
                           capture_output=True, text=True).stdout.split()
    inside, numpy, library = float(probe[0]), probe[1] == "True", probe[2] == "True"
    diff = [h - b for h, b in zip(helps, bare)]
    detail = [{"round": k, "bare_python_s": b, "help_s": h} for k, (b, h) in
              enumerate(zip(bare, helps))]
    write_csv(detail, out / "cli.csv")
    note = f"median of {rounds} paired rounds; budget {BUDGET} s"
    return [
        Row("cli", "appdyn --help", "wall time", statistics.median(helps), "s", note),
        Row("cli", "appdyn --help", "wall time - bare interpreter", statistics.median(diff),
            "s", note),
        Row("cli", "appdyn --help", "in-process (parser + help)", inside, "s",
            f"numpy imported: {numpy}; library imported: {library}"),
    ]


def main(argv=None) -> int:
    return script_main(run, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
