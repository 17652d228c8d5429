"""The NLP's hand-assembled derivatives (`ocp.assembly`) against CasADi's own automatic
differentiation of the same NLP, and one structure serving problems of equal structure."""
import casadi as ca
import numpy as np
import pytest

from appdyn import ocp
from appdyn.dynamics import clear_caches
from appdyn.ocp import Constraint, Mesh, Problem, solve
from appdyn.ocp.assembly import content_key
from appdyn.ocp.guess import initial_guess
from appdyn.ocp.nlp import Discretization
from appdyn.ocp.scaling import auto_scaling
from appdyn.ocp.transcription import get_transcription

from .reference import bang_bang, bryson_denham, rigid_slew, static_parameter


def _loaded_problem():
    """Path constraints, boundary constraints, a free parameter, Mayer and Lagrange costs,
    a free horizon, maximization: every block of the NLP."""
    base, _ = static_parameter()
    return Problem(base.model, T=(0.5, 2.0), x_initial=[0.0, 0.0], x_final={"v": 0.0},
                   lagrange=lambda x, u, p: 0.5 * u ** 2 * (1 + x[0] ** 2),
                   mayer=lambda xf, p, T: 1.5 * p ** 2 + xf[0] * T,
                   path=[Constraint(lambda x, u, p: x[1] * u - p, upper=1.0),
                         lambda x, u, p: ca.vertcat(x[0] - 2, u * u - 4)],
                   boundary=lambda x0, xf, p: xf[0] * p - 1.0,
                   p_bounds={"k": (0.1, 10.0)}, maximize=True)


def _pointing_problem():
    pr, _ = rigid_slew(theta_f=0.8)
    return pr.replace(q_final_tol=0.05, T=(0.5, 5.0), u_bounds=([-1] * 3, [1] * 3))


PROBLEMS = {
    "loaded": _loaded_problem,
    "bryson_denham": lambda: bryson_denham()[0],
    "bang_bang": lambda: bang_bang()[0],
    "rigid_slew": lambda: rigid_slew(theta_f=0.8)[0],
    "pointing": _pointing_problem,
}


@pytest.mark.parametrize("transcription", ["radau", "trapezoid", "hermite-simpson",
                                           "hermite-simpson-compressed"])
@pytest.mark.parametrize("name", sorted(PROBLEMS))
def test_assembled_derivatives_equal_automatic_differentiation(name, transcription):
    """Gradient, constraint Jacobian and Lagrangian Hessian (upper triangle), values and
    sparsity, at a random point of a non-uniform mesh, against ``casadi.gradient``,
    ``jacobian`` and ``hessian`` of the NLP's own value graph."""
    problem = PROBLEMS[name]()
    rng = np.random.default_rng(7)
    tr = get_transcription(transcription)
    mesh = Mesh(np.concatenate([[0.0], np.sort(rng.uniform(size=4)), [1.0]]))
    guess = initial_guess(problem, tr, mesh, guess=None)
    disc = Discretization(problem, tr, mesh, auto_scaling(problem, guess, overrides=None))
    nlp = disc.nlp
    w, lam_g, lam_f = rng.normal(size=disc.w.size), rng.normal(size=disc.g.size), 0.37
    lg = ca.MX.sym("lg", disc.g.size)
    L = lam_f * nlp["f"] + ca.dot(lg, nlp["g"])
    truth = ca.Function("ad", [nlp["x"], nlp["p"], lg],
                        [ca.gradient(nlp["f"], nlp["x"]), ca.jacobian(nlp["g"], nlp["x"]),
                         ca.triu(ca.hessian(L, nlp["x"])[0])])
    grad, jac, hess = truth(w, disc.P, lam_g)
    d = disc.structure.derivatives
    f1, grad1 = d["grad_f"](w, disc.P)
    g1, jac1 = d["jac_g"](w, disc.P)
    hess1 = d["hess_lag"](w, disc.P, lam_f, lam_g)
    f0, g0 = disc.structure.evaluate(w, disc.P)
    assert float(f1) == pytest.approx(f0, rel=1e-14, abs=1e-14)
    np.testing.assert_allclose(np.asarray(g1).ravel(), g0, rtol=1e-14, atol=1e-14)
    for got, want in ((grad1, grad), (jac1, jac), (hess1, hess)):
        got, want = ca.DM(got), ca.DM(want)
        scale = max(1.0, float(np.max(np.abs(want.full()))) if want.numel() else 1.0)
        assert got.shape == want.shape
        np.testing.assert_allclose(got.full(), want.full(), rtol=0, atol=1e-12 * scale)


def _disc(problem, N=30, transcription="radau"):
    tr = get_transcription(transcription)
    mesh = Mesh.uniform(N)
    return Discretization(problem, tr, mesh, auto_scaling(problem, initial_guess(problem, tr, mesh)))


def test_problems_of_equal_structure_share_one_structure():
    """Another target, horizon and scaling: the same symbolic NLP (numbers are NLP
    parameters); another number of intervals, cost function or model (an inertia is part
    of the rigid-body right-hand side): another one."""
    a, ta = rigid_slew(theta_f=1.0)
    b, tb = rigid_slew(theta_f=0.5, axis=0, T=3.0)
    da, db = _disc(a), _disc(b)
    assert da.structure is db.structure and da.key == db.key
    assert not np.array_equal(da.P, db.P)
    assert _disc(a, N=31).structure is not da.structure
    c = a.replace(lagrange=lambda x, u, p: ca.sumsqr(u))
    assert _disc(c).structure is not da.structure
    assert _disc(rigid_slew(inertia=2.0)[0]).structure is not da.structure
    sa, sb = solve(a, N=30), solve(b, N=30)
    assert sa.success and sb.success
    assert sa.cost == pytest.approx(ta["J"], rel=1e-6) and sb.cost == pytest.approx(tb["J"], rel=1e-6)


def test_content_key_is_equal_for_equal_functions_and_differs_otherwise():
    x = ca.SX.sym("x")
    f1 = ca.Function("f", [x], [x ** 2])
    f2 = ca.Function("f", [x], [x ** 2])
    f3 = ca.Function("f", [x], [x ** 3])
    assert content_key(f1) == content_key(f2) != content_key(f3)
    assert content_key(None) is None
    # kept per Function object: the same answer again, and the same as computed afresh
    assert content_key(f1) is content_key(f1)
    kept = content_key(f3)
    clear_caches()
    assert content_key(f3) == kept and content_key(f3) != content_key(ca.Function("g", [x], [x ** 3]))


def test_warm_start_with_multipliers_converges_at_once():
    """Re-solving from its own solution (same structure and mesh): primal and dual values
    handed to IPOPT, which then has nothing to do."""
    problem, truth = bryson_denham()
    # (bound_tol: x <= l is crossed between the nodes by 6.4e-6 of its scale; backed off by
    # default, and a backed-off solution's multipliers belong to the tightened NLP)
    cold = solve(problem, N=40, bound_tol=1e-5)
    warm = solve(problem, N=40, guess=cold, bound_tol=1e-5)
    assert cold.success and warm.success
    assert warm.iterations <= 1 < cold.iterations
    # the same optimum to IPOPT's tolerance (tol 1e-8 on the scaled NLP; the discretization
    # error of the cost, against the closed form 4/(9 l), is 6e-6)
    assert warm.cost == pytest.approx(cold.cost, rel=1e-6)
    assert abs(warm.cost - truth["J"]) < 1e-5
    assert cold.nlp_point is not None and set(cold.nlp_point) >= {"x_phys", "lam_x_phys", "lam_g_phys"}


def test_warm_start_of_another_problem_uses_primal_values_only():
    """The dual warm start is kept for the same NLP; a Solution of another problem of the
    same structure (other target) starts IPOPT from its primal values, as before."""
    from appdyn.ocp.solve import _warm_point

    a, _ = rigid_slew(theta_f=1.0)
    b, tb = rigid_slew(theta_f=1.1)
    sa = solve(a, N=30)
    assert _warm_point(sa, _disc(a)) is not None
    assert _warm_point(sa, _disc(b)) is None
    warm = solve(b, N=30, guess=sa)
    assert warm.success and warm.cost == pytest.approx(tb["J"], rel=1e-6)


def test_code_generation_gives_the_same_solution():
    """``codegen=True`` compiles the interval derivatives to C: the same iterates, the
    same optimum (Bryson-Denham, J = 4 / (9 l)) as the SX Functions."""
    from appdyn.dynamics.cache import compiler

    problem, truth = bryson_denham()
    plain = solve(problem, N=12)
    built = solve(problem, N=12, codegen=True)
    assert built.success and plain.success
    assert built.iterations == plain.iterations
    assert built.cost == pytest.approx(plain.cost, rel=1e-12)
    assert abs(built.cost - truth["J"]) < 1e-3
    tr = get_transcription("radau")
    mesh = Mesh.uniform(12)
    disc = Discretization(problem, tr, mesh, auto_scaling(problem, initial_guess(problem, tr, mesh)),
                          codegen=True)
    assert disc.structure.compiled == (compiler() is not None)
    with pytest.raises(ValueError, match="codegen"):
        solve(problem, N=12, codegen="yes")


@pytest.mark.parametrize("name", ["loaded", "rigid_slew", "pointing"])
def test_switch_time_nlp_assembled_equals_the_whole_nlp_differentiated_by_casadi(name):
    """The switch-time NLP of `ocp.refine.arc_nlp`, assembled per segment, against the same
    NLP stated whole in MX around the mapped RK8 step (`_whole`) and differentiated by
    casadi: constraint blocks, values, gradient, Jacobian, Lagrangian Hessian (upper
    triangle) and cost at a random point, on arcs of unequal segment counts."""
    from appdyn.ocp.refine.arc_nlp import _whole, arc_nlp
    from appdyn.ocp.refine.rk8_step import step_function

    problem = PROBLEMS[name]()
    step = step_function(problem.model, problem.lagrange)
    nseg = np.array([3, 1, 4])
    mine, whole = arc_nlp(problem, step, 3, nseg), _whole(problem, step, 3, nseg, None)
    assert mine.derivatives is not None and mine.blocks == whole.blocks
    x, p = whole.nlp["x"], whole.nlp["p"]
    rng = np.random.default_rng(3)
    w, par = rng.uniform(0.5, 1.5, x.numel()), rng.uniform(0.5, 1.5, p.numel())
    lam_g, lam_f = rng.normal(size=whole.nlp["g"].numel()), 0.37
    lg = ca.MX.sym("lg", lam_g.size)
    ad = ca.Function("ad", [x, p, lg], [
        whole.nlp["f"], whole.nlp["g"], ca.gradient(whole.nlp["f"], x),
        ca.jacobian(whole.nlp["g"], x),
        ca.triu(ca.hessian(lam_f * whole.nlp["f"] + ca.dot(lg, whole.nlp["g"]), x)[0])])
    f0, g0, G0, J0, H0 = (np.asarray(ca.densify(v)) for v in ad(w, par, lam_g))
    d = mine.derivatives
    f1, G1 = (np.asarray(ca.densify(v)) for v in d["grad_f"](w, par))
    g1, J1 = (np.asarray(ca.densify(v)) for v in d["jac_g"](w, par))
    H1 = np.asarray(ca.densify(d["hess_lag"](w, par, lam_f, lam_g)))
    for ref, got in ((f0, f1), (g0, g1), (G0, G1.reshape(G0.shape)), (J0, J1), (H0, H1)):
        np.testing.assert_allclose(got, ref, rtol=1e-12, atol=1e-12 * max(1.0, np.abs(ref).max()))
    assert abs(float(mine.cost(w, par)) - float(whole.cost(w, par))) <= 1e-12 * max(
        1.0, abs(float(whole.cost(w, par))))


@pytest.mark.parametrize("name", ["loaded", "rigid_slew", "pointing"])
def test_step_adjoint_is_the_transposed_jacobian_of_the_step(name):
    """`ocp.refine.rk8_step.step_adjoint` (one reverse sweep: the switch-time costates)
    against casadi's whole state Jacobian of the RK8 step and of its running-cost integral,
    transposed and applied to random seeds, at random points, batched by `map`."""
    from appdyn.ocp.refine.rk8_step import step_adjoint, step_function

    problem = PROBLEMS[name]()
    step = step_function(problem.model, problem.lagrange)
    sym = ca.SX if step.is_a("SXFunction") else ca.MX
    x, u, p, h = (sym.sym(n, step.sparsity_in(i)) for i, n in enumerate("xuph"))
    xn, qn = step(x, u, p, h)
    jac = ca.Function("step_jac", [x, u, p, h], [ca.jacobian(xn, x), ca.jacobian(qn, x)])
    rng = np.random.default_rng(5)
    n = 4
    X, U = rng.uniform(-1, 1, (x.numel(), n)), rng.uniform(-1, 1, (u.numel(), n))
    P, H = rng.uniform(0.5, 1.5, (p.numel(), n)), rng.uniform(0.01, 0.2, (1, n))
    L, S = rng.normal(size=(x.numel(), n)), rng.normal(size=(1, n))
    got = np.asarray(step_adjoint(step).map(n)(X, U, P, H, L, S), float)
    for k in range(n):
        Jx, Jq = (np.asarray(ca.densify(v), float) for v in jac(X[:, k], U[:, k], P[:, k], H[0, k]))
        ref = Jx.T @ L[:, k] + S[0, k] * Jq.reshape(-1)
        np.testing.assert_allclose(got[:, k], ref, rtol=1e-12, atol=1e-12 * max(1.0, np.abs(ref).max()))
    if name == "loaded":  # L = u^2 (1 + x1^2) / 2: the running cost's part is there (not zero)
        assert np.abs(np.asarray(ca.densify(jac(X[:, 0], U[:, 0], P[:, 0], H[0, 0])[1]))).max() > 0
