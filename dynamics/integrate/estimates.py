"""The numerical estimates ``auto`` rests on (`dynamics.integrate.auto` and its one-pass
path): scaled differences of runs, the round-off floor of a run (modelled and measured),
the spectral radius and decay rate of the Jacobian at ``x0``, and the reproducible sign
patterns of the perturbations that expose rounding."""
from __future__ import annotations

import math

import casadi as ca
import numpy as np

from .. import cache
from .evaluate import call_buffered, map_eval
from .inputs import Problem
from .result import Run

__all__ = ["AUTO_ACCEPT", "EPS", "FLOOR_ULPS", "carried", "floor_signs", "initial_step",
           "jacobian_at", "jacobian_x", "measured_floor", "norm_bounds", "perturbed",
           "rho_sigma", "roundoff", "scaled_diff", "screen", "screens", "signs", "spectra",
           "spectrum", "table", "tightened"]

EPS = np.finfo(float).eps
AUTO_ACCEPT = 0.5     # accept a trusted estimate (truncation + round-off) below this
FLOOR_ULPS = 1000     # least error floor of a run in ulps of a state's size (`measured_floor`)
#: The most time constants ``L T`` over which `measured_floor` bounds the carried rounding's
#: growth by ``1 + L T`` instead of measuring it.
LINEAR_LT = 1.0


def scaled_diff(xa: np.ndarray, xb: np.ndarray, scale: np.ndarray) -> float:
    """max |xa - xb| / scale over states and output times; inf if anything is non-finite."""
    if not (np.all(np.isfinite(xa)) and np.all(np.isfinite(xb))):
        return math.inf
    diff = np.abs(xa - xb)
    ratio = np.divide(diff, scale, out=np.where(diff == 0, 0.0, np.inf), where=scale > 0)
    return float(ratio.max())


def tightened(run_at, rtol: float, atol: np.ndarray, first: float, ratio: float,
              tightest: float):
    """A global error estimate for a method with *local* error control (cvodes, DOP853 with
    step rejection): runs ``run_at(local_rtol, local_atol) -> Run`` at the local tolerances
    ``(rtol, atol) * f`` for ``f = first, first * ratio, ...`` (``local_rtol`` at least
    ``tightest``) until two successive runs differ by at most the tolerance ``atol + rtol
    |x|`` at the output times (scaled max). The tighter run is taken with that difference
    as its error estimate: conservative whenever it is at least twice as accurate as the
    other (a ``1 / ratio``-fold tighter local tolerance).

    Returns ``(run, verdict, estimate, n_steps, n_rhs)``: ``verdict`` ``"met"``;
    ``"tightest"`` (not met at ``tightest``: the last run); ``"failed"`` (a run failed:
    it is returned); ``None`` when ``run_at`` returned None (no such run can be made).
    """
    total = [0, 0]
    prev, estimate, factor = None, math.inf, first
    while True:
        local = rtol * factor
        run = run_at(max(local, tightest), atol * factor)
        if run is None:
            return None, None, math.nan, *total
        total[0] += run.n_steps
        total[1] += run.n_rhs
        if not run.ok:
            return run, "failed", math.nan, *total
        if prev is not None:
            scale = atol[:, None] + rtol * np.abs(run.x[:, 1:])
            estimate = scaled_diff(prev.x[:, 1:], run.x[:, 1:], scale)
            if estimate <= 1.0:
                return run, "met", estimate, *total
        if local <= tightest:
            return run, "tightest", estimate, *total
        prev, factor = run, factor * ratio


def roundoff(x: np.ndarray, n_steps: int, scale: np.ndarray) -> float:
    """Scaled round-off model of a fixed-step run: ``n_steps eps max_t |x_i|`` per state.

    Measured on a 100 s tumbling body (double against long double with the same DOP853
    weights, 1000-16000 steps) the accumulated round-off was 0.15-3 eps per step relative
    to the state's size, growing about linearly in the number of steps.
    """
    size = np.max(np.abs(x), axis=1, keepdims=True)
    floor = np.broadcast_to(n_steps * EPS * size, scale.shape)
    ratio = np.divide(floor, scale, out=np.where(floor == 0, 0.0, np.inf), where=scale > 0)
    return float(ratio.max())


def initial_step(problem: Problem, rtol, atol, order: int) -> tuple[float | None, float]:
    """Starting step and Lipschitz estimate ``(h, L)`` [s, 1/s].

    ``h``: Hairer's heuristic (Hairer, Norsett & Wanner I, II.4), capped at ``2 / L`` for
    explicit stability, with ``L = |f(x0 + h0 f0) - f0| / |h0 f0|`` (scaled norms). ``h`` is
    None when the heuristic is degenerate (a zero state or zero derivative); ``L`` is then 0.
    (`initial_steps` makes the same for many runs at once, to the bit.)
    """
    model, x0 = problem.model, problem.x0
    t0, H0 = float(problem.t[0]), float(problem.t[1] - problem.t[0])
    u0 = problem.control.at(t0, 0, t0, H0)
    scale = atol + rtol * np.abs(x0)
    if np.any(scale == 0):
        return None, 0.0
    f0 = _xdot(model, x0, u0, problem.p)
    d0 = np.sqrt(np.mean((x0 / scale) ** 2))
    d1 = np.sqrt(np.mean((f0 / scale) ** 2))
    if not (np.isfinite(d1) and d0 > 1e-5 and d1 > 1e-5):
        return None, 0.0
    h0 = 0.01 * d0 / d1
    u1 = problem.control.at(t0 + min(h0, H0), 0, t0, H0)
    f1 = _xdot(model, x0 + h0 * f0, u1, problem.p)
    d2 = np.sqrt(np.mean(((f1 - f0) / scale) ** 2)) / h0
    if not np.isfinite(d2):
        return None, 0.0
    return _hairer(float(h0), float(d1), float(d2), order)


def _hairer(h0: float, d1: float, d2: float, order: int) -> tuple[float, float]:
    """``(h, L)`` of `initial_step` from its trial step ``h0`` and scaled norms ``d1`` (of
    f0) and ``d2`` (of the change of f over h0, per second), in Python floats."""
    big = max(d1, d2)
    h1 = (0.01 / big) ** (1.0 / (order + 1)) if big > 1e-15 else 100 * h0
    h, lipschitz = min(100 * h0, h1), d2 / d1
    return (min(h, 2.0 / lipschitz) if lipschitz > 0 else h), lipschitz


def initial_steps(model, x0: np.ndarray, p: np.ndarray, rtol: float, atol: np.ndarray,
                  order: int, t0: float, H0: float, control_at) -> tuple[list, list]:
    """`initial_step` of K runs at once, each run's the same bits as alone (the norms
    reduced along each run's row, as numpy reduces one run's vector; the rest, `_hairer`,
    in Python floats for both; tested against single runs).

    Parameters
    ----------
    model : Model
    x0 : ndarray, shape (K, nx)
        The runs' initial states, C-contiguous.
    p : ndarray, shape (K, np)
    rtol : float
    atol : ndarray, shape (nx,)
    order : int
        The method's order (the step grows as the tolerance to the ``1 / (order + 1)``).
    t0, H0 : float [s]
        The start and the first output interval of every run.
    control_at : callable
        ``control_at(t (K,)) -> (K, nu)``: each run's control at its time ``t[k]`` in the
        first interval.

    Returns
    -------
    h : list of float or None, length K [s]
    lipschitz : list of float, length K [1/s]
    """
    scale = atol + rtol * np.abs(x0)
    f0 = _xdot(model, x0, control_at(np.full(len(x0), t0)), p)
    with np.errstate(all="ignore"):  # (a degenerate run's values are not used)
        d0 = np.sqrt(np.mean((x0 / scale) ** 2, axis=1))
        d1 = np.sqrt(np.mean((f0 / scale) ** 2, axis=1))
        usable = ~np.any(scale == 0, axis=1) & np.isfinite(d1) & (d0 > 1e-5) & (d1 > 1e-5)
        h0 = np.where(usable, 0.01 * d0 / d1, 0.0)
        f1 = _xdot(model, x0 + h0[:, None] * f0, control_at(t0 + np.minimum(h0, H0)), p)
        d2 = np.sqrt(np.mean(((f1 - f0) / scale) ** 2, axis=1)) / h0
    steps, lipschitz = [], []
    for ok, a, b, c in zip((usable & np.isfinite(d2)).tolist(), h0.tolist(), d1.tolist(),
                           d2.tolist()):
        h, L = _hairer(a, b, c, order) if ok else (None, 0.0)
        steps.append(h)
        lipschitz.append(L)
    return steps, lipschitz


def _xdot(model, x: np.ndarray, u: np.ndarray, p: np.ndarray) -> np.ndarray:
    """``xdot`` of ``model.f`` at one run's ``x (nx,)``, ``u (nu,)``, ``p (np,)`` (shape
    ``(nx,)``) or at the rows of ``(K, nx)``, ``(K, nu)``, ``(K, np)`` (shape ``(K, nx)``):
    `Model.rhs`'s answers to the bit, through a buffer (`call_buffered`, one run: 5 against
    51 us a call on the rigid body, whose dictionary call converts every argument;
    `map_eval` for K runs)."""
    if x.ndim == 1:
        return call_buffered(model.f, [x, u, p], (model.nx,))
    return map_eval(model.f, [x.T, u.T, p.T]).T


def spectrum(problem: Problem, *, J: np.ndarray | None = None) -> tuple[float, float] | None:
    """``(rho, sigma)`` [1/s] from the eigenvalues ``lam`` of ``df/dx`` at ``x0``: the
    spectral radius ``max |lam|`` (what explicit stability must resolve) and the fastest
    decay that only an implicit method steps over cheaply, ``max(-Re lam)`` over the
    eigenvalues with ``Re lam < 0`` and ``|Im lam| <= |Re lam|`` (oscillatory modes must be
    resolved by any method, so they do not count). None when it cannot be evaluated.
    ``J``: `jacobian_at`'s, when the caller has it."""
    J = jacobian_at(problem) if J is None else J
    return None if J is None else rho_sigma(J[None])


def jacobian_at(problem: Problem) -> np.ndarray | None:
    """``df/dx (nx, nx)`` at ``x0``, the control at ``t[0]`` and ``p``; None when it cannot
    be evaluated."""
    t0, H0 = float(problem.t[0]), float(problem.t[1] - problem.t[0])
    u0 = problem.control.at(t0, 0, t0, H0)
    try:
        nx = problem.model.nx  # (a C-ordered (nx, nx) buffer holds J^T)
        return call_buffered(jacobian_x(problem.model), [problem.x0, u0, problem.p],
                             (nx, nx)).T
    except RuntimeError:
        return None


def norm_bounds(J: np.ndarray) -> np.ndarray:
    """``|J|_inf`` (the largest row sum of ``|J_ij|``) of each matrix ``J (..., n, n)``: at
    least its spectral radius (every induced norm is), without its eigenvalues; NaN where
    ``J`` is not finite."""
    return np.abs(J).sum(axis=-1).max(axis=-1, initial=0.0)


def jacobian_x(model) -> ca.Function:
    """``(x, u, p) -> df/dx`` of ``model`` (cached); on SX when ``model.f`` is an SX
    Function (built in 15 against 36 ms for the hinged bodies: a fresh process's first
    ``simulate`` of a model compiled before spends most of its time here)."""
    def build():
        sym = ca.SX if model.f.is_a("SXFunction") else ca.MX
        x, u, p = (sym.sym(n, model.f.sparsity_in(n)) for n in ("x", "u", "p"))
        xdot = model.f.call({"x": x, "u": u, "p": p})["xdot"]
        return ca.Function("jac_x", [x, u, p], [ca.densify(ca.jacobian(xdot, x))])

    return cache.get(("jac_x", cache.function_key(model.f)), build, keepalive=model.f)


def rho_sigma(J: np.ndarray) -> tuple[float, float] | None:
    """`spectrum`'s ``(rho, sigma)`` over the Jacobians ``J (K, nx, nx)`` (the largest of
    each over the K, `spectra`'s); None when a matrix or an eigenvalue is not finite."""
    rho, sigma = spectra(J)
    if not np.isfinite(rho).all():
        return None
    return float(np.max(rho, initial=0.0)), float(np.max(sigma, initial=0.0))


#: LAPACK's ``dgeev`` (scipy's wrapper), imported by `spectra` on first use.
_DGEEV = None


def spectra(J: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(rho, sigma)`` of each matrix ``J (K, n, n)``, shapes ``(K,)``: the spectral radius
    ``max |lam|`` and the fastest decay ``max(-Re lam)`` over the eigenvalues with ``Re lam
    < 0`` and ``|Im lam| <= -Re lam`` (0 when none); ``rho`` NaN where a matrix or an
    eigenvalue is not finite (inf where one overflows).

    The eigenvalues from LAPACK's ``dgeev`` on a Fortran-ordered copy of each matrix
    (scipy's wrapper; ``numpy.linalg.eigvals`` and the reductions after it took 38 us of a
    330 us single call under sampled controls, these 18 us); a single run's and a batch's
    runs' alike, so the same bits.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.integrate.estimates import spectra
    >>> rho, sigma = spectra(np.array([[[-100.0, 0.0], [0.0, 0.0]],   # (a decay of 100/s)
    ...                                [[0.0, 1.0], [-4.0, 0.0]]]))  # (an oscillation)
    >>> np.round(rho, 12).tolist(), sigma.tolist()
    ([100.0, 2.0], [100.0, 0.0])
    """
    global _DGEEV
    if _DGEEV is None:  # (on first use: scipy.linalg costs an import 0.14 s)
        from scipy.linalg.lapack import dgeev as _DGEEV
    K, n = J.shape[0], J.shape[-1]
    wr, wi = np.full((K, n), np.nan), np.zeros((K, n))
    for k in np.flatnonzero(np.isfinite(J).all(axis=(1, 2))).tolist():
        r, i, _, _, info = _DGEEV(np.array(J[k], dtype=float, order="F"), compute_vl=0,
                                  compute_vr=0, overwrite_a=1)
        if info == 0:
            wr[k], wi[k] = r, i
    rho = np.hypot(wr, wi).max(axis=1, initial=0.0)  # (NaN where one is: max propagates it)
    stiff = (wr < 0) & (np.abs(wi) <= -wr)
    return rho, np.where(stiff, -wr, 0.0).max(axis=1, initial=0.0)


def measured_floor(target, run: Run, rtol, atol, lipschitz: float, jit: bool,
           progress, *, rerun=None) -> tuple[float, int]:
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
    inside the smallest tolerance of any state and the horizon is at most `LINEAR_LT` time
    constants ``1 / L`` (beyond, the flow may amplify exponentially, which ``1 + L T`` does
    not bound: Lorenz over 30 s was verified at 0.47 with an error of 4.7 tolerances
    against a 40-digit mpmath integration, the bound being 0.007), that bound is the
    floor; otherwise the
    flow's real amplification is measured by repeating ``run`` from ``x0 + e`` (random
    signs, same steps): the floor is the scaled difference (an error injected at the start,
    the worst time for it). The floor is never below ``FLOOR_ULPS`` ulps of a state's size
    (the rounding of the state itself, shared alike: near a separatrix every run, rk8 at
    16-400 steps per interval and scipy's DOP853 alike, was off by 900 ulps of ``|w|``
    while they agreed to 90). ``rerun(x0) -> Run | None`` makes the check run of a
    step-controlled ``run`` (the same local tolerance from the moved start; its steps
    differ a little, so the difference also holds truncation: conservative; inf when it
    returns None); default ``target.run`` with ``run``'s fixed substeps.
    """
    x = run.x
    horizon = float(target.t[-1] - target.t[0])
    cols = np.unique(np.linspace(0, x.shape[1] - 1, min(16, x.shape[1])).round().astype(int))
    X = x[:, cols]
    flips, signs = floor_signs(X.shape, x.shape[0])
    pert = [X] + [X * (1 + EPS * f) for f in flips]
    F = target.rhs(np.concatenate(pert, axis=1),
                   np.tile(cols, len(pert))).reshape(x.shape[0], len(pert), cols.size)
    if not np.all(np.isfinite(F)):
        return math.inf, 0
    noise = np.max(np.abs(F[:, 1:] - F[:, :1]), axis=(1, 2))
    e = carried(noise, horizon, lipschitz)
    scale = atol[:, None] + rtol * np.abs(x[:, 1:])
    ulps = roundoff(x, FLOOR_ULPS, scale)
    local = scaled_diff(np.broadcast_to(e[:, None], scale.shape), np.zeros(scale.shape), scale)
    bound = screen(e, np.min(scale, axis=1), horizon, lipschitz, runs=target.runs)
    if bound <= 0.1 * AUTO_ACCEPT and lipschitz * horizon <= LINEAR_LT:
        return max(bound, ulps), 0
    if rerun is not None:
        check = rerun(target.x0 + signs * e)
        if check is None:
            return math.inf, 0
    else:
        check = target.run(target.x0 + signs * e, run.substeps, jit, progress)
    return max(local, ulps, scaled_diff(check.x[:, 1:], x[:, 1:], scale)), check.n_steps


def carried(noise: np.ndarray, horizon: float, lipschitz) -> np.ndarray:
    """`measured_floor`'s rounding error ``2 sqrt(T min(T, 1 / L)) noise`` carried over the horizon
    ``T`` from the right-hand side's rounding ``noise`` per state (``L`` the spectral
    radius): ``noise (nx,)`` with a float ``lipschitz``, or the runs' ``(R, nx)`` with
    theirs ``(R,)``."""
    if np.ndim(lipschitz):
        L = np.asarray(lipschitz, dtype=float)  # (1 / L where L > 0 or NaN, else inf:
        tau = np.minimum(horizon, np.divide(1.0, L, out=np.full(L.shape, np.inf),  # no
                                            where=~(L <= 0)))  # errstate, 4 us a call)
        return 2 * np.sqrt(horizon * tau)[:, None] * noise
    tau = horizon if lipschitz <= 0 else min(horizon, 1.0 / lipschitz)
    return 2 * math.sqrt(horizon * tau) * noise


def screen(e: np.ndarray, smin: np.ndarray, horizon: float, lipschitz: float,
            *, runs: int = 1) -> float:
    """`measured_floor`'s screening bound of the carried rounding ``e`` against the least tolerance
    ``smin`` of each state: the flow may carry the noise of any state into any other (the
    spin-rate noise of a flat body into the phase of its transverse rates), so across the
    states of each run (the runs of a batch do not share noise), the largest over the runs,
    grown by ``1 + L T`` (`screens`, one run's each)."""
    return float(np.max(screens(e.reshape(runs, -1), smin.reshape(runs, -1), horizon,
                                lipschitz)))


def screens(e: np.ndarray, smin: np.ndarray, horizon: float, lipschitz) -> np.ndarray:
    """`screen`'s bound of each run: ``e``, ``smin`` of shape ``(R, nx)``, ``lipschitz`` a
    float or the runs' ``(R,)``; shape ``(R,)``."""
    top, least = e.max(axis=1), smin.min(axis=1)  # (the methods: a third of np.max's cost)
    worst = np.divide(top, least, out=np.where(top > 0, np.inf, 0.0), where=least > 0)
    return worst * (1 + np.asarray(lipschitz) * horizon)


def perturbed(x0: np.ndarray, m: int) -> np.ndarray:
    """``x0`` moved by 2 ulp in a sign pattern that differs between step
    counts ``m`` (reproducibly): the differences between ``auto``'s runs then also show how
    strongly the problem amplifies double-precision representation errors (of ``x0`` and of
    the model's constants, rounded alike). Near a separatrix this amplification put a common
    error of 3e-13 into every run at 16-400 steps per interval that step-count differences
    alone cannot see; a well-conditioned problem just carries the 2 ulp."""
    return x0 + 2 * EPS * signs(m, x0.size) * x0


def table(kind: str) -> dict:
    """A table of small read-only arrays of ``kind`` (sign patterns, start states), kept as
    ONE entry of `dynamics.cache` (so that `dynamics.clear_caches` empties it and its many
    small arrays never evict compiled Functions); at most 256 arrays, emptied when full."""
    got = cache.get(("arrays", kind), dict)
    if len(got) >= 256:
        got.clear()
    return got


def signs(seed: int, size: int) -> np.ndarray:
    """A reproducible random sign pattern of ``size`` entries (read-only). Kept (`table`):
    seeding a numpy generator costs about 40 us, more than an rk8 run of a small model."""
    known = table("signs")
    out = known.get((seed, size))
    if out is None:
        out = np.random.default_rng(seed).choice((-1.0, 1.0), size=size)
        out.setflags(write=False)
        known[seed, size] = out
    return out


def floor_signs(shape: tuple, n: int) -> tuple:
    """`measured_floor`'s sign patterns (kept, `table`; read-only): three of ``shape`` for
    the ulp moves of the sampled states, then ``n`` for the start of its check run, drawn in
    that order from one generator seeded 0."""
    known = table("floor_signs")
    out = known.get((tuple(shape), n))
    if out is None:
        rng = np.random.default_rng(0)
        flips = [rng.choice((-1.0, 1.0), size=shape) for _ in range(3)]
        start = rng.choice((-1.0, 1.0), size=n)
        for a in (*flips, start):
            a.setflags(write=False)
        out = known[tuple(shape), n] = (tuple(flips), start)
    return out
