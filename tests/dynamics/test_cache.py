"""The one cache (`dynamics.cache`) and its deterministic jit policy."""
import shutil
import tempfile
import threading

import numpy as np
import pytest

from appdyn import dynamics
from appdyn.dynamics import cache, rigid_body, simulate

HAVE_CC = shutil.which("gcc") is not None or shutil.which("cc") is not None
X0 = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 0.1, 0.8])


def test_get_builds_once_and_info_counts():
    calls = []

    def build():
        calls.append(1)
        return object()

    key = ("test-entry", 1)
    first = cache.get(key, build)
    assert cache.get(key, build) is first and calls == [1]
    assert cache.contains(key)
    info = cache.info()
    assert info.kinds.get("test-entry") == 1 and info.hits >= 1 and info.entries <= info.maxsize


def test_get_is_thread_safe_one_build_per_key():
    calls = []

    def build():
        calls.append(1)
        return len(calls)

    key = ("test-threads", 2)
    out = []
    threads = [threading.Thread(target=lambda: out.append(cache.get(key, build)))
               for _ in range(8)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert calls == [1] and set(out) == {1}


def test_memoized_model_factory_is_cached_and_cleared():
    a = rigid_body([1.0, 2.0, 3.0])
    assert rigid_body([1.0, 2.0, 3.0]) is a
    dynamics.clear_caches()
    assert rigid_body([1.0, 2.0, 3.0]) is not a
    assert cache.info().entries >= 1


def test_should_compile_depends_only_on_arguments():
    assert cache.should_compile(True, 0) and not cache.should_compile(False, 1e12)
    assert not cache.should_compile(None, cache.JIT_MIN_WORK - 1)
    assert cache.should_compile(None, cache.JIT_MIN_WORK)
    assert cache.should_compile(None, float("inf"))


@pytest.mark.slow
def test_identical_auto_calls_make_identical_jit_choices():
    """Four identical calls: the same `compiled` flag every time (the old policy compiled on
    the third use of a model) and the same answer."""
    model = rigid_body([1.0, 2.0, 2.5])
    t = np.linspace(0.0, 10.0, 101)
    runs = [simulate(model, X0, t) for _ in range(4)]
    assert len({r.compiled for r in runs}) == 1
    assert all(np.array_equal(r.x, runs[0].x) for r in runs)


@pytest.mark.skipif(not HAVE_CC, reason="no C compiler for the jit")
def test_clear_caches_removes_compiled_files_and_rebuilds(tmp_path, monkeypatch):
    """Compiling leaves no files behind; clear_caches drops the loaded code and rebuilds."""
    # a temp directory of its own: other processes compiling at the same time do not count
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    model = rigid_body([1.0, 2.0, 2.75])
    t = np.linspace(0.0, 1.0, 11)
    first = simulate(model, X0, t, method="rk4", jit=True)
    assert first.compiled and cache.info().compiler is not None
    assert list(tmp_path.iterdir()) == []
    dynamics.clear_caches()
    info = cache.info()
    assert info.entries == 0
    again = simulate(model, X0, t, method="rk4", jit=True)
    assert again.compiled and np.allclose(again.x, first.x, rtol=0, atol=1e-14)


# ------------------------------------------------------------ memoize_values (wrappers)
def test_memoize_values_keys_by_value_before_the_checks():
    """A repeated wrapper call is one cache hit (no checks, no scene): equal values in a
    list, a tuple or an array are one key; a different value is a miss."""
    import numpy as np

    from appdyn.dynamics import cache as c
    from appdyn.dynamics import rigid_body

    first = rigid_body([1.0, 2.0, 2.5])
    before = c.info()
    assert rigid_body((1, 2, 2.5)) is first and rigid_body(np.array([1.0, 2.0, 2.5])) is first
    after = c.info()
    assert after.hits == before.hits + 2 and after.misses == before.misses
    assert rigid_body([1.0, 2.0, 2.25]) is not first


def test_memoize_values_never_caches_bad_input_and_keeps_types_apart():
    import numpy as np

    from appdyn.dynamics import cache as c
    from appdyn.dynamics import wheel_spacecraft

    for _ in range(2):   # raised on every call: nothing was cached
        with pytest.raises(ValueError, match="inertia"):
            wheel_spacecraft([1.0, 2.0, -3.0], np.eye(3), 0.05)
    assert c.value_key(True) != c.value_key(1.0) and c.value_key(1) == c.value_key(1.0)
    assert c.value_key([1, 2]) == c.value_key(np.array([1.0, 2.0]))
    for unkeyable in ([True, False], [[1, 2], [3]], object()):
        with pytest.raises(c._Unkeyable):
            c.value_key(unkeyable)
    assert c.value_key(float("nan")) != c.value_key(float("nan"))   # NaN: always a miss


@pytest.mark.skipif(not HAVE_CC, reason="no C compiler: nothing is made")
def test_a_compile_job_is_made_under_the_construction_lock():
    """`compile_ahead` runs outside any build (e.g. from `simulate` in a thread-pool task):
    its job's ``make`` builds CasADi symbols, so the compile holds the construction lock
    while it makes and generates (another thread cannot take the lock meanwhile)."""
    seen = []

    def other_thread_can_lock() -> bool:
        out = []

        def probe():
            got = cache.construction_lock().acquire(blocking=False)
            if got:
                cache.construction_lock().release()
            out.append(got)

        th = threading.Thread(target=probe)
        th.start()
        th.join()
        return out[0]

    def make():
        seen.append(other_thread_can_lock())
        raise RuntimeError("not generated")  # (nothing is compiled)

    job = cache.Job(make, "-O1", lambda path: path)
    out = cache.compile_parallel([job])[0]
    assert isinstance(out, RuntimeError) and "not generated" in str(out)
    assert seen == [False] and other_thread_can_lock()
