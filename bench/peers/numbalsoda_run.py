"""numbalsoda peer of bench/simulate.py; runs in bench/peers/.venv-numbalsoda (own numpy/numba).

Reads a JSON job from stdin, prints JSON to stdout. Job: ``inertia``, ``t`` (output grid),
``x0`` (7,), ``tols`` (rtol list; atol = rtol/100), ``repeats``, and optionally ``batch``:
``{"x0s": (K, 7), "t": grid, "rtol": r}`` for the numba-jitted loop of dop853 runs.
Answers carry body rates (the main process computes errors against the Jacobi truth).
``mxstep`` (optional, default numbalsoda's 10,000): most steps of a run. ``warm`` (optional,
seconds, default 0): each tolerance's runs repeated that long before they are timed (as
appdyn's side is: ``bench/_common.py``, `warmed`).

A job with ``library`` (path of a shared library exporting ``peer_rhs(t, x, dx, p)``, the
signature of numbalsoda's ``lsoda_sig``: the right-hand side of any appdyn model compiled
from the same casadi-generated C as appdyn's own, see bench/integrate_peers.py) instead of
``inertia`` integrates that model; its answers carry the whole state (``x``) and, when the library exports ``peer_calls``
(the right-hand-side calls since its last call), ``rhs_calls`` of one run.
"""
import json
import sys
import time

import numba as nb
import numpy as np
from numbalsoda import dop853, lsoda, lsoda_sig


def make_rhs(inertia):
    I1, I2, I3 = inertia

    @nb.cfunc(lsoda_sig)
    def rhs(t, x, dx, p):
        q1, q2, q3, q4, w1, w2, w3 = x[0], x[1], x[2], x[3], x[4], x[5], x[6]
        dx[0] = 0.5 * (q4 * w1 + q2 * w3 - q3 * w2)
        dx[1] = 0.5 * (q4 * w2 + q3 * w1 - q1 * w3)
        dx[2] = 0.5 * (q4 * w3 + q1 * w2 - q2 * w1)
        dx[3] = -0.5 * (q1 * w1 + q2 * w2 + q3 * w3)
        dx[4] = (I2 - I3) * w2 * w3 / I1
        dx[5] = (I3 - I1) * w3 * w1 / I2
        dx[6] = (I1 - I2) * w1 * w2 / I3

    return rhs.address


def main():
    job = json.load(sys.stdin)
    if job.get("library"):
        import ctypes
        lib = ctypes.CDLL(job["library"])
        ptr = ctypes.cast(lib.peer_rhs, ctypes.c_void_p).value
        calls = getattr(lib, "peer_calls", None)
        if calls is not None:
            calls.restype = ctypes.c_longlong
    else:
        calls = None
        ptr = make_rhs(job["inertia"])
    t = np.asarray(job["t"], float)
    x0 = np.asarray(job["x0"], float)
    out = {"runs": []}
    mxstep = int(job.get("mxstep", 10000))
    for name, solver in (("lsoda", lsoda), ("dop853", dop853)):
        if name not in job.get("solvers", ("lsoda", "dop853")):
            continue
        for rtol in job["tols"]:
            times, extra = [], {}
            warm = time.perf_counter() + job.get("warm", 0.0)  # (as appdyn's `warmed`)
            while time.perf_counter() < warm:
                solver(ptr, x0, t, rtol=rtol, atol=rtol * 1e-2, mxstep=mxstep)
            for k in range(job["repeats"] + 1):
                if calls is not None and k == 1:
                    calls()
                t0 = time.perf_counter()
                usol, ok = solver(ptr, x0, t, rtol=rtol, atol=rtol * 1e-2, mxstep=mxstep)
                times.append(time.perf_counter() - t0)
                if calls is not None and k == 1:
                    extra["rhs_calls"] = int(calls())
            answer = dict(x=usol.tolist()) if job.get("library") else dict(w=usol[:, 4:7].tolist())
            out["runs"].append(dict(solver=name, rtol=rtol, first=times[0], times=times[1:],
                                    success=bool(ok), **answer, **extra))
    if job.get("batch"):
        b = job["batch"]
        x0s, tb, rtol = np.asarray(b["x0s"], float), np.asarray(b["t"], float), b["rtol"]

        @nb.njit
        def loop(x0s, tb, rtol):
            w = np.empty((x0s.shape[0], tb.size, 3))
            ok = True
            for k in range(x0s.shape[0]):
                usol, success = dop853(ptr, x0s[k], tb, rtol=rtol, atol=rtol * 1e-2)
                w[k] = usol[:, 4:7]
                ok = ok and success
            return w, ok

        times = []
        for _ in range(job["repeats"] + 1):
            t0 = time.perf_counter()
            w, ok = loop(x0s, tb, rtol)
            times.append(time.perf_counter() - t0)
        out["batch"] = dict(rtol=rtol, first=times[0], times=times[1:], success=bool(ok),
                            w=w.tolist())
    json.dump(out, sys.stdout)


if __name__ == "__main__":
    main()
