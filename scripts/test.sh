#!/usr/bin/env bash
# The whole test suite: installs what is missing, builds (Release) and runs ctest.
# `scripts/test.sh asan` does the same with AddressSanitizer and UndefinedBehaviorSanitizer,
# leaving out the tests labelled slow (minutes of stiff simulation, 5-10x slower sanitized).
set -euo pipefail
cd "$(dirname "$0")/.."
preset=${1:-release}
scripts/install-deps.sh
scripts/build.sh "$preset"
exclude=()
[ "$preset" = asan ] && exclude=(--label-exclude slow)
ctest --preset "$preset" -j"$(nproc)" "${exclude[@]}"
