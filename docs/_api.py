"""The API reference pages, written from the packages' ``__all__`` at every docs build.

`public_packages` lists ``appdyn.dynamics``, ``appdyn.ocp``, ``appdyn.problems`` and every
public subpackage below them (no part of the name starting with ``_``); `write_api` writes
one page per package, an autosummary table of every name in its ``__all__`` with a page
generated for each, and an index page ``api/index.rst``. A name that a package re-exports
from one of its public subpackages (the same object under the same name there), and a
subpackage named in ``__all__``, is documented once, on the subpackage's page, and linked
from the parent's (Sphinx refuses two descriptions of one object). Constants (names that
are neither classes, callables nor modules) are described on the package's page with their
value and the ``#:`` comment where they are defined (autosummary would show the docstring
of their type: "Convert a string or number to a floating point number").
"""
from __future__ import annotations

import ast
import importlib
import importlib.util
import inspect
import pkgutil
from pathlib import Path

ROOTS = ("appdyn.dynamics", "appdyn.ocp", "appdyn.problems")


def public_packages() -> list[str]:
    """Dotted names of the public packages (not modules) under `ROOTS`, roots first."""
    names = []
    for root in ROOTS:
        package = importlib.import_module(root)
        names.append(root)
        for info in pkgutil.walk_packages(package.__path__, prefix=f"{root}."):
            if info.ispkg and not any(part.startswith("_") for part in info.name.split(".")):
                names.append(info.name)
    return names


def public_names(package: str) -> list[str]:
    """The names in ``package.__all__`` (empty when it has none)."""
    return list(getattr(importlib.import_module(package), "__all__", ()))


def is_constant(obj) -> bool:
    """Data rather than code: not a class, a callable or a module."""
    return not (inspect.isclass(obj) or inspect.ismodule(obj) or callable(obj))


def comments_above(source: str) -> dict[str, str]:
    """``{name: text}`` of the module-level assignments in ``source`` documented the ways
    Sphinx reads: ``#:`` comment lines right above, a ``#:`` comment on the line, or a
    string right after."""
    lines = source.splitlines()
    found = {}
    body = ast.parse(source).body
    for i, node in enumerate(body):
        targets = node.targets if isinstance(node, ast.Assign) else \
            [node.target] if isinstance(node, ast.AnnAssign) else []
        comment, k = [], node.lineno - 2
        while k >= 0 and lines[k].lstrip().startswith("#:"):
            comment.insert(0, lines[k].lstrip()[2:].strip())
            k -= 1
        _, inline, after = lines[node.end_lineno - 1].partition("#:")
        if inline and after.strip() and not comment:
            comment = [after.strip()]  # ``NAME = value  #: text``
        following = body[i + 1] if i + 1 < len(body) else None
        if not comment and isinstance(following, ast.Expr) and isinstance(
                getattr(following, "value", None), ast.Constant) and isinstance(
                following.value.value, str):
            comment = [" ".join(following.value.value.split())]  # a string after it
        for target in targets:
            if isinstance(target, ast.Name) and comment:
                found[target.id] = " ".join(comment)
    return found


def constant_doc(package: str, name: str) -> str:
    """The ``#:`` comment of ``name`` in the module of ``package`` that defines it; empty
    when there is none."""
    root = importlib.import_module(package)
    modules = [package] + [info.name for info in
                           pkgutil.walk_packages(getattr(root, "__path__", []), f"{package}.")]
    for module in modules:
        spec = importlib.util.find_spec(module)
        if spec is None or not spec.origin or not spec.origin.endswith(".py"):
            continue
        text = comments_above(Path(spec.origin).read_text()).get(name)
        if text:
            return text
    return ""


def home(package: str, name: str, packages: list[str]) -> str:
    """Where ``package.name`` is documented: the dotted name of the public package below
    ``package`` that exports the same object under the same name (or that is the object),
    else the public package that defines it and exports it under that name (a class one
    package re-exports from another branch, as `problems.stability` the dampers of
    `dynamics.scene`), else ``package`` itself."""
    obj = getattr(importlib.import_module(package), name)
    if inspect.ismodule(obj) and obj.__name__ in packages:
        return obj.__name__
    for sub in packages:
        if sub.startswith(f"{package}.") and name in public_names(sub) \
                and getattr(importlib.import_module(sub), name) is obj:
            return home(sub, name, packages)
    defining = getattr(obj, "__module__", None) or ""
    if defining == package or defining.startswith(f"{package}."):
        return package
    for other in sorted(packages, key=len, reverse=True):  # a re-export from another branch:
        if (defining == other or defining.startswith(f"{other}.")) \
                and not package.startswith(f"{other}.") \
                and name in public_names(other) \
                and getattr(importlib.import_module(other), name) is obj:
            return home(other, name, packages)  # documented where it is defined
    return package


def page(package: str, packages: list[str]) -> str:
    """The reStructuredText of one package's reference page (``packages``: all the public
    packages, for the names documented on another page)."""
    title = f"``{package}``"
    lines = [title, "=" * len(title), "", f".. automodule:: {package}", "   :no-members:", ""]
    names = public_names(package)
    homes = {name: home(package, name, packages) for name in names}
    module = importlib.import_module(package)
    own = [name for name in names if homes[name] == package
           and not is_constant(getattr(module, name))]
    constants = [name for name in names if homes[name] == package
                 and is_constant(getattr(module, name))]
    elsewhere = [name for name in names if homes[name] != package]
    if names:
        lines += [".. currentmodule:: " + package, "", "Public names", "------------", ""]
    if own:
        lines += [".. autosummary::", "   :toctree: generated/", "   :nosignatures:", ""]
        lines += [f"   {name}" for name in own]
        lines.append("")
    if constants:
        lines += ["Constants", "---------", ""]
        for name in constants:
            value = " ".join(repr(getattr(module, name)).split())
            lines += [f".. py:data:: {name}", f"   :value: {value}", ""]
            doc = constant_doc(package, name)
            if doc:
                lines += ["   " + line if line else "" for line in doc.splitlines()] + [""]
    if elsewhere:
        lines += ["Also exported here, documented with their subpackage:", ""]
        for name in elsewhere:
            target = homes[name]
            link = (f":doc:`{name} <{target}>`" if target.endswith(f".{name}")
                    and target in packages else f":py:obj:`{name} <{target}.{name}>`")
            lines.append(f"- {link} (``{target}``)")
        lines.append("")
    return "\n".join(lines)


def write_api(folder) -> list[Path]:
    """Write ``folder/index.rst`` and one page per public package; the paths written (files
    whose text is unchanged are left alone, so Sphinx does not rebuild them)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    packages = public_packages()
    texts = {f"{name}.rst": page(name, packages) for name in packages}
    stubs = {f"{package}.{name}" for package in packages for name in public_names(package)
             if home(package, name, packages) == package
             and not is_constant(getattr(importlib.import_module(package), name))}
    for stale in (folder / "generated").glob("*.rst"):
        if stale.stem not in stubs:  # a name that left __all__ or became a constant
            stale.unlink()
    texts["index.rst"] = "\n".join([
        "API reference", "=============", "",
        "Every public name of every package, from its docstring (numpydoc). The names are",
        "those of each package's ``__all__``; a name re-exported by a parent package is",
        "listed under both.", "",
        ".. toctree::", "   :maxdepth: 1", ""] + [f"   {name}" for name in packages]) + "\n"
    written = []
    for name, text in texts.items():
        path = folder / name
        if not path.is_file() or path.read_text() != text:
            path.write_text(text)
        written.append(path)
    return written
