"""Two rigid bodies joined by a frictionless hinge in free space (Rheinfurth & Wilson, NASA
RP-1262, Ch. 6 Example 5), in Boltzmann-Hamel form (Eqs. 6.19-6.20) with Lagrange
multipliers (Sec. 5.5; `dynamics.constrained`).

Derivation
----------
Body ``i`` (1, 2): mass ``m_i``, inertia ``I_i`` about its mass centre ``C_i`` in its own
axes, attitude ``q_i`` (``A_i = A(q_i)``: inertial -> body ``i``), body rates ``w_i``,
mass-centre velocity ``v_i`` in body-``i`` axes, mass-centre position ``R_i`` in inertial
axes. With ``T = sum_i 1/2 m_i v_i.v_i + 1/2 w_i.I_i w_i`` the partials are
``dT/dv_i = m_i v_i`` and ``dT/dw_i = I_i w_i``; Eqs. 6.19-6.20 (``v x dT/dv = 0``) give
Eqs. 6.54-6.57, for ``nu = (v1, w1, v2, w2)`` (the seed's order)::

    M nu' = Q + Q_R,     M = diag(m1 E, I1, m2 E, I2),
    Q = (-m1 w1 x v1, -w1 x I1 w1, -m2 w2 x v2, -w2 x I2 w2)

with the kinematics ``q_i' = -1/2 Wbar(w_i) q_i`` (Eq. 4.70) and ``R_i' = A_i^T v_i``.

The hinge point ``O`` is ``r_i`` from ``C_i`` (body-``i`` axes). A **ball** hinge is three
constraints (inertial axes, metres)::

    phi_b = (R1 + A1^T r1) - (R2 + A2^T r2) = 0.

As ``A' = -[w x] A``, ``(A^T)' = A^T [w x]`` and::

    phi_b' = A1^T (v1 + w1 x r1) - A2^T (v2 + w2 x r2) = B_b nu,
    B_b = [A1^T, -A1^T [r1 x], -A2^T, A2^T [r2 x]],
    c_b = A1^T (w1 x (v1 + w1 x r1)) - A2^T (w2 x (v2 + w2 x r2)).

The reaction ``-B^T lam`` is ``A2 lam`` on body 2 and ``-A1 lam`` on body 1, with moments
``r_i x F_i``: ``lam`` is the force body 1 exerts on body 2 at ``O`` (inertial axes).
Seed check: in body-2 axes, Eq. 6.58 with ``l1 = r1``, ``l2 = -r2`` and ``A = A2 A1^T``
reads ``B = [-A | A [l1 x] | E | [l2 x]]``; the OCR's ``-A l1^`` has the wrong sign.

A **revolute** hinge about the unit ``axis`` ``a`` (body-1 axes; body 2's hinge axis has the
same components in body-2 axes: the frames are parallel at zero hinge angle) adds::

    phi_r = [n1.g, n2.g] = 0,     g = A1 A2^T a,

``(n1, n2, a)`` a right-handed orthonormal triad fixed in body 1. With ``Ct = A1 A2^T``
(body 2 -> body 1 axes) and ``m_k = Ct^T n_k``::

    (n_k.g)' = -(g x n_k).w1 + (a x m_k).w2,
    c_k = (a x m_k').w2 - (g' x n_k).w1,
    g' = Ct (w2 x a) - w1 x g,   m_k' = Ct^T (w1 x n_k) - w2 x m_k,

exact also for quaternions off unit norm (``A' = -[w x] A`` holds for ``A(q)`` scaled by
``|q|^2``). For a rotation ``Ct``, ``(n_k.g)' = (g x n_k).w_rel`` with the relative rate
``w_rel = Ct w2 - w1``, which on the hinge is ``[w_rel.n2, -w_rel.n1]``: the relative rotation
is about ``a`` only, and the constraint couple (``-B^T lam`` of these rows) has no component
along ``a`` (frictionless).

`hinge_terms` writes ``phi``, ``B`` and ``c`` out as above (the tests compare them with
`dynamics.constrained.constraint_terms`, which differentiates ``phi``: four times the
instructions); `dynamics.constrained.constrained_accelerations` gives ``nu'`` and ``lam``
(Eq. 5.66) and `dynamics.constrained.baumgarte` the drift control.

Degrees of freedom: 12 velocities less 3 (ball: 9 DOF, as in the seed) or 5 (revolute: 7).
The seed integrates 9 and takes ``v2`` from the constraint; here both bodies are integrated
in full and the constraints are held by Baumgarte stabilization (time constant
``stabilization``) or `HingedBodies.project`. Only body 1's quaternion fits
``Model.attitude``; nothing is renormalized implicitly: body 2's quaternion norm is the
invariant ``quat_norm_2`` (both drift at the integrator's error level; ``'lie'`` integrates
body 2's quaternion by RK4, so prefer ``'rk8'``/``'auto'``), and `HingedBodies.project`
renormalizes both on request.
"""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from . import cache
from .attitude import dcm_from_quat, propagate_quat, quat_from_axis_angle, quat_mul, quat_rate, skew
from .constrained import (DEFAULT_TIME_CONSTANT, ConstraintTerms, Projection, baumgarte,
                          constrained_accelerations, project_positions, project_velocities,
                          residual_invariant)
from .model import Model
from .rigid_body import RIGID_BODY_STATES
from .validate import (check_inertia, finite_array, one_of, positive, unit_axes, unit_quaternion,
                       unit_vector)

__all__ = ["ASSEMBLY_TOL", "HINGED_STATES", "Hinge", "HingedBodies", "hinge_terms", "hinged_bodies",
           "hinged_scene", "two_body_state"]

_BODY = RIGID_BODY_STATES + ("v1", "v2", "v3", "x", "y", "z")
#: State names: body 1, then body 2 (suffix ``_2``); see `hinged_bodies`.
HINGED_STATES = _BODY + tuple(f"{s}_2" for s in _BODY)
_UNITS = {**dict.fromkeys(RIGID_BODY_STATES[:4], "-"),
          **dict.fromkeys(RIGID_BODY_STATES[4:], "rad/s"),
          **dict.fromkeys(("v1", "v2", "v3"), "m/s"), **dict.fromkeys("xyz", "m")}
_NU = np.r_[7:10, 4:7, 20:23, 17:20]  # nu = (v1, w1, v2, w2) inside x

#: How far a revolute ``q2`` / ``w2`` given to `HingedBodies.initial_state` may miss the hinge
#: (angle [rad]; relative-rate fraction) before it is refused rather than projected.
ASSEMBLY_TOL = 1e-9


@dataclass(frozen=True)
class Hinge:
    """The defining (checked) arguments of `hinged_bodies`, as hashable tuples."""

    m1: float
    I1: tuple
    m2: float
    I2: tuple
    r1: tuple
    r2: tuple
    kind: str
    axis: tuple | None
    stabilization: float | None

    def mass_matrix(self) -> np.ndarray:
        """``M = diag(m1 E, I1, m2 E, I2)``, shape (12, 12), for ``nu = (v1, w1, v2, w2)``."""
        from scipy import linalg  # a heavy import, only here

        return linalg.block_diag(self.m1 * np.eye(3), np.reshape(self.I1, (3, 3)),
                                 self.m2 * np.eye(3), np.reshape(self.I2, (3, 3)))

    def normals(self) -> tuple[np.ndarray, np.ndarray]:
        """``n1, n2`` completing the right-handed triad ``(n1, n2, axis)``."""
        a = np.array(self.axis)
        n1 = np.cross(np.eye(3)[int(np.argmin(np.abs(a)))], a)
        n1 /= np.linalg.norm(n1)
        return n1, np.cross(a, n1)


@dataclass(frozen=True)
class HingedBodies(Model):
    """A `Model` of two hinged bodies, with the hinge and its assembly helpers.

    Attributes
    ----------
    hinge : Hinge
        The defining arguments.
    constraints : casadi.Function
        ``(x, p) -> (phi, B, residual)``: position residual ``phi`` (3 or 5), the constraint
        matrix ``B`` (m x 12, for ``nu = (v1, w1, v2, w2)``) and ``B nu``.
    """

    hinge: Hinge | None = None
    constraints: ca.Function | None = None

    def __reduce__(self):
        return (_rebuild, (self.hinge,))

    def initial_state(self, q1, w1, v1, q2, w2, *, position=None) -> np.ndarray:
        """A state on the hinge: body 2's position and velocity completed from the hinge.

        Parameters
        ----------
        q1, q2 : array_like, shape (4,)
            Unit quaternions of the bodies. Revolute: ``q2`` must be body 1's attitude turned
            about ``axis``, ``quat_mul(quat_from_axis_angle(axis, angle), q1)`` (to
            `ASSEMBLY_TOL`; then made exact).
        w1, w2 : array_like, shape (3,) [rad/s]
            Body rates. Revolute: the relative rate must be along ``axis`` (to `ASSEMBLY_TOL`
            of the rates; then projected onto it).
        v1 : array_like, shape (3,) [m/s]
            Body 1's mass-centre velocity in body-1 axes.
        position : array_like, shape (3,) [m], optional
            Body 1's mass centre, inertial axes (origin).

        Returns
        -------
        numpy.ndarray, shape (26,)
            ``x`` with ``R2 = R1 + A1^T r1 - A2^T r2`` and
            ``v2 = A2 A1^T (v1 + w1 x r1) - w2 x r2``.

        Raises
        ------
        ValueError
            Naming the argument: not finite, wrong shape, a quaternion not of unit norm;
            revolute ``q2`` off the hinge axis or ``w2`` with a relative rate across it.

        Examples
        --------
        >>> import numpy as np
        >>> from appdyn.dynamics import hinged_bodies
        >>> from appdyn.dynamics.attitude import dcm_from_quat, quat_from_axis_angle, quat_mul
        >>> axis = np.array([0.0, 0.0, 1.0])
        >>> model = hinged_bodies(10.0, [1, 2, 2.5], 2.0, [0.2, 0.2, 0.3], [0, 0, 0.5],
        ...                       [0, 0, -0.2], kind="revolute", axis=axis)
        >>> q1, w1 = [0.0, 0.0, 0.0, 1.0], np.array([0.1, 0.0, 0.2])
        >>> q2 = quat_mul(quat_from_axis_angle(axis, 0.3), q1)  # hinge angle 0.3 rad
        >>> C = dcm_from_quat(q2) @ dcm_from_quat(q1).T  # body 1 -> body 2 axes
        >>> x0 = model.initial_state(q1, w1, [1.0, 0, 0], q2, C @ (w1 + 0.5 * axis))
        >>> np.round(x0[23:26], 12)  # body 2's mass centre: 0.5 + 0.2 above body 1's
        array([0. , 0. , 0.7])
        >>> model.initial_state(q1, w1, [1.0, 0, 0], q2, [0.0, 0.0, 0.7])
        Traceback (most recent call last):
            ...
        ValueError: `w2` turns body 2 across the revolute hinge: ...
        """
        h = self.hinge
        q1, q2 = unit_quaternion(q1, "q1"), unit_quaternion(q2, "q2")
        w1, v1, w2 = (finite_array(a, n, (3,)) for a, n in ((w1, "w1"), (v1, "v1"), (w2, "w2")))
        R1 = np.zeros(3) if position is None else finite_array(position, "position", (3,))
        A1, A2 = dcm_from_quat(q1), dcm_from_quat(q2)
        r1, r2 = np.array(h.r1), np.array(h.r2)
        if h.kind == "revolute":
            q2, A2, w2 = _assemble_revolute(h, q1, A1, A2, q2, w1, w2)
        R2 = R1 + A1.T @ r1 - A2.T @ r2
        v2 = A2 @ A1.T @ (v1 + np.cross(w1, r1)) - np.cross(w2, r2)
        return np.r_[q1, w1, v1, R1, q2, w2, v2, R2]

    def project(self, x, *, tol: float = 1e-12, max_iter: int = 20) -> Projection:
        """Project a state onto the hinge (between steps or after a run).

        Renormalizes both quaternions, then moves positions and attitudes by the smallest
        mass-weighted displacement that closes the hinge (Newton steps,
        `dynamics.constrained.project_positions` with ``weight = M``: the system mass centre
        stays put), then removes the velocity residual by the ``M``-nearest velocity
        (`dynamics.constrained.project_velocities`: an internal impulse, so linear and
        angular momentum are kept).

        Parameters
        ----------
        x : array_like, shape (26,)
        tol : float, optional
            Accepted ``|[phi, B nu]|`` at the end [m, m/s, rad, rad/s].
        max_iter : int, optional
            Newton steps at most.

        Returns
        -------
        Projection
            ``x`` (projected), ``residual`` (``|[phi, B nu]|``), ``iterations``, ``success``.

        Examples
        --------
        >>> import numpy as np
        >>> from appdyn.dynamics import hinged_bodies
        >>> model = hinged_bodies(3.0, [1, 1, 1], 1.0, [0.1, 0.1, 0.1], [0.5, 0, 0], [-0.2, 0, 0])
        >>> x = model.initial_state([0, 0, 0, 1], [0, 0, 1.0], [0, 0, 0], [0, 0, 0, 1], [0, 0, 1.0])
        >>> x[23] += 1e-3  # open the hinge by a millimetre
        >>> res = model.project(x)
        >>> res.success, bool(res.residual < 1e-12)
        (True, True)
        """
        h = self.hinge
        x = np.array(finite_array(x, "x", (self.nx,)), dtype=float)
        for o in (0, 13):
            x[o:o + 4] = unit_vector(x[o:o + 4], f"x[{o}:{o + 4}]", size=4)  # explicit
        parts = lambda x: [np.asarray(a) for a in self.constraints(x, [])]  # noqa: E731
        M = h.mass_matrix()
        pos = project_positions(lambda x: parts(x)[0].ravel(), lambda x: parts(x)[1], x,
                                retract=_retract, weight=M, tol=tol, max_iter=max_iter)
        x = pos.x
        x[_NU] = project_velocities(M, parts(x)[1], x[_NU])
        phi, _, r = parts(x)
        err = float(np.linalg.norm(np.r_[phi.ravel(), r.ravel()]))
        return Projection(x, err, pos.iterations, err <= tol)


def _retract(x, d):
    """Displace ``x`` by ``d = (t1, th1, t2, th2)``: translations and rotations in body axes."""
    x = x.copy()
    for i, o in enumerate((0, 13)):
        x[o + 10:o + 13] += dcm_from_quat(x[o:o + 4]).T @ d[6 * i:6 * i + 3]
        x[o:o + 4] = propagate_quat(x[o:o + 4], d[6 * i + 3:6 * i + 6], 1.0)
    return x


def _assemble_revolute(h: Hinge, q1, A1, A2, q2, w1, w2):
    """``q2`` made exactly a turn of ``q1`` about the axis and ``w2`` projected (or ValueError)."""
    a = np.array(h.axis)
    n1, n2 = h.normals()
    C = A2 @ A1.T
    off = np.linalg.norm(C.T @ a - a)
    if off > ASSEMBLY_TOL:
        raise ValueError(f"`q2` is off the revolute hinge: body 2's axis seen in body 1 is "
                         f"{(C.T @ a).tolist()}, not `axis` {a.tolist()} (off by {off:.3g}); use "
                         f"q2 = quat_mul(quat_from_axis_angle(axis, angle), q1)")
    angle = np.arctan2(-(n2 @ C @ n1), n1 @ C @ n1)  # C = E cos + (1 - cos) a a^T - sin [a x]
    exact = quat_mul(quat_from_axis_angle(a, angle), q1)
    q2 = exact if exact @ q2 >= 0 else -exact
    A2 = dcm_from_quat(q2)
    C = A2 @ A1.T
    w_rel = C.T @ w2 - w1
    across = np.linalg.norm(w_rel - (a @ w_rel) * a)
    if across > ASSEMBLY_TOL * max(1.0, np.linalg.norm(w1), np.linalg.norm(w2)):
        raise ValueError(f"`w2` turns body 2 across the revolute hinge: the relative rate "
                         f"{w_rel.tolist()} rad/s (body-1 axes) has {across:.3g} rad/s off "
                         f"`axis` {a.tolist()}; use w2 = A2 A1^T (w1 + rate * axis)")
    return q2, A2, C @ (w1 + (a @ w_rel) * a)


def hinge_terms(h: Hinge, q1, w1, v1, R1, q2, w2, v2, R2):
    """``phi``, ``B`` (for ``nu = (v1, w1, v2, w2)``) and ``c`` of the hinge (module docstring).

    Written out by hand (a quarter of the instructions of differentiating ``phi`` with
    `dynamics.constrained.constraint_terms`, which the tests compare it with), exact at any
    quaternion norm.

    Parameters
    ----------
    h : Hinge
    q1, w1, v1, R1, q2, w2, v2, R2 : casadi SX/MX columns
        Quaternions (4), body rates (3) [rad/s], mass-centre velocities in body axes (3)
        [m/s], mass-centre positions in inertial axes (3) [m].

    Returns
    -------
    phi : (m,) position residual [m, -]
    B : (m, 12)
    c : (m,) ``B nu' + c = 0`` on the hinge [m/s^2, rad/s^2]
    """
    A1, A2 = dcm_from_quat(q1), dcm_from_quat(q2)
    r1, r2 = ca.DM(h.r1), ca.DM(h.r2)
    s1, s2 = (ca.DM(skew(np.array(r))) for r in (h.r1, h.r2))
    phi = R1 + ca.mtimes(A1.T, r1) - R2 - ca.mtimes(A2.T, r2)
    B = ca.horzcat(A1.T, -ca.mtimes(A1.T, s1), -A2.T, ca.mtimes(A2.T, s2))
    c = (ca.mtimes(A1.T, ca.cross(w1, v1 + ca.cross(w1, r1)))
         - ca.mtimes(A2.T, ca.cross(w2, v2 + ca.cross(w2, r2))))
    if h.kind == "revolute":
        a = ca.DM(h.axis)
        Ct = ca.mtimes(A1, A2.T)  # body 2 -> body 1 axes
        g = ca.mtimes(Ct, a)
        gdot = ca.mtimes(Ct, ca.cross(w2, a)) - ca.cross(w1, g)
        rows, cs, zero = [], [], ca.DM.zeros(1, 3)
        for n in (ca.DM(n) for n in h.normals()):
            m = ca.mtimes(Ct.T, n)
            mdot = ca.mtimes(Ct.T, ca.cross(w1, n)) - ca.cross(w2, m)
            rows.append(ca.horzcat(zero, -ca.cross(g, n).T, zero, ca.cross(a, m).T))
            cs.append(ca.dot(ca.cross(a, mdot), w2) - ca.dot(ca.cross(gdot, n), w1))
        phi = ca.vertcat(phi, *(ca.dot(ca.DM(n), g) for n in h.normals()))
        B, c = ca.vertcat(B, *rows), ca.vertcat(c, *cs)
    return phi, B, c


@cache.memoize
def _hinged(h: Hinge) -> HingedBodies:
    body = [[ca.SX.sym(f"{n}_{i}", k) for n, k in (("q", 4), ("w", 3), ("v", 3), ("R", 3))]
            for i in (1, 2)]
    (q1, w1, v1, R1), (q2, w2, v2, R2) = body
    x, u, p = ca.vertcat(*body[0], *body[1]), ca.SX.sym("u", 0), ca.SX.sym("p", 0)
    A1, A2 = dcm_from_quat(q1), dcm_from_quat(q2)
    I1, I2 = (ca.DM(np.reshape(I, (3, 3))) for I in (h.I1, h.I2))
    phi, B, c = hinge_terms(h, q1, w1, v1, R1, q2, w2, v2, R2)
    nu = ca.vertcat(v1, w1, v2, w2)
    terms = ConstraintTerms(phi, ca.mtimes(B, nu), B, ca.DM.zeros(B.shape[0]), c)
    if h.stabilization is not None:
        c = baumgarte(c, terms.residual, phi, time_constant=h.stabilization)
    rates = ca.vertcat(quat_rate(q1, w1), ca.mtimes(A1.T, v1),
                       quat_rate(q2, w2), ca.mtimes(A2.T, v2))
    Q = ca.vertcat(-h.m1 * ca.cross(w1, v1), -ca.cross(w1, ca.mtimes(I1, w1)),
                   -h.m2 * ca.cross(w2, v2), -ca.cross(w2, ca.mtimes(I2, w2)))
    acc = constrained_accelerations(h.mass_matrix(), Q, terms.B, c)
    d = acc.vdot
    xdot = ca.vertcat(rates[0:4], d[3:6], d[0:3], rates[4:7],
                      rates[7:11], d[9:12], d[6:9], rates[11:14])
    f = ca.Function("hinged_bodies", [x, u, p], [xdot], ["x", "u", "p"], ["xdot"], {"cse": True})

    H1, H2 = ca.mtimes(I1, w1), ca.mtimes(I2, w2)
    P1, P2 = h.m1 * ca.mtimes(A1.T, v1), h.m2 * ca.mtimes(A2.T, v2)  # inertial momenta
    centre = (h.m1 * R1 + h.m2 * R2) / (h.m1 + h.m2)
    F2 = acc.reaction[6:9]  # on body 2, body-2 axes
    exprs = {
        "energy": 0.5 * (h.m1 * ca.sumsqr(v1) + ca.dot(w1, H1)
                         + h.m2 * ca.sumsqr(v2) + ca.dot(w2, H2)),
        "momentum_linear": P1 + P2,
        "momentum_angular": (ca.mtimes(A1.T, H1) + ca.cross(R1 - centre, P1)
                             + ca.mtimes(A2.T, H2) + ca.cross(R2 - centre, P2)),
        "quat_norm": ca.norm_2(q1),
        "quat_norm_2": ca.norm_2(q2),
        "hinge_force": ca.mtimes(A2.T, F2),
        "hinge_torque": ca.mtimes(A2.T, acc.reaction[9:12] - ca.cross(ca.DM(h.r2), F2)),
    }
    invariants = {k: ca.Function(k, [x, p], [e], ["x", "p"], [k]) for k, e in exprs.items()}
    invariants["constraint_residual"] = residual_invariant(x, p, terms)
    constraints = ca.Function("hinge_constraints", [x, p], [phi, terms.B, terms.residual],
                              ["x", "p"], ["phi", "B", "residual"])
    return HingedBodies(f=f, states=HINGED_STATES, controls=(),
                        units={**_UNITS, **{f"{k}_2": v for k, v in _UNITS.items()}},
                        invariants=invariants, name=f"hinged_bodies_{h.kind}", attitude=(0, 4),
                        hinge=h, constraints=constraints)


def _rebuild(h: Hinge) -> HingedBodies:
    return _hinged(h)


def hinged_bodies(m1, I1, m2, I2, r1, r2, *, kind: str = "ball", axis=None,
                  stabilization: float | None = DEFAULT_TIME_CONSTANT) -> HingedBodies:
    """Two rigid bodies joined by a frictionless ball or revolute hinge in free space.

    Parameters
    ----------
    m1, m2 : float [kg]
        Masses, > 0.
    I1, I2 : array_like, shape (3, 3) or (3,) [kg m^2]
        Inertias about each mass centre in that body's axes (see `dynamics.validate.check_inertia`).
    r1, r2 : array_like, shape (3,) [m]
        The hinge point from each body's mass centre, in that body's axes.
    kind : {'ball', 'revolute'}, optional
        Ball: 3 constraints, 9 DOF. Revolute: 5 constraints, 7 DOF; rotation about ``axis``.
    axis : array_like, shape (3,), optional
        Revolute only: unit hinge axis in body-1 axes; body 2's hinge axis has the same
        components in body-2 axes (frames parallel at zero hinge angle).
    stabilization : float or None, optional
        Baumgarte time constant ``tau`` [s] (`dynamics.constrained.baumgarte`; default
        `dynamics.constrained.DEFAULT_TIME_CONSTANT`, 1 s: a few integration steps or more),
        or ``None`` for none (the constraints then drift with the integration error).

    Returns
    -------
    HingedBodies
        A `Model` (module docstring for the equations) with ``x`` (26) = body 1
        ``[q1..q4, w1..w3, v1..v3, x, y, z]`` then body 2 with the suffix ``_2``
        (``q`` scalar-last, inertial -> body; ``w`` body rates [rad/s]; ``v`` mass-centre
        velocity in body axes [m/s]; ``x, y, z`` mass centre, inertial [m]); no controls, no
        parameters, ``attitude = (0, 4)`` (body 1). Invariants: ``energy`` [J],
        ``momentum_linear`` [N s] and ``momentum_angular`` [N m s] (about the system mass
        centre), both inertial; ``constraint_residual`` ``[|phi|, |B nu|]`` [m or rad, m/s or
        rad/s]; ``quat_norm``, ``quat_norm_2``; and the monitored ``hinge_force`` [N] (body 1
        on body 2 at the hinge) and ``hinge_torque`` [N m] (the constraint couple of body 1 on
        body 2; zero for a ball, normal to the axis for a revolute hinge), inertial axes.
        Methods ``initial_state`` and ``project``; cached by the arguments.

    Raises
    ------
    TypeError
        If an argument does not hold numbers.
    ValueError
        Naming the argument: ``m1``/``m2`` not > 0, bad ``I1``/``I2``, ``r1``/``r2`` not 3
        finite numbers, unknown ``kind``, ``axis`` missing, not of unit length, or given for a
        ball hinge, ``stabilization`` not > 0.

    References
    ----------
    .. [1] Rheinfurth & Wilson, NASA RP-1262, Ch. 6 Example 5 (Eqs. 6.54-6.58), Eqs. 6.19-6.20,
       Sec. 5.5 (Eqs. 5.59-5.67).

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics import hinged_bodies
    >>> model = hinged_bodies(10.0, [1.0, 2.0, 2.5], 2.0, [0.2, 0.3, 0.4],
    ...                       [0.4, 0.0, 0.0], [-0.3, 0.0, 0.0])
    >>> model.nx, model.states[13:17]
    (26, ('q1_2', 'q2_2', 'q3_2', 'q4_2'))
    >>> x0 = model.initial_state([0, 0, 0, 1], [0, 0, 1.0], [0, 0, 0], [0, 0, 0, 1], [0, 0, 1.0])
    >>> x0[20:26]  # body 2 follows: v2 = w x (0.7, 0, 0), position 0.4 + 0.3
    array([0. , 0.7, 0. , 0.7, 0. , 0. ])
    >>> bool(np.all(model.invariant("constraint_residual", x0) < 1e-15))
    True
    >>> model.invariant("hinge_force", x0).round(6)  # centripetal pull on body 2 (mu w^2 d)
    array([-1.166667,  0.      ,  0.      ])
    """
    m1, m2 = positive(m1, "m1"), positive(m2, "m2")
    I1, I2 = check_inertia(I1, name="I1"), check_inertia(I2, name="I2")
    r1, r2 = finite_array(r1, "r1", (3,)), finite_array(r2, "r2", (3,))
    kind = one_of(kind, "kind", ("ball", "revolute"))
    if kind == "revolute":
        if axis is None:
            raise ValueError("`axis` is required for kind='revolute' (unit vector, body-1 axes)")
        axis = tuple(unit_axes(axis, "axis", n=1)[:, 0].tolist())
    elif axis is not None:
        raise ValueError(f"`axis` applies to kind='revolute' only, got axis={axis!r} "
                         f"with kind='ball'")
    if stabilization is not None:
        stabilization = positive(stabilization, "stabilization")
    as_tuple = lambda a: tuple(float(v) for v in np.ravel(a))  # noqa: E731
    return _hinged(Hinge(m1, as_tuple(I1), m2, as_tuple(I2), as_tuple(r1), as_tuple(r2), kind,
                         axis, stabilization))


def hinged_scene(m1, inertia1, m2, inertia2, r1, r2, kind="revolute", axis=None) -> "Scene":
    """The two hinged bodies of `hinged_bodies` as a scene, in minimal coordinates: body 1
    the six-degree-of-freedom hub, body 2 a `dynamics.scene.HingedPanel` (no multipliers,
    no constraint drift; `two_body_state` maps its states to `hinged_bodies`').

    Parameters
    ----------
    m1, m2 : float [kg]
    inertia1, inertia2 : array_like, shape (3, 3) or (3,) [kg m^2]
        About each mass centre, each body's axes (parallel at zero hinge angle).
    r1, r2 : array_like, shape (3,) [m]
        The hinge point from each mass centre (``hinged_bodies``' convention): the panel's
        ``hinge_point`` is ``r1``, its ``cm_offset`` ``-r2``.
    kind : {'revolute', 'ball'}, optional
    axis : array_like, shape (3,), optional
        The revolute hinge axis (body-1 axes; default ``[0, 0, 1]``).

    Returns
    -------
    Scene
        ``Scene(RigidHub(inertia1, mass=m1), HingedPanel(m2, inertia2, r1, -r2, axis=...),
        name=f"hinged_{kind}")``; states ``q, w, r, v`` (body 1's mass centre) then
        ``theta, theta_dot`` (revolute) or ``p1..p4, u1..u3`` (ball).

    Raises
    ------
    TypeError, ValueError
        Naming the argument (``m1``, ``inertia1``, ``r1``, ``axis``, ...).

    Examples
    --------
    >>> from appdyn.dynamics.hinged import hinged_scene
    >>> scene = hinged_scene(10.0, [2.0, 2.0, 3.0], 2.0, [0.2, 0.2, 0.3], [0, 0, 0.5],
    ...                      [0, 0, -0.2])
    >>> scene.model().states[7:]
    ('r1', 'r2', 'r3', 'v1', 'v2', 'v3', 'theta', 'theta_dot')
    """
    from .scene import HingedPanel, RigidHub, Scene

    if kind not in ("revolute", "ball"):
        raise ValueError(f"`kind` must be 'revolute' or 'ball', got {kind!r}")
    if kind == "ball" and axis is not None:
        raise ValueError(f"`axis` applies to kind='revolute' only, got {axis!r}")
    hinge_axis = None if kind == "ball" else ([0.0, 0.0, 1.0] if axis is None else axis)
    m1, m2 = positive(m1, "m1"), positive(m2, "m2")
    inertia1 = check_inertia(inertia1, name="inertia1")
    inertia2 = check_inertia(inertia2, name="inertia2")
    r1, r2 = finite_array(r1, "r1", (3,)), finite_array(r2, "r2", (3,))
    if hinge_axis is not None:
        hinge_axis = unit_axes(hinge_axis, "axis", n=1)[:, 0]
    return Scene(RigidHub(inertia1, mass=m1),
                 HingedPanel(m2, inertia2, hinge_point=r1, cm_offset=-r2, axis=hinge_axis),
                 name=f"hinged_{kind}")

def two_body_state(scene) -> ca.Function:
    """The state of `hinged_bodies` (26) from the state of a `hinged_scene`.

    Body 1 is the hub (``q, w``; ``v`` its mass-centre velocity, hub axes; ``x, y, z = r``);
    body 2 the panel: ``q_2 = p (x) q`` (``p`` the panel's relative quaternion, hub -> panel;
    revolute: `~dynamics.attitude.quat_from_axis_angle` of ``theta`` about the axis),
    ``w_2 = R^T (w + w_rel)`` and ``v_2 = R^T (v + w x rho + w_rel x R c)`` in panel axes,
    position ``r + A(q)^T rho`` (``R`` panel -> hub, ``rho = hinge_point + R c``, ``c`` the
    panel's ``cm_offset``; `dynamics.scene.HingedPanel`).

    Parameters
    ----------
    scene : Scene
        A `hinged_scene` (a hub with ``mass`` at its mass centre and one `HingedPanel`).

    Returns
    -------
    casadi.Function
        ``x (nx of the scene) -> x2 (26)``, in `HINGED_STATES` order; with
        ``hinged_bodies(...).invariants`` it gives the two-body energy, momenta, constraint
        residual and hinge reaction along a scene's run.

    Raises
    ------
    ValueError
        Naming ``scene``, if it is not a hub at its mass centre with one hinged panel.

    Examples
    --------
    >>> import numpy as np
    >>> scene = hinged_scene(10.0, [2.0, 2.0, 3.0], 2.0, [0.2, 0.2, 0.3], [0, 0, 0.5],
    ...                      [0, 0, -0.2])
    >>> x2 = np.asarray(two_body_state(scene)(scene.state(w=[0, 0, 1.0]))).ravel()
    >>> x2[20:23].round(12), x2[23:26]  # body 2 turns about z: v_2 = 0, 0.7 m above body 1
    (array([0., 0., 0.]), array([0. , 0. , 0.7]))
    """
    from types import SimpleNamespace

    from .scene import HingedPanel

    hub, parts = scene.hub, scene.parts
    if (not hub.translates or any(hub.reference) or len(parts) != 1
            or not isinstance(parts[0], HingedPanel)
            or getattr(parts[0], "parent", None) is not None):
        raise ValueError("`scene` must be a hinged_scene: a hub with `mass` (reference at its "
                         f"mass centre) and one HingedPanel, got {scene!r}")
    panel, model = parts[0], scene.model()
    with cache.construction_lock():  # (casadi construction: one thread at a time)
        x = ca.SX.sym("x", model.nx)
        hub_lay, lay = model.layout["hub"], model.layout[scene.part_names[0]]
        names = model.states
        q, w = x[hub_lay.coords], x[hub_lay.speeds]
        r = x[names.index("r1"):names.index("r3") + 1]
        v = x[names.index("v1"):names.index("v3") + 1]
        own = SimpleNamespace(coords=x[lay.coords], speeds=x[lay.speeds])
        R, w_rel = panel.attitude(own)
        p = own.coords if not panel.revolute else quat_from_axis_angle(ca.DM(panel.axis),
                                                                       own.coords[0])
        arm = ca.mtimes(R, ca.DM(panel.cm_offset))
        rho = ca.DM(panel.hinge_point) + arm
        v2 = v + ca.cross(w, rho) + ca.cross(w_rel, arm)
        x2 = ca.vertcat(q, w, v, r, quat_mul(p, q), ca.mtimes(R.T, w + w_rel), ca.mtimes(R.T, v2),
                        r + ca.mtimes(dcm_from_quat(q).T, rho))
        return ca.Function("two_body_state", [x], [x2], ["x"], ["x2"])
