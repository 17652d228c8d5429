"""`simulate(..., method='dop853')`: one DOP853 run at the local tolerances, nothing verified.

Checked against closed forms (the torque-free body's Jacobi-elliptic rates; a spherical
body under sampled, held and callable torques, whose rates integrate the torque exactly), a
peer (scipy's DOP853 at the same tolerances: the same method, so errors and steps of the
same size), and the contract of an unverified method: ``error_estimate`` NaN, a failure
said with its cause, the sanity check of the fixed-step methods."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from appdyn.dynamics import Event, rigid_body, simulate
from appdyn.dynamics.integrate.result import FAILED, TERMINAL_EVENT, VIOLATED
from appdyn.dynamics.truth import torque_free_omega

INERTIA, W0 = [1.5, 2.5, 3.2], [0.5, 0.0, 1.0]
X0 = np.r_[0.0, 0.0, 0.0, 1.0, W0]
T = np.linspace(0.0, 60.0, 121)


def rate_error(res, t=T):
    return float(np.max(np.abs(res.x[4:] - torque_free_omega(INERTIA, W0, t))))


@pytest.mark.parametrize("jit", [None, False])
def test_the_error_follows_the_local_tolerance(jit):
    """Against Jacobi: a tighter tolerance, a smaller error, within 1000 tolerances over the
    60 s (nothing verified: DOP853's global error follows its local tolerance); where the
    steps follow the error alone (compiled, constant control) three decades of rtol buy at
    least two of error. From Python the steps end on the grid, which bounds them at loose
    tolerances."""
    errs, tols = [], (1e-6, 1e-9, 1e-12)
    for rtol in tols:
        res = simulate(rigid_body(INERTIA), X0, T, method="dop853", rtol=rtol, atol=rtol / 100,
                       jit=jit)
        assert res.success and res.status == 0 and res.method == "dop853"
        assert np.isnan(res.error_estimate) and "dop853" in res.message
        errs.append(rate_error(res))
    assert errs[2] < 1e-11 and errs[0] > errs[1] > errs[2]
    assert all(e < 1000 * rtol for e, rtol in zip(errs, tols))
    if jit is None:
        assert errs[1] < errs[0] / 100 and errs[2] < errs[1] / 100


def test_as_scipy_dop853_at_the_same_tolerances():
    """The same method as scipy's DOP853: errors within 5x of each other, steps within 30 %
    (scipy's controller differs in its step-change limits)."""
    model = rigid_body(INERTIA)
    f = lambda t, x: np.asarray(model.f(x, np.zeros(3), []), float).ravel()  # noqa: E731
    for rtol in (1e-7, 1e-10):
        res = simulate(model, X0, T, method="dop853", rtol=rtol, atol=rtol / 100)
        ref = solve_ivp(f, (0.0, 60.0), X0, method="DOP853", t_eval=T, rtol=rtol,
                        atol=rtol / 100)
        mine, theirs = rate_error(res), float(np.max(np.abs(
            ref.y[4:] - torque_free_omega(INERTIA, W0, T))))
        assert theirs / 5 < mine < 5 * theirs
        assert abs(res.n_steps / (ref.nfev / 12) - 1) < 0.3


def sphere_case():
    """J = 2 E: w(t) = w0 + (1/2) integral of the torque, exactly (w x J w = 0)."""
    return rigid_body([2.0, 2.0, 2.0]), np.r_[0.0, 0.0, 0.0, 1.0, 0.3, -0.2, 0.1]


def test_sampled_held_and_callable_torques_against_closed_forms():
    model, x0 = sphere_case()
    t = np.linspace(0.0, 4.0, 9)
    a, b = np.array([0.2, -0.1, 0.05]), np.array([0.0, 0.3, -0.2])
    # linear samples u = a + b t: w = w0 + (a t + b t^2 / 2) / 2
    U = a[:, None] + b[:, None] * t
    exact = x0[4:, None] + (a[:, None] * t + b[:, None] * t ** 2 / 2) / 2
    for u in (U, lambda s: a + b * s):
        res = simulate(model, x0, t, u=u, method="dop853", rtol=1e-11, atol=1e-13)
        assert res.success
        np.testing.assert_allclose(res.x[4:], exact, rtol=0, atol=1e-10)
    # held: u[:, k] on [t_k, t_k+1): w = w0 + cumulative sum of u_k h / 2
    res = simulate(model, x0, t, u=U, hold="zoh", method="dop853", rtol=1e-11, atol=1e-13)
    held = x0[4:, None] + np.concatenate([[[0.0]] * 3, np.cumsum(U[:, :-1] * 0.5, axis=1) / 2],
                                         axis=1)
    assert res.success
    np.testing.assert_allclose(res.x[4:], held, rtol=0, atol=1e-10)


def test_an_event_is_located_on_the_run():
    """A constant torque -0.4 on a sphere J = 2: w_x = 0.3 - 0.2 t crosses zero at 1.5 s."""
    model, x0 = sphere_case()
    stop = Event(lambda t, x, u, p: x[4], terminal=True, direction=-1, name="w_x")
    res = simulate(model, x0, np.linspace(0.0, 4.0, 5), u=[-0.4, 0.0, 0.0], method="dop853",
                   rtol=1e-12, atol=1e-12, events=stop)
    assert res.status == TERMINAL_EVENT and abs(res.t[-1] - 1.5) < 1e-10


def test_a_batch_is_its_runs_one_by_one():
    model = rigid_body(INERTIA)
    X = np.stack([X0, np.r_[0.0, 0.0, 0.0, 1.0, 0.1, 0.9, 0.2]], axis=1)
    res = simulate(model, X, T, method="dop853", rtol=1e-9, atol=1e-11)
    assert res.all_success and res.method == "dop853" and np.all(np.isnan(res.error_estimate))
    for k in range(2):
        one = simulate(model, X[:, k], T, method="dop853", rtol=1e-9, atol=1e-11)
        np.testing.assert_array_equal(res.x[:, :, k], one.x)


def test_failures_are_reported_with_their_cause():
    model = rigid_body(INERTIA)
    res = simulate(model, X0, T, method="dop853", max_steps=10)
    assert not res.success and res.status == FAILED
    assert "more than max_steps steps" in res.message
    assert np.isnan(res.x[:, -1]).all() and np.isfinite(res.x[:, 0]).all()
    # a tolerance too loose for a 600 s tumble: the quaternion's norm gives it away
    t = np.linspace(0.0, 600.0, 601)
    res = simulate(model, X0, t, method="dop853", rtol=0.05, atol=5e-4)
    assert not res.success and res.status == VIOLATED
    assert "tighten `rtol`/`atol` or use method='auto'" in res.message


@pytest.mark.parametrize("rtol, points", [(1e-9, 2), (1e-9, 121), (1e-3, 601), (0.05, 601)])
def test_the_pass_measures_the_drift_and_substeps_the_sanity_check_reads(rtol, points):
    """The compiled answer alone measures its quaternion's drift and its substeps in C
    (`Run.quat_off`, ``substeps``): against numpy's norm of the returned states and the
    grid's longest interval over the smallest step, on runs that keep the norm and one
    that loses it (rtol 0.05 over 600 s, refused by the sanity check)."""
    import math

    from appdyn.dynamics.integrate.dense import dense_run
    from appdyn.dynamics.integrate.stepcontrol import plain_run
    t = np.linspace(0.0, 600.0 if points == 601 else 60.0, points)
    model = rigid_body(INERTIA)
    run = plain_run(model, X0, t, rtol, np.full(7, rtol / 100), 10 ** 6)
    off = np.abs(np.linalg.norm(run.x[:4], axis=0) - 1.0).max()
    assert run.ok and abs(run.quat_off - off) <= 4e-16, (run.quat_off, off)
    got = dense_run(model, X0, t, rtol, rtol / 100, 1e6, math.inf, check=False)
    assert run.substeps == got.substeps == math.ceil(np.diff(t).max() / got.hmin) >= 1
    res = simulate(model, X0, t, method="dop853", rtol=rtol, atol=rtol / 100, p=[])
    assert res.success == (off <= 1e-3) and (res.status == VIOLATED) == (off > 1e-3)


def test_steps_are_refused():
    with pytest.raises(ValueError, match="`steps` applies to the fixed-step methods"):
        simulate(rigid_body(INERTIA), X0, T, method="dop853", steps=4)


def test_a_batch_run_that_fails_is_said_and_the_others_answer():
    """One compiled loop over the runs; a run that needs more than ``max_steps`` fails
    alone (NaN from where it stopped), the slow run beside it is answered."""
    model = rigid_body(INERTIA)
    slow, fast = np.r_[0.0, 0.0, 0.0, 1.0, 0.01, 0.0, 0.02], np.r_[0.0, 0.0, 0.0, 1.0, 5.0, 0.1, 6.0]
    res = simulate(model, np.stack([slow, fast], axis=1), T, method="dop853", max_steps=200)
    assert res.success.tolist() == [True, False] and res.status[1] == FAILED
    assert "1 failed" in res.message and "more than max_steps steps" in res.message
    assert np.isfinite(res.x[:, :, 0]).all() and np.isnan(res.x[:, -1, 1]).all()
    one = simulate(model, slow, T, method="dop853", max_steps=200)
    np.testing.assert_array_equal(res.x[:, :, 0], one.x)


@pytest.mark.parametrize("case", ["body", "no inputs", "parameters"])
def test_the_first_step_evaluates_the_model_as_its_rhs_does_to_the_bit(case):
    """`estimates._xdot` (the buffered call `initial_step` makes, and its mapped call over
    the rows of a batch) gives `Model.rhs`'s bits, also for a model without controls or
    parameters; so a run's first step, and every step after it, is what the dictionary
    call gave."""
    import casadi as ca

    from appdyn.dynamics import Model
    from appdyn.dynamics.integrate.estimates import _xdot

    rng = np.random.default_rng(5)
    if case == "body":
        model = rigid_body([1.5, 2.5, 3.2])
        x, u, p = np.r_[0.1, -0.2, 0.3, 0.9, rng.normal(size=3)], rng.normal(size=3), None
    else:
        s, k = ca.SX.sym("s"), ca.SX.sym("k")
        params = {"k": k} if case == "parameters" else None
        model = Model.from_expressions({"s": s}, {"s": (k if params else 1.0) * s ** 2 - 0.3},
                                       params=params, p_default=[1.7] if params else None)
        x, u, p = np.array([0.7]), np.zeros(0), None
    p = model.resolve_p(p)
    for _ in range(5):
        assert np.array_equal(_xdot(model, x, u, p), model.rhs(x, u, p))
        rows = _xdot(model, np.stack([x, 2 * x]), np.stack([u, u]), np.stack([p, p]))
        assert np.array_equal(rows[1], model.rhs(2 * x, u, p))
        x = x + 0.1 * rng.normal(size=x.size)


@pytest.mark.parametrize("hold", ["linear", "zoh"])
@pytest.mark.parametrize("threads", [1, 2])
def test_a_batch_under_sampled_torques_is_its_runs_one_by_one_and_exact(hold, threads):
    """Each run its own sampled torque (steps ending on the grid, the compiled stepper per
    run, first steps found together): the bits of its single call on any number of
    threads, and on a sphere J = 2 E the closed form w = w0 + (1/2) integral of the torque
    (linear samples: the trapezoid; held: the left sums)."""
    model, x0 = sphere_case()
    t = np.linspace(0.0, 4.0, 9)
    K = 7
    rng = np.random.default_rng(11)
    X0 = np.tile(x0[:, None], (1, K))
    X0[4:] += rng.normal(size=(3, K))
    U = rng.normal(size=(3, t.size, K))
    res = simulate(model, X0, t, u=U, hold=hold, method="dop853", rtol=1e-11, atol=1e-13,
                   threads=threads)
    assert res.all_success and "compiled stepper" in res.message
    h = np.diff(t)[None, :, None]
    steps = (U[:, :-1] + U[:, 1:]) / 2 * h if hold == "linear" else U[:, :-1] * h
    exact = X0[4:, None, :] + np.concatenate([np.zeros((3, 1, K)), np.cumsum(steps, axis=1)],
                                             axis=1) / 2
    np.testing.assert_allclose(res.x[4:], exact, rtol=0, atol=1e-10)
    for k in (0, 3, K - 1):
        one = simulate(model, X0[:, k], t, u=U[:, :, k], hold=hold, method="dop853",
                       rtol=1e-11, atol=1e-13)
        np.testing.assert_array_equal(res.x[:, :, k], one.x)


def test_a_sampled_batch_run_that_blows_up_fails_alone_with_its_cause():
    """x' = x^2 + u: the run from 2 blows up before t = 0.5, the others answer as alone."""
    import casadi as ca

    from appdyn.dynamics import Model

    s, u = ca.SX.sym("s"), ca.SX.sym("u")
    model = Model.from_expressions({"s": s}, {"s": s ** 2 + u}, controls={"u": u})
    t = np.linspace(0.0, 0.9, 10)
    x0 = np.array([[0.1, 2.0, -0.3]])
    U = 0.01 * np.sin(np.arange(3 * t.size)).reshape(1, t.size, 3)
    res = simulate(model, x0, t, u=U, method="dop853", rtol=1e-10, atol=1e-12)
    assert res.success.tolist() == [True, False, True] and res.status[1] == FAILED
    assert "1 failed" in res.message
    assert np.isnan(res.x[0, -1, 1]) and np.isfinite(res.x[0, 0, 1])
    for k in (0, 2):
        one = simulate(model, x0[:, k], t, u=U[:, :, k], method="dop853", rtol=1e-10,
                       atol=1e-12)
        np.testing.assert_array_equal(res.x[:, :, k], one.x)
    alone = simulate(model, x0[:, 1], t, u=U[:, :, 1], method="dop853", rtol=1e-10,
                     atol=1e-12)
    assert alone.message.split(": ", 1)[1] in res.message


@pytest.mark.parametrize("threads", [1, 2])
def test_a_ctrl_c_stops_the_stepped_loops_from_taking_runs(threads, monkeypatch):
    """A Ctrl-C while a sampled `dop853` batch runs (`stepcontrol.run_stepped_many`) is
    deferred and raised (KeyboardInterrupt) once the runs taken have finished: a loop that
    sees it takes no further run (here it arrives as the loops start: none is taken), and
    the next call is whole."""
    import os
    import signal

    from appdyn.dynamics import executors
    from appdyn.dynamics.integrate.cpass import pass_library

    if signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
        pytest.skip("SIGINT has a handler of its own here")
    model, x0 = sphere_case()
    t, K = np.linspace(0.0, 1.0, 5), 300
    X0 = np.tile(x0[:, None], (1, K))
    U = np.random.default_rng(2).normal(size=(3, t.size, K))
    lib, calls = pass_library(model), []
    many, split = lib.stepper_many, executors.run_split
    monkeypatch.setattr(lib, "stepper_many", lambda *a: calls.append(1) or many(*a))

    def interrupted_split(fun, tasks):  # (inside the deferral: the loops are about to start)
        os.kill(os.getpid(), signal.SIGINT)
        return split(fun, tasks)

    monkeypatch.setattr(executors, "run_split", interrupted_split)
    with pytest.raises(KeyboardInterrupt):
        simulate(model, X0, t, u=U, method="dop853", threads=threads)
    assert not calls
    monkeypatch.setattr(executors, "run_split", split)
    res = simulate(model, X0[:, :20], t, u=U[:, :, :20], method="dop853", threads=threads)
    assert res.all_success and calls


@pytest.mark.parametrize("sampled", [False, True])
def test_a_dop853_batch_tells_progress_its_steps(sampled):
    """The compiled loops of a `dop853` batch (constant or sampled controls) tell a progress
    callback every run's steps (accepted and rejected) once they are done: the last call
    is (total, total), the total the runs' own steps, as single calls count them."""
    model, x0 = sphere_case()
    t, K = np.linspace(0.0, 2.0, 5), 6
    X0 = np.tile(x0[:, None], (1, K))
    X0[4:] += np.random.default_rng(4).normal(size=(3, K))
    U = (np.random.default_rng(5).normal(size=(3, t.size, K)) if sampled
         else np.array([0.1, 0.0, -0.2]))
    calls = []
    res = simulate(model, X0, t, u=U, method="dop853", progress=lambda d, n: calls.append((d, n)))
    single = sum(simulate(model, X0[:, k], t, u=U[:, :, k] if sampled else U,
                          method="dop853").n_steps for k in range(K))
    assert res.all_success and calls and calls[-1] == (single, single)
