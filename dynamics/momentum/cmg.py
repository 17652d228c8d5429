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
prescribed, their derivatives are not model inputs; `dynamics.scene.CMGCluster` with
``drive="torque"`` drives the gimbals by torques and has it) and the rotor spin-up (``h_i``
constant).
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

import numpy as np

from .. import cache
from ..model import Model
from ..scene import CMGCluster, ExternalTorque, RigidHub, Scene
from ..scene.cmgs import FIDELITIES

__all__ = ["FIDELITIES", "cmg_spacecraft"]


@cache.memoize_values
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
        ``cmg_momentum`` [N m s] (``sum_i h_i s_i``, body axes). It is the scene
        ``Scene(RigidHub(inertia), CMGCluster(gimbal_axes, spin_axes0, h, ...)[,
        ExternalTorque()], name=...)`` (`dynamics.scene`), cached by value.

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
    hub = RigidHub(inertia)
    cmgs = CMGCluster(gimbal_axes, spin_axes0, h, rotor_inertia=rotor_inertia,
                      gimbal_inertia=gimbal_inertia, fidelity=fidelity)
    if not isinstance(external_torque, (bool, np.bool_)):
        raise TypeError(f"`external_torque` must be True or False, got {external_torque!r}")
    torque = (ExternalTorque(),) if external_torque else ()
    name = "cmg_spacecraft" if cmgs.fidelity == "exact" else "cmg_spacecraft_torque"
    return Scene(hub, cmgs, *torque, name=name).model()
