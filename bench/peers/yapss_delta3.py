"""yapss peer: the four-phase Delta III ascent; runs in bench/peers/.venv-yapss (casadi <= 3.7.2).

The problem is yapss's own example, ``yapss.examples.delta_iii_ascent`` (yapss 0.2.3,
``python -m yapss.examples.delta_iii_ascent``): this script imports its ``setup()`` unchanged
(SI units, yapss user scaling by R_e / sqrt(mu/R_e) / initial mass, LGL collocation with
5 segments x 5 points per phase, IPOPT through the libipopt bundled in the casadi wheel, with
MUMPS) and only times the solve and reports the answer.

Usage (from the project root)::

    bench/peers/.venv-yapss/bin/python bench/peers/yapss_delta3.py --json --quiet

``--json`` prints one JSON object on stdout: final_mass (kg), phase_end_times (s, 4),
solve_time (s, ``Problem.solve()`` alone: NLP construction with CasADi derivatives + IPOPT),
ipopt_time (s, from IPOPT's first iteration callback to the end), total_time (s, the example's
``setup()`` + solve; importing yapss and the example module is import_time), iterations
(IPOPT), status, mesh, n_variables, yapss, casadi. Every solver print (IPOPT writes to the
C-level stdout) is sent to stderr while solving, so stdout carries only the JSON.
``--quiet`` silences IPOPT (print_level 0) altogether.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from importlib.metadata import version

from _runner import stdout_to_stderr


def run(quiet: bool) -> dict:
    import casadi
    import numpy as np

    t_import = time.perf_counter()
    from yapss.examples import delta_iii_ascent as ex  # also imports matplotlib

    t_start = time.perf_counter()
    ocp = ex.setup()
    if quiet:
        ocp.ipopt_options.print_level = 0
        ocp.ipopt_options.sb = "yes"

    # count IPOPT iterations through yapss's intermediate callback (keeps its abort logic)
    seen = {"iter": None, "t_first": None}
    original_cb = ocp._intermediate_cb

    def counting_cb(*args):
        if seen["t_first"] is None:
            seen["t_first"] = time.perf_counter()
        seen["iter"] = int(args[1])
        return original_cb(*args)

    try:
        object.__setattr__(ocp, "_intermediate_cb", counting_cb)
    except Exception:  # a later yapss may forbid it: iterations then stay null
        pass

    t_solve = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        solution = ocp.solve()
    t_end = time.perf_counter()

    phases = solution.phase
    mesh = ocp.mesh.phase
    segs = [len(mesh[p].collocation_points) for p in range(4)]
    pts = [tuple(int(n) for n in mesh[p].collocation_points) for p in range(4)]
    mesh_desc = (f"{ocp.spectral_method.upper()} collocation, 4 phases x "
                 f"{segs[0]} segments x {pts[0][0]} points"
                 if len(set(pts)) == 1 and len(set(pts[0])) == 1
                 else f"{ocp.spectral_method.upper()}, collocation points per phase {pts}")
    return {
        "final_mass": float(phases[3].state[6][-1]),
        "objective": float(solution.objective),
        "phase_end_times": [float(phases[p].final_time) for p in range(4)],
        "solve_time": t_end - t_solve,
        "ipopt_time": (t_end - seen["t_first"]) if seen["t_first"] else None,
        "total_time": t_end - t_start,
        "import_time": t_start - t_import,
        "iterations": seen["iter"],
        "status": solution.nlp_info.ipopt_status_message,
        "ipopt_status": int(solution.nlp_info.ipopt_status),
        "mesh": mesh_desc,
        "n_variables": int(np.asarray(solution.nlp_info.x).size),
        "example": "yapss.examples.delta_iii_ascent",
        "yapss": version("yapss"),
        "casadi": casadi.__version__,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    ap.add_argument("--quiet", action="store_true", help="silence IPOPT output")
    args = ap.parse_args()
    if args.json:
        with stdout_to_stderr():
            out = run(args.quiet)
        json.dump(out, sys.stdout)
        sys.stdout.write("\n")
    else:
        out = run(args.quiet)
        for key, value in out.items():
            print(f"{key:>16}: {value}")


if __name__ == "__main__":
    main()
