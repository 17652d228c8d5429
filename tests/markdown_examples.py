"""Running the examples of a markdown page (the README, the docs' user-guide pages) as tests.

Python blocks (```python) are executed in order in one namespace; console blocks
(```console) have their ``$ appdyn ...`` lines run through the CLI entry point. Blocks
marked ```python no-test are skipped (set-up commands, or code that needs a cluster).

A checked example line: ``print(...)  # -> EXPECTED; explanation``. Every number, word and
literal of EXPECTED must appear, in order, in what the line printed; a number matches when
the printed one rounds to it at the precision it is written with (``5e-14`` matches
5.229e-14, ``3.243083`` matches 3.2430833).
"""
from __future__ import annotations

import re
import sys
from pathlib import Path

__all__ = ["BLOCK", "blocks", "check_printed", "token_matches", "run_python_blocks",
           "console_lines"]

BLOCK = re.compile(r"^```(\w+)([^\n]*)\n(.*?)^```", re.S | re.M)
EXPECT = re.compile(r"#\s*->\s*([^;]*)")
TOKEN = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|[A-Za-z_]\w*")


def blocks(path: Path, kind: str) -> list[str]:
    """The bodies of the ```KIND blocks of ``path`` not marked ``no-test``."""
    return [body for lang, flags, body in BLOCK.findall(Path(path).read_text())
            if lang == kind and "no-test" not in flags]


def _is_number(token: str) -> bool:
    return bool(re.fullmatch(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?", token))


def _resolution(token: str) -> float:
    """Half a unit in the last digit written: 0.5e-14 for '5e-14', 0.5e-6 for '3.243083'."""
    mantissa, _, exponent = token.lower().partition("e")
    decimals = len(mantissa.split(".")[1]) if "." in mantissa else 0
    return 0.5 * 10.0 ** (int(exponent or 0) - decimals)


def token_matches(expected: str, printed: str) -> bool:
    """Does the printed token match the expected one (numbers to the digits written)?"""
    if _is_number(expected):
        return _is_number(printed) and abs(float(printed) - float(expected)) <= \
            _resolution(expected) * (1 + 1e-9)
    return expected == printed


def check_printed(expected_text: str, printed_text: str, where: str = "README") -> None:
    """Assert that every token of ``expected_text`` appears, in order, in ``printed_text``."""
    printed = TOKEN.findall(printed_text)
    i = 0
    for token in TOKEN.findall(expected_text):
        while i < len(printed) and not token_matches(token, printed[i]):
            i += 1
        assert i < len(printed), (f"{where} says {expected_text.strip()!r}; the line printed "
                                  f"{printed_text.strip()!r} (no match for {token!r})")
        i += 1


def run_python_blocks(path: Path) -> int:
    """Execute the python blocks of ``path`` in order in one namespace and check every
    ``print(...)  # -> value`` line; the number of lines checked. Raises AssertionError
    naming the page and line of a wrong value."""
    path = Path(path)
    text = path.read_text()
    code = [(text[:m.start(3)].count("\n"), body) for m in BLOCK.finditer(text)
            for lang, flags, body in [m.groups()] if lang == "python" and "no-test" not in flags]
    assert code, f"{path.name} has no python examples"
    lines = text.splitlines()
    namespace: dict = {}
    checked = 0
    for offset, body in code:
        printed: dict = {}

        def recording_print(*args, sep=" ", end="\n", **kwargs):
            frame = sys._getframe(1)
            if frame.f_code.co_filename == str(path):
                printed.setdefault(frame.f_lineno + offset, []).append(
                    sep.join(str(a) for a in args))

        namespace["print"] = recording_print
        exec(compile(body, str(path), "exec"), namespace)
        for k, line in enumerate(body.splitlines(), start=offset + 1):
            m = EXPECT.search(lines[k - 1])
            if m and line.lstrip().startswith("print("):
                assert k in printed, f"{path.name} line {k} printed nothing"
                check_printed(m.group(1), "\n".join(printed[k]), f"{path.name} line {k}")
                checked += 1
    return checked


def console_lines(path: Path) -> list[str]:
    """The ``appdyn ...`` command lines of the console blocks of ``path`` (``bench`` left
    out: it runs for minutes)."""
    found = []
    for body in blocks(path, "console"):
        for line in body.splitlines():
            line = line.strip()
            if line.startswith("$ appdyn ") and "bench" not in line:
                found.append(line[2:])
    return found
