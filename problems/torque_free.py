"""Torque-free rigid body: simulate and check against the Jacobi-elliptic truth.

This is the toolkit's smallest end-to-end job: build the model, integrate it, and measure
the error against a closed form (Rheinfurth & Wilson, NASA RP-1262, Sec. 4.5 B) and the
drift of the conserved quantities.

Status of a `TorqueFreeReport` (``report.status``): `STATUS_VERIFIED` (0) the integrator
succeeded and the truth check passed; `STATUS_CHECK_FAILED` (1) the integrator succeeded but
the error exceeds what was asked; `STATUS_INTEGRATOR_FAILED` (-1) the integration failed.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import asdict, dataclass, field

import numpy as np

from appdyn.dynamics import rigid_body
from appdyn.dynamics.attitude import principal_axes
from appdyn.dynamics.rigid_body import check_inertia
from appdyn.dynamics import simulate
from appdyn.dynamics.truth import torque_free_omega
from appdyn.dynamics.figures import finish_figure, panel_grid
from appdyn.dynamics.results import Result

__all__ = ["TorqueFreeReport", "torque_free", "CHECK_FACTOR", "ROUNDOFF_FACTOR",
           "STATUS_VERIFIED", "STATUS_CHECK_FAILED", "STATUS_INTEGRATOR_FAILED"]

#: status: integrated and verified against the exact solution
STATUS_VERIFIED = 0
#: status: integrated, but the error exceeds what was asked (``success`` is False)
STATUS_CHECK_FAILED = 1
#: status: the integrator failed (``success`` is False)
STATUS_INTEGRATOR_FAILED = -1

#: the truth check allows ``CHECK_FACTOR`` times the requested ``atol + rtol |w_exact|``
#: (1: ``method='auto'`` promises the tolerance as a global error and says so only when met)
CHECK_FACTOR = 1.0
#: round-off floor of the truth check: ``ROUNDOFF_FACTOR eps |w0| (1 + |w0| t_final)`` [rad/s]
#: (double precision loses about ``eps`` of relative phase per radian turned; measured
#: errors of ``method='auto'`` at the tightest tolerances stay below half of it)
ROUNDOFF_FACTOR = 10.0


@dataclass(frozen=True, repr=False)
class TorqueFreeReport(Result):
    """Outcome of a torque-free run, compared with the exact solution.

    Attributes
    ----------
    inertia : list of list of float, shape (3, 3) [kg m^2]
        The inertia matrix.
    w0 : list of float, shape (3,) [rad/s]
        Initial body rates.
    t_final : float [s]
        Final time.
    method : str
        Integration method actually used.
    success : bool
        The integrator succeeded *and* the truth check passed (`verified`).
    message : str
        The integrator's message.
    max_rate_error : float [rad/s]
        Max over t and axes of ``|w - w_exact|``.
    max_rel_rate_error : float
        ``max_rate_error / |w0|``.
    energy_drift : float
        ``max |T(t) - T(0)| / T(0)``.
    momentum_drift : float
        ``max |H(t) - H(0)| / |H(0)|`` with ``H`` in inertial axes.
    quat_norm_drift : float
        ``max | |q| - 1 |``.
    wall_time : float [s]
        Time spent in `simulate`.
    n_steps : int
        Integration steps.
    integrator_success : bool
        What the integrator reported.
    verified : bool
        The truth check passed: at every output time and axis
        ``|w - w_exact| <= allowed_error`` (NaN or inf fails).
    allowed_error : float [rad/s]
        The check's bound, ``max(CHECK_FACTOR (atol + rtol |w_exact|), roundoff)`` at the
        worst point, or ``tol |w0|`` when ``tol`` was given.
    error_ratio : float
        ``max |w - w_exact| / bound`` over times and axes (<= 1 passes).
    check : str
        The rule applied, in words.
    rtol, atol : float
        The requested tolerances (fixed-step methods: the accuracy asked of the result; the
        integrator does not use them).
    tol : float or None
        Relative accuracy asked instead (``max_rel_rate_error <= tol``).
    worst_time : float [s]
        Output time of the largest ``error_ratio``.
    worst_component : int
        0-based index of the body rate with the largest ``error_ratio`` (was ``worst_axis``).
    status : int
        `STATUS_VERIFIED`, `STATUS_CHECK_FAILED` or `STATUS_INTEGRATOR_FAILED` (property).
    """

    inertia: list
    w0: list
    t_final: float
    method: str
    success: bool
    message: str
    max_rate_error: float
    max_rel_rate_error: float
    energy_drift: float
    momentum_drift: float
    quat_norm_drift: float
    wall_time: float
    n_steps: int
    integrator_success: bool = True
    verified: bool = True
    allowed_error: float = math.inf
    error_ratio: float = 0.0
    check: str = ""
    rtol: float = math.nan
    atol: float = math.nan
    tol: float | None = None
    worst_time: float = math.nan
    worst_component: int = 0
    _series: dict = field(default_factory=dict, repr=False, compare=False)

    _repr_fields = ('method', 'max_rate_error', 'energy_drift')

    @property
    def status(self) -> int:
        """`STATUS_VERIFIED`, `STATUS_CHECK_FAILED` or `STATUS_INTEGRATOR_FAILED`."""
        if not self.integrator_success:
            return STATUS_INTEGRATOR_FAILED
        return STATUS_VERIFIED if self.verified else STATUS_CHECK_FAILED

    @property
    def worst_axis(self) -> int:
        """Deprecated name of `worst_component` (an integer is a component, not an axis)."""
        warnings.warn("`TorqueFreeReport.worst_axis` is deprecated; use `worst_component`",
                      DeprecationWarning, stacklevel=2)
        return self.worst_component

    def to_dict(self) -> dict:
        """JSON-ready summary (no time series), with ``status``."""
        d = asdict(self)
        d.pop("_series")
        d["status"] = self.status
        return d

    @property
    def check_text(self) -> str:
        """``truth check passed: ...`` or ``truth check FAILED: ...`` with the numbers."""
        if self.verified:
            return (f"truth check passed: max |w - w_exact| = {self.max_rate_error:.3e} rad/s, "
                    f"{self.error_ratio:.2g} of the allowed error ({self.check})")
        return (f"truth check FAILED: max |w - w_exact| = {self.max_rate_error:.3e} rad/s; "
                f"at t = {self.worst_time:g} s the w{self.worst_component + 1} error is "
                f"{self.error_ratio:.3g} times the allowed {self.allowed_error:.3e} rad/s "
                f"({self.check})")

    def __str__(self) -> str:
        rows = [
            ("inertia diag [kg m^2]", ", ".join(f"{v:g}" for v in np.diag(self.inertia))),
            ("w0 [rad/s]", ", ".join(f"{v:g}" for v in self.w0)),
            ("t_final [s]", f"{self.t_final:g}"),
            ("method", self.method),
            ("success", f"{self.success} (integrator: {self.message})"),
            ("max |w - w_exact| [rad/s]", f"{self.max_rate_error:.3e}"),
            ("  relative to |w0|", f"{self.max_rel_rate_error:.3e}"),
            ("energy drift (rel)", f"{self.energy_drift:.3e}"),
            ("inertial momentum drift (rel)", f"{self.momentum_drift:.3e}"),
            ("quaternion norm drift", f"{self.quat_norm_drift:.3e}"),
            ("steps", f"{self.n_steps}"),
            ("wall time [ms]", f"{1e3 * self.wall_time:.3f}"),
        ]
        width = max(len(k) for k, _ in rows)
        lines = ["Torque-free rigid body vs Jacobi-elliptic solution"]
        lines += [f"  {k:<{width}}  {v}" for k, v in rows]
        lines.append(f"  {self.check_text}")
        return "\n".join(lines)

    def plot(self, ax=None):
        """Rates (simulated and exact), the polhode, invariant drift and error vs truth.

        Parameters
        ----------
        ax : matplotlib.axes.Axes or matplotlib.figure.Figure, optional
            Draw the panels in this axes' slot (divided into the panels) or on this figure
            (cleared); by default on a new `matplotlib.figure.Figure` (no pyplot).

        Returns
        -------
        matplotlib.figure.Figure
        """
        fig, grid = panel_grid(ax, 2, 2, (12.0, 8.0))
        s = self._series
        t, w, w_ex = s["t"], s["w"], s["w_exact"]
        ax1 = fig.add_subplot(grid[0, 0])
        for i, c in enumerate("tab:blue tab:orange tab:green".split()):
            ax1.plot(t, w[i], color=c, label=f"w{i + 1}")
            ax1.plot(t, w_ex[i], color="k", ls=":", lw=1)
        ax1.set(xlabel="t [s]", ylabel="body rate [rad/s]", title="Rates (dotted: exact)")
        ax1.legend(loc="upper right")
        ax2 = fig.add_subplot(grid[0, 1], projection="3d")
        ax2.plot(w[0], w[1], w[2], lw=1)
        ax2.set(xlabel="w1 [rad/s]", ylabel="w2 [rad/s]", zlabel="w3 [rad/s]",
                title="Polhode (body rates)")
        ax3 = fig.add_subplot(grid[1, 0])
        tiny = 1e-17
        ax3.semilogy(t, np.abs(s["energy"] / s["energy"][0] - 1) + tiny, label="|dT/T|")
        ax3.semilogy(t, s["momentum_err"] + tiny, label="|dH|/|H|")
        ax3.semilogy(t, np.abs(s["quat_norm"] - 1) + tiny, label="||q| - 1|")
        ax3.set(xlabel="t [s]", ylabel="relative drift [-]", title="Invariant drift")
        ax3.legend()
        ax4 = fig.add_subplot(grid[1, 1])
        ax4.semilogy(t, np.max(np.abs(w - w_ex), axis=0) + tiny)
        ax4.set(xlabel="t [s]", ylabel="max |w - w_exact| [rad/s]", title="Error vs truth")
        return finish_figure(fig)


def torque_free(inertia, w0, *, t_final=50.0, n_points=1001, q0=None, method="auto",
                rtol=1e-10, atol=1e-12, steps=None, tol=None, progress=None) -> TorqueFreeReport:
    """Simulate a torque-free rigid body and compare with the exact solution.

    Parameters
    ----------
    inertia : array_like, shape (3,) or (3, 3) [kg m^2]
        Principal moments or a full inertia matrix (the truth is evaluated in principal axes).
    w0 : array_like, shape (3,) [rad/s]
        Initial body rates.
    t_final : float [s], optional
        Final time (50).
    n_points : int, optional
        Output grid size (1001).
    q0 : array_like, shape (4,), optional
        Initial attitude, scalar-last (identity).
    method, rtol, atol, steps : optional
        Passed to `dynamics.simulate` (fixed-step methods ignore ``rtol``/``atol`` but the
        truth check still uses them).
    tol : float, optional
        Relative accuracy asked of the result instead of ``rtol``/``atol``.
    progress : callable, optional
        ``progress(done, total)`` in integration steps, passed to `dynamics.simulate`.

    Returns
    -------
    TorqueFreeReport
        ``success`` is the integrator's success *and* the truth check (`verified`):

        * default: ``|w_i(t) - w_exact_i(t)| <= max(CHECK_FACTOR (atol + rtol |w_exact_i(t)|),
          ROUNDOFF_FACTOR eps |w0| (1 + |w0| t_final))`` at every output time and axis —
          the requested tolerance read as a *global* error (what ``method='auto'`` controls;
          ``cvodes`` controls the local error only and usually misses it on long runs);
        * with ``tol``: ``max |w - w_exact| <= tol |w0|`` (``max_rel_rate_error <= tol``).
    """
    I = check_inertia(inertia)
    w0 = np.asarray(w0, dtype=float).reshape(-1)
    if w0.shape != (3,) or not np.all(np.isfinite(w0)):
        raise ValueError(f"`w0` must be 3 finite body rates [rad/s], got {w0}")
    if not (np.isfinite(t_final) and t_final > 0):
        raise ValueError(f"`t_final` must be positive and finite, got {t_final}")
    if int(n_points) < 2:
        raise ValueError(f"`n_points` must be at least 2, got {n_points}")
    q0 = np.array([0.0, 0.0, 0.0, 1.0]) if q0 is None else np.asarray(q0, dtype=float)
    model = rigid_body(I)
    t = np.linspace(0.0, float(t_final), int(n_points))
    if tol is not None and not (np.isfinite(tol) and tol > 0):
        raise ValueError(f"`tol` must be positive and finite, got {tol}")
    extra = {} if steps is None else dict(steps=int(steps))
    with np.errstate(over="ignore", invalid="ignore"):  # a diverged run is reported, not warned
        res = simulate(model, np.concatenate([q0, w0]), t, method=method, rtol=rtol,
                       atol=atol, invariants=True, progress=progress, **extra)
        moments, A = principal_axes(I)
        w = res.x[model.layout["hub"].speeds]
        w_exact = A.T @ torque_free_omega(moments, A @ w0, t)
        dev = np.abs(w - w_exact)
        err = np.max(dev)
        wn = float(np.linalg.norm(w0))
        if tol is None:
            floor = ROUNDOFF_FACTOR * np.finfo(float).eps * wn * (1.0 + wn * float(t_final))
            bound = np.maximum(CHECK_FACTOR * (atol + rtol * np.abs(w_exact)), floor)
            check = (f"|w - w_exact| <= {CHECK_FACTOR:g} (atol + rtol |w_exact|) with atol = "
                     f"{atol:g}, rtol = {rtol:g}, round-off floor {floor:.1e} rad/s")
        else:
            bound = np.full_like(dev, tol * max(wn, 1e-300))
            check = f"max |w - w_exact| <= tol |w0| with tol = {tol:g}"
        ratio = np.where(np.isfinite(dev), dev / bound, np.inf)
        worst = np.unravel_index(int(np.argmax(ratio)), ratio.shape)
        verified = bool(np.all(np.isfinite(dev)) and np.max(ratio) <= 1.0)
        energy = np.asarray(res.invariants["energy"])
        energy_drift = (float(np.max(np.abs(energy / energy[0] - 1))) if energy[0] > 0
                        else 0.0)
        H = np.asarray(res.invariants["momentum_inertial"])
        H0 = np.linalg.norm(H[:, 0])
        momentum_err = np.linalg.norm(H - H[:, :1], axis=0) / H0 if H0 > 0 else np.zeros_like(t)
        qn = np.asarray(res.invariants["quat_norm"])
    return TorqueFreeReport(
        inertia=I.tolist(),
        w0=w0.tolist(),
        t_final=float(t_final),
        method=res.method,
        success=bool(res.success) and verified,
        message=str(res.message),
        max_rate_error=float(err),
        max_rel_rate_error=float(err / max(np.linalg.norm(w0), 1e-300)),
        energy_drift=energy_drift,
        momentum_drift=float(np.max(momentum_err)),
        quat_norm_drift=float(np.max(np.abs(qn - 1))),
        wall_time=float(res.wall_time),
        n_steps=int(res.n_steps),
        integrator_success=bool(res.success),
        verified=verified,
        allowed_error=float(bound[worst]),
        error_ratio=float(ratio[worst]),
        check=check,
        rtol=float(rtol),
        atol=float(atol),
        tol=None if tol is None else float(tol),
        worst_time=float(t[worst[1]]),
        worst_component=int(worst[0]),
        _series=dict(t=t, w=w, w_exact=w_exact, energy=energy, momentum_err=momentum_err,
                     quat_norm=qn),
    )
