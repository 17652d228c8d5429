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


def _pendulum(nonsmooth=False):
    """theta'' = -(g / l) sin(theta) + u, g / l a parameter; with ``nonsmooth`` a stop
    (``fmin``) the rewrite does not take."""
    th, om, k, u = ca.SX.sym("theta"), ca.SX.sym("omega"), ca.SX.sym("k"), ca.SX.sym("u")
    acc = -k * ca.sin(th) + u
    if nonsmooth:
        acc = ca.fmin(acc, 5.0)
    return Model.from_expressions({"theta": th, "omega": om}, {"theta": om, "omega": acc},
                                  controls={"u": u}, params={"k": k}, p_default=[1.0])


def test_the_rewrite_takes_arithmetic_and_functions_and_refuses_conditionals():
    assert lanes.lane_source(kernel(rigid_body([1.0, 2.0, 3.0]), "rk8", "linear",
                                    compiled=True)) is not None
    assert "v_sin(" in lanes.lane_source(kernel(_pendulum(), "rk8", "linear", compiled=True))
    assert lanes.lane_source(kernel(_pendulum(True), "rk8", "linear", compiled=True)) is None


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
