"""solve(): failures without exceptions, progress output, guesses, dense output, propagation."""
from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest

from appdyn.ocp import (Constraint, HermiteSimpson, Mesh, Problem, Progress, Radau, Solution, Trapezoid,
                 solve)
from appdyn.ocp.status import STATUS_INFEASIBLE, STATUS_MAX_ITER, STATUS_SUCCESS

from .reference import (STRICT, TRANSCRIPTION_NAMES, brachistochrone, double_integrator,
                        min_energy, observed_order, rigid_slew)


# --------------------------------------------------------------------- failures
@pytest.mark.parametrize("name", TRANSCRIPTION_NAMES)
def test_infeasible_problem_returns_failure_with_ipopt_status(name):
    # rest-to-rest over distance 1 in T = 1 needs |u| >= 4 somewhere; |u| <= 0.1 allows it
    # only for T >= 2 sqrt(1 / 0.1) = 6.3
    problem = Problem(double_integrator(), T=1.0, x_initial=[0, 0], x_final=[1, 0],
                      u_bounds={"u": (-0.1, 0.1)}, lagrange=lambda x, u, p: u ** 2)
    sol = solve(problem, transcription=name, N=10, verbose=False)
    assert isinstance(sol, Solution)
    assert sol.success is False
    assert sol.status == STATUS_INFEASIBLE
    assert sol.solver_status in sol.message
    assert sol.x.shape == (2, sol.t.size) and sol.constraint_violation > 1e-3


def test_iteration_limit_returns_failure():
    problem, truth = brachistochrone()
    sol = solve(problem, N=8, verbose=False, guess=truth["guess"], ipopt_options={"max_iter": 2})
    assert not sol.success
    assert sol.status == STATUS_MAX_ITER and sol.iterations == 2


# ---------------------------------------------------------------------- progress
def test_verbose_false_prints_nothing(capfd):
    problem, _ = min_energy()
    solve(problem, N=5, verbose=False)
    out, err = capfd.readouterr()
    assert out == "" and err == ""


def test_verbose_true_prints_one_line_per_iteration_to_stderr(capfd):
    problem, truth = brachistochrone()
    sol = solve(problem, N=8, verbose=True, guess=truth["guess"])
    out, err = capfd.readouterr()
    assert out == ""  # progress goes to stderr: stdout stays the caller's
    lines = err.strip().splitlines()
    assert "objective" in lines[0] and "inf_pr" in lines[0]
    assert len(lines) == 1 + sol.iterations + 1  # header, iterations 0..n
    last = lines[-1].split()
    assert int(last[0]) == sol.iterations and float(last[2]) < 1e-8


def test_progress_callable_receives_iterations():
    problem, _ = min_energy()
    seen = []
    sol = solve(problem, N=5, verbose=seen.append)
    assert all(isinstance(p, Progress) for p in seen)
    assert [p.iteration for p in seen] == list(range(sol.iterations + 1))
    assert seen[-1].objective == pytest.approx(sol.cost)


# ------------------------------------------------------------------------ guesses
def test_warm_start_from_solution_on_another_transcription_and_mesh():
    problem, truth = rigid_slew(theta_f=2.0, T=3.0, axis=1)
    cold = solve(problem, transcription="hermite-simpson", N=12, verbose=False, ipopt_options=STRICT)
    coarse = solve(problem, transcription="radau", N=4, verbose=False)
    warm = solve(problem, transcription="hermite-simpson", N=12, guess=coarse, verbose=False,
                 ipopt_options=STRICT)
    assert warm.success and cold.success
    assert warm.cost == pytest.approx(cold.cost, abs=1e-9)
    assert warm.iterations <= cold.iterations


def test_warm_start_carries_free_time_and_parameters():
    problem, truth = brachistochrone()
    first = solve(problem, N=8, guess=truth["guess"], verbose=False, ipopt_options=STRICT)
    again = solve(problem.replace(T=(0.2, 3.0)), N=16, guess=first, verbose=False,
                  ipopt_options=STRICT)
    # primal warm start only (IPOPT restarts its barrier at mu_init): fewer iterations, not ~0
    assert again.iterations < first.iterations
    assert again.T == pytest.approx(truth["T"], abs=1e-9)


def test_guess_from_arrays_and_callables():
    problem, truth = min_energy()
    t = np.linspace(0.0, 1.0, 5)
    for guess in ({"t": t, "x": truth["x"](t), "u": truth["u"](t)[None, :]},
                  {"x": lambda tt: truth["x"](tt), "u": lambda tt: [truth["u"](tt)]}):
        sol = solve(problem, transcription="radau", N=5, guess=guess, verbose=False,
                    ipopt_options=STRICT)
        assert sol.iterations <= 1  # the exact solution is representable: already optimal
        assert sol.cost == pytest.approx(6.0, abs=1e-9)


def test_default_attitude_guess_is_slerp():
    problem, truth = rigid_slew(theta_f=2.5, T=3.0, axis=0, sign=-1.0)
    from appdyn.ocp.guess import initial_guess
    g = initial_guess(problem, Radau(3), Mesh.uniform(4))
    q = g.X[0:4]
    assert np.allclose(np.linalg.norm(q, axis=0), 1.0, atol=1e-15)
    # the sign of q_final nearer q0 is used: the shorter rotation, angle linear in time
    angle = 2 * np.arctan2(np.abs(q[0]), q[3])
    tau = Radau(3).state_tau(Mesh.uniform(4))
    assert np.allclose(angle, 2.5 * tau, atol=1e-12)


# ------------------------------------------------------------------- dense output
@pytest.mark.parametrize("name", TRANSCRIPTION_NAMES)
def test_sample_reproduces_node_values(name):
    problem, _ = rigid_slew(theta_f=1.0, T=2.0)
    sol = solve(problem, transcription=name, N=4, verbose=False)
    x, u = sol.sample(sol.t)
    assert np.max(np.abs(x - sol.x)) <= 1e-13
    assert np.max(np.abs(u[:, 1:] - sol.u[:, 1:])) <= 1e-13


def test_sample_interpolates_like_the_transcription():
    problem, _ = rigid_slew(theta_f=1.0, T=2.0)
    f = problem.model.f
    # trapezoid: linear in x and u
    sol = solve(problem, transcription=Trapezoid(), N=4, verbose=False)
    tm = 0.5 * (sol.t[1:] + sol.t[:-1])
    x, u = sol.sample(tm)
    assert np.allclose(x, 0.5 * (sol.x[:, 1:] + sol.x[:, :-1]), atol=1e-14, rtol=0)
    assert np.allclose(u, 0.5 * (sol.u[:, 1:] + sol.u[:, :-1]), atol=1e-14, rtol=0)
    # Hermite-Simpson: quadratic u through start/mid/end, cubic Hermite x with slopes f
    sol = solve(problem, transcription=HermiteSimpson(), N=4, verbose=False)
    t0, t1 = sol.t[0], sol.t[2]
    h, s = t1 - t0, 0.3
    x, u = sol.sample(t0 + s * h)
    lag = [(s - 0.5) * (s - 1) / 0.5, s * (s - 1) / -0.25, s * (s - 0.5) / 0.5]
    assert np.allclose(u, lag[0] * sol.u[:, 0] + lag[1] * sol.u[:, 1] + lag[2] * sol.u[:, 2], atol=1e-13)
    f0 = np.asarray(f(sol.x[:, 0], sol.u[:, 0], [])).ravel()
    f1 = np.asarray(f(sol.x[:, 2], sol.u[:, 2], [])).ravel()
    herm = ((2 * s ** 3 - 3 * s ** 2 + 1) * sol.x[:, 0] + (s ** 3 - 2 * s ** 2 + s) * h * f0
            + (-2 * s ** 3 + 3 * s ** 2) * sol.x[:, 2] + (s ** 3 - s ** 2) * h * f1)
    assert np.allclose(x, herm, atol=1e-13)
    # Radau: degree-d Lagrange polynomial through t_k and the d collocation points
    sol = solve(problem, transcription=Radau(3), N=4, verbose=False)
    tk = sol.t[0:4]
    tq = tk[0] + 0.37 * (tk[-1] - tk[0])
    x, _ = sol.sample(tq)
    basis = [np.prod([(tq - tk[m]) / (tk[j] - tk[m]) for m in range(4) if m != j]) for j in range(4)]
    assert np.allclose(x, sol.x[:, 0:4] @ np.array(basis), atol=1e-13)


@pytest.mark.parametrize("name", TRANSCRIPTION_NAMES + ("radau-constant-control",
                                                         "radau-linear-control"))
def test_dense_weights_equal_the_interpolant_function(name):
    # the numpy path of DenseOutput.eval (transcription.dense_weights) against the symbolic
    # interpolant it replaces, at random points of random intervals, ends included
    problem, _ = rigid_slew(theta_f=1.0, T=2.0)
    sol = solve(problem, transcription=name, N=4, verbose=False)
    d, rng = sol.dense, np.random.default_rng(3)
    if sol.transcription.dense_weights(np.array([0.5])) is None:
        assert name.startswith("hermite-simpson")  # depends on f: the Function path
        return
    k, s = rng.integers(0, d.N, 40), np.concatenate([[0.0, 1.0], rng.random(38)])
    x, u = d.eval(k, s)
    for i in range(k.size):
        xf, uf = d.interp(d.xs[:, k[i]], d.Xo[:, k[i]], d.us[:, k[i]], d.Uo[:, k[i]], d.h[k[i]],
                          sol.p, s[i])
        assert np.allclose(x[:, i], np.asarray(xf).ravel(), rtol=1e-14, atol=1e-14)
        assert np.allclose(u[:, i], np.asarray(uf).ravel(), rtol=1e-14, atol=1e-14)


def test_sample_rejects_times_outside_horizon():
    problem, _ = min_energy()
    sol = solve(problem, N=4, verbose=False)
    with pytest.raises(ValueError, match="`t`"):
        sol.sample(1.5)
    x, u = sol.sample(0.25)
    assert x.shape == (2,) and u.shape == (1,)


# -------------------------------------------------------------------- propagation
def test_propagation_error_converges_with_the_stage_order():
    """Radau IIA of degree d: states at the interior collocation points converge with the
    stage order d (mesh points faster), so the re-simulated control's deviation from the
    collocated states shrinks at least like h^d (measured order 3.7 for d = 3)."""
    problem, _ = rigid_slew(theta_f=1.0, T=2.0)
    e = [solve(problem, N=N, verbose=False).propagate() for N in (8, 16)]
    assert all(p.success for p in e)
    assert observed_order(np.max(e[0].error), np.max(e[1].error)) >= 3 - 0.3


def test_propagation_handles_control_jumps_at_mesh_points():
    """Bang-bang Radau control jumps at the switch (a mesh point): integrating interval by
    interval keeps the propagation exact (the polynomial control is exactly +-1)."""
    from .reference import bang_bang
    problem, _ = bang_bang()
    sol = solve(problem, N=10, verbose=False, ipopt_options=STRICT)
    assert sol.propagation_error <= 1e-9


def test_propagate_rejects_bad_tolerances():
    problem, _ = min_energy()
    sol = solve(problem, N=3, verbose=False)
    with pytest.raises(ValueError, match="`rtol`"):
        sol.propagate(rtol=0.0)


# ---------------------------------------------------------------- problem features
def test_boundary_function_and_mayer_replace_fixed_values():
    """x(tf) = 1 stated as c(x0, xf, p) = xf[0] - 1 = 0 instead of a fixed value."""
    problem = Problem(double_integrator(), T=1.0, x_initial=[0, 0], x_final={"v": 0.0},
                      boundary=lambda x0, xf, p: xf[0] - 1.0, lagrange=lambda x, u, p: 0.5 * u ** 2)
    sol = solve(problem, transcription="hermite-simpson", N=5, verbose=False, ipopt_options=STRICT)
    assert sol.cost == pytest.approx(6.0, abs=1e-9)


def test_free_initial_quaternion_gets_unit_norm():
    q = np.array([0.0, 0.0, math.sin(0.5), math.cos(0.5)])
    from appdyn.dynamics.rigid_body import rigid_body
    problem = Problem(rigid_body(np.eye(3)), T=2.0, x_initial={"w1": 0, "w2": 0, "w3": 0.1},
                      x_final={"w1": 0, "w2": 0, "w3": 0}, q_final=q,
                      lagrange=lambda x, u, p: 0.5 * ca.sumsqr(u))
    sol = solve(problem, N=6, verbose=False, ipopt_options=STRICT)
    assert sol.success
    assert np.linalg.norm(sol.x[0:4, 0]) == pytest.approx(1.0, abs=1e-12)
    # stopping w3 = 0.1 in T: min int u^2/2 = w^2 / (2 T) with the attitude left free
    assert sol.cost == pytest.approx(0.1 ** 2 / (2 * 2.0), abs=1e-10)


def test_t0_offsets_times_only():
    problem, truth = min_energy()
    shifted = problem.replace(t0=10.0)
    a = solve(problem, N=5, verbose=False, ipopt_options=STRICT)
    b = solve(shifted, N=5, verbose=False, ipopt_options=STRICT)
    assert b.t[0] == 10.0 and b.t[-1] == 11.0
    assert b.cost == pytest.approx(a.cost, abs=1e-12)
    assert np.allclose(b.sample(10.3)[0], a.sample(0.3)[0], atol=1e-12)


def test_scale_overrides_and_expand_do_not_change_the_answer():
    problem, truth = brachistochrone()
    ref = solve(problem, N=8, guess=truth["guess"], verbose=False, ipopt_options=STRICT)
    for kw in ({"scale": {"x": 3.0, "v": 0.7, "theta": 2.0, "T": 0.3, "objective": 5.0}},
               {"expand": False}):
        sol = solve(problem, N=8, guess=truth["guess"], verbose=False, ipopt_options=STRICT, **kw)
        assert sol.success
        assert sol.T == pytest.approx(ref.T, abs=1e-10)


def test_path_constraint_scale_override():
    from .reference import bryson_denham
    problem, truth = bryson_denham()
    con = Constraint(lambda x, u, p: x[0] - truth["l"], scale=1e-2)
    sol = solve(problem.replace(path=con), transcription="radau", N=9, verbose=False,
                ipopt_options=STRICT)
    assert sol.cost == pytest.approx(truth["J"], abs=1e-9)


def test_solution_attributes():
    problem, truth = rigid_slew()
    sol = solve(problem, transcription="radau", degree=2, N=5, verbose=False)
    n = 1 + 5 * 2
    assert sol.t.shape == (n,) and sol.x.shape == (7, n) and sol.u.shape == (3, n)
    assert sol.p.shape == (0,)
    assert sol.transcription == Radau(2) and sol.mesh == Mesh.uniform(5)
    assert sol.solve_time > 0 and sol.build_time > 0 and sol.iterations > 0
    assert sol.status == STATUS_SUCCESS and sol.success
    assert np.all(np.diff(sol.t) > 0) and sol.t[-1] == sol.T
    assert "radau" in repr(sol)
    with pytest.raises(ValueError):
        sol.x[0, 0] = 1.0


def test_constraint_row_scales_follow_the_gradient_rule_on_every_guess():
    """Path and boundary row scales: the largest |gradient| over the nodes w.r.t. the scaled
    variables, rounded to a power of two, computed here by hand; the gradient Functions are
    built once (one cache), so a second guess must still give its own scales."""
    from dataclasses import replace

    from appdyn.ocp.guess import initial_guess
    from appdyn.ocp.scaling import auto_scaling
    problem = Problem(double_integrator(), T=1.0, x_initial=[0.1, 0.3], x_final=[2.9, -0.7],
                      path=[Constraint(lambda x, u, p: 3 * x[0] * u + x[1], upper=50.0)],
                      boundary=[Constraint(lambda x0, xf, p: 5 * xf[0] ** 2, upper=100.0)],
                      lagrange=lambda x, u, p: 0.5 * u ** 2)
    g = initial_guess(problem, Radau(3), Mesh.uniform(3))
    pow2 = lambda v: np.exp2(np.round(np.log2(v)))  # noqa: E731
    for guess in (g, replace(g, X=4 * g.X, Xu=4 * g.Xu, U=g.U + 3.0)):
        sc = auto_scaling(problem, guess)
        x, u = guess.Xu, guess.U
        grad = np.stack([3 * u[0] * sc.x[0], np.full_like(u[0], sc.x[1]), 3 * x[0] * sc.u[0]])
        assert sc.path[0] == pow2(np.max(np.abs(grad)))
        assert sc.boundary[0] == pow2(10 * abs(guess.X[0, -1]) * sc.x[0])


def test_automatic_scales_are_powers_of_two_so_boundary_values_are_exact():
    """Scaling by powers of two is exact in floating point: fixed boundary values reach
    IPOPT (as fixed variables) and come back bit for bit."""
    from appdyn.ocp.guess import initial_guess
    from appdyn.ocp.scaling import auto_scaling
    problem = Problem(double_integrator(), T=1.0, x_initial=[0.1, 1 / 3], x_final=[2.9, -0.7],
                      u_bounds={"u": (-30.3, 30.3)}, lagrange=lambda x, u, p: 0.5 * u ** 2)
    g = initial_guess(problem, Radau(3), Mesh.uniform(3))
    sc = auto_scaling(problem, g)
    for v in (sc.x, sc.u, np.array([sc.T])):
        assert np.array_equal(np.exp2(np.round(np.log2(v))), v)
    assert np.array_equal(sc.x, [4.0, 0.5]) and np.array_equal(sc.u, [32.0])  # 2.9, 0.7, 30.3
    sol = solve(problem, N=3, verbose=False)
    assert sol.success
    assert np.array_equal(sol.x[:, 0], [0.1, 1 / 3]) and np.array_equal(sol.x[:, -1], [2.9, -0.7])
