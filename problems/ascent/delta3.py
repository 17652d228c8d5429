"""Delta III-class four-phase launch vehicle ascent: data, dynamics, target orbit, guesses.

The standard multi-phase benchmark of Benson (2005, MIT PhD thesis), Betts (2010, *Practical
Methods for Optimal Control and Estimation Using Nonlinear Programming*, 2nd ed., Example
6.15), Rao et al. (2010, GPOPS, ACM TOMS 37(2)) and Patterson & Rao (2014, GPOPS-II, ACM TOMS
41(1), "Multiple-Stage Launch Vehicle Ascent"), also shipped as the yapss example
``delta_iii_ascent`` and the PSOPT example ``launch.cxx``. This module states the problem (no
optimization): the per-phase `dynamics.Model`, the data, the target orbit, bounds and an
initial guess. Units are SI throughout (m, s, kg, N, rad).

Dynamics (Earth-centred inertial frame, z along the spin axis)
--------------------------------------------------------------
State ``x = [rx, ry, rz, vx, vy, vz, m]`` (position [m], inertial velocity [m/s], mass [kg]),
control ``u = [ux, uy, uz]``, the thrust direction (``|u| = 1`` is a path constraint of the
problem, as in GPOPS-II; the model uses ``u`` as given, so ``T u`` is the thrust)::

    r' = v
    v' = -mu r / |r|^3 + (T u - D) / m
    m' = -mdot                      (mdot = T / (g0 Isp) > 0, constant per phase)

Drag acts against the velocity relative to the rotating atmosphere::

    v_rel = v - omega_E x r,   omega_E = [0, 0, OMEGA_E]
    rho   = RHO0 exp(-h / H_SCALE),   h = |r| - RE
    D     = 1/2 CD S_REF rho |v_rel| v_rel

``|v_rel|`` is evaluated as ``sqrt(v_rel . v_rel + V_REL_EPS^2)`` with ``V_REL_EPS = 1e-3``
m/s: the vehicle starts at rest in the atmosphere (``v_rel = 0``), where the derivative of
``sqrt`` is infinite and CasADi would return NaN sensitivities (yapss adds 1e-100 under the
root and ASSET perturbs the initial velocity for the same reason). The change in drag is
below ``V_REL_EPS^2 / (2 |v_rel|^2)`` relative (5e-11 at 100 m/s) and drag at rest stays
exactly zero.

Data (Betts 2010; GPOPS-II; yapss; PSOPT -- all four agree)
-----------------------------------------------------------
mu = 3.986012e14 m^3/s^2, R_E = 6378145 m, omega_E = 7.29211585e-5 rad/s, g0 = 9.80665
m/s^2, rho0 = 1.225 kg/m^3, H = 7200 m, C_D = 0.5, S = 4 pi m^2; launch from latitude
28.5 deg (longitude 0 in ECI at t = 0) at rest relative to the rotating Earth.

=====================  =========  ==========  ==========
                       SRB (x9)   stage 1     stage 2
=====================  =========  ==========  ==========
total mass [kg]        19290      104380      19300
propellant [kg]        17010      95550       16820
dry mass [kg]          2280       8830        2480
thrust [N]             628500     1083100     110094
burn time [s]          75.2       261         700
Isp [s] (derived)      283.33364  301.68776   467.21311
=====================  =========  ==========  ==========

Payload 4164 kg; launch mass 301454 kg. ``Isp = T tau / (m_prop g0)`` so that each motor
burns exactly its propellant in its burn time (the codes of GPOPS-II, PSOPT, yapss and
ASSET all do this; ASSET lists 283.33364 / 301.68 / 467.21 s, while tables copied from the
GPOPS-II example print rounded Isp 284 / 301.7 / 462.4 s, whose last value is not
consistent with the 700 s burn). Phases: (0) six SRBs + stage 1,
0 -> 75.2 s, then six SRB dry masses are dropped; (1) three SRBs + stage 1, 75.2 -> 150.4
s, three SRB dry masses dropped; (2) stage 1 alone, 150.4 -> 261 s, stage-1 dry mass
dropped; (3) stage 2, from 261 s to a free final time <= 961 s.

Target orbit (GTO): a = 24361140 m, e = 0.7308, i = 28.5 deg, RAAN = 269.8 deg, argument of
perigee = 130.5 deg; true anomaly free.

Published optimum (maximum final mass)
--------------------------------------
* Betts (2010): m(tf) = 7529.712412 kg at tf = 924.139 s (the last phase, index 3, lasts 663.139 s), as
  quoted to those digits by independent reproductions (a JuMP/Ipopt implementation compares
  against ``tbt_betts = 924.139``, ``mf_betts = 7529.712412``).
* yapss (its example test of ``yapss.examples.delta_iii_ascent``): 7529.712287 kg (Ipopt).
* ASSET (Alabama ASRL, ``doc/examples/Delta3.rst``): 7529.749 kg, "effectively the same as
  that given by Betts (7529.712 kg)".

Terminal conditions: `orbit_residuals`
--------------------------------------
GPOPS-II, PSOPT and yapss impose the five elements computed with ``acos`` plus quadrant
fixes (yapss: ``Omega = 360 - acos(n_x / n)``, valid because the target RAAN is in
(180, 360) deg; PSOPT blends both branches with a smooth Heaviside). `orbit_residuals` uses
no ``acos`` and no branch: each angle residual is the ``atan2`` of the element's cosine and
sine *rotated by the target angle*, i.e. ``wrap(angle - target)`` into (-pi, pi], which is
smooth everywhere except 180 deg away from the target, and well conditioned at the target
(``acos`` has an infinite slope at 0 and 180 deg). See its docstring.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from types import MappingProxyType
from typing import NamedTuple

import casadi as ca
import numpy as np

from appdyn.dynamics import cache
from appdyn.dynamics.model import Model, model_from_expressions
from appdyn.dynamics.validate import finite_array, finite_scalar, integer, is_symbolic, positive

__all__ = [
    "CD", "CONTROLS", "FINAL_MASS_BETTS", "FINAL_MASS_YAPSS", "FINAL_TIME_BETTS", "G0",
    "H_SCALE", "LAUNCH_LATITUDE", "LAUNCH_MASS", "MU", "N_SRB", "OMEGA_E", "OrbitalElements",
    "PAYLOAD_MASS", "PHASES", "PhaseData", "RE", "RHO0", "SRB_BURN_TIME", "SRB_DRY",
    "SRB_ISP", "SRB_MASS", "SRB_PROPELLANT", "SRB_THRUST", "STAGE1_BURN_TIME", "STAGE1_DRY",
    "STAGE1_ISP", "STAGE1_MASS", "STAGE1_PROPELLANT", "STAGE1_THRUST", "STAGE2_BURN_TIME",
    "STAGE2_DRY", "STAGE2_ISP", "STAGE2_MASS", "STAGE2_PROPELLANT", "STAGE2_THRUST", "STATES",
    "S_REF", "TARGET_ORBIT", "V_MAX", "V_REL_EPS", "delta3_model", "drag_force", "guess",
    "initial_state", "orbit_residuals", "orbital_elements", "phase_bounds", "state_from_elements"
]

# ----------------------------------------------------------------- Earth and atmosphere
MU = 3.986012e14            # gravitational parameter [m^3/s^2]
RE = 6378145.0              # equatorial radius [m]
OMEGA_E = 7.29211585e-5     # rotation rate [rad/s]
RHO0 = 1.225                # sea-level density [kg/m^3]
H_SCALE = 7200.0            # density scale height [m]
G0 = 9.80665                # standard gravity (Isp reference) [m/s^2]
CD = 0.5                    # drag coefficient [-]
S_REF = 4.0 * math.pi       # reference area [m^2]
V_REL_EPS = 1e-3            # regularization of |v_rel| at rest [m/s] (module docstring)
LAUNCH_LATITUDE = math.radians(28.5)  # Cape Canaveral, geocentric [rad]

# ----------------------------------------------------------------------------- vehicle
N_SRB = 9
SRB_MASS, SRB_PROPELLANT, SRB_THRUST, SRB_BURN_TIME = 19290.0, 17010.0, 628500.0, 75.2
STAGE1_MASS, STAGE1_PROPELLANT, STAGE1_THRUST, STAGE1_BURN_TIME = 104380.0, 95550.0, 1083100.0, 261.0
STAGE2_MASS, STAGE2_PROPELLANT, STAGE2_THRUST, STAGE2_BURN_TIME = 19300.0, 16820.0, 110094.0, 700.0
PAYLOAD_MASS = 4164.0
SRB_DRY = SRB_MASS - SRB_PROPELLANT               # 2280 kg
STAGE1_DRY = STAGE1_MASS - STAGE1_PROPELLANT      # 8830 kg
STAGE2_DRY = STAGE2_MASS - STAGE2_PROPELLANT      # 2480 kg
SRB_ISP = SRB_THRUST * SRB_BURN_TIME / (SRB_PROPELLANT * G0)              # 283.33364 s
STAGE1_ISP = STAGE1_THRUST * STAGE1_BURN_TIME / (STAGE1_PROPELLANT * G0)  # 301.68776 s
STAGE2_ISP = STAGE2_THRUST * STAGE2_BURN_TIME / (STAGE2_PROPELLANT * G0)  # 467.21311 s
LAUNCH_MASS = PAYLOAD_MASS + STAGE2_MASS + STAGE1_MASS + N_SRB * SRB_MASS  # 301454 kg

# ------------------------------------------------------------------ published optimum
FINAL_MASS_BETTS = 7529.712412  # [kg] Betts (2010)
FINAL_TIME_BETTS = 924.139      # [s] Betts (2010): the last phase (index 3) ends here
FINAL_MASS_YAPSS = 7529.712287  # [kg] yapss example test

V_MAX = 10000.0  # velocity component bound of GPOPS-II / PSOPT / yapss [m/s]

STATES = ("rx", "ry", "rz", "vx", "vy", "vz", "m")
CONTROLS = ("ux", "uy", "uz")

TARGET_ORBIT = MappingProxyType({
    "a": 24361140.0,               # semi-major axis [m]
    "e": 0.7308,                   # eccentricity [-]
    "i": math.radians(28.5),       # inclination [rad]
    "raan": math.radians(269.8),   # right ascension of the ascending node [rad]
    "argp": math.radians(130.5),   # argument of perigee [rad]
})
"""The terminal GTO of the benchmark (all sources agree); the true anomaly is free."""


@dataclass(frozen=True)
class PhaseData:
    """One phase of the ascent: what burns, for how long, and what is dropped after it.

    Parameters
    ----------
    name : str
        What burns (``"6 SRB + stage 1"``).
    t_start : float [s]
        Phase start time.
    t_end : float or None [s]
        Phase end time; ``None`` when free (the last phase), bounded by ``t_end_max``.
    t_end_max : float [s]
        Latest end time (``t_end`` when fixed; for the last phase the burn-out time).
    thrust : float [N]
        Total vacuum thrust of the burning motors.
    mass_flow : float [kg/s]
        Total propellant mass flow, positive (``m' = -mass_flow``).
    mass_start : float [kg]
        Vehicle mass at the start of the phase (known: the burn is not throttled).
    dry_mass_dropped : float [kg]
        Dry mass jettisoned at the END of the phase (the next phase starts without it).
    """

    name: str
    t_start: float
    t_end: float | None
    t_end_max: float
    thrust: float
    mass_flow: float
    mass_start: float
    dry_mass_dropped: float

    @property
    def isp(self) -> float:
        """Effective specific impulse of the phase, ``thrust / (G0 mass_flow)`` [s]."""
        return self.thrust / (G0 * self.mass_flow)

    @property
    def mass_end_min(self) -> float:
        """Mass at ``t_end_max`` (the least mass the phase can reach) [kg]."""
        return self.mass_start - self.mass_flow * (self.t_end_max - self.t_start)


def _phases() -> tuple[PhaseData, ...]:
    srb_flow, flow1 = SRB_PROPELLANT / SRB_BURN_TIME, STAGE1_PROPELLANT / STAGE1_BURN_TIME
    spec = (("6 SRB + stage 1", 0.0, SRB_BURN_TIME, 6 * SRB_THRUST + STAGE1_THRUST,
             6 * srb_flow + flow1, 6 * SRB_DRY),
            ("3 SRB + stage 1", SRB_BURN_TIME, 2 * SRB_BURN_TIME, 3 * SRB_THRUST + STAGE1_THRUST,
             3 * srb_flow + flow1, 3 * SRB_DRY),
            ("stage 1", 2 * SRB_BURN_TIME, STAGE1_BURN_TIME, STAGE1_THRUST, flow1, STAGE1_DRY),
            ("stage 2", STAGE1_BURN_TIME, None, STAGE2_THRUST,
             STAGE2_PROPELLANT / STAGE2_BURN_TIME, 0.0))
    phases, mass = [], LAUNCH_MASS
    for name, t0, t1, thrust, flow, dropped in spec:
        t_max = STAGE1_BURN_TIME + STAGE2_BURN_TIME if t1 is None else t1
        phase = PhaseData(name, t0, t1, t_max, thrust, flow, mass, dropped)
        phases.append(phase)
        mass = phase.mass_end_min - dropped
    return tuple(phases)


PHASES = _phases()
"""The four `PhaseData` (phase index 0..3)."""


def _check_phase(phase) -> int:
    phase = integer(phase, "phase", minimum=0)
    if phase > 3:
        raise ValueError(f"`phase` must be 0, 1, 2 or 3 (four phases), got {phase}")
    return phase


# ------------------------------------------------------------------------------ model
def _components(x, name):
    """``x`` as three components (floats, (n,) arrays or CasADi scalars) and a kind flag."""
    if isinstance(x, (ca.SX, ca.MX)):
        if x.numel() != 3 or not (x.is_column() or x.is_row()):
            raise ValueError(f"`{name}` must be a 3-vector, got a CasADi {x.shape}")
        return [x[k] for k in range(3)], True
    a = finite_array(x, name, (3,), batch=True)
    if a.ndim > 2:
        raise ValueError(f"`{name}` must have shape (3,) or (3, n), got {a.shape}")
    return [float(c) for c in a] if a.ndim == 1 else [a[k] for k in range(3)], False


def _drag(r, v, symbolic: bool) -> list:
    """Drag components for lists of three position / velocity components."""
    vrel = [v[0] + OMEGA_E * r[1], v[1] - OMEGA_E * r[0], v[2]]
    sqrt, exp = (ca.sqrt, ca.exp) if symbolic else (np.sqrt, np.exp)
    rad = sqrt(r[0] ** 2 + r[1] ** 2 + r[2] ** 2)
    speed = sqrt(vrel[0] ** 2 + vrel[1] ** 2 + vrel[2] ** 2 + V_REL_EPS ** 2)
    k = 0.5 * CD * S_REF * RHO0 * exp(-(rad - RE) / H_SCALE) * speed
    return [k * c for c in vrel]


def drag_force(r, v):
    """Aerodynamic drag on the vehicle, as the model applies it (the term ``- D / m`` of ``v'``).

    ``D = 1/2 CD S_REF rho(h) sqrt(v_rel . v_rel + V_REL_EPS^2) v_rel`` with ``v_rel = v -
    omega_E x r`` and ``rho = RHO0 exp(-(|r| - RE) / H_SCALE)``.

    Parameters
    ----------
    r, v : casadi.SX, casadi.MX (3 elements), or array_like, shape (3,) or (3, n)
        Inertial position [m] and velocity [m/s].

    Returns
    -------
    casadi.SX or casadi.MX, shape (3, 1), or numpy.ndarray, shape (3,) or (3, n) [N]
    """
    rc, sym_r = _components(r, "r")
    vc, sym_v = _components(v, "v")
    rows = _drag(rc, vc, sym_r or sym_v)
    return ca.vertcat(*rows) if (sym_r or sym_v) else np.array(rows, dtype=float)


@cache.memoize
def _delta3_model(phase: int, normalized: bool = False) -> Model:
    data = PHASES[phase]
    xs = {name: ca.SX.sym(name) for name in STATES}
    us = {name: ca.SX.sym(name) for name in CONTROLS}
    r = [xs["rx"], xs["ry"], xs["rz"]]
    v = [xs["vx"], xs["vy"], xs["vz"]]
    u = [us["ux"], us["uy"], us["uz"]]
    if normalized:
        size = ca.sqrt(u[0] ** 2 + u[1] ** 2 + u[2] ** 2)
        u = [c / size for c in u]
    m = xs["m"]
    mu_r3 = MU / (r[0] ** 2 + r[1] ** 2 + r[2] ** 2) ** 1.5
    drag = _drag(r, v, True)
    acc = [-mu_r3 * r[k] + (data.thrust * u[k] - drag[k]) / m for k in range(3)]
    xdot = v + acc + [-data.mass_flow]
    units = {**{k: "m" for k in STATES[:3]}, **{k: "m/s" for k in STATES[3:6]}, "m": "kg",
             **{k: "-" for k in CONTROLS}}
    return model_from_expressions(xs, dict(zip(STATES, xdot)), us, units=units,
                                  name=f"delta3_phase{phase}" + ("_normalized" if normalized else ""))


def delta3_model(phase: int, normalized: bool = False) -> Model:
    """The ECI point-mass ascent model of one phase (module docstring for the equations).

    Parameters
    ----------
    phase : int
        0 (six SRBs + stage 1), 1 (three SRBs + stage 1), 2 (stage 1), 3 (stage 2).
    normalized : bool, optional
        False (default): the thrust is ``T u`` (impose ``|u| = 1`` in the problem). True:
        the thrust is ``T u / |u|`` (ASSET's form), so the dynamics do not depend on
        ``|u|`` and a problem may bound ``|u|`` in a band (``0.5 <= |u| <= 1.5``) instead
        of the nonconvex ``|u| = 1``; the two agree wherever ``|u| = 1``.

    Returns
    -------
    Model
        States ``rx, ry, rz`` [m], ``vx, vy, vz`` [m/s], ``m`` [kg]; controls ``ux, uy, uz``
        (thrust direction); no parameters. Built once per phase and form and cached
        (`dynamics.clear_caches` drops it).

    Raises
    ------
    ValueError
        If ``phase`` is not 0, 1, 2 or 3 (``TypeError`` subclass for a non-integer).

    Examples
    --------
    >>> from appdyn.problems.ascent.delta3 import delta3_model, initial_state, PHASES
    >>> model = delta3_model(0)
    >>> model.states, model.controls
    (('rx', 'ry', 'rz', 'vx', 'vy', 'vz', 'm'), ('ux', 'uy', 'uz'))
    >>> bool(model.rhs(initial_state())[6] == -PHASES[0].mass_flow)
    True
    """
    if not isinstance(normalized, (bool, np.bool_)):
        raise TypeError(f"`normalized` must be True or False, got {normalized!r}")
    return _delta3_model(_check_phase(phase), bool(normalized))


def initial_state() -> np.ndarray:
    """State at ``t = 0``: on the surface at 28.5 deg latitude, at rest on the rotating Earth.

    Returns
    -------
    numpy.ndarray, shape (7,)
        ``[RE cos(lat), 0, RE sin(lat), 0, OMEGA_E RE cos(lat), 0, LAUNCH_MASS]`` (m, m/s, kg).
    """
    c, s = math.cos(LAUNCH_LATITUDE), math.sin(LAUNCH_LATITUDE)
    return np.array([RE * c, 0.0, RE * s, 0.0, OMEGA_E * RE * c, 0.0, LAUNCH_MASS])


# --------------------------------------------------------------------- orbital elements
class OrbitalElements(NamedTuple):
    """Classical elements: ``a`` [m], ``e`` [-], ``i``, ``raan``, ``argp``, ``nu`` [rad]."""

    a: np.ndarray
    e: np.ndarray
    i: np.ndarray
    raan: np.ndarray
    argp: np.ndarray
    nu: np.ndarray


def _vectors(r, v, mu):
    """Components of h, n = z x h and the eccentricity vector, for lists of 3 components."""
    def cross(p, q):
        return [p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0]]

    def dot(p, q):
        return p[0] * q[0] + p[1] * q[1] + p[2] * q[2]

    h = cross(r, v)
    n = [-h[1], h[0], 0.0 * h[0]]
    r2, v2, rv = dot(r, r), dot(v, v), dot(r, v)
    rad = r2 ** 0.5
    ecc = [((v2 - mu / rad) * r[k] - rv * v[k]) / mu for k in range(3)]
    return h, n, ecc, rad, v2, cross, dot


def orbital_elements(r, v, mu: float = MU) -> OrbitalElements:
    """Classical orbital elements from inertial position and velocity (numbers only).

    Parameters
    ----------
    r : array_like, shape (3,) or (3, n) [m]
    v : array_like, shape (3,) or (3, n) [m/s]
    mu : float, optional [m^3/s^2]

    Returns
    -------
    OrbitalElements
        ``a`` [m] (``1 / (2/r - v^2/mu)``, negative for hyperbolae), ``e``, and the angles
        [rad]: ``i`` in [0, pi]; ``raan``, ``argp``, ``nu`` in [0, 2 pi). Scalars for (3,)
        input, arrays (n,) for (3, n). The angles use the standard quadrant rules
        (``raan > pi`` iff ``n_y < 0``, ``argp > pi`` iff ``e_z < 0``, ``nu > pi`` iff
        ``r . v < 0``), evaluated as ``atan2`` of the cosine and sine (exact to round-off
        near 0 and pi, where ``acos`` loses half the digits). Undefined (arbitrary) for
        equatorial (``raan``, ``argp``) or circular (``argp``, ``nu``) orbits.

    Raises
    ------
    TypeError
        If ``r`` or ``v`` is symbolic or not numeric (use `orbit_residuals` for CasADi).
    ValueError
        If shapes are not (3,) / (3, n) or do not match, or values are not finite, or
        ``mu <= 0``.
    """
    if is_symbolic(r) or is_symbolic(v):
        raise TypeError("`r`, `v` must be numbers for orbital_elements; use orbit_residuals "
                        "for CasADi symbols")
    mu = positive(mu, "mu")
    rc, _ = _components(r, "r")
    vc, _ = _components(v, "v")
    if np.shape(rc[0]) != np.shape(vc[0]):
        raise ValueError(f"`r` and `v` must have the same shape, got {np.shape(r)} and "
                         f"{np.shape(v)}")
    h, n, ecc, rad, v2, cross, dot = _vectors(rc, vc, mu)
    hmag = np.sqrt(dot(h, h))
    a = 1.0 / (2.0 / rad - v2 / mu)
    e = np.sqrt(dot(ecc, ecc))
    inc = np.arctan2(np.hypot(h[0], h[1]), h[2])
    raan = np.mod(np.arctan2(n[1], n[0]), 2 * np.pi)
    argp = np.mod(np.arctan2(dot(h, cross(n, ecc)) / hmag, dot(n, ecc)), 2 * np.pi)
    nu = np.mod(np.arctan2(dot(h, cross(ecc, rc)) / hmag, dot(ecc, rc)), 2 * np.pi)
    return OrbitalElements(*(x if np.ndim(x) else float(x) for x in (a, e, inc, raan, argp, nu)))


def orbit_residuals(r, v, target=TARGET_ORBIT, mu: float = MU):
    """The five terminal residuals ``[a, e, i, raan, argp] - target`` (numbers or CasADi).

    Formulation (branch-free, no ``acos``)::

        a    = 1 / (2/|r| - |v|^2/mu) - a_t                         [m]
        e    = |e_vec| - e_t,   e_vec = ((v^2 - mu/r) r - (r.v) v) / mu
        i    = atan2(sqrt(h_x^2 + h_y^2), h_z) - i_t                  [rad]
        raan = atan2(n_y cos W_t - n_x sin W_t,  n_x cos W_t + n_y sin W_t)       [rad]
        argp = atan2(s cos w_t - c sin w_t,  c cos w_t + s sin w_t)               [rad]

    with ``n = z x h``, ``c = n . e_vec`` and ``s = h_hat . (n x e_vec)`` (``|n||e|`` times
    the cosine and sine of the argument of perigee). The angle rows are ``wrap(angle -
    target)`` in (-pi, pi]: equal to the element minus its target whenever the element is
    within 180 deg of it, smooth everywhere except exactly opposite the target, with unit
    slope at the target. Compared with the ``acos`` + quadrant-fix forms (GPOPS-II, PSOPT,
    yapss), there is no branch to pick and no infinite slope at 0 or 180 deg. ``i`` is
    smooth away from equatorial orbits (the target has 28.5 deg), ``e`` away from circular
    ones and ``a`` for elliptic ones.

    Parameters
    ----------
    r, v : casadi.SX, casadi.MX (3 elements), or array_like, shape (3,) or (3, n)
        Position [m] and inertial velocity [m/s].
    target : mapping, optional
        Keys ``a, e, i, raan, argp`` (m, -, rad); default `TARGET_ORBIT`.
    mu : float, optional [m^3/s^2]

    Returns
    -------
    casadi.SX or casadi.MX, shape (5, 1), for symbolic input; numpy.ndarray, shape (5,)
    or (5, n), for numbers.

    Raises
    ------
    TypeError
        If ``r`` / ``v`` are neither CasADi symbols nor numbers, or ``target`` is not a mapping.
    ValueError
        Naming the argument: wrong shapes, non-finite numbers, ``mu <= 0``, a missing
        ``target`` key.
    """
    mu = positive(mu, "mu")
    if not hasattr(target, "keys"):
        raise TypeError(f"`target` must be a mapping with keys a, e, i, raan, argp, got "
                        f"{type(target).__name__}")
    missing = [k for k in ("a", "e", "i", "raan", "argp") if k not in target]
    if missing:
        raise ValueError(f"`target` has no value for {missing}")
    tgt = {k: float(target[k]) for k in ("a", "e", "i", "raan", "argp")}
    rc, sym_r = _components(r, "r")
    vc, sym_v = _components(v, "v")
    symbolic = sym_r or sym_v
    if not symbolic and np.shape(rc[0]) != np.shape(vc[0]):
        raise ValueError(f"`r` and `v` must have the same shape, got {np.shape(r)} and "
                         f"{np.shape(v)}")
    atan2, sqrt = (ca.atan2, ca.sqrt) if symbolic else (np.arctan2, np.sqrt)
    h, n, ecc, rad, v2, cross, dot = _vectors(rc, vc, mu)
    hmag = sqrt(dot(h, h))
    c = dot(n, ecc)
    s = dot(h, cross(n, ecc)) / hmag
    cW, sW = math.cos(tgt["raan"]), math.sin(tgt["raan"])
    cw, sw = math.cos(tgt["argp"]), math.sin(tgt["argp"])
    rows = [1.0 / (2.0 / rad - v2 / mu) - tgt["a"],
            sqrt(dot(ecc, ecc)) - tgt["e"],
            atan2(sqrt(h[0] ** 2 + h[1] ** 2), h[2]) - tgt["i"],
            atan2(n[1] * cW - n[0] * sW, n[0] * cW + n[1] * sW),
            atan2(s * cw - c * sw, c * cw + s * sw)]
    if symbolic:
        return ca.vertcat(*rows)
    return np.array(rows, dtype=float)


# -------------------------------------------------------------------- bounds and guess
def phase_bounds(phase: int) -> tuple[np.ndarray, np.ndarray]:
    """Box bounds of one phase for an NLP (as GPOPS-II, PSOPT and yapss set them).

    Parameters
    ----------
    phase : int
        0..3.

    Returns
    -------
    x_bounds : numpy.ndarray, shape (2, 7)
        Rows lower, upper: each position component within ``+-2 RE`` [m], each velocity
        component within ``+-V_MAX`` (10 km/s), mass between the phase's least end mass
        (`PhaseData.mass_end_min`; for stage 2 the burn-out mass 6644 kg) and its start mass.
    u_bounds : numpy.ndarray, shape (2, 3)
        ``-1 <= u_k <= 1`` (with ``|u| = 1`` imposed as a path constraint).
    """
    data = PHASES[_check_phase(phase)]
    lower = np.r_[np.full(3, -2 * RE), np.full(3, -V_MAX), data.mass_end_min]
    upper = np.r_[np.full(3, 2 * RE), np.full(3, V_MAX), data.mass_start]
    return np.vstack([lower, upper]), np.vstack([-np.ones(3), np.ones(3)])


def state_from_elements(a: float, e: float, i: float, raan: float, argp: float, nu: float,
                        mu: float = MU) -> tuple[np.ndarray, np.ndarray]:
    """Inertial position [m] and velocity [m/s], shapes (3,), of the orbit with elements
    ``a`` [m], ``e``, ``i``, ``raan``, ``argp`` and true anomaly ``nu`` [rad] (perifocal
    state rotated by ``R3(-raan) R1(-i) R3(-argp)``); the inverse of `orbital_elements`.
    ``ValueError`` naming the element for a non-finite one, ``a <= 0`` or ``e`` outside
    ``[0, 1)`` (closed orbits)."""
    a, e, i, raan, argp, nu = (finite_scalar(v, n) for v, n in zip(
        (a, e, i, raan, argp, nu), ("a", "e", "i", "raan", "argp", "nu")))
    a, mu = positive(a, "a"), positive(mu, "mu")
    if not 0.0 <= e < 1.0:
        raise ValueError(f"`e` must be in [0, 1) (a closed orbit), got {e}")
    p = a * (1.0 - e * e)
    rad = p / (1.0 + e * math.cos(nu))
    r_pf = np.array([rad * math.cos(nu), rad * math.sin(nu), 0.0])
    v_pf = math.sqrt(mu / p) * np.array([-math.sin(nu), e + math.cos(nu), 0.0])
    cO, sO, ci, si = math.cos(raan), math.sin(raan), math.cos(i), math.sin(i)
    cw, sw = math.cos(argp), math.sin(argp)
    rot = np.array([[cO * cw - sO * sw * ci, -cO * sw - sO * cw * ci, sO * si],
                    [sO * cw + cO * sw * ci, -sO * sw + cO * cw * ci, -cO * si],
                    [sw * si, cw * si, ci]])
    return rot @ r_pf, rot @ v_pf


def _spherical(r: np.ndarray) -> tuple[float, float, float]:
    """``(radius, latitude, longitude)`` of a position [m, rad, rad]."""
    rad = float(np.linalg.norm(r))
    return rad, math.asin(r[2] / rad), math.atan2(r[1], r[0])


def guess(phase: int, n: int = 21) -> dict:
    """An initial guess for one phase, continuous in position and velocity across phases.

    Over the whole flight, from launch (`initial_state`) at ``t = 0`` to the perigee of the
    target orbit at the latest final time ``t_f = 961`` s, the radius, latitude and longitude
    (the shorter way round) and the inertial velocity are interpolated linearly in
    ``t / t_f`` (the guess of yapss's ``delta_iii_ascent`` example: it never passes through
    the Earth); the mass falls linearly from each phase's start mass to its least end mass
    (`PhaseData.mass_end_min`); the thrust points along ``+y``. `problems.ascent.delta3_problem`
    hands the last phase's guess its full 700 s duration as the guessed free duration (its
    final state on the target orbit); measured on the default mesh of
    `problems.ascent.delta3_ascent` (5 Radau-5 intervals per phase, IPOPT's default options):
    21 IPOPT iterations to the optimum from the relaxed start, against 53 with the guess
    sampled over its first 350 s only (the middle of the free duration's range, the engine's
    default without a guessed duration).

    Parameters
    ----------
    phase : int
        0..3.
    n : int, optional
        Number of samples, evenly spaced over the phase (``>= 2``).

    Returns
    -------
    dict
        ``'t'`` (n,) [s] (absolute), ``'x'`` (7, n) (m, m/s, kg), ``'u'`` (3, n) unit thrust
        directions. New arrays on every call.
    """
    phase = _check_phase(phase)
    n = integer(n, "n", minimum=2)
    data = PHASES[phase]
    t_final = PHASES[-1].t_end_max
    x0 = initial_state()
    rf, vf = state_from_elements(*(TARGET_ORBIT[k] for k in ("a", "e", "i", "raan", "argp")), 0.0)
    (r0, lat0, lon0), (r1, lat1, lon1) = _spherical(x0[:3]), _spherical(rf)
    dlon = math.atan2(math.sin(lon1 - lon0), math.cos(lon1 - lon0))
    t = np.linspace(data.t_start, data.t_end_max, n)
    f = t / t_final
    rad, lat, lon = r0 + f * (r1 - r0), lat0 + f * (lat1 - lat0), lon0 + f * dlon
    position = rad * np.vstack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)])
    velocity = x0[3:6, None] + f * (vf - x0[3:6])[:, None]
    mass = np.linspace(data.mass_start, data.mass_end_min, n)[None, :]
    x = np.vstack([position, velocity, mass])
    x[:, 0] = x0 if phase == 0 else x[:, 0]
    return {"t": t, "x": x, "u": np.tile([[0.0], [1.0], [0.0]], (1, n))}
