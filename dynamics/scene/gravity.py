"""Gravity on every body of a scene: `GravityGradient` (a central body of parameter ``mu``).

Each body ``b`` of the scene (the hub's and every part's: mass ``m_b``, inertia ``I_b`` about
its mass centre in hub axes) at ``R_b`` from the central body's centre feels the force and
the torque about its mass centre of the potential (MacCullagh's, to second order in the
body's size)::

    V_b = -mu m_b / |R_b| + mu / (2 |R_b|^3) (3 o.I_b o - tr I_b),    o = -R_b / |R_b|,
    T_b = 3 mu / |R_b|^3  o x I_b o                               (gravity-gradient torque)

(MacCullagh's formula; Hughes, Spacecraft Attitude Dynamics, on gravitational torques; not
in the seeds). How ``R_b`` is known depends on the hub:

Six-degree-of-freedom hub (``RigidHub(..., mass=...)``): ``R_b = A r + rho_b`` in hub axes,
``r`` the reference point's inertial position (the central body at the inertial origin) and
``rho_b`` the body's mass centre from it. The force on each body is the exact gradient
``-dV_b/dR_b`` (point-mass gravity plus the small force of the second-order term), so
``energy`` (with ``V = sum_b V_b``) and ``momentum_inertial`` (about the central body) are
conserved exactly. ``radius`` must not be given: the distance is the state's.

Attitude-only hub: the hub's mass centre (the fixed reference point) is taken on a circular
orbit of ``radius`` ``R`` in the inertial x-y plane, counter-clockwise about ``+z`` at the
mean motion ``n = sqrt(mu / R^3)``, at ``R (cos nt, sin nt, 0)`` at the clock ``t``
(`dynamics.clock`: the part's coordinate ``t`` [s] with ``t' = 1``), so the unit nadir is
``o = A(q) (-cos nt, -sin nt, 0)``. In the freely falling frame of the hub's centre each body
feels the tidal force and the torque above::

    F_b = mu m_b / R^3 (3 o (o.rho_b) - rho_b),    T_b = 3 mu / R^3  o x I_b o,

of ``V_b = -mu m_b / (2 R^3) (3 (o.rho_b)^2 - |rho_b|^2) + mu / (2 R^3) (3 o.I_b o - tr I_b)``
(part of ``energy``, which the turning field does not conserve; the Jacobi integral
``energy - n momentum_inertial[2]`` it does). The hub's centre, not the scene's mass centre,
follows the orbit: an attitude model, exact as the parts' mass moves with respect to the hub
only to the order ``m_parts / m_hub`` of the tidal terms. The local-vertical
local-horizontal frame (``x`` along track, ``z`` to nadir, ``y`` against the orbit normal)
turns at ``-n`` about its ``y``; a hub with principal axes along it librates in pitch as
``I_y theta'' = -3/2 n^2 (I_x - I_z) sin 2 theta``, at ``n sqrt(3 (I_x - I_z) / I_y)`` for
small angles (stable for ``I_x > I_z``).

Bodies without an inertia (a wheel's ``Body``) feel the force on their mass only.
"""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca

from ..validate import positive
from .assembly import turning_frame_dcm
from .contract import Contribution, Load, Part, PartVariables, Variable

__all__ = ["GravityGradient"]


@dataclass(frozen=True, init=False)
class GravityGradient(Part):
    """Gravity of a central body on every body of the scene: forces and gravity-gradient torques.

    Parameters
    ----------
    mu : float [m^3/s^2]
        Gravitational parameter of the central body (Earth: 3.986004418e14), > 0.
    radius : float [m], optional
        Attitude-only hub: the radius of its circular orbit; the part then carries the clock
        state ``t`` [s] (`dynamics.clock`; put the part last). Six-degree-of-freedom hub:
        leave it out (the distance is the hub's position ``r``).
    name : str, optional

    Raises
    ------
    ValueError
        Naming the argument: ``mu`` or ``radius`` not > 0; at assembly, ``radius`` given for a
        six-degree-of-freedom hub or missing for an attitude-only one.

    Notes
    -----
    The module docstring gives the potential, forces and torques and the circular orbit of an
    attitude-only hub. Its orbit's mean motion ``n = sqrt(mu / R^3)`` is `mean_motion`. On a
    hub with a ``reference_rate`` the orbit stays inertial (`assembly.turning_frame_dcm` turns
    it into the reference axes): with ``reference_rate = (0, 0, n)`` the hub's attitude is
    measured from the local-vertical local-horizontal frame, where the nadir is fixed.

    Examples
    --------
    A hub in the local-vertical local-horizontal frame (the orbit starts on the inertial
    ``x`` axis, so the frame's axes are inertial ``(y, -z, -x)``) pitched by 0.1 rad from it
    is pulled back (``I_x > I_z``): ``w2' = -3/2 n^2 (I_x - I_z) sin(0.2) / I_y``:

    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import quat_from_dcm, dcm_axis
    >>> from appdyn.dynamics.scene import GravityGradient, RigidHub, Scene
    >>> gravity = GravityGradient(3.986004418e14, 7.0e6)
    >>> scene = Scene(RigidHub([100.0, 80.0, 40.0]), gravity)
    >>> lvlh = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, -1.0], [-1.0, 0.0, 0.0]])
    >>> q = quat_from_dcm(dcm_axis(2, 0.1) @ lvlh)
    >>> n = gravity.mean_motion
    >>> x = scene.state(q=q, w=[0.0, -n, 0.0])
    >>> scene.model().states[7:]
    ('t',)
    >>> bool(np.isclose(scene.model().rhs(x)[5], -1.5 * n**2 * 60.0 * np.sin(0.2) / 80.0))
    True
    """

    mu: float
    radius: float | None
    name: str | None
    kind = "gravity"
    mountable = False

    def __init__(self, mu, radius=None, *, name=None):
        object.__setattr__(self, "mu", positive(mu, "mu"))
        object.__setattr__(self, "radius", None if radius is None else positive(radius, "radius"))
        object.__setattr__(self, "name", name)

    @property
    def mean_motion(self) -> float | None:
        """``n = sqrt(mu / radius^3)`` [rad/s] of the circular orbit (None without ``radius``)."""
        return None if self.radius is None else (self.mu / self.radius ** 3) ** 0.5

    def variables(self) -> PartVariables:
        if self.radius is None:
            return PartVariables()
        from ..clock import CLOCK_STATE, CLOCK_UNIT
        return PartVariables(coords=(Variable(CLOCK_STATE, CLOCK_UNIT, terminal="free"),))

    def contribute(self, frame, own) -> Contribution:
        return Contribution(rates=ca.SX.ones(own.coords.numel()))

    def field_loads(self, frame, bodies, own) -> Contribution:
        if frame.r is not None and self.radius is not None:
            raise ValueError("GravityGradient `radius` applies to an attitude-only hub; a "
                             "six-degree-of-freedom hub's distance is its position r: leave "
                             "`radius` out")
        if frame.r is None and self.radius is None:
            raise ValueError("GravityGradient on an attitude-only hub needs `radius` (the "
                             "circular orbit of the hub's centre), or give the hub a `mass`")
        rho = ca.SX.sym("rho", 3)
        o, k = self.nadir(frame, rho, None if frame.r is not None else own.coords[0])
        loads, total = [], 0.0
        for b in bodies:
            if frame.r is not None:  # point mass: -mu m / |R|
                V = -self.mu * b.mass / ca.norm_2(ca.mtimes(frame.dcm, frame.r) + rho)
            else:  # tidal about the hub's centre, on its circular orbit
                V = -0.5 * k * b.mass * (3 * ca.dot(o, rho) ** 2 - ca.dot(rho, rho))
            if b.inertia is not None:
                I = ca.SX(b.inertia)
                Io = ca.mtimes(I, o)
                V = V + 0.5 * k * (3 * ca.dot(o, Io) - ca.trace(I))
                torque = ca.substitute(3 * k * ca.cross(o, Io), rho, b.position)
                loads.append(Load(torque, b.angular_velocity))
            force = ca.substitute(-ca.gradient(V, rho), rho, b.position)
            loads.append(Load(force, b.velocity))
            total = total + ca.substitute(V, rho, b.position)
        return Contribution(loads=loads, potential=total)

    def nadir(self, frame, rho, t=None):
        """The unit nadir ``o`` (hub axes) at a point ``rho`` from the hub's reference point,
        and ``mu / R^3`` there (the hub's orbit ``radius`` without ``mass``).

        Parameters
        ----------
        frame : Frame
        rho : SX, 3x1 [m]
        t : SX scalar [s], optional
            The clock (attitude-only hub).

        Returns
        -------
        o : SX, 3x1
        k : SX or float [1/s^2]
        """
        if frame.r is None:
            n = self.mean_motion
            o = ca.vertcat(-ca.cos(n * t), -ca.sin(n * t), 0.0)  # inertial axes
            if frame.reference_rate is not None:  # the hub's attitude is from a turning frame
                o = ca.mtimes(turning_frame_dcm(frame.reference_rate, t), o)
            return ca.mtimes(frame.dcm, o), self.mu / self.radius ** 3
        R = ca.mtimes(frame.dcm, frame.r) + rho
        dist = ca.norm_2(R)
        return -R / dist, self.mu / dist ** 3
