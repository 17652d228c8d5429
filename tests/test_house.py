"""One house: the package's imports and caches read from its source (``ast``, nothing imported).

Rules checked over every ``.py`` of ``dynamics/``, ``ocp/``, ``problems/`` (the command line
included) and ``appdyn/``:

* **No private cross-import.** A module never imports a ``_private`` name (one underscore,
  not a dunder) from another module of the package, nor reads one as an attribute of an
  imported module (``from . import m; m._helper``). A helper another module needs gets a
  public name in a shared module (or the two modules merge). Private *modules* are not used
  in the package; a submodule imported by name (``from . import estimates``) is not a name.
* **No import circle.** The graph has an edge ``a -> b`` for every import of module ``b``
  (or of a name defined in ``b``) written anywhere in ``a``: at the top, inside a function
  (a "lazy" import), or under ``if TYPE_CHECKING:``. A circle closed through a function-local
  or type-checking import is still a circle: the two modules are one unit split in two
  files, and the lazy import only hides the order they must be loaded in. The implicit
  import of a parent package (importing ``a.b.c`` first runs ``a/b/__init__.py``) is not an
  edge; an explicit ``from .. import name`` of the parent is.
* **One cache.** No ``functools.lru_cache``/``functools.cache`` and no module-level table
  (``{}``, ``dict()``, ``OrderedDict()``, a ``weakref`` dictionary) outside the one cache
  (`appdyn.dynamics.cache`, emptied by `appdyn.dynamics.clear_caches`): a memoized factory
  uses ``cache.memoize``/``cache.memoize_values``, anything else ``cache.get``.
* **Options keyword-only** (in `appdyn.dynamics.integrate` and `appdyn.ocp`). A public
  function (a name in its module's or its package's ``__all__``) and a public method of a
  public class take its essentials (the data it is about, without defaults) positionally
  and its options (parameters with a default) after ``*``: no positional-or-keyword
  parameter has a default. Dataclass fields (generated ``__init__``) are not checked.

The allowlists below hold the exceptions, each with its reason (private imports and import
circles: none). An entry that no longer occurs fails too (so the lists only shrink).
"""
from __future__ import annotations

import ast
from functools import lru_cache
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FOLDERS = ("dynamics", "ocp", "problems", "appdyn")

# (importing module, module the name comes from, name): none left.
PRIVATE_ALLOWED: set = set()

# Strongly connected sets of modules (each closed through a function-local import): none.
CIRCLES_ALLOWED: set = set()

# (module, name) of caches outside the one cache. The first two are not caches of built
# things: `function_key`'s identity table (weak references, part of the one cache itself)
# and `diskcache`'s identities of this process (its code's hash, the machine, the compiler's
# path and size: constant while the process runs, and the compile cache's key). The third
# holds the problems a multistart worker process received (its inputs, not a cache).
CACHES_ALLOWED = {
    ("appdyn.dynamics.cache", "_KEYS"),
    ("appdyn.dynamics.cache", "_AHEAD"),  # compiler processes under way, not built objects
    ("appdyn.dynamics.diskcache", "_IDS"),
    ("appdyn.ocp.refine.multistart", "_RECEIVED"),  # a worker's unpickled problems
}

# Packages whose public functions take their options keyword-only.
KEYWORD_ONLY_PACKAGES = ("appdyn.dynamics.integrate", "appdyn.ocp")
# (module, qualified name, parameter) of the defaults kept positional, each with its reason.
POSITIONAL_DEFAULTS_ALLOWED = {
    # the axes a plot draws into: ``result.plot(ax)``, as matplotlib's own plot helpers
    ("appdyn.dynamics.integrate.batch", "BatchResult.plot", "ax"),
    ("appdyn.dynamics.integrate.result", "SimulationResult.plot", "ax"),
    ("appdyn.ocp.solution", "Solution.plot", "ax"),
    ("appdyn.ocp.phases.solution", "MultiPhaseSolution.plot", "ax"),
    # the NLP point whose bound violation is measured besides ``g``: data, not an option
    ("appdyn.ocp.nlp", "Discretization.violation", "w"),
    ("appdyn.ocp.phases.nlp", "PhasedDiscretization.violation", "w"),
    # the solution to refine from (``refine(problem, sol)``, the documented call form)
    ("appdyn.ocp.refine.mesh_update", "refine", "solution"),
    # the info merged into the annotated solution (``annotate(sol, {...})``): its data
    ("appdyn.ocp.refine.result", "annotate", "info"),
    # the transcription named: the function's one essential (``"radau"`` when omitted)
    ("appdyn.ocp.transcription", "get_transcription", "transcription"),
}


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts) if parts[0] == "appdyn" else "appdyn." + ".".join(parts)


@lru_cache(maxsize=1)  # the test's own parse of the source tree, once per session
def _modules() -> dict:
    """``module name -> (path, ast tree)`` of every module of the package."""
    out = {}
    for folder in FOLDERS:
        for path in sorted((ROOT / folder).rglob("*.py")):
            out[_module_name(path)] = (path, ast.parse(path.read_text(), str(path)))
    return out


@lru_cache(maxsize=None)
def _nodes(module: str) -> tuple:
    """Every node of ``module``'s tree (walked once)."""
    return tuple(ast.walk(_modules()[module][1]))


def _source(module: str, node: ast.ImportFrom) -> str | None:
    """The absolute module an ``ImportFrom`` reads from (None outside the package)."""
    if node.level == 0:
        return node.module if (node.module or "").startswith("appdyn") else None
    path = _modules()[module][0]
    base = module.split(".") if path.name == "__init__.py" else module.split(".")[:-1]
    base = base[:len(base) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def _imports(module: str):
    """``(lineno, source module, name or None)`` of every import in ``module``, wherever it
    is written (a submodule imported by name comes back as the source with name None)."""
    modules = _modules()
    for node in _nodes(module):
        if isinstance(node, ast.ImportFrom):
            source = _source(module, node)
            if source is None:
                continue
            for alias in node.names:
                sub = f"{source}.{alias.name}"
                yield (node.lineno, sub, None) if sub in modules else (
                    node.lineno, source, alias.name)
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.startswith("appdyn"):
                    yield node.lineno, alias.name, None


def _is_private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


def private_cross_imports() -> set:
    """``(module, source, name)`` of every private name a module takes from another."""
    modules = _modules()
    found = set()
    for module in modules:
        aliases = {}
        for _, source, name in _imports(module):
            if name is not None and _is_private(name) and source != module:
                found.add((module, source, name))
        for node in _nodes(module):  # ``from . import m`` then ``m._x``
            if isinstance(node, ast.ImportFrom) and _source(module, node):
                for alias in node.names:
                    sub = f"{_source(module, node)}.{alias.name}"
                    if sub in modules:
                        aliases[alias.asname or alias.name] = sub
        for node in _nodes(module):
            if (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name)
                    and node.value.id in aliases and _is_private(node.attr)):
                found.add((module, aliases[node.value.id], node.attr))
    return found


def import_graph() -> dict:
    """``module -> set of modules it imports`` (top-level, function-local and type-checking
    imports alike; a name's edge goes to the module that defines or re-exports it)."""
    modules = _modules()
    return {m: {src for _, src, _ in _imports(m) if src in modules and src != m}
            for m in modules}


def circles(graph: dict) -> set:
    """The strongly connected sets of more than one module (Tarjan, iterative)."""
    index, low, stack, on, out, counter = {}, {}, [], set(), set(), [0]
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter[0]
        counter[0] += 1
        stack.append(root)
        on.add(root)
        while work:
            v, children = work[-1]
            for w in children:
                if w not in index:
                    index[w] = low[w] = counter[0]
                    counter[0] += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(graph[w]))))
                    break
                if w in on:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    comp = set()
                    while True:
                        w = stack.pop()
                        on.discard(w)
                        comp.add(w)
                        if w == v:
                            break
                    if len(comp) > 1:
                        out.add(frozenset(comp))
    return out


_CACHE_DECORATORS = {"lru_cache", "cache"}
_TABLES = {"dict", "OrderedDict", "WeakValueDictionary", "WeakKeyDictionary", "defaultdict"}


def _is_cache_decorator(node) -> bool:
    node = node.func if isinstance(node, ast.Call) else node
    if isinstance(node, ast.Attribute):
        return (node.attr in _CACHE_DECORATORS and isinstance(node.value, ast.Name)
                and node.value.id == "functools")
    return isinstance(node, ast.Name) and node.id == "lru_cache"


def _is_table(node) -> bool:
    if isinstance(node, ast.Dict):
        return not node.keys
    if isinstance(node, ast.Call) and not node.args and not node.keywords:
        f = node.func
        name = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", None)
        return name in _TABLES
    return False


def caches_outside_the_one_cache() -> set:
    """``(module, name)`` of every functools cache and module-level empty table."""
    found = set()
    for module, (_, tree) in _modules().items():
        for node in _nodes(module):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                if any(_is_cache_decorator(d) for d in node.decorator_list):
                    found.add((module, node.name))
        for node in tree.body:
            if isinstance(node, (ast.Assign, ast.AnnAssign)) and node.value is not None:
                targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                if _is_table(node.value):
                    found |= {(module, t.id) for t in targets if isinstance(t, ast.Name)}
    return found


def _exported(module: str) -> set:
    """The names in ``__all__`` of ``module`` and of every package above it."""
    names, parts = set(), module.split(".")
    for k in range(len(parts), 1, -1):
        name = ".".join(parts[:k])
        if name not in _modules():
            continue
        for node in _modules()[name][1].body:
            if (isinstance(node, ast.Assign) and any(getattr(t, "id", None) == "__all__"
                                                     for t in node.targets)
                    and isinstance(node.value, (ast.List, ast.Tuple))):
                names |= {e.value for e in node.value.elts if isinstance(e, ast.Constant)}
    return names


def _positional_defaults(fun: ast.FunctionDef) -> list:
    """The positional-or-keyword parameters of ``fun`` that have a default."""
    args = fun.args
    return [a.arg for a in args.args[len(args.args) - len(args.defaults):]]


def positional_defaults(packages=KEYWORD_ONLY_PACKAGES) -> set:
    """``(module, qualified name, parameter)`` of every option (a parameter with a default)
    a public function or method of ``packages`` takes positionally."""
    found = set()
    for module, (_, tree) in _modules().items():
        if not module.startswith(packages):
            continue
        public = _exported(module)
        for node in tree.body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and node.name in public:
                found |= {(module, node.name, a) for a in _positional_defaults(node)}
            elif isinstance(node, ast.ClassDef) and node.name in public:
                for fun in node.body:
                    if (isinstance(fun, (ast.FunctionDef, ast.AsyncFunctionDef))
                            and not fun.name.startswith("_")):
                        found |= {(module, f"{node.name}.{fun.name}", a)
                                  for a in _positional_defaults(fun)}
    return found


def _check(found: set, allowed: set, what: str) -> None:
    new, gone = found - allowed, allowed - found
    assert not new, f"{what} (give the helper a public name, or merge): {sorted(new)}"
    assert not gone, f"no longer found; remove from the allowlist in {__file__}: {sorted(gone)}"


def test_the_walk_sees_the_whole_package():
    modules = _modules()
    for name in ("appdyn", "appdyn.dynamics.cache", "appdyn.ocp.solve",
                 "appdyn.problems.cli.slew", "appdyn.dynamics.scene.contract"):
        assert name in modules
    assert len(modules) > 150


def test_no_private_name_is_imported_from_another_module():
    _check(private_cross_imports(), PRIVATE_ALLOWED, "private names imported across modules")


def test_no_import_circles_lazy_and_type_checking_imports_included():
    _check(circles(import_graph()), CIRCLES_ALLOWED, "import circles")


def test_every_cache_is_the_one_cache():
    _check(caches_outside_the_one_cache(), CACHES_ALLOWED, "caches outside dynamics.cache")


def test_public_options_are_keyword_only():
    found = positional_defaults()
    new, gone = found - POSITIONAL_DEFAULTS_ALLOWED, POSITIONAL_DEFAULTS_ALLOWED - found
    assert not new, f"options taken positionally (move them after `*`): {sorted(new)}"
    assert not gone, f"no longer found; remove from the allowlist in {__file__}: {sorted(gone)}"


@pytest.mark.parametrize("graph, expected", [
    ({"a": {"b"}, "b": {"a"}, "c": {"a"}}, {frozenset("ab")}),
    ({"a": {"b"}, "b": {"c"}, "c": {"a", "d"}, "d": set()}, {frozenset("abc")}),
    ({"a": {"b"}, "b": set()}, set()),
    ({"a": {"b", "c"}, "b": {"a"}, "c": {"d"}, "d": {"c"}}, {frozenset("ab"), frozenset("cd")}),
])
def test_circles_finds_the_strongly_connected_sets(graph, expected):
    assert circles(graph) == expected


def test_the_rules_catch_what_they_forbid(tmp_path, monkeypatch):
    """A lazy circle, a private import and a cache, written into a scratch package."""
    pkg = tmp_path / "dynamics"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("import functools\nfrom .b import _helper\n_T = {}\n"
                              "@functools.lru_cache(maxsize=2)\ndef f():\n    pass\n")
    (pkg / "b.py").write_text("def _helper():\n    from . import a\n")
    (pkg / "c.py").write_text(
        "__all__ = ['run', 'Kept', 'ok']\n"
        "def run(x, y=1, *, z=2):\n    pass\n"          # y: an option taken positionally
        "def ok(x, *, y=1):\n    pass\n"
        "def other(x, y=1):\n    pass\n"              # not public
        "class Kept:\n    def go(self, a, b=0):\n        pass\n"
        "    def _own(self, a=0):\n        pass\n")
    monkeypatch.setitem(globals(), "ROOT", tmp_path)
    monkeypatch.setitem(globals(), "FOLDERS", ("dynamics",))
    _modules.cache_clear()
    _nodes.cache_clear()
    try:
        assert private_cross_imports() == {("appdyn.dynamics.a", "appdyn.dynamics.b",
                                            "_helper")}
        assert circles(import_graph()) == {frozenset({"appdyn.dynamics.a",
                                                      "appdyn.dynamics.b"})}
        assert caches_outside_the_one_cache() == {("appdyn.dynamics.a", "_T"),
                                                  ("appdyn.dynamics.a", "f")}
        assert positional_defaults(("appdyn.dynamics",)) == {
            ("appdyn.dynamics.c", "run", "y"), ("appdyn.dynamics.c", "Kept.go", "b")}
    finally:
        _modules.cache_clear()
        _nodes.cache_clear()
