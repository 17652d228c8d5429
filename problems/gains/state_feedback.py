"""Full-state feedback gains of a linear plant by multi-scenario collocation (LQR by NLP).

`state_feedback_gains` designs ``u = -K x`` for ``x' = A x + B u`` by minimizing the summed
quadratic cost ``sum_k integral_0^T (x^T Q x + u^T R u) dt`` of the closed loop
``x' = (A - B K) x`` from several initial states ``x_k(0)`` at once, every entry of ``K``
a free parameter shared by the scenarios (`ocp.scenario_problem`). It never solves a
Riccati equation: the comparison with ``control.lqr`` in the result's ``verification`` is
an independent check.

Why it reproduces LQR: for a stabilizing ``K`` the infinite-horizon cost of one initial
state is ``x0^T P_K x0`` with ``P_K`` the closed loop's Lyapunov matrix, and the LQR gain
minimizes ``P_K`` in the matrix sense, so it minimizes ``trace(P_K X0 X0^T)`` for *every*
set of initial states. When the columns of ``X0`` span ``R^n`` that minimizer is unique
(= LQR). Otherwise ``K`` is determined only on the states the optimal trajectories visit:
all of ``R^n`` for a generic initial state, a subspace when the initial states lie in an
invariant subspace of the closed loop -- so it is a warning, ``K`` need not be unique. On a
finite horizon ``T`` the truncated tail ``x(T)^T P x(T)`` is of order
``exp(-2 T / tau)`` (``tau`` the slowest closed-loop time constant), so ``T`` should be
many time constants (a warning below ``HORIZON_RATIO_MIN``); the remaining difference is the
collocation error.
"""
from __future__ import annotations

import time
from typing import Mapping

import casadi as ca
import numpy as np

from appdyn.config import param
from appdyn import ocp
from appdyn.dynamics import cache
from appdyn.dynamics.model import Model
from appdyn.dynamics.validate import finite_array, positive

from appdyn.ocp import status as _status

from .result import STATUS_UNSTABLE, GainDesign

__all__ = ["state_feedback_gains", "linear_system", "default_initial_gain", "HORIZON_RATIO_MIN", "STATUS_SHORT_HORIZON",
           "STATUS_NOT_SPANNING"]

#: a horizon shorter than this many slowest closed-loop time constants draws a warning
HORIZON_RATIO_MIN = 10.0
#: status 120 (``success`` stays True; `ocp.status`): the horizon is shorter than
#: ``HORIZON_RATIO_MIN`` time constants of the designed loop, so ``K`` is a finite-horizon
#: compromise, not the LQR gain
STATUS_SHORT_HORIZON = _status.STATUS_SHORT_HORIZON
#: status 121 (``success`` stays True): the initial states do not span ``R^n``; ``K`` need
#: not be unique (module docstring)
STATUS_NOT_SPANNING = _status.STATUS_NOT_SPANNING

_DEFAULT_IPOPT = {"tol": 1e-10}


# --------------------------------------------------------------------------- input checks
def _matrix(value, name: str) -> np.ndarray:
    """A finite 2-D array (a scalar as 1 x 1) (`dynamics.validate.finite_array`)."""
    a = finite_array(value, name)
    if a.ndim == 0:
        a = a.reshape(1, 1)
    if a.ndim != 2:
        raise ValueError(f"`{name}` must be a 2-D array, got shape {a.shape}")
    return a


def _check_plant(A, B, Q, R, initial_states):
    A, B, Q, R = (_matrix(v, n) for v, n in ((A, "A"), (B, "B"), (Q, "Q"), (R, "R")))
    n = A.shape[0]
    if A.shape != (n, n) or n < 1:
        raise ValueError(f"`A` must be square (n, n), got shape {A.shape}")
    if B.shape[0] != n or B.shape[1] < 1:
        raise ValueError(f"`B` must have shape ({n}, nu) with nu >= 1, got {B.shape}")
    nu = B.shape[1]
    if Q.shape != (n, n):
        raise ValueError(f"`Q` must have shape ({n}, {n}), got {Q.shape}")
    if R.shape != (nu, nu):
        raise ValueError(f"`R` must have shape ({nu}, {nu}), got {R.shape}")
    for M, name, definite in ((Q, "Q", False), (R, "R", True)):
        scale = max(1.0, float(np.max(np.abs(M))))
        if not np.allclose(M, M.T, rtol=0, atol=1e-12 * scale):
            raise ValueError(f"`{name}` must be symmetric")
        lam = np.linalg.eigvalsh(0.5 * (M + M.T))
        if definite and not lam[0] > 1e-12 * scale:
            raise ValueError(f"`{name}` must be positive definite, smallest eigenvalue {lam[0]:.3g}")
        if not definite and lam[0] < -1e-12 * scale:
            raise ValueError(f"`{name}` must be positive semidefinite, smallest eigenvalue {lam[0]:.3g}")
    X0 = _matrix(initial_states, "initial_states")
    if X0.shape[0] != n or X0.shape[1] < 2:
        raise ValueError(f"`initial_states` must have shape ({n}, m) with m >= 2 initial states "
                         f"as columns, got {X0.shape}")
    if np.any(np.all(X0 == 0, axis=0)):
        raise ValueError("`initial_states` has a zero column (an initial state at the origin "
                         "costs nothing and determines nothing)")
    return A, B, Q, R, X0


def _check_gain_matrix(K, nu: int, n: int, name: str) -> np.ndarray:
    K = _matrix(K, name)
    if K.shape != (nu, n):
        raise ValueError(f"`{name}` must have shape ({nu}, {n}), got {K.shape}")
    return K


def _gain_bounds(value, nu: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    if value is None:
        return np.full((nu, n), -np.inf), np.full((nu, n), np.inf)
    try:
        lo, hi = value
        lo = np.broadcast_to(np.array(lo, dtype=float), (nu, n)).copy()
        hi = np.broadcast_to(np.array(hi, dtype=float), (nu, n)).copy()
    except (TypeError, ValueError):
        raise ValueError(f"`K_bounds` must be (lower, upper), each a number or an array ({nu}, {n}), "
                         f"got {value!r}") from None
    if np.any(np.isnan(lo)) or np.any(np.isnan(hi)) or np.any(lo >= hi):
        raise ValueError("`K_bounds` must have lower < upper for every entry (inf allowed)")
    return lo, hi


# ----------------------------------------------------------------------------- the design
def _names(nu: int, n: int) -> list[str]:
    return [f"K[{i},{j}]" for i in range(nu) for j in range(n)]


@cache.constructs
def _closed_loop(A, B) -> Model:
    """``x' = (A - B K) x`` with the entries of ``K`` (row-major) as parameters (SX)."""
    n, nu = B.shape
    x, k = ca.SX.sym("x", n), ca.SX.sym("k", nu * n)
    K = ca.reshape(k, n, nu).T  # row-major parameters -> K (nu, n)
    xdot = ca.mtimes(ca.DM(A), x) - ca.mtimes(ca.DM(B), ca.mtimes(K, x))
    f = ca.Function("state_feedback_loop", [x, ca.SX.sym("u", 0), k], [xdot],
                    ["x", "u", "p"], ["xdot"])
    return Model(f, tuple(f"x{i + 1}" for i in range(n)), (), tuple(_names(nu, n)),
                 p_default=np.zeros(nu * n), name="state_feedback_loop")


def default_initial_gain(A, B, Q, R) -> np.ndarray:
    """The default starting gain of `state_feedback_gains`: a pole placement.

    Poles ``-w (1 + 0.25 i)``, ``i = 0 .. n-1`` (real, distinct), with
    ``w = max(rho(A), (|Q|_2 |B|_2^2 / lambda_min(R))^(1/(2n)), 1e-3)``: the spectral radius of
    the plant or the bandwidth of the LQR of a chain of ``n`` integrators with those weights
    (Butterworth radius ``(q/r)^(1/2n)``), whichever is faster -- the right order of
    magnitude, stabilizing, and found without a Riccati equation. Falls back to ``K = 0``
    when the pair ``(A, B)`` cannot be placed (not controllable).

    Returns
    -------
    ndarray, shape (nu, n)
    """
    n, nu = B.shape
    rho = float(np.max(np.abs(np.linalg.eigvals(A))))
    band = (np.linalg.norm(Q, 2) * np.linalg.norm(B, 2) ** 2 / np.linalg.eigvalsh(R)[0]) ** (0.5 / n)
    w = max(rho, float(band), 1e-3)
    poles = -w * (1.0 + 0.25 * np.arange(n))
    from scipy.signal import place_poles  # a heavy import, only here

    try:
        K = np.asarray(place_poles(A, B, poles).gain_matrix, dtype=float)
    except Exception:  # noqa: BLE001 -- uncontrollable pair, numerical failure: no placement
        return np.zeros((nu, n))
    return K if np.all(np.isfinite(K)) else np.zeros((nu, n))


def _guess(A, B, K0, X0, horizon: float, samples: int) -> dict:
    """The closed loop under ``K0`` from every initial state, exactly (matrix exponential)."""
    t = np.linspace(0.0, horizon, samples)
    from scipy.linalg import expm  # a heavy import, only here

    step = expm((A - B @ K0) * (t[1] - t[0]))
    x = np.empty((X0.shape[0], samples, X0.shape[1]))
    x[:, 0, :] = X0
    for i in range(1, samples):
        x[:, i, :] = step @ x[:, i - 1, :]
    big = x.transpose(2, 0, 1).reshape(-1, samples)  # scenario-major rows, as ocp.stack
    if not np.all(np.abs(big) <= 1e3 * np.max(np.abs(X0))):  # K0 not stabilizing: hold x0
        big = np.repeat(X0.reshape(-1, 1, order="F"), samples, 1)
    return {"t": t, "x": big, "p": K0.reshape(-1)}


def _lqr_reference(A, B, Q, R, K) -> dict:
    """``control.lqr`` and the relative differences of ``K`` from it (None if lqr fails)."""
    try:
        import control
        K_lqr, P, _ = control.lqr(A, B, Q, R)
    except Exception as exc:  # noqa: BLE001 -- not stabilizable/detectable: no reference
        return {"K_lqr": None, "lqr_relative_difference": None, "lqr_max_relative_difference": None,
                "lqr_note": f"control.lqr failed: {exc}"}
    K_lqr = np.asarray(K_lqr, dtype=float)
    scale = np.linalg.norm(K_lqr)
    nonzero = np.abs(K_lqr) > 1e-12 * max(scale, 1e-300)
    rel = np.abs(K - K_lqr)[nonzero] / np.abs(K_lqr)[nonzero]
    return {"K_lqr": K_lqr, "P_lqr": np.asarray(P, dtype=float),
            "lqr_relative_difference": float(np.linalg.norm(K - K_lqr) / scale) if scale > 0 else None,
            "lqr_max_relative_difference": float(np.max(rel)) if rel.size else None}


def linear_system(sys, name: str = "sys") -> tuple[np.ndarray, np.ndarray]:
    """``(A, B)`` of a continuous-time linear system given as a python-control ``StateSpace``
    (or any object with matrices ``A`` and ``B``), as python-control's ``lqr(sys, Q, R)``
    takes it.

    Raises
    ------
    ValueError
        If ``sys`` is a discrete-time system (``dt`` not 0/None).

    Examples
    --------
    >>> import control
    >>> from appdyn.problems.gains.state_feedback import linear_system
    >>> A, B = linear_system(control.ss([[0, 1], [0, 0]], [[0], [1]], [[1, 0]], [[0]]))
    >>> A.shape, B.shape
    ((2, 2), (2, 1))
    """
    dt = getattr(sys, "dt", 0)
    if dt is True or (dt is not None and dt != 0):
        raise ValueError(f"`{name}` must be a continuous-time system (dt = 0), got dt = {dt}")
    return np.asarray(sys.A, dtype=float), np.asarray(sys.B, dtype=float)


def _is_system(value) -> bool:
    return hasattr(value, "A") and hasattr(value, "B") and not isinstance(value, np.ndarray)


def state_feedback_gains(A, B, Q, R, initial_states, horizon=None, *, N: int | None = None,
                         transcription="radau", ipopt_options: Mapping | None = None,
                         K0=None, K_bounds=None) -> tuple[np.ndarray, GainDesign]:
    """Full-state feedback ``u = -K x`` minimizing a quadratic cost summed over initial states.

    Minimizes ``sum_k integral_0^horizon (x^T Q x + u^T R u) dt`` over the closed loop
    ``x' = (A - B K) x`` from each column ``x_k(0)`` of ``initial_states``, with every entry
    of ``K`` a free parameter shared by all scenarios (`ocp.scenario_problem`, solved by
    `ocp.solve`). Over a horizon of many closed-loop time constants and from initial states
    spanning ``R^n`` the optimum is the LQR gain (module docstring); the design itself never
    solves a Riccati equation and never calls ``control.lqr``, which is only the check in
    ``verification``.

    The plant may also be given as one python-control ``StateSpace`` (continuous time), as
    ``control.lqr`` takes it: ``state_feedback_gains(sys, Q, R, initial_states, horizon)``.

    Parameters
    ----------
    A : array_like, shape (n, n) [1/s], or control.StateSpace
        Plant matrix (or the whole plant: the other arguments then shift left by one).
    B : array_like, shape (n, nu)
        Input matrix [state units / (s input unit)].
    Q : array_like, shape (n, n)
        State weight, symmetric positive semidefinite.
    R : array_like, shape (nu, nu)
        Input weight, symmetric positive definite.
    initial_states : array_like, shape (n, m), m >= 2
        The initial conditions (columns), none zero; they should span ``R^n`` (else a warning:
        ``K`` is then not unique).
    horizon : float [s]
        Required (its default only lets the ``StateSpace`` form shift the arguments). The
        cost's horizon; should be at least ``HORIZON_RATIO_MIN`` (10) times the slowest
        time constant of the designed loop (else a warning).
    N : int, optional
        Collocation intervals (default ``appdyn.config`` ``problems.feedback_N``, 80; uniform
        mesh, Radau degree 3 by default).
    transcription : str, optional
        Any of ``ocp.TRANSCRIPTIONS`` (default ``'radau'``).
    ipopt_options : mapping, optional
        IPOPT options; default ``{'tol': 1e-10}`` (the gains are wanted to many digits),
        merged with what is given.
    K0 : array_like, shape (nu, n), optional
        Initial guess of the gains; default `default_initial_gain` (a pole placement, no
        Riccati equation). The state guess is the closed loop under ``K0`` (exact, by the
        matrix exponential).
    K_bounds : (lower, upper), optional
        Bounds of the gain entries, each a number or an array (nu, n); default unbounded.

    Returns
    -------
    K : ndarray, shape (nu, n)
        The designed gains (``u = -K x``) [input units / state units].
    result : GainDesign
        ``gains`` by name ``'K[i,j]'`` (0-based), ``cost`` (the summed collocated cost),
        ``scenarios`` (per initial state ``'t'`` (p,) [s], ``'x'`` (n, p), ``'u'`` (nu, p),
        ``'peak'``: ``{'|x|', '|u|'}``), ``solution`` (the `ocp.Solution`) and
        ``verification``:

        * ``'poles'`` (n,) complex [1/s]: eigenvalues of ``A - B K``; ``'stable'``;
        * ``'slowest_time_constant'`` [s] ``= 1 / min(-Re(pole))`` (inf if not stable);
        * ``'horizon_ratio'``: ``horizon / slowest_time_constant``;
        * ``'spanning'``, ``'initial_state_rank'``: rank of ``initial_states``;
        * ``'K_lqr'`` (nu, n), ``'P_lqr'`` (n, n): ``control.lqr(A, B, Q, R)``;
          ``'lqr_relative_difference'`` ``= |K - K_lqr|_F / |K_lqr|_F``,
          ``'lqr_max_relative_difference'`` ``= max_ij |K - K_lqr|_ij / |K_lqr|_ij`` (over
          nonzero entries of ``K_lqr``); ``None`` (and ``'lqr_note'``) when lqr fails;
        * ``'lqr_cost'``: ``sum_k x_k^T P_lqr x_k``, the infinite-horizon optimum;
        * ``'warnings'``: list of the warnings' statuses; ``'K0'``: the initial guess;
          ``'design_time'`` [s].

        ``success`` only if the NLP is verified (`ocp.solve`) and the closed loop is stable
        (else ``status`` is the solver's or `STATUS_UNSTABLE`). A successful design may carry
        a warning: ``status`` `STATUS_NOT_SPANNING` (initial states not spanning ``R^n``) or
        `STATUS_SHORT_HORIZON` (``horizon_ratio < HORIZON_RATIO_MIN``), the first of those
        that applies, and the message says so (all applicable in ``'warnings'``).

    Raises
    ------
    TypeError
        If a matrix is not an array of numbers, or ``horizon`` not a number.
    ValueError
        Naming the argument: shapes (``A`` square, ``B`` (n, nu), ``Q`` (n, n), ``R`` (nu, nu),
        ``initial_states`` (n, m >= 2) without zero columns, ``K0`` (nu, n)), non-finite
        entries, ``Q`` not symmetric PSD, ``R`` not symmetric PD, ``horizon`` not > 0,
        ``K_bounds``, and the errors of `ocp.solve` (``N``, ``transcription``,
        ``ipopt_options``).

    Examples
    --------
    The double integrator with ``Q = I``, ``R = 1`` (LQR gain ``[1, sqrt(3)]``):

    >>> import numpy as np
    >>> from appdyn.problems.gains.state_feedback import state_feedback_gains
    >>> A, B = np.array([[0.0, 1.0], [0.0, 0.0]]), np.array([[0.0], [1.0]])
    >>> K, res = state_feedback_gains(A, B, np.eye(2), np.eye(1), np.eye(2), 20.0)
    >>> res.success, np.round(K, 4), res.verification["lqr_relative_difference"] < 1e-4
    (True, array([[1.    , 1.7321]]), True)
    """
    N = param("problems.feedback_N", N)
    t_start = time.perf_counter()
    if _is_system(A):  # (sys, Q, R, initial_states, horizon)
        if horizon is not None:
            raise TypeError("with a StateSpace the arguments are (sys, Q, R, initial_states, "
                            "horizon): one too many given")
        (A, B), Q, R, initial_states, horizon = linear_system(A), B, Q, R, initial_states
    A, B, Q, R, X0 = _check_plant(A, B, Q, R, initial_states)
    if horizon is None:
        raise TypeError("`horizon` is required: state_feedback_gains(A, B, Q, R, "
                        "initial_states, horizon) or (sys, Q, R, initial_states, horizon)")
    horizon = positive(horizon, "horizon")
    n, nu = B.shape
    K0 = default_initial_gain(A, B, Q, R) if K0 is None else _check_gain_matrix(K0, nu, n, "K0")
    lo, hi = _gain_bounds(K_bounds, nu, n)
    K0 = np.clip(K0, lo, hi)
    names = _names(nu, n)
    loop = _closed_loop(A, B)
    Qd, Rd = ca.DM(Q), ca.DM(R)

    def cost(x, u, p):
        K = ca.reshape(p, n, nu).T
        v = ca.mtimes(K, x)
        return ca.mtimes([x.T, Qd, x]) + ca.mtimes([v.T, Rd, v])

    problem = ocp.scenario_problem(
        loop, X0, T=horizon, lagrange=cost, p=K0.reshape(-1),
        p_bounds={name: (float(a), float(b)) for name, a, b in zip(names, lo.ravel(), hi.ravel())},
        name="state_feedback_gains")
    opts = {**_DEFAULT_IPOPT, **dict(ipopt_options or {})}
    guess = _guess(A, B, K0, X0, horizon, 4 * int(N) + 1 if isinstance(N, (int, np.integer)) else 201)
    sol = ocp.solve(problem, transcription=transcription, N=N, ipopt_options=opts, guess=guess)
    K = np.asarray(sol.p, dtype=float).reshape(nu, n)

    poles = np.linalg.eigvals(A - B @ K)
    stable = bool(np.all(poles.real < 0))
    tau = float(1.0 / np.min(-poles.real)) if stable else float("inf")
    ratio = horizon / tau
    rank = int(np.linalg.matrix_rank(X0))
    ver = {"poles": poles, "stable": stable, "slowest_time_constant": tau, "horizon_ratio": ratio,
           "initial_state_rank": rank, "spanning": rank == n, "K0": K0}
    ver.update(_lqr_reference(A, B, Q, R, K))
    if ver.get("P_lqr") is not None:
        ver["lqr_cost"] = float(np.einsum("ik,ij,jk->", X0, ver["P_lqr"], X0))

    warnings, notes = [], []
    if rank < n:
        warnings.append(STATUS_NOT_SPANNING)
        notes.append(f"the {X0.shape[1]} initial states span only {rank} of {n} dimensions: "
                     "K need not be unique (it is determined only on the states the optimal "
                     "trajectories visit)")
    if stable and ratio < HORIZON_RATIO_MIN:
        warnings.append(STATUS_SHORT_HORIZON)
        notes.append(f"the horizon {horizon:g} s is only {ratio:.3g} slowest closed-loop time "
                     f"constants ({tau:.4g} s), less than {HORIZON_RATIO_MIN:g}: K is a "
                     "finite-horizon compromise, not the LQR gain")
    ver["warnings"] = warnings

    if not sol.success:
        success, status = False, sol.status
        message = f"gain design failed: {sol.message}"
    elif not stable:
        success, status = False, STATUS_UNSTABLE
        message = (f"the NLP converged but A - B K is not stable (largest real part of a pole "
                   f"{np.max(poles.real):.4g} 1/s)")
    else:
        success = True
        status = warnings[0] if warnings else sol.status
        diff = ver.get("lqr_relative_difference")
        message = (f"designed K: closed loop stable, slowest time constant {tau:.4g} s "
                   f"(horizon {ratio:.3g} of them)"
                   + ("" if diff is None else f"; |K - K_lqr| / |K_lqr| = {diff:.2e}"))
    if notes:
        message += "; WARNING: " + "; ".join(notes)

    xs = ocp.unstack(sol.x, X0.shape[1])
    scenarios = []
    for k in range(X0.shape[1]):
        x = xs[:, :, k]
        u = -K @ x
        scenarios.append({"t": np.asarray(sol.t), "x": x, "u": u,
                          "peak": {"|x|": float(np.max(np.abs(x))), "|u|": float(np.max(np.abs(u)))}})
    ver["design_time"] = time.perf_counter() - t_start
    result = GainDesign(success=success, status=status, message=message,
                        gains={name: float(v) for name, v in zip(names, K.ravel())},
                        units={name: "-" for name in names}, cost=float(sol.cost),
                        scenarios=scenarios, verification=ver, solution=sol)
    return K, result
