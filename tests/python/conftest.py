"""Fixtures of the Python module's tests (tests/python/CMakeLists.txt runs them against the module of
the same build tree, with PYTHONPATH at <build>/python; by hand:
    PYTHONPATH=build/python SEAMLESS_EXE=build/src/app/seamless python3 -m pytest tests/python)."""
import os
import subprocess

import pytest

SRC = os.environ.get("SEAMLESS_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
DATA = os.environ.get("SEAMLESS_DATA", os.path.join(SRC, "..", "shared", "data"))
EXE = os.environ.get("SEAMLESS_EXE", "")


@pytest.fixture(scope="session")
def seamless_cli():
    """Runs the `seamless` command of the same build; returns its CompletedProcess."""
    if not EXE or not os.access(EXE, os.X_OK):
        pytest.skip("SEAMLESS_EXE does not name the seamless command of this build")

    def run(*args, check=True):
        r = subprocess.run([EXE, *map(str, args)], capture_output=True, text=True, timeout=600)
        if check and r.returncode != 0:
            raise AssertionError(f"seamless {' '.join(map(str, args))} exited {r.returncode}:\n{r.stderr}")
        return r
    return run


@pytest.fixture(scope="session")
def fr1_rpy():
    """The real TUM freiburg1_rpy frames 150-299 of ../shared/data (skipped where they are absent)."""
    path = os.path.join(DATA, "tum_fr1_rpy_150-299")
    if not os.path.isfile(os.path.join(path, "rgb.txt")):
        pytest.skip(f"no recording at {path}")
    return path


@pytest.fixture(scope="session")
def source_dir():
    return SRC
