"""The table of named stability cases: the one place that maps a case name (or its
command-line spelling) to its function."""
from __future__ import annotations

from typing import Callable

from .constrained import conical_pendulum
from .hinged import hinged_spin
from .launch_vehicle import launch_vehicle
from .periodic import PeriodicStabilityReport, shaken_pendulum
from .report import StabilityReport
from .spin import gyrostat, spin
from .tilt import heavy_top, rotor, spinning_projectile

__all__ = ["CASES", "CASE_ALIASES", "resolve_case"]

#: case name -> function; every case takes its parameters by keyword and returns a
#: `StabilityReport` (`shaken_pendulum`: a `PeriodicStabilityReport`, the same format)
CASES: dict[str, Callable[..., StabilityReport | PeriodicStabilityReport]] = {
    "spin": spin, "heavy_top": heavy_top, "spinning_projectile": spinning_projectile,
    "rotor": rotor, "gyrostat": gyrostat, "launch_vehicle": launch_vehicle,
    "shaken_pendulum": shaken_pendulum, "conical_pendulum": conical_pendulum,
    "hinged_spin": hinged_spin,
}
#: other accepted spellings (the command line's among them) -> case name
CASE_ALIASES = {"heavy-top": "heavy_top", "projectile": "spinning_projectile",
                "spinning-projectile": "spinning_projectile", "launch-vehicle": "launch_vehicle",
                "shaken-pendulum": "shaken_pendulum", "conical-pendulum": "conical_pendulum",
                "hinged-spin": "hinged_spin"}


def resolve_case(case):
    """``(name, function)`` of a case given by name, alias or function.

    Parameters
    ----------
    case : str or callable
        A key of `CASES` or `CASE_ALIASES`, or one of the case functions.

    Returns
    -------
    (str, callable)

    Raises
    ------
    ValueError
        "```case`` must be one of ...".

    Examples
    --------
    >>> resolve_case("projectile")[0]
    'spinning_projectile'
    """
    if callable(case):
        for name, fun in CASES.items():
            if fun is case:
                return name, fun
        raise ValueError(f"`case` must be one of {sorted(CASES)} (or the function), got {case!r}")
    if not isinstance(case, str):
        raise TypeError(f"`case` must be a case name (one of {sorted(CASES)}) or a case "
                        f"function, got {type(case).__name__}")
    name = CASE_ALIASES.get(case, case)
    if name not in CASES:
        raise ValueError(f"`case` must be one of {sorted(CASES)}, got {case!r}")
    return name, CASES[name]
