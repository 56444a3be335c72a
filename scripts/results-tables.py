#!/usr/bin/env python3
"""The README's Results numbers from the committed CSV alone (no number typed by hand).

Rewrites the blocks between <!-- stability-summary:begin/end --> (the stability map's measured
thresholds against their predictions, per integrator and scene, from
experiments/results/stability.csv and its sidecar) in README.md. With --check it changes
nothing and exits 1 when README.md differs from what the data gives (ctest runs it so).

    scripts/results-tables.py [--check]
"""
import argparse
import csv
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from readme_blocks import replace_block  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RESULTS = os.path.join(ROOT, "experiments", "results")
README = os.path.join(ROOT, "README.md")
ORDER = ["rk4", "symplectic", "euler", "implicit", "cvode"]


def span(values, fmt="{:.2f}"):
    lo, hi = min(values), max(values)
    a, b = fmt.format(lo), fmt.format(hi)
    return a if a == b else f"{a}-{b}"


def k_text(k):
    exponent = round(__import__("math").log10(k) * 2) / 2
    return f"10^{exponent:g}"


def stability_summary():
    with open(os.path.join(RESULTS, "stability.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    with open(os.path.join(RESULTS, "stability.json")) as f:
        sidecar = json.load(f)
    rule = sidecar["parameters"]["blow_up"]
    by = {}
    for r in rows:
        by.setdefault((r["scene"], r["integrator"]), {}).setdefault(float(r["k_N_per_m"]), {})[
            r["source"]] = r
    lines = [
        f"Blow-up rule of this run: {rule['time_s']:g} simulated s (explicit methods at least "
        f"{rule.get('explicit_min_steps', 0)} steps), energy above {rule['energy_factor']:g} "
        f"times its envelope (the largest of the first {rule.get('energy_envelope_steps', 0)} "
        f"steps), or a point {rule['divergence_bound_m']:g} m out; bisection to "
        f"{100 * sidecar['parameters']['bisection_tolerance']:g}%; commit "
        f"{sidecar['commit'][:7]}{' (modified tree)' if sidecar.get('tree_modified') else ''}, "
        f"{sidecar['date_utc'][:10]}.",
        "",
        "| scene | integrator | measured / predicted | h w_max measured | h w_max predicted | "
        "fastest mode's damping ratio |",
        "|---|---|---|---|---|---|"]
    for scene in ("free", "wall"):
        for name in ORDER:
            points = by.get((scene, name))
            if not points:
                continue
            ks = sorted(points)
            measured = [points[k]["measured"] for k in ks]
            zeta = span([float(points[k]["measured"]["zeta_max"]) for k in ks])
            if all(m["outcome"] == "stable_to_max" for m in measured):
                courant = span([float(m["courant_number"]) for m in measured], "{:,.0f}")
                lines.append(f"| {scene} | {name} | never blew up up to dt = "
                             f"{float(measured[0]['dt_s']):g} s | up to {courant.split('-')[-1]} "
                             f"| none | {zeta} |")
                continue
            ratio = [float(points[k]["measured"]["dt_s"]) / float(points[k]["predicted"]["dt_s"])
                     for k in ks]
            detail = ", ".join(f"{k_text(k)}: {r:.2f}" for k, r in zip(ks, ratio))
            lines.append(
                f"| {scene} | {name} | {span(ratio)} (k = {detail}) | "
                f"{span([float(points[k]['measured']['courant_number']) for k in ks])} | "
                f"{span([float(points[k]['predicted']['courant_number']) for k in ks])} | "
                f"{zeta} |")
    free_w = {float(r["k_N_per_m"]): float(r["w_max_rad_per_s"]) for r in rows
              if r["scene"] == "free"}
    wall_w = {float(r["k_N_per_m"]): float(r["w_max_rad_per_s"]) for r in rows
              if r["scene"] == "wall"}
    if wall_w:
        raise_ = [wall_w[k] / free_w[k] - 1 for k in wall_w if k in free_w]
        lines += ["", f"The wall's contact springs raise w_max by "
                      f"{span([100 * r for r in raise_], '{:.0f}')}% over the free cube's."]
    return "\n".join(lines)


BLOCKS = {"stability-summary": stability_summary}


def render(text):
    for name, make in BLOCKS.items():
        text = replace_block(text, name, make())
    return text


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true",
                        help="change nothing; exit 1 if README.md disagrees with the data")
    args = parser.parse_args()
    with open(README) as f:
        text = f.read()
    new = render(text)
    if args.check:
        if new != text:
            print("results-tables: README.md disagrees with experiments/results (run "
                  "scripts/results-tables.py)", file=sys.stderr)
            return 1
        print("results-tables: README.md agrees with the data")
        return 0
    if new != text:
        with open(README + ".tmp", "w") as f:
            f.write(new)
        os.replace(README + ".tmp", README)
    print(stability_summary())
    return 0


if __name__ == "__main__":
    sys.exit(main())
