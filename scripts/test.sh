#!/usr/bin/env bash
# Installs what is missing, builds and runs the whole test suite:
#  1. Release build, all tests (ctest);
#  2. AddressSanitizer + UndefinedBehaviorSanitizer build, all tests
#     (skip with DELAYSPEC_NO_SANITIZE=1 for a quick local run).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
"$here/scripts/setup-debian.sh"
"$here/scripts/build.sh" "$here/build"
(cd "$here/build" && ctest --output-on-failure -j "$(nproc)")
if [ "${DELAYSPEC_NO_SANITIZE:-0}" != 1 ]; then
  "$here/scripts/build.sh" "$here/build-sanitize" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDELAYSPEC_SANITIZE=ON \
    -DDELAYSPEC_BUILD_BENCH=OFF
  (cd "$here/build-sanitize" && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
    ctest --output-on-failure -j "$(nproc)")
fi
