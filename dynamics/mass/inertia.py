"""Inertia transformations (Sec. 4.4 B-E): parallel axes, rotated axes, moment about an axis.

Products of inertia with the seed's sign (Eq. 4.16, ``Ixy = -sum m x y``): an inertia matrix
is ``sum m (r^2 E - r r^T)``. A DCM ``A`` maps old (unprimed) to new (primed) components.
"""
from __future__ import annotations

import numpy as np

from .. import validate

__all__ = ["parallel_axis", "rotate_inertia", "inertia_about_axis", "radius_of_gyration"]


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
        raise ValueError(f"`{name}` must be positive semi-definite, got eigenvalues "
                         f"{tuple(eig.tolist())}")
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
