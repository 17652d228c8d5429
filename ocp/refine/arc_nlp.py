"""The switch-time NLP of `ocp.refine.switch_times`, built once per problem structure and
switching structure: every number (arc controls, fixed parameter values, scales, target
quaternion) an NLP parameter, kept in the one cache (`ocp.cached`), so a slew to another
target with as many arcs builds nothing."""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from ..assembly import structure_key
from ..attitude import attitude_error, target_bounds
from ..cached import cached
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
    the cache key."""

    nlp: dict
    cost: ca.Function
    blocks: tuple
    key: tuple


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
    """The NLP of `arc_nlp` in MX around the mapped SX step (under the construction lock)."""
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
