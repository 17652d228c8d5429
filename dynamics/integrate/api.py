"""`simulate`: the public driver (checks the inputs, runs a method, builds the result)."""
from __future__ import annotations

import math
import time
from dataclasses import replace
from types import MappingProxyType
from typing import Callable, Literal, Mapping, NamedTuple

import numpy as np

from .. import cache, validate
from ..clock import CLOCK_STATE, check_clock_start, clock_index
from ..model import Model, check_model
from ..progress import progress_reporter
from .auto import STIFF_STEPS, dense_outcome, solve_auto
from .batch import BatchResult, check_batch, simulate_batch
from .batch_fixed import batch_threads
from .cvodes import run_cvodes
from .dense import constant_control, dense_run, pass_plan
from .events import apply_events, check_events
from .impacts import check_impact, simulate_impacts
from .inputs import (RTOL_MIN, Problem, RunOptions, check_cvodes_options, check_invariants,
                     check_t, check_tolerances, check_u, check_x0, fast_x0, handed_t)
from .kernels import check_lie_model
from .loops import Progress, run_fixed, run_short
from .result import FAILED, OK, OK_STIFF, VIOLATED, Dense, Run, SimulationResult, new_result
from .sanity import remedy, violation
from .smoothness import nonsmooth_operations
from .stepcontrol import plain_run, run_dop853

__all__ = ["simulate", "METHODS", "Method", "Hold", "CallPlan", "call_plan"]

Method = Literal["auto", "dop853", "cvodes", "rk4", "rk8", "lie"]
Hold = Literal["linear", "zoh"]
METHODS = ("auto", "dop853", "cvodes", "rk4", "rk8", "lie")
_FIXED_STEP = ("rk4", "rk8", "lie")


def simulate(model: Model, x0, t, *, u=None, p=None, hold: Hold = "linear", method: Method = "auto",
             rtol: float = 1e-8, atol=1e-10, invariants=False, steps: int | None = None,
             jit: bool | None = None, max_steps: int = 100_000_000,
             cvodes_options: Mapping | None = None,
             progress: bool | Callable[[int, int], None] | None = None,
             events=None, impacts=None,
             threads: int | None = None) -> SimulationResult | BatchResult:
    """Integrate ``xdot = f(x, u, p)`` of ``model`` from ``x0`` over the grid ``t``.

    Parameters
    ----------
    model : Model
        The dynamics (``model.f``: ``(x, u, p) -> xdot``).
    x0 : array_like, shape (nx,) or (nx, K)
        State at ``t[0]``, in the model's units. Shape ``(nx, K)``, ``K >= 2``: a batch of K
        runs on the same grid, integrated together (one compiled call per chunk of steps
        for all runs, spread over the cores; `dynamics.integrate.batch`); ``p`` may then be
        ``(np, K)`` and ``u`` samples ``(nu, n, K)``, one per run (a callable ``u`` is not
        taken), and the result is a `BatchResult` with ``x (nx, n, K)`` and per-run
        ``success``, ``status`` and ``error_estimate``.
    t : array_like, shape (n,) [s]
        Output times, strictly increasing, ``n >= 2``. Fixed-step methods step exactly onto
        every output time.
    u : None, array_like (nu,) or (nu, n), or callable, optional
        Control [model units]: ``None`` is zero; a constant; samples on ``t``, between
        samples as ``hold`` says; or ``u(t) -> (nu,)`` for a float ``t`` [s], called at every
        stage time (fixed step) or right-hand-side evaluation (cvodes).
    p : array_like, shape (np,) or, for a batch, (np, K), optional
        Parameters; the model's defaults when omitted.
    hold : {'linear', 'zoh'}, optional
        How samples ``u`` of shape ``(nu, n)`` (or ``(nu, n, K)``) act between the output
        times: ``'linear'`` (default) interpolates; ``'zoh'`` (zero-order hold, a digital
        controller's output) applies ``u[:, k]`` on ``[t_k, t_{k+1})`` (``u[:, -1]`` acts
        after the grid: it only enters ``xdot`` and ``sample`` at ``t[-1]``). The jumps sit
        on the grid, where every method's steps start and end, so every method integrates
        each interval with its constant control and loses no order. A constant or ``None``
        ``u`` is the same under both; a callable ``u`` takes only ``'linear'``.
    method : {'auto', 'dop853', 'cvodes', 'rk4', 'rk8', 'lie'}
        * ``'rk4'``, ``'rk8'`` (DOP853's 8th-order weights), ``'lie'`` (CF4 on the quaternion,
          RK4 on the other states; needs ``model.attitude``): fixed step, ``steps`` steps per
          output interval, run by one compiled chunk Function of 512 steps called in a
          loop (the code and its compile time do not depend on the grid or step count).
        * ``'cvodes'``: SUNDIALS CVODES (BDF by default) through ``casadi.integrator`` with
          ``rtol``/``atol`` as its local tolerances (the smallest ``atol`` when a vector).
        * ``'dop853'``: one run of DOP853 (Hairer's 8(5,3) pair, as scipy's and
          numbalsoda's) with ``rtol``/``atol`` as its local tolerances, compiled C
          (`dynamics.integrate.stepcontrol.run_dop853`): under a control constant over the
          run its steps follow the error estimate alone and the outputs come from its
          continuous extension of order 7; under sampled controls its steps end on the grid;
          a callable ``u`` (or ``jit=False``) steps from Python. Its global error is *not*
          estimated (``error_estimate`` NaN; ``success`` says the run finished and passed
          the invariant sanity check of the fixed-step methods): the peers' contract, at
          their speed (``bench/integrate_peers.py``). ``auto`` verifies the tolerance.
        * ``'auto'``: ``rk8`` with the step count chosen from global error estimates so
          that ``|error| <= atol + rtol |x|`` at every output time. First one compiled C
          pass (no callable ``u``, a C compiler, a tolerance at least 1e6 ulps above the
          states): steps per interval from DOP853's embedded error estimate, checked
          against a run with half the steps carried alongside (`dynamics.integrate.adaptive`);
          then, if that check is not met, Richardson estimates from runs with different
          step counts, checked for 8th-order behaviour (`dynamics.integrate.auto`). A stiff problem (a decaying mode of the Jacobian at
          ``x0`` faster than ``1e6`` explicit steps over the horizon can follow) goes to
          cvodes, whose global error is then estimated from runs at tightened local
          tolerances (``status`` 1). A non-smooth right-hand side (``fmin``, ``fmax``,
          ``if_else``, ``fabs``, ... in the model's expression graph, found by
          `dynamics.integrate.smoothness`, or a callable ``u``, which may jump) loses the
          order those estimates assume at its kinks: it is integrated by DOP853 with step
          rejection (its steps crowd at the kinks), the global error again estimated from
          runs at local tolerances 100x apart (`dynamics.integrate.stepcontrol`; ``method``
          ``'dop853'`` in the result). A tolerance that cannot be verified is
          ``success=False`` with ``status`` 2 (round-off floor), 3 (``max_steps``) or 5
          (non-smooth right-hand side: order loss at kinks); never a silent fallback.
    rtol : float, optional
        Relative tolerance, ``100 eps <= rtol < 1`` (used by ``auto``, ``dop853`` and ``cvodes``).
    atol : float or array_like (nx,), optional
        Absolute tolerance [state units], ``>= 0``.
    invariants : bool or sequence of str, optional
        Evaluate all (``True``) or the named ``model.invariants`` along the solution.
    steps : int, optional
        Fixed-step methods only: steps per output interval (default 1: the grid is the step).
    jit : bool, optional
        Compile the loops to C (``True``) or never (``False``). By default (``None``) every
        method compiles its one chunk loop per model and control mode on first use whenever
        a C compiler (``gcc`` or ``cc``) is found, never depending on how often the model was
        used (see `dynamics.cache`; costs in `dynamics.integrate`). Compiled loops are
        cached; `dynamics.clear_caches` drops them.
    max_steps : int, optional
        ``auto``: most rk8 steps in one run (default 1e8); a tolerance that needs more is
        reported as ``status`` 3, not attempted. ``dop853``: most steps, accepted and
        rejected (a run that needs more fails, NaN from there on).
    cvodes_options : mapping, optional
        Extra options for ``casadi.integrator('cvodes')`` over casadi's defaults (BDF,
        ``max_num_steps`` 10 000 per output interval), e.g.
        ``{'linear_multistep_method': 'adams'}`` (about 2x fewer steps than BDF on a
        non-stiff tumbling body).
    progress : bool or callable, optional
        ``True`` shows a bar on stderr (`dynamics.progress`: tqdm when installed, else a
        text bar). A callable ``progress(done, total)`` is called after every chunk of 512
        fixed steps with the steps done and expected so far (``total`` grows when ``auto``
        starts another run, and counts the run it may need next, so ``done`` reaches
        ``total`` once, at the end); for a progress line on long runs. Not called by
        ``cvodes``.
    events : callable, casadi.Function, Event, or a sequence of them, optional
        Event functions ``g(t, x, u, p) -> scalar`` whose zero crossings are located on the
        solution to the integrator's accuracy (`dynamics.integrate.events`: what is
        detected on which steps), with scipy's attributes ``terminal`` (bool or number of
        occurrences) and ``direction``; `dynamics.Event` gives them to a Function. Results
        in ``t_events`` and ``x_events``; a terminal event ends ``t`` at the event (status
        6). Single runs only (not with ``x0`` of shape (nx, K)).
    impacts : Impact, optional
        A contact (`dynamics.Impact`: a guard and a jump map): when the guard crosses zero
        downwards the state jumps (an impulse: a touchdown, a docking) and the integration
        restarts from the new state (`dynamics.integrate.impacts`); every impact is listed in
        ``impacts`` of the result, and a contact that comes to rest (the Zeno guard
        ``rest_speed``) stops the solution (status 6). Single runs only, not with ``events``.
    threads : int, optional
        A batch (``x0`` of shape ``(nx, K)``): the threads its runs are spread over (the
        runs are independent; each is computed alone, so the answers are the same bits for
        every thread count). Default: ``appdyn.config`` ``"dynamics.threads"``, else the
        cores this process may use (``os.sched_getaffinity``); ``1`` runs the batch in the
        calling thread. A single run uses one thread whatever ``threads`` says.

    Returns
    -------
    SimulationResult
        ``t``, ``x (nx, n)``, ``success``, ``status``, ``message``, ``method``, ``wall_time``,
        ``n_steps``, ``n_rhs``, ``substeps``, ``error_estimate``, ``compiled``,
        ``invariants``, ``t_events``, ``x_events``, ``impacts`` and ``sample(t)``.

    Raises
    ------
    TypeError
        If ``model`` is not a `Model`.
    ValueError
        Naming the argument: non-finite or wrongly shaped ``x0``, ``t`` not strictly
        increasing or shorter than 2, ``u`` or ``p`` of the wrong shape (also a callable
        ``u`` returning the wrong shape), an unknown ``method``, bad ``rtol``/``atol``,
        ``steps`` with a method that does not take it, an unknown ``hold`` or ``'zoh'``
        with a callable ``u``, ``'lie'`` on a model without an
        attitude, unknown ``invariants``, an attitude quaternion in ``x0`` whose norm is
        not 1 to 1e-6, an unknown or ill-typed ``cvodes_options`` entry, ``events`` with a
        batch, an event Function of the wrong inputs or outputs, an event function whose
        value is not one finite number, ``impacts`` with ``events`` or a batch, a jump map
        that returns the wrong number of states. ``TypeError`` for ``cvodes_options`` that
        is not a mapping, ``events`` that are not callables, ``impacts`` that is not an
        `Impact`.

    Notes
    -----
    A numerical failure (cvodes gives up, a fixed-step state becomes non-finite) returns
    ``success=False`` with the reason; it never raises. A fixed-step run whose invariants are
    grossly violated at an output time (a quaternion norm off by more than 1e-3, a conserved
    energy or momentum off by more than its size: `dynamics.integrate.sanity`) is
    ``success=False`` with ``status`` 4: its step is too large for the motion. An exception raised by a callable
    ``u`` or an event function propagates.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics import rigid_body, simulate
    >>> from appdyn.dynamics.truth import torque_free_omega
    >>> inertia, w0, t = [1.0, 2.0, 3.0], [0.1, 0.2, 0.3], np.linspace(0.0, 10.0, 11)
    >>> res = simulate(rigid_body(inertia), [0, 0, 0, 1, *w0], t, method="rk8", steps=10, jit=False)
    >>> res.success, res.x.shape
    (True, (7, 11))
    >>> bool(np.max(np.abs(res.x[4:] - torque_free_omega(inertia, w0, t))) < 1e-10)
    True
    """
    if isinstance(progress, bool):  # True: a bar on stderr (`dynamics.progress`)
        with progress_reporter(progress, "simulate") as bar:
            return simulate(model, x0, t, u=u, p=p, hold=hold, method=method, rtol=rtol,
                            atol=atol, invariants=invariants, steps=steps, jit=jit,
                            max_steps=max_steps, cvodes_options=cvodes_options,
                            progress=bar, events=events, impacts=impacts, threads=threads)
    start = time.perf_counter()
    if ((method == "auto" or method == "dop853") and hold == "linear" and events is None
            and impacts is None and invariants is False and steps is None
            and (jit is None or jit is True) and cvodes_options is None and progress is None
            and threads is None):
        result = _common_call(model, x0, t, rtol, atol, max_steps, start, method, u, p)
        if result is not None:
            return result
    model = check_model(model)
    if method not in METHODS:
        raise ValueError(f"`method` must be one of {METHODS}, got {method!r}")
    t = check_t(t)
    if threads is not None:  # (checked for a single run too, which has one thread)
        batch_threads(threads)
    x = fast_x0(x0, model)  # the common x0 at once (shape (nx,): no batch); else in full
    if x is None:
        shape = getattr(x0, "shape", None)  # (a casadi DM's own: numpy's would warn on it)
        shape = shape if isinstance(shape, tuple) else np.shape(x0)
        if len(shape) == 2 and shape[1] >= 2:
            for name, given in (("events", events), ("impacts", impacts)):
                if given is not None:
                    raise ValueError(f"`{name}` are located for single runs only; simulate "
                                     "the runs of a batch (`x0` of shape (nx, K)) one by one")
            options = RunOptions(method=method, rtol=rtol, atol=atol, steps=steps, jit=jit,
                                 max_steps=max_steps, cvodes_options=cvodes_options,
                                 progress=progress, threads=threads)
            return _simulate_batch(model, x0, t, u, p, options, invariants=invariants,
                                   hold=hold, start=start)
        x = check_x0(x0, model)
    x0 = x
    plan = call_plan(model)
    if plan.clock:  # a time-dependent model: its clock starts at t[0]
        check_clock_start(model, x0, t[0])
    p = model.p_default if p is None else model.resolve_p(p)  # (read-only defaults)
    rtol, atol = check_tolerances(rtol, atol, model.nx)
    control = None if u is None and hold == "linear" else check_u(u, model.nu, t, hold=hold)
    # (None: zero, made if needed)
    names = () if invariants is False else check_invariants(invariants, model)
    if impacts is not None:
        impact = check_impact(impacts)
        if events is not None:
            raise ValueError("`impacts` and `events` are not taken together (yet): locate the "
                             "events on the result of the run with impacts, e.g. by simulating "
                             "between its impact times with `events`")
        options = RunOptions(method=method, rtol=rtol, atol=atol, steps=steps, jit=jit,
                             max_steps=max_steps, cvodes_options=cvodes_options,
                             progress=progress)
        return simulate_impacts(simulate, model, x0, t, impact, u, p, hold=hold,
                                invariants=names, options=options)
    specs = None if events is None else check_events(events, model, t, x0, control, p)
    max_steps, steps, cvodes_options, counter = _check_options(method, max_steps, jit, steps,
                                                               cvodes_options, progress)
    if method == "lie":
        check_lie_model(model, x0, p)
    used, status, estimate = method, OK, math.nan
    run = None
    if control is None and method in _FIXED_STEP and progress is None:
        # the common short run (one chunk, zero control) without `run_fixed`'s machinery
        run = run_short(model, x0, t, p, method, steps, cache.should_compile(jit, math.inf))
    if run is None:
        if control is None:
            control = check_u(None, model.nu, t)
        problem = Problem.new(model, x0, t, control, p)
        if method in _FIXED_STEP:
            run = run_fixed(problem, method, steps, cache.should_compile(jit, math.inf),
                            progress=counter)
        elif method == "cvodes":
            run = run_cvodes(problem, rtol, atol, cvodes_options)
        elif method == "dop853":
            run = run_dop853(problem, rtol, atol, max_steps,
                             compiled=cache.should_compile(jit, math.inf), progress=counter)
        else:
            run, used, status, estimate = solve_auto(problem, rtol, atol, max_steps, jit,
                                                     cvodes_options, counter,
                                                     nonsmooth=plan.nonsmooth)
        counter.finish()
    if (method in _FIXED_STEP or method == "dop853") and run.ok:
        run, status = _sane(model, t, run, control, p, method)
    result = _result(model, t, run, used, status, estimate, control, p, names, start)
    if specs is None:
        return result
    problem = Problem.new(model, x0, t, check_u(None, model.nu, t) if control is None
                          else control, p)
    return apply_events(result, specs, problem, method, rtol, atol, cvodes_options,
                        cache.should_compile(jit, math.inf))


def _common_call(model, x0, t, rtol, atol, max_steps, start: float, method: str = "auto",
                 u=None, p=None):
    """`simulate` of the common call, ``method='auto'`` (or ``'dop853'``) without options:
    a `Model` with no clock state and a smooth right-hand side, ``x0`` of shape ``(nx,)``
    that `fast_x0` takes, a float64 grid `inputs.handed_t` takes, tolerances
    `check_tolerances` takes (``atol`` a float or one per state), an int ``max_steps``, a
    control constant over the run (``u`` None, ``(nu,)``, or samples all equal, as
    `check_u` takes them; not a callable) and the model's parameters or a ``p``
    `Model.resolve_p` takes. Returns the answer of the compiled dense pass
    (`dense.dense_run`) at once when it answers (`auto.dense_outcome`: verified, or below
    the rounding floor; for
    ``dop853`` its answer alone, `stepcontrol.plain_run`, with the sanity check of an
    unverified run on the quaternion's drift the pass measured), ``start`` the call's
    `time.perf_counter`. None for anything else, for a grid the pass finds not finite and
    increasing, or when the pass leaves the run to auto's other paths: the general path
    then decides (and words any error)."""
    if type(model) is not Model:
        return None
    plan = call_plan(model)
    if not plan.common:
        return None
    passes = plan.passes
    if not passes:
        passes.append(pass_plan(model))
    passes = passes[0]
    if passes is None:
        return None
    if type(rtol) in _FLOATS and type(atol) in _FLOATS:  # (numpy's float64 scalars too: a
        rtol, atol = float(rtol), float(atol)            # sweep over `np.logspace`)
        if not (RTOL_MIN <= rtol < 1 and 0 <= atol < math.inf):
            return None
    else:  # (an atol per state, other number types: as the general path checks them)
        try:
            rtol, atol = check_tolerances(rtol, atol, model.nx)
        except (TypeError, ValueError):
            return None
    if type(max_steps) is not int or max_steps < 1:
        return None
    t = handed_t(t)  # (finite and increasing: the pass looks, `dense_run` None if not)
    x0 = fast_x0(x0, model)
    if t is None or x0 is None:
        return None
    control = uc = None
    if u is not None:  # (a constant one; samples and a callable: the general path)
        if callable(u):
            return None
        if type(u) is np.ndarray and u.ndim == 2 and u.shape[1] > 1 and \
                not (u == u[:, :1]).all():
            return None  # (samples that vary: at once, before they are checked twice)
        try:
            control = check_u(u, model.nu, t)
        except ValueError:  # (the general path words it, after the checks before it)
            return None
        if not constant_control(control):
            return None
        uc = control.ua[0]
    if p is None:
        p = model.p_default
    else:
        try:
            p = model.resolve_p(p)
        except (TypeError, ValueError):
            return None
    if method == "dop853":
        run = plain_run(model, x0, t, rtol, atol, max_steps, u=uc, p=p, plan=passes)
        if run is None:
            return None
        status = OK
        if run.ok:
            run, status = _sane(model, t, run, control, p, method)
        return _result(model, t, run, method, status, math.nan, control, p, (), start)
    got = dense_run(model, x0, t, rtol, atol, max_steps, STIFF_STEPS, u=uc, p=p, plan=passes)
    out = None if got is None else dense_outcome(got, rtol)
    if out is None:
        return None
    run, estimate, status = out
    return _result(model, t, run, "rk8", status, estimate, control, p, (), start)


#: The tolerance types `_common_call` takes (a numpy float64 scalar is a Python float).
_FLOATS = (float, np.float64)


def _result(model: Model, t: np.ndarray, run: Run, used: str, status: int, estimate: float,
            control, p: np.ndarray, names: tuple, start: float) -> SimulationResult:
    """The `SimulationResult` of ``run`` (its ``x`` made read-only) by the method ``used``,
    with the invariants ``names`` evaluated; ``control`` None for zero."""
    x = run.x
    x.setflags(False)  # (read-only; positional: a third of the keyword's cost)
    values = MappingProxyType(_invariants(model, x, p, names)) if names else _NO_INVARIANTS
    return new_result(
        t, x, run, success=run.ok and status in (OK, OK_STIFF),
        status=status if run.ok else FAILED, method=used,
        wall_time=time.perf_counter() - start, error_estimate=estimate, invariants=values,
        dense=Dense(model, p, lambda: _zero_grid(t, model.nu) if control is None
                    else control.grid(t), None if control is None else control.left_grid(t)))


#: The ``invariants`` of a result that asked for none (read-only, shared).
_NO_INVARIANTS = MappingProxyType({})


class CallPlan(NamedTuple):
    """What every `simulate` call with one model shares, found once (`call_plan`).

    Attributes
    ----------
    clock : bool
        The model has a clock state (`dynamics.clock`), started at ``t[0]``.
    nonsmooth : tuple of str
        The non-smooth operations of its right-hand side
        (`dynamics.integrate.smoothness.nonsmooth_operations`).
    common : bool
        Neither: the common call (``auto`` at the defaults) may take the compiled dense
        pass at once.
    passes : list
        The model's compiled-pass plan (`dense.pass_plan`; None without a compiler), one
        slot filled in place by the first common call: each later one then looks the model
        up once, not twice (each look-up of the one cache about 0.5 us).
    """

    clock: bool
    nonsmooth: tuple
    common: bool
    passes: list


def call_plan(model: Model) -> CallPlan:
    """The `CallPlan` of ``model`` (cached in the one cache with the model: `dynamics.cache`).

    Examples
    --------
    >>> from appdyn.dynamics import rigid_body
    >>> from appdyn.dynamics.integrate.api import call_plan
    >>> call_plan(rigid_body([1.0, 2.0, 3.0]))[:3]
    (False, (), True)
    """
    def build():
        clock, nonsmooth = CLOCK_STATE in model.states, nonsmooth_operations(model.f)
        return CallPlan(clock, nonsmooth, not clock and not nonsmooth, [])

    return cache.get(("simulate_plan", id(model)), build, keepalive=model)


def _simulate_batch(model, x0, t, u, p, options: RunOptions, *, invariants, hold: str,
                    start: float) -> BatchResult:
    """`simulate` for ``x0`` of shape ``(nx, K)`` (`dynamics.integrate.batch`); ``options``
    as given to `simulate` (checked here), ``start`` its `time.perf_counter` at the call."""
    if clock_index(model) is not None:
        raise ValueError("`x0` of shape (nx, K) (a batch) is not supported for a model with a "
                         "clock state; simulate its runs one by one")
    if invariants not in (False, None, ()):
        raise ValueError("`invariants` are evaluated per run for a batch: use "
                         "`result.run(k).sample` or `model.invariant` on `result.x[:, :, k]`")
    batch = check_batch(model, x0, t, u, p, hold=hold)
    rtol, atol = check_tolerances(options.rtol, options.atol, model.nx)
    max_steps, steps, cvodes_options, counter = _check_options(
        options.method, options.max_steps, options.jit, options.steps, options.cvodes_options,
        options.progress)
    if options.method == "lie":
        check_lie_model(model, batch.x0[:, 0], batch.p[:, 0])
    checked = replace(options, rtol=rtol, atol=atol, steps=steps, max_steps=max_steps,
                      cvodes_options=cvodes_options, progress=counter,
                      threads=batch_threads(options.threads))
    result = simulate_batch(batch, checked, start=start)
    counter.finish()
    return result


def _check_options(method, max_steps, jit, steps, cvodes_options, progress):
    """`simulate`'s run options checked: ``(max_steps, steps, cvodes_options, Progress)``."""
    if type(max_steps) is not int or max_steps < 1:  # (an int >= 1 at once: the common case)
        max_steps = validate.integer(max_steps, "max_steps", minimum=1)
    if jit not in (None, True, False):
        raise ValueError(f"`jit` must be None, True or False, got {jit!r}")
    if method in _FIXED_STEP:
        steps = 1 if steps is None else validate.integer(steps, "steps", minimum=1)
    elif steps is not None:
        raise ValueError(f"`steps` applies to the fixed-step methods {_FIXED_STEP}, not {method!r}")
    cvodes_options = check_cvodes_options(cvodes_options)
    if progress is not None and not callable(progress):
        raise TypeError(f"`progress` must be None, True/False or a callable (done, total), "
                        f"got {type(progress).__name__}")
    return max_steps, steps, cvodes_options, Progress(progress)


def _sane(model: Model, t: np.ndarray, run: Run, control, p: np.ndarray, method: str):
    """``(run, status)`` of a finished fixed-step run: ``VIOLATED`` with the reason and the
    remedy in its message when its invariants are grossly off (`sanity.violation`, with
    the quaternion's drift the run measured, ``run.quat_off``)."""
    bad = violation(model, t, run.x, lambda: _zero_grid(t, model.nu) if control is None
                    else control.grid(t), p, method, quat_off=run.quat_off)
    if not bad:
        return run, OK
    said = run.message if type(run.message) is str else run.message()  # (made on first use)
    return (Run.new(run.x, run.n_steps, run.n_rhs, run.substeps, run.compiled, True,
                    f"{said}; not a solution: {bad}; {remedy(method)}"), VIOLATED)


def _zero_grid(t: np.ndarray, nu: int) -> np.ndarray:
    """The zero control on the grid, shape (nu, n): ``Control.grid`` of ``u=None``, to the
    memory layout."""
    return np.zeros((t.size, nu)).T


def _invariants(model: Model, x: np.ndarray, p: np.ndarray, names) -> dict:
    out = {}
    for name in names:
        value = np.asarray(model.invariant(name, x, p))
        value.setflags(write=False)
        out[name] = value
    return out
