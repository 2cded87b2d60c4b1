"""Shared test set-up: caches go to a per-session temporary directory unless set."""

import os

import pytest


@pytest.fixture(autouse=True, scope="session")
def _isolated_cache(tmp_path_factory):
    if "STARTRACK_CACHE_DIR" not in os.environ:
        os.environ["STARTRACK_CACHE_DIR"] = str(tmp_path_factory.mktemp("startrack-cache"))
    yield
