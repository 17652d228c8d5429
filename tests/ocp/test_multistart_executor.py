"""`ocp.solve_multistart(executor=...)`: threads and processes give the serial outcome.

The serial run is the truth: the same best start, the same solution arrays (bit for bit),
and the same ``info['starts']`` records but their ``time``.
"""
from __future__ import annotations

import concurrent.futures
import multiprocessing
import signal
import time

import numpy as np
import pytest

from appdyn import ocp
from appdyn.ocp.examples import min_time
from appdyn.dynamics.executors import process_pool

GUESSES = [None, {"T": 5.0}, {"T": 1.0}, {"T": 3.0}]
# start 0 is capped before it converges; start 2 tries a capped attempt first
OPTIONS = [{"ipopt_options": {"max_iter": 3}}, {},
           [{"ipopt_options": {"max_iter": 2}}, {}], {"transcription": "hermite-simpson"}]


@pytest.fixture(scope="module")
def problem():
    return min_time()


@pytest.fixture(scope="module")
def pools():
    with concurrent.futures.ThreadPoolExecutor(2) as threads, \
            process_pool(2) as processes:
        yield {"threads": threads, "processes": processes}


def _records(sol):
    return [{k: v for k, v in s.items() if k != "time"} for s in sol.info["starts"]]


def _same(a, b):
    assert (b.success, b.status, b.message, b.info["best"]) == \
        (a.success, a.status, a.message, a.info["best"])
    assert _records(b) == _records(a)
    for name in ("t", "x", "u", "p"):
        assert np.array_equal(getattr(b, name), getattr(a, name))
    assert b.cost == a.cost and b.T == a.T and b.iterations == a.iterations


@pytest.mark.parametrize("kind", ["threads", "processes"])
def test_executor_gives_the_serial_multistart(problem, pools, kind):
    serial = ocp.solve_multistart(problem, GUESSES, start_options=OPTIONS, N=10)
    assert not serial.info["starts"][0]["success"] and serial.info["best"] != 0
    got = ocp.solve_multistart(problem, GUESSES, start_options=OPTIONS, N=10,
                               executor=pools[kind])
    _same(serial, got)
    assert got.problem is problem  # also from a worker process
    assert all(s["time"] > 0 for s in got.info["starts"])


@pytest.mark.slow
def test_spawned_workers_give_the_serial_multistart(problem):
    serial = ocp.solve_multistart(problem, GUESSES[:2], N=10)
    context = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(2, mp_context=context) as pool:
        got = ocp.solve_multistart(problem, GUESSES[:2], N=10, executor=pool)
    _same(serial, got)


def test_guess_error_is_the_serial_one(problem, pools):
    guesses = [None, {"bogus": 1.0}, {"T": 2.0}, {"wrong": 1.0}]
    with pytest.raises(ValueError) as serial:
        ocp.solve_multistart(problem, guesses, N=10)
    for kind in ("threads", "processes"):
        with pytest.raises(ValueError) as got:
            ocp.solve_multistart(problem, guesses, N=10, executor=pools[kind])
        assert str(got.value) == str(serial.value) and "bogus" in str(got.value)


@pytest.mark.parametrize("bad", ["threads", 2, multiprocessing.get_context().Pool])
def test_bad_executor_is_refused(problem, bad):
    with pytest.raises(TypeError, match="`executor`"):
        ocp.solve_multistart(problem, [None], N=10, executor=bad)


def test_interrupt_cancels_the_pending_starts(problem):
    """A Ctrl-C (a real SIGINT, deferred to the wait loop) during the first start: the
    starts not yet begun never run."""
    begun = []

    def progress(p):
        if p.iteration == 0:
            begun.append(p)
            if len(begun) == 1:
                signal.raise_signal(signal.SIGINT)
                time.sleep(0.5)  # the wait loop polls every 0.1 s

    with concurrent.futures.ThreadPoolExecutor(1) as pool:
        with pytest.raises(KeyboardInterrupt):
            # (backoff=False: the first start's bound violation is not re-solved, so every
            # iteration 0 seen is a start's)
            ocp.solve_multistart(problem, GUESSES, N=10, progress=progress, executor=pool,
                                 backoff=False)
    assert len(begun) == 1


def test_problem_is_unpickled_once_per_worker(problem):
    from appdyn.ocp.refine.multistart import _Shipped

    a, b = _Shipped(problem), _Shipped(problem)
    assert a.digest == b.digest and a.get() is b.get() and a.get() is not problem


def test_agreeing_starts_stop_the_serial_multistart(problem):
    """x'' = u, |u| <= 1 from rest to rest over a unit distance: T = 2 from every guess, so
    with ``agree`` the second converged start ends the run; without it, every start runs."""
    guesses = [None, {"T": 5.0}, {"T": 3.0}]
    kw = dict(N=10, control="constant")
    every = ocp.solve_multistart(problem, guesses, **kw)
    short = ocp.solve_multistart(problem, guesses, agree=1e-6, **kw)
    assert every.info["skipped"] == 0 and len(every.info["starts"]) == 3
    assert short.info["skipped"] == 1 and len(short.info["starts"]) == 2
    assert short.success and abs(short.T - 2.0) < 1e-6
    assert _records(short) == _records(every)[:2]  # the same starts, the third not solved
    with pytest.raises(ValueError, match="`agree`"):
        ocp.solve_multistart(problem, guesses, agree=-1.0, **kw)
