"""Reference optimal-control problems with published or closed-form optima.

Each builder returns ``(problem, truth)`` where ``truth`` holds the exact optimum. The
dynamics are written out here (not taken from appdyn's model library) except for the rigid
body, whose closed form is independent of its implementation.
"""
from __future__ import annotations

import math

import casadi as ca
import numpy as np
from scipy.optimize import brentq

from appdyn.dynamics.model import Model
from appdyn.dynamics.rigid_body import rigid_body
from appdyn.ocp import Problem

TRANSCRIPTION_NAMES = ("trapezoid", "hermite-simpson", "hermite-simpson-compressed", "radau")
# Nominal convergence orders for smooth problems: trapezoid 2, Hermite-Simpson 4 (both
# forms), Radau IIA of degree 3: 2d - 1 = 5 at the mesh points (objective and states).
ORDER = {"trapezoid": 2, "hermite-simpson": 4, "hermite-simpson-compressed": 4, "radau": 5}
# Tight IPOPT settings for accuracy tests: tol far below the discretization errors measured,
# and no bound relaxation (IPOPT relaxes bounds by 1e-8 relative by default, which moves a
# bound-limited optimum by ~1e-8).
STRICT = {"tol": 1e-12, "bound_relax_factor": 0.0}


def double_integrator() -> Model:
    x, u, p = ca.SX.sym("x", 2), ca.SX.sym("u"), ca.SX.sym("p", 0)
    f = ca.Function("double_integrator", [x, u, p], [ca.vertcat(x[1], u)], ["x", "u", "p"], ["xdot"])
    return Model(f, ("x", "v"), ("u",), name="double_integrator")


def min_energy():
    """Bryson & Ho, Applied Optimal Control (1975): x'' = u, rest-to-rest x: 0 -> 1 in T = 1, min int u^2/2.

    Optimum: u = 6 - 12 t, x = 3 t^2 - 2 t^3, J = 6; with H = u^2/2 + l1 v + l2 u the
    costates are l1 = -12, l2 = 12 t - 6.
    """
    pr = Problem(double_integrator(), T=1.0, x_initial=[0.0, 0.0], x_final=[1.0, 0.0],
                 lagrange=lambda x, u, p: 0.5 * u ** 2)
    truth = {
        "J": 6.0,
        "u": lambda t: 6.0 - 12.0 * t,
        "x": lambda t: np.array([3 * t ** 2 - 2 * t ** 3, 6 * t - 6 * t ** 2]),
        "costate": lambda t: np.array([-12.0 + 0.0 * t, 12.0 * t - 6.0]),
    }
    return pr, truth


def bang_bang(distance=1.0, accel=1.0):
    """Minimum-time rest-to-rest double integrator, |u| <= a: T* = 2 sqrt(d / a),
    u = +a then -a with the switch at T*/2 (Bryson & Ho 1975, minimum-time control)."""
    pr = Problem(double_integrator(), T=(0.1, 10.0), x_initial=[0.0, 0.0], x_final=[distance, 0.0],
                 u_bounds={"u": (-accel, accel)}, mayer=lambda xf, p, T: T)
    return pr, {"T": 2.0 * math.sqrt(distance / accel)}


def bryson_denham(l=1 / 9, as_bound=False):
    """Bryson, Denham & Dreyfus (1963), AIAA J. 1(11); Bryson & Ho (1975), state-variable
    inequality constraints: x'' = u, x(0) = x(1) = 0,
    v(0) = 1, v(1) = -1, x <= l, min int u^2/2. For l <= 1/6: J = 4 / (9 l), boundary arc
    x = l on [3l, 1 - 3l], u = -2/(3l) (1 - t/(3l)) on [0, 3l]."""
    kw = {"x_bounds": {"x": (None, l)}} if as_bound else {"path": lambda x, u, p: x[0] - l}
    pr = Problem(double_integrator(), T=1.0, x_initial=[0.0, 1.0], x_final=[0.0, -1.0],
                 lagrange=lambda x, u, p: 0.5 * u ** 2, **kw)
    return pr, {"J": 4.0 / (9.0 * l), "l": l}


def brachistochrone(xf=1.0, yf=1.0, g=9.81):
    """Bernoulli's brachistochrone, free final time, y downward, theta from the vertical:
    x' = v sin(theta), y' = v cos(theta), v' = g cos(theta), from rest at the origin to
    (xf, yf). Cycloid x = R (phi - sin phi), y = R (1 - cos phi): phi_f from
    (phi - sin phi)/(1 - cos phi) = xf/yf, R = yf/(1 - cos phi_f), T* = phi_f sqrt(R/g)."""
    x, th, p = ca.SX.sym("x", 3), ca.SX.sym("theta"), ca.SX.sym("p", 0)
    rhs = ca.vertcat(x[2] * ca.sin(th), x[2] * ca.cos(th), g * ca.cos(th))
    model = Model(ca.Function("brachistochrone", [x, th, p], [rhs], ["x", "u", "p"], ["xdot"]),
                  ("x", "y", "v"), ("theta",))
    pr = Problem(model, T=(0.1, 5.0), x_initial=[0.0, 0.0, 0.0], x_final={"x": xf, "y": yf},
                 u_bounds={"theta": (-math.pi, math.pi)}, mayer=lambda xf_, p_, T: T)
    phi = brentq(lambda f: (f - math.sin(f)) / (1 - math.cos(f)) - xf / yf, 1e-6, 2 * math.pi - 1e-6,
                 xtol=1e-15, rtol=4 * np.finfo(float).eps)
    R = yf / (1 - math.cos(phi))
    # the default guess (v = 0, theta = 0) has a rank-deficient constraint Jacobian; a rough
    # physical guess: straight line, speeding up, 45 degrees
    guess = {"x": np.array([[0.0, xf], [0.0, yf], [0.0, 4.0]]), "u": np.array([[0.8, 0.8]]), "T": 1.0}
    return pr, {"T": phi * math.sqrt(R / g), "guess": guess}


def static_parameter():
    """x' = v, v' = k u with the gain k a static parameter, rest-to-rest 0 -> 1 in T = 1,
    min int u^2/2 + 3 k^2 / 2 (Mayer). For fixed k the optimum is 6 / k^2, so
    J(k) = 6/k^2 + 3 k^2/2 is least at k* = sqrt(2): J* = 6, u = (6 - 12 t) / 2."""
    x, u, k = ca.SX.sym("x", 2), ca.SX.sym("u"), ca.SX.sym("k")
    f = ca.Function("gain_double_integrator", [x, u, k], [ca.vertcat(x[1], k * u)],
                    ["x", "u", "p"], ["xdot"])
    model = Model(f, ("x", "v"), ("u",), ("k",), p_default=[1.0])
    pr = Problem(model, T=1.0, x_initial=[0.0, 0.0], x_final=[1.0, 0.0],
                 lagrange=lambda x, u, p: 0.5 * u ** 2, mayer=lambda xf, p, T: 1.5 * p ** 2,
                 p_bounds={"k": (0.1, 10.0)})
    return pr, {"J": 6.0, "k": math.sqrt(2.0)}


def rigid_slew(theta_f=1.0, T=2.0, axis=2, sign=1.0, inertia=1.0):
    """Rest-to-rest minimum-effort slew of a rigid body with J = inertia * identity by
    theta_f about a body axis, min int |u|^2/2. The single-axis solution is stationary (a
    geodesic with cubic timing): theta = theta_f (3 s^2 - 2 s^3), s = t/T,
    u = J theta_f (6/T^2 - 12 t/T^3), J* = 6 J^2 theta_f^2 / T^3."""
    e = np.zeros(3)
    e[axis] = 1.0
    q_target = np.concatenate([math.sin(theta_f / 2) * e, [math.cos(theta_f / 2)]])
    pr = Problem(rigid_body(inertia * np.eye(3)), T=T, x_initial=[0, 0, 0, 1, 0, 0, 0],
                 x_final={"w1": 0.0, "w2": 0.0, "w3": 0.0}, q_final=sign * q_target,
                 lagrange=lambda x, u, p: 0.5 * ca.sumsqr(u))
    truth = {
        "J": 6 * inertia ** 2 * theta_f ** 2 / T ** 3,
        "u_axis": lambda t: inertia * theta_f * (6 / T ** 2 - 12 * t / T ** 3),
        "q_target": q_target,
        "axis": axis,
    }
    return pr, truth


def observed_order(e_coarse: float, e_fine: float, refinement: float = 2.0) -> float:
    return math.log(e_coarse / e_fine) / math.log(refinement)


def orbit_raising(angle_bounds=None):
    """Bryson & Ho (1975), Applied Optimal Control, sec. 2.5: maximum final radius of a
    low-thrust transfer in a fixed time, normalized units (mu = 1, r0 = 1, thrust 0.1405,
    mass rate 0.0749, tf = 3.32). States r, radial and tangential velocity u, v, mass m;
    control the thrust angle phi from the local horizontal:

        r' = u,  u' = v^2/r - 1/r^2 + thrust sin(phi)/m,  v' = -u v/r + thrust cos(phi)/m,
        m' = -0.0749,

    from r = 1, u = 0, v = 1, m = 1 to a circular orbit (u = 0, v = 1/sqrt(r)). Optimum
    r(tf) = 1.5253 (Bryson & Ho's figure 2.5.1 and the later literature, e.g. Betts 2010,
    Practical Methods for Optimal Control, 2nd ed., example 'orbit raising': 1.52526).
    ``angle_bounds``: ``None`` leaves phi unbounded (a periodic control: 2 pi k jumps cost
    the collocation nothing), else ``(lower, upper)``."""
    thrust, mdot = 0.1405, 0.0749
    x, phi, p = ca.SX.sym("x", 4), ca.SX.sym("phi"), ca.SX.sym("p", 0)
    r, u, v, m = x[0], x[1], x[2], x[3]
    rhs = ca.vertcat(u, v ** 2 / r - 1 / r ** 2 + thrust * ca.sin(phi) / m,
                     -u * v / r + thrust * ca.cos(phi) / m, -mdot)
    model = Model(ca.Function("orbit_raising", [x, phi, p], [rhs], ["x", "u", "p"], ["xdot"]),
                  ("r", "u", "v", "m"), ("phi",), name="orbit_raising")
    kw = {} if angle_bounds is None else {"u_bounds": {"phi": tuple(angle_bounds)}}
    pr = Problem(model, T=3.32, x_initial=[1.0, 0.0, 1.0, 1.0], x_final={"u": 0.0},
                 x_bounds={"r": (0.5, 5.0), "m": (0.1, 1.0)},
                 boundary=lambda r_f, v_f: v_f - 1 / ca.sqrt(r_f),
                 mayer=lambda r_f: r_f, maximize=True, **kw)
    return pr, {"r_f": 1.5253}


def free_flying_robot():
    """Sakawa (1999), "Trajectory planning of a free-flying robot by using the optimal
    control", Optimal Control Applications and Methods 20; as in Betts (2010) and PSOPT's
    example: x' = vx, y' = vy, theta' = omega, vx' = (F1 + F2) cos(theta), vy' = (F1 + F2)
    sin(theta), omega' = 0.2 F1 - 0.2 F2 with F1 = u1 - u2, F2 = u3 - u4, 0 <= u_i <= 1,
    u1 + u2 <= 1, u3 + u4 <= 1, from (-10, -10, pi/2, 0, 0, 0) to rest at the origin in
    T = 12, min integral (u1 + u2 + u3 + u4) dt. Optimum J = 7.9101 (Betts: 7.910154646;
    PSOPT: 7.9101471): bang-bang thrusts with singular pieces."""
    x, u, p = ca.SX.sym("x", 6), ca.SX.sym("u", 4), ca.SX.sym("p", 0)
    F1, F2 = u[0] - u[1], u[2] - u[3]
    rhs = ca.vertcat(x[3], x[4], x[5], (F1 + F2) * ca.cos(x[2]), (F1 + F2) * ca.sin(x[2]),
                     0.2 * F1 - 0.2 * F2)
    model = Model(ca.Function("free_flying_robot", [x, u, p], [rhs], ["x", "u", "p"], ["xdot"]),
                  ("x", "y", "theta", "vx", "vy", "omega"), ("u1", "u2", "u3", "u4"),
                  name="free_flying_robot")
    pr = Problem(model, T=12.0, x_initial=[-10.0, -10.0, math.pi / 2, 0.0, 0.0, 0.0],
                 x_final=[0.0] * 6, u_bounds=([0.0] * 4, [1.0] * 4),
                 path=lambda x, u, p: ca.vertcat(u[0] + u[1] - 1, u[2] + u[3] - 1),
                 lagrange=lambda x, u, p: ca.sum1(u))
    return pr, {"J": 7.9101}
