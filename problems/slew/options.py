"""`SlewOptions`: every setting of a `slew` in one typed, validated, immutable object.

One options object instead of twenty keywords (acados' ``AcadosOcpOptions``): the fields and
their defaults are written once, here; `slew` takes ``options=SlewOptions(...)`` or the same
fields as keywords (``slew(scene, ..., N=40, starts=2)``), and an unknown keyword is a
``TypeError`` that names it and lists the fields (`with_fields`).
"""
from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

from appdyn.dynamics.validate import integer, one_of, positive, unit_quaternion
from appdyn.ocp import CONTROLS, TRANSCRIPTIONS

from .targets import MIN_REFINE_TOL, POINTING_TOL, RATE_TOL, KeepOut

__all__ = ["SlewOptions", "with_fields"]


@dataclass(frozen=True)
class SlewOptions:
    """How a `slew` is solved and graded (the *what* -- scene, objective, target, ``T``,
    end rates -- are `slew`'s own arguments).

    Every field is checked on creation; a bad value is a ``TypeError`` or ``ValueError``
    naming the field. ``None`` means "the engine's default" where said.

    Parameters
    ----------
    N : int, optional
        Collocation intervals of the first solve (default: 30 time-optimal, 20 minimum
        effort, 30 by the device engines; on the generic path more where a part oscillates:
        `scene_slew.scene_intervals`).
    starts : int, optional
        Seeded starts (the eigenaxis SLERP and tilted SLERPs) of a time-optimal slew without
        a ``guess`` (default 3), or of a minimum-effort slew with a ``keep_out`` cone
        (default 4).
    seed : int, optional
        Seed of the tilt axes of the starts (default 0: reproducible).
    tol : float
        Mesh-refinement target of a minimum-effort slew (`ocp.refine`), at least
        `MIN_REFINE_TOL` (default 1e-7).
    pointing_tol : float [rad]
        Largest re-simulated final attitude error of a success (default `POINTING_TOL`).
    rate_tol : float [rad/s]
        Largest re-simulated error of the fixed final rates and part states of a success
        (default `RATE_TOL`).
    T_max : float [s], optional
        Upper bound of the final time of a time-optimal slew (default 20 times a rough
        bang-bang time).
    q0 : array_like, shape (4,), optional
        Initial attitude, scalar-last (default identity); stored as a tuple.
    keep_out : KeepOut, optional
        A keep-out cone held along the whole slew.
    norm_bound : bool
        Bound ``|L| <= u_max`` instead of per axis (a hub with one `ExternalTorque` only).
    polish : bool, optional
        Polish the switch times of a bang-bang time-optimal result (default: where it
        applies; `time_optimal`).
    transcription : str
        Of the first solve (one of ``ocp.TRANSCRIPTIONS``; default ``'radau'``).
    control : {'constant', 'linear', 'polynomial'}
        The control of a time-optimal result that must be re-solved to keep its bounds
        between the nodes (`bounded`; default ``'constant'``).
    verbose : bool or callable
        IPOPT's progress to stderr (True) or to a callable (default False).
    ipopt_options : mapping, optional
        Extra IPOPT options (stored read-only).
    guess : ocp.Solution or mapping, optional
        A user guess: a single start is solved.
    state0 : mapping, optional
        Initial part states by block, as `dynamics.scene.Scene.state` takes them
        (``{"wheels": [10.0, 0.0, 0.0]}``); every block not given at rest. Stored read-only.
    min_measure : float [(N m s)^3], optional
        Lower bound of a CMG cluster's singularity measure along the slew (`cmg_slew`).

    Raises
    ------
    TypeError, ValueError
        Naming the field and what was expected.

    Examples
    --------
    >>> from appdyn.problems.slew import SlewOptions
    >>> opts = SlewOptions(N=40, starts=2)
    >>> opts.N, opts.starts, opts.tol, opts.transcription
    (40, 2, 1e-07, 'radau')
    >>> SlewOptions(N=0)
    Traceback (most recent call last):
        ...
    ValueError: `N` must be an integer >= 1, got 0
    """

    N: int | None = None
    starts: int | None = None
    seed: int | None = None
    tol: float = 1e-7
    pointing_tol: float = POINTING_TOL
    rate_tol: float = RATE_TOL
    T_max: float | None = None
    q0: tuple | None = None
    keep_out: KeepOut | None = None
    norm_bound: bool = False
    polish: bool | None = None
    transcription: str = "radau"
    control: str = "constant"
    verbose: object = False
    ipopt_options: Mapping | None = None
    guess: object = None
    state0: Mapping | None = None
    min_measure: float | None = None

    def __post_init__(self):
        put = lambda name, value: object.__setattr__(self, name, value)  # noqa: E731
        for name in ("N", "starts"):
            if getattr(self, name) is not None:
                put(name, integer(getattr(self, name), name, minimum=1))
        if self.seed is not None:
            put("seed", integer(self.seed, "seed", minimum=0))
        for name in ("tol", "pointing_tol", "rate_tol"):
            put(name, positive(getattr(self, name), name))
        if self.tol < MIN_REFINE_TOL:
            raise ValueError(f"`tol` must be at least {MIN_REFINE_TOL:g} (what the "
                             f"re-integration reference resolves), got {self.tol:g}")
        for name in ("T_max", "min_measure"):
            if getattr(self, name) is not None:
                put(name, positive(getattr(self, name), name))
        if self.q0 is not None:
            put("q0", tuple(unit_quaternion(self.q0, "q0").tolist()))
        if self.keep_out is not None and not isinstance(self.keep_out, KeepOut):
            raise TypeError(f"`keep_out` must be a KeepOut, got {type(self.keep_out).__name__}")
        for name in ("norm_bound",) + (() if self.polish is None else ("polish",)):
            if not isinstance(getattr(self, name), bool):
                raise TypeError(f"`{name}` must be True or False, got "
                                f"{type(getattr(self, name)).__name__}")
        put("transcription", one_of(self.transcription, "transcription", TRANSCRIPTIONS))
        put("control", one_of(self.control, "control", CONTROLS))
        if not (isinstance(self.verbose, bool) or callable(self.verbose)):
            raise TypeError(f"`verbose` must be True, False or a callable, got "
                            f"{type(self.verbose).__name__}")
        for name in ("ipopt_options", "state0"):
            value = getattr(self, name)
            if value is None:
                continue
            if not isinstance(value, Mapping) or not all(isinstance(k, str) for k in value):
                raise TypeError(f"`{name}` must be a mapping with str keys, got "
                                f"{type(value).__name__}")
            put(name, MappingProxyType(dict(value)))

    __hash__ = None  # mappings and a user guess inside: compared, never hashed


def _field_names() -> tuple:
    return tuple(f.name for f in dataclasses.fields(SlewOptions))


def with_fields(options, given: Mapping, *, name: str = "slew") -> SlewOptions:
    """``options`` (a `SlewOptions`, or None for the defaults) with the fields in ``given``
    replaced.

    Parameters
    ----------
    options : SlewOptions or None
    given : mapping of str to object
        Field values, as keywords of ``name``.
    name : str
        The function the keywords were given to (for the message).

    Returns
    -------
    SlewOptions

    Raises
    ------
    TypeError
        If ``options`` is not a `SlewOptions`, or a key of ``given`` is not a field (the
        message names it and lists the fields).
    ValueError
        A bad field value (naming the field).

    Examples
    --------
    >>> from appdyn.problems.slew.options import SlewOptions, with_fields
    >>> with_fields(SlewOptions(N=40), {"starts": 2}).N
    40
    >>> with_fields(None, {"Nn": 40})
    Traceback (most recent call last):
        ...
    TypeError: slew() got an unexpected keyword argument 'Nn'; the options are N, starts, seed, ...
    """
    if options is None:
        options = SlewOptions()
    elif not isinstance(options, SlewOptions):
        raise TypeError(f"`options` must be a SlewOptions, got {type(options).__name__}")
    fields = _field_names()
    unknown = [k for k in given if k not in fields]
    if unknown:
        raise TypeError(f"{name}() got an unexpected keyword argument {unknown[0]!r}; the "
                        f"options are {', '.join(fields)}")
    return dataclasses.replace(options, **given) if given else options
