"""`cmake --install` puts a working package where the system python3 finds it under the prefix."""
import os
import subprocess
import sys

from conftest import program


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
