#!/usr/bin/env bash
# The whole test suite: installs what is missing, builds (Release) and runs ctest.
# `scripts/test.sh asan` does the same with AddressSanitizer and UndefinedBehaviorSanitizer
# (assertions and validations on), leaving out the tests labelled slow, soak and experiments
# (minutes of simulation, 5-10x slower sanitized). JELLO_WERROR=ON makes warnings errors.
set -euo pipefail
cd "$(dirname "$0")/.."
preset=${1:-release}
scripts/install-deps.sh
scripts/build.sh "$preset"
# Single-threaded BLAS and CHOLMOD, as jello-sim runs them (solvers/solver_threads.h).
export OMP_THREAD_LIMIT=${OMP_THREAD_LIMIT:-1} OPENBLAS_NUM_THREADS=${OPENBLAS_NUM_THREADS:-1}
exclude=()
[ "$preset" = asan ] && exclude=(--label-exclude "slow|soak|experiments")
ctest --preset "$preset" -j"$(nproc)" "${exclude[@]}"
