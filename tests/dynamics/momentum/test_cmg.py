"""CMG spacecraft: the shared geometry, exact conservation of inertial momentum for any
gimbal-rate history, the torque model as the exact model's limit of fast rotors, and the
gyrostat as a CMG with its gimbal still."""
import doctest

import casadi as ca
import numpy as np
import pytest

from appdyn.dynamics import simulate
from appdyn.dynamics.attitude import dcm_from_quat
from appdyn.dynamics.momentum import cmg
from appdyn.dynamics.momentum.cluster import cluster_momentum, pyramid
from appdyn.dynamics.momentum.cmg import cmg_spacecraft
from appdyn.dynamics.spinning import gyrostat_model

INERTIA = np.array([[12.0, 0.3, -0.2], [0.3, 10.0, 0.1], [-0.2, 0.1, 8.0]])
GEO = pyramid(np.arccos(1 / np.sqrt(3)), 2.0)
G, S0 = GEO.gimbal_axes, GEO.spin_axes0
H_ROTOR = np.array([2.0, 2.0, 2.5, 1.5])
W0 = np.array([0.03, -0.02, 0.04])


def random_state(rng, n=4):
    q = rng.normal(size=4)
    return np.concatenate([q / np.linalg.norm(q), rng.normal(size=3), rng.normal(size=n)])


def gimbal_rates(t):
    """Smooth, time-varying gimbal rates [rad/s]."""
    k = np.arange(1, 5)
    return 0.05 * np.sin(0.1 * k * t + k) + 0.02 * np.cos(0.07 * t)


def axes_at(delta):
    """The convention written out: s = cos d s0 + sin d (g x s0), t = g x s."""
    s = np.cos(delta) * S0 + np.sin(delta) * np.cross(G, S0, axis=0)
    return s, np.cross(G, s, axis=0)


def total_momentum(x, J=0.0):
    """``A^T (I w + sum_i (J_i s_i s_i^T w + h_i s_i))``, from its definition."""
    w, s = x[4:7], axes_at(x[7:])[0]
    H = INERTIA @ w + s @ (J * (s.T @ w) + H_ROTOR)
    return dcm_from_quat(x[:4]).T @ H


def rates_of_invariants(model):
    x, u = ca.SX.sym("x", model.nx), ca.SX.sym("u", model.nu)
    xdot = model.f(x=x, u=u, p=ca.DM.zeros(0))["xdot"]
    return {k: ca.Function(k, [x, u], [ca.jtimes(fun(x, ca.DM.zeros(0)), x, xdot)])
            for k, fun in model.invariants.items()}


# ------------------------------------------------------------------------------ structure
def test_metadata_geometry_and_cache():
    model = cmg_spacecraft(INERTIA, G, S0, H_ROTOR)
    assert model.states[7:] == ("d1", "d2", "d3", "d4")
    assert model.controls == ("d1_dot", "d2_dot", "d3_dot", "d4_dot")
    assert model.units["d3"] == "rad" and model.units["d3_dot"] == "rad/s"
    assert model.attitude == (0, 4) and model.params == ()
    assert set(model.invariants) == {"energy", "momentum_inertial", "quat_norm", "cmg_momentum"}
    assert cmg_spacecraft(INERTIA.tolist(), G.tolist(), S0.tolist(), H_ROTOR.tolist()) is model
    forced = cmg_spacecraft(INERTIA, G, S0, 1.0, fidelity="torque", external_torque=True)
    assert forced.controls[-3:] == ("L1", "L2", "L3")
    rng = np.random.default_rng(0)
    for _ in range(5):
        x = random_state(rng)
        s, _ = axes_at(x[7:])
        np.testing.assert_allclose(model.invariant("cmg_momentum", x), s @ H_ROTOR, atol=1e-14)
        geo = pyramid(np.arccos(1 / np.sqrt(3)), H_ROTOR)  # the cluster analysis agrees
        np.testing.assert_allclose(model.invariant("cmg_momentum", x),
                                   cluster_momentum(geo, x[7:]), atol=1e-14)


def test_body_at_rest_feels_the_seed_cmg_torque():
    """w = 0: I w' = L_c = -sum_i w_c,i x H_m,i with w_c = delta' g, H_m = h s (Eq. 4.150)."""
    rng = np.random.default_rng(1)
    for fidelity in ("exact", "torque"):
        model = cmg_spacecraft(INERTIA, G, S0, H_ROTOR, fidelity=fidelity)
        for _ in range(3):
            x, rate = random_state(rng), rng.normal(size=4)
            x[4:7] = 0.0
            s, _ = axes_at(x[7:])
            Lc = -sum(np.cross(rate[i] * G[:, i], H_ROTOR[i] * s[:, i]) for i in range(4))
            xdot = model.rhs(x, rate)
            np.testing.assert_allclose(INERTIA @ xdot[4:7], Lc, atol=1e-14)
            np.testing.assert_array_equal(xdot[7:], rate)


def test_torque_model_is_the_exact_model_without_rotor_inertia():
    exact = cmg_spacecraft(INERTIA, G, S0, H_ROTOR, external_torque=True)
    torque = cmg_spacecraft(INERTIA, G, S0, H_ROTOR, fidelity="torque", external_torque=True)
    rng = np.random.default_rng(2)
    for _ in range(10):
        x, u = random_state(rng), rng.normal(size=7)
        np.testing.assert_allclose(torque.rhs(x, u), exact.rhs(x, u), rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize("fidelity, J", [("exact", 0.0), ("exact", 0.3), ("torque", 0.0)])
def test_invariant_rates_along_the_flow(fidelity, J):
    """Exactly: d(A^T H)/dt = A^T L, and d(1/2 w.I(d) w)/dt = -sum_i d_i' (h_i t_i.w +
    J_i (s_i.w)(t_i.w)) with L = 0."""
    kw = dict(rotor_inertia=J) if J else {}
    model = cmg_spacecraft(INERTIA, G, S0, H_ROTOR, fidelity=fidelity, external_torque=True, **kw)
    rate = rates_of_invariants(model)
    rng = np.random.default_rng(3)
    for _ in range(10):
        x, u = random_state(rng), rng.normal(size=7)
        A = dcm_from_quat(x[:4])
        np.testing.assert_allclose(rate["momentum_inertial"](x, u).full().ravel(), A.T @ u[4:],
                                   atol=1e-12)
        np.testing.assert_allclose(model.invariant("momentum_inertial", x), total_momentum(x, J),
                                   atol=1e-13)
        u[4:] = 0.0
        w, (s, t) = x[4:7], axes_at(x[7:])
        expected = -np.sum(u[:4] * (H_ROTOR * (t.T @ w) + J * (s.T @ w) * (t.T @ w)))
        assert float(rate["energy"](x, u)) == pytest.approx(expected, rel=1e-11, abs=1e-13)


def test_gimbal_rate_momentum_balance():
    """With gimbal inertia the model carries w x (J_g d' g): d(A^T H)/dt = -A^T (w x sum_i
    J_g,i d_i' g_i), so that A^T (H + sum_i J_g,i d_i' g_i) is constant at constant rates."""
    Jg = np.array([0.1, 0.2, 0.3, 0.4])
    model = cmg_spacecraft(INERTIA, G, S0, H_ROTOR, rotor_inertia=0.3, gimbal_inertia=Jg)
    rate = rates_of_invariants(model)
    rng = np.random.default_rng(4)
    for _ in range(10):
        x, u = random_state(rng), rng.normal(size=4)
        A = dcm_from_quat(x[:4])
        expected = -A.T @ np.cross(x[4:7], G @ (Jg * u))
        np.testing.assert_allclose(rate["momentum_inertial"](x, u).full().ravel(), expected,
                                   atol=1e-12)


def test_still_gimbal_is_a_gyrostat():
    """One CMG with d' = 0: gyrostat_model(I + J s s^T, wheel_axis=s, wheel_momentum=h)."""
    g, s0 = np.array([[0.0], [0.0], [1.0]]), np.array([[0.6], [0.8], [0.0]])
    J, h = 0.4, 3.0
    model = cmg_spacecraft(INERTIA, g, s0, h, rotor_inertia=J, gimbal_inertia=0.7)
    rng = np.random.default_rng(5)
    for _ in range(5):
        x = random_state(rng, 1)
        s = np.cos(x[7]) * s0[:, 0] + np.sin(x[7]) * np.cross(g[:, 0], s0[:, 0])
        gyro = gyrostat_model(INERTIA + J * np.outer(s, s), wheel_axis=s, wheel_momentum=h)
        np.testing.assert_allclose(model.rhs(x, [0.0])[:7], gyro.rhs(x[:7]), rtol=1e-10,
                                   atol=1e-14)
        assert float(model.invariant("energy", x)) == pytest.approx(
            float(gyro.invariant("energy", x[:7])), rel=1e-13)


# --------------------------------------------------------------------- long-run conservation
@pytest.mark.parametrize("fidelity, J", [("exact", 0.3), ("torque", 0.0)])
def test_momentum_conserved_over_100_s_with_time_varying_gimbal_rates(fidelity, J):
    kw = dict(rotor_inertia=[0.3, 0.2, 0.3, 0.25]) if J else {}
    model = cmg_spacecraft(INERTIA, G, S0, H_ROTOR, fidelity=fidelity, **kw)
    t = np.linspace(0.0, 100.0, 201)
    x0 = np.r_[0.1, -0.2, 0.3, 0.9, W0, 0.1, -0.2, 0.3, 0.0]
    x0[:4] /= np.linalg.norm(x0[:4])
    res = simulate(model, x0, t, u=gimbal_rates, method="rk8", steps=10)
    assert res.success
    H = model.invariant("momentum_inertial", res.x)
    drift = np.max(np.linalg.norm(H - H[:, :1], axis=0)) / np.linalg.norm(H[:, 0])
    assert drift < 1e-10
    assert np.ptp(res.x[7:], axis=1).min() > 0.5  # the gimbals really turned
    assert np.ptp(res.x[4:7], axis=1).max() > 0.05  # and moved the body


def test_constant_gimbal_rates_conserve_the_total_with_gimbal_momentum():
    Jg = np.array([0.1, 0.2, 0.3, 0.4])
    model = cmg_spacecraft(INERTIA, G, S0, H_ROTOR, rotor_inertia=0.3, gimbal_inertia=Jg)
    rate = np.array([0.05, -0.03, 0.04, 0.02])
    t = np.linspace(0.0, 100.0, 201)
    res = simulate(model, np.r_[0, 0, 0, 1, W0, 0, 0, 0, 0], t, u=rate, method="rk8", steps=10)
    gimbal = np.stack([dcm_from_quat(res.x[:4, k]).T @ (G @ (Jg * rate)) for k in range(t.size)], 1)
    H = model.invariant("momentum_inertial", res.x) + gimbal
    assert np.max(np.linalg.norm(H - H[:, :1], axis=0)) / np.linalg.norm(H[:, 0]) < 1e-10


def test_energy_conserved_while_the_gimbals_stand_still():
    model = cmg_spacecraft(INERTIA, G, S0, H_ROTOR, rotor_inertia=0.3)
    t = np.linspace(0.0, 100.0, 101)
    res = simulate(model, np.r_[0, 0, 0, 1, 10 * W0, 0.3, -0.1, 0.2, 0.5], t, method="rk8",
                   steps=20, invariants=["energy"])
    E = res.invariants["energy"]
    assert np.max(np.abs(E - E[0])) < 1e-12 * E[0]


# ------------------------------------------------------------------ exact vs torque model
@pytest.mark.slow
def test_torque_model_is_the_limit_of_fast_rotors():
    """At fixed rotor momentum h, rotor speed Omega = h / J over the body rate |w| grows
    tenfold per step; the trajectories' difference shrinks tenfold (first order in J)."""
    torque = cmg_spacecraft(INERTIA, G, S0, H_ROTOR, fidelity="torque")
    t = np.linspace(0.0, 30.0, 61)
    x0 = np.r_[0, 0, 0, 1, W0, 0, 0, 0, 0]
    ref = simulate(torque, x0, t, u=gimbal_rates, method="rk8", steps=10)
    body_rate = np.max(np.linalg.norm(ref.x[4:7], axis=0))
    errors = []
    for ratio in (1e2, 1e3, 1e4):
        J = H_ROTOR / (ratio * body_rate)  # rotor spin = ratio x the largest body rate
        exact = cmg_spacecraft(INERTIA, G, S0, H_ROTOR, rotor_inertia=J, gimbal_inertia=J)
        res = simulate(exact, x0, t, u=gimbal_rates, method="rk8", steps=10)
        errors.append(np.max(np.abs(res.x[4:7] - ref.x[4:7])) / body_rate)
    assert errors[0] < 0.05
    np.testing.assert_allclose(np.array(errors[:-1]) / errors[1:], 10.0, rtol=0.1)


# ------------------------------------------------------------------------------ bad inputs
@pytest.mark.parametrize("kwargs, error, match", [
    (dict(gimbal_axes=G[:2]), ValueError, r"`gimbal_axes` must have shape \(3, n\)"),
    (dict(spin_axes0=S0[:, :3]), ValueError, "`spin_axes0` must have the shape of `gimbal_axes`"),
    (dict(gimbal_axes=2 * G), ValueError, r"`gimbal_axes\[:, 0\]` must be a unit vector"),
    (dict(spin_axes0=np.c_[S0[:, :3], np.zeros(3)]), ValueError, r"`spin_axes0\[:, 3\]`.*non-zero"),
    (dict(spin_axes0=np.c_[S0[:, :3], G[:, 3]]), ValueError,
     r"`spin_axes0\[:, 3\]` must be perpendicular to `gimbal_axes\[:, 3\]`"),
    (dict(h=0.0), ValueError, "`h` must be a finite number > 0"),
    (dict(h=[1.0, 2.0]), ValueError, r"`h` must be a scalar or have shape \(4,\)"),
    (dict(h=[1.0, 2.0, -1.0, 1.0]), ValueError, r"`h\[2\]`"),
    (dict(inertia=[1.0, 1.0, 3.0]), ValueError, "`inertia`.*triangle"),
    (dict(fidelity="approximate"), ValueError, "`fidelity` must be 'exact' or 'torque'"),
    (dict(fidelity=1), TypeError, "`fidelity`"),
    (dict(rotor_inertia=-0.1), ValueError, r"`rotor_inertia` must be a finite number > 0"),
    (dict(gimbal_inertia=[0.1, 0.1]), ValueError, r"`gimbal_inertia` must be a scalar or have shape"),
    (dict(fidelity="torque", rotor_inertia=0.1), ValueError, "`rotor_inertia` is not used"),
    (dict(fidelity="torque", gimbal_inertia=0.1), ValueError, "`gimbal_inertia` is not used"),
    (dict(gimbal_axes="up"), TypeError, "`gimbal_axes`"),
    (dict(external_torque=None), TypeError, "`external_torque`"),
])
def test_bad_inputs_name_the_argument(kwargs, error, match):
    args = dict(inertia=INERTIA, gimbal_axes=G, spin_axes0=S0, h=H_ROTOR)
    args.update(kwargs)
    with pytest.raises(error, match=match):
        cmg_spacecraft(**args)


def test_docstring_examples():
    result = doctest.testmod(cmg, optionflags=doctest.NORMALIZE_WHITESPACE | doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0
