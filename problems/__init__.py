"""Ready-made jobs on top of `dynamics` and `ocp`: `torque_free` (simulation checked against
the exact solution), `slew` (optimal attitude maneuvers), `stability` (linear stability
reports) and `cli` (the ``appdyn`` command line, the only place that prints or saves)."""
