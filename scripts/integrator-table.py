#!/usr/bin/env python3
"""What each integrator keeps of a spinning, stretched, undamped stiff cube over 1 s.

Runs jello-sim on worlds/spinning-k1e4.w (k = 1e4 N/m, 5% stretched, spinning at 2 rad/s, no
damping, no contact) under every implicit integrator at dt = 0.01 s, cvode, and RK4 at a stable
step as the reference, and writes experiments/results/integrators.csv (one row per integrator)
with a JSON sidecar. With --readme it also rewrites the table in README.md between the markers
<!-- integrators-table:begin --> and <!-- integrators-table:end --> from that CSV alone.

    scripts/integrator-table.py [--readme] [--no-run] [--bin build/native/bin]

The second README table, the cost of one step of each implicit integrator, comes from
experiments/results/implicit_steps.json, and the third, wall time per simulated second against
RK4 (projective's crossover), from experiments/results/crossover.json; Google Benchmark writes
both:
    OMP_THREAD_LIMIT=1 OPENBLAS_NUM_THREADS=1 taskset -c 0 build/native/bin/benchmarks \
      --benchmark_filter=ImplicitIntegratorStep --benchmark_min_time=0.2 \
      --benchmark_out=experiments/results/implicit_steps.json --benchmark_out_format=json
    OMP_THREAD_LIMIT=1 OPENBLAS_NUM_THREADS=1 taskset -c 0 build/native/bin/benchmarks \
      --benchmark_filter='Crossover|CvodeOneSecond/rtol1e3' \
      --benchmark_out=experiments/results/crossover.json --benchmark_out_format=json
    OMP_THREAD_LIMIT=1 OPENBLAS_NUM_THREADS=1 taskset -c 0 build/native/bin/benchmarks \
      --benchmark_filter=KeptFactorSolve --benchmark_repetitions=3 \
      --benchmark_out=experiments/results/kept_factor.json --benchmark_out_format=json
"""
import argparse
import csv
import datetime
import json
import os
import platform
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import closed_sets  # noqa: E402
from readme_blocks import write_blocks  # noqa: E402

INTEGRATORS = {r["name"]: r for r in closed_sets.integrators()}

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
WORLD = os.path.join(ROOT, "worlds", "spinning-k1e4.w")
CSV = os.path.join(ROOT, "experiments", "results", "integrators.csv")
SIDECAR = os.path.join(ROOT, "experiments", "results", "integrators.json")
# Google Benchmark's JSON of BM_ImplicitIntegratorStep (see --steps-json), and its README table.
STEPS_JSON = os.path.join(ROOT, "experiments", "results", "implicit_steps.json")
CROSSOVER_JSON = os.path.join(ROOT, "experiments", "results", "crossover.json")
# BM_KeptFactorSolve (solvers/linalg/prefactored_cholesky.h), its own JSON.
FACTOR_JSON = os.path.join(ROOT, "experiments", "results", "kept_factor.json")

# Benchmark variants of one integrator (experiments/bench/benchmarks_implicit.cpp), as the tables
# name them.
VARIANTS = {
    "implicit-cholmod": "`implicit`, CHOLMOD",
    "implicit-fast": "`implicit`, fast (10 seeds, exact Jacobian, CG (projective) to 1e-2)",
    "bdf2-fast": "`bdf2`, fast (10 seeds, exact Jacobian, CG (projective) to 1e-2)",
}


def label(name):
    return VARIANTS.get(name, f"`{name}`")


# The reference: RK4 at a step far below its limit.
REFERENCE = ("rk4", 1e-4, [])
# Settings of one integrator run beside its defaults (the VARIANTS above).
VARIANT_RUNS = {
    "implicit": [["--linear-solver", "cholmod"],
                 # ImplicitOptions::fast()
                 ["--preconditioner", "projective", "--newton-seed", "10",
                  "--newton-seed-tol", "1e-8", "--newton-seed-chebyshev", "0.9",
                  "--clamp-on-demand", "--no-factor-reuse", "--cg-tol", "1e-2"]],
}


def runs():
    """(integrator, dt (s), extra jello-sim arguments): the reference, then every implicit and
    adaptive integrator of the table (src/world/integrator_table.h) at dt = 0.01 s in the
    studies' order, each followed by its variants; the adaptive ones at rtol 1e-6."""
    out = [REFERENCE]
    for name in closed_sets.study_order():
        row = INTEGRATORS[name]
        if row["explicit"]:
            continue
        out.append((name, 0.01, ["--rtol", "1e-6"] if row["adaptive"] else []))
        out += [(name, 0.01, extra) for extra in VARIANT_RUNS.get(name, [])]
    return out
COLUMNS = ["integrator", "settings", "dt_s", "simulated_s", "steps", "energy_start_J",
           "energy_end_J",
           "energy_kept", "angular_momentum_kept", "wall_time_s", "wall_time_per_step_ms",
           "newton_iterations_per_step", "newton_unconverged_steps", "factorizations", "diverged"]


def run(binary, integrator, dt, extra):
    with tempfile.TemporaryDirectory() as tmp:
        stats = os.path.join(tmp, "stats.json")
        cmd = [os.path.join(binary, "jello-sim"), WORLD, "--integrator", integrator, "--dt",
               repr(dt), "--time", "1", "--quiet", "--stats", stats] + extra
        print("integrator-table:", " ".join(cmd[1:]), file=sys.stderr)
        done = subprocess.run(cmd, check=False)
        if done.returncode not in (0, 3):
            sys.exit(f"integrator-table: jello-sim exited {done.returncode}")
        with open(stats) as f:
            s = json.load(f)
    l0 = s["angular_momentum_start_kg_m2_per_s"]
    l1 = s["angular_momentum_end_kg_m2_per_s"]
    solver = s.get("solver", {})
    return {
        "integrator": integrator,
        "settings": " ".join(extra),
        "dt_s": dt,
        "simulated_s": s["simulated_time_s"],
        "steps": s["steps"],
        "energy_start_J": s["energy_start"]["total_J"],
        "energy_end_J": s["energy_end"]["total_J"],
        "energy_kept": s["energy_end"]["total_J"] / s["energy_start"]["total_J"],
        "angular_momentum_kept": sum(a * b for a, b in zip(l0, l1)) / sum(a * a for a in l0),
        "wall_time_s": s["wall_time_s"],
        "wall_time_per_step_ms": 1e3 * s["wall_time_s"] / max(1, s["steps"]),
        "newton_iterations_per_step": solver.get("newton_iterations_per_step", ""),
        "newton_unconverged_steps": solver.get("newton_unconverged_steps", ""),
        "factorizations": solver.get("factorizations", ""),
        "diverged": s["diverged"],
    }


def write_atomically(path, text):
    fd, tmp = tempfile.mkstemp(dir=os.path.dirname(path), prefix=".tmp.")
    with os.fdopen(fd, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def table_from_csv():
    with open(CSV) as f:
        rows = list(csv.DictReader(f))
    lines = ["| integrator | dt (s) | energy kept | angular momentum kept | wall time for 1 s "
             "| per step | Newton iterations per step |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        newton = r["newton_iterations_per_step"]
        newton = f"{float(newton):.1f}" if newton else "n/a"
        name = f"`{r['integrator']}`"
        if r.get("settings"):
            name += f" `{r['settings']}`"
        if r["diverged"] not in ("", "0", "False", "false"):
            name += f" (diverged at t = {float(r['simulated_s']):.3g} s; figures there)"
        lines.append(f"| {name} | {float(r['dt_s']):g} | "
                     f"{float(r['energy_kept']):.4g} | {float(r['angular_momentum_kept']):.4g} | "
                     f"{float(r['wall_time_s']):.3g} s | "
                     f"{float(r['wall_time_per_step_ms']):.3g} ms | {newton} |")
    return "\n".join(lines)


def steps_table_from_json():
    with open(STEPS_JSON) as f:
        data = json.load(f)
    cells = {}
    order = []
    for b in data["benchmarks"]:
        # BM_ImplicitIntegratorStep/<integrator>/N:<n>/spinning:<0|1>
        _, name, n, spinning = b["name"].split("/")
        name = name.replace("_", "-")
        if name not in order:
            order.append(name)
        ms = b["real_time"] * {"ms": 1.0, "s": 1e3, "us": 1e-3}[b["time_unit"]]
        newton = b.get("newton_per_step")
        if b.get("error_occurred"):  # the simulation stopped it: a divergence
            ms, newton = None, None
        cells[(name, n.split(":")[1], spinning.split(":")[1])] = (ms, newton)
    columns = [(n, spinning) for n in ("8", "16", "32") for spinning in ("0", "1")
               if any((name, n, spinning) in cells for name in order)]
    lines = ["| integrator | " + " | ".join(
                 f"{'spinning cube' if spinning == '1' else 'jello.w'} {n}^3"
                 for n, spinning in columns) + " |",
             "|---|" + "---|" * len(columns)]
    for name in order:
        row = [label(name)]
        for column in columns:
            if (name, *column) not in cells:  # 32^3: projective alone
                row.append("")
                continue
            ms, newton = cells[(name, *column)]
            if ms is None:
                row.append("diverges")
                continue
            text = f"{ms:.3g} ms" if ms < 1000 else f"{ms / 1e3:.3g} s"
            row.append(text + (f" ({newton:.2g} it.)" if newton is not None else ""))
        lines.append("| " + " | ".join(row) + " |")
    date = data["context"]["date"][:10]
    lines.append("")
    lines.append(f"{date}, one core; each figure a step after a first step timed apart "
                 "(`first_step_ms` in the JSON).")
    return "\n".join(lines)


def milliseconds(b):
    return b["real_time"] * {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[b["time_unit"]]


def duration(ms):
    return f"{ms:.3g} ms" if ms < 1000 else f"{ms / 1e3:.3g} s"


def crossover_table_from_json():
    """Wall time per simulated second (BM_Crossover/<method>/<E>, k = 10^E; medians of 3, the
    set-up and first step timed apart) and each method's speed-up over RK4 measured in the same
    run."""
    with open(CROSSOVER_JSON) as f:
        data = json.load(f)
    cells, order, exponents = {}, [], []
    for b in data["benchmarks"]:
        if b.get("aggregate_name") != "median" or not b["name"].startswith("BM_Crossover/"):
            continue
        _, method, exponent = b["name"].split("/")[:3]
        method = method.replace("_", "-")
        if method not in order:
            order.append(method)
        if exponent not in exponents:
            exponents.append(exponent)
        cells[(method, exponent)] = (milliseconds(b), b["dt_s"], b["setup_s"] * 1e3)
    lines = ["| integrator | " + " | ".join(f"k = 1e{e}: per simulated second (dt; set-up)"
                                            for e in exponents) +
             " | " + " | ".join(f"speed-up over RK4 at 1e{e}" for e in exponents) + " |",
             "|---|" + "---|" * (2 * len(exponents))]
    for method in order:
        row = [label(method)]
        for e in exponents:
            ms, dt, setup = cells[(method, e)]
            row.append(f"{duration(ms)} ({dt:.3g} s; {duration_fine(setup)})")
        for e in exponents:
            row.append(f"{cells[('rk4', e)][0] / cells[(method, e)][0]:.2g}x")
        lines.append("| " + " | ".join(row) + " |")
    return "\n".join(lines)


def cvode_table_from_json():
    """1 s of jello.w under CVODE at rtol 1e-3 (BM_CvodeOneSecond, same JSON as the crossover)."""
    with open(CROSSOVER_JSON) as f:
        data = json.load(f)
    lines = ["| CVODE on 1 s of jello.w, rtol 1e-3 (median of 3) | wall time | steps | "
             "error-test failures "
             "| factorizations |", "|---|---|---|---|---|"]
    for b in data["benchmarks"]:
        # Medians of the repetitions (older runs: single runs, no aggregate).
        if not b["name"].startswith("BM_CvodeOneSecond/") or \
                b.get("aggregate_name", "median") != "median":
            continue
        variant = b["name"].split("/")[1].split("_", 1)[1]
        label = {"cholmod": "BDF, CHOLMOD", "cg": "BDF, CG (jacobi, matrix-free; the default)",
                 "cg_sundials_vectors": "BDF, CG, with SUNDIALS' own vector loops",
                 "adams": "Adams, fixed point",
                 "adams_sundials_vectors": "Adams, with SUNDIALS' own vector loops",
                 "spgmr": "BDF, SPGMR preconditioned by a kept CHOLMOD factor"}
        lines.append(f"| {label.get(variant, variant)} | {duration(milliseconds(b))} | "
                     f"{b['cvode_steps']:.0f} | {b['error_test_failures']:.0f} | "
                     f"{b.get('factorizations', 0):.0f} |")
    return "\n".join(lines)


def kept_factor_table_from_json():
    """Three right-hand sides through projective's kept factor: the copy and the
    single-precision supernodes against CHOLMOD."""
    with open(FACTOR_JSON) as f:
        data = json.load(f)
    cells, sizes = {}, []
    for b in data["benchmarks"]:
        if b.get("aggregate_name") != "median" or not b["name"].startswith("BM_KeptFactorSolve/"):
            continue
        _, how, n = b["name"].split("/")[:3]
        n = n.split("_")[0]
        if n not in sizes:
            sizes.append(n)
        cells[(how, n)] = (milliseconds(b), b["nnz_L"])
    lines = ["| three right-hand sides, M/h^2 + L | " +
             " | ".join(f"{n}^3 (L: {cells[('cholmod', n)][1]:,.0f} entries)" for n in sizes) +
             " |",
             "|---|" + "---|" * len(sizes)]
    ways = (("copy", "our substitutions over the copied factor"),
            ("single", "our substitutions over its supernodes in single precision"),
            ("cholmod", "CHOLMOD's `cholmod_solve2`"))
    for how, text in ways:
        lines.append(f"| {text} | " + " | ".join(
            duration_fine(cells[(how, n)][0]) if (how, n) in cells else "" for n in sizes) + " |")
    for how, text in ways[:2]:
        lines.append(f"| {how} / CHOLMOD | " + " | ".join(
            f"{cells[(how, n)][0] / cells[('cholmod', n)][0]:.2f}" if (how, n) in cells else ""
            for n in sizes) + " |")
    date = data["context"]["date"][:10]
    lines.append("")
    lines.append(f"Medians of 3 runs, {date}, one core (`experiments/results/kept_factor.json`).")
    return "\n".join(lines)


def duration_fine(ms):
    return f"{ms * 1e3:.3g} us" if ms < 1 else duration(ms)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bin", default=os.path.join(ROOT, "build", "native", "bin"))
    parser.add_argument("--readme", action="store_true", help="rewrite README's table only")
    parser.add_argument("--no-run", action="store_true", help="use the committed CSV")
    args = parser.parse_args()
    if not args.no_run:
        # The tree's state before this run writes its own CSV (which git tracks).
        commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "HEAD"], capture_output=True,
                                text=True).stdout.strip()
        dirty = bool(subprocess.run(["git", "-C", ROOT, "status", "--porcelain",
                                     "--untracked-files=no"], capture_output=True,
                                    text=True).stdout.strip())
        rows = [run(args.bin, *r) for r in runs()]
        with tempfile.NamedTemporaryFile("w", newline="", delete=False,
                                         dir=os.path.dirname(CSV)) as f:
            writer = csv.DictWriter(f, fieldnames=COLUMNS)
            writer.writeheader()
            writer.writerows(rows)
        os.replace(f.name, CSV)
        cpu = "unknown"
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
        sidecar = {"command_line": sys.argv, "world": os.path.relpath(WORLD, ROOT),
                   "runs": [{"integrator": i, "dt_s": dt, "extra": e} for i, dt, e in runs()],
                   "commit": commit, "tree_modified": dirty, "cpu": cpu,
                   "cores": os.cpu_count(), "kernel": platform.release(),
                   "OPENBLAS_NUM_THREADS": os.environ.get("OPENBLAS_NUM_THREADS", ""),
                   "OMP_THREAD_LIMIT": os.environ.get("OMP_THREAD_LIMIT", ""),
                   "date_utc": datetime.datetime.utcnow().strftime("%Y-%m-%dT%H:%M:%SZ")}
        write_atomically(SIDECAR, json.dumps(sidecar, indent=2) + "\n")
    if args.readme:
        write_blocks({"integrators-table": table_from_csv(),
                      "implicit-steps": steps_table_from_json(),
                      "crossover": crossover_table_from_json(),
                      "cvode-second": cvode_table_from_json(),
                      "kept-factor": kept_factor_table_from_json()})


if __name__ == "__main__":
    main()
