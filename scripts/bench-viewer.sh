#!/usr/bin/env bash
# Frames per second of the viewer at 640x480 under Xvfb (Mesa's software renderer), RK4 at the
# world's own dt and n, shaded and wireframe. `scripts/bench-viewer.sh [WORLD] [FRAMES]`.
set -euo pipefail
cd "$(dirname "$0")/.."
world=${1:-worlds/jello.w}
frames=${2:-1200}
scripts/build.sh release >/dev/null
for mode in "" --wireframe; do
  xvfb-run -a -s "-screen 0 1024x768x24" \
    build/release/bin/jello "$world" --integrator rk4 --benchmark "$frames" $mode
done
