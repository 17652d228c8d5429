"""Re-simulation of a solution's control: `Propagation` and the CVODES machinery behind
`ocp.Solution.propagate` and the error estimates of `ocp.refine`."""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from appdyn.dynamics.validate.base import real_array

from .cached import cached, function_key
from .functions import sx_compatible

__all__ = ["Propagation", "propagate", "interval_integrator", "stack_interval_controls",
           "state_scale", "SCALE_FLOOR"]


#: Floor of the typical magnitude of a state in the scaled propagation errors
#: (`Propagation.scale`) [state units]: a state that stays at zero is compared with this.
SCALE_FLOOR = 1e-6

#: CVODES' methods of `propagate`, in turn until one integrates every interval: Adams-Moulton
#: first (the re-simulation is of a non-stiff flow at tight tolerances, where it takes fewer
#: and more accurate steps than BDF: a 3 s minimum-effort slew at rtol 1e-12, pointing error
#: 1.5e-11 rad off the truth in 8.1 ms against BDF's 1.6e-10 rad in 13.2 ms; Bilimoria-Wie
#: 3.3 against 4.9 ms), BDF where Adams fails (a stiff flow).
METHODS = ("adams", "bdf")


@dataclass(frozen=True)
class Propagation:
    """Re-simulation of a solution's control (see `Solution.propagate`).

    Attributes
    ----------
    t : ndarray, shape (n,) [s]
        The solution's node times.
    x : ndarray, shape (nx, n)
        States integrated from ``x[:, 0]`` of the solution under its dense control.
    error : ndarray, shape (nx,)
        Largest ``|x_propagated - x_collocated|`` of each state over the nodes [state units]
        (NaN after a failure).
    success : bool
    message : str
    cost : float
        The objective ``phi(x_sim(tf), p, T) + integral L(x_sim, u, p) dt`` of the
        re-simulated trajectory, the running cost integrated by CVODES as a quadrature
        alongside the states [cost units], with the user's sign (``J`` itself for a
        ``maximize`` problem, as `Solution.cost`). This is the value the returned control
        actually achieves. NaN after a failure.
    scale : ndarray, shape (nx,)
        Typical magnitude of each state: ``max(max_n |x_i(t_n)|, SCALE_FLOOR)`` over the
        collocated nodes [state units] (`SCALE_FLOOR` = 1e-6).
    """

    t: np.ndarray
    x: np.ndarray
    error: np.ndarray
    success: bool
    message: str
    cost: float = float("nan")
    scale: np.ndarray | None = None

    @property
    def relative_error(self) -> np.ndarray:
        """``error / scale`` per state, shape (nx,) [-]: the propagation error relative to
        the state's typical magnitude (0.34 m on a 1e5 m altitude reads 3.4e-6). NaN after
        a failure; ``error`` itself when no ``scale`` was recorded."""
        if self.scale is None:
            return np.asarray(self.error, dtype=float)
        return np.asarray(self.error, dtype=float) / self.scale


def state_scale(x: np.ndarray) -> np.ndarray:
    """Typical magnitude of each state, ``max(max_n |x_i(t_n)|, SCALE_FLOOR)``.

    Parameters
    ----------
    x : array_like, shape (nx, n)
        States at the nodes [state units].

    Returns
    -------
    ndarray, shape (nx,) [state units]
    """
    x = real_array(x, "x")
    if x.ndim != 2:
        raise ValueError(f"`x` must have shape (nx, n), got {x.shape}")
    if x.shape[1] == 0:
        return np.full(x.shape[0], SCALE_FLOOR)
    return np.maximum(np.max(np.abs(x), axis=1), SCALE_FLOOR)


def propagate(sol, *, rtol: float = 1e-12, atol: float = 1e-12) -> Propagation:
    """`ocp.Solution.propagate` (its docstring): re-simulate ``sol``'s dense control with
    CVODES per mesh interval, with the running cost as a quadrature."""
    for name, v in (("rtol", rtol), ("atol", atol)):
        if isinstance(v, bool) or not (isinstance(v, (int, float)) and 0 < v < 1):
            raise ValueError(f"`{name}` must be a float in (0, 1), got {v!r}")
    d = sol.dense
    problem = sol.problem
    nx = problem.model.nx
    scale = state_scale(sol.x)
    scale.setflags(write=False)
    nan = float("nan")
    pars = np.concatenate([d.us, stack_interval_controls(d.Uo, np.arange(d.N)), d.h[None, :],
                           np.repeat(sol.p[:, None], d.N, axis=1)], axis=0)
    why, failed = "", np.full((nx, sol.t.size), np.nan)
    for method in METHODS:
        try:
            _, xall, qall = _propagator(sol, rtol, atol, method)(sol.x[:, 0], pars)
        except RuntimeError as exc:
            why = f"cvodes ({method}) failed: {exc}"
            continue
        xp = np.concatenate([sol.x[:, :1], np.asarray(xall)], axis=1)
        if not np.all(np.isfinite(xp)):
            why, failed = f"cvodes ({method}): non-finite state", xp
            continue
        cost = float(np.sum(np.asarray(qall))) if problem.lagrange is not None else 0.0
        if problem.mayer is not None:
            cost += float(problem.mayer(xp[:, -1], sol.p, sol.T))
        break
    else:
        return Propagation(sol.t, failed, np.full(nx, np.nan), False, why, nan, scale)
    err = np.max(np.abs(xp - sol.x), axis=1)
    return Propagation(sol.t, xp, err, True, f"cvodes ({method}) per mesh interval, rtol {rtol:g}, "
                       f"atol {atol:g}", cost, scale)


def interval_integrator(sol, grid, rtol: float, atol: float, *,
                        lagrange: ca.Function | None = None, method: str = "bdf") -> ca.Function:
    """CVODES over one mesh interval in normalized time ``s in [0, 1]`` under the solution's
    own control polynomial, with outputs at the normalized times ``grid``.

    Inputs ``x0`` (nx,) and ``p`` = ``[u_start, vec(U_interval), h, p_model]``; output ``xf``
    (nx, len(grid)) and, with a ``lagrange`` Function ``(x, u, p) -> L``, ``qf`` (1, len(grid)):
    ``integral L dt`` from the interval start to each grid point [cost units]. Shared by
    `Solution.propagate` and mesh refinement (`ocp.refine`); built once per transcription,
    model right-hand side, running cost, grid, tolerances and ``method`` (`ocp.cached`).
    ``method``: CVODES' linear multistep method, ``'bdf'`` (stiff problems) or ``'adams'``
    (Adams-Moulton: non-stiff problems at tight tolerances, `propagate`'s first choice).
    """
    tr, f = sol.transcription, sol.problem.model.f
    grid = tuple(float(v) for v in grid)
    if lagrange is not None and not isinstance(lagrange, ca.Function):
        raise TypeError(f"`lagrange` must be a casadi.Function or None, got {type(lagrange).__name__}")
    lkey = None if lagrange is None else function_key(lagrange)
    keep = f if lagrange is None else (f, lagrange)
    return cached("interval_integrator",
                  (tr, function_key(f), lkey, grid, float(rtol), float(atol), method),
                  lambda: _build_interval_integrator(sol, grid, rtol, atol, lagrange, method),
                  keepalive=keep)


def _build_interval_integrator(sol, grid, rtol, atol, lagrange=None, method="bdf"):
    d = sol.dense
    model = sol.problem.model
    nx, nu = model.nx, model.nu
    sx = sx_compatible(model.f) and (lagrange is None or lagrange.is_a("SXFunction"))
    sym = ca.SX if sx else ca.MX
    x, s = sym.sym("x", nx), sym.sym("s")
    us, U = sym.sym("us", nu), sym.sym("U", nu, d.m_u)
    h, p = sym.sym("h"), sym.sym("p", model.np)
    u = sol.transcription.control_at(us, U, s)  # the interpolant's control, without its states
    data = ca.vertcat(us, ca.vec(U), h, p)
    dae = {"x": x, "p": data, "t": s, "ode": h * model.f(x, u, p)}
    opts = {"abstol": atol, "reltol": rtol, "max_num_steps": 100000,
            "linear_multistep_method": method}
    if lagrange is not None:
        # the quadrature under CVODES' error control too: outside it the steps are those of
        # the states alone, and where the states are exact for long steps (x' = -1 under a
        # constant control) the integral of L = x^2/2 was 8 % off (0.1526 against 1/6)
        dae["quad"] = h * lagrange(x, u, p)
        opts["quad_err_con"] = True
    return ca.integrator("interval", "cvodes", dae, 0.0, [float(v) for v in grid], opts)


def _propagator(sol, rtol: float, atol: float, method: str) -> ca.Function:
    """``(x0 (nx,), data (.., N)) -> (xf, x at the owned nodes of every interval, integral of
    L over every interval (1, N))``: the interval integrators chained by ``mapaccum`` over the
    ``N`` intervals (cached; the running cost ``problem.lagrange`` is part of the key, the
    integral is 0 without one)."""
    tr, f, N = sol.transcription, sol.problem.model.f, sol.dense.N
    L = sol.problem.lagrange

    def build():
        # the states by an integrator of their own: with the running cost under CVODES' error
        # control too, its steps (and so the states) would change with L
        integ = interval_integrator(sol, tr.node_sigma, rtol, atol, method=method)
        x0 = ca.MX.sym("x0", f.numel_in(0))
        dat = ca.MX.sym("data", integ.numel_in("p"))
        xs = integ(x0=x0, p=dat)["xf"]
        q = ca.MX(1, 1)
        if L is not None:
            cost = interval_integrator(sol, (1.0,), rtol, atol, lagrange=L, method=method)
            q = cost(x0=x0, p=dat)["qf"][:, -1]
        return ca.Function("step", [x0, dat], [xs[:, -1], xs, q]).mapaccum("propagate", N)

    lkey = None if L is None else function_key(L)
    keep = f if L is None else (f, L)
    return cached("propagator", (tr, function_key(f), lkey, N, float(rtol), float(atol), method),
                  build, keepalive=keep)


def stack_interval_controls(Uo: np.ndarray, k: np.ndarray) -> np.ndarray:
    """``vec(U_k)`` (column-major, as ``casadi.vec``) of intervals ``k``: shape (nu m_u, len(k))."""
    nu, _, m_u = Uo.shape
    blocks = Uo[:, k, :]  # (nu, K, m_u)
    return blocks.transpose(2, 0, 1).reshape(m_u * nu, k.size)
