#!/usr/bin/env bash
# Frames per second of the viewer at 640x480 under Xvfb (Mesa's software renderer), with 4x
# multisampling and the panel open, the simulation on its own thread in real time:
#   jello.w, RK4 at the world's dt, shaded and wireframe (the simulation keeps up);
#   cube16.w with cvode (the simulation lags far behind: the drawing must not);
#   cube16.w with RK4 as the viewer runs it (its loops on one CPU fewer than there are:
#   src/base/parallel.h, leaveOneCpuFree) and with JELLO_THREADS=2.
# Pinned to one core for the drawing's figure (`taskset -c 0,1` leaves the simulation thread
# the other). Writes experiments/results/viewer_fps.json; `scripts/viewer-table.py --readme`
# puts it in the README.   scripts/bench-viewer.sh [FRAMES]
set -euo pipefail
cd "$(dirname "$0")/.."
frames=${1:-1200}
scripts/build.sh native >/dev/null
export OMP_THREAD_LIMIT=1 OPENBLAS_NUM_THREADS=1
out=experiments/results/viewer_fps.json
tmp=$(mktemp)
trap 'rm -f "$tmp"' EXIT
. scripts/xvfb.sh
bench() {  # name, world, args...
  local name=$1 world=$2
  shift 2
  echo "bench-viewer: $name" >&2
  local line
  line=$(xvfb env ${BENCH_ENV:-} build/native/bin/jello "$world" "$@")
  echo "$line" >&2
  printf '%s\t%s\n' "$name" "$line" >>"$tmp"
}
bench jello-rk4-shaded worlds/jello.w --integrator rk4 --benchmark "$frames"
bench jello-rk4-wireframe worlds/jello.w --integrator rk4 --benchmark "$frames" --wireframe
bench cube16-cvode-shaded worlds/cube16.w --integrator cvode --benchmark $((frames / 4))
bench cube16-rk4-shaded worlds/cube16.w --integrator rk4 --benchmark $((frames / 4))
BENCH_ENV=JELLO_THREADS=2 bench cube16-rk4-shaded-2threads worlds/cube16.w --integrator rk4 \
  --benchmark $((frames / 4))
python3 - "$tmp" "$out" "$(git rev-parse --short HEAD)$(git diff --quiet HEAD -- viewer src solvers || echo -dirty)" <<'PY'
import json, os, re, sys
rows = {}
pattern = re.compile(r"(\d+) frames in ([\d.]+) s: ([\d.]+) frames/s \((\w+), (\d+)x(\d+), "
                     r"(\d+) samples, panel (\w+), ([\w-]+), t = ([\d.e+-]+) s, simulating "
                     r"([\d.e+-]+) s per wall second(, lagging)?; (.*)\)")
for line in open(sys.argv[1]):
    name, text = line.rstrip("\n").split("\t", 1)
    m = pattern.search(text)
    if not m:
        sys.exit(f"bench-viewer: cannot read: {text}")
    rows[name] = dict(frames=int(m[1]), seconds=float(m[2]), fps=float(m[3]), mode=m[4],
                      width=int(m[5]), height=int(m[6]), samples=int(m[7]), panel=m[8],
                      integrator=m[9], simulated_s=float(m[10]), sim_rate=float(m[11]),
                      lagging=bool(m[12]), renderer=m[13])
data = {"commit": sys.argv[3], "runs": rows}
tmp = sys.argv[2] + ".tmp"
with open(tmp, "w") as f:
    json.dump(data, f, indent=1)
os.replace(tmp, sys.argv[2])
print(f"bench-viewer: wrote {sys.argv[2]}")
PY
