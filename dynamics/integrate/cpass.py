"""The compiled pass of `dynamics.integrate.adaptive`: its C source (`_DRIVER`, a plain loop
around the casadi-generated rk8 steps and right-hand side of a model), the step-controlled
DOP853 of `dynamics.integrate.stepcontrol` (`_STEPPER`, in the same library) and their
build (`pass_library`: compiled once per model for this machine, loaded with ``ctypes``;
the stepper is the attribute ``stepper`` of the returned function), and DOP853 stepping by
its error estimate alone with dense output (`_DENSE`, the attribute ``dense``)."""
from __future__ import annotations

import ctypes

import casadi as ca

from .. import cache
from ..model import Model
from .csteps import loop_steps
from .kernels import calls_rhs, dense_kernels, kernel
from .tableaux import DOP853_DENSE_STAGES
from .chunks import BATCH_CHUNK, CHUNK, chunk_compile_job, chunk_name

__all__ = ["BMAX", "CHECK_EVERY", "LANES", "NOISE", "pass_library", "pass_lanes_job",
           "pass_chunk"]

#: Runs stepped together in the lanes of a vector step (4 doubles: 256-bit registers;
#: narrower machines split them): the pass's lane driver (``PASS_LANES``) and the vector
#: steps of `lanes` it drives.
LANES = 4

#: Most check-run steps in one output interval (the answer takes ``2 b + 1``; a longer
#: interval, or a problem that needs more, leaves the pass to the multi-run search).
BMAX = 32
#: An embedded estimate at most this many ``eps / rtol`` (tolerance units) is rounding.
NOISE = 30

#: C flags of the pass, tried in turn: compiled for this machine's instruction set (the
#: library is built and used here only; FMA and AVX made the pass 22% faster on the 2-core
#: VM, 742 steps in 149 against 191 us), else plain -O1 (as the chunk loops; -O2/-O3 were
#: no faster and compile 30-80% longer on the generated steps). The driver's own C (the
#: loops, controller, outputs and checks around the steps: `_DRIVER` on) is built at -O2
#: by a pragma: the 1,000-run Monte Carlo of ``bench/integrate_peers.py`` took 8% less
#: time, the same bits. No ``a * b + c`` is contracted into a fused multiply-add (gcc's
#: -O1 contracts none: the same code with the flag), as in the vector lanes (`lanes`): a
#: lane's arithmetic is then the scalar step's to the bit on any gcc. ``sqrt`` sets no
#: ``errno`` (no value changes), so the lanes' controller roots are one vector ``sqrt``.
_OPTS = ("-O1 -ffp-contract=off -fno-math-errno -march=native",
         "-O1 -ffp-contract=off -fno-math-errno")

#: The answer's embedded estimate (and the model's rounding) is taken in every
#: `CHECK_EVERY`-th interval (-1 in the others): it only tells whether the two runs show the
#: method's order.
CHECK_EVERY = 4

# columns of the pass statistics per interval: answer steps, its embedded estimate (first
# step), the check run's (-1 where not taken), steps taken (a redone interval included)
_N, _E, _EC, _S = range(4)

# The driver: the generated steps `rk8_step_err` (x, h, ua, ud, p, rtol, atol) -> (x+, err)
# and `rk8_step` (x, h, ua, ud, p) -> x+ called from a plain C loop over the output intervals.
_DRIVER = r"""
#pragma GCC optimize ("O2", "fp-contract=off")
#include <float.h>
#include <stddef.h>
#define PASS_NX %(nx)d
#define PASS_NU %(nu)d
#define PASS_NP %(np)d
#define PASS_NW %(nw)d
#define PASS_NIW %(niw)d
#define PASS_NARG %(narg)d
#define PASS_NRES %(nres)d
#define PASS_LANES %(lanes)d
/* 1: with the steps in vector lanes (`rk8_auto_v` given vector steps, `rk8_auto_lanes`):
   the pass's second build, compiled with `lanes.dense_lanes`; 0: the first call's build */
#define PASS_WITH_LANES %(with_lanes)d
#define PASS_U (PASS_NU > 0 ? PASS_NU : 1)
#define CHECK_EVERY %(every)d
/* the stages the continuous extension reads (`tableaux.DOP853_DENSE_STAGES`) */
#define CONT_STAGES {%(cont)s}
#define CONT_NSTAGES %(ncont)d
%(steps)s
typedef struct {
  const casadi_real *p, *atol, *ud;
  casadi_real rtol;
  casadi_real w[PASS_NW + 1];
  casadi_int iw[PASS_NIW + 1];
} pass_ctx;

/* n steps of H / n from x0 into x (x0 may be x); returns the embedded estimate of the
   first step when `estimate` (else -1: the estimate costs about half a step) */
static casadi_real pass_steps(pass_ctx* c, const casadi_real* x0, casadi_real* x, int n,
                              casadi_real H, const casadi_real* ua, int estimate) {
  const casadi_real* arg[PASS_NARG + 7];
  casadi_real* res[PASS_NRES + 2];
  casadi_real h = H / n, err = -1, xn[PASS_NX], u[PASS_U];
  int i, j;
  for (i = 0; i < PASS_NX; ++i) x[i] = x0[i];
  arg[0] = x; arg[1] = &h; arg[2] = u; arg[3] = c->ud; arg[4] = c->p; arg[5] = &c->rtol;
  arg[6] = c->atol; res[0] = xn; res[1] = &err;
  for (j = 0; j < n; ++j) {
    for (i = 0; i < PASS_NU; ++i) u[i] = ua[i] + (j * h) * c->ud[i];
    if (j == 0 && estimate) rk8_step_err(arg, res, c->iw, c->w, 0);
    else rk8_step(arg, res, c->iw, c->w, 0);
    for (i = 0; i < PASS_NX; ++i) x[i] = xn[i];
  }
  return err;
}

/* Hairer's DOP853 controller (`stepcontrol.next_step`) after a step of `hs` with the error
   factor `fac` (err^(1/8) / 0.9): the next proposal from the current one `h`; safety 0.9,
   the step changed by a factor in [1/3, 6], no growth right after a rejection; a step cut
   short (by an output time or hmax) says nothing against the proposal. `rejected` (in/out):
   whether the step before was rejected; a rejection is counted in count[1]. */
static casadi_real ctl_next(casadi_real hs, casadi_real h, casadi_real fac, int accepted,
                            int* rejected, casadi_real* count) {
  int was = *rejected;
  *rejected = !accepted;
  if (!accepted) {
    count[1] += 1;  /* rejected steps */
    return hs / fmin(3.0, fac);
  }
  fac = fmax(1.0 / 6.0, fmin(3.0, fac));
  fac = was ? fmin(hs, hs / fac) : hs / fac;
  return hs < h && fac < h ? h : fac;
}

/* Why a stepper stops after a step (0: it goes on): 3 more than max_steps steps (accepted
   and rejected, `count[0] + count[1]`), 2 the proposal `h` underflowed against `span`,
   1 a non-finite state or estimate (`finite` 0). */
static int ctl_flag(const casadi_real* count, casadi_real max_steps, casadi_real h,
                    casadi_real span, int finite) {
  if (count[0] + count[1] > max_steps) return 3;
  if (!(h > 64 * DBL_EPSILON * span)) return finite ? 2 : 1;
  return 0;
}

/* the model's right-hand side at (x, u): its rounding noise is measured with it */
static void pass_rhs_at(pass_ctx* c, const casadi_real* x, const casadi_real* u,
                        casadi_real* xdot) {
  const casadi_real* arg[PASS_NARG + 3];
  casadi_real* res[PASS_NRES + 1];
  arg[0] = x; arg[1] = u; arg[2] = c->p; res[0] = xdot;
  pass_rhs(arg, res, c->iw, c->w, 0);
}

static int pass_predict(casadi_real n, casadi_real e, casadi_real target, casadi_real lo, int kmax) {
  /* steps for an estimate of `target` per unit time, from `e` at `n` steps (e ~ h^7) */
  casadi_real want = e > 0 ? ceil(n * pow(e * n / target, 1.0 / 6.0)) : lo;
  if (!(want >= lo)) want = lo;
  if (want > kmax) want = kmax;
  return (int) want;
}

/* `state` (in and out): the accumulators ST_... below, then max |x_i| (answer, every
   output), then min (atol_i + rtol |x_i|) over the outputs after the first, then the
   rounding noise max |f_i(x (1 + eps s)) - f_i(x)| of the right-hand side at the answer's
   states (every CHECK_EVERY-th output; s = +-`signs`, alternating) */
#define ST_B 0      /* check steps in the last interval */
#define ST_EC 1     /* their embedded estimate */
#define ST_STEPS 2  /* steps taken (redone check intervals included) */
#define ST_D 3      /* max |answer - check| / (atol + rtol |answer|) */
#define ST_ORDER 4  /* intervals whose estimates show order 5-10 ... */
#define ST_ORDERS 5 /* ... of the intervals where both were measured above `noise` */
#define ST_ECMAX 6  /* the check run's largest estimate */
#define ST_FLAG 7   /* 1: a non-finite state, 2: an interval needs more than bmax steps,
                       3: a state's size over its tolerance exceeds `ratio_max` */
#define ST_NMIN 8   /* least answer steps in an interval */
#define ST_NMAX 9   /* most */
#define ST_ANSWER 10 /* answer steps */
#define ST_RMIN 11  /* least n / b */
#define ST_ULP 12   /* max_i max|x_i| / min (atol_i + rtol |x_i|) (eps times it: one ulp) */
#define ST_SIZE 13

/* The pass over `nint` intervals; returns the intervals done (fewer when ST_FLAG is set;
   the last one done is the one that failed). The check run's steps b follow its embedded
   estimate (per unit time `theta`); the answer takes n = 2 b + 1 (n = 2 for b = 1). */
int rk8_pass(casadi_real* xf, casadi_real* xc, casadi_real* state, int nint,
             const casadi_real* H, const casadi_real* ua, const casadi_real* ud, int ustride,
             const casadi_real* p, casadi_real rtol, const casadi_real* atol, casadi_real theta,
             int bmax, int bmin, casadi_real noise, casadi_real ratio_max,
             const casadi_real* signs, casadi_real* X, casadi_real* XC, int ldx,
             casadi_real* stats) {
  pass_ctx c;
  casadi_real tmp[PASS_NX], e, ec, sc, o, b_prev = state[ST_B], ec_prev = state[ST_EC];
  casadi_real* size = state + ST_SIZE;
  casadi_real* smin = state + ST_SIZE + PASS_NX;
  casadi_real* rnoise = state + ST_SIZE + 2 * PASS_NX;
  casadi_real f0[PASS_NX], f1[PASS_NX], uend[PASS_U];
  const casadi_real* u;
  int k, i, n, b, b2, s, bad;
  c.p = p; c.atol = atol; c.rtol = rtol;
  for (k = 0; k < nint; ++k) {
    c.ud = ud + k * ustride;
    u = ua + k * ustride;
    b = pass_predict(b_prev, ec_prev, theta * H[k], fmax(bmin, floor(b_prev / 2)), bmax);
    ec = pass_steps(&c, xc, tmp, b, H[k], u, 1);
    s = b;
    if (ec > theta * H[k] / b && b < bmax) {
      b2 = pass_predict(b, 1.2 * ec, theta * H[k], b + 1, bmax);
      ec = pass_steps(&c, xc, tmp, b2, H[k], u, 1);
      b = b2;
      s += b2;
    }
    for (i = 0; i < PASS_NX; ++i) xc[i] = tmp[i];
    n = b >= 2 ? 2 * b + 1 : 2;
    e = pass_steps(&c, xf, xf, n, H[k], u, k %% CHECK_EVERY == 0);
    s += n;
    bad = 0;
    for (i = 0; i < PASS_NX; ++i) {
      X[i * ldx + k] = xf[i];
      XC[i * ldx + k] = xc[i];
      if (!isfinite(xf[i]) || !isfinite(xc[i])) bad = 1;
      sc = atol[i] + rtol * fabs(xf[i]);
      if (fabs(xf[i]) > size[i]) size[i] = fabs(xf[i]);
      if (sc < smin[i]) smin[i] = sc;
      if (size[i] > ratio_max * smin[i]) bad = bad ? bad : 3;
      sc = fabs(xf[i] - xc[i]) / sc;
      if (!(sc <= state[ST_D])) state[ST_D] = sc;
    }
    if (k %% CHECK_EVERY == 0 && !bad) {
      for (i = 0; i < PASS_NU; ++i) uend[i] = u[i] + H[k] * c.ud[i];
      pass_rhs_at(&c, xf, uend, f0);
      sc = (k / CHECK_EVERY) %% 2 ? -DBL_EPSILON : DBL_EPSILON;
      for (i = 0; i < PASS_NX; ++i) tmp[i] = xf[i] * (1 + sc * signs[i]);
      pass_rhs_at(&c, tmp, uend, f1);
      for (i = 0; i < PASS_NX; ++i)
        if (fabs(f1[i] - f0[i]) > rnoise[i]) rnoise[i] = fabs(f1[i] - f0[i]);
    }
    stats[4 * k] = n; stats[4 * k + 1] = e; stats[4 * k + 2] = ec; stats[4 * k + 3] = s;
    state[ST_STEPS] += s;
    state[ST_ANSWER] += n;
    if (ec > state[ST_ECMAX]) state[ST_ECMAX] = ec;
    if (n < state[ST_NMIN]) state[ST_NMIN] = n;
    if (n > state[ST_NMAX]) state[ST_NMAX] = n;
    if ((casadi_real) n / b < state[ST_RMIN]) state[ST_RMIN] = (casadi_real) n / b;
    if (e > noise && ec > 0) {
      o = log(ec / e) / log((casadi_real) n / b);
      state[ST_ORDERS] += 1;
      if (o >= 5 && o <= 10) state[ST_ORDER] += 1;
    }
    b_prev = b; ec_prev = ec;
    if (bad || (b >= bmax && !(ec <= theta * H[k] / b))) {
      state[ST_FLAG] = bad ? bad : 2;
      break;
    }
  }
  state[ST_B] = b_prev; state[ST_EC] = ec_prev;
  for (i = 0; i < PASS_NX; ++i) {
    sc = smin[i] > 0 ? size[i] / smin[i] : (size[i] > 0 ? INFINITY : 0);
    if (!(sc <= state[ST_ULP])) state[ST_ULP] = sc;
  }
  return k < nint ? k + 1 : nint;
}

/* `rk8_pass` on a workspace: `ws + off[i]` are xf, xc, state, H, ua, ud, p, atol, stats,
   signs and the parameters (rtol, theta, bmax, bmin, noise, ratio_max, ustride, ldx);
   intervals `done` to `done + k`; X and XC (nx, ldx) get the states (one call of few
   arguments). The first call (done = 0) sets the check run's start and the first column. */
int rk8_pass_ws(casadi_real* ws, const long long* off, int done, int k, casadi_real* X,
                casadi_real* XC) {
  const casadi_real* par = ws + off[10];
  int ustride = (int) par[6], ldx = (int) par[7], i;
  if (done == 0)  /* the check run starts 2 ulp away: xc = x0 (1 + 2 eps signs) */
    for (i = 0; i < PASS_NX; ++i) {
      ws[off[1] + i] = ws[off[0] + i] * (1 + 2 * DBL_EPSILON * ws[off[9] + i]);
      X[i * ldx] = ws[off[0] + i];
      XC[i * ldx] = ws[off[1] + i];
    }
  return rk8_pass(ws + off[0], ws + off[1], ws + off[2], k, ws + off[3] + done,
                  ws + off[4] + done * ustride, ws + off[5] + done * ustride, ustride,
                  ws + off[6], par[0], ws + off[7], par[1], (int) par[2], (int) par[3], par[4],
                  par[5], ws + off[9], X + done + 1, XC + done + 1, ldx,
                  ws + off[8] + 4 * done);
}

/* The next run of a batch for a thread's compiled loop over its runs (`rk8_pass_many`,
   `rk8_adaptive_many`), handed out through the counter *cursor the loops of every thread
   share (atomic, as `au_claim`); -1 when every run is handed out, -2 when the runs this
   loop did have made `budget` steps (0: no limit; the caller looks at Ctrl-C and calls
   again). */
static long long pass_next(long long n, long long* cursor, double budget, double spent) {
  long long k;
  if (budget > 0 && spent >= budget) return -2;
  k = __atomic_fetch_add(cursor, 1, __ATOMIC_RELAXED);
  return k < n ? k : -1;
}

/* `rk8_pass_ws` for the runs of a batch on one grid, each run's calls as a run alone makes
   them (`adaptive.run_pass`: `chunk` intervals to a call, none after a call that set
   ST_FLAG or passed `max_steps` steps), the runs handed out through the shared `cursor`
   (`pass_next`) to the threads that call this: run k on its own workspace
   ws + k stride (the layout `off`), its states into X + k xstride and XC + k xstride, its
   intervals done into done[k]. No run is taken once the runs done have made `budget`
   steps (0: no limit). Returns 1 when every run is handed out, else 0. */
int rk8_pass_many(long long n, long long* cursor, double budget, casadi_real* ws,
                  long long stride, const long long* off, int nint, int chunk,
                  casadi_real max_steps, casadi_real* X, casadi_real* XC, long long xstride,
                  long long* done) {
  long long k;
  int d, m;
  double spent = 0;
  while ((k = pass_next(n, cursor, budget, spent)) >= 0) {
    {
      casadi_real* w = ws + k * stride;
      const casadi_real* st = w + off[2];
      for (d = 0; d < nint;) {
        m = nint - d < chunk ? nint - d : chunk;
        d += rk8_pass_ws(w, off, d, m, X + k * xstride, XC + k * xstride);
        if (st[ST_FLAG] || st[ST_STEPS] > max_steps) break;
      }
      done[k] = d;
      spent += st[ST_STEPS];
    }
  }
  return k == -1;
}

/* The check run of `rk8_pass` replayed from x (in/out) on its own steps: interval k of
   length H[k] in b[k] rk8 steps (`pass_steps`, the pass's arithmetic; controls ua + tau ud
   of stride `ustride`), the states into X (nx, ldx) from column 1; returns the intervals
   done (fewer at a non-finite state). From the pass's exact start it shows what the flow
   made of the check's start, 2 ulp away (`auto._amplified`). */
int rk8_replay(casadi_real* x, int nint, const casadi_real* H, const casadi_real* ua,
               const casadi_real* ud, int ustride, const casadi_real* p,
               const casadi_real* atol, const casadi_real* b, casadi_real* X, int ldx) {
  pass_ctx c;
  casadi_real tmp[PASS_NX];
  int k, i, bad;
  c.p = p; c.atol = atol; c.rtol = 0;
  for (k = 0; k < nint; ++k) {
    c.ud = ud + k * ustride;
    pass_steps(&c, x, tmp, (int) b[k], H[k], ua + k * ustride, 0);
    for (i = 0, bad = 0; i < PASS_NX; ++i) {
      x[i] = tmp[i];
      X[i * ldx + k + 1] = tmp[i];
      if (!isfinite(tmp[i])) bad = 1;
    }
    if (bad) return k + 1;
  }
  return nint;
}

/* `rk8_replay` of the check run of each pass of `rk8_pass_many` that `runs` names (runs[0
   ... n - 1], handed out through the shared `cursor`, `pass_next`): run k's intervals,
   controls and parameters from its workspace ws + k stride (the layout `off`), its check
   steps per interval from B + i nint, from its exact start (column 0 of X + k xstride,
   (nx, nint + 1)) into R + i nx (nint + 1) (its column 0 the start; columns after a
   non-finite state not written). Returns 1. */
int rk8_replay_many(long long n, long long* cursor, const long long* runs,
                    const casadi_real* ws, long long stride, const long long* off, int nint,
                    const casadi_real* B, const casadi_real* X, long long xstride,
                    casadi_real* R) {
  casadi_real x[PASS_NX];
  long long i;
  int j, ldx = nint + 1;
  while ((i = pass_next(n, cursor, 0, 0)) >= 0) {
    const casadi_real* w = ws + runs[i] * stride;
    const casadi_real* x0 = X + runs[i] * xstride;
    casadi_real* r = R + i * PASS_NX * ldx;
    for (j = 0; j < PASS_NX; ++j) r[j * ldx] = x[j] = x0[j * ldx];
    rk8_replay(x, nint, w + off[3], w + off[4], w + off[5], (int) w[off[10] + 6], w + off[6],
               w + off[7], B + i * nint, r, ldx);
  }
  return 1;
}
"""


# The stepper of `dynamics.integrate.stepcontrol`: DOP853 (the same generated step with its
# embedded estimate) with classical step-size control and step rejection over the output
# intervals, every interval ending exactly on its output time (kinks of a non-smooth
# right-hand side shrink the steps that straddle them, as they should).
_STEPPER = r"""
/* Steps of x (in/out) over `nint` output intervals of lengths H, no step of interval k
   longer than hmax[k]; controls ua + tau ud on interval k (stride `ustride`); `hio`
   (in/out) the controller's proposed step; outputs in X (nx, ldx) from column 0 and the
   longest accepted step of each interval in `hbig`. `count` (in/out): accepted steps, rejected
   steps, flag (1: a non-finite state, 2: step-size underflow, 3: more than max_steps
   steps), smallest accepted step. Returns the intervals done (fewer when the flag is set).
   Hairer's DOP853 controller (`stepcontrol.next_step`): safety 0.9, the step changed by a
   factor in [1/3, 6], no growth right after a rejection; a step cut short (by the output
   time or hmax) says nothing against the proposal. */
int rk8_adaptive(casadi_real* x, casadi_real* hio, int nint, const casadi_real* H,
                 const casadi_real* hmax, const casadi_real* ua, const casadi_real* ud,
                 int ustride, const casadi_real* p, casadi_real rtol, const casadi_real* atol,
                 casadi_real max_steps, casadi_real* X, int ldx, casadi_real* hbig,
                 casadi_real* count) {
  pass_ctx c;
  const casadi_real* arg[PASS_NARG + 7];
  casadi_real* res[PASS_NRES + 2];
  casadi_real xn[PASS_NX], u[PASS_U], h = *hio, hp, hs, tau, err, fac, Hk;
  int k, i, last, rejected, finite;
  c.p = p; c.atol = atol; c.rtol = rtol;
  arg[0] = x; arg[1] = &hs; arg[2] = u; arg[4] = p; arg[5] = &c.rtol; arg[6] = atol;
  res[0] = xn; res[1] = &err;
  for (k = 0; k < nint; ++k) {
    Hk = H[k];
    arg[3] = ud + k * ustride;
    tau = 0;
    rejected = 0;
    hbig[k] = 0;
    while (tau < Hk) {
      hp = fmin(h, hmax[k]);
      last = tau + 1.01 * hp >= Hk;
      hs = last ? Hk - tau : hp;
      for (i = 0; i < PASS_NU; ++i) u[i] = ua[k * ustride + i] + tau * ud[k * ustride + i];
      rk8_step_err(arg, res, c.iw, c.w, 0);
      finite = isfinite(err);
      for (i = 0; i < PASS_NX && finite; ++i) finite = isfinite(xn[i]);
      fac = finite ? pow(err, 0.125) / 0.9 : 3.0;
      if (finite && err <= 1.0) {
        for (i = 0; i < PASS_NX; ++i) x[i] = xn[i];
        tau = last ? Hk : tau + hs;
        count[0] += 1;
        if (hs > hbig[k]) hbig[k] = hs;
        if (hs < count[3]) count[3] = hs;
      }
      h = ctl_next(hs, h, fac, finite && err <= 1.0, &rejected, count);
      if ((count[2] = ctl_flag(count, max_steps, h, Hk, finite))) break;
    }
    if (count[2]) break;
    for (i = 0; i < PASS_NX; ++i) X[i * ldx + k] = x[i];
  }
  *hio = h;
  return k;
}

/* `rk8_adaptive` for the runs of a batch on one grid, each run's calls as a run alone
   makes them (`stepcontrol._intervals`: `chunk` intervals to a call), the runs handed out
   through the shared `cursor` (`pass_next`) to the threads that call this: run k
   from x + k nx (updated in place) with the proposal h[k], controls ua, ud + k nint nu
   (stride nu), parameters p + k pstride, its outputs into X + k nx nint (nx, nint), hbig +
   k nint and count + 4 k, its intervals done into done[k]. No run is taken once the runs
   done have made `budget` steps (0: no limit). Returns 1 when every run is handed out,
   else 0. */
int rk8_adaptive_many(long long n, long long* cursor, double budget, int nint, int chunk,
                      const casadi_real* H, casadi_real* x, casadi_real* h,
                      const casadi_real* ua, const casadi_real* ud, int nu,
                      const casadi_real* p, int pstride, casadi_real rtol,
                      const casadi_real* atol, casadi_real max_steps, casadi_real* X,
                      casadi_real* hbig, casadi_real* count, long long* done) {
  long long k;
  int d, m;
  double spent = 0;
  while ((k = pass_next(n, cursor, budget, spent)) >= 0) {
    {
      casadi_real *c = count + 4 * k, *xk = x + k * PASS_NX, *Xk = X + k * PASS_NX * nint;
      const casadi_real *uak = ua + k * nint * nu, *udk = ud + k * nint * nu;
      for (d = 0; d < nint && !c[2]; d += m) {
        m = nint - d < chunk ? nint - d : chunk;
        m = rk8_adaptive(xk, h + k, m, H + d, H + d, uak + d * nu, udk + d * nu, nu,
                         p + k * pstride, rtol, atol, max_steps, Xk + d, nint,
                         hbig + k * nint + d, c);
      }
      done[k] = d;
      spent += c[0] + c[1];
    }
  }
  return k == -1;
}
"""


# DOP853 stepping by its error estimate alone, for a control constant over the run (`dense_run`,
# called by `_AUTO`): the output times never cut a step (but the
# last of each call); an output inside a step is filled from the step's continuous
# extension of order 7 (`rk8_cont`, four more right-hand sides, only on such a step), as
# Hairer's DOP853 with dense output does.
_DENSE = r"""
#define DENSE_NOISE_EVERY 8
/* The first step (Hairer, Norsett & Wanner I, II.4; scipy's `select_initial_step` for an
   error estimate of order 7), at most the run's length. */
static casadi_real dense_first_step(pass_ctx* c, const casadi_real* x, const casadi_real* u,
                                    casadi_real t, casadi_real tend, casadi_real* lipschitz) {
  casadi_real f0[PASS_NX], f1[PASS_NX], x1[PASS_NX], sk, d0 = 0, d1 = 0, d2 = 0, h0, h1;
  int i;
  pass_rhs_at(c, x, u, f0);
  for (i = 0; i < PASS_NX; ++i) {
    sk = c->atol[i] + c->rtol * fabs(x[i]);
    d0 += (x[i] / sk) * (x[i] / sk);
    d1 += (f0[i] / sk) * (f0[i] / sk);
  }
  d0 = sqrt(d0 / PASS_NX); d1 = sqrt(d1 / PASS_NX);
  h0 = d0 < 1e-5 || d1 < 1e-5 || !isfinite(d0 + d1) ? 1e-6 : 0.01 * d0 / d1;
  h0 = fmin(h0, tend - t);
  for (i = 0; i < PASS_NX; ++i) x1[i] = x[i] + h0 * f0[i];
  pass_rhs_at(c, x1, u, f1);
  for (i = 0; i < PASS_NX; ++i) {
    sk = c->atol[i] + c->rtol * fabs(x[i]);
    d2 += ((f1[i] - f0[i]) / sk) * ((f1[i] - f0[i]) / sk);
  }
  d2 = sqrt(d2 / PASS_NX) / h0;
  *lipschitz = d1 > 0 && isfinite(d2 / d1) ? d2 / d1 : 0;
  h1 = d1 <= 1e-15 && d2 <= 1e-15 ? fmax(1e-6, 1e-3 * h0)
                                   : pow(0.01 / fmax(d1, d2), 1.0 / 8.0);
  h1 = fmin(100 * h0, h1);
  return isfinite(h1) && h1 > 0 ? fmin(h1, tend - t) : tend - t;
}

/* The outputs ts[j0] ... ts[j1 - 1], inside the step of `hs` from (t, x), from its
   continuous extension F (`rk8_cont`: order 7) into X (nx, ldx) */
static void dense_fill(const casadi_real* x, const casadi_real* F, casadi_real t,
                       casadi_real hs, const casadi_real* ts, int j0, int j1, casadi_real* X,
                       int ldx) {
  casadi_real s, r;
  int i, j;
  for (j = j0; j < j1; ++j) {
    s = (ts[j] - t) / hs;
    for (i = 0; i < PASS_NX; ++i) {
      r = F[5 * PASS_NX + i] + s * F[6 * PASS_NX + i];
      r = F[4 * PASS_NX + i] + (1 - s) * r;
      r = F[3 * PASS_NX + i] + s * r;
      r = F[2 * PASS_NX + i] + (1 - s) * r;
      r = F[PASS_NX + i] + s * r;
      r = F[i] + (1 - s) * r;
      X[i * ldx + j] = x[i] + s * r;
    }
  }
}

/* The outputs ts[*j] ... in the step of `hs` from (t, x) to (tn, xn) (stages K) into X
   (nx, ldx): those inside from the step's continuous extension of order 7 (`rk8_cont`,
   evaluated only for a step that holds one: *have 1 then; or given, Fin not NULL; or, with
   `span` not NULL, left to the caller: their range of indices into span[0], span[1]), those
   on its end from xn. */
static void dense_outputs(pass_ctx* c, const casadi_real* x, const casadi_real* xn,
                          const casadi_real* K, casadi_real hs, const casadi_real* u,
                          const casadi_real* p, casadi_real t, casadi_real tn, int nout,
                          const casadi_real* ts, int* j, casadi_real* X, int ldx, int* have,
                          const casadi_real* Fin, int* span) {
  const casadi_real* arg[PASS_NARG + 7];
  casadi_real* res[PASS_NRES + 3];
  casadi_real Fout[7 * PASS_NX];
  int j0 = *j, i;
  while (*j < nout && ts[*j] < tn) ++*j;
  *have = *j > j0;
  if (span) {
    span[0] = j0; span[1] = *j;
  } else if (*have) {
    if (!Fin) {
      arg[0] = x; arg[1] = xn; arg[2] = K; arg[3] = &hs; arg[4] = u; arg[5] = p;
      res[0] = Fout;
      rk8_cont(arg, res, c->iw, c->w, 0);
    }
    dense_fill(x, Fin ? Fin : Fout, t, hs, ts, j0, *j, X, ldx);
  }
  while (*j < nout && ts[*j] == tn) {  /* an output on the step's end */
    for (i = 0; i < PASS_NX; ++i) X[i * ldx + *j] = xn[i];
    ++*j;
  }
}

/* The check of merged step pairs (Richardson on the answer's own steps): its state `rich`
   is RI_T its time, RI_PEND the answer's step not yet merged (0: none), RI_J its outputs
   filled, RI_STEPS its steps, RI_E the sum of the answer's embedded estimates over its
   accepted steps, RI_EC the sum of the check's over its steps, then its x (nx). */
#define RI_T 0
#define RI_PEND 1
#define RI_J 2
#define RI_STEPS 3
#define RI_E 4
#define RI_EC 5
#define RI_HMAX 6
#define RI_X 7
#define RI_SIZE (RI_X + PASS_NX)
/* The answer's longest step under a check: the run's length over this many. On a run of
   few long steps the check is blind: the answer's continuous extension (order 7, its error
   40-75 times the step's own at mid-step) carries most of the error between the step ends,
   and the check's merged steps, of unequal halves where the steps grow from the first one,
   set the small errors of their own extension near their ends against it: the Richardson
   ratio is no longer 2^8 (random linear systems over 0.2-4 time constants on 11-201
   outputs: answers of 4-7 steps verified at estimates 0.02-0.09 with true errors of
   1.02-3.7 tolerances; none of 3,840 + 2,210 batch runs and 2,000 single calls with this
   floor; 8 left one of 2,210 batch runs at 1.16). */
#define RI_STEPS_MIN 12.0

/* DOP853's step with its stages (`rk8_step_k`) of `h` from x under the run's tolerances */
static void dense_step(pass_ctx* c, const casadi_real* x, casadi_real h, const casadi_real* u,
                       const casadi_real* p, casadi_real* xn, casadi_real* err, casadi_real* K) {
  const casadi_real* arg[PASS_NARG + 7];
  casadi_real* res[PASS_NRES + 3];
  arg[0] = x; arg[1] = &h; arg[2] = u; arg[3] = p; arg[4] = &c->rtol; arg[5] = c->atol;
  res[0] = xn; res[1] = err; res[2] = K;
  rk8_step_k(arg, res, c->iw, c->w, 0);
}

/* The rounding of a run's steps emulated at random (`dense_jitter`): after each accepted
   step of h, x_i moves by eps |x_i| + h rate_i (rate_i the run's own measure of its
   right-hand side's rounding so far, `dense_take`), its sign drawn from `stream` */
typedef struct {
  unsigned long long stream;
} dense_jit;

/* A `dense_run` in progress: its arguments and its loop's variables, so that its steps can
   be taken by the step function (`dense_run`) or in the lanes of a vector step
   (`rk8_auto_lanes`) alike: `dense_open`, then per step `dense_next`, the step, `dense_take`
   (and the check's step when `check_due`: `rich_step`, or the step and `rich_take`), then
   `dense_close`. */
typedef struct {
  pass_ctx c;
  casadi_real *x, *t, *count, *rich, *X, *XC;
  const casadi_real *ts, *u, *p;
  casadi_real h, hs, tend, max_steps, due;  /* due: the end of the check's step due */
  const dense_jit* jit;  /* not NULL: each accepted state rounded at random */
  int j, nout, ldx, rejected, last, check_due;
} dense_state;

/* the 64 random bits of stream position k (splitmix64: a hash, so that a run cut into
   calls draws the same bits) */
static unsigned long long dense_bits(unsigned long long k) {
  unsigned long long z = k * 0x9E3779B97F4A7C15ULL + 0x9E3779B97F4A7C15ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

/* the rounding of a step of h emulated on its accepted state x (stochastic arithmetic as
   in Vignes' CESTAC): x_i moved by eps |x_i| (its own rounding) plus h rate_i (the
   right-hand side's rounding over the step: rate_i the largest the run measured so far,
   count[8 + i], `dense_take`), of a random sign per state and step (`dense_bits` of the
   stream and the step's count): the rerun that measures the rounding floor (`au_floor`)
   takes each step's rounding where it arises, so the flow carries it from there on, not
   from the start; it needs nothing of the answer, so it can run alongside it
   (`au_step_spec`) */
static void dense_jitter(const dense_state* s, casadi_real* x, casadi_real h) {
  unsigned long long bits = 0, k = (unsigned long long) s->count[0] * ((PASS_NX + 63) / 64);
  int i;
  for (i = 0; i < PASS_NX; ++i) {
    if (i % 64 == 0) bits = dense_bits((s->jit->stream << 40) + k++);
    x[i] += ((bits >> (i % 64)) & 1 ? -1.0 : 1.0)
            * (DBL_EPSILON * fabs(x[i]) + h * s->count[8 + i]);
  }
}

/* `dense_run`'s start (its arguments); 0 when the run ends at once (count[2] 4: stiff) */
static int dense_open(dense_state* s, casadi_real* x, casadi_real* t, casadi_real hio,
                      int nout, const casadi_real* ts, const casadi_real* u,
                      const casadi_real* p, casadi_real rtol, const casadi_real* atol,
                      casadi_real max_steps, casadi_real* X, int ldx, casadi_real* count,
                      casadi_real stiff_steps, casadi_real* rich, casadi_real* XC,
                      const dense_jit* jit) {
  s->c.p = p; s->c.atol = atol; s->c.rtol = rtol; s->jit = jit;
  s->x = x; s->t = t; s->count = count; s->rich = rich; s->X = X; s->XC = XC;
  s->ts = ts; s->u = u; s->p = p; s->tend = ts[nout - 1]; s->max_steps = max_steps;
  s->j = (int) count[5]; s->nout = nout; s->ldx = ldx; s->rejected = count[6] > 0;
  s->check_due = 0; s->h = hio;
  if (!(s->h > 0)) {
    s->h = dense_first_step(&s->c, x, u, *t, s->tend, count + 7);
    if (count[7] * (s->tend - *t) / 6.0 > stiff_steps) {  /* stability alone: too many steps */
      count[2] = 4;
      return 0;
    }
    if (rich) {  /* under a check: at least RI_STEPS_MIN steps */
      rich[RI_HMAX] = (s->tend - *t) / RI_STEPS_MIN;
      s->h = fmin(s->h, rich[RI_HMAX]);
    }
  }
  return 1;
}

/* the next step: its size s->hs (the proposal, or to the last output: s->last) */
static void dense_next(dense_state* s) {
  s->last = *s->t + 1.01 * s->h >= s->tend;
  s->hs = s->last ? s->tend - *s->t : s->h;
}

/* whether the step of `dense_next`, accepted, holds an output inside (its stages then
   serve the continuous extension) */
static int dense_wants_k(const dense_state* s) {
  return s->j < s->nout && s->ts[s->j] < (s->last ? s->tend : *s->t + s->hs);
}

/* err^(1/8) of an embedded estimate err >= 0 (the controller's; a third of pow's cost, and
   the same bits in a vector lane: `au_vcall`; not finite for err not finite) */
static casadi_real ctl_root(casadi_real err) {
  return sqrt(sqrt(sqrt(err)));
}

/* after the step of s->hs to xn (its estimate err, its root `ctl_root(err)`, stages K: read
   only when `dense_wants_k`, and not when its continuous extension F is given): accepted, its
   outputs (those inside left to the caller with `span` not NULL: their indices in
   [span[0], span[1]), empty when none), the check's pair (a step of the check due to
   s->due: s->check_due), the rounding noise; then the controller. Returns 1 when the run
   stops (its flag in count[2]). */
static int dense_take(dense_state* s, casadi_real* xn, casadi_real err, casadi_real root,
                      const casadi_real* K, const casadi_real* F, int* span) {
  casadi_real *x = s->x, *count = s->count, *rich = s->rich, hs = s->hs, fac, tn;
  int i, have, finite = isfinite(err);
  if (span) span[0] = span[1] = 0;
  for (i = 0; i < PASS_NX && finite; ++i) finite = isfinite(xn[i]);
  fac = finite ? root / 0.9 : 3.0;
  if (finite && err <= 1.0) {
    tn = s->last ? s->tend : *s->t + hs;
    dense_outputs(&s->c, x, xn, K, hs, s->u, s->p, *s->t, tn, s->nout, s->ts, &s->j, s->X,
                  s->ldx, &have, F, span);
    count[4] += have;
    for (i = 0; i < PASS_NX; ++i) x[i] = xn[i];
    *s->t = tn;
    count[0] += 1;
    if (rich) {
      rich[RI_E] += err;
      if (rich[RI_PEND] > 0 || s->last) {  /* a pair (or the lone last step): checked */
        rich[RI_PEND] = 0;
        s->check_due = 1;
        s->due = tn;
      } else {
        rich[RI_PEND] = hs;
      }
    }
    if (((int) count[0]) % DENSE_NOISE_EVERY == 1) {
      casadi_real f0[PASS_NX], f1[PASS_NX], sg = ((int) count[0] / DENSE_NOISE_EVERY) % 2
                                                  ? -DBL_EPSILON : DBL_EPSILON;
      pass_rhs_at(&s->c, x, s->u, f0);
      for (i = 0; i < PASS_NX; ++i) xn[i] = x[i] * (1 + (i % 2 ? -sg : sg));
      pass_rhs_at(&s->c, xn, s->u, f1);
      for (i = 0; i < PASS_NX; ++i)
        if (fabs(f1[i] - f0[i]) > count[8 + i]) count[8 + i] = fabs(f1[i] - f0[i]);
    }
    if (s->jit) dense_jitter(s, x, hs);  /* (after the noise it is measured with) */
    if (hs < count[3] && !s->last) count[3] = hs;
  }
  s->h = ctl_next(hs, s->h, fac, finite && err <= 1.0, &s->rejected, count);
  if (rich && s->h > rich[RI_HMAX]) s->h = rich[RI_HMAX];
  count[2] = ctl_flag(count, s->max_steps, s->h, fmax(fabs(*s->t), fabs(s->tend)), finite);
  return count[2] != 0;
}

/* `dense_run`'s end: the proposal into *hio, the outputs filled and the rejection kept */
static void dense_close(dense_state* s, casadi_real* hio) {
  *hio = s->h;
  s->count[5] = s->j;
  s->count[6] = s->rejected;
}

/* whether the check's step due holds an output inside (as `dense_wants_k`) */
static int rich_wants_k(const dense_state* s) {
  int j = (int) s->rich[RI_J];
  return j < s->nout && s->ts[j] < s->due;
}

/* the check's step due (two of the answer's steps merged, or its lone last step) taken to
   xn (estimate err, stages K: read only when `rich_wants_k`, and not when its continuous
   extension F is given): its outputs into XC */
static void rich_take(dense_state* s, const casadi_real* xn, casadi_real err,
                      const casadi_real* K, const casadi_real* F, int* span) {
  casadi_real* rich = s->rich;
  casadi_real* xc = rich + RI_X;
  int j = (int) rich[RI_J], i, have;
  dense_outputs(&s->c, xc, xn, K, s->due - rich[RI_T], s->u, s->p, rich[RI_T], s->due,
                s->nout, s->ts, &j, s->XC, s->ldx, &have, F, span);
  for (i = 0; i < PASS_NX; ++i) xc[i] = xn[i];
  rich[RI_T] = s->due; rich[RI_J] = j; rich[RI_STEPS] += 1;
  rich[RI_EC] += isfinite(err) ? err : INFINITY;
  s->check_due = 0;
}

/* the check's step due, by the step function */
static void rich_step(dense_state* s) {
  casadi_real xn[PASS_NX], K[12 * PASS_NX], err;
  dense_step(&s->c, s->rich + RI_X, s->due - s->rich[RI_T], s->u, s->p, xn, &err, K);
  rich_take(s, xn, err, K, NULL, NULL);
}

/* one answer step of the run in progress (`dense_next`'s) by the step function, and the
   check's step it makes due at once; 1 when the run stops */
static int dense_advance(dense_state* s) {
  casadi_real xn[PASS_NX], K[12 * PASS_NX], err;
  int stop;
  dense_step(&s->c, s->x, s->hs, s->u, s->p, xn, &err, K);
  stop = dense_take(s, xn, err, ctl_root(err), K, NULL, NULL);
  if (s->check_due) rich_step(s);
  return stop;
}

/* ---- Steps in the lanes of a vector step (`lanes.dense_lanes`: `rk8_step_k` and
   `rk8_cont` rewritten with each value a vector of PASS_LANES doubles, each lane the step
   function's arithmetic in its order: the same bits): a lane is a slot for any step of
   the run's model, an answer's or a check's, of any run. ---- */
typedef double au_vec __attribute__((vector_size(8 * PASS_LANES)));
typedef long long au_lmask __attribute__((vector_size(8 * PASS_LANES)));  /* a lane mask */
typedef int (*au_vstep)(const au_vec** arg, au_vec** res);

/* the vector step's inputs and outputs (those of `rk8_step_k`, a lane per run), then the
   step's continuous extension (`rk8_cont` of x, xn, K, h, u, p); `filled` the lanes that
   hold a step's inputs (a bit each; 0 where declared) */
typedef struct {
  au_vec x[PASS_NX], h, u[PASS_U], p[PASS_NP > 0 ? PASS_NP : 1], rtol, atol[PASS_NX];
  au_vec xn[PASS_NX], err, root, K[12 * PASS_NX], F[7 * PASS_NX];
  int filled;
} au_vio;

#if PASS_WITH_LANES
/* lane l's inputs that hold over a run's answer and its check: the run's control,
   parameters and tolerances (`au_vstep_in` sets a step's own) */
static void au_vrun(au_vio* v, int l, const dense_state* s) {
  int i;
  for (i = 0; i < PASS_NX; ++i) v->atol[i][l] = s->c.atol[i];
  for (i = 0; i < PASS_NU; ++i) v->u[i][l] = s->u[i];
  for (i = 0; i < PASS_NP; ++i) v->p[i][l] = s->p[i];
  v->rtol[l] = s->c.rtol;
}

/* lane l's inputs: a step of h from x (the run's control, parameters and tolerances in
   the lane already: `au_vrun`) */
static void au_vstep_in(au_vio* v, int l, const casadi_real* x, casadi_real h) {
  int i;
  for (i = 0; i < PASS_NX; ++i) v->x[i][l] = x[i];
  v->h[l] = h;
  v->filled |= 1 << l;
}

/* the lanes `took` (all bits set) of the vector step in v start their next step where it
   ended: x = xn there, bit for bit (the others keep x) */
static void au_vkeep(au_vio* v, au_lmask took) {
  int i;
  for (i = 0; i < PASS_NX; ++i)
    v->x[i] = (au_vec) (((au_lmask) v->xn[i] & took) | ((au_lmask) v->x[i] & ~took));
}

/* the vector step of the lanes `use`; a lane not in use computes the inputs it last held
   (a step's: finite values, read by nobody), or, never filled, those of the first in use */
static void au_vcall(au_vstep step, au_vio* v, const int* use) {
  const au_vec* arg[6];
  au_vec* res[3];
  int l, i, f = 0;
  while (!use[f]) ++f;
  for (l = 0; l < PASS_LANES; ++l)
    if (!use[l] && !(v->filled & (1 << l))) {
      v->filled |= 1 << l;
      for (i = 0; i < PASS_NX; ++i) {
        v->x[i][l] = v->x[i][f];
        v->atol[i][l] = v->atol[i][f];
      }
      for (i = 0; i < PASS_U; ++i) v->u[i][l] = v->u[i][f];
      for (i = 0; i < (PASS_NP > 0 ? PASS_NP : 1); ++i) v->p[i][l] = v->p[i][f];
      v->h[l] = v->h[f];
      v->rtol[l] = v->rtol[f];
    }
  arg[0] = v->x; arg[1] = &v->h; arg[2] = v->u; arg[3] = v->p; arg[4] = &v->rtol;
  arg[5] = v->atol;
  res[0] = v->xn; res[1] = &v->err; res[2] = v->K;
  step(arg, res);
  for (l = 0; l < PASS_LANES; ++l)  /* (every lane's `ctl_root` at once) */
    v->root[l] = ctl_root(v->err[l]);
}

/* the continuous extension of the vector step in v (`vcont`) into v->F */
static void au_vext(au_vstep vcont, au_vio* v) {
  const au_vec* arg[6];
  au_vec* res[1];
  arg[0] = v->x; arg[1] = v->xn; arg[2] = v->K; arg[3] = &v->h; arg[4] = v->u; arg[5] = v->p;
  res[0] = v->F;
  vcont(arg, res);
}

/* the continuous extension of the vector step just taken, when a lane of `want` needs it */
static void au_vcont(au_vstep vcont, au_vio* v, const int* want) {
  int l, any = 0;
  for (l = 0; l < PASS_LANES; ++l) any |= want[l];
  if (any) au_vext(vcont, v);
}

/* lane l's outputs: x_next, the estimate and (`withf`) the continuous extension */
static void au_vget(const au_vio* v, int l, casadi_real* xn, casadi_real* err,
                    casadi_real* root, casadi_real* F, int withf) {
  int i;
  for (i = 0; i < PASS_NX; ++i) xn[i] = v->xn[i][l];
  *err = v->err[l];
  *root = v->root[l];
  if (withf)
    for (i = 0; i < 7 * PASS_NX; ++i) F[i] = v->F[i][l];
}

/* draws of a floor a vector step carries beside an answer and its check (`au_step_spec`) */
#define DENSE_VDRAWS (PASS_LANES >= 4 ? 2 : 0)

/* one vector step (`step`, `cont`): the answer's step of the run in progress (lane 0,
   `dense_next`'s; `a` 0: it ended), the check's step due before it (lane 1: a check step
   waits one answer step, so a checked run costs one vector step per answer step, about one
   scalar step, where `dense_advance` takes one and a half) and the next step of each draw
   k of its floor under way (lanes 2 and 3, dl[k] 1: `au_step_spec`; each with its own
   steps and controller, rounded at random by `dense_jitter`; dl[k] set to 0 when draw k
   ends; d NULL: none). The same bits as each run stepped alone. 1 when the answer stops. */
static int dense_advance_v(dense_state* s, int a, dense_state* d, int* dl, au_vio* v,
                           au_vstep step, au_vstep cont) {
  casadi_real xn[PASS_NX], F[7 * PASS_NX], err, root, c0;
  au_lmask took;
  int use[PASS_LANES], want[PASS_LANES], l, k, i, had = a && s->check_due, stop = 0;
  int nd = d ? DENSE_VDRAWS : 0;
  for (l = 0; l < PASS_LANES; ++l) use[l] = want[l] = took[l] = 0;
  /* (the run's inputs, the answer's state and the check's in lanes 0 and 1: `dense_run`) */
  if (a) { use[0] = 1; v->h[0] = s->hs; v->filled |= 1; }
  if (had) { use[1] = 1; v->h[1] = s->due - s->rich[RI_T]; v->filled |= 2; }
  for (k = 0; k < nd; ++k)
    if (dl[k]) { use[2 + k] = 1; v->h[2 + k] = d[k].hs; v->filled |= 4 << k; }
  au_vcall(step, v, use);
  want[0] = a && v->err[0] <= 1.0 && dense_wants_k(s);
  want[1] = had && rich_wants_k(s);
  for (k = 0; k < nd; ++k) want[2 + k] = dl[k] && v->err[2 + k] <= 1.0 && dense_wants_k(&d[k]);
  au_vcont(cont, v, want);
  if (had) {  /* (the check's step due before this answer step) */
    au_vget(v, 1, xn, &err, &root, F, want[1]);
    rich_take(s, xn, err, NULL, F, NULL);
    took[1] = -1;
  }
  if (a) {
    c0 = s->count[0];
    au_vget(v, 0, xn, &err, &root, F, want[0]);
    stop = dense_take(s, xn, err, root, NULL, want[0] ? F : NULL, NULL);
    took[0] = s->count[0] != c0 ? -1 : 0;
  }
  for (k = 0; k < nd; ++k)
    if (dl[k]) {
      c0 = d[k].count[0];
      au_vget(v, 2 + k, xn, &err, &root, F, want[2 + k]);
      if (dense_take(&d[k], xn, err, root, NULL, want[2 + k] ? F : NULL, NULL)
          || d[k].j >= d[k].nout)
        dl[k] = 0;
      took[2 + k] = d[k].count[0] != c0 ? -1 : 0;
    }
  au_vkeep(v, took);
  for (k = 0; k < nd; ++k)  /* (an accepted draw's state was rounded at random after xn) */
    if (took[2 + k])
      for (i = 0; i < PASS_NX; ++i) v->x[i][2 + k] = d[k].x[i];
  return stop;
}
#endif

/* Steps of x (in/out) from time *t (in/out) towards ts[nout - 1], the outputs at the times
   ts (increasing, after the start) in X (nx, ldx); control u throughout; `hio` (in/out) the
   controller's proposed step (<= 0: `dense_first_step`); `count` (in/out): accepted steps,
   rejected steps, flag (as `rk8_adaptive`'s), smallest accepted step, steps whose continuous
   extension was evaluated, outputs filled, 1 after a rejection, the Lipschitz estimate of
   `dense_first_step` (flag 4 when that many times the run's length over DOP853's stability
   interval 6 exceeds `stiff_steps`: no step is taken), then per state the rounding noise
   max |f_i(x (1 + eps s)) - f_i(x)| of the right-hand side at every DENSE_NOISE_EVERY-th
   accepted state (s = +-1 alternating over the states and the samples). At most `budget`
   steps per call (the caller checks for interrupts between calls). Returns the outputs
   filled. The controller is `rk8_adaptive`'s; the last step lands on ts[nout - 1]. With
   `rich` (not NULL) the check of merged step pairs runs alongside (outputs into XC), its
   steps in a lane of the answer's when `step` and `cont` (`lanes.dense_lanes`) are given
   (`dense_advance_v`; a check still due when the run stops or the budget ends is taken
   alone), else by the step function (`dense_advance`). With `jit` (not NULL) each
   accepted state is rounded at random (`dense_jitter`). */
static int dense_run(casadi_real* x, casadi_real* t, casadi_real* hio, int nout,
                     const casadi_real* ts, const casadi_real* u, const casadi_real* p,
                     casadi_real rtol, const casadi_real* atol, casadi_real max_steps,
                     casadi_real* X, int ldx, casadi_real* count, int budget,
                     casadi_real stiff_steps, casadi_real* rich, casadi_real* XC,
                     const dense_jit* jit, au_vstep step, au_vstep cont) {
  dense_state s;
#if PASS_WITH_LANES
  au_vio v;
  v.filled = 0;
#endif
  if (!dense_open(&s, x, t, *hio, nout, ts, u, p, rtol, atol, max_steps, X, ldx, count,
                  stiff_steps, rich, XC, jit))
    return s.j;
#if PASS_WITH_LANES
  if (rich && step) {  /* (the answer's lane 0 and its check's lane 1: one run's inputs;
                          their states, which then follow their steps: `dense_advance_v`) */
    au_vrun(&v, 0, &s);
    au_vrun(&v, 1, &s);
    au_vstep_in(&v, 0, s.x, s.h);
    au_vstep_in(&v, 1, rich + RI_X, s.h);
  }
  while (s.j < nout && budget-- > 0) {
    dense_next(&s);
    if (rich && step ? dense_advance_v(&s, 1, NULL, NULL, &v, step, cont)
                     : dense_advance(&s)) break;
  }
#else
  while (s.j < nout && budget-- > 0) {
    dense_next(&s);
    if (dense_advance(&s)) break;
  }
#endif
  if (s.check_due) rich_step(&s);
  dense_close(&s, hio);
  return s.j;
}
"""


# ``auto`` for a smooth right-hand side under a constant control in ONE call: DOP853 with
# dense output (`_DENSE`) as the answer, its check (its steps merged in pairs, alongside),
# their comparison and the verdict, with no Python between (`dynamics.integrate.dense`, which
# states the rules; the layout of the workspace is `dense.LAYOUT`).
_AUTO = r"""
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#define AU_RTOL 0     /* in: the requested rtol */
#define AU_FACTOR 1   /* in/out: the answer's local tolerance over the requested one */
#define AU_LOOSE 2    /* in/out: the check run's */
#define AU_MAXSTEPS 3 /* in: most steps of all runs */
#define AU_STIFF 4    /* in: `dense_run`'s stiff_steps */
#define AU_T0 5       /* in: the start time */
#define AU_IQ 6       /* in: index of the attitude quaternion, -1: none */
#define AU_TRIES 7    /* in: answer-check pairs at most; 0: the answer alone at the local
                         factor, no check and no verdict (AU_RESULT 2: `method='dop853'`) */
#define AU_PHASE 8    /* 0 start, 1 check run, 2 answer, 4 the answer rounded at random (the
                         rounding floor: `dense_jitter`), 3 done */
#define AU_SPENT 9    /* steps of every run (accepted and rejected) */
#define AU_NCHK 10    /* steps of the check run */
#define AU_NANS 11    /* steps of the answer */
#define AU_RESULT 12  /* 1 verified, 0 not (AU_EST), 2 answered, not checked (AU_TRIES 0),
                         -2 a tolerance below an ulp of the states' size (AU_FMIN > 1), -3 a
                         run failed, -4 an output grid not finite and strictly increasing
                         (no run made: `au_grid_ok`) */
#define AU_EST 13     /* the error estimate [tolerances] */
#define AU_D 14       /* the scaled difference of the answer and the check run */
#define AU_FLAG 15    /* `dense_run`'s flag of a failed run */
#define AU_TRY 16     /* answers made */
#define AU_ACC 17     /* the answer's accepted steps */
#define AU_REJ 18     /* its rejected steps */
#define AU_HMIN 19    /* its smallest step (a last one cut short excluded) */
#define AU_INTERP 20  /* its steps whose continuous extension was evaluated */
#define AU_LIP 21     /* the Lipschitz estimate of its first step */
#define AU_RATIO 22   /* the check's local tolerance over the answer's */
#define AU_BOUND 23   /* the rounding bound added (0: none) */
#define AU_NOUT 24    /* in: outputs after the start */
#define AU_SUB 25     /* the longest output interval over the answer's smallest step */
#define AU_GATE 26    /* the acceptance of the estimate (0.5 or 1) */
#define AU_FLOOR 27   /* the rounding floor measured by a rerun rounded at random (0: none) */
#define AU_ORDER 28   /* the order shown by the embedded estimates of the check's merged
                         steps against the answer's (`au_order`; NaN: not measured) */
#define AU_ULPS 29    /* FLOOR_ULPS ulps of the largest state's size over its least tolerance
                         at the outputs (`au_diff`): the rounding no answer is verified below */
#define AU_PFAC 30    /* the previous answer's local factor (0: none) ... */
#define AU_PEST 31    /* ... and the part of its estimate that the local tolerance controls */
#define AU_FMIN 32    /* the least local factor: the answer's local tolerance kept
                         AU_LOCAL_ULPS ulps above the states' size and at least AU_RTOL_MIN */
#define AU_DRAWS 33   /* the floor's reruns made (`au_floor`) ... */
#define AU_DRAW 34    /* ... and the largest of their differences from the answer */
#define AU_QOFF 35    /* the answer alone (AU_TRIES 0): the most its attitude quaternion's
                         norm is off 1 at the outputs (0: none; `sanity.violation`'s test) */
#define AU_HDR 36
#define AU_ACCEPT 0.5        /* estimates.AUTO_ACCEPT */
#define AU_FLOOR_ULPS 1000.0 /* estimates.FLOOR_ULPS */
#define AU_MEASURED 1e6      /* auto's PASS_MEASURED */
#define AU_DEEP 1e4          /* a retry whose local tolerance lies within this many ulps of
                                the states' size measures the rounding floor: per step the
                                rounding is an ulp against the truncation's AU_DEEP, so it is
                                a part of the difference over N steps only below ~10 sqrt(N)
                                ulps (300 at N = 1000); the near-separatrix tumble that showed
                                it ran at 80 */
#define AU_RTOL_MIN 1e-14    /* stepcontrol.LOCAL_RTOL_MIN */
#define AU_LADDER 1e-2       /* the most a new answer's local tolerance shrinks */
#define AU_LOCAL_ULPS 1.0    /* a local tolerance below this many ulps of a state's size
                                asks DOP853 for less than the state's own rounding */
#define AU_FLOOR_GATE 1.0    /* the acceptance of the estimate with a measured floor on top
                                (as `auto.auto_runs`: truncation within AU_ACCEPT, floor
                                included within the tolerance) */
#define AU_JITTER_RMS 3.5    /* a draw's move of a state (eps |x|, `dense_jitter`: twice the
                                most a rounding to nearest moves it) over that rounding's
                                rms (0.29 ulp, an ulp 0.5-1 eps |x|): at least this, so a
                                draw's difference from the answer is the floor as it is */
#define AU_JITTER_DRAWS 2    /* the most reruns of a floor (the largest counts) */
#define AU_JITTER_SPREAD 30.0 /* the most one draw fell below another: four draws spread 4x
                                 on the 39-state scene (rtol 1e-8), 10x on the near-separatrix
                                 tumble (w0 1e-3), 33x on the hinged scene (rtol 1e-8) */
#define AU_NOISE_EPS 30.0    /* NOISE: an embedded estimate at most this many eps / rtol
                                is rounding */
#define AU_AIM 0.2           /* a new answer's aim [tolerances] */
#define AU_ORDER_LO 5.0      /* the least order of the estimates that shows the method's
                                asymptotic range (DOP853's estimate: 6-8 there) */
#define AU_ORDER_HI 11.0     /* the most */
#define AU_RICHARDSON 127.0  /* |answer - check| over this is the answer's error in that
                                range: 2^p - 1 for the check's merged steps, p = 7 (the
                                method's order is 8: 2x conservative) */
/* the workspace after the header: x0, u, p, atol, ts (AU_NOUT), then the run's x, t, h,
   count (8 + nx), local atol, the answer's noise, the check's state (`RI_SIZE`) */
#define AU_X0(w) ((w) + AU_HDR)
#define AU_U(w) (AU_X0(w) + PASS_NX)
#define AU_P(w) (AU_U(w) + PASS_NU)
#define AU_ATOL(w) (AU_P(w) + PASS_NP)
#define AU_TS(w) (AU_ATOL(w) + PASS_NX)
#define AU_XR(w) (AU_TS(w) + (int) (w)[AU_NOUT])
#define AU_TT(w) (AU_XR(w) + PASS_NX)
#define AU_H(w) (AU_TT(w) + 1)
#define AU_COUNT(w) (AU_H(w) + 1)
#define AU_AL(w) (AU_COUNT(w) + 8 + PASS_NX)
#define AU_NOISE(w) (AU_AL(w) + PASS_NX)
#define AU_RICH(w) (AU_NOISE(w) + PASS_NX)
/* the floor's draws alongside the answer (`au_step_spec`): 0 none, 1 due, 2 under way */
#define AU_SPEC(w) (AU_RICH(w) + RI_SIZE)
/* draw k alongside: its x (nx), t, h and count (8 + nx) */
#define AU_DSZ (2 * PASS_NX + 10)
#define AU_DS(w, k) (AU_SPEC(w) + 1 + (k) * AU_DSZ)
#define AU_SIZE(nout) (AU_HDR + 11 * PASS_NX + PASS_NU + PASS_NP + (nout) + 38)

/* `estimates.carried`'s growth 2 sqrt(T min(T, 1 / L)) of a rounding rate over the horizon
   T (L: the answer's Lipschitz estimate) */
static casadi_real au_carry(const casadi_real* w) {
  casadi_real horizon = AU_TS(w)[(int) w[AU_NOUT] - 1] - w[AU_T0], lip = w[AU_LIP];
  return 2 * sqrt(horizon * (lip <= 0 ? horizon : fmin(horizon, 1.0 / lip)));
}

/* a run from x0 at the local tolerance (rtol, atol) factor (the check's state reset) */
static void au_begin(casadi_real* w, casadi_real factor) {
  casadi_real* count = AU_COUNT(w);
  casadi_real* rich = AU_RICH(w);
  int i;
  for (i = 0; i < PASS_NX; ++i) {
    AU_XR(w)[i] = AU_X0(w)[i];
    AU_AL(w)[i] = AU_ATOL(w)[i] * factor;
    rich[RI_X + i] = AU_X0(w)[i];
  }
  for (i = 0; i < RI_X; ++i) rich[i] = 0;
  rich[RI_T] = w[AU_T0];
  *AU_TT(w) = w[AU_T0];
  *AU_H(w) = 0;
  for (i = 0; i < 8 + PASS_NX; ++i) count[i] = 0;
  count[3] = INFINITY;
}

#if PASS_WITH_LANES && PASS_LANES >= 4
/* whether an answer's floor is likely measured (`au_judge`: when the rounding it carries
   over the horizon, `au_carried`, exceeds a tenth of the acceptance): that rounding as
   the right-hand side's at x0 gives it (`dense_take`'s measure there; `lip` the answer's
   Lipschitz estimate), with 10x to spare. Only where the draws run (alongside the answer,
   or after it when needed) depends on it, never their bits. */
static int au_deep(const casadi_real* w);

static int au_likely(const casadi_real* w, pass_ctx* c, casadi_real lip) {
  casadi_real f0[PASS_NX], f1[PASS_NX], xs[PASS_NX], noise = 0, lmin = INFINITY, T;
  const casadi_real* x0 = AU_X0(w);
  int i;
  pass_rhs_at(c, x0, AU_U(w), f0);
  for (i = 0; i < PASS_NX; ++i) xs[i] = x0[i] * (1 + (i % 2 ? -DBL_EPSILON : DBL_EPSILON));
  pass_rhs_at(c, xs, AU_U(w), f1);
  for (i = 0; i < PASS_NX; ++i) {
    noise = fmax(noise, fabs(f1[i] - f0[i]));
    lmin = fmin(lmin, AU_ATOL(w)[i] + w[AU_RTOL] * fabs(x0[i]));
  }
  T = AU_TS(w)[(int) w[AU_NOUT] - 1] - w[AU_T0];
  noise *= 2 * sqrt(T * (lip <= 0 ? T : fmin(T, 1.0 / lip))) * (1 + lip * T);
  return !(noise <= 0.01 * AU_ACCEPT * lmin);
}

/* `au_step` of an answer with its check, and alongside them in the free lanes of
   their vector step, both draws of the floor it may need (`au_may_floor`), begun from x0
   as `au_begin` begins a rerun, into XD (2, nx, nout + 1): the lanes cost the answer's
   steps nothing, so a floor that a rerun after the answer measured is measured during it.
   The draws' own bookkeeping is not free (a tumbling body's call 25 % longer), so they
   run alongside (AU_SPEC 1 -> 2) only when the floor is likely measured: a retry within
   AU_DEEP ulps (measured whenever accepted), or `au_likely`; else (AU_SPEC 0) after the
   answer when it is. At most *budget vector steps; 1 when the answer failed, or it and
   both draws ended (`au_spec_floor` judges them; a draw not needed is not counted). */
static int au_step_spec(casadi_real* w, casadi_real factor, casadi_real* X, int* budget,
                        casadi_real* XC, casadi_real* XD, au_vstep step, au_vstep cont) {
  casadi_real* count = AU_COUNT(w);
  casadi_real *ds, *dc, rtol = w[AU_RTOL] * factor, most = w[AU_MAXSTEPS] - w[AU_SPENT];
  int nout = (int) w[AU_NOUT], ld = nout + 1, k, i, a, oa, od[2], dl[2], stop;
  dense_state s, d[2];
  dense_jit jit[2];
  au_vio v;
  v.filled = 0;
  oa = count[2] == 0 && count[5] < nout
       && dense_open(&s, AU_XR(w), AU_TT(w), *AU_H(w), nout, AU_TS(w), AU_U(w), AU_P(w),
                     rtol, AU_AL(w), most, X + 1, ld, count, w[AU_STIFF], AU_RICH(w),
                     XC + 1, NULL);
  if (count[2] != 0) return 1;  /* (failed: no floor is wanted) */
  if (*AU_SPEC(w) == 1) {  /* (the answer opened: its Lipschitz estimate in count[7]) */
    *AU_SPEC(w) = (w[AU_TRY] >= 1 && au_deep(w)) || au_likely(w, &s.c, count[7]) ? 2 : 0;
    for (k = 0; k < 2 && *AU_SPEC(w) == 2; ++k) {
      ds = AU_DS(w, k);
      for (i = 0; i < PASS_NX; ++i) ds[i] = XD[((size_t) k * PASS_NX + i) * ld] = AU_X0(w)[i];
      ds[PASS_NX] = w[AU_T0];
      for (i = PASS_NX + 1; i < AU_DSZ; ++i) ds[i] = 0;
      ds[PASS_NX + 2 + 3] = INFINITY;
    }
  }
  a = oa && s.j < nout;
  if (oa) {
    au_vrun(&v, 0, &s);
    au_vrun(&v, 1, &s);
    au_vstep_in(&v, 0, s.x, s.h);
    au_vstep_in(&v, 1, AU_RICH(w) + RI_X, s.h);
  }
  for (k = 0; k < 2; ++k) {
    ds = AU_DS(w, k);
    dc = ds + PASS_NX + 2;
    jit[k].stream = (unsigned long long) k;
    od[k] = *AU_SPEC(w) == 2 && dc[2] == 0 && dc[5] < nout
            && dense_open(&d[k], ds, ds + PASS_NX, ds[PASS_NX + 1], nout, AU_TS(w), AU_U(w),
                          AU_P(w), rtol, AU_AL(w), most, XD + (size_t) k * PASS_NX * ld + 1,
                          ld, dc, w[AU_STIFF], NULL, NULL, &jit[k]);
    dl[k] = od[k] && d[k].j < nout;
    if (dl[k]) {
      au_vrun(&v, 2 + k, &d[k]);
      au_vstep_in(&v, 2 + k, d[k].x, d[k].h);
    }
  }
  while ((a || dl[0] || dl[1]) && (*budget)-- > 0) {
    if (a) dense_next(&s);
    for (k = 0; k < 2; ++k)
      if (dl[k]) dense_next(&d[k]);
    stop = dense_advance_v(&s, a, d, dl, &v, step, cont);
    if (a && (stop || s.j >= nout)) {
      if (count[2] != 0) break;  /* (the answer failed) */
      a = 0;
    }
  }
  if (oa) {
    if (s.check_due) rich_step(&s);
    dense_close(&s, AU_H(w));
  }
  for (k = 0; k < 2; ++k)
    if (od[k]) dense_close(&d[k], AU_DS(w, k) + PASS_NX + 1);
  if (count[2] != 0) return 1;
  if (count[5] < nout) return 0;
  for (k = 0; k < 2; ++k) {
    dc = AU_DS(w, k) + PASS_NX + 2;
    if (dc[2] == 0 && dc[5] < nout) return 0;
  }
  return 1;
}
#endif

/* `dense_run` on the run in progress into Y (nx, nout + 1) at local factor `factor`, at
   most *budget steps, with the check of merged step pairs into XC when `check`; a retried
   answer whose floor's draws are due alongside (AU_SPEC) with them into XD (2, nx,
   nout + 1) when the vector lanes are given (`au_step_spec`); returns 1 when it ended
   (finished or failed) */
static int au_step(casadi_real* w, casadi_real factor, casadi_real* Y, int* budget,
                   int check, casadi_real* XC, au_vstep step, au_vstep cont,
                   casadi_real* XD) {
  casadi_real* count = AU_COUNT(w);
  int nout = (int) w[AU_NOUT], j;
  casadi_real before = count[0] + count[1];
  dense_jit jit;
#if PASS_WITH_LANES && PASS_LANES >= 4
  if (w[AU_PHASE] == 2 && *AU_SPEC(w) > 0 && check && step && XD)
    return au_step_spec(w, factor, Y, budget, XC, XD, step, cont);
#endif
  jit.stream = (unsigned long long) w[AU_DRAWS];  /* (the floor's draw, in phase 4) */
  j = dense_run(AU_XR(w), AU_TT(w), AU_H(w), nout, AU_TS(w), AU_U(w), AU_P(w),
                w[AU_RTOL] * factor, AU_AL(w), w[AU_MAXSTEPS] - w[AU_SPENT], Y + 1, nout + 1,
                count, *budget, w[AU_STIFF], check ? AU_RICH(w) : NULL, XC + 1,
                w[AU_PHASE] == 4 ? &jit : NULL, step, cont);
  *budget -= (int) (count[0] + count[1] - before);
  return j >= nout || count[2] != 0;
}

/* the largest |x_i| / (atol_i + rtol |x_i|) at x0 (`auto.sizes_over_tolerance`) */
static casadi_real au_size(const casadi_real* w) {
  const casadi_real* x0 = AU_X0(w);
  const casadi_real* at = AU_ATOL(w);
  casadi_real rtol = w[AU_RTOL], out = 0, s, l, qn = 0;
  int i, iq = (int) w[AU_IQ];
  if (iq >= 0) for (i = iq; i < iq + 4; ++i) qn += x0[i] * x0[i];
  qn = sqrt(qn);
  for (i = 0; i < PASS_NX; ++i) {
    int inq = iq >= 0 && i >= iq && i < iq + 4;
    s = inq ? qn : fabs(x0[i]);
    l = inq ? at[i] : at[i] + rtol * s;
    if (s > 0) out = fmax(out, l > 0 ? s / l : INFINITY);
  }
  return out;
}

/* whether the answer's local tolerance lies within AU_DEEP ulps of the states' size */
static int au_deep(const casadi_real* w) {
  return au_size(w) / w[AU_FACTOR] * DBL_EPSILON * AU_DEEP > 1.0;
}

/* whether the answer about to begin (AU_TRY made before it) may have its floor measured
   (`au_judge`): the requested tolerance within AU_MEASURED ulps of the states' size, or,
   for a retry, its local one within AU_DEEP */
static int au_may_floor(const casadi_real* w) {
  return au_size(w) * DBL_EPSILON * AU_MEASURED > 1.0 || (w[AU_TRY] >= 1 && au_deep(w));
}

/* the largest |X - Y| / (atol + rtol |X|) over the states and the outputs after the first
   (inf for a non-finite one); *ulps: 1000 ulps of the largest state's size over its least
   tolerance (`estimates.roundoff`), *lmin the least tolerance */
static casadi_real au_diff(const casadi_real* w, const casadi_real* X, const casadi_real* Y,
                           casadi_real* ulps, casadi_real* lmin) {
  int ld = (int) w[AU_NOUT] + 1, i, j;
  casadi_real rtol = w[AU_RTOL], d = 0, sc, size, smin, e;
  *ulps = 0; *lmin = INFINITY;
  for (i = 0; i < PASS_NX; ++i) {
    size = fabs(X[i * ld]);
    smin = INFINITY;
    for (j = 1; j < ld; ++j) {
      casadi_real xa = X[i * ld + j];
      if (fabs(xa) > size) size = fabs(xa);
      sc = AU_ATOL(w)[i] + rtol * fabs(xa);
      if (sc < smin) smin = sc;
      e = fabs(xa - Y[i * ld + j]);
      e = sc > 0 ? e / sc : (e == 0 ? 0 : INFINITY);
      if (e != e) e = INFINITY;
      if (e > d) d = e;
    }
    e = smin > 0 ? size / smin : (size > 0 ? INFINITY : 0);
    if (e > *ulps) *ulps = e;
    if (smin < *lmin) *lmin = smin;
  }
  *ulps *= AU_FLOOR_ULPS * DBL_EPSILON;
  return d;
}

/* the rounding the answer measured on its way (AU_NOISE, per state), carried over the
   horizon (`estimates.carried`), into AU_NOISE; returns its largest */
static casadi_real au_carried(casadi_real* w) {
  int i;
  casadi_real carry = au_carry(w), out = 0;
  for (i = 0; i < PASS_NX; ++i) {
    AU_NOISE(w)[i] *= carry;
    if (AU_NOISE(w)[i] > out) out = AU_NOISE(w)[i];
  }
  return out;
}

/* the verdict on the estimate `est` (AU_RESULT, AU_PHASE); not accepted, the next answer,
   tighter, or done. The next local factor is predicted from the part of the estimate the
   local tolerance controls (`est` less the rounding AU_ULPS and AU_BOUND, which no tighter
   tolerance lowers): DOP853's global error follows its local tolerance about linearly
   (tolerance proportionality: its error estimate is of the step's order, measured slope
   0.9-1.1 over 1e-5..1 of rtol on torque-free bodies and the hinged scene), so the first
   retry scales the factor by aim / part; a later one by the slope measured between the last
   two answers (within [0.5, 2]). The aim is AU_AIM, less where the rounding takes more of
   the acceptance (half what it leaves); at most AU_LADDER tighter per answer, never below
   AU_FMIN. No answer is made when the rounding alone takes 90 % of the acceptance, or the
   factor cannot shrink by 1.5 (at AU_FMIN): the tolerance lies at the rounding floor. */
static void au_verdict(casadi_real* w, casadi_real est) {
  casadi_real e, part, aim, slope = 1, rounding = w[AU_ULPS] + w[AU_BOUND];
  w[AU_EST] = est;
  w[AU_PHASE] = 3;
  if (est <= w[AU_GATE]) {
    w[AU_RESULT] = 1;
    return;
  }
  w[AU_RESULT] = 0;
  if (!isfinite(est) || w[AU_TRY] >= w[AU_TRIES] || w[AU_FLOOR] > 0) return;
  part = est - rounding;
  aim = fmin(AU_AIM, 0.5 * (AU_ACCEPT - rounding));
  if (!(aim > 0.05 * AU_ACCEPT) || !(part > 0)) return;
  if (w[AU_PFAC] > w[AU_FACTOR] && w[AU_PEST] > part)
    slope = fmin(2.0, fmax(0.5, log(w[AU_PEST] / part) / log(w[AU_PFAC] / w[AU_FACTOR])));
  e = fmax(AU_LADDER, fmin(0.5, pow(aim / part, 1.0 / slope)));
  e = fmax(e, w[AU_FMIN] / w[AU_FACTOR]);
  if (!(e <= 1.0 / 1.5)) return;
  w[AU_PFAC] = w[AU_FACTOR]; w[AU_PEST] = part;
  w[AU_FACTOR] *= e;
  w[AU_LOOSE] = w[AU_FACTOR];
  au_begin(w, w[AU_FACTOR]);
  *AU_SPEC(w) = au_may_floor(w);
  w[AU_PHASE] = 2;
}

/* the order the check's merged steps show: log2 of 2 x the sum of their embedded estimates
   over the answer's sum (twice the steps; a step of 2h has 2^p the estimate of one of h);
   NaN when the answer's are rounding (at most NOISE eps / rtol) or a sum is not finite */
static casadi_real au_order(const casadi_real* w, const casadi_real* rich) {
  casadi_real e = rich[RI_E], ec = rich[RI_EC];
  casadi_real noise = AU_NOISE_EPS * DBL_EPSILON / (w[AU_RTOL] * w[AU_FACTOR]);
  if (!(e > noise * w[AU_ACC]) || !isfinite(ec) || !(ec > 0)) return NAN;
  return log2(2 * ec / e);
}

/* the answer X against the check XC (its steps merged in pairs): AU_D, AU_EST and the
   verdict; near the states' rounding (within 1e6 ulps) the model's rounding measured on
   the way, carried over the horizon, is added when small (`estimates.screen`), else
   measured: the answer repeated with each step's rounding emulated at random (phase 4,
   `dense_jitter`, into XC, judged by `au_floor`; or its draws made alongside it, in XD:
   `au_spec_floor`) */
static void au_spec_floor(casadi_real* w, casadi_real* X, casadi_real* XD);

static void au_judge(casadi_real* w, casadi_real* X, casadi_real* XC, casadi_real* XD) {
  int nout = (int) w[AU_NOUT], deep;
  casadi_real d, ulps, lmin, e, est, horizon, lip = w[AU_LIP], order;
  d = au_diff(w, X, XC, &ulps, &lmin);
  w[AU_ULPS] = ulps;
  order = au_order(w, AU_RICH(w));
  w[AU_ORDER] = order;
  if (order >= AU_ORDER_LO && order <= AU_ORDER_HI) {  /* Richardson */
    est = d / AU_RICHARDSON + ulps;
    w[AU_GATE] = AU_ACCEPT;
  } else {  /* (no order shown: the difference itself) */
    est = d + ulps;
    w[AU_GATE] = 1.0;
  }
  w[AU_D] = d; w[AU_RATIO] = 2; w[AU_BOUND] = 0; w[AU_FLOOR] = 0;
  /* a retry whose local tolerance lies within AU_DEEP ulps of the states' size: the
     difference of the answer and its check may be rounding the flow amplified, which the
     Richardson division would hide (near a separatrix: 20 tolerances estimated at 0.18):
     the floor is measured, not modelled */
  deep = w[AU_TRY] > 1 && au_deep(w);
  if (est <= w[AU_GATE] && (deep || au_size(w) * DBL_EPSILON * AU_MEASURED > 1.0)) {
    horizon = AU_TS(w)[nout - 1] - w[AU_T0];
    e = au_carried(w);
    e = lmin > 0 ? e / lmin : (e > 0 ? INFINITY : 0);
    e *= 1 + lip * horizon;
    if (e <= 0.1 * AU_ACCEPT && !deep) {
      w[AU_BOUND] = e;
      est += e;
    } else {  /* the flow's real amplification: the answer again, rounded at random */
      w[AU_EST] = est;
      w[AU_DRAWS] = 0; w[AU_DRAW] = 0;
      if (*AU_SPEC(w) == 2) {  /* (its draws ran alongside it) */
        au_spec_floor(w, X, XD);
        return;
      }
      au_begin(w, w[AU_FACTOR]);
      w[AU_PHASE] = 4;
      return;
    }
  }
  au_verdict(w, est);
}

/* after a rerun rounded at random (in XC, draw AU_DRAWS): the floor is the largest of
   the draws' differences from the answer (a draw of the rounding's random walk, the
   answer's own another; the margin is in the draw's moves: AU_JITTER_RMS), the carried rounding
   against the least tolerance and the ulps (as `estimates.measured_floor`), in the
   estimate in place of the ulps; accepted within AU_FLOOR_GATE (the truncation estimate
   was within the acceptance: the rerun is made only then). A draw may fall far below
   another (AU_JITTER_SPREAD), so below the answer's own rounding by that over
   AU_JITTER_RMS: a second is drawn unless the first already rejects (a second only raises
   the floor) or accepts with that to spare. Returns 1 when the second is wanted (the
   verdict waits for it). */
static int au_floor(casadi_real* w, casadi_real* X, casadi_real* XC) {
  casadi_real ulps, lmin, d = au_diff(w, X, XC, &ulps, &lmin), local = 0, drawn, fixed, base;
  int i;
  for (i = 0; i < PASS_NX; ++i) local = fmax(local, AU_NOISE(w)[i]);
  local = lmin > 0 ? local / lmin : (local > 0 ? INFINITY : 0);
  w[AU_DRAWS] += 1;
  drawn = fmax(w[AU_DRAW], d);  /* (the draws' part; the rest is fixed) */
  w[AU_DRAW] = drawn;
  fixed = fmax(local, ulps);
  w[AU_FLOOR] = fmax(drawn, fixed);
  /* (the floor replaces the ulps in the estimate: it is at least them) */
  w[AU_GATE] = AU_FLOOR_GATE;
  base = w[AU_EST] - ulps;
  if (w[AU_DRAWS] < AU_JITTER_DRAWS && base + w[AU_FLOOR] <= w[AU_GATE]
      && base + fmax(AU_JITTER_SPREAD / AU_JITTER_RMS * drawn, fixed) > w[AU_GATE])
    return 1;
  au_verdict(w, base + w[AU_FLOOR]);
  return 0;
}

/* the floor from the draws made alongside the answer (`au_step_spec`, XD), judged in turn
   by `au_floor` as the reruns after it are: a draw's steps counted when it is judged; a
   draw that failed, or took more steps than the rerun in its place may (the max_steps
   left then), is not verified */
static void au_spec_floor(casadi_real* w, casadi_real* X, casadi_real* XD) {
  int ld = (int) w[AU_NOUT] + 1, k;
  casadi_real *dc, n, most;
  for (k = 0; k < AU_JITTER_DRAWS; ++k) {
    dc = AU_DS(w, k) + PASS_NX + 2;
    n = dc[0] + dc[1];
    most = w[AU_MAXSTEPS] - w[AU_SPENT];
    if (n > most) n = fmax(floor(most), 0) + 1;  /* (where `ctl_flag` stops the rerun) */
    w[AU_SPENT] += n;
    if (dc[2] != 0 || dc[0] + dc[1] > most) {
      au_verdict(w, INFINITY);
      return;
    }
    if (!au_floor(w, X, XD + (size_t) k * PASS_NX * ld)) return;
  }
}

/* whether the output grid (AU_T0, then the AU_NOUT times AU_TS) is finite and strictly
   increasing, as `inputs.check_t` asks: `simulate`'s common call hands its grid over
   unchecked, and a grid that is not is left to `check_t` to word (AU_RESULT -4) */
static int au_grid_ok(const casadi_real* w) {
  const casadi_real* ts = AU_TS(w);
  casadi_real last = w[AU_T0];
  int j, nout = (int) w[AU_NOUT];
  if (!isfinite(last)) return 0;
  for (j = 0; j < nout; last = ts[j++])
    if (!(ts[j] > last)) return 0;  /* (NaN fails the comparison) */
  return isfinite(last);
}

/* AU_SUB: the longest output interval over the answer's smallest step */
static void au_substeps(casadi_real* w) {
  const casadi_real* ts = AU_TS(w);
  casadi_real e = ts[0] - w[AU_T0];
  int j, nout = (int) w[AU_NOUT];
  for (j = 1; j < nout; ++j)
    if (ts[j] - ts[j - 1] > e) e = ts[j] - ts[j - 1];
  w[AU_SUB] = w[AU_HMIN] < INFINITY ? ceil(e / w[AU_HMIN]) : 1;
}

/* AU_QOFF of the answer X (nx, nout + 1): max over its outputs of | |q| - 1 | (the sums of
   squares in `sanity._quat_off`'s order, no contraction: the same bits) */
static void au_quat_off(casadi_real* w, const casadi_real* X) {
  int j, iq = (int) w[AU_IQ], ld = (int) w[AU_NOUT] + 1;
  casadi_real off = 0, a, b, c, d, e;
  if (iq >= 0)
    for (j = 0; j < ld; ++j) {
      a = X[iq * ld + j]; b = X[(iq + 1) * ld + j]; c = X[(iq + 2) * ld + j];
      d = X[(iq + 3) * ld + j];
      e = fabs(sqrt(a * a + b * b + c * c + d * d) - 1.0);
      if (!(e <= off)) off = e;  /* (a NaN is kept) */
    }
  w[AU_QOFF] = off;
}

/* `rk8_auto`'s start (AU_PHASE 0): the header reset, the first answer begun (AU_PHASE 2);
   1 when no run is made (AU_RESULT -2 or -4, AU_PHASE 3) */
static int au_start(casadi_real* w, int nout, casadi_real* X, casadi_real* XC) {
  int i, ld = nout + 1;
  w[AU_SPENT] = 0; w[AU_TRY] = 0; w[AU_RESULT] = 0; w[AU_FLAG] = 0; w[AU_EST] = NAN;
  w[AU_BOUND] = 0; w[AU_FLOOR] = 0; w[AU_ULPS] = 0; w[AU_PFAC] = 0; w[AU_PEST] = 0;
  w[AU_DRAWS] = 0; w[AU_DRAW] = 0; w[AU_QOFF] = 0; *AU_SPEC(w) = 0;
  if (!au_grid_ok(w)) {
    w[AU_RESULT] = -4; w[AU_PHASE] = 3;
    return 1;
  }
  for (i = 0; i < PASS_NX; ++i) X[i * ld] = XC[i * ld] = AU_X0(w)[i];
  /* the local tolerance kept AU_LOCAL_ULPS ulps above the states' size (a tighter one asks
     for less than DOP853's rounding) and at least AU_RTOL_MIN; a requested tolerance
     itself below that: no run (-2) */
  w[AU_FMIN] = w[AU_TRIES] <= 0 ? 0  /* (the answer alone: at the tolerance asked) */
    : fmax(au_size(w) * DBL_EPSILON * AU_LOCAL_ULPS, AU_RTOL_MIN / w[AU_RTOL]);
  if (w[AU_FMIN] > 1.0) {
    w[AU_RESULT] = -2; w[AU_PHASE] = 3;
    return 1;
  }
  if (w[AU_FACTOR] < w[AU_FMIN]) w[AU_FACTOR] = w[AU_FMIN];
  w[AU_LOOSE] = w[AU_FACTOR];
  au_begin(w, w[AU_FACTOR]);
  *AU_SPEC(w) = au_may_floor(w);
  w[AU_PHASE] = 2;
  return 0;
}

/* `rk8_auto` after a run ended (an answer with its check, or the rerun rounded at random:
   `floor`; `plain`: the answer alone): its steps counted, then the verdict, a retry or the
   rerun (AU_PHASE) */
static void au_ended(casadi_real* w, casadi_real* X, casadi_real* XC, int floor, int plain,
                     casadi_real* XD) {
  casadi_real* count = AU_COUNT(w);
  int i;
  w[AU_SPENT] += count[0] + count[1] + (floor ? 0 : AU_RICH(w)[RI_STEPS]);
  if (count[2] != 0 && floor) {  /* (no floor: not verified) */
    au_verdict(w, INFINITY);
    return;
  }
  if (count[2] != 0) {
    w[AU_FLAG] = count[2]; w[AU_RESULT] = -3; w[AU_PHASE] = 3;
    return;
  }
  if (floor) {
    if (au_floor(w, X, XC)) au_begin(w, w[AU_FACTOR]);  /* (phase 4 again, the next draw) */
    return;
  }
  w[AU_NCHK] = AU_RICH(w)[RI_STEPS];
  w[AU_NANS] = count[0] + count[1];
  w[AU_ACC] = count[0]; w[AU_REJ] = count[1]; w[AU_HMIN] = count[3];
  w[AU_INTERP] = count[4]; w[AU_LIP] = count[7];
  for (i = 0; i < PASS_NX; ++i) AU_NOISE(w)[i] = count[8 + i];
  w[AU_TRY] += 1;
  au_substeps(w);
  if (plain) {  /* the answer alone: not checked */
    w[AU_RESULT] = 2; w[AU_EST] = NAN; w[AU_PHASE] = 3;
    au_quat_off(w, X);
    return;
  }
  au_judge(w, X, XC, XD);
}

/* The whole of `dense.dense_auto` for one problem: the answer into X (nx, nout + 1; column
   0 = x0) and, alongside, its check (its steps merged in pairs) into XC, compared; at most
   `budget` steps per call (interrupts are looked at between calls); with `vstep` and
   `vcont` (`lanes.dense_lanes`, else NULL) the check's steps ride in a lane of the
   answer's (`dense_advance_v`: the same bits), and with XD (2, nx, nout + 1; else NULL)
   a retried answer's floor is drawn in the two lanes left (`au_step_spec`: the same bits
   as the reruns after it). Returns AU_PHASE (3: done). */
int rk8_auto_v(casadi_real* w, int nout, int budget, casadi_real* X, casadi_real* XC,
               void* vstep, void* vcont, casadi_real* XD) {
  w[AU_NOUT] = nout;
  if (w[AU_PHASE] == 0 && au_start(w, nout, X, XC)) return 3;
  while (budget > 0 && w[AU_PHASE] != 3) {
    int floor = w[AU_PHASE] == 4, plain = w[AU_TRIES] <= 0;
    if (au_step(w, w[AU_FACTOR], floor ? XC : X, &budget, !floor && !plain, XC,
                (au_vstep) vstep, (au_vstep) vcont, XD))
      au_ended(w, X, XC, floor, plain, XD);
  }
  return (int) w[AU_PHASE];
}

/* `rk8_auto_v` with the step function alone */
int rk8_auto(casadi_real* w, int nout, int budget, casadi_real* X, casadi_real* XC) {
  return rk8_auto_v(w, nout, budget, X, XC, NULL, NULL, NULL);
}

/* the workspace wk of run k of a batch: the shared inputs of w with the run's x0, u and
   p (K rows of nx, max(nu, 1) and max(np, 1)), at its start (AU_PHASE 0) */
static void au_load(casadi_real* wk, const casadi_real* w, int size, size_t k,
                    const casadi_real* x0, const casadi_real* u, const casadi_real* p) {
  int i;
  for (i = 0; i < size; ++i) wk[i] = w[i];
  for (i = 0; i < PASS_NX; ++i) AU_X0(wk)[i] = x0[k * PASS_NX + i];
  for (i = 0; i < PASS_NU; ++i) AU_U(wk)[i] = u[k * PASS_U + i];
  for (i = 0; i < PASS_NP; ++i) AU_P(wk)[i] = p[k * (PASS_NP > 0 ? PASS_NP : 1) + i];
  wk[AU_PHASE] = 0;
}

/* The next run of a batch for a loop of `rk8_auto_many` or `rk8_auto_lanes`: the runs are
   runs[0] ... runs[n - 1] (rows of x0, u, p, X and res), handed out one at a time through
   the counter *cursor that the loops of every thread share (an atomic increment: a thread
   takes the next run as soon as it has room, so the threads finish together); -1 when
   every run is handed out. */
static long long au_claim(const long long* runs, long long n, long long* cursor) {
  long long i = __atomic_fetch_add(cursor, 1, __ATOMIC_RELAXED);
  return i < n ? runs[i] : -1;
}

/* `rk8_auto` for runs of a batch (`au_claim`: runs[0 ... n - 1] through the shared
   `cursor`), one after another, each with its own steps and verdict: x0 (K, nx), u (K,
   nu), p (K, np) by run; the workspace `w` (its inputs but x0, u, p set) copied to `wk`
   for each; X (K, nx, nout + 1) the answers; XC (nx, nout + 1) scratch; `res` (K, AU_HDR)
   each run's header. No run is taken once the runs done have spent `budget` steps (0: no
   limit), so that the caller can look at Ctrl-C between calls. Returns 1 when every run
   is handed out, 0 when the budget stopped it first (-1: no memory). */
int rk8_auto_many(const casadi_real* w, int nout, const long long* runs, long long n,
                  long long* cursor, double budget, const casadi_real* x0,
                  const casadi_real* u, const casadi_real* p, casadi_real* X, casadi_real* XC,
                  casadi_real* res) {
  int size = AU_SIZE(nout), i, ld = nout + 1;
  long long k;
  double spent = 0;
  casadi_real* wk = (casadi_real*) malloc(sizeof(casadi_real) * size);
  if (!wk) return -1;
  for (;;) {
    if (budget > 0 && spent >= budget) break;
    if ((k = au_claim(runs, n, cursor)) < 0) {
      free(wk);
      return 1;
    }
    au_load(wk, w, size, (size_t) k, x0, u, p);
    rk8_auto(wk, nout, INT_MAX, X + (size_t) k * PASS_NX * ld, XC);
    for (i = 0; i < AU_HDR; ++i) res[(size_t) k * AU_HDR + i] = wk[i];
    spent += wk[AU_SPENT];
  }
  free(wk);
  return 0;
}

#if PASS_WITH_LANES
/* ---- `rk8_auto_many` with PASS_LANES runs stepped at once in the lanes of a vector step:
   `lanes.lane_source`'s `rk8_step_k` and `rk8_cont`, each lane a run's own arithmetic in
   the order of the step function (the same bits). Each lane keeps its own steps,
   controller, outputs and check (`dense_state`); a lane whose run ended takes the next
   run. The continuous extensions of the lanes' steps that hold an output are gathered four
   to a vector call (`au_pend`). ---- */
/* a lane: its run k (-1: none), that run's workspace, answer and check outputs, and its
   `dense_run` in progress (`opened` 0: it ended at its start) */
typedef struct {
  dense_state s;
  dense_jit jit;  /* its floor's rerun's (`dense_jitter`) */
  casadi_real *w, *X, *XC;
  long k;
  int opened, ended, floor, fresh, lane;  /* fresh: opened since its lane took `au_vrun` */
} au_lane;

/* Continuous extensions gathered from the lanes' steps (answers' and checks'), PASS_LANES to
   a vector call of `rk8_cont`: slot q holds a step's inputs of `rk8_cont` (x, xn, K, h, u,
   p: v's fields, lane q) and the outputs it fills (ts[j0] ... ts[j1 - 1] of a step from
   time t into X, ldx). A lane's steps hold an output on about one step in three, so a
   call for the lanes of one step would mostly compute lanes nobody reads. */
typedef struct {
  au_vio v;
  int n;
  const casadi_real* ts[PASS_LANES];
  casadi_real t[PASS_LANES], *X[PASS_LANES];
  int j0[PASS_LANES], j1[PASS_LANES], ldx[PASS_LANES];
} au_pend;

/* `dense_fill` of every lane of v at once, from its extension in v->F: lane l's outputs
   ts[l][j0[l]] ... ts[l][j1[l] - 1] inside its step of v->h[l] from (t[l], v->x lane l)
   into X[l] (nx, ldx[l]); the vectors read whole, each lane `dense_fill`'s arithmetic in
   its order (the same bits); a lane with j1 <= j0 has none */
static void au_vfill(const au_vio* v, const casadi_real* t, const casadi_real* const* ts,
                     const int* j0, const int* j1, casadi_real* const* X, const int* ldx) {
  au_vec sv, r;
  int l, i, k, most = 0;
  for (l = 0; l < PASS_LANES; ++l)
    if (j1[l] - j0[l] > most) most = j1[l] - j0[l];
  for (k = 0; k < most; ++k) {
    for (l = 0; l < PASS_LANES; ++l)
      sv[l] = k < j1[l] - j0[l] ? (ts[l][j0[l] + k] - t[l]) / v->h[l] : 0.0;
    for (i = 0; i < PASS_NX; ++i) {
      r = v->F[5 * PASS_NX + i] + sv * v->F[6 * PASS_NX + i];
      r = v->F[4 * PASS_NX + i] + (1 - sv) * r;
      r = v->F[3 * PASS_NX + i] + sv * r;
      r = v->F[2 * PASS_NX + i] + (1 - sv) * r;
      r = v->F[PASS_NX + i] + sv * r;
      r = v->F[i] + (1 - sv) * r;
      r = v->x[i] + sv * r;
      for (l = 0; l < PASS_LANES; ++l)
        if (k < j1[l] - j0[l]) X[l][i * ldx[l] + j0[l] + k] = r[l];
    }
  }
}

/* the extension of slots 0 ... n - 1 in one vector call, their outputs filled (the other
   lanes compute what they last held: finite values, read by nobody) */
static void au_flush(au_pend* P, au_vstep vcont) {
  int q;
  if (!P->n) return;
  au_vext(vcont, &P->v);
  for (q = P->n; q < PASS_LANES; ++q) P->j0[q] = P->j1[q] = 0;  /* (slots not in use) */
  au_vfill(&P->v, P->t, P->ts, P->j0, P->j1, P->X, P->ldx);
  P->n = 0;
}

/* lane l's step of v, taken from time t by the run of s, its outputs inside left in
   [span[0], span[1]) (`dense_take`, `rich_take`), into a slot for X; a vector call when the
   slots are full */
static void au_defer(au_pend* P, au_vstep vcont, const au_vio* v, int l, const dense_state* s,
                     casadi_real t, const int* span, casadi_real* X) {
  static const int stages[CONT_NSTAGES] = CONT_STAGES;
  int q = P->n, i, j;
  if (span[1] <= span[0]) return;
  for (i = 0; i < PASS_NX; ++i) {
    P->v.x[i][q] = v->x[i][l];
    P->v.xn[i][q] = v->xn[i][l];
  }
  for (j = 0; j < CONT_NSTAGES; ++j)  /* (the stages the extension reads) */
    for (i = stages[j] * PASS_NX; i < (stages[j] + 1) * PASS_NX; ++i)
      P->v.K[i][q] = v->K[i][l];
  for (i = 0; i < PASS_U; ++i) P->v.u[i][q] = v->u[i][l];
  for (i = 0; i < (PASS_NP > 0 ? PASS_NP : 1); ++i) P->v.p[i][q] = v->p[i][l];
  P->v.h[q] = v->h[l];
  P->t[q] = t; P->ts[q] = s->ts; P->X[q] = X; P->ldx[q] = s->ldx;
  P->j0[q] = span[0]; P->j1[q] = span[1];
  if (++P->n == PASS_LANES) au_flush(P, vcont);
}

/* Lanes holding outputs in a vector step from which its extension is computed at once
   (`au_extend`): a vector extension costs about as much as three gathered ones (`au_defer`'s
   copies of the stages included; 175 against 78 ns a lane on the rigid body). */
#define AU_DIRECT 3

/* the outputs inside the steps of the lanes of v (lane l's from time t[l] by the run of
   S[l] into X[l], their indices in [span[l][0], span[l][1]), empty when none): with at
   least AU_DIRECT lanes holding some, from v's own vector extension, else gathered into
   P (`au_defer`); the same bits either way (each lane its own arithmetic) */
static void au_extend(au_pend* P, au_vstep vcont, au_vio* v, int (*span)[2],
                      const casadi_real* t, dense_state* const* S, casadi_real* const* X) {
  const casadi_real* ts[PASS_LANES];
  int l, n = 0, j0[PASS_LANES], j1[PASS_LANES], ldx[PASS_LANES];
  for (l = 0; l < PASS_LANES; ++l) n += span[l][1] > span[l][0];
  if (n < AU_DIRECT) {
    for (l = 0; l < PASS_LANES; ++l)
      if (span[l][1] > span[l][0]) au_defer(P, vcont, v, l, S[l], t[l], span[l], X[l]);
    return;
  }
  au_vext(vcont, v);
  for (l = 0; l < PASS_LANES; ++l) {
    ts[l] = S[l]->ts; j0[l] = span[l][0]; j1[l] = span[l][1]; ldx[l] = S[l]->ldx;
  }
  au_vfill(v, t, ts, j0, j1, X, ldx);
}

/* lane L's run (or answer) opened since it last came here: its control, parameters and
   tolerances into its lane of the answers' v and the checks' vc (`au_vrun`), its state
   into v and its check's into vc (each then follows its steps in place: `rk8_auto_lanes`,
   `au_checks`) */
static void au_vfresh(au_vio* v, au_vio* vc, au_lane* L) {
  int l = L->lane;
  if (!L->fresh) return;
  au_vrun(v, l, &L->s);
  au_vrun(vc, l, &L->s);
  au_vstep_in(v, l, L->s.x, L->s.h);
  if (L->s.rich) au_vstep_in(vc, l, L->s.rich + RI_X, L->s.h);
  L->fresh = 0;
}

/* the check steps due in the lanes, in one vector step, when one of them cannot wait
   (`all`; or a lane whose next accepted step would make another due: it ends a pair or
   the run); a check step waits at most one answer step, so about one vector step of
   checks serves every lane's pair; their continuous extensions gathered in P */
static void au_checks(au_lane* L, au_vio* v, au_pend* P, au_vstep step, au_vstep vcont,
                      int all) {
  casadi_real xn[PASS_NX], err, root, t[PASS_LANES], *X[PASS_LANES];
  dense_state* S[PASS_LANES];
  au_lmask took;
  int use[PASS_LANES], span[PASS_LANES][2], l, i, any = 0, urgent = all;
  for (l = 0; l < PASS_LANES; ++l) {
    dense_state* s = &L[l].s;
    use[l] = L[l].k >= 0 && L[l].opened && s->check_due;
    any |= use[l];
    if (use[l] && (s->rich[RI_PEND] > 0 || *s->t + 1.01 * s->h >= s->tend)) urgent = 1;
  }
  if (!any || !urgent) return;
  for (l = 0; l < PASS_LANES; ++l)  /* (the runs' inputs and states: `au_vfresh`) */
    if (use[l]) {
      v->h[l] = L[l].s.due - L[l].s.rich[RI_T];
      v->filled |= 1 << l;
    }
  au_vcall(step, v, use);
  for (l = 0; l < PASS_LANES; ++l) {
    S[l] = &L[l].s; X[l] = L[l].s.XC; t[l] = 0; span[l][0] = span[l][1] = 0;
    took[l] = use[l] ? -1 : 0;
    if (use[l]) {
      au_vget(v, l, xn, &err, &root, NULL, 0);
      t[l] = L[l].s.rich[RI_T];
      rich_take(&L[l].s, xn, err, NULL, NULL, span[l]);
    }
  }
  au_extend(P, vcont, v, span, t, S, X);
  au_vkeep(v, took);  /* (a check step is never rejected) */
}

/* lane L's run in progress opened as `au_step` opens it (a retried answer with its check,
   or the rerun rounded at random into XC, `floor`); 1 when it has steps to take */
static int au_lane_open(au_lane* L, int nout, int plain) {
  casadi_real* w = L->w;
  L->fresh = 1;
  L->jit.stream = (unsigned long long) w[AU_DRAWS];
  L->opened = dense_open(&L->s, AU_XR(w), AU_TT(w), *AU_H(w), nout, AU_TS(w), AU_U(w),
                         AU_P(w), w[AU_RTOL] * w[AU_FACTOR], AU_AL(w),
                         w[AU_MAXSTEPS] - w[AU_SPENT], (L->floor ? L->XC : L->X) + 1,
                         nout + 1, AU_COUNT(w), w[AU_STIFF],
                         L->floor || plain ? NULL : AU_RICH(w), L->XC + 1,
                         L->floor ? &L->jit : NULL);
  return L->opened && L->s.j < nout;
}

/* lane L's run after its answer (or rerun) ended: `rk8_auto`'s verdict; a retry or a rerun
   rounded at random goes on in the lane (the lanes stay full); a run done leaves its
   header in res (AU_HDR per run) and the lane empty */
static void au_lane_next(au_lane* L, int nout, casadi_real* res, int plain) {
  casadi_real* w = L->w;
  int i;
  do {
    if (L->opened) dense_close(&L->s, AU_H(w));
    au_ended(w, L->X, L->XC, L->floor, plain, NULL);
    if (w[AU_PHASE] == 3) {
      for (i = 0; i < AU_HDR; ++i) res[(size_t) L->k * AU_HDR + i] = w[i];
      L->k = -1;
      return;
    }
    L->floor = w[AU_PHASE] == 4;
  } while (!au_lane_open(L, nout, plain));
}

/* lane L takes run k (`au_load`, `rk8_auto`'s start, its first answer opened as `au_step`
   opens it); a run that takes no step is finished at once (the lane is then empty) */
static void au_lane_load(au_lane* L, const casadi_real* w, int size, int nout, long k,
                         const casadi_real* x0, const casadi_real* u, const casadi_real* p,
                         casadi_real* X, casadi_real* res, int plain) {
  casadi_real* wk = L->w;
  int i;
  au_load(wk, w, size, (size_t) k, x0, u, p);
  wk[AU_NOUT] = nout;
  L->k = k;
  L->X = X + (size_t) k * PASS_NX * (nout + 1);
  L->ended = 0;
  if (au_start(wk, nout, L->X, L->XC)) {
    for (i = 0; i < AU_HDR; ++i) res[(size_t) k * AU_HDR + i] = wk[i];
    L->k = -1;
    return;
  }
  L->floor = 0;
  if (!au_lane_open(L, nout, plain)) au_lane_next(L, nout, res, plain);
}

/* `rk8_auto_many` (the same arguments, the same answers and headers) with the runs'
   answers, their checks, retries and reruns stepped PASS_LANES at a time by `vstep` and
   `vcont` (the vector `rk8_step_k` and `rk8_cont`); XC (PASS_LANES, nx, nout + 1)
   scratch, a lane's each. An empty lane takes the next run (`au_claim`) until the vector
   steps have made `budget` lane-steps; the runs in the lanes then finish. */
int rk8_auto_lanes(const casadi_real* w, int nout, const long long* runs, long long n,
                   long long* cursor, double budget, const casadi_real* x0,
                   const casadi_real* u, const casadi_real* p, casadi_real* X,
                   casadi_real* XC, casadi_real* res, void* vstep, void* vcont) {
  au_vstep step = (au_vstep) vstep, cont = (au_vstep) vcont;
  au_vio v, vc;  /* the answers' steps and the checks' */
  au_pend P;
  au_lane L[PASS_LANES];
  au_lmask took;
  casadi_real xn[PASS_NX], err, root, t[PASS_LANES], *XO[PASS_LANES], count;
  dense_state* S[PASS_LANES];
  int size = AU_SIZE(nout), plain = w[AU_TRIES] <= 0, use[PASS_LANES], span[PASS_LANES][2];
  int l, i, any, taking = 1, handed = 0;
  long long k;
  double spent = 0;
  casadi_real* wk = (casadi_real*) malloc(sizeof(casadi_real) * size * PASS_LANES);
  if (!wk) return -1;
  memset(&P, 0, sizeof P);
  v.filled = vc.filled = 0;
  for (l = 0; l < PASS_LANES; ++l) {
    L[l].w = wk + (size_t) l * size;
    L[l].XC = XC + (size_t) l * PASS_NX * (nout + 1);
    L[l].k = -1;
    L[l].lane = l;
    L[l].fresh = 1;
  }
  for (;;) {
    taking = taking && !(budget > 0 && spent >= budget);
    for (l = 0; l < PASS_LANES && taking; ++l)  /* (an empty lane takes the next run) */
      while (L[l].k < 0) {
        if ((k = au_claim(runs, n, cursor)) < 0) {
          taking = 0;
          handed = 1;
          break;
        }
        au_lane_load(&L[l], w, size, nout, k, x0, u, p, X, res, plain);
      }
    any = 0;
    for (l = 0; l < PASS_LANES; ++l) any |= use[l] = L[l].k >= 0;
    if (!any) break;
    spent += PASS_LANES;
    for (l = 0; l < PASS_LANES; ++l)
      if (use[l]) au_vfresh(&v, &vc, &L[l]);
    au_checks(L, &vc, &P, step, cont, 0);
    for (l = 0; l < PASS_LANES; ++l)
      if (use[l]) {  /* (a lane's x in v is its run's: `au_vfresh`, then the blend below) */
        dense_next(&L[l].s);
        v.h[l] = L[l].s.hs;
        v.filled |= 1 << l;
      }
    au_vcall(step, &v, use);
    any = 0;
    for (l = 0; l < PASS_LANES; ++l) {
      S[l] = &L[l].s; XO[l] = L[l].s.X; t[l] = 0; span[l][0] = span[l][1] = 0;
      took[l] = 0;
      if (use[l]) {
        au_vget(&v, l, xn, &err, &root, NULL, 0);
        t[l] = *L[l].s.t;
        count = L[l].s.count[0];
        L[l].ended = dense_take(&L[l].s, xn, err, root, NULL, NULL, span[l]) ||
                     L[l].s.j >= nout;
        took[l] = L[l].s.count[0] != count ? -1 : 0;  /* (accepted: its state is xn) */
        any |= L[l].ended;
      }
    }
    au_extend(&P, cont, &v, span, t, S, XO);
    au_vkeep(&v, took);  /* (each lane's next x: xn where accepted) */
    for (l = 0; l < PASS_LANES; ++l)  /* (a rerun's rounded at random: `dense_jitter`) */
      if (took[l] && L[l].floor)
        for (i = 0; i < PASS_NX; ++i) v.x[i][l] = L[l].s.x[i];
    if (!any) continue;
    au_checks(L, &vc, &P, step, cont, 1);  /* (a run ends with its checks taken) */
    au_flush(&P, cont);  /* (and its outputs filled) */
    for (l = 0; l < PASS_LANES; ++l)
      if (use[l] && L[l].ended) au_lane_next(&L[l], nout, res, plain);
  }
  free(wk);
  return handed;
}
#endif
"""


# Fixed-step rk8 over the runs of a batch, each under its constant control, in one plain C
# loop around the generated step (`dynamics.integrate.batch_fixed`).
_FIXED = r"""
/* m rk8 steps per output interval (lengths H, nint of them) for the runs k0 <= k < k1:
   x0 (K, nx), u (K, PASS_U), p (K, max(np, 1)) by run; X (K, nint + 1, nx) the states at
   the outputs. Returns the runs done. */
int rk8_fixed_many(int k0, int k1, int nint, int m, const casadi_real* H,
                   const casadi_real* x0, const casadi_real* u, const casadi_real* p,
                   casadi_real* X) {
  pass_ctx c;
  const casadi_real* arg[PASS_NARG + 5];
  casadi_real* res[PASS_NRES + 1];
  casadi_real x[PASS_NX], xn[PASS_NX], h, zero[PASS_U];
  int k, j, s, i, np1 = PASS_NP > 0 ? PASS_NP : 1;
  for (i = 0; i < PASS_U; ++i) zero[i] = 0;
  arg[0] = x; arg[1] = &h; arg[3] = zero; res[0] = xn;
  for (k = k0; k < k1; ++k) {
    casadi_real* out = X + (size_t) k * (nint + 1) * PASS_NX;
    arg[2] = u + (size_t) k * PASS_U;
    arg[4] = p + (size_t) k * np1;
    for (i = 0; i < PASS_NX; ++i) out[i] = x[i] = x0[(size_t) k * PASS_NX + i];
    for (j = 0; j < nint; ++j) {
      h = H[j] / m;
      for (s = 0; s < m; ++s) {
        rk8_step(arg, res, c.iw, c.w, 0);
        for (i = 0; i < PASS_NX; ++i) x[i] = xn[i];
      }
      for (i = 0; i < PASS_NX; ++i) out[(j + 1) * PASS_NX + i] = x[i];
    }
  }
  return k1 - k0;
}
"""


# The fixed-step rk8 chunk of `chunks.build_chunk` for a model whose rhs is called (`csteps`:
# the C loops' steps), exported in casadi's external-function form under the chunk's names
# (`chunk_name`), its signature (inputs, outputs, work) that of a generated stand-in
# Function (`_chunk_signature`, named `chunk_sig_<size>`): (x0, n, h (1 x B), ua (nu x B),
# ud (nu x B), p) -> X (nx x B), the state after each of the first n steps, then the state
# after step n repeated.
_CHUNK = r"""
static int pass_chunk(const casadi_real** arg, casadi_real** res, int size) {
  const casadi_real* a[5];
  casadi_real* r[1];
  pass_ctx c;
  const casadi_real *h = arg[2], *ua = arg[3], *ud = arg[4];
  casadi_real n = arg[1] ? arg[1][0] : 0, x[PASS_NX], *X = res[0];
  int s, i;
  for (i = 0; i < PASS_NX; ++i) x[i] = arg[0] ? arg[0][i] : 0;
  a[4] = arg[5];
  for (s = 0; s < size; ++s) {
    if (s < n) {
      a[0] = x; a[1] = h + s;
      a[2] = ua ? ua + s * PASS_NU : 0; a[3] = ud ? ud + s * PASS_NU : 0;
      r[0] = X + s * PASS_NX;
      rk8_step(a, r, c.iw, c.w, 0);
      for (i = 0; i < PASS_NX; ++i) x[i] = X[s * PASS_NX + i];
    } else {
      for (i = 0; i < PASS_NX; ++i) X[s * PASS_NX + i] = x[i];
    }
  }
  return 0;
}
#define PASS_CHUNK(NAME, SIG, SIZE) \
CASADI_SYMBOL_EXPORT int NAME(const casadi_real** arg, casadi_real** res, casadi_int* iw, \
                              casadi_real* w, int mem) { return pass_chunk(arg, res, SIZE); } \
CASADI_SYMBOL_EXPORT casadi_int NAME##_n_in(void) { return SIG##_n_in(); } \
CASADI_SYMBOL_EXPORT casadi_int NAME##_n_out(void) { return SIG##_n_out(); } \
CASADI_SYMBOL_EXPORT const char* NAME##_name_in(casadi_int i) { return SIG##_name_in(i); } \
CASADI_SYMBOL_EXPORT const char* NAME##_name_out(casadi_int i) { return SIG##_name_out(i); } \
CASADI_SYMBOL_EXPORT const casadi_int* NAME##_sparsity_in(casadi_int i) { \
  return SIG##_sparsity_in(i); } \
CASADI_SYMBOL_EXPORT const casadi_int* NAME##_sparsity_out(casadi_int i) { \
  return SIG##_sparsity_out(i); } \
CASADI_SYMBOL_EXPORT int NAME##_work(casadi_int* sz_arg, casadi_int* sz_res, \
                                     casadi_int* sz_iw, casadi_int* sz_w) { \
  return SIG##_work(sz_arg, sz_res, sz_iw, sz_w); }
PASS_CHUNK(%(chunk)s, chunk_sig_%(chunk_size)d, %(chunk_size)d)
PASS_CHUNK(%(batch)s, chunk_sig_%(batch_size)d, %(batch_size)d)
"""

# One call of each compiled step form on the same data, for tests (the pass's steps against
# the casadi kernels they stand for): into out, in turn, the plain step's x_next (nx), the
# error step's x_next (nx) and error (1), the dense step's x_next (nx), error (1) and
# stages (12 nx) under the constant control ua, and that step's extension F (7 nx).
_PROBE = r"""
int rk8_probe(const casadi_real* x, casadi_real h, const casadi_real* ua,
              const casadi_real* ud, const casadi_real* p, casadi_real rtol,
              const casadi_real* atol, casadi_real* out) {
  const casadi_real* arg[PASS_NARG + 7];
  casadi_real* res[PASS_NRES + 3];
  pass_ctx c;
  casadi_real *xk = out + 2 * PASS_NX + 1, *K = xk + PASS_NX + 1;
  arg[0] = x; arg[1] = &h; arg[2] = ua; arg[3] = ud; arg[4] = p; arg[5] = &rtol;
  arg[6] = atol; res[0] = out;
  if (rk8_step(arg, res, c.iw, c.w, 0)) return 1;
  res[0] = out + PASS_NX; res[1] = out + 2 * PASS_NX;
  if (rk8_step_err(arg, res, c.iw, c.w, 0)) return 1;
  arg[3] = p; arg[4] = &rtol; arg[5] = atol;
  res[0] = xk; res[1] = xk + PASS_NX; res[2] = K;
  if (rk8_step_k(arg, res, c.iw, c.w, 0)) return 1;
  arg[1] = xk; arg[2] = K; arg[3] = &h; arg[4] = ua; arg[5] = p;
  res[0] = K + 12 * PASS_NX;
  return rk8_cont(arg, res, c.iw, c.w, 0);
}
"""

def pass_library(model: Model, *, lanes: bool = False) -> object | None:
    """The compiled pass of ``model`` (a ``ctypes`` function, cached); None without a C
    compiler or when the model cannot be code-generated (the pass is worth it only as C).

    ``lanes`` False: the first call's build, without the driver of steps in vector lanes
    (``auto_lanes`` None; ``auto_v`` takes no vector steps); True: the same C with it
    (``PASS_WITH_LANES``), which `lanes.dense_lanes` compiles in the background with the
    vector steps it drives. The lane driver at -O2 was half the first build's gcc time:
    the first `simulate` of a model with an empty cache 1.0-1.2 s, against 0.4-0.7 s before
    it was added (`bench/compile_cache.py`). Both builds' scalar paths are the same C: the
    same bits."""
    def job(opt):
        return _pass_job(model, opt, lanes)

    def build():
        lib = cache.compile_parallel([job(_OPTS[0])])[0]
        if isinstance(lib, RuntimeError):  # (e.g. a compiler without -march=native)
            lib = cache.compile_parallel([job(_OPTS[1])])[0]
        # auto's multi-run search (the fallback) runs the rk8 chunk loop: its compile starts
        # now, in the background (`cache.compile_ahead`; a call that needs it waits for it),
        # after the pass's units had the cores to themselves
        chunk = None if lanes or calls_rhs(model, "rk8") else \
            chunk_compile_job(model, "rk8", "linear")
        if chunk is not None:  # (a called rhs: the pass runs the chunk, `pass_chunk`)
            cache.compile_ahead([chunk])
        if lib is None or isinstance(lib, RuntimeError):
            return None
        return _loaded(lib, lanes)

    return cache.get((_pass_name(lanes), cache.function_key(model.f)), build,
                     keepalive=model.f)


def pass_lanes_job(model: Model) -> cache.Job:
    """The compile job of ``pass_library(model, lanes=True)`` (this machine's flags), for
    `lanes.dense_lanes` to start in the background and to ask whether it is ready."""
    return _pass_job(model, _OPTS[0], True)


def _pass_job(model: Model, opt: str, lanes: bool) -> cache.Job:
    """The `cache.Job` of the pass of ``model`` at the flags ``opt``, with the lane driver
    when ``lanes``."""
    def make():
        # Translation units compiled at once (`cache.compile_parallel`), each a list: the
        # driver's own C with what it needs beside it, and the big generated functions (the
        # rigid body's four inlined steps: one unit of 0.85 s of gcc, two of 0.3 and 0.4 s
        # beside the driver's 0.24 s)
        rhs = _renamed(model.f, "pass_rhs")
        if calls_rhs(model, "rk8"):  # (the steps as C loops around the one rhs: `csteps`)
            main = [_chunk_signature(model, size) for size in (CHUNK, BATCH_CHUNK)]
            units, wrappers = [[rhs]], loop_steps()
        else:
            step = _renamed(kernel(model, "rk8", "linear", error=True, compiled=True),
                            "rk8_step_err")
            plain = _renamed(kernel(model, "rk8", "linear", compiled=True), "rk8_step")
            main, units, wrappers = [rhs], [[step, plain], list(dense_kernels(model))], ""
        every = main + [f for unit in units for f in unit]
        sizes = dict(every=CHECK_EVERY, lanes=LANES, with_lanes=int(lanes),
                     ncont=len(DOP853_DENSE_STAGES),
                     cont=", ".join(map(str, DOP853_DENSE_STAGES)), nx=model.nx,
                     nu=model.nu, np=model.np,
                     nw=max(f.sz_w() for f in every), niw=max(f.sz_iw() for f in every),
                     narg=max(f.sz_arg() for f in every), nres=max(f.sz_res() for f in every),
                     steps=wrappers)
        extra = _DRIVER % sizes + _STEPPER + _DENSE + _AUTO + _FIXED + _PROBE
        if calls_rhs(model, "rk8"):
            extra += _CHUNK % dict(chunk=chunk_name("rk8", CHUNK), chunk_size=CHUNK,
                                   batch=chunk_name("rk8", BATCH_CHUNK),
                                   batch_size=BATCH_CHUNK)
        return main + units, extra

    return cache.Job(make, opt, ctypes.CDLL, cache.recipe(_pass_name(lanes), model.f, opt))


def _pass_name(lanes: bool) -> str:
    """The name of the pass's build (with the lane driver or not): its cache key and recipe."""
    return "rk8_pass_lanes" if lanes else "rk8_pass"


def _loaded(lib, lanes: bool):
    """The pass's entry points of the loaded library ``lib`` (`pass_library`)."""
    fun = lib.rk8_pass_ws
    ptr, i32 = ctypes.c_void_p, ctypes.c_int
    fun.argtypes = [ptr, ptr, i32, i32, ptr, ptr]
    fun.restype = i32
    fun.library = lib  # (kept alive with the function)
    stepper = lib.rk8_adaptive
    f64 = ctypes.c_double
    stepper.argtypes = [ptr, ptr, i32, ptr, ptr, ptr, ptr, i32, ptr, f64, ptr, f64, ptr,
                        i32, ptr, ptr]
    stepper.restype = i32
    fun.stepper = stepper  # (`dynamics.integrate.stepcontrol`)
    passes = lib.rk8_pass_many
    passes.argtypes = [ctypes.c_longlong, ptr, f64, ptr, ctypes.c_longlong, ptr, i32, i32, f64,
                       ptr, ptr, ctypes.c_longlong, ptr]
    passes.restype = i32
    fun.pass_many = passes  # (`adaptive.run_pass_many`)
    many = lib.rk8_adaptive_many
    i64 = ctypes.c_longlong
    many.argtypes = [i64, ptr, f64, i32, i32, ptr, ptr, ptr, ptr, ptr, i32, ptr, i32, f64, ptr,
                     f64, ptr, ptr, ptr, ptr]
    many.restype = i32
    fun.stepper_many = many  # (`stepcontrol.run_stepped_many`)
    auto = lib.rk8_auto
    auto.argtypes = [ptr, i32, i32, ptr, ptr]
    auto.restype = i32
    fun.auto = auto  # (`dynamics.integrate.dense`)
    auto_v = lib.rk8_auto_v
    auto_v.argtypes = [ptr, i32, i32, ptr, ptr, ptr, ptr, ptr]
    auto_v.restype = i32
    fun.auto_v = auto_v  # (the same, the check in a lane when ``lanes``: `lanes.dense_lanes`)
    many = lib.rk8_auto_many
    i64 = ctypes.c_longlong
    many.argtypes = [ptr, i32, ptr, i64, ptr, f64, ptr, ptr, ptr, ptr, ptr, ptr]
    many.restype = i32
    fun.auto_many = many  # (`dynamics.integrate.dense`, a batch)
    fun.auto_lanes = None
    if lanes:  # (the same, in vector lanes: `lanes.dense_lanes`)
        fun.auto_lanes = lib.rk8_auto_lanes
        fun.auto_lanes.argtypes = [ptr, i32, ptr, i64, ptr, f64, ptr, ptr, ptr, ptr, ptr, ptr,
                                   ptr, ptr]
        fun.auto_lanes.restype = i32
    fixed = lib.rk8_fixed_many
    fixed.argtypes = [i32, i32, i32, i32, ptr, ptr, ptr, ptr, ptr]
    fixed.restype = i32
    fun.fixed_many = fixed  # (`dynamics.integrate.batch_fixed`)
    probe = lib.rk8_probe
    probe.argtypes = [ptr, f64, ptr, ptr, ptr, f64, ptr, ptr]
    probe.restype = i32
    fun.probe = probe  # (tests: `_PROBE`)
    replay = lib.rk8_replay
    replay.argtypes = [ptr, i32, ptr, ptr, ptr, i32, ptr, ptr, ptr, ptr, i32]
    replay.restype = i32
    fun.replay = replay  # (`adaptive.replay_check`)
    replays = lib.rk8_replay_many
    replays.argtypes = [ctypes.c_longlong, ptr, ptr, ptr, ctypes.c_longlong, ptr, i32, ptr, ptr,
                        ctypes.c_longlong, ptr]
    replays.restype = i32
    fun.replay_many = replays  # (`adaptive.replay_checks`)
    fun.path = lib._name  # (`pass_chunk`)
    return fun


def pass_chunk(model: Model, size: int) -> ca.Function | None:
    """The rk8 chunk Function of ``size`` steps (`chunks.build_chunk`'s inputs and output,
    control linear over each step) run by the compiled pass of a model whose right-hand
    side is called (`kernels.calls_rhs`): the pass's C loop over its steps (`_CHUNK`),
    loaded with ``casadi.external`` from the pass's library. None for another model,
    without a compiled pass, or for a size the pass does not hold."""
    if size not in (CHUNK, BATCH_CHUNK) or not calls_rhs(model, "rk8"):
        return None
    lib = pass_library(model)
    if lib is None:
        return None
    try:  # (the loaded library by its path: with the disk cache off, its file is gone)
        return ca.external(chunk_name("rk8", size), lib.path)
    except RuntimeError:  # (then the casadi chunk is compiled instead)
        return None


def _chunk_signature(model: Model, size: int) -> ca.Function:
    """A Function with the chunk's inputs and output (`chunks.build_chunk`, ``linear``
    control; its value ``x0`` repeated): generated only for its signature (`_CHUNK`)."""
    nx, nu, np_ = model.nx, model.nu, model.np
    ins = [ca.MX.sym("x0", nx), ca.MX.sym("n"), ca.MX.sym("h", 1, size),
           ca.MX.sym("ua", nu, size), ca.MX.sym("ud", nu, size), ca.MX.sym("p", np_)]
    # (MX: a few lines of C; an SX output of nx x size scalars would be as many lines)
    return ca.Function(f"chunk_sig_{size}", ins, [ca.repmat(ins[0], 1, size)])


def _renamed(fun: ca.Function, name: str, sym=None) -> ca.Function:
    """``fun`` under ``name`` (the generated C function's name); ``sym=casadi.MX``: a
    wrapper calling ``fun`` (not a copy of its expressions)."""
    if fun.name() == name:
        return fun
    ins = [fun.sx_in(i) for i in range(fun.n_in())] if fun.is_a("SXFunction") and sym is None \
        else [fun.mx_in(i) for i in range(fun.n_in())]
    return ca.Function(name, ins, fun.call(ins))
