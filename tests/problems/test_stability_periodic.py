"""Floquet stability of the shaken pendulum (`problems.stability.shaken_pendulum`) against
Mathieu's chart and an independent integration.

Independent truths: Mathieu's characteristic values (``scipy.special.mathieu_a / _b``) with
the mapping written out here (``a = 4 s w0^2 / freq^2``, ``q = 2 amp_y / l_eff``);
`dynamics.mechanisms.kapitza_frequency` / `resonance_tongue`; Liouville's formula; a
monodromy of the linear Hill equation integrated here with scipy's DOP853.
"""
import doctest
import json
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.special import mathieu_a, mathieu_b

from appdyn.dynamics.mechanisms import kapitza_frequency, resonance_tongue
from appdyn.problems import stability as st
from appdyn.problems.stability import periodic

ROD = dict(mass=1.0, inertia=1.0 / 48.0, length=0.25)   # uniform rod 0.5 m, l_eff = 1/3 m
G0 = 9.80665


def constants(mass, inertia, length, gravity=G0):
    i_h = inertia + mass * length ** 2
    l_eff = i_h / (mass * length)
    return i_h, l_eff, math.sqrt(gravity / l_eff)


def hill_monodromy(freq, amp_y, damping, s, mass, inertia, length, gravity=G0):
    """Monodromy of I_h u'' + c u' + s (m g l - m l amp_y freq^2 sin(freq t)) u = 0."""
    i_h = inertia + mass * length ** 2

    def rhs(t, y):
        k = s * (mass * gravity * length - mass * length * amp_y * freq ** 2 * np.sin(freq * t))
        u, v = y.reshape(2, 2)
        return np.concatenate([v, -(k * u + damping * v) / i_h])

    sol = solve_ivp(rhs, [0, 2 * np.pi / freq], [1.0, 0.0, 0.0, 1.0], method="DOP853",
                    rtol=1e-13, atol=1e-13)
    return sol.y[:, -1].reshape(2, 2)


@pytest.mark.parametrize("amp_y", [0.01, 0.02, 0.05])
def test_inverted_stable_well_above_kapitza_and_unstable_well_below(amp_y):
    _, l_eff, w0 = constants(**ROD)
    q = 2 * amp_y / l_eff
    f_star = 2 * w0 / math.sqrt(-mathieu_a(0, q))         # the edge a = a0(q), written here
    for factor, verdict in ((1.5, "marginally stable"), (3.0, "marginally stable"),
                            (0.7, "unstable"), (0.3, "unstable")):
        freq = factor * f_star
        assert (-4 * w0 ** 2 / freq ** 2 > mathieu_a(0, q)) == (verdict != "unstable")
        rep = st.shaken_pendulum(**ROD, amp_y=amp_y, freq=freq, position="inverted")
        assert rep.verdict == verdict, (factor, rep.reason)
        assert rep.status == st.STATUS_VERIFIED and rep.success, rep.message
        assert rep.predicted == verdict


def test_sweep_finds_the_kapitza_threshold():
    amp_y = 0.02
    f_star = kapitza_frequency(amp_y, **ROD, exact=True)
    res = st.sweep("shaken-pendulum", "freq", np.linspace(0.8, 1.3, 4) * f_star, amp_y=amp_y,
                   position="inverted", **ROD)
    assert [(b.before, b.after) for b in res.boundaries] == [("unstable", "marginally stable")]
    assert abs(res.boundaries[0].value / f_star - 1) < 1e-6
    assert res.success and res.case == "shaken_pendulum"
    # the exponents are what the sweep tracks: Re = log|mu| / T
    assert res.least_damped[0].real > 0 and abs(res.least_damped[-1].real) < 1e-6


@pytest.mark.parametrize("damping, outside", [(0.0, "marginally stable"),
                                              (0.002, "asymptotically stable")])
def test_hanging_first_tongue(damping, outside):
    amp_y = 0.02
    _, l_eff, w0 = constants(**ROD)
    q = 2 * amp_y / l_eff
    low, high = 2 * w0 / math.sqrt(mathieu_a(1, q)), 2 * w0 / math.sqrt(mathieu_b(1, q))
    inside = st.shaken_pendulum(**ROD, amp_y=amp_y, freq=0.5 * (low + high), damping=damping)
    assert inside.verdict == "unstable"
    assert min(m.multiplier.real for m in inside.modes) < -1   # period-2T response
    for freq in (0.85 * low, 1.2 * high, 3 * high):
        rep = st.shaken_pendulum(**ROD, amp_y=amp_y, freq=freq, damping=damping)
        assert rep.verdict == outside, (freq, rep.reason)
        assert rep.status == st.STATUS_VERIFIED, rep.message


def test_sweep_finds_the_tongue_edges():
    amp_y = 0.02
    low, high = resonance_tongue(amp_y, **ROD)
    res = st.sweep(st.shaken_pendulum, "freq", np.linspace(0.8 * low, 1.2 * high, 7),
                   amp_y=amp_y, **ROD)
    assert [(b.before, b.after) for b in res.boundaries] == [
        ("marginally stable", "unstable"), ("unstable", "marginally stable")]
    got = [b.value for b in res.boundaries]
    assert abs(got[0] / low - 1) < 1e-6 and abs(got[1] / high - 1) < 1e-6


@pytest.mark.parametrize("freq, position", [(200.0, "inverted"), (60.0, "inverted"),
                                            (11.0, "hanging"), (25.0, "hanging")])
def test_undamped_multipliers_have_product_one(freq, position):
    rep = st.shaken_pendulum(**ROD, amp_y=0.02, freq=freq, position=position)
    assert abs(np.prod(rep.multipliers) - 1) < 1e-10
    assert rep.period == pytest.approx(2 * np.pi / freq, rel=1e-15)
    assert rep.states == ("theta", "theta_dot")


@pytest.mark.parametrize("freq, position, damping", [(200.0, "inverted", 0.003),
                                                     (11.0, "hanging", 0.001),
                                                     (30.0, "hanging", 0.01)])
def test_multipliers_match_an_independent_hill_integration(freq, position, damping):
    s = 1.0 if position == "hanging" else -1.0
    rep = st.shaken_pendulum(**ROD, amp_y=0.02, freq=freq, position=position, damping=damping)
    phi = hill_monodromy(freq, 0.02, damping, s, **ROD)
    assert np.max(np.abs(rep.monodromy - phi)) < 1e-8 * np.max(np.abs(phi))
    i_h, _, _ = constants(**ROD)
    liouville = math.exp(-damping * rep.period / i_h)
    assert abs(np.prod(rep.multipliers) - liouville) < 1e-10
    if rep.verdict != "unstable":   # damped Mathieu, v stable: every |mu| = exp(-c T / 2 I_h)
        assert np.allclose(np.abs(rep.multipliers), math.sqrt(liouville), rtol=0, atol=1e-10)


def test_status_is_unchecked_near_the_edge_and_for_a_horizontal_shake():
    f_star = kapitza_frequency(0.02, **ROD)
    near = st.shaken_pendulum(**ROD, amp_y=0.02, freq=f_star * (1 + 1e-8), position="inverted")
    assert near.status == st.STATUS_UNCHECKED and near.predicted is None
    assert "edge" in near.message
    shaken = st.shaken_pendulum(**ROD, amp_y=0.02, amp_x=0.005, freq=20.0)
    assert shaken.status == st.STATUS_UNCHECKED and shaken.success


@pytest.mark.parametrize("position, amp_x", [("hanging", 0.01), ("inverted", 0.001)])
def test_horizontal_shake_finds_the_periodic_orbit(position, amp_x):
    """The orbit's start, integrated here from the seed's equation, repeats after T."""
    amp_y, freq = 0.02, 200.0 if position == "inverted" else 20.0
    rep = st.shaken_pendulum(**ROD, amp_y=amp_y, amp_x=amp_x, freq=freq, position=position)
    assert rep.integrated and rep.closure < 1e-9
    x0 = [rep.quantity("orbit theta(0)").value, rep.quantity("orbit theta_dot(0)").value]
    m, i_c, l = ROD["mass"], ROD["inertia"], ROD["length"]

    def rhs(t, y):
        th, w = y
        torque = (-m * G0 * l * np.sin(th) + m * l * freq ** 2 * np.sin(freq * t)
                  * (amp_y * np.sin(th) + amp_x * np.cos(th)))
        return [w, torque / (i_c + m * l * l)]

    sol = solve_ivp(rhs, [0, 2 * np.pi / freq], x0, method="DOP853", rtol=1e-12, atol=1e-12)
    assert np.max(np.abs(sol.y[:, -1] - x0)) < 1e-8
    assert abs(x0[0] - periodic.POSITIONS[position]) < 0.2


def test_report_format_json_text_and_plot(tmp_path):
    rep = st.shaken_pendulum(**ROD, amp_y=0.02, freq=200.0, position="inverted", damping=0.002)
    data = json.loads(rep.to_json())
    assert data["verdict"] == "asymptotically stable" and data["status"] == 0
    assert len(data["multipliers"]) == 2 and len(data["modes"]) == 2
    assert {"period", "quantities", "eigenvalues", "monodromy", "notes"} <= set(data)
    text = str(rep)
    assert "ASYMPTOTICALLY STABLE" in text and "Kapitza frequency (Mathieu a0)" in text
    from matplotlib.figure import Figure
    ax = Figure().subplots()
    assert rep.plot(ax) is ax.figure and len(ax.lines) >= 2  # the unit circle and the multipliers
    # the exponent carries the decay: Re = log|mu| / T
    assert rep.least_damped().real == pytest.approx(math.log(rep.spectral_radius) / rep.period)


@pytest.mark.parametrize("kwargs, name", [
    (dict(mass=0.0), "mass"), (dict(length=-1.0), "length"), (dict(inertia=-1e-3), "inertia"),
    (dict(amp_y=-0.01), "amp_y"), (dict(freq=0.0), "freq"), (dict(freq=math.inf), "freq"),
    (dict(damping=-0.1), "damping"), (dict(gravity=0.0), "gravity"),
    (dict(amp_x=math.nan), "amp_x"), (dict(position="sideways"), "position"),
    (dict(mass="heavy"), "mass")])
def test_bad_input_names_the_argument(kwargs, name):
    args = {**ROD, "amp_y": 0.02, "freq": 100.0, **kwargs}
    with pytest.raises(ValueError, match=f"`{name}`"):
        st.shaken_pendulum(**args)


def test_mathieu_region_edges():
    q = 0.3
    assert periodic.mathieu_region(mathieu_a(0, q) - 0.1, q)[0] is False
    assert periodic.mathieu_region(0.5 * (mathieu_b(2, q) + mathieu_a(2, q)), q)[0] is False
    assert periodic.mathieu_region(2.5, q)[0] is True
    assert periodic.mathieu_region(mathieu_a(1, q) * (1 + 1e-9), q)[1] < 1e-8


def test_docstring_examples_run():
    result = doctest.testmod(periodic, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.failed == 0 and result.attempted > 0
