"""Initial guess from a simulation of the model under a given control."""
import numpy as np
import pytest

from appdyn.ocp import guess_from_simulation, solve

from .reference import min_energy


def test_guess_from_simulating_the_optimal_control_is_the_optimum():
    """Simulating u = 6 - 12 t from rest gives x = 3t^2 - 2t^3, v = 6t - 6t^2 (closed form),
    and the solve started there is already optimal."""
    problem, truth = min_energy()
    g = guess_from_simulation(problem, lambda t: [6.0 - 12.0 * t], n=51, rtol=1e-12, atol=1e-12)
    assert g["x"].shape == (2, 51) and g["u"].shape == (1, 51) and g["T"] == 1.0
    np.testing.assert_allclose(g["x"], truth["x"](g["t"]), atol=1e-10)
    sol = solve(problem, guess=g, N=10, verbose=False)
    assert sol.success and abs(sol.cost - truth["J"]) < 1e-9
    assert sol.iterations <= 3


def test_guess_from_simulation_clips_and_broadcasts_a_constant_control():
    problem, _ = min_energy()
    g = guess_from_simulation(problem, [2.0], n=11)
    np.testing.assert_allclose(g["u"], 2.0)
    np.testing.assert_allclose(g["x"][0], g["t"] ** 2, atol=1e-9)  # x = t^2 under u = 2


def test_guess_from_simulation_needs_a_given_initial_state():
    problem, _ = min_energy()
    with pytest.raises(ValueError, match="fully given"):
        guess_from_simulation(problem.replace(x_initial=[np.nan, 0.0]), [0.0])
