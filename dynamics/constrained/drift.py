"""Constraint drift control (the equations: `dynamics.constrained`).

Integrating ``B vdot + c = 0`` keeps the *second* derivative of ``phi`` at zero; round-off
and truncation errors then drift (``phi`` grows like ``t^2``, ``B v + b`` like ``t``).

* Baumgarte stabilization (`baumgarte`): ``c -> c + 2 alpha (B v + b) + beta^2 phi`` with
  ``alpha = beta = 1/tau`` for a time constant ``tau`` [s] on holonomic rows, so that the
  residual obeys ``e'' + (2/tau) e' + e/tau^2 = 0`` (critically damped, double root
  ``-1/tau``: ``e = (e0 + (e0' + e0/tau) t) exp(-t/tau)``), and by
  ``c + (1/tau)(B v + b)`` on velocity-only (nonholonomic) rows (``e' + e/tau = 0``). On the
  constraint manifold nothing changes. Default ``tau`` = `DEFAULT_TIME_CONSTANT` (1 s):
  keep it several integration steps long (the added modes ``-1/tau`` must be resolved by
  an explicit method) and shorter than the run.
* Projection between steps or after a run: `project_positions` (Newton steps of minimal
  ``weight``-norm onto ``phi = 0``) and `project_velocities` (the ``M``-norm-nearest
  ``v`` with ``B v + b = 0``: one KKT solve, an impulse ``-B^T mu``; internal constraints
  then keep the total momentum).
* Monitoring: `residual_invariant` is the model invariant ``constraint_residual`` =
  ``[|phi|, |B v + b|]``.
"""
from __future__ import annotations

from typing import Callable, NamedTuple

import casadi as ca
import numpy as np

from ..validate import finite_array, integer, positive
from .checks import CASADI_TYPES, column, is_casadi, matrix, vector
from .solve import constrained_accelerations

__all__ = ["DEFAULT_TIME_CONSTANT", "Projection", "baumgarte", "project_velocities",
           "project_positions"]

#: Baumgarte time constant ``tau`` [s] used when none is given.
DEFAULT_TIME_CONSTANT = 1.0


class Projection(NamedTuple):
    """A projected state ``x``, its remaining ``residual`` norm, Newton ``iterations`` and
    ``success`` (``residual <= tol``)."""

    x: np.ndarray
    residual: float
    iterations: int
    success: bool


def baumgarte(c, residual, position=None, *, time_constant=DEFAULT_TIME_CONSTANT):
    """Baumgarte-stabilized acceleration term (module docstring, Drift control).

    Parameters
    ----------
    c : array_like (m,) or casadi
        ``c`` of ``B vdot + c = 0``.
    residual : array_like (m,) or casadi
        Velocity residual ``B v + b``.
    position : array_like (k,) or casadi, optional
        Position residual ``phi`` of the first ``k <= m`` (holonomic) rows.
    time_constant : float, optional
        ``tau`` [s] > 0 (default `DEFAULT_TIME_CONSTANT`).

    Returns
    -------
    Same kind as ``c``
        ``c + (2/tau) residual + phi/tau^2`` on the first ``k`` rows,
        ``c + residual/tau`` on the others.

    Raises
    ------
    ValueError
        If ``time_constant`` is not a finite number > 0 or ``position`` has more rows than ``c``.

    Examples
    --------
    >>> from appdyn.dynamics.constrained import baumgarte
    >>> baumgarte([0.0, 0.0], [1.0, 1.0], [0.5], time_constant=0.5)
    array([6., 2.])
    """
    tau = positive(time_constant, "time_constant")
    symbolic = is_casadi(c, residual, position)
    col = column if symbolic else (lambda a, name: finite_array(a, name).reshape(-1))
    c, residual = col(c, "c"), col(residual, "residual")
    if residual.shape != c.shape:
        raise ValueError(f"`residual` must have {c.shape[0]} rows like `c`, "
                         f"got {residual.shape[0]}")
    k = 0 if position is None else col(position, "position").shape[0]
    if k > c.shape[0]:
        raise ValueError(f"`position` has {k} rows, more than the {c.shape[0]} rows of `c`")
    gain = np.r_[np.full(k, 2.0 / tau), np.full(c.shape[0] - k, 1.0 / tau)]
    out = c + (ca.DM(gain) if symbolic else gain) * residual
    if k:
        extra = col(position, "position") / tau**2
        out = (ca.vertcat(out[:k, 0] + extra, out[k:, 0]) if symbolic
               else np.r_[out[:k] + extra, out[k:]])
    return out


def project_velocities(M, B, v, b=None):
    """The velocity nearest to ``v`` in the ``M`` norm with ``B v + b = 0``.

    ``v - M^-1 B^T (B M^-1 B^T)^-1 (B v + b)``: the constrained-acceleration solve with
    ``Q = 0`` and ``c = B v + b`` (an impulse ``-B^T mu``; internal constraints keep the
    total momentum).

    Parameters
    ----------
    M : array_like (n, n) or casadi
    B : array_like (m, n) or casadi
    v : array_like (n,) or casadi
    b : array_like (m,) or casadi, optional (zero)

    Returns
    -------
    Same kind as ``v``

    Raises
    ------
    ValueError
        As `constrained_accelerations` (numeric input).

    Examples
    --------
    >>> from appdyn.dynamics.constrained import project_velocities
    >>> project_velocities([[1.0, 0.0], [0.0, 3.0]], [[1.0, -1.0]], [4.0, 0.0])  # equal speeds
    array([1., 1.])
    """
    if is_casadi(M, B, v, b):
        Bm = B if isinstance(B, CASADI_TYPES) else ca.DM(matrix(B, "B"))
        vc = column(v, "v")
        r = ca.mtimes(Bm, vc) + (0 if b is None else column(b, "b"))
        zero = 0 * vc
    else:
        Bm = matrix(B, "B")
        vc = vector(v, "v", Bm.shape[1])
        r = Bm @ vc + (0.0 if b is None else vector(b, "b", Bm.shape[0]))
        zero = np.zeros_like(vc)
    return vc + constrained_accelerations(M, zero, Bm, r).vdot


def project_positions(residual: Callable, jacobian: Callable, x, *, retract: Callable | None = None,
                      weight=None, tol: float = 1e-12, max_iter: int = 20) -> Projection:
    """Newton projection of a state onto ``phi(x) = 0`` (numeric).

    Each step is the ``weight``-norm-smallest displacement ``dxi`` with
    ``phi + J dxi = 0``, i.e. `constrained_accelerations` with ``M = weight``, ``Q = 0``,
    ``B = J``, ``c = phi``; then ``x <- retract(x, dxi)``.

    Parameters
    ----------
    residual : callable ``x -> phi``, shape (m,)
    jacobian : callable ``x -> J``, shape (m, k)
        Derivative of ``phi`` along the displacement ``dxi`` of ``retract``.
    x : array_like
        State to project.
    retract : callable ``(x, dxi) -> x``, optional
        Applies a displacement (default ``x + dxi``; e.g. rotates quaternions).
    weight : array_like (k, k), optional
        Symmetric positive definite metric of the displacements (identity).
    tol : float, optional
        Stop when ``|phi| <= tol`` [units of ``phi``].
    max_iter : int, optional

    Returns
    -------
    Projection
        ``x``, ``residual`` (``|phi|`` at the end), ``iterations``, ``success``.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.constrained import project_positions
    >>> res = project_positions(lambda x: [x @ x - 1.0], lambda x: [2 * x], np.array([3.0, 4.0]))
    >>> np.round(res.x, 12), res.success
    (array([0.6, 0.8]), True)
    """
    tol = positive(tol, "tol")
    max_iter = integer(max_iter, "max_iter", minimum=0)
    for fun, name in ((residual, "residual"), (jacobian, "jacobian"), (retract, "retract")):
        if not callable(fun) and (fun is not None or name != "retract"):
            raise TypeError(f"`{name}` must be a callable of the state x, got "
                            f"{type(fun).__name__}")
    retract = retract or (lambda x, d: x + d)
    x = np.array(finite_array(x, "x"), dtype=float)
    if x.ndim != 1:
        raise ValueError(f"`x` must be a state of shape (k,), got shape {x.shape}")
    phi = np.atleast_1d(np.asarray(residual(x), float)).reshape(-1)
    it = 0
    while np.linalg.norm(phi) > tol and it < max_iter:
        J = np.atleast_2d(np.asarray(jacobian(x), float))
        W = np.eye(J.shape[1]) if weight is None else weight
        x = retract(x, constrained_accelerations(W, np.zeros(J.shape[1]), J, phi).vdot)
        phi = np.atleast_1d(np.asarray(residual(x), float)).reshape(-1)
        it += 1
    err = float(np.linalg.norm(phi))
    return Projection(x, err, it, err <= tol)
