#!/usr/bin/env bash
# Regenerates the project's own scenes in worlds/ with jello-create-world (the six reference
# worlds there are copies and are never regenerated). Run after scripts/build.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
create=build/release/bin/jello-create-world

# Stiff free cubes for the stability studies: no plane, no field, undamped, far corner pulled.
$create -o worlds/stiff-k1e4.w --k-elastic 1e4 --d-elastic 0 --no-plane --field-resolution 0 \
  --velocity 0 0 0 --dt 1e-4
$create -o worlds/stiff-k1e5.w --k-elastic 1e5 --d-elastic 0 --no-plane --field-resolution 0 \
  --velocity 0 0 0 --dt 2e-5
# Dropped under gravity onto a sphere (the sphere extension).
$create -o worlds/sphere-drop.w --no-plane --field gravity --field-resolution 2 --pose translated \
  --translate -0.5 -0.5 0.2 --velocity 0 0 0 --sphere 0 0 -1.2 0.8 --dt 2e-4
# Spinning in rotate.w's vortex, against the plane of jello.w.
$create -o worlds/vortex-spin.w --field vortex --field-resolution 5 --pose rest --spin 20 \
  --velocity 0 0 0 --dt 5e-4
# The default scene with a 16^3 cube (the cube extension), for cost as N grows.
$create -o worlds/cube16.w --cube 16 --field-resolution 0 --dt 2.5e-4
# The spinning, 5% stretched, undamped stiff cube (vibratingStiffCube(1e4)): what the implicit
# integrators keep of its energy and angular momentum (scripts/integrator-table.py).
$create -o worlds/spinning-k1e4.w --integrator implicit --k-elastic 1e4 --d-elastic 0 --no-plane \
  --field-resolution 0 --pose stretched --stretch 1.05 --spin 2 --velocity 0 0 0 --dt 0.01
# The showcase (scripts/showcase.sh): dropped spinning (3 rad/s) under gravity onto a spiral
# ramp (1.5 turns) that winds around a cone (the cone and spiral extensions); with Coulomb
# friction mu = 0.1, about the ramp's slope at mid-width (pitch / (2 pi r) = 0.15 at r = 1.35 m,
# 0.11 at its rim), it tumbles, rides the ramp down a turn and, under the turn above, slows to a
# creep (frictionless, it slid off the end and under the ramp, out of sight). At dt 1 ms
# (friction costs a second contact query a point), RK4 keeps ahead of real time. Its top 2 cm
# below the box's ceiling: the barrier model needs every point off every solid at the start.
$create -o worlds/showcase.w --no-plane --field gravity --field-resolution 2 --pose translated \
  --translate 0.62 0.26 0.98 --velocity 0 0 0 --spin 3 --cone 0 0 0.3 0 0 -1 2.3 0.7 \
  --spiral 0 0 0.6 0.75 1.95 1.3 1.5 0.25 --friction 0.1 --dt 1e-3
