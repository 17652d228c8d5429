"""Attitude kinematics: quaternions, direction cosines, Euler angles, principal axes.

Conventions (Rheinfurth & Wilson, NASA RP-1262, Sec. 4.3):

* Quaternion **scalar-last** ``q = [q1, q2, q3, q4]`` with ``q4 = cos(delta/2)`` (Eqs. 4.55-4.58).
* The direction cosine matrix ``A(q)`` (Eq. 4.63) maps inertial components to body components,
  ``x_body = A @ x_inertial``. Its rows are the body unit vectors in inertial components.
* Kinematics ``qdot = -1/2 Wbar(w) q`` (Eq. 4.70) with the body angular velocity ``w``.
* ``quat_mul(q, p)`` is defined so that ``A(quat_mul(q, p)) = A(q) @ A(p)``: ``p`` is applied
  first, then ``q`` (successive frame rotations).
* Euler angles: classical 3-1-3 ``(psi, theta, phi)`` with ``A = A3(phi) A1(theta) A3(psi)``;
  modern 3-2-1 ``(psi, theta, phi)`` (yaw, pitch, roll) with ``A = A1(phi) A2(theta) A3(psi)``.
  ``A1, A2, A3`` are frame rotations (Eq. 4.45 with the axis along a coordinate axis).

Every function works on numpy arrays and on CasADi ``SX``/``MX``/``DM`` alike. Arrays are
**components first**: a quaternion is shape ``(4,)`` or, for a batch, ``(4, n)``; a DCM is
``(3, 3)`` or ``(3, 3, n)``; Euler angle triples are ``(3,)`` or ``(3, n)``. CasADi inputs are
column vectors (``4x1``, ``3x1``) and ``3x3`` matrices.

Input checks (`dynamics.validate`): numeric arguments (numpy arrays, lists, numbers and CasADi
``DM``) are checked on every call; symbolic ``SX``/``MX`` arguments pass through untouched
(only their shape is checked), so the functions keep working inside CasADi graphs. A wrong
kind of object (string, dict, ``None``, complex, boolean) raises ``TypeError``; a wrong shape
or value raises ``ValueError`` naming the argument (for a batch, the first bad column, e.g.
``q[:, 3]``). What each function accepts:

* every number must be finite (no NaN, no infinity);
* a quaternion that stands for an *attitude* (``dcm_from_quat``, ``rotation_angle``,
  ``axis_angle_from_quat``, ``propagate_quat``, ``euler313_from_quat``,
  ``euler321_from_quat``) must have unit norm to ``validate.QUAT_NORM_TOL`` (1e-6); it is
  then normalized before use;
* quaternion *algebra* (``quat_mul``, ``quat_conj``, ``quat_rate``) accepts any finite
  quaternion, since it also acts on rates ``qdot`` and on states off the unit sphere;
  ``quat_normalize`` accepts any finite non-zero quaternion;
* a DCM argument must be a proper rotation: orthogonal to ``validate.DCM_ORTHO_TOL`` (1e-6,
  ``max |A A^T - E|``) with ``det A = +1``;
* a rotation axis must be a finite non-zero 3-vector (normalized here); angles, rates and
  time steps must be finite.

Modules (every name in ``__all__`` is importable from ``dynamics.attitude``):

* `quaternion` -- products, conjugate, normalization, kinematics matrix and rate, rotation
  angle, closed-form propagation;
* `dcm` -- DCM <-> quaternion and axis-angle conversions;
* `euler` -- elementary rotations, 3-1-3 and 3-2-1 angles;
* `rates` -- kinematical differential equations: 3-2-1 and 3-1-3 Euler-angle rates <-> body
  rates (Eqs. 4.36-4.40, refused at gimbal lock for numbers) and the DCM Poisson equation
  ``A' = -[w x] A`` (Eq. 4.33);
* `principal` -- principal axes of an inertia matrix;
* `aero` -- aerodynamic (direction) angles of the body-frame air velocity: Type I
  ``(alpha, beta)``, Type II ``(alpha_T, phi_R)`` and the conversions (seed Sec. 4.3 E);
* `backend` -- the numpy/CasADi dispatch and argument checks the others share.
"""
from __future__ import annotations

from .aero import (aero_angles, aero_angles_from_total, total_aoa, total_aoa_from_aero_angles,
                   velocity_direction, velocity_direction_total)
from .dcm import (axis_angle_from_quat, dcm_from_axis_angle, dcm_from_quat, quat_from_axis_angle,
                  quat_from_dcm)
from .euler import (dcm_axis, dcm_from_euler313, dcm_from_euler321, euler313_from_dcm,
                    euler313_from_quat, euler321_from_dcm, euler321_from_quat, quat_from_euler313,
                    quat_from_euler321)
from .principal import principal_axes
from .quaternion import (propagate_quat, quat_conj, quat_kinematics_matrix, quat_mul, quat_normalize,
                         quat_rate, rotation_angle, skew)
from .rates import (body_rates_from_euler313, body_rates_from_euler321, dcm_rate,
                    euler313_rates, euler321_rates)

__all__ = [
    "skew",
    "quat_mul",
    "quat_conj",
    "quat_normalize",
    "quat_kinematics_matrix",
    "quat_rate",
    "dcm_from_quat",
    "quat_from_dcm",
    "dcm_from_axis_angle",
    "quat_from_axis_angle",
    "axis_angle_from_quat",
    "rotation_angle",
    "propagate_quat",
    "dcm_axis",
    "dcm_from_euler313",
    "euler313_from_dcm",
    "quat_from_euler313",
    "euler313_from_quat",
    "dcm_from_euler321",
    "euler321_from_dcm",
    "quat_from_euler321",
    "euler321_from_quat",
    "euler321_rates",
    "body_rates_from_euler321",
    "euler313_rates",
    "body_rates_from_euler313",
    "dcm_rate",
    "principal_axes",
    "aero_angles",
    "total_aoa",
    "aero_angles_from_total",
    "total_aoa_from_aero_angles",
    "velocity_direction",
    "velocity_direction_total",
]
