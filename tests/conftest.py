"""Shared test set-up: caches go to a per-session temporary directory unless set."""

import os

import pytest


@pytest.fixture(autouse=True, scope="session")
def _isolated_cache(tmp_path_factory):
    if "STARTRACK_CACHE_DIR" not in os.environ:
        os.environ["STARTRACK_CACHE_DIR"] = str(tmp_path_factory.mktemp("startrack-cache"))
    yield


@pytest.fixture(autouse=True, scope="session")
def _kernels_compiled_ahead(_isolated_cache):
    """The kernels of the image chain, the plate solver and the INS compiled first, on both cores
    (``startrack.precompile``): no test's output depends on whether it is the first to need them, and the
    suite compiles them in about half the time."""
    from navsim.attitude.run import IMAGE_LANES
    from navsim.navigation.run import VECTOR_LANES
    from startrack.precompile import compile_ahead

    compile_ahead((*IMAGE_LANES, ("startrack.identify.warmup:plate_solver",), *VECTOR_LANES))
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
