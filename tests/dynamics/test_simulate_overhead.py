"""What the per-call fast paths of `simulate` must leave unchanged: results (bitwise), the
input checks and their messages, and thread safety of the per-thread call buffers."""
from __future__ import annotations

import gc
import pickle
import threading

import casadi as ca
import numpy as np
import pytest

from appdyn import dynamics
from appdyn.dynamics.integrate.evaluate import call_buffered
from appdyn.dynamics.integrate.kernels import kernel
from appdyn.dynamics.integrate.result import SimulationResult, make_result
from appdyn.dynamics.validate import QUAT_NORM_TOL, check_unit_quaternion, unit_quaternion

INERTIA = [1.0, 2.0, 3.0]
X0 = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 0.1, 0.8])


@pytest.fixture(scope="module")
def body():
    return dynamics.rigid_body(INERTIA)


def _stepwise(model, x0, t, steps, u=None):
    """rk8 by calling the one-step kernel (SX, interpreted) step by step: another path."""
    step = kernel(model, "rk8", "linear")
    u = np.zeros(model.nu) if u is None else np.asarray(u, dtype=float)
    x, out = ca.DM(x0), [np.asarray(x0, dtype=float)]
    for k in range(t.size - 1):
        h = (t[k + 1] - t[k]) / steps
        for _ in range(steps):
            x = step(x, h, u, np.zeros(model.nu), model.p_default)
        out.append(np.asarray(x).ravel())
    return np.stack(out, axis=1)


@pytest.mark.parametrize("steps", [1, 3, 700])  # 700: two chunks, the second one short
def test_rk8_matches_the_kernel_step_by_step(body, steps):
    t = np.array([0.0, 0.4, 1.0])
    res = dynamics.simulate(body, X0, t, method="rk8", steps=steps, jit=False)
    assert res.success and res.n_steps == steps * 2
    np.testing.assert_array_equal(res.x, _stepwise(body, X0, t, steps))


def test_compiled_rk8_matches_the_kernel_to_round_off(body):
    t = np.array([0.0, 1.0])
    res = dynamics.simulate(body, X0, t, method="rk8", steps=1)
    np.testing.assert_allclose(res.x, _stepwise(body, X0, t, 1), rtol=0, atol=1e-15)


@pytest.mark.parametrize("jit", [None, False])
def test_repeated_and_interleaved_calls_are_identical(body, jit):
    short, long_ = np.array([0.0, 1.0]), np.linspace(0.0, 10.0, 101)
    first = [dynamics.simulate(body, X0, g, method="rk8", steps=s, jit=jit).x
             for g, s in ((short, 1), (long_, 7), (short, 2))]
    for _ in range(3):
        again = [dynamics.simulate(body, X0, g, method="rk8", steps=s, jit=jit).x
                 for g, s in ((short, 1), (long_, 7), (short, 2))]
        for a, b in zip(first, again):
            np.testing.assert_array_equal(a, b)


def test_constant_control_paths_agree_bitwise():
    model = dynamics.rigid_body(INERTIA)
    t = np.linspace(0.0, 2.0, 5)
    u = np.array([0.01, -0.02, 0.03])
    const = dynamics.simulate(model, X0, t, u=u, method="rk8", steps=3, jit=False)
    samples = dynamics.simulate(model, X0, t, u=np.repeat(u[:, None], t.size, axis=1),
                                method="rk8", steps=3, jit=False)
    np.testing.assert_array_equal(const.x, samples.x)
    np.testing.assert_array_equal(const.x, _stepwise(model, X0, t, 3, u))
    zero = dynamics.simulate(model, X0, t, method="rk8", steps=3, jit=False)
    zeros = dynamics.simulate(model, X0, t, u=np.zeros((3, t.size)), method="rk8", steps=3,
                              jit=False)
    np.testing.assert_array_equal(zero.x, zeros.x)


def test_ramp_control_unchanged_by_constant_flag():
    model = dynamics.rigid_body(INERTIA)
    t = np.linspace(0.0, 1.0, 3)
    u = np.array([[0.0, 0.1, 0.0], [0.0, 0.0, 0.2], [0.1, 0.1, 0.1]])
    res = dynamics.simulate(model, X0, t, u=u, method="rk4", steps=2)
    seg = dynamics.simulate(model, X0, t[:2], u=u[:, :2], method="rk4", steps=2)
    np.testing.assert_array_equal(res.x[:, :2], seg.x)


def test_threads_share_no_buffer(body):
    t = np.linspace(0.0, 5.0, 21)
    rng = np.random.default_rng(3)
    x0s = []
    for _ in range(4):
        q = rng.standard_normal(4)
        x0s.append(np.concatenate([q / np.linalg.norm(q), rng.standard_normal(3)]))
    serial = [dynamics.simulate(body, x0, t, method="rk8", steps=s).x
              for x0 in x0s for s in (1, 40)]
    results, errors = {}, []
    barrier = threading.Barrier(4)

    def work(i):
        try:
            barrier.wait()
            for rep in range(50):
                for j, s in enumerate((1, 40)):
                    results[(i, rep, j)] = dynamics.simulate(body, x0s[i], t, method="rk8",
                                                             steps=s).x
        except Exception as exc:  # noqa: BLE001 - reported below
            errors.append(exc)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert not errors
    for (i, rep, j), x in results.items():
        np.testing.assert_array_equal(x, serial[2 * i + j])


def test_buffer_dropped_with_its_function():
    from appdyn.dynamics.integrate import evaluate
    x = ca.SX.sym("x", 2)
    f = ca.Function("twice", [x], [2 * x])
    np.testing.assert_array_equal(call_buffered(f, [np.array([1.0, 2.0])], (2,)), [2.0, 4.0])
    key = id(f)
    assert key in evaluate._thread_table("buffers")
    del f
    gc.collect()
    assert key not in evaluate._thread_table("buffers")


def test_inputs_left_out_are_zero_after_a_full_call():
    x, y = ca.SX.sym("x"), ca.SX.sym("y")
    f = ca.Function("sum", [x, y], [x + y])
    assert call_buffered(f, [np.array([1.0]), np.array([5.0])], (1,))[0] == 6.0
    assert call_buffered(f, [np.array([1.0])], (1,))[0] == 1.0
    assert call_buffered(f, [np.array([2.0]), np.array([5.0])], (1,))[0] == 7.0


@pytest.mark.parametrize("bad, match", [
    ([0, 0, 0, 2.0, 1, 0, 0], r"x0\[0:4\] \(the attitude quaternion\)` must be a unit "
                              r"quaternion \(norm 1 to 1e-06\), got norm 2"),
    ([0, 0, 0, 1 + 3e-6, 1, 0, 0], "got norm 1.000003"),
    ([0, 0, 0, float("nan"), 1, 0, 0], "`x0` must be finite"),
    ([0, 0, 0, 1.0, 1, 0], r"`x0` must have shape \(7,\)"),
])
def test_x0_checks_unchanged(body, bad, match):
    with pytest.raises(ValueError, match=match):
        dynamics.simulate(body, bad, [0.0, 1.0], method="rk8")


@pytest.mark.parametrize("kw, match", [
    ({"rtol": float("nan")}, "`rtol` must be finite"),
    ({"rtol": 1.0}, r"`rtol` must be in \["),
    ({"rtol": "a"}, "`rtol` must be real numbers"),
    ({"atol": -1e-3}, "`atol` must be non-negative"),
    ({"atol": float("inf")}, "`atol` must be finite"),
    ({"atol": float("nan")}, "`atol` must be finite"),
    ({"atol": [1e-3, 1e-3]}, r"`atol` must be a scalar or have shape \(7,\)"),
])
def test_tolerance_checks_unchanged(body, kw, match):
    with pytest.raises(ValueError, match=match):
        dynamics.simulate(body, X0, [0.0, 1.0], method="rk8", **kw)


@pytest.mark.parametrize("atol", [1e-10, 0.0, 1, np.float64(1e-9), [1e-9] * 7])
def test_tolerances_accepted_alike(body, atol):
    res = dynamics.simulate(body, X0, [0.0, 1.0], method="rk8", atol=atol, rtol=1e-8)
    assert res.success


def test_check_unit_quaternion_decides_as_unit_quaternion():
    rng = np.random.default_rng(11)
    for scale in (0.0, 1e-7, 4.9e-7, 5e-7, 9.99e-7, 1e-6, 1.0001e-6, 2e-6, 1e-3):
        for _ in range(50):
            q = rng.standard_normal(4)
            q = q / np.linalg.norm(q) * (1.0 + scale * rng.choice([-1.0, 1.0]))
            try:
                unit_quaternion(q, "q")
                expected = None
            except ValueError as exc:
                expected = str(exc)
            try:
                check_unit_quaternion(q, "q")
                got = None
            except ValueError as exc:
                got = str(exc)
            assert got == expected
    for q in ([0.0, 0.0, 0.0, 1.0], (0.0, 0.6, 0.0, 0.8), np.array([[0.0], [0], [0], [1]])):
        check_unit_quaternion(q, "q")
    with pytest.raises(ValueError, match="4 finite numbers"):
        check_unit_quaternion([0.0, float("inf"), 0.0, 1.0], "q")
    assert QUAT_NORM_TOL == 1e-6


def test_make_result_is_the_constructed_result(body):
    res = dynamics.simulate(body, X0, [0.0, 1.0], method="rk8", invariants=True)
    assert type(res) is SimulationResult
    values = dict(res.__dict__)
    built = SimulationResult(**values)
    assert built.__dict__.keys() == res.__dict__.keys()
    assert all(built.__dict__[k] is v for k, v in res.__dict__.items())
    with pytest.raises(Exception):
        res.success = False  # still frozen
    back = pickle.loads(pickle.dumps(res))
    np.testing.assert_array_equal(back.x, res.x)
    np.testing.assert_array_equal(back.sample(0.5), res.sample(0.5))
    with pytest.raises(TypeError, match="make_result needs exactly the fields"):
        make_result(t=res.t)
