"""``method='auto'``: rk8 step counts chosen from Richardson estimates of the global error,
the round-off floor of a run, the stiffness test, and cvodes with an estimated global error
for stiff problems."""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import partial

import numpy as np

from .. import cache
from .adaptive import check_steps, replay_check, run_pass
from .cpass import BMAX, CHECK_EVERY, NOISE
from .cvodes import run_cvodes
from .dense import DenseAuto, dense_auto
from .estimates import (AUTO_ACCEPT, EPS, FLOOR_ULPS, carried, initial_step, jacobian_at,
                        measured_floor, norm_bounds, perturbed, roundoff, scaled_diff,
                        screen, screens, spectra, spectrum, tightened)
from .evaluate import map_eval
from .inputs import Problem
from .loops import Progress, run_fixed
from .result import FAILED, NONSMOOTH, OK, OK_STIFF, ROUNDOFF, UNVERIFIED, Run
from .smoothness import nonsmooth_operations
from .stepcontrol import LOCAL_RTOL_MIN, solve_stepped
from .tableaux import DOP853

__all__ = ["solve_auto", "auto_jit", "STIFF_STEPS", "Single", "auto_runs", "dense_pass",
           "dense_outcome", "dense_answer", "dense_message", "one_pass", "nonsmooth_causes",
           "rounding_bound", "rounding_bounds"]

_AUTO_AIM = 0.1        # predict the step count for this estimated scaled error
_AUTO_RUNS = 8         # give up (status 3) after this many fixed-step runs

_AUTO_CONFIRM = 1024   # below this many steps a trusted triple must be confirmed by another
STIFF_STEPS = 1e6     # explicit steps for stability alone beyond which auto uses cvodes
_CVODES_RTOL_MIN = 1e-14  # tightest local rtol auto asks cvodes for
_RK8_STABILITY = 6.0   # DOP853's stability interval on the negative real axis is about [-6, 0]
PASS_THETA = 1.0      # the check run's embedded estimates over the horizon, in tolerances
_PASS_TRIES = 3        # passes (each aimed tighter) before the multi-run search
PASS_ULPS = 10 ** 4   # the one-pass path needs the tolerance this many ulps above the state
PASS_MEASURED = 10 ** 6  # and below this many it measures the model's rounding (`measured_floor`)
_ORDER_LOSS = 100.0    # differences this many times the modelled round-off: not round-off


@dataclass(frozen=True)
class _Estimate:
    """Global error estimate of the finest finite run, in units of the tolerance."""

    value: float       # estimated max |error| / (atol + rtol |x|); inf when not known
    accept: bool       # the tolerance is met
    next_m: int        # substeps per interval to try next (0: stop, round-off floor)
    trusted: bool = False  # the runs were seen in the asymptotic range
    order_lost: bool = False  # stopped with differences far above the modelled round-off


def _estimate(runs: dict, rtol, atol, asymptotic: bool) -> _Estimate:
    """Richardson estimate from the finite runs (substeps per interval ``a < b < c``).

    ``e_c = d_bc / ((c/b)^8 - 1)`` is the truncation error of run ``c`` if the runs are in
    the asymptotic range. That is checked: ``d_ab / d_bc`` must be within a factor 4 of
    ``(a^-8 - b^-8) / (b^-8 - c^-8)``, and ``d_bc`` must stand 4x clear of the modelled
    round-off ``rho`` of run ``c`` (`roundoff`, an upper bound: ``n eps max|x|``).

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
    * Three runs that agree to the modelled round-off (``d_ab, d_bc <= 4 rho``; a solution
      rk8 integrates exactly, such as a body at rest, where no order can be seen): accepted
      at ``2 max(d_ab, d_bc) + rho`` when that is at most 0.5. A truncation error above the
      round-off would make the differences differ by ``(b/a)^8``.
    * Otherwise the next count aims at ``e = 0.1`` (1.25x to 8x the last count).
    """
    order = 8
    finite = sorted(m for m, r in runs.items() if r.ok)
    if not finite:
        return _Estimate(math.inf, False, 8 * max(runs))
    c = finite[-1]
    xc = runs[c].x[:, 1:]
    scale = atol[:, None] + rtol * np.abs(xc)
    rho = roundoff(runs[c].x, runs[c].n_steps, scale)
    if len(finite) == 1:
        return _Estimate(math.inf, False, 2 * c if c == max(runs) else 8 * max(runs))
    b = finite[-2]
    d_bc = scaled_diff(runs[b].x[:, 1:], xc, scale)
    e_c = d_bc / ((c / b) ** order - 1)
    # Accept on a two-orders-lower extrapolation: pre-asymptotic triples can look 8th order
    # (measured: runs 1, 2, 7 steps looked order 7.7, and the 8th-order estimate was 22x low).
    e_acc = d_bc / ((c / b) ** (order - 2) - 1)
    trusted, d_ab = False, math.inf
    if len(finite) >= 3:
        a = finite[-3]
        d_ab = scaled_diff(runs[a].x[:, 1:], runs[b].x[:, 1:], scale)
        if 4 * rho < d_bc < math.inf:
            predicted = (a ** -order - b ** -order) / (b ** -order - c ** -order)
            trusted = 0.25 <= (d_ab / d_bc) / predicted <= 4.0
    # A triple of very coarse runs can look 8th order by coincidence (runs of 1, 2, 4 steps
    # matched the predicted ratio to 7% while the 4-step error was 12x the estimate): below
    # `_AUTO_CONFIRM` steps (cheap) a second trusted triple is asked for.
    confirmed = asymptotic or runs[c].n_steps >= _AUTO_CONFIRM
    if trusted and confirmed and e_acc + rho <= AUTO_ACCEPT:
        return _Estimate(e_acc + rho, True, c, True)
    if trusted and e_acc + rho <= AUTO_ACCEPT:
        return _Estimate(e_acc + rho, False, math.ceil(1.25 * c), True)
    if c >= 2 * b and 2 * d_bc <= 1.0 and confirmed:
        return _Estimate(2 * d_bc, True, c, trusted)
    if asymptotic and (c / b) ** (order - 2) >= 2 and 2 * d_bc <= AUTO_ACCEPT:
        return _Estimate(2 * d_bc, True, c, trusted)
    if len(finite) == 2 and b > 1 and e_acc + rho <= AUTO_ACCEPT:
        return _Estimate(math.inf, False, b // 2)  # a cheap coarser run to check the order
    if d_bc <= 4 * rho and asymptotic and e_acc + rho <= 1.0:
        return _Estimate(e_acc + rho, True, c, trusted)
    if d_bc > 0.5 * d_ab and 2 * max(d_ab, d_bc) <= AUTO_ACCEPT:
        # three runs agree within the tolerance and more steps no longer shrink their
        # differences: truncation is below the rounding, which the differences show
        return _Estimate(2 * max(d_ab, d_bc), True, c, trusted)
    if d_bc > 0.5 * d_ab and (d_bc <= 4 * rho or d_bc <= 1e4 or asymptotic):
        # (differences above 1e4 tolerances that do not shrink are runs before the
        # asymptotic range, not a round-off floor)
        # more steps no longer shrink the differences (truncation alone would shrink them
        # (c/b)^8 >= 6x): the measured round-off floor; stop
        # (far above the modelled round-off, which is pessimistic, it is the order that
        # is lost: a kink or a jump of the right-hand side, see `auto_runs`)
        return _Estimate(d_bc + e_c, False, 0, trusted, d_bc > _ORDER_LOSS * rho)
    if len(finite) >= 3 and max(d_ab, d_bc) <= 4 * rho and 2 * max(d_ab, d_bc) + rho <= \
            AUTO_ACCEPT:
        # three step counts agree to the modelled round-off: the truncation error of the
        # coarsest is below it (a solution rk8 integrates exactly, e.g. a body at rest);
        # truncation that large would differ by (b/a)^8 between the runs
        return _Estimate(2 * max(d_ab, d_bc) + rho, True, c, trusted)
    if d_bc <= 4 * rho:  # the runs agree to the modelled round-off: try twice the steps
        return _Estimate(d_bc + rho, False, 2 * c, trusted)
    if math.isfinite(e_c) and e_c > 0:
        nxt = c * (e_c / _AUTO_AIM) ** (1.0 / order)
    else:
        nxt = 8 * c
    nxt = min(max(math.ceil(nxt), math.ceil(1.25 * c)), 8 * c)
    return _Estimate(e_c + rho if trusted else math.inf, False, int(nxt), trusted)


class Single:
    """What `auto_runs` asks of the runs it controls: here one `Problem` (a batch of runs:
    `dynamics.integrate.batch.BatchTarget`). States are flat: ``x0 (N,)``, a run's ``x``
    ``(N, n)``."""

    runs = 1  # independent runs whose flat states are stacked (a batch: K)

    def __init__(self, problem: Problem):
        self.problem, self.t, self.x0 = problem, problem.t, problem.x0
        #: why the right-hand side may be non-smooth (`nonsmooth_causes`); () if smooth
        self.nonsmooth = nonsmooth_causes(problem)

    def run(self, x0: np.ndarray, m: int, jit: bool, progress) -> Run:
        """``m`` rk8 steps per output interval from ``x0``."""
        return run_fixed(replace(self.problem, x0=x0), "rk8", m, jit, progress=progress)

    def spectrum(self, rtol, atol, *, J: np.ndarray | None = None):
        """``(rho, sigma)`` as `estimates.spectrum` (``(L, 0)`` from `initial_step` when that
        fails); ``J`` its Jacobian at ``x0`` when known."""
        found = spectrum(self.problem, J=J)
        return (initial_step(self.problem, rtol, atol, 8)[1], 0.0) if found is None else found

    def rhs(self, X: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """The right-hand side at the states ``X (N, c)`` taken at output times ``t[cols]``."""
        problem = self.problem
        if problem.control.mode == "linear":
            U = problem.control.grid(problem.t)[:, cols]
        else:
            U = np.stack([problem.control.fun(float(problem.t[c])) for c in cols], axis=1)
        return map_eval(problem.model.f, [X, U, problem.p])


def auto_runs(target, rtol, atol, max_steps, jit_pref, progress: Progress, *,
              rounding: float = 0.0):
    """Run ``rk8`` with step counts chosen until the global error estimate meets the tolerance
    (``target``: a `Single` problem or a batch; ``atol`` per flat state).

    Returns ``(run or None, estimate, status, reason, total_steps, total_rhs)``: ``None`` and
    reason ``"stiff"`` hand the problem to `_auto_cvodes`. ``status`` is ``OK``,
    ``ROUNDOFF`` (the tolerance lies below the round-off floor), ``NONSMOOTH`` (a
    right-hand side that may be non-smooth, ``target.nonsmooth``, whose runs stopped
    converging far above the modelled round-off, or did not settle: the order is lost at
    kinks) or ``UNVERIFIED`` (not within ``max_steps`` or the run budget); the best run
    found is returned with them. ``rounding``: a rounding floor measured before
    (`dense_pass`'s), the least floor an estimate is accepted with.
    """
    t = target.t
    nint = t.size - 1
    horizon = float(t[-1] - t[0])
    Hmax = float(np.max(np.diff(t)))
    lipschitz, sigma = target.spectrum(rtol, atol)
    if horizon * sigma / _RK8_STABILITY > STIFF_STEPS:
        return (None, math.nan, 0, f"stiff: a decay rate of {sigma:.3g}/s needs "
                f"~{horizon * sigma / _RK8_STABILITY:.3g} explicit steps for stability alone",
                0, 0)
    stable = nint * max(1.0, Hmax * lipschitz / _RK8_STABILITY)
    if stable > max_steps:
        return (None, math.nan, UNVERIFIED,
                f"explicit stability alone needs ~{stable:.3g} rk8 steps (spectral radius "
                f"{lipschitz:.3g}/s over {horizon:.6g} s) > max_steps = {max_steps}", 0, 0)
    # Start from the count explicit stability needs (cheap at loose tolerances: the order-8
    # prediction then jumps to the count the tolerance needs); Hairer's accuracy heuristic
    # is tolerance-blind here and started 2-4x too fine (measured in bench/simulate.py).
    m = max(1, math.ceil(Hmax * lipschitz / 2))
    runs: dict[int, Run] = {}
    total = [0, 0]
    asymptotic = False
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
        progress.ahead = 2 * m * nint  # another run, if one is needed, takes about twice the steps
        run = target.run(perturbed(target.x0, m), m, auto_jit(jit_pref), progress)
        run.x[:, 0] = target.x0
        runs[m] = run
        total[0] += run.n_steps
        total[1] += run.n_rhs
        if not run.ok and any(not r.ok and 8 * k <= m and _first_bad(r.x) == _first_bad(run.x)
                              for k, r in runs.items()):
            return run, math.inf, FAILED, "", *total  # 8x finer steps did not help: blow-up
        if len(runs) == 1:
            m = 2 * m
            continue
        est = _estimate(runs, rtol, atol, asymptotic)
        asymptotic = asymptotic or est.trusted
        if est.accept:
            best = runs[max(k for k, r in runs.items() if r.ok)]
            floor, extra = measured_floor(target, best, rtol, atol, lipschitz, auto_jit(jit_pref),
                                  progress)
            floor = max(floor, rounding)
            total[0] += extra
            total[1] += extra * DOP853.stages
            if est.value + floor > 1.0:
                return best, est.value + floor, ROUNDOFF, "", *total
            return best, est.value, OK, "", *total
        if est.next_m == 0:
            lost = est.order_lost and target.nonsmooth
            return (runs[max(k for k, r in runs.items() if r.ok)], est.value,
                    NONSMOOTH if lost else ROUNDOFF, "", *total)
        m = est.next_m
    finite = [k for k, r in runs.items() if r.ok]
    best = runs[max(finite)] if finite else (runs[max(runs)] if runs else None)
    settled = not (target.nonsmooth and reason.startswith("the error estimates did not"))
    return best, est.value, UNVERIFIED if settled else NONSMOOTH, reason, *total


def _first_bad(x: np.ndarray) -> int:
    """Index of the first output time with a non-finite state (``x.shape[1]`` if none)."""
    bad = ~np.isfinite(x).all(axis=0)
    return int(np.argmax(bad)) if bad.any() else x.shape[1]


def auto_jit(jit_pref) -> bool:
    """jit for ``auto``'s runs: `cache.should_compile` with unbounded work, as for the
    fixed-step methods (one compiled chunk per model, reused by every run and call)."""
    return cache.should_compile(jit_pref, math.inf)


def _auto_cvodes(problem: Problem, rtol, atol, extra):
    """cvodes for a stiff problem, with its global error estimated (`estimates.tightened`):
    runs at local tolerances ``tol / 10, tol / 1000, ...`` until two successive runs agree
    within the tolerance; the tighter run is returned with their scaled difference as its
    (conservative) error estimate. Returns ``(run, estimate, status, n_steps, n_rhs)``."""
    run, verdict, estimate, n_steps, n_rhs = tightened(
        lambda r, a: run_cvodes(problem, r, a, extra), rtol, atol, 0.1, 1e-2,
        _CVODES_RTOL_MIN)
    status = {"met": OK_STIFF, "tightest": UNVERIFIED, "failed": FAILED}[verdict]
    return run, estimate, status, n_steps, n_rhs


def one_pass(problem: Problem, rtol, atol, max_steps, jit_pref, progress, *,
             rounding: float = 0.0):
    """``auto`` in one compiled pass (`dynamics.integrate.adaptive`) where it applies:
    returns ``(run, estimate, steps)``, or ``(None, nan, steps)`` to leave the problem to
    the multi-run search (`auto_runs`) with ``steps`` already spent.

    The check run (``b`` steps per interval, chosen by DOP853's embedded estimate) and the
    answer (``n = 2 b + 1``, or 2 for ``b = 1``; ``r`` the least ``n / b``) differ by ``d``
    (scaled, max over the outputs). Accepted:

    * when the two runs show the method's order (in at least half of at least 3 intervals
      where both estimates were measured clear of rounding, ``e > 30 eps / rtol`` in
      tolerance units, ``log(ec / e) / log(n / b)`` lies in [5, 10]: measured 7-8 on the
      rigid body, the estimate being of order h^7-h^8): at ``d / (r^6 - 1)`` (the Richardson
      estimate of `_estimate`, two orders low) plus 1000 ulps of each state, when that is
      at most 0.5;
    * when no estimate of the answer stands clear of rounding (``e <= 30 eps / rtol`` in
      every one of at least 12 intervals): as above, the answer's steps times that level
      added (its truncation, step by step, is at most the rounding level);
    * otherwise at ``2 d`` plus the ulps when at most 1 (the answer is at least twice as
      accurate as the check: ``e <= d``), every check step measured being within DOP853's
      local tolerance.

    Within `PASS_MEASURED` ulps of a state's size, the tolerance may meet the rounding of
    the model's own formulas, which both runs share: the pass measures it (the change of
    ``f`` when its state moves by one ulp) and `measured_floor`'s screening bound, carried over the
    horizon with the spectral radius at ``x0``, must be below 0.05 (it is added to the
    estimate); otherwise the multi-run search measures the flow's real amplification.

    ``rounding``: a rounding floor measured before (`dense_pass`'s), added at least. Where
    the Richardson division decides (``2 d`` plus the ulps above 1), the part of ``d`` that
    the check's start, 2 ulp away, makes is not truncation and is not divided: near a
    separatrix the flow amplifies it 1e8-fold (``d`` 1.0-5.6 tolerances estimated at
    0.02-0.09, answers 1.3-2.6 tolerances off); `_amplified` measures it (the check's steps
    replayed from the exact start), added to the estimate, which is then accepted within
    1, or left to the multi-run search.

    Not accepted, the pass is repeated aimed tighter (`_PASS_TRIES` in all). Not taken: a
    callable control, no compiled pass, a tolerance within `PASS_ULPS` ulps of a state, a
    non-finite state or an interval that needs more than ``2 cpass.BMAX + 1`` steps.
    """
    if problem.control.mode != "linear" or not auto_jit(jit_pref):
        return None, math.nan, 0
    if sizes_over_tolerance(problem.model, problem.x0[None], rtol, atol)[0] * EPS * \
            PASS_ULPS > 1.0:
        return None, math.nan, 0  # (the states' sizes put the tolerance near round-off)
    horizon = float(problem.t[-1] - problem.t[0])
    theta = PASS_THETA / horizon
    spent, bmin = 0, 1
    for _ in range(_PASS_TRIES):
        got = run_pass(problem, rtol, atol, theta, max_steps - spent, progress, bmin=bmin,
                       ulps=PASS_ULPS)
        if got is None:
            return None, math.nan, spent
        spent += got.n_steps
        estimate, extra, factor = pass_verdict(problem, got, rtol, atol, rounding, progress)
        spent += extra
        if estimate is not None:
            return pass_run(got, spent, estimate), estimate, spent
        if factor is None:
            return None, math.nan, spent
        theta /= factor ** 7
        bmin = max(bmin, math.ceil(factor * (got.stats[:, 3] - got.stats[:, 0]).mean()))
        if bmin > BMAX:
            return None, math.nan, spent
    return None, math.nan, spent


def pass_verdict(problem: Problem, got, rtol, atol, rounding, progress, *,
                 bound: float | None = None,
                 replayed: np.ndarray | None = None) -> tuple[float | None, int, float | None]:
    """`one_pass`'s verdict on its pass ``got`` over ``problem`` (see there):
    ``(estimate, extra, factor)``, ``estimate`` the accepted answer's (None: not accepted),
    ``extra`` the steps `_amplified` made, ``factor`` (not accepted) how much finer the
    next pass's steps are aimed, None when the problem is left to the multi-run search.
    ``bound``: `rounding_bound`'s, and ``replayed``: the check replayed from the exact start
    (`adaptive.replay_check`'s), when known (a batch finds its runs' at once)."""
    if not got.ok:
        return None, 0, None
    d, ulps = got.d, max(got.ulp * FLOOR_ULPS, rounding)
    if got.ulp * PASS_MEASURED > 1.0:  # near round-off: the model's rounding, measured
        if bound is None:
            bound = rounding_bound(problem, got, rtol, atol,
                                   below=min(ulps, 0.1 * AUTO_ACCEPT))
        if not bound <= 0.1 * AUTO_ACCEPT:
            return None, 0, None  # (the multi-run search measures the flow's)
        ulps = max(ulps, bound)
    shown, measured = got.orders
    richardson = d / (got.ratio ** 6 - 1)
    if measured == 0 and got.stats.shape[0] >= 3 * CHECK_EVERY:
        # the answer's own estimates are all at the rounding level: its truncation is
        # at most that level per step, added up over its steps
        richardson += got.answer_steps * NOISE * EPS / rtol
        trusted = True
    else:
        trusted = measured >= 3 and 2 * shown >= measured
    if trusted and richardson + ulps <= AUTO_ACCEPT:
        if 2 * d + ulps <= 1.0:
            return richardson + ulps, 0, None
        # (the Richardson division decides: what the check's start made of it, measured)
        floor, extra = _amplified(problem, got, rtol, atol, progress, replayed)
        if not richardson + max(floor, ulps) <= 1.0:
            return None, extra, None  # (the multi-run search says what it is)
        return richardson + max(floor, ulps), extra, None
    if got.ec <= 1.0 and 2 * d + ulps <= 1.0:
        return 2 * d + ulps, 0, None
    if not math.isfinite(d):
        return None, 0, None
    # aim at an estimate of 0.05 (d ~ h^8, the embedded estimate ~ h^7)
    return None, 0, max(1.1, ((richardson if trusted else 2 * d) / 0.05) ** (1 / 8))


def rounding_bound(problem: Problem, got, rtol, atol, *, below: float = 0.0) -> float:
    """The screening bound (`estimates.screen`) of the model's rounding that the pass
    ``got`` measured, carried over the horizon with the spectral radius at ``x0``
    (`Single.spectrum`): how much of the tolerance it may take; ``below`` as
    `rounding_bounds` takes it (`pass_verdict` gives the least of the states' ulps, which
    it adds anyway, and the 0.05 it refuses above)."""
    horizon = float(problem.t[-1] - problem.t[0])
    J = jacobian_at(problem)
    spectral = lambda _: Single(problem).spectrum(rtol, atol, J=J)[0]  # noqa: E731
    if J is None:
        lipschitz = spectral(0)
        return screen(carried(got.rounding, horizon, lipschitz), got.smin, horizon, lipschitz)
    return float(rounding_bounds(J[None], got.rounding[None], got.smin[None], horizon,
                                 np.array([below]), spectral)[0])


def rounding_bounds(J: np.ndarray, rounding: np.ndarray, smin: np.ndarray, horizon: float,
                    below: np.ndarray, spectral) -> np.ndarray:
    """`rounding_bound` of R runs at once (a single call's, R = 1, and a sampled batch's,
    `batch._bounds`: one place, the same bits): their Jacobians at ``x0`` ``J (R, nx,
    nx)``, the rounding their passes measured and their least tolerances ``(R, nx)``;
    shape ``(R,)``.

    ``below (R,)``: a level under which a run's bound decides nothing. The bound grows with
    the rate it is carried with, and ``|J|_inf`` (`estimates.norm_bounds`) is at least the
    spectral radius, so the bound with it is an upper bound; where that lies under
    ``below`` (a margin of 1e-9 for the rounding of both) it is taken and the eigenvalues
    (half of the bound's cost on the rigid body) are not computed: a verdict that adds the
    larger of the bound and ``below`` is the same to the bit. Elsewhere the spectral radius
    (`estimates.spectra`), or ``spectral(i)`` for run ``i`` where that is not finite."""
    upper = norm_bounds(J)
    bound = screens(carried(rounding, horizon, upper), smin, horizon, upper)
    exact = np.flatnonzero(~(bound <= below * (1 - 1e-9)))
    if exact.size:
        radius = spectra(J[exact])[0]
        for i in np.flatnonzero(np.isnan(radius)).tolist():
            radius[i] = spectral(int(exact[i]))
        bound[exact] = screens(carried(rounding[exact], horizon, radius), smin[exact],
                               horizon, radius)
    return bound


def pass_run(got, spent: int, estimate: float) -> Run:
    """The `Run` of `one_pass`'s accepted pass ``got`` (``spent`` the steps of every pass
    and measurement made, ``estimate`` its verdict's)."""
    lo, hi = got.n_range
    message = (f"auto: rk8 with embedded error control: {got.answer_steps} steps ({lo}-{hi} "
               "per output interval), checked against a run with fewer than half the steps; "
               f"estimated error {estimate:.2g} of tolerance")
    return Run.new(got.x, spent, DOP853.stages * spent, hi, True, True, message)


def _amplified(problem: Problem, got, rtol, atol, progress,
               replayed: np.ndarray | None = None) -> tuple[float, int]:
    """`one_pass`'s measure of what the flow made of its check's start, 2 ulp away:
    ``(floor, steps)``, twice the scaled difference of the check ``got.xc`` from its own
    steps replayed from the exact start (`adaptive.replay_check`, or ``replayed`` when made
    before: the same truncation, so the difference is the amplified start alone; twice:
    one start is one draw of the rounding, as `cpass`'s ``AU_JITTER_SPREAD`` measures), inf
    when the replay fails."""
    x = replay_check(problem, got) if replayed is None else replayed
    steps = int(check_steps(got).sum())
    if x is None:
        return math.inf, 0
    progress.step(steps, 1.0)
    scale = atol[:, None] + rtol * np.abs(got.x[:, 1:])
    return 2 * scaled_diff(x[:, 1:], got.xc[:, 1:], scale), steps


def dense_pass(problem: Problem, rtol, atol, max_steps, progress):
    """``auto`` for a smooth right-hand side under a control constant over the run: DOP853
    stepping by its error estimate alone, the outputs filled from its continuous extension
    (`stepcontrol.plain_run`), so the work follows the solution, not the output grid; the
    answer, its check (its steps merged in pairs), their comparison and the verdict in
    one compiled call (`dense.dense_auto`, whose docstring states the rules).
    Returns ``(run, estimate, status, spent, floor)``: status ``OK`` (verified), ``ROUNDOFF``
    (not verified because the tolerance lies below the rounding floor of double precision:
    1000 ulps of a state's size, with the carried rounding, or the rounding floor measured
    exceed it at the outputs, so no path of ``auto`` can verify it; the answer is returned
    at once with its estimate, `_floor_message` words it), or ``(None, nan, None, spent,
    floor)`` to leave the problem to `one_pass` and the multi-run
    search (stiff by the first step's Lipschitz estimate: more than `STIFF_STEPS` steps for
    stability alone; no compiled library, a control that varies, a requested tolerance below
    one ulp of a state's size, a failed run, or no verdict after `dense.TRIES` answers).

    Within `PASS_MEASURED` ulps of a state's size the rounding the answer measured on its
    way, carried over the horizon, is added; where it is not small, the floor measured by the
    answer repeated with each step's rounding emulated at random (one or two draws: `dense`),
    in the same call.
    ``spent``: the steps of its runs (counted in the result whichever path answers);
    ``floor`` the rounding floor measured (0: none), which the other paths then add at
    least (they model the rounding; the pass measured it).
    """
    got = dense_auto(problem, rtol, atol, max_steps, STIFF_STEPS, progress=progress)
    if got is None:
        return None, math.nan, None, 0, 0.0
    out = dense_outcome(got, rtol)
    return (*out, got.spent, got.floor) if out is not None else \
        (None, math.nan, None, got.spent, got.floor)


def dense_outcome(got: DenseAuto, rtol: float) -> tuple[Run, float, int] | None:
    """``(run, estimate, status)`` of a dense pass's outcome ``got`` that answers: ``OK``
    (verified) or ``ROUNDOFF`` (not verified below the rounding floor, `dense_pass`); None
    for one left to auto's other paths. Shared by `dense_pass` and `simulate`'s common
    call (which would otherwise run the same pass again on the general path)."""
    if got.result == 1:
        return *dense_answer(got, rtol), OK
    if got.result == 0 and max(got.ulps + got.bound, got.floor) > 1.0:
        # (every path accepts at most a floor of the tolerance: `auto_runs`' estimate plus
        # its floor, which is at least these ulps, within 1; and the floor the pass measured
        # is the rounding of this problem in double precision, whichever path runs it: the
        # other paths model it, the pass measured it)
        return (Run.new(got.x, got.spent, DOP853.stages * got.spent, got.substeps, True, True,
                        _floor_message(got, rtol)), got.estimate, ROUNDOFF)
    return None


def _floor_message(got: DenseAuto, rtol: float) -> str:
    """The message of `dense_pass`'s answer below the rounding floor: what was asked, what
    the floor is (the states' ulps, or the rounding the flow amplifies, measured), the
    answer's estimate and the remedy."""
    fixed = got.ulps + got.bound
    if got.floor > fixed:
        what = (f"the rounding of its steps, amplified by the flow, reaches {got.floor:.2g} "
                "of the tolerance at the outputs")
    else:
        what = (f"1000 ulps of the largest state's size are {got.ulps:.2g} of its least "
                "tolerance at the outputs"
                + (f", the rounding carried over the horizon {got.bound:.2g} more"
                   if got.bound else ""))
    return (f"auto: tolerance not verified: it lies below the round-off floor of double "
            f"precision for these states ({what}); {dense_message(got, rtol)[len('auto: '):]}; "
            f"x is the best solution found; remedy: rtol and atol at least "
            f"{4 * max(fixed, got.floor):.2g}x looser" + (" or a shorter horizon"
                                                          if got.floor > fixed else ""))


def dense_answer(got: DenseAuto, rtol: float) -> tuple[Run, float]:
    """``(run, estimate)`` of a verified `dense.DenseAuto` (``got.result`` 1) for the
    requested ``rtol``: its answer and step counts, its message made on first use
    (`dense_message`)."""
    return Run.new(got.x, got.spent, DOP853.stages * got.spent, got.substeps, True, True,
                   partial(dense_message, got, rtol)), got.estimate


def dense_message(got: DenseAuto, rtol: float) -> str:
    """The message of `dense_answer`'s run: the answer's steps, its check and the estimate."""
    return (f"auto: DOP853 with dense output, steps chosen by its error estimate "
            f"({got.answer_steps - got.rejected} steps, {got.rejected} rejected, "
            f"{got.interpolated} interpolated, local rtol {rtol * got.factor:.3g}), checked "
            f"against its steps merged in pairs ({got.check_steps} steps); estimated error "
            f"{got.estimate:.2g} of tolerance"
            + (f" (a rounding floor of {got.floor:.2g} measured by {got.draws} "
               f"rerun{'s' if got.draws > 1 else ''} with each step's rounding emulated "
               "included)" if got.floor > 0 else ""))


def sizes_over_tolerance(model, x0: np.ndarray, rtol: float, atol: np.ndarray) -> np.ndarray:
    """The largest ``|x0_i| / (atol_i + rtol |x0_i|)`` of each run ``x0 (K, nx)`` (shape
    ``(K,)``; inf for a zero tolerance of a nonzero state); a unit quaternion's parts
    (``model.attitude``) count at its norm over ``atol`` (they reach both)."""
    size = np.abs(x0)
    least = atol + rtol * size
    if model.attitude is not None:
        iq = model.attitude[0]
        q = size[:, iq:iq + 4]
        size[:, iq:iq + 4] = np.sqrt(q[:, 0] * q[:, 0] + q[:, 1] * q[:, 1] + q[:, 2] * q[:, 2]
                                     + q[:, 3] * q[:, 3])[:, None]
        least[:, iq:iq + 4] = atol[iq:iq + 4]
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(least > 0, size / least, np.inf)
    return np.where(size > 0, ratio, 0.0).max(axis=1, initial=0.0)


def nonsmooth_causes(problem: Problem, *, operations: tuple | None = None) -> tuple[str, ...]:
    """Why ``problem``'s right-hand side may be non-smooth: the non-smooth operations of
    the model (`smoothness.nonsmooth_operations`, or ``operations`` when they are known),
    and ``"callable u"`` for a control that is a Python callable (it may jump); ``()`` when
    it is smooth."""
    found = nonsmooth_operations(problem.model.f) if operations is None else operations
    return found + (("callable u",) if problem.control.mode == "stages" else ())


def _nonsmooth_remedy(causes, cause: str = "") -> str:
    """The words of status ``NONSMOOTH``: the causes found, ``cause`` (what else is known)
    and the remedy."""
    return (f"non-smooth right-hand side ({', '.join(causes)}): order loss at kinks"
            f"{', ' + cause if cause else ''}; remedy: a looser tolerance, a smooth law (e.g. "
            "tanh instead of a saturation), output times on the switching times, or a "
            "control given as samples (hold='zoh')")


def _auto_stepped(problem: Problem, rtol, atol, max_steps, jit, progress, causes):
    """``auto`` for a non-smooth right-hand side (`stepcontrol`): ``(run, method, status,
    estimate)``, or None to leave it to the general path (no compiled stepper for a
    sampled control, or a stiff problem, which goes to cvodes). A callable control steps
    from Python (`stepcontrol.run_stepped_callable`)."""
    if problem.control.mode == "linear" and not auto_jit(jit):
        return None
    lipschitz, sigma = Single(problem).spectrum(rtol, atol)
    horizon = float(problem.t[-1] - problem.t[0])
    if horizon * sigma / _RK8_STABILITY > STIFF_STEPS:
        return None
    run, verdict, estimate, n_steps, n_rhs = solve_stepped(problem, rtol, atol, max_steps,
                                                           progress=progress)
    if verdict is None:
        return None
    head = f"auto: non-smooth right-hand side ({', '.join(causes)})"
    if verdict == "met":
        message = (f"{head}: DOP853 with step rejection, its steps crowded at the kinks "
                   f"({run.message}); estimated error {estimate:.2g} of tolerance, from a "
                   "run at a 100x looser local tolerance and steps at least twice as long")
        status = OK
    elif verdict == "tightest":
        message = (f"auto: tolerance not verified: {_nonsmooth_remedy(causes)} (DOP853 with "
                   f"step rejection down to local rtol {LOCAL_RTOL_MIN:g}: runs still differ by "
                   f"{estimate:.2g} of tolerance; {run.message}); x is the best solution found")
        status = NONSMOOTH
    elif "max_steps" in run.message:  # (x: NaN from the stop on, as auto's other paths)
        message = (f"auto: tolerance not verified: {run.message} ({head}); raise max_steps "
                   "or loosen the tolerance")
        return (Run(run.x, n_steps, n_rhs, 0, run.compiled, True, message), "dop853",
                UNVERIFIED, estimate)
    else:
        message, status = f"{head}: {run.message}", FAILED
    return (Run(run.x, n_steps, n_rhs, 0, run.compiled, run.ok, message), "dop853", status,
            estimate)


def solve_auto(problem: Problem, rtol, atol, max_steps, jit, cvodes_options, progress, *,
               nonsmooth: tuple | None = None):
    """``auto``: -> (run, method used, status, error estimate); counters cover every run;
    ``nonsmooth`` the model's non-smooth operations when known (`nonsmooth_causes`).

    A right-hand side with kinks (`nonsmooth_causes`) goes to DOP853 with step rejection
    (`_auto_stepped`), which does not assume the method's order; a smooth one under a
    constant control to DOP853 with dense output (`dense_pass`: its steps follow the error,
    never the output grid); then (a control that varies, or no verdict) to the one-pass
    path, then the multi-run Richardson search (`auto_runs`)."""
    causes = nonsmooth_causes(problem, operations=nonsmooth)
    spent = tried = 0
    rounding = 0.0  # (the rounding floor the dense pass measured: the others add it)
    if causes:
        got = _auto_stepped(problem, rtol, atol, max_steps, jit, progress, causes)
        if got is not None:
            return got
    else:
        run, estimate, status, tried, rounding = dense_pass(problem, rtol, atol, max_steps,
                                                            progress) \
            if auto_jit(jit) else (None, math.nan, None, 0, 0.0)
        if run is not None:  # (DOP853's 8th-order steps, as the fixed-step rk8)
            return run, "rk8", status, estimate
        run, estimate, spent = one_pass(problem, rtol, atol, max_steps, jit, progress,
                                        rounding=rounding)
        if run is not None:  # (the steps of every path tried are counted)
            return Run.new(run.x, run.n_steps + tried, run.n_rhs + DOP853.stages * tried,
                           run.substeps, run.compiled, run.ok, run.message,
                           quat_off=run.quat_off), "rk8", OK, estimate
    run, estimate, status, reason, n_steps, n_rhs = auto_runs(Single(problem), rtol, atol,
                                                          max_steps - spent, jit, progress,
                                                          rounding=rounding)
    spent += tried
    n_steps, n_rhs = n_steps + spent, n_rhs + DOP853.stages * spent
    if run is None and reason.startswith("stiff"):
        crun, estimate, status, cs, cr = _auto_cvodes(problem, rtol, atol, cvodes_options)
        verdict = {OK_STIFF: f"estimated error {estimate:.2g} of tolerance (from runs at "
                             "tightened local tolerances)",
                   UNVERIFIED: f"the tolerance could not be verified (estimated error "
                               f"{estimate:.2g} of tolerance at the tightest local tolerance)",
                   FAILED: "the integration failed"}[status]
        message = f"auto: {reason}: used cvodes; {verdict}. {crun.message}"
        return (Run(crun.x, n_steps + cs, n_rhs + cr, 0, False, crun.ok, message), "cvodes",
                status, estimate)
    if run is None:
        x = np.full((problem.model.nx, problem.t.size), np.nan)
        x[:, 0] = problem.x0
        return (Run(x, 0, 0, 0, False, True, f"auto: tolerance not verified: {reason}; "
                    "no run was made (raise max_steps or shorten the grid)"), "rk8", status,
                math.nan)
    if not run.ok:
        return (Run(run.x, n_steps, n_rhs, run.substeps, run.compiled, False,
                    f"auto: {run.message}"), "rk8", FAILED, estimate)
    if status == ROUNDOFF:
        message = ("auto: tolerance not verified: it lies at the round-off floor of fixed-step "
                   f"runs on this grid ({run.message}; estimated error incl. modelled round-off "
                   f"{estimate:.2g} of tolerance); x is the best solution found; remedy: rtol "
                   f"and atol at least {4 * max(estimate, 1.0):.2g}x looser, or a shorter "
                   "horizon")
    elif status == NONSMOOTH:
        message = (f"auto: tolerance not verified: "
                   f"{_nonsmooth_remedy(Single(problem).nonsmooth, 'not round-off')}"
                   f" (rk8 runs of different step counts do not converge at order 8"
                   f"{': ' + reason if reason else ''}; {run.message}; estimated error "
                   f"{estimate:.2g} of tolerance); x is the best solution found")
    elif status == UNVERIFIED:
        message = (f"auto: tolerance not verified: {reason} ({run.message}; estimated error "
                   f"{estimate:.2g} of tolerance); x is the best solution found")
    else:
        message = f"auto: {run.message}; estimated error {estimate:.2g} of tolerance"
    return (Run(run.x, n_steps, n_rhs, run.substeps, run.compiled, True, message), "rk8",
            status, estimate)
