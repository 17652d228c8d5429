"""The thrust-vectored launch vehicle in the yaw plane and its opt-in parts (Rheinfurth &
Wilson, NASA RP-1262, Sec. 5.4 Eqs. 5.53-5.54, Sec. 3.4 Eq. 3.49, Ch. 6).

Frame and signs
---------------
Inertial axes ``X, Y`` span the yaw plane; ``psi`` turns ``X`` into the vehicle axis
``e1 = (cos psi, sin psi)`` (towards the nose), counter-clockwise positive, and
``e2 = (-sin psi, cos psi)``. Body components are along ``(e1, e2)``; ``J`` turns a vector by
+90 deg. ``(x, y)`` is the vehicle mass centre. ``O`` is the mass centre with the propellant at
rest; every station is measured from ``O``. The gimbal is ``l = arm`` aft (body point
``(-l, 0)``); the deflection ``delta`` turns the thrust *clockwise* from the axis: thrust
``F (cos delta, -sin delta)`` in body axes, inertial direction ``psi - delta``. Gravity is
left out (the seed's yaw plane).

Rigid vehicle (Eqs. 5.53-5.54, re-derived)
------------------------------------------
``T = 1/2 m (x'^2 + y'^2) + 1/2 I psi'^2``. The thrust acts at ``r_g = (x, y) - l e1``;
``Q_k = F . dr_g/dq_k`` with ``dr_g/dpsi = -l e2`` and ``F . e2 = -F sin delta``::

    m x'' = F cos(psi - delta),   m y'' = F sin(psi - delta),   I psi'' = F l sin delta.

This agrees with the seed (its "survival point" is the swivel point). The autopilot
``delta = -(k_psi psi + k_psidot psi')`` with ``sin delta ~ delta`` gives the seed's
``I psi'' + F l k_psidot psi' + F l k_psi psi = 0``.

Forces on the structure
-----------------------
In body components, at body points ``p`` from ``O``:

* thrust ``f_T = F (cos(sigma_g eta - delta), sin(sigma_g eta - delta))`` at
  ``(-l, phi_g eta)`` (the engine mount moves and turns with a bending mode);
* aerodynamics ``f_A = (0, q S C_N_alpha alpha)`` at ``(l_cp, 0)``, with
  ``alpha = atan2(-w_b, u_b)``, ``(u_b, w_b)`` the body components of the air-relative
  velocity ``(x' - wind_x, y' - wind_y)``: nose left of the velocity is ``alpha > 0`` and
  pushes along ``+e2``, so ``l_cp > 0`` is unstable;
* the internal flow (Eqs. 3.46-3.48): propellant flows aft at ``mdot`` from ``l1`` to the exit
  ``l2`` (distances aft of ``O``); element ``dm`` at ``-s e1`` with relative speed ``c``
  (``c dm = mdot ds``) feels ``2 dm w x v_rel``, the structure the reaction. Its resultant is
  ``f_C = (0, 2 mdot psi' (l2 - l1))`` and its moment about ``O`` is
  ``L_C = -integral of s 2 mdot psi' ds = -mdot psi' (l2^2 - l1^2)`` -- Eq. 3.49, the jet
  damping. It is applied as ``f_C`` at ``O`` plus the couple ``L_C``.

Translation: the mass centre obeys ``m (x'', y'') = C(psi) (f_T + f_A + f_C)`` whatever the
slosh and bending do (the mode is orthogonal to the rigid motions).

Rotation and slosh
------------------
The slosh mass ``m_s`` sits at ``rho_s(xi)``: pendulum ``(h - L cos theta_s, -L sin theta_s)``
(hinge ``h``, hanging aft at rest), spring-mass ``(h, r_s)``. With ``rho0 = rho_s(0)``, the
rigid part (``m_r = m - m_s``) has its centre at ``rho_r = -(m_s/m_r) rho0``; the mass centre is
``Delta = (m_s/m) (rho_s - rho0)`` from ``O``. With ``s = rho_s - rho_r``, the reduced mass
``mu = m_s m_r / m`` and the rigid part's own inertia ``I_r = I - mu |s(0)|^2``::

    T = 1/2 m |(x', y')|^2 + 1/2 I_r psi'^2 + 1/2 mu |psi' J s + s'|^2.

Each structural force ``f`` at ``p`` acts at ``(x, y) + C(psi) (p - Delta(xi))``; its virtual
work gives ``Q_psi = sum (p - Delta) x f + L_C`` and
``Q_xi = -(m_s/m) drho_s/dxi . sum f = -m_s a . drho_s/dxi``, ``a`` the body components of the
mass-centre acceleration (the accelerating frame's inertial force, which makes the pendulum
restoring: ``-m_s a L sin theta_s`` in steady thrust). The spring adds
``V = 1/2 m_s omega_s^2 r_s^2``, each damper its force. The ``xi`` equation is divided by
``m_s``, so ``m_s = 0`` is the rigid vehicle with slosh states that follow it. Linearized at
``psi = xi = 0`` in steady thrust (``a = F/m``, ``d = h - rho_r`` the hinge from the rigid
centre), with the vehicle free the slosh frequency is::

    pendulum:     omega^2 = (a/L) (m/m_r + m_s d (d - L) / I_r)
    spring-mass:  omega^2 = omega_s^2 m/m_r + m_s d (omega_s^2 d + a) / I_r

(Newton-Euler for the two bodies gives the same), tending to the held values ``sqrt(a/L)``
and ``omega_s`` as ``m_s -> 0``.

Bending, sensor, autopilot, actuator
------------------------------------
``M_b (eta'' + 2 zeta_b omega_b eta' + omega_b^2 eta) = f_T . (0, phi_g)
= F phi_g sin(sigma_g eta - delta)`` (Eq. 6.39); the gyros read ``psi_s = psi + sigma_s eta``
and ``psi_s' = psi' + sigma_s eta'``; the autopilot commands
``delta_c = -(k_psi psi_s + k_psidot psi_s')``; the actuator follows
``delta' = clip((clip(delta_c, lower, upper) - delta)/tau, -rate_limit, rate_limit)``.
The mode uses mean axes (it carries no linear or angular momentum, ``int phi dm = 0``,
``int s phi dm = 0``), so it adds no inertial coupling; only the thrust excites it
(aerodynamic and slosh forces act on the undeformed frame; engine inertia is left out).

Reading the seed's OCR
----------------------
Eqs. 5.53-5.54 and 3.49 check out as printed ("survival point" is the swivel point,
"altitude control" attitude control). In Example 3's flexibility equation the garbled
``[F M / -] ...`` is ``[F/M - w x (w x l_c) - ...]``: the centre-of-mass acceleration, which
is the ``-m_s a . drho_s/dxi`` term here.

Variable mass
-------------
``m' = -mdot``, ``F = mdot v_e``, inertia at a constant radius of gyration
``I(m) = I m / mass``; the equations are written at the instantaneous mass (no ``m'`` terms
besides the jet forces above, as the seed's note after Eq. 3.49).

Aerodynamic closed forms (linear, ``psi = 0``, speed ``V`` along ``X``, no wind)
------------------------------------------------------------------------------
``alpha = psi - y'/V`` and ``I psi'' = q S C_N_alpha l_cp alpha``. With the flight path held
the attitude poles are ``+-sqrt(c)``, ``c = q S C_N_alpha l_cp / I``: real (one unstable) for
the centre of pressure ahead, an oscillation at ``sqrt(-c)`` behind. With the lateral motion
free (``b = q S C_N_alpha / m``): ``s^3 + (b/V) s^2 - c s + F c / (m V) = 0``.
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from .. import cache
from ..model import Model
from ..validate import ArgumentTypeError, finite_scalar, is_symbolic, positive
from .parts import Actuator, Aero, Bending, MassFlow, Slosh

__all__ = ["launch_vehicle", "rigid_part", "RIGID_STATES"]

#: The states every launch-vehicle model starts with (mass centre, yaw angle, their rates).
RIGID_STATES = ("x", "y", "psi", "x_dot", "y_dot", "psi_dot")
_RIGID_UNITS = ("m", "m", "rad", "m/s", "m/s", "rad/s")
_SLOSH_STATES = {"pendulum": (("theta_s", "rad"), ("theta_s_dot", "rad/s")),
                 "spring": (("r_s", "m"), ("r_s_dot", "m/s"))}
_WIND = (("wind_x", "m/s"), ("wind_y", "m/s"))
_NO_BENDING = Bending(frequency=1.0, generalized_mass=1.0)  # zero slopes and deflection
_PARTS = {"aero": Aero, "mass_flow": MassFlow, "slosh": Slosh, "bending": Bending,
          "actuator": Actuator}


def _cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


def _slosh_geometry(slosh: Slosh, xi):
    """``rho_s(xi)`` [m], body components from ``O``."""
    if slosh.kind == "pendulum":
        return (slosh.hinge - slosh.length * ca.cos(xi), -slosh.length * ca.sin(xi))
    return (ca.SX(slosh.hinge), xi)


def rigid_part(slosh: Slosh | None, m, I):
    """``(m_r, mu, I_r)`` of the vehicle without its slosh mass (module docstring).

    Parameters
    ----------
    slosh : Slosh or None
    m : float or casadi SX [kg]
        Vehicle mass (slosh mass included).
    I : float or casadi SX [kg m^2]
        Vehicle inertia about ``O`` with the slosh mass frozen at rest.

    Returns
    -------
    m_r [kg], mu [kg], I_r [kg m^2]
        Rigid mass ``m - m_s``, reduced mass ``m_s m_r / m`` and the rigid part's inertia about
        its own centre, ``I - m m_s rho0^2 / m_r`` (``rho0``: slosh mass at rest from ``O``).

    Raises
    ------
    TypeError
        If ``slosh`` is neither a `Slosh` nor ``None``, or ``m`` or ``I`` is neither a real
        number nor a CasADi symbol.
    ValueError
        If a numeric ``m`` or ``I`` is not finite and ``> 0``, or ``m`` is not larger than the
        slosh mass.

    Examples
    --------
    >>> from appdyn.dynamics.launch_vehicle import Slosh
    >>> from appdyn.dynamics.launch_vehicle.vehicle import rigid_part
    >>> rigid_part(Slosh(mass=1.0, hinge=2.0, length=1.0), 4.0, 10.0)  # 10 - 4 * 1 * 1 / 3
    (3.0, 0.75, 8.666666666666666)
    """
    if slosh is not None and not isinstance(slosh, Slosh):
        raise ArgumentTypeError(f"`slosh` must be a Slosh or None, got {type(slosh).__name__}")
    m = m if is_symbolic(m) else positive(m, "m")
    I = I if is_symbolic(I) else positive(I, "I")  # noqa: E741
    if slosh is None:
        return m, 0.0, I
    ms = slosh.mass
    if not is_symbolic(m) and not is_symbolic(ms) and not m > ms:
        raise ValueError(f"`m` must be larger than the slosh mass {ms!r}, got {m!r}")
    rho0 = slosh.hinge - (slosh.length or 0.0)
    return m - ms, ms * (m - ms) / m, I - m * ms * rho0 ** 2 / (m - ms)


def _rotation_slosh(slosh, m, I, q_psi, a_body, X, thrust):
    """``(psi'', xi'')`` from the Lagrange equations of ``T`` (module docstring);
    ``q_psi(Delta)`` is ``Q_psi`` for the mass-centre shift ``Delta``."""
    ms, xi, xid, psid = slosh.mass, X["xi"], X["xi_dot"], X["psi_dot"]
    mr, mu, I_r = rigid_part(slosh, m, I)
    rho = _slosh_geometry(slosh, xi)
    rho0 = [ca.substitute(r, xi, 0) for r in rho]
    s = ca.vertcat(rho[0] + ms / mr * rho0[0], rho[1] + ms / mr * rho0[1])
    ds = ca.jacobian(s, xi)
    q, qd = ca.vertcat(X["psi"], xi), ca.vertcat(psid, xid)
    K = 0.5 * ca.sumsqr(psid * ca.vertcat(-s[1], s[0]) + ds * xid)
    MK, _ = ca.hessian(K, qd)
    bK = ca.mtimes(ca.jacobian(ca.mtimes(MK, qd), q), qd) - ca.gradient(K, q)
    Q_psi = q_psi([ms / m * (rho[0] - rho0[0]), ms / m * (rho[1] - rho0[1])])
    zeta = slosh.damping_ratio
    if slosh.kind == "pendulum":
        L = slosh.length
        per_mass = 2 * zeta * L ** 2 * ca.sqrt(thrust / (m * L)) * xid
    else:
        per_mass = slosh.frequency ** 2 * xi + 2 * zeta * slosh.frequency * xid
    # psi row:        (I_r + mu MK00) psi'' + mu MK01 xi'' = Q_psi - mu bK0
    # xi row / m_s:   (m_r/m) (MK10 psi'' + MK11 xi'') = -a . ds/dxi - (m_r/m) bK1 - per_mass
    a11, a12, b1 = I_r + mu * MK[0, 0], mu * MK[0, 1], Q_psi - mu * bK[0]
    a21, a22 = mr / m * MK[1, 0], mr / m * MK[1, 1]
    b2 = -(a_body[0] * ds[0] + a_body[1] * ds[1]) - mr / m * bK[1] - per_mass
    psidd = (b1 - a12 * b2 / a22) / (a11 - a12 * a21 / a22)  # exact rigid row when m_s = 0
    return psidd, (b2 - a21 * psidd) / a22


def _equations(thrust, inertia, arm, mass, gains, aero, mass_flow, slosh, bending, actuator,
               X, W):
    """State derivatives and monitored outputs (dicts of SX) from the state symbols ``X`` and
    the wind/control symbols ``W`` (module docstring)."""
    psi, psid = X["psi"], X["psi_dot"]
    c, s = ca.cos(psi), ca.sin(psi)
    m = X["mass"] if mass_flow else mass
    I = inertia * m / mass if mass_flow else inertia
    eta, etad = (X["eta"], X["eta_dot"]) if bending else (0, 0)
    b = bending or _NO_BENDING
    monitors = {"mass": ca.SX(m), "psi_sensed": psi + b.slope_sensor * eta,
                "psi_dot_sensed": psid + b.slope_sensor * etad}
    if gains:
        command = -(gains[0] * monitors["psi_sensed"] + gains[1] * monitors["psi_dot_sensed"])
        monitors["delta_command"] = command
    else:
        command = W["delta_command" if actuator else "delta"]
    delta = X["delta"] if actuator else command
    angle = b.slope_gimbal * eta - delta
    f_thrust = (thrust * ca.cos(angle), thrust * ca.sin(angle))
    forces = [((-arm, b.deflection_gimbal * eta), f_thrust)]  # (body point, body force)
    couple = 0
    if aero:
        vx, vy = X["x_dot"] - W["wind_x"], X["y_dot"] - W["wind_y"]
        alpha = ca.atan2(s * vx - c * vy, c * vx + s * vy)
        monitors["alpha"] = alpha
        normal = aero.dynamic_pressure * aero.area * aero.normal_force_slope * alpha
        forces.append(((aero.cp_arm, 0), (0, normal)))
    if mass_flow:
        l1 = mass_flow.flow_start
        l2 = arm if mass_flow.nozzle_exit is None else mass_flow.nozzle_exit
        forces.append(((0, 0), (0, 2 * mass_flow.rate * psid * (l2 - l1))))
        couple = -mass_flow.rate * psid * (l2 ** 2 - l1 ** 2)
    fx = sum(f[0] for _, f in forces)
    fy = sum(f[1] for _, f in forces)
    a_body = (fx / m, fy / m)

    def q_psi(shift):
        return sum(_cross((p[0] - shift[0], p[1] - shift[1]), f) for p, f in forces) + couple

    xdot = {"x": X["x_dot"], "y": X["y_dot"], "psi": psid,
            "x_dot": c * a_body[0] - s * a_body[1], "y_dot": s * a_body[0] + c * a_body[1]}
    if slosh:
        xdot["psi_dot"], xdot["xi_dot"] = _rotation_slosh(slosh, m, I, q_psi, a_body, X,
                                                          thrust)
        xdot["xi"] = X["xi_dot"]
    else:
        xdot["psi_dot"] = q_psi((0, 0)) / I
    if mass_flow:
        xdot["mass"] = ca.SX(-mass_flow.rate)
    if bending:
        w = bending.frequency
        xdot["eta"] = etad
        xdot["eta_dot"] = (f_thrust[1] * bending.deflection_gimbal / bending.generalized_mass
                           - 2 * bending.damping_ratio * w * etad - w ** 2 * eta)
    if actuator:
        target = command
        if actuator.deflection_limits is not None:
            target = ca.fmin(ca.fmax(target, actuator.deflection_limits[0]),
                             actuator.deflection_limits[1])
        rate = (target - delta) / actuator.time_constant
        if actuator.rate_limit is not None:
            rate = ca.fmin(ca.fmax(rate, -actuator.rate_limit), actuator.rate_limit)
        xdot["delta"] = rate
    return xdot, monitors


@cache.memoize
def _launch_vehicle(thrust, inertia, arm, mass, gains, aero, mass_flow, slosh, bending,
                    actuator) -> Model:
    layout = list(zip(RIGID_STATES, _RIGID_UNITS))
    layout += [("mass", "kg")] if mass_flow else []
    layout += list(_SLOSH_STATES[slosh.kind]) if slosh else []
    layout += [("eta", "m"), ("eta_dot", "m/s")] if bending else []
    layout += [("delta", "rad")] if actuator else []
    controls = [] if gains else [("delta_command" if actuator else "delta", "rad")]
    params = list(_WIND) if aero and aero.wind == "parameter" else []
    controls += list(_WIND) if aero and aero.wind == "control" else []
    X = {name: ca.SX.sym(name) for name, _ in layout}
    if slosh:
        X["xi"], X["xi_dot"] = (X[name] for name, _ in _SLOSH_STATES[slosh.kind])
    U = {name: ca.SX.sym(name) for name, _ in controls}
    P = {name: ca.SX.sym(name) for name, _ in params}
    xdot, monitors = _equations(thrust, inertia, arm, mass, gains, aero, mass_flow, slosh,
                                bending, actuator, X, {**U, **P})
    if slosh:
        for (name, _), key in zip(_SLOSH_STATES[slosh.kind], ("xi", "xi_dot")):
            xdot[name] = xdot.pop(key)
    x = ca.vertcat(*[X[name] for name, _ in layout])
    u = ca.vertcat(*[U[name] for name, _ in controls]) if controls else ca.SX(0, 1)
    p = ca.vertcat(*[P[name] for name, _ in params]) if params else ca.SX(0, 1)
    f = ca.Function("launch_vehicle", [x, u, p], [ca.vertcat(*[xdot[n] for n, _ in layout])],
                    ["x", "u", "p"], ["xdot"])
    invariants = {key: ca.Function(key, [x, p], [value], ["x", "p"], [key])
                  for key, value in monitors.items() if not ca.depends_on(value, u)}
    return Model(f=f, states=tuple(n for n, _ in layout), controls=tuple(n for n, _ in controls),
                 params=tuple(n for n, _ in params), p_default=np.zeros(len(params)),
                 units=dict(layout + controls + params), invariants=invariants,
                 name="launch_vehicle")


def _check_parts(parts: dict) -> None:
    for name, value in parts.items():
        if value is not None and not isinstance(value, _PARTS[name]):
            raise TypeError(f"`{name}` must be a dynamics.launch_vehicle.{_PARTS[name].__name__} "
                            f"or None, got {type(value).__name__}")


def _check_mass_flow(mass_flow: MassFlow, thrust: float, arm: float, mass: float) -> None:
    if mass_flow.exhaust_velocity is not None:
        produced = mass_flow.rate * mass_flow.exhaust_velocity
        if abs(produced - thrust) > 1e-9 * thrust:
            raise ValueError(f"`mass_flow`: rate * exhaust_velocity = {produced!r} N must equal "
                             f"`thrust` = {thrust!r} N (F = mdot v_e)")
    exit_ = arm if mass_flow.nozzle_exit is None else mass_flow.nozzle_exit
    if mass_flow.flow_start > exit_:
        raise ValueError(f"`mass_flow.flow_start` ({mass_flow.flow_start!r} m aft) must be at or "
                         f"ahead of the nozzle exit ({exit_!r} m aft of the mass centre)")
    if mass_flow.burn_time is not None:
        burnt = mass_flow.rate * mass_flow.burn_time
        if burnt >= mass:
            raise ValueError(f"`mass_flow`: rate * burn_time = {burnt!r} kg empties the vehicle "
                             f"(`mass` = {mass!r} kg)")


def _check_slosh(slosh: Slosh, masses, inertia: float, mass: float) -> None:
    for m in masses:
        if not slosh.mass < m:
            raise ValueError(f"`slosh.mass` ({slosh.mass!r} kg) must be less than the vehicle "
                             f"mass ({m!r} kg)")
        _, _, I_r = rigid_part(slosh, m, inertia * m / mass)
        if not I_r > 0:
            raise ValueError(f"`slosh` at rest carries more than the vehicle inertia: the rigid "
                             f"part's own inertia would be {I_r!r} kg m^2 at mass {m!r} kg")


def launch_vehicle(*, thrust, inertia, arm, mass, k_psi=None, k_psidot=None, aero=None,
                   mass_flow=None, slosh=None, bending=None, actuator=None) -> Model:
    """Thrust-vectored launch vehicle in the yaw plane, with opt-in parts (module docstring).

    Parameters
    ----------
    thrust : float [N]
        ``F > 0``.
    inertia : float [kg m^2]
        ``I > 0`` about the mass centre (slosh mass frozen at rest, if any); with
        ``mass_flow`` the value at ``mass``, scaled as ``I m / mass``.
    arm : float [m]
        ``l > 0``, mass centre to the gimbal (aft).
    mass : float [kg]
        ``m > 0``, slosh mass included; with ``mass_flow`` the reference mass of ``inertia``
        (the mass is then a state).
    k_psi : float [rad/rad], optional
    k_psidot : float [rad/(rad/s)], optional
        Attitude and rate gains, both or neither. Given, the autopilot
        ``delta_c = -(k_psi psi_sensed + k_psidot psi_dot_sensed)`` closes the loop and the
        deflection control disappears (with ``actuator``, ``delta_c`` is its command).
    aero, mass_flow, slosh, bending, actuator : optional
        `Aero`, `MassFlow`, `Slosh`, `Bending`, `Actuator` (``dynamics.launch_vehicle``);
        each absent part adds no state, control or parameter.

    Returns
    -------
    Model
        States ``x, y`` [m], ``psi`` [rad], ``x_dot, y_dot`` [m/s], ``psi_dot`` [rad/s], then
        ``mass`` [kg] (mass flow), ``theta_s`` [rad], ``theta_s_dot`` [rad/s] (pendulum) or
        ``r_s`` [m], ``r_s_dot`` [m/s] (spring-mass), ``eta`` [m], ``eta_dot`` [m/s]
        (bending), ``delta`` [rad] (actuator). Controls: ``delta`` [rad] (no autopilot, no
        actuator) or ``delta_command`` [rad] (actuator, no autopilot), then ``wind_x, wind_y``
        [m/s] for ``Aero(wind='control')``; parameters ``wind_x, wind_y`` [m/s] (default 0) for
        ``Aero(wind='parameter')``. ``invariants`` holds monitored outputs of ``(x, p)``:
        ``mass`` [kg], the sensor outputs ``psi_sensed`` [rad] and ``psi_dot_sensed`` [rad/s],
        ``delta_command`` [rad] (autopilot) and ``alpha`` [rad] (aero with parameter wind).
        Cached by the arguments.

    Raises
    ------
    TypeError
        If a number is not a real number or a part is not of its class.
    ValueError
        Naming the argument: ``thrust``, ``inertia``, ``arm`` or ``mass`` not finite and
        positive; one gain without the other; ``rate * exhaust_velocity != thrust``; a flow
        starting aft of the nozzle exit; a burn that empties the vehicle; a slosh mass not
        below the vehicle mass or heavier in inertia than the vehicle (also at the end of
        ``burn_time``); bad part fields (see each part).

    References
    ----------
    .. [1] Rheinfurth & Wilson, NASA RP-1262, Sec. 5.4 (Eqs. 5.53-5.54), Sec. 3.4 (Eq. 3.49),
       Ch. 6 (Example 3, Eqs. 6.33-6.41).

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics import launch_vehicle, linearize
    >>> F, I, l = 2.0e6, 4.0e7, 20.0
    >>> model = launch_vehicle(thrust=F, inertia=I, arm=l, mass=1.0e5, k_psi=2.0, k_psidot=0.5)
    >>> model.states, model.controls
    (('x', 'y', 'psi', 'x_dot', 'y_dot', 'psi_dot'), ())
    >>> poles = np.linalg.eigvals(linearize(model, np.zeros(6), allow_non_equilibrium=True).A)
    >>> wn = np.sqrt(F * l * 2.0 / I)  # I psi'' + F l k_psidot psi' + F l k_psi psi = 0
    >>> bool(np.isclose(np.abs(poles).max(), wn, rtol=1e-12))
    True
    """
    F = positive(thrust, "thrust")
    I = positive(inertia, "inertia")
    l = positive(arm, "arm")
    m = positive(mass, "mass")
    if (k_psi is None) != (k_psidot is None):
        missing = "k_psidot" if k_psidot is None else "k_psi"
        raise ValueError(f"`{missing}` must be given too: the autopilot needs both gains")
    gains = None if k_psi is None else (finite_scalar(k_psi, "k_psi"),
                                        finite_scalar(k_psidot, "k_psidot"))
    _check_parts({"aero": aero, "mass_flow": mass_flow, "slosh": slosh, "bending": bending,
                  "actuator": actuator})
    masses = [m]
    if mass_flow is not None:
        _check_mass_flow(mass_flow, F, l, m)
        if mass_flow.burn_time is not None:
            masses.append(m - mass_flow.rate * mass_flow.burn_time)
    if slosh is not None:
        _check_slosh(slosh, masses, I, m)
    return _launch_vehicle(F, I, l, m, gains, aero, mass_flow, slosh, bending, actuator)
