"""Run the docstring Examples of every module in ``dynamics`` (numpydoc ``>>>`` lines).

Every public entry point carries an Examples section (checked below for the names the package
exports, the attitude and truth functions and the input checks), and every example must
print what its docstring says.
"""
import doctest
import importlib
import inspect
import pkgutil

import pytest

from appdyn import dynamics
from appdyn.dynamics import attitude, truth, validate

OPTIONS = doctest.NORMALIZE_WHITESPACE | doctest.ELLIPSIS
MODULES = sorted(
    info.name for info in pkgutil.walk_packages(dynamics.__path__, prefix="appdyn.dynamics.")
) + ["appdyn.dynamics"]


def _tests(module_name):
    """The doctests of the docstrings written in ``module_name`` (not of re-exported names)."""
    module = importlib.import_module(module_name)
    return [t for t in doctest.DocTestFinder(exclude_empty=True).find(module, module_name)
            if t.examples]


@pytest.mark.parametrize("module_name", MODULES)
def test_docstring_examples_run_as_written(module_name):
    runner = doctest.DocTestRunner(optionflags=OPTIONS)
    for test in _tests(module_name):
        runner.run(test)
    result = runner.summarize(verbose=False)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples failed in {module_name}"


def _public_entry_points():
    names = [f"appdyn.dynamics.{n}" for n in ("Model", "rigid_body", "simulate", "linearize", "clear_caches")]
    for module in (attitude, truth, validate):
        names += [f"{module.__name__}.{n}" for n in module.__all__
                  if inspect.isfunction(getattr(module, n))]
    return names


@pytest.mark.parametrize("qualname", _public_entry_points())
def test_every_public_entry_point_has_examples(qualname):
    module_name, name = qualname.rsplit(".", 1)
    obj = getattr(importlib.import_module(module_name), name)
    tests = doctest.DocTestFinder(recurse=False).find(obj, name)
    assert tests and tests[0].examples, f"{qualname} has no Examples"
    assert "Examples\n" in inspect.getdoc(obj)
