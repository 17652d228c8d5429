"""Per-step cost of appdyn's compiled DOP853 (`cpass._DENSE` ``rk8_dense``, no check run, no
outputs but the end) against numbalsoda's ``dop853`` on the same casadi-generated C
right-hand side (`integrate_peers.peer_library`, which counts the peer's rhs calls), on
long runs at a fixed tolerance (10,000+ steps): the torque-free body and the wheel
spacecraft. Reports steps, rhs evaluations and time per step [us] on both sides (the least of
`REPEATS` runs, appdyn timed twice between three peer sessions: the loaded VM drifts, and
the least time of a CPU-bound run is the least disturbed).

Run: ``python bench/step_cost.py [--quick]``.
"""
from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

from appdyn.dynamics import rigid_body
from appdyn.dynamics.integrate.inputs import Problem, check_u
from appdyn.dynamics.integrate.stepcontrol import run_dense

from _common import Row, script_main, timed, write_csv
from integrate_peers import peer_library
from simulate import numbalsoda

REPEATS = 7
RTOL = 1e-10


def cases(quick: bool):
    """(name, model, x0, horizon [s]): long runs of 10,000+ steps at `RTOL`."""
    from workprecision import case_wheels

    w = case_wheels()
    scale = 0.1 if quick else 1.0
    return [("torque-free body (1, 2, 3)", rigid_body([1.0, 2.0, 3.0]),
             np.r_[0.0, 0.0, 0.0, 1.0, 1.0, 0.1, 0.8], 3000.0 * scale),
            ("wheel spacecraft", w.model, np.asarray(w.x0, float), 3000.0 * scale)]


def appdyn_side(model, x0, horizon, repeats):
    t = np.array([0.0, horizon])
    problem = Problem.new(model, x0, t, check_u(None, model.nu, t), np.asarray(
        getattr(model, "p_default", np.zeros(model.np)), float).ravel())
    atol = np.full(model.nx, RTOL / 100)

    def go():
        return run_dense(problem, RTOL, atol, 10**7)[0]

    run = go()
    return run, min(timed(go, repeats)[1])


def peer_side(lib, x0, horizon, repeats):
    ans = numbalsoda(dict(library=str(lib), t=[0.0, horizon], x0=list(map(float, x0)),
                          tols=[RTOL], repeats=repeats, solvers=["dop853"], mxstep=10**7))
    if ans is None:
        return None
    r = ans["runs"][0]
    return r, min(r["times"])


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
            d = dict(workload=name, horizon=horizon, rtol=RTOL, solver="appdyn rk8_dense",
                     steps=steps, rhs=mine.n_rhs, time=ta, us_per_step=ta / steps * 1e6,
                     message=mine.message)
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
    return rows


if __name__ == "__main__":
    sys.exit(script_main(run, sys.argv[1:]))
