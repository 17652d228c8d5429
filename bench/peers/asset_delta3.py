"""ASSET peer: the four-phase Delta III ascent; runs in bench/peers/.venv-asset.

ASSET (asset_asrl 0.5.1, C++ with its own interior-point solver PSIOPT) solves the problem
as its own Delta III example states it (``examples/Delta3Launch.py`` of the asset_asrl
repository; the facts are taken over, the code is our own): canonical units (R_E, the 961 s
burn time, the launch mass); the thrust direction is ``u / |u|`` in the dynamics with
``0.5 <= |u| <= 1.5`` as a path bound; ``|r| >= R_E`` (``0.999999 R_E`` in the first
phase, which starts on the surface); the time, position, velocity and control continuous
across the stagings, the mass set at each phase start; the five terminal elements (acos
and quadrant checks) as an equality at the end; ASSET's Isp values 283.33364 / 301.68 /
467.21 s (so its optimum, 7529.7485 kg, is not Betts' 7529.7124 kg). The start is the
example's: a straight line in Cartesian coordinates from the launch state to the point of
the target orbit at mean anomaly -0.05 rad, the thrust along +y, the mass linear per
phase. LGL3 collocation with ``segments`` segments per phase; PSIOPT line searches as in
the example (L1, at most 2 line-search iterations).

Usage (from the project root)::

    bench/peers/.venv-asset/bin/python bench/peers/asset_delta3.py --json [--segments 16 32 64]
        [--repeats 3] [--threads N]

``--json`` prints one JSON object on stdout: ``asset`` (version), ``threads``, and ``runs``:
one entry per segment count with ``segments``, ``final_mass`` (kg), ``final_time`` (s),
``build_time`` (s, the phases and the problem set up), ``solve_time`` (s,
``solve_optimize`` alone; the median of the repeats), ``first_solve_time`` (s),
``iterations`` (PSIOPT, summed over its solve and optimize stages when it reports them),
``status`` (PSIOPT's convergence flag). Every print of PSIOPT goes to stderr.
"""
from __future__ import annotations

import time

import numpy as np

from _runner import asset_main

# ------------------------------------------------------------------ data (SI)
G0, RE, OMEGA_E, MU = 9.80665, 6378145.0, 7.29211585e-5, 3.986012e14
RHO0, H_SCALE, CD, S_REF = 1.225, 7200.0, 0.5, 4 * np.pi
THRUST = {"srb": 628500.0, "first": 1083100.0, "second": 110094.0}
ISP = {"srb": 283.33364, "first": 301.68, "second": 467.21}  # ASSET's rounded values
BURN = {"srb": 75.2, "first": 261.0, "second": 700.0}
TOTAL = {"srb": 19290.0, "first": 104380.0, "second": 19300.0}
PROP = {"srb": 17010.0, "first": 95550.0, "second": 16820.0}
PAYLOAD = 4164.0
TARGET = (24361140.0, 0.7308, np.deg2rad(28.5), np.deg2rad(269.8), np.deg2rad(130.5))
LATITUDE = np.deg2rad(28.5)

# canonical units
L_STAR, T_STAR, M_STAR = RE, 961.0, 301454.0


def canonical():
    """The problem's numbers in canonical units (length R_E, time 961 s, mass m_0)."""
    a_star = L_STAR / T_STAR**2
    f_star = a_star * M_STAR
    c = dict(mu=MU * T_STAR**2 / L_STAR**3, re=1.0, we=OMEGA_E * T_STAR,
             rho=RHO0 * L_STAR**3 / M_STAR, h=H_SCALE / L_STAR, g=G0 / a_star,
             cds=CD * S_REF / L_STAR**2)
    T = {k: v / f_star for k, v in THRUST.items()}
    isp = {k: v / T_STAR for k, v in ISP.items()}
    mdot = {k: T[k] / (isp[k] * c["g"]) for k in T}
    t_srb, t_1, t_2 = (BURN[k] / T_STAR for k in ("srb", "first", "second"))
    m = {k: v / M_STAR for k, v in TOTAL.items()}
    p = {k: v / M_STAR for k, v in PROP.items()}
    dry = {k: m[k] - p[k] for k in m}
    thrust = [6 * T["srb"] + T["first"], 3 * T["srb"] + T["first"], T["first"], T["second"]]
    flow = [6 * mdot["srb"] + mdot["first"], 3 * mdot["srb"] + mdot["first"], mdot["first"],
            mdot["second"]]
    t_end = [t_srb, 2 * t_srb, t_1, t_1 + t_2]
    m0 = [9 * m["srb"] + m["first"] + m["second"] + PAYLOAD / M_STAR]
    m0.append(m0[0] - 6 * p["srb"] - t_srb / t_1 * p["first"] - 6 * dry["srb"])
    m0.append(m0[1] - 3 * p["srb"] - t_srb / t_1 * p["first"] - 3 * dry["srb"])
    m0.append(m0[2] - (1 - 2 * t_srb / t_1) * p["first"] - dry["first"])
    mf = [m0[0] - 6 * p["srb"] - t_srb / t_1 * p["first"],
          m0[1] - 3 * p["srb"] - t_srb / t_1 * p["first"],
          m0[2] - (1 - 2 * t_srb / t_1) * p["first"], m0[3] - p["second"]]
    return c, thrust, flow, t_end, m0, mf


def build(ast, segments: int):
    """The ASSET problem and its four phases on ``segments`` LGL3 segments per phase."""
    vf, oc = ast.VectorFunctions, ast.OptimalControl
    c, thrust, flow, t_end, m0, mf = canonical()

    class Rocket(oc.ODEBase):
        def __init__(self, T, mdot):
            args = oc.ODEArguments(7, 3)
            r, v, m = args.XVec().head3(), args.XVec().segment3(3), args.XVar(6)
            u = args.tail3().normalized()
            rho = c["rho"] * vf.exp(-(r.norm() - c["re"]) / c["h"])
            vr = v + r.cross(np.array([0, 0, c["we"]]))
            drag = (-0.5 * c["cds"]) * rho * (vr * vr.norm())
            vdot = (-c["mu"]) * r.normalized_power3() + (T * u + drag) / m
            super().__init__(vf.stack(v, vdot, -mdot), 7, 3)

    def target_orbit():
        at, et, it, Wt, wt = TARGET
        rv, vv = vf.Arguments(6).tolist([(0, 3), (3, 3)])
        h = rv.cross(vv)
        n = vf.cross([0, 0, 1], h)
        a = -0.5 * c["mu"] / (0.5 * vv.norm() ** 2 - c["mu"] / rv.norm())
        ev = vv.cross(h) / c["mu"] - rv.normalized()
        i = vf.arccos(h.normalized()[2])
        W = vf.ifelse(n[1] > 0, vf.arccos(n.normalized()[0]), 2 * np.pi - vf.arccos(n.normalized()[0]))
        w = vf.arccos(n.normalized().dot(ev.normalized()))
        w = vf.ifelse(ev[2] > 0, w, 2 * np.pi - w)
        return vf.stack([a, ev.norm(), i, W, w]) - np.array([at / L_STAR, et, it, Wt, wt])

    # the start: launch state -> the target orbit at mean anomaly -0.05 rad, straight line
    y0 = np.zeros(6)
    y0[:3] = np.array([np.cos(LATITUDE), 0, np.sin(LATITUDE)]) * c["re"]
    y0[3:6] = -np.cross(y0[:3], np.array([0, 0, c["we"]]))
    y0[3] += 1e-5 / (L_STAR / T_STAR)  # not exactly zero: the drag's derivative at rest
    at, et, it, Wt, wt = TARGET
    yf = np.asarray(ast.Astro.classic_to_cartesian([at / L_STAR, et, it, Wt, wt, -0.05], c["mu"]))
    guesses = [[] for _ in range(4)]
    starts = [0.0, *t_end[:3]]
    for t in np.linspace(0, t_end[-1], 1000):
        k = int(np.searchsorted(t_end[:3], t, side="right"))
        X = np.zeros(11)
        X[:6] = y0 + (yf - y0) * t / t_end[-1]
        X[6] = m0[k] + (mf[k] - m0[k]) * (t - starts[k]) / (t_end[k] - starts[k])
        X[7] = t
        X[8:11] = [0, 1, 0]
        guesses[k].append(X)

    phases = []
    for k in range(4):
        ph = Rocket(thrust[k], flow[k]).phase("LGL3", guesses[k], segments)
        ph.setControlMode("HighestOrderSpline")
        ph.addLUNormBound("Path", [8, 9, 10], 0.5, 1.5)
        ph.addLowerNormBound("Path", [0, 1, 2], c["re"] * (0.999999 if k == 0 else 1.0))
        if k == 0:
            ph.addBoundaryValue("Front", range(0, 8), guesses[0][0][0:8])
        else:
            ph.addBoundaryValue("Front", [6], [m0[k]])
        if k < 3:
            ph.addBoundaryValue("Back", [7], [t_end[k]])
        else:
            ph.addValueObjective("Back", 6, -1.0)
            ph.addUpperVarBound("Back", 7, t_end[3], 1.0)
            ph.addEqualCon("Back", target_orbit(), range(0, 6))
        phases.append(ph)
    ocp = oc.OptimalControlProblem()
    for ph in phases:
        ocp.addPhase(ph)
    ocp.addForwardLinkEqualCon(phases[0], phases[3], [0, 1, 2, 3, 4, 5, 7, 8, 9, 10])
    ocp.optimizer.set_OptLSMode("L1")
    ocp.optimizer.set_SoeLSMode("L1")
    ocp.optimizer.set_MaxLSIters(2)
    ocp.optimizer.set_PrintLevel(3)
    return ocp, phases


def run_one(ast, segments: int, threads: int | None) -> dict:
    t0 = time.perf_counter()
    ocp, phases = build(ast, segments)
    if threads:
        ocp.setThreads(threads, threads)
    t1 = time.perf_counter()
    flag = ocp.solve_optimize()
    t2 = time.perf_counter()
    last = np.asarray(phases[3].returnTraj()[-1])
    return {"segments": segments, "final_mass": float(last[6] * M_STAR),
            "final_time": float(last[7] * T_STAR), "build_time": t1 - t0, "solve_time": t2 - t1,
            "iterations": int(ocp.optimizer.LastIterNum), "status": str(getattr(flag, "name", flag))}


if __name__ == "__main__":
    asset_main(__doc__, run_one, [16, 32, 64])
