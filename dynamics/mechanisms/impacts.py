"""Impact dynamics (Rheinfurth & Wilson, NASA RP-1262, Sec. 3.5): the impulse equations
(Eqs. 3.50-3.52) on a generalized-coordinate model, Newton's coefficient of restitution
(Eq. 3.53), sticking and sliding (Coulomb) contact, and the seed's Examples 1-5.

The model
---------
During an impact the coordinates ``q`` stay put and the rates ``v = q'`` jump. With the mass
matrix ``M(q)`` (``T = 1/2 v' M v``), the contact's normal Jacobian ``n (n_q,)`` (the normal
relative velocity of the contact points is ``n . v``, negative while they approach) and its
tangent Jacobian ``D (k, n_q)`` (``k = 1`` planar, 2 spatial; the slip velocity ``D v``),
the integrated equations of motion (Eqs. 3.51-3.52 in generalized form) read::

    M (v+ - v-) = n P_n + D' P_t             (other forces are finite: no impulse)

with the normal impulse ``P_n >= 0`` and the friction impulse ``P_t``. Newton's restitution
(Eq. 3.53) closes the normal direction: ``n . v+ = -e n . v-``. In the Delassus matrix
``W = J M^-1 J'`` (``J = [n; D]``):

* **sticking** (the seed's "normal rebound"): the slip stops, ``D v+ = 0``;
  ``W [P_n; P_t] = -[(1 + e) n.v-; D v-]``, kept when ``|P_t| <= mu P_n``;
* **sliding**: otherwise ``P_t = mu P_n d`` along the direction ``d = P_t / |P_t|`` of the
  sticking impulse (the seed's ``R = mu F`` opposing the slip), and
  ``(W_nn + mu W_nt d) P_n = -(1 + e) n.v-``;
* **frictionless** (no ``D`` or ``mu = 0``): ``P_n = -(1 + e) n.v- / W_nn``, and the kinetic
  energy lost is exactly ``1/2 (1 - e^2) (n.v-)^2 / W_nn`` (Example 1:
  ``1/2 m1 m2 / (m1 + m2) (1 - e^2) (u1 - u2)^2``).

Energy: a frictionless impact, and any impact with ``e = 0``, never gains kinetic energy; a
sticking impact without slip before it (``D v- = 0``) loses exactly
``1/2 (1 - e^2) (n.v-)^2 (W^-1)_nn``. With friction and ``e > 0`` Newton's law can gain
energy where the slip couples to the normal (Kane's paradox; e.g. Example 5 with ``u0 =
-v0``, ``e = 1``): the result says so in its ``message`` and a negative ``energy_loss``.

`impact` solves these; `contact_jump` makes of them the jump map of an impact event of
`simulate` (`dynamics.integrate.impacts`).

Seed errata found by re-deriving (the closed forms below are the corrected ones): Example 3,
Eq. 3.61 needs ``phi' l / (2 sqrt 2)`` (printed ``phi' l / sqrt 2``), the normal rebound's
``phi' = (1 + e) v0 / (2 sqrt 2 l)`` (printed without ``1/l``), its normal impulse is
``F = 7/12 (1 + e) m v0`` (printed 7/24) and so normal rebound needs ``mu >= 1/7`` (printed
2/7; the sliding solution meets the normal one at ``mu = 1/7``); Example 4, Eq. 3.71 reads
``y1' cos(alpha)``; Example 5 at 45 deg, ``omega = 3 ((1 + e) v0 - u0) / (2 sqrt 2 l)``
(Eq. 3.93 prints ``2 (1 + e) v0``), ``R = m (5 u0 + 3 (1 + e) v0) / 8`` (Eq. 3.94 prints
``(1 + e) v0``) and normal rebound needs ``mu > (5 u0 + 3 (1 + e) v0) / (3 u0 + 5 (1 + e)
v0)`` (Eq. 3.96 prints the ratio upside down).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Mapping

import numpy as np

from .. import validate
from ..results import Result, quantity

__all__ = ["ImpactResult", "impact", "contact_jump", "central_collision", "ballistic_pendulum",
           "dumbbell_impact", "carriage_impact", "falling_bar_impact", "SEPARATING", "FRICTIONLESS",
           "STICKING", "SLIDING"]

#: Regimes of an `ImpactResult`.
SEPARATING, FRICTIONLESS, STICKING, SLIDING = "separating", "frictionless", "sticking", "sliding"

# relative slack of the friction-cone test |P_t| <= mu P_n (round-off of the sticking solve)
_CONE_SLACK = 1e-12
# energy gained relative to the kinetic energy before that the message reports
_GAIN_TOL = 1e-12


@dataclass(frozen=True, repr=False)
class ImpactResult(Result):
    """Outcome of `impact`: the rates after the impact and the impulses.

    Follows the result protocol (`dynamics.results.Result`): ``status`` is 0 when the impulse
    was found, -1 when the contact jams (``success`` False).

    Attributes
    ----------
    v : ndarray, shape (n_q,)
        Generalized rates after the impact ``v+`` [model units].
    v_before : ndarray, shape (n_q,)
        The rates before ``v-``.
    impulse : ndarray, shape (n_q,)
        Generalized impulse ``n P_n + D' P_t = M (v+ - v-)``.
    normal_impulse : float [N s]
        ``P_n >= 0`` (0 when separating).
    tangent_impulse : ndarray, shape (k,) [N s]
        ``P_t`` (empty without a tangent Jacobian).
    regime : str
        ``'separating'`` (``n.v- >= 0``: no impact), ``'frictionless'``, ``'sticking'`` (the
        slip stops: the seed's normal rebound) or ``'sliding'`` (on the friction cone).
    normal_velocity : (float, float) [m/s]
        ``n.v`` before and after (after: ``-e`` times before).
    slip : ndarray, shape (k,) [m/s]
        ``D v+``: the slip velocity after (zero when sticking).
    energy_loss : float [J]
        ``T(v-) - T(v+)``.
    success : bool
        False when no impulse on the friction cone stops the approach (a sliding contact
        whose normal impulse would have to be negative: the contact jams).
    message : str
        What happened.
    names : tuple of str
        Names of the rates (``res["x_dot"]`` reads one).
    derived : mapping of str to float
        Quantities an example computes from the rates (e.g. the rebound angle).
    """

    v: np.ndarray
    v_before: np.ndarray
    impulse: np.ndarray
    normal_impulse: float
    tangent_impulse: np.ndarray
    regime: str
    normal_velocity: tuple
    slip: np.ndarray
    energy_loss: float
    success: bool = True
    message: str = ""
    names: tuple = ()
    derived: Mapping[str, float] = field(default_factory=lambda: MappingProxyType({}))

    _repr_fields = ("regime", "v", "normal_impulse", "normal_velocity", "energy_loss")

    @property
    def status(self) -> int:
        """0: the impulse found; -1: the contact jams (no impulse on the friction cone)."""
        return 0 if self.success else -1

    def to_dict(self) -> dict:
        """The fields, ``status`` and the derived quantities as plain data."""
        return dict(super().to_dict(), status=self.status, derived=dict(self.derived))

    def __str__(self) -> str:
        rates = ", ".join(f"{n} = {quantity(x)}" for n, x in zip(self.names, self.v)) or \
            ", ".join(quantity(x) for x in self.v)
        lines = [f"impact ({self.regime}): {'success' if self.success else 'FAILED'}"
                 + (f" -- {self.message}" if self.message else ""),
                 f"  normal velocity  {quantity(self.normal_velocity[0], 'm/s')} before, "
                 f"{quantity(self.normal_velocity[1], 'm/s')} after",
                 f"  normal impulse   {quantity(self.normal_impulse, 'N s')}",
                 f"  energy lost      {quantity(self.energy_loss, 'J')}",
                 f"  rates after      {rates} (model units)"]
        lines += [f"  {k:<16} {quantity(v)}" for k, v in self.derived.items()]
        return "\n".join(lines)

    def __getstate__(self) -> dict:
        return dict(self.__dict__, derived=dict(self.derived))

    def __setstate__(self, state: dict) -> None:
        for key, value in state.items():
            object.__setattr__(self, key, MappingProxyType(dict(value)) if key == "derived"
                               else value)

    def __getitem__(self, name: str) -> float:
        """The rate ``name`` after the impact, or a derived quantity.

        Raises
        ------
        KeyError
            If ``name`` is neither (the message lists both).
        """
        if name in self.names:
            return float(self.v[self.names.index(name)])
        if name in self.derived:
            return float(self.derived[name])
        raise KeyError(f"no rate or derived quantity named {name!r}; the rates are "
                       f"{self.names}, the derived quantities {tuple(self.derived)}")


def _matrix(M, n: int) -> np.ndarray:
    M = validate.finite_array(M, "mass_matrix")
    M = M.reshape(1, 1) if M.ndim == 0 else M
    if M.ndim != 2 or M.shape[0] != M.shape[1] or M.shape[0] != n:
        raise ValueError(f"`mass_matrix` must be square of the size of `v` ({n}), got shape "
                         f"{M.shape}")
    if not np.allclose(M, M.T, rtol=1e-12, atol=0.0):
        raise ValueError("`mass_matrix` must be symmetric")
    try:
        np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        raise ValueError("`mass_matrix` must be positive definite, got eigenvalues "
                         f"{np.linalg.eigvalsh(M)}") from None
    return M


def _jacobians(normal, tangent, nq: int):
    n = validate.finite_array(normal, "normal").reshape(-1)
    if n.size != nq or not np.any(n):
        raise ValueError(f"`normal` must be a non-zero row of {nq} entries (d(gap rate)/dv), "
                         f"got {n.size} entries")
    if tangent is None:
        return n, np.zeros((0, nq))
    D = validate.finite_array(tangent, "tangent")
    D = D.reshape(1, -1) if D.ndim == 1 else D
    if D.ndim != 2 or D.shape[1] != nq or D.shape[0] > 2:
        raise ValueError(f"`tangent` must have shape (k, {nq}) with k = 1 or 2, got {D.shape}")
    return n, D


def _friction(mu) -> float:
    try:
        value = float(mu)
    except (TypeError, ValueError):
        value = math.nan
    if isinstance(mu, (bool, np.bool_, str, bytes)) or not value >= 0:
        raise ValueError(f"`mu` (coefficient of friction) must be a number >= 0 (inf: always "
                         f"sticking), got {mu!r}")
    return value


def impact(mass_matrix, normal, v, *, tangent=None, e=0.0, mu=math.inf,
           names=None) -> ImpactResult:
    """The rates after an impact at one contact (seed Sec. 3.5, Eqs. 3.50-3.53): Newton's
    restitution with Coulomb friction, sticking or sliding as the friction cone decides.

    Parameters
    ----------
    mass_matrix : array_like, shape (n_q, n_q)
        ``M(q)`` at the contact configuration (symmetric positive definite).
    normal : array_like, shape (n_q,)
        Normal Jacobian ``n``: the normal relative velocity of the contact points (second
        body minus first, along the normal pointing from the first to the second; for a
        fixed obstacle the gap's rate) is ``n . v``. The normal impulse acts as ``n P_n``.
    v : array_like, shape (n_q,)
        Rates before the impact ``v-``.
    tangent : array_like, shape (k, n_q) or (n_q,), optional
        Tangent Jacobian ``D``: the slip velocity is ``D v`` (``k = 1`` or 2). None: no
        friction.
    e : float, optional
        Coefficient of restitution, ``0 <= e <= 1`` (Eq. 3.53).
    mu : float, optional
        Coefficient of friction ``>= 0`` (default ``inf``: the contact always sticks).
    names : sequence of str, optional
        Names of the rates, for ``result[name]``.

    Returns
    -------
    ImpactResult
        ``regime`` ``'separating'`` (no impulse) when ``n . v- >= 0``.

    Raises
    ------
    ValueError
        Naming ``mass_matrix`` (not square, symmetric, positive definite), ``normal``,
        ``tangent``, ``v`` (wrong sizes, not finite; ``[normal; tangent]`` not of full row
        rank), ``e`` (outside [0, 1]), ``mu``
        (negative) or ``names``.

    Examples
    --------
    A 2 kg ball at 3 m/s hits one of 1 kg at rest, e = 0.5 (Example 1): the first keeps
    ``3 - 1 (1.5) 3 / 3 = 1.5`` m/s, the second takes ``2 (1.5) 3 / 3 = 3`` m/s:

    >>> from appdyn.dynamics.mechanisms import impact
    >>> res = impact([[2.0, 0.0], [0.0, 1.0]], [-1.0, 1.0], [3.0, 0.0], e=0.5)
    >>> res.regime, res.v.tolist(), res.normal_impulse, res.energy_loss
    ('frictionless', [1.5, 3.0], 3.0, 2.25)
    """
    v = validate.finite_array(v, "v")
    if v.ndim > 1:
        raise ValueError(f"`v` must be a vector of rates (n_q,), got shape {v.shape}")
    v = v.reshape(-1)
    M = _matrix(mass_matrix, v.size)
    n, D = _jacobians(normal, tangent, v.size)
    e = validate.finite_scalar(e, "e")
    if not 0.0 <= e <= 1.0:
        raise ValueError(f"`e` (coefficient of restitution) must lie in [0, 1], got {e!r}")
    mu = _friction(mu)
    names = () if names is None else tuple(names)
    if names and len(names) != v.size:
        raise ValueError(f"`names` must name the {v.size} rates, got {len(names)}")
    un = float(n @ v)
    T = 0.5 * float(v @ M @ v)
    k = D.shape[0]
    if un >= 0.0:
        return ImpactResult(v.copy(), v.copy(), np.zeros(v.size), 0.0, np.zeros(k), SEPARATING,
                            (un, un), D @ v, 0.0, True, "the contact points separate: no "
                            "impact", names)
    J = np.vstack([n, D])
    if np.linalg.matrix_rank(J) < J.shape[0]:
        raise ValueError(f"`normal` and `tangent` must be independent rows ([n; D] of full row "
                         f"rank {J.shape[0]}), got rank {np.linalg.matrix_rank(J)}")
    MinvJT = np.linalg.solve(M, J.T)
    W = J @ MinvJT
    ok, message = True, ""
    if k == 0 or mu == 0.0:
        regime, P = FRICTIONLESS, np.r_[-(1 + e) * un / W[0, 0], np.zeros(k)]
        message = "frictionless contact"
    else:
        target = -np.r_[(1 + e) * un, D @ v]
        P = np.linalg.solve(W, target)
        pt = float(np.linalg.norm(P[1:]))
        if pt <= mu * P[0] * (1 + _CONE_SLACK) and P[0] >= 0:
            regime, message = STICKING, f"sticking: |P_t| / P_n = {pt / P[0]:.6g} <= mu"
        else:
            d = P[1:] / pt if pt > 0 else np.zeros(k)
            den = W[0, 0] + mu * float(W[0, 1:] @ d)
            regime = SLIDING
            if not math.isfinite(mu):
                ok, P = False, np.zeros(k + 1)
                message = ("sticking would need a pulling normal impulse and the friction is "
                           "unbounded (mu = inf): no impulse on the friction cone stops the "
                           "approach (the contact jams); give a finite mu")
            elif den > 0:
                need = f" (sticking would need mu >= {pt / P[0]:.6g})" if P[0] > 0 else ""
                pn = -(1 + e) * un / den
                P = np.r_[pn, mu * pn * d]
                message = "sliding on the friction cone" + need
            else:
                ok, P = False, np.zeros(k + 1)
                message = ("no impulse on the friction cone stops the approach (the contact "
                           "jams: W_nn + mu W_nt d <= 0); use a smaller mu or model the contact "
                           "compliance")
    impulse = J.T @ P
    v_plus = v + MinvJT @ P
    loss = T - 0.5 * float(v_plus @ M @ v_plus)
    if loss < -_GAIN_TOL * T:
        message += (f"; kinetic energy gained ({-loss:.6g} J): Newton's restitution with "
                    "friction (the seed's law) is not energy-consistent when the slip couples "
                    "to the normal (Kane's paradox); frictionless or e = 0 contact never gains")
    return ImpactResult(v_plus, v.copy(), impulse, float(P[0]), P[1:].copy(), regime,
                        (un, float(n @ v_plus)), D @ v_plus, loss, ok, message, names)


def contact_jump(mass_matrix, normal, *, tangent=None, e=0.0, mu=math.inf, nq: int,
                 names=None):
    """The jump map of an impact event of `simulate` for a mechanism with the state
    ``x = [q (nq), v (nq), ...]``: at the contact, ``v`` jumps as `impact` says.

    Parameters
    ----------
    mass_matrix, normal : callable
        ``M(q, p) -> (nq, nq)`` and ``n(q, p) -> (nq,)`` (numbers; a CasADi Function of
        ``(q, p)`` is called the same way).
    tangent : callable, optional
        ``D(q, p) -> (k, nq)``.
    e, mu : float
        As for `impact`.
    nq : int
        Number of coordinates.
    names : sequence of str, optional
        Names of the ``nq`` rates, for ``info[name]`` (e.g. ``model.states[nq:2 * nq]``).

    Returns
    -------
    callable
        ``jump(t, x, u, p) -> (x_plus, ImpactResult)``, for `dynamics.integrate.Impact`.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.mechanisms import contact_jump
    >>> jump = contact_jump(lambda q, p: np.eye(1), lambda q, p: [1.0], e=0.8, nq=1)
    >>> x_plus, res = jump(0.0, np.array([0.0, -5.0]), np.zeros(0), np.zeros(0))
    >>> x_plus.tolist(), res.normal_impulse
    ([0.0, 4.0], 9.0)
    """
    nq = validate.integer(nq, "nq", minimum=1)
    names = None if names is None else tuple(names)
    if names is not None and len(names) != nq:
        raise ValueError(f"`names` must name the {nq} rates, got {len(names)}")
    for name, fun in (("mass_matrix", mass_matrix), ("normal", normal), ("tangent", tangent)):
        if (fun is not None or name != "tangent") and not callable(fun):
            raise TypeError(f"`{name}` must be a callable of (q, p), got {type(fun).__name__}")

    def numbers(fun, q, p):
        return np.asarray(fun(q, p), dtype=float)

    def jump(t, x, u, p):
        x = np.asarray(x, dtype=float)
        q, v = x[:nq], x[nq:2 * nq]
        res = impact(numbers(mass_matrix, q, p), numbers(normal, q, p), v,
                     tangent=None if tangent is None else numbers(tangent, q, p), e=e, mu=mu,
                     names=names)
        x_plus = x.copy()
        x_plus[nq:2 * nq] = res.v
        return x_plus, res

    return jump


def _with(res: ImpactResult, names, **derived) -> ImpactResult:
    values = dict(res.__dict__, names=tuple(names), derived=MappingProxyType(derived))
    return ImpactResult(**values)


# ------------------------------------------------------------------------- the examples
def central_collision(m1, m2, u1, u2, *, e=1.0) -> ImpactResult:
    """Example 1: the central collision of two spheres, ``m1`` at ``u1`` behind ``m2`` at
    ``u2`` on one line (``u1 > u2``: they approach).

    Closed forms: ``v1 = u1 - m2 (1 + e) (u1 - u2) / (m1 + m2)``,
    ``v2 = u2 + m1 (1 + e) (u1 - u2) / (m1 + m2)``, the energy lost
    ``1/2 m1 m2 / (m1 + m2) (1 - e^2) (u1 - u2)^2``; ``e = 0`` (plastic): one common velocity.

    Parameters
    ----------
    m1, m2 : float [kg]
    u1, u2 : float [m/s]
    e : float, optional

    Returns
    -------
    ImpactResult
        Rates ``'v1'``, ``'v2'``.

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import central_collision
    >>> res = central_collision(1.0, 3.0, 2.0, 0.0, e=0.0)      # plastic: (1 * 2) / 4
    >>> res["v1"], res["v2"]
    (0.5, 0.5)
    """
    m1, m2 = validate.positive(m1, "m1"), validate.positive(m2, "m2")
    res = impact(np.diag([m1, m2]), [-1.0, 1.0], [validate.finite_scalar(u1, "u1"),
                                                  validate.finite_scalar(u2, "u2")], e=e)
    return _with(res, ("v1", "v2"))


def ballistic_pendulum(m1, m2, length, v1, *, e=0.0) -> ImpactResult:
    """Example 2: a bullet ``m1`` at ``v1`` hits the bob ``m2`` of a pendulum of length
    ``length`` hanging at rest (Eqs. 3.54-3.57).

    Coordinates: the bullet's ``x1`` and the pendulum's angle ``theta`` (the bob moves at
    ``l theta'``); ``M = diag(m1, m2 l^2)``. Closed forms:
    ``v1' = (m1 - e m2) v1 / (m1 + m2)``, ``theta' = (1 + e) m1 v1 / ((m1 + m2) l)``.

    Parameters
    ----------
    m1, m2 : float [kg]
    length : float [m]
    v1 : float [m/s]
    e : float, optional

    Returns
    -------
    ImpactResult
        Rates ``'x1_dot'``, ``'theta_dot'``.

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import ballistic_pendulum
    >>> res = ballistic_pendulum(0.01, 0.99, 2.0, 300.0)        # plastic: 3 m/s, 1.5 rad/s
    >>> round(res["x1_dot"], 12), round(res["theta_dot"], 12)
    (3.0, 1.5)
    """
    m1, m2 = validate.positive(m1, "m1"), validate.positive(m2, "m2")
    l = validate.positive(length, "length")
    res = impact(np.diag([m1, m2 * l * l]), [-1.0, l], [validate.finite_scalar(v1, "v1"), 0.0],
                 e=e)
    return _with(res, ("x1_dot", "theta_dot"))


def dumbbell_impact(mass, length, v0, *, e=0.0, mu=math.inf) -> ImpactResult:
    """Example 3: a particle ``m`` moving along ``x`` at ``v0`` hits one end of a dumbbell
    (two particles ``m`` joined by a massless rod of length ``l``, at rest along the
    diagonal at 45 deg, the struck end the lower-left one: ``r = -(l/2)(1, 1)/sqrt 2`` from
    the dumbbell's centre); the normal is ``x``.

    Coordinates ``(xp, yp, x, y, phi)``: the particle, the dumbbell's centre and its angle;
    ``M = diag(m, m, 2m, 2m, m l^2 / 2)``; the struck end moves at
    ``(x' + phi' l/(2 sqrt 2), y' - phi' l/(2 sqrt 2))`` (Eqs. 3.58-3.61, with 3.61
    corrected). Closed forms: sliding (``mu < 1/7``)::

        vx' = (3 - mu - 4e) v0 / (7 - mu),    vy' = -4 mu (1 + e) v0 / (7 - mu)
        x' = 2 (1 + e) v0 / (7 - mu),  y' = 2 mu (1 + e) v0 / (7 - mu)
        phi' = 2 sqrt 2 (1 - mu) (1 + e) v0 / ((7 - mu) l)

    normal rebound (sticking, ``mu >= 1/7``): ``vx' = (5 - 7e) v0 / 12``,
    ``vy' = -(1 + e) v0 / 12``, ``x' = 7 (1 + e) v0 / 24``, ``y' = (1 + e) v0 / 24``,
    ``phi' = (1 + e) v0 / (2 sqrt 2 l)``.

    Parameters
    ----------
    mass : float [kg]
        ``m`` of each of the three particles.
    length : float [m]
    v0 : float [m/s]
        ``> 0``.
    e, mu : float, optional

    Returns
    -------
    ImpactResult
        Rates ``'vx'``, ``'vy'``, ``'x_dot'``, ``'y_dot'``, ``'phi_dot'``.

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import dumbbell_impact
    >>> res = dumbbell_impact(1.0, 1.0, 12.0, e=1.0, mu=1.0)
    >>> res.regime, round(res["vx"], 12), round(res["vy"], 12)
    ('sticking', -2.0, -2.0)
    """
    m, l = validate.positive(mass, "mass"), validate.positive(length, "length")
    c = l / (2 * math.sqrt(2))
    M = np.diag([m, m, 2 * m, 2 * m, m * l * l / 2])
    res = impact(M, [-1.0, 0.0, 1.0, 0.0, c], [validate.finite_scalar(v0, "v0"), 0, 0, 0, 0],
                 tangent=[[0.0, -1.0, 0.0, 1.0, -c]], e=e, mu=mu)
    return _with(res, ("vx", "vy", "x_dot", "y_dot", "phi_dot"))


def carriage_impact(m1, m2, alpha, x1_dot, *, e=0.0, stiffness=1.0) -> ImpactResult:
    """Example 4: a sphere ``m1`` moving horizontally at ``x1_dot`` hits the smooth face of
    a carriage ``m2`` on a rail, backed by a spring ``stiffness`` (Eqs. 3.63-3.75).

    Coordinates ``(x1, y1, x2)`` (the carriage only moves along ``x``); the face's normal
    from the sphere to the carriage is ``(sin a, -cos a)``, so ``n = (-sin a, cos a, sin a)``
    and ``M = diag(m1, m1, m2)``. Closed forms, with ``P = (1 + e) m1 m2 x1 sin a / (m2 +
    m1 sin^2 a)``: ``x2' = P sin a / m2``, ``x1' = x1 - P sin a / m1``,
    ``y1' = P cos a / m1``; the rebound angle ``tan(theta) = y1'/x1'`` (Eq. 3.74), speed
    ``v' = |(x1', y1')|`` (3.75) and the carriage's travel ``delta = sqrt(m2/k) x2'``.

    Parameters
    ----------
    m1, m2 : float [kg]
    alpha : float [rad]
        Inclination of the face.
    x1_dot : float [m/s]
    e : float, optional
    stiffness : float [N/m], optional
        ``k > 0``.

    Returns
    -------
    ImpactResult
        Rates ``'x1_dot'``, ``'y1_dot'``, ``'x2_dot'``; derived ``'rebound_speed'`` [m/s],
        ``'rebound_angle'`` [rad] (``atan2(y1', x1')``) and ``'travel'`` [m].

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.mechanisms import carriage_impact
    >>> res = carriage_impact(1.0, 1.0, np.pi / 2, 2.0, e=1.0, stiffness=4.0)  # a wall:
    >>> round(res["x1_dot"], 12), round(res["x2_dot"], 12), round(res["travel"], 12)
    (0.0, 2.0, 1.0)
    """
    m1, m2 = validate.positive(m1, "m1"), validate.positive(m2, "m2")
    a = validate.finite_scalar(alpha, "alpha")
    k = validate.positive(stiffness, "stiffness")
    s, c = math.sin(a), math.cos(a)
    res = impact(np.diag([m1, m1, m2]), [-s, c, s], [validate.finite_scalar(x1_dot, "x1_dot"),
                                                      0.0, 0.0], e=e)
    x1, y1, x2 = res.v
    return _with(res, ("x1_dot", "y1_dot", "x2_dot"), rebound_speed=math.hypot(x1, y1),
                 rebound_angle=math.atan2(y1, x1), travel=math.sqrt(m2 / k) * x2)


def falling_bar_impact(mass, length, u0, v0, *, theta=math.pi / 4, e=0.0,
                       mu=math.inf) -> ImpactResult:
    """Example 5: a uniform bar (``m``, ``l``) falling without rotation at ``(u0, -v0)``
    hits a horizontal floor with its lower end, the bar at ``theta`` to the floor
    (Eqs. 3.76-3.106).

    Coordinates ``(x, y, phi)`` (centre, angle counter-clockwise); the lower end is at
    ``(l/2)(cos th, -sin th)`` from the centre and moves at ``(x' + phi' (l/2) sin th,
    y' + phi' (l/2) cos th)``; ``M = diag(m, m, m l^2 / 12)``. Closed forms at 45 deg:
    normal rebound (sticking, ``mu > (5 u0 + 3 (1 + e) v0) / (3 u0 + 5 (1 + e) v0)``)::

        y' = ((5e - 3) v0 + 3 u0) / 8,    x' = 3 (u0 - (1 + e) v0) / 8
        omega = 3 ((1 + e) v0 - u0) / (2 sqrt 2 l)
        R = m (5 u0 + 3 (1 + e) v0) / 8,  F = m (3 u0 + 5 (1 + e) v0) / 8

    sliding: ``y' = v0 (2e - 3 (1 - mu)) / (2 + 3 (1 - mu))``,
    ``x' = u0 - 2 mu (1 + e) v0 / (2 + 3 (1 - mu))``,
    ``omega = 12 (1 + e) (1 - mu) v0 / (sqrt 2 (2 + 3 (1 - mu)) l)`` (Eqs. 3.105-3.106).
    (Eqs. 3.93, 3.94 and 3.96 as printed do not solve 3.76-3.81: see the module notes.)

    Parameters
    ----------
    mass : float [kg]
    length : float [m]
    u0, v0 : float [m/s]
        Horizontal velocity and the downward speed (``v0 > 0``).
    theta : float [rad], optional
        The bar's angle to the floor, in ``(0, pi/2]``.
    e, mu : float, optional

    Returns
    -------
    ImpactResult
        Rates ``'x_dot'``, ``'y_dot'``, ``'omega'``; the normal impulse is the seed's ``F``,
        the tangent impulse ``-R`` (the friction acts along ``-x`` for ``R > 0``).

    Examples
    --------
    >>> from appdyn.dynamics.mechanisms import falling_bar_impact
    >>> res = falling_bar_impact(1.0, 1.0, 0.0, 8.0, e=1.0, mu=10.0)
    >>> res.regime, round(res["y_dot"], 12), round(res.normal_impulse, 12)
    ('sticking', 2.0, 10.0)
    """
    m, l = validate.positive(mass, "mass"), validate.positive(length, "length")
    th = validate.finite_scalar(theta, "theta")
    if not 0.0 < th <= math.pi / 2:
        raise ValueError(f"`theta` must lie in (0, pi/2], got {theta!r}")
    h = l / 2
    res = impact(np.diag([m, m, m * l * l / 12]), [0.0, 1.0, h * math.cos(th)],
                 [validate.finite_scalar(u0, "u0"), -validate.finite_scalar(v0, "v0"), 0.0],
                 tangent=[[1.0, 0.0, h * math.sin(th)]], e=e, mu=mu)
    return _with(res, ("x_dot", "y_dot", "omega"))
