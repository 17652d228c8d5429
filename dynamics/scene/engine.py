"""A gimbaled rocket engine with mass flow: `Engine` (seed Sec. 3.4, Eqs. 3.38-3.49).

Thrust
------
A thrust of constant size ``F`` acts at the gimbal point ``position`` on the parent, along
``d = cos(dp) cos(dy) a - cos(dp) sin(dy) b + sin(dp) c`` in the parent's axes: ``a`` is the
thrust axis at zero deflection (``axis``, default ``+x``), ``c = unit(a x (0, 1, 0))``
(``+z`` for ``a = +x``; ``unit((0, 0, 1) x a)`` when ``a`` is along ``y``) and ``b = c x a``.
With the gimbal aft of the mass centre a positive pitch deflection ``dp`` turns the vehicle
about ``+b`` and a positive yaw deflection ``dy`` about ``+c`` (the launch vehicle's ``delta``:
thrust ``F (cos delta, -sin delta)``, `dynamics.launch_vehicle`). The deflections are the
controls ``dp, dy`` (bounded by ``gimbal``), or, with an ``actuator``
(`dynamics.launch_vehicle.Actuator`), states following the commands ``dp_c, dy_c``:
``delta' = clip((clip(delta_c, limits) - delta) / tau, -rate_limit, rate_limit)``.

Mass flow (control volume, seed Sec. 3.4)
-----------------------------------------
With ``mass_flow`` (or ``isp``: ``mdot = F / (isp g0)``, Eq. 3.40) the propellant is a point
mass ``m_p`` at ``tank`` on the parent, the state ``m_p`` [kg] with ``m_p' = -mdot``. The
thrust ``F = mdot C`` (Eq. 3.39) is the momentum the exhaust carries away; the vehicle's
equations are written at the instantaneous mass -- the inertia forces hold ``m_p`` frozen
(`Variable` ``frozen``), so no ``m' v`` term appears (the seed's note after Eq. 3.49). The
internal flow from ``flow_start`` to ``nozzle_exit`` (a straight stream line ``r(s) = r_A + s
D``, ``D = r_B - r_A``, ``0 <= s <= 1``) adds the Coriolis force of Eq. 3.47 and the moment of
Eq. 3.48 about the reference point::

    F_C = -2 mdot w x D,
    L_C = -2 mdot int_0^1 r(s) x (w x D) ds = r_M x F_C,   r_M = (r_A + r_B) / 2,

i.e. the force ``F_C`` applied at the stream line's midpoint ``r_M``. For the seed's rocket
(flow along the axis from ``l1`` to ``l2`` aft of the mass centre, ``w`` transverse)
``L_C = -mdot w (l2^2 - l1^2)``: jet damping, Eq. 3.49.

Energy
------
No energy is conserved with the engine burning. The kinetic energy ``T`` of the scene obeys
``T' = F d . v_gimbal + F_C . v_M - 1/2 mdot |v_tank|^2 (+ the other parts' power)``: the
thrust's and the Coriolis force's power, less the kinetic energy the leaving propellant
carries (the mass is frozen in the inertia forces, not in ``T``). With ``thrust = 0`` and no
mass flow the engine adds nothing but its gimbal states, and the scene conserves what it did.
The model holds while ``m_p > 0``: burnout is not modelled (stop the run at ``m_p = 0``).
"""
from __future__ import annotations

from dataclasses import KW_ONLY, dataclass

import casadi as ca
import numpy as np

from ..launch_vehicle.parts import Actuator
from ..mass import G0
from ..validate import finite_array
from .contract import (Body, Contribution, Load, Part, PartVariables, Variable,
                       bounds_from_u_max)
from .dampers import real_number, unit_vector

__all__ = ["Engine", "G0", "gimbal_basis", "coriolis_load", "gimbaled_engine"]

# G0: standard gravity [m/s^2] of the specific impulse (``C = isp g0``, seed Eq. 3.40), one
# constant with `dynamics.mass` (its `isp` and `delta_v`)


def gimbal_basis(axis) -> np.ndarray:
    """``(a, b, c)`` as rows: the thrust axis and the pitch and yaw turning axes (module
    docstring).

    Examples
    --------
    >>> from appdyn.dynamics.scene.engine import gimbal_basis
    >>> gimbal_basis([1.0, 0.0, 0.0])
    array([[1., 0., 0.],
           [0., 1., 0.],
           [0., 0., 1.]])
    """
    a = unit_vector(axis, "axis")
    ref = np.array([0.0, 1.0, 0.0])
    c = np.cross(a, ref)
    if np.linalg.norm(c) < 1e-9:
        c = np.cross([0.0, 0.0, 1.0], a)
    c = c / np.linalg.norm(c)
    return np.array([a, np.cross(c, a), c]) + 0.0


def coriolis_load(frame, mdot, start, end) -> Load:
    """The internal flow's Coriolis force ``-2 mdot w x (r_B - r_A)`` at the stream line's
    midpoint (module docstring; seed Eqs. 3.47-3.49).

    Parameters
    ----------
    frame : Frame
    mdot : float [kg/s]
    start, end : tuple, shape (3,) [m]
        ``r_A`` and ``r_B`` on the parent, from the hub's mass centre.

    Examples
    --------
    Jet damping of the seed's rocket (``l1 = 1``, ``l2 = 3``, ``mdot = 2``, ``w = 0.1``):
    ``L_C = -mdot w (l2^2 - l1^2) = -1.6``

    >>> import casadi as ca
    >>> from appdyn.dynamics.scene.contract import Frame
    >>> from appdyn.dynamics.scene.engine import coriolis_load
    >>> frame = Frame(q=None, dcm=None, w=ca.DM([0, 0, 0.1]), v=ca.DM.zeros(3), r=None,
    ...               reference=(0.0, 0.0, 0.0), mass=None)
    >>> load = coriolis_load(frame, 2.0, (-1.0, 0.0, 0.0), (-3.0, 0.0, 0.0))
    >>> F = ca.DM(load.vector); float(ca.cross(ca.DM([-2.0, 0, 0]), F)[2])
    -1.6
    """
    D = ca.DM(end) - ca.DM(start)
    mid = frame.point(tuple(0.5 * (np.asarray(start) + np.asarray(end))))
    return Load(-2.0 * mdot * ca.cross(frame.w, D), frame.velocity(mid))


@dataclass(frozen=True)
class Engine(Part):
    """A gimbaled engine: thrust at a point of its parent, mass flow, jet damping.

    Parameters
    ----------
    thrust : float [N]
        ``F >= 0``, constant.
    position : array_like, shape (3,) [m]
        The gimbal point on the parent, from the hub's mass centre.
    axis : array_like, shape (3,), optional
        Thrust direction at zero deflection (default ``(1, 0, 0)``: pushing along ``+x``).
    gimbal : float [rad], optional
        Maximum deflection ``u_max`` of the pitch and yaw controls ``dp, dy`` (or of the
        commands ``dp_c, dy_c`` with ``actuator``); None: a fixed engine.
    mass_flow : float [kg/s], optional
        ``mdot > 0``; with it the propellant mass ``m_p`` is a state.
    isp : float [s], optional
        Specific impulse instead of ``mass_flow``: ``mdot = F / (isp g0)``.
    propellant : float [kg], optional
        Propellant mass at rest (the rest value of ``m_p``); needed with a mass flow.
    tank : array_like, shape (3,) [m], optional
        Where the propellant mass sits on the parent (default the hub's mass centre).
    flow_start, nozzle_exit : array_like, shape (3,) [m], optional
        The internal flow's stream line (defaults: ``tank`` and ``position``).
    actuator : dynamics.launch_vehicle.Actuator, optional
        The deflections become states following the commands (needs ``gimbal``).
    parent : str, optional
        The scene name of the part it sits on (None: the hub).
    name : str, optional

    Raises
    ------
    ValueError
        Naming the argument: a negative thrust, a bad point or axis, both or a non-positive
        ``mass_flow`` and ``isp``, a mass flow without ``propellant``, an ``actuator``
        without ``gimbal``.
    TypeError
        If ``actuator`` is not an `Actuator`.

    Examples
    --------
    A 2 kN engine 3 m aft on a 100 kg vehicle, deflected 0.1 rad in yaw:

    >>> import numpy as np
    >>> from appdyn.dynamics.scene import Engine, RigidHub, Scene
    >>> scene = Scene(RigidHub([10.0, 50.0, 50.0], mass=100.0),
    ...               Engine(2000.0, (-3.0, 0.0, 0.0), gimbal=0.2, isp=300.0, propellant=20.0))
    >>> model = scene.model()
    >>> model.states[13:], model.controls
    (('m_p',), ('dp', 'dy'))
    >>> xdot = model.rhs(scene.state(), [0.0, 0.1])
    >>> round(float(xdot[6]), 6), round(float(xdot[13]), 6)  # F l sin(dy) / I3, -F/(isp g0)
    (11.98001, -0.679811)
    """

    thrust: float
    position: tuple
    _: KW_ONLY
    axis: tuple = (1.0, 0.0, 0.0)
    gimbal: float | None = None
    mass_flow: float | None = None
    isp: float | None = None
    propellant: float = 0.0
    tank: tuple = (0.0, 0.0, 0.0)
    flow_start: tuple | None = None
    nozzle_exit: tuple | None = None
    actuator: Actuator | None = None
    parent: str | None = None
    name: str | None = None
    kind = "engine"

    def __post_init__(self):
        setf = object.__setattr__

        def point(field):
            value = getattr(self, field)
            if value is not None:
                setf(self, field, tuple(finite_array(value, field, (3,)).tolist()))

        setf(self, "thrust", real_number(self.thrust, "thrust", nonnegative=True))
        for field in ("position", "tank", "flow_start", "nozzle_exit"):
            point(field)
        setf(self, "axis", tuple(unit_vector(self.axis, "axis").tolist()))
        if self.gimbal is not None:
            setf(self, "gimbal", real_number(self.gimbal, "gimbal", positive=True))
        if self.mass_flow is not None and self.isp is not None:
            raise ValueError("give one of `mass_flow` and `isp` (mdot = thrust / (isp g0)), "
                             f"got mass_flow={self.mass_flow!r}, isp={self.isp!r}")
        for field in ("mass_flow", "isp"):
            if getattr(self, field) is not None:
                setf(self, field, real_number(getattr(self, field), field, positive=True))
        setf(self, "propellant", real_number(self.propellant, "propellant", nonnegative=True))
        if self.mdot > 0 and not self.propellant > 0:
            raise ValueError("a mass flow needs the `propellant` mass [kg] > 0, got "
                             f"{self.propellant!r}")
        if self.actuator is not None:
            if not isinstance(self.actuator, Actuator):
                raise TypeError("`actuator` must be a dynamics.launch_vehicle.Actuator, got "
                                f"{type(self.actuator).__name__}")
            if self.gimbal is None:
                raise ValueError("an `actuator` needs `gimbal` (the command bound [rad])")

    @property
    def mdot(self) -> float:
        """The mass flow [kg/s] (0 without ``mass_flow`` or ``isp``)."""
        if self.mass_flow is not None:
            return self.mass_flow
        return 0.0 if self.isp is None else self.thrust / (self.isp * G0)

    def variables(self) -> PartVariables:
        coords, controls = [], []
        if self.gimbal is not None:
            bound = bounds_from_u_max(self.gimbal, 1, "gimbal")[0]
            names = ("dp", "dy")
            if self.actuator is None:
                controls = [Variable(n, "rad", bounds=bound) for n in names]
            else:
                coords = [Variable(n, "rad", terminal="free") for n in names]
                controls = [Variable(n + "_c", "rad", bounds=bound) for n in names]
        if self.mdot > 0:
            coords.append(Variable("m_p", "kg", rest=self.propellant,
                                   bounds=(0.0, self.propellant), terminal="free",
                                   frozen=True))
        return PartVariables(coords=tuple(coords), controls=tuple(controls))

    def _deflections(self, own):
        if self.gimbal is None:
            return 0.0, 0.0, []
        if self.actuator is None:
            return own["dp"], own["dy"], []
        act, rates = self.actuator, []
        for n in ("dp", "dy"):
            target = own[n + "_c"]
            if act.deflection_limits is not None:
                target = ca.fmin(ca.fmax(target, act.deflection_limits[0]),
                                 act.deflection_limits[1])
            rate = (target - own[n]) / act.time_constant
            if act.rate_limit is not None:
                rate = ca.fmin(ca.fmax(rate, -act.rate_limit), act.rate_limit)
            rates.append(rate)
        return own["dp"], own["dy"], rates

    def direction(self, dp, dy) -> ca.SX:
        """The unit thrust direction (parent axes) at the deflections ``dp, dy`` [rad]."""
        a, b, c = (ca.DM(v) for v in gimbal_basis(self.axis))
        return ca.cos(dp) * ca.cos(dy) * a - ca.cos(dp) * ca.sin(dy) * b + ca.sin(dp) * c

    def contribute(self, frame, own) -> Contribution:
        dp, dy, rates = self._deflections(own)
        rho_g = frame.point(self.position)
        loads = [Load(self.thrust * self.direction(dp, dy), frame.velocity(rho_g))]
        bodies = []
        mdot = self.mdot
        if mdot > 0:
            rates.append(-mdot)
            m_p = own["m_p"]
            rho_t = frame.point(self.tank)
            v_t = frame.velocity(rho_t)
            bodies.append(Body(velocity=v_t, angular_velocity=frame.w, momentum=m_p * v_t,
                               angular_momentum=ca.SX.zeros(3), position=rho_t, mass=m_p))
            start = self.tank if self.flow_start is None else self.flow_start
            end = self.position if self.nozzle_exit is None else self.nozzle_exit
            loads.append(coriolis_load(frame, mdot, start, end))
        return Contribution(rates=ca.vertcat(*rates) if rates else None, bodies=bodies,
                            loads=loads)



def gimbaled_engine(scene, engine=None):
    """``(name, part)`` of the gimbaled `Engine` of ``scene`` (the only one, the only gimbaled
    one, or ``engine``).

    Raises
    ------
    ValueError
        Naming ``engine``: no Engine, several and none named, an unknown name, or an engine
        without ``gimbal``.

    Examples
    --------
    >>> from appdyn.dynamics.scene import Engine, RigidHub, Scene
    >>> from appdyn.dynamics.scene.engine import gimbaled_engine
    >>> gimbaled_engine(Scene(RigidHub([1.0, 1.0, 1.0], mass=1.0),
    ...                       Engine(1.0, (-1.0, 0.0, 0.0), gimbal=0.1)))[0]
    'engine'
    """
    names = [n for n, p in zip(scene.part_names, scene.parts) if isinstance(p, Engine)]
    gimbaled = [n for n in names if scene.part(n).gimbal is not None]
    if engine is None and len(names) != 1 and len(gimbaled) == 1:
        engine = gimbaled[0]  # one gimbaled engine (a propellant feed beside it)
    if engine is None and len(names) != 1 or engine is not None and engine not in names:
        raise ValueError(f"`engine` must name one Engine of the scene {names}, got {engine!r}")
    name = engine or names[0]
    part = scene.part(name)
    if part.gimbal is None:
        raise ValueError(f"`engine` {name!r} has no gimbal: give Engine(..., gimbal=...)")
    return name, part
