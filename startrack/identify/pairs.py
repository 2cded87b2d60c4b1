"""Catalog star pairs as the compiled search reads them: pair tables and per-star neighbour lists.

A :class:`PairTable` is the list of star pairs sorted by angular distance (000 §2.2) that gives the
first two catalog stars of a hypothesis: the full-sky table with its k-vector (000 eq. 3-5), the
pairs of every field star (the dense table, with its own k-vector), or one sub-catalog's pairs
(000 §2.3; ``subset``, ascending pair indices into the full table, so still sorted by distance).
A sub-catalog's pairs are also stored contiguously (:class:`SubCatalogPairs`), so that its search
touches a few kilobytes.  ``counts`` is the k-vector of eq. 4 sampled at 4096 equally spaced
distances (cumulative pair counts, cache-resident): the expected number of pairs in a distance
interval without touching the table itself.

The kernels take a table as a plain tuple (:meth:`PairTable.arrays`), one type for every table: one
compiled kernel.  Helpers that allocate nothing are compiled with ``_nrt=False`` (no reference counting
of their array arguments: ~40 ns less per call in the search's inner loops).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from startrack.catalog.kvector import KVector
from startrack.catalog.navigation import pattern_pairs
from startrack.compiled.numba_setup import njit
from startrack.identify.zones import bisect

#: Distance bins of the cumulative pair counts of a k-vector table.
_COUNT_BINS = 4096


def _frozen(array, dtype):
    array = np.ascontiguousarray(array, dtype=dtype)
    array.flags.writeable = False
    return array


#: Angular distances of a table [rad] in single precision (2e-8 rad at 0.3 rad, far inside any gate):
#: half the memory a search reads.
_THETA = np.float32

_NO_INDEX = _frozen(np.zeros(0), np.int32)
_NO_COUNTS = _frozen(np.zeros(0), np.int64)


@dataclass(frozen=True, eq=False)
class PairTable:
    """Star pairs sorted by angular distance: ``theta`` [rad], star indices ``first``, ``second``.

    With a k-vector (``k`` int64, ``slope`` m and ``intercept`` q of eq. 3-4 of 000) a distance
    interval is found by eq. 5 (then trimmed exactly); without one (``k`` empty) by a binary search.
    """

    theta: np.ndarray
    first: np.ndarray
    second: np.ndarray
    k: np.ndarray
    slope: float = 1.0
    intercept: float = 0.0

    def __post_init__(self):
        for name, dtype in (("theta", _THETA), ("first", np.int32), ("second", np.int32), ("k", np.int32)):
            object.__setattr__(self, name, _frozen(getattr(self, name), dtype))

    @classmethod
    def full_sky(cls, catalog) -> "PairTable":
        """Every pattern pair of the navigation catalog, searched with its k-vector."""
        kv = catalog.kvector
        return cls(catalog.pair_theta, catalog.pair_i, catalog.pair_j, kv.k, float(kv.slope), float(kv.intercept))

    @classmethod
    def of_stars(cls, vectors, theta_min: float, theta_max: float) -> "PairTable":
        """Every pair of the unit vectors (N, 3) with distance in [theta_min, theta_max] [rad] (000 §2.2),
        with its own k-vector (eq. 3-4)."""
        theta, first, second = pattern_pairs(vectors, theta_min, theta_max)
        kv = KVector.build(theta, theta_min, theta_max)
        return cls(theta, first, second, kv.k, float(kv.slope), float(kv.intercept))

    @functools.cached_property
    def arrays(self):
        """The tuple the kernels take: (theta, first, second, k, slope, intercept, counts, counts_low,
        counts_step); ``counts`` [i] = pairs with theta < counts_low + i counts_step (empty: count exactly)."""
        if self.k.size == 0:
            return self.theta, self.first, self.second, self.k, self.slope, self.intercept, _NO_COUNTS, 0.0, 1.0
        low, high = float(self.theta[0]), float(self.theta[-1])
        step = max(high - low, 1e-12) / _COUNT_BINS
        counts = _frozen(np.searchsorted(self.theta, low + step * np.arange(_COUNT_BINS + 1)), np.int64)
        return self.theta, self.first, self.second, self.k, self.slope, self.intercept, counts, low, step


class SubCatalogPairs:
    """The pairs of every sub-catalog of a navigation catalog, one contiguous table per sub-catalog
    (000 §2.3: pair indices of each sub-catalog into the pattern table, gathered once here)."""

    def __init__(self, catalog):
        index = catalog.sub_pair_index
        self.offsets = np.asarray(catalog.sub_pair_offsets, dtype=np.int64)
        self.theta = _frozen(catalog.pair_theta[index], _THETA)
        self.first = _frozen(catalog.pair_i[index], np.int32)
        self.second = _frozen(catalog.pair_j[index], np.int32)

    def arrays(self, b: int):
        """:meth:`PairTable.arrays` of sub-catalog ``b`` (searched by bisection)."""
        start, stop = self.offsets[b], self.offsets[b + 1]
        return (self.theta[start:stop], self.first[start:stop], self.second[start:stop], _NO_INDEX, 1.0, 0.0,
                _NO_COUNTS, 0.0, 1.0)


@njit(_nrt=False)
def kvector_range(theta, k, slope, intercept, low, high):  # pragma: no cover  (compiled)
    """[lo, hi) of the pairs with theta in [low, high]: eq. 5 of 000 widened by one bucket each side,
    k(j_start) .. k(j_end) (Mortari), a superset of the exact range."""
    n = k.size
    start = min(max(np.floor((low - intercept) / slope) - 1.0, 1.0), float(n))
    stop = min(max(np.ceil((high - intercept) / slope) + 1.0, 1.0), float(n))
    return k[int(start) - 1], k[int(stop) - 1]


@njit(_nrt=False)
def pair_range(table, low, high):  # pragma: no cover  (compiled)
    """Exact [lo, hi) of the pairs of ``table`` (:meth:`PairTable.arrays`) with theta in [low, high]:
    the k-vector superset trimmed by bisection, or a bisection of the whole (sub-catalog) table."""
    theta, _, _, k, slope, intercept, _, _, _ = table
    lo, hi = 0, theta.size
    if k.size:
        lo, hi = kvector_range(theta, k, slope, intercept, low, high)
    lo = bisect(theta, lo, hi, low, False)
    return lo, bisect(theta, lo, hi, high, True)


@njit(_nrt=False)
def pair_count(table, low, high):  # pragma: no cover  (compiled)
    """Number of pairs of ``table`` with theta in [low, high]: interpolated in the cumulative counts
    when the table has them (expected value, within a fraction of a bin's pairs), else exact."""
    counts, counts_low, step = table[6], table[7], table[8]
    if counts.size == 0:
        lo, hi = pair_range(table, low, high)
        return float(hi - lo)
    return _cumulative(counts, counts_low, step, high) - _cumulative(counts, counts_low, step, low)


@njit(_nrt=False)
def _cumulative(counts, counts_low, step, x):  # pragma: no cover  (compiled)
    position = min(max((x - counts_low) / step, 0.0), counts.size - 1.0)
    i = min(int(position), counts.size - 2)
    return counts[i] + (position - i) * (counts[i + 1] - counts[i])
