"""appdyn dynamics: models as named-I/O CasADi Functions, simulation, closed-form truths.

The public entry points are imported lazily so that importing one part (say, attitude
kinematics) does not pay for the others.
"""
from __future__ import annotations

import importlib

from . import attitude
from .model import Model
from .rigid_body import rigid_body

_LAZY = {
    "simulate": ("dynamics.simulate", "simulate"),
    "linearize": ("dynamics.linearize", "linearize"),
    "truth": ("dynamics.truth", None),
}

__all__ = ["Model", "attitude", "rigid_body", *_LAZY]


def __getattr__(name):
    if name in _LAZY:
        module, attr = _LAZY[name]
        mod = importlib.import_module(module)
        return mod if attr is None else getattr(mod, attr)
    raise AttributeError(f"module 'dynamics' has no attribute {name!r}")
