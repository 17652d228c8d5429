"""A sympy.mechanics Kane model of a free hub carrying a slosh pendulum and a slosh spring
(test-only): the independent formulation `test_dampers` checks the scene against.

The hub (mass ``M``, inertia about its mass centre ``G``) has its reference point ``O`` at
``reference`` from ``G``; generalized speeds: the hub rate ``w`` and ``O``'s velocity ``v``
(hub components), the pendulum angle rates and the spring's ``s'``. The spring force acts on
the mass and, reversed, on the hub point it passes; a force ``F`` (hub components) acts at
``point``; the hinge damping is the generalized force ``-c theta_i'``.
"""
import numpy as np
import sympy as sp
from sympy.physics import mechanics as me


def slosh_hub_equations(inertia, M, reference, point, pendulum, spring):
    """``f(w, v, th, thd, s, sd, F) -> (w', v', th'', s'')`` as a numpy function.

    Parameters
    ----------
    inertia : (3, 3) array [kg m^2]
    M : float [kg]
    reference, point : (3,) [m] from the hub's mass centre
    pendulum : Slosh (kind 'pendulum'), spring : Slosh (kind 'spring')
    """
    q1, q2, q3, t1, t2, s = me.dynamicsymbols("q1 q2 q3 t1 t2 s")
    u = me.dynamicsymbols("u1:10")
    F = sp.symbols("F1:4")
    N = me.ReferenceFrame("N")
    B = me.ReferenceFrame("B")
    B.orient_body_fixed(N, (q1, q2, q3), "123")
    wq = B.ang_vel_in(N)
    kd = [wq.dot(B.x) - u[0], wq.dot(B.y) - u[1], wq.dot(B.z) - u[2],
          t1.diff() - u[6], t2.diff() - u[7], s.diff() - u[8]]
    B.set_ang_vel(N, u[0] * B.x + u[1] * B.y + u[2] * B.z)

    def vec(c):
        return float(c[0]) * B.x + float(c[1]) * B.y + float(c[2]) * B.z

    ref = np.asarray(reference, float)
    O = me.Point("O")
    O.set_vel(N, u[3] * B.x + u[4] * B.y + u[5] * B.z)
    G = O.locatenew("G", vec(-ref))
    G.v2pt_theory(O, N, B)
    I = np.asarray(inertia, float)
    dyad = sum((float(I[i, j]) * me.outer(b_i, b_j) for i, b_i in enumerate((B.x, B.y, B.z))
                for j, b_j in enumerate((B.x, B.y, B.z))), me.Dyadic(0))
    hub = me.RigidBody("hub", G, B, M, (dyad, G))

    R = pendulum.rod_basis()
    e_loc = [sp.cos(t2) * sp.cos(t1), sp.cos(t2) * sp.sin(t1), sp.sin(t2)]
    e = sum((sum(float(R[i, k]) * e_loc[k] for k in range(3)) * b_i
             for i, b_i in enumerate((B.x, B.y, B.z))), me.Vector(0))
    r_p = vec(np.asarray(pendulum.hinge) - ref) + pendulum.length * e
    P = O.locatenew("P", r_p)
    P.set_vel(B, r_p.dt(B))
    P.v1pt_theory(O, N, B)
    r_s = vec(np.asarray(spring.position) - ref) + s * vec(spring.direction)
    S = O.locatenew("S", r_s)
    S.set_vel(B, r_s.dt(B))
    S.v1pt_theory(O, N, B)
    Sc = O.locatenew("Sc", r_s)  # the hub point the spring mass passes
    Sc.v2pt_theory(O, N, B)
    Fp = O.locatenew("Fp", vec(np.asarray(point) - ref))
    Fp.v2pt_theory(O, N, B)

    f_s = (-spring.stiffness * s - spring.damping * u[8]) * vec(spring.direction)
    loads = [(Fp, F[0] * B.x + F[1] * B.y + F[2] * B.z), (S, f_s), (Sc, -f_s)]
    bodies = [hub, me.Particle("pm", P, pendulum.mass), me.Particle("sm", S, spring.mass)]
    kane = me.KanesMethod(N, q_ind=[q1, q2, q3, t1, t2, s], u_ind=u, kd_eqs=kd)
    kane.kanes_equations(bodies, loads)
    MM, ff = kane.mass_matrix, kane.forcing
    ff = ff + sp.Matrix([0] * 6 + [-pendulum.damping * u[6], -pendulum.damping * u[7], 0])
    args = [t1, t2, s] + list(u) + list(F)
    Mf, ffun = sp.lambdify(args, MM, "numpy"), sp.lambdify(args, ff, "numpy")

    def rates(w, v, th, thd, s_, sd, force):
        a = [th[0], th[1], s_, *w, *v, thd[0], thd[1], sd, *force]
        return np.linalg.solve(np.array(Mf(*a), float), np.array(ffun(*a), float).ravel())

    return rates
