"""Worked example: how the nutation angle of a spinning spacecraft spreads under uncertainty.

A near-axisymmetric rigid body (principal moments ``I_t (1 + d/2)``, ``I_t (1 - d/2)``,
``I_a``; symmetry axis body 3) spins at ``w3`` with a small transverse rate ``w1``. Its
nutation angle is the angle between the body symmetry axis and the (inertially fixed)
angular momentum ``H``. For an axisymmetric body (``d = 0``), torque-free, it is constant
(RP-1262 Sec. 4.5; `dynamics.truth.symmetric_precession`):

    theta = atan(I_t |w_t| / (I_a w3)),   |w_t| = sqrt(w1^2 + w2^2).

`nutation_spread` disperses ``I_t``, ``I_a`` (and ``d``, ``w1``, ``w3``) and reports the spread
of the simulated nutation angle. Everything here is module-level, so the samples also run
on a ``ProcessPoolExecutor``.
"""
from __future__ import annotations

import numpy as np

from appdyn.dynamics import rigid_body, validate
from appdyn.dynamics.attitude import dcm_from_quat

from .distributions import Normal
from .run import dispersion

__all__ = ["spinner", "nutation_history", "nutation_max", "nutation_closed_form",
           "nutation_spread"]


def _moments(transverse_inertia, axial_inertia, transverse_asymmetry):
    d = validate.finite_scalar(transverse_asymmetry, "transverse_asymmetry")
    it = validate.positive(transverse_inertia, "transverse_inertia")
    ia = validate.positive(axial_inertia, "axial_inertia")
    return np.array([it * (1 + d / 2), it * (1 - d / 2), ia], dtype=float)


_QUATERNION = ("q1", "q2", "q3", "q4")
_RATES = ("w1", "w2", "w3")


def _states(res) -> tuple:
    """``(q, w)``, shapes (4, n) and (3, n), of a run, picked by the state names (a `spinner`
    run, or a scene's: its hub's ``q1..q4, w1..w3``), checked finite."""
    if not hasattr(res, "x"):
        raise validate.ArgumentTypeError(f"`res` must be a SimulationResult (with states `x`), "
                                         f"got {type(res).__name__}")
    x = validate.finite_array(res.x, "res.x")
    names = tuple(getattr(res, "states", ()))
    if x.ndim != 2 or x.shape[1] == 0 or not set(_QUATERNION + _RATES) <= set(names) \
            or x.shape[0] != len(names):
        raise ValueError(f"`res` must be a run with states q1..q4, w1..w3 (a spinner or a "
                         f"scene), got states {names} and `res.x` of shape {x.shape}")
    return (x[[names.index(s) for s in _QUATERNION]], x[[names.index(s) for s in _RATES]])


def spinner(transverse_inertia, axial_inertia, transverse_asymmetry=0.0):
    """`dynamics.rigid_body` with principal moments ``(I_t (1 + d/2), I_t (1 - d/2), I_a)``.

    Parameters
    ----------
    transverse_inertia : float [kg m^2]
        Mean transverse moment ``I_t``.
    axial_inertia : float [kg m^2]
        Moment ``I_a`` about the symmetry axis (body 3).
    transverse_asymmetry : float, optional
        Relative difference ``d = (I_1 - I_2) / I_t`` of the transverse moments (0: axisymmetric).

    Returns
    -------
    Model
        ``rigid_body`` (cached by inertia).

    Examples
    --------
    >>> from appdyn.problems.dispersion import spinner
    >>> spinner(1000.0, 1500.0).states
    ('q1', 'q2', 'q3', 'q4', 'w1', 'w2', 'w3')
    """
    return rigid_body(_moments(transverse_inertia, axial_inertia, transverse_asymmetry))


def nutation_history(res, transverse_inertia, axial_inertia, transverse_asymmetry=0.0):
    """Angle between the body symmetry axis and the initial inertial momentum, along ``res``.

    ``theta(t) = atan2(|b x h|, b . h)`` with ``b = A(q(t))^T e3`` (the symmetry axis in
    inertial axes) and ``h = A(q0)^T I w0`` (the angular momentum at ``t[0]``, inertial): it
    uses the simulated attitude, not only the rates.

    Parameters
    ----------
    res : SimulationResult
        A `spinner` run (states ``q1..q4, w1..w3``).
    transverse_inertia, axial_inertia, transverse_asymmetry : float
        As for `spinner`.

    Returns
    -------
    ndarray, shape (n,) [rad]

    Raises
    ------
    TypeError
        If ``res`` is not a simulation result, or an inertia is not a real number.
    ValueError
        If ``res.x`` is not finite or has no states ``q1..q4, w1..w3``, or an inertia is not
        finite and ``> 0``.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics import simulate
    >>> from appdyn.problems.dispersion import nutation_closed_form, nutation_history, spinner
    >>> res = simulate(spinner(1000.0, 1500.0), [0, 0, 0, 1, 0.02, 0, 1.0],
    ...                np.linspace(0, 10, 11), jit=False)
    >>> theta = nutation_history(res, 1000.0, 1500.0)
    >>> bool(np.max(np.abs(theta - nutation_closed_form(1000.0, 1500.0, [0.02, 0, 1.0]))) < 1e-9)
    True
    """
    inertia = _moments(transverse_inertia, axial_inertia, transverse_asymmetry)
    q, w = _states(res)
    h = dcm_from_quat(q[:, 0]).T @ (inertia * w[:, 0])
    b = np.einsum("jik,j->ik", dcm_from_quat(q), np.array([0.0, 0.0, 1.0]))
    return np.arctan2(np.linalg.norm(np.cross(b.T, h), axis=1), b.T @ h)


def nutation_max(res, transverse_inertia, axial_inertia, transverse_asymmetry=0.0) -> float:
    """Largest `nutation_history` angle along ``res`` [rad] (errors as for it)."""
    return float(np.max(nutation_history(res, transverse_inertia, axial_inertia,
                                         transverse_asymmetry)))


def nutation_closed_form(transverse_inertia, axial_inertia, w0) -> float:
    """``atan2(I_t |w_t|, I_a w3)`` [rad]: the constant nutation of an axisymmetric body.

    Parameters
    ----------
    transverse_inertia, axial_inertia : float [kg m^2]
    w0 : array_like, shape (3,) [rad/s]
        Body rates (any time: ``|w_t|`` and ``w3`` are constant).

    Raises
    ------
    TypeError
        If an argument is not real numbers.
    ValueError
        If an inertia is not finite and ``> 0``, or ``w0`` is not 3 finite numbers.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.problems.dispersion import nutation_closed_form
    >>> round(float(np.degrees(nutation_closed_form(1000.0, 1500.0, [0.02, 0.0, 1.0]))), 6)
    0.763898
    """
    it = validate.positive(transverse_inertia, "transverse_inertia")
    ia = validate.positive(axial_inertia, "axial_inertia")
    w = validate.finite_array(w0, "w0", (3,))
    return float(np.arctan2(it * np.hypot(w[0], w[1]), ia * w[2]))


def _closed_form_output(res, transverse_inertia, axial_inertia):
    return nutation_closed_form(transverse_inertia, axial_inertia, _states(res)[1][:, 0])


def nutation_spread(samples: int = 200, seed: int | None = 0, *,
                    transverse_inertia=Normal(1000.0, 20.0), axial_inertia=Normal(1500.0, 30.0),
                    transverse_asymmetry=0.0, transverse_rate=Normal(0.02, 0.004),
                    spin_rate=1.0, duration: float = 30.0, points: int = 61,
                    executor=None, progress=None, **simulate_kwargs):
    """Monte Carlo spread of the nutation angle of a spinning spacecraft.

    Each sample is a `spinner` with drawn moments, started at ``q = [0, 0, 0, 1]``,
    ``w = [transverse_rate, 0, spin_rate]``, simulated torque-free over ``duration``.

    Parameters
    ----------
    samples : int, optional
    seed : int or None, optional
    transverse_inertia, axial_inertia : spec, optional [kg m^2]
        ``I_t`` and ``I_a`` (numbers, `Distribution` s or callables ``rng -> value``).
    transverse_asymmetry : spec, optional
        ``d`` of `spinner` (0: axisymmetric, where the closed form is exact).
    transverse_rate, spin_rate : spec, optional [rad/s]
        Initial ``w1`` and ``w3``.
    duration : float, optional [s]
    points : int, optional
        Output times on ``[0, duration]``.
    executor, progress, **simulate_kwargs
        As for `dispersion`.

    Returns
    -------
    DispersionResult
        Outputs ``nutation`` (history, shape (points,)) and ``nutation_max`` [rad] (from the
        simulation), ``nutation_closed_form`` [rad] (``atan2(I_t |w_t|, I_a w3)`` of the
        sample: exact when ``d = 0``), and the drifts ``energy_drift``,
        ``momentum_inertial_drift``, ``quat_norm_drift``.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.problems.dispersion import nutation_spread
    >>> res = nutation_spread(samples=8, seed=1, points=21)
    >>> res.success, res.outputs["nutation"].shape
    (True, (8, 21))
    >>> err = res.outputs["nutation"] - res.outputs["nutation_closed_form"][:, None]
    >>> bool(np.max(np.abs(err)) < 1e-8)  # axisymmetric: the closed form, sample by sample
    True
    """
    t = np.linspace(0.0, float(duration), int(points))
    params = {"transverse_inertia": transverse_inertia, "axial_inertia": axial_inertia,
              "transverse_asymmetry": transverse_asymmetry, "w1": transverse_rate,
              "w3": spin_rate}
    outputs = {"nutation": nutation_history, "nutation_max": nutation_max,
               "nutation_closed_form": _closed_form_output}
    units = {"nutation": "rad", "nutation_max": "rad", "nutation_closed_form": "rad",
             "transverse_inertia": "kg m^2", "axial_inertia": "kg m^2", "w1": "rad/s",
             "w3": "rad/s"}
    return dispersion(spinner, [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0], t, samples=samples,
                      seed=seed, outputs=outputs, params=params, invariant_drift=True,
                      executor=executor, progress=progress, units=units, **simulate_kwargs)
