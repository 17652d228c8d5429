"""Aerodynamic loads on a six-degree-of-freedom hub: `Aerodynamics`.

A quasi-steady normal and axial force at a centre of pressure (the launch vehicle's model,
`dynamics.launch_vehicle`, now in three dimensions). The air-relative velocity of the centre
of pressure in the parent's axes is ``v_a = v + w x rho_cp - A w_i`` (``w_i`` the inertial
wind, zero or the controls ``wind1..wind3``); its total angle of attack ``alpha_T`` and roll
angle ``phi_R`` (`dynamics.attitude.total_aoa`, seed Sec. 4.3 E) set the normal force, the
dynamic pressure ``qbar = 1/2 rho |v_a|^2`` its size::

    axial   X = -qbar S C_A                                  (along -x, the body axis)
    normal  N = -qbar S C_N_alpha alpha_T (0, sin phi_R, cos phi_R)
              = -qbar S C_N_alpha (alpha_T / |v_c|) (0, v_ay, v_az),   v_c = (v_ay, v_az),

opposite the crossflow. The second form is the one evaluated: ``alpha_T / |v_c|`` is an even
analytic function of ``|v_c|`` (``atan(t)/t``, ``t = |v_c| / v_ax``, by its series near the
axis), so the force and its derivatives are exact at zero crossflow, where the linearizations
of straight flight are taken. In the yaw plane (``v_az = 0``, ``v_ax > 0``) the normal force is
``qbar S C_N_alpha atan2(-v_ay, v_ax)`` along ``+y``: the launch vehicle's ``alpha`` and
``f_A``, except that the launch vehicle takes the air velocity of the mass centre:
``air_velocity="mass_centre"`` does the same here (no aerodynamic damping from the turning
rate), and the yaw-plane restriction then equals that model. The density is constant or an
exponential atmosphere ``rho0 exp(-h / H)`` in the altitude ``h = up . r`` of the hub's
reference point.
"""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca

from ..validate import finite_array, one_of
from .contract import Contribution, Load, Part, PartVariables, Variable
from .dampers import real_number, unit_vector

__all__ = ["Aerodynamics", "require_translating_hub", "crossflow_gain"]

_SERIES = 1e-6  # (|v_c| / v_ax)^2 below which atan(t)/t is its series (error < t^6/7)


def require_translating_hub(frame, part: str):
    """``frame`` if its hub has six degrees of freedom; a ValueError naming the part otherwise.

    Examples
    --------
    >>> from appdyn.dynamics.scene import Aerodynamics, RigidHub, Scene
    >>> Scene(RigidHub([1.0, 1.0, 1.0]), Aerodynamics(1.0, 2.0)).model()
    Traceback (most recent call last):
        ...
    ValueError: `Aerodynamics` needs a six-degree-of-freedom hub: ...
    """
    if frame.r is None:
        raise ValueError(f"`{part}` needs a six-degree-of-freedom hub: give the hub a mass, "
                         "RigidHub(inertia, mass=...)")
    return frame


def crossflow_gain(v_axial, crossflow_sq):
    """``alpha_T / |v_c| = atan2(|v_c|, v_x) / |v_c|`` [s/m], analytic at zero crossflow.

    Parameters
    ----------
    v_axial : CasADi scalar [m/s]
        ``v_x``, the air velocity along the body axis.
    crossflow_sq : CasADi scalar [m^2/s^2]
        ``|v_c|^2 = v_y^2 + v_z^2``.

    Returns
    -------
    CasADi scalar
        ``1/v_x (1 - t^2/3 + t^4/5)`` for ``t^2 = |v_c|^2 / v_x^2 < 1e-6`` and ``v_x > 0``,
        else the quotient (``|v_c| = 0`` with ``v_x <= 0``, flight backwards along the axis,
        has no normal direction: 0).

    Examples
    --------
    >>> import casadi as ca
    >>> from appdyn.dynamics.scene.aero import crossflow_gain
    >>> float(crossflow_gain(ca.DM(100.0), ca.DM(0.0)))  # 1 / v_x
    0.01
    """
    t2 = crossflow_sq / ca.if_else(v_axial > 0, v_axial ** 2, 1.0)
    series = (1 - t2 / 3 + t2 ** 2 / 5) / ca.if_else(v_axial > 0, v_axial, 1.0)
    c_safe = ca.sqrt(ca.if_else(crossflow_sq > 0, crossflow_sq, 1.0))
    quotient = ca.if_else(crossflow_sq > 0, ca.atan2(c_safe, v_axial) / c_safe, 0.0)
    return ca.if_else(ca.logic_and(v_axial > 0, t2 < _SERIES), series, quotient)


@dataclass(frozen=True)
class Aerodynamics(Part):
    """Normal and axial aerodynamic force at a centre of pressure (module docstring).

    Needs a six-degree-of-freedom hub (``RigidHub(inertia, mass=...)``): the air velocity is
    that of the vehicle.

    Parameters
    ----------
    area : float [m^2]
        Reference area ``S > 0``.
    normal_force_slope : float [1/rad]
        ``C_N_alpha >= 0``: ``N = qbar S C_N_alpha alpha_T``.
    axial_force : float [-], optional
        ``C_A`` (default 0): ``X = qbar S C_A`` along ``-x``.
    centre_of_pressure : array_like, shape (3,) [m], optional
        On the parent, from the hub's mass centre (default the mass centre).
    density : float [kg/m^3], optional
        Air density (at zero altitude with ``scale_height``); default 1.225.
    scale_height : float [m], optional
        ``H`` of the exponential atmosphere ``rho = density exp(-h / H)``; None: constant.
    up : array_like, shape (3,), optional
        The inertial direction of the altitude ``h = up . r`` (default ``(0, 0, 1)``).
    wind : {'zero', 'control'}, optional
        The inertial wind: none, or the controls ``wind1..wind3`` [m/s] (inertial axes). On
        a hub with a ``reference_rate`` the air is at rest in the turning frame (velocity
        ``Omega x r``) and the wind is relative to it, in its axes.
    air_velocity : {'centre_of_pressure', 'mass_centre'}, optional
        Whose velocity sets the angle of attack: the centre of pressure's (default: with the
        aerodynamic damping of the turning rate) or the hub's mass centre's (the launch
        vehicle's quasi-steady model).
    parent : str, optional
        The scene name of the part it sits on (None: the hub).
    name : str, optional

    Raises
    ------
    ValueError
        Naming the argument: a non-positive ``area`` or ``density``, a negative slope, a
        bad point or direction, an unknown ``wind``; at assembly, a hub without mass.

    Examples
    --------
    A vehicle flying along ``x`` at 100 m/s with the centre of pressure 2 m ahead of its mass
    centre; a side velocity of 5 m/s (``alpha_T = atan(5/100)``) pushes the nose to ``-y``,
    away from the velocity (the centre of pressure ahead: unstable):

    >>> import numpy as np
    >>> from appdyn.dynamics.scene import Aerodynamics, RigidHub, Scene
    >>> scene = Scene(RigidHub([10.0, 100.0, 100.0], mass=500.0),
    ...               Aerodynamics(0.5, 3.0, centre_of_pressure=(2.0, 0.0, 0.0)))
    >>> xdot = scene.model().rhs(scene.state(v=[100.0, 5.0, 0.0]), [])
    >>> qS = 0.5 * 1.225 * (100.0 ** 2 + 5.0 ** 2) * 0.5
    >>> bool(np.isclose(xdot[11], -qS * 3.0 * np.arctan(0.05) / 500.0))  # m v2' = N_y
    True
    >>> round(float(xdot[6]), 6)  # w3' = 2 m x N_y / I3 < 0
    -9.202805
    """

    area: float
    normal_force_slope: float
    axial_force: float = 0.0
    centre_of_pressure: tuple = (0.0, 0.0, 0.0)
    density: float = 1.225
    scale_height: float | None = None
    up: tuple = (0.0, 0.0, 1.0)
    wind: str = "zero"
    air_velocity: str = "centre_of_pressure"
    parent: str | None = None
    name: str | None = None
    kind = "aero"

    def __post_init__(self):
        setf = object.__setattr__
        setf(self, "area", real_number(self.area, "area", positive=True))
        setf(self, "normal_force_slope",
             real_number(self.normal_force_slope, "normal_force_slope", nonnegative=True))
        setf(self, "axial_force", real_number(self.axial_force, "axial_force"))
        setf(self, "centre_of_pressure", tuple(
            finite_array(self.centre_of_pressure, "centre_of_pressure", (3,)).tolist()))
        setf(self, "density", real_number(self.density, "density", positive=True))
        if self.scale_height is not None:
            setf(self, "scale_height", real_number(self.scale_height, "scale_height",
                                                   positive=True))
        setf(self, "up", tuple(unit_vector(self.up, "up").tolist()))
        setf(self, "wind", one_of(self.wind, "wind", ("zero", "control")))
        setf(self, "air_velocity", one_of(self.air_velocity, "air_velocity",
                                          ("centre_of_pressure", "mass_centre")))

    def variables(self) -> PartVariables:
        if self.wind == "zero":
            return PartVariables()
        return PartVariables(controls=tuple(Variable(f"wind{i}", "m/s") for i in (1, 2, 3)))

    def air_density(self, frame):
        """``rho`` [kg/m^3] at the hub's reference point (constant or exponential)."""
        if self.scale_height is None:
            return self.density
        h = ca.dot(ca.DM(self.up), frame.r)
        return self.density * ca.exp(-h / self.scale_height)

    def force(self, v_air, rho):
        """The aerodynamic force [N] (parent axes) for the air velocity ``v_air`` [m/s]
        (parent axes, 3x1) and the density ``rho`` (module docstring)."""
        qbar_S = 0.5 * rho * ca.sumsqr(v_air) * self.area
        k = crossflow_gain(v_air[0], v_air[1] ** 2 + v_air[2] ** 2)
        cn = qbar_S * self.normal_force_slope * k
        return ca.vertcat(-qbar_S * self.axial_force, -cn * v_air[1], -cn * v_air[2])

    def contribute(self, frame, own) -> Contribution:
        require_translating_hub(frame, "Aerodynamics")
        if self.air_velocity == "mass_centre" and not frame.is_hub:
            raise ValueError("`air_velocity='mass_centre'` reads the hub's mass centre: an "
                             "Aerodynamics on another part (`parent`) needs "
                             "air_velocity='centre_of_pressure'")
        rho_cp = frame.point(self.centre_of_pressure)
        v_cp = frame.velocity(rho_cp)
        at = rho_cp if self.air_velocity == "centre_of_pressure" else frame.point((0.0, 0.0, 0.0))
        v_air = frame.velocity(at)
        if frame.reference_rate is not None:  # the air is at rest in the turning frame
            r_at = frame.r + ca.mtimes(frame.dcm.T, at)
            v_air = v_air - ca.mtimes(frame.dcm, ca.cross(ca.DM(frame.reference_rate), r_at))
        if self.wind == "control":
            v_air = v_air - ca.mtimes(frame.dcm, own.controls)
        return Contribution(loads=[Load(self.force(v_air, self.air_density(frame)), v_cp)])

