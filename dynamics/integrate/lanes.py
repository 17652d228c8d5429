"""Fixed-step rk8 over the runs of a batch, `LANES` runs at a time in the lanes of the
machine's vector registers (`dynamics.integrate.batch_fixed`).

The runs of a fixed-step batch share the grid and the step sizes; each has its own state,
constant control and parameters. The casadi-generated C of the model's rk8 step (the same
step `cpass._FIXED` calls for one run) is rewritten with every value a vector of `LANES`
doubles (GCC's ``vector_size`` extension): one call steps `LANES` runs, each lane doing a
run's arithmetic in the same order as the scalar step (on the rigid body, 1,000 runs of 120
steps: 3.3-5x less time than the scalar loop). Each lane is computed alone (no operation
mixes lanes; a short last group repeats its last run in the empty lanes), so a run's answer
does not depend on the runs beside it, nor on how the runs are split over threads.

Only steps made of ``+ - * /``, constants and the functions of `_FUNCTIONS` are rewritten
(`lane_source`); a step with comparisons or conditionals (``if_else``, ``fmin`` inside the
code's own helpers), work arrays or calls of other Functions keeps the scalar loop.
"""
from __future__ import annotations

import ctypes
import re

import casadi as ca

from .. import cache
from ..model import Model
from .kernels import kernel

__all__ = ["LANES", "lane_source", "lanes_library"]

#: Runs stepped together (4 doubles: 256-bit registers; narrower machines split them).
LANES = 4

#: C functions of generated code and their lane-wise forms (each lane by the C function).
_FUNCTIONS = {name: f"v_{name}" for name in (
    "sqrt", "sin", "cos", "tan", "asin", "acos", "atan", "exp", "log", "sinh", "cosh",
    "tanh", "fabs", "floor", "ceil")}
_FUNCTIONS.update(casadi_sq="v_sq")

#: C flags tried in turn (as the pass library's: this machine's instructions, else plain).
_OPTS = ("-O1 -march=native", "-O1")

_HEADER = r"""
#include <math.h>
#include <stddef.h>
typedef double lane_t __attribute__((vector_size(%(bytes)d)));
#define LANES %(lanes)d
#define LANE_NX %(nx)d
#define LANE_NU %(nu)d
#define LANE_NP %(np)d
#define LANE_U (LANE_NU > 0 ? LANE_NU : 1)
#define LANE_P (LANE_NP > 0 ? LANE_NP : 1)
static inline lane_t VB(double c) { lane_t r; int l; for (l = 0; l < LANES; ++l) r[l] = c; return r; }
static inline lane_t v_sq(lane_t a) { return a * a; }
%(functions)s
"""

_FUNCTION = ("static inline lane_t %s(lane_t a) { lane_t r; int l; "
             "for (l = 0; l < LANES; ++l) r[l] = %s(a[l]); return r; }")

# The loop: as `rk8_fixed_many` of `cpass._FIXED`, LANES runs per pass.
_LOOP = r"""
/* m rk8 steps per output interval (lengths H, nint of them) for the runs k0 <= k < k1,
   LANES at a time: x0 (K, nx), u (K, max(nu, 1)), p (K, max(np, 1)) by run; X (K, nint + 1,
   nx) the states at the outputs. Returns the runs done. */
int rk8_fixed_lanes(int k0, int k1, int nint, int m, const double* H, const double* x0,
                    const double* u, const double* p, double* X) {
  lane_t x[LANE_NX], xn[LANE_NX], h, ua[LANE_U], zero[LANE_U], pp[LANE_P];
  const lane_t* arg[5];
  lane_t* res[1];
  int k, j, s, i, l, n;
  for (i = 0; i < LANE_U; ++i) zero[i] = VB(0.0);
  for (i = 0; i < LANE_P; ++i) pp[i] = VB(0.0);
  arg[0] = x; arg[1] = &h; arg[2] = ua; arg[3] = zero; arg[4] = pp; res[0] = xn;
  for (k = k0; k < k1; k += LANES) {
    n = k1 - k < LANES ? k1 - k : LANES;
    for (l = 0; l < LANES; ++l) {
      size_t r = (size_t) k + (l < n ? l : n - 1);  /* (empty lanes repeat the last run) */
      for (i = 0; i < LANE_NX; ++i) x[i][l] = x0[r * LANE_NX + i];
      for (i = 0; i < LANE_U; ++i) ua[i][l] = u[r * LANE_U + i];
      for (i = 0; i < LANE_NP; ++i) pp[i][l] = p[r * LANE_P + i];
    }
    for (l = 0; l < n; ++l)
      for (i = 0; i < LANE_NX; ++i) X[(size_t) (k + l) * (nint + 1) * LANE_NX + i] = x[i][l];
    for (j = 0; j < nint; ++j) {
      h = VB(H[j] / m);
      for (s = 0; s < m; ++s) {
        rk8_lane_step(arg, res);
        for (i = 0; i < LANE_NX; ++i) x[i] = xn[i];
      }
      for (l = 0; l < n; ++l)
        for (i = 0; i < LANE_NX; ++i)
          X[((size_t) (k + l) * (nint + 1) + j + 1) * LANE_NX + i] = x[i][l];
    }
  }
  return k1 - k0;
}
"""

_BODY = re.compile(r"static int casadi_f0\(const casadi_real\*\* arg, casadi_real\*\* res, "
                   r"casadi_int\* iw, casadi_real\* w, int mem\) \{\n(.*?)\n\}\n", re.S)
_NUMBER = r"-?(?:\d+\.?\d*|\.\d+)(?:e[+-]?\d+)?"
# a statement of the rewritten body: a declaration, an assignment of a value made of
# variables, numbers, + - * / and the lane-wise functions, an output, the return
_STATEMENT = re.compile(
    r"lane_t (?:a\d+, )*a\d+;"
    r"|a\d+=VB\(" + _NUMBER + r"\);"
    r"|a\d+=arg\[\d+\]\[\d+\];"
    r"|a\d+=(?:[-+*/() ]|a\d+|" + _NUMBER + r"|v_\w+\()+;"
    r"|if \(res\[\d+\]!=0\) res\[\d+\]\[\d+\]=a\d+;"
    r"|return 0;")


def lane_source(step: ca.Function) -> str | None:
    """The C of ``step`` (an rk8 step ``(x, h, ua, ud, p) -> x+`` of `kernels.kernel`) as
    ``static int rk8_lane_step(const lane_t** arg, lane_t** res)``, every value a vector
    of `LANES` doubles; None when the generated code holds anything but the statements
    the rewrite knows (see the module docstring).

    Examples
    --------
    >>> from appdyn.dynamics import rigid_body
    >>> from appdyn.dynamics.integrate.kernels import kernel
    >>> from appdyn.dynamics.integrate.lanes import lane_source
    >>> src = lane_source(kernel(rigid_body([1.0, 2.0, 3.0]), "rk8", "linear", compiled=True))
    >>> src.splitlines()[0]
    'static int rk8_lane_step(const lane_t** arg, lane_t** res) {'
    """
    gen = ca.CodeGenerator("lane_step.c", {"with_header": False})
    gen.add(step)
    code = gen.dump()
    if code.count("static int casadi_f") != 1:  # (calls of other Functions)
        return None
    found = _BODY.search(code)
    if found is None:
        return None
    lines = []
    for line in found.group(1).splitlines():
        line = line.strip()
        line = re.sub(r"^casadi_real ", "lane_t ", line)
        line = re.sub(r"^(a\d+)=(" + _NUMBER + r");$", r"\1=VB(\2);", line)
        line = re.sub(r"arg\[(\d+)\]\? arg\[\1\]\[(\d+)\] : 0", r"arg[\1][\2]", line)
        line = re.sub(r"\b(" + "|".join(_FUNCTIONS) + r")\(",
                      lambda mt: _FUNCTIONS[mt.group(1)] + "(", line)
        if not _STATEMENT.fullmatch(line):
            return None
        lines.append("  " + line)
    return ("static int rk8_lane_step(const lane_t** arg, lane_t** res) {\n"
            + "\n".join(lines) + "\n}\n")


def lanes_library(model: Model, *, build: bool = True):
    """``rk8_fixed_lanes(k0, k1, nint, m, H, x0, u, p, X)`` of ``model`` (a ``ctypes``
    function with the arguments of ``rk8_fixed_many``, `cpass._FIXED`), compiled once per
    model for this machine (cached; the persistent compile cache keeps it between
    processes); None when the step cannot be rewritten (`lane_source`), without a C
    compiler, or with ``build=False`` when it is not built yet in this process."""
    key = ("rk8_lanes", cache.function_key(model.f))
    if not build and not cache.contains(key):
        return None

    def make():  # (only when the persistent cache does not hold the library)
        body = lane_source(kernel(model, "rk8", "linear", compiled=True))
        if body is None:
            raise RuntimeError("the rk8 step holds operations the lane rewrite does not take")
        functions = "\n".join(_FUNCTION % (v, c) for c, v in _FUNCTIONS.items()
                               if c != "casadi_sq")
        x = ca.SX.sym("x")
        return ([ca.Function("rk8_lanes", [x], [x])],  # (names the library)
                _HEADER % dict(bytes=8 * LANES, lanes=LANES, nx=model.nx, nu=model.nu,
                               np=model.np, functions=functions) + body + _LOOP)

    def job(opt):
        return cache.Job(make, opt, ctypes.CDLL, cache.recipe("rk8_lanes", model.f, LANES, opt))

    def make_library():
        lib = cache.compile_parallel([job(_OPTS[0])])[0]
        if isinstance(lib, RuntimeError):
            lib = cache.compile_parallel([job(_OPTS[1])])[0]
        if lib is None or isinstance(lib, RuntimeError):
            return None
        fun = lib.rk8_fixed_lanes
        ptr, i32 = ctypes.c_void_p, ctypes.c_int
        fun.argtypes = [i32, i32, i32, i32, ptr, ptr, ptr, ptr, ptr]
        fun.restype = i32
        fun.library = lib  # (kept alive with the function)
        return fun

    return cache.get(key, make_library, keepalive=model.f)
