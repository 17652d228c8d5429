"""Worked mechanisms of the seeds, each a `Model` builder with its closed forms.

* `pendulums` -- the double pendulum (Rheinfurth & Wilson, NASA RP-1262, Sec. 5.4 a) with
  its normal-mode frequencies, the pendulum on a string of prescribed length (Eq. 5.51),
  and the exact simple pendulum (`pendulum_swing`, `pendulum_period`);
* `spherical` -- the spherical pendulum of Ch. 6 Example 1 in 3-1-3 and 3-2-1 angles, the
  conical rate and the mass matrices;
* `shaken` -- the physical pendulum on a sinusoidally shaken hinge (seed 000, Euler's law
  about an arbitrary point), with the Kapitza frequency and the first resonance tongue;
* `multipliers` -- systems held by Lagrange multipliers (`dynamics.constrained`): the rod
  pendulum in Cartesian coordinates and its rod tension, the shaken pendulum a second time
  (its multipliers the hinge force), the bead on a driven wire (Eq. 5.79);
* `hamel` -- the Boltzmann-Hamel equations (Sec. 6.1): equations of motion in
  quasi-velocities from ``T*(q, u)`` and the kinematics ``q' = W(q) u``;
* `noninertial` -- a particle in a frame with prescribed motion (Sec. 2.2, Eq. 2.1: the
  d'Alembert, Euler, centrifugal and Coriolis forces) and the seed's examples: turntable,
  Foucault pendulum, accelerometer, twirling skater;
* `bodies` -- constrained rigid bodies: the rolling coin (nonholonomic) with its steady
  circular rolling, the rolling sphere (Sec. 5.5 a, its 2 x 5 constraint matrix), and the
  dumbbell elastically hinged to a free disk with its planar swing frequency;
* `lagrange` -- Lagrange's equations by automatic differentiation, with applied forces at
  points, explicit time and velocity-dependent potentials (`lagrange_model`), and the
  assembly of a constrained model (shared by `multipliers` and `bodies`);
* `impacts` -- impact dynamics (Sec. 3.5): `impact` (restitution, sticking and sliding
  contact on a generalized-coordinate model), `contact_jump` (its jump map for an impact
  event of `simulate`) and Examples 1-5 (`central_collision`, `ballistic_pendulum`,
  `dumbbell_impact`, `carriage_impact`, `falling_bar_impact`);
* `common` -- the shared symbols, model assembly and parameter checks.

Time-dependent mechanisms carry the clock state ``t`` of `dynamics.clock`. Every model
keeps its physical constants as parameters (``model.params``), defaulting to the builder's
arguments, so one built right-hand side serves all values.
"""
from __future__ import annotations

from .common import GRAVITY
from .bodies import (coin_state, coin_steady_rates, dumbbell_disk, dumbbell_disk_frequency,
                     dumbbell_disk_state, rolling_coin, rolling_sphere, sphere_constraint_matrix,
                     sphere_state)
from .hamel import hamel_model, hamel_terms
from .lagrange import generalized_forces, lagrange_model, lagrange_terms
from .noninertial import (EARTH_RATE, accelerometer, accelerometer_offset, foucault_pendulum,
                          foucault_precession_rate, foucault_swing, noninertial_particle,
                          skater_rate, skater_work, turntable, turntable_path,
                          twirling_skater)
from .impacts import (ImpactResult, ballistic_pendulum, carriage_impact, central_collision,
                      contact_jump, dumbbell_impact, falling_bar_impact, impact)
from .multipliers import (bead_motion, bead_torque, rod_pendulum, rod_reaction,
                          shaken_multiplier_state, shaken_pendulum_multipliers, sliding_bead)
from .pendulums import (double_pendulum, double_pendulum_modes, pendulum_period, pendulum_swing,
                        variable_length_pendulum)
from .shaken import (SHAKEN_DEFAULTS, equivalent_length, kapitza_frequency, natural_frequency,
                     resonance_tongue, shaken_pendulum)
from .spherical import SEQUENCES, conical_rate, spherical_mass_matrix, spherical_pendulum

__all__ = ["GRAVITY", "SEQUENCES", "SHAKEN_DEFAULTS", "bead_motion", "bead_torque",
           "coin_state", "coin_steady_rates", "conical_rate", "double_pendulum",
           "double_pendulum_modes", "dumbbell_disk", "dumbbell_disk_frequency",
           "dumbbell_disk_state", "equivalent_length", "kapitza_frequency", "lagrange_terms",
           "lagrange_model", "generalized_forces",
           "natural_frequency", "pendulum_period", "pendulum_swing", "resonance_tongue",
           "rod_pendulum", "rod_reaction", "rolling_coin", "shaken_multiplier_state",
           "shaken_pendulum", "shaken_pendulum_multipliers", "sliding_bead",
           "spherical_mass_matrix", "spherical_pendulum", "variable_length_pendulum",
           "EARTH_RATE", "hamel_model", "hamel_terms", "accelerometer", "accelerometer_offset",
           "foucault_pendulum",
           "foucault_precession_rate", "foucault_swing", "noninertial_particle", "skater_rate",
           "skater_work", "turntable", "turntable_path", "twirling_skater",
           "ImpactResult", "ballistic_pendulum", "carriage_impact", "central_collision",
           "contact_jump", "dumbbell_impact", "falling_bar_impact", "impact", "rolling_sphere",
           "sphere_constraint_matrix", "sphere_state"]
