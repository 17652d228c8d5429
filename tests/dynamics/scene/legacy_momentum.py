"""The hand-written attitude models as they were before `rigid_body`, `wheel_spacecraft` and
`cmg_spacecraft` became thin wrappers over scenes: copied verbatim (only the imports made
absolute, and the three modules concatenated) from ``dynamics/rigid_body.py``,
``dynamics/momentum/wheels.py`` and ``dynamics/momentum/cmg.py`` at commit 6d25715. Test-only:
the independent reference of tests/dynamics/scene/test_momentum_parts.py.
"""
from __future__ import annotations

from typing import Literal

import casadi as ca
import numpy as np

from appdyn.dynamics import cache
from appdyn.dynamics.attitude import dcm_from_quat, quat_rate
from appdyn.dynamics.model import Model
from appdyn.dynamics.momentum.cluster import ClusterGeometry
from appdyn.dynamics.momentum.gyroscopic import cmg_torque
from appdyn.dynamics.validate import (check_inertia, finite_array, is_symbolic, one_of, positive,
                                      positive_each, unit_axes)

# ==================================================================== dynamics/rigid_body.py
RIGID_BODY_STATES = ("q1", "q2", "q3", "q4", "w1", "w2", "w3")


@cache.memoize
def _rigid_body(inertia_key: tuple) -> Model:
    inertia = np.array(inertia_key).reshape(3, 3)
    inv = np.linalg.inv(inertia)
    x = ca.SX.sym("x", 7)
    u = ca.SX.sym("u", 3)
    p = ca.SX.sym("p", 0)
    q, w = x[0:4], x[4:7]
    I, Iinv = ca.DM(inertia), ca.DM(inv)
    h = ca.mtimes(I, w)
    wdot = ca.mtimes(Iinv, u - ca.cross(w, h))
    xdot = ca.vertcat(quat_rate(q, w), wdot)
    f = ca.Function("rigid_body", [x, u, p], [xdot], ["x", "u", "p"], ["xdot"])
    invariants = {
        "energy": ca.Function("energy", [x, p], [0.5 * ca.dot(w, h)], ["x", "p"], ["energy"]),
        "momentum_inertial": ca.Function(
            "momentum_inertial", [x, p], [ca.mtimes(dcm_from_quat(q).T, h)], ["x", "p"],
            ["momentum_inertial"],
        ),
        "quat_norm": ca.Function("quat_norm", [x, p], [ca.norm_2(q)], ["x", "p"], ["quat_norm"]),
    }
    units = {**{k: "-" for k in RIGID_BODY_STATES[:4]}, **{k: "rad/s" for k in RIGID_BODY_STATES[4:]},
             "L1": "N m", "L2": "N m", "L3": "N m"}
    return Model(
        f=f,
        states=RIGID_BODY_STATES,
        controls=("L1", "L2", "L3"),
        params=(),
        p_default=np.zeros(0),
        units=units,
        invariants=invariants,
        name="rigid_body",
        attitude=(0, 4),
    )


def rigid_body(inertia) -> Model:
    """Torque-driven rigid body with quaternion attitude.

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2]
        Inertia matrix about the mass center in body axes (full symmetric; products of
        inertia with the sign of [1]_, Eq. 4.16, ``Ixy = -sum m x y``), or principal moments.

    Returns
    -------
    Model
        ``x = [q1, q2, q3, q4, w1, w2, w3]``, ``u = [L1, L2, L3]`` [N m], no parameters,
        ``attitude = (0, 4)``, invariants ``energy`` [J] (``1/2 w.Iw``),
        ``momentum_inertial`` [N m s] (``A(q)^T I w``, shape 3) and ``quat_norm``.
        Models are cached by inertia, so repeated calls return the same object.

    Raises
    ------
    ValueError
        If ``inertia`` has the wrong shape, is not finite, not symmetric, not positive definite,
        or violates the triangle inequality (see `check_inertia`).

    References
    ----------
    .. [1] Rheinfurth & Wilson, NASA RP-1262, Sec. 4.2 (Euler's law), Eq. 4.16 (products
       of inertia), Eq. 4.70 (kinematics).

    Examples
    --------
    >>> from appdyn.dynamics import rigid_body
    >>> model = rigid_body([1.0, 2.0, 3.0])
    >>> model.states, model.controls
    (('q1', 'q2', 'q3', 'q4', 'w1', 'w2', 'w3'), ('L1', 'L2', 'L3'))
    >>> xdot = model.f(x=[0, 0, 0, 1, 1.0, 1.0, 1.0], u=[0, 0, 0], p=[])["xdot"]
    >>> xdot[4:].T  # Euler's equations: I wdot = (I w) x w
    DM([[-1, 1, -0.333333]])
    """
    a = check_inertia(inertia)
    return _rigid_body(tuple(a.reshape(-1).tolist()))

# ============================================================ dynamics/momentum/wheels.py
#: Units of the attitude states and of an external torque ``L1..L3``.
ATTITUDE_UNITS = {**{k: "-" for k in RIGID_BODY_STATES[:4]},
                  **{k: "rad/s" for k in RIGID_BODY_STATES[4:]},
                  "L1": "N m", "L2": "N m", "L3": "N m"}


def rotor_dynamics(inertia, axes, w, h, torque=None, *, wheel_inertia=None, motor=None):
    """Angular momentum and accelerations of a rigid body carrying wheels (module docstring).

    Parameters
    ----------
    inertia : array_like, shape (3, 3) [kg m^2]
        *Locked* inertia ``I_L``: the body with every wheel as if locked (axial moments
        included).
    axes : array_like, shape (3, n)
        Unit wheel axes ``a_i`` in body axes.
    w : casadi SX/MX or DM, 3x1 [rad/s]
        Body angular velocity.
    h : casadi or array_like, n entries [N m s]
        Wheel momenta relative to the body, ``h_i = J_i W_i``.
    torque : casadi or array_like, 3 entries [N m], optional
        External torque ``L`` about the mass center (zero when omitted).
    wheel_inertia : array_like, shape (n,) [kg m^2], optional
        Axial moments ``J_i``; needed with ``motor``.
    motor : casadi or array_like, n entries [N m], optional
        Motor torques ``tau_i`` on the wheels. ``None``: every wheel is *held* at constant
        relative speed (its motor supplies ``J_i a_i.w'``).

    Returns
    -------
    H : 3x1 [N m s]
        ``I_L w + sum_i h_i a_i`` (body axes).
    wdot : 3x1 [rad/s^2]
        Held: ``I_L^-1 (L - w x H)``; driven: ``I^-1 (L - sum_i a_i tau_i - w x H)`` with the
        hub inertia ``I = I_L - sum_i J_i a_i a_i^T``.
    hdot : n x 1 [N m]
        ``h_i' = tau_i - J_i a_i.w'`` (zero when held).

    Raises
    ------
    TypeError
        If ``inertia`` or ``axes`` is not real numbers, or ``w`` or ``h`` is neither real
        numbers nor a CasADi expression.
    ValueError
        If ``inertia`` is not a finite symmetric positive definite (3, 3) matrix, ``axes`` not
        finite unit columns (3, n), ``w`` not 3 entries, ``h`` not n entries, a numeric ``w``
        or ``h`` not finite, or ``motor`` is given without ``wheel_inertia``.

    Examples
    --------
    >>> import casadi as ca
    >>> from appdyn.dynamics.momentum.wheels import rotor_dynamics
    >>> H, wdot, hdot = rotor_dynamics([[1, 0, 0], [0, 2, 0], [0, 0, 3]], [[1.0], [0.0], [0.0]],
    ...                                ca.DM([0.0, 0.0, 1.0]), [2.0])  # held wheel, h = 2
    >>> H.T, wdot.T  # w x H = (0, 2, 0), I_L wdot = -w x H
    (DM([[2, 0, 3]]), DM([[0, -1, 0]]))
    """
    IL = ca.DM(check_inertia(inertia, triangle=False))
    A = ca.DM(unit_axes(axes, "axes"))
    n = A.shape[1]
    if is_symbolic(w):
        if w.shape != (3, 1):
            raise ValueError(f"`w` must be a 3x1 CasADi column, got shape {w.shape}")
    else:
        w = ca.DM(finite_array(w, "w", (3,)))
    symbolic_h = is_symbolic(h) or (isinstance(h, (list, tuple))
                                    and any(is_symbolic(e) for e in h))
    size = (h.numel() if is_symbolic(h) else len(h)) if symbolic_h else finite_array(h, "h").size
    if size != n:
        raise ValueError(f"`h` must have {n} entries (one per wheel), got {size}")
    H = ca.mtimes(IL, w) + ca.mtimes(A, ca.vertcat(*[h[i] for i in range(A.shape[1])]))
    L = ca.DM.zeros(3) if torque is None else torque
    if motor is None:
        return H, ca.solve(IL, L - ca.cross(w, H)), ca.DM.zeros(A.shape[1])
    if wheel_inertia is None:
        raise ValueError("`wheel_inertia` is needed to drive the wheels with `motor` torques")
    J = np.asarray(wheel_inertia, dtype=float).reshape(-1)
    tau = ca.vertcat(*[motor[i] for i in range(A.shape[1])])
    hub = IL - ca.mtimes(ca.mtimes(A, ca.diag(ca.DM(J))), A.T)
    wdot = ca.solve(hub, L - ca.mtimes(A, tau) - ca.cross(w, H))
    return H, wdot, tau - ca.DM(J) * ca.mtimes(A.T, wdot)


def attitude_invariants(x, p, H, energy, **more) -> dict:
    """The invariants of an attitude model as Functions of ``(x, p)``.

    Parameters
    ----------
    x, p : casadi SX
        The model's state (quaternion in ``x[0:4]``) and parameter symbols.
    H : casadi SX, 3x1 [N m s]
        Total angular momentum in body axes.
    energy : casadi SX [J]
    **more : casadi SX
        Further monitored quantities, by name.

    Returns
    -------
    dict of str to casadi.Function
        ``energy``, ``momentum_inertial`` (``A(q)^T H``), ``quat_norm`` and ``more``; each
        has inputs ``('x', 'p')`` and one output named like its key.

    Examples
    --------
    >>> import casadi as ca
    >>> from appdyn.dynamics.momentum.wheels import attitude_invariants
    >>> x, p = ca.SX.sym("x", 7), ca.SX.sym("p", 0)
    >>> sorted(attitude_invariants(x, p, x[4:7], 0.5 * ca.sumsqr(x[4:7])))
    ['energy', 'momentum_inertial', 'quat_norm']
    """
    q = x[0:4]
    exprs = {"energy": energy, "momentum_inertial": ca.mtimes(dcm_from_quat(q).T, H),
             "quat_norm": ca.norm_2(q), **more}
    return {key: ca.Function(key, [x, p], [value], ["x", "p"], [key])
            for key, value in exprs.items()}


@cache.memoize
def _wheel_spacecraft(inertia_key: tuple, axes_key: tuple, wheel_key: tuple,
                      external_torque: bool) -> Model:
    hub = np.array(inertia_key).reshape(3, 3)
    A = np.array(axes_key).reshape(3, -1)
    J = np.array(wheel_key)
    n = J.size
    x = ca.SX.sym("x", 7 + n)
    u = ca.SX.sym("u", n + (3 if external_torque else 0))
    p = ca.SX.sym("p", 0)
    q, w, W = x[0:4], x[4:7], x[7:]
    tau = u[0:n]
    L = u[n:n + 3] if external_torque else None
    locked = hub + A @ np.diag(J) @ A.T
    H, wdot, hdot = rotor_dynamics(locked, A, w, ca.DM(J) * W, L, wheel_inertia=J, motor=tau)
    f = ca.Function("wheel_spacecraft", [x, u, p], [ca.vertcat(quat_rate(q, w), wdot, hdot / J)],
                    ["x", "u", "p"], ["xdot"])
    wheel_momentum = ca.DM(J) * (ca.mtimes(ca.DM(A).T, w) + W)  # absolute, about a_i
    energy = 0.5 * ca.dot(w, ca.mtimes(ca.DM(hub), w)) + 0.5 * ca.dot(wheel_momentum, wheel_momentum / J)
    speeds = tuple(f"W{i + 1}" for i in range(n))
    torques = tuple(f"tau{i + 1}" for i in range(n))
    controls = torques + (("L1", "L2", "L3") if external_torque else ())
    units = {**ATTITUDE_UNITS, **{k: "rad/s" for k in speeds}, **{k: "N m" for k in torques}}
    return Model(f=f, states=RIGID_BODY_STATES + speeds, controls=controls,
                 units={k: v for k, v in units.items() if k in RIGID_BODY_STATES + speeds + controls},
                 invariants=attitude_invariants(x, p, H, energy, wheel_momentum=wheel_momentum),
                 name="wheel_spacecraft", attitude=(0, 4))


def wheel_spacecraft(inertia, axes, wheel_inertia, *, external_torque: bool = False) -> Model:
    """Rigid hub with ``n`` reaction wheels driven by motor torques (module docstring).

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2]
        Hub inertia about the system mass center in body axes, including the wheels' masses
        and transverse moments but *not* their axial moments ``J_i`` (with them it is
        ``I + sum_i J_i a_i a_i^T``, the inertia with the wheels locked).
    axes : array_like, shape (3, n), or (3,) for one wheel
        Unit spin axes ``a_i`` in body axes, one per column.
    wheel_inertia : float or array_like, shape (n,) [kg m^2]
        Axial moments ``J_i > 0`` (one value for all wheels, or one per wheel).
    external_torque : bool, optional
        Add the body-frame external torque ``L1, L2, L3`` [N m] to the controls.

    Returns
    -------
    Model
        ``x = [q1..q4, w1..w3, W1..Wn]`` (``W_i`` [rad/s]: wheel speed relative to the hub,
        about ``a_i``); ``u = [tau1..taun]`` (motor torque on wheel ``i`` about ``a_i``,
        [N m]; the hub feels ``-tau_i a_i``), then ``[L1, L2, L3]`` if ``external_torque``;
        no parameters; ``attitude = (0, 4)``. Invariants: ``momentum_inertial`` [N m s]
        (``A(q)^T H``, hub and wheels; conserved for ``L = 0`` whatever the motor torques),
        ``energy`` [J] (``1/2 w.I w + 1/2 sum_i J_i (a_i.w + W_i)^2``; its rate is
        ``sum_i tau_i W_i + L.w``), ``quat_norm`` and ``wheel_momentum`` [N m s] (shape n:
        each wheel's absolute axial momentum ``J_i (a_i.w + W_i)``). Cached by the arguments.

    Raises
    ------
    TypeError
        If an argument does not hold numbers.
    ValueError
        Naming the argument: bad ``inertia`` (see `dynamics.validate.check_inertia`),
        ``axes`` not of shape (3, n) or a column not of unit length, ``wheel_inertia`` not
        positive or of the wrong length.

    References
    ----------
    .. [1] Rheinfurth & Wilson, NASA RP-1262, Sec. 4.7, Eqs. 4.147-4.148.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.momentum.wheels import wheel_spacecraft
    >>> model = wheel_spacecraft([10.0, 12.0, 8.0], np.eye(3), 0.05)
    >>> model.states[7:], model.controls
    (('W1', 'W2', 'W3'), ('tau1', 'tau2', 'tau3'))
    >>> xdot = model.rhs([0, 0, 0, 1, 0, 0, 0, 0, 0, 0], [0.01, 0, 0])  # spin up wheel 1
    >>> np.round(xdot[[4, 7]], 12)  # hub: -tau/I1; wheel: tau/J - wdot1
    array([-0.001,  0.201])
    """
    hub = check_inertia(inertia)
    A = unit_axes(axes, "axes")
    J = positive_each(wheel_inertia, "wheel_inertia", A.shape[1])
    if not isinstance(external_torque, (bool, np.bool_)):
        raise TypeError(f"`external_torque` must be True or False, got {external_torque!r}")
    return _wheel_spacecraft(tuple(hub.reshape(-1).tolist()), tuple(A.reshape(-1).tolist()),
                             tuple(J.tolist()), bool(external_torque))

# =============================================================== dynamics/momentum/cmg.py
#: The levels of `cmg_spacecraft`.
FIDELITIES = ("exact", "torque")


def _spin_transverse(geometry: ClusterGeometry, delta):
    """Lists of the columns ``s_i`` and ``t_i = ds_i/d(delta_i)`` (CasADi 3x1)."""
    S0, T0 = geometry.spin_axes0, geometry.transverse_axes0
    c, s = ca.cos(delta), ca.sin(delta)
    spins = [ca.DM(S0[:, i]) * c[i] + ca.DM(T0[:, i]) * s[i] for i in range(geometry.n)]
    transverse = [ca.DM(T0[:, i]) * c[i] - ca.DM(S0[:, i]) * s[i] for i in range(geometry.n)]
    return spins, transverse


@cache.memoize
def _cmg_spacecraft(inertia_key: tuple, gimbal_key: tuple, spin_key: tuple, h_key: tuple,
                    fidelity: str, rotor_key: tuple, gimbal_inertia_key: tuple,
                    external_torque: bool) -> Model:
    n = len(h_key)
    geometry = ClusterGeometry(np.array(gimbal_key).reshape(3, n),
                               np.array(spin_key).reshape(3, n), np.array(h_key))
    G, h = geometry.gimbal_axes, geometry.h
    x = ca.SX.sym("x", 7 + n)
    u = ca.SX.sym("u", n + (3 if external_torque else 0))
    p = ca.SX.sym("p", 0)
    q, w, delta, rate = x[0:4], x[4:7], x[7:], u[0:n]
    L = u[n:n + 3] if external_torque else ca.DM.zeros(3)
    spins, transverse = _spin_transverse(geometry, delta)
    rotors = [h[i] * spins[i] for i in range(n)]
    inertia = ca.DM(np.array(inertia_key).reshape(3, 3))
    if fidelity == "torque":
        H = ca.mtimes(inertia, w) + sum(rotors)
        torque = sum(cmg_torque(rate[i] * ca.DM(G[:, i]), rotors[i]) - ca.cross(w, rotors[i])
                     for i in range(n))
        wdot = ca.solve(inertia, L + torque - ca.cross(w, ca.mtimes(inertia, w)))
    else:
        for i, J in enumerate(rotor_key):
            inertia = inertia + J * ca.mtimes(spins[i], spins[i].T)
        H = ca.mtimes(inertia, w) + sum(rotors)
        gimbal_momentum = sum(Jg * rate[i] * ca.DM(G[:, i]) for i, Jg in enumerate(gimbal_inertia_key))
        rhs = L - ca.cross(w, H + gimbal_momentum)
        for i in range(n):
            s_i, t_i = spins[i], transverse[i]
            turning = rotor_key[i] * (t_i * ca.dot(s_i, w) + s_i * ca.dot(t_i, w)) if rotor_key else 0
            rhs = rhs - rate[i] * (h[i] * t_i + turning)
        wdot = ca.solve(inertia, rhs)
    f = ca.Function("cmg_spacecraft", [x, u, p], [ca.vertcat(quat_rate(q, w), wdot, rate)],
                    ["x", "u", "p"], ["xdot"])
    angles = tuple(f"d{i + 1}" for i in range(n))
    rates = tuple(f"d{i + 1}_dot" for i in range(n))
    controls = rates + (("L1", "L2", "L3") if external_torque else ())
    units = {**{k: v for k, v in ATTITUDE_UNITS.items() if k in RIGID_BODY_STATES + controls},
             **{k: "rad" for k in angles}, **{k: "rad/s" for k in rates}}
    energy = 0.5 * ca.dot(w, ca.mtimes(inertia, w))
    return Model(f=f, states=RIGID_BODY_STATES + angles, controls=controls, units=units,
                 invariants=attitude_invariants(x, p, H, energy, cmg_momentum=sum(rotors)),
                 name="cmg_spacecraft" if fidelity == "exact" else "cmg_spacecraft_torque",
                 attitude=(0, 4))


def cmg_spacecraft(inertia, gimbal_axes, spin_axes0, h, *,
                   fidelity: Literal["exact", "torque"] = "exact", rotor_inertia=None,
                   gimbal_inertia=None, external_torque: bool = False) -> Model:
    """Rigid spacecraft with ``n`` single-gimbal CMGs driven by gimbal rates (module docstring).

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2]
        Vehicle inertia about the system mass center, body axes: everything that does not
        change with the gimbal angles (with ``rotor_inertia=None``, all of it).
    gimbal_axes : array_like, shape (3, n)
        Unit gimbal axes ``g_i`` in body axes, one per column (refused, not normalized, when
        not of unit length to 1e-9).
    spin_axes0 : array_like, shape (3, n)
        Unit spin axes ``s0_i`` at ``delta_i = 0``, each perpendicular to ``g_i`` (to 1e-9).
    h : float or array_like, shape (n,) [N m s]
        Rotor momenta ``h_i > 0`` relative to the gimbals (constant).
    fidelity : {'exact', 'torque'}, optional
        ``'exact'``: momentum of rotors and gimbals carried in the total angular momentum;
        ``'torque'``: the seed's CMG torque ``-w_c x H_m`` (Eq. 4.150) plus the Coriolis term
        on a rigid body (see the module docstring for both and where they agree).
    rotor_inertia : float or array_like, shape (n,) [kg m^2], optional
        ``'exact'`` only: ``J_i = J_s - J_t > 0``, unit ``i``'s (gimbal plus rotor) moment about
        ``s_i`` minus that about ``t_i`` -- the inertia that turns with the gimbal angle
        (about half the rotor's spin moment for a thin disk in a light gimbal).
    gimbal_inertia : float or array_like, shape (n,) [kg m^2], optional
        ``'exact'`` only: ``J_g,i > 0``, unit ``i``'s moment about ``g_i``; adds the momentum
        of the gimbal rate ``J_g,i delta_i' g_i`` (its acceleration torque is not modelled).
    external_torque : bool, optional
        Add the body-frame external torque ``L1, L2, L3`` [N m] to the controls.

    Returns
    -------
    Model
        ``x = [q1..q4, w1..w3, d1..dn]`` (gimbal angles [rad]), ``u = [d1_dot..dn_dot]``
        (gimbal rates [rad/s]) then ``[L1, L2, L3]`` if ``external_torque``; no parameters;
        ``attitude = (0, 4)``. Invariants: ``momentum_inertial`` [N m s] (``A(q)^T (I(delta) w
        + sum_i h_i s_i)``), ``energy`` [J] (``1/2 w.I(delta) w``: the body's kinetic energy
        with the gimbals and rotors locked, as for `dynamics.spinning.gyrostat_model`;
        conserved while the gimbals stand still, changed at the rate ``-sum_i delta_i'
        (h_i t_i.w + J_i (s_i.w)(t_i.w))`` when they turn), ``quat_norm`` and
        ``cmg_momentum`` [N m s] (``sum_i h_i s_i``, body axes). Cached by the arguments.

    Raises
    ------
    TypeError
        If an argument does not hold numbers or ``fidelity`` is not a string.
    ValueError
        Naming the argument (and unit): bad ``inertia``; axes of the wrong shape, zero or not
        of unit length; ``spin_axes0`` not perpendicular to ``gimbal_axes``; ``h``,
        ``rotor_inertia`` or ``gimbal_inertia`` not positive or of the wrong length;
        ``rotor_inertia``/``gimbal_inertia`` with ``fidelity='torque'``; an unknown ``fidelity``.

    References
    ----------
    .. [1] Rheinfurth & Wilson, NASA RP-1262, Sec. 4.7, Eqs. 4.147-4.152.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.momentum.cmg import cmg_spacecraft
    >>> g, s0 = [[0.0], [0.0], [1.0]], [[1.0], [0.0], [0.0]]  # one CMG, gimbal about z
    >>> model = cmg_spacecraft([10.0, 10.0, 10.0], g, s0, h=2.0)
    >>> model.states[7:], model.controls
    (('d1',), ('d1_dot',))
    >>> xdot = model.rhs([0, 0, 0, 1, 0, 0, 0, 0.0], [0.5])  # body at rest, gimbal turning
    >>> np.round(xdot[4:7], 12) + 0.0  # I w' = -h delta' t, t = g x s = e_y
    array([ 0. , -0.1,  0. ])
    """
    I = check_inertia(inertia)
    geometry = ClusterGeometry(gimbal_axes, spin_axes0, h)
    fidelity = one_of(fidelity, "fidelity", FIDELITIES)
    if not isinstance(external_torque, (bool, np.bool_)):
        raise TypeError(f"`external_torque` must be True or False, got {external_torque!r}")
    extra = {}
    for name, value in (("rotor_inertia", rotor_inertia), ("gimbal_inertia", gimbal_inertia)):
        if value is None:
            extra[name] = ()
        elif fidelity == "torque":
            raise ValueError(f"`{name}` is not used by fidelity='torque' (the torque model "
                             "neglects rotor and gimbal inertia); use fidelity='exact'")
        else:
            extra[name] = tuple(positive_each(value, name, geometry.n).tolist())
    return _cmg_spacecraft(tuple(I.reshape(-1).tolist()),
                           tuple(geometry.gimbal_axes.reshape(-1).tolist()),
                           tuple(geometry.spin_axes0.reshape(-1).tolist()),
                           tuple(geometry.h.tolist()), fidelity, extra["rotor_inertia"],
                           extra["gimbal_inertia"], bool(external_torque))
