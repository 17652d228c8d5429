"""The closed attitude loop of `problems.gains.spacecraft`: the PD law
``u = -2 kp q_e - kd w`` on `dynamics.rigid_body` with the gains as parameters, its scenarios
(initial attitude errors and rates), and what the verification measures (torque, error angle,
settle time, linearization, the time-optimal reference)."""
from __future__ import annotations

import math
from typing import Mapping, Sequence

import casadi as ca
import numpy as np

from appdyn.dynamics import cache, simulate
from appdyn.dynamics.model import Model
from appdyn.dynamics.scene import ExternalTorque, RigidHub, Scene
from appdyn.dynamics.validate import finite_array, nonnegative

__all__ = ["attitude_loop", "initial_state", "settle_time", "error_angle", "check_scenarios",
           "gain_names", "pd_law", "loop_torque", "linearized_loop", "bang_bang_time",
           "simulate_loop", "spacecraft_scene", "scene_torque_bound", "Q_VECTOR", "Q_SCALAR",
           "RATES"]

#: the rigid spacecraft's state blocks, from the scene layout (never literal indices):
#: the quaternion's vector part, its scalar and the body rates
_SCENE = Scene(RigidHub([1.0, 1.0, 1.0]))
_HUB = _SCENE.layout["hub"]
Q_VECTOR = slice(_HUB.coords.start, _HUB.coords.stop - 1)
Q_SCALAR = _HUB.coords.stop - 1
RATES = _HUB.speeds


def spacecraft_scene(inertia) -> Scene:
    """The rigid spacecraft of the gain design as a scene: a hub and one body torque.

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2], or Scene
        The hub's inertia, or a scene of a hub (attitude only) and at most one
        `ExternalTorque` (the law's torque; a hub alone gets one).

    Returns
    -------
    Scene

    Raises
    ------
    ValueError
        Naming ``inertia``: a scene with a translating hub or other parts (wheels, dampers:
        the PD law acts on the body torque of a rigid spacecraft), or a bad inertia.

    Examples
    --------
    >>> spacecraft_scene([1.0, 2.0, 3.0]).model().controls
    ('L1', 'L2', 'L3')
    """
    if not isinstance(inertia, Scene):
        return Scene(RigidHub(inertia), ExternalTorque())
    others = [type(p).__name__ for p in inertia.parts if not isinstance(p, ExternalTorque)]
    if inertia.hub.translates or others or len(inertia.parts) > 1:
        raise ValueError("`inertia` as a scene must be a rigid spacecraft: an attitude-only "
                         "RigidHub with at most one ExternalTorque; got "
                         f"{'a translating hub' if inertia.hub.translates else 'the parts'} "
                         f"{[type(p).__name__ for p in inertia.parts]}")
    return inertia if inertia.parts else Scene(inertia.hub, ExternalTorque(), name=inertia.name)


def scene_torque_bound(scene: Scene):
    """The ``u_max`` of the scene's `ExternalTorque` (None if unbounded)."""
    return next((p.u_max for p in scene.parts if isinstance(p, ExternalTorque)), None)


# --------------------------------------------------------------------------- input checks
def initial_state(angle, axis, w0=None) -> np.ndarray:
    """The state ``[q1, q2, q3, q4, w1, w2, w3]`` of an attitude error ``angle`` about ``axis``.

    Parameters
    ----------
    angle : float [rad]
        Rotation of the body from the target attitude, ``0 <= angle < pi``.
    axis : array_like, shape (3,)
        Rotation axis (body frame), nonzero; normalized here.
    w0 : array_like, shape (3,), optional
        Body rates [rad/s] (default rest).

    Returns
    -------
    ndarray, shape (7,)
        ``q = [e sin(angle/2), cos(angle/2)]`` (scalar-last, ``q4 > 0``) and ``w0``.

    Raises
    ------
    TypeError, ValueError
        Naming ``angle``, ``axis`` or ``w0``.
    """
    a = nonnegative(angle, "angle")
    if a >= math.pi:
        raise ValueError(f"`angle` must be below pi (180 deg; the law u = -2 kp q_e - kd w "
                         f"needs q4 > 0), got {angle!r}")
    e = finite_array(axis, "axis", (3,))
    if not np.linalg.norm(e) > 0:
        raise ValueError("`axis` must be nonzero")
    e = e / np.linalg.norm(e)
    w = np.zeros(3) if w0 is None else finite_array(w0, "w0", (3,))
    return _SCENE.state(q=np.r_[e * math.sin(a / 2), math.cos(a / 2)], w=w)


def check_scenarios(scenarios) -> tuple[np.ndarray, list[dict]]:
    if isinstance(scenarios, (Mapping, str, bytes)) or not isinstance(scenarios, Sequence):
        raise TypeError("`scenarios` must be a sequence of mappings with 'angle' [rad], "
                        f"'axis' (3,) and optionally 'w0' (3,) [rad/s], got {type(scenarios).__name__}")
    if len(scenarios) < 1:
        raise ValueError("`scenarios` must hold at least one scenario")
    cols, info = [], []
    for k, sc in enumerate(scenarios):
        if not isinstance(sc, Mapping):
            raise TypeError(f"`scenarios[{k}]` must be a mapping with 'angle', 'axis'[, 'w0'], "
                            f"got {type(sc).__name__}")
        unknown = sorted(set(sc) - {"angle", "axis", "w0"})
        missing = sorted({"angle", "axis"} - set(sc))
        if unknown or missing:
            raise ValueError(f"`scenarios[{k}]`: keys are 'angle', 'axis', 'w0'; "
                             f"unknown {unknown}, missing {missing}")
        try:
            x0 = initial_state(sc["angle"], sc["axis"], sc.get("w0"))
        except (TypeError, ValueError) as exc:
            raise type(exc)(f"`scenarios[{k}]`: {exc}") from None
        if not (np.any(x0[Q_VECTOR] != 0) or np.any(x0[RATES] != 0)):
            raise ValueError(f"`scenarios[{k}]` starts at the target at rest (costs nothing)")
        axis = np.asarray(sc["axis"], dtype=float)
        cols.append(x0)
        info.append({"angle": float(sc["angle"]), "axis": axis / np.linalg.norm(axis),
                     "w0": x0[RATES].copy()})
    return np.array(cols).T, info


# ----------------------------------------------------------------------------- the loop
def gain_names(per_axis: bool) -> tuple[str, ...]:
    return ("kp1", "kp2", "kp3", "kd1", "kd2", "kd3") if per_axis else ("kp", "kd")


def pd_law(x, p, per_axis: bool):
    """``u = -2 kp q_e - kd w`` (SX/MX or numbers)."""
    kp, kd = (p[0:3], p[3:6]) if per_axis else (p[0], p[1])
    return -2 * kp * x[Q_VECTOR] - kd * x[RATES]


@cache.constructs
def attitude_loop(inertia, *, per_axis: bool = False) -> Model:
    """The closed loop of the rigid spacecraft (`spacecraft_scene`: ``rigid_body(inertia)``)
    + ``u = -2 kp q_e - kd w``, gains as parameters.

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2], or Scene
        See `spacecraft_scene`.
    per_axis : bool
        Gains ``kp1..3, kd1..3`` (per body axis) instead of ``kp, kd``.

    Returns
    -------
    dynamics.Model
        States ``q1..q4, w1..w3`` (error quaternion w.r.t. the target, scalar-last; body rates
        [rad/s]), no controls, parameters the gains ([N m/rad], [N m s/rad]), ``attitude``
        marker ``(0, 4)``, built in SX.
    """
    scene = spacecraft_scene(inertia)
    body = scene.model()
    names = gain_names(per_axis)
    x, p = ca.SX.sym("x", body.nx), ca.SX.sym("p", len(names))
    torque = next(n for n, part in zip(scene.part_names, scene.parts)
                  if isinstance(part, ExternalTorque))
    u = ca.SX.zeros(body.nu)
    u[scene.layout[torque].controls] = pd_law(x, p, per_axis)
    xdot = body.f(x, u, ca.DM(0, 1))
    f = ca.Function("attitude_pd_loop", [x, ca.SX.sym("u", 0), p], [xdot], ["x", "u", "p"], ["xdot"])
    units = {**{k: v for k, v in dict(body.units).items() if k in body.states},
             **{n: ("N m/rad" if n.startswith("kp") else "N m s/rad") for n in names}}
    return Model(f, body.states, (), names, p_default=np.ones(len(names)), units=units,
                 name="attitude_pd_loop", attitude=body.attitude)


def loop_torque(x: np.ndarray, gains: np.ndarray, per_axis: bool) -> np.ndarray:
    """Torques (3, n) of the law on states (7, n)."""
    if per_axis:
        kp, kd = gains[0:3, None], gains[3:6, None]
    else:
        kp, kd = gains[0], gains[1]
    return -2 * kp * x[Q_VECTOR] - kd * x[RATES]


def error_angle(x) -> np.ndarray:
    """Attitude error angle [rad] in ``[0, pi]`` of states (7, n) (or quaternions (4, n))."""
    x = np.asarray(x, dtype=float)
    return 2 * np.arctan2(np.linalg.norm(x[Q_VECTOR], axis=0), np.abs(x[Q_SCALAR]))


def settle_time(t, angle, band: float) -> float:
    """First time after which ``angle`` stays within ``band`` to the end of ``t``.

    Parameters
    ----------
    t : array_like, shape (n,) [s]
    angle : array_like, shape (n,) [rad]
    band : float [rad]

    Returns
    -------
    float [s]
        ``t[0]`` if always inside; the linearly interpolated last crossing of ``band``;
        ``inf`` if still outside at ``t[-1]``.
    """
    t, a = np.asarray(t, dtype=float), np.asarray(angle, dtype=float)
    out = np.flatnonzero(a > band)
    if out.size == 0:
        return float(t[0])
    i = int(out[-1])
    if i == t.size - 1:
        return float("inf")
    return float(t[i] + (t[i + 1] - t[i]) * (a[i] - band) / (a[i] - a[i + 1]))


@cache.constructs
def linearized_loop(loop: Model, gains: np.ndarray) -> np.ndarray:
    """Jacobian (6, 6) of the loop in ``(q1, q2, q3, w1, w2, w3)`` at the target at rest."""
    x = ca.SX.sym("x", loop.nx)
    jac = ca.Function("loop_jacobian", [x], [ca.jacobian(loop.f(x, ca.DM(0, 1), ca.DM(gains)), x)])
    target = np.zeros(loop.nx)
    target[Q_SCALAR] = 1.0
    J = np.asarray(jac(target), dtype=float)
    keep = [i for i in range(loop.nx) if i != Q_SCALAR]
    return J[np.ix_(keep, keep)]


def bang_bang_time(I: np.ndarray, angle: float, axis: np.ndarray, u_max: np.ndarray) -> float:
    """``2 sqrt(angle / alpha)``, ``alpha = min_i u_max_i / |(J e)_i|`` (the eigenaxis
    rest-to-rest bang-bang time; an order of magnitude for any axis)."""
    Je = np.abs(I @ axis)
    alpha = np.min(u_max[Je > 0] / Je[Je > 0])
    return 2 * math.sqrt(angle / alpha)


def simulate_loop(loop, x0, gains, t):
    """The loop from ``x0`` under ``gains`` on ``t`` (CVODES, tight local tolerances); when
    CVODES gives up, ``auto`` at the same tolerances (its answer verified), whose result is
    returned when it succeeds (else CVODES', which says where and why it failed).

    CVODES gave up (``CV_REPTD_RHSFUNC_ERR`` near t = 15.2 s, its own step producing a
    non-finite state) on a slew about ``(2.3e-175, -1, 9.4e-167)``, where the components of
    ~1e-169 it carried were all that stood for the two other axes; ``auto`` runs it to the
    end, 4.5e-167 from its run about ``(0, -1, 0)`` and 2.8e-9 from CVODES' (found by the
    random valid inputs).

    Examples
    --------
    >>> import numpy as np
    >>> loop = attitude_loop([2.71153947, 1.0, 2.70250077])
    >>> x0 = initial_state(0.99999, [2.33577719e-175, -1.0, 9.40160007e-167])
    >>> sim = simulate_loop(loop, x0, np.array([0.952, 1.020]), np.linspace(0, 30, 61))
    >>> sim.success, sim.method
    (True, 'rk8')
    """
    sim = simulate(loop, x0, t, p=gains, method="cvodes", rtol=1e-10, atol=1e-12)
    if sim.success:
        return sim
    again = simulate(loop, x0, t, p=gains, rtol=1e-10, atol=1e-12)
    return again if again.success else sim


# ----------------------------------------------------------------------------- the design
