#!/usr/bin/env python3
"""Energy of each integrator over time, from Python: the spinning stiff cube of the README's
integrator table (worlds/spinning-k1e4.w: k = 1e4 N/m, stretched 5%, spinning at 2 rad/s, no
spring damping, no contact) for 1 s under each integrator, its total energy sampled every
0.01 s and charted; the energy and angular momentum kept at the end are compared with the
committed experiments/results/integrators.csv (scripts/integrator-table.py, run by jello-sim).

    PYTHONPATH=build/release/python python3 experiments/python/energy_over_time.py \
        [--quick] [--time 1.0] [--integrators rk4,implicit,...] [--out FILE.png]
"""
import argparse
import csv
import os
import sys
import time

import matplotlib
import numpy as np

if not os.environ.get("DISPLAY") and "MPLBACKEND" not in os.environ:
    matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import jello  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
WORLD = os.path.join(ROOT, "worlds", "spinning-k1e4.w")
COMMITTED = os.path.join(ROOT, "experiments", "results", "integrators.csv")
# integrator, dt (s), solver options, as scripts/integrator-table.py runs them: RK4 far below
# its limit as the reference, then every implicit and adaptive row of the integrator table at
# dt = 0.01 s (the adaptive ones, CVODE, at rtol 1e-6), the adaptive ones last.
_TABLE = [r for r in jello.integrator_table() if not r["explicit"]]
RUNS = [("rk4", 1e-4, {})] + \
    [(r["name"], 0.01, {}) for r in _TABLE if not r["adaptive"]] + \
    [(r["name"], 0.01, {"rtol": 1e-6}) for r in _TABLE if r["adaptive"]]
# --quick: the reference and Newton's first- and second-order steps.
QUICK = ("rk4", "implicit", "midpoint")
SAMPLE = 0.01  # s between energy samples


def run(world, integrator, dt, options, duration):
    sim = jello.Simulation(world, integrator=integrator, dt=dt, **options)
    l0 = np.array(sim.angular_momentum())
    times, energies = [0.0], [sim.energy()["total"]]

    def sample(s):
        times.append(s.t)
        energies.append(s.energy()["total"])

    every = max(1, round(SAMPLE / dt))
    diverged = None
    started = time.monotonic()
    try:
        sim.run(time=duration, callback=sample, every=every)
    except jello.Diverged as e:
        diverged = e
    wall = time.monotonic() - started
    return {"t": times, "energy": energies, "wall": wall, "diverged": diverged,
            "energy_kept": energies[-1] / energies[0],
            # The share of the start's angular momentum left along its direction.
            "angular_momentum_kept": np.dot(sim.angular_momentum(), l0) / np.dot(l0, l0)}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--time", type=float, default=1.0, help="simulated seconds (default 1)")
    parser.add_argument("--integrators", help="comma-separated (default: the README table's)")
    parser.add_argument("--quick", action="store_true", help="0.1 s of rk4, implicit, midpoint")
    parser.add_argument("--out", default="energy_over_time.png", help="chart (PNG or SVG)")
    args = parser.parse_args()
    runs = RUNS
    if args.quick:
        args.time = min(args.time, 0.1)
        runs = [r for r in RUNS if r[0] in QUICK]
    if args.integrators:
        wanted = args.integrators.split(",")
        unknown = set(wanted) - {r[0] for r in RUNS}
        if unknown:
            parser.error(f"unknown integrators {sorted(unknown)}")
        runs = [r for r in RUNS if r[0] in wanted]
    if not args.time > 0:
        parser.error("--time must be positive")

    world = jello.load_world(WORLD)
    committed = {}
    if os.path.exists(COMMITTED):
        with open(COMMITTED, newline="") as f:
            committed = {row["integrator"]: row for row in csv.DictReader(f)}

    results = {}
    print(f"{'integrator':>16} {'dt (s)':>7} {'energy kept':>12} {'L kept':>9} {'wall (s)':>9}"
          f"  committed (jello-sim, 1 s)")
    for integrator, dt, options in runs:
        r = results[integrator] = run(world, integrator, dt, options, args.time)
        note = f"  diverged at t = {r['diverged'].t:.3g} s" if r["diverged"] else ""
        row = committed.get(integrator)
        ref = ""
        if row and args.time == 1.0:
            ref = (f"  {float(row['energy_kept']):.4g} / {float(row['angular_momentum_kept']):.4g}"
                   + (" (diverged)" if row["diverged"] == "True" else ""))
        print(f"{integrator:>16} {dt:>7g} {r['energy_kept']:>12.4g} "
              f"{r['angular_momentum_kept']:>9.4g} {r['wall']:>9.2f}{ref}{note}")

    fig, ax = plt.subplots(figsize=(9, 5.6))
    for integrator, r in results.items():
        label = integrator + (" (diverged)" if r["diverged"] else "")
        ax.plot(r["t"], np.array(r["energy"]) / r["energy"][0], lw=2, label=label)
    ax.set_yscale("log")
    ax.set_xlabel("simulated time (s)")
    ax.set_ylabel("total energy / its start")
    ax.set_title("Energy over time, undamped spinning stiff cube (k = 1e4 N/m), from Python")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, ncol=2)
    fig.tight_layout()
    tmp = args.out + ".tmp" + os.path.splitext(args.out)[1]
    fig.savefig(tmp, dpi=100)
    os.replace(tmp, args.out)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
