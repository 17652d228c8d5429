"""The engine's one switch detector: `find_switches`, `control_switches` and the switch
intervals of `interval_errors` agree (bang-bang double integrator, T* = 2 sqrt(d), one switch
at T*/2)."""
import numpy as np
import pytest

from appdyn.ocp import control_switches, find_switches, interval_errors, solve
from appdyn.ocp.refine.switch_times import bang_arcs
from appdyn.ocp.status import STATUS_BOUND_VIOLATION

from .reference import STRICT, bang_bang


@pytest.mark.parametrize("N", [7, 8])  # odd: switch inside an interval; even: on a knot
def test_detectors_agree_on_a_bang_bang_solution(N):
    problem, truth = bang_bang()
    # the Radau control polynomial through the switch overshoots |u| <= 1 (N = 7): the
    # detectors read the collocated solution all the same
    sol = solve(problem, N=N, ipopt_options=STRICT, verify=False)
    assert sol.success if N == 8 else sol.status == STATUS_BOUND_VIOLATION, sol.message
    per = control_switches(sol)
    merged = find_switches(sol)
    assert len(per) == 1
    np.testing.assert_array_equal(per[0], merged)
    assert merged.size == 1 and abs(merged[0] - truth["T"] / 2) < 0.02
    est = interval_errors(sol)
    tb = sol.t0 + sol.T * sol.mesh.breaks
    # every interval flagged as switching holds a detected switch
    for k in np.flatnonzero(est.switching):
        assert tb[k] <= merged[0] <= tb[k + 1]
        assert tb[k] <= est.switch_time[k] <= tb[k + 1]
    if N % 2:  # a smeared switch inside interval 3 is flagged there and only there
        assert list(np.flatnonzero(est.switching)) == [3]
    else:  # a jump on a knot: nothing smeared, nothing flagged
        assert not np.any(est.switching)
    # the bang-bang structure of the switch-time polish: the same switch, +1 then -1
    arcs, why = bang_arcs(sol)
    assert why == ""
    np.testing.assert_array_equal(arcs.switch_times, merged)
    np.testing.assert_allclose(arcs.durations, [merged[0] - sol.t0, sol.t0 + sol.T - merged[0]])
    np.testing.assert_array_equal(arcs.controls, [[1.0, -1.0]])


def test_detector_checks_its_arguments():
    problem, _ = bang_bang()
    sol = solve(problem, N=4)
    with pytest.raises(TypeError, match="`solution`"):
        control_switches("sol")
    with pytest.raises(ValueError, match="`samples`"):
        find_switches(sol, samples=1)
    with pytest.raises(TypeError, match="`samples`"):
        find_switches(sol, samples=2.5)
