"""Spacecraft attitude PD gains under torque limits by multi-scenario collocation.

`attitude_gains` designs the quaternion-error PD law

    u = -2 kp * q_e - kd * w          [N m]

(``q_e`` the vector part of the attitude-error quaternion, scalar-last, target = identity,
so ``2 q_e`` is the rotation vector for small errors; ``*`` per axis) for a rigid spacecraft
(`dynamics.rigid_body`: ``J w' = u - w x J w``, ``q' = -1/2 Wbar(w) q``) by minimizing, over
several initial attitude errors and rates at once,

    sum_k integral_0^T ( |2 q_e|^2 + effort_weight * sum_i (u_i / u_max_i)^2 ) dt

with the torque limit ``|u_i| <= u_max_i`` a path constraint in every scenario (no saturation
function: the law stays smooth and the limit is met, not clipped). The gains ``kp``
[N m/rad] and ``kd`` [N m s/rad] are free parameters shared by the scenarios
(`ocp.scenario_problem`), one pair or one pair per body axis.

Linearized about the target the loop is, per principal axis with a diagonal ``J``,
``J_i theta'' + kd_i theta' + kp_i theta = 0`` (``theta = 2 q_e,i``); the reported poles are
the eigenvalues of the Jacobian of the full nonlinear loop in ``(q_e, w)`` (the ``q4`` row and
column are zero at the target), so that closed form is a check.

Verification (in ``GainDesign.verification``): the linearized loop's poles (stable), each
scenario re-simulated with `dynamics.simulate` (CVODES) under the designed gains: its peak
torque per axis (the limit met within ``limit_tol`` relative) and its settle time (the
attitude error stays within ``settle_angle`` from then on), compared with the time-optimal
rest-to-rest slew (`problems.slew.time_optimal`) of the largest-angle scenario under the same
per-axis torque bounds: no feedback law can beat it, the ratio says by how much it falls short.

Optionally (``settle_by_horizon``) every scenario must be settled at the end of the horizon,
for good with one gain pair: a boundary constraint on the loop's Lyapunov function
``V = 1/2 w.J w + 4 kp (1 - q4)``, which the PD law makes nonincreasing (``V' = -kd |w|^2``).
An infeasible set of limits is ``success=False`` with `STATUS_LIMITS` and a message naming
the constraints.

A note on the law: ``u = -2 kp q_e`` is continuous and unwinds for errors beyond 180 deg
(``q4 < 0``); the scenarios are therefore limited to angles below 180 deg with ``q4 > 0``
(``sign(q4)`` in the law would be nonsmooth for the NLP).
"""
from __future__ import annotations

import math
import time
from typing import Mapping

import casadi as ca
import numpy as np

from appdyn.config import param
from appdyn import ocp
from appdyn.dynamics.validate import finite_array, nonnegative, positive, positive_each
from appdyn.ocp.status import STATUS_SIMULATION, status_code

from .attitude_loop import (Q_SCALAR, Q_VECTOR, RATES, attitude_loop, bang_bang_time,
                            check_scenarios, error_angle, gain_names, initial_state,
                            linearized_loop, loop_torque, pd_law, scene_torque_bound,
                            settle_time, simulate_loop, spacecraft_scene)
from .result import STATUS_LIMITS, STATUS_UNSTABLE, GainDesign

__all__ = ["attitude_gains", "attitude_loop", "initial_state", "settle_time", "error_angle",
           "DEFAULT_SETTLE_ANGLE", "DEFAULT_LIMIT_TOL"]

#: default settle band of the attitude error [rad] (1 deg)
DEFAULT_SETTLE_ANGLE = math.radians(1.0)
#: default relative tolerance of the re-simulated peak torque over ``u_max``
DEFAULT_LIMIT_TOL = 1e-3
_INFEASIBLE = (status_code("Infeasible_Problem_Detected"), status_code("Restoration_Failed"))
_TORQUE = "torque limit |u_i| <= u_max_i"


def attitude_gains(inertia, scenarios, *, u_max, horizon=None, per_axis: bool = False,
                   effort_weight: float = 0.1, settle_angle: float = DEFAULT_SETTLE_ANGLE,
                   settle_by_horizon: bool = False, gains0=None, gain_bounds=None,
                   N=None, transcription="radau", ipopt_options: Mapping | None = None,
                   time_optimal_reference: bool = True, time_optimal_options: Mapping | None = None,
                   limit_tol: float = DEFAULT_LIMIT_TOL) -> GainDesign:
    """PD attitude gains for a rigid spacecraft under per-axis torque limits (module docstring).

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2], or Scene
        Inertia about the mass center, body axes (or principal moments); or the spacecraft
        as a `dynamics.scene.Scene`: an attitude-only hub with at most one `ExternalTorque`
        (`problems.gains.attitude_loop.spacecraft_scene`); ``u_max=None`` takes its
        torque's bound.
    scenarios : sequence of mappings
        Initial conditions, each ``{'angle': float [rad], 'axis': (3,), 'w0': (3,) [rad/s]}``
        (``w0`` optional, default rest): the body rotated by ``angle`` (``0 <= angle < pi``)
        about ``axis`` from the target. Their designs share one set of gains.
    u_max : float or array_like, shape (3,) [N m]
        Torque limit per body axis; a path constraint in every scenario (also at ``t = 0``).
        ``None`` (with a scene whose torque is bounded): that bound.
    horizon : float [s], optional
        The cost's horizon; default 5 times the eigenaxis rest-to-rest bang-bang time
        ``2 sqrt(angle / alpha)`` of the largest-angle scenario (``alpha = min_i u_max_i /
        |(J e)_i|``).
    per_axis : bool, optional
        One ``kp, kd`` pair per body axis (``kp1..3, kd1..3``) instead of one pair.
    effort_weight : float, optional
        Weight [rad^2] of the normalized effort ``sum_i (u_i / u_max_i)^2`` against the
        squared error angle ``|2 q_e|^2`` [rad^2] in the running cost (default 0.1).
    settle_angle : float [rad], optional
        The settle band of the verification (default 1 deg), ``0 < settle_angle < pi``.
    settle_by_horizon : bool, optional
        Also require every scenario to be settled at ``t = horizon`` (a boundary constraint;
        default False). With one gain pair the constraint is on the loop's Lyapunov function
        ``V = 1/2 w.J w + 4 kp (1 - q4)`` (``V' = -kd |w|^2 <= 0`` along the nonlinear loop):
        ``V(horizon) <= 4 kp (1 - cos(settle_angle / 2))``, which for ``kp > 0`` keeps the
        error within ``settle_angle`` for all later times, together with
        ``error(horizon) <= settle_angle`` (which alone is the constraint with per-axis gains,
        for which there is no such ``V``; and which rules out ``kp = 0``, ``V = 0``).
    gains0 : array_like, optional
        Initial guess ``[kp, kd]`` (or ``[kp1, kp2, kp3, kd1, kd2, kd3]``). Default: a
        critically damped pair on the largest principal moment ``J_max`` with ``kp`` giving
        half the smallest torque limit at the largest initial angle,
        ``kp = 0.5 min(u_max) / angle_max``, ``kd = 2 sqrt(kp J_max)``.
    gain_bounds : (lower, upper), optional
        Bounds of every gain (numbers or arrays of the gains' size); default ``(0, inf)``.
    N : int, optional
        Collocation intervals (default ``appdyn.config`` ``problems.N``, 40).
    transcription : str, optional
        Default ``'radau'``.
    ipopt_options : mapping, optional
        IPOPT options (default ``{'tol': 1e-9}``), merged with what is given.
    time_optimal_reference : bool, optional
        Solve the time-optimal rest-to-rest slew of the largest-angle scenario
        (`problems.slew.time_optimal` with ``starts=1``, per-axis bounds ``u_max``) as the
        reference (default True; a second or two).
    time_optimal_options : mapping, optional
        Further keyword arguments of `problems.slew.time_optimal` (e.g. ``{'starts': 3}``).
    limit_tol : float, optional
        Relative tolerance of the re-simulated peak torque over ``u_max`` (default 1e-3: the
        constraint holds at the collocation nodes; between them the peak can exceed it by
        the collocation error).

    Returns
    -------
    GainDesign
        ``gains`` ``{'kp': .., 'kd': ..}`` [N m/rad, N m s/rad] (or per axis); ``cost``;
        ``scenarios``: per scenario ``'t'`` (n,) [s], ``'x'`` (7, n) and ``'u'`` (3, n) [N m]
        and ``'angle'`` (n,) [rad] re-simulated over ``2 horizon`` (CVODES, rtol 1e-10),
        ``'settle_time'`` [s] (inf if not settled), ``'peak'`` ``{'|L1|', '|L2|', '|L3|'}``
        [N m] and ``'angle'`` [rad] (largest error), ``'angle0'`` [rad]. ``verification``:

        * ``'poles'`` (6,) complex [1/s] of the loop linearized at the target, ``'stable'``,
          ``'damping'`` (6,), ``'natural_frequency'`` (6,) [rad/s],
          ``'slowest_time_constant'`` [s];
        * ``'peak_torque'`` (K, 3) [N m], ``'torque_ratio'`` = max peak / u_max,
          ``'limits_met'`` (ratio <= 1 + limit_tol);
        * ``'settle_times'`` (K,) [s], ``'settle_angle'`` [rad];
        * ``'reference_scenario'``, ``'T_time_optimal'`` [s] (its time-optimal rest-to-rest
          slew; NaN if not computed or not verified), ``'time_optimal_success'``,
          ``'settle_over_time_optimal'`` = its settle time / ``T_time_optimal``;
        * ``'horizon'`` [s], ``'gains0'``, ``'design_time'`` [s].

        ``success`` only if the NLP is verified (`ocp.solve`), the linearized loop is stable
        and the torque limits (and, with ``settle_by_horizon``, the settle constraint) hold
        in the re-simulation. Failures: ``status`` `STATUS_LIMITS` when IPOPT finds the
        constraints infeasible or the re-simulation violates them (the message names the
        constraint), `STATUS_UNSTABLE`, or the solver's status.

    Raises
    ------
    TypeError, ValueError
        Naming the argument: ``inertia`` (`dynamics.rigid_body`), ``scenarios`` (keys, angle
        in ``[0, pi)``, axis nonzero, finite rates), ``u_max`` (> 0), ``horizon``,
        ``effort_weight`` (>= 0), ``settle_angle``, ``gains0``, ``gain_bounds``,
        ``limit_tol``; and the errors of `ocp.solve`.

    Examples
    --------
    A 30 deg slew about the third principal axis, ``J3 = 3 kg m^2``, ``|u_i| <= 0.5 N m``:

    >>> import numpy as np
    >>> from appdyn.problems.gains.spacecraft import attitude_gains
    >>> res = attitude_gains([1.0, 2.0, 3.0], [{"angle": np.radians(30), "axis": [0, 0, 1]}],
    ...                      u_max=0.5, time_optimal_reference=False)
    >>> res.success, res.verification["limits_met"], res.verification["stable"]
    (True, True, True)
    """
    N = param("problems.N", N)
    t_start = time.perf_counter()
    scene = spacecraft_scene(inertia)
    I = scene.hub.inertia_matrix
    X0, info = check_scenarios(scenarios)
    if u_max is None:
        u_max = scene_torque_bound(scene)
        if u_max is None:
            raise ValueError("`u_max` is required (or a scene whose ExternalTorque has u_max)")
    umax = positive_each(u_max, "u_max", 3)
    if not isinstance(per_axis, (bool, np.bool_)):
        raise TypeError(f"`per_axis` must be True or False, got {per_axis!r}")
    w_eff = nonnegative(effort_weight, "effort_weight")
    band = positive(settle_angle, "settle_angle")
    if band >= math.pi:
        raise ValueError(f"`settle_angle` must be below pi, got {settle_angle!r}")
    ltol = nonnegative(limit_tol, "limit_tol")
    names = gain_names(bool(per_axis))
    ng = len(names)
    K = X0.shape[1]
    angles = np.array([s["angle"] for s in info])
    ref = int(np.argmax(angles))
    a_max = float(angles[ref])
    J_max = float(np.max(np.linalg.eigvalsh(I)))
    if horizon is None:
        axis = info[ref]["axis"]
        T_est = bang_bang_time(I, a_max, axis, umax) if a_max > 0 else 0.0
        if T_est <= 0:  # rates only: the time to stop the largest rate at full torque
            T_est = max(float(np.max(np.abs(I @ s["w0"]) / umax)) for s in info)
        horizon = 5.0 * T_est
    horizon = positive(horizon, "horizon")

    if gains0 is None:
        kp0 = 0.5 * float(np.min(umax)) / max(a_max, math.radians(1.0))
        kd0 = 2.0 * math.sqrt(kp0 * J_max)
        g0 = np.array([kp0] * (ng // 2) + [kd0] * (ng // 2))
    else:
        g0 = finite_array(gains0, "gains0", (ng,))
    if gain_bounds is None:
        lo, hi = np.zeros(ng), np.full(ng, np.inf)
    else:
        try:
            lo, hi = (np.broadcast_to(np.array(b, dtype=float), (ng,)).copy() for b in gain_bounds)
        except (TypeError, ValueError):
            raise ValueError(f"`gain_bounds` must be (lower, upper), numbers or arrays ({ng},), "
                             f"got {gain_bounds!r}") from None
        if np.any(np.isnan(lo)) or np.any(np.isnan(hi)) or np.any(lo >= hi):
            raise ValueError("`gain_bounds` must have lower < upper for every gain")
    g0 = np.clip(g0, lo, hi)

    loop = attitude_loop(scene, per_axis=bool(per_axis))
    umax_dm = ca.DM(umax)

    def cost(x, u, p):
        tau = pd_law(x, p, bool(per_axis)) / umax_dm
        return 4 * ca.sumsqr(x[Q_VECTOR]) + w_eff * ca.sumsqr(tau)

    torque = ocp.Constraint(lambda x, u, p: pd_law(x, p, bool(per_axis)), -umax, umax, umax, _TORQUE)
    extra = {}
    if per_axis:
        settle_name = (f"settle constraint: attitude error <= {math.degrees(band):.4g} deg at "
                       "t = horizon")
    else:
        settle_name = (f"settle constraint: attitude error <= {math.degrees(band):.4g} deg from "
                       "t = horizon on")
    if settle_by_horizon:
        c = 1.0 - math.cos(band / 2)
        Id = ca.DM(I)

        def settled(x0, xf, p):
            Xf = ca.reshape(xf, loop.nx, K)
            # |q_e|^2 <= sin^2(band / 2) at the horizon
            rows = [ca.sumsqr(Xf[Q_VECTOR, k]) - math.sin(band / 2) ** 2 for k in range(K)]
            if not per_axis:  # and the Lyapunov function V = 1/2 w.Jw + 4 kp (1 - q4) <= 4 kp c
                rows += [0.5 * ca.mtimes([Xf[RATES, k].T, Id, Xf[RATES, k]])
                         + 4 * p[0] * (1 - Xf[Q_SCALAR, k] - c) for k in range(K)]
            return ca.vertcat(*rows)

        row_scale = [math.sin(band / 2) ** 2] * K + ([] if per_axis else [4 * max(float(g0[0]), 1e-9) * c] * K)
        extra["boundary"] = [ocp.Constraint(settled, -np.inf, 0.0, row_scale, settle_name)]
    problem = ocp.scenario_problem(loop, X0, T=horizon, lagrange=cost, path=[torque], p=g0,
                                   p_bounds={n: (float(a), float(b)) for n, a, b in zip(names, lo, hi)},
                                   name="attitude_gains", **extra)
    t_guess = np.linspace(0.0, horizon, 201)
    xg = []
    for k in range(K):
        sim = simulate_loop(loop, X0[:, k], g0, t_guess)
        xg.append(sim.x if sim.success else np.repeat(X0[:, k:k + 1], t_guess.size, 1))
    guess = {"t": t_guess, "x": np.vstack(xg), "p": g0}
    opts = {"tol": 1e-9, **dict(ipopt_options or {})}
    # verify=False: the design is judged on the true closed loop (every scenario re-simulated
    # by `dynamics.simulate` under the designed gains, its peak torque against the limit,
    # below), not by the collocation's agreement with its own re-integration: on the random
    # valid inputs of the stress tests a scenario's rate on a coarse mesh re-simulated 0.4 %
    # of its size off the collocated one (cost 5.6e-6) and failed the generic gate
    sol = ocp.solve(problem, transcription=transcription, N=N, ipopt_options=opts, guess=guess,
                    verify=False)
    gains = np.asarray(sol.p, dtype=float)

    # ---- verification: linearized loop, re-simulation, time-optimal reference
    Alin = linearized_loop(loop, gains)
    poles = np.linalg.eigvals(Alin)
    stable = bool(np.all(poles.real < 0))
    wn = np.abs(poles)
    damping = np.where(wn > 0, -poles.real / np.where(wn > 0, wn, 1.0), 1.0)
    tau = float(1.0 / np.min(-poles.real)) if stable else float("inf")

    t_sim = np.linspace(0.0, 2 * horizon, 4001)
    scen, peaks, settles, sim_ok, end_angles, sim_message = [], [], [], True, [], ""
    for k in range(K):
        sim = simulate_loop(loop, X0[:, k], gains, t_sim)
        if sim_ok and not sim.success:
            sim_message = f"scenario {k}: {sim.message}"
        sim_ok &= bool(sim.success)
        u = loop_torque(sim.x, gains, bool(per_axis))
        ang = error_angle(sim.x)
        pk = np.max(np.abs(u), axis=1)
        ts = settle_time(t_sim, ang, band)
        i_h = int(np.searchsorted(t_sim, horizon))
        end_angles.append(float(ang[i_h]))
        peaks.append(pk)
        settles.append(ts)
        scen.append({"t": t_sim, "x": sim.x, "u": u, "angle": ang, "settle_time": ts,
                     "angle0": float(info[k]["angle"]),
                     "peak": {"|L1|": float(pk[0]), "|L2|": float(pk[1]), "|L3|": float(pk[2]),
                              "angle": float(np.max(ang))}})
    peaks = np.array(peaks)
    ratio = float(np.max(peaks / umax))
    limits_met = ratio <= 1.0 + ltol
    if not settle_by_horizon:
        settled_ok = True
    elif per_axis:
        settled_ok = max(end_angles) <= band * (1.0 + 1e-3)
    else:  # settled for good by the horizon (within a band 1e-3 wider: the collocation error)
        settled_ok = all(settle_time(t_sim, sc["angle"], band * (1.0 + 1e-3)) <= horizon for sc in scen)

    T_opt, to_ok, to_msg = float("nan"), False, "not computed"
    if time_optimal_reference and a_max > 0:
        from appdyn.problems.slew import time_optimal
        kw = {"starts": 1, "N": 30, **dict(time_optimal_options or {})}
        try:
            ts_sol = time_optimal(I, angle=a_max, axis=info[ref]["axis"], u_max=umax, **kw)
            to_ok, to_msg = bool(ts_sol.success), ts_sol.message
            T_opt = float(ts_sol.T) if ts_sol.success else float("nan")
        except (ValueError, RuntimeError) as exc:  # reference only: never fails the design
            to_msg = f"time_optimal failed: {exc}"
    ver = {"poles": poles, "stable": stable, "damping": damping, "natural_frequency": wn,
           "slowest_time_constant": tau, "linearization": Alin,
           "peak_torque": peaks, "u_max": umax, "torque_ratio": ratio, "limits_met": limits_met,
           "settle_times": np.array(settles), "settle_angle": band,
           "angle_at_horizon": np.array(end_angles),
           "reference_scenario": ref, "T_time_optimal": T_opt, "time_optimal_success": to_ok,
           "time_optimal_message": to_msg,
           "settle_over_time_optimal": settles[ref] / T_opt if T_opt > 0 else float("nan"),
           "horizon": horizon, "gains0": g0, "simulation_success": sim_ok}

    constraints = _TORQUE + (f" and the {settle_name}" if settle_by_horizon else "")
    if not sol.success:
        if sol.status in _INFEASIBLE:
            status = STATUS_LIMITS
            message = (f"no gains of the form u = -2 kp q_e - kd w meet the {constraints} "
                       f"(u_max = {np.array2string(umax, precision=4)} N m, horizon {horizon:g} s) "
                       f"in every scenario: {sol.message}")
        else:
            status = sol.status
            message = f"gain design failed (constraints: {constraints}): {sol.message}"
        success = False
    elif not stable:
        success, status = False, STATUS_UNSTABLE
        message = (f"the NLP converged but the loop linearized at the target is not stable "
                   f"(largest real part {np.max(poles.real):.4g} 1/s)")
    elif not sim_ok:  # before the limits: a failed run's peaks and settle times are NaN
        success, status = False, STATUS_SIMULATION
        message = f"the re-simulation of the designed loop failed: {sim_message}"
    elif not limits_met:
        success, status = False, STATUS_LIMITS
        message = (f"the re-simulated peak torque exceeds the {_TORQUE} by "
                   f"{100 * (ratio - 1):.3g} % (limit_tol {100 * ltol:g} %)")
    elif not settled_ok:
        success, status = False, STATUS_LIMITS
        message = (f"the re-simulation violates the {settle_name}: largest error at the horizon "
                   f"{math.degrees(max(end_angles)):.4g} deg")
    else:
        success, status = True, sol.status
        worst = float(np.max(settles))
        message = (f"gains designed: loop stable (slowest time constant {tau:.4g} s), peak torque "
                   f"{100 * ratio:.4g} % of the limit, settle within "
                   f"{math.degrees(band):.3g} deg by {worst:.4g} s")
        if T_opt > 0:
            message += (f"; the largest slew settles in {ver['settle_over_time_optimal']:.3g} x its "
                        f"time-optimal T = {T_opt:.4g} s")
    ver["design_time"] = time.perf_counter() - t_start
    units = {n: ("N m/rad" if n.startswith("kp") else "N m s/rad") for n in names}
    return GainDesign(success=success, status=status, message=message,
                      gains={n: float(v) for n, v in zip(names, gains)}, units=units,
                      cost=float(sol.cost), scenarios=scen, verification=ver, solution=sol)
