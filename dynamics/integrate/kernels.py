"""One step of a method as a CasADi Function ``(x, h, u-data, p) -> x_next`` (SX where the
model allows): explicit Runge-Kutta from a `Tableau`, and the Lie-group method CF4."""
from __future__ import annotations

import casadi as ca
import numpy as np

from .. import cache
from ..attitude import propagate_quat, quat_rate
from ..model import Model
from .tableaux import (DOP853_DENSE_A, DOP853_DENSE_C, DOP853_DENSE_D, DOP853_E3, DOP853_E5,
                       TABLEAUX, unique_nodes)

__all__ = ["kernel", "check_lie_model", "INLINE_MAX", "calls_rhs", "dense_kernels"]

#: Most right-hand-side instructions a compiled Runge-Kutta step inlines (stages times the
#: rhs's instruction count); a larger step calls the rhs as a C function instead (see
#: `calls_rhs` and the module docstring of `dynamics.cache`, First compile).
INLINE_MAX = 2000


def _sym(f: ca.Function):
    """SX when ``f`` can be evaluated on SX (small, fast kernels), else MX."""
    try:
        f.call([ca.SX.sym("x", f.sparsity_in(i)) for i in range(f.n_in())])
        return ca.SX
    except RuntimeError:
        return ca.MX


def _kernel_inputs(sym, nx, nu, np_, mode, n_nodes):
    x, h, p = sym.sym("x", nx), sym.sym("h"), sym.sym("p", np_)
    if mode == "linear":
        ua, ud = sym.sym("ua", nu), sym.sym("ud", nu)
        return [x, h, ua, ud, p], (lambda c: ua + (c * h) * ud)
    us = sym.sym("us", nu * n_nodes)
    return [x, h, us, p], None


def _stage_control(mode, ins, nu, nodes_unique, linear_u):
    if mode == "linear":
        return linear_u
    us = ins[2]

    def u_at(c):
        j = nodes_unique.index(c)
        return us[j * nu:(j + 1) * nu]

    return u_at


def _rk_kernel(f: ca.Function, method: str, mode: str, error: bool = False,
               call: bool = False) -> ca.Function:
    """One explicit Runge-Kutta step ``(x, h, u-data, p) -> x_next`` as a Function.

    ``call``: the step calls ``f`` (an SX call node: ``f`` generated once as its own C
    function, the stages' sums scalar C); default SX where ``f`` allows (``f`` inlined in
    every stage), else MX.

    ``error`` (``rk8`` only): inputs ``rtol`` (scalar) and ``atol (nx)`` follow, and a
    second output is DOP853's embedded error estimate of the step (`DOP853_E5`), in units
    of the tolerance ``atol + rtol max(|x|, |x_next|)``.
    """
    tab = TABLEAUX[method]
    nx, nu, np_ = f.numel_in(0), f.numel_in(1), f.numel_in(2)
    nodes = unique_nodes(method)
    sym = ca.SX if call else _sym(f)
    ins, linear_u = _kernel_inputs(sym, nx, nu, np_, mode, len(nodes))
    u_at = _stage_control(mode, ins, nu, nodes, linear_u)
    x, h, p = ins[0], ins[1], ins[-1]
    k = _stages(f, tab.a, tab.c, x, h, u_at, p, [], call=call)
    x_next = x + h * _combine(tab.b, k)
    if not error:
        return ca.Function(f"{method}_step", ins, [x_next])
    rtol, atol = sym.sym("rtol"), sym.sym("atol", nx)
    err = _embedded_error(x, x_next, k, h, rtol, atol)
    return ca.Function(f"{method}_step_err", ins + [rtol, atol], [x_next, err])


def _stages(f: ca.Function, a, c, x, h, u_at, p, k: list, *, call=False) -> list:
    """The stages ``k_i = f(x + h sum_j a_ij k_j, u(c_i h), p)`` of the rows ``a`` (nodes
    ``c``) appended to the stages ``k`` already known; returns ``k``. ``call``: ``f`` is
    called (an SX call node, generated as a C call) rather than inlined."""
    for ai, ci in zip(a, c):
        xi = x
        for j, aij in enumerate(ai):
            if aij != 0.0:
                xi = xi + (aij * h) * k[j]
        k.append(f.call([xi, u_at(ci), p], not call, call)[0])
    return k


def _embedded_error(x, x_next, k: list, h, rtol, atol):
    """DOP853's embedded error estimate of a step (`DOP853_E5`, `DOP853_E3`) in units of
    the tolerance ``atol + rtol max(|x|, |x_next|)``."""
    scale = atol + rtol * ca.fmax(ca.fabs(x), ca.fabs(x_next))
    e5 = ca.sumsqr(_combine(DOP853_E5, k) / scale)
    e3 = ca.sumsqr(_combine(DOP853_E3, k) / scale)
    # (0/0 where both vanish: the floor keeps the quotient 0)
    return ca.fabs(h) * e5 / ca.sqrt(x.numel() * ca.fmax(e5 + 0.01 * e3, 1e-300))


def dense_kernels(model: Model) -> tuple[ca.Function, ca.Function]:
    """DOP853 with its dense output for a control constant over the run (cached):
    ``rk8_step_k (x, h, u, p, rtol, atol) -> (x_next, err, K)`` (``err`` as the ``error``
    step of `kernel`; ``K (12 nx)`` the stages, stacked) and ``rk8_cont (x, x_next, K, h,
    u, p) -> F (7 nx)``, the coefficients of the step's continuous extension of order 7
    (`tableaux.DOP853_DENSE_D`; four more right-hand sides, spent only on a step that
    holds an output time). The compiled pass generates them for a model whose right-hand
    side inlines (`calls_rhs` False); for a larger one it runs the same sums as C loops
    (`csteps`).

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics import rigid_body
    >>> from appdyn.dynamics.integrate.kernels import dense_kernels
    >>> step, cont = dense_kernels(rigid_body([1.0, 2.0, 3.0]))
    >>> x0, u, p = np.r_[0, 0, 0, 1, 0.1, 0.2, 0.3], np.zeros(3), np.zeros(0)
    >>> xn, err, K = step(x0, 0.5, u, p, 1e-8, 1e-10 * np.ones(7))
    >>> F = np.asarray(cont(x0, xn, K, 0.5, u, p)).reshape(7, 7)
    >>> bool(np.allclose(F[0], np.asarray(xn).ravel() - x0))  # F0 = x_next - x: the end is exact
    True
    """
    def build():
        f, tab = model.f, TABLEAUX["rk8"]
        sym = _sym(f)
        nx, nu, np_ = model.nx, model.nu, f.numel_in(2)
        x, h, u, p = sym.sym("x", nx), sym.sym("h"), sym.sym("u", nu), sym.sym("p", np_)
        rtol, atol = sym.sym("rtol"), sym.sym("atol", nx)
        k = _stages(f, tab.a, tab.c, x, h, lambda c: u, p, [])
        x_next = x + h * _combine(tab.b, k)
        step = ca.Function("rk8_step_k", [x, h, u, p, rtol, atol],
                           [x_next, _embedded_error(x, x_next, k, h, rtol, atol),
                            ca.vertcat(*k)])
        xn, K = sym.sym("x_next", nx), sym.sym("K", tab.stages * nx)
        k = [K[i * nx:(i + 1) * nx] for i in range(tab.stages)]
        k = _stages(f, ((),), (1.0,), xn, h, lambda c: u, p, k)  # k13 = f(x_next)
        k = _stages(f, DOP853_DENSE_A, DOP853_DENSE_C, x, h, lambda c: u, p, k)
        dx = xn - x
        F = [dx, h * k[0] - dx, 2 * dx - h * (k[12] + k[0])] + \
            [h * _combine(row, k) for row in DOP853_DENSE_D]
        cont = ca.Function("rk8_cont", [x, xn, K, h, u, p], [ca.vertcat(*F)])
        return step, cont

    return cache.get(("dense_kernels", cache.function_key(model.f)), build,
                     keepalive=model.f)


def _combine(weights, k: list):
    """``sum w_i k_i`` over the nonzero weights."""
    out = 0
    for w, ki in zip(weights, k):
        if w != 0.0:
            out = out + w * ki
    return out


def _lie_kernel(f: ca.Function, attitude: tuple[int, int], mode: str) -> ca.Function:
    """One step of the commutator-free Lie group method CF4 (Celledoni, Marthinsen & Owren 2003).

    The state is ``(q, y)``: the unit quaternion ``q = x[iq:iq+4]`` on S^3 and every other
    state ``y`` in a vector space. A right-hand side evaluation ``F_i`` at a stage state gives
    the body rate ``w_i`` (a Lie algebra element acting on ``q`` by ``qdot = -1/2 Wbar(w) q``)
    and ``ydot_i``. The flow of a frozen combination ``sum a_i F_i`` over ``h`` is exact:
    ``q <- propagate_quat(q, sum a_i w_i, h)`` and ``y <- y + h sum a_i ydot_i``.

        X2 = exp(h/2 F1) x,  X3 = exp(h/2 F2) x,  X4 = exp(h (F3 - F1/2)) X2,
        x+ = exp(h (-F1/12 + F2/6 + F3/6 + F4/4)) applied after exp(h (F1/4 + F2/6 + F3/6 - F4/12)).

    The final flows are applied in this order (measured: 4th order; the other order is 2nd
    order for the quaternion). For ``y`` this is the classical RK4; ``q`` only ever moves
    by exact rotations, so ``|q|`` is kept to round-off for any step size and horizon.
    """
    iq, iw = attitude
    nx, nu, np_ = f.numel_in(0), f.numel_in(1), f.numel_in(2)
    nodes = unique_nodes("lie")
    sym = _sym(f)
    ins, linear_u = _kernel_inputs(sym, nx, nu, np_, mode, len(nodes))
    u_at = _stage_control(mode, ins, nu, nodes, linear_u)
    x, h, p = ins[0], ins[1], ins[-1]
    qsl = slice(iq, iq + 4)

    def rhs(xs, c):
        return xs[iw:iw + 3], f.call([xs, u_at(c), p])[0]

    def flow(base, coefs, evals):
        w = sum(a * e[0] for a, e in zip(coefs, evals) if a != 0)
        d = sum(a * e[1] for a, e in zip(coefs, evals) if a != 0)
        out = base + h * d
        out[qsl] = propagate_quat(base[qsl], w, h)
        return out

    f1 = rhs(x, 0.0)
    x2 = flow(x, [0.5], [f1])
    f2 = rhs(x2, 0.5)
    x3 = flow(x, [0.5], [f2])
    f3 = rhs(x3, 0.5)
    x4 = flow(x2, [-0.5, 0.0, 1.0], [f1, f2, f3])
    f4 = rhs(x4, 1.0)
    evals = [f1, f2, f3, f4]
    mid = flow(x, [1 / 4, 1 / 6, 1 / 6, -1 / 12], evals)
    return ca.Function("lie_step", ins, [flow(mid, [-1 / 12, 1 / 6, 1 / 6, 1 / 4], evals)])


def check_lie_model(model: Model, x0: np.ndarray, p: np.ndarray):
    """Raise ValueError unless ``model`` has an attitude whose kinematics are Eq. 4.70.

    Checked numerically at ``x0`` and at two random states near it, once per model (a
    passed check is cached).
    """
    if model.attitude is None:
        raise ValueError(
            f"`method` 'lie' needs a model with an attitude (model.attitude), "
            f"and {model.name!r} has none"
        )
    iq, iw = model.attitude
    if not (iq + 4 <= iw or iw + 3 <= iq):
        raise ValueError(f"`model` attitude blocks overlap: quaternion at {iq}, rates at {iw}")
    key = ("lie-check", cache.function_key(model.f), model.attitude)
    if not cache.contains(key):
        cache.get(key, lambda: _lie_kinematics_check(model, x0, p), keepalive=model.f)


def _lie_kinematics_check(model: Model, x0: np.ndarray, p: np.ndarray) -> bool:
    iq, iw = model.attitude
    rng = np.random.default_rng(7)
    for trial in range(3):
        x = x0.copy()
        if trial:
            q = rng.standard_normal(4)
            x[iq:iq + 4] = q / np.linalg.norm(q)
            x[iw:iw + 3] = x0[iw:iw + 3] + rng.standard_normal(3)
        u = rng.standard_normal(model.nu) if trial else np.zeros(model.nu)
        qdot = model.rhs(x, u, p)[iq:iq + 4]
        expected = quat_rate(x[iq:iq + 4], x[iw:iw + 3])
        if not np.all(np.isfinite(qdot)):
            continue
        scale = np.linalg.norm(x[iq:iq + 4]) * (np.linalg.norm(x[iw:iw + 3]) + 1.0)
        if np.max(np.abs(qdot - expected)) > 1e-10 * scale:
            raise ValueError(
                f"`model` {model.name!r}: the derivative of x[{iq}:{iq + 4}] is not the "
                f"quaternion kinematics -1/2 Wbar(w) q of the rates x[{iw}:{iw + 3}] "
                "(Eq. 4.70), so the 'lie' method does not apply"
            )
    return True


def calls_rhs(model: Model, method: str) -> bool:
    """Whether the compiled step of ``method`` calls the right-hand side rather than
    inlining it: a Runge-Kutta step whose inlined rhs evaluations (stages times
    ``model.f.n_instructions()``) exceed `INLINE_MAX` (``lie`` always inlines).

    Examples
    --------
    >>> from appdyn.dynamics import hinged_bodies, rigid_body
    >>> from appdyn.dynamics.integrate.kernels import calls_rhs
    >>> calls_rhs(rigid_body([1.0, 2.0, 3.0]), "rk8")
    False
    >>> calls_rhs(hinged_bodies(1.0, [1, 1, 1], 1.0, [1, 1, 1], [0, 0, 1], [0, 0, -1]), "rk8")
    True
    """
    if method == "lie":
        return False
    return TABLEAUX[method].stages * model.f.n_instructions() > INLINE_MAX


def kernel(model: Model, method: str, mode: str, *, error: bool = False,
           compiled: bool = False) -> ca.Function:
    """The step Function of ``model`` and ``method`` (cached); ``error``: with DOP853's
    embedded error estimate (``rk8``; see `_rk_kernel`); ``compiled``: the form to generate
    C from (the rhs called, not inlined, when `calls_rhs`; else the same Function)."""
    call = compiled and calls_rhs(model, method)
    key = ("kernel", cache.function_key(model.f), model.attitude if method == "lie" else None,
           method, mode) + (("error",) if error else ()) + (("call",) if call else ())

    def build():
        if method == "lie":
            return _lie_kernel(model.f, model.attitude, mode)
        return _rk_kernel(model.f, method, mode, error, call)

    return cache.get(key, build, keepalive=model.f)
