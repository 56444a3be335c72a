#!/usr/bin/env python3
"""Newton's convergence through contact under each contact model.

Runs jello-sim on scenes that meet walls and obstacles (worlds/jello.w; the course's stiffer
world, kElastic 2e4 N/m at dt = 0.01 s, written by jello-create-world; worlds/showcase.w) under
every integrator that ends its steps in Newton's iterations, with each contact model of
src/world/contact_law.h (`--contact`, the smooth one at its default layer), and writes
experiments/results/contact_models.json: per run the steps, the steps left unconverged at the
Newton cap after the retries in half steps, the (sub-)steps retried, Newton iterations per step,
the least signed distance of any point to a solid over the run and the energy at the start and the end. The README's
contact table (scripts/results-tables.py, block contact-newton) is made from that file alone.

    scripts/contact-table.py [--bin build/native/bin]
"""
import argparse
import datetime
import json
import os
import platform
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import closed_sets  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "experiments", "results", "contact_models.json")
CONTACT_TABLE = os.path.join(ROOT, "src", "world", "contact_law.h")


def contact_models():
    """The names of JELLO_CONTACT_MODELS, in the table's order."""
    body = closed_sets._macro(CONTACT_TABLE, "JELLO_CONTACT_MODELS")
    import re
    return re.findall(r'X\(\w+,\s*"([^"]*)"', body)


def scenes(tmp, bin_dir):
    """(name, world file, steps, dt or None for the world's): the worlds the table runs. The
    showcase at 0.01 s: its cube lands on the ramp after 0.35 s and rides it."""
    course = os.path.join(tmp, "course-k2e4.w")
    subprocess.run([os.path.join(bin_dir, "jello-create-world"), "-o", course,
                    "--k-elastic", "2e4", "--dt", "0.01"], check=True, stdout=subprocess.DEVNULL)
    return [("jello.w", os.path.join(ROOT, "worlds", "jello.w"), 100, None),
            ("course, kElastic 2e4, dt 0.01", course, 200, None),
            ("showcase.w, dt 0.01", os.path.join(ROOT, "worlds", "showcase.w"), 200, 0.01)]


def run(bin_dir, world, steps, dt, integrator, model, tmp):
    stats = os.path.join(tmp, "stats.json")
    proc = subprocess.run([os.path.join(bin_dir, "jello-sim"), world, "--integrator", integrator,
                           "--contact", model, "--steps", str(steps), "--quiet",
                           *(["--dt", str(dt)] if dt else []),
                           "--stats", stats], capture_output=True, text=True)
    if proc.returncode == 1 and "barrier contact model needs" in proc.stderr:
        return {"refused": proc.stderr.strip().split(": ", 2)[-1]}
    if proc.returncode not in (0, 3):
        raise SystemExit(f"contact-table: jello-sim failed ({proc.returncode}): {proc.stderr}")
    with open(stats) as f:
        s = json.load(f)
    solver = s.get("solver", {})
    return {"steps": s["steps"], "diverged": s["diverged"],
            "unconverged_steps": int(solver.get("newton_unconverged_steps", 0)),
            "retried_steps": int(solver.get("newton_retried_steps", 0)),
            "newton_per_step": solver.get("newton_iterations_per_step", 0.0),
            "energy_start_J": s["energy_start"]["total_J"],
            "energy_end_J": s["energy_end"]["total_J"],
            "contact_layer_m": s["contact"]["layer_m"],
            "dhat_m": s["contact"]["dhat_m"], "kappa_N_per_m": s["contact"]["kappa_N_per_m"],
            "min_obstacle_distance_m": s["min_obstacle_distance_m"]}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--bin", default=os.path.join(ROOT, "build", "native", "bin"))
    args = parser.parse_args()
    newton = [r["name"] for r in closed_sets.integrators() if r["family"] == "Newton"]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for scene, world, steps, dt in scenes(tmp, args.bin):
            for integrator in newton:
                for model in contact_models():
                    print(f"{scene}: {integrator}, {model}", file=sys.stderr)
                    rows.append({"scene": scene, "integrator": integrator, "contact": model,
                                 **run(args.bin, world, steps, dt, integrator, model, tmp)})
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "HEAD"], capture_output=True,
                            text=True).stdout.strip()
    data = {"date_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
            "commit": commit, "machine": platform.node(), "bin": os.path.relpath(args.bin, ROOT),
            "runs": rows}
    tmp_out = OUT + ".tmp"
    with open(tmp_out, "w") as f:
        json.dump(data, f, indent=1)
        f.write("\n")
    os.replace(tmp_out, OUT)
    print(f"contact-table: {len(rows)} runs into {os.path.relpath(OUT, ROOT)}", file=sys.stderr)


if __name__ == "__main__":
    main()
