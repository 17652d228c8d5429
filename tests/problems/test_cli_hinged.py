"""``appdyn simulate hinged``, ``appdyn stability shaken-pendulum`` / ``conical-pendulum`` and
``appdyn stability sweep shaken-pendulum``, run in-process: exit codes, files written, strict
JSON, the summary's conservation numbers, and bad options refused with status 2 naming the
option. Runs are short and uncompiled (``--no-jit``) to keep the file fast."""
import json
import math
import re

import numpy as np
import pytest

from appdyn.problems.cli import main

BALL = ["simulate", "hinged", "--m1", "10", "--inertia1", "1,2,2.5", "--m2", "2",
        "--inertia2", "0.2,0.3,0.4", "--r1", "0.4,0,0", "--r2", "-0.3,0,0",
        "--w1", "0.1,0.2,1", "--w2", "0.3,-0.2,0.5", "--t-final", "2", "--points", "41",
        "--no-jit", "--quiet"]
REVOLUTE = ["simulate", "hinged", "--m1", "10", "--inertia1", "1,2,2.5", "--m2", "2",
            "--inertia2", "0.2,0.2,0.3", "--r1", "0,0,0.5", "--r2", "0,0,-0.2",
            "--kind", "revolute", "--axis", "0,0,1", "--w1", "0.1,0,0.2", "--w2", "0.1,0,0.7",
            "--t-final", "2", "--points", "41", "--no-jit", "--quiet"]
ROD = ["--mass", "1", "--inertia", str(1 / 48), "--length", "0.25", "--amp-y", "0.02"]


def strict_json(path):
    return json.loads(path.read_text(), parse_constant=lambda c: pytest.fail(f"non-strict {c}"))


def printed_numbers(text, names):
    """``{name: value}`` from summary lines ``  name   1.234e-15``."""
    found = {}
    for name in names:
        m = re.search(rf"^\s+{name}\s+([-+0-9.e]+)\s*$", text, re.M)
        assert m, f"no line for {name} in\n{text}"
        found[name] = float(m.group(1))
    return found


@pytest.mark.slow
def test_ball_hinge_conserves_and_writes_plot_and_json(tmp_path, capsys):
    png, out = tmp_path / "h.png", tmp_path / "h.json"
    assert main([*BALL, "--plot", str(png), "--json", str(out)]) == 0
    text = capsys.readouterr().out
    assert "ball hinge" in text and "check: PASSED" in text
    drift = printed_numbers(text, ("energy", "momentum_linear", "momentum_angular",
                                   "quat_norm", "quat_norm_2", "position", "velocity"))
    assert all(0 <= v < 1e-12 for v in drift.values()), drift
    assert re.search(r"\|force\|\s+[0-9.e+-]+ \.\. [0-9.e+-]+ N", text)
    assert png.read_bytes()[:4] == b"\x89PNG" and png.stat().st_size > 20_000
    data = strict_json(out)
    assert data["success"] is True and data["kind"] == "ball"
    assert data["parameters"]["stabilization"] is True and data["parameters"]["v1"] is None
    assert data["drift"]["energy"] == pytest.approx(drift["energy"], rel=1e-3, abs=1e-18)
    assert max(data["constraint_residual_max"].values()) < 1e-12
    assert len(data["history"]["t"]) == 41 and len(data["history"]["w2"]) == 3
    lo, hi = data["hinge_force_range"]
    assert 0 < lo <= hi and data["hinge_torque_range"][1] < 1e-12  # a ball hinge: no couple


def test_revolute_hinge_without_stabilization(tmp_path, capsys):
    out = tmp_path / "r.json"
    assert main([*REVOLUTE, "--no-stabilization", "--json", str(out)]) == 0
    text = capsys.readouterr().out
    assert "revolute hinge" in text and "drift control: none" in text
    data = strict_json(out)
    assert data["parameters"]["stabilization"] is False and data["success"] is True
    w1, w2 = data["final"]["w1"], data["final"]["w2"]
    assert all(math.isfinite(v) for v in w1 + w2)


@pytest.mark.parametrize("argv", [BALL, REVOLUTE])
@pytest.mark.slow
def test_the_scene_run_equals_the_multiplier_model(argv, tmp_path, capsys):
    """The default run is the scene (minimal coordinates); --model multiplier integrates
    the two free bodies: the same final states (rk8, both at round-off level per step), and
    the scene's mapped run keeps the multiplier model's constraints to round-off."""
    runs = {}
    for model in ("scene", "multiplier"):
        out = tmp_path / f"{model}.json"
        assert main([*argv, "--model", model, "--json", str(out)]) == 0
        text = capsys.readouterr().out
        runs[model] = strict_json(out)
        assert runs[model]["model"] == model and runs[model]["parameters"]["model"] == model
        assert ("minimal coordinates" in text) == (model == "scene")
    a, b = runs["scene"], runs["multiplier"]
    for key, value in b["final"].items():
        assert np.allclose(a["final"][key], value, rtol=0, atol=1e-10), key
    assert max(a["constraint_residual_max"].values()) < 1e-13
    assert np.allclose(a["hinge_force_range"], b["hinge_force_range"], rtol=1e-9)


def test_a_tolerance_below_round_off_fails_with_status_1(capsys):
    assert main([*BALL, "--tol", "1e-18"]) == 1
    captured = capsys.readouterr()
    assert "check: FAILED" in captured.out and "above --tol 1e-18" in captured.err


@pytest.mark.parametrize("extra, option", [
    (["--axis", "0,0,1"], "--axis"),                      # axis with a ball hinge
    (["--m1", "-1"], "--m1"),
    (["--inertia1", "1,2"], "--inertia1"),
    (["--steps", "0"], "--steps"),
    (["--plot", "h.txt"], "--plot"),
    (["--kind", "hinge"], "--kind"),
])
def test_bad_options_exit_2(extra, option, capsys):
    with pytest.raises(SystemExit) as exc:
        main([*BALL, *extra])
    assert exc.value.code == 2
    assert f"argument {option}" in capsys.readouterr().err


def test_revolute_needs_an_axis_and_rates_along_it(capsys):
    bare = [a for a in REVOLUTE if a not in ("--axis", "0,0,1")]
    with pytest.raises(SystemExit) as exc:
        main(bare)
    assert exc.value.code == 2 and "argument --axis" in capsys.readouterr().err
    across = [("0.5,0,0.7" if a == "0.1,0,0.7" else a) for a in REVOLUTE]
    with pytest.raises(SystemExit) as exc:
        main(across)
    err = capsys.readouterr().err
    assert exc.value.code == 2 and "argument --w2" in err and len(err.strip().splitlines()) == 1


def test_inertia_that_is_not_positive_definite_exits_2(capsys):
    args = [("-1,2,2.5" if a == "1,2,2.5" else a) for a in BALL]
    with pytest.raises(SystemExit) as exc:
        main(args)
    err = capsys.readouterr().err
    assert exc.value.code == 2 and "error: argument --inertia1:" in err


# ----------------------------------------------------------------- stability cases
@pytest.mark.slow
def test_shaken_pendulum_inverted_is_stabilized(tmp_path, capsys):
    out, png = tmp_path / "sp.json", tmp_path / "sp.png"
    assert main(["stability", "shaken-pendulum", *ROD, "--freq", "200", "--position",
                 "inverted", "--json", str(out), "--plot", str(png)]) == 0
    assert "verdict: MARGINALLY STABLE" in capsys.readouterr().out
    data = strict_json(out)
    assert data["success"] is True and data["status"] == 0
    assert png.read_bytes()[:4] == b"\x89PNG"


def test_shaken_pendulum_slow_shaking_leaves_it_unstable(capsys):
    assert main(["stability", "shaken-pendulum", *ROD, "--freq", "100", "--position",
                 "inverted"]) == 0  # the verdict is in the report, not the exit status
    assert "verdict: UNSTABLE" in capsys.readouterr().out


def test_conical_pendulum_in_degrees(tmp_path, capsys):
    out = tmp_path / "cp.json"
    assert main(["stability", "conical-pendulum", "--mass", "1", "--length", "1",
                 "--cone-angle", "60", "--json", str(out)]) == 0
    assert "cone 60 deg" in capsys.readouterr().out
    data = strict_json(out)
    assert data["success"] is True
    assert data["parameters"]["cone_angle"] == pytest.approx(math.pi / 3, rel=1e-15)
    assert main(["stability", "conical-pendulum", "--mass", "1", "--length", "1",
                 "--cone-angle", "30", "--inertia", "0.1", "--sequence", "3-1-3"]) == 0


def test_sweep_shaken_pendulum_finds_the_kapitza_frequency(capsys):
    assert main(["stability", "sweep", "shaken-pendulum", "--parameter", "freq",
                 "--values", "100:200:3", "--quiet", *ROD, "--position", "inverted"]) == 0
    text = capsys.readouterr().out
    assert re.search(r"freq = 127\.9457", text)


@pytest.mark.parametrize("argv, option", [
    (["shaken-pendulum", *ROD, "--freq", "200", "--position", "upside"], "--position"),
    (["shaken-pendulum", *ROD], "--freq"),
    (["conical-pendulum", "--mass", "1", "--length", "1", "--cone-angle", "95"],
     "--cone-angle"),
    (["conical-pendulum", "--mass", "1", "--length", "1", "--cone-angle", "30",
      "--inertia", "0.1"], "--inertia"),
    (["conical-pendulum", "--mass", "1", "--length", "1", "--cone-angle", "30",
      "--sequence", "1-2-3"], "--sequence"),
])
def test_stability_bad_options_exit_2(argv, option, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["stability", *argv])
    assert exc.value.code == 2 and option in capsys.readouterr().err
