"""A free-free body bending mode in mean axes that carries parts: `BendingMode`.

One given mode of the structure (modal synthesis, seed Ch. 6, Eqs. 6.33-6.41) bends it in
each of its planes: the plane spanned by the structure's ``axis`` and a transverse
``direction`` ``d``, with normal ``n = axis x d``. Its coordinate ``eta`` [m] scales a
dimensionless shape ``phi(s)``; slopes ``sigma = dphi/ds`` [rad/m]. A symmetric vehicle bends
alike in its two transverse planes (the default: ``d = y`` with ``n = z``, and ``d = z``
with ``n = -y``), each plane with its own states ``eta, eta_dot`` and the same modal mass
``M_b``, frequency ``omega_b`` and damping ratio ``zeta_b``::

    M_b (eta'' + 2 zeta_b omega_b eta' + omega_b^2 eta) = Q_eta.

Mean axes: the mode carries no linear or angular momentum (``int phi dm = 0``,
``int s phi dm = 0``), so it has no inertial coupling with the rigid motion. It is written as
a pseudo-body per plane with angular velocity ``eta' d`` and angular momentum
``M_b eta' d`` (no mass, no linear momentum): Kane's sum along ``eta'`` is
``d . (M_b eta'' d + w x M_b eta' d) = M_b eta''`` exactly, its partial velocities along the
hub's speeds are zero, its kinetic energy is ``1/2 M_b eta'^2``, and it adds nothing to the
momentum invariants. The strain potential is ``1/2 M_b omega_b^2 eta^2``; spring and damping
act as the force ``-M_b (omega_b^2 eta + 2 zeta_b omega_b eta')`` on ``eta'``.

Parts on the mode: its body frame is the section at ``station`` (a point of the parent, from
the hub's mass centre; the gimbal): its origin is displaced ``phi_g eta d`` and its axes turned
by ``sigma_g eta`` about ``n`` (plane by plane, in the order of ``directions``). A part on it
(``Engine(..., parent="bending")`` at ``(0, 0, 0)``) has its point and its direction move with
the mode, and its load excites the mode through the partial velocity ``phi_g d``: the thrust's
``F . phi_g d``, the planar model's ``F phi_g sin(sigma_g eta - delta)``
(`dynamics.launch_vehicle`).

The sensor: the gyros at a station of slope ``sigma_s`` read the parent's attitude turned by
``sigma_s eta`` about ``n``: the invariants ``gyro_tilt = sigma_s sum eta n`` [rad] and
``gyro_tilt_rate = sigma_s sum eta' n`` [rad/s] (hub axes) are what they add to the hub's
small attitude angles and to its rate (`dynamics.scene.rocket.sensed_attitude`).
"""
from __future__ import annotations

from dataclasses import KW_ONLY, dataclass

import casadi as ca
import numpy as np

from ..validate import finite_array
from .contract import Body, Contribution, Load, Part, PartVariables, Variable
from .dampers import real_number, unit_vector

__all__ = ["BendingMode", "axis_rotation"]


def axis_rotation(axis, angle) -> ca.SX:
    """The rotation matrix turning by ``angle`` [rad] about the unit ``axis`` (Rodrigues).

    Parameters
    ----------
    axis : array_like, shape (3,)
        A unit vector.
    angle : float or SX
        Right-handed about ``axis``.

    Returns
    -------
    SX, 3x3

    Examples
    --------
    >>> import math
    >>> import casadi as ca
    >>> from appdyn.dynamics.scene.bending import axis_rotation
    >>> R = ca.DM(axis_rotation((0.0, 0.0, 1.0), math.pi / 2))
    >>> [round(float(v), 12) + 0.0 for v in R[:, 0].full().ravel()]  # x turns into y
    [0.0, 1.0, 0.0]
    """
    n = ca.DM(axis)
    skew = ca.DM([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]],
                  [-axis[1], axis[0], 0.0]])
    return (ca.cos(angle) * ca.SX.eye(3) + ca.sin(angle) * skew
            + (1.0 - ca.cos(angle)) * ca.mtimes(n, n.T))


@dataclass(frozen=True)
class BendingMode(Part):
    """One free-free body bending mode per transverse plane, mean axes, carrying parts.

    Parameters
    ----------
    generalized_mass : float [kg]
        ``M_b > 0`` (``int phi^2 dm``).
    frequency : float [rad/s]
        ``omega_b > 0``.
    damping_ratio : float, optional
        ``zeta_b >= 0``.
    station : array_like, shape (3,) [m], optional
        The section the parts on the mode sit at (the gimbal), a point of the parent from the
        hub's mass centre.
    deflection : float [-], optional
        ``phi_g``: the section's displacement along ``d`` per unit ``eta``.
    slope : float [rad/m], optional
        ``sigma_g``: the section's turn about ``n`` per unit ``eta``.
    sensor_slope : float [rad/m], optional
        ``sigma_s``: the gyros' turn about ``n`` per unit ``eta``.
    axis : array_like, shape (3,), optional
        The structure's long axis (default ``+x``).
    directions : array_like, shape (k, 3), optional
        The bending directions, unit and normal to ``axis`` (default ``y`` and ``z``).
    parent : str, optional
        The scene name of the part it sits on (None: the hub).
    name : str, optional

    Notes
    -----
    States ``eta, eta_dot`` [m, m/s] for one plane, ``eta1, eta2, eta1_dot, eta2_dot`` for
    two; invariants ``gyro_tilt``, ``gyro_tilt_rate`` (module docstring).

    Raises
    ------
    ValueError
        Naming the argument: a non-positive mass or frequency, a negative damping ratio, a
        non-finite slope or deflection, a bad point, axis or direction (not unit-normal to
        ``axis``).

    Examples
    --------
    A free hub with the mode: ``eta'' = -omega_b^2 eta`` whatever the hub does.

    >>> from appdyn.dynamics.scene import BendingMode, RigidHub, Scene
    >>> scene = Scene(RigidHub([1.0, 2.0, 3.0], mass=5.0), BendingMode(2.0, 3.0))
    >>> model = scene.model()
    >>> model.states[13:]
    ('eta1', 'eta2', 'eta1_dot', 'eta2_dot')
    >>> x = scene.state(w=[0.1, 0.2, 0.3])
    >>> x[13:15] = [0.01, -0.02]
    >>> [round(float(v), 12) for v in model.rhs(x, [])[15:]]  # -9 eta
    [-0.09, 0.18]
    """

    generalized_mass: float
    frequency: float
    _: KW_ONLY
    damping_ratio: float = 0.0
    station: tuple = (0.0, 0.0, 0.0)
    deflection: float = 0.0
    slope: float = 0.0
    sensor_slope: float = 0.0
    axis: tuple = (1.0, 0.0, 0.0)
    directions: tuple = ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    parent: str | None = None
    name: str | None = None

    kind = "bending"
    carries_parts = True

    def __post_init__(self):
        setf = object.__setattr__
        for f in ("generalized_mass", "frequency"):
            setf(self, f, real_number(getattr(self, f), f, positive=True))
        setf(self, "damping_ratio", real_number(self.damping_ratio, "damping_ratio",
                                                nonnegative=True))
        for f in ("deflection", "slope", "sensor_slope"):
            setf(self, f, real_number(getattr(self, f), f))
        setf(self, "station", tuple(finite_array(self.station, "station", (3,)).tolist()))
        a = unit_vector(self.axis, "axis")
        setf(self, "axis", tuple(a.tolist()))
        try:
            dirs = np.atleast_2d(np.asarray(self.directions, dtype=float))
        except (TypeError, ValueError):
            dirs = np.zeros((0, 0))
        if dirs.ndim != 2 or dirs.shape[1] != 3 or not 1 <= dirs.shape[0] <= 2:
            raise ValueError("`directions` must be one or two 3-vectors, got "
                             f"{self.directions!r}")
        units = [unit_vector(d, "directions") for d in dirs]
        if any(abs(float(d @ a)) > 1e-12 for d in units) or (
                len(units) == 2 and abs(float(units[0] @ units[1])) > 1e-12):
            raise ValueError("`directions` must be normal to `axis` and to each other, got "
                             f"{self.directions!r}")
        setf(self, "directions", tuple(tuple(d.tolist()) for d in units))

    @property
    def normals(self) -> tuple:
        """The planes' normals ``n = axis x d`` (turning axes of the slopes)."""
        return tuple(tuple(np.cross(self.axis, d).tolist()) for d in self.directions)

    def _names(self) -> tuple:
        k = len(self.directions)
        return ("eta",) if k == 1 else tuple(f"eta{i + 1}" for i in range(k))

    def variables(self) -> PartVariables:
        names = self._names()
        return PartVariables(coords=tuple(Variable(n, "m") for n in names),
                             speeds=tuple(Variable(n + "_dot", "m/s") for n in names))

    def body_frame(self, frame, own):
        """The section at ``station``: displaced ``phi_g eta d``, turned ``sigma_g eta``
        about ``n`` (module docstring); parts on it give their points from the section."""
        eta, rate = own.coords, own.speeds
        R, w_rel = ca.SX.eye(3), ca.SX.zeros(3)
        shift, v_rel = ca.SX.zeros(3), ca.SX.zeros(3)
        for i, (d, n) in enumerate(zip(self.directions, self.normals)):
            w_rel = w_rel + ca.mtimes(R, ca.DM(n)) * (self.slope * rate[i])
            R = ca.mtimes(R, axis_rotation(n, self.slope * eta[i]))
            shift = shift + self.deflection * eta[i] * ca.DM(d)
            v_rel = v_rel + self.deflection * rate[i] * ca.DM(d)
        return frame.child(R, frame.point(self.station) + shift, w_rel, v_rel)

    def contribute(self, frame, own) -> Contribution:
        eta, rate = own.coords, own.speeds
        M, w, z = self.generalized_mass, self.frequency, self.damping_ratio
        bodies, loads = [], []
        tilt, tilt_rate = ca.SX.zeros(3), ca.SX.zeros(3)
        for i, (d, n) in enumerate(zip(self.directions, self.normals)):
            spin = rate[i] * ca.DM(d)
            bodies.append(Body(velocity=ca.SX.zeros(3), angular_velocity=spin,
                               momentum=ca.SX.zeros(3), angular_momentum=M * spin,
                               position=frame.point(self.station)))
            loads.append(Load(-M * (w ** 2 * eta[i] + 2.0 * z * w * rate[i]), rate[i]))
            tilt = tilt + self.sensor_slope * eta[i] * ca.DM(n)
            tilt_rate = tilt_rate + self.sensor_slope * rate[i] * ca.DM(n)
        if not frame.is_hub:
            tilt, tilt_rate = ca.mtimes(frame.to_hub, tilt), ca.mtimes(frame.to_hub, tilt_rate)
        # the scene's suffix of this mode's names ("_2"), to keep two modes' invariants apart
        first = self._names()[0]
        suffix = eta[0].name()[len(first):] if eta[0].is_symbolic() else ""
        return Contribution(bodies=bodies, loads=loads,
                            potential=0.5 * M * w ** 2 * ca.sumsqr(eta),
                            momentum=ca.SX.zeros(3),
                            invariants={"gyro_tilt" + suffix: tilt,
                                        "gyro_tilt_rate" + suffix: tilt_rate})
