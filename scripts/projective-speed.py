#!/usr/bin/env python3
"""Projective's step on both cores: the cosine-transform global step against the CHOLMOD factor.

    scripts/projective-speed.py [--run]

--run runs BM_ProjectiveStep (experiments/bench/benchmarks_implicit.cpp: one step of jello.w, or
of the spinning stiff cube, at dt = 0.01 s with 10 iterations, after a first step timed apart; on
1 and 2 threads; the global step by the default, spectral from 16^3 up, and by the factor at
every size, spectralFrom = 0, the same-run baseline) on the native build without taskset, three
repetitions, and writes Google Benchmark's JSON with the commit measured to
experiments/results/projective_speed.json (about three minutes). Without it, prints the README's
table (block projective-speed, which scripts/results-tables.py writes from that file alone).
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


def run():
    tmp = JSON + ".tmp"
    subprocess.run([BINARY, "--benchmark_filter=BM_ProjectiveStep", "--benchmark_repetitions=3",
                    "--benchmark_out=" + tmp, "--benchmark_out_format=json"], check=True)
    commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True,
                            text=True, check=True).stdout.strip()
    dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=ROOT,
                           capture_output=True, text=True, check=True).stdout.strip()
    with open(tmp) as f:
        data = json.load(f)
    data["context"]["jello_commit"] = commit + ("-dirty" if dirty else "")
    with open(tmp, "w") as f:
        json.dump(data, f, indent=2)
    os.replace(tmp, JSON)


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
                 f"on both cores the slower scene's step takes {ms(worst)}.")
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--run", action="store_true", help="measure again (about three minutes)")
    args = parser.parse_args()
    if args.run:
        if not os.path.exists(BINARY):
            sys.exit(f"projective-speed: no {BINARY}: build the native preset first")
        run()
    print(table())


if __name__ == "__main__":
    main()
