"""Automatic scaling of NLP variables and constraints.

The NLP works with scaled variables ``x = d_x * x_s`` (per state), ``u = d_u * u_s``,
``p = d_p * p_s`` (free parameters), ``T = d_T * T_s``, and scaled constraint rows
(defects of state ``i`` divided by ``d_x[i]``; path and boundary rows by their scale), and
minimizes ``J / d_J``.

Rules (every automatic scale is rounded to a power of two, so scaling and unscaling are exact
in floating point and fixed boundary values reach IPOPT unchanged):

* states, controls, parameters: ``max(|lower|, |upper|)`` when both bounds are finite
  (a range the user chose); otherwise the largest magnitude of the initial guess on the
  nodes (boundary values included), at least `ocp.propagation.SCALE_FLOOR` (1e-6, the
  least magnitude the re-simulation and bound checks measure a variable against; below it
  a warm start's roundoff set the scale: `_magnitude`); otherwise (zero in the guess) 1;
* ``T``: the initial guess of ``T``;
* path and boundary constraint rows: the largest infinity-norm over the nodes of the row's
  gradient with respect to the *scaled* variables at the initial guess, so that scaled rows
  have unit gradients there (clamped to [1e-6, 1e6]; 1 when the gradient vanishes);
* the attitude-target rows ``vec(q_final^* (x) q(tf))`` (`ocp.problem`): ``16 e``, clamped
  to [1e-8, 1] and rounded, with ``e = max(e0, T_g max|w_g| / 2)``: ``e0 =
  |vec(q_final^* (x) q_guess(t0))|`` (about half the initial angle to the target) and the
  second term the half-angle the guess's body rates ``w_g`` could turn over its horizon
  ``T_g``. So 1 for targets more than about 7 deg away; a slew by a tiny angle still has
  O(1) target rows, and IPOPT's tolerances and the constraint-violation check of
  `ocp.solve` are relative to the requested rotation instead of admitting a body that
  never moves;
* the objective: 1 (IPOPT's own gradient-based scaling still applies on top).

Overrides: ``scale={'name': value}`` in `ocp.solve` for any state, control or parameter
name, ``'T'``, ``'objective'`` and ``'q_final'`` (used as given, not rounded); ``Constraint(scale=...)``
for constraint rows.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

import casadi as ca
import numpy as np

from .cached import cached, function_key
from .functions import sx_compatible
from .propagation import SCALE_FLOOR

__all__ = ["Scaling", "auto_scaling"]

_CLAMP = (1e-6, 1e6)


@dataclass(frozen=True, eq=False)
class Scaling:
    """Scale factors (typical magnitudes) of the NLP.

    Attributes
    ----------
    x : ndarray, shape (nx,) [state units]
    u : ndarray, shape (nu,) [control units]
    p : ndarray, shape (np,) [parameter units]
    T : float [s]
    objective : float [cost units]
    path : ndarray, shape (ng,)
        Rows of all path constraints, concatenated in order.
    boundary : ndarray, shape (nb,)
        Rows of all boundary constraints, concatenated.
    q_final : float
        The attitude-target rows (1 without a ``q_final``).
    """

    x: np.ndarray
    u: np.ndarray
    p: np.ndarray
    T: float
    objective: float
    path: np.ndarray
    boundary: np.ndarray
    q_final: float = 1.0


def _pow2(v: np.ndarray) -> np.ndarray:
    return np.exp2(np.round(np.log2(v)))


def _magnitude(bounds: np.ndarray, samples: np.ndarray) -> np.ndarray:
    """Scale of each variable (module docstring): the span of its finite bounds, else its
    largest magnitude in ``samples`` (n, m) floored at `SCALE_FLOOR`, else (zero in the
    samples: at most 1e-12) 1; rounded to a power of two.

    The floor: a state that is zero by symmetry (an off-axis rate of a slew about a
    principal axis) carries roundoff in a warm start from a solution. A time-optimal CMG
    slew's ``w2`` reached 1.1e-12 and was scaled by 2**-40, so that its defect rows read an
    absolute roundoff of 1e-16 as 1e-4 in NLP units, above ``constr_viol_tol``: every warm
    re-solve of `problems.slew.bounded` stopped at IPOPT's acceptable level (at tol 1e-10
    after 229 iterations, with a constant control after 66). Scaled by 2**-20: 3 and 54
    iterations to Solve_Succeeded.
    """
    lo, hi = bounds
    out = np.ones(lo.size)
    both = np.isfinite(lo) & np.isfinite(hi)
    span = np.maximum(np.abs(lo), np.abs(hi))
    out[both & (span > 0)] = span[both & (span > 0)]
    if samples.size:
        g = np.max(np.abs(samples), axis=1)
        use = ~(both & (span > 0)) & (g > 1e-12)
        out[use] = np.maximum(g[use], SCALE_FLOOR)
    return _pow2(out)


def _row_scale(jac: np.ndarray) -> np.ndarray:
    """Largest |entry| of each row over nodes: jac has shape (rows, cols, nodes)."""
    if jac.size == 0:
        return np.ones(jac.shape[0])
    g = np.max(np.abs(jac), axis=(1, 2))
    out = np.ones_like(g)
    ok = g > 0
    out[ok] = _pow2(np.clip(g[ok], *_CLAMP))
    return out


def _concat(constraints, attr):
    parts = [getattr(c, attr) for c in constraints]
    return np.concatenate(parts) if parts else np.zeros(0)


def auto_scaling(problem, guess, *, overrides: Mapping | None = None) -> Scaling:
    """Scale factors from the bounds and the initial guess, with overrides.

    Parameters
    ----------
    problem : ocp.Problem
    guess : ocp.guess.NodeGuess
    overrides : mapping of str to float, optional
        Scales by state/control/parameter name, ``'T'``, ``'objective'``, ``'q_final'``.

    Returns
    -------
    Scaling

    Raises
    ------
    ValueError
        Naming ``scale``: unknown or ambiguous names, non-positive or non-finite values.
    """
    model = problem.model
    dx = _magnitude(problem.x_bounds, np.concatenate([guess.X, guess.Xu], axis=1))
    du = _magnitude(problem.u_bounds, guess.U)
    dp = _magnitude(problem.p_bounds, guess.p[:, None])
    dT = float(_pow2(np.array([guess.T]))[0]) if guess.T > 0 else 1.0
    dJ = 1.0
    dq = _q_final_scale(problem, guess)

    if overrides is not None:
        if not isinstance(overrides, Mapping):
            raise ValueError(f"`scale` must be a mapping name -> scale, got {type(overrides).__name__}")
        targets = {}
        for vec, names in ((dx, model.states), (du, model.controls), (dp, model.params)):
            for i, n in enumerate(names):
                targets.setdefault(n, []).append((vec, i))
        for key, value in overrides.items():
            v = float(value)
            if not (math.isfinite(v) and v > 0):
                raise ValueError(f"`scale`[{key!r}] must be finite and > 0, got {value!r}")
            if key == "T":
                dT = v
            elif key == "objective":
                dJ = v
            elif key == "q_final":
                dq = v
            elif key in targets:
                if len(targets[key]) > 1:
                    raise ValueError(f"`scale` key {key!r} is ambiguous (several model components share it)")
                vec, i = targets[key][0]
                vec[i] = v
            else:
                raise ValueError(f"`scale` names unknown variable {key!r}; expected a state, control or "
                                 "parameter name, 'T', 'objective' or 'q_final'")

    free = problem.free_params
    dp_free = np.zeros(model.np)
    dp_free[free] = dp[free]
    path = _path_scales(problem, guess, dx, du, dp_free)
    boundary = _boundary_scales(problem, guess, dx, dp_free)
    return Scaling(x=dx, u=du, p=dp, T=dT, objective=dJ, path=path, boundary=boundary, q_final=dq)


def _q_final_scale(problem, guess) -> float:
    """Scale of the attitude-target rows from the guess's initial attitude (module docstring)."""
    if problem.q_final is None or problem.q_final_tol > 0:
        return 1.0
    iq = problem.model.attitude[0]
    q0 = np.asarray(guess.X[iq:iq + 4, 0], dtype=float)
    n = np.linalg.norm(q0)
    if not (np.isfinite(n) and n > 0):
        return 1.0
    e0 = float(np.linalg.norm(np.asarray(problem.attitude_error(q0 / n), dtype=float)))
    # rotation the guess's rates could carry out over its horizon (a start on the target
    # with non-zero rates has to come back to it: that motion sets the scale then)
    iw = problem.model.attitude[1]
    w = np.asarray(guess.X[iw:iw + 3], dtype=float)
    w_max = float(np.max(np.abs(w))) if w.size and np.all(np.isfinite(w)) else 0.0
    e_ref = max(e0, 0.5 * w_max * float(guess.T))
    return float(_pow2(np.array([np.clip(16.0 * e_ref, 1e-8, 1.0)]))[0])


def _path_scales(problem, guess, dx, du, dp_free) -> np.ndarray:
    cons = problem.path
    if not cons:
        return np.zeros(0)
    auto = _auto_rows(
        [c.fun for c in cons],
        [("x", guess.Xu, dx), ("u", guess.U, du), ("p", guess.p[:, None], dp_free)],
        guess.U.shape[1],
    )
    return _merge(cons, auto)


def _boundary_scales(problem, guess, dx, dp_free) -> np.ndarray:
    cons = problem.boundary
    if not cons:
        return np.zeros(0)
    auto = _auto_rows(
        [c.fun for c in cons],
        [("x0", guess.X[:, :1], dx), ("xf", guess.X[:, -1:], dx), ("p", guess.p[:, None], dp_free)],
        1,
    )
    return _merge(cons, auto)


def _auto_rows(funs, args, n_nodes) -> np.ndarray:
    """Row scales of the stacked ``funs`` from gradients w.r.t. scaled arguments."""
    rows = []
    d = np.concatenate([np.asarray(s, float) for _, _, s in args])
    vals = [np.broadcast_to(v, (v.shape[0], n_nodes)) if v.shape[1] == 1 else v for _, v, _ in args]
    for fun in funs:
        J = np.asarray(_row_gradients(fun, tuple(name for name, _, _ in args), n_nodes)(*vals))
        m = fun.numel_out(0)
        J = J.reshape(m, -1, n_nodes, order="F")
        # scaled arguments; a fixed parameter (scale 0) contributes nothing, not 0 * inf
        rows.append(_row_scale(np.where(d[None, :, None] == 0, 0.0, J * d[None, :, None])))
    return np.concatenate(rows)


def _row_gradients(fun: ca.Function, names: tuple, n_nodes: int) -> ca.Function:
    """``(args...) -> [d fun / d arg_1, ...]`` (shape (m, n_args_total)), mapped over
    ``n_nodes`` points, built once per Function, argument names and count in the one cache
    (`ocp.cached`): a round of refinement scales the same constraints again."""
    def build():
        sym = ca.SX if sx_compatible(fun) else ca.MX
        syms = [sym.sym(name, fun.size_in(i)) for i, name in enumerate(names)]
        out = fun(*syms)
        jf = ca.Function("row_gradients", syms, [ca.horzcat(*[ca.jacobian(out, s) for s in syms])])
        return jf.map(n_nodes) if n_nodes > 1 else jf

    return cached("row_gradients", (function_key(fun), tuple(names), int(n_nodes)), build,
                  keepalive=fun)


def _merge(cons, auto: np.ndarray) -> np.ndarray:
    out, k = [], 0
    for c in cons:
        m = c.size
        out.append(np.array(c.scale) if c.scale is not None else auto[k:k + m])
        k += m
    return np.concatenate(out)
