"""The hub of a scene: `RigidHub` (attitude only, or six degrees of freedom)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..validate import check_inertia, finite_array, positive
from .contract import Variable

__all__ = ["RigidHub"]


@dataclass(frozen=True, init=False)
class RigidHub:
    """The rigid hub every part of a `Scene` is mounted on.

    Without ``mass`` the hub turns about a fixed reference point (its mass centre, taken to
    stay at the system's): states ``q1..q4`` (scalar-last quaternion, inertial -> hub) and
    ``w1..w3`` (hub angular velocity [rad/s], hub axes): Euler's law ``H' + w x H = L`` with
    the kinematics ``q' = -1/2 Wbar(w) q`` (seed Eqs. 4.70, 4.147). With ``mass`` it has six
    degrees of freedom: ``r1..r3`` (inertial position of the reference point [m]) and
    ``v1..v3`` (its velocity [m/s] in hub axes), the Boltzmann-Hamel form of seed
    Eqs. 6.19-6.20 (``m (v' + w x v) = F`` about the mass centre); with ``reference`` a hub
    point other than the mass centre, Euler's law about that point (seed 000, Eqs.
    6.43-6.46) -- the assembly derives both from the same momenta, so it writes them once.

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2]
        About the hub's mass centre, hub axes (products of inertia with the seed's sign).
        Parts say what they add (reaction wheels: their transverse moments belong here).
    mass : float [kg], optional
        Hub mass; makes the hub six-degree-of-freedom.
    reference : array_like, shape (3,) [m], optional
        The reference point (whose position and velocity are the states) from the hub's
        mass centre, hub axes. Needs ``mass``.
    reference_rate : array_like, shape (3,) [rad/s], optional
        Refer the attitude to a frame turning at this constant rate ``Omega`` with respect
        to inertial space (its own axes: ``(0, 0, Omega_E)`` for the Earth-fixed frame, the
        orbit rate for an LVLH frame of a circular orbit; seed 000 Eq. 6.42): ``q`` is then
        reference frame -> hub, ``q' = -1/2 Wbar(w - A(q) Omega) q``, and ``r`` (six degrees of
        freedom) is the position in that frame, ``r' = A^T v - Omega x r``. ``w`` and ``v``
        stay absolute (hub axes), so Euler's law is unchanged; ``frame.dcm`` is reference ->
        hub (``frame.reference_rate`` tells the parts: `GravityGradient` keeps its orbit
        inertial, `Aerodynamics` takes the air at rest in the turning frame, a `TiltTorque`
        direction is fixed in it), and the ``momentum_inertial`` and ``momentum_linear``
        invariants are in the reference frame's axes (they turn there at ``-Omega``:
        ``H' = -Omega x H``).

    Raises
    ------
    ValueError
        Naming the argument: bad ``inertia`` (`dynamics.validate.check_inertia`), a
        non-positive ``mass``, a ``reference`` not of 3 finite numbers or given without
        ``mass``, a ``reference_rate`` not of 3 finite numbers.

    Examples
    --------
    >>> from appdyn.dynamics.scene import RigidHub, Scene
    >>> Scene(RigidHub([1.0, 2.0, 3.0])).model().states
    ('q1', 'q2', 'q3', 'q4', 'w1', 'w2', 'w3')
    >>> Scene(RigidHub([1.0, 2.0, 3.0], mass=10.0)).model().nx
    13

    Attitude referred to the Earth-fixed frame: at rest there (``w = A Omega``), ``q`` stays:

    >>> hub = RigidHub([1.0, 2.0, 3.0], reference_rate=[0.0, 0.0, 7.2921159e-5])
    >>> scene = Scene(hub)
    >>> (scene.model().rhs(scene.state(w=[0.0, 0.0, 7.2921159e-5]))[:4] + 0.0).tolist()
    [0.0, 0.0, 0.0, 0.0]
    """

    inertia: tuple
    mass: float | None
    reference: tuple
    reference_rate: tuple | None

    def __init__(self, inertia, *, mass=None, reference=None, reference_rate=None):
        I = check_inertia(inertia)
        m = None if mass is None else positive(mass, "mass")
        if reference is not None and m is None:
            raise ValueError("`reference` needs `mass`: a reference point other than the mass "
                             "centre only matters when the hub translates")
        ref = (0.0, 0.0, 0.0) if reference is None else tuple(
            finite_array(reference, "reference", (3,)).tolist())
        object.__setattr__(self, "inertia", tuple(np.asarray(I, float).reshape(-1).tolist()))
        object.__setattr__(self, "mass", m)
        object.__setattr__(self, "reference", ref)
        object.__setattr__(self, "reference_rate", None if reference_rate is None else tuple(
            finite_array(reference_rate, "reference_rate", (3,)).tolist()))

    @property
    def inertia_matrix(self) -> np.ndarray:
        """``inertia`` as a (3, 3) array [kg m^2]."""
        return np.array(self.inertia).reshape(3, 3)

    @property
    def translates(self) -> bool:
        """Whether the hub has six degrees of freedom."""
        return self.mass is not None

    def variables(self):
        """Coordinates ``q`` (and ``r``) and speeds ``w`` (and ``v``), as `Variable`."""
        coords = [Variable(f"q{i}", "-", 1.0 if i == 4 else 0.0, terminal="free")
                  for i in range(1, 5)]
        speeds = [Variable(f"w{i}", "rad/s") for i in range(1, 4)]
        if self.translates:
            coords += [Variable(f"r{i}", "m", terminal="free") for i in range(1, 4)]
            speeds += [Variable(f"v{i}", "m/s", terminal="free") for i in range(1, 4)]
        return tuple(coords), tuple(speeds)
