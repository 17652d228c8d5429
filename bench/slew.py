"""Optimal-slew benchmark: acceptance numbers of the collocation engine.

1. Bilimoria & Wie (1993): J = E, |u_i| <= 1, rest-to-rest 180 deg about z, no user guess.
   Median wall time over 5 runs of `problems.slew.time_optimal` including problem
   construction; T must lie in [3.2428, 3.2435] (best known 3.2430); the eigenaxis time
   2 sqrt(pi) = 3.5449 is printed beside it.
2. Minimum-effort single-axis slew against its closed form (cost 6 J^2 theta^2 / T^3) and
   the propagation error of the refined solution (target < 1e-6).
3. Scaling: build and IPOPT time of a minimum-effort slew versus N = 50 ... 800 (Radau,
   degree 3) and the log-log slopes.
4. Reuse: build time of a second `ocp.solve` of the same minimum-effort slew (N = 200) from
   another guess of the same magnitudes (the NLP and IPOPT solver come from
   `dynamics.cache`), and after `dynamics.clear_caches`.

Run: ``make bench`` or ``appdyn bench slew``; ``--quick`` for a smoke run.
"""
from __future__ import annotations

import sys
import time

import numpy as np

from ocp import solve
from problems import slew


def bilimoria_wie(runs):
    times, Ts, sols = [], [], []
    for _ in range(runs):
        t0 = time.perf_counter()
        sol = slew.time_optimal(np.eye(3), angle=np.pi, axis=[0, 0, 1], u_max=1.0)
        times.append(time.perf_counter() - t0)
        Ts.append(sol.T)
        sols.append(sol)
    return np.array(times), np.array(Ts), sols[-1]


def scaling(Ns):
    J, theta, T = np.array([2.0, 3.0, 4.0]), 1.0, 2.0
    problem = slew.slew_problem(J, objective="effort", T=T, angle=theta, axis=[1, 0.5, 0.2],
                                u_max=None)
    rows = []
    for N in Ns:
        sol = solve(problem, N=N, verbose=False)
        rows.append((N, sol.build_time, sol.solve_time, sol.iterations, sol.success))
    return rows


def reuse(N=200):
    from dynamics import clear_caches

    J = np.array([2.0, 3.0, 4.0])
    problem = slew.slew_problem(J, objective="effort", T=4.0, angle=1.0, axis=[1, 0.5, 0.2])
    guesses = {"first": slew.attitude_guess(problem),
               "another guess": slew.attitude_guess(problem, tilt_axis=[0, 0, 1], tilt=0.02)}
    rows = []
    for label, guess in guesses.items():
        sol = solve(problem, N=N, guess=guess)
        rows.append((label, sol.build_time, sol.solve_time, sol.cost))
    clear_caches()
    sol = solve(problem, N=N, guess=guesses["another guess"])
    rows.append(("after clear_caches", sol.build_time, sol.solve_time, sol.cost))
    return rows


def main(argv=()):
    quick = "--quick" in argv
    runs = 2 if quick else 5
    times, Ts, sol = bilimoria_wie(runs)
    eig = slew.eigenaxis_time(np.eye(3), np.pi, [0, 0, 1])
    ok = bool(np.all((Ts >= 3.2428) & (Ts <= 3.2435)))
    print("Bilimoria & Wie time-optimal 180 deg slew (J = E, |u_i| <= 1), no user guess:")
    print(f"  T = {np.median(Ts):.6f} s (runs: {', '.join(f'{t:.6f}' for t in Ts)}) "
          f"in [3.2428, 3.2435]: {ok}")
    print(f"  eigenaxis maneuver T = 2 sqrt(pi) = {eig:.6f} s  (optimal is "
          f"{100 * (1 - np.median(Ts) / eig):.2f}% shorter)")
    print(f"  median wall time over {runs} runs (incl. construction): {np.median(times):.3f} s "
          f"(min {times.min():.3f}, max {times.max():.3f}); target < 2 s")
    print(slew.format_summary(slew.summary(sol, eigenaxis=eig)))

    J, theta, T = np.array([2.0, 3.0, 4.0]), 1.0, 2.0
    t0 = time.perf_counter()
    me = slew.min_effort(J, T, angle=theta, axis=[1, 0, 0], tol=1e-8)
    wall = time.perf_counter() - t0
    exact = 6 * J[0] ** 2 * theta**2 / T**3
    print("\nMinimum-effort single-axis slew (J1 = 2, theta = 1 rad, T = 2 s):")
    print(f"  cost {me.cost:.12f} vs closed form {exact:.12f}: rel. error "
          f"{abs(me.cost / exact - 1):.1e}; propagation error {me.propagation_error:.2e} "
          f"(target < 1e-6); wall {wall:.3f} s; {me.t.size} nodes")

    Ns = [50, 100, 200] if quick else [50, 100, 200, 400, 800]
    rows = scaling(Ns)
    print("\nScaling with N (min-effort slew, Radau degree 3):")
    print(f"  {'N':>5} {'build [s]':>10} {'IPOPT [s]':>10} {'iters':>6}")
    for N, b, s, it, success in rows:
        print(f"  {N:>5} {b:>10.3f} {s:>10.3f} {it:>6d}{'' if success else '  (failed)'}")
    n = np.log([r[0] for r in rows])
    for label, col in (("build", 1), ("IPOPT", 2), ("IPOPT per iteration", None)):
        y = np.array([r[2] / r[3] if col is None else r[col] for r in rows])
        slope = np.polyfit(n, np.log(y), 1)[0]
        print(f"  log-log slope of {label} time vs N ({Ns[0]}..{Ns[-1]}): {slope:.2f}")

    print("\nReuse: the same min-effort slew (N = 200) solved again from another guess:")
    print(f"  {'solve':<20} {'build [s]':>10} {'IPOPT [s]':>10} {'cost':>14}")
    for label, b, t, cost in reuse():
        print(f"  {label:<20} {b:>10.3f} {t:>10.3f} {cost:>14.10f}")


if __name__ == "__main__":
    main(sys.argv[1:])
