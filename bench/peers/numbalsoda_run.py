"""numbalsoda peer of bench/simulate.py; runs in bench/peers/.venv-numbalsoda (own numpy/numba).

Reads a JSON job from stdin, prints JSON to stdout. Job: ``inertia``, ``t`` (output grid),
``x0`` (7,), ``tols`` (rtol list; atol = rtol/100), ``repeats``, and optionally ``batch``:
``{"x0s": (K, 7), "t": grid, "rtol": r}`` for the numba-jitted loop of dop853 runs, with
``"u": (K, n, 3)`` each run's torque samples on the grid, linear between them (the right-hand
side reads its run's samples through numbalsoda's ``data`` pointer; ``"restart": true``: each
run restarted at every output time, so that no step straddles a kink of the interpolation).
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


def make_rhs_sampled(inertia):
    """The body under torques sampled on a uniform grid, linear between the samples: ``p``
    holds ``t0``, the spacing, the samples' count ``n`` and the samples ``(n, 3)``."""
    I1, I2, I3 = inertia

    @nb.cfunc(lsoda_sig)
    def rhs(t, x, dx, p):
        n = int(p[2])
        s = (t - p[0]) / p[1]
        k = min(max(int(np.floor(s)), 0), n - 2)
        f = s - k
        a, b = 3 + 3 * k, 6 + 3 * k
        u1 = p[a] + f * (p[b] - p[a])
        u2 = p[a + 1] + f * (p[b + 1] - p[a + 1])
        u3 = p[a + 2] + f * (p[b + 2] - p[a + 2])
        q1, q2, q3, q4, w1, w2, w3 = x[0], x[1], x[2], x[3], x[4], x[5], x[6]
        dx[0] = 0.5 * (q4 * w1 + q2 * w3 - q3 * w2)
        dx[1] = 0.5 * (q4 * w2 + q3 * w1 - q1 * w3)
        dx[2] = 0.5 * (q4 * w3 + q1 * w2 - q2 * w1)
        dx[3] = -0.5 * (q1 * w1 + q2 * w2 + q3 * w3)
        dx[4] = ((I2 - I3) * w2 * w3 + u1) / I1
        dx[5] = ((I3 - I1) * w3 * w1 + u2) / I2
        dx[6] = ((I1 - I2) * w1 * w2 + u3) / I3

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
        K = x0s.shape[0]
        if "u" in b:  # (each run's samples behind its data pointer)
            fun = make_rhs_sampled(job["inertia"])
            u = np.asarray(b["u"], float).reshape(K, -1)
            data = np.c_[np.tile([tb[0], tb[1] - tb[0], tb.size], (K, 1)), u]
        else:
            fun, data = ptr, np.zeros((K, 1))

        @nb.njit
        def loop(x0s, tb, rtol, data):
            w = np.empty((x0s.shape[0], tb.size, 3))
            ok = True
            for k in range(x0s.shape[0]):
                usol, success = dop853(fun, x0s[k], tb, data=data[k], rtol=rtol,
                                       atol=rtol * 1e-2)
                w[k] = usol[:, 4:7]
                ok = ok and success
            return w, ok

        @nb.njit
        def restarted(x0s, tb, rtol, data):  # (a run restarted at every sample: no kink inside)
            w = np.empty((x0s.shape[0], tb.size, 3))
            ok = True
            for k in range(x0s.shape[0]):
                x = x0s[k].copy()
                w[k, 0] = x[4:7]
                for j in range(tb.size - 1):
                    usol, success = dop853(fun, x, tb[j:j + 2], data=data[k], rtol=rtol,
                                           atol=rtol * 1e-2)
                    x = usol[1].copy()
                    w[k, j + 1] = x[4:7]
                    ok = ok and success
            return w, ok

        run = restarted if b.get("restart") else loop
        times = []
        for _ in range(job["repeats"] + 1):
            t0 = time.perf_counter()
            w, ok = run(x0s, tb, rtol, data)
            times.append(time.perf_counter() - t0)
        out["batch"] = dict(rtol=rtol, first=times[0], times=times[1:], success=bool(ok),
                            w=w.tolist())
    json.dump(out, sys.stdout)


if __name__ == "__main__":
    main()
