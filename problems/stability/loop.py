"""`loop`: closed-loop stability and classical margins of any plant under a feedback law."""
from __future__ import annotations

import math

import numpy as np
from appdyn.dynamics.results import timed

from .report import Margins, StabilityReport, build_report

__all__ = ["loop"]

#: The gain factors on either side of a phase crossover's gain margin at which the closed
#: loop's count of unstable poles must differ for the crossover to be one (`_margins`).
CONFIRM = 1e-3


@timed
def loop(plant, controller, *, title: str = "Feedback loop", closed_form=None) -> StabilityReport:
    """Closed-loop stability and margins of ``plant`` under ``u = -controller(y)``.

    Parameters
    ----------
    plant : control.StateSpace or control.TransferFunction
        ``ny`` outputs, ``nu`` inputs.
    controller : array_like, shape (nu, ny), or control.StateSpace / TransferFunction
        A static gain or a dynamic compensator from ``y`` to ``u`` (negative feedback).
    title : str, optional
        Title of the report.
    closed_form : array_like of complex, optional
        Expected closed-loop eigenvalues, matched and checked.

    Returns
    -------
    StabilityReport
        ``ss`` is the closed loop (input added at the plant input, outputs ``y``); ``margins``
        of the loop transfer ``L = controller * plant`` broken at the plant input, when it
        is single-input (``None`` otherwise, with a note).

    Raises
    ------
    ValueError
        Naming ``plant`` or ``controller`` when they are not LTI systems or do not fit.

    Examples
    --------
    Attitude loop of a launch vehicle, ``I psi'' = F l delta`` with
    ``delta = -(k_psi psi + k_psidot psi')`` (RP-1262, Ch. 5, Eqs. 5.53-5.54):

    >>> import control, numpy as np
    >>> from appdyn.problems import stability
    >>> plant = control.ss([[0, 1], [0, 0]], [[0], [200.0]], np.eye(2), np.zeros((2, 1)))
    >>> rep = stability.loop(plant, [[0.8, 0.3]])
    >>> rep.verdict
    'asymptotically stable'
    >>> round(rep.margins.phase_margin, 2)
    87.46
    """
    import control

    if isinstance(plant, control.TransferFunction):
        plant = control.ss(plant)
    if not isinstance(plant, control.StateSpace):
        raise ValueError(f"`plant` must be a control.StateSpace or TransferFunction, got "
                         f"{type(plant).__name__}")
    if isinstance(controller, control.TransferFunction):
        controller = control.ss(controller)
    if not isinstance(controller, control.StateSpace):
        try:
            K = np.atleast_2d(np.asarray(controller, dtype=float))
        except (TypeError, ValueError):
            raise ValueError("`controller` must be a gain matrix or an LTI system, got "
                             f"{type(controller).__name__}") from None
        if K.shape != (plant.ninputs, plant.noutputs) or not np.all(np.isfinite(K)):
            raise ValueError(f"`controller` gain must be finite with shape (nu, ny) = "
                             f"({plant.ninputs}, {plant.noutputs}), got {K.shape}")
        controller = control.ss(np.zeros((0, 0)), np.zeros((0, plant.noutputs)),
                                np.zeros((plant.ninputs, 0)), K, name="controller")
    if controller.ninputs != plant.noutputs or controller.noutputs != plant.ninputs:
        raise ValueError(f"`controller` must map the {plant.noutputs} plant outputs to the "
                         f"{plant.ninputs} plant inputs, got {controller.ninputs} -> "
                         f"{controller.noutputs}")
    closed = control.feedback(plant, controller, sign=-1)
    k_states = [f"k_{s}" for s in controller.state_labels]
    closed = control.ss(closed.A, closed.B, closed.C, closed.D,
                        states=list(plant.state_labels) + k_states,
                        inputs=list(plant.input_labels), outputs=list(plant.output_labels),
                        name="closed_loop")
    margins, notes = None, []
    if plant.ninputs == 1:
        L = control.series(plant, controller)
        gm, pm, sm, wpc, wgc, wms = _margins(L)
        margins = Margins(gain_margin=gm,
                          gain_margin_db=20 * math.log10(gm) if gm > 0 and math.isfinite(gm)
                          else (math.inf if gm == math.inf else math.nan),
                          phase_margin=float(pm), stability_margin=float(sm),
                          phase_crossover=float(wpc), gain_crossover=float(wgc),
                          stability_margin_frequency=float(wms))
    else:
        notes.append(f"margins need a single loop; the plant has {plant.ninputs} inputs")
    groups = {"plant": list(plant.state_labels),
              "controller": k_states}
    return build_report("loop", title, {"plant": plant.name, "controller": controller.name},
                        closed, groups=groups, margins=margins, notes=notes,
                        closed_form=closed_form)


def _unstable(L, k: float) -> int:
    """The closed loop ``feedback(k L)``'s poles in the right half-plane (its scale's
    1e-12 on the imaginary axis counts as stable)."""
    import control

    closed = control.feedback(k * L, 1, sign=-1)
    poles = np.linalg.eigvals(np.asarray(closed.A)) if closed.nstates else np.zeros(0)
    scale = max(1.0, float(np.max(np.abs(poles)))) if poles.size else 1.0
    return int(np.sum(poles.real > 1e-12 * scale))


def gain_margins(L) -> tuple[np.ndarray, np.ndarray]:
    """Every gain margin of the SISO loop ``L`` and its phase crossover frequency [rad/s]:
    python-control's (``stability_margins(L, returnall=True)``) where the closed loop's
    unstable poles differ between the gains ``g (1 - CONFIRM)`` and ``g (1 + CONFIRM)``
    (what a gain margin is; a crossover found at a zero on the imaginary axis changes
    nothing, `_margins`). Shapes (k,), (k,).

    Examples
    --------
    >>> import control
    >>> from appdyn.problems.stability.loop import gain_margins
    >>> gain_margins(control.tf([1.0, 0.0, 4.0], [1.0, 2.0, 2.0, 1.0]))[0].round(9)
    array([1.5])
    """
    return _confirmed(L, _all_margins(L))


def _all_margins(L) -> tuple[np.ndarray, ...]:
    """``control.stability_margins(L, returnall=True)`` as six float arrays."""
    import control

    return tuple(np.atleast_1d(np.asarray(v, float))
                 for v in control.stability_margins(L, returnall=True))


def _confirmed(L, margins: tuple) -> tuple[np.ndarray, np.ndarray]:
    """The gain margins and phase crossovers of ``margins`` (`_all_margins`) where the
    closed loop's unstable poles change across the margin (`gain_margins`)."""
    import control

    gms, wpcs = margins[0], margins[3]
    ss = control.ss(L)
    real = [i for i, g in enumerate(gms) if np.isfinite(g) and g > 0
            and _unstable(ss, g * (1 - CONFIRM)) != _unstable(ss, g * (1 + CONFIRM))]
    return gms[real], wpcs[real]


def _margins(L) -> tuple[float, float, float, float, float, float]:
    """``control.stability_margins(L)`` (gain margin, phase margin, stability margin, and
    their frequencies), without the phase crossovers that are not: a gain margin ``g``
    counts only where the closed loop's unstable poles differ between the gains
    ``g (1 - CONFIRM)`` and ``g (1 + CONFIRM)``, the property that defines it. A crossover
    python-control finds at a zero on the imaginary axis (an undamped slosh zero: the phase
    flips by 180 deg there with |L| = 0) changes nothing: rounding decides whether it is
    found and at what |L| (1e-9 on one CPU, 3e-4 on another, a gain margin of 3197
    against none), so it is dropped. Of the rest, the one nearest 1 in log is reported, as
    python-control does.

    Examples
    --------
    >>> import control
    >>> from appdyn.problems.stability.loop import _margins
    >>> L = control.tf([1.0], [1.0, 3.0, 3.0, 1.0])  # 1 / (s + 1)^3: unstable beyond 8
    >>> round(_margins(L)[0], 9), round(_margins(L)[3] ** 2, 9)
    (8.0, 3.0)
    >>> z = control.tf([1.0, 0.0, 4.0], [1.0, 1.0, 5.0, 1.0])  # zeros at +-2j: stable for all k
    >>> gm, _, _, w, _, _ = control.stability_margins(z)  # a crossover at the zero
    >>> bool(gm > 1e12), round(float(w), 9)
    (True, 2.0)
    >>> _margins(z)[0], bool(math.isnan(_margins(z)[3]))
    (inf, True)
    """
    margins = _all_margins(L)
    _, pms, sms, _, wgcs, wmss = margins
    gms, wpcs = _confirmed(L, margins)
    if gms.size:
        i = int(np.argmin(np.abs(np.log(gms))))
        gm, wpc = float(gms[i]), float(wpcs[i])
    else:
        gm, wpc = math.inf, math.nan
    if pms.size:
        j = int(np.argmin(np.abs(pms)))
        pm, wgc = float(pms[j]), float(wgcs[j])
    else:
        pm, wgc = math.inf, math.nan
    if sms.size:
        k = int(np.argmin(sms))
        sm, wms = float(sms[k]), float(wmss[k])
    else:
        sm, wms = math.inf, math.nan
    return gm, pm, sm, wpc, wgc, wms
