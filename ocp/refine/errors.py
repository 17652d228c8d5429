"""Per-interval error estimate of a collocation solution (`interval_errors`): the defect of
a re-integration from each interval start, and the state increment a smeared bang-bang
switch misses."""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from ..cached import cached, function_key
from appdyn.dynamics.validate import integer
from ..solution import Solution, interval_integrator, stack_interval_controls
from ..mesh import sorted_union
from ..transcription import Transcription
from .switches import control_switches

__all__ = ["IntervalErrors", "interval_errors"]


@dataclass(frozen=True)
class IntervalErrors:
    """Per-interval error estimate of a solution (see `interval_errors`).

    Attributes
    ----------
    error : ndarray, shape (N,)
        ``max(defect, switch)`` per interval (``inf`` where the re-integration failed).
    defect : ndarray, shape (N,)
        ``max_i max_points |x_integrated - x_solution|_i / max(1, max_t |x_i|)`` over the
        interval's nodes and quarter points, the integration restarted from the collocated
        state at each interval start.
    switch : ndarray, shape (N,)
        For intervals where a control jumps (bang-bang switch inside the interval):
        ``max_i integral |f_i(x, u_bang) - f_i(x, u)| dt / max(1, max_t |x_i|)``, with
        ``u_bang`` the two-level control of the same impulse; 0 elsewhere.
    switching : ndarray of bool, shape (N,)
    switch_time : ndarray, shape (N,) [s]
        Estimated switch time inside switching intervals (NaN elsewhere).
    scale : ndarray, shape (nx,)
        ``max(1, max_t |x_i|)``.
    """

    error: np.ndarray
    defect: np.ndarray
    switch: np.ndarray
    switching: np.ndarray
    switch_time: np.ndarray
    scale: np.ndarray

    @property
    def max_error(self) -> float:
        return float(np.max(self.error)) if self.error.size else 0.0


def _check_sigma(tr: Transcription) -> np.ndarray:
    """Where the re-integrated state is compared inside an interval: the owned nodes and the
    quarter points (the dense output between nodes counts too: for the trapezoid its linear
    interpolant is only second-order accurate, while its mesh points are third-order
    locally)."""
    return sorted_union(tr.node_sigma, [0.25, 0.5, 0.75])


def _interval_integrator(sol: Solution, rtol: float, atol: float) -> ca.Function:
    """``(x0 (nx, N), data) -> x at the check points of every interval`` by CVODES."""
    tr, f, N = sol.transcription, sol.problem.model.f, sol.dense.N

    def build():
        integ = interval_integrator(sol, _check_sigma(tr), rtol, atol)
        x0, dat = ca.MX.sym("x0", f.numel_in(0)), ca.MX.sym("data", integ.numel_in("p"))
        step = ca.Function("interval_step", [x0, dat], [ca.vec(integ(x0=x0, p=dat)["xf"])])
        return step.map(N)

    return cached("interval_check", (tr, function_key(f), N, float(rtol), float(atol)), build,
                  keepalive=f)


def _simpson(n: int) -> np.ndarray:
    """Simpson weights on ``n`` (odd) equally spaced points of [0, 1]."""
    w = np.ones(n)
    w[1:-1:2], w[2:-1:2] = 4.0, 2.0
    return w / (3.0 * (n - 1))


def interval_errors(solution: Solution, *, rtol: float = 1e-11, atol: float = 1e-12,
                    samples: int = 33) -> IntervalErrors:
    """Estimate the error of each mesh interval of ``solution``.

    *Defect*: the dynamics are integrated by CVODES over each interval from the collocated
    state at its start, under the transcription's dense control, and compared with the
    solution's states at the interval's nodes and at its quarter points (the dense output,
    `Solution.sample`), relative to ``max(1, max_t |x_i|)``; the largest deviation counts.

    *Switches*: a control component "switches" in an interval when the switch detector of
    the engine (`ocp.refine.switches.control_switches`, the one behind `find_switches`) puts
    one of its switches in the interval (ends included), the levels ``A`` before
    and ``B`` after it differ by at least 0.4 of its range (``u_upper - u_lower`` for a
    bounded control, the span over the horizon otherwise, then with a sign change) and the
    control in the interval is neither all at ``A`` nor all at ``B`` (within 5% of the range):
    a smeared jump (a polynomial control crossing over, a constant control in between).
    ``A`` is the control at the last control node of the previous interval, ``B`` at the
    first control node of the next one, each taken as the bound itself when within 10% of
    the range of it. The switch time matches the impulse,
    ``s* = (mean(u) - B) / (A - B)`` (fraction of the interval). The error is the state
    increment that the smeared control misses, ``integral |f(x, u_bang) - f(x, u)| dt`` with
    ``u_bang = A`` before ``s*`` and ``B`` after, relative as above. It is ``O(h)``, while the
    error of ``T`` or of the cost from a smeared switch is ``O(h^2)``.

    Parameters
    ----------
    solution : Solution
    rtol, atol : float
        CVODES tolerances of the re-integration.
    samples : int
        Odd number of sample points per interval for the switch analysis.

    Returns
    -------
    IntervalErrors
    """
    if not isinstance(solution, Solution):
        raise TypeError(f"`solution` must be an ocp.Solution, got {type(solution).__name__}")
    samples = integer(samples, "samples", minimum=3)
    if samples % 2 == 0:
        raise ValueError(f"`samples` must be an odd integer >= 3, got {samples!r}")
    sol, d = solution, solution.dense
    problem, model = sol.problem, sol.problem.model
    nx, nu, N = model.nx, model.nu, d.N
    scale = np.maximum(1.0, np.max(np.abs(sol.x), axis=1))

    # ---------------------------------------------------------------- defects
    try:
        run = _interval_integrator(sol, rtol, atol)
        pars = np.concatenate([d.us, stack_interval_controls(d.Uo, np.arange(N)), d.h[None, :],
                               np.repeat(sol.p[:, None], N, axis=1)], axis=0)
        sig = _check_sigma(sol.transcription)
        xi = np.asarray(run(d.xs, pars)).reshape(nx, sig.size, N, order="F")
        xc, _ = d.eval(np.repeat(np.arange(N), sig.size), np.tile(sig, N))
        xc = xc.reshape(nx, N, sig.size).transpose(0, 2, 1)
        dev = np.abs(xi - xc) / scale[:, None, None]
        defect = np.max(dev, axis=(0, 1))
        defect[~np.isfinite(defect)] = np.inf
    except RuntimeError:
        defect = np.full(N, np.inf)

    # ---------------------------------------------------------------- switches
    s = np.linspace(0.0, 1.0, samples)
    k_all = np.repeat(np.arange(N), samples)
    xs_, us_ = d.eval(k_all, np.tile(s, N))
    xs_ = xs_.reshape(nx, N, samples)
    us_ = us_.reshape(nu, N, samples)
    lo, hi = problem.u_bounds
    tr = sol.transcription
    # the control at the last control node of each interval (sigma = 1 in every
    # transcription) and at the first one (where a Radau polynomial is not extrapolated)
    s_first = 0.0 if tr.u_at_start else float(tr.u_sigma[0])
    _, u_first = d.eval(np.arange(N), np.full(N, s_first))
    detected = control_switches(sol)
    slack = 1e-12 * max(sol.T, 1.0)
    switching = np.zeros(N, bool)
    s_star = np.full(N, np.nan)
    u_bang = us_.copy()
    for j in range(nu):
        uj = us_[j]
        bounded = np.isfinite(lo[j]) and np.isfinite(hi[j]) and hi[j] > lo[j]
        span = (hi[j] - lo[j]) if bounded else float(np.ptp(uj))
        if not span > 0:
            continue
        last = uj[:, -1]
        A = np.concatenate([[u_first[j, 0]], last[:-1]])  # level before interval k
        B = np.concatenate([u_first[j, 1:], [last[-1]]])  # level after it
        if bounded:  # levels within 10% of the range of a bound are taken as that bound
            for level in (A, B):
                level[level <= lo[j] + 0.1 * span] = lo[j]
                level[level >= hi[j] - 0.1 * span] = hi[j]
        else:
            A, B = np.where(A * B < 0, A, 0.0), np.where(A * B < 0, B, 0.0)  # sign changes only
        at_A = np.all(np.abs(uj - A[:, None]) <= 0.05 * span, axis=1)
        at_B = np.all(np.abs(uj - B[:, None]) <= 0.05 * span, axis=1)
        flag = (np.abs(A - B) >= 0.4 * span) & ~at_A & ~at_B
        holds = np.zeros(N, bool)  # intervals that hold a detected switch of component j
        for ts in detected[j]:
            holds |= (d.t_breaks[:-1] - slack <= ts) & (ts <= d.t_breaks[1:] + slack)
        flag &= holds
        mean = uj @ _simpson(samples)
        with np.errstate(divide="ignore", invalid="ignore"):
            frac = np.clip((mean - B) / (A - B), 0.0, 1.0)
        for k in np.flatnonzero(flag):
            switching[k] = True
            sk = frac[k]
            s_star[k] = sk if np.isnan(s_star[k]) else 0.5 * (s_star[k] + sk)
            u_bang[j, k] = np.where(s < sk, A[k], B[k])
    switch = np.zeros(N)
    ks = np.flatnonzero(switching)
    if ks.size:
        M = ks.size * samples
        X = xs_[:, ks].reshape(nx, M)
        args = (np.repeat(sol.p[:, None], M, axis=1),)
        fmap = model.f.map(M)
        diff = np.abs(np.asarray(fmap(X, u_bang[:, ks].reshape(nu, M), *args))
                      - np.asarray(fmap(X, us_[:, ks].reshape(nu, M), *args)))
        incr = diff.reshape(nx, ks.size, samples) @ _simpson(samples) * d.h[ks][None, :]
        switch[ks] = np.max(incr / scale[:, None], axis=0)
    switch_time = np.full(N, np.nan)
    switch_time[ks] = d.t_breaks[ks] + s_star[ks] * d.h[ks]
    error = np.maximum(defect, switch)
    for a in (error, defect, switch, switching, switch_time, scale):
        a.setflags(write=False)
    return IntervalErrors(error, defect, switch, switching, switch_time, scale)
