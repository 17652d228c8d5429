"""Gyroscopic torques of internal rotating masses (Rheinfurth & Wilson, NASA RP-1262, Sec. 4.7).

A body ``M_0`` turning at ``Omega`` (inertial angular velocity, body frame) carries a mass ``m``
spinning at ``omega`` relative to it. Its rotational equation (Eq. 4.147) is

    ``I Omegadot + Omega x I Omega + 2 Omega . C_m x omega + I_m omegadot + omega x I_m omega = L``

with ``I`` the inertia of the whole system, ``I_m`` that of the moving mass about its own mass
center and the *Coriolis dyadic* ``C_m = int r r dm = (1/2 tr I_m) E - I_m`` (Eq. 4.144).
Moving a term to the right-hand side makes it a torque on the main body:

* `wheel_torque` -- momentum (reaction) wheel, ``L = -I_m omegadot`` (Eq. 4.148);
* `cmg_torque` -- control moment gyro, ``L = -w_c x H_m`` (Eq. 4.150);
* `coriolis_torque` -- Coriolis reaction torque ``L_R = -2 Omega·C_m x omega`` (Eq. 4.151);
* `propeller_torque` -- the seed's Example 1, a propeller on a yawing airplane;
* `gyroscope_reaction_torque` -- symmetric gyroscope, ``L_R = -Omega x H`` (Eq. 4.152).

All are SI (rates [rad/s], inertia [kg m^2], momentum [N m s], torque [N m]) and work on numpy
and CasADi ``SX``/``MX``/``DM`` alike; 3-vectors may be numpy batches ``(3, m)`` where said.
"""
from __future__ import annotations

import math

import casadi as ca
import numpy as np

from .. import validate
from ..attitude.backend import CA_TYPES, checked, finite3, finite_any, finite_vector, ops_for
from ..validate.base import cross3

__all__ = ["wheel_torque", "cmg_torque", "coriolis_torque", "propeller_torque",
           "gyroscope_reaction_torque"]


def _vec3(x, name):
    return checked(x, name, (3,), finite3)


def _neg_cross(a, b):
    """``-(a x b) = b x a`` of two 3-vectors (numpy batches or CasADi columns)."""
    return ops_for(a, b).stack(cross3(b, a))


def _inertia(inertia, name="inertia"):
    """A 3x3 inertia dyadic: CasADi 3x3, or numbers of shape (3, 3) or (3,) (principal)."""
    if isinstance(inertia, CA_TYPES):
        return checked(inertia, name, (3, 3), finite_any)
    a = validate.finite_array(inertia, name)
    if a.shape == (3,):
        return np.diag(a)
    if a.shape != (3, 3):
        raise ValueError(f"`{name}` must have shape (3, 3) or (3,) (principal moments) "
                         f"[kg m^2], got {a.shape}")
    return a


def _matvec(M, v):
    if isinstance(M, CA_TYPES) or isinstance(v, CA_TYPES):
        return ca.mtimes(M, v)
    return M @ v


def wheel_torque(wheel_inertia, wheel_accel):
    """Momentum-wheel control torque on the body, ``L_c = -I_m·omegadot_c`` (Eq. 4.148).

    The wheel spins about a principal axis, so ``omega x I_m omega = 0``; the torque is the
    reaction to its relative angular acceleration. Vector form: with a scalar axial moment
    ``I_a`` and ``omegadot_c = alpha a`` along the spin axis ``a``, ``L_c = -I_a alpha a``.

    Parameters
    ----------
    wheel_inertia : float [kg m^2], array_like shape (3, 3), or CasADi scalar / 3x3
        Axial moment of inertia of the wheel (the acceleration is along the spin axis), or its
        full inertia dyadic ``I_m`` in body components.
    wheel_accel : array_like, shape (3,) or (3, m) [rad/s^2], or CasADi 3x1
        Relative angular acceleration ``omegadot_c`` of the wheel (body frame).

    Returns
    -------
    L : ndarray, shape (3,) or (3, m) [N m], or CasADi 3x1

    Examples
    --------
    >>> from appdyn.dynamics.momentum import wheel_torque
    >>> wheel_torque(0.05, [2.0, -2.0, 2.0])  # spin-up about (1, -1, 1) pushes the body back
    array([-0.1,  0.1, -0.1])
    """
    accel = _vec3(wheel_accel, "wheel_accel")
    if isinstance(wheel_inertia, CA_TYPES):
        scalar = wheel_inertia.shape == (1, 1)
    else:
        scalar = np.ndim(wheel_inertia) == 0
    if scalar:
        inertia = checked(wheel_inertia, "wheel_inertia", (), finite_any)
        return -inertia * accel
    return -_matvec(_inertia(wheel_inertia, "wheel_inertia"), accel)


def cmg_torque(gimbal_rate_vector, rotor_momentum):
    """Control-moment-gyro torque on the body, ``L_c = -w_c x H_m`` (Eq. 4.150).

    The rotor momentum ``H_m = I_m . omega_0`` (Eq. 4.149) is turned by the gimbal at
    ``w_c``; the body receives the reaction to ``dH_m/dt = w_c x H_m``. For unit ``i`` of a
    cluster, ``w_c = delta_dot_i g_i`` and ``H_m = h_i s_i`` give ``-delta_dot_i h_i t_i``:
    the sum over the units is ``-C delta_dot`` (`dynamics.momentum.steering`).

    Parameters
    ----------
    gimbal_rate_vector : array_like, shape (3,) or (3, m) [rad/s], or CasADi 3x1
        Gimbal angular velocity ``w_c`` relative to the body (body frame).
    rotor_momentum : array_like, shape (3,) or (3, m) [N m s], or CasADi 3x1
        Rotor angular momentum ``H_m`` (body frame).

    Returns
    -------
    L : ndarray, shape (3,) or (3, m) [N m], or CasADi 3x1

    Examples
    --------
    >>> from appdyn.dynamics.momentum import cmg_torque
    >>> cmg_torque([0.0, 0.0, 0.5], [10.0, 0.0, 0.0])  # -(0.5 e_z) x (10 e_x)
    array([ 0., -5.,  0.])
    """
    return _neg_cross(_vec3(gimbal_rate_vector, "gimbal_rate_vector"),
                      _vec3(rotor_momentum, "rotor_momentum"))


def coriolis_torque(Omega, omega, inertia):
    """Coriolis reaction torque ``L_R = -2 Omega·C_m x omega`` (Eq. 4.151).

    ``C_m = (1/2 tr I_m) E - I_m`` (Eq. 4.144). In the principal axes of the moving mass
    (moments ``I_1, I_2, I_3``) this is the seed's component form

    * ``L_1 = Omega_3 omega_2 (I_1 + I_2 - I_3) - Omega_2 omega_3 (I_1 - I_2 + I_3)``,
    * ``L_2 = Omega_1 omega_3 (I_2 + I_3 - I_1) - Omega_3 omega_1 (I_1 + I_2 - I_3)``,
    * ``L_3 = Omega_2 omega_1 (I_1 - I_2 + I_3) - Omega_1 omega_2 (I_2 + I_3 - I_1)``.

    Parameters
    ----------
    Omega : array_like, shape (3,) [rad/s], or CasADi 3x1
        Inertial angular velocity of the main body.
    omega : array_like, shape (3,) [rad/s], or CasADi 3x1
        Angular velocity of the moving mass relative to the main body.
    inertia : array_like, shape (3, 3) or (3,) [kg m^2], or CasADi 3x3
        Inertia dyadic ``I_m`` of the moving mass about its own mass center, in the components
        of ``Omega`` and ``omega`` (three numbers: principal moments in those axes). Only
        symmetry of the physics is assumed: a slender rod with a zero moment is accepted.

    Returns
    -------
    L_R : ndarray, shape (3,) [N m], or CasADi 3x1

    Examples
    --------
    >>> from appdyn.dynamics.momentum import coriolis_torque
    >>> coriolis_torque([0.0, 0.0, 1.0], [10.0, 0.0, 0.0], [2.0, 1.0, 1.0])  # -Omega x I1 omega
    array([  0., -20.,   0.])
    """
    Omega, omega = _vec3(Omega, "Omega"), _vec3(omega, "omega")
    inertia = _inertia(inertia)
    trace = inertia[0, 0] + inertia[1, 1] + inertia[2, 2]
    coriolis = 0.5 * trace * (ca.DM.eye(3) if isinstance(inertia, CA_TYPES) else np.eye(3)) \
        - inertia
    return 2.0 * _neg_cross(_matvec(coriolis, Omega), omega)


def propeller_torque(yaw_rate, spin_rate, inertia, t, *, blades=2, phase=0.0):
    """Gyroscopic (Coriolis) reaction torque of a propeller on a yawing airplane (Sec. 4.7,
    Example 1).

    Airplane axes: ``X`` along the propeller shaft, ``Z`` the yaw axis (``Omega = yaw_rate Z``),
    ``Y = Z x X``. The propeller spins at ``omega_0 X`` and has ``blades`` equal slender
    blades at the angles ``phi_k = omega_0 t + phase + 2 pi k / N`` from ``Z`` (about ``+X``).
    Summing Eq. 4.151 over the blades (blade ``k`` has ``C_k = (I / N) b_k b_k``, ``I`` the
    polar moment of the propeller):

    ``L_Y = -(I / N) yaw_rate omega_0 sum_k (1 + cos 2 phi_k)``,
    ``L_Z = -(I / N) yaw_rate omega_0 sum_k sin 2 phi_k``,  ``L_X = 0``.

    For two blades this is the seed's ``L_Y = -2 I yaw_rate omega_0 cos^2 phi``,
    ``L_Z = -2 I yaw_rate omega_0 sin phi cos phi`` (``I = m l^2 / 12``): a torque at twice the
    propeller frequency. For three or more blades the cyclic part cancels and the torque is the
    steady ``-Omega x H = -I yaw_rate omega_0 Y`` (Eq. 4.152). The centrifugal term
    ``-Omega x I_p Omega`` (the seed's ``L_x``, not gyroscopic) is not included.

    Parameters
    ----------
    yaw_rate : float [rad/s], or CasADi scalar
    spin_rate : float [rad/s], or CasADi scalar
        Propeller speed ``omega_0`` about ``+X``.
    inertia : float [kg m^2], or CasADi scalar
        Polar moment ``I`` of the whole propeller about its shaft.
    t : float or array_like, shape (m,) [s], or CasADi scalar
    blades : int, optional
        Number of blades ``N >= 2``.
    phase : float [rad], optional
        Angle of blade 0 from ``Z`` at ``t = 0``.

    Returns
    -------
    L : ndarray, shape (3,) or (3, m) [N m] (airplane axes X, Y, Z), or CasADi 3x1

    Raises
    ------
    ValueError
        Naming the argument: ``yaw_rate``, ``spin_rate`` or ``inertia`` not a finite scalar
        (``inertia`` also not positive), ``t`` not finite or of more than one dimension,
        ``blades`` below 2, ``phase`` not finite.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.momentum import propeller_torque
    >>> np.round(propeller_torque(0.1, 100.0, 2.0, [0.0, np.pi / 400]), 12) + 0.0
    array([[  0.,   0.],
           [-40., -20.],
           [  0., -20.]])
    >>> np.round(propeller_torque(0.1, 100.0, 2.0, 0.3, blades=3), 12) + 0.0  # steady
    array([  0., -20.,   0.])
    """
    scalars = [checked(x, name, (), check) for x, name, check in
               ((yaw_rate, "yaw_rate", validate.finite_scalar),
                (spin_rate, "spin_rate", validate.finite_scalar),
                (inertia, "inertia", validate.positive), (t, "t", finite_vector))]
    yaw_rate, spin_rate, inertia, t = scalars
    n = validate.integer(blades, "blades", minimum=2)
    phase = validate.finite_scalar(phase, "phase")
    o = ops_for(*scalars)
    angles = [2 * (spin_rate * t + phase + 2 * math.pi * k / n) for k in range(n)]
    gain = -inertia / n * yaw_rate * spin_rate
    return o.stack([0 * t, gain * sum(1 + o.cos(a) for a in angles),
                    gain * sum(o.sin(a) for a in angles)])


def gyroscope_reaction_torque(Omega, H):
    """Reaction torque of a symmetric gyroscope, ``L_R = -Omega x H`` (Eq. 4.152).

    ``H = I_1 omega_0`` is the rotor's momentum relative to the rotating system (steady spin
    about its symmetry axis, ``I_2 = I_3``); the result is Eq. 4.151 for that rotor, exact for
    any ratio of ``omega_0`` to ``Omega``. It turns ``Omega`` towards ``omega_0`` (Foucault's
    homologous parallelism).

    Parameters
    ----------
    Omega : array_like, shape (3,) or (3, m) [rad/s], or CasADi 3x1
        Angular velocity forced on the gyroscope's frame (body frame).
    H : array_like, shape (3,) or (3, m) [N m s], or CasADi 3x1
        Relative angular momentum of the rotor.

    Returns
    -------
    L_R : ndarray, shape (3,) or (3, m) [N m], or CasADi 3x1

    Examples
    --------
    >>> from appdyn.dynamics.momentum import gyroscope_reaction_torque
    >>> gyroscope_reaction_torque([0.0, 0.0, 1.0], [5.0, 0.0, 0.0])
    array([ 0., -5.,  0.])
    """
    return _neg_cross(_vec3(Omega, "Omega"), _vec3(H, "H"))
