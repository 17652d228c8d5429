"""`FlexibleAppendage` against independent truths: the clamped-free closed form (hub locked),
an independent finite-element rotating beam (spinning hub), mass-orthonormality by an
independent quadrature, and conservation of momentum and energy.
"""
import numpy as np
import pytest

from appdyn.dynamics import simulate
from appdyn.dynamics.linearize import linearization
from appdyn.dynamics.scene import FlexibleAppendage, RigidHub, Scene
from appdyn.dynamics.scene.beams import ClampedFreeModes, clamped_free_roots

#: textbook clamped-free roots beta L (Blevins, Formulas for Natural Frequency, Table 8-1)
TEXTBOOK = np.array([1.87510406871196, 4.69409113297418, 7.85475743823761, 10.9955407348755,
                     14.1371683910465])
LOCKED = 1e12 * np.eye(3)  # a hub this heavy does not move: the beam is a cantilever


def _block_eigs(lin, names):
    idx = [lin.index(s) for s in names]
    return np.linalg.eigvals(lin.A[np.ix_(idx, idx)])


def _freqs(lin, part_states):
    ev = _block_eigs(lin, part_states)
    return np.sort(ev.imag[ev.imag > 0])


def test_roots_match_textbook():
    assert np.max(np.abs(clamped_free_roots(5) / TEXTBOOK - 1)) < 1e-13


@pytest.mark.parametrize("tip_mass", [0.0, 0.4])
def test_shapes_mass_orthonormal_and_boundary_conditions(tip_mass):
    beam = ClampedFreeModes(1.7, 0.8, 10, tip_mass=tip_mass)
    # an independent quadrature: composite Gauss-Legendre, 40 panels of 20 points
    t, w = np.polynomial.legendre.leggauss(20)
    edges = np.linspace(0.0, 1.7, 41)
    x = np.concatenate([0.5 * (b - a) * t + 0.5 * (a + b) for a, b in zip(edges, edges[1:])])
    wx = np.concatenate([0.5 * (b - a) * w for a, b in zip(edges, edges[1:])])
    phi, tip = beam.shape(x), beam.shape([1.7])[:, 0]
    gram = 0.8 * (phi * wx) @ phi.T + tip_mass * np.outer(tip, tip)
    assert np.max(np.abs(gram - np.eye(10))) < 1e-12
    scale = np.max(np.abs(phi))
    assert np.max(np.abs(beam.shape([0.0])[:, 0])) < 1e-12 * scale          # w(0) = 0
    assert np.max(np.abs(beam.shape([0.0], 1)[:, 0])) < 1e-12 * scale * 30  # w'(0) = 0
    # free end: w''(L) = 0 and EI w'''(L) = M_t w..(L) = -M_t omega^2 w(L)
    om2 = beam.frequencies(1.0) ** 2
    d2, d3 = beam.shape([1.7], 2)[:, 0], beam.shape([1.7], 3)[:, 0]
    s2, s3 = np.max(np.abs(beam.shape(x, 2)), axis=1), np.max(np.abs(beam.shape(x, 3)), axis=1)
    assert np.max(np.abs(d2) / s2) < 1e-12
    assert np.max(np.abs(d3 + tip_mass * om2 * tip) / s3) < 1e-12


@pytest.mark.parametrize("stiffening", [True, False])
def test_hub_locked_frequencies_equal_clamped_free_closed_form(stiffening):
    L, m, EI = 2.0, 0.5, (10.0, 17.0)
    part = FlexibleAppendage(L, m, EI, root=(0.6, 0.2, -0.1), direction=(0.0, 0.6, 0.8),
                             modes=4, stiffening=stiffening)
    scene = Scene(RigidHub(LOCKED), part)
    model = scene.model()
    lin = linearization(model, scene.state(), frame="rates")
    for plane, ei in zip(("eta", "xi"), EI):
        names = [f"{plane}{i}" for i in range(1, 5)] + [f"{plane}{i}_dot" for i in range(1, 5)]
        expected = TEXTBOOK[:4] ** 2 * np.sqrt(ei / (m * L ** 4))
        assert np.max(np.abs(_freqs(lin, names) / expected - 1)) < 1e-8


def _fe_rotating_beam(L, m, EI, r0, tip_mass, rate, *, elements=80, in_plane=False):
    """First natural frequency [rad/s] of a rotating cantilever by Euler-Bernoulli Hermite
    elements with the centrifugal tension's geometric stiffness (and the in-plane -rate^2 M
    term): an independent reference."""
    ndof = 2 * (elements + 1)
    K, M = np.zeros((ndof, ndof)), np.zeros((ndof, ndof))
    h = L / elements
    t, w = np.polynomial.legendre.leggauss(6)
    for e in range(elements):
        x0 = e * h
        ke = EI / h ** 3 * np.array([[12, 6 * h, -12, 6 * h], [6 * h, 4 * h * h, -6 * h, 2 * h * h],
                                     [-12, -6 * h, 12, -6 * h], [6 * h, 2 * h * h, -6 * h, 4 * h * h]])
        me, kg = np.zeros((4, 4)), np.zeros((4, 4))
        for ti, wi in zip(t, w):
            s = 0.5 * (ti + 1.0)
            N = np.array([1 - 3 * s ** 2 + 2 * s ** 3, h * (s - 2 * s ** 2 + s ** 3),
                          3 * s ** 2 - 2 * s ** 3, h * (-s ** 2 + s ** 3)])
            dN = np.array([-6 * s + 6 * s ** 2, h * (1 - 4 * s + 3 * s ** 2),
                           6 * s - 6 * s ** 2, h * (-2 * s + 3 * s ** 2)]) / h
            x = x0 + s * h
            T = rate ** 2 * (m * (r0 * (L - x) + 0.5 * (L ** 2 - x ** 2)) + tip_mass * (r0 + L))
            me += 0.5 * h * wi * m * np.outer(N, N)
            kg += 0.5 * h * wi * T * np.outer(dN, dN)
        sl = slice(2 * e, 2 * e + 4)
        K[sl, sl] += ke + kg
        M[sl, sl] += me
    M[-2, -2] += tip_mass
    if in_plane:
        K -= rate ** 2 * M
    K, M = K[2:, 2:], M[2:, 2:]
    lam = np.linalg.eigvals(np.linalg.solve(M, K)).real
    return float(np.sqrt(np.min(lam)))


@pytest.mark.parametrize("tip_mass", [0.0, 0.3])
@pytest.mark.slow
def test_spinning_frequencies_match_finite_element_rotating_beam(tip_mass):
    L, m, EI, r0, n = 2.0, 0.5, 10.0, 0.7, 8  # 6 modes: 1.6e-4 at 2 omega_1
    part = FlexibleAppendage(L, m, EI, root=(r0, 0.0, 0.0), modes=n, tip_mass=tip_mass)
    assert np.allclose(part.normal, [0, 1, 0]) and np.allclose(part.binormal, [0, 0, 1])
    scene = Scene(RigidHub(LOCKED), part)
    model = scene.model()
    w1 = part.frequencies()[0, 0]
    eta = [f"eta{i}" for i in range(1, n + 1)] + [f"eta{i}_dot" for i in range(1, n + 1)]
    xi = [f"xi{i}" for i in range(1, n + 1)] + [f"xi{i}_dot" for i in range(1, n + 1)]
    for rate in np.linspace(0.0, 2.0 * w1, 5):
        lin = linearization(model, scene.state(w=[0.0, 0.0, rate]), frame="rates")
        f_in, f_out = _freqs(lin, eta)[0], _freqs(lin, xi)[0]
        fe_in = _fe_rotating_beam(L, m, EI, r0, tip_mass, rate, in_plane=True)
        fe_out = _fe_rotating_beam(L, m, EI, r0, tip_mass, rate)
        assert abs(f_out / fe_out - 1) < 1e-4, (rate, f_out, fe_out)
        assert abs(f_in / fe_in - 1) < 1e-4, (rate, f_in, fe_in)
        # in plane: the squared frequency is offset by -rate^2 (the same stiffened beam)
        assert abs(f_out ** 2 - f_in ** 2 - rate ** 2) < 1e-9 * f_out ** 2
        assert f_out > w1 or rate == 0.0  # stiffened


def test_linear_model_softens_under_spin():
    """Without stiffening the in-plane frequency is sqrt(omega^2 - rate^2): it diverges."""
    part = FlexibleAppendage(2.0, 0.5, 10.0, root=(0.7, 0, 0), modes=1, stiffening=False)
    scene = Scene(RigidHub(LOCKED), part)
    w1 = part.frequencies()[0, 0]
    lin = linearization(scene.model(), scene.state(w=[0, 0, 0.5 * w1]), frame="rates")
    assert abs(_freqs(lin, ["eta1", "eta1_dot"])[0] / (w1 * np.sqrt(0.75)) - 1) < 1e-9
    assert abs(_freqs(lin, ["xi1", "xi1_dot"])[0] / w1 - 1) < 1e-9


@pytest.mark.parametrize("stiffening", [True, False])
@pytest.mark.parametrize("mass", [None, 20.0])
@pytest.mark.slow
def test_momentum_and_energy_conserved(stiffening, mass):
    part = FlexibleAppendage(2.0, 0.5, (0.5, 0.8), root=(0.5, 0.1, -0.2),
                             direction=(1.0, 0.2, 0.3), modes=2, tip_mass=0.3,
                             stiffening=stiffening)
    hub = RigidHub([[10.0, 1.2, -0.8], [1.2, 12.0, 0.6], [-0.8, 0.6, 8.0]], mass=mass,
                   reference=None if mass is None else [0.1, -0.05, 0.2])
    scene = Scene(hub, part)
    model = scene.model()
    rng = np.random.default_rng(3)
    x0 = scene.state(w=[0.3, -0.2, 0.5])
    lay = model.layout[scene.part_names[0]]
    x0[lay.states] = rng.normal(scale=0.2, size=lay.states.stop - lay.states.start)
    if mass:
        x0[7:13] = rng.normal(scale=0.5, size=6)
    t = np.linspace(0.0, 100.0, 11)
    res = simulate(model, x0, t, method="rk8", steps=2000, jit=False)
    assert res.success, res.message
    keys = ["energy", "momentum_inertial"] + (["momentum_linear"] if mass else [])
    for key in keys:
        v = np.asarray(model.invariant(key, res.x)).reshape(-1, t.size)
        drift = np.max(np.abs(v - v[:, :1])) / np.max(np.abs(v))
        assert drift < 1e-10, (key, drift)


def test_bad_input_names_the_argument():
    with pytest.raises(ValueError, match="normal"):
        FlexibleAppendage(1.0, 1.0, 1.0, normal=(1.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="bending_stiffness"):
        FlexibleAppendage(1.0, 1.0, (1.0, -1.0))
    with pytest.raises(ValueError, match="modes"):
        FlexibleAppendage(1.0, 1.0, 1.0, modes=0)
    with pytest.raises(ValueError, match="length"):
        FlexibleAppendage(-1.0, 1.0, 1.0)


@pytest.mark.slow
def test_seed_example6_hub_locked_limit_gives_cantilever_frequencies():
    from appdyn.dynamics.scene import flexible_antenna_satellite
    from appdyn.problems import stability
    L, m, EI = 3.0, 0.2, (20.0, 35.0)
    sat = flexible_antenna_satellite(np.diag([1e12, 1e12, 1e12]), L, m, EI, hub_radius=0.8,
                                     modes=2)
    rep = stability.spin(sat, [0, 0, 1], 0.0)   # rate 0 allowed
    found = np.sort(rep.eigenvalues.imag[rep.eigenvalues.imag > 1e-6])
    cantilever = np.sort(np.concatenate([TEXTBOOK[:2] ** 2 * np.sqrt(ei / (m * L ** 4))
                                         for ei in EI] * 4))
    assert np.max(np.abs(found / cantilever - 1)) < 1e-8
    flex = [md for md in rep.modes if md.wn > 1e-6]
    # in plane (eta, along spin x direction) at EI[0], out of plane (xi) at EI[1]
    for md in flex:
        coord = md.label.split(": ")[1]
        ei = EI[0] if coord.startswith("eta") else EI[1]
        k = int(coord[3 if coord.startswith("eta") else 2])
        assert abs(md.wn / (TEXTBOOK[k - 1] ** 2 * np.sqrt(ei / (m * L ** 4))) - 1) < 1e-8


@pytest.mark.slow
def test_seed_example6_spinning_stiffens_and_stays_stable():
    from appdyn.dynamics.scene import flexible_antenna_satellite
    from appdyn.problems import stability
    sat = flexible_antenna_satellite([300.0, 300.0, 500.0], 3.0, 0.2, 20.0, hub_radius=0.8,
                                     modes=2)
    w1 = sat.parts[0].frequencies()[0, 0]
    rep = stability.spin(sat, [0, 0, 1], 2.0)
    assert rep.verdict == "marginally stable"
    out = [md.wn for md in rep.modes if ": xi1" in md.label]
    assert out and min(out) > w1   # the out-of-plane bending is stiffened by the spin


def test_parent_is_a_field_and_must_be_a_name():
    part = FlexibleAppendage(1.0, 1.0, 1.0, parent="panel")
    assert part.parent == "panel" and FlexibleAppendage(1.0, 1.0, 1.0).parent is None
    with pytest.raises(TypeError, match="parent"):
        FlexibleAppendage(1.0, 1.0, 1.0, parent=3)


def test_default_normal_is_perpendicular_and_right_handed_planes():
    rng = np.random.default_rng(0)
    for _ in range(20):
        d = rng.normal(size=3)
        part = FlexibleAppendage(1.0, 1.0, 1.0, direction=d, modes=1)
        n, b, dd = map(np.asarray, (part.normal, part.binormal, part.direction))
        assert abs(n @ dd) < 1e-15 and abs(np.linalg.norm(n) - 1) < 1e-15
        assert np.allclose(np.cross(dd, n), b, atol=1e-15)


def _textbook_shapes(x, L, m, roots):
    """Clamped-free shapes from the textbook formula, normalized by their own quadrature."""
    b = np.asarray(roots)[:, None] / L
    sig = (np.cosh(roots) + np.cos(roots)) / (np.sinh(roots) + np.sin(roots))
    phi = np.cosh(b * x) - np.cos(b * x) - sig[:, None] * (np.sinh(b * x) - np.sin(b * x))
    xs, ws = np.polynomial.legendre.leggauss(200)
    xs, ws = 0.5 * L * (xs + 1), 0.5 * L * ws
    ref = np.cosh(b * xs) - np.cos(b * xs) - sig[:, None] * (np.sinh(b * xs) - np.sin(b * xs))
    return phi / np.sqrt(m * (ref ** 2) @ ws)[:, None]


def test_seed_example6_in_plane_modes_coupled_with_the_hub():
    """At rate 0 the in-plane bending couples with the hub's rotation about the spin axis:
    ``[[I, b^T], [b, E]] q.. + diag(0, Omega^2) q = 0`` per antenna, ``b_i = int m (r + x)
    phi_i`` (textbook shapes, own quadrature); the symmetric scene's frequencies hold them."""
    from appdyn.dynamics.scene import flexible_antenna_satellite
    from appdyn.problems import stability
    L, m, EI, r, Iz, n = 3.0, 0.2, 20.0, 0.8, 500.0, 2
    sat = flexible_antenna_satellite([300.0, 300.0, Iz], L, m, EI, hub_radius=r, modes=n)
    found = stability.spin(sat, [0, 0, 1], 0.0).eigenvalues
    xs, ws = np.polynomial.legendre.leggauss(200)
    xs, ws = 0.5 * L * (xs + 1), 0.5 * L * ws
    phi = _textbook_shapes(xs, L, m, TEXTBOOK[:n])
    b = m * phi @ (ws * (r + xs))
    I_tot = Iz + 4 * m * ws @ (r + xs) ** 2
    om2 = TEXTBOOK[:n] ** 4 * EI / (m * L ** 4)
    M = np.eye(1 + 4 * n)
    M[0, 0] = I_tot
    M[0, 1:] = M[1:, 0] = np.tile(b, 4)
    K = np.diag(np.r_[0.0, np.tile(om2, 4)])
    lam = np.sort(np.linalg.eigvals(np.linalg.solve(M, K)).real)[1:]  # without the rigid 0
    expected = np.sqrt(lam)
    for f in expected:
        assert np.min(np.abs(found.imag - f)) < 1e-9 * f, f
    # n of them (all antennas bending alike, the hub turning against them) are stiffer than
    # the cantilever's; the other 3 n are the cantilever's
    stiffer = expected[np.min(np.abs(expected[:, None] - np.sqrt(om2)[None, :]), axis=1)
                       > 1e-6 * expected]
    assert stiffer.size == n and np.all(stiffer > np.sqrt(om2))


@pytest.mark.slow
def test_on_a_locked_hinged_boom_it_is_the_same_beam_as_on_the_hub():
    """Parts on parts: the appendage clamped on a panel (root and direction in panel axes,
    from the hinge) that a very heavy, very stiff hinge holds at zero angle: locked, its
    frequencies are the cantilever's; spinning, those of the same beam clamped on the hub at
    hinge + root (the centrifugal stiffening depends on that radius)."""
    from appdyn.dynamics.scene import HingedPanel
    L, m, EI = 2.0, 0.5, (10.0, 17.0)
    boom = HingedPanel(1e12, [1e12, 1e12, 1e12], hinge_point=[0.0, 0.5, 0.0],
                       cm_offset=[0.0, 0.5, 0.0], axis=[1.0, 0.0, 0.0], stiffness=1e16,
                       name="boom")
    on_boom = Scene(RigidHub(LOCKED), boom,
                    FlexibleAppendage(L, m, EI, root=(0.0, 1.0, 0.0), direction=(0.0, 1.0, 0.0),
                                      modes=3, parent="boom"))
    on_hub = Scene(RigidHub(LOCKED),
                   FlexibleAppendage(L, m, EI, root=(0.0, 1.5, 0.0), direction=(0.0, 1.0, 0.0),
                                     modes=3))
    names = {p: [f"{p}{i}" for i in range(1, 4)] + [f"{p}{i}_dot" for i in range(1, 4)]
             for p in ("eta", "xi")}
    for rate in (0.0, 5.0):
        a, b = (linearization(s.model(), s.state(w=[0.0, 0.0, rate]), frame="rates")
                for s in (on_boom, on_hub))
        for plane, ei in zip(("eta", "xi"), EI):
            fa, fb = _freqs(a, names[plane]), _freqs(b, names[plane])
            assert np.max(np.abs(fa / fb - 1)) < 1e-9
            if rate == 0.0:
                expected = TEXTBOOK[:3] ** 2 * np.sqrt(ei / (m * L ** 4))
                assert np.max(np.abs(fa / expected - 1)) < 1e-8
            else:
                assert fa[0] > TEXTBOOK[0] ** 2 * np.sqrt(ei / (m * L ** 4)) * 1.05


# ------------------------------------------------------------------ a user's shape table
def test_polynomial_shape_table_gives_the_two_term_ritz_frequencies():
    """Shapes x^2, x^3 (exact for the spline): the Ritz eigenproblem of their exact
    integrals, M = m L [[1/5, 1/6], [1/6, 1/7]], K = EI / L^3 [[4, 6], [6, 12]]."""
    L, m, EI = 2.0, 0.5, 10.0
    x = np.linspace(0.0, L, 9)
    part = FlexibleAppendage(L, m, EI, shapes=(x, np.column_stack([x ** 2, x ** 3])),
                             root=(0.5, 0.0, 0.0))
    assert part.modes == 2
    M = m * L * np.array([[1 / 5, 1 / 6], [1 / 6, 1 / 7]])
    K = EI / L ** 3 * np.array([[4.0, 6.0], [6.0, 12.0]])
    expected = np.sqrt(np.sort(np.linalg.eigvals(np.linalg.solve(M, K)).real))
    assert np.max(np.abs(part.frequencies()[0] / expected - 1)) < 1e-12
    scene = Scene(RigidHub(LOCKED), part)
    lin = linearization(scene.model(), scene.state(), frame="rates")
    names = ["eta1", "eta2", "eta1_dot", "eta2_dot"]
    assert np.max(np.abs(_freqs(lin, names) / expected - 1)) < 1e-8


@pytest.mark.slow
def test_a_sampled_clamped_free_table_is_the_computed_beam():
    """The library's own shapes, tabulated at 401 stations, give the same beam: frequencies
    to 1e-8 (the cubic spline's error), spinning frequencies to 1e-6."""
    L, m, EI, n = 2.0, 0.5, 10.0, 3
    x = np.linspace(0.0, L, 401)
    table = ClampedFreeModes(L, m, n, 0.2).shape(x).T * np.array([1.0, -3.0, 0.5])
    given = FlexibleAppendage(L, m, EI, root=(0.7, 0, 0), modes=n, tip_mass=0.2)
    tabulated = FlexibleAppendage(L, m, EI, root=(0.7, 0, 0), tip_mass=0.2, shapes=(x, table))
    assert np.max(np.abs(tabulated.frequencies() / given.frequencies() - 1)) < 1e-8
    rate = 1.5 * given.frequencies()[0, 0]
    eta = [f"eta{i}" for i in range(1, n + 1)] + [f"eta{i}_dot" for i in range(1, n + 1)]
    f = []
    for part in (given, tabulated):
        scene = Scene(RigidHub(LOCKED), part)
        lin = linearization(scene.model(), scene.state(w=[0, 0, rate]), frame="rates")
        f.append(_freqs(lin, eta))
    assert np.max(np.abs(f[1] / f[0] - 1)) < 1e-6


@pytest.mark.slow
def test_a_shape_table_conserves_momentum_and_energy():
    x = np.linspace(0.0, 1.5, 7)
    part = FlexibleAppendage(1.5, 0.4, (0.6, 0.9), root=(0.4, 0.1, 0.0),
                             shapes=(x, np.column_stack([x ** 2, x ** 3 - x ** 2])))
    scene = Scene(RigidHub([[10.0, 1.2, -0.8], [1.2, 12.0, 0.6], [-0.8, 0.6, 8.0]]), part)
    model = scene.model()
    x0 = scene.state(w=[0.3, -0.2, 0.5], eta1=0.05, xi2_dot=0.1)
    t = np.linspace(0.0, 100.0, 11)
    res = simulate(model, x0, t, method="rk8", steps=2000, jit=False)
    assert res.success, res.message
    for key in ("energy", "momentum_inertial"):
        v = np.asarray(model.invariant(key, res.x)).reshape(-1, t.size)
        assert np.max(np.abs(v - v[:, :1])) / np.max(np.abs(v)) < 1e-10, key


def test_bad_shape_tables_name_the_argument():
    x = np.linspace(0.0, 2.0, 6)
    with pytest.raises(ValueError, match="`shapes` must be zero at the clamped root"):
        FlexibleAppendage(2.0, 0.5, 10.0, shapes=(x, np.column_stack([x + 1.0])))
    with pytest.raises(ValueError, match="`x` must increase from 0 to `length`"):
        FlexibleAppendage(2.0, 0.5, 10.0, shapes=(x[:-1], np.column_stack([x[:-1] ** 2])))
    with pytest.raises(ValueError, match="linearly independent"):
        FlexibleAppendage(2.0, 0.5, 10.0, shapes=(x, np.column_stack([x ** 2, 2 * x ** 2])))
    with pytest.raises(TypeError, match="`shapes` must be a pair"):
        FlexibleAppendage(2.0, 0.5, 10.0, shapes=x)
