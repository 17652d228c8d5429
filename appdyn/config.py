"""The package's defaults: one registry of named values (python-control's ``config`` style).

Every option a function leaves unset (``None``) is read here at call time, so a default is
written once and can be changed for a whole session or a block of code: the argument wins,
then the registry, then the fallback the caller names (`param`).

``defaults``
    The registry: a dict ``"<package>.<name>" -> value`` (read it; change it with
    `set_defaults` or `using`).
``set_defaults(package, **values)``
    Change registered defaults (an unknown name is a ``KeyError``).
``reset_defaults()``
    Back to the values below.
``using(package, **values)``
    Context manager: the defaults changed inside the block, restored after (even on an
    error). Process-wide, like `set_defaults`: threads see the change too.
``param(key, value=None, fallback=None)``
    ``value`` if not None, else ``defaults[key]`` (``fallback`` when ``key`` is not
    registered).

The registered values:

``ocp.N`` = 20
    Collocation intervals of `appdyn.ocp.solve` without a mesh.
``ocp.ipopt_strict`` = ``{'tol': 1e-10, 'bound_relax_factor': 0.0, 'max_iter': 3000}``
    IPOPT options of the polish and switch-time NLPs (`appdyn.ocp.refine`).
``problems.N`` = 40
    Collocation intervals of the ready-made designs: `appdyn.problems.gains.attitude_gains`,
    `appdyn.problems.gains.launch_vehicle_gains`, the planar ascent.
``problems.slew_N`` = 30
    First-solve intervals of the time-optimal slews (``time_optimal``, ``wheel_slew``,
    ``cmg_slew``, ``slew(objective='time')``).
``problems.effort_N`` = 20
    First-mesh intervals of the minimum-effort slews (``min_effort``,
    ``slew(objective='effort')``).
``problems.feedback_N`` = 80
    Intervals of `appdyn.problems.gains.state_feedback_gains` (its match of the Riccati
    gains needs the finer mesh).
``dynamics.threads`` = None
    Threads over which the runs of a batched `appdyn.dynamics.simulate` (``x0`` of shape
    ``(nx, K)``; also `appdyn.problems.dispersion` with ``batch=True``) are spread: None is
    the cores this process may use (``os.sched_getaffinity``), ``1`` the calling thread
    alone. The answers are the same bits for every value.

Why several ``N``: a job's interval count is set by what it must resolve (a bang-bang
switch, a smooth effort profile, an 80-interval match of a Riccati solution); the jobs that
resolve the same kind of answer share one key.

Examples
--------
>>> from appdyn import config
>>> config.defaults["ocp.N"]
20
>>> config.param("ocp.N", 50), config.param("ocp.N")
(50, 20)
>>> with config.using("ocp", N=35):
...     config.param("ocp.N")
35
>>> config.param("ocp.N")
20
"""
from __future__ import annotations

import contextlib
import copy
import threading
from typing import Any, Iterator

__all__ = ["defaults", "set_defaults", "reset_defaults", "using", "param"]

_INITIAL: dict[str, Any] = {
    "ocp.N": 20,
    "ocp.ipopt_strict": {"tol": 1e-10, "bound_relax_factor": 0.0, "max_iter": 3000},
    "problems.N": 40,
    "problems.slew_N": 30,
    "problems.effort_N": 20,
    "problems.feedback_N": 80,
    "dynamics.threads": None,
}

#: the registry (``"<package>.<name>" -> value``)
defaults: dict[str, Any] = copy.deepcopy(_INITIAL)
_LOCK = threading.Lock()


def _keys(package: str, values: dict) -> dict:
    if not isinstance(package, str) or not package:
        raise TypeError(f"`package` must be a non-empty string such as 'ocp', got {package!r}")
    out = {f"{package}.{name}": value for name, value in values.items()}
    unknown = sorted(set(out) - set(defaults))
    if unknown:
        raise KeyError(f"no registered default {unknown}; registered: {sorted(defaults)}")
    return out


def set_defaults(package: str, **values) -> None:
    """Change registered defaults of ``package`` (``set_defaults('ocp', N=30)``).

    Raises ``KeyError`` naming an unregistered key, and the registered ones.

    Examples
    --------
    >>> from appdyn import config
    >>> config.set_defaults("problems", slew_N=45)
    >>> config.param("problems.slew_N")
    45
    >>> config.reset_defaults()
    """
    new = _keys(package, values)
    with _LOCK:
        defaults.update(new)


def reset_defaults() -> None:
    """Restore every registered default to its value in this module.

    Examples
    --------
    >>> from appdyn import config
    >>> config.set_defaults("ocp", N=99)
    >>> config.reset_defaults()
    >>> config.defaults["ocp.N"]
    20
    """
    with _LOCK:
        defaults.clear()
        defaults.update(copy.deepcopy(_INITIAL))


@contextlib.contextmanager
def using(package: str, **values) -> Iterator[None]:
    """Context manager: ``package``'s defaults set to ``values`` inside the block.

    Examples
    --------
    >>> from appdyn import config
    >>> with config.using("problems", N=60):
    ...     config.param("problems.N")
    60
    """
    new = _keys(package, values)
    with _LOCK:
        saved = {key: defaults[key] for key in new}
        defaults.update(new)
    try:
        yield
    finally:
        with _LOCK:
            defaults.update(saved)


def param(key: str, value: Any = None, fallback: Any = None) -> Any:
    """The value of an option: the argument, else the registry's, else the fallback.

    ``value`` if not None, else ``defaults[key]``, else ``fallback``. A dict default is returned as a copy (the caller may change it).

    Examples
    --------
    >>> from appdyn.config import param
    >>> param("problems.slew_N"), param("problems.slew_N", 12), param("no.such", None, 7)
    (30, 12, 7)
    """
    if value is not None:
        return value
    out = defaults.get(key, fallback)
    return dict(out) if isinstance(out, dict) else out
