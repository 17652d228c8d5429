"""Time-dependent models carry a clock state "t" (`dynamics.clock`): the collocation engine
needs no change. Forced double integrator x'' = u + sin(t), rest to rest over [0, pi],
minimum 1/2 integral u^2: with u = w - sin(t) the constraints ask w to be orthogonal to 1 and
t, so the optimum removes only the projection of sin onto them (its mean 2/pi; the part
along t - pi/2 vanishes by symmetry) and J = 1/2 * pi * (2/pi)^2 = 2/pi."""
import math

import casadi as ca
import numpy as np

from appdyn import ocp
from appdyn.dynamics import Model
from appdyn.dynamics.clock import clock_index


def test_forced_double_integrator_with_a_clock_state():
    x, u, p = ca.SX.sym("x", 3), ca.SX.sym("u"), ca.SX.sym("p", 0)
    f = ca.Function("forced", [x, u, p], [ca.vertcat(x[1], u + ca.sin(x[2]), 1)],
                    ["x", "u", "p"], ["xdot"])
    model = Model(f, ("x", "v", "t"), ("u",))
    assert clock_index(model) == 2
    problem = ocp.Problem(model, T=math.pi, x_initial=[0, 0, 0], x_final=[0, 0, np.nan],
                          lagrange=lambda x, u, p: 0.5 * u ** 2)
    sol = ocp.solve(problem, N=40)
    assert sol.success, sol.message
    assert abs(sol.cost - 2 / math.pi) < 1e-8
    assert abs(sol.x[2, -1] - math.pi) < 1e-12  # the clock ran with time
    assert sol.propagation_error < 1e-6  # re-simulated from t0 with the clock
