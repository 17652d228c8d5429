"""Multi-phase engine (`ocp.phases`) against independent truths: a problem split in two
phases has the optimum of the merged problem (closed form 6 d^2 / T^3), a two-stage rocket
has the optimal propellant split of the closed-form rocket equation, links and events hold
to the solver tolerance, warm starts, failures and argument errors."""
from __future__ import annotations

import json
from dataclasses import replace
import math

import casadi as ca
import numpy as np
import pytest
from scipy.optimize import brentq

from appdyn import ocp
from appdyn.dynamics.model import model_from_expressions
from appdyn.ocp.examples import double_integrator
from appdyn.ocp.status import STATUS_SUCCESS

ENERGY = lambda x, u, p: 0.5 * u**2  # noqa: E731


def split_energy(N=10, T=(1.0, 1.0)):
    """Rest at 0 to rest at 1, minimum integral u^2/2, as two phases of durations T."""
    di = double_integrator()
    first = ocp.Problem(di, T=T[0], x_initial=[0.0, 0.0], lagrange=ENERGY)
    second = ocp.Problem(di, T=T[1], x_final=[1.0, 0.0], lagrange=ENERGY)
    return ocp.MultiPhaseProblem([ocp.Phase(first, N=N), ocp.Phase(second, N=N)],
                                 links=[ocp.Link(0, 1)], name="split double integrator")


def test_split_problem_has_the_merged_optimum():
    sol = ocp.solve_phases(split_energy())
    assert sol.success, sol.message
    assert sol.cost == pytest.approx(6 * 1.0**2 / 2.0**3, rel=1e-10)  # Bryson & Ho: 6 d^2/T^3
    merged = ocp.solve(ocp.examples.min_energy(T=2.0), N=20)
    assert sol.cost == pytest.approx(merged.cost, rel=1e-10)
    np.testing.assert_allclose(sol.t0, [0.0, 1.0])
    np.testing.assert_allclose(sol.tf, [1.0, 2.0])
    first, second = sol.phases
    np.testing.assert_allclose(second.x[:, 0], first.x[:, -1], atol=1e-9)  # the link holds
    assert sol.event_violation <= 1e-9
    # the optimal control u = 6/T^2 (1 - 2 t / T) with T = 2 continues across the phases
    t = np.linspace(0.0, 2.0, 9)
    np.testing.assert_allclose(sol.sample("u", t), 1.5 * (1 - t), atol=1e-8)


def test_unequal_meshes_and_transcriptions_per_phase():
    di = double_integrator()
    first = ocp.Problem(di, T=0.5, x_initial=[0.0, 0.0], lagrange=ENERGY)
    second = ocp.Problem(di, T=1.5, x_final=[1.0, 0.0], lagrange=ENERGY)
    mp = ocp.MultiPhaseProblem([ocp.Phase(first, N=4, transcription="hermite-simpson"),
                                ocp.Phase(second, N=12, degree=4, scale={"v": 4.0, "u": 8.0})],
                               links=[ocp.Link(0, 1)])
    sol = ocp.solve_phases(mp)
    assert sol.success, sol.message
    assert sol.cost == pytest.approx(0.75, rel=1e-9)
    assert [s.mesh.N for s in sol.phases] == [4, 12]
    # a third phase on trapezoids: still the merged optimum 6 d^2 / T^3 over T = 2.5 s
    third = ocp.Problem(di, T=0.5, x_final=[1.0, 0.0], lagrange=ENERGY)
    middle = ocp.Problem(di, T=1.5, lagrange=ENERGY)
    costs = []
    for n in (20, 40):  # trapezoids: second order, the error falls 4x per halving
        mp3 = ocp.MultiPhaseProblem([ocp.Phase(first, N=4), ocp.Phase(middle, N=n, transcription="trapezoid"),
                                     ocp.Phase(third, N=3)], links=[ocp.Link(0, 1), ocp.Link(1, 2)])
        sol3 = ocp.solve_phases(mp3)
        assert sol3.success, sol3.message
        costs.append(sol3.cost - 6 / 2.5**3)
    assert 0 < costs[1] < costs[0] / 3.5 and costs[1] < 1e-3


def test_free_durations_and_an_objective_on_the_phase_ends():
    di = double_integrator()
    bound = {"u": (-1.0, 1.0)}
    a = ocp.Problem(di, T=(0.1, 5.0), x_initial=[0.0, 0.0], u_bounds=bound)
    b = ocp.Problem(di, T=(0.1, 5.0), x_final=[1.0, 0.0], u_bounds=bound)
    # minimum time with the switch as the phase boundary: T = 2 sqrt(d / u_max)
    mp = ocp.MultiPhaseProblem([ocp.Phase(a, N=8), ocp.Phase(b, N=8)], links=[ocp.Link(0, 1)],
                               objective=lambda ends: ends[1].tf,
                               events=ocp.Constraint(lambda e: e[0]["x_f"], 0.5, 0.5))
    # (an interior point keeps u off its bound by ~ the barrier: a tight tol for 1e-9)
    sol = ocp.solve_phases(mp, ipopt_options={"tol": 1e-12, "bound_relax_factor": 0.0})
    assert sol.success, sol.message
    assert sol.cost == pytest.approx(2.0, rel=1e-9)  # bang-bang exact with the switch on the boundary
    np.testing.assert_allclose(sol.T, [1.0, 1.0], rtol=1e-8)
    np.testing.assert_allclose(sol.phases[0].u, 1.0, atol=1e-7)
    np.testing.assert_allclose(sol.phases[1].u, -1.0, atol=1e-7)


# ------------------------------------------------------------ two-stage rocket
VE, THRUST, SIGMA, PAYLOAD, M0 = 3000.0, 2.0e5, 0.1, 1000.0, 20000.0
PROPELLANT = (M0 - PAYLOAD) / (1 + SIGMA)  # structure = SIGMA x propellant per stage


def delta_v(p1):
    """Rocket equation for the propellant split (p1, PROPELLANT - p1) [m/s]."""
    p2 = PROPELLANT - p1
    m2 = M0 - (1 + SIGMA) * p1
    return VE * (math.log(M0 / (M0 - p1)) + math.log(m2 / (PAYLOAD + SIGMA * p2)))


def optimal_split():
    """Root of d(delta_v)/d(p1) (closed-form derivative of the rocket equation)."""
    def slope(p1):
        p2 = PROPELLANT - p1
        m2 = M0 - (1 + SIGMA) * p1
        return 1 / (M0 - p1) - (1 + SIGMA) / m2 + SIGMA / (PAYLOAD + SIGMA * p2)
    return brentq(slope, 1.0, PROPELLANT - 1.0, xtol=1e-12)


def two_stage_rocket(N=10):
    v, m = ca.SX.sym("v"), ca.SX.sym("m")
    model = model_from_expressions([("v", v), ("m", m)], [THRUST / m, -THRUST / VE])
    first = ocp.Problem(model, T=(1.0, 400.0), x_initial={"v": 0.0, "m": M0},
                        x_bounds={"m": (PAYLOAD, M0)})
    second = ocp.Problem(model, T=(1.0, 400.0), x_bounds={"m": (PAYLOAD, M0)})
    staging = ocp.Constraint(  # the first stage's structure (SIGMA x its propellant) drops
        lambda e: e[1]["m_0"] - (e[0]["m_f"] - SIGMA * (e[0]["m_0"] - e[0]["m_f"])), 0, 0)
    burnout = ocp.Constraint(lambda e: e[1]["m_f"] - (PAYLOAD + SIGMA * (e[1]["m_0"] - e[1]["m_f"])), 0, 0)
    return ocp.MultiPhaseProblem([ocp.Phase(first, N=N), ocp.Phase(second, N=N)],
                                 links=[ocp.Link(0, 1, states=["v"])], events=[staging, burnout],
                                 objective=lambda e: e[1]["v_f"], maximize=True, name="two-stage rocket")


@pytest.mark.slow
def test_staged_rocket_reaches_the_closed_form_optimum_with_refinement():
    p1 = optimal_split()
    sol = ocp.solve_phases(two_stage_rocket(), refine_tol=1e-10)
    assert sol.success and sol.info["converged"], sol.message
    assert sol.cost == pytest.approx(delta_v(p1), rel=1e-11)
    burned = M0 - sol.phases[0].x[1, -1]
    assert burned == pytest.approx(p1, rel=1e-6)  # the optimum is flat in p1: sqrt of the cost error
    assert sol.event_violation <= 1e-8
    # the refinement record: error estimates fall below refine_tol on finer meshes
    rounds = sol.info["rounds"]
    assert max(rounds[-1][1]) <= 1e-10 < max(rounds[0][1])
    # each round after the first starts from the previous one, primal and dual: few iterations
    assert all(r[3] <= 5 for r in rounds[1:]) and rounds[0][3] > 5, rounds
    # the collocated cost equals the propagated one (rocket equation in each phase)
    for ph in sol.phases:
        prop = ph.propagate()
        assert prop.success
        np.testing.assert_allclose(prop.x[:, -1], ph.x[:, -1], rtol=1e-9)


def test_refinement_rounds_solve_the_nlp_below_refine_tol():
    # an interval's error estimate floors at the NLP's own accuracy: the rounds ask IPOPT
    # for refine_tol / 10, unless the caller chose tol
    from appdyn.ocp.phases.solve import NLP_TOL_PER_REFINE_TOL, _refinement_ipopt_options

    base = {"constr_viol_tol": 1e-9, "print_level": 0}
    tight = _refinement_ipopt_options(base, None, 1e-9)
    assert tight == {**base, "tol": NLP_TOL_PER_REFINE_TOL * 1e-9} and "tol" not in base
    assert _refinement_ipopt_options({**base, "tol": 1e-14}, None, 1e-9)["tol"] == 1e-14
    assert _refinement_ipopt_options({**base, "tol": 1e-6}, {"tol": 1e-6}, 1e-9)["tol"] == 1e-6


def test_unrefined_solve_is_close_and_warm_start_reuses_the_nlp():
    mp = two_stage_rocket()
    sol = ocp.solve_phases(mp)
    assert sol.success
    assert sol.cost == pytest.approx(delta_v(optimal_split()), rel=1e-6)
    again = ocp.solve_phases(mp, guess=sol)
    assert again.success and again.iterations <= 3
    assert again.cost == pytest.approx(sol.cost, rel=1e-12)


def test_warm_start_carries_over_to_the_same_nlp_with_other_bounds():
    """A bound homotopy: the solution of one NLP warm-starts (primal and dual values) the
    same NLP with other bounds; here a speed bound on the second stage that the optimum
    meets with room to spare, so the answer is the same in a few iterations."""
    mp = two_stage_rocket()
    sol = ocp.solve_phases(mp)
    assert sol.success
    bounded = replace(mp.phases[1].problem, x_bounds={"m": (PAYLOAD, M0), "v": (-2e4, 2e4)})
    other = ocp.MultiPhaseProblem([mp.phases[0], replace(mp.phases[1], problem=bounded)],
                                  links=mp.links, events=mp.events, objective=mp.objective,
                                  maximize=True)
    cold = ocp.solve_phases(other)
    warm = ocp.solve_phases(other, guess=sol)
    assert cold.success and warm.success
    assert warm.iterations <= 3 < cold.iterations
    assert warm.cost == pytest.approx(cold.cost, rel=1e-9)
    # the same variables and rows in the same units: the scalings are kept, not derived again
    assert all(a is b for a, b in zip(warm.nlp_point["scalings"], sol.nlp_point["scalings"]))
    assert not any(a is b for a, b in zip(cold.nlp_point["scalings"], sol.nlp_point["scalings"]))


def test_a_solution_on_other_meshes_starts_primal_and_dual():
    """A solution on 10 intervals per phase starts the same problem on 7 and 16 (costates
    interpolated into the defect multipliers, links and events copied): the answer of a
    cold solve on those meshes in a few iterations."""
    coarse = ocp.solve_phases(two_stage_rocket())
    fine = two_stage_rocket()
    fine = ocp.MultiPhaseProblem([replace(fine.phases[0], N=7), replace(fine.phases[1], N=16)],
                                 links=fine.links, events=fine.events, objective=fine.objective,
                                 maximize=True)
    cold = ocp.solve_phases(fine)
    warm = ocp.solve_phases(fine, guess=coarse)
    assert coarse.success and cold.success and warm.success, (cold.message, warm.message)
    assert warm.iterations <= 3 < cold.iterations
    assert warm.cost == pytest.approx(cold.cost, rel=1e-9)
    assert [s.mesh.N for s in warm.phases] == [7, 16]


def test_a_stopped_solution_on_other_meshes_still_starts_the_solve():
    """A solve stopped after 2 iterations starts the problem on 14 intervals per phase (its
    primal values only: the multipliers of a failed solve are not taken): the answer of a
    cold solve."""
    stopped = ocp.solve_phases(two_stage_rocket(), ipopt_options={"max_iter": 2})
    assert not stopped.success
    fine = two_stage_rocket(N=14)
    sol = ocp.solve_phases(fine, guess=stopped)
    assert sol.success, sol.message
    assert sol.cost == pytest.approx(ocp.solve_phases(fine).cost, rel=1e-9)


def test_an_infeasible_event_is_a_failure_not_an_exception():
    mp = two_stage_rocket()
    impossible = ocp.MultiPhaseProblem(
        mp.phases, links=mp.links, objective=mp.objective, maximize=True,
        events=[*mp.events, ocp.Constraint(lambda e: e[1]["v_f"], 2e4, np.inf)])
    sol = ocp.solve_phases(impossible, ipopt_options={"max_iter": 200})
    assert not sol.success
    assert sol.status != STATUS_SUCCESS
    assert sol.message


def test_solution_views_and_json():
    sol = ocp.solve_phases(split_energy(N=6))
    assert sol.phase_at(0.5) == 0 and sol.phase_at(1.0) == 1 and sol.phase_at(2.0) == 1
    assert sol["x"].shape == sol.t.shape
    data = json.loads(sol.to_json())
    assert data["success"] and len(data["phases"]) == 2
    assert data["phases"][1]["t0"] == pytest.approx(1.0)
    assert "phase 1" in str(sol)
    with pytest.raises(ValueError, match="`t`"):
        sol.phase_at(3.0)


def test_argument_errors():
    di = double_integrator()
    pb = ocp.Problem(di, T=1.0, lagrange=ENERGY)
    ph = ocp.Phase(pb)
    with pytest.raises(ValueError, match="`phases`"):
        ocp.MultiPhaseProblem([])
    with pytest.raises(TypeError, match=r"`phases\[1\]`"):
        ocp.MultiPhaseProblem([ph, pb])
    with pytest.raises(ValueError, match="a < b"):
        ocp.MultiPhaseProblem([ph, ph], links=[ocp.Link(1, 0)])
    with pytest.raises(ValueError, match=r"`links\[0\]\.a`"):
        ocp.MultiPhaseProblem([ph, ph], links=[ocp.Link(2, 3)])
    with pytest.raises(ValueError, match="not a state of both"):
        ocp.MultiPhaseProblem([ph, ph], links=[ocp.Link(0, 1, states=["q"])])
    with pytest.raises(ValueError, match="not a linked state"):
        ocp.MultiPhaseProblem([ph, ph], links=[ocp.Link(0, 1, states=["x"], jump={"v": 1.0})])
    with pytest.raises(ValueError, match="maximize"):
        ocp.MultiPhaseProblem([ocp.Phase(ocp.Problem(di, T=1.0, mayer=lambda xf, p, T: xf[0],
                                                     maximize=True))])
    with pytest.raises(ValueError, match="`objective` must return a scalar"):
        ocp.MultiPhaseProblem([ph], objective=lambda e: e[0].xf)
    with pytest.raises(ValueError, match=r"`events\[0\]\.lower`"):
        ocp.MultiPhaseProblem([ph], events=ocp.Constraint(lambda e: e[0].xf, [0, 1, 2], 5))
    with pytest.raises(TypeError, match="`objective`"):
        ocp.MultiPhaseProblem([ph], objective=3.0)
    with pytest.raises(ValueError, match="unknown phase-end name 'speed_f'"):
        ocp.MultiPhaseProblem([ph], objective=lambda e: e[0]["speed_f"])
    mp = ocp.MultiPhaseProblem([ph])
    with pytest.raises(TypeError, match="`problem`"):
        ocp.solve_phases(pb)
    with pytest.raises(ValueError, match="`refine_tol`"):
        ocp.solve_phases(mp, refine_tol=-1.0)
    with pytest.raises(ValueError, match="`guess`"):
        ocp.solve_phases(mp, guess=[None, None])


def test_phase_parameters_shared_by_an_event():
    """x'' = u + a with a free bias ``a`` in each phase, tied equal by an event, and
    Phi = (a - 1)^2 over the ends: J = 0.75 + a^2 T / 2 + (a - 1)^2 with T = 2 (rest-to-rest
    over 1 in 2 s; the bias costs integral a^2 / 2 because the optimal u + a is the unbiased
    profile), minimal at a = 1/2, J = 1.25."""
    x, v, u, a = (ca.SX.sym(n) for n in ("x", "v", "u", "a"))
    model = model_from_expressions([("x", x), ("v", v)], [v, u + a], controls=[("u", u)],
                                   params=[("a", a)], p_default=[0.0])
    free = {"a": (-2.0, 2.0)}
    first = ocp.Problem(model, T=1.0, x_initial=[0.0, 0.0], p_bounds=free, lagrange=ENERGY)
    second = ocp.Problem(model, T=1.0, x_final=[1.0, 0.0], p_bounds=free, lagrange=ENERGY)
    mp = ocp.MultiPhaseProblem([ocp.Phase(first, N=8), ocp.Phase(second, N=8)], links=[ocp.Link(0, 1)],
                               events=ocp.Constraint(lambda e: e[0]["a"] - e[1]["a"], 0, 0),
                               objective=lambda e: (e[0]["a"] - 1) ** 2)
    sol = ocp.solve_phases(mp)
    assert sol.success, sol.message
    assert sol.cost == pytest.approx(1.25, rel=1e-9)
    for ph in sol.phases:
        assert ph.p[0] == pytest.approx(0.5, rel=1e-8)


def test_violations_measure_each_point_and_the_phases_as_their_own_discretizations():
    """`PhasedDiscretization.violations` keeps its last point's answer: a new point is
    measured again (not the kept answer), and every phase's share is what that phase's own
    `Discretization.violation` gives on its slice; the link rows by hand."""
    from appdyn.ocp.guess import initial_guess
    from appdyn.ocp.nlp import Discretization
    from appdyn.ocp.phases.nlp import PhasedDiscretization
    from appdyn.ocp.scaling import auto_scaling
    from appdyn.ocp.solve import default_mesh
    from appdyn.ocp.transcription import get_transcription

    problem = split_energy(N=4)
    discs = []
    for ph in problem.phases:
        tr, mesh = get_transcription(ph.transcription, degree=ph.degree), default_mesh(ph.N, ph.mesh)
        pb = replace(ph.problem, t0=0.0)
        discs.append(Discretization(pb, tr, mesh, auto_scaling(pb, initial_guess(pb, tr, mesh))))
    n_e = problem.event_bounds()[0].size
    disc = PhasedDiscretization(problem, discs, 1.0, np.ones(n_e))
    rng = np.random.default_rng(3)
    w = np.clip(rng.normal(size=disc.lbx.size), disc.lbx, disc.ubx)  # the rows decide
    points = [rng.normal(size=disc.lbg.size) * s for s in (1.0, 3.0, 1.0)]
    points[2] = points[0].copy()
    for g in points:
        phases, events = disc.violations(g, w)
        gs, ge = disc.split_g(g)
        ws = disc.split_w(w)
        assert phases == tuple(d.violation(gi, wi) for d, gi, wi in zip(discs, gs, ws))
        lo, hi = problem.event_bounds()
        assert events == pytest.approx(max(0.0, np.max(np.maximum(lo - ge, ge - hi))), abs=0)
        assert disc.violation(g, w) == max(*phases, events)
    for g in points:  # without the variables
        gs, _ = disc.split_g(g)
        assert disc.violations(g, None)[0] == tuple(d.violation(gi) for d, gi in zip(discs, gs))
