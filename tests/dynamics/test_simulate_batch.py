"""Batched simulation (`simulate` with ``x0`` of shape (nx, K)): every run against an
independent truth (the Jacobi-elliptic torque-free rates, closed forms under constant
torque and of a damped oscillator with per-run parameters), against single runs, per-run
failure, and the argument checks."""
import threading

import casadi as ca
import numpy as np
import pytest

from appdyn.dynamics import Model, rigid_body, simulate
from appdyn.dynamics.integrate.batch import BatchResult
from appdyn.dynamics.truth import torque_free_omega

INERTIA = [1.0, 2.0, 3.0]


def _rates(K, seed=0):
    rng = np.random.default_rng(seed)
    W = np.array([1.5, 0.0, 0.0])[:, None] + rng.uniform(-1, 1, (3, K))
    return W, np.vstack([np.tile([[0.0], [0.0], [0.0], [1.0]], (1, K)), W])


def _truth(W, t):
    return np.stack([torque_free_omega(INERTIA, W[:, k], t) for k in range(W.shape[1])], axis=2)


@pytest.mark.parametrize("method, kw, tol", [("rk8", {"steps": 4}, 1e-9),
                                             ("auto", {"rtol": 1e-9, "atol": 1e-9}, 1e-8)])
def test_every_run_of_a_torque_free_batch_meets_the_jacobi_truth(method, kw, tol):
    t = np.linspace(0.0, 20.0, 41)
    W, X0 = _rates(60)
    res = simulate(rigid_body(INERTIA), X0, t, method=method, **kw)
    assert isinstance(res, BatchResult) and res.x.shape == (7, 41, 60) and len(res) == 60
    assert res.all_success and res.success.shape == (60,) and res.method == "rk8"
    err = np.max(np.abs(res.x[4:] - _truth(W, t)), axis=(0, 1))
    assert np.all(err < tol), err.max()
    np.testing.assert_allclose(np.linalg.norm(res.x[:4], axis=0), 1.0, atol=1e-12)
    if method == "auto":
        assert np.all(np.isfinite(res.error_estimate)) and np.all(res.error_estimate <= 1.0)
        assert np.all(res.status == 0)


@pytest.mark.parametrize("method", ["rk8", "rk4", "lie", "cvodes", "dop853"])
def test_a_batch_equals_its_runs_one_by_one(method):
    t = np.linspace(0.0, 5.0, 11)
    _, X0 = _rates(5, seed=1)
    model = rigid_body(INERTIA)
    kw = {} if method in ("cvodes", "dop853") else {"steps": 3}
    res = simulate(model, X0, t, method=method, **kw)
    for k in range(5):
        one = simulate(model, X0[:, k], t, method=method, **kw)
        np.testing.assert_allclose(res.x[:, :, k], one.x, rtol=0, atol=1e-13)
        run = res.run(k)
        assert run.success and run.x.shape == (7, 11)
        np.testing.assert_allclose(run.sample(2.5), one.sample(2.5), atol=1e-12)


def test_constant_torque_per_run_on_a_sphere():
    """J = E: w(t) = w0 + u t for each run's own torque (samples of shape (nu, n, K))."""
    t = np.linspace(0.0, 2.0, 9)
    K = 4
    rng = np.random.default_rng(2)
    W0, T = rng.normal(size=(3, K)), rng.normal(size=(3, K))
    X0 = np.vstack([np.tile([[0.0], [0.0], [0.0], [1.0]], (1, K)), W0])
    U = np.repeat(T[:, None, :], t.size, axis=1)
    res = simulate(rigid_body([1.0, 1.0, 1.0]), X0, t, u=U, method="rk8", steps=4)
    assert res.all_success
    np.testing.assert_allclose(res.x[4:], W0[:, None, :] + T[:, None, :] * t[None, :, None],
                               atol=1e-12)


@pytest.mark.parametrize("u", [None, [0.3, -0.2, 0.1]])
@pytest.mark.parametrize("method", ["auto", "rk8"])
def test_a_torque_shared_by_the_runs_is_held_once_and_integrated_exactly(u, method):
    """J = E under one constant torque (``u`` of shape (nu,), or none) for every run:
    w(t) = w0 + u t; the batch holds that control once (a view of strides 0, not a copy per
    run and interval) and each run equals its single call."""
    t = np.linspace(0.0, 2.0, 9)
    K = 5
    W0 = np.random.default_rng(3).normal(size=(3, K))
    X0 = np.vstack([np.tile([[0.0], [0.0], [0.0], [1.0]], (1, K)), W0])
    model = rigid_body([1.0, 1.0, 1.0])
    kw = {"steps": 4} if method == "rk8" else {}
    res = simulate(model, X0, t, u=u, method=method, **kw)
    assert res.all_success
    T = np.zeros(3) if u is None else np.asarray(u)
    np.testing.assert_allclose(res.x[4:], W0[:, None, :] + T[:, None, None] * t[None, :, None],
                               atol=1e-12)
    ua = res._batch.ua
    assert ua.shape == (K, t.size - 1, 3) and ua.strides[:2] == (0, 0)
    assert not ua.flags.writeable and res._batch.ub is ua
    for k in (0, K - 1):
        np.testing.assert_array_equal(res.x[:, :, k], simulate(model, X0[:, k], t, u=u,
                                                               method=method, **kw).x)


def test_parameters_per_run():
    """x'' = -k x: x(t) = cos(sqrt(k) t) with each run's own k (p of shape (np, K))."""
    x, v, k = ca.SX.sym("x"), ca.SX.sym("v"), ca.SX.sym("k")
    model = Model.from_expressions({"x": x, "v": v}, {"x": v, "v": -k * x}, params={"k": k},
                                   p_default=[1.0])
    t = np.linspace(0.0, 3.0, 7)
    ks = np.array([[0.5, 1.0, 4.0]])
    X0 = np.array([[1.0, 1.0, 1.0], [0.0, 0.0, 0.0]])
    res = simulate(model, X0, t, p=ks, rtol=1e-10, atol=1e-12)
    assert res.all_success
    np.testing.assert_allclose(res.x[0], np.cos(np.sqrt(ks[0])[None, :] * t[:, None]), atol=1e-9)


def test_a_run_that_blows_up_fails_alone():
    """x' = x^2 from x0 = 2 blows up at t = 0.5; the run from 0.1 (x = 0.1 / (1 - 0.1 t)) not."""
    x = ca.SX.sym("x")
    model = Model.from_expressions({"x": x}, {"x": x ** 2})
    t = np.linspace(0.0, 0.9, 10)
    res = simulate(model, np.array([[0.1, 2.0]]), t, method="rk8", steps=50)
    assert res.success.tolist() == [True, False] and res.status.tolist() == [0, -1]
    np.testing.assert_allclose(res.x[0, :, 0], 0.1 / (1 - 0.1 * t), rtol=1e-12)
    assert np.isnan(res.x[0, -1, 1]) and "non-finite" in res.message


def test_an_auto_run_that_blows_up_fails_alone_among_verified_runs():
    """The same blow-up among 40 runs of the dense loop (``auto``): the runs it verified are
    reported finite without a look at their outputs, so each must be; the blown-up run
    fails with the true cause."""
    x = ca.SX.sym("x")
    model = Model.from_expressions({"x": x}, {"x": x ** 2})
    t = np.linspace(0.0, 0.9, 10)
    x0 = np.linspace(0.05, 1.0, 40)
    x0[17] = 2.0
    res = simulate(model, x0[None, :], t)
    assert res.status[17] == -1 and not res.success[17]
    assert not np.all(np.isfinite(res.x[:, :, 17]))
    good = np.delete(np.arange(40), 17)
    assert res.success[good].all() and np.isfinite(res.x[:, :, good]).all()
    np.testing.assert_allclose(res.x[0, :, good], x0[good, None] / (1 - x0[good, None] * t),
                               rtol=1e-7)


def _sphere_runs(K, hold, seed=11):
    """K runs on a sphere J = 2 E, each its own rates and sampled torque (run 2 one torque
    throughout), and the closed form of the rates: w = w0 + (1/2) integral of the torque
    (linear samples: the trapezoid; held: the left sums)."""
    t = np.linspace(0.0, 4.0, 9)
    rng = np.random.default_rng(seed)
    X0 = np.tile(np.r_[0.0, 0.0, 0.0, 1.0, 0.3, -0.2, 0.1][:, None], (1, K))
    X0[4:] += rng.normal(size=(3, K))
    U = rng.normal(size=(3, t.size, K))
    U[:, :, 2] = [[0.2], [-0.1], [0.3]]
    h = np.diff(t)[None, :, None]
    steps = (U[:, :-1] + U[:, 1:]) / 2 * h if hold == "linear" else U[:, :-1] * h
    exact = X0[4:, None, :] + np.concatenate([np.zeros((3, 1, K)), np.cumsum(steps, axis=1)],
                                             axis=1) / 2
    return rigid_body([2.0, 2.0, 2.0]), t, X0, U, exact


@pytest.mark.parametrize("hold", ["linear", "zoh"])
@pytest.mark.parametrize("threads", [1, 2])
def test_an_auto_batch_under_sampled_torques_is_its_single_calls_and_exact(hold, threads):
    """``auto`` on runs whose torques vary within a run: each run's one-pass answer in one
    compiled loop over the runs, judged as its single call judges it; every run (the one
    under a single torque, which takes the dense pass, too) is its single call to the bit
    (states, status, estimate, steps) on any number of threads, within the tolerance of the
    closed form, and a progress callback hears every step the single calls count (and the
    first passes of the runs redone alone)."""
    K = 9
    model, t, X0, U, exact = _sphere_runs(K, hold)
    calls = []
    res = simulate(model, X0, t, u=U, hold=hold, threads=threads,
                   progress=lambda d, n: calls.append((d, n)))
    assert res.all_success and "one compiled loop" in res.message
    assert "run(s) alone" in res.message  # (run 2 at least: the dense pass, as its single call)
    scale = 1e-10 + 1e-8 * np.abs(exact)
    assert np.all(np.abs(res.x[4:] - exact) <= scale)
    total = 0
    for k in range(K):
        one = simulate(model, X0[:, k], t, u=U[:, :, k], hold=hold)
        np.testing.assert_array_equal(res.x[:, :, k], one.x)
        assert (res.status[k], res.error_estimate[k]) == (one.status, one.error_estimate)
        total += one.n_steps
        assert ("embedded error control" in one.message) == (k != 2)
    assert calls[-1][0] == calls[-1][1] >= total


@pytest.mark.parametrize("threads", [1, 2])
def test_an_auto_batch_under_sampled_torques_in_groups_is_its_single_calls(threads,
                                                                          monkeypatch):
    """The runs in groups, each group judged while the other thread steps the next
    (`batch.PASS_GROUPS`, here groups of 5 runs): every run is still its single call to
    the bit, and the answers are those of one group."""
    from appdyn.dynamics.integrate import batch as batch_module

    K = 20
    model, t, X0, U, exact = _sphere_runs(K, "linear", seed=5)
    one_group = simulate(model, X0, t, u=U, threads=threads)
    monkeypatch.setattr(batch_module, "PASS_GROUP_MIN", 5)
    res = simulate(model, X0, t, u=U, threads=threads)
    assert res.all_success and "one compiled loop" in res.message
    np.testing.assert_array_equal(res.x, one_group.x)
    np.testing.assert_array_equal(res.error_estimate, one_group.error_estimate)
    assert np.all(np.abs(res.x[4:] - exact) <= 1e-10 + 1e-8 * np.abs(exact))
    for k in range(0, K, 3):
        one = simulate(model, X0[:, k], t, u=U[:, :, k])
        np.testing.assert_array_equal(res.x[:, :, k], one.x)
        assert (res.status[k], res.error_estimate[k]) == (one.status, one.error_estimate)


def test_an_auto_batch_under_sampled_controls_leaves_a_blown_up_run_alone():
    """x' = x^2 + u with each run's own sampled u: the run from 2 blows up before t = 0.5
    and fails alone with the cause its single call gives; the others are their single calls."""
    s, u = ca.SX.sym("s"), ca.SX.sym("u")
    model = Model.from_expressions({"s": s}, {"s": s ** 2 + u}, controls={"u": u})
    t = np.linspace(0.0, 0.9, 10)
    x0 = np.array([[0.1, 2.0, -0.3]])
    U = 0.01 * np.sin(np.arange(3 * t.size)).reshape(1, t.size, 3)
    res = simulate(model, x0, t, u=U)
    assert res.success.tolist() == [True, False, True] and res.status[1] == -1
    assert "one compiled loop" in res.message
    for k in range(3):
        one = simulate(model, x0[:, k], t, u=U[:, :, k])
        np.testing.assert_array_equal(res.x[:, :, k], one.x)
        assert res.status[k] == one.status
    alone = simulate(model, x0[:, 1], t, u=U[:, :, 1])
    assert alone.message in res.message


def test_an_auto_batch_under_sampled_torques_says_what_max_steps_stopped_as_its_runs_do():
    """Too few ``max_steps`` for any run's pass: each run goes alone and says what its single
    call says (status 3, not verified; no run made), not a failure."""
    model, t, X0, U, _ = _sphere_runs(4, "linear")
    res = simulate(model, X0, t, u=U, max_steps=10)
    for k in range(4):
        one = simulate(model, X0[:, k], t, u=U[:, :, k], max_steps=10)
        assert (res.status[k], res.success[k]) == (one.status, one.success) == (3, False)
        np.testing.assert_array_equal(res.x[:, :, k], one.x)
    assert "max_steps" in res.message


def test_progress_counts_the_steps_of_a_batch():
    calls = []
    _, X0 = _rates(3)
    simulate(rigid_body(INERTIA), X0, np.linspace(0, 1, 101), method="rk8", steps=2,
             progress=lambda d, n: calls.append((d, n)))
    assert calls and calls[-1] == (200, 200)


def test_batch_argument_errors():
    model = rigid_body(INERTIA)
    t = np.linspace(0, 1, 5)
    _, X0 = _rates(3)
    with pytest.raises(ValueError, match="`u`.*callable|`u` must be None or an array"):
        simulate(model, X0, t, u=lambda s: np.zeros(3))
    with pytest.raises(ValueError, match=r"`u` must be None, \(3,\)"):
        simulate(model, X0, t, u=np.zeros((3, 5, 2)))
    with pytest.raises(ValueError, match="x0\\[0:4, 1\\]"):
        bad = X0.copy()
        bad[3, 1] = 2.0
        simulate(model, bad, t)
    with pytest.raises(ValueError, match="`invariants`"):
        simulate(model, X0, t, invariants=True)
    with pytest.raises(ValueError, match="`x0` must be finite|`x0`"):
        bad = X0.copy()
        bad[5, 0] = np.nan
        simulate(model, bad, t)
    res = simulate(model, X0, t, method="rk8")
    with pytest.raises(ValueError, match="`k`"):
        res.run(3)


def test_a_stiff_batch_goes_to_cvodes_run_by_run_as_single_runs_do():
    """x' = -1e9 x over 1 s (~2e8 explicit steps for stability alone): auto hands each run
    to cvodes with an estimated global error, exactly as a single call does."""
    x = ca.SX.sym("x")
    model = Model.from_expressions({"x": x}, {"x": -1e9 * x})
    t = np.linspace(0.0, 1.0, 5)
    res = simulate(model, np.array([[1.0, 2.0]]), t)
    assert res.all_success and res.method == "cvodes" and np.all(res.status == 1)
    for k, x0 in enumerate((1.0, 2.0)):
        one = simulate(model, [x0], t)
        assert one.method == "cvodes" and one.status == 1
        np.testing.assert_array_equal(res.x[:, :, k], one.x)
        assert res.error_estimate[k] == one.error_estimate <= 1.0


# ------------------------------------------------ parts of a batch spread over threads
from appdyn import config  # noqa: E402
from appdyn.dynamics import executors  # noqa: E402
from appdyn.dynamics.integrate import batch_fixed as batch_module  # noqa: E402


@pytest.fixture
def spread(monkeypatch):
    """``spread(threads, part_runs)``: every chunk split into parts of at most ``part_runs``
    runs on ``threads`` threads, however small the batch."""
    def use(threads, part_runs):
        monkeypatch.setitem(config.defaults, "dynamics.threads", threads)
        monkeypatch.setattr(batch_module, "PART_RUNS", part_runs)
        monkeypatch.setattr(batch_module, "PARALLEL_STEPS", 0)
    return use


@pytest.mark.parametrize("K, steps", [(1000, 64), (23, 64), (3, 5), (1, 64), (5, 1)])
def test_parts_cover_the_runs_in_near_equal_contiguous_slices(spread, K, steps):
    spread(2, 8)
    parts, threads = batch_module._parts(K, steps, 2)
    assert threads == min(2, K)
    assert parts[0].start == 0 and parts[-1].stop == K
    assert all(a.stop == b.start for a, b in zip(parts[:-1], parts[1:]))
    sizes = [p.stop - p.start for p in parts]
    assert max(sizes) <= 8 and max(sizes) - min(sizes) <= 1 and min(sizes) >= 1
    assert len(parts) >= min(K, K * steps // batch_module.PART_STEPS) and len(parts) >= threads


def test_parts_of_a_large_batch_are_small_enough_to_balance_the_threads():
    parts, threads = batch_module._parts(1000, 64, 2)
    assert threads == 2 and len(parts) == 1000 * 64 // batch_module.PART_STEPS


def test_a_small_chunk_stays_on_one_thread():
    parts, threads = batch_module._parts(3, 10, 2)  # 30 run-steps: not worth a hand-over
    assert threads == 1 and parts == [slice(0, 3)]


def _controlled_batch(K, seed):
    """Runs with their own rates, parameters-free torques (``u (3, n, K)``) and grid."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 3.0, 31)
    W, X0 = _rates(K, seed)
    U = 0.1 * rng.normal(size=(3, t.size, K))
    return t, X0, U


@pytest.mark.parametrize("method", ["rk8", "rk4", "lie"])
def test_threads_and_parts_give_the_bits_of_one_serial_call(spread, method):
    """Any split (threads, part sizes, uneven last parts, lanes reused between calls of
    other sizes and controls) gives the same bits as one thread with one part."""
    model = rigid_body(INERTIA)
    t, X0, U = _controlled_batch(23, 3)
    spread(1, 10_000)
    ref = [simulate(model, X0, t, method=method, steps=9).x.copy(),  # 270 steps: 5 chunks
           simulate(model, X0, t, u=U, method=method, steps=9).x.copy(),
           simulate(model, X0[:, :7], t, method=method, steps=2).x.copy()]
    for threads, part_runs in [(2, 4), (2, 10_000), (3, 5), (1, 6)]:
        spread(threads, part_runs)
        for _ in range(2):  # the second time through lanes that hold data of other calls
            np.testing.assert_array_equal(simulate(model, X0, t, method=method, steps=9).x,
                                          ref[0])
            np.testing.assert_array_equal(
                simulate(model, X0, t, u=U, method=method, steps=9).x, ref[1])
            np.testing.assert_array_equal(
                simulate(model, X0[:, :7], t, method=method, steps=2).x, ref[2])


@pytest.mark.parametrize("kw, vector", [({}, False), ({}, True),
                                        ({"method": "rk8", "steps": 3}, False)],
                         ids=["auto (runs handed out one at a time)", "auto in vector lanes",
                              "rk8 (one C loop per part)"])
def test_the_compiled_loops_give_the_same_bits_on_any_number_of_threads(kw, vector,
                                                                       monkeypatch):
    """The runs are independent: 1 thread (the serial loop), 2, 3 (parts of uneven sizes)
    and more threads than runs give the same bits, with ``auto``'s loops returning to
    Python after every few steps (the threads then take the runs in other orders);
    ``auto``'s runs each meet their Jacobi truth within the tolerance."""
    from appdyn.dynamics.integrate import batch as batch_auto, dense, lanes
    monkeypatch.setattr(dense, "MANY_BUDGET", 8.0)  # (a compiled loop returns after 8 steps)
    if vector:
        assert lanes.dense_lanes(rigid_body(INERTIA), wait=True) is not None
    else:
        monkeypatch.setattr(batch_auto, "dense_lanes", lambda model, build: None)
    model, t = rigid_body(INERTIA), np.linspace(0.0, 10.0, 21)
    W, X0 = _rates(37, seed=5)
    ref = simulate(model, X0, t, threads=1, **kw)
    assert ref.all_success
    for threads in (2, 3, 64):
        got = simulate(model, X0, t, threads=threads, **kw)
        np.testing.assert_array_equal(got.x, ref.x)
        np.testing.assert_array_equal(got.error_estimate, ref.error_estimate)
    with config.using("dynamics", threads=2):  # the registered default
        np.testing.assert_array_equal(simulate(model, X0, t, **kw).x, ref.x)
    w = _truth(W, t)
    assert np.all(np.abs(ref.x[4:] - w) <= 1e-9 + 1e-7 * np.abs(w))


@pytest.mark.parametrize("threads, error", [(0, ValueError), (-2, ValueError),
                                            (1.5, TypeError), ("2", TypeError),
                                            (True, TypeError)])
def test_threads_must_be_a_positive_integer(threads, error):
    model, t = rigid_body(INERTIA), np.linspace(0.0, 1.0, 3)
    _, X0 = _rates(2)
    for x0 in (X0, X0[:, 0]):  # a batch, and a single run (one thread, checked too)
        with pytest.raises(error, match="`threads`"):
            simulate(model, x0, t, threads=threads)
    with config.using("dynamics", threads=threads), pytest.raises(error, match="`threads`"):
        simulate(model, X0, t)


def test_spread_runs_calls_every_run_once_in_contiguous_parts():
    seen = []
    for threads, part in [(1, 5), (2, 5), (3, 64), (4, 1)]:
        seen.clear()
        batch_module.spread_runs(lambda k0, k1: seen.append((k0, k1)), 23, threads, part)
        spans = sorted(seen)
        assert spans[0][0] == 0 and spans[-1][1] == 23
        assert all(a[1] == b[0] and a[0] < a[1] for a, b in zip(spans[:-1], spans[1:]))
        assert max(b - a for a, b in spans) <= part
        if threads == 1:
            assert seen == spans  # in order, in the calling thread


@pytest.mark.parametrize("threads", [1, 2])
def test_a_ctrl_c_stops_the_compiled_loops_between_groups_of_parts(threads):
    """A Ctrl-C during a part of a compiled loop over the runs is raised (KeyboardInterrupt)
    once the parts handed out with it have finished; no later group is started."""
    import os
    import signal

    if signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
        pytest.skip("SIGINT has a handler of its own here")
    seen = []

    def call(k0, k1):
        if not seen:
            os.kill(os.getpid(), signal.SIGINT)
        seen.append(k0)

    K = 4 * batch_module.GROUP * threads  # four groups of parts of one run
    with pytest.raises(KeyboardInterrupt):
        batch_module.spread_runs(call, K, threads, 1)
    assert len(seen) == batch_module.GROUP * threads  # the first group only
    model, t = rigid_body(INERTIA), np.linspace(0.0, 1.0, 5)
    _, X0 = _rates(3)
    assert simulate(model, X0, t, threads=threads).all_success  # (and the next call is whole)


@pytest.mark.parametrize("threads", [1, 2])
def test_a_ctrl_c_stops_the_dense_loops_from_taking_runs(threads, monkeypatch):
    """A Ctrl-C while ``auto``'s compiled loops over a batch's runs go (`dense.dense_many`)
    is raised (KeyboardInterrupt) once the runs taken have finished: the calling thread's
    loop takes no run after it (here the SIGINT arrives as it starts), and the next call
    is whole."""
    import os
    import signal

    from appdyn.dynamics.integrate import dense

    if signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
        pytest.skip("SIGINT has a handler of its own here")
    real, taken = dense._workspace, []

    def workspace(plan, nout):
        if threading.current_thread() is threading.main_thread() and not taken:
            os.kill(os.getpid(), signal.SIGINT)
        taken.append(1)
        return real(plan, nout)

    monkeypatch.setattr(dense, "MANY_BUDGET", 1.0)  # (a loop returns after every run)
    monkeypatch.setattr(dense, "_workspace", workspace)
    model, t, K = rigid_body(INERTIA), np.linspace(0.0, 1.0, 5), 400
    _, X0 = _rates(K)
    head = np.full((K, dense.HEADER), np.nan)
    with pytest.raises(KeyboardInterrupt):
        dense.dense_many(model, np.ascontiguousarray(X0.T), t, np.zeros((K, 3)),
                         np.zeros((K, 1)), 1e-8, np.full(7, 1e-10), 1e8, 1e6, slice(0, K),
                         out=(np.empty((K, 7, 5)), head), threads=threads)
    assert np.isnan(head[:, 0]).sum() >= (K if threads == 1 else 1)  # (runs never taken)
    monkeypatch.setattr(dense, "_workspace", real)
    assert simulate(model, X0[:, :40], t, threads=threads).all_success


def test_a_run_that_blows_up_fails_alone_in_any_part(spread):
    x = ca.SX.sym("x")
    model = Model.from_expressions({"x": x}, {"x": x ** 2})
    t = np.linspace(0.0, 0.9, 10)
    x0 = np.full((1, 9), 0.1)
    x0[0, [2, 7]] = 2.0
    spread(2, 2)
    res = simulate(model, x0, t, method="rk8", steps=50)
    assert np.flatnonzero(~res.success).tolist() == [2, 7]
    assert np.all(np.isnan(res.x[0, -1, [2, 7]])) and np.all(np.isfinite(res.x[0, :, 0]))
    np.testing.assert_allclose(res.x[0, :, 8], 0.1 / (1 - 0.1 * t), rtol=1e-12)


def test_progress_and_ctrl_c_of_a_batch_spread_over_threads(spread):
    """The progress callback runs in the calling thread after every chunk; a Ctrl-C during
    the call stops it at the next chunk with KeyboardInterrupt, and the next call is whole."""
    import os
    import signal
    import threading

    if signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
        pytest.skip("SIGINT has a handler of its own here")
    model = rigid_body(INERTIA)
    t, X0, _ = _controlled_batch(23, 4)
    spread(2, 4)
    calls = []

    def record(done, total):
        calls.append((done, total, threading.current_thread() is threading.main_thread()))

    ref = simulate(model, X0, t, method="rk8", steps=9, progress=record).x.copy()
    assert [c[:2] for c in calls] == [(64, 270), (128, 270), (192, 270), (256, 270),
                                      (270, 270)] and all(c[2] for c in calls)

    def interrupt(done, total):
        if done == 128:
            os.kill(os.getpid(), signal.SIGINT)

    with pytest.raises(KeyboardInterrupt):
        simulate(model, X0, t, method="rk8", steps=9, progress=interrupt)
    np.testing.assert_array_equal(simulate(model, X0, t, method="rk8", steps=9).x, ref)


def test_an_error_in_a_part_is_raised_after_every_part_finished(spread, monkeypatch):
    model = rigid_body(INERTIA)
    t, X0, U = _controlled_batch(12, 5)  # (a varying control: the chunk loop)
    spread(2, 3)
    ref = simulate(model, X0, t, u=U, method="rk8", steps=2).x.copy()
    advance = batch_module._FixedBatch.advance
    finished = []

    def failing(self, fun, lane, runs, chunk):
        if runs.stop == 12:  # the last part
            raise RuntimeError("part failed")
        advance(self, fun, lane, runs, chunk)
        finished.append(runs.start)

    monkeypatch.setattr(batch_module._FixedBatch, "advance", failing)
    with pytest.raises(RuntimeError, match="part failed"):
        simulate(model, X0, t, u=U, method="rk8", steps=2)
    assert finished and 11 not in finished
    monkeypatch.setattr(batch_module._FixedBatch, "advance", advance)
    np.testing.assert_array_equal(simulate(model, X0, t, u=U, method="rk8", steps=2).x, ref)


def test_run_split_runs_every_task_and_raises_the_first_error():
    import threading
    import time

    seen, lock = [], threading.Lock()

    def task(i):
        time.sleep(0.01 * (3 - i))
        with lock:
            seen.append(i)
        if i in (1, 2):
            raise ValueError(f"task {i}")

    with pytest.raises(ValueError, match="task 1"):
        executors.run_split(task, [0, 1, 2])
    assert sorted(seen) == [0, 1, 2]  # all finished before the error was raised
    out = []
    executors.run_split(out.append, ["only"])
    assert out == ["only"]
    assert executors.worker_pool(2) is executors.worker_pool(1)


def test_run_split_runs_here_what_the_pool_no_longer_takes(monkeypatch):
    """At the interpreter's exit a pool refuses new tasks: they run in the calling thread."""
    import threading

    class Closed:
        def submit(self, fun, task):
            raise RuntimeError("cannot schedule new futures after interpreter shutdown")

    monkeypatch.setattr(executors, "worker_pool", lambda workers: Closed())
    where = []
    executors.run_split(lambda i: where.append((i, threading.current_thread().name)), [0, 1, 2])
    assert where == [(i, threading.current_thread().name) for i in range(3)]


def test_worker_pool_is_made_again_in_a_forked_child():
    import os

    if not hasattr(os, "fork"):
        pytest.skip("no fork")
    executors.worker_pool(1)
    pid = os.fork()
    if pid == 0:  # child: the pool's threads are not here; a task must still run
        try:
            out = []
            executors.run_split(out.append, [1, 2])
            os._exit(0 if sorted(out) == [1, 2] else 1)
        except BaseException:
            os._exit(2)
    _, status = os.waitpid(pid, 0)
    assert os.WEXITSTATUS(status) == 0


def test_lanes_are_dropped_with_their_chunk_function():
    """A thread's lane does not hold the chunk Function; its table entry goes with it."""
    import gc

    from appdyn.dynamics.integrate import evaluate

    x, n = ca.SX.sym("x", 2), ca.SX.sym("n")
    f = ca.Function("chunkish", [x, n], [ca.repmat(x, 1, 4)])
    lane = evaluate.borrow_state(f, lambda ref: batch_module._Lane(ref, f, 3))
    assert lane.args[0].shape == (3, 2) and lane.out.shape == (3, 4, 2)
    evaluate.return_state(f, lane)
    key = id(f)
    assert evaluate._thread_table("state")[key] is lane
    del f
    gc.collect()
    assert lane.ref() is None and key not in evaluate._thread_table("state")


def test_nan_after_failure_tells_huge_finite_runs_from_non_finite_ones():
    x = np.ones((4, 5, 2))
    x[1] = 1e308  # finite terms whose sum overflows
    x[2, 3, 1] = np.inf
    x[3, 1, 0] = np.nan
    out, ok = batch_module._nan_after_failure(x.copy())
    assert ok.tolist() == [True, True, False, False] and out.shape == (2, 5, 4)
    np.testing.assert_array_equal(out[:, :, 1], x[1].T)
    assert np.all(np.isnan(out[:, 3:, 2])) and np.all(out[:, :3, 2] == 1.0)
    assert np.all(np.isnan(out[:, 1:, 3])) and np.all(out[:, 0, 3] == 1.0)


def test_a_constant_control_rk8_batch_is_one_c_loop_matching_single_runs(monkeypatch):
    """Compiled rk8 over a batch under constant controls runs in one plain C loop over the
    runs (`cpass._FIXED`): each run equals its single call (the chunk loop) to rounding and
    its Jacobi truth to the method's error."""
    from appdyn.dynamics.truth import torque_free_omega
    calls = []
    real = batch_module._c_loop
    monkeypatch.setattr(batch_module, "_c_loop", lambda *a: calls.append(1) or real(*a))
    model, t = rigid_body(INERTIA), np.linspace(0.0, 10.0, 21)
    rng = np.random.default_rng(3)
    x0 = np.r_[np.zeros((3, 5)), np.ones((1, 5)), rng.uniform(-1.0, 1.0, (3, 5))]
    res = simulate(model, x0, t, method="rk8", steps=6)
    assert calls and res.all_success
    for k in range(5):
        one = simulate(model, x0[:, k], t, method="rk8", steps=6).x
        np.testing.assert_allclose(res.x[:, :, k], one, rtol=0, atol=1e-13)
        w = torque_free_omega(INERTIA, x0[4:, k], t)
        assert np.max(np.abs(res.x[4:, :, k] - w)) < 1e-9


def test_dense_loops_refuse_runs_outside_the_batch():
    """`dense.dense_many` hands its ``runs`` to compiled loops that read those rows: an
    index outside ``x0`` is a ValueError naming ``runs``, not a read past the array."""
    from appdyn.dynamics.integrate import dense

    model, t = rigid_body(INERTIA), np.linspace(0.0, 1.0, 3)
    x0 = np.ascontiguousarray(_rates(3)[1].T)
    for runs in ([0, 3], [-1]):
        with pytest.raises(ValueError, match="`runs`"):
            dense.dense_many(model, x0, t, np.zeros((3, 3)), np.zeros((3, 1)), 1e-8,
                             np.full(7, 1e-10), 1e8, 1e6, runs)
