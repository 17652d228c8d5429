"""`slew.switch_times` is the engine's switch detector; `plot_slew` builds a Figure."""
import numpy as np
import pytest
from matplotlib.figure import Figure

from appdyn import ocp
from appdyn.problems import slew


@pytest.fixture(scope="module")
def bilimoria_wie():
    return slew.time_optimal(np.eye(3), angle=np.pi, axis=[0, 0, 1], u_max=1.0)


@pytest.mark.slow
def test_switch_times_agree_with_the_engine(bilimoria_wie):
    sol = bilimoria_wie
    assert sol.success, sol.message
    per = slew.switch_times(sol)
    assert len(per) == 3
    for a, b in zip(per, ocp.control_switches(sol)):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_allclose(np.unique(np.concatenate(per)), ocp.find_switches(sol), atol=1e-9)
    np.testing.assert_array_equal(slew.switch_times(sol, axis=2), per[2])
    assert slew.summary(sol)["switch_times"] == [s.tolist() for s in per]
    with pytest.raises(ValueError, match="`axis`"):
        slew.switch_times(sol, axis=3)


@pytest.mark.slow
def test_a_slew_plots_itself_on_the_axes_given(bilimoria_wie):
    fig = bilimoria_wie.plot()  # a slew's plot() is the slew figure (plot_slew an alias)
    assert isinstance(fig, Figure) and len(fig.axes) == 4
    assert [a.get_ylabel() for a in fig.axes[:3]] == ["quaternion [-]", "body rate [rad/s]",
                                                      "control [N m]"]
    given = Figure().subplots(1, 2)
    assert slew.plot_slew(bilimoria_wie, given[0]) is given[1].figure
    assert len(given[1].figure.axes) == 1 + 4  # the slot of given[0] divided into the panels
    with pytest.raises(TypeError, match="`ax`"):
        slew.plot_slew(bilimoria_wie, "figure")


@pytest.mark.slow
def test_switch_times_component_and_the_deprecated_axis(bilimoria_wie):
    sol = bilimoria_wie
    per = slew.switch_times(sol)
    np.testing.assert_array_equal(slew.switch_times(sol, component=1), per[1])
    with pytest.warns(DeprecationWarning, match="component"):
        np.testing.assert_array_equal(slew.switch_times(sol, axis=1), per[1])
    with pytest.raises(ValueError, match="`component`"):
        slew.switch_times(sol, component=3)
    with pytest.raises(TypeError, match="`component`"):
        slew.switch_times(sol, component=[0, 0, 1])
    with pytest.raises(TypeError, match="not both"):
        slew.switch_times(sol, component=1, axis=1)


# ---------------------------------------------------- the polish's budget and record
# the new user's slew: a full inertia with products of inertia, pi/2 about (0, 1, 1)/sqrt 2
USER_INERTIA = np.array([[10.0, 1.2, -0.8], [1.2, 12.0, 0.6], [-0.8, 0.6, 8.0]])
USER_SLEW = dict(angle=np.pi / 2, axis=np.array([0.0, 1.0, 1.0]) / np.sqrt(2),
                 u_max=[0.5, 0.5, 0.3])


@pytest.mark.slow
def test_polish_skipped_on_a_first_solution_that_is_not_bang_bang():
    """Its first solution has a singular arc (component 0 off its bounds on a stretch): the
    switch-time polish does not apply, and the moving-knot re-solve it fell back to took
    6.5 s (20x the solve) to be discarded. Now skipped before anything is built, saying so:
    the same T (the times are measured by bench/trust.py, not asserted here)."""
    import time

    plain = slew.time_optimal(USER_INERTIA, **USER_SLEW, polish=False)
    t = time.perf_counter()
    sol = slew.time_optimal(USER_INERTIA, **USER_SLEW)
    t_polish = time.perf_counter() - t
    assert plain.success and sol.success, sol.message
    arcs, why = ocp.bang_arcs(plain)
    assert arcs is None and "singular" in why  # the independent reading of the structure
    record = sol.info["polish"]
    assert record["ran"] is False and record["used"] is False and "not bang-bang" in record["why"]
    assert "polish skipped: not bang-bang" in sol.message
    assert sol.T == plain.T and record["gain"] == 0.0 and record["wall_time"] == 0.0
    assert sol.info["wall_time"] <= t_polish


def test_polish_record_of_a_bang_bang_slew(bilimoria_wie):
    """Bilimoria-Wie: the polish runs within its budget and records what it gained: the
    switch-time T (exact to ~1e-12, Bilimoria & Wie 3.2431) against the first solve's."""
    sol = bilimoria_wie
    record = sol.info["polish"]
    assert record["ran"] and record["used"] and record["method"] == "switch-times"
    assert record["T_after"] == sol.T and abs(sol.T - 3.2430833) < 1e-6
    assert record["gain"] == pytest.approx(record["T_before"] - sol.T, abs=1e-15)
    # an iteration budget per NLP (the same answer on any load): at least POLISH_MIN_ITER
    from appdyn.problems.slew.maneuvers import POLISH_ITER_FACTOR, POLISH_MIN_ITER
    first = sol.info["race"]["iterations"] if "race" in sol.info else None
    assert isinstance(record["budget"], int) and record["budget"] >= POLISH_MIN_ITER
    assert first is None or record["budget"] <= max(POLISH_MIN_ITER, POLISH_ITER_FACTOR * first)
    assert f"at most {record['budget']} IPOPT iterations per NLP" in sol.message
    assert sol.info["wall_time"] >= record["wall_time"]
    assert "polish (switch-times" in sol.message and "gain" in sol.message


def test_the_polish_stops_at_its_iteration_budget(monkeypatch):
    """A budget of 2 IPOPT iterations per NLP (Bilimoria-Wie's switch-time NLP needs 3):
    the polish runs, is not used, and the first solution comes back as `polish=False`
    gives it, the record and the message naming the budget. The budget counts iterations,
    not seconds, so this is the answer on any load."""
    from appdyn.problems.slew import maneuvers

    monkeypatch.setattr(maneuvers, "POLISH_MIN_ITER", 2)
    monkeypatch.setattr(maneuvers, "POLISH_ITER_FACTOR", 0)
    kw = dict(angle=np.pi, axis=[0, 0, 1], u_max=1.0, N=10, starts=1)
    plain = slew.time_optimal(np.eye(3), polish=False, **kw)
    sol = slew.time_optimal(np.eye(3), **kw)
    record = sol.info["polish"]
    assert plain.success and sol.success, sol.message
    assert record["ran"] and not record["used"] and record["budget"] == 2
    assert sol.T == plain.T and record["gain"] == 0.0
    assert "at most 2 IPOPT iterations per NLP" in sol.message


# ------------------------------------------------------------------ the coarse race
def test_the_coarse_race_reaches_the_optimum_of_the_fine_starts(monkeypatch, bilimoria_wie):
    """The starts raced on `RACE_N` intervals and the best polished at once give the T of
    the pipeline that solves every start on N = 30 before the polish (a second formulation:
    the race switched off), to the switch-time integration error; two agreeing starts stop
    the race (the 2 rad slew). Bilimoria-Wie's eigenaxis start (idle x and y torques: it
    stays on the eigenaxis local optimum 2 sqrt(pi) by symmetry) goes last and is skipped
    once the two tilted ones agree below it."""
    from appdyn.problems.slew import maneuvers

    second = dict(angle=2.0, axis=[0.2, 1.0, 0.5], u_max=1.0)
    raced = slew.time_optimal(np.eye(3), **second)
    monkeypatch.setattr(maneuvers, "RACE_N", None)
    fine = slew.time_optimal(np.eye(3), **second)
    assert raced.success and fine.success, (raced.message, fine.message)
    assert "race" not in fine.info and len(fine.info["starts"]) == 3
    assert raced.info["race"]["N"] == 10
    assert raced.info["race"]["skipped"] == 1 and len(raced.info["starts"]) == 2
    assert raced.info["polish"]["used"] and raced.info["polish"]["method"] == "switch-times"
    assert abs(raced.T - fine.T) <= 1e-9 * fine.T
    bw = bilimoria_wie.info
    assert bw["race"]["skipped"] == 1 and len(bw["starts"]) == 2
    assert max(s["T"] for s in bw["starts"]) < 3.2443 < slew.eigenaxis_time(np.eye(3), np.pi, [0, 0, 1])
