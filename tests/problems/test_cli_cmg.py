"""``appdyn cmg envelope`` and ``appdyn cmg steer``, run in-process through `problems.cli.main`.

Independent truths: the pyramid's closed-form envelope extents 2 h (1 + cos beta) (x, y) and
4 h sin beta (z), computed here; momentum exchange ``H(t) = H(0) - torque t`` for the
pseudo-inverse away from singular states.
"""
import doctest

import numpy as np
import pytest

from appdyn.problems.cli import COMMANDS, main
from appdyn.problems.cli import cmg as cmg_cli
from tests.problems.test_cli_trust import exit_code, strict_loads

BETA = 54.74
ENV = ["cmg", "envelope", "--beta", str(BETA)]
STEER = ["cmg", "steer", "--beta", str(BETA)]


def test_registered():
    assert COMMANDS["cmg"] is cmg_cli


@pytest.mark.slow
def test_envelope_checks_the_closed_forms(tmp_path, capsys):
    plot, out = tmp_path / "env.png", tmp_path / "env.json"
    assert main([*ENV, "--plot", str(plot), "--json", str(out)]) == 0
    text = capsys.readouterr().out
    assert "Momentum envelope" in text and "check passed" in text and "2 h (1 + cos beta)" in text
    assert plot.stat().st_size > 10_000
    data = strict_loads(out.read_text())
    b = np.deg2rad(BETA)
    check = data["closed_form_check"]
    assert check["passed"] is True
    assert check["closed_form"]["x"] == pytest.approx(2 * (1 + np.cos(b)), abs=1e-12)
    assert check["closed_form"]["z"] == pytest.approx(4 * np.sin(b), abs=1e-12)
    for axis in "xyz":
        assert check["computed"][axis] == pytest.approx(check["closed_form"][axis], abs=1e-9)
    assert data["groups"]["0"]["elliptic"] == data["groups"]["0"]["points"]


def test_envelope_unequal_rotors(capsys):
    assert main([*ENV, "--h", "1,2,1.5,0.5", "--directions", "400"]) == 0
    assert "cos beta (h1 + h3) + h2 + h4" in capsys.readouterr().out
    ext = cmg_cli.pyramid_extent(np.deg2rad(BETA), [1.0, 2.0, 1.5, 0.5])
    assert ext["x"] == pytest.approx(np.cos(np.deg2rad(BETA)) * 2.5 + 2.5)


def test_envelope_failed_check_exits_1(monkeypatch, capsys):
    monkeypatch.setattr(cmg_cli, "pyramid_extent",
                        lambda beta, h: {"x": 3.0, "y": 3.0, "z": 3.0})
    assert main([*ENV, "--directions", "100"]) == 1
    captured = capsys.readouterr()
    assert "check FAILED" in captured.out and "closed-form check failed" in captured.err


@pytest.mark.slow
def test_steer_sr_report_plot_and_json(tmp_path, capsys):
    plot, out = tmp_path / "steer.png", tmp_path / "steer.json"
    argv = [*STEER, "--torque", "0,0,0.5", "--law", "sr", "--t-final", "10", "--plot",
            str(plot), "--json", str(out), "--torque-tol", "inf"]
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "CMG steering" in text and "d1 [deg]" in text and "-90.000" in text  # degrees
    assert plot.stat().st_size > 10_000
    data = strict_loads(out.read_text())
    assert data["success"] is True and data["law"] == "sr"
    assert np.array(data["delta"]).shape == (4, 201)


def test_steer_saturated_cluster_exits_1_unless_the_torque_error_is_accepted(capsys):
    """0.5 N m along z saturates the cluster (4 h sin beta = 3.27 N m s) after 6.5 s: 6 s is a
    success; 10 s is not (the torque is not delivered), unless --torque-tol accepts it."""
    assert main([*STEER, "--torque", "0,0,0.5", "--law", "sr", "--t-final", "6"]) == 0
    capsys.readouterr()
    assert main([*STEER, "--torque", "0,0,0.5", "--law", "sr", "--t-final", "10"]) == 1
    assert "not delivered" in capsys.readouterr().out
    assert main([*STEER, "--torque", "0,0,0.5", "--law", "sr", "--t-final", "10",
                 "--torque-tol", "2"]) == 0


def test_steer_negative_torque_and_delta0_in_degrees(tmp_path, capsys):
    out = tmp_path / "s.json"
    assert main([*STEER, "--torque", "-0.1,0,0", "--law", "pinv", "--t-final", "2",
                 "--delta0", "-10,0,10,0", "--points", "21", "--json", str(out)]) == 0
    data = strict_loads(out.read_text())
    delta, H, t = (np.array(data[k]) for k in ("delta", "H", "t"))
    assert delta[:, 0] == pytest.approx(np.deg2rad([-10, 0, 10, 0]), abs=1e-15)
    assert np.max(np.abs(H[0] - H[0, 0] - 0.1 * t)) < 1e-9  # H(t) = H(0) - torque t


def test_steer_pinv_through_the_singularity_exits_1(capsys):
    assert main([*STEER, "--torque", "-0.1,0,0", "--law", "pinv", "--t-final", "15"]) == 1
    captured = capsys.readouterr()
    assert "False" in captured.out and "momentum balance" in captured.err


def test_steer_rate_limit_in_degrees_per_second(capsys):
    # the pseudo-inverse starts at 0.0866 rad/s = 4.96 deg/s per gimbal
    assert main([*STEER, "--torque", "-0.1,0,0", "--law", "pinv", "--t-final", "1",
                 "--points", "11", "--rate-limit", "4"]) == 1
    assert "rate_limit" in capsys.readouterr().err
    assert main([*STEER, "--torque", "-0.1,0,0", "--law", "pinv", "--t-final", "1",
                 "--points", "11", "--rate-limit", "6"]) == 0


def test_steer_gsr(capsys):
    assert main([*STEER, "--torque", "0,0.2,0", "--law", "gsr", "--t-final", "3",
                 "--points", "31"]) == 0
    assert "gsr" in capsys.readouterr().out


@pytest.mark.parametrize("argv, option", [
    ([*ENV[:3], "0"], "--beta"),
    ([*ENV[:3], "95"], "--beta"),
    ([*ENV[:3], "nan"], "--beta"),
    ([*ENV, "--h", "-1"], "--h"),
    ([*ENV, "--h", "1,2"], "--h"),
    ([*ENV, "--directions", "10"], "--directions"),
    ([*ENV, "--plot", "env.txt"], "--plot"),
    ([*ENV, "--plot", "/no/such/dir/env.png"], "--plot"),
    ([*ENV, "--plot", "a.png", "--json", "a.png"], "--json"),
    ([*STEER, "--torque", "1,2"], "--torque"),
    ([*STEER, "--torque", "0,0,0.1", "--law", "foo"], "--law"),
    ([*STEER, "--torque", "0,0,0.1", "--t-final", "-1"], "--t-final"),
    ([*STEER, "--torque", "0,0,0.1", "--delta0", "1,2,3"], "--delta0"),
    ([*STEER, "--torque", "0,0,0.1", "--points", "1"], "--points"),
    ([*STEER, "--torque", "0,0,0.1", "--rate-limit", "0"], "--rate-limit"),
    ([*STEER], "--torque"),
])
def test_bad_input_exits_2_naming_the_option(argv, option, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert exit_code(argv) == 2
    err = capsys.readouterr().err
    assert option in err and len(err.strip().splitlines()[-1]) < 300


def test_docstring_examples():
    result = doctest.testmod(cmg_cli, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0 and result.failed == 0
