"""Steering-law simulations of a CMG cluster: gimbal angles driven by a commanded body torque.

`steering_model` builds the gimbal kinematics ``delta' = law(C(delta), torque)`` of a steering
law of `dynamics.momentum.steering` as a `Model` (CasADi SX, so `simulate` compiles it); `steer`
integrates it (``rk8``) and reports along the way the momentum, the singularity measure, the
gimbal rates and the delivered body torque ``-C delta'`` against the commanded one
(`SteeringResult`).

Every run also integrates the cluster momentum from the gimbal rates,
``H_int' = C(delta) delta'`` (``momentum_states=True``), and compares it with
``H(delta(t))``: the two agree to integrator accuracy on a smooth solution, and differ by
order one when a step jumps across a singular state where the rates blow up (a
pseudo-inverse driven into a singularity), even between output points. Such a run is
reported as ``success=False``, never as a trusted trajectory.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from typing import Mapping

import casadi as ca
import numpy as np

from .. import cache, validate
from ..figures import finish_figure, panel_axes
from ..integrate import simulate
from ..model import Model
from ..serialize import text_table, to_json
from .cluster import ClusterGeometry, cluster_jacobian, cluster_momentum, singularity_measure
from .steering import gsr_inverse_steering, pseudo_inverse_steering, sr_inverse_steering
from ..results import Result

__all__ = ["LAWS", "LAW_OPTIONS", "MOMENTUM_TOL", "TORQUE_TOL", "OK", "RATE_LIMIT",
           "MOMENTUM_BALANCE", "TORQUE_ERROR", "FAILED", "steering_model", "steer",
           "SteeringResult"]

#: Steering laws: Moore-Penrose, singularity-robust, generalized SR (dither; adds a clock).
LAWS = ("pinv", "sr", "gsr")
#: Keyword options of each law (those of the functions in `dynamics.momentum.steering`).
LAW_OPTIONS = {"pinv": (), "sr": ("lam0", "mu"), "gsr": ("lam0", "mu", "eps0", "omega", "phase")}
#: Largest ``|H(delta) - H_int|``, relative to ``sum(h)``, of a trusted run.
MOMENTUM_TOL = 1e-8
#: Default largest ``|delivered - commanded|`` torque of a successful run, relative to the
#: largest commanded ``|torque|`` (`steer`'s ``torque_tol``).
TORQUE_TOL = 0.01
#: `SteeringResult.status`: done; gimbal rates above ``rate_limit``; momentum balance broken
#: (a step jumped across a singular state); the commanded torque not delivered (a
#: singularity-robust law at a singular state, or a saturated cluster); integration failed
#: (non-finite state or rate).
OK, RATE_LIMIT, MOMENTUM_BALANCE, TORQUE_ERROR, FAILED = 0, 1, 2, 3, -1


def _geometry(geometry) -> ClusterGeometry:
    if not isinstance(geometry, ClusterGeometry):
        raise validate.ArgumentTypeError(
            f"`geometry` must be a ClusterGeometry, got {type(geometry).__name__}")
    return geometry


def _law_options(law, options: Mapping) -> tuple:
    """Checked ``(law, ((name, value), ...))``, values as floats or tuples (hashable)."""
    law = validate.one_of(law, "law", LAWS)
    unknown = sorted(set(options) - set(LAW_OPTIONS[law]))
    if unknown:
        allowed = ", ".join(LAW_OPTIONS[law]) or "none"
        raise validate.ArgumentTypeError(
            f"`law_options` {unknown} do not apply to law {law!r} (its options: {allowed})")
    items = []
    for name in sorted(options):
        if name == "phase":
            items.append((name, tuple(validate.finite_array(options[name], name, (3,)).tolist())))
        else:
            items.append((name, validate.finite_scalar(options[name], name)))
    return law, tuple(items)


@cache.memoize
def _steering_model(gimbal_key, spin_key, h_key, law, options, momentum_states) -> Model:
    n = len(h_key)
    geo = ClusterGeometry(np.reshape(gimbal_key, (3, n)), np.reshape(spin_key, (3, n)),
                          np.array(h_key))
    clock = law == "gsr"
    x = ca.SX.sym("x", n + clock + 3 * momentum_states)
    u, p = ca.SX.sym("u", 3), ca.SX.sym("p", 0)
    C = cluster_jacobian(geo, x[:n])
    kwargs = dict(options)
    if law == "pinv":
        rate = pseudo_inverse_steering(C, u)
    elif law == "sr":
        rate = sr_inverse_steering(C, u, **kwargs)
    else:
        rate = gsr_inverse_steering(C, u, x[n], **kwargs)
    parts = [rate] + [ca.DM(1.0)] * clock + [ca.mtimes(C, rate)] * momentum_states
    f = ca.Function(f"cmg_steering_{law}", [x, u, p], [ca.vertcat(*parts)], ["x", "u", "p"],
                    ["xdot"])
    angles = tuple(f"d{i + 1}" for i in range(n))
    extra = (("t",) if clock else ()) + (("H1", "H2", "H3") if momentum_states else ())
    units = {**dict.fromkeys(angles, "rad"), **dict.fromkeys(("T1", "T2", "T3"), "N m"),
             **{k: "s" if k == "t" else "N m s" for k in extra}}
    return Model(f, angles + extra, ("T1", "T2", "T3"), units=units,
                 name=f"cmg_steering_{law}")


def steering_model(geometry: ClusterGeometry, law="sr", *, momentum_states: bool = False,
                   **law_options) -> Model:
    """Gimbal kinematics under a steering law, ``delta' = law(C(delta), torque)``, as a `Model`.

    States ``d1..dn`` [rad], then ``t`` [s] (``tdot = 1``) when the law needs time (``gsr``,
    its dither), then ``H1..H3`` [N m s] with ``H' = C delta'`` when ``momentum_states``.
    Controls ``T1..T3``: the commanded body torque [N m] (the law solves ``C delta' =
    -torque``). The right-hand side is CasADi SX; models are cached by their arguments.

    Parameters
    ----------
    geometry : ClusterGeometry
    law : {'pinv', 'sr', 'gsr'}
        `pseudo_inverse_steering`, `sr_inverse_steering` or `gsr_inverse_steering`.
    momentum_states : bool, optional
        Also integrate the cluster momentum from the gimbal rates (the check `steer` makes).
    **law_options
        The law's options (`LAW_OPTIONS`): ``lam0``, ``mu`` (sr, gsr); ``eps0``, ``omega``,
        ``phase`` (gsr).

    Returns
    -------
    Model

    Raises
    ------
    TypeError
        If ``geometry`` is not a `ClusterGeometry` or an option does not apply to ``law``.
    ValueError
        Naming ``law`` (unknown) or the option (non-finite, negative gain).

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.momentum import pyramid, steering_model
    >>> model = steering_model(pyramid(np.deg2rad(54.74)), "gsr", eps0=0.02)
    >>> model.states, model.controls
    (('d1', 'd2', 'd3', 'd4', 't'), ('T1', 'T2', 'T3'))
    >>> np.round(model.rhs(np.zeros(5), [0.1, 0.0, 0.0]), 4) + 0.0  # -C^+ torque, clock
    array([ 0.0866,  0.    , -0.0866,  0.    ,  1.    ])
    """
    geo = _geometry(geometry)
    law, options = _law_options(law, law_options)
    if not isinstance(momentum_states, (bool, np.bool_)):
        raise validate.ArgumentTypeError(
            f"`momentum_states` must be True or False, got {momentum_states!r}")
    return _steering_model(tuple(geo.gimbal_axes.ravel()), tuple(geo.spin_axes0.ravel()),
                           tuple(geo.h), law, options, bool(momentum_states))


def _torque_samples(torque, t: np.ndarray) -> np.ndarray:
    """The commanded torque on the grid ``t``, shape (3, m), checked (naming ``torque``)."""
    if callable(torque):
        out = []
        for tk in t:
            value = validate.finite_array(torque(float(tk)), "torque")
            if value.shape != (3,):
                raise ValueError(f"`torque` must return shape (3,) when called with a time, "
                                 f"got {value.shape} at t = {tk}")
            out.append(value)
        return np.array(out).T
    a = validate.finite_array(torque, "torque")
    if a.shape == (3,):
        return np.repeat(a[:, None], t.size, axis=1)
    if a.shape == (3, t.size):
        return a
    raise ValueError(f"`torque` must be a constant (3,), samples (3, {t.size}) on `t`, or a "
                     f"callable of t returning (3,); got shape {a.shape}")


def _columns(fun, delta, ok, rows):
    """``fun(delta[:, ok])`` in the columns ``ok``, NaN elsewhere; shape (rows..., m)."""
    out = np.full(rows + (delta.shape[1],), np.nan)
    if np.any(ok):
        out[..., ok] = fun(delta[:, ok])
    return out


def _cell(value, width: int, decimals: int) -> str:
    """``value`` right-aligned in ``width`` with ``decimals``; exponent form when too wide."""
    text = f"{value:.{decimals}f}"
    return f"{text if len(text) < width else f'{value:.2e}':>{width}}"


def _nanmax(a) -> float:
    a = np.asarray(a, dtype=float)
    return float(np.nanmax(a)) if np.any(np.isfinite(a)) else float("nan")


def steer(geometry: ClusterGeometry, torque, t, *, law="sr", delta0=None, steps: int = 20,
          rate_limit=None, torque_tol: float = TORQUE_TOL, **law_options) -> "SteeringResult":
    """Simulate the gimbal angles under a commanded body torque and a steering law.

    Parameters
    ----------
    geometry : ClusterGeometry
    torque : array_like (3,) or (3, m), or callable
        Commanded body torque [N m]: a constant, samples on ``t`` (linear between them), or
        ``torque(t) -> (3,)``.
    t : array_like, shape (m,) [s]
        Output times, strictly increasing, ``m >= 2``.
    law : {'pinv', 'sr', 'gsr'}, optional
    delta0 : array_like, shape (n,) [rad], optional
        Initial gimbal angles (zeros).
    steps : int, optional
        ``rk8`` steps per output interval.
    rate_limit : float [rad/s], optional
        Largest allowed ``|delta_i'|`` (checked at the output times); a run beyond it is
        ``success=False`` (status `RATE_LIMIT`).
    torque_tol : float, optional
        Largest ``|delivered - commanded|`` at the output times, relative to the largest
        commanded ``|torque|`` (default 1 %); a run beyond it delivered something else than
        was asked and is ``success=False`` (status `TORQUE_ERROR`): a singularity-robust law
        trading torque for bounded rates at a singular state, a gimbal lock, a saturated
        cluster. ``numpy.inf`` accepts any torque error (the error is still reported).
    **law_options
        Options of the law (`steering_model`).

    Returns
    -------
    SteeringResult

    Raises
    ------
    TypeError, ValueError
        Naming the argument: ``geometry``, ``law`` or an option, ``torque`` (shape, values),
        ``t``, ``delta0``, ``steps``, ``rate_limit``, ``torque_tol``.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.momentum import pyramid, steer
    >>> geo, t = pyramid(np.deg2rad(54.74)), np.linspace(0, 5, 51)
    >>> res = steer(geo, [0.0, 0.0, -0.2], t, law="pinv")
    >>> res.success, np.round(res.H[:, -1], 9) + 0.0  # H(t) = H(0) - torque t
    (True, array([0., 0., 1.]))
    >>> sr = steer(geo, [0.0, 0.0, -0.2], t)  # SR: a small torque error, lam > 0
    >>> bool(0 < sr.max_torque_error < 1e-7)
    True
    """
    start = time.perf_counter()
    geo = _geometry(geometry)
    t = validate.finite_array(t, "t")
    if t.ndim != 1 or t.size < 2:
        raise ValueError(f"`t` must be a 1-D grid of at least 2 times, got shape {t.shape}")
    commanded = _torque_samples(torque, t)
    delta0 = (np.zeros(geo.n) if delta0 is None
              else validate.finite_array(delta0, "delta0", (geo.n,)))
    if rate_limit is not None:
        rate_limit = validate.positive(rate_limit, "rate_limit")
    torque_tol = _torque_tol(torque_tol)
    law, options = _law_options(law, law_options)
    model = steering_model(geo, law, momentum_states=True, **dict(options))
    clock = [float(t[0])] if law == "gsr" else []
    x0 = np.concatenate([delta0, clock, cluster_momentum(geo, delta0)])
    u = torque if callable(torque) else commanded
    sim = simulate(model, x0, t, u=u, method="rk8", steps=steps)
    n = geo.n
    delta = sim.x[:n]
    rates = sim.xdot[:n]
    ok = np.all(np.isfinite(delta), axis=0) & np.all(np.isfinite(rates), axis=0)
    H = _columns(lambda d: cluster_momentum(geo, d), delta, ok, (3,))
    measure = _columns(lambda d: singularity_measure(geo, d), delta, ok, ())
    C = _columns(lambda d: cluster_jacobian(geo, d), delta, ok, (3, n))
    delivered = -np.einsum("ikm,km->im", C, rates)
    balance = np.linalg.norm(H - sim.x[-3:], axis=0)
    res = SteeringResult(t=t, delta=delta, H=H, measure=measure, rates=rates,
                         commanded=commanded, delivered=delivered,
                         torque_error=np.linalg.norm(delivered - commanded, axis=0),
                         momentum_error=balance, success=True, status=OK, message="",
                         law=law, law_options=dict(options), geometry=geo,
                         rate_limit=rate_limit, steps=sim.substeps, simulation=sim)
    scale = float(np.max(np.linalg.norm(commanded, axis=0)))
    status, message = _verdict(res, sim, ok, MOMENTUM_TOL * float(np.sum(geo.h)),
                               torque_tol * scale)
    return replace(res, success=status == OK, status=status, message=message,
                   wall_time=time.perf_counter() - start)


def _torque_tol(value) -> float:
    """``torque_tol``: a number >= 0 (``inf`` allowed: any torque error accepted)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.number)):
        raise validate.ArgumentTypeError(
            f"`torque_tol` must be a number >= 0 (a fraction of the largest commanded torque, "
            f"inf for any), got {type(value).__name__}")
    value = float(value)
    if not value >= 0:
        raise ValueError(f"`torque_tol` must be >= 0 (inf for any torque error), got {value}")
    return value


def _verdict(res, sim, ok, tol, torque_tol) -> tuple:
    """``(status, message)`` of a run: the first failed check, in the order of the statuses."""
    if not sim.success or not np.all(ok):
        bad = res.t[~ok][0] if not np.all(ok) else res.t[-1]
        return FAILED, (f"the run went non-finite at t = {bad:g} s (unbounded gimbal rates?): "
                        f"{sim.message}")
    if res.rate_limit is not None and res.max_rate > res.rate_limit:
        k = int(np.argmax(np.max(np.abs(res.rates), axis=0) > res.rate_limit))
        return RATE_LIMIT, (f"gimbal rate {res.max_rate:.4g} rad/s exceeds rate_limit "
                            f"{res.rate_limit:g} rad/s (first at t = {res.t[k]:g} s, singularity "
                            f"measure {res.measure[k]:.3g})")
    if res.max_momentum_error > tol:
        k = int(np.argmax(res.momentum_error > tol))
        return MOMENTUM_BALANCE, (
            f"momentum balance broken: |H(delta) - H(delta0) - int C delta' dt| = "
            f"{res.max_momentum_error:.3g} N m s > {tol:.1g} from t = {res.t[k]:g} s: the gimbal "
            f"rates blew up between output points (a step jumped across a singular state), or "
            f"`steps` is too coarse for them (more steps tell which)")
    if res.max_torque_error > torque_tol:
        bad = res.torque_error > torque_tol
        k = int(np.argmax(bad))
        spent = float(np.sum(np.diff(res.t)[bad[:-1]]))
        return TORQUE_ERROR, (
            f"commanded torque not delivered: |delivered - commanded| up to "
            f"{res.max_torque_error:.3g} N m > torque_tol {torque_tol:.3g} N m, from t = "
            f"{res.t[k]:g} s, for about {spent:.3g} s (singularity measure there "
            f"{res.measure[k]:.3g}; a singular state or a saturated cluster; torque_tol=inf "
            f"accepts it)")
    return OK, (f"{sim.message}; momentum balance {res.max_momentum_error:.2g} N m s")


@dataclass(frozen=True, eq=False, repr=False)
class SteeringResult(Result):
    """A steering-law run (`steer`); arrays on the output grid ``t`` (m points).

    Attributes
    ----------
    t : ndarray, shape (m,) [s]
    delta : ndarray, shape (n, m) [rad]
    H : ndarray, shape (3, m) [N m s]
        Cluster momentum ``H(delta)``.
    measure : ndarray, shape (m,) [(N m s)^3]
        Singularity measure ``sqrt(det(C C^T))``.
    rates : ndarray, shape (n, m) [rad/s]
        Gimbal rates of the law.
    commanded, delivered : ndarray, shape (3, m) [N m]
        Commanded body torque and the one delivered, ``-C delta'``.
    torque_error : ndarray, shape (m,) [N m]
        ``|delivered - commanded|``.
    momentum_error : ndarray, shape (m,) [N m s]
        ``|H(delta) - H(delta0) - int C delta' dt|`` (module docstring).
    success : bool
        Finite, within ``rate_limit`` and momentum balance within `MOMENTUM_TOL` ``sum(h)``.
    status : int
        `OK` (0), `RATE_LIMIT` (1), `MOMENTUM_BALANCE` (2) or `FAILED` (-1).
    message : str
    law : str
    law_options : dict
    geometry : ClusterGeometry
    rate_limit : float or None [rad/s]
    steps : int
        ``rk8`` steps per output interval.
    simulation : SimulationResult
        The raw run (states ``d1..dn``, [``t``], ``H1..H3``).
    wall_time : float [s]
    """

    t: np.ndarray
    delta: np.ndarray
    H: np.ndarray
    measure: np.ndarray
    rates: np.ndarray
    commanded: np.ndarray
    delivered: np.ndarray
    torque_error: np.ndarray
    momentum_error: np.ndarray
    success: bool
    status: int
    message: str
    law: str
    law_options: dict
    geometry: ClusterGeometry
    rate_limit: float | None = None
    steps: int = 0
    simulation: object = field(default=None, repr=False)
    wall_time: float = float("nan")

    _repr_fields = ('law', 't', 'delta', 'max_rate', 'max_torque_error')

    @property
    def rate_norm(self) -> np.ndarray:
        """``|delta'|`` [rad/s], shape (m,)."""
        return np.linalg.norm(self.rates, axis=0)

    @property
    def min_measure(self) -> float:
        """Smallest singularity measure along the run [(N m s)^3]."""
        return -_nanmax(-self.measure)

    @property
    def max_rate(self) -> float:
        """Largest ``|delta_i'|`` over units and output times [rad/s]."""
        return _nanmax(np.abs(self.rates))

    @property
    def max_torque_error(self) -> float:
        """Largest ``|delivered - commanded|`` [N m]."""
        return _nanmax(self.torque_error)

    @property
    def max_momentum_error(self) -> float:
        """Largest momentum-balance error [N m s] (NaN-free columns)."""
        return _nanmax(self.momentum_error)

    def _law_text(self) -> str:
        opts = ", ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}"
                         for k, v in self.law_options.items())
        return self.law + (f" ({opts})" if opts else "")

    def to_dict(self) -> dict:
        """Summary and trajectories (SI units, radians) as plain Python (`to_json`)."""
        return {"success": bool(self.success), "status": int(self.status),
                "message": self.message, "law": self.law, "law_options": self.law_options,
                "h": self.geometry.h, "gimbal_axes": self.geometry.gimbal_axes,
                "spin_axes0": self.geometry.spin_axes0, "rate_limit": self.rate_limit,
                "steps": self.steps, "wall_time": self.wall_time,
                "min_measure": self.min_measure, "max_rate": self.max_rate,
                "max_torque_error": self.max_torque_error,
                "max_momentum_error": self.max_momentum_error, "t": self.t,
                "delta": self.delta, "H": self.H, "measure": self.measure, "rates": self.rates,
                "commanded": self.commanded, "delivered": self.delivered,
                "torque_error": self.torque_error, "momentum_error": self.momentum_error}

    def __str__(self) -> str:
        n = self.geometry.n
        limit = "" if self.rate_limit is None else \
            f" (limit {np.degrees(self.rate_limit):.6g} deg/s)"
        rows = [("success", f"{self.success} (status {self.status})"),
                ("law", self._law_text()),
                ("run", f"{n} gimbals, t = {self.t[0]:g} .. {self.t[-1]:g} s, {self.t.size} "
                        f"points, rk8 {self.steps} step(s) per interval"),
                ("min measure", f"{self.min_measure:.4g} (N m s)^3"),
                ("max gimbal rate", f"{np.degrees(self.max_rate):.4g} deg/s{limit}"),
                ("max torque error", f"{self.max_torque_error:.4g} N m"),
                ("momentum balance", f"{self.max_momentum_error:.3g} N m s"),
                ("wall time", f"{self.wall_time:.3f} s"),
                ("message", self.message)]
        head = (f"  {'t [s]':>8}" + "".join(f"{f'd{i + 1} [deg]':>10}" for i in range(n))
                + f"{'|H| [N m s]':>13}{'measure':>10}{'|rate| [deg/s]':>16}{'|T err| [N m]':>15}")
        lines = [text_table("CMG steering", rows), head]
        shown = np.unique(np.linspace(0, self.t.size - 1, min(self.t.size, 11)).round())
        for k in shown.astype(int):
            angles = "".join(_cell(a, 10, 3) for a in np.degrees(self.delta[:, k]))
            lines.append(f"  {_cell(self.t[k], 8, 3)}{angles}"
                         f"{_cell(np.linalg.norm(self.H[:, k]), 13, 6)}"
                         f"{_cell(self.measure[k], 10, 4)}"
                         f"{_cell(np.degrees(self.rate_norm[k]), 16, 4)}"
                         f"{self.torque_error[k]:>15.3e}")
        return "\n".join(lines)

    def plot(self, ax=None):
        """Gimbal angles, singularity measure, gimbal rates and torque error against time.

        Parameters
        ----------
        ax : matplotlib.axes.Axes or matplotlib.figure.Figure, optional
            Draw the panels in this axes' slot (divided into the panels) or on this figure
            (cleared); by default on a new `matplotlib.figure.Figure` (no pyplot).

        Returns
        -------
        matplotlib.figure.Figure
        """
        fig, axes = panel_axes(ax, 2, 2, (11.0, 7.0))
        for i in range(self.geometry.n):
            axes[0, 0].plot(self.t, np.degrees(self.delta[i]), label=f"d{i + 1}")
            axes[1, 0].plot(self.t, np.degrees(self.rates[i]), label=f"d{i + 1}")
        axes[0, 1].plot(self.t, self.measure, color="k")
        axes[1, 1].plot(self.t, self.torque_error, color="tab:red", label="|delivered - commanded|")
        axes[1, 1].plot(self.t, np.linalg.norm(self.commanded, axis=0), color="tab:gray",
                        linestyle="--", label="|commanded|")
        for ax, label in zip(axes.flat, ("gimbal angle [deg]", "singularity measure [(N m s)^3]",
                                         "gimbal rate [deg/s]", "torque [N m]")):
            ax.set_ylabel(label)
            ax.grid(True, alpha=0.3)
        for ax in axes[1]:
            ax.set_xlabel("t [s]")
        axes[0, 0].legend(fontsize=8)
        axes[1, 1].legend(fontsize=8)
        fig.suptitle(f"CMG steering, {self._law_text()}"
                     + ("" if self.success else f" (failed: status {self.status})"))
        return finish_figure(fig)
