"""Floquet analysis of time-periodic operating points: the monodromy matrix and its
multipliers.

A solution ``x*(t)`` of ``x' = f(x, u, p)`` that repeats after ``T`` (a time-periodic model
carrying the clock of `dynamics.clock`, with a periodic prescribed motion, at an orbit
such as the hanging or inverted shaken pendulum; or an equilibrium of any model, for any
``T``) is stable as its linear perturbations ``dx' = A(t) dx``, ``A = df/dx (x*(t))``, are.
Over one period they are mapped by the **monodromy matrix** ``Phi(T)``:

    Phi' = A(t) Phi,   Phi(0) = E,    dx(T) = Phi(T) dx(0)

Its eigenvalues, the Floquet **multipliers** ``mu``, decide: perturbations grow like
``|mu|^(t/T)``; the **exponents** ``log(mu) / T`` [1/s] play the role of eigenvalues
(``log`` the principal branch: the imaginary part is defined only modulo ``2 pi / T``).

Method. ``Phi`` is integrated together with the orbit, from the model's exact CasADi
Jacobian: the model is augmented with the ``n x n`` variational states (`variational_model`,
built once per model and cached) and run through `dynamics.simulate` -- by default with
``method='auto'``, whose verified global error bound ``atol + rtol |x|`` then holds for
every entry of ``Phi``; with ``steps`` a fixed rk8 run. The clock state is excluded: its
perturbation is zero (the clock always starts at the run's start time), so its row of the
full monodromy is ``[0 ... 0 1]`` with the trivial multiplier 1, and the other states'
equations need only the Jacobian columns of the other states. ``Phi`` is therefore
``(nx - 1) x (nx - 1)`` for a model with a clock, ordered like ``model.states`` without
``t``.

Checks that come free: by Liouville's formula ``det Phi(T) = exp(int_0^T tr A dt)``, so a
Hamiltonian (undamped) system has ``det = 1`` and reciprocal multiplier pairs.

Verdict (``tol`` default `TOL` = 1e-6). With ``r = max |mu|``: ``"asymptotically stable"`` if
``r < 1 - tol``, ``"marginally stable"`` if ``r <= 1 + tol``, ``"unstable"`` otherwise.
The default ``rtol`` of 1e-10 leaves simple multipliers accurate to about 1e-10, so
``1e-6`` separates numerical error from growth by four orders; at the edge of an
instability region two multipliers meet at +-1 and each moves by about the square root
of the error (1e-5), where no verdict is reliable -- and a double multiplier on the unit
circle with a Jordan block (linear growth) is not detected: it counts as marginal.

Measured (tests/dynamics/test_floquet.py, shaken pendulum): the monodromy agrees with
central differences of scipy's DOP853 at rtol 1e-12 to 2e-10 of its size, the multipliers
to 1e-10; ``det Phi`` matches Liouville to 1e-12; stability edges found by root finding on
``tr Phi = +-2`` agree with Mathieu's characteristic values to 1e-11. A call takes about
3 ms once the model's variational loop is compiled (about 0.4 s, once per model).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import casadi as ca
import numpy as np

from . import cache, validate
from .clock import clock_index
from .figures import axes_or_new_figure, finish_figure
from .integrate import simulate
from .model import Model, check_model
from .results import Result
from .serialize import jsonable, text_table, to_json

__all__ = ["FloquetResult", "monodromy", "floquet", "variational_model", "classify_multipliers",
           "VERDICTS", "TOL"]

#: the verdicts, worst first
VERDICTS = ("unstable", "marginally stable", "asymptotically stable")
#: default distance from the unit circle below which a multiplier counts as on it
TOL = 1e-6


# -------------------------------------------------------------------- variational model
def variational_model(model: Model) -> Model:
    """``model`` augmented with its variational equations ``Phi' = A Phi`` (clock excluded).

    Parameters
    ----------
    model : Model

    Returns
    -------
    Model
        States ``model.states`` followed by the ``n x n`` entries of ``Phi`` in column-major
        order, named ``Phi_i_j`` (``n = nx - 1`` with a clock, else ``nx``); the same controls
        and parameters. Cached per ``model.f``: its ``p_default`` is that of the first model
        seen with this ``f``, so always pass ``p`` explicitly.

    Examples
    --------
    >>> from appdyn.dynamics.floquet import variational_model
    >>> from appdyn.dynamics.mechanisms import shaken_pendulum
    >>> variational_model(shaken_pendulum()).states
    ('theta', 'theta_dot', 't', 'Phi_0_0', 'Phi_1_0', 'Phi_0_1', 'Phi_1_1')
    """
    model = check_model(model)
    return cache.get(("floquet.variational", cache.function_key(model.f)),
                     lambda: _build_variational(model), keepalive=model.f)


def _build_variational(model: Model) -> Model:
    ic = clock_index(model)
    keep = [i for i in range(model.nx) if i != ic]
    n = len(keep)
    sym = ca.SX if model.f.is_a("SXFunction") else ca.MX
    x, u, p = sym.sym("x", model.nx), sym.sym("u", model.nu), sym.sym("p", model.np)
    phi = sym.sym("Phi", n, n)
    xdot = model.f(x, u, p)
    jac = ca.jacobian(xdot, x)[keep, keep]
    rhs = ca.vertcat(xdot, ca.vec(ca.mtimes(jac, phi)))
    f = ca.Function(f"{model.f.name()}_variational", [ca.vertcat(x, ca.vec(phi)), u, p], [rhs],
                    ["x", "u", "p"], ["xdot"])
    names = tuple(f"Phi_{i}_{j}" for j in range(n) for i in range(n))
    return Model(f, model.states + names, model.controls, model.params,
                 p_default=model.p_default, units=dict(model.units),
                 name=f"{model.name}_variational")


# ---------------------------------------------------------------------------- result
@dataclass(frozen=True, repr=False)
class FloquetResult(Result):
    """Floquet multipliers of a periodic orbit and the verdict on its stability.

    Attributes
    ----------
    multipliers : ndarray of complex, shape (n,)
        Eigenvalues of `monodromy`, by decreasing modulus.
    exponents : ndarray of complex, shape (n,) [1/s]
        ``log(mu) / period`` (principal branch).
    monodromy : ndarray, shape (n, n)
        ``Phi(T)``, states as ``states``.
    period : float [s]
    states : tuple of str
        The model's states without the clock.
    verdict : {'unstable', 'marginally stable', 'asymptotically stable'}
    reason : str
        The deciding multiplier and ``tol``, in words.
    tol : float
    closure : float
        ``max |x(T) - x0|`` over ``states`` [state units]: near zero for a periodic orbit
        (Floquet theory says nothing about an ``x0`` that does not repeat).
    success : bool
        The integration succeeded (and met its tolerance for ``method='auto'``).
    status : int
        `dynamics.simulate`'s status.
    message : str
    wall_time : float [s]
    model_name : str
    """

    multipliers: np.ndarray
    exponents: np.ndarray
    monodromy: np.ndarray
    period: float
    states: tuple
    verdict: str
    reason: str
    tol: float
    closure: float
    success: bool
    status: int
    message: str
    wall_time: float
    model_name: str = "model"

    _repr_fields = ('verdict', 'period', 'multipliers', 'closure')

    @property
    def spectral_radius(self) -> float:
        """``max |mu|``: the growth of the worst perturbation over one period."""
        return float(np.max(np.abs(self.multipliers), initial=0.0))

    def to_dict(self) -> dict:
        """Plain-Python summary (complex numbers as ``[re, im]``)."""
        return jsonable({
            "model": self.model_name, "success": self.success, "status": self.status,
            "message": self.message, "verdict": self.verdict, "reason": self.reason,
            "period": self.period, "tol": self.tol, "closure": self.closure,
            "states": list(self.states), "multipliers": self.multipliers,
            "exponents": self.exponents, "monodromy": self.monodromy,
            "spectral_radius": self.spectral_radius, "wall_time": self.wall_time})

    def __str__(self) -> str:
        rows = [("verdict", f"{self.verdict}: {self.reason}"), ("period", f"{self.period:.6g} s"),
                ("closure", f"{self.closure:.2e} (|x(T) - x0|)")]
        for k, (mu, s) in enumerate(zip(self.multipliers, self.exponents)):
            rows.append((f"mu{k + 1}", f"{mu.real:+.9f} {mu.imag:+.9f}j  |mu| = {abs(mu):.9f}  "
                                       f"exponent {s.real:+.4e} {s.imag:+.4e}j 1/s"))
        rows += [("success", f"{self.success} (status {self.status})"),
                 ("wall time", f"{1e3 * self.wall_time:.1f} ms"), ("message", self.message)]
        return text_table(f"Floquet analysis of {self.model_name}", rows)

    def plot(self, ax=None):
        """The multipliers in the complex plane, with the unit circle.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Draw on these axes; by default on a new `matplotlib.figure.Figure` (no pyplot).

        Returns
        -------
        matplotlib.figure.Figure
        """
        fig, ax = axes_or_new_figure(ax, (5.5, 5.5))
        phase = np.linspace(0.0, 2 * np.pi, 361)
        ax.plot(np.cos(phase), np.sin(phase), "k-", lw=0.8, label="|mu| = 1")
        ax.plot(self.multipliers.real, self.multipliers.imag, "x", ms=9, mew=2, label="mu")
        ax.set(xlabel="Re mu", ylabel="Im mu", aspect="equal",
               title=f"Floquet multipliers of {self.model_name}: {self.verdict}")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
        return finish_figure(fig)


def classify_multipliers(multipliers, *, tol: float = TOL) -> tuple[str, str]:
    """Verdict and reason for Floquet multipliers (the rule of the module notes).

    Parameters
    ----------
    multipliers : array_like of complex, shape (n,)
    tol : float, optional
        ``0 < tol < 1``.

    Returns
    -------
    verdict : str
        One of `VERDICTS`.
    reason : str

    Raises
    ------
    ValueError
        Naming ``tol`` (out of range) or ``multipliers`` (not finite).

    Examples
    --------
    >>> from appdyn.dynamics.floquet import classify_multipliers
    >>> classify_multipliers([0.5, -0.9j])[0], classify_multipliers([1j, -1j])[0]
    ('asymptotically stable', 'marginally stable')
    >>> classify_multipliers([2.0, 0.5])
    ('unstable', '|mu| = 2 > 1 + tol (mu = 2+0j, tol = 1e-06)')
    """
    tol = _check_tol(tol)
    mu = np.asarray(multipliers, dtype=complex).reshape(-1)
    if not np.all(np.isfinite(mu)):
        raise ValueError(f"`multipliers` must be finite, got {mu}")
    if mu.size == 0:
        return "asymptotically stable", "no perturbation states"
    worst = complex(mu[np.argmax(np.abs(mu))])
    r = abs(worst)
    text = f"mu = {worst:.6g}, tol = {tol:g}"
    if r < 1 - tol:
        return "asymptotically stable", f"|mu| = {r:.9g} < 1 - tol ({text})"
    if r <= 1 + tol:
        return "marginally stable", f"|mu| = {r:.9g} within 1 +- tol ({text})"
    return "unstable", f"|mu| = {r:.9g} > 1 + tol ({text})"


def _check_tol(tol) -> float:
    tol = validate.positive(tol, "tol")
    if tol >= 1:
        raise ValueError(f"`tol` must be in (0, 1), got {tol!r}")
    return tol


# ------------------------------------------------------------------------- drivers
def _propagate(model, x0, period, u, p, rtol, atol, steps, jit):
    model = check_model(model)
    x0 = validate.finite_array(x0, "x0", (model.nx,))
    period = validate.positive(period, "period")
    ic = clock_index(model)
    keep = [i for i in range(model.nx) if i != ic]
    n = len(keep)
    t0 = float(x0[ic]) if ic is not None else 0.0
    aug = variational_model(model)
    options = {"method": "auto", "rtol": rtol, "atol": atol} if steps is None else \
        {"method": "rk8", "steps": validate.integer(steps, "steps", minimum=1)}
    res = simulate(aug, np.concatenate([x0, np.eye(n).ravel(order="F")]),
                   [t0, t0 + period], u=u, p=model.resolve_p(p), jit=jit, **options)
    end = res.x[:, -1]
    phi = end[model.nx:].reshape((n, n), order="F")
    closure = float(np.max(np.abs(end[keep] - x0[keep]), initial=0.0))
    return model, keep, phi, closure, res


def monodromy(model, x0, period, *, u=None, p=None, rtol=1e-10, atol=1e-10, steps=None,
              jit=None) -> np.ndarray:
    """Monodromy matrix ``Phi(T)`` of the orbit through ``x0`` (clock excluded).

    Parameters
    ----------
    model : Model
    x0 : array_like, shape (nx,)
        A state on the periodic orbit; with a clock, its clock is the start time [s].
    period : float [s]
        ``T > 0``.
    u : array_like, shape (nu,), optional
        Constant control (default zero).
    p : array_like, shape (np,), optional
        Parameters (default ``model.p_default``).
    rtol, atol : float, optional
        Global error bound of ``method='auto'`` on the orbit and on every entry of ``Phi``.
    steps : int, optional
        Instead, a fixed rk8 run of this many steps over the period.
    jit : bool, optional
        As for `dynamics.simulate`.

    Returns
    -------
    numpy.ndarray, shape (n, n)
        ``n = nx - 1`` with a clock (its row and column dropped), else ``nx``.

    Raises
    ------
    TypeError
        If ``model`` is not a `dynamics.Model`.
    ValueError
        Naming ``x0`` (shape, finiteness), ``period`` (not positive), ``steps``, or an
        argument `dynamics.simulate` refuses (``u``, ``p``, ``rtol``, ``atol``).

    Examples
    --------
    An equilibrium of an autonomous model: ``Phi(T) = expm(A T)``; for the double pendulum
    hanging at rest, ``det Phi = 1`` (no damping):

    >>> import numpy as np
    >>> from appdyn.dynamics.floquet import monodromy
    >>> from appdyn.dynamics.mechanisms import double_pendulum
    >>> phi = monodromy(double_pendulum(), np.zeros(4), 1.0, jit=False)
    >>> phi.shape, round(float(np.linalg.det(phi)), 9)
    ((4, 4), 1.0)
    """
    return _propagate(model, x0, period, u, p, rtol, atol, steps, jit)[2]


def floquet(model, x0, period, *, u=None, p=None, tol=TOL, rtol=1e-10, atol=1e-10,
            steps=None, jit=None) -> FloquetResult:
    """Floquet multipliers, exponents and stability verdict of a periodic orbit.

    Parameters
    ----------
    model, x0, period, u, p, rtol, atol, steps, jit
        As for `monodromy`.
    tol : float, optional
        Distance from the unit circle within which a multiplier counts as on it
        (default `TOL`; see the module notes).

    Returns
    -------
    FloquetResult
        A failed integration gives ``success=False`` (and NaN multipliers, verdict
        ``"unknown"``, if the matrix is not finite); it does not raise.

    Raises
    ------
    TypeError, ValueError
        As for `monodromy`; ``tol`` outside ``(0, 1)``.

    Examples
    --------
    The inverted physical pendulum, shaken vertically by 2 cm at 200 rad/s (above its
    Kapitza frequency of 128 rad/s), with a little hinge damping:

    >>> import math
    >>> from appdyn.dynamics.floquet import floquet
    >>> from appdyn.dynamics.mechanisms import shaken_pendulum
    >>> model = shaken_pendulum(freq=200.0, damping=0.002)
    >>> res = floquet(model, [math.pi, 0.0, 0.0], 2 * math.pi / 200.0, jit=False)
    >>> res.verdict, res.success, res.multipliers.shape
    ('asymptotically stable', True, (2,))
    >>> round(res.spectral_radius, 6)   # a damped pair: |mu| = exp(-c T / (2 I_h))
    0.999623
    """
    start = time.perf_counter()
    tol = _check_tol(tol)
    model, keep, phi, closure, res = _propagate(model, x0, period, u, p, rtol, atol, steps, jit)
    period = float(period)
    if np.all(np.isfinite(phi)):
        mu = np.linalg.eigvals(phi).astype(complex)
        mu = mu[np.argsort(-np.abs(mu), kind="stable")]
        verdict, reason = classify_multipliers(mu, tol=tol)
    else:
        mu = np.full(len(keep), complex(math.nan, math.nan))
        verdict, reason = "unknown", "the monodromy matrix is not finite"
    with np.errstate(divide="ignore", invalid="ignore"):
        exponents = np.log(mu) / period
    return FloquetResult(
        multipliers=mu, exponents=exponents, monodromy=phi, period=period,
        states=tuple(model.states[i] for i in keep), verdict=verdict, reason=reason,
        tol=float(tol), closure=closure, success=bool(res.success), status=int(res.status),
        message=res.message, wall_time=time.perf_counter() - start, model_name=model.name)
