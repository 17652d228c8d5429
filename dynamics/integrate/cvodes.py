"""SUNDIALS CVODES through ``casadi.integrator``: one run on the grid, with a callable
control through a ``casadi.Callback``; a failure returns the solution up to where it stopped.

Threads: a cvodes integrator keeps its whole solver state in the memory used by a plain call,
so one instance must never run in two threads at once. The integrators of linear controls
are pooled in `dynamics.cache` (`cache.checkout`: one instance per concurrent caller, reused);
those of callable controls are built per call; every construction holds
`cache.construction_lock`."""
from __future__ import annotations

import casadi as ca
import numpy as np

from .. import cache
from .inputs import Problem
from .result import Run

__all__ = ["ControlCallback", "integrator_options", "run_cvodes", "failure_reason"]


class ControlCallback(ca.Callback):
    """``u(t)`` of a Python callable as a casadi Function of time, for cvodes. Its
    ``error`` holds the first exception the callable raised (re-raise it after the call)."""

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
        # max_num_steps). `run_cvodes` then re-raises the exception.
        if self.error is None:
            try:
                return [ca.DM(self._fun(float(arg[0])))]
            except Exception as exc:
                self.error = exc
        return [ca.DM.nan(self._nu, 1)]


_CVODES_DEFAULTS = {"show_eval_warnings": False, "disable_internal_warnings": True}


def _cvodes_integrator(model, mode, t, opts, callback=None):
    with cache.construction_lock():
        return _build_cvodes_integrator(model, mode, t, opts, callback)


def _build_cvodes_integrator(model, mode, t, opts, callback):
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


def integrator_options(rtol, atol, extra) -> dict:
    """Options of ``casadi.integrator('cvodes')``: the defaults, ``rtol`` and the least
    ``atol`` as its local tolerances, then ``extra`` (``cvodes_options``) over them."""
    opts = dict(_CVODES_DEFAULTS)
    opts.update({"reltol": rtol, "abstol": float(np.min(atol))})
    opts.update(dict(extra or {}))
    return opts


def run_cvodes(problem: Problem, rtol, atol, extra, *, pooled: bool = True) -> Run:
    """cvodes on ``problem``'s grid; ``pooled=False`` builds an integrator for this call
    alone (a grid used once, e.g. an event scan's: it is not kept in `dynamics.cache`)."""
    model, t, ctrl = problem.model, problem.t, problem.control
    opts = integrator_options(rtol, atol, extra)
    if ctrl.mode == "linear" and not pooled:
        return _run(problem, _cvodes_integrator(model, "linear", t, opts), opts, rtol, atol, None)
    if ctrl.mode == "linear":
        key = ("cvodes", cache.function_key(model.f), t.tobytes(),
               repr(sorted(opts.items(), key=str)))
        with cache.checkout(key, lambda: _cvodes_integrator(model, "linear", t, opts),
                            keepalive=model.f) as integ:
            return _run(problem, integ, opts, rtol, atol, None)
    with cache.construction_lock():
        callback = ControlCallback(ctrl.fun, model.nu)
    integ = _cvodes_integrator(model, "stages", t, opts, callback)
    return _run(problem, integ, opts, rtol, atol, callback)


def _run(problem: Problem, integ, opts, rtol, atol, callback) -> Run:
    """One call of ``integ`` (used by this thread alone) and its statistics."""
    t = problem.t
    try:
        out = _cvodes_call(integ, problem.x0, problem.p, problem.control.cvodes_input(t))
    except RuntimeError as exc:
        if callback is not None and callback.error is not None:
            raise callback.error
        stats = integ.stats()
        reached = float(stats.get("tcur", t[0]))
        x = _cvodes_prefix(problem, opts, reached, callback)
        return Run(x, int(stats.get("nsteps", 0)), int(stats.get("nfevals", 0)), 0, False, False,
                   f"cvodes failed near t = {reached:.6g}: {failure_reason(str(exc))}")
    stats = integ.stats()
    x = np.concatenate([problem.x0[:, None], out.T], axis=1)
    return Run(x, int(stats["nsteps"]), int(stats["nfevals"]), 0, False, True,
               f"cvodes: {int(stats['nsteps'])} steps (rtol {rtol:g}, atol {np.min(atol):g})")


#: What a CVODES failure flag means and what to do about it (`failure_reason`); the
#: right-hand-side flags mean the model returned NaN or inf there (casadi reports a
#: non-finite right-hand side to CVODES as a recoverable error).
_DOMAIN = ("check the model and its inputs near that time; method='dop853' or 'auto' stop "
           "at the first non-finite state and name it")
_FLAGS = {
    "CV_TOO_MUCH_WORK": (
        "more than max_num_steps internal steps before the next output time (a finite-time "
        "blow-up, a singularity, or a stiff or fast transient)",
        "look at the model and its inputs near that time (a solution that blows up cannot be "
        "integrated past it); for a long but regular stretch raise "
        "cvodes_options={'max_num_steps': ...} or add output times"),
    "CV_TOO_MUCH_ACC": (
        "the tolerances ask for more accuracy than double precision gives there",
        "loosen rtol/atol (atol above the rounding of the states, rtol above 1e-14)"),
    "CV_ERR_FAILURE": (
        "the error test failed repeatedly, down to the least step (a discontinuity, a kink "
        "or a singularity of the right-hand side)",
        "split the run at the discontinuity, or simulate with method='auto', which steps "
        "across non-smooth right-hand sides"),
    "CV_CONV_FAILURE": (
        "the Newton iteration failed repeatedly, down to the least step (the right-hand "
        "side is not defined or not smooth there, e.g. sqrt or log of a negative, or its "
        "Jacobian is singular)", _DOMAIN),
    "CV_LSETUP_FAIL": ("the linear solver's setup failed (a singular or non-finite Jacobian)",
                       _DOMAIN),
    "CV_LSOLVE_FAIL": ("the linear solve failed (a singular or non-finite Jacobian)", _DOMAIN),
    **dict.fromkeys(("CV_RHSFUNC_FAIL", "CV_REPTD_RHSFUNC_ERR", "CV_FIRST_RHSFUNC_ERR",
                     "CV_UNREC_RHSFUNC_ERR"), (
        "the right-hand side returned NaN or inf there (the state left the model's domain: "
        "a division by zero, sqrt or log of a negative, a singular matrix)", _DOMAIN)),
}


def failure_reason(text: str) -> str:
    """The reason of a failed cvodes call from casadi's error ``text``: CVODES' flag, what
    it means and a remedy (the flag alone for one not listed in `_FLAGS`).

    Examples
    --------
    >>> from appdyn.dynamics.integrate.cvodes import failure_reason
    >>> print(failure_reason('CVode returned "CV_TOO_MUCH_ACC". Consult CVODES documentation.'))
    CV_TOO_MUCH_ACC: the tolerances ask for more accuracy than double precision gives there; loosen rtol/atol (atol above the rounding of the states, rtol above 1e-14)
    """
    cut = text.find("CVode returned")
    reason = text[cut:] if cut >= 0 else (text.strip().splitlines() or [""])[-1]
    for flag, (meaning, remedy) in _FLAGS.items():
        if f'"{flag}"' in reason:
            return f"{flag}: {meaning}; {remedy}"
    return reason.replace(" Consult CVODES documentation.", "")


def _cvodes_call(integ, x0, p, uaug) -> np.ndarray:
    """Run the integrator; (nint, nx) out. A plain call: buffers do not record SUNDIALS stats."""
    res = integ(x0=x0, p=p, u=np.ascontiguousarray(uaug.T))
    return np.asarray(res["xf"], dtype=float).reshape(x0.size, uaug.shape[0]).T


def _cvodes_prefix(problem: Problem, opts, reached: float, callback) -> np.ndarray:
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

