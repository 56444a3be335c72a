#!/usr/bin/env bash
# Runs the three experiments in full and draws their charts into experiments/results/ (CSV,
# JSON sidecars, PNG and SVG). About 25 minutes on 2 cores. `scripts/run-experiments.sh quick`
# runs the --quick grids instead (under a minute), into build/experiments-quick/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh release >/dev/null
bin=build/release/experiments
out=experiments/results
args=()
if [ "${1:-}" = quick ]; then
  out=build/experiments-quick
  args=(--quick)
fi
mkdir -p "$out"
"$bin/jello-stability" "${args[@]}" --out-dir "$out"
"$bin/jello-work-precision" "${args[@]}" --out-dir "$out"
# One point at a time: a neighbour's memory traffic would bend the timings.
"$bin/jello-scaling" "${args[@]}" --jobs 1 --out-dir "$out"
for plot in stability work_precision scaling; do
  gnuplot -e "dir='$out'" "experiments/plots/$plot.gp"
done
echo "run-experiments: results and charts in $out/"
