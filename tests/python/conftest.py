"""Shared fixtures of the Python module's tests (ctest runs each file with PYTHONPATH set to the
build tree's python/ folder and JELLO_SIM, JELLO_CREATE_WORLD naming the programs)."""
import os
import pathlib

# Single-threaded BLAS and CHOLMOD, as jello-sim runs them, before numpy loads BLAS: a
# multithreaded BLAS sums in another order, and "bit for bit" would not hold.
os.environ.setdefault("OMP_THREAD_LIMIT", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import pytest  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]
WORLDS = ROOT / "worlds"


@pytest.fixture
def worlds_dir():
    return WORLDS


@pytest.fixture
def jello_w():
    import jello
    return jello.load_world(str(WORLDS / "jello.w"))


def program(name):
    """The path of a built program, from the environment ctest sets."""
    path = os.environ.get(name)
    if not path:
        pytest.skip(f"{name} is not set (run through ctest)")
    return path
