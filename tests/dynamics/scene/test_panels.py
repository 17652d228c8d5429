"""HingedPanel (minimal coordinates) against the multiplier formulation `hinged_bodies`
(two free bodies joined by a ball or revolute hinge) and against a sympy.mechanics Kane
model of a pinned hub with a spring-loaded revolute panel."""
import casadi as ca
import numpy as np
import pytest

from appdyn.dynamics import hinged_bodies, simulate
from appdyn.dynamics.attitude import (dcm_from_axis_angle, dcm_from_quat, quat_from_axis_angle,
                                      quat_mul)
from appdyn.dynamics.scene import HingedPanel, RigidHub, Scene

M1, I1 = 12.0, np.array([[4.0, 0.3, -0.2], [0.3, 5.0, 0.4], [-0.2, 0.4, 6.0]])
M2, I2 = 2.5, np.array([[0.6, -0.05, 0.02], [-0.05, 0.3, 0.04], [0.02, 0.04, 0.8]])
R1 = np.array([0.4, 0.9, -0.2])     # hinge from body 1's mass centre, body-1 axes
R2 = np.array([-0.1, -0.7, 0.15])   # hinge from body 2's mass centre, body-2 axes
AXIS = np.array([1.0, 2.0, -0.5]) / np.linalg.norm([1.0, 2.0, -0.5])


def scenes(kind):
    axis = AXIS if kind == "revolute" else None
    scene = Scene(RigidHub(I1, mass=M1),
                  HingedPanel(M2, I2, hinge_point=R1, cm_offset=-R2, axis=axis))
    return scene, hinged_bodies(M1, I1, M2, I2, R1, R2, kind=kind, axis=axis)


def to_hinged(scene, x):
    """The two-body state of a scene state (SX or numbers): body 2 from the hinge."""
    x = ca.SX(x) if isinstance(x, ca.SX) else ca.DM(x)
    q1, w1, r, v = x[0:4], x[4:7], x[7:10], x[10:13]
    panel = scene.parts[0]
    if panel.revolute:
        a = ca.DM(panel.axis)
        theta, rate = x[13], x[14]
        C = dcm_from_axis_angle(a, theta)             # body 1 -> body 2 axes
        q2 = quat_mul(quat_from_axis_angle(a, theta), q1)
        w_rel = rate * a
    else:
        p, u = x[13:17], x[17:20]
        C = dcm_from_quat(p)
        q2 = quat_mul(p, q1)
        w_rel = ca.mtimes(C.T, u)
    A1 = dcm_from_quat(q1)
    arm = ca.mtimes(C.T, ca.DM(-R2))
    w2 = ca.mtimes(C, w1 + w_rel)
    v2 = ca.mtimes(C, v + ca.cross(w1, ca.DM(R1) + arm) + ca.cross(w_rel, arm))
    R2_in = r + ca.mtimes(A1.T, ca.DM(R1) + arm)
    return ca.vertcat(q1, w1, v, r, q2, w2, v2, R2_in)


def start(kind):
    q = np.array([0.2, -0.3, 0.1, 0.0])
    q[3] = np.sqrt(1 - q @ q)
    base = dict(q=q, w=[0.3, -0.2, 0.25], r=[1.0, -2.0, 0.5], v=[0.1, 0.3, -0.2])
    if kind == "revolute":
        return dict(base, panel=[0.4, -0.6])
    p = quat_from_axis_angle([0.3, -1.0, 0.6], 0.7)
    return dict(base, panel=np.r_[p, 0.5, -0.4, 0.3])


@pytest.mark.parametrize("kind", ["revolute", "ball"])
def test_rhs_maps_onto_the_multiplier_model(kind):
    """d/dt of the mapped state equals the multiplier model's rhs at random states."""
    scene, hinged = scenes(kind)
    model = scene.model()
    xs = ca.SX.sym("x", model.nx)
    mapped = to_hinged(scene, xs)
    rate = ca.Function("rate", [xs],
                       [mapped, ca.mtimes(ca.jacobian(mapped, xs), model.f(xs, [], []))])
    rng = np.random.default_rng(7)
    for _ in range(5):
        blocks = start(kind)
        x = scene.state(**blocks)
        x[4:13] += rng.normal(scale=0.3, size=9)
        x[13:] += rng.normal(scale=0.3, size=x.size - 13)
        if kind == "ball":
            x[13:17] /= np.linalg.norm(x[13:17])
        xh, xh_dot = (np.asarray(a).ravel() for a in rate(x))
        assert float(np.max(hinged.invariant("constraint_residual", xh))) < 1e-14
        np.testing.assert_allclose(xh_dot, hinged.rhs(xh), rtol=0, atol=1e-12)


@pytest.mark.parametrize("kind", ["revolute", "ball"])
def test_trajectory_equals_the_multiplier_model_over_20_s(kind):
    scene, hinged = scenes(kind)
    model = scene.model()
    x0 = scene.state(**start(kind))
    xs = ca.SX.sym("x", model.nx)
    mapping = ca.Function("m", [xs], [to_hinged(scene, xs)])
    xh0 = np.asarray(mapping(x0)).ravel()
    t = np.linspace(0.0, 20.0, 41)
    a = simulate(model, x0, t, rtol=1e-11, atol=1e-11, jit=False)
    b = simulate(hinged, xh0, t, rtol=1e-11, atol=1e-11, jit=False)
    assert a.success and b.success
    mapped = np.asarray(mapping.map(t.size)(a.x))
    err = np.max(np.abs(mapped - b.x))
    assert err < 1e-10, err
    # energy and momenta conserved by the scene model (no spring, no damper)
    for key in ("energy", "momentum_linear", "momentum_inertial"):
        vals = np.array([model.invariant(key, a.x[:, k]) for k in range(t.size)])
        assert np.max(np.abs(vals - vals[0])) < 1e-9 * max(1.0, np.max(np.abs(vals)))


def kane_pinned_hub_with_revolute_panel(I_hub, m, I_panel, hinge, offset, axis, k, c):
    """sympy.mechanics (Kane): a hub turning about its fixed mass centre and a revolute panel
    with a spring and damper; ``(w, theta, theta_dot) -> (w', theta_ddot)`` as numbers."""
    sm = pytest.importorskip("sympy")
    me = pytest.importorskip("sympy.physics.mechanics")
    th, w1, w2, w3, thd = me.dynamicsymbols("th w1 w2 w3 thd")
    N, B = me.ReferenceFrame("N"), me.ReferenceFrame("B")
    B.set_ang_vel(N, w1 * B.x + w2 * B.y + w3 * B.z)  # the rates do not depend on the attitude
    ax = axis[0] * B.x + axis[1] * B.y + axis[2] * B.z
    P = B.orientnew("P", "Axis", (th, ax))
    O = me.Point("O")
    O.set_vel(N, 0)
    H = O.locatenew("H", hinge[0] * B.x + hinge[1] * B.y + hinge[2] * B.z)
    G = H.locatenew("G", offset[0] * P.x + offset[1] * P.y + offset[2] * P.z)
    H.v2pt_theory(O, N, B)
    G.v2pt_theory(H, N, P)

    def dyadic(F, J):
        return me.inertia(F, J[0, 0], J[1, 1], J[2, 2], J[0, 1], J[1, 2], J[2, 0])

    hub = me.RigidBody("hub", O, B, 1.0, (dyadic(B, I_hub), O))
    panel = me.RigidBody("panel", G, P, m, (dyadic(P, I_panel), G))
    kd = [thd - th.diff()]
    hinge_torque = (-k * th - c * thd) * ax
    km = me.KanesMethod(N, q_ind=[th], u_ind=[w1, w2, w3, thd], kd_eqs=kd)
    km.kanes_equations([hub, panel], [(P, hinge_torque), (B, -hinge_torque)])
    args = [th, w1, w2, w3, thd]
    mass = sm.lambdify(args, km.mass_matrix, "numpy")
    force = sm.lambdify(args, km.forcing, "numpy")

    def rhs(w, theta, theta_dot):
        x = [theta, *w, theta_dot]
        return np.linalg.solve(np.array(mass(*x), float), np.array(force(*x), float).ravel())

    return rhs


@pytest.mark.slow
def test_revolute_panel_on_a_pinned_hub_equals_a_sympy_kane_model():
    axis, k, c = AXIS, 3.0, 0.4
    kane = kane_pinned_hub_with_revolute_panel(I1, M2, I2, R1, -R2, axis, k, c)
    scene = Scene(RigidHub(I1), HingedPanel(M2, I2, R1, -R2, axis=axis, stiffness=k, damping=c))
    model = scene.model()
    rng = np.random.default_rng(3)
    for _ in range(5):
        w, theta, rate = rng.normal(scale=0.5, size=3), rng.uniform(-2.0, 2.0), rng.normal()
        xdot = model.rhs(scene.state(w=w, theta=theta, theta_dot=rate))
        ref = kane(w, theta, rate)
        np.testing.assert_allclose(xdot[[4, 5, 6, 8]], ref, rtol=0,
                                   atol=1e-12 * max(1.0, np.max(np.abs(ref))))


@pytest.mark.parametrize("kind", ["revolute", "ball"])
def test_hinge_spring_on_an_immovable_hub_is_the_torsion_pendulum(kind):
    """Hub inertia 1e12 times the panel's: from rest, the panel's angular acceleration about
    the hinge is ``I_H^-1 T`` with ``I_H = I + m (|c|^2 E - c c^T)`` (parallel axes) and the
    spring torque ``-k theta a`` (revolute) or ``-k sin(phi) e`` (ball, module docstring)."""
    k, phi = 5.0, 0.3
    c = -R2
    I_H = I2 + M2 * (c @ c * np.eye(3) - np.outer(c, c))
    axis = AXIS if kind == "revolute" else None
    scene = Scene(RigidHub(1e12 * np.eye(3)), HingedPanel(M2, I2, R1, c, axis=axis, stiffness=k))
    model = scene.model()
    e = AXIS if kind == "revolute" else np.array([0.2, -0.9, 0.4]) / np.sqrt(1.01)
    if kind == "revolute":
        xdot = model.rhs(scene.state(theta=phi))
        expected = -k * phi / (e @ I_H @ e)
        assert abs(xdot[8] - expected) < 1e-10 * abs(expected)
    else:
        xdot = model.rhs(scene.state(panel=np.r_[quat_from_axis_angle(e, phi), 0.0, 0.0, 0.0]))
        # the panel's axes after the turn: I_H and e in them (e is unchanged by the turn)
        expected = np.linalg.solve(I_H, -k * np.sin(phi) * e)
        np.testing.assert_allclose(xdot[11:14], expected, rtol=0,
                                   atol=1e-10 * np.max(np.abs(expected)))


@pytest.mark.parametrize("kind", ["revolute", "ball"])
def test_energy_falls_at_the_damper_power(kind):
    """``dE/dt = -c |relative rate|^2`` (kinetic plus spring energy) at random states of a
    six-degree-of-freedom hub with a spring-loaded, damped panel: rhs level, to 1e-13 of the
    terms."""
    axis = AXIS if kind == "revolute" else None
    c = 0.7
    scene = Scene(RigidHub(I1, mass=M1), HingedPanel(M2, I2, R1, -R2, axis=axis, stiffness=3.0,
                                                     damping=c))
    model = scene.model()
    x = ca.SX.sym("x", model.nx)
    terms = ca.jacobian(model.invariants["energy"](x, []), x).T * model.f(x, [], [])
    rel = x[model.layout["panel"].speeds]
    rate = ca.Function("rate", [x], [ca.sum1(terms) + c * ca.sumsqr(rel), ca.sum1(ca.fabs(terms))])
    rng = np.random.default_rng(23)
    for _ in range(5):
        blocks = start(kind)
        xs = scene.state(**blocks)
        xs[4:] += rng.normal(scale=0.3, size=model.nx - 4)
        if kind == "ball":
            xs[13:17] /= np.linalg.norm(xs[13:17])
        residual, size = (float(v) for v in rate(xs))
        assert abs(residual) < 1e-13 * size, (residual, size)


def test_bad_panel_arguments_are_refused_by_name():
    with pytest.raises(ValueError, match="mass"):
        HingedPanel(0.0, I2, R1, R2)
    with pytest.raises(ValueError, match="hinge_point"):
        HingedPanel(1.0, I2, [0.0, 1.0], R2)
    with pytest.raises(ValueError, match="cm_offset"):
        HingedPanel(1.0, I2, R1, [0.0, np.nan, 0.0])
    with pytest.raises(ValueError, match="axis"):
        HingedPanel(1.0, I2, R1, R2, axis=[1.0, 1.0, 0.0])
    with pytest.raises(ValueError, match="stiffness"):
        HingedPanel(1.0, I2, R1, R2, stiffness=-1.0)
    with pytest.raises(ValueError, match="inertia"):
        HingedPanel(1.0, [1.0, 1.0, 5.0], R1, R2)


def test_two_ball_panels_keep_their_own_names_and_invariants():
    scene = Scene(RigidHub(I1), HingedPanel(M2, I2, R1, -R2), HingedPanel(M2, I2, -R1, R2))
    model = scene.model()
    assert scene.part_names == ("panel", "panel_2")
    assert model.states[7:] == ("p1", "p2", "p3", "p4", "u1", "u2", "u3",
                                "p1_2", "p2_2", "p3_2", "p4_2", "u1_2", "u2_2", "u3_2")
    x = scene.state(panel_2=[0.0, 0.0, 0.6, 0.8, 0.0, 0.0, 0.0],
                    panel=[0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0])
    assert float(model.invariant("panel_quat_norm", x)) == 2.0
    assert float(model.invariant("panel_quat_norm_2", x)) == 1.0


@pytest.mark.parametrize("kind", ["revolute", "ball"])
def test_two_body_state_equals_the_test_mapping(kind):
    """`dynamics.hinged.two_body_state` (the library's map, used by ``simulate hinged``)
    against this file's `to_hinged`, at random states; and `hinged_scene` is `scenes`."""
    from appdyn.dynamics.hinged import hinged_scene, two_body_state

    scene, _ = scenes(kind)
    assert hinged_scene(M1, I1, M2, I2, R1, R2, kind,
                        AXIS if kind == "revolute" else None).parts == scene.parts
    fun = two_body_state(scene)
    rng = np.random.default_rng(11)
    for _ in range(5):
        x = scene.state(**start(kind))
        x[4:] += rng.normal(scale=0.3, size=x.size - 4)
        if kind == "ball":
            x[13:17] /= np.linalg.norm(x[13:17])
        np.testing.assert_allclose(np.asarray(fun(x)).ravel(),
                                   np.asarray(to_hinged(scene, x)).ravel(), rtol=0, atol=1e-14)
    with pytest.raises(ValueError, match="`scene`"):
        two_body_state(Scene(RigidHub(I1, mass=M1)))
