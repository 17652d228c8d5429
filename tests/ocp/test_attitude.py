"""`ocp.attitude`: the attitude pieces kept out of the generic problem (closed forms)."""
import math

import numpy as np
import pytest

from appdyn.dynamics import rigid_body
from appdyn.dynamics.attitude import quat_from_axis_angle
from appdyn.ocp import Problem
from appdyn.ocp.attitude import attitude_error, quaternion_path, slerp, target_bounds, target_rows


def test_slerp_is_the_constant_rate_rotation():
    """SLERP from identity to a rotation by a about e is the rotation by s a about e."""
    e, a = np.array([0.0, 0.6, 0.8]), 2.0
    s = np.linspace(0, 1, 5)
    q = slerp([0, 0, 0, 1.0], quat_from_axis_angle(e, a), s)
    expect = np.stack([quat_from_axis_angle(e, a * si) for si in s], axis=1)
    np.testing.assert_allclose(q, expect, atol=1e-14)


def test_attitude_error_vanishes_up_to_sign():
    qf = quat_from_axis_angle([1.0, 0, 0], 0.7)
    np.testing.assert_allclose(attitude_error(qf, qf), 0.0, atol=1e-15)
    np.testing.assert_allclose(attitude_error(qf, -qf), 0.0, atol=1e-15)
    off = quat_from_axis_angle([1.0, 0, 0], 0.9)
    assert np.linalg.norm(attitude_error(qf, off)) == pytest.approx(math.sin(0.1))


def test_problem_uses_the_attitude_pieces():
    qf = quat_from_axis_angle([0.0, 0, 1], 1.0)
    model = rigid_body(np.eye(3))
    exact = Problem(model, T=1.0, x_initial=[0, 0, 0, 1, 0, 0, 0], q_final=-qf)
    assert target_rows(exact) == 3 and target_bounds(exact) == (0.0, 0.0)
    loose = exact.replace(q_final_tol=0.2)
    assert target_rows(loose) == 1 and target_bounds(loose)[1] == pytest.approx(math.sin(0.1) ** 2)
    sl, path = quaternion_path(exact)  # the shorter way round: towards +qf
    np.testing.assert_allclose(path(np.array([1.0]))[:, 0], qf, atol=1e-14)
    assert sl == slice(0, 4)


def test_attitude_inputs_follow_the_error_convention():
    model = rigid_body(np.eye(3))
    with pytest.raises(TypeError, match="`q_final`"):
        Problem(model, T=1.0, q_final="north")
    with pytest.raises(TypeError, match="`q_final_tol`"):
        Problem(model, T=1.0, q_final=[0, 0, 0, 1], q_final_tol="0.1")
    with pytest.raises(ValueError, match="`q_final`"):
        Problem(model, T=1.0, q_final=[0, 0, 0, 1.1])
