"""OCP work-precision benchmark: objective error against work for every transcription.

Each problem is solved by `ocp.solve` on uniform meshes of N intervals (N swept) with the
transcriptions ``trapezoid``, ``hermite-simpson``, ``radau`` degree 3 and ``radau`` degree 5,
IPOPT at ``tol = 1e-12`` without bound relaxation (so the error is the discretization's, not
IPOPT's, down to ~1e-10). Per run: build time (guess, scaling, NLP and solver: every run is a
new structure, so it is built; one unrecorded warm-up solve at N = 4 per problem and
transcription first builds the interval kernels, so the rows time what a new N costs), IPOPT
time (single runs, not medians), iterations, status, the relative error of the
collocated objective ``|cost - J*| / |J*|``, the relative error of the *re-simulated*
objective (`ocp.Solution.simulated_cost`: what the returned control achieves) and the
propagation errors (`ocp.Solution.propagation_error`, mixed units, and the largest per-state
scaled one of `ocp.Solution.propagation_errors`).

Problems and their references
-----------------------------
1. ``min-effort slew``: rigid body J = diag(2, 3, 4) kg m^2, 1 rad about x in T = 2 s,
   minimum ``1/2 int |u|^2``: closed form ``6 J1^2 theta^2 / T^3 = 3`` (the cubic
   eigenaxis profile; the angle is cubic in t but the quaternion is not, so no
   transcription is exact).
2. ``Bilimoria-Wie``: time-optimal 180 deg rest-to-rest slew about z, J = E, ``|u_i| <= 1``:
   best known T = 3.2430832775 s (Bilimoria & Wie 1993; `problems.slew.time_optimal` with
   its switch polish reproduces it). The non-convex problem needs a guess: every run starts
   from one `problems.slew.time_optimal` solution (N = 30, polished; its time is reported in
   its own CSV row, ``transcription = 'time_optimal (polished)'``), interpolated to the run's
   mesh. Bang-bang controls with switches between mesh points: no transcription shows its
   smooth order; the error falls irregularly (not monotonically: Hermite-Simpson measured
   1.2e-4, 1.1e-4, 3.1e-8, 4.5e-8, 4.7e-8 at N = 20 ... 320) and stalls near 3e-8 -- 1e-7,
   far above what the switch polish of `problems.slew.time_optimal` reaches (1.5e-11 at
   N = 30).
3. ``min-energy`` (`ocp.examples.min_energy`, Bryson & Ho): ``J = 6 d^2 / T^3``; polynomial
   optimum (exact for Hermite-Simpson and Radau).
4. ``min-time`` (`ocp.examples.min_time`): ``T = 2 sqrt(d / u_max)``; the switch at T/2 lies
   on a mesh point for even N, so every run with even N is exact to IPOPT's tolerance.
5. ``Goddard`` (`ocp.examples.goddard_rocket`, COPS 3.0): ``h(tf) = 1.0128369183``
   (`ocp.examples.GODDARD_OPTIMUM`); a singular arc: the collocated objective may beat the
   optimum, the re-simulated one is the honest number.
6. ``brachistochrone`` (Bernoulli; the tests' `tests/ocp/reference.py` builds the same):
   from rest at the origin to (1, 1) m, g = 9.81, free T; the cycloid's T* from its closed
   form (a smooth, non-polynomial optimum; Radau degree 5 is at 1e-15 already at N = 10).
7. ``wheel slew``: minimum-effort slew by four reaction wheels (three orthogonal plus a
   skewed one) on a hub with products of inertia, 1.2 rad about (1, 2, 0.5), T = 4 s. No
   closed form: the reference is this benchmark's OWN fine solution (Radau degree 5,
   N = 640; quick: N = 160), so the error is a self-convergence error (a summary row gives
   how far the finest Hermite-Simpson run lies from it).

Outputs: ``ocp_precision.csv`` (one row per run), ``ocp_precision.png`` (objective error vs
IPOPT time, log-log, one line per transcription, one panel per problem; the re-simulated
error of Goddard as well). Summary rows: per problem the cheapest successful run (build +
IPOPT time) whose collocated *and* re-simulated objective errors are <= 1e-6 relative, and
per transcription the least-squares log-log slopes of build and IPOPT time in N (over the
runs of the smooth problems 1, 3, 6, 7 that succeeded, one intercept per problem).

What to expect (measured on a 2-core machine)
----------------------------------------------
* The re-simulated objective has a floor of ~1e-11 * N relative (one CVODES solve per mesh
  interval at rtol = atol = 1e-12, errors adding up): below ~1e-9 at N = 320 the collocated
  error is the finer number.
* Radau degree 5 costs most per iteration, and not from function evaluations: on the wheel
  slew at N = 320, 4 iterations took 3.3 s in IPOPT's own linear algebra (MUMPS) against
  0.39 s for degree 3 (twice the Jacobian nonzeros, eight times the time).
* Goddard: IPOPT's iteration count grows with N on the singular arc (Radau-5: 26 at N = 10,
  209 at N = 320); the collocated error stalls near 1e-6 for the high-order transcriptions
  while the trapezoid's re-simulated error falls fastest (smoothing by its low order).

Run: ``python bench/ocp_precision.py [--quick] [--out DIR]`` or ``appdyn bench ocp_precision``.
"""
from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import casadi as ca
import numpy as np
from scipy.optimize import brentq

from _common import Row, save_figure, script_main, write_csv  # bench/ on sys.path (runner, script)
from appdyn.dynamics import wheel_spacecraft
from appdyn.dynamics.model import Model
from appdyn.ocp import Problem, solve
from appdyn.ocp.examples import GODDARD_OPTIMUM, goddard_rocket, min_energy, min_time
from appdyn.ocp.status import status_name
from appdyn.problems import slew

NAME = "ocp_precision"
BW_T = 3.2430832775  # Bilimoria & Wie (1993), best known
TARGET = 1e-6  # relative objective error of the summary
#: IPOPT for accuracy: tolerance far below the errors measured, bounds not relaxed
IPOPT = {"tol": 1e-12, "bound_relax_factor": 0.0, "max_iter": 1000}
#: (label, transcription, degree)
METHODS = (("trapezoid", "trapezoid", None), ("hermite-simpson", "hermite-simpson", None),
           ("radau-3", "radau", 3), ("radau-5", "radau", 5))
QUICK_N, FULL_N = (10, 20, 40), (10, 20, 40, 80, 160, 320)
REF_N = {True: 160, False: 640}  # N of the wheel slew's self-reference (radau-5)
SMOOTH = ("min-effort slew", "min-energy", "brachistochrone", "wheel slew")


# ----------------------------------------------------------------------------- problems
def brachistochrone(xf=1.0, yf=1.0, g=9.81):
    """``(problem, T*, guess)``: x' = v sin(th), y' = v cos(th), v' = g cos(th) (y down)."""
    x, th, p = ca.SX.sym("x", 3), ca.SX.sym("theta"), ca.SX.sym("p", 0)
    rhs = ca.vertcat(x[2] * ca.sin(th), x[2] * ca.cos(th), g * ca.cos(th))
    model = Model(ca.Function("brachistochrone", [x, th, p], [rhs], ["x", "u", "p"], ["xdot"]),
                  ("x", "y", "v"), ("theta",), name="brachistochrone")
    pr = Problem(model, T=(0.1, 5.0), x_initial=[0.0, 0.0, 0.0], x_final={"x": xf, "y": yf},
                 u_bounds={"theta": (-math.pi, math.pi)}, mayer=lambda xf_, p_, T: T,
                 name="brachistochrone")
    phi = brentq(lambda f: (f - math.sin(f)) / (1 - math.cos(f)) - xf / yf, 1e-6, 2 * math.pi - 1e-6,
                 xtol=1e-15, rtol=4 * np.finfo(float).eps)
    R = yf / (1 - math.cos(phi))
    # the default guess (v = 0, theta = 0) has a rank-deficient constraint Jacobian
    guess = {"x": np.array([[0.0, xf], [0.0, yf], [0.0, 4.0]]), "u": np.array([[0.8, 0.8]]), "T": 1.0}
    return pr, phi * math.sqrt(R / g), guess


def wheel_problem():
    """Minimum-effort slew by four wheels (three orthogonal, one skewed), no closed form."""
    I = np.array([[10.0, 0.5, -0.3], [0.5, 12.0, 0.4], [-0.3, 0.4, 8.0]])
    s = 1.0 / math.sqrt(3.0)
    A = np.array([[1.0, 0.0, 0.0, s], [0.0, 1.0, 0.0, s], [0.0, 0.0, 1.0, s]])
    model = wheel_spacecraft(I, A, 0.05)
    axis = np.array([1.0, 2.0, 0.5]) / np.linalg.norm([1.0, 2.0, 0.5])
    angle = 1.2
    qf = np.r_[math.sin(angle / 2) * axis, math.cos(angle / 2)]
    n = A.shape[1]
    return Problem(model, T=4.0, x_initial=np.r_[0, 0, 0, 1, 0, 0, 0, np.zeros(n)],
                   x_final=np.r_[np.full(4, np.nan), 0, 0, 0, np.full(n, np.nan)], q_final=qf,
                   lagrange=lambda x, u, p: 0.5 * ca.sumsqr(u), name="wheel slew (effort)")


def cases(quick):
    """``[(name, problem, reference, guess, note)]`` (guess None: the engine's default)."""
    J = np.array([2.0, 3.0, 4.0])
    effort = slew.slew_problem(J, objective="effort", T=2.0, angle=1.0, axis=[1, 0, 0], u_max=None)
    bw = slew.slew_problem(np.eye(3), objective="time", angle=np.pi, axis=[0, 0, 1], u_max=1.0)
    brach, T_brach, g_brach = brachistochrone()
    out = [("min-effort slew", effort, 6 * J[0] ** 2 * 1.0 ** 2 / 2.0 ** 3, None,
            "closed form 6 J1^2 theta^2 / T^3"),
           ("Bilimoria-Wie", bw, BW_T, "time_optimal", "best known T (Bilimoria & Wie 1993)"),
           ("min-energy", min_energy(), 6.0, None, "closed form 6 d^2 / T^3 (Bryson & Ho)"),
           ("min-time", min_time(), 2.0, None, "closed form 2 sqrt(d / u_max)"),
           ("Goddard", goddard_rocket(), GODDARD_OPTIMUM["h_f"], None,
            "h(tf) of the bang/singular/coast structure (COPS 3.0: 1.01283)"),
           ("brachistochrone", brach, T_brach, g_brach, "closed form (cycloid)"),
           ("wheel slew", wheel_problem(), None, None,
            f"self-reference: radau-5, N = {REF_N[quick]}")]
    return out


# ----------------------------------------------------------------------------- runs
def _rel(value, ref):
    return abs(value - ref) / abs(ref) if np.isfinite(value) else float("nan")


def one_run(name, problem, ref, guess, label, transcription, degree, N):
    sol = solve(problem, transcription=transcription, degree=degree, N=N, guess=guess,
                ipopt_options=IPOPT)
    t0 = time.perf_counter()
    try:
        prop_ok = sol.propagation.success
        sim_cost, prop_err = sol.simulated_cost, sol.propagation_error
        scaled = max((v[1] for v in sol.propagation_errors.values()), default=0.0)
    except Exception:  # noqa: BLE001 - a failed re-simulation is a number, not a crash
        prop_ok, sim_cost, prop_err, scaled = False, float("nan"), float("nan"), float("nan")
    prop_time = time.perf_counter() - t0
    row = dict(problem=name, transcription=label, N=N, success=bool(sol.success),
               status=status_name(sol.status),
               iterations=int(sol.iterations), build_time=float(sol.build_time),
               solve_time=float(sol.solve_time),
               time_per_iteration=float(sol.solve_time) / max(int(sol.iterations), 1),
               cost=float(sol.cost), reference=ref,
               cost_error=float("nan"), simulated_cost=float(sim_cost), simulated_cost_error=float("nan"),
               propagation_error=float(prop_err), propagation_error_scaled=float(scaled),
               propagation_success=bool(prop_ok), propagation_time=prop_time)
    return row, sol


def _errors(row):
    ref = row["reference"]
    if ref is not None and np.isfinite(ref):
        row["cost_error"] = _rel(row["cost"], ref)
        row["simulated_cost_error"] = _rel(row["simulated_cost"], ref)
    return row


def sweep(quick):
    Ns = QUICK_N if quick else FULL_N
    rows = []
    for name, problem, ref, guess, note in cases(quick):
        extra = []
        if guess == "time_optimal":  # one polished time-optimal solution as the guess
            t0 = time.perf_counter()
            first = slew.time_optimal(np.eye(3), angle=np.pi, axis=[0, 0, 1], u_max=1.0, N=30)
            wall = time.perf_counter() - t0
            guess = first
            extra.append(dict(problem=name, transcription="time_optimal (polished)", N=30,
                              success=bool(first.success), status=status_name(first.status),
                              iterations=int(first.iterations), build_time=float("nan"),
                              solve_time=wall, time_per_iteration=float("nan"),
                              cost=float(first.T), reference=ref,
                              cost_error=float("nan"), simulated_cost=float(first.T),
                              simulated_cost_error=float("nan"), propagation_error=float("nan"),
                              propagation_error_scaled=float("nan"), propagation_success=True,
                              propagation_time=0.0))
        if ref is None:  # self-reference from a fine Radau-5 solution
            N_ref = REF_N[quick]
            r, _ = one_run(name, problem, None, guess, "radau-5 (reference)", "radau", 5, N_ref)
            ref = r["cost"] if r["success"] else float("nan")
            r["reference"] = ref
            extra.append(r)
        for row in extra:
            row["note"] = note
            rows.append(_errors(row))
        for label, tr, degree in METHODS:
            # warm-up (not recorded): the first solve of a model and transcription builds its
            # interval kernels; the rows then time what a new N costs
            solve(problem, transcription=tr, degree=degree, N=4, guess=guess, ipopt_options=IPOPT)
            for N in Ns:
                r, _ = one_run(name, problem, ref, guess, label, tr, degree, N)
                r["note"] = note
                rows.append(_errors(r))
    return rows


# ----------------------------------------------------------------------------- summary
def cheapest(rows, problem):
    """The successful run of ``problem`` with the least build + IPOPT time whose collocated and
    re-simulated objective errors are both <= TARGET, or None."""
    ok = [r for r in rows if r["problem"] == problem and r["success"] and np.isfinite(r["build_time"])
          and r["transcription"] in {m[0] for m in METHODS}
          and r["cost_error"] <= TARGET and r["simulated_cost_error"] <= TARGET]
    return min(ok, key=lambda r: r["build_time"] + r["solve_time"]) if ok else None


def slopes(rows, label):
    """Least-squares log-log slopes of build and IPOPT time in N (smooth problems, successes),
    with the problem as a per-problem offset (each problem its own intercept)."""
    sel = [r for r in rows if r["transcription"] == label and r["problem"] in SMOOTH and r["success"]]
    probs = sorted({r["problem"] for r in sel})
    if len({r["N"] for r in sel}) < 2:
        return float("nan"), float("nan")
    X = np.array([[math.log(r["N"])] + [1.0 * (r["problem"] == p) for p in probs] for r in sel])
    out = []
    for key in ("build_time", "solve_time"):
        y = np.log([max(r[key], 1e-9) for r in sel])
        out.append(float(np.linalg.lstsq(X, y, rcond=None)[0][0]))
    return tuple(out)


def summary(rows):
    out = []
    for name in dict.fromkeys(r["problem"] for r in rows):
        best = cheapest(rows, name)
        if best is None:
            errs = [r["cost_error"] for r in rows if r["problem"] == name and r["success"]
                    and r["transcription"] in {m[0] for m in METHODS} and np.isfinite(r["cost_error"])]
            out.append(Row(NAME, f"{name}, objective error <= 1e-6", "not reached", float("nan"), "",
                           f"smallest collocated error {min(errs):.1e}" if errs else "no successful run"))
            continue
        out.append(Row(NAME, f"{name}, objective error <= 1e-6", "build + IPOPT time",
                       best["build_time"] + best["solve_time"], "s",
                       f"{best['transcription']}, N = {best['N']}, error {best['cost_error']:.1e} "
                       f"(re-simulated {best['simulated_cost_error']:.1e}), IPOPT {best['solve_time']:.3f} s"))
    for r in rows:
        if r["transcription"] == "time_optimal (polished)":
            out.append(Row(NAME, f"{r['problem']}, problems.slew.time_optimal", "objective error",
                           r["cost_error"], "", f"N = 30, 3 starts + switch polish, T = {r['cost']:.10f}, "
                           f"wall {r['solve_time']:.3f} s (first call of the process), success {r['success']}"))
        if r["transcription"] == "radau-5 (reference)":
            hs = [q for q in rows if q["problem"] == r["problem"] and q["transcription"] == "hermite-simpson"
                  and q["success"]]
            check = max(hs, key=lambda q: q["N"]) if hs else None
            out.append(Row(NAME, f"{r['problem']}, self-reference", "objective", r["cost"], "",
                           f"radau-5, N = {r['N']}; hermite-simpson N = {check['N']} differs by "
                           f"{check['cost_error']:.1e} relative" if check else f"radau-5, N = {r['N']}"))
    for label, _, _ in METHODS:
        b, s = slopes(rows, label)
        out.append(Row(NAME, f"{label}, smooth problems", "log-log slope of build time in N", b, "",
                       "least squares, one intercept per problem"))
        out.append(Row(NAME, f"{label}, smooth problems", "log-log slope of IPOPT time in N", s, "",
                       "least squares, one intercept per problem"))
    return out


# ----------------------------------------------------------------------------- figure
def figure(rows):
    from matplotlib.figure import Figure
    from matplotlib.ticker import NullFormatter

    names = list(dict.fromkeys(r["problem"] for r in rows))
    ncol = 4
    nrow = math.ceil(len(names) / ncol)
    fig = Figure(figsize=(4.2 * ncol, 3.4 * nrow))
    floor = 1e-16
    for k, name in enumerate(names):
        ax = fig.add_subplot(nrow, ncol, k + 1)
        for j, (label, _, _) in enumerate(METHODS):
            sel = sorted((r for r in rows if r["problem"] == name and r["transcription"] == label),
                         key=lambda r: r["N"])
            if not sel:
                continue
            t = np.array([r["solve_time"] for r in sel])
            e = np.array([max(r["cost_error"], floor) for r in sel])
            ok = np.array([r["success"] for r in sel])
            line, = ax.loglog(t, e, "o-", color=f"C{j}", label=label)
            ax.loglog(t[~ok], e[~ok], "x", color="k", ms=9)
            if name == "Goddard":
                es = np.array([max(r["simulated_cost_error"], floor) for r in sel])
                ax.loglog(t, es, "s:", color=f"C{j}", mfc="none")
        ax.axhline(TARGET, color="0.6", lw=0.8, ls="--")
        ax.set_title(name + (" (self-reference)" if name == "wheel slew" else ""), fontsize=10)
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("IPOPT time [s]")
        if k % ncol == 0:
            ax.set_ylabel("relative objective error")
        if k == 0:
            ax.legend(fontsize=7)
    fig.suptitle("OCP work-precision (x: not successful; Goddard dotted: re-simulated objective; "
                 "errors floored at 1e-16)", fontsize=10)
    fig.tight_layout()
    return fig


def run(quick: bool, out: Path) -> list:
    out = Path(out)
    t0 = time.perf_counter()
    rows = sweep(quick)
    wall = time.perf_counter() - t0
    write_csv(rows, out / f"{NAME}.csv")
    save_figure(figure(rows), out / f"{NAME}.png")
    summ = summary(rows)
    summ.append(Row(NAME, "whole sweep", "wall time", wall, "s",
                    f"{len(rows)} runs, re-simulation included"))
    return summ


def main(argv=()):
    return script_main(run, list(argv))


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
