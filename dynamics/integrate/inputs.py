"""Normalisation of `simulate`'s inputs (``t``, ``x0``, ``u``, tolerances, options) into a
`Problem`; every check raises naming the argument (``TypeError`` wrong type, ``ValueError``
wrong value)."""
from __future__ import annotations

import contextlib
import difflib
import io
import math
import re
from dataclasses import dataclass
from typing import Callable, Mapping

import casadi as ca
import numpy as np

from .. import cache
from ..model import Model
from ..validate import (QUAT_NORM_TOL, check_unit_quaternion, finite_array, finite_scalar,
                        unit_quaternion)

__all__ = ["HOLDS", "RTOL_MIN", "Batch", "Control", "Problem", "RunOptions", "check_batch",
           "check_t", "check_x0", "check_tolerances",
           "check_u", "check_invariants", "check_cvodes_options"]

_EPS = np.finfo(float).eps
#: The least ``rtol`` taken (100 ulps of 1).
RTOL_MIN = 100 * _EPS


@dataclass(frozen=True)
class RunOptions:
    """The run options of one `simulate` call, carried as one object through its internal
    runs (instead of a long positional list).

    Attributes
    ----------
    method : str
        One of `simulate`'s methods.
    rtol : float
        Relative tolerance.
    atol : float or numpy.ndarray
        Absolute tolerance, scalar or ``(nx,)`` (checked: ``(nx,)``).
    steps : int or None
        Substeps per output interval of a fixed-step method.
    jit : bool or None
        Compile the kernels (None: when worth it).
    max_steps : int
        Step budget of the adaptive runs.
    cvodes_options : Mapping or None
        Extra options of cvodes.
    progress : callable or None
        ``progress(done, total)`` (checked: a ``Progress``).
    threads : int or None
        Threads of a batch (None: `batch_fixed.batch_threads`' default).

    Examples
    --------
    >>> from appdyn.dynamics.integrate.inputs import RunOptions
    >>> opts = RunOptions(method="rk4", rtol=1e-8, atol=1e-10, steps=10, jit=False,
    ...                   max_steps=1000, cvodes_options=None, progress=None)
    >>> opts.method, opts.steps
    ('rk4', 10)
    """

    method: str
    rtol: float
    atol: float | np.ndarray
    steps: int | None
    jit: bool | None
    max_steps: int
    cvodes_options: Mapping | None
    progress: Callable | None
    threads: int | None = None

    def keywords(self) -> dict:
        """The options as `simulate`'s keyword arguments (``simulate(..., **o.keywords())``).

        Examples
        --------
        >>> from appdyn.dynamics.integrate.inputs import RunOptions
        >>> RunOptions(method="rk4", rtol=1e-8, atol=1e-10, steps=10, jit=False,
        ...            max_steps=1000, cvodes_options=None, progress=None).keywords()["steps"]
        10
        """
        return dict(self.__dict__)


#: numpy's float64 dtype object (native byte order): an array's ``dtype is _FLOAT64`` is the
#: cheap test of the fast paths (another float64 dtype object takes the general path).
_FLOAT64 = np.dtype(np.float64)


def check_t(t) -> np.ndarray:
    """The output grid: 1-D, at least 2 finite times, strictly increasing (read-only copy)."""
    tp = type(t)
    if tp is np.ndarray:  # fast path: a short float64 grid that passes every check
        if t.dtype is _FLOAT64 and t.ndim == 1 and 2 <= t.size <= 16:
            v = t.tolist()
            if _finite_increasing(v):
                t = t.copy()
                t.setflags(False)  # (read-only; positional: a third of the keyword's cost)
                return t
    elif (tp is list or tp is tuple) and 2 <= len(t) <= 16 and all(
            type(e) is float for e in t) and _finite_increasing(t):
        t = np.array(t)
        t.setflags(False)
        return t
    t = np.array(finite_array(t, "t"), dtype=float)
    if t.ndim != 1 or t.size < 2:
        raise ValueError(f"`t` must be a 1-D grid of at least 2 times, got shape {t.shape}")
    if not _increasing(t):
        dt = t[1:] - t[:-1]
        k = int(np.argmin(dt))
        raise ValueError(
            f"`t` must be strictly increasing, got t[{k}] = {t[k]} >= t[{k + 1}] = {t[k + 1]}"
        )
    t.setflags(write=False)
    return t


def handed_t(t) -> np.ndarray | None:
    """The grid of `simulate`'s common call, handed to the compiled pass unchecked: a
    read-only float64 copy of a 1-D ``t`` of at least 2 real times (an ndarray, or a list
    or tuple numpy makes one of; integers converted, as `check_t` converts them); None for
    any other ``t`` (`check_t` decides). Whether it is finite and strictly increasing the
    pass looks, in its first loop over the times (`dense.dense_run` returns None for a
    grid `check_t` refuses): in Python that took a third of the call's time on 121
    outputs."""
    tp = type(t)
    if tp is not np.ndarray:
        if tp is not list and tp is not tuple:
            return None
        try:
            t = np.array(t)
        except Exception:  # noqa: BLE001 - `check_t` words the error
            return None
    elif t.dtype is _FLOAT64:
        t = t.copy()
    if t.dtype is not _FLOAT64:
        if t.dtype.kind not in "iu":
            return None
        t = t.astype(np.float64)  # (exact to 2**53 s, as `check_t`'s conversion)
    if t.ndim != 1 or t.size < 2:
        return None
    t.setflags(False)  # (read-only; positional: a third of the keyword's cost)
    return t


def _finite_increasing(v) -> bool:
    """Whether the floats ``v`` are finite and strictly increasing (finite ends and ``<``
    between neighbours: a NaN anywhere fails the comparisons)."""
    return (math.isfinite(v[0]) and math.isfinite(v[-1])
            and all(map(float.__lt__, v[:-1], v[1:])))


def _increasing(t: np.ndarray) -> bool:
    """Whether the finite 1-D ``t`` is strictly increasing (a short one compared in Python,
    without numpy's per-call overhead)."""
    if t.size <= 16:
        v = t.tolist()
        return all(map(float.__lt__, v[:-1], v[1:]))
    return bool((t[1:] > t[:-1]).all())


def check_x0(x0, model: Model) -> np.ndarray:
    """The initial state, shape (nx,) (a copy); its attitude quaternion of unit norm."""
    x = fast_x0(x0, model)
    if x is not None:
        return x
    nx = model.nx
    x = finite_array(x0, "x0")
    if x.shape not in ((nx,), (nx, 1)):
        raise ValueError(f"`x0` must have shape ({nx},), got {x.shape}")
    x = np.array(x, dtype=float).reshape(nx)
    if model.attitude is not None:
        iq = model.attitude[0]
        check_unit_quaternion(x[iq:iq + 4], f"x0[{iq}:{iq + 4}] (the attitude quaternion)")
    return x


def fast_x0(x0, model: Model) -> np.ndarray | None:
    """`check_x0` of a common ``x0`` that passes every check (a list, tuple or ndarray of
    ``nx`` real numbers, finite, its quaternion of unit norm): the same array, at about a
    third of the cost; ``None`` for anything else (`check_x0` then decides and words the
    error). Its shape ``(nx,)`` also tells that ``x0`` is no batch."""
    tp = type(x0)
    if tp is np.ndarray:
        a = x0
    elif tp is list or tp is tuple:
        try:
            a = np.asarray(x0)  # as `real_array` converts it; a new array
        except Exception:  # noqa: BLE001 - the general path words the error
            return None
    else:
        return None
    if a.shape != (model.nx,) or a.dtype.kind not in "fiu":
        return None
    if a.dtype is _FLOAT64:  # (the common dtype object: a cheaper test than ``==``)
        x = a if a is not x0 else a.copy()  # (made here from a list: already the copy)
    else:
        x = np.array(a, dtype=float)
    v = x.tolist()
    if not math.isfinite(sum(v)):  # an inf or NaN makes the sum inf or NaN (an overflow of
        return None               # the sum alone only sends x0 to the general path)
    if model.attitude is not None:  # `check_unit_quaternion`'s test, on the same floats
        iq = model.attitude[0]
        q1, q2, q3, q4 = v[iq:iq + 4]
        if not abs(q1 * q1 + q2 * q2 + q3 * q3 + q4 * q4 - 1.0) <= QUAT_NORM_TOL - 1e-15:
            return None
    return x


def check_cvodes_options(options) -> dict:
    """``cvodes_options`` as a dict, each key and value checked by building a one-state
    cvodes integrator with them (cached): a ``ValueError`` names the bad option."""
    if options is None:
        return {}
    if not isinstance(options, Mapping):
        raise TypeError(f"`cvodes_options` must be a mapping, got {type(options).__name__}")
    options = dict(options)
    bad = [k for k in options if not isinstance(k, str)]
    if bad:
        raise TypeError(f"`cvodes_options` keys must be strings, got {bad[0]!r}")
    key = ("cvodes-options", repr(sorted(options.items(), key=str)))
    if not cache.contains(key):
        cache.get(key, lambda: _try_cvodes_options(options))
    return options


def _try_cvodes_options(options: dict) -> bool:
    x = ca.SX.sym("x")
    try:
        ca.integrator("check", "cvodes", {"x": x, "ode": -x}, 0.0, [1.0], options)
    except RuntimeError as exc:
        text = [line.strip() for line in str(exc).strip().splitlines() if line.strip()]
        unknown = [k for k in options if k not in _cvodes_option_names()]
        if unknown:
            close = difflib.get_close_matches(unknown[0], _cvodes_option_names(), n=3)
            hint = f"; did you mean {', '.join(map(repr, close))}?" if close else ""
            raise ValueError(f"`cvodes_options` has an unknown option {unknown[0]!r}{hint} "
                             "(see casadi's integrator documentation for 'cvodes')") from None
        raise ValueError(f"`cvodes_options` has a bad value: {text[-1] if text else exc}") from None
    return True


@cache.memoize
def _cvodes_option_names() -> frozenset:
    """Names of the options casadi's cvodes integrator takes (parsed from print_options)."""
    x = ca.SX.sym("x")
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        ca.integrator("names", "cvodes", {"x": x, "ode": -x}, 0.0, [1.0], {}).print_options()
    return frozenset(re.findall(r'^> "([^"]+)"', buf.getvalue(), flags=re.M))


def check_tolerances(rtol, atol, nx: int) -> tuple[float, np.ndarray]:
    """``rtol`` in ``[100 eps, 1)``; ``atol`` a scalar or (nx,), finite and >= 0 -> (nx,)."""
    if (type(rtol) is float and type(atol) is float and RTOL_MIN <= rtol < 1
            and 0 <= atol < math.inf):  # fast path: the common case, every check passed
        a = np.empty(nx)  # (`numpy.full` costs twice as much)
        a.fill(atol)
        return rtol, a
    rtol_f = finite_scalar(rtol, "rtol")
    if not RTOL_MIN <= rtol_f < 1:
        raise ValueError(f"`rtol` must be in [{RTOL_MIN:.3g}, 1), got {rtol!r}")
    if type(atol) is float and 0 <= atol < math.inf:  # fast path: the common case
        return rtol_f, np.full(nx, atol)
    if type(atol) is np.ndarray and atol.dtype is _FLOAT64 and atol.shape == (nx,):
        a = atol.copy()  # fast path: one per state, every check passed (in Python floats)
        if all(0.0 <= v < math.inf for v in a.tolist()):
            return rtol_f, a
    a = finite_array(atol, "atol")
    if a.shape not in ((), (nx,)):
        raise ValueError(f"`atol` must be a scalar or have shape ({nx},), got {a.shape}")
    if not (a >= 0).all():
        raise ValueError(f"`atol` must be non-negative, got {atol!r}")
    a = np.full(nx, float(a)) if a.ndim == 0 else np.array(a, dtype=float)
    return rtol_f, a


@dataclass(frozen=True)
class Control:
    """The control input, normalized.

    ``mode == "linear"``: ``ua[k], ub[k]`` (shape (nint, nu)) are the values at the start and
    end of interval ``k``, linear in between (a zero-order hold has ``ub = ua``);
    ``constant`` when known to be one value throughout (``False`` leaves it to be found from
    the values); ``tail (nu,)`` the sample at ``t[-1]`` when it is not ``ub[-1]`` (a
    zero-order hold: the value held after the grid). ``mode == "stages"``: ``fun(t) ->
    (nu,)`` is called at stage times.
    """

    mode: str
    ua: np.ndarray | None = None
    ub: np.ndarray | None = None
    fun: Callable | None = None
    constant: bool = False
    tail: np.ndarray | None = None

    def at(self, t: float, k: int, tk: float, H: float) -> np.ndarray:
        if self.mode == "stages":
            return self.fun(t)
        return self.ua[k] + (t - tk) / H * (self.ub[k] - self.ua[k])

    def grid(self, t: np.ndarray) -> np.ndarray:
        """Control on the output grid, shape (nu, n) (at a jump of a zero-order hold: the
        value from the grid time on)."""
        if self.mode == "stages":
            return np.stack([self.fun(ti) for ti in t], axis=1)
        last = self.ub[-1:] if self.tail is None else self.tail[None, :]
        return np.concatenate([self.ua, last], axis=0).T

    def left_grid(self, t: np.ndarray) -> np.ndarray | None:
        """The control's left limits on the output grid, shape (nu, n) (the first column:
        the value at ``t[0]``), where they differ from `grid` (a zero-order hold); else
        None."""
        if self.tail is None:
            return None
        return np.concatenate([self.ua[:1], self.ub], axis=0).T

    def head(self, nint: int) -> "Control":
        """The control of the first ``nint`` intervals."""
        if self.mode == "stages":
            return self
        tail = None if self.tail is None else (
            self.ua[nint] if nint < self.ua.shape[0] else self.tail)
        return Control("linear", self.ua[:nint], self.ub[:nint], constant=self.constant,
                       tail=tail)

    def cvodes_input(self, t: np.ndarray) -> np.ndarray:
        """Piecewise-constant integrator input ``[u_k, slope_k, t_k]``, shape (nint, 2 nu + 1)."""
        if self.mode == "stages":
            return np.zeros((t.size - 1, 0))
        slope = (self.ub - self.ua) / np.diff(t)[:, None]
        return np.concatenate([self.ua, slope, t[:-1, None]], axis=1)


#: How sampled controls are interpolated between samples: linearly, or held (zero order).
HOLDS = ("linear", "zoh")


def _rows(a: np.ndarray, *lead: int) -> np.ndarray:
    """``np.broadcast_to(a, (*lead, a.size))`` of a fresh C-contiguous float64 ``a``: the
    same read-only view, strides 0 but the last, made directly (a tenth of its cost); a
    constant control's rows (``lead`` ``(m,)``: its ``m`` intervals; ``(K, m)``: those of
    ``K`` runs in a batch, nothing allocated per run nor faulted in when read)."""
    if a.size == 0:
        return np.broadcast_to(a, (*lead, 0))
    rows = np.ndarray((*lead, a.size), np.float64, a, 0, (0,) * len(lead) + (a.itemsize,))
    rows.flags.writeable = False
    return rows


def check_u(u, nu: int, t: np.ndarray, *, hold: str = "linear") -> Control:
    """``u`` (see `dynamics.simulate`) as a `Control` on the grid ``t``; ``hold`` how
    samples ``(nu, n)`` are interpolated: ``"linear"``, or ``"zoh"`` (``u[:, k]`` on
    ``[t_k, t_{k+1})``). Raises naming ``u`` or ``hold``."""
    if hold not in HOLDS:
        raise ValueError(f"`hold` must be one of {HOLDS}, got {hold!r}")
    n = t.size
    if u is None:
        z = np.zeros((n - 1, nu))
        return _new(Control, mode="linear", ua=z, ub=z, fun=None, constant=True, tail=None)
    if callable(u):
        if hold != "linear":
            raise ValueError(f"`hold={hold!r}` applies to samples `u` of shape ({nu}, {n}); "
                             "a callable `u` is evaluated where the integrator needs it")
        fun = _checked_callable(u, nu)
        fun(float(t[0]))  # raises ValueError naming `u` on a wrong shape
        if nu == 0:
            z = np.zeros((n - 1, 0))
            return Control("linear", z, z, constant=True)
        return Control("stages", fun=fun)
    try:
        a = np.array(u, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"`u` must be None, a callable or an array of numbers: {exc}") from None
    if a.ndim == 0 and nu == 1:
        a = a.reshape(1)
    if a.shape == (nu,):
        if not all(map(math.isfinite, a.tolist())):  # (floats: a few times numpy's speed)
            raise ValueError(f"`u` must be finite, got {a.tolist()}")
        c = _rows(a, n - 1)
        return _new(Control, mode="linear", ua=c, ub=c, fun=None, constant=True, tail=None)
    if a.shape == (nu, n):
        if not np.all(np.isfinite(a)):
            raise ValueError("`u` must be finite")
        ua = np.ascontiguousarray(a[:, :-1].T)
        if hold == "zoh":
            return Control("linear", ua, ua, tail=a[:, -1].copy())
        return Control("linear", ua, np.ascontiguousarray(a[:, 1:].T))
    raise ValueError(
        f"`u` must be None, a constant of shape ({nu},), samples of shape ({nu}, {n}) on `t`, "
        f"or a callable of t returning shape ({nu},); got shape {a.shape}"
    )


def _checked_callable(fun, nu: int):
    def checked(t: float) -> np.ndarray:
        value = np.asarray(fun(t), dtype=float)
        if value.size != nu or value.ndim > 1 or (value.ndim == 0 and nu != 1):
            raise ValueError(
                f"`u` must return shape ({nu},) when called with a time, "
                f"got {value.shape} at t = {t}"
            )
        value = value.reshape(nu)
        # (a finite sum: every value is finite, the common case at a third of the cost)
        if not math.isfinite(value.sum()) and not np.all(np.isfinite(value)):
            raise ValueError(f"`u` returned a non-finite value {value.tolist()} at t = {t}")
        return value

    return checked


def check_invariants(invariants, model: Model) -> tuple[str, ...]:
    if invariants is True:
        return tuple(model.invariants)
    if invariants is False or invariants is None:
        return ()
    if isinstance(invariants, str):
        invariants = (invariants,)
    try:
        names = tuple(invariants)
    except TypeError:
        raise ValueError(
            f"`invariants` must be a bool or names of invariants, got {invariants!r}") from None
    unknown = [k for k in names if k not in model.invariants]
    if unknown:
        raise ValueError(
            f"`invariants` names unknown invariants {unknown}; "
            f"this model has {sorted(model.invariants)}"
        )
    return names


def _new(cls, **values):
    """``cls(**values)`` of a frozen dataclass given every field, without the per-field
    ``object.__setattr__`` of its ``__init__`` (about 0.4 us a call)."""
    obj = object.__new__(cls)
    obj.__dict__.update(values)
    return obj


@dataclass(frozen=True)
class Problem:
    model: Model
    x0: np.ndarray
    t: np.ndarray
    control: Control
    p: np.ndarray

    @property
    def nint(self) -> int:
        return self.t.size - 1

    @classmethod
    def new(cls, model: Model, x0: np.ndarray, t: np.ndarray, control: Control,
            p: np.ndarray) -> "Problem":
        """``Problem(model, x0, t, control, p)``, built faster (`_new`)."""
        return _new(cls, model=model, x0=x0, t=t, control=control, p=p)


@dataclass(frozen=True)
class Batch:
    """K runs on one grid: ``x0 (nx, K)``, ``p (np, K)``, controls ``ua, ub (K, nint, nu)``
    (the values at the start and end of each output interval, linear in between);
    ``constant`` when each run's control is known to be one value throughout (``False``
    leaves it to be found from the values); ``tail (K, nu)`` the samples at ``t[-1]`` of a
    zero-order hold (``ub = ua``), else None."""

    model: Model
    x0: np.ndarray
    t: np.ndarray
    p: np.ndarray
    ua: np.ndarray
    ub: np.ndarray
    constant: bool = False
    tail: np.ndarray | None = None  # (K, nu): the samples at t[-1] of a zero-order hold

    @property
    def K(self) -> int:
        return self.x0.shape[1]

    @property
    def nint(self) -> int:
        return self.t.size - 1

    def problem(self, k: int) -> Problem:
        """Run ``k`` as a single-run `Problem`."""
        return Problem(self.model, self.x0[:, k].copy(), self.t,
                       Control("linear", self.ua[k], self.ub[k],
                               tail=None if self.tail is None else self.tail[k]),
                       self.p[:, k].copy())


def check_batch(model: Model, x0, t: np.ndarray, u, p, *, hold: str = "linear") -> Batch:
    """The batch of ``x0 (nx, K)`` with ``p`` ``(np,)`` or ``(np, K)`` and ``u`` None,
    ``(nu,)``, ``(nu, n)`` (shared) or ``(nu, n, K)`` (per run), samples held as ``hold``
    says (`dynamics.integrate.inputs.HOLDS`); raises naming the argument."""
    if hold not in HOLDS:
        raise ValueError(f"`hold` must be one of {HOLDS}, got {hold!r}")
    nx, nu, n = model.nx, model.nu, t.size
    X0 = np.array(finite_array(x0, "x0"), dtype=float)
    if X0.ndim != 2 or X0.shape[0] != nx or X0.shape[1] < 1:
        raise ValueError(f"`x0` must have shape ({nx},) or ({nx}, K) for a batch of K runs, "
                         f"got {X0.shape}")
    K = X0.shape[1]
    if model.attitude is not None:
        iq = model.attitude[0]
        q = X0[iq:iq + 4]  # (the norm of each run's quaternion, without a temporary per row)
        bad = np.abs(np.sqrt(np.einsum("ik,ik->k", q, q)) - 1.0) > QUAT_NORM_TOL
        if bad.any():  # the message of the single-run check, naming the run
            k = int(np.argmax(bad))
            unit_quaternion(X0[iq:iq + 4, k], f"x0[{iq}:{iq + 4}, {k}] (the attitude quaternion)")
    if p is None:
        P = np.repeat(model.resolve_p(None)[:, None], K, axis=1)
    else:
        a = np.asarray(finite_array(p, "p"), dtype=float)
        if a.ndim == 2 and a.shape == (model.np, K):
            P = np.array(a)
        elif a.ndim <= 1:
            P = np.repeat(model.resolve_p(a)[:, None], K, axis=1)
        else:
            raise ValueError(f"`p` must have shape ({model.np},) or ({model.np}, {K}) for a "
                             f"batch of {K} runs, got {a.shape}")
    if callable(u):
        raise ValueError("`u` must be None or an array for a batch of runs (x0 of shape "
                         f"({nx}, K)): give samples of shape ({nu}, {n}) or ({nu}, {n}, K)")
    a = np.zeros(nu) if u is None else np.asarray(finite_array(u, "u"), dtype=float)
    if a.shape == (nu,):  # (one value for every run and time: a view, nothing copied per run)
        same = _rows(np.array(a), K, n - 1)
        return Batch(model, X0, t, P, same, same, True)
    if a.shape == (nu, n):
        U = np.broadcast_to(a.T, (K, n, nu))
    elif a.shape == (nu, n, K):
        U = a.transpose(2, 1, 0)
    else:
        raise ValueError(f"`u` must be None, ({nu},), ({nu}, {n}) or ({nu}, {n}, {K}) for "
                         f"a batch of {K} runs, got {a.shape}")
    ua = np.ascontiguousarray(U[:, :-1])
    if hold == "zoh":
        return Batch(model, X0, t, P, ua, ua, False, np.array(U[:, -1]))
    return Batch(model, X0, t, P, ua, np.ascontiguousarray(U[:, 1:]))
