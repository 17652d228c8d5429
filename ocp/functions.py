"""The user's cost and constraint functions as canonical CasADi Functions.

`Problem` takes ``lagrange``, ``mayer``, ``path`` and ``boundary`` (and the ``fun`` of a
`Constraint`) as a ``casadi.Function`` or a Python callable, and stores each as a canonical
Function (`named_function`): named inputs, the positional ones of its kind below, and one
output, flattened column-major to a column.

=============  ===================  ======  ==================================
kind           positional inputs    output  meaning
=============  ===================  ======  ==================================
``lagrange``   ``(x, u, p)``        ``L``   running cost (scalar)
``path``       ``(x, u, p)``        ``g``   path constraint rows
``mayer``      ``(xf, p, T)``       ``phi`` terminal cost (scalar)
``boundary``   ``(x0, xf, p)``      ``c``   boundary constraint rows
=============  ===================  ======  ==================================

Positional convention: a ``casadi.Function`` (always), or a callable called with the column
vectors of the inputs, whatever its parameter names (``lambda xf_, p_, T`` works).

By-name convention (`by_name`): a callable whose parameter names are all names of the
problem (`vocabulary`) and not exactly the positional ones is called with scalar symbols:
states, controls and parameters by name (``lagrange``, ``path``); final states by name or
with the suffix ``_f``, parameters and ``T`` (``mayer``); initial states with the suffix
``_0``, final ones with ``_f``, and parameters (``boundary``). It may return a list of
expressions (stacked into rows). The user-facing rules are in the Notes of `Problem`.

A callable is evaluated once on SX symbols, or on MX when SX fails (`canonical`).
"""
from __future__ import annotations

import inspect
import re
from typing import Sequence

import casadi as ca
import numpy as np

from appdyn.dynamics import cache
from appdyn.dynamics.model import Model

__all__ = ["named_function", "canonical", "by_name", "vocabulary", "valid_names", "POSITIONAL",
           "sx_compatible"]


@cache.constructs
def sx_compatible(fun: ca.Function) -> bool:
    """Whether ``fun`` can be called on SX symbols (then kernels are built expanded, in SX).

    The trial call builds symbols, under the construction lock (`dynamics.cache`).

    Examples
    --------
    >>> import casadi as ca
    >>> from appdyn.ocp.functions import sx_compatible
    >>> x = ca.MX.sym("x")
    >>> sx_compatible(ca.Function("f", [x], [ca.sin(x)]))
    True
    """
    try:
        fun(*[ca.SX.sym(f"a{i}", fun.sparsity_in(i)) for i in range(fun.n_in())])
        return True
    except Exception:  # noqa: BLE001 - e.g. an MX Function holding an integrator
        return False

#: The positional inputs of each kind of function (the inputs its names refer to).
POSITIONAL = {
    "lagrange": ("x", "u", "p"),
    "path": ("x", "u", "p"),
    "mayer": ("xf", "p", "T"),
    "boundary": ("x0", "xf", "p"),
}
# the output name of each kind, and the kinds whose output is a scalar
_OUTPUT = {"lagrange": "L", "path": "g", "mayer": "phi", "boundary": "c"}
_SCALAR = ("lagrange", "mayer")


def named_function(fun, kind: str, model: Model, argname: str) -> ca.Function:
    """A user function of ``kind`` as its canonical named-I/O Function.

    Parameters
    ----------
    fun : casadi.Function or callable
        Positional or by name (see the module docstring).
    kind : {'lagrange', 'path', 'mayer', 'boundary'}
    model : dynamics.Model
        Gives the input sizes and the names a callable may take.
    argname : str
        Name of the argument in messages (``'path[1]'``).

    Returns
    -------
    casadi.Function
        Inputs ``POSITIONAL[kind]`` (sizes from ``model``), one output (``L``, ``g``,
        ``phi`` or ``c``), a column; a scalar for ``lagrange`` and ``mayer``.

    Raises
    ------
    ValueError
        Naming ``argname``: a wrong signature, an unknown or ambiguous argument name, a
        function that cannot be evaluated on symbols, a non-scalar cost.

    Examples
    --------
    >>> from appdyn.ocp.examples import double_integrator
    >>> model = double_integrator()  # states ('x', 'v'), control 'u'
    >>> c = named_function(lambda x_f, v_0: [x_f - 1, v_0], "boundary", model, "boundary")
    >>> c.name_in(), c.name_out(), c.numel_out(0)
    (['x0', 'xf', 'p'], ['c'], 2)
    """
    sizes = {"x": model.nx, "u": model.nu, "p": model.np, "x0": model.nx, "xf": model.nx, "T": 1}
    inputs = [(n, sizes[n]) for n in POSITIONAL[kind]]
    return canonical(by_name(fun, kind, model, argname), inputs, _OUTPUT[kind], argname,
                     scalar=kind in _SCALAR)


def vocabulary(kind: str, model: Model) -> dict[str, list[tuple[int, int]]]:
    """Argument name -> every ``(input, component)`` it may denote for functions of ``kind``
    (more than one entry: the name is ambiguous)."""
    vocab: dict[str, list[tuple[int, int]]] = {}

    def add(name, where):
        if where not in vocab.setdefault(name, []):
            vocab[name].append(where)

    if kind in ("lagrange", "path"):  # inputs (x, u, p)
        for i, s in enumerate(model.states):
            add(s, (0, i))
        for i, c in enumerate(model.controls):
            add(c, (1, i))
        for i, q in enumerate(model.params):
            add(q, (2, i))
    elif kind == "mayer":  # inputs (xf, p, T): states are final values
        for i, s in enumerate(model.states):
            add(s, (0, i))
            add(f"{s}_f", (0, i))
        for i, q in enumerate(model.params):
            add(q, (1, i))
        add("T", (2, 0))
    else:  # boundary, inputs (x0, xf, p): initial values `<state>_0`, final `<state>_f`
        for i, s in enumerate(model.states):
            add(f"{s}_0", (0, i))
            add(f"{s}_f", (1, i))
        for i, q in enumerate(model.params):
            add(q, (2, i))
    return vocab


def valid_names(kind: str, model: Model) -> str:
    """The names a function of ``kind`` may take, as a phrase for messages."""
    if kind in ("lagrange", "path"):
        return (f"states {list(model.states)}, controls {list(model.controls)}, "
                f"parameters {list(model.params)}")
    if kind == "mayer":
        return (f"final states {list(model.states)} (or with the suffix '_f'), parameters "
                f"{list(model.params)}, and 'T' (the horizon)")
    return (f"initial states {[s + '_0' for s in model.states]}, final states "
            f"{[s + '_f' for s in model.states]}, parameters {list(model.params)}")


def by_name(fun, kind: str, model: Model, argname: str):
    """``fun`` itself when it takes the positional arguments of ``kind``; else a positional
    wrapper that calls it with the scalar components its parameter names denote.

    A plain callable (not a ``casadi.Function``) whose parameters can all be passed by keyword
    is taken by name when every parameter name is a name of ``kind`` (`vocabulary`) and the
    names are not exactly the positional ones; a callable that cannot take the three
    positional arguments must name its arguments so (ValueError naming the first that does
    not: unknown or ambiguous). Any other callable keeps the positional convention.
    """
    if isinstance(fun, ca.Function) or not callable(fun):
        return fun
    try:
        params = list(inspect.signature(fun).parameters.values())
    except (TypeError, ValueError):  # no signature (some builtins): positional
        return fun
    kinds = {p.kind for p in params}
    if kinds & {inspect.Parameter.VAR_POSITIONAL, inspect.Parameter.VAR_KEYWORD,
                inspect.Parameter.POSITIONAL_ONLY}:
        return fun
    names = tuple(p.name for p in params)
    positional = POSITIONAL[kind]
    if names == positional:
        return fun
    vocab = vocabulary(kind, model)
    state_names = set(model.states)
    # a state name without suffix in `boundary` is recognized but ambiguous (x0 or xf)
    recognized = [n in vocab or (kind == "boundary" and n in state_names) for n in names]
    required = sum(p.default is inspect.Parameter.empty for p in params)
    takes_positional = required <= len(positional) <= len(params)
    if not all(recognized) and takes_positional:
        return fun  # the positional convention, under other names (as `lambda xf_, p_, T`)
    valid = valid_names(kind, model)
    where = []
    for n, ok in zip(names, recognized):
        if not ok:
            raise ValueError(
                f"`{argname}`: argument {n!r} is not a name of this problem; by name it may "
                f"take {valid}; or write it positionally as {kind}({', '.join(positional)})")
        if n not in vocab:
            raise ValueError(
                f"`{argname}`: argument {n!r} is ambiguous (initial or final value of state "
                f"{n!r}); write {n + '_0'!r} or {n + '_f'!r}")
        if len(vocab[n]) > 1:
            raise ValueError(
                f"`{argname}`: argument {n!r} is ambiguous: it names more than one input "
                f"{[positional[i] + f'[{j}]' for i, j in vocab[n]]}; rename the model's "
                f"component or use the positional form {kind}({', '.join(positional)})")
        where.append(vocab[n][0])

    def positional_call(*inputs):
        out = fun(**{n: inputs[i][j] for n, (i, j) in zip(names, where)})
        if isinstance(out, (list, tuple)):  # rows given as a list of expressions
            out = ca.vertcat(*[ca.vec(o) if isinstance(o, (ca.SX, ca.MX, ca.DM)) else o
                               for o in out]) if out else ca.DM.zeros(0, 1)
        return out

    positional_call.__name__ = getattr(fun, "__name__", kind)
    return positional_call


@cache.constructs
def canonical(fun, inputs: Sequence[tuple[str, int]], out_name: str, argname: str, *,
              scalar: bool = False) -> ca.Function:
    """A user Function or (positional) callable as a named-I/O Function with one flattened
    output.

    Built under the construction lock (`dynamics.cache`), the user's callable evaluated on
    symbols with it: problems are stated in the tasks of thread pools
    (`problems.slew.maneuver_table`), and two threads building symbols at once can corrupt
    CasADi's reference counts.

    Parameters
    ----------
    fun : casadi.Function or callable
        Of the inputs in order; a callable may return a list (its first item is taken) or a
        number or array (constant).
    inputs : sequence of (str, int)
        Name and number of elements of each input (column vectors).
    out_name : str
        Name of the output.
    argname : str
        Name of the argument in messages; also gives the Function's name (``'path[0]'`` ->
        ``'path_0'``).
    scalar : bool, optional
        Require one output element.

    Returns
    -------
    casadi.Function
        On SX symbols when ``fun`` allows it (cheaper), else on MX.

    Raises
    ------
    ValueError
        Naming ``argname``: wrong number or sizes of inputs, not callable, not evaluable on
        symbols, not a scalar when ``scalar``.
    """
    names = [n for n, _ in inputs]
    sizes = [s for _, s in inputs]
    signature = f"({', '.join(f'{n} ({s},)' for n, s in inputs)})"
    if isinstance(fun, ca.Function):
        if fun.n_in() != len(inputs) or fun.n_out() < 1:
            raise ValueError(
                f"`{argname}` must be a casadi.Function of {signature}, got "
                f"{fun.n_in()} inputs {tuple(fun.name_in())}"
            )
        for i, (n, s) in enumerate(inputs):
            if fun.numel_in(i) != s:
                raise ValueError(
                    f"`{argname}`: input {i} ({fun.name_in(i)!r}) must have {s} elements "
                    f"(the {n} of the problem), got {fun.numel_in(i)}; expected {signature}"
                )
        call = lambda *a: fun(*[ca.reshape(ai, fun.size_in(i)) for i, ai in enumerate(a)])  # noqa: E731
    elif callable(fun):
        call = fun
    else:
        raise ValueError(f"`{argname}` must be a casadi.Function or a callable of {signature}, "
                         f"got {type(fun).__name__}")
    last_error = None
    for sym in (ca.SX, ca.MX):  # SX when the function allows it (cheaper), else MX
        syms = [sym.sym(n, s) for n, s in zip(names, sizes)]
        try:
            out = call(*syms)
        except Exception as exc:  # noqa: BLE001 - retried with MX, then reported
            last_error = exc
            continue
        if isinstance(out, (list, tuple)):
            out = out[0]
        if isinstance(out, (int, float, np.ndarray)):
            out = sym(ca.DM(np.asarray(out, dtype=float)))
        out = ca.vec(out)
        if scalar and out.numel() != 1:
            raise ValueError(f"`{argname}` must return a scalar, got shape {out.shape}")
        fname = re.sub(r"_+", "_", re.sub(r"\W", "_", argname)).strip("_")  # 'path[0]' -> 'path_0'
        return ca.Function(fname, syms, [out], names, [out_name])
    raise ValueError(f"`{argname}` could not be evaluated on symbols of {signature}: {last_error}")
