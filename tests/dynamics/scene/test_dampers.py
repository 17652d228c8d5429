"""Dampers, slosh and the tilt torque as scene parts.

* `gyrostat_model` and `tilt_torque_body` (scene wrappers) equal the hand-written models they
  replace (`legacy_spinning`, copied verbatim) in rhs, Jacobians and invariants to 1e-13;
* each part against an independent truth: conservation of energy and inertial momentum,
  the energy's decay at the dissipation rate, the slosh pendulum's closed-form frequencies.
"""
import dataclasses
import math

import casadi as ca
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from appdyn.dynamics import simulate
from appdyn.dynamics.scene import (ExternalForce, HeldRotor, PointMassDamper,
                                   RigidHub, Scene, Slosh, SphericalDamper, TiltTorque)
from appdyn.dynamics.spinning import gyrostat_model, tilt_torque_body

from . import legacy_spinning as legacy

TOL = 1e-13
real = lambda lo, hi: st.floats(lo, hi, allow_nan=False, allow_infinity=False)  # noqa: E731
vec3 = st.tuples(real(-1, 1), real(-1, 1), real(-1, 1)).filter(lambda v: np.linalg.norm(v) > 0.1)


@st.composite
def inertias(draw):
    """Principal moments in [2, 4] (the triangle inequality holds) in random axes."""
    moments = [draw(real(2.0, 4.0)) for _ in range(3)]
    q = np.array(draw(st.tuples(*[real(-1, 1)] * 4).filter(lambda v: np.linalg.norm(v) > 0.1)))
    R = _dcm(q / np.linalg.norm(q))
    return R @ np.diag(moments) @ R.T


def _dcm(q):
    from appdyn.dynamics.attitude import dcm_from_quat
    return np.array(ca.DM(dcm_from_quat(ca.DM(q))))


@st.composite
def states(draw, n_extra, extra_range):
    q = np.array(draw(st.tuples(*[real(-1, 1)] * 4).filter(lambda v: np.linalg.norm(v) > 0.1)))
    w = [draw(real(-2, 2)) for _ in range(3)]
    extra = [draw(real(-r, r)) for r in extra_range[:n_extra]]
    return np.r_[q / np.linalg.norm(q), w, extra]


def _functions(model):
    x = ca.SX.sym("x", model.nx)
    u = ca.SX.sym("u", model.nu)
    p = ca.SX.sym("p", 0)
    xdot = model.f(x, u, p)
    out = {"rhs": ca.Function("r", [x, u], [xdot]),
           "jac_x": ca.Function("jx", [x, u], [ca.jacobian(xdot, x)]),
           "jac_u": ca.Function("ju", [x, u], [ca.jacobian(xdot, u)])}
    for key, fun in model.invariants.items():
        out[key] = ca.Function(key, [x, u], [fun(x, p)])
    return out


def assert_same_model(new, old, x, u):
    """rhs, d xdot/dx, d xdot/du and every invariant agree to 1e-13 (relative to the
    magnitude, absolute floor 1e-13); names and units too."""
    assert new.states == old.states and new.controls == old.controls
    assert dict(new.units) == dict(old.units)
    assert new.name == old.name and set(new.invariants) == set(old.invariants)
    fn, fo = _functions(new), _functions(old)
    for key in fo:
        a, b = np.array(fn[key](x, u)), np.array(fo[key](x, u))
        assert a.shape == b.shape, key
        scale = max(1.0, float(np.abs(b).max(initial=0.0)))
        err = float(np.abs(a - b).max(initial=0.0))
        assert err <= TOL * scale, f"{key}: |new - old| = {err:.3e} (scale {scale:.3e})"


# ------------------------------------------------------------ wrappers = legacy models
@st.composite
def gyrostats(draw):
    kind = draw(st.sampled_from(["none", "point", "sphere", "sphere-rotor"]))
    kw = dict(wheel_axis=draw(vec3),
              wheel_momentum=draw(st.one_of(st.just(0.0), real(-5, 5))))
    extra_range = ()
    if kind == "point":
        kw["damper"] = PointMassDamper(
            draw(real(0.1, 2.0)), draw(real(1.0, 100.0)), draw(real(0.0, 5.0)),
            position=draw(st.tuples(real(-1, 1), real(-1, 1), real(-1, 1))),
            direction=draw(vec3), body_mass=draw(st.one_of(st.just(math.inf), real(1.0, 100.0))))
        extra_range = (0.2, 1.0)
    elif kind.startswith("sphere"):
        kw["damper"] = SphericalDamper(draw(real(0.01, 1.0)), draw(real(0.0, 1.0)))
        extra_range = (3.0, 3.0, 3.0)
        if kind == "sphere-rotor":
            kw.update(damper_on="rotor", wheel_rate=draw(real(-10, 10)))
    return kw, extra_range


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(inertias(), gyrostats(), st.data())
@pytest.mark.slow
def test_gyrostat_wrapper_equals_the_hand_written_model(inertia, case, data):
    kw, extra_range = case
    new, old = gyrostat_model(inertia, **kw), legacy.gyrostat_model(inertia, **kw)
    x = data.draw(states(len(extra_range), extra_range))
    u = data.draw(st.tuples(real(-1, 1), real(-1, 1), real(-1, 1)))
    assert_same_model(new, old, x, u)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(inertias(), real(-10, 10), vec3, vec3, st.one_of(st.just(0.0), real(0.0, 3.0)),
       st.data())
@pytest.mark.slow
def test_tilt_torque_wrapper_equals_the_hand_written_model(inertia, kappa, axis, direction,
                                                          damping, data):
    kw = dict(axis=axis, direction=direction, internal_damping=damping)
    new, old = tilt_torque_body(inertia, kappa, **kw), legacy.tilt_torque_body(inertia, kappa, **kw)
    x = data.draw(states(0, ()))
    u = data.draw(st.tuples(real(-1, 1), real(-1, 1), real(-1, 1)))
    assert_same_model(new, old, x, u)


# ------------------------------------------------------------------- conservation laws
IH = np.array([[10.0, 0.4, -0.3], [0.4, 12.0, 0.2], [-0.3, 0.2, 8.0]])

CONSERVATIVE = {
    "point": lambda: Scene(RigidHub(IH), PointMassDamper(0.8, 40.0, 0.0, (0.2, 0.5, -0.1),
                                                           (1.0, 0.2, 0.3), body_mass=50.0)),
    "point-6dof": lambda: Scene(RigidHub(IH, mass=40.0, reference=(0.1, -0.2, 0.3)),
                                PointMassDamper(0.8, 40.0, 0.0, (0.2, 0.5, -0.1), (1.0, 0.2, 0.3))),
    "sphere": lambda: Scene(RigidHub(IH), HeldRotor((0.0, 0.6, 0.8), 2.0),
                            SphericalDamper(0.5, 0.0, housing_rate=(0.0, 3.0, 4.0))),
    "sphere-6dof": lambda: Scene(RigidHub(IH, mass=40.0, reference=(0.1, -0.2, 0.3)),
                                 SphericalDamper(0.5, 0.0)),
    "slosh-6dof": lambda: Scene(RigidHub(IH, mass=40.0),
                                Slosh(2.0, length=0.4, hinge=(0.3, 0.1, -0.2),
                                      direction=(1.0, 1.0, 0.0)),
                                Slosh(1.0, kind="spring", frequency=4.0, position=(0.0, 0.5, 0.1),
                                      direction=(0.0, 0.3, 1.0))),
    "slosh": lambda: Scene(RigidHub(IH), Slosh(2.0, length=0.4, hinge=(0.3, 0.1, -0.2),
                                              direction=(0.2, 0.1, 1.0))),
    "tilt": lambda: Scene(RigidHub(IH), TiltTorque(3.0, axis=(0.1, 0.2, 1.0),
                                                   direction=(0.0, 0.3, 1.0))),
}


def _moving_state(scene):
    """A tumbling state with every part displaced and moving."""
    x = scene.state(q=np.array([0.1, -0.2, 0.3, 0.9]) / np.linalg.norm([0.1, -0.2, 0.3, 0.9]),
                    w=[0.3, -0.2, 0.5])
    for name in scene.part_names:
        sl = scene.layout[name].states
        x[sl] += 0.1 * np.cos(np.arange(sl.start, sl.stop))
    if scene.hub.translates:
        x[7:13] = [1.0, -2.0, 0.5, 0.2, 0.1, -0.3]
    return x


@pytest.mark.parametrize("case", sorted(CONSERVATIVE))
def test_energy_and_momenta_are_conserved_without_damping(case):
    """u = 0, no damping: energy, inertial angular momentum (its component along the field
    direction under the tilt torque) and linear momentum stay put to 1e-10 relative over
    100 s (Basilisk's check)."""
    scene = CONSERVATIVE[case]()
    model = scene.model()
    t = np.linspace(0.0, 100.0, 201)
    res = simulate(model, _moving_state(scene), t, method="rk8", steps=40, invariants=True,
                   jit=False)
    assert res.success
    E = np.asarray(res.invariants["energy"]).reshape(-1)
    H = np.asarray(res.invariants["momentum_inertial"]).reshape(3, -1)
    if case == "tilt":
        H = np.array(scene.parts[0].direction) @ H  # the torque has no component along d
        assert abs(H[0]) > 0.1
    checks = {"energy": E, "momentum_inertial": H}
    if scene.hub.translates:
        checks["momentum_linear"] = np.asarray(res.invariants["momentum_linear"]).reshape(3, -1)
    for key, val in checks.items():
        val = np.atleast_2d(val)
        drift = np.abs(val - val[:, :1]).max() / np.abs(val[:, 0]).max()
        assert drift <= 1e-10, f"{key} drifts by {drift:.2e}"


# ------------------------------------------------------------------------ dissipation
def _dissipation_cases(c):
    """(scene, power(x)) with damping ``c``: the power of the dissipative loads, written out."""
    point = PointMassDamper(0.8, 40.0, c, (0.2, 0.5, -0.1), (1.0, 0.2, 0.3))
    hr = np.array([0.0, 3.0, 4.0])
    sphere = SphericalDamper(0.5, c, housing_rate=hr)
    pend = Slosh(2.0, length=0.4, hinge=(0.3, 0.1, -0.2), direction=(1.0, 1.0, 0.0), damping=c)
    spring = Slosh(1.0, kind="spring", stiffness=9.0, damping=c, direction=(0.0, 0.3, 1.0))
    tilt = TiltTorque(3.0, axis=(0.1, 0.2, 1.0), direction=(0.0, 0.3, 1.0), internal_damping=c)

    def tilt_power(x):
        from appdyn.dynamics.attitude import dcm_from_quat
        a, w = np.array(tilt.axis), x[4:7]
        n = np.array(ca.DM(dcm_from_quat(ca.DM(x[:4])))) @ np.array(tilt.direction)
        tau_rate = (np.outer(n, a) - (a @ n) * np.eye(3)) @ w
        return -c * tau_rate @ tau_rate

    # the core's torque -c (wd - w - hr) does work on the core's rate relative to the hub
    sphere_power = lambda x: -c * (x[7:10] - x[4:7] - hr) @ (x[7:10] - x[4:7])  # noqa: E731
    return {
        "point": (Scene(RigidHub(IH), point), lambda x: -c * x[8] ** 2),
        "point-6dof": (Scene(RigidHub(IH, mass=40.0), point), lambda x: -c * x[14] ** 2),
        "sphere": (Scene(RigidHub(IH), HeldRotor((0.0, 0.6, 0.8), 2.0), sphere), sphere_power),
        "slosh": (Scene(RigidHub(IH, mass=40.0), pend, spring),
                  lambda x: -c * (x[15] ** 2 + x[16] ** 2 + x[18] ** 2)),
        "tilt": (Scene(RigidHub(IH), tilt), tilt_power),
    }


@settings(max_examples=30, deadline=None)
@given(st.sampled_from(["point", "point-6dof", "sphere", "slosh", "tilt"]),
       st.sampled_from([0.7, 2.3]), st.data())
def test_energy_decays_at_the_dissipation_rate(case, c, data):
    """u = 0: dE/dt = (dE/dx) f(x) equals the dampers' power, exactly (1e-12 relative); it
    is a loss except where a turning housing (a motor) drives the spherical core."""
    scene, power = _dissipation_cases(c)[case]
    model = scene.model()
    n = model.nx - 7
    x = data.draw(states(n, (0.3,) * n))
    xs = ca.SX.sym("x", model.nx)
    rate = ca.Function("dE", [xs], [ca.jacobian(model.invariants["energy"](xs, []), xs)
                                    @ model.f(xs, ca.DM.zeros(model.nu), [])])
    got, want = float(rate(x)), power(x)
    assert case == "sphere" or want <= 0.0
    assert abs(got - want) <= 1e-12 * max(1.0, abs(want)), (got, want)


# ------------------------------------------------------------- slosh: closed forms
def _block_eigenvalues(model, x, u, names):
    """Eigenvalues of the Jacobian block of the states ``names`` at ``(x, u)``, after
    checking that the block is invariant (its rows depend on no other state there), so
    that they are eigenvalues of the whole linearization."""
    xs = ca.SX.sym("x", model.nx)
    J = np.array(ca.Function("J", [xs], [ca.jacobian(model.f(xs, u, []), xs)])(x))
    idx = [model.states.index(n) for n in names]
    others = [k for k in range(model.nx) if k not in idx]
    scale = np.abs(J[np.ix_(idx, idx)]).max()
    assert np.abs(J[np.ix_(idx, others)]).max() <= 1e-14 * scale
    return np.sort_complex(np.linalg.eigvals(J[np.ix_(idx, idx)]))


def test_slosh_pendulum_swings_at_sqrt_a_over_l_on_an_accelerated_hub():
    """A force F on the free hub (mass M) with the pendulum hinged at its mass centre: the
    relative motion is a pendulum of the reduced mass in the field F/M, so omega^2 = F/(M l)
    in both planes (M+m moves at F/(M+m); the hub, pulled by F and held back by the
    pendulum, sees the rod force only along the rod)."""
    M, m, l, F = 40.0, 3.0, 0.4, 25.0
    scene = Scene(RigidHub(IH, mass=M), Slosh(m, length=l, direction=(-1.0, 0.0, 0.0)),
                  ExternalForce())
    eig = _block_eigenvalues(scene.model(), scene.state(), [F, 0.0, 0.0],
                             ["theta1", "theta2", "theta1_dot", "theta2_dot"])
    omega = math.sqrt(F / (M * l))
    np.testing.assert_allclose(eig, [-1j * omega] * 2 + [1j * omega] * 2, rtol=1e-12, atol=0)


def test_slosh_pendulum_in_the_spin_plane_swings_at_w_sqrt_r_over_l():
    """Hub (moment C about the spin axis) spinning at W, pendulum hinged at R pointing
    outward: in the spin plane, with the hub's rate free (angular momentum conserved),
    omega^2 = W^2 (R / l) (1 + m (R + l)^2 / C); Lagrange with the cyclic hub angle."""
    C, m, R, l, W = 6.0, 0.5, 0.8, 0.3, 2.0
    scene = Scene(RigidHub([4.0, 5.0, C]), Slosh(m, length=l, hinge=(R, 0.0, 0.0)))
    eig = _block_eigenvalues(scene.model(), scene.state(w=[0.0, 0.0, W]), [],
                             ["w3", "theta1", "theta1_dot"])
    omega = W * math.sqrt(R / l * (1.0 + m * (R + l) ** 2 / C))
    np.testing.assert_allclose(eig, [-1j * omega, 0.0, 1j * omega], rtol=1e-12, atol=1e-12)


def test_spring_slosh_and_point_damper_oscillate_at_the_reduced_mass_frequency():
    """A spring through the mass centre of a free hub (mass M): omega^2 = k / mu with
    mu = m M / (m + M); the point-mass damper on an attitude-only hub with body_mass M
    gives the same."""
    M, m, k = 40.0, 3.0, 50.0
    omega = math.sqrt(k * (M + m) / (M * m))
    for scene in (Scene(RigidHub(IH, mass=M), Slosh(m, kind="spring", stiffness=k)),
                  Scene(RigidHub(IH), PointMassDamper(m, k, 0.0, body_mass=M))):
        eig = _block_eigenvalues(scene.model(), scene.state(), [], ["s", "s_dot"])
        np.testing.assert_allclose(eig, [-1j * omega, 1j * omega], rtol=1e-12, atol=0)


# ------------------------------------------------------------------------- bad input
def test_bad_parts_are_refused_by_field_name():
    with pytest.raises(ValueError, match="`damper.body_mass`"):
        Scene(RigidHub(IH, mass=10.0), PointMassDamper(1.0, 2.0, 0.0, body_mass=5.0)).model()
    with pytest.raises(ValueError, match="`damper.stiffness` must be positive"):
        PointMassDamper(1.0, 0.0, 0.0)
    with pytest.raises(ValueError, match="`damper.direction` must be a finite non-zero"):
        PointMassDamper(1.0, 1.0, 0.0, direction=(0, 0, 0))
    with pytest.raises(ValueError, match="damper.housing_rate"):
        SphericalDamper(1.0, 0.1, housing_rate=(1.0, 2.0))
    with pytest.raises(ValueError, match="needs `length`"):
        Slosh(1.0)
    with pytest.raises(ValueError, match="`length` must be positive"):
        Slosh(1.0, length=-0.1)
    with pytest.raises(ValueError, match="exactly one of `frequency`"):
        Slosh(1.0, kind="spring")
    with pytest.raises(ValueError, match="exactly one of `frequency`"):
        Slosh(1.0, kind="spring", frequency=1.0, stiffness=2.0)
    # both, when they agree (k = m f^2), are a copy's fields: dataclasses.replace works
    spring = Slosh(1.5, kind="spring", frequency=2.0)
    assert dataclasses.replace(spring, parent="panel").stiffness == spring.stiffness
    with pytest.raises(ValueError, match="`frequency` is for kind='spring'"):
        Slosh(1.0, length=1.0, frequency=2.0)
    with pytest.raises(ValueError, match="kind"):
        Slosh(1.0, kind="bath")
    with pytest.raises(ValueError, match="`internal_damping` must be non-negative"):
        TiltTorque(1.0, internal_damping=-1.0)
    with pytest.raises(ValueError, match="`axis` must be a finite non-zero 3-vector"):
        TiltTorque(1.0, axis=(0.0, 0.0, 0.0))


def test_scene_parts_keep_the_stability_names_and_state_helpers():
    """The dampers are the same classes under dynamics.spinning and problems.stability, and a
    scene puts a spherical core at rest relative to its turning housing."""
    from appdyn.dynamics import spinning
    from appdyn.problems import stability
    assert spinning.PointMassDamper is stability.PointMassDamper is PointMassDamper
    assert spinning.SphericalDamper is stability.SphericalDamper is SphericalDamper
    scene = Scene(RigidHub(IH), SphericalDamper(0.5, 0.1, housing_rate=(0.0, 0.0, 7.0)))
    np.testing.assert_array_equal(scene.state(w=[0.0, 0.0, 1.0])[7:], [0.0, 0.0, 8.0])
    x = spinning.steady_spin_state([0, 0, 1], 1.0, damper=SphericalDamper(0.5, 0.1),
                                   damper_on="rotor", wheel_rate=7.0)
    model = gyrostat_model(IH, wheel_axis=(0, 0, 1), wheel_momentum=2.0,
                           damper=SphericalDamper(0.5, 0.1), damper_on="rotor", wheel_rate=7.0)
    np.testing.assert_array_equal(x[7:], [0.0, 0.0, 8.0])
    assert model.layout["damper"].speeds == slice(7, 10)


# ------------------------------------------------------- slosh: a sympy Kane model
@pytest.mark.slow
def test_slosh_hub_equals_an_independent_sympy_kane_model():
    """A free hub (reference point off its mass centre) with a damped pendulum hinged off
    the mass centre, a damped spring-mass and a force at a third point: the scene's
    accelerations equal sympy.mechanics' Kane equations (Euler angles, physical spring
    force pair) to 1e-12 at random states."""
    from .kane_slosh import slosh_hub_equations
    pend = Slosh(2.0, length=0.4, hinge=(0.3, 0.1, -0.2), direction=(0.3, -1.0, 0.2),
                 damping=0.3)
    spring = Slosh(1.5, kind="spring", frequency=4.0, damping=0.7, position=(0.0, 0.5, 0.1),
                   direction=(0.2, 0.3, 1.0))
    ref, point = (0.1, -0.2, 0.3), (0.4, 0.0, -0.5)
    scene = Scene(RigidHub(IH, mass=40.0, reference=ref), pend, spring, ExternalForce(point=point))
    model = scene.model()
    truth = slosh_hub_equations(IH, 40.0, ref, point, pend, spring)
    rows = [model.states.index(n) for n in
            ("w1", "w2", "w3", "v1", "v2", "v3", "theta1_dot", "theta2_dot", "s_dot")]
    rng = np.random.default_rng(7)
    for _ in range(5):
        q = rng.normal(size=4)
        x = scene.state(q=q / np.linalg.norm(q), w=rng.normal(size=3), r=rng.normal(size=3),
                        v=rng.normal(size=3), pendulum=rng.normal(size=4),
                        spring=rng.normal(size=2) * [0.2, 1.0])
        F = rng.normal(size=3) * 10.0
        want = truth(x[4:7], x[10:13], x[13:15], x[15:17], x[17], x[18], F)
        got = model.rhs(x, F)[rows]
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * np.abs(want).max())


@pytest.mark.parametrize("case", ["point", "point-6dof", "sphere", "slosh"])
@pytest.mark.slow
def test_damping_keeps_the_momenta_and_only_loses_energy(case):
    """Damping is internal: with it on, the inertial (and linear) momentum still stay put to
    1e-10 over 100 s while the energy falls (the spherical core's housing turns, its motor
    works: only momentum there)."""
    scene, _ = _dissipation_cases(0.7)[case]
    res = simulate(scene.model(), _moving_state(scene), np.linspace(0.0, 100.0, 201),
                   method="rk8", steps=40, invariants=True, jit=False)
    assert res.success
    keys = ["momentum_inertial"] + (["momentum_linear"] if scene.hub.translates else [])
    for key in keys:
        val = np.asarray(res.invariants[key]).reshape(3, -1)
        drift = np.abs(val - val[:, :1]).max() / np.abs(val[:, 0]).max()
        assert drift <= 1e-10, f"{key} drifts by {drift:.2e}"
    E = np.asarray(res.invariants["energy"]).reshape(-1)
    if case != "sphere":
        assert np.all(np.diff(E) <= 1e-12 * abs(E[0])) and E[-1] < 0.99 * E[0]
