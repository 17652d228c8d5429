"""The numpydoc ``Examples`` of the ocp engine and of `problems.slew` run as written."""
from __future__ import annotations

import doctest
import importlib
import pkgutil

import numpy as np
import pytest

from appdyn import ocp
import appdyn.problems.slew  # noqa: F401
from appdyn import problems

FLAGS = doctest.NORMALIZE_WHITESPACE | doctest.ELLIPSIS


def _modules(package):
    yield package.__name__
    for info in pkgutil.walk_packages(package.__path__, package.__name__ + "."):
        yield info.name


MODULES = sorted(set(_modules(ocp)) | set(_modules(problems.slew)))


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    module = importlib.import_module(name)
    finder = doctest.DocTestFinder(exclude_empty=True)
    runner = doctest.DocTestRunner(optionflags=FLAGS)
    with np.printoptions(legacy=False):
        for test in finder.find(module, name):  # globals: a copy of the module's
            runner.run(test)
    failed, attempted = runner.summarize(verbose=False)
    assert failed == 0, f"{failed} of {attempted} examples failed in {name} (see the output above)"


def test_every_public_entry_point_has_an_example():
    from appdyn.problems import slew

    entries = [ocp.Problem, ocp.solve, ocp.rest_solution, ocp.refine, ocp.solve_multistart,
               ocp.polish_switches, ocp.guess_from_simulation, ocp.Solution.sample,
               ocp.control_switches, ocp.find_switches, slew.time_optimal, slew.min_effort,
               slew.eigenaxis_time, slew.switch_times, slew.summary, slew.format_summary,
               slew.KeepOut, slew.verify, slew.slew_problem, slew.attitude_guess, ocp.solve_phases,
               slew.slew, slew.SlewOptions, slew.scene_problem]
    missing = [e.__qualname__ for e in entries if ">>>" not in (e.__doc__ or "")]
    assert not missing, f"no Examples in {missing}"
