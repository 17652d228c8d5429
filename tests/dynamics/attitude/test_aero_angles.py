"""Aerodynamic angles (seed Sec. 4.3 E): the defining components, the four conversion formulas,
round trips, numpy and CasADi alike, the Type II indeterminate case and bad input."""
import math

import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from appdyn.dynamics.attitude import (aero_angles, aero_angles_from_total, total_aoa,
                                      total_aoa_from_aero_angles, velocity_direction,
                                      velocity_direction_total)

comp = st.floats(-1e3, 1e3, allow_nan=False)
velocities = st.tuples(comp, comp, comp).filter(lambda v: np.linalg.norm(v) > 1e-6).map(np.array)


@settings(max_examples=200, deadline=None)
@given(velocities)
@pytest.mark.slow
def test_angles_reproduce_the_seed_components(v):
    V = np.linalg.norm(v)
    a, b = aero_angles(v)
    aT, phi = total_aoa(v)
    # Type I: v = V (cos a cos b, sin b, sin a cos b)
    # Type II: v = V (cos aT, sin aT sin phi, sin aT cos phi)
    np.testing.assert_allclose([V * math.cos(a) * math.cos(b), V * math.sin(b),
                                V * math.sin(a) * math.cos(b)], v, rtol=0, atol=1e-12 * V)
    np.testing.assert_allclose([V * math.cos(aT), V * math.sin(aT) * math.sin(phi),
                                V * math.sin(aT) * math.cos(phi)], v, rtol=0, atol=1e-12 * V)
    assert -math.pi <= a <= math.pi and -math.pi / 2 <= b <= math.pi / 2
    assert 0.0 <= aT <= math.pi and 0.0 <= phi < 2 * math.pi


@settings(max_examples=200, deadline=None)
@given(velocities)
@pytest.mark.slow
def test_the_four_conversion_formulas(v):
    a, b = aero_angles(v)
    aT, phi = total_aoa(v)
    tol = 1e-12
    # I -> II: cos aT = cos a cos b; tan phi = tan b / sin a (cross-multiplied: no division by 0)
    assert abs(math.cos(aT) - math.cos(a) * math.cos(b)) < tol
    assert abs(math.sin(phi) * math.sin(a) * math.cos(b) - math.cos(phi) * math.sin(b)) < tol
    # II -> I: tan a = cos phi tan aT; sin b = sin phi sin aT
    assert abs(math.sin(a) * math.cos(aT) - math.cos(a) * math.cos(phi) * math.sin(aT)) < tol
    assert abs(math.sin(b) - math.sin(phi) * math.sin(aT)) < tol
    # and the conversion functions give the angles of the same direction (an angle itself is
    # indeterminate on the axes: phi_R at v_y = v_z = 0, alpha at v_x = v_z = 0)
    e = v / np.linalg.norm(v)
    np.testing.assert_allclose(velocity_direction(*aero_angles_from_total(aT, phi)), e,
                               rtol=0, atol=1e-12)
    aT2, phi2 = total_aoa_from_aero_angles(a, b)
    np.testing.assert_allclose(velocity_direction_total(aT2, phi2), e, rtol=0, atol=1e-12)


@settings(max_examples=100, deadline=None)
@given(st.floats(-3.1, 3.1), st.floats(-1.5, 1.5))
def test_round_trip_type_one_through_type_two(a, b):
    aT, phi = total_aoa_from_aero_angles(a, b)
    np.testing.assert_allclose(aero_angles_from_total(aT, phi), (a, b), rtol=0, atol=1e-12)
    np.testing.assert_allclose(aero_angles(velocity_direction(a, b)), (a, b), rtol=0, atol=1e-12)


@settings(max_examples=100, deadline=None)
@given(st.floats(0.01, 3.13), st.floats(0.0, 6.28))
def test_round_trip_type_two_through_type_one(aT, phi):
    a, b = aero_angles_from_total(aT, phi)
    np.testing.assert_allclose(total_aoa_from_aero_angles(a, b), (aT, phi), rtol=0, atol=1e-12)


def test_known_directions():
    deg = np.degrees
    np.testing.assert_allclose(deg(aero_angles([1.0, 0.0, 1.0])), (45.0, 0.0), atol=1e-12)
    np.testing.assert_allclose(deg(aero_angles([1.0, 1.0, 0.0])), (0.0, 45.0), atol=1e-12)
    np.testing.assert_allclose(deg(aero_angles([-1.0, 0.0, 1.0])), (135.0, 0.0), atol=1e-12)
    np.testing.assert_allclose(deg(total_aoa([1.0, 1.0, 0.0])), (45.0, 90.0), atol=1e-12)
    np.testing.assert_allclose(deg(total_aoa([1.0, 0.0, -1.0])), (45.0, 180.0), atol=1e-12)


def test_batch_equals_columns_and_casadi_equals_numpy():
    rng = np.random.default_rng(3)
    V = rng.normal(size=(3, 7)) * 50
    V[1:, 2] = 0.0  # an indeterminate column inside a batch
    v = ca.SX.sym("v", 3)
    sx = ca.Function("f", [v], [ca.vertcat(*aero_angles(v), *total_aoa(v, return_defined=True))])
    vm = ca.MX.sym("v", 3)
    mx = ca.Function("g", [vm], [ca.vertcat(*aero_angles(vm), *total_aoa(vm, return_defined=True))])
    batch = np.vstack([*aero_angles(V), *total_aoa(V, return_defined=True)])
    for k in range(V.shape[1]):
        col = np.hstack([*aero_angles(V[:, k]), *total_aoa(V[:, k], return_defined=True)])
        np.testing.assert_allclose(batch[:, k], col, rtol=0, atol=1e-15)
        np.testing.assert_allclose(np.array(sx(V[:, k])).ravel(), col, rtol=0, atol=1e-14)
        np.testing.assert_allclose(np.array(mx(V[:, k])).ravel(), col, rtol=0, atol=1e-14)
        dm = ca.DM(V[:, k])
        got = np.array(ca.vertcat(*aero_angles(dm))).ravel()
        np.testing.assert_allclose(got, col[:2], atol=1e-14)
    assert batch[3, 2] == 0.0 and not batch[4, 2] and batch[4].sum() == 6


@pytest.mark.parametrize("v", [[3.0, 0.0, 0.0], [-2.0, 0.0, 0.0]])
def test_type_two_indeterminate_is_reported_not_nan(v):
    aT, phi, defined = total_aoa(v, return_defined=True)
    assert (aT, phi, defined) == (0.0 if v[0] > 0 else math.pi, 0.0, False)
    assert total_aoa_from_aero_angles(0.0, 0.0, return_defined=True) == (0.0, 0.0, False)
    for sym in (ca.SX.sym("v", 3), ca.MX.sym("v", 3)):
        aT, phi, d = total_aoa(sym, return_defined=True)
        out = ca.vertcat(aT, phi, d)
        f = ca.Function("f", [sym], [out, ca.jacobian(out, sym)])
        val, jac = (np.array(m) for m in f(v))
        assert np.all(np.isfinite(val)) and np.all(np.isfinite(jac))
        np.testing.assert_array_equal(val.ravel(), [0.0 if v[0] > 0 else math.pi, 0.0, 0.0])
    # pure sideslip: alpha indeterminate, 0 by convention, finite derivatives
    sym = ca.SX.sym("v", 3)
    out = ca.vertcat(*aero_angles(sym))
    g = ca.Function("g", [sym], [out, ca.jacobian(out, sym)])
    val, jac = (np.array(m) for m in g([0, -2.0, 0]))
    assert np.all(np.isfinite(jac)) and val.ravel().tolist() == [0.0, -math.pi / 2]


def test_derivatives_match_finite_differences_away_from_the_axis():
    v = ca.SX.sym("v", 3)
    out = ca.vertcat(*aero_angles(v), *total_aoa(v))
    f = ca.Function("f", [v], [out, ca.jacobian(out, v)])
    v0 = np.array([40.0, -3.0, 7.0])
    jac = np.array(f(v0)[1])
    h = 1e-6
    fd = np.column_stack([(np.array(f(v0 + h * e)[0]) - np.array(f(v0 - h * e)[0])).ravel()
                          / (2 * h) for e in np.eye(3)])
    np.testing.assert_allclose(jac, fd, rtol=1e-7, atol=1e-10)


@pytest.mark.parametrize("func", [aero_angles, total_aoa])
def test_zero_velocity_is_a_value_error_naming_v_body(func):
    for bad in ([0.0, 0.0, 0.0], ca.DM.zeros(3)):
        with pytest.raises(ValueError, match="v_body"):
            func(bad)
    with pytest.raises(ValueError, match=r"v_body\[:, 1\]"):
        func(np.array([[1.0, 0.0], [0.0, 0.0], [0.0, 0.0]]))
    with pytest.raises(ValueError, match="v_body"):
        func([1.0, 2.0])
    with pytest.raises(ValueError, match="v_body"):
        func([1.0, np.nan, 0.0])
    with pytest.raises(ValueError, match="v_body"):
        func(ca.SX.sym("v", 2))
    with pytest.raises(TypeError):
        func("abc")


def test_bad_arguments_of_the_conversions():
    with pytest.raises(ValueError, match="beta"):
        velocity_direction(0.1, np.nan)
    with pytest.raises(TypeError, match="alpha_T"):
        velocity_direction_total("a", 0.0)
    with pytest.raises(ValueError, match="phi_R"):
        aero_angles_from_total(0.1, math.inf)
    with pytest.raises(TypeError, match="return_defined"):
        total_aoa([1.0, 0.0, 0.0], return_defined=1)
