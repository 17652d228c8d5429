"""A plain import pulls in no heavy dependency: scipy's submodules, matplotlib,
python-control, sympy and multiprocessing are imported where a call needs them, and
`appdyn.dynamics` imports its heavier parts on first use (PEP 562) while every public name
stays importable.

Structural, not timed: which modules a fresh process holds after the import.
"""
import subprocess
import sys
from pathlib import Path

import pytest

import appdyn.dynamics

ROOT = Path(__file__).resolve().parents[1]
HEAVY = ("scipy.optimize", "scipy.linalg", "scipy.sparse", "scipy.special", "scipy.integrate",
         "scipy.interpolate", "scipy.signal", "matplotlib", "control", "sympy",
         "multiprocessing")  # (the process pool's: it brings subprocess, tempfile, ...)


def _loaded_after(statement: str) -> list[str]:
    probe = (f"import sys\n{statement}\n"
             f"print(sorted(m for m in {HEAVY!r} if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         timeout=300, env={"PYTHONPATH": str(ROOT), "PATH": ""})
    assert out.returncode == 0, out.stderr
    return eval(out.stdout)  # a printed list of names


@pytest.mark.parametrize("statement", [
    "import appdyn", "import appdyn.dynamics",
    "import appdyn.problems.slew, appdyn.problems.gains, appdyn.problems.stability, "
    "appdyn.problems.dispersion, appdyn.problems.ascent, appdyn.ocp"])
def test_a_plain_import_pulls_no_heavy_dependency(statement):
    assert _loaded_after(statement) == []


def test_the_probe_sees_a_heavy_import():
    """The check can fail: a call that needs scipy.special brings it in."""
    assert "scipy.special" in _loaded_after(
        "from appdyn.dynamics.mechanisms import pendulum_period; pendulum_period(1.0)")


def test_every_public_name_of_dynamics_resolves():
    names = appdyn.dynamics.__all__
    assert set(names) <= set(dir(appdyn.dynamics))
    assert all(getattr(appdyn.dynamics, name) is not None for name in names)
    from appdyn.dynamics.launch_vehicle.parts import Aero  # noqa: F401  (the submodules loaded)
    from appdyn.dynamics.linearize import linearization  # noqa: F401
    from appdyn.dynamics import launch_vehicle, linearize, rigid_body, simulate

    # a function, not the submodule of the same name
    assert all(callable(f) and not hasattr(f, "__path__") and type(f).__name__ == "function"
               for f in (launch_vehicle, linearize, rigid_body, simulate))
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        appdyn.dynamics.nothing  # noqa: B018
