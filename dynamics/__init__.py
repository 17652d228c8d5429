"""appdyn dynamics: models as named-I/O CasADi Functions, simulation, closed-form truths.

Entry points: `Model`, `rigid_body`, `wheel_spacecraft` and `cmg_spacecraft` (momentum-exchange
devices; cluster analysis and steering laws in `dynamics.momentum`), `launch_vehicle` (the
thrust-vectored vehicle in the yaw plane with opt-in aero, mass flow, slosh, bending, actuator
and autopilot; parts in `dynamics.launch_vehicle`), `hinged_bodies` (two rigid
bodies joined by a ball or revolute hinge, held by Lagrange multipliers), `closed_loop` (a
state-feedback law closed around any model), `simulate` (with `SimulationResult`, `METHODS`, `Event` and `Impact`;
internals in the subpackage `dynamics.integrate`), `linearize` (exact linearization about
equilibria and steady spins, as a python-control StateSpace), `clear_caches` (empties the one
cache of built and compiled Functions, `dynamics.cache`), and the modules `attitude`
(kinematics), `constrained` (the multiplier machinery: accelerations, multipliers, reaction
forces, Baumgarte stabilization and projection), `mechanisms` (the seed's worked systems with
their closed forms), `clock` (time-dependent models carry a clock state ``"t"``), `mass`
(parallel and rotated axes, radius of gyration, specific impulse and the rocket equation), `floquet`
(monodromy matrix and multipliers of periodic motion) and `truth` (closed forms).

Only `Model`, `rigid_body`, `launch_vehicle`, `linearize` and the cache are imported with the
package; every other name is imported on first use, so ``import appdyn.dynamics`` costs little
beyond casadi and numpy.
"""
from __future__ import annotations

import importlib

from . import cache
# `launch_vehicle`, `linearize` and `rigid_body` are both a submodule and a function: bound
# here, before anything imports the submodule (which would bind the module under the name)
from .launch_vehicle import launch_vehicle
from .linearize import Linearization, linearization, linearize
from .model import Model
from .rigid_body import rigid_body

# every other public name, imported on first use (PEP 562): name -> (module, attribute or
# None for the module itself); ``import appdyn.dynamics`` then stays cheap
_LAZY = {
    "attitude": (".attitude", None), "clock": (".clock", None),
    "constrained": (".constrained", None), "floquet": (".floquet", None),
    "mass": (".mass", None), "mechanisms": (".mechanisms", None),
    "momentum": (".momentum", None), "truth": (".truth", None),
    "closed_loop": (".feedback", "closed_loop"), "hinged_bodies": (".hinged", "hinged_bodies"),
    "cmg_spacecraft": (".momentum", "cmg_spacecraft"),
    "wheel_spacecraft": (".momentum", "wheel_spacecraft"),
    **{name: (".integrate", name) for name in ("METHODS", "BatchResult", "Event", "Impact",
                                              "ImpactRecord", "SimulationResult", "simulate")},
}

__all__ = ["METHODS", "BatchResult", "Event", "Impact", "ImpactRecord", "Linearization", "Model", "SimulationResult", "attitude", "clear_caches",
           "clock", "closed_loop", "cmg_spacecraft", "constrained", "floquet", "hinged_bodies",
           "launch_vehicle", "linearization", "linearize", "mass", "mechanisms", "momentum", "rigid_body", "simulate", "truth",
           "wheel_spacecraft"]

def clear_caches() -> None:
    """Empty every cache of built and compiled CasADi Functions, jit files included.

    Models, integration loops, Jacobians and compiled C code are all kept in
    `dynamics.cache`; after this call they are rebuilt (and recompiled) on next use.

    Examples
    --------
    >>> from appdyn.dynamics import clear_caches, rigid_body
    >>> model = rigid_body([1.0, 2.0, 3.0])
    >>> rigid_body([1.0, 2.0, 3.0]) is model  # built once, cached by inertia
    True
    >>> clear_caches()
    >>> rigid_body([1.0, 2.0, 3.0]) is model  # rebuilt
    False
    """
    cache.clear()


def __getattr__(name):
    if name not in _LAZY:
        raise AttributeError(f"module 'appdyn.dynamics' has no attribute {name!r}")
    module, attribute = _LAZY[name]
    value = importlib.import_module(module, __name__)
    if attribute is not None:
        value = getattr(value, attribute)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))
