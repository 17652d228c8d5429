"""`stability.spin(scene, axis, rate)`: the spin of a scene against the closed forms.

Truths: the rigid body's Euler-equation perturbations (RP-1262, Sec. 4.5 C, Eqs. 4.94-4.95),
the gyrostat's (``I w' = -w x (I w + h a)``, seed Sec. 4.7) with its stability boundaries
``h = (Ib - Ia) W`` and ``(Ic - Ia) W``, and free reaction wheels, whose absolute axial momenta
``J_i (a_i.w + W_i)`` are conserved: at rest relative to a hub spinning at ``W a`` they act as
a gyrostat of momentum ``h = J W`` on the axis, the transverse wheels adding nothing.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as hs

from appdyn.dynamics.attitude import dcm_from_quat
from appdyn.dynamics.scene import (ExternalTorque, HeldRotor, ReactionWheels, RigidHub, Scene)
from appdyn.problems import stability as st
from appdyn.problems.stability.spin_scene import spin_point


def sorted_ev(z):
    return np.array(sorted(np.asarray(z, complex), key=lambda v: (round(v.real, 9), v.imag)))


def assert_eigenvalues(rep, expected, rtol=1e-9):
    got, want = sorted_ev(rep.eigenvalues), sorted_ev(expected)
    assert got.shape == want.shape
    scale = max(1.0, np.max(np.abs(want)))
    assert np.max(np.abs(got - want)) <= rtol * scale, (got, want)


def gyrostat_roots(Ia, Ib, Ic, W, h):
    lam = np.sqrt(complex(-(Ia * W + h - Ib * W) * (Ia * W + h - Ic * W) / (Ib * Ic)))
    return [lam, -lam]


def rotation(angles):
    return dcm_from_quat(np.array([*np.sin(angles[0] / 2) * np.array(
        [np.cos(angles[1]) * np.cos(angles[2]), np.sin(angles[1]) * np.cos(angles[2]),
         np.sin(angles[2])]), np.cos(angles[0] / 2)]))


# ------------------------------------------------------------------ rigid hub
@pytest.mark.parametrize("which, verdict", [(0, "marginally stable"), (1, "unstable"),
                                            (2, "marginally stable")])
def test_rigid_hub_minor_intermediate_major(which, verdict):
    I = np.array([2.0, 3.0, 4.5])
    rep = st.spin(Scene(RigidHub(I)), np.eye(3)[which], 10.0)
    Ia, Ib, Ic = I[which], *np.delete(I, which)
    lam = 1j * 10.0 * np.sqrt(complex((Ia - Ib) * (Ia - Ic) / (Ib * Ic)))
    assert_eigenvalues(rep, [lam, -lam])
    assert rep.verdict == verdict and rep.status == st.STATUS_VERIFIED
    assert rep.ss.state_labels == [s for s in ("w1", "w2", "w3") if s != f"w{which + 1}"]
    assert {m.label for m in rep.modes} == {"nutation"}


@settings(max_examples=20, deadline=None)
@given(moments=hs.tuples(*[hs.floats(1.0, 10.0)] * 2), third=hs.floats(0.0, 1.0),
       angles=hs.tuples(*[hs.floats(-np.pi, np.pi)] * 3), which=hs.integers(0, 2),
       rate=hs.floats(0.1, 50.0))
def test_rigid_hub_any_principal_axis_closed_form(moments, third, angles, which, rate):
    """Random principal moments (triangle inequality held) in random hub axes; the scene's
    spin equals the inertia path's (the same report machinery) and the closed form."""
    a, b = moments
    I_p = np.array([a, b, max(abs(a - b) + third * (a + b - abs(a - b)), 0.05)])
    R = rotation(angles)
    inertia = R.T @ np.diag(I_p) @ R
    inertia = 0.5 * (inertia + inertia.T)
    Ia, Ib, Ic = I_p[which], *np.delete(I_p, which)
    lam = 1j * rate * np.sqrt(complex((Ia - Ib) * (Ia - Ic) / (Ib * Ic)))
    if abs(lam) < 1e-4 * rate:
        return  # (nearly) equal moments: a double eigenvalue at 0
    rep = st.spin(Scene(RigidHub(inertia)), R[which], rate)
    assert_eigenvalues(rep, [lam, -lam], rtol=1e-8)
    assert rep.verdict == ("unstable" if lam.imag == 0 else "marginally stable")
    np.testing.assert_array_equal(rep.eigenvalues, st.spin(inertia, R[which], rate).eigenvalues)


# ------------------------------------------------------------------ gyrostat (held rotor)
@pytest.mark.parametrize("h", [-3.0, 0.0, 1.0, 1.9, 2.1, 3.0, 3.9, 4.1, 6.0])
def test_held_rotor_gyrostat_boundaries(h):
    """Unstable iff (Ib - Ia) W < h < (Ic - Ia) W (boundaries 2 and 4 N m s here)."""
    Ia, Ib, Ic, W = 3.0, 4.0, 5.0, 2.0
    rep = st.spin(Scene(RigidHub([Ia, Ib, Ic]), HeldRotor([1, 0, 0], h)), [1, 0, 0], W)
    assert_eigenvalues(rep, gyrostat_roots(Ia, Ib, Ic, W, h))
    inside = (Ib - Ia) * W < h < (Ic - Ia) * W
    assert rep.verdict == ("unstable" if inside else "marginally stable")
    assert rep.status == st.STATUS_VERIFIED
    wrapped = st.gyrostat([Ia, Ib, Ic], [1, 0, 0], W, h)  # the wrapper builds this scene
    np.testing.assert_allclose(wrapped.eigenvalues, rep.eigenvalues, rtol=0, atol=1e-14)
    assert wrapped.verdict == rep.verdict


def test_held_rotor_boundaries_by_sweep_bisection():
    """The verdict boundaries of the scene spin, located by bisection on the momentum."""
    Ia, Ib, Ic, W = 3.0, 4.0, 5.0, 2.0

    def unstable(h):
        scene = Scene(RigidHub([Ia, Ib, Ic]), HeldRotor([1, 0, 0], h))
        return st.spin(scene, [1, 0, 0], W).verdict == "unstable"

    for lo, hi, truth in ((0.0, 3.0, (Ib - Ia) * W), (6.0, 3.0, (Ic - Ia) * W)):
        for _ in range(30):
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if unstable(mid) else (mid, hi)
        assert abs(0.5 * (lo + hi) - truth) < 1e-7


def test_held_rotor_despun_platform():
    """W = 0: the rotor alone stiffens the platform, eigenvalues +/- i h / sqrt(Ib Ic)."""
    rep = st.spin(Scene(RigidHub([3.0, 4.0, 5.0]), HeldRotor([1, 0, 0], 2.0)), [1, 0, 0], 0.0)
    assert_eigenvalues(rep, [2j / np.sqrt(20.0), -2j / np.sqrt(20.0)])
    assert rep.verdict == "marginally stable"


# ------------------------------------------------------------------ reaction wheels
@pytest.mark.parametrize("which", [0, 1, 2])
def test_reaction_wheels_at_rest_spin_like_a_gyrostat(which):
    """Three free wheels at zero relative speed: a gyrostat of momentum J W on the axis; the
    hub's transverse moments alone (the transverse wheels turn freely)."""
    I, J, W = np.array([4.0, 4.1, 4.15]), 0.2, 2.0
    scene = Scene(RigidHub(I), ReactionWheels(np.eye(3), J), ExternalTorque())
    rep = st.spin(scene, np.eye(3)[which], W)
    Ia, Ib, Ic = I[which], *np.delete(I, which)
    assert_eigenvalues(rep, gyrostat_roots(Ia, Ib, Ic, W, J * W))
    assert rep.status == st.STATUS_VERIFIED
    assert rep.ss.state_labels == [s for s in ("w1", "w2", "w3") if s != f"w{which + 1}"]
    # the rigid body with the wheels locked would say otherwise about axis 1 (minor: 4.2 <
    # 4.3, 4.35): the free transverse wheels do not count
    expected = "unstable" if Ib < Ia + J < Ic or Ic < Ia + J < Ib else "marginally stable"
    assert rep.verdict == expected
    # the spin point: wheels at rest relative to the hub
    x = rep.linearization.x0
    lay = scene.model().layout["wheels"]
    np.testing.assert_array_equal(x[lay.states], 0.0)


def test_reaction_wheels_intermediate_axis_made_stable():
    """Hub intermediate about e1 (3.9 between 3.8 and 4.0); an axial wheel of J = 0.2 makes
    Ia + J = 4.1 the major moment: the spin becomes marginally stable."""
    I = [3.9, 3.8, 4.0]
    assert st.spin(Scene(RigidHub(I)), [1, 0, 0], 1.0).verdict == "unstable"
    rep = st.spin(Scene(RigidHub(I), ReactionWheels([1.0, 0.0, 0.0], 0.2)), [1, 0, 0], 1.0)
    assert rep.verdict == "marginally stable"
    assert_eigenvalues(rep, gyrostat_roots(3.9, 3.8, 4.0, 1.0, 0.2))


def test_spin_point_of_parts_without_coordinates_is_the_scene_state():
    scene = Scene(RigidHub([1.0, 2.0, 3.0]), ReactionWheels(np.eye(3), 0.1))
    pt = spin_point(scene, np.array([0.0, 0.0, 1.0]), 3.0)
    np.testing.assert_array_equal(pt.x, scene.state(w=[0.0, 0.0, 3.0]))
    assert pt.converged and pt.coordinates == ()


# ------------------------------------------------------------------ bad input
def test_axis_not_principal_for_the_hub_is_refused_with_the_residual():
    I = np.array([[2.0, 0.3, 0.0], [0.3, 3.0, 0.0], [0.0, 0.0, 4.5]])
    with pytest.raises(ValueError, match=r"`axis`.*principal.*d\(w3\)/dt"):
        st.spin(Scene(RigidHub(I)), [1, 0, 0], 2.0)


def test_rotor_off_the_spin_axis_is_not_a_relative_equilibrium():
    scene = Scene(RigidHub([3.0, 4.0, 5.0]), HeldRotor([0, 1, 0], 1.0))
    with pytest.raises(ValueError, match="no relative equilibrium"):
        st.spin(scene, [1, 0, 0], 2.0)


@pytest.mark.parametrize("call, match", [
    (lambda: st.spin(Scene(RigidHub([1.0, 2.0, 3.0])), [0, 0, 0], 1.0), "`axis`"),
    (lambda: st.spin(Scene(RigidHub([1.0, 2.0, 3.0])), [1, 0, 0], np.nan), "`rate`"),
    (lambda: st.spin(Scene(RigidHub([1.0, 2.0, 3.0])), [1, 0, 0], "fast"), "`rate`"),
    (lambda: st.spin(Scene(RigidHub([1.0, 2.0, 3.0], mass=5.0)), [1, 0, 0], 1.0), "`scene`"),
    (lambda: st.spin(Scene(RigidHub([1.0, 2.0, 3.0])), [1, 0, 0], 1.0,
                     damper=st.SphericalDamper(0.1, 0.1)), "`damper`"),
    (lambda: st.spin("a scene", [1, 0, 0], 1.0), "inertia"),
])
def test_bad_input_names_the_argument(call, match):
    with pytest.raises((ValueError, TypeError), match=match):
        call()
