"""ASSET peer: Betts' shuttle reentry, maximum crossrange without a heating limit; runs in
bench/peers/.venv-asset.

The problem of `appdyn.ocp.examples.shuttle_reentry` as ASSET's own example states it
(``examples/Reentry.py`` of the asset_asrl repository: units 1e5 ft, 60 s, the vehicle's
mass; its straight-line start over 1000 s; L1 line searches; ``solve_optimize``); the code is
ours. LGL3 with ``segments`` segments; literature 34.1412 deg (Betts 2010).

Usage (from the project root)::

    bench/peers/.venv-asset/bin/python bench/peers/asset_reentry.py --json
        [--segments 32 64 128] [--repeats 3] [--threads 1]

prints ``{"asset", "threads", "runs": [...]}``, one run per segment count with
``segments``, ``theta_f_deg``, ``final_time`` [s], ``build_time``, ``solve_time`` (median),
``first_solve_time``, ``iterations``, ``status``.
"""
from __future__ import annotations

import time

import numpy as np

from _runner import asset_main, asset_solve

L_STAR, T_STAR = 1.0e5, 60.0
G0, WEIGHT = 32.2, 203000.0
M_STAR = WEIGHT / G0


def build(ast, segments: int):
    vf, oc = ast.VectorFunctions, ast.OptimalControl
    v_star = L_STAR / T_STAR
    re, area = 20902900.0 / L_STAR, 2690.0 / L_STAR**2
    mass, mu = 1.0, 0.140765e17 / (L_STAR**3 / T_STAR**2)
    rho0, h_ref = 0.002378 / (M_STAR / L_STAR**3), 23800.0 / L_STAR

    class Reentry(oc.ODEBase):
        def __init__(self):
            args = oc.ODEArguments(5, 2)
            h, theta, v, gamma, psi = args.XVec().tolist()
            alpha, beta = args.UVec().tolist()
            a = (180.0 / np.pi) * alpha
            cl = -0.20704 + 0.029244 * a
            cd = 0.07854 - 0.61592e-2 * a + 0.621408e-3 * (a**2)
            rho = rho0 * vf.exp(-h / h_ref)
            r = h + re
            lift = 0.5 * cl * area * rho * (v**2)
            drag = 0.5 * cd * area * rho * (v**2)
            g = mu / (r**2)
            ode = vf.stack([v * vf.sin(gamma),
                            (v / r) * vf.cos(gamma) * vf.cos(psi),
                            -drag / mass - g * vf.sin(gamma),
                            (lift / (mass * v)) * vf.cos(beta) + vf.cos(gamma) * (v / r - g / v),
                            lift * vf.sin(beta) / (mass * v * vf.cos(gamma))
                            + (v / r) * vf.cos(gamma) * vf.sin(psi) * vf.tan(theta)])
            super().__init__(ode, 5, 2)

    tf = 1000.0 / T_STAR
    h0, hf, v0, vf_, g0, gf = (260000.0 / L_STAR, 80000.0 / L_STAR, 25600.0 / v_star,
                               2500.0 / v_star, np.deg2rad(-1.0), np.deg2rad(-5.0))
    guess = []
    for t in np.linspace(0, tf, 200):
        f = t / tf
        guess.append(np.array([h0 + f * (hf - h0), 0.0, v0 + f * (vf_ - v0), g0 + f * (gf - g0),
                               np.deg2rad(90.0), t, 0.0, 0.0]))
    ph = Reentry().phase("LGL3", guess, segments)
    ph.addBoundaryValue("Front", range(0, 6), guess[0][0:6])
    ph.addLUVarBounds("Path", [1, 3], np.deg2rad(-89.0), np.deg2rad(89.0), 1.0)
    ph.addLUVarBound("Path", 6, np.deg2rad(-90.0), np.deg2rad(90.0), 1.0)
    ph.addLUVarBound("Path", 7, np.deg2rad(-90.0), np.deg2rad(1.0), 1.0)
    ph.addUpperDeltaTimeBound(2500.0 / T_STAR, 1.0)
    ph.addBoundaryValue("Back", [0, 2, 3], [hf, vf_, gf])
    ph.addDeltaVarObjective(1, -10.0)
    ph.optimizer.set_SoeLSMode("L1")
    ph.optimizer.set_OptLSMode("L1")
    ph.optimizer.set_PrintLevel(3)
    return ph


def run_one(ast, segments: int, threads: int | None) -> dict:
    t0 = time.perf_counter()
    ph = build(ast, segments)
    build_time = time.perf_counter() - t0
    last, row = asset_solve(ph, threads, "solve_optimize")
    last = np.asarray(last)
    return {"segments": segments, "theta_f_deg": float(np.rad2deg(last[1])),
            "final_time": float(last[5] * T_STAR), "build_time": build_time, **row}


if __name__ == "__main__":
    asset_main(__doc__, run_one, [32, 64, 128])
