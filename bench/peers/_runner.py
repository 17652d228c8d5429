"""What the peer runners share: C-level stdout sent to stderr (so stdout carries only JSON),
repeated runs with their median times, and the command line of the ASSET and rockit runners.

Imported by the runners of this folder (each run as a script in its own venv, so this folder
is on ``sys.path``); standard library only.
"""
from __future__ import annotations

import argparse
import contextlib
import ctypes
import json
import os
import statistics
import sys
import time

__all__ = ["stdout_to_stderr", "repeated", "main", "asset_main"]


@contextlib.contextmanager
def stdout_to_stderr():
    """Point file descriptor 1 at stderr (catches C-level printf from IPOPT too)."""
    libc = ctypes.CDLL(None)
    sys.stdout.flush()
    libc.fflush(None)
    saved = os.dup(1)
    os.dup2(2, 1)
    try:
        yield
    finally:
        sys.stdout.flush()
        libc.fflush(None)
        os.dup2(saved, 1)
        os.close(saved)


def repeated(run_one, sizes, repeats: int) -> list:
    """``run_one(size)`` (a dict with ``build_time`` and ``solve_time``) ``repeats`` times per
    size: the last run's dict with the median times and ``first_solve_time``."""
    runs = []
    for n in sizes:
        rs = [run_one(n) for _ in range(max(repeats, 1))]
        times = [r["solve_time"] for r in rs]
        out = dict(rs[-1])
        out.update(solve_time=float(statistics.median(times)), first_solve_time=times[0],
                   build_time=float(statistics.median(r["build_time"] for r in rs)))
        runs.append(out)
    return runs


def main(doc: str, run, sizes_flag: str, default_sizes, extra=None, repeats: int = 3) -> None:
    """The command line of a runner: ``--json``, ``--repeats``, the sizes under
    ``sizes_flag`` and the options ``extra(parser)`` adds; ``run(args)`` returns the JSON."""
    ap = argparse.ArgumentParser(description=doc.splitlines()[0])
    ap.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    ap.add_argument(sizes_flag, dest="sizes", type=int, nargs="+", default=list(default_sizes))
    ap.add_argument("--repeats", type=int, default=repeats)
    if extra:
        extra(ap)
    args = ap.parse_args()
    with stdout_to_stderr():
        out = run(args)
    if args.json:
        json.dump(out, sys.stdout)
        sys.stdout.write("\n")
    else:
        for r in out["runs"]:
            print(r)


def asset_solve(phase, threads: int | None, solve: str = "optimize") -> tuple:
    """Run an ASSET phase built just before: ``(final state, solve time [s], row)`` where
    ``row`` holds ``solve_time``, ``iterations`` and ``status`` for a runner's result."""
    if threads:
        phase.setThreads(threads, threads)
    t1 = time.perf_counter()
    flag = getattr(phase, solve)()
    solve_time = time.perf_counter() - t1
    last = phase.returnTraj()[-1]
    return last, {"solve_time": solve_time, "iterations": int(phase.optimizer.LastIterNum),
                  "status": str(getattr(flag, "name", flag))}


def asset_main(doc: str, run_one, default_sizes) -> None:
    """`main` of an ASSET runner: ``run_one(asset_asrl, segments, threads)`` per segment
    count (``--segments``), ``--threads`` (default: ASSET's own)."""
    def run(args) -> dict:
        from importlib.metadata import version

        import asset_asrl as ast

        runs = repeated(lambda n: run_one(ast, n, args.threads), args.sizes, args.repeats)
        return {"asset": version("asset-asrl"), "threads": args.threads, "runs": runs}

    def threads(ap) -> None:
        ap.add_argument("--threads", type=int, default=None,
                        help="ASSET's function and KKT threads (default: ASSET's own)")

    main(doc, run, "--segments", default_sizes, threads)
