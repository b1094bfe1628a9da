#!/usr/bin/env bash
# Installs what is missing, builds and runs the whole test suite:
#  1. Release build, all tests (ctest);
#  2. install into a temporary prefix; build and run examples/user_model against the installed
#     package (find_package(delayspec)); import the installed Python package;
#  3. AddressSanitizer + UndefinedBehaviorSanitizer build, all tests
#     (skip with DELAYSPEC_NO_SANITIZE=1 for a quick local run).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
"$here/scripts/setup-debian.sh"
"$here/scripts/build.sh" "$here/build"
(cd "$here/build" && ctest --output-on-failure -j "$(nproc)")
prefix=$(mktemp -d)
trap 'rm -rf "$prefix"' EXIT
cmake --install "$here/build" --prefix "$prefix/install" >/dev/null
cmake -S "$here/examples/user_model" -B "$prefix/example" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix/install" >/dev/null
cmake --build "$prefix/example" >/dev/null
"$prefix/example/user_model"
"$prefix/install/bin/delayspec" --version
# The installed Python package (when built) imports from the prefix's site directory.
if grep -q '^DELAYSPEC_PYTHON:BOOL=ON' "$here/build/CMakeCache.txt"; then
  site=$(sed -n 's/^DELAYSPEC_PYTHON_INSTALL_DIR:STRING=//p' "$here/build/CMakeCache.txt")
  (cd "$prefix" && PYTHONPATH="$prefix/install/$site" /usr/bin/python3 -c \
    "import delayspec; assert delayspec.__file__.startswith('$prefix/install/'); print('python:', delayspec.floquet(N=20).multipliers[0])")
fi
if [ "${DELAYSPEC_NO_SANITIZE:-0}" != 1 ]; then
  "$here/scripts/build.sh" "$here/build-sanitize" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDELAYSPEC_SANITIZE=ON \
    -DDELAYSPEC_BUILD_BENCH=OFF
  (cd "$here/build-sanitize" && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
    ctest --output-on-failure -j "$(nproc)")
fi
