"""Slew inputs follow the one error convention (`dynamics.validate`): TypeError for a wrong
type, ValueError for a wrong value, naming the argument; a warning for an ignored one."""
import numpy as np
import pytest

from appdyn.problems import slew


def test_ignored_horizon_of_a_time_optimal_slew_warns():
    with pytest.warns(UserWarning, match="`T` is ignored"):
        slew.slew_problem(np.eye(3), objective="time", T=3.0, angle=1.0, axis=[0, 0, 1])


@pytest.mark.parametrize("kwargs, exc, match", [
    (dict(angle="one", axis=[0, 0, 1]), TypeError, "`angle`"),
    (dict(angle=1.0, axis=[0, 0, 0]), ValueError, "`axis`"),
    (dict(angle=1.0, axis=[0, 0, 1], w0=[0, 0, np.nan]), ValueError, "`w0`"),
    (dict(qf=[0, 0, 0, 1], q0=[0, 0, 0.5, 0.5]), ValueError, "`q0`"),
    (dict(angle=1.0, axis=[0, 0, 1], keep_out="sun"), TypeError, "`keep_out`"),
    (dict(angle=1.0, axis=[0, 0, 1], u_max="big"), TypeError, "`u_max`"),
])
def test_bad_slew_inputs(kwargs, exc, match):
    with pytest.raises(exc, match=match):
        slew.slew_problem(np.eye(3), objective="time", **kwargs)


def test_keep_out_checks_and_normalizes():
    cone = slew.KeepOut(boresight=[2, 0, 0], direction=[0, 0, 3], half_angle=0.5)
    assert cone.boresight == (1.0, 0.0, 0.0) and cone.direction == (0.0, 0.0, 1.0)
    with pytest.raises(ValueError, match="`boresight`"):
        slew.KeepOut(boresight=[0, 0, 0], direction=[0, 0, 1], half_angle=0.5)
    with pytest.raises(ValueError, match="`half_angle`"):
        slew.KeepOut(boresight=[1, 0, 0], direction=[0, 0, 1], half_angle=4.0)


def test_starts_must_be_a_positive_integer():
    with pytest.raises(ValueError, match="`starts`"):
        slew.time_optimal(np.eye(3), angle=1.0, axis=[0, 0, 1], starts=0)
    with pytest.raises(TypeError, match="`starts`"):
        slew.time_optimal(np.eye(3), angle=1.0, axis=[0, 0, 1], starts=2.5)


def test_ignored_arguments_warn():
    guess = {"T": 1.0}
    with pytest.warns(UserWarning, match="`starts` and `seed` are ignored with a user `guess`"):
        slew.time_optimal(np.eye(3), angle=0.1, axis=[0, 0, 1], guess=guess, starts=2, seed=1,
                          N=8, polish=False)
    with pytest.warns(UserWarning, match="`polish` is ignored with `norm_bound`"):
        slew.time_optimal(np.eye(3), angle=0.1, axis=[0, 0, 1], norm_bound=True, polish=True,
                          starts=1, N=8)
    with pytest.warns(UserWarning, match="`starts` is ignored without a `keep_out`"):
        slew.min_effort(np.eye(3), 2.0, angle=0.1, axis=[1, 0, 0], N=8, starts=2)
    with pytest.warns(UserWarning, match="`T_max` is ignored"):
        slew.slew_problem(np.eye(3), objective="effort", T=1.0, angle=0.1, axis=[1, 0, 0],
                          T_max=5.0)
