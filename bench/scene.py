"""Scene benchmark: "skip what a scene doesn't need", measured (issue "Build any vehicle from
parts").

* ``hub-only scene vs rigid_body`` -- the torque-free body I = [[10,1.2,-0.8],[1.2,12,0.6],
  [-0.8,0.6,8]] over 60 s (121 outputs), simulated from the same state by
  ``Scene(RigidHub(I)).model()`` and by the hand-written rigid body that `rigid_body` was
  before it became a scene (kept as the tests' reference,
  ``tests/dynamics/scene/legacy_momentum.py``; today's `rigid_body` when that file is
  absent), ``rk8`` with 20 steps per output, compiled, and ``auto`` at rtol 1e-10, in the
  same process, interleaved: the median wall time of each and their ratio; the state count
  and the right-hand side's instruction count of each.
* ``build time`` -- ``Scene(...).model()`` with the one cache cleared first, for scenes of 1
  to 10 parts (the parts of `PARTS`, the first k of them): the median of 5 builds.
* ``multipliers formed`` -- whether building the 10-part scene called the multiplier
  machinery of `dynamics.constrained` (it must not: no part brings constraints).

Writes ``scene.csv`` into the output folder and returns summary rows.
Run: ``appdyn bench scene`` or ``python bench/scene.py [--quick]``.
"""
from __future__ import annotations

import importlib.util
import statistics
import sys
import time
from pathlib import Path
from unittest import mock

import numpy as np

from appdyn.dynamics import cache, constrained, rigid_body, simulate
from appdyn.dynamics import scene as sc

from _common import Row, script_main, write_csv

NAME = "scene"
INERTIA = np.array([[10.0, 1.2, -0.8], [1.2, 12.0, 0.6], [-0.8, 0.6, 8.0]])
X0 = np.array([0.0, 0.0, 0.0, 1.0, 0.3, -0.2, 0.5])
GRID = np.linspace(0.0, 60.0, 121)
AXES4 = np.array([[1.0, 0.0, 0.0, 0.57735026918962573],
                  [0.0, 1.0, 0.0, 0.57735026918962573],
                  [0.0, 0.0, 1.0, 0.57735026918962573]])


def parts() -> list:
    """Ten parts of every kind this checkout has, in a fixed order."""
    out = [sc.ReactionWheels(AXES4, 0.05, u_max=0.2), sc.ExternalTorque(u_max=1.0),
           sc.HeldRotor([0.0, 0.0, 1.0], 2.0)]
    optional = [
        ("PointMassDamper", dict(mass=2.0, stiffness=50.0, damping=1.0,
                                 position=(0.5, 0.0, 0.0), direction=(0.0, 0.0, 1.0))),
        ("SphericalDamper", dict(inertia=0.3, damping=0.2)),
        ("HingedPanel", dict(mass=5.0, inertia=[1.0, 0.5, 0.6], hinge_point=[0.0, 1.0, 0.0],
                             cm_offset=[0.0, 1.0, 0.0], axis=[1.0, 0.0, 0.0],
                             stiffness=5.0, damping=0.1)),
        ("CMGCluster", dict(gimbal_axes=np.eye(3)[:, [2]], spin_axes0=np.eye(3)[:, [0]],
                            h=[1.0], u_max=1.0)),
        ("Slosh", dict(mass=3.0)),
    ]
    for cls_name, kwargs in optional:
        cls = getattr(sc, cls_name, None)
        if cls is None:
            continue
        try:
            out.append(cls(**kwargs))
        except (TypeError, ValueError):
            continue
    while len(out) < 10:  # fill with more of the basic kinds
        k = len(out)
        out.append(sc.HeldRotor([1.0, 0.0, 0.0] if k % 2 else [0.0, 1.0, 0.0], 0.5 + k))
    return out[:10]


def _median_time(fun, repeats):
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fun()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def _build_times(repeats: int) -> list:
    out = []
    all_parts = parts()
    for k in range(1, len(all_parts) + 1):
        def build():
            cache.clear()
            return sc.Scene(sc.RigidHub(INERTIA), *all_parts[:k]).model()
        model = build()
        out.append({"parts": k, "states": model.nx, "controls": model.nu,
                    "build_s": _median_time(build, repeats),
                    "kinds": ",".join(sorted({type(p).__name__ for p in all_parts[:k]}))})
    return out


def _hand_written_rigid_body():
    """The hand-written rigid body of before the scene (the tests' reference), or None."""
    path = Path(__file__).resolve().parents[1] / "tests" / "dynamics" / "scene" / "legacy_momentum.py"
    if not path.is_file():
        return None
    spec = importlib.util.spec_from_file_location("appdyn_bench_legacy_momentum", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.rigid_body(INERTIA)


def _speed(repeats: int) -> list:
    hub_only = sc.Scene(sc.RigidHub(INERTIA)).model()
    rb = _hand_written_rigid_body() or rigid_body(INERTIA)
    rows = []
    for label, kw in (("rk8, 20 steps/output, compiled", dict(method="rk8", steps=20, jit=True)),
                      ("auto, rtol 1e-10", dict(method="auto", rtol=1e-10, atol=1e-12))):
        for model in (hub_only, rb):  # first calls: compile and cache
            simulate(model, X0, GRID, **kw)
        t_scene, t_rb = [], []
        for _ in range(repeats):  # interleaved: this VM's speed drifts within seconds
            t_scene.append(_median_time(lambda: simulate(hub_only, X0, GRID, **kw), 3))
            t_rb.append(_median_time(lambda: simulate(rb, X0, GRID, **kw), 3))
        a = simulate(hub_only, X0, GRID, **kw).x
        b = simulate(rb, X0, GRID, **kw).x
        rows.append({"case": label, "scene_s": statistics.median(t_scene),
                     "rigid_body_s": statistics.median(t_rb),
                     "ratio": statistics.median(t_scene) / statistics.median(t_rb),
                     "max_state_difference": float(np.max(np.abs(a - b))),
                     "states": hub_only.nx, "instructions_scene": hub_only.f.n_instructions(),
                     "instructions_rigid_body": rb.f.n_instructions()})
    return rows


def _multipliers_formed() -> bool:
    cache.clear()
    names = [n for n in dir(constrained) if callable(getattr(constrained, n)) and not n.startswith("_")]
    patches = [mock.patch.object(constrained, n, side_effect=AssertionError(n)) for n in names]
    for p in patches:
        p.start()
    try:
        sc.Scene(sc.RigidHub(INERTIA), *parts()).model()
        return False
    except AssertionError:
        return True
    finally:
        for p in patches:
            p.stop()


def run(quick: bool, out: Path):
    repeats = 3 if quick else 7
    speed = _speed(repeats)
    builds = _build_times(3 if quick else 5)
    formed = _multipliers_formed()
    write_csv([{"kind": "speed", **r} for r in speed] + [{"kind": "build", **r} for r in builds],
              out / f"{NAME}.csv")
    rows = []
    for r in speed:
        rows.append(Row(NAME, f"hub-only scene vs hand-written rigid body, 60 s torque-free, "
                              f"{r['case']}",
                        "wall time ratio (scene / hand-written)", r["ratio"], "x",
                        f"{r['scene_s'] * 1e3:.3g} ms vs {r['rigid_body_s'] * 1e3:.3g} ms; "
                        f"{r['states']} states; {r['instructions_scene']} vs "
                        f"{r['instructions_rigid_body']} instructions; states differ by "
                        f"{r['max_state_difference']:.1e}"))
    worst = max(builds, key=lambda r: r["build_s"])
    rows.append(Row(NAME, f"Scene(...).model() build, 1 to {len(builds)} parts, cache cleared",
                    "slowest build (median of repeats)", worst["build_s"], "s",
                    f"{worst['parts']} parts, {worst['states']} states: {worst['kinds']}"))
    rows.append(Row(NAME, f"{len(builds)}-part scene", "multiplier system formed",
                    float(formed), "", "0: no part brings constraints, none is formed"))
    return rows


def main(argv=None) -> int:
    return script_main(run, argv)


if __name__ == "__main__":
    sys.exit(main())
