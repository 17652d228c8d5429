"""The multiplier machinery (dynamics.constrained) against closed forms and explicit formulas.

Truths: a particle on a circle (tension m v^2 / r), the simple pendulum in Cartesian
coordinates (lambda = m g cos(theta)/l + m thetadot^2, accelerations from theta'' =
-g/l sin(theta)), Eq. 5.66 written with explicit inverses and the KKT system solved densely,
and the Baumgarte residual law e'' + 2 e'/tau + e/tau^2 = 0 in closed form.
"""
import casadi as ca
import numpy as np
import pytest

from appdyn.dynamics import Model, simulate
from appdyn.dynamics.constrained import (DEFAULT_TIME_CONSTANT, baumgarte, constrained_accelerations,
                                  constraint_terms, project_positions, project_velocities,
                                  reaction_forces, residual_invariant)

G = 9.81


def _random_system(rng, n=7, m=3):
    A = rng.normal(size=(n, n))
    return A @ A.T + n * np.eye(n), rng.normal(size=n), rng.normal(size=(m, n)), rng.normal(size=m)


# ------------------------------------------------------------------ closed forms
@pytest.mark.parametrize("angle", [0.0, 0.7, 2.5, -1.9])
def test_particle_on_circle_tension_is_m_v2_over_r(angle):
    m, r, speed = 3.0, 0.8, 2.5
    e = np.array([np.cos(angle), np.sin(angle)])
    x, v = r * e, speed * np.array([-e[1], e[0]])
    # phi = (x.x - r^2)/2: B = x^T, c = Bdot v = v.v
    res = constrained_accelerations(m * np.eye(2), np.zeros(2), x[None, :], [v @ v])
    assert res.lam[0] == pytest.approx(m * speed**2 / r**2, rel=1e-14)
    np.testing.assert_allclose(res.reaction, -m * speed**2 / r * e, rtol=0, atol=1e-13)
    np.testing.assert_allclose(res.vdot, -speed**2 / r * e, rtol=0, atol=1e-13)


@pytest.mark.parametrize("theta, thetadot", [(0.0, 0.0), (0.4, 1.3), (2.0, -0.7), (-3.0, 2.2)])
def test_cartesian_pendulum_multiplier_and_accelerations(theta, thetadot):
    m, l = 1.7, 0.9
    x = l * np.array([np.sin(theta), -np.cos(theta)])  # theta from the downward vertical
    v = l * thetadot * np.array([np.cos(theta), np.sin(theta)])
    res = constrained_accelerations(m * np.eye(2), [0.0, -m * G], x, v @ v)
    assert res.lam[0] == pytest.approx(m * G * np.cos(theta) / l + m * thetadot**2, abs=1e-13)
    tension = m * G * np.cos(theta) + m * l * thetadot**2  # along the rod, toward the pivot
    np.testing.assert_allclose(res.reaction, -tension * x / l, atol=1e-13)
    thetaddot = -G / l * np.sin(theta)
    acc = l * np.array([thetaddot * np.cos(theta) - thetadot**2 * np.sin(theta),
                        thetaddot * np.sin(theta) + thetadot**2 * np.cos(theta)])
    np.testing.assert_allclose(res.vdot, acc, atol=1e-13)


def test_solution_matches_eq_5_66_with_inverses_and_the_kkt_system():
    rng = np.random.default_rng(0)
    for _ in range(5):
        M, Q, B, c = _random_system(rng)
        Mi = np.linalg.inv(M)
        lam = np.linalg.inv(B @ Mi @ B.T) @ (B @ Mi @ Q + c)  # Eq. 5.66 as printed
        vdot = Mi @ (Q - B.T @ lam)
        n, m = B.shape[1], B.shape[0]
        kkt = np.block([[M, B.T], [B, np.zeros((m, m))]])
        sol = np.linalg.solve(kkt, np.r_[Q, -c])
        res = constrained_accelerations(M, Q, B, c)
        np.testing.assert_allclose(res.lam, lam, rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(res.lam, sol[n:], rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(res.vdot, vdot, rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(res.vdot, sol[:n], rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(res.reaction, -B.T @ lam, rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(B @ res.vdot + c, 0, atol=1e-12)
        np.testing.assert_allclose(reaction_forces(B, res.lam), res.reaction, atol=0)


@pytest.mark.parametrize("kind", [ca.SX, ca.MX])
@pytest.mark.parametrize("numeric_mass", [False, True])
def test_symbolic_inputs_give_the_numeric_solution(kind, numeric_mass):
    M, Q, B, c = _random_system(np.random.default_rng(1))
    ref = constrained_accelerations(M, Q, B, c)
    Ms = M if numeric_mass else kind.sym("M", *M.shape)
    Qs, Bs, cs = kind.sym("Q", Q.size), kind.sym("B", *B.shape), kind.sym("c", c.size)
    out = constrained_accelerations(Ms, Qs, Bs, cs)
    ins = ([] if numeric_mass else [Ms]) + [Qs, Bs, cs]
    f = ca.Function("f", ins, list(out))
    got = f(*(([] if numeric_mass else [M]) + [Q, B, c]))
    for a, b in zip(got, ref):
        np.testing.assert_allclose(np.asarray(a).ravel(), b, rtol=1e-12, atol=1e-13)


def test_dm_in_dm_out_and_no_constraints():
    M, Q, B, c = _random_system(np.random.default_rng(2))
    res = constrained_accelerations(ca.DM(M), Q, B, c)
    assert isinstance(res.vdot, ca.DM) and res.vdot.shape == (7, 1)
    free = constrained_accelerations(M, Q, np.zeros((0, 7)), np.zeros(0))
    np.testing.assert_allclose(free.vdot, np.linalg.solve(M, Q), rtol=1e-12)
    assert free.lam.shape == (0,)


# --------------------------------------------------------------------- bad input
@pytest.mark.parametrize("M, match", [
    ([[1.0, 0.0], [0.0, 0.0]], "positive definite"),        # singular (a zero mass)
    ([[1.0, 0.0], [0.0, -2.0]], "positive definite"),       # a negative mass
    ([[1.0, 0.5], [0.0, 1.0]], "symmetric"),
    ([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], "square"),
    ([[1.0, np.nan], [np.nan, 1.0]], "finite"),
])
def test_bad_mass_matrix_is_refused(M, match):
    with pytest.raises(ValueError, match=r"`M`.*" + match):
        constrained_accelerations(M, [0.0, 0.0], [[1.0, 0.0]], [0.0])


def test_redundant_and_inconsistent_constraints_are_refused():
    M, Q = np.eye(3), np.zeros(3)
    with pytest.raises(ValueError, match=r"redundant.*rank 1 < 2 rows \(singular values "
                                         r"3.16, [0-9.e-]+\)") as info:
        constrained_accelerations(M, Q, [[1.0, 1.0, 0.0], [2.0, 2.0, 0.0]], [1.0, 2.0])
    assert "np.float64" not in str(info.value)  # (the values as numbers: sqrt(10), ~0)
    with pytest.raises(ValueError, match="inconsistent.*rank 1 < 2"):
        constrained_accelerations(M, Q, [[1.0, 1.0, 0.0], [2.0, 2.0, 0.0]], [1.0, 0.0])
    with pytest.raises(ValueError, match="redundant"):  # more constraints than velocities
        constrained_accelerations(np.eye(2), [0.0, 0.0], np.ones((3, 2)) + np.eye(3, 2), [0.0] * 3)
    with pytest.raises(ValueError, match="redundant"):  # numeric B with symbolic c
        constrained_accelerations(M, ca.SX.sym("Q", 3), [[1.0, 0, 0], [1.0, 0, 0]], ca.SX.sym("c", 2))


@pytest.mark.parametrize("args, name", [
    ((np.eye(2), [0.0, 0.0, 0.0], [[1.0, 0.0]], [0.0]), "`Q`"),
    ((np.eye(2), [0.0, 0.0], [[1.0, 0.0, 0.0]], [0.0]), "`B`"),
    ((np.eye(2), [0.0, 0.0], [[1.0, 0.0]], [0.0, 1.0]), "`c`"),
])
def test_shapes_are_checked_by_name(args, name):
    with pytest.raises(ValueError, match=name):
        constrained_accelerations(*args)


def test_mixing_sx_and_mx_or_bad_types_is_a_type_error():
    with pytest.raises(TypeError, match="SX and MX"):
        constrained_accelerations(np.eye(1), ca.SX.sym("Q"), [[1.0]], ca.MX.sym("c"))
    with pytest.raises(TypeError, match="`M`"):
        constrained_accelerations("mass", [0.0], [[1.0]], [0.0])
    with pytest.raises(ValueError, match="`Q`"):  # numeric parts of a symbolic call: checked
        constrained_accelerations(ca.SX.sym("M", 1, 1), [np.nan], [[1.0]], ca.SX.sym("c"))


# ------------------------------------------------------------- terms and drift
def test_constraint_terms_of_the_pendulum():
    q, v, t = ca.SX.sym("q", 2), ca.SX.sym("v", 2), ca.SX.sym("t")
    l0 = 1.2
    # a rod whose length grows as l0 + 0.1 t (rheonomic): b = -l l', c = vdot-free part
    terms = constraint_terms(q, v, v, position=(ca.sumsqr(q) - (l0 + 0.1 * t) ** 2) / 2, t=t)
    f = ca.Function("f", [q, v, t], [terms.B, terms.b, terms.c, terms.residual])
    qv, vv, tv = np.array([0.3, -1.0]), np.array([0.5, 0.2]), 2.0
    B, b, c, r = (np.asarray(a) for a in f(qv, vv, tv))
    b, c, r = (a.item() for a in (b, c, r))
    lt = l0 + 0.1 * tv
    np.testing.assert_allclose(B, [qv], atol=1e-15)
    assert b == pytest.approx(-lt * 0.1, rel=1e-14)
    assert c == pytest.approx(vv @ vv - 0.1**2, rel=1e-14)
    assert r == pytest.approx(qv @ vv - lt * 0.1, rel=1e-14)
    with pytest.raises(TypeError, match="`q`"):
        constraint_terms(np.zeros(2), v, v, position=q[0])
    with pytest.raises(TypeError, match="position"):
        constraint_terms(q, v, v)


def test_baumgarte_form_and_gains():
    c, r, phi, tau = np.array([1.0, 2.0, 3.0]), np.array([0.5, -1.0, 2.0]), np.array([4.0, 1.0]), 0.5
    out = baumgarte(c, r, phi, time_constant=tau)
    np.testing.assert_allclose(out, [1 + 2 * 0.5 / tau + 4 / tau**2, 2 - 2 / tau + 1 / tau**2,
                                     3 + 2 / tau])
    sym = baumgarte(ca.DM(c), ca.DM(r), ca.DM(phi), time_constant=tau)
    np.testing.assert_allclose(np.asarray(sym).ravel(), out)
    np.testing.assert_allclose(baumgarte(c, r), c + r / DEFAULT_TIME_CONSTANT)
    with pytest.raises(ValueError, match="time_constant"):
        baumgarte(c, r, time_constant=0.0)
    with pytest.raises(ValueError, match="`position`"):
        baumgarte(c, r, np.ones(4))


def _pendulum_model(m, l, tau):
    """Cartesian pendulum built from the machinery (as a model author would)."""
    x = ca.SX.sym("x", 4)
    q, v = x[:2], x[2:]
    u, p = ca.SX.sym("u", 0), ca.SX.sym("p", 0)
    terms = constraint_terms(q, v, v, position=(ca.sumsqr(q) - l**2) / 2)
    c = terms.c if tau is None else baumgarte(terms.c, terms.residual, terms.position, time_constant=tau)
    acc = constrained_accelerations(m * np.eye(2), ca.vertcat(0, -m * G), terms.B, c)
    f = ca.Function("pendulum", [x, u, p], [ca.vertcat(v, acc.vdot)], ["x", "u", "p"], ["xdot"])
    return Model(f, ("x", "y", "xdot", "ydot"), (), invariants={
        "constraint_residual": residual_invariant(x, p, terms),
        "phi": ca.Function("phi", [x, p], [terms.position], ["x", "p"], ["phi"])})


def _pendulum_ode():
    s = ca.SX.sym("s", 2)
    f = ca.Function("ode", [s, ca.SX.sym("u", 0), ca.SX.sym("p", 0)],
                    [ca.vertcat(s[1], -G / 0.9 * ca.sin(s[0]))], ["x", "u", "p"], ["xdot"])
    return Model(f, ("theta", "thetadot"), ())


def test_cartesian_pendulum_model_follows_theta_ode():
    l, th0, thd0 = 0.9, 2.0, 0.3
    x0 = [l * np.sin(th0), -l * np.cos(th0), l * thd0 * np.cos(th0), l * thd0 * np.sin(th0)]
    t = np.linspace(0.0, 5.0, 51)
    res = simulate(_pendulum_model(1.3, l, 0.5), x0, t, method="rk8", steps=20, jit=False)
    ref = simulate(_pendulum_ode(), [th0, thd0], t, method="rk8", steps=20, jit=False)
    np.testing.assert_allclose(res.x[0], l * np.sin(ref.x[0]), atol=1e-10)
    np.testing.assert_allclose(res.x[1], -l * np.cos(ref.x[0]), atol=1e-10)


def test_baumgarte_residual_decays_critically_damped():
    """e = phi obeys e'' + 2 e'/tau + e/tau^2 = 0: e = (e0 + (e0' + e0/tau) t) exp(-t/tau)."""
    l, tau, th0, thd0, stretch = 0.9, 0.4, 1.0, 0.5, 1e-3
    rho = l + stretch  # start off the circle, with a radial velocity too
    x0 = np.array([rho * np.sin(th0), -rho * np.cos(th0),
                   rho * thd0 * np.cos(th0) + 0.01 * np.sin(th0),
                   rho * thd0 * np.sin(th0) - 0.01 * np.cos(th0)])
    e0, e0dot = (rho**2 - l**2) / 2, x0[:2] @ x0[2:]
    t = np.linspace(0.0, 4.0, 41)
    model = _pendulum_model(1.0, l, tau)
    res = simulate(model, x0, t, method="rk8", steps=50, jit=False, invariants=["phi"])
    np.testing.assert_allclose(res.invariants["phi"], (e0 + (e0dot + e0 / tau) * t) * np.exp(-t / tau),
                               atol=1e-13)
    off = simulate(_pendulum_model(1.0, l, None), x0, t, method="rk8", steps=50, jit=False,
                   invariants=["phi"])
    np.testing.assert_allclose(off.invariants["phi"], e0 + e0dot * t, atol=1e-12)  # drifts


def test_residual_invariant_and_drift_without_stabilization():
    l, th0 = 0.9, 1.2
    x0 = [l * np.sin(th0), -l * np.cos(th0), 0.0, 0.0]
    t = np.linspace(0.0, 200.0, 3)
    kw = dict(method="rk8", steps=4000, jit=False, invariants=["constraint_residual"])
    on = simulate(_pendulum_model(1.0, l, 0.5), x0, t, **kw).invariants["constraint_residual"]
    off = simulate(_pendulum_model(1.0, l, None), x0, t, **kw).invariants["constraint_residual"]
    assert on.shape == (2, 3) and np.max(on) < 1e-12  # held at the local error level
    assert off[0, -1] > 3 * off[0, 1]  # phi grows like t^2 without stabilization
    assert off[0, -1] > 100 * np.max(on)


# -------------------------------------------------------------------- projection
def test_project_velocities_is_the_mass_weighted_nearest():
    M, _, B, _ = _random_system(np.random.default_rng(3), n=5, m=2)
    v, b = np.arange(5.0), np.array([0.3, -0.2])
    w = project_velocities(M, B, v, b)
    np.testing.assert_allclose(B @ w + b, 0, atol=1e-12)
    # nearest in the M norm: M (w - v) lies in the row space of B
    mu, *_ = np.linalg.lstsq(B.T, M @ (w - v), rcond=None)
    np.testing.assert_allclose(B.T @ mu, M @ (w - v), atol=1e-12)
    vs = ca.SX.sym("v", 5)
    sym = ca.Function("p", [vs], [project_velocities(M, B, vs, b)])(v)
    np.testing.assert_allclose(np.asarray(sym).ravel(), w, atol=1e-12)


def test_project_positions_onto_a_circle_with_weights():
    res = project_positions(lambda x: [x @ x - 1.0], lambda x: [2 * x], np.array([3.0, 4.0]))
    np.testing.assert_allclose(res.x, [0.6, 0.8], atol=1e-15)
    assert res.success and res.residual <= 1e-12 and 0 < res.iterations < 10
    # a heavy first coordinate moves less: the result is still on the circle
    w = project_positions(lambda x: [x @ x - 1.0], lambda x: [2 * x], np.array([1.0, 1.0]),
                          weight=np.diag([100.0, 1.0]))
    assert abs(w.x @ w.x - 1) <= 1e-12 and w.x[0] > w.x[1]
    stuck = project_positions(lambda x: [x @ x - 1.0], lambda x: [2 * x], [3.0, 4.0], max_iter=1)
    assert not stuck.success and stuck.iterations == 1
