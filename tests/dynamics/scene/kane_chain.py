"""A sympy.mechanics Kane model of parts on parts (test-only): a hub turning about its fixed
mass centre carries a revolute panel; the panel carries a reaction wheel and a second revolute
panel; the second panel carries a sliding spring mass. The independent formulation
`test_parts_on_parts` checks the scene against.

Every panel frame is oriented by ``orient_axis`` (a positive rotation of the frame about the
hinge axis, as `dynamics.attitude.dcm_from_axis_angle`); points of a panel are given from its
hinge in its axes. Generalized speeds: the hub rate (hub axes), the hinge rates, the wheel's
speed relative to its panel and the spring mass's sliding rate.
"""
import numpy as np
import sympy as sp
from sympy.physics import mechanics as me


def _vec(frame, c):
    return sum((float(c[i]) * e for i, e in enumerate((frame.x, frame.y, frame.z))),
               me.Vector(0))


def _dyadic(frame, inertia):
    I = np.asarray(inertia, float).reshape(3, 3)
    axes = (frame.x, frame.y, frame.z)
    return sum((float(I[i, j]) * me.outer(axes[i], axes[j]) for i in range(3)
                for j in range(3)), me.Dyadic(0))


def _panel(label, N, parent, origin, spec, angle, rate):
    """A revolute panel on ``parent`` (hinge from ``origin``): frame, axis, hinge, body."""
    P = me.ReferenceFrame("P" + label)
    a = _vec(parent, spec["axis"])
    P.orient_axis(parent, a, angle)
    P.set_ang_vel(parent, rate * a)
    H = origin.locatenew("H" + label, _vec(parent, spec["hinge"]))
    H.v2pt_theory(origin, N, parent)
    C = H.locatenew("C" + label, _vec(P, spec["cm"]))
    C.v2pt_theory(H, N, P)
    return P, a, H, me.RigidBody("p" + label, C, P, spec["mass"], (_dyadic(P, spec["inertia"]), C))


def chain_equations(hub_inertia, panel1, wheel, panel2, damper):
    """``f(th1, th2, s, w, th1d, th2d, W, sd, tau) -> (w', th1'', th2'', W', s'')``.

    ``panel1``, ``panel2``: dicts with ``mass, inertia (3, 3), hinge, cm, axis, k``;
    ``wheel``: ``axis, J``; ``damper``: ``mass, k, position, direction``.
    """
    th1, th2, s = me.dynamicsymbols("th1 th2 s")
    u = me.dynamicsymbols("u1:8")
    tau = sp.Symbol("tau")
    N, B = me.ReferenceFrame("N"), me.ReferenceFrame("B")
    B.set_ang_vel(N, u[0] * B.x + u[1] * B.y + u[2] * B.z)
    O = me.Point("O")
    O.set_vel(N, 0)
    hub = me.RigidBody("hub", O, B, 0, (_dyadic(B, hub_inertia), O))

    P1, a1, H1, body1 = _panel("1", N, B, O, panel1, th1, u[3])

    Wf = me.ReferenceFrame("Wf")
    b = _vec(P1, wheel["axis"])
    Wf.set_ang_vel(P1, u[5] * b)
    rotor = me.RigidBody("w", H1, Wf, 0, (wheel["J"] * me.outer(b, b), H1))

    P2, a2, H2, body2 = _panel("2", N, P1, H1, panel2, th2, u[4])

    d = _vec(P2, damper["direction"])
    r_d = _vec(P2, damper["position"]) + s * d
    D = H2.locatenew("D", r_d)
    D.set_vel(P2, u[6] * d)
    D.v1pt_theory(H2, N, P2)
    Dc = H2.locatenew("Dc", r_d)  # the panel point the mass passes
    Dc.v2pt_theory(H2, N, P2)
    mass = me.Particle("m", D, damper["mass"])

    f_d = -damper["k"] * s * d
    loads = [(Wf, tau * b), (P1, -tau * b),
             (P1, -panel1["k"] * th1 * a1), (B, panel1["k"] * th1 * a1),
             (P2, -panel2["k"] * th2 * a2), (P1, panel2["k"] * th2 * a2),
             (D, f_d), (Dc, -f_d)]
    kane = me.KanesMethod(N, q_ind=[th1, th2, s], u_ind=u,
                          kd_eqs=[th1.diff() - u[3], th2.diff() - u[4], s.diff() - u[6]])
    kane.kanes_equations([hub, body1, rotor, body2, mass], loads)
    args = [th1, th2, s] + list(u) + [tau]
    Mf = sp.lambdify(args, kane.mass_matrix, "numpy")
    ff = sp.lambdify(args, kane.forcing, "numpy")

    def rates(th1_, th2_, s_, w, th1d, th2d, W, sd, tau_):
        a = [th1_, th2_, s_, *w, th1d, th2d, W, sd, tau_]
        return np.linalg.solve(np.array(Mf(*a), float), np.array(ff(*a), float).ravel())

    return rates
