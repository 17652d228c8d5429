"""The opt-in parts of `dynamics.launch_vehicle`: small frozen dataclasses, checked on creation.

Every length is measured along the vehicle axis from the vehicle mass centre *with the
propellant at rest* (slosh at its neutral position): stations ``hinge`` and ``cp_arm`` are
positive *ahead* of it, the engine distances ``arm``, ``flow_start`` and ``nozzle_exit``
positive *aft* of it. Each part holds plain floats (and strings), so it is hashable and
serves as a cache key.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..validate import finite_array, finite_scalar, one_of, positive

__all__ = ["Aero", "MassFlow", "Slosh", "Bending", "Actuator", "WIND_MODES"]

#: How the wind velocity enters an `Aero` model: as parameters (constant over a run, e.g. a
#: step gust from t = 0) or as controls (any gust history through ``simulate(u=...)``).
WIND_MODES = ("parameter", "control")


def _set(part, name, value):
    object.__setattr__(part, name, value)


def _non_negative(part, name):
    value = finite_scalar(getattr(part, name), f"{type(part).__name__}.{name}")
    if value < 0:
        raise ValueError(f"`{type(part).__name__}.{name}` must be >= 0, got {value!r}")
    _set(part, name, value)


def _check(part, positives=(), finites=(), non_negatives=(), optional_positives=()):
    label = type(part).__name__
    for name in positives:
        _set(part, name, positive(getattr(part, name), f"{label}.{name}"))
    for name in finites:
        _set(part, name, finite_scalar(getattr(part, name), f"{label}.{name}"))
    for name in non_negatives:
        _non_negative(part, name)
    for name in optional_positives:
        if getattr(part, name) is not None:
            _set(part, name, positive(getattr(part, name), f"{label}.{name}"))


@dataclass(frozen=True)
class Aero:
    """Aerodynamic normal force at a centre of pressure (quasi-steady, frozen flight condition).

    Parameters
    ----------
    dynamic_pressure : float [Pa]
        ``q > 0``, held at the flight condition studied (e.g. max-q).
    area : float [m^2]
        Reference area ``S > 0``.
    normal_force_slope : float [1/rad]
        ``C_N_alpha > 0``; the normal force is ``N = q S C_N_alpha alpha``.
    cp_arm : float [m]
        Centre of pressure ahead of the mass centre (> 0: aerodynamically unstable airframe;
        < 0: behind it, stable).
    wind : {'parameter', 'control'}
        The inertial wind velocity ``(wind_x, wind_y)`` [m/s] enters as two parameters
        (default 0) or as two controls.

    Examples
    --------
    >>> from appdyn.dynamics.launch_vehicle import Aero
    >>> Aero(dynamic_pressure=3.0e4, area=10.0, normal_force_slope=3.0, cp_arm=5.0).wind
    'parameter'
    """

    dynamic_pressure: float
    area: float
    normal_force_slope: float
    cp_arm: float
    wind: str = "parameter"

    def __post_init__(self):
        _check(self, positives=("dynamic_pressure", "area", "normal_force_slope"),
               finites=("cp_arm",))
        one_of(self.wind, "Aero.wind", WIND_MODES)


@dataclass(frozen=True)
class MassFlow:
    """Variable mass: constant mass flow, thrust ``F = rate * exhaust_velocity``, jet damping.

    Parameters
    ----------
    rate : float [kg/s]
        Mass flow ``mdot > 0`` out of the nozzle; ``mass' = -rate``.
    exhaust_velocity : float [m/s], optional
        ``v_e``; ``rate * v_e`` must equal the vehicle's ``thrust``. Omitted: ``thrust / rate``.
    flow_start : float [m]
        ``l1`` of Eq. 3.49: where the internal flow starts, aft of the mass centre (negative:
        ahead of it).
    nozzle_exit : float [m], optional
        ``l2`` of Eq. 3.49: the nozzle exit plane aft of the mass centre, ``>= flow_start``.
        Omitted: at the gimbal (``l2 = arm``).
    burn_time : float [s], optional
        When given, the vehicle must not empty (nor the slosh model break down) within it.

    Examples
    --------
    >>> from appdyn.dynamics.launch_vehicle import MassFlow
    >>> MassFlow(rate=250.0, flow_start=-2.0, burn_time=100.0).nozzle_exit is None
    True
    """

    rate: float
    exhaust_velocity: float | None = None
    flow_start: float = 0.0
    nozzle_exit: float | None = None
    burn_time: float | None = None

    def __post_init__(self):
        _check(self, positives=("rate",), finites=("flow_start",),
               optional_positives=("exhaust_velocity", "burn_time"))
        if self.nozzle_exit is not None:
            _set(self, "nozzle_exit", finite_scalar(self.nozzle_exit, "MassFlow.nozzle_exit"))
            if self.nozzle_exit < self.flow_start:
                raise ValueError(f"`MassFlow.nozzle_exit` ({self.nozzle_exit!r} m) must be at or "
                                 f"aft of `MassFlow.flow_start` ({self.flow_start!r} m)")


@dataclass(frozen=True)
class Slosh:
    """One planar propellant-slosh mode: a pendulum or a spring-mass (Ch. 6, Example 3).

    Give exactly one of ``length`` (pendulum) and ``frequency`` (spring-mass).

    Parameters
    ----------
    mass : float [kg]
        Slosh mass ``m_s >= 0`` (part of the vehicle's ``mass``). ``0`` keeps the vehicle
        rigid: the slosh states then follow the vehicle without acting on it.
    hinge : float [m]
        Pendulum hinge, or the station of the spring-mass, ahead of the mass centre.
    length : float [m], optional
        Pendulum length ``L > 0``; the mass hangs aft of the hinge when at rest (axial
        acceleration ``a = F/m`` gives the held frequency ``sqrt(a/L)``).
    frequency : float [rad/s], optional
        Spring-mass frequency with the vehicle held, ``sqrt(k/m_s)``; the spring constant
        is ``stiffness = m_s frequency^2``.
    damping_ratio : float
        ``zeta >= 0`` of the held oscillator: hinge torque ``-2 zeta m_s L^2 sqrt(a/L)
        theta_s'`` (pendulum) or force ``-2 zeta m_s frequency r_s'`` (spring-mass).

    Examples
    --------
    >>> from appdyn.dynamics.launch_vehicle import Slosh
    >>> Slosh(mass=2000.0, hinge=3.0, frequency=2.0).stiffness  # N/m
    8000.0
    """

    mass: float
    hinge: float
    length: float | None = None
    frequency: float | None = None
    damping_ratio: float = 0.0

    def __post_init__(self):
        _check(self, finites=("hinge",), non_negatives=("mass", "damping_ratio"),
               optional_positives=("length", "frequency"))
        if (self.length is None) == (self.frequency is None):
            raise ValueError("`Slosh` needs exactly one of `length` (pendulum) and `frequency` "
                             f"(spring-mass), got length={self.length!r}, "
                             f"frequency={self.frequency!r}")

    @property
    def kind(self) -> str:
        """``'pendulum'`` or ``'spring'``."""
        return "pendulum" if self.length is not None else "spring"

    @property
    def stiffness(self) -> float | None:
        """Spring constant ``k = m_s frequency^2`` [N/m] (``None`` for a pendulum)."""
        return None if self.frequency is None else self.mass * self.frequency ** 2


@dataclass(frozen=True)
class Bending:
    """One free-free bending mode (modal synthesis, Ch. 6, Eqs. 6.33-6.41).

    The mode coordinate ``eta`` [m] scales a dimensionless mode shape ``phi(s)``; slopes are
    ``sigma = dphi/ds`` [rad/m] (positive: the local section turns like ``psi``).

    Parameters
    ----------
    frequency : float [rad/s]
        ``omega_b > 0``.
    generalized_mass : float [kg]
        ``M_b = integral of phi^2 dm > 0``.
    damping_ratio : float
        ``zeta_b >= 0``.
    slope_sensor : float [rad/m]
        ``sigma_s``: the gyros read ``psi + sigma_s eta`` and ``psi_dot + sigma_s eta_dot``.
    deflection_gimbal : float [-]
        ``phi_g``: lateral deflection of the gimbal per unit ``eta``.
    slope_gimbal : float [rad/m]
        ``sigma_g``: rotation of the engine mount per unit ``eta``.

    Examples
    --------
    >>> from appdyn.dynamics.launch_vehicle import Bending
    >>> Bending(frequency=12.0, generalized_mass=5000.0, slope_sensor=0.02).damping_ratio
    0.0
    """

    frequency: float
    generalized_mass: float
    damping_ratio: float = 0.0
    slope_sensor: float = 0.0
    deflection_gimbal: float = 0.0
    slope_gimbal: float = 0.0

    def __post_init__(self):
        _check(self, positives=("frequency", "generalized_mass"),
               finites=("slope_sensor", "deflection_gimbal", "slope_gimbal"),
               non_negatives=("damping_ratio",))


@dataclass(frozen=True)
class Actuator:
    """First-order gimbal actuator ``delta' = (delta_command - delta) / time_constant``.

    Limits are hard clamps in the right-hand side: the command is clamped to
    ``deflection_limits`` and then the rate to ``+-rate_limit``, so a deflection that starts
    inside the limits stays inside.

    Parameters
    ----------
    time_constant : float [s]
        ``tau > 0``.
    deflection_limits : (float, float) [rad], optional
        ``(lower, upper)`` with ``lower < upper``.
    rate_limit : float [rad/s], optional
        ``> 0``.

    Examples
    --------
    >>> from appdyn.dynamics.launch_vehicle import Actuator
    >>> Actuator(0.05, deflection_limits=(-0.1, 0.1), rate_limit=0.5).deflection_limits
    (-0.1, 0.1)
    """

    time_constant: float
    deflection_limits: tuple[float, float] | None = None
    rate_limit: float | None = None

    def __post_init__(self):
        _check(self, positives=("time_constant",), optional_positives=("rate_limit",))
        if self.deflection_limits is not None:
            lo, hi = finite_array(self.deflection_limits, "Actuator.deflection_limits", (2,))
            if not lo < hi:
                raise ValueError("`Actuator.deflection_limits` must be (lower, upper) with "
                                 f"lower < upper, got {self.deflection_limits!r}")
            _set(self, "deflection_limits", (float(lo), float(hi)))

