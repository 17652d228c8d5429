"""The conical pendulum (`problems.stability.conical_pendulum`): the reduced linearization
against the closed form, the two formulations against each other, a Cartesian simulation.

Independent truths: ``omega^2 = (g / (l cos a)) (1 + 3 cos^2 a)`` for a point mass (written
here); for a body with inertia, the second derivative of the Routhian potential taken by
central differences here; the nutation period of a point mass on a sphere integrated in
Cartesian coordinates with scipy.
"""
import doctest
import json
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from appdyn.problems import stability as st
from appdyn.problems.stability import constrained

G0 = 9.80665


def point_mass_omega(a, length, gravity=G0):
    return math.sqrt(gravity / (length * math.cos(a)) * (1 + 3 * math.cos(a) ** 2))


@pytest.mark.parametrize("form", ["3-2-1", "3-1-3"])
@pytest.mark.parametrize("cone_angle", [1e-3, 0.1, 0.6, math.pi / 3, 1.4, 1.55])
def test_reduced_frequency_is_the_closed_form(form, cone_angle):
    rep = st.conical_pendulum(mass=2.0, length=1.5, cone_angle=cone_angle, sequence=form)
    omega = point_mass_omega(cone_angle, 1.5)
    assert rep.ss.state_labels == ["theta", "theta_dot"]
    assert len(rep.eigenvalues) == 2
    assert np.max(np.abs(np.abs(rep.eigenvalues.imag) - omega)) < 1e-10 * omega
    assert np.max(np.abs(rep.eigenvalues.real)) < 1e-10 * omega
    assert rep.verdict == "marginally stable"
    assert rep.status == st.STATUS_VERIFIED and rep.success
    assert rep.quantity("nutation").value == pytest.approx(omega, rel=1e-10)


@pytest.mark.parametrize("cone_angle", [0.05, 0.9, 1.5])
def test_both_forms_agree_for_a_point_mass(cone_angle):
    reps = [st.conical_pendulum(mass=0.7, length=2.0, cone_angle=cone_angle, gravity=3.7,
                                sequence=f) for f in ("3-1-3", "3-2-1")]
    w = [r.quantity("nutation").value for r in reps]
    assert abs(w[0] - w[1]) < 1e-10 * w[0]
    p = [r.quantity("vertical angular momentum").value for r in reps]
    assert abs(p[0] - p[1]) < 1e-10 * p[0]
    # the azimuth and its rate went, with their reasons
    for r, az in zip(reps, ("psi", "phi")):
        assert any(f"'{az}'" in n for n in r.notes) and any(f"'{az}_dot'" in n for n in r.notes)


@pytest.mark.parametrize("inertia", [0.01, 0.5, 3.0])
def test_body_with_inertia_matches_the_routhian_by_differences(inertia):
    m, l, a = 2.0, 1.5, 0.8
    rate = math.sqrt(G0 / (l * math.cos(a)))
    p = (m * l * l * math.sin(a) ** 2 + inertia) * rate

    def v_eff(th):
        return -m * G0 * l * math.cos(th) + p * p / (2 * (m * l * l * math.sin(th) ** 2 + inertia))

    h = 1e-4
    stiffness = (v_eff(a + h) - 2 * v_eff(a) + v_eff(a - h)) / h ** 2
    omega = math.sqrt(stiffness / (m * l * l + inertia))
    rep = st.conical_pendulum(mass=m, length=l, cone_angle=a, inertia=inertia, sequence="3-1-3")
    assert rep.quantity("nutation").value == pytest.approx(omega, rel=1e-6)
    assert rep.status == st.STATUS_VERIFIED and rep.verdict == "marginally stable"


def test_nutation_period_of_a_cartesian_simulation():
    """A point mass on a sphere (r'' = g e3 - lambda r), started on a slightly wider cone."""
    l, a, g = 1.2, 0.7, G0
    rate = math.sqrt(g / (l * math.cos(a)))
    a0 = a + 1e-4   # same speed, slightly wider: the cone angle oscillates at omega
    r0 = l * np.array([math.sin(a0), 0.0, math.cos(a0)])
    v0 = np.array([0.0, l * math.sin(a) * rate, 0.0])

    def rhs(t, y):
        r, v = y[:3], y[3:]
        lam = (v @ v + g * r[2]) / (r @ r)
        return np.concatenate([v, np.array([0.0, 0.0, g]) - lam * r])

    omega = st.conical_pendulum(mass=1.0, length=l, cone_angle=a).quantity("nutation").value
    t_end = 6 * 2 * math.pi / omega
    sol = solve_ivp(rhs, [0, t_end], np.concatenate([r0, v0]), method="DOP853", rtol=1e-12,
                    atol=1e-13, dense_output=True)
    t = np.linspace(0, t_end, 20001)
    polar = np.arccos(np.clip(sol.sol(t)[2] / l, -1, 1))
    wave = polar - polar.mean()
    k = np.nonzero(np.diff(np.sign(wave)) > 0)[0]   # upward crossings, interpolated
    crossings = t[k] - wave[k] * (t[k + 1] - t[k]) / (wave[k + 1] - wave[k])
    period = np.mean(np.diff(crossings))
    assert abs(2 * math.pi / period / omega - 1) < 1e-5


@pytest.mark.parametrize("cone_angle", [0.0, -0.2, math.pi / 2, 2.0, math.nan])
def test_bad_cone_angles_are_refused(cone_angle):
    with pytest.raises(ValueError, match="`cone_angle`"):
        st.conical_pendulum(mass=1.0, length=1.0, cone_angle=cone_angle)


@pytest.mark.parametrize("kwargs, name", [
    (dict(sequence="3-2-3"), "sequence"), (dict(inertia=0.1, sequence="3-2-1"), "inertia"),
    (dict(mass=0.0), "mass"), (dict(length=-1.0), "length"), (dict(gravity=0.0), "gravity"),
    (dict(inertia=-0.1, sequence="3-1-3"), "inertia")])
def test_bad_input_names_the_argument(kwargs, name):
    args = {"mass": 1.0, "length": 1.0, "cone_angle": 0.5, **kwargs}
    with pytest.raises(ValueError, match=f"`{name}`"):
        st.conical_pendulum(**args)


def test_registered_sweepable_and_strict_json():
    assert st.resolve_case("conical-pendulum") == ("conical_pendulum", st.conical_pendulum)
    res = st.sweep("conical_pendulum", "cone_angle", np.linspace(0.1, 1.5, 5), mass=1.0,
                   length=1.0)
    assert set(res.verdicts) == {"marginally stable"} and not res.boundaries
    assert res.status == st.STATUS_VERIFIED
    rep = st.conical_pendulum(mass=1.0, length=1.0, cone_angle=0.5, sequence="3-1-3")
    data = json.loads(rep.to_json())
    assert data["case"] == "conical_pendulum" and data["states"] == ["theta", "theta_dot"]
    assert "Jordan" in str(rep)


def test_docstring_examples_run():
    result = doctest.testmod(constrained, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.failed == 0 and result.attempted > 0
