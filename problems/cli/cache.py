"""``appdyn cache info|clear``: the persistent compile cache (`appdyn.dynamics.diskcache`).

``info`` prints the directory (or that the cache is off), the artifacts, their size and the
limit, and this process's hits and compiles; ``clear`` deletes every artifact.
"""
from __future__ import annotations

__all__ = ["add_parser", "check", "run"]


def add_parser(subparsers):
    """Add ``cache`` to ``subparsers``."""
    cache = subparsers.add_parser(
        "cache", help="the compile cache: where it is and what it holds, or empty it",
        description="The persistent compile cache: compiled models kept per user "
                    "($APPDYN_CACHE_DIR, else $XDG_CACHE_HOME/appdyn or ~/.cache/appdyn; "
                    "APPDYN_DISK_CACHE=0 turns it off).")
    cache.add_argument("action", choices=("info", "clear"),
                       help="info: directory, entries, size, limit; clear: delete every entry")
    cache.set_defaults(_parser=cache)
    return cache


def check(parser, args) -> None:
    """Nothing to check across options."""


def run(args) -> int:
    """Print the cache's state, or clear it; 0."""
    from appdyn.dynamics import diskcache

    if args.action == "clear":
        removed = diskcache.clear()
        where = diskcache.directory()
        print(f"removed {removed} entries from {where}" if where is not None
              else "the compile cache is off: nothing to clear")
        return 0
    info = diskcache.info()
    mb = 1024 * 1024
    print(f"directory: {info.directory if info.directory is not None else 'off (no disk cache)'}")
    print(f"entries:   {info.entries}")
    print(f"size:      {info.size / mb:.1f} MB of {info.limit / mb:.0f} MB")
    print(f"this process: {info.hits} loaded from the cache, {info.compiles} compiled"
          + (f" ({info.reused} translation units taken from the cache)" if info.reused else ""))
    return 0
