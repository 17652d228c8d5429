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
