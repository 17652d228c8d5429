"""The one set of input checks shared by every appdyn package.

Each check takes the value and the *name of the argument* it came from, and raises
``TypeError`` (wrong kind of object: a string, a dict, ``None``, complex or boolean numbers, a
symbolic CasADi expression) or ``ValueError`` (wrong shape or value) with a message that names
the argument and says what was expected. They return the value as a float numpy array (the
input object itself when it already is a float64 array: do not modify it in place).

Arrays are **components first**, as everywhere in appdyn: a quaternion is ``(4,)`` or, for a
batch, ``(4, n)``; a rotation matrix is ``(3, 3)`` or ``(3, 3, n)``. ``batch=True`` accepts the
single shape and the single shape followed by batch axes; errors about one member of a batch
name it by index, e.g. ``q[:, 3]``.

Numbers only: callers that also accept CasADi symbols test `is_symbolic` first and skip the
check for ``SX``/``MX``. A ``casadi.DM`` holds numbers and is checked like an array (a ``n x 1``
DM is a vector of length ``n``).

Modules: `base` (the error class, symbol detection, shared array helpers), `numbers`
(finite arrays and scalars, integers, positive values, choices), `rotations` (unit vectors,
device axes, unit quaternions, rotation matrices and their tolerances), `inertia` (`check_inertia`).
"""
from __future__ import annotations

from .base import ArgumentTypeError, is_symbolic
from .inertia import check_inertia
from .numbers import (finite_array, finite_scalar, integer, nonnegative, one_of, positive,
                      positive_each)
from .rotations import (AXIS_NORM_TOL, DCM_ORTHO_TOL, EULER_LOCK_TOL, QUAT_NORM_TOL,
                        rotation_matrix, unit_axes,
                        check_unit_quaternion, unit_quaternion, unit_quaternions, unit_vector)

ArgumentTypeError.__module__ = __name__  # shown where users import it from

__all__ = [
    "ArgumentTypeError",
    "QUAT_NORM_TOL",
    "DCM_ORTHO_TOL",
    "AXIS_NORM_TOL",
    "EULER_LOCK_TOL",
    "is_symbolic",
    "finite_array",
    "finite_scalar",
    "unit_vector",
    "unit_axes",
    "positive_each",
    "nonnegative",
    "check_unit_quaternion",
    "unit_quaternion",
    "unit_quaternions",
    "rotation_matrix",
    "one_of",
    "integer",
    "positive",
    "check_inertia",
]

