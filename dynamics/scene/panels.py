"""A rigid appendage on a hinge: `HingedPanel` (revolute or ball), in minimal coordinates.

The panel is a rigid body (mass ``m``, inertia ``I`` about its mass centre in panel axes)
hinged to the hub at ``hinge_point`` (hub axes, from the hub's mass centre); its mass centre
is ``cm_offset`` from the hinge in panel axes, which equal the hub's at zero hinge angle.
With ``R`` the panel -> hub rotation (components), the scene sees the body::

    position  rho = hinge_point + R cm_offset            (from the hub's mass centre)
    velocity  v + w x rho + w_rel x (R cm_offset)        (hub axes)
    angular velocity   w + w_rel,     inertia  R I R^T   (hub axes)

with ``w_rel`` the panel's rate relative to the hub in hub axes. The assembly differentiates
these (Kane's method), so no hinge force or multiplier appears; the two-body multiplier
formulation `dynamics.hinged_bodies` is the independent check (tests).

Revolute (``axis`` ``a``, a unit hub-axis vector): coordinate ``theta`` [rad], speed
``theta_dot`` [rad/s], ``R = E cos theta + (1 - cos theta) a a^T + sin theta [a x]`` (the
transpose of seed Eq. 4.45 for the angle ``theta`` about ``a``), ``w_rel = theta_dot a``;
spring and damper ``-k theta - c theta_dot`` on ``theta``, potential ``1/2 k theta^2``.

Ball (no ``axis``): coordinates ``p1..p4``, the relative attitude quaternion (scalar-last,
hub -> panel: ``A(p)`` maps hub components to panel components, ``R = A(p)^T``), speeds
``u1..u3``, the relative rate in *panel* axes (``w_rel = R u``), so that
``p' = -1/2 Wbar(u) p`` is seed Eq. 4.70 with the hub in the role of the inertial frame.
The spring derives from the potential::

    V = 2 k (1 - p4^2) = k (1 - cos phi)     (phi the relative rotation angle)

whose rate along Eq. 4.70 is ``dV/dt = 2 k p4 (p1..p3).u`` for any ``p``: the torque on the
panel, panel axes, is ``-2 k p4 (p1, p2, p3) = -k sin(phi) e`` (``e`` the rotation axis), a
linear spring ``-k phi e`` for small angles, as the revolute one. The damper torque is
``-c u``. Both act on the relative rate (their reactions on the hub follow).
"""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from ..attitude import dcm_from_axis_angle, dcm_from_quat, quat_rate
from ..validate import check_inertia, finite_array, nonnegative, positive, unit_axes
from .contract import Body, Contribution, Load, Part, PartVariables, Variable

__all__ = ["HingedPanel"]


@dataclass(frozen=True, init=False)
class HingedPanel(Part):
    """A rigid panel on a revolute (``axis``) or ball hinge, with a hinge spring and damper.

    Parameters
    ----------
    mass : float [kg]
        Panel mass, > 0.
    inertia : array_like, shape (3, 3) or (3,) [kg m^2]
        About the panel's mass centre, panel axes (products with the seed's sign).
    hinge_point : array_like, shape (3,) [m]
        The hinge from the hub's mass centre, hub axes (on a ``parent`` panel: from its
        hinge, in its axes).
    cm_offset : array_like, shape (3,) [m]
        The panel's mass centre from the hinge, panel axes (= hub axes at zero hinge angle).
    axis : array_like, shape (3,), optional
        Unit hinge axis (hub axes; the same components in panel axes): a revolute hinge with
        states ``theta`` [rad], ``theta_dot`` [rad/s]. Without it, a ball hinge with states
        ``p1..p4`` (relative quaternion, scalar-last, hub -> panel) and ``u1..u3`` (relative
        rate, panel axes [rad/s]).
    stiffness : float, optional
        Hinge spring ``k >= 0`` [N m/rad]: torque ``-k theta`` (revolute) or
        ``-2 k p4 (p1, p2, p3)`` (ball; module docstring).
    damping : float, optional
        Hinge damper ``c >= 0`` [N m s/rad]: torque ``-c theta_dot`` or ``-c u``.
    name : str, optional
    parent : str, optional
        The scene name of the part it sits on (default: the hub); its positions and axes
        are then that part's (`dynamics.scene.contract`, parts on parts).

    Notes
    -----
    The potential energy (``1/2 k theta^2``, ``2 k (1 - p4^2)``) is part of the scene's
    ``energy``, which is conserved without damping and loads. A ball panel adds the
    invariant ``panel_quat_norm`` (``|p|``, 1 up to the integration error; with the suffix of
    its state names, ``panel_quat_norm_2``, for a second one). Coordinates are
    held at rest (zero angle) by a slew's terminal condition only with a spring; without one
    any angle is an equilibrium and they are left free.

    Examples
    --------
    A panel on a hub turning about the hinge line: the hinge spring pulls a deflected panel
    back (``theta_dot' < 0`` for ``theta > 0``):

    >>> import numpy as np
    >>> from appdyn.dynamics.scene import HingedPanel, RigidHub, Scene
    >>> scene = Scene(RigidHub([10.0, 12.0, 8.0]),
    ...               HingedPanel(2.0, [0.5, 0.1, 0.5], hinge_point=[0.0, 0.6, 0.0],
    ...                           cm_offset=[0.0, 0.5, 0.0], axis=[1.0, 0.0, 0.0],
    ...                           stiffness=3.0))
    >>> scene.model().states[7:]
    ('theta', 'theta_dot')
    >>> x = scene.state(theta=0.1)
    >>> bool(scene.model().rhs(x)[8] < 0)
    True
    >>> Scene(RigidHub([10.0, 12.0, 8.0]), HingedPanel(2.0, [0.5, 0.1, 0.5], [0.0, 0.6, 0.0],
    ...                                                 [0.0, 0.5, 0.0])).model().states[7:]
    ('p1', 'p2', 'p3', 'p4', 'u1', 'u2', 'u3')
    """

    mass: float
    inertia: tuple
    hinge_point: tuple
    cm_offset: tuple
    axis: tuple | None
    stiffness: float
    damping: float
    name: str | None
    parent: str | None
    kind = "panel"
    carries_parts = True

    def __init__(self, mass, inertia, hinge_point, cm_offset, *, axis=None, stiffness=0.0,
                 damping=0.0, name=None, parent=None):
        if isinstance(inertia, tuple) and len(inertia) == 9:  # a copy (dataclasses.replace)
            inertia = np.reshape(inertia, (3, 3))
        I = check_inertia(inertia)
        fields = {
            "mass": positive(mass, "mass"),
            "inertia": tuple(np.asarray(I, float).reshape(-1).tolist()),
            "hinge_point": tuple(finite_array(hinge_point, "hinge_point", (3,)).tolist()),
            "cm_offset": tuple(finite_array(cm_offset, "cm_offset", (3,)).tolist()),
            "axis": None if axis is None else tuple(unit_axes(axis, "axis", n=1)[:, 0].tolist()),
            "stiffness": nonnegative(stiffness, "stiffness"),
            "damping": nonnegative(damping, "damping"),
            "name": name,
            "parent": parent,
        }
        for key, value in fields.items():
            object.__setattr__(self, key, value)

    @property
    def revolute(self) -> bool:
        """Whether the hinge is revolute (``axis`` given) rather than a ball."""
        return self.axis is not None

    def variables(self) -> PartVariables:
        coord_end = "rest" if self.stiffness > 0 else "free"
        if self.revolute:
            return PartVariables(coords=(Variable("theta", "rad", terminal=coord_end),),
                                 speeds=(Variable("theta_dot", "rad/s"),))
        return PartVariables(
            coords=tuple(Variable(f"p{i}", "-", 1.0 if i == 4 else 0.0, terminal=coord_end)
                         for i in range(1, 5)),
            speeds=tuple(Variable(f"u{i}", "rad/s") for i in range(1, 4)))

    def attitude(self, own):
        """The panel's attitude and rate relative to the hub, from its own symbols.

        Parameters
        ----------
        own : PartSymbols
            Its coordinates (``theta``, or ``p1..p4``) and speeds (``theta_dot``, or
            ``u1..u3``).

        Returns
        -------
        R : SX, 3x3
            Panel -> hub components (module docstring).
        w_rel : SX, 3x1 [rad/s]
            The panel's angular velocity relative to the hub, hub axes.
        """
        if self.revolute:
            a = ca.DM(self.axis)
            R = ca.SX(dcm_from_axis_angle(a, own.coords[0])).T
            return R, own.speeds[0] * a
        R = ca.SX(dcm_from_quat(own.coords)).T
        return R, ca.mtimes(R, own.speeds)

    def body_frame(self, frame, own):
        """The panel's frame: its axes, origin at the hinge (parts on the panel give their
        points from the hinge, in panel axes)."""
        R, w_rel = self.attitude(own)
        return frame.child(R, frame.point(self.hinge_point), w_rel)

    def contribute(self, frame, own) -> Contribution:
        R, w_rel = self.attitude(own)
        arm = ca.mtimes(R, ca.DM(self.cm_offset))
        rho = frame.point(self.hinge_point) + arm
        inertia = ca.mtimes([R, ca.DM(np.reshape(self.inertia, (3, 3))), R.T])
        body = Body.rigid(self.mass, inertia, rho, frame.velocity(rho, ca.cross(w_rel, arm)),
                          frame.w + w_rel)
        k, c = self.stiffness, self.damping
        if self.revolute:
            theta, rate = own.coords[0], own.speeds[0]
            return Contribution(bodies=[body], loads=[Load(-k * theta - c * rate, rate)],
                                potential=0.5 * k * theta ** 2)
        p, u = own.coords, own.speeds
        # the scene's suffix of this panel's names ("_2"), to keep two panels' invariants apart
        suffix = p[0].name()[len("p1"):] if p[0].is_symbolic() else ""
        torque = -2.0 * k * p[3] * p[0:3] - c * u
        return Contribution(rates=quat_rate(p, u), bodies=[body], loads=[Load(torque, u)],
                            potential=2.0 * k * (1.0 - p[3] ** 2),
                            invariants={"panel_quat_norm" + suffix: ca.norm_2(p)})
