"""Slews with momentum-exchange devices: reaction wheels (`wheel_slew`) and single-gimbal
CMGs (`cmg_slew`).

The model is `dynamics.wheel_spacecraft` (controls: wheel motor torques) or
`dynamics.cmg_spacecraft` (controls: gimbal rates); no external torque acts, so the total
inertial angular momentum (hub plus devices) is conserved and the attitude changes by
momentum exchange alone. Rest to rest by default, with the device states starting at ``W0`` /
``delta0`` and, where given, ending at ``Wf`` / ``deltaf``.

Guesses come from the rigid-body slew guesses (`attitude_guess`, SLERP with a smooth-step
profile, optionally tilted) of the hub: the device states follow from momentum
conservation (wheels: the least-norm wheel speeds that carry the momentum the hub does not;
CMGs: gimbal angles tracking the required cluster momentum by pseudo-inverse steps), the
controls from their rates. The pipelines and the verification (re-simulation of the
returned controls; every fixed final state checked) are those of `time_optimal` and
`min_effort`; ``info['momentum_drift']`` is the largest change of the total inertial
momentum along the collocated trajectory, relative to the largest device momentum (the
collocation accuracy: momentum is conserved by the dynamics, not imposed).
"""
from __future__ import annotations


import casadi as ca
import numpy as np

from appdyn.config import param
from appdyn.dynamics import cmg_spacecraft, wheel_spacecraft
from appdyn.dynamics.attitude import dcm_from_quat
from appdyn.dynamics.interrupts import interruptible
from appdyn.dynamics.momentum import (ClusterGeometry, cluster_jacobian, cluster_momentum,
                               gram_determinant)
from appdyn.dynamics.validate import (check_inertia, finite_array, integer, one_of, positive,
                               positive_each, unit_axes)
from appdyn.ocp import Constraint, Problem, annotate, solve, solve_multistart

from .maneuvers import (START_BUDGET, SEED_OPTIONS, bounded, refine_and_verify, restarted,
                        solve_time_optimal, with_minimum_time)
from .problem import attitude_guess, rough_time, seeded_guesses, slew_problem
from .targets import POINTING_TOL, RATE_TOL, check_tol, targets

__all__ = ["wheel_slew", "cmg_slew", "solve_converted", "slew_horizon", "slew_costs",
           "DEVICE_STARTS"]

DEVICE_STARTS = 3  # seeded starts of a time-optimal device slew


def _vector(value, name, n, default) -> np.ndarray:
    """``value`` as shape (n,) (``default`` when None; a scalar for all)."""
    if value is None:
        return np.full(n, float(default))
    v = finite_array(value, name)
    v = np.full(n, float(v)) if v.ndim == 0 else v
    if v.shape != (n,):
        raise ValueError(f"`{name}` must be a scalar or have shape ({n},), got {v.shape}")
    return v


def slew_horizon(objective, T, T_max, T_ref):
    """The ``T`` of an `ocp.Problem` of a slew: ``(0, T_max)`` for ``'time'`` (default 20
    times the rough time ``T_ref`` [s]), the fixed positive ``T`` for ``'effort'``."""
    if objective == "time":
        return (0.0, float(T_max) if T_max is not None else 20.0 * T_ref)
    if T is None:
        raise ValueError("`T` must be a positive finite horizon [s], got None")
    return positive(T, "T")


def slew_costs(objective):
    """The objective keywords of `ocp.Problem`: ``mayer = T`` (``'time'``) or ``lagrange =
    1/2 |u|^2`` (``'effort'``)."""
    if objective == "time":
        return dict(mayer=lambda xf, p, T: T)
    return dict(lagrange=lambda x, u, p: 0.5 * ca.sumsqr(u))


def _problems(model, I, objective, horizon, q0, qf, dev0, devf, u_max, body_max, device, *,
              x_bounds=None, path=()):
    """The device slew's `ocp.Problem` (rest to rest; device states from ``dev0`` to ``devf``,
    free where None; controls within ``+-u_max``) and the hub's rigid-body slew problem whose
    guesses are converted (body torque bound ``body_max``)."""
    free = np.full(dev0.size, np.nan)
    problem = Problem(
        model, T=horizon, x_initial=np.r_[q0, 0.0, 0.0, 0.0, dev0],
        x_final=np.r_[np.full(4, np.nan), 0.0, 0.0, 0.0, free if devf is None else devf],
        u_bounds=None if u_max is None else (-u_max, u_max), x_bounds=x_bounds, q_final=qf,
        path=path, name=f"{device} slew ({objective})", **slew_costs(objective))
    rb = slew_problem(I, objective=objective, T=None if objective == "time" else horizon,
                      q0=q0, qf=qf, u_max=body_max)
    return problem, rb


def _momentum_info(sol, scale) -> dict:
    """``momentum_drift``: max |H_in(t) - H_in(0)| over the nodes / ``scale``."""
    H = np.asarray(sol.problem.model.invariant("momentum_inertial", sol.x))
    H = H.reshape(3, -1)
    drift = float(np.max(np.abs(H - H[:, :1]))) / scale
    return {"momentum_drift": drift}


def _body_momentum(q, H_inertial):
    """Total momentum in body axes along the quaternions ``q`` (4, n) of a rigid-body guess:
    ``A(q) H_inertial``."""
    return np.einsum("ijk,j->ik", dcm_from_quat(q), H_inertial)


def solve_converted(problem, rb_problem, convert, objective, *, starts, seed, N, tol, verbose,
                    ipopt_options, ptol, rtol, polish, scale=None, guess=None,
                    transcription="radau", control="constant", eigenaxis=True,
                    seed_control=None, fastest=None):
    """Solve the slew ``problem`` from the rigid-body guesses of ``rb_problem`` converted by
    ``convert`` (a guess dict of the hub -> one of ``problem``), by the pipelines of
    `time_optimal` (``'time'``: the best of ``starts`` seeded starts, polished when
    ``polish``, kept within its bounds with ``control``) and `min_effort` (``'effort'``:
    the eigenaxis start, or with ``eigenaxis=False`` -- a keep-out cone -- the best of the
    seeded tilted starts; refined to ``tol``), verified by re-simulation.

    ``seed_control`` is the control interpolant of the first time-optimal solve (default the
    transcription's own, polynomial for Radau: the seed whose switches the polish reads;
    ``'constant'`` or ``'linear'`` keep the bounds between the nodes, so that no bounded
    re-solve follows: `scene_slew.settling_parts`).

    ``fastest`` (``'effort'`` with a control bound): a callable giving the time-optimal slew
    of the same scene, run when the first solve is infeasible (`maneuvers.restarted`: a
    ``T`` below the minimum time is said so, else the slew is re-solved from it).

    ``guess`` (a solution or mapping of ``problem``) replaces the starts. With ``scale``
    [N m s] the result's ``info['momentum_drift']`` is the largest change of the total
    inertial momentum along the collocated trajectory over ``scale`` (momentum-exchange
    slews, where it is conserved)."""
    opts = dict(N=N, verbose=verbose, ipopt_options=ipopt_options, scale=None)
    if objective == "time":
        guesses = None if guess is not None else [
            convert(g) for g in seeded_guesses(rb_problem, starts, seed, eigenaxis=eigenaxis)]
        first = dict(opts, transcription=transcription, control=seed_control,
                     **SEED_OPTIONS)  # as time_optimal
        sol = solve_time_optimal(problem, guess, guesses, first,
                                 polish=polish, pointing_tol=ptol, rate_tol=rtol,
                                 ipopt_options=ipopt_options, verbose=verbose)
        sol = bounded(problem, sol, control=control, pointing_tol=ptol, rate_tol=rtol,
                      ipopt_options=ipopt_options)
    else:
        if guess is not None:
            first = solve(problem, guess=guess, **opts)
        elif eigenaxis:
            first = solve(problem, guess=convert(attitude_guess(rb_problem)), **opts)
        else:
            first = solve_multistart(problem, [convert(g) for g in seeded_guesses(
                rb_problem, starts, seed, eigenaxis=False)], start_budget=START_BUDGET, **opts)
        first, fast = restarted(problem, first, fastest, opts)
        sol = refine_and_verify(problem, first, tol=tol, scale=None, pointing_tol=ptol,
                                rate_tol=rtol, ipopt_options=ipopt_options, verbose=verbose)
        sol = with_minimum_time(sol, problem.T, fast)
    return sol if scale is None else annotate(sol, _momentum_info(sol, scale))


def _common(objective, tol, pointing_tol, rate_tol, starts):
    objective = one_of(objective, "objective", ("time", "effort"))
    return (objective, check_tol("tol", tol, 1e-7), check_tol("pointing_tol", pointing_tol, POINTING_TOL),
            check_tol("rate_tol", rate_tol, RATE_TOL),
            integer(DEVICE_STARTS if starts is None else starts, "starts", minimum=1))


@interruptible
def wheel_slew(inertia, axes, wheel_inertia, *, objective="time", T=None, angle=None, axis=None,
               q0=None, qf=None, torque_max=1.0, speed_max=None, W0=None, Wf=None, T_max=None,
               N=None, starts=None, seed=0, tol=1e-7, verbose=False, ipopt_options=None,
               pointing_tol=POINTING_TOL, rate_tol=RATE_TOL):
    """Time-optimal or minimum-effort rest-to-rest slew by reaction wheels.

    The engine of `slew` for this scene; prefer ``slew(Scene(RigidHub(inertia),
    ReactionWheels(axes, wheel_inertia, u_max=torque_max, speed_max=speed_max)), ...)``.

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2]
        Hub inertia including the wheels' transverse inertia (as `dynamics.wheel_spacecraft`).
    axes : array_like, shape (3, n)
        Unit wheel spin axes (body frame), one per column.
    wheel_inertia : float or array_like, shape (n,) [kg m^2]
        Axial moments of the wheels.
    objective : {'time', 'effort'}
        Minimum final time, or minimum ``1/2 integral |tau|^2 dt`` [N^2 m^2 s] over ``T``.
    T : float [s]
        Horizon of ``'effort'``.
    angle, axis, q0, qf
        The target, as in `time_optimal`.
    torque_max : float or array_like, shape (n,) [N m], or None
        Motor-torque bound per wheel (``None``: unbounded, ``'effort'`` only).
    speed_max : float or array_like, shape (n,) [rad/s], optional
        Wheel-speed bound (relative to the hub) along the whole slew.
    W0, Wf : array_like, shape (n,) [rad/s], optional
        Wheel speeds at the start (default 0) and at the end (default free).
    T_max : float [s], optional
        Upper bound of the final time of ``'time'`` (default 20x a rough bang-bang time).
    N, starts, seed, tol, verbose, ipopt_options, pointing_tol, rate_tol
        As in `time_optimal` (``starts``, ``seed``: ``'time'``) and `min_effort` (``tol``:
        ``'effort'``).

    Returns
    -------
    ocp.RefinedSolution
        ``success`` as for the rigid-body slews (verified NLP, re-simulated pointing, rates
        and the fixed final wheel speeds); ``info['momentum_drift']`` (module docstring).

    Raises
    ------
    ValueError
        Naming the argument (bad geometry, bounds, ``W0`` outside ``speed_max``, ...).

    Examples
    --------
    Three orthogonal wheels on a unit-inertia hub, 0.2 rad about the third axis: with zero
    total momentum the hub obeys ``I w' = -tau``, so the optimum is the rigid body's
    bang-bang ``T = 2 sqrt(0.2)``:

    >>> import numpy as np
    >>> from appdyn.problems import slew
    >>> sol = slew.wheel_slew(np.eye(3), np.eye(3), 0.01, angle=0.2, axis=[0, 0, 1], N=10,
    ...                       starts=1)
    >>> sol.success, round(sol.T, 6), round(2 * 0.2 ** 0.5, 6)
    (True, 0.894427, 0.894427)
    """
    N = param("problems.slew_N", N)
    objective, tol, ptol, rtol, starts = _common(objective, tol, pointing_tol, rate_tol, starts)
    I = check_inertia(inertia)
    A = unit_axes(axes, "axes")
    n = A.shape[1]
    J = positive_each(wheel_inertia, "wheel_inertia", n)
    model = wheel_spacecraft(I, A, J)
    q0, qf = targets(q0, qf, angle, axis)
    W0 = _vector(W0, "W0", n, 0.0)
    Wf = None if Wf is None else _vector(Wf, "Wf", n, 0.0)
    tmax = None if torque_max is None else positive_each(torque_max, "torque_max", n)
    if tmax is None and objective == "time":
        raise ValueError("a time-optimal slew needs a motor-torque bound `torque_max`")
    smax = None if speed_max is None else positive_each(speed_max, "speed_max", n)
    if smax is not None and np.any(np.abs(W0) > smax):
        raise ValueError(f"`W0` {W0.tolist()} lies outside `speed_max` {smax.tolist()}")
    sigma = np.linalg.svd(A, compute_uv=False)  # (fewer than 3 wheels: fewer than 3 values)
    if sigma.size < 3 or sigma[-1] == 0:
        raise ValueError("`axes` must span the three body axes for a slew")
    body_max = float(np.min(tmax)) * float(sigma[-1]) if tmax is not None else None
    T_ref = rough_time(I, q0, qf, np.full(3, body_max if body_max else 1.0))
    horizon = slew_horizon(objective, T, T_max, T_ref)
    lo = np.full(model.nx, -np.inf)
    if smax is not None:
        lo[model.layout["wheels"].speeds] = -smax
    problem, rb = _problems(model, I, objective, horizon, q0, qf, W0, Wf, tmax,
                            body_max if body_max else None, "wheel", x_bounds=(lo, -lo))
    H_in = A @ (J * W0)  # at rest: the wheels carry it all (identity body = inertial at t0)
    H_in = dcm_from_quat(q0).T @ H_in
    AJ_pinv, A_pinv = np.linalg.pinv(A * J), np.linalg.pinv(A)

    hub = rb.model.layout["hub"]

    def convert(g):
        x, t = g["x"], g["t"]
        w = x[hub.speeds]
        Hb = _body_momentum(x[hub.coords], H_in)
        W = AJ_pinv @ (Hb - I @ w) - A.T @ w
        wdot = np.gradient(w, t, axis=1, edge_order=2)
        tau = -A_pinv @ (I @ wdot + np.cross(w.T, Hb.T).T)
        if tmax is not None:
            tau = np.clip(tau, -tmax[:, None], tmax[:, None])
        return dict(t=t, x=np.vstack([x, W]), u=tau, T=g["T"])

    scale = max(float(np.max(J * np.abs(W0))), float(np.max(J)) * 1.0, 1e-300)

    def fastest():  # the time-optimal slew of this scene (see `solve_converted`)
        return wheel_slew(inertia, axes, wheel_inertia, q0=q0, qf=qf, torque_max=torque_max,
                          speed_max=speed_max, W0=W0, Wf=Wf, N=N, starts=starts, seed=seed,
                          tol=tol, ipopt_options=ipopt_options, pointing_tol=ptol, rate_tol=rtol)

    return solve_converted(problem, rb, convert, objective, starts=starts, seed=seed, N=N,
                           tol=tol, verbose=verbose, ipopt_options=ipopt_options, ptol=ptol,
                           rtol=rtol, scale=scale, polish=True,
                           fastest=fastest if objective == "effort" and tmax is not None else None)


@interruptible
def cmg_slew(inertia, geometry, *, objective="time", T=None, angle=None, axis=None, q0=None,
             qf=None, rate_max=1.0, min_measure=None, delta0=None, deltaf=None, T_max=None,
             N=None, starts=None, seed=0, tol=1e-7, verbose=False, ipopt_options=None,
             pointing_tol=POINTING_TOL, rate_tol=RATE_TOL):
    """Time-optimal or minimum-effort rest-to-rest slew by a cluster of single-gimbal CMGs.

    The engine of `slew` for this scene; prefer
    ``slew(Scene(RigidHub(inertia), <CMG cluster>), ...)``.

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2]
        Spacecraft inertia (as `dynamics.cmg_spacecraft`, exact fidelity).
    geometry : dynamics.momentum.ClusterGeometry
        The cluster (e.g. `dynamics.momentum.pyramid`).
    objective : {'time', 'effort'}
        Minimum final time, or minimum ``1/2 integral |delta_dot|^2 dt`` over ``T``.
    T, angle, axis, q0, qf, T_max
        As in `wheel_slew`.
    rate_max : float or array_like, shape (n,) [rad/s], or None
        Gimbal-rate bound (``None``: unbounded, ``'effort'`` only).
    min_measure : float, optional [(N m s)^3]
        Lower bound of the singularity measure ``sqrt(det(C C^T))`` along the slew (imposed
        as ``det(C C^T) >= min_measure^2`` at every control node), so the optimal path
        steers clear of singular states; ``None``: no bound.
    delta0, deltaf : array_like, shape (n,) [rad], optional
        Gimbal angles at the start (default 0) and at the end (default free).
    N, starts, seed, tol, verbose, ipopt_options, pointing_tol, rate_tol
        As in `wheel_slew`. A time-optimal CMG slew is not polished (its gimbal rates are
        not bang-bang: singular and measure-constrained arcs); a fixed mesh that misses the
        target is refined (`ocp.refine`) instead, and where a singular arc stalls the
        refinement, the fallbacks of `time_optimal` (``info['fallback']``: the uniform mesh
        twice as fine, then the slightly regularized problem, ``T`` within about 1e-5
        relative of the unregularized one on the tests).

    Returns
    -------
    ocp.RefinedSolution
        As in `wheel_slew`; ``info['min_measure']`` is the smallest singularity measure at
        the solution's nodes.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.momentum import pyramid
    >>> from appdyn.problems import slew
    >>> geo = pyramid(np.deg2rad(54.74), h=1.0)
    >>> sol = slew.cmg_slew(10 * np.eye(3), geo, objective="effort", T=3.0, angle=0.1,
    ...                     axis=[1, 0, 0], min_measure=0.5, N=15)
    >>> sol.success, sol.info["min_measure"] >= 0.5 - 1e-6
    (True, True)
    """
    N = param("problems.slew_N", N)
    objective, tol, ptol, rtol, starts = _common(objective, tol, pointing_tol, rate_tol, starts)
    if not isinstance(geometry, ClusterGeometry):
        raise TypeError(f"`geometry` must be a dynamics.momentum.ClusterGeometry, got "
                        f"{type(geometry).__name__}")
    I = check_inertia(inertia)
    n = geometry.n
    model = cmg_spacecraft(I, geometry.gimbal_axes, geometry.spin_axes0, geometry.h)
    q0, qf = targets(q0, qf, angle, axis)
    d0 = _vector(delta0, "delta0", n, 0.0)
    df = None if deltaf is None else _vector(deltaf, "deltaf", n, 0.0)
    rmax = None if rate_max is None else positive_each(rate_max, "rate_max", n)
    if rmax is None and objective == "time":
        raise ValueError("a time-optimal slew needs a gimbal-rate bound `rate_max`")
    path = ()
    if min_measure is not None:
        m_min = positive(min_measure, "min_measure")
        if float(np.sqrt(gram_determinant(cluster_jacobian(geometry, d0)))) < m_min:
            raise ValueError(f"`delta0` starts below `min_measure` {m_min:g}")
        gimbals = model.layout["cmgs"].coords  # the gimbal angles, read by name
        path = (Constraint(lambda x, u, p: gram_determinant(cluster_jacobian(geometry, x[gimbals])),
                           lower=m_min ** 2, upper=np.inf, name="singularity"),)
    body_max = float(np.min(geometry.h)) * (float(np.min(rmax)) if rmax is not None else 1.0)
    T_ref = rough_time(I, q0, qf, np.full(3, body_max))
    horizon = slew_horizon(objective, T, T_max, T_ref)
    problem, rb = _problems(model, I, objective, horizon, q0, qf, d0, df, rmax, body_max, "cmg",
                            path=path)
    H_in = dcm_from_quat(q0).T @ cluster_momentum(geometry, d0)
    hub = rb.model.layout["hub"]

    def convert(g):
        x, t = g["x"], g["t"]
        Hc = _body_momentum(x[hub.coords], H_in) - I @ x[hub.speeds]  # the cluster's share
        d = np.empty((n, t.size))
        d[:, 0] = d0
        for k in range(1, t.size):  # track Hc by damped pseudo-inverse (Newton) steps
            dk = d[:, k - 1].copy()
            for _ in range(3):
                C = cluster_jacobian(geometry, dk)
                dk = dk + C.T @ np.linalg.solve(C @ C.T + 1e-3 * np.eye(3),
                                                Hc[:, k] - cluster_momentum(geometry, dk))
            d[:, k] = dk
        rates = np.gradient(d, t, axis=1, edge_order=2)
        if rmax is not None:
            rates = np.clip(rates, -rmax[:, None], rmax[:, None])
        return dict(t=t, x=np.vstack([x, d]), u=rates, T=g["T"])

    def fastest():  # the time-optimal slew of this scene (see `solve_converted`)
        return cmg_slew(inertia, geometry, q0=q0, qf=qf, rate_max=rate_max,
                        min_measure=min_measure, delta0=delta0, deltaf=deltaf, N=N,
                        starts=starts, seed=seed, tol=tol, ipopt_options=ipopt_options,
                        pointing_tol=ptol, rate_tol=rtol)

    sol = solve_converted(problem, rb, convert, objective, starts=starts, seed=seed, N=N,
                          tol=tol, verbose=verbose, ipopt_options=ipopt_options, ptol=ptol,
                          rtol=rtol, scale=float(np.sum(geometry.h)), polish=False,
                          fastest=fastest if objective == "effort" and rmax is not None else None)
    angles = sol.x[model.layout["cmgs"].coords]
    measure = np.sqrt(np.maximum(gram_determinant(cluster_jacobian(geometry, angles)), 0.0))
    return annotate(sol, {"min_measure": float(np.min(measure))})
