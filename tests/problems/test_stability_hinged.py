"""`problems.stability.hinged_spin`: two hinged bodies spinning together about a common axis,
reduced to the independent coordinates and checked against closed forms derived here."""
import json
import math

import numpy as np
import pytest

from appdyn.problems import stability as st

BASE = dict(m1=10.0, inertia1=[2.0, 2.0, 3.0], m2=2.0, inertia2=[0.2, 0.2, 0.3],
            r1=[0.0, 0.0, 0.5], r2=[0.0, 0.0, -0.2], rate=5.0)


def _sorted(ev):
    return np.array(sorted(np.asarray(ev, complex), key=lambda z: (round(z.imag, 9), z.real)))


def _locked_inertia(m1, I1, m2, I2, r1, r2):
    """Independent: the pair locked, about the system mass centre (parallel axes)."""
    I1, I2 = (np.diag(I) if np.ndim(I) == 1 else np.asarray(I, float) for I in (I1, I2))
    M = m1 + m2
    c1, c2 = np.zeros(3), np.asarray(r1, float) - np.asarray(r2, float)  # C1, C2
    G = (m1 * c1 + m2 * c2) / M
    def shift(m, c):
        return m * (np.dot(c - G, c - G) * np.eye(3) - np.outer(c - G, c - G))

    return I1 + I2 + shift(m1, c1) + shift(m2, c2)


def _rigid_roots(I, W):
    Ix, Iy, Iz = I[0, 0], I[1, 1], I[2, 2]
    lam = np.sqrt(complex(-W * W * (Iz - Ix) * (Iz - Iy) / (Ix * Iy)))
    return np.array([lam, -lam])


@pytest.mark.parametrize("rate", [5.0, -2.0, 40.0])
def test_revolute_nutation_is_the_locked_rigid_body(rate):
    rep = st.hinged_spin(**{**BASE, "rate": rate})
    I = _locked_inertia(BASE["m1"], BASE["inertia1"], BASE["m2"], BASE["inertia2"],
                        BASE["r1"], BASE["r2"])
    It, Iz = I[0, 0], I[2, 2]
    nut = abs(rate * (Iz - It) / It)                       # w (Iz - It) / It
    assert rep.ss.state_labels == ["w1", "w2"]
    assert rep.verdict == "marginally stable" and rep.status == st.STATUS_VERIFIED
    got = sorted(abs(z.imag) for z in rep.eigenvalues)
    assert np.allclose(got, [nut, nut], rtol=1e-8, atol=0)
    assert np.max(np.abs(np.real(rep.eigenvalues))) <= 1e-8 * nut
    assert rep.quantity("nutation").value == pytest.approx(nut, rel=1e-8)


def test_revolute_intermediate_axis_is_unstable_and_matches_spin():
    args = {**BASE, "inertia1": [2.0, 4.0, 3.0]}        # locked Ix 3.02 < Iz 3.3 < Iy 5.02
    rep = st.hinged_spin(**args)
    I = _locked_inertia(args["m1"], args["inertia1"], args["m2"], args["inertia2"],
                        args["r1"], args["r2"])
    assert I[0, 0] < I[2, 2] < I[1, 1]
    expected = _rigid_roots(I, args["rate"])
    assert rep.verdict == "unstable" and rep.status == st.STATUS_VERIFIED
    assert np.allclose(_sorted(rep.eigenvalues.real), _sorted(expected.real), rtol=1e-8, atol=0)
    assert np.max(np.abs(rep.eigenvalues.imag)) <= 1e-8 * np.max(np.abs(expected))
    # the same as the rigid body of the locked inertia through `spin`
    ref = st.spin(I, [0, 0, 1], args["rate"])
    assert np.allclose(np.sort(rep.eigenvalues.real), np.sort(ref.eigenvalues.real), rtol=1e-8)


def test_revolute_non_axisymmetric_major_axis_is_marginally_stable():
    args = {**BASE, "inertia1": [2.0, 2.5, 4.0], "inertia2": [0.2, 0.25, 0.4]}
    rep = st.hinged_spin(**args)
    I = _locked_inertia(args["m1"], args["inertia1"], args["m2"], args["inertia2"],
                        args["r1"], args["r2"])
    expected = _rigid_roots(I, args["rate"])
    assert rep.verdict == "marginally stable"
    assert np.allclose(np.sort(np.abs(rep.eigenvalues.imag)), np.sort(np.abs(expected.imag)),
                       rtol=1e-8, atol=0)


@pytest.mark.parametrize("geometry", [
    dict(),
    dict(m1=3.0, inertia1=[1.0, 1.0, 0.5], m2=5.0, inertia2=[0.4, 0.4, 0.7],
         r1=[0, 0, 0.3], r2=[0, 0, -0.6], rate=-4.0),
    dict(m1=1.0, inertia1=[0.3, 0.3, 0.2], m2=1.0, inertia2=[0.3, 0.3, 0.2],
         r1=[0, 0, -0.4], r2=[0, 0, 0.1], rate=12.0)])
def test_ball_tilts_match_the_lagrangian(geometry):
    args = {**BASE, "kind": "ball", **geometry}
    rep = st.hinged_spin(**args)
    W = args["rate"]
    # inertial circular frequencies w (signed) -> frame spinning at W: |w - W|
    freqs = sorted([abs(W)] + [abs(w - W) for w in _signed_frequencies(args)])
    assert rep.ss.state_labels == ["w1", "w2", "q1_rel", "q2_rel", "w1_2", "w2_2"]
    assert rep.verdict == "marginally stable" and rep.status == st.STATUS_VERIFIED
    got = sorted(abs(z.imag) for z in rep.eigenvalues)
    assert np.allclose(got, np.repeat(freqs, 2), rtol=1e-8, atol=0)


def _signed_frequencies(args):
    """Independent reduced-coordinate linearization of the ball-hinged axisymmetric pair.

    Generalized coordinates: the transverse tilts ``zeta_i = u_ix + i u_iy`` of the symmetry
    axes; hinge at ``O``, ``C1 = O - l1 e1``, ``C2 = O + l2 e2``, system mass centre fixed, so
    the transverse mass-centre offsets are ``-(m2/M) s`` and ``(m1/M) s``,
    ``s = l1 zeta1 + l2 zeta2``. Lagrangian to second order (inertial frame, symmetric-top
    gyroscopic term): ``A_i zeta_i'' - i C_i W zeta_i' + mu l_i s'' = 0``. With
    ``zeta ~ exp(i w t)`` the roots are ``w = 0`` (twice: tilted steady spins) and the
    signed ``w`` of ``w Kc Z = W diag(C) Z``. Seen from the frame spinning at ``W`` a mode
    ``w`` is ``+-i (w - W)`` (one rigid body: ``C W / A - W``, its body nutation); of the two
    ``w = 0`` one is the tilt of the angular momentum (removed by the reduction), the other a
    bent pair at rest, ``+-i W``."""
    I1, I2 = np.asarray(args["inertia1"]), np.asarray(args["inertia2"])
    m1, m2, W = args["m1"], args["m2"], args["rate"]
    l1, l2 = args["r1"][2], -args["r2"][2]
    mu = m1 * m2 / (m1 + m2)
    Kc = np.array([[I1[0] + mu * l1 * l1, mu * l1 * l2], [mu * l1 * l2, I2[0] + mu * l2 * l2]])
    # generalized eigenproblem w Kc Z = W diag(C) Z (the w = 0 roots factored out)
    return np.real(np.linalg.eigvals(np.linalg.solve(Kc, W * np.diag([I1[2], I2[2]]))))


def test_ball_non_axisymmetric_runs_and_keeps_the_bent_family():
    args = {**BASE, "kind": "ball", "inertia1": [2.0, 2.5, 1.0], "inertia2": [0.2, 0.3, 0.4],
            "rate": -3.0}
    rep = st.hinged_spin(**args)
    assert rep.status == st.STATUS_UNCHECKED and rep.ss.nstates == 6
    assert np.min(np.abs(np.abs(rep.eigenvalues.imag) - 3.0)) < 1e-9


@pytest.mark.parametrize("kwargs, name", [
    (dict(m1=0.0), "m1"), (dict(m2=-1.0), "m2"),
    (dict(inertia1=[[2, 0, 0.1], [0, 2, 0], [0.1, 0, 3]]), "inertia1"),
    (dict(inertia2=[1.0, 1.0, 3.0]), "inertia2"),             # triangle inequality
    (dict(r1=[0.1, 0, 0.5]), "r1"), (dict(r2=[0, 0]), "r2"), (dict(rate=0.0), "rate"),
    (dict(rate=math.nan), "rate"), (dict(kind="hinge"), "kind"),
    (dict(axis=[1.0, 0, 0]), "axis"), (dict(kind="ball", axis=[0, 0, 1.0]), "axis")])
def test_bad_input_names_the_argument(kwargs, name):
    with pytest.raises(ValueError, match=f"`{name}`"):
        st.hinged_spin(**{**BASE, **kwargs})


def test_registered_and_json():
    assert st.resolve_case("hinged-spin") == ("hinged_spin", st.hinged_spin)
    assert st.CASES["hinged_spin"] is st.hinged_spin
    rep = st.hinged_spin(**BASE, axis=[0, 0, 1])
    data = json.loads(rep.to_json())
    assert data["case"] == "hinged_spin" and data["states"] == ["w1", "w2"]
    text = " ".join(rep.notes)
    for word in ("q4_rel", "dth3", "q3_rel", "w3_2", "mass centre", "angular momentum"):
        assert word in text


# ------------------------------------------------- the scene against the multiplier model
CASES = [dict(), dict(inertia1=[2.0, 4.0, 3.0]), dict(rate=-2.0),
         dict(inertia1=[2.0, 2.5, 4.0], inertia2=[0.2, 0.25, 0.4]),
         dict(m1=3.0, inertia1=[1.0, 1.0, 0.5], m2=5.0, inertia2=[0.4, 0.4, 0.7],
              r1=[0, 0, 0.3], r2=[0, 0, -0.6], rate=-4.0),
         dict(inertia1=[2.0, 2.5, 1.0], inertia2=[0.2, 0.3, 0.4], rate=-3.0)]


@pytest.mark.parametrize("kind", ["revolute", "ball"])
@pytest.mark.parametrize("geometry", CASES)
def test_scene_equals_the_multiplier_model(kind, geometry):
    """`hinged_spin` goes through the scene (minimal coordinates); the two-body multiplier
    model reduced by hand (the verbatim former `hinged_spin`) is the independent reference:
    same verdict, states, eigenvalues to 1e-8 and, in the same coordinates, the same matrix."""
    from tests.problems.stability import legacy_hinged_spin as legacy

    args = {**BASE, "kind": kind, **geometry}
    rep, ref = st.hinged_spin(**args), legacy.hinged_spin(**args)
    assert rep.verdict == ref.verdict and rep.status == ref.status
    assert rep.ss.state_labels == ref.ss.state_labels
    scale = np.max(np.abs(ref.eigenvalues))
    assert np.max(np.abs(_sorted(rep.eigenvalues) - _sorted(ref.eigenvalues))) <= 1e-8 * scale
    assert np.allclose(rep.ss.A, ref.ss.A, rtol=0, atol=1e-8 * np.max(np.abs(ref.ss.A)))


def test_spin_of_the_hinged_scene_has_the_same_modes_and_the_panel_rate_family():
    """`spin(scene)` on the translating hub: the nutation of the locked pair plus the
    eigenvalue 0 of the panel's free axial rate (which `hinged_spin` restricts)."""
    scene = st.hinged_scene(BASE["m1"], BASE["inertia1"], BASE["m2"], BASE["inertia2"],
                            BASE["r1"], BASE["r2"])
    rep = st.spin(scene, [0, 0, 1], BASE["rate"])
    ref = st.hinged_spin(**BASE)
    ev = rep.eigenvalues
    assert rep.ss.state_labels == ["w1", "w2", "theta_dot"]
    assert np.min(np.abs(ev)) <= 1e-12
    nonzero = ev[np.abs(ev) > 1e-12]
    assert np.allclose(_sorted(nonzero), _sorted(ref.eigenvalues), rtol=1e-10, atol=0)
