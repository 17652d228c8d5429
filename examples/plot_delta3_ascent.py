"""
The Delta III ascent to GTO
===========================

The four-phase ascent of a Delta III-class launcher to a geosynchronous transfer orbit
(Benson 2005; Betts 2010, GPOPS-II): six and then three solid boosters burn beside the first
stage and are dropped at fixed times, then the first and second stages burn out. The
dynamics are Earth-centred inertial, with a rotating exponential atmosphere and drag; the
five terminal orbital elements are events; the final mass is maximized.
`appdyn.problems.ascent.delta3_ascent` builds the multi-phase problem
(`appdyn.ocp.MultiPhaseProblem`), solves it on 8 Radau intervals of degree 4 per phase,
refines every phase's mesh until the estimated error is below 1e-9 and checks the answer:
the final orbit recomputed from the final state, each phase re-simulated. It takes about
3 s (the full mesh; no coarsening needed here).
"""
import matplotlib.pyplot as plt

from appdyn.problems.ascent import delta3_ascent

d3 = delta3_ascent()
print(d3.summary())
print(f"final mass {d3.final_mass:.6f} kg; Betts (2010): 7529.712412 kg, "
      f"difference {d3.final_mass - 7529.712412:+.1e} kg")
assert d3.success and abs(d3.final_mass - 7529.712412) < 1e-3

# %%
# Altitude, speed, mass, thrust direction, dynamic pressure and flight-path angle, the
# stagings marked.
fig = plt.figure(figsize=(10, 8))
d3.plot(fig)
