#!/usr/bin/env bash
# Fails when an include goes up the layers or does not name its layer (src/ARCHITECTURE.md,
# solvers/README.md). Layers and wings, each may include what its line names (a folder ends in
# /, anything else is one file):
#   src/base/          src/base/
#   src/world/         + src/world/
#   src/effects/       + src/effects/
#   src/               all of src/ (Model, State)
#   solvers/linalg/    src/base/, solvers/linalg/, solvers/step_result.h   (no physics: no model)
#   solvers/ (face's declarations: integrator, solver_options, step_result)
#                      src/, solvers/linalg/, the face's declarations
#   solvers/system/    src/, solvers/linalg/, solvers/system/, the face's declarations
#   solvers/methods/   + solvers/methods/
#   solvers/cvode/     src/, solvers/linalg/, solvers/system/, solvers/cvode/, the declarations
#   solvers/ (the factory, Simulation): all of src/ and solvers/
#   viewer/            src/, solvers/, viewer/
#   experiments/       src/, solvers/, experiments/
#   tests/             anything
# The face's declarations are what the wings implement and return; no wing includes the
# factory or Simulation, and no face declaration includes a wing but linalg/: every arrow
# between wings runs one way. Project headers are included by their path from the project
# directory: "src/model.h".
set -euo pipefail
cd "$(dirname "$0")/.."
declarations="solvers/integrator.h solvers/solver_options.h solvers/step_result.h"
allowed() {
  case "$1" in
    src/base/*) echo "src/base/" ;;
    src/world/*) echo "src/base/ src/world/" ;;
    src/effects/*) echo "src/base/ src/world/ src/effects/" ;;
    src/*) echo "src/" ;;
    solvers/linalg/*) echo "src/base/ solvers/linalg/ solvers/step_result.h" ;;
    solvers/system/*) echo "src/ solvers/linalg/ solvers/system/ $declarations" ;;
    solvers/methods/*) echo "src/ solvers/linalg/ solvers/system/ solvers/methods/ $declarations" ;;
    solvers/cvode/*) echo "src/ solvers/linalg/ solvers/system/ solvers/cvode/ $declarations" ;;
    solvers/integrator.* | solvers/solver_options.h | solvers/step_result.h)
      echo "src/ solvers/linalg/ $declarations" ;;
    solvers/*) echo "src/ solvers/" ;;
    viewer/*) echo "src/ solvers/ viewer/" ;;
    experiments/*) echo "src/ solvers/ experiments/" ;;
    tests/*) echo "src/ solvers/ viewer/ experiments/ tests/" ;;
  esac
}
status=0
while IFS= read -r file; do
  layers=$(allowed "$file")
  while IFS=: read -r line target; do
    ok=0
    for layer in $layers; do
      if [[ "$layer" == */ ]]; then
        [[ "$target" == "$layer"* ]] && ok=1
      else
        [[ "$target" == "$layer" ]] && ok=1
      fi
    done
    if [ $ok -eq 0 ]; then
      if [[ "$target" != */* ]]; then
        echo "$file:$line: include \"$target\" does not name its layer (write \"<layer>/$target\")"
      else
        echo "$file:$line: include \"$target\" goes against the layers (${file%/*}/ may include: $layers)"
      fi
      status=1
    fi
  done < <(grep -n '^[[:space:]]*#[[:space:]]*include[[:space:]]*"' "$file" |
           sed -E 's/^([0-9]+):[[:space:]]*#[[:space:]]*include[[:space:]]*"([^"]+)".*/\1:\2/')
done < <(git ls-files -co --exclude-standard -- 'src/*' 'solvers/*' 'viewer/*' 'experiments/*' 'tests/*' |
         grep -E '\.(h|cpp)$' | while read -r f; do [ -f "$f" ] && echo "$f"; done)
[ $status -eq 0 ] && echo "check-layers: every include names its layer and goes down"
exit $status
