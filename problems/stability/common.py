"""Small shared pieces of `problems.stability`: the number check of the cases, the
plain-Python / text conversions and the figure helpers used by reports and sweeps."""
from __future__ import annotations

import math
from dataclasses import asdict

import numpy as np

__all__ = ["STANDARD_GRAVITY", "check_number", "plain", "jsonable", "format_complex",
           "format_number", "param_text", "axes_or_new_figure", "finish_figure"]

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


def plain(v, *, strict=False):
    """Plain-Python copy: arrays -> lists, complex -> [re, im], dataclasses -> dicts; with
    ``strict`` also non-finite floats -> None (JSON-ready)."""
    if isinstance(v, dict):
        return {str(k): plain(x, strict=strict) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [plain(x, strict=strict) for x in v]
    if isinstance(v, np.ndarray):
        return plain(v.tolist(), strict=strict)
    if isinstance(v, (complex, np.complexfloating)):
        return [plain(float(v.real), strict=strict), plain(float(v.imag), strict=strict)]
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, (int, np.integer)):
        return int(v)
    if isinstance(v, (float, np.floating)):
        return None if strict and not math.isfinite(v) else float(v)
    if hasattr(v, "__dataclass_fields__"):
        return {"type": type(v).__name__, **plain(asdict(v), strict=strict)}
    return v


def jsonable(v):
    """JSON-ready copy: complex -> [re, im], arrays -> lists, non-finite floats -> None."""
    return plain(v, strict=True)


def format_complex(z, width=13) -> str:
    """``+1.234560e+00 + 5.000000e-01j`` (``-`` for None); ``width - 7`` decimals."""
    if z is None:
        return "-"
    z = complex(z)
    if z.imag == 0:
        return f"{z.real:+.{width - 7}e}"
    return f"{z.real:+.{width - 7}e} {'+-'[z.imag < 0]} {abs(z.imag):.{width - 7}e}j"


def format_number(v, spec=".6g") -> str:
    """``format(v, spec)``, with ``-`` for None and ``inf`` for an infinite float."""
    if v is None:
        return "-"
    if isinstance(v, float) and math.isinf(v):
        return "inf"
    return format(v, spec)


def param_text(v) -> str:
    """Compact text of a parameter value (dicts as ``k=v``, lists in brackets)."""
    if isinstance(v, dict):
        return ", ".join(f"{k}={param_text(x)}" for k, x in v.items())
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(param_text(x) for x in v) + "]"
    if isinstance(v, float):
        return f"{v:.10g}"
    return str(v)


def axes_or_new_figure(ax, figsize):
    """``(ax.figure, ax)``, or a new `matplotlib.figure.Figure` with one axes (no pyplot)."""
    if ax is not None:
        return ax.figure, ax
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize)
    return fig, fig.add_subplot(1, 1, 1)


def finish_figure(fig, path=None):
    """Lay ``fig`` out, save it to ``path`` if given (PNG unless the suffix says otherwise),
    and return it."""
    fig.tight_layout()
    if path is not None:
        from pathlib import Path

        suffix = Path(path).suffix.lower().lstrip(".")
        fig.savefig(path, dpi=110, format=suffix if suffix in ("png", "pdf", "svg") else "png")
    return fig
