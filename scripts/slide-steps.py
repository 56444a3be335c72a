#!/usr/bin/env python3
"""The friction scene's implicit errors against their step (issue 39, item 2's open question),
from every NAME_tries.csv, NAME_atlas.csv and NAME.json in experiments/results/slide_steps/
(scripts/run-experiments.sh slide-steps: jello-scaling --atlas-scene slide, two processes, every
run of each search kept, down to steps that resolve static friction's damping rate): the block
slide-steps of experiments/README.md, written by scripts/results-tables.py. Run alone, it prints
the block.

    scripts/slide-steps.py
"""
import csv
import glob
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import closed_sets  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DIR = os.path.join(ROOT, "experiments", "results", "slide_steps")


def _files(suffix, where=DIR):
    return sorted(glob.glob(os.path.join(where, "*" + suffix)))


def _read(suffix, where):
    rows = []
    for path in _files(suffix, where):
        with open(path, newline="") as f:
            rows += list(csv.DictReader(f))
    return rows


def ran(where=DIR):
    return bool(_files("_tries.csv", where))


def _cell(row):
    if row is None:
        return ""
    if row["finished"] != "1":
        return {"budget": "over budget", "diverged": "diverged"}.get(row["why"], "failed")
    return f"{100 * float(row['visible_error_m']):.2g}"


def _rises(rows):
    """(how many halvings raised the error, how many halvings there were) over the finished
    runs, each against the one before it."""
    done = [float(r["visible_error_m"]) for r in rows if r["finished"] == "1"]
    return sum(b > a for a, b in zip(done, done[1:])), max(len(done) - 1, 0)


def _load(where):
    """The runs in `where`: every try, every sidecar, w_max and the tolerance."""
    sidecars = []
    for path in _files(".json", where):
        with open(path) as f:
            sidecars.append(json.load(f))
    return (_read("_tries.csv", where), sidecars,
            float(_read("_atlas.csv", where)[0]["w_max_rad_per_s"]),
            sidecars[0]["parameters"]["atlas"]["tolerance_m"])


def _first_within(rows, tolerance):
    """The first finished run within the tolerance, or None."""
    return next((r for r in rows if r["finished"] == "1"
                 and float(r["visible_error_m"]) <= tolerance), None)


def within(where=DIR):
    """(smallest h w_max tried, [(integrator, h w_max of its first run within the tolerance)])
    in the integrator table's order, or None when it has not run."""
    if not ran(where):
        return None
    tries, _, w_max, tolerance = _load(where)
    found = []
    for r in closed_sets.integrators():
        ok = _first_within([t for t in tries if t["integrator"] == r["name"]], tolerance)
        if ok:
            found.append((r["name"], float(ok["dt_s"]) * w_max))
    return min(float(t["dt_s"]) for t in tries) * w_max, found


def table(where=DIR):
    """The block from the runs in `where`."""
    if not ran(where):
        return "Not run yet (`scripts/run-experiments.sh slide-steps`)."
    tries, sidecars, w_max, tolerance = _load(where)
    commits = sorted({s["commit"][:7] for s in sidecars})
    dates = sorted({s["date_utc"][:10] for s in sidecars})
    minutes = max(s["wall_time_s"] for s in sidecars) / 60
    ran_here = {r["integrator"] for r in tries}
    names = [r["name"] for r in closed_sets.integrators() if r["name"] in ran_here]
    steps = sorted({float(r["dt_s"]) for r in tries}, reverse=True)
    by = {(r["integrator"], float(r["dt_s"])): r for r in tries}
    point = tries[0]
    lines = [f"N = {point['n']}, k = {float(point['k_N_per_m']):g} N/m, w_max {w_max:,.0f} rad/s "
             f"(static friction's damping rate); the largest corner distance from the reference "
             f"over the 2 s, cm (commit {', '.join(commits)}, {', '.join(dates)}, "
             f"{len(sidecars)} runs side by side, {minutes:.0f} min):", "",
             "| dt (s) | h w_max | " + " | ".join(f"`{n}`" for n in names) + " |",
             "|---|---|" + "---|" * len(names)]
    for dt in steps:
        lines.append(f"| {dt:.3g} | {dt * w_max:.3g} | "
                     + " | ".join(_cell(by.get((n, dt))) for n in names) + " |")
    said = []
    for n in names:
        mine = [by[(n, dt)] for dt in steps if (n, dt) in by]
        first = _first_within(mine, tolerance)
        rises, halvings = _rises(mine)
        text = (f"`{n}` within {100 * tolerance:g} cm from dt = {float(first['dt_s']):.3g} s "
                f"(h w_max = {float(first['dt_s']) * w_max:.2g})" if first
                else f"`{n}` never within {100 * tolerance:g} cm")
        if halvings:
            text += f", its error higher after {rises} of its {halvings} halvings"
        said.append(text)
    lines += ["", "; ".join(said) + "."]
    return "\n".join(lines)


if __name__ == "__main__":
    print(table())
