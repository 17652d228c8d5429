"""Rigid-body model against Euler's equations, a second formulation and conservation laws."""
import casadi as ca
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from appdyn.dynamics import Model, rigid_body
from appdyn.dynamics.attitude import dcm_from_quat, principal_axes
from tests.bodies import GEMINI



def random_state(rng):
    q = rng.normal(size=4)
    return np.concatenate([q / np.linalg.norm(q), rng.normal(size=3)])


def test_diagonal_inertia_matches_eq_4_82():
    """I1 w1' + (I3 - I2) w2 w3 = L1 (cyclic), written out component by component."""
    I1, I2, I3 = 2.0, 3.0, 4.5
    model = rigid_body([I1, I2, I3])
    rng = np.random.default_rng(0)
    for _ in range(5):
        x, u = random_state(rng), rng.normal(size=3)
        w1, w2, w3 = x[4:]
        expected = [
            (u[0] - (I3 - I2) * w2 * w3) / I1,
            (u[1] - (I1 - I3) * w1 * w3) / I2,
            (u[2] - (I2 - I1) * w1 * w2) / I3,
        ]
        np.testing.assert_allclose(model.rhs(x, u)[4:], expected, rtol=1e-14)


def test_full_inertia_equals_principal_frame_formulation(gemini):
    """Second formulation: rotate to principal axes, apply Eq. 4.82, rotate back."""
    model = gemini
    moments, A = principal_axes(GEMINI)
    principal = rigid_body(moments)
    rng = np.random.default_rng(1)
    for _ in range(5):
        x, u = random_state(rng), 100 * rng.normal(size=3)
        xp = np.concatenate([x[:4], A @ x[4:]])
        wdot_p = principal.rhs(xp, A @ u)[4:]
        np.testing.assert_allclose(model.rhs(x, u)[4:], A.T @ wdot_p, rtol=1e-10, atol=1e-15)


def test_invariant_rates_along_the_flow(gemini):
    """dT/dt = w.u and d(A^T I w)/dt = A^T u (torque in inertial axes), exactly."""
    model = gemini
    x, u = ca.SX.sym("x", 7), ca.SX.sym("u", 3)
    xdot = model.f(x=x, u=u, p=ca.DM.zeros(0))["xdot"]
    rates = {
        k: ca.Function(k, [x, u], [ca.jtimes(fun(x, ca.DM.zeros(0)), x, xdot)])
        for k, fun in model.invariants.items()
    }
    rng = np.random.default_rng(2)
    for _ in range(5):
        xv, uv = random_state(rng), rng.normal(size=3)
        A = dcm_from_quat(xv[:4])
        assert float(rates["energy"](xv, uv)) == pytest.approx(xv[4:] @ uv, rel=1e-10)
        np.testing.assert_allclose(np.array(rates["momentum_inertial"](xv, uv)).ravel(), A.T @ uv, atol=1e-11)
        assert float(rates["quat_norm"](xv, uv)) == pytest.approx(0.0, abs=1e-15)


def test_invariants_evaluate_along_trajectory():
    model = rigid_body([1.0, 2.0, 2.5])
    rng = np.random.default_rng(3)
    X = np.stack([random_state(rng) for _ in range(4)], axis=1)
    H = model.invariant("momentum_inertial", X)
    assert H.shape == (3, 4)
    T = model.invariant("energy", X)
    assert T.shape == (4,)
    np.testing.assert_allclose(T, 0.5 * np.sum(np.array([1, 2, 2.5])[:, None] * X[4:] ** 2, 0))
    np.testing.assert_allclose(model.invariant("quat_norm", X), 1.0)
    # |H| is frame independent
    np.testing.assert_allclose(np.linalg.norm(H, axis=0),
                               np.linalg.norm(np.array([1, 2, 2.5])[:, None] * X[4:], axis=0))


def test_model_metadata_and_cache():
    model = rigid_body(GEMINI)
    assert model.states == ("q1", "q2", "q3", "q4", "w1", "w2", "w3")
    assert model.controls == ("L1", "L2", "L3") and model.params == ()
    assert model.attitude == (0, 4)
    assert model.f.name_in() == ["x", "u", "p"] and model.f.name_out() == ["xdot"]
    assert set(model.invariants) == {"energy", "momentum_inertial", "quat_norm"}
    assert rigid_body(GEMINI.tolist()) is model


def test_scipy_rotation_peer_for_momentum():
    model = rigid_body([1.0, 2.0, 2.5])
    q = Rotation.random(random_state=4).as_quat()
    w = np.array([0.3, -0.1, 0.7])
    H_body = np.array([1.0, 2.0, 2.5]) * w
    expected = Rotation.from_quat(q).apply(H_body)  # active rotation: body -> inertial
    np.testing.assert_allclose(model.invariant("momentum_inertial", np.r_[q, w]), expected, atol=1e-15)


@pytest.mark.parametrize(
    "inertia, match",
    [
        (np.eye(2), "shape"),
        ([1.0, 2.0], "shape"),
        ([[1, 0, 0], [0, 1, 0], [0, 0, np.nan]], "finite"),
        ([[1, 0.1, 0], [0, 1, 0], [0, 0, 1]], "symmetric"),
        ([1.0, -2.0, 2.0], "positive definite"),
        ([1.0, 1.0, 3.0], "triangle inequality"),
        ("abc", "`inertia` must be real numbers"),
        (["1", "2", "3"], "`inertia` must be real numbers"),
    ],
)
def test_invalid_inertia_raises(inertia, match):
    with pytest.raises(ValueError, match=f"`inertia`.*{match}|{match}"):
        rigid_body(inertia)


def test_model_rejects_inconsistent_functions():
    x, u, p = ca.SX.sym("x", 2), ca.SX.sym("u", 1), ca.SX.sym("p", 0)
    good = ca.Function("f", [x, u, p], [x], ["x", "u", "p"], ["xdot"])
    Model(good, ("a", "b"), ("c",))
    with pytest.raises(ValueError, match="inputs"):
        Model(ca.Function("f", [x, u, p], [x]), ("a", "b"), ("c",))
    with pytest.raises(ValueError, match="input 'x'"):
        Model(good, ("a",), ("c",))
    with pytest.raises(ValueError, match="p_default"):
        Model(good, ("a", "b"), ("c",), p_default=[1.0])
    with pytest.raises(TypeError, match="casadi.Function"):
        Model(lambda x: x, ("a", "b"), ("c",))
    with pytest.raises(ValueError, match="attitude"):
        Model(good, ("a", "b"), ("c",), attitude=(0, 4))
    m = Model(good, ("a", "b"), ("c",))
    with pytest.raises(ValueError, match="`p` must have 0"):
        m.rhs([1, 2], [0], p=[1.0])
