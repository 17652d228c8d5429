"""The part contract: what a part of a `Scene` declares and what it contributes.

A scene is a hub (`RigidHub`) carrying parts. The assembly (`dynamics.scene.assembly`) writes
Euler's law and the quaternion kinematics once, by Kane's method on the symbols: every part
describes its bodies kinematically and the loads it applies, the assembly forms the
generalized inertia forces, the mass matrix and the right-hand side, and solves the block
system once (hub accelerations from the Schur complement, then each part's: Basilisk's
back-substitution, done symbolically so the result has exact derivatives).

Rules for adding a part
-----------------------
A part is a frozen (hashable) dataclass deriving from `Part` whose fields are numbers, strings
or tuples (convert arrays to tuples in ``__post_init__``, after validating them with a message
that names the field). It sets ``kind`` (the default name, ``"wheels"``), and implements:

``variables(self) -> PartVariables``
    Its *coordinates* (positions: an angle, a displacement, a gimbal angle; or the clock),
    its *speeds* (generalized speeds whose derivatives the assembly solves for) and its
    *controls*, each a `Variable` with a name, a unit, a rest value, bounds, and for states
    whether the slew jobs hold it at rest at the end (``terminal="rest"``) or leave it free
    (``"free"``: a wheel speed, a gimbal angle). A coordinate that is a mass flowing out of
    the vehicle (an engine's propellant) is declared ``frozen=True``: the inertia forces hold
    it constant (the control-volume law; the momentum the flow carries is in the thrust). ``u_max`` is the one word for a control
    bound: pass it to `Variable` as ``bounds=(-u_max, u_max)``. Names are local (``"s"``,
    ``"W1"``); the scene makes them unique (a second damper's states become ``s_2``, ...).
``contribute(self, frame, own) -> Contribution``
    Given the hub `Frame` (its angular velocity ``w``, the velocity ``v`` of its reference
    point, the DCM, positions measured from the hub's mass centre by `Frame.point`) and the
    part's own symbols ``own`` (`PartSymbols`: ``own.coords``, ``own.speeds``,
    ``own.controls``, each a column and each entry also by local name ``own["s"]``):

    * ``rates``: the derivatives of its coordinates (in its speeds, coordinates, controls),
    * ``bodies``: each moving mass as a `Body` -- absolute velocity of its mass centre and
      absolute angular velocity (hub axes), its linear momentum and its angular momentum about
      its mass centre (hub axes). The partial velocities, the mass matrix and every
      Coriolis and centrifugal term follow from these by differentiation; a body may carry
      momentum that is not ``I w`` (a held rotor's ``h a``),
    * ``loads``: forces and torques as `Load` (a vector and the velocity it does work on: a
      force with its point's velocity, a torque with the angular velocity of the body it acts
      on, a spring's force with its coordinate's rate). A torque between the part and the hub
      acts on the *relative* angular velocity; its reaction on the hub is then implied,
    * ``potential``: its potential energy (springs, fields), ``kinetic``: only when its
      kinetic energy is not ``1/2 (p.v + h.w)`` summed over its bodies, ``momentum``: only
      when the angular momentum it adds to the ``momentum_inertial`` invariant (about the
      reference point, hub axes) is not its bodies' ``h + rho x p`` (a share carried by a
      prescribed motion, i.e. by a control, must be left out: invariants are functions of
      the state),
    * ``invariants``: further monitored quantities of the state, by name.

    Loads that depend on the mass distribution of the whole scene (gravity) implement
    ``field_loads(self, frame, bodies, own) -> Contribution`` instead, which receives every
    body of the scene (the hub's first) and the part's own symbols (a field may turn with a
    clock coordinate the part declares; its ``rates`` still come from ``contribute``).
``spin_speeds(self, frame, own) -> expression`` (optional)
    The part's speeds when it is at rest relative to a hub spinning at ``frame.w`` (zero
    unless its speeds are absolute rates, as a spherical damper's core rate); used by
    `Scene.state` and the spin stability case.

Parts on parts
--------------
A part sits on the hub unless its ``parent`` field names another part of the scene (every part
has the keyword ``parent=None``; the scene checks that the parent exists, comes in no cycle
and can carry parts). A part that can carry parts sets ``carries_parts = True`` and implements

``body_frame(self, frame, own) -> Frame``
    The frame of its body, built from the frame it sits on by `Frame.child` (its rotation,
    the origin of its axes on the parent and its angular velocity relative to the parent).

A part on a parent is written exactly as one on the hub: the assembly hands it its parent's
`Frame` (the parent's axes, its points measured from the parent frame's origin, ``frame.mass``
None) and rotates what it returns into hub axes, so nothing in a part knows where it sits.
Fields that act on the whole scene (``field_loads``) set ``mountable = False``: they cannot
name a parent.

Constraints are not part of the contract yet: every part is written in minimal coordinates,
so an assembled model never forms a multiplier system (`dynamics.constrained` holds that
machinery for the hand-written constrained models).

Conventions: hub axes throughout, SI units, the quaternion scalar-last (inertial -> body).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar, Literal

import casadi as ca

__all__ = ["Variable", "PartVariables", "PartSymbols", "Body", "Load", "Contribution", "Frame",
           "Part", "bounds_from_u_max"]


@dataclass(frozen=True)
class Variable:
    """One named scalar of a part: a coordinate, a speed or a control.

    Parameters
    ----------
    name : str
        Local name (made unique by the scene).
    unit : str
        SI unit as printed (``"rad/s"``).
    rest : float, optional
        Value at rest (`Scene.state` fills unspecified blocks with it).
    bounds : (float, float), optional
        Lower and upper bound (controls: from ``u_max``; states: a speed limit).
    terminal : {'rest', 'free'}, optional
        Whether a rest-to-rest slew holds it at ``rest`` at the end.
    frozen : bool, optional
        A coordinate the inertia forces hold frozen: a mass that flows out of the vehicle
        (seed Sec. 3.4, control-volume law ``m v' = F``, no ``m' v`` term). Kane's equations
        then leave out the momenta's derivative along its rate.
    """

    name: str
    unit: str
    rest: float = 0.0
    bounds: tuple = (-math.inf, math.inf)
    terminal: Literal["rest", "free"] = "rest"
    frozen: bool = False


@dataclass(frozen=True)
class PartVariables:
    """A part's declared coordinates, speeds and controls (tuples of `Variable`)."""

    coords: tuple = ()
    speeds: tuple = ()
    controls: tuple = ()


class PartSymbols:
    """The symbols of one part inside an assembly: ``coords``, ``speeds``, ``controls``
    (SX columns), and each scalar by its local name (``own["W1"]``)."""

    def __init__(self, coords: ca.SX, speeds: ca.SX, controls: ca.SX, names: dict):
        self.coords, self.speeds, self.controls = coords, speeds, controls
        self._names = names

    def __getitem__(self, name: str) -> ca.SX:
        return self._names[name]


@dataclass
class Body:
    """A moving mass of a part, described in hub axes.

    Parameters
    ----------
    velocity : SX, 3x1 [m/s]
        Absolute velocity of its mass centre (``frame.velocity(rho, rho_dot)``).
    angular_velocity : SX, 3x1 [rad/s]
        Absolute angular velocity.
    momentum : SX, 3x1 [N s]
        Linear momentum (``m * velocity``; zero for a massless rotor).
    angular_momentum : SX, 3x1 [N m s]
        Angular momentum about its mass centre (``I * angular_velocity``, plus any stored
        momentum such as a held rotor's).
    position : SX, 3x1 [m]
        Its mass centre from the hub's reference point (for momentum about the reference and
        for fields).
    mass : float [kg]
    inertia : SX, 3x3 [kg m^2]
        About its mass centre (for fields; may depend on the coordinates).
    """

    velocity: ca.SX
    angular_velocity: ca.SX
    momentum: ca.SX
    angular_momentum: ca.SX
    position: ca.SX
    mass: float = 0.0
    inertia: ca.SX | None = None

    @classmethod
    def rigid(cls, mass: float, inertia, position, velocity, angular_velocity,
              stored=None) -> "Body":
        """A rigid body: ``p = m v``, ``h = I w (+ stored)``."""
        I = ca.SX(inertia)
        h = ca.mtimes(I, angular_velocity)
        if stored is not None:
            h = h + stored
        return cls(velocity=velocity, angular_velocity=angular_velocity,
                   momentum=mass * velocity, angular_momentum=h, position=position,
                   mass=float(mass), inertia=I)


@dataclass
class Load:
    """A generalized load: ``vector`` does work on ``velocity`` (its power is their dot product).

    A force and the velocity of its point, a torque and the angular velocity of the body it
    acts on (relative to the hub for an internal motor), or a scalar spring force and its
    coordinate's rate. The assembly maps it to generalized forces by the partial velocities.
    """

    vector: ca.SX
    velocity: ca.SX


@dataclass
class Contribution:
    """What a part adds to the assembly (module docstring, rules for adding a part)."""

    rates: ca.SX | None = None
    bodies: list = field(default_factory=list)
    loads: list = field(default_factory=list)
    potential: ca.SX | float = 0.0
    kinetic: ca.SX | None = None
    momentum: ca.SX | None = None
    invariants: dict = field(default_factory=dict)


@dataclass
class Frame:
    """The hub, or the body a part sits on, as its parts see it (its axes).

    A part on the hub receives the hub's frame; a part on another part receives that part's
    body frame (`Frame.child`): the same attributes in the parent's axes, its points
    measured from the parent's origin.

    Attributes
    ----------
    q : SX, 4x1 or None
        Hub attitude quaternion (scalar-last, inertial -> hub); None in a body frame.
    dcm : SX, 3x3
        ``A(q)``: inertial -> hub components.
    w : SX, 3x1 [rad/s]
        Hub angular velocity.
    v : SX, 3x1 [m/s]
        Velocity of the hub's reference point (zero for an attitude-only hub, whose
        reference point is fixed).
    r : SX, 3x1 [m] or None
        Inertial position of the reference point (six-degree-of-freedom hub only).
    reference : tuple of float, shape (3,) [m]
        The reference point from the hub's mass centre.
    mass : float or None [kg]
        Hub mass (None: attitude-only hub, or a part's body frame).
    to_hub : SX, 3x3 or None
        This frame's axes -> hub axes (None: the hub's frame).
    origin : SX, 3x1 or None [m]
        This frame's origin from the hub's reference point, hub axes (None: the hub's).
    reference_rate : tuple of float, shape (3,) [rad/s], or None
        The hub's ``reference_rate`` ``Omega``: ``q``, ``dcm`` and ``r`` are then referred to
        a frame turning at ``Omega`` about the origin of ``r`` (its axes), not to inertial
        axes; ``w`` and ``v`` stay absolute. None: inertial.
    """

    q: ca.SX
    dcm: ca.SX
    w: ca.SX
    v: ca.SX
    r: ca.SX | None
    reference: tuple
    mass: float | None
    to_hub: ca.SX | None = None
    origin: ca.SX | None = None
    reference_rate: tuple | None = None

    @property
    def is_hub(self) -> bool:
        """Whether this is the hub's frame (not a part's body frame)."""
        return self.to_hub is None

    def child(self, rotation, origin, w_rel, v_rel=None) -> "Frame":
        """The frame of a body mounted on this one (parts on parts).

        Parameters
        ----------
        rotation : SX, 3x3
            Child axes -> this frame's axes (components).
        origin : SX, 3x1 [m]
            The child frame's origin (a hinge, say) from this frame's reference point, in
            this frame's axes (``frame.point(hinge_point)``).
        w_rel : SX, 3x1 [rad/s]
            The child's angular velocity relative to this frame, this frame's axes.
        v_rel : SX, 3x1 [m/s], optional
            The velocity of the child's origin relative to this frame (zero for a hinge).

        Returns
        -------
        Frame
            In the child's axes: ``w`` and ``v`` (of the child's origin) absolute,
            ``dcm`` inertial -> child, ``r`` the origin's inertial position (six-degree-of-
            freedom hub only), ``reference`` zero (points from the origin), ``mass`` None,
            ``q`` None, and ``to_hub``/``origin`` for the assembly (child axes -> hub axes;
            the origin from the hub's reference point, hub axes); ``reference_rate`` the
            hub's.
        """
        R, o = ca.SX(rotation), ca.SX(origin)
        Rt = R.T
        v = self.velocity(o, v_rel)
        r = None if self.r is None else self.r + ca.mtimes(self.dcm.T, o)
        to_hub = R if self.is_hub else ca.mtimes(self.to_hub, R)
        at = o if self.is_hub else self.origin + ca.mtimes(self.to_hub, o)
        return Frame(q=None, dcm=ca.mtimes(Rt, self.dcm), w=ca.mtimes(Rt, self.w + w_rel),
                     v=ca.mtimes(Rt, v), r=r, reference=(0.0, 0.0, 0.0), mass=None,
                     to_hub=to_hub, origin=at, reference_rate=self.reference_rate)

    def point(self, from_mass_centre) -> ca.SX:
        """A hub point given from the hub's mass centre, as measured from the reference."""
        return ca.SX(ca.DM(from_mass_centre)) - ca.DM(self.reference)

    def velocity(self, position, relative=None) -> ca.SX:
        """Absolute velocity of a point at ``position`` (from the reference) moving at
        ``relative`` with respect to the hub: ``v + w x position + relative``."""
        out = self.v + ca.cross(self.w, position)
        return out if relative is None else out + relative


def bounds_from_u_max(u_max, n: int, name: str = "u_max") -> tuple:
    """``n`` symmetric bounds ``(-u_max_i, u_max_i)`` (unbounded for None).

    Raises
    ------
    ValueError
        If ``u_max`` is not positive, or not a scalar or ``n`` values.
    """
    from ..validate import positive_each
    if u_max is None:
        return tuple((-math.inf, math.inf) for _ in range(n))
    vals = positive_each(u_max, name, n)
    return tuple((-float(v), float(v)) for v in vals)


class Part:
    """Base class of the parts of a `Scene` (the contract is the module docstring).

    Subclasses are frozen dataclasses with a ``name`` field (``None``: the scene names it
    after ``kind``) and a ``parent`` field (``None``: the hub; the module docstring, parts on
    parts).
    """

    kind: ClassVar[str] = "part"
    carries_parts: ClassVar[bool] = False
    mountable: ClassVar[bool] = True

    def variables(self) -> PartVariables:
        """The part's coordinates, speeds and controls."""
        return PartVariables()

    def contribute(self, frame: Frame, own: PartSymbols) -> Contribution:
        """The part's rates, bodies, loads, energy and invariants (module docstring)."""
        return Contribution()

    def field_loads(self, frame: Frame, bodies: list, own: PartSymbols) -> Contribution:
        """Loads that act on every body of the scene (gravity); none by default."""
        return Contribution()

    def body_frame(self, frame: Frame, own: PartSymbols) -> Frame:
        """The frame of the part's body, for parts sitting on it (``carries_parts``)."""
        raise NotImplementedError(f"{type(self).__name__} cannot carry parts")

    def spin_speeds(self, frame: Frame, own: PartSymbols):
        """The part's speeds at rest relative to a hub turning at ``frame.w`` (zero)."""
        return ca.DM.zeros(own.speeds.numel())
