"""The one cache of built and compiled CasADi Functions, and the jit policy.

Building a CasADi Function (a model's right-hand side, a Runge-Kutta step, a chunked
integration loop, a Jacobian) costs milliseconds; compiling one to C costs about 0.2-0.5 s.
Every package keeps what it builds here, keyed by the arguments that define it, so that
`dynamics.clear_caches` (and `clear`) can empty all of it in one place.

API
---
``get(key, build, keepalive=None)``
    The entry for ``key`` (any hashable; by convention a tuple whose first item names the
    kind of entry, e.g. ``("chunk", function_key(f), ...)``), built by ``build()`` on a miss.
    ``keepalive`` is held with the entry: pass the Function whose `function_key` is in
    ``key`` so that its address cannot be reused by another Function while the entry lives.
``contains(key)``
    Whether ``key`` has an entry (does not count as a use).
``clear()``
    Drop every entry (compiled libraries are unloaded with their Functions).
``set_maxsize(n)``
    Keep at most ``n`` entries from now on (evicting at once); returns the previous limit.
``info()``
    A `CacheInfo`: entries, maximum size, hits, misses, entries per kind and the C
    compiler.
``function_key(f)``
    The identity of a ``casadi.Function`` to put in a key.
``checkout(key, build, keepalive=None)``
    Context manager lending an instance of a pooled entry (``with checkout(k, b) as obj``)
    that no other thread uses until the block ends (see Threads below).
``construction_lock()``
    The lock to hold around casadi construction outside `get` (see Threads below).
``constructs``
    Decorator for helpers that build and drop CasADi symbols outside `get` (each call
    under the construction lock).
``memoize``
    Decorator for factories of hashable arguments (e.g. ``rigid_body``'s model builder).
``memoize_values``
    Decorator for public builders of array-like arguments, keyed by their values (a repeated
    ``rigid_body([1, 2, 3])`` skips its checks and scene).
``compiler()``
    Path of the C compiler (``gcc`` or ``cc`` on the ``PATH``), or ``None``.
``compile_function(f)``
    ``f`` compiled to C and loaded with ``casadi.external``; no files stay behind.
``compile_parallel(jobs)``, ``compile_ahead(jobs)``
    Compile several `Job` at once and wait; start compiling and return at once (a later
    ``compile_parallel`` of the job waits for that compile).

Entries are evicted least-recently-used beyond `MAXSIZE` (`set_maxsize`); a ``build`` may
itself call `get` (a loop built from a cached step): the construction lock is re-entrant.

Threads
-------
Everything in ``dynamics`` and ``ocp`` may be called from several threads at once, on
shared models, grids and problems; results are identical to a serial run. How:

* **Construction is serialized.** CasADi's symbolic objects are reference counted without
  atomics, and ``casadi.integrator``, ``casadi.nlpsol`` and jit compilation are not
  thread-safe. Every ``build`` of `get` runs under one re-entrant construction lock, and
  code that builds outside the cache (a cvodes integrator with a Python control callback,
  an IPOPT solver with a progress listener or for the warm re-solve) holds the same lock:
  `construction_lock`. The table itself has a second lock, held only for a look-up or an
  insertion (never while building), so a cache hit does not wait for another thread's
  build. Lock order is always construction, then table (no deadlock); evicted entries are
  released under the construction lock.
* **Non-reentrant objects are never shared by two running calls.** A plain call of a
  ``casadi.Function`` evaluates in the Function's memory object 0, which holds the whole
  state of a cvodes integrator (and its linear solver) or of an IPOPT solver: two threads
  calling one such object at once corrupt the heap (seen as ``double free``,
  ``linsol.cpp: Assertion "m->is_nfact" failed``, SIGSEGV). Such entries are *pooled*:
  `checkout` lends one instance to one caller at a time and builds another (under the
  construction lock) only when every instance is busy, so N threads use at most N
  instances and a single thread always reuses the same one. `dynamics.simulate`'s cvodes
  integrators and `ocp.solve`'s IPOPT solvers (with their transcribed NLP) are pooled;
  the ocp's per-interval cvodes integrators are kept per thread (`ocp.cached`).
* **Pure Functions are shared freely.** Fixed-step chunk loops (``rk4``, ``rk8``,
  ``lie``, compiled or not) are called through a ``Function.buffer()`` kept per thread and
  per Function (`dynamics.integrate.evaluate.call_buffered`, and `borrow_bound` with
  numpy arrays bound to its inputs for `simulate`'s chunk loops; dropped with its
  Function), which reserves its own memory object;
  Jacobians and linearizations are SX/MX Functions without solver state.

Cost on a single thread: one pool look-up per cvodes or IPOPT call, about 3 us (a cvodes
call on a 20-point grid takes about 0.4 ms; an IPOPT solve, milliseconds to seconds):
measured end to end, `simulate(method="cvodes")` and a small `ocp.solve` are unchanged
within timing noise (398 vs 399 us, 2.61 vs 2.59 ms).
Limits: builds are serialized (a 1 s IPOPT build in one thread delays other threads'
builds, not their cache hits: a hit during such a build takes microseconds, measured in
tests/stress/test_threads.py); a user's own casadi objects called outside appdyn (e.g. one
integrator shared by the user's threads) are the user's to guard.

Jit policy
----------
Deterministic: whether a loop is compiled depends only on the arguments of the call (and on
whether a C compiler -- ``gcc`` or ``cc`` on the ``PATH`` -- exists), never on how often a
model was used before. `should_compile`:

* ``jit=True``: compile; ``jit=False``: never.
* ``jit=None`` (the default): compile when the work is at least `JIT_MIN_WORK`
  right-hand-side evaluations. `dynamics.simulate` passes ``work=inf`` for every method:
  its one chunk loop per model, method and control mode is compiled on first use (about
  0.4 s) and reused for every grid, step count and later call. (A work-based rule for
  ``auto``'s estimation runs left a typical 100 s run interpreted on every call: 23 ms
  against 3.4 ms compiled.)

A Function that cannot be code-generated falls back to the interpreted one.

Compiled once per machine
-------------------------
Every compile (`compile_parallel`) goes through the persistent compile cache,
`dynamics.diskcache`: a library compiled before on this machine, by any process, is loaded
instead of compiled. The chunk loops and ``auto``'s pass are looked up by their *recipe*
(`Job`, `recipe`: the serialized model Function, the method and this code's version), before
any step Function is built or any C generated, so a fresh process's first ``simulate`` of a
known model costs milliseconds (``bench/compile_cache.py``). `clear` empties only the
in-memory cache; ``appdyn cache clear`` (`diskcache.clear`) the disk.

First compile
-------------
What the first-ever ``simulate`` of a model waits for is the C compiler (the pass and the
chunk loop compile in parallel). gcc's time at ``-O1`` grows faster than linearly with the
size of one C function, and a Runge-Kutta step that inlines the right-hand side in each
stage is ``stages`` times its size: the two hinged bodies' (26 states, 666 instructions)
rk8 step was 484 kB of C and its first ``simulate`` 4.8 s; a 10-part scene's (35 states,
3,760 instructions) 2 MB and 42 s. Choices weighed:

* running interpreted while the compile finishes in a background thread: rejected, the
  answer would depend on timing (``auto``'s C pass and its interpreted fallback are
  different algorithms), against the deterministic jit policy above;
* ``-O0`` for big sources: 3-5x faster compiles, but 3x slower steps for every later run
  (measured on the hinged bodies' chunk loop);
* **smaller generated code (chosen)**: a compiled step whose inlined right-hand side
  evaluations exceed `kernels.INLINE_MAX` (2,000 instructions) calls the right-hand side as
  one C function and combines the stages as vector loops (`kernels.calls_rhs`; the pass
  shares that function with its rhs). Generated C: hinged bodies 484 to 79 kB (pass) and 243
  to 64 kB (chunk), the scene 2 MB to 149 kB and 994 to 134 kB; compiler CPU (about the
  wall time of the parallel compiles on an idle machine) 0.75 s for the hinged bodies and
  1.2 s for the scene, against 4.6 s and 42 s. The steps cost 1.2x the inlined ones on the
  hinged bodies (21.8 against 18.0 us per step in the compiled chunk, a loaded machine) and
  0.7x on the scene (38.7 against 57.2 us: the smaller code fits the instruction cache); the
  results are the same to the last bit or within 3e-17. Small models (the rigid body: 12 x
  67 instructions) keep the inlined step, which is 1.8x faster there.

Since then the pass's steps around a called right-hand side sum their stages as scalar C
(an MX step copied every stage vector through its work array: the wheel spacecraft's step
took 4-6 us, now under 1 us), which made each step large again: the hinged bodies' pass
held four of them (the plain step, the step with its error, the dense step and its
continuous extension, 3,900-5,300 lines each; 465 kB of C, 2.6 s of gcc). It now
generated one step for the first three uses: 294 kB, 1.55 s of gcc (paired runs, one core).

Now a model whose right-hand side is called runs DOP853's sums as C loops over the state
(`integrate.csteps`, as Hairer's dop853.f): the only model-specific C of its pass is the
rhs (the hinged bodies' pass 294 to 75 kB, gcc 1.47 to 0.41 s; the steps are the
generated ones' to the last bit, and cost the same or less per step: the wheel spacecraft
0.70 to 0.56 us, the hinged scene 6.35 and 6.38 us). The same library runs such a model's
fixed-step rk8 chunk (`integrate.cpass.pass_chunk`, loaded as a casadi external Function:
the hinged bodies 2.3 to 2.0 us per step), so its first ``simulate`` compiles one library,
whichever path answers. A small model's casadi chunk loop, which ``auto`` runs only in its
multi-run fallback, is compiled *ahead* (`compile_ahead`): its compiler starts with the
pass's and runs in the background; a call that needs the chunk waits for it, and the
process's exit waits for compiles under way so that they land in the persistent cache.
This is not the interpreted fallback rejected above: no answer depends on timing, only
when a library is ready does. And a library's big generated functions compile as
translation units of their own, at once, then linked (`Job`: a list among the functions):
the rigid body's four inlined steps in two units beside the driver's (one unit of 0.85 s
of gcc became 0.24, 0.30 and 0.40 s side by side), a large model's right-hand side beside
the driver. Measured first ``simulate`` in a fresh process with an empty cache
(``bench/compile_cache.py``, 2-core VM, repeated runs): the rigid body 0.79-1.06 to
0.49-0.52 s, the hinged bodies 1.77 to 0.39 s, the 10-part scene 1.08 to 0.38-0.40 s, the
tests' 10-part registry scene (35 states) 3.47 to 0.41-0.45 s; 13 registry parts (39
states), whose run ``auto`` hands to its multi-run search, 1.35 s (the chunk compiled
ahead) to 0.60-0.76 s; all 15 registry parts (45 states) 0.54-0.69 s.
"""
from __future__ import annotations

import atexit
import contextlib
import functools
import os
import threading
import weakref
from collections import Counter, OrderedDict
from typing import Callable, Hashable, NamedTuple

import casadi as ca

from . import diskcache
from .validate import integer

__all__ = ["MAXSIZE", "JIT_MIN_WORK", "CacheInfo", "FunctionCache", "get", "contains", "clear",
           "info", "set_maxsize", "function_key", "constructs", "memoize", "memoize_values", "value_key",
           "checkout", "construction_lock", "POOL_SIZE", "compiler", "should_compile",
           "compile_function", "compile_c", "compile_parallel", "compile_ahead", "ready", "Job",
           "recipe"]

#: Most entries kept (least recently used are dropped first).
MAXSIZE = 512

#: Right-hand-side evaluations from which a run is compiled under ``jit=None`` (interpreted,
#: this many cost about the compile time of a small model).
JIT_MIN_WORK = 500_000

#: Most idle instances a pooled entry keeps (`checkout`); more are built when busy.
POOL_SIZE = 8


class CacheInfo(NamedTuple):
    """What `info` reports."""

    entries: int
    maxsize: int
    hits: int
    misses: int
    kinds: dict  # first item of the key (when a string) -> number of entries
    compiler: str | None


class FunctionCache:
    """Built CasADi Functions keyed by their defining arguments (LRU, thread-safe).

    One instance serves the process (the module-level functions); see the module docstring.
    """

    def __init__(self, maxsize: int = MAXSIZE):
        self._maxsize = maxsize
        self._items: OrderedDict = OrderedDict()
        self._lock = threading.Lock()  # the table (held briefly)
        self._build_lock = threading.RLock()  # casadi construction (held through a build)
        self._hits = self._misses = 0
        self._compiler: str | None = None
        self._compiler_checked = False

    def get(self, key: Hashable, build: Callable[[], object], keepalive=None):
        """Return the entry for ``key``, building it with ``build()`` on a miss."""
        with self._lock:
            entry = self._items.get(key)
            if entry is not None:
                self._hits += 1
                self._items.move_to_end(key)
                return entry[0]
        with self._build_lock:
            with self._lock:  # built by another thread while this one waited?
                if key in self._items:
                    self._hits += 1
                    self._items.move_to_end(key)
                    return self._items[key][0]
                self._misses += 1
            value = build()
            with self._lock:
                self._items[key] = (value, keepalive)
                evicted = self._evict()
            del evicted  # released here, still under the construction lock
            return value

    def _evict(self) -> list:
        """Drop the least recently used entries beyond the limit (hold ``_lock``); returns
        them, to be released by the caller under the construction lock."""
        evicted = []
        while len(self._items) > self._maxsize:
            evicted.append(self._items.popitem(last=False))
        return evicted

    @contextlib.contextmanager
    def checkout(self, key: Hashable, build: Callable[[], object], keepalive=None):
        """Lend an instance of the pooled entry ``key`` to this caller alone (a context
        manager); ``build()`` makes a new instance, under the construction lock, when none
        is idle."""
        pool = self.get(key, _Pool, keepalive)
        with self._lock:
            value = pool.idle.pop() if pool.idle else None
        if value is None:
            with self._build_lock:
                value = build()
        try:
            yield value
        finally:
            with self._lock:
                if len(pool.idle) < POOL_SIZE:
                    pool.idle.append(value)

    def construction_lock(self):
        """The re-entrant lock held by every build; hold it around casadi construction."""
        return self._build_lock

    def set_maxsize(self, maxsize: int) -> int:
        """Keep at most ``maxsize`` entries (least recently used are evicted at once);
        returns the previous limit. An evicted compiled loop unloads its library once no
        caller holds it: resident memory stays flat however many models a long session
        compiles (measured: 200 distinct compiles at ``maxsize=30`` leave it unchanged to
        0.1 MB; without eviction each compile keeps about 75 kB)."""
        maxsize = integer(maxsize, "maxsize", minimum=1)
        with self._build_lock:
            with self._lock:
                previous, self._maxsize = self._maxsize, maxsize
                evicted = self._evict()
            del evicted
            return previous

    def contains(self, key: Hashable) -> bool:
        """Whether ``key`` has an entry."""
        with self._lock:
            return key in self._items

    def clear(self) -> None:
        """Drop every entry (compiled libraries are unloaded with their Functions)."""
        with self._build_lock:
            with self._lock:
                items, self._items = self._items, OrderedDict()
                self._hits = self._misses = 0
            del items

    def info(self) -> CacheInfo:
        """Counts and the C compiler, for diagnostics."""
        compiler = self.compiler()
        with self._lock:
            kinds = Counter(k[0] for k in self._items
                            if isinstance(k, tuple) and k and isinstance(k[0], str))
            return CacheInfo(len(self._items), self._maxsize, self._hits, self._misses,
                             dict(kinds), compiler)

    def compiler(self) -> str | None:
        """Path of the C compiler (``gcc`` or ``cc`` on the ``PATH``), or None (looked up
        once)."""
        if self._compiler_checked:  # set once, never changed: no lock needed to read it
            return self._compiler
        with self._lock:
            if not self._compiler_checked:
                import shutil  # (stdlib, imported when first compiling)

                self._compiler_checked = True
                self._compiler = shutil.which("gcc") or shutil.which("cc")
            return self._compiler


class _Pool:
    """Idle instances of one pooled entry (`FunctionCache.checkout`)."""

    __slots__ = ("idle",)

    def __init__(self):
        self.idle: list = []


def compile_function(fun: ca.Function, *, opt: str = "-O3") -> ca.Function | None:
    """``fun`` compiled to C and loaded with ``casadi.external``; None without a C compiler.

    The code is generated into a scratch directory, compiled with ``opt`` (``-O3``; the
    chunk loops of `dynamics.simulate` use ``-O1``) by the C compiler
    found on the ``PATH`` (`compiler` tells which), loaded, and the files are deleted at
    once (a loaded shared library stays mapped): unlike casadi's own jit, which leaves two
    file descriptors open per compile (casadi issue #4295) and its files on disk, nothing is
    left behind. Raises ``RuntimeError`` when the code cannot be generated or compiled.
    """
    return compile_c([fun], "", opt, lambda library: ca.external(fun.name(), library))


def compile_c(functions: list, extra: str, opt: str, load: Callable[[str], object]):
    """Generate C for the casadi ``functions``, append the C source ``extra`` (which may call
    them by name), compile to a shared library with the flags ``opt`` (space-separated) and
    return ``load(path)`` (e.g. ``ctypes.CDLL``); the files are deleted after loading. None
    without a C compiler; ``RuntimeError`` when generating or compiling fails (see
    `compile_function`)."""
    out = compile_parallel([(functions, extra, opt, load)])[0]
    if isinstance(out, RuntimeError):
        raise out
    return out


class Job(NamedTuple):
    """A compile for `compile_parallel` whose functions are built only when needed.

    ``make()`` returns ``(functions, extra)`` (the casadi Functions to generate, the first
    naming the library, and C source appended to them; an item that is a list of Functions
    is a translation unit of its own, compiled at the same time as the others and linked
    with them, its functions declared for ``extra``); ``opt`` the compiler flags;
    ``load(path)`` the loaded result; ``recipe`` a text that determines the generated source
    (with the code of `diskcache.code_version`): the persistent cache is looked up by it
    before anything is built (`recipe`). ``None``: the source is generated and hashed.
    """

    make: Callable[[], tuple]
    opt: str
    load: Callable[[str], object]
    recipe: str | None = None


def recipe(*parts) -> str | None:
    """The `Job.recipe` of ``parts``: casadi Functions by their serialized form, anything else
    by its ``repr``; None when a Function cannot be serialized (the job then hashes its
    generated source).

    Examples
    --------
    >>> import casadi as ca
    >>> from appdyn.dynamics import cache
    >>> x = ca.SX.sym("x")
    >>> f = ca.Function("f", [x], [2 * x])
    >>> cache.recipe("chunk", f, "rk8") == cache.recipe("chunk", f, "rk8")
    True
    """
    out = []
    for part in parts:
        if isinstance(part, ca.Function):
            try:
                part = part.serialize()
            except RuntimeError:
                return None
        out.append(repr(part))
    return "\0".join(out)


def compile_parallel(jobs: list) -> list:
    """`compile_c` of several jobs (`Job`, or ``(functions, extra, opt, load)``), the C
    compilers running at once (one process each): per job, in order, the loaded result or
    the ``RuntimeError`` saying why it failed (returned, not raised); a list of None without
    a C compiler.

    A library compiled before on this machine is loaded from the persistent compile cache
    (`dynamics.diskcache`) instead: looked up by the job's recipe before anything is built,
    or by the hash of the generated C source; the compiler runs only for the jobs whose
    library is not there (or is rejected as corrupted or foreign). A job whose compile
    `compile_ahead` started waits for that compile instead of starting another."""
    compiler = _CACHE.compiler()
    if compiler is None:
        return [None] * len(jobs)
    jobs = [_as_job(job) for job in jobs]
    results: list = [None] * len(jobs)
    try:
        for i, job in enumerate(jobs):
            results[i] = _start(job, compiler)
        for i, job in enumerate(jobs):
            if isinstance(results[i], _Build):
                results[i] = _finish(results[i], job)
    finally:  # (an interrupt: no compiler process or scratch directory is left behind)
        for out in results:
            if isinstance(out, _Build):
                out.stop()
                out.close()
    return results


def compile_ahead(jobs: list) -> None:
    """Start compiling the jobs (`Job` with a recipe) whose libraries are neither in the
    persistent cache nor being compiled, and return at once: the compilers run in the
    background (their libraries go into the persistent cache when they finish), and a later
    `compile_parallel` of such a job waits for its compile rather than starting another
    (results do not depend on timing: only when a library is ready does). What a call does
    not need now is compiled while it runs and after it returns; a process exiting waits
    for its compiles under way (so that the machine compiles each library once). Nothing
    happens without a C compiler."""
    compiler = _CACHE.compiler()
    if compiler is None:
        return
    for job in map(_as_job, jobs):
        if job.recipe is None:
            continue
        key = _job_key(job, compiler)
        with _AHEAD_LOCK:
            if key in _AHEAD:
                continue
        if diskcache.lookup(key) is not None:
            continue
        build = _spawn(job, compiler, key)
        if isinstance(build, _Build):
            with _AHEAD_LOCK:
                _AHEAD[key] = build
            threading.Thread(target=build.wait, name="appdyn-compile", daemon=True).start()


def ready(job: Job) -> bool:
    """Whether `compile_parallel` of ``job`` (a `Job` with a recipe) would load its library
    without waiting for a compiler: the persistent cache holds it, or `compile_ahead`'s
    compile of it has finished. With `compile_ahead`, a call that can do without a library
    uses it only once it is ready: the first call does not wait for the compile."""
    compiler = _CACHE.compiler()
    if compiler is None or job.recipe is None:
        return False
    key = _job_key(job, compiler)
    with _AHEAD_LOCK:
        ahead = _AHEAD.get(key)
    if ahead is not None:
        return ahead.finished()
    return diskcache.lookup(key) is not None


def _as_job(job) -> Job:
    return job if isinstance(job, Job) else Job(lambda job=job: (job[0], job[1]), job[2], job[3])


def _flags(job: Job) -> list:
    return [*job.opt.split(), "-w", "-fPIC", "-shared"]


def _job_key(job: Job, compiler: str) -> str:
    """The persistent cache's key of a job with a recipe."""
    return diskcache.artifact_key(job.recipe.encode() + diskcache.code_version(), compiler,
                                  _flags(job))


class _Build:
    """One C compile in its scratch directory ``work`` (removed by `close`): once started,
    the generated library's ``name``, its persistent-cache ``key``, the ``library`` it
    makes, the compiler processes ``procs`` (one per translation unit, running at once)
    and the ``link`` command joining their objects (None: one unit, compiled to the
    library directly)."""

    def __init__(self, work: str):
        self.work, self.name, self.key, self.library = work, "", "", ""
        self.procs: list = []
        self.link: list | None = None
        self.objects: list = []  # (key, path) of the units compiled here, kept as objects
        self._lock = threading.Lock()
        self._outcome = None

    def wait(self):
        """Wait for the compilers and link (once; any thread): the library's path
        (published to the persistent cache) or the ``RuntimeError`` saying why the compile
        failed."""
        with self._lock:
            if self._outcome is None:
                errors = [err for err, code in ((p.communicate()[1], p.returncode)
                                                for p in self.procs) if code != 0]
                if not errors and self.link is not None:
                    import subprocess

                    for key, path in self.objects:  # (for a later build sharing the unit)
                        diskcache.publish(key, path, suffix=".o")

                    done = subprocess.run(self.link, cwd=self.work, capture_output=True,
                                          text=True)
                    errors = [done.stderr] if done.returncode != 0 else []
                self._outcome = (RuntimeError(f"C compilation of {self.name} failed: "
                                              f"{errors[0].strip()[-500:]}") if errors else
                                 diskcache.publish(self.key, self.library))
            return self._outcome

    def finished(self) -> bool:
        """Whether the compilers (and the link) are done: `wait` then returns at once."""
        if self._outcome is not None:
            return True
        if any(proc.poll() is None for proc in self.procs):
            return False
        self.wait()  # (the link, if any: a few milliseconds)
        return True

    def stop(self) -> None:
        """Stop the compilers (each one's whole process group: the driver and its passes)
        that still run."""
        import signal

        for proc in self.procs:
            if proc.poll() is None:
                try:
                    if hasattr(os, "killpg"):
                        os.killpg(proc.pid, signal.SIGKILL)
                    else:  # (no process groups)
                        proc.kill()
                except OSError:
                    pass
        if self.procs:
            self.wait()

    def close(self) -> None:
        import shutil

        shutil.rmtree(self.work, ignore_errors=True)


def _start(job: Job, compiler: str):
    """The job's library loaded from the persistent cache, a compile under way (`_Build`:
    started by `compile_ahead`, or now) or the ``RuntimeError`` of a failed generation."""
    key = None
    if job.recipe is not None:
        key = _job_key(job, compiler)
        with _AHEAD_LOCK:
            ahead = _AHEAD.pop(key, None)
        if ahead is not None:
            return ahead
        found = _load_cached(key, job)
        if found is not None:
            return found
    return _spawn(job, compiler, key)


def _spawn(job: Job, compiler: str, key: str | None):
    """Generate the job's C and start its compiler: a `_Build`, the library loaded from the
    persistent cache (found by the hash of the source, ``key`` None), or the
    ``RuntimeError`` of a failed generation."""
    import subprocess  # (stdlib, imported when first compiling)
    import tempfile

    # (a plain directory, removed by `_Build.close`: a TemporaryDirectory's own exit hook
    # would remove it under a compile that the exit waits for)
    work = tempfile.mkdtemp(prefix="appdyn-cc-")
    build = _Build(work)
    try:
        # (the job's Functions are built and generated under the construction lock: a call
        # outside a build, e.g. `compile_ahead` from a thread-pool task, builds symbols too)
        with _CACHE.construction_lock():
            functions, extra = job.make()
            units = [list(f) for f in functions if isinstance(f, (list, tuple))]
            main = [f for f in functions if not isinstance(f, (list, tuple))]
            build.name = main[0].name()
            sources = [_generate_c(main, _prototypes(units) + extra, work)] + \
                [_generate_c(unit, "", work) for unit in units]
    except RuntimeError as exc:  # (a Function that cannot be code-generated)
        build.close()
        return RuntimeError(f"generating C failed: {exc}")
    except BaseException:
        build.close()
        raise
    flags = _flags(job)
    if key is None:
        text = b""
        for source in sources:
            with open(source, "rb") as f:
                text += f.read()
        key = diskcache.artifact_key(text, compiler, flags)
        found = _load_cached(key, job)
        if found is not None:
            build.close()
            return found
    build.key, build.library = key, os.path.join(work, f"{build.name}.so")
    diskcache.compiled()
    # (the compiler's own temporary files go to the scratch directory too; each its own
    # process group, so that `_Build.stop` stops its passes with it)
    names = [os.path.basename(source) for source in sources]
    if len(names) == 1:
        commands = [[compiler, *flags, names[0], "-o", build.library, "-lm"]]
    else:  # (the units compiled at once, then linked: `_Build.wait`)
        compile_flags = [f for f in flags if f != "-shared"]
        commands = []
        for i, name in enumerate(names):
            # (a unit after the driver is kept as an object under the key of its own source:
            # a build sharing it, as the pass's two builds share their steps, takes it)
            unit = None if i == 0 else _unit_key(os.path.join(work, name), compiler,
                                                   compile_flags)
            obj = os.path.join(work, name[:-2] + ".o")
            if unit is not None and _take_object(unit, obj):
                continue
            if unit is not None:
                build.objects.append((unit, obj))
            commands.append([compiler, *compile_flags, "-c", name, "-o", obj])
        build.link = [compiler, *flags, *(n[:-2] + ".o" for n in names), "-o", build.library,
                      "-lm"]
    build.procs = [subprocess.Popen(command, cwd=work, stdout=subprocess.PIPE,
                                    stderr=subprocess.PIPE, text=True,
                                    env={**os.environ, "TMPDIR": work}, start_new_session=True)
                   for command in commands]
    return build


def _unit_key(source: str, compiler: str, flags: list) -> str:
    """The persistent cache's key of the object of the translation unit ``source``."""
    with open(source, "rb") as f:
        return diskcache.artifact_key(f.read(), compiler, [*flags, "-c"])


def _take_object(key: str, obj: str) -> bool:
    """Copy the object of ``key`` from the persistent cache to ``obj`` (for the link: an
    eviction meanwhile cannot take it away); False when it is not there."""
    import shutil

    found = diskcache.lookup(key, suffix=".o")
    if found is None:
        return False
    try:
        shutil.copyfile(found, obj)
    except OSError:
        return False
    diskcache.reused()
    return True


def _prototypes(units: list) -> str:
    """C declarations of the generated functions of other translation units."""
    return "".join(f"int {f.name()}(const casadi_real** arg, casadi_real** res, "
                   "casadi_int* iw, casadi_real* w, int mem);\n"
                   for unit in units for f in unit)


def _finish(build: _Build, job: Job):
    """The job's library loaded once its compile has finished, or the ``RuntimeError``."""
    try:
        out = build.wait()
        if isinstance(out, RuntimeError):
            return out
        try:
            return job.load(out)
        except (OSError, RuntimeError) as exc:  # (a library that does not load)
            return RuntimeError(f"loading {build.name} failed: {exc}")
    finally:
        build.close()


def _load_cached(key: str, job: Job):
    """The library of ``key`` loaded from the persistent cache, or None (absent; one that
    fails to load is deleted, to be rebuilt)."""
    found = diskcache.lookup(key)
    if found is None:
        return None
    try:
        out = job.load(found)
    except (OSError, RuntimeError):
        diskcache.discard(key)
        return None
    diskcache.hit()
    return out


#: compiles started by `compile_ahead`, by persistent-cache key, until a job takes them
_AHEAD: dict = {}
_AHEAD_LOCK = threading.Lock()


def _finish_ahead() -> None:
    """At exit: wait for the compiles under way (their libraries land in the persistent
    cache; with that cache off, stop them instead) and remove their scratch directories."""
    with _AHEAD_LOCK:
        builds = list(_AHEAD.values())
        _AHEAD.clear()
    keep = diskcache.directory() is not None
    for build in builds:
        if keep:
            build.wait()
        else:
            build.stop()
        build.close()


def _forget_ahead() -> None:
    """In a forked child: the parent's compiler processes are not the child's to wait for."""
    _AHEAD.clear()


atexit.register(_finish_ahead)
os.register_at_fork(after_in_child=_forget_ahead)


def _generate_c(functions: list, extra: str, work: str) -> str:
    """Generate the C source of the casadi ``functions`` (named after the first) into the
    directory ``work``, with the C source ``extra`` appended; returns its path."""
    name = functions[0].name()
    gen = ca.CodeGenerator(f"{name}.c", {"with_header": False})
    for fun in functions:
        gen.add(fun)
    gen.generate(work + os.sep)
    source = os.path.join(work, f"{name}.c")
    if extra:
        with open(source, "a") as out:
            out.write(extra)
    return source


_CACHE = FunctionCache()

get = _CACHE.get
contains = _CACHE.contains
clear = _CACHE.clear
set_maxsize = _CACHE.set_maxsize
info = _CACHE.info
compiler = _CACHE.compiler
checkout = _CACHE.checkout
construction_lock = _CACHE.construction_lock


def function_key(f: ca.Function) -> int:
    """Identity of a casadi Function (the address of its internal object), for cache keys.

    Pass ``f`` as ``keepalive`` to `get` with any key that contains it. Remembered per
    Python object while it lives (casadi's ``__hash__`` costs about 0.6 us a call).
    """
    entry = _KEYS.get(id(f))
    if entry is not None and entry[0]() is f:
        return entry[1]
    key = hash(f)
    try:
        ref = weakref.ref(f, lambda _ref, i=id(f): _KEYS.pop(i, None))
    except TypeError:  # not weakly referable: not remembered
        return key
    _KEYS[id(f)] = (ref, key)
    return key


#: `function_key`'s memory: ``id(f) -> (weak reference to f, key)``, dropped with ``f``
_KEYS: dict = {}


def constructs(fun: Callable) -> Callable:
    """Decorator: each call of ``fun`` (which builds CasADi symbols and Functions outside
    `get`, evaluates and drops them) runs under the construction lock, so that its symbols
    are made and released there (Threads above: CasADi counts references without atomics;
    two threads building from one model at once crashed a thread-pooled stability sweep).
    For quick helpers: a long solve should hold the lock only while it builds."""
    @functools.wraps(fun)
    def locked(*args, **kwargs):
        with _CACHE.construction_lock():
            return fun(*args, **kwargs)

    return locked


def memoize(fun: Callable) -> Callable:
    """Decorator: cache ``fun(*args)`` (hashable positional arguments) in the one cache."""
    name = f"{fun.__module__}.{fun.__qualname__}"

    @functools.wraps(fun)
    def cached(*args):
        return get((name,) + args, lambda: fun(*args))

    return cached


class _Unkeyable(Exception):
    """An argument `value_key` cannot key by value (the call is not cached)."""


def value_key(v) -> Hashable:
    """A hashable key of one argument by value: a list, tuple or array of real numbers as
    ``("array", shape, values)`` (so ``[1, 2]`` and ``np.array([1.0, 2.0])`` are one key),
    a real number as ``("num", float)``, ``None``, a string, a boolean or a hashable
    dataclass (a part) with its type name. Raises `_Unkeyable` for anything else (booleans
    inside arrays, ragged lists, CasADi symbols, other objects): such calls are not cached."""
    import dataclasses
    import numbers

    import numpy as np

    if isinstance(v, (list, tuple, np.ndarray)):
        try:
            a = np.asarray(v)
        except (TypeError, ValueError):
            raise _Unkeyable from None
        if a.dtype.kind not in "fi":
            if isinstance(v, tuple) and a.dtype.kind == "O":
                return ("tuple",) + tuple(value_key(e) for e in v)
            raise _Unkeyable
        return ("array", a.shape, tuple(a.astype(float).ravel().tolist()))
    if isinstance(v, numbers.Real) and not isinstance(v, (bool, np.bool_)):
        return ("num", float(v))
    if not (v is None or isinstance(v, (str, bool, np.bool_))
            or dataclasses.is_dataclass(v) and not isinstance(v, type)):
        raise _Unkeyable
    try:
        hash(v)
    except TypeError:
        raise _Unkeyable from None
    return (type(v).__name__, v)


def memoize_values(fun: Callable) -> Callable:
    """Decorator: cache ``fun(*args, **kwargs)`` in the one cache, keyed by the arguments'
    values (`value_key`), before ``fun`` checks them.

    For public builders that check array-like arguments and build a scene whose model is
    cached (``rigid_body``): a repeated call returns the cached model without the checks
    (a bad argument is never cached: its call raises on every miss). Calls whose arguments
    cannot be keyed are not cached.

    Examples
    --------
    >>> from appdyn.dynamics import rigid_body
    >>> rigid_body([1.0, 2.0, 3.0]) is rigid_body((1, 2, 3))
    True
    """
    name = f"{fun.__module__}.{fun.__qualname__}"

    @functools.wraps(fun)
    def cached(*args, **kwargs):
        try:
            key = (name, tuple(value_key(a) for a in args),
                   tuple(sorted((k, value_key(v)) for k, v in kwargs.items())))
        except _Unkeyable:
            return fun(*args, **kwargs)
        return get(key, lambda: fun(*args, **kwargs))

    return cached


def should_compile(jit: bool | None, work: float) -> bool:
    """The jit policy (module docstring): ``jit`` if given, else ``work >= JIT_MIN_WORK``.

    Parameters
    ----------
    jit : bool or None
        The caller's choice; ``None`` decides by ``work``.
    work : float
        Right-hand-side evaluations of the run (``inf`` to compile whenever possible).

    Returns
    -------
    bool
        Whether to ask for a compiled Function (`compiler` may still say there is no
        compiler).
    """
    if jit is not None:
        return bool(jit)
    return work >= JIT_MIN_WORK
