"""The sorts of the compiled kernels, compiled once and cached like every kernel.

numba compiles its own ``np.argsort``/``np.sort``/``np.unique``/``np.median`` into every kernel that calls
them, once per process and per key type and algorithm (four variants took ~5 s of the first compile of the
identifier, again in each process compiling a caller); these are ordinary cached kernels, compiled once per
installation.  Keys are finite (NaN has no place in them).
"""

import numpy as np

from startrack.compiled.numba_setup import njit

#: Runs sorted by insertion before merging.
_RUN = 16


@njit
def argsort(keys):  # pragma: no cover  (compiled)
    """Indices (n,) int64 ordering ``keys`` (n,) float64 ascending, stable (equal keys keep their order,
    as ``np.argsort(keys, kind="stable")``): insertion-sorted runs, then bottom-up merges."""
    n = keys.shape[0]
    order = np.arange(n)
    for start in range(0, n, _RUN):
        for i in range(start + 1, min(start + _RUN, n)):
            item, key, j = order[i], keys[order[i]], i - 1
            while j >= start and keys[order[j]] > key:
                order[j + 1] = order[j]
                j -= 1
            order[j + 1] = item
    source, target = order, np.empty(n, np.int64)
    width = _RUN
    while width < n:
        for low in range(0, n, 2 * width):
            _merge(keys, source, target, low, min(low + width, n), min(low + 2 * width, n))
        source, target = target, source
        width *= 2
    return source


@njit
def _merge(keys, source, target, low, middle, high):  # pragma: no cover  (compiled)
    """target[low:high] = the ordered runs source[low:middle] and source[middle:high] merged (left first on ties)."""
    i, j = low, middle
    for k in range(low, high):
        if j >= high or (i < middle and keys[source[i]] <= keys[source[j]]):
            target[k] = source[i]
            i += 1
        else:
            target[k] = source[j]
            j += 1


@njit
def unique(values):  # pragma: no cover  (compiled)
    """The distinct entries of ``values`` (n,) int64 (|v| < 2**53), ascending (``np.unique``)."""
    out = np.empty(values.size, np.int64)
    count = 0
    for i in argsort(values.astype(np.float64)):
        if count == 0 or values[i] != out[count - 1]:
            out[count] = values[i]
            count += 1
    return out[:count]


@njit
def median(values):  # pragma: no cover  (compiled)
    """``np.median`` of ``values`` (n,) float64, n >= 1."""
    ordered = values[argsort(values)]
    half = ordered.size // 2
    return ordered[half] if ordered.size % 2 else 0.5 * (ordered[half - 1] + ordered[half])
