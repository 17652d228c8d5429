"""Test-suite set-up: the compile cache, the Hypothesis profiles and the shared fixtures.

Compile cache
-------------
Compiled libraries go to a temporary compile cache, never to the user's
(`appdyn.dynamics.diskcache`). ``APPDYN_CACHE_DIR`` is set, for this process and every
subprocess a test starts, to a directory made for the session and removed at its end;
``APPDYN_TEST_CACHE_DIR`` names one to keep instead (e.g. to reuse the compiled libraries
across local runs). Under pytest-xdist (``make test JOBS=auto``) the workers share the
controller's directory (the compile cache is safe across processes) and the controller
removes it.

Hypothesis profiles
-------------------
``HYPOTHESIS_PROFILE`` selects one; the default is ``ci`` when ``CI`` is set (CI's run),
else ``dev``. Both have no deadline (the machines are shared and loaded: a deadline there
measures the neighbours). ``ci``: Hypothesis' default 100 examples, no example database (a
fresh clone has none), the reproduction blob printed on failure. ``dev``: 25 examples and
the local database (a failure found once is replayed first). A test's own ``@settings``
(most give ``max_examples``) overrides the profile.

Markers
-------
``slow`` (registered in pyproject.toml): the long cases. ``make quick`` (``pytest -m "not
slow"``) leaves them out; ``make test`` and CI run everything.

Fixtures
--------
``gemini_inertia``, ``gemini``, ``rigid_123`` (the standard bodies, see `tests.bodies`) and
``hypothesis_global_constants``.
"""
import os
import shutil
import tempfile

import numpy as np
import pytest
from hypothesis import settings

from tests.bodies import GEMINI, INERTIA_123

_WORKER = os.environ.get("PYTEST_XDIST_WORKER")
_KEEP = os.environ.get("APPDYN_TEST_CACHE_DIR")
if _WORKER and os.environ.get("APPDYN_CACHE_DIR"):  # the controller's (inherited)
    _KEEP = _SESSION_DIR = os.environ["APPDYN_CACHE_DIR"]
else:
    _SESSION_DIR = _KEEP or tempfile.mkdtemp(prefix="appdyn-test-cache-")
os.environ["APPDYN_CACHE_DIR"] = _SESSION_DIR
os.environ.pop("APPDYN_DISK_CACHE", None)

settings.register_profile("ci", deadline=None, database=None, print_blob=True)
settings.register_profile("dev", deadline=None, max_examples=25)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci" if os.environ.get("CI") else "dev"))


def pytest_sessionfinish(session, exitstatus):
    """Remove the session's compile cache (unless ``APPDYN_TEST_CACHE_DIR`` named it)."""
    if not _KEEP:
        shutil.rmtree(_SESSION_DIR, ignore_errors=True)


@pytest.fixture
def gemini_inertia():
    """The Gemini capsule's inertia [kg m^2], shape (3, 3) (a copy the test may change)."""
    return np.array(GEMINI)


@pytest.fixture
def gemini():
    """``rigid_body(GEMINI)``: the Gemini capsule as a torque-driven rigid body."""
    from appdyn.dynamics import rigid_body
    return rigid_body(GEMINI)


@pytest.fixture
def rigid_123():
    """``rigid_body([1.0, 2.0, 3.0])``: the small standard rigid body."""
    from appdyn.dynamics import rigid_body
    return rigid_body(list(INERTIA_123))


@pytest.fixture
def hypothesis_global_constants():
    """Draws independent of the code base's literals.

    Hypothesis (6.1xx) mixes constants it mines from every loaded local module (appdyn's
    own files) into its draws, so a new float literal anywhere, or another set of modules
    loaded by earlier tests, changes the draws of a seeded test. Within this fixture only
    Hypothesis' global constants are used; the constant cache is cleared before and after.
    """
    from hypothesis.internal.conjecture import providers
    real = providers._get_local_constants
    providers._get_local_constants = providers.Constants
    providers.CONSTANTS_CACHE.cache.clear()
    yield
    providers._get_local_constants = real
    providers.CONSTANTS_CACHE.cache.clear()
