"""Shared test set-up: caches go to one temporary directory per session unless set, shared by the
session's xdist workers."""

import fcntl
import os
import shutil
import tempfile
from pathlib import Path

import pytest


def pytest_configure(config):
    """In the session's first process (xdist's controller, or the only one): one cache folder, which the
    workers inherit with the environment, so the kernels, the star tables and the pattern catalogs are made
    once per session rather than once per worker."""
    if hasattr(config, "workerinput") or "STARTRACK_CACHE_DIR" in os.environ:
        return
    folder = tempfile.mkdtemp(prefix="startrack-test-cache-")
    os.environ["STARTRACK_CACHE_DIR"] = folder
    config.add_cleanup(lambda: shutil.rmtree(folder, ignore_errors=True))


@pytest.fixture(autouse=True, scope="session")
def _kernels_compiled_ahead():
    """The kernels of the image chain, the plate solver and the INS compiled first, on both cores
    (``startrack.compiled.compile_ahead``), by the first worker to get here while the others wait (then find them
    compiled): no test's output depends on whether it is the first to need them, and the suite compiles
    them once, in about half the time of one core."""
    from navsim.attitude.run import IMAGE_LANES
    from navsim.navigation.run import VECTOR_LANES
    from startrack.compiled.compile_ahead import compile_ahead

    with open(Path(os.environ["STARTRACK_CACHE_DIR"]) / "compile-ahead.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        compile_ahead((*IMAGE_LANES, ("startrack.compile_tasks:plate_solver",), *VECTOR_LANES))
    yield


@pytest.fixture(scope="session")
def skyfield_sky():
    """skyfield's built-in timescale and JPL's DE421 ephemeris as shipped by the skyfield-data
    package (a test dependency): the independent reference of the apparent-place tests; nothing is
    downloaded."""
    from importlib.resources import files

    from skyfield.api import Loader

    load = Loader(str(files("skyfield_data") / "data"), verbose=False)
    return load.timescale(builtin=True), load("de421.bsp")
