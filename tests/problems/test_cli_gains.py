"""``appdyn gains launch-vehicle --config FILE``, run in-process: the shipped example designs
and verifies (exit 0, gains and margins printed, strict JSON, a figure); bad configurations
exit 2 naming the field; infeasible limits exit 1 naming the limit."""
import json
import math

import pytest

from appdyn.problems.cli import COMMANDS, main
from appdyn.problems.gains.config import EXAMPLE_CONFIG


def strict_json(path):
    return json.loads(path.read_text(), parse_constant=lambda c: pytest.fail(f"non-strict {c}"))


@pytest.mark.slow
def test_shipped_config_designs_prints_gains_margins_and_writes_json(tmp_path, capsys):
    assert "gains" in COMMANDS
    out, png = tmp_path / "lv.json", tmp_path / "lv.png"
    code = main(["gains", "launch-vehicle", "--config", str(EXAMPLE_CONFIG), "--json", str(out),
                 "--plot", str(png)])
    text = capsys.readouterr().out
    assert code == 0, text
    assert "k_psi " in text and "k_psidot" in text and "rad/(rad/s)" in text
    assert "phase margin" in text and "gain margin" in text and "asymptotically stable" in text
    for name in ("attitude error", "rate error", "wind gust"):
        assert name in text
    data = strict_json(out)
    assert data["success"] is True and set(data["gains"]) == {"k_psi", "k_psidot"}
    v = data["verification"]
    assert v["verdict"] == "asymptotically stable" and v["phase_margin_deg"] > 30
    assert v["gain_margin_upper"] is None  # infinite: strict JSON null
    assert [s["name"] for s in data["scenarios"]] == ["attitude error", "rate error", "wind gust"]
    for s in data["scenarios"]:
        assert s["peak_deg"]["delta"] <= 6.0 * 1.005
        assert s["peak_deg"]["delta_rate"] <= 25.0 * 1.005
        assert s["peak_deg"]["delta"] == pytest.approx(math.degrees(s["peak"]["delta"]))
    assert png.read_bytes()[:4] == b"\x89PNG"


def _config(tmp_path, old, new, *more):
    text = EXAMPLE_CONFIG.read_text()
    for a, b in ((old, new), *more):
        assert a in text
        text = text.replace(a, b)
    path = tmp_path / "lv.toml"
    path.write_text(text)
    return str(path)


@pytest.mark.parametrize("old, new, message", [
    ("thrust = 2.0e6", "thrust = -2.0e6", "vehicle.thrust must be > 0"),
    ("arm = 20.0", "arm = 20.0\nlength = 40.0", "unknown key vehicle.length"),
    ("delta_max_deg = 6.0", "", "limits.delta_max_deg is required"),
    ("intervals = 40", "intervals = \"forty\"", "design.intervals must be an integer"),
    ("[vehicle]", "[vehicle", "not valid TOML"),
])
def test_bad_config_exits_2_naming_the_field(tmp_path, capsys, old, new, message):
    with pytest.raises(SystemExit) as exc:
        main(["gains", "launch-vehicle", "--config", _config(tmp_path, old, new)])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "argument --config" in err and message in err


def test_missing_config_and_clashing_outputs_exit_2(tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["gains", "launch-vehicle", "--config", str(tmp_path / "none.toml")])
    assert exc.value.code == 2 and "no such file" in capsys.readouterr().err
    same = str(tmp_path / "out.png")
    with pytest.raises(SystemExit) as exc:
        main(["gains", "launch-vehicle", "--config", str(EXAMPLE_CONFIG), "--plot", same,
              "--json", same])
    assert exc.value.code == 2


@pytest.mark.slow
def test_infeasible_limits_exit_1_naming_the_limit(tmp_path, capsys):
    path = _config(tmp_path, "delta_max_deg = 6.0", "delta_max_deg = 0.1",
                   ("intervals = 40", "intervals = 16"))
    code = main(["gains", "launch-vehicle", "--config", path])
    assert code == 1
    captured = capsys.readouterr()
    assert "FAILED (status 109 Limits_Not_Met" in captured.out
    assert "gimbal deflection |delta| <= 0.1 deg" in captured.err
