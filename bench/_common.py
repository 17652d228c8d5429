"""What every benchmark of ``bench/`` shares: the result protocol, the machine description,
CSV and figure output, and timing.

The protocol
------------
A benchmark is a module ``bench/NAME.py`` (names starting with ``_`` are helpers, not
benchmarks) with

* ``run(quick: bool, out: pathlib.Path) -> list[Row]``: runs the benchmark, writes its own
  detail files into ``out`` (``NAME.csv`` always, ``NAME.png`` where it has a figure; more
  files are fine, each named ``NAME*``) and returns its *summary rows*: the few headline
  numbers a reader wants (the tables of ``docs/performance.md`` are generated from them);
* ``main(argv=())``: ``python bench/NAME.py [--quick] [--out DIR]`` (`script_main`).

``--quick`` must finish in well under two minutes for all benchmarks together; peers that
are not installed are skipped with a one-line notice (never an error).

The runner
----------
``appdyn bench [NAME ...] [--quick] [--out DIR] [--docs]`` (``problems/cli/bench.py``)
puts ``bench/`` on ``sys.path`` (so a script imports ``from _common import Row``), imports
each named benchmark, calls ``run(quick, out)``, prints the rows, and writes
``OUT/summary.csv`` (all benchmarks' rows; a partial run replaces only its own) and
``OUT/machine.json`` (`machine`). A benchmark that raises is reported and the others still
run. ``--docs`` (``--readme``, its former name, and ``make bench``) regenerate the tables of
the performance page, ``docs/performance.md``, from ``RESULTS`` with ``bench/_readme.py``;
those numbers are never edited by hand.
"""
from __future__ import annotations

import csv
import datetime
import json
import os
import platform
import subprocess
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path

__all__ = ["Row", "RESULTS", "PEERS", "machine", "write_csv", "write_rows", "save_figure",
           "timed", "script_main", "format_rows", "run_peer"]

#: default output folder of ``appdyn bench`` / ``make bench`` (committed: the tables of
#: docs/performance.md are generated from ``summary.csv`` and ``machine.json`` in it)
RESULTS = Path(__file__).resolve().parent / "results"

#: the peer runners (``bench/peers/*.py``), each run in its own venv ``peers/.venv-NAME``
PEERS = Path(__file__).resolve().parent / "peers"


def run_peer(venv: str, script: str, args, *, timeout: float = 600.0) -> dict | None:
    """The JSON a peer runner prints: ``peers/.venv-VENV/bin/python peers/SCRIPT --json
    ARGS`` in a fresh process; None, with a one-line notice, when the venv is missing
    (``bash bench/peers/setup_VENV.sh``) or the runner fails."""
    python = PEERS / f".venv-{venv}" / "bin" / "python"
    if not python.exists():
        print(f"{venv}: no {python.parent.parent} (bash bench/peers/setup_{venv}.sh); skipped")
        return None
    proc = subprocess.run([str(python), str(PEERS / script), "--json", *map(str, args)],
                          capture_output=True, text=True, timeout=timeout)
    if proc.returncode:
        print(f"{venv}: peer failed: {proc.stderr.strip().splitlines()[-1:]}; skipped")
        return None
    return json.loads(proc.stdout)


@dataclass(frozen=True)
class Row:
    """One headline number of a benchmark.

    Parameters
    ----------
    benchmark : str
        The module name (``"simulate"``).
    case : str
        What was run (``"torque-free body, error <= 1e-6"``).
    metric : str
        What is measured (``"wall time"``, ``"speed-up vs scipy DOP853"``, ``"error"``).
    value : float
    unit : str
        ``"s"``, ``"ms"``, ``"x"``, ``"rad/s"``, ``""`` ...
    note : str, optional
        The setting that produced it (``"rk8, steps 2"``), a peer's name, a caveat.
    """

    benchmark: str
    case: str
    metric: str
    value: float
    unit: str = ""
    note: str = ""


def _cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.lower().startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _ipopt_linear_solver() -> str:
    """The linear solver IPOPT uses by default in this casadi build (``mumps`` unless told)."""
    try:
        import casadi as ca

        x = ca.SX.sym("x")
        solver = ca.nlpsol("probe", "ipopt", {"x": x, "f": x**2},
                           {"print_time": False, "ipopt": {"print_level": 0, "sb": "yes"}})
        solver(x0=1.0)
        return str(solver.stats().get("linear_solver", "mumps"))
    except Exception:  # noqa: BLE001 - a description, never a failure
        return "unknown"


def machine() -> dict:
    """Machine and software description: CPU model, cores, Python and library versions,
    IPOPT's linear solver, and the date (UTC)."""
    from importlib.metadata import PackageNotFoundError, version

    def ver(name):
        try:
            return version(name)
        except PackageNotFoundError:
            return None

    return {
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "cpu": _cpu_model(), "cores": os.cpu_count(), "platform": platform.platform(),
        "python": platform.python_version(),
        "casadi": ver("casadi"), "numpy": ver("numpy"), "scipy": ver("scipy"),
        "ipopt_linear_solver": _ipopt_linear_solver(),
    }


def write_csv(rows, path: Path) -> Path:
    """Write dicts (or `Row`s) as CSV with the union of their keys as columns."""
    rows = [asdict(r) if isinstance(r, Row) else dict(r) for r in rows]
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fields: list[str] = []
    for r in rows:
        fields += [k for k in r if k not in fields]
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=fields)
        w.writeheader()
        w.writerows(rows)
    return path


def write_rows(rows, path: Path) -> Path:
    """Write summary `Row`s (the columns of `Row`)."""
    return write_csv(rows, path)


def save_figure(fig, path: Path) -> Path:
    """Save a `matplotlib.figure.Figure` (no pyplot) to ``path``."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    return path


#: Seconds of the timed work run before a short timing (`warmed`): the VM's cores come out
#: of idle slowly, and a sub-millisecond call timed right after one (a peer's subprocess
#: waited for, a sleep) measured 1.7x its time on a busy core (bench/integrate_peers.py's
#: 121-output body: 85-133 against 51-53 us, alternating in one process). Both sides of a
#: comparison are warmed alike (the peers' scripts with the same `WARM`).
WARM = 0.2


def warmed(fun, seconds: float = WARM) -> None:
    """Call ``fun()`` repeatedly for ``seconds`` (at least once): the core is at speed
    for the timing that follows."""
    end = time.perf_counter() + seconds
    fun()
    while time.perf_counter() < end:
        fun()


def timed(fun, repeats: int = 1):
    """``(first-call time, later times, result)``: ``fun()`` once, then ``repeats`` more."""
    t0 = time.perf_counter()
    result = fun()
    first = time.perf_counter() - t0
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = fun()
        times.append(time.perf_counter() - t0)
    return first, (times or [first]), result


def format_rows(rows) -> str:
    """Summary rows as a plain-text table."""
    rows = list(rows)
    if not rows:
        return "(no summary rows)"
    head = ("benchmark", "case", "metric", "value", "unit", "note")
    cells = [[r.benchmark, r.case, r.metric, f"{r.value:.4g}", r.unit, r.note] for r in rows]
    widths = [max(len(h), *(len(c[i]) for c in cells)) for i, h in enumerate(head)]
    line = "  ".join(h.ljust(w) for h, w in zip(head, widths))
    out = [line, "-" * len(line)]
    out += ["  ".join(c.ljust(w) for c, w in zip(cell, widths)) for cell in cells]
    return "\n".join(out)


def script_main(run, argv=None) -> int:
    """``main`` of a benchmark script: ``[--quick] [--out DIR]``; prints the summary rows."""
    argv = list(sys.argv[1:] if argv is None else argv)
    quick = "--quick" in argv
    out = RESULTS
    if "--out" in argv:
        i = argv.index("--out")
        if i + 1 >= len(argv):
            print("error: --out needs a folder", file=sys.stderr)
            return 2
        out = Path(argv[i + 1])
    out.mkdir(parents=True, exist_ok=True)
    rows = run(quick, out)
    print(format_rows(rows))
    (out / "machine.json").write_text(json.dumps(machine(), indent=2) + "\n")
    return 0
