#!/usr/bin/env bash
# Fuzzes the world reader with libFuzzer (clang 14, ASan + UBSan) for SECONDS (default 60).
# Seeds: tests/fuzz/corpus (small hand-made worlds) plus the heads of the reference worlds.
# Findings (crash-*, leak-*, timeout-*, oom-*) land in build/fuzz/; the run fails on any.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
out=build/fuzz
mkdir -p "$out/corpus"
clang++-14 -std=c++20 -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all \
  -Isrc tests/fuzz/world_reader_fuzzer.cpp src/world_reader.cpp src/integrator_name.cpp \
  -o "$out/world_reader_fuzzer"
for w in worlds/*.w; do head -c 4096 "$w" > "$out/corpus/head-$(basename "$w")"; done
cd "$out"
./world_reader_fuzzer -max_total_time="$seconds" -timeout=1 -rss_limit_mb=2048 \
  -max_len=8192 -print_final_stats=1 corpus ../../tests/fuzz/corpus 2>&1 | tail -15
