"""Batched simulation (`simulate` with ``x0`` of shape (nx, K)): every run against an
independent truth (the Jacobi-elliptic torque-free rates, closed forms under constant
torque and of a damped oscillator with per-run parameters), against single runs, per-run
failure, and the argument checks."""
import casadi as ca
import numpy as np
import pytest

from dynamics import Model, rigid_body, simulate
from dynamics.integrate.batch import BatchResult
from dynamics.truth import torque_free_omega

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


@pytest.mark.parametrize("method", ["rk8", "rk4", "lie", "cvodes"])
def test_a_batch_equals_its_runs_one_by_one(method):
    t = np.linspace(0.0, 5.0, 11)
    _, X0 = _rates(5, seed=1)
    model = rigid_body(INERTIA)
    kw = {} if method == "cvodes" else {"steps": 3}
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
