"""`slew(scene, ...)`: the one slew entry point -- any `dynamics.scene.Scene`, time-optimal or
minimum-effort, verified by re-simulation.

The bounds come from the parts (``u_max`` of an `ExternalTorque`, a `ReactionWheels`' or a CMG
cluster's; a wheel's ``speed_max``), read from the assembled model (`Model.bounds`). A scene
that is exactly one of the proven pipelines goes to it:

==============================================  ================================
hub + `ExternalTorque`                          `time_optimal` / `min_effort`
hub + `ReactionWheels` (rest to rest)           `wheel_slew`
hub + `CMGCluster` (rest to rest; rate drive,   `cmg_slew`
exact fidelity, no rotor or gimbal inertia)
==============================================  ================================

Any other scene -- wheels with a damper, a hinged panel, a held rotor, a translating hub, or
one of the above with a setting its engine does not take -- is solved by the generic path
(`scene_problem`): an `ocp.Problem` on ``scene.model()`` from the model, its layout and bounds
alone (never a part's class), with guesses converted from the rigid-body ones of the hub
(`attitude_guess`: the SLERP with a smooth-step profile, tilted for the further starts) with
the parts at rest and the controls that best produce the hub's torque, on enough intervals
for the fastest oscillation of the model (`scene_intervals`), and the pipelines of
`time_optimal` and `min_effort` (`solve_converted`). A time-optimal slew that must bring
parts to rest (a damper, a panel, a slosh mass: `settling_parts`) is solved at once with the
bounded piecewise-constant control, from the eigenaxis start, without the switch-time polish
(its control switches again and again to settle the parts' modes), or else warm from a
minimum-effort slew of a longer horizon. Every result says
``success=True`` only when verified by re-simulation (pointing, rates and every fixed final
part state within the tolerances; `verify`).
"""
from __future__ import annotations

import warnings

import casadi as ca
import numpy as np

from appdyn.config import param
from appdyn.dynamics import cache
from appdyn.dynamics.attitude import dcm_from_quat
from appdyn.dynamics.interrupts import interruptible
from appdyn.dynamics.momentum import ClusterGeometry
from appdyn.dynamics.scene import ExternalTorque, ReactionWheels, Scene, check_scene
from appdyn.dynamics.validate import one_of
from appdyn.ocp import Constraint, Problem, Solution, annotate

from .devices import DEVICE_STARTS, cmg_slew, slew_costs, slew_horizon, solve_converted, wheel_slew
from .maneuvers import DEFAULT_STARTS_EFFORT, DEFAULT_STARTS_TIME, min_effort, time_optimal
from .options import SlewOptions, with_fields
from .problem import attitude_guess, rough_time, slew_problem
from .targets import targets, vector3

__all__ = ["slew", "scene_problem", "torque_map", "scene_intervals", "quaternion_blocks",
           "settling_parts", "EFFORT_HORIZON",
           "default_N", "INTERVALS_PER_PERIOD", "MAX_AUTO_N"]


def default_N(objective: str) -> int:
    """The default interval count of a slew of ``objective`` (``'time'`` or ``'effort'``).

    ``appdyn.config``'s ``problems.slew_N`` (30) for a time-optimal slew, ``problems.effort_N``
    (20) for a minimum-effort one.

    Examples
    --------
    >>> from appdyn.problems.slew.scene_slew import default_N
    >>> default_N("time"), default_N("effort")
    (30, 20)
    """
    return param("problems.slew_N" if objective == "time" else "problems.effort_N")


#: Least intervals per period of the fastest oscillation of a scene (`scene_intervals`): a
#: damper on a 60 N/m spring with 0.5 kg (11.0 rad/s on its hub), 30 s of minimum effort: 20
#: intervals stall the refinement (``Refinement_Stalled``); 4 per period ask for 211, capped
#: at `MAX_AUTO_N`, verified after refinement to 232 (10.9 s; measured).
INTERVALS_PER_PERIOD = 4

#: Most intervals `scene_intervals` asks for (the refinement adds more where needed).
MAX_AUTO_N = 200

_GENERIC_ONLY = ("guess", "keep_out")  # settings the device engines do not take


@interruptible
def slew(scene, *, objective="time", angle=None, axis=None, q_final=None, T=None, w0=None,
         wf=None, options=None, **fields) -> Solution:
    """Time-optimal or minimum-effort slew of any scene, verified by re-simulation.

    Parameters
    ----------
    scene : dynamics.scene.Scene
        The vehicle: a `RigidHub` and its parts. Control and state bounds come from the parts
        (``u_max``, ``speed_max``).
    objective : {'time', 'effort'}
        Minimum final time (every control bounded), or minimum ``1/2 integral |u|^2 dt`` over
        the fixed ``T`` (the sum over all controls, in their own units).
    angle : float [rad]
        Rotation from the initial attitude about ``axis``.
    axis : array_like, shape (3,)
        The rotation axis, hub frame at the start.
    q_final : array_like, shape (4,)
        The target attitude instead (scalar-last; met up to sign).
    T : float [s]
        Horizon of ``'effort'`` (ignored, with a warning, for ``'time'``).
    w0, wf : array_like, shape (3,) [rad/s]
        Hub rates at the start and at the end (default rest to rest).
    options : SlewOptions, optional
        How it is solved and graded.
    **fields
        `SlewOptions` fields, replacing those of ``options`` (``N=40, starts=2``).

    Returns
    -------
    ocp.Solution
        A verified `ocp.RefinedSolution` on success (module docstring); the part states
        start at rest (or at ``state0``) and end at rest where their `Variable.terminal`
        says ``'rest'`` (free otherwise: wheel speeds, gimbal angles). ``info['engine']``
        names the pipeline (``'time_optimal'``, ``'min_effort'``, ``'wheel_slew'``,
        ``'cmg_slew'`` or ``'scene'``); ``info['settle']``, why a time-optimal slew of
        parts brought to rest left its bounded single start (`settling_parts`).

    Raises
    ------
    TypeError
        ``scene`` not a `Scene`; an unknown keyword (named, with the list of fields).
    ValueError
        Naming the argument: a bad target or rate; a time-optimal slew with an unbounded
        control (naming the part and ``u_max``); a scene without controls, or whose controls
        do not turn the hub about every axis; a setting that does not apply to the scene.

    Examples
    --------
    Bilimoria & Wie's 180 deg slew of a unit-inertia body, ``|L_i| <= 1``: T = 3.24308 s,
    below the eigenaxis maneuver's ``2 sqrt(pi) = 3.5449`` s:

    >>> import numpy as np
    >>> from appdyn.dynamics.scene import ExternalTorque, RigidHub, Scene
    >>> from appdyn.problems.slew import slew
    >>> scene = Scene(RigidHub(np.eye(3)), ExternalTorque(u_max=1.0))
    >>> sol = slew(scene, objective="time", angle=np.pi, axis=[0, 0, 1])
    >>> sol.success, round(sol.T, 5), sol.info["engine"]
    (True, 3.24308, 'time_optimal')

    A hub with three wheels and a held rotor (no proven pipeline: the generic path), 0.2 rad
    in 3 s at least effort:

    >>> from appdyn.dynamics.scene import HeldRotor, ReactionWheels
    >>> scene = Scene(RigidHub([1.0, 1.2, 0.9]), ReactionWheels(np.eye(3), 0.01),
    ...               HeldRotor([1, 0, 0], 0.05))
    >>> sol = slew(scene, objective="effort", T=3.0, angle=0.2, axis=[0, 0, 1], N=15)
    >>> sol.success, sol.info["engine"]
    (True, 'scene')
    """
    check_scene(scene)
    objective = one_of(objective, "objective", ("time", "effort"))
    opts = with_fields(options, fields)
    model = scene.model()
    _check_controls(scene, model, objective)
    _check_state0(scene, opts)
    if objective == "time" and T is not None:
        warnings.warn("`T` is ignored for a time-optimal slew (the horizon is optimized; "
                      "bound it with `T_max`)", stacklevel=3)
    if objective == "effort":
        _ignored(opts, T_max=None, polish=None, transcription="radau", control="constant",
                 why="for a minimum-effort slew")
    single = scene.parts[0] if len(scene.parts) == 1 and not scene.hub.translates else None
    if opts.norm_bound and not isinstance(single, ExternalTorque):
        raise ValueError("`norm_bound` applies to a scene of a hub and one ExternalTorque only")
    if opts.min_measure is not None and getattr(single, "kind", None) != "cmgs":
        raise ValueError("`min_measure` applies to a scene of a hub and one CMG cluster only")
    for engine in (_rigid, _wheels, _cmgs):
        sol = engine(scene, objective, angle, axis, q_final, T, w0, wf, opts)
        if sol is not None:
            return sol
    if opts.min_measure is not None:
        raise ValueError("`min_measure` is taken by `cmg_slew` only: rest to rest, without "
                         "`guess`, `keep_out`, `polish=True` and with the default "
                         "`transcription` and `control`")
    problem, rb, convert = scene_problem(scene, objective=objective, angle=angle, axis=axis,
                                         q_final=q_final, T=T, w0=w0, wf=wf, options=opts)
    keep_out = opts.keep_out is not None
    if keep_out and opts.polish:
        _ignored(opts, polish=None, why="with `keep_out` (not bang-bang per axis)")
    # parts the slew must bring to rest (a damper, a panel, a slosh mass): the time-optimal
    # control switches again and again to settle their modes (module docstring)
    settle = objective == "time" and bool(settling_parts(scene, problem))
    N = opts.N or scene_intervals(problem, default_N(objective), attitude_guess(rb, n=3)["T"])
    run = dict(seed=opts.seed or 0, N=N, tol=opts.tol, verbose=opts.verbose,
               ipopt_options=_dict(opts.ipopt_options), ptol=opts.pointing_tol,
               rtol=opts.rate_tol, guess=opts.guess, transcription=opts.transcription,
               control=opts.control, eigenaxis=not keep_out)
    if settle:
        sol = solve_converted(problem, rb, convert, objective, starts=opts.starts or 1,
                              polish=opts.polish is True and not keep_out,
                              seed_control=opts.control, **run)
        if sol.success or opts.starts is not None or opts.polish is not None:
            return _engine(sol, "scene")
        failed = sol
        if opts.guess is None:  # warm from a verified minimum-effort slew of a longer T
            sol = _from_effort(scene, problem, failed, angle, axis, q_final, w0, wf, opts, run)
            if sol is not None and sol.success:
                return _engine(sol, "scene")
        # then the pipeline of the other scenes (slower)
    starts = opts.starts if opts.starts is not None else (
        DEFAULT_STARTS_TIME if objective == "time" else DEFAULT_STARTS_EFFORT)
    sol = solve_converted(problem, rb, convert, objective, starts=starts,
                          polish=opts.polish is not False and not keep_out, **run)
    if settle:
        sol = annotate(sol, {"settle": f"the bounded single start failed first: "
                                      f"{failed.message[:300]}"})
    return _engine(sol, "scene")


#: Horizon of the minimum-effort slew the time-optimal slew of parts brought to rest is warm
#: started from, when its single start fails, relative to that start's T (`_from_effort`):
#: a ball-hinged panel (0.3 rad) failed at T = 12.68 s; 15 s of minimum effort verified
#: (127 intervals), the time-optimal slew warm from it verified in 14 s, T = 12.606 s.
EFFORT_HORIZON = 1.2


def _from_effort(scene, problem, failed, angle, axis, q_final, w0, wf, opts, run):
    """The time-optimal slew ``problem`` of parts brought to rest, warm from the verified
    minimum-effort slew over `EFFORT_HORIZON` times the ``failed`` start's T (a homotopy in
    the cost: the effort slew is feasible and smooth, settles the parts, and sits near the
    time-optimal one), on its refined mesh, with the bounded control; None if there is
    no such T or the effort slew fails."""
    if not (np.isfinite(failed.T) and failed.T > 0):
        return None
    T_effort = EFFORT_HORIZON * float(failed.T)
    effort, rb, convert = scene_problem(scene, objective="effort", angle=angle, axis=axis,
                                        q_final=q_final, T=T_effort, w0=w0, wf=wf,
                                        options=opts)
    warm = solve_converted(effort, rb, convert, "effort", starts=1, polish=False,
                           **{**run, "N": max(run["N"], default_N("effort"))})
    if not warm.success:
        return None
    rigid = scene_problem(scene, objective="time", angle=angle, axis=axis, q_final=q_final,
                          w0=w0, wf=wf, options=opts)[1]
    sol = solve_converted(problem, rigid, convert, "time", starts=1, polish=False,
                          seed_control=opts.control, **{**run, "N": warm.mesh.N, "guess": warm})
    return annotate(sol, {"settle": f"warm from the minimum-effort slew of {T_effort:.6g} s "
                                    f"(the bounded single start failed: "
                                    f"{failed.message[:200]})"})


# ----------------------------------------------------------------------- checks
def _check_controls(scene, model, objective) -> None:
    """A scene without controls, or a time-optimal slew with an unbounded control: a
    ValueError naming the part and ``u_max``."""
    if model.nu == 0:
        raise ValueError("the scene has no controls: add a part that acts (ExternalTorque, "
                         "ReactionWheels, a CMG cluster)")
    if objective != "time":
        return
    lo, hi = model.limits("controls")
    for name, lay in scene.layout.items():
        free = [model.controls[i] for i in range(lay.controls.start, lay.controls.stop)
                if not (np.isfinite(lo[i]) and np.isfinite(hi[i]))]
        if free:
            raise ValueError(f"a time-optimal slew needs every control bounded: part {name!r} "
                             f"({type(scene.part(name)).__name__}) has no `u_max` for "
                             f"{', '.join(free)}")


def _check_state0(scene, opts) -> None:
    if opts.state0 is None:
        return
    taken = [k for k in opts.state0 if k in ("q", "w")
             or (k in scene.states[:7] and k not in scene.part_names)]
    if taken:
        raise ValueError(f"`state0` gives the part states; the hub's attitude and rates are "
                         f"`q0` and `w0` (got {taken})")
    scene.state(**opts.state0)  # names an unknown block or a wrong size


def _ignored(opts, *, why, **defaults) -> None:
    """A warning naming the fields of ``opts`` set away from ``defaults``: ignored ``why``."""
    names = [f"`{k}`" for k, v in defaults.items() if getattr(opts, k) != v]
    if names:
        warnings.warn(f"{' and '.join(names)} {'is' if len(names) == 1 else 'are'} ignored "
                      f"{why}", stacklevel=4)


def _dict(mapping):
    return None if mapping is None else dict(mapping)


def _engine(sol, name):
    """``sol`` with ``info['engine'] = name``."""
    return annotate(sol, {"engine": name})


def _rest_to_rest(w0, wf) -> bool:
    return all(w is None or not np.any(vector3(w, n, [0, 0, 0])) for w, n in ((w0, "w0"),
                                                                            (wf, "wf")))


def _common(opts, objective):
    """The keywords every engine takes."""
    return dict(N=opts.N or default_N(objective), verbose=opts.verbose,
                ipopt_options=_dict(opts.ipopt_options), pointing_tol=opts.pointing_tol,
                rate_tol=opts.rate_tol)


# ---------------------------------------------------------------------- engines
def _rigid(scene, objective, angle, axis, q_final, T, w0, wf, opts):
    """A hub with one `ExternalTorque`: `time_optimal` / `min_effort` (or None)."""
    if scene.hub.translates or len(scene.parts) != 1 or not isinstance(scene.parts[0],
                                                                        ExternalTorque):
        return None
    I, u_max = scene.hub.inertia_matrix, scene.parts[0].u_max
    kw = dict(angle=angle, axis=axis, q0=opts.q0, qf=q_final, w0=w0, wf=wf,
              keep_out=opts.keep_out, norm_bound=opts.norm_bound, guess=opts.guess,
              starts=opts.starts, seed=opts.seed, **_common(opts, objective))
    if opts.norm_bound and u_max is not None and len(set(u_max)) == 1:
        u_max = u_max[0]  # the scalar a norm bound needs
    if objective == "time":
        sol = time_optimal(I, u_max=np.asarray(u_max), T_max=opts.T_max, polish=opts.polish,
                           transcription=opts.transcription, control=opts.control, **kw)
        return _engine(sol, "time_optimal")
    if opts.keep_out is None and opts.guess is None:
        kw.update(starts=None, seed=None)  # (min_effort warns about them there)
    sol = min_effort(I, T, u_max=None if u_max is None else np.asarray(u_max), tol=opts.tol,
                     **kw)
    return _engine(sol, "min_effort")


def _device_ok(scene, w0, wf, opts) -> bool:
    """Whether a device engine takes this slew: attitude-only hub, rest to rest, no setting
    only the generic path takes, a default first solve."""
    return (not scene.hub.translates and len(scene.parts) == 1 and _rest_to_rest(w0, wf)
            and all(getattr(opts, k) is None for k in _GENERIC_ONLY) and not opts.norm_bound
            and opts.transcription == "radau" and opts.control == "constant")


def _device_kw(scene, objective, angle, axis, q_final, T, opts):
    """The keywords of `wheel_slew` and `cmg_slew` from the options, and the part's
    initial states (``state0``)."""
    part_states = scene.state(**(opts.state0 or {}))[scene.layout[scene.part_names[0]].states]
    kw = dict(objective=objective, T=T, angle=angle, axis=axis, q0=opts.q0, qf=q_final,
              T_max=opts.T_max, starts=opts.starts or DEVICE_STARTS, seed=opts.seed or 0,
              tol=opts.tol, **_common(opts, "time"))
    return kw, part_states


def _wheels(scene, objective, angle, axis, q_final, T, w0, wf, opts):
    """A hub with one `ReactionWheels`, rest to rest: `wheel_slew` (or None)."""
    if not (_device_ok(scene, w0, wf, opts) and isinstance(scene.parts[0], ReactionWheels)
            and opts.polish is not False):
        return None
    part = scene.parts[0]
    kw, W0 = _device_kw(scene, objective, angle, axis, q_final, T, opts)
    sol = wheel_slew(scene.hub.inertia_matrix, part.axes_matrix, np.asarray(part.inertia),
                     torque_max=None if part.u_max is None else np.asarray(part.u_max),
                     speed_max=None if part.speed_max is None else np.asarray(part.speed_max),
                     W0=W0, **kw)
    return _engine(sol, "wheel_slew")


def _cmgs(scene, objective, angle, axis, q_final, T, w0, wf, opts):
    """A hub with one CMG cluster (kind ``'cmgs'``: gimbal-rate drive, exact fidelity, no
    rotor or gimbal inertia -- `dynamics.cmg_spacecraft`'s model), rest to rest: `cmg_slew`
    (or None)."""
    part = scene.parts[0] if len(scene.parts) == 1 else None
    if not (part is not None and getattr(part, "kind", None) == "cmgs"
            and _device_ok(scene, w0, wf, opts) and opts.polish is not True
            and getattr(part, "drive", "rate") == "rate"
            and getattr(part, "fidelity", "exact") == "exact"
            and not getattr(part, "rotor_inertia", None)
            and not getattr(part, "gimbal_inertia", None)):
        return None
    geometry = ClusterGeometry(np.asarray(part.gimbal_axes, float).reshape(3, -1),
                               np.asarray(part.spin_axes0, float).reshape(3, -1),
                               np.asarray(part.h, float))
    kw, delta0 = _device_kw(scene, objective, angle, axis, q_final, T, opts)
    u_max = getattr(part, "u_max", None)
    sol = cmg_slew(scene.hub.inertia_matrix, geometry,
                   rate_max=None if u_max is None else np.asarray(u_max),
                   min_measure=opts.min_measure, delta0=delta0, **kw)
    return _engine(sol, "cmg_slew")


# ------------------------------------------------------------------ generic path
@cache.constructs
def torque_map(model, x) -> np.ndarray:
    """The hub's angular acceleration per unit control at the state ``x``: ``d(w')/du``.

    Times the hub inertia, the torque each control produces on the hub (`scene_problem`).

    Parameters
    ----------
    model : dynamics.Model
        An assembled scene model (hub rates ``w1..w3`` at ``x[4:7]``).
    x : array_like, shape (nx,)

    Returns
    -------
    numpy.ndarray, shape (3, nu) [rad/s^2 per unit control]

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.scene import ExternalTorque, RigidHub, Scene
    >>> from appdyn.problems.slew.scene_slew import torque_map
    >>> scene = Scene(RigidHub([1.0, 2.0, 2.5]), ExternalTorque())
    >>> torque_map(scene.model(), scene.state())  # I^-1
    array([[1. , 0. , 0. ],
           [0. , 0.5, 0. ],
           [0. , 0. , 0.4]])
    """
    xs, us = ca.SX.sym("x", model.nx), ca.SX.sym("u", model.nu)
    p = ca.DM(model.resolve_p())
    jac = ca.Function("B", [xs, us], [ca.jacobian(model.f(xs, us, p)[4:7], us)])
    return np.array(jac(np.asarray(x, float), np.zeros(model.nu)))


def settling_parts(scene, problem) -> tuple:
    """The parts of ``scene`` that the slew ``problem`` brings to rest: those with a fixed
    final state (`Variable.terminal` ``'rest'``: a damper, a hinged panel, a slosh mass; not
    wheel speeds or gimbal angles, which end free).

    A time-optimal slew of such a scene is solved at once with the bounded control of
    `SlewOptions.control` (piecewise constant by default), from the eigenaxis start alone
    and without the switch-time polish (unless ``starts`` or ``polish=True`` are given;
    should that fail, warm from the verified minimum-effort slew of `EFFORT_HORIZON` times
    its T, and failing that by the pipeline of the other scenes; ``info['settle']`` says
    which):
    its control switches many times to settle the parts' modes, so the polynomial seed
    overshoots its bounds between the nodes and the polish of its many arcs runs out of its
    budget. The README craft (wheels, a damper, a revolute panel; 90 deg): 226 s through
    three polynomial starts, the polish (64 s, not converged), a refinement and a constant
    re-solve on 400 intervals, against one constant-control solve on 200 intervals, 19 s
    (both verified; T = 56.464 and 56.480 s; measured on a loaded machine).

    Parameters
    ----------
    scene : dynamics.scene.Scene
    problem : ocp.Problem
        A slew of ``scene`` (`scene_problem`).

    Returns
    -------
    tuple of str
        Part names, in the scene's order.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.scene import PointMassDamper, ReactionWheels, RigidHub, Scene
    >>> from appdyn.problems.slew.scene_slew import scene_problem, settling_parts
    >>> scene = Scene(RigidHub([10.0, 12.0, 8.0]), ReactionWheels(np.eye(3), 0.05, u_max=0.1),
    ...               PointMassDamper(0.5, 2.0, 0.8, position=[0.5, 0, 0], direction=[0, 1, 0]))
    >>> settling_parts(scene, scene_problem(scene, objective="time", angle=0.3,
    ...                                     axis=[0, 0, 1])[0])
    ('damper',)
    """
    fixed = np.isfinite(np.asarray(problem.x_final, dtype=float))
    return tuple(name for name, lay in scene.layout.items()
                 if name != "hub" and bool(np.any(fixed[lay.states])))


@cache.constructs
def scene_intervals(problem, least: int, horizon: float) -> int:
    """Collocation intervals for a scene's slew ``problem``: at least ``least``, and at least
    `INTERVALS_PER_PERIOD` per period of the fastest oscillation of the model linearized at
    the initial state (a spring-mass damper, a slosh pendulum) over ``horizon``, at most
    `MAX_AUTO_N` (or ``least`` if more).

    Parameters
    ----------
    problem : ocp.Problem
    least : int
    horizon : float [s]
        The expected slew time (the fixed ``T``, or the rough bang-bang time of a free one).

    Returns
    -------
    int

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.scene import ExternalTorque, PointMassDamper, RigidHub, Scene
    >>> from appdyn.problems.slew.scene_slew import scene_intervals, scene_problem
    >>> stiff = Scene(RigidHub([10.0, 12.0, 8.0]), ExternalTorque(),
    ...               PointMassDamper(0.5, 60.0, 0.8, position=[0.5, 0, 0], direction=[0, 1, 0]))
    >>> pb = scene_problem(stiff, objective="effort", T=10.0, angle=0.3, axis=[0, 0, 1])[0]
    >>> scene_intervals(pb, 20, 10.0)  # 10 s of an 11.0 rad/s mode: 17.5 periods
    71
    >>> scene_intervals(scene_problem(Scene(RigidHub([10.0, 12.0, 8.0]), ExternalTorque()),
    ...     objective="effort", T=10.0, angle=0.3, axis=[0, 0, 1])[0], 20, 10.0)  # no mode
    20
    """
    model = problem.model
    xs, us = ca.SX.sym("x", model.nx), ca.SX.sym("u", model.nu)
    f = model.f(xs, us, ca.DM(model.resolve_p()))
    A = np.array(ca.Function("A", [xs, us], [ca.jacobian(f, xs)])(problem.x_initial,
                                                                   np.zeros(model.nu)))
    omega = float(np.max(np.abs(np.linalg.eigvals(A).imag), initial=0.0))
    n = int(np.ceil(INTERVALS_PER_PERIOD * omega * horizon / (2 * np.pi)))
    return max(least, min(n, MAX_AUTO_N))


def scene_problem(scene, *, objective, angle=None, axis=None, q_final=None, T=None, w0=None,
                  wf=None, options=None):
    """The generic slew of a scene: its `ocp.Problem`, the hub's rigid-body problem whose
    guesses are converted, and the converter.

    The problem reads the model alone: states from ``scene.state(q=q0, w=w0, **state0)`` to
    the target (``q_final`` up to sign, ``wf``, each state whose `Variable.terminal` is
    ``'rest'`` at its rest value, the others free), controls and states within
    ``model.bounds``, minimum ``T`` or ``1/2 integral |u|^2 dt``, and the keep-out cone of
    ``options``. The rigid-body problem is the hub's (its inertia, the per-axis torque bound
    ``sigma_min(I B diag(u_max))`` the controls surely produce at the start, `torque_map`);
    a guess converts to the scene by holding the parts at rest (at ``state0``) along the hub's
    path and giving the controls that best produce its torque (least squares, clipped to the
    bounds).

    Parameters
    ----------
    scene : dynamics.scene.Scene
    objective, angle, axis, q_final, T, w0, wf
        As in `slew`.
    options : SlewOptions, optional
        ``q0``, ``T_max``, ``keep_out``, ``state0`` are read.

    Returns
    -------
    problem : ocp.Problem
    rigid : ocp.Problem
        The hub's rigid-body slew (`slew_problem`).
    convert : callable
        A guess dict of ``rigid`` (``t``, ``x`` (7, n), ``u`` (3, n), ``T``) -> one of
        ``problem``.

    Raises
    ------
    ValueError
        As `slew`; also when the controls cannot turn the hub about every axis at the start.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.scene import HeldRotor, ReactionWheels, RigidHub, Scene
    >>> from appdyn.problems.slew import attitude_guess
    >>> from appdyn.problems.slew.scene_slew import scene_problem
    >>> scene = Scene(RigidHub(np.eye(3)), ReactionWheels(np.eye(3), 0.01, u_max=0.1),
    ...               HeldRotor([1, 0, 0], 0.05))
    >>> pb, rigid, convert = scene_problem(scene, objective="time", angle=0.5, axis=[0, 0, 1])
    >>> pb.model.nx, pb.x_final[7:], rigid.model.nx
    (10, array([nan, nan, nan]), 7)
    >>> guess = convert(attitude_guess(rigid, n=5))
    >>> guess["x"].shape, guess["u"].shape
    ((10, 5), (3, 5))
    """
    check_scene(scene)
    objective = one_of(objective, "objective", ("time", "effort"))
    opts = SlewOptions() if options is None else options
    if not isinstance(opts, SlewOptions):
        raise TypeError(f"`options` must be a SlewOptions, got {type(opts).__name__}")
    model = scene.model()
    names = scene.variable_names()
    q0, qf = targets(opts.q0, q_final, angle, axis, qf_name="q_final")
    w0, wf = vector3(w0, "w0", [0, 0, 0]), vector3(wf, "wf", [0, 0, 0])
    state0 = dict(opts.state0 or {})
    x0 = scene.state(q=q0, w=w0, **state0)
    xf = scene.state(q=qf, w=wf)
    xf[[names["terminal"][s] == "free" for s in model.states]] = np.nan
    xf[:4] = np.nan
    for block in quaternion_blocks(scene):  # at rest up to sign: the vector part only
        xf[block.stop - 1] = np.nan
    lo, hi = model.limits("controls")
    I = scene.hub.inertia_matrix
    torque = I @ torque_map(model, x0)
    scale = np.where(np.isfinite(hi) & (hi > 0), hi, 1.0)
    sigma = np.linalg.svd(torque * scale, compute_uv=False)
    if sigma.size < 3 or sigma[-1] <= 1e-9 * max(sigma[0], 1e-300):
        raise ValueError(f"the scene's controls {list(model.controls)} do not turn the hub "
                         f"about every axis at the start (torque map of rank "
                         f"{int(np.sum(sigma > 1e-9 * max(sigma[0], 1e-300)))}): add a part "
                         f"that acts about the missing axis")
    body_max = float(sigma[-1])
    horizon = slew_horizon(objective, T, opts.T_max,
                           rough_time(I, q0, qf, np.full(3, body_max)))
    path = () if opts.keep_out is None else (_keep_out(opts.keep_out),)
    problem = Problem(model, T=horizon, x_initial=x0, x_final=xf, u_bounds=(lo, hi),
                      x_bounds=model.limits("states"), q_final=qf, path=path,
                      name=f"{scene.name or 'scene'} slew ({objective})", **slew_costs(objective))
    # (its checks: the keep-out cone clear at both ends)
    rigid = slew_problem(I, objective=objective, T=None if objective == "time" else horizon,
                         q0=q0, qf=qf, u_max=body_max, w0=w0, wf=wf, keep_out=opts.keep_out)
    to_controls = np.linalg.pinv(torque)
    def convert(guess):
        t, xr = guess["t"], guess["x"]
        x = np.column_stack([scene.state(q=xr[:4, k], w=xr[4:7, k], **state0)
                             for k in range(t.size)])
        u = np.clip(to_controls @ guess["u"], lo[:, None], hi[:, None])
        return dict(t=t, x=x, u=u, T=guess["T"])

    return problem, rigid, convert


def quaternion_blocks(scene) -> list:
    """The parts' unit-quaternion coordinates: runs of four coordinates of one part at rest
    ``(0, 0, 0, 1)`` whose norm the model's rates preserve (``p . p' = 0`` at random states
    and controls), as slices of the state. Read from the model alone (a ball hinge's
    relative attitude, ...).

    A slew holds such a block at rest at the end by its vector part only (the norm keeps the
    fourth): fixing all four over-determines the end and IPOPT then stalls (a ball-hinged
    panel, 30 s: ``Solved_To_Acceptable_Level`` after 165 s, measured).

    Parameters
    ----------
    scene : dynamics.scene.Scene

    Returns
    -------
    list of slice

    Examples
    --------
    >>> from appdyn.dynamics.scene import ExternalTorque, RigidHub, Scene
    >>> from appdyn.problems.slew.scene_slew import quaternion_blocks
    >>> quaternion_blocks(Scene(RigidHub([1.0, 2.0, 2.5]), ExternalTorque()))  # not the hub's
    []
    """
    model = scene.model()
    rest = np.array([scene.variable_names()["rest"][s] for s in model.states])
    rng = np.random.default_rng(0)
    blocks = []
    for name, lay in scene.layout.items():
        if name == "hub":
            continue
        for k in range(lay.coords.start, lay.coords.stop - 3):
            if not np.array_equal(rest[k:k + 4], [0.0, 0.0, 0.0, 1.0]):
                continue
            preserved = True
            for _ in range(3):
                x = rng.normal(size=model.nx)
                x[k:k + 4] /= np.linalg.norm(x[k:k + 4])
                xdot = np.asarray(model.rhs(x, rng.normal(size=model.nu)), dtype=float)
                preserved &= abs(x[k:k + 4] @ xdot[k:k + 4]) <= 1e-12 * max(
                    1.0, np.linalg.norm(xdot[k:k + 4]))
            if preserved:
                blocks.append(slice(k, k + 4))
    return blocks


def _keep_out(cone) -> Constraint:
    """The keep-out cone on the hub attitude ``x[0:4]`` of a model of any size."""
    b, s = ca.DM(cone.boresight), ca.DM(cone.direction)
    return Constraint(lambda x, u, p: ca.dot(b, ca.mtimes(dcm_from_quat(x[:4]), s))
                      - np.cos(cone.half_angle), name="keep_out")
