"""Principal axes of an inertia matrix, with the minimum-rotation labelling of Sec. 4.4 D.
"""
from __future__ import annotations

import itertools

import numpy as np

from .. import validate

__all__ = ["principal_axes"]


def principal_axes(inertia, *, order="nearest"):
    """Principal moments and the principal-axes rotation [1]_.

    The eigenvectors of ``inertia`` form the modal matrix ``Phi`` (columns); the rotation is
    ``A = Phi^T`` so that ``A @ inertia @ A.T = diag(moments)`` and ``x_principal = A @ x_ref``.
    Eigenvector signs are chosen so that ``det A = +1`` and the rotation angle
    (``tr A = 1 + 2 cos delta``) is the smallest, as in [1]_.

    Parameters
    ----------
    inertia : array_like, shape (3, 3) [kg m^2]
        Symmetric positive definite
    order : {"nearest", "ascending", "descending"}
        ``"nearest"`` (default) also chooses which principal axis is called 1, 2, 3: among
        all 24 proper assignments the smallest rotation wins, so each principal axis keeps the
        label of the reference axis it lies closest to (the Gemini ordering of [1]_).
        ``"ascending"``/``"descending"`` fix the order of the moments and choose signs only.

    Returns
    -------
    moments : ndarray, shape (3,) [kg m^2]
    A : ndarray, shape (3, 3)
        Rotation from reference to principal axes (rows = axes)

    Raises
    ------
    TypeError
        If ``inertia`` is not numbers or ``order`` is not a string.
    ValueError
        If ``inertia`` is not a finite, symmetric, positive definite 3x3 matrix, or ``order``
        is unknown.

    References
    ----------
    .. [1] Rheinfurth & Wilson, NASA RP-1262, Sec. 4.4 D (the Gemini example).

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.attitude import principal_axes
    >>> inertia = [[4560.7, 31.2, -43.4], [31.2, 4545.0, -270.7], [-43.4, -270.7, 1567.4]]
    >>> moments, A = principal_axes(inertia)  # Gemini (Sec. 4.4)
    >>> np.round(moments, 3)
    array([4530.119, 4600.532, 1542.449])
    >>> round(float(np.degrees(np.arccos((np.trace(A) - 1) / 2))), 2)  # rotation angle [deg]
    42.01
    """

    inertia = validate.check_inertia(validate.finite_array(inertia, "inertia"), triangle=False)
    order = validate.one_of(order, "order", ("nearest", "ascending", "descending"))
    vals, vecs = np.linalg.eigh(inertia)  # ascending
    perms = list(itertools.permutations(range(3)))
    if order == "ascending":
        perms = [(0, 1, 2)]
    elif order == "descending":
        perms = [(2, 1, 0)]
    best = None
    for perm in perms:
        for signs in itertools.product((1.0, -1.0), repeat=3):
            phi = vecs[:, perm] * np.array(signs)
            if np.linalg.det(phi) < 0:
                continue
            tr = np.trace(phi)
            if best is None or tr > best[0] + 1e-12:
                best = (tr, vals[list(perm)], phi.T.copy())
    return best[1], best[2]
