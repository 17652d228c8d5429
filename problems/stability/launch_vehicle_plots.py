"""Loop plots of the launch-vehicle autopilot (`problems.stability.launch_vehicle`): the loop
transfer broken at the engine deflection, its Bode and Nichols plots with the gain and phase
margins of ``control.stability_margins`` marked (the report's own `plot` is the pole map)."""
from __future__ import annotations

import math

import numpy as np

from appdyn.dynamics.figures import axes_or_new_figure, cleared_figure, finish_figure

from .report import StabilityReport

__all__ = ["loop_transfer", "bode_plot", "nichols_plot"]


def loop_transfer(report: StabilityReport):
    """The loop transfer ``L = K P`` of a `launch_vehicle` report, broken at the deflection.

    ``P`` is rebuilt from the closed loop (``A = A_cl + B K C``), ``K = [k_psi, k_psidot]``.

    Parameters
    ----------
    report : StabilityReport
        From `launch_vehicle`.

    Returns
    -------
    control.StateSpace
        One input (the deflection command), one output (the autopilot's ``-delta_c``).

    Raises
    ------
    ValueError
        Naming ``report`` when it is not a launch-vehicle report.

    Examples
    --------
    >>> import control
    >>> from appdyn.problems import stability
    >>> rep = stability.launch_vehicle(thrust=2e6, inertia=4e7, arm=20, mass=1e5, k_psi=2,
    ...                                k_psidot=2)
    >>> round(float(control.stability_margins(stability.loop_transfer(rep))[1]), 4)
    65.5302
    """
    import control

    if not isinstance(report, StabilityReport) or report.case != "launch_vehicle":
        raise ValueError("`report` must be a StabilityReport of "
                         "problems.stability.launch_vehicle, got "
                         f"{getattr(report, 'case', type(report).__name__)!r}")
    ss = report.ss
    K = np.array([[report.parameters["k_psi"], report.parameters["k_psidot"]]])
    A = np.asarray(ss.A) + np.asarray(ss.B) @ K @ np.asarray(ss.C)
    return control.ss(A, ss.B, K @ np.asarray(ss.C), np.zeros((1, 1)),
                      states=list(ss.state_labels), inputs=list(ss.input_labels),
                      outputs=["-delta_command"], name="loop")


def _frequency_grid(L, margins, omega):
    if omega is not None:
        return np.asarray(omega, dtype=float)
    ev = np.linalg.eigvals(np.asarray(L.A)) if L.nstates else np.zeros(0)
    crossings = [w for w in (margins.gain_crossover, margins.phase_crossover)
                 if math.isfinite(w) and w > 0]
    marks = [abs(z) for z in ev if abs(z) > 0] + crossings
    lo, hi = (min(marks) / 30, max(marks) * 30) if marks else (1e-2, 1e2)
    grid = [np.logspace(math.log10(lo), math.log10(hi), 1500), crossings]
    for z in ev:  # resolve lightly damped peaks (slosh, bending)
        if abs(z) > 0 and abs(z.real) < 0.1 * abs(z):
            grid.append(abs(z) * (1 + max(abs(z.real) / abs(z), 1e-4) * np.linspace(-5, 5, 41)))
    return np.unique(np.concatenate(grid))


def _loop_response(report, omega):
    """``(omega, magnitude [dB], phase [deg])``; the phase shifted by whole turns so that it
    reads ``-180 + PM`` at the gain crossover (or lies in (-360, 0] at the lowest frequency)."""
    L = loop_transfer(report)
    mg = report.margins
    omega = _frequency_grid(L, mg, omega)
    resp = np.atleast_1d(L(1j * omega)).reshape(-1)
    mag = 20 * np.log10(np.maximum(np.abs(resp), 1e-300))
    phase = np.degrees(np.unwrap(np.angle(resp)))
    if math.isfinite(mg.gain_crossover) and math.isfinite(mg.phase_margin):
        at = np.interp(math.log(mg.gain_crossover), np.log(omega), phase)
        phase += 360 * round((-180 + mg.phase_margin - at) / 360)
    else:
        phase -= 360 * math.ceil(phase[0] / 360)
    return omega, mag, phase


def _margin_texts(mg):
    gm = ("GM = inf (no phase crossover)" if not math.isfinite(mg.phase_crossover) else
          f"GM = {mg.gain_margin_db:.3g} dB at {mg.phase_crossover:.3g} rad/s")
    pm = ("PM = inf (no gain crossover)" if not math.isfinite(mg.gain_crossover) else
          f"PM = {mg.phase_margin:.3g} deg at {mg.gain_crossover:.3g} rad/s")
    return gm, pm


def bode_plot(report: StabilityReport, *, path=None, fig=None, omega=None,
              pole_map: bool = False):
    """Bode plot of the loop at the engine deflection with the gain and phase margins marked.

    Parameters
    ----------
    report : StabilityReport
        From `launch_vehicle`.
    path : str or path-like, optional
        Also save the figure there.
    fig : matplotlib.figure.Figure, optional
        Draw on this figure (cleared); by default a new one (no pyplot).
    omega : array_like [rad/s], optional
        Frequencies (default: around the poles and crossovers, lightly damped peaks resolved).
    pole_map : bool
        Add the report's pole map (`StabilityReport.plot`) on the right.

    Returns
    -------
    matplotlib.figure.Figure
        Magnitude and phase of ``L(i omega)``: the gain margin a red bar from ``|L|`` to
        0 dB at the phase crossover, the phase margin a green bar from -180 deg at the gain
        crossover, both written out.

    Examples
    --------
    >>> from appdyn.problems import stability
    >>> rep = stability.launch_vehicle(thrust=2e6, inertia=4e7, arm=20, mass=1e5, k_psi=2,
    ...                                k_psidot=2)
    >>> fig = stability.bode_plot(rep, pole_map=True)
    >>> len(fig.axes), fig.axes[1].texts[0].get_text()
    (3, 'PM = 65.5 deg at 2.2 rad/s')
    """
    w, mag, phase = _loop_response(report, omega)
    mg = report.margins
    fig = cleared_figure(fig, (13.0, 6.5) if pole_map else (8.0, 6.5))
    grid = fig.add_gridspec(2, 2 if pole_map else 1)
    ax_m = fig.add_subplot(grid[0, 0])
    ax_p = fig.add_subplot(grid[1, 0], sharex=ax_m)
    ax_m.semilogx(w, mag, color="tab:blue")
    ax_p.semilogx(w, phase, color="tab:blue")
    ax_m.axhline(0, color="0.5", lw=0.8)
    for turn in range(math.ceil((phase.min() + 180) / 360),
                      math.floor((phase.max() + 180) / 360) + 1):
        ax_p.axhline(-180 + 360 * turn, color="0.5", lw=0.8)
    gm_text, pm_text = _margin_texts(mg)
    if math.isfinite(mg.phase_crossover):
        ax_m.vlines(mg.phase_crossover, -mg.gain_margin_db, 0, color="tab:red", lw=2)
        ax_p.plot([mg.phase_crossover], [np.interp(math.log(mg.phase_crossover), np.log(w),
                                                   phase)], "o", color="tab:red")
    if math.isfinite(mg.gain_crossover):
        ax_p.vlines(mg.gain_crossover, -180, -180 + mg.phase_margin, color="tab:green", lw=2)
        ax_m.plot([mg.gain_crossover], [0], "o", color="tab:green")
    ax_m.text(0.02, 0.05, gm_text, transform=ax_m.transAxes, color="tab:red", fontsize=9)
    ax_p.text(0.02, 0.05, pm_text, transform=ax_p.transAxes, color="tab:green", fontsize=9)
    ax_m.set(ylabel="|L| [dB]", title="Loop at the engine deflection, L = [k_psi, k_psidot] P")
    ax_p.set(xlabel="frequency [rad/s]", ylabel="phase of L [deg]")
    for ax in (ax_m, ax_p):
        ax.grid(True, which="both", alpha=0.3)
    if pole_map:
        report.plot(ax=fig.add_subplot(grid[:, 1]))
    return finish_figure(fig, path)


def nichols_plot(report: StabilityReport, *, path=None, ax=None, omega=None):
    """Nichols plot of the loop at the engine deflection: the critical point (-180 deg, 0 dB),
    the gain margin (vertical) and the phase margin (horizontal) marked.

    Parameters
    ----------
    report : StabilityReport
        From `launch_vehicle`.
    path : str or path-like, optional
        Also save the figure there.
    ax : matplotlib.axes.Axes, optional
        Draw on these axes; by default on a new figure (no pyplot).
    omega : array_like [rad/s], optional
        Frequencies (default as in `bode_plot`).

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> from appdyn.problems import stability
    >>> rep = stability.launch_vehicle(thrust=2e6, inertia=4e7, arm=20, mass=1e5, k_psi=2,
    ...                                k_psidot=2)
    >>> [t.get_text() for t in stability.nichols_plot(rep).axes[0].get_legend().get_texts()]
    ['critical point', 'PM = 65.5 deg at 2.2 rad/s']
    """
    _, mag, phase = _loop_response(report, omega)
    mg = report.margins
    fig, ax = axes_or_new_figure(ax, (7.0, 5.5))
    ax.plot(phase, mag, color="tab:blue")
    ax.plot([-180], [0], "+", ms=14, mew=2, color="k", label="critical point")
    gm_text, pm_text = _margin_texts(mg)
    if math.isfinite(mg.phase_crossover):
        ax.vlines(-180, -mg.gain_margin_db, 0, color="tab:red", lw=2, label=gm_text)
    if math.isfinite(mg.gain_crossover):
        ax.hlines(0, -180, -180 + mg.phase_margin, color="tab:green", lw=2, label=pm_text)
    ax.set(xlabel="phase of L [deg]", ylabel="|L| [dB]",
           title="Nichols: loop at the engine deflection")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    return finish_figure(fig, path)
