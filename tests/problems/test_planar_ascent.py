"""Pitch-plane ascent (`problems.ascent.planar`) against independent truths: Tsiolkovsky
vertical flight in vacuum over a flat Earth, the re-propagated optimum against its terminal
conditions and path limits (loads recomputed here), the q limit active and monotonic, the
autopilot tracking the pitch program (and the unstable airframe tumbling open loop), and
argument checks."""
import math

import numpy as np
import pytest

from appdyn.dynamics import simulate
from appdyn.problems.ascent import (G0, AscentVehicle, fly_pitch_program,
                                    planar_ascent, planar_model, vertical_rise)
from appdyn.ocp.status import STATUS_SIMULATION, STATUS_TRACKING

TARGET = dict(target_altitude=65e3, target_gamma=math.radians(40.0))
Q_MAX, QA_MAX = 45e3, 2e3


@pytest.fixture(scope="module")
def ascent():
    return planar_ascent(**TARGET, q_max=Q_MAX, qalpha_max=QA_MAX, N=30)


def loads(x, theta, rho0=1.225):
    """q [Pa] and q alpha [Pa rad], written out here."""
    q = 0.5 * rho0 * np.exp(-x[0] / 7200.0) * x[2] ** 2
    return q, q * (theta - x[3])


# ---------------------------------------------------------------- (a) Tsiolkovsky
def test_vertical_flight_in_vacuum_is_tsiolkovsky():
    """rho0 = 0 and a radius of 1e15 m (flat Earth, g = g0 to 1e-11): theta = gamma = 90 deg
    gives V = V0 - g0 t + v_e ln(m0 / m) and the altitude's integral of it."""
    veh = AscentVehicle.default()
    model = planar_model(veh)
    V0, h0, m0 = 30.0, 100.0, veh.mass
    ve, mdot = veh.exhaust_velocity, veh.mass_flow_rate
    t = np.linspace(0.0, 60.0, 61)
    res = simulate(model, [h0, 0.0, V0, math.pi / 2, m0], t, u=[math.pi / 2],
                   p=[0.0, G0, 1e15], method="rk8", steps=20, jit=False)
    assert res.success
    m = m0 - mdot * t
    V = V0 - G0 * t + ve * np.log(m0 / m)
    a = mdot / m0
    s = 1.0 - a * t
    h = h0 + V0 * t - 0.5 * G0 * t ** 2 + ve * (s * np.log(s) - s + 1.0) / a
    assert np.max(np.abs(res["m"] - m)) <= 1e-8 * m0
    assert np.max(np.abs(res["V"] - V)) <= 1e-8 * np.max(V)
    assert np.max(np.abs(res["h"] - h)) <= 1e-8 * np.max(h)
    assert np.max(np.abs(res["gamma"] - math.pi / 2)) <= 1e-12
    # the module's own closed-form rise agrees (V0 = 0, h0 = 0)
    tr, hr, mr = vertical_rise(veh, 50.0)
    assert -ve * math.log(1 - a * tr) - G0 * tr == pytest.approx(50.0, rel=1e-12)
    assert mr == pytest.approx(m0 - mdot * tr, rel=1e-12) and hr > 0


def test_inverse_square_gravity_at_altitude():
    model = planar_model()
    R = 6378145.0
    h = 100e3
    xdot = model.rhs([h, 0.0, 1000.0, math.pi / 2, 1e5], [math.pi / 2], [0.0, G0, R])
    assert xdot[2] == pytest.approx(2e6 / 1e5 - G0 * (R / (R + h)) ** 2, rel=1e-13)


# ---------------------------------------------------------------- (b) the optimum
def test_optimum_repropagated_meets_targets_and_limits(ascent):
    assert ascent.success, ascent.message
    sol = ascent.solution
    prop = sol.propagate(rtol=1e-10, atol=1e-8)  # independent CVODES run of the control
    assert prop.success
    xf = prop.x[:, -1]
    assert abs(xf[0] - TARGET["target_altitude"]) <= 10.0  # m
    assert abs(xf[3] - TARGET["target_gamma"]) <= 2e-4  # rad
    assert xf[4] == pytest.approx(ascent.vehicle.burnout_mass, rel=1e-9)  # burn to depletion
    q, qa = loads(prop.x, sol.u[0])
    assert q.max() <= Q_MAX * 1.01 and np.abs(qa).max() <= QA_MAX * 1.01
    assert ascent.peak_q <= Q_MAX * 1.01 and ascent.peak_qalpha <= QA_MAX * 1.01
    # the burnout speed is below the ideal rocket's and above 2/3 of it
    ideal = ascent.vehicle.exhaust_velocity * math.log(ascent.initial["m"] / xf[4]) + 50.0
    assert 0.66 * ideal < ascent.burnout_speed < ideal
    assert float(ascent.theta(ascent.t[-1])) == pytest.approx(sol.u[0, -1], abs=1e-9)


def test_mass_objective_reaches_target_speed_early():
    res = planar_ascent(**TARGET, q_max=Q_MAX, qalpha_max=QA_MAX, objective="mass",
                        target_speed=2300.0, N=30)
    assert res.success, res.message
    assert abs(res.final["V"] - 2300.0) <= 0.5
    assert res.t[-1] < AscentVehicle.default().burn_time
    assert res.burnout_mass > AscentVehicle.default().burnout_mass


# ---------------------------------------------------------------- (c) active q limit
@pytest.mark.slow
def test_tightening_q_max_lowers_the_optimum(ascent):
    free = planar_ascent(**TARGET, q_max=1e6, qalpha_max=QA_MAX, N=30)
    runs = [planar_ascent(**TARGET, q_max=qm, qalpha_max=QA_MAX, N=30) for qm in (46e3, 44e3)]
    assert free.success and all(r.success for r in runs)
    assert free.peak_q > 46.5e3  # the unlimited optimum exceeds every limit below
    speeds = [free.burnout_speed, runs[0].burnout_speed, ascent.burnout_speed,
              runs[1].burnout_speed]
    assert all(a > b for a, b in zip(speeds, speeds[1:])), speeds
    for r, qm in ((runs[0], 46e3), (ascent, Q_MAX), (runs[1], 44e3)):
        assert r.peak_q == pytest.approx(qm, rel=5e-3)  # active
        sol = r.solution
        assert np.max(sol.multipliers["path"]) > 0 or np.min(sol.multipliers["path"]) < 0


# ---------------------------------------------------------------- (d) tracking
def test_autopilot_tracks_the_pitch_program(ascent):
    tr = fly_pitch_program(ascent)
    assert tr.success, tr.message
    assert tr.max_error < math.radians(2.0) and tr.rms_error < math.radians(0.5)
    assert tr.peak_delta < tr.delta_max == pytest.approx(math.radians(6.0))
    assert abs(tr.final["h"] - ascent.final["h"]) < 500.0
    assert abs(tr.final["gamma"] - ascent.final["gamma"]) < math.radians(0.5)
    assert abs(tr.final["V"] - ascent.final["V"]) < 5.0


def test_open_loop_unstable_airframe_diverges(ascent):
    tr = fly_pitch_program(ascent, gains={"k_theta": 0.0, "k_thetadot": 0.0})
    assert not tr.success
    assert tr.status in (STATUS_TRACKING, STATUS_SIMULATION)
    if tr.status == STATUS_TRACKING:
        assert tr.max_error > math.radians(90.0)


# ---------------------------------------------------------------- (e) arguments
@pytest.mark.parametrize("kwargs, name", [
    (dict(q_max=0.0), "q_max"), (dict(qalpha_max=-1.0), "qalpha_max"),
    (dict(objective="fuel"), "objective"), (dict(N=2), "N"),
    (dict(objective="mass"), "target_speed"), (dict(target_speed=2000.0), "target_speed"),
    (dict(target_gamma=math.radians(95)), "target_gamma"),
    (dict(target_altitude=10.0), "target_altitude"), (dict(kick=0.0), "kick"),
    (dict(initial_speed=1e5), "initial_speed"), (dict(tolerances={"hh": 1.0}), "tolerances"),
])
def test_bad_arguments_name_themselves(kwargs, name):
    args = dict(**TARGET, q_max=Q_MAX, qalpha_max=QA_MAX, N=10) | kwargs
    with pytest.raises(ValueError, match=name):
        planar_ascent(**args)


@pytest.mark.parametrize("kwargs, name", [
    (dict(dt=0.0), "dt"), (dict(gains={"k": 1.0}), "gains"), (dict(error_max=-1.0), "error_max"),
    (dict(delta_max=0.0), "delta_max")])
def test_bad_tracking_arguments(ascent, kwargs, name):
    with pytest.raises(ValueError, match=name):
        fly_pitch_program(ascent, **kwargs)
    with pytest.raises(TypeError, match="ascent"):
        fly_pitch_program(object())
