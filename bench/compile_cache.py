"""Compile-cache benchmark: what the first ``simulate`` of a model costs in a fresh process,
with an empty compile cache (the first-ever compile) and with the model compiled before on
this machine (issue "Compile once per machine", items 1 and 2).

Models: the rigid body (inertia (1.5, 2.5, 3.2), 7 states), the two hinged bodies (26
states), the 10-part scene of ``bench/scene.py`` (`scene.parts`, hub inertia
`scene.INERTIA`, 19 states) and a scene of 10 parts of the tests' registry
(``tests/dynamics/scene/registry.py``, the first 10 of ``ALL``: 35 states; and its first 13,
39 states, whose run ``auto``'s pass hands to its multi-run search: the call then needs
the fixed-step chunk too). Each run is a fresh Python process with ``APPDYN_CACHE_DIR`` set to a
temporary directory (emptied before the cold run): the model is built (not timed), then the
first ``simulate(model, x0, t)`` (default ``auto``, 21 outputs over 10 s) is timed; the
compiler's CPU time (``RUSAGE_CHILDREN``; the compiles run in parallel, so on an idle machine
the wall time of the wait is about the larger of them) and the process's compile-cache
counts are reported with it. Warm: the median of three fresh processes. In the cold
process, the model's vector lanes (which a batch, or its 16th single call, compiles in the
background) are then waited for: their compiler CPU time, and the step units their build of
the pass took from the first build's objects in the cache instead of compiling them.

Writes ``compile_cache.csv`` into the output folder and returns summary rows.
Run: ``appdyn bench compile_cache`` or ``python bench/compile_cache.py [--quick]``.
"""
from __future__ import annotations

import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from _common import Row, script_main, write_csv

NAME = "compile_cache"
HERE = Path(__file__).resolve().parent

CHILD = r"""
import json, resource, sys, time
sys.path.insert(0, sys.argv[2])
import numpy as np
from appdyn.dynamics import diskcache, hinged_bodies, rigid_body, simulate
which = sys.argv[1]
if which == "rigid_body":
    model = rigid_body([1.5, 2.5, 3.2])
    x0 = np.array([0.0, 0.0, 0.0, 1.0, 0.5, 0.0, 1.0])
elif which == "hinged_bodies":
    model = hinged_bodies(2.0, [1.0, 1.2, 0.8], 3.0, [0.9, 1.1, 1.3], [0, 0, 0.5], [0, 0, -0.5])
    x0 = model.initial_state([0, 0, 0, 1], [0.1, 0, 0.2], [1.0, 0, 0], [0, 0, 0, 1], [0.1, 0, 0.2])
elif which == "scene_10_parts":
    from appdyn.dynamics import scene as sc
    from scene import INERTIA, parts
    s = sc.Scene(sc.RigidHub(INERTIA), *parts())
    model, x0 = s.model(), s.state(w=[0.1, 0.2, 0.3])
else:  # the first 10 (or 13) parts of the tests' registry
    from appdyn.dynamics import scene as sc
    sys.path.insert(0, sys.argv[3])
    from registry import ALL, I_HUB, PARTS
    count = 13 if which.endswith("_13") else 10
    s = sc.Scene(sc.RigidHub(I_HUB), *[PARTS[n].make() for n in ALL[:count]])
    model, x0 = s.model(), s.state(w=[0.1, 0.2, 0.3])
t = np.linspace(0.0, 10.0, 21)
t0 = time.perf_counter()
res = simulate(model, x0, t)
wall = time.perf_counter() - t0
cpu = resource.getrusage(resource.RUSAGE_CHILDREN)
info = diskcache.info()
# then the vector lanes of batches (and the pass's build with their driver), which a model
# compiles in the background once a batch or its 16th single call asks for them: timed
# here waiting for them, their compiler CPU time and the units they took from the cache
from appdyn.dynamics.integrate import lanes
t0 = time.perf_counter()
vector = lanes.dense_lanes(model, wait=True)
lanes_wall = time.perf_counter() - t0
after = resource.getrusage(resource.RUSAGE_CHILDREN)
print(json.dumps({"wall_s": wall, "compiler_cpu_s": cpu.ru_utime + cpu.ru_stime,
                  "success": bool(res.success), "states": model.nx, "hits": info.hits,
                  "compiles": info.compiles, "lanes": vector is not None,
                  "lanes_wall_s": lanes_wall,
                  "lanes_compiler_cpu_s": after.ru_utime + after.ru_stime
                  - cpu.ru_utime - cpu.ru_stime,
                  "lanes_reused": diskcache.info().reused - info.reused}))
"""

MODELS = ("rigid_body", "hinged_bodies", "scene_10_parts", "scene_registry", "scene_registry_13")
#: the tests' registry of example parts (``scene_registry``; skipped when absent)
REGISTRY = HERE.parent / "tests" / "dynamics" / "scene"


def _child(which: str, cache_dir: str) -> dict:
    env = dict(os.environ, APPDYN_CACHE_DIR=cache_dir)
    env.pop("APPDYN_DISK_CACHE", None)
    done = subprocess.run([sys.executable, "-c", CHILD, which, str(HERE), str(REGISTRY)], env=env,
                          capture_output=True, text=True, timeout=1800)
    if done.returncode != 0:
        raise RuntimeError(f"{which}: {done.stderr.strip()[-500:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def measure(which: str, warm_repeats: int) -> dict:
    """Cold and warm first-simulate times of ``which`` (module docstring)."""
    cache_dir = tempfile.mkdtemp(prefix="appdyn-bench-cache-")
    try:
        cold = _child(which, cache_dir)
        warm = [_child(which, cache_dir) for _ in range(warm_repeats)]
    finally:
        shutil.rmtree(cache_dir, ignore_errors=True)
    return {"model": which, "states": cold["states"], "cold_s": cold["wall_s"],
            "cold_compiler_cpu_s": cold["compiler_cpu_s"], "cold_compiles": cold["compiles"],
            "warm_s": statistics.median(w["wall_s"] for w in warm),
            "warm_compiles": max(w["compiles"] for w in warm),
            "warm_hits": min(w["hits"] for w in warm),
            "lanes": cold["lanes"], "lanes_wall_s": cold["lanes_wall_s"],
            "lanes_compiler_cpu_s": cold["lanes_compiler_cpu_s"],
            "lanes_reused": cold["lanes_reused"],
            "success": cold["success"] and all(w["success"] for w in warm)}


def run(quick: bool, out: Path):
    results = [measure(which, 1 if quick else 3) for which in MODELS
               if not which.startswith("scene_registry") or (REGISTRY / "registry.py").exists()]
    write_csv(results, out / f"{NAME}.csv")
    rows = []
    for r in results:
        rows.append(Row(NAME, f"{r['model']} ({r['states']} states), first simulate, fresh "
                              "process, compiled before", "wall time", r["warm_s"], "s",
                        f"libraries loaded {r['warm_hits']}, compiled {r['warm_compiles']}"))
        rows.append(Row(NAME, f"{r['model']} ({r['states']} states), first simulate, empty "
                              "cache", "wall time", r["cold_s"], "s",
                        f"{r['cold_compiles']} compiles, compiler CPU "
                        f"{r['cold_compiler_cpu_s']:.2f} s"))
        if r["lanes"]:
            rows.append(Row(NAME, f"{r['model']} ({r['states']} states), its vector lanes "
                                  "after the first simulate, empty cache", "compiler CPU",
                            r["lanes_compiler_cpu_s"], "s",
                            f"waited {r['lanes_wall_s']:.2f} s; step units taken from the "
                            f"first build {r['lanes_reused']}"))
    return rows


def main(argv=None) -> int:
    return script_main(run, argv)


if __name__ == "__main__":
    sys.exit(main())
