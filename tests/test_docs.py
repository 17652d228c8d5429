"""The docs' pages: their examples run as written, and the API reference covers every public
name.

Every python block of the quickstart, the conventions page and each user-guide page runs
(each page in its own namespace, in order) and every ``print(...)  # -> value`` line must
print that value (the README's convention, `markdown_examples`); the ``$ appdyn ...`` lines
of their console blocks must exit 0. The full build (``make docs``, warnings as errors) is
run by CI after the tests.
"""
import importlib.util
import re
import runpy
import shlex
from pathlib import Path

import pytest

from appdyn.problems.cli import main

from .markdown_examples import console_lines, run_python_blocks

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
GUIDE = sorted((DOCS / "guide").glob("*.md"))
PAGES = [DOCS / "quickstart.md", DOCS / "conventions.md"] + GUIDE
#: pages that are prose only (no runnable example)
PROSE = {"index.md", "architecture.md", "cli.md", "parallel.md"}
#: user-guide pages the issue asks for (one per capability)
CAPABILITIES = {"scene", "models", "attitude", "stability", "optimal_control", "slews", "trajectories",
                "gains", "dispersion", "wheels", "launch_vehicle", "cli", "parallel"}


EXAMPLES = sorted((ROOT / "examples").glob("plot_*.py"))
#: the gallery's first examples, as the issue lists them: (a) to (e)
GALLERY = {"plot_wheel_slew", "plot_own_model", "plot_dispersion", "plot_gains_bode",
           "plot_delta3_ascent"}


def _api():
    spec = importlib.util.spec_from_file_location("docs_api", DOCS / "_api.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_one_guide_page_per_capability():
    assert CAPABILITIES <= {page.stem for page in GUIDE}
    index = (DOCS / "guide" / "index.md").read_text()
    assert all(f"\n{name}\n" in index for name in CAPABILITIES), "a page is not in the toctree"


@pytest.mark.parametrize("page", [p for p in PAGES if p.name not in PROSE],
                         ids=lambda p: p.stem)
@pytest.mark.slow
def test_page_python_examples_run(page, tmp_path, monkeypatch):
    """Every python block of the page runs; every ``# -> value`` line prints that value."""
    monkeypatch.chdir(tmp_path)
    assert run_python_blocks(page) >= 1, f"{page.name} checks no printed value"


@pytest.mark.parametrize("line", [line for page in PAGES for line in console_lines(page)])
@pytest.mark.slow
def test_page_cli_examples_run(line, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(shlex.split(line)[1:]) == 0


@pytest.mark.slow
def test_api_reference_lists_every_public_name(tmp_path):
    """Each name in the ``__all__`` of appdyn.dynamics, appdyn.ocp, appdyn.problems and their
    public subpackages has an autosummary entry (a constant: a ``py:data`` description) on
    one reference page, or a link from its package's page to the subpackage page that
    documents it (same object, same name)."""
    api = _api()
    packages = api.public_packages()
    for name in ("appdyn.dynamics", "appdyn.ocp", "appdyn.problems",
                 "appdyn.dynamics.attitude", "appdyn.ocp.phases", "appdyn.problems.slew"):
        assert name in packages
    assert not [p for p in packages if "._" in p]
    api.write_api(tmp_path)
    documented = set()
    for package in packages:
        text = (tmp_path / f"{package}.rst").read_text()
        entries = text.split(".. autosummary::")[1].split("\n\n", 2)[1] \
            if ".. autosummary::" in text else ""
        documented |= {f"{package}.{line.strip()}" for line in entries.splitlines()}
        documented |= {f"{package}.{name}" for name in
                       re.findall(r"^\.\. py:data:: (\w+)$", text, flags=re.M)}
    missing = []
    for package in packages:
        text = (tmp_path / f"{package}.rst").read_text()
        for name in api.public_names(package):
            target = api.home(package, name, packages)
            if target == package:
                ok = f"{package}.{name}" in documented
            else:
                ok = f"<{target}.{name}>" in text or f"<{target}>" in text
                ok = ok and (target in packages and target.endswith(f".{name}")
                             or f"{target}.{name}" in documented)
            if not ok:
                missing.append(f"{package}.{name}")
    assert not missing, f"not in the API reference: {missing}"
    assert len(documented) >= 250


def test_constant_comments_are_found():
    """``#:`` comment lines right above a module-level assignment, a ``#:`` comment on its
    line or a string after it document it (Sphinx's conventions); a plain comment or a blank
    line between does not."""
    api = _api()
    source = ("#: the first\n#: and second line\nA = 1\n# plain\nB = 2\n#: c\n\nC = 3\n"
              "#: typed\nD: float = 4.0\nE, F = 5, 6\nG = 7  #: inline\n"
              "H = 8\n\"\"\"after\n   it\"\"\"\n")
    assert api.comments_above(source) == {"A": "the first and second line", "D": "typed",
                                          "G": "inline", "H": "after it"}
    assert api.constant_doc("appdyn.problems.stability", "ZERO_RTOL").startswith(
        "eigenvalues with")


def test_guide_api_links_name_documented_objects():
    """Each ``{py:obj}`` link of a guide page names the page an object is documented on
    (its package's, not a re-export), so that Sphinx resolves it."""
    api = _api()
    packages = api.public_packages()
    targets = [(page.name, t) for page in GUIDE
               for t in re.findall(r"\{py:obj\}`~?([\w.]+)`", page.read_text())]
    assert len(targets) >= 40
    wrong = []
    for page, target in targets:
        package, _, name = target.rpartition(".")
        if package not in packages or name not in api.public_names(package) \
                or api.home(package, name, packages) != package:
            wrong.append((page, target))
    assert not wrong, f"links to names not documented there: {wrong}"


def test_gallery_has_the_examples_asked_for():
    assert GALLERY <= {path.stem for path in EXAMPLES}


@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.stem)
@pytest.mark.slow
def test_gallery_example_runs(script, tmp_path, monkeypatch):
    """Each example checks itself (``assert`` against its closed form, peer library or
    conservation law) and draws at least one figure, as sphinx-gallery will run it."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    monkeypatch.chdir(tmp_path)
    plt.close("all")
    runpy.run_path(str(script), run_name="__main__")
    assert plt.get_fignums(), f"{script.name} drew no figure (sphinx-gallery shows pyplot's)"
    plt.close("all")
