"""
Monte Carlo dispersion with a progress bar
==========================================

How far does a spinning spacecraft nutate when its inertia and its initial transverse rate
are uncertain? `appdyn.problems.dispersion.dispersion` draws the inputs (seeded and
reproducible whatever the executor), simulates every sample, and reduces named outputs to
statistics. ``progress(done, total)`` is called as samples finish: here it draws a text
progress bar (in a terminal, ``tqdm`` would do as well).

Each sample is checked against the axisymmetric closed form of the nutation angle,
``theta = atan(I_t |w_t| / (I_a w_3))``, constant in time.
"""
import sys

import matplotlib.pyplot as plt
import numpy as np

from appdyn.problems.dispersion import (Normal, dispersion, nutation_history,
                                        nutation_max, spinner)


class ProgressBar:
    """``progress(done, total)``: a text bar, redrawn every 10 % (on stdout)."""

    def __init__(self, width=40):
        self.width, self.shown = width, -1

    def __call__(self, done, total):
        tenth = 10 * done // total
        if tenth > self.shown:
            self.shown = tenth
            filled = self.width * done // total
            bar = "#" * filled + "." * (self.width - filled)
            sys.stdout.write(f"[{bar}] {done}/{total}\n")


# %%
# 100 samples over 30 s: the spinner's transverse and axial moments [kg m^2] (keywords of
# ``spinner``) and the initial rate ``w1`` [rad/s] (a state of ``x0``) are dispersed.
t = np.linspace(0.0, 30.0, 61)
res = dispersion(spinner, [0, 0, 0, 1, 0.0, 0.0, 1.0], t, samples=100, seed=0,
                 params={"transverse_inertia": Normal(1000.0, 20.0),
                         "axial_inertia": Normal(1500.0, 30.0),
                         "w1": Normal(0.02, 0.004)},
                 outputs={"nutation": nutation_history, "peak": nutation_max},
                 units={"nutation": "rad", "peak": "rad"}, progress=ProgressBar())
print(res.success, res.message)
peak = res.statistics["peak"]
mean, std, p99 = np.degrees([peak.mean, peak.std, peak.percentiles[99.0]])
print(f"peak nutation: mean {mean:.3f} deg, std {std:.3f} deg, 99th percentile {p99:.3f} deg")

# %%
# Every sample against its closed form:
theta = np.arctan2(res.inputs["transverse_inertia"] * np.abs(res.inputs["w1"]),
                   res.inputs["axial_inertia"])
error = np.max(np.abs(res.outputs["nutation"] - theta[:, None]))
print(f"largest difference from the closed form: {error:.1e} rad")
assert res.success and error < 1e-8

# %%
# The library draws the histogram of the peak nutation and the envelope of the nutation
# history (median, percentile band, min-max band).
fig = plt.figure(figsize=(10, 4))
res.plot(fig)
