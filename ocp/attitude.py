"""Attitude pieces of the engine, kept out of the generic problem and NLP.

For a model with an attitude (``model.attitude = (iq, iw)``, quaternion ``x[iq:iq+4]``,
scalar-last) this module holds what the engine does with it:

* the checks of the attitude inputs of a `Problem` (`check_attitude`): the terminal target
  ``q_final`` (a unit quaternion, met up to sign), its pointing tolerance ``q_final_tol``, a
  given initial quaternion (unit norm, normalized), and the refusal of four fixed final
  quaternion components;
* the NLP rows (`nlp_rows`, `target_bounds`): ``|q(t0)|^2 = 1`` when the initial
  quaternion is not given (`needs_norm_at_t0`), and the target rows
  ``vec(q_final^* (x) q(tf)) = 0`` (`attitude_error`; three equations, or one inequality
  ``|vec(.)|^2 <= sin^2(tol/2)`` with a pointing tolerance);
* the default guess (`quaternion_path`): SLERP (`slerp`) from the initial to the target
  attitude, the shorter way round.

See the module docstring of `ocp.problem` for why the norm is imposed at ``t0`` only and
why the target is stated through the vector part of the error quaternion.
"""
from __future__ import annotations

import math

import casadi as ca
import numpy as np

from appdyn.dynamics.attitude import quat_conj, quat_mul
from appdyn.dynamics.validate import QUAT_NORM_TOL, unit_quaternion

__all__ = ["check_attitude", "needs_norm_at_t0", "attitude_error", "target_rows", "nlp_rows",
           "target_bounds", "slerp", "quaternion_path"]


def check_attitude(model, x_initial: np.ndarray, x_final: np.ndarray, q_final, q_final_tol):
    """Validated ``(x_initial, q_final, q_final_tol)`` of a problem on ``model``.

    ``x_initial`` gets a given initial quaternion normalized; ``q_final`` is returned
    normalized (read-only) or ``None``; ``q_final_tol`` as a float.

    Raises
    ------
    TypeError
        If ``q_final`` or ``q_final_tol`` is not numeric.
    ValueError
        Naming the argument: ``q_final`` without an attitude model or not of unit norm (to
        1e-6), ``q_final_tol`` outside [0, pi) or without a ``q_final``, a given initial
        quaternion not of unit norm, all four final quaternion components fixed.
    """
    if q_final is not None:
        if model.attitude is None:
            raise ValueError("`q_final` needs a model with an attitude (`model.attitude` is None)")
        q_final = unit_quaternion(q_final, "q_final")
        q_final.setflags(write=False)
    tol = q_final_tol
    if isinstance(tol, (bool, np.bool_)) or not isinstance(tol, (int, float, np.integer, np.floating)):
        raise TypeError(f"`q_final_tol` must be an angle in [0, pi) [rad], got {tol!r}")
    if not 0 <= tol < math.pi:
        raise ValueError(f"`q_final_tol` must be an angle in [0, pi) [rad], got {tol!r}")
    if tol > 0 and q_final is None:
        raise ValueError("`q_final_tol` needs a `q_final`")
    if model.attitude is None:
        return x_initial, q_final, float(tol)
    iq = model.attitude[0]
    sl = slice(iq, iq + 4)
    if not np.any(np.isnan(x_initial[sl])):
        n = float(np.linalg.norm(x_initial[sl]))
        if abs(n - 1.0) > QUAT_NORM_TOL:
            raise ValueError(
                f"`x_initial`: the initial quaternion {model.states[sl]} must have unit norm "
                f"(within {QUAT_NORM_TOL}), got norm {n}")
        x_initial = np.array(x_initial)
        x_initial[sl] = x_initial[sl] / n
    if not np.any(np.isnan(x_final[sl])):
        raise ValueError(
            f"`x_final` fixes all four quaternion components {model.states[sl]}: four "
            "equations for three attitude degrees of freedom make the NLP degenerate "
            "(the discrete dynamics conserve |q| only approximately). Give the target "
            "attitude as `q_final=` (met up to sign, three equations) instead.")
    return x_initial, q_final, float(tol)


def needs_norm_at_t0(model, x_initial) -> bool:
    """Whether the NLP needs ``|q(t0)|^2 = 1`` (attitude model, initial quaternion not given)."""
    if model.attitude is None:
        return False
    iq = model.attitude[0]
    return bool(np.any(np.isnan(x_initial[iq:iq + 4])))


def attitude_error(q_final, qf):
    """Vector part of ``q_final^* (x) qf`` (zero iff ``qf = +/- q_final``), shape (3,).

    Parameters
    ----------
    q_final : array_like, shape (4,), or casadi 4x1 (then ``qf`` is symbolic too)
    qf : casadi 4x1 or array_like, shape (4,)
    """
    if isinstance(q_final, (ca.SX, ca.MX)):
        qt = q_final
    else:
        qt = ca.DM(q_final) if isinstance(qf, (ca.SX, ca.MX, ca.DM)) else np.asarray(q_final, dtype=float)
    return quat_mul(quat_conj(qt), qf)[0:3]


def target_rows(problem) -> int:
    """Rows of the attitude-target block: 0 without ``q_final``, 1 with a pointing
    tolerance, else 3."""
    if problem.q_final is None:
        return 0
    return 1 if problem.q_final_tol > 0 else 3


def nlp_rows(problem, X, q_final_scale: float):
    """``(quat_norm, q_final)`` constraint blocks of the NLP on the state nodes ``X`` (nx, n)
    (physical units; the target rows divided by ``q_final_scale`` when exact). Empty
    ``MX(0, 1)`` blocks where the problem has none."""
    model = problem.model
    iq = model.attitude[0] if model.attitude is not None else 0
    norm = ca.sumsqr(X[iq:iq + 4, 0]) - 1 if problem.quaternion_norm_at_t0 else ca.MX(0, 1)
    if problem.q_final is None:
        target = ca.MX(0, 1)
    elif problem.q_final_tol > 0:
        target = ca.sumsqr(attitude_error(problem.q_final, X[iq:iq + 4, -1]))
    else:
        target = attitude_error(problem.q_final, X[iq:iq + 4, -1]) / q_final_scale
    return norm, target


def target_bounds(problem) -> tuple[float, float]:
    """Bounds ``(lower, upper)`` of the target rows: 0 and ``sin^2(tol/2)`` (or 0)."""
    hi = math.sin(problem.q_final_tol / 2) ** 2 if problem.q_final_tol > 0 else 0.0
    return 0.0, hi


def slerp(qa, qb, s) -> np.ndarray:
    """Spherical linear interpolation between unit quaternions (no sign flip applied).

    Parameters
    ----------
    qa, qb : array_like, shape (4,)
    s : array_like, shape (m,)
        Fractions in [0, 1].

    Returns
    -------
    ndarray, shape (4, m)
    """
    qa, qb = np.asarray(qa, float), np.asarray(qb, float)
    s = np.asarray(s, float).reshape(-1)
    c = float(np.clip(np.dot(qa, qb), -1.0, 1.0))
    angle = math.acos(c)
    if angle < 1e-8:
        q = qa[:, None] + s[None, :] * (qb - qa)[:, None]
    else:
        sa = math.sin(angle)
        q = (np.sin((1 - s) * angle)[None, :] * qa[:, None]
             + np.sin(s * angle)[None, :] * qb[:, None]) / sa
    return q / np.linalg.norm(q, axis=0)


def quaternion_path(problem):
    """The default attitude guess: ``(slice, fun)`` with ``fun(tau) -> (4, m)`` the SLERP
    from the initial quaternion to ``q_final`` (the sign nearer the start), or ``None`` for
    a model without an attitude. A free end takes the other end's value (the identity when
    both are free)."""
    model = problem.model
    if model.attitude is None:
        return None
    iq = model.attitude[0]
    sl = slice(iq, iq + 4)
    a = problem.x_initial
    qa = None if np.any(np.isnan(a[sl])) else a[sl]
    qb = None if problem.q_final is None else np.array(problem.q_final)
    if qa is not None and qb is not None and np.dot(qa, qb) < 0:
        qb = -qb
    if qa is None and qb is None:
        qa = qb = np.array([0.0, 0.0, 0.0, 1.0])
    elif qa is None:
        qa = qb
    elif qb is None:
        qb = qa
    return sl, lambda tau: slerp(qa, qb, tau)
