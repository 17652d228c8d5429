"""
Your own model, optimized: the brachistochrone
==============================================

A bead slides without friction along a wire from the origin to the point ``(pi, -2)`` m
under gravity; which wire shape gets it there first? The model is written from CasADi
expressions of named symbols (`appdyn.dynamics.Model.from_expressions`): position ``x``,
``y`` and speed ``v``, the control is the angle ``theta`` of the path from the downward
vertical::

    x' = v sin(theta),   y' = -v cos(theta),   v' = g cos(theta)

`appdyn.ocp.Problem` states the minimum-time problem (free horizon, ``mayer=lambda T: T``)
and `appdyn.ocp.solve` transcribes it by Radau collocation and solves it with IPOPT.

The answer is known: the cycloid ``x = r (phi - sin phi)``, ``y = -r (1 - cos phi)``
through the end point with ``r = 1`` m and ``phi_f = pi``, reached at
``T = pi sqrt(r / g)``.
"""
import casadi as ca
import matplotlib.pyplot as plt
import numpy as np

from appdyn.dynamics import Model
from appdyn.ocp import Problem, solve

g = 9.81
x, y, v, theta = ca.SX.sym("x"), ca.SX.sym("y"), ca.SX.sym("v"), ca.SX.sym("theta")
bead = Model.from_expressions({"x": x, "y": y, "v": v},
                              {"x": v * ca.sin(theta), "y": -v * ca.cos(theta),
                               "v": g * ca.cos(theta)},
                              controls={"theta": theta}, name="brachistochrone",
                              units={"x": "m", "y": "m", "v": "m/s", "theta": "rad"})
print(bead.states, bead.controls)

# %%
# The problem: start at rest at the origin, end at ``(pi, -2)`` with any speed,
# minimize the horizon ``T`` (free between 0.1 s and 5 s).
problem = Problem(bead, T=(0.1, 5.0), x_initial={"x": 0.0, "y": 0.0, "v": 0.0},
                  x_final={"x": np.pi, "y": -2.0}, u_bounds={"theta": (0.0, np.pi)},
                  mayer=lambda T: T)
sol = solve(problem, transcription="radau", N=30, verbose=False,
            ipopt_options={"tol": 1e-10})
exact = np.pi / np.sqrt(g)
print(sol.success, sol.status)
print(f"T = {sol.T:.8f} s, cycloid {exact:.8f} s, difference {sol.T - exact:.1e} s")
for name, (error, relative) in sol.propagation_errors.items():  # re-simulated control
    print(f"propagation error of {name}: {error:.1e} ({relative:.1e} relative)")
assert sol.success and abs(sol.T - exact) < 1e-6

# %%
# The path against the cycloid, and the control: along the cycloid the angle from the
# vertical grows linearly in time, ``theta = pi t / T``.
tt = np.linspace(0.0, sol.T, 200)
xs, us = sol.sample(tt)
phi = np.linspace(0.0, np.pi, 200)
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
ax1.plot(phi - np.sin(phi), -(1 - np.cos(phi)), "k:", lw=3, label="cycloid")
ax1.plot(xs[0], xs[1], label="collocation")
ax1.set_aspect("equal")
ax1.set_xlabel("x [m]")
ax1.set_ylabel("y [m]")
ax1.legend()
ax2.plot(tt, np.pi * tt / sol.T, "k:", lw=3, label="pi t / T")
ax2.plot(tt, us[0], label="theta")
ax2.set_xlabel("t [s]")
ax2.set_ylabel("theta [rad]")
ax2.legend()
fig.tight_layout()
