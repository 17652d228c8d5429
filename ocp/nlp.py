"""Assembly of the sparse NLP of a transcribed problem.

`Discretization` maps the transcription's interval kernel over the mesh (one
``Function.map`` call: every interval's defects and quadrature at once), evaluates the path
constraints with one mapped Function over the control nodes, and stacks variables and
constraints through `ocp.layout.Layout` blocks:

* variables ``w``: ``X`` (nx, 1 + N m_x) states at the state nodes, ``U`` (nu, n_u) controls
  at the control nodes, ``P`` (k, 1) free parameters, ``T`` (1, 1) when the horizon is free
  — all scaled (`ocp.scaling`);
* constraints ``g``: ``defect`` (nx, N m_d), ``path`` (ng, n_u), ``boundary`` (nb, 1),
  ``quat_norm`` (1, 1) when ``|q(t0)|`` must be imposed, ``q_final`` (3, 1) for an attitude
  target (1, 1 with a pointing tolerance).

Boundary values and bounds are variable bounds (IPOPT treats fixed variables as parameters).
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from .attitude import nlp_rows, target_bounds, target_rows
from .layout import Layout

__all__ = ["Discretization"]


def _diag_scale(M, d: np.ndarray):
    """``M / d`` row-wise (``d`` shape (rows,)), as a sparse diagonal product."""
    if M.shape[0] == 0:
        return M
    return ca.mtimes(ca.diag(ca.DM(1.0 / d)), M)


def _path_function(problem) -> ca.Function | None:
    cons = problem.path
    if not cons:
        return None
    m = problem.model
    syms = [ca.MX.sym("x", m.nx), ca.MX.sym("u", m.nu), ca.MX.sym("p", m.np)]
    out = ca.vertcat(*[c.fun(*syms) for c in cons])
    return ca.Function("path", syms, [out], ["x", "u", "p"], ["g"])


class Discretization:
    """The NLP of ``problem`` transcribed by ``transcription`` on ``mesh``.

    Parameters
    ----------
    problem : ocp.Problem
    transcription : ocp.Transcription
    mesh : ocp.Mesh
    scaling : ocp.scaling.Scaling

    Attributes
    ----------
    w, g : Layout
        Structure of the decision and constraint vectors.
    nlp : dict
        ``{'x': w, 'f': sign J / d_J, 'g': g}`` (MX) for ``casadi.nlpsol``, ``sign`` =
        `Problem.objective_sign` (``-1`` when maximizing).
    lbx, ubx, lbg, ubg : ndarray
        Bounds of the scaled variables and constraints.
    """

    def __init__(self, problem, transcription, mesh, scaling):
        self.problem, self.transcription, self.mesh, self.scaling = problem, transcription, mesh, scaling
        model = problem.model
        nx, nu, np_ = model.nx, model.nu, model.np
        N = mesh.N
        tr = transcription
        m_x, m_u = tr.x_sigma.size, tr.u_sigma.size
        self.n_x, self.n_u = 1 + N * m_x, N * m_u + int(tr.u_at_start)
        free = problem.free_params
        sc = scaling

        kernel = tr.kernel(model.f, problem.lagrange)
        m_d = kernel.size2_out("defect")
        n_path = sum(c.size for c in problem.path)
        n_bound = sum(c.size for c in problem.boundary)
        self.w = Layout({"X": (nx, self.n_x), "U": (nu, self.n_u), "P": (free.size, 1),
                         "T": (int(problem.free_time), 1)})
        self.g = Layout({"defect": (nx, N * m_d), "path": (n_path, self.n_u),
                         "boundary": (n_bound, 1), "quat_norm": (int(problem.quaternion_norm_at_t0), 1),
                         "q_final": (target_rows(problem), 1)})

        # ------------------------------------------------ symbols (scaled -> physical)
        wsym = ca.MX.sym("w", self.w.size)
        v = self.w.split(wsym)
        X = ca.mtimes(ca.diag(ca.DM(sc.x)), v["X"]) if nx else v["X"]
        U = ca.mtimes(ca.diag(ca.DM(sc.u)), v["U"]) if nu else v["U"]
        E = np.zeros((np_, free.size))
        E[free, np.arange(free.size)] = sc.p[free]
        p_const = np.array(problem.p, dtype=float)
        p_const[free] = 0.0
        p = ca.DM(p_const) + ca.mtimes(ca.DM(E), v["P"]) if free.size else ca.DM(p_const)
        T = sc.T * v["T"] if problem.free_time else ca.DM(problem.T)
        self._phys = ca.Function("physical", [wsym], [X, U, p, T], ["w"], ["X", "U", "p", "T"])

        # ------------------------------------------------ intervals: one mapped kernel
        h = T * ca.DM(mesh.fractions).T  # (1, N)
        xs = X[:, ca.Slice(0, N * m_x, m_x)]
        Xo = X[:, 1:]
        if tr.u_at_start:
            us, Uo = U[:, ca.Slice(0, N * m_u, m_u)], U[:, 1:]
        else:
            us, Uo = ca.DM.zeros(nu, N), U
        kmap = kernel.map(N, [False] * 5 + [True], [False, False, True])
        out = kmap(xs=xs, X=Xo, us=us, U=Uo, h=h, p=p)
        defect, xu, quad = out["defect"], out["xu"], out["quad"]
        Xu = ca.horzcat(X[:, 0], xu) if tr.u_at_start else xu

        # ------------------------------------------------ objective
        J = quad
        if problem.mayer is not None:
            J = J + problem.mayer(X[:, -1], p, T)
        self._cost = ca.Function("cost", [wsym], [J], ["w"], ["J"])

        # ------------------------------------------------ constraints
        parts = {"defect": _diag_scale(defect, sc.x)}
        path = _path_function(problem)
        if path is not None:
            G = path.map(self.n_u, [False, False, True], [False])(Xu, U, p)
            parts["path"] = _diag_scale(G, sc.path)
        else:
            parts["path"] = ca.MX(0, self.n_u)
        if problem.boundary:
            c = ca.vertcat(*[b.fun(X[:, 0], X[:, -1], p) for b in problem.boundary])
            parts["boundary"] = _diag_scale(c, sc.boundary)
        else:
            parts["boundary"] = ca.MX(0, 1)
        parts["quat_norm"], parts["q_final"] = nlp_rows(problem, X, sc.q_final)  # ocp.attitude
        gsym = self.g.join(parts, symbolic=True)
        self.nlp = {"x": wsym, "f": problem.objective_sign * J / sc.objective, "g": gsym}

        # ------------------------------------------------ bounds
        xl = np.repeat(problem.x_bounds[0][:, None], self.n_x, axis=1)
        xh = np.repeat(problem.x_bounds[1][:, None], self.n_x, axis=1)
        for col, values in ((0, problem.x_initial), (-1, problem.x_final)):
            given = ~np.isnan(values)
            xl[given, col] = values[given]
            xh[given, col] = values[given]
        ul = np.repeat(problem.u_bounds[0][:, None], self.n_u, axis=1)
        uh = np.repeat(problem.u_bounds[1][:, None], self.n_u, axis=1)
        pl, ph = problem.p_bounds[0][free], problem.p_bounds[1][free]
        Tl, Th = (np.array(problem.T) / sc.T) if problem.free_time else (np.zeros(0), np.zeros(0))
        self.lbx = self.w.join({"X": xl / sc.x[:, None], "U": ul / sc.u[:, None],
                                "P": (pl / sc.p[free])[:, None], "T": np.reshape(Tl, (-1, 1))})
        self.ubx = self.w.join({"X": xh / sc.x[:, None], "U": uh / sc.u[:, None],
                                "P": (ph / sc.p[free])[:, None], "T": np.reshape(Th, (-1, 1))})
        zeros = np.zeros
        path_lo = np.concatenate([c.lower for c in problem.path]) if problem.path else zeros(0)
        path_hi = np.concatenate([c.upper for c in problem.path]) if problem.path else zeros(0)
        b_lo = np.concatenate([c.lower for c in problem.boundary]) if problem.boundary else zeros(0)
        b_hi = np.concatenate([c.upper for c in problem.boundary]) if problem.boundary else zeros(0)
        common = {"defect": 0.0, "quat_norm": 0.0}
        q_lo, q_hi = target_bounds(problem)
        self.lbg = self.g.join({**common, "path": (path_lo / sc.path)[:, None],
                                "boundary": (b_lo / sc.boundary)[:, None], "q_final": q_lo})
        self.ubg = self.g.join({**common, "path": (path_hi / sc.path)[:, None],
                                "boundary": (b_hi / sc.boundary)[:, None], "q_final": q_hi})

    # ---------------------------------------------------------------- packing
    def pack(self, guess) -> np.ndarray:
        """Scaled decision vector from a `NodeGuess`, clipped into the variable bounds."""
        sc, free = self.scaling, self.problem.free_params
        w = self.w.join({"X": guess.X / sc.x[:, None], "U": guess.U / sc.u[:, None],
                         "P": (guess.p[free] / sc.p[free])[:, None],
                         "T": np.full((int(self.problem.free_time), 1), guess.T / sc.T)})
        return np.clip(w, self.lbx, self.ubx)

    def unpack(self, w) -> dict:
        """Physical ``X`` (nx, n_x), ``U`` (nu, n_u), ``p`` (np,), ``T`` from a scaled ``w``."""
        out = self._phys(w=np.asarray(w, dtype=float))
        return {"X": np.asarray(out["X"]).reshape(self.w.shapes["X"]),
                "U": np.asarray(out["U"]).reshape(self.w.shapes["U"]),
                "p": np.asarray(out["p"]).reshape(-1), "T": float(out["T"])}

    def cost(self, w) -> float:
        """Unscaled objective ``J`` at a scaled ``w``, with the user's sign (not negated when
        maximizing)."""
        return float(self._cost(w=np.asarray(w, dtype=float))["J"])

    def multipliers(self, lam_g, objective_multiplier: float = 1.0) -> dict:
        """Multipliers of the unscaled constraints, by block.

        CasADi's ``lam_g`` belongs to the scaled NLP ``sign J / d_J + lam_g . g_scaled``; for
        the minimized objective ``sign J + nu . g`` (``sign`` = `Problem.objective_sign`, so
        ``-J`` when maximizing) they are ``nu = lam_g d_J / row_scale``.
        """
        parts = self.g.split(np.asarray(lam_g, dtype=float).reshape(-1))
        sc, dJ = self.scaling, self.scaling.objective
        parts["defect"] = parts["defect"] * dJ / sc.x[:, None]
        if parts["path"].size:
            parts["path"] = parts["path"] * dJ / sc.path[:, None]
        if parts["boundary"].size:
            parts["boundary"] = parts["boundary"] * dJ / sc.boundary[:, None]
        parts["quat_norm"] = parts["quat_norm"] * dJ
        parts["q_final"] = parts["q_final"] * dJ / sc.q_final
        return parts

    def violation(self, g, w=None) -> float:
        """Largest violation of the constraint bounds by ``g`` and, when given, of the
        variable bounds by ``w``, both in the units of the NLP handed to IPOPT (scaled by
        `ocp.scaling`, not by IPOPT's internal scaling)."""
        g = np.asarray(g, dtype=float).reshape(-1)
        out = 0.0
        if g.size:
            out = float(np.max(np.maximum(0.0, np.maximum(self.lbg - g, g - self.ubg))))
        if w is not None:
            w = np.asarray(w, dtype=float).reshape(-1)
            if w.size:
                out = max(out, float(np.max(np.maximum(0.0, np.maximum(self.lbx - w, w - self.ubx)))))
        return out
