"""`simulate(..., hold="zoh")`: sampled controls held constant between the output times
(appdyn issue 27, item 5a), against closed forms: a double integrator (position and velocity
piecewise quadratic and linear) and a rigid body spun up about a principal axis by a
piecewise-constant torque (rate piecewise linear, angle piecewise quadratic)."""
import casadi as ca
import numpy as np
import pytest

from appdyn.dynamics import Model, rigid_body, simulate

RNG = np.random.default_rng(27)
T = np.cumsum(np.r_[0.0, RNG.uniform(0.2, 0.7, 30)])  # a non-uniform grid
U = RNG.uniform(-1.0, 1.0, T.size)                    # u[k] acts on [t_k, t_k+1)


def double_integrator() -> Model:
    y, v, a = ca.SX.sym("y"), ca.SX.sym("v"), ca.SX.sym("a")
    return Model.from_expressions([("y", y), ("v", v)], [v, a], [("a", a)])


def held_double_integrator(y0, v0, t, u):
    """Exact y, v at ``t`` under ``a = u[k]`` on ``[t_k, t_k+1)``."""
    y, v = [y0], [v0]
    for k in range(t.size - 1):
        h = t[k + 1] - t[k]
        y.append(y[-1] + v[-1] * h + 0.5 * u[k] * h * h)
        v.append(v[-1] + u[k] * h)
    return np.array([y, v])


def held_spin(inertia3, w0, t, torque):
    """Rate and angle about the principal axis 3 under ``L3 = torque[k]`` on each interval:
    ``(w (n,), angle (n,))``."""
    w, angle = [w0], [0.0]
    for k in range(t.size - 1):
        h, a = t[k + 1] - t[k], torque[k] / inertia3
        angle.append(angle[-1] + w[-1] * h + 0.5 * a * h * h)
        w.append(w[-1] + a * h)
    return np.array(w), np.array(angle)


TRUTH = held_double_integrator(0.3, -0.2, T, U)


@pytest.mark.parametrize("method, kwargs, tol", [
    ("rk4", {}, 1e-12),              # one step per interval: exact for a quadratic
    ("rk8", {"steps": 2}, 1e-12),
    ("auto", {"rtol": 1e-10}, None),  # None: the requested tolerance
    ("cvodes", {"rtol": 1e-12, "atol": 1e-12}, 1e-8),
])
def test_double_integrator_under_a_zero_order_hold_is_exact(method, kwargs, tol):
    res = simulate(double_integrator(), [0.3, -0.2], T, u=U[None, :], hold="zoh",
                   method=method, **kwargs)
    assert res.success, res.message
    if tol is None:
        tol_x = 1e-10 + 1e-10 * np.abs(TRUTH)
        assert np.all(np.abs(res.x - TRUTH) <= tol_x), np.max(np.abs(res.x - TRUTH) / tol_x)
    else:
        np.testing.assert_allclose(res.x, TRUTH, rtol=0, atol=tol)
    # the hold matters: linear interpolation of the same samples is another trajectory
    lin = simulate(double_integrator(), [0.3, -0.2], T, u=U[None, :], method="rk8", steps=2)
    assert np.max(np.abs(lin.x - TRUTH)) > 1e-2


def test_zoh_batch_matches_each_run_closed_form():
    K = 3
    u = np.stack([U, -U, 0.5 * U], axis=1)[None, :, :]  # (1, n, K)
    x0 = np.array([[0.3, -0.2], [0.0, 1.0], [-1.0, 0.0]]).T
    for method, kw in (("rk4", {}), ("auto", {"rtol": 1e-10}), ("cvodes", {"rtol": 1e-12,
                                                                           "atol": 1e-12})):
        res = simulate(double_integrator(), x0, T, u=u, hold="zoh", method=method, **kw)
        assert res.all_success, res.message
        for k in range(K):
            truth = held_double_integrator(*x0[:, k], T, u[0, :, k])
            np.testing.assert_allclose(res.x[:, :, k], truth, rtol=0, atol=1e-8)


@pytest.mark.slow
def test_rigid_body_spun_up_by_a_held_torque_matches_the_closed_form():
    """Torque about the principal axis 3 of a body at rest: w3 piecewise linear, the angle
    piecewise quadratic, q = [0, 0, sin(angle/2), cos(angle/2)]."""
    inertia = [2.0, 3.0, 4.0]
    torque = np.zeros((3, T.size))
    torque[2] = 2.0 * U
    w, angle = held_spin(4.0, 0.1, T, torque[2])
    for method, kw in (("rk8", {"steps": 8}), ("lie", {"steps": 8}),
                       ("auto", {"rtol": 1e-10})):
        res = simulate(rigid_body(inertia), [0, 0, 0, 1, 0, 0, 0.1], T, u=torque, hold="zoh",
                       method=method, **kw)
        assert res.success, res.message
        np.testing.assert_allclose(res.x[6], w, rtol=0, atol=1e-9)
        np.testing.assert_allclose(res.x[2], np.sin(angle / 2), rtol=0, atol=1e-9)
        np.testing.assert_allclose(res.x[3], np.cos(angle / 2), rtol=0, atol=1e-9)


def test_dense_output_takes_each_side_of_the_jumps():
    """v is linear on each interval with slope u[k]: the cubic Hermite output is exact when
    the derivative at an interval's end is its left limit (u[k], not u[k+1])."""
    res = simulate(double_integrator(), [0.3, -0.2], T, u=U[None, :], hold="zoh", method="rk4")
    mid = 0.5 * (T[1:] + T[:-1])
    np.testing.assert_allclose(res.sample(mid)[1], TRUTH[1, :-1] + U[:-1] * (mid - T[:-1]),
                               rtol=0, atol=1e-12)
    np.testing.assert_allclose(res.xdot[1], U, rtol=0, atol=0)  # xdot at t_k: u[k] acts


def test_constant_and_zero_controls_are_the_same_under_both_holds():
    for u in (None, [0.7]):
        a = simulate(double_integrator(), [0.3, -0.2], T, u=u, method="rk4")
        b = simulate(double_integrator(), [0.3, -0.2], T, u=u, hold="zoh", method="rk4")
        np.testing.assert_array_equal(a.x, b.x)


def test_bad_hold_is_a_value_error_naming_it():
    with pytest.raises(ValueError, match="`hold`"):
        simulate(double_integrator(), [0.0, 0.0], T, u=U[None, :], hold="cubic")
    with pytest.raises(ValueError, match="`hold='zoh'`.*callable"):
        simulate(double_integrator(), [0.0, 0.0], T, u=lambda t: [1.0], hold="zoh")
    with pytest.raises(ValueError, match="`hold`"):
        simulate(double_integrator(), np.zeros((2, 2)), T, u=U[None, :], hold="cubic")
