"""The distribution installs one import name, ``appdyn``, and nothing generic at the top level."""
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

import appdyn

ROOT = Path(__file__).resolve().parents[1]
# what a wheel is built from (pyproject.toml, setup.py and the source folders)
SOURCES = ("appdyn", "dynamics", "ocp", "problems", "pyproject.toml", "setup.py", "README.md",
           "LICENSE")


def test_version_is_the_distributions():
    from importlib.metadata import version

    assert appdyn.__version__ == version("appdyn")
    assert appdyn.__version__.count(".") >= 2


def test_subpackages_by_attribute_and_import():
    from appdyn.dynamics import rigid_body
    from appdyn.ocp import Problem
    from appdyn.problems import slew

    assert appdyn.dynamics.rigid_body is rigid_body
    assert appdyn.ocp.Problem is Problem and callable(slew.time_optimal)
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        appdyn.nothing  # noqa: B018


def test_no_generic_top_level_module_is_imported():
    """Every module of the library lives under ``appdyn.``: nothing imported as ``dynamics``,
    ``ocp`` or ``problems`` (which a user's own file of that name would shadow)."""
    code = ("import sys, appdyn.problems.cli, appdyn.problems.slew, appdyn.ocp, appdyn.dynamics;"
            "bad = [m for m in sys.modules if m.split('.')[0] in ('dynamics', 'ocp', 'problems')];"
            "print(bad); sys.exit(1 if bad else 0)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stdout + out.stderr


def test_a_users_dynamics_py_does_not_shadow_the_library(tmp_path):
    for name in ("dynamics", "ocp", "problems"):
        (tmp_path / f"{name}.py").write_text("raise RuntimeError('the user\\'s own module')\n")
    code = ("import appdyn; from appdyn.dynamics import rigid_body; from appdyn.ocp import solve;"
            "from appdyn.problems import slew; print(rigid_body([1.0, 2.0, 3.0]).nx)")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    out = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True,
                         timeout=300, env=env)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "7"


def test_cli_version():
    out = subprocess.run([sys.executable, "-m", "appdyn.problems.cli", "--version"],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == f"appdyn {appdyn.__version__}"


def test_wheel_installs_only_appdyn(tmp_path):
    """Build the wheel from a copy of the sources and read its file list."""
    src = tmp_path / "src"
    src.mkdir()
    for name in SOURCES:
        path = ROOT / name
        if path.is_dir():
            shutil.copytree(path, src / name, ignore=shutil.ignore_patterns("__pycache__"))
        else:
            shutil.copy2(path, src / name)
    out = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
                          "--quiet", "-w", str(tmp_path / "dist"), str(src)],
                         capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stdout + out.stderr
    wheel, = (tmp_path / "dist").glob("appdyn-*.whl")
    names = zipfile.ZipFile(wheel).namelist()
    tops = {n.split("/")[0] for n in names}
    assert tops == {"appdyn", f"appdyn-{appdyn.__version__}.dist-info"}, tops
    for expected in ("appdyn/__init__.py", "appdyn/py.typed", "appdyn/dynamics/__init__.py",
                     "appdyn/ocp/solve.py", "appdyn/problems/cli/__init__.py",
                     "appdyn/problems/gains/launch_vehicle.toml"):
        assert expected in names, expected
    meta = zipfile.ZipFile(wheel).read(f"appdyn-{appdyn.__version__}.dist-info/METADATA").decode()
    assert "License-Expression: MIT" in meta
    assert any(n.endswith("licenses/LICENSE") for n in names)
