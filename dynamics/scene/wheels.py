"""Rotors on the hub: `ReactionWheels` (driven by motor torques) and `HeldRotor` (the
gyrostat's wheel at constant relative speed). Seed Sec. 4.7, Eqs. 4.147-4.148.

A wheel ``i`` turns about the unit hub axis ``a_i`` at ``W_i`` relative to the hub, with
axial moment ``J_i``: absolute angular velocity ``w + W_i a_i`` and, as only its axial moment
is left out of the hub's inertia, angular momentum ``J_i (a_i.w + W_i) a_i``. The motor
torque ``tau_i a_i`` acts on the wheel and ``-tau_i a_i`` on the hub: it does work on the
relative rate ``W_i a_i``. For fields (`GravityGradient`) a wheel's body carries its axial
inertia ``J_i a_i a_i^T`` (the rest is the hub's).
"""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from ..validate import finite_scalar, positive_each, unit_axes, unit_vector
from .contract import Body, Contribution, Load, Part, PartVariables, Variable, bounds_from_u_max
from .loads import u_max_tuple

__all__ = ["ReactionWheels", "HeldRotor"]


@dataclass(frozen=True)
class ReactionWheels(Part):
    """``n`` reaction wheels: states ``W1..Wn`` [rad/s], controls ``tau1..taun`` [N m].

    Parameters
    ----------
    axes : array_like, shape (3, n), or (3,) for one wheel
        Unit spin axes ``a_i`` in hub axes, one per column.
    inertia : float or array_like, shape (n,) [kg m^2]
        Axial moments ``J_i > 0``. The wheels' masses and transverse moments belong to the
        hub's inertia (`RigidHub`), their axial moments not.
    u_max : float or array_like, shape (n,) [N m], optional
        Motor-torque bound.
    speed_max : float or array_like, shape (n,) [rad/s], optional
        Wheel-speed bound (relative to the hub), carried as a state bound.
    name : str, optional
    parent : str, optional
        The scene name of the part it sits on (default: the hub); its positions and axes
        are then that part's (`dynamics.scene.contract`, parts on parts).

    Notes
    -----
    Invariant ``wheel_momentum`` [N m s], shape (n,): each wheel's absolute axial momentum
    ``J_i (a_i.w + W_i)``. With the motors on, the energy changes at ``sum_i tau_i W_i``.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.scene import ReactionWheels, RigidHub, Scene
    >>> model = Scene(RigidHub([10.0, 12.0, 8.0]), ReactionWheels(np.eye(3), 0.05)).model()
    >>> np.round(model.rhs([0, 0, 0, 1, 0, 0, 0, 0, 0, 0], [0.01, 0, 0])[[4, 7]], 12)
    array([-0.001,  0.201])
    """

    axes: tuple
    inertia: tuple
    u_max: tuple | None = None
    speed_max: tuple | None = None
    name: str | None = None
    parent: str | None = None
    kind = "wheels"

    def __post_init__(self):
        A = unit_axes(self.axes, "axes")
        n = A.shape[1]
        object.__setattr__(self, "axes", tuple(map(tuple, A.tolist())))
        object.__setattr__(self, "inertia", tuple(positive_each(self.inertia, "inertia", n).tolist()))
        for key in ("u_max", "speed_max"):
            object.__setattr__(self, key, u_max_tuple(getattr(self, key), n, key))

    @property
    def axes_matrix(self) -> np.ndarray:
        """The unit axes, shape (3, n)."""
        return np.array(self.axes)

    @property
    def n(self) -> int:
        """Number of wheels."""
        return len(self.inertia)

    def variables(self) -> PartVariables:
        ub = bounds_from_u_max(self.u_max, self.n)
        sb = bounds_from_u_max(self.speed_max, self.n, "speed_max")
        return PartVariables(
            speeds=tuple(Variable(f"W{i + 1}", "rad/s", bounds=sb[i], terminal="free")
                         for i in range(self.n)),
            controls=tuple(Variable(f"tau{i + 1}", "N m", bounds=ub[i]) for i in range(self.n)))

    def contribute(self, frame, own) -> Contribution:
        A = self.axes_matrix
        bodies, loads, absolute = [], [], []
        for i, J in enumerate(self.inertia):
            a = ca.DM(A[:, i])
            spin = ca.dot(a, frame.w) + own.speeds[i]
            absolute.append(J * spin)
            bodies.append(Body(velocity=ca.SX.zeros(3), angular_velocity=frame.w + own.speeds[i] * a,
                               momentum=ca.SX.zeros(3), angular_momentum=J * spin * a,
                               position=ca.SX.zeros(3), inertia=J * ca.mtimes(a, a.T)))
            loads.append(Load(own.controls[i], own.speeds[i]))
        return Contribution(bodies=bodies, loads=loads,
                            invariants={"wheel_momentum": ca.vertcat(*absolute)})


@dataclass(frozen=True)
class HeldRotor(Part):
    """A rotor held at constant speed relative to the hub (the gyrostat's wheel): no states.

    Its relative angular momentum ``momentum * axis`` is constant in hub axes (the motor
    supplies whatever torque holds the speed); the hub's inertia includes the rotor as if
    locked. Euler's law becomes ``I w' = L - w x (I w + h a)`` (seed Sec. 4.7).

    Parameters
    ----------
    axis : array_like, shape (3,)
        Spin axis in hub axes (normalized).
    momentum : float [N m s]
        Relative angular momentum ``h`` (either sign).
    name : str, optional
    parent : str, optional
        The scene name of the part it sits on (default: the hub); its positions and axes
        are then that part's (`dynamics.scene.contract`, parts on parts).

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.scene import HeldRotor, RigidHub, Scene
    >>> model = Scene(RigidHub([1.0, 2.0, 3.0]), HeldRotor([1, 0, 0], 2.0)).model()
    >>> model.rhs([0, 0, 0, 1, 0, 0, 1.0])[4:7] + 0.0  # I w' = -w x (I w + h a) = (0, -2, 0)
    array([ 0., -1.,  0.])
    """

    axis: tuple
    momentum: float
    name: str | None = None
    parent: str | None = None
    kind = "rotor"

    def __post_init__(self):
        object.__setattr__(self, "axis", tuple(unit_vector(self.axis, "axis").tolist()))
        object.__setattr__(self, "momentum", finite_scalar(self.momentum, "momentum"))

    def contribute(self, frame, own) -> Contribution:
        h = self.momentum * ca.DM(self.axis)
        body = Body(velocity=ca.SX.zeros(3), angular_velocity=frame.w, momentum=ca.SX.zeros(3),
                    angular_momentum=ca.SX(h), position=ca.SX.zeros(3))
        return Contribution(bodies=[body], kinetic=0.0)
