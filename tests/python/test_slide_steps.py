"""scripts/slide-steps.py: the friction scene's errors against the step, read from every
process's files of scripts/run-experiments.sh slide-steps, as experiments/README.md shows them."""
import importlib.util
import json

from conftest import ROOT

TRIES = ("k_N_per_m,n,integrator,dt_s,rtol,steps,wall_per_simulated_s,visible_error_m,finished,"
         "why\n")
ATLAS = ("k_N_per_m,n,w_max_rad_per_s,integrator,dt_s,rtol,steps,wall_per_simulated_s,"
         "visible_error_m,tried,outcome,reference_dt_s,reference_check_m\n")


def module():
    spec = importlib.util.spec_from_file_location("slide_steps", ROOT / "scripts" / "slide-steps.py")
    loaded = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(loaded)
    return loaded


def write_run(where, name, tries, cells, wall):
    (where / f"{name}_tries.csv").write_text(TRIES + "".join(tries))
    (where / f"{name}_atlas.csv").write_text(ATLAS + "".join(cells))
    (where / f"{name}.json").write_text(json.dumps({
        "commit": "abcdef0123", "date_utc": "2026-12-07T22:00:00Z", "wall_time_s": wall,
        "parameters": {"atlas": {"tolerance_m": 0.01}}}))


def test_errors_by_step_from_both_processes(tmp_path):
    slide = module()
    assert slide.table(tmp_path).startswith("Not run yet")
    # Backward Euler's error falling to the tolerance; projective's then over the budget.
    write_run(tmp_path, "newton", [
        f"10000,8,implicit,{dt},,{round(2 / dt)},1.0,{e},1,\n"
        for dt, e in ((0.02, 0.2), (0.01, 0.1), (0.005, 0.05), (0.0025, 0.008))],
        ["10000,8,1000,implicit,0.0025,,800,1.0,0.008,4,ok,1e-5,1e-4\n"], 600)
    write_run(tmp_path, "others", [
        "10000,8,projective,0.02,,100,1.0,0.3,1,\n",
        "10000,8,projective,0.01,,200,,0.3,0,budget\n"],
        ["10000,8,1000,projective,,,0,,0.3,2,budget,1e-5,1e-4\n"], 1200)
    text = slide.table(tmp_path)
    lines = text.splitlines()
    assert "w_max 1,000 rad/s" in lines[0]
    assert "commit abcdef0, 2026-12-07, 2 runs side by side, 20 min" in lines[0]
    # The integrator table's order; one row per step, largest first, h w_max beside it.
    assert lines[2] == "| dt (s) | h w_max | `implicit` | `projective` |"
    assert lines[4] == "| 0.02 | 20 | 20 | 30 |"
    assert lines[5] == "| 0.01 | 10 | 10 | over budget |"
    assert lines[7] == "| 0.0025 | 2.5 | 0.8 |  |"
    # Where each is within 1 cm, and how often a halving raised its error (none for backward
    # Euler here, its error falling steadily; projective finished one run: no halving).
    assert ("`implicit` within 1 cm from dt = 0.0025 s (h w_max = 2.5), its error higher after 0 "
            "of its 3 halvings") in lines[-1]
    assert "`projective` never within 1 cm." in lines[-1]


def test_an_error_that_rises_as_the_step_falls_is_counted(tmp_path):
    slide = module()
    write_run(tmp_path, "one", [
        f"10000,8,bdf2,{dt},,{round(2 / dt)},1.0,{e},1,\n"
        for dt, e in ((0.02, 0.1), (0.01, 0.12), (0.005, 0.03), (0.0025, 0.09))],
        ["10000,8,1000,bdf2,,,0,,0.09,4,not_reached,1e-5,1e-4\n"], 60)
    assert "`bdf2` never within 1 cm, its error higher after 2 of its 3 halvings." in (
        slide.table(tmp_path).splitlines()[-1])


def test_within_names_the_first_step_within_the_tolerance(tmp_path):
    slide = module()
    assert slide.within(tmp_path) is None
    write_run(tmp_path, "one", [
        f"10000,8,bdf2,{dt},,{round(2 / dt)},1.0,{e},1,\n"
        for dt, e in ((0.02, 0.1), (0.01, 0.005), (0.005, 0.003))],
        ["10000,8,1000,bdf2,0.01,,200,1.0,0.005,2,ok,1e-5,1e-4\n"], 60)
    smallest, found = slide.within(tmp_path)
    assert smallest == 5.0  # 0.005 s at w_max 1000 rad/s
    assert found == [("bdf2", 10.0)]
