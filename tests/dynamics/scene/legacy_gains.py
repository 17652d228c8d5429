"""The hand-written attitude PD loop of `problems.gains.attitude_loop` before it was built on
a scene, copied verbatim (the independent reference of tests/problems/gains/test_gains_scene.py).
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from appdyn.dynamics.model import Model
from appdyn.dynamics.rigid_body import RIGID_BODY_STATES, rigid_body


def gain_names(per_axis: bool) -> tuple[str, ...]:
    return ("kp1", "kp2", "kp3", "kd1", "kd2", "kd3") if per_axis else ("kp", "kd")


def pd_law(x, p, per_axis: bool):
    """``u = -2 kp q_e - kd w`` (SX/MX or numbers)."""
    kp, kd = (p[0:3], p[3:6]) if per_axis else (p[0], p[1])
    return -2 * kp * x[0:3] - kd * x[4:7]


def attitude_loop(inertia, *, per_axis: bool = False) -> Model:
    """The closed loop ``rigid_body(inertia)`` + ``u = -2 kp q_e - kd w``, gains as parameters.

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2]
    per_axis : bool
        Gains ``kp1..3, kd1..3`` (per body axis) instead of ``kp, kd``.

    Returns
    -------
    dynamics.Model
        States ``q1..q4, w1..w3`` (error quaternion w.r.t. the target, scalar-last; body rates
        [rad/s]), no controls, parameters the gains ([N m/rad], [N m s/rad]), ``attitude``
        marker ``(0, 4)``, built in SX.
    """
    body = rigid_body(inertia)
    names = gain_names(per_axis)
    x, p = ca.SX.sym("x", 7), ca.SX.sym("p", len(names))
    xdot = body.f(x, pd_law(x, p, per_axis), ca.DM(0, 1))
    f = ca.Function("attitude_pd_loop", [x, ca.SX.sym("u", 0), p], [xdot], ["x", "u", "p"], ["xdot"])
    units = {**{k: v for k, v in dict(body.units).items() if k in RIGID_BODY_STATES},
             **{n: ("N m/rad" if n.startswith("kp") else "N m s/rad") for n in names}}
    return Model(f, RIGID_BODY_STATES, (), names, p_default=np.ones(len(names)), units=units,
                 name="attitude_pd_loop", attitude=(0, 4))

