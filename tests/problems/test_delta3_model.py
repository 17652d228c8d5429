"""Delta III ascent data and dynamics (`problems.ascent.delta3`) against independent truths."""
from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest

from appdyn.problems.ascent import delta3 as d3

MU = 3.986012e14
OMEGA = 7.29211585e-5


def rv_from_elements(a, e, i, raan, argp, nu, mu=MU):
    """Position and velocity from classical elements through the perifocal frame (3-1-3)."""
    p = a * (1 - e**2)
    rad = p / (1 + e * math.cos(nu))
    r_pf = np.array([rad * math.cos(nu), rad * math.sin(nu), 0.0])
    v_pf = math.sqrt(mu / p) * np.array([-math.sin(nu), e + math.cos(nu), 0.0])

    def rot3(x):
        c, s = math.cos(x), math.sin(x)
        return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])

    def rot1(x):
        c, s = math.cos(x), math.sin(x)
        return np.array([[1.0, 0, 0], [0, c, -s], [0, s, c]])

    Q = rot3(raan) @ rot1(i) @ rot3(argp)  # perifocal -> inertial
    return Q @ r_pf, Q @ v_pf


CASES = [  # (a [m], e, i, raan, argp, nu [rad]): every quadrant of raan, argp and nu
    (24361140.0, 0.7308, math.radians(28.5), math.radians(269.8), math.radians(130.5), 0.3),
    (7.0e6, 0.01, math.radians(98.0), math.radians(45.0), math.radians(300.0), 4.0),
    (4.2e7, 0.3, math.radians(5.0), math.radians(170.0), math.radians(200.0), 2.0),
    (1.0e7, 0.5, math.radians(150.0), math.radians(330.0), math.radians(10.0), 5.9),
]


# ----------------------------------------------------------------- (a) orbital elements
@pytest.mark.parametrize("case", CASES)
def test_orbital_elements_recover_hand_built_orbit(case):
    r, v = rv_from_elements(*case)
    el = d3.orbital_elements(r, v)
    assert el.a == pytest.approx(case[0], rel=1e-10)
    np.testing.assert_allclose([el.e, el.i, el.raan, el.argp, el.nu], case[1:], rtol=0,
                               atol=1e-10)


def test_orbital_elements_batch_matches_single():
    rv = [rv_from_elements(*c) for c in CASES]
    R = np.column_stack([r for r, _ in rv])
    V = np.column_stack([v for _, v in rv])
    el = d3.orbital_elements(R, V)
    assert el.a.shape == (len(CASES),)
    np.testing.assert_allclose(np.array(el).T, [tuple(c) for c in CASES], rtol=1e-10, atol=1e-10)


def test_orbital_elements_bad_input():
    with pytest.raises(ValueError, match="`r`"):
        d3.orbital_elements([1.0, 2.0], [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="`v`"):
        d3.orbital_elements([7e6, 0, 0], [0, np.nan, 0])
    with pytest.raises(ValueError, match="`mu`"):
        d3.orbital_elements([7e6, 0, 0], [0, 7e3, 0], mu=-1.0)
    with pytest.raises(TypeError):
        d3.orbital_elements(ca.SX.sym("r", 3), [0, 7e3, 0])


# ---------------------------------------------------------------- (b) orbit residuals
def _near_target_states(n=6, seed=1):
    rng = np.random.default_rng(seed)
    t = d3.TARGET_ORBIT
    out = []
    for _ in range(n):
        el = (t["a"] * (1 + 0.05 * rng.standard_normal()), t["e"] + 0.02 * rng.standard_normal(),
              t["i"] + 0.05 * rng.standard_normal(), t["raan"] + 0.3 * rng.standard_normal(),
              t["argp"] + 0.3 * rng.standard_normal(), rng.uniform(0, 2 * np.pi))
        out.append((el, *rv_from_elements(*el)))
    return out


def test_orbit_residuals_are_elements_minus_target():
    t = d3.TARGET_ORBIT
    for el, r, v in _near_target_states():
        res = d3.orbit_residuals(r, v)
        expected = np.array(el[:5]) - [t["a"], t["e"], t["i"], t["raan"], t["argp"]]
        assert res[0] == pytest.approx(expected[0], abs=1e-8 * t["a"])
        np.testing.assert_allclose(res[1:], expected[1:], atol=1e-10)


def test_orbit_residuals_zero_on_target_orbit():
    t = d3.TARGET_ORBIT
    for nu in (0.0, 1.0, 3.0, 5.5):
        r, v = rv_from_elements(t["a"], t["e"], t["i"], t["raan"], t["argp"], nu)
        res = d3.orbit_residuals(r, v)
        assert abs(res[0]) < 1e-8 * t["a"]
        np.testing.assert_allclose(res[1:], 0.0, atol=1e-11)


@pytest.mark.parametrize("kind", [ca.SX, ca.MX])
def test_orbit_residuals_symbolic_equal_numeric(kind):
    r, v = kind.sym("r", 3), kind.sym("v", 3)
    res = d3.orbit_residuals(r, v)
    assert isinstance(res, kind) and res.shape == (5, 1)
    f = ca.Function("res", [r, v], [res, ca.jacobian(res, ca.vertcat(r, v))])
    states = _near_target_states(4, seed=2) + [(None, d3.initial_state()[:3],
                                                d3.initial_state()[3:6])]
    for _, rn, vn in states:
        val, jac = f(rn, vn)
        np.testing.assert_allclose(np.asarray(val).ravel(), d3.orbit_residuals(rn, vn),
                                   rtol=1e-13, atol=1e-13)
        assert np.all(np.isfinite(np.asarray(jac)))


def test_orbit_residuals_batch_and_errors():
    rv = [(r, v) for _, r, v in _near_target_states(3)]
    R, V = np.column_stack([r for r, _ in rv]), np.column_stack([v for _, v in rv])
    out = d3.orbit_residuals(R, V)
    assert out.shape == (5, 3)
    np.testing.assert_allclose(out[:, 1], d3.orbit_residuals(*rv[1]), rtol=1e-14, atol=1e-14)
    with pytest.raises(ValueError, match="`r` and `v`"):
        d3.orbit_residuals(R, V[:, 0])
    with pytest.raises(ValueError, match="`target`"):
        d3.orbit_residuals(R, V, target={"a": 1.0})
    with pytest.raises(TypeError, match="`target`"):
        d3.orbit_residuals(R, V, target=[1, 2, 3, 4, 5])
    with pytest.raises(ValueError, match="`r`"):
        d3.orbit_residuals(ca.SX.sym("r", 2), ca.SX.sym("v", 3))


# --------------------------------------------- (c) gravity alone without thrust and drag
def test_model_is_two_body_without_thrust_and_drag():
    rng = np.random.default_rng(3)
    for phase in range(4):
        model = d3.delta3_model(phase)
        for _ in range(3):
            r = rng.standard_normal(3)
            r *= rng.uniform(1.0, 1.5) * d3.RE / np.linalg.norm(r)
            # at rest in the rotating atmosphere: v_rel = 0, so no drag at any altitude
            v = np.cross([0.0, 0.0, OMEGA], r)
            xdot = model.rhs(np.r_[r, v, 5.0e4], np.zeros(3))
            np.testing.assert_array_equal(xdot[:3], v)
            np.testing.assert_allclose(xdot[3:6], -MU * r / np.linalg.norm(r) ** 3,
                                       rtol=1e-14, atol=1e-16)
        # far above the atmosphere (rho ~ 1e-61 rho0) with any velocity: still two-body
        r, v = rv_from_elements(*CASES[2])
        xdot = model.rhs(np.r_[r, v, 5.0e4], np.zeros(3))
        np.testing.assert_allclose(xdot[3:6], -MU * r / np.linalg.norm(r) ** 3, rtol=1e-14)


def test_normalized_model_is_the_plain_one_at_the_unit_direction():
    """``normalized=True`` (ASSET's form, thrust ``T u / |u|``) equals the plain model fed
    ``u / |u|`` for any ``|u|``, its derivatives included (chain rule through the
    normalization), and both agree wherever ``|u| = 1``."""
    rng = np.random.default_rng(7)
    for phase in range(4):
        plain, scaled = d3.delta3_model(phase), d3.delta3_model(phase, normalized=True)
        assert scaled is d3.delta3_model(phase, normalized=True) and scaled is not plain
        for _ in range(3):
            r = rng.standard_normal(3)
            r *= rng.uniform(1.0, 1.2) * d3.RE / np.linalg.norm(r)
            x = np.r_[r, 7e3 * rng.standard_normal(3), 3.0e4]
            u = rng.standard_normal(3) * rng.uniform(0.5, 1.5)
            unit = u / np.linalg.norm(u)
            np.testing.assert_allclose(scaled.rhs(x, u), plain.rhs(x, unit), rtol=1e-14)
            np.testing.assert_allclose(scaled.rhs(x, unit), plain.rhs(x, unit), rtol=1e-14)
        us = ca.SX.sym("u", 3)
        xs = ca.SX.sym("x", 7)
        J = ca.Function("J", [xs, us], [ca.jacobian(scaled.f(xs, us, ca.SX(0, 1)), us)])
        # the thrust does not depend on |u|: d xdot/du . u = 0
        np.testing.assert_allclose(np.asarray(J(x, u)) @ u, 0.0, atol=1e-9)
    with pytest.raises(TypeError, match="`normalized`"):
        d3.delta3_model(0, normalized="yes")


# ------------------------------------------------------------ (d) mass flow and masses
ISP_ASSET = {"srb": 283.33364, "first": 301.68, "second": 467.21}  # [s], as ASSET prints them


def test_mass_rate_per_phase_is_thrust_over_g0_isp():
    g0 = 9.80665
    flow = {k: thrust / (g0 * ISP_ASSET[k]) for k, thrust in
            (("srb", 628500.0), ("first", 1083100.0), ("second", 110094.0))}
    expected = [6 * flow["srb"] + flow["first"], 3 * flow["srb"] + flow["first"],
                flow["first"], flow["second"]]
    x = np.r_[d3.initial_state()[:6] * 1.2, 1.0e5]
    for phase, mdot in enumerate(expected):
        assert d3.delta3_model(phase).rhs(x, [0.0, 1.0, 0.0])[6] == pytest.approx(-mdot, rel=5e-5)
    np.testing.assert_allclose([d3.SRB_ISP, d3.STAGE1_ISP, d3.STAGE2_ISP],
                               list(ISP_ASSET.values()), rtol=5e-5)  # 301.68 is rounded
    # exactly: each motor burns its propellant in its burn time
    exact = [6 * 17010 / 75.2 + 95550 / 261, 3 * 17010 / 75.2 + 95550 / 261, 95550 / 261,
             16820 / 700]
    for phase, mdot in enumerate(exact):
        assert d3.delta3_model(phase).rhs(x, [0.0, 1.0, 0.0])[6] == pytest.approx(-mdot, rel=1e-14)
        assert d3.PHASES[phase].mass_flow == pytest.approx(mdot, rel=1e-14)
        assert d3.PHASES[phase].isp * 9.80665 * mdot == pytest.approx(d3.PHASES[phase].thrust,
                                                                      rel=1e-14)


def test_stage_masses_match_published_totals():
    assert d3.LAUNCH_MASS == 301454.0  # 9 x 19290 + 104380 + 19300 + 4164
    assert (d3.SRB_DRY, d3.STAGE1_DRY, d3.STAGE2_DRY) == (2280.0, 8830.0, 2480.0)
    p = d3.PHASES
    # phase start masses as the yapss example writes them (propellant fractions burned)
    m0 = 301454.0
    m0f = m0 - 6 * 17010 - 75.2 / 261 * 95550
    m1 = m0f - 6 * 2280
    m1f = m1 - 3 * 17010 - 75.2 / 261 * 95550
    m2 = m1f - 3 * 2280
    m2f = m2 - (1 - 2 * 75.2 / 261) * 95550
    m3 = m2f - 8830
    np.testing.assert_allclose([ph.mass_start for ph in p], [m0, m1, m2, m3], rtol=1e-13)
    assert p[3].mass_start == pytest.approx(4164.0 + 19300.0, rel=1e-13)
    assert p[3].mass_end_min == pytest.approx(4164.0 + 2480.0, rel=1e-12)
    assert [ph.dry_mass_dropped for ph in p] == [13680.0, 6840.0, 8830.0, 0.0]
    assert [(ph.t_start, ph.t_end, ph.t_end_max) for ph in p] == [
        (0.0, 75.2, 75.2), (75.2, 150.4, 150.4), (150.4, 261.0, 261.0), (261.0, None, 961.0)]
    assert [ph.thrust for ph in p] == [4854100.0, 2968600.0, 1083100.0, 110094.0]
    assert d3.FINAL_TIME_BETTS < p[3].t_end_max and d3.FINAL_MASS_BETTS > p[3].mass_end_min


# ------------------------------------------------------------------------------ (e) drag
def test_no_drag_at_launch():
    x0 = d3.initial_state()
    r = x0[:3]
    assert np.linalg.norm(r) == pytest.approx(6378145.0, rel=1e-15)
    np.testing.assert_allclose(x0[3:6], np.cross([0, 0, OMEGA], r), rtol=1e-15, atol=1e-12)
    np.testing.assert_array_equal(d3.drag_force(r, x0[3:6]), 0.0)
    u = np.array([0.6, 0.0, 0.8])
    xdot = d3.delta3_model(0).rhs(x0, u)
    gravity = -MU * r / np.linalg.norm(r) ** 3
    np.testing.assert_allclose(xdot[3:6], gravity + 4854100.0 * u / 301454.0, rtol=1e-14)


def test_drag_opposes_relative_velocity():
    rng = np.random.default_rng(4)
    model = d3.delta3_model(2)
    for _ in range(5):
        r = rng.standard_normal(3)
        r *= (6378145.0 + rng.uniform(0, 60e3)) / np.linalg.norm(r)
        v = np.cross([0, 0, OMEGA], r) + rng.uniform(50, 3000) * rng.standard_normal(3)
        m = rng.uniform(3e4, 3e5)
        xdot = model.rhs(np.r_[r, v, m], np.zeros(3))
        drag_acc = xdot[3:6] + MU * r / np.linalg.norm(r) ** 3
        vrel = v - np.cross([0, 0, OMEGA], r)
        rho = 1.225 * math.exp(-(np.linalg.norm(r) - 6378145.0) / 7200.0)
        expected = -0.5 * 0.5 * 4 * math.pi * rho * np.linalg.norm(vrel) * vrel / m
        np.testing.assert_allclose(drag_acc, expected, rtol=1e-9, atol=1e-12)
        cosine = drag_acc @ vrel / (np.linalg.norm(drag_acc) * np.linalg.norm(vrel))
        assert cosine == pytest.approx(-1.0, abs=1e-12)
        np.testing.assert_allclose(d3.drag_force(r, v), -m * expected, rtol=1e-9)


def test_sensitivities_finite_at_rest():
    model = d3.delta3_model(0)
    x, u = ca.SX.sym("x", 7), ca.SX.sym("u", 3)
    xdot = model.f(x=x, u=u, p=ca.DM.zeros(0))["xdot"]
    jac = ca.Function("rhs_jacobian", [x, u], [ca.jacobian(xdot, ca.vertcat(x, u))])
    assert np.all(np.isfinite(np.asarray(jac(d3.initial_state(), [1.0, 0.0, 0.0]))))


# ------------------------------------------------------------ model, bounds and guess
def test_model_names_and_cache():
    model = d3.delta3_model(1)
    assert model.states == ("rx", "ry", "rz", "vx", "vy", "vz", "m")
    assert model.controls == ("ux", "uy", "uz") and model.params == ()
    assert d3.delta3_model(1) is model and d3.delta3_model(2) is not model
    with pytest.raises(ValueError, match="`phase`"):
        d3.delta3_model(4)
    with pytest.raises(TypeError, match="`phase`"):
        d3.delta3_model("0")


def test_bounds_and_guess_are_consistent():
    previous = None
    for phase in range(4):
        xb, ub = d3.phase_bounds(phase)
        assert xb.shape == (2, 7) and ub.shape == (2, 3)
        g = d3.guess(phase, n=9)
        assert g["t"].shape == (9,) and g["x"].shape == (7, 9) and g["u"].shape == (3, 9)
        assert np.all(g["x"] >= xb[0:1].T - 1e-6) and np.all(g["x"] <= xb[1:2].T + 1e-6)
        np.testing.assert_allclose(np.linalg.norm(g["u"], axis=0), 1.0, rtol=1e-12)
        assert np.all(np.linalg.norm(g["x"][:3], axis=0) >= d3.RE - 1e-6)  # above ground
        data = d3.PHASES[phase]
        assert g["t"][0] == data.t_start
        assert g["x"][6, 0] == pytest.approx(data.mass_start, rel=1e-12)
        if previous is not None:
            np.testing.assert_allclose(g["x"][:6, 0], previous["x"][:6, -1], rtol=1e-12)
        previous = g
    assert previous["t"][-1] == pytest.approx(961.0)
    # the guess ends on the target orbit's perigee (state_from_elements inverts orbital_elements)
    el = d3.orbital_elements(previous["x"][:3, -1], previous["x"][3:6, -1])
    for k in ("a", "e", "i", "raan", "argp"):
        assert getattr(el, k) == pytest.approx(d3.TARGET_ORBIT[k], rel=1e-12)
    assert abs(math.remainder(float(el.nu), 2 * math.pi)) < 1e-9
    np.testing.assert_array_equal(d3.guess(0, 5)["x"][:, 0], d3.initial_state())
    with pytest.raises(ValueError, match="`n`"):
        d3.guess(0, n=1)


def test_docstring_examples():
    import doctest

    finder = doctest.DocTestFinder(exclude_empty=True)
    runner = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE)
    for test in finder.find(d3, d3.__name__):
        runner.run(test)
    assert runner.summarize(verbose=False).failed == 0
    assert runner.summarize(verbose=False).attempted >= 3
