"""ASSET peer: Bryson & Ho's orbit raising, the thrust direction a unit vector; runs in
bench/peers/.venv-asset.

The problem of `appdyn.ocp.examples.orbit_raising` stated in ASSET (asset_asrl 0.5.1; our
code): states ``r, vr, vt, m``, controls ``ur, ut`` with ``ur^2 + ut^2 = 1`` as a path
equality, ``mu = 1``, thrust 0.1405, mass rate 0.0749, from ``(1, 0, 1, 1)`` over ``T = 3.32``
to ``vr = 0``, ``vt = 1 / sqrt(r)``; maximum ``r(T)`` (literature 1.5253). LGL3 collocation
with ``segments`` segments; the start: a straight line from ``(1, 0, 1, 1)`` to ``(1.5, 0,
0.8, 0.75)`` with the thrust along the velocity (``ut = 1``), as the appdyn benchmark's
start.

Usage (from the project root)::

    bench/peers/.venv-asset/bin/python bench/peers/asset_orbit_raising.py --json
        [--segments 20 40 80] [--repeats 3] [--threads 1]

prints ``{"asset", "threads", "runs": [...]}``, one run per segment count with
``segments``, ``r_f``, ``build_time``, ``solve_time`` (median of the repeats),
``first_solve_time``, ``iterations``, ``status``.
"""
from __future__ import annotations

import time

import numpy as np

from _runner import asset_main, asset_solve

THRUST, MDOT, T_FINAL = 0.1405, 0.0749, 3.32


def build(ast, segments: int):
    vf, oc = ast.VectorFunctions, ast.OptimalControl

    class OrbitRaising(oc.ODEBase):
        def __init__(self):
            args = oc.ODEArguments(4, 2)
            r, vr, vt, m = (args.XVar(i) for i in range(4))
            ur, ut = args.UVar(0), args.UVar(1)
            ode = vf.stack([vr, vt * vt / r - 1.0 / (r * r) + THRUST * ur / m,
                            -vr * vt / r + THRUST * ut / m, -MDOT + 0 * r])
            super().__init__(ode, 4, 2)

    guess = []
    for t in np.linspace(0.0, T_FINAL, 200):
        f = t / T_FINAL
        guess.append(np.array([1 + 0.5 * f, 0.0, 1 - 0.2 * f, 1 - 0.25 * f, t, 0.0, 1.0]))
    ph = OrbitRaising().phase("LGL3", guess, segments)
    ph.setControlMode("HighestOrderSpline")
    ph.addBoundaryValue("Front", range(0, 5), [1.0, 0.0, 1.0, 1.0, 0.0])
    ph.addBoundaryValue("Back", [4], [T_FINAL])
    ph.addBoundaryValue("Back", [1], [0.0])
    rv = vf.Arguments(2)
    ph.addEqualCon("Back", rv[1] - 1.0 / vf.sqrt(rv[0]), [0, 2])
    ph.addEqualCon("Path", vf.Arguments(2).norm() - 1.0, [5, 6])
    ph.addValueObjective("Back", 0, -1.0)
    ph.optimizer.set_PrintLevel(3)
    return ph


def run_one(ast, segments: int, threads: int | None) -> dict:
    t0 = time.perf_counter()
    ph = build(ast, segments)
    build_time = time.perf_counter() - t0
    last, row = asset_solve(ph, threads)
    return {"segments": segments, "r_f": float(np.asarray(last)[0]), "build_time": build_time,
            **row}


if __name__ == "__main__":
    asset_main(__doc__, run_one, [20, 40, 80])
