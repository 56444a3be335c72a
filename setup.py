"""The build step pyproject.toml's setuptools cannot make alone: jello._core, compiled by CMake.

The core is built in an existing CMake build directory (JELLO_CMAKE_BUILD_DIR, by default
build/release, configured with its preset when it is not yet), so that `pip install .` after
`scripts/build.sh` compiles nothing again; then copied into the wheel beside jello/__init__.py.
"""
import glob
import os
import shutil
import subprocess

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build = os.environ.get("JELLO_CMAKE_BUILD_DIR", os.path.join(ROOT, "build", "release"))
        if not os.path.exists(os.path.join(build, "CMakeCache.txt")):
            if os.path.abspath(build) != os.path.join(ROOT, "build", "release"):
                raise RuntimeError(f"{build} is not a configured CMake build directory")
            subprocess.run(["cmake", "--preset", "release"], cwd=ROOT, check=True)
        jobs = str(os.cpu_count() or 1)
        subprocess.run(["cmake", "--build", build, "--target", "jello_python_core", "-j", jobs],
                       check=True)
        built = glob.glob(os.path.join(build, "python", "jello", "_core*.so"))
        if len(built) != 1:
            raise RuntimeError(f"expected one jello/_core*.so in {build}/python, found {built}")
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copy2(built[0], target)


setup(ext_modules=[Extension("jello._core", sources=[])], cmdclass={"build_ext": CMakeBuild})
