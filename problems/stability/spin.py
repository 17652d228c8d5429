"""Free-spin cases: `spin` (any scene; a rigid body, optionally with an energy damper) and
`gyrostat` (dual spin).

Every case builds its vehicle as a `dynamics.scene.Scene` and analyses its spin with
`problems.stability.spin_scene`: linearized in body rates (``frame='rates'``; the attitude
does not enter torque-free dynamics) and restricted to the first integrals (``|H|^2``, the
parts' conserved invariants), which removes the eigenvalue 0 of the neighbouring steady
spins; the notes say which state went. The closed forms stay per case.
"""
from __future__ import annotations

import math

import numpy as np

from appdyn.dynamics.rigid_body import check_inertia
from appdyn.dynamics.scene import (ExternalForce, ExternalTorque, FlexibleAppendage, HeldRotor,
                                   ReactionWheels, RigidHub, Scene, TiltTorque)
from appdyn.dynamics.spinning import (PointMassDamper, SphericalDamper, gyrostat_scene,
                                      unit_vector)
from appdyn.dynamics.results import timed

from .closed_forms import (axis_kind, gyrostat_lambda2, method3_roots, principal_moments,
                           rigid_spin_lambda2, spherical_damper_roots, with_conjugates)
from .common import check_number, plain
from .report import Quantity, StabilityReport, build_report
from .spin_scene import spin_linearization

__all__ = ["spin", "gyrostat"]


def _damper_dict(damper):
    return None if damper is None else plain(damper)


@timed
def spin(inertia, axis, rate, *, damper=None) -> StabilityReport:
    """Spin ``w = rate * axis`` of a scene, or torque-free spin of a rigid body about a
    principal axis, optionally with a damper.

    Given a `dynamics.scene.Scene` (``spin(scene, axis, rate)``): the relative equilibrium
    with every part at rest relative to the hub (`problems.stability.spin_scene`: part
    speeds from `Part.spin_speeds`, part coordinates solved so that the part speeds stay
    constant), linearized in body rates, reduced by the momentum and the parts' first
    integrals, modes labelled by part (``'nutation'`` for the hub, else the part's name).
    Closed forms where known: a hub with held rotors and reaction wheels (at rest relative
    to the hub, axes along or normal to the spin) spins as a gyrostat of wheel momentum
    ``h = sum(held momenta) + rate sum(J_i, wheels along the axis)``; a hub with one energy
    damper as below; a hub symmetric about the axis under an upright `TiltTorque` by
    Method III (Eq. 4.127, in the frame spinning with the hub).

    The body-rate perturbations (Rheinfurth & Wilson, NASA RP-1262, Sec. 4.5 C,
    Eqs. 4.94-4.95) have the eigenvalues
    ``+/- i rate sqrt((Ia - Ib)(Ia - Ic) / (Ib Ic))`` (a real pair about the intermediate
    axis). With an energy damper (`PointMassDamper` or `SphericalDamper` on the body, a
    multibody `dynamics.spinning.gyrostat_model`) the spin is asymptotically stable about the
    major axis and unstable about the minor one (Kelvin-Tait-Chetaev; RP-1262, Sec. 4.5,
    NOTE).

    The model is linearized in body rates (``frame='rates'``; the attitude does not enter
    torque-free dynamics) and restricted to constant ``|H|``, which removes the eigenvalue 0
    of the neighbouring steady spins (one spin-axis state is eliminated).

    Parameters
    ----------
    inertia : Scene, or array_like, shape (3, 3) or (3,) [kg m^2]
        A scene (a six-degree-of-freedom hub is reduced to its attitude with the system mass
        centre at rest: `~problems.stability.spin_scene.attitude_subsystem`), or the inertia of the rigid body about its mass
        center (without the damper mass / core inertia).
    axis : array_like, shape (3,)
        Spin axis in body (hub) axes; must be a principal axis of the (loaded) body.
    rate : float [rad/s]
        Spin rate, finite and non-zero (a scene: finite).
    damper : PointMassDamper or SphericalDamper, optional
        An energy damper on the body (not with a scene: mount it on the scene).

    Returns
    -------
    StabilityReport
        Closed forms for the rigid body and for a symmetric body with a spherical damper
        (`~problems.stability.closed_forms.spherical_damper_roots`); mode labels
        'nutation' / 'damper'.

    Raises
    ------
    ValueError
        Naming ``inertia``, ``axis``, ``rate`` or ``damper`` (e.g. a damper position that
        makes the axis non-principal for the loaded body: the residual is shown).

    References
    ----------
    Rheinfurth & Wilson, NASA RP-1262, Sec. 4.5 C, Eqs. 4.94-4.95 (rigid body);
    Sec. 4.5, NOTE (energy dissipation).

    Examples
    --------
    >>> from appdyn.problems import stability
    >>> rep = stability.spin([2.0, 3.0, 4.5], axis=[1, 0, 0], rate=10.0)
    >>> rep.verdict
    'marginally stable'
    >>> print(rep.eigenvalues.round(4))
    [0.-4.3033j 0.+4.3033j]
    >>> stability.spin([2.0, 3.0, 4.5], [0, 1, 0], 10.0).verdict  # intermediate axis
    'unstable'
    >>> damper = stability.PointMassDamper(mass=0.5, stiffness=60.0, damping=0.8,
    ...                                    position=[0, 0.6, 0], direction=[1, 0, 0])
    >>> stability.spin([2.0, 3.0, 4.5], [1, 0, 0], 4.0, damper=damper).verdict  # minor axis
    'unstable'

    A scene: a hub with a held rotor (a gyrostat, ``Ia + h/W = 4.5`` between 4 and 5):

    >>> from appdyn.dynamics.scene import HeldRotor, RigidHub, Scene
    >>> rep = stability.spin(Scene(RigidHub([3.0, 4.0, 5.0]), HeldRotor([1, 0, 0], 3.0)),
    ...                      [1, 0, 0], 2.0)
    >>> rep.verdict, rep.status, [m.label for m in rep.modes]
    ('unstable', 0, ['nutation', 'nutation'])
    """
    if isinstance(inertia, Scene):
        if damper is not None:
            raise ValueError("`damper` is for an inertia; mount the damper on the scene as a "
                             "part")
        return _scene_spin(inertia, axis, rate)
    I = check_inertia(inertia)
    a = unit_vector(axis, "axis")
    rate = check_number(rate, "rate", nonzero=True)
    Ia, Ib, Ic = principal_moments(I, a)
    if damper is not None and not isinstance(damper, (PointMassDamper, SphericalDamper)):
        raise ValueError("`damper` must be None, a PointMassDamper or a SphericalDamper, got "
                         f"{type(damper).__name__}")
    params = {"inertia": I, "axis": a, "rate": rate, "damper": _damper_dict(damper)}
    if damper is None:
        sl = _scene_case(Scene(RigidHub(I)), a, rate)
        title = "Torque-free spin about a principal axis (RP-1262, Sec. 4.5)"
        kind = axis_kind(Ia, Ib, Ic)
        lam2 = rigid_spin_lambda2(Ia, Ib, Ic, rate)
        root = np.sqrt(complex(lam2))
        cf = np.array([root, -root])
        quantities = [Quantity("lambda^2 = -rate^2 (Ia - Ib)(Ia - Ic) / (Ib Ic)", None, lam2,
                               "1/s^2", "Eqs. 4.94-4.95")]
        if lam2 < 0:
            quantities.append(Quantity("nutation frequency (body rates)",
                                       _pair_frequency(sl.reduced.eigenvalues()),
                                       float(abs(root.imag)), "rad/s",
                                       "Sec. 4.5 C: sqrt(lambda1 lambda2)"))
        more = []
    else:
        sl = _scene_case(gyrostat_scene(I, wheel_axis=a, damper=damper), a, rate, damper=True)
        title = (f"Spin about a principal axis with a {type(damper).__name__} "
                 "(RP-1262, Sec. 4.5 NOTE)")
        kind, quantities, cf, more = _damper_terms(I, a, rate, damper, _damper_offset(sl))
    notes = _notes(sl) + more
    notes.insert(0, f"spin about the {kind} axis{' of the loaded body' if damper else ''}; "
                    f"rigid moments Ia = {Ia:.10g}, Ib = {Ib:.10g}, Ic = {Ic:.10g} kg m^2")
    return build_report("spin", title, params, sl.reduced.ss, lin=sl.lin, closed_form=cf,
                        groups=sl.groups, quantities=quantities, notes=notes)


def _damper_offset(sl) -> float:
    """The point-mass damper's resting displacement ``s`` [m] at the spin point (0 else)."""
    return float(sl.point.values[0]) if sl.point.values else 0.0


def _damper_terms(I, a, rate, damper, s) -> tuple:
    """``(kind, quantities, closed_form, notes)`` of a torque-free body carrying one energy
    damper: its loaded moments, the locked-damper ``lambda^2``, the closed form of a
    symmetric body with a spherical damper and the Kelvin-Tait-Chetaev note."""
    Ia, Ib, Ic = principal_moments(I, a)
    comp = I + (damper.inertia_at(s) if isinstance(damper, PointMassDamper)
                else damper.inertia * np.eye(3))
    Ja, Jb, Jc = principal_moments(comp, a)
    kind = axis_kind(Ja, Jb, Jc)
    quantities = [Quantity("loaded axial moment Ja", None, Ja, "kg m^2"),
                  Quantity("loaded transverse moment Jb", None, Jb, "kg m^2"),
                  Quantity("loaded transverse moment Jc", None, Jc, "kg m^2"),
                  Quantity("locked-damper lambda^2 = -rate^2 (Ja-Jb)(Ja-Jc)/(Jb Jc)", None,
                           rigid_spin_lambda2(Ja, Jb, Jc, rate), "1/s^2",
                           "Eqs. 4.94-4.95, damper locked")]
    cf, notes = None, []
    if isinstance(damper, SphericalDamper) and abs(Ib - Ic) <= 1e-12 * Ib:
        cf = spherical_damper_roots(Ib, damper.inertia, damper.damping, Ia * rate, rate, rate,
                                    Ia)
    expected = {"major": "asymptotically stable", "minor": "unstable",
                "intermediate": "unstable"}.get(kind)
    if expected:
        notes.append(f"Kelvin-Tait-Chetaev: energy dissipation makes a {kind}-axis spin "
                     f"{expected} (if the damper is excited by the nutation)")
    return kind, quantities, cf, notes


def _held_momentum(scene: Scene, a) -> tuple | None:
    """``(per_rate, held)``: the axial wheel momentum per unit rate [N m s^2] and the held
    momentum [N m s] of a scene whose parts are held rotors along ``a``, reaction wheels
    along or normal to it, and loads; None for any other part (no closed form)."""
    per_rate, held = 0.0, 0.0
    for part in scene.parts:
        if isinstance(part, (ExternalTorque, ExternalForce)):
            continue
        if isinstance(part, HeldRotor) and abs(abs(np.dot(part.axis, a)) - 1) <= 1e-12:
            held += part.momentum * float(np.dot(part.axis, a))
        elif isinstance(part, ReactionWheels):
            c = part.axes_matrix.T @ a
            if np.any((np.abs(c) > 1e-12) & (np.abs(np.abs(c) - 1) > 1e-12)):
                return None
            per_rate += float(np.sum(np.asarray(part.inertia) * c ** 2))
        else:
            return None
    return per_rate, held


def _scene_spin(scene: Scene, axis, rate) -> StabilityReport:
    """`spin` of a scene (its docstring)."""
    a = unit_vector(axis, "axis")
    W = check_number(rate, "rate")
    sl = _scene_case(scene, a, W)
    notes, quantities, cf = _notes(sl), [], None
    rotors = _held_momentum(scene, a)
    damper, tilt = _lone_damper(scene), _upright_tilt(scene, a, sl)
    if tilt is not None:
        Ia, Ib, _ = principal_moments(scene.hub.inertia_matrix, a)
        (r1, r2), G, K = method3_roots(Ia, Ib, tilt.overturning, W, damping=tilt.internal_damping)
        cf = with_conjugates((r1, r2))
        quantities += [Quantity("K = (I1 - I2) w0^2 - kappa", None, K, "N m/rad",
                                "Eq. 4.122"),
                       Quantity("G = 2 I2 - I1", None, G, "kg m^2", "Eq. 4.122")]
        notes.append("eigenvalues in the frame spinning at w0 (Method III, Eq. 4.127)")
    elif damper is not None:
        kind, quantities, cf, more = _damper_terms(scene.hub.inertia_matrix, a, W, damper,
                                                   _damper_offset(sl))
        notes = [f"spin about the {kind} axis of the loaded body"] + notes + more
    elif rotors is not None:
        Ia, Ib, Ic = principal_moments(scene.hub.inertia_matrix, a)
        h = rotors[0] * W + rotors[1]
        lam2 = gyrostat_lambda2(Ia, Ib, Ic, W, h)
        root = np.sqrt(complex(lam2))
        cf = np.array([root, -root])
        quantities += [Quantity("axial wheel momentum h", None, h, "N m s"),
                       Quantity("lambda^2 = -(Ia W + h - Ib W)(Ia W + h - Ic W) / (Ib Ic)",
                                None, lam2, "1/s^2", "Eqs. 4.94-4.95 with a wheel")]
        if W:
            kind = axis_kind(Ia + h / W, Ib, Ic)
            notes.insert(0, f"spin about the {kind} axis of the hub with its wheels: "
                            f"Ia + h/W = {Ia + h / W:.10g}, Ib = {Ib:.10g}, Ic = {Ic:.10g} "
                            "kg m^2")
    title = f"Spin of {scene.name or 'a scene'} about a hub axis"
    params = {"scene": str(scene), "axis": a, "rate": W}
    return build_report("spin", title, params, sl.reduced.ss, lin=sl.lin, closed_form=cf,
                        groups=sl.groups, labeler=_modal_labeler(scene, sl),
                        quantities=quantities, notes=notes)


def _modal_labeler(scene: Scene, sl):
    """Mode labels naming the dominant modal coordinate of a flexible appendage
    (``'antenna_2: eta1_2'``: the part, then the coordinate of the largest eigenvector
    entry among the part's states, a rate named by its coordinate); None (labels by part)
    for a scene without one."""
    flexible = {name for name, part in zip(scene.part_names, scene.parts)
                if isinstance(part, FlexibleAppendage)}
    if not flexible:
        return None
    states = sl.reduced.states

    def label(_, v):
        share = {g: float(np.sum(np.abs(v[[states.index(s) for s in names]]) ** 2))
                 for g, names in sl.groups.items()}
        group = max(share, key=share.get)
        if group not in flexible:
            return group
        own = [states.index(s) for s in sl.groups[group]]
        best = states[max(own, key=lambda i: abs(v[i]))]
        return f"{group}: {best.replace('_dot', '')}"
    return label


def _upright_tilt(scene: Scene, a, sl):
    """The `TiltTorque` of a scene that is a hub symmetric about ``a`` with a tilt torque
    about ``a`` from the direction ``a`` (Method III upright) and loads, linearized in the
    spinning frame; None for any other scene."""
    parts = [p for p in scene.parts if not isinstance(p, (ExternalTorque, ExternalForce))]
    if len(parts) != 1 or not isinstance(parts[0], TiltTorque) or sl.lin.frame != "spinning":
        return None
    tilt = parts[0]
    _, Ib, Ic = principal_moments(scene.hub.inertia_matrix, a)
    aligned = min(np.dot(tilt.axis, a), np.dot(tilt.direction, a)) >= 1 - 1e-12
    return tilt if aligned and abs(Ib - Ic) <= 1e-12 * Ib else None


def _lone_damper(scene: Scene):
    """The energy damper of a scene that is a hub, one damper on the hub and loads; None for
    any other scene."""
    loads = (ExternalTorque, ExternalForce)
    dampers = [p for p in scene.parts if not isinstance(p, loads)]
    if len(dampers) != 1 or not (
            isinstance(dampers[0], PointMassDamper)
            or isinstance(dampers[0], SphericalDamper) and not any(dampers[0].housing_rate)):
        return None
    return dampers[0]


def _scene_case(scene: Scene, a, rate, *, damper: bool = False):
    """`spin_linearization` of a case's scene; with a damper, a spin that is no relative
    equilibrium is blamed on ``damper`` (the rigid body's axis was checked before)."""
    try:
        return spin_linearization(scene, a, rate)
    except ValueError as exc:
        if not damper:
            raise
        raise ValueError(f"`damper`: no steady spin about `axis` with this damper: {exc}") \
            from None


def _notes(sl) -> list:
    """The reduction's notes of a `SpinLinearization`."""
    return list(sl.reduced.notes) + list(sl.notes)


def _pair_frequency(ev) -> float | None:
    im = [abs(z.imag) for z in ev if abs(z.imag) > 0]
    return float(max(im)) if im else None


@timed
def gyrostat(inertia, axis, rate, wheel_momentum, *, wheel_inertia=None, damper=None,
             damper_on: str = "platform") -> StabilityReport:
    """Dual-spin gyrostat: platform spinning at ``rate`` about ``axis``, a wheel along
    ``axis`` with relative momentum ``h`` held constant, optionally an energy damper.

    Without damper the transverse rates obey ``Ib wb' = (Ic W - Ia W - h) wc`` and
    ``Ic wc' = (Ia W + h - Ib W) wb``: eigenvalues ``+/- sqrt(-(Ia W + h - Ib W)(Ia W + h
    - Ic W) / (Ib Ic))``, unstable iff ``Ia + h/W`` lies between ``Ib`` and ``Ic``
    (boundaries ``h = (Ib - Ia) W``, ``(Ic - Ia) W``). With a `SphericalDamper` and
    ``Ib = Ic = It`` the eigenvalues are closed-form too
    (`~problems.stability.closed_forms.spherical_damper_roots`); the boundary, where the
    housing turns at the nutation rate, is ``h = (It - Ia) W`` on the platform and
    ``(Ia - It) W + (J_r - It) W_r = 0`` (``W_r = h / J_r``) on the rotor.

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2]
        Platform plus wheel (locked) about the mass center; without damper mass / core.
    axis : array_like, shape (3,)
        Wheel and spin axis, body frame; a principal axis of ``inertia``.
    rate : float [rad/s]
        Platform spin ``W`` (0: despun platform).
    wheel_momentum : float [N m s]
        ``h = J_r W_r``, relative to the platform.
    wheel_inertia : float [kg m^2], optional
        ``J_r``, needed for a damper on the rotor.
    damper : PointMassDamper or SphericalDamper, optional
        An energy damper on the platform or in the rotor.
    damper_on : {'platform', 'rotor'}, optional
        Where the damper sits (default ``'platform'``).

    Returns
    -------
    StabilityReport

    Raises
    ------
    ValueError
        Naming the argument.

    Examples
    --------
    >>> from appdyn.problems import stability
    >>> rep = stability.gyrostat([3.0, 4.0, 5.0], [1, 0, 0], rate=2.0, wheel_momentum=3.0)
    >>> rep.verdict  # Ia + h/W = 4.5 lies between the transverse moments 4 and 5
    'unstable'
    >>> stability.gyrostat([3.0, 4.0, 5.0], [1, 0, 0], 2.0, wheel_momentum=6.0).verdict
    'marginally stable'
    """
    I = check_inertia(inertia)
    a = unit_vector(axis, "axis")
    W = check_number(rate, "rate")
    h = check_number(wheel_momentum, "wheel_momentum")
    Ia, Ib, Ic = principal_moments(I, a)
    if damper_on not in ("platform", "rotor"):
        raise ValueError(f"`damper_on` must be 'platform' or 'rotor', got {damper_on!r}")
    Wr = 0.0
    if wheel_inertia is not None:
        Jr = check_number(wheel_inertia, "wheel_inertia", positive=True)
        if Jr > Ia:
            raise ValueError(f"`wheel_inertia` {Jr} exceeds the axial moment Ia = {Ia} of "
                             "`inertia`, which includes the wheel")
        Wr = h / Jr
    elif damper is not None and damper_on == "rotor":
        raise ValueError("`wheel_inertia` is needed for a damper on the rotor (its housing "
                         "turns at rate + wheel_momentum / wheel_inertia)")
    if W == 0 and h == 0:
        raise ValueError("`rate` and `wheel_momentum` are both zero: nothing spins")
    scene = gyrostat_scene(I, wheel_axis=a, wheel_momentum=h, damper=damper,
                           damper_on=damper_on, wheel_rate=Wr)
    sl = _scene_case(scene, a, W, damper=damper is not None)
    lin, red, notes, groups = sl.lin, sl.reduced, _notes(sl), sl.groups
    params = {"inertia": I, "axis": a, "rate": W, "wheel_momentum": h,
              "wheel_inertia": wheel_inertia, "damper": _damper_dict(damper),
              "damper_on": damper_on}
    Ha = Ia * W + h
    quantities = [Quantity("axial momentum Ia W + h", None, Ha, "N m s"),
                  Quantity("effective axial moment Ia + h/W", None,
                           Ia + h / W if W else math.inf, "kg m^2")]
    cf = None
    if damper is None:
        lam2 = gyrostat_lambda2(Ia, Ib, Ic, W, h)
        root = np.sqrt(complex(lam2))
        cf = np.array([root, -root])
        lo, hi = sorted([(Ib - Ia) * W, (Ic - Ia) * W])
        quantities += [Quantity("boundary h = (Ib - Ia) W", None, (Ib - Ia) * W, "N m s"),
                       Quantity("boundary h = (Ic - Ia) W", None, (Ic - Ia) * W, "N m s")]
        notes.append(f"undamped: unstable for {lo:.10g} < h < {hi:.10g} N m s")
    elif isinstance(damper, SphericalDamper) and abs(Ib - Ic) <= 1e-12 * Ib:
        It, Jd = Ib, damper.inertia
        wd = W + (Wr if damper_on == "rotor" else 0.0)
        cf = spherical_damper_roots(It, Jd, damper.damping, Ha, W, wd, Ia)
        if damper_on == "platform":
            quantities.append(Quantity("boundary h = (It - Ia) W", None, (It - Ia) * W, "N m s",
                                       "housing at the nutation rate"))
        elif wheel_inertia is not None and It != Jr:
            quantities.append(Quantity("boundary h = Jr (Ia - It) W / (It - Jr)", None,
                                       Jr * (Ia - It) * W / (It - Jr), "N m s",
                                       "housing at the nutation rate"))
    title = "Gyrostat (dual spin)" + (f" with a {type(damper).__name__} on the {damper_on}"
                                      if damper else "")
    return build_report("gyrostat", title, params, red.ss, lin=lin, closed_form=cf,
                        groups=groups, quantities=quantities, notes=notes)


