"""Example parts for the generated scene tests (the conservation matrix, build time).

Each entry: a factory of the part (conservative: no damping), the invariants it leaves
conserved when every control is zero, and for each control block the velocity it does work
on (the energy-work balance ``E' = sum u . v_u``), as a function of the named state.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from appdyn.dynamics import scene as sc
from appdyn.dynamics.launch_vehicle import Actuator

AXES = np.array([[1.0, 0.0, 0.0, 0.57735026918962573],
                 [0.0, 1.0, 0.0, 0.57735026918962573],
                 [0.0, 0.0, 1.0, 0.57735026918962573]])
I_HUB = np.array([[10.0, 1.2, -0.8], [1.2, 12.0, 0.6], [-0.8, 0.6, 8.0]])
MOMENTA = ("momentum_inertial", "momentum_linear")
_B = np.deg2rad(54.74)
#: the four-CMG pyramid (DESIGN.md truth catalogue): gimbal axes and spin axes at zero angles
PYRAMID_G = np.array([[np.sin(_B), 0.0, -np.sin(_B), 0.0], [0.0, np.sin(_B), 0.0, -np.sin(_B)],
                      [np.cos(_B)] * 4])
PYRAMID_S = np.array([[0.0, -1.0, 0.0, 1.0], [1.0, 0.0, -1.0, 0.0], [0.0, 0.0, 0.0, 0.0]])


@dataclass
class Entry:
    """One example part: ``make()``, what it conserves, and its controls' work velocities."""

    make: Callable
    conserves: tuple = ("energy",) + MOMENTA
    #: control prefix -> f(state dict, part name) -> (n,); None: the controls prescribe a
    #: motion (a rate-driven gimbal), so there is no energy-work law of the form u . v
    work: dict | None = field(default_factory=dict)
    #: rk8 steps per 10 s over the 100 s run (the scene takes the most of its parts')
    steps: int = 1000


def _point_velocity(point):
    def velocity(s, name):
        w = np.array([s["w1"], s["w2"], s["w3"]])
        v = np.array([s.get("v1", 0.0), s.get("v2", 0.0), s.get("v3", 0.0)])
        return v + np.cross(w, np.asarray(point) - s["__reference__"])
    return velocity


#: the parts of the scene with all of them (the pendulum slosh only in pairs: see its entry)
PARTS: dict[str, Entry] = {
    "wheels": Entry(lambda: sc.ReactionWheels(AXES, [0.05, 0.04, 0.06, 0.03]),
                    work={"tau": lambda s, n: np.array([s[k] for k in s["__speeds__"][n]])}),
    "rotor": Entry(lambda: sc.HeldRotor([0.3, -0.5, 0.8], 2.5)),
    "torque": Entry(lambda: sc.ExternalTorque(), conserves=("energy", "momentum_linear"),
                    work={"L": lambda s, n: np.array([s["w1"], s["w2"], s["w3"]])}),
    "damper": Entry(lambda: sc.PointMassDamper(mass=2.0, stiffness=50.0, damping=0.0,
                                               position=(0.5, 0.2, -0.1),
                                               direction=(0.0, 0.6, 0.8))),
    "core": Entry(lambda: sc.SphericalDamper(inertia=0.4, damping=0.0)),
    # the pendulum's two angles are singular 90 degrees from rest (theta2 = +-pi/2): in the
    # scene with every part, free of any restoring field, it wanders there within 100 s
    "slosh": Entry(lambda: sc.Slosh(3.0, length=0.4, hinge=(0.1, -0.3, 0.6),
                                    direction=(0.0, 0.0, -1.0)), steps=4000),
    "slosh_spring": Entry(lambda: sc.Slosh(1.5, kind="spring", frequency=2.0,
                                           position=(-0.3, 0.2, 0.4),
                                           direction=(1.0, 0.0, 0.0))),
    "panel": Entry(lambda: sc.HingedPanel(4.0, [0.8, 0.3, 0.6], [0.0, 0.6, 0.1],
                                          [0.0, 0.7, 0.0], axis=[1.0, 0.0, 0.0],
                                          stiffness=6.0)),
    "ball_panel": Entry(lambda: sc.HingedPanel(3.0, [0.5, 0.2, 0.4], [0.0, -0.6, 0.0],
                                               [0.1, -0.5, 0.0], stiffness=4.0)),
    "cmgs": Entry(lambda: sc.CMGCluster(PYRAMID_G, PYRAMID_S, [1.0, 1.2, 0.9, 1.1],
                                        rotor_inertia=0.01, gimbal_inertia=0.004), work=None),
    "cmgs_torque": Entry(lambda: sc.CMGCluster(PYRAMID_G[:, :2], PYRAMID_S[:, :2], [1.0, 0.8],
                                               rotor_inertia=0.01, gimbal_inertia=0.004,
                                               drive="torque"),
                         steps=2000,  # on a ball-jointed panel: 5e-10 at 1000, 3e-13 at 2000
                         work={"tg": lambda s, n: np.array([s[k] for k in s["__speeds__"][n]])}),
    "tilt": Entry(lambda: sc.TiltTorque(3.0, axis=(0.0, 0.0, 1.0), direction=(0.0, 0.0, 1.0)),
                  conserves=("energy", "momentum_linear")),
    "flexible": Entry(lambda: sc.FlexibleAppendage(2.0, 0.5, (0.5, 0.8), root=(0.3, -0.4, 0.2),
                                                   direction=(0.6, 0.0, 0.8), modes=1,
                                                   tip_mass=0.2)),
    "force": Entry(lambda: sc.ExternalForce(point=[0.2, 0.4, -0.3]), conserves=("energy",),
                   work={"F": _point_velocity([0.2, 0.4, -0.3])}),
    # a mean-axes bending mode, undamped (it carries parts at its station: a carrier)
    "bending": Entry(lambda: sc.BendingMode(2.0, 3.0, station=(-0.5, 0.1, 0.0), deflection=0.6,
                                            slope=0.4, sensor_slope=0.2)),
    # engine off (no thrust, no mass flow): its gimbal actuator states move, nothing else
    "engine": Entry(lambda: sc.Engine(0.0, (-0.5, 0.1, 0.0), gimbal=0.1,
                                      actuator=Actuator(0.2, rate_limit=1.0)),
                    work={"dp_c": lambda s, n: np.zeros(2)}),
}

ALL = tuple(name for name in PARTS if name != "slosh")
