"""Energy dampers and slosh on the hub: `PointMassDamper`, `SphericalDamper`, `Slosh`.

Rheinfurth & Wilson, NASA RP-1262, Sec. 4.5 NOTE (energy dampers make a spin about the major
axis asymptotically stable), Ch. 6 (the slosh pendulum and the slosh spring-mass).

Every moving mass here is a point mass: its body has the absolute velocity
``frame.velocity(rho, rho')`` of its position ``rho`` (from the hub's reference point), its
momentum ``m`` times that and no angular momentum of its own; the assembly derives the mass
matrix, the Coriolis and centrifugal terms and the hub's reaction from these
(`dynamics.scene.contract`). A mass on an attitude-only hub moves about a fixed reference
point (an infinitely heavy hub, or the point-mass damper's reduced mass); on a
six-degree-of-freedom hub the hub's own mass makes the system's mass centre move.
"""
from __future__ import annotations

import math
from dataclasses import KW_ONLY, dataclass

import casadi as ca
import numpy as np

from .. import validate
from .contract import Body, Contribution, Load, Part, PartVariables, Variable

__all__ = ["PointMassDamper", "SphericalDamper", "Slosh", "unit_vector", "real_number",
           "sliding_mass"]


def unit_vector(v, name: str) -> np.ndarray:
    """`validate.unit_vector` of a 3-vector, with the one message the stability reports show:
    "`name` must be a finite non-zero 3-vector" for a wrong shape, a non-finite or a zero
    vector (a `validate.ArgumentTypeError` when ``v`` holds no numbers).

    Examples
    --------
    >>> from appdyn.dynamics.scene.dampers import unit_vector
    >>> unit_vector([0.0, 3.0, 4.0], "direction")
    array([0. , 0.6, 0.8])
    """
    try:
        return validate.unit_vector(v, name)
    except ValueError as exc:
        raise type(exc)(f"`{name}` must be a finite non-zero 3-vector, got {v!r}") from None


def real_number(value, name, *, positive=False, nonnegative=False, allow_inf=False) -> float:
    """A real number (`validate.finite_scalar`), optionally positive or non-negative;
    ``allow_inf`` also accepts ``+inf`` (an infinitely heavy body).

    Raises
    ------
    ValueError
        "`name` must be positive, got ..." (or non-negative, or finite).

    Examples
    --------
    >>> from appdyn.dynamics.scene.dampers import real_number
    >>> real_number(2, "mass", positive=True), real_number(math.inf, "m", allow_inf=True)
    (2.0, inf)
    """
    if allow_inf and isinstance(value, (int, float, np.floating)) and value == math.inf:
        return math.inf
    v = validate.finite_scalar(value, name)
    if positive and not v > 0:
        raise ValueError(f"`{name}` must be positive, got {v}")
    if nonnegative and v < 0:
        raise ValueError(f"`{name}` must be non-negative, got {v}")
    return v


def _point(value, name) -> tuple:
    try:
        pos = np.array(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise ValueError(f"`{name}` must be 3 numbers, got {value!r}") from None
    if pos.size != 3 or not np.all(np.isfinite(pos)):
        raise ValueError(f"`{name}` must be 3 finite numbers [m], got {pos.tolist()}")
    return tuple(pos.tolist())


def sliding_mass(frame, own, mass, stiffness, damping, position, direction) -> Contribution:
    """A point mass on a spring and dashpot sliding along a hub line (states ``s, s_dot``).

    Parameters
    ----------
    frame : Frame
    own : PartSymbols
        Coordinate ``s`` [m] and speed ``s_dot`` [m/s].
    mass : float [kg]
    stiffness : float [N/m]
    damping : float [N s/m]
    position : tuple, shape (3,) [m]
        Rest position from the hub's mass centre.
    direction : tuple, shape (3,)
        Unit direction of travel, hub axes.

    Returns
    -------
    Contribution
        The body at ``rho = position + s d``, the spring-dashpot force ``-k s - c s'`` on
        ``s'`` and the potential ``k s^2 / 2`` [J].
    """
    s, sd = own.coords[0], own.speeds[0]
    d = ca.DM(direction)
    rho = frame.point(position) + s * d
    vel = frame.velocity(rho, sd * d)
    body = Body(velocity=vel, angular_velocity=frame.w, momentum=mass * vel,
                angular_momentum=ca.SX.zeros(3), position=rho, mass=float(mass))
    return Contribution(bodies=[body], loads=[Load(-stiffness * s - damping * sd, sd)],
                        potential=0.5 * stiffness * s ** 2)


_SLIDING = PartVariables(coords=(Variable("s", "m"),), speeds=(Variable("s_dot", "m/s"),))


@dataclass(frozen=True)
class PointMassDamper(Part):
    """A point mass on a spring and dashpot, sliding along a straight line fixed in the body.

    States ``s`` [m] (displacement from the relaxed spring) and ``s_dot`` [m/s]; the mass
    sits at ``rho = position + s d``, the spring and dashpot push it with ``-k s - c s'``
    along ``d``, the spring stores ``k s^2 / 2``.

    Parameters
    ----------
    mass : float [kg]
        The moving mass ``m > 0``
    stiffness : float [N/m]
        Spring ``k > 0`` (force ``-k s``)
    damping : float [N s/m]
        Dashpot ``c >= 0`` (force ``-c s'``)
    position : array_like, shape (3,) [m]
        Body-frame position of the mass at ``s = 0`` (spring relaxed) relative to the mass
        center of the rigid body that carries it.
    direction : array_like, shape (3,)
        Direction ``d`` of travel in body axes (normalized here); ``rho = position + s d``.
    body_mass : float [kg], optional
        Mass ``M`` of the carrying body. The free system's mass center moves with the mass;
        this enters only through the reduced mass ``mu = m M / (m + M)``. The default ``inf``
        gives ``mu = m`` (the body's mass center stays at the system's). On a
        six-degree-of-freedom hub (`RigidHub` with ``mass``) the hub's own mass plays this
        part: a finite ``body_mass`` is refused there.
    name : str, optional
    parent : str, optional
        The scene name of the part it sits on (default: the hub); its positions and axes
        are then that part's (`dynamics.scene.contract`, parts on parts).

    Examples
    --------
    >>> from appdyn.dynamics.scene import PointMassDamper, RigidHub, Scene
    >>> scene = Scene(RigidHub([2.0, 3.0, 4.0]), PointMassDamper(0.5, 60.0, 0.8))
    >>> scene.model().states[7:]
    ('s', 's_dot')
    >>> float(scene.model().rhs(scene.state(s=0.01))[8])  # through the mass centre: -k s / m
    -1.2
    """

    mass: float
    stiffness: float
    damping: float
    position: tuple = (0.0, 0.0, 0.0)
    direction: tuple = (1.0, 0.0, 0.0)
    body_mass: float = math.inf
    name: str | None = None
    parent: str | None = None
    kind = "damper"

    def __post_init__(self):
        object.__setattr__(self, "mass", real_number(self.mass, "damper.mass", positive=True))
        object.__setattr__(self, "stiffness",
                           real_number(self.stiffness, "damper.stiffness", positive=True))
        object.__setattr__(self, "damping",
                           real_number(self.damping, "damper.damping", nonnegative=True))
        object.__setattr__(self, "position", _point(self.position, "damper.position"))
        object.__setattr__(self, "direction",
                           tuple(unit_vector(self.direction, "damper.direction").tolist()))
        object.__setattr__(self, "body_mass", real_number(self.body_mass, "damper.body_mass",
                                                          positive=True, allow_inf=True))

    @property
    def reduced_mass(self) -> float:
        """``mu = m M / (m + M)`` [kg] (``m`` for an infinite body mass)."""
        if math.isinf(self.body_mass):
            return self.mass
        return self.mass * self.body_mass / (self.mass + self.body_mass)

    def inertia_at(self, s: float = 0.0) -> np.ndarray:
        """Inertia [kg m^2] the mass adds about the system mass center at displacement ``s``:
        ``mu (|rho|^2 E - rho rho^T)``."""
        rho = np.asarray(self.position) + s * np.asarray(self.direction)
        return self.reduced_mass * (rho @ rho * np.eye(3) - np.outer(rho, rho))

    def variables(self) -> PartVariables:
        return _SLIDING

    def contribute(self, frame, own) -> Contribution:
        if frame.mass is not None and not math.isinf(self.body_mass):
            raise ValueError(f"`damper.body_mass` = {self.body_mass} kg is for an attitude-only "
                             "hub; on a six-degree-of-freedom hub (RigidHub with `mass`) the "
                             "hub's mass moves the mass centre itself: leave body_mass at inf")
        mass = self.mass if frame.mass is not None else self.reduced_mass
        return sliding_mass(frame, own, mass, self.stiffness, self.damping, self.position,
                            self.direction)


@dataclass(frozen=True)
class SphericalDamper(Part):
    """A spherical core (fluid in a spherical cavity, say) coupled to its housing viscously.

    The core has isotropic inertia ``J_d`` about its center, which lies at the hub's mass
    center (its mass belongs to the hub's); it receives the torque ``-c (w_d - w_h)``,
    ``w_d`` its angular velocity and ``w_h = w + housing_rate`` that of the housing, and the
    hub the reaction. Speeds ``wd1..wd3`` [rad/s]: the core's absolute rate, hub axes.
    The energy changes at ``-c (w_d - w_h).(w_d - w)``: a loss when the housing is the hub;
    a turning housing's motor supplies the difference.
    At rest relative to its housing, ``w_d = w + housing_rate`` (`Scene.state`).

    Parameters
    ----------
    inertia : float [kg m^2]
        ``J_d > 0``
    damping : float [N m s]
        ``c >= 0``
    housing_rate : array_like, shape (3,) [rad/s], optional
        The housing's angular velocity relative to the hub, hub axes (default zero: the
        housing is the hub). A damper on a gyrostat's rotor turning at ``W`` about ``a``
        has ``housing_rate = W a``.
    name : str, optional
    parent : str, optional
        The scene name of the part it sits on (default: the hub); its positions and axes
        are then that part's (`dynamics.scene.contract`, parts on parts).

    Examples
    --------
    >>> from appdyn.dynamics.scene import RigidHub, Scene, SphericalDamper
    >>> scene = Scene(RigidHub([2.0, 2.0, 4.0]), SphericalDamper(0.1, 0.05))
    >>> x = scene.state(w=[0.0, 0.0, 1.0])
    >>> x[7:]  # the core turns with its housing
    array([0., 0., 1.])
    >>> float(abs(scene.model().rhs(x)[4:]).max())  # a steady spin
    0.0
    """

    inertia: float
    damping: float
    housing_rate: tuple = (0.0, 0.0, 0.0)
    name: str | None = None
    parent: str | None = None
    kind = "damper"

    def __post_init__(self):
        object.__setattr__(self, "inertia",
                           real_number(self.inertia, "damper.inertia", positive=True))
        object.__setattr__(self, "damping",
                           real_number(self.damping, "damper.damping", nonnegative=True))
        object.__setattr__(self, "housing_rate", tuple(validate.finite_array(
            self.housing_rate, "damper.housing_rate", (3,)).tolist()))

    def variables(self) -> PartVariables:
        return PartVariables(speeds=tuple(Variable(f"wd{i}", "rad/s", terminal="free")
                                          for i in (1, 2, 3)))

    def spin_speeds(self, frame, own):
        return frame.w + ca.DM(self.housing_rate)

    def contribute(self, frame, own) -> Contribution:
        wd = own.speeds
        relative = wd - self.spin_speeds(frame, own)
        pos = frame.point((0.0, 0.0, 0.0))
        core = Body(velocity=frame.velocity(pos), angular_velocity=wd, momentum=ca.SX.zeros(3),
                    angular_momentum=self.inertia * wd, position=pos)
        # the torque acts on the core's rate relative to the hub (its housing turns at a
        # constant rate relative to the hub, so the partial velocities are the same)
        return Contribution(bodies=[core], loads=[Load(-self.damping * relative, wd - frame.w)])


@dataclass(frozen=True)
class Slosh(Part):
    """Propellant slosh as a mechanical analogue: a pendulum or a spring-mass.

    ``kind="pendulum"``: the mass ``m`` on a massless rod of ``length`` ``l`` hinged at the hub
    point ``hinge``; at rest the rod points along ``direction`` ``d``. The rod's direction is
    ``e = cos(theta2) (cos(theta1) d + sin(theta1) p1) + sin(theta2) p2``, with ``p1`` the
    hub axis least aligned with ``d`` made perpendicular to it and ``p2 = d x p1``
    (coordinates ``theta1, theta2`` [rad], speeds ``theta1_dot, theta2_dot`` [rad/s]); the
    hinge damps each angle rate with ``-c theta_i'`` [N m]. Under a constant acceleration
    ``a`` of the hinge (the mass hanging along ``-a``) it swings at ``omega^2 = a / l``;
    hinged at ``R`` from the axis of a steady spin ``W`` and pointing outward, at
    ``omega^2 = W^2 R / l`` in the spin plane and ``W^2 (R + l) / l`` out of it.

    ``kind="spring"``: the mass slides along ``direction`` through its rest point
    ``position`` on a spring of ``stiffness`` ``k`` (or ``frequency`` ``sqrt(k/m)``) and a
    dashpot ``damping`` (states ``s`` [m], ``s_dot`` [m/s]), as a `PointMassDamper` with
    an infinite ``body_mass``.

    The two pendulum angles are singular where the rod is perpendicular to ``p1`` and
    ``direction`` both (``theta2 = +-pi/2``, 90 degrees from rest): slosh under thrust or
    spin stays far from it, but a pendulum free of any restoring field can swing there,
    where ``theta1'`` grows without bound and the integrator's steps shrink.

    The mass is a point mass; on an attitude-only hub it moves about the fixed reference
    point, on a six-degree-of-freedom hub the hub's mass reacts to it.

    Parameters
    ----------
    mass : float [kg]
        The slosh mass ``m > 0``.
    kind : {'pendulum', 'spring'}, optional
        The analogue (also the part's default name).
    length : float [m]
        Pendulum rod length ``l > 0`` (pendulum only, required).
    hinge : array_like, shape (3,) [m], optional
        Pendulum hinge from the hub's mass centre, hub axes.
    position : array_like, shape (3,) [m], optional
        Spring-mass rest position from the hub's mass centre, hub axes.
    direction : array_like, shape (3,), optional
        Pendulum: the rod's rest direction; spring: the direction of travel (normalized).
    frequency : float [rad/s], optional
        Spring only: ``sqrt(k / m)``; give it or ``stiffness``.
    stiffness : float [N/m], optional
        Spring only: ``k``; give it or ``frequency``.
    damping : float, optional
        ``c >= 0``: [N m s] on each pendulum angle rate, [N s/m] on the spring's.
    name : str, optional
    parent : str, optional
        The scene name of the part it sits on (default: the hub); its positions and axes
        are then that part's (`dynamics.scene.contract`, parts on parts).

    Raises
    ------
    ValueError
        Naming the field: a non-positive ``mass``, ``length``, ``frequency`` or
        ``stiffness``, a pendulum without ``length`` or with a spring field, a spring
        without (or with both) ``frequency`` and ``stiffness`` or with ``length``.

    Examples
    --------
    >>> from appdyn.dynamics.scene import RigidHub, Scene, Slosh
    >>> scene = Scene(RigidHub([2.0, 3.0, 4.0], mass=10.0), Slosh(1.0, length=0.5))
    >>> scene.model().states[13:]
    ('theta1', 'theta2', 'theta1_dot', 'theta2_dot')
    >>> Slosh(2.0, kind="spring", frequency=3.0).stiffness
    18.0
    """

    mass: float
    _: KW_ONLY
    kind: str = "pendulum"
    length: float | None = None
    hinge: tuple = (0.0, 0.0, 0.0)
    position: tuple = (0.0, 0.0, 0.0)
    direction: tuple = (1.0, 0.0, 0.0)
    frequency: float | None = None
    stiffness: float | None = None
    damping: float = 0.0
    name: str | None = None
    parent: str | None = None

    def __post_init__(self):
        set_ = lambda key, value: object.__setattr__(self, key, value)  # noqa: E731
        set_("mass", real_number(self.mass, "mass", positive=True))
        set_("kind", validate.one_of(self.kind, "kind", ("pendulum", "spring")))
        set_("hinge", _point(self.hinge, "hinge"))
        set_("position", _point(self.position, "position"))
        set_("direction", tuple(unit_vector(self.direction, "direction").tolist()))
        set_("damping", real_number(self.damping, "damping", nonnegative=True))
        if self.kind == "pendulum":
            if self.length is None:
                raise ValueError("a slosh pendulum needs `length` [m] (> 0)")
            for key in ("frequency", "stiffness"):
                if getattr(self, key) is not None:
                    raise ValueError(f"`{key}` is for kind='spring'; a pendulum's frequency "
                                     "follows from `length` and the acceleration")
            set_("length", real_number(self.length, "length", positive=True))
            return
        if self.length is not None:
            raise ValueError("`length` is for kind='pendulum'")
        if self.frequency is not None and self.stiffness is not None:
            f = real_number(self.frequency, "frequency", positive=True)
            if math.isclose(self.stiffness, self.mass * f * f, rel_tol=1e-12):
                set_("stiffness", None)  # a copy (dataclasses.replace) carries both
        if (self.frequency is None) == (self.stiffness is None):
            raise ValueError("a slosh spring needs exactly one of `frequency` [rad/s] and "
                             f"`stiffness` [N/m], got frequency={self.frequency!r}, "
                             f"stiffness={self.stiffness!r}")
        if self.frequency is not None:
            f = real_number(self.frequency, "frequency", positive=True)
            set_("frequency", f)
            set_("stiffness", self.mass * f * f)
        else:
            k = real_number(self.stiffness, "stiffness", positive=True)
            set_("stiffness", k)
            set_("frequency", math.sqrt(k / self.mass))

    def rod_basis(self) -> np.ndarray:
        """``(d, p1, p2)`` as the columns of a (3, 3) rotation (pendulum angles' axes)."""
        d = np.asarray(self.direction)
        e = np.eye(3)[int(np.argmin(np.abs(d)))]
        p1 = e - (e @ d) * d
        p1 /= np.linalg.norm(p1)
        return np.column_stack([d, p1, np.cross(d, p1)])

    def variables(self) -> PartVariables:
        if self.kind == "spring":
            return _SLIDING
        return PartVariables(
            coords=(Variable("theta1", "rad"), Variable("theta2", "rad")),
            speeds=(Variable("theta1_dot", "rad/s"), Variable("theta2_dot", "rad/s")))

    def contribute(self, frame, own) -> Contribution:
        if self.kind == "spring":
            return sliding_mass(frame, own, self.mass, self.stiffness, self.damping,
                                self.position, self.direction)
        t1, t2 = own.coords[0], own.coords[1]
        B = ca.DM(self.rod_basis())
        e = ca.mtimes(B, ca.vertcat(ca.cos(t2) * ca.cos(t1), ca.cos(t2) * ca.sin(t1), ca.sin(t2)))
        rho = frame.point(self.hinge) + self.length * e
        rel = self.length * ca.mtimes(ca.jacobian(e, own.coords), own.speeds)
        vel = frame.velocity(rho, rel)
        body = Body(velocity=vel, angular_velocity=frame.w, momentum=self.mass * vel,
                    angular_momentum=ca.SX.zeros(3), position=rho, mass=self.mass)
        return Contribution(bodies=[body], loads=[Load(-self.damping * own.speeds, own.speeds)])
