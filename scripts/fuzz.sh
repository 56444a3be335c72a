#!/usr/bin/env bash
# Fuzzes the world reader with libFuzzer (clang 14, ASan + UBSan, the fuzz preset) for SECONDS
# (default 60). Seeds: tests/fuzz/corpus (small hand-made worlds) plus the heads of the worlds.
# Findings (crash-*, leak-*, timeout-*, oom-*) land in build/fuzz/run/; the run fails on any.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
scripts/build.sh fuzz >/dev/null
out=build/fuzz/run
mkdir -p "$out/corpus"
for w in worlds/*.w; do head -c 4096 "$w" > "$out/corpus/head-$(basename "$w")"; done
cd "$out"
../bin/world_reader_fuzzer -max_total_time="$seconds" -timeout=1 -rss_limit_mb=2048 \
  -max_len=8192 -print_final_stats=1 corpus ../../../tests/fuzz/corpus 2>&1 | tail -15
