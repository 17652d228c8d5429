"""A success is verified in what is returned: the dense output keeps the bounds between the
nodes (`Solution.bound_violation`), and the re-simulation of the returned control agrees
with the collocation (`ocp.checks`), also through `ocp.refine`.

Truths: the literature optima of the free-flying robot (Sakawa 1999; Betts 2010: 7.910154646)
and of Bryson & Ho's orbit raising (r(tf) = 1.5253); bounds sampled on a grid of our own;
re-simulations by scipy's Radau integrator (independent of CVODES and of the transcription).
"""
from __future__ import annotations

import importlib
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from appdyn import ocp
from appdyn.ocp import refine, solve

from .reference import STRICT, bang_bang, free_flying_robot, min_energy, orbit_raising

FINE = 4001  # samples of the dense output, independent of ocp.checks.bound_grid


def _fine_controls(sol, n=FINE):
    return sol.sample(np.linspace(sol.t0, sol.t0 + sol.T, n))[1]


def _replay(sol, rtol=1e-11):
    """x(tf) from scipy's Radau integrator under ``sol.sample``'s control, interval by
    interval (the control is taken from the interval's own interpolant, nudged off the
    left mesh point where `sample` would take the previous interval's)."""
    f = sol.problem.model.f
    x = np.asarray(sol.x[:, 0], float)
    tb = sol.dense.t_breaks
    for a, b in zip(tb[:-1], tb[1:]):
        eps = 1e-12 * max(sol.T, 1.0)

        def rhs(t, y, a=a):
            u = sol.sample(min(max(t, a + eps), b))[1]
            return np.asarray(f(y, u, sol.p), float).reshape(-1)

        x = solve_ivp(rhs, (a, b), x, method="Radau", rtol=rtol, atol=rtol).y[:, -1]
    return x


# ------------------------------------------------------- free-flying robot (Sakawa)
def test_free_flying_robot_polynomial_control_leaving_its_bounds_is_no_success():
    problem, _ = free_flying_robot()
    sol = solve(problem, N=40)
    u = _fine_controls(sol)
    assert u.max() > 1.0 + 1e-2 or u.min() < -1e-2  # the polynomial overshoots [0, 1]
    assert not sol.success and sol.status == ocp.STATUS_BOUND_VIOLATION
    bv = sol.bound_violation
    # the four thrusts, and the two rows of its path constraint (thrust pairs, checked on the
    # same dense output)
    assert set(bv.by_name) == {"u1", "u2", "u3", "u4", "path[0]", "path[1]"} and bv.max > 1e-2
    assert bv.kind == "control"
    assert bv.max == pytest.approx(max(bv.by_name.values()))
    assert f"`{bv.name}`" in sol.message and "control='linear'" in sol.message
    assert f"t = {bv.time:.6g} s" in sol.message
    assert not 0.0 <= bv.value <= 1.0 and (bv.lower, bv.upper) == (0.0, 1.0)
    assert bv.max == pytest.approx(max(bv.value - 1.0, -bv.value), rel=1e-12)  # scale 1
    assert bv.max >= max(u.max() - 1.0, -u.min()) - 1e-3  # the fine grid finds no worse


@pytest.mark.parametrize("control", ["linear", "constant"])
@pytest.mark.slow
def test_free_flying_robot_within_bounds_with_a_linear_or_constant_control(control):
    problem, truth = free_flying_robot()
    sol = solve(problem, N=80, control=control)
    assert sol.success, sol.message
    u = _fine_controls(sol)
    assert u.min() >= -1e-6 and u.max() <= 1.0 + 1e-6
    assert sol.bound_violation.max <= 1e-6
    # a feasible control: not below the optimum, within the O(h) error of the fixed mesh
    assert truth["J"] - 1e-3 < sol.simulated_cost < truth["J"] * 1.01  # measured 7.9283 / 7.9156
    # the re-simulation that verified it replays sample()'s control: scipy agrees
    np.testing.assert_allclose(_replay(sol), sol.propagation.x[:, -1], atol=1e-7)


@pytest.mark.slow
def test_the_replayed_control_is_samples_also_where_the_polynomial_overshoots():
    """`propagate` integrates exactly the interpolant `sample` returns, overshoot and all."""
    problem, _ = bang_bang()
    sol = solve(problem, N=7, ipopt_options=STRICT)  # switch inside an interval: overshoot
    assert sol.status == ocp.STATUS_BOUND_VIOLATION
    np.testing.assert_allclose(_replay(sol), sol.propagation.x[:, -1], atol=1e-8)


# ---------------------------------------------------------- orbit raising (Bryson & Ho)
def test_orbit_raising_with_an_unbounded_angle_fails_naming_the_cause():
    problem, truth = orbit_raising()
    sol = solve(problem, N=20)
    # the returned control, re-simulated, "beats" the optimum: it is not what was collocated
    assert sol.simulated_cost > truth["r_f"] + 1e-2
    assert not sol.success and sol.status == ocp.STATUS_RESIMULATION
    for words in ("`phi`", "2 pi", "bound it", "unit vector"):
        assert words in sol.message, words
    # opting out returns the collocated solution as IPOPT's success
    assert solve(problem, N=20, verify=False).success


def test_orbit_raising_refine_does_not_pile_intervals_on_the_angle_jumps():
    problem, _ = orbit_raising()
    sol = refine(problem, N=20, tol=1e-6)
    assert not sol.success and sol.status == ocp.STATUS_RESIMULATION
    assert sol.mesh.N == 20 and len(sol.refinement) == 1
    assert "`phi`" in sol.message and "2 pi" in sol.message


def test_orbit_raising_with_a_bounded_angle_reaches_the_literature_optimum():
    # the optimal thrust angle turns from 0.43 to 5.44 rad: [-pi, pi] forces a wrap at pi,
    # which the Radau control polynomial cannot follow (it overshoots the bound)
    wrapped, _ = orbit_raising((-math.pi, math.pi))
    assert solve(wrapped, N=40).status == ocp.STATUS_BOUND_VIOLATION
    problem, truth = orbit_raising((0.0, 2 * math.pi))
    ramp = {"t": [0.0, 3.32], "x": [[1.0, 1.5], [0.0, 0.0], [1.0, 0.8], [1.0, 0.75]],
            "u": [[0.5, 5.4]], "T": 3.32}
    sol = refine(problem, solve(problem, N=40, guess=ramp), tol=1e-6)
    assert sol.success and sol.info["converged"], sol.message
    assert round(sol.cost, 4) == truth["r_f"] and round(sol.simulated_cost, 4) == truth["r_f"]
    assert sol.propagation.x[2, -1] == pytest.approx(1 / math.sqrt(sol.propagation.x[0, -1]), abs=1e-6)


# ------------------------------------------------------------- refine: never worse
@pytest.mark.slow
def test_refine_never_returns_a_worse_objective_than_an_earlier_round(monkeypatch):
    """A refinement round that lands on a worse (verified) solution -- here forced: every
    re-solve returns the coarse solution of a 10-interval mesh -- does not replace the
    better input."""
    problem, truth = free_flying_robot()
    first = solve(problem, N=80, control="linear")
    coarse = solve(problem, N=10, control="linear")
    assert first.success and coarse.success and coarse.simulated_cost > first.simulated_cost + 1e-2
    mesh_update = importlib.import_module("appdyn.ocp.refine.mesh_update")
    monkeypatch.setattr(mesh_update, "solve", lambda *a, **k: coarse)
    sol = refine(problem, first, tol=1e-9, max_rounds=1, control="linear")
    assert sol.simulated_cost == pytest.approx(first.simulated_cost, abs=1e-12)
    assert sol.mesh.N == 80 and sol.info["returned_round"] == 0
    assert "worse" in sol.message and f"{coarse.simulated_cost:.10g}" in sol.message


# ---------------------------------------------------------------- options, defaults
def test_resolved_reference_problems_pass_the_default_verification():
    for name in ("trapezoid", "hermite-simpson", "radau"):
        sol = solve(min_energy()[0], transcription=name, N=10)
        assert sol.success, (name, sol.message)
        assert "propagation" in vars(sol)  # verified by re-simulation, cached on the result


def test_control_and_verify_arguments_are_checked():
    problem, _ = min_energy()
    with pytest.raises(ValueError, match="`control`"):
        solve(problem, N=4, control="cubic")
    with pytest.raises(ValueError, match="`control`"):
        solve(problem, N=4, transcription="hermite-simpson", control="linear")
    with pytest.raises(ValueError, match="`verify`"):
        solve(problem, N=4, verify="yes")
    with pytest.raises(ValueError, match="`verify_tol`"):
        solve(problem, N=4, verify_tol=0.0)
    assert ocp.get_transcription("radau", degree=4, control="linear") == ocp.RadauLinearControl(4)
    assert ocp.get_transcription("trapezoid", degree=None, control="linear") == ocp.Trapezoid()


def test_a_linear_control_is_exact_where_the_optimum_is_linear():
    """min energy of x'' = u: u = 6 - 12 t is linear, so the piecewise-linear control holds
    it exactly and the cost is J = 6."""
    problem, truth = min_energy()
    sol = solve(problem, N=6, control="linear", ipopt_options=STRICT)
    assert sol.success and abs(sol.cost - truth["J"]) < 1e-9
    t = np.linspace(0.0, 1.0, 37)
    np.testing.assert_allclose(sol.sample(t)[1][0], truth["u"](t), atol=1e-8)
