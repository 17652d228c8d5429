"""Trajectory benchmark: the four-phase Delta III ascent to GTO, appdyn next to yapss and ASSET.

appdyn (`problems.ascent.delta3_ascent`, `ocp.solve_phases`: Radau degree 5 per phase) is run
in this process; yapss 0.2.3 (its own example ``yapss.examples.delta_iii_ascent``: LGL, 5
segments x 5 points per phase, SI units with its own scaling) in its own venv
``bench/peers/.venv-yapss`` (yapss pins casadi <= 3.7.2; ``bash bench/peers/setup_yapss.sh``),
through ``bench/peers/yapss_delta3.py``, skipped with a notice when that venv is missing.
ASSET 0.5.1 (its own Delta III formulation: LGL3, 16, 32 and 64 segments per phase, PSIOPT,
one thread like IPOPT with MUMPS) in ``bench/peers/.venv-asset``
(``bash bench/peers/setup_asset.sh``) through ``bench/peers/asset_delta3.py``, likewise.

Rows (each timed: first call of the process, then the median of the repeats):

* appdyn, 5 intervals of Radau degree 5 per phase (yapss's mesh: 5 x 5 LGL), no refinement, from the
  relaxed start (`delta3_ascent`'s default);
* the solve before issue 32: 8 intervals of Radau degree 4 per phase, |u| = 1 from the guess
  (``relaxed_start=False``);
* appdyn, default: 5 intervals per phase refined until every interval's estimated error is
  below 1e-9 (the converged answer: the reference for the "error" column);
* yapss example (solve = derivative construction + IPOPT; its process import excluded);
* ASSET, 16/32/64 segments (solve = ``solve_optimize``; build = the phases set up). Its
  error is against its own 64-segment answer (ASSET's rounded Isp values move its optimum
  to 7529.7485 kg).

Error = |final mass - converged appdyn answer| [kg]; the published optimum is 7529.712412 kg
(Betts 2010), 7529.712287 kg (yapss's test). Writes ``ascent.csv`` into the output folder
and returns the summary rows (`run`): final mass, its distance to Betts (2010), the coarse
mesh's error, wall times, and the yapss ratio when yapss ran.
Run: ``make bench`` or ``appdyn bench ascent`` (``--quick``: first calls only, no yapss).
"""
from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from appdyn.dynamics import clear_caches
from appdyn.problems.ascent import delta3_ascent
from appdyn.problems.ascent.delta3 import FINAL_MASS_BETTS

from _common import Row, script_main, write_csv

PEERS = Path(__file__).resolve().parent / "peers"
YAPSS_PY = PEERS / ".venv-yapss" / "bin" / "python"
ASSET_PY = PEERS / ".venv-asset" / "bin" / "python"


def appdyn_runs(repeats: int, **kw):
    """``(first-call wall time, later wall times, last result)``; caches emptied first."""
    clear_caches()
    t0 = time.perf_counter()
    res = delta3_ascent(**kw)
    first = time.perf_counter() - t0
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = delta3_ascent(**kw)
        times.append(time.perf_counter() - t0)
    return first, np.array(times or [first]), res


def yapss_runs(repeats: int):
    """yapss's answers (one fresh process per run), or None with a notice."""
    if not YAPSS_PY.exists():
        print(f"yapss: no {YAPSS_PY.parent.parent} (bash bench/peers/setup_yapss.sh); skipped")
        return None
    out = []
    for _ in range(max(repeats, 1)):
        proc = subprocess.run([str(YAPSS_PY), str(PEERS / "yapss_delta3.py"), "--json", "--quiet"],
                              capture_output=True, text=True, timeout=600)
        if proc.returncode:
            print(f"yapss: peer failed: {proc.stderr.strip().splitlines()[-1:]}; skipped")
            return None
        out.append(json.loads(proc.stdout))
    return out


def asset_runs(repeats: int):
    """ASSET's answers at 16/32/64 segments per phase (one process), or None with a notice."""
    if not ASSET_PY.exists():
        print(f"ASSET: no {ASSET_PY.parent.parent} (bash bench/peers/setup_asset.sh); skipped")
        return None
    proc = subprocess.run([str(ASSET_PY), str(PEERS / "asset_delta3.py"), "--json", "--threads", "1",
                           "--repeats", str(max(repeats, 1))],
                          capture_output=True, text=True, timeout=1200)
    if proc.returncode:
        print(f"ASSET: peer failed: {proc.stderr.strip().splitlines()[-1:]}; skipped")
        return None
    return json.loads(proc.stdout)


def run(quick: bool, out: Path) -> list:
    """Run the benchmark, write ``ascent.csv`` into ``out``; the summary `Row`s."""
    repeats = 0 if quick else 5
    rows = []
    f_c, t_c, coarse = appdyn_runs(repeats, refine_tol=None)
    f_r, t_r, refined = appdyn_runs(repeats)
    f_o, t_o, cold = appdyn_runs(repeats, refine_tol=None, relaxed_start=False, N=8, degree=4)
    ref = refined.final_mass
    for label, first, times, res in (("appdyn, 5 x Radau-5 per phase", f_c, t_c, coarse),
                                     ("appdyn, refined to 1e-9", f_r, t_r, refined),
                                     ("appdyn before: 8 x Radau-4, no relaxed start", f_o, t_o, cold)):
        sol = res.solution
        rows.append(dict(solver=label, final_mass=res.final_mass, error=abs(res.final_mass - ref),
                         final_time=res.final_time, first_call=first, wall=float(np.median(times)),
                         build=res.build_time, solve=res.solve_time, iterations=res.iterations,
                         intervals="/".join(str(s.mesh.N) for s in sol.phases),
                         success=res.success))
    peer = None if quick else yapss_runs(repeats)
    if quick:
        print("yapss, ASSET: skipped (--quick)")
    if peer:
        walls = np.array([p["solve_time"] for p in peer])
        rows.append(dict(solver=f"yapss {peer[0]['yapss']} (casadi {peer[0]['casadi']})",
                         final_mass=peer[0]["final_mass"], error=abs(peer[0]["final_mass"] - ref),
                         final_time=peer[0]["phase_end_times"][-1], first_call=float(walls[0]),
                         wall=float(np.median(walls)), build=float("nan"),
                         solve=float(np.median(walls)), iterations=peer[0]["iterations"],
                         intervals="5/5/5/5 (LGL 5 points)",
                         success=peer[0]["status"].startswith("Optimal")))
    asset = None if quick else asset_runs(repeats)
    if asset:
        own = asset["runs"][-1]["final_mass"]  # its finest mesh: ASSET's own converged answer
        for r in asset["runs"]:
            n = r["segments"]
            rows.append(dict(solver=f"ASSET {asset['asset']}, {n} x LGL3 per phase",
                             final_mass=r["final_mass"], error=abs(r["final_mass"] - own),
                             final_time=r["final_time"], first_call=r["first_solve_time"],
                             wall=r["build_time"] + r["solve_time"], build=r["build_time"],
                             solve=r["solve_time"], iterations=r["iterations"],
                             intervals=f"{n}/{n}/{n}/{n} (LGL3)", success=r["status"] == "CONVERGED"))
    print("Delta III ascent to GTO (maximum final mass), 4 phases; published 7529.712412 kg "
          "(Betts 2010), 7529.712287 kg (yapss)")
    print(f"{'solver':<40}{'final mass [kg]':>17}{'error [kg]':>12}{'tf [s]':>10}{'first [s]':>11}"
          f"{'median [s]':>12}{'build [s]':>11}{'solve [s]':>11}{'iter':>6}  intervals")
    for r in rows:
        print(f"{r['solver']:<40}{r['final_mass']:>17.6f}{r['error']:>12.1e}{r['final_time']:>10.3f}"
              f"{r['first_call']:>11.3f}{r['wall']:>12.3f}{r['build']:>11.3f}{r['solve']:>11.3f}"
              f"{r['iterations']:>6}  {r['intervals']}")
    print(f"converged appdyn answer - Betts (2010): {ref - FINAL_MASS_BETTS:+.2e} kg")
    for r in rows[:3]:
        for p in rows[3:]:
            print(f"{p['solver']} median / {r['solver']} median: {p['wall'] / r['wall']:.2f}x")
    path = write_csv(rows, Path(out) / "ascent.csv")
    print(f"written: {path}")
    return summary_rows(rows, ref, repeats)


def summary_rows(rows, ref, repeats):
    """Final mass, error and wall times of each solver; the peers' time over appdyn's."""
    case = "Delta III ascent to GTO, 4 phases"
    how = f"median of {repeats}" if repeats else "one call"
    out = [Row("ascent", case, "final mass, refined", ref, "kg",
               f"{ref:.6f} kg; Betts (2010): 7529.712412 kg"),
           Row("ascent", case, "final mass - Betts (2010)", ref - FINAL_MASS_BETTS, "kg")]
    for r in rows:
        ok = "" if r["success"] else "; NOT successful"
        if r is not rows[1]:
            what = "vs ASSET's 64-segment answer" if r["solver"].startswith("ASSET") else \
                "vs the refined answer"
            out.append(Row("ascent", case, f"error, {r['solver']}", r["error"], "kg",
                           f"final mass {r['final_mass']:.6f} kg; {what}{ok}"))
        out.append(Row("ascent", case, f"wall time, {r['solver']}", r["wall"], "s",
                       f"{how}; " + (f"first call {r['first_call']:.3g} s; " if repeats else "")
                       + f"build {r['build']:.3g} s, solve {r['solve']:.3g} s; "
                       f"{r['iterations']} iterations; intervals {r['intervals']}{ok}"))
    peers = {r["solver"]: r for r in rows[3:]}
    pairs = [(rows[0], p) for p in peers if "yapss" in p or ", 32 x" in p]
    pairs += [(rows[1], p) for p in peers if "yapss" in p or ", 64 x" in p]
    pairs += [(rows[2], p) for p in peers if ", 32 x" in p]
    for r, p in pairs:
        out.append(Row("ascent", case, f"{p} / {r['solver']}", peers[p]["wall"] / r["wall"], "x",
                       "wall-time ratio in one run (> 1: appdyn faster)"))
    return out


def main(argv=None) -> int:
    return script_main(run, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
