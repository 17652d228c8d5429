"""Trust benchmark: the cases a new user met in the first hour (issue "Trust, round two"),
timed as a user meets them -- each case in a fresh process, first call included.

Cases (every number from an actual run, checked against what the user asked):

* ``new user's slew`` -- `appdyn.problems.slew.time_optimal` of a body with products of
  inertia, pi/2 rad about (0, 1, 1)/sqrt 2, ``u_max = (0.5, 0.5, 0.3)`` N m, default options
  (three seeded starts, the switch-time polish where it applies), for two inertias: wall
  time, ``T``, ``success``, and the peak of ``|u| / u_max`` on a 20 001-point grid of the
  returned ``sample()`` (at most 1 for an answer that keeps its bounds);
* ``saturated wheel slew`` -- a reaction-wheel spacecraft under a saturated PD law (a CasADi
  ``fmin``/``fmax`` on the torque; the most common GNC simulation), 60 s, 121 outputs,
  ``simulate`` at its default method with ``rtol=1e-6``: first call (compiles), the median
  of 5 later calls, ``status``, and the largest error against scipy's DOP853 at rtol 1e-13
  (atol 1e-16) in units of the asked tolerance ``atol + rtol |x|``;
* ``bang-bang callable`` -- a rigid body under a bang-bang torque given as a Python
  callable, rtol 1e-6: wall time and status.

Before and after: with the environment variable ``APPDYN_BENCH_BASELINE`` naming the root of
another source checkout of appdyn (an older commit: ``git worktree add DIR COMMIT``), each
case also runs there, in its own process with that checkout first on ``sys.path``, in the
same session, and the rows say ``before`` / ``after``. Older checkouts import the packages
as ``dynamics``/``problems``; the case script accepts both layouts.

Writes ``trust.csv`` into the output folder and returns summary rows.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

from _common import Row, script_main, write_csv

NAME = "trust"

#: the case script, run in a fresh process; prints one JSON line
_CASES = textwrap.dedent('''
    import json, math, sys, time
    import numpy as np
    import importlib, os
    # the baseline checkout first on sys.path: its own packages (older ones are top-level)
    prefixes = ("", "appdyn.") if os.environ.get("APPDYN_BENCH_SIDE") == "before" else ("appdyn.", "")
    for prefix in prefixes:
        try:
            dyn = importlib.import_module(prefix + "dynamics")
            break
        except ImportError:
            continue
    closed_loop, rigid_body, simulate = dyn.closed_loop, dyn.rigid_body, dyn.simulate
    quat_conj, quat_mul = dyn.attitude.quat_conj, dyn.attitude.quat_mul
    wheel_spacecraft = dyn.wheel_spacecraft
    slew = importlib.import_module(prefix + "problems.slew")
    import casadi as ca
    from scipy.integrate import solve_ivp

    case = sys.argv[1]
    out = {}
    if case.startswith("slew"):
        inertia = {"slew-a": [[10.0, 1.2, -0.8], [1.2, 8.0, 0.5], [-0.8, 0.5, 6.0]],
                   "slew-b": [[10.0, 1.2, -0.8], [1.2, 12.0, 0.6], [-0.8, 0.6, 8.0]]}[case]
        u_max = np.array([0.5, 0.5, 0.3])
        t0 = time.perf_counter()
        sol = slew.time_optimal(np.array(inertia), angle=np.pi / 2,
                                axis=np.array([0.0, 1.0, 1.0]) / np.sqrt(2), u_max=u_max)
        out["wall"] = time.perf_counter() - t0
        _, u = sol.sample(np.linspace(sol.t0, sol.t0 + sol.T, 20001))
        out.update(T=float(sol.T), success=bool(sol.success),
                   peak=float(np.max(np.abs(u) / u_max[:, None])))
    else:
        inertia = np.array([[12.0, 0.3, -0.2], [0.3, 10.0, 0.1], [-0.2, 0.1, 8.0]])
        t = np.linspace(0.0, 60.0, 121)
        if case == "wheels":
            target = np.array([0.3, -0.4, 0.2, 0.0])
            target[3] = np.sqrt(1 - target[:3] @ target[:3])
            model = wheel_spacecraft(inertia, np.eye(3), 0.05)
            x = ca.SX.sym("x", model.nx)
            qe = quat_mul(x[0:4], ca.DM(quat_conj(target)))
            torque = ca.fmin(ca.fmax(-4.0 * qe[3] * qe[0:3] - 6.0 * x[4:7], -0.2), 0.2)
            loop = closed_loop(model, ca.Function("sat_pd", [x], [-torque], ["x"], ["tau"]))
            x0 = np.r_[0, 0, 0, 1.0, 0, 0, 0, 0, 0, 0]
            run = lambda: simulate(loop, x0, t, rtol=1e-6)
            f = loop.f
            p = loop.resolve_p(None)
            rhs = lambda s, y: np.asarray(f(y, np.zeros(loop.nu), p), float).ravel()
        else:
            bang = lambda s: 0.1 * np.sign(np.sin(2 * np.pi * s / 7)) * np.array([1.0, -1.0, 0.5])
            model = rigid_body(inertia)
            x0 = np.r_[0, 0, 0, 1.0, 0.01, 0, 0]
            run = lambda: simulate(model, x0, t, u=bang, rtol=1e-6)
            rhs = None
        t0 = time.perf_counter()
        res = run()
        out["first"] = time.perf_counter() - t0
        later = []
        for _ in range(5 if case == "wheels" else 1):
            t0 = time.perf_counter()
            res = run()
            later.append(time.perf_counter() - t0)
        out.update(later=float(np.median(later)), success=bool(res.success),
                   status=int(res.status), method=str(res.method))
        if rhs is not None:
            ref = solve_ivp(rhs, (t[0], t[-1]), x0, method="DOP853", t_eval=t, rtol=1e-13,
                            atol=1e-16).y
            scale = 1e-10 + 1e-6 * np.abs(ref)
            out["error"] = float(np.max(np.abs(res.x - ref) / scale))
    print(json.dumps(out))
''')


def _run_case(case: str, root: Path | None) -> dict:
    """One case in a fresh process (``root``: a checkout first on ``sys.path``)."""
    env = dict(os.environ)
    if root is not None:
        env.update(PYTHONPATH=str(root), APPDYN_BENCH_SIDE="before")
    proc = subprocess.run([sys.executable, "-c", _CASES, case], capture_output=True, text=True,
                          env=env, cwd=root or Path.cwd(), timeout=1800)
    if proc.returncode != 0:
        return {"error_text": proc.stderr.strip().splitlines()[-1:] or ["failed"]}
    return json.loads(proc.stdout.strip().splitlines()[-1])


def run(quick: bool, out: Path):
    baseline = os.environ.get("APPDYN_BENCH_BASELINE")
    sides = [("after", None)] + ([("before", Path(baseline))] if baseline else [])
    cases = ["slew-a", "wheels"] if quick else ["slew-a", "slew-b", "wheels", "bang"]
    names = {"slew-a": "new user's slew, I = [[10,1.2,-0.8],[1.2,8,0.5],[-0.8,0.5,6]]",
             "slew-b": "new user's slew, I = [[10,1.2,-0.8],[1.2,12,0.6],[-0.8,0.6,8]]",
             "wheels": "saturated PD wheel slew, 60 s, rtol 1e-6",
             "bang": "bang-bang callable torque, 60 s, rtol 1e-6"}
    detail, rows = [], []
    for case in cases:
        for side, root in sides:
            got = _run_case(case, root)
            detail.append({"case": case, "side": side, **got})
            label = f"{names[case]} ({side})" if baseline else names[case]
            if "error_text" in got:
                rows.append(Row(NAME, label, "failed", float("nan"), "", got["error_text"][0][:120]))
                continue
            ok = "success" if got["success"] else "NOT success"
            if case.startswith("slew"):
                rows.append(Row(NAME, label, "wall time, first call", got["wall"], "s",
                                f"T = {got['T']:.8g} s, {ok}"))
                rows.append(Row(NAME, label, "peak |u| / u_max of sample()", got["peak"], "",
                                "at most 1 when the returned control keeps its bounds"))
            else:
                note = f"{ok}, status {got['status']}, method {got['method']}"
                rows.append(Row(NAME, label, "wall time, first call", got["first"], "s", note))
                rows.append(Row(NAME, label, "wall time, later call (median)", got["later"],
                                "s", note))
                if "error" in got:
                    rows.append(Row(NAME, label, "error / tolerance vs scipy DOP853 1e-13",
                                    got["error"], "", "at most 1 when the tolerance is met"))
    write_csv(detail, out / f"{NAME}.csv")
    return rows


def main(argv=None) -> int:
    return script_main(run, argv)


if __name__ == "__main__":
    sys.exit(main())
