#!/usr/bin/env bash
# The main job: installs what is missing, builds (Release) and runs jello-sim on worlds/jello.w.
# Arguments go to jello-sim, e.g. `scripts/run.sh --integrator euler --time 5`.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh release
exec build/release/experiments/jello-sim worlds/jello.w "$@"
