"""Packaging of the source folders under one import name: the repository keeps its top-level
folders ``dynamics/``, ``ocp/`` and ``problems/``; they install as ``appdyn.dynamics``,
``appdyn.ocp`` and ``appdyn.problems`` (nothing generic at the top level of site-packages).
Everything else is in pyproject.toml."""
from setuptools import find_packages, setup

_FOLDERS = ("dynamics", "ocp", "problems")
_SUB = find_packages(include=[f"{name}*" for name in _FOLDERS])

setup(
    packages=["appdyn"] + [f"appdyn.{name}" for name in _SUB],
    package_dir={"appdyn": "appdyn", **{f"appdyn.{name}": name for name in _FOLDERS}},
)
