"""The shared input checks of `dynamics.validate`.

Independent truths: hand-made values whose norms, orthogonality errors and determinants are
known in closed form, numpy's own ``linalg.norm`` / ``linalg.det``, and scipy's random
rotations. Every check must raise ``TypeError`` for the wrong kind of object and ``ValueError``
for a wrong value, with the argument's name in the message, and never warn.
"""
import casadi as ca
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from appdyn.dynamics import validate as v

pytestmark = pytest.mark.filterwarnings("error")  # the checks never warn

finite = dict(allow_nan=False, allow_infinity=False)

NOT_NUMBERS = [
    pytest.param("abcd", id="str"),
    pytest.param({"q": 1}, id="dict"),
    pytest.param(None, id="None"),
    pytest.param([1, "2", 3, 4], id="list-with-str"),
    pytest.param([None, 0, 0, 1], id="list-with-None"),
    pytest.param(np.array([1j, 0, 0, 1]), id="complex"),
    pytest.param(np.array([True, False, False, True]), id="bool"),
    pytest.param(ca.SX.sym("x", 4), id="SX"),
    pytest.param(ca.MX.sym("x", 4), id="MX"),
]

CHECKS = {
    "finite_array": lambda x: v.finite_array(x, "arg", (4,), batch=True),
    "finite_scalar": lambda x: v.finite_scalar(x, "arg"),
    "unit_vector": lambda x: v.unit_vector(x, "arg", size=4),
    "unit_quaternion": lambda x: v.unit_quaternion(x, "arg"),
    "unit_quaternions": lambda x: v.unit_quaternions(x, "arg"),
    "rotation_matrix": lambda x: v.rotation_matrix(x, "arg"),
}


# ----------------------------------------------------------------- wrong kind of object
@pytest.mark.parametrize("check", CHECKS.values(), ids=CHECKS.keys())
@pytest.mark.parametrize("bad", NOT_NUMBERS)
def test_wrong_type_is_type_error_naming_the_argument(check, bad):
    with pytest.raises(TypeError, match="`arg`"):
        check(bad)


def test_is_symbolic():
    assert v.is_symbolic(ca.SX.sym("a")) and v.is_symbolic(ca.MX.sym("a", 3))
    assert not v.is_symbolic(ca.DM([1.0, 2.0]))
    assert not v.is_symbolic(np.zeros(3)) and not v.is_symbolic(1.0)


# ------------------------------------------------------------------------ finite_array
def test_finite_array_returns_float_array_of_the_values():
    a = v.finite_array([1, 2, 3], "x", (3,))
    assert a.dtype == np.float64 and a.tolist() == [1.0, 2.0, 3.0]
    assert v.finite_array(ca.DM([1, 2, 3]), "x", (3,)).tolist() == [1.0, 2.0, 3.0]
    assert v.finite_array(np.ones((3, 3, 5)), "A", (3, 3), batch=True).shape == (3, 3, 5)
    assert v.finite_array(2.5, "t").shape == ()


@pytest.mark.parametrize("x, shape, batch", [
    ([1.0, 2.0], (3,), False),
    (np.zeros((3, 2)), (3,), False),          # a batch where a single vector is expected
    (np.zeros((4, 2)), (3,), True),
    (np.zeros((3, 2)), (3, 3), True),
    (np.zeros(()), (3,), True),
])
def test_finite_array_wrong_shape(x, shape, batch):
    with pytest.raises(ValueError, match=r"`x` must have shape \(3"):
        v.finite_array(x, "x", shape, batch=batch)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_finite_array_names_the_first_non_finite_entry(bad):
    x = np.zeros((3, 4))
    x[1, 2] = bad
    x[2, 3] = np.nan
    with pytest.raises(ValueError, match=r"`w` must be finite, got -?(nan|inf) at index \[1, 2\]"):
        v.finite_array(x, "w", (3,), batch=True)


def test_ragged_input_is_value_error():
    with pytest.raises(ValueError, match="`x` must be a regular"):
        v.finite_array([[1, 2], [3]], "x")


# ----------------------------------------------------------------------- finite_scalar
def test_finite_scalar():
    assert v.finite_scalar(np.float32(0.5), "h") == 0.5
    assert v.finite_scalar(3, "h") == 3.0
    assert v.finite_scalar(ca.DM(2.0), "h") == 2.0
    with pytest.raises(ValueError, match="`h` must be a scalar"):
        v.finite_scalar([1.0, 2.0], "h")
    for bad in (np.nan, np.inf):
        with pytest.raises(ValueError, match="`h` must be finite"):
            v.finite_scalar(bad, "h")


# ------------------------------------------------------------------------- unit_vector
def test_unit_vector_scales_without_under_or_overflow():
    np.testing.assert_allclose(v.unit_vector([3.0, 4.0, 0.0], "axis"), [0.6, 0.8, 0.0], rtol=1e-15)
    np.testing.assert_allclose(v.unit_vector([0.0, 3e-300, 4e-300], "axis"), [0, 0.6, 0.8], rtol=1e-15)
    np.testing.assert_allclose(v.unit_vector([3e300, -4e300, 0.0], "axis"), [0.6, -0.8, 0], rtol=1e-15)
    out = v.unit_vector(np.array([[3.0, 0.0], [4.0, 0.0], [0.0, -2.0]]), "axis", batch=True)
    np.testing.assert_allclose(out, [[0.6, 0.0], [0.8, 0.0], [0.0, -1.0]], rtol=1e-15)


def test_unit_vector_refuses_zero_and_names_the_column():
    with pytest.raises(ValueError, match="`axis` must be a non-zero vector"):
        v.unit_vector([0.0, 0.0, 0.0], "axis")
    batch = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    with pytest.raises(ValueError, match=r"`axis\[:, 1\]` must be a non-zero vector"):
        v.unit_vector(batch, "axis", batch=True)
    with pytest.raises(ValueError, match="`axis` must be finite"):
        v.unit_vector([np.nan, 1.0, 0.0], "axis")


# -------------------------------------------------------------------- unit quaternions
def test_unit_quaternion_normalizes_within_tolerance():
    q = np.array([0.0, 0.6, 0.0, 0.8]) * (1 + 0.9e-6)
    np.testing.assert_allclose(v.unit_quaternion(q, "q0"), [0.0, 0.6, 0.0, 0.8], rtol=1e-15)
    np.testing.assert_allclose(v.unit_quaternion(ca.DM([0, 0, 0, 1]), "q0"), [0, 0, 0, 1])


@pytest.mark.parametrize("q, norm", [
    ([0.0, 0.0, 0.0, 0.0], "0"),
    ([0.0, 0.0, 0.0, 1 + 1.1e-6], "1.0000011"),
    ([0.0, 0.0, 0.0, 2.0], "2"),
    ([3e200, 0.0, 0.0, 4e200], "5e\\+200"),
])
def test_unit_quaternion_refuses_non_unit_with_the_norm(q, norm):
    for check in (v.unit_quaternion, v.unit_quaternions):
        with pytest.raises(ValueError, match=rf"`q0` must be a unit quaternion .* got norm {norm}"):
            check(q, "q0")


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_unit_quaternion_refuses_non_finite(bad):
    with pytest.raises(ValueError, match="`q0` must be 4 finite numbers"):
        v.unit_quaternion([0.0, 0.0, bad, 1.0], "q0")
    with pytest.raises(ValueError, match="`q0` must be finite"):
        v.unit_quaternions([0.0, 0.0, bad, 1.0], "q0")


def test_unit_quaternions_batch_names_first_bad_column():
    q = np.tile(np.array([[0.0], [0.0], [0.0], [1.0]]), (1, 6))
    q[:, 4] = [0.0, 0.0, 0.0, 0.5]
    q[:, 5] = 0.0
    with pytest.raises(ValueError, match=r"`q\[:, 4\]` must be a unit quaternion .* got norm 0.5"):
        v.unit_quaternions(q, "q")
    q[2, 1] = np.nan
    with pytest.raises(ValueError, match=r"`q\[:, 1\]` must be finite"):
        v.unit_quaternions(q, "q")
    with pytest.raises(ValueError, match=r"`q` must have shape \(4,\) or \(4, n\)"):
        v.unit_quaternions(np.zeros((3, 2)), "q")


def test_unit_quaternions_returns_as_given_or_normalized():
    q = np.array([[0.0, 0.6], [0.0, 0.0], [0.0, 0.0], [1.0, 0.8]]) * (1 - 5e-7)
    assert v.unit_quaternions(q, "q") is q
    np.testing.assert_allclose(v.unit_quaternions(q, "q", normalize=True),
                               [[0, 0.6], [0, 0], [0, 0], [1, 0.8]], rtol=1e-15)


@given(st.lists(st.tuples(*[st.floats(-1, 1, **finite)] * 4), min_size=1, max_size=8),
       st.floats(-0.99e-6, 0.99e-6))
def test_unit_quaternions_accept_everything_within_tolerance(rows, dn):
    q = np.array(rows, float).T
    n = np.linalg.norm(q, axis=0)
    q = q[:, n > 1e-3] / n[n > 1e-3] * (1 + dn)
    out = v.unit_quaternions(q, "q", normalize=True)
    np.testing.assert_allclose(np.linalg.norm(out, axis=0), 1.0, rtol=1e-15)


# -------------------------------------------------------------------- rotation_matrix
def test_rotation_matrix_accepts_rotations():
    R = Rotation.random(50, random_state=np.random.default_rng(0)).as_matrix()
    batch = np.moveaxis(R, 0, -1)
    assert v.rotation_matrix(batch, "A", batch=True) is batch
    v.rotation_matrix(np.eye(3), "A")
    v.rotation_matrix(ca.DM.eye(3), "A")


@pytest.mark.parametrize("A, match", [
    (2 * np.eye(3), r"max \|A A\^T - E\| = 3"),
    (np.zeros((3, 3)), r"max \|A A\^T - E\| = 1"),
    (np.ones((3, 3)), r"max \|A A\^T - E\| = 3"),  # A A^T = 3 ones
    (np.diag([1.0, 1.0, 1 + 2e-6]), r"max \|A A\^T - E\| = 4e-06"),
    (-np.eye(3), r"proper rotation \(det \+1\), got det -1"),
    (np.diag([1.0, -1.0, 1.0]), r"proper rotation \(det \+1\), got det -1"),
    (np.full((3, 3), np.nan), "finite"),
    (np.diag([1.0, np.inf, 1.0]), "finite"),
    (np.diag([1.0, 1.0, np.nan]), "finite"),   # NaN only in the last row
    (np.array([[1.0, 0, 0], [0, 1, 0], [np.nan, 0, 1]]), "finite"),
])
def test_rotation_matrix_refuses_non_rotations(A, match):
    with pytest.raises(ValueError, match=r"`A` must be .*" + match):
        v.rotation_matrix(A, "A")


def test_rotation_matrix_tolerance_boundary():
    # diag(1, 1, 1 + e): A A^T - E = diag(0, 0, 2e + e^2)
    v.rotation_matrix(np.diag([1.0, 1.0, 1 + 0.49e-6]), "A")
    with pytest.raises(ValueError, match="orthogonal to 1e-06"):
        v.rotation_matrix(np.diag([1.0, 1.0, 1 + 0.51e-6]), "A")
    v.rotation_matrix(np.diag([1.0, 1.0, 1 + 0.51e-6]), "A", tol=2e-6)


def test_rotation_matrix_batch_names_first_bad_matrix():
    A = np.stack([np.eye(3), np.eye(3), np.diag([-1.0, 1.0, 1.0]), 2 * np.eye(3)], axis=-1)
    with pytest.raises(ValueError, match=r"`A\[:, :, 3\]` must be a rotation matrix"):
        v.rotation_matrix(A, "A", batch=True)
    A[:, :, 3] = np.eye(3)
    with pytest.raises(ValueError, match=r"`A\[:, :, 2\]` must be a proper rotation .* det -1"):
        v.rotation_matrix(A, "A", batch=True)
    with pytest.raises(ValueError, match=r"`A` must have shape \(3, 3\), got \(3, 3, 4\)"):
        v.rotation_matrix(A, "A")


# ----------------------------------------------------------------------------- one_of
def test_one_of():
    assert v.one_of(2, "axis", (1, 2, 3)) == 2
    assert type(v.one_of(np.int64(3), "axis", (1, 2, 3))) is int
    assert v.one_of("ascending", "order", ("nearest", "ascending")) == "ascending"
    with pytest.raises(ValueError, match="`axis` must be 1, 2 or 3, got 4"):
        v.one_of(4, "axis", (1, 2, 3))
    for bad in (True, 1.0, "1", None):
        with pytest.raises(TypeError, match="`axis` must be 1, 2 or 3"):
            v.one_of(bad, "axis", (1, 2, 3))
    with pytest.raises(TypeError, match="`order` must be 'nearest' or 'ascending'"):
        v.one_of(0, "order", ("nearest", "ascending"))


# ---------------------------------------------------------------------------- integer
def test_integer():
    assert v.integer(3, "steps") == 3 and type(v.integer(np.int64(3), "steps")) is int
    assert v.integer(0, "index", minimum=0) == 0
    with pytest.raises(ValueError, match="`steps` must be an integer >= 1, got 0"):
        v.integer(0, "steps", minimum=1)
    for bad in (2.5, 3.0, np.float64(2.0)):
        with pytest.raises(ValueError, match="`steps` must be an integer"):
            v.integer(bad, "steps")
    for bad in ("3", None, True, [3]):
        with pytest.raises(TypeError, match="`steps` must be an integer"):
            v.integer(bad, "steps")


# ---------------------------------------------------------------------- check_inertia
def test_check_inertia_lives_here_and_in_rigid_body():
    from appdyn.dynamics.rigid_body import check_inertia

    assert check_inertia is v.check_inertia
    np.testing.assert_array_equal(v.check_inertia([1.0, 2.0, 2.5]), np.diag([1.0, 2.0, 2.5]))
    with pytest.raises(ValueError, match="`J` violates the triangle inequality"):
        v.check_inertia([1.0, 1.0, 3.0], name="J")
    v.check_inertia([1.0, 1.0, 3.0], triangle=False)


def test_an_inertia_error_prints_its_eigenvalues_as_plain_numbers():
    """The moments and eigenvalues in an inertia's or mass matrix's error read as numbers
    (numpy 2 printed ``np.float64(0.66)`` for each)."""
    from appdyn.dynamics.constrained.checks import factor_mass
    from appdyn.dynamics.mass.inertia import parallel_axis
    calls = [("principal moments (0.66, 0.69, 2.8)", lambda: v.check_inertia([0.66, 0.69, 2.8])),
             ("eigenvalues (-1.0, 1.0, 1.0)", lambda: v.check_inertia([-1.0, 1.0, 1.0])),
             ("eigenvalues (-1.0, 1.0, 1.0)",
              lambda: parallel_axis(np.diag([-1.0, 1.0, 1.0]), 1.0, [0.0, 0.0, 1.0])),
             ("eigenvalues (0.0, 1.0)", lambda: factor_mass(np.diag([0.0, 1.0])))]
    for expected, call in calls:
        with pytest.raises(ValueError) as info:
            call()
        assert expected in str(info.value) and "np.float64" not in str(info.value), info.value


def test_wrong_kind_is_a_type_error_that_old_value_error_handlers_still_catch():
    for call in (lambda: v.finite_scalar("x", "rate"), lambda: v.check_inertia("abc")):
        with pytest.raises(TypeError) as info:
            call()
        assert isinstance(info.value, ValueError) and isinstance(info.value, v.ArgumentTypeError)
