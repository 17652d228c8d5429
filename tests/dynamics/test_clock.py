"""The clock convention: time-dependent models carry a state ``t`` with ``t' = 1``."""
import math

import numpy as np
import pytest

from appdyn.dynamics import rigid_body, simulate
from appdyn.dynamics.clock import CLOCK_RTOL, CLOCK_STATE, CLOCK_UNIT, check_clock_start, clock_index
from appdyn.dynamics.linearize import linearization
from appdyn.dynamics.mechanisms import shaken_pendulum, variable_length_pendulum


def test_clock_state_name_unit_and_index():
    model = variable_length_pendulum(length_rate=0.1)
    assert CLOCK_STATE == "t" and CLOCK_UNIT == "s"
    assert clock_index(model) == 2 and model.states[2] == "t" and model.units["t"] == "s"
    assert clock_index(rigid_body([1.0, 2.0, 3.0])) is None
    # the clock's derivative is exactly one, wherever the other states are
    rng = np.random.default_rng(0)
    for _ in range(5):
        x = rng.normal(size=3)
        assert model.rhs(x)[2] == 1.0


def test_simulation_keeps_time_on_a_grid_not_starting_at_zero():
    """Started at t0 = 7 s with the clock set to 7 s, the clock equals the grid (every RK
    method is exact on t' = 1) and the prescribed length is read at the right time."""
    model = variable_length_pendulum(length=1.0, length_rate=0.02, length_amp=0.05,
                                     length_freq=3.0)
    t = np.linspace(7.0, 9.0, 21)
    x0 = check_clock_start(model, [0.2, 0.0, 7.0], t[0])
    res = simulate(model, x0, t, method="rk8", steps=8, invariants=["length"])
    np.testing.assert_allclose(res.x[2], t, rtol=0, atol=1e-13)
    np.testing.assert_allclose(res.invariants["length"], 1.0 + 0.02 * t + 0.05 * np.sin(3.0 * t),
                               rtol=1e-14)


def test_time_shift_equals_a_later_start():
    """A run from t0 = 0 sampled at 0.4 s continues exactly like a run started there."""
    model = shaken_pendulum(amp_y=0.01, amp_x=0.005, freq=30.0)
    t = np.linspace(0.0, 0.8, 9)
    full = simulate(model, [0.3, 0.0, 0.0], t, method="rk8", steps=40)
    late = simulate(model, full.x[:, 4], t[4:], method="rk8", steps=40)
    np.testing.assert_allclose(late.x, full.x[:, 4:], rtol=0, atol=1e-12)


def test_linearization_of_a_clocked_model_has_a_zero_clock_row():
    """The clock row of A is zero; its column is the explicit time dependence df/dt."""
    model = shaken_pendulum(amp_y=0.02, freq=20.0)
    x = [0.4, 0.1, 0.3]
    lin = linearization(model, x, allow_non_equilibrium=True)
    assert not lin.is_equilibrium
    np.testing.assert_array_equal(lin.A[2], np.zeros(3))
    h = 1e-6
    dfdt = (model.rhs([0.4, 0.1, 0.3 + h]) - model.rhs([0.4, 0.1, 0.3 - h])) / (2 * h)
    np.testing.assert_allclose(lin.A[:, 2], dfdt, rtol=1e-7, atol=1e-7)


def test_check_clock_start_accepts_round_off_and_refuses_a_wrong_start():
    model = shaken_pendulum()
    t0 = 0.1 + 0.2  # 0.30000000000000004
    x0 = check_clock_start(model, [0.0, 0.0, 0.3], t0)
    assert x0.dtype == float and x0.shape == (3,)
    with pytest.raises(ValueError, match=r"`x0` sets the clock state 't' \(index 2\)"):
        check_clock_start(model, [0.0, 0.0, 0.3 + 10 * CLOCK_RTOL], 0.3)
    with pytest.raises(ValueError, match="`x0`"):
        check_clock_start(model, [0.0, 0.0], 0.0)
    with pytest.raises(ValueError, match="`x0`"):
        check_clock_start(model, [math.nan, 0.0, 0.0], 0.0)
    with pytest.raises(ValueError, match="`t0`"):
        check_clock_start(model, [0.0, 0.0, 0.0], math.inf)
    with pytest.raises(TypeError, match="`t0`"):
        check_clock_start(model, [0.0, 0.0, 0.0], "now")
    with pytest.raises(TypeError, match="`model`"):
        check_clock_start("shaken", [0.0, 0.0, 0.0], 0.0)
    with pytest.raises(TypeError, match="`model`"):
        clock_index(None)
    # a model without a clock only has x0 checked
    np.testing.assert_array_equal(
        check_clock_start(rigid_body([1.0, 2.0, 3.0]), [0, 0, 0, 1, 0, 0, 0], 5.0),
        [0, 0, 0, 1, 0, 0, 0])
