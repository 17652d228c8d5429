"""Simulation of a `Model` on a time grid: compiled fixed-step loops, a Lie-group integrator,
SUNDIALS CVODES, and an ``auto`` mode that meets a requested global tolerance.

Every fixed-step integration (``rk4``, ``rk8``, ``lie`` and the runs ``auto`` makes) is ONE
CasADi Function: a ``mapaccum`` over the substeps of an output interval nested in a
``mapaccum`` over the intervals, wrapped in an MX Function (so the generated code is a loop,
never an unrolled SX graph) and jit-compiled to C when a C compiler is present. Built
Functions are cached by their defining arguments (right-hand side, method, control mode,
substeps, number of intervals), and they are called through ``Function.buffer()`` so that a
repeated call costs microseconds of Python, not a data conversion per element.

Costs measured on a 2-core machine (rigid body, 7 states): per step about 55 ns (rk4),
140 ns (lie), 180 ns (rk8) compiled, 2-3 us interpreted; about 55 us of Python per call.
Building a loop costs about 13 us per rk8 step (casadi's activity analysis runs over every
step each time a call node is created) plus 0.3-0.5 s of C compilation: the first call of a
100 000-step rk8 loop takes ~2 s, later calls ~18 ms.

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

import math
import shutil
import tempfile
import threading
import time
import weakref
from collections import OrderedDict
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Callable, Literal, Mapping

import casadi as ca
import numpy as np

from .attitude import propagate_quat, quat_rate
from .model import Model

__all__ = ["simulate", "SimulationResult", "METHODS"]

Method = Literal["auto", "cvodes", "rk4", "rk8", "lie"]
METHODS = ("auto", "cvodes", "rk4", "rk8", "lie")
_FIXED_STEP = ("rk4", "rk8", "lie")

_EPS = np.finfo(float).eps
_BASE = 4  # unroll base of mapaccum: casadi's construction cost grows ~5x from base 4 to 10

# status codes of SimulationResult
_OK, _OK_FALLBACK, _ROUNDOFF, _FAILED = 0, 1, 2, -1


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
        self._lock = threading.Lock()

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
        True when the integration reached ``t[-1]`` with finite states. Whether ``auto``
        met the tolerance is in ``status`` and ``error_estimate``.
    status : int
        ``0`` success (``auto``: the estimated global error is within tolerance); ``1``
        success of ``auto`` through its cvodes fallback (the tolerance is then cvodes' local
        error control, not a verified global error); ``2`` success of ``auto``, but the
        tolerance lies at or below the round-off floor of fixed-step runs on this grid and
        could not be verified: ``x`` is the best solution found, ``error_estimate`` (> 1,
        modelled round-off included) says how far off; ``-1`` failure (integrator error, or
        a non-finite state).
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


def _check_x0(x0, nx: int) -> np.ndarray:
    try:
        x = np.array(x0, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"`x0` must be a vector of {nx} numbers: {exc}") from None
    if x.shape not in ((nx,), (nx, 1)):
        raise ValueError(f"`x0` must have shape ({nx},), got {x.shape}")
    x = x.reshape(nx)
    if not np.isfinite(x).all():
        raise ValueError(f"`x0` must be finite, got {x.tolist()}")
    return x


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
def _loop(model: Model, method: str, mode: str, m: int, nint: int, jit: bool):
    """The whole fixed-step integration as one Function (cached); returns (Function, compiled).

    Inputs ``mode == 'linear'``: ``x0 (nx)``, ``H (1 x nint)`` interval lengths,
    ``UA, UB (nu x nint)`` control at interval starts/ends, ``P (np x nint)``.
    ``mode == 'stages'``: ``x0``, ``H``, ``US (nu*s x m*nint)`` control at the distinct
    stage nodes of every step, ``P``. Output ``X (nx x nint)``: the states at ``t[1:]``.
    """
    base_key = ("loop", _fkey(model.f), model.attitude if method == "lie" else None,
                method, mode, m, nint)
    opts = _CACHE.jit_options() if jit else None
    if opts is None:
        return _CACHE.get(base_key + (False,),
                          lambda: (_build_loop(model, method, mode, m, nint, {}), False),
                          keepalive=model.f)

    def build_compiled():
        try:
            return _build_loop(model, method, mode, m, nint, opts), True
        except RuntimeError:  # e.g. a right-hand side that cannot be code-generated
            return _build_loop(model, method, mode, m, nint, {}), False

    return _CACHE.get(base_key + (True,), build_compiled, keepalive=model.f)


def _build_loop(model, method, mode, m, nint, opts) -> ca.Function:
    step = _kernel(model, method, mode)
    nx, nu, np_ = model.nx, model.nu, model.np
    n_nodes = len(_unique_nodes(method))
    xk, H, p = ca.MX.sym("x", nx), ca.MX.sym("H"), ca.MX.sym("p", np_)
    h = H / m
    if mode == "linear":
        ua, ub = ca.MX.sym("ua", nu), ca.MX.sym("ub", nu)
        ud = (ub - ua) / H
        if m == 1:
            xn = step(xk, h, ua, ud, p)
        else:
            offsets = ca.DM(np.arange(m, dtype=float)).T * h  # substep start - interval start
            u_sub = ca.repmat(ua, 1, m) + ca.mtimes(ud, offsets)
            xn = step.mapaccum("substeps", m, {"base": _BASE})(xk, h, u_sub, ud, p)[:, -1]
        interval = ca.Function("interval", [xk, H, ua, ub, p], [xn])
    else:
        us = ca.MX.sym("us", nu * n_nodes, m)
        if m == 1:
            xn = step(xk, h, us, p)
        else:
            xn = step.mapaccum("substeps", m, {"base": _BASE})(xk, h, us, p)[:, -1]
        interval = ca.Function("interval", [xk, H, us, p], [xn])
    loop = interval.mapaccum("intervals", nint, {"base": _BASE})
    ins = [ca.MX.sym(loop.name_in(i), loop.sparsity_in(i)) for i in range(loop.n_in())]
    return ca.Function(f"simulate_{method}", ins, loop.call(ins), opts)


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


def _run_fixed(problem: _Problem, method: str, m: int, jit: bool) -> _Run:
    model, nint = problem.model, problem.nint
    fun, compiled = _loop(model, method, problem.control.mode, m, nint, jit)
    H = np.diff(problem.t)
    P = np.broadcast_to(problem.p, (nint, model.np))
    if problem.control.mode == "linear":
        args = [problem.x0, H, problem.control.ua, problem.control.ub, P]
    else:
        args = [problem.x0, H, _stage_samples(problem, method, m), P]
    out = _call(fun, args, (nint, model.nx))
    x = np.concatenate([problem.x0[:, None], out.T], axis=1)
    n_steps = m * nint
    stages = 4 if method == "lie" else _TABLEAUX[method].stages
    if not np.isfinite(out).all():
        k = int(np.argmax(~np.isfinite(x).all(axis=0)))
        x[:, k:] = np.nan
        return _Run(x, n_steps, stages * n_steps, m, compiled, False,
                    f"{method}: the state became non-finite before t = {problem.t[k]}")
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
_AUTO_ROUNDOFF = 0.5   # stop refining when round-off alone would use this much of the tolerance
_AUTO_RUNS = 8         # give up (fall back to cvodes) after this many fixed-step runs
_AUTO_INTERPRET = 500_000  # RHS evaluations below which a first-time run is interpreted
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
    round-off ``rho`` of run ``c`` (`_roundoff`; runs b and c add at most ``2 rho``).

    * Trusted: accepted when ``e_c + rho <= 0.5``.
    * Untrusted: ``c >= 2 b`` with ``d_bc <= 1`` still bounds the error (``e_c <= d_bc``
      for any convergent method of order >= 1; ``d_bc`` contains the round-off differences).
    * Two runs whose estimate already meets the tolerance: the next run is the coarser
      ``b // 2`` (cheap), to test the order on a triple.
    * ``d_bc`` at round-off level after an earlier trusted triple (``asymptotic``):
      accepted when ``e_c + rho <= 1``.
    * Otherwise the next count aims at ``e = 0.1``, or, when round-off would exceed the
      tolerance first, where truncation equals round-off; ``next_m = 0`` means stop there.
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
        return _Estimate(math.inf, False, 2 * c)
    b = finite[-2]
    d_bc = _scaled_diff(runs[b].x[:, 1:], xc, scale)
    e_c = d_bc / ((c / b) ** order - 1)
    trusted = False
    if len(finite) >= 3 and 4 * rho < d_bc < math.inf:
        a = finite[-3]
        d_ab = _scaled_diff(runs[a].x[:, 1:], runs[b].x[:, 1:], scale)
        predicted = (a ** -order - b ** -order) / (b ** -order - c ** -order)
        trusted = 0.25 <= (d_ab / d_bc) / predicted <= 4.0
    if trusted and e_c + rho <= _AUTO_ACCEPT:
        return _Estimate(e_c + rho, True, c, True)
    if c >= 2 * b and d_bc <= 1.0:
        return _Estimate(d_bc, True, c, trusted)
    if len(finite) == 2 and b > 1 and e_c + rho <= _AUTO_ACCEPT:
        return _Estimate(math.inf, False, b // 2)  # a cheap coarser run to check the order
    if d_bc <= 4 * rho:  # the runs agree to round-off: truncation is below it
        if asymptotic and e_c + rho <= 1.0:
            return _Estimate(e_c + rho, True, c, trusted)
        return _Estimate(d_bc + rho, False, 2 * c if 2 * rho <= _AUTO_ROUNDOFF else 0, trusted)
    if math.isfinite(e_c) and e_c > 0:
        nxt = c * (e_c / _AUTO_AIM) ** (1.0 / order)
        if rho * nxt / c > _AUTO_ROUNDOFF:  # truncation = round-off is the best there is
            balance = c * (e_c / rho) ** (1.0 / (order + 1))
            nxt = balance if balance > 1.25 * c else 0
    else:
        nxt = 8 * c
    nxt = 0 if nxt == 0 else min(max(math.ceil(nxt), math.ceil(1.25 * c)), 8 * c)
    return _Estimate(e_c + rho if trusted else math.inf, False, int(nxt), trusted)


def _auto(problem: _Problem, rtol, atol, max_steps, jit_pref):
    """Run ``rk8`` with step counts chosen until the global error estimate meets the tolerance.

    Returns ``(run or None, estimate, reason, total_steps, total_rhs, status)``; ``None``
    asks for the cvodes fallback (``reason`` says why). ``status`` is 0, or 2 when the
    tolerance lies below the round-off floor (the best run found is returned).
    """
    nint = problem.nint
    Hmax = float(np.max(np.diff(problem.t)))
    _, lipschitz = _initial_step(problem, rtol, atol, 8)
    stable_steps = nint * math.ceil(Hmax * lipschitz / _RK8_STABILITY)
    if stable_steps > max_steps:
        return (None, math.nan, f"the problem looks stiff (Lipschitz estimate {lipschitz:.3g}/s: "
                f"explicit stability alone needs ~{stable_steps} steps > max_steps = {max_steps})",
                0, 0, 0)
    # Start from the count explicit stability needs (cheap at loose tolerances: the order-8
    # prediction then jumps to the count the tolerance needs); Hairer's accuracy heuristic
    # is tolerance-blind here and started 2-4x too fine (measured in bench/simulate.py).
    m0 = int(min(max(1, math.ceil(Hmax * lipschitz / 2)), max(1, 4096 // nint)))
    runs: dict[int, _Run] = {}
    total = [0, 0]
    m, asymptotic = m0, False
    while True:
        if m * nint > max_steps:
            return (None, math.nan, f"the tolerance needs more than max_steps = {max_steps} "
                    f"steps ({m} per output interval were predicted)", *total, 0)
        if m in runs or len(runs) >= _AUTO_RUNS:
            return None, math.nan, "the error estimates did not settle", *total, 0
        run = _run_fixed(problem, "rk8", m, _auto_jit(problem, m, jit_pref))
        runs[m] = run
        total[0] += run.n_steps
        total[1] += run.n_rhs
        if len(runs) == 1:
            m = 2 * m
            continue
        est = _estimate(runs, rtol, atol, asymptotic)
        asymptotic = asymptotic or est.trusted
        if est.accept or est.next_m == 0:
            best = max(k for k, r in runs.items() if r.ok)
            return runs[best], est.value, "", *total, 0 if est.accept else 2
        m = est.next_m


def _auto_jit(problem: _Problem, m: int, jit_pref) -> bool:
    """jit for auto's runs: forced by ``jit``; else when large, already compiled, or in use."""
    if jit_pref is not None:
        return bool(jit_pref)
    if m * problem.nint * _DOP853.stages >= _AUTO_INTERPRET:
        return True
    key = ("loop", _fkey(problem.model.f), None, "rk8", problem.control.mode, m, problem.nint)
    return _CACHE.contains(key + (True,)) or _CACHE.uses(key + (False,)) >= 2


# ============================================================================ simulate
def simulate(model: Model, x0, t, *, u=None, p=None, method: Method = "auto",
             rtol: float = 1e-8, atol=1e-10, invariants=False, steps: int | None = None,
             jit: bool | None = None, max_steps: int = 100_000,
             cvodes_options: Mapping | None = None) -> SimulationResult:
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
          output interval, the whole run one compiled CasADi loop.
        * ``'cvodes'``: SUNDIALS CVODES (BDF by default) through ``casadi.integrator`` with
          ``rtol``/``atol`` as its local tolerances (the smallest ``atol`` when a vector).
        * ``'auto'``: ``rk8`` with the step count chosen from global error estimates so
          that ``|error| <= atol + rtol |x|`` at every output time (Richardson estimates
          from runs with different step counts, checked for 8th-order behaviour; see
          `_estimate`), falling back to ``cvodes`` when that would take more than
          ``max_steps`` steps or the estimates do not settle (``status`` 1, and the message
          says why). A tolerance at the round-off floor gives ``status`` 2.
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
        ``auto``: most fixed-step steps in one run before falling back to cvodes.
    cvodes_options : mapping, optional
        Extra options for ``casadi.integrator('cvodes')`` over casadi's defaults (BDF,
        ``max_num_steps`` 10 000 per output interval), e.g.
        ``{'linear_multistep_method': 'adams'}`` (about 2x fewer steps than BDF on a
        non-stiff tumbling body).

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
        attitude, unknown ``invariants``.

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
    x0 = _check_x0(x0, model.nx)
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
    if cvodes_options is not None and not isinstance(cvodes_options, Mapping):
        raise ValueError(f"`cvodes_options` must be a mapping, got {type(cvodes_options).__name__}")
    if method == "lie":
        _check_lie_model(model, x0, p)

    problem = _Problem(model, x0, t, control, p)
    used, status, estimate = method, _OK, math.nan
    if method in _FIXED_STEP:
        run = _run_fixed(problem, method, steps, jit is not False)
    elif method == "cvodes":
        run = _run_cvodes(problem, rtol, atol, cvodes_options)
    else:
        run, used, status, estimate = _solve_auto(problem, rtol, atol, max_steps, jit,
                                                  cvodes_options)
    x = run.x
    x.setflags(write=False)
    return SimulationResult(
        t=t, x=x, success=run.ok, status=status if run.ok else _FAILED, message=run.message,
        method=used, wall_time=time.perf_counter() - start, n_steps=run.n_steps, n_rhs=run.n_rhs,
        substeps=run.substeps, error_estimate=estimate, compiled=run.compiled,
        invariants=MappingProxyType(_invariants(model, x, p, names)),
        _dense=_Dense(model, p, lambda: control.grid(t)),
    )


def _invariants(model: Model, x: np.ndarray, p: np.ndarray, names) -> dict:
    out = {}
    for name in names:
        value = np.asarray(model.invariant(name, x, p))
        value.setflags(write=False)
        out[name] = value
    return out


def _solve_auto(problem: _Problem, rtol, atol, max_steps, jit, cvodes_options):
    """``auto``: -> (run, method used, status, error estimate); counters cover every run."""
    run, estimate, reason, n_steps, n_rhs, status = _auto(problem, rtol, atol, max_steps, jit)
    if run is None:
        fallback = _run_cvodes(problem, rtol, atol, cvodes_options)
        message = (f"auto: {reason}; fell back to cvodes (local tolerances, global error not "
                   f"verified). {fallback.message}")
        return (_Run(fallback.x, n_steps + fallback.n_steps, n_rhs + fallback.n_rhs, 0, False,
                     fallback.ok, message), "cvodes", _OK_FALLBACK, math.nan)
    if status == _ROUNDOFF:
        message = ("auto: could not verify the tolerance, which is at the round-off floor of "
                   f"fixed-step runs on this grid ({run.message}; estimated error incl. modelled "
                   f"round-off {estimate:.2g} of tolerance); x is the best solution found")
    else:
        message = f"auto: {run.message}; estimated error {estimate:.2g} of tolerance"
    return (_Run(run.x, n_steps, n_rhs, run.substeps, run.compiled, run.ok, message), "rk8",
            status, estimate)
