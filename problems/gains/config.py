"""TOML configuration of a launch-vehicle gain design (`appdyn gains launch-vehicle --config`).

The file (an example ships as ``problems/gains/launch_vehicle.toml``; `EXAMPLE_CONFIG`)::

    [vehicle]                      # required
    thrust = 2.0e6                 # F [N]                        > 0, required
    inertia = 4.0e7                # I [kg m^2]                   > 0, required
    arm = 20.0                     # l [m], mass centre to gimbal > 0, required
    mass = 1.0e5                   # m [kg]                       > 0, required
    velocity = 300.0               # V [m/s]                      > 0, with [vehicle.aero] only

    [vehicle.aero]                 # optional: normal force at the centre of pressure
    dynamic_pressure = 3.0e4       # q [Pa] > 0
    area = 10.0                    # S [m^2] > 0
    normal_force_slope = 3.0       # C_N_alpha [1/rad] > 0
    cp_arm = 5.0                   # [m] ahead of the mass centre (> 0: unstable airframe)

    [vehicle.actuator]             # optional first-order gimbal
    time_constant = 0.05           # tau [s] > 0
    deflection_limits_deg = [-8.0, 8.0]   # optional clamps of the re-simulation [deg]
    rate_limit_deg = 30.0                 # optional clamp [deg/s]

    [limits]                       # required
    delta_max_deg = 6.0            # |delta| <= [deg]
    delta_rate_max_deg = 25.0      # |delta_dot| <= [deg/s]

    [weights]                      # optional running-cost weights (rad, s units), >= 0
    psi = 1.0
    psi_dot = 0.0
    delta = 1.0
    delta_rate = 0.0

    [design]                       # optional
    horizon = 8.0                  # [s] > 0
    intervals = 40                 # collocation intervals, integer >= 4
    min_decay = 0.01               # [1/s] >= 0, poles at Re <= -min_decay
    limit_tol = 0.005              # relative tolerance of the re-simulated limit check
    k_psi_bounds = [0.0, 50.0]     # [rad/rad]
    k_psidot_bounds = [0.0, 50.0]  # [rad/(rad/s)]
    integral = false               # true: also design k_i of - k_i integral(psi) dt
    # k_i_bounds = [0.0, 50.0]     # [rad/(rad s)], only with integral = true
    # filter_time_constant = 0.1   # [s] optional first-order command filter

    [[scenarios]]                  # one table per scenario, at least one
    name = "attitude error"        # optional label
    psi0_deg = 2.0                 # initial attitude error [deg]
    psi_dot0_deg = 0.0             # initial rate error [deg/s]
    gust_alpha_deg = 0.0           # step-gust angle of attack [deg], needs [vehicle.aero]
    weight = 1.0                   # >= 0

Angles are in degrees in the file (keys ending ``_deg``) and in radians in the library.
Every problem with the file's content -- an unknown key, a missing one, a value of the
wrong type or out of range, invalid TOML -- raises ValueError naming the field by its dotted
path (``vehicle.thrust must be > 0, got -1.0``; ``scenarios[2].psi0_deg ...``), so the CLI
reports it as bad input (exit status 2).
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Mapping

from appdyn.dynamics.launch_vehicle import Actuator, Aero

from .launch_vehicle import LaunchScenario, LaunchVehicle

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10: parse_config still works, load_config needs 3.11
    tomllib = None

__all__ = ["LaunchVehicleConfig", "load_config", "parse_config", "EXAMPLE_CONFIG"]

#: the example configuration shipped with the package
EXAMPLE_CONFIG = Path(__file__).with_name("launch_vehicle.toml")

_POS, _FIN, _NONNEG, _INT4, _PAIR, _STR, _BOOL = ("pos", "fin", "nonneg", "int4", "pair", "str",
                                                  "bool")
_SPEC = {
    "vehicle": {"thrust": _POS, "inertia": _POS, "arm": _POS, "mass": _POS, "velocity": _POS,
                "aero": dict, "actuator": dict},
    "vehicle.aero": {"dynamic_pressure": _POS, "area": _POS, "normal_force_slope": _POS,
                     "cp_arm": _FIN},
    "vehicle.actuator": {"time_constant": _POS, "deflection_limits_deg": _PAIR,
                         "rate_limit_deg": _POS},
    "limits": {"delta_max_deg": _POS, "delta_rate_max_deg": _POS},
    "weights": {"psi": _NONNEG, "psi_dot": _NONNEG, "delta": _NONNEG, "delta_rate": _NONNEG},
    "design": {"horizon": _POS, "intervals": _INT4, "min_decay": _NONNEG, "limit_tol": _NONNEG,
               "k_psi_bounds": _PAIR, "k_psidot_bounds": _PAIR, "k_i_bounds": _PAIR,
               "integral": _BOOL, "filter_time_constant": _POS},
    "scenario": {"name": _STR, "psi0_deg": _FIN, "psi_dot0_deg": _FIN, "gust_alpha_deg": _FIN,
                 "weight": _NONNEG},
}
_TOP = ("vehicle", "limits", "weights", "design", "scenarios")
_REQUIRED = {"vehicle": ("thrust", "inertia", "arm", "mass"),
             "vehicle.aero": ("dynamic_pressure", "area", "normal_force_slope", "cp_arm"),
             "vehicle.actuator": ("time_constant",),
             "limits": ("delta_max_deg", "delta_rate_max_deg")}


@dataclass(frozen=True)
class LaunchVehicleConfig:
    """A parsed, checked configuration: the arguments of `launch_vehicle_gains`.

    Attributes
    ----------
    vehicle : LaunchVehicle
    scenarios : list of LaunchScenario
    options : dict
        The keyword arguments: ``delta_max`` [rad], ``delta_rate_max`` [rad/s] and those
        the file sets (``weights``, ``horizon`` [s], ``N``, ``min_decay`` [1/s],
        ``limit_tol``, ``gain_bounds``).
    source : str
        Where it came from (a path, or ``'<mapping>'``).
    """

    vehicle: LaunchVehicle
    scenarios: list
    options: dict = field(default_factory=dict)
    source: str = "<mapping>"

    def design(self, **overrides):
        """Run `launch_vehicle_gains` on this configuration (``overrides`` win)."""
        from .launch_vehicle import launch_vehicle_gains

        return launch_vehicle_gains(self.vehicle, self.scenarios, **{**self.options, **overrides})


def _value(value, kind, where):
    if kind is _BOOL:
        if not isinstance(value, bool):
            raise ValueError(f"{where} must be true or false, got {value!r}")
        return value
    if kind is _STR:
        if not isinstance(value, str):
            raise ValueError(f"{where} must be a string, got {value!r}")
        return value
    if kind is _PAIR:
        if (not isinstance(value, (list, tuple)) or len(value) != 2
                or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)):
            raise ValueError(f"{where} must be a pair of numbers [lower, upper], got {value!r}")
        lo, hi = float(value[0]), float(value[1])
        if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
            raise ValueError(f"{where} must be finite with lower < upper, got {value!r}")
        return lo, hi
    if kind is _INT4:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ValueError(f"{where} must be an integer, got {value!r}")
        if value < 4:
            raise ValueError(f"{where} must be >= 4, got {value!r}")
        return value
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"{where} must be a number, got {value!r}")
    v = float(value)
    if not math.isfinite(v):
        raise ValueError(f"{where} must be finite, got {value!r}")
    if kind is _POS and not v > 0:
        raise ValueError(f"{where} must be > 0, got {value!r}")
    if kind is _NONNEG and v < 0:
        raise ValueError(f"{where} must be >= 0, got {value!r}")
    return v


def _table(data, section, where=None) -> dict:
    """The checked values of one table (unknown and missing keys named)."""
    where = where or section
    if not isinstance(data, Mapping):
        raise ValueError(f"{where} must be a table, got {data!r}")
    spec = _SPEC[section]
    unknown = sorted(set(data) - set(spec))
    if unknown:
        raise ValueError(f"unknown key {where}.{unknown[0]} (known in {where}: "
                         f"{', '.join(spec)})")
    for key in _REQUIRED.get(section, ()):
        if key not in data:
            raise ValueError(f"{where}.{key} is required")
    out = {}
    for key, value in data.items():
        if spec[key] is dict:
            continue  # sub-tables, parsed by the caller
        out[key] = _value(value, spec[key], f"{where}.{key}")
    return out


def _vehicle(data) -> LaunchVehicle:
    v = _table(data, "vehicle")
    aero = actuator = None
    if "aero" in data:
        aero = Aero(**_table(data["aero"], "vehicle.aero"), wind="parameter")
        if "velocity" not in v:
            raise ValueError("vehicle.velocity is required with [vehicle.aero]")
    elif "velocity" in v:
        raise ValueError("vehicle.velocity is the flight speed of [vehicle.aero]; give it "
                         "only with [vehicle.aero]")
    if "actuator" in data:
        a = _table(data["actuator"], "vehicle.actuator")
        limits = a.get("deflection_limits_deg")
        actuator = Actuator(a["time_constant"],
                            deflection_limits=None if limits is None
                            else tuple(math.radians(x) for x in limits),
                            rate_limit=None if "rate_limit_deg" not in a
                            else math.radians(a["rate_limit_deg"]))
    return LaunchVehicle(v["thrust"], v["inertia"], v["arm"], v["mass"], aero=aero,
                         velocity=v.get("velocity"), actuator=actuator)


def _scenarios(data, vehicle) -> list:
    if not isinstance(data, list) or not data:
        raise ValueError("scenarios must be a non-empty array of tables ([[scenarios]])")
    out = []
    for i, item in enumerate(data):
        where = f"scenarios[{i}]"
        s = _table(item, "scenario", where)
        gust = s.get("gust_alpha_deg", 0.0)
        if not abs(gust) < 90.0:
            raise ValueError(f"{where}.gust_alpha_deg must be within (-90, 90), got {gust!r}")
        if gust and vehicle.aero is None:
            raise ValueError(f"{where}.gust_alpha_deg needs [vehicle.aero] (a gust acts "
                             "through the air)")
        out.append(LaunchScenario(psi0=math.radians(s.get("psi0_deg", 0.0)),
                                  psi_dot0=math.radians(s.get("psi_dot0_deg", 0.0)),
                                  gust_alpha=math.radians(gust), weight=s.get("weight", 1.0),
                                  name=s.get("name", f"scenario {i}")))
    if not any(s.weight > 0 for s in out):
        raise ValueError("scenarios: at least one scenario needs weight > 0")
    return out


def parse_config(data: Mapping, *, source: str = "<mapping>") -> LaunchVehicleConfig:
    """Check a configuration mapping (as `tomllib` reads it) and build its arguments.

    Parameters
    ----------
    data : mapping
        Tables ``vehicle``, ``limits``, ``scenarios`` (required), ``weights``, ``design``.
    source : str, optional
        Where it came from, kept in the result.

    Returns
    -------
    LaunchVehicleConfig

    Raises
    ------
    ValueError
        Naming the field by its dotted path: unknown or missing keys, wrong types, values
        out of range (module docstring).

    Examples
    --------
    >>> cfg = parse_config({"vehicle": {"thrust": 2e6, "inertia": 4e7, "arm": 20.0,
    ...                                 "mass": 1e5},
    ...                     "limits": {"delta_max_deg": 6.0, "delta_rate_max_deg": 25.0},
    ...                     "scenarios": [{"psi0_deg": 2.0}]})
    >>> round(cfg.options["delta_max"], 6), len(cfg.scenarios)
    (0.10472, 1)
    >>> parse_config({"vehicle": {"thrust": -1, "inertia": 4e7, "arm": 20.0, "mass": 1e5}})
    Traceback (most recent call last):
    ...
    ValueError: vehicle.thrust must be > 0, got -1
    """
    if not isinstance(data, Mapping):
        raise TypeError(f"`data` (the configuration) must be a table (a mapping), got "
                        f"{type(data).__name__}")
    unknown = sorted(set(data) - set(_TOP))
    if unknown:
        raise ValueError(f"unknown key {unknown[0]} (known: {', '.join(_TOP)})")
    def need(key):
        if key not in data:
            raise ValueError(f"{key} is required (a [{key}] table)" if key != "scenarios"
                             else "scenarios is required (one [[scenarios]] table each)")
        return data[key]

    vehicle = _vehicle(need("vehicle"))
    limits = _table(need("limits"), "limits")
    options = {"delta_max": math.radians(limits["delta_max_deg"]),
               "delta_rate_max": math.radians(limits["delta_rate_max_deg"])}
    if "weights" in data:
        weights = _table(data["weights"], "weights")
        if not any(weights.values()):
            raise ValueError("weights: at least one weight must be > 0")
        options["weights"] = weights
    if "design" in data:
        d = _table(data["design"], "design")
        rename = {"horizon": "horizon", "intervals": "N", "min_decay": "min_decay",
                  "limit_tol": "limit_tol", "integral": "integral",
                  "filter_time_constant": "filter_time_constant"}
        options.update({rename[k]: v for k, v in d.items() if k in rename})
        if "k_i_bounds" in d and not d.get("integral", False):
            raise ValueError("design.k_i_bounds needs design.integral = true")
        bounds = {g: d[f"{g}_bounds"] for g in ("k_psi", "k_psidot", "k_i")
                  if f"{g}_bounds" in d}
        for g, (lo, _) in bounds.items():
            if lo < 0:
                raise ValueError(f"design.{g}_bounds must have lower >= 0, got {lo!r}")
        if bounds:
            options["gain_bounds"] = bounds
    return LaunchVehicleConfig(vehicle, _scenarios(need("scenarios"), vehicle), options, source)


def load_config(path) -> LaunchVehicleConfig:
    """Read and check a TOML configuration file (`parse_config`).

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    LaunchVehicleConfig

    Raises
    ------
    ValueError
        Naming ``path`` when the file cannot be read or is not TOML; naming the field
        otherwise (`parse_config`).
    RuntimeError
        On Python 3.10 (no `tomllib`).

    Examples
    --------
    >>> cfg = load_config(EXAMPLE_CONFIG)
    >>> cfg.vehicle.thrust, [s.name for s in cfg.scenarios]
    (2000000.0, ['attitude error', 'rate error', 'wind gust'])
    """
    if tomllib is None:
        raise RuntimeError("reading TOML needs Python >= 3.11 (tomllib); use parse_config")
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"`path` must be a file path (str or os.PathLike), got "
                        f"{type(path).__name__}")
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"`path`: cannot read {str(p)!r}: {exc}") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"`path`: {str(p)!r} is not valid TOML: {exc}") from None
    return parse_config(data, source=str(p))
