"""Sanity of a fixed-step run: the model's invariants checked at the output grid.

A fixed-step method takes no tolerance, so a step far too large for the motion gives a
finite but meaningless answer (``rk4`` with one step of 500 s on a tumbling body: a
quaternion of norm 1e30). `violations` finds such runs from what the model itself promises,
at the output times only (one vectorized evaluation):

* the attitude quaternion (``model.attitude``) keeps unit norm: off by more than
  `QUAT_DRIFT` at any output time is gross (for ``rk4``/``rk8`` on a model with an
  attitude this is the whole check: see `violation`);
* an invariant of ``model.invariants`` that the flow conserves along this run (its rate
  ``dI/dx . f(x, u, p)`` vanishes to rounding, `RATE_RTOL`, at every output state with the
  run's control: energy and momentum of a torque-free body, a quantity conserved whatever
  the control) may not change by more than `INVARIANT_DRIFT` times its initial size
  (a run that keeps it to 1e-3 is not flagged: this catches blow-ups, it does not grade
  accuracy; ``SimulationResult.invariant_drift`` does that).

An invariant the model only monitors (its rate is not zero: damping, a driven body) is not
checked.
"""
from __future__ import annotations

import math

import casadi as ca
import numpy as np

from .. import cache
from ..model import Model
from .evaluate import call_buffered, map_eval

__all__ = ["QUAT_DRIFT", "INVARIANT_DRIFT", "RATE_RTOL", "violation", "violations", "remedy"]

#: Largest ``| |q| - 1 |`` of the attitude quaternion at an output time of a sane run.
QUAT_DRIFT = 1e-3
#: Largest ``|I(t) - I(t0)| / |I(t0)|`` of a conserved invariant in a sane run.
INVARIANT_DRIFT = 1.0
#: ``|dI/dt| <= RATE_RTOL sum_j |dI/dx_j| |f_j|`` at every output state: conserved.
RATE_RTOL = 1e-9


def remedy(method: str) -> str:
    """The advice appended to a violation found in a run of ``method``."""
    if method == "dop853":
        return ("the local tolerance of 'dop853' is too loose for this motion: tighten "
                "`rtol`/`atol` or use method='auto' (a verified tolerance)")
    return (f"the step of {method!r} is too large for this motion: use more `steps` per "
            "output interval or method='auto' (a verified tolerance)")


def _rates(model: Model) -> ca.Function | None:
    """``(x, u, p) -> [I, dI/dt, sum_j |dI/dx_j| |f_j|]`` of all invariants stacked (one row
    per invariant component), cached per model; None without invariants."""
    if not model.invariants:
        return None

    def build():
        sym = ca.SX.sym if model.f.is_a("SXFunction") else ca.MX.sym
        x, u, p = sym("x", model.nx), sym("u", model.nu), sym("p", model.np)
        f = model.f(x, u, p)
        values, rates, scales = [], [], []
        for fun in model.invariants.values():
            value = ca.vec(fun(x, p))
            grad = ca.jacobian(value, x)
            values.append(value)
            rates.append(ca.mtimes(grad, f))
            scales.append(ca.mtimes(ca.fabs(grad), ca.fabs(f)))
        out = ca.vertcat(*values, *rates, *scales)
        return ca.Function("invariant_rates", [x, u, p], [out])

    return cache.get(("invariant_rates", cache.function_key(model.f),
                      tuple(cache.function_key(v) for v in model.invariants.values())),
                     build, keepalive=model.f)


def _values(model: Model) -> ca.Function | None:
    """``(x, p) -> I``: all invariants stacked (cached per model; None without any)."""
    if not model.invariants:
        return None

    def build():
        sym = ca.SX.sym if model.f.is_a("SXFunction") else ca.MX.sym
        x, p = sym("x", model.nx), sym("p", model.np)
        return ca.Function("invariant_values", [x, p],
                           [ca.vertcat(*(ca.vec(fun(x, p)) for fun in model.invariants.values()))])

    return cache.get(("invariant_values", cache.function_key(model.f),
                      tuple(cache.function_key(v) for v in model.invariants.values())),
                     build, keepalive=model.f)


def _screen(model: Model, n: int) -> ca.Function:
    """``(X (nx, n), p) -> (2,)``: 0 and the largest drift of an invariant over
    `INVARIANT_DRIFT` times its initial size (0 for none); cached per model and ``n``. At
    most 1: the run is sane; otherwise `violations` decides (whether the drifting
    invariant is conserved along the run: the rates cost a Jacobian, evaluated only then)
    and words it."""
    def build():
        X, p = ca.MX.sym("X", model.nx, n), ca.MX.sym("p", model.np)
        worst = [ca.MX(0.0), ca.MX(0.0)]
        fun = _values(model)
        if fun is not None:
            values = fun.map(n, "serial")(X, ca.repmat(p, 1, n))
            start = 0
            for v in model.invariants.values():
                rows = list(range(start, start + v.numel_out(0)))
                start += len(rows)
                group = values[rows, :]
                ref = ca.norm_2(group[:, 0])
                drift = ca.mmax(ca.sqrt(ca.sum1((group - ca.repmat(group[:, 0], 1, n)) ** 2)))
                worst[1] = ca.fmax(worst[1], ca.if_else(ref > 0, drift / (INVARIANT_DRIFT * ref),
                                                        0.0))
        screen = ca.Function("sanity_screen", [X, p], [ca.vertcat(*worst)])
        try:
            return screen.expand() if n <= 64 else screen  # (SX: faster for short grids)
        except RuntimeError:
            return screen

    return cache.get(("sanity_screen", cache.function_key(model.f), n), build, keepalive=model.f)


def _quat_off(q: np.ndarray) -> float:
    """``max_t | |q(t)| - 1 |`` of ``q (4, n)`` (a short one in Python floats: half the
    time of numpy's)."""
    if q.shape[1] <= 32:
        return max(abs(math.sqrt(a * a + b * b + c * c + d * d) - 1.0)
                   for a, b, c, d in zip(*q.tolist()))
    return float(np.abs(np.sqrt(np.einsum("in,in->n", q, q)) - 1.0).max())


def violation(model: Model, t: np.ndarray, x: np.ndarray, u, p: np.ndarray,
              method: str, *, quat_off: float | None = None) -> str:
    """`violations` of one run of ``method`` (``x (nx, n)``, ``u() -> (nu, n)``, ``p
    (np,)``), screened first; ``""`` for a sane run. ``quat_off``: the most the attitude
    quaternion's norm is off 1 on ``x`` when it is known (the compiled pass measures it:
    `dense.DenseAuto` ``qoff``), else None (measured here).

    The quaternion's norm is looked at first (a few microseconds). A Runge-Kutta method
    does not keep it, so a step too large for the attitude motion shows there before
    anywhere else: for ``rk4``/``rk8`` on a model with an attitude that is the check. The
    invariants are screened (one call of `_screen`) where the norm cannot tell: ``lie``
    keeps it exactly, and a model without an attitude has none."""
    if model.attitude is not None:
        if quat_off is None:
            quat_off = _quat_off(x[model.attitude[0]:model.attitude[0] + 4])
        if quat_off > QUAT_DRIFT:
            return violations(model, t, x[:, :, None], lambda: u()[:, :, None], p[:, None],
                              method)[0]
        if method != "lie":
            return ""
    if not model.invariants:
        return ""
    worst = call_buffered(_screen(model, t.size), [x.T, p], (2,))
    if not worst[1] > 1.0:
        return ""
    return violations(model, t, x[:, :, None], lambda: u()[:, :, None], p[:, None],
                              method)[0]


def violations(model: Model, t: np.ndarray, x: np.ndarray, u, p: np.ndarray,
               method: str) -> list[str]:
    """What is grossly wrong with each of K runs of ``method`` on the grid ``t``: ``""``
    for a sane run (the invariants looked at as `violation` says).

    Parameters
    ----------
    model : Model
    t : ndarray, shape (n,) [s]
    x : ndarray, shape (nx, n, K)
        The runs' states at ``t`` (finite).
    u : callable
        ``u() -> ndarray (nu, n, K)``: the control at ``t`` (called only when an invariant
        drifts grossly: whether the flow conserves it depends on the control).
    p : ndarray, shape (np, K)

    Returns
    -------
    list of str, length K
        Each a sentence naming the violated invariant, its worst value and the time.
    """
    nx, n, K = x.shape
    found = [""] * K
    if model.attitude is not None:
        iq = model.attitude[0]
        off = np.abs(np.sqrt(np.einsum("ink,ink->nk", x[iq:iq + 4], x[iq:iq + 4])) - 1.0)
        for k in np.flatnonzero(off.max(axis=0) > QUAT_DRIFT):
            j = int(np.argmax(off[:, k]))
            found[k] = (f"the attitude quaternion's norm is {1.0 + off[j, k]:.6g} at "
                        f"t = {t[j]:.6g} (it must stay 1 to {QUAT_DRIFT:g})")
    fun = _values(model)
    if fun is None or all(found) or (model.attitude is not None and method != "lie"):
        return found
    X = x.transpose(0, 2, 1).reshape(nx, K * n)  # run by run
    P = np.repeat(p, n, axis=1)
    values = map_eval(fun, [X, P]).reshape(-1, K, n)
    sizes = [v.numel_out(0) for v in model.invariants.values()]
    bounds = np.cumsum([0] + sizes)
    drifts = []  # (invariant, run, worst column, drift over initial size)
    for i, (lo, hi) in enumerate(zip(bounds[:-1], bounds[1:])):
        v = values[lo:hi]
        ref = np.linalg.norm(v[:, :, 0], axis=0)  # (K,)
        drift = np.linalg.norm(v - v[:, :, :1], axis=0)  # (K, n)
        for k in np.flatnonzero((drift.max(axis=1) > INVARIANT_DRIFT * ref) & (ref > 0)):
            if not found[k]:
                j = int(np.argmax(drift[k]))
                drifts.append((i, k, j, drift[k, j] / ref[k]))
    if not drifts:
        return found
    runs = sorted({k for _, k, _, _ in drifts})  # is the drifting invariant conserved?
    U = u()
    cols = np.concatenate([np.arange(k * n, (k + 1) * n) for k in runs])
    rates = map_eval(_rates(model), [X[:, cols], U.transpose(0, 2, 1).reshape(model.nu, K * n)[:, cols],
                                     P[:, cols]]).reshape(3, -1, len(runs), n)
    conserved = (np.abs(rates[1]) <= RATE_RTOL * rates[2]).all(axis=2)  # (m, runs)
    names = list(model.invariants)
    for i, k, j, rel in drifts:
        if not found[k] and conserved[bounds[i]:bounds[i + 1], runs.index(k)].all():
            found[k] = (f"the invariant {names[i]!r}, conserved along this run, changed by "
                        f"{rel:.3g} times its initial size by t = {t[j]:.6g}")
    return found
