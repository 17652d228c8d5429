"""Pieces shared by the `appdyn` commands: argparse value types, argv clean-up, output-path
checks, strict JSON, progress lines and output writing (figures are saved here: the library
only builds them).

Exit-code convention of every command: 0 done (and verified where the command checks its
answer), 1 numerical failure or failed verification, 2 bad input (argparse-style one-line
``appdyn ...: error: ...`` message naming the option, printed before any computation where
the input can be checked up front).
"""
from __future__ import annotations

import argparse
import contextlib
import math
import os
import re
import sys
import time
from pathlib import Path



__all__ = ["vector", "number", "positive", "integer", "output_file", "attach_negative_values",
           "strict_jsonable", "strict_json", "Progress", "progress_enabled", "write_outputs",
           "save_figure", "write_json", "inertia_matrix", "same_file", "PLOT_SUFFIXES"]

#: file name suffixes a ``--plot`` may have (matplotlib infers the format from them)
PLOT_SUFFIXES = (".png", ".pdf", ".svg")


def vector(n_allowed):
    """argparse type: comma-separated finite floats, with one of the allowed lengths."""

    def parse(text):
        try:
            vals = [float(v) for v in text.replace(" ", "").split(",") if v != ""]
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected comma-separated numbers, got {text!r}")
        if len(vals) not in n_allowed:
            raise argparse.ArgumentTypeError(
                f"expected {' or '.join(map(str, n_allowed))} comma-separated numbers, got {len(vals)}"
            )
        if not all(math.isfinite(v) for v in vals):
            raise argparse.ArgumentTypeError(f"numbers must be finite, got {text!r}")
        import numpy as np  # (imported on use: ``appdyn --help`` stays light)

        return np.array(vals)

    return parse


def number(text):
    """argparse type: one finite float."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}")
    if not math.isfinite(v):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}")
    return v


def positive(text):
    """argparse type: one finite float > 0."""
    v = number(text)
    if v <= 0:
        raise argparse.ArgumentTypeError(f"expected a positive number, got {text!r}")
    return v


def integer(minimum):
    """argparse type: an integer ``>= minimum``."""

    def parse(text):
        try:
            v = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None
        if v < minimum:
            raise argparse.ArgumentTypeError(f"expected an integer >= {minimum}, got {v}")
        return v

    return parse


def output_file(suffixes=None):
    """argparse type: a file the command can create, checked before any computation.

    The parent directory must exist and be writable, the name must not be an existing
    directory, and (when ``suffixes`` is given) it must end in one of ``suffixes``.
    """

    def parse(text):
        if not text or text.endswith(("/", os.sep)):
            raise argparse.ArgumentTypeError(f"expected a file name, got {text!r}")
        path = Path(text).expanduser()
        if path.is_dir():
            raise argparse.ArgumentTypeError(f"{text!r} is a directory, expected a file name")
        if suffixes is not None and path.suffix.lower() not in suffixes:
            raise argparse.ArgumentTypeError(
                f"file name must end in {', '.join(suffixes)}, got {text!r}")
        parent = path.parent
        if not parent.is_dir():
            raise argparse.ArgumentTypeError(f"directory {str(parent)!r} does not exist")
        if not os.access(parent, os.W_OK | os.X_OK):
            raise argparse.ArgumentTypeError(f"directory {str(parent)!r} is not writable")
        if path.exists() and not os.access(path, os.W_OK):
            raise argparse.ArgumentTypeError(f"{text!r} exists and is not writable")
        return str(path)

    return parse


def _is_negative_numbers(text) -> bool:
    """True for an option value made of numbers that starts with a minus sign: ``-1``,
    ``-1,0.1,0.8``, ``-1e-3``, ``-1:1:5``, ``-inf``."""
    text = text.strip()
    if not text.startswith("-") or text.startswith("--"):
        return False
    parts = [v for v in re.split(r"[,:]", text.replace(" ", "")) if v != ""]
    try:
        [float(v) for v in parts]
    except ValueError:
        return False
    return bool(parts)


def _value_options(parser) -> set:
    """Option strings (``--w0`` ...) that take a value, in ``parser`` and its sub-parsers."""
    found, todo, seen = set(), [parser], set()
    while todo:
        p = todo.pop()
        if id(p) in seen:
            continue
        seen.add(id(p))
        for action in p._actions:  # argparse keeps no public list of actions
            if isinstance(action, argparse._SubParsersAction):
                todo.extend(action.choices.values())
            elif action.option_strings and action.nargs != 0:
                found.update(s for s in action.option_strings if s.startswith("--"))
    return found


def attach_negative_values(parser, argv) -> list:
    """``['--w0', '-1,0.1,0.8']`` -> ``['--w0=-1,0.1,0.8']`` for options that take a value.

    argparse reads a value starting with ``-`` as an option unless it is a plain negative
    number, so ``--w0 -1,0.1,0.8`` and ``--values -1:1:5`` would fail. Only a token made of
    numbers (comma or colon separated) following an option that takes a value is attached.
    """
    takes_value = _value_options(parser)
    out, i = [], 0
    argv = list(argv)
    while i < len(argv):
        tok = argv[i]
        if (tok in takes_value and i + 1 < len(argv)
                and _is_negative_numbers(argv[i + 1])):
            out.append(f"{tok}={argv[i + 1]}")
            i += 2
            continue
        if tok == "--":
            out.extend(argv[i:])
            break
        out.append(tok)
        i += 1
    return out


# ------------------------------------------------------------------------------ JSON
# one converter for every result (dynamics.serialize); the CLI's names for it
def strict_jsonable(data):
    """`dynamics.serialize.jsonable` (imported on use: ``appdyn --help`` imports no library)."""
    from appdyn.dynamics.serialize import jsonable

    return jsonable(data)


def strict_json(data) -> str:
    """`dynamics.serialize.to_json` (imported on use)."""
    from appdyn.dynamics.serialize import to_json

    return to_json(data)


# -------------------------------------------------------------------------- progress
class Progress:
    """``(done, total)`` callback writing a progress line to ``stream`` (stderr).

    On a terminal the line is redrawn in place (at most 10 times a second); otherwise a line
    is written every ``interval`` seconds. `close` ends the line. ``enabled=False`` makes
    every call a no-op.
    """

    def __init__(self, label, *, enabled=True, stream=None, interval=2.0):
        self.label, self.enabled = label, enabled
        self.stream = sys.stderr if stream is None else stream
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.interval = 0.1 if self.tty else interval
        self.start = time.perf_counter()
        self.last = -math.inf
        self.shown = False

    def __call__(self, done, total):
        if not self.enabled:
            return
        now = time.perf_counter()
        if now - self.last < self.interval and done < total:
            return
        self.last = now
        pct = 100.0 * done / total if total else 100.0
        text = f"{self.label}: {done}/{total} ({pct:.0f}%), {now - self.start:.1f} s"
        self.stream.write(f"\r{text}\033[K" if self.tty else text + "\n")
        self.stream.flush()
        self.shown = True

    def close(self):
        if self.enabled and self.shown and self.tty:
            self.stream.write("\n")
            self.stream.flush()


def progress_enabled(args) -> bool:
    """Progress lines: with ``--progress``, or when stderr is a terminal; never with ``--quiet``."""
    if getattr(args, "quiet", False):
        return False
    return bool(getattr(args, "progress", False)) or sys.stderr.isatty()


# --------------------------------------------------------------------------- outputs
def inertia_matrix(values):
    """``--inertia`` values: 3 principal moments as they are, 9 entries as a 3x3 matrix."""
    return values if values.size == 3 else values.reshape(3, 3)


def same_file(a, b) -> bool:
    """Whether two output options name the same file (both given)."""
    return bool(a and b and Path(a).resolve() == Path(b).resolve())


def save_figure(fig, path) -> None:
    """Save a `matplotlib.figure.Figure` (format from the suffix, `PLOT_SUFFIXES`)."""
    fig.savefig(path, dpi=110)


def write_json(data, path) -> None:
    """Write ``data`` to ``path`` as strict JSON."""
    Path(path).write_text(strict_json(data) + "\n")


def add_executor_options(parser) -> None:
    """``--workers N`` (a local process pool) or ``--scheduler ADDRESS`` (a Dask cluster):
    where the independent runs of a command go (`executor_from`)."""
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--workers", type=integer(1), metavar="N",
                       help="run the independent pieces on N local processes (default: serial)")
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="run them on a Dask cluster (e.g. tcp://host:8786; needs the "
                            "[distributed] extra and appdyn on every worker)")


@contextlib.contextmanager
def executor_from(args):
    """The executor of ``--workers`` / ``--scheduler`` (None: serial), shut down on exit."""
    workers, scheduler = getattr(args, "workers", None), getattr(args, "scheduler", None)
    if scheduler:
        try:
            from distributed import Client
        except ImportError:
            raise ValueError("--scheduler needs Dask: pip install 'appdyn[distributed]'") from None
        client = Client(scheduler)
        try:
            yield client.get_executor()
        finally:
            client.close()
    elif workers and workers > 1:
        from appdyn.dynamics.executors import process_pool

        with process_pool(workers) as pool:
            yield pool
    else:
        yield None


def finish(result, command: str, *, plot=None, json=None) -> int:
    """Print ``result``, write ``--plot``/``--json`` (`write_outputs`), say why on stderr when
    it is not a success; the exit status: 0 verified, 1 not."""
    print(result)
    write_outputs(result, plot=plot, json=json)
    if not result.success:
        print(f"appdyn {command}: {result.message}", file=sys.stderr)
    return 0 if result.success else 1


def write_outputs(result, *, plot=None, json=None) -> None:
    """Save the figure of ``result.plot()`` and strict JSON of ``result.to_dict()`` where
    asked, saying so on stdout."""
    if plot:
        save_figure(result.plot(), plot)
        print(f"plot written to {plot}")
    if json:
        write_json(result.to_dict(), json)
        print(f"report written to {json}")
