#!/usr/bin/env python3
"""Projective's step on both cores: the cosine-transform global step against the CHOLMOD factor.

    scripts/projective-speed.py [--run] [--baseline BENCHMARKS]

--run runs BM_ProjectiveStep (experiments/bench/benchmarks_implicit.cpp: one step of jello.w, or
of the spinning stiff cube, at dt = 0.01 s with 10 iterations, after a first step timed apart; on
1 and 2 threads; the global step by the default, spectral from 16^3 up, and by the factor at
every size, spectralFrom = 0, the same-run baseline) on the native build without taskset, three
repetitions, and writes Google Benchmark's JSON with the commit measured to
experiments/results/projective_speed.json (about three minutes). Without it, prints the README's
table (block projective-speed, which scripts/results-tables.py writes from that file alone).

--baseline BENCHMARKS takes a benchmarks binary built from an earlier commit (a git worktree's
build/native/bin/benchmarks) and runs, alternately with this checkout's, the benchmarks both
have at 8^3 and 16^3: BM_ContactRun/projective/penalty (jello.w's first 30 steps) and
BM_ImplicitIntegratorStep/projective on the spinning cube, three repetitions each, on both
cores, into experiments/results/projective_baseline.json (the steps before and after a change,
in one run).
"""
import argparse
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
JSON = os.path.join(ROOT, "experiments", "results", "projective_speed.json")
BINARY = os.path.join(ROOT, "build", "native", "bin", "benchmarks")
SCENES = {"0": "jello.w", "1": "spinning cube"}


def commit_of(directory):
    return subprocess.run(["git", "rev-parse", "HEAD"], cwd=directory, capture_output=True,
                          text=True, check=True).stdout.strip()


def run():
    tmp = JSON + ".tmp"
    subprocess.run([BINARY, "--benchmark_filter=BM_ProjectiveStep", "--benchmark_repetitions=3",
                    "--benchmark_out=" + tmp, "--benchmark_out_format=json"], check=True)
    commit = commit_of(ROOT)
    dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=ROOT,
                           capture_output=True, text=True, check=True).stdout.strip()
    with open(tmp) as f:
        data = json.load(f)
    data["context"]["jello_commit"] = commit + ("-dirty" if dirty else "")
    with open(tmp, "w") as f:
        json.dump(data, f, indent=2)
    os.replace(tmp, JSON)


BASELINE_JSON = os.path.join(ROOT, "experiments", "results", "projective_baseline.json")
BASELINE_FILTER = ("BM_ContactRun/projective/penalty/N:(8|16)/|"
                   "BM_ImplicitIntegratorStep/projective/N:(8|16)/spinning:1")


def run_baseline(binary):
    """Medians (ms) of BASELINE_FILTER by the baseline binary and this checkout's, alternately."""
    out = {"baseline_commit": commit_of(os.path.dirname(os.path.abspath(binary))),
           "commit": commit_of(ROOT), "benchmarks": {}}
    for round_ in range(3):
        for which, path in (("baseline", binary), ("now", BINARY)):
            tmp = BASELINE_JSON + f".{which}.tmp"
            subprocess.run([path, "--benchmark_filter=" + BASELINE_FILTER,
                            "--benchmark_out=" + tmp, "--benchmark_out_format=json"], check=True)
            with open(tmp) as f:
                data = json.load(f)
            os.remove(tmp)
            for b in data["benchmarks"]:
                ms = b["real_time"] * {"us": 1e-3, "ms": 1.0, "s": 1e3}[b["time_unit"]]
                out["benchmarks"].setdefault(b["name"], {}).setdefault(which, []).append(ms)
            out["date"] = data["context"]["date"]
    tmp = BASELINE_JSON + ".tmp"
    with open(tmp, "w") as f:
        json.dump(out, f, indent=2)
    os.replace(tmp, BASELINE_JSON)


def baseline_text():
    """The README's sentence on the steps before and after, from projective_baseline.json."""
    if not os.path.exists(BASELINE_JSON):
        return ""
    with open(BASELINE_JSON) as f:
        data = json.load(f)
    parts = []
    for name, runs in data["benchmarks"].items():
        def median_and_range(values):
            v = sorted(values)
            return f"{v[len(v) // 2]:.3g} ms ({v[0]:.3g}-{v[-1]:.3g})"
        n = name.split("N:")[1].split("/")[0]
        scene = "jello.w's first 30 steps" if name.startswith("BM_ContactRun") else "the spinning cube"
        parts.append(f"{n}^3, {scene}: {median_and_range(runs['baseline'])} before, "
                     f"{median_and_range(runs['now'])} after")
    return (f" Against the code before the cosine bound (commit {data['baseline_commit'][:7]}), "
            f"alternately in one run on both cores (medians of 3, their range in brackets; "
            f"`--baseline`, experiments/results/projective_baseline.json), a step at "
            + "; ".join(parts) + ".")


def medians(data):
    """{(global, n, scene, threads): ms} from the medians of the repetitions."""
    out = {}
    for b in data["benchmarks"]:
        if b.get("aggregate_name") != "median" or b.get("error_occurred"):
            continue
        # BM_ProjectiveStep/<global>/N:<n>/spinning:<s>/threads:<t>/real_time_median
        parts = b["run_name"].split("/")
        key = (parts[1],) + tuple(p.split(":")[1] for p in parts[2:5])
        out[key] = b["real_time"] * {"us": 1e-3, "ms": 1.0, "s": 1e3}[b["time_unit"]]
    return out


def ms(x):
    return f"{x:.3g} ms"


def table(path=JSON):
    """The README block: ms per step by both global steps, 1 and 2 threads, and their ratio."""
    if not os.path.exists(path):
        return "Not measured yet (`scripts/projective-speed.py --run`)."
    with open(path) as f:
        data = json.load(f)
    m = medians(data)
    lines = ["| scene | N^3 | 1 thread: cosine bound | factor | 2 threads: cosine bound | factor "
             "| factor / cosine bound (2 threads) |", "|---|---|---|---|---|---|---|"]
    for scene, name in SCENES.items():
        for n in ("8", "16", "32"):
            cells = [m.get((g, n, scene, t)) for t in ("1", "2") for g in ("spectral", "factor")]
            if None in cells:
                continue
            shown = [ms(c) for c in cells]
            ratio = f"{cells[3] / cells[2]:.2f}x"
            if n == "8":  # 8^3 keeps its factor: both columns run the same code
                shown[0] += " (the factor)"
                shown[2] += " (the factor)"
                ratio = "the same code (the columns differ by the machine's noise)"
            lines.append(f"| {name} | {n}^3 | " + " | ".join(shown) + f" | {ratio} |")
    ctx = data["context"]
    worst = max(m[("spectral", "32", s, "2")] for s in SCENES)
    lines.append("")
    lines.append(f"Wall time of one step at dt = 0.01 s (10 iterations), after a first step timed "
                 f"apart; medians of 3 repetitions, both variants in the same run "
                 f"(`scripts/projective-speed.py --run`, the native build, "
                 f"{ctx['num_cpus']} CPUs, {ctx['date'][:10]}, commit "
                 f"{ctx['jello_commit'][:7]}; experiments/results/projective_speed.json). At 32^3 "
                 f"on both cores the slower scene's step takes {ms(worst)}." + baseline_text())
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--run", action="store_true", help="measure again (about three minutes)")
    parser.add_argument("--baseline", metavar="BENCHMARKS",
                        help="an earlier commit's benchmarks binary: before and after, alternately")
    args = parser.parse_args()
    if (args.run or args.baseline) and not os.path.exists(BINARY):
        sys.exit(f"projective-speed: no {BINARY}: build the native preset first")
    if args.baseline and not os.access(args.baseline, os.X_OK):
        sys.exit(f"projective-speed: --baseline {args.baseline}: not an executable")
    if args.run:
        run()
    if args.baseline:
        run_baseline(args.baseline)
    print(table())


if __name__ == "__main__":
    main()
