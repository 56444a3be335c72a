#!/usr/bin/env python3
"""The README's Speed tables, from Google Benchmark's JSON alone (no number typed by hand).

    scripts/speed-tables.py [--run] [--readme]

--run runs the benchmarks on one core, single-threaded BLAS and CHOLMOD, 3 repetitions, and
writes experiments/results/speed.json (its context records the machine and the date; commit it
from a clean tree). --readme rewrites the tables between the markers
<!-- speed-explicit:begin/end -->, <!-- speed-implicit:begin/end -->,
<!-- speed-product:begin/end -->, <!-- speed-stiff:begin/end --> and
<!-- speed-threads:begin/end --> in README.md from those JSON files (BM_Threads runs on both
cores, without taskset, into experiments/results/speed_threads.json).
Without either, it prints the tables.
"""
import argparse
import json
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import closed_sets  # noqa: E402
from readme_blocks import write_blocks  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
JSON = os.path.join(ROOT, "experiments", "results", "speed.json")
# Both cores: BM_Threads, run without taskset (1 and 2 threads in the same run).
THREADS_JSON = os.path.join(ROOT, "experiments", "results", "speed_threads.json")
# The native build (-march=native): the README's speed figures are this machine's best.
BINARY = os.path.join(ROOT, "build", "native", "bin", "benchmarks")
FILTER = ("BM_SpringForces|BM_Step/|BM_Refill|BM_OperatorFill|BM_Factorize|BM_Solve/|BM_CgSolve|BM_SystemProduct|"
          "BM_ImplicitStep/|BM_StiffOneSecond")
# BM_CgSolve's preconditioner argument is its row in the table (solvers/linalg/linear_solver.h).
PRECONDITIONERS = [r["name"] for r in closed_sets.preconditioners()]


def run(threads=True):
    env = dict(os.environ, OMP_THREAD_LIMIT="1", OPENBLAS_NUM_THREADS="1")
    runs = [(["taskset", "-c", "0"], FILTER, JSON)]
    if threads:
        runs.append(([], "BM_Threads", THREADS_JSON))
    for prefix, name, out in runs:
        tmp = out + ".tmp"
        subprocess.run(prefix + [BINARY, f"--benchmark_filter={name}",
                                 "--benchmark_repetitions=5" if not prefix else
                                 "--benchmark_repetitions=3",
                                 "--benchmark_report_aggregates_only=true",
                                 f"--benchmark_out={tmp}", "--benchmark_out_format=json"],
                       check=True, env=env)
        os.replace(tmp, out)


class Results:
    def __init__(self, data):
        self.context = data["context"]
        self.median = {}
        for b in data["benchmarks"]:
            if b.get("run_type") == "aggregate" and b.get("aggregate_name") == "median":
                self.median[b["run_name"]] = b

    def get(self, name):
        if name not in self.median:
            sys.exit(f"speed.json has no {name}: run scripts/speed-tables.py --run")
        return self.median[name]

    def seconds(self, name):
        b = self.get(name)
        scale = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[b["time_unit"]]
        return b["real_time"] * scale


def fmt_time(s):
    if s >= 1.0:
        return f"{s:.2f} s"
    if s >= 1e-3:
        return f"{s * 1e3:.3g} ms"
    return f"{s * 1e6:.3g} us"


def grouped(x):
    return f"{x:,.0f}"


def explicit_table(r):
    ns = [8, 16, 32]
    springs = [r.get(f"BM_SpringForces/{n}")["springs"] for n in ns]
    evals = [r.seconds(f"BM_SpringForces/{n}") for n in ns]
    rk4 = [1.0 / r.seconds(f"BM_Step/rk4/{n}") for n in ns]
    lines = ["| benchmark | 8^3 (jello.w) | 16^3 | 32^3 |", "|---|---|---|---|",
             "| springs | " + " | ".join(grouped(s) for s in springs) + " |",
             "| one evaluation of every spring | " + " | ".join(fmt_time(e) for e in evals) + " |",
             "| ns per spring evaluation | " +
             " | ".join(f"{e / s * 1e9:.2f}" for e, s in zip(evals, springs)) + " |",
             "| **RK4 steps/s** (whole step: 4 force evaluations, contact, divergence check) | " +
             " | ".join(("**" + grouped(x) + "**") if i == 0 else grouped(x)
                        for i, x in enumerate(rk4)) + " |",
             f"| explicit Euler steps/s | {grouped(1 / r.seconds('BM_Step/euler/8'))} | | |",
             f"| symplectic Euler steps/s | {grouped(1 / r.seconds('BM_Step/symplectic/8'))} | | |",
             "",
             f"RK4 on jello.w runs **{grouped(rk4[0])} steps/s on one core, "
             f"{rk4[0] * 0.0005:.1f}x real time** at its dt = 0.0005 s."]
    return "\n".join(lines)


def implicit_table(r):
    ns = [8, 16]
    lines = ["| at dt = 0.01 on jello.w | 8^3 (1,536 unknowns) | 16^3 (12,288 unknowns) |",
             "|---|---|---|",
             "| nonzeros of K (and of D, A) | " +
             " | ".join(grouped(r.get(f"BM_Refill/{n}")["nonzeros"]) for n in ns) + " |",
             "| refill K and D in place | " +
             " | ".join(fmt_time(r.seconds(f"BM_Refill/{n}")) for n in ns) + " |",
             "| CG's operator of A: K and D refilled, combined, gathered | " +
             " | ".join(fmt_time(r.seconds(f"BM_OperatorFill/N:{n}/filled:0")) for n in ns) +
             " |",
             "| **CG's operator of A filled straight from the springs** (Newton's) | " +
             " | ".join(fmt_time(r.seconds(f"BM_OperatorFill/N:{n}/filled:1")) for n in ns) +
             " |",
             "| CHOLMOD supernodal factorization | " +
             " | ".join(fmt_time(r.seconds(f"BM_Factorize/{n}")) for n in ns) + " |",
             "| CHOLMOD solve | " +
             " | ".join(fmt_time(r.seconds(f"BM_Solve/{n}")) for n in ns) + " |"]
    for pre_index, pre in enumerate(PRECONDITIONERS):
        for mf in (1, 0):
            cells = []
            for n in ns:
                name = f"BM_CgSolve/N:{n}/pre:{pre_index}/mf:{mf}"
                b = r.get(name)
                cells.append(f"{fmt_time(r.seconds(name))} ({b['iterations']:.0f} iterations)")
            label = f"CG solve, {pre}, {'matrix-free' if mf else 'sparse product'}"
            if pre_index == 0 and mf == 1:
                label = "**" + label + "**"
            lines.append(f"| {label} | " + " | ".join(cells) + " |")
    lines += ["| **implicit step (converged backward Euler), CHOLMOD** | " +
              " | ".join(fmt_time(r.seconds(f"BM_ImplicitStep/cholmod/{n}")) for n in ns) + " |",
              "| **implicit step (converged backward Euler), CG** (jacobi, matrix-free) | " +
              " | ".join(fmt_time(r.seconds(f"BM_ImplicitStep/cg/{n}")) for n in ns) + " |"]
    return "\n".join(lines)


def product_table(r):
    ns = [8, 16, 32]
    csr = [r.seconds(f"BM_SystemProduct/N:{n}/mf:0") for n in ns]
    mf = [r.seconds(f"BM_SystemProduct/N:{n}/mf:1") for n in ns]
    return "\n".join([
        "| y = A p | 8^3 | 16^3 | 32^3 |", "|---|---|---|---|",
        "| sparse matrix (Eigen, CSC) | " + " | ".join(fmt_time(t) for t in csr) + " |",
        "| matrix-free, through the spring groups | " + " | ".join(fmt_time(t) for t in mf) + " |",
        "| ratio | " + " | ".join(f"{c / m:.1f}x" for c, m in zip(csr, mf)) + " |"])


def stiff_table(r):
    rk4 = {k: r.seconds(f"BM_StiffOneSecond/rk4_at_its_limit/{k}/iterations:3") for k in (5, 6)}
    dt = {k: r.get(f"BM_StiffOneSecond/rk4_at_its_limit/{k}/iterations:3")["dt_s"] for k in (5, 6)}
    lines = ["| method | k = 10^5 | k = 10^6 |", "|---|---|---|",
             "| RK4 at its largest stable dt (bisection, then 5% below) | " +
             " | ".join(f"dt {dt[k]:.3g} s: **{fmt_time(rk4[k])}**" for k in (5, 6)) + " |"]
    for name, label in [("implicit_cg_dt001", "implicit, CG, dt = 0.01"),
                        ("implicit_cholmod_dt001", "implicit, CHOLMOD, dt = 0.01")]:
        cells = []
        for k in (5, 6):
            t = r.seconds(f"BM_StiffOneSecond/{name}/{k}/iterations:3")
            ratio = rk4[k] / t
            cells.append(f"{fmt_time(t)} ({ratio:.1f}x faster than RK4)" if ratio >= 1
                         else f"{fmt_time(t)} (RK4 {1 / ratio:.1f}x faster)")
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def threads_table(r):
    lines = ["| both cores (no taskset) | 1 thread | 2 threads | speed-up |", "|---|---|---|---|"]
    for what, label in [("springs", "every spring's force"), ("rk4_step", "a whole RK4 step"),
                        ("product", "the implicit solvers' matrix-free product")]:
        for n in (16, 32):
            one = r.seconds(f"BM_Threads/{what}/N:{n}/threads:1/real_time")
            two = r.seconds(f"BM_Threads/{what}/N:{n}/threads:2/real_time")
            lines.append(f"| {label}, {n}^3 | {fmt_time(one)} | {fmt_time(two)} | "
                         f"{one / two:.2f}x |")
    lines.append("")
    lines.append(f"Medians of 5 repetitions, {r.context['date'][:10]} "
                 "(`experiments/results/speed_threads.json`).")
    return "\n".join(lines)


def context_line(r):
    c = r.context
    return (f"Measured {c['date'][:10]} with `scripts/speed-tables.py --run` (one core, "
            f"medians of 3 repetitions, {c.get('host_name', '?')}, {c['num_cpus']} CPUs at "
            f"{c['mhz_per_cpu']} MHz, the native build: `-O3 -march=native`; "
            "`experiments/results/speed.json`). The machine is a shared VM: compare figures "
            "within one run, not across runs.")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--run", action="store_true", help="run the benchmarks first")
    parser.add_argument("--readme", action="store_true", help="rewrite the README tables")
    parser.add_argument("--no-threads", action="store_true",
                        help="with --run: keep speed_threads.json (its two-core run needs a "
                             "machine whose second CPU is idle)")
    args = parser.parse_args()
    if args.run:
        run(threads=not args.no_threads)
    with open(JSON) as f:
        r = Results(json.load(f))
    with open(THREADS_JSON) as f:
        threads = Results(json.load(f))
    tables = {"speed-explicit": context_line(r) + "\n\n" + explicit_table(r),
              "speed-threads": threads_table(threads),
              "speed-implicit": implicit_table(r),
              "speed-product": product_table(r),
              "speed-stiff": stiff_table(r)}
    if not args.readme:
        for name, text in tables.items():
            print(f"== {name}\n{text}\n")
        return 0
    write_blocks(tables)
    return 0


if __name__ == "__main__":
    sys.exit(main())
