#!/usr/bin/env python3
"""The documents' results from the committed CSV and JSON alone (no number typed by hand):
the README's findings, CI time and contact tables (contact-newton from contact_models.json,
contact-speed from contact_speed.json: scripts/contact-table.py, scripts/contact-speed.py), and
the experiments' summaries (experiments/README.md).

Rewrites the blocks between <!-- stability-summary:begin/end --> (the stability map's measured
thresholds against their predictions, per integrator and scene, from
experiments/results/stability.csv and its sidecar) and <!-- work-precision-summary:begin/end -->
(per scene, each integrator's cheapest run within given position errors over the whole window,
from experiments/results/work_precision.csv and its sidecar), <!-- implicit-damping:... -->
<!-- scaling-summary:... --> (cost per simulated second against N, from scaling.csv) and
<!-- drift-summary:... --> (the long-run drift of energy and angular momentum per integrator,
from work_precision_drift_summary.csv), the crossover atlas's (atlas-summary and atlas-region
from every *_atlas.csv; atlas-free-summary from experiments/results/atlas_free/;
atlas-contact-summary from experiments/results/atlas_contact_*/; atlas-slide-summary, the
friction scene's, from experiments/results/atlas_slide/, and slide-steps, its implicit errors
against their step, by scripts/slide-steps.py; atlas-trace-summary, the falling
scene's visible motion over time, from experiments/results/atlas_trace/), each in the
document scripts/readme_blocks.py names. With --check it changes nothing and exits 1 when a
document differs from what the data gives (ctest runs it so).

    scripts/results-tables.py [--check]
"""
import argparse
import csv
import functools
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import closed_sets  # noqa: E402
import readme_blocks  # noqa: E402
from readme_blocks import replace_block, write_blocks  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RESULTS = os.path.join(ROOT, "experiments", "results")
README = os.path.join(ROOT, "README.md")
INTEGRATORS = {r["name"]: r for r in closed_sets.integrators()}


def explicit_first(names):
    """The explicit integrators first, the most stable first (the table's explicit rows
    reversed: rk4, symplectic, euler), then the others in the given order."""
    explicit = [n for n in names if INTEGRATORS[n]["explicit"]]
    return explicit[::-1] + [n for n in names if not INTEGRATORS[n]["explicit"]]


# The stability table's rows: the integrator table's order, explicit ones first.
ORDER = explicit_first(list(INTEGRATORS))


def read_rows(name):
    """The rows of experiments/results/NAME.csv, as dicts."""
    with open(os.path.join(RESULTS, name + ".csv"), newline="") as f:
        return list(csv.DictReader(f))


def read_sidecar(name):
    """The JSON sidecar experiments/results/NAME.json."""
    with open(os.path.join(RESULTS, name + ".json")) as f:
        return json.load(f)


def span(values, fmt="{:.2f}"):
    lo, hi = min(values), max(values)
    a, b = fmt.format(lo), fmt.format(hi)
    return a if a == b else f"{a}-{b}"


def k_text(k):
    exponent = round(__import__("math").log10(k) * 2) / 2
    return f"10^{exponent:g}"


def stability_summary():
    rows = read_rows("stability")
    sidecar = read_sidecar("stability")
    rule = sidecar["parameters"]["blow_up"]
    by = {}
    for r in rows:
        by.setdefault((r["scene"], r["integrator"]), {}).setdefault(float(r["k_N_per_m"]), {})[
            r["source"]] = r
    lines = [
        f"Blow-up rule of this run: {rule['time_s']:g} simulated s (explicit methods at least "
        f"{rule.get('explicit_min_steps', 0)} steps), energy above {rule['energy_factor']:g} "
        f"times its envelope (explicit methods: the largest of the first "
        f"{rule.get('energy_envelope_steps', 0)} steps; implicit ones and cvode: the start's), "
        f"or a point {rule['divergence_bound_m']:g} m out; bisection to "
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
            if all(points[k]["predicted"]["outcome"] == "unconditional" for k in ks):
                # Stable on the linear equation at every step, yet blew up on the scene.
                def threshold(m):
                    return ("stable to the largest dt" if m["outcome"] == "stable_to_max"
                            else f"{float(m['courant_number']):.2f}")
                detail = ", ".join(f"{k_text(k)}: {threshold(points[k]['measured'])}"
                                   for k in ks)
                blew = [float(points[k]["measured"]["courant_number"]) for k in ks
                        if points[k]["measured"]["outcome"] != "stable_to_max"]
                lines.append(f"| {scene} | {name} | none predicted; blew up past h w_max "
                             f"(k = {detail}) | {span(blew)} | none | {zeta} |")
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




def precision_labels(rows):
    """The work-precision table's rows: the studies' order (adaptive last), explicit ones first,
    an adaptive integrator once per method the data has ("cvode bdf", "cvode adams")."""
    labels = []
    for name in explicit_first(closed_sets.study_order()):
        methods = dict.fromkeys(r["cvode_method"] for r in rows if r["integrator"] == name)
        labels += [name if m == "none" else f"{name} {m}" for m in methods]
    return labels

ACCURACIES = [1e-2, 1e-3, 1e-4, 1e-6]  # m, largest position error over the window


def seconds(t):
    return f"{t * 1e3:.3g} ms" if t < 1 else f"{t:.3g} s"


def work_precision_summary():
    rows = [r for r in read_rows("work_precision") if r["outcome"] == "ok"]
    sidecar = read_sidecar("work_precision")
    params = sidecar["parameters"]
    lines = [
        f"Errors sampled every {params['sample_interval_s']:g} s against the reference; wall "
        f"time of the steps, median of {params['repeats']} runs (set-up apart); commit "
        f"{sidecar['commit'][:7]}{' (modified tree)' if sidecar.get('tree_modified') else ''}, "
        f"{sidecar['date_utc'][:10]}, {params['jobs']} runs at a time.", ""]
    for scene in params["scenes"]:
        name = scene["scene"]
        lines += [f"**{name}**: {scene['description']}; w_max {scene['w_max_rad_per_s']:,.0f} "
                  f"rad/s; the reference (RK4 at dt = {scene['reference_dt_s']:.2g} s) within "
                  f"{scene['reference_vs_twice_its_step_m']:.1e} m of RK4 at twice its step "
                  "(accuracies below 10 times that are beyond the reference).",
                  "",
                  "| integrator | " + " | ".join(f"max error <= {a:g} m" for a in ACCURACIES)
                  + " | smallest error reached |",
                  "|---|" + "---|" * (len(ACCURACIES) + 1)]
        best = {}
        for label in precision_labels(rows):
            integ, _, method = label.partition(" ")
            runs = [r for r in rows if r["scene"] == name and r["integrator"] == integ
                    and (r["cvode_method"] == (method or "none"))]
            if not runs:
                continue
            cells = []
            for a in ACCURACIES:
                if a < 10 * scene["reference_vs_twice_its_step_m"]:
                    cells.append("beyond the reference")
                    continue
                ok = [r for r in runs if float(r["position_error_max_m"]) <= a]
                if not ok:
                    cells.append("not reached")
                    continue
                r = min(ok, key=lambda r: float(r["wall_time_s"]))
                setting = (f"rtol {float(r['rtol']):g}" if INTEGRATORS[integ]["adaptive"]
                           else f"dt {float(r['dt_s']):.3g}")
                cells.append(f"{seconds(float(r['wall_time_s']))} ({setting})")
                best.setdefault(a, []).append((float(r["wall_time_s"]), label))
            smallest = min(float(r["position_error_max_m"]) for r in runs)
            lines.append(f"| {label} | " + " | ".join(cells) + f" | {smallest:.1e} m |")
        winners = []
        for a in ACCURACIES:
            if a in best:
                ranked = sorted(best[a])
                text = f"{ranked[0][1]} at {a:g} m"
                rk4 = [t for t, n in ranked if n == "rk4"]
                if ranked[0][1] != "rk4" and rk4:
                    text += f" ({rk4[0] / ranked[0][0]:.1f}x faster than rk4)"
                winners.append(text)
        lines += ["", "Cheapest: " + "; ".join(winners) + ".", ""]
    return "\n".join(lines).rstrip()


def implicit_damping():
    rows = sorted((r for r in read_rows("work_precision_damping")
                   if r["integrator"] == "implicit"), key=lambda r: float(r["dt_s"]))
    span_s = read_sidecar("work_precision")["parameters"]["damping_scene"]["time_s"]

    def lost(r):
        return 100 * (1 - float(r["energy_end_J"]) / float(r["energy_start_J"]))

    small, large = rows[0], rows[-1]
    rates = [float(r["energy_decay_rate_per_s"]) for r in rows]
    peak = max(rows, key=lambda r: float(r["energy_decay_rate_per_s"]))
    return (f"Over the first {span_s:g} s the implicit step removes {lost(small):.4g}% of the "
            f"vibration energy at its smallest step (dt = {float(small['dt_s']):.2g} s, h w_max = "
            f"{float(small['h_w_max']):.2g}) and {lost(large):.4g}% at its largest (dt = "
            f"{float(large['dt_s']):.2g} s, h w_max = {float(large['h_w_max']):,.0f}): decay "
            f"rates ln(E0/E)/T from {min(rates):,.0f} to {max(rates):,.0f} per second, the "
            f"fastest at dt = {float(peak['dt_s']):.2g} s (h w_max = "
            f"{float(peak['h_w_max']):.2g}).")


def drift_summary():
    rows = read_rows("work_precision_drift_summary")
    sidecar = read_sidecar("work_precision")
    scene = sidecar["parameters"]["drift_scene"]
    lines = [f"Undamped cube, k = {scene['k_N_per_m']:g} N/m, {scene['time_s']:g} s, sampled "
             f"every {scene['sample_interval_s']:g} s; commit {sidecar['commit'][:7]}, "
             f"{sidecar['date_utc'][:10]}.", "",
             "| integrator | dt (s) | h w_max | E/E0 at the end | max \|E/E0 - 1\|, first half "
             "| same, second half | max \|L - L0\| / \|L0\| | wall time |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r["outcome"] != "ok":
            lines.append(f"| {r['integrator']} | {float(r['dt_s']):.3g} | "
                         f"{float(r['h_w_max']):.3g} | {r['outcome']} at t = "
                         f"{float(r['diverged_at_s']):.3g} s | | | | |")
            continue
        lines.append(f"| {r['integrator']} | {float(r['dt_s']):.3g} | {float(r['h_w_max']):.3g} | "
                     f"{float(r['energy_ratio_end']):.4g} | "
                     f"{float(r['energy_deviation_max_first_half']):.2g} | "
                     f"{float(r['energy_deviation_max_second_half']):.2g} | "
                     f"{float(r['angular_momentum_error_max']):.2g} | "
                     f"{seconds(float(r['wall_time_s']))} |")
    return "\n".join(lines)


def scaling_summary():
    rows = read_rows("scaling")
    sidecar = read_sidecar("scaling")
    cost = {(int(r["n"]), r["integrator"], r["linear_solver"]): r for r in rows}
    ns = sorted({int(r["n"]) for r in rows})
    # A column per (integrator, linear solver) the data has, in ORDER and the solvers' table's.
    solvers = ["none"] + [r["name"] for r in closed_sets.linear_solvers()]
    columns = [(integ, solver, integ if solver == "none" else f"{integ}, {solver.upper()}")
               for integ in ORDER for solver in solvers
               if any((n, integ, solver) in cost for n in ns)]

    def per_s(r):
        return float(r["wall_per_simulated_s"])

    def fmt(v):
        return f"{v:,.3g}" if v < 1000 else f"{v:,.0f}"

    lines = [f"Wall seconds per simulated second; commit {sidecar['commit'][:7]}"
             f"{' (modified tree)' if sidecar.get('tree_modified') else ''}, "
             f"{sidecar['date_utc'][:10]}, one point at a time. In brackets: the share of "
             "CHOLMOD's factorizations in the implicit step.", "",
             "| N | " + " | ".join(c[2] for c in columns) + " |",
             "|---|" + "---|" * len(columns)]
    for n in ns:
        cells = []
        for integ, solver, _ in columns:
            r = cost.get((n, integ, solver))
            if r is None:
                cells.append("not run")
                continue
            text = fmt(per_s(r))
            if integ == "implicit" and solver == "cholmod":
                text += f" ({100 * float(r['factor_per_simulated_s']) / per_s(r):.0f}%)"
            cells.append(text)
        lines.append(f"| {n} | " + " | ".join(cells) + " |")
    lo, hi = ns[0], ns[-1]
    rk4 = per_s(cost[(hi, "rk4", "none")]) / per_s(cost[(lo, "rk4", "none")])
    ratio = [per_s(cost[(n, "implicit", "cholmod")]) / per_s(cost[(n, "implicit", "cg")])
             for n in ns if (n, "implicit", "cholmod") in cost and (n, "implicit", "cg") in cost]
    wmax = [float(r["w_max_rad_per_s"]) for r in rows]
    lines += ["", f"From N = {lo} to {hi} (springs x{(hi / lo) ** 3:,.0f}) RK4's cost grows "
                  f"x{rk4:,.0f}; CG keeps the implicit step {min(ratio):.2g}-{max(ratio):.2g}x "
                  f"cheaper than CHOLMOD; w_max stays {min(wmax):,.0f}-{max(wmax):,.0f} rad/s "
                  "at every N."]
    return "\n".join(lines)


# The free scene's atlas (jello-scaling --atlas-scene free) has its own directory.
ATLAS_FREE = "atlas_free"
# The falling scene with stiffer floors (jello-scaling --atlas-contact; run-experiments.sh
# atlas-contact), by setting: the subdirectory each one's runs are in.
ATLAS_CONTACT = {"k": "atlas_contact_k", "20k": "atlas_contact_20k",
                 "barrier": "atlas_contact_barrier"}
FLOOR_WORDS = {"k": "as stiff as the springs (kCollision = k)",
               "20k": "20 times stiffer than the springs (kCollision = 20 k)",
               "barrier": "a log barrier (kappa = k, dhat 5 mm: no point crosses it)"}


def atlas_ran(subdirectory):
    """True when a subdirectory of the results holds an atlas."""
    directory = os.path.join(RESULTS, subdirectory)
    return os.path.isdir(directory) and any(f.endswith("_atlas.csv") for f in os.listdir(directory))


def stiff_floors():
    """Where implicit pays on the stiffer floors that have run (for the findings), or ""."""
    said = []
    for setting, subdirectory in ATLAS_CONTACT.items():
        if not atlas_ran(subdirectory):
            continue
        pays = atlas_pays(subdirectory)
        by_n = atlas_sources(subdirectory)
        tolerance = next(iter(by_n.values()))[1][0]["parameters"]["atlas"]["tolerance_m"]
        # Where RK4 at twice the reference's step is more than half the tolerance away, the
        # cells' verdicts are not to be trusted.
        uncertain = sorted({float(r["k_N_per_m"]) for rows, _ in by_n.values() for r in rows
                            if float(r["reference_check_m"]) > 0.5 * tolerance})
        said.append(f"with the floor {FLOOR_WORDS[setting]}, " + (
            "at " + "; ".join(f"N = {n}, k = {k_text(k)} ({name}, {x:.2g}x)"
                              for n, k, name, x in pays) if pays else "nowhere") +
            f" (N = {', '.join(str(n) for n in sorted(by_n))}" +
            (f"; its RK4 references are not converged to the tolerance from k = "
             f"{k_text(uncertain[0])}" if uncertain else "") + ")")
    return "; " + "; ".join(said) if said else ""


def atlas_contact_summary():
    """The falling scene's atlas per stiffer floor, each as atlas_summary writes it; a floor
    not run yet says so."""
    parts = []
    for setting, subdirectory in ATLAS_CONTACT.items():
        ran = atlas_ran(subdirectory)
        parts.append(f"**The floor {FLOOR_WORDS[setting]}** (`experiments/results/{subdirectory}/`): "
                     + ("\n\n" + atlas_summary(subdirectory) if ran else
                        "not run yet (`scripts/run-experiments.sh atlas-contact`)."))
    return "\n\n".join(parts)


# The friction scene's atlas (jello-scaling --atlas-scene slide; run-experiments.sh atlas-slide).
ATLAS_SLIDE = "atlas_slide"
# The methods that are neither explicit nor adaptive, in the table's order.
FIXED_STEP_IMPLICIT = [name for name in ORDER if not INTEGRATORS[name]["explicit"]
                       and not INTEGRATORS[name]["adaptive"]]


def atlas_every_integrator(subdirectory):
    """Every integrator's outcome at every (N, k) of an atlas: its cost and step where it kept
    the visible motion, else why not, with the error of the smallest step it finished."""
    by_n = atlas_sources(subdirectory)
    columns = [(n, k) for n in sorted(by_n)
               for k in sorted({float(r["k_N_per_m"]) for r in by_n[n][0]})]
    rows = {(int(r["n"]), float(r["k_N_per_m"]), r["integrator"]): r
            for n in by_n for r in by_n[n][0]}

    def cell(r):
        if r is None:
            return ""
        if r["outcome"] == "ok":
            step = (f"rtol {float(r['rtol']):.0e}" if INTEGRATORS[r["integrator"]]["adaptive"]
                    else f"dt {float(r['dt_s']):.3g}")
            return f"{seconds(float(r['wall_per_simulated_s']))} ({step})"
        error = float(r["visible_error_m"])
        last = "" if error != error else f", {100 * error:.2g} cm at its last step"
        return {"not_reached": "not within the tolerance", "budget": "over budget",
                "never_stable": "never stable", "no_reference": "no reference"}.get(
                    r["outcome"], r["outcome"]) + last

    lines = ["| integrator | " + " | ".join(f"N = {n}, k = {k_text(k)}" for n, k in columns)
             + " |", "|---|" + "---|" * len(columns)]
    for name in ORDER:
        if any((n, k, name) in rows for n, k in columns):
            lines.append(f"| `{name}` | " + " | ".join(cell(rows.get((n, k, name)))
                                                      for n, k in columns) + " |")
    return "\n".join(lines)


def slide_finding():
    """Where implicit pays on the friction scene, for the findings; "" when it has not run."""
    if not atlas_ran(ATLAS_SLIDE):
        return ""
    by_n = atlas_sources(ATLAS_SLIDE)
    cells = []
    for n in sorted(by_n):
        rows = by_n[n][0]
        for k in sorted({float(r["k_N_per_m"]) for r in rows}):
            here = [r for r in rows if float(r["k_N_per_m"]) == k]
            best = atlas_cheapest(here)
            cells.append(f"N = {n}, k = {k_text(k)}: " +
                         (f"{best['integrator']} ({seconds(float(best['wall_per_simulated_s']))})"
                          if best else "none within the budget"))
    fixed = FIXED_STEP_IMPLICIT
    outcomes = {name: {r["outcome"] for rows, _ in by_n.values() for r in rows
                       if r["integrator"] == name} for name in fixed}
    missed = [name for name in fixed if "ok" not in outcomes[name]
              and "not_reached" in outcomes[name]]
    over = [name for name in fixed if "ok" not in outcomes[name] and name not in missed]
    atlas = next(iter(by_n.values()))[1][0]["parameters"]["atlas"]
    smallest = atlas["sample_interval_s"] / 2 ** (atlas["steps_tried"] - 1)
    said = []
    if missed:
        said.append(f"{', '.join(missed)} miss it by more than 1 cm at every step they finished "
                    f"within the budget, down to dt = {smallest:.2g} s")
    if over:
        said.append(f"{', '.join(over)} {'runs' if len(over) == 1 else 'run'} over the budget "
                    "before keeping it")
    steps = _script("slide-steps").within()
    if steps and steps[1]:
        said.append("with steps that resolve static friction (N = 8, k = 10^4, down to h w_max = "
                    f"{steps[0]:.2g}) " + " and ".join(f"{name} from h w_max = {hw:.2g}"
                                                       for name, hw in steps[1])
                    + " keep it within 1 cm, experiments/README.md shows why")
    return ("; sliding to rest on an incline with friction (mu = 0.6) the cheapest within 1 cm is "
            + "; ".join(cells) + (" (" + "; ".join(said) + ")" if said else ""))


def atlas_slide_summary():
    """The friction scene's atlas: the summary and every integrator's cell; or not run yet."""
    if not atlas_ran(ATLAS_SLIDE):
        return "Not run yet (`scripts/run-experiments.sh atlas-slide`)."
    return (atlas_summary(ATLAS_SLIDE) + "\n\nEvery integrator (wall time per simulated second "
            "at its largest step within the tolerance; dt or rtol in brackets):\n\n"
            + atlas_every_integrator(ATLAS_SLIDE))


# The falling scene's visible motion over time (jello-scaling --atlas-trace; run-experiments.sh
# atlas-trace).
ATLAS_TRACE = "atlas_trace"
# The reference and the fixed-step implicit methods (the explicit ones' largest step is their
# stability limit's, and cvode's its loosest tolerance: neither is what the atlas's misses are).
TRACED = ["reference"] + FIXED_STEP_IMPLICIT


def atlas_trace_summary():
    """Per N: the reference's and a few methods' (at their largest step) least height of the
    cube, lowest centre and rebound after it, and largest corner distance from the reference."""
    path = os.path.join(RESULTS, ATLAS_TRACE, "scaling_trace.csv")
    if not os.path.exists(path):
        return "Not run yet (`scripts/run-experiments.sh atlas-trace`)."
    with open(path) as f:
        rows = list(csv.DictReader(f))
    sidecar = read_sidecar(os.path.join(ATLAS_TRACE, "scaling"))
    lines = [f"k = {k_text(float(rows[0]['k_N_per_m']))} (commit {sidecar['commit'][:7]}, "
             f"{sidecar['date_utc'][:10]}, {sidecar['wall_time_s'] / 60:.0f} min):", "",
             "| N | run | step | least height of the cube (m) | lowest centre (m), at t (s) | "
             "highest centre after it (m) | largest corner distance from the reference (m), at "
             "t (s) | last t reached (s) |",
             "|---|---|---|---|---|---|---|---|"]
    for n in sorted({int(r["n"]) for r in rows}):
        for name in TRACED:
            mine = [r for r in rows if int(r["n"]) == n and r["integrator"] == name]
            if not mine:
                continue
            flat = min(float(r["height_m"]) for r in mine)
            low = min(mine, key=lambda r: float(r["centre_z_m"]))
            after = [float(r["centre_z_m"]) for r in mine if float(r["t_s"]) > float(low["t_s"])]
            rebound = f"{max(after):.3f}" if after else ""
            far = max(mine, key=lambda r: float(r["corner_distance_m"]))
            step = f"dt {float(mine[0]['dt_s']):.3g}"
            miss = ("" if name == "reference" else
                    f"{float(far['corner_distance_m']):.3g}, {float(far['t_s']):.2f}")
            lines.append(f"| {n} | {name} | {step} | {flat:.3f} | {float(low['centre_z_m']):.3f}, "
                         f"{float(low['t_s']):.2f} | {rebound} | {miss} | "
                         f"{float(mine[-1]['t_s']):.2f} |")
    return "\n".join(lines)


@functools.lru_cache(maxsize=None)
def atlas_sources(subdirectory=""):
    """Every committed atlas of a scene: (rows, sidecars) of scaling_atlas.csv (jello-scaling's
    full run) and of each NAME_atlas.csv an atlas-only run wrote (NAME.json its sidecar), by N,
    from experiments/results (the falling scene) or a subdirectory of it (ATLAS_FREE). One N may
    come from several runs over different k (N = 32's stiffest point was run apart): its
    sidecars in file order; a (k, N) in two files is an error. Read once (several blocks use
    it); not to be modified."""
    directory = os.path.join(RESULTS, subdirectory)
    names = sorted(f[:-len("_atlas.csv")] for f in os.listdir(directory)
                   if f.endswith("_atlas.csv"))
    by_n = {}
    for name in names:
        sidecar = read_sidecar(os.path.join(subdirectory, name))
        rows = read_rows(os.path.join(subdirectory, name + "_atlas"))
        for n in sorted({int(r["n"]) for r in rows}):
            mine = [r for r in rows if int(r["n"]) == n]
            have, sidecars = by_n.setdefault(n, ([], []))
            twice = {r["k_N_per_m"] for r in have} & {r["k_N_per_m"] for r in mine}
            if twice:
                raise SystemExit(f"results-tables: the atlas at N = {n}, k = "
                                 f"{', '.join(sorted(twice))} is in two files")
            have.extend(mine)
            sidecars.append(sidecar)
    return by_n


def atlas_run_text(sidecar, ks):
    """Commit, date and run time of one atlas run, with its k when an N has several runs."""
    return (f"commit {sidecar['commit'][:7]}"
            f"{' (modified tree)' if sidecar.get('tree_modified') else ''}, "
            f"{sidecar['date_utc'][:10]}, {sidecar['wall_time_s'] / 60:.0f} min"
            f"{' with the resolution grid' if sidecar['parameters']['n'] else ''}"
            f"{machine_text(sidecar)}"
            + (f" for k = {', '.join(k_text(k) for k in ks)}" if ks else ""))


def machine_text(sidecar):
    """The machine's calibration a sidecar holds: one force evaluation of the 8^3 cube."""
    machine = sidecar.get("machine", {})
    t = machine.get("force_evaluation_8_s")
    level = f" ({machine['vector_level']})" if "vector_level" in machine else ""
    return f", a force evaluation at N = 8 {t * 1e6:.2g} us{level}" if t else ""


def machine_spread(subdirectory=""):
    """The sentence saying how far the machines of an atlas's runs differ, when by 2x or more
    (an explicit method's cost is force evaluations; a crossover between two runs' cells is then
    partly the machines'); "" otherwise."""
    times = {}
    for n, (_, sidecars) in atlas_sources(subdirectory).items():
        for sidecar in sidecars:
            t = sidecar.get("machine", {}).get("force_evaluation_8_s")
            if t:
                times.setdefault(n, []).append(t)
    if not times:
        return ""
    every = [t for ts in times.values() for t in ts]
    if max(every) < 2 * min(every):
        return ""
    return ("The runs' machines differ: a force evaluation at N = 8 took " + "; ".join(
        f"{span([t * 1e6 for t in ts], '{:.2g}')} us in N = {n}'s" for n, ts in sorted(times.items()))
        + f" (each sidecar's `machine`), {max(every) / min(every):.2g}x from the fastest to the "
        "slowest. An explicit method's cost is its force evaluations, so a comparison of cells "
        "made on different machines (the region table's columns) is partly the machines'.")


ATLAS_EXPLICIT = {name for name, r in INTEGRATORS.items() if r["explicit"]}


def atlas_cheapest(rows, explicit=None):
    """The cheapest run within the tolerance among rows (explicit: only explicit methods, or
    only the others; None: all)."""
    ok = [r for r in rows if r["outcome"] == "ok" and
          (explicit is None or (r["integrator"] in ATLAS_EXPLICIT) == explicit)]
    return min(ok, key=lambda r: float(r["wall_per_simulated_s"]), default=None)


def atlas_pays(subdirectory=""):
    """(N, k, integrator, speed-up) wherever an implicit or adaptive method keeps the visible
    motion for less than the cheapest explicit one, in order of N and k."""
    pays = []
    for n, (rows, _) in sorted(atlas_sources(subdirectory).items()):
        for k in sorted({float(r["k_N_per_m"]) for r in rows}):
            here = [r for r in rows if float(r["k_N_per_m"]) == k]
            e, o = atlas_cheapest(here, True), atlas_cheapest(here, False)
            if e and o:
                x = float(e["wall_per_simulated_s"]) / float(o["wall_per_simulated_s"])
                if x >= 1:
                    pays.append((n, k, o["integrator"], x))
    return pays


def atlas_alone(subdirectory=""):
    """(N, k, integrator) wherever no explicit method kept the visible motion within the budget
    and another did (the cheapest of those), in order of N and k."""
    alone = []
    for n, (rows, _) in sorted(atlas_sources(subdirectory).items()):
        for k in sorted({float(r["k_N_per_m"]) for r in rows}):
            here = [r for r in rows if float(r["k_N_per_m"]) == k]
            o = atlas_cheapest(here, False)
            if o and not atlas_cheapest(here, True):
                alone.append((n, k, o["integrator"]))
    return alone


def atlas_summary(subdirectory=""):
    by_n = atlas_sources(subdirectory)
    first = next(iter(by_n.values()))[1][0]["parameters"]["atlas"]
    checks = [float(r["reference_check_m"]) for rows, _ in by_n.values() for r in rows
              if r["outcome"] != "no_reference"]
    lines = [f"Visible motion within {100 * first['tolerance_m']:g} cm at the corners over "
             f"{first['time_s']:g} s; the references within {1e3 * min(checks):.2g}-"
             f"{1e3 * max(checks):.2g} mm of RK4 at twice their step.", ""]
    for n in sorted(by_n):
        rows, sidecars = by_n[n]
        budgets = sorted({s["parameters"]["atlas"]["run_budget_s"] for s in sidecars})
        runs = "; ".join(atlas_run_text(
            s, sorted({float(r["k_N_per_m"]) for r in rows if float(r["k_N_per_m"]) in
                       s["parameters"]["atlas"]["k_N_per_m"]}) if len(sidecars) > 1 else None)
            for s in sidecars)
        lines += [f"**N = {n}** (wall time per simulated second; dt of the run in brackets; "
                  f"budget {' and '.join(f'{b:g}' for b in budgets)} s a run; {runs})", "",
                  "| k (N/m) | w_max (rad/s) | cheapest explicit | cheapest other | "
                  "other vs explicit | not reached or over budget |",
                  "|---|---|---|---|---|---|"]
        for k in sorted({float(r["k_N_per_m"]) for r in rows}):
            here = [r for r in rows if float(r["k_N_per_m"]) == k]

            def text(r):
                if r is None:
                    return "none"
                step = (f"rtol {float(r['rtol']):.0e}" if INTEGRATORS[r["integrator"]]["adaptive"]
                        else f"dt {float(r['dt_s']):.3g}")
                return f"{r['integrator']} {seconds(float(r['wall_per_simulated_s']))} ({step})"

            e, o = atlas_cheapest(here, True), atlas_cheapest(here, False)
            ratio = ""
            if e and o:
                x = float(e["wall_per_simulated_s"]) / float(o["wall_per_simulated_s"])
                ratio = f"{x:.2g}x faster" if x >= 1 else f"{1 / x:.2g}x slower"
            referenced = [float(r["reference_check_m"]) for r in here
                          if r["outcome"] != "no_reference"]
            check = max(referenced, default=None)
            uncertain = (" (no reference: RK4 failed at every step tried)" if check is None else
                         f" (reference within {1e3 * check:.2g} mm only)"
                         if check > 0.5 * first["tolerance_m"] else "")
            missing = ("" if check is None else
                       ", ".join(sorted(r["integrator"] + ("" if r["outcome"] == "not_reached"
                                                           else f" ({r['outcome']})")
                                        for r in here if r["outcome"] != "ok")))
            lines.append(f"| {k_text(k)}{uncertain} | {float(here[0]['w_max_rad_per_s']):,.0f} | {text(e)} | "
                         f"{text(o)} | {ratio} | {missing} |")
        lines.append("")
    pays = atlas_pays(subdirectory)
    if pays:
        lines.append("Where an implicit or adaptive method is cheapest: " + "; ".join(
            f"N = {n}, k = {k_text(k)}: {name}, {x:.2g}x faster than the cheapest explicit method"
            for n, k, name, x in pays) + ".")
    alone = [f"N = {n}, k = {k_text(k)}: {name}" for n, k, name in atlas_alone(subdirectory)]
    if alone:
        lines.append("Where no explicit method keeps it within the budget and another does: "
                     + "; ".join(alone) + ".")
    if not pays and not alone:
        lines.append("At no point is an implicit or adaptive method cheaper than the cheapest "
                     "explicit one.")
    spread = machine_spread(subdirectory)
    if spread:
        lines += ["", spread]
    return "\n".join(lines)


def atlas_region():
    """The cheapest method at each (k, N) of the atlas, with its cost; a blank: not run."""
    by_n = atlas_sources()
    ns = sorted(by_n)
    ks = sorted({float(r["k_N_per_m"]) for rows, _ in by_n.values() for r in rows})
    lines = ["| k (N/m) | " + " | ".join(f"N = {n}" for n in ns) + " |",
             "|---|" + "---|" * len(ns)]
    for k in ks:
        cells = []
        for n in ns:
            here = [r for r in by_n[n][0] if float(r["k_N_per_m"]) == k]
            best = atlas_cheapest(here)
            if not here:
                cells.append("not run")
            elif best is None:
                budget = by_n[n][1][0]["parameters"]["atlas"]["run_budget_s"]
                cells.append(f"none within {budget:g} s")
            else:
                cells.append(f"{best['integrator']} "
                             f"{seconds(float(best['wall_per_simulated_s']))}")
        lines.append(f"| {k_text(k)} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def experiments_runtime():
    parts = []
    for name in ("stability", "work_precision", "scaling"):
        sidecar = read_sidecar(name)
        parts.append((name.replace("_", "-"), sidecar["wall_time_s"],
                      sidecar["parameters"]["jobs"]))
    total = sum(t for _, t, _ in parts)
    each = ", ".join(f"jello-{n} {t / 60:.1f} min on {j} thread{'s' if j > 1 else ''}"
                     for n, t, j in parts)
    text = (f"The committed results took {total / 60:.0f} minutes of wall time to make on 2-core "
            f"VMs ({each}; each sidecar's `wall_time_s`, machine and date).")
    # The atlas-only runs (scripts/run-experiments.sh atlas), one or more per N: (N, the run's
    # k when N has several, minutes, a note on its references).
    # A run whose references are kept in a directory (--atlas-references; read from there when
    # found, so its time may not include them) or computed on threads of their own says so.
    def reference_note(sidecar):
        atlas = sidecar["parameters"]["atlas"]
        where, count = atlas.get("reference_dir", ""), atlas.get("reference_threads", 0)
        if not where:
            return f" (its reference on {count} threads)" if count > 1 else ""
        return (f" (its reference kept in `{where}`, read from there when found"
                + (f", else computed on {count} threads" if count > 1 else "") + ")")

    extra = [(n, sidecar["parameters"]["atlas"]["k_N_per_m"] if len(sidecars) > 1 else None,
              sidecar["wall_time_s"] / 60, reference_note(sidecar))
             for n, (_, sidecars) in sorted(atlas_sources().items()) for sidecar in sidecars
             if not sidecar["parameters"]["n"]]
    if extra:
        def which(n, ks):
            if not ks:
                return f"N = {n}"
            span = k_text(ks[0]) + ("" if len(ks) == 1 else f" to {k_text(ks[-1])}")
            return f"N = {n} at k = {span}"
        text += (" The atlas at " + " and ".join(which(n, ks) for n, ks, _, _ in extra) +
                 " took " + " and ".join(
                     f"{t:.0f} min{r}" for _, _, t, r in extra) +
                 (", the timed runs" if any(r for *_, r in extra) else ",") +
                 " each on one core of the same machine.")
    free = sorted((n, sidecar["wall_time_s"], sidecar["parameters"]["jobs"],
                   reference_note(sidecar))
                  for n, (_, sidecars) in atlas_sources(ATLAS_FREE).items()
                  for sidecar in sidecars)
    if free:
        text += (" The free scene's atlas at " + " and ".join(f"N = {n}" for n, *_ in free) +
                 " took " + " and ".join(
                     f"{t / 60:.0f} min on {'one core' if j == 1 else f'{j} cores'}{note}"
                     for _, t, j, note in free) + ".")
    return text


def cheapest_by_accuracy(scene_name):
    """{accuracy (m): (wall time (s), label)} of the cheapest run keeping the position error
    within it, on one work-precision scene (accuracies the reference resolves)."""
    rows = [r for r in read_rows("work_precision") if r["outcome"] == "ok"]
    scene = next(s for s in read_sidecar("work_precision")["parameters"]["scenes"]
                 if s["scene"] == scene_name)
    best = {}
    for label in precision_labels(rows):
        integ, _, method = label.partition(" ")
        runs = [r for r in rows if r["scene"] == scene_name and r["integrator"] == integ
                and r["cvode_method"] == (method or "none")]
        for a in ACCURACIES:
            ok = [float(r["wall_time_s"]) for r in runs if float(r["position_error_max_m"]) <= a]
            if ok and a >= 10 * scene["reference_vs_twice_its_step_m"]:
                best[a] = min(best.get(a, (float("inf"), "")), (min(ok), label))
    return best


def crossover_ms():
    """{(method, exponent of k): wall ms per simulated second} of BM_Crossover's medians."""
    with open(os.path.join(RESULTS, "crossover.json")) as f:
        data = json.load(f)
    unit = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}
    return {tuple(b["name"].split("/")[1:3]): b["real_time"] * unit[b["time_unit"]]
            for b in data["benchmarks"]
            if b.get("aggregate_name") == "median" and b["name"].startswith("BM_Crossover/")}


def findings():
    """The README's findings, five paragraphs, every figure from the committed results."""
    rows = [r for r in read_rows("stability") if r["scene"] == "free"]
    by = {}
    for r in rows:
        by.setdefault(r["integrator"], {}).setdefault(float(r["k_N_per_m"]), {})[r["source"]] = r
    limits = []
    for name in ORDER:
        points = by.get(name, {})
        if not INTEGRATORS[name]["explicit"] or not points:
            continue
        ratio = {k: float(p["measured"]["dt_s"]) / float(p["predicted"]["dt_s"])
                 for k, p in points.items() if float(p["predicted"]["dt_s"]) > 0}
        if max(ratio.values()) <= 1.1:
            limits.append(f"{name} at {span(list(ratio.values()))} of its predicted step")
        else:  # within 10% only from some k on: there the prediction holds
            ks = sorted(ratio)
            start = next(k for i, k in enumerate(ks) if all(ratio[q] <= 1.1 for q in ks[i:]))
            limits.append(f"{name} at its damping limit h = c/k from k = {k_text(start)} up "
                          "(below, its slow growth outlasts the run)")
    stable = [n for n in ORDER if not INTEGRATORS[n]["explicit"] and by.get(n) and
              all(p["measured"]["outcome"] == "stable_to_max" for p in by[n].values())]
    unstable = [n for n in ORDER if not INTEGRATORS[n]["explicit"] and by.get(n) and n not in stable]
    dt_max = max(float(p["measured"]["dt_s"]) for n in stable for p in by[n].values())
    blew = "; ".join(
        f"{n} blew up past h w_max {span([float(p['measured']['courant_number']) for p in by[n].values() if p['measured']['outcome'] != 'stable_to_max'])}"
        for n in unstable)
    ks = sorted({float(r["k_N_per_m"]) for r in rows})
    first = (f"**Where each integrator blows up**: the explicit ones where linear stability "
             f"predicts ({'; '.join(limits)}; the free cube, k = {k_text(ks[0])} to "
             f"{k_text(ks[-1])} N/m); every other method survived every step tried up to "
             f"dt = {dt_max:g} s"
             + (f", except that {blew} on the free cube, whose corner is pulled a whole "
                "spacing: a nonlinear instability the linear prediction cannot see"
                if unstable else "") + ".")
    soft = cheapest_by_accuracy("soft")
    coarse, fine = soft[1e-2], soft[1e-3]
    rk4 = {a: t for a, (t, lab) in soft.items() if lab == "rk4"}
    damping = implicit_damping_loss()
    wp = [r for r in read_rows("work_precision") if r["outcome"] == "ok" and r["scene"] == "soft"]
    first_order = [n for n in closed_sets.study_order()
                   if INTEGRATORS[n]["linear_model"] == "BackwardEuler"]
    closest = min(float(r["position_error_max_m"]) for r in wp if r["integrator"] in first_order)
    second = (f"**What accuracy costs**: through jello.w's first contact the cheapest way to "
              f"1 cm is {coarse[1]} ({seconds(coarse[0])} of wall time), to 1 mm {fine[1]} "
              f"({seconds(fine[0])}); the first-order implicit methods come no closer than "
              f"{closest:.2g} m at any step tried, their artificial damping's price (backward "
              f"Euler removes {damping[1]:.4g}% of an undamped stiff cube's vibration energy in "
              f"{damping[2]:g} s even at h w_max = {damping[0]:.2g}).")
    free = atlas_pays(ATLAS_FREE)
    falling = atlas_pays()
    free8 = [p for p in free if p[0] == min(q[0] for q in free)]
    third = (f"**Where implicit integration pays**: in free flight from k = {k_text(free8[0][1])} "
             f"at N = {free8[0][0]} ({free8[0][2]}, {free8[0][3]:.2g}x faster than the cheapest "
             f"explicit method; {free8[-1][3]:.2g}x at k = {k_text(free8[-1][1])})"
             + "".join(f"; at N = {n} at " + ", ".join(
                 f"k = {k_text(k)} ({name}, {x:.2g}x)" for m, k, name, x in free if m == n)
                 for n in sorted({p[0] for p in free} - {free8[0][0]}))
             + "".join(f"; at N = {n}, k = {k_text(k)} no explicit method keeps it within the "
                       f"budget and {name} does"
                       for n, k, name in atlas_alone(ATLAS_FREE))
             + "; once the cube "
             "falls onto the course's soft floor (400 N/m), " +
             ("only at " + "; ".join(f"N = {n}, k = {k_text(k)} ({name}, {x:.2g}x)"
                                    for n, k, name, x in falling) if falling else "nowhere") +
             " in the crossover atlas (N = 8, 16, 32; k = 10^2 to 10^8"
             + ("; its runs' machines differ, experiments/README.md says how" if machine_spread()
                else "") + ")" + stiff_floors()
             + slide_finding() + ".")
    cross = crossover_ms()
    pd = closed_sets.names("Projective")[0]  # the crossover benchmark's subject
    fourth = (f"**How fast**: projective dynamics takes a simulated second of the spinning cube "
              f"at k = 10^5 in {cross[(pd, '5')]:.3g} ms against RK4's "
              f"{cross[('rk4', '5')]:.3g} ms at its stability limit "
              f"({cross[('rk4', '5')] / cross[(pd, '5')]:.2g}x, one core, the native build)"
              + projective_32() + "; no comparison with other libraries is committed here.")
    return "\n\n".join([first, second, third, fourth, contact_finding()])


def projective_32():
    """Projective's step at 32^3 on both cores against the factor's (projective_speed.json)."""
    path = os.path.join(RESULTS, "projective_speed.json")
    if not os.path.exists(path):
        return ""
    with open(path) as f:
        m = _script("projective-speed").medians(json.load(f))
    step = {s: m[("spectral", "32", s, "2")] for s in ("0", "1")}
    faster = {s: m[("factor", "32", s, "2")] / step[s] for s in step}
    return (f"; at 32^3 its step takes {step['0']:.3g} ms on jello.w and {step['1']:.3g} ms on "
            f"the spinning cube on both cores, {faster['0']:.2g}x and {faster['1']:.2g}x faster "
            "than with the factor of its matrix in the same run")


def contact_finding():
    """What contact costs: projective's step at 16^3 per contact model (contact_speed.json), and
    backward Euler's unconverged steps per model over the contact table's scenes."""
    speed_path = os.path.join(RESULTS, "contact_speed.json")
    table_path = os.path.join(RESULTS, "contact_models.json")
    if not (os.path.exists(speed_path) and os.path.exists(table_path)):
        return "**Through contact**: not measured yet (`scripts/contact-speed.py`, `contact-table.py`)."
    with open(speed_path) as f:
        speed = json.load(f)
    pd = closed_sets.names("Projective")[0]
    # Backward Euler: the Newton family's member whose linear model is backward Euler's.
    be = next(r["name"] for r in closed_sets.integrators()
              if r["family"] == "Newton" and r["linear_model"] == "BackwardEuler")
    steps, fast = {}, {}
    for b in speed["benchmarks"]:
        parts = b["name"].split("/")
        if b.get("run_type", "iteration") != "iteration":
            continue
        if parts[1] == pd and parts[3] == "N:16":
            steps[parts[2]] = (b["real_time"], b.get("factorizations", 0))
        # Converged backward Euler in its fast configuration (ImplicitOptions::fast()), 8^3.
        if parts[1] == be + "_fast" and parts[3] == "N:8":
            fast[parts[2]] = (b["real_time"], b["newton_iterations_per_step"])
    with open(table_path) as f:
        runs = [r for r in json.load(f)["runs"] if r["integrator"] == be]
    models = list(dict.fromkeys(r["contact"] for r in runs))
    left = {m: sum(r["unconverged_steps"] for r in runs if r["contact"] == m) for m in models}
    total = {m: sum(r["steps"] for r in runs if r["contact"] == m) for m in models}
    scenes = sorted({r["scene"] for r in runs})
    most = max(f for _, f in steps.values())
    if not any(left.values()):
        newton = (f"with its retries in half steps, backward Euler leaves none of its "
                  f"{max(total.values())} steps unconverged under any model")
    else:
        newton = "backward Euler leaves " + ", ".join(
            f"{left[m]} of {total[m]} steps unconverged under {m}" for m in models)
    kept = {0: "needs no factorization (the cosine transform's bound serves)",
            1: "keeps one factorization"}
    return ("**Through contact**: projective "
            + kept.get(round(most), f"keeps at most {most:.0f} factorizations")
            + " on jello.w at 16^3, a step taking "
            + ", ".join(f"{ms:.3g} ms under {m}" for m, (ms, _) in steps.items())
            + " contact (30 steps at dt = 0.01 s, one core); converged backward Euler in its fast "
            "configuration takes, at 8^3, "
            + ", ".join(f"{ms:.3g} ms ({it:.1f} Newton iterations)" for ms, it in fast.values())
            + " a step under " + ", ".join(fast) + " contact; " + newton
            + f" over the contact table's scenes ({'; '.join(scenes)}).")


def implicit_damping_loss():
    """(h w_max, % lost, window) of backward Euler at its smallest step in the damping study."""
    rows = sorted((r for r in read_rows("work_precision_damping") if r["integrator"] == "implicit"),
                  key=lambda r: float(r["dt_s"]))
    span_s = read_sidecar("work_precision")["parameters"]["damping_scene"]["time_s"]
    r = rows[0]
    return (float(r["h_w_max"]), 100 * (1 - float(r["energy_end_J"]) / float(r["energy_start_J"])),
            span_s)


def ci_time():
    """How long CI took from a fresh clone (scripts/time-ci.sh writes ci_time.json)."""
    path = os.path.join(RESULTS, "ci_time.json")
    if not os.path.exists(path):
        return "CI's time from a fresh clone is not measured yet (`scripts/time-ci.sh`)."
    with open(path) as f:
        t = json.load(f)
    stages = ", ".join(f"{name} {seconds / 60:.1f}" for name, seconds in t["stages_s"].items()
                       if seconds >= 30)
    return (f"CI (`.ci/run`: format, layers and function-length checks, the release suite with "
            f"warnings as errors, 60 s of fuzzing, the sanitized suite) took "
            f"{t['wall_time_s'] / 60:.1f} minutes from a fresh clone on {t['machine']} "
            f"({t['date_utc'][:10]}, commit {t['commit'][:7]}, ccache {t['ccache']}); "
            f"the stages over half a minute: {stages} minutes.")


def _script(name):
    """scripts/NAME.py as a module (its name has a hyphen)."""
    import importlib.util
    spec = importlib.util.spec_from_file_location(
        name.replace("-", "_"), os.path.join(os.path.dirname(os.path.abspath(__file__)), name + ".py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def contact_cell(r):
    """One run of the contact table: unconverged (retried), Newton/step, least distance."""
    if "refused" in r:
        return "refused: a solid without an exterior distance"
    least = r["min_obstacle_distance_m"]
    cell = (f"{r['unconverged_steps']} of {r['steps']} ({r['retried_steps']}), "
            f"{r['newton_per_step']:.1f}, {least * 1000:+.3g}")
    return cell + (" (diverged)" if r["diverged"] else "")


def contact_newton():
    """Newton's unconverged steps per scene, integrator and contact model (scripts/contact-table.py)."""
    path = os.path.join(RESULTS, "contact_models.json")
    if not os.path.exists(path):
        return "Not measured yet (`scripts/contact-table.py`)."
    with open(path) as f:
        data = json.load(f)
    runs = data["runs"]
    models = list(dict.fromkeys(r["contact"] for r in runs))
    head = "| scene | integrator | " + " | ".join(models) + " |"
    lines = [head, "|---|---|" + "---|" * len(models)]
    cells = {}
    for r in runs:
        cells.setdefault((r["scene"], r["integrator"]), {})[r["contact"]] = r
    for (scene, integrator), by_model in cells.items():
        row = [contact_cell(by_model[m]) for m in models]
        lines.append(f"| {scene} | `{integrator}` | " + " | ".join(row) + " |")
    layer = next(r["contact_layer_m"] for r in runs if r["contact"] == "smooth")
    dhat = next(r["dhat_m"] for r in runs if r["contact"] == "barrier" and "dhat_m" in r)
    lines.append("")
    lines.append(f"Each cell: unconverged of steps (retried), Newton iterations per step, least "
                 f"distance to a solid in mm. The smooth model at its default layer, "
                 f"{layer * 1000:g} mm; the barrier at dhat {dhat * 1000:g} mm, kappa = "
                 f"kCollision ({data['date_utc'][:10]}, commit {data['commit'][:7]}).")
    return "\n".join(lines)


FAMILY_WORDS = {"Explicit": "explicit", "Newton": "implicit, Newton to convergence",
                "Linearized": "implicit, one linear solve a step", "Cvode": "adaptive (SUNDIALS)",
                "Projective": "implicit, prefactored local/global iterations"}
MODEL_WORDS = {"ForwardEuler": "stable only for h <= c/k", "SymplecticEuler": "h w_max < 2",
               "RungeKutta4": "h w_max <= 2 sqrt 2", "BackwardEuler": "A-stable, damps",
               "Bdf2": "A-stable, damps high modes", "Trapezoidal": "A-stable, no damping",
               "Adaptive": "error-controlled"}


def integrator_list():
    """The README's table of integrators, from the integrator table itself."""
    lines = ["| integrator | kind | on a linear mode | what it is |", "|---|---|---|---|"]
    for r in closed_sets.integrators():
        lines.append(f"| `{r['name']}` | {FAMILY_WORDS[r['family']]} | "
                     f"{MODEL_WORDS[r['linear_model']]} | {r['summary']} |")
    return "\n".join(lines)


BLOCKS = {"findings": findings,
          "integrator-list": integrator_list,
          "ci-time": ci_time,
          "contact-newton": contact_newton,
          "contact-speed": lambda: _script("contact-speed").table(),
          "projective-speed": lambda: _script("projective-speed").table(),
          "stability-summary": stability_summary,
          "scaling-summary": scaling_summary,
          "work-precision-summary": work_precision_summary,
          "implicit-damping": implicit_damping,
          "drift-summary": drift_summary,
          "atlas-summary": atlas_summary,
          "atlas-region": atlas_region,
          "atlas-free-summary": lambda: atlas_summary(ATLAS_FREE),
          "atlas-contact-summary": atlas_contact_summary,
          "atlas-slide-summary": atlas_slide_summary,
          "atlas-trace-summary": atlas_trace_summary,
          "slide-steps": lambda: _script("slide-steps").table(),
          "experiments-runtime": experiments_runtime}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true",
                        help="change nothing; exit 1 if a document disagrees with the data")
    args = parser.parse_args()
    blocks = {name: make() for name, make in BLOCKS.items()}
    if args.check:
        stale = []
        for name, body in blocks.items():
            with open(readme_blocks.document(name)) as f:
                text = f.read()
            if replace_block(text, name, body, readme_blocks.document(name)) != text:
                stale.append(f"{readme_blocks.BLOCKS[name]} ({name})")
        if stale:
            print("results-tables: these blocks disagree with experiments/results (run "
                  "scripts/results-tables.py): " + ", ".join(stale))
            sys.exit(1)
        print("results-tables: every document agrees with the data")
    else:
        write_blocks(blocks)


if __name__ == "__main__":
    main()
