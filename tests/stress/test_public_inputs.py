"""Every public function refuses garbage cleanly (DESIGN.md, errors).

The public functions (``inspect.isfunction``) in ``__all__`` of the packages below are
enumerated at collection time. For every required parameter of each function, the function
is called with that parameter set to a garbage value (``"x"``, ``None``, NaN, ``object()``,
a wrong-shape array) and every other required parameter set to a valid example value from
the table ``VALID`` (built lazily, some need a cheap solve or simulation). The call must
raise ``TypeError`` or ``ValueError`` (subclasses count): never another exception type and
never a silent result. A returned result whose ``success`` is False with a message is
accepted (numerical drivers); such cases are reported through ``GarbageAcceptedWarning``.
A refusal whose message does not name the parameter fails (it was a warning until the
last 40 such messages were fixed). ``test_valid_examples`` checks that the example
values are accepted (functions that would solve an NLP excepted), so that each refusal is
caused by its garbage.

Library bugs found are marked ``xfail(strict=True)`` in ``KNOWN_BUGS``.
"""
from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

from .public_api import _NO_VALID, EXPENSIVE, EXTRA, FUNCTIONS, _required, _valid

class GarbageAcceptedWarning(UserWarning):
    """Garbage answered by a result object with ``success=False`` (allowed, reported)."""


# --------------------------------------------------------------------------------------------
# garbage
# --------------------------------------------------------------------------------------------

GARBAGE = {
    "str": lambda: "x",
    "none": lambda: None,
    "nan": lambda: float("nan"),
    "object": lambda: object(),
    "cube": lambda: np.zeros((7, 7, 7)),
}

# (function, parameter) -> {garbage id: reason it is a legitimate input}
ALLOWED_GARBAGE = {
    ("appdyn.dynamics.launch_vehicle.rigid_part", "slosh"): {"none": "documented `Slosh or None`"},
    ("appdyn.problems.ascent.vertical_rise", "vehicle"): {"none": "documented `AscentVehicle or None`"},
    ("appdyn.problems.ascent.pitch_model", "vehicle"): {"none": "documented `AscentVehicle or None`"},
    ("appdyn.ocp.status_code", "name"): {"str": "a name not in the table is the documented "
                                                 "code -201 (Unknown): IPOPT may add statuses"},
    ("appdyn.ocp.check_ipopt_options", "options"): {"none": "documented `mapping ... or None`"},
    ("appdyn.problems.dispersion.dispersion", "seed"): {"none": "documented `int or None` (fresh entropy)"},
    ("appdyn.problems.dispersion.statistics", "values"): {
        "cube": "documented shape (m, ...): a (7, 7, 7) array is valid"},
    ("appdyn.problems.dispersion.draw_samples", "seed"): {
        "none": "fresh entropy, as `dispersion(seed=None)` documents"},
}
# elementwise closed forms with no documented shape: any array broadcasts
for _func, _params in {
    "appdyn.dynamics.mechanisms.bead_motion": ("t", "r0", "r0_dot", "rate"),
    "appdyn.dynamics.mechanisms.bead_torque": ("r", "r_dot", "rate", "rate_dot"),
    "appdyn.dynamics.mechanisms.rod_reaction": ("theta", "theta_dot"),
    "appdyn.dynamics.mechanisms.turntable_path": ("t",),
    "appdyn.dynamics.mechanisms.foucault_swing": ("t",),
    "appdyn.dynamics.mechanisms.skater_rate": ("t",),
}.items():
    for _param in _params:
        ALLOWED_GARBAGE.setdefault((_func, _param), {})["cube"] = (
            "elementwise, shape not documented: arrays broadcast")


# --------------------------------------------------------------------------------------------
# functions not exercised
# --------------------------------------------------------------------------------------------

SKIPPED = {
    "appdyn.dynamics.clear_caches": "no required parameter",
    "appdyn.dynamics.attitude.dcm_axis": "no required parameter",
    "appdyn.dynamics.mechanisms.double_pendulum": "no required parameter",
    "appdyn.dynamics.mechanisms.accelerometer": "no required parameter",
    "appdyn.ocp.ipopt_option_table": "no required parameter",
    "appdyn.dynamics.mechanisms.accelerometer_offset": "no required parameter",
    "appdyn.dynamics.mechanisms.foucault_pendulum": "no required parameter",
    "appdyn.dynamics.mechanisms.noninertial_particle": "no required parameter",
    "appdyn.dynamics.mechanisms.turntable": "no required parameter",
    "appdyn.dynamics.mechanisms.twirling_skater": "no required parameter",
    "appdyn.dynamics.mechanisms.double_pendulum_modes": "no required parameter",
    "appdyn.dynamics.mechanisms.dumbbell_disk": "no required parameter",
    "appdyn.dynamics.mechanisms.dumbbell_disk_frequency": "no required parameter",
    "appdyn.dynamics.mechanisms.equivalent_length": "no required parameter",
    "appdyn.dynamics.mechanisms.natural_frequency": "no required parameter",
    "appdyn.dynamics.mechanisms.rod_pendulum": "no required parameter",
    "appdyn.dynamics.mechanisms.rolling_coin": "no required parameter",
    "appdyn.dynamics.mechanisms.rolling_sphere": "no required parameter",
    "appdyn.dynamics.mechanisms.shaken_pendulum": "no required parameter",
    "appdyn.dynamics.mechanisms.shaken_pendulum_multipliers": "no required parameter",
    "appdyn.dynamics.mechanisms.sliding_bead": "no required parameter",
    "appdyn.dynamics.mechanisms.variable_length_pendulum": "no required parameter",
    "appdyn.ocp.get_transcription": "no required parameter",
    "appdyn.problems.slew.example_targets": "no required parameter",
    "appdyn.problems.dispersion.nutation_spread": "no required parameter",
    "appdyn.problems.ascent.delta3_ascent": "no required parameter",
    "appdyn.problems.ascent.delta3_problem": "no required parameter",
    "appdyn.problems.ascent.initial_state": "no required parameter",
    "appdyn.problems.ascent.default_gains": "no required parameter",
    "appdyn.problems.ascent.planar_model": "no required parameter",
}

# (function, parameter, garbage) -> reason: known library bugs, strict xfail
KNOWN_BUGS: dict[tuple[str, str, str], str] = {}
ALL = tuple(GARBAGE)


def _bug(func, params, gids, reason):
    for param in params:
        for gid in gids:
            KNOWN_BUGS[(func, param, gid)] = reason


# (function, parameter, garbage) -> reason: cases skipped (too expensive / undetectable)
SKIPPED_CASES: dict[tuple[str, str, str], str] = {}


def _cases():
    cases = []
    for func, fn in sorted(FUNCTIONS.items()):
        if func in SKIPPED:
            continue
        for param in _required(fn):
            allowed = ALLOWED_GARBAGE.get((func, param), {})
            for gid in GARBAGE:
                if gid in allowed:
                    continue
                marks = []
                key = (func, param, gid)
                if key in KNOWN_BUGS:
                    marks.append(pytest.mark.xfail(strict=True, reason=KNOWN_BUGS[key]))
                if key in SKIPPED_CASES:
                    marks.append(pytest.mark.skip(reason=SKIPPED_CASES[key]))
                cases.append(pytest.param(func, param, gid, marks=marks,
                                          id=f"{func}-{param}-{gid}"))
    return cases


CASES = _cases()


def test_enumeration_is_covered():
    """Every enumerated function is exercised or skipped with a reason; no stale entries."""
    assert len(FUNCTIONS) >= 150
    exercised = {c.values[0] for c in CASES}
    for func, fn in FUNCTIONS.items():
        assert (func in exercised) != (func in SKIPPED), func
        if func in SKIPPED and SKIPPED[func] == "no required parameter":
            assert not _required(fn), func
    assert set(SKIPPED) <= set(FUNCTIONS)
    for table in (KNOWN_BUGS, SKIPPED_CASES):
        for func, param, gid in table:
            assert func in FUNCTIONS and param in _required(FUNCTIONS[func]) and gid in GARBAGE


def _names(message, param):
    """Whether ``message`` names ``param``: quoted, or as a whole word when 3+ letters long."""
    quoted = any(f"{a}{param}{b}" in message for a, b in ("``", "''", '""', "` ", "'`"))
    quoted = quoted or re.search(rf"(?<![\w.]){re.escape(param)}\s*(=|\[|must|should)",
                                 message) is not None
    return quoted or (len(param) >= 3 and re.search(rf"\b{re.escape(param)}\b", message))


VALID_CHECKED = sorted(
    func for func, fn in FUNCTIONS.items()
    if func not in SKIPPED and func not in EXPENSIVE and len(_required(fn)) >= 2)


#: the examples that take seconds (measured > 5 s on a loaded machine): marked slow
SLOW_EXAMPLES = {"appdyn.dynamics.momentum.steer", "appdyn.problems.dispersion.nutation_history",
                 "appdyn.problems.slew.bounded", "appdyn.problems.stability.launch_vehicle_response",
                 "appdyn.problems.stability.shaken_pendulum"}


@pytest.mark.parametrize("func", [pytest.param(f, marks=pytest.mark.slow) if f in SLOW_EXAMPLES
                                  else f for f in VALID_CHECKED])
def test_valid_examples(func):
    """The example values are accepted, so each garbage case is refused for its garbage."""
    fn = FUNCTIONS[func]
    kwargs = EXTRA[func]() if func in EXTRA else {}
    for name in _required(fn):
        value = _valid(func, name)
        assert value is not _NO_VALID, f"no valid example for {func}({name})"
        kwargs[name] = value
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fn(**kwargs)


@pytest.mark.parametrize("func, param, gid", CASES)
def test_garbage_is_refused(func, param, gid):
    fn = FUNCTIONS[func]
    kwargs = EXTRA[func]() if func in EXTRA else {}
    for name in _required(fn):
        if name == param:
            kwargs[name] = GARBAGE[gid]()
        else:
            value = _valid(func, name)
            kwargs[name] = GARBAGE[gid]() if value is _NO_VALID else value
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            result = fn(**kwargs)
    except (TypeError, ValueError) as exc:
        message = str(exc)
        assert _names(message, param), (  # DESIGN.md: the error names the argument
            f"{func}({param}={gid}): {type(exc).__name__} does not name `{param}`: "
            f"{message[:200]}")
        return
    except Exception as exc:  # noqa: BLE001 -- the point of the test
        pytest.fail(f"{func}({param}={gid}) raised {type(exc).__name__}, "
                    f"not TypeError/ValueError: {exc}")
    success = getattr(result, "success", None)
    if success is False and getattr(result, "message", None):
        warnings.warn(f"{func}({param}={gid}) returned success=False: {result.message}",
                      GarbageAcceptedWarning, stacklevel=1)
        return
    pytest.fail(f"{func}({param}={gid}) returned {type(result).__name__} silently")
