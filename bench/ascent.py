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
* appdyn, default: 5 intervals per phase refined until every interval's estimated error is
  below 1e-9 (the converged answer: the reference for the "error" column; each round
  warm-started primal and dual from the last);
* the formulation before issue 32: 8 intervals of Radau degree 4 per phase, |u| = 1 from the
  guess (``relaxed_start=False``; the guess as it is now, with the last phase's duration);
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


#: appdyn's rows: label and `delta3_ascent` keywords
CONFIGS = (("appdyn, 5 x Radau-5 per phase", dict(refine_tol=None)),
           ("appdyn, refined to 1e-9", {}),
           ("appdyn, 8 x Radau-4, |u| = 1 from the guess",
            dict(refine_tol=None, relaxed_start=False, N=8, degree=4)))


def appdyn_round() -> dict:
    """One call of every appdyn row: ``{label: row dict}``."""
    out = {}
    for label, kw in CONFIGS:
        t0 = time.perf_counter()
        res = delta3_ascent(**kw)
        wall = time.perf_counter() - t0
        out[label] = dict(solver=label, final_mass=res.final_mass, final_time=res.final_time,
                          wall=wall, build=res.build_time, solve=res.solve_time,
                          iterations=res.iterations, success=res.success,
                          intervals="/".join(str(s.mesh.N) for s in res.solution.phases))
    return out


def _peer(python: Path, script: str, args: list, name: str, setup: str):
    """The JSON answer of one run of a peer in its own venv, or None with a notice."""
    if not python.exists():
        print(f"{name}: no {python.parent.parent} (bash bench/peers/{setup}); skipped")
        return None
    proc = subprocess.run([str(python), str(PEERS / script), *args], capture_output=True,
                          text=True, timeout=1200)
    if proc.returncode:
        print(f"{name}: peer failed: {proc.stderr.strip().splitlines()[-1:]}; skipped")
        return None
    return json.loads(proc.stdout)


def yapss_round() -> dict:
    """One fresh yapss process: ``{label: row dict}`` (empty when skipped)."""
    p = _peer(YAPSS_PY, "yapss_delta3.py", ["--json", "--quiet"], "yapss", "setup_yapss.sh")
    if p is None:
        return {}
    label = f"yapss {p['yapss']} (casadi {p['casadi']})"
    return {label: dict(solver=label, final_mass=p["final_mass"], final_time=p["phase_end_times"][-1],
                        wall=p["solve_time"], build=float("nan"), solve=p["solve_time"],
                        iterations=p["iterations"], intervals="5/5/5/5 (LGL 5 points)",
                        success=p["status"].startswith("Optimal"))}


def asset_round() -> dict:
    """One fresh ASSET process solving on 16, 32 and 64 segments: ``{label: row dict}``."""
    a = _peer(ASSET_PY, "asset_delta3.py", ["--json", "--threads", "1", "--repeats", "1"],
              "ASSET", "setup_asset.sh")
    out = {}
    for r in (a or {}).get("runs", []):
        n = r["segments"]
        label = f"ASSET {a['asset']}, {n} x LGL3 per phase"
        out[label] = dict(solver=label, final_mass=r["final_mass"], final_time=r["final_time"],
                          wall=r["build_time"] + r["solve_time"], build=r["build_time"],
                          solve=r["solve_time"], iterations=r["iterations"],
                          intervals=f"{n}/{n}/{n}/{n} (LGL3)", success=r["status"] == "CONVERGED")
    return out


def run(quick: bool, out: Path) -> list:
    """Run the benchmark, write ``ascent.csv`` into ``out``; the summary `Row`s.

    Every round calls each solver once, back to back (appdyn in this process, each peer in a
    fresh process), so a ratio is taken within a round (paired) and the load of a shared
    machine falls on both sides alike; round 0 starts from empty caches (first calls)."""
    repeats = 0 if quick else 5
    clear_caches()
    rounds = []
    for k in range(repeats + 1):
        r = appdyn_round()
        if not quick:
            r.update(yapss_round())
            r.update(asset_round())
        rounds.append(r)
    if quick:
        print("yapss, ASSET: skipped (--quick)")
    later = rounds[1:] or rounds
    ref = rounds[-1][CONFIGS[1][0]]["final_mass"]
    asset_ref = next((v["final_mass"] for k, v in rounds[-1].items() if ", 64 x" in k), None)
    rows = []
    for label, last in rounds[-1].items():
        row = dict(last)
        row.update(first_call=rounds[0][label]["wall"] if label in rounds[0] else float("nan"),
                   wall=float(np.median([r[label]["wall"] for r in later if label in r])),
                   error=abs(last["final_mass"] - (asset_ref if label.startswith("ASSET") else ref)))
        rows.append(row)
    ratios = {}
    for a_label, _ in CONFIGS:
        for p_label in rows[len(CONFIGS):]:
            p_label = p_label["solver"]
            ratios[(p_label, a_label)] = float(np.median(
                [r[p_label]["wall"] / r[a_label]["wall"] for r in later if p_label in r]))
    print("Delta III ascent to GTO (maximum final mass), 4 phases; published 7529.712412 kg "
          "(Betts 2010), 7529.712287 kg (yapss)")
    print(f"{'solver':<40}{'final mass [kg]':>17}{'error [kg]':>12}{'tf [s]':>10}{'first [s]':>11}"
          f"{'median [s]':>12}{'build [s]':>11}{'solve [s]':>11}{'iter':>6}  intervals")
    for r in rows:
        print(f"{r['solver']:<40}{r['final_mass']:>17.6f}{r['error']:>12.1e}{r['final_time']:>10.3f}"
              f"{r['first_call']:>11.3f}{r['wall']:>12.3f}{r['build']:>11.3f}{r['solve']:>11.3f}"
              f"{r['iterations']:>6}  {r['intervals']}")
    print(f"converged appdyn answer - Betts (2010): {ref - FINAL_MASS_BETTS:+.2e} kg")
    for (p, r), x in ratios.items():
        print(f"{p} / {r}: {x:.2f}x (median of the per-round ratios)")
    path = write_csv(rows, Path(out) / "ascent.csv")
    print(f"written: {path}")
    return summary_rows(rows, ref, repeats, ratios)


def summary_rows(rows, ref, repeats, ratios):
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
    wanted = [(p, CONFIGS[0][0]) for p, _ in ratios if "yapss" in p or ", 32 x" in p]
    wanted += [(p, CONFIGS[1][0]) for p, _ in ratios if "yapss" in p or ", 64 x" in p]
    wanted += [(p, CONFIGS[2][0]) for p, _ in ratios if ", 32 x" in p]
    for p, r in dict.fromkeys(wanted):
        out.append(Row("ascent", case, f"{p} / {r}", ratios[(p, r)], "x",
                       "wall-time ratio, median over rounds of back-to-back calls (> 1: appdyn "
                       "faster)"))
    return out


def main(argv=None) -> int:
    return script_main(run, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
