"""``appdyn bench [NAME ...]``: run the scripts in the source checkout's ``bench/`` folder."""
from __future__ import annotations

import runpy
import sys
from pathlib import Path

__all__ = ["add_parser", "check", "run", "BENCH_DIR"]

#: the benchmark scripts, next to the packages in a source checkout
BENCH_DIR = Path(__file__).resolve().parents[2] / "bench"


def add_parser(subparsers):
    """Add ``bench`` to ``subparsers``."""
    bench = subparsers.add_parser("bench", help="run benchmarks from the bench/ folder")
    bench.set_defaults(_parser=bench)
    bench.add_argument("names", nargs="*", help="benchmark names (default: all), e.g. simulate")
    return bench


def check(parser, args) -> None:
    """Nothing to check across options (names are checked by `run`)."""


def run(args) -> int:
    """Run the named benchmarks (all by default); 2 for a missing folder or unknown names."""
    if not BENCH_DIR.is_dir():
        print(f"appdyn: error: no bench/ folder next to the package ({BENCH_DIR}); "
              "benchmarks run from a source checkout", file=sys.stderr)
        return 2
    available = sorted(p.stem for p in BENCH_DIR.glob("*.py") if not p.stem.startswith("_"))
    names = args.names or available
    unknown = sorted(set(names) - set(available))
    if unknown:
        print(f"appdyn: error: unknown benchmark(s) {unknown}; available: {available}",
              file=sys.stderr)
        return 2
    for name in names:
        print(f"== bench/{name}.py ==", flush=True)
        runpy.run_path(str(BENCH_DIR / f"{name}.py"), run_name="__main__")
    return 0
