"""The data of a launch-vehicle gain design (`problems.gains.launch_vehicle`): the vehicle, the
scenarios, the weights and gain bounds, and their checks."""
from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import Mapping, Sequence

import numpy as np

from appdyn.dynamics.launch_vehicle import Actuator, Aero
from appdyn.dynamics.validate import finite_scalar, positive

__all__ = ["WEIGHT_KEYS", "DEFAULT_WEIGHTS", "GM_INF", "GAIN_UNITS", "LaunchVehicle",
           "LaunchScenario", "check_weights", "check_gain_bounds", "check_scenarios",
           "guess_gains"]


#: keys of ``weights``: the running-cost terms
WEIGHT_KEYS = ("psi", "psi_dot", "delta", "delta_rate")
DEFAULT_WEIGHTS = {"psi": 1.0, "psi_dot": 0.0, "delta": 1.0, "delta_rate": 0.0}
#: gain margins above this factor are phase crossovers at numerically infinite frequency
GM_INF = 1e8
GAIN_UNITS = {"k_psi": "rad/rad", "k_psidot": "rad/(rad/s)", "k_i": "rad/(rad s)"}


@dataclass(frozen=True)
class LaunchVehicle:
    """The vehicle data of a launch-vehicle gain design (frozen flight condition).

    Parameters
    ----------
    thrust : float [N]
        ``F > 0``.
    inertia : float [kg m^2]
        ``I > 0`` about the mass centre.
    arm : float [m]
        ``l > 0``, mass centre to the gimbal (aft).
    mass : float [kg]
        ``m > 0``.
    aero : dynamics.launch_vehicle.Aero, optional
        Normal force at the centre of pressure (``cp_arm > 0``: unstable airframe). Its
        ``wind`` mode is ignored (the design sets the wind per scenario).
    velocity : float [m/s], optional
        Flight speed ``V > 0``; required with ``aero`` and only there.
    actuator : dynamics.launch_vehicle.Actuator, optional
        First-order gimbal; its clamps (``deflection_limits``, ``rate_limit``) act in the
        verifying re-simulation, not in the design model.

    Slosh, bending and mass flow (`dynamics.launch_vehicle`'s other parts) are not part of
    the design model.

    Raises
    ------
    ValueError
        Naming the field: a number not finite and positive, ``velocity`` missing with
        ``aero`` or given without it.
    TypeError
        If ``aero`` / ``actuator`` is not an `Aero` / `Actuator`.

    Examples
    --------
    >>> from appdyn.dynamics.launch_vehicle import Aero
    >>> v = LaunchVehicle(2e6, 4e7, 20.0, 1e5, aero=Aero(3e4, 10.0, 3.0, 5.0), velocity=300.0)
    >>> round(v.aero_gain_bound, 4)  # q S C_N_alpha l_cp / (F l)
    0.1125
    """

    thrust: float
    inertia: float
    arm: float
    mass: float
    aero: Aero | None = None
    velocity: float | None = None
    actuator: Actuator | None = None

    def __post_init__(self):
        for name in ("thrust", "inertia", "arm", "mass"):
            object.__setattr__(self, name, positive(getattr(self, name), name))
        if self.aero is not None and not isinstance(self.aero, Aero):
            raise TypeError(f"`aero` must be a dynamics.launch_vehicle.Aero or None, got "
                            f"{type(self.aero).__name__}")
        if self.actuator is not None and not isinstance(self.actuator, Actuator):
            raise TypeError(f"`actuator` must be a dynamics.launch_vehicle.Actuator or None, "
                            f"got {type(self.actuator).__name__}")
        if self.aero is None and self.velocity is not None:
            raise ValueError("`velocity` is the flight speed of `aero`; give it only with `aero`")
        if self.aero is not None:
            if self.velocity is None:
                raise ValueError("`velocity` is needed with `aero` (alpha = psi - y_dot / V)")
            object.__setattr__(self, "velocity", positive(self.velocity, "velocity"))
            if self.aero.wind != "parameter":
                object.__setattr__(self, "aero", replace(self.aero, wind="parameter"))

    @classmethod
    def coerce(cls, vehicle) -> "LaunchVehicle":
        """``vehicle`` as a `LaunchVehicle`: itself, or built from a mapping of its fields
        (ValueError naming an unknown or missing key, TypeError for anything else)."""
        return _coerce(cls, vehicle, "vehicle", required=("thrust", "inertia", "arm", "mass"))

    @property
    def aero_moment(self) -> float:
        """``M = q S C_N_alpha l_cp`` [N m/rad] (0 without aero): the airframe's unstable
        moment per radian of angle of attack."""
        a = self.aero
        return 0.0 if a is None else a.dynamic_pressure * a.area * a.normal_force_slope * a.cp_arm

    @property
    def aero_gain_bound(self) -> float:
        """``M / (F l)`` [rad/rad]: the least ``k_psi`` with the flight path held."""
        return self.aero_moment / (self.thrust * self.arm)

    def stability_kwargs(self) -> dict:
        """Keyword arguments of `problems.stability.launch_vehicle` (without the gains)."""
        return dict(thrust=self.thrust, inertia=self.inertia, arm=self.arm, mass=self.mass,
                    aero=self.aero, velocity=self.velocity, actuator=self.actuator)


@dataclass(frozen=True)
class LaunchScenario:
    """One scenario of the design: initial errors and a step wind gust.

    Parameters
    ----------
    psi0 : float [rad]
        Initial attitude error.
    psi_dot0 : float [rad/s]
        Initial rate error.
    gust_alpha : float [rad]
        Angle of attack of the wind gust at ``t = 0`` (lateral wind ``V tan(gust_alpha)``,
        constant over the horizon); ``|gust_alpha| < pi/2``, 0 without aero.
    weight : float
        Weight ``>= 0`` of this scenario's cost.
    name : str
        Label in reports.

    Examples
    --------
    >>> LaunchScenario(gust_alpha=0.05, name="gust").psi0
    0.0
    """

    psi0: float = 0.0
    psi_dot0: float = 0.0
    gust_alpha: float = 0.0
    weight: float = 1.0
    name: str = ""

    def __post_init__(self):
        for f in ("psi0", "psi_dot0", "gust_alpha", "weight"):
            object.__setattr__(self, f, finite_scalar(getattr(self, f), f))
        if self.weight < 0:
            raise ValueError(f"`weight` must be >= 0, got {self.weight!r}")
        if not abs(self.gust_alpha) < math.pi / 2:
            raise ValueError(f"`gust_alpha` must be within (-pi/2, pi/2) rad, got "
                             f"{self.gust_alpha!r}")
        if not isinstance(self.name, str):
            raise TypeError(f"`name` must be a str, got {type(self.name).__name__}")

    @classmethod
    def coerce(cls, scenario, index: int) -> "LaunchScenario":
        """``scenario`` as a `LaunchScenario` (itself or a mapping of its fields); errors
        name ``scenarios[index]``."""
        return _coerce(cls, scenario, f"scenarios[{index}]")


def _coerce(cls, value, argname: str, required=()):
    """``value`` as the dataclass ``cls``: itself, or ``cls(**value)`` from a mapping of its
    fields; errors name ``argname`` (unknown or missing keys, bad values, other types)."""
    if isinstance(value, cls):
        return value
    if not isinstance(value, Mapping):
        raise TypeError(f"`{argname}` must be a {cls.__name__} or a mapping of its fields, got "
                        f"{type(value).__name__}")
    known = {f.name for f in fields(cls)}
    unknown = sorted(set(value) - known)
    if unknown:
        raise ValueError(f"`{argname}` has unknown keys {unknown}; known: {sorted(known)}")
    missing = [k for k in required if k not in value]
    if missing:
        raise ValueError(f"`{argname}` needs {missing}")
    try:
        return cls(**value)
    except ValueError as exc:
        if f"`{argname}`" in str(exc):
            raise
        raise ValueError(f"`{argname}`: {exc}") from None


# ------------------------------------------------------------------- argument checks
def check_weights(weights) -> dict:
    if weights is None:
        return dict(DEFAULT_WEIGHTS)
    if not isinstance(weights, Mapping):
        raise TypeError(f"`weights` must be a mapping of {WEIGHT_KEYS} to numbers, got "
                        f"{type(weights).__name__}")
    unknown = sorted(set(weights) - set(WEIGHT_KEYS))
    if unknown:
        raise ValueError(f"`weights` has unknown keys {unknown}; known: {list(WEIGHT_KEYS)}")
    w = {k: 0.0 for k in WEIGHT_KEYS}
    for key, value in weights.items():
        v = finite_scalar(value, f"weights[{key!r}]")
        if v < 0:
            raise ValueError(f"`weights[{key!r}]` must be >= 0, got {v!r}")
        w[key] = v
    if not any(w.values()):
        raise ValueError("`weights` must have at least one positive entry")
    return w


def check_gain_bounds(gain_bounds, integral: bool) -> dict:
    out = {"k_psi": (0.0, 50.0), "k_psidot": (0.0, 50.0)}
    if integral:
        out["k_i"] = (0.0, 50.0)
    if gain_bounds is None:
        return out
    if not isinstance(gain_bounds, Mapping):
        raise TypeError(f"`gain_bounds` must be a mapping of gain name to (lower, upper), got "
                        f"{type(gain_bounds).__name__}")
    for key, value in gain_bounds.items():
        if key not in out:
            raise ValueError(f"`gain_bounds` has unknown key {key!r}; known: {sorted(out)}")
        try:
            lo, hi = (float(v) for v in value)
        except (TypeError, ValueError):
            raise ValueError(f"`gain_bounds[{key!r}]` must be (lower, upper), got "
                             f"{value!r}") from None
        if not (math.isfinite(lo) and math.isfinite(hi) and 0 <= lo < hi):
            raise ValueError(f"`gain_bounds[{key!r}]` must be finite with 0 <= lower < upper, "
                             f"got {value!r}")
        out[key] = (lo, hi)
    return out


def check_scenarios(scenarios, veh) -> list:
    if isinstance(scenarios, (str, bytes, Mapping)) or not isinstance(scenarios, Sequence):
        raise TypeError("`scenarios` must be a sequence of LaunchScenario or mappings, got "
                        f"{type(scenarios).__name__}")
    out = [LaunchScenario.coerce(s, i) for i, s in enumerate(scenarios)]
    if not out:
        raise ValueError("`scenarios` must hold at least one scenario")
    if not any(s.weight > 0 for s in out):
        raise ValueError("`scenarios`: at least one scenario needs a weight > 0")
    if veh.aero is None and any(s.gust_alpha for s in out):
        raise ValueError("`scenarios`: a gust (gust_alpha != 0) needs `vehicle.aero`")
    return out


def guess_gains(veh: LaunchVehicle, bounds) -> np.ndarray:
    """A stabilizing start: ``k_psi`` three times the aero bound (at least 1), ``k_psidot``
    for damping 0.7 of ``I s^2 + F l k_psidot s + (F l k_psi - M)``, ``k_i`` = 0.01
    ``k_psi omega_n``."""
    Fl = veh.thrust * veh.arm
    k = max(1.0, 3.0 * veh.aero_gain_bound)
    wn2 = max(Fl * k - veh.aero_moment, 1e-9) / veh.inertia
    kd = 1.4 * math.sqrt(veh.inertia * max(Fl * k - veh.aero_moment, 1e-9)) / Fl
    out = {"k_psi": k, "k_psidot": kd, "k_i": 0.01 * k * math.sqrt(wn2)}
    return np.array([np.clip(out[g], *b) for g, b in bounds.items()])


