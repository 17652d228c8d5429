"""`DenseOutput`: a solution's interval data and the transcription's interpolant."""
from __future__ import annotations

import casadi as ca
import numpy as np

from ..dynamics import cache

__all__ = ["DenseOutput"]

def _mapped(interp: ca.Function, M: int) -> ca.Function:
    """``interp`` mapped over ``M`` points (itself when ``M == 1``), built once per pair and
    kept in the one cache (`dynamics.cache`): building a map Function takes about 0.5 ms, as
    long as evaluating it on a few hundred points, and a slew's switch detection samples the
    same counts dozens of times per solve."""
    if M == 1:
        return interp
    key = ("ocp.dense.mapped", cache.function_key(interp), M)
    return cache.get(key, lambda: interp.map(M, [False] * 5 + [True, False], [False, False]),
                     keepalive=interp)


class DenseOutput:
    """Interval data of a solution and the transcription's interpolant (its dense output).

    Attributes
    ----------
    xs : ndarray, shape (nx, N)
        State at each interval start.
    Xo : ndarray, shape (nx, N, m_x)
        States at the interval's own state nodes.
    us : ndarray, shape (nu, N)
        Control at each interval start (zeros when the transcription has none there).
    Uo : ndarray, shape (nu, N, m_u)
        Controls at the interval's own control nodes.
    p : ndarray, shape (np,)
    h : ndarray, shape (N,) [s]
        Interval lengths.
    t_breaks : ndarray, shape (N + 1,) [s]
        Mesh points in time.
    """

    def __init__(self, transcription, mesh, model, X, U, p, T, t0):
        N = mesh.N
        tr = transcription
        m_x, m_u = tr.x_sigma.size, tr.u_sigma.size
        self.transcription, self.mesh, self.model = tr, mesh, model
        self.nx, self.nu, self.N, self.m_x, self.m_u = model.nx, model.nu, N, m_x, m_u
        self.xs = X[:, 0:N * m_x:m_x]
        self.Xo = X[:, 1:].reshape(model.nx, N, m_x)
        if tr.u_at_start:
            self.us, Uo = U[:, 0:N * m_u:m_u], U[:, 1:]
        else:
            self.us, Uo = np.zeros((model.nu, N)), U
        self.Uo = Uo.reshape(model.nu, N, m_u)
        self.p = p
        self.h = T * mesh.fractions
        self.t_breaks = t0 + T * mesh.breaks
        self.t_breaks[-1] = t0 + T
        self._interp = None  # built on first use: Radau's dense output needs none (`eval`)

    @property
    def interp(self) -> ca.Function:
        """The transcription's interpolant Function (`Transcription.interpolant`; built on
        first use, from the cache when present)."""
        fun = self._interp
        if fun is None:
            fun = self._interp = self.transcription.interpolant(self.model.f)
        return fun

    def __getstate__(self) -> dict:
        state = dict(self.__dict__)
        state["_interp"] = None  # a cached CasADi Function: rebuilt on load
        return state

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)

    def eval(self, k: np.ndarray, s: np.ndarray):
        """``(x (nx, M), u (nu, M))`` in intervals ``k`` at ``sigma = s``: by the
        transcription's `dense_weights` where the interpolant is linear in the node values
        (one numpy product), else by its interpolant Function mapped over the points."""
        M = k.size
        if M == 0:
            return np.zeros((self.nx, 0)), np.zeros((self.nu, 0))
        s_at, at = np.unique(np.asarray(s, float), return_inverse=True)  # few distinct s
        weights = self.transcription.dense_weights(s_at)
        if weights is not None:  # linear in the node values: numpy, no Function call
            wx, wu = weights[0][at.ravel()], weights[1][at.ravel()]
            x = np.einsum("imj,mj->im", self.Xo[:, k, :], wx[:, 1:]) + self.xs[:, k] * wx[:, 0]
            u = np.einsum("imj,mj->im", self.Uo[:, k, :], wu[:, 1:]) + self.us[:, k] * wu[:, 0]
            return x, u
        args = [self.xs[:, k], self.Xo[:, k, :].reshape(self.nx, M * self.m_x),
                self.us[:, k], self.Uo[:, k, :].reshape(self.nu, M * self.m_u),
                self.h[k][None, :], self.p[:, None], s[None, :]]
        x, u = _mapped(self.interp, M)(*args)
        return np.asarray(x).reshape(self.nx, M), np.asarray(u).reshape(self.nu, M)

    def locate(self, t: np.ndarray):
        """Interval index (intervals are ``(t_k, t_k+1]``, ``t0`` in the first) and sigma."""
        k = np.clip(np.searchsorted(self.t_breaks, t, side="left") - 1, 0, self.N - 1)
        h = self.h[k]
        s = np.divide(t - self.t_breaks[k], h, out=np.zeros(np.shape(t)), where=h > 0)
        return k, np.clip(s, 0.0, 1.0)
