"""IPOPT's BLAS (CasADi's OpenBLAS, loaded with the IPOPT plugin) starts no threads of its
own unless ``OPENBLAS_NUM_THREADS`` asks for them (`ocp.ipopt_options.load_ipopt`). The
truth is the process's own thread list, counted in a fresh process (in this one the plugin
may be loaded already), and the same script with the variable set, where OpenBLAS does
start its threads."""
import os
import subprocess
import sys

import pytest

pytestmark = pytest.mark.skipif(not os.path.isdir("/proc/self/task"),
                                reason="counts threads in /proc/self/task (Linux)")

_SCRIPT = r"""
import os
import casadi as ca
from appdyn.ocp.ipopt_options import ipopt_solver
before = len(os.listdir("/proc/self/task"))
x = ca.SX.sym("x")
s = ipopt_solver("s", {"x": x, "f": (x - 2) ** 2},
                 {"print_time": False, "ipopt": {"print_level": 0, "sb": "yes"}})
print(before, len(os.listdir("/proc/self/task")), float(s(x0=0)["x"]),
      os.environ.get("OPENBLAS_NUM_THREADS"))
"""


def _run(env: dict) -> list:
    out = subprocess.run([sys.executable, "-c", _SCRIPT], capture_output=True, text=True,
                         timeout=120, check=True, env=env)
    return out.stdout.split()


def test_ipopt_blas_starts_no_threads_by_default():
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"}
    before, after, x, left = _run(env)
    assert int(after) == int(before)
    assert float(x) == pytest.approx(2.0, abs=1e-8)
    assert left == "None"  # the variable is not left behind


def test_openblas_num_threads_of_the_user_is_kept():
    before, after, x, left = _run({**os.environ, "OPENBLAS_NUM_THREADS": "2"})
    assert int(after) > int(before)  # OpenBLAS started its thread: the user's choice holds
    assert float(x) == pytest.approx(2.0, abs=1e-8)
    assert left == "2"


def test_clear_caches_does_not_load_the_plugin_again():
    """The plugin is loaded once per process: a solve after `clear_caches` prints nothing
    (casadi said "Solver ipopt is already in use. Ignored." on stderr when it was asked to
    load it again)."""
    script = (
        "import casadi as ca\n"
        "from appdyn.dynamics import clear_caches\n"
        "from appdyn.ocp.ipopt_options import ipopt_solver\n"
        "x = ca.SX.sym('x')\n"
        "for _ in range(2):\n"
        "    s = ipopt_solver('s', {'x': x, 'f': (x - 2) ** 2},\n"
        "                     {'print_time': False, 'ipopt': {'print_level': 0, 'sb': 'yes'}})\n"
        "    print(float(s(x0=0)['x']))\n"
        "    clear_caches()\n")
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         timeout=120, check=True)
    assert [float(v) for v in out.stdout.split()] == pytest.approx([2.0, 2.0], abs=1e-8)
    assert "already in use" not in out.stderr, out.stderr
