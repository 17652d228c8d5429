"""Optimal-control problem statement (no transcription, no solver).

A `Problem` says *what* is optimized: the dynamics (a `dynamics.Model`), the horizon (fixed
or free final time), bounds, boundary conditions, path constraints and the cost. How it is
discretized lives in `ocp.transcription`; how it is solved in `ocp.solve`.

The problem, on ``t in [t0, t0 + T]``::

    minimize     J = phi(x(tf), p, T) + integral_t0^tf L(x, u, p) dt   (maximize with maximize=True)
    over         x(t), u(t), the free parameters p, and T when it is free
    subject to   xdot = f(x, u, p)                                  (model.f)
                 x_lower <= x(t) <= x_upper, u_lower <= u(t) <= u_upper
                 p_lower <= p <= p_upper,    T_min <= T <= T_max
                 x(t0)_i = x_initial_i, x(tf)_i = x_final_i          (components given)
                 lower <= g(x(t), u(t), p) <= upper                  (path constraints)
                 lower <= c(x(t0), x(tf), p) <= upper                (boundary constraints)
                 q(tf) = +/- q_final  (or within an angle q_final_tol)  (attitude target)

Quaternion states
-----------------
The statement itself is generic: everything attitude-specific (the checks below, the NLP
rows, the SLERP guess) lives in `ocp.attitude`; ``q_final`` and ``q_final_tol`` are the
fields through which a problem asks for it.

For a model with an attitude (``model.attitude = (iq, iw)``) the quaternion ``q = x[iq:iq+4]``
has unit norm. The continuous dynamics preserve ``|q|`` exactly, so the norm is imposed at
``t0`` only: a fully given initial quaternion must have unit norm (to 1e-6; it is then
normalized), and a free or partly free one gets the constraint ``|q(t0)|^2 = 1``. Imposing
``|q|^2 = 1`` at every node as well would over-determine the discrete dynamics (collocation
does not conserve the norm exactly, and the controls cannot steer it), leaving IPOPT an
inconsistent or degenerate problem. The discrete drift of ``|q|`` is of the order of the
transcription's error and is reported as `Solution.quaternion_norm_error`.

The terminal attitude target ``q_final`` is met *up to sign* (``q`` and ``-q`` are the same
attitude) through the three equations ``vec(q_final^* (x) q(tf)) = 0``: the vector part of the
error quaternion vanishes exactly when ``q(tf)`` is parallel to ``q_final``. Unlike
``1 - (q_final . q(tf))^2 = 0`` (whose gradient is parallel to that of the norm, violating
LICQ at the solution), these rows have full rank and are orthogonal to ``q(tf)``. Fixing all
four quaternion components in ``x_final`` is refused for the same reason (four equations
for three degrees of freedom): use ``q_final``.
"""
from __future__ import annotations

import inspect
import math
import re
from dataclasses import dataclass, replace
from typing import Callable, Mapping, Sequence, Union

import casadi as ca
import numpy as np

from dynamics.model import Model

from .attitude import attitude_error, check_attitude, needs_norm_at_t0

__all__ = ["Problem", "Constraint"]

FunctionLike = Union[ca.Function, Callable]


@dataclass(frozen=True)
class Constraint:
    """A vector constraint ``lower <= fun(...) <= upper`` with an optional row scale.

    Parameters
    ----------
    fun : casadi.Function or callable
        Path constraints: ``g(x, u, p)``; boundary constraints: ``c(x0, xf, p)``. A callable
        is called once with CasADi SX symbols of those sizes and must return an expression;
        or it takes scalar components by name (``Constraint(lambda h, v: h * v, 0, 1)``;
        boundary names ``h_0``/``h_f``; see `Problem`, Notes). The output (any shape) is
        flattened column-major to ``m`` rows.
    lower, upper : float or array_like, shape (m,)
        Bounds (``-inf``/``inf`` for none). Defaults: ``g <= 0``.
    scale : float or array_like, shape (m,), optional
        Typical magnitude of each row (the NLP uses ``g / scale``); by default chosen from the
        gradient at the initial guess (see `ocp.scaling`).
    name : str, optional
        Label used in messages.
    """

    fun: FunctionLike
    lower: object = -math.inf
    upper: object = 0.0
    scale: object = None
    name: str = ""

    @property
    def size(self) -> int:
        """Number of rows ``m`` (after `Problem` normalized it)."""
        return int(np.size(self.lower))


def _as_vector(value, n: int, argname: str, *, allow_nan=False) -> np.ndarray:
    try:
        a = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"`{argname}` must be numeric: {exc}") from None
    if a.ndim == 0:
        a = np.full(n, float(a))
    a = a.reshape(-1) if a.ndim == 1 or a.size == n else a
    if a.shape != (n,):
        raise ValueError(f"`{argname}` must have shape ({n},), got {np.shape(value)}")
    if not allow_nan and np.any(np.isnan(a)):
        raise ValueError(f"`{argname}` must not contain NaN, got {a.tolist()}")
    return a


def _read_only(value) -> None:
    if isinstance(value, np.ndarray):
        value.setflags(write=False)


def _index(names: tuple[str, ...], key, argname: str) -> int:
    if key not in names:
        raise ValueError(f"`{argname}` names unknown component {key!r}; expected one of {names}")
    return names.index(key)


def _values(arg, names: tuple[str, ...], argname: str) -> np.ndarray:
    """Boundary values: mapping name -> value (others free), or array with NaN = free."""
    n = len(names)
    out = np.full(n, np.nan)
    if arg is None:
        return out
    if isinstance(arg, Mapping):
        for key, value in arg.items():
            i = _index(names, key, argname)
            if value is None:
                continue
            v = float(value)
            if not math.isfinite(v):
                raise ValueError(f"`{argname}`[{key!r}] must be finite or None, got {value!r}")
            out[i] = v
        return out
    if isinstance(arg, (list, tuple)):
        arg = [np.nan if v is None else v for v in arg]
    a = _as_vector(arg, n, argname, allow_nan=True)
    if np.any(np.isinf(a)):
        raise ValueError(f"`{argname}` must be finite (NaN or None marks a free component), got {a.tolist()}")
    return a


def _bounds(arg, names: tuple[str, ...], argname: str) -> np.ndarray:
    """Bounds: mapping name -> (lo, hi), or a pair (lower (n,), upper (n,)). Shape (2, n)."""
    n = len(names)
    out = np.array([np.full(n, -np.inf), np.full(n, np.inf)])
    if arg is None:
        return out
    if isinstance(arg, Mapping):
        for key, pair in arg.items():
            i = _index(names, key, argname)
            try:
                lo, hi = pair
            except (TypeError, ValueError):
                raise ValueError(f"`{argname}`[{key!r}] must be a pair (lower, upper), got {pair!r}") from None
            out[0, i] = -np.inf if lo is None else float(lo)
            out[1, i] = np.inf if hi is None else float(hi)
    else:
        try:
            lo, hi = arg
        except (TypeError, ValueError):
            raise ValueError(
                f"`{argname}` must be a mapping name -> (lower, upper) or a pair (lower, upper) "
                f"of arrays of shape ({n},)"
            ) from None
        lo = -np.inf if lo is None else lo
        hi = np.inf if hi is None else hi
        out[0] = _as_vector(lo, n, f"{argname}[0]")
        out[1] = _as_vector(hi, n, f"{argname}[1]")
    if np.any(np.isnan(out)):
        raise ValueError(f"`{argname}` must not contain NaN")
    bad = np.flatnonzero(out[0] > out[1])
    if bad.size:
        raise ValueError(
            f"`{argname}`: lower bound exceeds upper bound for {[names[i] for i in bad]}: "
            f"{out[0, bad].tolist()} > {out[1, bad].tolist()}"
        )
    out.setflags(write=False)
    return out


# ------------------------------------------------------------ callables by name
# the positional convention of each kind of function and the inputs its names refer to
_POSITIONAL = {
    "lagrange": ("x", "u", "p"),
    "path": ("x", "u", "p"),
    "mayer": ("xf", "p", "T"),
    "boundary": ("x0", "xf", "p"),
}


def _vocabulary(kind: str, model: Model) -> dict[str, list[tuple[int, int]]]:
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


def _valid_names(kind: str, model: Model) -> str:
    if kind in ("lagrange", "path"):
        return (f"states {list(model.states)}, controls {list(model.controls)}, "
                f"parameters {list(model.params)}")
    if kind == "mayer":
        return (f"final states {list(model.states)} (or with the suffix '_f'), parameters "
                f"{list(model.params)}, and 'T' (the horizon)")
    return (f"initial states {[s + '_0' for s in model.states]}, final states "
            f"{[s + '_f' for s in model.states]}, parameters {list(model.params)}")


def _by_name(fun, kind: str, model: Model, argname: str):
    """``fun`` itself when it takes the positional arguments of ``kind``; else a positional
    wrapper that calls it with the scalar components its parameter names denote.

    A plain callable (not a ``casadi.Function``) whose parameters can all be passed by keyword
    is taken by name when every parameter name is a name of ``kind`` (`_vocabulary`) and the
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
    positional = _POSITIONAL[kind]
    if names == positional:
        return fun
    vocab = _vocabulary(kind, model)
    state_names = set(model.states)
    # a state name without suffix in `boundary` is recognized but ambiguous (x0 or xf)
    recognized = [n in vocab or (kind == "boundary" and n in state_names) for n in names]
    required = sum(p.default is inspect.Parameter.empty for p in params)
    takes_positional = required <= len(positional) <= len(params)
    if not all(recognized) and takes_positional:
        return fun  # the positional convention, under other names (as `lambda xf_, p_, T`)
    valid = _valid_names(kind, model)
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


def _canonical(fun, inputs: Sequence[tuple[str, int]], out_name: str, argname: str, *,
               scalar: bool = False) -> ca.Function:
    """A user Function or callable as a named-I/O Function with one flattened output."""
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


@dataclass(frozen=True, eq=False)
class Problem:
    """Statement of an optimal-control problem (immutable, validated on creation).

    Parameters
    ----------
    model : dynamics.Model
        Dynamics ``xdot = f(x, u, p)``.
    T : float or tuple (T_min, T_max) [s]
        Horizon length ``tf - t0``: fixed (``T > 0``), or free within ``0 <= T_min < T_max``
        (``T_max`` may be ``inf``). Stored as given: a float, or a tuple of two floats.
    x_initial, x_final : mapping of str to float, or array_like, shape (nx,), optional
        Boundary values of the states at ``t0`` and ``tf``. A mapping gives values by state
        name, unlisted states are free; an array marks free components by NaN or None.
        Stored as arrays of shape (nx,) with NaN for free components.
    x_bounds, u_bounds : mapping of str to (lower, upper), or (lower, upper), optional
        Bounds on states (at every state node) and controls (at every control node); by name
        or as two arrays of shape (nx,)/(nu,); ``None``/``inf`` for none. Stored as arrays of
        shape (2, nx) and (2, nu).
    p : mapping of str to float, or array_like, shape (np,), optional
        Parameter values: the value of every fixed parameter and the initial guess of the
        free ones. Defaults to ``model.p_default``. Stored as shape (np,).
    p_bounds : mapping of str to (lower, upper), or (lower, upper) arrays of shape (np,), optional
        Parameters listed in the mapping are optimized (static parameters) within their
        bounds; all others are fixed at ``p``. In the array form, components with
        ``lower == upper`` are fixed (at ``p``). Stored as shape (2, np), fixed ones with
        ``lower == upper == p``.
    lagrange : casadi.Function or callable, optional
        Running cost ``L(x, u, p)`` (scalar) [cost/s]; a callable may instead take states,
        controls and parameters by name (see Notes): ``lagrange=lambda u: 0.5 * u**2``.
    mayer : casadi.Function or callable, optional
        Terminal cost ``phi(xf, p, T)`` (scalar). ``mayer=lambda xf, p, T: T`` is minimum time
        By name: ``mayer=lambda T: T``, or ``mayer=lambda h: -h`` (minimizes ``-h(tf)``).
    path : Constraint, casadi.Function, callable, or a sequence of them
        Path constraints ``g(x, u, p)``; a bare Function/callable means ``g <= 0``.
        Imposed at the control nodes of the transcription. By name:
        ``path=lambda h, v: ...``.
    boundary : Constraint, casadi.Function, callable, or a sequence of them
        Boundary constraints ``c(x0, xf, p)``; a bare Function/callable means ``c = 0``.
        By name, initial values carry the suffix ``_0`` and final values ``_f``:
        ``boundary=lambda h_f, v_0: h_f - 2 * v_0``.
    q_final : array_like, shape (4,), optional
        Target attitude (scalar-last unit quaternion) at ``tf``, met up to sign. Needs
        ``model.attitude``. Normalized on input (its norm must be 1 to 1e-6).
    q_final_tol : float, optional [rad]
        Pointing tolerance: ``0`` (default) imposes ``q(tf) = +/- q_final`` exactly (three
        equations); ``0 < tol < pi`` lets the final attitude lie within a rotation angle
        ``tol`` of the target (one inequality ``|vec(q_final^* (x) q(tf))|^2 <= sin^2(tol/2)``).
    t0 : float, optional [s]
        Initial time (the dynamics are time-invariant; ``t0`` only offsets output times).
    name : str, optional
    maximize : bool, optional
        ``True`` maximizes ``J = phi + integral L`` instead of minimizing it (default
        ``False``). ``lagrange`` and ``mayer`` are kept as given (`replace` does not negate
        them again); the NLP minimizes ``objective_sign * J`` = ``-J``, `Solution.cost` is
        ``J`` itself (the maximized value), and multipliers and costates belong to the
        minimized objective ``-J`` (``H = -L + lambda . f``). Compare costs with `better`.

    Raises
    ------
    TypeError
        If ``model`` is not a `dynamics.Model`.
    ValueError
        Naming the argument: wrong shapes or unknown names, lower > upper, a bad horizon
        ``T``, boundary values outside the bounds, functions of the wrong signature,
        ``q_final`` without an attitude or not of unit norm, a non-unit fixed initial
        quaternion, all four final quaternion components fixed (use ``q_final``),
        ``maximize`` not ``True``/``False``.

    Notes
    -----
    **Functions by name.** A Python callable given as ``lagrange``, ``mayer``, ``path`` or
    ``boundary`` (also as the ``fun`` of a `Constraint`) is called in one of two ways, told
    apart by `inspect.signature`:

    * *positional* (as a ``casadi.Function`` always is): with the column vectors
      ``(x, u, p)`` (``lagrange``, ``path``), ``(xf, p, T)`` (``mayer``) or ``(x0, xf, p)``
      (``boundary``), whatever the parameter names (``lambda xf_, p_, T`` works);
    * *by name*: with scalar symbols, when every parameter name is a name of the problem
      and the names are not exactly the positional ones above:

      ==================  ==========================================================
      ``lagrange, path``  a state, control or parameter name: its value at time t
      ``mayer``           a state name, or the state name + ``_f``: its final value;
                          a parameter name; ``T``: the horizon length [s]
      ``boundary``        a state name + ``_0`` (initial value) or + ``_f`` (final
                          value); a parameter name. A bare state name is refused
                          (ambiguous)
      ==================  ==========================================================

      Such a callable may return one expression or a list of them (stacked into rows;
      the positional form takes the first item of a list, as it did before).

    A callable that cannot take the three positional arguments (fewer parameters, or more
    without defaults) must name its arguments so: a name that is not one of the problem
    (a typo, a control in ``mayer``) or that is ambiguous (a bare state name in
    ``boundary``; a name that denotes two inputs, like ``T`` in ``mayer`` for a model
    with a component ``T``) raises ValueError naming the argument and listing the valid
    names. A callable with ``*args``, ``**kwargs`` or positional-only parameters is always
    positional. For a model whose names coincide with the positional ones (the double
    integrator's state ``x`` and control ``u``), ``lambda x, u, p`` is positional and
    ``lambda x, u`` by name. Stored attributes are the same either way: canonical
    Functions of the positional inputs.

    Quaternion norm handling and the sign-free attitude target are described in the module
    docstring of `ocp.problem`.

    Examples
    --------
    Minimum energy (Bryson & Ho: J = 6) and minimum time (T = 2) of the double integrator,
    rest to rest over a unit distance:

    >>> import casadi as ca
    >>> from dynamics.model import Model
    >>> import ocp
    >>> x, u, p = ca.SX.sym("x", 2), ca.SX.sym("u"), ca.SX.sym("p", 0)
    >>> f = ca.Function("f", [x, u, p], [ca.vertcat(x[1], u)], ["x", "u", "p"], ["xdot"])
    >>> model = Model(f, ("x", "v"), ("u",))  # the double integrator x'' = u
    >>> energy = ocp.Problem(model, T=1.0, x_initial=[0, 0], x_final=[1, 0],
    ...                       lagrange=lambda x, u, p: 0.5 * u**2)
    >>> fastest = ocp.Problem(model, T=(0.1, 10.0), x_initial=[0, 0], x_final=[1, 0],
    ...                        u_bounds={"u": (-1, 1)}, mayer=lambda xf, p, T: T)
    >>> energy.free_time, fastest.free_time, fastest.T_bounds
    (False, True, (0.1, 10.0))

    The same two problems with the functions taking the model's names:

    >>> energy = ocp.Problem(model, T=1.0, x_initial=[0, 0], x_final=[1, 0],
    ...                       lagrange=lambda u: 0.5 * u**2)
    >>> fastest = ocp.Problem(model, T=(0.1, 10.0), x_initial=[0, 0], x_final=[1, 0],
    ...                        u_bounds={"u": (-1, 1)}, mayer=lambda T: T,
    ...                        boundary=lambda x_f, v_0: [x_f - 1, v_0])
    >>> energy.lagrange.name_in(), fastest.mayer.name_in()
    (['x', 'u', 'p'], ['xf', 'p', 'T'])
    """

    model: Model
    T: object
    x_initial: object = None
    x_final: object = None
    x_bounds: object = None
    u_bounds: object = None
    p: object = None
    p_bounds: object = None
    lagrange: object = None
    mayer: object = None
    path: object = ()
    boundary: object = ()
    q_final: object = None
    q_final_tol: float = 0.0
    t0: float = 0.0
    name: str = "ocp"
    maximize: bool = False

    def __post_init__(self):
        model = self.model
        if not isinstance(model, Model):
            raise TypeError(f"`model` must be a dynamics.Model, got {type(model).__name__}")
        put = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731
        nx, nu, np_ = model.nx, model.nu, model.np
        if not isinstance(self.maximize, (bool, np.bool_)):
            raise ValueError(f"`maximize` must be True or False, got {self.maximize!r}")
        put("maximize", bool(self.maximize))

        # horizon
        T = self.T
        if isinstance(T, (tuple, list, np.ndarray)):
            if len(T) != 2:
                raise ValueError(f"`T` must be a float or a pair (T_min, T_max), got {T!r}")
            lo, hi = float(T[0]), float(T[1])
            if not (math.isfinite(lo) and lo >= 0 and hi > lo) or math.isnan(hi):
                raise ValueError(f"`T` bounds must satisfy 0 <= T_min < T_max, got ({lo}, {hi})")
            put("T", (lo, hi))
        else:
            try:
                T = float(T)
            except (TypeError, ValueError):
                raise ValueError(f"`T` must be a float or a pair (T_min, T_max), got {T!r}") from None
            if not (math.isfinite(T) and T > 0):
                raise ValueError(f"`T` (horizon length) must be finite and > 0, got {T}")
            put("T", T)
        t0 = float(self.t0)
        if not math.isfinite(t0):
            raise ValueError(f"`t0` must be finite, got {self.t0}")
        put("t0", t0)

        # bounds and boundary values
        xb = _bounds(self.x_bounds, model.states, "x_bounds")
        ub = _bounds(self.u_bounds, model.controls, "u_bounds")
        put("x_bounds", xb)
        put("u_bounds", ub)
        for argname in ("x_initial", "x_final"):
            v = _values(getattr(self, argname), model.states, argname)
            given = ~np.isnan(v)
            out = given & ((v < xb[0]) | (v > xb[1]))
            if np.any(out):
                i = np.flatnonzero(out)
                raise ValueError(
                    f"`{argname}` lies outside `x_bounds` for {[model.states[j] for j in i]}: "
                    f"{v[i].tolist()} not in [{xb[0, i].tolist()}, {xb[1, i].tolist()}]"
                )
            put(argname, v)

        # parameters
        if self.p is None:
            p = np.array(model.p_default, dtype=float)
        elif isinstance(self.p, Mapping):
            p = np.array(model.p_default, dtype=float)
            for key, value in self.p.items():
                p[_index(model.params, key, "p")] = float(value)
        else:
            p = _as_vector(self.p, np_, "p")
        if not np.all(np.isfinite(p)):
            raise ValueError(f"`p` must be finite, got {p.tolist()}")
        pb = np.array(_bounds(self.p_bounds, model.params, "p_bounds"))
        if isinstance(self.p_bounds, Mapping):
            listed = np.zeros(np_, bool)
            for key in self.p_bounds:
                listed[model.params.index(key)] = True
            fixed = ~listed
        else:  # a pair of arrays: components with lower == upper are fixed at `p`
            fixed = pb[0] == pb[1]
        pb[0, fixed] = p[fixed]
        pb[1, fixed] = p[fixed]
        outside = (p < pb[0]) | (p > pb[1])
        if np.any(outside):
            i = np.flatnonzero(outside)
            raise ValueError(f"`p` lies outside `p_bounds` for {[model.params[j] for j in i]}")
        p.setflags(write=False)
        pb.setflags(write=False)
        put("p", p)
        put("p_bounds", pb)

        # cost and constraints
        xs, us, ps = ("x", nx), ("u", nu), ("p", np_)
        if self.lagrange is not None:
            put("lagrange", _canonical(_by_name(self.lagrange, "lagrange", model, "lagrange"),
                                       [xs, us, ps], "L", "lagrange", scalar=True))
        if self.mayer is not None:
            put("mayer", _canonical(_by_name(self.mayer, "mayer", model, "mayer"),
                                    [("xf", nx), ps, ("T", 1)], "phi", "mayer", scalar=True))
        put("path", self._constraints(self.path, "path", [xs, us, ps], (-math.inf, 0.0), model))
        put("boundary", self._constraints(self.boundary, "boundary",
                                          [("x0", nx), ("xf", nx), ps], (0.0, 0.0), model))

        # attitude (ocp.attitude)
        x0, qf, qtol = check_attitude(model, self.x_initial, self.x_final, self.q_final, self.q_final_tol)
        put("x_initial", x0)
        put("q_final", qf)
        put("q_final_tol", qtol)

        for argname in ("x_initial", "x_final"):
            getattr(self, argname).setflags(write=False)

    # ------------------------------------------------------------------ helpers
    @staticmethod
    def _constraints(arg, argname, inputs, default_bounds, model) -> tuple[Constraint, ...]:
        if arg is None:
            return ()
        items = list(arg) if isinstance(arg, (list, tuple)) else [arg]
        out = []
        for j, item in enumerate(items):
            label = f"{argname}[{j}]" if isinstance(arg, (list, tuple)) else argname
            if isinstance(item, Constraint):
                con = item
            else:
                con = Constraint(item, *default_bounds)
            fun = _canonical(_by_name(con.fun, argname, model, label), inputs,
                             "g" if argname == "path" else "c", label)
            m = fun.numel_out(0)
            if m == 0:
                raise ValueError(f"`{label}` returns no rows")
            lo = _as_vector(con.lower, m, f"{label}.lower")
            hi = _as_vector(con.upper, m, f"{label}.upper")
            if np.any(lo > hi):
                raise ValueError(f"`{label}`: lower bound exceeds upper bound ({lo.tolist()} > {hi.tolist()})")
            if np.all(np.isinf(lo)) and np.all(np.isinf(hi)):
                raise ValueError(f"`{label}` has no finite bound")
            scale = None
            if con.scale is not None:
                scale = _as_vector(con.scale, m, f"{label}.scale")
                if not np.all(np.isfinite(scale) & (scale > 0)):
                    raise ValueError(f"`{label}.scale` must be finite and > 0, got {scale.tolist()}")
                scale.setflags(write=False)
            lo.setflags(write=False)
            hi.setflags(write=False)
            out.append(Constraint(fun, lo, hi, scale, con.name or label))
        return tuple(out)

    # ----------------------------------------------------------------- pickling
    def __setstate__(self, state: dict) -> None:
        """Restore a pickled problem as it was normalized (no re-validation), its arrays
        read-only again (pickle does not keep numpy's write flag)."""
        for value in state.values():
            _read_only(value)
            for con in value if isinstance(value, tuple) else ():
                if isinstance(con, Constraint):
                    for part in (con.lower, con.upper, con.scale):
                        _read_only(part)
        for key, value in state.items():
            object.__setattr__(self, key, value)

    # --------------------------------------------------------------- properties
    @property
    def free_time(self) -> bool:
        """Whether the horizon length ``T`` is optimized."""
        return isinstance(self.T, tuple)

    @property
    def T_bounds(self) -> tuple[float, float]:
        """``(T_min, T_max)``; equal for a fixed horizon."""
        return self.T if self.free_time else (self.T, self.T)

    @property
    def objective_sign(self) -> float:
        """``+1.0`` (minimize) or ``-1.0`` (``maximize``): the NLP minimizes ``objective_sign * J``."""
        return -1.0 if self.maximize else 1.0

    def better(self, a: float, b: float) -> bool:
        """Whether cost ``a`` is strictly better than cost ``b`` for this problem.

        Parameters
        ----------
        a, b : float
            Values of the objective ``J`` (as `Solution.cost`, the user's sign).

        Returns
        -------
        bool
            ``a < b`` when minimizing, ``a > b`` when ``maximize``; ``False`` if ``a`` is NaN,
            ``True`` if ``b`` is NaN and ``a`` is not.
        """
        a, b = float(a), float(b)
        if math.isnan(a):
            return False
        if math.isnan(b):
            return True
        return self.objective_sign * a < self.objective_sign * b

    @property
    def free_params(self) -> np.ndarray:
        """Indices of the optimized parameters, shape (k,)."""
        return np.flatnonzero(self.p_bounds[0] < self.p_bounds[1])

    @property
    def quaternion_norm_at_t0(self) -> bool:
        """Whether the NLP needs ``|q(t0)|^2 = 1`` (attitude model, initial quaternion not
        given; `ocp.attitude.needs_norm_at_t0`)."""
        return needs_norm_at_t0(self.model, self.x_initial)

    def attitude_error(self, qf):
        """Vector part of ``q_final^* (x) qf`` (zero iff ``qf = +/- q_final``), shape (3,).

        Parameters
        ----------
        qf : casadi 4x1 or array_like, shape (4,)
        """
        if self.q_final is None:
            raise ValueError("this problem has no `q_final`")
        return attitude_error(self.q_final, qf)

    def replace(self, **changes) -> "Problem":
        """A copy with some fields changed (validated again), like `dataclasses.replace`.

        ``lagrange`` and ``mayer`` are stored as given (never negated), so a copy of a
        ``maximize`` problem maximizes the same ``J``.
        """
        return replace(self, **changes)
