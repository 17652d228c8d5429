"""The `Model` container: a named-I/O CasADi right-hand side plus its metadata.

A model is ``xdot = f(x, u, p)`` with ``x`` the state, ``u`` the control and ``p`` static
parameters. Every other part of appdyn (simulation, linearization, collocation) consumes
models only through this container.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Mapping

import casadi as ca
import numpy as np

from . import cache

__all__ = ["Model", "check_model", "model_from_expressions", "named_symbols"]


def _freeze(mapping: Mapping | None) -> Mapping:
    return MappingProxyType(dict(mapping or {}))


def _function_from_text(text: str) -> ca.Function:
    return ca.Function.deserialize(text)


def _rebuild_model(f: str, states, controls, params, p_default, units: dict,
                   invariants: dict, name: str, attitude, layout=None, bounds=None) -> "Model":
    """Inverse of `Model.__reduce__`: deserialize the Functions, re-check, re-freeze."""
    return Model(_function_from_text(f), states, controls, params, p_default=p_default,
                 units=units,
                 invariants={k: _function_from_text(v) for k, v in invariants.items()},
                 name=name, attitude=attitude, layout=layout or {}, bounds=bounds or {})


@dataclass(frozen=True)
class Model:
    """A dynamic system ``xdot = f(x, u, p)`` as a named-I/O CasADi Function.

    Parameters
    ----------
    f : casadi.Function
        Inputs named ``('x', 'u', 'p')`` (column vectors of sizes ``nx``, ``nu``, ``np``),
        one output named ``'xdot'`` of size ``nx``.
    states, controls, params : tuple of str
        Names of the components of ``x``, ``u`` and ``p``, in order.
    p_default : array_like, shape (np,)
        Default parameter values, used whenever ``p`` is not given.
    units : mapping of str to str, optional
        Unit of each named component (``{'w1': 'rad/s', ...}``).
    invariants : mapping of str to casadi.Function, optional
        Quantities conserved (or otherwise monitored) along solutions; each is a Function of
        ``(x, p)`` with one output named like the key.
    name : str, optional
        Human-readable model name.
    attitude : tuple of int, optional
        ``(iq, iw)``: the state indices where a unit quaternion ``x[iq:iq+4]`` (scalar-last)
        and its body angular velocity ``x[iw:iw+3]`` [rad/s] start, for models that carry
        an attitude. Geometric integrators and attitude linearization use it; ``None``
        when the model has no attitude.
    layout : mapping of str to PartLayout, optional
        For a model assembled from parts (`dynamics.scene.Scene.model`): each part's name to
        its slices of ``x`` and ``u`` (`dynamics.scene.PartLayout`). Read states and controls
        through it (``x[model.layout["wheels"].states]``), never by literal index.
    bounds : mapping of str to (float, float), optional
        Bounds ``(lower, upper)`` of named states and controls that come with the model (a
        part's ``u_max``, a wheel's ``speed_max``); names without bounds are unbounded.

    Raises
    ------
    TypeError
        If ``f`` or an invariant is not a ``casadi.Function``.
    ValueError
        If the I/O names or sizes of ``f`` or of an invariant do not match the name tuples.

    Examples
    --------
    >>> import casadi as ca
    >>> from appdyn.dynamics import Model
    >>> x, u, p = ca.SX.sym("x", 2), ca.SX.sym("u", 1), ca.SX.sym("p", 1)
    >>> f = ca.Function("oscillator", [x, u, p], [ca.vertcat(x[1], -p[0] * x[0] + u[0])],
    ...                 ["x", "u", "p"], ["xdot"])
    >>> model = Model(f, ("y", "ydot"), ("force",), ("k",), p_default=[4.0],
    ...               units={"y": "m", "ydot": "m/s", "force": "N/kg", "k": "1/s^2"})
    >>> model.nx, model.nu, model.np
    (2, 1, 1)
    >>> model.f(x=[1.0, 0.0], u=0.0, p=model.p_default)["xdot"]
    DM([0, -4])
    """

    f: ca.Function
    states: tuple[str, ...]
    controls: tuple[str, ...]
    params: tuple[str, ...] = ()
    p_default: np.ndarray = field(default_factory=lambda: np.zeros(0))
    units: Mapping[str, str] = field(default_factory=dict)
    invariants: Mapping[str, ca.Function] = field(default_factory=dict)
    name: str = "model"
    attitude: tuple[int, int] | None = None
    layout: Mapping[str, object] = field(default_factory=dict)
    bounds: Mapping[str, tuple] = field(default_factory=dict)

    def __post_init__(self):
        if not isinstance(self.f, ca.Function):
            raise TypeError(f"`f` must be a casadi.Function, got {type(self.f).__name__}")
        object.__setattr__(self, "states", tuple(self.states))
        object.__setattr__(self, "controls", tuple(self.controls))
        object.__setattr__(self, "params", tuple(self.params))
        p_default = np.array(self.p_default, dtype=float).reshape(-1)
        p_default.setflags(write=False)
        object.__setattr__(self, "p_default", p_default)
        object.__setattr__(self, "units", _freeze(self.units))
        object.__setattr__(self, "invariants", _freeze(self.invariants))
        object.__setattr__(self, "layout", _freeze(self.layout))
        unknown = [k for k in self.bounds if k not in self.states and k not in self.controls]
        if unknown:
            raise ValueError(f"`bounds` names unknown state(s) or control(s) {unknown}")
        object.__setattr__(self, "bounds", _freeze(
            {k: (float(lo), float(hi)) for k, (lo, hi) in dict(self.bounds).items()}))

        if self.f.name_in() != ["x", "u", "p"] or self.f.name_out() != ["xdot"]:
            raise ValueError(
                "`f` must have inputs ('x', 'u', 'p') and output ('xdot',), got "
                f"{tuple(self.f.name_in())} -> {tuple(self.f.name_out())}"
            )
        sizes = {"x": len(self.states), "u": len(self.controls), "p": len(self.params)}
        for arg, n in sizes.items():
            if self.f.numel_in(arg) != n:
                raise ValueError(
                    f"input '{arg}' of `f` has {self.f.numel_in(arg)} elements but "
                    f"{n} names were given"
                )
        if self.f.numel_out("xdot") != sizes["x"]:
            raise ValueError(
                f"output 'xdot' of `f` has {self.f.numel_out('xdot')} elements, expected {sizes['x']}"
            )
        if p_default.size != sizes["p"]:
            raise ValueError(
                f"`p_default` must have {sizes['p']} values (one per parameter), got {p_default.size}"
            )
        if self.attitude is not None:
            iq, iw = (int(i) for i in self.attitude)
            if not (0 <= iq <= self.nx - 4 and 0 <= iw <= self.nx - 3):
                raise ValueError(f"`attitude` indices {self.attitude} do not fit {self.nx} states")
            object.__setattr__(self, "attitude", (iq, iw))
        for key, fun in self.invariants.items():
            if not isinstance(fun, ca.Function):
                raise TypeError(f"invariant {key!r} must be a casadi.Function")
            if fun.name_in() != ["x", "p"] or fun.n_out() != 1:
                raise ValueError(
                    f"invariant {key!r} must map inputs ('x', 'p') to one output, got "
                    f"{tuple(fun.name_in())} -> {tuple(fun.name_out())}"
                )

    # ----------------------------------------------------------- construction
    @classmethod
    def from_expressions(cls, states, xdot, controls=None, params=None, *, p_default=None,
                         units=None, invariants=None, name: str = "model",
                         attitude=None) -> "Model":
        """A model from CasADi SX expressions of named scalar symbols (`model_from_expressions`).

        Examples
        --------
        >>> import casadi as ca
        >>> from appdyn.dynamics import Model
        >>> x, v, u = ca.SX.sym("x"), ca.SX.sym("v"), ca.SX.sym("u")
        >>> model = Model.from_expressions({"x": x, "v": v}, {"x": v, "v": u}, {"u": u})
        >>> model.states, model.controls, model.params
        (('x', 'v'), ('u',), ())
        >>> model.rhs([0.0, 2.0], [3.0])
        array([2., 3.])
        """
        return model_from_expressions(states, xdot, controls, params, p_default=p_default,
                                      units=units, invariants=invariants, name=name,
                                      attitude=attitude)

    # --------------------------------------------------------------- pickling
    def __reduce__(self):
        """Pickle through CasADi's own serialization of ``f`` and the invariants.

        The mappings travel as plain dicts and are frozen again on load; the loaded model is
        a new object (with its own cache entries: the cache keys on the Function's identity).
        """
        return (_rebuild_model, (
            self.f.serialize(), self.states, self.controls, self.params,
            np.array(self.p_default), dict(self.units),
            {k: fun.serialize() for k, fun in self.invariants.items()},
            self.name, self.attitude, dict(self.layout), dict(self.bounds)))

    # ------------------------------------------------------------------ sizes
    @property
    def nx(self) -> int:
        """Number of states."""
        return len(self.states)

    @property
    def nu(self) -> int:
        """Number of controls."""
        return len(self.controls)

    @property
    def np(self) -> int:
        """Number of parameters."""
        return len(self.params)

    # ----------------------------------------------------------------- bounds
    def limits(self, which: str = "controls") -> tuple[np.ndarray, np.ndarray]:
        """The ``bounds`` of the controls or states as two arrays (``-inf``/``inf`` where none).

        Parameters
        ----------
        which : {'controls', 'states'}

        Returns
        -------
        lower, upper : numpy.ndarray, shape (nu,) or (nx,)

        Examples
        --------
        >>> from appdyn.dynamics.scene import ExternalTorque, RigidHub, Scene
        >>> Scene(RigidHub([1.0, 2.0, 3.0]), ExternalTorque(u_max=0.5)).model().limits()
        (array([-0.5, -0.5, -0.5]), array([0.5, 0.5, 0.5]))
        """
        if which not in ("controls", "states"):
            raise ValueError(f"`which` must be 'controls' or 'states', got {which!r}")
        names = self.controls if which == "controls" else self.states
        lo = np.array([self.bounds.get(k, (-np.inf, np.inf))[0] for k in names], dtype=float)
        hi = np.array([self.bounds.get(k, (-np.inf, np.inf))[1] for k in names], dtype=float)
        return lo, hi

    # ------------------------------------------------------------- evaluation
    def resolve_p(self, p=None) -> np.ndarray:
        """Return the parameter vector to use: ``p`` checked, or the defaults.

        Parameters
        ----------
        p : array_like, shape (np,), optional

        Returns
        -------
        numpy.ndarray, shape (np,)
        """
        if p is None:
            return np.array(self.p_default)
        p = np.array(p, dtype=float).reshape(-1)  # (a copy: a result keeps its own)
        if p.size != self.np:
            raise ValueError(f"`p` must have {self.np} elements {self.params}, got {p.size}")
        if not all(map(math.isfinite, p.tolist())):  # (floats: a few times numpy's speed)
            raise ValueError(f"`p` must be finite, got {p}")
        return p

    def rhs(self, x, u=None, p=None) -> np.ndarray:
        """Evaluate ``xdot`` numerically (convenience; not for hot loops).

        Parameters
        ----------
        x : array_like, shape (nx,)
        u : array_like, shape (nu,), optional (zero)
        p : array_like, shape (np,), optional (defaults)

        Returns
        -------
        numpy.ndarray, shape (nx,)
        """
        u = np.zeros(self.nu) if u is None else np.asarray(u, dtype=float).reshape(-1)
        out = self.f(x=np.asarray(x, dtype=float).reshape(-1), u=u, p=self.resolve_p(p))
        return np.asarray(out["xdot"]).reshape(-1)

    def invariant(self, key: str, x, p=None) -> np.ndarray:
        """Evaluate invariant ``key`` at one state or along a trajectory.

        Parameters
        ----------
        key : str
            One of ``invariants``.
        x : array_like, shape (nx,) or (nx, n)
        p : array_like, shape (np,), optional

        Returns
        -------
        numpy.ndarray, shape (m,) for one state or (m, n) along a trajectory; ``m`` is the
        invariant's size (a scalar invariant gives shape () or (n,)).
        """
        if key not in self.invariants:
            raise KeyError(f"unknown invariant {key!r}; this model has {sorted(self.invariants)}")
        fun = self.invariants[key]
        x = np.asarray(x, dtype=float)
        single = x.ndim == 1
        x2 = x.reshape(self.nx, -1)
        p = self.resolve_p(p)
        res = np.asarray(fun.map(x2.shape[1])(x2, np.tile(p[:, None], (1, x2.shape[1]))))
        if res.shape[0] == 1:
            res = res[0]
        return res[..., 0] if single else res


# ------------------------------------------------------- models from expressions
def named_symbols(arg, argname: str, *, required: bool = False) -> tuple[tuple[str, ...], list]:
    """``(names, symbols)`` of a mapping name -> scalar SX symbol or a sequence of pairs.

    Parameters
    ----------
    arg : mapping of str to casadi.SX, or sequence of (str, casadi.SX), or None
    argname : str
        The argument's name, for the errors.
    required : bool, optional
        Refuse ``None`` and an empty ``arg`` (else they give no names).

    Returns
    -------
    (tuple of str, list of casadi.SX)

    Raises
    ------
    TypeError, ValueError
        Naming ``argname``: not a mapping or pairs, a name not a str or given twice, a symbol
        not a scalar ``casadi.SX.sym``; with ``required``, nothing given.

    Examples
    --------
    >>> import casadi as ca
    >>> from appdyn.dynamics.model import named_symbols
    >>> named_symbols({"x": ca.SX.sym("x"), "v": ca.SX.sym("v")}, "states")
    (('x', 'v'), [SX(x), SX(v)])
    >>> named_symbols(None, "coords", required=True)
    Traceback (most recent call last):
        ...
    TypeError: `coords` must name at least one symbol: a mapping name -> casadi.SX symbol ...
    """
    if required and (arg is None or (isinstance(arg, (Mapping, list, tuple)) and not len(arg))):
        error = TypeError if arg is None else ValueError
        raise error(f"`{argname}` must name at least one symbol: a mapping name -> casadi.SX "
                    f"symbol or a sequence of (name, symbol) pairs, got {arg!r}")
    if arg is None:
        return (), []
    if isinstance(arg, Mapping):
        pairs = list(arg.items())
    elif isinstance(arg, (list, tuple)):
        pairs = list(arg)
        if not all(isinstance(pair, (list, tuple)) and len(pair) == 2 for pair in pairs):
            raise TypeError(f"`{argname}` must be a mapping name -> casadi.SX symbol or a "
                            f"sequence of (name, symbol) pairs, got {arg!r}")
    else:
        raise TypeError(f"`{argname}` must be a mapping name -> casadi.SX symbol or a sequence "
                        f"of (name, symbol) pairs, got {type(arg).__name__}")
    names, syms = [], []
    for key, sym in pairs:
        if not isinstance(key, str) or not key:
            raise TypeError(f"`{argname}`: names must be non-empty str, got {key!r}")
        if key in names:
            raise ValueError(f"`{argname}`: name {key!r} is given twice")
        if not isinstance(sym, ca.SX):
            raise TypeError(f"`{argname}`[{key!r}] must be a casadi.SX symbol, got "
                            f"{type(sym).__name__}")
        if sym.numel() != 1 or not sym.is_symbolic():
            raise ValueError(f"`{argname}`[{key!r}] must be a scalar symbol (casadi.SX.sym), "
                             f"got {sym}")
        names.append(key)
        syms.append(sym)
    return tuple(names), syms


def _scalar_expression(expr, label: str) -> ca.SX:
    if isinstance(expr, ca.MX):
        raise TypeError(f"{label} must be a casadi.SX expression or a number, got casadi.MX")
    try:
        out = ca.SX(expr)
    except (NotImplementedError, TypeError, RuntimeError):
        raise TypeError(f"{label} must be a casadi.SX expression or a number, got "
                        f"{type(expr).__name__}") from None
    if out.numel() != 1:
        raise ValueError(f"{label} must be a scalar expression, got shape {out.shape}")
    return out


def _check_declared(expr: ca.SX, declared: ca.SX, label: str, allowed: str) -> None:
    """ValueError naming the symbols of ``expr`` that are not among ``declared``."""
    free = [s.name() for s in ca.symvar(expr)
            if declared.numel() == 0 or not ca.depends_on(s, declared)]
    if free:
        raise ValueError(f"{label} depends on undeclared symbol(s) {free}; declare them in "
                         f"{allowed}")


@cache.constructs
def model_from_expressions(states, xdot, controls=None, params=None, *, p_default=None,
                           units=None, invariants=None, name: str = "model",
                           attitude=None) -> Model:
    """Build a `Model` from CasADi SX expressions of named scalar symbols.

    The named-I/O Function ``f(x, u, p) -> xdot`` is built here (no empty parameter
    symbol needed when there are no parameters or controls).

    Parameters
    ----------
    states : mapping of str to casadi.SX, or sequence of (str, casadi.SX)
        The state names and their scalar symbols (``casadi.SX.sym``), in state order.
    xdot : mapping of str to expression, or sequence of expressions
        Each state's derivative (an SX expression or a number): by state name, or in state
        order. Expressions may use only the declared state, control and parameter symbols.
    controls, params : mapping of str to casadi.SX, or sequence of (str, casadi.SX), optional
        The control and parameter names and symbols, in order (none by default).
    p_default : mapping of str to float, or array_like, shape (np,), optional
        Default parameter values, by name (every parameter) or in order. Needed when there
        are parameters.
    units : mapping of str to str, optional
        As `Model`.
    invariants : mapping of str to expression or casadi.Function, optional
        Monitored quantities: SX expressions of the states and parameters (scalar or
        vector), or ready Functions of ``(x, p)`` (as `Model`).
    name : str, optional
        Model name (also the name of the Function).
    attitude : tuple of (int or str), optional
        As `Model`; the two entries may also be state names (``("q1", "w1")``).

    Returns
    -------
    Model

    Raises
    ------
    TypeError
        If a symbol is not a ``casadi.SX`` or an expression is not SX or a number.
    ValueError
        Naming the argument: a state without an ``xdot`` (or an ``xdot`` without a state),
        a name given twice, a non-scalar symbol or derivative, an expression depending on an
        undeclared symbol, missing or extra ``p_default`` values.

    Examples
    --------
    A pendulum ``theta'' = -(g / l) sin(theta) + u``:

    >>> import casadi as ca
    >>> from appdyn.dynamics.model import model_from_expressions
    >>> th, om, u, g, l = (ca.SX.sym(n) for n in ("theta", "omega", "u", "g", "l"))
    >>> model = model_from_expressions(
    ...     [("theta", th), ("omega", om)], [om, -g / l * ca.sin(th) + u],
    ...     {"u": u}, {"g": g, "l": l}, p_default={"g": 9.81, "l": 1.0},
    ...     invariants={"energy": 0.5 * l**2 * om**2 + g * l * (1 - ca.cos(th))},
    ...     name="pendulum")
    >>> model.params, model.p_default
    (('g', 'l'), array([9.81, 1.  ]))
    >>> model.rhs([0.0, 1.0], [0.5])
    array([1. , 0.5])
    >>> float(model.invariant("energy", [0.0, 2.0]))
    2.0
    """
    state_names, xs = named_symbols(states, "states")
    control_names, us = named_symbols(controls, "controls")
    param_names, ps = named_symbols(params, "params")
    if not state_names:
        raise ValueError("`states` must name at least one state")
    seen: dict[str, str] = {}
    for argname, names in (("states", state_names), ("controls", control_names),
                           ("params", param_names)):
        for key in names:
            if key in seen:
                raise ValueError(f"name {key!r} is used in both `{seen[key]}` and `{argname}`")
            seen[key] = argname
    everything = xs + us + ps
    all_names = state_names + control_names + param_names
    for i in range(1, len(everything)):
        if ca.depends_on(everything[i], ca.vertcat(*everything[:i])):
            raise ValueError(f"{all_names[i]!r} reuses the symbol of an earlier name; "
                             "`states`, `controls` and `params` need distinct symbols")

    # derivatives, in state order
    if isinstance(xdot, Mapping):
        missing = [k for k in state_names if k not in xdot]
        if missing:
            raise ValueError(f"`xdot` gives no derivative for state(s) {missing}")
        extra = [k for k in xdot if k not in state_names]
        if extra:
            raise ValueError(f"`xdot` names unknown state(s) {extra}; the states are {state_names}")
        exprs = [xdot[k] for k in state_names]
    elif isinstance(xdot, (list, tuple)):
        if len(xdot) != len(state_names):
            raise ValueError(f"`xdot` must have {len(state_names)} expressions (one per state "
                             f"{state_names}), got {len(xdot)}")
        exprs = list(xdot)
    else:
        raise TypeError(f"`xdot` must be a mapping state name -> expression or a sequence of "
                        f"expressions, got {type(xdot).__name__}")
    declared = ca.vertcat(*everything)
    rhs = []
    for key, expr in zip(state_names, exprs):
        e = _scalar_expression(expr, f"`xdot`[{key!r}]")
        _check_declared(e, declared, f"`xdot`[{key!r}]", "`states`, `controls` or `params`")
        rhs.append(e)

    x = ca.vertcat(*xs)
    u = ca.vertcat(*us) if us else ca.SX.sym("u", 0)
    p = ca.vertcat(*ps) if ps else ca.SX.sym("p", 0)
    f = ca.Function(str(name) or "model", [x, u, p], [ca.vertcat(*rhs)], ["x", "u", "p"], ["xdot"])

    # parameter defaults
    if isinstance(p_default, Mapping):
        unknown = [k for k in p_default if k not in param_names]
        if unknown:
            raise ValueError(f"`p_default` names unknown parameter(s) {unknown}; the "
                             f"parameters are {param_names}")
        missing = [k for k in param_names if k not in p_default]
        if missing:
            raise ValueError(f"`p_default` gives no value for parameter(s) {missing}")
        p_default = [float(p_default[k]) for k in param_names]
    elif p_default is None:
        if param_names:
            raise ValueError(f"`p_default` must give a value for each parameter {param_names}")
        p_default = np.zeros(0)

    # invariants: expressions of (x, p), or Functions as `Model` takes them
    state_params = ca.vertcat(*(xs + ps))
    funs = {}
    for key, expr in dict(invariants or {}).items():
        if isinstance(expr, ca.Function):
            funs[key] = expr
            continue
        if isinstance(expr, ca.MX):
            raise TypeError(f"`invariants`[{key!r}] must be a casadi.SX expression or a "
                            "casadi.Function, got casadi.MX")
        e = ca.SX(expr) if not isinstance(expr, ca.SX) else expr
        _check_declared(e, state_params, f"`invariants`[{key!r}]", "`states` or `params`")
        funs[key] = ca.Function(str(key), [x, p], [ca.vec(e)], ["x", "p"], [str(key)])

    if attitude is not None:
        try:
            attitude = tuple(state_names.index(a) if isinstance(a, str) else a for a in attitude)
        except ValueError:
            raise ValueError(f"`attitude` names unknown state(s) in {attitude!r}; the states "
                             f"are {state_names}") from None
    return Model(f, state_names, control_names, param_names, p_default=p_default,
                 units=units or {}, invariants=funs, name=str(name), attitude=attitude)


def check_model(model, name: str = "model") -> Model:
    """``model`` if it is a `Model`; a ``TypeError`` naming ``name`` otherwise."""
    if not isinstance(model, Model):
        raise TypeError(f"`{name}` must be a dynamics.Model, got {type(model).__name__}")
    return model
