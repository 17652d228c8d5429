"""The persistent compile cache: compiled shared libraries kept on disk, per user, so that a
model compiled once on this machine is loaded, not compiled, by every later process.

Every C compile of ``dynamics`` and ``ocp`` (`dynamics.cache.compile_parallel`: the chunk
loops of `dynamics.simulate`, the compiled pass of ``auto``, the jit'd Functions of
``ocp``) goes through `lookup` and `publish`: the C source is generated (cheap), hashed, and
a library found under that hash is loaded (``casadi.external`` or ``ctypes``) instead of
running the compiler. Measured (``bench/compile_cache.py``): a fresh process's first
``simulate`` of the rigid body takes 0.02 s with the library on disk against 1.1 s compiling,
the hinged bodies (26 states) 0.03 s against 4.8 s.

Where
-----
``$APPDYN_CACHE_DIR`` when set (set and empty: the cache is off), else
``$XDG_CACHE_HOME/appdyn``, else ``~/.cache/appdyn``. ``APPDYN_DISK_CACHE=0`` (or ``false``,
``no``, ``off``) turns it off; `configure` overrides both for this process.

Key
---
An artifact is named by the SHA-256 of: the generated C source, the compiler (its resolved
path, size and modification time), the flags, the CasADi version, the machine's architecture
and its CPU (model and instruction-set flags: the pass is built with ``-march=native``, so a
cache directory shared by machines of different CPUs keeps one library per CPU) and this
module's format version. No Python ABI enters: the libraries are plain C, loaded by
``ctypes`` or by CasADi (whose version is in the key).

Safety
------
* **Verified before loading.** Each ``<key>.so`` has a sidecar ``<key>.json`` holding the
  whole key, the library's size and its SHA-256. A library whose sidecar is missing,
  unreadable, written for another key, or whose size or hash differs (truncated, replaced,
  corrupted), or that fails to load, is deleted and rebuilt: never loaded.
* **Concurrent processes.** A compile writes to a private temporary file in the cache
  directory and publishes it by ``os.replace`` (atomic on POSIX): library first, then the
  sidecar. A reader sees either nothing (and compiles too: both succeed, the later rename
  wins with identical content) or a complete pair. A library already loaded stays mapped
  when another process replaces or evicts its file.
* **Objects too.** A library built from several translation units (`dynamics.cache`:
  the compiled pass of ``auto``, in two builds that share their step units) keeps each
  unit but the first (the driver) as an object ``<key>.o`` under the key of the unit's own
  source and compile flags, verified the same way: a library whose units were compiled
  before (with the other build of the pass) compiles only its own.
* **Bounded.** After each publish the least recently used artifacts (a hit refreshes the
  library's modification time) are deleted until the directory holds at most `MAX_BYTES`
  (500 MB by default; ``APPDYN_CACHE_MAX_MB`` or `configure`); the one just published stays.
  A typical artifact is 0.1-2 MB. Temporary files left by a killed process are removed
  after an hour.

API
---
`configure` (directory, on/off, size limit), `directory`, `enabled`, `info` (a
`DiskCacheInfo`), `clear`, `lookup`, `publish`, `artifact_key`; the command line:
``appdyn cache info`` and ``appdyn cache clear``.
"""
from __future__ import annotations

import hashlib
import json
import os
import platform
import threading
import time
from pathlib import Path
from typing import NamedTuple

import casadi as ca

__all__ = ["MAX_BYTES", "FORMAT", "DiskCacheInfo", "configure", "directory", "enabled", "info",
           "clear", "lookup", "publish", "artifact_key", "discard", "code_version", "hit",
           "compiled", "reused", "limit"]

#: Default size limit of the cache directory [bytes] (``APPDYN_CACHE_MAX_MB`` overrides).
MAX_BYTES = 500 * 1024 * 1024

#: Format version of the artifacts (part of every key: a change orphans the old ones).
FORMAT = 1

_STALE_TMP = 3600.0  # [s] age after which a leftover temporary file is removed
_OFF = ("0", "false", "no", "off")
_UNSET = object()


class DiskCacheInfo(NamedTuple):
    """What `info` reports: the directory (None when the cache is off), the artifacts in it,
    their size [bytes], the limit [bytes], and this process's counts: libraries loaded from
    the cache (``hits``), compiles (``compiles``), artifacts rejected as corrupted or foreign
    (``rejected``) and deleted to keep the bound (``evicted``), and translation units whose
    object was taken from the cache instead of compiled (``reused``)."""

    directory: str | None
    entries: int
    size: int
    limit: int
    hits: int
    compiles: int
    rejected: int
    evicted: int
    reused: int = 0


_lock = threading.Lock()
_settings: dict = {"directory": _UNSET, "enabled": None, "limit": None}
_counts = {"hits": 0, "compiles": 0, "rejected": 0, "evicted": 0, "reused": 0}


def configure(*, directory=_UNSET, enabled: bool | None = _UNSET, max_bytes: int | None = _UNSET) -> dict:
    """Override the environment for this process; returns the previous overrides.

    Parameters
    ----------
    directory : str or os.PathLike or None, optional
        The cache directory; ``None`` returns to the environment's choice (module docstring).
    enabled : bool or None, optional
        ``False`` turns the cache off, ``True`` on; ``None`` returns to the environment's.
    max_bytes : int or None, optional
        Size limit [bytes], >= 0; ``None`` returns to the environment's (default `MAX_BYTES`).

    Returns
    -------
    dict
        The previous overrides (pass them back as keywords to restore).

    Examples
    --------
    >>> from appdyn.dynamics import diskcache
    >>> old = diskcache.configure(enabled=False)
    >>> diskcache.enabled()
    False
    >>> _ = diskcache.configure(**old)
    """
    if enabled is not _UNSET and enabled is not None and not isinstance(enabled, bool):
        raise TypeError(f"`enabled` must be True, False or None, got {enabled!r}")
    if max_bytes is not _UNSET and max_bytes is not None:
        if isinstance(max_bytes, bool) or not isinstance(max_bytes, int) or max_bytes < 0:
            raise ValueError(f"`max_bytes` must be an integer >= 0 or None, got {max_bytes!r}")
    with _lock:
        previous = {"directory": None if _settings["directory"] is _UNSET else _settings["directory"],
                    "enabled": _settings["enabled"], "max_bytes": _settings["limit"]}
        if directory is not _UNSET:
            _settings["directory"] = _UNSET if directory is None else os.fspath(directory)
        if enabled is not _UNSET:
            _settings["enabled"] = enabled
        if max_bytes is not _UNSET:
            _settings["limit"] = max_bytes
    return previous


def directory() -> Path | None:
    """The cache directory in use, or None when the cache is off (module docstring, Where).

    Examples
    --------
    >>> from appdyn.dynamics import diskcache
    >>> d = diskcache.directory()
    >>> d is None or d.is_absolute()
    True
    """
    if _settings["enabled"] is False:
        return None
    if _settings["enabled"] is None and os.environ.get("APPDYN_DISK_CACHE", "").strip().lower() in _OFF:
        return None
    chosen = _settings["directory"]
    if chosen is _UNSET:
        chosen = os.environ.get("APPDYN_CACHE_DIR")
        if chosen is None:
            base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
            chosen = os.path.join(base, "appdyn")
    if not chosen:
        return None
    return Path(chosen).expanduser().absolute()


def enabled() -> bool:
    """Whether compiled libraries are kept on disk (`directory` is not None).

    Examples
    --------
    >>> from appdyn.dynamics import diskcache
    >>> diskcache.enabled() == (diskcache.directory() is not None)
    True
    """
    return directory() is not None


def limit() -> int:
    """The size limit in use [bytes]."""
    if _settings["limit"] is not None:
        return _settings["limit"]
    text = os.environ.get("APPDYN_CACHE_MAX_MB")
    if text:
        try:
            return max(0, int(float(text) * 1024 * 1024))
        except ValueError:
            pass
    return MAX_BYTES


def artifact_key(source: bytes, compiler: str, flags: list) -> str:
    """The key of a library (hex SHA-256; module docstring, Key).

    Parameters
    ----------
    source : bytes
        The whole C source.
    compiler : str
        Path of the C compiler.
    flags : list of str
        Every flag of the compile command.

    Returns
    -------
    str
        64 hexadecimal digits.

    Examples
    --------
    >>> from appdyn.dynamics.diskcache import artifact_key
    >>> k = artifact_key(b"int f(void) { return 1; }", "/usr/bin/gcc", ["-O1"])
    >>> len(k), k == artifact_key(b"int f(void) { return 2; }", "/usr/bin/gcc", ["-O1"])
    (64, False)
    """
    h = hashlib.sha256()
    for part in (str(FORMAT), _compiler_id(compiler), " ".join(flags), ca.__version__,
                 _machine_id()):
        h.update(part.encode())
        h.update(b"\0")
    h.update(source)
    return h.hexdigest()


def code_version() -> bytes:
    """Hash of the code that turns a model into C (`dynamics.integrate`, `dynamics.cache`,
    this module, `dynamics.attitude`): part of the key of a `dynamics.cache.Job` looked up
    by its recipe, so that an upgrade of appdyn never loads a library built by older code.

    Taken once per process, when `dynamics.integrate` is imported (the code the process
    runs), not at the first compile: files replaced on disk after the import (an upgrade
    while a kernel runs) would otherwise key this process's libraries, built by the old
    code, as the new code's, and later processes would load them.

    Examples
    --------
    >>> from appdyn.dynamics.diskcache import code_version
    >>> len(code_version())
    32
    """
    out = _IDS.get("code")
    if out is None:
        here = Path(__file__).parent
        h = hashlib.sha256()
        for path in sorted([*(here / "integrate").glob("*.py"), here / "cache.py",
                            here / "diskcache.py", *(here / "attitude").glob("*.py")]):
            h.update(path.name.encode())
            h.update(path.read_bytes())
        out = _IDS["code"] = h.digest()
    return out


def lookup(key: str, *, suffix: str = ".so") -> str | None:
    """Path of the verified library of ``key`` in the cache (``suffix`` ``".o"``: of the
    object), or None (off, absent, or rejected: a rejected artifact is deleted). A hit
    refreshes its last use."""
    root = directory()
    if root is None:
        return None
    library, sidecar = _paths(root, key, suffix)
    try:
        meta = json.loads(sidecar.read_text())
        data = library.read_bytes()
    except FileNotFoundError:
        return None
    except (OSError, ValueError):
        meta, data = None, b""
    if not (isinstance(meta, dict) and meta.get("key") == key and meta.get("size") == len(data)
            and meta.get("sha256") == hashlib.sha256(data).hexdigest()):
        discard(key, suffix=suffix)
        return None
    try:
        os.utime(library)
    except OSError:
        pass
    return str(library)


def hit() -> None:
    """Count a library loaded from the cache (`info`)."""
    _count("hits")


def compiled() -> None:
    """Count a compile (`info`)."""
    _count("compiles")


def reused() -> None:
    """Count a translation unit whose object was taken from the cache (`info`)."""
    _count("reused")


def discard(key: str, *, suffix: str = ".so") -> None:
    """Delete the artifact of ``key`` (``suffix`` as `lookup`'s; a corrupted or foreign one:
    counted as rejected)."""
    root = directory()
    if root is None:
        return
    _count("rejected")
    for path in _paths(root, key, suffix):
        _unlink(path)


def publish(key: str, built: str, *, suffix: str = ".so") -> str:
    """Put the compiled library ``built`` (``suffix`` ``".o"``: an object) into the cache
    under ``key`` and return its path there (atomically, then evicting beyond the limit);
    ``built`` itself when the cache is off or cannot be written."""
    root = directory()
    if root is None:
        return built
    library, sidecar = _paths(root, key, suffix)
    try:
        root.mkdir(parents=True, exist_ok=True)
        data = Path(built).read_bytes()
        meta = {"key": key, "size": len(data), "sha256": hashlib.sha256(data).hexdigest(),
                "casadi": ca.__version__, "machine": platform.machine(), "format": FORMAT}
        _atomic_write(library, data)
        _atomic_write(sidecar, json.dumps(meta).encode())
    except OSError:
        return built
    _evict(root, keep=library)
    return str(library)


def info() -> DiskCacheInfo:
    """The cache's directory, content and this process's counts.

    Examples
    --------
    >>> from appdyn.dynamics import diskcache
    >>> i = diskcache.info()
    >>> i.limit > 0 and i.entries >= 0
    True
    """
    root = directory()
    entries = _entries(root) if root is not None else []
    with _lock:
        counts = dict(_counts)
    return DiskCacheInfo(None if root is None else str(root), len(entries),
                         sum(size for _, size, _ in entries), limit(), **counts)


def clear() -> int:
    """Delete every artifact of the cache directory; returns how many.

    Examples
    --------
    >>> import tempfile
    >>> from appdyn.dynamics import diskcache
    >>> with tempfile.TemporaryDirectory() as d:
    ...     old = diskcache.configure(directory=d)
    ...     n = diskcache.clear()
    ...     _ = diskcache.configure(**old)
    >>> n
    0
    """
    root = directory()
    if root is None:
        return 0
    entries = _entries(root)
    for library, _, _ in entries:
        _unlink(library)
        _unlink(library.with_suffix(".json"))
    for tmp in root.glob(".tmp-*") if root.is_dir() else ():
        _unlink(tmp)
    return len(entries)


# ---------------------------------------------------------------------------------------
def _paths(root: Path, key: str, suffix: str = ".so") -> tuple[Path, Path]:
    return root / f"{key}{suffix}", root / f"{key}.json"


def _count(name: str) -> None:
    with _lock:
        _counts[name] += 1


def _unlink(path: Path) -> None:
    try:
        path.unlink()
    except OSError:
        pass


def _atomic_write(path: Path, data: bytes) -> None:
    import tempfile  # (stdlib, imported on the first store)

    fd, tmp = tempfile.mkstemp(prefix=f".tmp-{path.stem[:16]}-", suffix=path.suffix,
                               dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as out:
            out.write(data)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        _unlink(Path(tmp))
        raise


def _entries(root: Path) -> list:
    """``(library or object, size with its sidecar, last use)`` of every artifact."""
    out = []
    try:
        libraries = [*root.glob("*.so"), *root.glob("*.o")]
    except OSError:
        return out
    for library in libraries:
        try:
            st = library.stat()
        except OSError:
            continue
        try:
            extra = library.with_suffix(".json").stat().st_size
        except OSError:
            extra = 0
        out.append((library, st.st_size + extra, st.st_mtime))
    return out


def _evict(root: Path, keep: Path) -> None:
    """Delete the least recently used artifacts beyond `limit` (never ``keep``) and stale
    temporary files."""
    now = time.time()
    for tmp in root.glob(".tmp-*"):
        try:
            if now - tmp.stat().st_mtime > _STALE_TMP:
                tmp.unlink()
        except OSError:
            pass
    entries = sorted(_entries(root), key=lambda e: e[2])
    total, bound = sum(e[1] for e in entries), limit()
    for library, size, _ in entries:
        if total <= bound:
            break
        if library == keep:
            continue
        _unlink(library)
        _unlink(library.with_suffix(".json"))
        total -= size
        _count("evicted")


_IDS: dict = {}


def _compiler_id(compiler: str) -> str:
    """The compiler's resolved path, size and modification time (an upgrade changes it)."""
    out = _IDS.get(compiler)
    if out is None:
        real = os.path.realpath(compiler)
        try:
            st = os.stat(real)
            out = f"{real}:{st.st_size}:{st.st_mtime_ns}"
        except OSError:
            out = real
        _IDS[compiler] = out
    return out


def _machine_id() -> str:
    """Architecture and CPU (model name and instruction-set flags, on Linux)."""
    out = _IDS.get("machine")
    if out is None:
        cpu = ""
        try:
            with open("/proc/cpuinfo") as f:
                lines = {}
                for line in f:
                    name, _, value = line.partition(":")
                    name = name.strip()
                    if name in ("model name", "flags", "Features", "CPU part") and name not in lines:
                        lines[name] = value.strip()
                    if not line.strip() and lines:
                        break
            cpu = json.dumps(lines, sort_keys=True)
        except OSError:
            pass
        out = _IDS["machine"] = f"{platform.system()}:{platform.machine()}:{cpu}"
    return out
