"""Rigid body with quaternion attitude (Rheinfurth & Wilson, NASA RP-1262, Sec. 4.2 Euler's law,
Sec. 4.3 kinematics).

State ``x = [q1, q2, q3, q4, w1, w2, w3]``: scalar-last unit quaternion (inertial -> body) and
body angular velocity [rad/s]. Control ``u = [L1, L2, L3]``: body-frame torque [N m] about the
mass center. Dynamics ``I wdot = u - w x (I w)`` with a full symmetric inertia matrix, and
``qdot = -1/2 Wbar(w) q`` (Eq. 4.70).
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from . import cache
from .attitude import dcm_from_quat, quat_rate
from .model import Model
from .validate import check_inertia  # re-exported: its old home

__all__ = ["check_inertia", "rigid_body", "RIGID_BODY_STATES"]

RIGID_BODY_STATES = ("q1", "q2", "q3", "q4", "w1", "w2", "w3")


@cache.memoize
def _rigid_body(inertia_key: tuple) -> Model:
    inertia = np.array(inertia_key).reshape(3, 3)
    inv = np.linalg.inv(inertia)
    x = ca.SX.sym("x", 7)
    u = ca.SX.sym("u", 3)
    p = ca.SX.sym("p", 0)
    q, w = x[0:4], x[4:7]
    I, Iinv = ca.DM(inertia), ca.DM(inv)
    h = ca.mtimes(I, w)
    wdot = ca.mtimes(Iinv, u - ca.cross(w, h))
    xdot = ca.vertcat(quat_rate(q, w), wdot)
    f = ca.Function("rigid_body", [x, u, p], [xdot], ["x", "u", "p"], ["xdot"])
    invariants = {
        "energy": ca.Function("energy", [x, p], [0.5 * ca.dot(w, h)], ["x", "p"], ["energy"]),
        "momentum_inertial": ca.Function(
            "momentum_inertial", [x, p], [ca.mtimes(dcm_from_quat(q).T, h)], ["x", "p"],
            ["momentum_inertial"],
        ),
        "quat_norm": ca.Function("quat_norm", [x, p], [ca.norm_2(q)], ["x", "p"], ["quat_norm"]),
    }
    units = {**{k: "-" for k in RIGID_BODY_STATES[:4]}, **{k: "rad/s" for k in RIGID_BODY_STATES[4:]},
             "L1": "N m", "L2": "N m", "L3": "N m"}
    return Model(
        f=f,
        states=RIGID_BODY_STATES,
        controls=("L1", "L2", "L3"),
        params=(),
        p_default=np.zeros(0),
        units=units,
        invariants=invariants,
        name="rigid_body",
        attitude=(0, 4),
    )


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
        Models are cached by inertia, so repeated calls return the same object.

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
    a = check_inertia(inertia)
    return _rigid_body(tuple(a.reshape(-1).tolist()))
