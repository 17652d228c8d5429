"""Many runs at once: serial against executors, on this machine, in one process.

Every variant starts from empty caches (`dynamics.clear_caches`, also for forked workers)
and is warmed up by a small run that builds what is shared and starts the workers; what
each run builds for its own values (a model per sweep value or per sample) stays in the
timing, for every variant alike.

1. A stability sweep (gyrostat, wheel momentum over 41 values, two boundaries bisected to
   1e-8): serial, two threads, two processes, and a Dask
   ``LocalCluster`` with two worker processes when ``distributed`` is installed (skipped
   with a notice otherwise). Results must be identical to the serial run.
2. A Monte Carlo dispersion (`problems.dispersion.nutation_spread`, 100 samples): serial
   and two processes; per-sample wall time and the identity of the statistics.
3. A time-optimal slew's multistart (4 starts, `ocp.solve_multistart`): serial and two
   processes.
4. A maneuver table (`problems.slew.maneuver_table`, the 8 `example_targets`, J = diag(1,
   2, 3), time-optimal): serial, two threads and two processes; the same T in every row.

Writes ``many.csv`` (every variant's wall time) into the output folder and returns the
summary rows (`run`): the serial wall time and each executor's speed-up per workload.
Run: ``make bench`` or ``appdyn bench many`` (``--quick`` for a smoke run: 11 sweep values,
20 samples, no multistart, 4 targets without the thread pool, no Dask).
"""
from __future__ import annotations

import sys
import time
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor
from pathlib import Path

import numpy as np

from appdyn.dynamics import clear_caches
from appdyn.ocp import solve_multistart
from appdyn.problems import slew
from appdyn.problems import stability as st
from appdyn.problems.dispersion import nutation_spread

from _common import Row, script_main, write_csv

GYRO = dict(inertia=[3.0, 4.0, 5.0], axis=[1, 0, 0], rate=2.0)


def _timed(fun, *args, **kwargs):
    """``(wall time, fun(...))``."""
    t0 = time.perf_counter()
    out = fun(*args, **kwargs)
    return time.perf_counter() - t0, out


def _dask():
    try:
        import distributed
    except ImportError:
        return None
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=None, silence_logs=50)
    return cluster, distributed.Client(cluster)


def sweeps(values, dask=True):
    rows = []
    clear_caches()
    st.sweep("gyrostat", "wheel_momentum", values[:2], **GYRO)  # builds, as each pool's warm-up
    serial_t, serial = _timed(st.sweep, "gyrostat", "wheel_momentum", values, **GYRO)
    rows.append(("serial", serial_t, True))
    clear_caches()
    with ThreadPoolExecutor(2) as pool:
        st.sweep("gyrostat", "wheel_momentum", values[:2], executor=pool, **GYRO)
        t, res = _timed(st.sweep, "gyrostat", "wheel_momentum", values, executor=pool, **GYRO)
        rows.append(("2 threads", t, res.to_json() == serial.to_json()))
    clear_caches()  # forked workers start with what the parent holds
    with ProcessPoolExecutor(2) as pool:
        st.sweep("gyrostat", "wheel_momentum", values[:2], executor=pool, **GYRO)  # start workers
        t, res = _timed(st.sweep, "gyrostat", "wheel_momentum", values, executor=pool, **GYRO)
        rows.append(("2 processes", t, res.to_json() == serial.to_json()))
    clear_caches()
    wanted, dask = dask, (_dask() if dask else None)
    if dask is None:
        print("  (Dask LocalCluster skipped: "
              + ("--quick)" if not wanted else "pip install -e '.[distributed]')"))
    else:
        cluster, client = dask
        try:
            ex = client.get_executor()
            st.sweep("gyrostat", "wheel_momentum", values[:2], executor=ex, **GYRO)
            t, res = _timed(st.sweep, "gyrostat", "wheel_momentum", values, executor=ex, **GYRO)
            rows.append(("Dask, 2 workers", t, res.to_json() == serial.to_json()))
        finally:
            client.close()
            cluster.close()
    return serial, rows


def dispersions(samples):
    clear_caches()
    nutation_spread(4, 0)  # builds, as the pool's warm-up
    serial_t, serial = _timed(nutation_spread, samples, 0)
    clear_caches()
    with ProcessPoolExecutor(2) as pool:
        nutation_spread(4, 0, executor=pool)  # start the workers
        t, res = _timed(nutation_spread, samples, 0, executor=pool)
    same = all(np.array_equal(serial.outputs[k], res.outputs[k], equal_nan=True) for k in serial.outputs)
    return serial, [("serial", serial_t, True), ("2 processes", t, same)]


def multistarts():
    problem = slew.slew_problem(np.eye(3), objective="time", angle=np.pi, axis=[0, 0, 1], u_max=1.0)
    guesses = [slew.attitude_guess(problem, tilt_axis=a, tilt=1.0)
               for a in ([1, 0, 0], [0, 1, 0], [1, 1, 0], [1, -1, 0.5])]
    clear_caches()
    solve_multistart(problem, guesses[:1], N=30)  # build the solver
    serial_t, serial = _timed(solve_multistart, problem, guesses, N=30)
    clear_caches()
    with ProcessPoolExecutor(2) as pool:
        solve_multistart(problem, guesses[:2], N=30, executor=pool)  # start and build in the workers
        t, res = _timed(solve_multistart, problem, guesses, N=30, executor=pool)
    return serial, [("serial", serial_t, True), ("2 processes", t, res.cost == serial.cost)]


def tables(starts, n_targets=None, threads=True):
    J = np.diag([1.0, 2.0, 3.0])
    targets = slew.example_targets()[:n_targets]
    kw = dict(N=20, starts=starts)
    clear_caches()
    slew.maneuver_table(J, targets[:1], **kw)  # builds, as each pool's warm-up
    serial_t, serial = _timed(slew.maneuver_table, J, targets, **kw)
    rows = [("serial", serial_t, True)]
    kinds = (("2 threads", ThreadPoolExecutor),) if threads else ()
    for name, kind in kinds + (("2 processes", ProcessPoolExecutor),):
        clear_caches()
        with kind(2) as pool:
            slew.maneuver_table(J, targets[:2], executor=pool, **kw)  # start the workers
            t, res = _timed(slew.maneuver_table, J, targets, executor=pool, **kw)
        rows.append((name, t, bool(np.array_equal(res.T, serial.T))))
    return serial, rows


def _table(rows, unit=1.0, label="wall [s]"):
    base = rows[0][1]
    for name, t, same in rows:
        print(f"  {name:<16} {t / unit:>10.3f} {label}  speed-up {base / t:5.2f}x  "
              f"identical to serial: {same}")


def run(quick: bool, out: Path) -> list:
    """Run the benchmark, write ``many.csv`` into ``out``; the summary `Row`s."""
    detail, summary = [], []

    def record(case, rows):
        _table(rows)
        base = rows[0][1]
        for name, t, same in rows:
            detail.append(dict(case=case, variant=name, wall_time=t, speed_up=base / t,
                               identical=same))
            if name == "serial":
                summary.append(Row("many", case, "wall time, serial", t, "s"))
            else:
                summary.append(Row("many", case, f"speed-up, {name}", base / t, "x",
                                   "identical to serial" if same else "DIFFERS from serial"))

    values = np.linspace(-2, 8, 11 if quick else 41)
    print(f"1. Stability sweep, gyrostat, {values.size} wheel-momentum values:")
    serial, rows = sweeps(values, dask=not quick)
    print(f"  {serial.evaluations} case evaluations, {len(serial.boundaries)} boundaries")
    record(f"stability sweep, {values.size} values", rows)
    samples = 20 if quick else 100
    print(f"\n2. Dispersion, spinning spacecraft, {samples} samples (a new model per sample):")
    res, rows = dispersions(samples)
    record(f"dispersion, {samples} samples", rows)
    print(f"  per sample: serial {1e3 * rows[0][1] / samples:.1f} ms, "
          f"2 processes {1e3 * rows[1][1] / samples:.1f} ms; nutation max spread: mean "
          f"{np.degrees(res.statistics['nutation_max'].mean):.3f} deg, std "
          f"{np.degrees(res.statistics['nutation_max'].std):.3f} deg")
    if not quick:
        print("\n3. Multistart of the Bilimoria-Wie slew, 4 tilted starts, N = 30:")
        best, rows = multistarts()
        record("multistart, 4 starts, N = 30", rows)
        print(f"  best T = {best.T:.10f}")
    starts = 1 if quick else 3
    n_targets = 4 if quick else 8
    print(f"\n4. Maneuver table, {n_targets} example targets, J = diag(1, 2, 3), "
          f"starts = {starts}, N = 20:")
    table, rows = tables(starts, n_targets, threads=not quick)
    record(f"maneuver table, {n_targets} targets, {starts} start(s)", rows)
    print(f"  all verified: {table.success}; T [s] = {np.round(table.T, 4).tolist()}")
    write_csv(detail, Path(out) / "many.csv")
    return summary


def main(argv=None) -> int:
    return script_main(run, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
