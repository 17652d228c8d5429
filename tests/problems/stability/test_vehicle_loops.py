"""`stability.vehicle_loops` on the six-degree-of-freedom launch vehicle scene against the
planar case `stability.launch_vehicle` (an independent model and reduction): each axis's
margins and closed-loop eigenvalues, rigid, with air, with the actuator, with mass flow, with
slosh and with the body bending mode (the engine on it, the gyros on its slope)."""
import math

import numpy as np
import pytest

from appdyn.dynamics.launch_vehicle import Actuator, Aero, Bending, MassFlow, Slosh
from appdyn.dynamics.scene import ExternalTorque, RigidHub, Scene, launch_vehicle_scene
from appdyn.problems import stability

F, I, L, M = 2.0e6, 4.0e7, 20.0, 1.0e5
CASES = {
    "rigid": dict(),
    "aero": dict(aero=Aero(3.0e4, 10.0, 3.0, 5.0), velocity=400.0),
    "actuator": dict(actuator=Actuator(0.05)),
    "mass_flow": dict(mass_flow=MassFlow(rate=700.0, flow_start=-5.0)),
    "aero_actuator": dict(aero=Aero(3.0e4, 10.0, 3.0, -2.0), velocity=300.0,
                          actuator=Actuator(0.08)),
    "slosh": dict(slosh=Slosh(8.0e3, 6.0, length=2.5, damping_ratio=0.03)),
    "slosh_flow_actuator": dict(slosh=Slosh(5.0e3, -3.0, length=1.5),
                                mass_flow=MassFlow(rate=700.0, flow_start=-5.0),
                                actuator=Actuator(0.05)),
    # the gyros on the mode's slope drive it unstable (no bending filter); at a node, stable
    "bending": dict(bending=Bending(12.0, 5.0e3, damping_ratio=0.02, slope_sensor=0.03,
                                    deflection_gimbal=1.4, slope_gimbal=-0.05)),
    "bending_sensor_at_a_node": dict(bending=Bending(12.0, 5.0e3, damping_ratio=0.02,
                                                     deflection_gimbal=1.4, slope_gimbal=-0.05)),
    "bending_aero_actuator": dict(bending=Bending(12.0, 5.0e3, damping_ratio=0.02,
                                                  slope_sensor=0.03, deflection_gimbal=1.4,
                                                  slope_gimbal=-0.05),
                                  aero=Aero(3.0e4, 10.0, 3.0, -2.0), velocity=300.0,
                                  actuator=Actuator(0.05)),
}


def _margins(m):
    return np.array([m.gain_margin, m.phase_margin, m.gain_crossover, m.phase_crossover])


@pytest.mark.parametrize("case", CASES)
def test_each_axis_equals_the_planar_autopilot_loop(case):
    kw = CASES[case]
    gains = dict(k_psi=2.0, k_psidot=1.2)
    planar = stability.launch_vehicle(thrust=F, inertia=I, arm=L, mass=M, **gains, **kw)
    scene = launch_vehicle_scene(thrust=F, inertia=I, arm=L, mass=M, **kw)
    loops = stability.vehicle_loops(scene, velocity=kw.get("velocity", 0.0), **gains)
    expected = np.asarray(planar.eigenvalues, complex)
    for axis in ("pitch", "yaw"):
        rep = loops[axis]
        assert rep.verdict == planar.verdict
        ref, got = _margins(planar.margins), _margins(rep.margins)
        same = np.isclose(got, ref, rtol=1e-8, atol=0.0) | (np.isnan(ref) & np.isnan(got)) | (
            np.isinf(ref) & np.isinf(got))
        assert np.all(same), (axis, got, ref)
        # both axes' loops are closed: each planar eigenvalue appears twice
        eig = list(np.asarray(rep.eigenvalues, complex))
        assert len(eig) == 2 * len(expected)
        scale = np.max(np.abs(expected))
        for e in np.concatenate([expected, expected]):
            k = int(np.argmin(np.abs(np.array(eig) - e)))
            assert abs(eig[k] - e) <= 1e-8 * scale, (e, eig)
            eig.pop(k)


def test_rigid_closed_form_and_the_notes():
    scene = launch_vehicle_scene(thrust=F, inertia=I, arm=L, mass=M)
    rep = stability.vehicle_loops(scene, k_psi=2.0, k_psidot=2.0)["pitch"]
    wn = math.sqrt(F * L * 2.0 / I)  # I s^2 + F l k_psidot s + F l k_psi = 0
    assert np.allclose(np.abs(rep.eigenvalues), wn, rtol=1e-12)
    held = rep.notes[-1].split("(frozen): ")[1].split(";")[0].split(", ")
    assert sorted(held) == sorted(["q1", "q4", "w1", "r1", "r2", "r3", "v1", "v2", "v3"])
    assert rep.ss.state_labels == ["q2", "q3", "w2", "w3"]


def test_vehicle_loops_arguments():
    scene = launch_vehicle_scene(thrust=F, inertia=I, arm=L, mass=M)
    with pytest.raises(TypeError, match="scene"):
        stability.vehicle_loops("vehicle", k_psi=1.0, k_psidot=1.0)
    with pytest.raises(ValueError, match="six-degree-of-freedom"):
        stability.vehicle_loops(Scene(RigidHub([1.0, 2.0, 3.0]), ExternalTorque()), k_psi=1.0,
                                k_psidot=1.0)
    with pytest.raises(ValueError, match="k_psi"):
        stability.vehicle_loops(scene, k_psi=math.nan, k_psidot=1.0)
    with pytest.raises(ValueError, match="engine"):
        stability.vehicle_loops(scene, k_psi=1.0, k_psidot=1.0, engine="booster")
    with pytest.raises(ValueError, match="velocity"):
        stability.vehicle_loops(scene, k_psi=1.0, k_psidot=1.0, velocity=-3.0)


def test_docstring_examples():
    import doctest
    import importlib

    mod = importlib.import_module("appdyn.problems.stability.vehicle_loops")
    result = doctest.testmod(mod, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.failed == 0 and result.attempted > 0
