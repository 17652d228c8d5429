"""The design model of a launch-vehicle gain design (`problems.gains.launch_vehicle`): the
open-loop vehicle closed symbolically with the gains as parameters, the gust as a state, the
Routh-Hurwitz rows of the stable set, and the scenarios' initial states."""
from __future__ import annotations

import math

import casadi as ca
import numpy as np

from appdyn.dynamics import cache
from appdyn.dynamics.launch_vehicle import Actuator
from appdyn.dynamics.launch_vehicle import launch_vehicle as vehicle_model
from appdyn.dynamics.model import Model
from appdyn.dynamics.validate import positive

from .lv_data import GAIN_UNITS, LaunchVehicle

__all__ = ["open_loop", "wind_of", "closed_loop_model", "design_model", "hurwitz_rows",
           "initial_states"]


# ------------------------------------------------------------------------ the models
def open_loop(veh: LaunchVehicle, actuator) -> Model:
    return vehicle_model(thrust=veh.thrust, inertia=veh.inertia, arm=veh.arm, mass=veh.mass,
                         aero=veh.aero, actuator=actuator)


def wind_of(veh: LaunchVehicle, sym):
    """The open-loop model's parameter vector ``(wind_x, wind_y)`` (empty without aero)."""
    return ca.vertcat(0, sym) if veh.aero is not None else ca.SX(0, 1)


@cache.constructs
def closed_loop_model(veh: LaunchVehicle, actuator, integral: bool, filter_tau) -> tuple[Model, ca.Function]:
    """The closed loop on the vehicle's own right-hand side, the gains as parameters."""
    ol = open_loop(veh, actuator)
    names = ["psi", "psi_dot", "x_dot", "y_dot"] + (["delta"] if actuator else []) \
        + (["psi_integral"] if integral else []) + (["command"] if filter_tau else []) \
        + ["wind_y"]
    z = {n: ca.SX.sym(n) for n in names}
    gains = ["k_psi", "k_psidot"] + (["k_i"] if integral else [])
    k = ca.SX.sym("k", len(gains))
    law = -(k[0] * z["psi"] + k[1] * z["psi_dot"])
    if integral:
        law = law - k[2] * z["psi_integral"]
    command = z["command"] if filter_tau else law
    full = [0, 0, z["psi"], z["x_dot"], z["y_dot"], z["psi_dot"]] \
        + ([z["delta"]] if actuator else [])
    xdot = ol.f(ca.vertcat(*full), command, wind_of(veh, z["wind_y"]))
    rhs = {"psi": xdot[2], "psi_dot": xdot[5], "x_dot": xdot[3], "y_dot": xdot[4],
           "wind_y": ca.SX(0)}
    if integral:
        rhs["psi_integral"] = z["psi"]
    if filter_tau:
        rhs["command"] = (law - z["command"]) / filter_tau
    if actuator:
        rhs["delta"] = xdot[6]
        delta, rate = z["delta"], xdot[6]
    elif filter_tau:
        delta, rate = z["command"], rhs["command"]
    else:  # delta' = -(k_psi psi' + k_psidot psi'' + k_i psi), psi'' from the dynamics
        delta = law
        rate = -(k[0] * z["psi_dot"] + k[1] * xdot[5]) - (k[2] * z["psi"] if integral else 0)
    x = ca.vertcat(*[z[n] for n in names])
    f = ca.Function("launch_vehicle_gains", [x, ca.SX(0, 1), k],
                    [ca.vertcat(*[rhs[n] for n in names])], ["x", "u", "p"], ["xdot"])
    if veh.aero is not None:
        vx, vy = z["x_dot"], z["y_dot"] - z["wind_y"]
        c, s = ca.cos(z["psi"]), ca.sin(z["psi"])
        alpha = ca.atan2(s * vx - c * vy, c * vx + s * vy)
    else:
        alpha = ca.SX(0)
    out = ca.Function("outputs", [x, k], [delta, rate, alpha], ["x", "p"],
                      ["delta", "delta_rate", "alpha"])
    units = {"psi": "rad", "psi_dot": "rad/s", "x_dot": "m/s", "y_dot": "m/s", "delta": "rad",
             "psi_integral": "rad s", "command": "rad", "wind_y": "m/s", **GAIN_UNITS}
    model = Model(f, tuple(names), (), tuple(gains), p_default=np.ones(len(gains)),
                  units={n: units[n] for n in (*names, *gains)},
                  name="launch vehicle autopilot (gains as parameters)")
    return model, out


def design_model(vehicle, *, integral: bool = False,
                 filter_time_constant: float | None = None) -> tuple[Model, ca.Function]:
    """The closed loop with the gains as parameters, and its outputs.

    Parameters
    ----------
    vehicle : LaunchVehicle or mapping
    integral : bool
        Add the integral term ``- k_i integral(psi) dt`` to the law.
    filter_time_constant : float [s], optional
        A first-order filter ``tau_f c' = law - c`` between the law and the deflection
        command ``c``.

    Returns
    -------
    model : dynamics.Model
        States ``psi`` [rad], ``psi_dot`` [rad/s], ``x_dot``, ``y_dot`` [m/s], then
        ``delta`` [rad] (actuator), ``psi_integral`` [rad s] (integral), ``command`` [rad]
        (filter) and ``wind_y`` [m/s] (zero rate); no controls; parameters ``k_psi``
        [rad/rad], ``k_psidot`` [rad/(rad/s)] and ``k_i`` [rad/(rad s)] (integral). The
        actuator's clamps are left out (module notes).
    outputs : casadi.Function
        ``(x, p) -> (delta [rad], delta_rate [rad/s], alpha [rad])``, the rate exact from
        the dynamics (module notes).

    Examples
    --------
    >>> m, out = design_model({"thrust": 2e6, "inertia": 4e7, "arm": 20.0, "mass": 1e5},
    ...                       integral=True)
    >>> m.states, m.params
    (('psi', 'psi_dot', 'x_dot', 'y_dot', 'psi_integral', 'wind_y'), ('k_psi', 'k_psidot', 'k_i'))
    """
    veh = LaunchVehicle.coerce(vehicle)
    tau = None if veh.actuator is None else Actuator(veh.actuator.time_constant)
    tf = None if filter_time_constant is None else positive(filter_time_constant,
                                                            "filter_time_constant")
    return closed_loop_model(veh, tau, bool(integral), tf)


@cache.constructs
def hurwitz_rows(veh: LaunchVehicle, model: Model, min_decay: float) -> ca.Function:
    """``k -> rows >= 0`` iff every pole of the linear closed loop has ``Re <= -min_decay``.

    The loop is the design model linearized about steady flight (``psi = psi' = y_dot = 0``,
    ``x_dot = V``, no wind, the gimbal at rest) in the states the attitude loop sees
    (``psi, psi_dot``, ``y_dot`` with air, ``delta`` with the actuator: those the stability
    report keeps). ``A(k) + min_decay I`` must be Hurwitz: its characteristic polynomial
    (Faddeev-LeVerrier, symbolic in ``k``) has the leading principal minors of its Hurwitz
    matrix and its constant coefficient ``>= 0`` (Routh-Hurwitz).
    """
    keep = ["psi", "psi_dot"] + (["y_dot"] if veh.aero is not None else []) \
        + [n for n in ("delta", "psi_integral", "command") if n in model.states]
    idx = [model.states.index(n) for n in keep]
    x = ca.SX.sym("x", model.nx)
    k = ca.SX.sym("k", model.np)
    xdot = model.f(x, ca.SX(0, 1), k)
    point = np.zeros(model.nx)
    point[model.states.index("x_dot")] = veh.velocity or 0.0
    A = ca.substitute(ca.jacobian(xdot[idx], x)[:, idx], x, ca.DM(point))
    n = len(idx)
    A = A + min_decay * ca.SX.eye(n)
    coef = [ca.SX(1)]  # s^n + c1 s^(n-1) + ... + cn
    M = ca.SX.zeros(n, n)
    for i in range(1, n + 1):
        M = ca.mtimes(A, M) + coef[-1] * ca.SX.eye(n)
        coef.append(-ca.trace(ca.mtimes(A, M)) / i)
    a = lambda j: coef[j] if 0 <= j <= n else ca.SX(0)  # noqa: E731
    H = ca.SX.zeros(n, n)
    for i in range(n):
        for j in range(n):
            H[i, j] = a(2 * (j + 1) - (i + 1))
    rows = [ca.det(H[:m, :m]) for m in range(1, n)] + [coef[n]]
    return ca.Function("hurwitz", [k], [ca.simplify(ca.vertcat(*rows))], ["p"], ["rows"])


def initial_states(veh: LaunchVehicle, scenarios, names) -> np.ndarray:
    V = veh.velocity or 0.0
    cols = []
    for sc in scenarios:
        z = {"psi": sc.psi0, "psi_dot": sc.psi_dot0, "x_dot": V, "y_dot": 0.0, "delta": 0.0,
             "psi_integral": 0.0, "command": 0.0, "wind_y": V * math.tan(sc.gust_alpha)}
        cols.append([z[n] for n in names])
    return np.array(cols, dtype=float).T


