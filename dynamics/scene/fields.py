"""Direction-dependent torques on the hub: `TiltTorque` (the heavy top's gravity, the
spinning projectile's aerodynamic overturning moment, a rotor's elastic bearings).

Rheinfurth & Wilson, NASA RP-1262, Sec. 4.6, Method III and its Examples 1-3.
"""
from __future__ import annotations

from dataclasses import KW_ONLY, dataclass

import casadi as ca

from .contract import Contribution, Load, Part
from .dampers import real_number, unit_vector

__all__ = ["TiltTorque", "tilt_load"]


def tilt_load(frame, kappa: float, axis, direction, damping: float):
    """The tilt torque on the hub and its potential.

    With ``a`` the hub axis, ``n = A(q) d`` the inertially fixed unit direction ``d`` in hub
    axes, ``M = n a^T - (a.n) E`` (so that ``M w`` is the tilt vector ``a x n``'s rate seen
    in the hub):

        L = -kappa a x n - D M^T M w,        V = kappa a.n.

    Parameters
    ----------
    frame : Frame
    kappa : float [N m]
    axis, direction : tuple, shape (3,)
        Unit vectors ``a`` (hub axes) and ``d`` (inertial axes).
    damping : float [N m s]
        ``D``.

    Returns
    -------
    torque : SX, 3x1 [N m]
    potential : SX [J]
    """
    a, d = ca.DM(axis), ca.DM(direction)
    n = ca.mtimes(frame.dcm, d)
    M = ca.mtimes(n, a.T) - ca.dot(a, n) * ca.DM.eye(3)
    torque = -kappa * ca.cross(a, n) - damping * ca.mtimes(M.T, ca.mtimes(M, frame.w))
    return torque, kappa * ca.dot(a, n)


@dataclass(frozen=True)
class TiltTorque(Part):
    """A torque that depends only on the tilt of a hub axis from an inertial direction.

    ``L = -kappa a x n - D M^T M w`` (`tilt_load`): ``-kappa a x n`` derives from the
    potential ``V = kappa a.n`` (``n = A(q) d``); for the heavy top (``a`` from the pivot to
    the mass centre at ``l``, ``d`` up) ``kappa = m g l``, for the spinning projectile
    ``kappa = q S C_N_alpha l``, for a rotor in bearings of stiffness ``k`` at ``+/- l``
    ``kappa = -2 k l^2``. ``-D M^T M w`` is internal (rotating) damping from the Rayleigh
    function ``D |tau'|^2 / 2`` of the tilt vector ``tau = a x n``, power ``-D |M w|^2``.
    Place the hub's reference at the pivot (an attitude-only `RigidHub` whose inertia is
    about the pivot). No states or controls.

    Parameters
    ----------
    overturning : float [N m]
        ``kappa``: positive tips the axis away from ``d``, negative restores it.
    axis : array_like, shape (3,), optional
        Hub axis ``a`` (normalized; default e1).
    direction : array_like, shape (3,), optional
        Inertial direction ``d`` (normalized; default x).
    internal_damping : float [N m s], optional
        ``D >= 0``.
    name : str, optional

    Examples
    --------
    >>> from appdyn.dynamics.scene import RigidHub, Scene, TiltTorque
    >>> model = Scene(RigidHub([2.0, 3.0, 3.0]), TiltTorque(6.0, axis=(0, 0, 1))).model()
    >>> model.rhs([0, 0, 0, 1, 0, 0, 0])[4:7] + 0.0  # L = -6 e3 x e1 = -6 e2
    array([ 0., -2.,  0.])
    >>> float(model.invariant("energy", [0, 0, 0, 1, 0, 0, 0]))  # kappa a.n = 0
    0.0
    """

    overturning: float
    _: KW_ONLY
    axis: tuple = (1.0, 0.0, 0.0)
    direction: tuple = (1.0, 0.0, 0.0)
    internal_damping: float = 0.0
    name: str | None = None
    kind = "tilt"
    mountable = False

    def __post_init__(self):
        object.__setattr__(self, "overturning", real_number(self.overturning, "overturning"))
        object.__setattr__(self, "axis", tuple(unit_vector(self.axis, "axis").tolist()))
        object.__setattr__(self, "direction",
                           tuple(unit_vector(self.direction, "direction").tolist()))
        object.__setattr__(self, "internal_damping", real_number(
            self.internal_damping, "internal_damping", nonnegative=True))

    def contribute(self, frame, own) -> Contribution:
        torque, potential = tilt_load(frame, self.overturning, self.axis, self.direction,
                                      self.internal_damping)
        return Contribution(loads=[Load(torque, frame.w)], potential=potential)
