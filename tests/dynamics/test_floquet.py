"""Floquet analysis: the monodromy matrix against an independent integrator, Liouville's
formula, and the shaken pendulum's stability boundaries against Mathieu's closed forms.

The shaken pendulum (vertical shake ``a sin(Omega t)``) about theta = 0 or pi is
``th'' + (+-w0^2 -+ (a Omega^2 / l_eff) sin(Omega t)) th + (c / I_h) th' = 0``;
with ``tau = Omega t / 2``: Mathieu's ``y'' + (alpha - 2 q cos 2 tau) y = 0`` with
``alpha = +-4 w0^2 / Omega^2``, ``q = 2 a / l_eff`` (see `dynamics.mechanisms.shaken`).
"""
import json
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.linalg import expm
from scipy.optimize import brentq

from appdyn.dynamics import rigid_body
from appdyn.dynamics.floquet import (TOL, VERDICTS, FloquetResult, classify_multipliers, floquet,
                              monodromy, variational_model)
from appdyn.dynamics.linearize import linearization
from appdyn.dynamics.mechanisms import (double_pendulum, kapitza_frequency, natural_frequency,
                                 resonance_tongue, shaken_pendulum)

M, IC, L, G = 1.0, 1.0 / 48.0, 0.25, 9.81          # a 0.5 m uniform rod hinged at its end
IH = IC + M * L * L
L_EFF = IH / (M * L)
W0 = math.sqrt(G / L_EFF)
PARAMS = dict(mass=M, inertia=IC, length=L, gravity=G)


def p_vector(amp_y, freq, damping=0.0):
    return [M, IC, L, G, amp_y, 0.0, freq, damping]


def model():
    return shaken_pendulum(**PARAMS)


def numpy_rhs(t, z, amp_y, freq, damping):
    """The vertically shaken physical pendulum, written here: I_h th'' =
    -m l (g - a Omega^2 sin(Omega t)) sin th - c th'."""
    th, w = z
    return [w, (-M * L * (G - amp_y * freq ** 2 * math.sin(freq * t)) * math.sin(th)
                - damping * w) / IH]


def fd_monodromy(x_orbit, amp_y, freq, damping=0.0, h=1e-5):
    """Central differences of DOP853 runs (rtol 1e-12) over one period."""
    T = 2 * math.pi / freq
    cols = []
    for j in range(2):
        e = np.zeros(2)
        e[j] = h
        ends = [solve_ivp(numpy_rhs, (0.0, T), np.asarray(x_orbit) + sgn * e, method="DOP853",
                          rtol=1e-12, atol=1e-14, args=(amp_y, freq, damping)).y[:, -1]
                for sgn in (1, -1)]
        cols.append((ends[0] - ends[1]) / (2 * h))
    return np.array(cols).T


def run(theta, amp_y, freq, damping=0.0, **kw):
    return floquet(model(), [theta, 0.0, 0.0], 2 * math.pi / freq,
                   p=p_vector(amp_y, freq, damping), **kw)


# ------------------------------------------------------------- against an independent run
@pytest.mark.parametrize("freq_ratio, damping", [(1.0, 0.0), (1.3, 0.0), (0.7, 0.004)])
@pytest.mark.slow
def test_multipliers_match_finite_differences_of_an_independent_integrator(freq_ratio, damping):
    freq = freq_ratio * 2 * W0
    res = run(0.0, 0.02, freq, damping)
    assert res.success and res.closure == 0.0
    fd = fd_monodromy([0.0, 0.0], 0.02, freq, damping)
    np.testing.assert_allclose(res.monodromy, fd, rtol=0, atol=1e-7 * np.abs(fd).max())
    np.testing.assert_allclose(np.sort_complex(res.multipliers),
                               np.sort_complex(np.linalg.eigvals(fd).astype(complex)),
                               rtol=0, atol=1e-7)


@pytest.mark.slow
def test_autonomous_equilibrium_gives_the_matrix_exponential():
    """No clock: x' = A x about an equilibrium, Phi(T) = expm(A T), mu = exp(lambda T)."""
    dp = double_pendulum(mass1=1.0, mass2=0.5, length1=0.8, length2=0.6, gravity=G)
    A = linearization(dp, np.zeros(4)).A
    T = 1.7
    res = floquet(dp, np.zeros(4), T)
    np.testing.assert_allclose(res.monodromy, expm(A * T), rtol=0, atol=1e-10)
    np.testing.assert_allclose(np.sort_complex(res.multipliers),
                               np.sort_complex(np.exp(np.linalg.eigvals(A) * T)), atol=1e-10)
    assert res.states == dp.states and res.verdict == "marginally stable"
    # exponents equal the eigenvalues of A up to multiples of 2 pi i / T
    np.testing.assert_allclose(np.exp(res.exponents * T), res.multipliers, rtol=1e-14)
    for lam in np.linalg.eigvals(A):
        turns = (res.exponents - lam) * T / (2j * math.pi)
        assert np.min(np.abs(turns - np.round(turns.real))) < 1e-9


# --------------------------------------------------------------------- Liouville's formula
@pytest.mark.parametrize("theta, freq_ratio", [(0.0, 1.0), (0.0, 1.3), (math.pi, 20.0),
                                               (math.pi, 5.0)])
def test_undamped_multipliers_come_in_reciprocal_pairs(theta, freq_ratio):
    """det Phi = exp(int tr A) = 1 without damping (tr A = 0): mu1 mu2 = 1, so either a
    conjugate pair on the unit circle or a real pair mu, 1/mu."""
    res = run(theta, 0.02, freq_ratio * 2 * W0)
    assert abs(np.linalg.det(res.monodromy) - 1) < 1e-10
    assert abs(np.prod(res.multipliers) - 1) < 1e-10
    mu = res.multipliers
    if res.verdict == "unstable":
        assert np.all(mu.imag == 0) and abs(mu[0] * mu[1] - 1) < 1e-10
    else:
        assert np.all(np.abs(np.abs(mu) - 1) < 1e-10) and abs(mu[0] - mu[1].conjugate()) < 1e-10


@pytest.mark.parametrize("theta, damping", [(0.0, 0.003), (math.pi, 0.01), (0.0, 0.05)])
def test_damped_determinant_is_exp_of_minus_c_T_over_I(theta, damping):
    """tr A = -c / I_h (the only diagonal term of A is d th''/d th' = -c / I_h), so
    det Phi(T) = exp(-c T / I_h) whatever the shaking."""
    freq = 60.0 if theta else 2 * W0
    res = run(theta, 0.02, freq, damping)
    T = 2 * math.pi / freq
    assert np.linalg.det(res.monodromy) == pytest.approx(math.exp(-damping * T / IH), rel=1e-10)


# --------------------------------------------------------------------------- Kapitza
def test_inverted_position_is_stabilized_above_the_kapitza_frequency():
    """Approximate threshold a^2 Omega^2 = 2 g l_eff (ratio of shaking to gravity term = 1):
    0.8x is unstable, 1.25x stable (undamped: multipliers on the unit circle; with a little
    hinge damping: inside it)."""
    a = 0.02
    approx = kapitza_frequency(a, **PARAMS, exact=False)
    assert approx == pytest.approx(math.sqrt(2 * G * L_EFF) / a, rel=1e-15)
    assert run(math.pi, a, 0.8 * approx).verdict == "unstable"
    above = run(math.pi, a, 1.25 * approx)
    assert above.verdict == "marginally stable"
    assert run(math.pi, a, 1.25 * approx, damping=0.002).verdict == "asymptotically stable"
    assert run(math.pi, a, 0.8 * approx, damping=0.002).verdict == "unstable"
    # without shaking the inverted pendulum is a saddle: mu = exp(+-w0 T)
    still = run(math.pi, 0.0, 1.25 * approx)
    np.testing.assert_allclose(np.sort(still.multipliers.real),
                               np.exp(np.array([-W0, W0]) * still.period), rtol=1e-9)
    assert above.spectral_radius < still.spectral_radius


def test_kapitza_threshold_found_by_floquet_is_mathieus():
    """The stability edge (tr Phi = 2, a double multiplier +1) located by root finding on
    the computed monodromy equals 2 w0 / sqrt(-a0(q)) to 1e-9, and is above the averaging
    estimate by O(q^2)."""
    a = 0.02

    def edge(freq):
        return np.trace(monodromy(model(), [math.pi, 0.0, 0.0], 2 * math.pi / freq,
                                  p=p_vector(a, freq))) - 2.0

    found = brentq(edge, 80.0, 200.0, xtol=1e-12, rtol=1e-14)
    exact = kapitza_frequency(a, **PARAMS)
    assert found == pytest.approx(exact, rel=1e-9)
    q = 2 * a / L_EFF
    approx = kapitza_frequency(a, **PARAMS, exact=False)
    assert 0 < exact / approx - 1 < q ** 2


# ------------------------------------------------------------------ parametric resonance
def test_hanging_position_is_unstable_inside_the_first_tongue():
    a = 0.02
    low, high = resonance_tongue(a, **PARAMS)
    inside = run(0.0, a, 2 * W0)
    assert inside.verdict == "unstable"
    assert np.all(inside.multipliers.real < 0) and np.all(inside.multipliers.imag == 0)
    assert inside.exponents[0].imag == pytest.approx(math.pi / inside.period, rel=1e-12)
    for freq in (0.9 * low, 1.1 * high):      # outside: both sides
        assert run(0.0, a, freq).verdict == "marginally stable"


def test_tongue_edges_found_by_floquet_are_mathieus():
    """tr Phi = -2 (a double multiplier -1) at 2 w0 / sqrt(a1(q)) and 2 w0 / sqrt(b1(q))."""
    a = 0.02

    def edge(freq):
        return np.trace(monodromy(model(), [0.0, 0.0, 0.0], 2 * math.pi / freq,
                                  p=p_vector(a, freq))) + 2.0

    low, high = resonance_tongue(a, **PARAMS)
    assert brentq(edge, 0.9 * low, 2 * W0, xtol=1e-12, rtol=1e-14) == pytest.approx(low, rel=1e-9)
    assert brentq(edge, 2 * W0, 1.1 * high, xtol=1e-12, rtol=1e-14) == pytest.approx(high, rel=1e-9)


def test_damped_tongue_opens_only_when_shaken_hard_enough():
    """Landau-Lifshitz Sec. 27: th'' + 2 lam th' + w0^2 (1 + h cos 2 w0 t) th = 0 grows iff
    h w0 / 4 > lam. Here lam = c / (2 I_h) and h = a Omega^2 / g = 4 a / l_eff at
    Omega = 2 w0: threshold a* = c l_eff / (2 I_h w0). Check 2 a* and a* / 2."""
    c = 0.01
    a_star = c * L_EFF / (2 * IH * W0)
    assert run(0.0, 2 * a_star, 2 * W0, damping=c).verdict == "unstable"
    assert run(0.0, 0.5 * a_star, 2 * W0, damping=c).verdict == "asymptotically stable"
    assert run(0.0, 2 * a_star, 2 * W0).verdict == "unstable"      # undamped: any a > 0


# ----------------------------------------------------------------------------- plumbing
def test_result_object_text_json_plot_and_fixed_steps():
    res = run(math.pi, 0.02, 200.0, damping=0.002)
    assert isinstance(res, FloquetResult) and res.verdict in VERDICTS and res.tol == TOL
    text = str(res)
    assert "stable" in text and "mu1" in text and "closure" in text
    data = json.loads(res.to_json())
    assert data["verdict"] == "asymptotically stable" and len(data["multipliers"]) == 2
    assert data["multipliers"][0] == [res.multipliers[0].real, res.multipliers[0].imag]
    fig = res.plot()
    assert type(fig).__name__ == "Figure"
    fixed = run(math.pi, 0.02, 200.0, damping=0.002, steps=200)
    np.testing.assert_allclose(fixed.monodromy, res.monodromy, rtol=0, atol=1e-10)
    assert fixed.message.startswith("rk8")
    assert variational_model(model()).nx == 3 + 4


def test_a_non_periodic_start_shows_in_the_closure():
    res = run(0.3, 0.02, 200.0)
    assert res.closure > 1e-3


def test_verdict_rule():
    assert classify_multipliers([1 - 2 * TOL, 0.1])[0] == "asymptotically stable"
    assert classify_multipliers([1 + 0.5 * TOL])[0] == "marginally stable"
    assert classify_multipliers([-(1 + 2 * TOL)])[0] == "unstable"
    assert classify_multipliers([0.5], tol=0.6)[0] == "marginally stable"


@pytest.mark.parametrize("call, exc, name", [
    (lambda: floquet("model", [0, 0, 0], 1.0), TypeError, "model"),
    (lambda: floquet(model(), [0, 0], 1.0), ValueError, "x0"),
    (lambda: floquet(model(), [0, 0, math.nan], 1.0), ValueError, "x0"),
    (lambda: floquet(model(), [0, 0, 0], 0.0), ValueError, "period"),
    (lambda: floquet(model(), [0, 0, 0], "long"), TypeError, "period"),
    (lambda: floquet(model(), [0, 0, 0], 1.0, tol=1.5), ValueError, "tol"),
    (lambda: floquet(model(), [0, 0, 0], 1.0, tol=0.0), ValueError, "tol"),
    (lambda: monodromy(model(), [0, 0, 0], 1.0, steps=0), ValueError, "steps"),
    (lambda: monodromy(model(), [0, 0, 0], 1.0, p=[1.0]), ValueError, "p"),
    (lambda: classify_multipliers([math.nan]), ValueError, "multipliers"),
    (lambda: variational_model(rigid_body), TypeError, "model"),
])
def test_bad_inputs_name_the_argument(call, exc, name):
    with pytest.raises(exc, match=f"`{name}`"):
        call()
