"""Literature cases of trajectory optimization, appdyn next to ASSET: Bryson & Ho's orbit
raising with the thrust direction a unit vector (`ocp.examples.orbit_raising`, literature
optimum 1.5253).

appdyn (`ocp.solve`, Radau degree 3, its default start) on 20 and 40 intervals, in this
process; ASSET 0.5.1 (LGL3, 20/40/80/160 segments, PSIOPT on one thread) in its own venv
(``bash bench/peers/setup_asset.sh``) through ``bench/peers/asset_orbit_raising.py``,
skipped with a notice when that venv is missing. Each round calls every solver once, back
to back (ASSET in a fresh process), so the ratios are medians of per-round ratios. The error
of every row is against appdyn on 160 intervals (1.5252777; the literature agrees on 1.5253).
Writes ``literature.csv``; returns the summary rows (`run`).
Run: ``appdyn bench literature`` (``--quick``: one round, no ASSET).
"""
from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from appdyn.dynamics import clear_caches
from appdyn.ocp import solve
from appdyn.ocp.examples import ORBIT_RAISING_OPTIMUM, orbit_raising

from _common import Row, script_main, write_csv

PEERS = Path(__file__).resolve().parent / "peers"
ASSET_PY = PEERS / ".venv-asset" / "bin" / "python"
CASE = "orbit raising (Bryson & Ho), thrust a unit vector"
MESHES = (20, 40)


def appdyn_round() -> dict:
    out = {}
    for N in MESHES:
        t0 = time.perf_counter()
        sol = solve(orbit_raising(), N=N)
        wall = time.perf_counter() - t0
        label = f"appdyn, {N} x Radau-3"
        out[label] = dict(solver=label, objective=sol.cost, wall=wall, build=sol.build_time,
                          solve=sol.solve_time, iterations=sol.iterations, success=sol.success)
    return out


def asset_round() -> dict:
    if not ASSET_PY.exists():
        print(f"ASSET: no {ASSET_PY.parent.parent} (bash bench/peers/setup_asset.sh); skipped")
        return {}
    proc = subprocess.run([str(ASSET_PY), str(PEERS / "asset_orbit_raising.py"), "--json",
                           "--threads", "1", "--repeats", "1", "--segments", "20", "40", "80", "160"],
                          capture_output=True, text=True, timeout=600)
    if proc.returncode:
        print(f"ASSET: peer failed: {proc.stderr.strip().splitlines()[-1:]}; skipped")
        return {}
    a = json.loads(proc.stdout)
    out = {}
    for r in a["runs"]:
        label = f"ASSET {a['asset']}, {r['segments']} x LGL3"
        out[label] = dict(solver=label, objective=r["r_f"], wall=r["build_time"] + r["solve_time"],
                          build=r["build_time"], solve=r["solve_time"], iterations=r["iterations"],
                          success=r["status"] == "CONVERGED")
    return out


def run(quick: bool, out: Path) -> list:
    """Run the benchmark, write ``literature.csv`` into ``out``; the summary `Row`s."""
    repeats = 0 if quick else 5
    ref = solve(orbit_raising(), N=160).cost
    clear_caches()
    rounds = []
    for _ in range(repeats + 1):
        r = appdyn_round()
        if not quick:
            r.update(asset_round())
        rounds.append(r)
    later = rounds[1:] or rounds
    rows = []
    for label, last in rounds[-1].items():
        row = dict(last, error=abs(last["objective"] - ref), first_call=rounds[0][label]["wall"],
                   wall=float(np.median([r[label]["wall"] for r in later])))
        rows.append(row)
    print(f"{CASE}: maximum final radius; literature {ORBIT_RAISING_OPTIMUM['r_f']}, "
          f"appdyn on 160 intervals {ref:.7f}")
    print(f"{'solver':<28}{'r_f':>12}{'error':>10}{'first [s]':>11}{'median [s]':>12}"
          f"{'build [s]':>11}{'solve [s]':>11}{'iter':>6}")
    for r in rows:
        print(f"{r['solver']:<28}{r['objective']:>12.7f}{r['error']:>10.1e}{r['first_call']:>11.3f}"
              f"{r['wall']:>12.3f}{r['build']:>11.3f}{r['solve']:>11.3f}{r['iterations']:>6}")
    summary = [Row("literature", CASE, "final radius, appdyn on 160 intervals", ref, "r0",
                   f"literature {ORBIT_RAISING_OPTIMUM['r_f']}")]
    how = f"median of {repeats}" if repeats else "one call"
    for r in rows:
        ok = "" if r["success"] else "; NOT successful"
        summary.append(Row("literature", CASE, f"error, {r['solver']}", r["error"], "r0",
                           f"r_f = {r['objective']:.7f}{ok}"))
        summary.append(Row("literature", CASE, f"wall time, {r['solver']}", r["wall"], "s",
                           f"{how}; build {r['build']:.3g} s, solve {r['solve']:.3g} s; "
                           f"{r['iterations']} iterations{ok}"))
    for a in (f"appdyn, {N} x Radau-3" for N in MESHES):
        for p in (k for k in rounds[-1] if k.startswith("ASSET")):
            x = float(np.median([r[p]["wall"] / r[a]["wall"] for r in later]))
            print(f"{p} / {a}: {x:.2f}x")
            summary.append(Row("literature", CASE, f"{p} / {a}", x, "x",
                               "wall-time ratio, median over rounds (> 1: appdyn faster)"))
    path = write_csv(rows, Path(out) / "literature.csv")
    print(f"written: {path}")
    return summary


def main(argv=None) -> int:
    return script_main(run, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
