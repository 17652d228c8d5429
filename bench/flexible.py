"""Flexible-appendage benchmark (issue 30, items 1, 4, 5): the seed's spinning satellite with
four flexible antennas, and Kane, Ryan & Banerjee's spin-up.

* ``build`` / ``first call`` / ``speed`` -- `flexible_antenna_satellite` (hub
  ``[300, 300, 500]`` kg m^2, antennas 3 m, 0.2 kg/m, EI 20 N m^2, on a 0.8 m hub radius)
  spinning at 2 rad/s with the first antenna bent (``eta1 = xi1 = 0.05``), 60 s (121
  outputs), ``rk8`` with 20 steps per output: the build of ``Scene.model()`` with the cache
  cleared, the first ``simulate`` and the median of further runs; 2 modes per plane not
  compiled, and without ``--quick`` also compiled (the first call compiles) and 4 modes per
  plane; the right-hand side's instruction count.
* ``spin-up`` -- Kane, Ryan & Banerjee (J. Guidance 10(2), 1987): a cantilever of 10 m,
  1.2 kg/m, EI 14000 N m^2 (first frequency 3.80 rad/s) on a hub whose rate follows
  ``W(t) = Wf / T (t - T / (2 pi) sin(2 pi t / T))`` for ``t < T = 15 s``, then ``Wf = 6``
  rad/s (above the first frequency). The prescribed rate is realised by a hub 1e9 times the
  beam's inertia driven by the feedforward torque ``I_hub W'(t)`` (an `ExternalTorque`,
  samples held linearly): the hub rate follows the profile to about 1e-5 rad/s.
  The in-plane tip deflection with stiffening stays bounded (about its centrifugally
  stiffened equilibrium, 0 here); with ``stiffening=False`` (the plain linear modal model,
  for comparison only) it diverges once ``W`` passes the first frequency.

Writes ``flexible.csv`` (the tip deflections of both runs) into the output folder and returns
summary rows. Run: ``appdyn bench flexible`` or ``python bench/flexible.py [--quick]`` (the
spin-up's step is 0.02 s with ``--quick``, 0.01 s without).
"""
from __future__ import annotations

import statistics
import time
from pathlib import Path

import numpy as np

from appdyn.dynamics import cache, simulate
from appdyn.dynamics import scene as sc

from _common import Row, script_main, write_csv

NAME = "flexible"
GRID = np.linspace(0.0, 60.0, 121)
SPIN_UP = dict(length=10.0, mass_per_length=1.2, bending_stiffness=14000.0, final_rate=6.0,
               duration=15.0, end=40.0)


def _satellite(modes: int):
    return sc.flexible_antenna_satellite([300.0, 300.0, 500.0], 3.0, 0.2, 20.0,
                                         hub_radius=0.8, modes=modes)


def _timed(fun) -> tuple:
    t0 = time.perf_counter()
    out = fun()
    return out, time.perf_counter() - t0


def _speed(modes: int, repeats: int, jit: bool) -> dict:
    """Build, first call and median run of the satellite (module docstring); ``jit``:
    compiled (the first call compiles) or not."""
    cache.clear()
    scene, build = _timed(lambda: (s := _satellite(modes), s.model())[0])
    model = scene.model()
    x0 = scene.state(w=[0.0, 0.0, 2.0], eta1=0.05, xi1=0.05)
    kw = dict(method="rk8", steps=20, jit=jit)
    res, first = _timed(lambda: simulate(model, x0, GRID, **kw))
    times = [_timed(lambda: simulate(model, x0, GRID, **kw))[1] for _ in range(repeats)]
    e = np.asarray(model.invariant("energy", res.x)).ravel()
    return {"modes": modes, "jit": jit, "states": model.nx,
            "instructions": model.f.n_instructions(), "build_s": build,
            "first_call_s": first, "run_s": statistics.median(times),
            "energy_drift": float(np.max(np.abs(e - e[0])) / abs(e[0]))}


def _rate_profile(t, wf, T):
    """``(W, W')`` of the smooth spin-up profile (module docstring)."""
    t = np.asarray(t, dtype=float)
    up = t < T
    W = np.where(up, wf / T * (t - T / (2 * np.pi) * np.sin(2 * np.pi * t / T)), wf)
    Wd = np.where(up, wf / T * (1.0 - np.cos(2 * np.pi * t / T)), 0.0)
    return W, Wd


def spin_up(stiffening: bool, modes: int = 2, dt: float = 0.01) -> dict:
    """The Kane-Ryan-Banerjee spin-up (module docstring): times, the in-plane tip deflection
    [m], the hub rate error [rad/s] and whether the run succeeded."""
    p = SPIN_UP
    beam = sc.FlexibleAppendage(p["length"], p["mass_per_length"], p["bending_stiffness"],
                                modes=modes, stiffening=stiffening)
    I_beam = p["mass_per_length"] * p["length"] ** 3 / 3.0
    I_hub = 1e9 * I_beam
    scene = sc.Scene(sc.RigidHub([I_hub, I_hub, I_hub]), beam, sc.ExternalTorque())
    model = scene.model()
    t = np.arange(0.0, p["end"] + dt / 2, dt)
    W, Wd = _rate_profile(t, p["final_rate"], p["duration"])
    u = np.zeros((model.nu, t.size))
    u[2] = I_hub * Wd
    res = simulate(model, scene.state(), t, u=u, method="rk8", steps=4, jit=False)
    x = np.asarray(res.x)
    eta = x[[model.states.index(f"eta{i}") for i in range(1, modes + 1)]]
    xi = x[[model.states.index(f"xi{i}") for i in range(1, modes + 1)]]
    tip = beam.deflection(p["length"], eta, xi)
    return {"t": t, "tip": np.asarray(beam.normal) @ tip, "rate_error": float(np.max(np.abs(
        x[model.states.index("w3")] - W))), "success": bool(res.success),
            "message": res.message}


def run(quick: bool, out: Path):
    speed = [_speed(2, 1 if quick else 3, False)]
    if not quick:  # compiling takes about a minute a model
        speed += [_speed(2, 3, True), _speed(4, 3, False)]
    dt = 0.02 if quick else 0.01
    stiff, linear = spin_up(True, dt=dt), spin_up(False, dt=dt)
    write_csv([{"t": float(a), "tip_stiffening_m": float(b), "tip_linear_m": float(c)}
               for a, b, c in zip(stiff["t"], stiff["tip"], linear["tip"])],
              out / f"{NAME}.csv")
    rows = []
    for r in speed:
        how = "compiled" if r["jit"] else "not compiled (jit=False)"
        case = f"4-antenna satellite, {r['modes']} modes/plane"
        note = (f"{r['states']} states, {r['instructions']} instructions; energy drift "
                f"{r['energy_drift']:.1e}")
        rows += [Row(NAME, case, "build (cache cleared)", r["build_s"], "s", note),
                 Row(NAME, f"{case}, 60 s", f"first simulate, {how}", r["first_call_s"], "s",
                     "rk8, 20 steps/output" + (", compile included" if r["jit"] else "")),
                 Row(NAME, f"{case}, 60 s", f"simulate wall time (median), {how}", r["run_s"],
                     "s", "rk8, 20 steps/output")]
    for label, r in (("stiffening", stiff), ("linear (stiffening=False)", linear)):
        tip = np.abs(r["tip"])
        late = tip[r["t"] >= SPIN_UP["duration"]]
        rows.append(Row(NAME, f"KRB spin-up 0 -> 6 rad/s in 15 s, {label}",
                        "max |in-plane tip deflection| after spin-up",
                        float(np.max(late)) if np.all(np.isfinite(late)) else float("inf"),
                        "m", f"success={r['success']}; hub rate error "
                             f"{r['rate_error']:.1e} rad/s"))
    return rows


def main(argv=None) -> int:
    return script_main(run, argv)


if __name__ == "__main__":
    raise SystemExit(main())
