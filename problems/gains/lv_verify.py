"""The verification of a launch-vehicle gain design (`problems.gains.launch_vehicle`): the
stability report and margins, the re-simulation of every scenario, the limits, and the
diagnosis of an infeasible design."""
from __future__ import annotations

import math

import casadi as ca
import numpy as np

from appdyn import ocp
from appdyn.dynamics import cache
from appdyn.dynamics.launch_vehicle import launch_vehicle as vehicle_model
from appdyn.ocp.status import describe, status_code

from .result import STATUS_LIMITS, STATUS_UNSTABLE, GainDesign
from .lv_data import GM_INF, LaunchVehicle
from .lv_model import closed_loop_model, initial_states

__all__ = ["margins_of", "compensator", "stability_check", "resimulate", "limit_text",
           "violations", "node_peaks", "INFEASIBLE", "diagnose"]


# ------------------------------------------------------------------- verification
def margins_of(report, L) -> dict:
    """The report's margins of the loop ``L`` and its lower and upper gain margins
    (`stability.loop.gain_margins`)."""
    from appdyn.problems.stability.loop import gain_margins

    out = {}
    m = report.margins
    if m is not None:
        out.update(gain_margin=m.gain_margin, gain_margin_db=m.gain_margin_db,
                   phase_margin_deg=m.phase_margin, stability_margin=m.stability_margin,
                   phase_crossover=m.phase_crossover, gain_crossover=m.gain_crossover)
    gms = gain_margins(L)[0]  # (the crossovers that change the closed loop's stability)
    gms = gms[gms < GM_INF]
    lower, upper = gms[gms < 1], gms[gms > 1]
    out["gain_margin_lower"] = float(lower.max()) if lower.size else 0.0
    out["gain_margin_upper"] = float(upper.min()) if upper.size else math.inf
    return out


def compensator(gains, filter_tau):
    """``u = -C(s) [psi, psi_dot]``: the PD law with the integral and the filter, as a
    ``control.StateSpace`` (states ``psi_integral``, ``command``)."""
    import control

    k, kd = float(gains[0]), float(gains[1])
    ki = float(gains[2]) if len(gains) > 2 else None
    # law = k psi + kd psi' + ki z, z' = psi; filter tau_f c' = law - c, u = -c
    names = (["psi_integral"] if ki is not None else []) + (["command"] if filter_tau else [])
    n = len(names)
    A, B = np.zeros((n, n)), np.zeros((n, 2))
    C, D = np.zeros((1, n)), np.array([[k, kd]])
    if ki is not None:
        B[0, 0] = 1.0
        C[0, 0] = ki
    if filter_tau:
        A[-1, :] = C[0] / filter_tau
        A[-1, -1] = -1.0 / filter_tau
        B[-1, :] = D[0] / filter_tau
        C, D = np.eye(n)[-1:], np.zeros((1, 2))
    return control.ss(A, B, C, D, states=names, inputs=["psi_sensed", "psi_dot_sensed"],
                      outputs=["command"], name="autopilot")


def stability_check(veh: LaunchVehicle, gains, *, filter_tau=None) -> tuple[dict, object]:
    """The stability report of the designed loop: `problems.stability.launch_vehicle` for
    the PD law; for the integral/filter law its plant (recovered from that report as
    ``A = A_cl + B K C``) under the compensator, through `problems.stability.loop`."""
    import control

    from appdyn.problems.stability import launch_vehicle as stability_report
    from appdyn.problems.stability import loop, loop_transfer

    rep = stability_report(k_psi=gains[0], k_psidot=gains[1], **veh.stability_kwargs())
    L = loop_transfer(rep)
    if len(gains) > 2 or filter_tau:
        ss = rep.ss
        K = np.array([[gains[0], gains[1]]])
        A = np.asarray(ss.A) + np.asarray(ss.B) @ K @ np.asarray(ss.C)
        plant = control.ss(A, ss.B, ss.C, np.zeros((2, 1)), states=list(ss.state_labels),
                           inputs=list(ss.input_labels), outputs=list(ss.output_labels),
                           name="launch_vehicle")
        controller = compensator(gains, filter_tau)
        rep = loop(plant, controller, title="launch vehicle, dynamic autopilot")
        L = control.series(plant, controller)
    ver = {"verdict": rep.verdict, "stable": rep.verdict == "asymptotically stable",
           "poles": [complex(z) for z in rep.eigenvalues],
           "modes": [{"label": m.label, "eigenvalue": complex(m.eigenvalue), "wn": m.wn,
                      "zeta": m.zeta} for m in rep.modes],
           "least_damping_ratio": float(min((m.zeta for m in rep.modes
                                             if np.isfinite(m.zeta)), default=math.nan)),
           "closed_form_check": rep.message}
    ver.update(margins_of(rep, L))
    return ver, rep


@cache.constructs
def _outputs(veh: LaunchVehicle, gains: np.ndarray, scenarios, filter_tau, dynamic: bool,
             n: int):
    """`resimulate`'s model and outputs (built under the construction lock): ``(model, X0
    (the scenarios' initial states, dynamic law) or None, the outputs Function mapped over
    ``n`` points, the indices of psi and psi_dot)``."""
    X0 = None
    if dynamic:
        model, out = closed_loop_model(veh, veh.actuator, gains.size > 2, filter_tau)
        X0 = initial_states(veh, scenarios, model.states)
        xs = ca.SX.sym("x", model.nx)
        fun = ca.Function("outputs", [xs, ca.SX.sym("w", 0)], [ca.vertcat(*out(xs, gains))])
        i_psi, i_rate = model.states.index("psi"), model.states.index("psi_dot")
    else:
        model = vehicle_model(thrust=veh.thrust, inertia=veh.inertia, arm=veh.arm,
                              mass=veh.mass, k_psi=float(gains[0]), k_psidot=float(gains[1]),
                              aero=veh.aero, actuator=veh.actuator)
        xs, ps = ca.SX.sym("x", model.nx), ca.SX.sym("p", model.np)
        xdot = model.f(xs, ca.SX(0, 1), ps)
        command = -(gains[0] * xs[2] + gains[1] * xs[5])
        if veh.actuator is not None:
            delta, rate = xs[6], xdot[6]
        else:
            delta, rate = command, -(gains[0] * xs[5] + gains[1] * xdot[5])
        outs = [delta, rate, model.invariants["alpha"](xs, ps) if "alpha" in model.invariants
                else ca.SX(0)]
        fun = ca.Function("outputs", [xs, ps], [ca.vertcat(*outs)])
        i_psi, i_rate = 2, 5
    return model, X0, fun.map(n), i_psi, i_rate


def resimulate(veh: LaunchVehicle, gains, scenarios, horizon, points, *,
                filter_tau=None) -> list:
    """Every scenario re-simulated on a fine grid: on the library's closed-loop vehicle
    (`dynamics.launch_vehicle` with the gains given) for the PD law; for the integral/filter
    law on `closed_loop_model` with the user's actuator (clamps included)."""
    from appdyn.dynamics import simulate

    gains = np.asarray(gains, dtype=float)
    V = veh.velocity or 0.0
    dynamic = gains.size > 2 or bool(filter_tau)
    t = np.linspace(0.0, horizon, points)
    model, X0, outputs, i_psi, i_rate = _outputs(veh, gains, scenarios, filter_tau, dynamic,
                                                 t.size)
    fastest = min([horizon] + [tc for tc in (filter_tau, veh.actuator and
                                             veh.actuator.time_constant) if tc])
    steps = max(4, math.ceil((t[1] - t[0]) / (0.25 * fastest)))
    runs = []
    for i, sc in enumerate(scenarios):
        if dynamic:
            x0, p, w = X0[:, i], gains, np.zeros(0)
        else:
            x0 = np.zeros(model.nx)
            x0[2], x0[3], x0[5] = sc.psi0, V, sc.psi_dot0
            p = w = [0.0, V * math.tan(sc.gust_alpha)] if veh.aero is not None else []
        res = simulate(model, x0, t, p=p, method="rk8", steps=steps, jit=False)
        y = np.asarray(outputs(res.x, ca.repmat(ca.DM(w), 1, t.size)), dtype=float)
        run = {"name": sc.name, "t": t, "x": np.asarray(res.x), "states": model.states,
               "psi": res.x[i_psi], "psi_dot": res.x[i_rate], "delta": y[0],
               "delta_rate": y[1], "alpha": y[2], "gust_alpha": sc.gust_alpha}
        run["peak"] = {key: float(np.max(np.abs(run[key])))
                       for key in ("psi", "psi_dot", "delta", "delta_rate", "alpha")}
        runs.append(run)
    return runs


def limit_text(which, limit, peak, scenario) -> str:
    unit, label = (("deg", "gimbal deflection |delta|") if which == "delta"
                   else ("deg/s", "deflection rate |delta_dot|"))
    return (f"{label} <= {math.degrees(limit):.4g} {unit} (peak {math.degrees(peak):.4g} "
            f"{unit} in scenario {scenario!r})")


def violations(peaks_by_scenario, limits, tol) -> list:
    """``(which, limit, peak, scenario label)`` for each violated limit (the worst scenario)."""
    out = []
    for which, limit in limits.items():
        worst = max(peaks_by_scenario, key=lambda item: item[1][which])
        if worst[1][which] > limit * (1 + tol):
            out.append((which, limit, worst[1][which], worst[0]))
    return out


def node_peaks(model, outputs, sol, K, labels) -> list:
    X = ocp.unstack(sol.x, K)
    fun = outputs.map(X.shape[1])
    out = []
    for k in range(K):
        d, r, _ = (np.asarray(v, dtype=float).ravel() for v in fun(X[:, :, k], ca.repmat(
            ca.DM(sol.p), 1, X.shape[1])))
        out.append((labels[k], {"delta": float(np.max(np.abs(d))),
                                "delta_rate": float(np.max(np.abs(r)))}))
    return out


#: IPOPT statuses that mean "no feasible point" (rather than a convergence failure)
INFEASIBLE = tuple(status_code(name) for name in (
    "Infeasible_Problem_Detected", "Restoration_Failed", "Constraint_Tol_Not_Met",
    "Not_Enough_Degrees_Of_Freedom"))


def diagnose(sol, solve, lim, decay, bounds, fail, peak_of) -> GainDesign:
    """The failed design: which constraint cannot be met (module notes). ``solve(which)``
    solves with the limits ``which`` only; ``peak_of(limit, solution)`` is ``(scenario,
    peaks)`` of the worst scenario."""
    if not solve(()).success:
        text = ", ".join(f"{g} in [{lo:g}, {hi:g}]" for g, (lo, hi) in bounds.items())
        return fail(STATUS_UNSTABLE, f"no gains within gain_bounds ({text}) give a closed loop "
                                     f"stable to {decay:g} 1/s, even without the limits "
                                     f"({describe(sol.status, solver_status=sol.solver_status)})")
    alone = {k: solve((k,)) for k in lim}
    culprits = [k for k in lim if not alone[k].success]
    joint = not culprits
    if joint:  # each limit alone can be met
        if sol.status not in INFEASIBLE:
            return fail(sol.status, f"the NLP was not solved: {sol.message}")
        culprits = list(lim)
    parts = []
    for k in culprits:
        if k == "delta":
            text, unit = f"gimbal deflection |delta| <= {math.degrees(lim[k]):.4g} deg", "deg"
        else:
            text = f"deflection rate |delta_dot| <= {math.degrees(lim[k]):.4g} deg/s"
            unit = "deg/s"
        other = alone[next(o for o in lim if o != k)]
        if other.success:  # the stable design without this limit: how far it goes
            label, peaks = peak_of(k, other)
            text += (f" (designed without it, the stable loop peaks at "
                     f"{math.degrees(peaks[k]):.4g} {unit} in scenario {label!r})")
        parts.append(text)
    msg = (f"the limits cannot be met{' together' if joint else ''} by a loop stable to "
           f"{decay:g} 1/s: {'; '.join(parts)} ({describe(sol.status, solver_status=sol.solver_status)})")
    return fail(STATUS_LIMITS, msg, violated=culprits)


