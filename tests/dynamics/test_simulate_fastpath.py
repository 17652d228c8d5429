"""The per-call fast paths of `simulate` (issue 18, item 3): a common ``x0``/``t`` taken at
once, tolerances and options checked inline, the chunk Function's bound buffer reused
between calls. They must give bit-identical results to the general path and refuse bad
inputs with the same errors. No timing is asserted (``bench/overhead.py`` measures)."""
from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from appdyn import dynamics
from appdyn.dynamics import cache
from appdyn.dynamics.integrate import api, evaluate, inputs
from appdyn.dynamics.integrate.inputs import check_t
from appdyn.dynamics.truth import torque_free_omega

needs_compiler = pytest.mark.skipif(cache.compiler() is None, reason="needs a C compiler")

INERTIA = [1.5, 2.0, 3.25]  # a body of its own: other tests count the chunks of theirs
X0 = [0, 0, 0, 1, 1.0, 0.1, 0.8]
GRID = np.array([0.0, 0.5, 1.25])


@pytest.fixture(scope="module")
def body():
    return dynamics.rigid_body(INERTIA)


@pytest.fixture
def general(monkeypatch):
    """Switch the fast paths of ``x0`` and ``t`` off (the general checks run)."""
    def use():
        monkeypatch.setattr(api, "fast_x0", lambda x0, model: None)
        monkeypatch.setattr(inputs, "fast_x0", lambda x0, model: None)
        monkeypatch.setattr(api, "check_t", _general_t)
    return use


def _general_t(t):
    """`check_t` through its general path (a list of Python ints/objects skips the fast one)."""
    return check_t(np.asarray(t, dtype=object).tolist() if np.ndim(t) else t)


def _x0_variants():
    base = np.array(X0, dtype=float)
    wide = np.zeros((7, 2))
    wide[:, 0] = base
    return {
        "list": list(X0), "tuple": tuple(X0), "float64": base.copy(),
        "float32": base.astype(np.float32), "int": np.array([0, 0, 0, 1, 1, 0, 0]),
        "int-list": [0, 0, 0, 1, 1, 0, 0], "non-contiguous": wide[:, 0],
        "column": base.reshape(7, 1), "DM": ca.DM(base), "bool-mixed": [0, 0, 0, True, 1.0, 0.1, 0.8],
        "uint": np.array([0, 0, 0, 1, 1, 0, 0], dtype=np.uint8),
    }


def _same(a, b):
    np.testing.assert_array_equal(a.x, b.x)
    np.testing.assert_array_equal(a.t, b.t)
    assert (a.success, a.status, a.message, a.method, a.n_steps, a.n_rhs, a.substeps,
            a.compiled) == (b.success, b.status, b.message, b.method, b.n_steps, b.n_rhs,
                            b.substeps, b.compiled)
    assert a.x.dtype == b.x.dtype == np.float64
    assert not a.x.flags.writeable and not a.t.flags.writeable


@pytest.mark.parametrize("name", list(_x0_variants()))
@pytest.mark.parametrize("method", ["rk8", "rk4", "lie"])
def test_x0_fast_path_is_bit_identical(body, general, name, method):
    x0 = _x0_variants()[name]
    fast = dynamics.simulate(body, x0, GRID, method=method, steps=3)
    general()
    slow = dynamics.simulate(body, x0, GRID, method=method, steps=3)
    _same(fast, slow)
    np.testing.assert_array_equal(fast.x[:, 0], np.asarray(x0, dtype=float).reshape(-1))


@pytest.mark.parametrize("t", [
    np.array([0.0, 1.0]), [0.0, 1.0], (0.0, 0.5, 1.0), [0, 1], np.array([0, 1]),
    np.array([0.0, 1.0], dtype=np.float32), np.linspace(0.0, 1.0, 11)[::5],
    np.linspace(0.0, 2.0, 40),
])
def test_t_fast_path_is_bit_identical(body, general, t):
    fast = dynamics.simulate(body, X0, t, method="rk8", steps=2)
    general()
    slow = dynamics.simulate(body, X0, t, method="rk8", steps=2)
    _same(fast, slow)
    np.testing.assert_array_equal(fast.t, np.asarray(t, dtype=float))
    if isinstance(t, np.ndarray):
        assert fast.t is not t and not np.shares_memory(fast.t, t)


def test_inputs_are_copied_not_shared(body):
    x0, t = np.array(X0, dtype=float), np.array([0.0, 1.0])
    res = dynamics.simulate(body, x0, t, method="rk8")
    x0[4] = 99.0
    t[1] = 5.0
    assert res.x[4, 0] == 1.0 and res.t[1] == 1.0
    again = dynamics.simulate(body, [0, 0, 0, 1, 1.0, 0.1, 0.8], [0.0, 1.0], method="rk8")
    np.testing.assert_array_equal(res.x, again.x)


@pytest.mark.parametrize("method", ["auto", "dop853", "rk8"])
def test_parameters_and_control_are_copied_not_shared(method):
    """A result keeps the ``p`` and ``u`` it was made with: changed by the caller after
    the call, its derivatives and dense samples do not move."""
    model = _oscillator()
    p, u = np.array([2.5]), np.array([0.3])
    res = dynamics.simulate(model, [1.0, 0.0], GRID, p=p, u=u, method=method)
    p[0], u[0] = 100.0, -7.0
    again = dynamics.simulate(model, [1.0, 0.0], GRID, p=[2.5], u=[0.3], method=method)
    np.testing.assert_array_equal(res.xdot, again.xdot)
    np.testing.assert_array_equal(res.sample(0.3), again.sample(0.3))


def test_default_options_path_matches_explicit_options(body):
    base = dynamics.simulate(body, X0, GRID, method="rk8", steps=2)
    for kwargs in (dict(jit=True), dict(max_steps=10, cvodes_options=None),
                   dict(progress=lambda done, total: None), dict(rtol=1e-6, atol=[1e-9] * 7),
                   dict(rtol=np.float64(1e-6), atol=0)):
        _same(base, dynamics.simulate(body, X0, GRID, method="rk8", steps=2, **kwargs))


def _message(fun):
    with pytest.raises(Exception) as info:
        fun()
    return type(info.value), str(info.value)


BAD = [
    (dict(x0=[0, 0, 0, 1.0, 1, 0, float("nan")]), "`x0` must be finite"),
    (dict(x0=[0, 0, 0, 1.0, 1, 0, float("inf")]), "`x0` must be finite"),
    (dict(x0=[0, 0, 0, 2.0, 1, 0, 0]), "unit quaternion"),
    (dict(x0=np.array([0, 0, 0, 1 + 3e-6, 1, 0, 0])), "got norm 1.000003"),
    (dict(x0=[0, 0, 0, 1.0, 1, 0]), "`x0` must have shape"),
    (dict(x0=[True] * 7), "`x0` must be real numbers"),
    (dict(x0=["0"] * 7), "`x0` must be real numbers"),
    (dict(x0=np.zeros(7, dtype=complex)), "`x0` must be real numbers"),
    (dict(x0=None), "`x0`"),
    (dict(t=np.array([0.0, 0.0])), "`t` must be strictly increasing"),
    (dict(t=np.array([1.0, 0.0])), "`t` must be strictly increasing"),
    (dict(t=np.array([0.0, np.nan])), "`t` must be finite"),
    (dict(t=[0.0, np.inf]), "`t` must be finite"),
    (dict(t=[-np.inf, 0.0]), "`t` must be finite"),
    (dict(t=[0.0, np.nan, 1.0]), "`t` must be finite"),
    (dict(t=np.array([0.0])), "`t` must be a 1-D grid of at least 2 times"),
    (dict(t=[True, False]), "`t` must be real numbers"),
    (dict(rtol=float("nan")), "`rtol` must be finite"),
    (dict(rtol=1.0), "`rtol` must be in"),
    (dict(rtol=1e-17), "`rtol` must be in"),
    (dict(atol=-1e-3), "`atol` must be non-negative"),
    (dict(atol=float("inf")), "`atol` must be finite"),
    (dict(max_steps=1e8), "`max_steps` must be an integer"),
    (dict(max_steps=0), "`max_steps` must be an integer >= 1"),
    (dict(jit="yes"), "`jit` must be None, True or False"),
    (dict(steps=0), "`steps` must be an integer >= 1"),
    (dict(steps=1.5), "`steps` must be an integer"),
    (dict(progress=3), "`progress` must be None, True/False or a callable"),
    (dict(cvodes_options=[1]), "`cvodes_options` must be a mapping"),
]


@pytest.mark.parametrize("bad, match", BAD, ids=[m for _, m in BAD])
def test_bad_inputs_refused_alike(body, general, bad, match):
    kwargs = dict(x0=X0, t=GRID, method="rk8")
    kwargs.update(bad)
    x0, t = kwargs.pop("x0"), kwargs.pop("t")
    fast = _message(lambda: dynamics.simulate(body, x0, t, **kwargs))
    assert match in fast[1]
    general()
    assert _message(lambda: dynamics.simulate(body, x0, t, **kwargs)) == fast


def test_bound_buffer_reused_across_grids_and_controls(body):
    """The buffer keeps h and the control between calls: every call still sees only its own."""
    calls = [(GRID, 700, None), (GRID, 1, None), (np.array([0.0, 1.0]), 3, [0.01, 0.0, -0.02]),
             (GRID, 2, [0.01, 0.0, -0.02]), (GRID, 2, None),
             (np.linspace(0.0, 1.0, 4), 1, np.full((3, 4), 0.03) + np.arange(4) * 0.01),
             (GRID, 1, None), (np.array([0.0, 1.0]), 3, [0.02, 0.0, -0.02])]
    for jit in (None, False):
        got = [dynamics.simulate(body, X0, t, u=u, method="rk8", steps=s, jit=jit).x
               for t, s, u in calls]
        for (t, s, u), x in zip(calls, got):
            evaluate._thread_table("bound").clear()  # a fresh buffer, zero-filled
            fresh = dynamics.simulate(body, X0, t, u=u, method="rk8", steps=s, jit=jit).x
            np.testing.assert_array_equal(x, fresh)


def test_callable_control_unchanged_by_buffer_reuse(body):
    t = np.linspace(0.0, 1.0, 5)
    u = lambda s: [0.01 * s, 0.0, -0.02]  # noqa: E731
    first = dynamics.simulate(body, X0, t, u=u, method="rk8", steps=3).x
    dynamics.simulate(body, X0, GRID, u=[0.5, 0.5, 0.5], method="rk8", steps=3)
    np.testing.assert_array_equal(dynamics.simulate(body, X0, t, u=u, method="rk8", steps=3).x,
                                  first)


def test_function_key_remembered_and_dropped():
    x = ca.SX.sym("x")
    f = ca.Function("f", [x], [2 * x])
    assert cache.function_key(f) == hash(f) == cache.function_key(f)
    key = id(f)
    assert key in cache._KEYS
    del f
    import gc
    gc.collect()
    assert key not in cache._KEYS


def test_bound_buffer_dropped_with_its_function(body):
    x = ca.SX.sym("x", 2)
    f = ca.Function("twice", [x], [2 * x])
    buf = evaluate.borrow_bound(f, lambda: ([(2,)], (2,)))
    buf.args[0][:] = [1.0, 2.0]
    buf.trigger()
    np.testing.assert_array_equal(buf.out, [2.0, 4.0])
    evaluate.return_bound(f, buf)
    key = id(f)
    assert key in evaluate._thread_table("bound")
    del f, buf
    import gc
    gc.collect()
    assert key not in evaluate._thread_table("bound")


@pytest.mark.parametrize("method", ["rk8", "rk4", "lie"])
@pytest.mark.parametrize("t, steps", [
    (np.array([0.0, 1.0]), 1), (GRID, 3), (np.linspace(0.0, 2.0, 17), 32),  # 512: one chunk
    (np.array([0.0, 0.1, 0.35, 0.4, 1.0]), 1), (np.linspace(0.0, 1.0, 6), 1),
    (np.linspace(0.0, 1.0, 513), 1),
    (np.linspace(0.0, 2.0, 18), 32),  # 544 steps: two chunks, the general loop
    (np.array([0.0, 1e-3]), 700),
])
@pytest.mark.parametrize("jit", [None, False])
def test_short_run_path_is_bit_identical(body, monkeypatch, method, t, steps, jit):
    """`run_short` (zero control, one chunk) against `run_fixed` (the general loop)."""
    fast = dynamics.simulate(body, X0, t, method=method, steps=steps, jit=jit)
    monkeypatch.setattr(api, "run_short", lambda *args: None)
    slow = dynamics.simulate(body, X0, t, method=method, steps=steps, jit=jit)
    _same(fast, slow)
    assert fast.wall_time > 0
    np.testing.assert_array_equal(fast.xdot, slow.xdot)
    np.testing.assert_array_equal(fast.sample(t[-1] / 3), slow.sample(t[-1] / 3))
    assert dict(fast.invariant_drift) == dict(slow.invariant_drift)
    np.testing.assert_array_equal(fast._dense._controls(), slow._dense._controls())
    assert fast._dense._controls().flags.f_contiguous == slow._dense._controls().flags.f_contiguous


def test_short_run_with_invariants_and_a_non_finite_state(body, monkeypatch):
    x0 = [0, 0, 0, 1, 1e200, 1e200, 1e200]  # the rates overflow in the first step
    t = np.array([0.0, 1.0, 2.0])
    fast = [dynamics.simulate(body, x0, t, method="rk8"),
            dynamics.simulate(body, X0, t, method="rk4", invariants=True)]
    monkeypatch.setattr(api, "run_short", lambda *args: None)
    slow = [dynamics.simulate(body, x0, t, method="rk8"),
            dynamics.simulate(body, X0, t, method="rk4", invariants=True)]
    assert not fast[0].success and "non-finite" in fast[0].message
    for a, b in zip(fast, slow):
        _same(a, b)
        assert a.invariants.keys() == b.invariants.keys()
        for k in a.invariants:
            np.testing.assert_array_equal(a.invariants[k], b.invariants[k])


# ------------------------------------------------------------ the common `auto` call
# `simulate(model, x0, t)` at the defaults goes to the compiled dense pass at once
# (`api._common_call`: a per-model call plan, a thread's reused workspace, one ctypes call);
# it must give what the general path gives, bit for bit, and refuse what it refuses.


@pytest.fixture
def common_calls(monkeypatch):
    """Count the calls the common path answered; ``off()`` switches it off."""
    answered = []
    take = api._common_call

    def counted(*args):
        result = take(*args)
        if result is not None:
            answered.append(result)
        return result

    monkeypatch.setattr(api, "_common_call", counted)
    counted.answered = answered
    counted.off = lambda: monkeypatch.setattr(api, "_common_call", lambda *args: None)
    return counted


def _oscillator():
    """A smooth model with a parameter and a control: ``y'' = -k y + u``."""
    y, v, u, k = (ca.SX.sym(n) for n in "yvuk")
    return dynamics.Model.from_expressions({"y": y, "v": v}, {"y": v, "v": -k * y + u},
                                           {"u": u}, {"k": k}, p_default=[4.0])


def _same_auto(a, b):
    _same(a, b)
    assert a.error_estimate == b.error_estimate
    np.testing.assert_array_equal(a.xdot, b.xdot)
    np.testing.assert_array_equal(a.sample(0.3), b.sample(0.3))


@needs_compiler
@pytest.mark.parametrize("case", ["2-point", "list grid", "41 outputs", "x0 list", "oscillator",
                                  "int list grid", "int64 grid", "uint8 grid"])
def test_common_auto_call_is_the_general_path(body, common_calls, case):
    model, x0, t = body, np.array(X0, dtype=float), np.array([0.0, 10.0])
    if case == "list grid":
        t = [0.0, 0.5, 2.0]
    elif case == "int list grid":
        t = [0, 1, 3]
    elif case == "int64 grid":
        t = np.arange(0, 21, 2)
    elif case == "uint8 grid":
        t = np.array([0, 2, 5], dtype=np.uint8)
    elif case == "41 outputs":
        t = np.linspace(0.0, 20.0, 41)
    elif case == "x0 list":
        x0 = list(X0)
    elif case == "oscillator":
        model, x0 = _oscillator(), [1.0, 0.0]
    fast = dynamics.simulate(model, x0, t)
    assert len(common_calls.answered) == 1 and fast.success and fast.status == 0
    common_calls.off()
    slow = dynamics.simulate(model, x0, t)
    _same_auto(fast, slow)
    if model is body:  # the torque-free truth, to the tolerance
        w = torque_free_omega(INERTIA, fast.x[4:, 0], fast.t)
        assert np.all(np.abs(fast.x[4:] - w) <= 1e-10 + 1e-8 * np.abs(w))


@needs_compiler
@pytest.mark.parametrize("kwargs", [dict(max_steps=np.int64(10 ** 6)), dict(jit=False),
                                    dict(invariants=True), dict(threads=1),
                                    dict(u=np.outer([0.1, 0.0, -0.2], [1.0, 0.5, 0.0])),
                                    dict(u=lambda t: [0.1, 0.0, 0.0]),
                                    dict(u=[0.1, 0.0, 0.0], hold="zoh")])
def test_common_auto_call_declines_the_rest_alike(body, common_calls, kwargs):
    """What the common path does not take (other types, options) goes the general way,
    unchanged."""
    fast = dynamics.simulate(body, X0, GRID, **kwargs)
    assert common_calls.answered == []
    common_calls.off()
    _same(fast, dynamics.simulate(body, X0, GRID, **kwargs))


@needs_compiler
@pytest.mark.parametrize("method", ["auto", "dop853"])
@pytest.mark.parametrize("case", ["p", "p for none", "constant u", "u a scalar",
                                  "samples all equal", "u and p"])
def test_common_call_takes_a_constant_control_and_parameters(body, common_calls, method,
                                                              case):
    """A control constant over the run (``(nu,)``, or samples all equal) and given
    parameters take the common call: what the general path gives, to the bit (the result's
    dense output and derivatives included), here against a body under a constant torque
    and the oscillator ``y'' = -k y + u`` at its own ``k``."""
    model, x0, t, kw = body, list(X0), np.linspace(0.0, 5.0, 6), {}
    if case == "p":
        model, x0, kw = _oscillator(), [1.0, 0.0], dict(p=[2.5])
    elif case == "p for none":
        kw = dict(p=[])
    elif case == "constant u":
        kw = dict(u=[0.05, -0.02, 0.01])
    elif case == "u a scalar":
        model, x0, kw = _oscillator(), [1.0, 0.0], dict(u=0.3)
    elif case == "samples all equal":
        kw = dict(u=np.tile([[0.05], [-0.02], [0.01]], t.size))
    else:
        model, x0, kw = _oscillator(), [1.0, 0.0], dict(u=[0.3], p=np.array([2.5]))
    fast = dynamics.simulate(model, x0, t, method=method, **kw)
    assert len(common_calls.answered) == 1 and fast.success
    common_calls.off()
    slow = dynamics.simulate(model, x0, t, method=method, **kw)
    (_same_auto if method == "auto" else _same)(fast, slow)
    np.testing.assert_array_equal(fast.xdot, slow.xdot)
    if case in ("p", "u and p", "u a scalar"):  # y = A cos(w t) + u / k, w = sqrt(k)
        k = 2.5 if "p" in case else 4.0
        uu = 0.3 if "u" in case else 0.0
        y = (1.0 - uu / k) * np.cos(np.sqrt(k) * t) + uu / k
        assert np.abs(fast.x[0] - y).max() <= 1e-7


@needs_compiler
@pytest.mark.parametrize("bad", [dict(p=[1.0, 2.0]), dict(p=[np.nan]), dict(u=[np.inf]),
                                 dict(u=[1.0, 2.0]), dict(u="a"), dict(p="k")])
def test_bad_control_or_parameters_refused_alike_by_the_common_call(common_calls, bad):
    model = _oscillator()
    fast = _message(lambda: dynamics.simulate(model, [1.0, 0.0], GRID, **bad))
    assert common_calls.answered == [] and fast[0] is ValueError
    common_calls.off()
    assert _message(lambda: dynamics.simulate(model, [1.0, 0.0], GRID, **bad)) == fast


@needs_compiler
def test_common_auto_call_declines_a_nonsmooth_model(common_calls):
    x = ca.SX.sym("x")
    model = dynamics.Model.from_expressions({"x": x}, {"x": -ca.fabs(x)})
    res = dynamics.simulate(model, [1.0], np.array([0.0, 1.0]))
    assert common_calls.answered == [] and res.method == "dop853"
    assert abs(res.x[0, -1] - np.exp(-1.0)) <= 1e-8 * np.exp(-1.0) + 1e-10  # x = exp(-t)


@needs_compiler
def test_common_auto_call_results_share_no_memory(body):
    """The answer is copied out of the thread's reused buffer: an earlier result keeps its
    states when the same call is made again from another start."""
    first = dynamics.simulate(body, X0, GRID)
    kept = first.x.copy()
    other = dynamics.simulate(body, [0, 0, 0, 1, 0.2, -0.5, 0.3], GRID)
    np.testing.assert_array_equal(first.x, kept)
    assert not np.shares_memory(first.x, other.x)
    assert not first.x.flags.writeable


AUTO_BAD = [(bad, match) for bad, match in BAD if "steps" not in bad]


@pytest.mark.parametrize("bad, match", AUTO_BAD, ids=[m for _, m in AUTO_BAD])
def test_bad_inputs_refused_alike_by_the_common_auto_call(body, common_calls, bad, match):
    kwargs = dict(x0=X0, t=GRID)
    kwargs.update(bad)
    x0, t = kwargs.pop("x0"), kwargs.pop("t")
    fast = _message(lambda: dynamics.simulate(body, x0, t, **kwargs))
    assert match in fast[1]
    common_calls.off()
    assert _message(lambda: dynamics.simulate(body, x0, t, **kwargs)) == fast


@needs_compiler
def test_dense_message_made_on_first_read_pickled_made(body, common_calls):
    """The verified dense pass's message is made when first read (`result.Run`), once:
    the same text every read and thread, pickled and rebuilt by `result_fields`."""
    import pickle
    import threading

    from appdyn.dynamics.integrate.result import make_result, result_fields
    res = dynamics.simulate(body, X0, GRID)
    assert common_calls.answered == [res] and "message" not in res.__dict__
    fields = make_result(**result_fields(res))
    texts = []
    threads = [threading.Thread(target=lambda: texts.append(res.message)) for _ in range(4)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert len(set(texts)) == 1 and texts[0].startswith("auto: DOP853 with dense output")
    assert all(text is res.message for text in texts)
    assert fields.message == res.message == pickle.loads(pickle.dumps(res)).message
    common_calls.off()
    assert dynamics.simulate(body, X0, GRID).message == res.message


def _grids():
    """Grids the compiled pass refuses as `check_t` does, short and long (it looks at every
    time, in its first loop over them), the fault at the start, inside and at the end."""
    long = np.linspace(0.0, 30.0, 40)
    out = {}
    for where, k in (("first", 0), ("inside", 17), ("last", 39)):
        for what, value in (("nan", np.nan), ("inf", np.inf), ("-inf", -np.inf)):
            g = long.copy()
            g[k] = value
            out[f"{what} {where}"] = g
    g = long.copy()
    g[18] = g[17]
    out["a time repeated"] = g
    g = long.copy()
    g[38], g[39] = g[39], g[38]
    out["the last two swapped"] = g
    out["decreasing"] = long[::-1].copy()
    out["a list, nan inside"] = [0.0, 1.0, float("nan"), 3.0]
    return out


@needs_compiler
@pytest.mark.parametrize("method", ["auto", "dop853"])
@pytest.mark.parametrize("name", list(_grids()))
def test_a_grid_handed_over_unchecked_is_refused_as_check_t_refuses_it(
        body, common_calls, method, name):
    """The common call hands its grid to the compiled pass unchecked (`inputs.handed_t`);
    the pass looks (`cpass` ``au_grid_ok``) and a grid `check_t` refuses is never run: the
    same error, word for word, from the general path."""
    t = _grids()[name]
    fast = _message(lambda: dynamics.simulate(body, X0, t, method=method))
    assert fast[0] is ValueError and ("`t` must be" in fast[1]), fast
    assert common_calls.answered == []
    with pytest.raises(ValueError) as info:
        check_t(t)
    assert str(info.value) == fast[1]
    common_calls.off()
    assert _message(lambda: dynamics.simulate(body, X0, t, method=method)) == fast


@needs_compiler
@pytest.mark.parametrize("case", ["2-point", "41 outputs", "list grid", "too loose",
                                  "oscillator"])
def test_common_dop853_call_is_the_general_path(body, common_calls, case):
    """``method='dop853'`` at the defaults takes the pass at once, its substeps and the
    quaternion's drift measured in C: the same result, bit for bit, as the general path
    (`stepcontrol.plain_run`, `sanity.violation` in Python), a drifting quaternion (rtol
    0.05 over 600 s) refused alike."""
    model, x0, t, rtol = body, np.array(X0, dtype=float), np.array([0.0, 10.0]), 1e-8
    if case == "41 outputs":
        t = np.linspace(0.0, 20.0, 41)
    elif case == "list grid":
        t = [0.0, 0.5, 2.0]
    elif case == "too loose":
        t, rtol = np.linspace(0.0, 600.0, 601), 0.05
    elif case == "oscillator":
        model, x0 = _oscillator(), [1.0, 0.0]
    fast = dynamics.simulate(model, x0, t, method="dop853", rtol=rtol)
    assert len(common_calls.answered) == 1
    assert fast.success == (case != "too loose")
    if case == "too loose":
        assert fast.status == 4 and "the attitude quaternion's norm is" in fast.message
    common_calls.off()
    _same(fast, dynamics.simulate(model, x0, t, method="dop853", rtol=rtol))


@needs_compiler
@pytest.mark.parametrize("method", ["auto", "dop853"])
@pytest.mark.parametrize("tolerances", [(np.float64(1e-6), 1e-10), (1e-6, np.float64(1e-9)),
                                        tuple(np.logspace(-7, -9, 2)), (1e-7, [1e-9] * 7),
                                        (1e-7, np.geomspace(1e-12, 1e-9, 7)),
                                        (np.float32(1e-6), np.float32(1e-9))])
def test_other_tolerances_take_the_common_call(body, common_calls, method, tolerances):
    """Tolerances that are numpy scalars (a sweep over ``np.logspace`` hands them over) or
    an ``atol`` per state: the common call checks them as the general path does
    (`check_tolerances`), with the result the general path gives to the bit."""
    rtol, atol = tolerances
    fast = dynamics.simulate(body, X0, GRID, method=method, rtol=rtol, atol=atol)
    assert len(common_calls.answered) == 1 and fast.success
    common_calls.off()
    slow = dynamics.simulate(body, X0, GRID, method=method, rtol=rtol, atol=atol)
    (_same_auto if method == "auto" else _same)(fast, slow)


@pytest.mark.parametrize("atol", [np.geomspace(1e-12, 1e-6, 7), np.zeros(7),
                                  np.r_[np.full(6, 1e-9), np.nan], np.r_[np.full(6, 1e-9), np.inf],
                                  np.r_[np.full(6, 1e-9), -1e-9], np.r_[np.full(6, 1e-9), -0.0]])
def test_an_atol_per_state_is_checked_alike_as_an_array_and_as_a_list(atol):
    """`inputs.check_tolerances` takes a float64 array of one ``atol`` per state at once
    (its checks in Python floats); a list of the same numbers takes the general checks:
    the same values returned (a copy), the same error refused."""
    from appdyn.dynamics.integrate.inputs import check_tolerances

    def outcome(value):
        try:
            return check_tolerances(1e-8, value, 7)
        except ValueError as exc:
            return str(exc)

    fast, slow = outcome(atol), outcome(atol.tolist())
    if isinstance(slow, str):
        assert isinstance(fast, str) and fast.split(",")[0] == slow.split(",")[0]
    else:
        assert fast[0] == slow[0] == 1e-8
        np.testing.assert_array_equal(fast[1], slow[1])
        assert fast[1] is not atol and not np.shares_memory(fast[1], atol)
