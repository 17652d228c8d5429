"""Every example in the README runs as written, and the README stays short.

Python blocks (```python) are executed in order in one namespace; console blocks (```console)
have their `appdyn ...` lines run through the CLI entry point, which must exit 0. Blocks
marked ```python no-test or console lines with `make` are skipped (they are set-up commands,
exercised by CI itself). The ``# -> expected`` convention is in `markdown_examples`.
"""
import re
import shlex
from pathlib import Path

import pytest

from appdyn.problems.cli import main

from .markdown_examples import check_printed, console_lines, run_python_blocks

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
MAX_LINES = 200


def test_check_printed_catches_a_wrong_value():
    check_printed("3.243083", "3.2430833")
    check_printed("True 0 rk8 (7, 1001)", "True 0 rk8 (7, 1001)")
    check_printed("5e-14", "5.229150445984487e-14")
    check_printed("[0.5236 0 0]", "[5.23598776e-01 0.00000000e+00 1.2e-17]")
    for wrong, printed in (("3.243083", "3.2430853"), ("5e-14", "6.1e-14"),
                           ("True True", "True False"), ("unstable", "marginally stable")):
        with pytest.raises(AssertionError):
            check_printed(wrong, printed)


def test_readme_is_short():
    """A newcomer reads it in five minutes: at most 200 lines (it was 992)."""
    lines = README.read_text().splitlines()
    assert len(lines) <= MAX_LINES, f"README.md has {len(lines)} lines, at most {MAX_LINES}"


def test_readme_links_resolve():
    """Every relative link of the README names a file or folder of the checkout."""
    links = re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", README.read_text())
    local = [link for link in links if "://" not in link]
    assert local, "the README links to no docs page"
    missing = [link for link in local if not (ROOT / link).exists()]
    assert not missing, f"README links to missing files {missing}"


@pytest.mark.slow
def test_readme_python_examples_run(tmp_path, monkeypatch):
    """Every python block runs; every ``# -> value`` line prints that value."""
    monkeypatch.chdir(tmp_path)
    checked = run_python_blocks(README)
    assert checked >= 6, f"only {checked} README lines have a checked printed value"


@pytest.mark.parametrize("line", console_lines(README))
@pytest.mark.slow
def test_readme_cli_examples_run(line, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(shlex.split(line)[1:]) == 0
