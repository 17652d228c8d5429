#!/usr/bin/env bash
# Install ASSET (asset_asrl, C++ optimal control with its own interior-point solver PSIOPT)
# into its own venv, bench/peers/.venv-asset, so it can never change the project's numpy.
# asset_asrl 0.5.1 ships binary wheels on PyPI (no compiler needed).
# Usage: bash bench/peers/setup_asset.sh   (idempotent; PYTHON=... to pick the interpreter)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
venv="$here/.venv-asset"
python="${PYTHON:-python3}"
[ -x "$venv/bin/python" ] || "$python" -m venv "$venv"
"$venv/bin/python" -m pip install -q --upgrade pip
"$venv/bin/python" -m pip install -q "asset-asrl==0.5.1" numpy
"$venv/bin/python" -c "import asset_asrl, numpy; from importlib.metadata import version; print('asset ready:', version('asset-asrl'), 'numpy', numpy.__version__)"
