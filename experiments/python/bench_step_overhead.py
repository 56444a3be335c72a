#!/usr/bin/env python3
"""What a call from Python costs beyond the C++ step: sim.step() called N times from a Python
loop against sim.step(N) (one call, the same N steps in C++), interleaved over repetitions,
medians reported, on jello.w with RK4 (the issue's case) and on a 2^3 cube (where the step
itself is a microsecond, so the overhead stands out of the noise). Writes
experiments/results/python_step_overhead.json; with --readme also the README table between
<!-- python-overhead:begin --> and <!-- python-overhead:end --> from that JSON alone.

    taskset -c 0 env PYTHONPATH=build/release/python python3 \
        experiments/python/bench_step_overhead.py [--repetitions 15] [--readme] [--no-run]
"""
import argparse
import datetime
import json
import os
import platform
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
JSON = os.path.join(ROOT, "experiments", "results", "python_step_overhead.json")
sys.path.insert(0, os.path.join(ROOT, "scripts"))
from readme_blocks import write_blocks  # noqa: E402  (the block lives in python/README.md)


def measure(sim, steps, repetitions):
    """Per-step seconds, Python loop and C++ loop, interleaved, one pair per repetition."""
    python, native = [], []
    step = sim.step
    for _ in range(repetitions):
        t0 = time.perf_counter()
        for _ in range(steps):
            step()
        t1 = time.perf_counter()
        step(steps)
        t2 = time.perf_counter()
        python.append((t1 - t0) / steps)
        native.append((t2 - t1) / steps)
    return python, native


def run(repetitions):
    import jello

    cases = []
    for name, world, steps in [
        ("jello.w, rk4 (8^3 points)", jello.load_world(os.path.join(ROOT, "worlds", "jello.w")),
         2000),
        ("2^3 cube, rk4", jello.create_world(cube=2), 50000),
    ]:
        sim = jello.Simulation(world, integrator="rk4")
        sim.step(steps // 10)  # warm up caches and the allocator
        python, native = measure(sim, steps, repetitions)
        overhead = [p - n for p, n in zip(python, native)]
        cases.append({
            "case": name, "steps_per_repetition": steps, "repetitions": repetitions,
            "python_loop_step_s_median": statistics.median(python),
            "cpp_loop_step_s_median": statistics.median(native),
            "overhead_s_median": statistics.median(overhead),
            "overhead_s_min": min(overhead), "overhead_s_max": max(overhead),
        })
    try:
        commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "HEAD"], capture_output=True,
                                text=True, check=True).stdout.strip()
        dirty = bool(subprocess.run(["git", "-C", ROOT, "status", "--porcelain",
                                     "--untracked-files=no"], capture_output=True, text=True,
                                    check=True).stdout.strip())
    except (OSError, subprocess.CalledProcessError):
        commit, dirty = "unknown", True
    return {
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "commit": commit, "tree_modified": dirty,
        "machine": platform.processor() or platform.machine(), "cpus": os.cpu_count(),
        "python": platform.python_version(), "affinity": sorted(os.sched_getaffinity(0)),
        "cases": cases,
    }


def table(data):
    us = 1e6
    lines = ["| case | C++ step (`sim.step(N)`) | `sim.step()` from a Python loop | overhead per "
             "call (median, min-max) |", "|---|---|---|---|"]
    for c in data["cases"]:
        lines.append(f"| {c['case']} | {c['cpp_loop_step_s_median'] * us:.2f} us | "
                     f"{c['python_loop_step_s_median'] * us:.2f} us | "
                     f"{c['overhead_s_median'] * us:.2f} us ({c['overhead_s_min'] * us:.2f}-"
                     f"{c['overhead_s_max'] * us:.2f}) |")
    lines.append("")
    lines.append(f"Medians of {data['cases'][0]['repetitions']} interleaved repetitions, commit "
                 f"{data['commit'][:7]}{' (modified tree)' if data['tree_modified'] else ''}, "
                 f"{data['date'][:10]}, on CPUs {data['affinity']} of {data['cpus']} "
                 f"(`experiments/results/python_step_overhead.json`).")
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repetitions", type=int, default=15)
    parser.add_argument("--readme", action="store_true", help="rewrite the README table")
    parser.add_argument("--no-run", action="store_true", help="only the README, from the JSON")
    args = parser.parse_args()
    if args.repetitions < 1:
        parser.error("--repetitions must be at least 1")
    if not args.no_run:
        data = run(args.repetitions)
        tmp = JSON + ".tmp"
        with open(tmp, "w") as f:
            json.dump(data, f, indent=2)
            f.write("\n")
        os.replace(tmp, JSON)
    with open(JSON) as f:
        data = json.load(f)
    print(table(data))
    if args.readme:
        write_blocks({"python-overhead": table(data)})
    return 0


if __name__ == "__main__":
    sys.exit(main())
