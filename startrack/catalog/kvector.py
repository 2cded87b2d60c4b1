"""k-vector range search over a sorted table (eq. 3-5 of document 000; Mortari's k-vector).

Given the ``n_s`` values ``P`` sorted ascending (the angular distances of the
pattern pairs, within ``[theta_min, theta_max]``), the straight line

    z(x) = m x + q,   m = (theta_max - theta_min + 2 xi) / (n_s - 1),
                      q = theta_min - m - xi,   xi = eps max(|theta_min|, |theta_max|)   (eq. 3)

runs from ``(1, theta_min - xi)`` to ``(n_s, theta_max + xi)``, and the
k-vector holds, for x = 1 .. n_s (1-based, as in 000),

    k(1) = 0,  k(x) = #{P <= z(x)},  k(n_s) = n_s                                  (eq. 4)

i.e. ``k(x) = j`` with ``P(j) <= z(x) < P(j+1)``. A search for ``P`` in
``[theta_a, theta_b]`` takes ``j_start = floor((theta_a - q) / m)`` and
``j_end = ceil((theta_b - q) / m)`` (eq. 5); the answer lies in the index
range ``k(j_start) + 1 .. k(j_end)`` (1-based).

Exactness: eq. 5 alone returns a superset (a few values just outside the
interval at both ends), and in floating point ``z(j_start)`` may land a hair
above ``theta_a``. Here the bucket indices are widened by one on each side
(so the candidate window provably contains every value in the interval), then
the window is trimmed to the values inside ``[theta_a, theta_b]`` (ends
included) with a binary search of the few candidates. The result is the same
index range a brute-force scan gives. Indices returned are 0-based
half-open ranges ``[lo, hi)`` into ``P``.
"""

from __future__ import annotations

import bisect
import functools
import math
from dataclasses import dataclass

import numpy as np

from startrack.base.errors import InputError

#: Default relative precision eps of eq. 3 (xi = eps max |theta|).
_DEFAULT_EPSILON = 2.0 * np.finfo(float).eps


@dataclass(frozen=True, eq=False)
class KVector:
    """k-vector index of a sorted float array (eq. 3-5 of 000).

    ``values`` is the sorted table P, ``k`` the k-vector (length n_s, entry
    ``k[x - 1]`` = k(x) of eq. 4), ``slope`` m and ``intercept`` q of eq. 3.
    """

    values: np.ndarray
    k: np.ndarray
    slope: float
    intercept: float

    @classmethod
    def build(cls, values, lower=None, upper=None, epsilon: float = _DEFAULT_EPSILON) -> "KVector":
        """Build the k-vector of sorted ``values`` spanning ``[lower, upper]`` (eq. 3-4).

        ``lower``/``upper`` default to the first/last value (theta_min, theta_max of 000).
        """
        values = np.asarray(values, dtype=np.float64)
        if values.ndim != 1 or values.size < 2:
            raise InputError("the k-vector needs a one-dimensional table of at least 2 values.")
        if not np.all(np.isfinite(values)):
            raise InputError("the k-vector table contains a value that is not finite.")
        if np.any(np.diff(values) < 0):
            raise InputError("the k-vector table must be sorted in ascending order.")
        lower = float(values[0]) if lower is None else float(lower)
        upper = float(values[-1]) if upper is None else float(upper)
        if not lower <= values[0] or not values[-1] <= upper:
            raise InputError("the k-vector range [lower, upper] must contain every table value.")
        n = values.size
        xi = epsilon * (max(abs(lower), abs(upper)) or 1.0)  # eq. 3; an all-zero table still gets m > 0
        slope = (upper - lower + 2.0 * xi) / (n - 1)  # eq. 3
        intercept = lower - slope - xi
        z = slope * np.arange(1, n + 1) + intercept
        k = np.searchsorted(values, z, side="right").astype(np.int32 if n < 2**31 else np.int64)  # eq. 4
        k[0] = 0
        k[-1] = n
        values = values.copy()
        values.flags.writeable = False
        k.flags.writeable = False
        return cls(values=values, k=k, slope=float(slope), intercept=float(intercept))

    def __len__(self) -> int:
        return int(self.values.size)

    @functools.cached_property
    def _lists(self):
        """Python-list copies of the table and k-vector: scalar searches index them faster than numpy."""
        return self.values.tolist(), self.k.tolist()

    def range(self, lower: float, upper: float) -> tuple[int, int]:
        """Index range ``[lo, hi)`` of the table values in ``[lower, upper]`` (ends included).

        Scalar fast path (a few microseconds): eq. 5 with one extra bucket each
        side, then bisection inside that window.
        """
        lower = float(lower)
        upper = float(upper)
        if not upper >= lower:  # also rejects NaN
            return 0, 0
        values, k = self._lists
        n = len(k)
        x = (lower - self.intercept) / self.slope
        y = (upper - self.intercept) / self.slope
        # j_start = clip(floor(x) - 1, 1, n), j_end = clip(ceil(y) + 1, 1, n), safe for +-inf.
        j_start = 1 if not x >= 2.0 else (n if x >= n + 1.0 else math.floor(x) - 1)
        j_end = n if not y < n - 1.0 else (1 if y < 0.0 else math.ceil(y) + 1)
        start, stop = k[j_start - 1], k[j_end - 1]
        lo = bisect.bisect_left(values, lower, start, stop)
        hi = bisect.bisect_right(values, upper, lo, stop)
        return lo, hi

    def search(self, lower: float, upper: float) -> np.ndarray:
        """Indices (int64) of the table values in ``[lower, upper]``, ascending."""
        lo, hi = self.range(lower, upper)
        return np.arange(lo, hi)

    def _end_windows(self, theta):
        """For each value theta, the index range [k(floor(x) - 1), k(ceil(x) + 1)) bracketing it (eq. 5).

        With x = (theta - q) / m: every table index below the window holds a
        value < theta and every index at or above it a value > theta, since
        z(floor(x) - 1) < theta < z(ceil(x) + 1) by a margin of about m.
        """
        n = self.values.size
        x = (theta - self.intercept) / self.slope
        below = np.clip(np.floor(x) - 1.0, 1, n).astype(np.int64)
        above = np.clip(np.ceil(x) + 1.0, 1, n).astype(np.int64)
        return self.k[below - 1].astype(np.int64), self.k[above - 1].astype(np.int64)

    def _count_in_windows(self, start, stop, theta, side):
        """start + number of window values < theta (side "left") or <= theta (side "right")."""
        width = int(np.max(stop - start, initial=0))
        if width == 0:
            return start
        index = start[:, None] + np.arange(width)
        valid = index < stop[:, None]
        window = self.values[np.minimum(index, self.values.size - 1)]
        inside = window < theta[:, None] if side == "left" else window <= theta[:, None]
        return start + np.sum(valid & inside, axis=1)

    def range_many(self, lower, upper):
        """Vectorised :meth:`range` for arrays of intervals; returns (lo, hi) int64 arrays.

        Each end is bracketed by the k-vector (eq. 5, one bucket of margin each
        side) and located exactly inside its few-element window. Empty or NaN
        intervals give ``lo == hi``.
        """
        lower, upper = np.broadcast_arrays(np.asarray(lower, dtype=np.float64), np.asarray(upper, dtype=np.float64))
        shape = lower.shape
        lower, upper = lower.ravel(), upper.ravel()
        valid = upper >= lower  # False for NaN
        lower = np.where(valid, lower, 0.0)
        upper = np.where(valid, upper, 0.0)
        lo = self._count_in_windows(*self._end_windows(lower), lower, "left")
        hi = self._count_in_windows(*self._end_windows(upper), upper, "right")
        hi = np.where(valid, np.maximum(hi, lo), lo)
        return lo.reshape(shape), hi.reshape(shape)
