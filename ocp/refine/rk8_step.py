"""One fixed step of the DOP853 8th-order Runge-Kutta method as a casadi Function, with the
running cost integrated alongside, and its adjoint (a vector-Jacobian product: the costates
of `ocp.refine.switch_times`), built once per model and running cost (`ocp.cached`)."""
from __future__ import annotations

import casadi as ca

from appdyn.dynamics.integrate.tableaux import DOP853

from ..cached import cached, function_key
from ..functions import sx_compatible

__all__ = ["step_function", "step_adjoint"]


def _rk8_step(f: ca.Function, L: ca.Function | None) -> ca.Function:
    """One fixed step of the DOP853 8th-order Runge-Kutta method:
    ``(x, u, p, h) -> (x(t + h), integral of L over the step)``."""
    A, B = DOP853.a, DOP853.b  # dynamics.integrate.tableaux (the doubles of scipy's DOP853)
    nx, nu, np_ = f.numel_in(0), f.numel_in(1), f.numel_in(2)
    funs = [f] + ([L] if L is not None else [])
    sym = ca.SX if all(sx_compatible(g) for g in funs) else ca.MX
    x, u, p, h = sym.sym("x", nx), sym.sym("u", nu), sym.sym("p", np_), sym.sym("h")
    k, kq = [], []
    for i in range(len(B)):
        xi = x
        for j, a in enumerate(A[i]):
            if a != 0.0:
                xi = xi + (h * a) * k[j]
        k.append(f(xi, u, p))
        if L is not None:
            kq.append(L(xi, u, p))
    xn = x + h * sum(float(B[i]) * k[i] for i in range(len(k)) if B[i] != 0.0)
    qn = h * sum(float(B[i]) * kq[i] for i in range(len(kq)) if B[i] != 0.0) if L is not None else sym(0)
    return ca.Function(f"{f.name()}_rk8_step", [x, u, p, h], [xn, qn],
                       ["x", "u", "p", "h"], ["xf", "qf"])


def step_function(model, lagrange) -> ca.Function:
    parts = (function_key(model.f), None if lagrange is None else function_key(lagrange))
    keep = (model.f,) if lagrange is None else (model.f, lagrange)
    return cached("rk8_step", parts, lambda: _rk8_step(model.f, lagrange), keepalive=keep)


def step_adjoint(step: ca.Function) -> ca.Function:
    """The adjoint of one RK8 ``step``: a vector-Jacobian product in one reverse sweep.

    Parameters
    ----------
    step : casadi.Function
        ``(x, u, p, h) -> (x(t + h), q)`` of `step_function` (``q`` the running cost
        integrated over the step).

    Returns
    -------
    casadi.Function
        ``(x, u, p, h, lx, lq) -> lam = (d x(t + h) / d x)^T lx + (d q / d x)^T lq``,
        ``lx`` and ``lam`` of shape (nx, 1), ``lq`` a scalar: the costates inside a segment
        of `ocp.refine.switch_times` without the step's whole state Jacobian (Bilimoria-Wie:
        2147 instructions instead of 5981). Built once per step (`ocp.cached`).

    Examples
    --------
    One step of the double integrator x'' = u (`ocp.examples.min_time`): d x(t + h) / d x
    = [[1, h], [0, 1]], so the seed (1, 0) gives (1, h):

    >>> import numpy as np
    >>> from appdyn.ocp.examples import min_time
    >>> from appdyn.ocp.refine.rk8_step import step_adjoint, step_function
    >>> model = min_time().model
    >>> adjoint = step_adjoint(step_function(model, None))
    >>> np.asarray(adjoint([0, 0], [1], np.zeros(model.np), 0.1, [1, 0], 0)).ravel().round(12)
    array([1. , 0.1])
    """
    def build():
        sym = ca.SX if step.is_a("SXFunction") else ca.MX
        x, u, p, h = (sym.sym(n, step.sparsity_in(i)) for i, n in enumerate("xuph"))
        lx, lq = sym.sym("lx", step.sparsity_out(0)), sym.sym("lq")
        xn, qn = step(x, u, p, h)
        seed = ca.dot(lx, xn) + lq * qn
        return ca.Function(step.name() + "_adjoint", [x, u, p, h, lx, lq],
                           [ca.gradient(seed, x)], ["x", "u", "p", "h", "lx", "lq"], ["lam"])
    return cached("rk8_step_adjoint", (function_key(step),), build, keepalive=step)
