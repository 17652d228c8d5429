"""A flexible cantilever on the hub: `FlexibleAppendage`, by component modes with geometric
stiffening; the seed's spinning satellite with four antennas: `flexible_antenna_satellite`.

Rheinfurth & Wilson, NASA RP-1262 (seed 002), Ch. 6, Eqs. 6.33-6.45 and Example 6; geometric
stiffening after Kane, Ryan & Banerjee, "Dynamics of a cantilever beam attached to a moving
base", J. Guidance 10(2), 1987.

Kinematics. The beam is clamped at ``root`` (from the parent's mass centre) along the unit
``direction`` ``d``; it bends in two planes, along the unit ``normal`` ``n1`` and along
``n2 = d x n1``, with the mass-orthonormal clamped-free shapes ``phi_i`` of
`dynamics.scene.beams.ClampedFreeModes` (the same in both planes: they do not depend on
``EI``) and the modal coordinates ``eta_i`` (along ``n1``) and ``xi_i`` (along ``n2``). The
element at arc length ``x`` sits at::

    p(x) = root + (x - s(x)) d + sum_i phi_i(x) (eta_i n1 + xi_i n2),
    s(x) = 1/2 int_0^x (w1'^2 + w2'^2) = 1/2 sum_ij G_ij(x) (eta_i eta_j + xi_i xi_j),
    G_ij(x) = int_0^x phi_i' phi_j',

the axial foreshortening ``s`` of an inextensible beam, which makes the centrifugal tension
stiffen the beam under spin (with ``stiffening=False`` it is left out: the plain linear modal
model, *for comparison only*: it softens in plane under spin and diverges in a spin-up).

Kane's sum over the continuum. Every ``p(x)`` is ``sum_a c_a(x) P_a`` over the basis
functions ``c = (1, x, phi_i, G_ij (i <= j))`` with vector coefficients ``P_a`` of the state,
and the element's velocity ``sum_a c_a(x) U_a`` (``U_a = w x P_a + P_a'``, plus ``v`` for
``a = 0``). The generalized inertia forces ``int rho (dv/dnu)^T a dx`` are then
``sum_ab C_ab (dU_a/dnu)^T U_b'`` with ``C_ab = int rho c_a c_b dx`` (plus the tip mass),
computed once by Gauss quadrature. ``C`` is split as ``M c c^T`` (the beam's mass centre,
``c = C e_0 / M``: a body of mass ``M`` at the beam's mass centre) plus ``L L^T`` (the
spread about it), and ``L`` is rotated so that its columns sum to zero: each column is a
massless "pseudo-body" of unit momentum factor whose velocity is ``sum_a L_ak U_a``. The
assembly's sums over these bodies are then the exact continuum integrals: the generalized
inertia forces, the kinetic energy, the linear momentum (that of the mass-centre body) and the
angular momentum about the reference (``sum_k P_k x p_k``); the mass-centre body carries the
beam's inertia about its mass centre, so fields see the continuum to second order.

Strain energy (Eq. 6.40): ``1/2 q^T K q`` per plane, ``K_ij = EI int phi_i'' phi_j''``
(``diag(omega_i^2)`` for the exact modes), applied as the load ``-K q`` on the modal rates.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import casadi as ca
import numpy as np

from .. import cache
from ..validate import finite_array, integer, nonnegative, positive, positive_each
from .beams import ClampedFreeModes, TabulatedModes
from .contract import Body, Contribution, Load, Part, PartVariables, Variable
from .dampers import unit_vector

__all__ = ["FlexibleAppendage", "flexible_antenna_satellite", "default_normal"]

#: eigenvalues of the Jacobi-scaled spread matrix below this (relative) are round-off
_RANK_RTOL = 1e-14
MODAL_UNIT = "kg^0.5 m"


def default_normal(direction) -> np.ndarray:
    """The default bending ``normal`` of a beam along ``direction``: the hub axis least
    aligned with it (the first such), made perpendicular to it and unit.

    Examples
    --------
    >>> from appdyn.dynamics.scene.flexible import default_normal
    >>> default_normal([1.0, 0.0, 0.0]), default_normal([0.0, 0.0, -1.0])
    (array([0., 1., 0.]), array([1., 0., 0.]))
    """
    d = unit_vector(direction, "direction")
    e = np.zeros(3)
    e[int(np.argmin(np.abs(d)))] = 1.0
    n = e - (e @ d) * d
    return n / np.linalg.norm(n)


def _beam(length, mass_per_length, modes, tip_mass, shapes):
    """The appendage's modes: clamped-free, or the Ritz modes of a shape table."""
    if shapes is None:
        return ClampedFreeModes(length, mass_per_length, modes, tip_mass)
    return TabulatedModes(length, mass_per_length, shapes[0], shapes[1], tip_mass)


@cache.memoize
def _body_coefficients(length, mass_per_length, modes, tip_mass, stiffening, shapes=None):
    """``(B, mu, K_unit)``: the basis coefficients of the bodies (columns of ``B``, the
    mass-centre body first), their momentum factors, and ``int phi'' phi''`` (module
    docstring). Basis order: ``1, x, phi_1..n, G_ij (i <= j)``."""
    beam = _beam(length, mass_per_length, modes, tip_mass, shapes)
    x, w = beam.nodes()
    pairs = [(i, j) for i in range(modes) for j in range(i, modes)] if stiffening else []

    def basis(xs):
        rows = [np.ones_like(xs), xs, *beam.shape(xs)]
        if pairs:  # G_ij(xk) = int_0^xk phi_i' phi_j'
            rows += list(beam.slope_integrals(xs, pairs))
        return np.array(rows)

    c = basis(x)
    tip = basis(np.array([float(length)]))[:, 0]
    C = mass_per_length * (c * w) @ c.T + tip_mass * np.outer(tip, tip)
    C = 0.5 * (C + C.T)
    M = C[0, 0]
    cm = C[:, 0] / M
    spread = C - M * np.outer(cm, cm)
    sub = spread[1:, 1:]
    s = np.sqrt(np.diag(sub))
    lam, V = np.linalg.eigh(sub / np.outer(s, s))
    keep = lam > _RANK_RTOL * lam.max()
    L = np.zeros((C.shape[0], int(keep.sum()) + 1))  # one zero column: room to centre them
    L[1:, :-1] = s[:, None] * V[:, keep] * np.sqrt(lam[keep])
    k = L.shape[1]
    u = np.full(k, 1.0 / math.sqrt(k))
    u[-1] -= 1.0
    H = np.eye(k) - 2.0 * np.outer(u, u) / (u @ u)  # H 1/sqrt(k) = e_last: columns sum to 0
    B = np.column_stack([cm, L @ H])
    d2 = beam.shape(x, 2)
    K = (d2 * w) @ d2.T
    return B, np.r_[M, np.ones(k)], 0.5 * (K + K.T), tuple(pairs)


@dataclass(frozen=True, init=False)
class FlexibleAppendage(Part):
    """A uniform flexible cantilever (an antenna, a boom) bending in two planes, by its
    clamped-free component modes (or a user's shape table), with geometric stiffening
    (module docstring).

    Parameters
    ----------
    length : float [m]
    mass_per_length : float [kg/m]
    bending_stiffness : float or array_like, shape (2,) [N m^2]
        ``EI``: one value, or one for bending along ``normal`` and one along
        ``direction x normal``.
    root : array_like, shape (3,) [m], optional
        The clamped end, from the parent's mass centre (parent axes).
    direction : array_like, shape (3,), optional
        The undeformed beam's axis (made unit).
    normal : array_like, shape (3,), optional
        The first bending direction, perpendicular to ``direction`` (made unit); default
        `default_normal` (the hub axis least aligned with ``direction``, made perpendicular).
    modes : int, optional
        Modes per plane (>= 1).
    tip_mass : float [kg], optional
        A point mass at the free end (its frequency equation is solved for the shapes).
    parent : str, optional
        The scene name of the part it sits on (None: the hub).
    name : str, optional
    stiffening : bool, optional
        Include the axial foreshortening (True). False gives the plain linear modal model,
        *for comparison only* (it misses the centrifugal stiffening: a spin-up diverges).
    shapes : (array_like, array_like), optional
        A user's shape table ``(x, phi)``: stations ``x`` shape (n,) [m] from 0 (the root) to
        ``length``, and ``phi`` shape (n, modes) admissible shapes (zero at the root, any
        scale), used instead of the computed clamped-free modes: interpolated by a cubic
        spline clamped at the root, then made the beam's Ritz modes
        (`dynamics.scene.beams.TabulatedModes`). ``modes`` is then the table's column count.

    Raises
    ------
    ValueError
        Naming the argument: a non-positive ``length``, ``mass_per_length`` or
        ``bending_stiffness``, a negative ``tip_mass``, ``modes`` < 1, a zero or non-finite
        ``direction`` or ``normal``, a ``normal`` not perpendicular to ``direction``.
    TypeError
        A ``parent`` that is not a str (or a non-integer ``modes``).

    Notes
    -----
    States: ``eta1..etaN`` (along ``normal``), ``xi1..xiN`` (along ``direction x normal``)
    [kg^0.5 m, the shapes being mass-orthonormal: ``phi`` in kg^-1/2] and their rates
    ``eta1_dot``, ... [kg^0.5 m/s]; no controls. The deflection at ``x`` is
    `deflection`. Energy (with the strain energy) and both momenta are the scene's
    invariants, exactly (no truncation beyond the modes).

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.scene import FlexibleAppendage, RigidHub, Scene
    >>> boom = FlexibleAppendage(2.0, 0.5, 10.0, root=(0.5, 0, 0), modes=2)
    >>> scene = Scene(RigidHub([10.0, 12.0, 8.0]), boom)
    >>> scene.model().states[7:]
    ('eta1', 'eta2', 'xi1', 'xi2', 'eta1_dot', 'eta2_dot', 'xi1_dot', 'xi2_dot')
    >>> boom.frequencies().round(4)        # rad/s, per plane
    array([[ 3.931 , 24.6353],
           [ 3.931 , 24.6353]])
    >>> x = scene.state(eta1=0.1)
    >>> bool(scene.model().rhs(x)[11] < 0)  # the beam springs back
    True
    """

    length: float
    mass_per_length: float
    bending_stiffness: tuple
    root: tuple
    direction: tuple
    normal: tuple
    modes: int
    tip_mass: float
    parent: str | None
    name: str | None
    stiffening: bool
    shapes: tuple | None
    kind = "appendage"

    def __init__(self, length, mass_per_length, bending_stiffness, *, root=(0.0, 0.0, 0.0),
                 direction=(1.0, 0.0, 0.0), normal=None, modes=4, tip_mass=0.0, parent=None,
                 name=None, stiffening=True, shapes=None):
        d = unit_vector(direction, "direction")
        if normal is None:
            n = default_normal(d)
        else:
            n = unit_vector(normal, "normal")
            if abs(n @ d) > 1e-12:
                raise ValueError(f"`normal` must be perpendicular to `direction`, got normal "
                                 f"{np.asarray(normal).tolist()} and direction "
                                 f"{np.asarray(direction).tolist()}")
        fields = {
            "length": positive(length, "length"),
            "mass_per_length": positive(mass_per_length, "mass_per_length"),
            "bending_stiffness": tuple(positive_each(bending_stiffness, "bending_stiffness",
                                                     2).tolist()),
            "root": tuple(finite_array(root, "root", (3,)).tolist()),
            "direction": tuple(d.tolist()),
            "normal": tuple(n.tolist()),
            "modes": integer(modes, "modes", minimum=1),
            "tip_mass": nonnegative(tip_mass, "tip_mass"),
            "parent": parent,
            "name": name,
            "stiffening": bool(stiffening),
            "shapes": None,
        }
        if shapes is not None:
            if not isinstance(shapes, (tuple, list)) or len(shapes) != 2:
                raise TypeError(f"`shapes` must be a pair (x, phi), got {type(shapes).__name__}")
            table = TabulatedModes(fields["length"], fields["mass_per_length"], shapes[0],
                                   shapes[1], fields["tip_mass"])
            fields["shapes"] = (table.x, table.shapes)
            fields["modes"] = table.modes
        if parent is not None and not isinstance(parent, str):
            raise TypeError(f"`parent` must be a part's name (str) or None, got {parent!r}")
        for key, value in fields.items():
            object.__setattr__(self, key, value)

    @property
    def beam(self):
        """The mode shapes (`dynamics.scene.beams.ClampedFreeModes`, or `TabulatedModes` for
        a shape table)."""
        return _beam(self.length, self.mass_per_length, self.modes, self.tip_mass, self.shapes)

    @property
    def binormal(self) -> np.ndarray:
        """``direction x normal``: the second bending direction."""
        return np.cross(self.direction, self.normal)

    def frequencies(self) -> np.ndarray:
        """The clamped-free frequencies [rad/s], shape (2, modes): along ``normal``, then
        along ``binormal`` (the cantilever on a locked hub)."""
        return np.array([self.beam.frequencies(ei) for ei in self.bending_stiffness])

    def deflection(self, x, eta, xi) -> np.ndarray:
        """The deflection at arc length ``x`` [m] (from the root): shape (3, k) [m], parent
        axes, for modal coordinates ``eta``, ``xi`` (shape (modes,) or (modes, k)), without
        the second-order foreshortening.

        Examples
        --------
        >>> from appdyn.dynamics.scene import FlexibleAppendage
        >>> boom = FlexibleAppendage(2.0, 0.5, 10.0, modes=1)
        >>> boom.deflection(2.0, [0.5], [0.0]).round(12).ravel()  # tip: phi_1(L) = 2 / sqrt(m L)
        array([0., 1., 0.])
        """
        phi = self.beam.shape(np.atleast_1d(np.asarray(x, float)))[:, -1]
        a = phi @ np.asarray(eta, float).reshape(self.modes, -1)
        b = phi @ np.asarray(xi, float).reshape(self.modes, -1)
        return np.outer(self.normal, a) + np.outer(self.binormal, b)

    def variables(self) -> PartVariables:
        n = range(1, self.modes + 1)
        coords = tuple(Variable(f"{p}{i}", MODAL_UNIT) for p in ("eta", "xi") for i in n)
        speeds = tuple(Variable(f"{p}{i}_dot", MODAL_UNIT + "/s") for p in ("eta", "xi")
                       for i in n)
        return PartVariables(coords=coords, speeds=speeds)

    def contribute(self, frame, own) -> Contribution:
        n = self.modes
        B, mu, K, pairs = _body_coefficients(self.length, self.mass_per_length, n,
                                             self.tip_mass, self.stiffening, self.shapes)
        q = (own.coords[:n], own.coords[n:])
        qd = (own.speeds[:n], own.speeds[n:])
        d, dirs = ca.DM(self.direction), (ca.DM(self.normal), ca.DM(self.binormal))
        root = frame.point(self.root)
        bodies, spread = [], []
        for k in range(B.shape[1]):
            b = B[:, k]
            beta = ca.DM(b[2:2 + n])
            pos = b[0] * root + b[1] * d
            rel = ca.SX.zeros(3)
            for qi, qdi, e in zip(q, qd, dirs):
                pos = pos + ca.dot(beta, qi) * e
                rel = rel + ca.dot(beta, qdi) * e
            if pairs:
                S = np.zeros((n, n))
                for (i, j), g in zip(pairs, b[2 + n:]):  # s = 1/2 sum_ij G_ij q_i q_j
                    S[i, j] = S[j, i] = 0.5 * g
                S = ca.DM(S)
                shorten = sum(ca.dot(qi, ca.mtimes(S, qi)) for qi in q)
                rate = sum(2.0 * ca.dot(qi, ca.mtimes(S, qdi)) for qi, qdi in zip(q, qd))
                pos, rel = pos - shorten * d, rel - rate * d
            vel = b[0] * frame.v + ca.cross(frame.w, pos) + rel
            if k == 0:
                cm, v_cm = pos, vel
            else:
                spread.append(pos)
                bodies.append(Body(velocity=vel, angular_velocity=frame.w,
                                   momentum=mu[k] * vel, angular_momentum=ca.SX.zeros(3),
                                   position=pos))
        J = sum((ca.mtimes(p, p.T) for p in spread), ca.SX.zeros(3, 3))
        inertia = ca.trace(J) * ca.SX.eye(3) - J
        bodies.insert(0, Body(velocity=v_cm, angular_velocity=frame.w, momentum=mu[0] * v_cm,
                              angular_momentum=ca.SX.zeros(3), position=cm, mass=float(mu[0]),
                              inertia=inertia))
        loads, potential = [], 0.0
        for qi, qdi, ei in zip(q, qd, self.bending_stiffness):
            Kq = ca.mtimes(ca.DM(ei * K), qi)
            loads.append(Load(-Kq, qdi))
            potential = potential + 0.5 * ca.dot(qi, Kq)
        return Contribution(bodies=bodies, loads=loads, potential=potential)


def flexible_antenna_satellite(hub_inertia, length, mass_per_length, bending_stiffness, *,
                               hub_radius, modes=4, tip_mass=0.0, spin_axis=(0.0, 0.0, 1.0),
                               stiffening=True, name="antenna_satellite"):
    """The seed's Example 6: a spinning rigid satellite with four flexible cantilever antennas
    (RP-1262, Ch. 6), as a `Scene`.

    The antennas are clamped on the hub at ``hub_radius`` along the two hub axes normal to
    ``spin_axis`` (a hub axis), pointing radially out; each bends in plane (``eta``, along
    ``spin_axis x direction``) and out of plane (``xi``, along ``spin_axis``), the seed's
    ``y = sum Y_i eta_i`` and ``z = sum Z_k xi_k``.

    Parameters
    ----------
    hub_inertia : array_like, shape (3, 3) or (3,) [kg m^2]
    length, mass_per_length, bending_stiffness, modes, tip_mass, stiffening
        Of each antenna (`FlexibleAppendage`).
    hub_radius : float [m]
        The roots' distance from the hub's mass centre.
    spin_axis : array_like, shape (3,), optional
        A hub axis (``+-e_k``).

    Returns
    -------
    Scene
        Parts ``antenna``, ``antenna_2``, ``antenna_3``, ``antenna_4`` (+a, +b, -a, -b, with
        ``(a, b, spin_axis)`` right-handed).

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.scene import flexible_antenna_satellite
    >>> from appdyn.problems import stability
    >>> sat = flexible_antenna_satellite([300.0, 300.0, 500.0], 3.0, 0.2, 20.0,
    ...                                  hub_radius=0.8, modes=1)
    >>> rep = stability.spin(sat, [0, 0, 1], 1.0)
    >>> rep.verdict
    'marginally stable'
    """
    from .hubs import RigidHub
    from .scene import Scene
    a3 = unit_vector(spin_axis, "spin_axis")
    if np.count_nonzero(np.abs(a3) > 1e-15) != 1:
        raise ValueError(f"`spin_axis` must be a hub axis (+-e_k), got {np.asarray(spin_axis)}")
    r = positive(hub_radius, "hub_radius")
    k = int(np.argmax(np.abs(a3)))
    a1 = np.zeros(3)
    a1[(k + 1) % 3] = 1.0
    a2 = np.cross(a3, a1)
    parts = []
    for d in (a1, a2, -a1, -a2):
        parts.append(FlexibleAppendage(length, mass_per_length, bending_stiffness,
                                       root=tuple(r * d), direction=tuple(d),
                                       normal=tuple(np.cross(a3, d)), modes=modes,
                                       tip_mass=tip_mass, name="antenna" if not parts else f"antenna_{len(parts) + 1}",
                                       stiffening=stiffening))
    return Scene(RigidHub(hub_inertia), *parts, name=name)
