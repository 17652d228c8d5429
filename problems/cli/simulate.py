"""``appdyn simulate torque-free``: integrate a torque-free rigid body and check it against
the Jacobi-elliptic solution (`problems.torque_free`). ``appdyn simulate launch-vehicle``: the
launch-vehicle autopilot's response to an attitude error and a wind gust
(`problems.stability.launch_vehicle_response`). ``appdyn simulate hinged``: two rigid bodies
joined by a ball or revolute hinge, as a scene in minimal coordinates (`dynamics.hinged.hinged_scene`)
or the multiplier model (`dynamics.hinged_bodies`), checked by the latter's invariants."""
from __future__ import annotations

import re
import sys

from appdyn.problems.cli.common import PLOT_SUFFIXES, Progress, inertia_matrix, progress_enabled
from appdyn.problems.cli.common import integer as _integer
from appdyn.problems.cli.common import number as _number
from appdyn.problems.cli.common import output_file as _output_file
from appdyn.problems.cli.common import positive as _positive
from appdyn.problems.cli.common import same_file, save_figure
from appdyn.problems.cli.common import vector as _vector
from appdyn.problems.cli.common import finish, write_json, write_outputs
from appdyn.problems.cli.stability import (add_launch_vehicle_options, call_naming_parts, check_flight,
                                   launch_vehicle_kwargs)

__all__ = ["add_parser", "check", "run", "FIXED_STEP", "HINGED_TOL", "HINGED_CONSERVED",
           "HINGED_MODELS"]

#: methods that take ``--steps``
FIXED_STEP = ("rk4", "rk8", "lie")


def _add_outputs(parser, plot_what, json_what) -> None:
    """``--plot``, ``--json``, ``--progress`` and ``--quiet`` of a ``simulate`` case."""
    parser.add_argument("--plot", metavar="FILE.png", type=_output_file(PLOT_SUFFIXES),
                        help=f"save {plot_what} (.png, .pdf or .svg)")
    parser.add_argument("--json", metavar="FILE", type=_output_file(),
                        help=f"write {json_what} as JSON")
    parser.add_argument("--progress", action="store_true",
                        help="progress lines on stderr (default: only when stderr is a "
                             "terminal)")
    parser.add_argument("--quiet", action="store_true", help="no progress lines")


def add_parser(subparsers):
    """Add ``simulate`` (cases ``torque-free``, ``launch-vehicle``, ``hinged``) to
    ``subparsers``."""
    sim = subparsers.add_parser("simulate", help="simulate a model and check it against a truth")
    sim_sub = sim.add_subparsers(dest="case", required=True)
    tf = sim_sub.add_parser(
        "torque-free", help="torque-free rigid body vs the Jacobi-elliptic solution",
        description="Integrate a torque-free rigid body and compare the body rates with the "
                    "Jacobi-elliptic solution. Exit status 1 when the integrator fails or the "
                    "truth check fails: |w - w_exact| <= atol + rtol |w_exact| at every "
                    "output time and axis (plus a round-off floor 10 eps |w0| (1 + |w0| "
                    "t_final)), or max |w - w_exact| <= tol |w0| with --tol. Fixed-step "
                    "methods (rk4, rk8, lie) do not use rtol/atol, but the check does.")
    tf.set_defaults(_parser=tf)
    tf.add_argument("--inertia", type=_vector((3, 9)), required=True,
                    help="principal moments I1,I2,I3 or 9 matrix entries [kg m^2]")
    tf.add_argument("--w0", type=_vector((3,)), required=True, help="initial body rates [rad/s]")
    tf.add_argument("--t-final", type=_positive, default=50.0, help="final time [s] (50)")
    tf.add_argument("--points", type=_integer(2), default=1001, help="output points (1001)")
    tf.add_argument("--method", default="auto",
                    choices=["auto", "dop853", "cvodes", *FIXED_STEP], help="integrator (auto)")
    tf.add_argument("--steps", type=_integer(1),
                    help="steps per output interval, fixed-step methods only (1)")
    tf.add_argument("--rtol", type=_positive, default=1e-10,
                    help="relative tolerance; also the accuracy the truth check asks (1e-10)")
    tf.add_argument("--atol", type=_positive, default=1e-12,
                    help="absolute tolerance [rad/s]; also used by the truth check (1e-12)")
    tf.add_argument("--tol", type=_positive,
                    help="truth check: require max |w - w_exact| <= TOL |w0| instead")
    _add_outputs(tf, "rates, polhode and drift plot", "the summary")
    _add_launch_vehicle(sim_sub)
    _add_hinged(sim_sub)
    return sim


def _add_launch_vehicle(sim_sub) -> None:
    lv = sim_sub.add_parser(
        "launch-vehicle", help="launch-vehicle autopilot: response to an attitude error and a gust",
        description="Simulate the launch vehicle with its attitude/rate autopilot (RP-1262 "
                    "Sec. 5.4) from an attitude error --psi0, optionally through a '1 - cosine' "
                    "lateral gust (needs --aero): attitude, deflection, slosh, bending. Exit "
                    "status 1 when the integrator fails or cannot verify its tolerance.")
    lv.set_defaults(_parser=lv)
    add_launch_vehicle_options(lv)
    lv.add_argument("--deflection-limit", type=_positive, metavar="DEG",
                    help="actuator deflection limit +-DEG, with --actuator")
    lv.add_argument("--rate-limit", type=_positive, metavar="DEG_S",
                    help="actuator rate limit [deg/s], with --actuator")
    lv.add_argument("--psi0", type=_number, default=0.0, metavar="DEG",
                    help="initial attitude error [deg] (0)")
    lv.add_argument("--gust", type=_number, metavar="SPEED",
                    help="peak lateral wind of a '1 - cosine' gust [m/s], with --aero")
    lv.add_argument("--gust-start", type=_number, metavar="T", help="gust start [s] (1)")
    lv.add_argument("--gust-duration", type=_positive, metavar="T",
                    help="gust duration [s] (2)")
    lv.add_argument("--t-final", type=_positive, default=10.0, help="final time [s] (10)")
    lv.add_argument("--points", type=_integer(2), default=1001, help="output points (1001)")
    lv.add_argument("--rtol", type=_positive, default=1e-8, help="relative tolerance (1e-8)")
    _add_outputs(lv, "attitude, deflection, slosh, bending and gust plots",
                 "the summary and time histories")


def _check_launch_vehicle(parser, args) -> None:
    check_flight(parser, args)
    for flag in ("deflection_limit", "rate_limit"):
        if getattr(args, flag) is not None and args.actuator is None:
            parser.error(f"argument --{flag.replace('_', '-')}: only with --actuator")
    if args.gust is not None and args.aero is None:
        parser.error("argument --gust: needs --aero (the wind acts through the angle of attack)")
    for flag in ("gust_start", "gust_duration"):
        if getattr(args, flag) is not None and args.gust is None:
            parser.error(f"argument --{flag.replace('_', '-')}: only with --gust")
    if args.gust_start is not None and args.gust_start < 0:
        parser.error(f"argument --gust-start: expected a number >= 0, got {args.gust_start}")
    if args.psi0 == 0 and not args.gust:
        parser.error("argument --psi0: nothing excites the vehicle; give --psi0 or --gust")


def check(parser, args) -> None:
    """Checks across options, as argparse errors on ``parser`` (exit status 2)."""
    if args.case == "launch-vehicle":
        _check_launch_vehicle(parser, args)
    elif args.case == "hinged":
        _check_hinged(parser, args)
    elif args.steps is not None and args.method not in FIXED_STEP:
        parser.error(f"argument --steps: only with a fixed-step --method "
                     f"({', '.join(FIXED_STEP)}), got --method {args.method}")
    if same_file(args.plot, args.json):
        parser.error("argument --json: the same file as --plot")


def _run_launch_vehicle(args) -> int:
    import math
    from dataclasses import replace

    from appdyn.problems.stability import launch_vehicle_response

    kwargs = launch_vehicle_kwargs(args)
    if args.deflection_limit or args.rate_limit:  # degrees on the command line
        limit, rate = (None if v is None else math.radians(v)
                       for v in (args.deflection_limit, args.rate_limit))
        kwargs["actuator"] = replace(kwargs["actuator"], rate_limit=rate,
                                     deflection_limits=None if limit is None else (-limit, limit))
    progress = Progress("simulate launch-vehicle: steps", enabled=progress_enabled(args))
    try:
        result = call_naming_parts(
            launch_vehicle_response, **kwargs, psi0=math.radians(args.psi0),
            gust_speed=args.gust or 0.0,
            gust_start=1.0 if args.gust_start is None else args.gust_start,
            gust_duration=args.gust_duration or 2.0, t_final=args.t_final, points=args.points,
            rtol=args.rtol, progress=progress if progress.enabled else None)
    finally:
        progress.close()
    return finish(result, "simulate launch-vehicle", plot=args.plot, json=args.json)


def run(args) -> int:
    """Simulate, print the report, write ``--plot``/``--json``; 0 when verified, else 1."""
    from appdyn.problems.torque_free import torque_free

    if args.case == "launch-vehicle":
        return _run_launch_vehicle(args)
    if args.case == "hinged":
        return _run_hinged(args)

    progress = Progress("simulate torque-free: steps", enabled=progress_enabled(args))
    try:
        report = torque_free(inertia_matrix(args.inertia), args.w0, t_final=args.t_final,
                             n_points=args.points, method=args.method, rtol=args.rtol,
                             atol=args.atol, steps=args.steps, tol=args.tol,
                             progress=progress if progress.enabled else None)
    finally:
        progress.close()
    print(report)
    write_outputs(report, plot=args.plot, json=args.json)
    if not report.integrator_success:
        print(f"appdyn simulate torque-free: integrator failed: {report.message}",
              file=sys.stderr)
    elif not report.verified:
        print(f"appdyn simulate torque-free: {report.check_text}", file=sys.stderr)
    return 0 if report.success else 1


# ------------------------------------------------------------------------------- hinged
#: default check of ``simulate hinged``: relative drift of the conserved invariants and the
#: largest constraint residual [m, m/s; rad, rad/s for a revolute hinge's rows]
HINGED_TOL = 1e-8
#: invariants a free pair of hinged bodies conserves (relative drift checked against --tol)
HINGED_CONSERVED = ("energy", "momentum_linear", "momentum_angular", "quat_norm", "quat_norm_2")
#: the models of ``simulate hinged --model``
HINGED_MODELS = ("scene", "multiplier")
_FLOOR = 1e-17  # zero on the log axes of the drift plot


def _add_hinged(sim_sub) -> None:
    hg = sim_sub.add_parser(
        "hinged", help="two rigid bodies joined by a ball or revolute hinge (RP-1262 Ch. 6 Ex. 5)",
        description="Simulate two rigid bodies joined by a frictionless ball or revolute hinge "
                    "in free space, both starting with the identity attitude (rk8 fixed step): "
                    "by default the scene in minimal coordinates (a hub with a hinged panel), "
                    "its states mapped to the two bodies; --model multiplier integrates both "
                    "bodies in full (Lagrange multipliers, Baumgarte drift control). The "
                    "multiplier model's invariants check either run. Prints the final states, "
                    "the hinge reaction range and the invariant drift. Exit status 1 when the "
                    "integrator fails, energy, linear and angular momentum or a quaternion norm "
                    "drift by more than --tol (relative; absolute where the initial value is "
                    "0), or the constraint residual exceeds --tol [m, m/s; rad, rad/s].")
    hg.set_defaults(_parser=hg)
    for i in (1, 2):
        hg.add_argument(f"--m{i}", type=_positive, required=True, help=f"mass of body {i} [kg]")
        hg.add_argument(f"--inertia{i}", type=_vector((3, 9)), required=True,
                        help=f"body {i}: principal moments or 9 matrix entries about its mass "
                             "centre [kg m^2]")
        hg.add_argument(f"--r{i}", type=_vector((3,)), required=True,
                        help=f"hinge point from body {i}'s mass centre, body-{i} axes [m]")
    hg.add_argument("--kind", choices=["ball", "revolute"], default="ball",
                    help="hinge kind (ball)")
    hg.add_argument("--model", choices=HINGED_MODELS, default="scene",
                    help="scene: minimal coordinates, the hinge holds by construction; "
                         "multiplier: two free bodies held by Lagrange multipliers (scene)")
    hg.add_argument("--axis", type=_vector((3,)),
                    help="revolute hinge axis, unit vector in body-1 axes (= body-2 axes at "
                         "the start)")
    hg.add_argument("--w1", type=_vector((3,)), required=True, help="body 1 rates [rad/s]")
    hg.add_argument("--w2", type=_vector((3,)), required=True,
                    help="body 2 rates [rad/s] (revolute: w2 - w1 along --axis)")
    hg.add_argument("--v1", type=_vector((3,)), help="body 1 mass-centre velocity [m/s] (0)")
    hg.add_argument("--t-final", type=_positive, default=10.0, help="final time [s] (10)")
    hg.add_argument("--points", type=_integer(2), default=201, help="output points (201)")
    hg.add_argument("--steps", type=_integer(1), default=10,
                    help="rk8 steps per output interval (10)")
    hg.add_argument("--tol", type=_positive, default=HINGED_TOL,
                    help=f"check: largest invariant drift and constraint residual "
                         f"({HINGED_TOL:g})")
    hg.add_argument("--no-stabilization", action="store_true",
                    help="--model multiplier: no Baumgarte drift control (the constraints "
                         "drift with the integration error)")
    hg.add_argument("--no-jit", action="store_true",
                    help="do not compile the integration loop to C (faster for short runs)")
    _add_outputs(hg, "rates, hinge reaction and drift with and without stabilization",
                 "the summary and time histories")


def _check_hinged(parser, args) -> None:
    if args.kind == "revolute" and args.axis is None:
        parser.error("argument --axis: needed with --kind revolute")
    if args.kind == "ball" and args.axis is not None:
        parser.error("argument --axis: only with --kind revolute")


def _hinged_run(args, stabilized, progress=None, model_kind=None):
    """``(model, SimulationResult)`` of the hinged bodies: the multiplier model with or
    without drift control, or (``model_kind='scene'``, the default ``args.model``) the scene
    run with its states mapped to the two bodies and the multiplier model's invariants."""
    import numpy as np

    from appdyn.dynamics import hinged_bodies, simulate

    kwargs = {} if stabilized else {"stabilization": None}
    try:
        model = hinged_bodies(args.m1, inertia_matrix(args.inertia1), args.m2,
                              inertia_matrix(args.inertia2), args.r1, args.r2, kind=args.kind,
                              axis=args.axis, **kwargs)
    except ValueError as exc:  # the library's `I1`/`I2` are the options --inertia1/2
        m = re.match(r"`I([12])`", str(exc))
        if m is None:
            raise
        raise ValueError(f"argument --inertia{m.group(1)}: {exc}") from None
    identity = [0.0, 0.0, 0.0, 1.0]
    v1 = np.zeros(3) if args.v1 is None else args.v1
    x0 = model.initial_state(identity, args.w1, v1, identity, args.w2)
    t = np.linspace(0.0, args.t_final, args.points)
    options = dict(method="rk8", steps=args.steps, jit=False if args.no_jit else None,
                   progress=progress)
    if (model_kind or args.model) == "multiplier":
        return model, simulate(model, x0, t, invariants=True, **options)
    return model, _scene_run(args, model, x0, t, options)


def _scene_run(args, model, x0, t, options):
    """The `dynamics.hinged.hinged_scene` run from the two-body state ``x0`` (identity attitudes),
    as a `SimulationResult` in the two-body states with ``model``'s invariants."""
    from dataclasses import replace

    import casadi as ca
    import numpy as np

    from appdyn.dynamics import simulate
    from appdyn.dynamics.hinged import HINGED_STATES, hinged_scene, two_body_state

    scene = hinged_scene(args.m1, inertia_matrix(args.inertia1), args.m2,
                         inertia_matrix(args.inertia2), args.r1, args.r2, args.kind, args.axis)
    at = {s: x0[HINGED_STATES.index(s)] for s in HINGED_STATES}
    w1 = np.array([at[f"w{i}"] for i in (1, 2, 3)])
    w_rel = np.array([at[f"w{i}_2"] for i in (1, 2, 3)]) - w1   # body axes agree at the start
    speeds = [float(w_rel @ scene.parts[0].axis)] if args.kind == "revolute" else w_rel
    lay = scene.layout[scene.part_names[0]]
    y0 = scene.state(w=w1, v=[at["v1"], at["v2"], at["v3"]], r=[at["x"], at["y"], at["z"]])
    y0[lay.speeds] = speeds
    res = simulate(scene.model(), y0, t, **options)
    x = np.asarray(two_body_state(scene).map(t.size)(res.x))
    p = ca.DM.zeros(0, t.size)
    invariants = {k: np.asarray(f.map(t.size)(x, p)) for k, f in model.invariants.items()}
    return replace(res, x=x, invariants=invariants, _dense=None)


def _two_body_blocks() -> dict:
    """The named state blocks of `dynamics.hinged_bodies` (``q1``, ``w1``, ``v1``,
    ``position1``, then body 2's), as slices of its ``x``."""
    from appdyn.dynamics.hinged import HINGED_STATES
    from appdyn.problems.stability.common import block

    ends = {"q": ("q1", "q4"), "w": ("w1", "w3"), "v": ("v1", "v3"), "position": ("x", "z")}
    return {f"{k}{i}": block(HINGED_STATES, a + sfx, b + sfx)
            for i, sfx in ((1, ""), (2, "_2")) for k, (a, b) in ends.items()}


def _drift_history(res, name):
    """``|I(t) - I(0)| / |I(0)|`` (absolute where ``I(0) = 0``) along the run."""
    import numpy as np

    v = np.atleast_2d(np.asarray(res.invariants[name], dtype=float))
    d = np.linalg.norm(v - v[:, :1], axis=0)
    ref = float(np.linalg.norm(v[:, 0]))
    return d / ref if ref > 0 else d


def _hinged_summary(args, res, stabilized) -> dict:
    import numpy as np

    inv = res.invariants
    drift = {k: float(np.max(_drift_history(res, k))) for k in HINGED_CONSERVED}
    residual = np.asarray(inv["constraint_residual"], dtype=float)
    force = np.linalg.norm(np.asarray(inv["hinge_force"], dtype=float), axis=0)
    torque = np.linalg.norm(np.asarray(inv["hinge_torque"], dtype=float), axis=0)
    x = res.x[:, -1]
    worst = max([*drift.values(), *residual.max(axis=1)])
    verified = bool(res.success and np.isfinite(worst) and worst <= args.tol)
    if not res.success:
        message = f"integrator failed: {res.message}"
    elif verified:
        message = f"invariants conserved and constraint residual within {args.tol:g}"
    else:
        bad = [k for k, v in drift.items() if not v <= args.tol]
        bad += [n for n, v in zip(("residual position", "residual velocity"),
                                  residual.max(axis=1)) if not v <= args.tol]
        message = f"{', '.join(bad)} above --tol {args.tol:g} (largest {worst:.3g})"
    return {
        "case": "hinged", "kind": args.kind, "model": args.model, "success": verified,
        "message": message,
        "parameters": {"model": args.model, "m1": args.m1, "inertia1": args.inertia1, "r1": args.r1,
                       "m2": args.m2, "inertia2": args.inertia2, "r2": args.r2,
                       "axis": args.axis, "w1": args.w1, "w2": args.w2, "v1": args.v1,
                       "t_final": args.t_final, "points": args.points, "steps": args.steps,
                       "stabilization": stabilized, "tol": args.tol},
        "method": res.method, "wall_time": res.wall_time, "compiled": res.compiled,
        "final": {"t": float(res.t[-1]), **{k: x[sl] for k, sl in _two_body_blocks().items()}},
        "hinge_force_range": [float(force.min()), float(force.max())],
        "hinge_torque_range": [float(torque.min()), float(torque.max())],
        "drift": drift,
        "constraint_residual_max": {"position": float(residual[0].max()),
                                    "velocity": float(residual[1].max())},
        "history": {"t": res.t, "w1": res.x[_two_body_blocks()["w1"]],
                    "w2": res.x[_two_body_blocks()["w2"]],
                    "hinge_force": inv["hinge_force"], "hinge_torque": inv["hinge_torque"],
                    "constraint_residual": residual},
    }


_MODEL_TEXT = {"scene": "scene in minimal coordinates (hub + hinged panel)",
               "multiplier": "two free bodies with Lagrange multipliers"}


def _hinged_text(s) -> str:
    vec = lambda v: "[" + ", ".join(f"{float(c):+.9f}" for c in v) + "]"  # noqa: E731
    f, p = s["final"], s["parameters"]
    units = "m, m/s" if s["kind"] == "ball" else "m or rad, m/s or rad/s"
    lines = [
        f"Hinged bodies, {s['kind']} hinge (RP-1262 Ch. 6 Ex. 5): {_MODEL_TEXT[s['model']]}, "
        f"{s['method']}, {p['steps']} steps per output interval, {p['points']} points, "
        f"t_final {p['t_final']:g} s",
        "  drift control: " + ("none needed (minimal coordinates)" if s["model"] == "scene"
                               else "Baumgarte stabilization" if p["stabilization"]
                               else "none"),
        f"final state (t = {f['t']:g} s):",
        f"  body 1  w {vec(f['w1'])} rad/s  v {vec(f['v1'])} m/s",
        f"          q {vec(f['q1'])}",
        f"  body 2  w {vec(f['w2'])} rad/s  v {vec(f['v2'])} m/s",
        f"          q {vec(f['q2'])}",
        "hinge reaction (body 1 on body 2, inertial axes):",
        "  |force|   {:.6g} .. {:.6g} N".format(*s["hinge_force_range"]),
        "  |torque|  {:.6g} .. {:.6g} N m".format(*s["hinge_torque_range"]),
        "invariant drift (max |I - I0| / |I0|; absolute where I0 = 0):",
        *(f"  {k:<18} {v:.3e}" for k, v in s["drift"].items()),
        f"constraint residual (max, {units}):",
        "  {:<18} {:.3e}".format("position", s["constraint_residual_max"]["position"]),
        "  {:<18} {:.3e}".format("velocity", s["constraint_residual_max"]["velocity"]),
        f"check: {'PASSED' if s['success'] else 'FAILED'} ({s['message']}); "
        f"wall time {s['wall_time']:.3f} s" + (" (compiled)" if s["compiled"] else ""),
    ]
    return "\n".join(lines)


def _hinged_figure(args, runs):
    """Rates, hinge reaction, and drift/residual of ``runs`` = {label: result}, the main run
    first."""
    import numpy as np

    from appdyn.dynamics.figures import finish_figure, new_figure

    main_run = next(iter(runs.values()))
    fig = new_figure((11.0, 8.0))
    ax = fig.subplots(2, 2)
    t = main_run.t
    rates = _two_body_blocks()
    w1, w2 = main_run.x[rates["w1"]], main_run.x[rates["w2"]]
    for i, c in enumerate("rgb"):
        ax[0, 0].plot(t, w1[i], c, label=f"w{i + 1} body 1")
        ax[0, 0].plot(t, w2[i], c + "--", label=f"w{i + 1} body 2")
    ax[0, 0].set(xlabel="t [s]", ylabel="rate [rad/s]", title="body rates")
    ax[0, 0].legend(fontsize=7, ncol=2)
    force = np.asarray(main_run.invariants["hinge_force"])
    for i, c in enumerate("rgb"):
        ax[0, 1].plot(t, force[i], c, label=f"F{'xyz'[i]}")
    ax[0, 1].plot(t, np.linalg.norm(main_run.invariants["hinge_torque"], axis=0), "k--",
                  label="|torque| [N m]")
    ax[0, 1].set(xlabel="t [s]", ylabel="[N]", title="hinge reaction on body 2 (inertial)")
    ax[0, 1].legend(fontsize=7)
    for (tag, res), style in zip(runs.items(), ("-", ":")):
        for name, c in zip(("energy", "momentum_linear", "momentum_angular"), "rgb"):
            ax[1, 0].semilogy(res.t, np.maximum(_drift_history(res, name), _FLOOR),
                              c + style, label=f"{name} ({tag})")
        r = np.asarray(res.invariants["constraint_residual"])
        ax[1, 1].semilogy(res.t, np.maximum(r[0], _FLOOR), "b" + style,
                          label=f"position ({tag})")
        ax[1, 1].semilogy(res.t, np.maximum(r[1], _FLOOR), "r" + style,
                          label=f"velocity ({tag})")
    for a in (ax[1, 0], ax[1, 1]):
        a.axhline(args.tol, color="k", lw=0.8, alpha=0.5, label=f"--tol {args.tol:g}")
        a.legend(fontsize=7)
    ax[1, 0].set(xlabel="t [s]", ylabel="relative drift", title="invariant drift")
    ax[1, 1].set(xlabel="t [s]", ylabel="|residual|",
                 title="constraint residual: " + " vs ".join(runs))
    for a in ax.flat:
        a.grid(True, alpha=0.3)
    return finish_figure(fig)


def _run_hinged(args) -> int:
    stabilized = not args.no_stabilization
    progress = Progress("simulate hinged: steps", enabled=progress_enabled(args))
    try:
        _, res = _hinged_run(args, stabilized, progress if progress.enabled else None)
    finally:
        progress.close()
    summary = _hinged_summary(args, res, stabilized)
    print(_hinged_text(summary))
    if args.plot:  # the comparison: the multiplier model (with the other drift control)
        tag = {True: "stabilized", False: "unstabilized"}
        if args.model == "scene":
            runs = {"scene": res, f"multipliers, {tag[stabilized]}":
                    _hinged_run(args, stabilized, model_kind="multiplier")[1]}
        else:
            runs = {tag[stabilized]: res,
                    tag[not stabilized]: _hinged_run(args, not stabilized)[1]}
        save_figure(_hinged_figure(args, runs), args.plot)
        print(f"plot written to {args.plot}")
    if args.json:
        write_json(summary, args.json)
        print(f"report written to {args.json}")
    if not summary["success"]:
        print(f"appdyn simulate hinged: {summary['message']}", file=sys.stderr)
    return 0 if summary["success"] else 1
