"""Assemble a `Scene` into one `Model` by Kane's method on the symbols.

Generalized speeds ``nu = (w, [v], part speeds)``, coordinates ``c = (q, [r], part
coordinates)`` with ``q' = -1/2 Wbar(w) q`` (seed Eq. 4.70) and ``r' = A^T v`` (relative
to a turning frame with ``RigidHub(reference_rate=...)``: `reference_rates`). Each body
``b`` (the hub's and every part's) has the absolute velocity ``v_b`` of its mass centre and
angular velocity ``w_b``, linear momentum ``p_b`` and angular momentum ``h_b`` about its mass
centre, all in hub axes. Their inertial derivatives in hub components are
``p_b' = dp_b/dnu nu' + dp_b/dc c' + w x p_b`` (and likewise ``h_b'``), and Kane's equations
(``sum_b (dv_b/dnu)^T p_b' + (dw_b/dnu)^T h_b' = sum_loads (dv/dnu)^T F``) are linear in
``nu'``::

    M nu' = Q - G(nu' = 0),    M = dG / dnu'.

``M`` has a hub block and one block per part (parts couple to the hub, not to each other,
unless one sits on another: coupled parts are merged into one block). The system is solved
once by back-substitution: ``K_i^-1`` per part block (numeric when constant), the hub
accelerations from the Schur complement ``S = M_hh - sum_i M_hi K_i^-1 M_ih`` (inverted
numerically when constant: a hub alone is ``I^-1 (L - w x I w)``, nothing more), then each
part's accelerations. Controls that prescribe a motion (a CMG's gimbal rate) are held constant
over the derivative (their own derivative is not a model input).
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import casadi as ca
import numpy as np

from ..attitude import dcm_from_axis_angle, dcm_from_quat, quat_rate
from ..model import Model
from .contract import Body, Contribution, Frame, PartSymbols

__all__ = ["PartLayout", "assemble", "kane_equations", "in_hub_axes", "reference_rates",
           "turning_frame_dcm"]


@dataclass(frozen=True)
class PartLayout:
    """Where a part's variables sit in the model's ``x`` and ``u``.

    Attributes
    ----------
    states : slice
        All its states (coordinates then speeds).
    controls : slice
    coords, speeds : slice
        Its coordinates and its speeds inside ``x``.
    names : tuple of str
        Its state names, then its control names, as they appear in the model.
    """

    states: slice
    controls: slice
    coords: slice
    speeds: slice
    names: tuple = ()


def _column(syms: list) -> ca.SX:
    return ca.vertcat(*syms) if syms else ca.SX(0, 1)


def _jac(expr, wrt) -> ca.SX:
    if wrt.numel() == 0:
        return ca.SX(ca.SX(expr).numel(), 0)
    return ca.jacobian(ca.SX(expr), wrt)


def kane_equations(bodies: list, loads: list, w, speeds, coords, coord_rates):
    """``(M, F)`` with ``M nu' = F`` from the bodies and loads (module docstring).

    Parameters
    ----------
    bodies : list of Body
    loads : list of Load
    w : SX, 3x1
        The hub angular velocity (the frame the components are taken in turns at it).
    speeds, coords, coord_rates : SX columns
        ``nu``, ``c`` and ``c'``.

    Returns
    -------
    M : SX, (n, n)
    F : SX, (n, 1)

    Notes
    -----
    Kane's sum is linear in the momenta, so for each generalized speed the momenta whose
    partial velocities along it are the same constant column (the hub's and every rotor's
    or gimbal's turning with it, along ``w``) are summed before they are differentiated, and
    each such sum once for all the speeds that share it: one ``w x H`` for the hub, as in a
    hand-written model (a CMG pyramid's right-hand side: 189 instructions, hand-written 181;
    three reaction wheels: 123, hand-written 122).
    """
    n = speeds.numel()
    nud = ca.SX.sym("nu_dot", n)
    terms = []
    for b in bodies:
        for mom, vel in ((b.momentum, b.velocity), (b.angular_momentum, b.angular_velocity)):
            mom = ca.SX(mom)
            if not mom.is_zero():
                terms.append((_jac(vel, speeds), mom))
    rates = {}

    def rate_of(members: frozenset):
        if members not in rates:
            mom = sum((terms[i][1] for i in sorted(members)), ca.SX.zeros(3))
            rates[members] = (ca.mtimes(_jac(mom, speeds), nud)
                              + ca.mtimes(_jac(mom, coords), coord_rates) + ca.cross(w, mom))
        return rates[members]

    G = []
    for k in range(n):
        groups = {}
        for i, (P, _) in enumerate(terms):
            col = P[:, k]
            if col.is_zero():
                continue
            key = tuple(np.array(ca.DM(col)).ravel().tolist()) if col.is_constant() else i
            groups.setdefault(key, (col, []))[1].append(i)
        G.append(sum((ca.dot(col, rate_of(frozenset(members)))
                      for col, members in groups.values()), ca.SX(0)))
    G = ca.vertcat(*G) if G else ca.SX(0, 1)
    Q = ca.SX.zeros(n)
    for load in loads:
        Q += ca.mtimes(_jac(load.velocity, speeds).T, ca.SX(load.vector))
    M = ca.jacobian(G, nud)
    G0 = ca.substitute(G, nud, ca.SX.zeros(n))
    return M, Q - G0


def _blocks(M, n_hub: int, part_slices: list) -> list:
    """Part speed blocks, merged where the mass matrix couples two of them."""
    groups = [list(range(s.start, s.stop)) for s in part_slices if s.stop > s.start]
    merged = True
    while merged:
        merged = False
        for i in range(len(groups)):
            for j in range(i + 1, len(groups)):
                block = M[groups[i], groups[j]]
                if block.nnz() and not all(ca.SX(e).is_zero() for e in block.nonzeros()):
                    groups[i] = sorted(groups[i] + groups.pop(j))
                    merged = True
                    break
            if merged:
                break
    return groups


def _inverse_times(K, B):
    """``K^-1 B``: numerically when ``K`` is constant, else a symbolic solve."""
    if K.is_constant():
        return ca.mtimes(ca.DM(np.linalg.inv(np.array(ca.DM(K)))), B)
    return ca.solve(K, B)


def solve_blocks(M, F, n_hub: int, part_slices: list):
    """``nu'`` from ``M nu' = F`` by back-substitution over the hub (module docstring)."""
    n = F.numel()
    hub = list(range(n_hub))
    groups = _blocks(M, n_hub, part_slices)
    S = M[hub, hub]
    rhs = F[hub]
    solved = []
    for g in groups:
        K, Mgh, Fg = M[g, g], M[g, hub], F[g]
        KiM, KiF = _inverse_times(K, Mgh), _inverse_times(K, Fg)
        S = S - ca.mtimes(M[hub, g], KiM)
        rhs = rhs - ca.mtimes(M[hub, g], KiF)
        solved.append((g, KiM, KiF))
    a_hub = _inverse_times(S, rhs)
    out = [None] * n
    for i, k in enumerate(hub):
        out[k] = a_hub[i]
    for g, KiM, KiF in solved:
        a = KiF - ca.mtimes(KiM, a_hub)
        for i, k in enumerate(g):
            out[k] = a[i]
    return ca.vertcat(*out)


def in_hub_axes(frame: Frame, c: Contribution) -> Contribution:
    """A contribution written in a part's body frame (parts on parts), in hub axes.

    Bodies' vectors are turned by ``frame.to_hub`` and their positions moved to the hub's
    reference point; a momentum override (about the frame's origin) gains ``origin x P``.
    Loads need no turning: their power ``F . v`` and partial velocities are the same in any
    axes fixed to the hub or turning with the coordinates only.
    """
    if frame.is_hub:
        return c
    T, o = frame.to_hub, frame.origin

    def turn(vec):
        return ca.mtimes(T, ca.SX(vec))

    bodies = [Body(velocity=turn(b.velocity), angular_velocity=turn(b.angular_velocity),
                   momentum=turn(b.momentum), angular_momentum=turn(b.angular_momentum),
                   position=o + turn(b.position), mass=b.mass,
                   inertia=None if b.inertia is None else ca.mtimes([T, ca.SX(b.inertia), T.T]))
              for b in c.bodies]
    momentum = c.momentum
    if momentum is not None:
        P = sum((b.momentum for b in bodies), ca.SX.zeros(3))
        momentum = turn(momentum) + ca.cross(o, P)
    return replace(c, bodies=bodies, momentum=momentum)


def reference_rates(hub, q, w, A, r, v) -> list:
    """The hub's coordinate rates ``[q', (r')]``: ``q' = -1/2 Wbar(w_rel) q``, ``r' = A^T v``,
    relative to a frame turning at ``hub.reference_rate`` ``Omega`` when it is given
    (``w_rel = w - A Omega``, ``r' = A^T v - Omega x r``), else inertial."""
    if hub.reference_rate is None:
        return [quat_rate(q, w)] + ([ca.mtimes(A.T, v)] if r is not None else [])
    Om = ca.DM(hub.reference_rate)
    return [quat_rate(q, w - ca.mtimes(A, Om))] + (
        [ca.mtimes(A.T, v) - ca.cross(Om, r)] if r is not None else [])


def turning_frame_dcm(reference_rate, t):
    """Inertial -> turning-frame components at time ``t`` for a frame turning at the
    constant ``reference_rate`` ``Omega`` that coincides with the inertial axes at ``t = 0``.

    ``C(t) = dcm_from_axis_angle(Omega / |Omega|, |Omega| t)`` (seed Eq. 4.45).

    Parameters
    ----------
    reference_rate : array_like, shape (3,) [rad/s]
    t : float or SX scalar [s]

    Returns
    -------
    C : DM or SX, 3x3

    Examples
    --------
    >>> import numpy as np
    >>> C = turning_frame_dcm([0.0, 0.0, 0.5], np.pi)   # a quarter turn about z
    >>> np.round(np.array(C), 12) + 0.0                 # inertial x is then -y
    array([[ 0.,  1.,  0.],
           [-1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    """
    Om = ca.DM(reference_rate)
    rate = float(ca.norm_2(Om))
    if rate == 0.0:
        return ca.DM.eye(3)
    return dcm_from_axis_angle(Om / rate, rate * t)


def assemble(scene) -> Model:
    """The `Model` of ``scene`` (module docstring); use `Scene.model`, which caches it."""
    hub = scene.hub
    hub_coords, hub_speeds = hub.variables()
    named = scene.variable_names()
    sym = {name: ca.SX.sym(name) for name in named["states"] + named["controls"]}

    q = _column([sym[v.name] for v in hub_coords[:4]])
    w = _column([sym[v.name] for v in hub_speeds[:3]])
    if hub.translates:
        r = _column([sym[v.name] for v in hub_coords[4:]])
        v = _column([sym[v.name] for v in hub_speeds[3:]])
    else:
        r, v = None, ca.SX.zeros(3)
    A = dcm_from_quat(q)
    frame = Frame(q=q, dcm=A, w=w, v=v, r=r, reference=hub.reference, mass=hub.mass,
                  reference_rate=hub.reference_rate)

    I_hub = ca.DM(hub.inertia_matrix)
    cm = -ca.DM(hub.reference)
    hub_body = Body.rigid(hub.mass or 0.0, I_hub, cm, frame.velocity(cm), w)
    if hub.mass is None:
        hub_body.momentum = ca.SX.zeros(3)
    bodies_by_part = {"hub": [hub_body]}
    loads, potential, kinetic, extra, momenta = [], [], [], {}, {}
    coord_syms = [q] + ([r] if r is not None else [])
    coord_rates = reference_rates(hub, q, w, A, r, v)
    speed_syms = [w] + ([v] if hub.translates else [])
    part_speed_slices = []
    n_hub = 6 if hub.translates else 3
    offset = n_hub
    owns, frames = {}, {}
    frozen = set()
    for i in scene.mount_order:
        part, pname, parent = scene.parts[i], scene.part_names[i], scene.parents[i]
        local = named["local"][pname]
        own = PartSymbols(_column([sym[local[k]] for k in local["__coords__"]]),
                          _column([sym[local[k]] for k in local["__speeds__"]]),
                          _column([sym[local[k]] for k in local["__controls__"]]),
                          {k: sym[vname] for k, vname in local.items() if not k.startswith("__")})
        owns[pname] = own
        on = frame if parent is None else frames[parent]
        frozen.update(local[v.name] for v in part.variables().coords if v.frozen)
        c = in_hub_axes(on, part.contribute(on, own))
        if pname in scene.parents:
            frames[pname] = part.body_frame(on, own)
        if own.coords.numel():
            rates = ca.SX(c.rates) if c.rates is not None else own.speeds
            if rates.numel() != own.coords.numel():
                raise ValueError(f"part {pname!r} gives {rates.numel()} coordinate rates for "
                                 f"{own.coords.numel()} coordinates")
            coord_syms.append(own.coords)
            coord_rates.append(ca.vec(rates))
        speed_syms.append(own.speeds)
        ns = own.speeds.numel()
        part_speed_slices.append(slice(offset, offset + ns))
        offset += ns
        bodies_by_part[pname] = list(c.bodies)
        loads += list(c.loads)
        potential.append(c.potential)
        if c.kinetic is not None:
            kinetic.append(c.kinetic)
        else:
            kinetic.extend(0.5 * (ca.dot(b.momentum, b.velocity)
                                  + ca.dot(b.angular_momentum, b.angular_velocity))
                           for b in c.bodies)
        extra.update(c.invariants)
        if c.momentum is not None:
            momenta[pname] = ca.SX(c.momentum)
    all_bodies = [b for bs in bodies_by_part.values() for b in bs]
    for part, pname in zip(scene.parts, scene.part_names):
        c = part.field_loads(frame, all_bodies, owns[pname])
        loads += list(c.loads)
        potential.append(c.potential)
        extra.update(c.invariants)
    kinetic.append(0.5 * (ca.dot(hub_body.momentum, hub_body.velocity)
                          + ca.dot(hub_body.angular_momentum, w)))

    speeds = ca.vertcat(*speed_syms)
    coords = ca.vertcat(*coord_syms)
    cdot = ca.vertcat(*coord_rates)
    moving = [k for k in range(coords.numel()) if coords[k].name() not in frozen]
    M, F = kane_equations(all_bodies, loads, w, speeds, coords[moving], cdot[moving])
    nud = solve_blocks(M, F, n_hub, part_speed_slices)

    # x' in state order
    rate_of = {}
    for k in range(coords.numel()):
        rate_of[coords[k].name()] = cdot[k]
    for k in range(speeds.numel()):
        rate_of[speeds[k].name()] = nud[k]
    states = named["states"]
    x = ca.vertcat(*[sym[s] for s in states])
    u = _column([sym[c] for c in named["controls"]])
    p = ca.SX.sym("p", 0)
    xdot = ca.vertcat(*[rate_of[s] for s in states])
    label = scene.name or "scene"
    f = ca.Function(label, [x, u, p], [xdot], ["x", "u", "p"], ["xdot"])

    # invariants
    H = sum((momenta[pname] if pname in momenta else
             sum((b.angular_momentum + ca.cross(b.position, b.momentum) for b in bs),
                 ca.SX.zeros(3))
             for pname, bs in bodies_by_part.items()), ca.SX.zeros(3))
    P = sum((ca.SX(b.momentum) for b in all_bodies), ca.SX.zeros(3))
    H_in = ca.mtimes(A.T, H)
    exprs = {"energy": sum(kinetic) + sum(ca.SX(e) for e in potential)}
    if hub.translates:
        P_in = ca.mtimes(A.T, P)
        exprs["momentum_inertial"] = H_in + ca.cross(r, P_in)
        exprs["momentum_linear"] = P_in
    else:
        exprs["momentum_inertial"] = H_in
    exprs["quat_norm"] = ca.norm_2(q)
    exprs.update(extra)
    invariants = {}
    for key, e in exprs.items():
        e = ca.vec(ca.SX(e))
        if ca.depends_on(e, u) if u.numel() else False:
            raise ValueError(f"invariant {key!r} of part depends on a control")
        invariants[key] = ca.Function(key, [x, p], [e], ["x", "p"], [key])

    return Model(f=f, states=states, controls=named["controls"], units=named["units"],
                 invariants=invariants, name=label, attitude=(0, 4),
                 layout=scene.layout, bounds=named["bounds"])
