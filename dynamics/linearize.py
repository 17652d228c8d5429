"""Linearization of a `Model` about an equilibrium or a steady spin, with exact Jacobians.

``linearize(model, x)`` returns a ``control.StateSpace``; ``linearization(model, x)`` returns
the richer `Linearization` result (matrices, names, residual, equilibrium flag) it is made
from. Jacobians are CasADi's algorithmic derivatives (``casadi.jacobian``), exact to round-off.

Attitude models (``model.attitude = (iq, iw)``)
-----------------------------------------------
The four quaternion components are replaced by three small **body-frame** error angles
``dth = (dth1, dth2, dth3)`` [rad] about the axes of a reference frame ``q_ref``:

    q = quat_mul(dq(dth), q_ref),    A(q) = A(dq) A(q_ref),    A(dq) = E - skew(dth) + O(dth^2)

with ``dq(dth) = [dth/2, sqrt(1 - |dth|^2/4)]`` (so ``dth = 2 dq_v`` exactly). The unit-norm
constraint leaves no fourth, spurious zero mode. Two frames are offered:

* ``frame="spinning"`` (default): the reference frame turns at the constant body rate
  ``w_ref = x[iw:iw+3]`` of the operating point, ``q_ref(t)`` solving
  ``q_ref' = -1/2 Wbar(w_ref) q_ref`` from ``q_ref(0) = x[iq:iq+4]``; this is the nominal
  frame of Rheinfurth & Wilson, NASA RP-1262, Sec. 4.6 Method III. A steady spin
  ``w = w_ref`` with the other states at rest is then an equilibrium of the error dynamics
  (a *relative* equilibrium of the model), and ``dth' = dw - w_ref x dth`` to first order.
  With ``w_ref = 0`` this is the ordinary fixed-reference linearization.
* ``frame="rates"``: the attitude is dropped; the states are the body rates and the other
  states. Allowed only when their equations do not depend on the attitude (torque-free
  bodies, internal dampers): the Euler-equation perturbations of
  Rheinfurth & Wilson, Sec. 4.5 C.

The error dynamics in the spinning frame are time-invariant only if the model is symmetric
about the spin: the residual and the Jacobians are therefore also evaluated at two other spin
phases of the reference (spin angles ``2`` and ``4`` rad) and must agree.
"""
from __future__ import annotations

import warnings

from dataclasses import dataclass, field, replace
from typing import Literal, Mapping

import casadi as ca
import numpy as np

from . import cache
from .attitude import propagate_quat, quat_conj, quat_mul, quat_rate
from . import validate
from .model import Model, check_model

__all__ = ["Linearization", "linearization", "linearize", "error_dynamics", "ANGLE_STATES",
           "EQ_RTOL"]

Frame = Literal["spinning", "rates"]
FRAMES = ("spinning", "rates")
ANGLE_STATES = ("dth1", "dth2", "dth3")
EQ_RTOL = 1e-9
"""Default relative tolerance of the equilibrium test, see `linearization`."""
_PHASES = (2.0, 4.0)  # extra spin angles [rad] at which a spinning reference is re-checked


# --------------------------------------------------------------------------- result
@dataclass(frozen=True)
class Linearization:
    """A linear model ``dx' = A dx + B du``, ``y = C dx + D du`` about an operating point.

    Attributes
    ----------
    A : ndarray, shape (n, n)
    B : ndarray, shape (n, m)
    C : ndarray, shape (n, n)
        Identity: the outputs are the states
    D : ndarray, shape (n, m)
        Zero
    states, inputs : tuple of str
        Names of the (reduced) state and input components; attitude models use
        `ANGLE_STATES` for the error angles.
    x0 : ndarray, shape (nx,)
        The model state it was taken at (quaternion normalized)
    u0 : ndarray, shape (nu,)
    p : ndarray, shape (np,)
    frame : {'spinning', 'rates', 'none'}
        ``'none'`` for models without attitude
    w_ref : ndarray, shape (3,) or None
        Body rates [rad/s] of the reference frame (``frame='spinning'``); ``reference_rate``
        is its deprecated name.
    residual : ndarray, shape (n,)
        The derivative of the (reduced) state at the operating point; zero at an equilibrium.
        Its units are those of ``states`` per second.
    tolerance : float
        The bound the residual was tested against (max norm).
    is_equilibrium : bool
    units : mapping of str to str
        Unit of each state (``'rad'`` for the error angles).
    model_name : str
    notes : tuple of str
        What was reduced and why (filled by `quotient` and `restrict`).
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    states: tuple
    inputs: tuple
    x0: np.ndarray
    u0: np.ndarray
    p: np.ndarray
    frame: str
    w_ref: np.ndarray | None
    residual: np.ndarray
    tolerance: float
    is_equilibrium: bool
    units: Mapping[str, str] = field(default_factory=dict)
    model_name: str = "model"
    notes: tuple = ()

    @property
    def reference_rate(self) -> np.ndarray | None:
        """Deprecated name of `w_ref` (a rate vector is ``w_*``; ``rate`` is a scalar)."""
        warnings.warn("`reference_rate` is deprecated; use `w_ref`", DeprecationWarning,
                      stacklevel=2)
        return self.w_ref

    @property
    def outputs(self) -> tuple:
        """Output names (the states)."""
        return self.states

    @property
    def n(self) -> int:
        """Number of (reduced) states."""
        return len(self.states)

    @property
    def ss(self):
        """The linear model as a ``control.StateSpace`` with state, input and output names."""
        import control

        return control.ss(self.A, self.B, self.C, self.D, states=list(self.states),
                          inputs=list(self.inputs), outputs=list(self.outputs),
                          name=self.model_name)

    def eigenvalues(self) -> np.ndarray:
        """Eigenvalues of ``A`` [1/s], complex, sorted by real part then imaginary part."""
        ev = np.linalg.eigvals(self.A) if self.n else np.zeros(0, complex)
        return np.asarray(sorted(ev.astype(complex), key=lambda z: (z.real, z.imag)))

    def index(self, state: str) -> int:
        """Position of the named state; ``ValueError`` naming ``state`` if unknown."""
        if state not in self.states:
            raise ValueError(f"`state` must be one of {self.states}, got {state!r}")
        return self.states.index(state)

    def _scale(self) -> float:
        return max(float(np.max(np.abs(self.A))) if self.A.size else 0.0, 1e-300)

    def quotient(self, direction, *, eliminate: str | None = None, rtol: float = 1e-9,
                 reason: str = "") -> "Linearization":
        """Factor out a neutral direction ``n`` with ``A n = 0`` (a symmetry, e.g. spin phase).

        The induced map on ``R^n / span(n)`` is written in the coordinates of the remaining
        states (state ``k = eliminate`` is removed): ``A' = A[r, r] - n[r] A[k, r] / n[k]``,
        ``B' = B[r] - n[r] B[k] / n[k]``. Its eigenvalues are those of ``A`` with one zero
        removed. For ``n`` a unit coordinate vector this just deletes row and column ``k``.

        Parameters
        ----------
        direction : array_like, shape (n,) or str
            The null vector, or the name of a state whose unit vector it is.
        eliminate : str, optional
            Which state to remove (default: the largest component of ``direction``).
        rtol : float
            ``|A n| <= rtol max|A| |n|`` is required.
        reason : str
            Recorded in ``notes``.

        Raises
        ------
        ValueError
            If ``direction`` is not a null vector of ``A`` or ``eliminate`` does not fit it.
        """
        nvec = self._named_vector(direction, "direction")
        k = self._pick(nvec, eliminate)
        res = self.A @ nvec
        bound = rtol * self._scale() * np.max(np.abs(nvec))
        if np.max(np.abs(res)) > bound:
            raise ValueError(f"`direction` is not a null vector of A: max |A n| = "
                             f"{np.max(np.abs(res)):.3e} > {bound:.3e}")
        r = [i for i in range(self.n) if i != k]
        t = nvec[r] / nvec[k]
        A = self.A[np.ix_(r, r)] - np.outer(t, self.A[k, r])
        B = self.B[r] - np.outer(t, self.B[k])
        resid = self.residual[r] - t * self.residual[k]
        note = f"quotient by the neutral direction along '{self.states[k]}'"
        return self._reduced(A, B, r, resid, note + (f" ({reason})" if reason else ""))

    def restrict(self, gradient, *, eliminate: str | None = None, rtol: float = 1e-9,
                 reason: str = "") -> "Linearization":
        """Restrict to a level set of a first integral with gradient ``c`` (``c^T A = 0``).

        ``ker c^T`` is invariant under ``A``; it is parametrized by the remaining states, state
        ``k = eliminate`` being ``-c[r] . x[r] / c[k]``: ``A' = A[r, r] - A[r, k] c[r] / c[k]``.
        If a family of equilibria crosses the level sets (``c . n != 0`` for its tangent
        ``n``), the eigenvalue 0 of that family is removed and the others are kept. ``B'`` is
        ``B[r]``: inputs that change the integral are not represented in the reduced model.

        Parameters
        ----------
        gradient : array_like, shape (n,) or str
            ``c``, or the name of a state whose unit vector it is (a state with a zero row).
        eliminate : str, optional
            Which state to remove (default: the largest component of ``c``).
        rtol : float
            ``|c^T A| <= rtol max|A| |c|`` is required.
        reason : str
            Recorded in ``notes``.

        Raises
        ------
        ValueError
            If ``c^T A != 0`` or ``eliminate`` does not fit it.
        """
        c = self._named_vector(gradient, "gradient")
        k = self._pick(c, eliminate)
        res = c @ self.A
        bound = rtol * self._scale() * np.max(np.abs(c))
        if np.max(np.abs(res)) > bound:
            raise ValueError(f"`gradient` is not a left null vector of A (not a first integral "
                             f"here): max |c^T A| = {np.max(np.abs(res)):.3e} > {bound:.3e}")
        r = [i for i in range(self.n) if i != k]
        A = self.A[np.ix_(r, r)] - np.outer(self.A[r, k], c[r] / c[k])
        B = self.B[r]
        resid = self.residual[r]
        note = f"restricted to a level set of a first integral, '{self.states[k]}' eliminated"
        return self._reduced(A, B, r, resid, note + (f" ({reason})" if reason else ""))

    def _named_vector(self, v, name) -> np.ndarray:
        if isinstance(v, str):
            out = np.zeros(self.n)
            out[self.index(v)] = 1.0
            return out
        v = validate.finite_array(v, name).reshape(-1)
        if v.size != self.n or not np.any(v):
            raise ValueError(f"`{name}` must be a finite non-zero vector of {self.n} values "
                             f"or a state name, got {v}")
        return v

    def _pick(self, v, eliminate) -> int:
        if eliminate is None:
            return int(np.argmax(np.abs(v)))
        k = self.index(eliminate)
        if abs(v[k]) <= 1e-12 * np.max(np.abs(v)):
            raise ValueError(f"`eliminate` {eliminate!r} has no component in the vector; "
                             f"choose one of {[s for s, c in zip(self.states, v) if c]}")
        return k

    def _reduced(self, A, B, r, resid, note) -> "Linearization":
        states = tuple(self.states[i] for i in r)
        n = len(states)
        return replace(self, A=A, B=B, C=np.eye(n), D=np.zeros((n, len(self.inputs))),
                       states=states, residual=resid,
                       units={s: self.units.get(s, "") for s in states},
                       notes=self.notes + (note,))

    def __str__(self) -> str:
        head = (f"Linearization of '{self.model_name}' (frame: {self.frame}, "
                f"{'equilibrium' if self.is_equilibrium else 'NOT an equilibrium'}, "
                f"max |residual| {np.max(np.abs(self.residual), initial=0.0):.2e})")
        lines = [head, "  states: " + ", ".join(self.states),
                 "  inputs: " + (", ".join(self.inputs) or "(none)")]
        lines += [f"  note: {n}" for n in self.notes]
        with np.printoptions(precision=6, suppress=False, linewidth=110):
            lines.append("  A =\n" + "\n".join("    " + row for row in str(self.A).splitlines()))
        return "\n".join(lines)


# ------------------------------------------------------------------------ building
def _check_point(model: Model, x, u, p):
    # messages name the state names; the quaternion check is validate's (as simulate's)
    try:
        x = np.array(x, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise ValueError(f"`x` must be {model.nx} numbers {model.states}, got {x!r}") from None
    if x.size != model.nx or not np.all(np.isfinite(x)):
        raise ValueError(f"`x` must be {model.nx} finite numbers {model.states}, got {x}")
    if u is None:
        u = np.zeros(model.nu)
    else:
        u = np.array(u, dtype=float).reshape(-1)
        if u.size != model.nu or not np.all(np.isfinite(u)):
            raise ValueError(f"`u` must be {model.nu} finite numbers {model.controls}, got {u}")
    p = model.resolve_p(p)
    if model.attitude is not None:
        iq = model.attitude[0]
        x[iq:iq + 4] = validate.unit_quaternion(
            x[iq:iq + 4], f"x[{iq}:{iq + 4}] (the attitude quaternion {model.states[iq:iq + 4]})")
    return x, u, p


def _reduced_names(model: Model) -> tuple:
    iq = model.attitude[0]
    return model.states[:iq] + ANGLE_STATES + model.states[iq + 4:]


def _error_expression(model: Model, xr, u, p, q_ref, w_ref):
    """``xrdot`` of the error state ``xr`` (symbols or numbers) about ``q_ref``, ``w_ref``."""
    iq = model.attitude[0]
    dth = xr[iq:iq + 3]
    dq = ca.vertcat(dth / 2, ca.sqrt(1 - ca.sumsqr(dth) / 4))
    q = quat_mul(dq, q_ref)
    x = ca.vertcat(xr[:iq], q, xr[iq + 3:])
    xdot = model.f(x=x, u=u, p=p)["xdot"]
    qdot = xdot[iq:iq + 4]
    qref_dot = quat_rate(q_ref, w_ref)
    dq_dot = quat_mul(qdot, quat_conj(q_ref)) + quat_mul(q, quat_conj(qref_dot))
    return ca.vertcat(xdot[:iq], 2 * dq_dot[0:3], xdot[iq + 4:])


def error_dynamics(model: Model, q_ref, w_ref) -> ca.Function:
    """Attitude-error dynamics of an attitude model about a spinning reference frame.

    Parameters
    ----------
    model : Model
        With ``model.attitude = (iq, iw)``.
    q_ref : array_like, shape (4,)
        Unit quaternion of the reference frame at ``t = 0``.
    w_ref : array_like, shape (3,) [rad/s]
        Constant body rate of the reference frame (zero: a fixed reference).

    Returns
    -------
    casadi.Function
        ``(xr, u, p) -> (xrdot)``: ``xr`` is the model state with ``x[iq:iq+4]`` replaced by
        the error angles ``dth`` [rad] (``q = quat_mul(dq(dth), q_ref)``,
        ``dq = [dth/2, sqrt(1 - |dth|^2/4)]``), ``xrdot`` its exact time derivative at
        ``t = 0``: ``dth' = 2 vec(q' (x) q_ref* + q (x) q_ref'*)``.
    """
    model = check_model(model)
    if model.attitude is None:
        raise ValueError(f"`model` {model.name!r} has no attitude (model.attitude is None)")
    with cache.construction_lock():  # (casadi construction: one thread at a time)
        xr = ca.SX.sym("xr", model.nx - 1)
        u = ca.SX.sym("u", model.nu)
        p = ca.SX.sym("p", model.np)
        xrdot = _error_expression(model, xr, u, p, ca.DM(np.asarray(q_ref, dtype=float)),
                                  ca.DM(np.asarray(w_ref, dtype=float)))
        return ca.Function(f"{model.name}_error", [xr, u, p], [xrdot], ["xr", "u", "p"],
                           ["xrdot"])


def _jacobian_function(model: Model) -> ca.Function:
    """``(xr, u, p, q_ref, w_ref) -> (f, A, B)``, built once per model right-hand side.

    Without attitude ``xr`` is the state and ``q_ref``, ``w_ref`` are ignored. The cache
    entry keeps ``model.f`` alive, so its address cannot be reused while the entry exists.
    """
    key = ("linearization", cache.function_key(model.f), model.attitude)
    return cache.get(key, lambda: _build_jacobian_function(model), keepalive=model.f)


def _build_jacobian_function(model: Model) -> ca.Function:
    n = model.nx if model.attitude is None else model.nx - 1
    xr, u, p = ca.SX.sym("xr", n), ca.SX.sym("u", model.nu), ca.SX.sym("p", model.np)
    q_ref, w_ref = ca.SX.sym("q_ref", 4), ca.SX.sym("w_ref", 3)
    if model.attitude is None:
        f = model.f(x=xr, u=u, p=p)["xdot"]
    else:
        f = _error_expression(model, xr, u, p, q_ref, w_ref)
    fun = ca.Function("linearization", [xr, u, p, q_ref, w_ref],
                      [f, ca.jacobian(f, xr), ca.jacobian(f, u)],
                      ["xr", "u", "p", "q_ref", "w_ref"], ["f", "A", "B"])
    return fun


def _evaluate(jac: ca.Function, xr, u, p, q_ref=(0.0, 0.0, 0.0, 1.0), w_ref=(0.0, 0.0, 0.0)):
    out = jac(xr=xr, u=u, p=p, q_ref=q_ref, w_ref=w_ref)
    return (np.asarray(out["f"], dtype=float).reshape(-1), np.asarray(out["A"], dtype=float),
            np.asarray(out["B"], dtype=float).reshape(len(xr), len(u)))


def _residual_text(names, units, residual, limit=8) -> str:
    order = np.argsort(-np.abs(residual))
    shown = [f"d({names[i]})/dt = {residual[i]:+.6e} {units.get(names[i]) or '1'}/s"
             for i in order[:limit] if residual[i] != 0]
    more = int(np.count_nonzero(residual)) - len(shown)
    return "; ".join(shown) + (f"; ... ({more} more)" if more > 0 else "")


def linearization(model: Model, x, u=None, p=None, *, frame: Frame = "spinning",
                  allow_non_equilibrium: bool = False, eq_rtol: float = EQ_RTOL
                  ) -> Linearization:
    """Linearize ``model`` about the state ``x`` (and control ``u``), exactly.

    Parameters
    ----------
    model : Model
    x : array_like, shape (nx,)
        Operating point in the model's units. For attitude models its quaternion (unit norm
        to 1e-6, normalized here) is the reference attitude and its body rate the rate of
        the reference frame (``frame='spinning'``).
    u : array_like, shape (nu,), optional
        Control at the operating point (zero).
    p : array_like, shape (np,), optional
        Parameters (the model's defaults).
    frame : {'spinning', 'rates'}
        Attitude models only (see the module notes): error angles relative to the frame
        spinning with the operating point's body rate, or body rates only.
    allow_non_equilibrium : bool
        Return the linearization of a point that is not an (relative) equilibrium instead of
        raising; ``is_equilibrium`` is then ``False`` and ``residual`` holds the drift.
    eq_rtol : float
        ``x`` is an equilibrium when ``max|residual| <= eq_rtol (max|A| max(1, max|xr|) +
        max|B| max|u|)``, ``xr`` the reduced state: round-off in the terms that cancel.

    Returns
    -------
    Linearization
        ``.ss`` is the ``control.StateSpace``.

    Raises
    ------
    TypeError
        If ``model`` is not a `Model`.
    ValueError
        For a wrongly shaped or non-finite ``x``/``u``/``p``, a non-unit quaternion, an
        unknown ``frame`` (or ``'rates'`` on a model without attitude, or when the rate
        equations depend on the attitude), and — unless ``allow_non_equilibrium`` — when
        ``x`` is not an equilibrium (the message lists the residual by state) or when a
        spinning reference makes the linearization depend on the spin phase.
    """
    model = check_model(model)
    if frame not in FRAMES:
        raise ValueError(f"`frame` must be one of {FRAMES}, got {frame!r}")
    x, u, p = _check_point(model, x, u, p)
    if not (np.isfinite(eq_rtol) and eq_rtol > 0):
        raise ValueError(f"`eq_rtol` must be positive, got {eq_rtol}")
    units = dict(model.units)

    if model.attitude is None:
        if frame == "rates":
            raise ValueError(f"`frame`='rates' needs an attitude model; {model.name!r} has "
                             "no attitude (use the default)")
        names = model.states
        xr = x
        f0, A, B = _evaluate(_jacobian_function(model), xr, u, p)
        keep, w_ref, used_frame = list(range(model.nx)), None, "none"
        checks = []
    else:
        iq, iw = model.attitude
        names = _reduced_names(model)
        units.update({s: "rad" for s in ANGLE_STATES})
        q_ref = x[iq:iq + 4]
        w_ref = x[iw:iw + 3].copy()
        xr = np.concatenate([x[:iq], np.zeros(3), x[iq + 4:]])
        jac = _jacobian_function(model)
        f0, A, B = _evaluate(jac, xr, u, p, q_ref, w_ref)
        checks = []
        if np.any(w_ref):
            for phase in _PHASES:
                qk = np.asarray(propagate_quat(q_ref, w_ref, phase / np.linalg.norm(w_ref)),
                                dtype=float).reshape(-1)
                checks.append((phase, *_evaluate(jac, xr, u, p, qk, w_ref)))
        angle = list(range(iq, iq + 3))  # the angle slots replace the quaternion
        keep = list(range(model.nx - 1))
        used_frame = frame
        if frame == "rates":
            keep = [i for i in keep if i not in angle]
            coupling = A[np.ix_(keep, angle)]
            bound = eq_rtol * max(np.max(np.abs(A)), 1e-300)
            if np.max(np.abs(coupling), initial=0.0) > bound:
                i, j = np.unravel_index(np.argmax(np.abs(coupling)), coupling.shape)
                raise ValueError(
                    "`frame`='rates' drops the attitude, but the rate equations of "
                    f"{model.name!r} depend on it: d({names[keep[i]]}')/d({names[angle[j]]}) "
                    f"= {coupling[i, j]:.6e}; use frame='spinning'")

    tol = eq_rtol * (np.max(np.abs(A), initial=0.0) * max(1.0, np.max(np.abs(xr), initial=0.0))
                     + np.max(np.abs(B), initial=0.0) * np.max(np.abs(u), initial=0.0)) + 1e-300
    sub = np.ix_(keep, keep)
    residual = f0[keep]
    problems = []
    if np.max(np.abs(residual), initial=0.0) > tol:
        problems.append(
            f"`x` is not an equilibrium of {model.name!r} (frame {used_frame!r}): max |residual| "
            f"{np.max(np.abs(residual)):.3e} > tolerance {tol:.3e}; residual: "
            + _residual_text([names[i] for i in keep], units, residual))
    for phase, fk, Ak, Bk in checks if not problems else ():
        dres = np.max(np.abs(fk[keep]), initial=0.0)
        dA = np.max(np.abs(Ak[sub] - A[sub]), initial=0.0)
        if dres > tol or dA > tol:
            problems.append(
                f"the motion is not a relative equilibrium: at spin angle {phase:g} rad of the "
                f"reference frame (body rate {w_ref.tolist()} rad/s) max |residual| is "
                f"{dres:.3e} and A changes by {dA:.3e} (tolerance {tol:.3e}): the dynamics are "
                "not symmetric about the spin; residual there: "
                + _residual_text([names[i] for i in keep], units, fk[keep]))
            break
    if problems and not allow_non_equilibrium:
        raise ValueError(problems[0] + ". Pass allow_non_equilibrium=True to linearize anyway.")
    n = len(keep)
    states = tuple(names[i] for i in keep)
    return Linearization(
        A=A[sub], B=B[keep], C=np.eye(n), D=np.zeros((n, model.nu)), states=states,
        inputs=model.controls, x0=x, u0=u, p=p, frame=used_frame,
        w_ref=w_ref if used_frame == "spinning" else None, residual=residual,
        tolerance=float(tol), is_equilibrium=not problems,
        units={s: units.get(s, "") for s in states}, model_name=model.name,
        notes=tuple(problems))


def linearize(model: Model, x, u=None, p=None, *, frame: Frame = "spinning",
              allow_non_equilibrium: bool = False, eq_rtol: float = EQ_RTOL):
    """Linearize ``model`` about ``x`` and return a named ``control.StateSpace``.

    Exact CasADi Jacobians; attitude models use three body-frame error angles (see the
    module notes and `linearization`, which takes the same arguments and returns the
    residual and equilibrium flag too).

    Parameters
    ----------
    model : Model
    x : array_like, shape (nx,)
    u : array_like, shape (nu,), optional
    p : array_like, shape (np,), optional
    frame : {'spinning', 'rates'}
    allow_non_equilibrium : bool
    eq_rtol : float

    Returns
    -------
    control.StateSpace
        States, inputs and outputs named (outputs = states); ``A`` [1/s], ``B`` in state
        units per input unit per second.

    Examples
    --------
    >>> from appdyn.dynamics import rigid_body
    >>> sys = linearize(rigid_body([1.0, 2.0, 3.0]), [0, 0, 0, 1, 10.0, 0, 0])
    >>> sys.state_labels
    ['dth1', 'dth2', 'dth3', 'w1', 'w2', 'w3']
    """
    return linearization(model, x, u, p, frame=frame, allow_non_equilibrium=allow_non_equilibrium,
                         eq_rtol=eq_rtol).ss
