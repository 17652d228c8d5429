"""Reaction wheels: a rigid hub carrying wheels that spin about body-fixed axes
(Rheinfurth & Wilson, NASA RP-1262, Sec. 4.7, Eqs. 4.147-4.148), and the body-plus-rotor
derivation (`dynamics.spinning.gyrostat_model`, a scene, holds the wheel's speed).

Derivation
----------
Hub inertia ``I`` about the system mass center (the wheels' transverse moments included,
their axial moments not); wheel ``i`` is axisymmetric about the unit body axis ``a_i`` with
axial moment ``J_i`` and turns at ``W_i`` relative to the hub. With the *locked* inertia
``I_L = I + sum_i J_i a_i a_i^T`` and the wheels' relative momenta ``h_i = J_i W_i``:

* angular momentum (body axes): ``H = I w + sum_i J_i a_i (a_i.w + W_i) = I_L w + sum_i h_i a_i``;
* wheel ``i`` about its axis (Euler's law; the motor torque ``tau_i`` acts on the wheel,
  ``-tau_i a_i`` on the hub): ``J_i (a_i.w' + W_i') = tau_i``;
* whole vehicle: ``H'|body + w x H = L`` (external torque ``L``). Substituting the wheels::

      I w' = L - sum_i a_i tau_i - w x H,        W_i' = tau_i / J_i - a_i.w'.

  The seed's momentum-wheel torque ``L_c = -I_m w_c'`` (Eq. 4.148) is the ``-a_i tau_i``
  term; its Coriolis term (Eq. 4.152) is inside ``w x H``.
* a wheel *held* at constant relative speed (``W_i' = 0``: the motor supplies
  ``tau_i = J_i a_i.w'``) gives ``I_L w' = L - w x H`` -- the gyrostat.
* kinetic energy ``E = 1/2 w.I w + 1/2 sum_i J_i (a_i.w + W_i)^2``, and
  ``E' = L.w + sum_i tau_i W_i`` exactly (the work of the external torque and the motors).

`rotor_dynamics` is that derivation, written once (the gyrostat's); `wheel_spacecraft` is the
scene of a `dynamics.scene.RigidHub` carrying `dynamics.scene.ReactionWheels`, whose assembly
derives the same equations by Kane's method.
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from .. import cache
from ..model import Model
from ..scene import ExternalTorque, ReactionWheels, RigidHub, Scene
from ..validate import check_inertia, finite_array, is_symbolic, positive_each, unit_axes

__all__ = ["rotor_dynamics", "wheel_spacecraft"]


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


@cache.memoize_values
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
        each wheel's absolute axial momentum ``J_i (a_i.w + W_i)``). It is the scene
        ``Scene(RigidHub(inertia), ReactionWheels(axes, wheel_inertia)[, ExternalTorque()],
        name="wheel_spacecraft")`` (`dynamics.scene`), cached by value.

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
    hub = RigidHub(inertia)
    A = unit_axes(axes, "axes")
    J = positive_each(wheel_inertia, "wheel_inertia", A.shape[1])
    if not isinstance(external_torque, (bool, np.bool_)):
        raise TypeError(f"`external_torque` must be True or False, got {external_torque!r}")
    torque = (ExternalTorque(),) if external_torque else ()
    return Scene(hub, ReactionWheels(A, J), *torque, name="wheel_spacecraft").model()
