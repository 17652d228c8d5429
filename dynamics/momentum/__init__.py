"""Momentum-exchange devices (Rheinfurth & Wilson, NASA RP-1262, Sec. 4.7): reaction wheels,
control moment gyro clusters, steering laws and singularity analysis, and the seed's
gyroscopic torque formulas.

Modules (every name in ``__all__`` is importable from ``dynamics.momentum``):

* `cluster` -- single-gimbal CMG cluster geometry (`ClusterGeometry`, `pyramid`), momentum,
  Jacobian, singularity measure and classification;
* `steering` -- steering laws (pseudo-inverse, singularity-robust, generalized SR) and null
  motion, with the sign convention ``torque on the body = -C delta_dot``;
* `gyroscopic` -- the torques of Eqs. 4.148-4.152 (wheel, CMG, Coriolis, propeller,
  symmetric gyroscope);
* `wheels` -- `wheel_spacecraft` and `rotor_dynamics`, the one body-plus-rotor derivation
  (`dynamics.spinning.gyrostat_model` is its scene twin, a wheel held at constant speed);
* `cmg` -- `cmg_spacecraft` (exact and torque-model fidelity);
* `envelope` -- singular surfaces and the momentum envelope (`momentum_envelope`,
  `MomentumEnvelope`, `singular_surface`, `classify_singularities`);
* `steering_sim` -- steering-law simulations (`steering_model`, `steer`, `SteeringResult`).
"""
from __future__ import annotations

from .cluster import (ClusterGeometry, classify_singularity, cluster_jacobian, cluster_momentum,
                      gram_determinant, pyramid, singular_direction, singularity_measure)
from .gyroscopic import (cmg_torque, coriolis_torque, gyroscope_reaction_torque,
                         propeller_torque, wheel_torque)
from .cmg import cmg_spacecraft
from .envelope import (MomentumEnvelope, classify_singularities, fibonacci_directions,
                       momentum_envelope, singular_surface)
from .steering import (gsr_inverse_steering, null_motion, pseudo_inverse_steering,
                       sr_inverse_steering)
from .steering_sim import SteeringResult, steer, steering_model
from .wheels import rotor_dynamics, wheel_spacecraft

__all__ = [
    "wheel_spacecraft",
    "cmg_spacecraft",
    "rotor_dynamics",
    "ClusterGeometry",
    "pyramid",
    "cluster_momentum",
    "cluster_jacobian",
    "gram_determinant",
    "singularity_measure",
    "singular_direction",
    "classify_singularity",
    "pseudo_inverse_steering",
    "sr_inverse_steering",
    "gsr_inverse_steering",
    "null_motion",
    "fibonacci_directions",
    "singular_surface",
    "classify_singularities",
    "momentum_envelope",
    "MomentumEnvelope",
    "steering_model",
    "steer",
    "SteeringResult",
    "wheel_torque",
    "cmg_torque",
    "coriolis_torque",
    "propeller_torque",
    "gyroscope_reaction_torque",
]
