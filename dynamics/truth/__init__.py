"""Closed-form truth models of torque-free rigid-body rotation (numpy/scipy only).

These functions are *independent references* for the tests and benchmarks of the simulation
code: they use no integrator and none of appdyn's model code, only closed forms
(Rheinfurth & Wilson, NASA RP-1262, Sec. 4.5; Landau & Lifshitz, Mechanics, Sec. 37). Even
the quaternion product and the direction cosine matrix they need are written out (in
`dynamics.truth.common`) rather than imported from ``dynamics.attitude``, so that a bug
there cannot hide itself. (Only the input checks are shared: `dynamics.validate`.)

Modules, by topic (every name below is also importable from ``dynamics.truth``):

* `torque_free` -- the general body: `energy`, `momentum_magnitude`, the Jacobi-elliptic
  solution `torque_free_omega` and its constants `torque_free_parameters`;
* `axisymmetric` -- an axisymmetric body (`axisymmetric`, `symmetric_precession`) and a
  constant body rate (`constant_rate_quat`);
* `cones` -- small-motion formulas: `cone_angles`, `small_asymmetry_rates`,
  `small_asymmetry_frequency`;
* `forced` -- coning and forced motion of spinners (Secs. 4.5 C, 4.6 Methods I and II):
  `coning_angle`, `misaligned_thrust`, `floating_frame_accelerations`,
  `horizontal_gyroscope`;
* `common` -- input checks, tolerances and the private-to-truth quaternion kernels.

An integer principal-axis argument or result field is ``axis_index`` (0-based); the old
name ``axis`` still works and warns (``DeprecationWarning``).

Conventions (the project's):

* Principal body axes; ``inertia_diag`` holds the three principal moments in **any** order
  (equal moments allowed). Euler's torque-free equations ``I1 w1' = (I2 - I3) w2 w3``
  (cyclic), i.e. ``I w' = (I w) x w``.
* Quaternion scalar-last ``q = [q1, q2, q3, q4]``, ``q4 = cos(delta/2)``. The DCM
  ``A(q) = (q4^2 - |qv|^2) E + 2 qv qv^T - 2 q4 [qv x]`` maps inertial to body components.
  Kinematics ``qv' = 1/2 (q4 w + qv x w)``, ``q4' = -1/2 w . qv`` with body rates ``w``.
  ``quat_mul(q, p) = [q4 pv + p4 qv - qv x pv, q4 p4 - qv . pv]``, so that
  ``A(quat_mul(q, p)) = A(q) A(p)``.
* Arrays are components first: rates ``(3, n)``, quaternions ``(4, n)``. A time argument
  ``t`` is a scalar or a 1-D array of ``n`` times [s]; a scalar gives ``n = 1``. Times need not
  be sorted and may be negative (the closed forms hold for all real ``t``).
* SI units, radians.
"""
from __future__ import annotations

from .axisymmetric import SymmetricPrecession, axisymmetric, constant_rate_quat, symmetric_precession
from .cones import ConeAngles, cone_angles, small_asymmetry_frequency, small_asymmetry_rates
from .forced import (HorizontalGyroscope, MisalignedThrust, coning_angle,
                     floating_frame_accelerations, horizontal_gyroscope, misaligned_thrust)
from .torque_free import (TorqueFreeParameters, energy, momentum_magnitude, torque_free_omega,
                          torque_free_parameters)

__all__ = [
    "TorqueFreeParameters",
    "torque_free_parameters",
    "torque_free_omega",
    "axisymmetric",
    "constant_rate_quat",
    "energy",
    "momentum_magnitude",
    "ConeAngles",
    "cone_angles",
    "small_asymmetry_rates",
    "small_asymmetry_frequency",
    "SymmetricPrecession",
    "symmetric_precession",
    "coning_angle",
    "MisalignedThrust",
    "misaligned_thrust",
    "floating_frame_accelerations",
    "HorizontalGyroscope",
    "horizontal_gyroscope",
]
