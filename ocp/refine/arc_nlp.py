"""The switch-time NLP of `ocp.refine.switch_times`, built once per problem structure and
switching structure: every number (arc controls, fixed parameter values, scales, target
quaternion) an NLP parameter, kept in the one cache (`ocp.cached`), so a slew to another
target with as many arcs builds nothing.

Its gradient, Jacobian and Hessian of the Lagrangian are assembled (`ocp.assembly.assemble`)
from the derivatives of one segment and of the ends, each taken once in SX, as the
collocation NLPs of `ocp.assembly` are: on Bilimoria & Wie's slew (24 segments) the solver
is built in 0.04 s instead of 0.09 s and a Jacobian evaluation takes 1.0 ms instead of 4.1
ms, a Hessian 1.6 ms instead of 6.7 ms (casadi's derivatives of the NLP in MX around the
mapped step, kept for models with MX functions)."""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from ..assembly import assemble, local_functions, problem_functions, structure_key
from ..attitude import attitude_error, target_bounds
from ..cached import cached
from ..functions import sx_compatible
from ..problem import Problem

__all__ = ["ArcNLP", "arc_nlp", "constraint_bounds"]


@dataclass(frozen=True, eq=False)
class ArcNLP:
    """The switch-time NLP of one switching structure (`arc_nlp`), every number a parameter.

    ``nlp``: the casadi NLP (``x``: scaled durations, free parameters and segment-end
    states; ``p``: the arc controls (nu, S) column-major, the fixed parameter values (np),
    the state scales (nx), the duration scale, the free-parameter scales, the objective
    scale, the target quaternion (4) and the target scale). ``cost``: ``(w, par) -> J``
    (physical). ``blocks``: ``(kind, index, rows)`` of the constraints in order. ``key``:
    the cache key. ``derivatives``: the ``grad_f``, ``jac_g`` and ``hess_lag`` nlpsol
    options, assembled per segment (`_assembled`), or None (casadi differentiates ``nlp``)."""

    nlp: dict
    cost: ca.Function
    blocks: tuple
    key: tuple
    derivatives: dict | None = None


def arc_nlp(problem: Problem, step: ca.Function, n_arcs: int, nseg: np.ndarray) -> ArcNLP:
    """The switch-time NLP of ``problem`` with ``nseg[k]`` RK8 segments on arc ``k``, from
    the one cache: built once per problem structure (`ocp.assembly.structure_key`: model,
    cost and constraint functions by content) and segment counts, so a slew to another
    target with the same switching structure builds nothing."""
    nseg = tuple(int(n) for n in nseg)
    scales = (tuple(None if c.scale is None else tuple(np.asarray(c.scale, float).ravel())
                    for c in (*problem.path, *problem.boundary)))
    key = structure_key(problem, "rk8-arcs", sum(nseg), False) + (n_arcs, nseg, scales)
    return cached("switch_times_nlp", key, lambda: _build_arc_nlp(problem, step, n_arcs,
                                                                  np.asarray(nseg), key))


def _build_arc_nlp(problem, step, n_arcs, nseg, key) -> ArcNLP:
    """The NLP of `arc_nlp`: assembled from the derivatives of one segment and of the ends
    (`_assembled`) when the step and every function of ``problem`` allow SX, else in MX
    around the mapped step, differentiated by casadi (under the construction lock)."""
    if step.is_a("SXFunction") and all(f is None or sx_compatible(f)
                                       for f in problem_functions(problem)):
        return _assembled(problem, step, n_arcs, nseg, key)
    return _whole(problem, step, n_arcs, nseg, key)


def _whole(problem, step, n_arcs, nseg, key) -> ArcNLP:
    """The NLP of `arc_nlp` in MX around the mapped SX step, differentiated by casadi as a
    whole (the fallback of `_build_arc_nlp` for MX functions)."""
    model = problem.model
    nx, nu, free_p = model.nx, model.nu, problem.free_params
    S = int(nseg.sum())
    arc_of = np.repeat(np.arange(n_arcs), nseg)
    sym = ca.MX
    dh, ph, Xh = sym.sym("d", n_arcs), sym.sym("p", free_p.size), sym.sym("X", nx, S + 1)
    U, pfix, sx = sym.sym("U", nu, S), sym.sym("pfix", model.np), sym.sym("sx", nx)
    sT, sp, sJ = sym.sym("sT"), sym.sym("sp", free_p.size), sym.sym("sJ")
    qf, sq = sym.sym("qf", 4), sym.sym("sq")
    d = sT * dh
    p = pfix
    if free_p.size:
        sel = np.zeros((model.np, free_p.size))
        sel[free_p, np.arange(free_p.size)] = 1.0
        p = pfix + ca.mtimes(ca.DM(sel), sp * ph)
    X = ca.mtimes(ca.diag(sx), Xh)
    spread = np.zeros((n_arcs, S))  # h_j = d_k / n_k for the segments j of arc k
    spread[arc_of, np.arange(S)] = 1.0 / nseg[arc_of]
    h = ca.mtimes(d.T, ca.DM(spread))
    Xn, Q = step.map(S)(X[:, :-1], U, ca.repmat(p, 1, S), h)
    T = ca.sum1(d)
    g, blocks = [], []

    def add(kind, index, expr):
        expr = ca.vec(expr)
        g.append(expr)
        blocks.append((kind, index, expr.numel()))

    add("defect", None, (Xn - X[:, 1:]) / ca.repmat(sx, 1, S))  # continuity
    add("T", None, T / sT)
    x0, xf = X[:, 0], X[:, -1]
    if problem.q_final is not None:
        iq = model.attitude[0]
        err = attitude_error(qf, xf[iq:iq + 4])
        add("target", None, ca.sumsqr(err) / sq ** 2 if problem.q_final_tol > 0 else err / sq)
    if problem.quaternion_norm_at_t0:
        iq = model.attitude[0]
        add("qnorm", None, ca.sumsqr(x0[iq:iq + 4]) - 1)
    for i, c in enumerate(problem.boundary):
        cs = np.ones(c.size) if c.scale is None else np.asarray(c.scale, float)
        add("boundary", i, c.fun(x0, xf, p) / ca.DM(cs))
    for i, c in enumerate(problem.path):
        cs = np.ones(c.size) if c.scale is None else np.asarray(c.scale, float)
        fm = c.fun.map(S)
        for Xe in (X[:, :-1], X[:, 1:]):  # both ends of every segment, the arc's control
            add("path", i, fm(Xe, U, ca.repmat(p, 1, S)) / ca.repmat(ca.DM(cs), 1, S))
    J = sym(0)
    if problem.mayer is not None:
        J = J + problem.mayer(xf, p, T)
    if problem.lagrange is not None:
        J = J + ca.sum2(Q)
    w = ca.vertcat(dh, ph, ca.vec(Xh))
    par = ca.vertcat(ca.vec(U), pfix, sx, sT, sp, sJ, qf, sq)
    nlp = {"x": w, "p": par, "f": problem.objective_sign * J / sJ, "g": ca.vertcat(*g)}
    cost = ca.Function("switch_times_cost", [w, par], [J])
    return ArcNLP(nlp, cost, tuple(blocks), key)


def _assembled(problem, step, n_arcs, nseg, key) -> ArcNLP:
    """The NLP of `arc_nlp` with its derivatives assembled (`ocp.assembly.assemble`) from
    those of one segment -- its RK8 step, the path rows at both of its ends and its running
    cost, in the segment's start and end states, its arc's duration and the free parameters
    -- and of the ends (horizon, attitude target, quaternion norm, boundary rows, Mayer
    term), each differentiated once in SX: the same NLP as `_whole` (rows in the same
    order), whose casadi derivatives of the mapped step cost 0.085 s to build and 4-7 ms per
    Jacobian or Hessian evaluation on Bilimoria-Wie (24 segments)."""
    model = problem.model
    nx, nu, n_p = model.nx, model.nu, model.np
    free_p = problem.free_params
    nf = free_p.size
    S = int(nseg.sum())
    arc_of = np.repeat(np.arange(n_arcs), nseg)
    sign = problem.objective_sign
    sym = ca.SX
    # common parameters: pfix, sx, sT, sp, sJ, qf, sq (the NLP parameters after vec(U))
    c = sym.sym("c", n_p + nx + 1 + nf + 1 + 4 + 1)
    o = np.cumsum([0, n_p, nx, 1, nf, 1, 4, 1])
    pfix, sx, sT, sp, sJ, qf, sq = (c[o[i]:o[i + 1]] for i in range(7))
    s = sym.sym("s", nf)
    p = pfix
    if nf:
        sel = np.zeros((n_p, nf))
        sel[free_p, np.arange(nf)] = 1.0
        p = pfix + ca.mtimes(ca.DM(sel), sp * s)

    def scaled(rows, scale):
        cs = np.ones(rows.numel()) if scale is None else np.asarray(scale, float).ravel()
        return rows / ca.DM(cs)

    # one segment: z = (start state, end state, its arc's duration), scaled
    z, cu = sym.sym("z", 2 * nx + 1), sym.sym("cu", nu + 1)  # cu: (arc control, 1 / n_k)
    x, xe, u = sx * z[:nx], sx * z[nx:2 * nx], cu[:nu]
    xn, q = step(x, u, p, sT * z[2 * nx] * cu[nu])
    rows = [(xn - xe) / sx]
    for con in problem.path:
        rows += [scaled(con.fun(x, u, p), con.scale), scaled(con.fun(xe, u, p), con.scale)]
    seg_q = sign * q / sJ if problem.lagrange is not None else sym(0)
    seg_f = local_functions("arc_seg", [z, s, c, cu], ca.vertcat(*rows), seg_q,
                            ca.vertcat(z, s))

    # the ends: e = (durations, first state, last state), scaled
    e = sym.sym("e", n_arcs + 2 * nx)
    T = sT * ca.sum1(e[:n_arcs])
    x0, xf = sx * e[n_arcs:n_arcs + nx], sx * e[n_arcs + nx:]
    rows, blocks = [T / sT], [("defect", None, nx * S), ("T", None, 1)]
    if problem.q_final is not None:
        iq = model.attitude[0]
        err = attitude_error(qf, xf[iq:iq + 4])
        rows.append(ca.sumsqr(err) / sq ** 2 if problem.q_final_tol > 0 else err / sq)
        blocks.append(("target", None, rows[-1].numel()))
    if problem.quaternion_norm_at_t0:
        iq = model.attitude[0]
        rows.append(ca.sumsqr(x0[iq:iq + 4]) - 1)
        blocks.append(("qnorm", None, 1))
    for i, con in enumerate(problem.boundary):
        rows.append(scaled(con.fun(x0, xf, p), con.scale))
        blocks.append(("boundary", i, con.size))
    end_q = sign * problem.mayer(xf, p, T) / sJ if problem.mayer is not None else sym(0)
    end_f = local_functions("arc_ends", [e, s, c], ca.vertcat(*rows), end_q, ca.vertcat(e, s))

    # index maps: w = (durations, free parameters, vec(Xh)); g in the order of `blocks`
    Xi = n_arcs + nf + np.arange(nx * (S + 1)).reshape(S + 1, nx)  # [column, state]
    ph = n_arcs + np.arange(nf)
    j = np.arange(S)
    seg_cols = np.concatenate([Xi[:-1], Xi[1:], arc_of[:, None], np.repeat(ph[None, :], S, 0)], 1)
    end_cols = np.concatenate([np.arange(n_arcs), Xi[0], Xi[-1], ph])
    n_end = sum(b[2] for b in blocks[1:])
    seg_g = [j[:, None] * nx + np.arange(nx)[None, :]]
    at = nx * S + n_end
    for i, con in enumerate(problem.path):
        for _ in ("start", "end"):  # as `_whole`: all starts of the segments, then all ends
            seg_g.append(at + j[:, None] * con.size + np.arange(con.size)[None, :])
            blocks.append(("path", i, con.size * S))
            at += con.size * S
    seg_g = np.concatenate(seg_g, axis=1)
    end_g = nx * S + np.arange(n_end)

    w = ca.MX.sym("w", n_arcs + nf + nx * (S + 1))
    par = ca.MX.sym("par", nu * S + c.numel())
    Z = ca.reshape(w[seg_cols[:, :2 * nx + 1].reshape(-1).tolist()], 2 * nx + 1, S)
    shared = w[ph.tolist()] if nf else ca.MX(0, 1)
    cP = par[nu * S:]
    CU = ca.vertcat(ca.reshape(par[:nu * S], nu, S), ca.DM(1.0 / nseg[arc_of]).T)
    Ee = w[end_cols[:n_arcs + 2 * nx].tolist()]
    nlp, derivatives, _ = assemble(seg_f, end_f, w, par, [Z, shared, cP, CU], [Ee, shared, cP],
                                   [False, True, True, False], (seg_cols, seg_g, end_cols, end_g))
    sJ_par = par[nu * S + o[4]]
    cost = ca.Function("switch_times_cost", [w, par], [sign * nlp["f"] * sJ_par])
    return ArcNLP(nlp, cost, tuple(blocks), key, derivatives)


def constraint_bounds(problem: Problem, blocks, sT: float, sq: float):
    """``(lbg, ubg)`` of the constraint ``blocks`` of an `ArcNLP` (scaled as its rows)."""
    lo, hi = [], []
    T_lo, T_hi = problem.T_bounds
    for kind, i, n in blocks:
        if kind == "T":
            a, b = T_lo / sT, T_hi / sT
        elif kind == "target" and problem.q_final_tol > 0:
            a, b = (v / sq ** 2 for v in target_bounds(problem))
        elif kind in ("defect", "target", "qnorm"):
            a = b = 0.0
        else:
            c = (problem.boundary if kind == "boundary" else problem.path)[i]
            cs = np.ones(c.size) if c.scale is None else np.asarray(c.scale, float)
            a, b = np.asarray(c.lower, float) / cs, np.asarray(c.upper, float) / cs
        lo.append(np.resize(np.asarray(a, float).reshape(-1), n))
        hi.append(np.resize(np.asarray(b, float).reshape(-1), n))
    return np.concatenate(lo), np.concatenate(hi)
