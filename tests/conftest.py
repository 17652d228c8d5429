"""Test-suite set-up: compiled libraries go to a temporary compile cache, never to the
user's (`appdyn.dynamics.diskcache`).

``APPDYN_CACHE_DIR`` is set, for this process and every subprocess a test starts, to a
directory made for the session and removed at its end; ``APPDYN_TEST_CACHE_DIR`` names one
to keep instead (e.g. to reuse the compiled libraries across local runs).
"""
import os
import shutil
import tempfile

_KEEP = os.environ.get("APPDYN_TEST_CACHE_DIR")
_SESSION_DIR = _KEEP or tempfile.mkdtemp(prefix="appdyn-test-cache-")
os.environ["APPDYN_CACHE_DIR"] = _SESSION_DIR
os.environ.pop("APPDYN_DISK_CACHE", None)


def pytest_sessionfinish(session, exitstatus):
    """Remove the session's compile cache (unless ``APPDYN_TEST_CACHE_DIR`` named it)."""
    if not _KEEP:
        shutil.rmtree(_SESSION_DIR, ignore_errors=True)
