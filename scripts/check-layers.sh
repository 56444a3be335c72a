#!/usr/bin/env bash
# Fails when an include goes up the layers or does not name its layer (src/ARCHITECTURE.md):
#   src/          includes only src/
#   solvers/      src/, solvers/
#   viewer/       src/, solvers/, viewer/
#   experiments/  src/, solvers/, experiments/   (common/ only itself: the programs share it)
#   tests/        anything
# Project headers are included by their path from the project directory: "src/model.h".
set -euo pipefail
cd "$(dirname "$0")/.."
allowed() {
  case "$1" in
    src/*) echo "src" ;;
    solvers/*) echo "src solvers" ;;
    viewer/*) echo "src solvers viewer" ;;
    experiments/common/*) echo "experiments/common" ;;
    experiments/*) echo "src solvers experiments" ;;
    tests/*) echo "src solvers viewer experiments tests" ;;
  esac
}
status=0
while IFS= read -r file; do
  layers=$(allowed "$file")
  while IFS=: read -r line target; do
    ok=0
    for layer in $layers; do
      [[ "$target" == "$layer"/* ]] && ok=1
    done
    if [ $ok -eq 0 ]; then
      if [[ "$target" != */* ]]; then
        echo "$file:$line: include \"$target\" does not name its layer (write \"<layer>/$target\")"
      else
        echo "$file:$line: include \"$target\" goes against the layers (${file%%/*} may include: $layers)"
      fi
      status=1
    fi
  done < <(grep -n '^[[:space:]]*#[[:space:]]*include[[:space:]]*"' "$file" |
           sed -E 's/^([0-9]+):[[:space:]]*#[[:space:]]*include[[:space:]]*"([^"]+)".*/\1:\2/')
done < <(git ls-files -co --exclude-standard -- 'src/*' 'solvers/*' 'viewer/*' 'experiments/*' 'tests/*' |
         grep -E '\.(h|cpp)$' | while read -r f; do [ -f "$f" ] && echo "$f"; done)
[ $status -eq 0 ] && echo "check-layers: every include names its layer and goes down"
exit $status
