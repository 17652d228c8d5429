"""IPOPT's option list, and the check of user ``ipopt_options`` against it.

IPOPT's own options (``tol``, ``max_iter``, ``linear_solver``, ...) are not among CasADi's
``nlpsol_options('ipopt')``: CasADi hands them through to IPOPT, which reports an unknown or
ill-typed option only when the solver is built (a CasADi ``RuntimeError``, with IPOPT's
documentation dumped on stdout). `check_ipopt_options` checks them *before* the solver is
built and raises a ``ValueError`` naming the option.

The options this package sets itself (``tol``, ``max_iter``, ``acceptable_iter``, ...) are
checked against a small kept table; every other name against the installed IPOPT's own
list: its documentation output (``print_options_documentation yes``,
``print_advanced_options yes``, ``print_options_mode doxygen``, which names each option's
type) is captured once in a subprocess (so nothing reaches this process's stdout) and
parsed (`ipopt_option_table`; the result is kept in the one cache, `dynamics.cache`). If that
capture fails, names and values are not checked here and the solver's own error is
reported instead (see `ocp.solve`).

A ``linear_solver`` that the installed IPOPT cannot load (the HSL solvers ``ma27`` ...
``ma97`` without the HSL library, ``pardiso`` without its library) is not an option error for
IPOPT: the solve returns ``Invalid_Option`` with garbage counters. `available_linear_solvers`
probes which of `LINEAR_SOLVERS` load -- a one-variable NLP per name, solved in a
subprocess (a missing Pardiso library can crash the process that tries it) -- once per
process and library setting; `check_ipopt_options` then rejects an unavailable one before
anything is built.

BLAS threads
------------
IPOPT's linear algebra (MUMPS) runs on the OpenBLAS that CasADi ships, which starts a
thread per core when it is loaded (with the IPOPT plugin, at the first solver of a process).
Those threads spin about 0.1 s after each wake-up before sleeping, and the KKT systems of
this package's NLPs are too small for a threaded BLAS call to pay: on 2 cores a spinning
thread took 0.10 s of CPU during the first Bilimoria-Wie slew of a process (0.33 s CPU for
0.23 s wall), and on a busy machine that CPU is taken from the solve. `ipopt_solver` (every
IPOPT solver of this package is built by it) therefore loads the plugin with
`IPOPT_BLAS_THREADS` BLAS threads unless ``OPENBLAS_NUM_THREADS`` is set in the
environment, which then decides (`load_ipopt`). Measured against the code before, whole
processes alternated (load 0.5): the first slew of a process 0.18-0.24 s wall and the same
CPU, against 0.22-0.26 s wall and 0.33-0.37 s CPU; Delta III and a minimum-effort slew at
N = 2000 unchanged within their run-to-run spread.
"""
from __future__ import annotations

import difflib
import json
import math
import os
import re
import sys
from dataclasses import dataclass
from typing import Mapping

import casadi as ca
import numpy as np

from appdyn.dynamics import cache

__all__ = ["IpoptOption", "ipopt_option_table", "check_ipopt_options", "parse_documentation",
           "available_linear_solvers", "iteration_budget", "LINEAR_SOLVERS", "BUDGET_MIN_ITER",
           "IPOPT_MAX_ITER", "IPOPT_TOL", "IPOPT_BLAS_THREADS", "load_ipopt", "ipopt_solver"]

#: BLAS threads CasADi's OpenBLAS (IPOPT's linear algebra) is loaded with when
#: ``OPENBLAS_NUM_THREADS`` is not set (module docstring, "BLAS threads").
IPOPT_BLAS_THREADS = 1

#: The least IPOPT iteration budget `iteration_budget` gives.
BUDGET_MIN_ITER = 200
#: IPOPT's default ``max_iter``.
IPOPT_MAX_ITER = 3000
#: IPOPT's default ``tol``.
IPOPT_TOL = 1e-8

#: The linear solvers IPOPT may be built with or load at run time, probed by
#: `available_linear_solvers` (in this order).
LINEAR_SOLVERS = ("mumps", "ma27", "ma57", "ma77", "ma86", "ma97", "pardiso", "pardisomkl",
                  "spral", "wsmp")

#: IPOPT options that say where a linear solver's library is: part of the probe.
_LIBRARY_OPTIONS = ("hsllib", "pardisolib", "linear_solver_load_library")

# accepted by CasADi's IPOPT interface but not in IPOPT's documentation output
_UNDOCUMENTED = {"sb": ("String", ("yes", "no"))}

_CAPTURE = r"""
import casadi as ca
x = ca.SX.sym("x")
s = ca.nlpsol("doc", "ipopt", {"x": x, "f": x ** 2},
              {"print_time": False, "ipopt": {"print_options_documentation": "yes",
               "print_advanced_options": "yes", "print_options_mode": "doxygen",
               "max_iter": 0, "sb": "yes"}})
s(x0=1.0)
"""

# one line "@probe <name> <yes|no>" per linear solver named in argv[2:], flushed as it goes
# (a solver that crashes the process leaves the rest unreported); argv[1]: the library
# options as JSON
_PROBE = r"""
import json, sys
import casadi as ca
x = ca.SX.sym("x")
extra = json.loads(sys.argv[1])
for name in sys.argv[2:]:
    try:
        s = ca.nlpsol("probe", "ipopt", {"x": x, "f": (x - 1) ** 2},
                      {"print_time": False, "error_on_fail": False,
                       "ipopt": {"linear_solver": name, "print_level": 0, "sb": "yes", **extra}})
        s(x0=0.0)
        ok = s.stats().get("return_status") == "Solve_Succeeded"
    except Exception:
        ok = False
    print("@probe", name, "yes" if ok else "no", flush=True)
"""

_NAME = re.compile(r"^<strong>(\w+)</strong>")
_RANGE = re.compile(r"valid range for this (real|integer) option is (.*?) and its default")
_STRING = re.compile(r"default value for this string option is")
_VALUE = re.compile(r"^ - (.+?):")
_OPS = {"&le;": False, "<": True}  # operator -> strict


@dataclass(frozen=True)
class IpoptOption:
    """One IPOPT option.

    Attributes
    ----------
    name : str
    kind : {'Number', 'Integer', 'String'}
    lower, upper : float
        Bounds of a Number/Integer option (``-inf``/``inf`` for none).
    lower_strict, upper_strict : bool
        Whether the bound itself is excluded.
    values : tuple of str
        Allowed values of a String option; empty when any string is accepted.
    """

    name: str
    kind: str
    lower: float = -math.inf
    upper: float = math.inf
    lower_strict: bool = False
    upper_strict: bool = False
    values: tuple = ()

    def describe(self) -> str:
        if self.kind == "String":
            return "a string" + (f" in {list(self.values)}" if self.values else "")
        lo = "(" if self.lower_strict else "["
        hi = ")" if self.upper_strict else "]"
        what = "an integer" if self.kind == "Integer" else "a number"
        return f"{what} in {lo}{self.lower:g}, {self.upper:g}{hi}"


def load_ipopt() -> bool:
    """Load CasADi's IPOPT plugin once per process, with `IPOPT_BLAS_THREADS` BLAS threads
    unless ``OPENBLAS_NUM_THREADS`` is set (module docstring, "BLAS threads").

    The variable is set only while the plugin loads (OpenBLAS reads it when loaded) and
    restored at once, under `dynamics.cache.construction_lock`. A library loaded earlier by
    another CasADi plugin keeps its own setting.

    Returns
    -------
    bool
        True once the plugin is loaded (False when this CasADi has no IPOPT).

    Examples
    --------
    >>> from appdyn.ocp.ipopt_options import load_ipopt
    >>> load_ipopt()
    True
    """
    # (held here, not in `dynamics.cache`: a plugin stays loaded for the process, and
    # loading it again after `clear_caches` made casadi print "Solver ipopt is already in
    # use. Ignored." on stderr)
    return _PLUGIN[0] if _PLUGIN else _load_plugin()


#: Whether `load_ipopt` loaded the plugin (its one entry), once per process.
_PLUGIN: list = []


def _load_plugin() -> bool:
    with cache.construction_lock():
        if _PLUGIN:  # (another thread loaded it meanwhile)
            return _PLUGIN[0]
        unset = "OPENBLAS_NUM_THREADS" not in os.environ
        if unset:
            os.environ["OPENBLAS_NUM_THREADS"] = str(IPOPT_BLAS_THREADS)
        try:
            ca.load_nlpsol("ipopt")
            _PLUGIN.append(True)
        except RuntimeError:  # no IPOPT in this CasADi: the solver's own error says so
            _PLUGIN.append(False)
        finally:
            if unset:
                del os.environ["OPENBLAS_NUM_THREADS"]
        return _PLUGIN[0]


def ipopt_solver(name: str, nlp: dict, options: dict) -> ca.Function:
    """``casadi.nlpsol(name, 'ipopt', nlp, options)`` with the plugin loaded by `load_ipopt`:
    every IPOPT solver of this package is built here.

    Parameters
    ----------
    name : str
        The solver Function's name.
    nlp : dict or casadi.Function
        CasADi's NLP (``x``, ``p``, ``f``, ``g``).
    options : dict
        nlpsol options (IPOPT's own under ``'ipopt'``).

    Returns
    -------
    casadi.Function
        The solver.

    Examples
    --------
    >>> import casadi as ca
    >>> from appdyn.ocp.ipopt_options import ipopt_solver
    >>> x = ca.SX.sym("x")
    >>> s = ipopt_solver("s", {"x": x, "f": (x - 2) ** 2},
    ...                  {"print_time": False, "ipopt": {"print_level": 0, "sb": "yes"}})
    >>> round(float(s(x0=0)["x"]), 6)
    2.0
    """
    load_ipopt()
    return ca.nlpsol(name, "ipopt", nlp, options)


def _number(text: str) -> float:
    text = re.sub(r"10<sup>([-+]?\d+)</sup>", r"1e\1", text.strip())
    return {"+inf": math.inf, "inf": math.inf, "-inf": -math.inf}.get(text, None) or float(text)


def _parse_range(name: str, kind: str, text: str) -> IpoptOption:
    """``'0 &le; max_iter'``, ``'0 < tol < 1'``, ``'unrestricted'`` -> `IpoptOption`."""
    opt = IpoptOption(name, "Integer" if kind == "integer" else "Number")
    if text.strip() == "unrestricted":
        return opt
    left, _, right = text.partition(name)
    kw = {}
    left = left.strip()
    if left:
        for op, strict in _OPS.items():
            if left.endswith(op):
                kw.update(lower=_number(left[: -len(op)]), lower_strict=strict)
    right = right.strip()
    if right:
        for op, strict in _OPS.items():
            if right.startswith(op):
                kw.update(upper=_number(right[len(op):]), upper_strict=strict)
    return IpoptOption(opt.name, opt.kind, **kw)


def parse_documentation(text: str) -> dict:
    """`IpoptOption` by name from IPOPT's ``print_options_documentation`` output in
    ``print_options_mode doxygen`` (which names each option's type)."""
    table, current = {}, None
    for line in text.splitlines():
        m = _NAME.match(line)
        if m:
            current = m.group(1)
            continue
        if current is None:
            continue
        r = _RANGE.search(line)
        if r:
            try:
                table[current] = _parse_range(current, r.group(1), r.group(2))
            except ValueError:  # an unexpected range: keep the type only
                table[current] = IpoptOption(current, "Integer" if r.group(1) == "integer" else "Number")
            continue
        if _STRING.search(line):
            table[current] = IpoptOption(current, "String")
            continue
        if line.startswith("Possible values: ") and table.get(current) is not None:
            values = tuple(v.strip() for v in line[len("Possible values: "):].split(","))
            table[current] = IpoptOption(current, "String", values=tuple(v for v in values if v != "*"))
            continue
        v = _VALUE.match(line)
        if v and table.get(current) is not None and table[current].kind == "String":
            value = v.group(1).strip()
            if value != "*":
                table[current] = IpoptOption(current, "String", values=table[current].values + (value,))
        if line.startswith("</blockquote>"):
            current = None
    return table


@cache.memoize
def ipopt_option_table() -> Mapping[str, IpoptOption] | None:
    """The installed IPOPT's options, captured once per process (``None`` if unavailable); kept in the one cache
    (`dynamics.clear_caches` drops it).

    Returns
    -------
    mapping of str to IpoptOption, or None
    """
    import subprocess  # (stdlib, with the capture)

    try:
        out = subprocess.run([sys.executable, "-c", _CAPTURE], capture_output=True, text=True,
                             timeout=60, check=False)
    except (OSError, subprocess.SubprocessError):
        return None
    table = parse_documentation(out.stdout)
    if len(table) < 50 or "tol" not in table:  # not the documentation we expect
        return None
    for name, (kind, values) in _UNDOCUMENTED.items():
        table.setdefault(name, IpoptOption(name, kind, values=values))
    return table


def _probe(names, library: tuple) -> dict:
    """``{name: loads?}`` for ``names``, each solved in the subprocess of `_PROBE`; a name
    that ended the subprocess without a report counts as unavailable and the rest are
    probed in a new one. A failed capture (no subprocess) leaves the names unreported."""
    import subprocess  # (stdlib, with the probe)

    names, found = list(names), {}
    while names:
        try:
            out = subprocess.run([sys.executable, "-c", _PROBE, json.dumps(dict(library)), *names],
                                 capture_output=True, text=True, timeout=120, check=False)
        except (OSError, subprocess.SubprocessError):
            return found
        for line in out.stdout.splitlines():
            parts = line.split()
            if len(parts) == 3 and parts[0] == "@probe" and parts[1] in names:
                found[parts[1]] = parts[2] == "yes"
        rest = [n for n in names if n not in found]
        if rest and out.returncode == 0:  # finished without a word on them: give up
            return found
        if rest:  # the first unreported one crashed the process
            found[rest[0]] = False
        names = rest[1:]
    return found


@cache.memoize
def _available(library: tuple) -> tuple | None:
    found = _probe(LINEAR_SOLVERS, library)
    if not found.get("mumps", False) and not any(found.values()):
        return None  # the probe itself did not work: nothing known
    return tuple(n for n in LINEAR_SOLVERS if found.get(n, False))


def available_linear_solvers(*, options=None) -> tuple | None:
    """The IPOPT linear solvers that load in this installation (probed once per process and
    library setting; about 1 s, in a subprocess).

    Parameters
    ----------
    options : mapping, optional
        IPOPT options; only the ones that locate a solver's library (``hsllib``,
        ``pardisolib``, ``linear_solver_load_library``) are read.

    Returns
    -------
    tuple of str, or None
        The names of `LINEAR_SOLVERS` that solve a one-variable NLP (``'mumps'`` in a
        CasADi wheel), or ``None`` when the probe could not be run.

    Examples
    --------
    >>> from appdyn.ocp.ipopt_options import available_linear_solvers
    >>> "mumps" in available_linear_solvers()
    True
    """
    library = tuple(sorted((k, str(v)) for k, v in (options or {}).items()
                           if k in _LIBRARY_OPTIONS))
    return _available(library)


def _check_linear_solver(out: dict) -> None:
    """Raise a ValueError if ``out['linear_solver']`` does not load (`available_linear_solvers`)."""
    name = str(out["linear_solver"]).lower()
    available = available_linear_solvers(options=out)
    if available is None or name in available or name not in LINEAR_SOLVERS:
        return
    library = {k: out[k] for k in _LIBRARY_OPTIONS if k in out}
    where = f" with {library}" if library else ""
    raise ValueError(
        f"`ipopt_options`['linear_solver'] = {out['linear_solver']!r} is not available in this "
        f"IPOPT installation{where}: available {list(available)} (the HSL solvers ma27-ma97 "
        f"need the HSL library, e.g. `hsllib`; pardiso its own library)")


def _common() -> dict:
    """The options this package sets itself, as IPOPT documents them: checked without
    capturing the documentation (no subprocess on the common path)."""
    inf = math.inf
    pos = dict(lower=0.0, upper=inf, lower_strict=True)
    nonneg = dict(lower=0.0, upper=inf)
    yes_no = ("yes", "no")
    opts = [IpoptOption("tol", "Number", **pos), IpoptOption("acceptable_tol", "Number", **pos),
            IpoptOption("constr_viol_tol", "Number", **pos),
            IpoptOption("acceptable_constr_viol_tol", "Number", **pos),
            IpoptOption("dual_inf_tol", "Number", **pos), IpoptOption("compl_inf_tol", "Number", **pos),
            IpoptOption("mu_init", "Number", **pos), IpoptOption("bound_relax_factor", "Number", **nonneg),
            IpoptOption("max_wall_time", "Number", **pos), IpoptOption("max_cpu_time", "Number", **pos),
            IpoptOption("max_iter", "Integer", **nonneg), IpoptOption("acceptable_iter", "Integer", **nonneg),
            IpoptOption("print_level", "Integer", lower=0.0, upper=12.0),
            IpoptOption("warm_start_init_point", "String", values=("no", "yes")),
            IpoptOption("sb", "String", values=yes_no),
            IpoptOption("mu_strategy", "String", values=("monotone", "adaptive")),
            IpoptOption("hessian_approximation", "String", values=("exact", "limited-memory"))]
    return {o.name: o for o in opts}


_COMMON = _common()


def _check_value(opt: IpoptOption, value):
    key = opt.name
    if opt.kind == "String":
        if not isinstance(value, str):
            raise ValueError(f"`ipopt_options`[{key!r}] must be {opt.describe()}, got {value!r}")
        if opt.values and value.lower() not in {v.lower() for v in opt.values}:
            close = difflib.get_close_matches(value, opt.values, n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise ValueError(f"`ipopt_options`[{key!r}] must be one of {list(opt.values)}, "
                             f"got {value!r}{hint}")
        return value
    if opt.kind == "Integer":
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
            raise ValueError(f"`ipopt_options`[{key!r}] must be {opt.describe()}, got {value!r}")
        value = int(value)
    else:
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
            raise ValueError(f"`ipopt_options`[{key!r}] must be {opt.describe()}, got {value!r}")
        value = float(value)
        if math.isnan(value):
            raise ValueError(f"`ipopt_options`[{key!r}] must be {opt.describe()}, got nan")
    below = value <= opt.lower if opt.lower_strict else value < opt.lower
    above = value >= opt.upper if opt.upper_strict else value > opt.upper
    if below or above:
        raise ValueError(f"`ipopt_options`[{key!r}] must be {opt.describe()}, got {value!r}")
    return value


def check_ipopt_options(options) -> dict:
    """Validate user IPOPT options; return them without the ``'ipopt.'`` prefix.

    Parameters
    ----------
    options : mapping of str to object, or None
        IPOPT option names (with or without the ``'ipopt.'`` prefix) and values.

    Returns
    -------
    dict
        The options, keys without the prefix, integers and numbers as Python ``int``/``float``.

    Raises
    ------
    ValueError
        Naming ``ipopt_options`` and the option: not a mapping, a key that is not an IPOPT
        option (with the closest name, if any), or a value of the wrong type or out of range
        (Number: int or float; Integer: int; String: str, one of the allowed values), or a
        ``linear_solver`` that does not load here (with the ones that do:
        `available_linear_solvers`).
    """
    if options is None:
        return {}
    if not isinstance(options, Mapping):
        raise TypeError(f"`ipopt_options` (`options`) must be a mapping, got "
                        f"{type(options).__name__}")
    out = {}
    for key, value in options.items():
        if not isinstance(key, str):
            raise ValueError(f"`ipopt_options` keys must be IPOPT option names, got {key!r}")
        name = key[len("ipopt."):] if key.startswith("ipopt.") else key
        if name in _COMMON:
            out[name] = _check_value(_COMMON[name], value)
            continue
        table = ipopt_option_table()
        if table is not None:
            if name not in table:
                close = difflib.get_close_matches(name, list(table), n=1)
                hint = f"; did you mean {close[0]!r}?" if close else ""
                raise ValueError(f"`ipopt_options` names unknown IPOPT option {key!r}{hint}")
            value = _check_value(table[name], value)
        out[name] = value
    if "linear_solver" in out:
        _check_linear_solver(out)
    return out


def iteration_budget(ipopt_options: Mapping | None, iterations: int, factor: float, *,
                     minimum: int = BUDGET_MIN_ITER) -> tuple[dict, int]:
    """``(options, budget)``: ``ipopt_options`` with ``max_iter`` set to ``max(minimum,
    factor * iterations)`` -- the budget of a solve that a converged neighbour needed
    ``iterations`` for -- unless they set ``max_iter`` themselves (theirs wins).

    A solve that takes many times the iterations of a converged neighbour is wandering
    (IPOPT's restoration phase, a horizon drifting to its bound): a CMG slew's seeded starts
    ran 1,053 and 3,000 iterations (117 s) where the converged one took 16.

    Examples
    --------
    >>> from appdyn.ocp.ipopt_options import iteration_budget
    >>> iteration_budget({"tol": 1e-9}, 16, 10)
    ({'tol': 1e-09, 'max_iter': 200}, 200)
    >>> iteration_budget({"max_iter": 50}, 16, 10)
    ({'max_iter': 50}, 50)
    """
    options = dict(ipopt_options or {})
    budget = int(options.get("max_iter", max(int(minimum), math.ceil(factor * int(iterations)))))
    options["max_iter"] = budget
    return options, budget
