"""``auto``'s one-pass path (`dynamics.integrate.adaptive`): rk8 with DOP853's embedded error
control and a check run at half the steps, in one compiled C pass. Judged against the
Jacobi-elliptic torque-free truth and the closed form of a spin-up under a ramped torque."""
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from appdyn.dynamics import cache, rigid_body, simulate
from appdyn.dynamics.integrate import adaptive
from appdyn.dynamics.integrate.auto import one_pass
from appdyn.dynamics.integrate.inputs import Problem, check_u
from appdyn.dynamics.integrate.loops import Progress
from appdyn.dynamics.integrate.result import FAILED
from appdyn.dynamics.truth import torque_free_omega, torque_free_parameters

INERTIA = [1.0, 2.0, 3.0]
X0 = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 0.1, 0.8])
ONE_PASS = "embedded error control"

pytestmark = pytest.mark.skipif(cache.compiler() is None, reason="needs a C compiler")


@pytest.fixture(autouse=True)
def _no_dense_path(monkeypatch):
    """The one-pass path as ``auto`` takes it where DOP853 with dense output
    (`auto.dense_pass`, `dense.dense_run`, tested in test_simulate_dense.py) does not apply, e.g. under a
    control that varies: here with that path switched off, so that the same closed forms
    judge the pass."""
    monkeypatch.setattr("appdyn.dynamics.integrate.auto.dense_pass",
                        lambda *args: (None, math.nan, None, 0, 0.0))
    # (and the common call's way to the same pass: `simulate` at the defaults)
    monkeypatch.setattr("appdyn.dynamics.integrate.api.dense_run", lambda *args, **kw: None)


def ratio(res, inertia, rtol, atol):
    """max |w - w_true| / (atol + rtol |w_true|) over the rates and output times."""
    w_true = torque_free_omega(inertia, res.x[4:, 0], res.t)
    return float(np.max(np.abs(res.x[4:] - w_true) / (atol + rtol * np.abs(w_true))))


def test_one_pass_at_loose_tolerance_meets_it_in_one_pass():
    """The benchmark body, 100 s, 101 outputs, rtol 1e-3: one pass (1-2 check steps and 2-5
    answer steps per interval: about 300 steps; a second pass would at least double it),
    accepted by Richardson's division, so with what the flow made of the check's start, 2 ulp
    away, measured (`auto._amplified`: the check's 1-2 steps per interval replayed once,
    about 100 more), and the error far inside the tolerance."""
    t = np.linspace(0.0, 100.0, 101)
    res = simulate(rigid_body(INERTIA), X0, t, rtol=1e-3, atol=1e-5)
    assert res.success and res.status == 0 and res.method == "rk8", res.message
    assert ONE_PASS in res.message
    assert 400 <= res.n_steps <= 470 and res.n_rhs == 12 * res.n_steps
    assert 2 <= res.substeps <= 5 and res.compiled
    assert res.error_estimate <= 0.5
    assert ratio(res, INERTIA, 1e-3, 1e-5) <= res.error_estimate
    assert np.array_equal(res.x[:, 0], X0) and res.x.flags.c_contiguous


@settings(max_examples=30, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(
    inertia=st.sampled_from([(1.0, 2.0, 3.0), (1.0, 1.5, 2.0), (2.0, 3.0, 4.5), (5.0, 4.0, 2.0),
                             (3.0, 1.0, 3.5)]),
    w0=st.lists(st.floats(-3.0, 3.0), min_size=3, max_size=3),
    t_final=st.floats(1.0, 100.0),
    n=st.integers(2, 600),
    log_rtol=st.floats(-8.0, -2.0),
)
@pytest.mark.slow
def test_one_pass_success_implies_the_tolerance_is_met(inertia, w0, t_final, n, log_rtol):
    """Random torque-free runs at tolerances where the one-pass path applies: success means
    the true rate error is within the tolerance at every output (and within the estimate
    when the estimate is the check's ``2 d``)."""
    rtol = 10.0 ** log_rtol
    atol = rtol / 100
    w0 = np.array(w0)
    if np.linalg.norm(w0) < 1e-3:
        w0 = w0 + 0.1
    if 1 - float(torque_free_parameters(list(inertia), w0).m) <= 1e-3:
        w0 = w0 * np.array([1.0, 0.5, 1.0]) + np.array([0.0, 0.0, 0.3])  # off the separatrix
    t = np.linspace(0.0, t_final, n)
    res = simulate(rigid_body(list(inertia)), np.r_[0, 0, 0, 1.0, w0], t, rtol=rtol, atol=atol)
    assert res.success or res.status in (2, 3), res.message
    if res.success:
        assert ratio(res, list(inertia), rtol, atol) <= 1.0, res.message


def test_ramped_torque_matches_the_closed_form():
    """Spin-up from rest about the 3-axis under ``tau = a + b t`` (samples on the grid, linear
    in between: the pass's per-interval control): ``w3 = (a t + b t^2 / 2) / I3`` and the
    quaternion turns by ``phi = (a t^2 / 2 + b t^3 / 6) / I3`` about z."""
    a, b, i3 = 0.2, 0.05, INERTIA[2]
    t = np.linspace(0.0, 10.0, 41)
    u = np.zeros((3, t.size))
    u[2] = a + b * t
    res = simulate(rigid_body(INERTIA), [0, 0, 0, 1, 0, 0, 0], t, u=u, rtol=1e-7, atol=1e-9)
    assert res.success and ONE_PASS in res.message, res.message
    w3 = (a * t + b * t ** 2 / 2) / i3
    phi = (a * t ** 2 / 2 + b * t ** 3 / 6) / i3
    q = np.stack([0 * t, 0 * t, np.sin(phi / 2), np.cos(phi / 2)])
    assert np.max(np.abs(res.x[6] - w3) / (1e-9 + 1e-7 * np.abs(w3))) <= 1.0
    # the scalar-last quaternion's sign is fixed by the start q = [0, 0, 0, 1]
    assert np.max(np.abs(res.x[:4] - q) / (1e-9 + 1e-7 * np.abs(q))) <= 1.0


def test_many_calls_of_the_pass_match_the_truth_across_their_boundaries():
    """600 output intervals: three calls of the compiled pass (`INTERVALS` each), the
    controller's state carried across; the answer meets the tolerance everywhere."""
    assert adaptive.INTERVALS < 600
    t = np.linspace(0.0, 300.0, 601)
    res = simulate(rigid_body(INERTIA), X0, t, rtol=1e-6, atol=1e-8)
    assert res.success and ONE_PASS in res.message, res.message
    assert ratio(res, INERTIA, 1e-6, 1e-8) <= 1.0


def test_the_pass_reports_progress_and_counts_every_step():
    seen = []
    t = np.linspace(0.0, 50.0, 51)
    res = simulate(rigid_body(INERTIA), X0, t, rtol=1e-4, atol=1e-6,
                   progress=lambda done, total: seen.append((done, total)))
    assert res.success and ONE_PASS in res.message
    assert seen and seen[-1][0] == seen[-1][1] == res.n_steps


def test_a_callable_control_or_no_compile_takes_the_multi_run_search():
    t = np.linspace(0.0, 10.0, 11)
    model = rigid_body(INERTIA)
    res = simulate(model, X0, t, u=lambda s: np.zeros(3), rtol=1e-6)
    assert res.success and ONE_PASS not in res.message
    res = simulate(model, X0, t, rtol=1e-6, jit=False)
    assert res.success and ONE_PASS not in res.message


def test_a_tolerance_near_round_off_is_left_to_the_floor_measurement():
    """rtol 1e-12 (atol 1e-14) is within 1e6 ulps of the states: the multi-run search with
    its measured round-off floor decides, never the one pass."""
    t = np.linspace(0.0, 10.0, 11)
    res = simulate(rigid_body(INERTIA), X0, t, rtol=1e-12, atol=1e-14)
    assert ONE_PASS not in res.message


def test_a_blow_up_is_a_failure_not_a_pass():
    """A right-hand side that overflows: the pass stops at the non-finite state and auto's
    search reports the failure (status FAILED), as it did before the pass."""
    import casadi as ca
    from appdyn.dynamics import Model
    x = ca.SX.sym("x")
    model = Model(ca.Function("f", [x, ca.SX.sym("u", 0), ca.SX.sym("p", 0)], [x ** 2],
                              ["x", "u", "p"], ["xdot"]), ("x",), ())
    res = simulate(model, [1.0], np.linspace(0.0, 2.0, 21), rtol=1e-6)
    assert not res.success and res.status == FAILED, res.message
    assert "non-finite" in res.message


def test_max_steps_stops_the_pass_and_the_search_says_why():
    t = np.linspace(0.0, 100.0, 101)
    res = simulate(rigid_body(INERTIA), X0, t, rtol=1e-8, atol=1e-10, max_steps=150)
    assert not res.success and res.status == 3 and "max_steps" in res.message


@pytest.mark.slow
def test_the_pass_is_compiled_once_per_model():
    model = rigid_body([1.0, 2.5, 3.0])
    t = np.linspace(0.0, 10.0, 11)
    simulate(model, X0, t, rtol=1e-6)
    lib = adaptive.pass_library(model)
    assert lib is not None
    simulate(model, X0, np.linspace(0.0, 3.0, 301), rtol=1e-4, u=np.ones(3))
    assert adaptive.pass_library(model) is lib


def test_not_accepted_passes_hand_their_steps_to_the_search():
    """A pass that cannot be completed (one 100 s interval: more than ``2 BMAX + 1`` steps
    needed) returns no run and the steps it spent."""
    model = rigid_body(INERTIA)
    t = np.linspace(0.0, 100.0, 2)
    problem = Problem.new(model, X0, t, check_u(None, model.nu, t), model.resolve_p(None))
    run, estimate, spent = one_pass(problem, 1e-8, np.full(7, 1e-10), 10 ** 8, None,
                                    Progress(None))
    assert run is None and math.isnan(estimate) and spent > 0


@pytest.mark.slow
def test_the_first_auto_call_also_starts_the_fallback_loops_compile(tmp_path):
    """No second compile later: the first ``auto`` call of a model starts the compile of
    the rk8 chunk loop its multi-run search runs (in the background: `cache.compile_ahead`),
    so a later call that falls back (here a tolerance near round-off) waits for that
    compile, or loads its library, rather than compiling again."""
    from appdyn.dynamics import clear_caches, diskcache
    from appdyn.dynamics.integrate.loops import chunk_key
    old = diskcache.configure(directory=tmp_path, enabled=True)  # (nothing compiled before)
    try:
        clear_caches()  # the first call of this model in the process, whatever ran before
        model = rigid_body([1.0, 2.2, 3.0])
        t = np.linspace(0.0, 10.0, 11)
        start = diskcache.info().compiles
        simulate(model, X0, t, rtol=1e-4)
        key = chunk_key(model, "rk8", "linear") + (True,)
        assert not cache.contains(key)  # (not waited for: the pass answered)
        assert diskcache.info().compiles == start + 2  # (the pass, and the chunk under way)
        res = simulate(model, X0, t, rtol=1e-12, atol=1e-14)
        assert ONE_PASS not in res.message and res.compiled and cache.contains(key)
        assert diskcache.info().compiles == start + 2
    finally:
        diskcache.configure(**old)


def test_the_check_replayed_from_the_exact_start_is_its_own_steps():
    """`adaptive.replay_check` takes the check's own steps (from the answer's per-interval
    count) from the exact start: on the benchmark body, where the flow barely amplifies, it
    lies within a few ulp-sized tolerances of the check (started 2 ulp away); with the check's
    start it gives the check to the bit (the same arithmetic)."""
    import dataclasses
    from appdyn.dynamics.integrate.adaptive import replay_check, run_pass
    from appdyn.dynamics.integrate.inputs import Problem, check_u
    from appdyn.dynamics.integrate.loops import Progress
    model, t = rigid_body(INERTIA), np.linspace(0.0, 100.0, 101)
    problem = Problem.new(model, X0, t, check_u(None, model.nu, t), np.zeros(0))
    got = run_pass(problem, 1e-6, np.full(7, 1e-8), 1e-4, 10 ** 8, Progress(None))
    assert got.ok
    x = replay_check(problem, got)
    scale = 1e-8 + 1e-6 * np.abs(got.x[:, 1:])
    assert np.max(np.abs(x[:, 1:] - got.xc[:, 1:]) / scale) < 1e-3
    moved = replay_check(dataclasses.replace(problem, x0=got.xc[:, 0].copy()), got)
    np.testing.assert_array_equal(moved, got.xc)


@pytest.mark.parametrize("threads", [1, 2])
def test_a_batch_of_passes_is_its_runs_passes_and_replays_to_the_bit(threads):
    """`adaptive.run_pass_many` (one compiled loop over the runs) gives each run the `Pass`
    `run_pass` gives it alone, and `PassBatch.replay_checks` the check replayed from its
    exact start as `replay_check` makes it, every array and count to the bit, on any number
    of threads; a run whose spin the pass cannot follow stops as it does alone."""
    from appdyn.dynamics.integrate.adaptive import replay_check, run_pass, run_pass_many
    from appdyn.dynamics.integrate.inputs import check_batch
    model, t, K = rigid_body(INERTIA), np.linspace(0.0, 20.0, 21), 6
    rng = np.random.default_rng(3)
    X = np.tile(X0[:, None], (1, K))
    X[4:] += 0.3 * rng.normal(size=(3, K))
    X[4:, 5] = [40.0, 0.0, 0.0]  # (a spin the pass cannot follow in 2 BMAX + 1 steps)
    U = 0.05 * rng.normal(size=(3, t.size, K))
    batch = check_batch(model, X, t, U, None)
    atol = np.full(7, 1e-10)
    made = run_pass_many(model, batch.x0.T, t, batch.ua, batch.ub, batch.p.T, 1e-8, atol,
                         1.0 / 20.0, 10 ** 8, ulps=1e4, threads=threads)
    replays = made.replay_checks([k for k in range(K) if made.passes[k].ok])
    assert not made.passes[5].ok and len(replays) == K - 1
    for k in range(K):
        problem = batch.problem(k)
        alone = run_pass(problem, 1e-8, atol, 1.0 / 20.0, 10 ** 8, Progress(None), ulps=1e4)
        got = made.passes[k]
        for name, value in zip(got._fields, got):
            np.testing.assert_array_equal(value, getattr(alone, name), err_msg=name)
        if got.ok:
            np.testing.assert_array_equal(replays[k], replay_check(problem, alone))


def test_the_norm_bound_of_the_rounding_decides_nothing_the_spectrum_would_not():
    """`auto.rounding_bound` with ``below``: the bound carried with ``|J|_inf`` (at least the
    spectral radius) is an upper bound of the bound carried with the spectral radius, and
    is taken only under ``below``; the verdict of `auto.pass_verdict` (which asks with its
    states' ulps as ``below``) is then the one the exact bound gives, to the bit. Under a
    torque sampled on the grid at rtol 1e-8 (the one-pass path near the states' round-off,
    where the bound is asked for)."""
    from appdyn.dynamics.integrate.auto import pass_verdict, rounding_bound
    from appdyn.dynamics.integrate.estimates import (FLOOR_ULPS, jacobian_at, norm_bounds,
                                                     spectra)
    model, t = rigid_body(INERTIA), np.linspace(0.0, 20.0, 121)
    u = 0.01 * np.sin(np.outer([0.7, 1.3, 1.9], t) + np.array([[0.1], [0.5], [1.0]]))
    problem = Problem.new(model, X0, t, check_u(u, model.nu, t), np.zeros(0))
    atol = np.full(7, 1e-10)
    got = adaptive.run_pass(problem, 1e-8, atol, 1.0 / 20.0, 10 ** 8, Progress(None))
    assert got.ok and got.ulp * 1e6 > 1.0  # (the bound is asked for)
    J = jacobian_at(problem)
    assert norm_bounds(J) >= spectra(J[None])[0][0]
    exact = rounding_bound(problem, got, 1e-8, atol)
    upper = rounding_bound(problem, got, 1e-8, atol, below=1.0)
    assert exact < upper <= 1.0  # (here |J|_inf is larger than the spectral radius)
    assert rounding_bound(problem, got, 1e-8, atol, below=exact) == exact  # (not under it)
    ulps = got.ulp * FLOOR_ULPS
    assert upper < ulps  # (so the verdict adds the ulps, whichever bound it has)
    mine = pass_verdict(problem, got, 1e-8, atol, 0.0, Progress(None))
    theirs = pass_verdict(problem, got, 1e-8, atol, 0.0, Progress(None), bound=exact)
    assert mine == theirs and mine[0] is not None


def test_norm_bounds_hold_the_spectral_radius_of_any_matrix():
    """`estimates.norm_bounds` (``|J|_inf``) is at least `estimates.spectra`'s spectral
    radius, which is each matrix's largest ``|eigenvalue|`` (numpy's, to rounding); NaN
    for a matrix that is not finite."""
    from appdyn.dynamics.integrate.estimates import norm_bounds, spectra
    J = np.random.default_rng(3).normal(size=(200, 6, 6)) * np.logspace(-3, 3, 200)[:, None, None]
    rho, sigma = spectra(J)
    lam = np.linalg.eigvals(J)
    np.testing.assert_allclose(rho, np.abs(lam).max(axis=1), rtol=1e-12)
    assert np.all(norm_bounds(J) >= rho * (1 - 1e-12))
    decay = np.where((lam.real < 0) & (np.abs(lam.imag) <= -lam.real), -lam.real, 0.0)
    np.testing.assert_allclose(sigma, decay.max(axis=1), rtol=1e-12)
    J[7, 2, 3] = np.nan
    assert np.isnan(norm_bounds(J)[7]) and np.isnan(spectra(J)[0][7])
