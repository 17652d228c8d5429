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


def test_plot_returns_a_figure_of_the_chosen_states(tmp_path):
    res = simulate(rigid_body([1.0, 2.0, 3.0]), [0, 0, 0, 1, 1.0, 0.1, 0.8],
                   np.linspace(0.0, 5.0, 6))
    fig = res.plot(tmp_path / "sim.png", states=["w1", "w3"])
    assert type(fig).__name__ == "Figure" and len(fig.axes[0].lines) == 2
    assert (tmp_path / "sim.png").stat().st_size > 5_000
    with pytest.raises(ValueError, match="`states`"):
        res.plot(states=["w4"])
