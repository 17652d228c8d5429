"""``appdyn bench [NAME ...] [--quick] [--out DIR] [--docs]``: run the benchmarks of the
source checkout's ``bench/`` folder.

Each ``bench/NAME.py`` (names starting with ``_`` are helpers) follows the protocol of
``bench/_common.py``: ``run(quick, out) -> list[Row]``. The runner imports each named
benchmark, calls ``run``, prints its summary rows and, at the end, one table of all of them;
it writes ``OUT/summary.csv`` (a partial run replaces only the rows of the benchmarks that
ran and keeps the others) and ``OUT/machine.json``. A benchmark that raises is reported in
one line on stderr and the others still run (exit status 1 then). ``--docs`` regenerates
the tables of the performance page, ``docs/performance.md``, from ``OUT``
(``bench/_readme.py``); ``--readme`` is its former name, kept as an alias.

Exit status: 0 all ran; 1 a benchmark raised (or returned no list of rows); 2 unknown names
or no ``bench/`` folder.
"""
from __future__ import annotations

import csv
import importlib
import importlib.util
import json
import os
import sys
import traceback
from dataclasses import asdict, fields, is_dataclass
from pathlib import Path

__all__ = ["add_parser", "check", "run", "BENCH_DIR", "PERFORMANCE_PAGE", "load", "read_summary",
           "merge_rows"]

#: the benchmark scripts, next to the packages in a source checkout
BENCH_DIR = Path(__file__).resolve().parents[2] / "bench"
#: where ``_common`` and ``_readme`` come from when BENCH_DIR has none (a test's fake folder)
_HOME_BENCH = BENCH_DIR
#: the page whose marked part ``--docs`` regenerates (the tables left the README for it)
PERFORMANCE_PAGE = BENCH_DIR.parent / "docs" / "performance.md"


def add_parser(subparsers):
    """Add ``bench`` to ``subparsers``."""
    bench = subparsers.add_parser(
        "bench", help="run benchmarks from the bench/ folder",
        description="Run the benchmarks of bench/ (all by default); write OUT/summary.csv and "
                    "OUT/machine.json; --docs regenerates the tables of docs/performance.md.",
        epilog="exit status: 0 all ran, 1 a benchmark raised, 2 unknown names or no bench/ folder")
    bench.set_defaults(_parser=bench)
    bench.add_argument("names", nargs="*", help="benchmark names (default: all), e.g. simulate")
    bench.add_argument("--quick", action="store_true",
                       help="a smoke run: fewer tolerances, repeats and peers (all together "
                            "in under two minutes)")
    bench.add_argument("--out", type=Path, default=None, metavar="DIR",
                       help="output folder (default: bench/results/)")
    bench.add_argument("--docs", "--readme", dest="docs", action="store_true",
                       help="regenerate the tables of the docs' performance page "
                            "(docs/performance.md) from the results; --readme is its "
                            "former name")
    return bench


def check(parser, args) -> None:
    """``--out`` must not be an existing file (names are checked by `run`)."""
    if args.out is not None and args.out.exists() and not args.out.is_dir():
        parser.error(f"argument --out: {str(args.out)!r} is a file, expected a folder")


def _helper(name):
    """``bench/_NAME.py`` as a module (``_common``, ``_readme``), with ``bench/`` importable."""
    for folder in (BENCH_DIR, _HOME_BENCH):
        if str(folder) not in sys.path:
            sys.path.insert(0, str(folder))
    return importlib.import_module(name)


def load(name):
    """Import ``BENCH_DIR/NAME.py`` (under the module name ``appdyn_bench_NAME``)."""
    _helper("_common")
    path = BENCH_DIR / f"{name}.py"
    spec = importlib.util.spec_from_file_location(f"appdyn_bench_{name}", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses and pickling look the module up there
    try:
        spec.loader.exec_module(module)
    except BaseException:
        sys.modules.pop(spec.name, None)
        raise
    return module


def _as_row(Row, r):
    """A `Row` of ``_common`` from any row-like object (dataclass or dict)."""
    data = asdict(r) if is_dataclass(r) else dict(r)
    names = [f.name for f in fields(Row)]
    data = {k: data[k] for k in names if k in data}
    data["value"] = float(data["value"])
    return Row(**data)


def read_summary(path: Path):
    """The `Row`s of an existing ``summary.csv`` (empty when missing)."""
    Row = _helper("_common").Row
    if not Path(path).is_file():
        return []
    with open(path, newline="") as fh:
        return [_as_row(Row, r) for r in csv.DictReader(fh)]


def merge_rows(old, new, ran):
    """``old`` rows of benchmarks not in ``ran``, then ``new``, grouped by benchmark in the
    order of first appearance (a benchmark's rows keep their order)."""
    rows = [r for r in old if r.benchmark not in ran] + list(new)
    order = list(dict.fromkeys(r.benchmark for r in rows))
    return sorted(rows, key=lambda r: order.index(r.benchmark))


def merged_dates(machine_path: Path, ran, date: str, present) -> dict:
    """``{benchmark: date of its rows}``: ``date`` for those in ``ran``, the earlier record
    (``machine.json``'s ``dates``, else its ``date``) for the others in ``present``."""
    old: dict = {}
    if Path(machine_path).is_file():
        previous = json.loads(Path(machine_path).read_text())
        old = dict(previous.get("dates") or {})
        old = {b: old.get(b, previous.get("date", "")) for b in present}
    return {b: (date if b in ran else old.get(b, "")) for b in sorted(present)}


def run(args) -> int:
    """Run the named benchmarks (all by default); see the module docstring for exit status."""
    if not BENCH_DIR.is_dir():
        print(f"appdyn: error: no bench/ folder next to the package ({BENCH_DIR}); "
              "benchmarks run from a source checkout", file=sys.stderr)
        return 2
    available = sorted(p.stem for p in BENCH_DIR.glob("*.py") if not p.stem.startswith("_"))
    names = list(dict.fromkeys(args.names)) or available
    unknown = sorted(set(names) - set(available))
    if unknown:
        print(f"appdyn: error: unknown benchmark(s) {unknown}; available: {available}",
              file=sys.stderr)
        return 2
    common = _helper("_common")
    out = Path(args.out) if args.out is not None else common.RESULTS
    out.mkdir(parents=True, exist_ok=True)
    new, ran, failed = [], set(), []
    for name in names:
        print(f"== bench/{name}.py{' --quick' if args.quick else ''} ==", flush=True)
        try:
            rows = load(name).run(args.quick, out)
            if not isinstance(rows, (list, tuple)):
                raise TypeError(f"run() returned {type(rows).__name__}, expected a list of Row")
            rows = [_as_row(common.Row, r) for r in rows]
        except Exception as exc:  # noqa: BLE001 - reported, the others still run
            failed.append(name)
            text = " ".join(str(exc).split())[:300]
            print(f"appdyn bench: {name} failed: {type(exc).__name__}: {text}", file=sys.stderr,
                  flush=True)
            if os.environ.get("APPDYN_TRACEBACK"):
                traceback.print_exc()
            continue
        ran.add(name)
        new += rows
        print(f"\n-- {name}: summary --")
        print(common.format_rows(rows), flush=True)
    summary = out / "summary.csv"
    rows = merge_rows(read_summary(summary), new, ran)
    if rows:
        common.write_rows(rows, summary)
    machine = common.machine()
    machine["dates"] = merged_dates(out / "machine.json", ran, machine["date"],
                                    {r.benchmark for r in rows})
    (out / "machine.json").write_text(json.dumps(machine, indent=2) + "\n")
    print("\n== summary ==")
    print(common.format_rows(new))
    print(f"wrote {summary} and {out / 'machine.json'}")
    if failed:
        kept = sorted({r.benchmark for r in rows} & set(failed))
        print(f"appdyn bench: {len(failed)} benchmark(s) failed: {', '.join(failed)}"
              + (f"; earlier rows of {', '.join(kept)} in summary.csv kept" if kept else ""),
              file=sys.stderr)
    if args.docs:
        _helper("_readme").update_page(PERFORMANCE_PAGE, out)
        print(f"updated the tables of {PERFORMANCE_PAGE}")
    return 1 if failed else 0
