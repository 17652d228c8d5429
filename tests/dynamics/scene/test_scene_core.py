"""The scene's own behaviour: naming, layout, state blocks, caching, bad input."""
import numpy as np
import pytest

from appdyn.dynamics.scene import (ExternalForce, ExternalTorque, HeldRotor, ReactionWheels,
                                   RigidHub, Scene)

I = np.array([[10.0, 1.2, -0.8], [1.2, 12.0, 0.6], [-0.8, 0.6, 8.0]])


def test_hub_alone_is_the_rigid_body_with_seven_states():
    model = Scene(RigidHub(I)).model()
    assert model.states == ("q1", "q2", "q3", "q4", "w1", "w2", "w3")
    assert model.controls == ()
    w = np.array([0.3, -0.2, 0.5])
    xdot = model.rhs(np.r_[0.0, 0.0, 0.0, 1.0, w])
    np.testing.assert_allclose(I @ xdot[4:7], np.cross(I @ w, w), rtol=0, atol=1e-15)


def test_equal_scenes_share_one_model_and_hash_alike():
    a = Scene(RigidHub(I), ReactionWheels(np.eye(3), 0.05), ExternalTorque(u_max=1.0))
    b = Scene(RigidHub(I.tolist()), ReactionWheels(np.eye(3).tolist(), [0.05] * 3),
              ExternalTorque(u_max=[1.0, 1.0, 1.0]))
    assert a == b and hash(a) == hash(b)
    assert a.model() is b.model()
    assert a != Scene(RigidHub(I), ReactionWheels(np.eye(3), 0.06), ExternalTorque(u_max=1.0))


def test_parts_of_one_kind_get_distinct_names_and_states():
    scene = Scene(RigidHub(I), HeldRotor([1, 0, 0], 1.0), HeldRotor([0, 1, 0], 2.0),
                  ReactionWheels([1.0, 0.0, 0.0], 0.1), ReactionWheels([0.0, 0.0, 1.0], 0.2))
    assert scene.part_names == ("rotor", "rotor_2", "wheels", "wheels_2")
    model = scene.model()
    assert model.states[7:] == ("W1", "W1_2")
    assert model.controls == ("tau1", "tau1_2")
    assert model.layout["wheels_2"].states == slice(8, 9)
    with pytest.raises(ValueError, match="named 'w'"):
        Scene(RigidHub(I), HeldRotor([1, 0, 0], 1.0, name="w"), HeldRotor([0, 1, 0], 1.0, name="w"))


def test_state_blocks_fill_the_rest_at_rest():
    scene = Scene(RigidHub(I, mass=5.0), ReactionWheels(np.eye(3), 0.05))
    x = scene.state(w=[0.0, 0.0, 0.1], v=[1.0, 2.0, 3.0], W2=7.0)
    assert x.shape == (16,)
    np.testing.assert_array_equal(x[:4], [0, 0, 0, 1])
    np.testing.assert_array_equal(x[scene.layout["wheels"].states], [0.0, 7.0, 0.0])
    np.testing.assert_array_equal(x[10:13], [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="unknown state block 'x'"):
        scene.state(x=[1.0])
    with pytest.raises(ValueError, match="w"):
        scene.state(w=[1.0, 2.0])


def test_bad_hub_and_parts_are_refused_by_name():
    with pytest.raises(TypeError, match="`hub` must be a RigidHub"):
        Scene(I)
    with pytest.raises(TypeError, match="part 1 must be a scene Part"):
        Scene(RigidHub(I), "wheels")
    with pytest.raises(ValueError, match="`reference` needs `mass`"):
        RigidHub(I, reference=[0.0, 0.0, 1.0])
    with pytest.raises(ValueError, match="inertia"):
        RigidHub([1.0, 1.0, 5.0])
    with pytest.raises(ValueError, match="u_max"):
        ExternalTorque(u_max=-1.0)


def test_six_dof_hub_momentum_about_the_origin_and_the_force_law():
    scene = Scene(RigidHub(I, mass=4.0, reference=[0.1, -0.2, 0.3]), ExternalForce(point=[0.0, 1.0, 0.0]))
    model = scene.model()
    x = scene.state(q=[0.1, 0.2, 0.3, np.sqrt(1 - 0.14)], w=[0.2, -0.1, 0.3], r=[1.0, 2.0, 3.0],
                    v=[0.5, 0.1, -0.2])
    # free: d/dt of the linear momentum and of the angular momentum about the origin vanish
    xdot = model.rhs(x, [0.0, 0.0, 0.0])
    eps = 1e-6
    for key in ("momentum_linear", "momentum_inertial"):
        rate = (model.invariant(key, x + eps * xdot) - model.invariant(key, x - eps * xdot)) / (2 * eps)
        np.testing.assert_allclose(rate, 0.0, atol=1e-8)


def test_a_scene_pickles_to_an_equal_scene():
    import pickle
    scene = Scene(RigidHub(I), ReactionWheels(np.eye(3), 0.05, u_max=0.1), name="craft")
    back = pickle.loads(pickle.dumps(scene))
    assert back == scene and back.model() is scene.model()
    model = pickle.loads(pickle.dumps(scene.model()))
    assert model.layout["wheels"] == scene.layout["wheels"]
    assert model.bounds == scene.model().bounds
