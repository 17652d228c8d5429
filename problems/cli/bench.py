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
    bench.add_argument("--quick", action="store_true",
                       help="a smoke run: fewer tolerances and repeats (passed to each script)")
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
    argv = sys.argv
    try:
        for name in names:
            print(f"== bench/{name}.py ==", flush=True)
            sys.argv = [str(BENCH_DIR / f"{name}.py")] + (["--quick"] if args.quick else [])
            runpy.run_path(sys.argv[0], run_name="__main__")
    finally:
        sys.argv = argv
    return 0
