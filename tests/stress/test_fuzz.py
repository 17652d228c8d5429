"""Property-based fuzzing of the main public functions (hypothesis, few examples each).

Valid random inputs must give finite outputs that hold their invariants or agree with a
closed form; invalid random inputs (wrong shapes, NaN/inf, negative inertia, wrong types)
must raise ``TypeError``/``ValueError`` naming the argument -- never another exception,
never a silent NaN.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from appdyn.dynamics import attitude as att
from appdyn.dynamics import linearize, rigid_body, simulate
from appdyn.dynamics.truth import torque_free_omega
from appdyn.problems import slew

FUZZ = settings(max_examples=12, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
FEW = settings(max_examples=3, deadline=None, derandomize=True,
               suppress_health_check=[HealthCheck.too_slow])

finite = st.floats(min_value=-3.0, max_value=3.0, allow_nan=False, allow_infinity=False)
vec3 = st.lists(finite, min_size=3, max_size=3).map(np.array)
vec4 = st.lists(finite, min_size=4, max_size=4).map(np.array)


@st.composite
def principal_moments(draw):
    """Three positive moments obeying the triangle inequality, ratios up to 100."""
    a = draw(st.floats(0.1, 10.0))
    b = draw(st.floats(0.1, 10.0))
    lo, hi = abs(a - b), a + b
    c = draw(st.floats(max(lo, 0.1), hi))
    assume(c >= lo * (1 + 1e-9) and c <= hi * (1 - 1e-9))
    return np.array([a, b, c])


@st.composite
def unit_quats(draw):
    q = draw(vec4)
    assume(np.linalg.norm(q) > 1e-3)
    return q / np.linalg.norm(q)


@st.composite
def rotation_matrices(draw):
    return att.dcm_from_quat(draw(unit_quats()))


@st.composite
def time_grids(draw):
    n = draw(st.integers(2, 12))
    T = draw(st.floats(0.1, 20.0))
    gaps = np.array(draw(st.lists(st.floats(0.05, 1.0), min_size=n - 1, max_size=n - 1)))
    t0 = draw(st.floats(-5.0, 5.0))
    return t0 + np.concatenate([[0.0], np.cumsum(gaps) / np.sum(gaps) * T])


def _steps(inertia, w0, t, h_omega=0.005):
    """Fixed steps per output interval so that (step x fastest frequency) <= ``h_omega``."""
    omega = (np.linalg.norm(w0) + 1e-3) * np.max(inertia) / np.min(inertia)
    return int(max(10, np.ceil(np.max(np.diff(t)) * omega / h_omega)))


def _rel_drift(values):
    values = np.asarray(values)
    ref = values[..., :1]
    return float(np.max(np.abs(values - ref)) / max(np.max(np.abs(ref)), 1e-300))


# --------------------------------------------------------------------------------------------
# simulate: random rigid bodies, rates, grids
# --------------------------------------------------------------------------------------------


@FUZZ
@given(inertia=principal_moments(), w0=vec3, q0=unit_quats(), t=time_grids(),
       method=st.sampled_from(["auto", "rk8", "lie"]))
@pytest.mark.slow
def test_simulate_random_rigid_body(inertia, w0, q0, t, method):
    opts = {} if method == "auto" else {"steps": _steps(inertia, w0, t)}
    res = simulate(rigid_body(inertia), [*q0, *w0], t, method=method, invariants=True, **opts)
    assert res.x.shape == (7, len(t))
    assert res.success, res.message
    assert np.all(np.isfinite(res.x))
    assert _rel_drift(res.invariants["energy"]) < 1e-6 or np.linalg.norm(w0) < 1e-8
    H = res.invariants["momentum_inertial"]
    assert np.max(np.linalg.norm(H - H[:, :1], axis=0)) <= 1e-6 * (1 + np.linalg.norm(H[:, 0]))
    assert np.max(np.abs(res.invariants["quat_norm"] - 1.0)) < 1e-6
    w_true = torque_free_omega(inertia, w0, t - t[0])
    if method == "auto":  # success means checked: within 10x the asked tolerance
        err = np.abs(res.x[4:] - w_true) / (1e-10 + 1e-8 * np.abs(w_true))
        assert np.max(err) <= 10.0
    else:
        assert np.max(np.abs(res.x[4:] - w_true)) < 1e-3


@FUZZ
@given(inertia=principal_moments(), R=rotation_matrices(), w0=vec3, t=time_grids())
@pytest.mark.slow
def test_simulate_full_inertia_matrix_conserves_energy_and_momentum(inertia, R, w0, t):
    J = R.T @ np.diag(inertia) @ R
    J = 0.5 * (J + J.T)
    res = simulate(rigid_body(J), [0, 0, 0, 1, *w0], t, method="rk8",
                   steps=_steps(inertia, w0, t),
                   invariants=True)
    assert res.success and np.all(np.isfinite(res.x))
    assert _rel_drift(res.invariants["energy"]) < 1e-6 or np.linalg.norm(w0) < 1e-8
    # body rates in principal axes follow the Jacobi solution
    w_principal = R @ res.x[4:]
    w_true = torque_free_omega(inertia, R @ w0, t - t[0])
    assert np.max(np.abs(w_principal - w_true)) < 1e-3


# --------------------------------------------------------------------------------------------
# attitude conversions: round trips
# --------------------------------------------------------------------------------------------


@FUZZ
@given(q=unit_quats())
def test_quat_dcm_round_trip(q):
    A = att.dcm_from_quat(q)
    assert np.allclose(A @ A.T, np.eye(3), atol=1e-12) and abs(np.linalg.det(A) - 1) < 1e-12
    q2 = att.quat_from_dcm(A)
    assert q2[3] >= 0.0
    assert min(np.max(np.abs(q2 - q)), np.max(np.abs(q2 + q))) < 1e-12


@FUZZ
@given(A=rotation_matrices())
def test_dcm_euler_round_trips(A):
    for to_euler, from_euler in ((att.euler321_from_dcm, att.dcm_from_euler321),
                                 (att.euler313_from_dcm, att.dcm_from_euler313)):
        e = to_euler(A)
        assert np.all(np.isfinite(e))
        assert np.max(np.abs(from_euler(e) - A)) < 1e-7  # 1e-7: near a lock, cancellation


@FUZZ
@given(angles=vec3)
def test_euler_quat_round_trips(angles):
    for from_euler, to_euler, dcm in (
            (att.quat_from_euler321, att.euler321_from_quat, att.dcm_from_euler321),
            (att.quat_from_euler313, att.euler313_from_quat, att.dcm_from_euler313)):
        q = from_euler(angles)
        assert abs(np.linalg.norm(q) - 1) < 1e-14
        assert np.max(np.abs(att.dcm_from_quat(q) - dcm(angles))) < 1e-12
        assert np.max(np.abs(dcm(to_euler(q)) - dcm(angles))) < 1e-7


@FUZZ
@given(qs=st.lists(unit_quats(), min_size=1, max_size=5))
def test_batched_conversions_match_single(qs):
    Q = np.stack(qs, axis=1)
    A = att.dcm_from_quat(Q)
    assert A.shape == (3, 3, len(qs))
    for k, q in enumerate(qs):
        assert np.allclose(A[:, :, k], att.dcm_from_quat(q), atol=1e-15)
    E = att.euler321_from_quat(Q)
    assert E.shape == (3, len(qs)) and np.all(np.isfinite(E))


# --------------------------------------------------------------------------------------------
# linearize on spin states
# --------------------------------------------------------------------------------------------


@FUZZ
@given(inertia=principal_moments(), axis_index=st.integers(0, 2),
       rate=st.floats(0.01, 100.0) | st.floats(-100.0, -0.01))
def test_linearize_spin_state_eigenvalues(inertia, axis_index, rate):
    I = np.sort(inertia)
    assume(I[1] - I[0] > 1e-3 * I[2] and I[2] - I[1] > 1e-3 * I[2])
    w = np.zeros(3)
    w[axis_index] = rate
    ss = linearize(rigid_body(I), [0, 0, 0, 1, *w])
    A = np.asarray(ss.A)
    assert A.shape == (6, 6) and np.all(np.isfinite(A))
    eig = np.linalg.eigvals(A)
    j, k = [i for i in range(3) if i != axis_index]
    s = (I[axis_index] - I[j]) * (I[axis_index] - I[k]) / (I[j] * I[k])
    expected = abs(rate) * np.sqrt(abs(s))
    scale = max(1.0, np.max(np.abs(eig)))
    if s > 0:  # major / minor axis: a nutation pair +-i lam, no growth
        assert np.max(eig.real) < 1e-7 * scale
        assert np.min(np.abs(np.abs(eig.imag) - expected)) < 1e-7 * scale
    else:  # intermediate axis: a real unstable root
        assert abs(np.max(eig.real) - expected) < 1e-7 * scale


# --------------------------------------------------------------------------------------------
# min_effort on small random slews (a few examples: each is an NLP)
# --------------------------------------------------------------------------------------------


@FEW
@given(moments=st.lists(st.floats(0.5, 3.0), min_size=3, max_size=3),
       axis_index=st.integers(0, 2), angle=st.floats(0.01, 0.3), T=st.floats(1.0, 5.0))
def test_min_effort_small_principal_axis_slew(moments, axis_index, angle, T):
    I = np.sort(moments)
    assume(I[2] <= I[0] + I[1])
    axis = np.zeros(3)
    axis[axis_index] = 1.0
    sol = slew.min_effort(I, T, angle=angle, axis=axis, N=10)
    truth = 6.0 * (I[axis_index] * angle) ** 2 / T**3  # the cubic profile's cost
    if sol.success:
        assert np.isfinite(sol.cost)
        assert abs(sol.cost - truth) <= 1e-4 * truth
    else:
        assert sol.message


# --------------------------------------------------------------------------------------------
# invalid inputs: TypeError/ValueError naming the argument
# --------------------------------------------------------------------------------------------

BAD_NUMBERS = st.sampled_from([np.nan, np.inf, -np.inf])
WRONG_TYPES = st.sampled_from(["abc", None, {"a": 1}, object(), 1 + 2j])


def _raises_naming(fun, name):
    with pytest.raises((TypeError, ValueError)) as info:
        fun()
    assert name in str(info.value), f"message does not name `{name}`: {info.value}"


@FUZZ
@given(size=st.integers(0, 10).filter(lambda n: n != 7))
def test_simulate_wrong_x0_size(size):
    _raises_naming(lambda: simulate(rigid_body([1, 2, 3]), np.zeros(size), [0.0, 1.0]), "x0")


@FUZZ
@given(bad=BAD_NUMBERS, index=st.integers(0, 6))
def test_simulate_non_finite_x0(bad, index):
    x0 = np.array([0, 0, 0, 1, 0.1, 0.2, 0.3])
    x0[index] = bad
    _raises_naming(lambda: simulate(rigid_body([1, 2, 3]), x0, [0.0, 1.0]), "x0")


@FUZZ
@given(scale=st.floats(0.0, 0.99) | st.floats(1.01, 100.0))
def test_simulate_non_unit_quaternion(scale):
    x0 = [0, 0, 0, scale, 0.1, 0.2, 0.3]
    _raises_naming(lambda: simulate(rigid_body([1, 2, 3]), x0, [0.0, 1.0]), "x0")


@FUZZ
@given(t=st.one_of(
    st.lists(st.floats(0, 10), min_size=2, max_size=6).filter(lambda v: np.any(np.diff(v) <= 0)),
    st.just([0.0, np.nan, 2.0]), st.just([1.0]), st.just([[0.0, 1.0]]), st.just([]),
    st.just([0.0, np.inf])))
def test_simulate_bad_grid(t):
    _raises_naming(lambda: simulate(rigid_body([1, 2, 3]), [0, 0, 0, 1, 0, 0, 1], t), "t")


@FUZZ
@given(bad=WRONG_TYPES)
def test_simulate_wrong_types(bad):
    model, x0, t = rigid_body([1, 2, 3]), [0, 0, 0, 1, 0, 0, 1], [0.0, 1.0]
    with pytest.raises((TypeError, ValueError)):
        simulate(bad, x0, t)
    _raises_naming(lambda: simulate(model, bad, t), "x0")
    _raises_naming(lambda: simulate(model, x0, bad), "t")


@FUZZ
@given(u=st.one_of(st.lists(finite, min_size=1, max_size=5).filter(lambda v: len(v) != 3),
                   st.just([0.0, np.nan, 0.0])))
def test_simulate_bad_control(u):
    _raises_naming(lambda: simulate(rigid_body([1, 2, 3]), [0, 0, 0, 1, 0, 0, 1],
                                    [0.0, 1.0], u=u), "u")


@FUZZ
@given(inertia=st.one_of(
    st.lists(st.floats(-10, -0.01), min_size=3, max_size=3),            # negative
    st.lists(st.floats(0.1, 10), min_size=1, max_size=5).filter(lambda v: len(v) != 3),
    st.just([1.0, 2.0, np.nan]), st.just([1.0, 1.0, 5.0]),               # NaN, triangle
    st.just([[1.0, 0.5, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]),        # not symmetric
    st.just([0.0, 1.0, 1.0]), WRONG_TYPES))
def test_rigid_body_bad_inertia(inertia):
    _raises_naming(lambda: rigid_body(inertia), "inertia")


@FUZZ
@given(q=st.one_of(st.lists(finite, min_size=0, max_size=6).filter(lambda v: len(v) != 4),
                   st.just([0.0, 0.0, np.nan, 1.0]), st.just([0.0, 0.0, 0.0, 2.0]),
                   st.just([0.0, 0.0, 0.0, 0.0]), WRONG_TYPES))
def test_attitude_bad_quaternion(q):
    for fun in (att.dcm_from_quat, att.euler321_from_quat, att.euler313_from_quat,
                att.rotation_angle):
        _raises_naming(lambda: fun(q), "q")


@FUZZ
@given(A=st.one_of(st.just(np.ones((3, 3))), st.just(np.eye(2)), st.just(-np.eye(3)),
                   st.just(np.full((3, 3), np.nan)), st.just(np.eye(3) * 2), WRONG_TYPES))
def test_attitude_bad_dcm(A):
    for fun in (att.quat_from_dcm, att.euler321_from_dcm, att.euler313_from_dcm):
        _raises_naming(lambda: fun(A), "A")


@FUZZ
@given(angles=st.one_of(st.lists(finite, min_size=0, max_size=5).filter(lambda v: len(v) != 3),
                        st.just([0.0, np.inf, 0.0]), st.just([np.nan, 0.0, 0.0]), WRONG_TYPES))
def test_attitude_bad_angles(angles):
    for fun in (att.dcm_from_euler321, att.dcm_from_euler313, att.quat_from_euler321,
                att.quat_from_euler313):
        _raises_naming(lambda: fun(angles), "angles")


@FUZZ
@given(x=st.one_of(st.lists(finite, min_size=0, max_size=9).filter(lambda v: len(v) != 7),
                   st.just([0, 0, 0, 1, 0, 0, np.nan]), WRONG_TYPES))
def test_linearize_bad_state(x):
    _raises_naming(lambda: linearize(rigid_body([1, 2, 3]), x), "x")


@FUZZ
@given(bad=st.one_of(st.just(-1.0), st.just(0.0), st.just(np.nan), st.just(np.inf),
                    st.just(None)))
def test_min_effort_bad_horizon(bad):
    _raises_naming(lambda: slew.min_effort(np.eye(3), bad, angle=0.1, axis=[1, 0, 0], N=5), "T")


@pytest.mark.parametrize("call, name", [
    (lambda: slew.min_effort(np.eye(3), "1", angle=0.1, axis=[1, 0, 0], N=5), "T"),
    (lambda: slew.min_effort(np.eye(3), True, angle=0.1, axis=[1, 0, 0], N=5), "T"),
    (lambda: slew.min_effort(np.eye(3), "abc", angle=0.1, axis=[1, 0, 0], N=5), "T"),
    (lambda: rigid_body(["1", "2", "3"]), "inertia"),
], ids=["min_effort-T-str", "min_effort-T-bool", "min_effort-T-abc", "rigid_body-inertia-str"])
def test_numeric_strings_and_booleans_are_refused(call, name):
    """(Once a string or boolean horizon and string inertia were taken silently.)"""
    _raises_naming(call, name)


@FUZZ
@given(bad=st.one_of(st.just(np.nan), st.just("x"), st.just([1.0, 0.0]), st.just([0, 0, 0])))
def test_min_effort_bad_axis(bad):
    _raises_naming(lambda: slew.min_effort(np.eye(3), 2.0, angle=0.1, axis=bad, N=5), "axis")
