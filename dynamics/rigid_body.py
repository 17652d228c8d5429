"""Rigid body with quaternion attitude (Rheinfurth & Wilson, NASA RP-1262, Sec. 4.2 Euler's law,
Sec. 4.3 kinematics).

State ``x = [q1, q2, q3, q4, w1, w2, w3]``: scalar-last unit quaternion (inertial -> body) and
body angular velocity [rad/s]. Control ``u = [L1, L2, L3]``: body-frame torque [N m] about the
mass center. Dynamics ``I wdot = u - w x (I w)`` with a full symmetric inertia matrix, and
``qdot = -1/2 Wbar(w) q`` (Eq. 4.70).
"""
from __future__ import annotations

from . import cache
from .model import Model
from .scene import ExternalTorque, RigidHub, Scene
from .validate import check_inertia  # re-exported: its old home

__all__ = ["check_inertia", "rigid_body", "RIGID_BODY_STATES"]

RIGID_BODY_STATES = ("q1", "q2", "q3", "q4", "w1", "w2", "w3")


@cache.memoize_values
def rigid_body(inertia) -> Model:
    """Torque-driven rigid body with quaternion attitude.

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2]
        Inertia matrix about the mass center in body axes (full symmetric; products of
        inertia with the sign of [1]_, Eq. 4.16, ``Ixy = -sum m x y``), or principal moments.

    Returns
    -------
    Model
        ``x = [q1, q2, q3, q4, w1, w2, w3]``, ``u = [L1, L2, L3]`` [N m], no parameters,
        ``attitude = (0, 4)``, invariants ``energy`` [J] (``1/2 w.Iw``),
        ``momentum_inertial`` [N m s] (``A(q)^T I w``, shape 3) and ``quat_norm``.
        It is the scene ``Scene(RigidHub(inertia), ExternalTorque(), name="rigid_body")``
        (`dynamics.scene`; ``layout`` ``hub`` and ``torque``), cached by value, so repeated
        calls return the same object.

    Raises
    ------
    ValueError
        If ``inertia`` has the wrong shape, is not finite, not symmetric, not positive definite,
        or violates the triangle inequality (see `check_inertia`).

    References
    ----------
    .. [1] Rheinfurth & Wilson, NASA RP-1262, Sec. 4.2 (Euler's law), Eq. 4.16 (products
       of inertia), Eq. 4.70 (kinematics).

    Examples
    --------
    >>> from appdyn.dynamics import rigid_body
    >>> model = rigid_body([1.0, 2.0, 3.0])
    >>> model.states, model.controls
    (('q1', 'q2', 'q3', 'q4', 'w1', 'w2', 'w3'), ('L1', 'L2', 'L3'))
    >>> xdot = model.f(x=[0, 0, 0, 1, 1.0, 1.0, 1.0], u=[0, 0, 0], p=[])["xdot"]
    >>> xdot[4:].T  # Euler's equations: I wdot = (I w) x w
    DM([[-1, 1, -0.333333]])
    """
    return Scene(RigidHub(inertia), ExternalTorque(), name="rigid_body").model()
