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
from appdyn.dynamics.scene import (ExternalTorque, HeldRotor, PointMassDamper, ReactionWheels,
                                   RigidHub, Scene, Slosh, SphericalDamper, TiltTorque)
from appdyn.dynamics.spinning import point_mass_offset
from appdyn.problems import stability as st
from appdyn.problems.stability.spin_scene import spin_point
from tests.problems.test_stability import point_mass_polynomial, spherical_closed_form


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
@pytest.mark.slow
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


@pytest.mark.slow
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


# ------------------------------------------------------------------ energy dampers
M, K, C, R, W = 0.5, 60.0, 0.8, 0.6, 4.0


@pytest.mark.parametrize("I1, kind, verdict", [(5.0, "major", "asymptotically stable"),
                                               (2.0, "minor", "unstable"),
                                               (3.5, "intermediate", "unstable")])
def test_kelvin_tait_chetaev_point_mass_damper(I1, kind, verdict):
    """Hub (I1, 3, 4) spinning about e1, a mass at R e2 sliding along e1: loaded moments
    (I1 + m R^2, 3, 4 + m R^2); the hand-linearized polynomial gives the eigenvalues. The
    rigid hub alone is marginally stable about its major and minor axes."""
    hub = RigidHub([I1, 3.0, 4.0])
    scene = Scene(hub, PointMassDamper(M, K, C, position=(0, R, 0), direction=(1, 0, 0)))
    rep = st.spin(scene, [1, 0, 0], W)
    assert rep.verdict == verdict
    assert_eigenvalues(rep, point_mass_polynomial(I1 + M * R * R, 3.0, 4.0 + M * R * R, M, R,
                                                  K, C, W))
    assert rep.ss.state_labels == ["w2", "w3", "s", "s_dot"]
    assert {m.label for m in rep.modes} == {"nutation", "damper"}
    assert any(f"{kind} axis of the loaded body" in n for n in rep.notes)
    rigid = st.spin(Scene(hub), [1, 0, 0], W).verdict
    assert rigid == ("unstable" if kind == "intermediate" else "marginally stable")


@pytest.mark.parametrize("Ia, verdict", [(3.0, "asymptotically stable"), (1.5, "unstable")])
def test_kelvin_tait_chetaev_spherical_damper(Ia, verdict):
    It, Jd, c, W3 = 2.0, 0.05, 0.02, 10.0
    rep = st.spin(Scene(RigidHub([It, It, Ia]), SphericalDamper(Jd, c)), [0, 0, 1], W3)
    assert rep.verdict == verdict
    assert_eigenvalues(rep, spherical_closed_form(It, Ia, Jd, c, W3))
    assert rep.status == st.STATUS_VERIFIED  # the report's own closed form, checked
    assert rep.ss.state_labels == ["w1", "w2", "wd1", "wd2", "wd3"]


def test_point_mass_rests_at_its_centrifugal_offset():
    """A radial damper (along e2 at R e2) is pushed out: k s = mu W^2 (R + s); Newton finds
    the closed form `point_mass_offset`, and the spin stays a relative equilibrium."""
    damper = PointMassDamper(M, K, C, position=(0, R, 0), direction=(0, 1, 0))
    scene = Scene(RigidHub([5.0, 3.0, 4.0]), damper)
    pt = spin_point(scene, np.array([1.0, 0.0, 0.0]), W)
    s = point_mass_offset(damper, [1, 0, 0], W)
    assert pt.converged and pt.coordinates == ("s",)
    assert abs(pt.values[0] - s) <= 1e-14 * abs(s)
    assert abs(s - M * W * W * R / (K - M * W * W)) < 1e-14
    rep = st.spin(scene, [1, 0, 0], W)
    assert rep.linearization.x0[scene.layout["damper"].coords][0] == pt.values[0]
    # a radial damper in the spin plane is not excited by the nutation (decoupled to first
    # order): the nutation is that of the locked body, undamped
    r2 = M * (R + s) ** 2
    lam = 1j * W * np.sqrt((5.0 + r2 - 3.0) * (5.0 + r2 - 4.0 - r2) / (3.0 * (4.0 + r2)))
    nutation = [z for z in rep.eigenvalues if abs(z.real) <= 1e-12]
    np.testing.assert_allclose(sorted_ev(nutation), sorted_ev([lam, -lam]), rtol=1e-9)
    assert rep.verdict == "marginally stable"


def test_slosh_pendulum_swings_out_radially():
    """A pendulum hinged at e2 whose rest direction (0, 0.8, 0.6) leans out of the spin
    plane: spinning about e1 it swings out along the radius e2 (an angle atan2(0.6, 0.8) from
    its rest direction), a relative equilibrium; damped, about the major axis: asymptotically
    stable, its modes labelled by the part."""
    scene = Scene(RigidHub([50.0, 30.0, 40.0]),
                  Slosh(1.0, length=0.5, hinge=(0, 1.0, 0), direction=(0, 0.8, 0.6),
                        damping=0.01))
    rep = st.spin(scene, [1, 0, 0], 2.0)
    theta = rep.linearization.x0[scene.layout["pendulum"].coords]
    assert abs(np.hypot(*theta) - np.arctan2(0.6, 0.8)) < 1e-12
    assert rep.verdict == "asymptotically stable" and rep.status == st.STATUS_UNCHECKED
    assert {m.label for m in rep.modes} == {"nutation", "pendulum"}


def test_spring_the_centrifugal_load_cancels_finds_no_rest():
    damper = PointMassDamper(M, M * W * W, C, position=(0, R, 0), direction=(0, 1, 0))
    with pytest.raises(ValueError, match="parts find no rest.*Stiffen"):
        st.spin(Scene(RigidHub([5.0, 3.0, 4.0]), damper), [1, 0, 0], W)


def test_two_dampers_label_their_modes_by_part():
    """No closed form for two dampers: the status says unchecked, the verdict is still
    Kelvin-Tait-Chetaev's (major axis, energy dissipated: asymptotically stable), and each
    damper's modes carry its scene name."""
    scene = Scene(RigidHub([5.0, 3.0, 4.0]),
                  PointMassDamper(M, K, C, position=(0, R, 0), direction=(1, 0, 0)),
                  PointMassDamper(M, 2 * K, C, position=(0, 0, R), direction=(1, 0, 0)))
    rep = st.spin(scene, [1, 0, 0], W)
    assert rep.status == st.STATUS_UNCHECKED
    assert rep.verdict == "asymptotically stable"
    assert rep.ss.state_labels == ["w2", "w3", "s", "s_dot", "s_2", "s_dot_2"]
    assert {m.label for m in rep.modes} <= {"nutation", "damper", "damper_2"}
    assert "damper_2" in {m.label for m in rep.modes}


def test_damper_wrappers_equal_the_scene_spin():
    """`spin(inertia, damper=...)` and `gyrostat(..., damper=...)` build these scenes."""
    damper = PointMassDamper(M, K, C, position=(0, R, 0), direction=(1, 0, 0))
    a = st.spin([5.0, 3.0, 4.0], [1, 0, 0], W, damper=damper)
    b = st.spin(Scene(RigidHub([5.0, 3.0, 4.0]), damper), [1, 0, 0], W)
    np.testing.assert_allclose(a.eigenvalues, b.eigenvalues, rtol=0, atol=1e-13)
    sph = SphericalDamper(0.1, 0.05)
    g = st.gyrostat([3.0, 4.0, 4.0], [1, 0, 0], 2.0, 1.0, damper=sph)
    h = st.spin(Scene(RigidHub([3.0, 4.0, 4.0]), HeldRotor([1, 0, 0], 1.0), sph), [1, 0, 0], 2.0)
    np.testing.assert_allclose(g.eigenvalues, h.eigenvalues, rtol=0, atol=1e-13)
    assert g.closed_form_error < 1e-8


# ------------------------------------------------------------------ tilt torque (Method III)
I1_TOP, I2_TOP, MGL = 0.002, 0.005, 0.3 * 9.80665 * 0.04


@pytest.mark.parametrize("factor", [1.5, 3.0, -2.0, 0.7, 0.0])
def test_heavy_top_scene_eq_4_127(factor):
    """Hub (I1, I2, I2) about the pivot with gravity's tilt torque kappa = m g l, spinning
    upright at w0 = factor * the sleeping rate (Eq. 4.128): the roots of Eq. 4.127,
    s = i [(2 I2 - I1) w0 / (2 I2) +/- sqrt((I1 w0 / (2 I2))^2 - m g l / I2)], and conjugates,
    in the frame spinning at w0; the spin phase goes by quotient, the spin rate with the
    energy (or, at w0 = 0, as the rate no torque changes)."""
    w0 = factor * 2 / I1_TOP * np.sqrt(MGL * I2_TOP)
    scene = Scene(RigidHub([I1_TOP, I2_TOP, I2_TOP]), TiltTorque(MGL))
    rep = st.spin(scene, [1, 0, 0], w0)
    a = I1_TOP * w0 / (2 * I2_TOP)
    root = np.sqrt(complex(a * a - MGL / I2_TOP))
    lam = [1j * ((2 * I2_TOP - I1_TOP) * w0 / (2 * I2_TOP) + sgn * root) for sgn in (1, -1)]
    assert_eigenvalues(rep, lam + [np.conj(z) for z in lam], rtol=1e-8)
    assert rep.verdict == ("marginally stable" if abs(factor) > 1 else "unstable")
    assert rep.ss.state_labels == ["dth2", "dth3", "w2", "w3"]
    assert rep.status == st.STATUS_VERIFIED and {m.label for m in rep.modes} == {"nutation"}


@pytest.mark.parametrize("w0, verdict", [(50.0, "asymptotically stable"), (90.0, "unstable")])
def test_rotor_internal_damping_scene(w0, verdict):
    """Bearings kappa = -2 k l^2, internal damping D: unstable above
    w0^2 = 2 k l^2 / (I2 - I1) = 5000 (Kelvin-Tait-Chetaev, RP-1262 NOTE); no first integral
    is left, the axial rate goes as constant to first order."""
    scene = Scene(RigidHub([0.01, 0.05, 0.05]), TiltTorque(-2e4 * 0.01, internal_damping=0.01))
    rep = st.spin(scene, [1, 0, 0], w0)
    assert rep.verdict == verdict
    assert any("constant to first order" in n for n in rep.notes)
    np.testing.assert_allclose(rep.eigenvalues, st.rotor(0.01, 0.05, 1e4, 0.1, w0,
                                                         internal_damping=0.01).eigenvalues,
                               rtol=0, atol=1e-12 * w0)


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
    (lambda: st.spin(Scene(RigidHub([1.0, 2.0, 3.0])), [1, 0, 0], 1.0,
                     damper=st.SphericalDamper(0.1, 0.1)), "`damper`"),
    (lambda: st.spin("a scene", [1, 0, 0], 1.0), "inertia"),
])
def test_bad_input_names_the_argument(call, match):
    with pytest.raises((ValueError, TypeError), match=match):
        call()


@pytest.mark.parametrize("reference", [None, [0.3, -0.2, 0.1]])
@pytest.mark.parametrize("axis", [[1, 0, 0], [0, 1, 0]])
def test_a_translating_hub_spins_as_the_attitude_only_hub(reference, axis):
    """A free spinner's translation decouples: the six-degree-of-freedom hub (about its mass
    centre or another reference point, whose velocity at P = 0 is then w x reference) has
    the eigenvalues and verdict of the attitude-only hub, and the states of its attitude."""
    I = [2.0, 3.0, 4.5]
    rep = st.spin(Scene(RigidHub(I, mass=5.0, reference=reference)), axis, 3.0)
    ref = st.spin(Scene(RigidHub(I)), axis, 3.0)
    assert rep.verdict == ref.verdict and rep.ss.state_labels == ref.ss.state_labels
    assert np.allclose(np.sort_complex(rep.eigenvalues), np.sort_complex(ref.eigenvalues),
                       rtol=1e-12, atol=1e-12)


def test_the_attitude_subsystem_holds_the_mass_centre():
    """``v`` at P = 0 is w x (reference from the mass centre) in hub axes: the reduced
    right-hand side is the full one there, without the rows of r and v."""
    from appdyn.problems.stability.spin_scene import attitude_subsystem

    scene = Scene(RigidHub([2.0, 3.0, 4.5], mass=5.0, reference=[0.3, -0.2, 0.1]))
    model, full = attitude_subsystem(scene), scene.model()
    assert model.states == full.states[:7] and "momentum_linear" not in model.invariants
    w = np.array([0.4, -1.0, 2.0])
    y = scene.state(w=w)[:7]
    v = np.cross(w, [0.3, -0.2, 0.1])
    x = scene.state(w=w, v=v)
    assert np.allclose(np.asarray(full.invariants["momentum_linear"](x, [])).ravel(), 0,
                       atol=1e-14)
    assert np.allclose(np.asarray(model.f(y, [], [])).ravel(),
                       np.asarray(full.f(x, [], [])).ravel()[:7], rtol=1e-14, atol=1e-14)


@pytest.mark.slow
def test_sweep_over_the_rate_of_a_scene():
    """`sweep` runs spin(scene, ...) too: a held rotor h = 3 on a hub (3, 4, 5) is unstable
    while Ia + h/W lies between 4 and 5, i.e. for h/(Ic - Ia) = 1.5 < W < h/(Ib - Ia) = 3."""
    scene = Scene(RigidHub([3.0, 4.0, 5.0]), HeldRotor([1, 0, 0], 3.0))
    res = st.sweep("spin", "rate", np.linspace(1.0, 4.0, 7), inertia=scene, axis=[1, 0, 0])
    values = sorted(b.value for b in res.boundaries)
    np.testing.assert_allclose(values, [1.5, 3.0], atol=1e-6)
