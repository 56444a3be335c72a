#!/usr/bin/env bash
# The whole test suite: installs what is missing, builds (Release) and runs ctest.
# `scripts/test.sh asan` does the same with AddressSanitizer and UndefinedBehaviorSanitizer
# (assertions and validations on), leaving out the tests labelled slow, soak and experiments
# (minutes of simulation, 5-10x slower sanitized) and programs (the programs run as processes:
# their code is the libraries', tested in-process, and the option parsing, fuzzed). JELLO_WERROR=ON makes warnings errors.
# Arguments after the preset go to ctest (CI: `scripts/test.sh release --label-exclude "soak|sweep"`).
set -euo pipefail
cd "$(dirname "$0")/.."
preset=${1:-release}
shift || true
scripts/install-deps.sh
scripts/build.sh "$preset"
# One test per core. GNU nproc honours OMP_NUM_THREADS and OMP_THREAD_LIMIT, so it is asked
# without them (asked after the export below, it said 1 and ctest ran every test in turn).
jobs=$(env -u OMP_NUM_THREADS -u OMP_THREAD_LIMIT nproc)
# Single-threaded BLAS and CHOLMOD, as jello-sim runs them (solvers/linalg/solver_threads.h).
export OMP_THREAD_LIMIT=${OMP_THREAD_LIMIT:-1} OPENBLAS_NUM_THREADS=${OPENBLAS_NUM_THREADS:-1}
exclude=()
[ "$preset" = asan ] && exclude=(--label-exclude "slow|soak|sweep|experiments|programs")
ctest --preset "$preset" -j"$jobs" "${exclude[@]}" "$@"
