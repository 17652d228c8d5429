"""Stress benchmark: the long and adversarial cases that do not fit the unit-test budget.

Cases (every number is from an actual run, checked against an invariant or a truth):

* ``torque-free`` -- body (1, 2, 3) kg m^2, w0 = (0.1, 0.2, 0.3) rad/s, 1e5 s (quick: 1e4 s),
  1001 outputs, per method of `dynamics.simulate` (auto, rk8, rk4, lie, cvodes; fixed step
  h = 0.1 s): drift of ``|q| - 1``, relative energy and inertial momentum drift, the body-rate
  error against the Jacobi-elliptic truth, status and wall time;
* ``spherical pendulum`` -- the near-singular 3-1-3 formulation against the regular 3-2-1
  one (`dynamics.mechanisms.spherical_pendulum`, m = l = 1, point mass ``I = 0`` so both
  are the same physics), an almost planar swing (th0 = 0.5 rad, psi'0 = 5e-3 rad/s) that
  passes ~7e-4 rad from the bottom, where the 3-1-3 mass matrix has condition
  ``1 / sin^2(theta)`` ~ 2e6: bob position difference, energy drift, ``auto`` rtol 1e-10
  steps, status and wall time of each;
* ``hinged bodies`` -- two bodies on a ball hinge (`dynamics.hinged_bodies`) tumbling for
  1e4 s (quick: 1e3 s), rk8 h = 0.05 s, with Baumgarte stabilization (tau = 1 s) and
  without: constraint residual ``|phi|`` [m] and ``|B nu|`` [m/s] at the end, energy drift;
* ``CMG elliptic singularity`` -- a 4-CMG pyramid (beta = 54.74 deg, unit rotors) from zero
  gimbal angles, commanded torque (-0.1, 0, 0) N m for 20 s, so the cluster momentum is
  driven along +x through the elliptic singularity at H = (1.155, 0, 0) (gimbals -90, 0, 90,
  0 deg): per steering law (pinv, sr, gsr) the largest torque error, peak gimbal rate,
  smallest singularity measure ``sqrt(det(C C^T))``, status and wall time.

Writes ``stress.csv`` (every case, every metric) into the output folder and returns summary
rows. ``--quick`` runs shorter horizons (well under 30 s); the full run is a few minutes.
"""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from appdyn.dynamics import hinged_bodies, rigid_body, simulate
from appdyn.dynamics.truth import torque_free_omega

from _common import Row, script_main, write_csv

NAME = "stress"
INERTIA, W0 = [1.0, 2.0, 3.0], [0.1, 0.2, 0.3]


def _drift(res):
    qn = np.asarray(res.invariants["quat_norm"])
    E = np.asarray(res.invariants["energy"])
    H = np.asarray(res.invariants["momentum_inertial"])
    return (float(np.max(np.abs(qn - 1.0))),
            float(np.max(np.abs(E - E[0])) / abs(E[0])),
            float(np.max(np.linalg.norm(H - H[:, :1], axis=0)) / np.linalg.norm(H[:, 0])))


# --------------------------------------------------------------------------------------------
# torque-free body over 1e5 s
# --------------------------------------------------------------------------------------------

def torque_free(quick: bool):
    T = 1e4 if quick else 1e5
    t = np.linspace(0.0, T, 1001)
    steps = int(round((t[1] - t[0]) / 0.1))
    truth = torque_free_omega(INERTIA, W0, t)
    records = []
    for method in ("auto", "rk8", "rk4", "lie", "cvodes"):
        opts = {"steps": steps} if method in ("rk8", "rk4", "lie") else {}
        if method == "cvodes":
            opts = {"rtol": 1e-10, "atol": 1e-12}
        start = time.perf_counter()
        res = simulate(rigid_body(INERTIA), [0, 0, 0, 1, *W0], t, method=method,
                       invariants=True, **opts)
        wall = time.perf_counter() - start
        dq, dE, dH = _drift(res)
        records.append({
            "case": "torque-free", "setting": method, "horizon_s": T, "success": res.success,
            "status": res.status, "n_steps": res.n_steps, "q_norm_drift": dq,
            "energy_drift": dE, "momentum_drift": dH,
            "rate_error": float(np.max(np.abs(res.x[4:] - truth))), "wall_time_s": wall,
            "message": res.message})
    rows = []
    for r in records:
        label = f"torque-free {r['horizon_s']:.0e} s, {r['setting']}"
        note = (f"|q|-1 {r['q_norm_drift']:.1e}, energy {r['energy_drift']:.1e}, momentum "
                f"{r['momentum_drift']:.1e}, status {r['status']}")
        rows.append(Row(NAME, label, "max invariant drift (rel)",
                        max(r["q_norm_drift"], r["energy_drift"], r["momentum_drift"]), "",
                        note))
        rows.append(Row(NAME, label, "wall time", r["wall_time_s"], "s",
                        f"rate error {r['rate_error']:.1e} rad/s, {r['n_steps']} steps"))
    return records, rows


# --------------------------------------------------------------------------------------------
# spherical pendulum: 3-1-3 (near-singular) versus 3-2-1
# --------------------------------------------------------------------------------------------

def spherical(quick: bool):
    try:
        from appdyn.dynamics.mechanisms import spherical_mass_matrix, spherical_pendulum
    except ImportError as exc:  # pragma: no cover - the models live in dynamics.mechanisms
        return [{"case": "spherical pendulum", "setting": "skipped", "message": str(exc)}], []
    # point mass (I = 0): the same physics in both; almost planar, passing ~7e-4 rad from the
    # bottom, where the 3-1-3 psi equation divides by sin^2(theta) ~ 5e-7
    inertia, th0, rate0 = 0.0, 0.5, 5e-3
    T = 5.0 if quick else 20.0
    t = np.linspace(0.0, T, 2001)
    m313 = spherical_pendulum("3-1-3", inertia=inertia)
    m321 = spherical_pendulum("3-2-1", inertia=inertia)
    # the same bob position (0, -sin th0, cos th0) and velocity (l sin th0 psi', 0, 0)
    x313 = [0.0, th0, rate0, 0.0]
    x321 = [0.0, th0, np.tan(th0) * rate0, 0.0]
    records, results = [], {}
    for label, model, x0 in (("3-1-3", m313, x313), ("3-2-1", m321, x321)):
        start = time.perf_counter()
        res = simulate(model, x0, t, rtol=1e-10, atol=1e-12,
                       invariants=["energy", "position"])
        wall = time.perf_counter() - start
        E = np.asarray(res.invariants["energy"])
        results[label] = res
        records.append({"case": "spherical pendulum", "setting": label, "horizon_s": T,
                        "success": res.success, "status": res.status, "n_steps": res.n_steps,
                        "energy_drift": float(np.max(np.abs(E - E[0])) / abs(E[0])),
                        "wall_time_s": wall, "message": res.message})
    p313 = np.asarray(results["3-1-3"].invariants["position"])
    p321 = np.asarray(results["3-2-1"].invariants["position"])
    diff = float(np.max(np.linalg.norm(p313 - p321, axis=0)))
    theta = np.asarray(results["3-1-3"].x[1])
    k = int(np.argmin(np.abs(np.sin(theta))))
    M = spherical_mass_matrix("3-1-3", results["3-1-3"].x[:2, k], inertia=inertia)
    cond = float(np.max(np.diag(M)) / max(np.min(np.diag(M)), 1e-300))
    psi_rate = float(np.max(np.abs(results["3-1-3"].x[2])))
    for r in records:
        r.update(position_difference_m=diff, condition_313=cond, peak_psi_rate=psi_rate)
    a, b = records
    rows = [
        Row(NAME, "spherical pendulum 3-1-3 vs 3-2-1", "bob position difference", diff, "m",
            f"I = {inertia:g}, M(3-1-3) condition {cond:.1e}, peak psi' {psi_rate:.3g} rad/s, "
            f"status {a['status']}/{b['status']}"),
        Row(NAME, "spherical pendulum 3-1-3 vs 3-2-1", "wall time 3-1-3 / 3-2-1",
            a["wall_time_s"] / b["wall_time_s"], "x",
            f"{a['wall_time_s']:.3g} s ({a['n_steps']} steps) vs {b['wall_time_s']:.3g} s "
            f"({b['n_steps']} steps); energy drift {a['energy_drift']:.1e} / "
            f"{b['energy_drift']:.1e}"),
    ]
    return records, rows


# --------------------------------------------------------------------------------------------
# hinged bodies: constraint drift with and without Baumgarte stabilization
# --------------------------------------------------------------------------------------------

def hinged(quick: bool):
    T = 1e3 if quick else 1e4
    t = np.linspace(0.0, T, 1001)
    steps = int(round((t[1] - t[0]) / 0.05))
    records = []
    for label, tau in (("Baumgarte tau 1 s", 1.0), ("no stabilization", None)):
        model = hinged_bodies(10.0, [1.0, 2.0, 2.5], 2.0, [0.2, 0.3, 0.4],
                              [0.4, 0.0, 0.0], [-0.3, 0.0, 0.0], stabilization=tau)
        x0 = model.initial_state([0, 0, 0, 1], [0.3, 0.1, 1.0], [0, 0, 0], [0, 0, 0, 1],
                                 [-0.2, 0.4, 0.5])
        start = time.perf_counter()
        res = simulate(model, x0, t, method="rk8", steps=steps,
                       invariants=["constraint_residual", "energy"])
        wall = time.perf_counter() - start
        c = np.asarray(res.invariants["constraint_residual"])
        E = np.asarray(res.invariants["energy"])
        records.append({"case": "hinged bodies", "setting": label, "horizon_s": T,
                        "success": res.success, "status": res.status, "n_steps": res.n_steps,
                        "residual_position_m": float(np.max(c[0])),
                        "residual_velocity_m_s": float(np.max(c[1])),
                        "energy_drift": float(np.max(np.abs(E - E[0])) / abs(E[0])),
                        "wall_time_s": wall, "message": res.message})
    rows = []
    for r in records:
        rows.append(Row(NAME, f"hinged bodies {r['horizon_s']:.0e} s, {r['setting']}",
                        "max constraint residual |phi|", r["residual_position_m"], "m",
                        f"|B nu| {r['residual_velocity_m_s']:.1e} m/s, energy drift "
                        f"{r['energy_drift']:.1e}, rk8 h 0.05 s, {r['wall_time_s']:.2f} s"))
    return records, rows


# --------------------------------------------------------------------------------------------
# CMG pyramid through its elliptic singularity
# --------------------------------------------------------------------------------------------

def cmg(quick: bool):
    from appdyn.dynamics.momentum import pyramid, steer

    geo = pyramid(np.deg2rad(54.74))
    T = 20.0
    t = np.linspace(0.0, T, 201 if quick else 801)
    torque = [-0.1, 0.0, 0.0]  # H(t) = (0.1 t, 0, 0): through (1.155, 0, 0) at t ~ 11.5 s
    records = []
    for law in ("pinv", "sr", "gsr"):
        start = time.perf_counter()
        try:
            res = steer(geo, torque, t, law=law, steps=20 if quick else 50)
        except Exception as exc:  # noqa: BLE001 - a stress bench records, never stops
            records.append({"case": "CMG elliptic singularity", "setting": law,
                            "success": False, "status": "exception",
                            "message": f"{type(exc).__name__}: {exc}",
                            "wall_time_s": time.perf_counter() - start})
            continue
        wall = time.perf_counter() - start
        ok = np.isfinite(res.measure)
        k = int(np.nanargmin(np.where(ok, res.measure, np.nan))) if ok.any() else 0
        records.append({
            "case": "CMG elliptic singularity", "setting": law, "horizon_s": T,
            "success": res.success, "status": res.status,
            "max_torque_error": float(res.max_torque_error),
            "time_torque_error_over_10pct_s": float(
                np.sum(res.torque_error[:-1] > 0.01) * (t[1] - t[0])),
            "peak_gimbal_rate": float(res.max_rate), "min_measure": float(res.min_measure),
            "H_at_min_measure": np.round(res.H[:, k], 3).tolist(),
            "final_H": np.round(res.H[:, -1], 4).tolist(),
            "max_momentum_error": float(res.max_momentum_error), "wall_time_s": wall,
            "message": res.message})
    rows = []
    for r in records:
        if r.get("status") == "exception":
            rows.append(Row(NAME, f"CMG elliptic singularity, {r['setting']}", "exception",
                            float("nan"), "", r["message"][:80]))
            continue
        rows.append(Row(NAME, f"CMG elliptic singularity, {r['setting']}", "max torque error",
                        r["max_torque_error"], "N m",
                        f"error > 10% for {r['time_torque_error_over_10pct_s']:.3g} s, final H "
                        f"{r['final_H']} (asked (2, 0, 0)), "
                        f"peak gimbal rate {r['peak_gimbal_rate']:.3g} rad/s, min measure "
                        f"{r['min_measure']:.2g} at H {r['H_at_min_measure']}, status "
                        f"{r['status']}, {r['wall_time_s']:.2f} s"))
    return records, rows


CASES = (torque_free, spherical, hinged, cmg)


def run(quick: bool, out: Path) -> list:
    records, rows = [], []
    for case in CASES:
        start = time.perf_counter()
        try:
            rec, row = case(quick)
        except Exception as exc:  # noqa: BLE001 - one broken case must not hide the others
            rec = [{"case": case.__name__, "setting": "error",
                    "message": f"{type(exc).__name__}: {exc}"}]
            row = [Row(NAME, case.__name__, "error", float("nan"), "",
                       f"{type(exc).__name__}: {exc}"[:120])]
        for r in rec:
            r.setdefault("case_wall_time_s", time.perf_counter() - start)
        records += rec
        rows += row
    write_csv(records, Path(out) / f"{NAME}.csv")
    return rows


def main(argv=None) -> int:
    return script_main(run, argv)


if __name__ == "__main__":
    raise SystemExit(main())
