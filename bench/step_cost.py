"""Per-step cost of appdyn's compiled DOP853 (`stepcontrol.plain_run`: `cpass._DENSE`, no
check run, no outputs but the end) against numbalsoda's ``dop853`` on the same casadi-generated C
right-hand side (`integrate_peers.peer_library`, which counts the peer's rhs calls), on
long runs at a fixed tolerance (10,000+ steps): the torque-free body and the wheel
spacecraft. Reports steps, rhs evaluations and time per step [us] on both sides (the least of
`REPEATS` runs, appdyn timed twice between three peer sessions: the loaded VM drifts, and
the least time of a CPU-bound run is the least disturbed).

Then the hinged scene's predictability (`hinged_divergence`): why `integrate_peers` runs
it 50 s.

Run: ``python bench/step_cost.py [--quick]``.
"""
from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

from appdyn.dynamics import rigid_body
from appdyn.dynamics.integrate.stepcontrol import plain_run

from _common import Row, script_main, timed, write_csv
from integrate_peers import peer_library
from simulate import numbalsoda

REPEATS = 7
RTOL = 1e-10


def cases(quick: bool):
    """(name, model, x0, horizon [s]): long runs of 6,000+ steps at `RTOL` (the hinged
    scene 50 s, within its predictability time: see `hinged_divergence`)."""
    from workprecision import case_hinged_scene, case_wheels

    w, h = case_wheels(), case_hinged_scene()
    scale = 0.1 if quick else 1.0
    return [("torque-free body (1, 2, 3)", rigid_body([1.0, 2.0, 3.0]),
             np.r_[0.0, 0.0, 0.0, 1.0, 1.0, 0.1, 0.8], 3000.0 * scale),
            ("wheel spacecraft", w.model, np.asarray(w.x0, float), 3000.0 * scale),
            ("hinged scene", h.model, np.asarray(h.x0, float), 50.0)]


def appdyn_side(model, x0, horizon, repeats):
    t = np.array([0.0, horizon])
    atol = np.full(model.nx, RTOL / 100)

    def go():
        return plain_run(model, x0, t, RTOL, atol, 10**7)

    run = go()
    return run, min(timed(go, repeats)[1])


def peer_side(lib, x0, horizon, repeats):
    ans = numbalsoda(dict(library=str(lib), t=[0.0, horizon], x0=list(map(float, x0)),
                          tols=[RTOL], repeats=repeats, solvers=["dop853"], mxstep=10**7))
    if ans is None:
        return None
    r = ans["runs"][0]
    return r, min(r["times"])


def dense_states(model, x0, t, rtol):
    """DOP853 with dense output at local tolerance ``rtol`` (``atol = rtol / 100``), no
    check: the states (nx, t.size)."""
    return plain_run(model, x0, t, rtol, np.full(model.nx, rtol / 100), 10**8).x


def hinged_divergence() -> list[Row]:
    """The hinged scene's predictability (`integrate_peers.workloads`): two runs from starts
    1e-10 apart (rtol 1e-13), their distance and its growth rate ``ln(d / d0) / t``; two
    references (rtol 1e-12, 1e-13) and the last time they agree to 1e-9."""
    from workprecision import case_hinged_scene

    c = case_hinged_scene()
    model, x0 = c.model, np.asarray(c.x0, float)
    t = np.linspace(0.0, 100.0, 401)
    d0 = np.random.default_rng(1).standard_normal(x0.size)
    d0 *= 1e-10 / np.linalg.norm(d0)
    a = dense_states(model, x0, t, 1e-13)
    d = np.linalg.norm(dense_states(model, x0 + d0, t, 1e-13) - a, axis=0)
    e = np.max(np.abs(dense_states(model, x0, t, 1e-12) - a), axis=0)
    agree = float(t[np.argmax(e > 1e-9)]) if (e > 1e-9).any() else float(t[-1])
    case = "hinged scene, starts 1e-10 apart"
    rows = [Row("step_cost", case, f"distance at {t[k]:g} s", float(d[k]), "",
                f"references differ by {e[k]:.2g}") for k in range(0, t.size, 40)]
    k60 = int(np.searchsorted(t, 60.0))
    rows.append(Row("step_cost", case, "growth rate ln(d/d0)/t over 0-60 s",
                    float(np.log(d[k60] / 1e-10) / t[k60]), "1/s", ""))
    rows.append(Row("step_cost", case, "references agree to 1e-9 until", agree, "s", ""))
    return rows


def run(quick: bool, out: Path) -> list[Row]:
    repeats = 3 if quick else REPEATS
    rows, detail = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for name, model, x0, horizon in cases(quick):
            lib = peer_library(model, Path(tmp) / f"peer_{len(detail)}.so")
            p1 = peer_side(lib, x0, horizon, repeats)
            mine, ta = appdyn_side(model, x0, horizon, repeats)
            p2 = peer_side(lib, x0, horizon, repeats)
            ta = min(ta, appdyn_side(model, x0, horizon, repeats)[1])
            p3 = peer_side(lib, x0, horizon, repeats)
            steps = mine.n_steps  # (accepted and rejected)
            d = dict(workload=name, horizon=horizon, rtol=RTOL, solver="appdyn dop853 (plain_run)",
                     steps=steps, rhs=mine.n_rhs, time=ta, us_per_step=ta / steps * 1e6,
                     message=mine.message if isinstance(mine.message, str) else mine.message())
            detail.append(d)
            rows.append(Row("step_cost", name, "appdyn time per step", d["us_per_step"], "us",
                            f"{steps} steps, {mine.n_rhs} rhs, {ta * 1e3:.3g} ms"))
            if p1 and p2 and p3:
                tp = min(p1[1], p2[1], p3[1])
                calls = p1[0].get("rhs_calls", -1)
                psteps = calls / 12.0  # (DOP853: 12 evaluations per step, FSAL)
                detail.append(dict(workload=name, horizon=horizon, rtol=RTOL,
                                   solver="numbalsoda dop853", steps=psteps, rhs=calls,
                                   time=tp, us_per_step=tp / psteps * 1e6, message=""))
                rows.append(Row("step_cost", name, "numbalsoda time per step",
                                tp / psteps * 1e6, "us",
                                f"{calls} rhs (~{psteps:.0f} steps), {tp * 1e3:.3g} ms"))
                rows.append(Row("step_cost", name, "appdyn per-step cost over numbalsoda's",
                                (ta / steps) / (tp / psteps), "x", "< 1: appdyn cheaper"))
    write_csv(detail, out / "step_cost.csv")
    return rows + ([] if quick else hinged_divergence())


if __name__ == "__main__":
    sys.exit(script_main(run, sys.argv[1:]))
