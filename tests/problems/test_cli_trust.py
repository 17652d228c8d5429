"""Issue "Trustworthy results", CLI items: each test failed on the code before the fix.

Negative vector values, mutually exclusive options, output paths checked up front, strict
JSON, failed-slew plots, sweep progress and parameter names, the torque-free truth check and
its exit status, one-line errors. Slew tests monkeypatch the solver where only the CLI
plumbing is under test (fast, and independent of the solver's own work in progress).
"""
import json
import math
import re
from types import SimpleNamespace

import numpy as np
import pytest

from appdyn.dynamics.truth import torque_free_omega
from appdyn.problems import slew
from appdyn.problems import stability
from appdyn.problems.cli import main, rest_to_rest_bound
from appdyn.problems.cli.common import attach_negative_values, strict_json
from appdyn.problems.torque_free import CHECK_FACTOR, torque_free

TF = ["simulate", "torque-free", "--inertia", "1,2,3"]
SPIN = ["stability", "sweep", "spin", "--inertia", "1,2,3", "--axis", "1,0,0"]


def strict_loads(text):
    """json.loads that refuses NaN, Infinity and -Infinity (RFC 8259)."""
    def refuse(name):
        raise ValueError(f"non-standard JSON constant {name}")
    return json.loads(text, parse_constant=refuse)


def exit_code(argv):
    try:
        return main(argv)
    except SystemExit as exc:
        return exc.code


# ------------------------------------------------------------- 1. negative numbers
@pytest.mark.parametrize("w0", [["--w0", "-1,0.1,0.8"], ["--w0=-1,0.1,0.8"]])
def test_negative_vector_values_are_accepted(w0, tmp_path, capsys):
    out = tmp_path / "tf.json"
    assert main([*TF, *w0, "--t-final", "2", "--points", "21", "--json", str(out)]) == 0
    data = strict_loads(out.read_text())
    assert data["w0"] == [-1.0, 0.1, 0.8]
    # independent truth: the Jacobi-elliptic rates at t = 2 s from w0 = (-1, 0.1, 0.8)
    w_end = torque_free_omega([1.0, 2.0, 3.0], [-1.0, 0.1, 0.8], [2.0])[:, 0]
    assert data["max_rate_error"] < 1e-9 * np.linalg.norm(w_end)


def _fake_solution(success=False, T=float("nan")):
    return SimpleNamespace(success=success, status=0 if success else 2,
                           solver_status="Solve_Succeeded" if success
                           else "Infeasible_Problem_Detected", message="fake", T=T)


@pytest.fixture
def fake_report(monkeypatch):
    """Stand-ins for `slew.summary` / `slew.format_summary`: the CLI plumbing is under test,
    not the library's table (which another change is extending)."""

    def summary(sol, *, eigenaxis=None):
        return dict(success=sol.success, status=sol.status, message=sol.message, T=sol.T,
                    cost=float("nan"), propagation_error=float("nan"))

    def format_summary(data):
        return (f"Optimal slew\n  success  {data['success']} ({data['status']})\n"
                f"  T [s]    {data['T']:.6f}")

    monkeypatch.setattr(slew, "summary", summary)
    monkeypatch.setattr(slew, "format_summary", format_summary)
    return summary


def test_negative_axis_and_angle_reach_the_library(monkeypatch, fake_report, capsys):
    seen = {}

    def fake(inertia, T, **kw):
        seen.update(kw, T=T)
        return _fake_solution()

    monkeypatch.setattr(slew, "min_effort", fake)
    code = main(["slew", "--inertia", "2,3,4", "--axis", "-1,0,0", "--angle", "-30",
                 "--min-effort", "2", "--u-max", "0.5", "--quiet"])
    assert code == 1  # the fake failed
    np.testing.assert_array_equal(seen["axis"], [-1.0, 0.0, 0.0])
    assert seen["angle"] == pytest.approx(-math.pi / 6) and seen["T"] == 2.0


def test_negative_scalars_and_ranges_in_stability(capsys):
    assert main(["stability", "spin", "--inertia", "1,2,3", "--axis", "-1,0,0",
                 "--rate", "-2"]) == 0
    assert "axis" in capsys.readouterr().out
    assert main(["stability", "projectile", "--axial-inertia", "0.01", "--transverse-inertia",
                 "0.1", "--rate", "100", "--dynamic-pressure", "1000", "--area", "0.01",
                 "--cn-alpha", "2", "--cp-offset", "-0.05"]) == 0
    assert re.search(r"cp_offset +-0.05 m\n", capsys.readouterr().out)  # with its unit
    # intermediate axis: Re(lambda) = |rate| sqrt((I2 - I1)(I3 - I2) / (I1 I3)) (Euler)
    code = main([*SPIN[:6], "0,1,0", "--parameter", "rate", "--values", "-3:-1:3", "--quiet"])
    assert code == 0
    out = capsys.readouterr().out
    for rate in (-3, -2, -1):
        assert f"{rate}  unstable" in out
        assert f"{abs(rate) * math.sqrt(1 / 3):+.6e}" in out


def test_attach_negative_values_only_for_value_options():
    from appdyn.problems.cli import build_parser

    p = build_parser()
    assert attach_negative_values(p, ["--w0", "-1,2", "--angle", "-1e-3", "--values",
                                      "-1:1:5", "--time-optimal", "-1", "--plot", "-x.png"]) == \
        ["--w0=-1,2", "--angle=-1e-3", "--values=-1:1:5", "--time-optimal", "-1", "--plot",
         "-x.png"]


# ------------------------------------------------------- 2. mutually exclusive options
@pytest.mark.parametrize("args, names", [
    (["--axis", "1,0,0", "--qf", "0,0,0,1", "--time-optimal"], ("--qf", "--axis")),
    (["--angle", "30", "--qf", "0,0,0,1", "--time-optimal"], ("--qf", "--angle")),
    (["--axis", "1,0,0", "--angle", "30", "--min-effort", "2", "--starts", "4"],
     ("--starts", "--time-optimal")),
    (["--axis", "1,0,0", "--angle", "30", "--time-optimal", "--norm-bound", "--u-max", "1,2,3"],
     ("--norm-bound", "--u-max")),
    (["--axis", "1,0,0", "--time-optimal"], ("--axis", "--angle")),
    (["--axis", "0,0,0", "--angle", "30", "--time-optimal"], ("--axis", "non-zero")),
    (["--qf", "0,0,0,2", "--time-optimal"], ("--qf", "unit")),
    (["--axis", "1,0,0", "--angle", "30", "--time-optimal", "--u-max", "-1"], ("--u-max",)),
])
def test_slew_conflicting_options_are_usage_errors(args, names, monkeypatch, capsys):
    monkeypatch.setattr(slew, "time_optimal", lambda *a, **k: pytest.fail("solver ran"))
    monkeypatch.setattr(slew, "min_effort", lambda *a, **k: pytest.fail("solver ran"))
    assert exit_code(["slew", "--inertia", "1,1,1", *args]) == 2
    err = capsys.readouterr().err
    assert err.startswith("usage: appdyn slew")
    assert all(n in err.splitlines()[-1] for n in names)


@pytest.mark.parametrize("argv, names", [
    ([*TF, "--w0", "1,0,0", "--steps", "4"], ("--steps", "--method")),
    ([*SPIN, "--parameter", "rate", "--rate", "3", "--values", "1:2:3"], ("--rate", "swept")),
    (["stability", "gyrostat", "--inertia", "3,4,4", "--axis", "1,0,0", "--rate", "2",
      "--wheel-momentum", "1", "--damper-on", "rotor"], ("--damper-on", "--damper")),
])
def test_other_conflicting_options(argv, names, capsys):
    assert exit_code(argv) == 2
    last = capsys.readouterr().err.splitlines()[-1]
    assert all(n in last for n in names)


# --------------------------------------------------------- 3. output paths up front
@pytest.mark.parametrize("option, name, message", [
    ("--json", "missing/out.json", "does not exist"),
    ("--plot", "missing/out.png", "does not exist"),
    ("--plot", "out.txt", ".png"),
    ("--json", ".", "directory"),
])
def test_output_paths_are_checked_before_computing(option, name, message, tmp_path,
                                                   monkeypatch, capsys):
    import appdyn.problems.torque_free as tfmod

    monkeypatch.setattr(tfmod, "torque_free", lambda *a, **k: pytest.fail("computed"))
    path = str(tmp_path / name) if name != "." else str(tmp_path)
    assert exit_code([*TF, "--w0", "1,0.1,0.8", option, path]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    last = captured.err.splitlines()[-1]
    assert option in last and message in last


def test_stability_output_path_checked(tmp_path, capsys):
    code = exit_code(["stability", "spin", "--inertia", "1,2,3", "--axis", "1,0,0", "--rate",
                      "1", "--json", str(tmp_path / "no" / "r.json")])
    assert code == 2 and "--json" in capsys.readouterr().err


# ----------------------------------------------------------------- 4. strict JSON
def test_diverged_run_writes_strict_json(tmp_path, capsys):
    out = tmp_path / "tf.json"
    code = main([*TF, "--w0", "1,0.1,0.8", "--method", "rk4", "--t-final", "1e5", "--points",
                 "2", "--json", str(out)])
    assert code == 1
    data = strict_loads(out.read_text())
    assert data["success"] is False and data["verified"] is False
    assert data["momentum_drift"] is None  # overflowed to inf: null, not Infinity


def test_failed_slew_json_is_strict(monkeypatch, fake_report, tmp_path, capsys):
    monkeypatch.setattr(slew, "min_effort", lambda *a, **k: _fake_solution())
    out = tmp_path / "s.json"
    code = main(["slew", "--inertia", "2,3,4", "--axis", "1,0,0", "--angle", "30",
                 "--min-effort", "2", "--json", str(out), "--quiet"])
    assert code == 1
    data = strict_loads(out.read_text())
    assert data["success"] is False and data["propagation_error"] is None


def test_strict_json_helper():
    text = strict_json({"a": np.float64("nan"), "b": [np.inf, -np.inf, 1.5], "c": 1 + 2j,
                        "d": np.arange(2), "e": np.bool_(True)})
    assert strict_loads(text) == {"a": None, "b": [None, None, 1.5], "c": [1.0, 2.0],
                                  "d": [0, 1], "e": True}


# ------------------------------------------------------------------ 5. failed slew plot
def test_failed_slew_says_why_the_plot_was_skipped(monkeypatch, fake_report, tmp_path,
                                                   capsys):
    monkeypatch.setattr(slew, "min_effort", lambda *a, **k: _fake_solution())
    png = tmp_path / "s.png"
    code = main(["slew", "--inertia", "2,3,4", "--axis", "1,0,0", "--angle", "30",
                 "--min-effort", "2", "--plot", str(png), "--quiet"])
    assert code == 1
    err = capsys.readouterr().err
    assert f"--plot {png} skipped" in err and "Infeasible_Problem_Detected" in err
    assert not png.exists()


# --------------------------------------------------- 6. sweep progress and parameters
def test_sweep_progress_callback_and_library_silence(capsys):
    calls = []
    stability.sweep("spin", "rate", [1.0, 2.0, 3.0], inertia=[1, 2, 3], axis=[1, 0, 0],
                    progress=lambda d, n: calls.append((d, n)))
    assert calls == [(1, 3), (2, 3), (3, 3)]
    assert capsys.readouterr() == ("", "")


@pytest.mark.parametrize("flags, shown", [(["--progress"], True), (["--progress", "--quiet"],
                                                                   False), ([], False)])
def test_sweep_progress_lines_on_stderr(flags, shown, capsys):
    assert main([*SPIN, "--parameter", "rate", "--values", "1:3:3", *flags]) == 0
    err = capsys.readouterr().err
    assert ("sweep spin over rate: 3/3 (100%)" in err) is shown
    if not shown:
        assert err == ""  # capsys' stderr is no terminal: silent unless asked


@pytest.mark.parametrize("case, args, valid", [
    ("spin", ["--inertia", "1,2,3", "--axis", "1,0,0"], "rate"),
    ("gyrostat", ["--inertia", "3,4,5", "--axis", "1,0,0", "--rate", "2"],
     "rate, wheel-momentum, wheel-inertia"),
])
def test_sweep_unknown_parameter_lists_the_valid_ones(case, args, valid, capsys):
    assert exit_code(["stability", "sweep", case, *args, "--parameter", "speed",
                      "--values", "1:2:3"]) == 2
    last = capsys.readouterr().err.splitlines()[-1]
    assert "--parameter" in last and valid in last and "'speed'" in last


# ------------------------------------------------------- 7. torque-free truth check
def test_diverged_fixed_step_run_fails_the_truth_check(capsys):
    """One rk4 step of 1000 s: simulate itself says the run is not a solution (status 4:
    the quaternion's norm ~1e34), the truth check fails as well."""
    code = main([*TF, "--w0", "1,0.1,0.8", "--method", "rk4", "--t-final", "1000",
                 "--points", "2"])
    assert code == 1
    captured = capsys.readouterr()
    assert "truth check FAILED" in captured.out and "success                        False" \
        in captured.out
    assert captured.err.count("\n") == 1 and "not a solution" in captured.err
    assert "quaternion" in captured.err and "`steps`" in captured.err


def test_fixed_step_passes_with_enough_steps(capsys):
    base = [*TF[:3], "2,3,4", "--w0", "0.2,1,0.1", "--t-final", "10", "--points", "101",
            "--method", "rk4", "--rtol", "1e-8", "--atol", "1e-10"]
    assert main([*base, "--steps", "1"]) == 1
    assert main([*base, "--steps", "10"]) == 0
    assert "truth check passed" in capsys.readouterr().out


def test_truth_check_is_the_stated_bound():
    """``verified`` iff |w - w_exact| <= CHECK_FACTOR (atol + rtol |w_exact|) (or tol |w0|), recomputed
    here from the report's own series and the independent closed form."""
    I, w0 = [1.0, 2.0, 3.0], np.array([0.2, 1.0, 0.1])
    rep = torque_free(I, w0, t_final=10.0, n_points=51, method="rk4", rtol=1e-6, atol=1e-8)
    t = np.linspace(0.0, 10.0, 51)
    w_exact = torque_free_omega(I, w0, t)
    dev = np.abs(rep._series["w"] - w_exact)
    assert rep.max_rate_error == pytest.approx(dev.max(), rel=1e-6)
    ratio = np.max(dev / (CHECK_FACTOR * (1e-8 + 1e-6 * np.abs(w_exact))))
    assert rep.error_ratio == pytest.approx(ratio, rel=1e-6)
    assert rep.verified is bool(ratio <= 1) and rep.success is rep.verified
    rel = rep.max_rel_rate_error
    loose = torque_free(I, w0, t_final=10.0, n_points=51, method="rk4", tol=1.01 * rel)
    tight = torque_free(I, w0, t_final=10.0, n_points=51, method="rk4", tol=0.99 * rel)
    assert loose.verified and not tight.verified
    assert "truth check FAILED" in str(tight) and "truth check passed" in str(loose)
    d = tight.to_dict()
    assert d["verified"] is False and d["success"] is False and d["integrator_success"] is True


# --------------------------------------------------------------- 8. error paths
def test_library_value_error_is_one_line_exit_2(capsys):
    assert exit_code([*TF[:3], "1,1,3", "--w0", "1,0,0"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "argument --inertia:" in err and "triangle" in err


def test_unexpected_failure_is_one_line_exit_1(monkeypatch, capsys):
    import appdyn.problems.torque_free as tfmod

    def boom(*a, **k):
        raise RuntimeError("CVODES failed\n  at t = 3.2")

    monkeypatch.setattr(tfmod, "torque_free", boom)
    assert exit_code([*TF, "--w0", "1,0,0"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "RuntimeError: CVODES failed at t = 3.2" in err
    assert "Traceback" not in err


def test_tiny_time_optimal_slew_with_impossible_time_fails(monkeypatch, fake_report, capsys):
    """The solver's T = 2e-9 s for a 1e-4 deg slew is below the rest-to-rest bound."""
    monkeypatch.setattr(slew, "time_optimal", lambda *a, **k: _fake_solution(True, 2e-9))
    code = main(["slew", "--inertia", "1,1,1", "--axis", "0,0,1", "--angle", "0.0001",
                 "--time-optimal", "--quiet"])
    assert code == 1
    captured = capsys.readouterr()
    assert re.search(r"lower bound on T \[s\] +0\.002008\n", captured.out)
    assert re.search(r"success +False", captured.out)
    assert not re.search(r"success +True", captured.out)
    assert "below the rest-to-rest bound" in captured.err


def test_slew_prints_pointing_fields_and_fails_on_success_false(monkeypatch, fake_report,
                                                                capsys):
    real = fake_report

    def summary(sol, **kw):
        return dict(real(sol, **kw), pointing_error_arcsec=12.5, constraint_violation=3e-4)

    monkeypatch.setattr(slew, "summary", summary)
    monkeypatch.setattr(slew, "min_effort", lambda *a, **k: _fake_solution())
    assert main(["slew", "--inertia", "2,3,4", "--axis", "1,0,0", "--angle", "0.0001",
                 "--min-effort", "2", "--quiet"]) == 1
    out = capsys.readouterr().out
    assert "12.5" in out and "3.00e-04" in out


def test_rest_to_rest_bound_is_tight_for_a_sphere_under_a_norm_bound():
    # J = j E, |u| <= U about any axis: bang-bang eigenaxis T = 2 sqrt(j theta / U) is optimal
    assert rest_to_rest_bound([2.0, 2.0, 2.0], math.pi, 0.5) == pytest.approx(
        2 * math.sqrt(2.0 * math.pi / 0.5), rel=1e-14)
    # per-axis |u_i| <= 1, J = E, 180 deg: below the best known T = 3.2430 (Bilimoria & Wie)
    assert rest_to_rest_bound(np.eye(3), math.pi, math.sqrt(3)) < 3.2430


def test_real_tiny_slew_never_claims_success_with_an_impossible_time(tmp_path, capsys):
    """End to end (1e-4 deg): exit 0 only with T at or above the rest-to-rest bound and the
    printed success agreeing with the exit status."""
    out = tmp_path / "tiny.json"
    code = main(["slew", "--inertia", "1,1,1", "--axis", "0,0,1", "--angle", "0.0001",
                 "--time-optimal", "--starts", "1", "--quiet", "--json", str(out)])
    text = capsys.readouterr().out
    data = strict_loads(out.read_text())
    bound = 2 * math.sqrt(math.radians(1e-4) / math.sqrt(3))  # J = E, |u| <= sqrt(3)
    assert data["T_lower_bound"] == pytest.approx(bound, rel=1e-12)
    assert (code == 0) is data["success"] is bool(re.search(r"success +True", text))
    if code == 0:
        assert data["T"] >= bound
