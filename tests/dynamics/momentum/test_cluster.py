"""CMG cluster geometry, momentum, Jacobian and singularity analysis against independent truths.

Truths used here: the closed-form pyramid momentum (Wie, *Space Vehicle Dynamics and
Control*, Sec. 7.3, written out term by term below, not built from the code's geometry); the
momentum envelope found by numerical optimization and compared with ``2 h (1 + cos beta)``
and ``4 h sin beta``; ``det(C C^T) = 16 cos^4(beta) sin^2(beta)`` at zero gimbal angles
(``32/27`` at ``beta = acos(1/sqrt(3))``); the literature's elliptic and hyperbolic singular
states of the pyramid; finite differences and CasADi's automatic Jacobian.
"""
import doctest
import re

import casadi as ca
import numpy as np
import pytest
from scipy.optimize import minimize

from appdyn.dynamics.momentum import (ClusterGeometry, classify_singularity, cluster, cluster_jacobian,
                               cluster_momentum, gram_determinant, pyramid, singular_direction,
                               singularity_measure)

BETA_EXACT = np.arccos(1 / np.sqrt(3))  # 54.7356... deg
BETA = np.deg2rad(54.74)
RNG = np.random.default_rng(20240611)


def pyramid_closed_form(beta, d, h=(1.0, 1.0, 1.0, 1.0)):
    """Wie's pyramid: h1 = (-cb s1, c1, sb s1), h2 = (-c2, -cb s2, sb s2), h3 = (cb s3, -c3,
    sb s3), h4 = (c4, cb s4, sb s4)."""
    cb, sb = np.cos(beta), np.sin(beta)
    s, c = np.sin(d), np.cos(d)
    units = [(-cb * s[0], c[0], sb * s[0]), (-c[1], -cb * s[1], sb * s[1]),
             (cb * s[2], -c[2], sb * s[2]), (c[3], cb * s[3], sb * s[3])]
    return sum(hi * np.array(u) for hi, u in zip(h, units))


# ------------------------------------------------------------------------- pyramid geometry
@pytest.mark.parametrize("beta", [BETA, BETA_EXACT, np.deg2rad(30.0), np.pi / 2])
def test_pyramid_momentum_equals_closed_form(beta):
    h = np.array([1.0, 2.0, 0.5, 3.0])
    geo = pyramid(beta, h)
    d = RNG.uniform(-np.pi, np.pi, size=(4, 25))
    H = cluster_momentum(geo, d)
    assert H.shape == (3, 25)
    for j in range(25):
        np.testing.assert_allclose(H[:, j], pyramid_closed_form(beta, d[:, j], h), atol=1e-14)
        np.testing.assert_allclose(cluster_momentum(geo, d[:, j]), H[:, j], atol=1e-15)


def test_pyramid_gimbal_axes_are_normal_to_the_faces():
    geo = pyramid(BETA_EXACT)
    g = geo.gimbal_axes
    np.testing.assert_allclose(g[2], np.cos(BETA_EXACT), atol=1e-15)  # tilt beta from vertical
    horizontal = g[:2] / np.sin(BETA_EXACT)  # +x, +y, -x, -y: the four faces
    np.testing.assert_allclose(horizontal, [[1, 0, -1, 0], [0, 1, 0, -1]], atol=1e-15)
    np.testing.assert_allclose(np.sum(g * geo.spin_axes0, axis=0), 0.0, atol=1e-15)
    assert geo.n == 4 and geo.h.shape == (4,)


# ------------------------------------------------------------------------- momentum envelope
def maximum_projection(geo, e, starts=12):
    """max over delta of e . H(delta), by BFGS from several random starts."""
    best = None
    for _ in range(starts):
        res = minimize(lambda d: -e @ cluster_momentum(geo, d), RNG.uniform(-np.pi, np.pi, 4),
                       jac=lambda d: -e @ cluster_jacobian(geo, d), method="BFGS",
                       options={"gtol": 1e-12})
        if best is None or res.fun < best.fun:
            best = res
    return -best.fun, best.x


@pytest.mark.parametrize("beta", [BETA, BETA_EXACT])
@pytest.mark.parametrize("axis", [0, 1, 2])
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_momentum_envelope_along_the_axes(beta, axis, sign):
    geo = pyramid(beta)
    e = sign * np.eye(3)[axis]
    value, d = maximum_projection(geo, e)
    expected = 4 * np.sin(beta) if axis == 2 else 2 * (1 + np.cos(beta))
    assert value == pytest.approx(expected, abs=1e-10)
    H = cluster_momentum(geo, d)
    assert np.linalg.norm(H) == pytest.approx(value, abs=1e-8)  # the maximum lies along e
    assert classify_singularity(geo, d, tol=1e-6) == "elliptic"  # saturation is elliptic
    if beta == BETA:  # the published 3-decimal values
        assert round(value, 3) == (3.266 if axis == 2 else 3.155)


def test_envelope_maximizing_angles_analytically():
    geo = pyramid(BETA)
    cb, sb = np.cos(BETA), np.sin(BETA)
    H = cluster_momentum(geo, np.deg2rad([-90, 180, 90, 0]))
    np.testing.assert_allclose(H, [2 * (1 + cb), 0, 0], atol=1e-14)
    H = cluster_momentum(geo, np.deg2rad([90, 90, 90, 90]))
    np.testing.assert_allclose(H, [0, 0, 4 * sb], atol=1e-14)


# ------------------------------------------------------------------------- det(C C^T)
def det_at_zero(beta):
    """C(0) has the columns (-cb, 0, sb), (0, -cb, sb), (cb, 0, sb), (0, cb, sb): C C^T =
    diag(2 cb^2, 2 cb^2, 4 sb^2)."""
    return 16 * np.cos(beta) ** 4 * np.sin(beta) ** 2


def test_det_is_32_over_27_at_the_exact_skew_angle():
    geo = pyramid(BETA_EXACT)
    det = gram_determinant(cluster_jacobian(geo, np.zeros(4)))
    assert det == pytest.approx(32 / 27, rel=1e-14)
    assert singularity_measure(geo, np.zeros(4)) == pytest.approx(np.sqrt(32 / 27), rel=1e-14)


def test_det_at_54_74_deg_differs_by_the_angle_difference():
    det = gram_determinant(cluster_jacobian(pyramid(BETA), np.zeros(4)))
    assert det == pytest.approx(det_at_zero(BETA), rel=1e-14)
    # mean value theorem: |det(BETA) - 32/27| <= max |d det/d beta| * |BETA - BETA_EXACT|
    b = np.linspace(BETA_EXACT, BETA, 1001)
    slope = 16 * np.cos(b) ** 3 * np.sin(b) * (2 * np.cos(b) ** 2 - 4 * np.sin(b) ** 2)
    bound = np.max(np.abs(slope)) * abs(BETA - BETA_EXACT)
    assert abs(det - 32 / 27) <= bound
    assert abs(det - 32 / 27) >= 0.9 * bound  # and the difference is really that large


def test_beta_90_is_singular_at_zero_angles():
    geo = pyramid(np.pi / 2)
    m = singularity_measure(geo, np.zeros(4))
    assert 0.0 <= m <= 1e-15  # all transverse axes along e_z: rank 1
    assert classify_singularity(geo, np.zeros(4)) == "degenerate"


# ------------------------------------------------------------------------- singularities
def test_elliptic_singularity_of_the_pyramid():
    geo, d = pyramid(BETA), np.deg2rad([-90, 0, 90, 0])
    np.testing.assert_allclose(cluster_momentum(geo, d), [2 * np.cos(BETA), 0, 0], atol=1e-15)
    assert round(float(cluster_momentum(geo, d)[0]), 3) == 1.155
    assert classify_singularity(geo, d) == "elliptic"
    u = singular_direction(geo, d)
    np.testing.assert_allclose(u, [1, 0, 0], atol=1e-15)  # u . H > 0
    np.testing.assert_allclose(u @ cluster_jacobian(geo, d), 0.0, atol=1e-15)


@pytest.mark.parametrize("deg, H_expected, u_expected", [
    ([90, -90, 90, -90], [0, 0, 0], [0, 0, 1]),  # H = 0: largest component positive
    ([90, 0, 90, 0], [0, 0, 2 * np.sin(BETA)], [1, 0, 0]),  # u . H = 0 too: u = +x
])
def test_hyperbolic_singularities_of_the_pyramid(deg, H_expected, u_expected):
    geo, d = pyramid(BETA), np.deg2rad(deg)
    np.testing.assert_allclose(cluster_momentum(geo, d), H_expected, atol=1e-15)
    assert classify_singularity(geo, d) == "hyperbolic"
    u = singular_direction(geo, d)
    np.testing.assert_allclose(u, u_expected, atol=1e-15)
    assert np.linalg.norm(u @ cluster_jacobian(geo, d)) <= 1e-15


def test_generic_states_are_nonsingular():
    geo = pyramid(BETA)
    assert classify_singularity(geo, np.zeros(4)) == "nonsingular"
    for d in RNG.uniform(-np.pi, np.pi, size=(20, 4)):
        if singularity_measure(geo, d) > 1e-3:
            assert classify_singularity(geo, d) == "nonsingular"


def test_classification_does_not_depend_on_the_sign_of_u():
    """Q = N^T P N flips with u: definiteness (elliptic) and indefiniteness do not change."""
    geo, d = pyramid(BETA), np.deg2rad([-90, 0, 90, 0])
    C = cluster_jacobian(geo, d)
    units = geo.h * (np.cos(d) * geo.spin_axes0 + np.sin(d) * geo.transverse_axes0)
    N = np.linalg.svd(C)[2][2:].T
    for u in (np.array([1.0, 0, 0]), np.array([-1.0, 0, 0])):
        eig = np.linalg.eigvalsh(N.T @ np.diag(u @ units) @ N)
        assert np.all(eig > 0.1) or np.all(eig < -0.1)


def test_two_unit_cluster_has_no_null_motion():
    """n = 2: rank 2 everywhere generic, empty null space -> elliptic (no null motion)."""
    geo = ClusterGeometry(np.eye(3)[:, [2, 0]], np.eye(3)[:, [0, 1]], [1.0, 2.0])
    assert classify_singularity(geo, [0.3, 0.4]) == "elliptic"
    assert singularity_measure(geo, [0.3, 0.4]) <= 1e-7  # sqrt of a round-off det ~ 1e-16


# ------------------------------------------------------------------------- Jacobian
def test_jacobian_equals_central_differences():
    geo = pyramid(BETA, [1.0, 2.0, 0.5, 3.0])
    step = 1e-6  # truncation ~ step^2 h / 6 ~ 1e-12, round-off ~ 1e-16 h / step ~ 1e-10
    for d in RNG.uniform(-np.pi, np.pi, size=(10, 4)):
        H = lambda x: cluster_momentum(geo, x)  # noqa: E731
        fd = np.column_stack([H(d + step * e) - H(d - step * e) for e in np.eye(4)]) / (2 * step)
        np.testing.assert_allclose(cluster_jacobian(geo, d), fd, atol=1e-9)


@pytest.mark.parametrize("sym", [ca.SX, ca.MX])
def test_casadi_expressions_agree_with_numpy(sym):
    geo = pyramid(BETA, [1.0, 2.0, 0.5, 3.0])
    d = sym.sym("delta", 4)
    H, C, m = cluster_momentum(geo, d), cluster_jacobian(geo, d), singularity_measure(geo, d)
    assert isinstance(H, sym) and isinstance(C, sym) and isinstance(m, sym)
    f = ca.Function("f", [d], [H, C, ca.jacobian(H, d), m])
    for x in RNG.uniform(-np.pi, np.pi, size=(5, 4)):
        Hx, Cx, Jx, mx = (v.full() for v in f(x))
        np.testing.assert_allclose(Hx.ravel(), cluster_momentum(geo, x), atol=1e-14)
        np.testing.assert_allclose(Cx, cluster_jacobian(geo, x), atol=1e-14)
        np.testing.assert_allclose(Jx, Cx, atol=1e-14)  # CasADi's own derivative of H
        assert mx.item() == pytest.approx(singularity_measure(geo, x), rel=1e-12)


def test_batched_and_dm_input():
    geo = pyramid(BETA)
    d = RNG.uniform(-np.pi, np.pi, size=(4, 3, 2))
    C, m = cluster_jacobian(geo, d), singularity_measure(geo, d)
    assert C.shape == (3, 4, 3, 2) and m.shape == (3, 2)
    for idx in np.ndindex(3, 2):
        col = d[(slice(None), *idx)]
        np.testing.assert_allclose(C[(slice(None), slice(None), *idx)], cluster_jacobian(geo, col))
        assert m[idx] == pytest.approx(singularity_measure(geo, col), rel=1e-13)
    H = cluster_momentum(geo, ca.DM([0.1, 0.2, 0.3, 0.4]))
    assert isinstance(H, ca.DM)
    np.testing.assert_allclose(H.full().ravel(), cluster_momentum(geo, [0.1, 0.2, 0.3, 0.4]))


# ------------------------------------------------------------------------- input checks
G, S0 = np.eye(3)[:, [2, 2]], np.eye(3)[:, [0, 1]]  # two units gimbaled about e_z


def test_one_unit_may_be_given_as_3_vectors():
    one = ClusterGeometry(G[:, 0], S0[:, 0], 2.0)
    assert one.n == 1 and one.gimbal_axes.shape == (3, 1)
    np.testing.assert_array_equal(cluster_momentum(one, [0.0]), [2.0, 0.0, 0.0])


@pytest.mark.parametrize("gimbal, spin, h, name", [
    (G * [1, 0], S0, 1.0, "gimbal_axes[:, 1]"),  # zero axis
    (G * [1, 1.001], S0, 1.0, "gimbal_axes[:, 1]"),  # not unit
    (G, S0 * [1.0 + 1e-6, 1], 1.0, "spin_axes0[:, 0]"),
    (G, np.array([[1.0, 0], [0, 0.6], [0, 0.8]]), 1.0, "spin_axes0[:, 1]"),  # not perpendicular
    (G.T, S0.T, 1.0, "gimbal_axes"),  # (n, 3)
    (np.zeros((3, 0)), np.zeros((3, 0)), 1.0, "gimbal_axes"),  # n = 0
    (G, np.eye(3)[:, [0, 1, 1]], 1.0, "spin_axes0"),  # shape mismatch
    (G, S0, -1.0, "h"), (G, S0, 0.0, "h"), (G, S0, [1.0, 0.0], "h[1]"),
    (G, S0, [1.0, 2.0, 3.0], "h"), (G, S0, np.nan, "h"), (G, S0, [1.0, np.inf], "h"),
    (np.where(G == 1, np.nan, G), S0, 1.0, "gimbal_axes"),
    (G, np.where(S0 == 1, np.inf, S0), 1.0, "spin_axes0"),
])
def test_bad_geometry_raises_value_error_naming_the_argument(gimbal, spin, h, name):
    with pytest.raises(ValueError, match=re.escape(f"`{name}`")):
        ClusterGeometry(gimbal, spin, h)


@pytest.mark.parametrize("gimbal, spin, h, name", [
    ("z", S0, 1.0, "gimbal_axes"), (G, None, 1.0, "spin_axes0"), (G, S0, "big", "h"),
    (G, S0, [1.0, 1j], "h"), (G.astype(bool), S0, 1.0, "gimbal_axes"),
])
def test_non_numeric_geometry_raises_type_error(gimbal, spin, h, name):
    with pytest.raises(TypeError, match=f"`{name}`"):
        ClusterGeometry(gimbal, spin, h)


def test_bad_state_arguments():
    geo = pyramid(BETA)
    with pytest.raises(TypeError, match="`geometry`"):
        cluster_momentum("pyramid", np.zeros(4))
    with pytest.raises(ValueError, match="`delta`"):
        cluster_jacobian(geo, np.zeros(3))
    with pytest.raises(ValueError, match="`delta`"):
        singularity_measure(geo, ca.SX.sym("d", 3))
    with pytest.raises(ValueError, match="`delta`"):
        cluster_momentum(geo, [0, 0, np.nan, 0])
    with pytest.raises(TypeError, match="`delta`"):
        classify_singularity(geo, "zero")
    with pytest.raises(TypeError, match="`delta`"):
        singular_direction(geo, ca.SX.sym("d", 4))  # numeric only
    with pytest.raises(ValueError, match="`beta`"):
        pyramid(np.inf)


def test_geometry_is_immutable_and_owns_its_data():
    g, s0 = G.copy(), S0.copy()
    geo = ClusterGeometry(g, s0, [1.0, 2.0])
    g[0, 0] = 5.0
    assert geo.gimbal_axes[0, 0] == 0.0
    with pytest.raises(ValueError):
        geo.gimbal_axes[0, 0] = 1.0
    with pytest.raises(AttributeError):
        geo.h = np.ones(2)


def test_docstring_examples_run():
    result = doctest.testmod(cluster, optionflags=doctest.NORMALIZE_WHITESPACE | doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0
