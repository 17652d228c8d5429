"""`launch_vehicle`: the attitude/attitude-rate autopilot of a thrust-vectored launch vehicle
(Rheinfurth & Wilson, NASA RP-1262, Sec. 5.4, Eqs. 5.53-5.54) as a stability report. Its
loop is drawn by `problems.stability.launch_vehicle_plots` (Bode, Nichols), its time
response computed by `problems.stability.launch_vehicle_response`.

The loop
--------
The open-loop vehicle (`dynamics.launch_vehicle` with its opt-in parts, no gains) is
linearized about steady flight along ``X`` (``psi = 0``, speed ``velocity`` when there is
air); the plant runs from the engine deflection (``delta``, or ``delta_command`` into the
actuator) to the gyro readings ``psi_sensed, psi_dot_sensed``; the controller is the gain row
``[k_psi, k_psidot]`` of ``delta_c = -(k_psi psi_s + k_psidot psi_s')``. `loop` closes it and
reads the classical margins of ``L = K P`` (``control.stability_margins``): the loop broken
at the deflection command. The flight condition is frozen: the thrust accelerates the
vehicle (``x_dot' = F/m``, not an equilibrium), and the perturbations about the nominal path
are analysed with the dynamic pressure, speed and (with mass flow) the mass held.

Translational states
--------------------
``x, y, x_dot, y_dot`` carry zero eigenvalues in Jordan pairs (``x' = x_dot``,
``x_dot' = 0``): an attitude error makes the path drift like ``t^2``. That is rigid-body
translation, corrected by guidance, not by the autopilot. A translational state whose column
of ``A`` is zero (nothing depends on it: the position always, the axial speed to first
order, the lateral speed when there is no air) is factored out by
`~dynamics.linearize.Linearization.quotient`, as the spin cases factor out the spin phase;
the notes list them. With `Aero` the lateral speed changes the angle of attack
(``alpha = psi - y_dot / V``), so ``y_dot`` stays: its mode is the *lateral drift*. The mass
(mass flow) is frozen by `~dynamics.linearize.Linearization.restrict` (``m' = -rate`` is the
same for every perturbation). A well-tuned autopilot is then "asymptotically stable", as a
GNC engineer calls it, instead of "unstable" by the secular drift of ``x`` and ``y``.

Closed forms
------------
Rigid vehicle (Sec. 5.4): ``I psi'' + F l k_psidot psi' + F l k_psi psi = 0``, so
``omega_n = sqrt(F l k_psi / I)``, ``zeta = k_psidot sqrt(F l) / (2 sqrt(I k_psi))``. With
aero (``N = q S C_N_alpha``, ``M = N l_cp``, ``alpha = psi - y_dot / V``) the plant from
``delta`` to ``psi`` is ``Npsi / D`` with ``D = (I s^2 - M)(m s + N/V) + M (F + N) / V`` and
``Npsi = F l (m s + N/V) + F M / V``; an actuator lag ``1 / (tau s + 1)`` multiplies it; the
closed loop is ``(tau s + 1) D + (k_psi + k_psidot s) Npsi = 0`` (``D = I s^2``,
``Npsi = F l`` without air; mass flow without air adds the jet damping of Eq. 3.49,
``D = I s^2 + mdot (l2^2 - l1^2) s``). A zero slosh mass adds its held oscillator (pendulum
``sqrt(F / (m L))``, spring ``frequency``), a bending mode the thrust does not excite
(``deflection_gimbal = 0``; the rigid loop may still see it through the sensor and mount
slopes) its own ``omega_b``: the loop is block-triangular. (A gimbal that moves with the mode
couples both ways: the thrust excites it and its offset ``phi_g eta`` changes the thrust
moment.) Those cases are checked (`STATUS_VERIFIED`); the others are unchecked.

With aero and no other part the closed loop is a cubic whose coefficients are affine in
``k_psi``: the Routh-Hurwitz conditions give the stable range of ``k_psi`` with the drift
included (quantity "least stable k_psi"), which tends to the attitude-only bound
``F l k_psi > q S C_N_alpha l_cp`` as ``V`` grows (at 500 m/s it may differ by tens of
percent either way, depending on ``k_psidot``).
"""
from __future__ import annotations

import math
from dataclasses import replace

import casadi as ca
import numpy as np
from numpy.polynomial import Polynomial

from appdyn.dynamics import cache
from appdyn.dynamics.launch_vehicle import launch_vehicle as vehicle_model
from appdyn.dynamics.linearize import linearization
from appdyn.dynamics.results import timed

from .common import check_number
from .loop import loop
from .report import Quantity, StabilityReport, build_report

__all__ = ["launch_vehicle", "frozen_state", "flight_speed"]

_SENSORS = ("psi_sensed", "psi_dot_sensed")
_WHY = {"x": "the forces do not depend on the position",
        "y": "the forces do not depend on the position",
        "x_dot": "the axial speed acts on the attitude loop only at second order",
        "y_dot": "without air the lateral speed acts on nothing: Galilean invariance",
        "mass": "m' = -rate for every perturbation: the mass is frozen"}
_GROUPS = (("rigid attitude", ("psi", "psi_dot")),
           ("lateral drift", ("x", "y", "x_dot", "y_dot")),
           ("slosh", ("theta_s", "theta_s_dot", "r_s", "r_s_dot")),
           ("bending", ("eta", "eta_dot")), ("actuator", ("delta",)))


def flight_speed(aero, velocity):
    """``velocity`` [m/s] checked: positive with ``aero``, ``None`` without (ValueError
    naming ``velocity`` otherwise)."""
    if aero is None:
        if velocity is not None:
            raise ValueError("`velocity` is the flight speed of `aero`; give it only with "
                             "`aero`")
        return None
    if velocity is None:
        raise ValueError("`velocity` is needed with `aero` (alpha = psi - y_dot / velocity)")
    return check_number(velocity, "velocity", positive=True)


def frozen_state(model, velocity, mass):
    """The operating point of ``model``: ``psi = 0``, ``x_dot = velocity``, ``mass``, the
    slosh, bending and actuator states at rest, shape (nx,)."""
    x = np.zeros(model.nx)
    x[model.states.index("x_dot")] = velocity or 0.0
    if "mass" in model.states:
        x[model.states.index("mass")] = mass
    return x


@cache.constructs
def _sensor_matrix(model, x) -> np.ndarray:
    """``d(psi_sensed, psi_dot_sensed)/dx`` at ``x``, shape (2, nx)."""
    xs = ca.SX.sym("x", model.nx)
    y = ca.vertcat(*[model.invariants[n](xs, ca.DM(model.resolve_p())) for n in _SENSORS])
    return np.asarray(ca.Function("C", [xs], [ca.jacobian(y, xs)])(x), dtype=float)


def _reduced_plant(model, x):
    """Open-loop plant without the drift and mass states: ``(full lin, reduced lin, C)``."""
    full = linearization(model, x, allow_non_equilibrium=True)
    lin, C = full, _sensor_matrix(model, x)
    changed = True
    while changed:  # x leaves before x_dot can: repeat until no column is zero
        changed = False
        for name in ("x", "y", "x_dot", "y_dot"):
            k = lin.states.index(name) if name in lin.states else None
            if k is not None and not np.any(lin.A[:, k]) and not np.any(C[:, k]):
                lin = lin.quotient(name, reason=_WHY[name])
                C, changed = np.delete(C, k, axis=1), True
    if "mass" in lin.states:
        k = lin.states.index("mass")
        lin = lin.restrict("mass", reason=_WHY["mass"])
        C = np.delete(C, k, axis=1)
    return full, lin, C


def _oscillator(w, zeta):
    return list(np.roots([1.0, 2.0 * zeta * w, w * w]))


def _characteristic(F, I, l, m, k, kd, aero, V, actuator, mass_flow=None):
    """``(p0, p1)``: the rigid closed loop is ``p0 + k_psi p1 = 0`` (module notes)."""
    P = Polynomial
    if aero is None:
        D, Npsi = P([0.0, _jet_damping(mass_flow, l), I]), P([F * l])
    else:
        N = aero.dynamic_pressure * aero.area * aero.normal_force_slope
        M = N * aero.cp_arm
        D = P([-M, 0.0, I]) * P([N / V, m]) + M * (F + N) / V
        Npsi = F * l * P([N / V, m]) + F * M / V
    lag = P([1.0, actuator.time_constant]) if actuator is not None else P([1.0])
    return lag * D + kd * P([0.0, 1.0]) * Npsi, Npsi


def _jet_damping(mass_flow, l) -> float:
    """``mdot (l2^2 - l1^2)`` [kg m^2/s] of Eq. 3.49 (0 without mass flow)."""
    if mass_flow is None:
        return 0.0
    l2 = l if mass_flow.nozzle_exit is None else mass_flow.nozzle_exit
    return mass_flow.rate * (l2 ** 2 - mass_flow.flow_start ** 2)


def _closed_form(F, I, l, m, k, kd, aero, V, slosh, bending, actuator, mass_flow):
    """Closed-loop eigenvalues where a closed form exists (module notes), else None."""
    if (mass_flow is not None and aero is not None) or (slosh is not None and slosh.mass > 0):
        return None
    if bending is not None and bending.deflection_gimbal != 0:
        return None
    p0, p1 = _characteristic(F, I, l, m, k, kd, aero, V, actuator, mass_flow)
    roots = list((p0 + k * p1).roots())
    if slosh is not None:
        w = math.sqrt(F / (m * slosh.length)) if slosh.kind == "pendulum" else slosh.frequency
        roots += _oscillator(w, slosh.damping_ratio)
    if bending is not None:
        roots += _oscillator(bending.frequency, bending.damping_ratio)
    return np.array(roots, dtype=complex)


def _routh_gain_bounds(p0, p1):
    """``(lowest, highest)`` ``k_psi`` with every root of the cubic ``p0 + k p1`` in the left
    half plane (Routh-Hurwitz: ``a3, a2, a1, a0 > 0`` and ``a2 a1 > a3 a0``, each affine
    in ``k``); None if there is no such gain."""
    def conditions(k):
        a0, a1, a2, a3 = np.pad((p0 + k * p1).coef, (0, 4))[:4]
        return np.array([a3, a2, a1, a0, a2 * a1 - a3 * a0])

    f0, f1 = conditions(0.0), conditions(1.0) - conditions(0.0)
    lo, hi = -math.inf, math.inf
    for c0, c1 in zip(f0, f1):
        if c1 > 0:
            lo = max(lo, -c0 / c1)
        elif c1 < 0:
            hi = min(hi, -c0 / c1)
        elif c0 <= 0:
            return None
    return (lo, hi) if lo < hi else None


def _relabel(modes, aero, tol):
    """Growing attitude modes: the aero divergence (centre of pressure ahead) or an attitude
    divergence."""
    name = "aero divergence" if aero is not None and aero.cp_arm > 0 else "attitude divergence"
    return tuple(replace(m, label=name) if m.label == "rigid attitude"
                 and m.eigenvalue.real > tol else m for m in modes)


def _quantities(F, I, l, k, kd, aero, rigid, closed_ss, p0, p1):
    out = []
    if k > 0:
        A = np.asarray(closed_ss.A)
        wn = math.sqrt(np.linalg.det(A)) if rigid and np.linalg.det(A) > 0 else None
        out += [Quantity("rigid omega_n = sqrt(F l k_psi / I)", wn, math.sqrt(F * l * k / I),
                         "rad/s", "Sec. 5.4: I psi'' + F l k_psidot psi' + F l k_psi psi = 0"),
                Quantity("rigid zeta = k_psidot sqrt(F l) / (2 sqrt(I k_psi))",
                         -np.trace(A) / (2 * wn) if wn else None,
                         kd * math.sqrt(F * l) / (2 * math.sqrt(I * k)), "", "Sec. 5.4")]
    if aero is not None:
        M = aero.dynamic_pressure * aero.area * aero.normal_force_slope * aero.cp_arm
        out.append(Quantity("aero gain bound q S C_N_alpha l_cp / (F l)", None, M / (F * l),
                            "rad/rad", "F l k_psi > q S C_N_alpha l_cp, flight path held"))
        out.append(Quantity("airframe divergence rate sqrt(q S C_N_alpha l_cp / I)" if M > 0
                            else "airframe weathercock frequency sqrt(-q S C_N_alpha l_cp / I)",
                            None, math.sqrt(abs(M) / I), "1/s" if M > 0 else "rad/s",
                            "no control, flight path held"))
        if p0 is not None and p0.degree() == 3:
            bounds = _routh_gain_bounds(p0, p1)
            for i, which in enumerate(("least", "largest")):
                if bounds is not None and math.isfinite(bounds[i]):
                    out.append(Quantity(f"{which} stable k_psi, drift included", None,
                                        bounds[i], "rad/rad",
                                        "Routh-Hurwitz on the cubic (module notes)"))
    return out


def _by_reason(removed) -> dict:
    out = {}
    for name in removed:
        out.setdefault(_WHY[name], []).append(name)
    return out


def _title(parts) -> str:
    given = [name for name, part in parts.items() if part is not None]
    return ("Launch-vehicle autopilot (RP-1262, Sec. 5.4): "
            + (", ".join(given) if given else "rigid vehicle"))


@timed
def launch_vehicle(*, thrust, inertia, arm, mass, k_psi, k_psidot, aero=None, velocity=None,
                   slosh=None, bending=None, actuator=None, mass_flow=None) -> StabilityReport:
    """Stability and margins of the attitude/attitude-rate autopilot of a launch vehicle.

    The autopilot ``delta_c = -(k_psi psi_s + k_psidot psi_s')`` (RP-1262, Sec. 5.4) flies
    the thrust-vectored vehicle of `dynamics.launch_vehicle` with its opt-in parts; the
    loop is broken at the engine deflection command (module notes: the loop, the
    translational states, the closed forms).

    Parameters
    ----------
    thrust : float [N]
        ``F > 0``.
    inertia : float [kg m^2]
        ``I > 0`` about the mass centre.
    arm : float [m]
        ``l > 0``, mass centre to the gimbal.
    mass : float [kg]
        ``m > 0``.
    k_psi : float [rad/rad]
        Attitude gain.
    k_psidot : float [rad/(rad/s)]
        Rate gain.
    aero : dynamics.launch_vehicle.Aero, optional
        Normal force at the centre of pressure (``cp_arm > 0``: ahead, unstable airframe).
    velocity : float [m/s]
        Flight speed ``V > 0`` along ``X``; needed with ``aero`` (``alpha = psi - y_dot/V``)
        and only there.
    slosh, bending, actuator, mass_flow : optional
        `~dynamics.launch_vehicle.Slosh`, `~dynamics.launch_vehicle.Bending`,
        `~dynamics.launch_vehicle.Actuator` (its limits do not enter the linear loop),
        `~dynamics.launch_vehicle.MassFlow` (mass frozen, jet damping kept).

    Returns
    -------
    StabilityReport
        ``case`` ``'launch_vehicle'``; ``ss`` the closed loop (input: the deflection
        command, added at the plant input; outputs the gyro readings); modes labelled
        'rigid attitude', 'aero divergence' (or 'attitude divergence'), 'lateral drift',
        'slosh', 'bending', 'actuator'; ``margins`` of the loop at the deflection; closed
        forms and quantities (rigid ``omega_n`` and ``zeta``, the aerodynamic gain bound,
        the Routh-Hurwitz gain range with drift); ``linearization`` the full open loop.
        `bode_plot` and `nichols_plot` draw the loop with its margins.

    Raises
    ------
    ValueError
        Naming the argument: a non-finite gain, ``velocity`` missing (or not positive) with
        ``aero`` or given without it, and the checks of `dynamics.launch_vehicle`
        (``thrust``, ``inertia``, ``arm``, ``mass``, the parts).
    TypeError
        If a part is not of its class.

    Examples
    --------
    >>> import math
    >>> from appdyn.problems import stability
    >>> F, I, l = 2.0e6, 4.0e7, 20.0
    >>> rep = stability.launch_vehicle(thrust=F, inertia=I, arm=l, mass=1.0e5, k_psi=2.0,
    ...                                k_psidot=2.0)
    >>> rep.verdict, rep.status, rep.ss.state_labels
    ('asymptotically stable', 0, ['psi', 'psi_dot'])
    >>> mode = rep.modes[0]
    >>> mode.label, round(mode.wn, 6), round(mode.zeta, 6)
    ('rigid attitude', 1.414214, 0.707107)
    >>> round(math.sqrt(F * l * 2.0 / I), 6), round(2.0 * math.sqrt(F * l / (I * 2.0)) / 2, 6)
    (1.414214, 0.707107)
    >>> round(rep.margins.phase_margin, 2), rep.margins.gain_margin
    (65.53, inf)
    """
    import control

    k = check_number(k_psi, "k_psi")
    kd = check_number(k_psidot, "k_psidot")
    V = flight_speed(aero, velocity)
    parts = {"aero": aero, "slosh": slosh, "bending": bending, "actuator": actuator,
             "mass_flow": mass_flow}
    model = vehicle_model(thrust=thrust, inertia=inertia, arm=arm, mass=mass, **parts)
    F, I, l, m = (float(v) for v in (thrust, inertia, arm, mass))
    full, lin, C = _reduced_plant(model, frozen_state(model, V, m))
    col = lin.inputs.index("delta_command" if actuator is not None else "delta")
    plant = control.ss(lin.A, lin.B[:, [col]], C, np.zeros((2, 1)), states=list(lin.states),
                       inputs=[lin.inputs[col]], outputs=list(_SENSORS), name="launch_vehicle")
    cf = _closed_form(F, I, l, m, k, kd, aero, V, slosh, bending, actuator, mass_flow)
    closed = loop(plant, [[k, kd]], title="launch vehicle", closed_form=cf)
    removed = [s for s in full.states if s not in lin.states]
    notes = [f"linearized about steady flight along X at {V or 0.0:g} m/s with the flight "
             f"condition frozen (x_dot' = F/m = {F / m:.6g} m/s^2: not an equilibrium)",
             "factored out: " + "; ".join(f"{', '.join(names)} ({why})"
                                          for why, names in _by_reason(removed).items()),
             "the translation is rigid-body drift (zero eigenvalues in Jordan pairs: an "
             "attitude error makes the path drift like t^2), for guidance to correct"]
    if "y_dot" in lin.states:
        notes.append("with air the lateral speed changes the angle of attack "
                     "(alpha = psi - y_dot/V): y_dot stays, as the lateral drift mode")
    unstable = int(np.sum(np.linalg.eigvals(lin.A).real > closed.tolerance))
    if unstable:
        notes.append(f"the open loop has {unstable} unstable pole(s): read the margins by the "
                     "Nyquist criterion (a gain margin < 1 is a gain reduction to instability)")
    if actuator is not None and (actuator.deflection_limits or actuator.rate_limit):
        notes.append("actuator limits do not enter the linear loop")
    rigid = all(p is None for p in parts.values())
    p0, p1 = (_characteristic(F, I, l, m, k, kd, aero, V, actuator)
              if cf is not None and slosh is None and bending is None else (None, None))
    groups = {name: [s for s in states if s in lin.states] for name, states in _GROUPS}
    params = {"thrust": F, "inertia": I, "arm": l, "mass": m, "k_psi": k, "k_psidot": kd,
              **({"velocity": V} if aero is not None else {}),
              **{name: part for name, part in parts.items() if part is not None}}
    report = build_report("launch_vehicle", _title(parts), params, closed.ss, lin=full,
                          groups={g: s for g, s in groups.items() if s}, closed_form=cf,
                          margins=closed.margins, notes=notes,
                          quantities=_quantities(F, I, l, k, kd, aero, rigid, closed.ss, p0, p1))
    return replace(report, modes=_relabel(report.modes, aero, report.tolerance))

