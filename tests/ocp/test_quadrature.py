"""Quadrature and break-point helpers of the transcriptions against closed forms."""
import numpy as np
import pytest

from appdyn.ocp.mesh import sorted_union
from appdyn.ocp.transcription import Radau


@pytest.mark.parametrize("degree", [1, 2, 3, 4, 5, 7])
def test_radau_weights_are_the_radau_iia_quadrature(degree):
    # the Radau IIA weights integrate s^k over [0, 1] exactly up to k = 2 degree - 2
    tr = Radau(degree)
    for k in range(2 * degree - 1):
        assert tr.weights @ tr.points ** k == pytest.approx(1.0 / (k + 1), abs=1e-14)


def test_sorted_union_is_the_set_union():
    rng = np.random.default_rng(3)
    a, b, c = rng.integers(0, 20, 30) / 4, rng.integers(0, 20, 7) / 4, np.array([1.0, 1.0])
    out = sorted_union(a, b, c)
    assert out.tolist() == sorted(set(a) | set(b) | set(c))
    assert sorted_union([2, 1, 2]).dtype.kind == "i" and sorted_union().size == 0


def test_radau_degree_one_integrates_a_running_cost():
    # Radau degree 1 (implicit Euler) with a running cost: its one weight is 1 (it was an
    # array [[0.5, 0.5]] and the solve failed). Minimum energy x'' = u, rest to rest over
    # 1 m in 1 s: J = int u^2 / 2 = 6 exactly (u = 6 - 12 t); measured: the error falls by 4
    # when the mesh halves (0.015 at N = 20)
    from appdyn import ocp
    from appdyn.ocp.examples import min_energy

    errors = []
    for N in (20, 40):
        sol = ocp.solve(min_energy(), N=N, transcription="radau", degree=1)
        assert sol.success
        errors.append(abs(sol.cost - 6.0))
    assert errors[0] < 0.02 and 3.5 < errors[0] / errors[1] < 4.5
