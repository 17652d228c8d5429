"""`simulate` against independent truths: matrix exponentials, scipy's DOP853 at 1e-12, the
Jacobi-elliptic torque-free solution, conservation laws, and measured convergence orders."""
import functools
import math
import shutil

import casadi as ca
import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.linalg import expm

from appdyn.dynamics import METHODS, Model, SimulationResult, rigid_body, simulate
from appdyn.dynamics.attitude import dcm_from_quat, quat_kinematics_matrix, quat_rate
from appdyn.dynamics.truth import axisymmetric, torque_free_omega

HAVE_CC = shutil.which("gcc") is not None or shutil.which("cc") is not None

# A lightly damped oscillator with a second, slower mode (3 states, 2 inputs).
A3 = np.array([[0.0, 1.0, 0.0], [-4.0, -0.4, 0.3], [0.0, -0.2, -0.5]])
B3 = np.array([[0.0, 0.2], [1.0, 0.0], [0.0, 1.0]])
X3 = np.array([1.0, -0.5, 0.25])


@functools.lru_cache(maxsize=None)
def linear_model(nu: int = 2) -> Model:
    """xdot = A x + B u (a stand-in model built here, independent of the library's models)."""
    x, u, p = ca.SX.sym("x", 3), ca.SX.sym("u", nu), ca.SX.sym("p", 0)
    xdot = ca.mtimes(ca.DM(A3), x) + (ca.mtimes(ca.DM(B3[:, :nu]), u) if nu else 0)
    f = ca.Function("linear", [x, u, p], [xdot], ["x", "u", "p"], ["xdot"])
    return Model(f=f, states=("a", "b", "c"), controls=("u1", "u2")[:nu], name="linear")


@functools.lru_cache(maxsize=None)
def blow_up_model() -> Model:
    """xdot = x^2: x(t) = x0 / (1 - x0 t), infinite at t = 1/x0."""
    x, u, p = ca.SX.sym("x", 1), ca.SX.sym("u", 0), ca.SX.sym("p", 0)
    f = ca.Function("blow_up", [x, u, p], [x**2], ["x", "u", "p"], ["xdot"])
    return Model(f=f, states=("x",), controls=(), name="blow_up")


@functools.lru_cache(maxsize=None)
def gravity_gradient_model() -> Model:
    """Rigid body with a gravity-gradient torque 3 n^2 c x (I c), c = A(q) e3: the rates
    depend on the attitude, so a Lie method's quaternion and rate errors are coupled."""
    inertia = np.diag([1.0, 2.0, 3.0])
    n2 = 0.8
    x, u, p = ca.SX.sym("x", 7), ca.SX.sym("u", 0), ca.SX.sym("p", 0)
    q, w = x[:4], x[4:]
    c = ca.mtimes(dcm_from_quat(q), ca.DM([0.0, 0.0, 1.0]))
    torque = 3 * n2 * ca.cross(c, ca.mtimes(ca.DM(inertia), c))
    wdot = ca.solve(ca.DM(inertia), torque - ca.cross(w, ca.mtimes(ca.DM(inertia), w)))
    f = ca.Function("gg", [x, u, p], [ca.vertcat(quat_rate(q, w), wdot)], ["x", "u", "p"], ["xdot"])
    return Model(f=f, states=("q1", "q2", "q3", "q4", "w1", "w2", "w3"), controls=(),
                 name="gravity_gradient", attitude=(0, 4))


@functools.lru_cache(maxsize=None)
def oscillator_with_attitude() -> Model:
    """x = [q, w, y1, y2]: constant body rate (wdot = 0) and an undamped oscillator y.
    Linear truth: q(t) = expm(-1/2 Wbar(w) t) q0, y(t) = expm(A t) y0."""
    x, u, p = ca.SX.sym("x", 9), ca.SX.sym("u", 0), ca.SX.sym("p", 0)
    q, w, y = x[:4], x[4:7], x[7:]
    xdot = ca.vertcat(quat_rate(q, w), ca.DM.zeros(3), y[1], -9.0 * y[0])
    f = ca.Function("osc_att", [x, u, p], [xdot], ["x", "u", "p"], ["xdot"])
    return Model(f=f, states=("q1", "q2", "q3", "q4", "w1", "w2", "w3", "y1", "y2"), controls=(),
                 name="oscillator_with_attitude", attitude=(0, 4))


def unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def expm_truth(t, x0=X3):
    return np.stack([expm(A3 * ti) @ x0 for ti in t], axis=1)


def reference_ivp(fun, x0, t):
    """scipy DOP853 at rtol 1e-12, restarted on every grid interval (exact at the kinks)."""
    out, x = [np.asarray(x0, float)], np.asarray(x0, float)
    for a, b in zip(t[:-1], t[1:]):
        sol = solve_ivp(fun, (a, b), x, method="DOP853", rtol=1e-12, atol=1e-14)
        x = sol.y[:, -1]
        out.append(x)
    return np.stack(out, axis=1)


def scaled_error(x, truth, rtol, atol):
    return float(np.max(np.abs(x - truth) / (atol + rtol * np.abs(truth))))


# ------------------------------------------------------------------------ linear truths
@pytest.mark.parametrize("method, kwargs, tol", [
    ("rk4", {"steps": 40}, 1e-7),
    ("rk8", {"steps": 4}, 1e-10),
    ("cvodes", {"rtol": 1e-11, "atol": 1e-13}, 1e-8),
    ("auto", {"rtol": 1e-10, "atol": 1e-12}, 1e-10),
])
def test_linear_system_matches_matrix_exponential(method, kwargs, tol):
    t = np.linspace(0.0, 10.0, 21)
    res = simulate(linear_model(0), X3, t, method=method, jit=False, **kwargs)
    assert res.success and res.status in (0, 1), res.message
    assert res.x.shape == (3, 21) and res.t.shape == (21,)
    np.testing.assert_array_equal(res.x[:, 0], X3)
    assert np.max(np.abs(res.x - expm_truth(t))) < tol


@pytest.mark.slow
def test_lie_matches_matrix_exponential():
    """Constant rate: the quaternion part of the Lie method is exact; y is RK4."""
    model = oscillator_with_attitude()
    q0, w = unit([0.3, -0.2, 0.4, 0.8]), np.array([0.7, -1.1, 0.4])
    x0 = np.concatenate([q0, w, [1.0, 0.0]])
    t = np.linspace(0.0, 20.0, 41)
    res = simulate(model, x0, t, method="lie", steps=100, jit=False)
    Omega = -0.5 * quat_kinematics_matrix(w)
    q_true = np.stack([expm(Omega * ti) @ q0 for ti in t], axis=1)
    Ay = np.array([[0.0, 1.0], [-9.0, 0.0]])
    y_true = np.stack([expm(Ay * ti) @ x0[7:] for ti in t], axis=1)
    assert np.max(np.abs(res.x[:4] - q_true)) < 1e-12  # round-off of 2000 exact rotations
    assert np.max(np.abs(res.x[4:7] - w[:, None])) == 0.0
    assert np.max(np.abs(res.x[7:] - y_true)) < 1e-7


# --------------------------------------------------------------- forced linear system
def u_const():
    return np.array([0.3, -0.7])


def u_fun(t):
    return np.array([np.sin(3.0 * t), np.cos(t) ** 2])


T_FORCED = np.linspace(0.0, 6.0, 13)
U_SAMPLES = np.stack([np.sin(2.0 * T_FORCED), 0.5 - T_FORCED / 6.0])


def u_interpolated(t):
    return np.array([np.interp(t, T_FORCED, U_SAMPLES[i]) for i in range(2)])


def forced_reference(kind):
    ufun = {"constant": lambda t: u_const(), "array": u_interpolated, "callable": u_fun}[kind]
    return reference_ivp(lambda t, x: A3 @ x + B3 @ ufun(t), X3, T_FORCED)


def forced_u(kind):
    return {"constant": u_const(), "array": U_SAMPLES, "callable": u_fun}[kind]


@pytest.mark.parametrize("kind", ["constant", "array", "callable"])
@pytest.mark.parametrize("method, kwargs, tol", [
    ("rk4", {"steps": 40}, 1e-7),
    ("rk8", {"steps": 6}, 1e-11),
    ("cvodes", {"rtol": 1e-11, "atol": 1e-13}, 1e-8),
    ("auto", {"rtol": 1e-10, "atol": 1e-12}, 1e-10),
])
def test_forced_linear_system_matches_dop853(kind, method, kwargs, tol):
    res = simulate(linear_model(2), X3, T_FORCED, u=forced_u(kind), method=method, jit=False,
                   **kwargs)
    assert res.success, res.message
    err = np.max(np.abs(res.x - forced_reference(kind)))
    assert err < tol, f"{method} with {kind} u: error {err:.2e}"


def test_control_shapes_are_equivalent():
    """A constant, its samples on t and a constant callable give the same trajectory."""
    t = np.linspace(0.0, 2.0, 5)
    runs = [simulate(linear_model(2), X3, t, u=u, method="rk8", steps=3, jit=False).x
            for u in (u_const(), np.repeat(u_const()[:, None], 5, axis=1), lambda s: u_const())]
    np.testing.assert_allclose(runs[1], runs[0], rtol=0, atol=1e-15)
    np.testing.assert_allclose(runs[2], runs[0], rtol=0, atol=1e-15)


# ------------------------------------------------------------------ convergence orders
def observed_orders(model, x0, t, method, steps, truth, rows=slice(None)):
    errs = np.array([
        np.max(np.abs(simulate(model, x0, t, method=method, steps=s, jit=False).x[rows]
                      - truth[rows]))
        for s in steps
    ])
    return np.log2(errs[:-1] / errs[1:]), errs


def test_rk4_is_fourth_order():
    t = np.linspace(0.0, 10.0, 11)
    orders, _ = observed_orders(linear_model(0), X3, t, "rk4", [4, 8, 16], expm_truth(t))
    assert np.all(np.abs(orders - 4) < 0.15), orders


def test_rk8_is_eighth_order():
    t = np.linspace(0.0, 10.0, 11)
    orders, errs = observed_orders(linear_model(0), X3, t, "rk8", [1, 2, 4], expm_truth(t))
    assert errs[-1] > 1e-13  # still above round-off
    assert np.all(np.abs(orders - 8) < 0.5), orders


def test_lie_is_at_least_fourth_order_with_attitude_dependent_torque():
    model = gravity_gradient_model()
    x0 = np.concatenate([unit([0.1, 0.2, 0.3, 0.9]), [0.3, 1.5, 0.2]])
    t = np.linspace(0.0, 10.0, 11)
    truth = simulate(model, x0, t, method="rk8", steps=200, jit=False).x
    for rows in (slice(0, 4), slice(4, 7)):
        orders, _ = observed_orders(model, x0, t, "lie", [5, 10, 20, 40], truth, rows)
        assert np.all(orders > 3.85), orders


def test_dop853_weights_satisfy_quadrature_order_conditions():
    from appdyn.dynamics.integrate.tableaux import DOP853 as tab  # the copied coefficients, checked

    b, c = np.array(tab.b), np.array(tab.c)
    for k in range(8):
        assert b @ c**k == pytest.approx(1.0 / (k + 1), abs=1e-14)
    for i, row in enumerate(tab.a):
        assert sum(row) == pytest.approx(c[i], abs=1e-14)


# ------------------------------------------------------------------------- rigid body
INERTIA = np.array([1.0, 2.0, 3.0])
W0 = np.array([0.3, 1.0, 0.2])
Q0 = unit([0.1, -0.3, 0.2, 0.9])


def test_torque_free_body_matches_jacobi_elliptic_truth():
    model = rigid_body(INERTIA)
    t = np.linspace(0.0, 100.0, 201)
    res = simulate(model, np.concatenate([Q0, W0]), t, rtol=1e-12, invariants=True)
    assert res.success and res.method == "rk8", res.message
    assert np.max(np.abs(res.x[4:] - torque_free_omega(INERTIA, W0, t))) < 1e-9
    energy, momentum = res.invariants["energy"], res.invariants["momentum_inertial"]
    assert energy.shape == (201,) and momentum.shape == (3, 201)
    assert np.max(np.abs(energy / energy[0] - 1)) < 1e-11
    assert np.max(np.abs(momentum - momentum[:, :1])) < 1e-10 * np.linalg.norm(momentum[:, 0])


AXI_INERTIA, AXI_W0 = np.array([2.0, 2.0, 3.5]), np.array([0.4, -0.3, 1.2])


def axisymmetric_run(rtol, atol, t=np.linspace(0.0, 60.0, 61)):
    res = simulate(rigid_body(AXI_INERTIA), np.concatenate([Q0, AXI_W0]), t, rtol=rtol, atol=atol)
    w_true, q_true = axisymmetric(AXI_INERTIA, AXI_W0, Q0, t)
    return res, scaled_error(res.x, np.concatenate([q_true, w_true]), rtol, atol)


@pytest.mark.parametrize("rtol", [1e-5, 1e-8, 1e-10])
@pytest.mark.slow
def test_auto_meets_the_requested_tolerance(rtol):
    """Measured error against the closed form (axisymmetric body: rates AND attitude).

    The promise is |error| <= atol + rtol |x| at every output time, with the error
    estimated globally (Richardson), not per step. Measured (atol = rtol / 100): the worst
    ratio error / tolerance was 1.6e-3, 2.6e-2 and 6.1e-2 for rtol 1e-5, 1e-8, 1e-10; the
    estimate is conservative (reported 1.7e-3, 2.9e-2, 0.14)."""
    res, ratio = axisymmetric_run(rtol, rtol / 100)
    assert res.success and res.status == 0 and res.method == "rk8", res.message
    assert ratio <= 1.0, f"measured error is {ratio:.2f} x the tolerance"
    assert ratio <= res.error_estimate <= 1.0


def test_auto_reports_a_tolerance_below_round_off():
    """rtol = 1e-13: no double-precision fixed-step run can promise that; the result says so
    (status 2, error_estimate > 1, success False: nothing was verified) and still returns
    the best solution found."""
    res, ratio = axisymmetric_run(1e-13, 1e-15)
    assert not res.success and res.status == 2 and "round-off" in res.message
    assert res.error_estimate > 1.0 and ratio < 1e3


def rigid_body_numpy(inertia, torque):
    """Euler's equations and Eq. 4.70 in plain numpy, for the scipy reference."""
    def rhs(t, x):
        q, w = x[:4], x[4:]
        qdot = 0.5 * np.array([q[3] * w[0] + q[1] * w[2] - q[2] * w[1],
                               q[3] * w[1] + q[2] * w[0] - q[0] * w[2],
                               q[3] * w[2] + q[0] * w[1] - q[1] * w[0],
                               -(q[:3] @ w)])
        return np.concatenate([qdot, (torque(t) - np.cross(w, inertia * w)) / inertia])
    return rhs


@pytest.mark.parametrize("kind", ["array", "callable"])
def test_lie_with_torque_matches_dop853(kind):
    def torque(t):
        return np.array([0.1 * np.sin(t), 0.2, -0.1 * np.cos(2.0 * t)])

    t = np.linspace(0.0, 10.0, 21)
    samples = np.stack([torque(ti) for ti in t], axis=1)
    u = samples if kind == "array" else torque
    ufun = (lambda s: np.array([np.interp(s, t, samples[i]) for i in range(3)])) \
        if kind == "array" else torque
    x0 = np.concatenate([Q0, W0])
    truth = reference_ivp(rigid_body_numpy(INERTIA, ufun), x0, t)
    res = simulate(rigid_body(INERTIA), x0, t, u=u, method="lie", steps=50, jit=False)
    assert np.max(np.abs(res.x - truth)) < 1e-8
    assert np.max(np.abs(np.linalg.norm(res.x[:4], axis=0) - 1)) < 1e-14


def test_energy_and_momentum_conserved_by_fixed_step_methods():
    model = rigid_body(INERTIA)
    t = np.linspace(0.0, 50.0, 51)
    for method, steps in (("rk8", 10), ("lie", 100)):
        res = simulate(model, np.concatenate([Q0, W0]), t, method=method, steps=steps, jit=False,
                       invariants=["energy", "momentum_inertial"])
        energy, momentum = res.invariants["energy"], res.invariants["momentum_inertial"]
        assert np.max(np.abs(energy / energy[0] - 1)) < 1e-8, method
        assert np.max(np.abs(momentum - momentum[:, :1])) < 1e-7, method
        assert set(res.invariants) == {"energy", "momentum_inertial"}


def test_lie_keeps_unit_quaternion_over_a_long_run():
    model = rigid_body(INERTIA)
    t = np.linspace(0.0, 2000.0, 201)  # 20 000 steps of 0.1 s
    x0 = np.concatenate([Q0, [1.5, -2.0, 2.5]])
    lie = simulate(model, x0, t, method="lie", steps=100, invariants=["quat_norm"])
    rk4 = simulate(model, x0, t, method="rk4", steps=100, invariants=["quat_norm"])
    assert np.max(np.abs(lie.invariants["quat_norm"] - 1)) < 1e-13
    assert np.max(np.abs(rk4.invariants["quat_norm"] - 1)) > 1e-9  # what the Lie method avoids


# ----------------------------------------------------------------------------- failures
def test_cvodes_failure_is_reported_not_raised():
    t = np.linspace(0.0, 2.0, 21)
    res = simulate(blow_up_model(), [1.0], t, method="cvodes")
    assert not res.success and res.status == -1
    assert "cvodes" in res.message
    before = t < 0.95
    np.testing.assert_allclose(res.x[0, before], 1 / (1 - t[before]), rtol=1e-4)
    assert np.all(np.isnan(res.x[0, t > 1.0]))


def test_cvodes_failure_names_its_flag_what_it_means_and_a_remedy():
    """A right-hand side that turns NaN past x = 0.5 (x' = 1: at t = 0.5) makes CVODES give
    up with CV_REPTD_RHSFUNC_ERR; the blow-up of x' = x^2 from 1 (at t = 1) with
    CV_TOO_MUCH_WORK. The message says where, which flag, what it means and what to do."""
    x = ca.SX.sym("x")
    domain = Model.from_expressions({"x": x}, {"x": ca.if_else(x > 0.5, np.nan, 1.0)})
    res = simulate(domain, [0.0], np.linspace(0.0, 1.0, 11), method="cvodes")
    assert not res.success and res.status == -1
    assert "cvodes failed near t = 0.5: CV_REPTD_RHSFUNC_ERR: the right-hand side returned " \
        "NaN or inf there" in res.message and "method='dop853' or 'auto'" in res.message
    assert "Consult CVODES documentation" not in res.message
    res = simulate(blow_up_model(), [1.0], np.linspace(0.0, 2.0, 21), method="cvodes")
    assert "CV_TOO_MUCH_WORK: more than max_num_steps" in res.message, res.message
    assert "max_num_steps': ...}" in res.message


@pytest.mark.parametrize("method", ["rk4", "rk8", "auto"])
def test_other_methods_report_blow_up(method):
    kwargs = {"steps": 2} if method != "auto" else {"max_steps": 2000}
    res = simulate(blow_up_model(), [1.0], np.linspace(0.0, 2.0, 21), method=method, jit=False,
                   **kwargs)
    assert not res.success and res.status == -1, res.message
    assert isinstance(res, SimulationResult)


def test_auto_says_when_max_steps_is_too_small_and_never_falls_back():
    """No silent switch to cvodes: the step budget is reported as an unverified result."""
    res = simulate(linear_model(0), X3, np.linspace(0.0, 100.0, 3), rtol=1e-10, max_steps=50,
                   jit=False)
    assert not res.success and res.status == 3 and res.method == "rk8", res.message
    assert "max_steps = 50" in res.message and "not verified" in res.message


@functools.lru_cache(maxsize=None)
def stiff_model(lam=1e8) -> Model:
    """xdot = -lam (x - cos t), with t carried as a second state."""
    x, u, p = ca.SX.sym("x", 2), ca.SX.sym("u", 0), ca.SX.sym("p", 0)
    f = ca.Function("stiff", [x, u, p], [ca.vertcat(-lam * (x[0] - ca.cos(x[1])), 1.0)],
                    ["x", "u", "p"], ["xdot"])
    return Model(f=f, states=("x", "t"), controls=(), name="stiff")


def test_auto_sends_a_stiff_problem_to_cvodes():
    """Off the slow manifold the Lipschitz estimate is ~lam, so auto goes to cvodes at once."""
    lam, t = 1e8, np.linspace(0.0, 1.0, 11)
    res = simulate(stiff_model(lam), [2.0, 0.0], t, rtol=1e-8, atol=1e-10)
    assert res.success and res.status == 1 and res.method == "cvodes", res.message
    assert "stiff" in res.message and res.substeps == 0
    c = 2.0 - lam**2 / (lam**2 + 1)
    exact = (lam**2 * np.cos(t) + lam * np.sin(t)) / (lam**2 + 1) + c * np.exp(-lam * t)
    assert np.max(np.abs(res.x[0] - exact)) < 1e-7


# ----------------------------------------------------------------- results and caching
@pytest.mark.slow
def test_sample_is_hermite_dense_output():
    t = np.linspace(0.0, 10.0, 401)
    res = simulate(linear_model(0), X3, t, method="rk8", steps=1, jit=False)
    np.testing.assert_allclose(res.sample(t), res.x, rtol=0, atol=1e-15)
    tq = np.linspace(0.0, 10.0, 777)
    assert np.max(np.abs(res.sample(tq) - expm_truth(tq))) < 1e-7  # O(dt^4), dt = 0.025
    assert res.sample(2.5).shape == (3,)
    with pytest.raises(ValueError, match="`t`"):
        res.sample(10.5)


def test_result_attributes():
    res = simulate(linear_model(0), X3, [0.0, 1.0, 2.0], method="rk4", steps=3, jit=False)
    assert (res.n_steps, res.n_rhs, res.substeps, res.method) == (6, 24, 3, "rk4")
    assert res.wall_time > 0 and res.invariants == {} and math.isnan(res.error_estimate)
    assert not res.x.flags.writeable
    assert "rk4" in res.message


@pytest.mark.skipif(not HAVE_CC, reason="no C compiler for the jit")
def test_compiled_loop_is_cached_and_fast():
    model = rigid_body(INERTIA)
    x0, t = np.concatenate([Q0, W0]), np.linspace(0.0, 100.0, 101)
    first = simulate(model, x0, t, method="rk8", steps=5)
    second = simulate(model, x0, t, method="rk8", steps=5)
    interpreted = simulate(model, x0, t, method="rk8", steps=5, jit=False)
    assert first.compiled and second.compiled and not interpreted.compiled
    assert second.wall_time < 0.05
    np.testing.assert_allclose(second.x, interpreted.x, rtol=0, atol=1e-13)


def test_non_uniform_grid():
    t = np.array([0.0, 0.01, 0.5, 0.51, 3.0, 7.5])
    res = simulate(linear_model(0), X3, t, method="rk8", steps=50, jit=False)
    assert np.max(np.abs(res.x - expm_truth(t))) < 1e-11


# --------------------------------------------------------------------------- bad input
GOOD = dict(x0=X3, t=np.linspace(0.0, 1.0, 5))


@pytest.mark.parametrize("kwargs, name", [
    ({"x0": [1.0, np.nan, 0.0]}, "x0"),
    ({"x0": [1.0, 2.0]}, "x0"),
    ({"x0": np.ones((2, 3))}, "x0"),  # (3, K) is a batch; (2, 3) fits neither
    ({"t": [0.0]}, "t"),
    ({"t": [0.0, 1.0, 1.0]}, "t"),
    ({"t": [1.0, 0.0]}, "t"),
    ({"t": [0.0, np.inf]}, "t"),
    ({"t": np.ones((2, 2))}, "t"),
    ({"method": "rk45"}, "method"),
    ({"rtol": -1.0}, "rtol"),
    ({"rtol": 0.0}, "rtol"),
    ({"rtol": 1e-17}, "rtol"),
    ({"rtol": np.nan}, "rtol"),
    ({"atol": -1e-3}, "atol"),
    ({"atol": [1e-3, 1e-3]}, "atol"),
    ({"u": [1.0, 2.0, 3.0]}, "u"),
    ({"u": np.ones((2, 4))}, "u"),
    ({"u": [np.nan, 0.0]}, "u"),
    ({"u": lambda t: np.zeros(3)}, "u"),
    ({"u": lambda t: np.zeros((2, 1))}, "u"),
    ({"p": [1.0]}, "p"),
    ({"steps": 0, "method": "rk4"}, "steps"),
    ({"steps": 2.5, "method": "rk8"}, "steps"),
    ({"steps": 4, "method": "auto"}, "steps"),
    ({"method": "lie"}, "lie"),
    ({"invariants": ["nope"]}, "invariants"),
    ({"max_steps": 0}, "max_steps"),
    ({"jit": "yes"}, "jit"),
])
def test_bad_input_raises_value_error_naming_the_argument(kwargs, name):
    args = {**GOOD, **kwargs}
    with pytest.raises(ValueError, match=name):
        simulate(linear_model(2), args.pop("x0"), args.pop("t"), **args)


def test_model_must_be_a_model():
    with pytest.raises(TypeError, match="model"):
        simulate(lambda x: x, X3, [0.0, 1.0])


def test_lie_rejects_a_model_whose_kinematics_are_not_eq_4_70():
    x, u, p = ca.SX.sym("x", 7), ca.SX.sym("u", 0), ca.SX.sym("p", 0)
    f = ca.Function("wrong", [x, u, p], [ca.vertcat(-quat_rate(x[:4], x[4:]), ca.DM.zeros(3))],
                    ["x", "u", "p"], ["xdot"])
    model = Model(f=f, states=tuple("abcdefg"), controls=(), attitude=(0, 4))
    with pytest.raises(ValueError, match="kinematics"):
        simulate(model, np.r_[Q0, W0], [0.0, 1.0], method="lie")


def test_callable_u_errors_propagate_from_cvodes():
    def failing(t):
        if t > 0.5:
            raise ZeroDivisionError("user code failed")
        return np.zeros(2)

    with pytest.raises(ZeroDivisionError):
        simulate(linear_model(2), X3, [0.0, 1.0], u=failing, method="cvodes")


def test_methods_constant_lists_every_method():
    assert set(METHODS) == {"auto", "dop853", "cvodes", "rk4", "rk8", "lie"}
