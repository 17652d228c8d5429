"""`Problem(maximize=True)` and the default-guess hint in the message of a failed solve."""
import numpy as np
import pytest

from appdyn import ocp
from appdyn.ocp.examples import min_energy, min_time


def _max_energy():
    """Maximize -(1/2) integral u^2 over the min-energy double integrator (optimum -6)."""
    base = min_energy()
    return ocp.Problem(base.model, T=base.T, x_initial=base.x_initial, x_final=base.x_final,
                       lagrange=lambda x, u, p: -0.5 * u**2, maximize=True, name="max -energy")


def test_maximize_matches_minimize():
    lo = ocp.solve(min_energy(), N=10)
    hi = ocp.solve(_max_energy(), N=10)
    assert lo.success and hi.success
    assert lo.cost == pytest.approx(6.0, abs=1e-6)  # Bryson & Ho
    assert hi.cost == pytest.approx(-6.0, abs=1e-6)  # reported with the user's sign
    np.testing.assert_allclose(hi.u, lo.u, atol=1e-6)
    np.testing.assert_allclose(hi.x, lo.x, atol=1e-8)
    # costates belong to the minimized objective (-J = 1/2 int u^2): the same as minimizing
    np.testing.assert_allclose(hi.costates, lo.costates, atol=1e-6)


def test_replace_keeps_sign():
    prob = _max_energy()
    again = prob.replace(name="copy")
    assert again.maximize and again.objective_sign == -1.0
    sol = ocp.solve(again, N=10)
    assert sol.success and sol.cost == pytest.approx(-6.0, abs=1e-6)
    assert prob.replace(maximize=False).objective_sign == 1.0


def test_better():
    lo, hi = min_energy(), _max_energy()
    assert lo.better(1.0, 2.0) and not lo.better(2.0, 1.0)
    assert hi.better(2.0, 1.0) and not hi.better(1.0, 2.0)
    assert not hi.better(1.0, 1.0)
    assert hi.better(1.0, float("nan")) and not hi.better(float("nan"), 1.0)


def test_multistart_picks_largest():
    # maximize T (mayer T) of the double integrator under |u| <= 1 with T <= 3: any T in the
    # range is feasible, the best is the upper bound; a start capped early stays lower
    base = min_time(T_max=3.0)
    prob = ocp.Problem(base.model, T=base.T, x_initial=base.x_initial, x_final=base.x_final,
                       u_bounds=base.u_bounds, mayer=lambda xf, p, T: T, maximize=True)
    sol = ocp.solve_multistart(prob, [None, {"T": 2.5}], N=10)
    assert sol.success
    assert sol.T == pytest.approx(3.0, abs=1e-6)
    assert sol.cost == pytest.approx(3.0, abs=1e-6)
    costs = [s["cost"] for s in sol.info["starts"] if s["success"]]
    assert sol.cost == max(costs)


def test_multistart_ranks_by_sign(monkeypatch):
    """The ranking itself, with stub solves of known costs."""
    import importlib

    ms = importlib.import_module("appdyn.ocp.refine.multistart")

    prob = _max_energy()
    real = ocp.solve(prob, N=5)
    costs = iter([-3.0, -1.0, -2.0])

    def fake(problem, guess=None, **kw):
        import dataclasses
        return dataclasses.replace(real, cost=next(costs))

    monkeypatch.setattr(ms, "solve", fake)
    out = ms.solve_multistart(prob, [None, None, None])
    assert out.info["best"] == 1 and out.cost == -1.0
    costs = iter([-3.0, -1.0, -2.0])
    out = ms.solve_multistart(min_energy(), [None, None, None])
    assert out.info["best"] == 0 and out.cost == -3.0


@pytest.mark.parametrize("bad", [1, 0, "yes", None, 1.0])
def test_maximize_validated(bad):
    with pytest.raises(ValueError, match="maximize"):
        ocp.Problem(min_energy().model, T=1.0, lagrange=lambda x, u, p: u**2, maximize=bad)


def test_default_guess_hint_on_failure():
    fastest = min_time()
    sol = ocp.solve(fastest, N=10, ipopt_options={"max_iter": 1})
    assert not sol.success
    assert "default initial guess" in sol.message
    assert "guess=" in sol.message and "previous Solution" in sol.message
    assert "T = 5.05 s" in sol.message  # middle of [0.1, 10]
    user = ocp.solve(fastest, N=10, guess={"T": 3.0}, ipopt_options={"max_iter": 1})
    assert not user.success
    assert "default initial guess" not in user.message
    ok = ocp.solve(fastest, N=10, control="constant")  # bang-bang
    assert ok.success and "default initial guess" not in ok.message


def test_default_guess_hint_fixed_time():
    sol = ocp.solve(min_energy(), N=10, ipopt_options={"max_iter": 0})
    assert not sol.success
    assert "default initial guess" in sol.message and "free horizon" not in sol.message


def test_polish_keeps_the_sign():
    base = min_time()  # maximize -T is minimum time: T = 2
    prob = ocp.Problem(base.model, T=base.T, x_initial=base.x_initial, x_final=base.x_final,
                       u_bounds=base.u_bounds, mayer=lambda xf, p, T: -T, maximize=True)
    sol = ocp.solve(prob, N=10, control="constant")  # bang-bang
    assert sol.success and sol.cost == pytest.approx(-2.0, abs=1e-6)
    pol = ocp.polish_switches(prob, sol)
    assert pol.success and pol.cost == pytest.approx(-2.0, abs=1e-8)
