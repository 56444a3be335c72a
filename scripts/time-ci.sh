#!/usr/bin/env bash
# Times CI as a new checkout meets it: clones this repository's HEAD into a fresh directory, runs
# its .ci/run there, and writes experiments/results/ci_time.json (wall time, each stage's time
# from .ci/run's "== took N s: STAGE" lines, commit, machine, date, and how much ccache served:
# "cold" when it served nothing, else its hit rate), which scripts/results-tables.py turns into
# the README's CI line. The log stays in /tmp/jello-ci.log.
#   scripts/time-ci.sh [--cold]   (--cold empties ccache's cache first)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
[ "${1:-}" = --cold ] && ccache --clear >/dev/null 2>&1 || true
dir=$(mktemp -d /tmp/jello-ci.XXXXXX)
trap 'rm -rf "$dir"' EXIT
git clone -q "$root" "$dir/jello"
commit=$(git -C "$dir/jello" rev-parse HEAD)
stat() { ccache --print-stats 2>/dev/null | awk -v k="$1" '$1 == k { v = $2 } END { print v + 0 }'; }
hits0=$(( $(stat direct_cache_hit) + $(stat preprocessed_cache_hit) ))
miss0=$(stat cache_miss)
start=$(date +%s.%N)
(cd "$dir/jello" && .ci/run) > "$dir/ci.log" 2>&1 || { tail -40 "$dir/ci.log"; echo "time-ci: .ci/run failed" >&2; exit 1; }
end=$(date +%s.%N)
hits=$(( $(stat direct_cache_hit) + $(stat preprocessed_cache_hit) - hits0 ))
misses=$(( $(stat cache_miss) - miss0 ))
cp "$dir/ci.log" /tmp/jello-ci.log
python3 - "$root/experiments/results/ci_time.json" "$commit" "$start" "$end" "$hits" "$misses" \
  "$dir/ci.log" <<'PY'
import datetime, json, os, re, sys
path, commit, start, end, hits, misses, log = sys.argv[1:]
hits, misses = int(hits), int(misses)
cpus = os.cpu_count()
model = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
data = {"wall_time_s": round(float(end) - float(start), 1), "commit": commit,
        "date_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "machine": f"{cpus} CPUs ({model})",
        "ccache": "cold" if hits == 0 else f"{100 * hits / max(1, hits + misses):.0f}% of compiles served",
        "compiles_cached": hits, "compiles_run": misses,
        "stages_s": {m[2]: int(m[1]) for m in re.finditer(r"^== took (\d+) s: (.+)$", open(log).read(), re.M)}}
tmp = path + ".tmp"
with open(tmp, "w") as f:
    json.dump(data, f, indent=2)
    f.write("\n")
os.replace(tmp, path)
print(f"time-ci: {data['wall_time_s'] / 60:.1f} min ({data['ccache']})")
PY
