"""The example scripts of experiments/python run headless (matplotlib's Agg backend) and
reproduce the committed results they compare with."""
import os
import subprocess
import sys

from conftest import ROOT

SCRIPTS = ROOT / "experiments" / "python"


def run_script(name, tmp_path, *args):
    env = dict(os.environ, MPLBACKEND="Agg")
    env.pop("DISPLAY", None)
    out = tmp_path / (name.replace(".py", ".png"))
    result = subprocess.run([sys.executable, str(SCRIPTS / name), "--quick", "--out", str(out),
                             *args], capture_output=True, text=True, env=env, timeout=600)
    assert result.returncode == 0, result.stdout + result.stderr
    assert out.stat().st_size > 10_000  # a chart, not an empty canvas
    assert not list(tmp_path.glob("*.tmp*"))  # written through a temporary file, renamed
    return result.stdout


def test_stability_thresholds_script(tmp_path):
    stdout = run_script("stability_thresholds.py", tmp_path, "--jobs", "2")
    assert ("equal to the committed stability.csv (within the bisection's 2%): 6 of 6 thresholds "
            "compared") in stdout


def test_energy_over_time_script(tmp_path):
    stdout = run_script("energy_over_time.py", tmp_path)
    for integrator in ("rk4", "implicit", "midpoint"):
        assert f" {integrator} " in stdout
