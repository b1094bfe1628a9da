#!/usr/bin/env bash
# Configures and builds delayspec (Release, Ninja, ccache when installed).
# Usage: scripts/build.sh [BUILD_DIR] [extra cmake args...]
# DELAYSPEC_TARGETS="delayspec_cli ..." builds only those targets (default: everything).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build}
shift || true
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
fi
cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" "$@" >/dev/null
targets=()
for t in ${DELAYSPEC_TARGETS:-}; do targets+=(--target "$t"); done
cmake --build "$build" -j "$(nproc)" "${targets[@]}"
