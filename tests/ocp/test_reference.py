"""Every transcription on the same reference problems with closed-form optima.

How the tolerances follow from the discretization:

* *Exact representation.* When the exact optimal trajectory lies in the transcription's
  function space (piecewise cubic x / linear u for Hermite-Simpson and Radau d = 3 on the
  minimum-energy double integrator; constant pieces joined at mesh points for Radau on a
  bang-bang control; a cubic-then-constant x with junctions on mesh points for
  Bryson-Denham), the discrete optimum *is* the continuous one, and only IPOPT's tolerance
  (``tol = 1e-12`` here, no bound relaxation) separates them: we assert 1e-9 (cost) /
  1e-8 (controls at nodes), allowing for the conditioning of the KKT system.
* *Discrete closed form.* The trapezoidal discretizations of the double integrator have
  their own closed-form optima (derived in the tests): asserted to 1e-9.
* *Convergence order.* Otherwise the error behaves like ``C h^p`` (p = 2 trapezoid,
  4 Hermite-Simpson, 2d - 1 = 5 Radau at the mesh points). We solve on N and 2N and
  require an observed order ``log2(e_N / e_2N) >= p - 0.3`` (the margin covers the
  higher-order terms still visible at these coarse meshes; measured orders are within
  0.15 of p, or above it where the cost superconverges).
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from appdyn.ocp import solve
from appdyn.ocp.status import STATUS_BOUND_VIOLATION

from .reference import (ORDER, STRICT, TRANSCRIPTION_NAMES, bang_bang, brachistochrone,
                        bryson_denham, min_energy, observed_order, rigid_slew, static_parameter)

EXACT = ("hermite-simpson", "hermite-simpson-compressed", "radau")


def _solve(problem, name, N, **kw):
    kw.setdefault("ipopt_options", STRICT)
    sol = solve(problem, transcription=name, N=N, verbose=False, **kw)
    assert sol.success, sol.message
    return sol


def _trapezoid_min_energy_kkt(N: int):
    """Independent numpy solution of the trapezoidal discretization of `min_energy`:
    minimize sum_k h/4 (u_k^2 + u_{k+1}^2) s.t. the trapezoid defects and the boundary
    values (a linear-quadratic program, solved through its KKT system)."""
    h = 1.0 / N
    n = N + 1
    ix, iv, iu = np.arange(n), n + np.arange(n), 2 * n + np.arange(n)
    Q = np.zeros((3 * n, 3 * n))
    w = np.full(n, h)
    w[[0, -1]] = h / 2
    Q[iu, iu] = w  # objective 1/2 z^T Q z = sum w_k u_k^2 / 2
    rows, rhs = [], []
    for k in range(N):
        r = np.zeros(3 * n)
        r[ix[k + 1]], r[ix[k]], r[iv[k]], r[iv[k + 1]] = 1, -1, -h / 2, -h / 2
        rows.append(r)
        rhs.append(0.0)
        r = np.zeros(3 * n)
        r[iv[k + 1]], r[iv[k]], r[iu[k]], r[iu[k + 1]] = 1, -1, -h / 2, -h / 2
        rows.append(r)
        rhs.append(0.0)
    for idx, val in ((ix[0], 0.0), (iv[0], 0.0), (ix[-1], 1.0), (iv[-1], 0.0)):
        r = np.zeros(3 * n)
        r[idx] = 1
        rows.append(r)
        rhs.append(val)
    A = np.array(rows)
    K = np.block([[Q, A.T], [A, np.zeros((A.shape[0], A.shape[0]))]])
    z = np.linalg.solve(K, np.concatenate([np.zeros(3 * n), rhs]))[:3 * n]
    return 0.5 * z @ Q @ z, z[iu]


# --------------------------------------------------------------- minimum energy (J = 6)
@pytest.mark.parametrize("name", TRANSCRIPTION_NAMES)
def test_min_energy_double_integrator(name):
    problem, truth = min_energy()
    if name in EXACT:
        sol = _solve(problem, name, 10)
        assert abs(sol.cost - truth["J"]) <= 1e-9
        assert np.max(np.abs(sol.u[0] - truth["u"](sol.t))) <= 1e-8
        t = np.linspace(0.0, 1.0, 57)
        x, u = sol.sample(t)
        assert np.max(np.abs(x - truth["x"](t))) <= 1e-9
        assert np.max(np.abs(u[0] - truth["u"](t))) <= 1e-8
        assert sol.propagation_error <= 1e-9  # the control reproduces the states (cvodes 1e-12)
        return
    # trapezoid: the discrete optimum in closed form, and second-order convergence to J = 6
    errors = []
    for N in (10, 20):
        sol = _solve(problem, name, N)
        J_discrete, u_discrete = _trapezoid_min_energy_kkt(N)
        assert abs(sol.cost - J_discrete) <= 1e-9
        assert np.max(np.abs(sol.u[0] - u_discrete)) <= 1e-8
        errors.append(sol.cost - truth["J"])
    assert errors[0] > 0 and errors[1] > 0  # a coarser discretization costs more here
    assert observed_order(*errors) >= ORDER[name] - 0.3


# ----------------------------------------------------------- brachistochrone (free T)
@pytest.mark.parametrize("name", TRANSCRIPTION_NAMES)
def test_brachistochrone_free_final_time(name):
    problem, truth = brachistochrone()
    errors = []
    for N in (8, 16):
        sol = _solve(problem, name, N, guess=truth["guess"])
        errors.append(abs(sol.T - truth["T"]))
    assert observed_order(*errors) >= ORDER[name] - 0.3
    # absolute sanity at N = 16 (measured: 1.3e-4, 1.1e-8, 1.1e-8, 1.2e-10)
    assert errors[1] <= {"trapezoid": 3e-4, "radau": 3e-10}.get(name, 3e-8)


# -------------------------------------------------- bang-bang minimum time (free T)
@pytest.mark.parametrize("name", TRANSCRIPTION_NAMES)
def test_bang_bang_minimum_time(name):
    problem, truth = bang_bang()
    for N in (4, 10):  # even N: the switch at T/2 is a mesh point
        if name.startswith("hermite-simpson"):
            # its quadratic control through (+1, +1, 0) leaves the bound between the nodes
            # (below): a Bound_Violation, not a success (it was one before the dense output
            # was checked)
            sol = solve(problem, transcription=name, N=N, ipopt_options=STRICT)
            assert not sol.success and sol.status == STATUS_BOUND_VIOLATION, sol.message
            assert sol.bound_violation.max == pytest.approx(0.125, abs=1e-6)
            assert sol.bound_violation.name == "u" and "`u`" in sol.message
        else:
            sol = _solve(problem, name, N)
        if name == "trapezoid":
            # u = +1, ..., +1, 0 (switch node), -1, ...: v_max = h (N - 1)/2 and
            # x(T) = h^2 (N^2/4 - 1/2) = 1  =>  T_N = 2 / sqrt(1 - 2/N^2)   (O(h^2))
            assert abs(sol.T - 2.0 / math.sqrt(1.0 - 2.0 / N ** 2)) <= 1e-9
        else:
            assert abs(sol.T - truth["T"]) <= 1e-9
    if name == "radau":
        # piecewise-constant +-1 is representable exactly: no overshoot between nodes
        _, u = sol.sample(np.linspace(0.0, sol.T, 401))
        assert np.max(np.abs(u)) <= 1.0 + 1e-8
    elif name != "trapezoid":
        # Hermite-Simpson reaches T = 2 only because its quadratic control through
        # (+1, +1, 0) exceeds the bound between the nodes (peak 1 + 1/8 at sigma = 1/4):
        # bounds are imposed at nodes, and x(T) depends only on the first moment of u.
        _, u = sol.sample(np.linspace(0.0, sol.T, 801))
        assert np.max(u) == pytest.approx(1.125, abs=1e-6)


# -------------------------------------------- Bryson-Denham state constraint x <= l
@pytest.mark.parametrize("name", TRANSCRIPTION_NAMES)
def test_bryson_denham_path_constraint(name):
    problem, truth = bryson_denham()  # l = 1/9: junctions at 1/3, 2/3
    if name in EXACT:
        sol = _solve(problem, name, 9)  # junctions on mesh points: exact representation
        assert abs(sol.cost - truth["J"]) <= 1e-9
        assert np.max(sol.x[0]) <= truth["l"] + 1e-10
        # the constraint is active on the boundary arc [3l, 1 - 3l]. There the active rows
        # have dependent gradients (x = l, v = 0, u = 0 already follow from the dynamics),
        # LICQ fails, and interior-point iterates approach the arc like sqrt(mu): sqrt(tol)
        # = 1e-6 bounds the state, while the stationary cost errs only to second order.
        arc = (sol.t > 1 / 3 + 1e-9) & (sol.t < 2 / 3 - 1e-9)
        assert np.max(np.abs(sol.x[0, arc] - truth["l"])) <= 1e-6
        lam = sol.multipliers["path"][0]  # >= 0 at an active upper bound (CasADi's sign)
        assert lam.min() >= -1e-8 and lam.max() > 1e-3
        return
    errors = [abs(_solve(problem, name, N).cost - truth["J"]) for N in (9, 18)]
    assert observed_order(*errors) >= ORDER[name] - 0.3


def test_bryson_denham_as_state_bound_matches_path_form():
    """The same constraint as a variable bound (x_bounds) gives the same optimum."""
    problem, truth = bryson_denham(as_bound=True)
    sol = _solve(problem, "radau", 9)
    assert abs(sol.cost - truth["J"]) <= 1e-9


# ----------------------------------------------------------------- static parameter
@pytest.mark.parametrize("name", TRANSCRIPTION_NAMES)
def test_static_parameter(name):
    problem, truth = static_parameter()
    if name in EXACT:
        sol = _solve(problem, name, 10)
        assert abs(sol.cost - truth["J"]) <= 1e-9
        assert abs(sol.p[0] - truth["k"]) <= 1e-9
        return
    sols = [_solve(problem, name, N) for N in (10, 20)]
    errors = [abs(s.cost - truth["J"]) for s in sols]
    assert observed_order(*errors) >= ORDER[name] - 0.3
    # on the trapezoid the optimal gain follows the discrete cost J_N(k) = c_N/k^2 + 3k^2/2,
    # c_N = the discrete min-energy cost of `min_energy` (substitute k u -> u; the trapezoid
    # is linear in f and its quadrature linear in u^2): dJ/dk = 0 gives k_N^4 = 2 c_N / 3,
    # J_N = sqrt(6 c_N)  (k* = sqrt(2), J* = 6 for c = 6)
    for sol, N in zip(sols, (10, 20)):
        c_N, _ = _trapezoid_min_energy_kkt(N)
        assert abs(sol.p[0] - (2 * c_N / 3) ** 0.25) <= 1e-9
        assert abs(sol.cost - math.sqrt(6 * c_N)) <= 1e-9


# ------------------------------------------------- rigid-body rest-to-rest slew (q, -q)
@pytest.mark.parametrize("name", TRANSCRIPTION_NAMES)
def test_rigid_body_min_effort_slew_both_target_signs(name):
    costs = {}
    for sign in (1.0, -1.0):
        problem, truth = rigid_slew(theta_f=1.0, T=2.0, axis=2, sign=sign)
        sols = [_solve(problem, name, N) for N in (8, 16)]
        errors = [abs(s.cost - truth["J"]) for s in sols]
        assert observed_order(*errors) >= ORDER[name] - 0.3
        fine = sols[1]
        # the final attitude is the target up to sign; the slew stays about the z axis
        qf = fine.x[0:4, -1]
        assert min(np.linalg.norm(qf - truth["q_target"]), np.linalg.norm(qf + truth["q_target"])) <= 1e-6
        assert np.max(np.abs(fine.u[0:2])) <= 1e-8
        costs[sign] = fine.cost
        # quaternion norm: imposed through x_initial only; the discrete drift is of the
        # order of the discretization error (measured 2e-3 / 8e-6 / 3e-6 at N = 16)
        assert fine.quaternion_norm_error <= {"trapezoid": 1e-2}.get(name, 1e-4)
        # dense control against the closed form, inside the discretization error
        t = np.linspace(0.0, 2.0, 41)
        _, u = fine.sample(t)
        tol_u = {"trapezoid": 0.2, "radau": 1e-3}.get(name, 1e-2)
        assert np.max(np.abs(u[2] - truth["u_axis"](t))) <= tol_u
    assert costs[1.0] == pytest.approx(costs[-1.0], abs=1e-12)


@pytest.mark.parametrize("name", ["hermite-simpson", "radau"])
def test_rigid_body_slew_with_pointing_tolerance(name):
    """Within an angle tol of the target, the cheapest final attitude lies on the same
    geodesic at theta_f - tol: J* = 6 (theta_f - tol)^2 / T^3 (target sign irrelevant)."""
    problem, truth = rigid_slew(theta_f=1.0, T=2.0, sign=-1.0)
    problem = problem.replace(q_final_tol=0.2)
    J = 6 * (1.0 - 0.2) ** 2 / 2.0 ** 3
    errors = [abs(_solve(problem, name, N).cost - J) for N in (8, 16)]
    assert observed_order(*errors) >= ORDER[name] - 0.3
