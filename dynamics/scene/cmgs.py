"""Single-gimbal control moment gyros on the hub: `CMGCluster` (seed Sec. 4.7, Eqs.
4.147-4.152; the derivation is the docstring of `dynamics.momentum.cmg`).

Unit ``i`` has the unit gimbal axis ``g_i`` and the spin axis ``s_i = cos(d_i) s0_i +
sin(d_i) (g_i x s0_i)`` at the gimbal angle ``d_i``, ``t_i = g_i x s_i`` (so ``s_i' = d_i'
t_i``); its rotor keeps the momentum ``h_i s_i`` relative to the gimbal (a rotor motor holds
its speed). Of the unit's (gimbal plus rotor) inertia only ``J_i s_i s_i^T`` (``J_i =
J_s - J_t``, ``rotor_inertia``) changes with ``d_i``; the rest, ``J_g,i g_i g_i^T`` included,
belongs to the hub's inertia. The unit turns at ``w + d_i' g_i``.

Rate drive (``drive="rate"``)
-----------------------------
A servo imposes the gimbal rates: they are the controls ``d1_dot..dn_dot`` and the rates of
the coordinates ``d1..dn``. Each unit is a `Body` with the angular momentum ``J_i s_i s_i^T w +
h_i s_i + J_g,i d_i' g_i`` (what the hub's inertia does not already hold) and the angular
velocity ``w + d_i' g_i``. The gimbal acceleration ``d_i''`` is the derivative of a control,
which is not a model input: the assembly holds the controls constant over the derivative, so
the gimbal-acceleration torque ``-J_g,i d_i'' g_i`` is *not* in a rate-driven model (it cannot
be: the model would need the rates' derivatives as inputs). ``momentum_inertial`` leaves out
the control's share ``J_g,i d_i' g_i`` (it would not be a function of the state).

Torque drive (``drive="torque"``, needs ``gimbal_inertia``)
-----------------------------------------------------------
The gimbal rates are speeds (states ``d1_dot..dn_dot``), driven by the gimbal motor torques
``tg1..tgn`` [N m] (controls), each doing work on its relative rate ``d_i'``. Kane's method
then gives the gimbal-acceleration torque exactly: the gimbal's axial momentum is ``J_g,i
(g_i.w + d_i')``, so the unit carries ``J_g,i (g_i.w + d_i') g_i`` and a second body takes back
the ``J_g,i (g_i.w) g_i`` the hub's inertia holds while turning at ``w`` (its partial angular
velocity has no ``d_i'`` part). This is how a gimbal's inertia enters physically: a motor
torque accelerates the gimbal and the hub feels the reaction.

Fidelity ``"torque"`` is the seed's approximation (Eqs. 4.149-4.150): no rotor or gimbal
inertia, the torque ``-h_i d_i' t_i`` plus the Coriolis term ``-w x h_i s_i`` on the body;
rate drive only.

Energy
------
The kinetic energy with each rotor locked to its gimbal (the rotors' spin energy is kept up
by their motors and left out): the hub's ``1/2 w.I w`` plus ``1/2 J_i (s_i.w)^2`` per unit and,
with the torque drive, the gimbal's ``1/2 J_g,i ((g_i.w + d_i')^2 - (g_i.w)^2)``. Its rate is
exactly ``sum_i tg_i d_i' + L.w`` with the torque drive (the rotor momenta act gyroscopically
and do no work). With the rate drive the gimbal term, a control's, is left out (``1/2
w.I(d) w``, as `dynamics.momentum.cmg.cmg_spacecraft`'s energy): it changes while the
gimbals turn.
"""
from __future__ import annotations

from dataclasses import KW_ONLY, dataclass

import casadi as ca
import numpy as np

from ..validate import one_of, positive_each
from .contract import Body, Contribution, Load, Part, PartVariables, Variable, bounds_from_u_max

__all__ = ["CMGCluster", "FIDELITIES", "DRIVES", "spin_transverse"]

#: The fidelities of `CMGCluster` (and of `dynamics.momentum.cmg.cmg_spacecraft`).
FIDELITIES = ("exact", "torque")
#: How the gimbals of a `CMGCluster` are driven.
DRIVES = ("rate", "torque")


def spin_transverse(spin_axes0, transverse_axes0, delta):
    """The spin axes ``s_i`` and transverse axes ``t_i = g_i x s_i = ds_i/d(delta_i)``.

    Parameters
    ----------
    spin_axes0, transverse_axes0 : ndarray, shape (3, n)
        ``s0_i`` and ``g_i x s0_i`` as columns.
    delta : casadi SX, n x 1 [rad]
        Gimbal angles.

    Returns
    -------
    spins, transverse : list of casadi SX, 3x1 each

    Examples
    --------
    >>> import casadi as ca
    >>> import numpy as np
    >>> from appdyn.dynamics.scene.cmgs import spin_transverse
    >>> s, t = spin_transverse(np.c_[[1.0, 0, 0]], np.c_[[0, 1.0, 0]], ca.DM([np.pi / 2]))
    >>> np.round(np.array(s[0]).ravel(), 12) + 0.0, np.round(np.array(t[0]).ravel(), 12) + 0.0
    (array([0., 1., 0.]), array([-1.,  0.,  0.]))
    """
    c, s = ca.cos(delta), ca.sin(delta)
    n = spin_axes0.shape[1]
    spins = [ca.DM(spin_axes0[:, i]) * c[i] + ca.DM(transverse_axes0[:, i]) * s[i]
             for i in range(n)]
    transverse = [ca.DM(transverse_axes0[:, i]) * c[i] - ca.DM(spin_axes0[:, i]) * s[i]
                  for i in range(n)]
    return spins, transverse


@dataclass(frozen=True)
class CMGCluster(Part):
    """Single-gimbal control moment gyros, driven by gimbal rates or by gimbal torques.

    ``n`` units (module docstring): states ``d1..dn`` [rad], and either the gimbal-rate
    controls ``d1_dot..dn_dot`` [rad/s] (``drive="rate"``) or the gimbal-rate states
    ``d1_dot..dn_dot`` with the gimbal-torque controls ``tg1..tgn`` [N m]
    (``drive="torque"``).

    Parameters
    ----------
    gimbal_axes : array_like, shape (3, n)
        Unit gimbal axes ``g_i`` in hub axes, one per column (refused, not normalized, when
        not of unit length to 1e-9; `dynamics.momentum.cluster.ClusterGeometry`).
    spin_axes0 : array_like, shape (3, n)
        Unit spin axes ``s0_i`` at ``d_i = 0``, each perpendicular to ``g_i``.
    h : float or array_like, shape (n,) [N m s]
        Rotor momenta ``h_i > 0`` relative to the gimbals (constant).
    rotor_inertia : float or array_like, shape (n,) [kg m^2], optional
        ``J_i = J_s - J_t > 0``: unit ``i``'s moment about ``s_i`` minus that about ``t_i``,
        the inertia that turns with the gimbal angle (the rest is in the hub's inertia).
    gimbal_inertia : float or array_like, shape (n,) [kg m^2], optional
        ``J_g,i > 0``: unit ``i``'s moment about ``g_i`` (also in the hub's inertia). Adds the
        gimbal-rate momentum ``J_g,i d_i' g_i``; with ``drive="torque"`` also the
        gimbal-acceleration torque.
    fidelity : {'exact', 'torque'}, optional
        ``'torque'``: the seed's CMG torque model (no ``rotor_inertia`` or
        ``gimbal_inertia``; rate drive only).
    u_max : float or array_like, shape (n,), optional
        Control bound: gimbal rate [rad/s] (rate drive) or gimbal torque [N m] (torque
        drive).
    drive : {'rate', 'torque'}, optional
        What the controls are (module docstring).
    name : str, optional
    parent : str, optional
        The scene name of the part it sits on (default: the hub); its positions and axes
        are then that part's (`dynamics.scene.contract`, parts on parts).

    Notes
    -----
    Invariants: ``cmg_momentum`` [N m s] (``sum_i h_i s_i``, hub axes) and the scene's
    ``energy`` with the meaning of the module docstring. With ``L = 0`` the scene's
    ``momentum_inertial`` is conserved exactly for any gimbal torques (torque drive: it holds
    all the momentum) and for any gimbal-rate history without ``gimbal_inertia`` (rate
    drive). With it, the rate drive's invariant leaves out the control's share
    ``A^T sum_i J_g,i d_i' g_i``; the total with that share is conserved while the rates are
    constant (the neglected gimbal acceleration changes it otherwise).

    Raises
    ------
    TypeError
        If an axis or inertia does not hold numbers, or ``fidelity``/``drive`` is not a str.
    ValueError
        Naming the argument: bad axes or ``h`` (`ClusterGeometry`); ``rotor_inertia``,
        ``gimbal_inertia`` or ``u_max`` not positive or of the wrong length; an inertia with
        ``fidelity='torque'``; ``drive='torque'`` without ``gimbal_inertia`` or with
        ``fidelity='torque'``; an unknown ``fidelity`` or ``drive``.

    Examples
    --------
    One CMG gimballed about z with its rotor along x; the body at rest, the gimbal turning:

    >>> import numpy as np
    >>> from appdyn.dynamics.scene import CMGCluster, RigidHub, Scene
    >>> cmg = CMGCluster([[0.0], [0.0], [1.0]], [[1.0], [0.0], [0.0]], 2.0, u_max=1.0)
    >>> model = Scene(RigidHub([10.0, 10.0, 10.0]), cmg).model()
    >>> model.states[7:], model.controls, model.bounds["d1_dot"]
    (('d1',), ('d1_dot',), (-1.0, 1.0))
    >>> np.round(model.rhs([0, 0, 0, 1, 0, 0, 0, 0.0], [0.5])[4:7], 12) + 0.0  # I w' = -h d' t
    array([ 0. , -0.1,  0. ])

    Driven by a gimbal torque, the gimbal and the body share its reaction:

    >>> cmg = CMGCluster([[0.0], [0.0], [1.0]], [[1.0], [0.0], [0.0]], 2.0, gimbal_inertia=0.5,
    ...                  drive="torque")
    >>> model = Scene(RigidHub([10.0, 10.0, 10.0]), cmg).model()
    >>> model.states[7:], model.controls
    (('d1', 'd1_dot'), ('tg1',))
    >>> xdot = model.rhs([0, 0, 0, 1, 0, 0, 0, 0.0, 0.0], [1.0])  # d'' = tg / (J_g (1 - J_g/I3))
    >>> round(float(xdot[6]), 12), round(float(xdot[8]), 12)
    (-0.105263157895, 2.105263157895)
    """

    gimbal_axes: tuple
    spin_axes0: tuple
    h: tuple
    _: KW_ONLY
    rotor_inertia: tuple | None = None
    gimbal_inertia: tuple | None = None
    fidelity: str = "exact"
    u_max: tuple | None = None
    drive: str = "rate"
    name: str | None = None
    parent: str | None = None
    kind = "cmgs"

    def __post_init__(self):
        # imported here: dynamics.momentum builds its spacecraft models from scenes
        from ..momentum.cluster import ClusterGeometry
        geo = ClusterGeometry(self.gimbal_axes, self.spin_axes0, self.h)
        n = geo.n
        fidelity = one_of(self.fidelity, "fidelity", FIDELITIES)
        drive = one_of(self.drive, "drive", DRIVES)
        for key in ("rotor_inertia", "gimbal_inertia"):
            value = getattr(self, key)
            if value is None:
                continue
            if fidelity == "torque":
                raise ValueError(f"`{key}` is not used by fidelity='torque' (the torque model "
                                 "neglects rotor and gimbal inertia); use fidelity='exact'")
            object.__setattr__(self, key, tuple(positive_each(value, key, n).tolist()))
        if drive == "torque" and fidelity == "torque":
            raise ValueError("`drive='torque'` needs fidelity='exact' (the torque model has no "
                             "gimbal inertia for a gimbal torque to accelerate)")
        if drive == "torque" and self.gimbal_inertia is None:
            raise ValueError("`drive='torque'` needs `gimbal_inertia` (a gimbal torque "
                             "accelerates the gimbal's inertia about its axis)")
        object.__setattr__(self, "gimbal_axes", tuple(map(tuple, geo.gimbal_axes.tolist())))
        object.__setattr__(self, "spin_axes0", tuple(map(tuple, geo.spin_axes0.tolist())))
        object.__setattr__(self, "h", tuple(geo.h.tolist()))
        object.__setattr__(self, "fidelity", fidelity)
        object.__setattr__(self, "drive", drive)
        if self.u_max is not None:
            object.__setattr__(self, "u_max", tuple(
                b[1] for b in bounds_from_u_max(self.u_max, n)))

    @property
    def n(self) -> int:
        """Number of units."""
        return len(self.h)

    def variables(self) -> PartVariables:
        n = self.n
        bounds = bounds_from_u_max(self.u_max, n)
        angles = tuple(Variable(f"d{i + 1}", "rad", terminal="free") for i in range(n))
        if self.drive == "rate":
            return PartVariables(coords=angles, controls=tuple(
                Variable(f"d{i + 1}_dot", "rad/s", bounds=bounds[i]) for i in range(n)))
        return PartVariables(
            coords=angles,
            speeds=tuple(Variable(f"d{i + 1}_dot", "rad/s") for i in range(n)),
            controls=tuple(Variable(f"tg{i + 1}", "N m", bounds=bounds[i]) for i in range(n)))

    def contribute(self, frame, own) -> Contribution:
        G, S0 = np.array(self.gimbal_axes), np.array(self.spin_axes0)
        spins, _ = spin_transverse(S0, np.cross(G, S0, axis=0), own.coords)
        torque_drive = self.drive == "torque"
        rates = own.speeds if torque_drive else own.controls
        J = self.rotor_inertia or (0.0,) * self.n
        Jg = self.gimbal_inertia or (0.0,) * self.n
        w, zero = frame.w, ca.SX.zeros(3)
        bodies, loads, locked, kinetic = [], [], [], 0.0
        for i in range(self.n):
            g, s = ca.DM(G[:, i]), spins[i]
            sw = ca.dot(s, w)
            held = self.h[i] * s + (J[i] * sw * s if J[i] else 0.0)
            locked.append(held)
            kinetic = kinetic + 0.5 * J[i] * sw ** 2
            if torque_drive:
                gw = ca.dot(g, w)
                gimbal = Jg[i] * (gw + rates[i]) * g
                # the hub's inertia holds J_g g g^T turning at w: take it back
                bodies.append(Body(velocity=zero, angular_velocity=w, momentum=zero,
                                   angular_momentum=-Jg[i] * gw * g, position=zero))
                kinetic = kinetic + 0.5 * Jg[i] * ((gw + rates[i]) ** 2 - gw ** 2)
                loads.append(Load(own.controls[i], rates[i]))
            else:
                gimbal = Jg[i] * rates[i] * g if Jg[i] else 0.0
            bodies.append(Body(velocity=zero, angular_velocity=w + rates[i] * g, momentum=zero,
                               angular_momentum=held + gimbal, position=zero))
        return Contribution(
            rates=None if torque_drive else own.controls, bodies=bodies, loads=loads,
            kinetic=kinetic, momentum=None if torque_drive else sum(locked, zero),
            invariants={"cmg_momentum": sum((self.h[i] * spins[i] for i in range(self.n)),
                                            zero)})
