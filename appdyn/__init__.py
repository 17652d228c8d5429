"""appdyn: CasADi-based aerospace vehicle dynamics, linearization and optimal control.

The package has three floors, each a subpackage (every arrow points down):

- `appdyn.dynamics`: models as named-I/O CasADi Functions, simulation, linearization and
  closed-form truths;
- `appdyn.ocp`: the direct-collocation engine (problem statement, transcriptions, solve,
  refinement, phases);
- `appdyn.problems`: ready-made jobs (slews, stability reports, gains, ascent, dispersions)
  and the ``appdyn`` command line.

The subpackages are imported on first use (``import appdyn`` alone is cheap):

>>> import appdyn
>>> from appdyn.dynamics import rigid_body
>>> rigid_body([1.0, 2.0, 3.0]).nx
7
"""
from __future__ import annotations

import importlib
import os as _os

__all__ = ["__version__", "dynamics", "ocp", "problems"]

# A source checkout run in place (cwd or PYTHONPATH at the repository root, nothing
# installed from it): the subpackages live beside this folder, as setup.py maps them.
_ROOT = _os.path.dirname(_os.path.dirname(_os.path.abspath(__file__)))
if (_os.path.isfile(_os.path.join(_ROOT, "pyproject.toml"))
        and _os.path.isdir(_os.path.join(_ROOT, "dynamics", "scene"))
        and _ROOT not in __path__):
    __path__.append(_ROOT)

_SUBPACKAGES = ("dynamics", "ocp", "problems")


def _installed_version() -> str:
    # importlib.metadata costs ~0.1 s to import: looked up on first use of __version__
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("appdyn")
    except PackageNotFoundError:  # a source tree that was not installed
        return "0+unknown"


def __getattr__(name: str):
    if name == "__version__":
        globals()["__version__"] = value = _installed_version()
        return value
    if name in _SUBPACKAGES:
        return importlib.import_module(f"appdyn.{name}")
    raise AttributeError(f"module 'appdyn' has no attribute {name!r}")


def __dir__():
    return sorted(__all__)
