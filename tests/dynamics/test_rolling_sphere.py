"""The rolling sphere of seed 002 Sec. 5.5 a (nonholonomic, 2 x 5 constraint matrix):
constraint kept, energy and the angular momentum about the contact point conserved, and the
closed form: the centre rolls on a straight line at constant velocity with constant w."""
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from appdyn.dynamics import simulate
from appdyn.dynamics.attitude import dcm_from_euler321
from appdyn.dynamics.mechanisms import rolling_sphere, sphere_constraint_matrix, sphere_state


def _omega_from_dcm(q, qd, h=1e-6):
    """Inertial angular velocity from the DCM's rate (independent of the model's formula):
    d(A^T)/dt = w~ A^T with A = dcm_from_euler321((psi, theta, phi))."""
    def At(s):
        phi, psi, th = q[2:] + s * qd[2:]
        return dcm_from_euler321([psi, th, phi]).T
    dAt = (At(h) - At(-h)) / (2 * h)
    W = dAt @ At(0.0).T
    return np.array([W[2, 1], W[0, 2], W[1, 0]])


@settings(max_examples=25, deadline=None)
@given(q=st.lists(st.floats(-1.2, 1.2), min_size=5, max_size=5),
       qd=st.lists(st.floats(-2, 2), min_size=5, max_size=5), a=st.floats(0.05, 2.0))
def test_constraint_matrix_is_the_rolling_condition(q, qd, a):
    q, qd = np.array(q), np.array(qd)
    C = sphere_constraint_matrix(q, radius=a)
    w = _omega_from_dcm(q, qd)
    assert C.shape == (2, 5)
    # v_c = w x (a j): x' = -a w_z, z' = a w_x (Eq. 5.71)
    assert C @ qd == pytest.approx([qd[0] + a * w[2], qd[1] - a * w[0]], abs=1e-7)
    # the seed's phi' column: a A13, -a A11
    A = dcm_from_euler321([q[3], q[4], q[2]])
    assert C[:, 2] == pytest.approx([a * A[0, 2], -a * A[0, 0]], abs=1e-13)


def test_straight_line_rolling_energy_and_momentum():
    a, m = 0.2, 2.0
    model = rolling_sphere(mass=m, radius=a)
    x0 = sphere_state([0.7, -0.4], spin=1.5, angles=[0.3, -0.2, 0.4], radius=a,
                      position=[1.0, 2.0])
    t = np.linspace(0.0, 2.0, 21)
    res = simulate(model, x0, t, method="rk8", steps=20, invariants=True,
                   jit=False)
    assert res.success
    assert np.allclose(res["x"], 1.0 + 0.7 * t, atol=1e-9)
    assert np.allclose(res["z"], 2.0 - 0.4 * t, atol=1e-9)
    assert np.max(np.abs(res.invariants["constraint_residual"])) < 1e-9
    energy = res.invariants["energy"]
    assert np.max(np.abs(energy / energy[0] - 1)) < 1e-10
    assert energy[0] == pytest.approx(0.5 * m * (0.7 ** 2 + 0.4 ** 2)
                                      + 0.5 * 0.4 * m * a * a * ((0.7 ** 2 + 0.4 ** 2) / a ** 2
                                                                 + 1.5 ** 2), rel=1e-12)
    w = res.invariants["omega"]
    assert np.max(np.abs(w - w[:, :1])) < 1e-9
    assert w[:, 0] == pytest.approx([-0.4 / a, 1.5, -0.7 / a], rel=1e-12)
    h = res.invariants["contact_momentum"]
    assert np.max(np.abs(h - h[:, :1])) < 1e-9 * np.abs(h[:, 0]).max()
    assert np.max(np.abs(res.invariants["multipliers"])) < 1e-9     # no force needed


def test_a_disturbed_start_still_rolls_straight():
    """Any rolling start (the angles far from zero, theta near the singularity kept away)
    rolls straight; the contact moment vanishes, so the contact momentum is conserved."""
    model = rolling_sphere(mass=1.0, radius=0.1, inertia=0.006)   # not uniform
    x0 = sphere_state([-0.3, 0.9], spin=-4.0, angles=[1.0, 2.0, 1.0], radius=0.1)
    res = simulate(model, x0, np.linspace(0.0, 0.5, 6), method="rk8", steps=50, jit=False,
                   invariants=True)
    assert np.allclose(res.x[5:7], [[-0.3], [0.9]], atol=1e-9)
    assert np.max(np.abs(res.invariants["constraint_residual"])) < 1e-9


def test_bad_input():
    with pytest.raises(ValueError, match="`radius`"):
        rolling_sphere(radius=0.0)
    with pytest.raises(ValueError, match="`inertia`"):
        rolling_sphere(inertia=-1.0)
    with pytest.raises(ValueError, match="`q`"):
        sphere_constraint_matrix([0.0, 0.0])
    with pytest.raises(ValueError, match="`angles`"):
        sphere_state([1.0, 0.0], angles=[0.0, 0.0, np.pi / 2])
    with pytest.raises(ValueError, match="`velocity`"):
        sphere_state([1.0, 0.0, 0.0])
