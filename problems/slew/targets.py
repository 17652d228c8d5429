"""Inputs of a slew: the checks, the target attitude, the keep-out cone, and the defaults.

The defaults and statuses of every slew live here (`POINTING_TOL`, `RATE_TOL`,
`MIN_REFINE_TOL`, `STATUS_POINTING`, `STATUS_REFINE`); the checks have public names because
`problems.slew.problem` and `problems.slew.maneuvers` share them.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import casadi as ca
import numpy as np

from appdyn.dynamics import cache
from appdyn.dynamics.attitude import dcm_from_quat, quat_from_axis_angle, quat_mul, quat_normalize
from appdyn.dynamics.validate import finite_array, finite_scalar, unit_quaternion, unit_vector
from appdyn.dynamics.validate import positive
from appdyn.ocp.status import CODES as _CODES

__all__ = ["KeepOut", "POINTING_TOL", "RATE_TOL", "MIN_REFINE_TOL", "STATUS_POINTING",
           "STATUS_REFINE", "ARCSEC", "vector3", "targets", "check_u_max", "check_angle",
           "check_tol"]

POINTING_TOL = 1e-6  # [rad] default largest re-simulated final attitude error of a success
RATE_TOL = 1e-6  # [rad/s] default largest re-simulated final rate error of a success
MIN_REFINE_TOL = 1e-12  # smallest refinement tol min_effort accepts (CVODES reference ~1e-13)
STATUS_POINTING = _CODES["Pointing_Tol_Not_Met"]  #: status 106: pointing or rate error
STATUS_REFINE = _CODES["Refinement_Tol_Not_Met"]  #: status 107: refinement tolerance not reached
ARCSEC = 180.0 * 3600.0 / math.pi


@dataclass(frozen=True)
class KeepOut:
    """Keep-out cone: ``angle(A(q)^T boresight, direction) >= half_angle`` at all times.

    Parameters
    ----------
    boresight : array_like, shape (3,)
        Body-fixed unit vector (normalized here)
    direction : array_like, shape (3,)
        Inertial unit vector to avoid, e.g. the Sun
    half_angle : float [rad]
        In (0, pi)

    Examples
    --------
    Keep the body x axis 30 deg away from the inertial y axis (e.g. the Sun):

    >>> import numpy as np
    >>> from appdyn.problems import slew
    >>> cone = slew.KeepOut(boresight=[2, 0, 0], direction=[0, 1, 0], half_angle=np.radians(30))
    >>> cone.boresight, round(cone.half_angle, 6)
    ((1.0, 0.0, 0.0), 0.523599)
    >>> round(float(cone.margin([0, 0, 0, 1])), 6)  # >= 0: the identity attitude is clear
    0.866025
    """

    boresight: tuple
    direction: tuple
    half_angle: float

    def __post_init__(self):
        for name in ("boresight", "direction"):
            object.__setattr__(self, name,
                               tuple(float(v) for v in unit_vector(getattr(self, name), name)))
        a = finite_scalar(self.half_angle, "half_angle")
        if not (0 < a < math.pi):
            raise ValueError(f"KeepOut `half_angle` must be in (0, pi) rad, got {a}")
        object.__setattr__(self, "half_angle", a)

    def margin(self, q) -> np.ndarray:
        """``cos(half_angle) - cos(angle)``: >= 0 where the constraint holds.

        ``q`` (4,) or (4, n): attitudes, normalized first (a collocation solution's
        quaternion is unit only to the solver's tolerance).
        """
        A = dcm_from_quat(quat_normalize(np.asarray(q, dtype=float)))
        b, s = np.array(self.boresight), np.array(self.direction)
        # A(q) s: the inertial direction in body axes; its component along the boresight
        cosang = np.einsum("i,ij...,j->...", b, A, s)
        return math.cos(self.half_angle) - cosang

    def function(self) -> ca.Function:
        """Path constraint ``g(x, u, p) = dot(b, A(q) s) - cos(half_angle) <= 0``, built once
        per cone (in the one cache, under its construction lock: slews are stated in
        thread-pool tasks)."""
        return cache.get(("slew.keep_out", self), self._function)

    def _function(self) -> ca.Function:
        """`function`, built."""
        x, u, p = ca.SX.sym("x", 7), ca.SX.sym("u", 3), ca.SX.sym("p", 0)
        g = ca.dot(ca.DM(self.boresight), ca.mtimes(dcm_from_quat(x[:4]), ca.DM(self.direction)))
        return ca.Function("keep_out", [x, u, p], [g - math.cos(self.half_angle)],
                           ["x", "u", "p"], ["g"])


# ---------------------------------------------------------------------------- inputs
def vector3(v, name, default):
    """``default`` when ``v`` is None, else ``v`` as 3 finite numbers (`dynamics.validate`)."""
    return np.array(default, dtype=float) if v is None else finite_array(v, name, (3,))


def targets(q0, qf, angle, axis, *, qf_name="qf"):
    """``(q0, qf)``: ``q0`` (default identity) and the target ``qf``, or ``q0`` turned by
    ``angle`` [rad] about the body ``axis``; ``qf_name`` is ``qf``'s name in messages."""
    q0 = np.array([0.0, 0.0, 0.0, 1.0]) if q0 is None else unit_quaternion(q0, "q0")
    if qf is not None:
        if angle is not None or axis is not None:
            raise ValueError(f"give either `{qf_name}` or `angle` and `axis`, not both")
        return q0, unit_quaternion(qf, qf_name)
    if angle is None or axis is None:
        raise ValueError(f"the target needs `{qf_name}`, or both `angle` [rad] and `axis` "
                         f"(body frame)")
    angle = check_angle(angle)
    e = unit_vector(axis, "axis")
    return q0, quat_mul(quat_from_axis_angle(e, angle), q0)


def check_u_max(u_max):
    a = finite_array(u_max, "u_max").reshape(-1)
    if a.size == 1:
        a = np.repeat(a, 3)
    if a.shape != (3,) or np.any(a <= 0):
        raise ValueError(f"`u_max` must be a positive scalar or 3 positive values [N m], got {u_max!r}")
    return a


def check_angle(angle) -> float:
    """``angle`` [rad] as a finite float (`dynamics.validate.finite_scalar`)."""
    return finite_scalar(angle, "angle")

def check_tol(name, value, default):
    """``default`` when ``value`` is None, else a finite float > 0 (`dynamics.validate.positive`)."""
    return default if value is None else positive(value, name)
