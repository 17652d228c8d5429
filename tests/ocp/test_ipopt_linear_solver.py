"""An IPOPT ``linear_solver`` that does not load is a ValueError before any solve, at every
entry point (`ocp.check_ipopt_options`), not an ``Invalid_Option`` result with garbage
counters."""
import subprocess
import sys

import pytest

from appdyn.ocp import check_ipopt_options, polish_switches, solve
from appdyn.ocp.ipopt_options import available_linear_solvers

from .reference import bang_bang, min_energy

# the truth: IPOPT itself, through CasADi, in a subprocess (a missing Pardiso library can
# crash the process that tries it), without this package
_DIRECT = r"""
import sys
import casadi as ca
x = ca.SX.sym("x")
s = ca.nlpsol("s", "ipopt", {"x": x, "f": (x - 1) ** 2},
              {"print_time": False, "error_on_fail": False,
               "ipopt": {"linear_solver": sys.argv[1], "print_level": 0, "sb": "yes"}})
s(x0=0.0)
print(s.stats()["return_status"])
"""


def _direct_status(name: str) -> str:
    out = subprocess.run([sys.executable, "-c", _DIRECT, name], capture_output=True, text=True,
                         timeout=60, check=False)
    return out.stdout.strip().splitlines()[-1] if out.returncode == 0 and out.stdout.strip() \
        else f"crashed ({out.returncode})"


def test_available_linear_solvers_agree_with_ipopt_itself():
    available = available_linear_solvers()
    for name in ("mumps", "ma27", "ma57"):
        assert (name in available) == (_direct_status(name) == "Solve_Succeeded"), name


def test_an_unavailable_linear_solver_raises_naming_it_and_the_available_ones(capfd):
    if _direct_status("ma57") == "Solve_Succeeded":
        pytest.skip("the HSL library is installed here: ma57 loads")
    assert _direct_status("mumps") == "Solve_Succeeded"
    with pytest.raises(ValueError, match=r"linear_solver.*'ma57'.*available.*'mumps'"):
        check_ipopt_options({"linear_solver": "ma57"})
    problem, _ = min_energy()
    with pytest.raises(ValueError, match=r"linear_solver.*'ma57'.*'mumps'"):
        solve(problem, N=4, ipopt_options={"ipopt.linear_solver": "ma57"})
    fastest, _ = bang_bang(1.0, 1.0)
    start = solve(fastest, N=7)
    with pytest.raises(ValueError, match=r"linear_solver.*'ma57'.*'mumps'"):
        polish_switches(fastest, start, ipopt_options={"linear_solver": "ma57"})
    assert capfd.readouterr().out == ""
    # an available one passes and solves
    sol = solve(problem, N=4, ipopt_options={"linear_solver": "mumps"})
    assert sol.success and sol.iterations >= 0
