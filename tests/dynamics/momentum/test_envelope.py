"""Singular surfaces and the momentum envelope.

Independent truths: the pyramid's closed-form extents 2 h (1 + cos beta) along x, y and
4 h sin beta along z (Wie, Sec. 7.3), and in general the support function
``sum_i h_i |a - (a.g_i) g_i|`` of the reachable momentum (each unit's spin axis alone
maximizes ``a.s_i``); the definition of a singular state (``C^T u = 0``, smallest singular
value of ``C`` zero) checked with `cluster_jacobian` and numpy's SVD; `cluster_momentum` at
the returned angles; `classify_singularity` (the scalar classifier) on samples; the known
states of the design notes' truth catalogue.
"""
import doctest
import importlib
import json
import time

import numpy as np
import pytest

from appdyn.dynamics.momentum import (ClusterGeometry, MomentumEnvelope, classify_singularities,
                               classify_singularity, cluster_jacobian, cluster_momentum,
                               fibonacci_directions, momentum_envelope, pyramid, singular_surface,
                               singularity_measure)

BETA = np.deg2rad(54.74)
GEO = pyramid(BETA)
RNG = np.random.default_rng(11)


@pytest.fixture(scope="module")
def env():
    return momentum_envelope(GEO)


def support(geo, axis):
    """max over all gimbal states of axis . H = sum_i h_i |axis_perp_i| (closed form)."""
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    return float(np.sum(geo.h * np.sqrt(1.0 - (a @ geo.gimbal_axes) ** 2)))


def test_pyramid_extent_matches_closed_form_to_1e9(env):
    cb, sb = np.cos(BETA), np.sin(BETA)
    assert env.max_momentum([1, 0, 0]) == pytest.approx(2 * (1 + cb), abs=1e-9)
    assert env.max_momentum([0, 1, 0]) == pytest.approx(2 * (1 + cb), abs=1e-9)
    assert env.max_momentum([0, 0, 1]) == pytest.approx(4 * sb, abs=1e-9)
    assert env.max_momentum([0, 0, -3]) == pytest.approx(4 * sb, abs=1e-9)  # symmetric
    assert (2 * (1 + cb), 4 * sb) == pytest.approx((3.155, 3.266), abs=1e-3)
    ext = env.extent
    assert [ext[a] for a in "xyz"] == pytest.approx([2 * (1 + cb)] * 2 + [4 * sb], abs=1e-9)


def test_max_momentum_is_the_support_function_for_any_axis_and_rotors():
    geo = pyramid(np.deg2rad(40.0), [1.0, 2.0, 1.5, 0.5])
    env = momentum_envelope(geo, directions=300)  # coarse sampling, refined by the search
    for axis in RNG.normal(size=(8, 3)):
        assert env.max_momentum(axis) == pytest.approx(support(geo, axis), abs=1e-9)
        sampled = np.max(axis / np.linalg.norm(axis) @ env.points[0])
        assert sampled <= env.max_momentum(axis) + 1e-12


def test_surface_points_are_singular_with_the_momentum_they_claim(env):
    for k, H in env.points.items():
        delta = env.delta[k]
        assert np.max(np.abs(cluster_momentum(GEO, delta) - H)) < 1e-12
        C = np.moveaxis(cluster_jacobian(GEO, delta), -1, 0)
        sigma_min = np.linalg.svd(C, compute_uv=False)[:, -1]
        assert np.max(sigma_min) < 1e-12
        assert np.max(singularity_measure(GEO, delta)) < 1e-6  # sqrt of a round-off det
    assert {k: v.shape[1] for k, v in env.points.items()} == {0: 4000, 1: 16000, 2: 12000}


def test_singular_direction_annihilates_the_jacobian():
    u = fibonacci_directions(400)
    for signs in ([1, 1, 1, 1], [1, -1, 1, 1], [-1, 1, 1, -1]):
        pts = singular_surface(GEO, u, signs)
        C = cluster_jacobian(GEO, pts.delta)  # (3, n, m)
        residual = np.einsum("im,inm->nm", u[:, pts.index], C)
        assert np.max(np.abs(residual)) < 1e-14
        assert pts.index.size == 400


def test_direction_along_a_gimbal_axis_is_skipped():
    u = np.column_stack([GEO.gimbal_axes[:, 0], [1.0, 0.0, 0.0], 2 * GEO.gimbal_axes[:, 2]])
    pts = singular_surface(GEO, u, [1, 1, 1, 1])
    assert pts.index.tolist() == [1]
    assert pts.H.shape == (3, 1) and pts.delta.shape == (4, 1)


@pytest.mark.slow
def test_outer_surface_is_elliptic_and_internal_surfaces_have_both_kinds(env):
    assert set(env.kinds[0]) == {"elliptic"}
    for k in (1, 2):
        kinds = set(env.kinds[k])
        assert {"elliptic", "hyperbolic"} <= kinds
    counts = env.counts()
    assert all(c["nonsingular"] == 0 for c in counts.values())
    # the saturation surface is the outermost: every internal point lies inside it
    for k in (1, 2):
        H = env.points[k]
        u = H / np.linalg.norm(H, axis=0)
        assert np.all(np.einsum("im,im->m", u, H) <= [support(GEO, c) + 1e-12 for c in u.T])


def test_mirror_patterns_give_the_mirrored_surface():
    u = fibonacci_directions(200)
    a = singular_surface(GEO, u, [1, -1, 1, 1])
    b = singular_surface(GEO, u, [-1, 1, -1, -1])  # k = 3 negative signs: H -> -H
    assert np.max(np.abs(a.H + b.H)) < 1e-14
    c = singular_surface(GEO, -u, [-1, 1, -1, -1])  # and (-u, -eps) is the same point
    assert np.max(np.abs(a.H - c.H)) < 1e-14


def test_vectorised_classification_agrees_with_the_scalar_one(env):
    for k in env.points:
        idx = RNG.choice(env.kinds[k].size, 150, replace=False)
        scalar = [classify_singularity(GEO, env.delta[k][:, j]) for j in idx]
        assert env.kinds[k][idx].tolist() == scalar
    random_states = RNG.uniform(-np.pi, np.pi, (4, 50))
    assert set(classify_singularities(GEO, random_states)) == {"nonsingular"}


def test_catalogue_states():
    # design notes: (-90, 0, 90, 0) elliptic at H = (1.155, 0, 0); (90, -90, 90, -90) and
    # (90, 0, 90, 0) hyperbolic, at H = 0 and (0, 0, 1.633)
    states = np.deg2rad([[-90, 0, 90, 0], [90, -90, 90, -90], [90, 0, 90, 0]]).T
    assert classify_singularities(GEO, states).tolist() == ["elliptic", "hyperbolic", "hyperbolic"]
    pts = singular_surface(GEO, [1.0, 0.0, 0.0], [1, -1, 1, 1])
    assert pts.H[:, 0] == pytest.approx([2 * np.cos(BETA), 0, 0], abs=1e-12)
    assert np.degrees(pts.delta[:, 0]) == pytest.approx([-90, 0, 90, 0], abs=1e-12)
    assert np.round(cluster_momentum(GEO, states[:, 2]), 3).tolist() == [0.0, 0.0, 1.633]


def test_default_envelope_is_fast():
    start = time.perf_counter()
    env = momentum_envelope(pyramid(BETA, 2.0))
    _ = str(env)
    assert time.perf_counter() - start < 3.0
    assert env.max_momentum([1, 0, 0]) == pytest.approx(4 * (1 + np.cos(BETA)), abs=1e-9)


@pytest.mark.slow
def test_result_text_json_and_plot(env):
    text = str(env)
    assert "k=0 (saturation)" in text and "extent along x, y, z" in text and "100.0%" in text

    def refuse(name):
        raise ValueError(name)

    data = json.loads(env.to_json(), parse_constant=refuse)
    assert data["groups"]["0"]["points"] == 4000 and data["groups"]["0"]["elliptic"] == 4000
    assert np.array(data["groups"]["1"]["H"]["hyperbolic"]).shape[0] == 3
    assert data["extent"]["z"] == pytest.approx(4 * np.sin(BETA), abs=1e-9)
    fig = env.plot()
    assert type(fig).__name__ == "Figure" and len(fig.axes) == 3
    assert fig.axes[0].get_xlabel() == "H_x [N m s]"
    assert isinstance(env, MomentumEnvelope)


def test_bad_input_names_the_argument():
    with pytest.raises(TypeError, match="`geometry`"):
        momentum_envelope("pyramid")
    with pytest.raises(ValueError, match="`directions`"):
        momentum_envelope(GEO, directions=10)
    with pytest.raises(TypeError, match="`directions`"):
        momentum_envelope(GEO, directions=100.5)
    with pytest.raises(ValueError, match="`signs`"):
        singular_surface(GEO, [1.0, 0.0, 0.0], [1, 0, 1, 1])
    with pytest.raises(ValueError, match="`signs`"):
        singular_surface(GEO, [1.0, 0.0, 0.0], [1, 1, 1])
    with pytest.raises(ValueError, match="`directions"):
        singular_surface(GEO, [0.0, 0.0, 0.0], [1, 1, 1, 1])
    with pytest.raises(TypeError, match="`geometry`"):
        singular_surface(np.eye(3), [1.0, 0.0, 0.0], [1, 1, 1])
    with pytest.raises(ValueError, match="`delta`"):
        classify_singularities(GEO, np.zeros((3, 5)))
    with pytest.raises(ValueError, match="`axis`"):
        momentum_envelope(GEO, directions=60).max_momentum([0, 0, 0])
    with pytest.raises(ValueError, match="`count`"):
        fibonacci_directions(0)


def test_two_unit_cluster_is_always_singular():
    geo = ClusterGeometry([[0.0, 0.0], [0.0, 1.0], [1.0, 0.0]],
                          [[1.0, 1.0], [0.0, 0.0], [0.0, 0.0]])
    env = momentum_envelope(geo, directions=100)
    assert sorted(env.points) == [0, 1]
    assert env.max_momentum([1, 0, 0]) == pytest.approx(support(geo, [1, 0, 0]), abs=1e-9)


def test_docstring_examples():
    module = importlib.import_module("appdyn.dynamics.momentum.envelope")
    result = doctest.testmod(module, optionflags=doctest.NORMALIZE_WHITESPACE | doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0
