#!/usr/bin/env python3
"""What each contact model costs a step: projective and implicit on jello.w at 8^3 and 16^3.

    scripts/contact-speed.py [--run [--only INTEGRATOR]]

--run runs the benchmarks BM_ContactRun/<integrator>/<model>/N (experiments/bench/
benchmarks_implicit.cpp: 30 steps at dt = 0.01 from jello.w's start, the cube meeting the walls
and the plane, wall time per step after the first) on one core of the native build with
single-threaded BLAS and CHOLMOD, and writes Google Benchmark's JSON to
experiments/results/contact_speed.json; with --only, those of one integrator, replacing its
entries in that file and keeping the others' (implicit at 16^3 takes ten minutes); with --n, those
of one cube size (implicit_fast, ImplicitOptions::fast(), is measured at 8^3:
at 16^3 jello.w's impacts cost it step halvings and many Newton iterations). Without it,
prints the README's table (block
contact-speed, which scripts/results-tables.py writes from that file alone).
"""
import argparse
import json
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
JSON = os.path.join(ROOT, "experiments", "results", "contact_speed.json")
BINARY = os.path.join(ROOT, "build", "native", "bin", "benchmarks")


# The benchmarks' integrator names and how the table shows them.
LABELS = {"implicit_fast": "`implicit`, fast (ImplicitOptions::fast())"}


def run(only=None, n=None):
    env = dict(os.environ, OMP_THREAD_LIMIT="1", OPENBLAS_NUM_THREADS="1")
    tmp = JSON + ".tmp"
    pattern = "BM_ContactRun/" + (only + "/" if only else "") + (f".*/N:{n}/" if n else "")
    subprocess.run(["taskset", "-c", "0", BINARY, f"--benchmark_filter={pattern}",
                    f"--benchmark_out={tmp}", "--benchmark_out_format=json"],
                   check=True, env=env)
    if (only or n) and os.path.exists(JSON):
        with open(tmp) as f:
            fresh = json.load(f)
        with open(JSON) as f:
            kept = json.load(f)["benchmarks"]
        fresh["benchmarks"] = ([b for b in kept if not re.match(pattern, b["name"])] +
                               fresh["benchmarks"])
        with open(tmp, "w") as f:
            json.dump(fresh, f, indent=2)
    os.replace(tmp, JSON)


def plural(count, word):
    return f"{count:.0f} {word}" + ("" if round(count) == 1 else "s")


def table(path=JSON):
    """The README block: ms per step and what each integrator did, per model and size."""
    if not os.path.exists(path):
        return "Not measured yet (`scripts/contact-speed.py --run`)."
    with open(path) as f:
        data = json.load(f)
    runs = {}
    for b in data["benchmarks"]:
        if b.get("run_type", "iteration") != "iteration" or "error_occurred" in b:
            continue
        _, integrator, model, size = b["name"].split("/")[:4]
        n = int(size.split(":")[1])
        runs[(integrator, model, n)] = b
    models = list(dict.fromkeys(m for _, m, _ in runs))
    sizes = sorted({n for _, _, n in runs})
    lines = ["| integrator | N^3 | " + " | ".join(models) + " |",
             "|---|---|" + "---|" * len(models)]
    for integrator in dict.fromkeys(i for i, _, _ in runs):
        for n in sizes:
            cells = []
            for m in models:
                b = runs.get((integrator, m, n))
                if b is None:
                    cells.append("")
                    continue
                ms = b["real_time"] if b["time_unit"] == "ms" else b["real_time"] / 1e6
                extra = (f"{b['newton_iterations_per_step']:.1f} Newton/step"
                         if "newton_iterations_per_step" in b else
                         f"{plural(b.get('factorizations', 0), 'factorization')}, "
                         f"{plural(b.get('factor_updates', 0), 'update')}, "
                         f"{plural(b.get('coarse_corrections', 0), 'coarse correction')}")
                cells.append(f"{ms:.3g} ms ({extra})")
            if any(cells):
                shown = LABELS.get(integrator, f"`{integrator}`")
                lines.append(f"| {shown} | {n}^3 | " + " | ".join(cells) + " |")
    ctx = data["context"]
    lines.append("")
    lines.append(f"Wall time per step over jello.w's first 30 steps at dt = 0.01 s (its cube "
                 f"meets the walls and the plane), after the first; in parentheses Newton's "
                 f"iterations per step, or projective's factorizations, rank updates and "
                 f"coarse-corrected solves over the run (light contacts leave its factor alone: "
                 f"solvers/README.md) "
                 f"(`scripts/contact-speed.py --run`, one core of the native build, "
                 f"{ctx['date'][:10]}; experiments/results/contact_speed.json).")
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--run", action="store_true", help="measure again (about 15 minutes)")
    parser.add_argument("--only", choices=["projective", "implicit", "implicit_fast"],
                        help="with --run: measure this integrator alone, keep the others'")
    parser.add_argument("--n", type=int, choices=[8, 16],
                        help="with --run: measure this cube size alone, keep the others'")
    args = parser.parse_args()
    if args.run:
        if not os.path.exists(BINARY):
            sys.exit(f"contact-speed: no {BINARY}: build the native preset first")
        run(args.only, args.n)
    print(table())


if __name__ == "__main__":
    main()
