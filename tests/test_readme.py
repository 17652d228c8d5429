"""Every example in the README runs as written.

Python blocks (```python) are executed in order in one namespace; console blocks (```console)
have their `appdyn ...` lines run through the CLI entry point, which must exit 0. Blocks
marked ```python no-test or console lines with `make` are skipped (they are set-up commands,
exercised by CI itself).
"""
import re
import shlex
from pathlib import Path

import pytest

from problems.cli import main

README = Path(__file__).resolve().parents[1] / "README.md"
BLOCK = re.compile(r"^```(\w+)([^\n]*)\n(.*?)^```", re.S | re.M)


def blocks(kind):
    return [body for lang, flags, body in BLOCK.findall(README.read_text())
            if lang == kind and "no-test" not in flags]


def test_readme_python_examples_run(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code = blocks("python")
    assert code, "README has no python examples"
    namespace = {}
    for body in code:
        exec(compile(body, str(README), "exec"), namespace)


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
