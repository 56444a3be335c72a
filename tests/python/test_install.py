"""`cmake --install` puts a working package where the system python3 finds it under the prefix;
`pip install .` from the checkout, offline against Debian's packages, puts one into a virtual
environment (issue 41, item 10)."""
import os
import subprocess
import sys

from conftest import program

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def test_cmake_install_gives_an_importable_package(tmp_path):
    build = program("JELLO_BUILD_DIR")
    subprocess.run(["cmake", "--install", build, "--prefix", str(tmp_path)], check=True,
                   capture_output=True)
    site = tmp_path / "lib" / f"python3.{sys.version_info.minor}" / "dist-packages"
    assert (site / "jello" / "__init__.py").exists()
    env = dict(os.environ, PYTHONPATH=str(site))
    result = subprocess.run(
        [sys.executable, "-c", "import jello; print(jello.__file__); "
         "s = jello.Simulation(jello.World()); s.step(3); print(s.steps)"],
        capture_output=True, text=True, env=env, cwd=str(tmp_path), check=True)
    lines = result.stdout.split()
    assert lines[0].startswith(str(site)) and lines[1] == "3"


def test_pip_install_from_the_checkout_into_a_virtual_environment(tmp_path):
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", "--system-site-packages",
                    str(venv)], check=True, capture_output=True)
    python = str(venv / "bin" / "python")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["JELLO_CMAKE_BUILD_DIR"] = program("JELLO_BUILD_DIR")  # built already: nothing compiles
    # Debian's pip, seen through --system-site-packages, installs into the environment.
    installed = subprocess.run(
        [python, "-m", "pip", "install", "--no-build-isolation", "--no-index", "--quiet", ROOT],
        capture_output=True, text=True, env=env, cwd=str(tmp_path))
    assert installed.returncode == 0, installed.stdout + installed.stderr
    result = subprocess.run(
        [python, "-c", "import jello; print(jello.__file__); "
         "s = jello.Simulation(jello.World()); s.step(3); print(s.steps)"],
        capture_output=True, text=True, env=env, cwd=str(tmp_path), check=True)
    lines = result.stdout.split()
    assert lines[0].startswith(str(venv)) and lines[1] == "3"
    shown = subprocess.run([python, "-m", "pip", "show", "jello"], capture_output=True, text=True,
                           env=env, check=True).stdout
    assert "Version: 0.1.0" in shown
