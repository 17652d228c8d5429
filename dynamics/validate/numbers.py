"""Checks of numbers: finite arrays and scalars, integers, positive values, choices."""
from __future__ import annotations

import math

import casadi as ca
import numpy as np

from .base import ArgumentTypeError, check_finite, check_shape, real_array, short_repr

__all__ = ["finite_array", "finite_scalar", "one_of", "integer", "positive", "positive_each"]


def finite_array(x, name: str, shape: tuple | None = None, *, batch: bool = False) -> np.ndarray:
    """Check an array of finite real numbers, optionally of a given shape.

    Parameters
    ----------
    x : array_like
        The value to check (list, tuple, number, numpy array or ``casadi.DM``).
    name : str
        Argument name used in the error message.
    shape : tuple of int, optional
        Required shape, e.g. ``(3,)`` or ``(3, 3)``; ``None`` accepts any shape.
    batch : bool, optional
        Also accept ``shape`` followed by batch axes, e.g. ``(3, n)`` for ``shape=(3,)``.

    Returns
    -------
    ndarray, shape ``shape`` or ``shape + (n, ...)``
        ``x`` as a float array.

    Raises
    ------
    TypeError
        If ``x`` does not hold real numbers (string, dict, ``None``, complex, boolean, symbolic).
    ValueError
        If the shape is wrong or an entry is NaN or infinite.

    Examples
    --------
    >>> from appdyn.dynamics.validate import finite_array
    >>> finite_array([1, 2, 3], "w0", (3,))
    array([1., 2., 3.])
    >>> finite_array([1.0, float("nan"), 3.0], "w0", (3,))
    Traceback (most recent call last):
        ...
    ValueError: `w0` must be finite, got nan at index [1]
    """
    a = real_array(x, name)
    if shape is not None:
        check_shape(a, name, tuple(shape), batch)
    check_finite(a, name)
    return a


def finite_scalar(x, name: str) -> float:
    """Check one finite real number (an angle, a time step, a rate).

    Parameters
    ----------
    x : float or 0-d array_like (a ``1x1`` DM is accepted)
    name : str
        Argument name used in the error message.

    Returns
    -------
    float

    Raises
    ------
    TypeError
        If ``x`` is not a real number.
    ValueError
        If ``x`` is an array of more than one element, NaN or infinite.

    Examples
    --------
    >>> from appdyn.dynamics.validate import finite_scalar
    >>> finite_scalar(2, "rate")
    2.0
    >>> finite_scalar("fast", "rate")
    Traceback (most recent call last):
        ...
    appdyn.dynamics.validate.ArgumentTypeError: `rate` must be real numbers, got a string: 'fast'
    """
    if type(x) is float and math.isfinite(x):  # fast path: the common case
        return x
    a = real_array(x, name)
    if a.ndim != 0 and not (isinstance(x, ca.DM) and a.size == 1):
        raise ValueError(f"`{name}` must be a scalar, got shape {a.shape}")
    v = float(a.reshape(()))
    if not np.isfinite(v):
        raise ValueError(f"`{name}` must be finite, got {v}")
    return v


def one_of(value, name: str, choices: tuple):
    """Check that ``value`` is one of a few allowed options (strings or integers).

    Parameters
    ----------
    value : object
    name : str
        Argument name used in the error message.
    choices : tuple
        The allowed values; their types are the allowed types (a ``bool`` is not an ``int``
        here, and a numpy integer is).

    Returns
    -------
    object
        ``value`` (a numpy integer as a Python ``int``).

    Raises
    ------
    TypeError
        If ``value`` is not of the type of any choice.
    ValueError
        If it is of the right type but not among ``choices``.

    Examples
    --------
    >>> from appdyn.dynamics.validate import one_of
    >>> one_of("rk4", "method", ("rk4", "rk8"))
    'rk4'
    >>> one_of("rk5", "method", ("rk4", "rk8"))
    Traceback (most recent call last):
        ...
    ValueError: `method` must be 'rk4' or 'rk8', got 'rk5'
    """
    names = [repr(c) for c in choices]
    text = names[0] if len(names) == 1 else ", ".join(names[:-1]) + " or " + names[-1]
    ints = any(type(c) is int for c in choices)
    if isinstance(value, (bool, np.bool_)) and not any(type(c) is bool for c in choices):
        ok = False
    elif ints and isinstance(value, np.integer):
        value, ok = int(value), True
    else:
        ok = any(type(value) is type(c) for c in choices)
    if not ok:
        raise ArgumentTypeError(
            f"`{name}` must be {text}, got {type(value).__name__} {short_repr(value)}")
    if value not in choices:
        raise ValueError(f"`{name}` must be {text}, got {short_repr(value)}")
    return value


def integer(value, name: str, *, minimum: int | None = None) -> int:
    """Check an integer count (steps, a run budget, an index), optionally ``>= minimum``.

    Parameters
    ----------
    value : int
        A Python or numpy integer (``bool`` is refused).
    name : str
        Argument name used in the error message.
    minimum : int, optional
        Least accepted value.

    Returns
    -------
    int

    Raises
    ------
    TypeError
        If ``value`` is not an integer (a string, ``None``, a ``bool``, an array, ``2.5`` or
        ``3.0``); raised as `ArgumentTypeError`, which is also a ``ValueError``.
    ValueError
        If it is below ``minimum``.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.validate import integer
    >>> integer(np.int64(3), "steps", minimum=1)
    3
    >>> integer(0, "steps", minimum=1)
    Traceback (most recent call last):
        ...
    ValueError: `steps` must be an integer >= 1, got 0
    """
    if type(value) is int and (minimum is None or value >= minimum):  # fast path
        return value
    bound = "" if minimum is None else f" >= {minimum}"
    number = isinstance(value, (int, np.integer, float, np.floating))
    if isinstance(value, (bool, np.bool_)) or not number:
        raise ArgumentTypeError(
            f"`{name}` must be an integer{bound}, got {type(value).__name__} {short_repr(value)}")
    if not isinstance(value, (int, np.integer)):
        raise ArgumentTypeError(f"`{name}` must be an integer{bound}, got {value!r}")
    if minimum is not None and value < minimum:
        raise ValueError(f"`{name}` must be an integer{bound}, got {value!r}")
    return int(value)


def positive(value, name: str) -> float:
    """Check a finite number ``> 0`` and return it as a float.

    Parameters
    ----------
    value : float
    name : str
        Argument name used in the error message.

    Returns
    -------
    float

    Raises
    ------
    TypeError
        If ``value`` is not a real number.
    ValueError
        If it is not finite or not ``> 0``.

    Examples
    --------
    >>> from appdyn.dynamics.validate import positive
    >>> positive(2, "u_max")
    2.0
    >>> positive(0.0, "u_max")
    Traceback (most recent call last):
        ...
    ValueError: `u_max` must be a finite number > 0, got 0.0
    """
    v = finite_scalar(value, name)
    if not v > 0:
        raise ValueError(f"`{name}` must be a finite number > 0, got {value!r}")
    return v


def nonnegative(value, name: str) -> float:
    """Check a finite number ``>= 0`` and return it as a float (a weight, a tolerance).

    Raises
    ------
    TypeError
        If ``value`` is not a real number.
    ValueError
        If it is not finite or negative.

    Examples
    --------
    >>> from appdyn.dynamics.validate import nonnegative
    >>> nonnegative(0, "effort_weight")
    0.0
    """
    v = finite_scalar(value, name)
    if not v >= 0:
        raise ValueError(f"`{name}` must be a finite number >= 0, got {value!r}")
    return v


def positive_each(value, name: str, n: int) -> np.ndarray:
    """A finite number ``> 0`` per device (a scalar is used for all ``n``).

    Parameters
    ----------
    value : float or array_like, shape (n,)
        E.g. wheel axial moments [kg m^2] or rotor momenta [N m s].
    name : str
        Argument name used in error messages.
    n : int
        Number of devices.

    Returns
    -------
    ndarray, shape (n,)

    Raises
    ------
    TypeError
        If ``value`` does not hold real numbers.
    ValueError
        Naming ``name`` (and the entry): wrong length, not finite or not ``> 0``.

    Examples
    --------
    >>> from appdyn.dynamics.validate import positive_each
    >>> positive_each(0.5, "wheel_inertia", 3)
    array([0.5, 0.5, 0.5])
    >>> positive_each([1.0, -1.0], "wheel_inertia", 2)
    Traceback (most recent call last):
        ...
    ValueError: `wheel_inertia[1]` must be a finite number > 0, got -1.0
    """
    v = finite_array(value, name)
    if v.ndim == 0:
        return np.full(n, positive(float(v), name))
    if v.shape != (n,):
        raise ValueError(f"`{name}` must be a scalar or have shape ({n},) (one per unit), "
                         f"got {v.shape}")
    for i, vi in enumerate(v.tolist()):
        positive(vi, f"{name}[{i}]")
    return v
