"""Butcher tableaux of the explicit fixed-step methods, and the stage nodes of every method.

A method here is data only: `Tableau` (``a``, ``b``, ``c``, order); `kernels` turns it into
a step Function. ``lie`` (CF4) is not a tableau; its nodes are `CF4_NODES`.
"""
from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Tableau", "RK4", "DOP853", "DOP853_E3", "DOP853_E5", "CF4_NODES", "TABLEAUX",
           "unique_nodes"]


@dataclass(frozen=True)
class Tableau:
    """An explicit Runge-Kutta method: ``a`` (strictly lower rows), weights ``b``, nodes ``c``."""

    name: str
    a: tuple
    b: tuple
    c: tuple
    order: int

    @property
    def stages(self) -> int:
        return len(self.b)


RK4 = Tableau(
    "rk4",
    a=((), (0.5,), (0.0, 0.5), (0.0, 0.0, 1.0)),
    b=(1 / 6, 1 / 3, 1 / 3, 1 / 6),
    c=(0.0, 0.5, 0.5, 1.0),
    order=4,
)

# Dormand & Prince DOP853, 8th-order solution (Hairer, Norsett & Wanner, "Solving ODEs I",
# code dop853.f); the doubles are those of scipy.integrate's DOP853.
DOP853 = Tableau(
    "rk8",
    a=(
        (),
        (0.05260015195876773,),
        (0.0197250569845379, 0.0591751709536137),
        (0.02958758547680685, 0.0, 0.08876275643042054),
        (0.2413651341592667, 0.0, -0.8845494793282861, 0.924834003261792),
        (0.037037037037037035, 0.0, 0.0, 0.17082860872947386, 0.12546768756682242),
        (0.037109375, 0.0, 0.0, 0.17025221101954405, 0.06021653898045596, -0.017578125),
        (0.03709200011850479, 0.0, 0.0, 0.17038392571223998, 0.10726203044637328,
         -0.015319437748624402, 0.008273789163814023),
        (0.6241109587160757, 0.0, 0.0, -3.3608926294469414, -0.868219346841726,
         27.59209969944671, 20.154067550477894, -43.48988418106996),
        (0.47766253643826434, 0.0, 0.0, -2.4881146199716677, -0.590290826836843,
         21.230051448181193, 15.279233632882423, -33.28821096898486, -0.020331201708508627),
        (-0.9371424300859873, 0.0, 0.0, 5.186372428844064, 1.0914373489967295,
         -8.149787010746927, -18.52006565999696, 22.739487099350505, 2.4936055526796523,
         -3.0467644718982196),
        (2.273310147516538, 0.0, 0.0, -10.53449546673725, -2.0008720582248625,
         -17.9589318631188, 27.94888452941996, -2.8589982771350235, -8.87285693353063,
         12.360567175794303, 0.6433927460157636),
    ),
    b=(0.054293734116568765, 0.0, 0.0, 0.0, 0.0, 4.450312892752409, 1.8915178993145003,
       -5.801203960010585, 0.3111643669578199, -0.1521609496625161, 0.20136540080403034,
       0.04471061572777259),
    c=(0.0, 0.05260015195876773, 0.0789002279381516, 0.1183503419072274, 0.2816496580927726,
       0.3333333333333333, 0.25, 0.3076923076923077, 0.6512820512820513, 0.6,
       0.8571428571428571, 1.0),
    order=8,
)

# DOP853's embedded error weights over its 12 stages (Hairer's ``er`` and ``b - bhh``; the
# doubles of scipy's E5 and E3 without their zero 13th entry): with ``s = atol + rtol
# max(|x|, |x+|)``, ``e5 = sum E5_i k_i / s``, ``e3 = sum E3_i k_i / s``, the step's error
# estimate is ``|h| |e5|^2 / sqrt(n (|e5|^2 + 0.01 |e3|^2))`` (dop853.f), of order h^8.
DOP853_E5 = (0.01312004499419488, 0.0, 0.0, 0.0, 0.0, -1.2251564463762044, -0.4957589496572502,
             1.6643771824549864, -0.35032884874997366, 0.3341791187130175, 0.08192320648511571,
             -0.022355307863886294)
DOP853_E3 = (-0.18980075407240762, 0.0, 0.0, 0.0, 0.0, 4.450312892752409, 1.8915178993145003,
             -5.801203960010585, -0.4226823213237919, -0.1521609496625161, 0.20136540080403034,
             0.02265179219836082)

# Stage nodes of the commutator-free method CF4 used by "lie" (four right-hand sides a step).
CF4_NODES = (0.0, 0.5, 0.5, 1.0)


def _nodes(method: str) -> tuple:
    return CF4_NODES if method == "lie" else TABLEAUX[method].c


def unique_nodes(method: str) -> tuple:
    return tuple(sorted(set(_nodes(method))))


TABLEAUX = {"rk4": RK4, "rk8": DOP853}

