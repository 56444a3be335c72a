#!/usr/bin/env bash
# Fingerprints what the simulator computes, for refactorings that must not change a bit: every
# world in worlds/ stepped by every integrator (20 steps at the file's dt, and 20 at dt 0.005
# for the implicit ones, where contact begins), each final state written by jello-sim --out
# and hashed. Prints one "world integrator dt sha256" line per run; diff two runs' output.
#   scripts/fingerprint.sh [BUILD_DIR] > before.txt   ... change ...   scripts/fingerprint.sh | diff before.txt -
set -euo pipefail
cd "$(dirname "$0")/.."
sim=${1:-build/release}/bin/jello-sim
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export OMP_THREAD_LIMIT=1 OPENBLAS_NUM_THREADS=1 OMP_WAIT_POLICY=passive JELLO_THREADS=1
integrators=$("$sim" --help | sed -n 's/.*--integrator TEXT .*overriding the file.s: //p' | tr -d ,)
for world in worlds/*.w; do
  for integrator in $integrators; do
    for dt in file 0.005; do
      args=(--integrator "$integrator" --steps 20 --quiet)
      [ "$dt" = file ] || args+=(--dt "$dt")
      status=0
      "$sim" "$world" "${args[@]}" --out "$tmp/out.w" 2>/dev/null || status=$?
      if [ $status -eq 0 ]; then
        echo "$(basename "$world") $integrator $dt $(sha256sum < "$tmp/out.w" | cut -c1-16)"
      else
        echo "$(basename "$world") $integrator $dt exit $status"
      fi
    done
  done
done
