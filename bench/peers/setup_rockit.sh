#!/usr/bin/env bash
# Install rockit (rockit-meco, optimal control on CasADi, KU Leuven MECO) into its own venv,
# bench/peers/.venv-rockit, so the project's venv and test requirements stay without it
# (it is also the `[bench]` extra of pyproject.toml for a developer's own venv).
# Usage: bash bench/peers/setup_rockit.sh   (idempotent; PYTHON=... to pick the interpreter)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
venv="$here/.venv-rockit"
python="${PYTHON:-python3}"
[ -x "$venv/bin/python" ] || "$python" -m venv "$venv"
"$venv/bin/python" -m pip install -q --upgrade pip
"$venv/bin/python" -m pip install -q rockit-meco numpy
"$venv/bin/python" -c "import rockit, casadi, numpy; from importlib.metadata import version; print('rockit ready:', version('rockit-meco'), 'casadi', casadi.__version__, 'numpy', numpy.__version__)"
