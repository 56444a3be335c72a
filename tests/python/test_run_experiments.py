"""scripts/run-experiments.sh --ranks K: each program one MPI job of K ranks (issue 39, item 6),
run on the quick grids with two ranks against the programs of this build tree, and its bad
arguments."""
import csv
import json
import os
import shutil
import subprocess

import pytest

from conftest import ROOT

SCRIPT = ROOT / "scripts" / "run-experiments.sh"
QUICK = ROOT / "build" / "experiments-quick"


def run(*args, bin_dir=None):
    env = dict(os.environ)
    if bin_dir:
        env["JELLO_BIN"] = bin_dir
    env.pop("PMIX_MCA_gds", None)  # the script sets what it needs
    return subprocess.run(["bash", str(SCRIPT), *args], capture_output=True, text=True, env=env,
                          cwd=ROOT, timeout=900)


@pytest.mark.parametrize("args, message", [
    (["--ranks"], "--ranks needs the number of MPI ranks"),
    (["--ranks", "0"], "is not a number of ranks"),
    (["quick", "--ranks", "two"], "is not a number of ranks"),
    (["charts", "--ranks", "2"], "--ranks does not apply"),
    (["quick", "atlas"], "one mode at a time"),
    (["--rank", "2"], "unknown argument '--rank'"),
])
def test_bad_arguments_exit_2_naming_them(args, message):
    result = run(*args)
    assert result.returncode == 2, result.stdout + result.stderr
    assert message in result.stderr


@pytest.mark.parametrize("knob, value", [("FALL_N", "8"), ("FREE_N", "64")])
def test_an_unknown_size_exits_2_naming_it(knob, value):
    result = subprocess.run(["bash", str(SCRIPT), "atlas"], capture_output=True, text=True,
                            env={**os.environ, knob: value}, cwd=ROOT, timeout=60)
    assert result.returncode == 2, result.stdout + result.stderr
    assert f"{knob}='{value}'" in result.stderr


def test_help_names_the_ranks_option():
    result = run("--help")
    assert result.returncode == 0
    assert "--ranks K" in result.stdout and "MPI job" in result.stdout
    # The references computed apart, and the choice of N and k the long runs take.
    assert "atlas-references" in result.stdout.splitlines()[0]
    # The friction scene's errors against the step (its own mode).
    assert "slide-steps" in result.stdout.splitlines()[0]
    for knob in ("FALL_N", "FREE_K"):
        assert knob in result.stdout, knob


def test_quick_grids_as_two_rank_mpi_jobs():
    build = os.environ.get("JELLO_BUILD_DIR")
    if not build:
        pytest.skip("JELLO_BUILD_DIR is not set (run through ctest)")
    if not shutil.which("mpirun"):
        pytest.skip("no mpirun")
    shutil.rmtree(QUICK, ignore_errors=True)
    # The quick atlas's RK4 references, kept (ScalingCli.TheKeptQuickReferencesAreTodaysScenes
    # checks them against today's scenes): the run reads them from its atlas_references/.
    shutil.copytree(ROOT / "tests" / "data" / "atlas-quick-references", QUICK / "atlas_references")
    result = run("quick", "--ranks", "2", bin_dir=os.path.join(build, "bin"))
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    # Every program ran as one job of two ranks; rank 0 wrote the one CSV.
    for name in ("stability", "work_precision", "scaling"):
        with open(QUICK / f"{name}.json") as f:
            assert json.load(f)["mpi_ranks"] == 2, name
        assert (QUICK / f"{name}.csv").stat().st_size > 100, name
    # The atlas's quick grid, whole: k = 1e3 and 1e5 at N = 8, each integrator of the quick grid,
    # and every cell that kept its visible motion did so within the 1 cm tolerance of a
    # reference checked at twice its step.
    with open(QUICK / "scaling_atlas.csv") as f:
        rows = list(csv.DictReader(f))
    cells = {(float(r["k_N_per_m"]), int(r["n"]), r["integrator"]) for r in rows}
    integrators = {"symplectic", "rk4", "implicit", "midpoint", "projective"}
    assert cells == {(k, 8, i) for k in (1e3, 1e5) for i in integrators}
    kept = [r for r in rows if r["outcome"] == "ok"]
    # As in the single-process run (experiments_test, ScalingQuick): the explicit methods and
    # midpoint keep the visible motion, backward Euler and projective damp the rebound away.
    assert {r["integrator"] for r in kept} == {"symplectic", "rk4", "midpoint"}
    for r in kept:
        assert float(r["visible_error_m"]) <= 0.01, r
        assert float(r["reference_check_m"]) <= 0.01, r
    for chart in ("stability_free.png", "scaling.png", "atlas_n8.png"):
        assert (QUICK / chart).stat().st_size > 10_000, chart
