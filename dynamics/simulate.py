"""Simulation of a `Model` on a time grid: compiled fixed-step loops, a Lie-group integrator,
SUNDIALS CVODES, and an ``auto`` mode that meets a requested global tolerance.

Every fixed-step integration (``rk4``, ``rk8``, ``lie`` and the runs ``auto`` makes) calls
ONE CasADi Function per (model, method, control mode): a ``mapaccum`` of 512 steps, each
with its own step size and control data, wrapped in an MX Function (so the generated code is
a loop, never an unrolled SX graph) and jit-compiled to C when a C compiler is present. A run
of any length is a Python loop over such chunks, so neither the generated code nor the
compile time (about 0.4 s, once per model and method) depends on the grid length or the
step count: 1e7 steps cost only their arithmetic. Built Functions are cached by their
defining arguments and called through ``Function.buffer()``, so a call costs microseconds
of Python, not a data conversion per element; the steps of a short last chunk past its
length are skipped by a conditional inside the loop.

Costs measured on a 2-core machine (rigid body, 7 states): per step about 55 ns (rk4),
140 ns (lie), 180-250 ns (rk8) compiled, 2-3 us interpreted, plus a few us of Python per
chunk of 512 steps.

Controls
--------
``u`` is ``None`` (zero), a constant ``(nu,)`` vector, samples ``(nu, n)`` on the grid ``t``
(linear between samples: within interval ``k`` the control is
``u_k + (tau - t_k) (u_{k+1} - u_k) / (t_{k+1} - t_k)``, evaluated at every Runge-Kutta stage
time; the kinks sit on the grid, where steps start and end, so no order is lost), or a
callable ``u(t) -> (nu,)`` evaluated at every stage time (fixed-step methods; the calls are
made from Python before the compiled loop runs) or at every right-hand-side evaluation
(``cvodes``, through a ``casadi.Callback``).

The error of a fixed-step run is controlled by the number of substeps; ``auto`` chooses it
from Richardson step-halving estimates of the *global* error at the output times (see
`simulate`), which is what a tolerance should mean to a user. ``cvodes`` tolerances are local
error controls: they are not errors (on a 100 s tumbling body, rtol = 1e-10 gives 1e-7).
"""
from __future__ import annotations

import contextlib
import difflib
import functools
import io
import math
import re
import shutil
import tempfile
import threading
import time
import weakref
from collections import OrderedDict
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Callable, Literal, Mapping

import casadi as ca
import numpy as np

from .attitude import propagate_quat, quat_rate
from .model import Model
from .validate import unit_quaternion

__all__ = ["simulate", "SimulationResult", "METHODS"]

Method = Literal["auto", "cvodes", "rk4", "rk8", "lie"]
METHODS = ("auto", "cvodes", "rk4", "rk8", "lie")
_FIXED_STEP = ("rk4", "rk8", "lie")

_EPS = np.finfo(float).eps
_BASE = 4  # unroll base of mapaccum: casadi's construction cost grows ~5x from base 4 to 10

# status codes of SimulationResult
_OK, _OK_STIFF, _ROUNDOFF, _UNVERIFIED, _FAILED = 0, 1, 2, 3, -1


# ============================================================================ tableaux
@dataclass(frozen=True)
class _Tableau:
    """An explicit Runge-Kutta method: ``a`` (strictly lower rows), weights ``b``, nodes ``c``."""

    name: str
    a: tuple
    b: tuple
    c: tuple
    order: int

    @property
    def stages(self) -> int:
        return len(self.b)


_RK4 = _Tableau(
    "rk4",
    a=((), (0.5,), (0.0, 0.5), (0.0, 0.0, 1.0)),
    b=(1 / 6, 1 / 3, 1 / 3, 1 / 6),
    c=(0.0, 0.5, 0.5, 1.0),
    order=4,
)

# Dormand & Prince DOP853, 8th-order solution (Hairer, Norsett & Wanner, "Solving ODEs I",
# code dop853.f); the doubles are those of scipy.integrate's DOP853.
_DOP853 = _Tableau(
    "rk8",
    a=(
        (),
        (0.05260015195876773,),
        (0.0197250569845379, 0.0591751709536137),
        (0.02958758547680685, 0.0, 0.08876275643042054),
        (0.2413651341592667, 0.0, -0.8845494793282861, 0.924834003261792),
        (0.037037037037037035, 0.0, 0.0, 0.17082860872947386, 0.12546768756682242),
        (0.037109375, 0.0, 0.0, 0.17025221101954405, 0.06021653898045596, -0.017578125),
        (0.03709200011850479, 0.0, 0.0, 0.17038392571223998, 0.10726203044637328,
         -0.015319437748624402, 0.008273789163814023),
        (0.6241109587160757, 0.0, 0.0, -3.3608926294469414, -0.868219346841726,
         27.59209969944671, 20.154067550477894, -43.48988418106996),
        (0.47766253643826434, 0.0, 0.0, -2.4881146199716677, -0.590290826836843,
         21.230051448181193, 15.279233632882423, -33.28821096898486, -0.020331201708508627),
        (-0.9371424300859873, 0.0, 0.0, 5.186372428844064, 1.0914373489967295,
         -8.149787010746927, -18.52006565999696, 22.739487099350505, 2.4936055526796523,
         -3.0467644718982196),
        (2.273310147516538, 0.0, 0.0, -10.53449546673725, -2.0008720582248625,
         -17.9589318631188, 27.94888452941996, -2.8589982771350235, -8.87285693353063,
         12.360567175794303, 0.6433927460157636),
    ),
    b=(0.054293734116568765, 0.0, 0.0, 0.0, 0.0, 4.450312892752409, 1.8915178993145003,
       -5.801203960010585, 0.3111643669578199, -0.1521609496625161, 0.20136540080403034,
       0.04471061572777259),
    c=(0.0, 0.05260015195876773, 0.0789002279381516, 0.1183503419072274, 0.2816496580927726,
       0.3333333333333333, 0.25, 0.3076923076923077, 0.6512820512820513, 0.6,
       0.8571428571428571, 1.0),
    order=8,
)

# Stage nodes of the commutator-free method CF4 used by "lie" (four right-hand sides a step).
_CF4_NODES = (0.0, 0.5, 0.5, 1.0)


def _nodes(method: str) -> tuple:
    return _CF4_NODES if method == "lie" else _TABLEAUX[method].c


def _unique_nodes(method: str) -> tuple:
    return tuple(sorted(set(_nodes(method))))


_TABLEAUX = {"rk4": _RK4, "rk8": _DOP853}


# ============================================================================ result
class _Dense:
    """What `SimulationResult.sample` needs: the model, ``p`` and ``u`` on the grid; caches xdot."""

    def __init__(self, model: Model, p: np.ndarray, u_grid: Callable[[], np.ndarray]):
        self._model, self._p, self._u_grid = model, p, u_grid
        self._xdot = None
        self._drift = None
        self._lock = threading.Lock()

    def drift(self, x: np.ndarray) -> Mapping[str, float]:
        with self._lock:
            if self._drift is None:
                self._drift = MappingProxyType(_drift(self._model, x, self._p))
            return self._drift

    def xdot(self, x: np.ndarray) -> np.ndarray:
        with self._lock:
            if self._xdot is None:
                xdot = _map_eval(self._model.f, [x, self._u_grid(), self._p])
                xdot.setflags(write=False)
                self._xdot = xdot
            return self._xdot


@dataclass(frozen=True, eq=False)
class SimulationResult:
    """Outcome of `simulate`, in the manner of scipy's ``OdeResult``.

    Attributes
    ----------
    t : ndarray, shape (n,) [s]
        The output grid.
    x : ndarray, shape (nx, n)
        States at ``t`` (``x[:, 0]`` is ``x0``). After a failure the columns the integrator
        did not reach are NaN.
    success : bool
        True only when the answer was verified against what was asked: ``auto`` met the
        tolerance by its global error estimate (status 0 or 1); a fixed-step method or
        ``cvodes`` reached ``t[-1]`` with finite states (they take no global tolerance; see
        ``invariant_drift`` for a check of a fixed-step run).
    status : int
        ``0`` success (``auto``: the estimated global error of the rk8 run is within
        tolerance); ``1`` success of ``auto`` on a stiff problem through cvodes, its global
        error estimated from runs at tightened local tolerances; ``2`` not verified: the
        tolerance lies below the round-off floor of fixed-step runs on this grid (more steps
        no longer reduce the differences between runs); ``3`` not verified: ``max_steps``
        or the run budget was reached first; ``-1`` failure (integrator error, or a
        non-finite state). With 2 and 3 ``x`` is the finest run made and
        ``error_estimate`` says how far off it is thought to be.
    message : str
        What happened, in words.
    method : str
        The method that produced ``x`` (``auto`` reports ``rk8`` or ``cvodes``).
    wall_time : float [s]
        Time spent in `simulate`, validation and any compilation included.
    n_steps, n_rhs : int
        Steps taken and right-hand-side evaluations made, summed over every run the call made
        (``auto`` makes several).
    substeps : int
        Fixed-step methods: steps per output interval of the returned solution; 0 for cvodes.
    error_estimate : float
        ``auto`` with a fixed-step result: estimated max over states and output times of
        ``|error| / (atol + rtol |x|)`` (1.0 is exactly the tolerance); NaN otherwise.
    compiled : bool
        Whether the loop that produced ``x`` ran as jit-compiled C.
    invariants : mapping of str to ndarray
        Each requested invariant along ``x``: shape ``(n,)`` for a scalar, ``(m, n)`` for a
        vector invariant. Empty unless asked for.
    """

    t: np.ndarray
    x: np.ndarray
    success: bool
    status: int
    message: str
    method: str
    wall_time: float
    n_steps: int
    n_rhs: int
    substeps: int = 0
    error_estimate: float = float("nan")
    compiled: bool = False
    invariants: Mapping[str, np.ndarray] = field(default_factory=dict)
    _dense: _Dense | None = field(default=None, repr=False)

    @property
    def xdot(self) -> np.ndarray:
        """State derivative at ``t``, shape (nx, n); evaluated on first use."""
        if self._dense is None:
            raise ValueError("this result carries no model to evaluate xdot")
        return self._dense.xdot(self.x)

    @property
    def invariant_drift(self) -> Mapping[str, float]:
        """Largest change of each of the model's invariants along ``x`` (evaluated on first use).

        ``max_t |I(t) - I(t[0])| / |I(t[0])|`` (Euclidean norm for a vector invariant;
        absolute where ``I(t[0]) = 0``), NaN when ``x`` has non-finite columns. For a quantity
        conserved by the model under the given ``u`` (energy and inertial angular momentum of
        a torque-free body, a unit quaternion's norm) this is a measured error of the
        solution; a fixed-step run that went unstable shows it as a drift of order 1 or more.
        """
        if self._dense is None:
            return MappingProxyType({})
        return self._dense.drift(self.x)

    def sample(self, t) -> np.ndarray:
        """Dense output: cubic Hermite interpolation of ``x`` and ``xdot`` on the grid.

        Exact at the grid points; between them the error is ``O(dt^4)`` in the grid spacing
        ``dt`` (not the integrator's accuracy: refine ``t`` for accurate dense output).

        Parameters
        ----------
        t : float or array_like, shape (m,) [s]
            Times within ``[self.t[0], self.t[-1]]``.

        Returns
        -------
        ndarray, shape (nx,) for a scalar ``t``, else (nx, m)

        Raises
        ------
        ValueError
            If ``t`` is not finite or lies outside the grid (no extrapolation).
        """
        tq = np.asarray(t, dtype=float)
        scalar = tq.ndim == 0
        tq = tq.reshape(-1)
        if not np.all(np.isfinite(tq)):
            raise ValueError("`t` must be finite")
        if tq.size and (tq.min() < self.t[0] or tq.max() > self.t[-1]):
            raise ValueError(
                f"`t` must lie within the simulated interval [{self.t[0]}, {self.t[-1]}], "
                f"got [{tq.min()}, {tq.max()}]"
            )
        out = _hermite(self.t, self.x, self.xdot, tq)
        return out[:, 0] if scalar else out


def _hermite(t, x, xdot, tq):
    i = np.clip(np.searchsorted(t, tq, side="right") - 1, 0, t.size - 2)
    dt = t[i + 1] - t[i]
    s = (tq - t[i]) / dt
    s2, s3 = s * s, s * s * s
    h00, h10, h01, h11 = 2 * s3 - 3 * s2 + 1, s3 - 2 * s2 + s, 3 * s2 - 2 * s3, s3 - s2
    return (h00 * x[:, i] + h10 * dt * xdot[:, i] + h01 * x[:, i + 1]
            + h11 * dt * xdot[:, i + 1])


# ============================================================================ the cache
class _FunctionCache:
    """Built CasADi Functions keyed by their defining arguments (LRU, thread-safe).

    Entries keep the model's right-hand side alive, so a key made from its address cannot be
    reused by another Function while the entry exists. Also counts uses per key (``auto``
    compiles a loop on its third use), owns the jit scratch directory (removed at
    interpreter exit) and remembers whether a C compiler was found.
    """

    def __init__(self, maxsize: int = 96):
        self._maxsize = maxsize
        self._items: OrderedDict = OrderedDict()
        self._uses: dict = {}
        self._lock = threading.RLock()
        self._jit_dir: str | None = None
        self._jit_ok: bool | None = None
        self._jit_opts: dict | None = None

    def get(self, key, build, keepalive=None):
        """Return the entry for ``key``, building it with ``build()`` on a miss."""
        with self._lock:
            self._uses[key] = self._uses.get(key, 0) + 1
            if key in self._items:
                self._items.move_to_end(key)
                return self._items[key][0]
            value = build()
            self._items[key] = (value, keepalive)
            while len(self._items) > self._maxsize:
                old, _ = self._items.popitem(last=False)
                self._uses.pop(old, None)
            return value

    def contains(self, key) -> bool:
        with self._lock:
            return key in self._items

    def uses(self, key) -> int:
        with self._lock:
            return self._uses.get(key, 0)

    def jit_options(self) -> dict | None:
        """casadi jit options, or None when no C compiler is on the PATH."""
        with self._lock:
            if self._jit_ok is None:
                compiler = shutil.which("gcc") or shutil.which("cc")
                self._jit_ok = compiler is not None
                if compiler is not None:
                    self._jit_dir = tempfile.mkdtemp(prefix="appdyn-jit-")
                    weakref.finalize(self, _remove_jit_files, self._items, self._jit_dir)
                    self._jit_opts = {
                        "jit": True,
                        "compiler": "shell",
                        "jit_name": "appdyn_sim",
                        "jit_options": {
                            "flags": ["-O3", "-w"],
                            "compiler": compiler,
                            "linker": compiler,
                            "directory": self._jit_dir + "/",
                            "verbose": False,
                        },
                    }
            return self._jit_opts if self._jit_ok else None


def _remove_jit_files(items: dict, directory: str):
    """At exit: drop the Functions first (casadi deletes its own files), then the directory."""
    items.clear()
    shutil.rmtree(directory, ignore_errors=True)


_CACHE = _FunctionCache()


def _fkey(f: ca.Function) -> int:
    """Identity of a casadi Function: the address of its internal object."""
    return hash(f)


# ============================================================================ validation
def _check_model(model) -> Model:
    if not isinstance(model, Model):
        raise TypeError(f"`model` must be a dynamics.Model, got {type(model).__name__}")
    return model


def _check_t(t) -> np.ndarray:
    try:
        t = np.array(t, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"`t` must be an array of times: {exc}") from None
    if t.ndim != 1 or t.size < 2:
        raise ValueError(f"`t` must be a 1-D grid of at least 2 times, got shape {t.shape}")
    if not np.isfinite(t).all():
        raise ValueError("`t` must be finite")
    dt = t[1:] - t[:-1]
    if not (dt > 0).all():
        k = int(np.argmin(dt))
        raise ValueError(
            f"`t` must be strictly increasing, got t[{k}] = {t[k]} >= t[{k + 1}] = {t[k + 1]}"
        )
    t.setflags(write=False)
    return t


def _check_x0(x0, model: Model) -> np.ndarray:
    nx = model.nx
    try:
        x = np.array(x0, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"`x0` must be a vector of {nx} numbers: {exc}") from None
    if x.shape not in ((nx,), (nx, 1)):
        raise ValueError(f"`x0` must have shape ({nx},), got {x.shape}")
    x = x.reshape(nx)
    if not np.isfinite(x).all():
        raise ValueError(f"`x0` must be finite, got {x.tolist()}")
    if model.attitude is not None:
        iq = model.attitude[0]
        unit_quaternion(x[iq:iq + 4], f"x0[{iq}:{iq + 4}] (the attitude quaternion)")
    return x


def _check_cvodes_options(options) -> dict:
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
    if not _CACHE.contains(key):
        _CACHE.get(key, lambda: _try_cvodes_options(options))
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


@functools.lru_cache(maxsize=1)
def _cvodes_option_names() -> frozenset:
    """Names of the options casadi's cvodes integrator takes (parsed from print_options)."""
    x = ca.SX.sym("x")
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        ca.integrator("names", "cvodes", {"x": x, "ode": -x}, 0.0, [1.0], {}).print_options()
    return frozenset(re.findall(r'^> "([^"]+)"', buf.getvalue(), flags=re.M))


def _check_tolerances(rtol, atol, nx: int) -> tuple[float, np.ndarray]:
    try:
        rtol_f = float(rtol)
    except (TypeError, ValueError):
        raise ValueError(f"`rtol` must be a number, got {rtol!r}") from None
    if not (math.isfinite(rtol_f) and 100 * _EPS <= rtol_f < 1):
        raise ValueError(f"`rtol` must be in [{100 * _EPS:.3g}, 1), got {rtol!r}")
    try:
        a = np.array(atol, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(
            f"`atol` must be a number or a vector of {nx} numbers, got {atol!r}") from None
    if a.shape not in ((), (nx,)):
        raise ValueError(f"`atol` must be a scalar or have shape ({nx},), got {a.shape}")
    if not (np.isfinite(a).all() and (a >= 0).all()):
        raise ValueError(f"`atol` must be finite and non-negative, got {atol!r}")
    a = np.full(nx, float(a)) if a.ndim == 0 else a
    return rtol_f, a


def _check_int(value, name: str, minimum: int = 1) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise ValueError(f"`{name}` must be an integer >= {minimum}, got {value!r}")
    return int(value)


@dataclass(frozen=True)
class _Control:
    """The control input, normalized.

    ``mode == "linear"``: ``ua[k], ub[k]`` (shape (nint, nu)) are the values at the start and
    end of interval ``k``. ``mode == "stages"``: ``fun(t) -> (nu,)`` is called at stage times.
    """

    mode: str
    ua: np.ndarray | None = None
    ub: np.ndarray | None = None
    fun: Callable | None = None

    def at(self, t: float, k: int, tk: float, H: float) -> np.ndarray:
        if self.mode == "stages":
            return self.fun(t)
        return self.ua[k] + (t - tk) / H * (self.ub[k] - self.ua[k])

    def grid(self, t: np.ndarray) -> np.ndarray:
        """Control on the output grid, shape (nu, n)."""
        if self.mode == "stages":
            return np.stack([self.fun(ti) for ti in t], axis=1)
        return np.concatenate([self.ua, self.ub[-1:]], axis=0).T

    def head(self, nint: int) -> "_Control":
        """The control of the first ``nint`` intervals."""
        if self.mode == "stages":
            return self
        return _Control("linear", self.ua[:nint], self.ub[:nint])

    def cvodes_input(self, t: np.ndarray) -> np.ndarray:
        """Piecewise-constant integrator input ``[u_k, slope_k, t_k]``, shape (nint, 2 nu + 1)."""
        if self.mode == "stages":
            return np.zeros((t.size - 1, 0))
        slope = (self.ub - self.ua) / np.diff(t)[:, None]
        return np.concatenate([self.ua, slope, t[:-1, None]], axis=1)


def _check_u(u, nu: int, t: np.ndarray) -> _Control:
    n = t.size
    if u is None:
        z = np.zeros((n - 1, nu))
        return _Control("linear", z, z)
    if callable(u):
        fun = _checked_callable(u, nu)
        fun(float(t[0]))  # raises ValueError naming `u` on a wrong shape
        if nu == 0:
            z = np.zeros((n - 1, 0))
            return _Control("linear", z, z)
        return _Control("stages", fun=fun)
    try:
        a = np.array(u, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"`u` must be None, a callable or an array of numbers: {exc}") from None
    if a.ndim == 0 and nu == 1:
        a = a.reshape(1)
    if a.shape == (nu,):
        if not np.all(np.isfinite(a)):
            raise ValueError(f"`u` must be finite, got {a.tolist()}")
        c = np.broadcast_to(a, (n - 1, nu))
        return _Control("linear", c, c)
    if a.shape == (nu, n):
        if not np.all(np.isfinite(a)):
            raise ValueError("`u` must be finite")
        return _Control("linear", np.ascontiguousarray(a[:, :-1].T),
                        np.ascontiguousarray(a[:, 1:].T))
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
        if not np.all(np.isfinite(value)):
            raise ValueError(f"`u` returned a non-finite value {value.tolist()} at t = {t}")
        return value

    return checked


def _check_invariants(invariants, model: Model) -> tuple[str, ...]:
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


# ============================================================================ kernels (SX)
def _sym(f: ca.Function):
    """SX when ``f`` can be evaluated on SX (small, fast kernels), else MX."""
    try:
        f.call([ca.SX.sym("x", f.sparsity_in(i)) for i in range(f.n_in())])
        return ca.SX
    except RuntimeError:
        return ca.MX


def _kernel_inputs(sym, nx, nu, np_, mode, n_nodes):
    x, h, p = sym.sym("x", nx), sym.sym("h"), sym.sym("p", np_)
    if mode == "linear":
        ua, ud = sym.sym("ua", nu), sym.sym("ud", nu)
        return [x, h, ua, ud, p], (lambda c: ua + (c * h) * ud)
    us = sym.sym("us", nu * n_nodes)
    return [x, h, us, p], None


def _stage_control(mode, ins, nu, nodes_unique, linear_u):
    if mode == "linear":
        return linear_u
    us = ins[2]

    def u_at(c):
        j = nodes_unique.index(c)
        return us[j * nu:(j + 1) * nu]

    return u_at


def _rk_kernel(f: ca.Function, method: str, mode: str) -> ca.Function:
    """One explicit Runge-Kutta step ``(x, h, u-data, p) -> x_next`` as a Function."""
    tab = _TABLEAUX[method]
    nx, nu, np_ = f.numel_in(0), f.numel_in(1), f.numel_in(2)
    nodes = _unique_nodes(method)
    sym = _sym(f)
    ins, linear_u = _kernel_inputs(sym, nx, nu, np_, mode, len(nodes))
    u_at = _stage_control(mode, ins, nu, nodes, linear_u)
    x, h, p = ins[0], ins[1], ins[-1]
    k = []
    for i in range(tab.stages):
        xi = x
        for j, aij in enumerate(tab.a[i]):
            if aij != 0.0:
                xi = xi + (aij * h) * k[j]
        k.append(f.call([xi, u_at(tab.c[i]), p])[0])
    incr = 0
    for bi, ki in zip(tab.b, k):
        if bi != 0.0:
            incr = incr + bi * ki
    return ca.Function(f"{method}_step", ins, [x + h * incr])


def _lie_kernel(f: ca.Function, attitude: tuple[int, int], mode: str) -> ca.Function:
    """One step of the commutator-free Lie group method CF4 (Celledoni, Marthinsen & Owren 2003).

    The state is ``(q, y)``: the unit quaternion ``q = x[iq:iq+4]`` on S^3 and every other
    state ``y`` in a vector space. A right-hand side evaluation ``F_i`` at a stage state gives
    the body rate ``w_i`` (a Lie algebra element acting on ``q`` by ``qdot = -1/2 Wbar(w) q``)
    and ``ydot_i``. The flow of a frozen combination ``sum a_i F_i`` over ``h`` is exact:
    ``q <- propagate_quat(q, sum a_i w_i, h)`` and ``y <- y + h sum a_i ydot_i``.

        X2 = exp(h/2 F1) x,  X3 = exp(h/2 F2) x,  X4 = exp(h (F3 - F1/2)) X2,
        x+ = exp(h (-F1/12 + F2/6 + F3/6 + F4/4)) applied after exp(h (F1/4 + F2/6 + F3/6 - F4/12)).

    The final flows are applied in this order (measured: 4th order; the other order is 2nd
    order for the quaternion). For ``y`` this is the classical RK4; ``q`` only ever moves
    by exact rotations, so ``|q|`` is kept to round-off for any step size and horizon.
    """
    iq, iw = attitude
    nx, nu, np_ = f.numel_in(0), f.numel_in(1), f.numel_in(2)
    nodes = _unique_nodes("lie")
    sym = _sym(f)
    ins, linear_u = _kernel_inputs(sym, nx, nu, np_, mode, len(nodes))
    u_at = _stage_control(mode, ins, nu, nodes, linear_u)
    x, h, p = ins[0], ins[1], ins[-1]
    qsl = slice(iq, iq + 4)

    def rhs(xs, c):
        return xs[iw:iw + 3], f.call([xs, u_at(c), p])[0]

    def flow(base, coefs, evals):
        w = sum(a * e[0] for a, e in zip(coefs, evals) if a != 0)
        d = sum(a * e[1] for a, e in zip(coefs, evals) if a != 0)
        out = base + h * d
        out[qsl] = propagate_quat(base[qsl], w, h)
        return out

    f1 = rhs(x, 0.0)
    x2 = flow(x, [0.5], [f1])
    f2 = rhs(x2, 0.5)
    x3 = flow(x, [0.5], [f2])
    f3 = rhs(x3, 0.5)
    x4 = flow(x2, [-0.5, 0.0, 1.0], [f1, f2, f3])
    f4 = rhs(x4, 1.0)
    evals = [f1, f2, f3, f4]
    mid = flow(x, [1 / 4, 1 / 6, 1 / 6, -1 / 12], evals)
    return ca.Function("lie_step", ins, [flow(mid, [-1 / 12, 1 / 6, 1 / 6, 1 / 4], evals)])


def _check_lie_model(model: Model, x0: np.ndarray, p: np.ndarray):
    """Raise ValueError unless ``model`` has an attitude whose kinematics are Eq. 4.70.

    Checked numerically at ``x0`` and at two random states near it, once per model (a
    passed check is cached).
    """
    if model.attitude is None:
        raise ValueError(
            f"`method` 'lie' needs a model with an attitude (model.attitude), "
            f"and {model.name!r} has none"
        )
    iq, iw = model.attitude
    if not (iq + 4 <= iw or iw + 3 <= iq):
        raise ValueError(f"`model` attitude blocks overlap: quaternion at {iq}, rates at {iw}")
    key = ("lie-check", _fkey(model.f), model.attitude)
    if not _CACHE.contains(key):
        _CACHE.get(key, lambda: _lie_kinematics_check(model, x0, p), keepalive=model.f)


def _lie_kinematics_check(model: Model, x0: np.ndarray, p: np.ndarray) -> bool:
    iq, iw = model.attitude
    rng = np.random.default_rng(7)
    for trial in range(3):
        x = x0.copy()
        if trial:
            q = rng.standard_normal(4)
            x[iq:iq + 4] = q / np.linalg.norm(q)
            x[iw:iw + 3] = x0[iw:iw + 3] + rng.standard_normal(3)
        u = rng.standard_normal(model.nu) if trial else np.zeros(model.nu)
        qdot = model.rhs(x, u, p)[iq:iq + 4]
        expected = quat_rate(x[iq:iq + 4], x[iw:iw + 3])
        if not np.all(np.isfinite(qdot)):
            continue
        scale = np.linalg.norm(x[iq:iq + 4]) * (np.linalg.norm(x[iw:iw + 3]) + 1.0)
        if np.max(np.abs(qdot - expected)) > 1e-10 * scale:
            raise ValueError(
                f"`model` {model.name!r}: the derivative of x[{iq}:{iq + 4}] is not the "
                f"quaternion kinematics -1/2 Wbar(w) q of the rates x[{iw}:{iw + 3}] "
                "(Eq. 4.70), so the 'lie' method does not apply"
            )
    return True


def _kernel(model: Model, method: str, mode: str) -> ca.Function:
    key = ("kernel", _fkey(model.f), model.attitude if method == "lie" else None, method, mode)

    def build():
        if method == "lie":
            return _lie_kernel(model.f, model.attitude, mode)
        return _rk_kernel(model.f, method, mode)

    return _CACHE.get(key, build, keepalive=model.f)


# ============================================================================ loops (MX)
# Every fixed-step run calls ONE compiled Function per (model, method, control mode): a
# `mapaccum` of `_CHUNK` steps, each with its own step size and control data. A run of any
# length is a Python loop over chunks (a few microseconds each), so neither the code nor the
# compile time grows with the grid length or the step count, and 1e7 steps are as easy as 1e3.
# The steps of a short last chunk past its length are skipped (a conditional in the loop).
_CHUNK = 512


def _chunk_function(model: Model, method: str, mode: str, jit: bool):
    """The chunk Function of ``model`` and ``method`` (cached); returns (Function, compiled).

    Inputs ``mode == 'linear'``: ``x0 (nx)``, ``n`` the number of steps to take (the rest
    are skipped), ``h (1 x B)`` step sizes, ``ua (nu x B)`` control at the start of each
    step, ``ud (nu x B)`` its slope [1/s], ``p (np)``. ``mode == 'stages'``: ``x0``, ``n``,
    ``h``, ``us (nu*s x B)`` control at the distinct stage nodes of each step, ``p``.
    Output ``X (nx x B)``: the state after each step.
    """
    base_key = _chunk_key(model, method, mode)
    opts = _CACHE.jit_options() if jit else None
    if opts is None:
        return _CACHE.get(base_key + (False,),
                          lambda: (_build_chunk(model, method, mode, {}), False),
                          keepalive=model.f)

    def build_compiled():
        try:
            return _build_chunk(model, method, mode, opts), True
        except RuntimeError:  # e.g. a right-hand side that cannot be code-generated
            return _build_chunk(model, method, mode, {}), False

    return _CACHE.get(base_key + (True,), build_compiled, keepalive=model.f)


def _chunk_key(model: Model, method: str, mode: str) -> tuple:
    return ("chunk", _fkey(model.f), model.attitude if method == "lie" else None, method, mode)


_BLOCK = 16  # steps per block of a chunk: a chunk is `_CHUNK // _BLOCK` blocks


def _build_chunk(model, method, mode, opts) -> ca.Function:
    """``mapaccum`` of `_CHUNK` steps that takes only the first ``n``: the chunk is a
    ``mapaccum`` of blocks of `_BLOCK` steps, each block and each step inside a block a
    ``Function.conditional`` that skips (copies the state) past step ``n``. A short run
    then costs its own steps plus about 25 us, not the 512 steps of a full chunk."""
    step = _kernel(model, method, mode)
    args = [ca.MX.sym(step.name_in(i), step.sparsity_in(i)) for i in range(step.n_in())]
    gated = _gated(step, args, "step")
    inner = gated.mapaccum("steps", _BLOCK, {"base": _BASE})
    blk = [ca.MX.sym(inner.name_in(i), inner.sparsity_in(i)) for i in range(inner.n_in())]
    states = inner.call(blk)[0]
    run = ca.Function("block", blk, [states[:, -1], states])
    skip = ca.Function("skip_block", blk, [blk[0], ca.repmat(blk[0], 1, _BLOCK)])
    block_on = ca.MX.sym("block_on")
    gated_block = ca.Function("gated_block", [blk[0], block_on] + blk[1:],
                              ca.Function.conditional("maybe_block", [skip], run)
                              .call([block_on] + blk))
    loop = gated_block.mapaccum("blocks", _CHUNK // _BLOCK, 1, {"base": _BASE})
    x0, n = ca.MX.sym("x0", model.nx), ca.MX.sym("n")
    ins = [x0, n, ca.MX.sym("h", 1, _CHUNK)]
    if mode == "linear":
        ins += [ca.MX.sym("ua", model.nu, _CHUNK), ca.MX.sym("ud", model.nu, _CHUNK)]
    else:
        ins += [ca.MX.sym("us", model.nu * len(_unique_nodes(method)), _CHUNK)]
    ins.append(ca.MX.sym("p", model.np))
    step_on = ca.DM(np.arange(_CHUNK, dtype=float)).T < n
    block_on = ca.DM(np.arange(0, _CHUNK, _BLOCK, dtype=float)).T < n
    out = loop.call([x0, block_on, step_on] + ins[2:-1] + [ca.repmat(ins[-1], 1, _CHUNK)])
    return ca.Function(f"simulate_{method}", ins, [out[1]], opts)


def _gated(step: ca.Function, args: list, name: str) -> ca.Function:
    """``(x, on, *rest) -> step(x, *rest)`` when ``on`` else ``x``."""
    skip = ca.Function(f"skip_{name}", args, [args[0]])
    on = ca.MX.sym("on")
    return ca.Function(f"gated_{name}", [args[0], on] + args[1:],
                       ca.Function.conditional(f"maybe_{name}", [skip], step).call([on] + args))


def _call(fun: ca.Function, args, out_shape) -> np.ndarray:
    """Evaluate ``fun`` through a buffer: numpy in, numpy out, no per-element conversion.

    Arrays are passed in casadi's column-major layout: a C-ordered ``(ncol, nrow)`` numpy
    array is the casadi ``nrow x ncol`` matrix.
    """
    args = [np.ascontiguousarray(a, dtype=float) for a in args]
    out = np.empty(out_shape)
    buf, trigger = fun.buffer()
    for i, a in enumerate(args):
        buf.set_arg(i, memoryview(a))
    buf.set_res(0, memoryview(out))
    trigger()
    return out


def _map_eval(fun: ca.Function, args) -> np.ndarray:
    """Evaluate a Function column by column over ``n`` columns (cached ``map``); (m, n) out.

    ``args`` are arrays of shape (size_i, n) (or 1-D for inputs broadcast to all columns).
    """
    n = next(a.shape[1] for a in args if np.ndim(a) == 2)
    key = ("map", _fkey(fun), n)
    mapped = _CACHE.get(key, lambda: fun.map(n, "serial"), keepalive=fun)
    cols = []
    for a in args:
        a = np.asarray(a, dtype=float)
        cols.append(np.repeat(a.reshape(-1, 1), n, axis=1).T if a.ndim == 1 else a.T)
    out = _call(mapped, cols, (n, fun.numel_out(0)))
    return out.T


# ============================================================================ runners
@dataclass(frozen=True)
class _Problem:
    model: Model
    x0: np.ndarray
    t: np.ndarray
    control: _Control
    p: np.ndarray

    @property
    def nint(self) -> int:
        return self.t.size - 1


@dataclass(frozen=True)
class _Run:
    x: np.ndarray  # (nx, n)
    n_steps: int
    n_rhs: int
    substeps: int
    compiled: bool
    ok: bool
    message: str


def _stage_samples(problem: _Problem, method: str, m: int) -> np.ndarray:
    """Callable control at the distinct stage nodes of every step: shape (nint, m, s, nu)."""
    nodes = np.array(_unique_nodes(method))
    t = problem.t
    h = np.diff(t) / m
    offsets = np.arange(m)[None, :, None] + nodes[None, None, :]
    times = t[:-1, None, None] + offsets * h[:, None, None]
    fun, nu = problem.control.fun, problem.model.nu
    values = np.empty(times.shape + (nu,))
    flat_t, flat_v = times.reshape(-1), values.reshape(-1, nu)
    for i, ti in enumerate(flat_t):
        flat_v[i] = fun(float(ti))
    return values


class _Steps:
    """Per-step data of a fixed-step run, served a chunk at a time (padded to ``_CHUNK``).

    Step ``s`` is substep ``j = s mod m`` of output interval ``k = s // m``: size
    ``h = H_k / m``; linear control ``ua = u_k + j h ud_k`` with slope ``ud_k``; or, for a
    callable control, its samples at the step's stage times.
    """

    def __init__(self, problem: _Problem, method: str, m: int):
        self.m, self.total = m, m * problem.nint
        self.hm = np.diff(problem.t) / m
        ctrl = problem.control
        self.mode = ctrl.mode
        if self.mode == "linear":
            self.ua = ctrl.ua
            self.ud = (ctrl.ub - ctrl.ua) / np.diff(problem.t)[:, None]
            self.constant = not np.any(self.ud) and bool(np.all(ctrl.ua == ctrl.ua[:1]))
        else:
            s = _stage_samples(problem, method, m)  # (nint, m, nodes, nu)
            self.us = s.reshape(self.total, -1)
        nu = problem.model.nu
        self._pad_h = np.zeros(_CHUNK)
        if self.mode == "linear" and self.constant:
            self._ua_c = np.broadcast_to(ctrl.ua[:1], (_CHUNK, nu)).copy()
            self._ud_c = np.zeros((_CHUNK, nu))

    def chunk(self, s0: int) -> list:
        """Arrays for steps ``s0 .. s0 + _CHUNK - 1`` in casadi's column-major layout."""
        n = min(_CHUNK, self.total - s0)
        s = np.arange(s0, s0 + n)
        k = s // self.m
        h = self._pad_h.copy()
        h[:n] = self.hm[k]
        if self.mode != "linear":
            us = np.zeros((_CHUNK, self.us.shape[1]))
            us[:n] = self.us[s0:s0 + n]
            return [h, us]
        if self.constant:
            return [h, self._ua_c, self._ud_c]
        ua, ud = np.zeros((_CHUNK, self.ua.shape[1])), np.zeros((_CHUNK, self.ua.shape[1]))
        ud[:n] = self.ud[k]
        ua[:n] = self.ua[k] + ((s - k * self.m) * h[:n])[:, None] * ud[:n]
        return [h, ua, ud]


class _Progress:
    """Counts steps for a ``progress(done, total)`` callback across all runs of one call:
    ``total`` grows by each run's step count when the run starts."""

    def __init__(self, fun: Callable | None):
        self.fun, self.done, self.total = fun, 0, 0

    def start(self, n: int):
        self.total += n

    def advance(self, n: int):
        self.done += n
        if self.fun is not None:
            self.fun(self.done, self.total)

    def abandon(self, n: int):
        self.total -= n


def _run_fixed(problem: _Problem, method: str, m: int, jit: bool,
               progress: _Progress | None = None) -> _Run:
    """``m`` steps of ``method`` per output interval, chunk by chunk; stops at a non-finite
    state (the columns not reached are NaN)."""
    model, nint, t = problem.model, problem.nint, problem.t
    fun, compiled = _chunk_function(model, method, problem.control.mode, jit)
    steps = _Steps(problem, method, m)
    progress = _Progress(None) if progress is None else progress
    progress.start(steps.total)
    x = np.full((model.nx, nint + 1), np.nan)
    x[:, 0] = problem.x0
    xk = problem.x0
    stages = 4 if method == "lie" else _TABLEAUX[method].stages
    done = 0
    for s0 in range(0, steps.total, _CHUNK):
        n = min(_CHUNK, steps.total - s0)
        X = _call(fun, [xk, np.array([float(n)]), *steps.chunk(s0), problem.p],
                  (_CHUNK, model.nx))
        k_lo, k_hi = (s0 + m) // m - 1, (s0 + n) // m  # intervals ending in this chunk
        last = (np.arange(k_lo, k_hi) + 1) * m - 1 - s0
        x[:, k_lo + 1:k_hi + 1] = X[last].T
        xk = X[n - 1]
        done = s0 + n
        progress.advance(n)
        if not np.all(np.isfinite(xk)):
            break
    progress.abandon(steps.total - done)
    n_steps = done
    if done < steps.total or not np.all(np.isfinite(x)):
        k = int(np.argmax(~np.isfinite(x).all(axis=0)))
        x[:, k:] = np.nan
        return _Run(x, n_steps, stages * n_steps, m, compiled, False,
                    f"{method}: the state became non-finite before t = {t[k]:.6g}")
    return _Run(x, n_steps, stages * n_steps, m, compiled, True,
                f"{method}: {m} step(s) per output interval, {n_steps} steps")


# ------------------------------------------------------------------------------ cvodes
class _ControlCallback(ca.Callback):
    """``u(t)`` of a Python callable as a casadi Function of time, for cvodes."""

    def __init__(self, fun, nu: int):
        ca.Callback.__init__(self)
        self._fun, self._nu = fun, nu
        self.error: BaseException | None = None
        self.construct("u_of_t", {})

    def get_n_in(self):
        return 1

    def get_n_out(self):
        return 1

    def get_sparsity_in(self, i):
        return ca.Sparsity.dense(1, 1)

    def get_sparsity_out(self, i):
        return ca.Sparsity.dense(self._nu, 1)

    def eval(self, arg):
        # After a user exception every call returns NaN: casadi reports a non-finite rhs to
        # cvodes as a recoverable error, and errors at every time make it give up at once
        # (failing only after the bad time, it would creep towards that time until
        # max_num_steps). `_run_cvodes` then re-raises the exception.
        if self.error is None:
            try:
                return [ca.DM(self._fun(float(arg[0])))]
            except Exception as exc:
                self.error = exc
        return [ca.DM.nan(self._nu, 1)]


_CVODES_DEFAULTS = {"show_eval_warnings": False, "disable_internal_warnings": True}


def _cvodes_integrator(model, mode, t, opts, callback=None):
    nx, nu, np_ = model.nx, model.nu, model.np
    if mode == "linear":
        x, tau, p = ca.SX.sym("x", nx), ca.SX.sym("t"), ca.SX.sym("p", np_)
        ua, ud, tk = ca.SX.sym("ua", nu), ca.SX.sym("ud", nu), ca.SX.sym("tk")
        ode = model.f.call([x, ua + (tau - tk) * ud, p])[0]
        uaug = ca.vertcat(ua, ud, tk)
    else:
        x, tau, p = ca.MX.sym("x", nx), ca.MX.sym("t"), ca.MX.sym("p", np_)
        ode = model.f.call([x, callback(tau), p])[0]
        uaug = None
    dae = {"x": x, "t": tau, "p": p, "ode": ode}
    if uaug is not None:
        dae["u"] = uaug
    return ca.integrator("simulate_cvodes", "cvodes", dae, float(t[0]), t[1:].tolist(), opts)


def _cvodes_options(rtol, atol, extra) -> dict:
    opts = dict(_CVODES_DEFAULTS)
    opts.update({"reltol": rtol, "abstol": float(np.min(atol))})
    opts.update(dict(extra or {}))
    return opts


def _run_cvodes(problem: _Problem, rtol, atol, extra) -> _Run:
    model, t, ctrl = problem.model, problem.t, problem.control
    opts = _cvodes_options(rtol, atol, extra)
    callback = None
    if ctrl.mode == "linear":
        key = ("cvodes", _fkey(model.f), t.tobytes(), repr(sorted(opts.items(), key=str)))
        integ = _CACHE.get(key, lambda: _cvodes_integrator(model, "linear", t, opts),
                           keepalive=model.f)
    else:
        callback = _ControlCallback(ctrl.fun, model.nu)
        integ = _cvodes_integrator(model, "stages", t, opts, callback)
    try:
        out = _cvodes_call(integ, problem.x0, problem.p, ctrl.cvodes_input(t))
    except RuntimeError as exc:
        if callback is not None and callback.error is not None:
            raise callback.error
        stats = integ.stats()
        reached = float(stats.get("tcur", t[0]))
        x = _cvodes_prefix(problem, opts, reached, callback)
        text = str(exc)
        cut = text.find("CVode returned")
        reason = text[cut:] if cut >= 0 else text.strip().splitlines()[-1]
        return _Run(x, int(stats.get("nsteps", 0)), int(stats.get("nfevals", 0)), 0, False, False,
                    f"cvodes failed near t = {reached:.6g}: {reason}")
    stats = integ.stats()
    x = np.concatenate([problem.x0[:, None], out.T], axis=1)
    return _Run(x, int(stats["nsteps"]), int(stats["nfevals"]), 0, False, True,
                f"cvodes: {int(stats['nsteps'])} steps (rtol {rtol:g}, atol {np.min(atol):g})")


def _cvodes_call(integ, x0, p, uaug) -> np.ndarray:
    """Run the integrator; (nint, nx) out. A plain call: buffers do not record SUNDIALS stats."""
    res = integ(x0=x0, p=p, u=np.ascontiguousarray(uaug.T))
    return np.asarray(res["xf"], dtype=float).reshape(x0.size, uaug.shape[0]).T


def _cvodes_prefix(problem: _Problem, opts, reached: float, callback) -> np.ndarray:
    """After a failure: the solution on the grid points before ``reached`` (NaN after)."""
    t = problem.t
    x = np.full((problem.model.nx, t.size), np.nan)
    x[:, 0] = problem.x0
    k = int(np.searchsorted(t, reached, side="right"))  # t[:k] <= reached
    if k < 2:
        return x
    control = problem.control.head(k - 1)
    try:
        integ = _cvodes_integrator(problem.model, control.mode, t[:k], opts, callback)
        out = _cvodes_call(integ, problem.x0, problem.p, control.cvodes_input(t[:k]))
    except RuntimeError:
        return x
    x[:, 1:k] = out.T
    return x


# ------------------------------------------------------------------------------ auto
_AUTO_ACCEPT = 0.5     # accept a trusted estimate (truncation + round-off) below this
_AUTO_AIM = 0.1        # predict the step count for this estimated scaled error
_AUTO_RUNS = 8         # give up (status 3) after this many fixed-step runs
_AUTO_INTERPRET = 500_000  # RHS evaluations below which a first-time run is interpreted

_AUTO_CONFIRM = 1024   # below this many steps a trusted triple must be confirmed by another
_FLOOR_ULPS = 1000     # least error floor of a run in ulps of a state's size (`_floor`)
_STIFF_STEPS = 1e6     # explicit steps for stability alone beyond which auto uses cvodes
_CVODES_RTOL_MIN = 1e-14  # tightest local rtol auto asks cvodes for
_RK8_STABILITY = 6.0   # DOP853's stability interval on the negative real axis is about [-6, 0]


def _scaled_diff(xa: np.ndarray, xb: np.ndarray, scale: np.ndarray) -> float:
    """max |xa - xb| / scale over states and output times; inf if anything is non-finite."""
    if not (np.all(np.isfinite(xa)) and np.all(np.isfinite(xb))):
        return math.inf
    diff = np.abs(xa - xb)
    ratio = np.divide(diff, scale, out=np.where(diff == 0, 0.0, np.inf), where=scale > 0)
    return float(ratio.max())


def _roundoff(x: np.ndarray, n_steps: int, scale: np.ndarray) -> float:
    """Scaled round-off model of a fixed-step run: ``n_steps eps max_t |x_i|`` per state.

    Measured on a 100 s tumbling body (double against long double with the same DOP853
    weights, 1000-16000 steps) the accumulated round-off was 0.15-3 eps per step relative
    to the state's size, growing about linearly in the number of steps.
    """
    size = np.max(np.abs(x), axis=1, keepdims=True)
    floor = np.broadcast_to(n_steps * _EPS * size, scale.shape)
    ratio = np.divide(floor, scale, out=np.where(floor == 0, 0.0, np.inf), where=scale > 0)
    return float(ratio.max())


def _initial_step(problem: _Problem, rtol, atol, order: int) -> tuple[float | None, float]:
    """Starting step and Lipschitz estimate ``(h, L)`` [s, 1/s].

    ``h``: Hairer's heuristic (Hairer, Norsett & Wanner I, II.4), capped at ``2 / L`` for
    explicit stability, with ``L = |f(x0 + h0 f0) - f0| / |h0 f0|`` (scaled norms). ``h`` is
    None when the heuristic is degenerate (a zero state or zero derivative); ``L`` is then 0.
    """
    model, x0 = problem.model, problem.x0
    t0, H0 = float(problem.t[0]), float(problem.t[1] - problem.t[0])
    u0 = problem.control.at(t0, 0, t0, H0)
    scale = atol + rtol * np.abs(x0)
    if np.any(scale == 0):
        return None, 0.0
    f0 = model.rhs(x0, u0, problem.p)
    d0 = np.sqrt(np.mean((x0 / scale) ** 2))
    d1 = np.sqrt(np.mean((f0 / scale) ** 2))
    if not (np.isfinite(d1) and d0 > 1e-5 and d1 > 1e-5):
        return None, 0.0
    h0 = 0.01 * d0 / d1
    f1 = model.rhs(x0 + h0 * f0, problem.control.at(t0 + min(h0, H0), 0, t0, H0), problem.p)
    d2 = np.sqrt(np.mean(((f1 - f0) / scale) ** 2)) / h0
    if not np.isfinite(d2):
        return None, 0.0
    h1 = (0.01 / max(d1, d2)) ** (1.0 / (order + 1)) if max(d1, d2) > 1e-15 else 100 * h0
    lipschitz = d2 / d1
    h = min(100 * h0, h1)
    return (min(h, 2.0 / lipschitz) if lipschitz > 0 else h), lipschitz


@dataclass(frozen=True)
class _Estimate:
    """Global error estimate of the finest finite run, in units of the tolerance."""

    value: float       # estimated max |error| / (atol + rtol |x|); inf when not known
    accept: bool       # the tolerance is met
    next_m: int        # substeps per interval to try next (0: stop, round-off floor)
    trusted: bool = False  # the runs were seen in the asymptotic range


def _estimate(runs: dict, rtol, atol, asymptotic: bool) -> _Estimate:
    """Richardson estimate from the finite runs (substeps per interval ``a < b < c``).

    ``e_c = d_bc / ((c/b)^8 - 1)`` is the truncation error of run ``c`` if the runs are in
    the asymptotic range. That is checked: ``d_ab / d_bc`` must be within a factor 4 of
    ``(a^-8 - b^-8) / (b^-8 - c^-8)``, and ``d_bc`` must stand 4x clear of the modelled
    round-off ``rho`` of run ``c`` (`_roundoff`, an upper bound: ``n eps max|x|``).

    * Trusted: accepted when ``e_c + rho <= 0.5``.
    * Untrusted: ``c >= 2 b`` with ``2 d_bc <= 1``: ``e_c <= d_bc`` for any convergent
      method of order >= 1, and the (amplified) round-off of run ``c`` is about that of run
      ``b`` and independent of it, so it shows in ``d_bc`` as well: the estimate is
      ``2 d_bc``. (Near a separatrix the round-off of 70 000 steps grew to 1.5x the
      tolerance while ``d_bc`` was 0.79.)
    * Measured: after the runs were seen in the asymptotic range, ``2 d_bc <= 0.5`` with
      ``(c/b)^6 >= 2`` is accepted on the same grounds, even where the model ``rho``
      (often 10-100x pessimistic) says the tolerance lies below the round-off floor.
    * Two runs whose estimate already meets the tolerance: the next run is the coarser
      ``b // 2`` (cheap), to test the order on a triple.
    * ``d_bc`` at the modelled round-off level after an earlier trusted triple: accepted
      when ``e_c + rho <= 1``.
    * The differences no longer shrinking (``d_bc > d_ab / 2`` although truncation alone
      would shrink them ``(c/b)^8 >= 6``-fold) while three runs agree within a quarter of
      the tolerance: truncation is below the rounding; accepted at ``2 max(d_ab, d_bc)``.
      Otherwise that is the measured round-off floor:
      ``next_m = 0`` (stop). At the modelled level otherwise, the next run doubles the steps.
    * Otherwise the next count aims at ``e = 0.1`` (1.25x to 8x the last count).
    """
    order = 8
    finite = sorted(m for m, r in runs.items() if r.ok)
    if not finite:
        return _Estimate(math.inf, False, 8 * max(runs))
    c = finite[-1]
    xc = runs[c].x[:, 1:]
    scale = atol[:, None] + rtol * np.abs(xc)
    rho = _roundoff(runs[c].x, runs[c].n_steps, scale)
    if len(finite) == 1:
        return _Estimate(math.inf, False, 2 * c if c == max(runs) else 8 * max(runs))
    b = finite[-2]
    d_bc = _scaled_diff(runs[b].x[:, 1:], xc, scale)
    e_c = d_bc / ((c / b) ** order - 1)
    # Accept on a two-orders-lower extrapolation: pre-asymptotic triples can look 8th order
    # (measured: runs 1, 2, 7 steps looked order 7.7, and the 8th-order estimate was 22x low).
    e_acc = d_bc / ((c / b) ** (order - 2) - 1)
    trusted, d_ab = False, math.inf
    if len(finite) >= 3:
        a = finite[-3]
        d_ab = _scaled_diff(runs[a].x[:, 1:], runs[b].x[:, 1:], scale)
        if 4 * rho < d_bc < math.inf:
            predicted = (a ** -order - b ** -order) / (b ** -order - c ** -order)
            trusted = 0.25 <= (d_ab / d_bc) / predicted <= 4.0
    # A triple of very coarse runs can look 8th order by coincidence (runs of 1, 2, 4 steps
    # matched the predicted ratio to 7% while the 4-step error was 12x the estimate): below
    # `_AUTO_CONFIRM` steps (cheap) a second trusted triple is asked for.
    confirmed = asymptotic or runs[c].n_steps >= _AUTO_CONFIRM
    if trusted and confirmed and e_acc + rho <= _AUTO_ACCEPT:
        return _Estimate(e_acc + rho, True, c, True)
    if trusted and e_acc + rho <= _AUTO_ACCEPT:
        return _Estimate(e_acc + rho, False, math.ceil(1.25 * c), True)
    if c >= 2 * b and 2 * d_bc <= 1.0 and confirmed:
        return _Estimate(2 * d_bc, True, c, trusted)
    if asymptotic and (c / b) ** (order - 2) >= 2 and 2 * d_bc <= _AUTO_ACCEPT:
        return _Estimate(2 * d_bc, True, c, trusted)
    if len(finite) == 2 and b > 1 and e_acc + rho <= _AUTO_ACCEPT:
        return _Estimate(math.inf, False, b // 2)  # a cheap coarser run to check the order
    if d_bc <= 4 * rho and asymptotic and e_acc + rho <= 1.0:
        return _Estimate(e_acc + rho, True, c, trusted)
    if d_bc > 0.5 * d_ab and 2 * max(d_ab, d_bc) <= _AUTO_ACCEPT:
        # three runs agree within the tolerance and more steps no longer shrink their
        # differences: truncation is below the rounding, which the differences show
        return _Estimate(2 * max(d_ab, d_bc), True, c, trusted)
    if d_bc > 0.5 * d_ab and (d_bc <= 4 * rho or d_bc <= 1e4 or asymptotic):
        # (differences above 1e4 tolerances that do not shrink are runs before the
        # asymptotic range, not a round-off floor)
        # more steps no longer shrink the differences (truncation alone would shrink them
        # (c/b)^8 >= 6x): the measured round-off floor; stop
        return _Estimate(d_bc + e_c, False, 0, trusted)
    if d_bc <= 4 * rho:  # the runs agree to the modelled round-off: try twice the steps
        return _Estimate(d_bc + rho, False, 2 * c, trusted)
    if math.isfinite(e_c) and e_c > 0:
        nxt = c * (e_c / _AUTO_AIM) ** (1.0 / order)
    else:
        nxt = 8 * c
    nxt = min(max(math.ceil(nxt), math.ceil(1.25 * c)), 8 * c)
    return _Estimate(e_c + rho if trusted else math.inf, False, int(nxt), trusted)


def _spectrum(problem: _Problem) -> tuple[float, float] | None:
    """``(rho, sigma)`` [1/s] from the eigenvalues ``lam`` of ``df/dx`` at ``x0``: the
    spectral radius ``max |lam|`` (what explicit stability must resolve) and the fastest
    decay that only an implicit method steps over cheaply, ``max(-Re lam)`` over the
    eigenvalues with ``Re lam < 0`` and ``|Im lam| <= |Re lam|`` (oscillatory modes must be
    resolved by any method, so they do not count). None when it cannot be evaluated."""
    model = problem.model
    key = ("jac_x", _fkey(model.f))

    def build():
        x, u, p = (ca.MX.sym(n, model.f.sparsity_in(n)) for n in ("x", "u", "p"))
        xdot = model.f.call({"x": x, "u": u, "p": p})["xdot"]
        return ca.Function("jac_x", [x, u, p], [ca.jacobian(xdot, x)])

    t0, H0 = float(problem.t[0]), float(problem.t[1] - problem.t[0])
    u0 = problem.control.at(t0, 0, t0, H0)
    try:
        J = np.asarray(_CACHE.get(key, build, keepalive=model.f)(problem.x0, u0, problem.p),
                       dtype=float)
        lam = np.linalg.eigvals(J)
    except (RuntimeError, np.linalg.LinAlgError):
        return None
    if not np.all(np.isfinite(lam)):
        return None
    decay = -lam.real
    stiff = (decay > 0) & (np.abs(lam.imag) <= decay)
    return float(np.max(np.abs(lam), initial=0.0)), float(np.max(decay[stiff], initial=0.0))


def _auto(problem: _Problem, rtol, atol, max_steps, jit_pref, progress: _Progress):
    """Run ``rk8`` with step counts chosen until the global error estimate meets the tolerance.

    Returns ``(run or None, estimate, status, reason, total_steps, total_rhs)``: ``None`` and
    reason ``"stiff"`` hand the problem to `_auto_cvodes`. ``status`` is ``_OK``,
    ``_ROUNDOFF`` (the tolerance lies below the round-off floor) or ``_UNVERIFIED`` (not
    within ``max_steps`` or the run budget); the best run found is returned with them.
    """
    nint = problem.nint
    horizon = float(problem.t[-1] - problem.t[0])
    Hmax = float(np.max(np.diff(problem.t)))
    spectrum = _spectrum(problem)
    if spectrum is None:
        _, lipschitz = _initial_step(problem, rtol, atol, 8)
        sigma = 0.0
    else:
        lipschitz, sigma = spectrum
    if horizon * sigma / _RK8_STABILITY > _STIFF_STEPS:
        return (None, math.nan, 0, f"stiff: a decay rate of {sigma:.3g}/s needs "
                f"~{horizon * sigma / _RK8_STABILITY:.3g} explicit steps for stability alone",
                0, 0)
    stable = nint * max(1.0, Hmax * lipschitz / _RK8_STABILITY)
    if stable > max_steps:
        return (None, math.nan, _UNVERIFIED,
                f"explicit stability alone needs ~{stable:.3g} rk8 steps (spectral radius "
                f"{lipschitz:.3g}/s over {horizon:.6g} s) > max_steps = {max_steps}", 0, 0)
    # Start from the count explicit stability needs (cheap at loose tolerances: the order-8
    # prediction then jumps to the count the tolerance needs); Hairer's accuracy heuristic
    # is tolerance-blind here and started 2-4x too fine (measured in bench/simulate.py).
    m = max(1, math.ceil(Hmax * lipschitz / 2))
    runs: dict[int, _Run] = {}
    total = [0, 0]
    asymptotic = False
    calls = _CACHE.uses(_chunk_key(problem.model, "rk8", problem.control.mode) + ("auto",))
    _CACHE.get(_chunk_key(problem.model, "rk8", problem.control.mode) + ("auto",),
               lambda: True, keepalive=problem.model.f)
    est = _Estimate(math.inf, False, m)
    reason = ""
    while True:
        if m * nint > max_steps:
            reason = (f"the tolerance needs ~{m * nint:.3g} rk8 steps ({m} per output interval "
                      f"predicted) > max_steps = {max_steps}")
            break
        if m in runs or len(runs) >= _AUTO_RUNS:
            reason = f"the error estimates did not settle in {len(runs)} runs"
            break
        run = _run_fixed(_perturbed(problem, m), "rk8", m,
                         _auto_jit(problem, m, jit_pref, calls), progress)
        run.x[:, 0] = problem.x0
        runs[m] = run
        total[0] += run.n_steps
        total[1] += run.n_rhs
        if not run.ok and any(not r.ok and 8 * k <= m and _first_bad(r.x) == _first_bad(run.x)
                              for k, r in runs.items()):
            return run, math.inf, _FAILED, "", *total  # 8x finer steps did not help: blow-up
        if len(runs) == 1:
            m = 2 * m
            continue
        est = _estimate(runs, rtol, atol, asymptotic)
        asymptotic = asymptotic or est.trusted
        if est.accept:
            best = runs[max(k for k, r in runs.items() if r.ok)]
            floor, extra = _floor(problem, best, rtol, atol, lipschitz,
                                  _auto_jit(problem, best.substeps, jit_pref, calls), progress)
            total[0] += extra
            total[1] += extra * _DOP853.stages
            if est.value + floor > 1.0:
                return best, est.value + floor, _ROUNDOFF, "", *total
            return best, est.value, _OK, "", *total
        if est.next_m == 0:
            return (runs[max(k for k, r in runs.items() if r.ok)], est.value, _ROUNDOFF, "",
                    *total)
        m = est.next_m
    finite = [k for k, r in runs.items() if r.ok]
    best = runs[max(finite)] if finite else (runs[max(runs)] if runs else None)
    return best, est.value, _UNVERIFIED, reason, *total


def _floor(problem: _Problem, run: _Run, rtol, atol, lipschitz: float, jit: bool,
           progress) -> tuple[float, int]:
    """Scaled error floor of ``run`` from rounding; returns ``(floor, extra steps made)``.

    Rounding that every run shares (the model's own formulas) does not show in differences
    between runs, so it is measured. ``f`` is evaluated at up to 16 states of ``run`` and
    again with those states moved by one ulp in random sign patterns; the largest change
    ``noise_i`` is the rounding noise of ``f_i``, catastrophic cancellation included
    (``w x (I w)`` of I = (1, 1e4, 1e4) rounds to 1e4 eps |w2 w3|). While the state changes
    little, over a time ``tau = 1 / L`` (``L`` the spectral radius at ``x0``), the rounding
    repeats and adds up linearly; beyond, at random: ``e_i = 2 sqrt(T min(T, tau)) noise_i``
    over the horizon ``T`` (2 for the sampled noise; measured on that body: 1.1e-12 after
    1 s where the samples gave 5.5e-13/s, while a Richardson triple looked 8th order).
    If ``max_i e_i``, grown by ``1 + L T``, is far
    inside the smallest tolerance of any state, that bound is the floor; otherwise the
    flow's real amplification is measured by repeating ``run`` from ``x0 + e`` (random
    signs, same steps): the floor is the scaled difference (an error injected at the start,
    the worst time for it). The floor is never below ``_FLOOR_ULPS`` ulps of a state's size
    (the rounding of the state itself, shared alike: near a separatrix every run, rk8 at
    16-400 steps per interval and scipy's DOP853 alike, was off by 900 ulps of ``|w|``
    while they agreed to 90).
    """
    x, model = run.x, problem.model
    horizon = float(problem.t[-1] - problem.t[0])
    cols = np.unique(np.linspace(0, x.shape[1] - 1, min(16, x.shape[1])).round().astype(int))
    rng = np.random.default_rng(0)
    X = x[:, cols]
    pert = [X] + [X * (1 + _EPS * rng.choice((-1.0, 1.0), size=X.shape)) for _ in range(3)]
    if problem.control.mode == "linear":
        U = problem.control.grid(problem.t)[:, cols]
    else:
        U = np.stack([problem.control.fun(float(problem.t[c])) for c in cols], axis=1)
    F = _map_eval(model.f, [np.concatenate(pert, axis=1), np.tile(U, (1, len(pert))),
                            problem.p]).reshape(model.nx, len(pert), cols.size)
    if not np.all(np.isfinite(F)):
        return math.inf, 0
    noise = np.max(np.abs(F[:, 1:] - F[:, :1]), axis=(1, 2))
    tau = horizon if lipschitz <= 0 else min(horizon, 1.0 / lipschitz)
    e = 2 * math.sqrt(horizon * tau) * noise
    scale = atol[:, None] + rtol * np.abs(x[:, 1:])
    ulps = _roundoff(x, _FLOOR_ULPS, scale)
    local = _scaled_diff(np.broadcast_to(e[:, None], scale.shape), np.zeros(scale.shape), scale)
    # the flow may carry the noise of any state into any other (the spin-rate noise of a
    # flat body into the phase of its transverse rates): a screening bound across states
    bound = float(np.max(e)) * (1 + lipschitz * horizon) / float(np.min(scale))
    if bound <= 0.1 * _AUTO_ACCEPT:
        return max(bound, ulps), 0
    signs = rng.choice((-1.0, 1.0), size=e.size)
    check = _run_fixed(replace(problem, x0=problem.x0 + signs * e), "rk8", run.substeps, jit,
                       progress)
    return max(local, ulps, _scaled_diff(check.x[:, 1:], x[:, 1:], scale)), check.n_steps


def _perturbed(problem: _Problem, m: int) -> _Problem:
    """``problem`` with ``x0`` moved by 2 ulp in a sign pattern that differs between step
    counts ``m`` (reproducibly): the differences between ``auto``'s runs then also show how
    strongly the problem amplifies double-precision representation errors (of ``x0`` and of
    the model's constants, rounded alike). Near a separatrix this amplification put a common
    error of 3e-13 into every run at 16-400 steps per interval that step-count differences
    alone cannot see; a well-conditioned problem just carries the 2 ulp."""
    signs = np.random.default_rng(m).choice((-1.0, 1.0), size=problem.x0.size)
    return replace(problem, x0=problem.x0 + 2 * _EPS * signs * problem.x0)


def _first_bad(x: np.ndarray) -> int:
    """Index of the first output time with a non-finite state (``x.shape[1]`` if none)."""
    bad = ~np.isfinite(x).all(axis=0)
    return int(np.argmax(bad)) if bad.any() else x.shape[1]


def _auto_jit(problem: _Problem, m: int, jit_pref, calls: int) -> bool:
    """jit for auto's runs: forced by ``jit``; else when large, already compiled, or when
    ``auto`` has run this model before (``calls`` earlier calls)."""
    if jit_pref is not None:
        return bool(jit_pref)
    if m * problem.nint * _DOP853.stages >= _AUTO_INTERPRET or calls >= 2:
        return True
    return _CACHE.contains(_chunk_key(problem.model, "rk8", problem.control.mode) + (True,))


def _auto_cvodes(problem: _Problem, rtol, atol, extra):
    """cvodes for a stiff problem, with its global error estimated: runs at local tolerances
    ``tol / 10, tol / 1000, ...`` until two successive runs agree within the tolerance; the
    tighter run is returned with their scaled difference as its (conservative) error
    estimate. Returns ``(run, estimate, status, n_steps, n_rhs)``."""
    total = [0, 0]
    prev, estimate = None, math.inf
    factor = 0.1
    while True:
        r, a = rtol * factor, atol * factor
        run = _run_cvodes(problem, max(r, _CVODES_RTOL_MIN), a, extra)
        total[0] += run.n_steps
        total[1] += run.n_rhs
        if not run.ok:
            return run, math.nan, _FAILED, *total
        if prev is not None:
            scale = atol[:, None] + rtol * np.abs(run.x[:, 1:])
            estimate = _scaled_diff(prev.x[:, 1:], run.x[:, 1:], scale)
            if estimate <= 1.0:
                return run, estimate, _OK_STIFF, *total
        if r <= _CVODES_RTOL_MIN:
            return run, estimate, _UNVERIFIED, *total
        prev, factor = run, factor * 1e-2


# ============================================================================ simulate
def simulate(model: Model, x0, t, *, u=None, p=None, method: Method = "auto",
             rtol: float = 1e-8, atol=1e-10, invariants=False, steps: int | None = None,
             jit: bool | None = None, max_steps: int = 100_000_000,
             cvodes_options: Mapping | None = None,
             progress: Callable[[int, int], None] | None = None) -> SimulationResult:
    """Integrate ``xdot = f(x, u, p)`` of ``model`` from ``x0`` over the grid ``t``.

    Parameters
    ----------
    model : Model
        The dynamics (``model.f``: ``(x, u, p) -> xdot``).
    x0 : array_like, shape (nx,)
        State at ``t[0]``, in the model's units.
    t : array_like, shape (n,) [s]
        Output times, strictly increasing, ``n >= 2``. Fixed-step methods step exactly onto
        every output time.
    u : None, array_like (nu,) or (nu, n), or callable, optional
        Control [model units]: ``None`` is zero; a constant; samples on ``t``, linear in time
        between samples; or ``u(t) -> (nu,)`` for a float ``t`` [s], called at every stage
        time (fixed step) or right-hand-side evaluation (cvodes).
    p : array_like, shape (np,), optional
        Parameters; the model's defaults when omitted.
    method : {'auto', 'cvodes', 'rk4', 'rk8', 'lie'}
        * ``'rk4'``, ``'rk8'`` (DOP853's 8th-order weights), ``'lie'`` (CF4 on the quaternion,
          RK4 on the other states; needs ``model.attitude``): fixed step, ``steps`` steps per
          output interval, run by one compiled chunk Function of 512 steps called in a
          loop (the code and its compile time do not depend on the grid or step count).
        * ``'cvodes'``: SUNDIALS CVODES (BDF by default) through ``casadi.integrator`` with
          ``rtol``/``atol`` as its local tolerances (the smallest ``atol`` when a vector).
        * ``'auto'``: ``rk8`` with the step count chosen from global error estimates so
          that ``|error| <= atol + rtol |x|`` at every output time (Richardson estimates
          from runs with different step counts, checked for 8th-order behaviour; see
          `_estimate`). A stiff problem (a decaying mode of the Jacobian at ``x0`` faster
          than ``1e6`` explicit steps over the horizon can follow) goes to cvodes, whose
          global error is then estimated from runs at tightened local tolerances
          (``status`` 1). A tolerance that cannot be verified is ``success=False`` with
          ``status`` 2 (round-off floor) or 3 (``max_steps``); never a silent fallback.
    rtol : float, optional
        Relative tolerance, ``100 eps <= rtol < 1`` (used by ``auto`` and ``cvodes``).
    atol : float or array_like (nx,), optional
        Absolute tolerance [state units], ``>= 0``.
    invariants : bool or sequence of str, optional
        Evaluate all (``True``) or the named ``model.invariants`` along the solution.
    steps : int, optional
        Fixed-step methods only: steps per output interval (default 1: the grid is the step).
    jit : bool, optional
        Compile the loops to C (``True``), never (``False``), or by default compile every
        fixed-step loop when a C compiler is found, except that ``auto`` runs small
        first-time estimation loops interpreted (compiling them costs more than running
        them; they are compiled from their third use on). Compiled loops are cached.
    max_steps : int, optional
        ``auto``: most rk8 steps in one run (default 1e8, about 20 s); a tolerance that
        needs more is reported as ``status`` 3, not attempted.
    cvodes_options : mapping, optional
        Extra options for ``casadi.integrator('cvodes')`` over casadi's defaults (BDF,
        ``max_num_steps`` 10 000 per output interval), e.g.
        ``{'linear_multistep_method': 'adams'}`` (about 2x fewer steps than BDF on a
        non-stiff tumbling body).
    progress : callable, optional
        ``progress(done, total)`` is called after every chunk of 512 fixed steps with the
        steps done and planned so far (``total`` grows when ``auto`` starts another run);
        for a progress line on long runs. Not called by ``cvodes``.

    Returns
    -------
    SimulationResult
        ``t``, ``x (nx, n)``, ``success``, ``status``, ``message``, ``method``, ``wall_time``,
        ``n_steps``, ``n_rhs``, ``substeps``, ``error_estimate``, ``compiled``,
        ``invariants`` and ``sample(t)``.

    Raises
    ------
    TypeError
        If ``model`` is not a `Model`.
    ValueError
        Naming the argument: non-finite or wrongly shaped ``x0``, ``t`` not strictly
        increasing or shorter than 2, ``u`` or ``p`` of the wrong shape (also a callable
        ``u`` returning the wrong shape), an unknown ``method``, bad ``rtol``/``atol``,
        ``steps`` with a method that does not take it, ``'lie'`` on a model without an
        attitude, unknown ``invariants``, an attitude quaternion in ``x0`` whose norm is
        not 1 to 1e-6, an unknown or ill-typed ``cvodes_options`` entry.
        ``TypeError`` for ``cvodes_options`` that is not a mapping.

    Notes
    -----
    A numerical failure (cvodes gives up, a fixed-step state becomes non-finite) returns
    ``success=False`` with the reason; it never raises. An exception raised by a callable
    ``u`` propagates.
    """
    start = time.perf_counter()
    model = _check_model(model)
    if method not in METHODS:
        raise ValueError(f"`method` must be one of {METHODS}, got {method!r}")
    t = _check_t(t)
    x0 = _check_x0(x0, model)
    p = model.resolve_p(p)
    rtol, atol = _check_tolerances(rtol, atol, model.nx)
    control = _check_u(u, model.nu, t)
    names = _check_invariants(invariants, model)
    max_steps = _check_int(max_steps, "max_steps")
    if jit not in (None, True, False):
        raise ValueError(f"`jit` must be None, True or False, got {jit!r}")
    if method in _FIXED_STEP:
        steps = 1 if steps is None else _check_int(steps, "steps")
    elif steps is not None:
        raise ValueError(f"`steps` applies to the fixed-step methods {_FIXED_STEP}, not {method!r}")
    cvodes_options = _check_cvodes_options(cvodes_options)
    if method == "lie":
        _check_lie_model(model, x0, p)

    if progress is not None and not callable(progress):
        raise TypeError(f"`progress` must be None or a callable (done, total), "
                        f"got {type(progress).__name__}")
    counter = _Progress(progress)
    problem = _Problem(model, x0, t, control, p)
    used, status, estimate = method, _OK, math.nan
    if method in _FIXED_STEP:
        run = _run_fixed(problem, method, steps, jit is not False, counter)
    elif method == "cvodes":
        run = _run_cvodes(problem, rtol, atol, cvodes_options)
    else:
        run, used, status, estimate = _solve_auto(problem, rtol, atol, max_steps, jit,
                                                  cvodes_options, counter)
    x = run.x
    x.setflags(write=False)
    values = _invariants(model, x, p, names)
    success = run.ok and status in (_OK, _OK_STIFF)
    return SimulationResult(
        t=t, x=x, success=success, status=status if run.ok else _FAILED, message=run.message,
        method=used, wall_time=time.perf_counter() - start, n_steps=run.n_steps, n_rhs=run.n_rhs,
        substeps=run.substeps, error_estimate=estimate, compiled=run.compiled,
        invariants=MappingProxyType(values),
        _dense=_Dense(model, p, lambda: control.grid(t)),
    )


def _invariants(model: Model, x: np.ndarray, p: np.ndarray, names) -> dict:
    out = {}
    for name in names:
        value = np.asarray(model.invariant(name, x, p))
        value.setflags(write=False)
        out[name] = value
    return out


def _drift(model: Model, x: np.ndarray, p: np.ndarray) -> dict:
    """``max_t |I(t) - I(t[0])|`` relative to ``|I(t[0])|`` for each invariant of ``model``."""
    out = {}
    if not np.all(np.isfinite(x)):
        return {name: math.nan for name in model.invariants}
    for name, fun in model.invariants.items():
        v = _map_eval(fun, [x, p])
        diff = np.linalg.norm(v - v[:, :1], axis=0)
        ref = float(np.linalg.norm(v[:, 0]))
        out[name] = float(np.max(diff)) / ref if ref > 0 else float(np.max(diff))
    return out


def _solve_auto(problem: _Problem, rtol, atol, max_steps, jit, cvodes_options, progress):
    """``auto``: -> (run, method used, status, error estimate); counters cover every run."""
    run, estimate, status, reason, n_steps, n_rhs = _auto(problem, rtol, atol, max_steps, jit,
                                                          progress)
    if run is None and reason.startswith("stiff"):
        crun, estimate, status, cs, cr = _auto_cvodes(problem, rtol, atol, cvodes_options)
        verdict = {_OK_STIFF: f"estimated error {estimate:.2g} of tolerance (from runs at "
                              "tightened local tolerances)",
                   _UNVERIFIED: f"the tolerance could not be verified (estimated error "
                                f"{estimate:.2g} of tolerance at the tightest local tolerance)",
                   _FAILED: "the integration failed"}[status]
        message = f"auto: {reason}: used cvodes; {verdict}. {crun.message}"
        return (_Run(crun.x, n_steps + cs, n_rhs + cr, 0, False, crun.ok, message), "cvodes",
                status, estimate)
    if run is None:
        x = np.full((problem.model.nx, problem.t.size), np.nan)
        x[:, 0] = problem.x0
        return (_Run(x, 0, 0, 0, False, True, f"auto: tolerance not verified: {reason}; "
                     "no run was made (raise max_steps or shorten the grid)"), "rk8", status,
                math.nan)
    if not run.ok:
        return (_Run(run.x, n_steps, n_rhs, run.substeps, run.compiled, False,
                     f"auto: {run.message}"), "rk8", _FAILED, estimate)
    if status == _ROUNDOFF:
        message = ("auto: tolerance not verified: it lies at the round-off floor of fixed-step "
                   f"runs on this grid ({run.message}; estimated error incl. modelled round-off "
                   f"{estimate:.2g} of tolerance); x is the best solution found")
    elif status == _UNVERIFIED:
        message = (f"auto: tolerance not verified: {reason} ({run.message}; estimated error "
                   f"{estimate:.2g} of tolerance); x is the best solution found")
    else:
        message = f"auto: {run.message}; estimated error {estimate:.2g} of tolerance"
    return (_Run(run.x, n_steps, n_rhs, run.substeps, run.compiled, True, message), "rk8",
            status, estimate)
