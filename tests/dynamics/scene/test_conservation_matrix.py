"""The conservation matrix (Basilisk's bar): every pair of example parts, and one scene with
all of them, on both hubs.

With every control zero, the invariants each part leaves conserved (inertial angular
momentum, energy, and linear momentum on a six-degree-of-freedom hub) stay constant to 1e-10
relative over 100 s; with the controls on, the energy changes exactly at the power of the
controls (``E' = sum u . v_u``, each control with the velocity it does work on), at random
states.
"""
import dataclasses
import itertools

import numpy as np
import pytest

from appdyn.dynamics import simulate
from appdyn.dynamics.attitude import dcm_from_axis_angle
from appdyn.dynamics.scene import RigidHub, Scene

from .registry import ALL, I_HUB, PARTS

HUBS = {"attitude": lambda: RigidHub(I_HUB),
        "six_dof": lambda: RigidHub(I_HUB, mass=40.0, reference=[0.1, -0.05, 0.2])}
#: every pair and one scene with every example part (the simulations are slow: CI and
#: `make test` run them, `make quick` leaves them to the energy-power tests below)
PAIRS = list(itertools.combinations(PARTS, 2)) + [ALL]
RTOL = 1e-10


def _scene(hub, names):
    return Scene(HUBS[hub](), *(PARTS[n].make() for n in names))


def _random_state(scene, rng):
    model = scene.model()
    x = scene.state()
    q = rng.normal(size=4)
    x[0:4] = q / np.linalg.norm(q)
    x[4:7] = rng.normal(scale=0.1, size=3)
    for name, lay in model.layout.items():
        if name == "hub":
            continue
        n = lay.states.stop - lay.states.start
        x[lay.states] = x[lay.states] + rng.normal(scale=0.05, size=n)
        names = model.states[lay.coords]
        if len(names) >= 4 and [k.split("_")[0] for k in names[:4]] == ["p1", "p2", "p3", "p4"]:
            c = lay.coords.start  # a relative attitude quaternion: keep it a rotation
            x[c:c + 4] /= np.linalg.norm(x[c:c + 4])
    if scene.hub.translates:
        x[7:13] = rng.normal(scale=0.5, size=6)
    return x


def _conserved(names, hub):
    keys = set.intersection(*(set(PARTS[n].conserves) for n in names))
    if hub == "attitude":
        keys.discard("momentum_linear")
    return sorted(keys)


@pytest.mark.parametrize("hub", HUBS)
@pytest.mark.parametrize("names", PAIRS, ids=lambda p: "+".join(p) if len(p) < 3 else "all")
@pytest.mark.slow
def test_invariants_conserved_with_controls_off(hub, names):
    scene = _scene(hub, names)
    model = scene.model()
    keys = _conserved(names, hub)
    if not keys:
        pytest.skip("nothing conserved by this pair")
    x0 = _random_state(scene, np.random.default_rng(7))
    t = np.linspace(0.0, 100.0, 11)
    steps = max(PARTS[n].steps for n in names)
    res = simulate(model, x0, t, method="rk8", steps=steps, jit=False)
    assert res.success, res.message
    assert_conserved(model, res, keys)


def assert_conserved(model, res, keys):
    """Each invariant in ``keys`` constant along ``res`` to `RTOL` relative."""
    for key in keys:
        values = np.asarray(model.invariant(key, res.x)).reshape(-1, res.t.size)
        scale = max(float(np.max(np.abs(values))), 1e-300)
        drift = float(np.max(np.abs(values - values[:, :1]))) / scale
        assert drift < RTOL, f"{key} drifts by {drift:.2e} (relative) over {res.t[-1]} s"


def _named(scene, x):
    model = scene.model()
    s = dict(zip(model.states, x))
    s["__reference__"] = np.asarray(scene.hub.reference)
    s["__speeds__"] = {n: model.states[lay.speeds] for n, lay in model.layout.items()}
    return s


@pytest.mark.parametrize("hub", HUBS)
def test_energy_changes_at_the_power_of_the_controls(hub):
    names = tuple(n for n in ALL if PARTS[n].work is not None)
    scene = _scene(hub, names)
    model = scene.model()
    rng = np.random.default_rng(3)
    grad = model.invariants["energy"].jacobian()
    for _ in range(5):
        x = _random_state(scene, rng)
        u = rng.normal(size=model.nu)
        dE = float(np.asarray(grad(x, [], 0)[0]).reshape(-1) @ model.rhs(x, u))
        s = _named(scene, x)
        power = 0.0
        for pname, part_name in zip(names, scene.part_names):
            lay = model.layout[part_name]
            for prefix, velocity in PARTS[pname].work.items():
                power += float(np.dot(u[lay.controls], velocity(s, part_name)))
        dE0 = float(np.asarray(grad(x, [], 0)[0]).reshape(-1) @ model.rhs(x, np.zeros(model.nu)))
        assert abs(dE0) < 1e-12 * max(1.0, abs(power))
        assert abs(dE - power) <= 1e-10 * max(1.0, abs(power)), (dE, power)


# ------------------------------------------------------------------ parts on parts
#: the parts that can carry parts, and every part that can sit on one (fields cannot)
CARRIERS = ("panel", "ball_panel", "bending")
MOUNTABLE = tuple(n for n in PARTS if n != "tilt")
ON_PARTS = [(c, (n,)) for c in CARRIERS for n in MOUNTABLE] + [("panel", tuple(n for n in ALL if n in MOUNTABLE and n != "panel"))]


def _mounted_scene(hub, carrier, names):
    """The hub, a carrier (a panel, a bending mode), and ``names`` each on the carrier."""
    parts = [PARTS[carrier].make()]
    parts += [dataclasses.replace(PARTS[n].make(), parent=parts[0].kind) for n in names]
    return Scene(HUBS[hub](), *parts)


@pytest.mark.parametrize("hub", HUBS)
@pytest.mark.parametrize("carrier, names", ON_PARTS,
                         ids=lambda p: p if isinstance(p, str) else
                         ("+".join(p) if len(p) < 3 else "all"))
@pytest.mark.slow
def test_invariants_conserved_with_parts_on_a_panel(hub, carrier, names):
    scene = _mounted_scene(hub, carrier, names)
    model = scene.model()
    keys = _conserved((carrier,) + names, hub)
    x0 = _random_state(scene, np.random.default_rng(11))
    t = np.linspace(0.0, 100.0, 11)
    steps = max(PARTS[n].steps for n in (carrier,) + names)
    res = simulate(model, x0, t, method="rk8", steps=steps, jit=False)
    assert res.success, res.message
    assert_conserved(model, res, keys)


@pytest.mark.parametrize("hub", HUBS)
def test_energy_changes_at_the_power_of_controls_on_a_panel(hub):
    """Wheel motors on the panel work on the wheels' relative speeds; a body torque on the
    panel (panel axes) on the panel's absolute angular velocity ``R^T (w + theta_dot a)``."""
    panel = PARTS["panel"].make()
    scene = _mounted_scene(hub, "panel", ("wheels", "torque"))
    model = scene.model()
    grad = model.invariants["energy"].jacobian()
    rng = np.random.default_rng(5)
    a = np.asarray(panel.axis)
    for _ in range(5):
        x = _random_state(scene, rng)
        u = rng.normal(size=model.nu)
        s = dict(zip(model.states, x))
        R = dcm_from_axis_angle(a, s["theta"]).T  # panel -> hub
        w_panel = R.T @ (np.array([s["w1"], s["w2"], s["w3"]]) + s["theta_dot"] * a)
        wheels, torque = model.layout["wheels"], model.layout["torque"]
        power = float(u[wheels.controls] @ x[wheels.speeds] + u[torque.controls] @ w_panel)
        dE = float(np.asarray(grad(x, [], 0)[0]).reshape(-1) @ model.rhs(x, u))
        assert abs(dE - power) <= 1e-10 * max(1.0, abs(power)), (dE, power)
