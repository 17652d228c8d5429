#!/usr/bin/env bash
# Install yapss (pseudospectral optimal control on CasADi) into its own venv,
# bench/peers/.venv-yapss, so it can never change the project's casadi: yapss 0.2.3 pins
# casadi>=3.6.0,<=3.7.2 while the project uses casadi 3.8. yapss needs no cyipopt: it drives
# the IPOPT shared library that ships inside the casadi wheel (through its bundled mseipopt).
# Usage: bash bench/peers/setup_yapss.sh   (idempotent; PYTHON=... to pick the interpreter)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
venv="$here/.venv-yapss"
python="${PYTHON:-python3}"
[ -x "$venv/bin/python" ] || "$python" -m venv "$venv"
"$venv/bin/python" -m pip install -q --upgrade pip
"$venv/bin/python" -m pip install -q "yapss==0.2.3" numpy scipy "casadi>=3.6.0,<=3.7.2"
"$venv/bin/python" -c "import yapss, casadi, numpy, scipy; from importlib.metadata import version; print('yapss ready:', version('yapss'), 'casadi', casadi.__version__, 'numpy', numpy.__version__, 'scipy', scipy.__version__)"
