"""The horizon of an initial guess: the default ``T``, and a free ``T`` found by simulation.

A free ``T`` without a guess defaults to the middle of ``[T_min, T_max]`` (``max(1, 2
T_min)`` if ``T_max = inf``; `default_T`). When `ocp.guess` may choose it instead (a guess
``None``, or a mapping without ``'T'``, ``'t'`` and ``'x'`` whose ``'u'`` is not samples
over the horizon: see the module docstring there), `simulated_horizon` simulates the model
from ``x_initial`` under the guessed control by cheap fixed-step RK4 and takes the time in
``[T_min, T_max]`` at which the state comes closest to the given components of ``x_final``;
the simulated trajectory is then the state guess. The constants below set the search.

Cost: for a 7-state rigid body about 2 ms per solve, 6-15 ms the first time per model
(building the RK4 loop of `dynamics.simulate`), against 0.2-0.3 ms for the interpolated
default.
"""
from __future__ import annotations

import math
from typing import Callable

import numpy as np

__all__ = ["default_T", "simulated_horizon", "simulate_control", "typical_magnitude",
           "HORIZON_FACTOR", "SAMPLES", "SUBSTEPS", "ZOOMS", "MARCH", "IMPROVEMENT"]

#: Free horizon without a guessed ``T``: simulated up to ``T_max``, or this many times the
#: default ``T`` when ``T_max`` is infinite.
HORIZON_FACTOR = 100.0
#: Samples per simulated window of the horizon search, RK4 steps between samples, the
#: most times the first window shrinks (zooming in on an early best sample), and the most
#: windows added while the best sample is the last one (see `simulated_horizon`).
SAMPLES = 201
SUBSTEPS = 4
ZOOMS = 3
MARCH = 9
#: The simulated horizon is used only if its state is at most this fraction of the
#: initial (scaled) distance from the final state.
IMPROVEMENT = 0.5


def default_T(problem) -> float:
    """The horizon of the default guess.

    Parameters
    ----------
    problem : ocp.Problem

    Returns
    -------
    float [s]
        The fixed ``T``; for a free one the middle of ``[T_min, T_max]``, or
        ``max(1, 2 T_min)`` when ``T_max`` is infinite.
    """
    if not problem.free_time:
        return problem.T
    lo, hi = problem.T
    return 0.5 * (lo + hi) if math.isfinite(hi) else max(1.0, 2.0 * lo)


def typical_magnitude(problem) -> np.ndarray:
    """Per state, the magnitude by which a miss of the final value is measured.

    Parameters
    ----------
    problem : ocp.Problem

    Returns
    -------
    ndarray, shape (nx,) [state units]
        The distance between the boundary values, at least a tenth of their magnitude; for
        a state that should end where it starts, half its bound span if finite, else its
        magnitude, else 1.
    """
    a, b = problem.x_initial, problem.x_final
    lo, hi = problem.x_bounds
    with np.errstate(invalid="ignore"):
        s = np.maximum(np.abs(b - a), 0.1 * np.maximum(np.abs(a), np.abs(b)))
        span = np.where(np.isfinite(hi - lo), 0.5 * (hi - lo), 0.0)
    s = np.where(np.isfinite(s) & (s > 0), s, span)
    s = np.where(s > 0, s, np.where(np.isfinite(a) & (np.abs(a) > 0), np.abs(a), 1.0))
    return s


def simulate_control(problem, u: np.ndarray, t: np.ndarray, p, *, x0=None, **options):
    """`dynamics.simulate` of the model under control samples clipped into the bounds.

    Parameters
    ----------
    problem : ocp.Problem
    u : ndarray, shape (nu, n)
        Control samples on ``t``.
    t : ndarray, shape (n,) [s]
    p : array_like, shape (np,)
    x0 : array_like, shape (nx,), optional
        Initial state; default ``problem.x_initial``.
    **options
        Passed to `dynamics.simulate`.

    Returns
    -------
    res : dynamics.SimulationResult
    u : ndarray, shape (nu, n)
        The controls used (clipped).
    """
    from appdyn.dynamics import simulate

    lo, hi = problem.u_bounds
    u = np.clip(u, lo[:, None], hi[:, None])
    x0 = problem.x_initial if x0 is None else x0
    res = simulate(problem.model, x0, t, u=u if problem.model.nu else None, p=p, **options)
    return res, u


def simulated_horizon(problem, u_of_t: Callable, p: np.ndarray,
                      *, control: str = "the guessed control"):
    """The horizon of a free-time problem at which the model, simulated from ``x_initial``
    under the control ``u_of_t(t) -> (nu, len(t))``, comes closest to ``x_final``.

    The model is integrated by fixed-step RK4 (`dynamics.simulate`, not compiled:
    ``SUBSTEPS`` steps between ``SAMPLES`` samples) over a window ``[0, H]``, ``H = T_max``
    or, when ``T_max`` is infinite, ``HORIZON_FACTOR`` times the default ``T``. A run stops
    where the state leaves ``x_bounds`` or becomes non-finite. A best sample in the first
    tenth of the window shrinks the window to it (up to ``ZOOMS`` times; also when the first
    step blows up); a best sample at the end of a valid window continues the simulation
    with another window of the same length (up to ``MARCH`` more, so at most ``(1 + MARCH)
    H``). Only times within ``[T_min, T_max]`` count; the miss is the distance to the given
    components of ``x_final``, each divided by its `typical_magnitude`.

    Parameters
    ----------
    problem : ocp.Problem
        With a free horizon.
    u_of_t : callable
        ``u_of_t(t) -> (nu, len(t))``, ``t`` absolute times [s].
    p : ndarray, shape (np,)
    control : str, optional
        Names the control in the returned sentence.

    Returns
    -------
    tuple (T, x_fun, source) or None
        The horizon [s], the simulated states as a function of normalized time (arrays of
        shape (nx, m) for m times), and a sentence for messages; ``None`` (keep the default
        guess) when the initial state is not fully given, no final state is given, the
        simulation fails or leaves the bounds at once, or its best state is not at least
        halfway (``IMPROVEMENT``, in that distance) from ``x_initial`` to ``x_final``.
    """
    model = problem.model
    a, b = problem.x_initial, problem.x_final
    given = ~np.isnan(b)
    if np.any(np.isnan(a)) or not np.any(given):
        return None
    scale = typical_magnitude(problem)[given]
    d0 = float(np.linalg.norm((a[given] - b[given]) / scale))
    if not d0 > 0:
        return None
    T_lo, T_hi = problem.T
    H = T_hi if math.isfinite(T_hi) else HORIZON_FACTOR * default_T(problem)
    lo, hi = problem.x_bounds
    lo = np.where(np.isfinite(lo), lo - 1e-9 * (1.0 + np.abs(lo)), -np.inf)[:, None]
    hi = np.where(np.isfinite(hi), hi + 1e-9 * (1.0 + np.abs(hi)), np.inf)[:, None]
    t0, n = problem.t0, SAMPLES
    best = None
    start, x_start, zooms, windows = 0.0, a, 0, 0
    past_t, past_x = [], []  # earlier windows of the run (marching)
    while True:
        t = t0 + start + np.linspace(0.0, H, n)
        try:
            u = np.asarray(u_of_t(t), dtype=float).reshape(model.nu, n)
            res, u = simulate_control(problem, u, t, p, x0=x_start, method="rk4", steps=SUBSTEPS,
                               jit=False)
        except (ArithmeticError, ValueError, RuntimeError, TypeError):
            break
        x = np.asarray(res.x)
        with np.errstate(invalid="ignore"):
            ok = np.all(np.isfinite(x), axis=0) & np.all((x >= lo) & (x <= hi), axis=0)
        J = n if ok.all() else int(np.argmin(ok))  # valid samples: 0 .. J-1
        tt = t[:J] - t0
        d = np.linalg.norm((x[given, :J] - b[given, None]) / scale[:, None], axis=0)
        cand = np.flatnonzero((tt >= T_lo) & (tt <= T_hi) & (tt > 0))
        k = int(cand[np.argmin(d[cand])]) if cand.size else -1
        zoomed = start == 0.0 and zooms > 0  # finer than the earlier runs: preferred
        if k >= 0 and (best is None or d[k] < best[0] or zoomed):
            best = (float(d[k]), float(tt[k]), np.concatenate(past_t + [tt[:k + 1]]),
                    np.concatenate(past_x + [x[:, :k + 1]], axis=1))
        if start == 0.0 and zooms < ZOOMS and (
                (0 <= k < n // 10 and k + 1 < J) or (J < 2 and not np.all(np.isfinite(x[:, 1])))):
            # an early best sample (or a blow-up at the first step): a shorter window
            H = float(tt[k + 1]) if k >= 0 else H / 100.0
            zooms += 1
            best = None if k < 0 else best
            if H > T_lo:
                continue
            break
        if J == n and (k == n - 1 or k < 0) and start + H < T_hi and windows < MARCH:
            # still nearing x_final (or not yet past T_min) at the end: march on
            past_t.append(tt[:-1])
            past_x.append(x[:, :-1])
            start, x_start, windows = start + H, x[:, -1].copy(), windows + 1
            if model.attitude is not None:  # the next start must have a unit quaternion
                iq = model.attitude[0]
                x_start[iq:iq + 4] /= np.linalg.norm(x_start[iq:iq + 4])
            continue
        break
    if best is None or not best[0] <= IMPROVEMENT * d0:
        return None
    _, T, tt, xs = best
    tau = tt / T
    quat = None if model.attitude is None else model.attitude[0]

    def x_fun(s):
        s = np.asarray(s, float)
        x = np.stack([np.interp(s, tau, row) for row in xs])
        if quat is not None:  # interpolated quaternions: back to unit norm
            x[quat:quat + 4] /= np.linalg.norm(x[quat:quat + 4], axis=0)
        return x

    source = (f"states simulated from x_initial under {control} up to T = {T:.4g} s, the "
              f"time closest to x_final")
    return T, x_fun, source
