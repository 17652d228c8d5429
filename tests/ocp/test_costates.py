"""Radau costate estimates from the defect multipliers against the analytical costate.

For the minimum-energy double integrator (H = u^2/2 + l1 v + l2 u) the costates are
l1 = -12, l2 = 12 t - 6. Radau of degree d >= 3 represents the optimal state (cubic) and
control (linear) exactly, so the discrete KKT multipliers map *exactly* onto the costate
(Garg et al. 2010: lambda_i = -nu_i / w_i at the collocation points, lambda(t0) =
sum_i D_i0 nu_i): only IPOPT's tolerance (1e-12) remains, hence 1e-9, on uniform and
non-uniform meshes and with a scaled objective (the multipliers must be unscaled).
"""
from __future__ import annotations

import numpy as np
import pytest

from appdyn.ocp import Mesh, solve

from .reference import STRICT, min_energy


@pytest.mark.parametrize("degree", [3, 4])
@pytest.mark.parametrize("mesh", [Mesh.uniform(5), Mesh([0.0, 0.07, 0.3, 0.35, 0.8, 1.0])])
def test_radau_costates_match_analytical(degree, mesh):
    problem, truth = min_energy()
    sol = solve(problem, transcription="radau", degree=degree, mesh=mesh, verbose=False,
                ipopt_options=STRICT)
    assert sol.success
    assert sol.costates.shape == sol.x.shape
    assert np.max(np.abs(sol.costates - truth["costate"](sol.t))) <= 1e-9


def test_costates_invariant_to_scaling():
    problem, truth = min_energy()
    sol = solve(problem, N=4, verbose=False, ipopt_options=STRICT,
                scale={"objective": 64.0, "x": 0.25, "v": 8.0, "u": 16.0})
    assert np.max(np.abs(sol.costates - truth["costate"](sol.t))) <= 1e-9


def test_costates_are_none_for_other_transcriptions():
    problem, _ = min_energy()
    for name in ("trapezoid", "hermite-simpson"):
        assert solve(problem, transcription=name, N=4, verbose=False).costates is None
