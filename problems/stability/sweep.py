"""`sweep`: run a case along one parameter and locate each verdict boundary by bisection."""
from __future__ import annotations

import functools
import inspect

import numpy as np

from appdyn.dynamics.executors import check_executor, gather
from appdyn.dynamics.progress import accepts_progress_bar
from appdyn.dynamics.interrupts import check_interrupt, deferred_interrupts, interruptible
from appdyn.dynamics.results import timed

from .cases import resolve_case
from .common import plain
from .sweep_result import Boundary, SweepResult

__all__ = ["Boundary", "SweepResult", "sweep"]

_STABLE_UNSTABLE = {"asymptotically stable", "unstable"}
_BAND_RTOL = 1e-4  # a "marginally stable" stretch this narrow between the two is a zero band


def _control_first(fun):
    """``fun`` with python-control imported before it runs, a Ctrl-C during the import held
    until the import ends.

    The analyses of a sweep import python-control on first use (~1 s: scipy, matplotlib). A
    SIGINT landing inside those third-party imports is not reliably a ``KeyboardInterrupt``:
    it can be swallowed (the sweep runs on) or turned into ``RuntimeError: Error calling
    __set_name__`` in ``matplotlib.ticker``, leaving matplotlib half-imported. Deferred, it is
    raised as a plain ``KeyboardInterrupt`` right after the import, with the modules whole.
    """
    @functools.wraps(fun)
    def wrapper(*args, **kwargs):
        with deferred_interrupts():
            import control  # noqa: F401
        return fun(*args, **kwargs)
    return wrapper


@timed
@accepts_progress_bar("sweep")
@_control_first
@interruptible
def sweep(case, parameter: str, values, *, rtol: float = 1e-8, progress=None, executor=None,
          **case_kwargs) -> SweepResult:
    """Run ``case`` for each value of ``parameter`` and locate the verdict boundaries.

    Between consecutive values with different verdicts the boundary is bisected until the
    bracket is within ``rtol`` of its magnitude (1e-8 by default). Between "asymptotically
    stable" and "unstable" the sign of the largest real part is bisected instead of the
    verdict: it crosses zero continuously, while the verdict's zero band around the crossing
    (``|Re| <= ZERO_RTOL rho``, about ``ZERO_RTOL rho / |d Re / d parameter|`` wide) would
    give two boundaries. The same holds when a grid value falls inside that band: a
    "marginally stable" stretch narrower than 1e-4 relative between "unstable" and
    "asymptotically stable" is reported as one boundary at the crossing.

    Parameters
    ----------
    case : str or callable
        A name in `CASES` or `CASE_ALIASES` (``'heavy-top'``, ``'projectile'``), or the case
        function.
    parameter : str
        The keyword swept, e.g. ``'rate'`` or ``'wheel_momentum'``.
    values : array_like, shape (n,)
        Strictly increasing, finite, ``n >= 1``.
    rtol : float, optional
        Relative bracket width of the bisection.
    progress : bool or callable, optional
        ``True``: a bar on stderr (`dynamics.progress`); a callable: ``progress(done,
        total)`` after each grid value (``total = len(values)``; the
        bisections that follow are not counted). With an ``executor``, called in the calling
        thread as the grid values complete (in completion order).
    executor : concurrent.futures.Executor, optional
        Spread the work over this executor (a ``ThreadPoolExecutor``, a
        ``ProcessPoolExecutor``, dask.distributed's ``client.get_executor()``, ...): every
        grid value is one task, then the bisection between each pair of neighbouring grid
        values whose verdicts differ is one task. The result is the serial one: the same
        verdicts, eigenvalues, boundaries and ``evaluations`` (each task runs the serial
        code). The executor stays the caller's (not shut down). ``None`` (default): serial,
        in the calling thread.

        A process pool receives the case by name (looked up in `CASES` in the worker), so
        ``case_kwargs`` must pickle (numbers, arrays, the damper and vehicle objects of
        this package do); the workers import ``problems.stability`` (and CasADi) on first
        use, about a second each, so a process pool pays off for expensive cases or many
        values. Any start method works (``fork``, ``spawn``, ``forkserver``); with
        ``spawn`` the calling script needs the usual ``if __name__ == "__main__":`` guard.
        The merge of a verdict's zero band around a crossing (below) runs in the caller.
    **case_kwargs
        The case's other arguments (by keyword).

    Returns
    -------
    SweepResult

    Raises
    ------
    ValueError
        Naming ``case``, ``parameter``, ``values`` or ``rtol``; a ValueError of the case at
        one value is re-raised with that value (with an ``executor``: the error of the
        lowest failing grid value, as in a serial run; the tasks after it are cancelled).
    TypeError
        If ``executor`` is not a ``concurrent.futures.Executor``.
    KeyboardInterrupt
        On Ctrl-C (within one case evaluation, `dynamics.interrupts`). When some grid values
        were finished, the exception's ``partial`` attribute is their `SweepResult`
        (``complete=False``, with the boundaries located before the interrupt)::

            try:
                res = stability.sweep(...)
            except KeyboardInterrupt as exc:
                res = getattr(exc, "partial", None)

        With an ``executor`` the wait for the tasks looks for Ctrl-C every 0.1 s; the tasks
        not yet started are cancelled, and ``partial`` holds every grid value finished by
        then (in grid order; not necessarily a prefix of ``values``) and the boundaries of
        the finished bisection tasks. Tasks already running cannot be stopped from here:
        they finish in the background (threads) or in their worker (processes, unless the
        Ctrl-C reached the workers too), and shutting the executor down waits for them.

    Examples
    --------
    The sleeping top (RP-1262, Sec. 4.6, Eq. 4.128: ``w0 = (2 / I1) sqrt(m g l I2)``):

    >>> import numpy as np
    >>> from appdyn.problems import stability
    >>> res = stability.sweep("heavy_top", "rate", np.linspace(0, 60, 7), axial_inertia=0.002,
    ...                       transverse_inertia=0.005, mass=0.3, length=0.04)
    >>> res.verdicts[0], res.verdicts[-1]
    ('unstable', 'marginally stable')
    >>> b = res.boundaries[0]
    >>> print(f"{b.value:.6f}: {b.before} -> {b.after}")
    24.256937: unstable -> marginally stable

    The same sweep on two threads; in a script, a process pool the same way (the case
    travels by name, the arguments must pickle; `dynamics.executors.process_pool` starts
    its workers from a fork server, safe in a process that runs threads)::

        from appdyn.dynamics.executors import process_pool

        if __name__ == "__main__":
            with process_pool(max_workers=2) as pool:
                res = stability.sweep("heavy_top", "rate", ..., executor=pool)

    >>> from concurrent.futures import ThreadPoolExecutor
    >>> with ThreadPoolExecutor(max_workers=2) as pool:
    ...     again = stability.sweep("heavy_top", "rate", np.linspace(0, 60, 7),
    ...                             axial_inertia=0.002, transverse_inertia=0.005, mass=0.3,
    ...                             length=0.04, executor=pool)
    >>> again.boundaries == res.boundaries and again.to_json() == res.to_json()
    True
    """
    name, fun = resolve_case(case)
    sig = inspect.signature(fun)
    if not isinstance(parameter, str):
        raise TypeError(f"`parameter` must be the name of an argument of {name}: "
                        f"{list(sig.parameters)}, got {type(parameter).__name__}")
    if parameter not in sig.parameters:
        raise ValueError(f"`parameter` must be an argument of {name}: {list(sig.parameters)}, "
                         f"got {parameter!r}")
    if parameter in case_kwargs:
        raise ValueError(f"`{parameter}` is swept; do not pass it in case_kwargs")
    try:
        vals = np.array(values, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise ValueError(f"`values` must be numbers, got {values!r}") from None
    if vals.size < 1 or not np.all(np.isfinite(vals)) or np.any(np.diff(vals) <= 0):
        raise ValueError(f"`values` must be finite and strictly increasing, got {vals.tolist()}")
    if not (np.isfinite(rtol) and 1e-15 <= rtol < 1):
        raise ValueError(f"`rtol` must be in [1e-15, 1), got {rtol}")
    try:
        sig.bind(**{parameter: vals[0]}, **case_kwargs)
    except TypeError as exc:
        raise ValueError(f"`case_kwargs` do not fit {name}{sig}: {exc}") from None

    check_executor(executor)
    evaluate = _Case(name, parameter, case_kwargs)
    count = [0]

    def run(v):
        check_interrupt()
        count[0] += 1
        return evaluate(v)

    def crossing(lo, hi, unstable_at_lo):
        return _crossing(run, lo, hi, unstable_at_lo, rtol)

    reports, found = [], []
    done = {}  # grid index -> report, with an executor

    def result(boundaries, complete=True):
        if executor is None:
            return _result(name, parameter, vals[:len(reports)], reports, boundaries, rtol,
                           count[0], case_kwargs, complete)
        order = sorted(done)
        return _result(name, parameter, vals[order], [done[i] for i in order], boundaries,
                       rtol, count[0], case_kwargs, complete)

    if executor is not None:
        return _sweep_on(executor, evaluate, vals, rtol, progress, done, count, crossing,
                         result)
    try:
        for v in vals:
            reports.append(run(v))
            if progress is not None:
                progress(len(reports), len(vals))
        verdicts = tuple(r.verdict for r in reports)
        for i in range(len(vals) - 1):
            if verdicts[i] != verdicts[i + 1]:
                found += _locate(run, vals[i], verdicts[i], vals[i + 1], verdicts[i + 1], rtol)
        return result(_merged(found, rtol, crossing))
    except KeyboardInterrupt as exc:
        if reports:  # what was finished rides on the interrupt
            exc.partial = result(tuple(found), complete=False)
        raise


class _Case:
    """One case at fixed arguments, called with a value of the swept parameter.

    Picklable for a process pool: the case travels by name and is looked up in `CASES` on
    the worker.
    """

    def __init__(self, name, parameter, case_kwargs):
        self.name, self.parameter, self.case_kwargs = name, parameter, case_kwargs

    def __call__(self, v):
        fun = resolve_case(self.name)[1]
        try:
            return fun(**{self.parameter: float(v)}, **self.case_kwargs)
        except ValueError as exc:
            raise ValueError(f"{self.name} at {self.parameter} = {float(v)!r}: {exc}") from None


def _narrow(lo, hi, rtol) -> bool:
    return abs(hi - lo) > rtol * max(abs(lo), abs(hi)) and lo < 0.5 * (lo + hi) < hi


def _crossing(run, lo, hi, unstable_at_lo, rtol):
    """Bisect the sign of the largest real part (continuous through the crossing)."""
    while _narrow(lo, hi, rtol):
        mid = 0.5 * (lo + hi)
        if (run(mid).least_damped().real > 0) == unstable_at_lo:
            lo = mid
        else:
            hi = mid
    return lo, hi


def _locate(run, a, va, b, vb, rtol) -> list:
    """The boundaries between ``a`` (verdict ``va``) and ``b`` (``vb``), by bisection."""
    if {va, vb} == _STABLE_UNSTABLE:
        lo, hi = _crossing(run, a, b, va == "unstable", rtol)
        return [Boundary(0.5 * (lo + hi), lo, hi, va, vb)]
    lo, hi, vhi = a, b, vb
    while _narrow(lo, hi, rtol):
        mid = 0.5 * (lo + hi)
        vm = run(mid).verdict
        if vm == va:
            lo = mid
        else:
            hi, vhi = mid, vm
    here = [Boundary(0.5 * (lo + hi), lo, hi, va, vhi)]
    if vhi != vb:
        here += _locate(run, hi, vhi, b, vb, rtol)
    return here


def _locate_task(evaluate, a, va, b, vb, rtol):
    """`_locate` as one executor task: ``(boundaries, evaluations)``."""
    count = [0]

    def run(v):
        count[0] += 1
        return evaluate(v)

    return _locate(run, a, va, b, vb, rtol), count[0]


def _sweep_on(executor, evaluate, vals, rtol, progress, done, count, crossing, result):
    """The body of `sweep` with an executor: the grid values, then one bisection task per
    verdict change; ``done`` (grid index -> report) is filled as they finish."""
    located = {}  # interval index -> boundaries
    try:
        def grid_done(i, report):
            done[i] = report
            count[0] += 1
            if progress is not None:
                progress(len(done), len(vals))

        gather(executor, evaluate, [(v,) for v in vals], grid_done)
        verdicts = [done[i].verdict for i in range(len(vals))]
        changes = [i for i in range(len(vals) - 1) if verdicts[i] != verdicts[i + 1]]

        def bisected(k, out):
            located[changes[k]] = out[0]
            count[0] += out[1]

        gather(executor, _locate_task,
                [(evaluate, vals[i], verdicts[i], vals[i + 1], verdicts[i + 1], rtol)
                 for i in changes], bisected)
        found = [b for i in sorted(located) for b in located[i]]
        return result(_merged(found, rtol, crossing))
    except KeyboardInterrupt as exc:
        if done:
            exc.partial = result(tuple(b for i in sorted(located) for b in located[i]),
                                 complete=False)
        raise


def _merged(found, rtol, crossing) -> tuple:
    """Boundaries in sweep order, a verdict's zero band around a crossing (or brackets
    closer than ``rtol``) merged into one boundary."""
    boundaries = []
    for bnd in found:
        prev = boundaries[-1] if boundaries else None
        if prev is not None and prev.after == bnd.before:
            gap = abs(bnd.upper - prev.lower)
            scale = max(abs(prev.value), abs(bnd.value))
            if {prev.before, bnd.after} == _STABLE_UNSTABLE and gap <= _BAND_RTOL * scale:
                # a zero band of the verdict around a crossing: one boundary, at the crossing
                lo, hi = crossing(prev.lower, bnd.upper, prev.before == "unstable")
                boundaries[-1] = Boundary(0.5 * (lo + hi), lo, hi, prev.before, bnd.after)
                continue
            if gap <= rtol * scale and prev.before != bnd.after:
                boundaries[-1] = Boundary(0.5 * (prev.lower + bnd.upper), prev.lower, bnd.upper,
                                          prev.before, bnd.after)
                continue
        boundaries.append(bnd)
    return tuple(boundaries)


def _result(name, parameter, vals, reports, boundaries, rtol, evaluations, case_kwargs,
            complete) -> SweepResult:
    """The `SweepResult` of ``reports`` at the grid values ``vals``."""
    m = max(len(r.eigenvalues) for r in reports)
    ev = np.full((len(vals), m), np.nan + 1j * np.nan, dtype=complex)
    for i, r in enumerate(reports):
        ev[i, :len(r.eigenvalues)] = r.eigenvalues
    return SweepResult(case=name, parameter=parameter, values=np.array(vals),
                       verdicts=tuple(r.verdict for r in reports),
                       least_damped=np.array([r.least_damped() for r in reports], dtype=complex),
                       eigenvalues=ev, boundaries=tuple(boundaries), rtol=float(rtol),
                       evaluations=evaluations, case_kwargs=plain(case_kwargs),
                       statuses=tuple(r.status for r in reports), complete=complete)
