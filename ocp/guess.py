"""Initial guesses on the nodes of a transcription.

A guess is turned into functions of normalized time ``tau in [0, 1]`` (``t = t0 + T tau``)
for the states and controls, plus values of ``T`` and of the parameters, and then sampled at
the state and control nodes of the transcription on the mesh (`NodeGuess`).

Sources (argument ``guess`` of `ocp.solve`):

* ``None``: states linear between the given boundary values (a component given at one end
  only is held constant; one given at neither end sits at the middle of its finite bounds,
  or at 0 clipped into them); a model's quaternion by SLERP from the initial quaternion to
  ``q_final`` (the sign of ``q_final`` nearer the initial quaternion, i.e. the shorter
  rotation) and normalized; controls 0 clipped into their bounds; parameters ``problem.p``;
  a free ``T`` at the middle of ``[T_min, T_max]`` (``max(1, 2 T_min)`` if ``T_max = inf``)
  -- unless a simulation finds a better horizon (below).
* a `Solution` (warm start): its dense solution (`Solution.sample`) stretched to the new
  horizon in normalized time, its ``T`` and parameters.
* a mapping with any of the keys ``'t'`` (times [s], shape (m,)), ``'x'``, ``'u'``,
  ``'T'`` and ``'p'`` (array (np,) or mapping by name); missing entries fall back to the
  default. ``'x'`` and ``'u'`` are arrays (nx, m)/(nu, m) on ``t``, linearly
  interpolated; constant vectors; callables ``fun(t) -> (nx,)``/``(nu,)``; or mappings by
  state/control name to a number, an array (m,) on ``t`` or a callable ``fun(t)`` (a
  float), the components not named keeping the default (``{'u': {'CL': 0.8}}``). Without
  ``'t'``, arrays are taken as uniformly spaced over ``[t0, t0 + T]``.

Free horizon by simulation. For a free-time problem whose guess is ``None`` or a mapping
without ``'T'``, ``'t'`` and ``'x'`` (and with ``'u'`` absent, constant, or callable: not
samples over the horizon), the model is simulated from ``x_initial`` under the guessed
control (the default control, or ``guess['u']``) by cheap fixed-step RK4, up to ``T_max``
(or 100 times the default ``T`` when ``T_max`` is infinite, marching on up to 10 times as
far while the state keeps nearing ``x_final``), and ``T`` is the time in ``[T_min, T_max]``
at which the state comes closest to the given components of ``x_final`` (each measured
relative to a typical magnitude: the distance between its boundary values); the simulated
trajectory is then the state guess. The default is kept, silently, when ``x_initial`` is
not fully given, no component of ``x_final`` is given, the simulation fails or leaves
``x_bounds`` at once, or its best state is not at least halfway from ``x_initial`` to
``x_final`` (e.g. a system at rest under a zero control). `NodeGuess.source` says when
it was used. Details and cost in `ocp.horizon`.

Every guess is clipped into the bounds; fixed boundary values are imposed as given.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Mapping

import numpy as np

from appdyn.dynamics.validate.base import real_array

from .attitude import quaternion_path, slerp  # slerp: re-exported (compatibility)
from .horizon import default_T as _default_T, simulate_control as _simulate
from .horizon import simulated_horizon as _simulated_horizon
from .problem import Problem

__all__ = ["NodeGuess", "initial_guess", "slerp", "guess_from_simulation"]

_KEYS = ("t", "x", "u", "T", "p")


@dataclass(frozen=True)
class NodeGuess:
    """A guess sampled on the nodes of a transcription.

    Attributes
    ----------
    X : ndarray, shape (nx, n_x)
        States at the state nodes.
    U : ndarray, shape (nu, n_u)
        Controls at the control nodes.
    Xu : ndarray, shape (nx, n_u)
        States at the control nodes (for constraint scaling).
    p : ndarray, shape (np,)
        Full parameter vector.
    T : float [s]
    source : str
        How the states and ``T`` were made when not given: ``""`` (as given, or the
        default interpolation of the boundary values) or, when a free ``T`` came from a
        simulation, a sentence for messages such as ``"states simulated from x_initial
        under the default control (0 clipped into the bounds) up to T = 4.5 s, the time
        closest to x_final"``.
    """

    X: np.ndarray
    U: np.ndarray
    Xu: np.ndarray
    p: np.ndarray
    T: float
    source: str = ""


def _clip(v: np.ndarray, bounds: np.ndarray) -> np.ndarray:
    return np.clip(v, bounds[0][:, None], bounds[1][:, None])


def _default_state(problem) -> Callable:
    model = problem.model
    a, b = problem.x_initial, problem.x_final
    lo, hi = problem.x_bounds
    start, end = a.copy(), b.copy()
    for i in range(model.nx):
        if np.isnan(a[i]) and np.isnan(b[i]):
            if np.isfinite(lo[i]) and np.isfinite(hi[i]):
                mid = 0.5 * (lo[i] + hi[i])
            else:
                mid = float(np.clip(0.0, lo[i], hi[i]))
            start[i] = end[i] = mid
        elif np.isnan(a[i]):
            start[i] = b[i]
        elif np.isnan(b[i]):
            end[i] = a[i]
    quat = quaternion_path(problem)  # ocp.attitude: SLERP for attitude models

    def x_fun(tau):
        tau = np.asarray(tau, float)
        x = start[:, None] + tau[None, :] * (end - start)[:, None]
        if quat is not None:
            x[quat[0]] = quat[1](tau)
        return x

    return x_fun


def _default_control(problem) -> Callable:
    lo, hi = problem.u_bounds
    u0 = np.clip(np.zeros(problem.model.nu), lo, hi)
    return lambda tau: np.repeat(u0[:, None], np.size(tau), axis=1)



def _trajectory(value, n: int, key: str, t_grid, t0: float, T: float) -> Callable:
    """A guess entry as a function of normalized time."""
    if callable(value):
        def fun(tau):
            cols = []
            for ti in t0 + T * np.asarray(tau, float):
                v = np.asarray(value(float(ti)), dtype=float).reshape(-1)
                if v.size != n:
                    raise ValueError(f"`guess['{key}']` must return shape ({n},), got {v.shape} at t = {ti}")
                cols.append(v)
            return np.stack(cols, axis=1) if cols else np.zeros((n, 0))
        return fun
    try:
        a = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"`guess['{key}']` must be an array or a callable: {exc}") from None
    if a.ndim == 1 and a.size == n:
        return lambda tau: np.repeat(a[:, None], np.size(tau), axis=1)
    if a.ndim != 2 or a.shape[0] != n:
        raise ValueError(f"`guess['{key}']` must have shape ({n}, m), ({n},) or be a callable, got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"`guess['{key}']` must be finite")
    if t_grid is None:
        tt = np.linspace(0.0, 1.0, a.shape[1]) if a.shape[1] > 1 else np.zeros(1)
    else:
        if t_grid.size != a.shape[1]:
            raise ValueError(f"`guess['{key}']` has {a.shape[1]} columns but `guess['t']` has {t_grid.size} times")
        tt = (t_grid - t0) / T
    if a.shape[1] == 1:
        return lambda tau: np.repeat(a, np.size(tau), axis=1)
    return lambda tau: np.stack([np.interp(tau, tt, row) for row in a])


def _entry(value, names: tuple[str, ...], key: str, t_grid, t0: float, T: float,
           default: Callable) -> Callable:
    """``guess['x']`` or ``guess['u']`` as a function of normalized time: a whole trajectory
    (`_trajectory`), or a mapping by component name whose unnamed rows come from
    ``default``."""
    n = len(names)
    if not isinstance(value, Mapping):
        return _trajectory(value, n, key, t_grid, t0, T)
    what = "state" if key == "x" else "control"
    rows = {}
    for name, v in value.items():
        if name not in names:
            raise ValueError(f"`guess['{key}']` names unknown {what} {name!r}; the {what}s are "
                             f"{names}")
        label = f"{key}']['{name}"  # -> `guess['x']['h']` in messages
        if not callable(v):
            try:
                v = np.array(v, dtype=float)
            except (TypeError, ValueError) as exc:
                raise ValueError(f"`guess['{label}']` must be a number, an array on 't' or a "
                                 f"callable: {exc}") from None
            if v.ndim == 0 or v.size == 1:
                v = v.reshape(1)
            elif v.ndim == 1:
                v = v.reshape(1, -1)
            else:
                raise ValueError(f"`guess['{label}']` must be a number, an array of shape (m,) "
                                 f"on 't' or a callable, got shape {v.shape}")
        rows[names.index(name)] = _trajectory(v, 1, label, t_grid, t0, T)

    def fun(tau):
        out = np.array(default(tau), dtype=float)
        for i, row in rows.items():
            out[i] = row(tau)[0]
        return out

    return fun


def _depends_on_T(value, by_name: bool = False) -> bool:
    """Whether a guess entry is samples spread over the horizon (read only once ``T`` is
    known), rather than a constant or a function of time."""
    if value is None or callable(value):
        return False
    if isinstance(value, Mapping):
        return any(_depends_on_T(v, True) for v in value.values())
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return False  # reported when the entry is read
    return a.size > 1 if by_name else (a.ndim == 2 and a.shape[1] > 1)


def _guess_p(problem, guess: Mapping) -> np.ndarray:
    model = problem.model
    p = np.array(problem.p)
    if "p" in guess:
        gp = guess["p"]
        if isinstance(gp, Mapping):
            for key, v in gp.items():
                if key not in model.params:
                    raise ValueError(f"`guess['p']` names unknown parameter {key!r}")
                p[model.params.index(key)] = float(v)
        else:
            gp = np.asarray(gp, dtype=float).reshape(-1)
            if gp.size != model.np:
                raise ValueError(f"`guess['p']` must have shape ({model.np},), got {gp.shape}")
            free = problem.free_params
            p[free] = gp[free]
    return p


def _from_mapping(problem, guess: Mapping):
    unknown = set(guess) - set(_KEYS)
    if unknown:
        raise ValueError(f"`guess` has unknown keys {sorted(unknown)}; allowed {_KEYS}")
    model = problem.model
    T = _default_T(problem)
    if "T" in guess:
        T = float(guess["T"])
        if not (math.isfinite(T) and T > 0):
            raise ValueError(f"`guess['T']` must be finite and > 0, got {guess['T']!r}")
        if not problem.free_time and T != problem.T:
            raise ValueError(f"`guess['T']` = {T} differs from the fixed horizon T = {problem.T}")
    t_grid = None
    if "t" in guess:
        t_grid = np.asarray(guess["t"], dtype=float).reshape(-1)
        if t_grid.size < 2 or np.any(np.diff(t_grid) <= 0) or not np.all(np.isfinite(t_grid)):
            raise ValueError("`guess['t']` must be a strictly increasing array of at least 2 times")
    t0 = problem.t0
    p = _guess_p(problem, guess)
    x_fun = _default_state(problem)
    source = ""
    if (problem.free_time and not {"T", "t", "x"} & set(guess)
            and not _depends_on_T(guess.get("u"))):
        # no horizon guessed: the one at which a simulation under the guessed control comes
        # closest to the final state (None: keep the default)
        u_of_t = _entry(guess["u"], model.controls, "u", None, t0, 1.0,
                        _default_control(problem)) if "u" in guess else _default_control(problem)
        control = ("guess['u']" if "u" in guess
                   else "the default control (0 clipped into the bounds)")
        found = _simulated_horizon(problem, lambda t: u_of_t(np.asarray(t) - t0), p,
                                   control=control)
        if found is not None:
            T, x_fun, source = found
    if "x" in guess:
        x_fun = _entry(guess["x"], model.states, "x", t_grid, t0, T, x_fun)
    u_fun = _default_control(problem)
    if "u" in guess:
        u_fun = _entry(guess["u"], model.controls, "u", t_grid, t0, T, u_fun)
    return x_fun, u_fun, p, T, source


def _from_solution(problem, sol):
    model, other = problem.model, sol.problem.model
    if (other.nx, other.nu, other.np) != (model.nx, model.nu, model.np):
        raise ValueError(
            f"`guess` Solution has (nx, nu, np) = {(other.nx, other.nu, other.np)}, the problem "
            f"{(model.nx, model.nu, model.np)}"
        )
    T = float(sol.T) if problem.free_time else problem.T

    def x_fun(tau):
        return sol.sample(sol.t0 + np.asarray(tau, float) * sol.T)[0]

    def u_fun(tau):
        return sol.sample(sol.t0 + np.asarray(tau, float) * sol.T)[1]

    p = np.array(problem.p)
    free = problem.free_params
    p[free] = np.asarray(sol.p)[free]
    return x_fun, u_fun, p, T




def initial_guess(problem, transcription, mesh, *, guess=None) -> NodeGuess:
    """Sample a guess on the nodes of ``transcription`` on ``mesh``.

    Parameters
    ----------
    problem : ocp.Problem
    transcription : ocp.Transcription
    mesh : ocp.Mesh
    guess : None, Solution or mapping
        See the module docstring.

    Returns
    -------
    NodeGuess

    Raises
    ------
    ValueError
        Naming ``guess`` (or its key) for a wrong type, shape or unknown key or name.
    """
    from .solution import Solution

    source = ""
    if guess is None:
        x_fun, u_fun, p, T, source = _from_mapping(problem, {})
    elif isinstance(guess, Solution):
        x_fun, u_fun, p, T = _from_solution(problem, guess)
    elif isinstance(guess, Mapping):
        x_fun, u_fun, p, T, source = _from_mapping(problem, guess)
    else:
        raise ValueError(f"`guess` must be None, a Solution or a mapping, got {type(guess).__name__}")

    lo, hi = problem.T_bounds
    T = float(np.clip(T, max(lo, 1e-300), hi))
    p = np.clip(p, problem.p_bounds[0], problem.p_bounds[1])
    tau_x, tau_u = transcription.state_tau(mesh), transcription.control_tau(mesh)
    X = _clip(x_fun(tau_x), problem.x_bounds)
    Xu = _clip(x_fun(tau_u), problem.x_bounds)
    U = _clip(u_fun(tau_u), problem.u_bounds)
    for col, values in ((0, problem.x_initial), (-1, problem.x_final)):
        given = ~np.isnan(values)
        X[given, col] = values[given]
    if not (np.all(np.isfinite(X)) and np.all(np.isfinite(U)) and np.all(np.isfinite(Xu))):
        raise ValueError("`guess` produced non-finite values on the nodes")
    return NodeGuess(X=X, U=U, Xu=Xu, p=p, T=T, source=source)


def guess_from_simulation(problem, u, *, T=None, n=201, method="auto", rtol=1e-8,
                          atol=1e-10) -> dict:
    """A guess made by simulating the model from the problem's initial state.

    Parameters
    ----------
    problem : ocp.Problem
        Its initial state must be fully given (``x_initial`` without free components).
    u : array_like, shape (nu,) or (nu, n), or callable ``u(t) -> (nu,)``
        Control to apply (as accepted by `dynamics.simulate`); clipped into the bounds.
    T : float [s], optional
        Simulated horizon; default the fixed ``T``, or the middle of a free ``T`` range.
    n : int
        Number of output samples.
    method, rtol, atol : passed to `dynamics.simulate`

    Returns
    -------
    dict with keys ``t``, ``x`` (nx, n), ``u`` (nu, n), ``T`` — accepted by `ocp.solve`.

    Raises
    ------
    TypeError
        If ``problem`` is not an `ocp.Problem`, or an array ``u`` is not real numbers.
    ValueError
        If an array ``u`` has the wrong shape, the initial state is not fully given or the
        simulation fails.

    Examples
    --------
    >>> from appdyn import ocp
    >>> from appdyn.ocp.examples import min_time
    >>> fastest = min_time()  # x'' = u, |u| <= 1, from rest at 0 to rest at 1
    >>> guess = ocp.guess_from_simulation(fastest, lambda t: 1.0 if t < 1 else -1.0, T=2.0, n=21)
    >>> guess["x"].shape, guess["u"].shape, guess["T"]
    ((2, 21), (1, 21), 2.0)
    >>> sol = ocp.solve(fastest, N=10, guess=guess, control="constant")  # bang-bang
    >>> sol.success, round(sol.T, 6)
    (True, 2.0)
    """
    if not isinstance(problem, Problem):
        raise TypeError(f"`problem` must be an ocp.Problem, got {type(problem).__name__}")
    x0 = np.asarray(problem.x_initial, dtype=float)
    if np.any(np.isnan(x0)):
        free = [problem.model.states[i] for i in np.flatnonzero(np.isnan(x0))]
        raise ValueError(f"guess_from_simulation needs a fully given `x_initial`; free: {free}")
    T = _default_T(problem) if T is None else float(T)
    t = problem.t0 + np.linspace(0.0, T, int(n))
    nu = problem.model.nu
    if callable(u):
        uc = np.stack([np.asarray(u(tk), dtype=float).reshape(-1) for tk in t], 1).reshape(nu, -1)
    else:
        ua = real_array(u, "u")
        try:
            uc = np.broadcast_to(ua.reshape(-1, 1) if ua.ndim <= 1 else ua, (nu, t.size)).copy()
        except ValueError:
            raise ValueError(f"`u` must have shape ({nu},) or ({nu}, {t.size}), "
                             f"got {ua.shape}") from None
    res, uc = _simulate(problem, uc, t, problem.p, method=method, rtol=rtol, atol=atol)
    if not res.success or not np.all(np.isfinite(res.x)):
        raise ValueError(f"the simulation for the guess failed: {res.message}")
    return dict(t=t, x=res.x, u=uc, T=T)
