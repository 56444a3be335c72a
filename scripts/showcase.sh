#!/usr/bin/env bash
# The showcase animation: 300 frames (20 s at 15 frames/s, real-time pacing) of worlds/showcase.w,
# a cube dropped spinning under gravity onto a spiral ramp winding around a cone, with friction,
# the camera following it (--follow), into DIR (default
# showcase/), under Xvfb when there is no display; then a contact sheet of every 25th frame,
# experiments/results/showcase_sheet.png, for the README.
#   scripts/showcase.sh [DIR] [viewer options...]
set -euo pipefail
cd "$(dirname "$0")/.."
dir=${1:-showcase}
shift || true
[ -x build/release/bin/jello ] || scripts/build.sh release >/dev/null
viewer=(build/release/bin/jello worlds/showcase.w --record "$dir" --frames 300 --size 640x480 --no-hud
  --texture builtin --follow "$@")
if [ -n "${DISPLAY:-}" ]; then
  "${viewer[@]}"
else
  . scripts/xvfb.sh
  xvfb "${viewer[@]}"
fi
"${PYTHON:-/usr/bin/python3}" - "$dir" experiments/results/showcase_sheet.png <<'PY'
import os, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.image as mpimg
import numpy as np
frames, out = sys.argv[1], sys.argv[2]
picks = list(range(0, 300, 25))  # 12 frames: t = 0, 1.67, ... 18.3 s
images = [mpimg.imread(os.path.join(frames, "%03d.jpg" % i)) for i in picks]
rows = [np.concatenate(images[r * 4:(r + 1) * 4], axis=1) for r in range(3)]
sheet = np.concatenate(rows, axis=0)[::2, ::2]
tmp = out + ".tmp.png"
mpimg.imsave(tmp, sheet)
os.replace(tmp, out)
print(f"showcase: wrote {out} (frames {picks[0]} .. {picks[-1]} of {frames}/)")
PY
