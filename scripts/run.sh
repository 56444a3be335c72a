#!/usr/bin/env bash
# The main job: installs what is missing, builds (Release) and opens the viewer on
# worlds/jello.w. Without a display it records the showcase instead: 300 frames (20 s of
# simulation, played at 15 frames/s) of worlds/showcase.w, the camera following the cube, into
# frames/000.jpg ... and the video frames/showcase.mp4, under Xvfb.
# Arguments go to the viewer, e.g. `scripts/run.sh --integrator implicit --dt 0.01`.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh release
viewer=build/release/bin/jello
if [ -n "${DISPLAY:-}" ]; then
  exec "$viewer" worlds/jello.w "$@"
fi
echo "run: no display: recording the showcase (worlds/showcase.w) to frames/ and" \
  "frames/showcase.mp4 under Xvfb"
mkdir -p frames
. scripts/xvfb.sh
xvfb "$viewer" worlds/showcase.w --follow --texture builtin \
  --record frames --record-video frames/showcase.mp4 --frames 300 "$@"
