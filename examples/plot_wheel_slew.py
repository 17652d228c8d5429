"""
Reaction-wheel slew under a saturated feedback law
==================================================

A spacecraft with three reaction wheels turns 90 degrees about an oblique axis under a
PD law of your own, written as a CasADi Function with the motor torques clipped to
``tau_max`` by ``fmin``/``fmax``. `closed_loop` puts the law inside the model's
right-hand side, so `simulate` runs the whole loop in its compiled integrator (no Python per
step). The hub feels ``-tau`` for a motor torque ``tau``, so the motors are commanded with
the opposite of the wanted body torque ``L = -kp q_v - kd w``.

The checks: the attitude error settles, the motor torques never exceed the limit, and the
inertial angular momentum of hub plus wheels stays what it was (zero) to round-off — the
wheels only exchange momentum with the hub.
"""
import casadi as ca
import matplotlib.pyplot as plt
import numpy as np

from appdyn.dynamics import attitude as at
from appdyn.dynamics import closed_loop, simulate, wheel_spacecraft

inertia = np.diag([10.0, 12.0, 8.0])         # hub [kg m^2]
model = wheel_spacecraft(inertia, np.eye(3), 0.02)   # body-axis wheels, 0.02 kg m^2
tau_max, kp, kd = 0.05, 0.3, 3.0             # N m, N m/rad (per 2 q_v), N m s/rad

# %%
# The law: the states are ``[q1..q4, w1..w3, W1..W3]``; the target is the identity
# attitude, so the error is the quaternion itself (its vector part, on the short way round).
x = ca.SX.sym("x", model.nx)
q_vec, q4, w = x[0:3], x[3], x[4:7]
wanted = -kp * 2 * ca.sign(q4) * q_vec - kd * w           # body torque [N m]
tau = ca.fmin(ca.fmax(-wanted, -tau_max), tau_max)        # motor torques, saturated
law = ca.Function("saturated_pd", [x], [tau], ["x"], ["u"])
loop = closed_loop(model, law)
print(loop.states, loop.controls)            # the loop has no controls left

# %%
# Start 90 degrees away about an oblique axis, at rest, wheels stopped, and simulate 200 s.
# The saturation puts kinks in the right-hand side, where a method's order drops.
# ``simulate`` finds the ``fmin``/``fmax`` in the loop's CasADi graph, and its default
# ``auto`` integrates such a model by DOP853 with step rejection (the steps crowd at the
# kinks), estimating the global error from runs at tighter local tolerances: ``success``
# means the tolerance was verified. We check it against a run 100 times tighter.
q0 = at.quat_from_axis_angle(np.array([1.0, 1.0, 0.5]) / 1.5, np.radians(90))
x0 = np.r_[q0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
t = np.linspace(0.0, 200.0, 2001)
rtol, atol = 1e-8, 1e-10
res = simulate(loop, x0, t, rtol=rtol, atol=atol, invariants=["momentum_inertial"])
tight = simulate(loop, x0, t, rtol=rtol / 100, atol=atol / 100)
angle = np.degrees(at.rotation_angle(res.x[:4]))
torque = np.array(law.map(t.size)(res.x)).reshape(3, -1)
print(res.success, res.status, res.method, res.message.split(";")[0])
error = np.abs(tight.x - res.x) / (atol + rtol * np.abs(tight.x))
print(f"largest error against the tighter run: {error.max():.1e} of the tolerance")
print(f"error angle: {angle[0]:.1f} deg -> {angle[-1]:.2e} deg after {t[-1]:.0f} s")
print(f"largest motor torque {np.abs(torque).max():.4f} N m (limit {tau_max} N m)")
print("momentum drift [N m s]:", res.invariant_drift["momentum_inertial"])
assert res.success and res.method == "dop853" and error.max() <= 1.0   # verified
assert angle[-1] < 0.01 and np.abs(torque).max() <= tau_max     # settled, within limits
assert np.all(np.abs(res.invariant_drift["momentum_inertial"]) < 1e-10)

# %%
# The torques saturate during the first half of the turn; the wheels absorb the hub's
# momentum and give it back when the body stops.
fig, axes = plt.subplots(2, 2, figsize=(10, 6), sharex=True)
axes[0, 0].plot(t, angle)
axes[0, 0].set_ylabel("error angle [deg]")
axes[0, 1].plot(t, res.x[4:7].T)
axes[0, 1].set_ylabel("body rates [rad/s]")
axes[1, 0].plot(t, torque.T)
axes[1, 0].axhline(tau_max, color="k", ls=":")
axes[1, 0].axhline(-tau_max, color="k", ls=":")
axes[1, 0].set_ylabel("motor torque [N m]")
axes[1, 1].plot(t, res.x[7:10].T)
axes[1, 1].set_ylabel("wheel speed [rad/s]")
for ax in axes[1]:
    ax.set_xlabel("t [s]")
for ax, name in zip(axes[0, 1:].tolist() + axes[1].tolist(), ("w", "tau", "W")):
    ax.legend([f"{name}1", f"{name}2", f"{name}3"], fontsize=8)
fig.tight_layout()
