"""Shared machinery of `dynamics.attitude`: numpy/CasADi dispatch and argument checks.

Every attitude function works on numpy arrays and CasADi ``SX``/``MX``/``DM`` alike. `ops_for`
picks the backend (`NumpyOps` or `CasadiOps`, the same small vocabulary of elementary
operations) from the arguments; `checked` validates one argument: numbers by one of the
checks below (built on `dynamics.validate`), symbolic ``SX``/``MX`` by shape only.
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from .. import validate

__all__ = [
    "CA_TYPES", "NumpyOps", "CasadiOps", "ops_for", "checked", "finite3", "finite4",
    "unit_quat", "rotation_matrix", "finite_any", "finite_scalar", "finite_vector", "nonzero3",
    "nonzero4", "unit_axis",
]


CA_TYPES = (ca.SX, ca.MX, ca.DM)
"""The CasADi types; any of them among the arguments selects `CasadiOps`."""


class NumpyOps:
    sin, cos, sqrt, arctan2, arccos = np.sin, np.cos, np.sqrt, np.arctan2, np.arccos
    fabs = np.abs

    @staticmethod
    def stack(items):
        return np.stack(np.broadcast_arrays(*items), axis=0)

    @classmethod
    def matrix(cls, rows):
        return cls.stack([cls.stack(r) for r in rows])

    @staticmethod
    def where(cond, a, b):
        return np.where(cond, a, b)

    @staticmethod
    def sumsq(x):
        return np.sum(x * x, axis=0)


class CasadiOps:
    sin, cos, sqrt, arctan2, arccos = ca.sin, ca.cos, ca.sqrt, ca.atan2, ca.acos
    fabs = ca.fabs

    @staticmethod
    def stack(items):
        return ca.vertcat(*items)

    @staticmethod
    def matrix(rows):
        return ca.vertcat(*[ca.horzcat(*r) for r in rows])

    @staticmethod
    def where(cond, a, b):
        return ca.if_else(cond, a, b)

    @staticmethod
    def sumsq(x):
        return ca.sumsqr(x)


def ops_for(*args):
    return CasadiOps if any(isinstance(a, CA_TYPES) for a in args) else NumpyOps


def checked(x, name, shape, check):
    """Validate one argument: numbers by ``check(x, name)``, CasADi by shape.

    ``SX``/``MX`` symbols pass through untouched (only their shape is checked); a ``DM`` holds
    numbers, so its values are checked by ``check`` too, and it is returned as a DM (CasADi in,
    CasADi out). ``shape`` is the numpy shape of one item: ``(n,)`` means an ``n x 1`` CasADi
    column, ``()`` a ``1 x 1`` scalar.
    """
    if isinstance(x, CA_TYPES):
        want = shape if len(shape) == 2 else ((shape[0], 1) if shape else (1, 1))
        if x.shape != want:
            kind = {(1, 1): "scalar (1x1)"}.get(want, f"{want[0]}x{want[1]} CasADi "
                                                     + ("column" if want[1] == 1 else "matrix"))
            raise ValueError(f"`{name}` must be a {kind}, got shape {x.shape}")
        if isinstance(x, ca.DM):
            check(x, name)
        return x
    return check(x, name)


def finite3(x, name):
    return validate.finite_array(x, name, (3,), batch=True)


def finite4(x, name):
    return validate.finite_array(x, name, (4,), batch=True)


def unit_quat(x, name):
    return validate.unit_quaternions(x, name, normalize=True)


def rotation_matrix(x, name):
    return validate.rotation_matrix(x, name, batch=True)


def finite_any(x, name):
    return validate.finite_array(x, name)


finite_scalar = validate.finite_scalar  # (the one check; re-exported for the attitude modules)


def finite_vector(x, name):
    """A finite scalar or 1-D array (e.g. angles ``(n,)``); refuses higher dimensions."""
    a = validate.finite_array(x, name)
    if a.ndim > 1:
        raise ValueError(f"`{name}` must be a scalar or have shape (n,), got {a.shape}")
    return a


def nonzero3(x, name):
    return validate.unit_vector(x, name, batch=True)


def nonzero4(x, name):
    return validate.unit_vector(x, name, size=4, batch=True)


def unit_axis(axis, name="axis"):
    if isinstance(axis, CA_TYPES):
        axis = checked(axis, name, (3,), nonzero3)
        return axis / ca.sqrt(ca.sumsqr(axis))
    return validate.unit_vector(axis, name, batch=True)
