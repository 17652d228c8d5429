"""The NLP of a multi-phase problem: the phases' own NLPs side by side, plus the rows and
the objective over the phase ends.

Each phase is transcribed exactly as a single-phase problem (`ocp.nlp.Discretization` on
its `ocp.assembly.Structure`, from the one cache: the same interval kernels, scaling, bounds
and assembled derivatives). The multi-phase NLP stacks them::

    w = [w_0; w_1; ...]          P = [P_0; P_1; ...; d_J; s_e]
    f = sign (sum_i d_J_i f_i + Phi(E)) / d_J
    g = [g_0; g_1; ...; e(E) / s_e]

``E`` is the flat vector of phase ends (`ocp.phases.problem.ends_sizes`: ``x0, xf, p, T`` of
each phase, physical, read from the scaled variables and the phases' scale parameters),
``e`` the link and event rows and ``s_e`` their row scales. Its derivatives are assembled:
block-diagonal from every phase's own ``grad_f``/``jac_g``/``hess_lag`` Functions, plus the
(small, sparse) derivatives of ``Phi`` and ``e`` through ``E``. So a multi-phase NLP costs
its phases plus a few rows, and the combined structure is cached by the phases' structure
keys and the content of the ends function.
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from ..assembly import content_key
from ..cached import cached
from ..ipopt_options import ipopt_solver
from ..layout import Layout
from ..nlp import Discretization

__all__ = ["PhasedStructure", "PhasedDiscretization", "phased_structure"]


def _ends_expr(st, problem, w, P):
    """``(x0, xf, p, T)`` of one phase, physical, from its scaled variables ``w`` and its
    parameters ``P`` (symbols or numbers)."""
    X = st.w.indices("X")
    sx = P[st.params.indices("sx").reshape(-1).tolist()]
    x0 = w[X[:, 0].tolist()] * sx
    xf = w[X[:, -1].tolist()] * sx
    pval = P[st.params.indices("pval").reshape(-1).tolist()]
    sp = P[st.params.indices("sp").reshape(-1).tolist()]
    Pi = st.w.indices("P").reshape(-1)
    free = problem.free_params.tolist()
    p = ca.vertcat(*[w[int(Pi[free.index(k)])] * sp[k] if k in free else pval[k]
                     for k in range(problem.model.np)]) if problem.model.np else ca.MX(0, 1)
    if st.w.shapes["T"][0]:
        T = w[int(st.w.indices("T")[0, 0])] * P[int(st.params.indices("sT")[0, 0])]
    else:
        T = P[int(st.params.indices("Tfix")[0, 0])]
    return x0, xf, p, T


class PhasedStructure:
    """Symbolic multi-phase NLP and its assembled derivatives (see the module docstring).

    Attributes
    ----------
    w, P, g : Layout
        Blocks ``'0'``, ``'1'``, ... per phase (``P`` also ``'dJ'`` and ``'se'``; ``g`` also
        ``'e'``, the link and event rows).
    nlp : dict
        ``{'x', 'p', 'f', 'g'}`` (MX) for ``casadi.nlpsol``.
    derivatives : dict
        ``grad_f``, ``jac_g``, ``hess_lag``.
    ends : casadi.Function
        ``(w, P) -> E`` (the physical phase ends).
    """

    def __init__(self, structures, problems, ends_function: ca.Function, sign: float):
        n = len(structures)
        n_e = ends_function.numel_out(1)
        self.w = Layout({str(i): (st.w.size, 1) for i, st in enumerate(structures)})
        self.P = Layout({**{str(i): (st.params.size, 1) for i, st in enumerate(structures)},
                         "dJ": (1, 1), "se": (n_e, 1)})
        self.g = Layout({**{str(i): (st.g.size, 1) for i, st in enumerate(structures)}, "e": (n_e, 1)})
        w = ca.MX.sym("w", self.w.size)
        P = ca.MX.sym("P", self.P.size)
        lf = ca.MX.sym("lam_f")
        lg = ca.MX.sym("lam_g", self.g.size)

        def part(v, lay, name):
            o = lay.offset(name)
            return v[o:o + lay.shapes[name][0]]

        ws = [part(w, self.w, str(i)) for i in range(n)]
        Ps = [part(P, self.P, str(i)) for i in range(n)]
        dJ, se = P[self.P.offset("dJ")], part(P, self.P, "se")
        E = ca.vertcat(*[ca.vertcat(*_ends_expr(st, pb, wi, Pi))
                         for st, pb, wi, Pi in zip(structures, problems, ws, Ps)])
        phi, e = ends_function(E)
        e = e / se
        weights = [sign * Pi[int(st.params.indices("sJ")[0, 0])] / dJ for st, Pi in zip(structures, Ps)]
        fg = [st._fg(wi, Pi) for st, wi, Pi in zip(structures, ws, Ps)]
        f_end = sign * phi / dJ
        f = sum((c * fi for c, (fi, _) in zip(weights, fg)), f_end)
        g = ca.vertcat(*[gi for _, gi in fg], e)
        self.nlp = {"x": w, "p": P, "f": f, "g": g}
        self.ends = ca.Function("phase_ends_of_w", [w, P], [E], ["w", "P"], ["E"])

        grads = [st.derivatives["grad_f"](wi, Pi) for st, wi, Pi in zip(structures, ws, Ps)]
        grad = ca.vertcat(*[c * gr[1] for c, gr in zip(weights, grads)]) + ca.gradient(f_end, w)
        jacs = [st.derivatives["jac_g"](wi, Pi) for st, wi, Pi in zip(structures, ws, Ps)]
        J = ca.vertcat(ca.diagcat(*[jc[1] for jc in jacs]), ca.jacobian(e, w))
        lgs = [part(lg, self.g, str(i)) for i in range(n)]
        hs = [st.derivatives["hess_lag"](wi, Pi, lf * c, li)
              for st, wi, Pi, c, li in zip(structures, ws, Ps, weights, lgs)]
        lag_end = lf * f_end + ca.dot(part(lg, self.g, "e"), e) if n_e else lf * f_end
        H = ca.diagcat(*hs) + ca.triu(ca.hessian(lag_end, w)[0])
        self.derivatives = {
            "grad_f": ca.Function("nlp_grad_f", [w, P], [f, grad], ["x", "p"], ["f", "grad_f_x"]),
            "jac_g": ca.Function("nlp_jac_g", [w, P], [g, J], ["x", "p"], ["g", "jac_g_x"]),
            "hess_lag": ca.Function("nlp_hess_l", [w, P, lf, lg], [H],
                                    ["x", "p", "lam_f", "lam_g"], ["hess_gamma_x_x"]),
        }
        self._fg = ca.Function("nlp_fg", [w, P], [f, g], ["x", "p"], ["f", "g"])

    def evaluate(self, w, P) -> tuple[float, np.ndarray]:
        """``(f, g)`` of the scaled NLP at ``w`` with parameters ``P``."""
        out = self._fg(x=np.asarray(w, dtype=float), p=P)
        return float(out["f"]), np.asarray(out["g"]).reshape(-1)

    def nlpsol(self, name: str, options: dict) -> ca.Function:
        """An IPOPT solver on this NLP with the assembled derivatives."""
        opts = {k: v for k, v in options.items() if k != "expand"}
        opts.update(self.derivatives)
        opts.setdefault("calc_lam_p", False)
        return ipopt_solver(name, self.nlp, opts)


def phased_structure(problem, discs) -> PhasedStructure:
    """The `PhasedStructure` of ``problem`` (a `MultiPhaseProblem`) on the phase
    discretizations ``discs``, from the one cache."""
    key = (tuple(d.key for d in discs), content_key(problem.ends_function), problem.objective_sign)
    return cached("phased_structure", key, lambda: PhasedStructure(
        [d.structure for d in discs], [d.problem for d in discs], problem.ends_function,
        problem.objective_sign), keepalive=(problem.ends_function, *[d.structure for d in discs]))


class PhasedDiscretization:
    """The multi-phase NLP of one problem on given phase meshes and scalings.

    Parameters
    ----------
    problem : ocp.MultiPhaseProblem
    discs : sequence of ocp.nlp.Discretization
        One per phase (its problem, transcription, mesh and scaling).
    objective_scale : float
        ``d_J``: the NLP objective is ``J / d_J``.
    event_scale : ndarray, shape (n_e,)
        Row scales of the link and event rows.

    Attributes
    ----------
    structure : PhasedStructure
    P, lbx, ubx, lbg, ubg : ndarray
        Parameter values and bounds of the scaled variables and constraints.
    """

    def __init__(self, problem, discs, objective_scale: float, event_scale: np.ndarray):
        self.problem, self.discs = problem, list(discs)
        self.structure = st = phased_structure(problem, self.discs)
        self.key = ("phased", tuple(d.key for d in discs), content_key(problem.ends_function))
        self.objective_scale, self.event_scale = float(objective_scale), np.asarray(event_scale, float)
        lo, hi = problem.event_bounds()
        self.P = st.P.join({**{str(i): d.P[:, None] for i, d in enumerate(discs)},
                            "dJ": self.objective_scale, "se": self.event_scale[:, None]})
        self.lbx = np.concatenate([d.lbx for d in discs])
        self.ubx = np.concatenate([d.ubx for d in discs])
        self.lbg = np.concatenate([*[d.lbg for d in discs], lo / self.event_scale])
        self.ubg = np.concatenate([*[d.ubg for d in discs], hi / self.event_scale])
        self._last_violations = None

    def split_w(self, w) -> list[np.ndarray]:
        """The scaled variables of each phase."""
        parts = self.structure.w.split(np.asarray(w, dtype=float).reshape(-1))
        return [parts[str(i)].reshape(-1) for i in range(len(self.discs))]

    def split_g(self, g) -> tuple[list[np.ndarray], np.ndarray]:
        """``(rows of each phase, the link and event rows)`` of a constraint-sized vector."""
        parts = self.structure.g.split(np.asarray(g, dtype=float).reshape(-1))
        return [parts[str(i)].reshape(-1) for i in range(len(self.discs))], parts["e"].reshape(-1)

    def pack(self, guesses) -> np.ndarray:
        """Scaled start point from one `ocp.guess.NodeGuess` per phase."""
        return np.concatenate([d.pack(gs) for d, gs in zip(self.discs, guesses)])

    def ends(self, w) -> np.ndarray:
        """The physical phase ends ``E`` at a scaled ``w``."""
        return np.asarray(self.structure.ends(w, self.P)).reshape(-1)

    def cost(self, w) -> float:
        """``J`` (the user's sign) at a scaled ``w``."""
        f, _ = self.structure.evaluate(w, self.P)
        return self.problem.objective_sign * f * self.objective_scale

    def violation(self, g, w=None) -> float:
        """Largest violation of the constraint and (when given) variable bounds, in NLP
        units: each phase's rows and variables as `ocp.nlp.Discretization.violation`
        measures them, and the link and event rows."""
        phases, events = self.violations(g, w)
        return max(max(phases, default=0.0), events)

    def violations(self, g, w) -> tuple[tuple[float, ...], float]:
        """``(each phase's violation, the link and event rows' violation)`` at ``g`` and
        ``w`` (``None``: the constraints only), as `violation` measures them; the last
        point's answer is kept, so the result's check and the phases' solutions measure a
        solve's end point once."""
        g = np.asarray(g, dtype=float).reshape(-1)
        w = np.asarray(w, dtype=float).reshape(-1) if w is not None else None
        key = (g.tobytes(), None if w is None else w.tobytes())
        if self._last_violations is not None and self._last_violations[0] == key:
            return self._last_violations[1]
        gs, ge = self.split_g(g)
        ws = self.split_w(w) if w is not None else [None] * len(self.discs)
        phases = tuple(d.violation(gi, wi) for d, gi, wi in zip(self.discs, gs, ws))
        lo, hi = self.lbg[-ge.size:] if ge.size else ge, self.ubg[-ge.size:] if ge.size else ge
        out = (phases, float(np.max(np.maximum(0.0, np.maximum(lo - ge, ge - hi)), initial=0.0)))
        self._last_violations = (key, out)
        return out


def event_row_scales(problem, ends: np.ndarray, discs) -> np.ndarray:
    """Row scales of the link and event rows: the largest entry of each row of their Jacobian
    with respect to the phase ends in units of the phases' scales, at the guess ``ends``
    (a power of 2, clamped to [1e-6, 1e6]); an event's own ``scale`` where given."""
    jac = _ends_jacobian(problem.ends_function, ends.size)
    n_e = jac.size1_out(0)
    if n_e == 0:
        return np.zeros(0)
    units = []
    for d in discs:
        sc, pb = d.scaling, d.problem
        sp = np.ones(pb.model.np)
        sp[pb.free_params] = sc.p[pb.free_params]
        units += [sc.x, sc.x, sp, [sc.T if pb.free_time else 1.0]]
    unit = np.concatenate([np.asarray(u, dtype=float).reshape(-1) for u in units])
    J = np.abs(np.asarray(jac(ends))) * unit[None, :]
    g = J.max(axis=1)
    out = np.ones(n_e)
    ok = g > 0
    out[ok] = np.exp2(np.round(np.log2(np.clip(g[ok], 1e-6, 1e6))))
    n_link = n_e - sum(problem.event_sizes)
    k = n_link
    for ev, m in zip(problem.events, problem.event_sizes):
        if ev.scale is not None:
            out[k:k + m] = ev.scale
        k += m
    return out


def _ends_jacobian(ends_function: ca.Function, n: int) -> ca.Function:
    """``E -> d e / d E`` of the link and event rows ``e`` of ``ends_function`` (``n`` phase
    ends), built once per ends function in the one cache."""
    def build():
        E = ca.SX.sym("E", n)
        e = ends_function(E)[1]
        return ca.Function("event_rows_jacobian", [E], [ca.jacobian(e, E)])

    return cached("event_rows_jacobian", (content_key(ends_function), n), build,
                  keepalive=ends_function)


__all__ += ["event_row_scales"]
_ = Discretization  # the per-phase NLP this module stacks
