"""Several scenarios in one NLP sharing the static parameters (design of gains, robust plans).

A *scenario* is one trajectory of a model: its own initial state (and final state), its own
controls; the model parameters are shared. `scenario_problem` stacks ``K`` copies of a model
into one (`stack`: states ``x[k]``, controls ``u[k]``, the same parameters), so the
collocation engine solves them together: one NLP holding ``K`` trajectories whose cost is
the (weighted) sum of the scenarios' costs and whose path constraints hold in every
scenario. With the parameters free (``p_bounds``) this is multi-scenario parameter
optimization: the feedback gains of a closed loop that is good for every initial condition,
disturbance or flight condition at once (`problems.gains`).

A scenario-dependent constant (a disturbance level, a flight condition) is a state with zero
rate whose initial value differs between scenarios (`stack` leaves the parameters shared).

`unstack` splits a stacked trajectory ``(K nx, n)`` into ``(nx, n, K)``.

Examples
--------
Two initial conditions of ``x' = -k x``, with the gain ``k`` free: minimizing
``integral x^2 + u^2`` with ``u = -k x`` over a long horizon gives the LQR gain ``k = 1``
(``A = 0, B = 1, Q = R = 1``) for any set of initial conditions:

>>> import casadi as ca
>>> from appdyn import ocp
>>> from appdyn.dynamics import Model
>>> x, k = ca.SX.sym("x"), ca.SX.sym("k")
>>> loop = Model.from_expressions({"x": x}, {"x": -k * x}, params={"k": k}, p_default=[0.5])
>>> pr = ocp.scenario_problem(loop, [[1.0, -2.0]], T=20.0, p_bounds={"k": (0.01, 10.0)},
...                           lagrange=lambda x, u, p: x[0]**2 + (p[0] * x[0])**2)
>>> sol = ocp.solve(pr, N=40)
>>> sol.success, round(float(sol.p[0]), 4)
(True, 1.0)
"""
from __future__ import annotations

from typing import Mapping, Sequence

import casadi as ca
import numpy as np

from appdyn.dynamics.model import Model
from appdyn.dynamics.validate import integer
from appdyn.dynamics.validate.base import real_array

from .arguments import bounds, row_bounds
from .functions import named_function
from .problem import Constraint, Problem

__all__ = ["stack", "scenario_problem", "unstack"]


def _count(K) -> int:
    return integer(K, "K", minimum=1)  # the number of scenarios


def stack(model: Model, K: int) -> Model:
    """``K`` copies of ``model`` side by side, sharing its parameters.

    Parameters
    ----------
    model : dynamics.Model
    K : int
        Number of scenarios, >= 1.

    Returns
    -------
    dynamics.Model
        States ``name[k]`` (scenario-major: all states of scenario 0 first), controls
        ``name[k]``, the parameters of ``model``; ``xdot[k] = f(x[k], u[k], p)``. Units
        are carried over; invariants and the attitude marker are not (each scenario's
        quaternion is an ordinary state here).

    Raises
    ------
    TypeError
        If ``model`` is not a `dynamics.Model`.
    ValueError
        If ``K`` is not an integer >= 1.
    """
    if not isinstance(model, Model):
        raise TypeError(f"`model` must be a dynamics.Model, got {type(model).__name__}")
    K = _count(K)
    nx, nu, np_ = model.nx, model.nu, model.np
    sym = ca.SX if model.f.is_a("SXFunction") else ca.MX
    X, U, p = sym.sym("x", nx, K), sym.sym("u", nu, K), sym.sym("p", np_)
    xdot = model.f.map(K, [False, False, True], [False])(X, U, p)
    f = ca.Function(f"{model.f.name()}_x{K}", [ca.vec(X), ca.vec(U), p], [ca.vec(xdot)],
                    ["x", "u", "p"], ["xdot"])
    label = lambda names: tuple(f"{n}[{k}]" for k in range(K) for n in names)  # noqa: E731
    units = {f"{n}[{k}]": v for n, v in dict(model.units).items() for k in range(K)
             if n in model.states or n in model.controls}
    units.update({n: v for n, v in dict(model.units).items() if n in model.params})
    return Model(f, label(model.states), label(model.controls), tuple(model.params),
                 p_default=np.array(model.p_default, dtype=float), units=units,
                 name=f"{model.name} x {K} scenarios")


def _columns(value, nx: int, K: int | None, argname: str, *, allow_nan: bool) -> np.ndarray:
    """Scenario values as an array (nx, K): a (nx, K) array, a (nx,) vector for every
    scenario, or a sequence of K mappings/vectors (NaN = free where allowed)."""
    if isinstance(value, (list, tuple)) and value and all(isinstance(v, Mapping) for v in value):
        raise ValueError(f"`{argname}`: give arrays (nx, K); mappings by name are per-scenario "
                         "values of `ocp.Problem`, not of `scenario_problem`")
    a = np.array(real_array(value, argname))
    if a.ndim == 1 and K is not None and a.size == nx:
        a = np.repeat(a[:, None], K, axis=1)
    if a.ndim != 2 or a.shape[0] != nx or (K is not None and a.shape[1] != K):
        want = f"({nx}, K)" if K is None else f"({nx},) or ({nx}, {K})"
        raise ValueError(f"`{argname}` must have shape {want} (one column per scenario), got {a.shape}")
    if not allow_nan and not np.all(np.isfinite(a)):
        raise ValueError(f"`{argname}` must be finite (every initial state of every scenario given)")
    return a


def _as_list(value) -> list:
    return [value] if isinstance(value, Constraint) or callable(value) else list(value)


def _weights(weights, K: int) -> np.ndarray:
    if weights is None:
        return np.ones(K)
    w = np.array(weights, dtype=float).reshape(-1)
    if w.size != K or not np.all(np.isfinite(w)) or np.any(w < 0) or not np.any(w > 0):
        raise ValueError(f"`weights` must be {K} finite numbers >= 0, not all 0, got {weights!r}")
    return w


def _per_scenario(fun, kind: str, model: Model, K: int, argname: str, weights=None):
    """A function of one scenario applied to every scenario of the stacked model: summed
    with ``weights`` (costs) or stacked (constraints)."""
    g = named_function(fun, kind, model, argname)
    nx, nu = model.nx, model.nu
    if kind == "lagrange" or kind == "path":
        def stacked(x, u, p):
            X, U = ca.reshape(x, nx, K), ca.reshape(u, nu, K)
            vals = [g(X[:, k], U[:, k], p) for k in range(K)]
            if kind == "path":
                return ca.vertcat(*vals)
            return sum(float(weights[k]) * vals[k] for k in range(K))
    else:  # mayer
        def stacked(xf, p, T):
            X = ca.reshape(xf, nx, K)
            return sum(float(weights[k]) * g(X[:, k], p, T) for k in range(K))
    return stacked, g


def scenario_problem(model: Model, x_initial, *, T, x_final=None, lagrange=None, mayer=None,
                     path: Sequence = (), x_bounds=None, u_bounds=None, p=None, p_bounds=None,
                     weights=None, name: str = "scenarios", **problem_kwargs) -> Problem:
    """One `ocp.Problem` holding ``K`` scenarios of ``model`` that share its parameters.

    Parameters
    ----------
    model : dynamics.Model
        The model of one scenario.
    x_initial : array_like, shape (nx, K)
        Initial state of every scenario (columns); ``K`` is its number of columns.
    T : float or (T_min, T_max) [s]
        Horizon, common to all scenarios.
    x_final : array_like, shape (nx,) or (nx, K), optional
        Final states (NaN = free), for every scenario or per scenario.
    lagrange : callable or casadi.Function, optional
        Running cost of one scenario ``L(x, u, p)`` (positional or by name, as in
        `ocp.Problem`); the problem's is ``sum_k weights[k] L(x[k], u[k], p)``.
    mayer : callable or casadi.Function, optional
        Terminal cost of one scenario ``phi(xf, p, T)``, summed likewise.
    path : sequence of Constraint, callables or Functions
        Path constraints of one scenario (``g(x, u, p) <= 0`` for a bare callable), imposed
        in every scenario at the control nodes and, for a model without controls (a closed
        loop), also at ``t0``.
    x_bounds, u_bounds : (lower, upper) arrays of shape (nx,) / (nu,), or mappings by name
        Bounds of one scenario, the same in all.
    p, p_bounds
        Parameter values and bounds of the shared parameters, as in `ocp.Problem`
        (parameters listed in a ``p_bounds`` mapping are optimized).
    weights : array_like, shape (K,), optional
        Weights of the scenarios' costs (default all 1).
    name : str
    **problem_kwargs
        Further `ocp.Problem` arguments (``maximize``, ``t0``, ``boundary`` on the
        stacked states).

    Returns
    -------
    ocp.Problem
        On the stacked model (`stack`); split its solution's trajectories with `unstack`.

    Raises
    ------
    TypeError
        If ``model`` is not a `dynamics.Model`.
    ValueError
        Naming the argument: shapes, non-finite initial states, weights, functions of the
        wrong signature (the errors of `ocp.Problem`).
    """
    if not isinstance(model, Model):
        raise TypeError(f"`model` must be a dynamics.Model, got {type(model).__name__}")
    X0 = _columns(x_initial, model.nx, None, "x_initial", allow_nan=False)
    K = X0.shape[1]
    w = _weights(weights, K)
    big = stack(model, K)
    kw = dict(problem_kwargs)
    kw["x_initial"] = X0.reshape(-1, order="F")
    if x_final is not None:
        kw["x_final"] = _columns(x_final, model.nx, K, "x_final", allow_nan=True).reshape(-1, order="F")
    if lagrange is not None:
        kw["lagrange"] = _per_scenario(lagrange, "lagrange", model, K, "lagrange", w)[0]
    if mayer is not None:
        kw["mayer"] = _per_scenario(mayer, "mayer", model, K, "mayer", w)[0]
    cons = _as_list(path)
    rows = []
    for i, c in enumerate(cons):
        arg = f"path[{i}]"
        if isinstance(c, Constraint):
            fun, g = _per_scenario(c.fun, "path", model, K, arg)
            lo, hi, sc = row_bounds(c.lower, c.upper, c.scale, g.numel_out(0), arg)  # one scenario
            rows.append(Constraint(fun, np.tile(lo, K), np.tile(hi, K),
                                   None if sc is None else np.tile(sc, K), c.name or arg))
        else:
            rows.append(_per_scenario(c, "path", model, K, arg)[0])
    kw["path"] = rows
    if model.nu == 0 and rows:
        # a closed loop (no controls): its path rows depend on the state alone, so they are
        # also imposed at t0, which Radau's control nodes leave out (the initial deflection
        # of a feedback law is often its largest)
        start = []
        for i, r in enumerate(rows):
            con = r if isinstance(r, Constraint) else Constraint(r, -np.inf, 0.0, None, f"path[{i}]")
            start.append(Constraint(lambda x0, xf, p, g=con.fun: g(x0, ca.DM(0, 1), p),
                                    con.lower, con.upper, con.scale, f"{con.name} at t0"))
        kw["boundary"] = list(_as_list(kw.get("boundary", ()))) + start
    for argname, value, names in (("x_bounds", x_bounds, model.states), ("u_bounds", u_bounds, model.controls)):
        if value is None:
            continue
        one = bounds(value, names, argname)
        kw[argname] = (np.tile(one[0], K), np.tile(one[1], K))
    return Problem(big, T=T, p=p, p_bounds=p_bounds, name=name, **kw)


def unstack(x, K: int) -> np.ndarray:
    """Trajectories of the stacked model, shape (K n, m), as ``(n, m, K)`` per scenario.

    Parameters
    ----------
    x : array_like, shape (K n, m)
        States (or controls) of a solution of a `scenario_problem` at m times.
    K : int

    Returns
    -------
    ndarray, shape (n, m, K)

    Raises
    ------
    ValueError
        If ``K`` does not divide the number of rows.
    """
    K = _count(K)
    a = real_array(x, "x")
    if a.ndim != 2 or a.shape[0] % K:
        raise ValueError(f"`x` must have K n rows (K = {K}), got shape {a.shape}")
    n = a.shape[0] // K
    return a.reshape(K, n, a.shape[1]).transpose(1, 2, 0)
