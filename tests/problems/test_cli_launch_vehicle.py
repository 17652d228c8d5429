"""``appdyn stability launch-vehicle``, ``appdyn stability sweep launch-vehicle`` and
``appdyn simulate launch-vehicle``, run in-process: exit codes, files, strict JSON, and bad
options refused with status 2 and a message naming the option."""
import json
import math

import pytest

from appdyn.problems.cli import main

VEHICLE = ["--thrust", "2e6", "--inertia", "4e7", "--arm", "20", "--mass", "1e5"]
PARTS = ["--aero", "3e4,10,3,5", "--velocity", "500",
         "--slosh", "mass=2000,hinge=3,length=1.5,damping_ratio=0.01",
         "--bending", "frequency=12,generalized_mass=5000,damping_ratio=0.01,"
                      "slope_sensor=0.002,deflection_gimbal=0.5",
         "--actuator", "0.05"]


def strict_json(path):
    return json.loads(path.read_text(), parse_constant=lambda c: pytest.fail(f"non-strict {c}"))


@pytest.mark.slow
def test_rigid_report_is_verified_json_and_bode_plot(tmp_path, capsys):
    out, png = tmp_path / "lv.json", tmp_path / "lv.png"
    code = main(["stability", "launch-vehicle", *VEHICLE, "--k-psi", "2", "--k-psidot", "2",
                 "--json", str(out), "--plot", str(png)])
    assert code == 0
    text = capsys.readouterr().out
    assert "verdict: ASYMPTOTICALLY STABLE" in text and "rigid attitude" in text
    assert "phase margin  65.5302 deg" in text
    data = strict_json(out)
    assert data["status"] == 0 and data["states"] == ["psi", "psi_dot"]
    assert data["margins"]["gain_margin"] is None  # infinite: strict JSON null
    (mode,) = data["modes"]
    assert mode["wn"] == pytest.approx(math.sqrt(2e6 * 20 * 2 / 4e7), rel=1e-12)
    assert png.read_bytes()[:4] == b"\x89PNG" and png.stat().st_size > 20_000


def test_report_with_every_part(tmp_path, capsys):
    out = tmp_path / "lv.json"
    assert main(["stability", "launch-vehicle", *VEHICLE, "--k-psi", "1", "--k-psidot", "0.5",
                 *PARTS, "--json", str(out)]) == 0
    data = strict_json(out)
    assert {m["label"] for m in data["modes"]} == {"lateral drift", "rigid attitude", "slosh",
                                                    "bending", "actuator"}
    assert data["parameters"]["slosh"]["length"] == 1.5
    assert data["parameters"]["actuator"]["time_constant"] == 0.05
    assert data["verdict"] == "asymptotically stable" and data["status"] == 1  # unchecked


def test_too_little_gain_is_an_aero_divergence(capsys):
    assert main(["stability", "launch-vehicle", *VEHICLE, "--k-psi", "0.02", "--k-psidot",
                 "0.1", "--aero", "3e4,10,3,5", "--velocity", "500"]) == 0
    text = capsys.readouterr().out
    assert "verdict: UNSTABLE" in text and "aero divergence" in text


def test_sweep_finds_the_gain_boundary(capsys):
    assert main(["stability", "sweep", "launch-vehicle", "--parameter", "k-psi",
                 "--values", "0.05:0.5:4", "--quiet", *VEHICLE, "--k-psidot", "0.5",
                 "--aero", "3e4,10,3,5", "--velocity", "500"]) == 0
    assert "k_psi = 0.11492936" in capsys.readouterr().out  # Routh-Hurwitz, drift included


@pytest.mark.slow
def test_simulate_attitude_error(tmp_path, capsys):
    out, png = tmp_path / "sim.json", tmp_path / "sim.png"
    code = main(["simulate", "launch-vehicle", *VEHICLE, "--k-psi", "2", "--k-psidot", "2",
                 "--psi0", "3", "--t-final", "8", "--points", "401", "--quiet",
                 "--json", str(out), "--plot", str(png)])
    assert code == 0
    assert "psi [deg]" in capsys.readouterr().out
    data = strict_json(out)
    assert data["success"] is True and math.degrees(data["series"]["psi"][0]) == \
        pytest.approx(3.0)
    assert abs(data["series"]["psi"][-1]) < 1e-3 * math.radians(3)
    assert png.stat().st_size > 20_000


def test_simulate_gust_through_every_part(tmp_path, capsys):
    out = tmp_path / "gust.json"
    code = main(["simulate", "launch-vehicle", *VEHICLE, "--k-psi", "1", "--k-psidot", "0.5",
                 *PARTS, "--deflection-limit", "5", "--rate-limit", "20", "--gust", "20",
                 "--gust-start", "1", "--gust-duration", "2", "--t-final", "6",
                 "--points", "301", "--quiet", "--json", str(out)])
    assert code == 0
    data = strict_json(out)
    assert data["method"] == "cvodes"  # the actuator limits put kinks in the dynamics
    assert data["peaks"]["wind_y"] == pytest.approx(20.0)
    assert data["peaks"]["delta"] <= math.radians(5) + 1e-9
    assert {"theta_s", "eta", "alpha"} <= set(data["series"])


def lv(command, *extra):
    """A launch-vehicle command line with the vehicle and gains, plus ``extra``."""
    return [command, "launch-vehicle", *VEHICLE, "--k-psi", "1", "--k-psidot", "1", *extra]


@pytest.mark.parametrize("argv, message", [
    (lv("stability", "--aero", "3e4,10,3,5"), "argument --velocity: needed with --aero"),
    (lv("stability", "--velocity", "500"), "argument --velocity: only with --aero"),
    (lv("stability", "--aero", "3e4,10,3"), "argument --aero: expected 4 comma-separated"),
    (lv("stability", "--aero", "-3e4,10,3,5", "--velocity", "500"),
     "argument --aero: `Aero.dynamic_pressure`"),
    (lv("stability", "--slosh", "mass=1,hinge=2"), "argument --slosh: `Slosh` needs exactly"),
    (lv("stability", "--slosh", "mass=1,arm=2"), "argument --slosh: expected key=value items"),
    (lv("stability", "--bending", "frequency=12"), "argument --bending:"),
    (lv("stability", "--actuator", "-0.1"), "argument --actuator: expected a positive number"),
    (lv("stability", "--slosh", "mass=2e5,hinge=3,length=1"), "argument --slosh: `slosh.mass`"),
    (["stability", "launch-vehicle", *VEHICLE, "--k-psi", "1"], "--k-psidot"),
    (["stability", "launch-vehicle", "--thrust", "-2e6", *VEHICLE[2:], "--k-psi", "1",
      "--k-psidot", "1"], "argument --thrust: `thrust`"),
    (["stability", "sweep", "launch-vehicle", "--parameter", "velocity", "--values", "1:2:3",
      *VEHICLE, "--k-psi", "1", "--k-psidot", "1"], "argument --velocity: only with --aero"),
    (lv("simulate", "--gust", "10"), "argument --gust: needs --aero"),
    (lv("simulate", "--psi0", "1", "--rate-limit", "10"),
     "argument --rate-limit: only with --actuator"),
    (lv("simulate"), "argument --psi0: nothing excites the vehicle"),
    (lv("simulate", "--psi0", "1", "--gust-start", "2"), "argument --gust-start: only with"),
    (lv("simulate", "--psi0", "1", "--t-final", "0"), "argument --t-final: expected a positive"),
])
def test_bad_options_exit_2_naming_the_option(argv, message, capsys):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    assert message in capsys.readouterr().err
