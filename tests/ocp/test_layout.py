"""Layout: named blocks of a flat NLP vector, column-major like CasADi."""
from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from appdyn.ocp.layout import Layout


def test_split_join_round_trip_numeric_and_symbolic():
    lay = Layout({"X": (2, 3), "P": (0, 1), "T": (1, 1)})
    assert lay.size == 7
    v = np.arange(7.0)
    parts = lay.split(v)
    assert np.array_equal(parts["X"], np.array([[0, 2, 4], [1, 3, 5]]))
    assert parts["P"].shape == (0, 1) and parts["T"][0, 0] == 6.0
    assert np.array_equal(lay.join(parts), v)
    w = ca.MX.sym("w", 7)
    sym = lay.split(w)
    f = ca.Function("f", [w], [lay.join(sym, symbolic=True)])
    assert np.array_equal(np.asarray(f(v)).ravel(), v)  # same order as casadi.vec
    assert np.array_equal(np.asarray(ca.Function("g", [w], [ca.vec(sym["X"])])(v)).ravel(), v[:6])


def test_join_checks_blocks():
    lay = Layout({"X": (2, 2)})
    with pytest.raises(ValueError, match="missing"):
        lay.join({})
    with pytest.raises(ValueError, match="length 4"):
        lay.split(np.zeros(3))
