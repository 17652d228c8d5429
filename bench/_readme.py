"""The tables of the performance page (``docs/performance.md``), generated from a results
folder.

``render(results_dir)`` turns ``summary.csv`` and ``machine.json`` (written by ``appdyn
bench``) into markdown: one line naming the machine and versions, then one table per
benchmark. ``update_page(page_path, results_dir)`` puts that text between the markers
``<!-- bench:begin -->`` and ``<!-- bench:end -->`` of the page (``update_readme`` is its
former name: the tables were in the README until they moved to the docs). The numbers in
that part of the page are never edited by hand (``tests/test_bench_readme.py`` checks that
they are exactly ``render(bench/results)``); ``make bench`` regenerates them.
"""
from __future__ import annotations

import csv
import json
import math
from pathlib import Path

__all__ = ["BEGIN", "END", "GLANCE", "glance", "render", "update_page", "update_readme",
           "current", "format_value"]

BEGIN = "<!-- bench:begin -->"
END = "<!-- bench:end -->"

#: what each benchmark measures, the line above its table; the tables follow this order
#: (benchmarks not listed come after, in the order of ``summary.csv``)
TITLES = {
    "simulate": "Simulation, torque-free rigid body against its Jacobi-elliptic truth "
                "(`bench/simulate.py`)",
    "integrate_peers": "Single runs against numbalsoda dop853 at matched error, several "
                       "workloads (`bench/integrate_peers.py`)",
    "workprecision": "Work-precision of every integration method against scipy, every model "
                     "with a truth (`bench/workprecision.py`)",
    "slew": "Optimal slews (`bench/slew.py`)",
    "ocp_precision": "Optimal control: objective error against work for every transcription "
                     "(`bench/ocp_precision.py`)",
    "ascent": "Delta III ascent to GTO, 4 phases (`bench/ascent.py`)",
    "literature": "Literature cases: orbit raising and shuttle reentry, appdyn next to ASSET "
                  "(`bench/literature.py`)",
    "many": "Many runs: serial against thread and process pools (`bench/many.py`)",
    "overhead": "Per-call Python overhead of `simulate` on a 2-point grid, cached model "
                "(`bench/overhead.py`)",
    "stress": "Stress cases (`bench/stress.py`)",
    "trust": "A new user's first hour: slews and saturated-law simulations, each in a fresh "
             "process (`bench/trust.py`)",
    "scene": "Scenes: a hub-only scene against `rigid_body`, the build time of scenes of 1 to "
             "10 parts (`bench/scene.py`)",
    "compile_cache": "Compile cache: the first `simulate` of a model in a fresh process, compiled "
                     "before on this machine and with an empty cache, and the vector lanes "
                     "compiled after it (`bench/compile_cache.py`)",
    "cli": "Start-up of the command line: `appdyn --help` against a bare interpreter, fresh "
           "processes (`bench/cli.py`)",
    "flexible": "Flexible appendages: the four-antenna satellite's build and simulation, a "
                "spin-up with and without geometric stiffening (`bench/flexible.py`)",
}


#: The page's first table, "At a glance": headline comparisons read from the rows of the
#: tables below it (never typed in): ``(job, against, benchmark, test(case, metric))``; a
#: job whose test matches several rows (workloads, meshes, error targets) shows their range.
#: Ratios are the peer's time over appdyn's (> 1: appdyn faster) as in the tables.
GLANCE = (
    ("single run, `auto` (the default; its global error verified), at matched error",
     "numbalsoda dop853", "integrate_peers",
     lambda c, m: m == "speed-up vs numbalsoda dop853, interpolated at the target error"),
    ("single run, `method='dop853'` (not verified, as the peer), at matched error",
     "numbalsoda dop853", "integrate_peers", lambda c, m: m == (
         "appdyn dop853 (not verified): speed-up vs numbalsoda dop853, interpolated at the "
         "target error")),
    ("single run, `method='dop853'`, cost per second of a long run (the same method and "
     "tolerance: the steps' cost alone)", "numbalsoda dop853", "integrate_peers",
     lambda c, m: m == "cost per second of horizon: numbalsoda over appdyn"),
    ("1,000-run Monte Carlo at the defaults (every run verified), 1 thread",
     "numbalsoda njit loop", "integrate_peers", lambda c, m: "torque-free" in c
     and "njit loop (one thread), defaults" in m and m.endswith("on 1 thread(s)")),
    ("1,000-run Monte Carlo at the defaults (every run verified), 2 threads",
     "numbalsoda njit loop", "integrate_peers", lambda c, m: "torque-free" in c
     and "njit loop (one thread), defaults" in m and m.endswith("on 2 thread(s)")),
    ("1,000-run Monte Carlo, fixed-step rk8, 1 thread", "numbalsoda njit loop",
     "integrate_peers", lambda c, m: "torque-free" in c and "fixed-step rk8" in m
     and m.endswith("on 1 thread(s)")),
    ("1,000-run Monte Carlo under sampled torques at the defaults, 1 and 2 threads",
     "numbalsoda njit loop", "integrate_peers", lambda c, m: "sampled torques" in c
     and "njit loop (one thread), defaults" in m),
    ("torque-free body, `auto`", "scipy DOP853", "simulate",
     lambda c, m: m == "speed-up of auto vs scipy DOP853"),
    ("every model with a truth, `auto`", "scipy", "workprecision",
     lambda c, m: m == "speed-up of auto vs scipy"),
    ("time-optimal slew (Bilimoria-Wie), at matched accuracy", "rockit", "slew",
     lambda c, m: m == "speed-up vs rockit at matched accuracy"),
    ("Delta III ascent to GTO, 4 phases", "ASSET", "ascent",
     lambda c, m: m.startswith("ASSET") and "|u| = 1" not in m),
    ("shuttle reentry (Betts), meshes of 32-128 segments", "ASSET", "literature",
     lambda c, m: c.startswith("shuttle") and m.startswith("ASSET")),
    ("orbit raising (Bryson & Ho), meshes of 20-160 segments", "ASSET", "literature",
     lambda c, m: c.startswith("orbit raising") and m.startswith("ASSET")),
    ("orbit raising and shuttle reentry", "rockit", "literature",
     lambda c, m: m.startswith("rockit") and "/ appdyn" in m),
    ("first `simulate` in a fresh process, the model compiled before", "", "compile_cache",
     lambda c, m: "compiled before" in c and m == "wall time"),
)


def glance(rows: list[dict]) -> list[str]:
    """The lines of the "At a glance" table (`GLANCE`) from the ``summary.csv`` rows; a job
    without rows is left out (its benchmark not run)."""
    lines = ["**At a glance** (read from the tables below; ratios are the peer's time over "
             "appdyn's, > 1: appdyn faster)", "",
             "| job | against | result | rows |", "| --- | --- | ---: | ---: |"]
    for job, peer, bench, test in GLANCE:
        got = [r for r in rows if r["benchmark"] == bench and test(r["case"], r["metric"])]
        values = sorted(float(r["value"]) for r in got if math.isfinite(float(r["value"])))
        if not values:
            continue
        unit = f" {got[0]['unit']}" if got[0].get("unit") else ""
        text = format_value(values[0]) if len(values) == 1 else \
            f"{format_value(values[0])} - {format_value(values[-1])}"
        lines.append(f"| {_cell(job)} | {_cell(peer)} | {text}{unit} | {len(values)} |")
    return lines if len(lines) > 4 else []


def format_value(value: float) -> str:
    """A number with 4 significant digits (3 in exponent form): ``0.1234``, ``12.34``,
    ``7530``, ``1.23e-09``."""
    value = float(value)
    if not math.isfinite(value):
        return str(value)
    if value == 0:
        return "0"
    exp = math.floor(math.log10(abs(value)))
    if -3 <= exp < 5:
        text = f"{value:.{max(0, 3 - exp)}f}"
        # rounding may carry into a new digit (9.9996 -> "10.000"): one digit fewer then
        if len(text.lstrip("-").replace(".", "").lstrip("0")) > 4 and "." in text:
            text = text[:-1].rstrip(".")
        return text
    return f"{value:.2e}"


def _cell(text) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ").strip()


def _read(results_dir: Path):
    results_dir = Path(results_dir)
    with open(results_dir / "summary.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    machine = json.loads((results_dir / "machine.json").read_text())
    return rows, machine


def render(results_dir) -> str:
    """Markdown of the results in ``results_dir`` (``summary.csv``, ``machine.json``)."""
    rows, m = _read(results_dir)
    dates = m.get("dates") or {}
    when = sorted(set(dates.values()) - {""}) or [m.get("date")]
    span = when[0] if len(when) == 1 else f"{when[0]} to {when[-1]} (each table's date below)"
    lines = [f"Measured on {m.get('cpu')}, {m.get('cores')} cores, {span}; "
             f"casadi {m.get('casadi')}, numpy {m.get('numpy')}, scipy {m.get('scipy')}, "
             f"IPOPT linear solver {m.get('ipopt_linear_solver')}; "
             "regenerate with `make bench`."]
    head = glance(rows)
    lines += [""] + head if head else []
    names = list(dict.fromkeys(r["benchmark"] for r in rows))
    order = list(TITLES)
    names = sorted(names, key=lambda b: (order.index(b) if b in order else len(order),
                                         names.index(b)))
    for bench in names:
        dated = f", {dates[bench]}" if len(when) > 1 and dates.get(bench) else ""
        lines += ["", f"**{TITLES.get(bench, f'`bench/{bench}.py`')}**{dated}", "",
                  "| case | metric | value | note |", "| --- | --- | ---: | --- |"]
        for r in rows:
            if r["benchmark"] != bench:
                continue
            value = format_value(r["value"]) + (f" {r['unit']}" if r.get("unit") else "")
            lines.append(f"| {_cell(r['case'])} | {_cell(r['metric'])} | {_cell(value)} | "
                         f"{_cell(r.get('note', ''))} |")
    return "\n".join(lines) + "\n"


def _marked(path: Path, text: str) -> tuple[int, int]:
    """Where the generated part of ``text`` (read from ``path``) starts and ends."""
    i, j = text.find(BEGIN), text.find(END)
    if i < 0 or j < i:
        raise ValueError(f"`page_path` {path} has no {BEGIN} ... {END} markers")
    return i + len(BEGIN), j


def update_page(page_path, results_dir) -> bool:
    """Replace the text between `BEGIN` and `END` in ``page_path`` by
    ``render(results_dir)``; True when the file changed. Raises ``ValueError`` when the
    markers are missing."""
    path = Path(page_path)
    text = path.read_text()
    i, j = _marked(path, text)
    new = text[:i] + "\n" + render(results_dir) + text[j:]
    if new != text:
        path.write_text(new)
    return new != text


#: the former name of `update_page` (the tables were in the README)
update_readme = update_page


def current(page_path) -> str:
    """The generated text now between the markers of ``page_path`` (what `render` gave when
    it was last regenerated)."""
    path = Path(page_path)
    text = path.read_text()
    i, j = _marked(path, text)
    return text[i:j].removeprefix("\n")
