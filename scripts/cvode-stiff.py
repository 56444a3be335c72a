#!/usr/bin/env python3
"""CVODE's cost on very stiff scenes, measured (#16): jello.w with its spring stiffness raised
to k = 1e4 .. 1e7, CVODE's BDF at rtol 1e-3 (its defaults) over a window of a few thousand of
its steps, and backward Euler (default settings) for 20 steps of dt = 0.001 for comparison. Writes
experiments/results/cvode_stiff.csv and, with --readme, the table between
<!-- cvode-stiff:begin/end --> in README.md. Also prints the h * w_max CVODE settled at, the
constant jello-sim's cvode warning uses (kCvodeStepTimesWmax in solvers/system/modes.h).

Uses the Python module of the release build (build/release/python): scripts/test.sh builds it.
"""
import argparse
import csv
import os
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "build", "release", "python"))
os.environ.setdefault("OMP_THREAD_LIMIT", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
import jello  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from readme_blocks import write_blocks  # noqa: E402

CSV = os.path.join(ROOT, "experiments", "results", "cvode_stiff.csv")
KS = [1e4, 1e5, 1e6, 1e7]


def window(k):
    """A window of a few thousand CVODE steps: shorter as the scene stiffens."""
    return min(0.05, 2e-3 * (1e6 / k) ** 0.5)


def measure():
    rows = []
    for k in KS:
        world = jello.load_world(os.path.join(ROOT, "worlds", "jello.w"))
        world.k = k
        w_max = jello.w_max(world)
        t = window(k)
        for name, dt in (("cvode", t), ("implicit", 1e-3)):
            sim = jello.Simulation(world, name, dt)
            steps = 1 if name == "cvode" else 20  # backward Euler: 20 steps of 1 ms
            started = time.perf_counter()
            for _ in range(steps):
                sim.step()
            wall = time.perf_counter() - started
            simulated = sim.stats["simulated_time_s"]
            internal = sim.stats["solver"].get("cvode_steps", steps)
            rows.append({
                "k_N_per_m": k, "w_max_rad_per_s": w_max, "integrator": name,
                "window_s": simulated, "internal_steps": int(internal), "wall_s": wall,
                "steps_per_simulated_s": internal / simulated,
                "h_w_max": w_max * simulated / internal, "wall_per_simulated_s": wall / simulated,
            })
            print(f"k {k:8.0e} {name:9s} {internal:8.0f} steps in {simulated:.3g} s, wall "
                  f"{wall:.3f} s: {wall / simulated:.4g} s per simulated s, h w_max "
                  f"{w_max * simulated / internal:.3g}", flush=True)
    return rows


def committed_rows():
    with open(CSV, newline="") as f:
        return [{k: (v if k == "integrator" else float(v)) for k, v in r.items()}
                for r in csv.DictReader(f)]


def duration(s):
    if s < 120:
        return f"{s:.3g} s"
    if s < 7200:
        return f"{s / 60:.3g} min"
    return f"{s / 3600:.3g} h"


def table(rows):
    by = {(r["k_N_per_m"], r["integrator"]): r for r in rows}
    lines = ["| k (N/m) | w_max (rad/s) | cvode steps per simulated s | h w_max | cvode, wall per "
             "simulated s | implicit dt 0.001, wall per simulated s |", "|---|---|---|---|---|---|"]
    for k in sorted({r["k_N_per_m"] for r in rows}):
        c, i = by[(k, "cvode")], by[(k, "implicit")]
        lines.append(f"| {k:.0e} | {c['w_max_rad_per_s']:.3g} | {c['steps_per_simulated_s']:.3g} | "
                     f"{c['h_w_max']:.3f} | {duration(c['wall_per_simulated_s'])} | "
                     f"{duration(i['wall_per_simulated_s'])} |")
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--no-run", action="store_true", help="use the committed CSV")
    parser.add_argument("--readme", action="store_true", help="rewrite the README table")
    args = parser.parse_args()
    if args.no_run:
        rows = committed_rows()
    else:
        rows = measure()
        tmp = CSV + ".tmp"
        with open(tmp, "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)
        os.replace(tmp, CSV)
    hw = [r["h_w_max"] for r in rows if r["integrator"] == "cvode"]
    print(f"cvode h w_max from {min(hw):.3g} to {max(hw):.3g}")
    print(table(rows))
    if args.readme:
        write_blocks({"cvode-stiff": table(rows)})
    return 0


if __name__ == "__main__":
    sys.exit(main())
