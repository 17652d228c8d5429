"""The persistent compile cache (`dynamics.diskcache`): a second process loads what the
first compiled; corrupted, foreign or unloadable artifacts are rebuilt, never loaded;
concurrent processes both succeed; the size bound holds; the cache can be turned off.

The truths: the oscillator ``x'' = -c x`` from ``(1, 0)`` is ``cos(sqrt(c) t)``; a compiled
``k x`` evaluates to ``k x``; the compiles and loads counted by `diskcache.info`.
"""
import hashlib
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from appdyn.dynamics import cache, diskcache
from appdyn.problems.cli import main

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.skipif(shutil.which("gcc") is None and shutil.which("cc") is None,
                                reason="no C compiler")

# one simulate of an oscillator (compiled rk8 chunk loop), checked against its closed form;
# prints the cache counts of the process
SCRIPT = """
import json, sys
import casadi as ca
import numpy as np
from appdyn.dynamics import Model, diskcache, simulate
c = float(sys.argv[1])
x, u, p = ca.SX.sym("x", 2), ca.SX.sym("u", 0), ca.SX.sym("p", 0)
f = ca.Function("osc", [x, u, p], [ca.vertcat(x[1], -c * x[0])], ["x", "u", "p"], ["xdot"])
t = np.linspace(0.0, 1.0, 11)
res = simulate(Model(f=f, states=("a", "b"), controls=()), [1.0, 0.0], t, method="rk8",
               steps=4, jit=True)
assert res.compiled and res.success, res.message
err = float(np.max(np.abs(res.x[0] - np.cos(np.sqrt(c) * t))))
print(json.dumps({**diskcache.info()._asdict(), "err": err}))
"""


def run_script(cache_dir, c=1.5, env=None, wait=True):
    full = {**os.environ, "APPDYN_CACHE_DIR": str(cache_dir), **(env or {})}
    proc = subprocess.Popen([sys.executable, "-c", SCRIPT, str(c)], cwd=ROOT, env=full,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    return finish(proc) if wait else proc


def finish(proc):
    out, err = proc.communicate(timeout=600)
    assert proc.returncode == 0, err
    return json.loads(out.strip().splitlines()[-1])


def artifacts(directory):
    return sorted(Path(directory).glob("*.so"))


def verified(library: Path) -> bool:
    """The sidecar names this key and the library's size and hash (an independent check)."""
    meta = json.loads(library.with_suffix(".json").read_text())
    data = library.read_bytes()
    return (meta["key"] == library.stem and meta["size"] == len(data)
            and meta["sha256"] == hashlib.sha256(data).hexdigest())


@pytest.fixture
def disk(tmp_path):
    """This process's compile cache in ``tmp_path`` (restored afterwards)."""
    old = diskcache.configure(directory=tmp_path, enabled=True, max_bytes=None)
    yield tmp_path
    diskcache.configure(**old)


def scaled(k):
    """A compiled ``x -> k x`` (a Function of its own source for each ``k``)."""
    x = ca.SX.sym("x")
    fun = ca.Function("scaled", [x], [k * x])
    return cache.compile_c([fun], "", "-O0", lambda path: ca.external("scaled", path))


def counts():
    info = diskcache.info()
    return np.array([info.hits, info.compiles, info.rejected, info.evicted])


@pytest.mark.slow
def test_a_second_process_loads_what_the_first_compiled(tmp_path):
    first = run_script(tmp_path)
    assert first["compiles"] >= 1 and first["hits"] == 0 and first["err"] < 1e-9
    libraries = artifacts(tmp_path)
    assert len(libraries) == first["compiles"] and all(verified(p) for p in libraries)
    second = run_script(tmp_path)
    assert second["compiles"] == 0 and second["hits"] == first["compiles"]
    assert second["err"] == first["err"]
    assert artifacts(tmp_path) == libraries


@pytest.mark.slow
def test_a_truncated_artifact_is_rebuilt_not_loaded(tmp_path):
    run_script(tmp_path)
    (library,) = artifacts(tmp_path)
    whole = library.read_bytes()
    library.write_bytes(whole[: len(whole) // 2])
    again = run_script(tmp_path)
    assert again["rejected"] == 1 and again["compiles"] == 1 and again["hits"] == 0
    assert again["err"] < 1e-9
    assert artifacts(tmp_path) == [library] and verified(library)


@pytest.mark.slow
def test_a_foreign_artifact_is_rebuilt_not_loaded(tmp_path):
    """The library and sidecar of another model under this model's key."""
    run_script(tmp_path, c=1.5)
    (mine,) = artifacts(tmp_path)
    run_script(tmp_path, c=4.0)
    (other,) = [p for p in artifacts(tmp_path) if p != mine]
    shutil.copy(other, mine)
    shutil.copy(other.with_suffix(".json"), mine.with_suffix(".json"))
    again = run_script(tmp_path, c=1.5)
    assert again["rejected"] == 1 and again["compiles"] == 1 and again["err"] < 1e-9
    assert verified(mine) and verified(other)


def test_a_library_that_does_not_load_is_rebuilt(disk):
    assert float(scaled(3.0)(2.0)) == 6.0
    (library,) = artifacts(disk)
    junk = b"not a shared library" * 100
    library.write_bytes(junk)  # consistent metadata: only loading can tell
    library.with_suffix(".json").write_text(json.dumps(
        {"key": library.stem, "size": len(junk), "sha256": hashlib.sha256(junk).hexdigest()}))
    before = counts()
    assert float(scaled(3.0)(2.0)) == 6.0
    assert list(counts() - before) == [0, 1, 1, 0]
    assert verified(library)


@pytest.mark.slow
def test_two_processes_compiling_at_once_both_succeed(tmp_path):
    procs = [run_script(tmp_path, wait=False) for _ in range(2)]
    results = [finish(p) for p in procs]
    assert all(r["err"] < 1e-9 for r in results)
    assert sum(r["compiles"] + r["hits"] for r in results) == 2
    (library,) = artifacts(tmp_path)
    assert verified(library) and not list(tmp_path.glob(".tmp-*"))


def scaled_job(k, extra=""):
    """The `cache.Job` of a compiled ``x -> k x`` (with the C source ``extra``)."""
    x = ca.SX.sym("x")
    fun = ca.Function("scaled", [x], [k * x])
    return cache.Job(lambda: ([fun], extra), "-O0", lambda path: ca.external("scaled", path),
                     cache.recipe("scaled", fun, extra))


def test_a_compile_started_ahead_is_waited_for_not_repeated(disk):
    job = scaled_job(7.0)
    before = counts()
    cache.compile_ahead([job])
    cache.compile_ahead([job])  # (under way: not started twice)
    assert list(counts() - before) == [0, 1, 0, 0]
    (fun,) = cache.compile_parallel([job])
    assert float(fun(3.0)) == 21.0
    assert list(counts() - before) == [0, 1, 0, 0]
    (library,) = artifacts(disk)
    assert verified(library)
    cache.compile_ahead([job])  # (on disk: nothing to compile)
    (again,) = cache.compile_parallel([job])
    assert float(again(1.0)) == 7.0 and list(counts() - before) == [1, 1, 0, 0]


def test_a_compile_ahead_that_fails_says_why_when_taken(disk):
    job = scaled_job(2.0, extra="this is not C;")
    cache.compile_ahead([job])
    (out,) = cache.compile_parallel([job])
    assert isinstance(out, RuntimeError) and "C compilation of scaled failed" in str(out)
    assert not artifacts(disk)


AHEAD = """
import sys, casadi as ca
from appdyn.dynamics import cache
x = ca.SX.sym("x")
fun = ca.Function("scaled", [x], [sum(x ** k / (k + 1) for k in range(400))])
cache.compile_ahead([cache.Job(lambda: ([fun], ""), "-O2", lambda p: ca.external("scaled", p),
                               cache.recipe("scaled", fun))])
assert cache._AHEAD  # (still compiling when the process ends)
"""


@pytest.mark.slow
def test_an_exit_waits_for_the_compiles_under_way(tmp_path):
    """A process that ends while a compile it started ahead runs leaves the library in
    the cache (the next process compiles nothing) and no scratch directory behind."""
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    env = {**os.environ, "APPDYN_CACHE_DIR": str(tmp_path / "cache"), "TMPDIR": str(scratch)}
    done = subprocess.run([sys.executable, "-c", AHEAD], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    (library,) = artifacts(tmp_path / "cache")
    assert verified(library) and not list(scratch.iterdir())


@pytest.mark.slow
def test_with_the_cache_off_an_exit_stops_the_compiles_under_way(tmp_path):
    """Nothing would keep the library: the compile is stopped, its scratch removed."""
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    env = {**os.environ, "APPDYN_CACHE_DIR": str(tmp_path / "cache"), "TMPDIR": str(scratch),
           "APPDYN_DISK_CACHE": "0"}
    done = subprocess.run([sys.executable, "-c", AHEAD], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert not list(scratch.iterdir()) and not (tmp_path / "cache").exists()


def test_translation_units_compile_at_once_into_one_library(disk):
    """A job's item that is a list of Functions is its own translation unit: compiled
    beside the others, linked into the one library (cached as one), its functions
    declared for the job's C source, which may call them."""
    x = ca.SX.sym("x")
    twice, thrice = ca.Function("twice", [x], [2 * x]), ca.Function("thrice", [x], [3 * x])
    extra = ("double six_times(double x) { const casadi_real* a[1]; casadi_real* r[1]; "
             "casadi_real y; a[0] = &x; r[0] = &y; thrice(a, r, 0, 0, 0); return 2 * y; }\n")

    def load(path):
        import ctypes
        lib = ctypes.CDLL(path)
        lib.six_times.restype, lib.six_times.argtypes = ctypes.c_double, [ctypes.c_double]
        return ca.external("twice", path), ca.external("thrice", path), lib.six_times

    job = cache.Job(lambda: ([twice, [thrice]], extra), "-O0", load,
                    cache.recipe("units", twice, thrice, extra))
    before = counts()
    (two, three, six), = cache.compile_parallel([job])
    assert (float(two(5.0)), float(three(5.0)), six(5.0)) == (10.0, 15.0, 30.0)
    (library,) = artifacts(disk)
    assert verified(library) and list(counts() - before) == [0, 1, 0, 0]


def test_in_process_hits_and_the_key(disk):
    before = counts()
    scaled(5.0)
    scaled(5.0)  # (a second compile of the same source: loaded from disk)
    assert list(counts() - before) == [1, 1, 0, 0]
    key = diskcache.artifact_key(b"int f;", "/usr/bin/gcc", ["-O1"])
    assert key != diskcache.artifact_key(b"int f;", "/usr/bin/gcc", ["-O2"])
    assert key != diskcache.artifact_key(b"int g;", "/usr/bin/gcc", ["-O1"])


def test_eviction_keeps_the_bound_and_drops_the_least_recently_used(disk):
    scaled(2.0)
    (a,) = artifacts(disk)
    scaled(3.0)
    (b,) = [p for p in artifacts(disk) if p != a]
    bound = diskcache.info().size + 64  # room for these two only
    diskcache.configure(max_bytes=bound)
    assert float(scaled(2.0)(1.0)) == 2.0  # a hit: `a` is now the most recently used
    before = counts()
    scaled(7.0)
    info = diskcache.info()
    assert info.size <= bound and info.entries == 2 and list(counts() - before) == [0, 1, 0, 1]
    assert a.exists() and not b.exists()


def test_disabled_writes_nothing(disk, tmp_path):
    diskcache.configure(enabled=False)
    assert diskcache.directory() is None and not diskcache.enabled()
    before = counts()
    assert float(scaled(11.0)(1.0)) == 11.0
    assert artifacts(disk) == [] and list(counts() - before) == [0, 1, 0, 0]


@pytest.mark.parametrize("env", [{"APPDYN_DISK_CACHE": "0"}, {"APPDYN_CACHE_DIR": ""}])
@pytest.mark.slow
def test_disabled_by_the_environment(tmp_path, env):
    out = run_script(tmp_path, env=env)
    assert out["directory"] is None and out["compiles"] == 1 and out["err"] < 1e-9
    assert list(tmp_path.iterdir()) == []


def test_the_default_directory_follows_xdg(monkeypatch, tmp_path):
    monkeypatch.delenv("APPDYN_CACHE_DIR", raising=False)
    monkeypatch.delenv("APPDYN_DISK_CACHE", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert diskcache.directory() == tmp_path / "appdyn"
    monkeypatch.setenv("APPDYN_CACHE_DIR", str(tmp_path / "mine"))
    assert diskcache.directory() == tmp_path / "mine"


def test_the_test_suite_never_uses_the_users_cache():
    home = Path(os.path.expanduser("~")) / ".cache" / "appdyn"
    assert diskcache.directory() is not None and diskcache.directory() != home


def test_configure_rejects_bad_values():
    with pytest.raises(ValueError, match="max_bytes"):
        diskcache.configure(max_bytes=-1)
    with pytest.raises(TypeError, match="enabled"):
        diskcache.configure(enabled="yes")


def test_cli_info_and_clear(disk, capsys):
    scaled(13.0)
    assert main(["cache", "info"]) == 0
    out = capsys.readouterr().out
    assert str(disk) in out and "entries:   1" in out
    assert main(["cache", "clear"]) == 0
    assert "removed 1 entries" in capsys.readouterr().out and artifacts(disk) == []


UPGRADED_WHILE_RUNNING = """
import hashlib, sys
from pathlib import Path
import appdyn.dynamics.integrate  # the code this process runs
from appdyn.dynamics import diskcache
here = Path(diskcache.__file__).parent
assert here.is_relative_to(Path.cwd()), here  # (the copy, never the project's own files)
before = hashlib.sha256()
for path in sorted([*(here / "integrate").glob("*.py"), here / "cache.py",
                    here / "diskcache.py", *(here / "attitude").glob("*.py")]):
    before.update(path.name.encode())
    before.update(path.read_bytes())
dense = here / "integrate" / "dense.py"
dense.write_text(dense.read_text() + "\\n# upgraded on disk after the import\\n")
print(diskcache.code_version() == before.digest())
"""


def test_the_code_hash_is_the_imported_code_not_files_changed_later(tmp_path):
    # a copy of the package whose integrate code changes on disk after this process
    # imported it (an upgrade while a kernel runs): the key keeps the imported code's hash
    root = Path(__file__).resolve().parents[2]
    for name in ("appdyn", "dynamics", "ocp", "problems"):
        shutil.copytree(root / name, tmp_path / name,
                        ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(root / "pyproject.toml", tmp_path)  # (appdyn finds its packages beside it)
    env = dict(os.environ, PYTHONPATH=str(tmp_path), APPDYN_CACHE_DIR=str(tmp_path / "cache"))
    done = subprocess.run([sys.executable, "-c", UPGRADED_WHILE_RUNNING], cwd=tmp_path,
                          env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.split() == ["True"]


def _units_job(k: float, unit: ca.Function):
    """A library of a driver ``x -> k x`` (its own source for each ``k``) and the
    translation unit ``unit``; loads as ``(driver, unit)`` Functions."""
    x = ca.SX.sym("x")
    driver = ca.Function("drv", [x], [k * x])
    return cache.Job(lambda: ([driver, [unit]], ""), "-O0",
                     lambda path: (ca.external("drv", path), ca.external(unit.name(), path)),
                     cache.recipe("shared unit", driver, unit))


def objects(directory):
    return sorted(Path(directory).glob("*.o"))


def test_a_unit_compiled_before_is_taken_not_compiled_again(disk):
    """Two libraries sharing a translation unit (as the pass's two builds share their
    steps): the second compiles its driver only and links the first's object of the unit,
    taken from the cache (verified as a library is); a corrupted object is rejected and
    compiled again, never linked. Truth: the drivers compute ``k x``, the unit ``x^3``."""
    x = ca.SX.sym("x")
    cube = ca.Function("cube", [x], [x ** 3])
    before = diskcache.info()
    (d2, c2), = cache.compile_parallel([_units_job(2.0, cube)])
    (obj,) = objects(disk)
    assert verified(obj) and diskcache.info().reused == before.reused
    (d3, c3), = cache.compile_parallel([_units_job(3.0, cube)])
    assert (float(d2(5.0)), float(c2(5.0)), float(d3(5.0)), float(c3(5.0))) == \
        (10.0, 125.0, 15.0, 125.0)
    after = diskcache.info()
    assert after.reused == before.reused + 1 and after.compiles == before.compiles + 2
    assert objects(disk) == [obj] and len(artifacts(disk)) == 2
    obj.write_bytes(obj.read_bytes()[:100])  # (truncated: rejected, compiled again)
    (d4, c4), = cache.compile_parallel([_units_job(4.0, cube)])
    assert (float(d4(5.0)), float(c4(5.0))) == (20.0, 125.0)
    last = diskcache.info()
    assert last.reused == after.reused and last.rejected == after.rejected + 1
    assert objects(disk) == [obj] and verified(obj)
    assert diskcache.clear() == 4 and objects(disk) == [] and artifacts(disk) == []
