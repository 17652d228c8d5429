"""Mass properties and variable mass: inertia transformations and the rocket equations.

Rheinfurth & Wilson, NASA RP-1262:

* Sec. 4.4 B-E -- the parallel-axis (Steiner) theorem `parallel_axis`, the rotated-axes law
  `rotate_inertia`, the moment of inertia about an axis `inertia_about_axis` (Eq. 4.81) and the
  radius of gyration `radius_of_gyration`;
* Sec. 3.4 -- variable mass: the bullets fired from a vehicle on rails `rocket_steps` (the
  discrete rocket, whose limit is Tsiolkovsky's ``V = C ln(M0/M)``), `delta_v`, the specific
  impulse `isp` (Eq. 3.40) and the jet-damping torque `jet_damping_torque` (Eq. 3.49).

Conventions: products of inertia with the seed's sign (Eq. 4.16, ``Ixy = -sum m x y``), so an
inertia matrix is ``sum m (r^2 E - r r^T)``; a DCM ``A`` maps old (unprimed) to new (primed)
components, ``x' = A x``. SI units. Numpy only (mass properties are set-up data, not states).
"""
from __future__ import annotations

import numpy as np

from . import validate

__all__ = ["G0", "parallel_axis", "rotate_inertia", "inertia_about_axis", "radius_of_gyration",
           "isp", "delta_v", "rocket_steps", "jet_damping_torque"]

#: Standard gravity [m/s^2] of the specific impulse (Eq. 3.40; the seed rounds it to 9.81).
G0 = 9.80665


def _inertia(inertia, name="inertia"):
    """A symmetric positive semi-definite 3x3 (or 3 principal moments) as a float array."""
    a = validate.finite_array(inertia, name)
    if a.shape == (3,):
        a = np.diag(a)
    if a.shape != (3, 3):
        raise ValueError(f"`{name}` must have shape (3, 3) or (3,), got {a.shape}")
    scale = max(float(np.max(np.abs(a))), 1e-300)
    if np.max(np.abs(a - a.T)) > 1e-12 * scale:
        raise ValueError(f"`{name}` must be symmetric, got {a.tolist()}")
    a = 0.5 * (a + a.T)
    eig = np.linalg.eigvalsh(a)
    if eig[0] < -1e-12 * scale:
        raise ValueError(f"`{name}` must be positive semi-definite, got eigenvalues {tuple(eig)}")
    return a


def parallel_axis(inertia, mass, offset, *, inverse=False):
    """Inertia about a point ``O`` from the inertia about the mass centre (Steiner, Sec. 4.4 B).

    ``I_O = I_cm + M (d^2 E - d d^T) = I_cm - M [d x]^2`` with ``d`` the position of the mass
    centre relative to ``O``; in components ``I11 = I11c + M (d2^2 + d3^2)`` and
    ``I12 = I12c - M d1 d2`` (seed sign of the products, Eq. 4.16). With ``inverse=True`` the
    step is undone: ``inertia`` is about ``O`` and the result about the mass centre.

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2]
        About the mass centre (about ``O`` if ``inverse``); symmetric positive semi-definite.
    mass : float [kg]
        Positive.
    offset : array_like, shape (3,) [m]
        ``d``: the mass centre relative to ``O``, in the axes of ``inertia``.
    inverse : bool, optional
        Shift from ``O`` to the mass centre instead.

    Returns
    -------
    ndarray, shape (3, 3) [kg m^2]

    Raises
    ------
    TypeError
        If an argument is not real numbers.
    ValueError
        If ``inertia`` is not a symmetric positive semi-definite 3x3 (or 3 moments), ``mass``
        is not positive, ``offset`` is not 3 finite numbers, or (``inverse``) the result is not
        positive semi-definite (``inertia`` cannot be about ``O`` for that mass and offset).

    Examples
    --------
    >>> from appdyn.dynamics.mass import parallel_axis
    >>> parallel_axis([0.0, 1.0, 1.0], 3.0, [0.0, 0.0, 2.0])  # +M d^2 about x and y
    array([[12.,  0.,  0.],
           [ 0., 13.,  0.],
           [ 0.,  0.,  1.]])
    >>> float(parallel_axis([1.0, 1.0, 1.0], 1.0, [1.0, 1.0, 0.0])[0, 1])  # I12c - M d1 d2
    -1.0
    """
    I = _inertia(inertia)
    m = validate.positive(mass, "mass")
    d = validate.finite_array(offset, "offset", (3,))
    steiner = m * (d @ d * np.eye(3) - np.outer(d, d))
    if not inverse:
        return I + steiner
    out = I - steiner
    return _inertia(out, "inertia - M (d^2 E - d d^T)")


def rotate_inertia(inertia, A):
    """Inertia matrix in rotated axes, ``I' = A I A^T`` (theorem of rotated axes, Sec. 4.4 C).

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2]
        In the old (unprimed) axes.
    A : array_like, shape (3, 3)
        Rotation matrix from old to new components, ``x' = A x`` (the project's DCM
        direction: ``A`` of a body frame maps inertial to body components).

    Returns
    -------
    ndarray, shape (3, 3) [kg m^2]
        In the new (primed) axes.

    Raises
    ------
    TypeError
        If an argument is not real numbers.
    ValueError
        If ``inertia`` is not symmetric positive semi-definite or ``A`` is not a proper rotation.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import dcm_axis
    >>> from appdyn.dynamics.mass import rotate_inertia
    >>> np.round(rotate_inertia([1.0, 2.0, 3.0], dcm_axis(3, np.pi / 2)), 12)  # x and y swap
    array([[2., 0., 0.],
           [0., 1., 0.],
           [0., 0., 3.]])
    """
    I = _inertia(inertia)
    A = validate.rotation_matrix(A, "A")
    return A @ I @ A.T


def inertia_about_axis(inertia, axis):
    """Moment of inertia about an axis through the reference point, ``I_A = e^T I e`` (Eq. 4.81).

    From ``T = 1/2 w^T I w = 1/2 I_A |w|^2`` with ``w = |w| e``. (The seed's ellipsoid line
    ``I_A = 1/sqrt(rho^T I rho)`` is garbled: the ellipsoid radius along ``e`` is
    ``|rho| = 1/sqrt(I_A)``.)

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2]
    axis : array_like, shape (3,)
        Direction ``e`` in the axes of ``inertia`` (normalized here).

    Returns
    -------
    float [kg m^2]

    Raises
    ------
    TypeError
        If an argument is not real numbers.
    ValueError
        If ``inertia`` is not symmetric positive semi-definite or ``axis`` is zero or not finite.

    Examples
    --------
    >>> from appdyn.dynamics.mass import inertia_about_axis
    >>> round(inertia_about_axis([1.0, 2.0, 3.0], [1.0, 1.0, 0.0]), 12)  # (1 + 2) / 2
    1.5
    """
    I = _inertia(inertia)
    e = validate.unit_vector(axis, "axis")
    return float(e @ I @ e)


def radius_of_gyration(inertia, mass, axis=None):
    """Radius of gyration ``k_A = sqrt(I_A / M)`` (Sec. 4.4 E, ``I_A = M k_A^2``).

    Parameters
    ----------
    inertia : float or array_like, shape (3, 3) or (3,) [kg m^2]
        A moment ``I_A`` (scalar), or a matrix / principal moments with ``axis``.
    mass : float [kg]
        Positive.
    axis : array_like, shape (3,), optional
        Required with a matrix or moments: the axis of `inertia_about_axis`.

    Returns
    -------
    float [m]

    Raises
    ------
    TypeError
        If an argument is not real numbers.
    ValueError
        If ``mass`` is not positive, a scalar ``inertia`` is negative, ``axis`` is missing for
        a matrix or given for a scalar.

    Examples
    --------
    >>> from appdyn.dynamics.mass import radius_of_gyration
    >>> radius_of_gyration(8.0, 2.0)
    2.0
    >>> round(radius_of_gyration([2.0, 4.0, 4.0], 2.0, axis=[0, 0, 1]), 12)
    1.414213562373
    """
    m = validate.positive(mass, "mass")
    if np.ndim(inertia) == 0:
        if axis is not None:
            raise ValueError("`axis` is only for a matrix or principal moments; `inertia` is "
                             "already a moment about an axis")
        return float(np.sqrt(validate.nonnegative(inertia, "inertia") / m))
    if axis is None:
        raise ValueError("`axis` is required when `inertia` is a matrix or principal moments "
                         "(or pass the moment about the axis as a number)")
    return float(np.sqrt(inertia_about_axis(inertia, axis) / m))


def isp(thrust, mass_flow, *, g0=G0):
    """Specific impulse ``Is = F_T / (mdot g0) = C / g0`` (Sec. 3.4, Eq. 3.40).

    Parameters
    ----------
    thrust : float or array_like [N]
    mass_flow : float or array_like [kg/s]
        Propellant flow rate ``mdot > 0`` (the magnitude, as in Eq. 3.39).
    g0 : float [m/s^2], optional
        Standard gravity (`G0`).

    Returns
    -------
    float or ndarray [s]

    Raises
    ------
    TypeError
        If an argument is not real numbers.
    ValueError
        If ``mass_flow`` or ``g0`` is not positive or ``thrust`` is not finite.

    Examples
    --------
    >>> from appdyn.dynamics.mass import G0, isp
    >>> round(isp(628500.0, 17010.0 / 75.2), 3)  # a Delta III solid booster
    283.334
    """
    F = validate.finite_array(thrust, "thrust")
    md = validate.finite_array(mass_flow, "mass_flow")
    if np.any(md <= 0):
        raise ValueError(f"`mass_flow` must be positive (the flow magnitude), got {md.tolist()}")
    out = F / (md * validate.positive(g0, "g0"))
    return float(out) if out.ndim == 0 else out


def delta_v(initial_mass, final_mass, *, isp=None, exhaust_velocity=None, g0=G0):
    """Ideal velocity gain of a rocket in free space, ``V = C ln(M0 / M)`` (Sec. 3.4).

    The limit of `rocket_steps` for infinitely many infinitesimal firings (Tsiolkovsky), with
    the effective exhaust velocity ``C = Is g0`` (Eq. 3.40).

    Parameters
    ----------
    initial_mass, final_mass : float or array_like [kg]
        ``M0 >= M > 0``.
    isp : float [s], optional
        Specific impulse; give exactly one of ``isp`` and ``exhaust_velocity``.
    exhaust_velocity : float [m/s], optional
        ``C``.
    g0 : float [m/s^2], optional

    Returns
    -------
    float or ndarray [m/s]

    Raises
    ------
    TypeError
        If an argument is not real numbers.
    ValueError
        If the masses are not positive with ``M0 >= M``, or not exactly one of ``isp`` and
        ``exhaust_velocity`` is given, or it is not positive.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.mass import delta_v
    >>> round(delta_v(np.e, 1.0, exhaust_velocity=3000.0), 9)  # one e-fold of mass: V = C
    3000.0
    >>> round(delta_v(1000.0, 400.0, isp=300.0), 3)
    2695.723
    """
    C = _exhaust_velocity(isp, exhaust_velocity, g0)
    M0 = validate.finite_array(initial_mass, "initial_mass")
    M = validate.finite_array(final_mass, "final_mass")
    if np.any(M <= 0) or np.any(M0 < M):
        raise ValueError(f"need `initial_mass` >= `final_mass` > 0, got {M0.tolist()} and "
                         f"{M.tolist()}")
    out = C * np.log(M0 / M)
    return float(out) if out.ndim == 0 else out


def _exhaust_velocity(isp_, exhaust_velocity, g0):
    if (isp_ is None) == (exhaust_velocity is None):
        raise ValueError("give exactly one of `isp` [s] and `exhaust_velocity` [m/s]")
    if isp_ is not None:
        return validate.positive(isp_, "isp") * validate.positive(g0, "g0")
    return validate.positive(exhaust_velocity, "exhaust_velocity")


def rocket_steps(mass, pellet_mass, exhaust_velocity, count, *, simultaneous=False):
    """Velocity of a vehicle that fires ``count`` pellets backwards (Sec. 3.4, the discrete rocket).

    The seed's preliminary example: a vehicle of mass ``M`` (without the pellets) rolls on
    frictionless rails and fires pellets of mass ``m`` at the muzzle velocity ``C`` relative to
    the barrel. Momentum conservation at each firing gives, in sequence,
    ``V_k = C sum_{j=1..k} m / (M + (N - j + 1) m)``, the final speed
    ``V_N = C sum_{k=1..N} m / (M + k m)``; fired all at once ``V = N m C / (M + N m)`` (case
    (a), smaller). As ``N -> inf`` with ``N m`` fixed, ``V_N -> C ln(M0 / M)`` (`delta_v`).

    Parameters
    ----------
    mass : float [kg]
        ``M``: the vehicle without the pellets (positive).
    pellet_mass : float [kg]
        ``m`` (positive).
    exhaust_velocity : float [m/s]
        ``C``: the muzzle velocity relative to the barrel (positive).
    count : int
        ``N >= 1`` pellets.
    simultaneous : bool, optional
        Fire all at once (case (a)) instead of one after another.

    Returns
    -------
    ndarray, shape (count,) [m/s], or float
        In sequence: the speed after each firing; at once: the speed.

    Raises
    ------
    TypeError
        If an argument is not real numbers (``count`` not an integer).
    ValueError
        If a mass or the velocity is not positive or ``count < 1``.

    Examples
    --------
    >>> from appdyn.dynamics.mass import rocket_steps
    >>> rocket_steps(8.0, 1.0, 10.0, 2)  # the seed's two bullets: mC/(M+2m), + mC/(M+m)
    array([1.        , 2.11111111])
    >>> rocket_steps(8.0, 1.0, 10.0, 2, simultaneous=True)  # 2 m C / (M + 2 m)
    2.0
    """
    M = validate.positive(mass, "mass")
    m = validate.positive(pellet_mass, "pellet_mass")
    C = validate.positive(exhaust_velocity, "exhaust_velocity")
    N = validate.integer(count, "count", minimum=1)
    if simultaneous:
        return N * m * C / (M + N * m)
    remaining = M + m * np.arange(N, 0, -1)  # mass before each firing: M + N m, ..., M + m
    return np.cumsum(C * m / remaining)


def jet_damping_torque(mass_flow, rate, l1, l2):
    """Coriolis (jet-damping) torque of an axial mass flow, ``L_C = -mdot w (l2^2 - l1^2)`` (Eq. 3.49).

    A uniform flow ``mdot`` along the body x axis from ``x = l1`` to the nozzle exit
    ``x = l2`` of a body turning at ``w`` about a transverse axis through the mass centre
    (Eq. 3.48, ``L_C = -2 int mdot r x (w x dr)``); the torque is about the same axis.
    ``l1 = 0`` gives the textbook ``-mdot w l2^2``; ``l1 = -l2`` gives zero.

    Parameters
    ----------
    mass_flow : float [kg/s]
        ``mdot >= 0``.
    rate : float or array_like [rad/s]
        ``w``.
    l1, l2 : float [m]
        Start and end (nozzle exit) of the flow along x.

    Returns
    -------
    float or ndarray [N m]

    Raises
    ------
    TypeError
        If an argument is not real numbers.
    ValueError
        If ``mass_flow`` is negative or an argument is not finite.

    Examples
    --------
    >>> from appdyn.dynamics.mass import jet_damping_torque
    >>> jet_damping_torque(2.0, 0.1, 0.0, 3.0)  # -mdot w l2^2
    -1.8
    """
    md = validate.nonnegative(mass_flow, "mass_flow")
    w = validate.finite_array(rate, "rate")
    a, b = validate.finite_scalar(l1, "l1"), validate.finite_scalar(l2, "l2")
    out = -md * w * (b * b - a * a)
    return float(out) if out.ndim == 0 else out
