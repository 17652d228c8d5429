"""Parts on parts: the scene's tree against an independent sympy.mechanics Kane model
(`kane_chain`), and the parent checks."""
import numpy as np
import pytest

from appdyn.dynamics.scene import (GravityGradient, HingedPanel, PointMassDamper,
                                   ReactionWheels, RigidHub, Scene)

from .kane_chain import chain_equations

I_HUB = np.array([[10.0, 1.2, -0.8], [1.2, 12.0, 0.6], [-0.8, 0.6, 8.0]])
P1 = dict(mass=4.0, inertia=np.array([[0.8, 0.1, 0.0], [0.1, 0.3, 0.05], [0.0, 0.05, 0.6]]),
          hinge=[0.0, 0.6, 0.1], cm=[0.0, 0.7, 0.05], axis=[1.0, 0.0, 0.0], k=6.0)
P2 = dict(mass=1.5, inertia=np.diag([0.2, 0.05, 0.18]), hinge=[0.1, 1.4, 0.0],
          cm=[0.0, 0.4, -0.1], axis=[0.0, 0.6, 0.8], k=2.0)
WHEEL = dict(axis=[0.0, 0.0, 1.0], J=0.05)
DAMPER = dict(mass=0.7, k=30.0, position=[0.2, 0.3, 0.0], direction=[1.0, 0.0, 0.0])


def chain_scene():
    return Scene(
        RigidHub(I_HUB),
        HingedPanel(P1["mass"], P1["inertia"], P1["hinge"], P1["cm"], axis=P1["axis"],
                    stiffness=P1["k"], name="boom"),
        ReactionWheels(np.array(WHEEL["axis"])[:, None], WHEEL["J"], parent="boom"),
        HingedPanel(P2["mass"], P2["inertia"], P2["hinge"], P2["cm"], axis=P2["axis"],
                    stiffness=P2["k"], name="arm", parent="boom"),
        PointMassDamper(mass=DAMPER["mass"], stiffness=DAMPER["k"], damping=0.0,
                        position=DAMPER["position"], direction=DAMPER["direction"],
                        parent="arm"))


@pytest.fixture(scope="module")
def kane():
    return chain_equations(I_HUB, P1, WHEEL, P2, DAMPER)


@pytest.mark.slow
def test_chain_of_parts_equals_an_independent_kane_model(kane):
    scene = chain_scene()
    model = scene.model()
    assert scene.parents == (None, "boom", "boom", "arm")
    rng = np.random.default_rng(0)
    for _ in range(10):
        x = scene.state(q=[0.0, 0.0, 0.0, 1.0])
        x[4:] = rng.normal(scale=0.7, size=x.size - 4)
        s = dict(zip(model.states, x))
        tau = rng.normal()
        xdot = dict(zip(model.states, model.rhs(x, [tau])))
        ref = kane(s["theta"], s["theta_2"], s["s"], x[4:7], s["theta_dot"],
                   s["theta_dot_2"], s["W1"], s["s_dot"], tau)
        got = np.array([xdot["w1"], xdot["w2"], xdot["w3"], xdot["theta_dot"],
                        xdot["theta_dot_2"], xdot["W1"], xdot["s_dot"]])
        np.testing.assert_allclose(got, ref, rtol=1e-11, atol=1e-12 * np.abs(ref).max())


def test_a_part_on_a_panel_at_rest_follows_the_spin():
    """`Scene.state` gives a part on a panel the speeds of rest relative to its panel."""
    from appdyn.dynamics.scene import SphericalDamper
    scene = Scene(RigidHub(I_HUB), HingedPanel(2.0, [0.5, 0.1, 0.5], [0.0, 0.6, 0.0],
                                               [0.0, 0.5, 0.0], axis=[1.0, 0.0, 0.0]),
                  SphericalDamper(inertia=0.1, damping=0.2, parent="panel"))
    x = scene.state(w=[0.0, 0.0, 0.3], theta=0.4, theta_dot=0.2)
    s = dict(zip(scene.states, x))
    c, sn = np.cos(0.4), np.sin(0.4)
    R = np.array([[1.0, 0.0, 0.0], [0.0, c, -sn], [0.0, sn, c]])  # panel -> hub
    w_panel = R.T @ (np.array([0.0, 0.0, 0.3]) + 0.2 * np.array([1.0, 0.0, 0.0]))
    np.testing.assert_allclose([s["wd1"], s["wd2"], s["wd3"]], w_panel, rtol=1e-14,
                               atol=1e-15)


def test_parents_are_checked():
    hub = RigidHub(I_HUB)
    panel = HingedPanel(2.0, [0.5, 0.1, 0.5], [0.0, 0.6, 0.0], [0.0, 0.5, 0.0],
                        axis=[1.0, 0.0, 0.0])
    wheels = ReactionWheels(np.eye(3), 0.05, parent="boom")
    with pytest.raises(ValueError, match="`parent` 'boom' is not a part"):
        Scene(hub, panel, wheels)
    with pytest.raises(ValueError, match="cannot carry parts"):
        Scene(hub, ReactionWheels(np.eye(3), 0.05),
              ReactionWheels(np.eye(3), 0.05, parent="wheels"))
    with pytest.raises(TypeError, match="`parent` must be the name"):
        Scene(hub, panel, ReactionWheels(np.eye(3), 0.05, parent=3))
    a = HingedPanel(2.0, [0.5, 0.1, 0.5], [0.0, 0.6, 0.0], [0.0, 0.5, 0.0], name="a",
                    parent="b")
    b = HingedPanel(2.0, [0.5, 0.1, 0.5], [0.0, 0.6, 0.0], [0.0, 0.5, 0.0], name="b",
                    parent="a")
    with pytest.raises(ValueError, match="cycle"):
        Scene(hub, a, b)
    with pytest.raises(TypeError, match="unexpected keyword argument 'parent'"):
        GravityGradient(3.986e14, parent="panel")
    # the hub by name is the default
    assert Scene(hub, panel, ReactionWheels(np.eye(3), 0.05, parent="hub")).parents == (None,
                                                                                        None)


def test_a_child_listed_before_its_parent_is_the_same_model():
    """The state order follows the scene; the assembly mounts parents first."""
    panel = HingedPanel(2.0, [0.5, 0.1, 0.5], [0.0, 0.6, 0.0], [0.0, 0.5, 0.0],
                        axis=[1.0, 0.0, 0.0], stiffness=3.0)
    wheels = ReactionWheels(np.eye(3)[:, :1], 0.05, parent="panel")
    first, second = Scene(RigidHub(I_HUB), panel, wheels), Scene(RigidHub(I_HUB), wheels, panel)
    assert second.mount_order == (1, 0)
    x1 = first.state(w=[0.1, -0.2, 0.3], theta=0.3, theta_dot=0.1, W1=2.0)
    s = dict(zip(first.states, x1))
    x2 = np.array([s[k] for k in second.states])
    f1 = dict(zip(first.states, first.model().rhs(x1, [0.4])))
    f2 = dict(zip(second.states, second.model().rhs(x2, [0.4])))
    for k in f1:
        assert f1[k] == pytest.approx(f2[k], rel=1e-14, abs=1e-15)


def test_aerodynamics_on_a_panel_reads_its_own_point():
    """On a panel of a six-degree-of-freedom hub the air force acts at the panel's centre of
    pressure; the hub's mass centre is not the panel's to read."""
    from appdyn.dynamics.scene import Aerodynamics
    panel = HingedPanel(2.0, [0.5, 0.1, 0.5], [0.0, 0.6, 0.0], [0.0, 0.5, 0.0],
                        axis=[1.0, 0.0, 0.0])
    hub = RigidHub(I_HUB, mass=40.0)
    scene = Scene(hub, panel, Aerodynamics(1.0, 2.0, parent="panel"))
    assert scene.model().nx == 15
    with pytest.raises(ValueError, match="air_velocity='mass_centre'"):
        Scene(hub, panel, Aerodynamics(1.0, 2.0, air_velocity="mass_centre",
                                       parent="panel")).model()
    with pytest.raises(ValueError, match="six-degree-of-freedom hub"):
        Scene(RigidHub(I_HUB), panel, Aerodynamics(1.0, 2.0, parent="panel")).model()
