"""SimulationResult shares the result habits: __str__, to_dict, to_json (strict), plot."""
import json

import numpy as np
import pytest

from appdyn.dynamics import rigid_body, simulate


def strict_loads(text):
    def refuse(token):
        raise ValueError(f"non-strict JSON token {token}")
    return json.loads(text, parse_constant=refuse)


def test_to_dict_and_json_hold_the_trajectory_by_name():
    t = np.linspace(0.0, 5.0, 6)
    res = simulate(rigid_body([1.0, 2.0, 3.0]), [0, 0, 0, 1, 1.0, 0.1, 0.8], t,
                   invariants=["energy"])
    data = strict_loads(res.to_json())
    assert data["success"] is True and data["status"] == 0 and data["method"] == "rk8"
    assert list(data["x"]) == ["q1", "q2", "q3", "q4", "w1", "w2", "w3"]
    np.testing.assert_array_equal(data["x"]["w2"], res.x[5])
    np.testing.assert_array_equal(data["t"], t)
    np.testing.assert_array_equal(data["invariants"]["energy"], res.invariants["energy"])
    assert "success" in str(res) and res.message in str(res)


def _report_rows(res) -> dict:
    """The rows of ``str(res)``: label -> text."""
    rows = {}
    for line in str(res).splitlines()[1:]:
        label, _, text = line.strip().partition("  ")
        rows[label] = text.strip()
    return rows


def test_report_says_steps_per_interval_only_where_the_grid_sets_them():
    """A dense-output run's steps follow its error, not the grid: its report gives its step
    count, never the event search's bound (``substeps``, 549 "per interval" for 46 steps on
    one 10 s interval before); a fixed-step run's report gives its steps per interval. An
    unverified run's estimate reads "not estimated", not "nan of tolerance"."""
    model, x0 = rigid_body([1.0, 2.0, 3.0]), [0, 0, 0, 1, 1.0, 0.1, 0.8]
    dense = simulate(model, x0, [0.0, 10.0])
    assert "dense output" in dense.message and dense.substeps > dense.n_steps
    rows = _report_rows(dense)
    assert rows["method"] == "rk8" and rows["steps / rhs"] == f"{dense.n_steps} / {dense.n_rhs}"
    fixed = _report_rows(simulate(model, x0, np.linspace(0.0, 10.0, 11), method="rk8", steps=20))
    assert fixed["method"] == "rk8, 20 step(s) per interval"
    plain = _report_rows(simulate(model, x0, [0.0, 10.0], method="dop853"))
    assert plain["method"] == "dop853" and plain["error estimate"].startswith("not estimated")


def test_failed_run_serializes_non_finite_as_null():
    res = simulate(rigid_body([1.0, 2.0, 3.0]), [0, 0, 0, 1, 1.0, 0.1, 0.8],
                   np.linspace(0.0, 1e4, 3), method="rk8")
    assert not res.success
    data = strict_loads(res.to_json())
    assert data["x"]["w1"][-1] is None


def test_plot_groups_states_by_unit_on_the_given_axes():
    from matplotlib.figure import Figure
    model = rigid_body([1.0, 2.0, 3.0])
    res = simulate(model, [0, 0, 0, 1, 1.0, 0.1, 0.8], np.linspace(0.0, 5.0, 6))
    fig = res.plot(states=["q1", "w1", "w3"])
    labels = [a.get_ylabel() for a in fig.axes]
    assert labels == [f"[{model.units.get('q1') or '-'}]", f"[{model.units['w1']}]"]
    assert [len(a.lines) for a in fig.axes] == [1, 2]
    assert "success" not in fig.texts[0].get_text()  # a readable title, not "rk8: success True"
    given = Figure().subplots(1, 1)
    assert res.plot(given, states=["w1"]) is given.figure and len(given.lines) == 1
    with pytest.raises(ValueError, match="`states`"):
        res.plot(states=["w4"])


def test_repr_is_compact_and_html_renders():
    res = simulate(rigid_body([1.0, 2.0, 3.0]), [0, 0, 0, 1, 1.0, 0.1, 0.8],
                   np.linspace(0.0, 5.0, 101))
    text = repr(res)
    assert text.startswith("SimulationResult") and len(text.splitlines()) <= 10
    assert "array(shape=(7, 101), float64)" in text
    assert "<table>" in res._repr_html_()
