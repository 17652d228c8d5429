#!/usr/bin/env bash
# Build numbalsoda (LSODA and DOP853 callable from numba) into its own venv,
# bench/peers/.venv-numbalsoda, so it can never change the project's numpy or casadi.
# numbalsoda builds from source (scikit-build + CMake) and needs a Fortran compiler.
# Usage: bash bench/peers/setup_numbalsoda.sh   (idempotent; PYTHON=... to pick the interpreter)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
venv="$here/.venv-numbalsoda"
python="${PYTHON:-python3}"
if ! command -v gfortran >/dev/null; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
        apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq gfortran
    else
        echo "setup_numbalsoda: gfortran is missing; install it (e.g. apt-get install gfortran)" >&2
        exit 1
    fi
fi
[ -x "$venv/bin/python" ] || "$python" -m venv "$venv"
"$venv/bin/python" -m pip install -q --upgrade pip
"$venv/bin/python" -m pip install -q numbalsoda numba numpy
"$venv/bin/python" -c "import numbalsoda, numba, numpy; print('numbalsoda ready:', numba.__version__, numpy.__version__)"
