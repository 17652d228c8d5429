"""A six-degree-of-freedom hub's reference point: Euler's law about a body point ``c`` other
than the mass centre (seed 000, Eqs. 6.43-6.46) gives the motion of the mass-centre form
(Eqs. 6.19-6.20), mapped by ``r_ref = r_cm + A^T c``, ``v_ref = v_cm + w x c``."""
import casadi as ca
import numpy as np
import pytest

from appdyn.dynamics import simulate
from appdyn.dynamics.attitude import dcm_from_quat
from appdyn.dynamics.scene import ExternalForce, ExternalTorque, HingedPanel, RigidHub, Scene

I = np.array([[40.0, 2.0, -1.0], [2.0, 55.0, 3.0], [-1.0, 3.0, 35.0]])
C = np.array([0.4, -0.3, 0.7])


def parts(kind):
    axis = [0.0, 0.6, 0.8] if kind == "revolute" else None
    return (HingedPanel(6.0, [1.0, 0.4, 1.2], hinge_point=[0.2, 1.0, -0.3],
                        cm_offset=[0.0, 0.9, 0.1], axis=axis, stiffness=4.0, damping=0.3),
            ExternalForce(point=[0.5, -0.2, 0.9]), ExternalTorque())


def scenes(kind):
    return (Scene(RigidHub(I, mass=80.0, reference=C), *parts(kind)),
            Scene(RigidHub(I, mass=80.0), *parts(kind)))


def to_reference(x):
    """Mass-centre state -> reference-point state (SX)."""
    q, w, r, v = x[0:4], x[4:7], x[7:10], x[10:13]
    c = ca.DM(C)
    return ca.vertcat(q, w, r + ca.mtimes(dcm_from_quat(q).T, c), v + ca.cross(w, c), x[13:])


def random_state(scene, rng):
    q = rng.normal(size=4)
    panel = ([rng.uniform(-1, 1), rng.normal()] if scene.parts[0].revolute
             else np.r_[rng.normal(size=4), rng.normal(size=3)])
    if len(panel) == 7:
        panel[:4] /= np.linalg.norm(panel[:4])
    return scene.state(q=q / np.linalg.norm(q), w=rng.normal(scale=0.5, size=3),
                       r=rng.normal(size=3), v=rng.normal(size=3), panel=panel)


@pytest.mark.parametrize("kind", ["revolute", "ball"])
def test_rhs_about_a_reference_point_maps_onto_the_mass_centre_form(kind):
    at_ref, at_cm = scenes(kind)
    f_ref, f_cm = at_ref.model().f, at_cm.model().f
    x, u = ca.SX.sym("x", at_cm.model().nx), ca.SX.sym("u", at_cm.model().nu)
    mapped = to_reference(x)
    check = ca.Function("check", [x, u], [
        f_ref(mapped, u, []), ca.mtimes(ca.jacobian(mapped, x), f_cm(x, u, []))])
    rng = np.random.default_rng(17)
    for _ in range(5):
        out = check(random_state(at_cm, rng), rng.normal(size=6))
        lhs, rhs = (np.asarray(a).ravel() for a in out)
        np.testing.assert_allclose(lhs, rhs, rtol=0, atol=1e-12 * max(1.0, np.max(np.abs(rhs))))


@pytest.mark.parametrize("kind", ["revolute", "ball"])
@pytest.mark.slow
def test_trajectory_about_a_reference_point_equals_the_mass_centre_one(kind):
    at_ref, at_cm = scenes(kind)
    x = ca.SX.sym("x", at_cm.model().nx)
    mapping = ca.Function("m", [x], [to_reference(x)])
    rng = np.random.default_rng(19)
    x0 = random_state(at_cm, rng)
    t = np.linspace(0.0, 20.0, 41)
    u = np.outer(rng.normal(size=6), np.ones(t.size)) * np.cos(0.3 * t)  # force and torque
    a = simulate(at_cm.model(), x0, t, u=u, rtol=1e-11, atol=1e-11, jit=False)
    b = simulate(at_ref.model(), np.asarray(mapping(x0)).ravel(), t, u=u, rtol=1e-11,
                 atol=1e-11, jit=False)
    assert a.success and b.success
    err = np.max(np.abs(np.asarray(mapping.map(t.size)(a.x)) - b.x))
    assert err < 1e-10, err
