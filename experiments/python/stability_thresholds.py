#!/usr/bin/env python3
"""Largest stable time step against spring stiffness, from Python: the stability chart
(experiments/results/stability_free.png) again, measured with jello.stability_threshold (the
bisection and blow-up rule of jello-stability) and compared with the committed stability.csv.

    PYTHONPATH=build/release/python python3 experiments/python/stability_thresholds.py \
        [--quick] [--k 1e2,1e4] [--integrators euler,symplectic,rk4] [--jobs 2] [--out FILE.png]

The searches run on --jobs threads at once: stepping releases the GIL.
"""
import argparse
import concurrent.futures
import csv
import math
import os
import sys
import time

import matplotlib

if not os.environ.get("DISPLAY") and "MPLBACKEND" not in os.environ:
    matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import jello  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
COMMITTED = os.path.join(ROOT, "experiments", "results", "stability.csv")
# The explicit rows of the integrator table (those with a stability limit), each in the colour
# of its row in the charts (experiments/plots/integrators.gp).
PALETTE = ["#d62728", "#2ca02c", "#1f77b4", "#9467bd", "#ff7f0e", "#c5b0d5", "#17becf",
           "#bcbd22", "#e377c2", "#7f7f7f", "#8c564b", "#aec7e8", "#98df8a", "#ffbb78"]
COLORS = {r["name"]: PALETTE[i % len(PALETTE)] for i, r in enumerate(jello.integrator_table())}
EXPLICIT = [r["name"] for r in jello.integrator_table() if r["explicit"]]
DAMPING_RATIO = 1e-5  # s, c/k: jello-stability's default


def committed_thresholds(path):
    """{(integrator, k): dt} of the committed run's measured thresholds, free scene."""
    out = {}
    if os.path.exists(path):
        with open(path, newline="") as f:
            for row in csv.DictReader(f):
                if row["scene"] == "free" and row["source"] == "measured":
                    out[(row["integrator"], float(row["k_N_per_m"]))] = float(row["dt_s"])
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--k", help="stiffnesses, N/m, comma-separated (default 10 to 1e6, "
                        "two per decade; --quick: 1e2, 1e4)")
    parser.add_argument("--integrators", default=",".join(EXPLICIT))
    parser.add_argument("--quick", action="store_true", help="two stiffnesses, seconds")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--out", default="stability_free_python.png", help="chart (PNG or SVG)")
    args = parser.parse_args()
    if args.k:
        ks = [float(k) for k in args.k.split(",")]
    elif args.quick:
        ks = [1e2, 1e4]
    else:
        ks = [10 ** (i / 2) for i in range(2, 13)]
    integrators = args.integrators.split(",")
    if any(k <= 0 or not math.isfinite(k) for k in ks) or args.jobs < 1:
        parser.error("stiffnesses must be positive and --jobs at least 1")

    scenes = {k: jello.stability_scene("free", k, DAMPING_RATIO) for k in ks}
    w_max = {k: jello.w_max(w) for k, w in scenes.items()}
    started = time.monotonic()
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = {(i, k): pool.submit(jello.stability_threshold, scenes[k], i)
                   for i in integrators for k in ks}
        measured = {key: f.result()["stable"] for key, f in futures.items()}
    elapsed = time.monotonic() - started

    committed = committed_thresholds(COMMITTED)
    # Bisection on the same blow-up rule to the same 2%: a build for another CPU level than the
    # committed run's differs in the last bits, and where the rule's decision sits at the
    # threshold those move the bisection within its resolution (equal to 1e-9 on one build).
    same = [key for key in measured
            if key in committed and abs(committed[key] - measured[key]) <= 0.02 * committed[key]]
    compared = [key for key in measured if key in committed]
    print(f"{len(measured)} thresholds in {elapsed:.1f} s on {args.jobs} threads")
    print(f"{'integrator':>11} {'k (N/m)':>10} {'dt (s)':>12} {'h w_max':>8} {'predicted':>10}")
    for (i, k), dt in sorted(measured.items(), key=lambda item: (item[0][0], item[0][1])):
        predicted = jello.predicted_threshold(i, w_max[k], DAMPING_RATIO) * w_max[k]
        print(f"{i:>11} {k:>10.3g} {dt:>12.5g} {dt * w_max[k]:>8.4f} {predicted:>10.4f}")
    print(f"equal to the committed stability.csv (within the bisection's 2%): {len(same)} of "
          f"{len(compared)} thresholds compared")

    fig, ax = plt.subplots(figsize=(9, 6.2))
    dense = [10 ** (x / 20) for x in range(int(20 * math.log10(min(ks))),
                                           int(20 * math.log10(max(ks))) + 1)]
    for i in integrators:
        color = COLORS.get(i, "black")
        # Predicted: w_max scales as sqrt(k) at fixed mass (linear springs).
        k0 = ks[0]
        ax.plot(dense, [jello.predicted_threshold(i, w_max[k0] * math.sqrt(k / k0), DAMPING_RATIO)
                        for k in dense], color=color, lw=2, label=f"{i} predicted")
        ax.plot(ks, [measured[(i, k)] for k in ks], "o", color=color, label=f"{i} measured")
        ref = [(k, committed[(i, k)]) for k in ks if (i, k) in committed]
        if ref:
            ax.plot(*zip(*ref), "o", mfc="none", ms=12, color=color,
                    label=f"{i}, jello-stability (committed)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("spring stiffness k (N/m)")
    ax.set_ylabel("largest stable dt (s)")
    ax.set_title("Largest stable time step, free scene, from Python "
                 "(points measured, lines predicted)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, ncol=3, loc="upper right")
    fig.tight_layout()
    tmp = args.out + ".tmp" + os.path.splitext(args.out)[1]
    fig.savefig(tmp, dpi=100)
    os.replace(tmp, args.out)  # a chart is whole or absent
    print(f"wrote {args.out}")
    return 0 if len(same) == len(compared) else 1


if __name__ == "__main__":
    sys.exit(main())
