"""Runs of a batch `LANES` at a time in the lanes of the machine's vector registers:
fixed-step rk8 (`lanes_library`, for `dynamics.integrate.batch_fixed`) and the DOP853 step
with its stages that ``auto`` and ``dop853`` batches take (`dense_lanes`, for
`dynamics.integrate.dense.dense_many`: the compiled pass's ``rk8_auto_lanes`` steps each
lane's run with its own step sizes, controller, outputs and check).

The runs of a fixed-step batch share the grid and the step sizes; each has its own state,
constant control and parameters. The casadi-generated C of the model's rk8 step (the same
step `cpass._FIXED` calls for one run) is rewritten with every value a vector of `LANES`
doubles (GCC's ``vector_size`` extension): one call steps `LANES` runs, each lane doing a
run's arithmetic in the same order as the scalar step (on the rigid body, 1,000 runs of 120
steps: 3.3-5x less time than the scalar loop). Each lane is computed alone (no operation
mixes lanes; a short last group repeats its last run in the empty lanes), so a run's answer
does not depend on the runs beside it, nor on how the runs are split over threads.

Only steps made of ``+ - * /``, constants and the functions of `_FUNCTIONS` and
`_FUNCTIONS2` are rewritten (`lane_source`); a step with comparisons or conditionals
(``if_else``), work arrays or calls of other Functions keeps the scalar loop.
"""
from __future__ import annotations

import ctypes
import re

import casadi as ca

from .. import cache
from ..model import Model
from .cpass import LANES, pass_lanes_job, pass_library
from .csteps import loop_steps
from .kernels import calls_rhs, dense_kernels, kernel

__all__ = ["LANES", "lane_source", "lanes_library", "dense_lanes"]


#: C functions of generated code and their lane-wise forms (each lane by the C function).
_FUNCTIONS = {name: f"v_{name}" for name in (
    "sqrt", "sin", "cos", "tan", "asin", "acos", "atan", "exp", "log", "sinh", "cosh",
    "tanh", "fabs", "floor", "ceil")}
_FUNCTIONS.update(casadi_sq="v_sq", casadi_fabs="v_fabs")
#: The same for the functions of two arguments.
_FUNCTIONS2 = {"fmin": "v_fmin", "fmax": "v_fmax", "casadi_fmin": "v_fmin",
               "casadi_fmax": "v_fmax"}

#: Most right-hand-side instructions of a model given vector lanes (`dense_lanes`): gcc
#: -O2 takes about 0.7 s for the 35-state registry scene (3,760 instructions) and 0.9 s for
#: 45 states (4,992), in the background, but a process that exits waits for a compile under
#: way; a larger model keeps the scalar pass.
DENSE_MAX_INSTRUCTIONS = 20_000

#: C flags tried in turn (as the pass library's: this machine's instructions, else plain),
#: at -O2 without contracting ``a * b + c`` into fused multiply-adds: the pass's scalar
#: steps contract none either (`cpass._OPTS`), so a lane's arithmetic is the scalar step's
#: to the bit; -O2 made
#: the vector DOP853 step 1.5x faster than -O1 (219 against 353 ns for 4 runs of the rigid
#: body, its scalar step 215 ns) at the same compile time.
_OPTS = ("-O2 -ffp-contract=off -march=native", "-O2 -ffp-contract=off")

_HEADER = r"""
#include <math.h>
#include <stddef.h>
typedef double lane_t __attribute__((vector_size(%(bytes)d)));
typedef long long lane_mask __attribute__((vector_size(%(bytes)d)));
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
# (fmin and fmax as a select: glibc's x86-64 fmax is ``a > b ? a : b`` but for NaN, which
# gives the other; the lane-wise libm calls cost a third of the vector step)
_FUNCTION2 = ("static inline lane_t %s(lane_t a, lane_t b) { "
              "lane_mask m = (a %s b) | (b != b); "
              "return (lane_t) (((lane_mask) a & m) | ((lane_mask) b & ~m)); }")

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
    r"|a\d+=(?:[-+*/(), ]|a\d+|" + _NUMBER + r"|v_\w+\()+;"
    r"|if \(res\[\d+\]!=0\) res\[\d+\]\[\d+\]=a\d+;"
    r"|return 0;")


def lane_source(step: ca.Function, *, name: str = "rk8_lane_step",
                export: bool = False) -> str | None:
    """The C of ``step`` (a Function of `kernels`: an rk8 step ``(x, h, ua, ud, p) -> x+``,
    or the dense step ``rk8_step_k``) as ``static int name(const lane_t** arg, lane_t**
    res)`` (``export``: not static, for another library to call), every value a vector of
    `LANES` doubles; None when the generated code holds anything but the statements the
    rewrite knows (see the module docstring).

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
        line = re.sub(r"\b(" + "|".join([*_FUNCTIONS, *_FUNCTIONS2]) + r")\(",
                      lambda mt: {**_FUNCTIONS, **_FUNCTIONS2}[mt.group(1)] + "(", line)
        if not _STATEMENT.fullmatch(line):
            return None
        lines.append("  " + line)
    return (("" if export else "static ") + f"int {name}(const lane_t** arg, lane_t** res) {{\n"
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

    def make_library():
        lib = _compiled(_jobs(model, "rk8_lanes", lambda: lane_source(
            kernel(model, "rk8", "linear", compiled=True)), _LOOP))
        if lib is None:
            return None
        fun = lib.rk8_fixed_lanes
        ptr, i32 = ctypes.c_void_p, ctypes.c_int
        fun.argtypes = [i32, i32, i32, i32, ptr, ptr, ptr, ptr, ptr]
        fun.restype = i32
        fun.library = lib  # (kept alive with the function)
        return fun

    return cache.get(key, make_library, keepalive=model.f)


def dense_lanes(model: Model, *, build: bool = True, wait: bool = False):
    """The vector form of ``model``'s DOP853 step with its stages and of its continuous
    extension (`kernels.dense_kernels`' ``rk8_step_k`` and ``rk8_cont``, `lane_source`),
    exported as ``rk8_lane_step_k`` and ``rk8_lane_cont`` for the compiled pass's
    ``rk8_auto_lanes`` (`cpass`): a ``ctypes`` function pointer of the step (its
    ``address`` and ``cont`` the values the pass takes; the library kept alive with it),
    with the entry points of the pass's build that drives them (`cpass.pass_library` with
    ``lanes=True``: ``auto_v``, a single call with its check in a lane, and
    ``auto_lanes``, a batch's loop), compiled once per model for this machine (cached; kept
    on disk by the persistent compile cache). Both libraries compile together, in the
    background unless ``wait``: the first call's pass does without the lane driver.

    A model whose steps call its right-hand side (`kernels.calls_rhs`: the pass's steps are
    C loops, `csteps`) gets the vector form of those loops around its rewritten right-hand
    side (`csteps.loop_steps` with ``lanes``).

    None: the step (or that right-hand side) cannot be rewritten, a right-hand side of more
    than `DENSE_MAX_INSTRUCTIONS` instructions, no C compiler, ``build``
    False and not loaded in this process, or (``wait`` False) the library is neither on disk
    nor compiled yet: its compile then starts in the background (`cache.compile_ahead`) and
    a later call takes it once it is ready; a batch does not wait for it (the scalar loop
    gives the same bits)."""
    key = ("rk8_dense_lanes", cache.function_key(model.f))
    if cache.contains(key):
        return cache.get(key, lambda: None)
    if not build or model.f.n_instructions() > DENSE_MAX_INSTRUCTIONS:
        return None

    def body():
        if calls_rhs(model, "rk8"):  # (the pass's loops around its rhs, `csteps`)
            rhs = lane_source(model.f, name="rk8_lane_rhs")
            return None if rhs is None else rhs + loop_steps(lanes=True)
        step, cont = (lane_source(f, name="rk8_lane_" + f.name()[4:], export=True)
                      for f in dense_kernels(model))
        return None if step is None or cont is None else step + cont

    # (the jobs kept: their recipe serializes the model, and a caller that does not wait
    # asks again until the library is ready)
    jobs = cache.get(("rk8_dense_lanes_jobs", key[1]),
                     lambda: _jobs(model, "rk8_dense_lanes", body, "") + [
                         pass_lanes_job(model)], keepalive=model.f)
    if not wait and not (cache.ready(jobs[0]) and cache.ready(jobs[-1])):
        cache.compile_ahead([jobs[0], jobs[-1]])
        return None

    def make_library():
        cache.compile_ahead([jobs[0], jobs[-1]])  # (both at once, when not on disk yet)
        lib = _compiled(jobs[:-1])
        driver = None if lib is None else pass_library(model, lanes=True)
        if driver is None:
            return None
        fun = lib.rk8_lane_step_k
        fun.address = ctypes.cast(fun, ctypes.c_void_p).value
        fun.cont = ctypes.cast(lib.rk8_lane_cont, ctypes.c_void_p).value
        fun.library = lib  # (kept alive with the function)
        fun.auto_v, fun.auto_lanes, fun.driver = driver.auto_v, driver.auto_lanes, driver
        return fun

    return cache.get(key, make_library, keepalive=model.f)


def _jobs(model: Model, name: str, body, loop: str) -> list:
    """The compile jobs (`cache.Job`, one per flag set of `_OPTS`) of the library ``name``:
    the lane helpers, the rewritten step ``body()`` (`lane_source`; None: the job fails) and
    the C ``loop`` around it."""
    def make():  # (only when the persistent cache does not hold the library)
        step = body()
        if step is None:
            raise RuntimeError("the step holds operations the lane rewrite does not take")
        functions = "\n".join(
            [_FUNCTION % (v, v[2:]) for v in sorted(set(_FUNCTIONS.values()) - {"v_sq"})]
            + [_FUNCTION2 % (v, "<" if v == "v_fmin" else ">")
               for v in sorted(set(_FUNCTIONS2.values()))])
        x = ca.SX.sym("x")
        return ([ca.Function(name, [x], [x])],  # (names the library)
                _HEADER % dict(bytes=8 * LANES, lanes=LANES, nx=model.nx, nu=model.nu,
                               np=model.np, functions=functions) + step + loop)

    return [cache.Job(make, opt, ctypes.CDLL, cache.recipe(name, model.f, LANES, opt))
            for opt in _OPTS]


def _compiled(jobs: list):
    """The library of the first of ``jobs`` that compiles (or loads), else None."""
    for job in jobs:
        lib = cache.compile_parallel([job])[0]
        if lib is not None and not isinstance(lib, RuntimeError):
            return lib
        if lib is None:
            return None
    return None
