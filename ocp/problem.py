"""Optimal-control problem statement (no transcription, no solver).

A `Problem` says *what* is optimized: the dynamics (a `dynamics.Model`), the horizon (fixed
or free final time), bounds, boundary conditions, path constraints and the cost. How it is
discretized lives in `ocp.transcription`; how it is solved in `ocp.solve`. Its numeric
arguments are parsed by `ocp.arguments`, its functions made canonical by `ocp.functions`.

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

import math
from dataclasses import dataclass, replace
from typing import Callable, Union

import casadi as ca
import numpy as np

from appdyn.dynamics.model import Model

from .arguments import boundary_values, bounds, horizon, parameters, row_bounds
from .attitude import attitude_error, check_attitude, needs_norm_at_t0
from .functions import named_function

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


def _read_only(value) -> None:
    if isinstance(value, np.ndarray):
        value.setflags(write=False)


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
    >>> from appdyn.dynamics.model import Model
    >>> from appdyn import ocp
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
        if not isinstance(self.maximize, (bool, np.bool_)):
            raise ValueError(f"`maximize` must be True or False, got {self.maximize!r}")
        put("maximize", bool(self.maximize))
        put("T", horizon(self.T))
        t0 = float(self.t0)
        if not math.isfinite(t0):
            raise ValueError(f"`t0` must be finite, got {self.t0}")
        put("t0", t0)

        # bounds and boundary values (ocp.arguments)
        xb = bounds(self.x_bounds, model.states, "x_bounds")
        put("x_bounds", xb)
        put("u_bounds", bounds(self.u_bounds, model.controls, "u_bounds"))
        for argname in ("x_initial", "x_final"):
            v = boundary_values(getattr(self, argname), model.states, argname)
            out = ~np.isnan(v) & ((v < xb[0]) | (v > xb[1]))
            if np.any(out):
                i = np.flatnonzero(out)
                raise ValueError(
                    f"`{argname}` lies outside `x_bounds` for {[model.states[j] for j in i]}: "
                    f"{v[i].tolist()} not in [{xb[0, i].tolist()}, {xb[1, i].tolist()}]"
                )
            put(argname, v)
        p, pb = parameters(self.p, self.p_bounds, model)
        put("p", p)
        put("p_bounds", pb)

        # cost and constraints (ocp.functions)
        for kind in ("lagrange", "mayer"):
            if getattr(self, kind) is not None:
                put(kind, named_function(getattr(self, kind), kind, model, kind))
        put("path", self._constraints(self.path, "path", (-math.inf, 0.0), model))
        put("boundary", self._constraints(self.boundary, "boundary", (0.0, 0.0), model))

        # attitude (ocp.attitude)
        x0, qf, qtol = check_attitude(model, self.x_initial, self.x_final, self.q_final, self.q_final_tol)
        put("x_initial", x0)
        put("q_final", qf)
        put("q_final_tol", qtol)

        for argname in ("x_initial", "x_final"):
            getattr(self, argname).setflags(write=False)

    # ------------------------------------------------------------------ helpers
    @staticmethod
    def _constraints(arg, argname, default_bounds, model) -> tuple[Constraint, ...]:
        if arg is None:
            return ()
        items = list(arg) if isinstance(arg, (list, tuple)) else [arg]
        out = []
        for j, item in enumerate(items):
            label = f"{argname}[{j}]" if isinstance(arg, (list, tuple)) else argname
            con = item if isinstance(item, Constraint) else Constraint(item, *default_bounds)
            fun = named_function(con.fun, argname, model, label)
            m = fun.numel_out(0)
            if m == 0:
                raise ValueError(f"`{label}` returns no rows")
            lo, hi, scale = row_bounds(con.lower, con.upper, con.scale, m, label)
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
