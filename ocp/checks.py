"""Argument checks of the ocp engine that `dynamics.validate` does not (yet) offer.

One convention: ``TypeError`` for a value of the wrong type, ``ValueError`` for a wrong
value, the message naming the argument.
"""
from __future__ import annotations

import numpy as np

from dynamics.validate import finite_scalar

__all__ = ["integer", "positive"]


def integer(value, name: str, low: int) -> int:
    """``value`` as an int ``>= low``.

    Raises
    ------
    TypeError
        If ``value`` is not an integer (booleans are not).
    ValueError
        If it is below ``low``.
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"`{name}` must be an integer >= {low}, got {value!r}")
    if value < low:
        raise ValueError(f"`{name}` must be an integer >= {low}, got {value!r}")
    return int(value)


def positive(value, name: str) -> float:
    """``value`` as a finite float ``> 0`` (TypeError for a non-number, ValueError else)."""
    v = finite_scalar(value, name)
    if not v > 0:
        raise ValueError(f"`{name}` must be a finite number > 0, got {value!r}")
    return v
