"""Small shared pieces of `problems.stability`: the number check of the cases, the
plain-Python / text conversions and the figure helpers used by reports and sweeps."""
from __future__ import annotations

import math

import numpy as np

from appdyn.dynamics.figures import axes_or_new_figure, finish_figure
from appdyn.dynamics.serialize import jsonable, plain

__all__ = ["STANDARD_GRAVITY", "check_number", "block", "plain", "jsonable", "format_complex",
           "format_number", "param_text", "param_line", "PARAMETER_UNITS", "spectrum_text", "axes_or_new_figure",
           "finish_figure"]

#: standard gravity [m/s^2], the default ``gravity`` of `problems.stability.heavy_top`
STANDARD_GRAVITY = 9.80665


def check_number(value, name, *, positive=False, nonzero=False, nonnegative=False) -> float:
    """A finite float, optionally positive, non-zero or non-negative.

    Parameters
    ----------
    value : float
        The argument's value.
    name : str
        The argument's name, used in the error message.
    positive, nonzero, nonnegative : bool, optional
        Further conditions on the value.

    Returns
    -------
    float

    Raises
    ------
    ValueError
        "```name`` must be ..., got ...".
    """
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"`{name}` must be a number, got {value!r}") from None
    if not math.isfinite(v):
        raise ValueError(f"`{name}` must be finite, got {v}")
    if positive and not v > 0:
        raise ValueError(f"`{name}` must be positive, got {v}")
    if nonzero and v == 0:
        raise ValueError(f"`{name}` must be non-zero, got {v}")
    if nonnegative and v < 0:
        raise ValueError(f"`{name}` must be non-negative, got {v}")
    return v


def block(states, first: str, last: str) -> slice:
    """The slice of the consecutive named states ``first..last`` (a model's state blocks by
    name, never by literal index).

    Raises
    ------
    ValueError
        If a name is missing or ``last`` comes before ``first``.

    Examples
    --------
    >>> block(("q1", "q2", "q3", "q4", "w1", "w2", "w3"), "w1", "w3")
    slice(4, 7, None)
    """
    states = tuple(states)
    if first not in states or last not in states:
        raise ValueError(f"no state block {first!r}..{last!r} in {states}")
    i, j = states.index(first), states.index(last) + 1
    if j <= i:
        raise ValueError(f"state {last!r} comes before {first!r} in {states}")
    return slice(i, j)


def format_complex(z, *, width=13) -> str:
    """``+1.234560e+00 + 5.000000e-01j`` (``-`` for None); ``width - 7`` decimals."""
    if z is None:
        return "-"
    z = complex(z)
    if z.imag == 0:
        return f"{z.real:+.{width - 7}e}"
    return f"{z.real:+.{width - 7}e} {'+-'[z.imag < 0]} {abs(z.imag):.{width - 7}e}j"


def format_number(v, *, spec=".6g") -> str:
    """``format(v, spec)``, with ``-`` for None and ``inf`` for an infinite float."""
    if v is None:
        return "-"
    if isinstance(v, float) and math.isinf(v):
        return "inf"
    return format(v, spec)


#: the unit of each parameter a report prints (`param_line`); angles in radians
PARAMETER_UNITS = {
    "mass": "kg", "length": "m", "arm": "m", "gravity": "m/s^2", "inertia": "kg m^2",
    "axial_inertia": "kg m^2", "transverse_inertia": "kg m^2", "wheel_inertia": "kg m^2",
    "rate": "rad/s", "wheel_momentum": "N m s", "thrust": "N", "velocity": "m/s",
    "k_psi": "rad/rad", "k_psidot": "rad/(rad/s)", "area": "m^2", "dynamic_pressure": "Pa",
    "cn_alpha": "1/rad", "cp_offset": "m", "stiffness": "N/m", "bearing_distance": "m",
    "internal_damping": "N m s", "damping": "N m s", "amp_x": "m", "amp_y": "m",
    "freq": "rad/s", "cone_angle": "rad", "axis": "-",
}


def param_line(name: str, value) -> str:
    """A parameter's value with its unit (`PARAMETER_UNITS`); an angle also in degrees (the
    unit the command line takes it in).

    Examples
    --------
    >>> from appdyn.problems.stability.common import param_line
    >>> param_line("cone_angle", 1.0471975511965976)
    '1.047197551 rad (60 deg)'
    >>> param_line("mass", 1.0), param_line("sequence", "3-2-1")
    ('1 kg', '3-2-1')
    """
    unit = PARAMETER_UNITS.get(name, "")
    text = param_text(value)
    if unit == "rad" and isinstance(value, (int, float)) and not isinstance(value, bool):
        return f"{text} rad ({math.degrees(value):.10g} deg)"
    numeric = isinstance(value, (int, float, list, tuple)) and not isinstance(value, bool)
    return f"{text} {unit}" if unit and unit != "-" and numeric else text


def spectrum_text(eigenvalues) -> str:
    """Eigenvalues as ``+1.000e-01+2.000000e+00j, ...`` [1/s], round-off (a part below 1e-12
    of the spectral radius, as ``-7.2e-71``) shown as 0.

    Examples
    --------
    >>> from appdyn.problems.stability.common import spectrum_text
    >>> spectrum_text([-7.2e-71 + 2j, -0.5])
    '+0.000e+00+2.000000e+00j, -5.000e-01+0.000000e+00j'
    """
    from appdyn.dynamics.results import clean_number

    z = [complex(v) for v in eigenvalues]
    rho = max((abs(v) for v in z), default=0.0)
    return ", ".join(f"{clean_number(v.real, rho) + 0.0:+.3e}{clean_number(v.imag, rho) + 0.0:+.6e}j"
                     for v in z)


def param_text(v) -> str:
    """Compact text of a parameter value (dicts as ``k=v``, lists in brackets)."""
    if isinstance(v, dict):
        return ", ".join(f"{k}={param_text(x)}" for k, x in v.items())
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(param_text(x) for x in v) + "]"
    if isinstance(v, float):
        return f"{v:.10g}"
    return str(v)


