"""Basilisk peer of the reaction-wheel detumble: writes ``tests/data/basilisk_rw_scenario.csv``.

Runs in its own venv, with pytest (bsk's ``unitTestSupport``, which ``simIncludeRW`` imports,
imports it)::

    python3 -m venv /work/venv-bsk && /work/venv-bsk/bin/pip install bsk pytest

    /work/venv-bsk/bin/python bench/peers/basilisk_rw.py [OUT.csv]

The set-up is that of Basilisk's ``examples/scenarioAttitudeFeedbackRW.py`` (balanced wheels,
no jitter, no voltage interface), written again for the bsk 2.x module API: a 750 kg hub with
``I = diag(900, 800, 600)`` kg m^2 about its mass centre, three Honeywell HR16 wheels (50 N m s;
axes x, y, z; 100, 200, 300 RPM; the third at ``rWB_B = (0.5, 0.5, 0.5)`` m), Earth point-mass
gravity on an orbit of a = 10 000 km (no gravity-gradient effector: the orbit does not act on
the attitude), ``inertial3D`` (sigma_R0N = 0) -> ``attTrackingError`` -> ``mrpFeedback``
(K = 3.5, P = 30, Ki = -1: no integral; wheel speeds fed back) -> ``rwMotorTorque`` (the three
body axes) -> the wheels' motor command; one task at 0.1 s (dynamics RK4 and flight software),
10 min, recorders every 6 s (101 rows, t = 0 ... 600 s).

bsk 2.12.1 gives balanced wheels no mass properties: the spacecraft it assembles is the hub
alone (750 kg, mass centre at B, ``diag(900, 800, 600)`` about B, written in the header), so
that inertia stands for the whole vehicle with the wheels, their spin moments included, and
RW3's ``rWB_B`` does not enter the dynamics. The wheels act through
``Js (gsHat . omega' + Omega') = u`` only.

Columns: ``t`` [s]; ``sigma1..3`` (MRP of the body frame B relative to N, from the spacecraft
state message); ``omega1..3`` [rad/s] (omega_BN in B); ``Omega1..3`` [rad/s] (wheel speeds
relative to the hub); ``us1..3`` [N m] (the commanded motor torques rwMotorTorque wrote at
``t``, before the wheels' saturation); ``u1..3`` [N m] (the torques the wheels applied over the
step ending at ``t``, saturated at u_max); ``H1..3`` [N m s] (the spacecraft's total rotational
angular momentum about its mass centre, inertial components). The header comment lines
(``#``) give the bsk version and the parameters the bsk objects hold (Js, Jt, Jg, mass, u_max,
Omega_max, the spacecraft mass and inertia about B that bsk assembles).
"""
import sys
from pathlib import Path

import numpy as np
from Basilisk import __version__ as BSK_VERSION
from Basilisk.architecture import messaging
from Basilisk.fswAlgorithms import attTrackingError, inertial3D, mrpFeedback, rwMotorTorque
from Basilisk.simulation import reactionWheelStateEffector, simpleNav, spacecraft
from Basilisk.utilities import (SimulationBaseClass, macros, orbitalMotion, simIncludeGravBody,
                                simHelpers, simIncludeRW)

OUT = Path(__file__).resolve().parents[2] / "tests" / "data" / "basilisk_rw_scenario.csv"
I_HUB = [900.0, 0.0, 0.0, 0.0, 800.0, 0.0, 0.0, 0.0, 600.0]
GAINS = dict(K=3.5, P=30.0, Ki=-1.0)
SIGMA0, OMEGA0 = [0.1, 0.2, -0.3], [0.001, -0.01, 0.03]
WHEELS = (([1, 0, 0], 100.0, None), ([0, 1, 0], 200.0, None), ([0, 0, 1], 300.0, [0.5, 0.5, 0.5]))


def floats(a):
    """A flat list of Python floats (their repr round-trips)."""
    return [float(v) for v in np.ravel(a)]


def wheel_line(k, w):
    """Header line of wheel ``k``: the parameters the bsk RW object holds (before the run)."""
    names = ("Js", "Jt", "Jg", "mass", "u_max", "u_min", "Omega_max", "Omega", "fCoulomb",
             "cViscous", "fStatic")
    values = ", ".join(f"{name} = {float(getattr(w, name))!r}" for name in names)
    return (f"RW{k + 1} (SI units: kg m^2, kg, N m, rad/s): gsHat_B = {floats(w.gsHat_B)}, "
            f"rWB_B = {floats(w.rWB_B)} m, {values}")


def run():
    """Run the scenario; returns (columns dict, header lines)."""
    sim = SimulationBaseClass.SimBaseClass()
    dt, t_end = macros.sec2nano(0.1), macros.min2nano(10.0)
    sim.CreateNewProcess("proc").addTask(sim.CreateNewTask("task", dt))

    sc = spacecraft.Spacecraft()
    sc.ModelTag = "bsk-Sat"
    sc.hub.mHub = 750.0
    sc.hub.r_BcB_B = [[0.0], [0.0], [0.0]]
    sc.hub.IHubPntBc_B = simHelpers.np2EigenMatrix3d(I_HUB)
    sim.AddModelToTask("task", sc, 1)
    grav = simIncludeGravBody.gravBodyFactory()
    earth = grav.createEarth()
    earth.isCentralBody = True
    grav.addBodiesTo(sc)

    factory = simIncludeRW.rwFactory()
    for axis, rpm, r in WHEELS:
        extra = {} if r is None else {"rWB_B": r}
        factory.create("Honeywell_HR16", axis, maxMomentum=50.0, Omega=rpm,
                       RWModel=messaging.BalancedWheels, **extra)
    wheels = reactionWheelStateEffector.ReactionWheelStateEffector()
    wheels.ModelTag = "RW_cluster"
    factory.addToSpacecraft(sc.ModelTag, wheels, sc)
    sim.AddModelToTask("task", wheels, 2)

    nav = simpleNav.SimpleNav()
    sim.AddModelToTask("task", nav)
    guid = inertial3D.inertial3D()
    guid.sigma_R0N = [0.0, 0.0, 0.0]
    sim.AddModelToTask("task", guid)
    err = attTrackingError.attTrackingError()
    sim.AddModelToTask("task", err)
    ctrl = mrpFeedback.mrpFeedback()
    ctrl.K, ctrl.P, ctrl.Ki = GAINS["K"], GAINS["P"], GAINS["Ki"]
    ctrl.integralLimit = 2.0 / ctrl.Ki * 0.1
    sim.AddModelToTask("task", ctrl)
    motor = rwMotorTorque.rwMotorTorque()
    motor.controlAxes_B = [1, 0, 0, 0, 1, 0, 0, 0, 1]
    sim.AddModelToTask("task", motor)

    every = simHelpers.samplingTime(t_end, dt, 100)
    logs = dict(state=sc.scStateOutMsg.recorder(every), mass=sc.scMassOutMsg.recorder(every),
                us=motor.rwMotorTorqueOutMsg.recorder(every),
                speeds=wheels.rwSpeedOutMsg.recorder(every))
    rw_logs = [msg.recorder(every) for msg in wheels.rwOutMsgs]
    for rec in (*logs.values(), *rw_logs):
        sim.AddModelToTask("task", rec)
    h_log = sc.logger("totRotAngMomPntC_N", every)
    sim.AddModelToTask("task", h_log)

    veh = messaging.VehicleConfigMsgPayload()
    veh.ISCPntB_B = I_HUB
    veh_msg = messaging.VehicleConfigMsg().write(veh)
    rw_params = factory.getConfigMessage()

    mu = earth.mu
    oe = orbitalMotion.ClassicElements()
    oe.a, oe.e, oe.i = 1.0e7, 0.01, 33.3 * macros.D2R
    oe.Omega, oe.omega, oe.f = 48.2 * macros.D2R, 347.8 * macros.D2R, 85.3 * macros.D2R
    sc.hub.r_CN_NInit, sc.hub.v_CN_NInit = orbitalMotion.elem2rv(mu, oe)
    sc.hub.sigma_BNInit = [[s] for s in SIGMA0]
    sc.hub.omega_BN_BInit = [[w] for w in OMEGA0]

    nav.scStateInMsg.subscribeTo(sc.scStateOutMsg)
    err.attNavInMsg.subscribeTo(nav.attOutMsg)
    err.attRefInMsg.subscribeTo(guid.attRefOutMsg)
    ctrl.guidInMsg.subscribeTo(err.attGuidOutMsg)
    ctrl.vehConfigInMsg.subscribeTo(veh_msg)
    ctrl.rwParamsInMsg.subscribeTo(rw_params)
    ctrl.rwSpeedsInMsg.subscribeTo(wheels.rwSpeedOutMsg)
    motor.rwParamsInMsg.subscribeTo(rw_params)
    motor.vehControlInMsg.subscribeTo(ctrl.cmdTorqueOutMsg)
    wheels.rwMotorCmdInMsg.subscribeTo(motor.rwMotorTorqueOutMsg)

    header = [f"Basilisk (bsk) {BSK_VERSION}: examples/scenarioAttitudeFeedbackRW.py set-up, "
              "balanced wheels; written by bench/peers/basilisk_rw.py",
              f"hub: mHub = 750 kg, IHubPntBc_B = diag(900, 800, 600) kg m^2, r_BcB_B = 0; "
              f"sigma_BN(0) = {SIGMA0}, omega_BN_B(0) = {OMEGA0} rad/s",
              f"mrpFeedback K = {GAINS['K']}, P = {GAINS['P']}, Ki = {GAINS['Ki']} (off), "
              "controlLawType 0, wheel speeds fed back; rwMotorTorque on the 3 body axes; "
              "dt = 0.1 s (RK4 and FSW), 600 s"]
    header += [wheel_line(k, w) for k, w in enumerate(factory.rwList.values())]

    sim.InitializeSimulation()
    sim.ConfigureStopTime(t_end)
    sim.ExecuteSimulation()

    n = len(WHEELS)  # the speed and torque messages hold arrays of a fixed maximal length
    state = logs["state"]
    cols = {"t": state.times() * macros.NANO2SEC}
    blocks = {"sigma": np.array(state.sigma_BN), "omega": np.array(state.omega_BN_B),
              "Omega": np.array(logs["speeds"].wheelSpeeds)[:, :n],
              "us": np.array(logs["us"].motorTorque)[:, :n],
              "u": np.column_stack([np.array(rec.u_current) for rec in rw_logs]),
              "H": np.array(h_log.totRotAngMomPntC_N)}
    for name, block in blocks.items():
        for k in range(3):
            cols[f"{name}{k + 1}"] = block[:, k]

    mass = logs["mass"]
    header.append(f"bsk spacecraft mass properties (scMassOutMsg, t = 0; the balanced wheels add "
                  f"none): massSC = {float(mass.massSC[0])!r} kg, c_B = {floats(mass.c_B[0])} m, "
                  f"ISC_PntB_B = {floats(mass.ISC_PntB_B[0])} kg m^2")
    return cols, header


def main():
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else OUT
    cols, header = run()
    out.parent.mkdir(parents=True, exist_ok=True)
    data = np.column_stack(list(cols.values()))
    np.savetxt(out, data, delimiter=",", fmt="%.17g", header="\n".join(header + [",".join(cols)]))
    print(f"wrote {out}: {data.shape[0]} rows x {data.shape[1]} columns (bsk {BSK_VERSION})")


if __name__ == "__main__":
    main()
