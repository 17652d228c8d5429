"""
Gain design with a Bode plot
============================

`appdyn.problems.gains.attitude_gains` designs the PD attitude gains of a rigid spacecraft,
``u = -2 kp q_e - kd w``, by collocation: the gains are parameters of one optimal-control
problem over several slews at once, under a per-axis torque limit. The design is verified
by re-simulating every slew (peak torque, settle time) and by the poles of the loop
linearized at the target.

About the target each body axis is a double integrator, ``J_i theta'' = u_i`` with the
error angle ``theta = 2 q_e``, so the loop broken at the torque is
``L_i(s) = (kd s + kp) / (J_i s^2)``. python-control draws its Bode plot and margins; its
closed-loop poles, the roots of ``J_i s^2 + kd s + kp``, must be the design's.
"""
import control
import matplotlib.pyplot as plt
import numpy as np

from appdyn.problems.gains import attitude_gains

inertia = [10.0, 12.0, 8.0]                  # principal moments [kg m^2]
slews = [{"angle": np.radians(60), "axis": [0, 0, 1]},      # designed together
         {"angle": np.radians(30), "axis": [1, 0, 0]}]
design = attitude_gains(inertia, slews, u_max=0.5)         # |u_i| <= 0.5 N m
print(design)
kp, kd = design.gains["kp"], design.gains["kd"]
assert design.success and design.verification["limits_met"]

# %%
# The loop of each axis, its margins, and its closed-loop poles against the design's.
loops = [control.tf([kd, kp], [J, 0.0, 0.0]) for J in inertia]
poles = np.sort_complex(np.concatenate([np.roots([J, kd, kp]) for J in inertia]))
designed = np.sort_complex(np.asarray(design.verification["poles"]))
for J, loop in zip(inertia, loops):
    gm, pm, wg, wp = control.margin(loop)
    print(f"J = {J:4.1f} kg m^2: phase margin {pm:.1f} deg at {wp:.3f} rad/s")
print("closed-loop poles [1/s]:", np.round(poles, 5))
print(f"difference from the design's poles: {np.max(np.abs(poles - designed)):.1e}")
assert np.allclose(poles, designed, rtol=1e-8, atol=1e-10)

# %%
# The Bode plot of the three axes' loops, margins marked. Their phase is the same curve
# (``J_i`` only scales the magnitude), their crossover frequencies differ.
plt.figure(figsize=(8, 6))
bode = control.bode_plot(loops, display_margins=True, label=["axis 1", "axis 2", "axis 3"])
