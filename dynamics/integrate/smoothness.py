"""Whether a model's right-hand side is smooth: the CasADi expression graph scanned for
operations with kinks or jumps (``fmin``, ``fmax``, ``if_else``, ``fabs``, ``sign``,
``floor``, comparisons, ...).

An explicit Runge-Kutta method keeps its order only where the right-hand side is smooth
enough; at a kink (a saturation ``fmin(fmax(L, -L_max), L_max)``, a switch) the step that
straddles it loses order, so error estimates that assume the method's order (Richardson
extrapolation between step counts) do not hold. `nonsmooth_operations` lets ``auto`` choose
an error control that does not rely on the order (`dynamics.integrate.stepcontrol`).
"""
from __future__ import annotations

import casadi as ca

from .. import cache

__all__ = ["NONSMOOTH_OPERATIONS", "nonsmooth_operations"]

#: CasADi operation codes whose result has a kink or a jump, by name.
NONSMOOTH_OPERATIONS = {
    getattr(ca, f"OP_{name}"): name.lower()
    for name in ("FMIN", "FMAX", "IF_ELSE_ZERO", "SIGN", "FABS", "FLOOR", "CEIL", "FMOD",
                 "REMAINDER", "COPYSIGN", "LT", "LE", "EQ", "NE", "NOT", "AND", "OR",
                 "MMIN", "MMAX", "NORM1", "NORMINF")
    if hasattr(ca, f"OP_{name}")
}


def nonsmooth_operations(f: ca.Function) -> tuple[str, ...]:
    """The non-smooth operations (`NONSMOOTH_OPERATIONS`) in ``f``, sorted names; ``()``
    for a smooth ``f``. An MX Function is expanded to SX first; one that cannot be (an
    external or a callback) is scanned as it is, its calls of other Functions counted as
    smooth. Cached per Function."""
    return cache.get(("nonsmooth_operations", cache.function_key(f)), lambda: _scan(f),
                     keepalive=f)


def _scan(f: ca.Function) -> tuple[str, ...]:
    if not f.is_a("SXFunction"):
        try:
            f = f.expand()
        except RuntimeError:
            pass
    try:
        ids = {f.instruction_id(k) for k in range(f.n_instructions())}
    except RuntimeError:  # (no instruction list: e.g. an external)
        return ()
    return tuple(sorted({NONSMOOTH_OPERATIONS[i] for i in ids if i in NONSMOOTH_OPERATIONS}))
