"""`attitude_gains` and `attitude_loop` accept the spacecraft as a `Scene`.

Truths: the hand-written `dynamics.rigid_body` under the PD law applied from numpy (the loop's
right-hand side), and the inertia path of `attitude_gains` (the same NLP: the same gains).
"""
from __future__ import annotations

import doctest
import importlib

import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as hs

from appdyn.dynamics.rigid_body import rigid_body
from appdyn.dynamics.scene import ExternalTorque, ReactionWheels, RigidHub, Scene
from appdyn.problems.gains.attitude_loop import (Q_SCALAR, Q_VECTOR, RATES, attitude_loop,
                                                 initial_state, spacecraft_scene)
from appdyn.problems.gains.spacecraft import attitude_gains
from tests.dynamics.scene import legacy_gains

J = np.array([[2.0, 0.1, 0.0], [0.1, 3.0, -0.2], [0.0, -0.2, 4.0]])
SLEW = [{"angle": np.radians(30), "axis": [0, 0, 1]}]


def _derivatives(model, x, g):
    """``(xdot, d xdot/dx, d xdot/dp)`` of a loop at ``x`` with gains ``g``."""
    xs, ps = ca.SX.sym("x", model.nx), ca.SX.sym("p", model.np)
    xdot = model.f(xs, ca.DM(0, 1), ps)
    fun = ca.Function("d", [xs, ps], [xdot, ca.jacobian(xdot, xs), ca.jacobian(xdot, ps)])
    return [np.asarray(v, dtype=float) for v in fun(x, g)]


def _close(got, want):
    """Equal to 1e-13 relative to the magnitude, absolute floor 1e-13."""
    assert np.max(np.abs(got - want)) <= 1e-13 * max(1.0, np.max(np.abs(want)))


@settings(max_examples=25, deadline=None)
@given(x=hs.lists(hs.floats(-1.0, 1.0), min_size=7, max_size=7),
       gains=hs.lists(hs.floats(0.0, 5.0), min_size=6, max_size=6), per_axis=hs.booleans())
def test_scene_loop_is_the_legacy_loop(x, gains, per_axis):
    """The loop built on the scene against the old hand-written one (rigid_body under the
    law, tests/dynamics/scene/legacy_gains.py): rhs, d xdot/dx, d xdot/dp; and against
    the law applied from numpy on the rigid body."""
    x = np.array(x)
    x[0:4] = x[0:4] / max(np.linalg.norm(x[0:4]), 1e-3)
    g = np.array(gains if per_axis else gains[:2])
    kp, kd = (g[0:3], g[3:6]) if per_axis else (g[0], g[1])
    u = -2 * kp * x[0:3] - kd * x[4:7]  # the law written out on the rigid body's states
    legacy = legacy_gains.attitude_loop(J, per_axis=per_axis)
    want = _derivatives(legacy, x, g)
    _close(want[0].ravel(), rigid_body(J).rhs(x, u))
    for body in (J, Scene(RigidHub(J)), Scene(RigidHub(J), ExternalTorque(u_max=1.0))):
        loop = attitude_loop(body, per_axis=per_axis)
        assert (loop.states, loop.params, loop.controls) == (legacy.states, legacy.params, ())
        assert dict(loop.units) == dict(legacy.units) and loop.attitude == legacy.attitude
        for got, ref in zip(_derivatives(loop, x, g), want):
            _close(got, ref)


def test_layout_blocks_are_the_rigid_body_states():
    names = Scene(RigidHub(J)).model().states
    assert names[Q_VECTOR] == ("q1", "q2", "q3") and names[Q_SCALAR] == "q4"
    assert names[RATES] == ("w1", "w2", "w3")
    np.testing.assert_array_equal(initial_state(np.pi / 2, [0, 0, 2], [0.1, 0, 0]),
                                  [0, 0, np.sin(np.pi / 4), np.cos(np.pi / 4), 0.1, 0, 0])


def test_attitude_gains_of_a_scene_equal_those_of_its_inertia():
    """``u_max=None`` takes the scene's torque bound; the design is the inertia's."""
    ref = attitude_gains(J, SLEW, u_max=0.5, time_optimal_reference=False, N=20)
    res = attitude_gains(Scene(RigidHub(J), ExternalTorque(u_max=0.5)), SLEW, u_max=None,
                         time_optimal_reference=False, N=20)
    assert ref.success and res.success
    for k in ("kp", "kd"):
        assert res.gains[k] == pytest.approx(ref.gains[k], rel=1e-9)
    assert res.verification["limits_met"]


@pytest.mark.parametrize("body, kwargs, match", [
    (Scene(RigidHub(J), ReactionWheels(np.eye(3), 0.1)), {"u_max": 0.5}, "`inertia`.*ReactionWheels"),
    (Scene(RigidHub(J, mass=10.0)), {"u_max": 0.5}, "`inertia`.*translating"),
    (Scene(RigidHub(J), ExternalTorque()), {"u_max": None}, "`u_max`"),
    (J, {"u_max": None}, "`u_max`"),
])
def test_bad_scene_names_the_argument(body, kwargs, match):
    with pytest.raises(ValueError, match=match):
        attitude_gains(body, SLEW, time_optimal_reference=False, **kwargs)


def test_spacecraft_scene_keeps_a_given_torque():
    scene = Scene(RigidHub(J), ExternalTorque(u_max=0.3))
    assert spacecraft_scene(scene) is scene
    assert spacecraft_scene(J) == Scene(RigidHub(J), ExternalTorque())


def test_docstring_examples_run_as_written():
    module = importlib.import_module("appdyn.problems.gains.attitude_loop")
    result = doctest.testmod(module, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.failed == 0 and result.attempted > 0
