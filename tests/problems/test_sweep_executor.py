"""`stability.sweep(executor=...)`: threads and processes give the serial result, bit for bit.

The serial run is the truth: the same verdicts, eigenvalues (``np.array_equal``),
boundaries, evaluation count and JSON. One thread pool and one process pool (the platform's
default start method) serve the whole module.
"""
from __future__ import annotations

import concurrent.futures
import multiprocessing
import signal

import numpy as np
import pytest

from appdyn.problems import stability as st
from appdyn.problems.stability import SphericalDamper
from appdyn.dynamics.executors import process_pool

GYRO = dict(inertia=[3.0, 4.0, 5.0], axis=[1, 0, 0], rate=2.0)  # two boundaries
DAMPED = dict(inertia=[3.0, 4.0, 4.0], axis=[1, 0, 0], rate=2.0,
              damper=SphericalDamper(0.1, 0.05))  # unstable -> asymptotically stable
TOP = dict(axial_inertia=0.002, transverse_inertia=0.005, mass=0.3, length=0.04)
SWEEPS = {
    "gyrostat": (("gyrostat", "wheel_momentum", np.linspace(-2, 8, 6)), GYRO),
    "damped-gyrostat": (("gyrostat", "wheel_momentum", np.linspace(-2, 4, 7)), DAMPED),
    "heavy-top": (("heavy-top", "rate", np.linspace(0, 60, 7)), TOP),
}


@pytest.fixture(scope="module")
def pools():
    with concurrent.futures.ThreadPoolExecutor(2) as threads, \
            process_pool(2) as processes:
        yield {"threads": threads, "processes": processes}


def _same(a, b):
    assert b.verdicts == a.verdicts and b.boundaries == a.boundaries
    assert np.array_equal(b.values, a.values)
    assert np.array_equal(b.eigenvalues, a.eigenvalues, equal_nan=True)
    assert np.array_equal(b.least_damped, a.least_damped)
    assert b.evaluations == a.evaluations and b.statuses == a.statuses
    assert b.complete and b.to_json() == a.to_json() and str(b) == str(a)


@pytest.mark.parametrize("kind", ["threads", "processes"])
@pytest.mark.parametrize("which", sorted(SWEEPS))
@pytest.mark.slow
def test_executor_gives_the_serial_sweep(pools, kind, which):
    args, kw = SWEEPS[which]
    serial = st.sweep(*args, **kw)
    assert serial.boundaries  # a verdict boundary to bisect
    _same(serial, st.sweep(*args, executor=pools[kind], **kw))


@pytest.mark.slow
def test_progress_is_called_per_grid_value(pools):
    calls = []
    args, kw = SWEEPS["gyrostat"]
    res = st.sweep(*args, executor=pools["threads"], progress=lambda d, n: calls.append((d, n)),
                   **kw)
    assert calls == [(k, 6) for k in range(1, 7)] and res.complete


def test_case_error_is_the_serial_one(pools):
    values = [-2.0, -1.0, 0.0, 1.0, 2.0]  # rate 0 is refused
    kw = dict(inertia=[1, 2, 3], axis=[1, 0, 0])
    with pytest.raises(ValueError) as serial:
        st.sweep("spin", "rate", values, **kw)
    for kind in ("threads", "processes"):
        with pytest.raises(ValueError) as got:
            st.sweep("spin", "rate", values, executor=pools[kind], **kw)
        assert str(got.value) == str(serial.value)
        assert str(got.value).startswith("spin at rate = 0.0: `rate` must be non-zero")


@pytest.mark.parametrize("bad", ["threads", object(), multiprocessing.get_context().Pool])
def test_bad_executor_is_refused(bad):
    with pytest.raises(TypeError, match="`executor`"):
        st.sweep("heavy_top", "rate", [1.0, 2.0], executor=bad, **TOP)


def test_interrupt_keeps_the_finished_values(pools):
    """Ctrl-C (a real SIGINT, deferred to the wait loop) mid-grid: ``partial`` holds the
    values finished by then, each as the serial run has it."""
    values = np.linspace(0.5, 10.0, 40)
    kw = dict(inertia=[2.0, 3.0, 4.5], axis=[1, 0, 0])
    serial = st.sweep("spin", "rate", values, **kw)

    def progress(done, total):
        if done == 2:
            signal.raise_signal(signal.SIGINT)

    with pytest.raises(KeyboardInterrupt) as info:
        st.sweep("spin", "rate", values, executor=pools["threads"], progress=progress, **kw)
    part = info.value.partial
    assert part.complete is False and 2 <= len(part.values) <= len(values)
    assert "interrupted after" in part.message
    idx = np.searchsorted(values, part.values)
    assert np.array_equal(values[idx], part.values)
    assert [serial.verdicts[i] for i in idx] == list(part.verdicts)
    assert np.array_equal(serial.least_damped[idx], part.least_damped)


@pytest.mark.slow
def test_threaded_sweeps_build_their_casadi_symbols_one_at_a_time():
    """Found in CI: a heavy-top sweep on a thread pool crashed (SIGSEGV) in two threads'
    `spin_scene._conserved`, each building a Jacobian from the shared model at once (CasADi
    counts references without atomics). Before the fix 4 threads crashed within 25-123 such
    sweeps (three tries); the helpers now build under the construction lock
    (`cache.constructs`), and every sweep gives the serial one."""
    kw = dict(TOP)
    grid = np.linspace(0, 60, 9)
    serial = st.sweep("heavy-top", "rate", grid, **kw)
    with concurrent.futures.ThreadPoolExecutor(4) as pool:
        for _ in range(60):
            _same(serial, st.sweep("heavy-top", "rate", grid, executor=pool, **kw))
