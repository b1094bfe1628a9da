#!/usr/bin/env bash
# Installs what is missing, builds (Release) the program, runs the default scene: the leading
# Floquet multipliers of the soft-impact oscillator's period-1 orbit (paper parameters); then
# builds the modules the program loads on first use (the other built-in models, equations, MPI)
# and, where pybind11 is installed, the Python module. Extra arguments go to `delayspec floquet` (e.g. --json). How long
# it takes on a fresh clone: scripts/first_number_time.py (README.md). `scripts/build.sh build`
# builds everything else (the tests, the benches, libdelayspec_prebuilt: docs/models.md).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
"$here/scripts/setup-debian.sh"
DELAYSPEC_TARGETS=delayspec_cli "$here/scripts/build.sh" "$here/build"
"$here/build/delayspec" floquet "$here/data/scenes/default.toml" "$@"
# The modules after the first number (the default scene needs none), then the Python module
# (it shares the program's compiled scene layer).
modules=(--target delayspec_models --target delayspec_equations)
grep -q '^DELAYSPEC_MPI:BOOL=ON' "$here/build/CMakeCache.txt" && modules+=(--target delayspec_mpi)
cmake --build "$here/build" -j "$(nproc)" "${modules[@]}" >/dev/null
if grep -q '^DELAYSPEC_PYTHON:BOOL=ON' "$here/build/CMakeCache.txt"; then
  cmake --build "$here/build" -j "$(nproc)" --target delayspec_python >/dev/null
  PYTHONPATH="$here/build/python" /usr/bin/python3 -c "import delayspec" &&
    echo "python: PYTHONPATH=$here/build/python /usr/bin/python3 -c 'import delayspec' works (docs/python.md)"
fi
