"""Optimal attitude slews of a rigid body: time-optimal and minimum-effort.

Both build an `ocp.Problem` on `dynamics.rigid_body` (state ``[q1..q4, w1..w3]``, control
body torque) and return an `ocp.Solution`:

* `time_optimal` minimizes the final time under per-axis torque bounds ``|u_i| <= u_max_i``
  or a norm bound ``|u| <= u_max``. Time-optimal slews have local optima (the eigenaxis
  maneuver is one, Bilimoria & Wie 1993), so without a user guess it solves from several
  seeded guesses (the eigenaxis SLERP and SLERPs tilted by a sinusoidal rotation about
  seeded random axes), keeps the best, and polishes the bang-bang switch times
  (`ocp.polish_switches`).
* `min_effort` minimizes ``1/2 integral |u|^2 dt`` over a fixed time, refined until the
  re-integrated trajectory matches the collocated one (`ocp.refine`).

The target attitude is ``qf`` or a rotation by ``angle`` about ``axis`` (body frame at the
start) from ``q0``; it is met up to sign (``q`` and ``-q`` are the same attitude). End rates
default to rest. An optional keep-out cone keeps a body-fixed boresight more than a given
angle away from an inertial direction throughout.

Verified results
----------------
Every slew result says ``success=True`` only when

1. the NLP is verified (`ocp.solve`: IPOPT's ``Solve_Succeeded`` and a constraint violation
   below ``constraint_tol``; for `min_effort` also the refinement ``tol`` met), and
2. re-simulating the returned control from ``q0``, ``w0`` (`ocp.Solution.propagation`,
   CVODES at rtol = atol = 1e-12) ends within ``pointing_tol`` [rad] of the target attitude
   (`ocp.Solution.pointing_error`, the rotation angle between the re-simulated final
   quaternion and ``qf``) and within ``rate_tol`` [rad/s] of the final rates ``wf``
   (largest component of `ocp.Solution.terminal_error`). Defaults: ``pointing_tol`` =
   `POINTING_TOL` = 1e-6 rad (0.2 arcsec), ``rate_tol`` = `RATE_TOL` = 1e-6 rad/s.

Otherwise ``success=False`` with ``status`` `STATUS_POINTING` (``'Pointing_Tol_Not_Met'``),
`STATUS_REFINE` (``'Refinement_Tol_Not_Met'``) or the engine's own status. A rest-to-rest
slew by a zero angle (``q0 = +/- qf``) is answered exactly without an NLP:
`ocp.rest_solution` with ``T = 0`` (time-optimal) or zero torque over ``T`` (minimum
effort), ``status = 'Rest_Solution'``. Tiny angles are solved in well-conditioned units: the
horizon and the objective are scaled by the bang-bang time ``2 sqrt(angle / alpha)``, the
target rows by the initial attitude error (`ocp.scaling`).
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import casadi as ca
import numpy as np

from dynamics import rigid_body
from dynamics.attitude import (dcm_from_quat, quat_conj, quat_from_axis_angle, quat_mul,
                               quat_normalize, rotation_angle)
from dynamics.rigid_body import check_inertia
from dynamics.validate import finite_array, finite_scalar, unit_quaternion, unit_vector
from ocp import (Problem, Solution, annotate, control_switches, polish_switches, refine,
                 rest_solution, solve, solve_multistart)
from ocp.attitude import slerp
from ocp.checks import integer, positive

__all__ = ["KeepOut", "slew_problem", "time_optimal", "min_effort", "eigenaxis_time",
           "switch_times", "attitude_guess", "verify", "summary", "format_summary", "plot_slew",
           "POINTING_TOL", "RATE_TOL", "STATUS_POINTING", "STATUS_REFINE"]

POINTING_TOL = 1e-6  # [rad] default largest re-simulated final attitude error of a success
RATE_TOL = 1e-6  # [rad/s] default largest re-simulated final rate error of a success
MIN_REFINE_TOL = 1e-12  # smallest refinement tol min_effort accepts (CVODES reference ~1e-13)
STATUS_POINTING = "Pointing_Tol_Not_Met"
STATUS_REFINE = "Refinement_Tol_Not_Met"
_ARCSEC = 180.0 * 3600.0 / math.pi


@dataclass(frozen=True)
class KeepOut:
    """Keep-out cone: ``angle(A(q)^T boresight, direction) >= half_angle`` at all times.

    Parameters
    ----------
    boresight : array_like, shape (3,) — body-fixed unit vector (normalized here)
    direction : array_like, shape (3,) — inertial unit vector to avoid, e.g. the Sun
    half_angle : float [rad] — in (0, pi)
    """

    boresight: tuple
    direction: tuple
    half_angle: float

    def __post_init__(self):
        for name in ("boresight", "direction"):
            object.__setattr__(self, name, tuple(unit_vector(getattr(self, name), name)))
        a = finite_scalar(self.half_angle, "half_angle")
        if not (0 < a < math.pi):
            raise ValueError(f"KeepOut `half_angle` must be in (0, pi) rad, got {a}")
        object.__setattr__(self, "half_angle", a)

    def margin(self, q) -> np.ndarray:
        """``cos(half_angle) - cos(angle)``: >= 0 where the constraint holds.

        ``q`` (4,) or (4, n): attitudes, normalized first (a collocation solution's
        quaternion is unit only to the solver's tolerance).
        """
        A = dcm_from_quat(quat_normalize(np.asarray(q, dtype=float)))
        b, s = np.array(self.boresight), np.array(self.direction)
        # A(q) s: the inertial direction in body axes; its component along the boresight
        cosang = np.einsum("i,ij...,j->...", b, A, s)
        return math.cos(self.half_angle) - cosang

    def function(self) -> ca.Function:
        """Path constraint ``g(x, u, p) = b . A(q) s - cos(half_angle) <= 0``."""
        x, u, p = ca.SX.sym("x", 7), ca.SX.sym("u", 3), ca.SX.sym("p", 0)
        g = ca.dot(ca.DM(self.boresight), ca.mtimes(dcm_from_quat(x[:4]), ca.DM(self.direction)))
        return ca.Function("keep_out", [x, u, p], [g - math.cos(self.half_angle)],
                           ["x", "u", "p"], ["g"])


# ---------------------------------------------------------------------------- inputs
def _vec3(v, name, default):
    """``default`` when ``v`` is None, else ``v`` as 3 finite numbers (`dynamics.validate`)."""
    return np.array(default, dtype=float) if v is None else finite_array(v, name, (3,))


def _targets(q0, qf, angle, axis):
    q0 = np.array([0.0, 0.0, 0.0, 1.0]) if q0 is None else unit_quaternion(q0, "q0")
    if qf is not None:
        if angle is not None or axis is not None:
            raise ValueError("give either `qf` or `angle` and `axis`, not both")
        return q0, unit_quaternion(qf, "qf")
    if angle is None or axis is None:
        raise ValueError("the target needs `qf`, or both `angle` [rad] and `axis` (body frame)")
    angle = _angle(angle)
    e = unit_vector(axis, "axis")
    return q0, quat_mul(quat_from_axis_angle(e, angle), q0)


def _u_max(u_max):
    a = finite_array(u_max, "u_max").reshape(-1)
    if a.size == 1:
        a = np.repeat(a, 3)
    if a.shape != (3,) or np.any(a <= 0):
        raise ValueError(f"`u_max` must be a positive scalar or 3 positive values [N m], got {u_max!r}")
    return a


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
    T : float [s] — horizon for ``"effort"`` (ignored for ``"time"``)
    angle, axis, q0, qf : see module docstring; ``angle`` [rad], ``axis`` body frame
    u_max : float or array_like, shape (3,) [N m], or None (unbounded; ``"effort"`` only)
    norm_bound : bool — bound ``|u| <= u_max`` (scalar ``u_max``) instead of per axis
    w0, wf : array_like, shape (3,) [rad/s] — end rates (default rest)
    keep_out : KeepOut, optional
    T_max : float [s], optional — upper bound of a free final time (default 20x eigenaxis)

    Returns
    -------
    ocp.Problem
    """
    I = check_inertia(inertia)
    if objective not in ("time", "effort"):
        raise ValueError(f"`objective` must be 'time' or 'effort', got {objective!r}")
    if objective == "time" and T is not None:
        warnings.warn("`T` is ignored for a time-optimal slew (the horizon is optimized; "
                      "bound it with `T_max`)", stacklevel=2)
    q0, qf = _targets(q0, qf, angle, axis)
    w0, wf = _vec3(w0, "w0", [0, 0, 0]), _vec3(wf, "wf", [0, 0, 0])
    if u_max is None:
        if objective == "time":
            raise ValueError("a time-optimal slew needs a torque bound `u_max`")
        u_lim = np.full(3, np.inf)
    else:
        u_lim = _u_max(u_max)
    path = []
    if norm_bound:
        if u_max is None or np.ptp(u_lim) != 0:
            raise ValueError("`norm_bound=True` needs a scalar `u_max`")
        x, u, p = ca.SX.sym("x", 7), ca.SX.sym("u", 3), ca.SX.sym("p", 0)
        path.append(ca.Function("torque_norm", [x, u, p], [ca.sumsqr(u) - u_lim[0] ** 2],
                                ["x", "u", "p"], ["g"]))
    if keep_out is not None:
        if not isinstance(keep_out, KeepOut):
            raise TypeError(f"`keep_out` must be a KeepOut, got {type(keep_out).__name__}")
        for qq, name in ((q0, "q0"), (qf, "target")):
            if keep_out.margin(qq) < 0:
                raise ValueError(f"the {name} attitude already violates the keep-out cone "
                                 f"(margin {keep_out.margin(qq):.3g})")
        path.append(keep_out.function())
    model = rigid_body(I)
    if objective == "time":
        T_ref = _rough_time(I, q0, qf, u_lim)
        horizon = (0.0, float(T_max) if T_max is not None else 20.0 * T_ref)
        costs = dict(mayer=lambda xf, p, T: T)
    else:
        if T is None or not (math.isfinite(float(T)) and float(T) > 0):
            raise ValueError(f"`T` must be a positive finite horizon [s], got {T!r}")
        horizon = float(T)
        x, u, p = ca.SX.sym("x", 7), ca.SX.sym("u", 3), ca.SX.sym("p", 0)
        costs = dict(lagrange=ca.Function("effort", [x, u, p], [0.5 * ca.sumsqr(u)],
                                          ["x", "u", "p"], ["L"]))
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
    axis : array_like, shape (3,) — non-zero, body frame (normalized here)
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
    """
    I = check_inertia(inertia)
    angle = _angle(angle)
    e = unit_vector(axis, "axis")
    Je = I @ e
    if np.linalg.norm(Je - (e @ Je) * e) > 1e-9 * np.linalg.norm(Je):
        raise ValueError(f"`axis` {e} is not a principal axis of `inertia`")
    u = _u_max(u_max)
    alpha = np.min(u[np.abs(Je) > 0] / np.abs(Je[np.abs(Je) > 0]))
    a = math.fmod(abs(angle), 2.0 * math.pi)
    a = min(a, 2.0 * math.pi - a)  # the short way round
    return float(2.0 * math.sqrt(a / alpha))


def _angle(angle) -> float:
    """``angle`` [rad] as a finite float (`dynamics.validate.finite_scalar`)."""
    return finite_scalar(angle, "angle")


def _rough_time(I, q0, qf, u_lim, floor=1e-3):
    """Order-of-magnitude slew time: bang-bang about the error axis with the weakest axis
    (the angle taken as at least ``floor`` [rad])."""
    dq = quat_mul(qf, quat_conj(q0))
    angle = float(rotation_angle(dq))
    alpha = np.min(u_lim) / np.max(np.linalg.eigvalsh(I))
    return max(2.0 * math.sqrt(max(angle, floor) / alpha), 1e-6)


def _rest_to_rest(problem) -> bool:
    return bool(np.all(problem.x_initial[4:] == 0) and np.all(problem.x_final[4:] == 0))


def _slew_angle(problem) -> float:
    """Rotation angle [rad] from ``q0`` to the target, in [0, pi]."""
    return float(rotation_angle(quat_mul(np.asarray(problem.q_final), quat_conj(problem.x_initial[:4]))))


# ---------------------------------------------------------------------------- guesses
def attitude_guess(problem: Problem, *, tilt_axis=None, tilt=0.0, T=None, n=201) -> dict:
    """A slew guess: SLERP with a smooth-step profile, optionally tilted off the eigenaxis.

    ``q(s) = slerp(q0, qf, 3 s^2 - 2 s^3) (x) rot(tilt_axis, tilt sin(pi s))``: the tilt
    vanishes at both ends, so boundary values are kept. Rates follow from the quaternion path
    (``[w, 0] = 2 qdot (x) q^*``), torques from Euler's equations, clipped to the bounds.

    Returns
    -------
    dict with keys ``t``, ``x`` (7, n), ``u`` (3, n), ``T`` — accepted by `ocp.solve`
    """
    model = problem.model
    q0 = problem.x_initial[:4]
    qf = np.array(problem.q_final)
    if np.dot(qf, q0) < 0:
        qf = -qf  # the shorter way round
    if T is None:
        lo, hi = problem.T_bounds
        # rest to rest: the bang-bang time of the angle itself, however small
        T = problem.T if not problem.free_time else _rough_time(
            _inertia_of(model), q0, qf, problem.u_bounds[1],
            floor=1e-14 if _rest_to_rest(problem) else 1e-3)
    s = np.linspace(0.0, 1.0, n)
    q = slerp(q0, qf, 3 * s**2 - 2 * s**3)
    if tilt:
        q = quat_mul(q, quat_from_axis_angle(tilt_axis, tilt * np.sin(np.pi * s)))
    q = quat_normalize(q)
    t = s * T
    qdot = np.gradient(q, t, axis=1, edge_order=2)
    w = 2.0 * quat_mul(qdot, quat_conj(q))[:3]
    w[:, 0], w[:, -1] = problem.x_initial[4:], np.nan_to_num(problem.x_final[4:])
    I = _inertia_of(model)
    wdot = np.gradient(w, t, axis=1, edge_order=2)
    u = I @ wdot + np.cross(w.T, (I @ w).T).T
    u = np.clip(u, problem.u_bounds[0][:, None], problem.u_bounds[1][:, None])
    return dict(t=t, x=np.vstack([q, w]), u=u, T=float(T))


def _inertia_of(model):
    """Recover the inertia matrix of a rigid-body model from its Jacobian (exact)."""
    x, u = ca.SX.sym("x", 7), ca.SX.sym("u", 3)
    J = ca.Function("J", [x, u], [ca.jacobian(model.f(x, u, ca.DM.zeros(0))[4:], u)])
    return np.linalg.inv(np.array(J(np.r_[0, 0, 0, 1, 0, 0, 0], np.zeros(3))))


def _seeded_guesses(problem, starts, seed, *, eigenaxis=True):
    """The eigenaxis SLERP (optional) and SLERPs tilted about seeded random axes: ``starts``
    guesses in all."""
    rng = np.random.default_rng(seed)
    guesses = [attitude_guess(problem)] if eigenaxis else []
    while len(guesses) < starts:
        axis = rng.normal(size=3)
        guesses.append(attitude_guess(problem, tilt_axis=axis / np.linalg.norm(axis), tilt=1.0))
    return guesses


# ------------------------------------------------------------------------- maneuvers
def _check_tol(name, value, default):
    """``default`` when ``value`` is None, else a finite float > 0 (`ocp.checks.positive`)."""
    return default if value is None else positive(value, name)


def verify(solution: Solution, *, pointing_tol: float = POINTING_TOL, rate_tol: float = RATE_TOL):
    """Re-simulate a slew solution and grade it (see the module docstring).

    Parameters
    ----------
    solution : ocp.Solution
        A solution of a `slew_problem`.
    pointing_tol : float [rad]
        Largest accepted `ocp.Solution.pointing_error` (default 1e-6).
    rate_tol : float [rad/s]
        Largest accepted final rate error, ``max_i |w_sim,i(tf) - wf_i|`` (default 1e-6).

    Returns
    -------
    ocp.RefinedSolution
        ``solution`` with ``info['pointing_error']`` [rad], ``info['final_rate_error']``
        [rad/s], ``info['pointing_tol']``, ``info['rate_tol']``; ``success`` stays ``True``
        only if it was and both errors are within their tolerances (else ``status``
        `STATUS_POINTING` and a message with the numbers).

    Raises
    ------
    TypeError
        If ``solution`` is not an `ocp.Solution` or a tolerance is not a number.
    ValueError
        If a tolerance is not a finite number > 0.
    """
    if not isinstance(solution, Solution):
        raise TypeError(f"`solution` must be an ocp.Solution, got {type(solution).__name__}")
    ptol = _check_tol("pointing_tol", pointing_tol, POINTING_TOL)
    rtol = _check_tol("rate_tol", rate_tol, RATE_TOL)
    perr = solution.pointing_error
    perr = float("nan") if perr is None else perr
    term = solution.terminal_error[4:7]
    rerr = float(np.max(term)) if np.all(np.isfinite(term)) else float("nan")
    info = {"pointing_error": perr, "final_rate_error": rerr, "pointing_tol": ptol, "rate_tol": rtol}
    if not solution.success:
        return annotate(solution, info)
    if perr <= ptol and rerr <= rtol:
        return annotate(solution, info, message=(
            f"{solution.message}; verified by re-simulation: pointing error "
            f"{perr * _ARCSEC:.3g} arcsec, final rate error {rerr:.2g} rad/s"))
    return annotate(solution, info, success=False, status=STATUS_POINTING, message=(
        f"{solution.message}; NOT verified: the re-simulated control ends {perr:.3g} rad "
        f"({perr * _ARCSEC:.3g} arcsec) from the target (pointing_tol {ptol:g}) with a final "
        f"rate error {rerr:.3g} rad/s (rate_tol {rtol:g})"))


def _rest(problem, T, pointing_tol, rate_tol):
    """Zero-angle rest-to-rest slews: the exact answer, no NLP (or None)."""
    if not (_rest_to_rest(problem) and _slew_angle(problem) <= 8 * np.finfo(float).eps):
        return None
    return verify(rest_solution(problem, T=T), pointing_tol=pointing_tol, rate_tol=rate_tol)


def _tiny_scale(problem, T_est):
    """Scale overrides for small rest-to-rest angles: horizon and objective in units of the
    bang-bang time (IPOPT then sees O(1) numbers however small the angle)."""
    if _slew_angle(problem) >= 1e-2 or not _rest_to_rest(problem):
        return None
    d = float(2.0 ** round(math.log2(T_est)))
    return {"T": d, "objective": d}


def time_optimal(inertia, *, angle=None, axis=None, q0=None, qf=None, u_max=1.0,
                 norm_bound=False, w0=None, wf=None, keep_out=None, T_max=None, guess=None,
                 starts=3, seed=0, N=30, transcription="radau", polish=True,
                 verbose=False, ipopt_options=None, pointing_tol=POINTING_TOL,
                 rate_tol=RATE_TOL) -> Solution:
    """Minimum-time rigid-body slew under torque bounds.

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2]
    angle : float [rad], axis : array_like, shape (3,) — rotation from ``q0`` about a body axis
    q0, qf : array_like, shape (4,) — initial (default identity) and target quaternions
    u_max : float or array_like, shape (3,) [N m] — per-axis bound (or the norm bound)
    norm_bound : bool — ``|u| <= u_max`` instead of per-axis bounds
    w0, wf : array_like, shape (3,) [rad/s] — end rates (default rest to rest)
    keep_out : KeepOut, optional
    T_max : float [s], optional — upper bound on the final time
    guess : None, ocp.Solution or mapping
        A user guess (then a single start is solved). ``None``: multi-start.
    starts : int — number of seeded starts without a user guess (eigenaxis + tilted)
    seed : int — seed of the tilt axes (results are reproducible)
    N : int — intervals of the first solve
    transcription : str — of the first solve (any of ``ocp.TRANSCRIPTIONS``)
    polish : bool
        Re-solve with free knots so switch times are exact (`ocp.polish_switches`, Radau
        degree 5, IPOPT ``tol`` 1e-9 unless ``ipopt_options`` says otherwise). The polished
        result is returned only if it is verified and not slower than the first; otherwise
        the first solution (``info['polish']`` says why). Should neither be verified (the
        first's fixed mesh can smear the switches beyond ``pointing_tol``), the first is
        mesh-refined (`ocp.refine`, tol 1e-6, at most 4 rounds) and verified again.
    verbose : bool — IPOPT progress lines
    ipopt_options : dict, optional
    pointing_tol : float [rad] — largest re-simulated final attitude error of a success
    rate_tol : float [rad/s] — largest re-simulated final rate error of a success

    Returns
    -------
    ocp.RefinedSolution
        ``T`` is the optimal time [s]; ``success`` as in the module docstring; ``info``
        records the starts, the polish, ``pointing_error`` [rad] and ``final_rate_error``
        [rad/s]. A zero-angle rest-to-rest slew returns ``T = 0`` at once.
    """
    ptol = _check_tol("pointing_tol", pointing_tol, POINTING_TOL)
    rtol = _check_tol("rate_tol", rate_tol, RATE_TOL)
    problem = slew_problem(inertia, objective="time", angle=angle, axis=axis, q0=q0, qf=qf,
                           u_max=u_max, norm_bound=norm_bound, w0=w0, wf=wf,
                           keep_out=keep_out, T_max=T_max)
    if guess is None:
        starts = integer(starts, "starts", 1)
    rest = _rest(problem, 0.0, ptol, rtol)
    if rest is not None:
        return rest
    T_est = _rough_time(_inertia_of(problem.model), problem.x_initial[:4], problem.q_final,
                        problem.u_bounds[1], floor=1e-14 if _rest_to_rest(problem) else 1e-3)
    opts = dict(transcription=transcription, N=N, verbose=verbose, ipopt_options=ipopt_options,
                scale=_tiny_scale(problem, T_est))
    if guess is not None:
        sol = solve(problem, guess=guess, **opts)
    else:
        guesses = _seeded_guesses(problem, int(starts), seed, eigenaxis=keep_out is None)
        sol = solve_multistart(problem, guesses, **opts)
    first = sol
    sol = verify(sol, pointing_tol=ptol, rate_tol=rtol)
    if not (polish and first.success and not norm_bound and keep_out is None):
        return _refined_fallback(problem, first, sol, ptol, rtol, ipopt_options, opts["scale"])
    # degree 5: at degree 3 the ~4 intervals per arc under-resolve the states and the free
    # knots exploit the collocation error (T below the best known); at degree 4 the
    # re-simulated pointing error of Bilimoria-Wie is 4e-7 rad, at degree 5 3e-10 (measured)
    polish_opts = {"tol": 1e-9, **(ipopt_options or {})}
    pscale = None if opts["scale"] is None else {"objective": opts["scale"]["objective"],
                                                 "t_clock": opts["scale"]["T"]}
    polished = polish_switches(problem, sol, degree=5, verbose=verbose, ipopt_options=polish_opts,
                               scale=pscale)
    polished = verify(polished, pointing_tol=ptol, rate_tol=rtol)
    if polished.success and (polished.T <= sol.T + 1e-9 or not sol.success):
        first = {k: sol.info[k] for k in ("starts", "best") if k in sol.info}
        return annotate(polished, first) if first else polished
    why = (f"polish not used: {polished.message}" if not polished.success else
           f"polish not used: its T = {polished.T:.10g} s is not below {sol.T:.10g} s")
    return _refined_fallback(problem, first, annotate(sol, {"polish": why}), ptol, rtol,
                             ipopt_options, opts["scale"])


def _refined_fallback(problem, first, verified, ptol, rtol, ipopt_options, scale):
    """When the first NLP solution converged but its re-simulation misses the target (the
    fixed mesh smears the switches): refine the mesh (`ocp.refine`, 4 rounds, tol 1e-6)
    and verify again. Returns ``verified`` unchanged if it already is a success or the NLP
    itself failed."""
    if verified.success or not first.success:
        return verified
    ref = refine(problem, first, tol=1e-6, max_rounds=4, ipopt_options=ipopt_options, scale=scale)
    ref = verify(ref, pointing_tol=ptol, rate_tol=rtol)
    if ref.success:
        keep = {k: first.info[k] for k in ("starts", "best", "polish") if k in first.info}
        keep.update({k: verified.info[k] for k in ("polish",) if k in verified.info})
        return annotate(ref, keep)
    return verified


def min_effort(inertia, T, *, angle=None, axis=None, q0=None, qf=None, u_max=None,
               norm_bound=False, w0=None, wf=None, keep_out=None, guess=None, N=20,
               tol=1e-7, starts=4, seed=0, verbose=False, ipopt_options=None,
               pointing_tol=POINTING_TOL, rate_tol=RATE_TOL) -> Solution:
    """Minimum-effort (``1/2 integral |u|^2 dt``) rigid-body slew over a fixed time ``T``.

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2]
    T : float [s] — maneuver time
    angle, axis, q0, qf, w0, wf, keep_out : as in `time_optimal`
    u_max : float or array_like, shape (3,) [N m], optional — torque bound (default none)
    norm_bound : bool
    guess : None, ocp.Solution or mapping — default: eigenaxis SLERP (with a keep-out cone:
        multi-start from ``starts`` seeded tilted paths, best kept)
    N : int — intervals of the first mesh
    tol : float
        Mesh-refinement target for the relative re-integration error (`ocp.refine`), at
        least `MIN_REFINE_TOL` = 1e-12 (the CVODES reference of the error estimate is good
        to about 1e-13). ``success`` requires it to be met.
    verbose : bool
    ipopt_options : dict, optional
    pointing_tol : float [rad] — largest re-simulated final attitude error of a success
    rate_tol : float [rad/s] — largest re-simulated final rate error of a success

    Returns
    -------
    ocp.RefinedSolution
        ``cost`` in [N^2 m^2 s]; ``success`` as in the module docstring (``status``
        `STATUS_REFINE` when the refinement stopped above ``tol``). For a rest-to-rest
        rotation by ``theta`` about a principal axis with moment ``J`` and no active bound:
        ``u = J theta (6/T^2 - 12 t/T^3)``, cost ``6 J^2 theta^2 / T^3``.

    Raises
    ------
    TypeError, ValueError
        Bad input, naming the argument (``tol`` below 1e-12 among them).
    """
    ptol = _check_tol("pointing_tol", pointing_tol, POINTING_TOL)
    rtol = _check_tol("rate_tol", rate_tol, RATE_TOL)
    tol = _check_tol("tol", tol, 1e-7)
    if tol < MIN_REFINE_TOL:
        raise ValueError(f"`tol` must be at least {MIN_REFINE_TOL:g} (what the re-integration "
                         f"reference can resolve in double precision), got {tol:g}")
    problem = slew_problem(inertia, objective="effort", T=T, angle=angle, axis=axis, q0=q0,
                           qf=qf, u_max=u_max, norm_bound=norm_bound, w0=w0, wf=wf,
                           keep_out=keep_out)
    rest = _rest(problem, problem.T, ptol, rtol)
    if rest is not None:
        return rest
    scale = None
    if _rest_to_rest(problem) and _slew_angle(problem) < 1e-2:
        # the cost of the single-axis cubic profile, 6 (J theta)^2 / T^3, as its scale
        J = float(np.max(np.linalg.eigvalsh(_inertia_of(problem.model))))
        d = 6.0 * (J * _slew_angle(problem)) ** 2 / problem.T ** 3
        scale = {"objective": float(2.0 ** round(math.log2(d)))}
    opts = dict(N=N, verbose=verbose, ipopt_options=ipopt_options, scale=scale)
    if guess is not None:
        first = solve(problem, guess=guess, **opts)
    elif keep_out is None:
        first = solve(problem, guess=attitude_guess(problem), **opts)
    else:
        # the eigenaxis path may cross the cone's centre, a symmetric saddle between the two
        # ways around: start from seeded tilted paths instead and keep the best
        guesses = _seeded_guesses(problem, int(starts), seed, eigenaxis=False)
        first = solve_multistart(problem, guesses, **opts)
    if not first.success:
        return verify(first, pointing_tol=ptol, rate_tol=rtol)
    sol = refine(problem, first, tol=tol, verbose=verbose, ipopt_options=ipopt_options, scale=scale)
    if sol.success and not sol.info.get("converged", False):
        sol = annotate(sol, {}, success=False, status=STATUS_REFINE,
                       message=f"{sol.message}; the requested refinement tol {tol:g} was not met")
    return verify(sol, pointing_tol=ptol, rate_tol=rtol)


def switch_times(solution: Solution, *, axis=None) -> list:
    """Switch times [s] of each torque component: the engine's one switch detector
    (`ocp.control_switches`: bound-to-bound jumps at the middle of the range, and both ends
    of interior arcs), so they agree with `ocp.find_switches` and `ocp.interval_errors`.

    Parameters
    ----------
    solution : ocp.Solution of a slew
    axis : int, optional — one component (0, 1, 2); default all

    Returns
    -------
    list of ndarray — one array of switch times per component (or one array)
    """
    per = control_switches(solution)
    if axis is None:
        return per
    if isinstance(axis, (bool, np.bool_)) or not isinstance(axis, (int, np.integer)):
        raise TypeError(f"`axis` must be a component index 0, 1 or 2, got {axis!r}")
    if not 0 <= axis < len(per):
        raise ValueError(f"`axis` must be a component index in [0, {len(per)}), got {axis!r}")
    return per[int(axis)]


# ----------------------------------------------------------------------- reporting
def summary(solution: Solution, *, eigenaxis=None) -> dict:
    """JSON-ready summary of a slew solution.

    Keys: success, status, message, T [s], cost, switch_times [s] (per torque axis),
    iterations, solve_time [s], constraint_violation (NLP units, see `ocp.solve`),
    pointing_error_arcsec (final attitude error of the re-simulated control [arcsec]),
    final_rate_error [rad/s] (same re-simulation), propagation_error (largest deviation of
    the re-integrated trajectory from the collocated states), quaternion_norm_error, and
    ``eigenaxis_T`` [s] when given. Re-simulation numbers are NaN when it failed.
    """
    sw = switch_times(solution) if solution.success else [np.array([])] * 3
    info = getattr(solution, "info", {}) or {}
    perr = info.get("pointing_error", solution.pointing_error)
    rerr = info.get("final_rate_error")
    if rerr is None:
        term = solution.terminal_error[4:7]
        rerr = float(np.max(term)) if np.all(np.isfinite(term)) else float("nan")
    out = dict(
        success=bool(solution.success),
        status=str(solution.status),
        message=str(solution.message),
        T=float(solution.T),
        cost=float(solution.cost),
        switch_times=[s.tolist() for s in sw],
        iterations=int(solution.iterations),
        solve_time=float(solution.solve_time),
        constraint_violation=float(solution.constraint_violation),
        pointing_error_arcsec=float("nan") if perr is None else float(perr) * _ARCSEC,
        final_rate_error=float(rerr),
        propagation_error=float(solution.propagation_error),
        quaternion_norm_error=float(solution.quaternion_norm_error),
    )
    if eigenaxis is not None:
        out["eigenaxis_T"] = float(eigenaxis)
    return out


def format_summary(data: dict) -> str:
    """A readable table of `summary` output."""
    rows = [
        ("success", f"{data['success']} ({data['status']})"),
        ("maneuver time T [s]", f"{data['T']:.6f}"),
    ]
    if "eigenaxis_T" in data:
        rows.append(("eigenaxis maneuver T [s]", f"{data['eigenaxis_T']:.6f}"))
    rows.append(("cost", f"{data['cost']:.8g}"))
    for i, s in enumerate(data["switch_times"]):
        rows.append((f"switch times u{i + 1} [s]", ", ".join(f"{v:.4f}" for v in s) or "-"))
    rows += [
        ("IPOPT iterations", f"{data['iterations']}"),
        ("solve time [s]", f"{data['solve_time']:.3f}"),
        ("constraint violation", f"{data['constraint_violation']:.2e}"),
        ("pointing error [arcsec]", f"{data['pointing_error_arcsec']:.3g}"),
        ("final rate error [rad/s]", f"{data['final_rate_error']:.2e}"),
        ("propagation error", f"{data['propagation_error']:.2e}"),
        ("|q| - 1 (max)", f"{data['quaternion_norm_error']:.2e}"),
    ]
    width = max(len(k) for k, _ in rows)
    return "\n".join(["Optimal slew"] + [f"  {k:<{width}}  {v}" for k, v in rows])


def plot_slew(solution: Solution, path=None, *, fig=None, dpi: int = 110):
    """Quaternion, rates, torques and the rotation path (body axes on the unit sphere).

    Builds a `matplotlib.figure.Figure` (no pyplot, no backend change) and returns it; the
    caller shows or saves it. With ``path`` it is also saved there (``Figure.savefig``).

    Parameters
    ----------
    solution : ocp.Solution of a slew
    path : str or path-like, optional
        Where to save the figure.
    fig : matplotlib.figure.Figure, optional
        Draw into this (empty) figure instead of a new 12 x 8 in one.
    dpi : int
        Resolution when saving.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure

    if fig is None:
        fig = Figure(figsize=(12, 8))
    elif not isinstance(fig, Figure):
        raise TypeError(f"`fig` must be a matplotlib Figure, got {type(fig).__name__}")
    t = np.linspace(solution.t[0], solution.t[-1], 400)
    x, u = solution.sample(t)
    panels = [(x[:4], "quaternion", [f"q{i + 1}" for i in range(4)]),
              (x[4:], "body rate [rad/s]", ["w1", "w2", "w3"]),
              (u, "torque [N m]", ["u1", "u2", "u3"])]
    for k, (data, label, names) in enumerate(panels):
        ax = fig.add_subplot(2, 2, k + 1)
        for row, name in zip(data, names):
            ax.plot(t, row, label=name)
        ax.set(xlabel="t [s]", ylabel=label)
        ax.legend(loc="best", fontsize=8)
        ax.grid(alpha=0.3)
    ax = fig.add_subplot(2, 2, 4, projection="3d")
    A = dcm_from_quat(x[:4] / np.linalg.norm(x[:4], axis=0))  # (3, 3, n): rows = body axes
    for i, c in enumerate(("tab:red", "tab:green", "tab:blue")):
        ax.plot(A[i, 0], A[i, 1], A[i, 2], color=c, label=f"body axis {i + 1}")
        ax.scatter(*A[i, :, -1], color=c, marker="o")
    ax.set(title="Rotation path (inertial)", xlim=(-1, 1), ylim=(-1, 1), zlim=(-1, 1))
    ax.legend(fontsize=8)
    fig.suptitle(f"T = {solution.T:.5f} s, cost = {solution.cost:.6g}")
    fig.tight_layout()
    if path is not None:
        fig.savefig(path, dpi=dpi)
    return fig
