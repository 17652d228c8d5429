"""Check of an inertia matrix (symmetric positive definite, triangle inequality)."""
from __future__ import annotations

import numpy as np

from .base import real_array

__all__ = ["check_inertia"]


def check_inertia(inertia, *, name="inertia", triangle=True):
    """Validate an inertia matrix and return it as a float array.

    Parameters
    ----------
    inertia : array_like, shape (3, 3) or (3,) [kg m^2]
        Full symmetric matrix, or the three principal moments (a diagonal matrix).
    name : str
        Argument name used in error messages.
    triangle : bool
        Also require the triangle inequality of the principal moments, ``I_i + I_j >= I_k``
        (Rheinfurth & Wilson, NASA RP-1262, Sec. 4.4 A), which every physical body satisfies.

    Returns
    -------
    ndarray, shape (3, 3)

    Raises
    ------
    ArgumentTypeError
        (a ``TypeError`` and ``ValueError``) If ``inertia`` does not hold numbers.
    ValueError
        Naming the argument and the violated requirement: shape, finiteness, symmetry,
        positive definiteness (eigenvalues shown), triangle inequality (moments shown).

    Examples
    --------
    >>> from appdyn.dynamics.validate import check_inertia
    >>> check_inertia([1.0, 2.0, 3.0])  # principal moments become a diagonal matrix
    array([[1., 0., 0.],
           [0., 2., 0.],
           [0., 0., 3.]])
    >>> check_inertia([1.0, 1.0, 3.0])
    Traceback (most recent call last):
        ...
    ValueError: `inertia` violates the triangle inequality I1 + I2 >= I3 ...
    """
    a = np.array(real_array(inertia, name), dtype=float)  # refuses strings and booleans
    if a.shape == (3,):
        a = np.diag(a)
    if a.shape != (3, 3):
        raise ValueError(f"`{name}` must have shape (3, 3) or (3,), got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"`{name}` must be finite, got {a.tolist()}")
    scale = np.max(np.abs(a))
    if np.max(np.abs(a - a.T)) > 1e-12 * max(scale, 1e-300):
        raise ValueError(f"`{name}` must be symmetric, got {a.tolist()}")
    a = 0.5 * (a + a.T)
    eig = np.linalg.eigvalsh(a)
    if eig[0] <= 0:
        raise ValueError(
            f"`{name}` must be symmetric positive definite, got eigenvalues {tuple(eig.tolist())}")
    if triangle and eig[0] + eig[1] < eig[2] * (1 - 1e-12):
        raise ValueError(
            f"`{name}` violates the triangle inequality I1 + I2 >= I3 of rigid-body principal "
            f"moments (Rheinfurth & Wilson, NASA RP-1262, Sec. 4.4 A): principal moments "
            f"{tuple(eig.tolist())}"
        )
    return a
