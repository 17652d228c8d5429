"""Worked rigid-body systems with constraints (Rheinfurth & Wilson, NASA RP-1262, Ch. 6),
built on `dynamics.constrained` through `dynamics.mechanisms.lagrange`:

* `rolling_coin` -- a disk rolling without slipping (Example 4; nonholonomic), with the
  steady circular rolling of `coin_steady_rates`;
* `rolling_sphere` -- a uniform sphere rolling without slipping on a horizontal plane
  (Sec. 5.5 a; nonholonomic, the 2 x 5 constraint matrix `sphere_constraint_matrix`), with
  its states `sphere_state`;
* `dumbbell_disk` -- a dumbbell elastically hinged to a free disk at its mass centre
  (Example 2), with the exact frequency of its planar oscillation
  (`dumbbell_disk_frequency`).
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from .. import cache, validate
from ..attitude import dcm_from_euler321, dcm_from_quat, quat_rate
from ..constrained import DEFAULT_TIME_CONSTANT
from ..model import Model
from .common import GRAVITY, nonnegative, with_parameters
from .lagrange import checked_constants, constrained_model, lagrange_terms, stabilization

__all__ = ["rolling_coin", "coin_steady_rates", "coin_state", "rolling_sphere",
           "sphere_constraint_matrix", "sphere_state", "dumbbell_disk",
           "dumbbell_disk_state", "dumbbell_disk_frequency"]


# ------------------------------------------------------------------ rolling coin
_COIN = ("mass", "radius", "inertia_axial", "inertia_transverse", "gravity")


@cache.memoize
def _coin(tau) -> Model:
    x = ca.SX.sym("x", 12)
    p = ca.SX.sym("p", 5)
    m, R, I3, I1, g = (p[i] for i in range(5))
    q, v = x[:6], x[6:]
    psi, th = q[3], q[4]
    psid, thd, phid = v[3], v[4], v[5]
    T = (0.5 * m * ca.sumsqr(v[:3]) + 0.5 * I1 * (thd ** 2 + (psid * ca.sin(th)) ** 2)
         + 0.5 * I3 * (phid + psid * ca.cos(th)) ** 2)
    V = m * g * q[2]
    M, Q = lagrange_terms(T, V, q, v)
    node = ca.vertcat(ca.cos(psi), ca.sin(psi), 0)
    axis = ca.vertcat(ca.sin(th) * ca.sin(psi), -ca.sin(th) * ca.cos(psi), ca.cos(th))
    down = ca.vertcat(ca.cos(th) * ca.sin(psi), -ca.cos(th) * ca.cos(psi), -ca.sin(th))
    spin = psid * ca.vertcat(0, 0, 1) + thd * node + phid * axis
    contact = v[:3] + ca.cross(spin, R * down)
    energy = T + V
    return constrained_model("rolling_coin", ("x", "y", "z", "psi", "theta", "phi"),
                  ("m",) * 3 + ("rad",) * 3, ("m/s",) * 3 + ("rad/s",) * 3, q, v, None, p,
                  _COIN, {"mass": "kg", "radius": "m", "inertia_axial": "kg m^2",
                          "inertia_transverse": "kg m^2", "gravity": "m/s^2"},
                  [1.0, 0.1, 0.005, 0.0025, GRAVITY], M, Q,
                  position=q[2] - R * ca.sin(th), velocity=contact[:2], time_constant=tau,
                  extra=lambda lam: {"contact_force": -ca.vertcat(lam[1], lam[2], lam[0]),
                                     "energy": energy})


def rolling_coin(*, mass=1.0, radius=0.1, inertia_axial=None, inertia_transverse=None,
                 gravity=GRAVITY, time_constant=DEFAULT_TIME_CONSTANT) -> Model:
    """A disk (coin) rolling without slipping on a horizontal plane (Ch. 6 Example 4): a
    nonholonomic system.

    Coordinates: the centre ``(x, y, z)`` (``z`` up) and the 3-1-3 angles ``(psi, theta,
    phi)`` of the disk (``theta`` between its symmetry axis ``n`` and the vertical: upright
    at ``theta = pi/2``). With ``e = (cos psi, sin psi, 0)`` (the horizontal diameter),
    ``n = (sin th sin psi, -sin th cos psi, cos th)`` and the lowest rim direction
    ``d = (cos th sin psi, -cos th cos psi, -sin th)``::

        T = 1/2 m |v|^2 + 1/2 I1 (th'^2 + psi'^2 sin^2 th) + 1/2 I3 (phi' + psi' cos th)^2
        V = m g z,     Omega = psi' k + th' e + phi' n

    Constraints: contact ``phi = z - R sin th = 0`` (holonomic) and the horizontal
    components of the contact-point velocity ``v + Omega x (R d)`` (nonholonomic; the
    vertical one is ``phi'``). The reaction on the coin's centre is the contact force
    ``-(lam2, lam3, lam1)``, with its moment about the centre.

    Parameters
    ----------
    mass : float [kg]
        ``> 0``.
    radius : float [m]
        ``> 0``.
    inertia_axial, inertia_transverse : float [kg m^2], optional
        ``I3``, ``I1`` about the centre (``> 0``; default a thin disk: ``m R^2 / 2``,
        ``m R^2 / 4``).
    gravity : float [m/s^2]
        ``>= 0``.
    time_constant : float or None [s]
        Baumgarte time constant; ``None``: none.

    Returns
    -------
    Model
        ``x = [x, y, z, psi, theta, phi, <rates>]``; invariants ``multipliers``,
        ``contact_force`` [N] (inertial), ``energy`` [J] and ``constraint_residual``.
        Steady rolling: `coin_steady_rates`, `coin_state`.

    Raises
    ------
    ValueError
        Naming ``mass``, ``radius`` or an inertia (not positive), ``gravity`` (negative) or
        ``time_constant``.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.mechanisms import coin_state, rolling_coin
    >>> model = rolling_coin(gravity=9.81)
    >>> x0 = coin_state(np.pi / 2, 0.0, 10.0, radius=0.1)    # upright, rolling at 1 m/s
    >>> float(np.abs(model.rhs(x0)[6:]).max()) < 1e-12        # goes straight on
    True
    >>> (model.invariant("contact_force", x0).ravel() + 0.0).round(6).tolist()
    [0.0, 0.0, 9.81]
    """
    tau = stabilization(time_constant)
    m = validate.positive(mass, "mass")
    R = validate.positive(radius, "radius")
    I3 = m * R * R / 2 if inertia_axial is None else inertia_axial
    I1 = m * R * R / 4 if inertia_transverse is None else inertia_transverse
    vals = checked_constants(dict(mass=m, radius=R, inertia_axial=I3, inertia_transverse=I1,
                         gravity=gravity), ("inertia_axial", "inertia_transverse"), ("gravity",))
    return with_parameters(_coin(tau), vals)


def coin_steady_rates(theta, path_radius, *, mass=1.0, radius=0.1, inertia_axial=None,
                      inertia_transverse=None, gravity=GRAVITY) -> tuple[float, float]:
    """Steady rolling in a circle: the turn rate ``psi'`` and spin ``phi'`` [rad/s] for the
    tilt ``theta`` and the radius ``a`` of the circle of the centre.

    Derivation: with ``theta`` constant, ``Omega = W k + s n`` (``W = psi'``, ``s = phi'``);
    ``k x d = cos th e``, ``n x d = e``, so rolling gives ``v = -R w3 e`` with the axial
    rate ``w3 = W cos th + s``; the centre circles ``O = C - a h`` (``h`` horizontal,
    normal to ``e``, towards the raised side) at ``v = a W e``: ``a W = -R w3``. Euler about
    the centre, ``H = I1 W k + (I3 w3 - I1 W cos th) n``, ``H' = (I3 w3 - I1 W cos th) W
    sin th e``, equals the moment ``R d x m (a_c + g k) = m R (a W^2 sin th - g cos th) e``::

        W^2 sin th ((I3 + m R^2) a / R + I1 cos th) = m g R cos th

    The speed of the centre is ``|a W|``; the disk leans towards the centre of the circle
    (``a > 0`` for ``theta < pi/2``). Upright (``cos th = 0``) it rolls straight.

    Parameters
    ----------
    theta : float [rad]
        In ``(0, pi)``.
    path_radius : float [m]
        ``a``: signed, so that the right side over the bracket is positive.
    mass, radius, inertia_axial, inertia_transverse, gravity : float
        As for `rolling_coin`.

    Returns
    -------
    (float, float) [rad/s]
        ``(psi_dot, phi_dot)`` with ``psi_dot >= 0``.

    Raises
    ------
    ValueError
        Naming ``theta`` or ``path_radius`` when no steady rolling exists.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.mechanisms import coin_steady_rates
    >>> [round(r, 6) for r in coin_steady_rates(np.pi / 3, 0.5, gravity=9.81)]
    [2.725425, -14.989839]
    """
    th = validate.finite_scalar(theta, "theta")
    if not 0.0 < th < np.pi:
        raise ValueError(f"`theta` must lie in (0, pi), got {theta!r}")
    a = validate.finite_scalar(path_radius, "path_radius")
    m, R = validate.positive(mass, "mass"), validate.positive(radius, "radius")
    I3 = m * R * R / 2 if inertia_axial is None else validate.positive(inertia_axial,
                                                                      "inertia_axial")
    I1 = m * R * R / 4 if inertia_transverse is None else validate.positive(
        inertia_transverse, "inertia_transverse")
    g = nonnegative(gravity, "gravity")
    den = np.sin(th) * ((I3 + m * R * R) * a / R + I1 * np.cos(th))
    W2 = m * g * R * np.cos(th) / den if den != 0 else -1.0
    if not W2 >= 0 or not np.isfinite(W2):
        raise ValueError(f"`path_radius` {path_radius!r} admits no steady rolling at "
                         f"`theta` = {theta!r} (the turn rate squared would be {W2:g})")
    W = float(np.sqrt(W2))
    w3 = -a * W / R
    return W, float(w3 - W * np.cos(th))


def coin_state(theta, psi_dot, phi_dot, *, radius=0.1, psi=0.0, phi=0.0, theta_dot=0.0,
               x=0.0, y=0.0) -> np.ndarray:
    """A state of `rolling_coin` on its constraints (rolling, contact).

    Returns
    -------
    numpy.ndarray, shape (12,)

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import coin_state
    >>> (coin_state(1.5707963267948966, 0.0, 10.0)[6:9] + 0.0).round(6).tolist()
    [-1.0, 0.0, 0.0]
    """
    th, psi = validate.finite_scalar(theta, "theta"), validate.finite_scalar(psi, "psi")
    R = validate.positive(radius, "radius")
    W, thd, s = (validate.finite_scalar(a, k) for a, k in
                 ((psi_dot, "psi_dot"), (theta_dot, "theta_dot"), (phi_dot, "phi_dot")))
    node = np.array([np.cos(psi), np.sin(psi), 0.0])
    axis = np.array([np.sin(th) * np.sin(psi), -np.sin(th) * np.cos(psi), np.cos(th)])
    down = np.array([np.cos(th) * np.sin(psi), -np.cos(th) * np.cos(psi), -np.sin(th)])
    spin = np.array([0.0, 0.0, W]) + thd * node + s * axis
    v = -np.cross(spin, R * down)
    return np.r_[x, y, R * np.sin(th), psi, th, phi, v, W, thd, s]


# ------------------------------------------------------------------ rolling sphere
_SPHERE = ("mass", "radius", "inertia")
_SPHERE_COORDS = ("x", "z", "phi", "psi", "theta")


def _sphere_omega(q, qd):
    """Inertial angular velocity ``(wx, wy, wz)`` (``y`` up) of the 3-2-1 angles
    ``(psi, theta, phi)`` about the inertial axes ``(3, 2, 1)``: ``A = A1(phi) A2(theta)
    A3(psi)`` (inertial -> body) and ``w_body = (phi' - psi' s th, th' c ph + psi' c th s ph,
    -th' s ph + psi' c th c ph)``; ``w = A' w_body``."""
    phi, psi, th = q[2], q[3], q[4]
    phid, psid, thd = qd[2], qd[3], qd[4]
    c, s = ca.cos, ca.sin
    A = dcm_from_euler321(ca.vertcat(psi, th, phi))
    wb = ca.vertcat(phid - psid * s(th), thd * c(phi) + psid * c(th) * s(phi),
                    -thd * s(phi) + psid * c(th) * c(phi))
    return ca.mtimes(A.T, wb), A


@cache.memoize
def _sphere(tau) -> Model:
    x = ca.SX.sym("x", 10)
    p = ca.SX.sym("p", 3)
    m, a, I = p[0], p[1], p[2]
    q, v = x[:5], x[5:]
    w, _ = _sphere_omega(q, v)
    T = 0.5 * m * (v[0] ** 2 + v[1] ** 2) + 0.5 * I * ca.sumsqr(w)   # Eqs. 5.68, 5.73
    M, Q = lagrange_terms(T, 0.0, q, v)
    rolling = ca.vertcat(v[0] + a * w[2], v[1] - a * w[0])            # Eq. 5.71
    contact_point = ca.vertcat(q[0], 0.0, q[1])
    centre = ca.vertcat(q[0], a, q[1])
    momentum = I * w + m * ca.cross(centre - contact_point, ca.vertcat(v[0], 0.0, v[1]))
    return constrained_model("rolling_sphere", _SPHERE_COORDS, ("m",) * 2 + ("rad",) * 3,
                             ("m/s",) * 2 + ("rad/s",) * 3, q, v, None, p, _SPHERE,
                             {"mass": "kg", "radius": "m", "inertia": "kg m^2"},
                             [1.0, 0.1, 0.004], M, Q, velocity=rolling, time_constant=tau,
                             extra=lambda lam: {"energy": T, "omega": w,
                                                "contact_momentum": momentum})


def rolling_sphere(*, mass=1.0, radius=0.1, inertia=None,
                   time_constant=DEFAULT_TIME_CONSTANT) -> Model:
    """A uniform sphere rolling without slipping on a horizontal plane (Sec. 5.5 a): a
    nonholonomic system with the 2 x 5 constraint matrix of Eq. 5.72.

    Coordinates (the seed's order) ``q = [x, z, phi, psi, theta]``: the centre ``(x, a, z)``
    (``y`` up, the height ``a`` eliminated: Eq. 5.71's holonomic row) and the modern
    (3-2-1) angles, ``A = A1(phi) A2(theta) A3(psi)`` from the inertial axes to the body's
    (singular at ``theta = +-pi/2``). With the inertial angular velocity ``w`` (Eq. 5.70's
    components ``w_i = sum_k w_k A_ki``)::

        T = 1/2 m (x'^2 + z'^2) + 1/2 I |w|^2
          = 1/2 m (x'^2 + z'^2) + 1/2 I (th'^2 + psi'^2 + phi'^2 - 2 phi' psi' sin th)
        rolling  v_c = w x (a j):   x' + a w_z = 0,   z' - a w_x = 0     (C q' = 0, Eq. 5.72)

    held by two multipliers (`sphere_constraint_matrix` gives ``C``). The contact force
    exerts no moment about the contact point, so the angular momentum about it
    (``contact_momentum``) is conserved; with ``|w|`` and the speed fixed by it, the centre
    rolls on a straight line at constant velocity and ``w`` is constant.

    Parameters
    ----------
    mass : float [kg]
        ``> 0``.
    radius : float [m]
        ``a > 0``.
    inertia : float [kg m^2], optional
        ``I > 0`` about any diameter (default a uniform solid sphere ``2/5 m a^2``).
    time_constant : float or None [s]
        Baumgarte time constant; ``None``: none.

    Returns
    -------
    Model
        ``x = [x, z, phi, psi, theta, <rates>]``; invariants ``multipliers``, ``energy``
        [J], ``omega`` [rad/s] (inertial), ``contact_momentum`` [N m s] (angular momentum
        about the contact point, inertial) and ``constraint_residual``. Start on the
        constraints with `sphere_state`.

    Raises
    ------
    ValueError
        Naming ``mass``, ``radius``, ``inertia`` (not positive) or ``time_constant``.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.mechanisms import rolling_sphere, sphere_state
    >>> model = rolling_sphere()
    >>> x0 = sphere_state([1.0, 0.5], spin=3.0, angles=[0.1, 0.2, 0.3])
    >>> float(np.abs(model.rhs(x0)[:2] - [1.0, 0.5]).max()), float(np.abs(model.rhs(x0)[5:7]).max()) < 1e-12
    (0.0, True)
    """
    tau = stabilization(time_constant)
    m = validate.positive(mass, "mass")
    a = validate.positive(radius, "radius")
    I = 0.4 * m * a * a if inertia is None else inertia
    vals = checked_constants(dict(mass=m, radius=a, inertia=I), ("inertia",))
    return with_parameters(_sphere(tau), vals)


@cache.memoize
def _sphere_functions():
    q, qd, a = ca.SX.sym("q", 5), ca.SX.sym("qd", 5), ca.SX.sym("a")
    w, _ = _sphere_omega(q, qd)
    rolling = ca.vertcat(qd[0] + a * w[2], qd[1] - a * w[0])
    return (ca.Function("sphere_C", [q, a], [ca.jacobian(rolling, qd)]),
            ca.Function("sphere_W", [q], [ca.jacobian(w, qd[2:])]))


def sphere_constraint_matrix(q, *, radius=0.1) -> np.ndarray:
    """The constraint matrix ``C`` (2 x 5) of `rolling_sphere`: ``C q' = 0`` (Eq. 5.72).

    Rows: ``x' + a w_z`` and ``z' - a w_x`` as linear forms in
    ``q' = (x', z', phi', psi', theta')``; the ``phi'`` column is ``a (A13, -A11)`` (the seed's
    ``a A13 phi'`` and ``-A11 phi'`` terms).

    Parameters
    ----------
    q : array_like, shape (5,)
        ``[x, z, phi, psi, theta]`` [m, m, rad, rad, rad].
    radius : float [m], optional

    Returns
    -------
    numpy.ndarray, shape (2, 5)

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import sphere_constraint_matrix
    >>> (sphere_constraint_matrix([0, 0, 0, 0, 0], radius=2.0) + 0.0).tolist()
    [[1.0, 0.0, 0.0, 2.0, 0.0], [0.0, 1.0, -2.0, 0.0, 0.0]]
    """
    q = validate.finite_array(q, "q").reshape(-1)
    if q.shape != (5,):
        raise ValueError(f"`q` must be [x, z, phi, psi, theta] (5 entries), got {q.size}")
    a = validate.positive(radius, "radius")
    return np.asarray(_sphere_functions()[0](q, a), dtype=float)


def sphere_state(velocity, *, spin=0.0, angles=(0.0, 0.0, 0.0), radius=0.1,
                 position=(0.0, 0.0)) -> np.ndarray:
    """A state of `rolling_sphere` on its constraints: the centre's horizontal velocity
    ``(x', z')``, the spin ``w_y`` about the vertical, the angles ``(phi, psi, theta)``.

    Rolling fixes ``w_x = z'/a`` and ``w_z = -x'/a``; the angle rates solve
    ``w(q, q') = (w_x, spin, w_z)``.

    Parameters
    ----------
    velocity : array_like, shape (2,) [m/s]
    spin : float [rad/s], optional
    angles : array_like, shape (3,) [rad], optional
        ``(phi, psi, theta)``, ``|theta| < pi/2``.
    radius : float [m], optional
    position : array_like, shape (2,) [m], optional
        ``(x, z)``.

    Returns
    -------
    numpy.ndarray, shape (10,)

    Raises
    ------
    ValueError
        Naming ``velocity``, ``angles`` (wrong size, ``theta`` at +-pi/2), ``spin``,
        ``radius`` or ``position``.

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import sphere_state
    >>> (sphere_state([0.2, 0.0], radius=0.1) + 0.0).round(12).tolist()   # about -z: psi' = -2
    [0.0, 0.0, 0.0, 0.0, 0.0, 0.2, 0.0, 0.0, -2.0, 0.0]
    """
    vel = validate.finite_array(velocity, "velocity").reshape(-1)
    ang = validate.finite_array(angles, "angles").reshape(-1)
    pos = validate.finite_array(position, "position").reshape(-1)
    for name, arr, n in (("velocity", vel, 2), ("angles", ang, 3), ("position", pos, 2)):
        if arr.size != n:
            raise ValueError(f"`{name}` must have {n} entries, got {arr.size}")
    if abs(np.cos(ang[2])) < 1e-8:
        raise ValueError(f"`angles` theta must not be +-pi/2 (the 3-2-1 singularity), got "
                         f"{ang[2]!r}")
    a = validate.positive(radius, "radius")
    wy = validate.finite_scalar(spin, "spin")
    q = np.r_[pos, ang]
    B = np.asarray(_sphere_functions()[1](q), dtype=float)
    rates = np.linalg.solve(B, [vel[1] / a, wy, -vel[0] / a])
    return np.r_[q, vel, rates]


# ------------------------------------------------------------------ dumbbell on a disk
_DD = ("mass", "arm", "inertia1", "inertia2", "inertia3", "stiffness")
_DD_DEFAULTS = {"mass": 1.0, "arm": 0.5, "inertia1": 1.0, "inertia2": 1.5, "inertia3": 2.0,
                "stiffness": 2.0}


@cache.memoize
def _dumbbell_disk(tau) -> Model:
    x = ca.SX.sym("x", 13)
    p = ca.SX.sym("p", 6)
    m, l, k = p[0], p[1], p[5]
    J = ca.diag(p[2:5])
    quat, r, w, rd = x[:4], x[4:7], x[7:10], x[10:13]
    q, v = x[:7], x[7:]
    rho = ca.mtimes(dcm_from_quat(quat), r)          # mass 1 in disk axes (times |q|^2)
    alpha = ca.atan2(rho[0], rho[2])
    V = 0.5 * k * alpha ** 2
    qdot = ca.vertcat(quat_rate(quat, w), rd)
    M = ca.diagcat(J, 2 * m * ca.SX.eye(3))
    # Euler (Boltzmann-Hamel, Eq. 6.20) for the disk, Newton for the pair of masses; the
    # spring's generalized forces -dV/dq dq'/dv (a virtual rotation of the disk moves alpha)
    Q = ca.vertcat(-ca.cross(w, ca.mtimes(J, w)), ca.SX.zeros(3)) \
        - ca.mtimes(ca.jacobian(qdot, v).T, ca.gradient(V, q))
    A = dcm_from_quat(quat)
    momentum = ca.mtimes(A.T, ca.mtimes(J, w)) + 2 * m * ca.cross(r, rd)
    energy = 0.5 * ca.dot(w, ca.mtimes(J, w)) + m * ca.sumsqr(rd) + V
    return constrained_model("dumbbell_disk", ("q1", "q2", "q3", "q4", "rx", "ry", "rz"),
                  ("-",) * 4 + ("m",) * 3, ("rad/s",) * 3 + ("m/s",) * 3, q, v, None, p, _DD,
                  {"mass": "kg", "arm": "m", "inertia1": "kg m^2", "inertia2": "kg m^2",
                   "inertia3": "kg m^2", "stiffness": "N m/rad"},
                  [_DD_DEFAULTS[key] for key in _DD], M, Q,
                  position=ca.vertcat((ca.sumsqr(r) - l ** 2) / 2, rho[1]), qdot=qdot,
                  rates=("w1", "w2", "w3", "rx_dot", "ry_dot", "rz_dot"), attitude=(0, 7),
                  time_constant=tau,
                  extra=lambda lam: {"alpha": alpha, "energy": energy,
                                     "angular_momentum": momentum})


def dumbbell_disk(*, mass=_DD_DEFAULTS["mass"], arm=_DD_DEFAULTS["arm"], inertia=(1.0, 1.5, 2.0),
                  stiffness=_DD_DEFAULTS["stiffness"],
                  time_constant=DEFAULT_TIME_CONSTANT) -> Model:
    """A dumbbell (two masses ``m`` at ``+-l``) hinged at the mass centre of a free disk and
    held there by a torsion spring ``k`` (Ch. 6 Example 2), with Lagrange multipliers.

    The disk (principal moments ``A, B, C`` along its axes ``e1, e2, e3``) has the attitude
    quaternion ``q`` (scalar-last, ``A(q)`` inertial -> disk) and body rates ``w``; the
    dumbbell is the inertial position ``r`` of mass 1 (mass 2 at ``-r``: the common mass
    centre stays at rest). ``rho = A(q) r = l (sin a, 0, cos a)`` in disk axes gives the
    spring angle ``a`` (the seed's ``alpha``, about ``e2``)::

        T = 1/2 w.J w + m |r'|^2,     V = 1/2 k a^2,     a = atan2(rho1, rho3)
        phi = [(r.r - l^2)/2, rho2] = 0       (rod length; the dumbbell turns about e2 only)

    with Euler's equations for the disk (``Q = -w x J w``) and the spring's generalized
    forces ``-dV/dq dq'/dv``. The multipliers are the rod tension and the hinge's reaction
    (force ``lam2 e2`` on the masses, its couple on the disk). Small or large, the planar
    swing (``w = w2 e2``) is harmonic: `dumbbell_disk_frequency`.

    Parameters
    ----------
    mass : float [kg]
        Each end mass ``m``, ``> 0`` (``I0 = 2 m l^2``).
    arm : float [m]
        ``l``, ``> 0``.
    inertia : array_like, shape (3,) [kg m^2]
        ``(A, B, C)`` of the disk, each ``> 0``.
    stiffness : float [N m/rad]
        ``k >= 0``.
    time_constant : float or None [s]
        Baumgarte time constant; ``None``: none.

    Returns
    -------
    Model
        ``x = [q1..q4, rx, ry, rz, w1, w2, w3, rx_dot, ry_dot, rz_dot]`` (``attitude``
        ``(0, 7)``); invariants ``multipliers``, ``alpha`` [rad], ``energy`` [J],
        ``angular_momentum`` [N m s] (inertial) and ``constraint_residual``. Start with
        `dumbbell_disk_state`.

    Raises
    ------
    ValueError
        Naming ``mass``, ``arm``, ``inertia`` (not positive), ``stiffness`` (negative) or
        ``time_constant``.

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import dumbbell_disk, dumbbell_disk_state
    >>> model = dumbbell_disk()
    >>> x0 = dumbbell_disk_state(0.3, 0.0, [0.0, 0.0, 0.0])
    >>> round(float(model.invariant("alpha", x0)), 12), model.states[7:10]
    (0.3, ('w1', 'w2', 'w3'))
    """
    tau = stabilization(time_constant)
    vals = checked_constants(dict(mass=mass, arm=arm, stiffness=stiffness), ("mass", "arm"),
                    ("stiffness",))
    moments = validate.positive_each(inertia, "inertia", 3)
    vals.update({f"inertia{i + 1}": float(moments[i]) for i in range(3)})
    return with_parameters(_dumbbell_disk(tau), vals)


def dumbbell_disk_state(alpha, alpha_dot, w, *, arm=_DD_DEFAULTS["arm"]) -> np.ndarray:
    """A state of `dumbbell_disk` on its constraints: disk axes = inertial axes, spring angle
    ``alpha`` and rate ``alpha_dot`` [rad, rad/s], disk body rates ``w`` [rad/s].

    ``r = rho = l (sin a, 0, cos a)``, ``r' = w x rho + a' e2 x rho``.

    Returns
    -------
    numpy.ndarray, shape (13,)

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import dumbbell_disk_state
    >>> dumbbell_disk_state(0.0, 1.0, [0.0, 0.0, 0.0], arm=2.0)[4:].tolist()
    [0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0]
    """
    a = validate.finite_scalar(alpha, "alpha")
    ad = validate.finite_scalar(alpha_dot, "alpha_dot")
    l = validate.positive(arm, "arm")
    w = validate.finite_array(w, "w").reshape(-1)
    if w.shape != (3,):
        raise ValueError(f"`w` must have 3 components, got {w.size}")
    rho = l * np.array([np.sin(a), 0.0, np.cos(a)])
    rd = np.cross(w, rho) + ad * np.cross([0.0, 1.0, 0.0], rho)
    return np.r_[0.0, 0.0, 0.0, 1.0, rho, w, rd]


def dumbbell_disk_frequency(*, mass=_DD_DEFAULTS["mass"], arm=_DD_DEFAULTS["arm"],
                            inertia2=_DD_DEFAULTS["inertia2"],
                            stiffness=_DD_DEFAULTS["stiffness"]) -> float:
    """The frequency of the planar swing of `dumbbell_disk` [rad/s], exact at any amplitude.

    With ``w1 = w3 = 0`` the flexibility equation is ``I0 (a'' + w2') + k a = 0`` and the
    momentum ``B w2 + I0 (a' + w2)`` is constant, so ``w2' = -I0 a'' / (B + I0)`` and::

        (I0 B / (B + I0)) a'' + k a = 0,     w^2 = k (B + I0) / (I0 B),   I0 = 2 m l^2

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import dumbbell_disk_frequency
    >>> round(dumbbell_disk_frequency(), 12)          # I0 = 0.5, B = 1.5: w^2 = 16/3
    2.309401076759
    """
    m, l = validate.positive(mass, "mass"), validate.positive(arm, "arm")
    B = validate.positive(inertia2, "inertia2")
    k = nonnegative(stiffness, "stiffness")
    I0 = 2 * m * l * l
    return float(np.sqrt(k * (B + I0) / (I0 * B)))
