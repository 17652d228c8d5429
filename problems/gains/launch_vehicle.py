"""`launch_vehicle_gains`: the attitude/rate autopilot gains of a thrust-vectored launch vehicle
with an aerodynamically unstable airframe, designed by multi-scenario direct collocation.

The loop
--------
The vehicle is `dynamics.launch_vehicle` (RP-1262, Sec. 5.4) with `~dynamics.launch_vehicle.Aero`
(centre of pressure ahead of the mass centre: the open loop diverges at
``sqrt(q S C_N_alpha l_cp / I)``) and, optionally, a first-order gimbal
`~dynamics.launch_vehicle.Actuator`. Its autopilot is
``delta_c = -(k_psi psi + k_psidot psi')``; the two gains are the *parameters* of the design
model, shared by every scenario (`ocp.scenario_problem`). The design model is the open-loop
vehicle's own right-hand side with the loop closed symbolically: states
``psi, psi_dot, x_dot, y_dot`` (and ``delta`` with the actuator) and ``wind_y``. The position
``x, y`` is left out (no force depends on it). Optionally the law gains an integral term
``- k_i integral(psi) dt`` (state ``psi_integral``, ``k_i`` a third parameter) and a
first-order command filter ``tau_f c' = law - c`` of given ``tau_f`` (state ``command``:
the deflection, or the actuator's command).

Scenarios and the gust
----------------------
A scenario is an initial attitude error ``psi0``, rate ``psi_dot0`` and a wind gust: a step
of lateral wind present from ``t = 0`` that sets the angle of attack ``alpha_g`` at the start
(``alpha = atan2(wind_y - y_dot, V)`` at ``psi = 0``, so ``wind_y = V tan(alpha_g)``). The
wind enters the vehicle model as its ``wind_y`` parameter, but `ocp.scenario_problem` shares
parameters between scenarios; a per-scenario constant is therefore a *state with zero rate*
(``wind_y' = 0``) whose initial value differs between scenarios. The flight starts along
``X`` at ``velocity`` (``x_dot = V``, ``y_dot = 0``, the gimbal at rest with the actuator).

Cost and limits
---------------
Per scenario ``integral (w_psi psi^2 + w_psi_dot psi'^2 + w_delta delta^2
+ w_rate delta'^2) dt`` over ``horizon``, summed with the scenarios' weights, subject at every
collocation node and at ``t0`` to ``|delta| <= delta_max`` and ``|delta'| <= delta_rate_max``.
With the actuator ``delta`` is its state and ``delta' = (delta_c - delta) / tau``. Without it
``delta = delta_c`` and its rate is exact, from the dynamics (no finite differences):
``delta' = -(k_psi psi' + k_psidot psi'')`` with ``psi''`` the vehicle's own angular
acceleration at the current state and deflection (``delta`` is a function of the state
only, so there is no algebraic loop; with the integral term ``- k_i psi`` is added; with
the filter ``delta' = c'``). The design model drops the actuator's clamps (they would make
the NLP non-smooth); the limits are the design's constraints instead.

A finite horizon would reward a loop that diverges slowly enough to stay within the limits
over it, so the gains are also constrained to the stable set: the linearized closed loop
(about steady flight, in the states the stability report keeps) must have every pole at
``Re <= -min_decay``, imposed as Routh-Hurwitz rows on the gains (its characteristic
polynomial by Faddeev-LeVerrier, symbolic in the gains; `hurwitz_rows`).

Verification
------------
1. `problems.stability.launch_vehicle` with the designed gains: closed-loop poles, damping
   ratios and the classical margins of the loop broken at the deflection (python-control);
   the upper and lower gain margins (`control.stability_margins` with ``returnall``; a
   factor above 1e8, a phase crossover at numerically infinite frequency, counts as none)
   are added. The loop must be asymptotically stable, else ``STATUS_UNSTABLE``. With the
   integral term or the filter, the plant of that report (``A = A_cl + B K C``) under the
   compensator goes through `problems.stability.loop` instead.
2. Every scenario is re-simulated (`dynamics.simulate`) on the library's own closed-loop
   vehicle (`dynamics.launch_vehicle` with the gains given, the user's actuator with its
   clamps, the gust as its ``wind_y`` parameter) on a fine grid; the peaks of ``|delta|``
   and ``|delta'|`` must be within the limits (to ``limit_tol`` relative: the collocation
   enforces them at the nodes only), else ``STATUS_LIMITS``. (With the integral term or the
   filter the library has no closed-loop vehicle: the design model runs, with the user's
   actuator and its clamps.)

Infeasible limits (a gimbal too weak for the gust, a rate limit no gain meets) make IPOPT
fail. The design is then solved again with each limit alone (the stability rows kept): a
limit whose problem stays infeasible is named (both, if each alone can be met but not
together), with the peak the stable design reaches without it; the status is
``STATUS_LIMITS``.
"""
from __future__ import annotations

import math
from typing import Mapping

import numpy as np

from appdyn.config import param
from appdyn import ocp
from appdyn.dynamics.validate import finite_scalar, positive

from .result import STATUS_LIMITS, STATUS_UNSTABLE, GainDesign
from .lv_data import (GAIN_UNITS, LaunchScenario, LaunchVehicle, WEIGHT_KEYS, check_gain_bounds,
                      check_scenarios, check_weights, guess_gains)
from .lv_model import design_model, hurwitz_rows, initial_states
from .lv_verify import diagnose, limit_text, node_peaks, resimulate, stability_check, violations

__all__ = ["LaunchVehicle", "LaunchScenario", "launch_vehicle_gains", "design_model",
           "plot_design", "WEIGHT_KEYS"]


# ------------------------------------------------------------------------ the design
def launch_vehicle_gains(vehicle, scenarios, *, delta_max, delta_rate_max, weights=None,
                         horizon: float = 8.0, N=None, gain_bounds=None,
                         min_decay: float = 0.01, integral: bool = False,
                         filter_time_constant: float | None = None, limit_tol: float = 5e-3,
                         points: int = 801, ipopt_options: Mapping | None = None) -> GainDesign:
    """Design ``k_psi, k_psidot`` of ``delta_c = -(k_psi psi + k_psidot psi')`` for an
    (aerodynamically unstable) thrust-vectored launch vehicle over several scenarios.

    Optionally the law has an integral term, ``delta_c = -(k_psi psi + k_psidot psi'
    + k_i integral(psi) dt)`` (``k_i`` designed too), and a first-order filter of given time
    constant between the law and the deflection command.

    Parameters
    ----------
    vehicle : LaunchVehicle or mapping
        The vehicle data (`LaunchVehicle` fields: ``thrust`` [N], ``inertia`` [kg m^2],
        ``arm`` [m], ``mass`` [kg], ``aero``, ``velocity`` [m/s], ``actuator``).
    scenarios : sequence of LaunchScenario or mappings
        ``K >= 1`` scenarios (``psi0`` [rad], ``psi_dot0`` [rad/s], ``gust_alpha`` [rad],
        ``weight``, ``name``); module notes for the gust.
    delta_max : float [rad]
        Gimbal deflection limit ``|delta| <= delta_max``, ``> 0``.
    delta_rate_max : float [rad/s]
        Deflection-rate limit ``|delta'| <= delta_rate_max``, ``> 0``.
    weights : mapping, optional
        Running-cost weights by term, keys `WEIGHT_KEYS`: ``'psi'`` [1/rad^2 s],
        ``'psi_dot'`` [s/rad^2], ``'delta'`` [1/rad^2 s], ``'delta_rate'`` [s/rad^2]; missing
        keys are 0. Default ``{'psi': 1, 'delta': 1}``.
    horizon : float [s]
        Length of every scenario, ``> 0`` (several closed-loop time constants).
    N : int, optional
        Collocation intervals (Radau, degree 3), ``>= 4`` (default ``appdyn.config``
        ``problems.N``, 40).
    gain_bounds : mapping, optional
        ``{'k_psi': (lo, hi), 'k_psidot': (lo, hi)}`` (and ``'k_i'`` with ``integral``),
        ``0 <= lo < hi``; default (0, 50) each.
    min_decay : float [1/s]
        Stability margin imposed in the NLP: every pole of the linear closed loop (module
        notes) has ``Re <= -min_decay``, ``>= 0`` (Routh-Hurwitz rows on the gains, so that
        a finite horizon cannot reward a slowly diverging loop).
    integral : bool
        Design an integral gain ``k_i`` [rad/(rad s)] as well.
    filter_time_constant : float [s], optional
        ``tau_f > 0`` of a command filter ``tau_f c' = law - c`` (``c`` the deflection, or
        the actuator's command); the law's states start at 0.
    limit_tol : float
        Relative tolerance of the limit check in the re-simulation, ``>= 0``.
    points : int
        Samples of each re-simulated scenario (``>= 11``).
    ipopt_options : mapping, optional
        Passed to `ocp.solve`.

    Returns
    -------
    GainDesign
        ``gains`` ``{'k_psi', 'k_psidot'}``; ``scenarios``: per scenario the re-simulated
        ``'t'`` (points,) [s], ``'x'`` (nx, points) of `dynamics.launch_vehicle`'s closed
        loop (``'states'`` names them), ``'psi'`` [rad], ``'psi_dot'`` [rad/s], ``'delta'``
        [rad], ``'delta_rate'`` [rad/s], ``'alpha'`` [rad] and ``'peak'`` (max absolute value
        of each); ``verification``: the stability report's verdict, poles, modes (``wn``,
        ``zeta``), ``least_damping_ratio``, margins (``gain_margin``, ``gain_margin_lower``,
        ``gain_margin_upper`` [-], ``phase_margin_deg`` [deg], crossovers [rad/s]), the
        re-simulated peaks against the limits and the solve time [s]. ``success`` needs the
        NLP solved, the loop asymptotically stable (else ``STATUS_UNSTABLE``) and the limits
        held in every re-simulated scenario (else ``STATUS_LIMITS``); IPOPT failing on the
        limits is ``STATUS_LIMITS`` too, naming the limit (``verification['violated']``:
        ``'delta'`` and/or ``'delta_rate'``), and gain bounds that admit no loop stable to
        ``min_decay`` are ``STATUS_UNSTABLE``; the gains are then IPOPT's last iterate and
        ``scenarios`` is empty. With ``integral`` or a filter the
        stability report is `problems.stability.loop` on the vehicle's plant (from
        `problems.stability.launch_vehicle`) under the compensator, and the re-simulation
        runs the design model with the user's actuator; ``integral`` adds ``'k_i'`` to the
        gains. (The integral design is slower: about 10x the IPOPT time per iteration
        without an actuator.)

    Raises
    ------
    TypeError
        ``vehicle``, ``scenarios``, ``weights`` or ``gain_bounds`` of the wrong type.
    ValueError
        Naming the argument: non-positive limits, horizon or ``N``; unknown keys; a gust
        without aero; the checks of `LaunchVehicle` and `LaunchScenario`.

    Examples
    --------
    >>> import math
    >>> from appdyn.dynamics.launch_vehicle import Aero
    >>> v = LaunchVehicle(2e6, 4e7, 20.0, 1e5, aero=Aero(3e4, 10.0, 3.0, 5.0), velocity=300.0)
    >>> d = launch_vehicle_gains(v, [LaunchScenario(psi0=0.02), LaunchScenario(gust_alpha=0.03)],
    ...                          delta_max=math.radians(6), delta_rate_max=math.radians(25),
    ...                          N=20)
    >>> d.success, d.verification["verdict"]
    (True, 'asymptotically stable')
    """
    N = param("problems.N", N)
    import time

    veh = LaunchVehicle.coerce(vehicle)
    scs = check_scenarios(scenarios, veh)
    dmax = positive(delta_max, "delta_max")
    rmax = positive(delta_rate_max, "delta_rate_max")
    T = positive(horizon, "horizon")
    if isinstance(N, bool) or not isinstance(N, (int, np.integer)) or N < 4:
        raise ValueError(f"`N` must be an integer >= 4, got {N!r}")
    if isinstance(points, bool) or not isinstance(points, (int, np.integer)) or points < 11:
        raise ValueError(f"`points` must be an integer >= 11, got {points!r}")
    decay = finite_scalar(min_decay, "min_decay")
    if decay < 0:
        raise ValueError(f"`min_decay` must be >= 0, got {decay!r}")
    tol = finite_scalar(limit_tol, "limit_tol")
    if tol < 0:
        raise ValueError(f"`limit_tol` must be >= 0, got {tol!r}")
    w = check_weights(weights)
    bounds = check_gain_bounds(gain_bounds, bool(integral))
    tf = None if filter_time_constant is None else positive(filter_time_constant,
                                                            "filter_time_constant")

    model, outputs = design_model(veh, integral=bool(integral), filter_time_constant=tf)
    K = len(scs)
    X0 = initial_states(veh, scs, model.states)
    labels = [s.name or str(i) for i, s in enumerate(scs)]

    def cost(x, u, p):
        d, r, _ = outputs(x, p)
        return w["psi"] * x[0] ** 2 + w["psi_dot"] * x[1] ** 2 + w["delta"] * d ** 2 \
            + w["delta_rate"] * r ** 2

    limits = {"delta": ocp.Constraint(lambda x, u, p: outputs(x, p)[0], -dmax, dmax, dmax,
                                      "gimbal deflection"),
              "delta_rate": ocp.Constraint(lambda x, u, p: outputs(x, p)[1], -rmax, rmax, rmax,
                                           "deflection rate")}
    hurwitz = hurwitz_rows(veh, model, decay)
    stable = ocp.Constraint(lambda x0, xf, p: hurwitz(p), 0.0, math.inf, None,
                            "closed-loop stability (Routh-Hurwitz)")
    scale_x = {"psi": 0.05, "psi_dot": 0.05, "x_dot": max(veh.velocity or 1.0, 1.0),
               "y_dot": 1.0, "delta": dmax, "command": dmax, "psi_integral": 0.05 * T,
               "wind_y": max(1.0, float(np.max(np.abs(X0[-1]))))}
    scale = {f"{n}[{k}]": scale_x[n] for k in range(K) for n in model.states}
    p0 = guess_gains(veh, bounds)

    def solve(which):
        problem = ocp.scenario_problem(model, X0, T=T, lagrange=cost,
                                       path=[limits[k] for k in which], boundary=[stable],
                                       p_bounds=bounds, p=p0, weights=[s.weight for s in scs],
                                       name="launch vehicle gains")
        # verify=False: the design is judged by its own closed-loop re-simulation of every
        # scenario (`resimulate` below); the collocation under-resolves the 0.08 s actuator
        # on 0.2 s intervals (the gimbal deflection re-simulated 1 % off, the cost 4e-7)
        return ocp.solve(problem, N=N, scale=scale, ipopt_options=ipopt_options, verify=False)

    start = time.perf_counter()
    sol = solve(("delta", "delta_rate"))
    elapsed = time.perf_counter() - start
    gains = {name: float(v) for name, v in zip(model.params, sol.p)}
    units = {name: GAIN_UNITS[name] for name in model.params}
    lim = {"delta": dmax, "delta_rate": rmax}
    ver = {"solve_time": elapsed, "iterations": sol.iterations, "nlp_status": sol.solver_status,
           "delta_max": dmax, "delta_rate_max": rmax, "min_decay": decay, "horizon": T,
           "filter_time_constant": tf, "intervals": N}

    def fail(status, msg, runs=(), **more):
        return GainDesign(False, status, msg, gains, units, float(sol.cost), list(runs),
                          {**ver, **more}, sol)

    if not sol.success:
        return diagnose(sol, solve, lim, decay, bounds, fail,
                         lambda k, other: max(node_peaks(model, outputs, other, K, labels),
                                              key=lambda item: item[1][k]))

    stab, _ = stability_check(veh, sol.p, filter_tau=tf)
    ver.update(stab)
    runs = resimulate(veh, sol.p, scs, T, points, filter_tau=tf)
    for which in ("delta", "delta_rate"):
        ver[f"peak_{which}"] = max(r["peak"][which] for r in runs)
    if not stab["stable"]:
        msg = (f"the designed loop is not asymptotically stable ({stab['verdict']}): least "
               f"damping ratio {stab['least_damping_ratio']:.3g}; poles "
               f"{np.round(stab['poles'], 4).tolist()}")
        return fail(STATUS_UNSTABLE, msg, runs)
    bad = violations([(lab, r["peak"]) for lab, r in zip(labels, runs)], lim, tol)
    if bad:
        what = "; ".join(limit_text(*b) for b in bad)
        return fail(STATUS_LIMITS, f"re-simulation exceeds the limits: {what}", runs,
                    violated=[b[0] for b in bad])
    msg = (f"designed in {elapsed:.2f} s; stable (least damping ratio "
           f"{stab['least_damping_ratio']:.3f}, phase margin "
           f"{stab.get('phase_margin_deg', math.nan):.1f} deg); limits held in all {K} "
           "re-simulated scenarios")
    return GainDesign(True, sol.status, msg, gains, units, float(sol.cost), runs, ver, sol)


def plot_design(design: GainDesign, ax=None):
    """`GainDesign.plot` (kept as a function for existing callers).

    Parameters
    ----------
    design : GainDesign
        From `launch_vehicle_gains`, `attitude_gains` or `state_feedback_gains`.
    ax : matplotlib.axes.Axes or matplotlib.figure.Figure, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    if not isinstance(design, GainDesign):
        raise TypeError(f"`design` must be a GainDesign, got {type(design).__name__}")
    return design.plot(ax)
