"""`hinged_spin`: stability of two hinged bodies spinning together about a common axis
(a relative equilibrium of `dynamics.hinged_bodies`), reduced to independent coordinates;
`ball_tilt_eigenvalues`, the closed form of the ball hinge with axisymmetric bodies.

The reduction (mass-centre translation, the hinge's constraint directions, the conserved
momenta, the cyclic phases) is described in `hinged_spin`; the steps are recorded in the
report's notes.
"""
from __future__ import annotations

import math

import casadi as ca
import numpy as np

from appdyn.dynamics import cache
from appdyn.dynamics.hinged import hinged_scene
from appdyn.dynamics.scene import Scene
from appdyn.dynamics.results import timed

from .closed_forms import axis_kind, principal_moments, rigid_spin_lambda2
from .common import check_number, spectrum_text
from .report import Quantity, StabilityReport, build_report
from .spin_scene import attitude_subsystem, spin_linearization

__all__ = ["hinged_spin", "hinged_scene", "ball_tilt_eigenvalues"]


_TWO_BODY = {"p1": "q1_rel", "p2": "q2_rel", "u1": "w1_2", "u2": "w2_2"}
"""The ball panel's reduced states -> the two-body names (``q_rel``: body 1 -> body 2, which
is the panel's ``p``; ``w_2``: body 2's angular velocity in its own axes)."""


@cache.constructs
def _two_body_coordinates(scene: Scene, x, red):
    """``red`` (reduced states ``w1, w2, p1, p2, u1, u2`` of a ball panel) in the two-body
    coordinates ``w1, w2, q1_rel, q2_rel, w1_2, w2_2``: ``q_rel = p`` and body 2's rate
    ``w_2 = A(p) w + u`` (panel axes), linearized at ``x`` (a similarity transform: the
    eigenvalues do not change)."""
    from dataclasses import replace

    from appdyn.dynamics.attitude import dcm_from_quat

    model = attitude_subsystem(scene)
    xs = ca.SX.sym("x", model.nx)
    lay = model.layout["panel"]
    p, u = xs[lay.coords], xs[lay.speeds]
    w = xs[model.layout["hub"].speeds]
    jac = ca.Function("w_2", [xs], [ca.jacobian(ca.mtimes(dcm_from_quat(p), w) + u, xs)])
    J = np.asarray(jac(x), dtype=float)
    T = np.eye(red.n)   # the eliminated w3, p3, p4, u3 do not enter w1_2, w2_2 here
    for i, name in enumerate(red.states):
        if name in ("u1", "u2"):
            T[i] = [J[int(name[1]) - 1, model.states.index(s)] for s in red.states]
    Ti = np.linalg.inv(T)
    states = tuple(_TWO_BODY.get(s, s) for s in red.states)
    units = {s: ("-" if s.startswith("q") else "rad/s") for s in states}
    return replace(red, A=T @ red.A @ Ti, B=T @ red.B, C=np.eye(red.n),
                   D=np.zeros((red.n, len(red.inputs))), states=states,
                   residual=T @ red.residual, units=units,
                   notes=red.notes + ("two-body coordinates: q1_rel, q2_rel = p1, p2 (the "
                                      "relative quaternion body 1 -> body 2); w1_2, w2_2 = "
                                      "body 2's rate A(p) w + u in its own axes",))


def _hinged_check(m1, inertia1, m2, inertia2, r1, r2, rate, kind, axis):
    from appdyn.dynamics.validate import check_inertia

    m1 = check_number(m1, "m1", positive=True)
    m2 = check_number(m2, "m2", positive=True)
    I1 = check_inertia(inertia1, name="inertia1")
    I2 = check_inertia(inertia2, name="inertia2")
    for I, name in ((I1, "inertia1"), (I2, "inertia2")):
        if np.max(np.abs(I[2, :2])) > 1e-12 * np.max(np.abs(I)):
            raise ValueError(f"`{name}` must have the spin axis z (body axes) as a principal "
                             f"axis (I13 = I23 = 0), got {I.tolist()}")
    rs = []
    for r, name in ((r1, "r1"), (r2, "r2")):
        try:
            v = np.asarray(r, dtype=float).reshape(-1)
        except (TypeError, ValueError):
            raise ValueError(f"`{name}` must be 3 finite numbers, got {r!r}") from None
        if v.size != 3 or not np.all(np.isfinite(v)):
            raise ValueError(f"`{name}` must be 3 finite numbers, got {r!r}")
        if np.any(v[:2] != 0):
            raise ValueError(f"`{name}` must lie on the spin axis z (the hinge and both mass "
                             f"centres on it: (0, 0, l)), got {v.tolist()}")
        rs.append(v)
    rate = check_number(rate, "rate", nonzero=True)
    if kind not in ("revolute", "ball"):
        raise ValueError(f"`kind` must be 'revolute' or 'ball', got {kind!r}")
    if kind == "ball" and axis is not None:
        raise ValueError(f"`axis` applies to kind='revolute' only, got {axis!r}")
    if kind == "revolute" and axis is not None:
        try:
            a = np.asarray(axis, dtype=float).reshape(-1)
        except (TypeError, ValueError):
            a = np.zeros(0)
        if a.size != 3 or not np.all(np.isfinite(a)) or np.linalg.norm(a) == 0 or \
                np.linalg.norm(a[:2]) > 1e-12 * np.linalg.norm(a):
            raise ValueError(f"`axis` (the revolute hinge axis) must be the spin axis "
                             f"[0, 0, 1] here, got {axis!r}")
    return m1, I1, m2, I2, rs[0], rs[1], rate


def ball_tilt_eigenvalues(m1, A1, C1, m2, A2, C2, l1, l2, rate) -> np.ndarray:
    """Eigenvalues of the reduced ball-hinged pair of axisymmetric bodies (`hinged_spin`).

    Tilts ``zeta_i = u_ix + i u_iy`` of the symmetry axes, hinge a common point, system mass
    centre fixed: the mass centres' transverse offsets are ``-(m2/M) s``, ``(m1/M) s`` with
    ``s = l1 zeta1 + l2 zeta2`` (``r1 = (0, 0, l1)``, ``r2 = (0, 0, -l2)``), and the inertial
    linear equations are ``A_i zeta_i'' - i C_i W zeta_i' + mu l_i s'' = 0``. With
    ``zeta ~ exp(i w t)``: ``w^2 [(a1 a2 - k^2) w^2 - (a1 C2 + a2 C1) W w + C1 C2 W^2] = 0``,
    ``a_i = A_i + mu l_i^2``, ``k = mu l1 l2``. In the frame spinning at ``W`` a mode ``w``
    is ``+-i (w - W)``; of the double ``w = 0`` one (the tilt of the angular momentum) is
    removed by the reduction, the other (a bent pair at rest) stays at ``+-i W``.

    Returns
    -------
    ndarray, shape (6,), complex [1/s]
    """
    mu = m1 * m2 / (m1 + m2)
    a1, a2, k = A1 + mu * l1 * l1, A2 + mu * l2 * l2, mu * l1 * l2
    roots = np.roots([a1 * a2 - k * k, -(a1 * C2 + a2 * C1) * rate, C1 * C2 * rate * rate])
    freqs = [rate] + [float(np.real(w)) - rate for w in roots]   # w = 0, w+, w- shifted
    return np.array([s * 1j * f for f in freqs for s in (1, -1)])


@timed
def hinged_spin(*, m1, inertia1, m2, inertia2, r1, r2, rate, kind="revolute",
                axis=None) -> StabilityReport:
    """Stability of two hinged bodies (`dynamics.hinged.hinged_bodies`) spinning together at
    ``rate`` about the common z axis, reduced to the independent coordinates.

    The bodies' frames are parallel, their mass centres and the hinge lie on the body z axis
    (``r1 = (0, 0, l1)``, ``r2 = (0, 0, -l2)``: body 2 stacked above body 1), z is principal
    for both, and the system mass centre is at rest: the pair spins about z as if rigid, a
    relative equilibrium.

    The reduction: the pair is the scene `hinged_scene` (body 1 the six-degree-of-freedom
    hub, body 2 a `dynamics.scene.HingedPanel`: minimal coordinates, no multipliers) goes
    through `spin_linearization`, as `spin` does: its translation is removed exactly
    (`attitude_subsystem`: ``r`` is cyclic, and on the level set ``P = 0`` of the linear
    momentum the hub's ``v`` follows from the other speeds), it is linearized in body rates
    (the attitude, with the spin phase, does not enter), the hinge angle (``theta``, or the
    relative quaternion's twist and norm) is factored out as cyclic, and the state is
    restricted to the conserved ``|H|^2`` (``w3`` eliminated) or, for the ball, to the
    constant spin rate. Then the panel's axial rate relative to the hub (``theta_dot`` or
    ``u3``; body 2's absolute axial rate ``w3_2`` with ``w3``) is restricted: the hinge
    exerts no torque about z. Revolute: left is ``(w1, w2)``, body 1's transverse rates,
    and the pair is one rigid body of inertia ``I1 + I2 + mu |r1 - r2|^2 (E - e3 e3^T)``
    (``mu = m1 m2 / (m1 + m2)``) about the system mass centre:
    ``lambda^2 = -rate^2 (Iz - Ix)(Iz - Iy) / (Ix Iy)``. Ball: left are
    ``(w1, w2, q1_rel, q2_rel, w1_2, w2_2)``, the two bodies' tilts, in the two-body
    coordinates (``q_rel`` = the panel's ``p``; ``w_2 = A(p) w + u`` body 2's rate in its
    own axes: a similarity transform of the panel's ``u1, u2``); the closed form
    `ball_tilt_eigenvalues` for axisymmetric bodies. The multiplier model
    `dynamics.hinged_bodies`, reduced by hand, gives the same matrix (tests).

    Parameters
    ----------
    m1, m2 : float [kg]
        ``> 0``.
    inertia1, inertia2 : array_like, shape (3, 3) or (3,) [kg m^2]
        About each mass centre, body axes; z must be principal.
    r1, r2 : array_like, shape (3,) [m]
        Hinge point from each mass centre, on the z axis.
    rate : float [rad/s]
        Common spin rate about z, non-zero.
    kind : {'revolute', 'ball'}, optional
    axis : array_like, optional
        Revolute hinge axis; only ``[0, 0, 1]`` (the spin axis; the default) is supported.

    Returns
    -------
    StabilityReport

    Raises
    ------
    ValueError
        Naming the argument (``m1``, ``inertia2`` with z not principal, ``r1`` off the axis,
        ``rate`` zero, ``kind``, ``axis`` ...).

    Examples
    --------
    >>> from appdyn.problems import stability
    >>> rep = stability.hinged_spin(m1=10.0, inertia1=[2.0, 2.0, 3.0], m2=2.0,
    ...                             inertia2=[0.2, 0.2, 0.3], r1=[0, 0, 0.5],
    ...                             r2=[0, 0, -0.2], rate=5.0)
    >>> rep.verdict, rep.status, rep.ss.state_labels
    ('marginally stable', 0, ['w1', 'w2'])
    """
    m1, I1, m2, I2, r1, r2, W = _hinged_check(m1, inertia1, m2, inertia2, r1, r2, rate, kind,
                                              axis)
    scene = hinged_scene(m1, I1, m2, I2, r1, r2, kind)
    sl = spin_linearization(scene, np.array([0.0, 0.0, 1.0]), W)
    lin = sl.lin
    axial = "theta_dot" if kind == "revolute" else "u3"
    red = sl.reduced.restrict(axial, reason="body 2's axial rate w3_2 = w3 + "
                              f"{axial}: the hinge exerts no torque about z (a first integral "
                              "to first order)")
    if kind == "ball":
        red = _two_body_coordinates(scene, sl.point.x, red)
    mu = m1 * m2 / (m1 + m2)
    dist = float(np.linalg.norm(r1 - r2))
    comp = I1 + I2 + mu * dist ** 2 * np.diag([1.0, 1.0, 0.0])
    Ia, Ib, Ic = principal_moments(comp, np.array([0.0, 0.0, 1.0]))
    lam2 = rigid_spin_lambda2(Ia, Ib, Ic, W)
    quantities = [Quantity("combined axial moment Iz", None, Ia, "kg m^2", "I1z + I2z"),
                  Quantity("combined transverse moment Ix", None, Ib, "kg m^2",
                           "I1x + I2x + mu |r1 - r2|^2 (principal)"),
                  Quantity("combined transverse moment Iy", None, Ic, "kg m^2",
                           "I1y + I2y + mu |r1 - r2|^2 (principal)")]
    cf = None
    if kind == "revolute":
        root = np.sqrt(complex(lam2))
        cf = np.array([root, -root])
        quantities.append(Quantity("lambda^2 = -rate^2 (Iz - Ix)(Iz - Iy) / (Ix Iy)", None,
                                   lam2, "1/s^2", "rigid pair (Eqs. 4.94-4.95)"))
        if lam2 < 0:
            computed = float(max(abs(z.imag) for z in red.eigenvalues()))
            quantities.append(Quantity("nutation frequency (body rates)", computed,
                                       math.sqrt(-lam2), "rad/s",
                                       "rate (Iz - It) / It for Ix = Iy = It"))
    axisym = all(abs(I[0, 0] - I[1, 1]) <= 1e-12 * I[0, 0] and abs(I[0, 1]) <= 1e-12 * I[0, 0]
                 for I in (I1, I2))
    if kind == "ball" and axisym:
        cf = ball_tilt_eigenvalues(m1, I1[0, 0], I1[2, 2], m2, I2[0, 0], I2[2, 2],
                                   float(r1[2]), float(-r2[2]), W)
    notes = [f"{kind} hinge; combined moments about the system mass centre Iz = {Ia:.10g}, "
             f"Ix = {Ib:.10g}, Iy = {Ic:.10g} kg m^2 (spin about the "
             f"{axis_kind(Ia, Ib, Ic)} axis of the locked pair)",
             "the scene in minimal coordinates (body 1 the hub, body 2 a HingedPanel: "
             "hinged_scene); the system mass centre is held at rest (linear momentum P = 0: "
             "attitude_subsystem removes r, v exactly)",
             "body rates only: the attitude (the error angles dth1..dth3; dth3 the spin "
             "phase) does not enter; the inertial angular momentum |H| is conserved",
             "the hinge angle (theta, or the twist q3_rel of the relative quaternion q_rel = "
             "p; q4_rel its norm) is cyclic: a family of relative equilibria",
             f"unreduced spectrum ({lin.n} states): "
             + spectrum_text(lin.eigenvalues()),
             *red.notes, *sl.notes]
    title = (f"Hinged pair ({kind} hinge) spinning about the common axis z at "
             f"{W:.6g} rad/s")
    params = dict(m1=m1, inertia1=I1, m2=m2, inertia2=I2, r1=r1, r2=r2, rate=W, kind=kind,
                  axis=None if axis is None else [0.0, 0.0, 1.0])
    groups = {"nutation (body 1 tilt rates)": ["w1", "w2"],
              "relative tilt (body 2)": [s for s in red.states if s not in ("w1", "w2")]}
    return build_report("hinged_spin", title, params, red.ss, lin=lin, closed_form=cf,
                        groups={k: v for k, v in groups.items() if v},
                        quantities=quantities, notes=notes)
