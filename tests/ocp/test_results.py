"""ocp.Solution shares the result habits: __str__, to_dict, to_json (strict), plot."""
import json

import numpy as np

from appdyn import ocp
from appdyn.ocp.examples import min_energy


def test_solution_serializes_and_plots(tmp_path):
    sol = ocp.solve(min_energy(), N=10)
    data = json.loads(sol.to_json(), parse_constant=lambda c: (_ for _ in ()).throw(ValueError(c)))
    assert data["success"] is True and data["status"] == 0
    assert data["solver_status"] == "Solve_Succeeded"
    assert abs(data["cost"] - 6.0) < 1e-8  # Bryson & Ho: J = 6
    assert list(data["x"]) == list(sol.problem.model.states)
    np.testing.assert_array_equal(data["u"][sol.problem.model.controls[0]], sol.u[0])
    assert "Optimal control solution" in str(sol) and "Solve_Succeeded" in str(sol)
    fig = sol.plot()  # states and controls grouped by unit (the model's units)
    assert type(fig).__name__ == "Figure" and all(a.get_ylabel().startswith("[") for a in fig.axes)
    assert sum(len(a.get_legend().get_texts()) for a in fig.axes) == 3  # x, v, u
    text = repr(sol)
    assert text.startswith("Solution") and len(text.splitlines()) <= 10 and "radau" in text
