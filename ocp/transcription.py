"""Direct transcriptions: trapezoid, Hermite-Simpson, Radau (LGR) collocation.

All transcriptions share one small contract (`Transcription`). On a mesh of ``N`` intervals
(`ocp.mesh.Mesh`), interval ``k`` of duration ``h_k`` is parametrized by ``sigma in [0, 1]``
and owns

* the state at its start ``xs`` (shared with the end of interval ``k - 1``) and the states
  ``X`` at its own state nodes ``x_sigma`` (the last one at ``sigma = 1``);
* the controls ``U`` at its control nodes ``u_sigma``, plus, when ``u_at_start``, the
  control ``us`` at ``sigma = 0`` shared with the end of interval ``k - 1``.

A transcription supplies two symbolic pieces, both CasADi Functions of one interval:

* ``kernel``: ``(xs, X, us, U, h, p) -> (defect, xu, quad)`` — the collocation defects
  (zero on a discrete solution, in state units), the state at each owned control node
  (where path constraints and the running cost are evaluated) and the quadrature of the
  running cost ``L`` over the interval;
* ``interpolant``: ``(xs, X, us, U, h, p, s) -> (x, u)`` — the dense solution inside the
  interval at ``sigma = s``, consistent with the discretization (used by
  `Solution.sample` and by the re-simulation of the control).

`Transcription.build` maps the kernel over the intervals (``Function.map``; no Python loop
emits constraints) and assembles the sparse NLP (`ocp.nlp.Discretization`).

=====================  ==========  ==========  ================  =====================
transcription          x_sigma     u_sigma     u_at_start        dense x / dense u
=====================  ==========  ==========  ================  =====================
``Trapezoid``          1           1           yes               linear / linear
``HermiteSimpson``     1/2, 1      1/2, 1      yes               cubic Hermite / quad.
(``separated=False``)  1           1/2, 1      yes               cubic Hermite / quad.
``Radau(d)``           c_1..c_d    c_1..c_d    no                degree d / degree d-1
=====================  ==========  ==========  ================  =====================

``c_1 < ... < c_d = 1`` are the Radau IIA (flipped Legendre-Gauss-Radau) points,
``casadi.collocation_points(d, 'radau')``.

Control interpolants (``Transcription.control``)
------------------------------------------------
The dense control of ``Radau`` is the degree ``d - 1`` polynomial through its collocation
points: between the nodes it can leave the bounds the nodes satisfy (on bang-bang and
singular arcs it rings and overshoots, measured up to 1.9 times a torque bound on a
time-optimal slew). Two Radau variants cannot overshoot box bounds:

* ``RadauConstantControl`` (``control='constant'``): one value per interval;
* ``RadauLinearControl`` (``control='linear'``): continuous and piecewise linear, one value
  at every mesh point (a convex combination of two bounded values stays within the box).

`get_transcription` (and `ocp.solve`) pick them with ``control='constant'`` or
``'linear'``; ``'polynomial'`` is the transcription's own interpolant (linear for
``Trapezoid``, quadratic for ``HermiteSimpson``, degree ``d - 1`` for ``Radau``).
"""
from __future__ import annotations

import abc
from dataclasses import dataclass
from functools import cached_property

import casadi as ca
import numpy as np

from .cached import cached, function_key
from .functions import sx_compatible
from .mesh import Mesh, sorted_union

__all__ = ["Transcription", "Trapezoid", "HermiteSimpson", "Radau", "RadauConstantControl",
           "RadauLinearControl", "TRANSCRIPTIONS", "CONTROLS", "f_columns", "lagrange_columns", "sx_compatible",
           "get_transcription"]


def _lagrange_basis(nodes: np.ndarray, s):
    """Lagrange basis polynomials through ``nodes`` at ``s`` (product form: exact at nodes)."""
    out = []
    nodes = [float(v) for v in nodes]  # Python floats: an SX op with a numpy scalar is ~5x slower
    for j, tj in enumerate(nodes):
        b = 1
        for m, tm in enumerate(nodes):
            if m != j:
                b = b * (s - tm) / (tj - tm)
        out.append(b)
    return out


def _lagrange_matrix(nodes: np.ndarray, s: np.ndarray) -> np.ndarray:
    """`_lagrange_basis` for numeric ``s`` (shape (M,)) in one array: ``B[i, j] = l_j(s_i)``,
    shape (M, n) (the same factors: exact at the nodes)."""
    n = nodes.size
    den = nodes[:, None] - nodes[None, :]
    np.fill_diagonal(den, 1.0)
    factors = (s[:, None, None] - nodes[None, None, :]) / den[None, :, :]  # (M, j, m)
    factors[:, np.arange(n), np.arange(n)] = 1.0
    return np.prod(factors, axis=2)


def _differentiation_matrix(nodes: np.ndarray) -> np.ndarray:
    """``D[i, j] = l_j'(nodes[i])`` by barycentric weights (accurate to a few ulp)."""
    n = nodes.size
    diff = nodes[:, None] - nodes[None, :]
    np.fill_diagonal(diff, 1.0)
    bw = 1.0 / np.prod(diff, axis=1)
    D = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            if i != j:
                D[i, j] = bw[j] / bw[i] / (nodes[i] - nodes[j])
        D[i, i] = -np.sum(D[i, np.arange(n) != i])
    return D


def _quadrature_weights(nodes: np.ndarray) -> np.ndarray:
    """``w_i = integral_0^1 l_i(s) ds`` for the Lagrange basis through ``nodes``."""
    g, gw = np.polynomial.legendre.leggauss(nodes.size + 1)
    s, gw = 0.5 * (g + 1.0), 0.5 * gw
    return gw @ _lagrange_matrix(nodes, s)


@dataclass(frozen=True)
class Transcription(abc.ABC):
    """The contract every transcription meets (see the module docstring).

    Attributes
    ----------
    name : str
        Short identifier (``'trapezoid'``, ``'hermite-simpson'``, ...).
    x_sigma : ndarray, shape (m_x,)
        Owned state nodes in the interval (``x_sigma[-1] == 1``).
    u_sigma : ndarray, shape (m_u,)
        Owned control nodes in the interval.
    u_at_start : bool
        Whether a control node sits at ``sigma = 0`` (shared with the previous interval).
    order : int
        Nominal convergence order of the state at the mesh points for smooth problems
        (``error = O(h^order)``).
    control : str
        The dense control's interpolant: ``'polynomial'`` (through the control nodes of an
        interval, may overshoot between them), ``'linear'`` or ``'constant'`` (both stay
        within box bounds that the nodes satisfy).
    """

    # ----------------------------------------------------------- per-scheme part
    name = "transcription"
    order = 0
    u_at_start = True
    control = "polynomial"

    @property
    @abc.abstractmethod
    def x_sigma(self) -> np.ndarray: ...

    @property
    @abc.abstractmethod
    def u_sigma(self) -> np.ndarray: ...

    @abc.abstractmethod
    def _kernel(self, f, L, xs, X, us, U, h, p):
        """Symbolic ``(defect (nx, m_d), xu (nx, m_u), quad (1, 1))`` of one interval."""

    @property
    def path_sigma(self) -> np.ndarray:
        """Where in an interval the path constraints are imposed, shape (m_p,): the control
        nodes ``u_sigma`` (a constant or linear Radau control: every collocation point)."""
        return self.u_sigma

    def _path_points(self, xs, X, us, U, xu):
        """Symbolic ``(x (nx, m_p), u (nu, m_p))`` at `path_sigma` of one interval, given
        ``xu`` (the states at the control nodes, from `_kernel`)."""
        return xu, U

    @abc.abstractmethod
    def _interpolate(self, f, xs, X, us, U, h, p, s):
        """Symbolic ``(x (nx, 1), u (nu, 1))`` at ``sigma = s`` inside one interval (its
        ``u`` is `control_at`'s)."""

    @abc.abstractmethod
    def control_at(self, us, U, s):
        """The control polynomial of one interval at ``sigma = s``, symbolic (SX or MX).

        Parameters
        ----------
        us : casadi.SX or casadi.MX, shape (nu, 1)
            The control at the interval start (unused where the transcription has none).
        U : casadi.SX or casadi.MX, shape (nu, m_u)
            The interval's own control nodes.
        s : casadi.SX or casadi.MX, scalar
            The fraction of the interval.

        Returns
        -------
        casadi.SX or casadi.MX, shape (nu, 1)
            The same expression as the ``u`` of the interpolant (`interpolant`), built
            without its state part (re-simulations need the control alone).

        Examples
        --------
        >>> import casadi as ca
        >>> from appdyn.ocp.transcription import RadauLinearControl
        >>> us, U, s = ca.SX.sym("us"), ca.SX.sym("U", 1, 1), ca.SX.sym("s")
        >>> ca.Function("u", [us, U, s], [RadauLinearControl(3).control_at(us, U, s)])(1, 3, 0.5)
        DM(2)
        """

    def dense_weights(self, s: np.ndarray):
        """Weights of the dense output where it is linear in the node values, or ``None``.

        Parameters
        ----------
        s : ndarray, shape (M,)
            Fractions of the interval.

        Returns
        -------
        (wx, wu) or None
            ``wx`` (M, 1 + m_x) and ``wu`` (M, 1 + m_u) with ``x(s) = [xs, X] @ wx[i]`` and
            ``u(s) = [us, U] @ wu[i]`` (``us`` the control at the interval start, zero when
            the transcription has none there); ``None`` when the interpolant depends on the
            dynamics (Hermite-Simpson): use `interpolant`.
        """
        return None

    def costates(self, defect_multipliers: np.ndarray, mesh: Mesh):
        """Costate estimates at the state nodes from the defect multipliers, or ``None``.

        Parameters
        ----------
        defect_multipliers : ndarray, shape (nx, N m_d)
            Multipliers ``nu`` of the unscaled defects in the Lagrangian
            ``J + sum nu . defect`` (CasADi's sign).
        mesh : Mesh
        """
        return None

    # ------------------------------------------------------------ common part
    def kernel(self, f: ca.Function, L: ca.Function | None) -> ca.Function:
        """The interval Function ``(xs, X, us, U, h, p) -> (defect, xp, up, quad)``: the
        defects, the states and controls at `path_sigma`, the running cost's quadrature.

        Parameters
        ----------
        f : casadi.Function
            ``(x, u, p) -> xdot``.
        L : casadi.Function or None
            Running cost ``(x, u, p) -> L``; ``None`` gives ``quad = 0``.

        Returns
        -------
        casadi.Function
            Built once per transcription, ``f`` and ``L`` (`ocp.cached`).
        """
        Lkey = None if L is None else function_key(L)
        return cached("kernel", (self, function_key(f), Lkey), lambda: self._build_kernel(f, L),
                      keepalive=(f, L))

    def _build_kernel(self, f, L):
        sym = ca.SX if sx_compatible(f) and (L is None or sx_compatible(L)) else ca.MX
        nx, nu, np_ = f.numel_in(0), f.numel_in(1), f.numel_in(2)
        ins = self._symbols(sym, nx, nu, np_)
        defect, xu, quad = self._kernel(f, L, *ins)
        xp, up = self._path_points(ins[0], ins[1], ins[2], ins[3], xu)
        if not isinstance(quad, (ca.SX, ca.MX)):
            quad = sym.zeros(1, 1)
        return ca.Function(f"{self.name.replace('-', '_')}_interval", list(ins), [defect, xp, up, quad],
                           ["xs", "X", "us", "U", "h", "p"], ["defect", "xp", "up", "quad"])

    def interpolant(self, f: ca.Function) -> ca.Function:
        """The interval Function ``(xs, X, us, U, h, p, s) -> (x, u)`` (dense solution),
        built once per transcription and ``f`` (`ocp.cached`)."""
        return cached("interpolant", (self, function_key(f)), lambda: self._build_interpolant(f),
                      keepalive=f)

    def _build_interpolant(self, f):
        sym = ca.SX if sx_compatible(f) else ca.MX
        nx, nu, np_ = f.numel_in(0), f.numel_in(1), f.numel_in(2)
        ins = self._symbols(sym, nx, nu, np_)
        s = sym.sym("s")
        x, u = self._interpolate(f, *ins, s)
        return ca.Function(f"{self.name.replace('-', '_')}_interpolant", [*ins, s], [x, u],
                           ["xs", "X", "us", "U", "h", "p", "s"], ["x", "u"])

    def _symbols(self, sym, nx, nu, np_):
        m_x, m_u = self.x_sigma.size, self.u_sigma.size
        return (sym.sym("xs", nx), sym.sym("X", nx, m_x), sym.sym("us", nu),
                sym.sym("U", nu, m_u), sym.sym("h"), sym.sym("p", np_))

    def _tau(self, mesh: Mesh, sigma: np.ndarray) -> np.ndarray:
        b, h = mesh.breaks, mesh.fractions
        tau = b[:-1, None] + h[:, None] * sigma[None, :]
        tau[:, sigma == 1.0] = b[1:, None]
        return tau.reshape(-1)

    def state_tau(self, mesh: Mesh) -> np.ndarray:
        """Normalized times of the state columns ``X``, shape (1 + N m_x,)."""
        return np.concatenate([[0.0], self._tau(mesh, self.x_sigma)])

    def control_tau(self, mesh: Mesh) -> np.ndarray:
        """Normalized times of the control columns ``U``, shape (N m_u + u_at_start,)."""
        tau = self._tau(mesh, self.u_sigma)
        return np.concatenate([[0.0], tau]) if self.u_at_start else tau

    @property
    def node_sigma(self) -> np.ndarray:
        """Owned output nodes of an interval: union of state and control nodes."""
        return sorted_union(self.x_sigma, self.u_sigma)

    def node_tau(self, mesh: Mesh) -> np.ndarray:
        """Normalized times of all output nodes (``t0`` plus the owned nodes)."""
        return np.concatenate([[0.0], self._tau(mesh, self.node_sigma)])

    def build(self, problem, mesh: Mesh, scaling):
        """Assemble the NLP of ``problem`` on ``mesh`` with ``scaling``.

        Parameters
        ----------
        problem : ocp.Problem
        mesh : ocp.Mesh
        scaling : ocp.scaling.Scaling

        Returns
        -------
        ocp.nlp.Discretization
        """
        from .nlp import Discretization

        return Discretization(problem, self, mesh, scaling)


def f_columns(f, X, U, p):
    """``f`` at each column of ``X``/``U`` (shape (nx, m))."""
    m = X.shape[1]
    return f.map(m)(X, U, p) if m > 1 else f(X, U, p)


def lagrange_columns(L, X, U, p):
    """``L`` at each column of ``X``/``U`` (shape (1, m)); zeros without ``L``."""
    m = X.shape[1]
    if L is None:
        return ca.DM.zeros(1, m)
    return L.map(m)(X, U, p) if m > 1 else L(X, U, p)


# =============================================================================== trapezoid
@dataclass(frozen=True)
class Trapezoid(Transcription):
    """Trapezoidal collocation: states and controls at the mesh points.

    Defect ``x_{k+1} - x_k - h/2 (f_k + f_{k+1})``, quadrature ``h/2 (L_k + L_{k+1})``.
    Second order. Dense output linear in ``x`` and ``u``.
    """

    name = "trapezoid"
    order = 2
    u_at_start = True
    control = "linear"

    @property
    def x_sigma(self):
        return np.array([1.0])

    @property
    def u_sigma(self):
        return np.array([1.0])

    def _kernel(self, f, L, xs, X, us, U, h, p):
        xe, ue = X[:, 0], U[:, 0]
        defect = xe - xs - h / 2 * (f(xs, us, p) + f(xe, ue, p))
        quad = 0 if L is None else h / 2 * (L(xs, us, p) + L(xe, ue, p))
        return defect, xe, quad

    def _interpolate(self, f, xs, X, us, U, h, p, s):
        return xs + s * (X[:, 0] - xs), self.control_at(us, U, s)

    def control_at(self, us, U, s):
        return us + s * (U[:, 0] - us)

    def dense_weights(self, s):
        w = np.stack([1.0 - s, s], axis=1)
        return w, w


# ========================================================================= Hermite-Simpson
@dataclass(frozen=True)
class HermiteSimpson(Transcription):
    """Hermite-Simpson collocation (separated or compressed form).

    Per interval, with ``f_s, f_c, f_e`` at start, midpoint and end:

    * interpolation ``x_c = (x_s + x_e)/2 + h/8 (f_s - f_e)`` (the cubic Hermite midpoint),
    * Simpson ``x_e - x_s - h/6 (f_s + 4 f_c + f_e) = 0``; running cost by Simpson's rule.

    ``separated=True`` keeps ``x_c`` as a variable with the interpolation as a defect
    (sparser, better conditioned); ``separated=False`` (compressed) substitutes it, so the
    midpoint state is not a variable and state bounds are not imposed there. Fourth order.
    Dense output: cubic Hermite ``x`` (through ``x_s, x_e`` with slopes ``f_s, f_e``),
    quadratic ``u`` through ``u_s, u_c, u_e``.
    """

    separated: bool = True
    order = 4
    u_at_start = True

    @property
    def name(self):
        return "hermite-simpson" if self.separated else "hermite-simpson-compressed"

    @property
    def x_sigma(self):
        return np.array([0.5, 1.0]) if self.separated else np.array([1.0])

    @property
    def u_sigma(self):
        return np.array([0.5, 1.0])

    def _kernel(self, f, L, xs, X, us, U, h, p):
        uc, ue = U[:, 0], U[:, 1]
        xe = X[:, -1]
        fs, fe = f(xs, us, p), f(xe, ue, p)
        x_interp = (xs + xe) / 2 + h / 8 * (fs - fe)
        if self.separated:
            xc = X[:, 0]
            fc = f(xc, uc, p)
            defect = ca.horzcat(xc - x_interp, xe - xs - h / 6 * (fs + 4 * fc + fe))
        else:
            xc = x_interp
            fc = f(xc, uc, p)
            defect = xe - xs - h / 6 * (fs + 4 * fc + fe)
        quad = 0 if L is None else h / 6 * (L(xs, us, p) + 4 * L(xc, uc, p) + L(xe, ue, p))
        return defect, ca.horzcat(xc, xe), quad

    def _interpolate(self, f, xs, X, us, U, h, p, s):
        uc, ue = U[:, 0], U[:, 1]
        xe = X[:, -1]
        fs, fe = f(xs, us, p), f(xe, ue, p)
        s2, s3 = s * s, s * s * s
        x = ((2 * s3 - 3 * s2 + 1) * xs + (s3 - 2 * s2 + s) * h * fs
             + (-2 * s3 + 3 * s2) * xe + (s3 - s2) * h * fe)
        return x, self.control_at(us, U, s)

    def control_at(self, us, U, s):
        b0, bc, be = _lagrange_basis(np.array([0.0, 0.5, 1.0]), s)
        return b0 * us + bc * U[:, 0] + be * U[:, 1]


# ================================================================================== Radau
@dataclass(frozen=True)
class Radau(Transcription):
    """Legendre-Gauss-Radau (Radau IIA) collocation of degree ``d`` per interval.

    The state is a degree-``d`` polynomial through ``sigma = 0, c_1, ..., c_d`` (``c_d = 1``);
    the dynamics hold at the ``d`` collocation points: ``sum_j D_ij x_j - h f(x_i, u_i) = 0``
    (differentiation matrix ``D``, shape (d, d+1)); running cost by the Radau quadrature
    ``h sum_i w_i L_i`` (exact for degree ``2d - 2``). Controls live at the collocation
    points only (none at ``sigma = 0``): the dense control is the degree ``d - 1``
    polynomial through them, extrapolated on ``[0, c_1)``. State order ``2d - 1`` at the
    mesh points for smooth problems.

    Parameters
    ----------
    degree : int
        ``d >= 1`` (``d = 1`` is implicit Euler).

    Notes
    -----
    Costates (`costates`) follow Garg et al. (2010, Automatica 46, "A unified framework for
    the numerical solution of optimal control problems using pseudospectral methods"):
    ``lambda_i = -nu_i / w_i`` at the collocation points and ``lambda(t0) =
    sum_i D_i0 nu_i`` of the first interval, for the Hamiltonian ``H = L + lambda . f``.
    """

    degree: int = 3
    u_at_start = False

    def __post_init__(self):
        d = self.degree
        if isinstance(d, (bool, np.bool_)) or not isinstance(d, (int, np.integer)) or not 1 <= d <= 20:
            raise ValueError(f"`degree` (Radau collocation degree) must be an integer in [1, 20], got {d!r}")
        object.__setattr__(self, "degree", int(d))

    name = "radau"

    @property
    def order(self):
        return 2 * self.degree - 1

    @cached_property
    def points(self) -> np.ndarray:
        """Collocation points ``c_1..c_d`` in (0, 1]."""
        return np.array(ca.collocation_points(self.degree, "radau"))

    @cached_property
    def D(self) -> np.ndarray:
        """Differentiation matrix, shape (d, d+1): rows at ``c_i``, columns ``0, c_1..c_d``."""
        nodes = np.concatenate([[0.0], self.points])
        return _differentiation_matrix(nodes)[1:, :]

    @cached_property
    def weights(self) -> np.ndarray:
        """Radau quadrature weights on [0, 1], shape (d,) (sum to 1)."""
        return _quadrature_weights(self.points)

    @property
    def x_sigma(self):
        return self.points

    @property
    def u_sigma(self):
        return self.points

    def _kernel(self, f, L, xs, X, us, U, h, p):
        Xall = ca.horzcat(xs, X)
        F = f_columns(f, X, U, p)
        defect = ca.mtimes(Xall, ca.DM(self.D.T)) - h * F
        quad = 0 if L is None else h * ca.mtimes(lagrange_columns(L, X, U, p), ca.DM(self.weights))
        return defect, X, quad

    def _interpolate(self, f, xs, X, us, U, h, p, s):
        bx = _lagrange_basis(np.concatenate([[0.0], self.points]), s)
        x = bx[0] * xs
        for j in range(self.degree):
            x = x + bx[j + 1] * X[:, j]
        return x, self.control_at(us, U, s)

    def control_at(self, us, U, s):
        bu = _lagrange_basis(self.points, s)
        u = 0
        for j in range(self.degree):
            u = u + bu[j] * U[:, j]
        return u

    def _state_weights(self, s):
        """``wx`` of `dense_weights`: the Lagrange basis through ``0, c_1, ..., c_d``."""
        return _lagrange_matrix(np.concatenate([[0.0], self.points]), s)

    def dense_weights(self, s):
        wu = np.concatenate([np.zeros((s.size, 1)), _lagrange_matrix(self.points, s)], axis=1)
        return self._state_weights(s), wu

    def costates(self, defect_multipliers, mesh):
        nu = np.asarray(defect_multipliers)
        nx, d, N = nu.shape[0], self.degree, mesh.N
        per = nu.reshape(nx, N, d)
        lam = -per / self.weights[None, None, :]
        lam0 = per[:, 0, :] @ self.D[:, 0]
        return np.concatenate([lam0[:, None], lam.reshape(nx, N * d)], axis=1)


@dataclass(frozen=True)
class RadauConstantControl(Radau):
    """Radau collocation of degree ``d`` with one constant control per mesh interval.

    The state is collocated exactly as in `Radau`; the control is a single value per
    interval (``u_sigma = [1]``), held at every collocation point, so a bang-bang control
    can only switch at mesh points. Path constraints are imposed at every collocation point
    (`path_sigma`; before, at the interval ends only: a keep-out cone was crossed by 5.9e-4
    at a collocation point in between).
    Use it with ``solve(..., transcription="radau-constant-control", degree=3)`` (or an
    instance); `ocp.polish_switches` uses it on a free mesh.
    """

    name = "radau-constant-control"
    control = "constant"

    @property
    def u_sigma(self):
        return np.array([1.0])

    def _kernel(self, f, L, xs, X, us, U, h, p):
        Uc = ca.repmat(U[:, 0], 1, self.degree)
        Xall = ca.horzcat(xs, X)
        defect = ca.mtimes(Xall, ca.DM(self.D.T)) - h * f_columns(f, X, Uc, p)
        quad = 0 if L is None else h * ca.mtimes(lagrange_columns(L, X, Uc, p), ca.DM(self.weights))
        return defect, X[:, -1], quad

    def _interpolate(self, f, xs, X, us, U, h, p, s):
        x, _ = super()._interpolate(f, xs, X, us, ca.repmat(U[:, 0], 1, self.degree), h, p, s)
        return x, self.control_at(us, U, s)

    def control_at(self, us, U, s):
        return U[:, 0]

    @property
    def path_sigma(self):
        return self.points

    def _path_points(self, xs, X, us, U, xu):
        return X, ca.repmat(U[:, 0], 1, self.degree)

    def dense_weights(self, s):
        return self._state_weights(s), np.stack([np.zeros_like(s), np.ones_like(s)], axis=1)


@dataclass(frozen=True)
class RadauLinearControl(Radau):
    """Radau collocation of degree ``d`` with a continuous, piecewise-linear control.

    The state is collocated exactly as in `Radau`; the control is one value at every mesh
    point (``u_at_start``, ``u_sigma = [1]``: shared by neighbouring intervals) and linear
    in between, ``u(sigma) = (1 - sigma) u_k + sigma u_k+1``, evaluated so at the
    collocation points. A linear interpolant between values within box bounds stays within
    them, so unlike `Radau` the dense control cannot overshoot a bound on a bang-bang or
    singular arc; a switch is smeared over one interval (refine the mesh, or
    `ocp.polish_switches`, to sharpen it). Path constraints are imposed at every collocation
    point and at the start (`path_sigma`; before, at the mesh points only: a CMG singularity
    measure crossed its limit by 2.3e-5 relative in between at 28 intervals).
    Use it with ``solve(..., control="linear")`` (or ``transcription="radau-linear-control"``).
    """

    name = "radau-linear-control"
    control = "linear"
    u_at_start = True

    @property
    def u_sigma(self):
        return np.array([1.0])

    def _controls(self, us, U):
        """The control at the collocation points, shape (nu, d)."""
        return ca.horzcat(*[us + c * (U[:, 0] - us) for c in self.points])

    def _kernel(self, f, L, xs, X, us, U, h, p):
        Uc = self._controls(us, U)
        Xall = ca.horzcat(xs, X)
        defect = ca.mtimes(Xall, ca.DM(self.D.T)) - h * f_columns(f, X, Uc, p)
        quad = 0 if L is None else h * ca.mtimes(lagrange_columns(L, X, Uc, p), ca.DM(self.weights))
        return defect, X[:, -1], quad

    def _interpolate(self, f, xs, X, us, U, h, p, s):
        x, _ = super()._interpolate(f, xs, X, us, self._controls(us, U), h, p, s)
        return x, self.control_at(us, U, s)

    def control_at(self, us, U, s):
        return us + s * (U[:, 0] - us)

    @property
    def path_sigma(self):
        return self.points

    def _path_points(self, xs, X, us, U, xu):
        return X, self._controls(us, U)

    def dense_weights(self, s):
        return self._state_weights(s), np.stack([1.0 - s, s], axis=1)


TRANSCRIPTIONS = ("trapezoid", "hermite-simpson", "hermite-simpson-compressed", "radau",
                  "radau-constant-control", "radau-linear-control")
#: Values of the ``control`` argument of `get_transcription` and `ocp.solve`.
CONTROLS = ("polynomial", "linear", "constant")
_WITH_DEGREE = {"radau": Radau, "radau-constant-control": RadauConstantControl,
                "radau-linear-control": RadauLinearControl}
_RADAU_BY_CONTROL = {"polynomial": Radau, "constant": RadauConstantControl,
                     "linear": RadauLinearControl}


def get_transcription(transcription="radau", *, degree: int | None = None,
                      control: str | None = None) -> Transcription:
    """A `Transcription` from its name (or pass an instance through).

    Parameters
    ----------
    transcription : str or Transcription
        One of ``TRANSCRIPTIONS`` or an instance.
    degree : int, optional
        Radau degree (default 3); only valid with the Radau transcriptions.
    control : {'polynomial', 'linear', 'constant'}, optional
        The dense control (module docstring). Default: the transcription's own. For the
        Radau family it selects `Radau`, `RadauLinearControl` or `RadauConstantControl` of
        the same degree; ``Trapezoid``'s control is linear (``'linear'`` and
        ``'polynomial'`` both keep it); Hermite-Simpson has only its quadratic one.

    Raises
    ------
    ValueError
        Unknown name or ``control``, ``degree`` given for a transcription that has none, or a
        ``control`` the transcription does not offer.
    """
    tr = _named_transcription(transcription, degree)
    if control is None or control == tr.control:
        return tr
    if control not in CONTROLS:
        raise ValueError(f"`control` must be one of {CONTROLS}, got {control!r}")
    if isinstance(tr, Radau):
        return _RADAU_BY_CONTROL[control](tr.degree)
    if control == "polynomial":
        return tr
    raise ValueError(f"`control` = {control!r} is not available with the {tr.name!r} "
                     f"transcription (its control is {tr.control}); use transcription='radau'")


def _named_transcription(transcription, degree) -> Transcription:
    if isinstance(transcription, Transcription):
        if degree is not None and getattr(transcription, "degree", None) != degree:
            raise ValueError(f"`degree` {degree} conflicts with the transcription {transcription!r}")
        return transcription
    if transcription in _WITH_DEGREE:
        return _WITH_DEGREE[transcription](3 if degree is None else degree)
    if transcription not in TRANSCRIPTIONS:
        raise ValueError(f"`transcription` must be one of {TRANSCRIPTIONS} or a Transcription, "
                         f"got {transcription!r}")
    if degree is not None:
        raise ValueError(f"`degree` applies to the Radau transcriptions only, not to {transcription!r}")
    if transcription == "trapezoid":
        return Trapezoid()
    return HermiteSimpson(separated=transcription == "hermite-simpson")
