"""Literature cases of trajectory optimization, appdyn next to ASSET.

* Bryson & Ho's orbit raising with the thrust direction a unit vector
  (`ocp.examples.orbit_raising`, literature 1.5253): appdyn (`ocp.solve`, Radau degree 3,
  its default start) on 20 and 40 intervals; ASSET LGL3 on 20-160 segments
  (``bench/peers/asset_orbit_raising.py``).
  rockit 0.6.7 (DirectCollocation, N = 20, its own start) in ``bench/peers/.venv-rockit``
  (``bash bench/peers/setup_rockit.sh``; ``bench/peers/rockit_literature.py``).
* Betts' shuttle reentry, maximum crossrange (`ocp.examples.shuttle_reentry`, 34.1412 deg):
  appdyn on 20 intervals of Radau degree 5 from `shuttle_reentry_guess` (ASSET's start);
  ASSET as its own example, LGL3 on 32-128 segments (``bench/peers/asset_reentry.py``);
  rockit (DirectCollocation, N = 20) from the same straight-line start (its IPOPT ends
  ``Infeasible_Problem_Detected`` there: run once, its row marked not successful).

appdyn runs in this process; ASSET 0.5.1 (PSIOPT on one thread) in its own venv
(``bash bench/peers/setup_asset.sh``), skipped with a notice when that venv is missing.
Each round calls every solver once, back to back (ASSET in a fresh process), so the ratios
are medians of per-round ratios. The error of every row is against appdyn on a fine mesh
(the reference row).
Writes ``literature.csv``; returns the summary rows (`run`).
Run: ``appdyn bench literature`` (``--quick``: one round, no ASSET).
"""
from __future__ import annotations

import math
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from appdyn.dynamics import clear_caches
from appdyn.ocp import solve
from appdyn.ocp.examples import (ORBIT_RAISING_OPTIMUM, SHUTTLE_REENTRY_OPTIMUM, orbit_raising,
                                 shuttle_reentry, shuttle_reentry_guess)

from _common import Row, run_peer, script_main, write_csv



@dataclass(frozen=True)
class Case:
    """One literature case: appdyn's solves (label -> keywords of `ocp.solve`), the
    reference solve, ASSET's runner and segment counts, and the objective's unit."""

    name: str
    problem: Callable
    guess: Callable | None
    appdyn: tuple
    reference: dict
    asset_script: str
    asset_segments: tuple
    asset_key: str
    unit: str
    scale: float  # appdyn objective -> the unit
    literature: str
    rockit: str | None = None  # the case of bench/peers/rockit_literature.py


CASES = (
    Case("orbit raising (Bryson & Ho), thrust a unit vector", orbit_raising, None,
         (("appdyn, 20 x Radau-3", dict(N=20)), ("appdyn, 40 x Radau-3", dict(N=40))),
         dict(N=160), "asset_orbit_raising.py", (20, 40, 80, 160), "r_f", "r0", 1.0,
         f"literature {ORBIT_RAISING_OPTIMUM['r_f']}", rockit="orbit_raising"),
    Case("shuttle reentry (Betts), maximum crossrange", shuttle_reentry, shuttle_reentry_guess,
         (("appdyn, 20 x Radau-5", dict(N=20, degree=5)),),
         dict(N=80, degree=5), "asset_reentry.py", (32, 64, 128), "theta_f_deg", "deg",
         180.0 / math.pi, f"literature {SHUTTLE_REENTRY_OPTIMUM['theta_f_deg']} deg (Betts 2010)",
         rockit="reentry"),
)

#: rockit outcomes that failed, by case: a failed peer is run once, not every round (from the
#: straight-line start of the reentry rockit's IPOPT ends Infeasible_Problem_Detected after
#: ~2200 iterations, ~50 s)
_ROCKIT_FAILED: dict = {}


def appdyn_round(case: Case) -> dict:
    out = {}
    for label, kw in case.appdyn:
        t0 = time.perf_counter()
        guess = case.guess() if case.guess else None
        sol = solve(case.problem(), guess=guess, **kw)
        wall = time.perf_counter() - t0
        out[label] = dict(solver=label, objective=sol.cost * case.scale, wall=wall,
                          build=sol.build_time, solve=sol.solve_time, iterations=sol.iterations,
                          success=sol.success)
    return out


def asset_round(case: Case) -> dict:
    a = run_peer("asset", case.asset_script, ["--threads", 1, "--repeats", 1, "--segments",
                                               *case.asset_segments])
    if a is None:
        return {}
    out = {}
    for r in a["runs"]:
        label = f"ASSET {a['asset']}, {r['segments']} x LGL3"
        out[label] = dict(solver=label, objective=r[case.asset_key],
                          wall=r["build_time"] + r["solve_time"], build=r["build_time"],
                          solve=r["solve_time"], iterations=r["iterations"],
                          success=r["status"] == "CONVERGED")
    return out


def rockit_round(case: Case) -> dict:
    """rockit (DirectCollocation, N = 20) in a fresh process of its own venv, or nothing; a
    failed outcome is run once and repeated in later rounds (`_ROCKIT_FAILED`)."""
    if case.rockit is None:
        return {}
    if case.rockit in _ROCKIT_FAILED:
        return {k: dict(v, reused=True) for k, v in _ROCKIT_FAILED[case.rockit].items()}
    a = run_peer("rockit", "rockit_literature.py", ["--case", case.rockit, "--N", 20])
    if a is None:
        return {}
    out = {}
    for r in a["runs"]:
        label = f"rockit {a['rockit']}, {r['N']} x Radau-4"
        out[label] = dict(solver=label, objective=r["objective"],
                          wall=r["build_time"] + r["solve_time"], build=r["build_time"],
                          solve=r["solve_time"], iterations=r["iterations"],
                          success=r["status"] == "Solve_Succeeded")
    if not all(r["success"] for r in out.values()):
        _ROCKIT_FAILED[case.rockit] = out
    return out


def run_case(case: Case, quick: bool, repeats: int) -> list:
    """The rows of one case (printed) and its summary `Row`s."""
    ref_sol = solve(case.problem(), guess=case.guess() if case.guess else None, **case.reference)
    ref = ref_sol.cost * case.scale
    clear_caches()
    rounds = []
    for _ in range(repeats + 1):
        r = appdyn_round(case)
        if not quick:
            r.update(asset_round(case))
            r.update(rockit_round(case))
        rounds.append(r)
    later = rounds[1:] or rounds
    rows = []
    for label, last in rounds[-1].items():
        rows.append(dict(last, case=case.name, error=abs(last["objective"] - ref),
                         first_call=rounds[0][label]["wall"],
                         wall=float(np.median([r[label]["wall"] for r in later]))))
    print(f"\n{case.name}: {case.literature}; appdyn reference {case.reference} {ref:.7f} {case.unit}")
    print(f"{'solver':<28}{'objective':>13}{'error':>10}{'first [s]':>11}{'median [s]':>12}"
          f"{'build [s]':>11}{'solve [s]':>11}{'iter':>6}")
    for r in rows:
        print(f"{r['solver']:<28}{r['objective']:>13.7f}{r['error']:>10.1e}{r['first_call']:>11.3f}"
              f"{r['wall']:>12.3f}{r['build']:>11.3f}{r['solve']:>11.3f}{r['iterations']:>6}")
    summary = [Row("literature", case.name, f"objective, appdyn reference {case.reference}", ref,
                   case.unit, f"{ref:.7f}; {case.literature}; success {ref_sol.success}")]
    how = f"median of {repeats}" if repeats else "one call"
    for r in rows:
        ok = "" if r["success"] else "; NOT successful"
        summary.append(Row("literature", case.name, f"error, {r['solver']}", r["error"], case.unit,
                           f"objective {r['objective']:.7f}{ok}"))
        once = "one run (failed: not repeated)" if r.get("reused") else how
        summary.append(Row("literature", case.name, f"wall time, {r['solver']}", r["wall"], "s",
                           f"{once}; build {r['build']:.3g} s, solve {r['solve']:.3g} s; "
                           f"{r['iterations']} iterations{ok}"))
    for a, _ in case.appdyn:
        for p in (k for k in rounds[-1] if not k.startswith("appdyn")):
            x = float(np.median([r[p]["wall"] / r[a]["wall"] for r in later]))
            print(f"{p} / {a}: {x:.2f}x")
            summary.append(Row("literature", case.name, f"{p} / {a}", x, "x",
                               "wall-time ratio, median over rounds (> 1: appdyn faster)"))
    return rows, summary


def run(quick: bool, out: Path) -> list:
    """Run the benchmark, write ``literature.csv`` into ``out``; the summary `Row`s."""
    repeats = 0 if quick else 5
    rows, summary = [], []
    for case in CASES:
        r, s = run_case(case, quick, repeats)
        rows += r
        summary += s
    path = write_csv(rows, Path(out) / "literature.csv")
    print(f"written: {path}")
    return summary


def main(argv=None) -> int:
    return script_main(run, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
