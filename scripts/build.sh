#!/usr/bin/env bash
# Configures (once, or again when JELLO_WERROR asks for another value) and builds one CMake preset: release
# (default: runs on any x86-64), native (-march=native: benchmarks), debug, asan (its tests only)
# or fuzz.
# Programs land in build/<preset>/bin.
# JELLO_WERROR=ON (as CI sets it) turns compiler warnings into errors.
set -euo pipefail
cd "$(dirname "$0")/.."
preset=${1:-release}
cache=build/$preset/CMakeCache.txt
if [ ! -f "$cache" ] ||
  { [ -n "${JELLO_WERROR:-}" ] && ! grep -qx "JELLO_WERROR:BOOL=$JELLO_WERROR" "$cache"; }; then
  cmake --preset "$preset" ${JELLO_WERROR:+"-DJELLO_WERROR=$JELLO_WERROR"} >/dev/null
fi
# The sanitizer build serves its test run alone (scripts/test.sh asan): the test programs, not the
# programs and experiments, whose tests it leaves out (a third of the build).
target=()
[ "$preset" = asan ] && target=(--target jello_tests)
cmake --build --preset "$preset" -j"$(env -u OMP_NUM_THREADS -u OMP_THREAD_LIMIT nproc)" "${target[@]}"
