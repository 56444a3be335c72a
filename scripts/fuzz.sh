#!/usr/bin/env bash
# Fuzzes with libFuzzer (clang 14, ASan + UBSan, the fuzz preset) for SECONDS (default 60) in
# all: three quarters on the world reader (each accepted world builds its model, obstacles
# included, and evaluates its forces), a quarter on the shared command-line number validators,
# the two side by side (one core each: the run takes three quarters of SECONDS).
# Seeds: tests/fuzz/corpus (small hand-made worlds) plus the heads of the worlds, and
# tests/fuzz/option-corpus. Findings (crash-*, leak-*, timeout-*, oom-*) land in
# build/fuzz/run/; the run fails on any.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
reader=$((seconds * 3 / 4))
options=$((seconds - reader))
scripts/build.sh fuzz >/dev/null
out=build/fuzz/run
mkdir -p "$out/corpus" "$out/option-corpus"
for w in worlds/*.w; do head -c 4096 "$w" > "$out/corpus/head-$(basename "$w")"; done
cd "$out"
../bin/world_reader_fuzzer -max_total_time="$reader" -timeout=1 -rss_limit_mb=2048 \
  -max_len=8192 -print_final_stats=1 corpus ../../../tests/fuzz/corpus > reader.log 2>&1 &
reader_pid=$!
status=0
../bin/option_fuzzer -max_total_time="$options" -timeout=1 -rss_limit_mb=2048 \
  -max_len=512 -print_final_stats=1 option-corpus ../../../tests/fuzz/option-corpus \
  > options.log 2>&1 || status=$?
wait "$reader_pid" || status=$?
echo "world reader, ${reader} s:"
tail -15 reader.log
echo "option validators, ${options} s (beside it):"
tail -8 options.log
exit "$status"
