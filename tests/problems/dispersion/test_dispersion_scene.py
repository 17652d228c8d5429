"""`dispersion` accepts a `Scene` (and a factory returning one) as it does a `Model`.

Truth: the hub-only scene is the rigid body (`dynamics.rigid_body`, the hand-written model);
the same seeded draws give the same samples, and the axisymmetric spinner keeps its nutation
angle ``atan(I_t |w_t| / (I_a w3))`` in every sample.
"""
from __future__ import annotations

import numpy as np
import pytest

from appdyn.dynamics.scene import ExternalTorque, ReactionWheels, RigidHub, Scene
from appdyn.problems.dispersion import Normal, dispersion, nutation_history, spinner
from appdyn.problems.dispersion.sample import as_model

T = np.linspace(0.0, 20.0, 21)
X0 = [0, 0, 0, 1, 0.0, 0.0, 1.0]
PARAMS = {"transverse_inertia": Normal(1000.0, 20.0), "axial_inertia": Normal(1500.0, 30.0),
          "w1": Normal(0.02, 0.004)}


def scene_spinner(transverse_inertia, axial_inertia):
    """A factory returning a scene: the axisymmetric hub of `spinner`."""
    return Scene(RigidHub([transverse_inertia, transverse_inertia, axial_inertia]))


@pytest.mark.slow
def test_factory_returning_a_scene_matches_the_rigid_body_factory():
    outputs = {"nutation": nutation_history, "w1_final": "w1"}
    ref = dispersion(spinner, X0, T, samples=8, seed=3, params=PARAMS, outputs=outputs)
    res = dispersion(scene_spinner, X0, T, samples=8, seed=3, params=PARAMS, outputs=outputs)
    assert res.success and ref.success
    for key in outputs:
        np.testing.assert_allclose(res.outputs[key], ref.outputs[key], rtol=1e-9, atol=1e-12)
    theta = np.arctan2(res.inputs["transverse_inertia"] * np.abs(res.inputs["w1"]),
                       res.inputs["axial_inertia"])
    assert np.max(np.abs(res.outputs["nutation"] - theta[:, None])) < 1e-8


def test_a_fixed_scene_is_its_model():
    """A scene with wheels: the wheel states are dispersed by name like any model's; the
    absolute axial wheel momenta J (a_i.w + W_i) are conserved (torque-free, motors off)."""
    scene = Scene(RigidHub([10.0, 12.0, 8.0]), ReactionWheels(np.eye(3), 0.05), ExternalTorque())
    x0 = scene.state(w=[0.0, 0.0, 0.1], wheels=[10.0, 0.0, 0.0])
    model = scene.model()

    def drift(r):
        return (model.invariant("wheel_momentum", r.x[:, -1])
                - model.invariant("wheel_momentum", r.x[:, 0]))

    kw = dict(samples=6, seed=1, params={"W2": Normal(5.0, 1.0)}, outputs={"h": drift})
    res = dispersion(scene, x0, T, rtol=1e-10, atol=1e-12, **kw)
    ref = dispersion(model, x0, T, rtol=1e-10, atol=1e-12, **kw)
    assert res.success
    np.testing.assert_array_equal(res.outputs["h"], ref.outputs["h"])
    assert np.max(np.abs(res.outputs["h"])) < 1e-8


def test_as_model_names_the_argument():
    with pytest.raises(TypeError, match="model"):
        as_model("a scene")
    with pytest.raises(TypeError, match="`model` must be a Model, a Scene"):
        dispersion(3.0, X0, T, samples=2, seed=0, outputs={"w1": "w1"})


def test_nutation_history_reads_the_hub_states_by_name():
    """A scene whose hub carries wheels (axial moments 1e-9 kg m^2: a hub of the spinner's
    moments, to 1e-12) and wheel states after the hub's: the nutation output finds q and w by
    name and keeps the closed form atan(I_t |w_t| / (I_a w3))."""
    from appdyn.dynamics import simulate
    hub = RigidHub([1000.0, 1000.0, 1500.0])
    scene = Scene(hub, ReactionWheels(np.eye(3), 1e-9))
    t = np.linspace(0.0, 10.0, 11)
    res = simulate(scene.model(), scene.state(w=[0.02, 0.0, 1.0]), t, rtol=1e-11, atol=1e-13)
    theta = nutation_history(res, 1000.0, 1500.0)
    assert res.x.shape[0] == 10
    assert np.max(np.abs(theta - np.arctan2(1000.0 * 0.02, 1500.0))) < 1e-8
    fake = type("Run", (), {"x": np.zeros((3, 2)), "states": ("a", "b", "c")})()
    with pytest.raises(ValueError, match="q1..q4, w1..w3"):
        nutation_history(fake, 1000.0, 1500.0)


def test_a_batched_dispersion_over_a_scene_steps_each_sample_alone(monkeypatch):
    """``batch=True`` over a wheel scene: one batched ``simulate`` (``auto`` per run in one
    compiled loop) gives every sample the answer of its own single call, to the last bit;
    the wheel momenta stay conserved."""
    scene = Scene(RigidHub([10.0, 12.0, 8.0]), ReactionWheels(np.eye(3), 0.05), ExternalTorque())
    x0 = scene.state(w=[0.01, -0.02, 0.1], wheels=[10.0, 0.0, 0.0])
    model = scene.model()

    def drift(r):
        return (model.invariant("wheel_momentum", r.x[:, -1])
                - model.invariant("wheel_momentum", r.x[:, 0]))

    kw = dict(samples=6, seed=2, params={"W2": Normal(5.0, 1.0), "w1": Normal(0.01, 0.005)},
              outputs={"h": drift, "w3": "w3"})
    one = dispersion(model, x0, T, **kw)
    many = dispersion(model, x0, T, batch=True, **kw)
    assert many.success and one.success
    for key in ("h", "w3"):
        np.testing.assert_array_equal(many.outputs[key], one.outputs[key])
    assert np.max(np.abs(many.outputs["h"])) < 1e-8
    from appdyn.dynamics.integrate import dense
    monkeypatch.setattr(dense, "MANY_BUDGET", 1.0)  # (a compiled loop returns after each run)
    for threads in (1, 3):  # the samples spread over threads: the same bits
        spread = dispersion(model, x0, T, batch=True, threads=threads, **kw)
        for key in ("h", "w3"):
            np.testing.assert_array_equal(spread.outputs[key], one.outputs[key])
