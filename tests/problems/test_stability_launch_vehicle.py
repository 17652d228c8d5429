"""The launch-vehicle autopilot report (seed 002, Sec. 5.4, Eqs. 5.53-5.54) against truths
written out here: the closed loop ``I psi'' + F l k_psidot psi' + F l k_psi psi = 0``, loops
and margins built by hand and handed to python-control, the aerodynamic plant derived from
the forces, the Routh-Hurwitz boundary found by root finding, decoupled modes at their own
frequencies, jet damping (Eq. 3.49), the autopilot closed inside `dynamics.launch_vehicle`,
and the time response of the rigid loop."""
import doctest
import importlib
import json
import math

import control
import numpy as np
import pytest
from scipy.optimize import brentq, linear_sum_assignment

from appdyn.dynamics import launch_vehicle as vehicle_model
from appdyn.dynamics import linearize
from appdyn.dynamics.launch_vehicle import Actuator, Aero, Bending, MassFlow, Slosh
from appdyn.problems import stability as st
from appdyn.problems.stability import (bode_plot, classify, launch_vehicle, launch_vehicle_response,
                                loop_transfer, nichols_plot, sweep)

F, I, L, M = 2.0e6, 4.0e7, 20.0, 1.0e5  # N, kg m^2, m, kg
VEHICLE = dict(thrust=F, inertia=I, arm=L, mass=M)
AERO = Aero(dynamic_pressure=3e4, area=10.0, normal_force_slope=3.0, cp_arm=5.0)  # cp ahead
N_A = 3e4 * 10.0 * 3.0  # q S C_N_alpha [N/rad]
M_A = N_A * 5.0  # aerodynamic moment per rad [N m/rad]
V = 500.0


def pair_error(computed, expected):
    computed, expected = np.asarray(computed, complex), np.asarray(expected, complex)
    assert computed.shape == expected.shape, (computed, expected)
    rows, cols = linear_sum_assignment(np.abs(computed[:, None] - expected[None, :]))
    return np.max(np.abs(computed[rows] - expected[cols])) / np.max(np.abs(expected))


def labels(rep):
    return [m.label for m in rep.modes]


# --------------------------------------------------------------- rigid vehicle (Sec. 5.4)
@pytest.mark.parametrize("k, kd", [(2.0, 2.0), (0.5, 0.1), (8.0, 1.0), (1e-3, 1e-4)])
def test_rigid_closed_loop_formula(k, kd):
    """I psi'' + F l kd psi' + F l k psi = 0: wn = sqrt(F l k / I),
    zeta = kd sqrt(F l) / (2 sqrt(I k))."""
    rep = launch_vehicle(**VEHICLE, k_psi=k, k_psidot=kd)
    wn = math.sqrt(F * L * k / I)
    zeta = kd * math.sqrt(F * L) / (2 * math.sqrt(I * k))
    (mode,) = rep.modes
    assert mode.label == "rigid attitude" and mode.pair
    assert abs(mode.wn - wn) <= 1e-10 * wn
    assert abs(mode.zeta - zeta) <= 1e-10 * zeta
    assert rep.quantity("rigid omega_n").value == pytest.approx(wn, rel=1e-10)
    assert rep.quantity("rigid zeta").value == pytest.approx(zeta, rel=1e-10)
    assert rep.status == st.STATUS_VERIFIED and rep.closed_form_error < 1e-12
    assert rep.verdict == "asymptotically stable"
    assert rep.ss.state_labels == ["psi", "psi_dot"]


def test_overdamped_and_negative_gains():
    rep = launch_vehicle(**VEHICLE, k_psi=0.1, k_psidot=3.0)  # zeta > 1: two real roots
    assert pair_error(rep.eigenvalues, np.roots([I, F * L * 3.0, F * L * 0.1])) < 1e-12
    assert labels(rep) == ["rigid attitude", "rigid attitude"]
    assert rep.quantity("rigid omega_n").value == pytest.approx(math.sqrt(F * L * 0.1 / I))
    rep = launch_vehicle(**VEHICLE, k_psi=-0.5, k_psidot=1.0)  # wrong-sign attitude gain
    assert rep.verdict == "unstable" and rep.status == st.STATUS_VERIFIED
    assert "attitude divergence" in labels(rep)


def test_translation_is_factored_out_and_the_full_loop_is_what_the_model_closes():
    """The autopilot closed inside dynamics.launch_vehicle, linearized with every state,
    has the report's eigenvalues plus four zeros in Jordan pairs (x, x_dot; y, y_dot), which
    the verdict rule calls unstable: the drift the report factors out."""
    rep = launch_vehicle(**VEHICLE, k_psi=2.0, k_psidot=2.0)
    closed = vehicle_model(**VEHICLE, k_psi=2.0, k_psidot=2.0)
    A = np.asarray(linearize(closed, np.zeros(6), allow_non_equilibrium=True).A)
    assert pair_error(np.linalg.eigvals(A), np.r_[rep.eigenvalues, np.zeros(4)]) < 1e-14
    assert classify(A)[0] == "unstable" and "Jordan block" in classify(A)[1]
    assert rep.verdict == "asymptotically stable"
    note = next(n for n in rep.notes if n.startswith("factored out"))
    for name in ("x, y", "x_dot", "y_dot"):
        assert name in note
    assert any("drift" in n and "guidance" in n for n in rep.notes)
    assert rep.linearization.states == ("x", "y", "psi", "x_dot", "y_dot", "psi_dot")


def test_all_parts_closed_loop_matches_the_model_with_the_autopilot_inside():
    parts = dict(aero=AERO, velocity=V, slosh=Slosh(2000.0, 3.0, length=1.5, damping_ratio=0.01),
                 bending=Bending(12.0, 5000.0, 0.01, slope_sensor=0.002, deflection_gimbal=0.5),
                 actuator=Actuator(0.05))
    rep = launch_vehicle(**VEHICLE, k_psi=1.0, k_psidot=0.5, **parts)
    velocity = parts.pop("velocity")
    closed = vehicle_model(**VEHICLE, k_psi=1.0, k_psidot=0.5, **parts)
    x = np.zeros(closed.nx)
    x[3] = velocity
    A = np.asarray(linearize(closed, x, allow_non_equilibrium=True).A)
    assert pair_error(np.linalg.eigvals(A), np.r_[rep.eigenvalues, np.zeros(3)]) < 1e-12
    assert rep.status == st.STATUS_UNCHECKED  # coupled slosh and bending: no closed form
    assert set(labels(rep)) == {"lateral drift", "rigid attitude", "slosh", "bending",
                                "actuator"}
    slosh = next(m for m in rep.modes if m.label == "slosh")
    assert 3.0 < slosh.wn < 4.5  # near sqrt(a/L) = sqrt(20/1.5) = 3.65 rad/s, held vehicle
    bend = next(m for m in rep.modes if m.label == "bending")
    assert abs(bend.wn - 12.0) < 0.5
    act = next(m for m in rep.modes if m.label == "actuator")
    assert act.eigenvalue.real == pytest.approx(-1 / 0.05, rel=0.05)


# ---------------------------------------------------------------------------- margins
def test_rigid_margins_match_python_control_and_the_closed_form():
    """L(s) = F l (k + kd s) / (I s^2): the phase never reaches -180 deg at a finite
    frequency (GM infinite); |L(i wc)| = 1 at wc^2 = (a^2 kd^2 + sqrt(a^4 kd^4 +
    4 I^2 a^2 k^2)) / (2 I^2), a = F l, where the phase is -180 + atan(kd wc / k)."""
    k, kd = 2.0, 1.0
    rep = launch_vehicle(**VEHICLE, k_psi=k, k_psidot=kd)
    a = F * L
    gm, pm, sm, wpc, wgc, wms = control.stability_margins(control.tf([a * kd, a * k],
                                                                     [I, 0, 0]))
    mg = rep.margins
    assert mg.gain_margin == gm == math.inf
    assert mg.phase_margin == pytest.approx(pm, rel=1e-10)
    assert mg.gain_crossover == pytest.approx(wgc, rel=1e-10)
    wc = math.sqrt((a * a * kd * kd + math.sqrt(a ** 4 * kd ** 4 + 4 * I * I * a * a * k * k))
                   / (2 * I * I))
    assert abs(mg.gain_crossover - wc) <= 1e-10 * wc
    assert abs(mg.phase_margin - math.degrees(math.atan(kd * wc / k))) <= 1e-9
    assert control.stability_margins(loop_transfer(rep))[1] == pytest.approx(pm, rel=1e-12)


def aero_plant():
    """Linear plant from the forces, states (psi, y_dot, psi_dot), alpha = psi - y_dot/V:
    I psi'' = F l delta + M_a alpha; m y_dot' = F (psi - delta) + N_a alpha."""
    A = [[0, 0, 1],
         [(F + N_A) / M, -N_A / (M * V), 0],
         [M_A / I, -M_A / (I * V), 0]]
    B = [[0], [-F / M], [F * L / I]]
    return np.array(A, float), np.array(B, float), np.array([[1.0, 0, 0], [0, 0, 1.0]])


@pytest.mark.parametrize("k, kd", [(1.0, 0.5), (2.0, 1.5)])
def test_aero_loop_and_margins_match_a_hand_built_plant(k, kd):
    A, B, C = aero_plant()
    K = np.array([[k, kd]])
    rep = launch_vehicle(**VEHICLE, k_psi=k, k_psidot=kd, aero=AERO, velocity=V)
    assert pair_error(rep.eigenvalues, np.linalg.eigvals(A - B @ K @ C)) < 1e-12
    assert rep.status == st.STATUS_VERIFIED  # the cubic of the module notes
    gm, pm, sm, wpc, wgc, wms = control.stability_margins(control.ss(A, B, K @ C, 0))
    mg = rep.margins
    for ours, theirs in [(mg.gain_margin, gm), (mg.phase_margin, pm), (mg.phase_crossover, wpc),
                         (mg.gain_crossover, wgc), (mg.stability_margin, sm)]:
        assert ours == pytest.approx(theirs, rel=1e-8)
    assert rep.verdict == "asymptotically stable"
    assert any("unstable pole" in n for n in rep.notes)  # cp ahead: the airframe diverges


def test_aero_divergence_with_too_little_gain():
    """Cubic m I s^3 + a2 s^2 + a1 s + a0 with a1 = m (F l k - M_a) + F kd (l N_a + M_a)/V:
    a1 < 0 (too little gain: F l k below the aerodynamic moment M_a, with margin for the
    kd/V term) changes sign, so a root lies in the right half plane."""
    k, kd = 0.02, 0.1
    a1 = M * (F * L * k - M_A) + F * kd * (L * N_A + M_A) / V
    assert a1 < 0 and k < M_A / (F * L)
    rep = launch_vehicle(**VEHICLE, k_psi=k, k_psidot=kd, aero=AERO, velocity=V)
    assert rep.verdict == "unstable"
    div = next(m for m in rep.modes if m.label == "aero divergence")
    assert div.eigenvalue == rep.least_damped() and div.eigenvalue.real > 0 and not div.pair
    assert rep.quantity("aero gain bound").closed_form == pytest.approx(M_A / (F * L))
    assert rep.quantity("airframe divergence rate").closed_form == pytest.approx(
        math.sqrt(M_A / I))
    ok = launch_vehicle(**VEHICLE, k_psi=1.0, k_psidot=kd, aero=AERO, velocity=V)
    assert ok.verdict == "asymptotically stable" and "aero divergence" not in labels(ok)


def test_routh_gain_bound_by_root_finding_and_by_sweep():
    """The least stable k_psi with the drift included, found here as the zero of the
    largest real part of the hand-built closed loop; -> M_a / (F l) as V -> infinity."""
    A, B, C = aero_plant()
    kd = 0.5

    def growth(k):
        return np.max(np.linalg.eigvals(A - B @ np.array([[k, kd]]) @ C).real)

    k_star = brentq(growth, 0.05, 0.5, xtol=1e-14)
    rep = launch_vehicle(**VEHICLE, k_psi=1.0, k_psidot=kd, aero=AERO, velocity=V)
    assert rep.quantity("least stable k_psi").closed_form == pytest.approx(k_star, rel=1e-9)
    res = sweep("launch-vehicle", "k_psi", [0.05, 0.5], **VEHICLE, k_psidot=kd, aero=AERO,
                velocity=V)
    (b,) = res.boundaries
    assert abs(b.value - k_star) <= 1e-7 * k_star
    assert (b.before, b.after) == ("unstable", "asymptotically stable")
    fast = launch_vehicle(**VEHICLE, k_psi=1.0, k_psidot=kd, aero=AERO, velocity=1e7)
    assert fast.quantity("least stable k_psi").closed_form == pytest.approx(M_A / (F * L),
                                                                            rel=1e-4)


def test_stable_airframe_weathercocks():
    aero = Aero(3e4, 10.0, 3.0, cp_arm=-4.0)
    rep = launch_vehicle(**VEHICLE, k_psi=0.5, k_psidot=0.5, aero=aero, velocity=V)
    assert rep.verdict == "asymptotically stable" and "aero divergence" not in labels(rep)
    q = rep.quantity("airframe weathercock frequency")
    assert q.closed_form == pytest.approx(math.sqrt(N_A * 4.0 / I))
    # open loop s^3 + (b/V) s^2 - c s + F c/(m V), c = M_a/I < 0: one slow real root > 0
    # (the thrust turns the path after the weathercock), unlike the two of the cp ahead
    assert any("has 1 unstable pole" in n for n in rep.notes)


# ------------------------------------------------------- parts at their own frequencies
@pytest.mark.parametrize("bending", [
    Bending(12.0, 5000.0, 0.02),  # no coupling at all
    Bending(12.0, 5000.0, 0.02, slope_gimbal=0.01),  # turns the thrust, not excited by it
    Bending(12.0, 5000.0, 0.02, slope_sensor=0.05, slope_gimbal=0.01),  # also seen by the gyros
])
def test_uncoupled_bending_mode_keeps_its_own_frequency(bending):
    rep = launch_vehicle(**VEHICLE, k_psi=2.0, k_psidot=2.0, bending=bending)
    mode = next(m for m in rep.modes if m.label == "bending")
    w, z = 12.0, 0.02
    assert abs(mode.eigenvalue - complex(-z * w, w * math.sqrt(1 - z * z))) <= 1e-12 * w
    assert mode.wn == pytest.approx(w, rel=1e-12) and mode.zeta == pytest.approx(z, rel=1e-10)
    assert rep.status == st.STATUS_VERIFIED


@pytest.mark.parametrize("sensor", [0.0, 0.05])
def test_coupled_bending_moves_and_is_unchecked(sensor):
    """A gimbal moving with the mode (phi_g != 0): the thrust excites it, and its offset
    phi_g eta changes the thrust moment, even with the gyros blind to it."""
    rep = launch_vehicle(**VEHICLE, k_psi=2.0, k_psidot=2.0,
                         bending=Bending(12.0, 5000.0, 0.02, slope_sensor=sensor,
                                         deflection_gimbal=0.5))
    mode = next(m for m in rep.modes if m.label == "bending")
    assert abs(mode.wn - 12.0) > 1e-6 and rep.status == st.STATUS_UNCHECKED


@pytest.mark.parametrize("slosh, w", [
    (Slosh(0.0, 3.0, length=1.5, damping_ratio=0.05), math.sqrt(F / (M * 1.5))),
    (Slosh(0.0, 3.0, frequency=2.5), 2.5),
])
def test_massless_slosh_oscillates_at_its_held_frequency(slosh, w):
    rep = launch_vehicle(**VEHICLE, k_psi=2.0, k_psidot=2.0, slosh=slosh)
    mode = next(m for m in rep.modes if m.label == "slosh")
    assert mode.wn == pytest.approx(w, rel=1e-12)
    assert mode.zeta == pytest.approx(slosh.damping_ratio, abs=1e-12)
    assert rep.status == st.STATUS_VERIFIED


def test_actuator_lag_cubic():
    """(tau s + 1) I s^2 + F l (k + kd s) = 0."""
    tau, k, kd = 0.1, 2.0, 2.0
    rep = launch_vehicle(**VEHICLE, k_psi=k, k_psidot=kd, actuator=Actuator(tau))
    expected = np.roots([I * tau, I, F * L * kd, F * L * k])
    assert pair_error(rep.eigenvalues, expected) < 1e-12 and rep.status == st.STATUS_VERIFIED
    assert "actuator" in labels(rep) and rep.ss.input_labels == ["delta_command"]


def test_jet_damping_and_frozen_mass():
    """Eq. 3.49: the flow from l1 to l2 adds mdot (l2^2 - l1^2) psi' to the damping."""
    flow = MassFlow(rate=500.0, flow_start=-2.0, nozzle_exit=22.0)
    rep = launch_vehicle(**VEHICLE, k_psi=0.5, k_psidot=0.2, mass_flow=flow)
    jet = 500.0 * (22.0 ** 2 - 2.0 ** 2)
    expected = np.roots([I, F * L * 0.2 + jet, F * L * 0.5])
    assert pair_error(rep.eigenvalues, expected) < 1e-12 and rep.status == st.STATUS_VERIFIED
    assert "mass" not in rep.ss.state_labels
    assert any("mass" in n and "frozen" in n for n in rep.notes)


# ---------------------------------------------------------------------- plots and I/O
@pytest.mark.slow
def test_bode_plot_marks_the_margins_where_python_control_puts_them(tmp_path):
    from matplotlib.figure import Figure

    rep = launch_vehicle(**VEHICLE, k_psi=1.0, k_psidot=0.5, aero=AERO, velocity=V,
                         bending=Bending(12.0, 5000.0, 0.01, slope_sensor=0.002,
                                         deflection_gimbal=0.5))
    mg = rep.margins
    assert math.isfinite(mg.phase_crossover) and math.isfinite(mg.gain_crossover)
    fig = bode_plot(rep, pole_map=True)
    assert isinstance(fig, Figure) and len(fig.axes) == 3
    w, mag = fig.axes[0].lines[0].get_data()
    _, phase = fig.axes[1].lines[0].get_data()
    at = lambda y, w0: np.interp(math.log(w0), np.log(w), y)  # noqa: E731
    assert abs(at(mag, mg.gain_crossover)) < 1e-3  # 0 dB
    assert at(phase, mg.gain_crossover) == pytest.approx(-180 + mg.phase_margin, abs=1e-2)
    assert at(mag, mg.phase_crossover) == pytest.approx(-mg.gain_margin_db, abs=1e-2)
    texts = [t.get_text() for ax in fig.axes[:2] for t in ax.texts]
    assert any(t.startswith(f"GM = {mg.gain_margin_db:.3g} dB") for t in texts)
    assert any(t.startswith(f"PM = {mg.phase_margin:.3g} deg") for t in texts)
    fig = nichols_plot(rep)
    assert isinstance(fig, Figure) and "critical point" in [
        t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert len(bode_plot(launch_vehicle(**VEHICLE, k_psi=2, k_psidot=2)).axes) == 2
    given = Figure().subplots(1, 2)  # the panels fill the slot of the axes given
    assert bode_plot(rep, given[1]) is given[0].figure and len(given[0].figure.axes) == 3


def test_report_text_and_strict_json():
    rep = launch_vehicle(**VEHICLE, k_psi=1.0, k_psidot=0.5, aero=AERO, velocity=V,
                         slosh=Slosh(2000.0, 3.0, length=1.5), actuator=Actuator(0.05))
    text = str(rep)
    for word in ("rigid attitude", "slosh", "lateral drift", "actuator", "phase margin",
                 "aero gain bound", "factored out"):
        assert word in text
    d = json.loads(rep.to_json())
    assert d["case"] == "launch_vehicle" and d["parameters"]["aero"]["type"] == "Aero"
    assert d["margins"]["gain_crossover"] > 0 and d["states"][0] == "psi"
    assert st.resolve_case("launch-vehicle") == ("launch_vehicle", launch_vehicle)


@pytest.mark.parametrize("kwargs, error, name", [
    (dict(k_psi=float("nan"), k_psidot=1.0), ValueError, "`k_psi` must be finite"),
    (dict(k_psi=1.0, k_psidot="x"), ValueError, "`k_psidot` must be a number"),
    (dict(k_psi=1.0, k_psidot=1.0, aero=AERO), ValueError, "`velocity` is needed"),
    (dict(k_psi=1.0, k_psidot=1.0, velocity=300.0), ValueError, "`velocity` is the flight"),
    (dict(k_psi=1.0, k_psidot=1.0, aero=AERO, velocity=-1.0), ValueError,
     "`velocity` must be positive"),
    (dict(k_psi=1.0, k_psidot=1.0, thrust=-1.0), ValueError, "`thrust`"),
    (dict(k_psi=1.0, k_psidot=1.0, slosh=Slosh(2e5, 3.0, length=1.0)), ValueError,
     "`slosh.mass`"),
    (dict(k_psi=1.0, k_psidot=1.0, actuator=0.05), TypeError, "`actuator` must be"),
])
def test_bad_input_names_the_argument(kwargs, error, name):
    with pytest.raises(error, match=name):
        launch_vehicle(**{**VEHICLE, **kwargs})


def test_loop_transfer_needs_a_launch_vehicle_report():
    with pytest.raises(ValueError, match="`report` must be"):
        loop_transfer(st.spin([2.0, 3.0, 4.5], [1, 0, 0], 1.0))


# ------------------------------------------------------------------------ time response
@pytest.mark.slow
def test_rigid_response_follows_the_damped_oscillator():
    """Small psi0: psi = psi0 e^(-zeta wn t) (cos wd t + zeta wn / wd sin wd t); the
    nonlinearity sin(delta) - delta is (k psi0)^2 / 6 ~ 1e-6 relative."""
    k, kd, psi0 = 2.0, 1.0, 1e-3
    res = launch_vehicle_response(**VEHICLE, k_psi=k, k_psidot=kd, psi0=psi0, t_final=8.0,
                                  points=401)
    assert res.success and res.simulation.method == "rk8"
    wn = math.sqrt(F * L * k / I)
    zeta = kd * math.sqrt(F * L) / (2 * math.sqrt(I * k))
    wd = wn * math.sqrt(1 - zeta ** 2)
    t = res.t
    exact = psi0 * np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta * wn / wd * np.sin(wd * t))
    assert np.max(np.abs(res.series["psi"] - exact)) < 3e-6 * psi0
    rate = -psi0 * wn ** 2 / wd * np.exp(-zeta * wn * t) * np.sin(wd * t)
    assert np.max(np.abs(res.series["delta"] + k * exact + kd * rate)) < 1e-5 * psi0


@pytest.mark.slow
def test_gust_response_with_limited_actuator(tmp_path):
    act = Actuator(0.05, deflection_limits=(-0.01, 0.01), rate_limit=0.2)
    res = launch_vehicle_response(**VEHICLE, k_psi=1.0, k_psidot=0.5, aero=AERO, velocity=V,
                                  slosh=Slosh(2000.0, 3.0, length=1.5, damping_ratio=0.01),
                                  actuator=act, gust_speed=20.0, gust_start=1.0,
                                  gust_duration=2.0, t_final=6.0, points=301)
    assert res.success and res.simulation.method == "cvodes"
    assert res.peak("wind_y") == pytest.approx(20.0) and res.series["wind_y"][0] == 0
    assert 0.02 < res.peak("alpha") < 0.06  # about the gust angle 20/500 rad
    assert res.peak("delta") <= 0.01 + 1e-9  # the deflection limit holds
    assert res.peak("theta_s") > 0
    d = json.loads(res.to_json())
    assert d["success"] is True and len(d["series"]["psi"]) == len(res.t)
    assert "alpha [deg]" in str(res)
    fig = res.plot()
    assert len(fig.axes) == 4 + 1  # attitude, deflection, slosh, gust (+ the alpha axis)
    fig.savefig(tmp_path / "gust.png")  # the caller saves (the CLI does)
    assert (tmp_path / "gust.png").stat().st_size > 10_000


@pytest.mark.parametrize("kwargs, name", [
    (dict(gust_speed=10.0), "`gust_speed` needs `aero`"),
    (dict(psi0=0.01, points=1), "`points` must be an integer"),
    (dict(psi0=0.01, t_final=0.0), "`t_final` must be positive"),
    (dict(psi0=0.01, gust_start=-1.0), "`gust_start` must be non-negative"),
    (dict(psi0=0.01, mass_flow=MassFlow(rate=2e4)), "`t_final`"),
])
def test_response_bad_input_names_the_argument(kwargs, name):
    with pytest.raises(ValueError, match=name):
        launch_vehicle_response(**VEHICLE, k_psi=1.0, k_psidot=1.0, **kwargs)


@pytest.mark.parametrize("module", ["launch_vehicle", "launch_vehicle_plots",
                                    "launch_vehicle_response"])
@pytest.mark.slow
def test_docstring_examples_run(module):
    mod = importlib.import_module(f"appdyn.problems.stability.{module}")
    result = doctest.testmod(mod, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.failed == 0 and result.attempted > 0
