"""Test-only reference: `problems.stability.hinged_spin` as it was before it went through
the scene, copied verbatim (the two-body multiplier model `dynamics.hinged_bodies`, reduced by
hand). It stays as the independent formulation the scene-based `hinged_spin` is checked
against (tests/problems/test_stability_hinged.py). Do not edit.

`hinged_spin`: stability of two hinged bodies spinning together about a common axis
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
from appdyn.dynamics.linearize import linearization
from appdyn.dynamics.model import Model

from appdyn.problems.stability.closed_forms import axis_kind, principal_moments, rigid_spin_lambda2
from appdyn.problems.stability.common import block, check_number
from appdyn.problems.stability.report import Quantity, StabilityReport, build_report

__all__ = ["hinged_spin", "ball_tilt_eigenvalues"]

_HINGED_STATES = ("q1", "q2", "q3", "q4", "w1", "w2", "w3", "q1_rel", "q2_rel", "q3_rel",
                  "q4_rel", "w1_2", "w2_2", "w3_2")
_Y = {"q1": block(_HINGED_STATES, "q1", "q4"), "w1": block(_HINGED_STATES, "w1", "w3"),
      "q_rel": block(_HINGED_STATES, "q1_rel", "q4_rel"),
      "w2": block(_HINGED_STATES, "w1_2", "w3_2")}  # the blocks of the relative states


@cache.memoize
def _hinged_relative(m1, inertia1, m2, inertia2, r1, r2, kind):
    """``(model, assemble, full)``: the hinged pair with the system mass centre at rest at the
    origin, in the states ``(q1, w1, q_rel, w2)`` (``q2 = q_rel (x) q1``, ``w2`` body-2
    axes), ``assemble(y)`` the full 26-state ``x`` and ``full`` the `hinged_bodies` model
    (no Baumgarte term: the constraints are then exact first integrals)."""
    from appdyn.dynamics.attitude import dcm_from_quat, quat_conj, quat_mul
    from appdyn.dynamics.hinged import hinged_bodies

    axis = [0.0, 0.0, 1.0] if kind == "revolute" else None
    full = hinged_bodies(m1, np.reshape(inertia1, (3, 3)), m2, np.reshape(inertia2, (3, 3)),
                         list(r1), list(r2), kind=kind, axis=axis, stabilization=None)
    y, u, p = ca.SX.sym("y", len(_HINGED_STATES)), ca.SX.sym("u", 0), ca.SX.sym("p", 0)
    q1, w1, qr, w2 = (y[_Y[k]] for k in ("q1", "w1", "q_rel", "w2"))
    q2 = quat_mul(qr, q1)
    A1, A2 = dcm_from_quat(q1), dcm_from_quat(q2)
    M = m1 + m2
    d = ca.mtimes(A1.T, ca.DM(r1)) - ca.mtimes(A2.T, ca.DM(r2))          # C2 - C1, inertial
    dd = (ca.mtimes(A1.T, ca.cross(w1, ca.DM(r1)))
          - ca.mtimes(A2.T, ca.cross(w2, ca.DM(r2))))                      # its rate
    x = ca.vertcat(q1, w1, ca.mtimes(A1, -m2 / M * dd), -m2 / M * d,
                   q2, w2, ca.mtimes(A2, m1 / M * dd), m1 / M * d)
    xdot = full.f(x, u, p)
    names = full.states
    q1dot, q2dot = xdot[block(names, "q1", "q4")], xdot[block(names, "q1_2", "q4_2")]
    qrdot = quat_mul(q2dot, quat_conj(q1)) + quat_mul(q2, quat_conj(q1dot))
    f = ca.Function("hinged_spin", [y, u, p],
                    [ca.vertcat(q1dot, xdot[block(names, "w1", "w3")], qrdot,
                                xdot[block(names, "w1_2", "w3_2")])], ["x", "u", "p"],
                    ["xdot"])
    units = {**dict.fromkeys(_HINGED_STATES[_Y["q1"]] + _HINGED_STATES[_Y["q_rel"]], "-"),
             **dict.fromkeys(("w1", "w2", "w3", "w1_2", "w2_2", "w3_2"), "rad/s")}
    model = Model(f, _HINGED_STATES, (), (), units=units, name=f"hinged_spin_{kind}",
                  attitude=(0, 4))
    return model, ca.Function("assemble", [y], [x]), full


def _error_functions(assemble, full, kind):
    """``(xr) -> conserved / constraint functions`` in the linearization's 13 coordinates
    (``dth`` for body 1's attitude about the reference ``q_ref = [0, 0, 0, 1]``)."""
    from appdyn.dynamics.attitude import quat_mul

    xr = ca.SX.sym("xr", 13)
    dth = xr[0:3]
    q1 = quat_mul(ca.vertcat(dth / 2, ca.sqrt(1 - ca.sumsqr(dth) / 4)), ca.DM([0, 0, 0, 1]))
    y = ca.vertcat(q1, xr[3:])
    x = assemble(y)
    H = full.invariants["momentum_angular"](x, ca.DM.zeros(0))
    rows = [ca.sumsqr(y[_Y["q_rel"]])]
    if kind == "revolute":
        phi, _, bnu = full.constraints(x, ca.DM.zeros(0))
        rows += [bnu[3], bnu[4], phi[3], phi[4]]
    rows += [H[0], H[1]]
    return (ca.Function("rows", [xr], [ca.jacobian(ca.vertcat(*rows), xr)]),
            ca.Function("hz", [xr], [ca.jacobian(H[2], xr)]))


def _restrict_subspace(lin, L, eliminate, reason):
    """Restrict ``lin`` to the invariant subspace ``ker L`` (``L A = R L``: first integrals,
    constraints whose rates are those first integrals, or quantities that rotate among
    themselves), the states ``eliminate`` being solved from ``L x = 0``."""
    from dataclasses import replace

    L = np.atleast_2d(np.asarray(L, dtype=float))
    k = [lin.index(s) for s in eliminate]
    r = [i for i in range(lin.n) if i not in k]
    Lk = L[:, k]
    if np.linalg.cond(Lk) > 1e10:
        raise ValueError(f"cannot solve the conserved quantities for {list(eliminate)} "
                         f"(condition {np.linalg.cond(Lk):.3e})")
    P = -np.linalg.solve(Lk, L[:, r])                 # x[k] = P x[r]
    E = np.zeros((lin.n, len(r)))
    E[r, range(len(r))] = 1.0
    E[k, :] = P
    AE = lin.A @ E
    err = np.max(np.abs(L @ AE))                       # A (ker L) in ker L
    scale = max(float(np.max(np.abs(lin.A))), 1e-300)
    if err > 1e-9 * scale * max(1.0, np.max(np.abs(L))) * max(1.0, np.max(np.abs(E))):
        raise ValueError(f"ker L is not invariant under A: max |L A E| = {err:.3e}")
    n = len(r)
    states = tuple(lin.states[i] for i in r)
    note = (f"restricted to the invariant subspace of {len(k)} conserved / constraint "
            f"quantities, {list(eliminate)} eliminated ({reason})")
    return replace(lin, A=AE[r], B=lin.B[r], C=np.eye(n), D=np.zeros((n, len(lin.inputs))),
                   states=states, residual=lin.residual[r],
                   units={s: lin.units.get(s, "") for s in states},
                   notes=lin.notes + (note,)), E


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


def hinged_spin(*, m1, inertia1, m2, inertia2, r1, r2, rate, kind="revolute",
                axis=None) -> StabilityReport:
    """Stability of two hinged bodies (`dynamics.hinged.hinged_bodies`) spinning together at
    ``rate`` about the common z axis, reduced to the independent coordinates.

    The bodies' frames are parallel, their mass centres and the hinge lie on the body z axis
    (``r1 = (0, 0, l1)``, ``r2 = (0, 0, -l2)``: body 2 stacked above body 1), z is principal
    for both, and the system mass centre is at rest: the pair spins about z as if rigid, a
    relative equilibrium.

    Reduction
    ---------
    The pair is written in ``(q1, w1, q_rel, w2)`` (``q2 = q_rel (x) q1``, ``w2`` body-2
    axes) with ``v1, v2, R1, R2`` taken from the ball constraint and the system mass centre
    at rest (its translation removed exactly; the hinge constraints run without Baumgarte
    term, so they are exact first integrals), and linearized in the frame spinning at
    ``rate`` (`~dynamics.linearize.linearization`; body 1's quaternion becomes ``dth``). Then:
    ``ker L`` is kept, ``L`` the gradients of ``|q_rel|^2`` (quaternion norm), for the
    revolute hinge the two constraint rates ``B_r nu`` and positions ``phi_r`` (tilt of
    ``q_rel`` and transverse ``w2`` eliminated), and the inertial transverse angular
    momentum ``H_x, H_y`` (the direction of ``H``: its ``+-i rate`` mode, ``dth1, dth2``
    eliminated); restricted to ``w3_2`` (body 2's axial rate: no hinge torque along z) and
    the axial momentum ``H_z`` (``w3`` eliminated); quotient by the spin phase ``dth3`` and
    the twist of body 2 about z ``q3_rel`` (the hinge angle). Revolute: left is ``(w1, w2)``,
    body 1's transverse rates, and the pair is one rigid body of inertia
    ``I1 + I2 + mu |r1 - r2|^2 (E - e3 e3^T)`` (``mu = m1 m2 / (m1 + m2)``) about the system
    mass centre: ``lambda^2 = -rate^2 (Iz - Ix)(Iz - Iy) / (Ix Iy)``. Ball: left are
    ``(w1, w2, q1_rel, q2_rel, w1_2, w2_2)``, the two bodies' tilts; no closed form is
    attached.

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
    key = (m1, tuple(I1.ravel().tolist()), m2, tuple(I2.ravel().tolist()),
           tuple(r1.tolist()), tuple(r2.tolist()), kind)
    model, assemble, full = _hinged_relative(*key)
    y0 = np.zeros(len(_HINGED_STATES))
    for name, value in (("q4", 1.0), ("w3", W), ("q4_rel", 1.0), ("w3_2", W)):
        y0[_HINGED_STATES.index(name)] = value
    lin = linearization(model, y0)
    g_rows, g_hz = _error_functions(assemble, full, kind)
    xr0 = np.r_[np.zeros(3), y0[_Y["q1"].stop:]]  # dth replaces body 1's quaternion
    L = np.asarray(g_rows(xr0), dtype=float)
    c_hz = np.asarray(g_hz(xr0), dtype=float).ravel()
    elim = ["q4_rel"] + (["w1_2", "w2_2", "q1_rel", "q2_rel"] if kind == "revolute" else [])
    elim += ["dth1", "dth2"]
    red, E = _restrict_subspace(
        lin, L, elim, "quaternion norm of q_rel" + (", revolute constraint rates and positions"
                                                     if kind == "revolute" else "")
        + ", direction of the inertial angular momentum (its +-i rate mode)")
    red = red.restrict("w3_2", reason="body 2's axial rate: the hinge exerts no torque about "
                       "z (a first integral to first order)")
    kept = [s for s in lin.states if s not in elim]   # the columns of E
    c = c_hz @ E                                       # H_z on ker L; w3_2's level set: c[r]
    c = np.array([c[kept.index(s)] for s in red.states])
    red = red.restrict(c, eliminate="w3", reason="axial angular momentum H_z is conserved; "
                       "the neighbouring spins' eigenvalue 0 goes")
    red = red.quotient("dth3", reason="the spin phase about z is cyclic")
    red = red.quotient("q3_rel", reason="the twist of body 2 about z (the hinge angle) is "
                       "cyclic: a family of relative equilibria")
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
             "the system mass centre is held at rest and v1, v2, R1, R2 are taken from the "
             "ball constraint (its translation and the 3 + 3 translational directions are "
             "removed exactly); hinge constraints without Baumgarte term",
             f"unreduced spectrum ({lin.n} states): "
             + ", ".join(f"{z.real:+.3e}{z.imag:+.6e}j" for z in lin.eigenvalues()),
             *red.notes]
    title = (f"Hinged pair ({kind} hinge) spinning about the common axis z at "
             f"{W:.6g} rad/s")
    params = dict(m1=m1, inertia1=I1, m2=m2, inertia2=I2, r1=r1, r2=r2, rate=W, kind=kind,
                  axis=None if axis is None else [0.0, 0.0, 1.0])
    groups = {"nutation (body 1 tilt rates)": ["w1", "w2"],
              "relative tilt (body 2)": [s for s in red.states if s not in ("w1", "w2")]}
    return build_report("hinged_spin", title, params, red.ss, lin=lin, closed_form=cf,
                        groups={k: v for k, v in groups.items() if v},
                        quantities=quantities, notes=notes)
