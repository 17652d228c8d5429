"""Spacecraft with single-gimbal control moment gyros (Rheinfurth & Wilson, NASA RP-1262,
Sec. 4.7, Eqs. 4.147-4.152).

Geometry (`dynamics.momentum.cluster.ClusterGeometry`, shared with the cluster analysis):
unit ``i`` has the unit gimbal axis ``g_i`` and the unit spin axis at zero gimbal angle
``s0_i`` (perpendicular to ``g_i``); at the gimbal angle ``delta_i``

    ``s_i = cos(delta_i) s0_i + sin(delta_i) (g_i x s0_i)``,   ``t_i = g_i x s_i``,

so ``s_i' = delta_i' t_i`` (body frame). The rotor turns about ``s_i`` at a constant speed
relative to its gimbal, with the relative momentum ``h_i s_i``; the gimbal rates
``delta_i'`` are the controls (a servo imposes them).

Exact model (``fidelity="exact"``)
-----------------------------------
The whole vehicle obeys ``H'|body + w x H = L``. Unit ``i``'s gimbal-plus-rotor assembly has
the moments ``J_s``, ``J_t``, ``J_g`` about ``s_i``, ``t_i``, ``g_i``; since
``s s^T + t t^T + g g^T = E`` its inertia ``J_t E + (J_g - J_t) g g^T + (J_s - J_t) s s^T``
depends on ``delta_i`` only through ``J_i s_i s_i^T`` with ``J_i = J_s - J_t``
(``rotor_inertia``); the rest is constant and belongs to ``inertia`` (``I``). The assembly
also turns at ``delta_i' g_i`` relative to the body, which adds ``J_g,i delta_i' g_i``
(``gimbal_inertia``). Hence, with ``I(delta) = I + sum_i J_i s_i s_i^T``,

    ``H = I(delta) w + sum_i h_i s_i  (+ sum_i J_g,i delta_i' g_i)``,
    ``I(delta) w' = L - I(delta)' w - sum_i h_i delta_i' t_i - w x (H + sum_i J_g,i delta_i' g_i)``,
    ``I(delta)' w = sum_i J_i delta_i' (t_i (s_i.w) + s_i (t_i.w))``.

Not modelled: the gimbal acceleration torque ``-J_g,i delta_i'' g_i`` (the rates are
prescribed, their derivatives are not model inputs) and the rotor spin-up (``h_i`` constant).
``momentum_inertial`` is ``A(q)^T (I(delta) w + sum_i h_i s_i)``: exactly conserved (with
``L = 0``) for any gimbal-rate history when ``gimbal_inertia`` is None; with it the total
``A^T (H + sum_i J_g,i delta_i' g_i)`` changes by the neglected ``A^T sum_i J_g,i
delta_i'' g_i`` (it is conserved for constant rates).

Torque model (``fidelity="torque"``)
------------------------------------
The seed's approximation (Eqs. 4.149-4.150): the rotor momentum is ``H_m = h_i s_i`` alone
(rotor and gimbal inertia neglected beside it) and the gimbal turning it at ``w_c =
delta_i' g_i`` gives the control torque ``L_c = -w_c x H_m = -h_i delta_i' t_i``; the
Coriolis term of Eq. 4.147 stays on the body as ``-w x h_i s_i`` (Eq. 4.152). The body is
the rigid body ``I`` driven by their sum::

    I w' + w x I w = L - sum_i h_i delta_i' t_i - w x sum_i h_i s_i.

It is the exact model with ``rotor_inertia`` and ``gimbal_inertia`` set to zero, and agrees
with the exact model when each rotor spins much faster than the body turns: at fixed
``h_i``, ``J_i = h_i / Omega_i -> 0`` and the difference shrinks like ``|w| / Omega_i``.
"""
from __future__ import annotations

from typing import Literal

import casadi as ca
import numpy as np

from .. import cache
from ..attitude import quat_rate
from ..model import Model
from ..rigid_body import RIGID_BODY_STATES
from ..validate import check_inertia, one_of, positive_each
from .cluster import ClusterGeometry
from .gyroscopic import cmg_torque
from .wheels import ATTITUDE_UNITS, attitude_invariants

__all__ = ["FIDELITIES", "cmg_spacecraft"]

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
