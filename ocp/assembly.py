"""The symbolic NLP of one problem *structure*, with derivatives assembled per interval.

Why
---
Handing CasADi the whole transcribed NLP and letting it differentiate costs time in the
number of intervals ``N``: about 4.4 ms per Radau(3) interval of a rigid-body slew when the
NLP is expanded to SX, 1.3 ms without expansion (mostly the MX Jacobian of the mapped
kernel), so 3.6 s of construction before a 0.3 s solve at N = 800. Here every derivative is
taken once, of the functions of *one* interval (a few dozen variables), and the NLP's
gradient, Jacobian and Hessian of the Lagrangian are sums of the mapped interval derivatives
placed by integer index maps (`numpy`) — construction no longer grows with symbolic work
in ``N``.

Structure and parameters
------------------------
Everything numeric that does not change the shape of the NLP enters as an NLP *parameter*
``P`` (the ``p`` input of ``casadi.nlpsol``): the scale factors of `ocp.scaling`, the values
of fixed model parameters, a fixed horizon, the mesh fractions, the target quaternion.
Boundary values and bounds are variable and constraint bounds. So one `Structure` — and the
IPOPT solver built on it — serves every problem with the same model, cost and constraint
*functions* (compared by content, `content_key`), transcription, number of intervals,
free parameters, free or fixed horizon and kind of attitude target (`structure_key`).

Pieces
------
* ``seg(z, s, c, frac) -> (rows, quad)``: one interval. ``z`` its own scaled variables
  (start state, own state nodes, start control, own control nodes), ``s`` the shared
  ones (free parameters, ``T``), ``c`` the common parameters, ``frac`` its mesh fraction.
  ``rows``: its defects (divided by the state scales) and path rows at its own path
  points (`ocp.Transcription.path_sigma`: the control nodes, every collocation point for a
  constant or linear Radau control; divided by their scales); ``quad``: its share of
  ``sign J / d_J``.
* ``ends(e, s, c) -> (rows, mayer)``: the first and last state (and first control): the
  path rows at a start control node, boundary rows, ``|q(t0)|^2 - 1``, the attitude target
  rows, and the Mayer term.

Variables ``w`` and constraints ``g`` have the block layout of `ocp.nlp`.
"""
from __future__ import annotations

import hashlib

import casadi as ca
import numpy as np

from appdyn.dynamics.attitude import quat_conj, quat_mul

from appdyn.dynamics.cache import compile_function, compiler

from .cached import cached, function_key
from .layout import Layout
from .functions import sx_compatible
from .ipopt_options import ipopt_solver

__all__ = ["Structure", "Intervals", "intervals", "structure_key", "content_key",
           "local_functions", "assemble",
           "problem_functions"]


def content_key(fun: ca.Function | None):
    """A hashable key equal for Functions of equal content (name and serialized graph);
    the identity of ``fun`` when it cannot be serialized (e.g. it holds a Callback).

    Kept per Function object in the one cache (a casadi Function does not change once
    built): serializing the model and cost Functions on every solve and refinement round
    cost about 3 % of a Delta III solve."""
    if fun is None:
        return None
    return cached("content_key", (function_key(fun),), lambda: _content_key(fun), keepalive=fun)


def _content_key(fun: ca.Function):
    """`content_key` computed: the name and a digest of the serialized graph."""
    try:
        text = fun.serialize()
    except Exception:  # noqa: BLE001 - not serializable: identity (kept alive by the cache)
        return ("id", function_key(fun))
    return (fun.name(), hashlib.blake2b(text.encode(), digest_size=16).hexdigest())


def problem_functions(problem) -> list:
    """The CasADi Functions a problem's NLP is built from: the model's ``f``, the Lagrange
    and Mayer costs (None when absent), every path and boundary constraint's ``fun``."""
    return [problem.model.f, problem.lagrange, problem.mayer,
            *[c.fun for c in problem.path], *[c.fun for c in problem.boundary]]


def structure_key(problem, transcription, N: int, expand: bool, *, codegen: bool = False) -> tuple:
    """What determines a `Structure`: see the module docstring."""
    model = problem.model
    return (transcription, int(N), bool(expand), bool(codegen), content_key(model.f), content_key(problem.lagrange),
            content_key(problem.mayer), tuple((content_key(c.fun), c.size) for c in problem.path),
            tuple((content_key(c.fun), c.size) for c in problem.boundary),
            tuple(problem.free_params.tolist()), problem.free_time, problem.quaternion_norm_at_t0,
            _target_kind(problem), model.attitude[0] if model.attitude is not None else None,
            problem.objective_sign, model.nx, model.nu, model.np)


def _target_kind(problem) -> int:
    """0 without an attitude target, 1 for a pointing tolerance, 3 for an exact target."""
    if problem.q_final is None:
        return 0
    return 1 if problem.q_final_tol > 0 else 3


def _nonzeros(M):
    """The structural nonzeros of ``M`` as a column (column-major order)."""
    return ca.sparsity_cast(M, ca.Sparsity.dense(M.nnz(), 1))


def _triplets(M) -> tuple[np.ndarray, np.ndarray]:
    """Row and column of each structural nonzero of a symbolic matrix (column-major)."""
    r, c = M.sparsity().get_triplet()
    return np.asarray(r, dtype=np.int64), np.asarray(c, dtype=np.int64)


def local_functions(name: str, ins: list, rows, q, v, *, compiled: bool = False) -> tuple:
    """The derivative Functions of one piece of an NLP (an interval, the ends, a segment):
    ``(values, gradient, jacobian, hessian, jac triplets, grad triplets, hess triplets)``.

    ``ins`` are the piece's symbolic inputs, ``rows`` its constraint rows and ``q`` its
    share of the objective, ``v`` the variables (among ``ins``) they are differentiated by.
    ``values(*ins) -> (rows, q)``, ``gradient(*ins) -> (q, nonzeros of dq/dv)``,
    ``jacobian(*ins) -> (rows, nonzeros of d rows/dv)``, ``hessian(*ins, lam, lam_f) ->
    nonzeros of the upper triangle of d^2 (lam_f q + lam . rows) / dv^2``; the triplets are
    the ``(rows, cols)`` of those nonzeros in ``v``. ``compiled``: the derivatives compiled
    to C (`dynamics.cache.compile_function`).

    Examples
    --------
    >>> import casadi as ca
    >>> from appdyn.ocp.assembly import local_functions
    >>> x = ca.SX.sym("x", 2)
    >>> val, grad, jac, hess, jt, gt, ht = local_functions("f", [x], x[0] * x[1], x[0] ** 2, x)
    >>> float(hess([1, 2], [3], 1)[0]), jt[1].tolist(), ht[0].tolist()
    (2.0, [0, 1], [0, 0])
    """
    sym = ca.SX if isinstance(v, ca.SX) else ca.MX
    lam, lam_f = sym.sym("lam", rows.numel()), sym.sym("lam_f")
    J = ca.jacobian(rows, v)
    gq = ca.jacobian(q, v)
    H = ca.triu(ca.hessian(lam_f * q + ca.dot(lam, rows), v)[0])
    funs = (ca.Function(f"{name}_val", ins, [rows, q]),
            ca.Function(f"{name}_grad", ins, [q, _nonzeros(gq)]),
            ca.Function(f"{name}_jac", ins, [rows, _nonzeros(J)]),
            ca.Function(f"{name}_hess", ins + [lam, lam_f], [_nonzeros(H)]))
    if compiled:  # the derivatives; the values stay SX (IPOPT's nlp_grad differentiates them)
        funs = (funs[0], *(compile_function(fn) for fn in funs[1:]))
    return (*funs, _triplets(J), _triplets(gq), _triplets(H))


def assemble(seg_f: tuple, end_f: tuple, wsym, Psym, seg_args: list, end_args: list,
             rep_in: list, maps: tuple) -> tuple:
    """The NLP and its derivatives from pieces: ``(nlp, derivatives, fg)``.

    ``seg_f`` and ``end_f`` are `local_functions` of a repeated piece (mapped over the
    columns of its arguments ``seg_args``; ``rep_in`` says which are the same for every
    repetition) and of the single piece ``end_f(*end_args)``; ``maps = (seg_cols, seg_g,
    end_cols, end_g)`` are the positions in the NLP variables ``wsym`` of each repetition's
    and the single piece's variables, and in the constraints of their rows (numpy, one row
    per repetition). ``nlp``: ``{'x', 'p', 'f', 'g'}`` (MX; ``p`` = ``Psym``) for
    ``casadi.nlpsol``; ``derivatives``: ``grad_f``, ``jac_g`` and ``hess_lag`` Functions for
    its options of those names; ``fg``: ``(x, p) -> (f, g)``.

    Examples
    --------
    Two pieces ``x_k+1 - 2 x_k`` (objective ``x_k^2``) and one end row ``x_0 - 1``:

    >>> import casadi as ca
    >>> import numpy as np
    >>> from appdyn.ocp.assembly import assemble, local_functions
    >>> z, e = ca.SX.sym("z", 2), ca.SX.sym("e")  # a piece's (x_k, x_k+1); the end's x_0
    >>> seg = local_functions("seg", [z], z[1] - 2 * z[0], z[0] ** 2, z)
    >>> end = local_functions("end", [e], e - 1, 0 * e, e)
    >>> w, P = ca.MX.sym("w", 3), ca.MX.sym("P", 0)
    >>> cols = np.array([[0, 1], [1, 2]])  # the variables of each piece, a row per piece
    >>> maps = (cols, np.array([[0], [1]]), np.array([0]), np.array([2]))
    >>> Z = ca.reshape(w[cols.reshape(-1).tolist()], 2, 2)
    >>> nlp, d, fg = assemble(seg, end, w, P, [Z], [w[0]], [False], maps)
    >>> np.array(d["jac_g"]([1, 2, 4], [])[1]), float(fg([1, 2, 4], [])[0])
    (array([[-2.,  1.,  0.],
           [ 0., -2.,  1.],
           [ 1.,  0.,  0.]]), 5.0)
    """
    seg_cols, seg_g, end_cols, end_g = maps
    N = seg_cols.shape[0]
    n_seg, n_end = seg_g.shape[1], end_g.size
    n_w, n_g = wsym.numel(), N * n_seg + n_end

    def mapped(fun, reduce_out):
        return fun.map(N, rep_in, reduce_out)

    order = np.empty(n_g, dtype=np.int64)
    order[seg_g.reshape(-1)] = np.arange(N * n_seg)
    order[end_g] = N * n_seg + np.arange(n_end)
    order = order.tolist()

    def g_of(rows_seg, rows_end):
        return ca.vertcat(ca.vec(rows_seg), rows_end)[order] if order else ca.MX(0, 1)

    # values
    R, q = mapped(seg_f[0], [False, True])(*seg_args)
    Re, qe = end_f[0](*end_args)
    f, g = q + qe, g_of(R, Re)
    nlp = {"x": wsym, "p": Psym, "f": f, "g": g}

    # gradient of f
    q2, Gq = mapped(seg_f[1], [True, False])(*seg_args)
    qe2, Gqe = end_f[1](*end_args)
    cs, ce = seg_f[5][1], end_f[5][1]
    grad_rows = np.concatenate([seg_cols[:, cs].reshape(-1), end_cols[ce]])
    grad = _Assembly(n_w, 1, grad_rows, np.zeros(grad_rows.size, dtype=np.int64))
    gvec = ca.densify(grad(ca.vertcat(ca.vec(Gq), Gqe)))
    # Jacobian of g
    R3, Jz = mapped(seg_f[2], [False, False])(*seg_args)
    Re3, Je = end_f[2](*end_args)
    (rs, cs), (re, ce) = seg_f[4], end_f[4]
    jac = _Assembly(n_g, n_w, np.concatenate([seg_g[:, rs].reshape(-1), end_g[re]]),
                    np.concatenate([seg_cols[:, cs].reshape(-1), end_cols[ce]]))
    J = jac(ca.vertcat(ca.vec(Jz), Je))
    # Hessian of the Lagrangian (upper triangle)
    lf = ca.MX.sym("lam_f")
    lg = ca.MX.sym("lam_g", n_g)
    Lseg = ca.reshape(lg[seg_g.reshape(-1).tolist()], n_seg, N) if n_seg else ca.MX(0, N)
    Lend = lg[end_g.tolist()] if n_end else ca.MX(0, 1)
    Hz = seg_f[3].map(N, rep_in + [False, True], [False])(*seg_args, Lseg, lf)
    He = end_f[3](*end_args, Lend, lf)
    (rs, cs), (re, ce) = seg_f[6], end_f[6]
    hr = np.concatenate([seg_cols[:, rs].reshape(-1), end_cols[re]])
    hc = np.concatenate([seg_cols[:, cs].reshape(-1), end_cols[ce]])
    hess = _Assembly(n_w, n_w, np.minimum(hr, hc), np.maximum(hr, hc))
    H = hess(ca.vertcat(ca.vec(Hz), He))
    derivatives = {
        "grad_f": ca.Function("nlp_grad_f", [wsym, Psym], [q2 + qe2, gvec], ["x", "p"], ["f", "grad_f_x"]),
        "jac_g": ca.Function("nlp_jac_g", [wsym, Psym], [g_of(R3, Re3), J],
                             ["x", "p"], ["g", "jac_g_x"]),
        "hess_lag": ca.Function("nlp_hess_l", [wsym, Psym, lf, lg], [H],
                                ["x", "p", "lam_f", "lam_g"], ["hess_gamma_x_x"]),
    }
    return nlp, derivatives, ca.Function("nlp_fg", [wsym, Psym], [f, g], ["x", "p"], ["f", "g"])


class _Assembly:
    """Sum of value contributions into the nonzeros of a fixed sparse matrix.

    ``rows``, ``cols``: target positions of each contribution (value ``k`` of a stacked
    vector). Duplicated positions are summed (a sparse 0/1 matrix); otherwise a plain
    permutation."""

    def __init__(self, nrow: int, ncol: int, rows: np.ndarray, cols: np.ndarray):
        n = rows.size
        # the distinct positions in column-major (CSC) order: duplicates share one nonzero
        key = cols.astype(np.int64) * nrow + rows
        # pos: the position of each contribution in the CSC nonzeros
        uniq, pos = np.unique(key, return_inverse=True)
        indptr = np.searchsorted(uniq, np.arange(ncol + 1, dtype=np.int64) * nrow)
        self.sparsity = ca.Sparsity(nrow, ncol, indptr.tolist(), (uniq % nrow).tolist())
        self.nnz = uniq.size
        if uniq.size == n:
            order = np.empty(n, dtype=np.int64)
            order[pos] = np.arange(n)
            self._perm, self._sum = order.tolist(), None
        else:
            # one 1 per column k, in row pos[k]: contribution k adds into nonzero pos[k]
            self._perm = None
            self._sum = ca.DM(ca.Sparsity(uniq.size, n, list(range(n + 1)), pos.tolist()), np.ones(n))

    def __call__(self, values: ca.MX) -> ca.MX:
        """The sparse matrix from the stacked contributions ``values`` (MX column)."""
        if self.nnz == 0:
            return ca.MX(self.sparsity)
        if self._sum is None:
            nz = values[self._perm]
        else:
            nz = ca.densify(ca.mtimes(self._sum, values))
        return ca.MX(self.sparsity, nz)


class Intervals:
    """The part of a structure that does not depend on the number of intervals: the
    interval Function ``seg``, the end Function ``ends`` (module docstring) and their
    derivatives, built once per problem structure and kept in the cache (`intervals`), so
    refinement rounds that change ``N`` reuse them (and their C code with ``codegen``).

    Attributes
    ----------
    seg, ends : tuple
        ``(values, gradient, jacobian, hessian)`` Functions and the ``(rows, cols)`` of the
        structural nonzeros of the Jacobian, the cost gradient and the Hessian.
    common : Layout
        The parameters shared by every interval (scales, fixed values, horizon, target).
    sizes : dict
        Dimensions (``nx, nu, m_x, m_u, m_p, ua, m_d, n_path, n_bound, n_q, qn, nf, ft, n_z,
        n_s, n_seg, n_end``).
    symbolic : str
        ``'SX'`` or ``'MX'``.
    compiled : bool
        Whether the derivatives were compiled to C.
    """

    def __init__(self, problem, transcription, expand: bool = True, codegen: bool = False):
        model, tr = problem.model, transcription
        nx, nu, np_ = model.nx, model.nu, model.np
        m_x, m_u, m_p = tr.x_sigma.size, tr.u_sigma.size, tr.path_sigma.size
        ua = int(tr.u_at_start)
        free = problem.free_params
        nf, ft = free.size, int(problem.free_time)
        kernel = tr.kernel(model.f, problem.lagrange)
        m_d = kernel.size2_out("defect")
        n_path = sum(c.size for c in problem.path)
        n_bound = sum(c.size for c in problem.boundary)
        n_q = _target_kind(problem)
        qn = int(problem.quaternion_norm_at_t0)
        self.sizes = dict(nx=nx, nu=nu, m_x=m_x, m_u=m_u, m_p=m_p, ua=ua, m_d=m_d, n_path=n_path,
                          n_bound=n_bound, n_q=n_q, qn=qn, nf=nf, ft=ft)
        self.common = Layout({"sx": (nx, 1), "su": (nu, 1), "sp": (np_, 1), "sT": (1, 1), "sJ": (1, 1),
                              "spath": (n_path, 1), "sb": (n_bound, 1), "sq": (1, 1), "pval": (np_, 1),
                              "Tfix": (1, 1), "qf": (4 if n_q else 0, 1)})
        sx_ok = expand and all(f is None or sx_compatible(f) for f in problem_functions(problem))
        sym = ca.SX if sx_ok else ca.MX
        self.symbolic = sym.__name__
        sign = problem.objective_sign

        # ------------------------------------------------ physical values from scaled ones
        n_z = nx * (1 + m_x) + nu * (ua + m_u)
        n_s = nf + ft
        c = sym.sym("c", self.common.size)
        s = sym.sym("s", n_s)
        C = self.common.split(c)
        E = np.zeros((np_, nf))
        E[free, np.arange(nf)] = 1.0
        p = C["pval"] + (ca.mtimes(ca.DM(E), s[:nf] * C["sp"][free.tolist()]) if nf else 0)
        T = C["sT"] * s[nf] if ft else C["Tfix"]

        # ------------------------------------------------ one interval
        z = sym.sym("z", n_z)
        frac = sym.sym("frac")
        o = 0
        xs = C["sx"] * z[o:o + nx]; o += nx
        X = ca.reshape(z[o:o + nx * m_x], nx, m_x) * ca.repmat(C["sx"], 1, m_x); o += nx * m_x
        us = C["su"] * z[o:o + nu] if ua else sym.zeros(nu, 1); o += nu * ua
        U = ca.reshape(z[o:o + nu * m_u], nu, m_u) * ca.repmat(C["su"], 1, m_u)
        defect, xp, up, quad = kernel(xs, X, us, U, T * frac, p)
        rows = [ca.vec(defect / ca.repmat(C["sx"], 1, m_d))]
        if n_path:
            rows += [ca.vertcat(*[cons.fun(xp[:, j], up[:, j], p) for cons in problem.path]) / C["spath"]
                     for j in range(m_p)]
        seg_rows = ca.vertcat(*rows)
        seg_q = sign * quad / C["sJ"]
        seg_in = [z, s, c, frac]

        # ------------------------------------------------ the ends
        e = sym.sym("e", 2 * nx + nu * ua)
        x0, xf = C["sx"] * e[:nx], C["sx"] * e[nx:2 * nx]
        rows = []
        if ua and n_path:
            u0 = C["su"] * e[2 * nx:]
            rows.append(ca.vertcat(*[cons.fun(x0, u0, p) for cons in problem.path]) / C["spath"])
        if n_bound:
            rows.append(ca.vertcat(*[b.fun(x0, xf, p) for b in problem.boundary]) / C["sb"])
        iq = model.attitude[0] if model.attitude is not None else 0
        if qn:
            rows.append(ca.sumsqr(x0[iq:iq + 4]) - 1)
        if n_q:
            err = quat_mul(quat_conj(C["qf"]), xf[iq:iq + 4])[0:3]
            rows.append(ca.sumsqr(err) if n_q == 1 else err / C["sq"])
        end_rows = ca.vertcat(*rows) if rows else sym(0, 1)
        end_q = sign * problem.mayer(xf, p, T) / C["sJ"] if problem.mayer is not None else sym.zeros(1, 1)
        end_in = [e, s, c]

        # ------------------------------------------------ local derivative Functions
        n_seg, n_end = seg_rows.numel(), end_rows.numel()
        self.sizes.update(n_z=n_z, n_s=n_s, n_seg=n_seg, n_end=n_end)
        v_seg, v_end = ca.vertcat(z, s), ca.vertcat(e, s)
        self.compiled = bool(codegen and sx_ok and compiler() is not None)
        self.seg = local_functions("seg", seg_in, seg_rows, seg_q, v_seg, compiled=self.compiled)
        self.ends = local_functions("ends", end_in, end_rows, end_q, v_end, compiled=self.compiled)


def intervals(problem, transcription, *, expand: bool = True, codegen: bool = False) -> Intervals:
    """The `Intervals` of ``problem`` transcribed by ``transcription``, from the one cache."""
    key = structure_key(problem, transcription, 0, expand, codegen=codegen)
    return cached("nlp_intervals", key, lambda: Intervals(problem, transcription, expand, codegen),
                  keepalive=tuple(f for f in problem_functions(problem) if f is not None))


class Structure:
    """Symbolic NLP, derivative Functions and index maps of one problem structure.

    Parameters
    ----------
    problem : ocp.Problem
        Supplies the structure only (functions, sizes, flags); its numbers go to `params`.
    transcription : ocp.Transcription
    N : int
        Number of mesh intervals.
    expand : bool
        Build the interval functions in SX when every function allows it (faster
        evaluation); MX otherwise.
    codegen : bool, optional
        Compile the (SX) interval functions and their derivatives to C
        (`dynamics.cache.compile_function`; about 1-3 s once per structure, then kept in the
        cache with it). Ignored without a C compiler or for MX interval functions.

    Attributes
    ----------
    w, g : Layout
        Decision and constraint vectors (blocks as in `ocp.nlp`).
    params : Layout
        The NLP parameter vector ``P`` (`params_value` fills it).
    nlp : dict
        ``{'x', 'p', 'f', 'g'}`` (MX) for ``casadi.nlpsol``.
    derivatives : dict
        ``grad_f``, ``jac_g``, ``hess_lag`` Functions for the nlpsol options of those names.
    """

    def __init__(self, problem, transcription, N: int, expand: bool = True, codegen: bool = False):
        loc = intervals(problem, transcription, expand=expand, codegen=codegen)
        self.N, self.transcription, self.common = N, transcription, loc.common
        self.symbolic, self.compiled = loc.symbolic, loc.compiled
        dims = loc.sizes
        nx, nu, m_x, m_u, ua, m_d = (dims[k] for k in ("nx", "nu", "m_x", "m_u", "ua", "m_d"))
        n_path, n_z, n_seg, n_end = dims["n_path"], dims["n_z"], dims["n_seg"], dims["n_end"]
        m_p = dims["m_p"]
        n_x, n_u = 1 + N * m_x, N * m_u + ua
        self.w = Layout({"X": (nx, n_x), "U": (nu, n_u), "P": (dims["nf"], 1), "T": (dims["ft"], 1)})
        self.g = Layout({"defect": (nx, N * m_d), "path": (n_path, N * m_p + ua), "boundary": (dims["n_bound"], 1),
                         "quat_norm": (dims["qn"], 1), "q_final": (dims["n_q"], 1)})
        self.params = Layout({**self.common.shapes, "frac": (N, 1)})
        seg_f, end_f = loc.seg, loc.ends

        # ------------------------------------------------ index maps (numpy)
        Xi, Ui = self.w.indices("X"), self.w.indices("U")
        k = np.arange(N)
        own_x = 1 + k[:, None] * m_x + np.arange(m_x)[None, :]          # (N, m_x) X columns
        own_u = ua + k[:, None] * m_u + np.arange(m_u)[None, :]         # (N, m_u) U columns
        parts = [Xi[:, k * m_x].T, Xi[:, own_x.reshape(-1)].T.reshape(N, m_x * nx)]
        if ua:
            parts.append(Ui[:, k * m_u].T)
        parts.append(Ui[:, own_u.reshape(-1)].T.reshape(N, m_u * nu))
        shared = np.concatenate([self.w.indices("P").reshape(-1), self.w.indices("T").reshape(-1)])
        seg_cols = np.concatenate([*parts, np.repeat(shared[None, :], N, axis=0)], axis=1)
        end_cols = np.concatenate([Xi[:, 0], Xi[:, -1], Ui[:, 0] if ua else np.zeros(0, int), shared])
        Gd, Gp = self.g.indices("defect"), self.g.indices("path")
        seg_g = [Gd[:, k[:, None] * m_d + np.arange(m_d)[None, :]].transpose(1, 2, 0).reshape(N, nx * m_d)]
        if n_path:  # path rows at the interval's own path points (`path_sigma`)
            own_p = ua + k[:, None] * m_p + np.arange(m_p)[None, :]
            seg_g.append(Gp[:, own_p.reshape(-1)].T.reshape(N, m_p * n_path))
        seg_g = np.concatenate(seg_g, axis=1)
        end_g = np.concatenate([Gp[:, 0] if (ua and n_path) else np.zeros(0, int),
                                *[self.g.indices(b).reshape(-1) for b in ("boundary", "quat_norm", "q_final")]])
        self._maps = (seg_cols, seg_g, end_cols, end_g)

        # ------------------------------------------------ the NLP in MX
        wsym = ca.MX.sym("w", self.w.size)
        Psym = ca.MX.sym("P", self.params.size)
        cP = Psym[:self.common.size]
        fr = ca.reshape(Psym[self.common.size:], 1, N)
        Z = ca.reshape(wsym[seg_cols[:, :n_z].reshape(-1).tolist()], n_z, N)
        S = wsym[shared.tolist()] if shared.size else ca.MX(0, 1)
        Ee = wsym[end_cols[:end_cols.size - shared.size].tolist()]
        seg_args, end_args = [Z, S, cP, fr], [Ee, S, cP]
        rep_in = [False, True, True, False]
        self.nlp, self.derivatives, self._fg = assemble(
            seg_f, end_f, wsym, Psym, seg_args, end_args, rep_in, self._maps)

    # ---------------------------------------------------------------- use
    def params_value(self, problem, mesh, scaling) -> np.ndarray:
        """The parameter vector ``P`` of ``problem`` on ``mesh`` with ``scaling``."""
        free = problem.free_params
        pval = np.array(problem.p, dtype=float)
        pval[free] = 0.0
        sp = np.ones(problem.model.np)
        sp[free] = scaling.p[free]
        qf = np.asarray(problem.q_final, dtype=float) if problem.q_final is not None else np.zeros(0)
        return self.params.join({
            "sx": scaling.x[:, None], "su": scaling.u[:, None], "sp": sp[:, None], "sT": scaling.T,
            "sJ": scaling.objective, "spath": scaling.path[:, None], "sb": scaling.boundary[:, None],
            "sq": scaling.q_final, "pval": pval[:, None],
            "Tfix": 0.0 if problem.free_time else problem.T, "qf": qf[:, None],
            "frac": np.asarray(mesh.fractions, dtype=float)[:, None]})

    def evaluate(self, w, P) -> tuple[float, np.ndarray]:
        """``(f, g)`` of the scaled NLP at ``w`` with parameters ``P``."""
        out = self._fg(x=np.asarray(w, dtype=float), p=P)
        return float(out["f"]), np.asarray(out["g"]).reshape(-1)

    def nlpsol(self, name: str, options: dict) -> ca.Function:
        """An IPOPT solver on this NLP with the assembled derivatives (``options``: nlpsol
        options; ``expand`` is dropped — the interval functions are already SX)."""
        opts = {k: v for k, v in options.items() if k != "expand"}
        opts.update(self.derivatives)
        opts.setdefault("calc_lam_p", False)
        return ipopt_solver(name, self.nlp, opts)
