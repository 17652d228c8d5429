"""The defaults registry (`appdyn.config`): argument > registry > fallback, set/reset, the
context manager, and the jobs reading it."""
import doctest
import inspect

import pytest

from appdyn import config, ocp
from appdyn.problems.slew.scene_slew import default_N

from .ocp.reference import min_energy


@pytest.fixture(autouse=True)
def _fresh_defaults():
    config.reset_defaults()
    yield
    config.reset_defaults()


def test_docstring_examples():
    result = doctest.testmod(config, optionflags=doctest.ELLIPSIS)
    assert result.attempted >= 8 and result.failed == 0


def test_argument_beats_registry_beats_fallback():
    assert config.param("ocp.N", 7) == 7
    assert config.param("ocp.N") == 20
    assert config.param("ocp.nothing") is None
    assert config.param("ocp.nothing", None, 3) == 3
    assert config.param("ocp.N", 0) == 0  # only None means "not given"


def test_set_reset_and_using_restore_even_on_error():
    config.set_defaults("problems", N=60, slew_N=12)
    assert (config.param("problems.N"), default_N("time")) == (60, 12)
    with pytest.raises(RuntimeError):
        with config.using("problems", N=8):
            assert config.param("problems.N") == 8
            raise RuntimeError
    assert config.param("problems.N") == 60
    config.reset_defaults()
    assert (config.param("problems.N"), default_N("time"), default_N("effort")) == (40, 30, 20)


def test_a_dict_default_is_handed_out_as_a_copy():
    strict = config.param("ocp.ipopt_strict")
    strict["tol"] = 1.0
    assert config.param("ocp.ipopt_strict") == {"tol": 1e-10, "bound_relax_factor": 0.0,
                                                 "max_iter": 3000}


@pytest.mark.parametrize("call, error", [
    (lambda: config.set_defaults("ocp", n=3), KeyError),
    (lambda: config.using("ocp", M=3).__enter__(), KeyError),
    (lambda: config.set_defaults("", N=3), TypeError),
])
def test_unknown_names_are_refused_naming_the_registered_ones(call, error):
    with pytest.raises(error, match="ocp.N|package"):
        call()


def test_ocp_solve_reads_its_default_interval_count():
    """`ocp.solve` without ``N`` or ``mesh`` uses ``ocp.N``; the Bryson-Ho optimum J = 6."""
    problem, truth = min_energy()
    with config.using("ocp", N=6):
        sol = ocp.solve(problem)
    assert sol.success and sol.mesh.N == 6
    assert abs(sol.cost - truth["J"]) < 1e-6 * truth["J"]  # a cubic: exact on any mesh
    assert ocp.solve(problem).mesh.N == 20


def test_the_jobs_leave_their_interval_count_to_the_registry():
    from appdyn.problems.ascent.planar import planar_ascent
    from appdyn.problems.gains import attitude_gains, launch_vehicle_gains, state_feedback_gains
    from appdyn.problems.slew.devices import cmg_slew, wheel_slew
    from appdyn.problems.slew.maneuvers import min_effort, time_optimal
    for fn in (planar_ascent, attitude_gains, launch_vehicle_gains, state_feedback_gains,
               cmg_slew, wheel_slew, min_effort, time_optimal):
        assert inspect.signature(fn).parameters["N"].default is None, fn.__name__
