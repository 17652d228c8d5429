"""Linear stability reports about spin states and operating points (seed Secs. 4.5-4.6).

Every case returns a `StabilityReport`: the analysed ``control.StateSpace`` (``.ss``), its
eigenvalues, a verdict, a mode table with natural frequencies, damping ratios, labels and
closed-form values where the seed gives them, derived quantities (precession and whirl
rates, stability boundaries), and gain/phase margins for feedback loops.

Cases
-----
`spin`                 torque-free spin about a principal axis, optionally with an energy damper
`heavy_top`            Method III, Example 1 (Eqs. 4.122-4.132)
`spinning_projectile`  Example 2: aerodynamic overturning moment in place of ``m g l``
`rotor`                Example 3: whirl (4.134-4.135) and internal-damping instability
`gyrostat`             body + wheel of constant relative speed, optional damper
`loop`                 any plant with a feedback law: margins via ``control.stability_margins``
`analyze`              any ``StateSpace`` (e.g. from `dynamics.linearize.linearize`)

`sweep` runs a case along one parameter and locates each verdict boundary by bisection.

The verdict (one of `VERDICTS`) and the report machinery live in
`problems.stability_report`: an eigenvalue with ``|Re| <= ZERO_RTOL * rho`` (1e-9 of the
spectral radius) counts as on the imaginary axis; "marginally stable" needs those to be
semisimple.

Spin cases report the *reduced* motion: the spin phase about the axis (cyclic) and the
conserved spin-axis momentum (a first integral, whose steady spins form a one-parameter
family with eigenvalue 0) are factored out by `Linearization.quotient` and
`Linearization.restrict`; the notes say which states went.
"""
from __future__ import annotations

import inspect
import json
import math
from dataclasses import asdict, dataclass
from typing import Callable

import casadi as ca
import numpy as np

from dynamics.linearize import Linearization, linearization
from dynamics.rigid_body import check_inertia, rigid_body
from dynamics.spinning import (PointMassDamper, SphericalDamper, gyrostat_model,
                               steady_spin_state, tilt_torque_body, unit_vector)

from .stability_report import (VERDICTS, ZERO_RTOL, Margins, Mode, Quantity, StabilityReport,
                               analyze, build_report, classify, format_complex, jsonable,
                               param_text, plain)

__all__ = [
    "ZERO_RTOL", "VERDICTS", "Mode", "Margins", "Quantity", "StabilityReport", "Boundary",
    "SweepResult", "PointMassDamper", "SphericalDamper", "classify", "analyze", "spin",
    "heavy_top", "spinning_projectile", "rotor", "gyrostat", "loop", "sweep", "CASES",
    "STANDARD_GRAVITY",
]

STANDARD_GRAVITY = 9.80665  # m/s^2
_STABLE_UNSTABLE = {"asymptotically stable", "unstable"}
_BAND_RTOL = 1e-4  # a "marginally stable" stretch this narrow between the two is a zero band


# ------------------------------------------------------------------------- helpers
def _num(value, name, *, positive=False, nonzero=False, nonnegative=False) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"`{name}` must be a number, got {value!r}") from None
    if not math.isfinite(v):
        raise ValueError(f"`{name}` must be finite, got {v}")
    if positive and not v > 0:
        raise ValueError(f"`{name}` must be positive, got {v}")
    if nonzero and v == 0:
        raise ValueError(f"`{name}` must be non-zero, got {v}")
    if nonnegative and v < 0:
        raise ValueError(f"`{name}` must be non-negative, got {v}")
    return v


# ---------------------------------------------------------------- spin utilities
def _principal(I: np.ndarray, a: np.ndarray):
    """Check that the unit vector ``a`` is a principal axis of ``I``; return its moment and the
    two others ``(I_a, I_b, I_c)``, ``I_b <= I_c``."""
    v = I @ a
    Ia = float(a @ v)
    off = v - Ia * a
    if np.linalg.norm(off) > 1e-9 * np.linalg.norm(I, 2):
        vals, vecs = np.linalg.eigh(I)
        axes = "; ".join(f"{vals[k]:.6g} about [{', '.join(f'{c:.6g}' for c in vecs[:, k])}]"
                         for k in range(3))
        raise ValueError(f"`axis` must be a principal axis of `inertia`: I a - (a.I a) a = "
                         f"{off.tolist()} for a = {a.tolist()}; principal moments and axes: {axes}")
    # orthonormal basis of the plane normal to a, then the two other principal moments
    helper = np.eye(3)[int(np.argmin(np.abs(a)))]
    e1 = np.cross(a, helper)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(a, e1)
    Bm = np.array([e1, e2])
    vals = np.linalg.eigvalsh(Bm @ I @ Bm.T)
    return Ia, float(vals[0]), float(vals[1])


def _axis_kind(Ia, Ib, Ic) -> str:
    scale = max(Ia, Ib, Ic)
    lo, hi = min(Ib, Ic), max(Ib, Ic)
    if Ia > hi + 1e-12 * scale:
        return "major"
    if Ia < lo - 1e-12 * scale:
        return "minor"
    if lo + 1e-12 * scale < Ia < hi - 1e-12 * scale:
        return "intermediate"
    return "degenerate (equal moments)"


def _case_linearization(model, x, frame, damper):
    """Linearize a steady spin; a damper that spoils the relative equilibrium is named."""
    try:
        return linearization(model, x, frame=frame)
    except ValueError as exc:
        if damper is None:
            raise
        raise ValueError(f"`damper`: no steady spin about `axis` with this damper: {exc}") from None


def _invariant_gradient(model, x, lin: Linearization, key: str) -> np.ndarray:
    """Gradient of ``|invariant|^2`` at ``x``, in the (non-attitude) states of ``lin``."""
    xs = ca.SX.sym("x", model.nx)
    value = model.invariants[key](xs, ca.DM(model.resolve_p()))
    grad = ca.Function("grad", [xs], [ca.gradient(ca.sumsqr(value), xs)])
    g = np.asarray(grad(x), dtype=float).reshape(-1)
    return np.array([g[model.states.index(s)] if s in model.states else 0.0 for s in lin.states])


def _reduce_free_spin(model, x, lin: Linearization) -> tuple[Linearization, list]:
    """Remove the neutral spin-rate direction of a torque-free spin (rates frame).

    ``|H|^2`` is a first integral; where ``H = 0`` its gradient vanishes and the energy (a
    first integral, or decaying to second order at the steady spin) takes over."""
    notes = []
    for name, key in (("|H|^2", "momentum_inertial"), ("energy", "energy")):
        c = _invariant_gradient(model, x, lin, key)
        if np.max(np.abs(c)) == 0:
            continue
        try:
            red = lin.restrict(c, reason=f"{name} is a first integral; the steady spins form a "
                               "one-parameter family, whose eigenvalue 0 goes")
        except ValueError:
            continue
        return red, notes
    notes.append("no first integral with a non-zero gradient: the neutral eigenvalue 0 of the "
                 "spin-rate family stays in the model")
    return lin, notes


def _complex_quadratic_roots(a2, a1, a0):
    """Roots of ``a2 s^2 + a1 s + a0 = 0`` with complex coefficients (stable formula)."""
    disc = np.sqrt(complex(a1) ** 2 - 4 * complex(a2) * complex(a0))
    sgn = 1.0 if (np.conj(a1) * disc).real >= 0 else -1.0
    qq = -0.5 * (a1 + sgn * disc)
    r1 = qq / a2
    r2 = a0 / qq if qq != 0 else -a1 / a2 - r1
    return complex(r1), complex(r2)


def _with_conjugates(roots) -> np.ndarray:
    return np.array([*roots, *[complex(r).conjugate() for r in roots]], dtype=complex)


def _spherical_roots(It, Jd, c, Ha_rigid, Omega, wd_axial, Ia):
    """Closed-form eigenvalues of a symmetric spinner with a spherical damper.

    Transverse (complex, ``sigma = s + i Omega``):
    ``It Jd sigma^2 + (c (It + Jd) - i Ha Jd) sigma - i c (Ha + Jd wd) = 0`` with
    ``Ha = Ia Omega + h`` (rigid part), plus conjugates; axial: ``-c (1/Ia + 1/Jd)``.
    """
    s1, s2 = _complex_quadratic_roots(It * Jd, c * (It + Jd) - 1j * Ha_rigid * Jd,
                                      -1j * c * (Ha_rigid + Jd * wd_axial))
    roots = [s1 - 1j * Omega, s2 - 1j * Omega]
    return np.array([*_with_conjugates(roots), -c * (1 / Ia + 1 / Jd)], dtype=complex)


def _damper_dict(damper):
    return None if damper is None else plain(damper)


# --------------------------------------------------------------------------- spin
def spin(inertia, axis, rate, *, damper=None) -> StabilityReport:
    """Torque-free spin ``w = rate * axis`` about a principal axis, optionally with a damper.

    The body-rate perturbations (seed Sec. 4.5 C, Eqs. 4.94-4.95) have the eigenvalues
    ``+/- i rate sqrt((Ia - Ib)(Ia - Ic) / (Ib Ic))`` (a real pair about the intermediate
    axis). With an energy damper (`PointMassDamper` or `SphericalDamper` on the body, a
    multibody `dynamics.spinning.gyrostat_model`) the spin is asymptotically stable about the
    major axis and unstable about the minor one (Kelvin-Tait-Chetaev, seed Sec. 4.5 NOTE).

    The model is linearized in body rates (``frame='rates'``; the attitude does not enter
    torque-free dynamics) and restricted to constant ``|H|``, which removes the eigenvalue 0
    of the neighbouring steady spins (one spin-axis state is eliminated).

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2]
        Of the rigid body about its mass center (without the damper mass / core inertia).
    axis : array_like, shape (3,)
        Spin axis in body axes; must be a principal axis of ``inertia``.
    rate : float [rad/s] — finite, non-zero
    damper : PointMassDamper or SphericalDamper, optional

    Returns
    -------
    StabilityReport
        Closed forms for the rigid body and for a symmetric body with a spherical damper
        (see `_spherical_roots`); mode labels 'nutation' / 'damper'.

    Raises
    ------
    ValueError
        Naming ``inertia``, ``axis``, ``rate`` or ``damper`` (e.g. a damper position that
        makes the axis non-principal for the loaded body: the residual is shown).
    """
    I = check_inertia(inertia)
    a = unit_vector(axis, "axis")
    rate = _num(rate, "rate", nonzero=True)
    Ia, Ib, Ic = _principal(I, a)
    if damper is not None and not isinstance(damper, (PointMassDamper, SphericalDamper)):
        raise ValueError("`damper` must be None, a PointMassDamper or a SphericalDamper, got "
                         f"{type(damper).__name__}")
    params = {"inertia": I, "axis": a, "rate": rate, "damper": _damper_dict(damper)}
    notes, quantities, cf = [], [], None
    if damper is None:
        model = rigid_body(I)
        x = np.concatenate([[0.0, 0.0, 0.0, 1.0], rate * a])
        title = "Torque-free spin about a principal axis (seed Sec. 4.5)"
    else:
        model = gyrostat_model(I, wheel_axis=a, damper=damper)
        x = steady_spin_state(a, rate, damper=damper)
        title = f"Spin about a principal axis with a {type(damper).__name__} (seed Sec. 4.5 NOTE)"
    lin = _case_linearization(model, x, "rates", damper)
    red, more = _reduce_free_spin(model, x, lin)
    notes += list(red.notes) + more
    kind = _axis_kind(Ia, Ib, Ic)
    lam2 = -rate ** 2 * (Ia - Ib) * (Ia - Ic) / (Ib * Ic)
    if damper is None:
        root = np.sqrt(complex(lam2))
        cf = np.array([root, -root])
        quantities.append(Quantity("lambda^2 = -rate^2 (Ia - Ib)(Ia - Ic) / (Ib Ic)", None, lam2,
                                   "1/s^2", "Eqs. 4.94-4.95"))
        if lam2 < 0:
            quantities.append(Quantity("nutation frequency (body rates)",
                                       _pair_frequency(red.eigenvalues()), float(abs(root.imag)),
                                       "rad/s", "Sec. 4.5 C: sqrt(lambda1 lambda2)"))
    else:
        comp = I + (damper.inertia_at(float(x[7])) if isinstance(damper, PointMassDamper)
                    else damper.inertia * np.eye(3))
        Ja, Jb, Jc = _principal(comp, a)
        kind = _axis_kind(Ja, Jb, Jc)
        quantities += [Quantity("loaded axial moment Ja", None, Ja, "kg m^2"),
                       Quantity("loaded transverse moment Jb", None, Jb, "kg m^2"),
                       Quantity("loaded transverse moment Jc", None, Jc, "kg m^2"),
                       Quantity("locked-damper lambda^2 = -rate^2 (Ja-Jb)(Ja-Jc)/(Jb Jc)", None,
                                -rate ** 2 * (Ja - Jb) * (Ja - Jc) / (Jb * Jc), "1/s^2",
                                "Eqs. 4.94-4.95, damper locked")]
        if isinstance(damper, SphericalDamper) and abs(Ib - Ic) <= 1e-12 * Ib:
            cf = _spherical_roots(Ib, damper.inertia, damper.damping, Ia * rate, rate, rate, Ia)
        expected = {"major": "asymptotically stable", "minor": "unstable",
                    "intermediate": "unstable"}.get(kind)
        if expected:
            notes.append(f"Kelvin-Tait-Chetaev: energy dissipation makes a {kind}-axis spin "
                         f"{expected} (if the damper is excited by the nutation)")
    notes.insert(0, f"spin about the {kind} axis{' of the loaded body' if damper else ''}; "
                    f"rigid moments Ia = {Ia:.10g}, Ib = {Ib:.10g}, Ic = {Ic:.10g} kg m^2")
    rates = [s for s in red.states if s.startswith("w") and not s.startswith("wd")]
    others = [s for s in red.states if s not in rates]
    return build_report("spin", title, params, red.ss, lin=lin, closed_form=cf,
                        groups={"nutation": rates, "damper": others},
                        quantities=quantities, notes=notes)


def _pair_frequency(ev) -> float | None:
    im = [abs(z.imag) for z in ev if abs(z.imag) > 0]
    return float(max(im)) if im else None


# ------------------------------------------------------- Method III: tilt torques
def _check_axisymmetric(I1, I2):
    I1 = _num(I1, "axial_inertia", positive=True)
    I2 = _num(I2, "transverse_inertia", positive=True)
    if I1 > 2 * I2 * (1 + 1e-12):
        raise ValueError(f"`axial_inertia` {I1} exceeds 2 * `transverse_inertia` = {2 * I2}: "
                         "no body has such moments (triangle inequality, seed Sec. 4.4 A)")
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


def heavy_top(axial_inertia, transverse_inertia, mass, length, rate, *,
              gravity: float = STANDARD_GRAVITY) -> StabilityReport:
    """Heavy top spinning upright about its symmetry axis (seed Sec. 4.6 Method III, Ex. 1).

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
    axial_inertia : float [kg m^2] — ``I1`` about the symmetry axis
    transverse_inertia : float [kg m^2] — ``I2`` about a transverse axis through the pivot
    mass : float [kg] — positive
    length : float [m] — pivot to mass center along the axis (negative: hanging below)
    rate : float [rad/s] — spin ``w0`` (0 allowed: the upright pendulum)
    gravity : float [m/s^2], optional

    Returns
    -------
    StabilityReport
        States ``dth2, dth3, w2, w3``; quantities: sleeping rate, precession rates (from the
        eigenvectors and closed form), high-spin approximation.

    Raises
    ------
    ValueError
        Naming the argument: non-positive moments or mass, ``I1 > 2 I2``, non-finite values.
    """
    I1, I2 = _check_axisymmetric(axial_inertia, transverse_inertia)
    m = _num(mass, "mass", positive=True)
    l = _num(length, "length")
    rate = _num(rate, "rate")
    g = _num(gravity, "gravity", positive=True)
    mgl = m * g * l
    params = {"axial_inertia": I1, "transverse_inertia": I2, "mass": m, "length": l,
              "rate": rate, "gravity": g}
    title = "Heavy top, upright spin (seed Sec. 4.6 Method III, Example 1)"
    return _tilt_report("heavy_top", title, I1, I2, mgl, rate, 0.0, params, "m g l")


def spinning_projectile(axial_inertia, transverse_inertia, rate, *, dynamic_pressure, area,
                        cn_alpha, cp_offset) -> StabilityReport:
    """Spin-stabilized projectile (seed Sec. 4.6 Example 2): the heavy top with
    ``m g l -> M_alpha = q S C_N_alpha l``.

    The normal force ``q S C_N_alpha alpha`` acts at the center of pressure a distance ``l``
    ahead of the mass center; its moment ``-M_alpha a x n`` (``n`` the velocity direction in
    body axes) tips the nose away from the flight path. Stable (gyroscopically) iff the
    gyroscopic stability factor ``S_g = I1^2 w0^2 / (4 I2 M_alpha) > 1``, i.e. Eq. 4.128.

    Parameters
    ----------
    axial_inertia, transverse_inertia : float [kg m^2] — ``I1``, ``I2`` about the mass center
    rate : float [rad/s] — spin ``w0``
    dynamic_pressure : float [Pa] — ``q = rho V^2 / 2``, non-negative
    area : float [m^2] — reference area ``S``, positive
    cn_alpha : float [1/rad] — normal-force slope ``C_N_alpha``
    cp_offset : float [m] — center of pressure ahead of the mass center (negative: behind,
        aerodynamically stable)

    Returns
    -------
    StabilityReport
    """
    I1, I2 = _check_axisymmetric(axial_inertia, transverse_inertia)
    rate = _num(rate, "rate")
    q = _num(dynamic_pressure, "dynamic_pressure", nonnegative=True)
    S = _num(area, "area", positive=True)
    cna = _num(cn_alpha, "cn_alpha")
    l = _num(cp_offset, "cp_offset")
    Ma = q * S * cna * l
    params = {"axial_inertia": I1, "transverse_inertia": I2, "rate": rate,
              "dynamic_pressure": q, "area": S, "cn_alpha": cna, "cp_offset": l}
    title = "Spinning projectile (seed Sec. 4.6 Example 2)"
    return _tilt_report("spinning_projectile", title, I1, I2, Ma, rate, 0.0, params,
                        "M_alpha")


def rotor(axial_inertia, transverse_inertia, stiffness, bearing_distance, rate, *,
          internal_damping: float = 0.0) -> StabilityReport:
    """Rotor in elastic bearings (seed Sec. 4.6 Example 3): whirl and internal damping.

    Eq. 4.122 with ``K = (I1 - I2) w0^2 + 2 k l^2`` (``m g l -> -2 k l^2``): whirl frequencies
    ``-[I1 w0 / (2 I2) -/+ sqrt((I1 w0 / (2 I2))^2 + 2 k l^2 / I2)]`` (4.134 backward,
    4.135 forward). Internal (rotating) damping ``D`` adds ``D theta'``, ``D psi'``:
    ``I2 s^2 + (D - i G w0) s + K = 0``; by Kelvin-Tait-Chetaev the rotor is then unstable
    iff ``K < 0``: ``w0^2 > 2 k l^2 / (I2 - I1)`` (seed NOTE; only for ``I2 > I1``).

    Parameters
    ----------
    axial_inertia, transverse_inertia : float [kg m^2] — ``I1`` polar, ``I2`` transverse
        about the mass center (midway between the bearings)
    stiffness : float [N/m] — ``k`` of each bearing, non-negative
    bearing_distance : float [m] — ``l`` from the mass center to each bearing
    rate : float [rad/s] — spin ``w0``
    internal_damping : float [N m s] — ``D >= 0``

    Returns
    -------
    StabilityReport
    """
    I1, I2 = _check_axisymmetric(axial_inertia, transverse_inertia)
    k = _num(stiffness, "stiffness", nonnegative=True)
    l = _num(bearing_distance, "bearing_distance")
    rate = _num(rate, "rate")
    D = _num(internal_damping, "internal_damping", nonnegative=True)
    params = {"axial_inertia": I1, "transverse_inertia": I2, "stiffness": k,
              "bearing_distance": l, "rate": rate, "internal_damping": D}
    title = "Rotor in elastic bearings (seed Sec. 4.6 Example 3)"
    return _tilt_report("rotor", title, I1, I2, -2 * k * l * l, rate, D, params, "")


def _tilt_report(case, title, I1, I2, kappa, rate, damping, params, symbol):
    """Shared by the Method III cases: ``kappa`` replaces ``m g l``, ``symbol`` names it."""
    model = tilt_torque_body(np.diag([I1, I2, I2]), kappa, internal_damping=damping)
    x = np.array([0.0, 0.0, 0.0, 1.0, rate, 0.0, 0.0])
    lin = linearization(model, x, frame="spinning")
    red = lin.quotient("dth1", reason="the spin phase about the symmetry axis is cyclic")
    red = red.restrict("w1", reason="the spin rate w1 is constant to first order (L1 = 0, "
                       "I2 = I3): Method III's I1 phi'' = L1 = 0")
    G = 2 * I2 - I1
    K = (I1 - I2) * rate ** 2 - kappa
    r1, r2 = _complex_quadratic_roots(I2, damping - 1j * G * rate, K)
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
                                       2 / I1 * math.sqrt(kappa * I2), "rad/s", "Eq. 4.128"))
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
                        closed_form=_with_conjugates([r1, r2]), labeler=label,
                        quantities=quantities, notes=notes)


# ----------------------------------------------------------------------- gyrostat
def gyrostat(inertia, axis, rate, wheel_momentum, *, wheel_inertia=None, damper=None,
             damper_on: str = "platform") -> StabilityReport:
    """Dual-spin gyrostat: platform spinning at ``rate`` about ``axis``, a wheel along
    ``axis`` with relative momentum ``h`` held constant, optionally an energy damper.

    Without damper the transverse rates obey ``Ib wb' = (Ic W - Ia W - h) wc`` and
    ``Ic wc' = (Ia W + h - Ib W) wb``: eigenvalues ``+/- sqrt(-(Ia W + h - Ib W)(Ia W + h
    - Ic W) / (Ib Ic))``, unstable iff ``Ia + h/W`` lies between ``Ib`` and ``Ic``
    (boundaries ``h = (Ib - Ia) W``, ``(Ic - Ia) W``). With a `SphericalDamper` and
    ``Ib = Ic = It`` the eigenvalues are closed-form too (see `_spherical_roots`); the
    boundary, where the housing turns at the nutation rate, is ``h = (It - Ia) W`` on the
    platform and ``(Ia - It) W + (J_r - It) W_r = 0`` (``W_r = h / J_r``) on the rotor.

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2]
        Platform plus wheel (locked) about the mass center; without damper mass / core.
    axis : array_like, shape (3,) — wheel and spin axis, a principal axis of ``inertia``
    rate : float [rad/s] — platform spin ``W`` (0: despun platform)
    wheel_momentum : float [N m s] — ``h = J_r W_r``, relative to the platform
    wheel_inertia : float [kg m^2], optional — ``J_r``, needed for a damper on the rotor
    damper : PointMassDamper or SphericalDamper, optional
    damper_on : {'platform', 'rotor'}

    Returns
    -------
    StabilityReport

    Raises
    ------
    ValueError
        Naming the argument.
    """
    I = check_inertia(inertia)
    a = unit_vector(axis, "axis")
    W = _num(rate, "rate")
    h = _num(wheel_momentum, "wheel_momentum")
    Ia, Ib, Ic = _principal(I, a)
    if damper_on not in ("platform", "rotor"):
        raise ValueError(f"`damper_on` must be 'platform' or 'rotor', got {damper_on!r}")
    Wr = 0.0
    if wheel_inertia is not None:
        Jr = _num(wheel_inertia, "wheel_inertia", positive=True)
        if Jr > Ia:
            raise ValueError(f"`wheel_inertia` {Jr} exceeds the axial moment Ia = {Ia} of "
                             "`inertia`, which includes the wheel")
        Wr = h / Jr
    elif damper is not None and damper_on == "rotor":
        raise ValueError("`wheel_inertia` is needed for a damper on the rotor (its housing "
                         "turns at rate + wheel_momentum / wheel_inertia)")
    if W == 0 and h == 0:
        raise ValueError("`rate` and `wheel_momentum` are both zero: nothing spins")
    model = gyrostat_model(I, wheel_axis=a, wheel_momentum=h, damper=damper,
                           damper_on=damper_on, wheel_rate=Wr)
    x = steady_spin_state(a, W, damper=damper, damper_on=damper_on, wheel_rate=Wr)
    lin = _case_linearization(model, x, "rates", damper)
    red, notes = _reduce_free_spin(model, x, lin)
    notes = list(red.notes) + notes
    params = {"inertia": I, "axis": a, "rate": W, "wheel_momentum": h,
              "wheel_inertia": wheel_inertia, "damper": _damper_dict(damper),
              "damper_on": damper_on}
    Ha = Ia * W + h
    quantities = [Quantity("axial momentum Ia W + h", None, Ha, "N m s"),
                  Quantity("effective axial moment Ia + h/W", None,
                           Ia + h / W if W else math.inf, "kg m^2")]
    cf = None
    if damper is None:
        lam2 = -(Ha - Ib * W) * (Ha - Ic * W) / (Ib * Ic)
        root = np.sqrt(complex(lam2))
        cf = np.array([root, -root])
        lo, hi = sorted([(Ib - Ia) * W, (Ic - Ia) * W])
        quantities += [Quantity("boundary h = (Ib - Ia) W", None, (Ib - Ia) * W, "N m s"),
                       Quantity("boundary h = (Ic - Ia) W", None, (Ic - Ia) * W, "N m s")]
        notes.append(f"undamped: unstable for {lo:.10g} < h < {hi:.10g} N m s")
    elif isinstance(damper, SphericalDamper) and abs(Ib - Ic) <= 1e-12 * Ib:
        It, Jd = Ib, damper.inertia
        wd = W + (Wr if damper_on == "rotor" else 0.0)
        cf = _spherical_roots(It, Jd, damper.damping, Ha, W, wd, Ia)
        if damper_on == "platform":
            quantities.append(Quantity("boundary h = (It - Ia) W", None, (It - Ia) * W, "N m s",
                                       "housing at the nutation rate"))
        elif wheel_inertia is not None and It != Jr:
            quantities.append(Quantity("boundary h = Jr (Ia - It) W / (It - Jr)", None,
                                       Jr * (Ia - It) * W / (It - Jr), "N m s",
                                       "housing at the nutation rate"))
    rates = [s for s in red.states if s in ("w1", "w2", "w3")]
    title = "Gyrostat (dual spin)" + (f" with a {type(damper).__name__} on the {damper_on}"
                                      if damper else "")
    others = [s for s in red.states if s not in rates]
    return build_report("gyrostat", title, params, red.ss, lin=lin, closed_form=cf,
                        groups={"nutation": rates, "damper": others},
                        quantities=quantities, notes=notes)


# --------------------------------------------------------------------------- loop
def loop(plant, controller, *, title: str = "Feedback loop", closed_form=None) -> StabilityReport:
    """Closed-loop stability and margins of ``plant`` under ``u = -controller(y)``.

    Parameters
    ----------
    plant : control.StateSpace or control.TransferFunction
        ``ny`` outputs, ``nu`` inputs.
    controller : array_like, shape (nu, ny), or control.StateSpace / TransferFunction
        A static gain or a dynamic compensator from ``y`` to ``u`` (negative feedback).
    title : str, optional
    closed_form : array_like of complex, optional — expected closed-loop eigenvalues

    Returns
    -------
    StabilityReport
        ``ss`` is the closed loop (input added at the plant input, outputs ``y``); ``margins``
        of the loop transfer ``L = controller * plant`` broken at the plant input, when it
        is single-input (``None`` otherwise, with a note).

    Raises
    ------
    ValueError
        Naming ``plant`` or ``controller`` when they are not LTI systems or do not fit.
    """
    import control

    if isinstance(plant, control.TransferFunction):
        plant = control.ss(plant)
    if not isinstance(plant, control.StateSpace):
        raise ValueError(f"`plant` must be a control.StateSpace or TransferFunction, got "
                         f"{type(plant).__name__}")
    if isinstance(controller, control.TransferFunction):
        controller = control.ss(controller)
    if not isinstance(controller, control.StateSpace):
        try:
            K = np.atleast_2d(np.asarray(controller, dtype=float))
        except (TypeError, ValueError):
            raise ValueError("`controller` must be a gain matrix or an LTI system, got "
                             f"{type(controller).__name__}") from None
        if K.shape != (plant.ninputs, plant.noutputs) or not np.all(np.isfinite(K)):
            raise ValueError(f"`controller` gain must be finite with shape (nu, ny) = "
                             f"({plant.ninputs}, {plant.noutputs}), got {K.shape}")
        controller = control.ss(np.zeros((0, 0)), np.zeros((0, plant.noutputs)),
                                np.zeros((plant.ninputs, 0)), K, name="controller")
    if controller.ninputs != plant.noutputs or controller.noutputs != plant.ninputs:
        raise ValueError(f"`controller` must map the {plant.noutputs} plant outputs to the "
                         f"{plant.ninputs} plant inputs, got {controller.ninputs} -> "
                         f"{controller.noutputs}")
    closed = control.feedback(plant, controller, sign=-1)
    k_states = [f"k_{s}" for s in controller.state_labels]
    closed = control.ss(closed.A, closed.B, closed.C, closed.D,
                        states=list(plant.state_labels) + k_states,
                        inputs=list(plant.input_labels), outputs=list(plant.output_labels),
                        name="closed_loop")
    margins, notes = None, []
    if plant.ninputs == 1:
        L = control.series(plant, controller)
        gm, pm, sm, wpc, wgc, wms = control.stability_margins(L)
        gm = float(gm)
        margins = Margins(gain_margin=gm,
                          gain_margin_db=20 * math.log10(gm) if gm > 0 and math.isfinite(gm)
                          else (math.inf if gm == math.inf else math.nan),
                          phase_margin=float(pm), stability_margin=float(sm),
                          phase_crossover=float(wpc), gain_crossover=float(wgc),
                          stability_margin_frequency=float(wms))
    else:
        notes.append(f"margins need a single loop; the plant has {plant.ninputs} inputs")
    groups = {"plant": list(plant.state_labels),
              "controller": k_states}
    return build_report("loop", title, {"plant": plant.name, "controller": controller.name},
                        closed, groups=groups, margins=margins, notes=notes,
                        closed_form=closed_form)


# -------------------------------------------------------------------------- sweep
CASES: dict[str, Callable[..., StabilityReport]] = {
    "spin": spin, "heavy_top": heavy_top, "spinning_projectile": spinning_projectile,
    "rotor": rotor, "gyrostat": gyrostat,
}
_ALIASES = {"heavy-top": "heavy_top", "projectile": "spinning_projectile",
            "spinning-projectile": "spinning_projectile"}


@dataclass(frozen=True)
class Boundary:
    """A change of verdict located by bisection.

    Attributes
    ----------
    value : float — midpoint of the final bracket
    lower, upper : float — the bracket, ``|upper - lower| <= rtol * |value|``
    before, after : str — verdicts at ``lower`` and ``upper`` (in sweep order)
    """

    value: float
    lower: float
    upper: float
    before: str
    after: str


@dataclass(frozen=True)
class SweepResult:
    """Verdicts and least-damped eigenvalues of a case along one parameter.

    Attributes
    ----------
    case : str
    parameter : str
    values : ndarray, shape (n,)
    verdicts : tuple of str, length n
    least_damped : ndarray of complex, shape (n,) [1/s]
    eigenvalues : ndarray of complex, shape (n, m) — sorted by (Re, Im); nan-padded
    boundaries : tuple of Boundary
    rtol : float
    evaluations : int — case evaluations, bisection included
    case_kwargs : dict — the fixed arguments as plain Python values
    """

    case: str
    parameter: str
    values: np.ndarray
    verdicts: tuple
    least_damped: np.ndarray
    eigenvalues: np.ndarray
    boundaries: tuple
    rtol: float
    evaluations: int
    case_kwargs: dict

    def to_dict(self) -> dict:
        """JSON-ready summary (complex as ``[re, im]``)."""
        return jsonable({"case": self.case, "parameter": self.parameter,
                          "values": self.values, "verdicts": list(self.verdicts),
                          "least_damped": self.least_damped, "eigenvalues": self.eigenvalues,
                          "boundaries": [asdict(b) for b in self.boundaries],
                          "rtol": self.rtol, "evaluations": self.evaluations,
                          "case_kwargs": self.case_kwargs})

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), indent=2, allow_nan=False)

    def __str__(self) -> str:
        lines = [f"Sweep of {self.case} over {self.parameter} ({len(self.values)} values, "
                 f"{self.evaluations} evaluations)"]
        if self.case_kwargs:
            lines.append("  fixed: " + param_text(self.case_kwargs))
        lines.append(f"  {self.parameter:>16}  {'verdict':<22} "
                     f"{'least-damped eigenvalue [1/s]':>33}")
        for v, verdict, z in zip(self.values, self.verdicts, self.least_damped):
            lines.append(f"  {v:>16.8g}  {verdict:<22} {format_complex(z):>33}")
        if self.boundaries:
            lines.append(f"boundaries (bisection to {self.rtol:.0e} relative):")
            for b in self.boundaries:
                lines.append(f"  {self.parameter} = {b.value:.12g}   {b.before} -> {b.after}")
        else:
            lines.append("no verdict change along the sweep")
        return "\n".join(lines)

    def plot(self, path) -> None:
        """Write real and imaginary parts of every eigenvalue versus the parameter (PNG)."""
        from matplotlib.figure import Figure

        fig = Figure(figsize=(8.0, 6.5))
        ax1, ax2 = fig.add_subplot(2, 1, 1), fig.add_subplot(2, 1, 2)
        ev = self.eigenvalues
        for j in range(ev.shape[1]):
            ax1.plot(self.values, ev[:, j].real, ".", ms=3, color="tab:blue")
            ax2.plot(self.values, ev[:, j].imag, ".", ms=3, color="tab:blue")
        ax1.plot(self.values, self.least_damped.real, "-", color="tab:red", lw=1,
                 label="least damped")
        for b in self.boundaries:
            for ax in (ax1, ax2):
                ax.axvline(b.value, color="k", ls="--", lw=0.8)
        ax1.axhline(0, color="0.5", lw=0.8)
        ax1.set_ylabel("Re [1/s]")
        ax2.set_ylabel("Im [rad/s]")
        ax2.set_xlabel(self.parameter)
        ax1.set_title(f"{self.case}: eigenvalues vs {self.parameter} (dashed: boundaries)")
        ax1.legend(fontsize=8)
        for ax in (ax1, ax2):
            ax.grid(True, alpha=0.3)
        fig.tight_layout()
        fig.savefig(path, dpi=110, format="png")


def _resolve_case(case):
    if callable(case):
        for name, fun in CASES.items():
            if fun is case:
                return name, fun
        raise ValueError(f"`case` must be one of {sorted(CASES)} (or the function), got {case!r}")
    name = _ALIASES.get(case, case)
    if name not in CASES:
        raise ValueError(f"`case` must be one of {sorted(CASES)}, got {case!r}")
    return name, CASES[name]


def sweep(case, parameter: str, values, *, rtol: float = 1e-8, progress=None,
          **case_kwargs) -> SweepResult:
    """Run ``case`` for each value of ``parameter`` and locate the verdict boundaries.

    Between consecutive values with different verdicts the boundary is bisected until the
    bracket is within ``rtol`` of its magnitude (1e-8 by default). Between "asymptotically
    stable" and "unstable" the sign of the largest real part is bisected instead of the
    verdict: it crosses zero continuously, while the verdict's zero band around the crossing
    (``|Re| <= ZERO_RTOL rho``, about ``ZERO_RTOL rho / |d Re / d parameter|`` wide) would
    give two boundaries. The same holds when a grid value falls inside that band: a
    "marginally stable" stretch narrower than 1e-4 relative between "unstable" and
    "asymptotically stable" is reported as one boundary at the crossing.

    Parameters
    ----------
    case : str or callable — a name in `CASES` (``'heavy-top'`` and ``'projectile'`` also
        work) or the case function
    parameter : str — the keyword swept, e.g. ``'rate'`` or ``'wheel_momentum'``
    values : array_like, shape (n,) — strictly increasing, finite, ``n >= 1``
    rtol : float — relative bracket width of the bisection
    progress : callable, optional — ``progress(done, total)`` after each grid value
        (``total = len(values)``; the bisections that follow are not counted)
    **case_kwargs — the case's other arguments (by keyword)

    Returns
    -------
    SweepResult

    Raises
    ------
    ValueError
        Naming ``case``, ``parameter``, ``values`` or ``rtol``; a ValueError of the case at
        one value is re-raised with that value.
    """
    name, fun = _resolve_case(case)
    sig = inspect.signature(fun)
    if parameter not in sig.parameters:
        raise ValueError(f"`parameter` must be an argument of {name}: {list(sig.parameters)}, "
                         f"got {parameter!r}")
    if parameter in case_kwargs:
        raise ValueError(f"`{parameter}` is swept; do not pass it in case_kwargs")
    try:
        vals = np.array(values, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise ValueError(f"`values` must be numbers, got {values!r}") from None
    if vals.size < 1 or not np.all(np.isfinite(vals)) or np.any(np.diff(vals) <= 0):
        raise ValueError(f"`values` must be finite and strictly increasing, got {vals.tolist()}")
    if not (np.isfinite(rtol) and 1e-15 <= rtol < 1):
        raise ValueError(f"`rtol` must be in [1e-15, 1), got {rtol}")
    try:
        sig.bind(**{parameter: vals[0]}, **case_kwargs)
    except TypeError as exc:
        raise ValueError(f"`case_kwargs` do not fit {name}{sig}: {exc}") from None

    count = [0]

    def run(v):
        count[0] += 1
        try:
            return fun(**{parameter: float(v)}, **case_kwargs)
        except ValueError as exc:
            raise ValueError(f"{name} at {parameter} = {float(v)!r}: {exc}") from None

    reports = []
    for v in vals:
        reports.append(run(v))
        if progress is not None:
            progress(len(reports), len(vals))
    verdicts = tuple(r.verdict for r in reports)

    def narrow(lo, hi):
        return abs(hi - lo) > rtol * max(abs(lo), abs(hi)) and lo < 0.5 * (lo + hi) < hi

    def crossing(lo, hi, unstable_at_lo):
        """Bisect the sign of the largest real part (continuous through the crossing)."""
        while narrow(lo, hi):
            mid = 0.5 * (lo + hi)
            if (run(mid).least_damped().real > 0) == unstable_at_lo:
                lo = mid
            else:
                hi = mid
        return lo, hi

    def locate(a, va, b, vb):
        if {va, vb} == _STABLE_UNSTABLE:
            lo, hi = crossing(a, b, va == "unstable")
            return [Boundary(0.5 * (lo + hi), lo, hi, va, vb)]
        lo, hi, vhi = a, b, vb
        while narrow(lo, hi):
            mid = 0.5 * (lo + hi)
            vm = run(mid).verdict
            if vm == va:
                lo = mid
            else:
                hi, vhi = mid, vm
        found = [Boundary(0.5 * (lo + hi), lo, hi, va, vhi)]
        if vhi != vb:
            found += locate(hi, vhi, b, vb)
        return found

    found = []
    for i in range(len(vals) - 1):
        if verdicts[i] != verdicts[i + 1]:
            found += locate(vals[i], verdicts[i], vals[i + 1], verdicts[i + 1])
    boundaries = []
    for bnd in found:
        prev = boundaries[-1] if boundaries else None
        if prev is not None and prev.after == bnd.before:
            gap = abs(bnd.upper - prev.lower)
            scale = max(abs(prev.value), abs(bnd.value))
            if {prev.before, bnd.after} == _STABLE_UNSTABLE and gap <= _BAND_RTOL * scale:
                # a zero band of the verdict around a crossing: one boundary, at the crossing
                lo, hi = crossing(prev.lower, bnd.upper, prev.before == "unstable")
                boundaries[-1] = Boundary(0.5 * (lo + hi), lo, hi, prev.before, bnd.after)
                continue
            if gap <= rtol * scale and prev.before != bnd.after:
                boundaries[-1] = Boundary(0.5 * (prev.lower + bnd.upper), prev.lower, bnd.upper,
                                          prev.before, bnd.after)
                continue
        boundaries.append(bnd)
    m = max(len(r.eigenvalues) for r in reports)
    ev = np.full((len(vals), m), np.nan + 1j * np.nan, dtype=complex)
    for i, r in enumerate(reports):
        ev[i, :len(r.eigenvalues)] = r.eigenvalues
    return SweepResult(case=name, parameter=parameter, values=vals, verdicts=verdicts,
                       least_damped=np.array([r.least_damped() for r in reports], dtype=complex),
                       eigenvalues=ev, boundaries=tuple(boundaries), rtol=float(rtol),
                       evaluations=count[0], case_kwargs=plain(case_kwargs))
