"""Declination-zone index of unit vectors: the stars near a direction without a pass over all of them.

The sphere is cut into zones of equal declination height (1 deg); the stars of a zone are sorted by
right ascension.  The stars within an angle R of a direction c (RA alpha_c, Dec delta_c) lie in the
zones that overlap [delta_c - R, delta_c + R] and, unless the cap holds a pole (|delta_c| + R >= pi/2),
within alpha_c +- asin(sin R / cos delta_c) (the largest RA half-width of a spherical cap); each zone
is searched by bisection in that window (split where it wraps through RA = 0) and the candidates are
checked by their dot product with c.
"""

from __future__ import annotations

import math

import numpy as np

from startrack.compiled.numba_setup import njit

#: Height of a zone [rad].
ZONE_HEIGHT = math.radians(1.0)
#: ``region`` of the search kernels for the whole sky (cos rho = -2: every star).
SKY = (np.zeros(3), -2.0)


def cap(axis, radius: float):
    """``region`` of the search kernels: the stars within ``radius`` [rad] of the unit vector ``axis``."""
    return np.ascontiguousarray(axis, dtype=float), math.cos(min(radius, math.pi))


@njit(_nrt=False)
def bisect(values, start, stop, x, right):  # pragma: no cover  (compiled)
    """First index p in [start, stop) of the ascending ``values`` with values[p] > x (``right``) or >= x."""
    while start < stop:
        mid = (start + stop) >> 1
        if values[mid] < x or (right and values[mid] == x):
            start = mid + 1
        else:
            stop = mid
    return start


def zone_index(vectors):
    """The tuple the kernels take for the unit vectors (N, 3): (offsets (zones + 1,), ra (N,) [rad]
    sorted within each zone, star (N,) the vector index of each entry, zone height [rad])."""
    vectors = np.asarray(vectors, dtype=float)
    ra = np.mod(np.arctan2(vectors[:, 1], vectors[:, 0]), 2.0 * np.pi)
    dec = np.arcsin(np.clip(vectors[:, 2], -1.0, 1.0))
    n_zones = int(math.ceil(math.pi / ZONE_HEIGHT))
    zone = np.minimum(((dec + 0.5 * np.pi) / ZONE_HEIGHT).astype(np.int64), n_zones - 1)
    order = np.argsort(zone * 8.0 + ra)  # by zone, then RA (< 8): one float sort, 7x faster than np.lexsort
    offsets = np.searchsorted(zone[order], np.arange(n_zones + 1)).astype(np.int64)
    return offsets, np.ascontiguousarray(ra[order]), order.astype(np.int64), ZONE_HEIGHT


@njit(_nrt=False)
def _collect(zones, vectors, center, cos_radius, z, ra_low, ra_high, out, count, max_star):  # pragma: no cover
    """Append to ``out`` the stars (index < max_star) of zone z with RA in [ra_low, ra_high] within the
    radius; new count."""
    offsets, ra, star, _ = zones
    start = bisect(ra, offsets[z], offsets[z + 1], ra_low, False)
    stop = bisect(ra, start, offsets[z + 1], ra_high, True)
    for e in range(start, stop):
        s = star[e]
        if s < max_star and vectors[s, 0] * center[0] + vectors[s, 1] * center[1] + vectors[s, 2] * center[2] >= cos_radius:
            out[count] = s
            count += 1
    return count


@njit(_nrt=False)
def stars_near(zones, vectors, center, radius, out, max_star=-1):  # pragma: no cover  (compiled)
    """Indices of the unit ``vectors`` within ``radius`` [rad] of the unit vector ``center``, written to
    ``out`` (module text); returns their number.  ``max_star`` >= 0 keeps only indices below it (the
    brightest stars of vectors ordered brightest first)."""
    if max_star < 0:
        max_star = vectors.shape[0]
    height = zones[3]
    n_zones = zones[0].size - 1
    dec = math.asin(min(1.0, max(-1.0, center[2])))
    ra = math.atan2(center[1], center[0]) % (2.0 * math.pi)
    cos_radius = math.cos(radius)
    half = math.pi  # RA half-width of the cap
    if abs(dec) + radius < 0.5 * math.pi - 1e-9:
        half = math.asin(min(1.0, math.sin(radius) / math.cos(dec))) + 1e-12
    z0 = max(int((dec - radius + 0.5 * math.pi) / height), 0)
    z1 = min(int((dec + radius + 0.5 * math.pi) / height), n_zones - 1)
    count = 0
    for z in range(z0, z1 + 1):
        if half >= math.pi:
            count = _collect(zones, vectors, center, cos_radius, z, 0.0, 2.0 * math.pi, out, count, max_star)
            continue
        low, high = ra - half, ra + half
        if low < 0.0:
            count = _collect(zones, vectors, center, cos_radius, z, low + 2.0 * math.pi, 2.0 * math.pi, out, count, max_star)
            low = 0.0
        if high > 2.0 * math.pi:
            count = _collect(zones, vectors, center, cos_radius, z, 0.0, high - 2.0 * math.pi, out, count, max_star)
            high = 2.0 * math.pi
        count = _collect(zones, vectors, center, cos_radius, z, low, high, out, count, max_star)
    return count
