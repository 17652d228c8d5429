"""Fixed-step rk8 batches stepped several runs at a time in vector lanes
(`dynamics.integrate.lanes`): the same bits as the scalar loop and as single runs (each lane
is a run's own arithmetic), for runs with their own parameters and constant controls and a
short last group; steps the rewrite does not know keep the scalar loop. Truth: a pendulum's
energy with the closed-form small-angle period, and the scalar loop itself."""
import casadi as ca
import numpy as np
import pytest

from appdyn.dynamics import Model, rigid_body, simulate
from appdyn.dynamics.integrate import batch_fixed, lanes
from appdyn.dynamics.integrate.kernels import kernel


def _pendulum(nonsmooth=False, stop=None):
    """theta'' = -(g / l) sin(theta) + u, g / l a parameter; with ``nonsmooth`` a stop (an
    ``if_else``) the rewrite does not take; ``stop`` a function of (acc, 5.0) instead."""
    th, om, k, u = ca.SX.sym("theta"), ca.SX.sym("omega"), ca.SX.sym("k"), ca.SX.sym("u")
    acc = -k * ca.sin(th) + u
    if nonsmooth:
        acc = ca.if_else(acc > 5.0, 5.0, acc)
    if stop is not None:
        acc = stop(acc, 5.0)
    return Model.from_expressions({"theta": th, "omega": om}, {"theta": om, "omega": acc},
                                  controls={"u": u}, params={"k": k}, p_default=[1.0])


def test_the_rewrite_takes_arithmetic_and_functions_and_refuses_conditionals():
    assert lanes.lane_source(kernel(rigid_body([1.0, 2.0, 3.0]), "rk8", "linear",
                                    compiled=True)) is not None
    assert "v_sin(" in lanes.lane_source(kernel(_pendulum(), "rk8", "linear", compiled=True))
    assert lanes.lane_source(kernel(_pendulum(True), "rk8", "linear", compiled=True)) is None
    for stop, name in ((ca.fmin, "v_fmin("), (ca.fmax, "v_fmax(")):  # (lane-wise selects)
        assert name in lanes.lane_source(kernel(_pendulum(stop=stop), "rk8", "linear",
                                                compiled=True))


def test_a_rigid_body_batch_in_lanes_is_the_scalar_loop_to_the_bit(monkeypatch):
    model, t = rigid_body([1.0, 2.0, 3.0]), np.linspace(0.0, 5.0, 11)
    rng = np.random.default_rng(1)
    X0 = np.vstack([np.zeros((3, 10)), np.ones(10), rng.uniform(-1, 1, (3, 10))])
    assert lanes.lanes_library(model) is not None
    got = simulate(model, X0, t, method="rk8", steps=4, threads=1).x
    monkeypatch.setattr(batch_fixed, "lanes_library", lambda m, **kw: None)
    np.testing.assert_array_equal(got, simulate(model, X0, t, method="rk8", steps=4).x)


@pytest.mark.slow  # (two new models compiled: ~3 s each)
@pytest.mark.parametrize("nonsmooth", [False, True], ids=["lanes", "scalar loop"])
def test_lanes_give_the_bits_of_the_scalar_loop_and_of_single_runs(nonsmooth, monkeypatch):
    model = _pendulum(nonsmooth)
    if not nonsmooth:
        assert lanes.lanes_library(model) is not None
    K, t = 7, np.linspace(0.0, 4.0, 9)  # (7 runs: a last group of 3 lanes)
    rng = np.random.default_rng(4)
    X0 = np.vstack([rng.uniform(-0.5, 0.5, K), rng.uniform(-0.2, 0.2, K)])
    P = rng.uniform(0.5, 2.0, (1, K))
    U = rng.uniform(-0.1, 0.1, 2)[None, :]  # (a shared constant torque: u of shape (nu,))
    got = simulate(model, X0, t, p=P, u=U[0, :1], method="rk8", steps=6)
    assert got.all_success
    monkeypatch.setattr(batch_fixed, "lanes_library", lambda m, **kw: None)
    scalar = simulate(model, X0, t, p=P, u=U[0, :1], method="rk8", steps=6)
    np.testing.assert_array_equal(got.x, scalar.x)
    for k in (0, 6):
        one = simulate(model, X0[:, k], t, p=P[:, k], u=U[0, :1], method="rk8", steps=6)
        np.testing.assert_array_equal(got.x[:, :, k], one.x)


@pytest.mark.slow
def test_a_lane_run_keeps_the_pendulum_energy():
    """Unforced: E = omega^2 / 2 + k (1 - cos theta) is constant (rk8, 48 steps a period)."""
    model = _pendulum()
    assert lanes.lanes_library(model) is not None  # (built: this small batch takes it)
    K, t = 5, np.linspace(0.0, 2 * np.pi, 9)
    X0 = np.vstack([np.linspace(0.1, 1.0, K), np.zeros(K)])
    P = np.linspace(0.8, 1.2, K)[None, :]
    x = simulate(model, X0, t, p=P, method="rk8", steps=6).x
    energy = 0.5 * x[1] ** 2 + P * (1 - np.cos(x[0]))
    assert np.max(np.abs(energy - energy[0])) < 1e-9


def test_a_small_batch_does_not_build_the_lanes_but_takes_them_once_built(monkeypatch):
    """Below `batch_fixed.LANES_BUILD` run-steps the lane loop is not compiled for the batch
    (``build=False``); the batch is the same bits either way."""
    asked = []
    real = batch_fixed.lanes_library

    def spy(model, *, build=True):
        asked.append(build)
        return real(model, build=build)

    monkeypatch.setattr(batch_fixed, "lanes_library", spy)
    model, t = rigid_body([1.0, 2.0, 3.0]), np.linspace(0.0, 1.0, 3)
    X0 = np.vstack([np.zeros((3, 2)), np.ones(2), [[0.1, 0.2], [0.3, 0.1], [0.2, 0.5]]])
    small = simulate(model, X0, t, method="rk8", steps=2).x
    monkeypatch.setattr(batch_fixed, "LANES_BUILD", 1)
    np.testing.assert_array_equal(simulate(model, X0, t, method="rk8", steps=2).x, small)
    assert asked == [False, True]


def _tumbling(k, seed):
    """``k`` torque-free starts about a spin of 1.5 rad/s about the minor axis (7, k)."""
    rng = np.random.default_rng(seed)
    w = np.array([[1.5], [0.0], [0.0]]) + rng.uniform(-1.0, 1.0, (3, k))
    return np.vstack([np.zeros((3, k)), np.ones(k), w])


@pytest.mark.parametrize("kw, n", [({}, 41), (dict(rtol=1e-10, atol=1e-12), 41),
                                   (dict(method="dop853", rtol=1e-9, atol=1e-11), 41),
                                   ({}, 2), ({}, 801)],
                         ids=["auto", "auto near the rounding", "dop853", "auto, 2 points",
                              "auto, several outputs a step"])
def test_dense_batches_in_lanes_are_the_scalar_loop_to_the_bit(kw, n, monkeypatch):
    """``auto`` and ``dop853`` batches whose runs step four at a time in the lanes of the
    vector DOP853 step (`lanes.dense_lanes`; the pass's ``rk8_auto_lanes``: each lane its
    own steps, controller, outputs and check, an emptied lane taking the next run, the
    continuous extensions of the lanes' steps gathered four to a vector call and their
    outputs filled from it later) are the scalar loop's bits: answers, estimates, steps,
    verdicts; 11 runs (lanes refilled, a short last group); near the rounding some runs
    retry or rerun rounded at random alone; grids with no output inside a step (2 points)
    and with several inside each (801). Truth: Jacobi's closed form within the
    tolerance."""
    from appdyn.dynamics.integrate import batch
    from appdyn.dynamics.truth import torque_free_omega
    inertia = [1.0, 2.0, 3.0]
    model, t = rigid_body(inertia), np.linspace(0.0, 20.0, n)
    X0 = _tumbling(11, 3)
    assert lanes.dense_lanes(model, wait=True) is not None
    got = simulate(model, X0, t, threads=1, **kw)
    monkeypatch.setattr(batch, "dense_lanes", lambda m, **k: None)
    ref = simulate(model, X0, t, threads=1, **kw)
    np.testing.assert_array_equal(got.x, ref.x)
    np.testing.assert_array_equal(got.error_estimate, ref.error_estimate)
    np.testing.assert_array_equal(got.status, ref.status)
    assert got.n_steps == ref.n_steps and got.message == ref.message
    rtol, atol = kw.get("rtol", 1e-8), kw.get("atol", 1e-10)
    assert got.all_success
    for k in range(X0.shape[1]):
        w = torque_free_omega(inertia, X0[4:, k], t)
        err = np.abs(got.x[4:, :, k] - w) / (atol + rtol * np.abs(w))
        assert err.max() <= (1.0 if "method" not in kw else 30.0)  # (dop853: not verified)



def test_a_batch_whose_floors_take_one_or_two_draws_in_lanes_is_the_scalar_loop(monkeypatch):
    """Runs near the bench body's rounding (100 s, rtol 1e-10: six spins 2 % apart) measure
    their rounding floor by reruns rounded at random, one or two draws each (the second on
    its own stream, in the lane the first ran in, its state kept there between steps): the
    lanes give the scalar loop's bits; each run within the tolerance of Jacobi's rates."""
    from appdyn.dynamics.integrate import batch, dense
    from appdyn.dynamics.truth import torque_free_omega
    inertia = [1.0, 2.0, 3.0]
    model, t = rigid_body(inertia), np.linspace(0.0, 100.0, 101)
    w = np.array([[1.0], [0.1], [0.8]]) * (1 + np.linspace(-2e-2, 2e-2, 6))
    X0 = np.vstack([np.zeros((3, 6)), np.ones(6), w])
    rtol, atol = 1e-10, 1e-12
    draws = [dense.dense_run(model, X0[:, k], t, rtol, atol, 1e8, 1e6).draws for k in range(6)]
    assert 2 in draws and 1 in draws, draws
    assert lanes.dense_lanes(model, wait=True) is not None
    got = simulate(model, X0, t, rtol=rtol, atol=atol, threads=1)
    monkeypatch.setattr(batch, "dense_lanes", lambda m, **k: None)
    ref = simulate(model, X0, t, rtol=rtol, atol=atol, threads=1)
    np.testing.assert_array_equal(got.x, ref.x)
    np.testing.assert_array_equal(got.error_estimate, ref.error_estimate)
    assert got.n_steps == ref.n_steps and got.all_success
    for k in range(6):
        truth = torque_free_omega(inertia, X0[4:, k], t)
        assert np.all(np.abs(got.x[4:, :, k] - truth) <= atol + rtol * np.abs(truth))

def test_a_dense_batch_with_parameters_and_controls_in_lanes_is_the_scalar_loop():
    """Runs with their own parameter and constant control (the pendulum) in lanes: the
    scalar loop's bits; unforced, the energy is kept to the tolerance."""
    from appdyn.dynamics.integrate import batch
    model = _pendulum()
    assert lanes.dense_lanes(model, wait=True) is not None
    K, t = 6, np.linspace(0.0, 6.0, 13)
    rng = np.random.default_rng(5)
    X0 = np.vstack([rng.uniform(-1.0, 1.0, K), rng.uniform(-0.5, 0.5, K)])
    P = rng.uniform(0.5, 2.0, (1, K))
    for u in (np.zeros(1), np.array([0.05])):
        got = simulate(model, X0, t, p=P, u=u, threads=1)
        real = batch.dense_lanes
        try:
            batch.dense_lanes = lambda m, **k: None
            ref = simulate(model, X0, t, p=P, u=u, threads=1)
        finally:
            batch.dense_lanes = real
        np.testing.assert_array_equal(got.x, ref.x)
        np.testing.assert_array_equal(got.error_estimate, ref.error_estimate)
        assert got.all_success
    got = simulate(model, X0, t, p=P, threads=1)
    energy = 0.5 * got.x[1] ** 2 + P * (1 - np.cos(got.x[0]))
    assert np.max(np.abs(energy - energy[:1])) < 1e-7


def test_a_dense_batch_does_not_wait_for_its_lanes_and_takes_them_once_ready():
    """The vector step is compiled in the background (`cache.compile_ahead`) when a batch
    asks for it: the call does not wait (None, the scalar loop); once ready a later call
    takes it, and the answers are the same bits."""
    import time
    from appdyn.dynamics import cache
    model, t = rigid_body([1.1, 2.3, 2.9]), np.linspace(0.0, 5.0, 11)  # (a body of its own)
    X0 = _tumbling(5, 8)
    assert lanes.dense_lanes(model, build=False) is None
    before = simulate(model, X0, t, threads=1)
    first = lanes.dense_lanes(model)
    deadline = time.monotonic() + 120
    while first is None and time.monotonic() < deadline:
        time.sleep(0.05)
        first = lanes.dense_lanes(model)
    assert first is not None and first.address
    assert lanes.dense_lanes(model, build=False) is first
    np.testing.assert_array_equal(simulate(model, X0, t, threads=1).x, before.x)
    del cache


@pytest.mark.parametrize("kw,budget", [({}, None), ({}, 7), (dict(rtol=1e-10, atol=1e-12), None)],
                         ids=["defaults", "budgets of 7 steps", "near the rounding"])
def test_a_single_call_with_its_check_in_a_lane_is_the_scalar_call(kw, budget, monkeypatch):
    """A single checked call whose check's steps ride in a lane of its answer's vector steps
    (the pass's ``rk8_auto_v``, `dense_advance_v`) is the scalar call to the bit: answer,
    estimate, steps, message; also when the call is cut into budgets of 7 steps (a check
    due at a cut is taken alone) and near the rounding (a rerun rounded at random).
    Truth: Jacobi's closed form within the tolerance."""
    from appdyn.dynamics.integrate import dense
    from appdyn.dynamics.truth import torque_free_omega
    inertia, x0 = [1.5, 2.5, 3.2], np.r_[0.0, 0.0, 0.0, 1.0, 0.5, 0.0, 1.0]
    model, t = rigid_body(inertia), np.linspace(0.0, 60.0, 121)
    vector = lanes.dense_lanes(model, wait=True)
    assert vector is not None
    if budget is not None:
        monkeypatch.setattr(dense, "BUDGET", budget)
        # (workspaces made with this budget; a thread that made no call yet has none)
        monkeypatch.setattr(dense._LOCAL, "work", {}, raising=False)
    monkeypatch.setattr(dense, "_single_lanes", lambda m, plan: vector)
    got = simulate(model, x0, t, **kw)
    monkeypatch.setattr(dense, "_single_lanes", lambda m, plan: None)
    ref = simulate(model, x0, t, **kw)
    np.testing.assert_array_equal(got.x, ref.x)
    assert got.error_estimate == ref.error_estimate and got.n_steps == ref.n_steps
    assert got.message == ref.message and got.success
    rtol, atol = kw.get("rtol", 1e-8), kw.get("atol", 1e-10)
    w = torque_free_omega(inertia, x0[4:], t)
    assert np.all(np.abs(got.x[4:] - w) <= atol + rtol * np.abs(w))


def test_single_calls_ask_for_the_lanes_every_so_many_calls(monkeypatch):
    """A model's single checked calls ask for its vector lanes (`lanes.dense_lanes`, which
    loads them or compiles them in the background) at every `dense.SINGLE_LANES_AFTER`-th
    call until they are there, then take them; a script's few calls never ask."""
    from appdyn.dynamics.integrate import dense
    model, t = rigid_body([1.2, 2.2, 3.1]), np.linspace(0.0, 2.0, 3)  # (a plan of its own)
    asked = []
    monkeypatch.setattr(dense, "dense_lanes", lambda m: asked.append(m) or None)
    x0 = np.r_[0.0, 0.0, 0.0, 1.0, 0.3, 0.1, 0.2]
    for _ in range(dense.SINGLE_LANES_AFTER - 1):
        simulate(model, x0, t)
    assert asked == []
    simulate(model, x0, t)
    assert asked == [model]
    for _ in range(dense.SINGLE_LANES_AFTER):
        simulate(model, x0, t)
    assert asked == [model, model]


@pytest.mark.parametrize("which", ["wheels", "hinged"])
def test_a_model_whose_steps_call_its_rhs_takes_the_lanes_with_the_same_bits(which, monkeypatch):
    """A model whose steps call its right-hand side (`kernels.calls_rhs`: the pass's steps
    are C loops, `csteps`) gets the vector form of those loops around its rewritten
    right-hand side (`csteps.loop_steps(lanes=True)`): a single checked call (its check in a
    lane of its steps) and a batch of 6 runs (a lane per run) are the scalar pass's bits;
    the wheel spacecraft with a constant wheel torque, the hinged bodies."""
    from appdyn.dynamics.integrate import batch, dense
    from appdyn.dynamics.integrate.kernels import calls_rhs
    from tests.dynamics.test_simulate_dense import _hinged, _wheels

    model, x0 = _wheels() if which == "wheels" else _hinged()
    assert calls_rhs(model, "rk8")
    vector = lanes.dense_lanes(model, wait=True)
    assert vector is not None
    t = np.linspace(0.0, 4.0, 9)
    u = np.full(model.nu, 0.01) if model.nu else None
    monkeypatch.setattr(dense, "_single_lanes", lambda m, plan: vector)
    got = simulate(model, x0, t, u=u)
    monkeypatch.setattr(dense, "_single_lanes", lambda m, plan: None)
    ref = simulate(model, x0, t, u=u)
    np.testing.assert_array_equal(got.x, ref.x)
    assert got.error_estimate == ref.error_estimate and got.n_steps == ref.n_steps
    assert got.success and "dense output" in got.message, got.message
    rng = np.random.default_rng(2)
    X0 = np.repeat(x0[:, None], 6, axis=1)
    w = model.attitude[1]  # (the first body's rates dispersed)
    X0[w:w + 3] += rng.uniform(-0.05, 0.05, (3, 6))
    if which == "hinged":  # (a consistent start for each: the constraint holds)
        X0 = np.stack([model.initial_state([0, 0, 0, 1], X0[w:w + 3, k], [1.0, 0, 0],
                                           [0, 0, 0, 1], [0.1, 0, 0.2]) for k in range(6)], 1)
    got = simulate(model, X0, t, u=u, threads=1)
    monkeypatch.setattr(batch, "dense_lanes", lambda m, **k: None)
    ref = simulate(model, X0, t, u=u, threads=1)
    np.testing.assert_array_equal(got.x, ref.x)
    np.testing.assert_array_equal(got.error_estimate, ref.error_estimate)
    assert got.all_success, got.message


def test_a_model_past_the_instruction_bound_keeps_the_scalar_pass(monkeypatch):
    """`lanes.dense_lanes` gives no lanes to a right-hand side of more than
    `lanes.DENSE_MAX_INSTRUCTIONS` instructions (its background compile would hold up the
    process's exit); the batch is then the scalar loop's, and correct."""
    from appdyn.dynamics.truth import torque_free_omega
    model = rigid_body([1.3, 2.1, 2.7])  # (a body of its own)
    monkeypatch.setattr(lanes, "DENSE_MAX_INSTRUCTIONS", model.f.n_instructions() - 1)
    assert lanes.dense_lanes(model, wait=True) is None
    X0, t = _tumbling(3, 4), np.linspace(0.0, 5.0, 11)
    got = simulate(model, X0, t)
    assert got.all_success
    for k in range(3):
        w = torque_free_omega([1.3, 2.1, 2.7], X0[4:, k], t)
        assert np.all(np.abs(got.x[4:, :, k] - w) <= 1e-10 + 1e-8 * np.abs(w))


def test_the_first_pass_has_no_lane_driver_and_the_lanes_bring_theirs():
    """The first call's pass is built without the driver of steps in vector lanes (half its
    gcc time); `dense_lanes` compiles the pass's build with it beside the vector steps and
    hands over its entry points, which drive those steps: a single call through them is
    the first build's scalar call to the bit."""
    from appdyn.dynamics.integrate import cpass, dense

    model = rigid_body([1.0, 2.0, 2.5])
    first = cpass.pass_library(model)
    assert first.auto_lanes is None
    vector = lanes.dense_lanes(model, wait=True)
    assert vector.driver is cpass.pass_library(model, lanes=True) and vector.driver is not first
    assert vector.auto_v is vector.driver.auto_v and vector.auto_lanes is not None
    x0, t = np.r_[0.0, 0.0, 0.0, 1.0, 0.3, 1.1, -0.4], np.linspace(0.0, 15.0, 31)
    plan = dense.pass_plan(model)
    plan.single[1] = None  # (the scalar call of the first build)
    scalar = dense.dense_run(model, x0, t, 1e-9, 1e-11, 1e8, 1e6, p=model.p_default)
    plan.single[1] = vector  # (its check in a lane of the lanes build's driver)
    laned = dense.dense_run(model, x0, t, 1e-9, 1e-11, 1e8, 1e6, p=model.p_default)
    assert scalar.result == laned.result == 1 and np.array_equal(scalar.x, laned.x)


def test_the_lanes_build_takes_the_first_builds_steps_from_the_cache(tmp_path):
    """The pass's two builds share their step units: with an empty compile cache, the first
    build keeps each unit after its driver as an object, and the lanes build links those
    objects (counted as reused) instead of compiling the model's DOP853 steps again; its
    single call is still the first build's to the bit."""
    from appdyn.dynamics import diskcache
    from appdyn.dynamics.integrate import cpass, dense

    old = diskcache.configure(directory=tmp_path, enabled=True)
    try:
        model = rigid_body([1.0, 2.0, 2.7])
        assert cpass.pass_library(model) is not None
        objects = sorted(tmp_path.glob("*.o"))
        assert len(objects) == 2  # (the steps with their error, and the dense kernels)
        before = diskcache.info().reused
        vector = lanes.dense_lanes(model, wait=True)
        assert vector is not None and diskcache.info().reused == before + len(objects)
        x0, t = np.r_[0.0, 0.0, 0.0, 1.0, 0.3, 1.1, -0.4], np.linspace(0.0, 15.0, 31)
        plan = dense.pass_plan(model)
        plan.single[1] = None
        scalar = dense.dense_run(model, x0, t, 1e-9, 1e-11, 1e8, 1e6, p=model.p_default)
        plan.single[1] = vector
        laned = dense.dense_run(model, x0, t, 1e-9, 1e-11, 1e8, 1e6, p=model.p_default)
        assert scalar.result == laned.result == 1 and np.array_equal(scalar.x, laned.x)
    finally:
        diskcache.configure(**old)
