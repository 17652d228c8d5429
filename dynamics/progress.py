"""Progress for people: ``progress=True`` shows a bar, a callable still gets ``(done, total)``.

Every long-running function of appdyn (`simulate` and its batches, sweeps, dispersions,
maneuver tables) takes ``progress``:

- ``None`` or ``False``: quiet (the default: library code never prints on its own);
- a callable ``progress(done, total)``: called as the work advances (``total`` may grow, as
  when ``method='auto'`` starts another run; it never falls back below ``done``);
- ``True``: a bar on ``sys.stderr`` (never stdout): `tqdm` when it is installed, else a plain
  text bar, redrawn in place on a terminal and written at most every 2 s otherwise; the bar
  closes when the call returns.

`progress_reporter` turns the argument into a callable and a closer; a function wraps its
work as ``with progress_reporter(progress, "simulate") as report: ...``.
"""
from __future__ import annotations

import contextlib
import functools
import sys
import time
from typing import Callable

__all__ = ["TextBar", "progress_reporter", "check_progress", "accepts_progress_bar",
           "accepts_round_bar"]


def check_progress(progress, name: str = "progress"):
    """``progress`` if it is None, a bool or a callable, else TypeError naming ``name``.

    Examples
    --------
    >>> from appdyn.dynamics.progress import check_progress
    >>> check_progress(True), check_progress(None)
    (True, None)
    """
    if progress is None or isinstance(progress, bool) or callable(progress):
        return progress
    raise TypeError(f"`{name}` must be None, True/False or a callable (done, total), "
                    f"got {type(progress).__name__}")


class TextBar:
    """A ``(done, total)`` callable drawing ``label |#####     | 52% 520/1000 3.1 s`` on
    ``stream`` (stderr): in place on a terminal (at most 10 redraws a second), one line every
    ``interval`` seconds otherwise. `close` ends the line.

    Examples
    --------
    >>> import io
    >>> from appdyn.dynamics.progress import TextBar
    >>> out = io.StringIO()
    >>> bar = TextBar("demo", stream=out, width=10)
    >>> bar(5, 10); bar(10, 10); bar.close()
    >>> out.getvalue().splitlines()[-1].split(" 100%")[0]
    'demo |##########|'
    """

    def __init__(self, label: str, *, stream=None, interval: float = 2.0, width: int = 30):
        self.label, self.width = label, width
        self.stream = sys.stderr if stream is None else stream
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.interval = 0.1 if self.tty else interval
        self.start = time.perf_counter()
        self.last = -float("inf")
        self.shown = False
        self.state = self.drawn = (0, 0)

    def __call__(self, done: int, total: int) -> None:
        self.state = (done, total)
        now = time.perf_counter()
        if now - self.last < self.interval and done < total:
            return
        self.last = now
        self._draw(done, total, now)

    def _draw(self, done, total, now) -> None:
        frac = min(1.0, done / total) if total else 1.0
        fill = int(round(frac * self.width))
        text = (f"{self.label} |{'#' * fill}{' ' * (self.width - fill)}| {100 * frac:3.0f}% "
                f"{done}/{total} {now - self.start:.1f} s")
        self.stream.write(f"\r{text}\033[K" if self.tty else text + "\n")
        self.stream.flush()
        self.shown, self.drawn = True, (done, total)

    def close(self) -> None:
        """Draw the final state (if not drawn) and end the line."""
        done, total = self.state
        if total and self.drawn != self.state:
            self._draw(done, total, time.perf_counter())
        if self.shown and self.tty:
            self.stream.write("\n")
            self.stream.flush()


class _Tqdm:
    """``(done, total)`` onto a tqdm bar (its total updated as it grows)."""

    def __init__(self, label: str):
        from tqdm.auto import tqdm

        self.bar = tqdm(total=0, desc=label, file=sys.stderr, leave=False)

    def __call__(self, done: int, total: int) -> None:
        if total != self.bar.total:
            self.bar.total = total
        self.bar.update(done - self.bar.n)

    def close(self) -> None:
        self.bar.close()


def _bar(label: str):
    try:
        return _Tqdm(label)
    except ImportError:
        return TextBar(label)


@contextlib.contextmanager
def progress_reporter(progress, label: str):
    """The ``(done, total)`` callable for ``progress`` (None when quiet); a bar of ``True``
    is closed on leaving the block.

    Parameters
    ----------
    progress : None, bool or callable
    label : str
        The bar's label (the function's name).

    Yields
    ------
    callable or None

    Examples
    --------
    >>> from appdyn.dynamics.progress import progress_reporter
    >>> seen = []
    >>> with progress_reporter(lambda d, t: seen.append((d, t)), "demo") as report:
    ...     report(1, 2); report(2, 2)
    >>> seen
    [(1, 2), (2, 2)]
    """
    progress = check_progress(progress)
    if progress is None or progress is False:
        yield None
        return
    if progress is not True:
        yield progress
        return
    bar = _bar(label)
    try:
        yield bar
    finally:
        bar.close()




def accepts_progress_bar(label: str):
    """Decorator: the function's keyword ``progress`` may also be ``True`` (a bar labelled
    ``label``, closed when the call returns); the function itself sees a callable or None.

    Examples
    --------
    >>> from appdyn.dynamics.progress import accepts_progress_bar
    >>> @accepts_progress_bar("count")
    ... def count(n, *, progress=None):
    ...     for k in range(n):
    ...         if progress is not None:
    ...             progress(k + 1, n)
    ...     return n
    >>> count(3, progress=lambda d, t: print(d, t))
    1 3
    2 3
    3 3
    3
    """
    def wrap(fun):
        @functools.wraps(fun)
        def call(*args, progress=None, **kwargs):
            with progress_reporter(progress, label) as report:
                return fun(*args, progress=report, **kwargs)
        return call
    return wrap


def accepts_round_bar(label: str, rounds: Callable[[dict], int]):
    """Decorator for a function whose ``progress`` callable receives one report per round
    (`ocp.refine`): ``progress=True`` becomes a bar counting the rounds against at most
    ``rounds(kwargs)``; at the end it shows the rounds made as the total.

    Examples
    --------
    >>> import io, sys
    >>> from appdyn.dynamics.progress import accepts_round_bar
    >>> @accepts_round_bar("rounds", lambda kw: kw.get("max_rounds", 5) + 1)
    ... def work(*, max_rounds=5, progress=None):
    ...     for r in range(3):
    ...         if progress is not None:
    ...             progress(f"round {r}")
    ...     return 3
    >>> work(progress=print)
    round 0
    round 1
    round 2
    3
    """
    def wrap(fun):
        @functools.wraps(fun)
        def call(*args, progress=None, **kwargs):
            if progress is not True:
                return fun(*args, progress=check_progress(progress) or None, **kwargs)
            bar, done = _bar(label), [0]
            total = max(1, int(rounds(kwargs)))

            def report(_round):
                done[0] += 1
                bar(done[0], max(total, done[0] + 1))

            try:
                return fun(*args, progress=report, **kwargs)
            finally:
                if done[0]:
                    bar(done[0], done[0])
                bar.close()
        return call
    return wrap
