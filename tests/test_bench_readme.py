"""The performance page's tables (docs/performance.md) come from bench/results, and the bench
runner's contract.

No timing is asserted: these tests check where the numbers come from and how ``appdyn
bench`` handles its benchmarks (``bench/_common.py`` describes the protocol).
"""
from __future__ import annotations

import csv
import importlib.util
import json
from pathlib import Path

import pytest

from appdyn.problems.cli import bench as bench_cli
from appdyn.problems.cli import main

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
PAGE = ROOT / "docs" / "performance.md"
RESULTS = ROOT / "bench" / "results"


def _module(name):
    spec = importlib.util.spec_from_file_location(f"test_bench_{name}",
                                                  ROOT / "bench" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


readme = _module("_readme")


def test_performance_page_numbers_are_the_latest_results():
    """The text between the markers of docs/performance.md is exactly render(bench/results):
    regenerate with `make bench` (or `appdyn bench --docs`), never edit those numbers by
    hand. The tables left the README for that page."""
    assert readme.current(PAGE) == readme.render(RESULTS)
    assert readme.BEGIN not in README.read_text() and readme.END not in README.read_text()


@pytest.mark.parametrize("flag", ["--docs", "--readme"])
def test_docs_flag_rewrites_the_performance_page(flag, tmp_path, monkeypatch):
    """``--docs`` (and ``--readme``, its former name) rewrite the marked part of the
    performance page, and only that, from the results just written."""
    bench_dir, out = tmp_path / "bench", tmp_path / "results"
    bench_dir.mkdir()
    _fake(bench_dir, "one", 2.5)
    page = tmp_path / "performance.md"
    page.write_text(f"# Performance\n{readme.BEGIN}\nold\n{readme.END}\nprose\n")
    monkeypatch.setattr(bench_cli, "BENCH_DIR", bench_dir)
    monkeypatch.setattr(bench_cli, "PERFORMANCE_PAGE", page)
    assert main(["bench", "--out", str(out), flag]) == 0
    text = page.read_text()
    assert text.startswith(f"# Performance\n{readme.BEGIN}\n") and text.endswith(
        f"{readme.END}\nprose\n")
    assert readme.current(page) == readme.render(out) and "| case | metric | 2.500 s | full |" \
        in text


MACHINE = {"date": "2026-01-02 03:04 UTC", "cpu": "Test CPU", "cores": 2, "casadi": "3.8.0",
           "numpy": "2.0.0", "scipy": "1.14.0", "ipopt_linear_solver": "mumps"}


def _results(folder, rows):
    folder.mkdir(parents=True, exist_ok=True)
    with open(folder / "summary.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=["benchmark", "case", "metric", "value", "unit", "note"])
        w.writeheader()
        w.writerows(rows)
    (folder / "machine.json").write_text(json.dumps(MACHINE))
    return folder


def test_render_a_synthetic_results_folder(tmp_path):
    folder = _results(tmp_path, [
        dict(benchmark="alpha", case="c1", metric="wall time", value=0.000123456, unit="s",
             note="rk8"),
        dict(benchmark="alpha", case="c1", metric="speed-up", value=12.3456, unit="x", note=""),
        dict(benchmark="beta", case="a|b", metric="mass", value=7529.712295, unit="kg",
             note="n"),
        dict(benchmark="beta", case="c", metric="error", value=-1.1654e-4, unit="", note=""),
    ])
    assert readme.render(folder) == (
        "Measured on Test CPU, 2 cores, 2026-01-02 03:04 UTC; casadi 3.8.0, numpy 2.0.0, "
        "scipy 1.14.0, IPOPT linear solver mumps; regenerate with `make bench`.\n"
        "\n**`bench/alpha.py`**\n\n"
        "| case | metric | value | note |\n| --- | --- | ---: | --- |\n"
        "| c1 | wall time | 1.23e-04 s | rk8 |\n"
        "| c1 | speed-up | 12.35 x |  |\n"
        "\n**`bench/beta.py`**\n\n"
        "| case | metric | value | note |\n| --- | --- | ---: | --- |\n"
        "| a\\|b | mass | 7530 kg | n |\n"
        "| c | error | -1.17e-04 |  |\n")


def test_the_glance_table_reads_the_rows_below_it(tmp_path):
    """"At a glance" is read from the rows of the tables (never typed in): one row gives
    its value, several their range and count, a job without rows is left out, and no row
    at all gives no table."""
    rows = [dict(benchmark="integrate_peers", case=f"w{k}", metric="speed-up vs numbalsoda "
                 "dop853, interpolated at the target error", value=v, unit="x", note="")
            for k, v in enumerate([0.5, 2.25, 1.0])]
    rows.append(dict(benchmark="slew", case="bw", metric="speed-up vs rockit at matched "
                     "accuracy", value=55.0, unit="x", note=""))
    rows.append(dict(benchmark="slew", case="bw", metric="speed-up vs rockit N = 20",
                     value=9.0, unit="x", note=""))
    lines = readme.glance(rows)
    assert lines[2:4] == ["| job | against | result | rows |", "| --- | --- | ---: | ---: |"]
    assert len(lines) == 6  # (two jobs with rows; every other job of GLANCE left out)
    assert lines[4].endswith("| numbalsoda dop853 | 0.5000 - 2.250 x | 3 |")
    assert lines[5].endswith("| rockit | 55.00 x | 1 |")
    assert readme.glance(rows[-1:]) == []
    text = readme.render(_results(tmp_path, rows))
    assert text.index("**At a glance**") < text.index("**Single runs against numbalsoda")


@pytest.mark.parametrize("value, text", [(0, "0"), (1.0, "1.000"), (0.0012345, "0.001234"),
                                         (9.99996, "10.00"), (123456.0, "1.23e+05"),
                                         (float("nan"), "nan")])
def test_format_value(value, text):
    assert readme.format_value(value) == text


def test_update_page_replaces_only_the_marked_text(tmp_path):
    folder = _results(tmp_path / "r", [dict(benchmark="a", case="c", metric="m", value=1.5,
                                            unit="s", note="")])
    path = tmp_path / "performance.md"
    path.write_text(f"intro\n{readme.BEGIN}\nold 42\n{readme.END}\nrest\n")
    assert readme.update_readme is readme.update_page  # the former name still works
    assert readme.update_page(path, folder)
    text = path.read_text()
    assert text.startswith(f"intro\n{readme.BEGIN}\n") and text.endswith(f"{readme.END}\nrest\n")
    assert "old 42" not in text and readme.current(path) == readme.render(folder)
    assert not readme.update_page(path, folder)  # nothing to change the second time
    path.write_text("no markers\n")
    with pytest.raises(ValueError, match="markers"):
        readme.update_page(path, folder)


FAKE = '''
from _common import Row

def run(quick, out):
    (out / "{name}.csv").write_text("x\\n1\\n")
    {body}
    return [Row("{name}", "case", "metric", {value}, "s", "quick" if quick else "full")]
'''


def _fake(folder, name, value=1.0, body="pass"):
    (folder / f"{name}.py").write_text(FAKE.format(name=name, value=value, body=body))


def _summary(out):
    with open(out / "summary.csv", newline="") as fh:
        return [(r["benchmark"], float(r["value"]), r["note"]) for r in csv.DictReader(fh)]


def test_runner_writes_merges_and_reports_failures(tmp_path, monkeypatch, capsys):
    bench_dir, out = tmp_path / "bench", tmp_path / "results"
    bench_dir.mkdir()
    _fake(bench_dir, "one", 1.0)
    _fake(bench_dir, "two", 2.0)
    (bench_dir / "_helper.py").write_text("raise RuntimeError('helpers are not benchmarks')\n")
    monkeypatch.setattr(bench_cli, "BENCH_DIR", bench_dir)

    assert main(["bench", "--quick", "--out", str(out)]) == 0
    assert _summary(out) == [("one", 1.0, "quick"), ("two", 2.0, "quick")]
    assert {"cpu", "cores", "casadi", "numpy", "scipy", "ipopt_linear_solver", "date"} <= set(
        json.loads((out / "machine.json").read_text()))
    assert (out / "one.csv").is_file() and (out / "two.csv").is_file()
    printed = capsys.readouterr().out
    assert "== summary ==" in printed and "one" in printed and "two" in printed

    first = json.loads((out / "machine.json").read_text())
    assert first["dates"] == {"one": first["date"], "two": first["date"]}
    then = "2026-01-01 00:00 UTC"
    (out / "machine.json").write_text(json.dumps({**first, "date": then, "dates": {
        "one": then, "two": then}}))

    _fake(bench_dir, "two", 3.0)  # a partial run replaces only its own rows
    assert main(["bench", "two", "--out", str(out)]) == 0
    assert _summary(out) == [("one", 1.0, "quick"), ("two", 3.0, "full")]
    now = json.loads((out / "machine.json").read_text())
    assert now["dates"] == {"one": then, "two": now["date"]}  # each table keeps its date
    text = bench_cli._helper("_readme").render(out)
    assert f"{then} to {now['date']} (each table's date below)" in text
    assert f"`bench/two.py`**, {now['date']}" in text and f"`bench/one.py`**, {then}" in text

    _fake(bench_dir, "one", 5.0, body="raise RuntimeError('boom')")  # the others still run
    _fake(bench_dir, "two", 4.0)
    capsys.readouterr()
    assert main(["bench", "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert "one failed: RuntimeError: boom" in err
    assert _summary(out) == [("one", 1.0, "quick"), ("two", 4.0, "full")]


def test_runner_rejects_unknown_names_and_a_missing_folder(tmp_path, monkeypatch, capsys):
    _fake(tmp_path, "one")
    monkeypatch.setattr(bench_cli, "BENCH_DIR", tmp_path)
    assert main(["bench", "one", "nope", "--out", str(tmp_path / "r")]) == 2
    assert "unknown benchmark(s) ['nope']" in capsys.readouterr().err
    assert not (tmp_path / "r" / "summary.csv").exists()
    monkeypatch.setattr(bench_cli, "BENCH_DIR", tmp_path / "missing")
    assert main(["bench"]) == 2
