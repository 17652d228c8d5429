"""Every example in the README runs as written.

Python blocks (```python) are executed in order in one namespace; console blocks (```console)
have their `appdyn ...` lines run through the CLI entry point, which must exit 0. Blocks
marked ```python no-test or console lines with `make` are skipped (they are set-up commands,
exercised by CI itself).
"""
import re
import shlex
import sys
from pathlib import Path

import pytest

from appdyn.problems.cli import main

README = Path(__file__).resolve().parents[1] / "README.md"
BLOCK = re.compile(r"^```(\w+)([^\n]*)\n(.*?)^```", re.S | re.M)


def blocks(kind):
    return [body for lang, flags, body in BLOCK.findall(README.read_text())
            if lang == kind and "no-test" not in flags]


# A checked example line: ``print(...)  # -> EXPECTED; explanation``. Every number, word and
# literal of EXPECTED must appear, in order, in what the line printed; a number matches when
# the printed one rounds to it at the precision it is written with (``5e-14`` matches
# 5.229e-14, ``3.243083`` matches 3.2430833).
EXPECT = re.compile(r"#\s*->\s*([^;]*)")
TOKEN = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|[A-Za-z_]\w*")


def _is_number(token: str) -> bool:
    return bool(re.fullmatch(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?", token))


def _resolution(token: str) -> float:
    """Half a unit in the last digit written: 0.5e-14 for '5e-14', 0.5e-6 for '3.243083'."""
    mantissa, _, exponent = token.lower().partition("e")
    decimals = len(mantissa.split(".")[1]) if "." in mantissa else 0
    return 0.5 * 10.0 ** (int(exponent or 0) - decimals)


def token_matches(expected: str, printed: str) -> bool:
    if _is_number(expected):
        return _is_number(printed) and abs(float(printed) - float(expected)) <= \
            _resolution(expected) * (1 + 1e-9)
    return expected == printed


def check_printed(expected_text: str, printed_text: str) -> None:
    printed = TOKEN.findall(printed_text)
    i = 0
    for token in TOKEN.findall(expected_text):
        while i < len(printed) and not token_matches(token, printed[i]):
            i += 1
        assert i < len(printed), (f"README says {expected_text.strip()!r}; the line printed "
                                  f"{printed_text.strip()!r} (no match for {token!r})")
        i += 1


def test_check_printed_catches_a_wrong_value():
    check_printed("3.243083", "3.2430833")
    check_printed("True 0 rk8 (7, 1001)", "True 0 rk8 (7, 1001)")
    check_printed("5e-14", "5.229150445984487e-14")
    check_printed("[0.5236 0 0]", "[5.23598776e-01 0.00000000e+00 1.2e-17]")
    for wrong, printed in (("3.243083", "3.2430853"), ("5e-14", "6.1e-14"),
                           ("True True", "True False"), ("unstable", "marginally stable")):
        with pytest.raises(AssertionError):
            check_printed(wrong, printed)


def test_readme_python_examples_run(tmp_path, monkeypatch):
    """Every python block runs; every ``# -> value`` line prints that value."""
    monkeypatch.chdir(tmp_path)
    text = README.read_text()
    code = [(text[:m.start(3)].count("\n"), body) for m in BLOCK.finditer(text)
            for lang, flags, body in [m.groups()] if lang == "python" and "no-test" not in flags]
    assert code, "README has no python examples"
    lines = text.splitlines()
    namespace = {}
    checked = 0
    for offset, body in code:
        printed = {}

        def recording_print(*args, sep=" ", end="\n", **kwargs):
            frame = sys._getframe(1)
            if frame.f_code.co_filename == str(README):
                printed.setdefault(frame.f_lineno + offset, []).append(
                    sep.join(str(a) for a in args))

        namespace["print"] = recording_print
        exec(compile(body, str(README), "exec"), namespace)
        for k, line in enumerate(body.splitlines(), start=offset + 1):
            m = EXPECT.search(lines[k - 1])
            if m and line.lstrip().startswith("print("):
                assert k in printed, f"README line {k} printed nothing"
                check_printed(m.group(1), "\n".join(printed[k]))
                checked += 1
    assert checked >= 10, f"only {checked} README lines have a checked printed value"


def console_lines():
    for body in blocks("console"):
        for line in body.splitlines():
            line = line.strip()
            if line.startswith("$ appdyn ") and "bench" not in line:
                yield line[2:]


@pytest.mark.parametrize("line", list(console_lines()))
def test_readme_cli_examples_run(line, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(shlex.split(line)[1:]) == 0
