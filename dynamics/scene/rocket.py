"""The thrust-vectored launch vehicle as a six-degree-of-freedom scene: `launch_vehicle_scene`.

The yaw-plane model of `dynamics.launch_vehicle` takes its parts (`Aero`, `MassFlow`,
`Actuator`) as plain numbers; here the same numbers build a `Scene`: a `RigidHub` with the
vehicle's mass and inertia (axisymmetric: ``inertia`` in pitch and yaw, ``roll_inertia`` about
the axis ``x``), an `Engine` at ``(-arm, 0, 0)`` gimbaled in pitch and yaw, and
`Aerodynamics` at ``(cp_arm, 0, 0)``. The propellant sits at the mass centre, so the inertia
is the given one at the reference mass, as in the planar model. Restricted to the yaw plane
(``psi`` about ``z``, ``dp = 0``) the scene's right-hand side is the planar one: ``x' = r1'``,
``x'' = (A^T (v' + w x v))_1``, ``psi'' = w3'``, ``delta = dy``
(`tests/dynamics/scene/test_engine_aero.py`).

The planar aero holds the dynamic pressure fixed; the scene computes it from the air speed,
so the density is chosen to give ``dynamic_pressure`` at ``velocity`` (the flight speed the
stability cases linearize at).

Slosh (a pendulum): the planar model measures its stations from ``O``, the mass centre with
the propellant at rest; the hub here is the rigid part (mass ``m - m_s`` at
``rho_r = -(m_s / m_r) rho0`` from ``O``, inertia ``I_r`` of
`dynamics.launch_vehicle.vehicle.rigid_part`), its reference point is ``O``, and the
pendulum (`dynamics.scene.Slosh`, hanging aft, ``theta1 = -theta_s`` in the yaw plane)
swings in pitch and yaw; its hinge damping is the planar one at the reference mass,
``c = 2 zeta m_s L^2 sqrt(F / (m L))``. The planar spring-mass has no two-axis scene part
yet, nor the bending mode. With slosh the aerodynamic angle of attack is that of the rigid
part's mass centre (the planar model's is of the whole vehicle's).
"""
from __future__ import annotations

import math

from ..launch_vehicle.parts import Aero, MassFlow
from ..launch_vehicle.parts import Slosh as PlanarSlosh
from ..validate import positive
from .aero import Aerodynamics
from .dampers import Slosh
from .engine import Engine, gimbaled_engine
from .hubs import RigidHub
from .scene import Scene

__all__ = ["launch_vehicle_scene", "attitude_autopilot"]


def launch_vehicle_scene(*, thrust, inertia, arm, mass, roll_inertia=None, aero=None,
                         velocity=None, mass_flow=None, slosh=None, actuator=None,
                         gimbal=0.2) -> Scene:
    """The launch vehicle of `dynamics.launch_vehicle` in six degrees of freedom.

    Parameters
    ----------
    thrust : float [N]
    inertia : float [kg m^2]
        Pitch and yaw inertia about the mass centre (at ``mass``).
    arm : float [m]
        Mass centre to the gimbal (aft).
    mass : float [kg]
        Vehicle mass, propellant included.
    roll_inertia : float [kg m^2], optional
        About the axis (default ``inertia / 40``).
    aero : dynamics.launch_vehicle.Aero, optional
        Its ``dynamic_pressure`` is reached at ``velocity``; its ``wind`` mode ``'control'``
        gives the controls ``wind1..wind3``.
    velocity : float [m/s], optional
        Flight speed of ``aero`` (needed with it).
    mass_flow : dynamics.launch_vehicle.MassFlow, optional
        Rate, ``flow_start``, ``nozzle_exit``; the propellant ``mass_flow.rate *
        burn_time`` (or half the mass) is the state ``m_p`` at the mass centre.
    slosh : dynamics.launch_vehicle.Slosh, optional
        A pendulum (module docstring); its ``mass`` is part of ``mass``.
    actuator : dynamics.launch_vehicle.Actuator, optional
    gimbal : float [rad], optional
        Deflection bound of the controls (or commands).

    Returns
    -------
    Scene
        Parts ``engine``, with ``aero`` ``aero`` (air velocity of the mass centre, as the
        planar model), with ``slosh`` ``slosh``.

    Raises
    ------
    ValueError
        Naming the argument (non-positive numbers, ``velocity`` missing with ``aero``, a
        spring-mass ``slosh``, a slosh mass not below ``mass``).
    TypeError
        If a part is not of its class.

    Examples
    --------
    >>> from appdyn.dynamics.launch_vehicle import Aero
    >>> from appdyn.dynamics.scene import launch_vehicle_scene
    >>> scene = launch_vehicle_scene(thrust=2.0e6, inertia=4.0e7, arm=20.0, mass=1.0e5,
    ...                              aero=Aero(3.0e4, 10.0, 3.0, 5.0), velocity=400.0)
    >>> scene.part_names, scene.model().controls
    (('engine', 'aero'), ('dp', 'dy'))
    """
    F, I, l, m = (positive(v, n) for v, n in ((thrust, "thrust"), (inertia, "inertia"),
                                              (arm, "arm"), (mass, "mass")))
    I_roll = I / 40.0 if roll_inertia is None else positive(roll_inertia, "roll_inertia")
    for part, cls, label in ((aero, Aero, "aero"), (mass_flow, MassFlow, "mass_flow"),
                             (slosh, PlanarSlosh, "slosh")):
        if part is not None and not isinstance(part, cls):
            raise TypeError(f"`{label}` must be a dynamics.launch_vehicle.{cls.__name__}, "
                            f"got {type(part).__name__}")
    m_hub, I_hub, shift, slosh_parts = m, I, 0.0, []
    if slosh is not None:
        from ..launch_vehicle.vehicle import rigid_part
        if slosh.kind != "pendulum":
            raise ValueError("`slosh`: only a pendulum has a scene part in pitch and yaw; a "
                             "planar spring-mass is not mapped yet")
        m_hub, _, I_hub = rigid_part(slosh, m, I)
        rho0 = slosh.hinge - slosh.length
        shift = slosh.mass / m_hub * rho0  # O from the rigid part's mass centre
        L = slosh.length
        slosh_parts.append(Slosh(slosh.mass, length=L, hinge=(slosh.hinge + shift, 0.0, 0.0),
                                 direction=(-1.0, 0.0, 0.0),
                                 damping=2.0 * slosh.damping_ratio * slosh.mass * L ** 2
                                 * math.sqrt(F / (m * L))))

    def station(s):
        """A station along the axis (from ``O``, ahead positive) as a hub point."""
        return (s + shift, 0.0, 0.0)

    engine = dict(gimbal=gimbal, actuator=actuator)
    if mass_flow is not None:
        burn = mass_flow.burn_time
        mp = mass_flow.rate * burn if burn is not None else 0.5 * m_hub
        m_hub = m_hub - mp
        engine.update(mass_flow=mass_flow.rate, propellant=mp, tank=station(-shift),
                      flow_start=station(-mass_flow.flow_start),
                      nozzle_exit=None if mass_flow.nozzle_exit is None else station(
                          -mass_flow.nozzle_exit))
    parts = [Engine(F, station(-l), **engine)]
    if aero is not None:
        if velocity is None:
            raise ValueError("`velocity` is needed with `aero` (its dynamic pressure is "
                             "reached at that flight speed)")
        V = positive(velocity, "velocity")
        parts.append(Aerodynamics(aero.area, aero.normal_force_slope,
                                  centre_of_pressure=station(aero.cp_arm),
                                  density=2.0 * aero.dynamic_pressure / V ** 2,
                                  wind="control" if aero.wind == "control" else "zero",
                                  air_velocity="mass_centre"))
    elif velocity is not None:
        raise ValueError("`velocity` is the flight speed of `aero`; give it only with `aero`")
    parts += slosh_parts
    reference = None if slosh is None else (shift, 0.0, 0.0)
    return Scene(RigidHub([I_roll, I_hub, I_hub], mass=m_hub, reference=reference), *parts,
                 name="launch_vehicle")


def attitude_autopilot(scene, *, k_psi, k_psidot, engine=None):
    """The launch vehicle's attitude/rate autopilot in pitch and yaw, ``u = k(x)``.

    ``dp = -(k_psi theta + k_psidot w2)``, ``dy = -(k_psi psi + k_psidot w3)`` with the
    hub's pitch and yaw angles ``theta = 2 atan2(q2, q4)``, ``psi = 2 atan2(q3, q4)``
    (exact for a turn about one axis, the planar model's ``psi``; the small-angle ``2 q2``,
    ``2 q3`` of `problems.stability.vehicle_loops` to first order); the deflections, or their
    commands with an actuator; every other control (wind) zero.

    Parameters
    ----------
    scene : Scene
        With an `Engine` gimbaled in pitch and yaw.
    k_psi : float [rad/rad]
    k_psidot : float [rad/(rad/s)]
    engine : str, optional
        The engine's name (needed with several).

    Returns
    -------
    casadi.Function
        ``autopilot(x) -> u`` for `dynamics.closed_loop`.

    Raises
    ------
    TypeError
        If ``scene`` is not a Scene.
    ValueError
        Naming ``engine`` (none, several, or no ``gimbal``) or a non-finite gain.

    Examples
    --------
    >>> from appdyn.dynamics import closed_loop
    >>> from appdyn.dynamics.scene import attitude_autopilot, launch_vehicle_scene
    >>> scene = launch_vehicle_scene(thrust=2.0e6, inertia=4.0e7, arm=20.0, mass=1.0e5)
    >>> law = attitude_autopilot(scene, k_psi=2.0, k_psidot=1.0)
    >>> x = scene.state(q=[0.0, 0.0, 0.0499792, 0.99875])  # 0.1 rad of yaw
    >>> [round(float(v), 6) for v in law(x).full().ravel()]  # dp, dy
    [-0.0, -0.2]
    """
    import casadi as ca

    from ..validate import finite_scalar
    from .scene import check_scene

    scene = check_scene(scene)
    k, kd = finite_scalar(k_psi, "k_psi"), finite_scalar(k_psidot, "k_psidot")
    name, part = gimbaled_engine(scene, engine)
    model = scene.model()
    x = ca.SX.sym("x", model.nx)
    theta = 2 * ca.atan2(x[1], x[3])
    psi = 2 * ca.atan2(x[2], x[3])
    local = scene.variable_names()["local"][name]
    tail = "" if part.actuator is None else "_c"
    law = {local["dp" + tail]: -(k * theta + kd * x[5]), local["dy" + tail]: -(k * psi + kd * x[6])}
    u = ca.vertcat(*[law.get(c, ca.SX(0)) for c in model.controls])
    return ca.Function("autopilot", [x], [u], ["x"], ["u"])
