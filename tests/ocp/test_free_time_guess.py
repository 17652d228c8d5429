"""A free horizon without a guessed ``T``: the default guess simulates the model under the
guessed control and takes the time closest to the final state (`ocp.guess`)."""
from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest

from appdyn.dynamics import Model, rigid_body
from appdyn.dynamics.truth.torque_free import torque_free_omega
from appdyn.ocp import Mesh, Problem, Radau, solve
from appdyn.ocp.guess import initial_guess

from .reference import bang_bang, double_integrator

RADAU, MESH = Radau(3), Mesh.uniform(10)


def _guess(problem, guess=None, mesh=MESH):
    return initial_guess(problem, RADAU, mesh, guess=guess)


def _accelerate(distance, T):
    """x' = v, v' = u, |u| <= 1 from rest, only the final position given, minimum time:
    full acceleration, x = t^2/2, so T* = sqrt(2 distance) (and v(T*) = T*)."""
    return Problem(double_integrator(), T=T, x_initial=[0.0, 0.0], x_final={"x": distance},
                   u_bounds={"u": (-1.0, 1.0)}, mayer=lambda T: T)


# ------------------------------------------------------------------ closed forms
@pytest.mark.parametrize("T, spacing", [
    ((0.1, 10.0), 10.0 / 200),        # one window over [0, T_max]
    ((0.01, 1e4), 2.5 / 200),         # zoomed in from a 50 s sample spacing
    ((0.0, math.inf), 2.5 / 200),     # default T = 1: window 100 s, zoomed in
])
def test_simulated_horizon_under_a_constant_control_is_the_closed_form(T, spacing):
    """Under u = 1 from rest x = t^2/2 reaches 2 at t = 2: the guess has T = 2 to the grid
    spacing and the states x = t^2/2, v = t on the nodes."""
    prob = _accelerate(2.0, T)
    for u in ([1.0], {"u": 1.0}, lambda t: 1.0, {"u": lambda t: 1.0}):
        g = _guess(prob, {"u": u})
        assert abs(g.T - 2.0) <= spacing and "simulated" in g.source
        t = g.T * RADAU.state_tau(MESH)
        np.testing.assert_allclose(g.X[1], t, atol=1e-9)  # RK4 is exact for v = t
        np.testing.assert_allclose(g.X[0, :-1], 0.5 * t[:-1] ** 2, atol=spacing ** 2)
        assert g.X[0, -1] == 2.0  # the given final value, imposed
        np.testing.assert_allclose(g.U, 1.0)
    # u = 1 throughout: a constant control per interval holds it exactly (the Radau
    # polynomial through nodes a hair inside the bound overshoots it by ~1e-6)
    sol = solve(prob, N=10, guess={"u": [1.0]}, control="constant")
    assert sol.success and sol.T == pytest.approx(2.0, abs=1e-7)


def test_marching_past_the_first_window():
    """T_max = inf, default T = 1: the first window is [0, 100] s; x = t^2/2 = 11250 is
    reached at t = 150 s, in the second window."""
    g = _guess(_accelerate(11250.0, (0.0, math.inf)), {"u": [1.0]})
    assert abs(g.T - 150.0) <= 0.5 and "simulated" in g.source


def test_bang_bang_control_guess_gives_the_minimum_time():
    """u = +1 then -1 switching at t = 1 brings the double integrator from rest at 0 to rest
    at 1 at t = 2 = T* (Bryson & Ho 1975)."""
    prob, truth = bang_bang()
    g = _guess(prob, {"u": lambda t: 1.0 if t < 1.0 else -1.0})
    assert abs(g.T - truth["T"]) <= 0.1
    sol = solve(prob, N=20, guess={"u": lambda t: 1.0 if t < 1.0 else -1.0}, control="constant")
    assert sol.success and sol.T == pytest.approx(truth["T"], abs=1e-6)


def test_default_min_time_still_solves_from_the_middle_of_the_range():
    """At rest under the default u = 0 nothing moves: the default T (middle of [0.1, 10])
    is kept, and the solve still finds T* = 2."""
    prob, truth = bang_bang()
    g = _guess(prob)
    assert g.T == pytest.approx(5.05) and g.source == ""
    sol = solve(prob, N=20, control="constant")  # bang-bang
    assert sol.success and sol.T == pytest.approx(truth["T"], abs=1e-6)


def test_torque_free_flip_of_a_rigid_body():
    """Spin near the intermediate axis: the rate w2 flips from 0.5 to about -0.5 (the
    Dzhanibekov effect). The guess follows the exact torque-free rates (Jacobi elliptic
    functions) up to the chosen T, and w2 there is closer to -0.5 than half-way."""
    inertia, w0 = [1.0, 2.0, 2.5], [0.05, 0.5, 0.05]
    prob = Problem(rigid_body(inertia), T=(0.1, 50.0), x_initial=[0, 0, 0, 1, *w0],
                   x_final={"w2": -0.5}, u_bounds=([-1] * 3, [1] * 3),
                   lagrange=lambda x, u, p: ca.sumsqr(u))
    g = _guess(prob, mesh=Mesh.uniform(20))
    assert "simulated" in g.source and 10.0 < g.T <= 50.0
    t = g.T * RADAU.state_tau(Mesh.uniform(20))
    exact = torque_free_omega(inertia, w0, t)
    np.testing.assert_allclose(g.X[4:, :-1], exact[:, :-1], atol=2e-3)
    assert abs(exact[1, -1] + 0.5) < 0.25
    np.testing.assert_allclose(np.linalg.norm(g.X[:4], axis=0), 1.0, atol=1e-6)


# ---------------------------------------------------------------------- fallbacks
@pytest.mark.parametrize("change, T_default", [
    (dict(x_initial={"x": 0.0}), 5.05),                  # initial state not fully given
    (dict(x_final=None), 5.05),                          # no final state given
    (dict(x_initial=[0.0, 1.0], x_bounds={"x": (None, 0.0)}, x_final={"v": 0.0}), 5.05),
    (dict(T=(0.1, math.inf)), 1.0),                      # (still at rest: no progress)
])
def test_default_kept_when_the_simulation_cannot_help(change, T_default):
    prob, _ = bang_bang()
    prob = prob.replace(**change)
    for guess in (None, {"u": [0.0]}):
        g = _guess(prob, guess)
        assert g.T == pytest.approx(T_default) and g.source == ""


def test_no_simulation_when_the_guess_fixes_the_horizon_or_the_states():
    prob = _accelerate(2.0, (0.1, 10.0))
    assert _guess(prob, {"u": [1.0], "T": 3.0}).T == 3.0
    assert _guess(prob, {"u": [1.0], "x": [0.0, 0.0]}).T == pytest.approx(5.05)
    # control samples spread over the (unknown) horizon
    assert _guess(prob, {"u": np.ones((1, 5))}).T == pytest.approx(5.05)
    assert _guess(prob, {"u": {"u": np.ones(5)}}).T == pytest.approx(5.05)
    # a fixed horizon is never changed
    fixed = prob.replace(T=1.0)
    g = _guess(fixed, {"u": [1.0]})
    assert g.T == 1.0 and g.source == ""


# --------------------------------------------------------------- truth: a glider
G, C, CD0, K = 9.81, 0.09, 0.03, 0.05  # [m/s^2], rho S / (2 m) [1/m], drag polar CD0 + K CL^2


def _glider(h0=300.0, v0=12.0):
    """Point-mass glider in the vertical plane; control the lift coefficient CL in
    [0.2, 1.5]; maximize the range x(T) from (h0, v0, level) to the ground, T free."""
    x, h, v, gam, cl = (ca.SX.sym(n) for n in ("x", "h", "v", "gamma", "CL"))
    model = Model.from_expressions(
        {"x": x, "h": h, "v": v, "gamma": gam},
        {"x": v * ca.cos(gam), "h": v * ca.sin(gam),
         "v": -C * v**2 * (CD0 + K * cl**2) - G * ca.sin(gam),
         "gamma": C * v * cl - G * ca.cos(gam) / v},
        {"CL": cl}, name="glider")
    return Problem(model, T=(0.0, math.inf), x_initial={"x": 0, "h": h0, "v": v0, "gamma": 0},
                   x_final={"h": 0.0},
                   x_bounds={"h": (0, None), "v": (1, 100), "gamma": (-1.5, 1.5)},
                   u_bounds={"CL": (0.2, 1.5)}, mayer=lambda x: x, maximize=True)


@pytest.mark.parametrize("h0", [200.0, 500.0])
def test_glider_range_from_the_default_guess(h0):
    """From the default guess (simulated under CL = 0.2 down to the ground) IPOPT reaches the
    optimum found from a hand-made steady glide at the best lift-to-drag ratio (CL* =
    sqrt(CD0/K), (L/D)* = 1/(2 sqrt(CD0 K))), which the quasi-steady range
    (L/D)* (h0 + v0^2/(2g)) estimates to a few percent. (The former default, linear states
    with T = 1, fails or ends in a worse local optimum here.)"""
    v0 = 12.0
    prob = _glider(h0, v0)
    ld = 1.0 / (2.0 * math.sqrt(CD0 * K))
    cl = math.sqrt(CD0 / K)
    speed = math.sqrt(G / (C * cl))
    reach = ld * (h0 + v0**2 / (2 * G))
    T = reach / speed
    hand = {"t": [0.0, T], "T": T, "u": [cl],
            "x": {"x": [0.0, reach], "h": [h0, 0.0], "v": speed, "gamma": -math.atan(1 / ld)}}
    # the Radau CL polynomial overshoots CL <= 1.5 in the final flare: a constant CL per
    # interval. The open-loop replay of the phugoid over 220-550 s amplifies the collocation
    # error (gamma off by 50-120 % of its magnitude at the end, the range by 1e-4): judged
    # without the re-simulation (verify=False)
    opts = dict(control="constant", verify=False)
    best = solve(prob, N=40, guess=hand, **opts)
    assert best.success and best.cost == pytest.approx(reach, rel=0.03)
    g = _guess(prob, mesh=Mesh.uniform(40))
    assert "simulated" in g.source and g.T > 1.0
    sol = solve(prob, N=40, **opts)
    assert sol.success
    assert sol.cost == pytest.approx(best.cost, rel=1e-6)
    assert sol.T == pytest.approx(best.T, rel=1e-4)
