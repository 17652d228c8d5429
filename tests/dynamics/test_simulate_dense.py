"""DOP853 with dense output (`stepcontrol.plain_run`, `auto.dense_pass`): the continuous
extension's order, steps chosen by the error estimate and not by the output grid, and the
global tolerance delivered (not exceeded by orders of magnitude) against closed forms."""
import numpy as np
import pytest

from appdyn.dynamics import rigid_body, simulate
from appdyn.dynamics.integrate.inputs import Problem, check_u
from appdyn.dynamics.integrate.kernels import dense_kernels, kernel
from appdyn.dynamics.integrate.stepcontrol import plain_run
from appdyn.dynamics.truth import axisymmetric
from appdyn.dynamics.truth.torque_free import torque_free_omega

INERTIA = [1.5, 2.5, 3.2]
X0 = np.r_[0.0, 0.0, 0.0, 1.0, 0.5, 0.0, 1.0]


def _problem(model, x0, t):
    return Problem.new(model, x0, t, check_u(None, model.nu, t), np.zeros(model.f.numel_in(2)))


def _interpolate(F, x, s):
    """The continuous extension at ``s`` in [0, 1] (as `cpass._DENSE` evaluates it)."""
    r = F[5] + s * F[6]
    for i, w in ((4, 1 - s), (3, s), (2, 1 - s), (1, s), (0, 1 - s)):
        r = F[i] + w * r
    return x + s * r


def test_continuous_extension_is_seventh_order():
    """Inside one step the interpolant's error against a 200-step rk8 reference falls as
    h^8 (local error of an order-7 extension): 2^8 = 256 per halving, within a factor 2."""
    model = rigid_body(INERTIA)
    step, cont = dense_kernels(model)
    fine = kernel(model, "rk8", "linear")
    u, p = np.zeros(model.nu), np.zeros(model.f.numel_in(2))
    errors = []
    for H in (1.6, 0.8, 0.4):
        xn, _, K = step(X0, H, u, p, 1e-8, np.full(7, 1e-10))
        F = np.asarray(cont(X0, xn, K, H, u, p)).reshape(7, 7)
        assert np.array_equal(F[0], np.asarray(xn).ravel() - X0)  # the step's end is exact
        s = 0.37
        ref = X0.copy()
        for _ in range(200):
            ref = np.asarray(fine(ref, s * H / 200, u, u, p)).ravel()
        errors.append(np.abs(_interpolate(F, X0, s) - ref).max())
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all((ratios > 128) & (ratios < 512)), ratios


@pytest.mark.parametrize("rtol", [1e-6, 1e-9])
def test_steps_follow_the_error_not_the_grid(rtol):
    """121 and 1201 outputs over 60 s: the same steps (the outputs never cut one), and the
    outputs agree with the Jacobi truth within the local tolerance's global error."""
    model = rigid_body(INERTIA)
    runs = {}
    for n in (121, 1201, 2):
        t = np.linspace(0.0, 60.0, n)
        run = plain_run(model, X0, t, rtol, np.full(7, rtol * 1e-2), 10 ** 6)
        assert run.ok
        w = torque_free_omega(INERTIA, X0[4:], t)
        assert np.abs(run.x[4:] - w).max() < 10 * rtol
        runs[n] = run
    assert runs[121].n_steps == runs[1201].n_steps == runs[2].n_steps
    assert np.array_equal(runs[121].x[:, -1], runs[1201].x[:, -1])


@pytest.mark.parametrize("rtol", [1e-5, 1e-7, 1e-9])
@pytest.mark.parametrize("n", [2001, 4001])
def test_auto_delivers_the_tolerance(rtol, n):
    """``auto`` on an axisymmetric body (rates and attitude in closed form) on grids dense
    enough to bind the one pass (so the dense path is taken): the scaled error over every
    state is within the tolerance and not below it by more than 3 orders of magnitude."""
    inertia, w0 = [2.0, 2.0, 3.5], [0.4, -0.3, 1.1]
    t = np.linspace(0.0, 40.0, n)
    model = rigid_body(inertia)
    x0 = np.r_[0.0, 0.0, 0.0, 1.0, w0]
    atol = rtol * 1e-2
    res = simulate(model, x0, t, rtol=rtol, atol=atol)
    assert res.success and "dense output" in res.message, res.message
    w, q = axisymmetric(inertia, w0, x0[:4], t)
    q = q * np.sign(np.sum(q * res.x[:4], axis=0))
    truth = np.vstack([q, w])
    scaled = np.abs(res.x - truth) / (atol + rtol * np.abs(truth))
    assert 1e-3 < scaled.max() <= 1.0, scaled.max()


#: Asymmetric bodies of the issue and of the simulate benchmark (rates in Jacobi's closed form).
_JACOBI = [([1.5, 2.5, 3.2], [0.5, 0.0, 1.0]), ([1.0, 2.0, 3.0], [1.0, 0.1, 0.8])]


@pytest.mark.parametrize("horizon", [10.0, 60.0, 200.0])
@pytest.mark.parametrize("rtol", [1e-5, 1e-7, 1e-9])
@pytest.mark.parametrize("body", range(len(_JACOBI)))
def test_auto_delivers_the_tolerance_over_horizons_against_jacobi(body, rtol, horizon):
    """``auto`` (the dense path, its check the answer's steps merged in pairs) on tumbling
    asymmetric bodies over short and long horizons: the rates' error against Jacobi's closed
    form is within the tolerance, not below it by more than 3 orders of magnitude, and within
    the estimate; the inertial angular momentum (the attitude's truth) is kept to rtol."""
    inertia, w0 = _JACOBI[body]
    model, t = rigid_body(inertia), np.linspace(0.0, horizon, 61)
    x0, atol = np.r_[0.0, 0.0, 0.0, 1.0, w0], rtol * 1e-2
    res = simulate(model, x0, t, rtol=rtol, atol=atol)
    assert res.success and "merged in pairs" in res.message, res.message
    w = torque_free_omega(inertia, w0, t)
    scaled = np.max(np.abs(res.x[4:] - w) / (atol + rtol * np.abs(w)))
    assert 1e-3 < scaled <= min(1.0, res.error_estimate), (scaled, res.error_estimate)
    H = np.asarray(model.invariant("momentum_inertial", res.x))
    assert np.max(np.linalg.norm(H - H[:, :1], axis=0)) <= rtol * np.linalg.norm(H[:, 0])


def _lorenz():
    import casadi as ca
    from appdyn.dynamics.model import model_from_expressions
    x, y, z = ca.SX.sym("x"), ca.SX.sym("y"), ca.SX.sym("z")
    return model_from_expressions({"x": x, "y": y, "z": z},
                                  [10 * (y - x), x * (28 - z) - y, x * y - 8 / 3 * z],
                                  name="lorenz")


@pytest.mark.slow  # (the Lorenz model's first compile: seconds)
def test_the_check_verifies_a_chaotic_run_while_it_is_determined():
    """Lorenz over 15 s (errors grow ~e^(0.9 t), 1e6-fold): the answer, verified, is within
    its estimate and the tolerance of a run at a local tolerance 1e5x tighter than its own."""
    from appdyn.dynamics.integrate.dense import dense_auto
    model, t, x0, rtol = _lorenz(), np.linspace(0.0, 15.0, 41), np.ones(3), 1e-6
    problem = _problem(model, x0, t)
    got = dense_auto(problem, rtol, np.full(3, rtol / 100), 1e8, 1e6)
    assert got.result == 1
    ref = plain_run(model, x0, t, 1e-5 * rtol * got.factor, np.full(3, 1e-7 * rtol * got.factor),
                    10 ** 8)
    scaled = np.max(np.abs(got.x[:, 1:] - ref.x[:, 1:]) / (rtol / 100 + rtol * np.abs(ref.x[:, 1:])))
    assert scaled <= min(1.0, got.estimate), (scaled, got.estimate)


@pytest.mark.slow  # (the Lorenz model's first compile: seconds)
def test_the_check_refuses_a_chaotic_answer_double_precision_cannot_give():
    """Lorenz over 40 s: tight runs from starts one ulp apart end further apart than the
    tolerance (the answer is not determined to it in double precision), so the one call
    does not call its answer verified, nor does ``simulate`` report success."""
    from appdyn.dynamics.integrate.dense import dense_auto
    model, t, x0, rtol = _lorenz(), np.linspace(0.0, 40.0, 41), np.ones(3), 1e-6
    a = plain_run(model, x0, t, 1e-13, np.full(3, 1e-15), 10 ** 8)
    b = plain_run(model, x0 * (1 + 2.3e-16), t, 1e-13, np.full(3, 1e-15), 10 ** 8)
    assert np.max(np.abs(a.x - b.x) / (rtol / 100 + rtol * np.abs(a.x))) > 1.0
    got = dense_auto(_problem(model, x0, t), rtol, np.full(3, rtol / 100), 1e8, 1e6)
    assert got.result != 1
    assert not simulate(model, x0, t, rtol=rtol, atol=rtol / 100).success


def test_auto_work_barely_grows_with_the_grid():
    """``auto``'s steps for 12001 outputs are within 30% of those for 121 (the one pass
    there, dense output here): the grid-bound pass takes at least 3 steps per output
    interval, 36000 here."""
    model = rigid_body(INERTIA)
    steps = [simulate(model, X0, np.linspace(0.0, 60.0, n), rtol=1e-7, atol=1e-9).n_steps
             for n in (121, 12001)]
    assert steps[1] <= 1.3 * steps[0], steps


@pytest.mark.parametrize("n", [2, 121])
def test_a_sparse_grid_takes_the_dense_path(n):
    """Steps chosen by the error, never by the grid, on a sparse grid too (one compiled call,
    `dense.dense_auto`): the tolerance met against the Jacobi truth."""
    rtol, atol = 1e-7, 1e-9
    t = np.linspace(0.0, 60.0, n)
    res = simulate(rigid_body(INERTIA), X0, t, rtol=rtol, atol=atol)
    assert res.success and "dense output" in res.message, res.message
    w = torque_free_omega(INERTIA, X0[4:], t)
    assert np.all(np.abs(res.x[4:] - w) <= atol + rtol * np.abs(w))


def test_varying_control_keeps_the_grid_paths():
    """A control that changes on the grid is not stepped across (its kinks sit there)."""
    model = rigid_body(INERTIA)
    t = np.linspace(0.0, 10.0, 11)
    u = np.zeros((3, 11))
    u[0] = np.linspace(0.0, 0.1, 11)
    from appdyn.dynamics.integrate.dense import dense_auto
    varying = Problem.new(model, X0, t, check_u(u, 3, t), np.zeros(0))
    assert dense_auto(varying, 1e-8, np.full(7, 1e-10), 1e8, 1e6) is None
    res = simulate(model, X0, t, u=u)
    assert res.success and "dense output" not in res.message


@pytest.mark.parametrize("n", [2, 121])
def test_the_one_call_is_the_stepper_run_and_its_merged_steps(n):
    """`dense.dense_auto` (answer, check and verdict in one compiled call) makes the run
    `stepcontrol.plain_run` makes at the answer's local tolerance, equal to the last bit and
    with its steps; its check takes the answer's accepted steps merged in pairs (half of
    them, a lone last one alone); the Jacobi truth lies within the estimate."""
    from appdyn.dynamics.integrate.dense import FIRST, dense_auto
    model, t = rigid_body(INERTIA), np.linspace(0.0, 60.0, n)
    rtol, atol = 1e-8, np.full(7, 1e-10)
    got = dense_auto(_problem(model, X0, t), rtol, atol, 1e8, 1e6)
    assert got.result == 1 and got.factor <= FIRST and got.ratio == 2
    f = got.factor
    answer = plain_run(model, X0, t, rtol * f, atol * f, 10 ** 8)
    assert np.array_equal(got.x, answer.x)
    assert got.answer_steps == answer.n_steps
    assert got.check_steps == (got.answer_steps - got.rejected + 1) // 2
    assert got.spent >= answer.n_steps + got.check_steps
    w = torque_free_omega(INERTIA, X0[4:], t)
    assert np.all(np.abs(got.x[4:] - w) <= got.estimate * (1e-10 + rtol * np.abs(w)))


def _batch(K, seed=0):
    rng = np.random.default_rng(seed)
    w0 = np.array([0.5, 0.0, 1.0]) + rng.uniform(-0.4, 0.4, (K, 3))
    return np.c_[np.zeros((K, 3)), np.ones(K), w0].T


def test_a_batch_steps_each_run_by_its_own_error_and_verifies_it():
    """Batched ``auto`` (one compiled loop over the runs, `dense.dense_many`): each run is
    the single call's answer to the last bit (its own steps, its own check run), verified,
    and within the tolerance of its Jacobi truth."""
    model, t = rigid_body(INERTIA), np.linspace(0.0, 20.0, 41)
    x0 = _batch(12)
    res = simulate(model, x0, t)
    assert res.all_success and "dense output per run" in res.message, res.message
    steps = set()
    for k in range(x0.shape[1]):
        one = simulate(model, x0[:, k], t)
        assert np.array_equal(res.x[:, :, k], one.x)
        assert res.error_estimate[k] == one.error_estimate
        steps.add(one.n_steps)
        w = torque_free_omega(INERTIA, x0[4:, k], t)
        assert np.all(np.abs(res.x[4:, :, k] - w) <= 1e-10 + 1e-8 * np.abs(w))
    assert len(steps) > 1 and res.n_steps == max(steps)


def test_a_batch_run_not_verified_in_the_loop_goes_alone(monkeypatch):
    """A run whose check the compiled loop did not accept is run alone through every path of
    ``auto`` (here: its verdict forced to "not verified"): its answer is the single call's."""
    from appdyn.dynamics.integrate import batch as batch_module, dense
    real = batch_module.dense_many

    def forced(*args, **kw):
        X, head = real(*args, **kw)  # (``out``: the batch's arrays, rows ``runs`` filled)
        if 1 in np.asarray(args[-1]):
            head[1, dense.FIELDS.index("result")] = 0  # not verified
        return X, head

    monkeypatch.setattr(batch_module, "dense_many", forced)
    model, t = rigid_body(INERTIA), np.linspace(0.0, 10.0, 11)
    x0 = _batch(3, seed=1)
    res = simulate(model, x0, t)
    assert res.all_success and "1 run(s) alone" in res.message, res.message
    for k in range(3):
        assert np.array_equal(res.x[:, :, k], simulate(model, x0[:, k], t).x)


def test_later_rounds_of_a_batch_answer_first_at_the_factor_learned_before(monkeypatch):
    """A batch of 80 runs goes in two rounds (`batch.dense_rounds`): the first round's runs
    are their single calls to the last bit; the second round's runs are the single call
    with its first answer at the factor the first round's runs chose (`batch.first_factor`), each
    verified by its own check and within the tolerance of its Jacobi truth."""
    from appdyn.dynamics.integrate import batch as batch_module, dense
    seen = []
    real = batch_module.dense_many

    x0 = _batch(80, seed=3)
    index = {tuple(row): k for k, row in enumerate(x0.T)}  # (a call's runs by their x0)

    def spy(*args, factor=None, **kw):
        runs = [index[tuple(row)] for row in args[1][args[-1]]]
        seen.append((runs, factor))
        return real(*args, factor=factor, **kw)

    monkeypatch.setattr(batch_module, "dense_many", spy)
    model, t = rigid_body(INERTIA), np.linspace(0.0, 20.0, 41)
    res = simulate(model, x0, t, threads=1)
    assert res.all_success and "learned from the runs before" in res.message, res.message
    rounds = batch_module.dense_rounds(80)
    assert len(rounds) == 2
    assert sorted(k for runs, _ in seen for k in runs) == list(range(80))
    first = {k0 for k0, _ in rounds[0]}
    assert all(f == dense.FIRST for runs, f in seen if first & set(runs))
    assert all(f <= dense.FIRST for _, f in seen)  # (never looser than a single call's)
    w = np.stack([torque_free_omega(INERTIA, x0[4:, k], t) for k in range(80)], axis=2)
    assert np.all(np.abs(res.x[4:] - w) <= 1e-10 + 1e-8 * np.abs(w))
    for runs, factor in seen:
        monkeypatch.setattr(dense, "FIRST", factor)
        for k in (runs[0], runs[-1]):
            one = simulate(model, x0[:, k], t)
            assert np.array_equal(res.x[:, :, k], one.x)
            assert res.error_estimate[k] == one.error_estimate


def test_each_round_of_a_batch_draws_from_every_part_of_it():
    """`batch.dense_rounds`: the rounds cover every run once, in slices; the first takes
    the first `PILOT` runs of each sixteenth of the batch, so a batch sorted by a parameter
    (easy runs first) does not teach the second round the wrong tolerance."""
    from appdyn.dynamics.integrate.batch import PILOT, STRATA, dense_rounds
    for K in (64, 80, 1000, 1024, 5000):
        rounds = dense_rounds(K)
        assert len(rounds) == 2
        runs = [k for r in rounds for k0, k1 in r for k in range(k0, k1)]
        assert sorted(runs) == list(range(K))
        strata = np.array([K * i // STRATA for i in range(STRATA + 1)])
        part = lambda k: int(np.searchsorted(strata, k, side="right")) - 1
        assert sorted(part(k0) for k0, _ in rounds[0]) == list(range(STRATA))
        assert all(k1 - k0 == PILOT and part(k1 - 1) == part(k0) for k0, k1 in rounds[0])
    assert dense_rounds(2 * STRATA * PILOT - 1) == [((0, 2 * STRATA * PILOT - 1),)]


def test_first_factor_weighs_over_delivery_against_retries():
    """`batch.first_factor`: runs far inside their acceptance loosen the factor (at most
    `REACH` beyond where they were measured, never past a single call's `dense.FIRST`: the
    check's Richardson ratio is that call's), runs accepted only at a tighter
    factor bring it there (never below the local rtol floor), a lone chaotic run among regular ones retries alone
    (the factor is the regular runs'), while a tail of hard runs tightens it."""
    from appdyn.dynamics.integrate.batch import REACH, first_factor
    from appdyn.dynamics.integrate.stepcontrol import LOCAL_RTOL_MIN

    def choose(est, current=0.003, rtol=1e-8, at=None):
        m = len(est)
        at = [current] * m if at is None else np.broadcast_to(at, m)
        return first_factor(est, at, [150.0] * m, [0.5] * m, current=current, rtol=rtol)

    regular = list(np.geomspace(0.05, 0.3, 20))  # (estimates at 0.003: 170-1000 per unit)
    base = choose(regular)
    assert np.isclose(10.0 ** (np.arange(-8, 9) / 8.0), base / 0.003).any()  # (on the grid)
    assert 0.003 / REACH <= base <= 0.003 * REACH
    assert choose([1e-4] * 20, current=3e-4) == pytest.approx(3e-4 * REACH)  # (no further
    assert choose([1e-4] * 20, current=1e-5) == pytest.approx(1e-5 * REACH)  # than measured)
    assert choose([1e-4] * 20) == pytest.approx(0.003)  # (no looser than a single call's)
    assert choose([1e-4] * 20, current=0.5) == pytest.approx(0.003)
    # runs accepted only after retries, at 1e-5 with estimates 0.4: there, with a margin
    assert 0.3e-5 <= choose([0.4] * 20, at=1e-5) <= 1e-5
    assert choose([0.4] * 20, at=2e-5, rtol=1e-10) >= LOCAL_RTOL_MIN / 1e-10  # (the floor)
    # one chaotic run (accepted at 3e-6 after retries): it retries alone, the rest not tighter
    assert choose(regular + [0.3], at=[0.003] * 20 + [3e-6]) >= base
    assert choose(regular + [3.0] * 10) < base  # (a third of the runs 10x harder)
    nothing = [np.nan, 0.0, -1.0]
    assert first_factor(nothing, [0.003] * 3, [150.0] * 3, [0.5] * 3, current=0.003,
                        rtol=1e-8) == 0.003


def test_the_learned_factor_models_the_compiled_retry():
    """`batch.first_factor`'s model of a retry is the compiled one's (``AU_AIM``,
    ``AU_LADDER`` of `cpass`'s C)."""
    import re
    from pathlib import Path
    from appdyn.dynamics.integrate import batch, cpass
    source = Path(cpass.__file__).read_text()
    define = lambda name: float(re.search(rf"#define {name} ([0-9.e-]+)", source).group(1))
    assert (batch.RETRY_AIM, batch.RETRY_LADDER) == (define("AU_AIM"), define("AU_LADDER"))


def test_near_round_off_the_floor_is_measured_in_the_same_call():
    """rtol 1e-10 (atol 1e-12) on issue 31's body: within 1e6 ulps of the states, the carried
    rounding is not small against the quaternion's tolerance (1e-12 where a part crosses
    zero), so the answer is repeated with each step's rounding emulated at random in the
    same compiled call (its steps counted); the result meets the tolerance against the
    Jacobi truth."""
    from appdyn.dynamics.integrate.dense import dense_auto
    model, t = rigid_body(INERTIA), np.linspace(0.0, 60.0, 121)
    rtol, atol = 1e-10, 1e-12
    got = dense_auto(_problem(model, X0, t), rtol, np.full(7, atol), 1e8, 1e6)
    assert got.result == 1 and got.floor > 0 and got.bound == 0 and got.draws >= 1
    assert got.spent >= (1 + got.draws) * got.answer_steps + got.check_steps
    res = simulate(model, X0, t, rtol=rtol, atol=atol)
    assert res.success and "rounding floor" in res.message, res.message
    w = torque_free_omega(INERTIA, X0[4:], t)
    assert np.all(np.abs(res.x[4:] - w) <= atol + rtol * np.abs(w))


@pytest.mark.slow  # (a body of its own: its first compile)
def test_no_cliff_between_tolerances_near_the_rounding_floor():
    """A fast flat body on a dense grid (20 s, 2001 outputs) at rtol 1e-9 and 1e-10 (atol
    rtol/100, 4500 ulps of the quaternion's size at 1e-10): both verified on the dense path,
    the decade costing what the method's order says (steps ~ tol^(-1/8): 1.33x, a measured
    rounding floor included: at most 5x; it took 46x on the multi-run search before), each
    within its tolerance against Jacobi's closed form."""
    inertia, w0 = [10.0, 12.0, 21.0], [2.0, -1.0, 0.5]
    model, t = rigid_body(inertia), np.linspace(0.0, 20.0, 2001)
    x0, w = np.r_[0.0, 0.0, 0.0, 1.0, w0], torque_free_omega(inertia, w0, t)
    steps = {}
    for rtol in (1e-9, 1e-10):
        res = simulate(model, x0, t, rtol=rtol, atol=rtol / 100)
        assert res.success and "dense output" in res.message, res.message
        assert np.all(np.abs(res.x[4:] - w) <= rtol / 100 + rtol * np.abs(w))
        steps[rtol] = res.n_steps
    assert steps[1e-10] <= 5 * steps[1e-9], steps


def test_below_the_rounding_floor_answers_at_once_and_says_so():
    """rtol 1e-12, atol 1e-14 on issue 31's body: 1000 ulps of the quaternion's size (which
    crosses zero, where its tolerance is atol) are 22 tolerances, so no path of ``auto``
    can verify the answer: it comes at once from the dense path (one answer and its check,
    not the multi-run search: 3480 steps before), not called a success, with the floor and
    the remedy in its message; it is as good as double precision gives (rates within 1e-13
    of Jacobi's closed form)."""
    from appdyn.dynamics.integrate.result import ROUNDOFF
    model, t = rigid_body(INERTIA), np.linspace(0.0, 60.0, 121)
    loose = simulate(model, X0, t, rtol=1e-9, atol=1e-11)
    res = simulate(model, X0, t, rtol=1e-12, atol=1e-14)
    assert not res.success and res.status == ROUNDOFF
    assert "below the round-off floor" in res.message and "remedy" in res.message, res.message
    assert res.error_estimate > 1.0
    assert res.n_steps <= 2 * loose.n_steps, (res.n_steps, loose.n_steps)
    w = torque_free_omega(INERTIA, X0[4:], t)
    assert np.max(np.abs(res.x[4:] - w)) < 1e-13
    # the common call answers it from its one pass (it ran the pass again on the general
    # path): the same result as the general path (taken with a numpy int max_steps)
    general = simulate(model, X0, t, rtol=1e-12, atol=1e-14, max_steps=np.int64(10**6))
    assert (general.status, general.n_steps, general.message) == (res.status, res.n_steps,
                                                                  res.message)
    assert np.array_equal(general.x, res.x)


def test_a_retry_far_above_the_rounding_makes_no_floor_run():
    """The bench body near a separatrix (100 s) at rtol 1e-5: its first answer (at 0.003 of
    the tolerance) is refused and the retry, predicted from the estimate, lands about 30x
    tighter, 1e5 ulps above the states' size, where rounding is no part of the difference of
    the answer and its check (the floors measured there were 3e-6 of the tolerance): no
    floor rerun, two answers and their checks in all, verified and within the
    estimate of Jacobi's rates."""
    from appdyn.dynamics.integrate.dense import FIRST, dense_auto
    inertia, w0 = _JACOBI[1]
    model, t = rigid_body(inertia), np.linspace(0.0, 100.0, 101)
    x0, rtol, atol = np.r_[0.0, 0.0, 0.0, 1.0, w0], 1e-5, 1e-7
    got = dense_auto(_problem(model, x0, t), rtol, np.full(7, atol), 1e8, 1e6)
    assert got.result == 1 and got.factor < FIRST / 10 and got.floor == 0
    assert got.spent < 2 * (got.answer_steps + got.check_steps)
    w = torque_free_omega(inertia, w0, t)
    assert np.all(np.abs(got.x[4:] - w) <= got.estimate * (atol + rtol * np.abs(w)))


def test_header_inputs_are_the_first_slots():
    """`dense._fill` writes the header's inputs in one `struct` call in this order: the
    C code's ``AU_*`` slots (`dense.FIELDS`) must start with them."""
    from appdyn.dynamics.integrate.dense import FIELDS
    assert FIELDS[:9] == ("rtol", "factor", "loose", "max_steps", "stiff_steps", "t0", "iq",
                          "tries", "phase")


def _wheels():
    from appdyn.dynamics import wheel_spacecraft

    hub = np.array([[10.0, 0.2, -0.1], [0.2, 12.0, 0.3], [-0.1, 0.3, 8.0]])
    model = wheel_spacecraft(hub, np.c_[np.eye(3), np.ones(3) / np.sqrt(3.0)], 0.05)
    return model, np.r_[0.0, 0.0, 0.0, 1.0, 0.3, -0.2, 0.4, 100.0, -50.0, 80.0, 30.0]


def _hinged():
    from appdyn.dynamics import hinged_bodies

    model = hinged_bodies(2.0, [1.0, 1.2, 0.8], 3.0, [0.9, 1.1, 1.3], [0, 0, 0.5], [0, 0, -0.5])
    return model, model.initial_state([0, 0, 0, 1], [0.1, 0, 0.2], [1.0, 0, 0], [0, 0, 0, 1],
                                      [0.1, 0, 0.2])


@pytest.mark.parametrize("which", ["rigid", "wheels", "hinged"])
def test_the_compiled_steps_are_the_casadi_kernels(which):
    """Every step form of the compiled pass (`cpass._PROBE`) equals the casadi kernel it
    stands for, evaluated by casadi: generated C for a small model (the rigid body), C
    loops around one generated right-hand side for a large one (`csteps`: the wheel
    spacecraft with a control linear over the step, the hinged bodies)."""
    import ctypes

    from appdyn.dynamics.integrate.cpass import pass_library
    from appdyn.dynamics.integrate.kernels import calls_rhs

    if which == "rigid":
        model, x0 = rigid_body([1.5, 2.5, 3.2]), np.r_[0.1, -0.2, 0.3, 0.9, 0.5, 0.1, 1.0]
        x0[:4] /= np.linalg.norm(x0[:4])
    else:
        model, x0 = _wheels() if which == "wheels" else _hinged()
    assert calls_rhs(model, "rk8") == (which != "rigid")
    lib = pass_library(model)
    if lib is None:
        pytest.skip("no C compiler")
    nx, nu = model.nx, model.nu
    rng = np.random.default_rng(7)
    ua, ud = rng.normal(size=nu), rng.normal(size=nu)
    p, atol, h, rtol = np.zeros(model.f.numel_in(2)), np.full(nx, 1e-10), 0.3, 1e-8
    out = np.zeros(22 * nx + 2)
    x0, ua, ud, p, atol = (np.ascontiguousarray(a, float) for a in (x0, ua, ud, p, atol))
    ptr = [a.ctypes.data_as(ctypes.c_void_p) for a in (x0, ua, ud, p, atol, out)]
    assert lib.probe(ptr[0], h, ptr[1], ptr[2], ptr[3], rtol, ptr[4], ptr[5]) == 0
    plain, xe, e, xk, ek = out[:nx], out[nx:2 * nx], out[2 * nx], out[2 * nx + 1:3 * nx + 1], \
        out[3 * nx + 1]
    K, F = out[3 * nx + 2:15 * nx + 2], out[15 * nx + 2:]

    def close(got, want, tol=1e-14):
        want = np.ravel(np.asarray(want, float))
        assert np.allclose(got, want, rtol=tol, atol=tol * max(1.0, np.abs(want).max()))

    close(plain, kernel(model, "rk8", "linear")(x0, h, ua, ud, p))
    xw, ew = kernel(model, "rk8", "linear", error=True)(x0, h, ua, ud, p, rtol, atol)
    close(xe, xw)
    close(e, ew, 1e-12)
    step, cont = dense_kernels(model)
    xw, ew, Kw = step(x0, h, ua, p, rtol, atol)
    close(xk, xw)
    close(ek, ew, 1e-12)
    close(K, Kw)
    close(F, cont(x0, xw, Kw, h, ua, p), 1e-13)
    if nu:  # (the control's slope is taken in the one, not in the other)
        assert not np.allclose(xe, xk, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("size", [512, 64])
def test_the_passs_chunk_is_the_casadi_chunk(size):
    """The fixed-step rk8 chunk that the compiled pass runs for a model whose right-hand
    side is called (`cpass.pass_chunk`, C loops) equals the casadi chunk it stands for
    (`chunks.build_chunk`, evaluated by casadi): the first ``n`` steps of a control linear
    over each step, then the state after step ``n`` repeated."""
    from appdyn.dynamics.integrate.chunks import build_chunk
    from appdyn.dynamics.integrate.cpass import pass_chunk

    model, x0 = _wheels()
    fast = pass_chunk(model, size)
    if fast is None:
        pytest.skip("no C compiler")
    assert pass_chunk(rigid_body([1.0, 2.0, 3.0]), size) is None  # (inlined: casadi's chunk)
    rng = np.random.default_rng(3)
    n = size - 5
    h = 0.01 + 0.02 * rng.random((1, size))
    ua, ud = rng.normal(size=(model.nu, size)), rng.normal(size=(model.nu, size))
    p = np.zeros(model.np)
    got = np.asarray(fast(x0, n, h, ua, ud, p))
    want = np.asarray(build_chunk(model, "rk8", "linear", size=size)(x0, n, h, ua, ud, p))
    assert got.shape == want.shape == (model.nx, size)
    assert np.allclose(got, want, rtol=1e-13, atol=1e-11)
    assert np.array_equal(got[:, n:], np.repeat(got[:, n - 1:n], size - n, axis=1))


def test_the_passs_chunk_with_the_disk_cache_off():
    """With the persistent cache off the pass's library file is gone once loaded: its
    chunk still runs (the loaded library, by its path), as with the cache on."""
    from appdyn.dynamics import clear_caches, diskcache

    model, x0 = _wheels()
    t = np.linspace(0.0, 5.0, 6)
    want = simulate(model, x0, t, method="rk8", steps=20)
    old = diskcache.configure(enabled=False)
    try:
        clear_caches()
        got = simulate(model, x0, t, method="rk8", steps=20)
    finally:
        diskcache.configure(**old)
        clear_caches()
    assert want.success and got.success and got.compiled
    assert np.allclose(got.x, want.x, rtol=1e-13, atol=1e-12)


@pytest.mark.parametrize("lanes", [False, True], ids=["reruns after the answer",
                                                     "draws in the answer's lanes"])
def test_the_floor_draws_are_keyed_by_the_step_so_a_run_cut_anywhere_agrees(lanes,
                                                                           monkeypatch):
    """The floor's draws round each accepted state at random from a stream keyed by the
    run's step count: the bench body at rtol 1.5e-10 (a retried answer, two draws: the
    first leaves the verdict open) gives the same answer, floor and steps whether its call
    runs whole or is cut every 97 steps (as Ctrl-C checks cut it), and again on a second
    call; made after the answer by the step function, or alongside it in the free lanes of
    its vector steps (the draws' states kept between cut calls), the same bits. Truth:
    Jacobi's rates within the tolerance."""
    from appdyn.dynamics.integrate import dense
    inertia, w0 = _JACOBI[1]
    model, t = rigid_body(inertia), np.linspace(0.0, 100.0, 101)
    x0 = np.r_[0.0, 0.0, 0.0, 1.0, w0]
    vector = dense.dense_lanes(model, wait=True) if lanes else None
    assert vector is not None or not lanes
    monkeypatch.setattr(dense, "_single_lanes", lambda m, plan: vector)
    run = lambda: dense.dense_run(model, x0, t, 1.5e-10, 1.5e-12, 1e8, 1e6)
    whole = run()
    assert whole.result == 1 and whole.draws == 2 and whole.floor > 0 \
        and whole.factor < dense.FIRST
    plan = dense.pass_plan(model)  # (where the draws ran: alongside the retried answer or not)
    assert (dense._workspace(plan, t.size - 1).ws[dense._alongside(plan, t.size - 1)] == 2) \
        == lanes
    again = run()
    assert (again.floor, again.spent, again.draws) == (whole.floor, whole.spent, whole.draws)
    saved = dense._LOCAL.__dict__.pop("work", None)
    budget, dense.BUDGET = dense.BUDGET, 97
    try:
        cut = run()
    finally:
        dense.BUDGET = budget
        dense._LOCAL.__dict__.pop("work", None)
        if saved is not None:
            dense._LOCAL.work = saved
    assert np.array_equal(cut.x, whole.x)
    assert (cut.floor, cut.spent, cut.draws) == (whole.floor, whole.spent, whole.draws)
    monkeypatch.setattr(dense, "_single_lanes", lambda m, plan: None)
    alone = run()
    assert np.array_equal(alone.x, whole.x)
    assert (alone.floor, alone.spent, alone.draws, alone.estimate) == \
        (whole.floor, whole.spent, whole.draws, whole.estimate)
    w = torque_free_omega(inertia, w0, t)
    assert np.all(np.abs(whole.x[4:] - w) <= 1.5e-12 + 1.5e-10 * np.abs(w))


def test_max_steps_ends_the_draws_beside_the_answer_as_after_it(monkeypatch):
    """``max_steps`` reached in the second draw, in the first, before the first takes a
    step (the retried answer and its check used them all) or in the answer itself: the
    draws made beside the answer (the vector lanes) give the outcome, steps and answer of
    the reruns after it (the step function), to the bit; a floor cut short verifies
    nothing."""
    from appdyn.dynamics.integrate import dense
    inertia, w0 = _JACOBI[1]
    model, t = rigid_body(inertia), np.linspace(0.0, 100.0, 101)
    x0 = np.r_[0.0, 0.0, 0.0, 1.0, w0]
    vector = dense.dense_lanes(model, wait=True)
    assert vector is not None

    def run(lanes, most):
        monkeypatch.setattr(dense, "_single_lanes", lambda m, plan: vector if lanes else None)
        return dense.dense_run(model, x0, t, 1.5e-10, 1.5e-12, float(most), 1e6)

    full = run(True, 1e8)
    assert full.result == 1 and full.draws == 2
    answered = full.spent - 2 * (full.answer_steps)  # (before the draws, about)
    for most in (full.spent - 1, full.spent - full.answer_steps - 100, answered - 300,
                 answered - 700):
        beside, after = run(True, most), run(False, most)
        np.testing.assert_array_equal(beside.x, after.x)
        assert beside[1:] == after[1:], (most, beside, after)
        assert beside.result in (0, -3) and beside.spent <= most + 1 + full.check_steps


def test_a_first_floor_draw_that_refuses_makes_no_second():
    """A tumble 1e-3 rad/s off the separatrix (100 s, rtol 1e-8): the flow amplifies the
    rounding past the tolerance, so the first draw refuses the answer (a second could only
    raise the floor) and none is made; the refusal is right: the answer is more than a
    tolerance from Jacobi's rates."""
    from appdyn.dynamics.integrate.dense import dense_run
    inertia, w0 = [1.0, 2.0, 3.0], [1e-3, 1.0, 1e-3]
    model, t = rigid_body(inertia), np.linspace(0.0, 100.0, 201)
    got = dense_run(model, np.r_[0.0, 0.0, 0.0, 1.0, w0], t, 1e-8, 1e-10, 1e8, 1e6)
    assert got.result == 0 and got.draws == 1 and got.floor > 1.0, got
    w = torque_free_omega(inertia, w0, t)
    assert np.max(np.abs(got.x[4:] - w) / (1e-10 + 1e-8 * np.abs(w))) > 1.0
