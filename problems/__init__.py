"""Ready-made jobs on top of `dynamics` and `ocp`: `torque_free` (simulation checked against
the exact solution), `slew` (optimal attitude maneuvers), `stability` (linear stability
reports), `gains` (feedback gains by multi-scenario collocation), `dispersion` (Monte Carlo
runs over drawn inputs) and `cli` (the ``appdyn`` command line, the only place that prints
or saves)."""
