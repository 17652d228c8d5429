"""The Boltzmann-Hamel equations: Lagrange's equations in quasi-velocities (Rheinfurth &
Wilson, NASA RP-1262, Sec. 6.1, Eqs. 6.1-6.17).

Quasi-velocities ``u`` (body rates ``w``, velocity components ``v`` in moving axes, modal
rates ``eta'``) are related to the coordinates' rates by the kinematics ``q' = W(q) u`` (the
seed's ``Omega = A(q) q'`` with ``W = A^-1``; ``W`` may be tall, as the 4 x 3 quaternion
kinematics). With ``T*(q, u, t)`` the kinetic energy in them, virtual displacements
``dq = W d(xi)`` (Eq. 6.12) turn Lagrange's equations into (Eqs. 6.10, 6.17, re-derived)::

    d/dt dT*/du_r + sum_{s,l} c^l_rs u_s dT*/du_l - W_r . dT*/dq = k_r,     k = W^T Q

where ``W_r`` is the ``r``-th column of ``W`` and ``c^l_rs`` are Hamel's coefficients, the
components of the Lie bracket ``[W_r, W_s] = (dW_s/dq) W_r - (dW_r/dq) W_s`` along the columns
(``= sum_l c^l_rs W_l``; the seed's ``[(A' - J) A^-1]^T`` term). The brackets are formed by
automatic differentiation and resolved by the left inverse ``(W^T W)^-1 W^T``, so the builder
needs only ``W``. For the rigid body, ``T* = 1/2 (m v.v + w.J w)`` and the quaternion
kinematics give ``c^l_rs = e_rsl``, i.e. Eqs. 6.19-6.20: ``m (v' + w x v) = F``,
``J w' + w x J w + v x m v = L`` (the last term zero).
"""
from __future__ import annotations

import casadi as ca

from .. import validate
from ..clock import CLOCK_STATE, CLOCK_UNIT
from ..model import Model, model_from_expressions, named_symbols
from .lagrange import generalized_forces

__all__ = ["hamel_terms", "hamel_model"]


def hamel_terms(T, q, u, W, *, potential=None, t=None, forces=(), quasi_forces=None):
    """Mass matrix and forces of the Boltzmann-Hamel equations ``M u' = F`` (seed Eq. 6.17).

    Parameters
    ----------
    T : casadi.SX
        Kinetic energy ``T*(q, u, t)`` [J] in the quasi-velocities (scalar).
    q : casadi.SX, n x 1
        Coordinates (symbols).
    u : casadi.SX, m x 1
        Quasi-velocities (symbols), ``m <= n``.
    W : casadi.SX, n x m
        The kinematics ``q' = W(q) u`` (full column rank; independent of ``u``).
    potential : casadi.SX, optional
        Potential energy ``V(q, t)`` [J] (scalar): its forces ``k = -W^T dV/dq``.
    t : casadi.SX, optional
        Time symbol, when ``T`` or a force depends on time explicitly.
    forces : sequence of (casadi.SX, casadi.SX), optional
        Applied forces at points ``(F_i, r_i(q))`` as `lagrange.generalized_forces`; they
        enter as ``k = W^T Q`` (Eq. 6.14).
    quasi_forces : casadi.SX, m x 1, optional
        Forces along the quasi-coordinates directly (``k``: a body force and torque in body
        axes for ``u = (v, w)``, Eqs. 6.19-6.22).

    Returns
    -------
    (casadi.SX, casadi.SX)
        ``M = d^2 T*/du^2`` (m x m) and ``F`` (m x 1).

    Raises
    ------
    TypeError
        If an argument is not a CasADi SX/MX expression.
    ValueError
        If ``T`` is not a scalar, ``W`` is not ``n x m``, depends on ``u``, or
        ``quasi_forces`` has not ``m`` entries.

    Examples
    --------
    A rigid body's rotation in body rates with the quaternion kinematics: Euler's equations
    ``J w' = -w x J w``:

    >>> import casadi as ca
    >>> from appdyn.dynamics.attitude import quat_rate
    >>> from appdyn.dynamics.mechanisms import hamel_terms
    >>> q, w = ca.SX.sym("q", 4), ca.SX.sym("w", 3)
    >>> J = ca.diag(ca.DM([1.0, 2.0, 3.0]))
    >>> W = ca.jacobian(quat_rate(q, w), w)
    >>> M, F = hamel_terms(0.5 * ca.dot(w, ca.mtimes(J, w)), q, w, W)
    >>> f = ca.Function("f", [q, w], [ca.solve(M, F)])
    >>> f([0, 0, 0, 1], [1.0, 1.0, 1.0]).T                    # (J w) x w / J
    DM([[-1, 1, -0.333333]])
    """
    for name, a in (("T", T), ("q", q), ("u", u), ("W", W), ("t", t),
                    ("quasi_forces", quasi_forces), ("potential", potential)):
        if a is None and name in ("t", "quasi_forces", "potential"):
            continue
        if not validate.is_symbolic(a) and not (name == "W" and isinstance(a, ca.DM)):
            raise validate.ArgumentTypeError(f"`{name}` must be a casadi SX/MX expression, "
                                             f"got {type(a).__name__}")
    for name, a in (("T", T), ("potential", potential)):
        if a is not None and a.shape != (1, 1):
            raise ValueError(f"`{name}` must be a scalar (1x1) expression, got shape {a.shape}")
    n, m = q.numel(), u.numel()
    W = ca.SX(W)
    if W.shape != (n, m):
        raise ValueError(f"`W` must be {n} x {m} (coordinates x quasi-velocities), got "
                         f"{W.shape[0]} x {W.shape[1]}")
    if ca.depends_on(W, u):
        raise ValueError("`W` must not depend on the quasi-velocities `u` (q' = W(q) u)")
    qdot = ca.mtimes(W, u)
    p = ca.gradient(T, u)
    M = ca.jacobian(p, u)
    # the brackets sum_s u_s [W_r, W_s] as columns, resolved along the columns of W
    B = ca.mtimes(ca.jacobian(qdot, q), W) - ca.horzcat(
        *[ca.mtimes(ca.jacobian(W[:, r], q), qdot) for r in range(m)])
    C = ca.solve(ca.mtimes(W.T, W), ca.mtimes(W.T, B))             # m x m: c^l_rs u_s
    k = ca.mtimes(W.T, generalized_forces(forces, q)) if len(forces) else ca.SX.zeros(m)
    if quasi_forces is not None:
        kq = ca.vec(ca.SX(quasi_forces))
        if kq.numel() != m:
            raise ValueError(f"`quasi_forces` must have {m} entries (one per quasi-velocity), "
                             f"got {kq.numel()}")
        k = k + kq
    if potential is not None:
        k = k - ca.mtimes(W.T, ca.gradient(potential, q))
    F = k + ca.mtimes(W.T, ca.gradient(T, q)) - ca.mtimes(ca.jacobian(p, q), qdot) \
        - ca.mtimes(C.T, p)
    if t is not None:
        F = F - ca.jacobian(p, t)
    return M, F


def hamel_model(coords, speeds, T, W, *, potential=None, t=None, forces=(), quasi_forces=None,
                controls=None, params=None, p_default=None, units=None,
                name: str = "boltzmann_hamel", attitude=None) -> Model:
    """A `Model` from the Boltzmann-Hamel equations (`hamel_terms`).

    ``x = [q, u, (t)]``, ``x' = [W u, M^-1 F, (1)]``.

    Parameters
    ----------
    coords, speeds : mapping of str to casadi.SX, or sequence of (str, casadi.SX)
        The coordinates ``q`` and the quasi-velocities ``u``: names and scalar symbols.
    T, W, potential, t, forces, quasi_forces
        As `hamel_terms` (in these symbols, the controls and the parameters).
    controls, params : mapping of str to casadi.SX, or sequence of (str, casadi.SX), optional
        Control and parameter symbols the forces use (``p_default`` by name or in order).
    units : mapping of str to str, optional
    name : str, optional
    attitude : tuple, optional
        As `Model` (``("q1", "w1")`` for a quaternion and body rates).

    Returns
    -------
    Model
        States: coordinates, quasi-velocities (and the clock ``t``); invariant ``energy`` [J]
        (``T* + V``: conserved without applied forces and explicit time).

    Raises
    ------
    ValueError
        The errors of `hamel_terms` and `dynamics.model.model_from_expressions`.

    Examples
    --------
    A point mass in the plane, polar coordinates ``(r, phi)`` with the quasi-velocities
    ``v_r = r'``, ``v_t = r phi'`` (velocity components along the turning radius):

    >>> import casadi as ca
    >>> from appdyn.dynamics.mechanisms import hamel_model
    >>> r, phi, vr, vt = (ca.SX.sym(n) for n in ("r", "phi", "v_r", "v_t"))
    >>> model = hamel_model({"r": r, "phi": phi}, {"v_r": vr, "v_t": vt},
    ...                     0.5 * (vr ** 2 + vt ** 2), ca.diag(ca.vertcat(1, 1 / r)))
    >>> model.rhs([2.0, 0.0, 1.0, 3.0]).tolist()   # v_r' = v_t^2 / r, v_t' = -v_r v_t / r
    [1.0, 1.5, 4.5, -1.5]
    """
    q_named = dict(zip(*named_symbols(coords, "coords", required=True)))
    u_named = dict(zip(*named_symbols(speeds, "speeds", required=True)))
    q, u = ca.vertcat(*q_named.values()), ca.vertcat(*u_named.values())
    M, F = hamel_terms(T, q, u, W, potential=potential, t=t, forces=forces,
                       quasi_forces=quasi_forces)
    V = 0.0 if potential is None else potential
    states = [*q_named.items(), *u_named.items()] + ([(CLOCK_STATE, t)] if t is not None else [])
    xdot = (ca.vertsplit(ca.mtimes(ca.SX(W), u)) + ca.vertsplit(ca.solve(M, F))
            + ([1.0] if t is not None else []))
    units = {**({CLOCK_STATE: CLOCK_UNIT} if t is not None else {}), **dict(units or {})}
    return model_from_expressions(states, xdot, controls=controls, params=params,
                                  p_default=p_default, units=units, name=name,
                                  invariants={"energy": T + V}, attitude=attitude)
