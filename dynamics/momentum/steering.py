"""CMG steering laws and null motion (Wie, *Space Vehicle Dynamics and Control*, Sec. 7.3).

Sign convention (the one used everywhere in `dynamics.momentum`): a cluster with Jacobian
``C = dH/d(delta)`` (`dynamics.momentum.cluster.cluster_jacobian`) turning its gimbals at
``delta_dot`` exerts on the body the torque

    ``tau = -Hdot = -C delta_dot``

(Eq. 4.150, ``L = -w_c x H_m``, summed over the units). Every law here takes the *commanded
body torque* ``torque`` [N m] and returns gimbal rates that solve ``C delta_dot = -torque``
(exactly, or in the damped least-squares sense of the singularity-robust laws):

* `pseudo_inverse_steering` -- ``delta_dot = -C^+ torque`` (Moore-Penrose; minimum norm);
* `sr_inverse_steering` -- ``delta_dot = -C^T (C C^T + lam I)^-1 torque`` with
  ``lam = lam0 exp(-mu det(C C^T))`` (singularity-robust inverse, Nakamura-Hanafusa / Wie);
* `gsr_inverse_steering` -- ``delta_dot = -C^T (C C^T + lam E)^-1 torque`` with the dither
  ``E = [[1, e3, e2], [e3, 1, e1], [e2, e1, 1]]``, ``e_i = eps0 sin(omega t + phase_i)``
  (Wie's generalized SR inverse, which also passes *through* singular states);
* `null_motion` -- ``(I - C^+ C) gradient``: gimbal rates that leave ``H`` unchanged.

Numpy arrays and CasADi ``SX``/``MX``/``DM`` are accepted alike (a CasADi argument gives a
CasADi result); numeric arguments are checked by `dynamics.validate`.
"""
from __future__ import annotations

import math

import casadi as ca
import numpy as np

from .. import validate
from ..attitude.backend import CA_TYPES, CasadiOps, checked
from .cluster import gram_determinant

__all__ = ["SR_LAM0", "SR_MU", "GSR_EPS0", "GSR_OMEGA", "GSR_PHASE", "pseudo_inverse_steering",
           "sr_inverse_steering", "gsr_inverse_steering", "null_motion"]

#: Singularity-robust gain ``lam0`` (Wie: 0.01).
SR_LAM0 = 0.01
#: Exponential decay ``mu`` of the SR gain with ``det(C C^T)`` (Wie: 10).
SR_MU = 10.0
#: Dither amplitude ``eps0`` of the generalized SR inverse (Wie: 0.01).
GSR_EPS0 = 0.01
#: Dither frequency ``omega`` [rad/s] (Wie: pi/2).
GSR_OMEGA = math.pi / 2
#: Dither phases ``(phase_1, phase_2, phase_3)`` [rad] (Wie: 0, pi/2, pi).
GSR_PHASE = (0.0, math.pi / 2, math.pi)


def _jacobian(C):
    if isinstance(C, CA_TYPES):
        if C.shape[0] != 3 or C.shape[1] < 1:
            raise ValueError(f"`C` must be a 3 x n CasADi matrix, got shape {C.shape}")
        if isinstance(C, ca.DM):
            validate.finite_array(C.full(), "C")
        return C
    C = validate.finite_array(C, "C")
    if C.ndim != 2 or C.shape[0] != 3 or C.shape[1] < 1:
        raise ValueError(f"`C` must have shape (3, n) with n >= 1, got {C.shape}")
    return C


def _vector(x, name: str, size: int):
    return checked(x, name, (size,), lambda v, nm: validate.finite_array(v, nm, (size,)))


def _casadi(C, x):
    """``(C, True)``, ``C`` as a CasADi matrix, if ``C`` or ``x`` is CasADi; else ``(C, False)``."""
    if isinstance(C, CA_TYPES) or isinstance(x, CA_TYPES):
        return (C if isinstance(C, CA_TYPES) else ca.DM(C)), True
    return C, False


def _nonnegative(value, name: str) -> float:
    v = validate.finite_scalar(value, name)
    if v < 0:
        raise ValueError(f"`{name}` must be a finite number >= 0, got {value!r}")
    return v


def _damped(C, torque, lam0, mu, eps=(0.0, 0.0, 0.0)):
    """``-C^T (C C^T + lam E)^-1 torque``, ``lam = lam0 exp(-mu det(C C^T))``, E from ``eps``."""
    C, torque = _jacobian(C), _vector(torque, "torque", 3)
    lam0, mu = _nonnegative(lam0, "lam0"), _nonnegative(mu, "mu")
    e1, e2, e3 = eps
    E = [[1.0, e3, e2], [e3, 1.0, e1], [e2, e1, 1.0]]
    C, symbolic = _casadi(C, torque)
    if symbolic:
        lam = lam0 * ca.exp(-mu * gram_determinant(C))
        return -ca.mtimes(C.T, ca.solve(ca.mtimes(C, C.T) + lam * CasadiOps.matrix(E), torque))
    lam = lam0 * np.exp(-mu * gram_determinant(C))
    return -C.T @ np.linalg.solve(C @ C.T + lam * np.array(E), torque)


def pseudo_inverse_steering(C, torque):
    """Moore-Penrose steering ``delta_dot = -C^+ torque`` (minimum-norm gimbal rates).

    Produces the body torque ``-C delta_dot = torque`` exactly while ``C`` has rank 3; its
    rates grow like ``1 / sigma_min(C)`` near a singular state. Numeric ``C`` uses the SVD
    pseudo-inverse (finite at a singular state); CasADi ``C`` uses ``casadi.pinv``.

    Parameters
    ----------
    C : array_like, shape (3, n), or CasADi 3 x n
        Cluster Jacobian (`dynamics.momentum.cluster_jacobian`) [N m s / rad].
    torque : array_like, shape (3,), or CasADi 3 x 1
        Commanded torque on the body [N m].

    Returns
    -------
    delta_dot : ndarray, shape (n,) [rad/s], or CasADi n x 1

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.momentum import pyramid, cluster_jacobian, pseudo_inverse_steering
    >>> C = cluster_jacobian(pyramid(np.deg2rad(54.74)), np.zeros(4))
    >>> rate = pseudo_inverse_steering(C, [0.1, 0.0, 0.0])
    >>> np.round(-C @ rate, 12) + 0.0  # the body torque
    array([0.1, 0. , 0. ])
    """
    C, torque = _jacobian(C), _vector(torque, "torque", 3)
    C, symbolic = _casadi(C, torque)
    if symbolic:
        return -ca.mtimes(ca.pinv(C), torque)
    return -np.linalg.pinv(C) @ torque


def sr_inverse_steering(C, torque, *, lam0=SR_LAM0, mu=SR_MU):
    """Singularity-robust steering ``delta_dot = -C^T (C C^T + lam I)^-1 torque``.

    ``lam = lam0 exp(-mu det(C C^T))``. In the singular-value basis each rate component is
    ``sigma / (sigma^2 + lam)`` times the torque component, so ``|delta_dot| <=
    |torque| / (2 sqrt(lam))`` everywhere; the price is a torque error near singular states,
    and no torque at all along the singular direction *at* a singular state (gimbal lock).

    Parameters
    ----------
    C : array_like, shape (3, n), or CasADi 3 x n
        Cluster Jacobian [N m s / rad].
    torque : array_like, shape (3,), or CasADi 3 x 1
        Commanded torque on the body [N m].
    lam0 : float, optional
        Gain ``>= 0`` [(N m s)^2] (0 gives the pseudo-inverse away from singular states).
    mu : float, optional
        Decay ``>= 0`` [1/(N m s)^6].

    Returns
    -------
    delta_dot : ndarray, shape (n,) [rad/s], or CasADi n x 1

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.momentum import pyramid, cluster_jacobian, sr_inverse_steering
    >>> geo = pyramid(np.deg2rad(54.74))
    >>> C = cluster_jacobian(geo, np.deg2rad([-90, 0, 90, 0]))  # singular along x
    >>> np.round(sr_inverse_steering(C, [0.1, 0.0, 0.0]), 12) + 0.0  # bounded (here locked)
    array([0., 0., 0., 0.])
    """
    return _damped(C, torque, lam0, mu)


def gsr_inverse_steering(C, torque, t=None, *, lam0=SR_LAM0, mu=SR_MU, eps0=GSR_EPS0,
                         omega=GSR_OMEGA, phase=GSR_PHASE):
    """Generalized singularity-robust steering with off-diagonal dither (Wie).

    ``delta_dot = -C^T (C C^T + lam E)^-1 torque``, ``lam = lam0 exp(-mu det(C C^T))``,
    ``E = [[1, e3, e2], [e3, 1, e1], [e2, e1, 1]]``, ``e_i = eps0 sin(omega t + phase_i)``.
    The off-diagonal terms couple the singular direction with the others, so that a torque
    commanded along it still moves the gimbals and the state passes through the singularity.

    Parameters
    ----------
    C : array_like, shape (3, n), or CasADi 3 x n
        Cluster Jacobian [N m s / rad].
    torque : array_like, shape (3,), or CasADi 3 x 1
        Commanded torque on the body [N m].
    t : float [s], or CasADi scalar, optional
        Time of the dither. ``None`` turns the dither off (``E = I``: `sr_inverse_steering`).
    lam0, mu : float, optional
        As in `sr_inverse_steering`.
    eps0 : float, optional
        Dither amplitude ``>= 0`` (small, so that ``E`` stays positive definite).
    omega : float [rad/s], optional
    phase : array_like, shape (3,) [rad], optional

    Returns
    -------
    delta_dot : ndarray, shape (n,) [rad/s], or CasADi n x 1

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.momentum import pyramid, cluster_jacobian, gsr_inverse_steering
    >>> C = cluster_jacobian(pyramid(np.deg2rad(54.74)), np.deg2rad([-90, 0, 90, 0]))
    >>> rate = gsr_inverse_steering(C, [1.0, 0.0, 0.0], t=0.5)  # torque along the singular x
    >>> round(float(np.linalg.norm(rate)), 4)  # the dither moves the gimbals (SR: exactly 0)
    0.0075
    """
    if t is None:
        return _damped(C, torque, lam0, mu)
    eps0 = _nonnegative(eps0, "eps0")
    omega = validate.finite_scalar(omega, "omega")
    phase = validate.finite_array(phase, "phase", (3,))
    t = checked(t, "t", (), lambda v, nm: validate.finite_scalar(v, nm))
    sin = ca.sin if isinstance(t, CA_TYPES) else np.sin
    return _damped(C, torque, lam0, mu, [eps0 * sin(omega * t + p) for p in phase])


def null_motion(C, gradient):
    """Null motion ``(I - C^+ C) gradient``: gimbal rates that do not change ``H``.

    ``C @ null_motion(C, g) = 0``, and the rates move along the projection of ``g`` onto the
    null space of ``C``; with ``g = grad m(delta)`` of a singularity measure ``m`` (e.g.
    `dynamics.momentum.gram_determinant` of the Jacobian) the rate of change of ``m`` is
    ``|null_motion(C, g)|^2 >= 0``. Add it (scaled by a gain) to a steering law's rates.

    Parameters
    ----------
    C : array_like, shape (3, n), or CasADi 3 x n
        Cluster Jacobian [N m s / rad].
    gradient : array_like, shape (n,), or CasADi n x 1
        Preferred gimbal-rate direction, e.g. a gradient of a measure [rad/s].

    Returns
    -------
    delta_dot : ndarray, shape (n,) [rad/s], or CasADi n x 1

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.momentum import pyramid, cluster_jacobian, null_motion
    >>> C = cluster_jacobian(pyramid(np.deg2rad(54.74)), np.zeros(4))
    >>> rate = null_motion(C, [1.0, 0.0, 0.0, 0.0])
    >>> np.round(C @ rate, 12) + 0.0, bool(np.linalg.norm(rate) > 0)
    (array([0., 0., 0.]), True)
    """
    C = _jacobian(C)
    gradient = _vector(gradient, "gradient", C.shape[1])
    C, symbolic = _casadi(C, gradient)
    if symbolic:
        return gradient - ca.mtimes(ca.pinv(C), ca.mtimes(C, gradient))
    return gradient - np.linalg.pinv(C) @ (C @ gradient)
