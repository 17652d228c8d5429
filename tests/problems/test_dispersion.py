"""Monte Carlo dispersions (problems.dispersion) against independent truths.

Truths: the constant nutation angle of a torque-free axisymmetric body (written out here as
``atan2(I_t |w_t|, I_a w3)`` and taken from `dynamics.truth.symmetric_precession`), numpy's
statistics of those closed-form values, ``exp(-k T)`` for a decaying state with a dispersed
rate ``k``, and the composed quaternion of an attitude error.
"""
import doctest
import importlib
import json
import math
import os
import pickle
import re
import signal
from concurrent.futures import ThreadPoolExecutor

import casadi as ca
import numpy as np
import pytest

from appdyn.dynamics import rigid_body
from appdyn.dynamics.model import model_from_expressions
from appdyn.dynamics.truth import symmetric_precession
from appdyn.problems import dispersion as dp
from appdyn.problems.dispersion import (Normal, SmallRotation, Uniform, dispersion, nutation_history,
                                 nutation_spread, spinner)
from appdyn.dynamics.executors import process_pool

MODULES = ["appdyn.problems.dispersion", "appdyn.problems.dispersion.distributions",
           "appdyn.problems.dispersion.result", "appdyn.problems.dispersion.run", "appdyn.problems.dispersion.sample",
           "appdyn.problems.dispersion.spin"]
T = np.linspace(0.0, 20.0, 21)
X0 = [0.0, 0.0, 0.0, 1.0, 0.02, 0.0, 1.0]
SPIN = {"transverse_inertia": Normal(1000.0, 20.0), "axial_inertia": Normal(1500.0, 30.0),
        "w1": Normal(0.02, 0.004)}


def final_w1(res):  # module-level: picklable for the process pool
    return res["w1"][-1]


def spin_dispersion(**kwargs):
    args = dict(samples=6, seed=11, params=SPIN,
                outputs={"nutation": nutation_history, "w1_final": final_w1})
    args.update(kwargs)
    return dispersion(spinner, X0, T, **args)


def closed_form(inputs, w3=1.0):
    return np.arctan2(inputs["transverse_inertia"] * np.abs(inputs["w1"]),
                      inputs["axial_inertia"] * w3)


@pytest.fixture(scope="module")
def spread():
    return nutation_spread(samples=24, seed=3, points=31)


# ------------------------------------------------------------------ (a) closed form
@pytest.mark.slow
def test_axisymmetric_nutation_matches_closed_form_sample_by_sample(spread):
    assert spread.success and spread.status == dp.ALL_OK and spread.complete
    theta = closed_form(spread.inputs, spread.inputs["w3"])
    assert spread.outputs["nutation"].shape == (24, 31)
    assert np.max(np.abs(spread.outputs["nutation"] - theta[:, None])) < 1e-8
    for k in range(24):  # the library's own closed form, independently of the formula above
        w0 = [spread.inputs["w1"][k], 0.0, spread.inputs["w3"][k]]
        it, ia = spread.inputs["transverse_inertia"][k], spread.inputs["axial_inertia"][k]
        ref = symmetric_precession([it, it, ia], w0).nutation
        assert abs(spread.outputs["nutation_max"][k] - ref) < 1e-8
        assert abs(spread.outputs["nutation_closed_form"][k] - ref) < 1e-14
    assert np.max(spread.outputs["momentum_inertial_drift"]) < 1e-9


@pytest.mark.slow
def test_statistics_equal_numpy_statistics_of_closed_form(spread):
    theta = closed_form(spread.inputs, spread.inputs["w3"])
    s = spread.statistics["nutation_max"]
    assert s.count == 24
    assert s.mean == pytest.approx(np.mean(theta), abs=1e-8)
    assert s.std == pytest.approx(np.std(theta, ddof=1), abs=1e-8)
    assert s.min == pytest.approx(np.min(theta), abs=1e-8)
    assert s.max == pytest.approx(np.max(theta), abs=1e-8)
    assert set(s.percentiles) == {1.0, 50.0, 99.0}
    for p, v in s.percentiles.items():
        assert v == pytest.approx(np.percentile(theta, p), abs=1e-8)
    env = spread.statistics["nutation"]  # a time history: statistics per time
    assert env.mean.shape == (31,)
    np.testing.assert_allclose(env.percentiles[99.0], np.percentile(theta, 99.0), atol=1e-8)
    # the inputs are the draws: I_t ~ N(1000, 20) in distribution, roughly
    assert abs(np.mean(spread.inputs["transverse_inertia"]) - 1000.0) < 4 * 20 / math.sqrt(24)


@pytest.mark.slow
def test_report_json_and_plot(spread):
    text = str(spread)
    assert "nutation_max [rad]" in text and "p99" in text and "24 of 24" in text
    data = json.loads(spread.to_json())
    assert data["success"] is True and data["seed"] == 3
    assert data["params"]["axial_inertia"] == {"type": "Normal", "mean": 1500.0, "std": 30.0}
    assert len(data["outputs"]["nutation"]) == 24
    assert data["statistics"]["nutation_max"]["percentiles"]["50"] == pytest.approx(
        spread.statistics["nutation_max"].percentiles[50.0])
    fig = spread.plot(outputs=["nutation", "nutation_max"])
    assert type(fig).__name__ == "Figure" and len(fig.axes) == 2
    assert len(spread.plot().axes) == 6  # 1 history + 5 scalars
    with pytest.raises(ValueError, match="`outputs`"):
        spread.plot(outputs=["nope"])


# ------------------------------------------------------------------ (b) seeds
@pytest.mark.slow
def test_same_seed_same_samples_different_seed_different():
    a, b, c = spin_dispersion(), spin_dispersion(), spin_dispersion(seed=12)
    for name in SPIN:
        np.testing.assert_array_equal(a.inputs[name], b.inputs[name])
        assert not np.any(a.inputs[name] == c.inputs[name])
    for name in a.outputs:
        np.testing.assert_array_equal(a.outputs[name], b.outputs[name])
    longer = spin_dispersion(samples=9)  # sample i does not depend on `samples`
    np.testing.assert_array_equal(longer.inputs["w1"][:6], a.inputs["w1"])
    fresh = spin_dispersion(seed=None, samples=2)
    assert fresh.seed > 0
    again = spin_dispersion(seed=fresh.seed, samples=2)
    np.testing.assert_array_equal(again.inputs["w1"], fresh.inputs["w1"])


# ------------------------------------------------------------------ (c) executors
def _assert_identical(a, b):
    np.testing.assert_array_equal(a.index, b.index)
    np.testing.assert_array_equal(a.sample_success, b.sample_success)
    assert a.sample_messages == b.sample_messages
    for name in a.inputs:
        np.testing.assert_array_equal(a.inputs[name], b.inputs[name])
    assert list(a.outputs) == list(b.outputs)
    for name in a.outputs:
        np.testing.assert_array_equal(a.outputs[name], b.outputs[name])


def test_thread_and_process_pools_give_the_serial_result():
    serial = spin_dispersion(invariant_drift=["energy"])
    with ThreadPoolExecutor(2) as pool:
        threads = spin_dispersion(invariant_drift=["energy"], executor=pool)
        chunked = spin_dispersion(invariant_drift=["energy"], executor=pool, chunksize=4)
    with process_pool(2) as pool:
        processes = spin_dispersion(invariant_drift=["energy"], executor=pool, chunksize=2)
        with pytest.raises(TypeError, match="`outputs` must be picklable"):
            spin_dispersion(outputs={"w": lambda res: res["w1"][-1]}, executor=pool)
    assert serial.success and "energy_drift" in serial.outputs
    _assert_identical(serial, threads)
    _assert_identical(serial, processes)
    _assert_identical(serial, chunked)
    assert threads.executor == "ThreadPoolExecutor" and processes.executor == "ProcessPoolExecutor"



def _pendulum(k):
    """A factory that builds its model from fresh symbols in each sample."""
    y, v = ca.SX.sym("y"), ca.SX.sym("v")
    return model_from_expressions({"y": y, "v": v}, {"y": v, "v": -k * ca.sin(y) - 0.1 * v},
                                  invariants={"energy": 0.5 * v ** 2 + k * (1 - ca.cos(y))})


def test_threaded_factories_build_their_casadi_symbols_one_at_a_time():
    """Found in an audit of the executors: a model factory builds CasADi symbols in each
    sample's task, beside other threads' builds (CasADi counts references without atomics).
    The factory now runs under the construction lock (`dynamics.cache`): every threaded
    dispersion is the serial one."""
    kw = dict(samples=8, seed=2, params={"k": Uniform(1.0, 2.0)}, outputs={"y": "y"},
              invariant_drift=True, method="rk4", steps=20)
    serial = dispersion(_pendulum, [0.5, 0.0], np.linspace(0, 1.0, 6), **kw)
    assert serial.success
    with ThreadPoolExecutor(4) as pool:
        for _ in range(20):
            _assert_identical(serial, dispersion(_pendulum, [0.5, 0.0], np.linspace(0, 1.0, 6),
                                                 executor=pool, **kw))

def test_results_pickle():
    res = spin_dispersion(samples=2)
    back = pickle.loads(pickle.dumps(res))
    _assert_identical(res, back)


# ------------------------------------------------------------------ (d) progress
def test_progress_counts_every_sample():
    calls = []
    spin_dispersion(samples=5, progress=lambda d, n: calls.append((d, n)))
    assert calls == [(k, 5) for k in range(1, 6)]
    calls.clear()
    with ThreadPoolExecutor(2) as pool:
        spin_dispersion(samples=5, executor=pool, chunksize=2,
                        progress=lambda d, n: calls.append((d, n)))
    assert calls == [(k, 5) for k in range(1, 6)]


@pytest.mark.parametrize("threads", [False, True])
def test_interrupt_keeps_finished_samples(threads):
    def stop(done, total):
        if done == 3:
            raise KeyboardInterrupt

    with ThreadPoolExecutor(2) as pool, pytest.raises(KeyboardInterrupt) as info:
        spin_dispersion(samples=6, progress=stop, executor=pool if threads else None)
    part = info.value.partial
    assert not part.complete and not part.success and part.samples == 6
    assert len(part.index) == 3 and (threads or part.index.tolist() == [0, 1, 2])
    full = spin_dispersion(samples=6)
    np.testing.assert_array_equal(part.outputs["w1_final"], full.outputs["w1_final"][part.index])
    np.testing.assert_array_equal(part.inputs["w1"], full.inputs["w1"][part.index])
    assert "interrupted after 3 of 6" in part.message


# ------------------------------------------------------------------ (e) bad input
@pytest.mark.parametrize("change, exc, name", [
    (dict(samples=0), ValueError, "samples"),
    (dict(samples=2.5), TypeError, "samples"),
    (dict(seed=-1), ValueError, "seed"),
    (dict(seed="a"), TypeError, "seed"),
    (dict(t=[0.0, 1.0, 1.0]), ValueError, "t"),
    (dict(x0=[0.0, 0.0, 0.0, 1.0]), ValueError, "x0"),
    (dict(x0=[0, 0, 0, 1, np.nan, 0, 1]), ValueError, "x0"),
    (dict(model="rigid"), TypeError, "model"),
    (dict(outputs=[nutation_history]), TypeError, "outputs"),
    (dict(outputs={"a": 3}), TypeError, "outputs['a']"),
    (dict(outputs={"a": "w9"}), ValueError, "outputs['a']"),
    (dict(params={"wl": Normal(0, 1)}), ValueError, "params"),
    (dict(params={"w1": "fast"}), TypeError, "params['w1']"),
    (dict(params={"attitude": SmallRotation(0.1)}, model=model_from_expressions(
        {"y": ca.SX.sym("y")}, [0.0]), x0=[1.0]), ValueError, "params` entry 'attitude'"),
    (dict(model=spinner), TypeError, "model"),  # the factory misses axial_inertia ...
    (dict(outputs={"n": nutation_history}), TypeError, "outputs['n']"),
    (dict(executor="pool"), TypeError, "executor"),
    (dict(progress=3), TypeError, "progress"),
    (dict(percentiles=[50, 101]), ValueError, "percentiles"),
    (dict(chunksize=0), ValueError, "chunksize"),
    (dict(invariant_drift="energy"), TypeError, "invariant_drift"),
    (dict(invariant_drift=["entropy"]), ValueError, "invariant_drift"),
    (dict(method="euler"), ValueError, "method"),
    (dict(stepz=3), TypeError, "stepz"),
])
def test_bad_input_names_the_argument(change, exc, name):
    args = dict(model=rigid_body([1000.0, 1000.0, 1500.0]), x0=X0, t=T, samples=2, seed=0,
                outputs={"w1_final": final_w1}, params={"w1": Normal(0.02, 0.004)})
    args.update(change)
    with pytest.raises(exc, match=re.escape(f"`{name}")):
        dispersion(args.pop("model"), args.pop("x0"), args.pop("t"), **args)


@pytest.mark.parametrize("make, name", [
    (lambda: Normal(np.nan, 1.0), "mean"), (lambda: Normal(0.0, -1.0), "std"),
    (lambda: Normal([0.0, 1.0], [1.0, 1.0, 1.0]), "mean"), (lambda: Uniform(1.0, 0.0), "high"),
    (lambda: SmallRotation([0.1, 0.1]), "std"), (lambda: Uniform("a", 1.0), "low"),
])
def test_bad_distributions_name_the_argument(make, name):
    with pytest.raises((ValueError, TypeError), match=f"`{name}`"):
        make()


# ------------------------------------------------------------------ (f) failing samples
def _maybe_nan(rng):
    return np.nan if rng.random() < 0.5 else 1000.0


def test_failing_samples_are_reported_not_raised():
    res = spin_dispersion(samples=10, params={**SPIN, "transverse_inertia": _maybe_nan})
    bad = ~res.sample_success
    assert 0 < np.count_nonzero(bad) < 10
    np.testing.assert_array_equal(bad, np.isnan(res.inputs["transverse_inertia"]))
    assert not res.success and res.status == dp.SOME_FAILED
    assert all("inertia" in m for m in np.array(res.sample_messages)[bad])
    assert np.all(res.sample_status[bad] == dp.NOT_SIMULATED)
    assert np.all(np.isnan(res.outputs["w1_final"][bad]))
    good = res.outputs["nutation"][~bad]
    assert res.statistics["nutation"].count == len(good)
    np.testing.assert_allclose(res.statistics["nutation"].mean, good.mean(axis=0), rtol=1e-14)
    assert set(res.failures()) == set(res.index[bad].tolist())
    # a diverging fixed-step run: simulate's own failure status, per sample
    fast = spin_dispersion(samples=3, params={**SPIN, "w3": Uniform(1e4, 2e4)}, method="rk4",
                           outputs={"w1_final": final_w1})
    assert fast.status == dp.ALL_FAILED and np.all(fast.sample_status == -1)
    assert "non-finite" in fast.sample_messages[0]
    assert fast.outputs == {} and fast.statistics == {}  # no sample said what they look like


def _raising_output(res, w1):
    if w1 > 0.02:
        raise RuntimeError("too wobbly")
    return w1


def test_an_output_that_raises_fails_its_sample_only():
    res = spin_dispersion(samples=8, outputs={"w1": _raising_output})
    expected = res.inputs["w1"] <= 0.02
    np.testing.assert_array_equal(res.sample_success, expected)
    assert "RuntimeError: too wobbly" in res.sample_messages[int(np.argmin(expected))]
    np.testing.assert_array_equal(res.outputs["w1"][expected], res.inputs["w1"][expected])


# ------------------------------------------------------------------ routing of draws
def test_model_parameters_and_attitude_errors():
    y, k = ca.SX.sym("y"), ca.SX.sym("k")
    decay = model_from_expressions({"y": y}, {"y": -k * y}, params={"k": k}, p_default=[1.0])
    res = dispersion(decay, [2.0], np.linspace(0.0, 3.0, 4), samples=5, seed=1,
                     params={"k": Uniform(0.5, 1.5)}, outputs={"y": "y"}, rtol=1e-12)
    truth = 2.0 * np.exp(-np.outer(res.inputs["k"], np.linspace(0.0, 3.0, 4)))
    np.testing.assert_allclose(res.outputs["y"], truth, rtol=1e-9)

    q0 = [0.0, 0.0, np.sin(0.3), np.cos(0.3)]
    res = dispersion(rigid_body([1.0, 2.0, 3.0]), [*q0, 0.1, 0.2, 0.3], [0.0, 1.0], samples=4,
                     seed=2, params={"attitude": SmallRotation([0.01, 0.02, 0.03])},
                     outputs={"q_start": lambda r: r.x[0:4, 0]})
    for dq, q in zip(res.inputs["attitude"], res.outputs["q_start"]):
        v, s = dq[:3], dq[3]  # quat_mul(dq, q0) written out (scalar last)
        expected = [*(s * np.array(q0[:3]) + q0[3] * v - np.cross(v, q0[:3])),
                    s * q0[3] - v @ q0[:3]]
        np.testing.assert_allclose(q, expected, atol=1e-15)
    assert np.std(res.inputs["attitude"][:, 0]) > 0


def test_distribution_draws_are_seeded():
    rng = lambda: np.random.default_rng(5)  # noqa: E731
    assert Normal(1.0, 2.0).draw(rng()) == 1.0 + 2.0 * rng().standard_normal()
    assert Uniform(1.0, 3.0).draw(rng()) == 1.0 + 2.0 * rng().random()
    q = dp.RandomRotation().draw(rng())
    assert abs(np.linalg.norm(q) - 1.0) < 1e-15 and q[3] >= 0
    assert Normal([0.0, 1.0], 0.5).draw(rng()).shape == (2,)


@pytest.mark.parametrize("module_name", MODULES)
@pytest.mark.slow
def test_docstring_examples_run_as_written(module_name):
    module = importlib.import_module(module_name)
    result = doctest.testmod(module, optionflags=doctest.NORMALIZE_WHITESPACE | doctest.ELLIPSIS)
    assert result.failed == 0


def test_ctrl_c_stops_between_samples():
    def sigint(done, total):
        if done == 2:
            os.kill(os.getpid(), signal.SIGINT)  # deferred to the next sample boundary

    if signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
        pytest.skip("SIGINT has a non-default handler here")
    with pytest.raises(KeyboardInterrupt) as info:
        spin_dispersion(samples=5, progress=sigint)
    assert info.value.partial.index.tolist() == [0, 1]


# ------------------------------------------------------------------ one batched simulate
def _raising_flag(res, flag):
    if flag > 0.8:
        raise RuntimeError("too wobbly")
    return flag


@pytest.mark.slow
def test_batch_of_a_fixed_model_meets_the_closed_form_and_the_serial_run():
    """``batch=True``: all samples in one `simulate` call; each sample's transverse rate
    equals the axisymmetric closed form ``w1(t) = w1(0) cos(lambda t)``, ``lambda = (I_a -
    I_t) w3 / I_t``, as the per-sample runs do, and an output that raises fails its sample
    only."""
    it, ia = 1000.0, 1500.0
    body = rigid_body([it, it, ia])
    params = {"w1": Normal(0.02, 0.004), "w3": Normal(1.0, 0.05),
              "attitude": SmallRotation(0.01), "flag": Uniform(0.0, 1.0)}
    args = dict(samples=40, seed=5, params=params,
                outputs={"w1h": "w1", "flag": _raising_flag})
    many = dispersion(body, X0, T, batch=True, **args)
    one = dispersion(body, X0, T, **args)
    ok = many.inputs["flag"] <= 0.8
    assert 0 < np.count_nonzero(~ok) < 40
    np.testing.assert_array_equal(many.sample_success, ok)
    np.testing.assert_array_equal(one.sample_success, ok)
    lam = (ia - it) / it * many.inputs["w3"]
    truth = many.inputs["w1"][:, None] * np.cos(lam[:, None] * T[None, :])
    assert np.max(np.abs(many.outputs["w1h"][ok] - truth[ok])) < 1e-9
    np.testing.assert_allclose(many.outputs["w1h"][ok], one.outputs["w1h"][ok], atol=1e-9)
    assert "RuntimeError: too wobbly" in many.sample_messages[int(np.argmin(ok))]
    with pytest.raises(ValueError, match="`batch=True`"):
        spin_dispersion(batch=True)  # a factory
    with ThreadPoolExecutor(2) as pool, pytest.raises(ValueError, match="`batch=True`"):
        dispersion(body, X0, T, batch=True, executor=pool, **args)
    with pytest.raises(TypeError, match="`batch`"):
        dispersion(body, X0, T, batch="yes", **args)
