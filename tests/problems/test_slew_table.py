"""`problems.slew.maneuver_table`: rows against the single slews and the closed forms; the
executors give the serial table; progress, Ctrl-C partial tables and bad input."""
from __future__ import annotations

import doctest
import signal
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import appdyn.problems.slew.table as table_module
from appdyn.problems import slew
from appdyn.problems.slew import maneuver_table
from appdyn.dynamics.executors import process_pool

FAST = dict(N=10, starts=1)
AXES = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0])
SINGLE = [{"name": f"a{k}", "angle": th, "axis": AXES[k % 3]}
          for k, th in enumerate([0.05, 0.1, 0.2, 0.3])]


@pytest.fixture(scope="module")
def serial():
    return maneuver_table(np.eye(3), SINGLE, **FAST)


@pytest.mark.slow
def test_time_rows_match_the_bang_bang_closed_form(serial):
    # J = E, |u_i| <= 1, rest to rest about a principal axis: T = 2 sqrt(J theta / u)
    assert serial.success and serial.complete and serial.names == ("a0", "a1", "a2", "a3")
    np.testing.assert_allclose(serial.T, 2 * np.sqrt(serial.angles), rtol=1e-8)


def test_a_row_is_the_single_time_optimal_call(serial):
    one = slew.time_optimal(np.eye(3), angle=0.2, axis=[0, 0, 1], **FAST)
    assert serial.T[2] == pytest.approx(one.T, abs=1e-9)
    assert serial.row_status[2] == one.status and serial.solutions[2].T == serial.T[2]


def test_u_max_scales_the_closed_form():
    t = maneuver_table(np.diag([2.0, 2.0, 2.0]), SINGLE[:2], u_max=0.5, **FAST)
    np.testing.assert_allclose(t.T, 2 * np.sqrt(2.0 * t.angles / 0.5), rtol=1e-8)


def test_effort_rows_match_the_cubic_closed_form():
    q = np.array([[0.0, 0.0, np.sin(0.05), np.cos(0.05)], [np.sin(0.1), 0.0, 0.0, np.cos(0.1)]])
    t = maneuver_table([2.0, 3.0, 4.0], q, objective="effort", T=2.0, u_max=None, N=10)
    J = np.array([4.0, 2.0])  # principal moments about z and x
    assert t.success
    np.testing.assert_allclose(t.angles, [0.1, 0.2], rtol=1e-12)
    np.testing.assert_allclose(t.cost, 6 * J ** 2 * t.angles ** 2 / 2.0 ** 3, rtol=1e-6)


@pytest.mark.slow
def test_executors_give_the_serial_table(serial):
    calls = []
    with ThreadPoolExecutor(2) as threads, process_pool(2) as processes:
        for pool in (threads, processes):
            got = maneuver_table(np.eye(3), SINGLE, executor=pool,
                                 progress=lambda d, n: calls.append((d, n)), **FAST)
            assert np.array_equal(got.T, serial.T) and np.array_equal(got.cost, serial.cost)
            assert got.row_status == serial.row_status and got.names == serial.names
            assert got.executor == type(pool).__name__
    assert calls == [(k, 4) for k in range(1, 5)] * 2


def test_progress_is_called_with_done_and_total():
    calls = []
    maneuver_table(np.eye(3), SINGLE[:3], progress=lambda d, n: calls.append((d, n)), **FAST)
    assert calls == [(1, 3), (2, 3), (3, 3)]


@pytest.mark.parametrize("threads", [False, True])
@pytest.mark.slow
def test_interrupt_keeps_the_finished_rows(serial, threads):
    def stop(done, total):
        if done == 2:
            raise KeyboardInterrupt

    with ThreadPoolExecutor(2) as pool, pytest.raises(KeyboardInterrupt) as info:
        maneuver_table(np.eye(3), SINGLE, progress=stop, executor=pool if threads else None,
                       **FAST)
    part = info.value.partial
    assert not part.complete and not part.success and part.total == 4 and len(part.index) == 2
    assert threads or part.index.tolist() == [0, 1]
    np.testing.assert_array_equal(part.T, serial.T[part.index])
    assert "interrupted after 2 of 4" in part.message


def test_real_ctrl_c_stops_between_targets():
    if signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
        pytest.skip("SIGINT has a non-default handler here")

    def sigint(done, total):
        if done == 1:
            signal.raise_signal(signal.SIGINT)  # deferred to the next target boundary

    with pytest.raises(KeyboardInterrupt) as info:
        maneuver_table(np.eye(3), SINGLE[:3], progress=sigint, **FAST)
    assert info.value.partial.index.tolist() == [0]


def test_outputs(serial):
    d = serial.to_dict()
    assert d["success"] and len(d["rows"]) == 4 and d["rows"][1]["name"] == "a1"
    assert serial.to_json().startswith("{")
    csv = serial.to_csv().splitlines()
    assert csv[0].startswith("name,angle,axis1") and len(csv) == 5
    text = str(serial)
    assert "Maneuver table (minimum time)" in text and "a3" in text


@pytest.mark.parametrize("targets, kw, exc, match", [
    ("abc", {}, TypeError, "`targets`"),
    ([], {}, ValueError, "at least one"),
    (np.zeros((2, 3)), {}, ValueError, r"shape \(K, 4\)"),
    ([{"angle": 0.1}], {}, ValueError, r"`targets\[0\]`"),
    ([{"angle": 0.1, "axis": [0, 0, 0]}], {}, ValueError, r"`targets\[0\]`"),
    ([{"qf": [0, 0, 0, 2]}], {}, ValueError, r"`targets\[0\]`"),
    ([{"angle": 0.1, "axis": [1, 0, 0], "spin": 1}], {}, ValueError, "unknown keys"),
    ([{"name": 3, "qf": [0, 0, 0, 1]}], {}, TypeError, "name"),
    ([{"name": "a", "qf": [0, 0, 0, 1]}, {"name": "a", "qf": [0, 0, 0, 1]}], {}, ValueError,
     "unique"),
    (SINGLE, {"objective": "fast"}, ValueError, "`objective`"),
    (SINGLE, {"objective": "effort"}, ValueError, "`T`"),
    (SINGLE, {"T": 2.0}, ValueError, "`T`"),
    (SINGLE, {"u_max": -1.0}, ValueError, "`u_max`"),
    (SINGLE, {"u_max": None}, ValueError, "`u_max`"),
    (SINGLE, {"inertia": [1.0, 2.0, -3.0]}, ValueError, "`inertia`"),
    (SINGLE, {"executor": "threads"}, TypeError, "`executor`"),
    (SINGLE, {"progress": 3}, TypeError, "`progress`"),
    (SINGLE, {"Nx": 3}, TypeError, "`Nx`"),
    (SINGLE, {"angle": 3}, TypeError, "`angle`"),
])
def test_bad_input_names_the_argument(targets, kw, exc, match):
    kw = dict(kw)
    inertia = kw.pop("inertia", np.eye(3))
    with pytest.raises(exc, match=match):
        maneuver_table(inertia, targets, **kw)


def test_docstring_examples_run_as_written():
    result = doctest.testmod(table_module, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.failed == 0 and result.attempted > 0


# ------------------------------------------------------------------ CLI
@pytest.mark.slow
def test_cli_table_is_the_library_table(tmp_path, capsys):
    import json

    from appdyn.problems.cli import main

    src = tmp_path / "t.csv"
    src.write_text("name,angle,axis1,axis2,axis3,q1,q2,q3,q4\n"
                   "roll,5.729577951308232,1,0,0,,,,\n"
                   "yaw,,,,,0,0,0.04997916927067833,0.9987502603949663\n")
    out = tmp_path / "t.json"
    base = ["slew", "--inertia", "1,1,1", "--time-optimal", "--starts", "1", "--targets",
            str(src), "--quiet"]
    assert main(base + ["--json", str(out)]) == 0
    assert "roll" in capsys.readouterr().out
    rows = json.loads(out.read_text())["rows"]
    lib = maneuver_table(np.eye(3), [{"angle": 0.1, "axis": [1, 0, 0]}], starts=1)
    assert [r["name"] for r in rows] == ["roll", "yaw"]
    assert rows[0]["T"] == pytest.approx(lib.T[0], abs=1e-9)
    assert rows[1]["T"] == pytest.approx(2 * np.sqrt(0.1), rel=1e-8)
    assert main(base + ["--workers", "2", "--json", str(out)]) == 0
    assert [r["T"] for r in json.loads(out.read_text())["rows"]] == [r["T"] for r in rows]


@pytest.mark.parametrize("argv", [
    ["--targets", "/nonexistent.csv"],
    ["--example-targets", "--axis", "1,0,0", "--angle", "10"],
    ["--axis", "1,0,0", "--angle", "10", "--workers", "2"],
])
def test_cli_table_bad_options_exit_2(argv):
    from appdyn.problems.cli import main

    with pytest.raises(SystemExit) as exc:
        main(["slew", "--inertia", "1,1,1", "--time-optimal", *argv])
    assert exc.value.code == 2


# Found in an audit of the executors: each target's task states its slew (`slew_problem`: the
# torque-norm, effort and keep-out Functions; `ocp.Problem` making its functions canonical on
# symbols), building CasADi symbols outside the construction lock while other threads build
# (CasADi counts references without atomics; the heavy-top sweep crashed so). Those builds
# now run under the lock (`dynamics.cache`); every threaded table is the serial one, the
# time-optimal rows polished (the polish's budget is in IPOPT iterations, not seconds: a
# threaded row on a loaded CPU polishes as the serial one does).
RACED = {
    "time": dict(objective="time", **FAST),
    "keep-out": dict(objective="time", N=10, starts=2, norm_bound=True,
                     keep_out=slew.KeepOut([1, 0, 0], [0.955336, 0.29552, 0.5], 0.3)),
    "effort": dict(objective="effort", T=3.0, N=10),
}
RACED_TARGETS = [{"name": f"t{k}", "angle": 0.3 + 0.2 * k, "axis": [1.0, k % 2, 0.5]}
                 for k in range(3)]


@pytest.mark.parametrize("which", [pytest.param("time", marks=pytest.mark.slow),
                                   pytest.param("keep-out", marks=pytest.mark.slow), "effort"])
def test_threaded_tables_build_their_casadi_symbols_one_at_a_time(which):
    inertia = np.diag([1.0, 2.0, 3.0])
    serial = maneuver_table(inertia, RACED_TARGETS, **RACED[which])
    assert serial.success
    with ThreadPoolExecutor(4) as pool:
        for _ in range(5):
            got = maneuver_table(inertia, RACED_TARGETS, executor=pool, **RACED[which])
            assert np.array_equal(got.T, serial.T) and np.array_equal(got.cost, serial.cost)
            assert got.row_status == serial.row_status
            assert np.array_equal(got.iterations, serial.iterations)
            for a, b in zip(got.solutions, serial.solutions):
                assert np.array_equal(a.x, b.x) and np.array_equal(a.u, b.u)
