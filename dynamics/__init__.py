"""appdyn dynamics: models as named-I/O CasADi Functions, simulation, closed-form truths.

Entry points: `Model`, `rigid_body`, `simulate`, `linearize` (exact linearization about
equilibria and steady spins, as a python-control StateSpace), and the modules `attitude`
(kinematics) and `truth` (closed forms, imported on first use).
"""
from __future__ import annotations

import importlib

from . import attitude
from .model import Model
from .rigid_body import rigid_body
from .linearize import Linearization, linearization, linearize
from .simulate import SimulationResult, simulate

__all__ = ["Linearization", "Model", "SimulationResult", "attitude", "linearization",
           "linearize", "rigid_body", "simulate", "truth"]


def __getattr__(name):
    if name == "truth":
        return importlib.import_module("dynamics.truth")
    raise AttributeError(f"module 'dynamics' has no attribute {name!r}")
