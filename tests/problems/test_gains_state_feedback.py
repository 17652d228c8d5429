"""`problems.gains.state_feedback`: full-state feedback by multi-scenario collocation = LQR."""
import control
import numpy as np
import pytest

from appdyn.problems.gains.result import STATUS_UNSTABLE, GainDesign
from appdyn.problems.gains.state_feedback import (HORIZON_RATIO_MIN, STATUS_NOT_SPANNING,
                                           STATUS_SHORT_HORIZON, state_feedback_gains)
from appdyn.ocp.status import STATUS_SUCCESS

A_DI, B_DI = np.array([[0.0, 1.0], [0.0, 0.0]]), np.array([[0.0], [1.0]])


def _check_against_lqr(A, B, Q, R, X0, horizon, N):
    K, res = state_feedback_gains(A, B, Q, R, X0, horizon, N=N)
    K_lqr, _, _ = control.lqr(A, B, Q, R)
    assert isinstance(res, GainDesign)
    assert res.success, res.message
    assert res.status == STATUS_SUCCESS and res.verification["warnings"] == []
    assert res.verification["horizon_ratio"] >= HORIZON_RATIO_MIN
    np.testing.assert_allclose(K, K_lqr, rtol=1e-4)
    np.testing.assert_allclose(res.verification["K_lqr"], K_lqr)
    np.testing.assert_allclose(res.verification["poles"], np.linalg.eigvals(A - B @ K))
    assert res.verification["lqr_max_relative_difference"] < 1e-4
    # the summed cost approaches the infinite-horizon optimum sum x0^T P x0 from below (the
    # tail after the horizon is missing) and to the same accuracy
    assert res.cost == pytest.approx(res.verification["lqr_cost"], rel=1e-5)
    return K, res


def test_double_integrator_gains_are_the_lqr_gains():
    """Q = I, R = 1: K_lqr = [1, sqrt(3)]. Horizon 15 s = 13 slowest time constants, N = 100
    (Radau 3): measured max relative difference from control.lqr 2.1e-7 (limit 1e-4)."""
    K, res = _check_against_lqr(A_DI, B_DI, np.eye(2), np.eye(1), np.eye(2), 15.0, 100)
    np.testing.assert_allclose(K, [[1.0, np.sqrt(3.0)]], rtol=1e-4)
    assert res.verification["lqr_max_relative_difference"] < 1e-5


def test_a_statespace_is_taken_as_control_lqr_takes_it():
    """``state_feedback_gains(sys, Q, R, X0, horizon)`` equals the (A, B) call exactly (the
    same NLP); a discrete-time system is refused naming ``sys``."""
    sys = control.ss(A_DI, B_DI, np.eye(2), np.zeros((2, 1)))
    K_sys, res_sys = state_feedback_gains(sys, np.eye(2), np.eye(1), np.eye(2), 15.0, N=20)
    K_ab, _ = state_feedback_gains(A_DI, B_DI, np.eye(2), np.eye(1), np.eye(2), 15.0, N=20)
    np.testing.assert_array_equal(K_sys, K_ab)
    assert res_sys.success, res_sys.message
    with pytest.raises(ValueError, match="`sys` must be a continuous-time system"):
        state_feedback_gains(control.ss(A_DI, B_DI, np.eye(2), np.zeros((2, 1)), 0.1),
                             np.eye(2), np.eye(1), np.eye(2), 15.0)


def test_unstable_three_state_plant_gains_are_the_lqr_gains():
    """A chain with an open-loop pole at +0.81 1/s, Q = diag(1, 0.5, 0.2), R = 0.5; horizon
    14 s = 12.8 time constants, N = 100: measured max relative difference 5.6e-7."""
    A = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [2.0, -1.0, -1.0]])
    assert np.max(np.linalg.eigvals(A).real) > 0.8
    B = np.array([[0.0], [0.0], [1.0]])
    _check_against_lqr(A, B, np.diag([1.0, 0.5, 0.2]), np.array([[0.5]]), np.eye(3), 14.0, 100)


@pytest.mark.slow
def test_unstable_two_input_plant_gains_are_the_lqr_gains():
    """Two inputs, three states, open-loop pole at +0.70 1/s, R = diag(1, 2), four initial
    states; horizon 14 s = 15 time constants, N = 100: measured 9.8e-7 (all six entries
    free)."""
    A = np.array([[0.5, 1.0, 0.0], [0.0, -0.2, 1.0], [0.3, 0.0, -1.0]])
    B = np.array([[1.0, 0.0], [0.0, 0.0], [0.0, 2.0]])
    X0 = np.array([[1.0, 0, 0, 1], [0, 1.0, 0, -1], [0, 0, 1.0, 0.5]])
    K, res = _check_against_lqr(A, B, np.eye(3), np.diag([1.0, 2.0]), X0, 14.0, 100)
    assert K.shape == (2, 3) and len(res.gains) == 6 and len(res.scenarios) == 4
    np.testing.assert_allclose(res.scenarios[3]["x"][:, 0], X0[:, 3])
    np.testing.assert_allclose(res.scenarios[3]["u"], -K @ res.scenarios[3]["x"])


def test_short_horizon_warns_and_is_not_lqr():
    """3 s is about 2.6 time constants: a finite-horizon compromise, flagged (4.7 % off)."""
    K, res = state_feedback_gains(A_DI, B_DI, np.eye(2), np.eye(1), np.eye(2), 3.0)
    assert res.success and res.status == STATUS_SHORT_HORIZON
    assert res.verification["horizon_ratio"] < HORIZON_RATIO_MIN
    assert "WARNING" in res.message and "horizon" in res.message
    assert res.verification["lqr_relative_difference"] > 1e-2


@pytest.mark.slow
def test_initial_states_not_spanning_warn_and_leave_gains_undetermined():
    """Two decoupled stable modes, both initial states on the first axis (an invariant
    subspace of every diagonal loop): the second column of K does not affect the cost and
    stays at its initial guess; the first column is LQR's."""
    A, B = np.diag([-1.0, -2.0]), np.eye(2)
    K_lqr, _, _ = control.lqr(A, B, np.eye(2), np.eye(2))
    K0 = K_lqr + np.array([[0.0, 0.3], [0.0, 0.5]])
    K, res = state_feedback_gains(A, B, np.eye(2), np.eye(2), [[1.0, -2.0], [0.0, 0.0]], 10.0, K0=K0)
    assert res.success and res.status == STATUS_NOT_SPANNING
    assert res.verification["initial_state_rank"] == 1 and not res.verification["spanning"]
    assert "span" in res.message and "unique" in res.message
    np.testing.assert_allclose(K[:, 0], K_lqr[:, 0], atol=1e-6)
    np.testing.assert_allclose(K[:, 1], K0[:, 1], atol=1e-6)


def test_unstable_design_is_not_a_success():
    """Gains bounded to negative values: the NLP converges, the loop is unstable."""
    K, res = state_feedback_gains(A_DI, B_DI, np.eye(2), np.eye(1), np.eye(2), 3.0,
                                  K_bounds=(-1.0, -0.5))
    assert not res.success and res.status == STATUS_UNSTABLE
    assert not res.verification["stable"] and "not stable" in res.message


@pytest.mark.parametrize("change, error, match", [
    ({"A": np.ones((2, 3))}, ValueError, "`A`"),
    ({"A": [[0.0, np.nan], [0.0, 0.0]]}, ValueError, "`A`"),
    ({"B": np.ones((3, 1))}, ValueError, "`B`"),
    ({"Q": np.eye(3)}, ValueError, "`Q`"),
    ({"Q": [[1.0, 0.5], [0.0, 1.0]]}, ValueError, "`Q`.*symmetric"),
    ({"Q": np.diag([1.0, -1.0])}, ValueError, "`Q`.*semidefinite"),
    ({"R": [[0.0]]}, ValueError, "`R`.*positive definite"),
    ({"R": np.eye(2)}, ValueError, "`R`"),
    ({"initial_states": np.ones((2, 1))}, ValueError, "initial_states"),
    ({"initial_states": np.ones((3, 2))}, ValueError, "initial_states"),
    ({"initial_states": [[1.0, 0.0], [0.0, 0.0]]}, ValueError, "initial_states"),
    ({"horizon": 0.0}, ValueError, "horizon"),
    ({"horizon": np.inf}, ValueError, "horizon"),
    ({"horizon": "10"}, TypeError, "horizon"),
    ({"A": "abc"}, TypeError, "`A`"),
    ({"K0": np.ones((2, 2))}, ValueError, "K0"),
    ({"K_bounds": (1.0, 0.0)}, ValueError, "K_bounds"),
])
def test_bad_inputs_name_the_argument(change, error, match):
    args = {"A": A_DI, "B": B_DI, "Q": np.eye(2), "R": np.eye(1), "initial_states": np.eye(2),
            "horizon": 10.0, **change}
    with pytest.raises(error, match=match):
        state_feedback_gains(**args)
