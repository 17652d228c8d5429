"""Loads on the hub: `ExternalTorque` and `ExternalForce` (controls)."""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca

from ..validate import finite_array, one_of
from .contract import Contribution, Load, Part, PartVariables, Variable, bounds_from_u_max

__all__ = ["ExternalTorque", "ExternalForce", "vector_controls", "u_max_tuple"]


def u_max_tuple(u_max, n: int, name: str = "u_max"):
    """``u_max`` checked and stored as ``n`` positive floats (None stays None)."""
    return None if u_max is None else tuple(b[1] for b in bounds_from_u_max(u_max, n, name))


def vector_controls(prefix: str, unit: str, u_max) -> PartVariables:
    """Three controls ``prefix1..prefix3`` [unit] bounded by ``u_max``."""
    bounds = bounds_from_u_max(u_max, 3)
    return PartVariables(controls=tuple(Variable(f"{prefix}{i + 1}", unit, bounds=bounds[i])
                                        for i in range(3)))


@dataclass(frozen=True)
class ExternalTorque(Part):
    """A body torque on the hub, the controls ``L1..L3`` [N m] (hub axes).

    Parameters
    ----------
    u_max : float or array_like, shape (3,) [N m], optional
        Per-axis bound ``|L_i| <= u_max_i`` (unbounded by default).
    name : str, optional
    parent : str, optional
        The scene name of the part it sits on (default: the hub); its positions and axes
        are then that part's (`dynamics.scene.contract`, parts on parts).

    Examples
    --------
    >>> from appdyn.dynamics.scene import ExternalTorque, RigidHub, Scene
    >>> model = Scene(RigidHub([1.0, 2.0, 3.0]), ExternalTorque(u_max=1.0)).model()
    >>> model.controls, model.bounds["L3"]
    (('L1', 'L2', 'L3'), (-1.0, 1.0))
    >>> model.rhs([0, 0, 0, 1, 0, 0, 0], [1.0, 1.0, 1.0])[4:]  # I w' = L
    array([1.        , 0.5       , 0.33333333])
    """

    u_max: tuple | None = None
    name: str | None = None
    parent: str | None = None
    kind = "torque"

    def __post_init__(self):
        object.__setattr__(self, "u_max", u_max_tuple(self.u_max, 3))

    def variables(self) -> PartVariables:
        return vector_controls("L", "N m", self.u_max)

    def contribute(self, frame, own) -> Contribution:
        return Contribution(loads=[Load(own.controls, frame.w)])


@dataclass(frozen=True)
class ExternalForce(Part):
    """A force on the hub, the controls ``F1..F3`` [N], applied at a hub point.

    Parameters
    ----------
    point : array_like, shape (3,) [m], optional
        Where it acts, from the hub's mass centre (hub axes; default the mass centre).
    frame : {'body', 'inertial'}, optional
        The axes its components are given in.
    u_max : float or array_like, shape (3,) [N], optional
        Per-component bound.
    name : str, optional
    parent : str, optional
        The scene name of the part it sits on (default: the hub); its positions and axes
        are then that part's (`dynamics.scene.contract`, parts on parts).

    Notes
    -----
    On an attitude-only hub (whose reference point is fixed) only its moment about the
    reference acts; on a six-degree-of-freedom hub it also accelerates the vehicle.

    Examples
    --------
    >>> from appdyn.dynamics.scene import ExternalForce, RigidHub, Scene
    >>> model = Scene(RigidHub([1.0, 1.0, 1.0], mass=2.0), ExternalForce()).model()
    >>> x0 = Scene(RigidHub([1.0, 1.0, 1.0], mass=2.0)).state()
    >>> float(model.rhs(x0, [4.0, 0.0, 0.0])[model.states.index("v1")])  # m v' = F
    2.0
    """

    point: tuple = (0.0, 0.0, 0.0)
    frame: str = "body"
    u_max: tuple | None = None
    name: str | None = None
    parent: str | None = None
    kind = "force"

    def __post_init__(self):
        object.__setattr__(self, "point", tuple(finite_array(self.point, "point", (3,)).tolist()))
        object.__setattr__(self, "frame", one_of(self.frame, "frame", ("body", "inertial")))
        object.__setattr__(self, "u_max", u_max_tuple(self.u_max, 3))

    def variables(self) -> PartVariables:
        return vector_controls("F", "N", self.u_max)

    def contribute(self, frame, own) -> Contribution:
        F = own.controls if self.frame == "body" else ca.mtimes(frame.dcm, own.controls)
        return Contribution(loads=[Load(F, frame.velocity(frame.point(self.point)))])
