#!/usr/bin/env bash
# Runs the three experiments in full and draws their charts into experiments/results/ (CSV,
# JSON sidecars, PNG and SVG): the README's Results section gives their run time (generated
# from the sidecars). `scripts/run-experiments.sh quick`
# runs the --quick grids instead (under a minute), into build/experiments-quick/.
# `scripts/run-experiments.sh atlas` runs the crossover atlas at N = 16 (k = 1e2..1e8), then at
# N = 32 (k = 1e2..1e6, 1e7 and 1e8 in runs of their own) instead, one point at a time on one
# core; the RK4 references on both cores, kept in experiments/results/atlas_references/ (N = 32
# at k = 1e8: 2.5 million steps of 32^3, over an hour): a stopped reference resumes from its last
# saved state, and a committed one is reused, so that a rerun only times the integrators; then it
# redraws the atlas charts. FALL_N=16 or 32 runs one N.
# `scripts/run-experiments.sh atlas-references` computes those references alone, on both cores
# (nothing is timed, so a machine busy with other work does no harm; about 1.5 hours at N = 16),
# so that `atlas` then only times the integrators; FALL_N as above. With FREE_K (say 1e7,1e8) it
# computes instead the free scene's at N = 32 for those k (hours at 1e7 and 1e8), which
# `FREE_N=32 FREE_K=... scripts/run-experiments.sh atlas-free` then reads and times.
# `scripts/run-experiments.sh atlas-free` runs the atlas's second scene (the same throw and spin
# without gravity: no contact) at N = 8, then at N = 16 for k = 1e5, 1e6, 1e7, then at N = 32 for
# k = 1e2 to 1e6 (a 60 s budget from 16 up), one point at a time on one core (two at a time moved
# projective's figures by up to 40%; N = 32's references on both cores), into
# experiments/results/atlas_free/, and draws its charts (about 10, 40 and 60 minutes on a 2-core
# VM; at N = 32, k = 1e7 and 1e8 the RK4 reference alone takes hours); FREE_N=8, 16 or 32 runs
# one of them, FREE_K (with FREE_N=32) other k at N = 32, in a run of their own.
# `scripts/run-experiments.sh atlas-contact` runs the falling scene's atlas at N = 8 with the floor
# as stiff as the springs, 20 times stiffer and as the log barrier (--atlas-contact k, 20k,
# barrier), one point at a time, into experiments/results/atlas_contact_k/, atlas_contact_20k/
# and atlas_contact_barrier/ (about 20 minutes each); CONTACTS="20k barrier" runs only those.
# `scripts/run-experiments.sh atlas-slide` runs the friction scene (--atlas-scene slide: thrown
# down an incline with mu = 0.6, it slides and comes to rest) at N = 8 for k = 1e3, 1e4, 1e5 and
# at N = 16 for k = 1e4, side by side, one core each, with a 60 s budget a run (an explicit
# method's 2 s at the friction-limited step is 10-20 s at N = 8: a 20 s budget cut it by the
# machine's noise), into experiments/results/atlas_slide/ (about 30 and 60 minutes on a 2-core
# VM); SLIDE_N=8 or 16 runs one of them.
# `scripts/run-experiments.sh slide-steps` asks the friction scene why the implicit methods miss
# it: at N = 8, k = 1e4, backward Euler and BDF2 (L-stable, first and second order) in one
# process, midpoint (second order, not L-stable) and implicit-linear (one solve a step) in
# another beside it, each from dt = 0.02 s down to 4.9e-6 s (13 steps: static friction's damping
# rate w_max times the step from 3800 down to 0.92), stopping at the first within 1 cm, every run
# kept (NAME_tries.csv in experiments/results/slide_steps/; the errors matter here, not the
# timings), and draws slide_steps.png (about 20 minutes on a 2-core VM).
# `scripts/run-experiments.sh atlas-trace` runs the falling scene at k = 1e4 for N = 8, 16 and 32
# with --atlas-trace (the reference's visible motion over time, and each integrator's at its
# largest step; a 60 s budget a run) into experiments/results/atlas_trace/, and draws it (about
# 20 minutes on a 2-core VM).
# `scripts/run-experiments.sh charts` runs nothing: it redraws every chart from the committed CSV.
# `--ranks K` (with any of the above but charts) runs each program as one MPI job of K ranks
# (mpirun; on a cluster, inside the allocation): the grid points dealt out over the ranks, one
# point at a time per rank, rank 0 writing the CSV; with `atlas`, the whole atlas (N = 16 and
# 32, every k, the stored references) is that one job. JELLO_BIN=DIR runs the programs in DIR
# instead of building the native ones (the tests: build/release/bin).
set -euo pipefail
cd "$(dirname "$0")/.."
usage="usage: scripts/run-experiments.sh [quick | atlas | atlas-references | atlas-free | atlas-contact | atlas-slide | slide-steps | atlas-trace | charts] [--ranks K]"
mode=
ranks=
while [ $# -gt 0 ]; do
  case "$1" in
    quick | atlas | atlas-references | atlas-free | atlas-contact | atlas-slide | slide-steps | \
      atlas-trace | charts)
      if [ -n "$mode" ]; then
        echo "run-experiments: '$1' after '$mode': one mode at a time ($usage)" >&2
        exit 2
      fi
      mode=$1
      shift
      ;;
    --ranks)
      if [ $# -lt 2 ]; then
        echo "run-experiments: --ranks needs the number of MPI ranks ($usage)" >&2
        exit 2
      fi
      ranks=$2
      shift 2
      ;;
    --ranks=*)
      ranks=${1#--ranks=}
      shift
      ;;
    -h | --help)
      echo "$usage"
      sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'
      exit 0
      ;;
    *)
      echo "run-experiments: unknown argument '$1' ($usage)" >&2
      exit 2
      ;;
  esac
done
if [ -n "$ranks" ] && ! [[ "$ranks" =~ ^[1-9][0-9]{0,3}$ ]]; then
  echo "run-experiments: --ranks '$ranks' is not a number of ranks from 1 to 9999" >&2
  exit 2
fi
if [ -n "$ranks" ] && [ "$mode" = charts ]; then
  echo "run-experiments: charts runs nothing: --ranks does not apply" >&2
  exit 2
fi
case "${FALL_N:-16}:${FREE_N:-8}" in
  16:8 | 16:16 | 16:32 | 32:8 | 32:16 | 32:32) ;;
  *)
    echo "run-experiments: FALL_N is 16 or 32 and FREE_N 8, 16 or 32 (FALL_N='${FALL_N:-}'," \
      "FREE_N='${FREE_N:-}')" >&2
    exit 2
    ;;
esac
set -- ${mode:+"$mode"}
scripts/install-deps.sh
bin=${JELLO_BIN:-build/native/bin}  # -march=native: the committed results and figures (README)
# The launcher of every program (none without --ranks). PMIx's shared-memory store cannot start
# on some machines (experiments/README.md): its hash store works everywhere. As root, Open MPI
# wants to be told.
launch=()
if [ -n "$ranks" ]; then
  if ! command -v mpirun >/dev/null; then
    echo "run-experiments: --ranks needs mpirun (Debian: openmpi-bin)" >&2
    exit 1
  fi
  export PMIX_MCA_gds=${PMIX_MCA_gds:-hash}
  launch=(mpirun --oversubscribe -np "$ranks")
  if [ "$(id -u)" = 0 ]; then launch+=(--allow-run-as-root); fi
fi
out=experiments/results
args=()
stability_scenes='free wall'
precision_scenes='soft drop stiff'
if [ "${1:-}" = quick ]; then
  out=build/experiments-quick
  args=(--quick)
  stability_scenes=free
  precision_scenes=soft
fi
# The atlas's charts cover every N committed (the atlas-only runs' files included).
draw_atlas() {
  local ns
  ns=$(awk -F, 'FNR > 1 { print $2 }' "$out"/*_atlas.csv | sort -nu | tr '\n' ' ')
  gnuplot -e "dir='$out'; atlas_ns='$ns'" experiments/plots/scaling.gp
}
draw_free_atlas() {
  local ns="8 16"
  if [ -f "$out/atlas_free/atlas32_atlas.csv" ]; then ns="8 16 32"; fi
  gnuplot -e "dir='$out/atlas_free'; atlas_ns='$ns'; atlas_only=1; scene=' (free flight)'" \
    experiments/plots/scaling.gp
}
# The stiffer floors' atlases, those that have run.
draw_contact_atlases() {
  local contact what
  for contact in k 20k barrier; do
    what="kCollision = $contact"
    [ "$contact" = barrier ] && what="log barrier"
    if [ -f "$out/atlas_contact_$contact/scaling_atlas.csv" ]; then
      gnuplot -e "dir='$out/atlas_contact_$contact'; atlas_ns='8'; atlas_only=1; \
scene=' (floor $what)'" experiments/plots/scaling.gp
    fi
  done
}
# The friction scene's charts, for each N where a method kept the slide (none at N = 16).
draw_slide_atlas() {
  local ns
  if [ -f "$out/atlas_slide/atlas8_atlas.csv" ]; then
    ns=$(awk -F, 'FNR > 1 && $11 == "ok" { print $2 }' "$out"/atlas_slide/*_atlas.csv | sort -nu |
      tr '\n' ' ')
    gnuplot -e "dir='$out/atlas_slide'; atlas_ns='$ns'; atlas_only=1; \
scene=' (slide with friction)'" experiments/plots/scaling.gp
  fi
}
if [ "${1:-}" = charts ]; then
  gnuplot -e "dir='$out'; scenes='$stability_scenes'" experiments/plots/stability.gp
  gnuplot -e "dir='$out'; scenes='$precision_scenes'" experiments/plots/work_precision.gp
  draw_atlas
  draw_free_atlas
  draw_contact_atlases
  draw_slide_atlas
  if [ -f "$out/slide_steps/l-stable_tries.csv" ]; then
    gnuplot -e "dir='$out/slide_steps'" experiments/plots/slide_steps.gp
  fi
  if [ -f "$out/atlas_trace/scaling_trace.csv" ]; then
    gnuplot -e "dir='$out/atlas_trace'" experiments/plots/atlas_trace.gp
  fi
  echo "run-experiments: charts redrawn in $out/"
  exit 0
fi
if [ -z "${JELLO_BIN:-}" ]; then scripts/build.sh native >/dev/null; fi
# Committed results come from a clean tree: each sidecar records its commit, which must be the
# code that ran. JELLO_ALLOW_DIRTY=1 runs anyway (the sidecars then say "tree_modified": true).
if [ "$out" = experiments/results ] && [ -z "${JELLO_ALLOW_DIRTY:-}" ] &&
   [ -n "$(git status --porcelain --untracked-files=no)" ]; then
  echo "run-experiments: the tree has uncommitted changes; commit them first (the results would" >&2
  echo "  name a commit that is not the code that ran), or set JELLO_ALLOW_DIRTY=1" >&2
  exit 1
fi
mkdir -p "$out"
if [ "${1:-}" = atlas ]; then
  export OMP_THREAD_LIMIT=1 OPENBLAS_NUM_THREADS=1
  # A run of 60 s is allowed (20 at N = 8): at N = 16 and 32 a converged implicit second costs
  # tens of seconds, and a 20 s budget would hide where it is cheapest.
  common=(--no-grid --atlas-budget 60 --jobs 1 --out-dir "$out")
  # The two layouts of the same cells (one job's atlas.csv, or the split run's four files):
  # each run removes the other's, which would repeat its cells.
  if [ -n "$ranks" ]; then
    "${launch[@]}" "$bin/jello-scaling" "${common[@]}" --atlas-n 16,32 \
      --atlas-references "$out/atlas_references" --name atlas --quiet
    rm -f "$out"/atlas16{.json,_atlas.csv,_tries.csv} \
      "$out"/atlas32{,stiff,stiffest}{.json,_atlas.csv,_tries.csv}
    draw_atlas
    echo "run-experiments: the atlas at N = 16 and 32 in $out/ ($ranks ranks)"
    exit 0
  fi
  # One point at a time (two side by side moved projective's figures by up to 40%): the runs on
  # one thread, the RK4 references on both cores, kept in atlas_references/ so that a rerun only
  # times the integrators. FALL_N=16 or 32 runs one of them.
  common+=(--atlas-reference-threads 2 --atlas-references "$out/atlas_references")
  export JELLO_THREADS=1
  if [ -z "${FALL_N:-}" ] || [ "$FALL_N" = 16 ]; then
    "$bin/jello-scaling" "${common[@]}" --atlas-n 16 --name atlas16
  fi
  if [ -z "${FALL_N:-}" ] || [ "$FALL_N" = 32 ]; then
    "$bin/jello-scaling" "${common[@]}" --atlas-n 32 --atlas-k 1e2,1e3,1e4,1e5,1e6 \
      --name atlas32
    "$bin/jello-scaling" "${common[@]}" --atlas-n 32 --atlas-k 1e7 --name atlas32stiff
    "$bin/jello-scaling" "${common[@]}" --atlas-n 32 --atlas-k 1e8 --name atlas32stiffest
  fi
  rm -f "$out"/atlas{.json,_atlas.csv,_tries.csv}
  draw_atlas
  echo "run-experiments: the atlas at N = 16 and 32 in $out/"
  exit 0
fi
if [ "${1:-}" = atlas-references ]; then
  # The atlas's CSV of such a run has no rows: it goes to build/, not over the committed one.
  only=("${launch[@]}" "$bin/jello-scaling" --no-grid --jobs 1 ${ranks:+--quiet}
    --atlas-references-only --out-dir build/atlas-references)
  if [ -n "${FREE_K:-}" ]; then
    # The free scene's at N = 32 for FREE_K, which `FREE_N=32 FREE_K=... atlas-free` then reads.
    "${only[@]}" --atlas-scene free --atlas-n 32 --atlas-k "$FREE_K" \
      --atlas-references "$out/atlas_free/atlas_references" --name free32
    exit 0
  fi
  for n in ${FALL_N:-16 32}; do
    "${only[@]}" --atlas-n "$n" --atlas-references "$out/atlas_references" --name "atlas$n"
  done
  echo "run-experiments: the atlas's references in $out/atlas_references/"
  exit 0
fi
if [ "${1:-}" = atlas-free ]; then
  export OMP_THREAD_LIMIT=1 OPENBLAS_NUM_THREADS=1
  free="$out/atlas_free"
  mkdir -p "$free"
  if [ -n "$ranks" ]; then
    "${launch[@]}" "$bin/jello-scaling" --no-grid --atlas-scene free --atlas-n 8 --jobs 1 \
      --quiet --out-dir "$free"
    "${launch[@]}" "$bin/jello-scaling" --no-grid --atlas-scene free --atlas-n 16 \
      --atlas-k 1e5,1e6,1e7 --atlas-budget 60 --jobs 1 --name atlas16 --quiet --out-dir "$free"
  else
    if [ -z "${FREE_N:-}" ] || [ "$FREE_N" = 8 ]; then
      taskset -c 1 "$bin/jello-scaling" --no-grid --atlas-scene free --atlas-n 8 --jobs 1 \
        --out-dir "$free"
    fi
    if [ -z "${FREE_N:-}" ] || [ "$FREE_N" = 16 ]; then
      taskset -c 1 "$bin/jello-scaling" --no-grid --atlas-scene free --atlas-n 16 \
        --atlas-k 1e5,1e6,1e7 --atlas-budget 60 --jobs 1 --name atlas16 --out-dir "$free"
    fi
    if [ -z "${FREE_N:-}" ] || [ "$FREE_N" = 32 ]; then
      # The runs on one thread of either core (no taskset: the references use both), and the
      # references, minutes of RK4 each, on both.
      # FREE_K (say 1e7): those k alone, in a run of their own (atlas32k1e7).
      JELLO_THREADS=1 "$bin/jello-scaling" --no-grid --atlas-scene free --atlas-n 32 \
        --atlas-k "${FREE_K:-1e2,1e3,1e4,1e5,1e6}" --atlas-budget 60 --jobs 1 \
        --atlas-reference-threads 2 --atlas-references "$free/atlas_references" \
        --name "atlas32${FREE_K:+k${FREE_K//,/-}}" --out-dir "$free"
    fi
  fi
  draw_free_atlas
  echo "run-experiments: the free scene's atlas in $free/"
  exit 0
fi
if [ "${1:-}" = atlas-contact ]; then
  export OMP_THREAD_LIMIT=1 OPENBLAS_NUM_THREADS=1
  for contact in ${CONTACTS:-k 20k barrier}; do
    dir="$out/atlas_contact_$contact"
    mkdir -p "$dir"
    if [ -n "$ranks" ]; then
      "${launch[@]}" "$bin/jello-scaling" --no-grid --atlas-n 8 --atlas-contact "$contact" \
        --jobs 1 --quiet --out-dir "$dir"
    else
      taskset -c 1 "$bin/jello-scaling" --no-grid --atlas-n 8 --atlas-contact "$contact" \
        --jobs 1 --out-dir "$dir"
    fi
  done
  draw_contact_atlases
  echo "run-experiments: the falling scene's atlas with stiffer floors in $out/atlas_contact_*/"
  exit 0
fi
if [ "${1:-}" = atlas-slide ]; then
  export OMP_THREAD_LIMIT=1 OPENBLAS_NUM_THREADS=1
  slide="$out/atlas_slide"
  mkdir -p "$slide"
  common=(--no-grid --atlas-scene slide --atlas-budget 60 --jobs 1 --out-dir "$slide")
  eight=(--atlas-n 8 --atlas-k 1e3,1e4,1e5 --name atlas8)
  sixteen=(--atlas-n 16 --atlas-k 1e4 --name atlas16)
  if [ -n "$ranks" ] || [ -n "${SLIDE_N:-}" ]; then
    # One after the other: each an MPI job, or the one SLIDE_N names, on one core.
    pin=(taskset -c 0)
    if [ -n "$ranks" ]; then pin=(); fi
    for n in ${SLIDE_N:-8 16}; do
      if [ "$n" = 8 ]; then set -- "${eight[@]}"; else set -- "${sixteen[@]}"; fi
      "${pin[@]}" "${launch[@]}" "$bin/jello-scaling" "${common[@]}" "$@" ${ranks:+--quiet}
    done
  else
    taskset -c 0 "$bin/jello-scaling" "${common[@]}" "${eight[@]}" --quiet &
    first=$!
    taskset -c 1 "$bin/jello-scaling" "${common[@]}" "${sixteen[@]}"
    wait "$first"
  fi
  draw_slide_atlas
  echo "run-experiments: the friction scene's atlas in $slide/"
  exit 0
fi
if [ "${1:-}" = slide-steps ]; then
  export OMP_THREAD_LIMIT=1 OPENBLAS_NUM_THREADS=1
  dir="$out/slide_steps"
  mkdir -p "$dir"
  steps=(--no-grid --atlas-scene slide --atlas-n 8 --atlas-k 1e4 --atlas-steps-tried 13
    --atlas-budget 1200 --jobs 1 --atlas-references "$dir/atlas_references")
  # The reference first, on both cores; then the two processes, both reading it.
  "${launch[@]}" "$bin/jello-scaling" "${steps[@]}" --atlas-references-only \
    --atlas-reference-threads 2 --out-dir build/atlas-references --name slide ${ranks:+--quiet}
  "${launch[@]}" "$bin/jello-scaling" "${steps[@]}" --atlas-integrators implicit,bdf2 --quiet \
    --out-dir "$dir" --name l-stable &
  first=$!
  "${launch[@]}" "$bin/jello-scaling" "${steps[@]}" --atlas-integrators midpoint,implicit-linear \
    --out-dir "$dir" --name others ${ranks:+--quiet}
  wait "$first"
  gnuplot -e "dir='$dir'" experiments/plots/slide_steps.gp
  echo "run-experiments: the friction scene's implicit errors against their step in $dir/"
  exit 0
fi
if [ "${1:-}" = atlas-trace ]; then
  export OMP_THREAD_LIMIT=1 OPENBLAS_NUM_THREADS=1
  mkdir -p "$out/atlas_trace"
  "${launch[@]}" "$bin/jello-scaling" --no-grid --atlas-trace --atlas-n 8,16,32 --atlas-k 1e4 \
    --atlas-budget 60 --jobs 1 ${ranks:+--quiet} --out-dir "$out/atlas_trace"
  gnuplot -e "dir='$out/atlas_trace'" experiments/plots/atlas_trace.gp
  echo "run-experiments: the falling scene's visible motion over time in $out/atlas_trace/"
  exit 0
fi
# Under --ranks, one point at a time per rank (--jobs 1), quietly (one progress line per rank
# would interleave).
if [ -n "$ranks" ]; then args+=(--jobs 1 --quiet); fi
"${launch[@]}" "$bin/jello-stability" "${args[@]}" --out-dir "$out"
"${launch[@]}" "$bin/jello-work-precision" "${args[@]}" --out-dir "$out"
# One point at a time: a neighbour's memory traffic would bend the timings. The atlas at N = 8
# only: N = 16 and 32 are `scripts/run-experiments.sh atlas` (or `mpirun -np K jello-scaling
# --atlas-n 16,32` on a cluster).
atlas_n=(--atlas-n 8)
# The quick grid's references are kept beside its results: a rerun reads them (a quarter of a
# minute of RK4 each), as do the tests, from tests/data/atlas-quick-references/.
[ "${1:-}" = quick ] && atlas_n=(--atlas-references "$out/atlas_references")
if [ -n "$ranks" ]; then
  "${launch[@]}" "$bin/jello-scaling" "${args[@]}" "${atlas_n[@]}" --out-dir "$out"
else
  "$bin/jello-scaling" "${args[@]}" "${atlas_n[@]}" --jobs 1 --out-dir "$out"
fi
gnuplot -e "dir='$out'; scenes='$stability_scenes'" experiments/plots/stability.gp
gnuplot -e "dir='$out'; scenes='$precision_scenes'" experiments/plots/work_precision.gp
draw_atlas
echo "run-experiments: results and charts in $out/"
