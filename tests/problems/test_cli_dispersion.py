"""``appdyn dispersion spin`` and ``--workers`` on ``stability sweep``: the same answers as the
serial library calls."""
import json

import pytest

from appdyn.problems.cli import main
from appdyn.problems.dispersion import nutation_spread


@pytest.mark.slow
def test_dispersion_spin_reports_the_closed_form_statistics(tmp_path, capsys):
    out = tmp_path / "d.json"
    assert main(["dispersion", "spin", "--samples", "8", "--seed", "4", "--duration", "10",
                 "--json", str(out), "--quiet"]) == 0
    assert "nutation_max" in capsys.readouterr().out
    stats = json.loads(out.read_text())["statistics"]
    # nutation is constant for an axisymmetric body: its maximum equals the closed form
    assert stats["nutation_max"]["mean"] == pytest.approx(stats["nutation_closed_form"]["mean"], abs=1e-8)
    lib = nutation_spread(8, 4, duration=10.0)
    assert stats["nutation_max"]["mean"] == pytest.approx(lib.statistics["nutation_max"].mean, abs=0)


@pytest.mark.slow
def test_workers_give_the_serial_output(tmp_path, capsys):
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    common = ["dispersion", "spin", "--samples", "6", "--duration", "5", "--quiet"]
    assert main(common + ["--json", str(a)]) == 0
    assert main(common + ["--workers", "2", "--json", str(b)]) == 0
    assert json.loads(a.read_text())["statistics"] == json.loads(b.read_text())["statistics"]
    sweep = ["stability", "sweep", "gyrostat", "--parameter", "wheel-momentum", "--values=-2:8:6",
             "--inertia", "3,4,5", "--axis", "1,0,0", "--rate", "2", "--quiet"]
    capsys.readouterr()
    assert main(sweep) == 0
    serial = capsys.readouterr().out
    assert main(sweep + ["--workers", "2"]) == 0
    assert capsys.readouterr().out == serial


@pytest.mark.parametrize("argv", [["--samples", "0"], ["--workers", "0"],
                                  ["--workers", "2", "--scheduler", "tcp://x:1"]])
def test_bad_options_exit_2(argv, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["dispersion", "spin", *argv])
    assert exc.value.code == 2
