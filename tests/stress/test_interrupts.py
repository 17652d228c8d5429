"""Ctrl-C stops a long stability sweep or simulation as a plain KeyboardInterrupt, every time.

Before `dynamics.interrupts`, a SIGINT 3 s into such a sweep was ignored in 2 of 6 trials
(the process ran on) -- it landed inside CasADi's C code and was lost there.
"""
import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from appdyn.dynamics.interrupts import check_interrupt, deferred_interrupts

ROOT = Path(__file__).resolve().parents[2]
SWEEP = """
import numpy as np
import control  # imported before the signal (a loaded CI machine spends 1-3 s on it): the
from appdyn.problems import stability  # stop is timed in the sweep; the import's own
print("start", flush=True)  # Ctrl-C is test_a_ctrl_c_during_the_first_import_...
stability.sweep("spin", "rate", np.linspace(0.1, 10.0, 200000), inertia=[2.0, 3.0, 4.5],
                axis=[1, 0, 0])
print("finished", flush=True)
"""


SIMULATE = """
import numpy as np
from appdyn.dynamics import rigid_body, simulate
model = rigid_body([1.0, 2.0, 3.0])
simulate(model, [0, 0, 0, 1, 1.0, 0.1, 0.8], [0.0, 1.0], method="rk4", steps=10)  # compile
print("start", flush=True)
simulate(model, [0, 0, 0, 1, 1.0, 0.1, 0.8], np.linspace(0.0, 1e4, 10001), method="rk4",
         steps=20000)  # 2e8 steps, about 15 s
print("finished", flush=True)
"""

# IPOPT iterating (about 40 ms each) when the signal comes. Before the iteration callback
# checked for a deferred Ctrl-C, CasADi's own check inside IPOPT took the signal, IPOPT
# ended with NonIpopt_Exception_Thrown and the solve returned (a slew went on to its next
# start): the interrupt was lost every time.
SOLVE = """
import numpy as np
from appdyn import ocp
from appdyn.problems.slew import slew_problem
problem = slew_problem(np.diag([1.0, 2, 3]), objective="time", angle=2.5, axis=[1, 1, 1])

def progress(it):
    if it.iteration == 2:
        print("start", flush=True)

sol = ocp.solve(problem, N=250, expand=False, progress=progress)
print("finished", sol.status, flush=True)
"""

# slews back to back, warm caches: the signal lands in IPOPT, a build, the mesh refinement
# or the switch polish, wherever the trial's delay puts it
SLEW = """
import numpy as np
from appdyn.problems import slew
slew.time_optimal(np.diag([1.0, 2, 3]), angle=2.5, axis=[1, 1, 1], N=40)
print("start", flush=True)
for k in range(100):
    slew.time_optimal(np.diag([1.0, 2, 3]), angle=2.5, axis=[1, 1, 1], N=40)
print("finished", flush=True)
"""

# a few trials each in `make test`; APPDYN_SOAK=1 runs 20 of each
_SOAK = os.environ.get("APPDYN_SOAK") == "1"
CASES = {**{f"sweep-{k}": (SWEEP, k) for k in range(20 if _SOAK else 3)},
         **{f"simulate-{k}": (SIMULATE, k) for k in range(20 if _SOAK else 2)},
         **{f"solve-{k}": (SOLVE, k) for k in range(20 if _SOAK else 2)},
         **{f"slew-{k}": (SLEW, k) for k in range(20 if _SOAK else 4)}}


def _timed(script: str) -> str:
    """``script`` that prints ``stopped <time.time()>`` when the KeyboardInterrupt reaches its
    top level, then re-raises it: the stop is timed, not the interpreter's exit after it
    (about 0.3 s with casadi loaded, over 1 s on a loaded machine)."""
    return ("import time as _time\ntry:\n" + textwrap.indent(script, "    ")
            + "\nexcept KeyboardInterrupt:\n    print('stopped', _time.time(), flush=True)\n"
            "    raise\n")


@pytest.mark.parametrize("script, trial", list(CASES.values()), ids=list(CASES))
@pytest.mark.slow
def test_sigint_stops_a_long_run_within_a_second(script, trial):
    proc = subprocess.Popen([sys.executable, "-c", _timed(script)], cwd=ROOT, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    assert proc.stdout.readline().strip() == "start"
    time.sleep((0.3 if script is SOLVE else 1.0) + 0.3 * (trial % 5))
    sent = time.time()
    proc.send_signal(signal.SIGINT)
    try:
        out, err = proc.communicate(timeout=5)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.communicate()
        pytest.fail("SIGINT was ignored: the sweep ran on")
    stopped = [float(ln.split()[1]) for ln in out.splitlines() if ln.startswith("stopped ")]
    assert stopped and stopped[0] - sent < 1.0, out
    assert "finished" not in out
    # (CasADi may add warnings about its jit temp files at exit: not part of the traceback)
    lines = [ln for ln in err.strip().splitlines() if not ln.startswith("CasADi - ")]
    assert lines[-1] == "KeyboardInterrupt" and "SystemError" not in err


def test_deferral_raises_at_the_check_and_restores_the_handler():
    before = signal.getsignal(signal.SIGINT)
    with pytest.raises(KeyboardInterrupt):
        with deferred_interrupts():
            signal.raise_signal(signal.SIGINT)  # only sets the flag
            reached = True
            check_interrupt()
    assert reached and signal.getsignal(signal.SIGINT) is before
    check_interrupt()  # nothing pending any more


PARTIAL = """
import json
import numpy as np
import control  # the sweep's first analysis imports it (~1-3 s on a loaded machine): before
from appdyn.problems import stability  # the signal, so that it lands in the sweep itself
values = np.linspace(0.1, 10.0, 200000)
print("start", flush=True)
try:
    stability.sweep("spin", "rate", values, inertia=[2.0, 3.0, 4.5], axis=[1, 0, 0])
except KeyboardInterrupt as exc:
    part = exc.partial
    n = len(part.values)
    pick = sorted({0, n // 2, n - 1})  # distinct: a slow machine may have finished only one or two
    check = stability.sweep("spin", "rate", part.values[pick], inertia=[2.0, 3.0, 4.5],
                            axis=[1, 0, 0])
    print(json.dumps({"n": n, "complete": part.complete, "prefix": bool(np.array_equal(part.values, values[:n])),
                      "same": [part.verdicts[i] for i in pick] == list(check.verdicts),
                      "ld": bool(np.array_equal(part.least_damped[pick], check.least_damped)),
                      "message": part.message}))
"""


@pytest.mark.slow
def test_interrupted_sweep_keeps_the_values_it_finished():
    proc = subprocess.Popen([sys.executable, "-c", PARTIAL], cwd=ROOT, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    assert proc.stdout.readline().strip() == "start"
    time.sleep(3.0)  # a loaded CI machine spends over a second on imports and the first build
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=30)
    assert proc.returncode == 0, err
    got = json.loads(out.strip().splitlines()[-1])
    assert 0 < got["n"] < 200000 and got["complete"] is False and got["prefix"]
    assert got["same"] and got["ld"]  # the finished part is what a fresh run gives
    assert "interrupted after" in got["message"]


# a SIGINT raised from inside matplotlib.ticker's import (a meta-path hook raises it the
# moment the module is looked up): undeferred, it was swallowed or became "RuntimeError:
# Error calling __set_name__" with matplotlib left half-imported (the CI failure of the
# sweep case above, and 2 of 40 timed trials by hand)
IMPORT_HIT = """
import signal, sys
class Hit:
    def find_spec(self, name, path=None, target=None):
        if name == "matplotlib.ticker":
            sys.meta_path.remove(self)
            signal.raise_signal(signal.SIGINT)
        return None
sys.meta_path.insert(0, Hit())
import numpy as np
from appdyn.problems import stability
try:
    stability.sweep("spin", "rate", np.linspace(0.1, 10.0, 200000), inertia=[2.0, 3.0, 4.5],
                    axis=[1, 0, 0])
    print("finished")
except KeyboardInterrupt as exc:
    import matplotlib.ticker, control
    print("stopped", getattr(exc, "partial", None), "control" in sys.modules)
"""


def test_a_ctrl_c_during_the_first_import_of_python_control_is_a_keyboard_interrupt():
    proc = subprocess.run([sys.executable, "-c", IMPORT_HIT], cwd=ROOT, text=True,
                          capture_output=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    # raised right after the import (no grid value evaluated yet), the modules whole
    assert proc.stdout.split() == ["stopped", "None", "True"], proc.stdout + proc.stderr
