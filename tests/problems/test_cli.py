"""The `appdyn` command line and the torque-free job behind it."""
import json

import numpy as np
import pytest

from appdyn.problems.cli import main
from appdyn.problems.torque_free import torque_free


@pytest.mark.slow
def test_torque_free_summary_and_json(tmp_path, capsys):
    out = tmp_path / "tf.json"
    code = main(["simulate", "torque-free", "--inertia", "1,2,3", "--w0", "1,0.1,0.8",
                 "--t-final", "20", "--json", str(out)])
    assert code == 0
    text = capsys.readouterr().out
    assert "max |w - w_exact|" in text and "energy drift" in text and "wall time" in text
    data = json.loads(out.read_text())
    assert data["success"] is True
    assert data["max_rate_error"] < 1e-8  # requested rtol 1e-10 over 20 s
    assert data["energy_drift"] < 1e-9 and data["momentum_drift"] < 1e-9


@pytest.mark.slow
def test_torque_free_plot_written(tmp_path):
    path = tmp_path / "tf.png"
    assert main(["simulate", "torque-free", "--inertia", "1,2,3", "--w0", "0.2,1,0.1",
                 "--t-final", "10", "--points", "201", "--plot", str(path)]) == 0
    assert path.stat().st_size > 10_000


def test_full_inertia_matrix_compared_in_principal_axes():
    I = np.array([[4560.7, 31.2, -43.4], [31.2, 4545.0, -270.7], [-43.4, -270.7, 1567.4]])
    # atol 1e-12: a unit quaternion cannot be verified to 1e-13 (450 ulps; simulate
    # reports tolerances within 2000 ulps of a state as status 2, the round-off floor)
    rep = torque_free(I, [0.01, 0.02, 0.3], t_final=50.0, rtol=1e-11, atol=1e-12)
    assert rep.success
    assert rep.max_rel_rate_error < 1e-8
    assert rep.momentum_drift < 1e-9


@pytest.mark.parametrize(
    "args, message",
    [
        (["--inertia", "1,1,3", "--w0", "1,0,0"], "triangle inequality"),
        (["--inertia", "1,2", "--w0", "1,0,0"], "expected 3 or 9"),
        (["--inertia", "1,2,3", "--w0", "1,nan,0"], "finite"),
        (["--inertia", "1,2,3", "--w0", "1,0,0", "--t-final", "-1"], "positive"),
        (["--inertia", "1,2,3,0,0,0,1,0,0", "--w0", "1,0,0"], "symmetric"),
    ],
)
def test_bad_input_exits_with_message(args, message, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["simulate", "torque-free", *args])
    assert exc.value.code == 2
    assert message in capsys.readouterr().err


def test_slew_min_effort_cli(tmp_path, capsys):
    out = tmp_path / "slew.json"
    code = main(["slew", "--inertia", "2,3,4", "--axis", "1,0,0", "--angle", "57.29577951308232",
                 "--min-effort", "2", "--json", str(out), "--quiet"])
    assert code == 0
    assert "maneuver time T" in capsys.readouterr().out
    data = json.loads(out.read_text())
    assert data["cost"] == pytest.approx(6 * 2.0**2 / 2.0**3, rel=1e-7)  # 6 J^2 theta^2 / T^3


@pytest.mark.parametrize(
    "args, message",
    [
        (["--inertia", "1,1,1", "--axis", "0,0,1", "--time-optimal"], "--angle"),
        (["--inertia", "1,1,1", "--axis", "0,0,1", "--angle", "90"], "one of the arguments"),
        (["--inertia", "1,1,1", "--axis", "0,0,1", "--angle", "90", "--min-effort", "-2"],
         "positive"),
    ],
)
def test_slew_bad_input(args, message, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["slew", *args])
    assert exc.value.code == 2
    assert message in capsys.readouterr().err


@pytest.mark.slow
def test_torque_free_report_status_plot_and_deprecated_worst_axis():
    from matplotlib.figure import Figure

    from appdyn.problems.torque_free import STATUS_CHECK_FAILED, STATUS_VERIFIED

    rep = torque_free([1.0, 2.0, 3.0], [0.2, 1.0, 0.1], t_final=5.0, n_points=51)
    assert rep.status == STATUS_VERIFIED and rep.to_dict()["status"] == STATUS_VERIFIED
    assert isinstance(rep.plot(), Figure)
    with pytest.warns(DeprecationWarning, match="worst_component"):
        assert rep.worst_axis == rep.worst_component
    tight = torque_free([1.0, 2.0, 3.0], [0.2, 1.0, 0.1], t_final=5.0, n_points=51,
                        method="rk4", tol=1e-15)
    assert tight.status == STATUS_CHECK_FAILED and not tight.success


def test_umax_is_a_hidden_alias_of_u_max(capsys):
    from appdyn.problems.cli import build_parser

    parser = build_parser()
    base = ["slew", "--inertia", "1,1,1", "--axis", "0,0,1", "--angle", "90", "--time-optimal"]
    new = parser.parse_args(base + ["--u-max", "2"])
    old = parser.parse_args(base + ["--umax", "2"])
    assert new.u_max.tolist() == old.u_max.tolist() == [2.0]
    with pytest.raises(SystemExit):
        parser.parse_args(["slew", "--help"])
    text = capsys.readouterr().out
    assert "--u-max" in text and "--umax" not in text


def test_bench_passes_quick_and_out_to_run(tmp_path, monkeypatch, capsys):
    """`appdyn bench NAME --quick --out DIR` calls bench/NAME.py's run(True, DIR)."""
    from appdyn.problems.cli import bench

    seen = tmp_path / "seen.txt"
    (tmp_path / "probe.py").write_text(
        "def run(quick, out):\n"
        "    open(%r, 'w').write(f'{quick} {out}')\n"
        "    return []\n" % str(seen))
    monkeypatch.setattr(bench, "BENCH_DIR", tmp_path)
    out = tmp_path / "res"
    assert main(["bench", "probe", "--quick", "--out", str(out)]) == 0
    assert seen.read_text() == f"True {out}" and (out / "machine.json").is_file()
    assert main(["bench", "probe", "--out", str(out)]) == 0 and seen.read_text() == f"False {out}"
    assert main(["bench", "missing"]) == 2
    with pytest.raises(SystemExit) as exc:
        main(["bench", "probe", "--out", str(seen)])  # a file, not a folder
    assert exc.value.code == 2


@pytest.mark.slow
def test_slew_verbose_keeps_stdout_to_the_summary(tmp_path, capfd):
    """``appdyn slew ... --time-optimal`` (verbose: no --quiet): IPOPT's iterations go to
    stderr labelled by stage, the summary says what the polish did and the total wall time."""
    import re

    out = tmp_path / "slew.json"
    code = main(["slew", "--inertia", "1,1,1", "--u-max", "1", "--axis", "0,0,1", "--angle",
                 "180", "--time-optimal", "--json", str(out)])
    stdout, stderr = capfd.readouterr()
    assert code == 0
    iteration = re.compile(r"^\s*\d+\s+[-+]?\d\.\d+e[-+]\d+")
    assert not any(iteration.match(line) for line in stdout.splitlines()), stdout
    assert "This is Ipopt" not in stdout and "objective (scaled)" not in stdout
    assert "[slew: start 1/3]" in stderr and "[slew: start 2/3]" in stderr  # (the third:
    # skipped once two starts agree, `solve_multistart(agree=)`)
    assert "[polish]" in stderr
    assert "switch-time polish" in stdout and "wall time, total [s]" in stdout
    data = json.loads(out.read_text())
    assert data["polish"]["ran"] and data["polish"]["used"]
    assert data["polish"]["gain"] == pytest.approx(data["polish"]["T_before"] - data["T"])
    assert data["wall_time"] >= data["polish"]["wall_time"] + data["solve_time"]


def test_min_effort_verbose_labels_every_stage_on_stderr(tmp_path, capfd):
    """A minimum-effort slew, verbose: the first solve's and each refinement round's IPOPT
    lines go to stderr labelled ``[slew]``, ``[refine round k]`` and ``[refine]``; stdout
    holds the summary only."""
    import re

    code = main(["slew", "--inertia", "1,2,3", "--min-effort", "4", "--axis", "0,0,1", "--angle", "60",
                 "--json", str(tmp_path / "effort.json")])
    stdout, stderr = capfd.readouterr()
    assert code == 0
    iteration = re.compile(r"^\s*\d+\s+[-+]?\d\.\d+e[-+]\d+")
    assert not any(iteration.match(line) for line in stdout.splitlines()), stdout
    assert "[slew]" in stderr and "[refine round 1]" in stderr and "[refine] refine round 0" in stderr
    unlabelled = [line for line in stderr.splitlines() if line and not line.startswith("[")]
    assert not unlabelled, unlabelled[:5]


def test_help_imports_neither_numpy_nor_the_library():
    """`appdyn --help` builds one-line entries only (the benchmark bench/cli.py times it)."""
    import subprocess
    import sys
    from pathlib import Path

    probe = ("import sys, io, contextlib\n"
             "from appdyn.problems.cli import main\n"
             "with contextlib.redirect_stdout(io.StringIO()) as out:\n"
             "    try:\n"
             "        main(['--help'])\n"
             "    except SystemExit:\n"
             "        pass\n"
             "print('numpy' in sys.modules, 'appdyn.dynamics' in sys.modules, 'slew' in out.getvalue())")
    root = str(Path(__file__).resolve().parents[2])
    got = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         check=True, env={"PYTHONPATH": root, "PATH": ""}).stdout.split()
    assert got == ["False", "False", "True"]


def test_the_one_line_helps_are_the_commands_own():
    from appdyn.problems.cli import HELP, build_parser

    sub = next(a for a in build_parser("all")._actions if a.dest == "command")
    assert {c.dest: c.help for c in sub._choices_actions} == HELP
