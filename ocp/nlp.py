"""The NLP of one problem on one mesh: bounds, parameter values, packing and unpacking.

The symbolic NLP and its derivatives belong to the problem's *structure*
(`ocp.assembly.Structure`, kept in the one cache and shared by every problem of the same
structure); a `Discretization` adds what is particular to one problem, mesh and scaling:

* variables ``w``: ``X`` (nx, 1 + N m_x) states at the state nodes, ``U`` (nu, n_u) controls
  at the control nodes, ``P`` (k, 1) free parameters, ``T`` (1, 1) when the horizon is free
  — all scaled (`ocp.scaling`);
* constraints ``g``: ``defect`` (nx, N m_d), ``path`` (ng, n_u), ``boundary`` (nb, 1),
  ``quat_norm`` (1, 1) when ``|q(t0)|`` must be imposed, ``q_final`` (3, 1) for an attitude
  target (1, 1 with a pointing tolerance);
* the NLP parameter vector ``P`` (scales, fixed parameter values, a fixed horizon, the mesh
  fractions, the target quaternion).

Boundary values and bounds are variable bounds (IPOPT treats fixed variables as parameters).
"""
from __future__ import annotations

import numpy as np

from .assembly import Structure, problem_functions, structure_key
from .attitude import target_bounds
from .cached import cached

__all__ = ["Discretization", "structure"]


def structure(problem, transcription, N: int, *, expand: bool = True, codegen: bool = False,
              key: tuple | None = None) -> Structure:
    """The `Structure` of ``problem`` transcribed by ``transcription`` on ``N`` intervals,
    from the one cache (built on a miss; in MX when SX construction fails)."""
    def build():
        try:
            return Structure(problem, transcription, N, expand, codegen)
        except RuntimeError:
            if not expand:
                raise
            return Structure(problem, transcription, N, False)

    if key is None:  # (serializing the functions for their content keys costs about 60 us each)
        key = structure_key(problem, transcription, N, expand, codegen=codegen)
    return cached("nlp_structure", key, build,
                  keepalive=tuple(f for f in problem_functions(problem) if f is not None))


class Discretization:
    """The NLP of ``problem`` transcribed by ``transcription`` on ``mesh``.

    Parameters
    ----------
    problem : ocp.Problem
    transcription : ocp.Transcription
    mesh : ocp.Mesh
    scaling : ocp.scaling.Scaling
    expand : bool, optional
        Interval functions in SX when possible (default); see `ocp.assembly`.
    codegen : bool, optional
        Compile the interval functions to C (`ocp.assembly.Structure`).

    Attributes
    ----------
    structure : ocp.assembly.Structure
        The symbolic NLP and its derivative Functions (shared by equal structures).
    key : tuple
        `ocp.assembly.structure_key` of the structure.
    w, g : Layout
        Structure of the decision and constraint vectors.
    nlp : dict
        ``{'x': w, 'p': P, 'f': sign J / d_J, 'g': g}`` (MX) for ``casadi.nlpsol``, ``sign``
        = `Problem.objective_sign` (``-1`` when maximizing).
    P : ndarray, shape (n_P,)
        Value of the NLP parameters for this problem, mesh and scaling.
    lbx, ubx, lbg, ubg : ndarray
        Bounds of the scaled variables and constraints.
    """

    def __init__(self, problem, transcription, mesh, scaling, expand: bool = True, codegen: bool = False):
        self.problem, self.transcription, self.mesh, self.scaling = problem, transcription, mesh, scaling
        self.key = structure_key(problem, transcription, mesh.N, expand, codegen=codegen)
        st = self.structure = structure(problem, transcription, mesh.N, expand=expand,
                                        codegen=codegen, key=self.key)
        self.w, self.g, self.nlp = st.w, st.g, st.nlp
        self.P = st.params_value(problem, mesh, scaling)
        free, sc = problem.free_params, scaling
        n_x, n_u = self.w.shapes["X"][1], self.w.shapes["U"][1]

        # ------------------------------------------------ bounds
        xl = np.repeat(problem.x_bounds[0][:, None], n_x, axis=1)
        xh = np.repeat(problem.x_bounds[1][:, None], n_x, axis=1)
        for col, values in ((0, problem.x_initial), (-1, problem.x_final)):
            given = ~np.isnan(values)
            xl[given, col] = values[given]
            xh[given, col] = values[given]
        ul = np.repeat(problem.u_bounds[0][:, None], n_u, axis=1)
        uh = np.repeat(problem.u_bounds[1][:, None], n_u, axis=1)
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
        v = self.w.split(w)
        sc, problem = self.scaling, self.problem
        p = np.array(problem.p, dtype=float)
        free = problem.free_params
        p[free] = v["P"].reshape(-1) * sc.p[free]
        T = float(v["T"][0, 0] * sc.T) if problem.free_time else float(problem.T)
        return {"X": v["X"] * sc.x[:, None], "U": v["U"] * sc.u[:, None], "p": p, "T": T}

    def cost(self, w) -> float:
        """Unscaled objective ``J`` at a scaled ``w``, with the user's sign (not negated when
        maximizing)."""
        f, _ = self.structure.evaluate(w, self.P)
        return self.problem.objective_sign * f * self.scaling.objective

    def constraints(self, w) -> np.ndarray:
        """The scaled constraint vector ``g`` at a scaled ``w``, shape (n_g,)."""
        return self.structure.evaluate(w, self.P)[1]

    def scales(self) -> tuple[np.ndarray, np.ndarray, float]:
        """``(s_w, s_g, d_J)``: physical = scale x scaled, for every variable (shape (n_w,)),
        every constraint row (shape (n_g,)), and the objective."""
        sc, problem = self.scaling, self.problem
        free = problem.free_params
        n_x, n_u = self.w.shapes["X"][1], self.w.shapes["U"][1]
        sw = self.w.join({"X": np.repeat(sc.x[:, None], n_x, axis=1), "U": np.repeat(sc.u[:, None], n_u, axis=1),
                          "P": sc.p[free][:, None], "T": sc.T})
        q = sc.q_final if problem.q_final is not None and problem.q_final_tol == 0 else 1.0
        sg = self.g.join({"defect": sc.x[:, None], "path": sc.path[:, None] if sc.path.size else 1.0,
                          "boundary": sc.boundary[:, None] if sc.boundary.size else 1.0,
                          "quat_norm": 1.0, "q_final": q})
        return sw, sg, float(sc.objective)

    def multipliers(self, lam_g, *, objective_multiplier: float = 1.0) -> dict:
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
        `ocp.scaling`, not by IPOPT's internal scaling).

        A scale far above the natural size of its variable (a ``scale=`` override of 1e6 on
        a control of size 1) would hide a real violation: IPOPT relaxes a bound by 1e-8 of
        its scaled value, which is 0.01 in physical units there. With ``w`` given, a
        variable's (and its defect rows') violation is therefore measured against
        ``max(1, |value|, |finite bounds|)`` (states: over all nodes) wherever its scale
        exceeds 4x that size; elsewhere the scaled measure is unchanged.
        """
        g = np.asarray(g, dtype=float).reshape(-1)
        fw = fg = 1.0
        if w is not None:
            w = np.asarray(w, dtype=float).reshape(-1)
            fw, fg = self._oversize(w)
        out = 0.0
        if g.size:
            out = float(np.max(np.maximum(0.0, np.maximum(self.lbg - g, g - self.ubg)) * fg))
        if w is not None and w.size:
            out = max(out, float(np.max(np.maximum(0.0, np.maximum(self.lbx - w, w - self.ubx)) * fw)))
        return out

    def _oversize(self, w) -> tuple[np.ndarray, np.ndarray]:
        """Factors ``scale / natural size`` (1 unless the scale exceeds 4x the size) for
        every variable and constraint row (`violation`)."""
        sw, _, _ = self.scales()
        finite = lambda b: np.where(np.isfinite(b), np.abs(b), 0.0)  # noqa: E731
        size = self.w.split(np.maximum.reduce([np.ones_like(sw), np.abs(w * sw),
                                               finite(self.lbx * sw), finite(self.ubx * sw)]))
        for block in ("X", "U"):  # a state's or control's size: its largest over the nodes
            size[block] = np.repeat(size[block].max(axis=1, keepdims=True), size[block].shape[1], axis=1)
        size = self.w.join(size)
        fw = np.where(sw > 4 * size, sw / size, 1.0)
        sx, nat = self.scaling.x, self.w.split(size)["X"][:, 0]
        fx = np.where(sx > 4 * nat, sx / nat, 1.0)
        n_d = self.g.shapes["defect"][1]
        ones = {k: np.ones(shape) for k, shape in self.g.shapes.items()}
        fg = self.g.join({**ones, "defect": np.repeat(fx[:, None], n_d, axis=1)})
        return fw, fg
