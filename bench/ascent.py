"""Trajectory benchmark: the four-phase Delta III ascent to GTO, appdyn next to yapss.

appdyn (`problems.ascent.delta3_ascent`, `ocp.solve_phases`: Radau degree 4 per phase) is run
in this process; yapss 0.2.3 (its own example ``yapss.examples.delta_iii_ascent``: LGL, 5
segments x 5 points per phase, SI units with its own scaling) in its own venv
``bench/peers/.venv-yapss`` (yapss pins casadi <= 3.7.2; ``bash bench/peers/setup_yapss.sh``),
through ``bench/peers/yapss_delta3.py``, skipped with a notice when that venv is missing.

Rows (each timed: first call of the process, then the median of the repeats):

* appdyn, 8 intervals per phase, no refinement (about the size of yapss's mesh);
* appdyn, default: 8 intervals per phase refined until every interval's estimated error is
  below 1e-9 (the converged answer: the reference for the "error" column);
* yapss example (solve = derivative construction + IPOPT; its process import excluded).

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


def run(quick: bool, out: Path) -> list:
    """Run the benchmark, write ``ascent.csv`` into ``out``; the summary `Row`s."""
    repeats = 0 if quick else 5
    rows = []
    f_c, t_c, coarse = appdyn_runs(repeats, refine_tol=None)
    f_r, t_r, refined = appdyn_runs(repeats)
    ref = refined.final_mass
    for label, first, times, res in (("appdyn, 8 x Radau-4 per phase", f_c, t_c, coarse),
                                     ("appdyn, refined to 1e-9", f_r, t_r, refined)):
        sol = res.solution
        rows.append(dict(solver=label, final_mass=res.final_mass, error=abs(res.final_mass - ref),
                         final_time=res.final_time, first_call=first, wall=float(np.median(times)),
                         iterations=sol.info.get("iterations", sol.iterations),
                         intervals="/".join(str(s.mesh.N) for s in sol.phases),
                         success=res.success))
    peer = None if quick else yapss_runs(repeats)
    if quick:
        print("yapss: skipped (--quick)")
    if peer:
        walls = np.array([p["solve_time"] for p in peer])
        rows.append(dict(solver=f"yapss {peer[0]['yapss']} (casadi {peer[0]['casadi']})",
                         final_mass=peer[0]["final_mass"], error=abs(peer[0]["final_mass"] - ref),
                         final_time=peer[0]["phase_end_times"][-1], first_call=float(walls[0]),
                         wall=float(np.median(walls)), iterations=peer[0]["iterations"],
                         intervals="5/5/5/5 (LGL 5 points)",
                         success=peer[0]["status"].startswith("Optimal")))
    print("Delta III ascent to GTO (maximum final mass), 4 phases; published 7529.712412 kg "
          "(Betts 2010), 7529.712287 kg (yapss)")
    print(f"{'solver':<38}{'final mass [kg]':>17}{'error [kg]':>12}{'tf [s]':>10}{'first [s]':>11}"
          f"{'median [s]':>12}{'iter':>6}  intervals")
    for r in rows:
        print(f"{r['solver']:<38}{r['final_mass']:>17.6f}{r['error']:>12.1e}{r['final_time']:>10.3f}"
              f"{r['first_call']:>11.3f}{r['wall']:>12.3f}{r['iterations']:>6}  {r['intervals']}")
    print(f"converged appdyn answer - Betts (2010): {ref - FINAL_MASS_BETTS:+.2e} kg")
    if peer:
        for r in rows[:2]:
            print(f"yapss median / {r['solver']} median: {rows[-1]['wall'] / r['wall']:.2f}x")
    path = write_csv(rows, Path(out) / "ascent.csv")
    print(f"written: {path}")
    return summary_rows(rows, ref, repeats)


def summary_rows(rows, ref, repeats):
    """Final mass, error and wall times of each solver; the yapss ratios."""
    case = "Delta III ascent to GTO, 4 phases"
    how = f"median of {repeats}" if repeats else "one call"
    out = [Row("ascent", case, "final mass, refined", ref, "kg",
               f"{ref:.6f} kg; Betts (2010): 7529.712412 kg"),
           Row("ascent", case, "final mass - Betts (2010)", ref - FINAL_MASS_BETTS, "kg")]
    for r in rows:
        ok = "" if r["success"] else "; NOT successful"
        if r is not rows[1]:
            out.append(Row("ascent", case, f"error, {r['solver']}", r["error"], "kg",
                           f"vs the refined answer{ok}"))
        out.append(Row("ascent", case, f"wall time, {r['solver']}", r["wall"], "s",
                       f"{how}; " + (f"first call {r['first_call']:.3g} s; " if repeats else "")
                       + f"{r['iterations']} iterations; "
                       f"intervals {r['intervals']}{ok}"))
    if len(rows) > 2:
        for r in rows[:2]:
            out.append(Row("ascent", case, f"speed-up vs yapss, {r['solver']}",
                           rows[-1]["wall"] / r["wall"], "x"))
    return out


def main(argv=None) -> int:
    return script_main(run, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
