"""Single-gimbal control moment gyro (CMG) clusters: geometry, momentum, Jacobian, singularities.

Convention (shared with the CMG spacecraft model): unit ``i`` has a unit gimbal axis ``g_i``
(body frame), a unit initial spin axis ``s0_i`` perpendicular to ``g_i`` and a rotor momentum
``h_i > 0`` [N m s]. At the gimbal angle ``delta_i`` [rad] its spin and transverse axes are

    ``s_i = cos(delta_i) s0_i + sin(delta_i) (g_i x s0_i)``,   ``t_i = g_i x s_i``,

the cluster momentum is ``H(delta) = sum_i h_i s_i`` (body frame, shape (3,)) and its Jacobian
``C = dH/d(delta)`` has the columns ``h_i t_i`` (shape (3, n)). The torque of the cluster on the
body is ``-C delta_dot`` (`dynamics.momentum.steering`). Singularities (``det(C C^T) = 0``) are
classified after Wie, *Space Vehicle Dynamics and Control*, Sec. 7.3 (`classify_singularity`).

`cluster_momentum`, `cluster_jacobian`, `gram_determinant` and `singularity_measure` work on
numpy and on CasADi ``SX``/``MX``/``DM`` alike (an optimal-control path constraint can use the
measure symbolically); `singular_direction` and `classify_singularity` are numeric.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import casadi as ca
import numpy as np

from .. import validate
from ..attitude.backend import CA_TYPES, checked
from ..validate import AXIS_NORM_TOL

__all__ = ["AXIS_NORM_TOL", "SINGULAR_TOL", "ClusterGeometry", "pyramid", "cluster_momentum",
           "cluster_jacobian", "gram_determinant", "singularity_measure", "singular_direction",
           "classify_singularity"]

#: Default relative tolerance of the rank decisions (singular values below
#: ``SINGULAR_TOL * max(h)`` count as zero).
SINGULAR_TOL = 1e-8


# ------------------------------------------------------------------------- geometry
@dataclass(frozen=True, eq=False)
class ClusterGeometry:
    """Geometry of ``n`` single-gimbal CMGs; validated (and made read-only) on construction.

    Parameters
    ----------
    gimbal_axes : array_like, shape (3, n)
        Unit gimbal axes ``g_i`` as columns, body frame (norm 1 to `AXIS_NORM_TOL`; they are
        refused, not normalized, when further off).
    spin_axes0 : array_like, shape (3, n)
        Unit spin axes ``s0_i`` at zero gimbal angle, each perpendicular to its ``g_i``
        (``|g_i . s0_i| <= AXIS_NORM_TOL``).
    h : float or array_like, shape (n,) [N m s]
        Rotor angular momenta ``h_i > 0`` (a scalar is shared by all units).

    Attributes
    ----------
    n : int
    transverse_axes0 : ndarray, shape (3, n)
        ``g_i x s0_i``.

    Raises
    ------
    TypeError
        If an argument does not hold real numbers (`dynamics.validate.ArgumentTypeError`).
    ValueError
        Naming the argument (and the unit, e.g. ``gimbal_axes[:, 2]``): wrong shape, non-finite
        entry, zero or non-unit axis, spin axis not perpendicular to its gimbal axis, ``h`` of
        the wrong length or not ``> 0``.

    Examples
    --------
    >>> from appdyn.dynamics.momentum import ClusterGeometry
    >>> geo = ClusterGeometry([[0.0], [0.0], [1.0]], [[1.0], [0.0], [0.0]], h=2.0)
    >>> geo.n, geo.h, geo.transverse_axes0.ravel()  # one unit about e_z, spin e_x
    (1, array([2.]), array([0., 1., 0.]))
    >>> ClusterGeometry([[0.0], [0.0], [1.0]], [[0.0], [0.6], [0.8]])
    Traceback (most recent call last):
        ...
    ValueError: `spin_axes0[:, 0]` must be perpendicular to `gimbal_axes[:, 0]` ...
    """

    gimbal_axes: np.ndarray
    spin_axes0: np.ndarray
    h: np.ndarray = 1.0

    def __post_init__(self):
        g = validate.unit_axes(self.gimbal_axes, "gimbal_axes")
        s0 = validate.unit_axes(self.spin_axes0, "spin_axes0")
        if s0.shape != g.shape:
            raise ValueError(f"`spin_axes0` must have the shape of `gimbal_axes` {g.shape}, "
                             f"got {s0.shape}")
        dots = np.abs(np.sum(g * s0, axis=0))
        if np.any(dots > AXIS_NORM_TOL):
            j = int(np.argmax(dots > AXIS_NORM_TOL))
            raise ValueError(f"`spin_axes0[:, {j}]` must be perpendicular to `gimbal_axes[:, {j}]`"
                             f" (|g . s0| <= {AXIS_NORM_TOL:g}), got g . s0 = {dots[j]:.6g}")
        h = validate.positive_each(self.h, "h", g.shape[1])
        for name, value in (("gimbal_axes", g), ("spin_axes0", s0), ("h", h)):
            value = np.array(value, dtype=float)  # an own copy, frozen
            value.setflags(write=False)
            object.__setattr__(self, name, value)

    @property
    def n(self) -> int:
        """Number of units."""
        return self.gimbal_axes.shape[1]

    @property
    def transverse_axes0(self) -> np.ndarray:
        """``g_i x s0_i`` as columns, shape (3, n)."""
        return np.cross(self.gimbal_axes, self.spin_axes0, axis=0)


def pyramid(beta, h=1.0) -> ClusterGeometry:
    """The classic four-CMG pyramid with skew angle ``beta`` (Wie, Sec. 7.3).

    The gimbal axes are normal to the four faces of a pyramid whose faces are inclined by
    ``beta`` from the base (``g_i . e_z = cos(beta)``):
    ``g = (sb, 0, cb), (0, sb, cb), (-sb, 0, cb), (0, -sb, cb)`` and
    ``s0 = (0, 1, 0), (-1, 0, 0), (0, -1, 0), (1, 0, 0)`` (``sb = sin beta``,
    ``cb = cos beta``), which gives

    ``H = h [-cb s1 - c2 + cb s3 + c4,  c1 - cb s2 - c3 + cb s4,  sb (s1 + s2 + s3 + s4)]``

    with ``si = sin(delta_i)``, ``ci = cos(delta_i)``. ``beta = acos(1/sqrt(3))`` (54.74 deg)
    makes the momentum envelope nearly spherical: ``2 h (1 + cb)`` along x and y,
    ``4 h sb`` along z.

    Parameters
    ----------
    beta : float [rad]
        Skew angle.
    h : float or array_like, shape (4,) [N m s]
        Rotor momenta, ``> 0``.

    Returns
    -------
    ClusterGeometry

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.momentum import pyramid, cluster_momentum
    >>> geo = pyramid(np.arccos(1 / np.sqrt(3)))
    >>> np.round(cluster_momentum(geo, np.deg2rad([90, 90, 90, 90])), 4)  # 4 sin(beta) e_z
    array([0.    , 0.    , 3.266])
    """
    b = validate.finite_scalar(beta, "beta")
    sb, cb = np.sin(b), np.cos(b)
    gimbal = [[sb, 0.0, -sb, 0.0], [0.0, sb, 0.0, -sb], [cb, cb, cb, cb]]
    spin0 = [[0.0, -1.0, 0.0, 1.0], [1.0, 0.0, -1.0, 0.0], [0.0, 0.0, 0.0, 0.0]]
    return ClusterGeometry(np.array(gimbal), np.array(spin0), h)


# ------------------------------------------------------------------------- momentum, Jacobian
def _columns(geometry, delta, *, batch=True):
    """(``h_i s0_i``, ``h_i t0_i``) as (3, n) arrays, and the checked angles."""
    if not isinstance(geometry, ClusterGeometry):
        raise validate.ArgumentTypeError(
            f"`geometry` must be a ClusterGeometry, got {type(geometry).__name__}")
    n = geometry.n
    if batch:
        d = checked(delta, "delta", (n,),
                    lambda x, nm: validate.finite_array(x, nm, (n,), batch=True))
    else:
        d = validate.finite_array(delta, "delta", (n,))
    return geometry.spin_axes0 * geometry.h, geometry.transverse_axes0 * geometry.h, d


def cluster_momentum(geometry: ClusterGeometry, delta):
    """Cluster angular momentum ``H = sum_i h_i s_i(delta_i)`` in the body frame.

    Parameters
    ----------
    geometry : ClusterGeometry
    delta : array_like, shape (n,) or (n, ...) [rad], or CasADi n x 1 (SX, MX or DM)
        Gimbal angles; a numpy batch has the units first and any batch axes after them.

    Returns
    -------
    H : ndarray, shape (3,) or (3, ...) [N m s], or CasADi 3 x 1 of the type of ``delta``

    Examples
    --------
    >>> import casadi as ca
    >>> import numpy as np
    >>> from appdyn.dynamics.momentum import pyramid, cluster_momentum
    >>> geo = pyramid(np.deg2rad(54.74))
    >>> np.round(cluster_momentum(geo, np.deg2rad([-90, 0, 90, 0])), 3)  # elliptic singular state
    array([1.155, 0.   , 0.   ])
    >>> cluster_momentum(geo, np.zeros((4, 5))).shape  # a batch of 5 states
    (3, 5)
    >>> cluster_momentum(geo, ca.SX.sym("delta", 4)).shape
    (3, 1)
    """
    s0h, t0h, d = _columns(geometry, delta)
    if isinstance(d, CA_TYPES):
        return ca.mtimes(ca.DM(s0h), ca.cos(d)) + ca.mtimes(ca.DM(t0h), ca.sin(d))
    return np.tensordot(s0h, np.cos(d), axes=1) + np.tensordot(t0h, np.sin(d), axes=1)


def cluster_jacobian(geometry: ClusterGeometry, delta):
    """Jacobian ``C = dH/d(delta)``, column ``i`` = ``h_i t_i = h_i g_i x s_i``.

    Parameters
    ----------
    geometry : ClusterGeometry
    delta : array_like, shape (n,) or (n, ...) [rad], or CasADi n x 1 (SX, MX or DM)

    Returns
    -------
    C : ndarray, shape (3, n) or (3, n, ...) [N m s / rad], or CasADi 3 x n

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.momentum import pyramid, cluster_jacobian
    >>> np.round(cluster_jacobian(pyramid(np.pi / 2), np.zeros(4)), 12) + 0.0  # all along e_z
    array([[0., 0., 0., 0.],
           [0., 0., 0., 0.],
           [1., 1., 1., 1.]])
    """
    s0h, t0h, d = _columns(geometry, delta)
    if isinstance(d, CA_TYPES):
        c, s = ca.cos(d), ca.sin(d)
        return ca.horzcat(*[ca.DM(t0h[:, i]) * c[i] - ca.DM(s0h[:, i]) * s[i]
                            for i in range(s0h.shape[1])])
    pad = (...,) + (None,) * (d.ndim - 1)
    return t0h[pad] * np.cos(d)[None] - s0h[pad] * np.sin(d)[None]


def gram_determinant(C):
    """``det(C C^T)`` of a cluster Jacobian: zero exactly at the singular states; smooth in the
    gimbal angles (a better optimization constraint than its root, `singularity_measure`).

    Parameters
    ----------
    C : array_like, shape (3, n) or (3, n, ...), or CasADi 3 x n

    Returns
    -------
    float or ndarray, shape (...) [(N m s)^6], or CasADi 1 x 1

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.momentum import gram_determinant
    >>> float(gram_determinant(np.diag([1.0, 2.0, 3.0])))
    36.0
    """
    if isinstance(C, CA_TYPES):
        if C.shape[0] != 3:
            raise ValueError(f"`C` must have 3 rows, got shape {C.shape}")
        M = ca.mtimes(C, C.T)
    else:
        C = validate.finite_array(C, "C")
        if C.ndim < 2 or C.shape[0] != 3:
            raise ValueError(f"`C` must have shape (3, n) or (3, n, ...), got {C.shape}")
        M = np.einsum("ik...,jk...->ij...", C, C)
    return (M[0, 0] * (M[1, 1] * M[2, 2] - M[1, 2] * M[2, 1])
            - M[0, 1] * (M[1, 0] * M[2, 2] - M[1, 2] * M[2, 0])
            + M[0, 2] * (M[1, 0] * M[2, 1] - M[1, 1] * M[2, 0]))


def singularity_measure(geometry: ClusterGeometry, delta):
    """Singularity measure ``m = sqrt(det(C C^T))`` (zero at a singular state; a round-off
    negative determinant counts as zero).

    Parameters
    ----------
    geometry : ClusterGeometry
    delta : array_like, shape (n,) or (n, ...) [rad], or CasADi n x 1 (SX, MX or DM)

    Returns
    -------
    m : float or ndarray, shape (...) [(N m s)^3], or CasADi 1 x 1

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.momentum import pyramid, singularity_measure
    >>> geo = pyramid(np.arccos(1 / np.sqrt(3)))
    >>> round(float(singularity_measure(geo, np.zeros(4)) ** 2 * 27), 12)  # det = 32/27
    32.0
    """
    det = gram_determinant(cluster_jacobian(geometry, delta))
    if isinstance(det, CA_TYPES):
        return ca.sqrt(ca.fmax(det, 0))
    return np.sqrt(np.maximum(det, 0.0))


# ------------------------------------------------------------------------- singularity analysis
def _singular_state(geometry, delta, tol):
    """Unit momenta ``h_i s_i`` (3, n), SVD of ``C`` and the oriented ``u`` of a numeric state."""
    s0h, t0h, d = _columns(geometry, delta, batch=False)
    tol = validate.positive(tol, "tol")
    units = np.cos(d) * s0h + np.sin(d) * t0h
    U, S, Vt = np.linalg.svd(np.cos(d) * t0h - np.sin(d) * s0h)
    u = U[:, 2]
    p = float(u @ units.sum(axis=1))  # u . H > 0; if zero, largest component positive
    if abs(p) <= tol * float(np.sum(geometry.h)):
        p = u[int(np.argmax(np.abs(u)))]
    return units, S, Vt, (-u if p < 0 else u), tol


def singular_direction(geometry: ClusterGeometry, delta, *, tol=SINGULAR_TOL) -> np.ndarray:
    """Unit singular direction ``u`` with ``u^T C = 0`` at a singular state.

    ``u`` is the left singular vector of the smallest singular value of ``C`` (elsewhere the
    direction of least torque authority; one of several if ``rank C <= 1``). Sign: ``u . H > 0``
    (the outward normal of the singular surface at ``H``); where ``u . H`` vanishes (to
    ``tol * sum(h)``, e.g. at ``H = 0``) the component of largest magnitude is positive.

    Parameters
    ----------
    geometry : ClusterGeometry
    delta : array_like, shape (n,) [rad]
    tol : float, optional
        Relative tolerance of the ``u . H = 0`` tie-break.

    Returns
    -------
    u : ndarray, shape (3,)

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.momentum import pyramid, singular_direction
    >>> geo = pyramid(np.deg2rad(54.74))
    >>> np.round(singular_direction(geo, np.deg2rad([-90, 0, 90, 0])), 12) + 0.0
    array([1., 0., 0.])
    """
    return _singular_state(geometry, delta, tol)[3]


def classify_singularity(geometry: ClusterGeometry, delta, *, tol=SINGULAR_TOL
                         ) -> Literal["nonsingular", "elliptic", "hyperbolic", "degenerate"]:
    """Classify a gimbal state: ``"nonsingular"``, ``"elliptic"``, ``"hyperbolic"`` or
    ``"degenerate"``.

    The state is singular when the smallest singular value of ``C`` is at most
    ``tol * max(h)``. At a singular state of rank 2 the singular direction ``u``
    (`singular_direction`) is unique; with ``P = diag(u . h_i s_i)`` and an orthonormal basis
    ``N`` (n x (n - 2)) of the null space of ``C``, ``Q = N^T P N``:

    * definite ``Q`` (all eigenvalues of one sign, beyond ``tol * max(h)``): ``"elliptic"`` --
      no null motion leaves the singular state (also returned when the null space is empty,
      ``n = 2``: there is no null motion at all);
    * eigenvalues of both signs: ``"hyperbolic"`` -- null motion can pass through;
    * ``"degenerate"``: ``Q`` semi-definite with a zero eigenvalue (a degenerate hyperbolic
      state, where the second-order test is inconclusive), or ``rank C <= 1`` (the singular
      direction is not unique).

    The sign of ``u`` only flips ``Q``; with ``u . H > 0`` (`singular_direction`) an external
    saturation state has ``Q > 0``.

    Parameters
    ----------
    geometry : ClusterGeometry
    delta : array_like, shape (n,) [rad]
    tol : float, optional
        Relative tolerance of the rank and definiteness decisions.

    Returns
    -------
    str

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.momentum import pyramid, classify_singularity
    >>> geo = pyramid(np.deg2rad(54.74))
    >>> classify_singularity(geo, np.deg2rad([-90, 0, 90, 0]))
    'elliptic'
    >>> [classify_singularity(geo, np.deg2rad(d)) for d in ([90, -90, 90, -90], [0, 0, 0, 0])]
    ['hyperbolic', 'nonsingular']
    """
    units, S, Vt, u, tol = _singular_state(geometry, delta, tol)
    scale = float(np.max(geometry.h))
    rank = int(np.sum(S > tol * scale))
    if rank == 3:
        return "nonsingular"
    if rank <= 1:
        return "degenerate"
    N = Vt[rank:].T
    Q = N.T @ ((u @ units)[:, None] * N)
    eig = np.linalg.eigvalsh(Q) if Q.size else np.ones(1)
    pos, neg = np.any(eig > tol * scale), np.any(eig < -tol * scale)
    if pos and neg:
        return "hyperbolic"
    if np.all(np.abs(eig) > tol * scale):
        return "elliptic"
    return "degenerate"
