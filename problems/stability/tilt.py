"""Method III cases (Rheinfurth & Wilson, NASA RP-1262, Sec. 4.6): a symmetric body spinning
about its axis under a tilt torque -- `heavy_top`, `spinning_projectile`, `rotor`.

All three are Eq. 4.122 with ``m g l`` replaced by an overturning stiffness ``kappa``; the
model is `dynamics.spinning.tilt_torque_body`, linearized in the frame spinning at ``w0``,
with the spin phase (cyclic) and the spin rate (constant to first order) factored out.
"""
from __future__ import annotations

import math

import numpy as np

from appdyn.dynamics.linearize import Linearization
from appdyn.dynamics.spinning import tilt_torque_scene
from appdyn.dynamics.results import timed

from .closed_forms import method3_roots, sleeping_rate, with_conjugates
from .common import STANDARD_GRAVITY, check_number
from .report import Quantity, StabilityReport, build_report
from .spin_scene import spin_linearization

__all__ = ["heavy_top", "spinning_projectile", "rotor"]


def _check_axisymmetric(I1, I2):
    I1 = check_number(I1, "axial_inertia", positive=True)
    I2 = check_number(I2, "transverse_inertia", positive=True)
    if I1 > 2 * I2 * (1 + 1e-12):
        raise ValueError(f"`axial_inertia` {I1} exceeds 2 * `transverse_inertia` = {2 * I2}: "
                         "no body has such moments (triangle inequality, RP-1262, Sec. 4.4 A)")
    return I1, I2


def _root_branch(theta: complex, psi: complex) -> bool:
    """Whether an eigenvector with deviation-angle components ``(theta, psi)`` belongs to a
    root ``s`` of the complex equation for ``delta = psi + i theta``.

    A solution ``delta = c e^{st}`` has ``(theta, psi)`` proportional to ``(-i, 1)`` in the
    eigenvector of ``s`` (then ``theta + i psi = 0``); its conjugate partner has ``(+i, 1)``.
    """
    return abs(theta + 1j * psi) < abs(theta - 1j * psi)


def _inertial_roots(red: Linearization, rate: float) -> list:
    """The complex roots behind the eigenvalues, as seen inertially: ``s - i w0`` (Eq. 4.129)."""
    ev, V = np.linalg.eig(red.A)
    it, ip = red.index("dth2"), red.index("dth3")
    return sorted((complex(s) - 1j * rate for k, s in enumerate(ev)
                   if _root_branch(V[it, k], V[ip, k])), key=lambda z: abs(z.imag))



@timed
def heavy_top(axial_inertia, transverse_inertia, mass, length, rate, *,
              gravity: float = STANDARD_GRAVITY) -> StabilityReport:
    """Heavy top spinning upright about its symmetry axis.

    Perturbation equations 4.122 in the nominal frame spinning at ``w0``:
    ``I2 theta'' + K theta - G w0 psi' = 0``, ``I2 psi'' + K psi + G w0 theta' = 0`` with
    ``K = (I1 - I2) w0^2 - m g l`` and ``G = 2 I2 - I1``; the roots 4.127
    ``s = i [G w0 / (2 I2) +/- sqrt((I1 w0 / (2 I2))^2 - m g l / I2)]`` (and conjugates);
    sleeping (stable) for ``|w0| > (2 / I1) sqrt(m g l I2)`` (4.128); slow and fast
    precession seen inertially ``-[I1 w0 / (2 I2) -/+ sqrt(...)]`` (4.130-4.131, negative =
    same sense as the spin, "forward"), and ``-m g l / (I1 w0)`` at high spin (4.132, whose
    printed form drops the sign).

    The computed model is `dynamics.spinning.tilt_torque_body` (exact nonlinear top),
    linearized in the spinning frame; the spin phase and the spin rate are factored out.

    Parameters
    ----------
    axial_inertia : float [kg m^2]
        ``I1`` about the symmetry axis.
    transverse_inertia : float [kg m^2]
        ``I2`` about a transverse axis through the pivot.
    mass : float [kg]
        Positive.
    length : float [m]
        Pivot to mass center along the axis (negative: hanging below).
    rate : float [rad/s]
        Spin ``w0`` (0 allowed: the upright pendulum).
    gravity : float [m/s^2], optional
        Default `STANDARD_GRAVITY`.

    Returns
    -------
    StabilityReport
        States ``dth2, dth3, w2, w3``; quantities: sleeping rate, precession rates (from the
        eigenvectors and closed form), high-spin approximation.

    Raises
    ------
    ValueError
        Naming the argument: non-positive moments or mass, ``I1 > 2 I2``, non-finite values.

    References
    ----------
    Rheinfurth & Wilson, NASA RP-1262, Sec. 4.6, Method III, Example 1, Eqs. 4.122-4.132.

    Examples
    --------
    >>> from appdyn.problems import stability
    >>> top = stability.heavy_top(0.002, 0.005, mass=0.3, length=0.04, rate=40.0)
    >>> top.verdict
    'marginally stable'
    >>> round(top.quantity("slow precession rate").value, 6)  # Eq. 4.130
    -1.638865
    >>> round(top.quantity("minimum spin rate").closed_form, 6)  # Eq. 4.128
    24.256937
    >>> stability.heavy_top(0.002, 0.005, mass=0.3, length=0.04, rate=20.0).verdict
    'unstable'
    """
    I1, I2 = _check_axisymmetric(axial_inertia, transverse_inertia)
    m = check_number(mass, "mass", positive=True)
    l = check_number(length, "length")
    rate = check_number(rate, "rate")
    g = check_number(gravity, "gravity", positive=True)
    mgl = m * g * l
    params = {"axial_inertia": I1, "transverse_inertia": I2, "mass": m, "length": l,
              "rate": rate, "gravity": g}
    title = "Heavy top, upright spin (RP-1262, Sec. 4.6 Method III, Example 1)"
    return _tilt_report("heavy_top", title, I1, I2, mgl, rate, 0.0, params, "m g l")


@timed
def spinning_projectile(axial_inertia, transverse_inertia, rate, *, dynamic_pressure, area,
                        cn_alpha, cp_offset) -> StabilityReport:
    """Spin-stabilized projectile: the heavy top with ``m g l -> M_alpha = q S C_N_alpha l``.

    The normal force ``q S C_N_alpha alpha`` acts at the center of pressure a distance ``l``
    ahead of the mass center; its moment ``-M_alpha a x n`` (``n`` the velocity direction in
    body axes) tips the nose away from the flight path. Stable (gyroscopically) iff the
    gyroscopic stability factor ``S_g = I1^2 w0^2 / (4 I2 M_alpha) > 1``, i.e. Eq. 4.128.

    Parameters
    ----------
    axial_inertia, transverse_inertia : float [kg m^2]
        ``I1``, ``I2`` about the mass center.
    rate : float [rad/s]
        Spin ``w0``.
    dynamic_pressure : float [Pa]
        ``q = rho V^2 / 2``, non-negative.
    area : float [m^2]
        Reference area ``S``, positive.
    cn_alpha : float [1/rad]
        Normal-force slope ``C_N_alpha``.
    cp_offset : float [m]
        Center of pressure ahead of the mass center (negative: behind, aerodynamically
        stable).

    Returns
    -------
    StabilityReport

    References
    ----------
    Rheinfurth & Wilson, NASA RP-1262, Sec. 4.6, Example 2; stability condition Eq. 4.128.

    Examples
    --------
    >>> from appdyn.problems import stability
    >>> rep = stability.spinning_projectile(0.002, 0.02, 2000.0, dynamic_pressure=2e5,
    ...                                     area=1e-3, cn_alpha=2.0, cp_offset=0.03)
    >>> rep.verdict, round(rep.quantity("gyroscopic stability factor").closed_form, 4)
    ('marginally stable', 16.6667)
    """
    I1, I2 = _check_axisymmetric(axial_inertia, transverse_inertia)
    rate = check_number(rate, "rate")
    q = check_number(dynamic_pressure, "dynamic_pressure", nonnegative=True)
    S = check_number(area, "area", positive=True)
    cna = check_number(cn_alpha, "cn_alpha")
    l = check_number(cp_offset, "cp_offset")
    Ma = q * S * cna * l
    params = {"axial_inertia": I1, "transverse_inertia": I2, "rate": rate,
              "dynamic_pressure": q, "area": S, "cn_alpha": cna, "cp_offset": l}
    title = "Spinning projectile (RP-1262, Sec. 4.6 Example 2)"
    return _tilt_report("spinning_projectile", title, I1, I2, Ma, rate, 0.0, params,
                        "M_alpha")


@timed
def rotor(axial_inertia, transverse_inertia, stiffness, bearing_distance, rate, *,
          internal_damping: float = 0.0) -> StabilityReport:
    """Rotor in elastic bearings: whirl and internal damping.

    Eq. 4.122 with ``K = (I1 - I2) w0^2 + 2 k l^2`` (``m g l -> -2 k l^2``): whirl frequencies
    ``-[I1 w0 / (2 I2) -/+ sqrt((I1 w0 / (2 I2))^2 + 2 k l^2 / I2)]`` (4.134 backward,
    4.135 forward). Internal (rotating) damping ``D`` adds ``D theta'``, ``D psi'``:
    ``I2 s^2 + (D - i G w0) s + K = 0``; by Kelvin-Tait-Chetaev the rotor is then unstable
    iff ``K < 0``: ``w0^2 > 2 k l^2 / (I2 - I1)`` (RP-1262 NOTE; only for ``I2 > I1``).

    Parameters
    ----------
    axial_inertia, transverse_inertia : float [kg m^2]
        ``I1`` polar, ``I2`` transverse about the mass center (midway between the bearings).
    stiffness : float [N/m]
        ``k`` of each bearing, non-negative.
    bearing_distance : float [m]
        ``l`` from the mass center to each bearing.
    rate : float [rad/s]
        Spin ``w0``.
    internal_damping : float [N m s], optional
        ``D >= 0`` (default 0).

    Returns
    -------
    StabilityReport

    References
    ----------
    Rheinfurth & Wilson, NASA RP-1262, Sec. 4.6, Example 3, Eqs. 4.134-4.135, and the NOTE
    on internal damping.

    Examples
    --------
    >>> from appdyn.problems import stability
    >>> rep = stability.rotor(0.01, 0.05, stiffness=1e4, bearing_distance=0.1, rate=50.0,
    ...                       internal_damping=0.01)
    >>> rep.verdict
    'asymptotically stable'
    >>> round(rep.quantity("internal-damping instability speed").closed_form, 4)
    70.7107
    """
    I1, I2 = _check_axisymmetric(axial_inertia, transverse_inertia)
    k = check_number(stiffness, "stiffness", nonnegative=True)
    l = check_number(bearing_distance, "bearing_distance")
    rate = check_number(rate, "rate")
    D = check_number(internal_damping, "internal_damping", nonnegative=True)
    params = {"axial_inertia": I1, "transverse_inertia": I2, "stiffness": k,
              "bearing_distance": l, "rate": rate, "internal_damping": D}
    title = "Rotor in elastic bearings (RP-1262, Sec. 4.6 Example 3)"
    return _tilt_report("rotor", title, I1, I2, -2 * k * l * l, rate, D, params, "")


def _tilt_report(case, title, I1, I2, kappa, rate, damping, params, symbol):
    """Shared by the Method III cases: ``kappa`` replaces ``m g l``, ``symbol`` names it."""
    scene = tilt_torque_scene(np.diag([I1, I2, I2]), kappa, internal_damping=damping)
    sl = spin_linearization(scene, np.array([1.0, 0.0, 0.0]), rate, frame="spinning")
    lin, red = sl.lin, sl.reduced
    (r1, r2), G, K = method3_roots(I1, I2, kappa, rate, damping=damping)
    inertial_cf = sorted((complex(r) - 1j * rate for r in (r1, r2)), key=lambda z: abs(z.imag))
    inertial = _inertial_roots(red, rate)
    a = I1 * rate / (2 * I2)
    radicand = a * a - kappa / I2
    sleeping = radicand >= 0 or damping > 0
    whirl = case == "rotor"

    def label(s, v):
        it, ip = red.index("dth2"), red.index("dth3")
        root = complex(s) if _root_branch(v[it], v[ip]) else complex(s).conjugate()
        if not sleeping:
            motion = "precession" if rate else "tilt"
            return f"{motion}, {'growing' if root.real > 0 else 'decaying'}"
        w = root.imag - rate
        sense = "forward" if w * rate < 0 else ("backward" if w * rate > 0 else "no")
        slow = abs(w) <= abs(inertial_cf[0].imag) + 1e-9 * max(abs(rate), 1.0)
        return f"{'slow' if slow else 'fast'} {sense} {'whirl' if whirl else 'precession'}"

    if whirl:  # kappa = -2 k l^2: show the restoring stiffness with its own sign
        quantities = [Quantity("2 k l^2", None, -kappa, "N m/rad"),
                      Quantity("K = (I1 - I2) w0^2 + 2 k l^2", None, K, "N m/rad",
                               "Sec. 4.6 Ex. 3")]
        rad_name = "radicand (I1 w0 / 2 I2)^2 + 2 k l^2 / I2"
    else:
        quantities = [Quantity(symbol, None, kappa, "N m"),
                      Quantity(f"K = (I1 - I2) w0^2 - {symbol}", None, K, "N m/rad", "Eq. 4.122")]
        rad_name = f"radicand (I1 w0 / 2 I2)^2 - {symbol} / I2"
    quantities.append(Quantity("G = 2 I2 - I1", None, G, "kg m^2", "Eq. 4.122"))
    notes = list(red.notes)
    if not whirl:
        if kappa > 0:
            quantities.append(Quantity("minimum spin rate for stability", None,
                                       sleeping_rate(I1, I2, kappa), "rad/s", "Eq. 4.128"))
        if case == "spinning_projectile":
            sg = I1 ** 2 * rate ** 2 / (4 * I2 * kappa) if kappa != 0 else math.inf
            quantities.append(Quantity("gyroscopic stability factor S_g", None, sg, "",
                                       "I1^2 w0^2 / (4 I2 M_alpha) > 1 <=> Eq. 4.128"))
        names = ("slow precession rate", "fast precession rate")
        eqs = ("Eq. 4.130", "Eq. 4.131")
    else:
        names = ("backward whirl frequency", "forward whirl frequency")
        eqs = ("Eq. 4.134 (exact at D = 0)", "Eq. 4.135 (exact at D = 0)")
        if I2 > I1 and kappa < 0:
            quantities.append(Quantity("internal-damping instability speed", None,
                                       math.sqrt(-kappa / (I2 - I1)), "rad/s",
                                       "Sec. 4.6 NOTE: w0^2 > 2 k l^2 / (I2 - I1)"))
        else:
            notes.append("K > 0 at every speed (I1 >= I2 or no bearing stiffness): internal "
                         "damping cannot destabilize")
    if sleeping:
        for nm, eq, z, zc in zip(names, eqs, inertial, inertial_cf):
            quantities.append(Quantity(nm, z.imag, zc.imag, "rad/s", eq))
        if not whirl and rate != 0 and kappa != 0:
            quantities.append(Quantity("slow precession, high-spin approximation", None,
                                       -kappa / (I1 * rate), "rad/s",
                                       "Eq. 4.132 (sign as in 4.130)"))
    else:
        quantities.append(Quantity("precession rate (not sleeping)",
                                   inertial[0].imag if inertial else None, 0.0 - a, "rad/s",
                                   "Eq. 4.129: Im(root) - w0"))
        quantities.append(Quantity("growth rate", max(abs(z.real) for z in inertial)
                                   if inertial else None, math.sqrt(-radicand), "1/s",
                                   "sqrt(-radicand), Eq. 4.127"))
    quantities.append(Quantity(rad_name, None, radicand, "1/s^2", "Eq. 4.127"))
    notes.append("eigenvalues are those of the nominal frame spinning at w0 (Eq. 4.127); seen "
                 "inertially a root turns at Im(root) - w0 (Eq. 4.129): negative = the spin's "
                 "sense (forward)")
    return build_report(case, title, params, red.ss, lin=lin,
                        closed_form=with_conjugates([r1, r2]), labeler=label,
                        quantities=quantities, notes=notes)


