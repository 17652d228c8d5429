"""The `Model` container: a named-I/O CasADi right-hand side plus its metadata.

A model is ``xdot = f(x, u, p)`` with ``x`` the state, ``u`` the control and ``p`` static
parameters. Every other part of appdyn (simulation, linearization, collocation) consumes
models only through this container.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Mapping

import casadi as ca
import numpy as np

__all__ = ["Model", "check_model"]


def _freeze(mapping: Mapping | None) -> Mapping:
    return MappingProxyType(dict(mapping or {}))


def _function_from_text(text: str) -> ca.Function:
    return ca.Function.deserialize(text)


def _rebuild_model(f: str, states, controls, params, p_default, units: dict,
                   invariants: dict, name: str, attitude) -> "Model":
    """Inverse of `Model.__reduce__`: deserialize the Functions, re-check, re-freeze."""
    return Model(_function_from_text(f), states, controls, params, p_default=p_default,
                 units=units,
                 invariants={k: _function_from_text(v) for k, v in invariants.items()},
                 name=name, attitude=attitude)


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

    Raises
    ------
    TypeError
        If ``f`` or an invariant is not a ``casadi.Function``.
    ValueError
        If the I/O names or sizes of ``f`` or of an invariant do not match the name tuples.

    Examples
    --------
    >>> import casadi as ca
    >>> from dynamics import Model
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
            self.name, self.attitude))

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
        p = np.asarray(p, dtype=float).reshape(-1)
        if p.size != self.np:
            raise ValueError(f"`p` must have {self.np} elements {self.params}, got {p.size}")
        if not np.all(np.isfinite(p)):
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


def check_model(model, name: str = "model") -> Model:
    """``model`` if it is a `Model`; a ``TypeError`` naming ``name`` otherwise."""
    if not isinstance(model, Model):
        raise TypeError(f"`{name}` must be a dynamics.Model, got {type(model).__name__}")
    return model
