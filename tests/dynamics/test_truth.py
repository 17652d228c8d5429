"""Tests of the closed-form truths in ``dynamics.truth`` against independent references.

The references never use the closed forms: Euler's equations ``I w' = (I w) x w`` and the
quaternion kinematics ``qv' = 1/2 (q4 w + qv x w)``, ``q4' = -1/2 w . qv`` are integrated with
``scipy.integrate.solve_ivp`` (DOP853, ``rtol = atol = 1e-13``); the DCM and the matrix
exponential come from their definitions. Closed form and integration must agree to
``1e-9`` relative to ``|w0|`` (observed ~1e-12).
"""
import itertools

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp
from scipy.linalg import expm
from scipy.optimize import minimize_scalar

from appdyn.dynamics import truth

INTEGRATOR = dict(method="DOP853", rtol=1e-13, atol=1e-13)
TOL = 1e-9  # closed form vs. integration, relative to |w0| (or absolute for quaternions)
INVARIANT_TOL = 1e-12  # relative drift of T and |H| along the closed form

BASE = np.array([1.0, 1.7, 2.3])  # a triaxial body, ascending


# ---------------------------------------------------------------- independent references
def euler_rhs(inertia):
    inertia = np.asarray(inertia, dtype=float)

    def rhs(_t, w):
        return np.cross(inertia * w, w) / inertia

    return rhs


def attitude_rhs(inertia):
    inertia = np.asarray(inertia, dtype=float)

    def rhs(_t, x):
        qv, q4, w = x[:3], x[3], x[4:]
        qdot = np.concatenate([0.5 * (q4 * w + np.cross(qv, w)), [-0.5 * w @ qv]])
        return np.concatenate([qdot, np.cross(inertia * w, w) / inertia])

    return rhs


def integrate_rates(inertia, w0, t):
    """Euler's equations from t = 0 to every t (forward and/or backward)."""
    t = np.asarray(t, dtype=float)
    out = np.empty((3, t.size))
    for mask in (t >= 0, t < 0):
        if not mask.any():
            continue
        ts = t[mask]
        end = ts.max() if ts[0] >= 0 else ts.min()
        sol = solve_ivp(euler_rhs(inertia), (0.0, end), w0, dense_output=True, **INTEGRATOR)
        assert sol.success
        out[:, mask] = sol.sol(ts)
    return out


def integrate_attitude(inertia, w0, q0, t):
    sol = solve_ivp(
        attitude_rhs(inertia), (0.0, t[-1]), np.concatenate([q0, w0]), t_eval=t, **INTEGRATOR
    )
    assert sol.success
    return sol.y[4:], sol.y[:4]


def dcm(q):
    """A(q) = (q4^2 - |qv|^2) E + 2 qv qv^T - 2 q4 [qv x] (inertial -> body)."""
    qv, q4 = q[:3], q[3]
    return (q4 * q4 - qv @ qv) * np.eye(3) + 2 * np.outer(qv, qv) - 2 * q4 * skew(qv)


def skew(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def rel_err(a, b, w0):
    return np.max(np.abs(a - b)) / np.linalg.norm(w0)


def energy_ref(inertia, w):
    return 0.5 * np.sum(np.asarray(inertia)[:, None] * w**2, axis=0)


def momentum_ref(inertia, w):
    return np.linalg.norm(np.asarray(inertia)[:, None] * w, axis=0)


def unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


Q0 = unit([0.1, -0.3, 0.5, 0.8])


# ------------------------------------------------------------ general torque-free motion
# Rates in ascending-moment axes for BASE, one per branch: D > I2 (polhode about the
# largest-moment axis) and D < I2 (about the smallest-moment axis).
SORTED_W0 = {"major": np.array([0.6, -0.5, 1.1]), "minor": np.array([1.3, 0.5, -0.45])}


@pytest.mark.parametrize("perm", list(itertools.permutations(range(3))))
@pytest.mark.parametrize("branch", ["major", "minor"])
def test_every_ordering_and_branch_matches_integration(perm, branch):
    inertia = BASE[list(perm)]  # caller axis j carries sorted axis perm[j]
    w0 = SORTED_W0[branch][list(perm)]
    t = np.linspace(0.0, 40.0, 801)
    prm = truth.torque_free_parameters(inertia, w0)
    d_eff = momentum_ref(inertia, w0[:, None])[0] ** 2 / (2 * energy_ref(inertia, w0[:, None])[0])
    assert (d_eff > BASE[1]) == (branch == "major")  # the case really is this branch
    assert prm.branch == branch
    assert prm.axis_index == perm.index(2 if branch == "major" else 0)
    assert prm.D == pytest.approx(d_eff, rel=1e-14)
    assert 0.0 < prm.m < 1.0
    assert prm.lam * 40.0 > 2 * np.pi  # the run covers more than a period of u
    w = truth.torque_free_omega(inertia, w0, t)
    assert w.shape == (3, t.size)
    np.testing.assert_array_equal(truth.torque_free_omega(inertia, w0, 0.0)[:, 0], w[:, 0])
    assert rel_err(w[:, 0], w0, w0) < 1e-14
    assert rel_err(w, integrate_rates(inertia, w0, t), w0) < TOL


@pytest.mark.parametrize("branch", ["major", "minor"])
@pytest.mark.parametrize("signs", list(itertools.product([1.0, -1.0], repeat=3)))
def test_all_sign_combinations_of_initial_rates(branch, signs):
    inertia = BASE[[2, 0, 1]]  # an even, non-identity ordering
    w0 = (SORTED_W0[branch] * np.array(signs))[[2, 0, 1]]
    t = np.linspace(0.0, 20.0, 201)
    assert truth.torque_free_parameters(inertia, w0).branch == branch
    assert rel_err(truth.torque_free_omega(inertia, w0, t), integrate_rates(inertia, w0, t), w0) < TOL


def test_negative_and_unsorted_times():
    inertia, w0 = BASE[[1, 2, 0]], np.array([0.4, -0.9, 0.7])
    t = np.array([3.0, -7.5, 0.0, 12.0, -1.0, 5.5])
    w = truth.torque_free_omega(inertia, w0, t)
    assert rel_err(w, integrate_rates(inertia, w0, t), w0) < TOL


def test_scalar_time_gives_one_column():
    w = truth.torque_free_omega(BASE, [0.1, 0.2, 0.3], 2.5)
    assert w.shape == (3, 1)
    _, q = truth.axisymmetric([1.0, 1.0, 1.5], [0.1, 0.2, 0.3], Q0, 2.5)
    assert q.shape == (4, 1)
    assert truth.constant_rate_quat(Q0, [0.1, 0.2, 0.3], 2.5).shape == (4, 1)


@pytest.mark.parametrize("delta", [1e-6, -1e-6, 1e-3, -1e-3])
@pytest.mark.parametrize("perm", [(0, 1, 2), (2, 0, 1), (1, 0, 2)])
def test_near_separatrix(delta, perm):
    # I = (1, 2, 9/4), w = (3/4, w2, 1) lies exactly on the separatrix D = I2; scaling w1 by
    # (1 + delta) moves it off: delta > 0 lowers D (minor branch), delta < 0 raises it.
    sorted_inertia = np.array([1.0, 2.0, 2.25])
    sorted_w0 = np.array([0.75 * (1 + delta), 0.3, 1.0])
    inertia, w0 = sorted_inertia[list(perm)], sorted_w0[list(perm)]
    if perm == (1, 0, 2):  # also exercise negative rates
        w0 = -w0
    prm = truth.torque_free_parameters(inertia, w0)
    assert prm.branch == ("minor" if delta > 0 else "major")
    assert 0 < prm.m1 < 10 * abs(delta)
    assert prm.m + prm.m1 == pytest.approx(1.0, rel=1e-15)
    t = np.linspace(0.0, 30.0, 601)
    assert rel_err(truth.torque_free_omega(inertia, w0, t), integrate_rates(inertia, w0, t), w0) < TOL


def test_exact_separatrix():
    inertia, w0 = np.array([1.0, 2.0, 2.25]), np.array([0.75, 0.3, 1.0])
    prm = truth.torque_free_parameters(inertia, w0)
    assert prm.m == 1.0 and prm.period == np.inf and prm.D == pytest.approx(2.0, rel=1e-15)
    t = np.linspace(0.0, 25.0, 501)
    w = truth.torque_free_omega(inertia, w0, t)
    assert rel_err(w, integrate_rates(inertia, w0, t), w0) < TOL
    # The motion tends to the intermediate-axis spin with w1, w3 -> 0 (sech), keeping signs.
    assert np.all(w[0] > 0) and np.all(w[2] > 0) and abs(w[0, -1]) < 1e-3 * abs(w[1, -1])
    # the other side of the separatrix (w1 < 0) keeps its sign too
    w_neg = truth.torque_free_omega(inertia, -w0, t)
    assert np.all(w_neg[0] < 0) and np.all(w_neg[2] < 0)
    assert rel_err(w_neg, integrate_rates(inertia, -w0, t), w0) < TOL


@pytest.mark.parametrize(
    "inertia, w0",
    [
        ([1.0, 1.7, 2.3], [1.2, 0.0, 0.0]),
        ([1.0, 1.7, 2.3], [0.0, -1.2, 0.0]),  # unstable, but exactly stationary
        ([1.0, 1.7, 2.3], [0.0, 0.0, 0.8]),
        ([1.5, 1.5, 1.5], [0.3, -1.1, 0.7]),  # sphere
        ([2.0, 2.0, 3.0], [0.4, -0.9, 0.0]),  # oblate body turning about a transverse axis
        ([2.0, 3.0, 3.0], [0.0, -0.9, 0.4]),  # prolate likewise
        ([1.0, 1.7, 2.3], [0.0, 0.0, 0.0]),
    ],
)
def test_steady_rotations_are_exactly_constant(inertia, w0):
    t = np.linspace(-5.0, 50.0, 56)
    w = truth.torque_free_omega(inertia, w0, t)
    np.testing.assert_array_equal(w, np.repeat(np.array(w0)[:, None], t.size, axis=1))
    assert truth.torque_free_parameters(inertia, w0).branch == "steady"
    if any(w0):
        t_ref = np.linspace(0.0, 50.0, 11)
        ref = integrate_rates(inertia, np.array(w0), t_ref)
        assert rel_err(truth.torque_free_omega(inertia, w0, t_ref), ref, w0) < TOL


@pytest.mark.parametrize("spin_axis, horizon", [(1, 40.0), (2, 40.0), (0, 20.0)])
def test_slightly_perturbed_principal_spin(spin_axis, horizon):
    inertia = BASE[[1, 0, 2]]  # axis 0 is the intermediate one: unstable, shorter run
    w0 = np.full(3, 1e-7)
    w0[spin_axis] = 1.0
    t = np.linspace(0.0, horizon, 401)
    assert rel_err(truth.torque_free_omega(inertia, w0, t), integrate_rates(inertia, w0, t), w0) < TOL


@pytest.mark.parametrize("perturbation", [1e-3, 1e-5])
def test_group_property_near_the_intermediate_axis(perturbation):
    # Over two polhode periods a start this close to the separatrix is beyond what the
    # integrator resolves (its error reaches 5e-5 for 1e-5), so this checks the closed form
    # against itself: w(t; w0) == w(t - t1; w(t1; w0)), which would fail if the phase or
    # the quarter period K were inaccurate (scipy's ellipj(u, m), given only m, is off by
    # 3e-6 here). The first 20 s are checked against integration above.
    inertia = BASE[[1, 0, 2]]
    w0 = np.array([1.0, perturbation, perturbation])
    prm = truth.torque_free_parameters(inertia, w0)
    t = np.linspace(0.0, 2.2 * prm.period, 2001)
    w = truth.torque_free_omega(inertia, w0, t)
    t1 = 0.37 * prm.period
    w_t1 = truth.torque_free_omega(inertia, w0, t1)[:, 0]
    assert rel_err(w, truth.torque_free_omega(inertia, w_t1, t - t1), w0) < 1e-10
    # and w returns to w0 after each period
    assert rel_err(truth.torque_free_omega(inertia, w0, [prm.period, 2 * prm.period]),
                   np.stack([w0, w0], axis=1), w0) < 1e-10


@pytest.mark.parametrize("factor", [1e-150, 1e-3, 1e3, 1e150])
def test_scaling_laws(factor):
    # If w(t) solves Euler's equations so does c w(c t); scaling all moments changes nothing.
    inertia, w0 = BASE[[2, 0, 1]], np.array([0.4, -0.9, 0.7])
    t = np.linspace(-10.0, 30.0, 81)
    w = truth.torque_free_omega(inertia, w0, t)
    scaled = truth.torque_free_omega(inertia, factor * w0, t / factor) / factor
    assert rel_err(scaled, w, w0) < 1e-13
    assert rel_err(truth.torque_free_omega(factor * inertia, w0, t), w, w0) < 1e-13


def test_tiny_components_do_not_underflow():
    # found by hypothesis: a subnormal rate component made H^2 - 2T I1 underflow to 0/0
    w0 = np.array([0.0, 1.0, 2.2250738585e-311])
    w = truth.torque_free_omega([1.0, 1.0, 2.0], w0, np.linspace(0.0, 10.0, 11))
    assert np.all(np.isfinite(w))
    assert rel_err(w, np.repeat(w0[:, None], 11, axis=1), w0) < 1e-300


@pytest.mark.parametrize(
    "inertia, w0",
    [
        ([2.0, 2.0, 3.5], [0.3, -0.8, 1.1]),  # oblate, symmetric about axis 2
        ([3.5, 2.0, 2.0], [1.1, 0.3, -0.8]),  # oblate, symmetric about axis 0
        ([1.0, 3.0, 3.0], [-1.1, 0.3, 0.8]),  # prolate, symmetric about axis 0
        ([3.0, 1.0, 3.0], [0.3, -1.1, 0.8]),  # prolate, symmetric about axis 1
        ([2.0, 2.0 * (1 + 1e-13), 3.0], [0.3, -0.8, 1.1]),  # nearly axisymmetric
        ([1.0, 3.0, 3.0 * (1 + 1e-13)], [-1.1, 0.3, 0.8]),
    ],
)
def test_axisymmetric_and_nearly_axisymmetric_rates(inertia, w0):
    t = np.linspace(0.0, 40.0, 401)
    w = truth.torque_free_omega(inertia, w0, t)
    assert truth.torque_free_parameters(inertia, w0).m < 1e-12
    assert rel_err(w, integrate_rates(inertia, w0, t), w0) < TOL


# ------------------------------------------------------------------ invariants
@pytest.mark.parametrize(
    "inertia, w0",
    [
        (BASE, SORTED_W0["major"]),
        (BASE[[2, 1, 0]], SORTED_W0["minor"]),
        ([1.0, 2.0, 2.25], [0.75, 0.3, 1.0]),  # separatrix, m = 1
        ([1.0, 2.0, 2.25], [0.75 * (1 + 1e-9), 0.3, 1.0]),  # m = 1 - O(1e-9)
        ([1.0, 1.0, 1.8], [0.4, 0.7, -1.3]),
        ([1e4, 1.7e4, 2.3e4], [3e-3, -1e-3, 2e-3]),  # spacecraft-like magnitudes
    ],
)
def test_closed_form_conserves_energy_and_momentum(inertia, w0):
    t = np.linspace(-100.0, 400.0, 5001)
    w = truth.torque_free_omega(inertia, w0, t)
    e, h = truth.energy(inertia, w), truth.momentum_magnitude(inertia, w)
    e0, h0 = truth.energy(inertia, w0), truth.momentum_magnitude(inertia, w0)
    assert e0 == pytest.approx(energy_ref(inertia, np.array(w0)[:, None])[0], rel=1e-15)
    assert h0 == pytest.approx(momentum_ref(inertia, np.array(w0)[:, None])[0], rel=1e-15)
    assert np.max(np.abs(e / e0 - 1)) < INVARIANT_TOL
    assert np.max(np.abs(h / h0 - 1)) < INVARIANT_TOL


# ------------------------------------------------------------ small asymmetry (Sec. 4.5 C)
SMALL_ASYM = {"rod": np.array([1.0, 5.0, 5.2]), "disk": np.array([2.0, 1.05, 1.0])}


@pytest.mark.parametrize("body", ["rod", "disk"])
def test_small_asymmetry_frequency_is_the_exact_limit(body):
    inertia, w_spin = SMALL_ASYM[body], 1.3
    lam1, lam2 = truth.small_asymmetry_rates(inertia, w_spin, axis_index=0)
    assert lam1 == pytest.approx((inertia[0] - inertia[2]) / inertia[1] * w_spin, rel=1e-15)
    assert lam2 == pytest.approx((inertia[0] - inertia[1]) / inertia[2] * w_spin, rel=1e-15)
    assert (lam1 < 0) == (body == "rod")
    freq = truth.small_asymmetry_frequency(inertia, w_spin)
    assert freq == pytest.approx(np.sqrt(lam1 * lam2), rel=1e-15)
    # With the seed's initial condition w2(0) = 0 the exact rate equals sqrt(l1 l2) with
    # w0 = w1(0) for every nutation amplitude ...
    for eps in (1e-1, 1e-3):
        lam = truth.torque_free_parameters(inertia, [w_spin, 0.0, eps * w_spin]).lam
        assert lam == pytest.approx(freq, rel=1e-13)
    # ... and for w2(0) != 0 it converges to it at second order in the nutation.
    errs = [
        abs(truth.torque_free_parameters(inertia, [w_spin, eps * w_spin, 0.0]).lam / freq - 1)
        for eps in (1e-2, 1e-3)
    ]
    assert 0 < errs[1] < 1e-5
    assert errs[1] / errs[0] == pytest.approx(1e-2, rel=0.05)


@pytest.mark.parametrize("body", ["rod", "disk"])
def test_small_asymmetry_linear_solution_of_the_seed(body):
    # Eqs. 4.99-4.100: w2 = -l1 w3(0)/sqrt(l1 l2) sin(lt), w3 = w3(0) cos(lt), w2(0) = 0.
    inertia, w_spin = SMALL_ASYM[body], 1.3
    lam1, lam2 = truth.small_asymmetry_rates(inertia, w_spin)
    freq = np.sqrt(lam1 * lam2)
    t = np.linspace(0.0, 20.0, 401)
    errs = []
    for eps in (1e-2, 1e-3):
        w30 = eps * w_spin
        w = truth.torque_free_omega(inertia, [w_spin, 0.0, w30], t)
        lin = np.stack([-lam1 * w30 / freq * np.sin(freq * t), w30 * np.cos(freq * t)])
        # the linearization holds w1 = w0 fixed; the exact w1 varies at O(eps^2)
        assert np.max(np.abs(w[0] - w_spin)) < eps**2 * w_spin
        errs.append(np.max(np.abs(w[1:] - lin)) / w30)  # relative to the nutation amplitude
    assert errs[1] < 2e-6
    assert errs[1] / errs[0] == pytest.approx(1e-2, rel=0.05)  # second order in eps


@pytest.mark.parametrize("body", ["rod", "disk"])
def test_period_matches_integrated_zero_crossings(body):
    inertia, w_spin, eps = SMALL_ASYM[body], 1.3, 1e-3
    w0 = np.array([w_spin, 0.0, eps * w_spin])
    prm = truth.torque_free_parameters(inertia, w0)

    def w2_zero(_t, w):
        return w[1]

    # w2 starts at 0 moving up (rod) or down (disk); count the crossings after half periods
    w2_zero.direction = 1.0 if body == "disk" else -1.0
    sol = solve_ivp(euler_rhs(inertia), (0.0, 3.2 * prm.period), w0, events=w2_zero, **INTEGRATOR)
    crossings = sol.t_events[0]
    assert len(crossings) == 3
    assert np.diff(crossings) == pytest.approx(prm.period, rel=1e-10)
    lin_period = 2 * np.pi / truth.small_asymmetry_frequency(inertia, w_spin)
    assert 0 < abs(prm.period / lin_period - 1) < 10 * eps**2


def test_small_asymmetry_frequency_other_axes():
    inertia = np.array([5.0, 1.0, 5.2])  # spin about axis 1, the smallest moment
    lam1, lam2 = truth.small_asymmetry_rates(inertia, 2.0, axis_index=1)
    assert lam1 == pytest.approx((1.0 - 5.0) / 5.2 * 2.0) and lam2 == pytest.approx((1.0 - 5.2) / 5.0 * 2.0)
    # exact identity when the intermediate-axis rate (here axis 0) is zero
    lam = truth.torque_free_parameters(inertia, [0.0, 2.0, 1e-3]).lam
    assert lam == pytest.approx(truth.small_asymmetry_frequency(inertia, 2.0, axis_index=1),
                                rel=1e-13)


# ------------------------------------------------------------------ cone angles
def _angle_extremes(inertia, w0, axis_index, period):
    """Min and max angle between H (body) and the principal axis on the integrated motion."""
    sol = solve_ivp(euler_rhs(inertia), (0.0, period), w0, dense_output=True, **INTEGRATOR)

    def angle(tt):
        h = np.asarray(inertia) * sol.sol(tt)
        return np.arctan2(np.hypot(*np.delete(h, axis_index)), abs(h[axis_index]))

    grid = np.linspace(0.0, period, 2001)
    values = np.array([angle(tt) for tt in grid])
    out = []
    for sign, k in ((1.0, np.argmin(values)), (-1.0, np.argmax(values))):
        lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
        res = minimize_scalar(lambda tt: sign * angle(tt), bounds=(lo, hi), method="bounded",
                              options={"xatol": 1e-12})
        out.append(sign * res.fun)
    return out


@pytest.mark.parametrize("branch", ["major", "minor"])
def test_cone_angles_match_integrated_extremes(branch):
    perm = [1, 2, 0]
    inertia, w0 = BASE[perm], SORTED_W0[branch][perm]
    cones = truth.cone_angles(inertia, w0)
    prm = truth.torque_free_parameters(inertia, w0)
    assert cones.axis_index == prm.axis_index
    lo, hi = _angle_extremes(inertia, w0, cones.axis_index, prm.period)
    assert 0 < cones.theta_min < cones.theta_max < np.pi / 2
    assert cones.theta_min == pytest.approx(lo, abs=1e-9)
    assert cones.theta_max == pytest.approx(hi, abs=1e-9)


def test_cone_angle_ratio_small_asymmetry_limit():
    # Seed: alpha_max / alpha_min -> sqrt(I2 (I3 - I1) / (I3 (I2 - I1))) for small nutation.
    inertia = SMALL_ASYM["rod"]
    cones = truth.cone_angles(inertia, [1.0, 0.0, 1e-5])
    i1, i2, i3 = inertia
    ratio = np.tan(cones.theta_max) / np.tan(cones.theta_min)
    assert ratio == pytest.approx(np.sqrt(i2 * (i3 - i1) / (i3 * (i2 - i1))), rel=1e-8)
    assert np.tan(cones.theta_min) == pytest.approx(i3 * 1e-5 / i1, rel=1e-8)  # alpha_min


def test_cone_angles_axisymmetric_are_equal():
    cones = truth.cone_angles([2.0, 3.5, 2.0], [0.3, 1.1, -0.8])
    assert cones.axis_index == 1
    assert cones.theta_min == pytest.approx(cones.theta_max, rel=1e-14)
    assert np.tan(cones.theta_min) == pytest.approx(2.0 * np.hypot(0.3, 0.8) / (3.5 * 1.1), rel=1e-14)


# ------------------------------------------------------------------ attitude
@pytest.mark.parametrize(
    "inertia, w0, axis_index",
    [
        ([1.8, 1.0, 1.0], [1.0, 0.3, -0.5], 0),  # oblate (axial moment largest), lam > 0
        ([1.0, 3.0, 3.0], [1.0, 0.3, -0.5], 0),  # prolate, lam < 0
        ([2.0, 2.0, 3.5], [0.2, -0.4, 1.5], 2),
        ([1.0, 2.0, 1.0], [0.5, -1.0, 0.4], 1),
        ([2.0, 2.0, 2.0], [0.3, 0.2, 0.1], 0),  # sphere: constant rate
        ([2.0, 2.0, 3.5], [0.2, -0.4, 0.0], 2),  # no axial rate: steady transverse rotation
    ],
)
def test_axisymmetric_attitude_matches_integration(inertia, w0, axis_index):
    w0 = np.array(w0)
    t = np.linspace(0.0, 40.0, 401)
    w, q = truth.axisymmetric(inertia, w0, Q0, t)
    w_ax, q_ax = truth.axisymmetric(inertia, w0, Q0, t, axis_index=axis_index)
    np.testing.assert_array_equal(w, w_ax)
    np.testing.assert_array_equal(q, q_ax)
    assert w.shape == (3, t.size) and q.shape == (4, t.size)
    w_ref, q_ref = integrate_attitude(inertia, w0, Q0, t)
    assert rel_err(w, w_ref, w0) < TOL
    assert np.max(np.abs(q - q_ref)) < TOL  # no sign flips: both are continuous from q0
    np.testing.assert_allclose(q[:, 0], Q0, rtol=0, atol=1e-15)
    assert np.max(np.abs(np.linalg.norm(q, axis=0) - 1)) < 1e-14
    assert rel_err(w, truth.torque_free_omega(inertia, w0, t), w0) < 1e-13
    # inertial angular momentum A(q)^T I w is constant
    h_in = np.stack([dcm(q[:, k]).T @ (np.asarray(inertia) * w[:, k]) for k in range(t.size)], axis=1)
    h0 = np.linalg.norm(h_in[:, 0])
    assert np.max(np.abs(h_in - h_in[:, :1])) < INVARIANT_TOL * h0


def test_symmetric_precession_rates_from_integrated_attitude():
    inertia, w0 = np.array([1.0, 3.0, 3.0]), np.array([1.2, 0.3, -0.5])
    prec = truth.symmetric_precession(inertia, w0)
    assert prec.axis_index == 0
    n = w0[0]
    assert prec.lam == pytest.approx((1.0 - 3.0) / 3.0 * n, rel=1e-15)
    t = np.linspace(0.0, 30.0, 3001)
    w_ref, q_ref = integrate_attitude(inertia, w0, Q0, t)
    # transverse rate turns about +e at lam in the body frame
    ang_w = np.unwrap(np.arctan2(w_ref[2], w_ref[1]))
    assert (ang_w[-1] - ang_w[0]) / t[-1] == pytest.approx(prec.lam, rel=1e-10)
    # symmetry axis precesses about the inertial H at omega_p with constant nutation
    dcms = [dcm(q_ref[:, k]) for k in range(t.size)]
    h_in = unit(dcms[0].T @ (inertia * w0))
    e_in = np.stack([a[0] for a in dcms], axis=1)  # first body axis in inertial components
    nut = np.arccos(np.clip(h_in @ e_in, -1, 1))
    assert np.max(np.abs(nut - prec.nutation)) < 1e-10
    b1 = unit(np.cross(h_in, e_in[:, 0]))
    b2 = np.cross(h_in, b1)
    ang_e = np.unwrap(np.arctan2(b2 @ e_in, b1 @ e_in))
    assert (ang_e[-1] - ang_e[0]) / t[-1] == pytest.approx(prec.omega_p, rel=1e-10)
    # seed note: for small nutation omega_p -> I_a / I_t * n = n + lam
    small = truth.symmetric_precession(inertia, [1.2, 1e-6, 0.0])
    assert small.omega_p == pytest.approx(1.0 / 3.0 * 1.2, rel=1e-11)
    assert small.omega_p == pytest.approx(1.2 + small.lam, rel=1e-11)


def test_constant_rate_quat_matches_integration_and_matrix_exponential():
    w = np.array([0.3, -1.2, 0.7])
    t = np.linspace(0.0, 40.0, 401)
    q = truth.constant_rate_quat(Q0, w, t)
    sol = solve_ivp(
        lambda _t, x: np.concatenate([0.5 * (x[3] * w + np.cross(x[:3], w)), [-0.5 * w @ x[:3]]]),
        (0.0, t[-1]), Q0, t_eval=t, **INTEGRATOR,
    )
    assert np.max(np.abs(q - sol.y)) < TOL
    a0 = dcm(Q0)
    for k in (0, 37, 400):
        np.testing.assert_allclose(dcm(q[:, k]), expm(-skew(w) * t[k]) @ a0, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(truth.constant_rate_quat(Q0, [0.0, 0.0, 0.0], t), np.repeat(Q0[:, None], t.size, axis=1))


# ------------------------------------------------------------------ property-based
@st.composite
def bodies(draw):
    moments = np.array([draw(st.floats(1.0, 2.0)) for _ in range(3)])  # triangle holds
    if draw(st.booleans()):  # make two moments exactly equal sometimes
        i, j = draw(st.permutations(range(3)))[:2]
        moments[i] = moments[j]
    w0 = np.array([draw(st.floats(-2.0, 2.0, allow_subnormal=False)) for _ in range(3)])
    return moments, w0


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(bodies())
@pytest.mark.slow
def test_property_closed_form_matches_integration(body):
    inertia, w0 = body
    rate = np.linalg.norm(w0)
    assume(rate > 0.05)
    # Stay off the separatrix R = H^2 - 2T I_mid = 0 of triaxial bodies, where the motion
    # itself is ill-conditioned (axisymmetric bodies have no separatrix).
    i_mid = np.sort(inertia)[1]
    r = momentum_ref(inertia, w0[:, None])[0] ** 2 - 2 * energy_ref(inertia, w0[:, None])[0] * i_mid
    triaxial = len(set(inertia.tolist())) == 3
    assume(not triaxial or abs(r) > 1e-3 * (inertia.max() * rate) ** 2)
    t = np.linspace(0.0, 10.0, 101)
    w = truth.torque_free_omega(inertia, w0, t)
    assert rel_err(w, integrate_rates(inertia, w0, t), w0) < TOL
    e, h = truth.energy(inertia, w), truth.momentum_magnitude(inertia, w)
    assert np.max(np.abs(e / e[0] - 1)) < INVARIANT_TOL
    assert np.max(np.abs(h / h[0] - 1)) < INVARIANT_TOL


# ------------------------------------------------------------------ bad input
W = [0.1, 0.2, 0.3]
BAD = [
    (truth.torque_free_omega, ([1.0, 2.0], W, 1.0), {}, "inertia_diag"),
    (truth.torque_free_omega, ([1.0, np.nan, 2.0], W, 1.0), {}, "inertia_diag"),
    (truth.torque_free_omega, ([1.0, 0.0, 1.0], W, 1.0), {}, "inertia_diag"),
    (truth.torque_free_omega, ([1.0, -2.0, 2.0], W, 1.0), {}, "inertia_diag"),
    (truth.torque_free_omega, ([1.0, 1.0, 2.5], W, 1.0), {}, "inertia_diag"),  # triangle
    (truth.torque_free_omega, ("abc", W, 1.0), {}, "inertia_diag"),
    (truth.torque_free_omega, (BASE, [0.1, 0.2], 1.0), {}, "w0"),
    (truth.torque_free_omega, (BASE, [0.1, np.inf, 0.2], 1.0), {}, "w0"),
    (truth.torque_free_omega, (BASE, W, [[0.0, 1.0]]), {}, "t"),
    (truth.torque_free_omega, (BASE, W, [0.0, np.nan]), {}, "t"),
    (truth.torque_free_parameters, (BASE, [[0.1, 0.2, 0.3]]), {}, "w0"),
    (truth.axisymmetric, (BASE, W, Q0, 1.0), {}, "inertia_diag"),  # not axisymmetric
    (truth.axisymmetric, ([1.0, 1.0, 1.5], W, Q0, 1.0), {"axis": 0}, "inertia_diag"),
    (truth.axisymmetric, ([1.0, 1.0, 1.5], W, Q0, 1.0), {"axis": 3}, "axis"),
    (truth.axisymmetric, ([1.0, 1.0, 1.5], W, Q0, 1.0), {"axis": 1.0}, "axis"),
    (truth.axisymmetric, ([1.0, 1.0, 1.5], W, 2 * Q0, 1.0), {}, "q0"),
    (truth.axisymmetric, ([1.0, 1.0, 1.5], W, Q0[:3], 1.0), {}, "q0"),
    (truth.axisymmetric, ([1.0, 1.0, 1.5], [1.0, 2.0], Q0, 1.0), {}, "w0"),
    (truth.axisymmetric, ([1.0, 1.0, 1.5], W, Q0, np.ones((2, 2))), {}, "t"),
    (truth.constant_rate_quat, (Q0, [0.1, 0.2], 1.0), {}, "w"),
    (truth.constant_rate_quat, ([0.0, 0.0, 0.0, 0.0], W, 1.0), {}, "q0"),
    (truth.constant_rate_quat, (Q0, W, [np.inf]), {}, "t"),
    (truth.energy, (BASE, np.ones((4, 2))), {}, "w"),
    (truth.momentum_magnitude, ([1.0, 2.0, 4.0], W), {}, "inertia_diag"),
    (truth.cone_angles, (BASE, [0.0, 0.0, 0.0]), {}, "w0"),
    (truth.cone_angles, ([2.0, 2.0, 2.0], W), {}, "inertia_diag"),
    (truth.small_asymmetry_frequency, (BASE, 1.0), {"axis": 1}, "axis"),  # intermediate
    (truth.small_asymmetry_rates, (BASE, [1.0, 2.0]), {}, "rate"),
    (truth.small_asymmetry_rates, (BASE, 1.0), {"axis": -1}, "axis"),
    (truth.symmetric_precession, (BASE, W), {}, "inertia_diag"),
    (truth.axisymmetric, ([1.0, 1.0, 1.5], W, Q0, 1.0), {"axis_index": 0}, "inertia_diag"),
    (truth.axisymmetric, ([1.0, 1.0, 1.5], W, Q0, 1.0), {"axis_index": 3}, "axis_index"),
    (truth.small_asymmetry_frequency, (BASE, 1.0), {"axis_index": 1}, "axis_index"),
    (truth.small_asymmetry_rates, (BASE, 1.0), {"axis_index": -1}, "axis_index"),
    (truth.symmetric_precession, ([1.0, 1.0, 1.5], W), {"axis_index": 1}, "inertia_diag"),
]


@pytest.mark.filterwarnings("ignore:the keyword `axis` is deprecated:DeprecationWarning")
@pytest.mark.parametrize("func, args, kwargs, name", BAD, ids=lambda x: getattr(x, "__name__", None))
def test_bad_input_raises_value_error_naming_the_argument(func, args, kwargs, name):
    with pytest.raises(ValueError, match=f"`{name}`"):
        func(*args, **kwargs)


# ------------------------------------------- starts on the separatrix (regression tests)
@pytest.mark.parametrize("w0", [
    [0.0, 5.0, 2.7e-83],      # intermediate-axis spin, subnormal-scale transverse rate
    [1e-60, 5.0, 0.0],
    [0.3, -1.1, 0.7],
    [0.0, 5.0, 1e-150],       # below the flush threshold: steady, still w0 at t = 0
    [0.0, 0.0, 0.0],
])
def test_initial_value_is_returned_exactly(w0):
    w = truth.torque_free_omega([1.0, 2.0, 3.0], w0, [0.0, 1.0, 0.0])
    np.testing.assert_array_equal(w[:, 0], w0)
    np.testing.assert_array_equal(w[:, 2], w0)


@pytest.mark.parametrize("w_small", [2.7e-83, -1e-120, 1e-20])
def test_tiny_transverse_rate_about_the_intermediate_axis_matches_dop853(w_small):
    """Each component to 1e-10 of itself (not of |w|), though it starts 1e-83 of |w|."""
    i1, i2, i3 = 1.0, 2.0, 3.0
    w0 = [0.0, 5.0, w_small]

    def euler(_t, w):  # Euler's torque-free equations, written out
        return [(i2 - i3) / i1 * w[1] * w[2], (i3 - i1) / i2 * w[2] * w[0],
                (i1 - i2) / i3 * w[0] * w[1]]

    t = np.linspace(0.0, 5.0, 6)
    tiny = abs(w_small) * 1e-13
    ref = solve_ivp(euler, (0.0, 5.0), w0, t_eval=t, method="DOP853", rtol=1e-13,
                    atol=[tiny, 1e-13, tiny])
    assert ref.success
    w = truth.torque_free_omega([i1, i2, i3], w0, t)
    np.testing.assert_array_equal(w[:, 0], w0)
    np.testing.assert_allclose(w[:, 1:], ref.y[:, 1:], rtol=1e-10, atol=0.0)
    assert 1e-78 * abs(w_small) / 2.7e-83 < abs(w[2, -1]) < 1e-75 * abs(w_small) / 2.7e-83


# ------------------------------------------------- vocabulary: `axis` -> `axis_index`
@pytest.mark.parametrize("func, args, index", [
    (truth.small_asymmetry_rates, (BASE, 2.0), 2),
    (truth.small_asymmetry_frequency, (BASE, 2.0), 2),
    (truth.axisymmetric, ([1.0, 1.0, 1.5], [0.1, 0.2, 0.3], Q0, [0.0, 1.0]), 2),
    (truth.symmetric_precession, ([1.0, 1.0, 1.5], [0.1, 0.2, 0.3]), 2),
])
def test_deprecated_axis_keyword_warns_and_gives_the_same_result(func, args, index):
    with pytest.warns(DeprecationWarning, match="axis_index") as record:
        old = func(*args, axis=index)
    assert record[0].filename == __file__  # points at the caller
    new = func(*args, axis_index=index)
    np.testing.assert_equal(old, new)
    with pytest.raises(TypeError, match="`axis_index` only"):
        func(*args, axis_index=index, axis=index)


@pytest.mark.filterwarnings("error")
def test_deprecated_axis_field_warns():
    results = [truth.torque_free_parameters(BASE, [0.1, 0.2, 0.3]),
               truth.cone_angles(BASE, [0.1, 0.2, 0.3]),
               truth.symmetric_precession([1.0, 1.0, 1.5], [0.1, 0.2, 0.3])]
    for res in results:
        with pytest.warns(DeprecationWarning, match="axis_index"):
            assert res.axis == res.axis_index


def test_spin_rate_is_the_deprecated_name_of_rate():
    """Vocabulary: a scalar spin rate is `rate`; `spin_rate=` still works and warns."""
    new = truth.small_asymmetry_rates([1.0, 2.0, 3.0], rate=2.0, axis_index=2)
    with pytest.warns(DeprecationWarning, match="spin_rate"):
        old = truth.small_asymmetry_rates([1.0, 2.0, 3.0], spin_rate=2.0, axis_index=2)
    assert old == new == (2.0, 2.0)
    with pytest.warns(DeprecationWarning), pytest.raises(ValueError, match="`spin_rate`"):
        truth.small_asymmetry_frequency([1.0, 2.0, 3.0], spin_rate=float("nan"))
    with pytest.raises(TypeError, match="rate"):
        truth.small_asymmetry_rates([1.0, 2.0, 3.0], 1.0, spin_rate=1.0)
