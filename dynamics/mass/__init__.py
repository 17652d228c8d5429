"""Mass properties and variable mass: inertia transformations and the rocket equations.

Rheinfurth & Wilson, NASA RP-1262:

* Sec. 4.4 B-E -- the parallel-axis (Steiner) theorem `parallel_axis`, the rotated-axes law
  `rotate_inertia`, the moment of inertia about an axis `inertia_about_axis` (Eq. 4.81) and the
  radius of gyration `radius_of_gyration`;
* Sec. 3.4 -- variable mass: the bullets fired from a vehicle on rails `rocket_steps` (the
  discrete rocket, whose limit is Tsiolkovsky's ``V = C ln(M0/M)``), `delta_v`, the specific
  impulse `isp` (Eq. 3.40) and the jet-damping torque `jet_damping_torque` (Eq. 3.49).

Conventions: products of inertia with the seed's sign (Eq. 4.16, ``Ixy = -sum m x y``), so an
inertia matrix is ``sum m (r^2 E - r r^T)``; a DCM ``A`` maps old (unprimed) to new (primed)
components, ``x' = A x``. SI units. Numpy only (mass properties are set-up data, not states).

Modules: `inertia` (Sec. 4.4) and `rocket` (Sec. 3.4); every name is importable from
``dynamics.mass``.
"""
from __future__ import annotations

from .inertia import inertia_about_axis, parallel_axis, radius_of_gyration, rotate_inertia
from .rocket import G0, delta_v, isp, jet_damping_torque, rocket_steps

__all__ = ["G0", "parallel_axis", "rotate_inertia", "inertia_about_axis", "radius_of_gyration",
           "isp", "delta_v", "rocket_steps", "jet_damping_torque"]
