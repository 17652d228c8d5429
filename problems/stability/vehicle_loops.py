"""`vehicle_loops`: the pitch and yaw autopilot loops of a thrust-vectored vehicle scene.

The scene (a six-degree-of-freedom `RigidHub` with an `Engine` gimbaled in pitch and yaw,
e.g. `dynamics.scene.launch_vehicle_scene`) is linearized about steady flight along the hub
axis ``x`` at ``velocity`` (attitude at rest, parts at rest); the small attitude angles are
``theta = 2 q2`` (pitch, about ``y``) and ``psi = 2 q3`` (yaw, about ``z``), as the gyros
read them (`dynamics.scene.sensed_attitude`: plus a bending mode's slope at the sensor). The thrust
accelerates the vehicle, so this is not an equilibrium and the linearization depends on the
coordinates: the hub velocity is taken in inertial components ``V = A^T v`` (the states
``v1..v3`` stand for them), as the planar case's ``x_dot, y_dot``, which keeps its frozen
flight condition (``alpha = psi - y_dot / V``, the thrust turning with the attitude) and
makes each axis's loop equal the planar one. Each axis runs
the autopilot of the planar case (`problems.stability.launch_vehicle`):
``dp = -(k_psi theta + k_psidot w2)``, ``dy = -(k_psi psi + k_psidot w3)``. A loop's report
is that axis broken at its deflection with the *other* loop closed (loop-at-a-time margins).

Reduction: the propellant mass (a frozen coordinate, ``m_p' = -mdot`` for every
perturbation) is held; then, repeatedly, a state on which no other state's rate and no sensor
depends (the position, the roll angle and rate, the axial speed, ``q4`` at rest) is factored
out, as the planar case factors out its drift; the reports' notes name them.
"""
from __future__ import annotations

from dataclasses import replace

import casadi as ca
import numpy as np

from appdyn.dynamics import cache
from appdyn.dynamics.scene import check_scene, sensed_attitude
from appdyn.dynamics.scene.engine import gimbaled_engine

from .common import check_number
from .loop import loop

__all__ = ["vehicle_loops"]

_AXES = {"pitch": "dp", "yaw": "dy"}


def _reduce(A, C, states, frozen):
    """Drop the frozen states, then states nothing else depends on (module docstring)."""
    keep = [i for i, s in enumerate(states) if s not in frozen]
    removed = [s for s in states if s in frozen]
    changed = True
    while changed:
        changed = False
        for i in list(keep):
            others = [k for k in keep if k != i]
            if not np.any(A[others, i]) and not np.any(C[:, i]):
                keep.remove(i)
                removed.append(states[i])
                changed = True
    return keep, removed


@cache.constructs
def _sensed_jacobian(scene, model, x0) -> np.ndarray:
    """``d(sensed attitude)/dx`` at ``x0`` (`sensed_attitude`), shape (4, nx)."""
    xs = ca.SX.sym("x", model.nx)
    sensed = ca.Function("C", [xs], [ca.jacobian(sensed_attitude(scene)(xs), xs)])
    return np.asarray(sensed(x0), dtype=float)


@cache.constructs
def _inertial_velocity_jacobians(model, x0):
    """``(A, B)`` at ``x0`` with the hub velocity as inertial components ``V = A(q)^T v``
    (states ``v1..v3`` stand for ``V1..V3``; module docstring)."""
    from appdyn.dynamics.attitude import dcm_from_quat

    zs, us = ca.SX.sym("z", model.nx), ca.SX.sym("u", model.nu)
    iv = [model.states.index(f"v{i}") for i in (1, 2, 3)]
    Aq = dcm_from_quat(zs[0:4])
    v = ca.mtimes(Aq, zs[iv])
    x = ca.vertcat(*[v[iv.index(k)] if k in iv else zs[k] for k in range(model.nx)])
    f = model.f(x, us, ca.DM(0, 1))
    acc = ca.mtimes(Aq.T, f[iv] + ca.cross(x[4:7], v))
    zdot = ca.vertcat(*[acc[iv.index(k)] if k in iv else f[k] for k in range(model.nx)])
    jac = ca.Function("AB", [zs, us], [ca.jacobian(zdot, zs), ca.jacobian(zdot, us)])
    z0 = np.array(x0, dtype=float)
    z0[iv] = np.asarray(dcm_from_quat(z0[0:4])).T @ z0[iv]
    return (np.asarray(M, dtype=float) for M in jac(z0, np.zeros(model.nu)))


def vehicle_loops(scene, *, k_psi, k_psidot, velocity=0.0, engine=None) -> dict:
    """Pitch and yaw autopilot loops of a thrust-vectored vehicle scene (module docstring).

    Parameters
    ----------
    scene : dynamics.scene.Scene
        Six-degree-of-freedom hub with an `Engine` gimbaled in pitch and yaw (``gimbal``).
    k_psi : float [rad/rad]
        Attitude gain of both axes.
    k_psidot : float [rad/(rad/s)]
        Rate gain of both axes.
    velocity : float [m/s], optional
        Flight speed along the hub axis ``x``.
    engine : str, optional
        The engine part's name (needed when the scene has several).

    Returns
    -------
    dict
        ``{"pitch": StabilityReport, "yaw": StabilityReport}``: each the closed loop of both
        axes with its own axis broken for the margins (``margins``), states named as the
        scene's.

    Raises
    ------
    TypeError
        If ``scene`` is not a Scene.
    ValueError
        Naming the argument: an attitude-only hub, an engine without ``gimbal``, a non-finite
        gain or a negative ``velocity``.

    Examples
    --------
    The planar case's rigid vehicle: ``omega_n = sqrt(F l k_psi / I)`` in both axes.

    >>> import math
    >>> from appdyn.dynamics.scene import launch_vehicle_scene
    >>> from appdyn.problems import stability
    >>> scene = launch_vehicle_scene(thrust=2.0e6, inertia=4.0e7, arm=20.0, mass=1.0e5)
    >>> loops = stability.vehicle_loops(scene, k_psi=2.0, k_psidot=2.0)
    >>> loops["yaw"].verdict, round(loops["yaw"].margins.phase_margin, 2)
    ('asymptotically stable', 65.53)
    >>> sorted({round(abs(complex(e)), 6) for e in loops["pitch"].eigenvalues})
    [1.414214]
    """
    import control

    scene = check_scene(scene)
    if not scene.hub.translates:
        raise ValueError("`scene` needs a six-degree-of-freedom hub (RigidHub(..., mass=...))")
    k = check_number(k_psi, "k_psi")
    kd = check_number(k_psidot, "k_psidot")
    V = check_number(velocity, "velocity", nonnegative=True)
    name, part = gimbaled_engine(scene, engine)
    model = scene.model()
    local = scene.variable_names()["local"][name]
    frozen = {local[v.name] for v in part.variables().coords if v.frozen}
    for p, pn in zip(scene.parts, scene.part_names):
        if pn != name:
            frozen |= {scene.variable_names()["local"][pn][v.name]
                       for v in p.variables().coords if v.frozen}
    x0 = scene.state(v=[V, 0.0, 0.0])
    A, B = _inertial_velocity_jacobians(model, x0)
    inputs = {axis: model.controls.index(local[d] if part.actuator is None else local[d + "_c"])
              for axis, d in _AXES.items()}
    out = {}
    C = _sensed_jacobian(scene, model, x0)[[0, 2, 1, 3]]  # pitch angle, rate; yaw
    keep, removed = _reduce(A, C, model.states, frozen)
    A, C = A[np.ix_(keep, keep)], C[:, keep]
    states = [model.states[i] for i in keep]
    K = np.array([[k, kd]])
    for r, axis in enumerate(_AXES):
        other = 1 - r
        b, bo = B[keep, inputs[axis]][:, None], B[keep, inputs[list(_AXES)[other]]][:, None]
        Co = C[2 * other:2 * other + 2]
        A_cl = A - bo @ K @ Co  # the other loop closed
        plant = control.ss(A_cl, b, C[2 * r:2 * r + 2], np.zeros((2, 1)), states=states,
                           inputs=[model.controls[inputs[axis]]],
                           outputs=[f"{axis}_angle", f"{axis}_rate"], name=axis)
        rep = loop(plant, K, title=f"{scene.name or 'vehicle'} {axis} loop")
        note = (f"linearized about steady flight along x at {V:g} m/s (not an equilibrium "
                f"under thrust: the flight condition is frozen); factored out (nothing else "
                f"depends on them) or held (frozen): {', '.join(removed)}; the other loop is "
                "closed in the plant")
        out[axis] = replace(rep, notes=tuple(rep.notes) + (note,))
    return out
