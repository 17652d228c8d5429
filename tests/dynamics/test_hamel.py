"""The Boltzmann-Hamel builder (seed 002 Eqs. 6.1-6.17) against the hand-written rigid body
(legacy), the scene's six-degree-of-freedom hub (Kane's method) and Lagrange's equations."""
import casadi as ca
import numpy as np
import pytest

from appdyn.dynamics.attitude import dcm_from_quat, quat_rate
from appdyn.dynamics.mechanisms import hamel_model, hamel_terms, lagrange_model
from appdyn.dynamics.scene import ExternalForce, ExternalTorque, PointMassDamper, RigidHub, Scene
from tests.dynamics.scene.legacy_momentum import rigid_body as legacy_rigid_body

J = np.array([[10.0, 0.4, -0.2], [0.4, 12.0, 0.3], [-0.2, 0.3, 8.0]])
RNG = np.random.default_rng(617)


def _named(prefix, n):
    return {f"{prefix}{i + 1}": ca.SX.sym(f"{prefix}{i + 1}") for i in range(n)}


def _rigid_hamel(mass=None):
    qs, ws, Ls = _named("q", 4), _named("w", 3), _named("L", 3)
    q, w = ca.vertcat(*qs.values()), ca.vertcat(*ws.values())
    Wq = ca.jacobian(quat_rate(q, w), w)
    T = 0.5 * ca.dot(w, ca.mtimes(ca.DM(J), w))
    k = ca.vertcat(*Ls.values())
    if mass is None:
        return hamel_model(qs, ws, T, Wq, quasi_forces=k, controls=Ls)
    rs, vs, Fs = _named("r", 3), _named("v", 3), _named("F", 3)
    v = ca.vertcat(*vs.values())
    W = ca.diagcat(Wq, dcm_from_quat(q).T)                   # q' = Wq w, r' = A^T v
    return hamel_model({**qs, **rs}, {**ws, **vs}, T + 0.5 * mass * ca.dot(v, v), W,
                       quasi_forces=ca.vertcat(k, *Fs.values()), controls={**Ls, **Fs})


def _quat():
    q = RNG.normal(size=4)
    return q / np.linalg.norm(q)


def _jacobians(model):
    x, u = model.f.sx_in(0), model.f.sx_in(1)
    f = model.f(x, u, [])
    return ca.Function("J", [x, u], [ca.jacobian(f, x), ca.jacobian(f, u)])


def _close(a, b, tol=1e-12):
    a, b = np.asarray(a, float), np.asarray(b, float)
    np.testing.assert_allclose(a, b, rtol=0, atol=tol * max(1.0, np.abs(b).max()))


def test_hamel_rigid_body_is_eulers_equations_as_the_hand_written_model():
    model, ref = _rigid_hamel(), legacy_rigid_body(J)
    assert model.states == ref.states and model.controls == ref.controls
    Jm, Jr = _jacobians(model), _jacobians(ref)
    for _ in range(20):
        x, u = np.r_[_quat(), RNG.normal(size=3)], RNG.normal(size=3)
        _close(model.rhs(x, u), ref.rhs(x, u))
        for a, b in zip(Jm(x, u), Jr(x, u)):
            _close(np.array(a), np.array(b))
        _close(model.invariant("energy", x), ref.invariant("energy", x))


def test_hamel_six_dof_equals_the_scene_hub():
    m = 40.0
    model = _rigid_hamel(mass=m)
    ref = Scene(RigidHub(J, mass=m), ExternalTorque(), ExternalForce()).model()
    order = [model.states.index(s) for s in ref.states]       # q, w, r, v in the scene
    assert ref.controls == model.controls
    Jm, Jr = _jacobians(model), _jacobians(ref)
    for _ in range(20):
        x = np.r_[_quat(), RNG.normal(size=3), RNG.normal(scale=100, size=3), RNG.normal(size=3)]
        u = RNG.normal(size=6)
        xh = np.empty(13)
        xh[order] = x
        _close(model.rhs(xh, u)[order], ref.rhs(x, u))
        jx, ju = (np.array(a) for a in Jm(xh, u))
        rx, ru = (np.array(a) for a in Jr(x, u))
        _close(jx[np.ix_(order, order)], rx)
        _close(ju[order], ru)


def test_hamel_body_with_a_sliding_mass_equals_the_scene_damper():
    """``u = (w, s')``: body rates and a relative (modal-like) rate, ``T(w, s', s)`` of
    Eq. 6.18, spring potential and dashpot force, against Kane's method in the scene."""
    m, k, c = 0.5, 60.0, 0.8
    b, d = np.array([0.3, -0.2, 0.5]), np.array([0.0, 0.6, 0.8])
    qs, ws = _named("q", 4), _named("w", 3)
    s, sd = ca.SX.sym("s"), ca.SX.sym("s_dot")
    q, w = ca.vertcat(*qs.values()), ca.vertcat(*ws.values())
    rho = ca.DM(b) + s * ca.DM(d)
    vel = ca.cross(w, rho) + sd * ca.DM(d)
    T = 0.5 * ca.dot(w, ca.mtimes(ca.DM(J), w)) + 0.5 * m * ca.dot(vel, vel)
    W = ca.diagcat(ca.jacobian(quat_rate(q, w), w), ca.SX(1.0))
    model = hamel_model({**qs, "s": s}, {**ws, "s_dot": sd}, T, W, potential=0.5 * k * s ** 2,
                        quasi_forces=ca.vertcat(0, 0, 0, -c * sd))
    ref = Scene(RigidHub(J), PointMassDamper(m, k, c, position=b, direction=d)).model()
    order = [model.states.index(n) for n in ref.states]
    for _ in range(20):
        x = np.r_[_quat(), RNG.normal(size=3), RNG.normal(scale=0.1), RNG.normal()]
        xh = np.empty(9)
        xh[order] = x
        _close(model.rhs(xh)[order], ref.rhs(x))
        _close(model.invariant("energy", xh), ref.invariant("energy", x))


def test_hamel_polar_particle_equals_lagrange():
    """Quasi-velocities ``(r', r phi')`` vs. Lagrange in ``(r', phi')``, with a force."""
    r, phi, vr, vt = (ca.SX.sym(n) for n in ("r", "phi", "v_r", "v_t"))
    rd, phid = ca.SX.sym("r_dot"), ca.SX.sym("phi_dot")
    pos = r * ca.vertcat(ca.cos(phi), ca.sin(phi))
    F = ca.vertcat(0.3, -9.8)
    ham = hamel_model({"r": r, "phi": phi}, {"v_r": vr, "v_t": vt},
                      0.5 * 2.0 * (vr ** 2 + vt ** 2), ca.diag(ca.vertcat(1, 1 / r)),
                      forces=[(F, pos)])
    lag = lagrange_model({"r": r, "phi": phi}, {"r_dot": rd, "phi_dot": phid},
                         0.5 * 2.0 * (rd ** 2 + r ** 2 * phid ** 2), forces=[(F, pos)])
    for _ in range(10):
        R, P, Rd, Pd = RNG.uniform(0.5, 2.0), *RNG.normal(size=3)
        a, b = ham.rhs([R, P, Rd, R * Pd]), lag.rhs([R, P, Rd, Pd])
        _close(a[:2], b[:2])
        _close(a[2], b[2])
        _close(a[3], R * b[3] + Rd * Pd)                       # (r phi')' = r phi'' + r' phi'


def test_bad_arguments_are_named():
    q, u = ca.SX.sym("q", 2), ca.SX.sym("u", 2)
    T = 0.5 * ca.dot(u, u)
    with pytest.raises(ValueError, match="`W`"):
        hamel_terms(T, q, u, ca.SX.eye(3))
    with pytest.raises(ValueError, match="`W`"):
        hamel_terms(T, q, u, ca.diag(u))
    with pytest.raises(ValueError, match="`quasi_forces`"):
        hamel_terms(T, q, u, ca.SX.eye(2), quasi_forces=ca.SX.zeros(3))
    with pytest.raises(TypeError, match="`T`"):
        hamel_terms(1.0, q, u, ca.SX.eye(2))
