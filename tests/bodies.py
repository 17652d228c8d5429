"""Bodies the tests share (constants, for module-level use; `tests/conftest.py` serves them as
fixtures too).

``GEMINI``: the Gemini capsule's inertia about its mass centre in body axes [kg m^2], the
seed's printed example (Sec. 4.4; its principal moments and axes are checked against the
seed in tests/dynamics/test_attitude.py). ``INERTIA_123``: the diagonal inertia
``diag(1, 2, 3)`` [kg m^2] of the small standard rigid body.
"""
import numpy as np

GEMINI = np.array([[4560.7, 31.2, -43.4], [31.2, 4545.0, -270.7], [-43.4, -270.7, 1567.4]])
GEMINI.setflags(write=False)  # shared: a test that needs to change it takes a copy

INERTIA_123 = (1.0, 2.0, 3.0)
