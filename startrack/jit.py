"""Numba set-up for startrack: compiled kernels are cached under the user cache directory.

Import ``njit`` from here (not from numba) so that ``NUMBA_CACHE_DIR`` is set before numba loads;
``$NUMBA_CACHE_DIR`` set by the user wins.
"""

import functools
import os

from startrack.cache import cache_dir

os.environ.setdefault("NUMBA_CACHE_DIR", str(cache_dir() / "numba"))

import numba  # noqa: E402  (must follow the cache set-up)

#: ``@njit`` with on-disk caching; kernels are pure functions of arrays and scalars.
njit = functools.partial(numba.njit, cache=True, nogil=True)
