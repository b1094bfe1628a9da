#!/usr/bin/env bash
# Installs what is missing, builds and runs the whole test suite:
#  1. Release build, all tests (ctest);
#  2. install into a temporary prefix; build and run examples/user_model (a model of the user's
#     own, a built-in one) against the installed package (find_package(delayspec)); import the
#     installed Python package;
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
"$prefix/example/builtin_model"
"$prefix/install/bin/delayspec" --version
# The modules loaded on first use are found beside the installed library: a built-in model other
# than impact (libdelayspec_models), an equations scene (libdelayspec_equations) and, with MPI, a
# run under mpirun (libdelayspec_mpi).
"$prefix/install/bin/delayspec" floquet --set model=linear --set N=20 --set nev=2 --quiet >/dev/null
"$prefix/install/bin/delayspec" floquet "$here/data/scenes/equations_impact.toml" --set N=20 --set nev=2 \
  --set model_cache="$prefix/cache" --quiet >/dev/null
if grep -q '^DELAYSPEC_MPI:BOOL=ON' "$here/build/CMakeCache.txt"; then
  mpiexec=$(sed -n "s/^MPIEXEC_EXECUTABLE:FILEPATH=//p" "$here/build/CMakeCache.txt")
  OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 "$mpiexec" --oversubscribe -n 2 \
    "$prefix/install/bin/delayspec" chart --set model=mathieu --set N=20 --set solver=dense \
    --set chart_x_points=3 --set chart_y_points=2 --set threads=1 --quiet >/dev/null
fi
# The installed Python package (when built) imports from the prefix's site directory.
if grep -q '^DELAYSPEC_PYTHON:BOOL=ON' "$here/build/CMakeCache.txt"; then
  site=$(sed -n 's/^DELAYSPEC_PYTHON_INSTALL_DIR:STRING=//p' "$here/build/CMakeCache.txt")
  (cd "$prefix" && PYTHONPATH="$prefix/install/$site" /usr/bin/python3 -c \
    "import delayspec; assert delayspec.__file__.startswith('$prefix/install/'); print('python:', delayspec.floquet(N=20).multipliers[0]); print('python, equations:', delayspec.floquet('$here/data/scenes/equations_impact.toml', N=20, nev=2, model_cache='$prefix/cache').multipliers[0])")
fi
if [ "${DELAYSPEC_NO_SANITIZE:-0}" != 1 ]; then
  "$here/scripts/build.sh" "$here/build-sanitize" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDELAYSPEC_SANITIZE=ON \
    -DDELAYSPEC_BUILD_BENCH=OFF
  (cd "$here/build-sanitize" && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
    ctest --output-on-failure -j "$(nproc)")
fi
