"""Basilisk's reaction-wheel detumble through a scene, against Basilisk itself.

The peer is Basilisk's ``examples/scenarioAttitudeFeedbackRW.py``, run in bsk 2.12.1 by
``bench/peers/basilisk_rw.py`` (its own venv), which wrote ``tests/data/basilisk_rw_scenario.csv``
(101 records, t = 0, 6, ..., 600 s; the header gives the parameters the bsk objects hold).

The vehicle
-----------
Basilisk: a hub of 750 kg with ``I = diag(900, 800, 600)`` kg m^2 about its mass centre B, and
three Honeywell HR16 wheels of 50 N m s on the body axes (``simIncludeRW``: ``Omega_max`` =
6000 rpm, ``Js = 50 / Omega_max`` = 0.0796 kg m^2, ``Jt = Jg = Js / 2``, 9 kg, ``u_max`` =
0.2 N m), balanced, RW3 placed at ``rWB_B = (0.5, 0.5, 0.5)`` m. The brief expected RW3's 9 kg
to shift the mass centre and the wheels' transverse moments to add to the hub; bsk 2.12.1 adds
neither: a balanced wheel gives the spacecraft no mass properties (its ``scMassOutMsg``, in the
CSV header, is 750 kg, ``c_B = 0``, ``diag(900, 800, 600)`` about B), so ``rWB_B`` does not
enter, and the wheels act only through the back-substitution terms ``matrixD -= Js g g^T``,
``vecRot -= g u + Js Omega w x g``. With ``I_sc = diag(900, 800, 600)`` that is

    (I_sc - sum Js g g^T) w' = -w x (I_sc w + sum Js Omega g) - sum u g,  Js (g.w' + Omega') = u,

the equations of a vehicle whose total inertia, wheels included (their spin moments too), is
``I_sc``, with total angular momentum ``I_sc w + sum Js Omega g``. `ReactionWheels` carries the
axial moments itself (a wheel's momentum ``Js (g.w + W) g``; "the rest is the hub's"), so the
scene's hub is

    I_hub = I_sc - Js (x x^T + y y^T + z z^T) = diag(900, 800, 600) - Js * 1,

and its momentum ``I_hub w + sum Js (g.w + W) g = I_sc w + sum Js W g`` is bsk's. The test
checks that against the angular momentum bsk logged (``totRotAngMomPntC_N``) at its own states.
The orbit (Earth point-mass gravity, no gravity-gradient effector) acts on the translation
only: the attitude sees no torque, so the scene is attitude-only.

The flight software
-------------------
``inertial3D`` (``sigma_R0N = 0``, so ``sigma_BR = sigma_BN``, ``omega_RN = 0``) ->
``mrpFeedback`` (K = 3.5, P = 30, Ki = -1: the integral term is off) computes
``Lr = K sigma + P omega - [omega_RN + Ki z] x (I_sc w + sum Js (g.w + Omega) g)
+ I_sc (w x omega_RN - omega_RN') + L_known`` (controlLawType 0) and requests ``-Lr``: with
the inertial reference the gyroscopic term is zero, the request ``-(K sigma + P w)``.
``rwMotorTorque`` maps a request ``L`` on the wheels by ``us = -[C Gs]^T ([C Gs][C Gs]^T)^-1 C L``
(C, Gs = 1 here: ``us = K sigma + P w``); the wheel effector saturates it at ``u_max``. The
flight software runs every 0.1 s on the state at that instant and the wheels apply its output
over the next step (the effector, called first, reads the command written one step before):
a zero-order hold. The recorded ``us`` at ``t_k`` is the command computed at ``t_k``, the
recorded ``u`` the torque applied over ``[t_k - 0.1, t_k]`` (zero at t = 0). bsk integrates with
RK4 at 0.1 s, on MRPs (switched to the shadow set at ``|sigma| > 1``) where the scene has the
quaternion (``sigma = q_vec / (1 + q4)`` with ``q4 >= 0``).

Measured (our RK4 at 0.1 s, 6000 `simulate` calls, against bsk): sigma 1.8e-14, omega 1.4e-15
rad/s, Omega 2.6e-11 rad/s (|Omega| up to 305 rad/s); commanded and applied motor torques
8e-14 N m; our momentum at bsk's states against bsk's logged momentum 1.1e-14 N m s (|H| =
21.5 N m s). RK4's truncation error here (our RK4 against our rk8, 4 steps per 0.1 s) is of
the same size: sigma 2.6e-14, omega 4.0e-15, Omega 3.6e-11 -- the step resolves the motion
(|w| dt < 4e-3 rad, the wheels' gyroscopic rates |Js Omega| / I < 0.03 rad/s), so the two RK4s
on their two attitude coordinates agree to the round-off accumulated over 6000 steps. Asserted:
each block to ``1e-12 * max |block|`` (3e-13, 3e-14, 3e-10: 12x to 22x above what is measured),
RK4's own truncation error below the same bound (what makes it "what the integrators allow");
torques to 1e-12 N m; the momentum at bsk's states to 1e-13 relative; the saturation active
(at least one wheel at +-u_max for 152 s of the 600); total inertial angular momentum along our
run constant to 1e-10 N m s (measured 2.7e-12; the motor torques are internal). The check
discriminates: the hub taken as ``I_sc`` (axial moments counted twice) is off by 4.7e-5 in
sigma, 2.8e-6 rad/s, 0.06 rad/s; the brief's guess (wheel masses, RW3's offset and transverse
moments added about the shifted mass centre) by 3.6e-3, 2.2e-4 rad/s, 4.2 rad/s.
"""
import re
from pathlib import Path

import numpy as np
import pytest

from appdyn.dynamics import simulate
from appdyn.dynamics.attitude import dcm_from_quat
from appdyn.dynamics.scene import ReactionWheels, RigidHub, Scene

DATA = Path(__file__).resolve().parents[2] / "data" / "basilisk_rw_scenario.csv"
RPM = 2.0 * np.pi / 60.0
MAX_MOMENTUM, OMEGA_MAX, U_MAX = 50.0, 6000.0 * RPM, 0.2  # HR16 (simIncludeRW), SI
JS = MAX_MOMENTUM / OMEGA_MAX  # [kg m^2]
I_SC = np.diag([900.0, 800.0, 600.0])  # bsk's spacecraft inertia about B (= the FSW's)
AXES = np.eye(3)  # Gs: wheel spin axes, one per column
K, P = 3.5, 30.0
DT, N_STEPS, EVERY = 0.1, 6000, 60  # control period [s], steps, steps per record
SIGMA0, OMEGA0, WHEELS0 = [0.1, 0.2, -0.3], [0.001, -0.01, 0.03], np.array([100, 200, 300]) * RPM


# ----------------------------------------------------------------------------- the peer's data
def load():
    """The CSV as {column: array (101,)} and its header text."""
    text = DATA.read_text()
    comments = [line[2:] for line in text.splitlines() if line.startswith("#")]
    names = comments[-1].split(",")
    values = np.loadtxt(DATA, delimiter=",", comments="#")
    return {name: values[:, k] for k, name in enumerate(names)}, "\n".join(comments[:-1])


def block(cols, name):
    """Columns ``name1..name3`` as an array (101, 3)."""
    return np.column_stack([cols[f"{name}{k}"] for k in (1, 2, 3)])


# ------------------------------------------------------------------------------ conversions
def quat_from_mrp(sigma):
    """Scalar-last quaternion (inertial -> body) of the MRP ``sigma``: ``q4 >= 0`` when
    ``|sigma| <= 1``."""
    sigma = np.asarray(sigma, float)
    s2 = sigma @ sigma
    return np.r_[2.0 * sigma, 1.0 - s2] / (1.0 + s2)


def mrp_from_quat(q):
    """MRP ``q_vec / (1 + q4)`` of the sign with ``q4 >= 0`` (the set with ``|sigma| <= 1``,
    which Basilisk keeps by switching to the shadow set)."""
    q = np.asarray(q, float)
    q = q if q[3] >= 0.0 else -q
    return q[:3] / (1.0 + q[3])


def dcm_from_mrp(sigma):
    """Schaub and Junkins' ``[BN](sigma)`` (inertial -> body), Basilisk's MRP2C."""
    s = np.asarray(sigma, float)
    s2 = s @ s
    S = np.array([[0.0, -s[2], s[1]], [s[2], 0.0, -s[0]], [-s[1], s[0], 0.0]])
    return np.eye(3) + (8.0 * S @ S - 4.0 * (1.0 - s2) * S) / (1.0 + s2) ** 2


# --------------------------------------------------------------------------- the flight software
def mrp_feedback(sigma, omega, wheel_speeds, omega_r=np.zeros(3)):
    """mrpFeedback's torque request [N m] (controlLawType 0, integral off, ``domega_RN = 0``,
    no known torque): ``-(K sigma + P (w - omega_r) - omega_r x H + I_sc (w x omega_r))``
    with ``H = I_sc w + Gs Js (Gs^T w + Omega)``; ``omega_r = omega_RN`` is zero here."""
    H = I_SC @ omega + AXES @ (JS * (AXES.T @ omega + wheel_speeds))
    Lr = K * sigma + P * (omega - omega_r) - np.cross(omega_r, H) + I_SC @ np.cross(omega, omega_r)
    return -Lr


def rw_motor_torque(request):
    """rwMotorTorque on the three body axes: ``us = -Gs^T (Gs Gs^T)^-1 request`` [N m]."""
    return -AXES.T @ np.linalg.solve(AXES @ AXES.T, request)


def commanded(x):
    """The motor torques the flight software commands at state ``x`` (before saturation)."""
    return rw_motor_torque(mrp_feedback(mrp_from_quat(x[:4]), x[4:7], x[7:10]))


# ------------------------------------------------------------------------------------ our run
def scene():
    return Scene(RigidHub(I_SC - JS * AXES @ AXES.T), ReactionWheels(AXES, JS, u_max=U_MAX))


def initial_state():
    return scene().state(q=quat_from_mrp(SIGMA0), w=OMEGA0, wheels=WHEELS0)


def run(method, steps):
    """The sampled loop: every 0.1 s the law on the state, held over the step, saturated.
    Returns the states (6001, 10) and the applied torques (6000, 3)."""
    model = scene().model()
    x = initial_state()
    xs, taus = [x], []
    for k in range(N_STEPS):
        tau = np.clip(commanded(x), -U_MAX, U_MAX)
        res = simulate(model, x, [k * DT, (k + 1) * DT], u=tau, hold="zoh", method=method,
                       steps=steps)
        assert res.success, res.message
        x = res.x[:, -1]
        xs.append(x)
        taus.append(tau)
    return np.array(xs), np.array(taus)


@pytest.fixture(scope="module")
def peer():
    return load()


@pytest.fixture(scope="module")
def rk4():
    return run("rk4", 1)


@pytest.fixture(scope="module")
def rk8():
    return run("rk8", 4)


def blocks(xs):
    """sigma, omega, Omega at the records (every 6 s), each (101, 3)."""
    rec = xs[::EVERY]
    return {"sigma": np.array([mrp_from_quat(q) for q in rec[:, :4]]), "omega": rec[:, 4:7],
            "Omega": rec[:, 7:10]}


# ------------------------------------------------------------------------------------- tests
def test_the_data_holds_the_parameters_the_test_assumes(peer):
    cols, header = peer
    assert "bsk) 2.12.1" in header
    for k in (1, 2, 3):
        line = re.search(rf"^RW{k} .*$", header, re.M).group(0)
        value = {key: float(v) for key, v in re.findall(r"(\w+) = (-?[\d.e+-]+)", line)}
        assert value["Js"] == pytest.approx(JS, rel=1e-15)
        assert value["u_max"] == U_MAX and value["Omega_max"] == pytest.approx(OMEGA_MAX, rel=1e-15)
        assert value["Omega"] == pytest.approx(WHEELS0[k - 1], rel=1e-15)
        assert value["fCoulomb"] == value["cViscous"] == value["fStatic"] == value["u_min"] == 0.0
    assert "massSC = 750.0 kg, c_B = [0.0, 0.0, 0.0]" in header
    assert "ISC_PntB_B = [900.0, 0.0, 0.0, 0.0, 800.0, 0.0, 0.0, 0.0, 600.0]" in header
    np.testing.assert_allclose(cols["t"], np.arange(101) * EVERY * DT, rtol=0, atol=1e-9)
    np.testing.assert_allclose(block(cols, "sigma")[0], SIGMA0, rtol=0, atol=1e-16)
    # the wheel speed limit is never reached, so bsk's speed-limit logic never acts
    assert np.abs(block(cols, "Omega")).max() < 0.5 * OMEGA_MAX


def test_mrp_conversion_is_the_rotation_basilisk_means():
    rng = np.random.default_rng(3)
    for sigma in [np.array(SIGMA0), *rng.uniform(-0.55, 0.55, size=(20, 3))]:  # |sigma| < 1
        q = quat_from_mrp(sigma)
        np.testing.assert_allclose(dcm_from_quat(q), dcm_from_mrp(sigma), rtol=0, atol=1e-15)
        np.testing.assert_allclose(mrp_from_quat(q), sigma, rtol=0, atol=4e-16)
        np.testing.assert_allclose(mrp_from_quat(-q), sigma, rtol=0, atol=4e-16)  # q ~ -q
        shadow = -sigma / (sigma @ sigma)  # the same rotation, |shadow| > 1
        np.testing.assert_allclose(dcm_from_mrp(shadow), dcm_from_mrp(sigma), rtol=0, atol=1e-15)
        np.testing.assert_allclose(mrp_from_quat(quat_from_mrp(shadow)), sigma, rtol=0,
                                   atol=1e-15)


def test_scene_momentum_is_basilisks_at_basilisks_states(peer):
    """The inertia derivation: our ``momentum_inertial`` at bsk's (sigma, w, Omega) is the
    total angular momentum bsk logged, 1e-13 relative."""
    cols, _ = peer
    model = scene().model()
    xs = np.array([scene().state(q=quat_from_mrp(s), w=w, wheels=W) for s, w, W in
                   zip(block(cols, "sigma"), block(cols, "omega"), block(cols, "Omega"))])
    H = model.invariant("momentum_inertial", xs.T).T
    H_bsk = block(cols, "H")
    np.testing.assert_allclose(H, H_bsk, rtol=0, atol=1e-13 * np.abs(H_bsk).max())


@pytest.mark.slow
def test_trajectory_matches_basilisk_to_round_off(peer, rk4, rk8):
    cols, _ = peer
    ours, reference = blocks(rk4[0]), blocks(rk8[0])
    for name in ("sigma", "omega", "Omega"):
        bsk = block(cols, name)
        tol = 1e-12 * np.abs(bsk).max()
        truncation = np.abs(ours[name] - reference[name]).max()  # RK4's own error here
        assert truncation < tol, (name, truncation, tol)
        np.testing.assert_allclose(ours[name], bsk, rtol=0, atol=tol, err_msg=name)


@pytest.mark.slow
def test_motor_torques_match_basilisk(peer, rk4):
    cols, _ = peer
    xs, taus = rk4
    us = np.array([commanded(x) for x in xs[::EVERY]])
    np.testing.assert_allclose(us, block(cols, "us"), rtol=0, atol=1e-12)
    applied = block(cols, "u")
    np.testing.assert_array_equal(applied[0], 0.0)  # nothing applied before the first step
    np.testing.assert_allclose(taus[EVERY - 1::EVERY], applied[1:], rtol=0, atol=1e-12)
    saturated = np.isclose(np.abs(taus), U_MAX, rtol=0, atol=1e-15).any(axis=1)
    assert saturated.sum() * DT > 60.0  # the detumble saturates the wheels for over a minute
    assert np.abs(applied).max() == U_MAX


@pytest.mark.slow
def test_inertial_momentum_is_conserved_along_our_run(rk4):
    xs, _ = rk4
    H = scene().model().invariant("momentum_inertial", xs.T)
    drift = np.abs(H - H[:, :1]).max()
    assert drift < 1e-10, drift
