"""The spin of any `dynamics.scene.Scene`: its relative equilibrium, linearization and reduction.

A scene spinning at ``w = rate * axis`` (hub axes) with every part at rest relative to the hub
has the part speeds of `Part.spin_speeds` (`Scene.state`) and part coordinates that make the
part speeds' derivatives vanish (a point-mass damper's centrifugal offset), found by Newton's
method with the hub rate held (`spin_point`). The whole right-hand side is then checked by
`dynamics.linearize.linearization` (a hub rate derivative that does not vanish means the axis
is not principal for the loaded body). A six-degree-of-freedom hub is reduced to its
attitude first (`attitude_subsystem`: the position is cyclic, and the system mass centre is
held at rest, ``P = 0``), so every state and layout below is that subsystem's.

`spin_linearization` linearizes in body rates (``frame='rates'``; in the spinning frame, with
the spin phase factored out by `Linearization.quotient`, when a load depends on the
attitude), factors out cyclic part coordinates (nothing depends on them) and restricts to the level sets of the first integrals: ``|H|^2`` first (today's
free-spin reduction), then every further invariant of the scene that the
flow conserves exactly (a reaction wheel's absolute axial momentum), each only where its
gradient is independent of those already used. Modes are labelled by part, from the model's
``layout`` (``'nutation'`` for the hub's rates and angles, the part's name otherwise).
"""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from appdyn.dynamics import cache
from appdyn.dynamics.linearize import ANGLE_STATES, Linearization, linearization
from appdyn.dynamics.model import Model
from appdyn.dynamics.scene import PartLayout, Scene

__all__ = ["SpinPoint", "SpinLinearization", "spin_point", "spin_linearization",
           "spin_groups", "attitude_subsystem", "NEWTON_RTOL", "NEWTON_MAX_ITER"]

NEWTON_RTOL = 1e-13
"""Relative tolerance of the part-coordinate solve (`spin_point`)."""
NEWTON_MAX_ITER = 50
_DEPENDENT_RTOL = 1e-8  # a projected gradient below this (relative) repeats an integral
_CONSERVED_RTOL = 1e-9  # |d(invariant)/dt| relative to |grad| |xdot| at perturbed states
HUB_LABEL = "nutation"


@dataclass(frozen=True)
class SpinPoint:
    """The steady spin of a scene (`spin_point`).

    Attributes
    ----------
    x : ndarray, shape (nx,)
        The state: identity attitude, ``w = rate * axis``, parts at rest relative to the hub
        (a translating hub: the state of `attitude_subsystem`, without ``r``, ``v``).
    coordinates : tuple of str
        The part coordinates solved for.
    residual : float
        ``max |part speeds'|`` at ``x`` (their units per second).
    iterations : int
        Newton steps taken.
    converged : bool
    values : tuple of float
        The solved coordinates, in the order of ``coordinates``.
    """

    x: np.ndarray
    coordinates: tuple
    residual: float
    iterations: int
    converged: bool
    values: tuple = ()


@dataclass(frozen=True)
class SpinLinearization:
    """A scene's spin, linearized and reduced (`spin_linearization`).

    Attributes
    ----------
    point : SpinPoint
    lin : Linearization
        Before reduction.
    reduced : Linearization
        After the quotients and restrictions (its ``notes`` say which states went).
    notes : tuple of str
        Further notes (a first integral that could not be used).
    groups : dict of str -> list of str
        Mode labels by part: the reduced states of the hub (``'nutation'``) and of each part.
    """

    point: SpinPoint
    lin: Linearization
    reduced: Linearization
    notes: tuple
    groups: dict


TRANSLATION = ("r1", "r2", "r3", "v1", "v2", "v3")
"""The translational states of a six-degree-of-freedom hub, removed by `attitude_subsystem`."""


def _shifted(lay: PartLayout, index: dict) -> PartLayout:
    """``lay`` with its state slices renumbered by ``index`` (old -> new position; states
    not in ``index`` dropped, the others contiguous)."""
    def cut(sl):
        kept = [index[i] for i in range(sl.start, sl.stop) if i in index]
        return slice(kept[0], kept[-1] + 1) if kept else slice(0, 0)
    names = tuple(n for n in lay.names if n not in TRANSLATION)
    return PartLayout(states=cut(lay.states), controls=lay.controls, coords=cut(lay.coords),
                      speeds=cut(lay.speeds), names=names)


@cache.memoize
def attitude_subsystem(scene: Scene) -> Model:
    """The attitude of ``scene`` at zero linear momentum: the hub's ``r``, ``v`` removed.

    A free vehicle's translation decouples from its attitude. The hub's position ``r`` is
    cyclic (nothing in the right-hand side depends on it: checked), so its rows go; the
    linear momentum ``P`` is conserved, and on its level set ``P = 0`` (the system mass
    centre at rest) the hub's velocity is fixed by the other speeds: with the body-axis
    momentum ``P_b = dT/dv = M v + w x S + sum m_i v_rel,i`` (``T`` the kinetic energy,
    affine in ``v``), ``v = -J^-1 P_b(v = 0)``, ``J = dP_b/dv``. The flow on that level set
    is exact: ``x' = f(x(y))`` without the ``r``, ``v`` rows, ``x(y)`` the full state with
    ``r = 0`` and that ``v``. The invariants are the scene's at ``x(y)`` (the angular
    momentum about the origin is then the one about any point), ``momentum_linear``
    (identically zero) excepted. An attitude-only scene's model is returned unchanged.

    Parameters
    ----------
    scene : Scene

    Returns
    -------
    Model
        States of ``scene.model()`` without ``r1..r3, v1..v3``; controls, units, bounds and
        ``layout`` (renumbered) likewise. Controls that exert a force are kept, but their
        effect on ``P`` is not represented.

    Raises
    ------
    ValueError
        Naming ``scene``, if its right-hand side depends on the hub's position ``r`` (a
        field that acts on the position).

    Examples
    --------
    >>> from appdyn.dynamics.scene import HingedPanel, RigidHub, Scene
    >>> scene = Scene(RigidHub([2.0, 2.0, 3.0], mass=10.0),
    ...               HingedPanel(2.0, [0.2, 0.2, 0.3], [0, 0, 0.5], [0, 0, 0.2],
    ...                           axis=[0, 0, 1]))
    >>> attitude_subsystem(scene).states
    ('q1', 'q2', 'q3', 'q4', 'w1', 'w2', 'w3', 'theta', 'theta_dot')
    """
    model = scene.model()
    if not scene.hub.translates:
        return model
    names = model.states
    ir = [names.index(s) for s in TRANSLATION[:3]]
    iv = [names.index(s) for s in TRANSLATION[3:]]
    keep = [i for i in range(model.nx) if i not in ir + iv]
    y, u = ca.SX.sym("y", len(keep)), ca.SX.sym("u", model.nu)
    p = ca.SX.sym("p", model.np)
    v = ca.SX.sym("v", 3)
    x = ca.SX.zeros(model.nx)
    for k, i in enumerate(keep):
        x[i] = y[k]
    for k, i in enumerate(iv):
        x[i] = v[k]
    Pb = ca.gradient(model.invariants["energy"](x, p), v)      # dT/dv, affine in v
    J = ca.jacobian(Pb, v)
    vstar = -ca.solve(J, ca.substitute(Pb, v, ca.SX.zeros(3)))
    x = ca.substitute(x, v, vstar)
    xs = ca.SX.sym("x", model.nx)
    if ca.depends_on(model.f(xs, u, p)[keep], xs[ir]):
        raise ValueError("`scene`: its right-hand side depends on the hub's position r, so the "
                         "translation does not decouple from the attitude")
    f = ca.Function(model.name, [y, u, p], [model.f(x, u, p)[keep]], ["x", "u", "p"],
                    ["xdot"])
    invariants = {key: ca.Function(key, [y, p], [fun(x, p)], ["x", "p"], [key])
                  for key, fun in model.invariants.items() if key != "momentum_linear"}
    index = {i: k for k, i in enumerate(keep)}
    states = tuple(names[i] for i in keep)
    return Model(f, states, model.controls, model.params, p_default=model.p_default,
                 units={k: v for k, v in model.units.items() if k not in TRANSLATION},
                 invariants=invariants, name=f"{model.name}_attitude", attitude=(0, 4),
                 layout={k: _shifted(lay, index) for k, lay in model.layout.items()},
                 bounds={k: b for k, b in model.bounds.items() if k not in TRANSLATION})


def _rest_state(scene: Scene, w) -> np.ndarray:
    """`Scene.state` at the hub rate ``w``, in the states of `attitude_subsystem`."""
    x = scene.state(w=w)
    if not scene.hub.translates:
        return x
    drop = {scene.states.index(s) for s in TRANSLATION}
    return np.array([x[i] for i in range(x.size) if i not in drop])


def _indices(model, key: str) -> list:
    """State indices of every part's coordinates (``key='coords'``) or speeds, hub excluded."""
    out = []
    for pname, lay in model.layout.items():
        if pname != "hub":
            out += list(range(model.nx))[getattr(lay, key)]
    return out


@cache.constructs
def spin_point(scene: Scene, axis: np.ndarray, rate: float) -> SpinPoint:
    """The state of ``scene`` spinning at ``rate * axis`` with its parts at rest on the hub
    (``axis``: unit, hub axes; ``rate`` [rad/s]).

    Returns
    -------
    SpinPoint
        Part speeds from `Scene.state`; part coordinates from Newton's method on
        ``part speeds' = 0`` with ``q``, ``w`` and the speeds held (least-squares steps, so
        a part whose coordinates the rest equations do not fix keeps them at rest).
        ``converged`` is False when the residual stays above ``NEWTON_RTOL`` times its scale
        (a spring the centrifugal load overcomes).

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.scene import HeldRotor, RigidHub, Scene
    >>> pt = spin_point(Scene(RigidHub([3.0, 4.0, 5.0]), HeldRotor([1, 0, 0], 2.0)),
    ...                 np.array([1.0, 0.0, 0.0]), 2.0)
    >>> pt.x, pt.converged
    (array([0., 0., 0., 1., 2., 0., 0.]), True)
    """
    model = attitude_subsystem(scene)
    x = _rest_state(scene, rate * np.asarray(axis, dtype=float))
    ic, iv = _indices(model, "coords"), _indices(model, "speeds")
    names = tuple(model.states[i] for i in ic)
    if not ic or not iv:
        return SpinPoint(x, names, 0.0, 0, True)
    c = ca.SX.sym("c", len(ic))
    xs = ca.SX(ca.DM(x))
    for k, i in enumerate(ic):
        xs[i] = c[k]
    g = model.f(xs, ca.DM.zeros(model.nu), ca.DM(model.resolve_p()))[iv]
    fun = ca.Function("spin_rest", [c], [g, ca.jacobian(g, c)])
    cv = x[ic].copy()
    for it in range(NEWTON_MAX_ITER + 1):
        gv, J = (np.asarray(v, dtype=float) for v in fun(cv))
        gv = gv.reshape(-1)
        scale = np.max(np.abs(J), initial=0.0) * max(1.0, np.max(np.abs(cv))) + 1e-300
        res = float(np.max(np.abs(gv), initial=0.0))
        if res <= NEWTON_RTOL * scale or it == NEWTON_MAX_ITER:
            break
        cv = cv + np.linalg.lstsq(J, -gv, rcond=None)[0]
    x[ic] = cv
    return SpinPoint(x, names, res, it, res <= NEWTON_RTOL * scale, tuple(cv.tolist()))


@cache.constructs
def _conserved(model, key: str, x: np.ndarray) -> bool:
    """Whether the invariant ``key`` is conserved by the uncontrolled flow near ``x``:
    ``|d inv/dt| <= _CONSERVED_RTOL |grad| |xdot|`` at three perturbed states."""
    xs = ca.SX.sym("x", model.nx)
    p = ca.DM(model.resolve_p())
    val = model.invariants[key](xs, p)
    jac = ca.jacobian(val, xs)
    xdot = model.f(xs, ca.DM.zeros(model.nu), p)
    fun = ca.Function("conservation", [xs], [ca.mtimes(jac, xdot), jac, xdot])
    rng = np.random.default_rng(0)
    iq = model.attitude[0] if model.attitude else None
    for _ in range(3):
        xp = x + 1e-2 * max(1.0, float(np.max(np.abs(x)))) * rng.standard_normal(x.size)
        if iq is not None:
            xp[iq:iq + 4] /= np.linalg.norm(xp[iq:iq + 4])
        d, J, f = (np.asarray(v, dtype=float) for v in fun(xp))
        bound = _CONSERVED_RTOL * np.max(np.abs(J), initial=0.0) * np.max(np.abs(f), initial=0.0)
        if np.max(np.abs(d), initial=0.0) > bound + 1e-300:
            return False
    return True


@cache.constructs
def _gradients(model, x, key: str, square: bool) -> list:
    """Gradients at ``x`` (full state) of the invariant ``key``'s components, or of
    ``|invariant|^2``."""
    xs = ca.SX.sym("x", model.nx)
    val = model.invariants[key](xs, ca.DM(model.resolve_p()))
    rows = [ca.sumsqr(val)] if square else [val[i] for i in range(val.numel())]
    grad = ca.Function("grad", [xs], [ca.horzcat(*[ca.gradient(r, xs) for r in rows])])
    G = np.asarray(grad(x), dtype=float)
    return [G[:, j] for j in range(G.shape[1])]


def _in_states(model, g: np.ndarray, states) -> np.ndarray:
    """A full-state gradient on the named (non-attitude) states of a linearization."""
    return np.array([g[model.states.index(s)] if s in model.states else 0.0 for s in states])


def _restrict_integrals(model, lin: Linearization, integrals, prefer) -> tuple:
    """Restrict ``lin`` to each first integral in turn, its gradient projected onto the level
    set of those used before; repeats and non-integrals are skipped (with a note). A part's
    integral eliminates a state of ``prefer`` (the parts' states) where it can, so that the
    hub's rates describe the nutation."""
    base = lin.states
    T = np.eye(len(base))  # reduced coordinates -> coordinates of `base`
    red, notes, used = lin, [], 0
    for label, reason, g in integrals:
        full = _in_states(model, g, base)
        c = full @ T
        if np.max(np.abs(full), initial=0.0) == 0 or (
                np.max(np.abs(c), initial=0.0) <= _DEPENDENT_RTOL * np.max(np.abs(full))):
            continue
        own = [i for i, st in enumerate(red.states)
               if label != "|H|^2" and st in prefer and abs(c[i]) > 1e-6 * np.max(np.abs(c))]
        pick = red.states[max(own, key=lambda i: abs(c[i]))] if own else None
        try:
            nxt = red.restrict(c, eliminate=pick, reason=reason)
        except ValueError:
            notes.append(f"{label}: not a first integral of the linear model here; kept")
            continue
        k = next(i for i, s in enumerate(red.states) if s not in nxt.states)
        r = [i for i in range(red.n) if i != k]
        P = np.zeros((red.n, red.n - 1))
        P[r, range(red.n - 1)] = 1.0
        P[k] = -c[r] / c[k]
        T, red, used = T @ P, nxt, used + 1
    return red, notes, used


def reduce_spin(scene: Scene, x, lin: Linearization, axis) -> tuple:
    """Factor the cyclic coordinates out of ``lin`` and restrict it to the first integrals.

    The integrals are those the uncontrolled flow conserves exactly: ``|H|^2``, then the
    parts' invariants, the energy last. Where none applies (a dissipative torque that depends
    on the attitude), the hub's rate about ``axis``, if constant to first order (no torque
    about the axis), is restricted instead.

    Returns
    -------
    (Linearization, list of str)
        The reduced linearization and notes.
    """
    model = attitude_subsystem(scene)
    red = lin
    cyclic = [model.states[i] for i in _indices(model, "coords")]
    scale = max(float(np.max(np.abs(lin.A), initial=0.0)), 1e-300)
    for name in cyclic:
        if name in red.states and np.max(np.abs(red.A[:, red.index(name)])) <= 1e-13 * scale:
            red = red.quotient(name, reason="a cyclic coordinate: nothing depends on it")
    integrals = []
    if "momentum_inertial" in model.invariants and _conserved(model, "momentum_inertial", x):
        integrals += [("|H|^2", "|H|^2 is a first integral; the steady spins form a "
                       "one-parameter family, whose eigenvalue 0 goes", g)
                      for g in _gradients(model, x, "momentum_inertial", True)]
    keys = [k for k in model.invariants if k not in ("quat_norm", "momentum_inertial")]
    for key in sorted(keys, key=lambda k: k == "energy"):  # the energy last
        if not _conserved(model, key, x):
            continue
        for j, g in enumerate(_gradients(model, x, key, False)):
            label = key if key == "energy" else f"{key}[{j}]"
            integrals.append((label, f"{label} is a first integral", g))
    parts = {model.states[i] for i in _indices(model, "coords") + _indices(model, "speeds")}
    red, notes, used = _restrict_integrals(model, red, integrals, parts)
    if used:
        return red, notes
    rates = model.states[model.layout["hub"].speeds]
    c = np.array([axis[rates.index(s)] if s in rates else 0.0 for s in red.states])
    try:
        return red.restrict(c, reason="the spin rate about the axis is constant to first "
                            "order: no torque about it"), notes
    except ValueError:
        return red, notes + ["no first integral with a non-zero gradient: the neutral "
                             "eigenvalue 0 of the spin-rate family stays in the model"]


def spin_groups(model, states) -> dict:
    """Mode labels by part: ``'nutation'`` for the hub's (reduced) states and error angles,
    each part's name for its states (from ``model.layout``)."""
    groups = {}
    for pname, lay in model.layout.items():
        label = HUB_LABEL if pname == "hub" else pname
        own = set(lay.names) | (set(ANGLE_STATES) if pname == "hub" else set())
        groups[label] = [s for s in states if s in own]
    return {k: v for k, v in groups.items() if v}


def _linearize(model, x, frame) -> Linearization:
    """Body-rate linearization, or in the spinning frame when a load depends on the attitude
    or ``frame='spinning'`` (either may be a non-equilibrium: the caller checks)."""
    if frame != "spinning":
        try:
            return linearization(model, x, frame="rates", allow_non_equilibrium=True)
        except ValueError:
            pass
    return linearization(model, x, frame="spinning", allow_non_equilibrium=True)


def _quotient_phase(lin: Linearization, axis) -> Linearization:
    """Factor the spin phase (error angle along ``axis``) out of a spinning-frame model."""
    if lin.frame != "spinning":
        return lin
    n = np.zeros(lin.n)
    for k, s in enumerate(ANGLE_STATES):
        n[lin.index(s)] = axis[k]
    return lin.quotient(n, reason="the spin phase about the axis is cyclic")


def spin_linearization(scene: Scene, axis: np.ndarray, rate: float, *,
                       frame: str | None = None) -> SpinLinearization:
    """Linearize and reduce the steady spin of ``scene`` (module docstring).

    Parameters
    ----------
    scene : Scene
    axis : ndarray, shape (3,)
        Unit spin axis, hub axes.
    rate : float [rad/s]
    frame : {None, 'spinning'}, optional
        ``'spinning'`` keeps the attitude (error angles in the frame spinning with the hub,
        the spin phase factored out) even where the body rates alone would do.

    Returns
    -------
    SpinLinearization

    Raises
    ------
    ValueError
        Naming ``axis``: no relative equilibrium about it (the part coordinates found no rest,
        or the axis is not principal for the loaded body: the residual by state is shown).

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.scene import RigidHub, Scene
    >>> sl = spin_linearization(Scene(RigidHub([2.0, 3.0, 4.5])), np.array([1.0, 0, 0]), 10.0)
    >>> sl.reduced.states, sl.groups
    (('w2', 'w3'), {'nutation': ['w2', 'w3']})
    """
    model = attitude_subsystem(scene)
    point = spin_point(scene, axis, rate)
    where = f"`axis` = {np.round(axis, 12).tolist()} at `rate` = {rate:g} rad/s"
    if not point.converged:
        raise ValueError(
            f"the scene has no relative equilibrium spinning about {where}: the parts find no "
            f"rest (max |{', '.join(point.coordinates)} speeds'| = {point.residual:.3e} after "
            f"{point.iterations} Newton steps; e.g. a spring the centrifugal load overcomes). "
            "Stiffen the part or lower the rate")
    if frame not in (None, "spinning"):
        raise ValueError(f"`frame` must be None or 'spinning', got {frame!r}")
    lin = _linearize(model, point.x, frame)
    if not lin.is_equilibrium:
        raise ValueError(
            f"the scene has no relative equilibrium spinning about {where} with its parts at "
            f"rest on the hub (is `axis` a principal axis of the loaded body?): {lin.notes[0]}")
    red, notes = reduce_spin(scene, point.x, _quotient_phase(lin, axis), axis)
    return SpinLinearization(point, lin, red, tuple(notes), spin_groups(model, red.states))
