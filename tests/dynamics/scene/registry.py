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

AXES = np.array([[1.0, 0.0, 0.0, 0.57735026918962573],
                 [0.0, 1.0, 0.0, 0.57735026918962573],
                 [0.0, 0.0, 1.0, 0.57735026918962573]])
I_HUB = np.array([[10.0, 1.2, -0.8], [1.2, 12.0, 0.6], [-0.8, 0.6, 8.0]])
MOMENTA = ("momentum_inertial", "momentum_linear")


@dataclass
class Entry:
    """One example part: ``make()``, what it conserves, and its controls' work velocities."""

    make: Callable
    conserves: tuple = ("energy",) + MOMENTA
    work: dict = field(default_factory=dict)  # control prefix -> f(state dict, part name) -> (n,)


def _point_velocity(point):
    def velocity(s, name):
        w = np.array([s["w1"], s["w2"], s["w3"]])
        v = np.array([s.get("v1", 0.0), s.get("v2", 0.0), s.get("v3", 0.0)])
        return v + np.cross(w, np.asarray(point) - s["__reference__"])
    return velocity


PARTS: dict[str, Entry] = {
    "wheels": Entry(lambda: sc.ReactionWheels(AXES, [0.05, 0.04, 0.06, 0.03]),
                    work={"tau": lambda s, n: np.array([s[k] for k in s["__speeds__"][n]])}),
    "rotor": Entry(lambda: sc.HeldRotor([0.3, -0.5, 0.8], 2.5)),
    "torque": Entry(lambda: sc.ExternalTorque(), conserves=("energy", "momentum_linear"),
                    work={"L": lambda s, n: np.array([s["w1"], s["w2"], s["w3"]])}),
    "force": Entry(lambda: sc.ExternalForce(point=[0.2, 0.4, -0.3]), conserves=("energy",),
                   work={"F": _point_velocity([0.2, 0.4, -0.3])}),
}
