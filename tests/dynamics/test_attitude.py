"""Attitude kinematics against the seed's numbers and independent references.

Independent truths used here: the seed's printed Gemini example (Sec. 4.4), the axis-angle
rotation matrix (Eqs. 4.46-4.54), products of elementary rotations, scipy's
``Rotation`` (a peer library; its matrix is the *active* rotation, i.e. ``A^T``), and the
matrix exponential of the kinematics (Eq. 4.70).
"""
import itertools

import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.linalg import expm
from scipy.spatial.transform import Rotation

from appdyn.dynamics import attitude as at
from tests.bodies import GEMINI


finite = dict(allow_nan=False, allow_infinity=False)
unit_vectors = st.tuples(*[st.floats(-1, 1, **finite)] * 3).map(np.array).filter(
    lambda v: np.linalg.norm(v) > 1e-3
)


def unit_quat(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


quats = st.tuples(*[st.floats(-1, 1, **finite)] * 4).filter(
    lambda v: np.linalg.norm(v) > 1e-3
).map(unit_quat)


def same_rotation(q, p, tol=1e-12):
    """Quaternions q and p describe the same attitude (q = +/- p)."""
    return min(np.max(np.abs(q - p)), np.max(np.abs(q + p))) <= tol


# ------------------------------------------------------------------- Gemini (Sec. 4.4)
def test_gemini_principal_moments_match_seed():
    moments, A = at.principal_axes(GEMINI)
    np.testing.assert_allclose(moments, [4530.11944, 4600.531811, 1542.448749], atol=6e-6)
    np.testing.assert_allclose(A @ GEMINI @ A.T, np.diag(moments), atol=1e-9)
    assert np.linalg.det(A) == pytest.approx(1.0, abs=1e-12)


def test_gemini_rotation_matches_seed_matrix_and_angle():
    _, A = at.principal_axes(GEMINI)
    seed_A = np.array(
        [[0.74693, -0.66305, 0.04964], [0.66477, 0.74319, -0.07584], [0.01339, 0.08965, 0.99588]]
    )
    np.testing.assert_allclose(A, seed_A, atol=6e-6)
    delta = np.degrees(np.arccos((np.trace(A) - 1) / 2))
    assert round(delta, 2) == 42.01
    # The seed's other sign choices give larger angles (138.34, 178.88, 174.19 deg).
    assert delta < 138.34


def test_gemini_minor_axis_direction_matches_seed():
    _, A = at.principal_axes(GEMINI)
    psi, theta, phi = np.degrees(at.euler313_from_dcm(A))
    assert round(theta, 1) == 5.2
    assert round(phi, 1) == 146.8  # second quadrant: tan^-1(0.04964 / -0.07584)


@pytest.mark.parametrize("order", ["ascending", "descending"])
def test_principal_axes_fixed_order(order):
    moments, A = at.principal_axes(GEMINI, order=order)
    expected = np.sort(np.linalg.eigvalsh(GEMINI))
    np.testing.assert_allclose(moments, expected if order == "ascending" else expected[::-1])
    np.testing.assert_allclose(A @ GEMINI @ A.T, np.diag(moments), atol=1e-9)
    assert np.linalg.det(A) == pytest.approx(1.0)


def test_principal_axes_is_minimum_rotation_over_all_proper_choices():
    rng = np.random.default_rng(3)
    for _ in range(20):
        R = Rotation.random(random_state=rng).as_matrix()
        I = R @ np.diag(rng.uniform(1, 2, 3)) @ R.T
        _, A = at.principal_axes(I)
        # brute force over signed permutations with det +1
        vals, vecs = np.linalg.eigh(I)
        best = max(
            np.trace(vecs[:, list(p)] * s)
            for p in itertools.permutations(range(3))
            for s in itertools.product([1, -1], repeat=3)
            if np.linalg.det(vecs[:, list(p)] * s) > 0
        )
        assert np.trace(A) == pytest.approx(best, abs=1e-12)


# ----------------------------------------------------------- quaternion <-> DCM (4.63)
@given(unit_vectors, st.floats(-np.pi, np.pi, **finite))
def test_dcm_from_quat_equals_axis_angle_form(axis, angle):
    """Eq. 4.63 with Eqs. 4.55-4.58 against the direct elements 4.46-4.54."""
    A1 = at.dcm_from_quat(at.quat_from_axis_angle(axis, angle))
    A2 = at.dcm_from_axis_angle(axis, angle)
    np.testing.assert_allclose(A1, A2, atol=1e-14)


@given(quats)
def test_dcm_matches_scipy_passive_convention(q):
    """scipy's as_matrix is the active rotation R with x_inertial = R x_body, so A = R^T."""
    R = Rotation.from_quat(q).as_matrix()  # scipy is scalar-last too
    np.testing.assert_allclose(at.dcm_from_quat(q), R.T, atol=1e-14)


@given(quats, quats)
def test_quat_mul_composes_dcms(q, p):
    np.testing.assert_allclose(
        at.dcm_from_quat(at.quat_mul(q, p)), at.dcm_from_quat(q) @ at.dcm_from_quat(p), atol=1e-14
    )


@given(quats)
def test_conj_is_inverse(q):
    np.testing.assert_allclose(at.quat_mul(q, at.quat_conj(q)), [0, 0, 0, 1], atol=1e-15)


@given(quats)
def test_quat_dcm_round_trip(q):
    q_back = at.quat_from_dcm(at.dcm_from_quat(q))
    assert q_back[3] >= 0
    assert same_rotation(q_back, q, 2e-14)


@given(unit_vectors, st.floats(np.pi - 1e-6, np.pi, **finite))
def test_quat_from_dcm_near_180_degrees(axis, angle):
    """Near delta = pi, q4 -> 0: the largest-diagonal pivot keeps full accuracy."""
    q = at.quat_from_axis_angle(axis, angle)
    q_back = at.quat_from_dcm(at.dcm_from_quat(q))
    assert same_rotation(q_back, q, 1e-14)
    assert q_back[3] >= 0


def test_quat_from_dcm_matches_scipy_and_seed_sign_rule():
    rng = np.random.default_rng(0)
    R = Rotation.random(200, random_state=rng)
    A = np.stack([r.T for r in R.as_matrix()], axis=-1)
    q = at.quat_from_dcm(A)
    q_ref = R.as_quat().T * np.sign(R.as_quat()[:, 3])
    np.testing.assert_allclose(q, q_ref, atol=1e-14)
    assert np.all(q[3] >= 0)


def test_rotation_angle_from_trace():
    """Eq. 4.64: tr A = 1 + 2 cos(delta)."""
    rng = np.random.default_rng(1)
    for q in Rotation.random(50, random_state=rng).as_quat():
        A = at.dcm_from_quat(q)
        assert np.cos(at.rotation_angle(q)) == pytest.approx((np.trace(A) - 1) / 2, abs=1e-14)
        axis, angle = at.axis_angle_from_quat(q)
        np.testing.assert_allclose(at.dcm_from_axis_angle(axis, angle), A, atol=1e-14)


# ------------------------------------------------------------------- Euler angles
angle = st.floats(-np.pi, np.pi, **finite)


@given(angle, st.floats(0, np.pi, **finite), angle)
def test_euler313_matches_product_of_elementary_rotations(psi, theta, phi):
    A = at.dcm_axis(3, phi) @ at.dcm_axis(1, theta) @ at.dcm_axis(3, psi)
    np.testing.assert_allclose(at.dcm_from_euler313([psi, theta, phi]), A, atol=1e-15)
    assert same_rotation(at.quat_from_euler313([psi, theta, phi]), at.quat_from_dcm(A), 1e-14)


@given(angle, st.floats(-np.pi / 2, np.pi / 2, **finite), angle)
def test_euler321_matches_product_of_elementary_rotations(psi, theta, phi):
    A = at.dcm_axis(1, phi) @ at.dcm_axis(2, theta) @ at.dcm_axis(3, psi)
    np.testing.assert_allclose(at.dcm_from_euler321([psi, theta, phi]), A, atol=1e-15)
    assert same_rotation(at.quat_from_euler321([psi, theta, phi]), at.quat_from_dcm(A), 1e-14)


def test_elementary_rotations_match_scipy():
    for k, name in zip((1, 2, 3), "xyz"):
        np.testing.assert_allclose(
            at.dcm_axis(k, 0.3), Rotation.from_euler(name, 0.3).as_matrix().T, atol=1e-15
        )


@settings(max_examples=200)
@given(quats)
@pytest.mark.slow
def test_euler_round_trips_from_any_attitude(q):
    A = at.dcm_from_quat(q)
    for to_euler, from_euler in (
        (at.euler313_from_dcm, at.dcm_from_euler313),
        (at.euler321_from_dcm, at.dcm_from_euler321),
    ):
        np.testing.assert_allclose(from_euler(to_euler(A)), A, atol=2e-14)
    assert same_rotation(at.quat_from_euler313(at.euler313_from_quat(q)), q, 1e-14)
    assert same_rotation(at.quat_from_euler321(at.euler321_from_quat(q)), q, 1e-14)


@given(angle, st.floats(0, 1e-7, **finite), angle, st.sampled_from([1.0, -1.0]))
def test_euler321_round_trip_near_gimbal_lock(psi, eps, phi, sign):
    theta = sign * (np.pi / 2 - eps)
    A = at.dcm_from_euler321([psi, theta, phi])
    angles = at.euler321_from_dcm(A)
    np.testing.assert_allclose(at.dcm_from_euler321(angles), A, atol=1e-14)
    assert abs(angles[1]) <= np.pi / 2


@given(angle, st.floats(0, 1e-7, **finite), angle, st.sampled_from([0.0, np.pi]))
def test_euler313_round_trip_near_gimbal_lock(psi, eps, phi, lock):
    theta = abs(lock - eps)
    A = at.dcm_from_euler313([psi, theta, phi])
    angles = at.euler313_from_dcm(A)
    np.testing.assert_allclose(at.dcm_from_euler313(angles), A, atol=1e-14)
    assert 0 <= angles[1] <= np.pi


def test_euler_angles_recovered_in_principal_ranges():
    rng = np.random.default_rng(2)
    for _ in range(100):
        a313 = [rng.uniform(-np.pi, np.pi), rng.uniform(0.01, np.pi - 0.01), rng.uniform(-np.pi, np.pi)]
        np.testing.assert_allclose(at.euler313_from_dcm(at.dcm_from_euler313(a313)), a313, atol=1e-12)
        a321 = [rng.uniform(-np.pi, np.pi), rng.uniform(-1.5, 1.5), rng.uniform(-np.pi, np.pi)]
        np.testing.assert_allclose(at.euler321_from_dcm(at.dcm_from_euler321(a321)), a321, atol=1e-12)


def test_euler321_small_angle_quaternion_note():
    """Seed NOTE: for small angles q ~ (phi/2, theta/2, psi/2, 1)."""
    errs = []
    for scale in (1e-3, 1e-4):
        psi, theta, phi = scale * np.array([1.0, -2.0, 3.0])
        q = at.quat_from_euler321([psi, theta, phi])
        errs.append(np.max(np.abs(q - [phi / 2, theta / 2, psi / 2, 1])))
    assert errs[1] < 2e-7
    assert errs[0] / errs[1] == pytest.approx(100, rel=1e-3)  # the residual is second order


def test_euler_matches_scipy_sequences():
    """Modern 3-2-1 is scipy's intrinsic 'ZYX'; classical 3-1-3 is intrinsic 'ZXZ'."""
    rng = np.random.default_rng(5)
    for _ in range(20):
        q = Rotation.random(random_state=rng).as_quat()
        R = Rotation.from_quat(q)
        np.testing.assert_allclose(at.euler321_from_quat(q), R.as_euler("ZYX"), atol=1e-12)
        psi, theta, phi = at.euler313_from_quat(q)
        np.testing.assert_allclose(
            at.dcm_from_euler313([psi, theta, phi]),
            Rotation.from_euler("ZXZ", [psi, theta, phi]).as_matrix().T,
            atol=1e-14,
        )


# --------------------------------------------------------- propagation (Eq. 4.70)
@given(quats, st.tuples(*[st.floats(-5, 5, **finite)] * 3).map(np.array), st.floats(0, 2, **finite))
def test_propagate_quat_is_exact_for_constant_rate(q, w, h):
    """Closed form against the matrix exponential of qdot = -1/2 Wbar q."""
    expected = expm(-0.5 * at.quat_kinematics_matrix(w) * h) @ q
    np.testing.assert_allclose(at.propagate_quat(q, w, h), expected, atol=1e-13)


def test_quat_rate_is_eq_4_70():
    rng = np.random.default_rng(4)
    for _ in range(10):
        q, w = unit_quat(rng.normal(size=4)), rng.normal(size=3)
        np.testing.assert_allclose(at.quat_rate(q, w), -0.5 * at.quat_kinematics_matrix(w) @ q)
        W = at.quat_kinematics_matrix(w)
        np.testing.assert_allclose(W @ W, -np.dot(w, w) * np.eye(4), atol=1e-14)


def test_propagate_quat_smooth_through_zero_rate_in_casadi():
    q, w, h = ca.SX.sym("q", 4), ca.SX.sym("w", 3), ca.SX.sym("h")
    out = at.propagate_quat(q, w, h)
    J = ca.Function("J", [q, w, h], [ca.jacobian(out, w)])
    q0 = np.array([0.1, -0.2, 0.3, 0.9])
    J0 = np.array(J(q0, [0, 0, 0], 0.1))
    # at w = 0: d q(h) / d w = h * d(quat_rate)/dw
    Jrate = np.array(ca.Function("r", [q, w], [ca.jacobian(at.quat_rate(q, w), w)])(q0, [0, 0, 0]))
    np.testing.assert_allclose(J0, 0.1 * Jrate, atol=1e-15)
    assert np.all(np.isfinite(np.array(J(q0, [1e-9, 0, 0], 0.1))))


# ------------------------------------------------------------- numpy == casadi
def test_casadi_and_numpy_agree():
    rng = np.random.default_rng(7)
    q = unit_quat(rng.normal(size=4))
    w = rng.normal(size=3)
    A = at.dcm_from_quat(q)
    e313, e321 = at.euler313_from_dcm(A), at.euler321_from_dcm(A)
    cases = [
        (at.dcm_from_quat, [q]),
        (at.quat_from_dcm, [A]),
        (at.quat_mul, [q, unit_quat(rng.normal(size=4))]),
        (at.propagate_quat, [q, w, 0.3]),
        (at.euler313_from_dcm, [A]),
        (at.euler321_from_dcm, [A]),
        (at.dcm_from_euler313, [e313]),
        (at.dcm_from_euler321, [e321]),
        (at.quat_from_euler313, [e313]),
        (at.quat_from_euler321, [e321]),
        (at.rotation_angle, [q]),
    ]
    for fun, args in cases:
        syms = [ca.SX.sym(f"a{i}", *np.shape(a)) if np.ndim(a) else ca.SX.sym(f"a{i}") for i, a in enumerate(args)]
        F = ca.Function("F", syms, [fun(*syms)])
        got = np.array(F(*args)).reshape(np.shape(fun(*args)))
        np.testing.assert_allclose(got, fun(*args), atol=1e-15, err_msg=fun.__name__)


def test_batched_numpy_inputs():
    R = Rotation.random(7, random_state=np.random.default_rng(8))
    q = R.as_quat().T  # (4, 7)
    A = at.dcm_from_quat(q)
    assert A.shape == (3, 3, 7)
    assert at.euler321_from_dcm(A).shape == (3, 7)
    for i in range(7):
        np.testing.assert_allclose(A[:, :, i], at.dcm_from_quat(q[:, i]))


# ------------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: at.dcm_from_quat([1, 0, 0]), "`q` must have shape"),
        (lambda: at.quat_from_dcm(np.eye(2)), "`A` must have shape"),
        (lambda: at.quat_normalize([0, 0, 0, 0]), "`q` must be a non-zero"),
        (lambda: at.dcm_from_axis_angle([0, 0, 0], 1.0), "`axis` must be a non-zero"),
        (lambda: at.dcm_axis(4, 0.1), "`component` must be 1, 2 or 3"),
        (lambda: at.propagate_quat([0, 0, 0, 1], [1, 2], 0.1), "`w` must have shape"),
        (lambda: at.principal_axes(GEMINI, order="sorted"), "`order`"),
        (lambda: at.principal_axes(-GEMINI), "positive definite"),
        (lambda: at.quat_mul(ca.SX.sym("q", 3), [0, 0, 0, 1]), "4x1"),
    ],
)
def test_bad_input_raises(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_propagate_quat_matches_simulation_of_a_spinning_sphere():
    """A torque-free sphere keeps a constant body rate, so the closed form is exact:
    compare it with simulate's integration of Eq. 4.70 (cvodes and compiled rk8)."""
    from appdyn.dynamics import rigid_body, simulate

    q0 = unit_quat([0.3, -0.2, 0.5, 0.8])
    w = np.array([0.7, -1.1, 0.4])
    t = np.linspace(0.0, 20.0, 41)
    expected = np.stack([at.propagate_quat(q0, w, tk) for tk in t], axis=1)
    for method, kw in (("rk8", {"steps": 20}), ("cvodes", {"rtol": 1e-12, "atol": 1e-12})):
        res = simulate(rigid_body([2.0, 2.0, 2.0]), np.r_[q0, w], t, method=method, **kw)
        assert res.success, res.message
        np.testing.assert_allclose(res.x[:4], expected, atol=1e-9, err_msg=method)


# ------------------------------------------------------------- input validation (item 7)
# A valid call of every public function, by keyword, so each argument can be spoiled in turn.
_Q = unit_quat([0.1, -0.2, 0.3, 0.9])
_P = unit_quat([-0.5, 0.4, 0.1, 0.3])
_W = np.array([0.7, -1.1, 0.4])
_E = np.array([0.3, 1.1, -2.0])
_A = Rotation.from_quat(_Q).as_matrix().T  # independent DCM of _Q (scipy's is active: A = R^T)
VALID_CALLS = {
    "skew": (at.skew, dict(v=_W)),
    "quat_mul": (at.quat_mul, dict(q=_Q, p=_P)),
    "quat_conj": (at.quat_conj, dict(q=_Q)),
    "quat_normalize": (at.quat_normalize, dict(q=2 * _Q)),
    "quat_kinematics_matrix": (at.quat_kinematics_matrix, dict(w=_W)),
    "quat_rate": (at.quat_rate, dict(q=_Q, w=_W)),
    "dcm_from_quat": (at.dcm_from_quat, dict(q=_Q)),
    "quat_from_dcm": (at.quat_from_dcm, dict(A=_A)),
    "dcm_from_axis_angle": (at.dcm_from_axis_angle, dict(axis=_W, angle=0.7)),
    "quat_from_axis_angle": (at.quat_from_axis_angle, dict(axis=_W, angle=0.7)),
    "axis_angle_from_quat": (at.axis_angle_from_quat, dict(q=_Q)),
    "rotation_angle": (at.rotation_angle, dict(q=_Q)),
    "propagate_quat": (at.propagate_quat, dict(q=_Q, w=_W, h=0.3)),
    "dcm_axis": (at.dcm_axis, dict(component=2, angle=0.7)),
    "dcm_from_euler313": (at.dcm_from_euler313, dict(angles=_E)),
    "euler313_from_dcm": (at.euler313_from_dcm, dict(A=_A)),
    "quat_from_euler313": (at.quat_from_euler313, dict(angles=_E)),
    "euler313_from_quat": (at.euler313_from_quat, dict(q=_Q)),
    "dcm_from_euler321": (at.dcm_from_euler321, dict(angles=_E)),
    "euler321_from_dcm": (at.euler321_from_dcm, dict(A=_A)),
    "quat_from_euler321": (at.quat_from_euler321, dict(angles=_E)),
    "euler321_from_quat": (at.euler321_from_quat, dict(q=_Q)),
    "euler321_rates": (at.euler321_rates, dict(angles=_E, w=_W)),
    "body_rates_from_euler321": (at.body_rates_from_euler321, dict(angles=_E, angle_rates=_W)),
    "euler313_rates": (at.euler313_rates, dict(angles=_E, w=_W)),
    "body_rates_from_euler313": (at.body_rates_from_euler313, dict(angles=_E, angle_rates=_W)),
    "dcm_rate": (at.dcm_rate, dict(A=_A, w=_W)),
    "principal_axes": (at.principal_axes, dict(inertia=GEMINI)),
    "aero_angles": (at.aero_angles, dict(v_body=_W)),
    "total_aoa": (at.total_aoa, dict(v_body=_W)),
    "aero_angles_from_total": (at.aero_angles_from_total, dict(alpha_T=0.4, phi_R=2.0)),
    "total_aoa_from_aero_angles": (at.total_aoa_from_aero_angles, dict(alpha=0.3, beta=-0.2)),
    "velocity_direction": (at.velocity_direction, dict(alpha=0.3, beta=-0.2)),
    "velocity_direction_total": (at.velocity_direction_total, dict(alpha_T=0.4, phi_R=2.0)),
}
NUMERIC_ARGS = [(name, arg) for name, (_, kw) in VALID_CALLS.items() for arg in kw
                if not (name == "dcm_axis" and arg == "component")]
ALL_ARGS = [(name, arg) for name, (_, kw) in VALID_CALLS.items() for arg in kw]


def _spoil(value, bad):
    """``value`` with its first entry replaced by ``bad``."""
    a = np.array(value, dtype=float)
    a.flat[0] = bad
    return a


def test_every_public_function_is_covered_by_the_validation_tests():
    assert set(VALID_CALLS) == set(at.__all__)


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize("name, arg", NUMERIC_ARGS)
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_argument_is_value_error_naming_it(name, arg, bad):
    fun, kw = VALID_CALLS[name]
    with pytest.raises(ValueError, match=f"`{arg}` must be finite"):
        fun(**{**kw, arg: _spoil(kw[arg], bad)})


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize("name, arg", ALL_ARGS)
@pytest.mark.parametrize("bad", ["0.5", {"x": 1.0}, None, 1j, [True, False, True]],
                         ids=["str", "dict", "None", "complex", "bool"])
def test_wrong_type_argument_is_type_error_naming_it(name, arg, bad):
    fun, kw = VALID_CALLS[name]
    with pytest.raises(TypeError, match=f"`{arg}` must be"):
        fun(**{**kw, arg: bad})


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize(
    "call, error, match",
    [   # seen on the issue "Trustworthy results", item 7: each returned numbers before
        (lambda: at.quat_from_dcm(2 * np.eye(3)), ValueError, r"`A` must be a rotation matrix"),
        (lambda: at.quat_from_dcm(np.zeros((3, 3))), ValueError, r"`A` must be a rotation matrix"),
        (lambda: at.axis_angle_from_quat(np.zeros(4)), ValueError, r"`q` must be a unit .* norm 0"),
        (lambda: at.rotation_angle(np.zeros(4)), ValueError, r"`q` must be a unit .* norm 0"),
        (lambda: at.euler313_from_quat(np.zeros(4)), ValueError, r"`q` must be a unit .* norm 0"),
        (lambda: at.euler321_from_dcm(np.ones((3, 3))), ValueError, r"`A` must be a rotation matrix"),
        (lambda: at.quat_from_axis_angle([0, 0, 1], np.nan), ValueError, "`angle` must be finite"),
        (lambda: at.quat_from_axis_angle([np.nan, 0, 1], 1.0), ValueError, "`axis` must be finite"),
        (lambda: at.quat_normalize([np.nan, 0, 0, 1]), ValueError, "`q` must be finite"),
        (lambda: at.propagate_quat([0, 0, 0, 1], [np.nan, 0, 0], 0.1), ValueError, "`w` must be finite"),
        (lambda: at.propagate_quat([0, 0, 0, 1], [1, 0, 0], np.inf), ValueError, "`h` must be finite"),
        (lambda: at.propagate_quat([np.nan, 0, 0, 1], [1, 0, 0], 0.1), ValueError, "`q` must be finite"),
        (lambda: at.dcm_from_quat([0, 0, np.nan, 1]), ValueError, "`q` must be finite"),
        # and around them
        (lambda: at.quat_from_dcm(-np.eye(3)), ValueError, r"`A` must be a proper rotation .* det -1"),
        (lambda: at.euler313_from_dcm(np.diag([1.0, 1.0, -1.0])), ValueError, r"`A` .* det -1"),
        (lambda: at.dcm_from_quat([0, 0, 0, 2]), ValueError, r"`q` must be a unit .* norm 2"),
        (lambda: at.dcm_from_quat([0, 0, 0, 1 + 2e-6]), ValueError, r"`q` must be a unit quaternion"),
        (lambda: at.euler321_from_quat([0.5, 0, 0, 0.5]), ValueError, r"`q` must be a unit"),
        (lambda: at.propagate_quat([0, 0, 0, 3], [1, 0, 0], 0.1), ValueError, r"`q` must be a unit"),
        (lambda: at.propagate_quat([0, 0, 0, 1], [1e200, 0, 0], 1e200), ValueError, "too large"),
        (lambda: at.quat_normalize(np.zeros((4, 2))), ValueError, r"`q\[:, 0\]` must be a non-zero"),
        (lambda: at.quat_from_axis_angle([0, 0, 0], 1.0), ValueError, "`axis` must be a non-zero"),
        (lambda: at.quat_from_axis_angle([0, 0, 1], np.full(3, np.inf)), ValueError, "`angle` must be finite"),
        (lambda: at.dcm_axis(True, 0.1), TypeError, "`component` must be 1, 2 or 3"),
        (lambda: at.dcm_axis(1.0, 0.1), TypeError, "`component` must be 1, 2 or 3"),
        (lambda: at.principal_axes(GEMINI, order=1), TypeError, "`order` must be"),
        (lambda: at.axis_angle_from_quat(np.tile(_Q[:, None], (1, 2))), ValueError, r"`q` must have shape \(4,\)"),
        (lambda: at.axis_angle_from_quat(ca.SX.sym("q", 4)), TypeError, "`q` must be numeric"),
        (lambda: at.dcm_from_quat(ca.DM([0, 0, np.nan, 1])), ValueError, "`q` must be finite"),
        (lambda: at.quat_from_dcm(ca.DM(2 * np.eye(3))), ValueError, "`A` must be a rotation"),
        (lambda: at.quat_mul(ca.MX.sym("q", 4, 2), _Q), ValueError, "`q` must be a 4x1"),
    ],
)
def test_bad_values_are_refused_with_the_argument_named(call, error, match):
    with pytest.raises(error, match=match):
        call()


def test_batches_name_the_first_bad_column():
    q = np.tile(_Q[:, None], (1, 5))
    q[:, 3] = 0.0
    q[:, 4] = np.nan
    for fun in (at.dcm_from_quat, at.rotation_angle, at.euler313_from_quat, at.euler321_from_quat):
        with pytest.raises(ValueError, match=r"`q\[:, 3\]` must be a unit quaternion .* norm 0"):
            fun(q)
    A = np.stack([_A, _A, -_A], axis=-1)
    for fun in (at.quat_from_dcm, at.euler313_from_dcm, at.euler321_from_dcm):
        with pytest.raises(ValueError, match=r"`A\[:, :, 2\]` must be a proper rotation"):
            fun(A)
    with pytest.raises(ValueError, match=r"`axis\[:, 1\]` must be a non-zero"):
        at.quat_from_axis_angle(np.array([[1.0, 0.0], [0.0, 0.0], [0.0, 0.0]]), 0.5)


def test_unit_quaternion_tolerance_is_1e_minus_6_and_near_unit_input_is_normalized():
    for s in (1 - 0.99e-6, 1 + 0.99e-6):
        A = at.dcm_from_quat(s * _Q)  # normalized first: a rotation to round-off
        np.testing.assert_allclose(A, _A, atol=1e-15)
        np.testing.assert_allclose(A @ A.T, np.eye(3), atol=1e-15)
        assert at.rotation_angle(s * _Q) == pytest.approx(2 * np.arccos(_Q[3]), abs=1e-14)
    for s in (1 - 1.01e-6, 1 + 1.01e-6):
        with pytest.raises(ValueError, match="`q` must be a unit quaternion"):
            at.dcm_from_quat(s * _Q)


def test_quaternion_algebra_accepts_any_finite_quaternion():
    """quat_mul / quat_conj / quat_rate are algebra (also used on rates qdot): no unit norm."""
    q, p = 2.0 * _Q, np.array([0.3, -0.1, 0.2, -0.4])
    qv, pv = q[:3], p[:3]
    expected = np.r_[q[3] * pv + p[3] * qv - np.cross(qv, pv), q[3] * p[3] - qv @ pv]
    np.testing.assert_allclose(at.quat_mul(q, p), expected, atol=1e-15)
    np.testing.assert_array_equal(at.quat_mul(np.zeros(4), p), np.zeros(4))
    np.testing.assert_array_equal(at.quat_conj(q), np.r_[-qv, q[3]])
    W = np.array([[0, _W[2], -_W[1], _W[0]], [-_W[2], 0, _W[0], _W[1]],
                  [_W[1], -_W[0], 0, _W[2]], [-_W[0], -_W[1], -_W[2], 0]])  # -Wbar(w), Eq. 4.70
    np.testing.assert_allclose(at.quat_rate(q, _W), 0.5 * W @ q, atol=1e-15)


def test_quat_normalize_accepts_non_unit_and_tiny_or_huge_quaternions():
    q = np.array([[3.0, 0.0, 0.0], [0.0, 0.0, 1e-300], [0.0, 4e300, 0.0], [4.0, 3e300, 0.0]])
    expected = np.array([[0.6, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.8, 0.0], [0.8, 0.6, 0.0]])
    with np.errstate(all="raise"):
        np.testing.assert_allclose(at.quat_normalize(q), expected, rtol=1e-15)
        np.testing.assert_allclose(at.quat_from_axis_angle([0, 1e-200, 0], np.pi),
                                   [0, 1, 0, np.cos(np.pi / 2)], atol=1e-16)


def test_dm_is_checked_by_value_and_stays_casadi():
    out = at.dcm_from_quat(ca.DM(_Q))
    assert isinstance(out, ca.DM)
    np.testing.assert_allclose(np.array(out), _A, atol=1e-15)
    assert isinstance(at.quat_mul(ca.DM(_Q), _P), ca.DM)
    assert isinstance(at.quat_from_dcm(ca.DM(_A)), ca.DM)


# Arguments of the CasADi-capable functions as (numeric value, CasADi shape).
# (the aerodynamic angles return pairs: tests/dynamics/attitude/test_aero_angles.py checks
# them in SX and MX against numpy)
_SYMBOLIC = [name for name in VALID_CALLS if name not in (
    "axis_angle_from_quat", "principal_axes", "aero_angles", "total_aoa",
    "aero_angles_from_total", "total_aoa_from_aero_angles")]


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize("sym", [ca.SX, ca.MX], ids=["SX", "MX"])
@pytest.mark.parametrize("name", _SYMBOLIC)
def test_symbolic_inputs_pass_through_and_agree_with_numpy(name, sym):
    fun, kw = VALID_CALLS[name]
    numeric = {k: v for k, v in kw.items() if not (name == "dcm_axis" and k == "component")}
    fixed = {k: v for k, v in kw.items() if k not in numeric}
    syms = {k: sym.sym(k, *np.shape(v)) if np.ndim(v) == 2 else sym.sym(k, max(np.size(v), 1))
            for k, v in numeric.items()}
    F = ca.Function("F", list(syms.values()), [fun(**fixed, **syms)])
    got = np.array(F(*[np.reshape(v, (-1, 1)) if np.ndim(v) < 2 else v for v in numeric.values()]))
    want = fun(**kw)
    np.testing.assert_allclose(got.reshape(np.shape(want)), want, atol=1e-14, err_msg=name)


def test_symbolic_dcm_of_non_unit_quaternion_keeps_the_formula():
    """Symbols are never checked: the CasADi expression of Eq. 4.63 is |q|^2 times A(q/|q|)."""
    q = ca.SX.sym("q", 4)
    F = ca.Function("F", [q], [at.dcm_from_quat(q)])
    np.testing.assert_allclose(np.array(F(3 * _Q)), 9 * _A, atol=1e-14)
    G = ca.Function("G", [q], [at.quat_normalize(q)])
    np.testing.assert_allclose(np.array(G(3 * _Q)).ravel(), _Q, atol=1e-15)


@pytest.mark.filterwarnings("error")
@settings(max_examples=200)
@given(st.lists(quats, min_size=1, max_size=6), st.floats(-0.99e-6, 0.99e-6))
@pytest.mark.slow
def test_valid_inputs_within_tolerance_round_trip(qs, dn):
    """Quaternions off unit norm by < 1e-6 and DCMs built from them are accepted; the
    conversions agree with scipy and round-trip (batched and one at a time)."""
    q = np.stack(qs, axis=1) * (1 + dn)
    R = Rotation.from_quat(np.stack(qs))
    A = at.dcm_from_quat(q)
    np.testing.assert_allclose(A, np.moveaxis(R.as_matrix(), 0, -1).transpose(1, 0, 2), atol=2e-15)
    q_back = at.quat_from_dcm(A)
    assert np.all(q_back[3] >= 0)
    for k, qk in enumerate(qs):
        assert same_rotation(q_back[:, k], qk, 2e-14)
        assert same_rotation(at.quat_from_dcm(at.dcm_from_quat(q[:, k])), qk, 2e-14)
    np.testing.assert_allclose(at.dcm_from_euler313(at.euler313_from_quat(q)), A, atol=2e-14)
    np.testing.assert_allclose(at.dcm_from_euler321(at.euler321_from_quat(q)), A, atol=2e-14)
    np.testing.assert_allclose(at.rotation_angle(q), R.magnitude(), atol=1e-14)


@pytest.mark.filterwarnings("error")
@given(quats, st.tuples(*[st.floats(-1, 1, **finite)] * 9).map(lambda t: np.reshape(t, (3, 3))))
def test_dcm_perturbed_within_tolerance_is_accepted(q, noise):
    """A rotation perturbed by 1e-7 (so |A A^T - E| <= ~6e-7 < 1e-6) is still accepted."""
    A = at.dcm_from_quat(q) + 1e-7 * noise
    q_back = at.quat_from_dcm(A)
    assert same_rotation(q_back, q, 1e-6)
    assert np.all(np.isfinite(at.euler313_from_dcm(A))) and np.all(np.isfinite(at.euler321_from_dcm(A)))


def test_dcm_axis_keyword_axis_is_deprecated():
    """Vocabulary: `axis` is a 3-vector; the coordinate index of A1..A3 is `component`."""
    with pytest.warns(DeprecationWarning, match="component"):
        old = at.dcm_axis(axis=2, angle=0.7)
    np.testing.assert_array_equal(old, at.dcm_axis(component=2, angle=0.7))
    with pytest.warns(DeprecationWarning), pytest.raises(ValueError, match="`axis` must be 1, 2 or 3"):
        at.dcm_axis(axis=4, angle=0.1)
