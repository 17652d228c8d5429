"""rockit peer: the literature cases of bench/literature.py and the Bilimoria-Wie slew;
runs in bench/peers/.venv-rockit (``bash bench/peers/setup_rockit.sh``).

The problems as `appdyn.ocp.examples.orbit_raising`, `shuttle_reentry` and bench/slew.py's
Bilimoria-Wie slew state them, written in rockit (rockit-meco; our code): DirectCollocation
(rockit's default, Radau degree 4 per interval) with ``N`` intervals, IPOPT with MUMPS, the
same starts as appdyn (orbit raising: rockit's own, zeros, with ``ut = 1``; reentry: ASSET's
straight line over 1000 s). The slew: ``bilimoria_wie`` from the start a rockit user writes
(``set_initial``: a constant-rate turn about z over ``T = 3.5`` s), ``bilimoria_wie_own``
from rockit's own (zeros, ``T = 3.5``: on a loaded machine 1601 IPOPT iterations, 225 s at
N = 40), ``bilimoria_wie_tilted`` from the user's start times a turn about x by
``sin(pi t / 3.5)`` rad (as appdyn's tilted starts: off the eigenaxis local optimum).

Usage (from the project root)::

    bench/peers/.venv-rockit/bin/python bench/peers/rockit_literature.py --json
        --case orbit_raising|reentry|bilimoria_wie[_own|_tilted] [--N 20 40] [--repeats 1]

prints ``{"rockit", "casadi", "case", "runs": [...]}``, one run per ``N`` with
``objective`` (orbit raising: r_f; reentry: theta_f [deg]; slew: T [s]), ``build_time``
(the problem stated and transcribed), ``solve_time`` (``solve()``, median of the repeats),
``first_solve_time``, ``iterations``, ``status``.
"""
from __future__ import annotations

import time
from importlib.metadata import version

import numpy as np

from _runner import main, repeated


def orbit_raising(ca, rk, N):
    ocp = rk.Ocp(T=3.32)
    r, vr, vt, m = ocp.state(), ocp.state(), ocp.state(), ocp.state()
    ur, ut = ocp.control(), ocp.control()
    ocp.set_der(r, vr)
    ocp.set_der(vr, vt**2 / r - 1 / r**2 + 0.1405 * ur / m)
    ocp.set_der(vt, -vr * vt / r + 0.1405 * ut / m)
    ocp.set_der(m, -0.0749 + 0 * m)
    ocp.subject_to(ur**2 + ut**2 == 1)
    ocp.subject_to(ocp.at_t0(ca.vertcat(r, vr, vt, m)) == ca.vertcat(1, 0, 1, 1))
    ocp.subject_to(ocp.at_tf(vr) == 0)
    ocp.subject_to(ocp.at_tf(vt) == 1 / ca.sqrt(ocp.at_tf(r)))
    ocp.subject_to(0.5 <= (r <= 5))
    ocp.subject_to(0.1 <= (m <= 1))
    ocp.set_initial(r, 1)
    ocp.set_initial(vt, 1)
    ocp.set_initial(m, 1)
    ocp.set_initial(ut, 1)
    ocp.add_objective(-ocp.at_tf(r))
    return ocp, lambda sol: float(sol.value(ocp.at_tf(r)))


def reentry(ca, rk, N):
    L, T_ = 1.0e5, 60.0
    m_star = 203000.0 / 32.2
    re, area, mu = 20902900.0 / L, 2690.0 / L**2, 0.140765e17 / (L**3 / T_**2)
    rho0, h_ref = 0.002378 / (m_star / L**3), 23800.0 / L
    ocp = rk.Ocp(T=rk.FreeTime(1000.0 / T_))
    h, theta, v, gamma, psi = (ocp.state() for _ in range(5))
    alpha, beta = ocp.control(), ocp.control()
    a = alpha * 180 / np.pi
    cl = -0.20704 + 0.029244 * a
    cd = 0.07854 - 0.61592e-2 * a + 0.621408e-3 * a**2
    q = 0.5 * rho0 * ca.exp(-h / h_ref) * v**2 * area
    r = h + re
    g = mu / r**2
    ocp.set_der(h, v * ca.sin(gamma))
    ocp.set_der(theta, v / r * ca.cos(gamma) * ca.cos(psi))
    ocp.set_der(v, -cd * q - g * ca.sin(gamma))
    ocp.set_der(gamma, cl * q / v * ca.cos(beta) + ca.cos(gamma) * (v / r - g / v))
    ocp.set_der(psi, cl * q * ca.sin(beta) / (v * ca.cos(gamma))
                + v / r * ca.cos(gamma) * ca.sin(psi) * ca.tan(theta))
    v_star = L / T_
    start = [260000.0 / L, 0.0, 25600.0 / v_star, np.radians(-1.0), np.radians(90.0)]
    end = [80000.0 / L, 2500.0 / v_star, np.radians(-5.0)]
    ocp.subject_to(ocp.at_t0(ca.vertcat(h, theta, v, gamma, psi)) == ca.vertcat(*start))
    ocp.subject_to(ocp.at_tf(ca.vertcat(h, v, gamma)) == ca.vertcat(*end))
    lim = np.radians(89.0)
    ocp.subject_to(-lim <= (theta <= lim))
    ocp.subject_to(-lim <= (gamma <= lim))
    ocp.subject_to(-np.pi / 2 <= (alpha <= np.pi / 2))
    ocp.subject_to(-np.pi / 2 <= (beta <= np.radians(1.0)))
    ocp.subject_to(0.1 <= (ocp.T <= 2500.0 / T_))
    f = ocp.t / (1000.0 / T_)
    ocp.set_initial(h, start[0] + f * (end[0] - start[0]))
    ocp.set_initial(v, start[2] + f * (end[1] - start[2]))
    ocp.set_initial(gamma, start[3] + f * (end[2] - start[3]))
    ocp.set_initial(psi, start[4])
    ocp.add_objective(-ocp.at_tf(theta))
    return ocp, lambda sol: float(np.degrees(sol.value(ocp.at_tf(theta))))


def bilimoria_wie(ca, rk, N, start="eigenaxis"):
    ocp = rk.Ocp(T=rk.FreeTime(3.5))
    q, w, u = ocp.state(4), ocp.state(3), ocp.control(3)
    qv, q4 = q[:3], q[3]
    ocp.set_der(q, 0.5 * ca.vertcat(q4 * w + ca.cross(qv, w), -ca.dot(qv, w)))
    ocp.set_der(w, u)
    ocp.subject_to(-1 <= (u <= 1))
    ocp.subject_to(ocp.at_t0(q) == ca.vertcat(0, 0, 0, 1))
    ocp.subject_to(ocp.at_t0(w) == 0)
    ocp.subject_to(ocp.at_tf(q) == ca.vertcat(0, 0, 1, 0))
    ocp.subject_to(ocp.at_tf(w) == 0)
    if start != "own":
        # what a rockit user writes (rockit's set_initial with an expression of ocp.t): the
        # attitude turning at a constant rate about z over the guessed T = 3.5 s
        angle = np.pi * ocp.t / 3.5
        qz = ca.vertcat(0, 0, ca.sin(angle / 2), ca.cos(angle / 2))
        if start == "tilted":  # times a turn about x by sin(pi t / T) rad, 0 at both ends
            b = ca.sin(np.pi * ocp.t / 3.5) / 2
            qz = ca.vertcat(qz[3] * ca.sin(b), qz[2] * ca.sin(b), qz[2] * ca.cos(b),
                            qz[3] * ca.cos(b))
        ocp.set_initial(q, qz)
        ocp.set_initial(w, ca.vertcat(0, 0, np.pi / 3.5))
    ocp.add_objective(ocp.T)
    return ocp, lambda sol: float(sol.value(ocp.T))


def bilimoria_wie_own(ca, rk, N):
    """The slew from rockit's own start (zeros; T = 3.5 s)."""
    return bilimoria_wie(ca, rk, N, start="own")


def bilimoria_wie_tilted(ca, rk, N):
    """The slew from the user's start tilted off the eigenaxis (as appdyn's seeded starts)."""
    return bilimoria_wie(ca, rk, N, start="tilted")


CASES = {"orbit_raising": orbit_raising, "reentry": reentry, "bilimoria_wie": bilimoria_wie,
         "bilimoria_wie_own": bilimoria_wie_own, "bilimoria_wie_tilted": bilimoria_wie_tilted}


def run_one(case: str, N: int) -> dict:
    import casadi as ca
    import rockit as rk

    t0 = time.perf_counter()
    ocp, objective = CASES[case](ca, rk, N)
    ocp.solver("ipopt", {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes"})
    ocp.method(rk.DirectCollocation(N=N))
    t1 = time.perf_counter()
    try:
        sol = ocp.solve()
        stats, value = sol.stats, objective(sol)
    except RuntimeError:  # rockit raises on an IPOPT failure
        stats, value = ocp._method.opti.stats(), float("nan")
    t2 = time.perf_counter()
    return {"N": N, "objective": value, "build_time": t1 - t0, "solve_time": t2 - t1,
            "iterations": int(stats.get("iter_count", -1)),
            "status": str(stats.get("return_status", "?"))}


def run(args) -> dict:
    import casadi

    runs = repeated(lambda n: run_one(args.case, n), args.sizes, args.repeats)
    return {"rockit": version("rockit-meco"), "casadi": casadi.__version__, "case": args.case,
            "runs": runs}


def _case(ap) -> None:
    ap.add_argument("--case", choices=sorted(CASES), required=True)


if __name__ == "__main__":
    main(__doc__, run, "--N", [20, 40], _case, repeats=1)
