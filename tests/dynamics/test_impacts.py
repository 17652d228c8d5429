"""Impact dynamics (seed 002 Sec. 3.5): Examples 1-5 against their closed forms (the seed's,
corrected where re-derivation shows a misprint), momentum conservation, and energy."""
import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from appdyn.dynamics.mechanisms import (ballistic_pendulum, carriage_impact, central_collision,
                                        contact_jump, dumbbell_impact, falling_bar_impact, impact)

S2 = math.sqrt(2.0)
pos = st.floats(0.1, 10.0)
unit = st.floats(0.0, 1.0)
tight = dict(rel=1e-12, abs=1e-12)


# ------------------------------------------------------------------------ Example 1
@settings(max_examples=40, deadline=None)
@given(m1=pos, m2=pos, u1=st.floats(-5, 5), du=st.floats(0.01, 5), e=unit)
def test_central_collision_closed_form_momentum_and_energy(m1, m2, u1, du, e):
    u2 = u1 - du                                      # approaching
    res = central_collision(m1, m2, u1, u2, e=e)
    assert res["v1"] == pytest.approx(u1 - m2 * (1 + e) / (m1 + m2) * du, **tight)
    assert res["v2"] == pytest.approx(u2 + m1 * (1 + e) / (m1 + m2) * du, **tight)
    assert m1 * res["v1"] + m2 * res["v2"] == pytest.approx(m1 * u1 + m2 * u2, **tight)
    assert res.energy_loss == pytest.approx(0.5 * m1 * m2 / (m1 + m2) * (1 - e * e) * du ** 2,
                                            rel=1e-10, abs=1e-12)
    assert res.normal_velocity[1] == pytest.approx(-e * res.normal_velocity[0], **tight)


def test_central_collision_plastic_and_elastic():
    plastic = central_collision(2.0, 3.0, 4.0, -1.0, e=0.0)
    assert plastic["v1"] == pytest.approx(plastic["v2"]) == pytest.approx((8 - 3) / 5)
    elastic = central_collision(2.0, 3.0, 4.0, -1.0, e=1.0)
    assert elastic.energy_loss == pytest.approx(0.0, abs=1e-13)
    assert elastic["v2"] - elastic["v1"] == pytest.approx(5.0)   # separation = approach


def test_receding_bodies_do_not_impact():
    res = central_collision(1.0, 1.0, 0.0, 1.0, e=0.5)
    assert res.regime == "separating" and res.normal_impulse == 0.0
    assert res.v.tolist() == [0.0, 1.0]


# ------------------------------------------------------------------------ Example 2
@settings(max_examples=30, deadline=None)
@given(m1=pos, m2=pos, l=pos, v1=st.floats(0.1, 500), e=unit)
def test_ballistic_pendulum_closed_form(m1, m2, l, v1, e):
    res = ballistic_pendulum(m1, m2, l, v1, e=e)
    assert res["x1_dot"] == pytest.approx((m1 - m2 * e) / (m1 + m2) * v1, **tight)
    assert res["theta_dot"] == pytest.approx((1 + e) * m1 * v1 / ((m1 + m2) * l), **tight)
    # linear momentum of bullet and bob (the hinge takes no impulse from a horizontal hit)
    assert m1 * res["x1_dot"] + m2 * l * res["theta_dot"] == pytest.approx(m1 * v1, **tight)


# ------------------------------------------------------------------------ Example 3
def _dumbbell_sliding(mu, e, v0, l):
    d = 7 - mu
    return {"vx": (3 - mu - 4 * e) / d * v0, "vy": -4 * mu * (1 + e) / d * v0,
            "x_dot": 2 * (1 + e) / d * v0, "y_dot": 2 * mu * (1 + e) / d * v0,
            "phi_dot": 2 * S2 * (1 - mu) * (1 + e) * v0 / (d * l)}


def _dumbbell_normal(e, v0, l):   # with the corrected phi' = (1 + e) v0 / (2 sqrt 2 l)
    return {"vx": (5 - 7 * e) / 12 * v0, "vy": -(1 + e) / 12 * v0,
            "x_dot": 7 / 24 * (1 + e) * v0, "y_dot": (1 + e) / 24 * v0,
            "phi_dot": (1 + e) * v0 / (2 * S2 * l)}


@settings(max_examples=40, deadline=None)
@given(m=pos, l=pos, v0=pos, e=unit, mu=st.floats(0.0, 3.0))
def test_dumbbell_closed_forms_and_momenta(m, l, v0, e, mu):
    res = dumbbell_impact(m, l, v0, e=e, mu=mu)
    sliding = mu < 1 / 7 - 1e-9
    if abs(mu - 1 / 7) < 1e-9:
        return
    want = _dumbbell_sliding(mu, e, v0, l) if sliding else _dumbbell_normal(e, v0, l)
    assert res.regime == ("frictionless" if mu == 0 else "sliding" if sliding else "sticking")
    for name, value in want.items():
        assert res[name] == pytest.approx(value, rel=1e-11, abs=1e-11 * v0 / min(l, 1))
    # linear momentum (3.58, 3.59) and angular momentum about the dumbbell's centre (3.60)
    assert res["vx"] + 2 * res["x_dot"] == pytest.approx(v0, rel=1e-12)
    assert res["vy"] + 2 * res["y_dot"] == pytest.approx(0.0, abs=1e-12 * v0)
    assert (res["vx"] + res["phi_dot"] * l * S2 - res["vy"]) == pytest.approx(v0, rel=1e-11)
    assert res.energy_loss >= -1e-12 * m * v0 ** 2


def test_dumbbell_normal_rebound_needs_mu_one_seventh():
    """The seed prints F = 7/24 (1 + e) m v0 and mu = 2/7; F is 7/12 (1 + e) m v0 and the
    sliding solution meets the normal one at mu = 1/7."""
    res = dumbbell_impact(2.0, 1.0, 3.0, e=0.4)       # mu = inf: sticking
    assert res.normal_impulse == pytest.approx(7 / 12 * 1.4 * 2.0 * 3.0, rel=1e-13)
    assert abs(res.tangent_impulse[0]) / res.normal_impulse == pytest.approx(1 / 7, rel=1e-13)
    below, above = (dumbbell_impact(2.0, 1.0, 3.0, e=0.4, mu=mu) for mu in (1 / 7 - 1e-6,
                                                                            1 / 7 + 1e-6))
    assert below.regime == "sliding" and above.regime == "sticking"
    assert np.allclose(below.v, above.v, atol=1e-5)


# ------------------------------------------------------------------------ Example 4
@settings(max_examples=30, deadline=None)
@given(m1=pos, m2=pos, alpha=st.floats(0.05, math.pi / 2), x1=pos, e=unit, k=pos)
def test_carriage_closed_form(m1, m2, alpha, x1, e, k):
    res = carriage_impact(m1, m2, alpha, x1, e=e, stiffness=k)
    s, c = math.sin(alpha), math.cos(alpha)
    P = (1 + e) * m1 * m2 * x1 * s / (m2 + m1 * s * s)
    assert res["x2_dot"] == pytest.approx(P * s / m2, **tight)
    assert res["x1_dot"] == pytest.approx(x1 - P * s / m1, rel=1e-12, abs=1e-12 * x1)
    assert res["y1_dot"] == pytest.approx(P * c / m1, rel=1e-12, abs=1e-12 * x1)
    # Eqs. 3.71 (corrected), 3.72, 3.73
    n_after = res["x2_dot"] * s - (res["x1_dot"] * s - res["y1_dot"] * c)
    assert n_after == pytest.approx(e * x1 * s, rel=1e-11, abs=1e-12 * x1)
    assert m1 * res["x1_dot"] + m2 * res["x2_dot"] == pytest.approx(m1 * x1, rel=1e-12)
    assert res["x1_dot"] * c + res["y1_dot"] * s == pytest.approx(x1 * c, rel=1e-11,
                                                                  abs=1e-12 * x1)
    assert res["travel"] == pytest.approx(math.sqrt(m2 / k) * res["x2_dot"], **tight)
    assert math.tan(res["rebound_angle"]) == pytest.approx(res["y1_dot"] / res["x1_dot"],
                                                           rel=1e-9)


# ------------------------------------------------------------------------ Example 5
def _bar_normal(u0, v0, e, l, m):
    return {"y_dot": ((5 * e - 3) * v0 + 3 * u0) / 8, "x_dot": 3 * (u0 - (1 + e) * v0) / 8,
            "omega": 3 * ((1 + e) * v0 - u0) / (2 * S2 * l)}, \
        m * (3 * u0 + 5 * (1 + e) * v0) / 8, m * (5 * u0 + 3 * (1 + e) * v0) / 8


def _bar_sliding(u0, v0, e, mu, l):
    d = 2 + 3 * (1 - mu)
    return {"y_dot": v0 * (2 * e - 3 * (1 - mu)) / d, "x_dot": u0 - 2 * mu * (1 + e) * v0 / d,
            "omega": 12 * (1 + e) * (1 - mu) * v0 / (S2 * d * l)}


@settings(max_examples=40, deadline=None)
@given(m=pos, l=pos, u0=st.floats(0.0, 5.0), v0=pos, e=unit, mu=st.floats(0.0, 1.5))
def test_falling_bar_closed_forms(m, l, u0, v0, e, mu):
    res = falling_bar_impact(m, l, u0, v0, e=e, mu=mu)
    want, F, R = _bar_normal(u0, v0, e, l, m)
    ratio = R / F                               # the corrected Eq. 3.96
    if abs(mu - ratio) < 1e-9:
        return
    if mu > ratio:
        assert res.regime == "sticking"
        assert res.normal_impulse == pytest.approx(F, rel=1e-11)
        assert -res.tangent_impulse[0] == pytest.approx(R, rel=1e-11, abs=1e-12 * m * v0)
    else:
        assert res.regime == ("frictionless" if mu == 0 else "sliding")
        want = _bar_sliding(u0, v0, e, mu, l)
        assert -res.tangent_impulse[0] == pytest.approx(mu * res.normal_impulse, rel=1e-12)
    for name, value in want.items():
        assert res[name] == pytest.approx(value, rel=1e-11, abs=1e-11 * (u0 + v0) / min(l, 1))
    # angular momentum about the contact point is conserved in either regime
    rx, ry = l / 2 * S2 / 2, -l / 2 * S2 / 2      # contact point from the centre

    def h_contact(x_dot, y_dot, omega):        # (r_c - r_p) x m v + I omega
        return m * (-rx * y_dot + ry * x_dot) + m * l * l / 12 * omega
    if res.regime == "sticking":
        assert h_contact(res["x_dot"], res["y_dot"], res["omega"]) == pytest.approx(
            h_contact(u0, -v0, 0.0), rel=1e-11, abs=1e-11 * m * l * (u0 + v0))
    assert res.energy_loss >= -1e-12 * m * (u0 ** 2 + v0 ** 2)


def test_falling_bar_seed_misprints():
    """Eqs. 3.93, 3.94, 3.96 as printed do not solve 3.76-3.81; the corrected forms do."""
    m, l, u0, v0, e = 1.0, 1.0, 1.0, 2.0, 0.5
    res = falling_bar_impact(m, l, u0, v0, e=e)
    printed_omega = 3 / (2 * S2 * l) * (2 * (1 + e) * v0 - u0)
    printed_R = m * (5 * u0 + (1 + e) * v0) / 8
    assert res["omega"] != pytest.approx(printed_omega, rel=1e-3)
    assert -res.tangent_impulse[0] != pytest.approx(printed_R, rel=1e-3)
    # the equations themselves: 3.76-3.81 with I = m l^2 / 12
    F, R, w = res.normal_impulse, -res.tangent_impulse[0], res["omega"]
    c = s = S2 / 2
    assert F == pytest.approx(m * (res["y_dot"] + v0))
    assert R == pytest.approx(-m * (res["x_dot"] - u0))
    assert w == pytest.approx((F * l / 2 * c - R * l / 2 * s) / (m * l * l / 12))
    assert res["y_dot"] + l / 2 * c * w == pytest.approx(e * v0)
    assert res["x_dot"] + l / 2 * s * w == pytest.approx(0.0, abs=1e-14)


def test_a_jammed_contact_is_a_failure_not_an_exception():
    res = falling_bar_impact(1.0, 1.0, -4.0, 0.5)          # sticking would pull: F < 0
    assert not res.success and "jams" in res.message
    assert res.v.tolist() == res.v_before.tolist()
    assert falling_bar_impact(1.0, 1.0, -4.0, 0.5, mu=0.3).success


def test_results_pickle():
    import pickle
    res = carriage_impact(1.0, 2.0, 0.5, 1.0, e=0.5)
    back = pickle.loads(pickle.dumps(res))
    assert back["travel"] == res["travel"] and back.v.tolist() == res.v.tolist()


def test_newton_friction_energy_gain_is_reported():
    """Kane's paradox: the seed's law gains energy for the bar sliding backwards."""
    res = falling_bar_impact(1.0, 1.0, -1.0, 1.0, e=1.0)
    assert res.regime == "sticking"
    assert res.energy_loss == pytest.approx(1.0 - 1.0625, rel=1e-12)
    assert "energy gained" in res.message


# ------------------------------------------------------------------------ the generic law
@st.composite
def contacts(draw):
    k = draw(st.integers(1, 2))
    n = draw(st.integers(k + 1, 5))
    seed = draw(st.integers(0, 2 ** 32 - 1))
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(n, n))
    M = A @ A.T + 0.5 * np.eye(n)
    normal, D, v = rng.normal(size=n), rng.normal(size=(k, n)), rng.normal(size=n)
    if normal @ v >= 0:
        v = -v
    return M, normal, D, v


@settings(max_examples=60, deadline=None)
@given(case=contacts(), e=unit)
def test_frictionless_loses_the_restitution_share(case, e):
    M, normal, _, v = case
    res = impact(M, normal, v, e=e)
    un = normal @ v
    wnn = normal @ np.linalg.solve(M, normal)
    T = 0.5 * v @ M @ v
    assert res.energy_loss == pytest.approx(0.5 * (1 - e * e) * un * un / wnn, rel=1e-9,
                                            abs=1e-12 * T)
    assert res.normal_velocity[1] == pytest.approx(-e * un, rel=1e-10, abs=1e-12)
    assert res.energy_loss >= -1e-12 * T
    assert np.allclose(M @ (res.v - v), res.impulse, rtol=1e-10, atol=1e-12)


@settings(max_examples=60, deadline=None)
@given(case=contacts(), e=unit, mu=st.floats(0.0, 3.0))
def test_friction_cone_and_restitution(case, e, mu):
    M, normal, D, v = case
    res = impact(M, normal, v, tangent=D, e=e, mu=mu)
    T = 0.5 * v @ M @ v
    if not res.success:
        return
    assert res.normal_impulse >= 0
    assert res.normal_velocity[1] == pytest.approx(-e * normal @ v, rel=1e-9, abs=1e-12)
    pt = np.linalg.norm(res.tangent_impulse)
    assert pt <= mu * res.normal_impulse * (1 + 1e-9) + 1e-14
    if res.regime == "sticking":
        assert np.allclose(res.slip, 0.0, atol=1e-9 * (1 + np.abs(v).max()))
    elif res.regime == "sliding":
        assert pt == pytest.approx(mu * res.normal_impulse, rel=1e-12)
    if e == 0.0:
        assert res.energy_loss >= -1e-12 * T


@settings(max_examples=40, deadline=None)
@given(case=contacts(), e=unit)
def test_sticking_without_slip_loses_the_restitution_share(case, e):
    M, normal, D, v = case
    v = v - np.linalg.pinv(D) @ (D @ v)           # no slip before
    if normal @ v >= -1e-3:
        return
    res = impact(M, normal, v, tangent=D, e=e)    # mu = inf: sticks
    J = np.vstack([normal, D])
    Winv = np.linalg.inv(J @ np.linalg.solve(M, J.T))
    un = normal @ v
    assert res.regime == "sticking"
    assert res.energy_loss == pytest.approx(0.5 * (1 - e * e) * un * un * Winv[0, 0],
                                            rel=1e-8, abs=1e-10 * (0.5 * v @ M @ v))


def test_elastic_frictionless_conserves_energy():
    M = np.array([[2.0, 0.3, 0.0], [0.3, 1.0, 0.1], [0.0, 0.1, 0.5]])
    res = impact(M, [0.2, -1.0, 0.4], [0.1, 2.0, -0.3], e=1.0)
    assert res.energy_loss == pytest.approx(0.0, abs=1e-14)


def test_contact_jump_matches_impact():
    jump = contact_jump(lambda q, p: np.diag([1.0, 1.0, 1 / 12]),
                        lambda q, p: [0.0, 1.0, 0.5 * math.cos(q[2])],
                        tangent=lambda q, p: [[1.0, 0.0, -0.5 * math.sin(q[2])]], e=0.3, mu=0.4,
                        nq=3)
    x = np.array([0.0, 0.5, -math.pi / 4, 1.0, -2.0, 0.0])
    x_plus, res = jump(0.0, x, np.zeros(0), np.zeros(0))
    ref = falling_bar_impact(1.0, 1.0, 1.0, 2.0, e=0.3, mu=0.4)
    assert np.allclose(x_plus[3:], ref.v, rtol=0, atol=1e-14)
    assert x_plus[:3].tolist() == x[:3].tolist()
    assert res.regime == ref.regime


@pytest.mark.parametrize("kwargs, match", [
    (dict(mass_matrix=[[1.0, 2.0], [0.0, 1.0]]), "symmetric"),
    (dict(mass_matrix=[[1.0, 0.0], [0.0, -1.0]]), "positive definite"),
    (dict(mass_matrix=np.eye(3)), "square of the size of `v`"),
    (dict(v=np.ones((2, 2))), "`v` must be a vector"),
    (dict(normal=[0.0, 0.0]), "`normal`"),
    (dict(tangent=np.ones((3, 2))), "`tangent`"),
    (dict(tangent=[[2.0, 0.0]]), "full row rank"),
    (dict(e=1.5), "`e`"),
    (dict(mu=-1.0), "`mu`"),
    (dict(mu="x"), "`mu`"),
])
def test_bad_input_names_the_argument(kwargs, match):
    args = dict(mass_matrix=np.eye(2), normal=[1.0, 0.0], v=[-1.0, 0.0])
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        impact(args.pop("mass_matrix"), args.pop("normal"), args.pop("v"), **args)
