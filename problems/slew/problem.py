"""The `ocp.Problem` of a slew, its closed-form eigenaxis time, and the initial guesses."""
from __future__ import annotations

import math
import warnings

import casadi as ca
import numpy as np

from appdyn.dynamics import cache, rigid_body
from appdyn.dynamics.attitude import quat_conj, quat_from_axis_angle, quat_mul, quat_normalize, rotation_angle
from appdyn.dynamics.rigid_body import check_inertia
from appdyn.dynamics.validate import positive, unit_vector
from appdyn.ocp import Constraint, Problem
from appdyn.ocp.attitude import slerp

from .targets import KeepOut, check_angle, check_u_max, targets, vector3

__all__ = ["slew_problem", "eigenaxis_time", "attitude_guess", "attitude_blocks", "rough_time",
           "is_rest_to_rest",
           "slew_angle", "inertia_of", "seeded_guesses"]


# --------------------------------------------------------------------------- problem
def slew_problem(inertia, *, objective, T=None, angle=None, axis=None, q0=None, qf=None,
                 u_max=1.0, norm_bound=False, w0=None, wf=None, keep_out=None,
                 T_max=None) -> Problem:
    """The `ocp.Problem` of a rigid-body slew (shared by `time_optimal` and `min_effort`).

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2]
    objective : {"time", "effort"}
        Minimum final time, or minimum ``1/2 integral |u|^2 dt`` [N^2 m^2 s] over fixed ``T``.
    T : float [s]
        Horizon for ``"effort"`` (ignored for ``"time"``)
    angle, axis, q0, qf : see module docstring; ``angle`` [rad], ``axis`` body frame
    u_max : float or array_like, shape (3,) [N m], or None (unbounded; ``"effort"`` only)
    norm_bound : bool
        Bound ``|u| <= u_max`` (scalar ``u_max``) instead of per axis
    w0, wf : array_like, shape (3,) [rad/s]
        End rates (default rest)
    keep_out : KeepOut, optional
    T_max : float [s], optional
        Upper bound of a free final time (default 20x eigenaxis);
        ignored for ``"effort"``, with a warning

    Returns
    -------
    ocp.Problem

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.problems import slew
    >>> pb = slew.slew_problem(np.eye(3), objective="effort", T=2.0, angle=0.1, axis=[1, 0, 0])
    >>> pb.model.nx, pb.model.nu, pb.T, pb.name
    (7, 3, 2.0, 'slew (effort)')
    """
    I = check_inertia(inertia)
    if not isinstance(objective, str):
        raise TypeError(f"`objective` must be 'time' or 'effort', got {type(objective).__name__}")
    if objective not in ("time", "effort"):
        raise ValueError(f"`objective` must be 'time' or 'effort', got {objective!r}")
    if objective == "time" and T is not None:
        warnings.warn("`T` is ignored for a time-optimal slew (the horizon is optimized; "
                      "bound it with `T_max`)", stacklevel=2)
    if objective == "effort" and T_max is not None:
        warnings.warn("`T_max` is ignored for a minimum-effort slew (its horizon `T` is fixed)",
                      stacklevel=2)
    q0, qf = targets(q0, qf, angle, axis)
    w0, wf = vector3(w0, "w0", [0, 0, 0]), vector3(wf, "wf", [0, 0, 0])
    if u_max is None:
        if objective == "time":
            raise ValueError("a time-optimal slew needs a torque bound `u_max`")
        u_lim = np.full(3, np.inf)
    else:
        u_lim = check_u_max(u_max)
    path = []
    if norm_bound:
        if u_max is None or np.ptp(u_lim) != 0:
            raise ValueError("`norm_bound=True` needs a scalar `u_max`")
        path.append(Constraint(_torque_norm(float(u_lim[0])), name="torque_norm"))
    if keep_out is not None:
        if not isinstance(keep_out, KeepOut):
            raise TypeError(f"`keep_out` must be a KeepOut, got {type(keep_out).__name__}")
        for qq, name in ((q0, "q0"), (qf, "target")):
            if keep_out.margin(qq) < 0:
                raise ValueError(f"the {name} attitude already violates the keep-out cone "
                                 f"(margin {keep_out.margin(qq):.3g})")
        path.append(Constraint(keep_out.function(), name="keep_out"))
    model = rigid_body(I)
    if objective == "time":
        T_ref = rough_time(I, q0, qf, u_lim)
        horizon = (0.0, float(T_max) if T_max is not None else 20.0 * T_ref)
        costs = dict(mayer=lambda xf, p, T: T)
    else:
        if T is None:
            raise ValueError("`T` must be a positive finite horizon [s], got None")
        horizon = positive(T, "T")
        costs = dict(lagrange=_effort())
    return Problem(
        model,
        T=horizon,
        x_initial=np.r_[q0, w0],
        x_final=np.r_[[np.nan] * 4, wf],
        u_bounds=(-u_lim, u_lim),
        q_final=qf,
        path=tuple(path),
        name=f"slew ({objective})",
        **costs,
    )


@cache.memoize
def _torque_norm(limit: float) -> ca.Function:
    """``g(x, u, p) = |u|^2 - limit^2``: the torque norm bound, built once per limit (in the
    one cache, under its construction lock: slews are stated in thread-pool tasks)."""
    x, u, p = ca.SX.sym("x", 7), ca.SX.sym("u", 3), ca.SX.sym("p", 0)
    return ca.Function("torque_norm", [x, u, p], [ca.sumsqr(u) - limit ** 2], ["x", "u", "p"],
                       ["g"])


@cache.memoize
def _effort() -> ca.Function:
    """``L(x, u, p) = |u|^2 / 2``: the minimum-effort running cost, built once (as
    `_torque_norm`)."""
    x, u, p = ca.SX.sym("x", 7), ca.SX.sym("u", 3), ca.SX.sym("p", 0)
    return ca.Function("effort", [x, u, p], [0.5 * ca.sumsqr(u)], ["x", "u", "p"], ["L"])


def eigenaxis_time(inertia, angle, axis, u_max=1.0) -> float:
    """Rest-to-rest bang-bang time about a fixed principal axis: ``2 sqrt(angle / alpha)``.

    ``alpha`` is the largest angular acceleration the per-axis bounds allow along the axis,
    ``min_i u_max_i / |(J e)_i|``. For ``J = E`` and ``|u_i| <= 1`` about a body axis by
    180 deg this is ``2 sqrt(pi) = 3.5449`` (Bilimoria & Wie's eigenaxis reference).

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2]
    angle : float [rad]
        Rotation angle; the maneuver takes the short way: ``angle`` is reduced to the
        equivalent rotation in [0, pi] (modulo 2 pi, and ``2 pi - a`` about the same axis
        for ``a > pi``; the sign of ``angle`` does not matter).
    axis : array_like, shape (3,)
        Non-zero, body frame (normalized here)
    u_max : float or array_like, shape (3,) [N m]

    Returns
    -------
    float [s]

    Raises
    ------
    ValueError
        If ``angle`` is not finite, ``axis`` is zero or not finite, or ``axis`` is not a
        principal axis of ``inertia`` (then the eigenaxis maneuver needs gyroscopic torque
        and has no such closed form).

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.problems import slew
    >>> round(slew.eigenaxis_time(np.eye(3), np.pi, [0, 0, 1]), 6)  # 2 sqrt(pi)
    3.544908
    >>> J = np.diag([2.0, 3.0, 4.0])  # alpha = 2 / 4 about the third axis
    >>> round(slew.eigenaxis_time(J, np.pi / 2, [0, 0, 1], u_max=2.0), 6)
    3.544908
    """
    I = check_inertia(inertia)
    angle = check_angle(angle)
    e = unit_vector(axis, "axis")
    Je = I @ e
    if np.linalg.norm(Je - (e @ Je) * e) > 1e-9 * np.linalg.norm(Je):
        raise ValueError(f"`axis` {e} is not a principal axis of `inertia`")
    u = check_u_max(u_max)
    alpha = np.min(u[np.abs(Je) > 0] / np.abs(Je[np.abs(Je) > 0]))
    a = math.fmod(abs(angle), 2.0 * math.pi)
    a = min(a, 2.0 * math.pi - a)  # the short way round
    return float(2.0 * math.sqrt(a / alpha))



def rough_time(I, q0, qf, u_lim, *, floor=1e-3):
    """Order-of-magnitude slew time: bang-bang about the error axis with the weakest axis
    (the angle taken as at least ``floor`` [rad])."""
    dq = quat_mul(qf, quat_conj(q0))
    angle = float(rotation_angle(dq))
    alpha = np.min(u_lim) / np.max(np.linalg.eigvalsh(I))
    return max(2.0 * math.sqrt(max(angle, floor) / alpha), 1e-6)


def attitude_blocks(model) -> tuple:
    """``(q, w)``: the slices of an attitude model's quaternion (4) and body rates (3) in
    ``x``, from ``model.attitude`` (a scene's hub: ``model.layout["hub"]``'s coordinates
    and speeds).

    Raises
    ------
    ValueError
        If ``model`` has no attitude.

    Examples
    --------
    >>> from appdyn.dynamics import rigid_body
    >>> attitude_blocks(rigid_body([1.0, 2.0, 2.5]))
    (slice(0, 4, None), slice(4, 7, None))
    """
    if model.attitude is None:
        raise ValueError(f"`model` {model.name!r} has no attitude (quaternion and body rates)")
    iq, iw = model.attitude
    return slice(iq, iq + 4), slice(iw, iw + 3)


def is_rest_to_rest(problem) -> bool:
    """Whether every state but the attitude quaternion is zero at both ends."""
    rest = np.ones(problem.model.nx, dtype=bool)
    rest[attitude_blocks(problem.model)[0]] = False
    return bool(np.all(problem.x_initial[rest] == 0) and np.all(problem.x_final[rest] == 0))


def slew_angle(problem) -> float:
    """Rotation angle [rad] from ``q0`` to the target, in [0, pi]."""
    q0 = problem.x_initial[attitude_blocks(problem.model)[0]]
    return float(rotation_angle(quat_mul(np.asarray(problem.q_final), quat_conj(q0))))


# ---------------------------------------------------------------------------- guesses
def attitude_guess(problem: Problem, *, tilt_axis=None, tilt=0.0, T=None, n=201) -> dict:
    """A slew guess: SLERP with a smooth-step profile, optionally tilted off the eigenaxis.

    ``q(s) = slerp(q0, qf, 3 s^2 - 2 s^3) (x) rot(tilt_axis, tilt sin(pi s))``: the tilt
    vanishes at both ends, so boundary values are kept. Rates follow from the quaternion path
    (``[w, 0] = 2 qdot (x) q^*``), torques from Euler's equations, clipped to the bounds.

    Returns
    -------
    dict with keys ``t``, ``x`` (7, n), ``u`` (3, n), ``T`` — accepted by `ocp.solve`

    Raises
    ------
    TypeError
        If ``problem`` is not an `ocp.Problem`.
    ValueError
        If ``problem`` has no attitude target ``q_final`` (not a slew problem).

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.problems import slew
    >>> pb = slew.slew_problem(np.eye(3), objective="effort", T=2.0, angle=0.1, axis=[1, 0, 0])
    >>> guess = slew.attitude_guess(pb, n=11)
    >>> guess["x"].shape, guess["u"].shape, guess["T"]
    ((7, 11), (3, 11), 2.0)
    """
    if not isinstance(problem, Problem):
        raise TypeError(f"`problem` must be an ocp.Problem, got {type(problem).__name__}")
    if getattr(problem, "q_final", None) is None:
        raise ValueError("`problem` must be a slew problem (with an attitude target `q_final`)")
    model = problem.model
    iq, iw = attitude_blocks(model)
    q0 = problem.x_initial[iq]
    qf = np.array(problem.q_final)
    if np.dot(qf, q0) < 0:
        qf = -qf  # the shorter way round
    if T is None:
        lo, hi = problem.T_bounds
        # rest to rest: the bang-bang time of the angle itself, however small
        T = problem.T if not problem.free_time else rough_time(
            inertia_of(model), q0, qf, problem.u_bounds[1],
            floor=1e-14 if is_rest_to_rest(problem) else 1e-3)
    s = np.linspace(0.0, 1.0, n)
    q = slerp(q0, qf, 3 * s**2 - 2 * s**3)
    if tilt:
        q = quat_mul(q, quat_from_axis_angle(tilt_axis, tilt * np.sin(np.pi * s)))
    q = quat_normalize(q)
    t = s * T
    qdot = np.gradient(q, t, axis=1, edge_order=2)
    w = 2.0 * quat_mul(qdot, quat_conj(q))[:3]
    w[:, 0], w[:, -1] = problem.x_initial[iw], np.nan_to_num(problem.x_final[iw])
    I = inertia_of(model)
    wdot = np.gradient(w, t, axis=1, edge_order=2)
    u = I @ wdot + np.cross(w.T, (I @ w).T).T
    u = np.clip(u, problem.u_bounds[0][:, None], problem.u_bounds[1][:, None])
    return dict(t=t, x=np.vstack([q, w]), u=u, T=float(T))


def inertia_of(model):
    """Recover the inertia matrix of a rigid-body model from its Jacobian (exact); a
    read-only array, computed once per model (kept in the one cache, `dynamics.cache`: a
    slew reads it 5-7 times, about 1 ms each)."""
    def build():
        I = _inertia_of(model)
        I.setflags(write=False)
        return I
    return cache.get(("slew.inertia_of", cache.function_key(model.f)), build,
                     keepalive=model.f)


def _inertia_of(model):
    """`inertia_of`, computed."""
    iq, iw = attitude_blocks(model)
    x, u = ca.SX.sym("x", model.nx), ca.SX.sym("u", model.nu)
    J = ca.Function("J", [x, u], [ca.jacobian(model.f(x, u, ca.DM.zeros(0))[iw], u)])
    x0 = np.zeros(model.nx)
    x0[iq] = [0.0, 0.0, 0.0, 1.0]
    return np.linalg.inv(np.array(J(x0, np.zeros(model.nu))))


def seeded_guesses(problem, starts, seed, *, eigenaxis=True):
    """The eigenaxis SLERP (optional) and SLERPs tilted about seeded random axes: ``starts``
    guesses in all."""
    rng = np.random.default_rng(seed)
    guesses = [attitude_guess(problem)] if eigenaxis else []
    while len(guesses) < starts:
        axis = rng.normal(size=3)
        guesses.append(attitude_guess(problem, tilt_axis=axis / np.linalg.norm(axis), tilt=1.0))
    return guesses
