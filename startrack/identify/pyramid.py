"""Compiled star-pattern search: triangles extended to pyramids, each verified as soon as it is found.

For the brightest n centroids (brightest first) the observed triangles (i, j, k) = (i, i + dj,
i + dj + dk) are taken for dj = 1, 2, ..., then dk = 1, 2, ..., then i = 0, 1, ... (the order of
Mortari's pyramid algorithm): the first triangles are those of neighbouring brightness ranks,
(0, 1, 2), (1, 2, 3), (2, 3, 4), ..., so a false or uncatalogued bright star is left behind after
the few triangles it is part of (with star 0 false the second triangle is all true; with the
triangles of the brightest m stars first it would be the fourth, with two false stars the tenth).  Every observed pair (s, t) has the gate [beta - e, beta + e] (e the bound
of 001 §4.3.1, :mod:`startrack.identify.features`) and the catalog pairs inside it (the pair table:
k-vector of 000 eq. 3-5, or a sub-catalog's pairs; :func:`startrack.identify.pairs.pair_range`).

1. Triangle (001 §4.4.2): of its three observed pairs the two with the fewest expected candidates
   (they share one star s) are scanned: the catalog stars of s in the first are marked (with their
   partner), the second is scanned for a marked star; each hit gives a catalog triangle, kept when
   its third distance lies within the third gate and its handedness is the observed one (a mirror
   image is not a rotation).  Only contiguous runs of the pair table are read.
2. Pyramid (001 §4.4.3, the fourth star): the catalog triangle's SVD attitude puts each other
   centroid r (brightness order) on the sky; the first that falls within the first verification gate
   (3 r) of a field star (a look-up in the zone index, :mod:`startrack.identify.zones`) makes the
   four-star group, whose hypothesis is verified at once (:func:`startrack.identify.verify.verify_near`,
   which refits with every match); the first accepted hypothesis ends the search.
3. Triangles that no fourth star extends are kept (up to the buffer) and verified after every group
   of the n stars has failed: such a hypothesis needs further matches in the verification.

``region`` = (axis (3,), cos rho): only catalog stars within rho of the axis take part (the region
around a predicted boresight); cos rho = -2 for the whole table.  N_h of the false-match probability
counts the oriented catalog pairs inside the gates of every pair of the n stars (the hypotheses the
search could have made; expected counts for the k-vector tables, :func:`~startrack.identify.pairs.pair_count`).
"""

from __future__ import annotations

import numpy as np

from startrack.compiled.numba_setup import njit
from startrack.geometry.rotation_kernels import wahba_svd
from startrack.identify.pairs import pair_count, pair_range
from startrack.identify.verify import TRIANGLE_SEEDS, verify_near
from startrack.identify.zones import stars_near

#: Catalog triangles kept per observed triangle, and unextended triangles kept per search.
TRIANGLE_BUFFER = 64


@njit(_nrt=False)
def _triple(p, q, r):  # pragma: no cover  (compiled)
    """p . (q x r) of three 3-vectors."""
    return (p[0] * (q[1] * r[2] - q[2] * r[1]) + p[1] * (q[2] * r[0] - q[0] * r[2])
            + p[2] * (q[0] * r[1] - q[1] * r[0]))


@njit(_nrt=False)
def _inside(vectors, x, y, cos_low, cos_high):  # pragma: no cover  (compiled)
    """cos_low <= vectors[x] . vectors[y] <= cos_high: the angle lies inside its gate."""
    c = vectors[x, 0] * vectors[y, 0] + vectors[x, 1] * vectors[y, 1] + vectors[x, 2] * vectors[y, 2]
    return cos_low <= c <= cos_high


@njit(_nrt=False)
def _in_region(region, vectors, x):  # pragma: no cover  (compiled)
    axis, cos_radius = region
    return vectors[x, 0] * axis[0] + vectors[x, 1] * axis[1] + vectors[x, 2] * axis[2] >= cos_radius


@njit
def gate_cosines(beta):  # pragma: no cover  (compiled)
    """Caches (cos_low, cos_high) (m, m) of the gate ends, filled by :func:`_gate_ends` (2 = not yet)."""
    return np.full(beta.shape, 2.0), np.full(beta.shape, 2.0)


@njit(_nrt=False)
def _gate_ends(s, t, beta, gate, cos_low, cos_high):  # pragma: no cover  (compiled)
    """(cos(beta + e), cos(max(beta - e, 0))) of the pair (s, t): its gate as cosines (cached)."""
    if cos_low[s, t] > 1.0:
        cos_low[s, t] = cos_low[t, s] = np.cos(min(beta[s, t] + gate[s, t], np.pi))
        cos_high[s, t] = cos_high[t, s] = np.cos(max(beta[s, t] - gate[s, t], 0.0))
    return cos_low[s, t], cos_high[s, t]


@njit(_nrt=False)
def _slots(s, t, beta, gate, table, lo, hi):  # pragma: no cover  (compiled)
    """Cached [lo, hi) of the catalog pairs inside the gate of the observed pair (s, t)."""
    if lo[s, t] < 0:
        a, b = pair_range(table, beta[s, t] - gate[s, t], beta[s, t] + gate[s, t])
        lo[s, t], hi[s, t], lo[t, s], hi[t, s] = a, b, a, b
    return lo[s, t], hi[s, t]


@njit(_nrt=False)
def _expected(s, t, beta, gate, table, counts, lo, hi):  # pragma: no cover  (compiled)
    """Cached expected number of catalog pairs inside the gate of (s, t) (pair_count); exact, with its
    range cached too, for a table without cumulative counts."""
    if counts[s, t] < 0.0:
        if table[6].size:
            counts[s, t] = pair_count(table, beta[s, t] - gate[s, t], beta[s, t] + gate[s, t])
        else:
            a, b = _slots(s, t, beta, gate, table, lo, hi)
            counts[s, t] = b - a
        counts[t, s] = counts[s, t]
    return counts[s, t]


@njit(_nrt=False)
def _hypothesis_count(n, beta, gate, table, counts, lo, hi):  # pragma: no cover  (compiled)
    """N_h: oriented catalog pairs inside the gates of every pair of the first n centroids."""
    total = 0.0
    for s in range(n):
        for t in range(s + 1, n):
            total += 2.0 * _expected(s, t, beta, gate, table, counts, lo, hi)
    return int(np.ceil(total))


@njit(_nrt=False)
def _two_smallest(tri, beta, gate, table, counts, lo, hi, theta_max):  # pragma: no cover  (compiled)
    """(s, x, y): the triangle's star s shared by its two pairs (s, x), (s, y) with the fewest expected
    candidates among the pairs within the table's reach; s = -1 if fewer than two are, or if a pair
    has no candidate at all (no catalog triangle can match)."""
    best_e, best_count, second_e, second_count = -1, np.inf, -1, np.inf
    for e in range(3):  # pair e joins tri[e] and tri[(e + 1) % 3]
        a, b = tri[e], tri[(e + 1) % 3]
        if beta[a, b] - gate[a, b] > theta_max:
            continue
        count = _expected(a, b, beta, gate, table, counts, lo, hi)
        if count == 0.0:
            return -1, -1, -1
        if count < best_count:
            second_e, second_count, best_e, best_count = best_e, best_count, e, count
        elif count < second_count:
            second_e, second_count = e, count
    if second_e < 0:
        return -1, -1, -1
    # pairs e and f share the star tri[f] if f = e + 1, tri[e] if f = e - 1 (mod 3)
    e, f = best_e, second_e
    shared = tri[f] if f == (e + 1) % 3 else tri[e]
    x = tri[e] + tri[(e + 1) % 3] - shared
    y = tri[f] + tri[(f + 1) % 3] - shared
    return shared, x, y


@njit(_nrt=False)
def _catalog_triangles(tri, s, x, y, obs, beta, gate, cos_low, cos_high, table, region, x_slots, y_slots, vectors, head,
                      partner, chain, found):  # pragma: no cover  (compiled)
    """Catalog triangles matching the observed triangle ``tri`` through its pairs (s, x) and (s, y)
    (``x_slots``, ``y_slots`` their [lo, hi) in the table): rows of ``found`` (catalog stars of tri[0],
    tri[1], tri[2]); returns their number (module text, step 1).  ``head`` (n_stars,) is a work array
    of -1 (returned as found), ``partner`` and ``chain`` hold 2 (x_slots[1] - x_slots[0]) entries."""
    first, second = table[1], table[2]
    xy_low, xy_high = _gate_ends(x, y, beta, gate, cos_low, cos_high)
    m = 0
    for q in range(x_slots[0], x_slots[1]):  # mark the catalog stars of s, chained with their partner for x
        for o in range(2):
            S, X = (first[q], second[q]) if o == 0 else (second[q], first[q])
            partner[m], chain[m] = X, head[S]
            head[S] = m
            m += 1
    handed = _triple(obs[tri[0]], obs[tri[1]], obs[tri[2]])
    count = 0
    for q in range(y_slots[0], y_slots[1]):
        for o in range(2):
            S, Y = (first[q], second[q]) if o == 0 else (second[q], first[q])
            e = head[S]
            while e >= 0:
                X = partner[e]
                e = chain[e]
                if X == Y or not _inside(vectors, X, Y, xy_low, xy_high):
                    continue
                if not (_in_region(region, vectors, S) and _in_region(region, vectors, X)
                        and _in_region(region, vectors, Y)) or count == found.shape[0]:
                    continue
                for c in range(3):
                    found[count, c] = S if tri[c] == s else (X if tri[c] == x else Y)
                if handed * _triple(vectors[found[count, 0]], vectors[found[count, 1]], vectors[found[count, 2]]) > 0.0:
                    count += 1
    for q in range(x_slots[0], x_slots[1]):
        head[first[q]] = -1
        head[second[q]] = -1
    return count


@njit(_nrt=False)
def _fourth_star(R_IS, obs, tri, n, field, near, direction):  # pragma: no cover  (compiled)
    """The first centroid r < n outside the triangle ``tri`` that the triangle's attitude R_IS puts within
    the first verification gate (3 r) of a field star, or -1 (module text, step 2; ``near`` a work
    array of at least one entry per field star, ``direction`` one of 3)."""
    vectors, zones, gate = field[0], field[1], field[4][0]
    for r in range(n):
        if r == tri[0] or r == tri[1] or r == tri[2]:
            continue
        for c in range(3):
            direction[c] = R_IS[c, 0] * obs[r, 0] + R_IS[c, 1] * obs[r, 1] + R_IS[c, 2] * obs[r, 2]
        if stars_near(zones, vectors, direction, gate, near) > 0:
            return r
    return -1


@njit
def no_result():  # pragma: no cover  (compiled)
    """verify_near's tuple for "nothing verified"."""
    empty = np.zeros(0, np.int64)
    return False, np.eye(3), empty, empty, 1.0, 0


@njit
def _attitude(obs, observed, stars, vectors):  # pragma: no cover  (compiled)
    """SVD attitude R_IS of the centroids ``observed`` matched to the catalog ``stars``."""
    ref = np.empty((stars.size, 3))
    seen = np.empty((stars.size, 3))
    for m in range(stars.size):
        ref[m] = vectors[stars[m]]
        seen[m] = obs[observed[m]]
    return wahba_svd(ref, seen)


@njit
def search(obs, n, beta, gate, cos_low, cos_high, table, vectors, region, field, head, triangles,
           n_h_before):  # pragma: no cover  (compiled)
    """Pyramids of the brightest n centroids, each verified when found (module text).

    ``vectors`` (N, 3): the stars the table indexes; ``head`` (N,) int32 work array of -1;
    ``triangles`` (TRIANGLE_BUFFER, 6) int64 receives the unextended triangles (3 centroids, 3 catalog
    stars); ``n_h_before``: hypotheses an earlier search of the frame could make (added to N_h).
    Returns (verify_near's tuple, N_h, triangles kept).
    """
    lo = np.full((n, n), -1, np.int64)
    hi = np.full((n, n), -1, np.int64)
    counts = np.full((n, n), -1.0)
    n_h = _hypothesis_count(n, beta, gate, table, counts, lo, hi) + int(np.ceil(n_h_before))
    found = np.empty((TRIANGLE_BUFFER, 3), np.int64)
    tri = np.empty(3, np.int64)
    x_slots = np.empty(2, np.int64)
    y_slots = np.empty(2, np.int64)
    partner = np.empty(0, np.int64)
    chain = np.empty(0, np.int64)
    near = np.empty(field[0].shape[0], np.int64)
    direction = np.empty(3)
    theta_max = table[0][-1] if table[0].size else 0.0
    kept = 0
    for dj in range(1, n - 1):
        for dk in range(1, n - dj):
            for i in range(n - dj - dk):
                tri[0], tri[1], tri[2] = i, i + dj, i + dj + dk
                s, x, y = _two_smallest(tri, beta, gate, table, counts, lo, hi, theta_max)
                if s < 0:
                    continue
                x_slots[0], x_slots[1] = _slots(s, x, beta, gate, table, lo, hi)
                y_slots[0], y_slots[1] = _slots(s, y, beta, gate, table, lo, hi)
                if partner.size < 2 * (x_slots[1] - x_slots[0]):
                    partner = np.empty(4 * (x_slots[1] - x_slots[0]), np.int64)
                    chain = np.empty(partner.size, np.int64)
                for t in range(_catalog_triangles(tri, s, x, y, obs, beta, gate, cos_low, cos_high, table, region, x_slots,
                                                 y_slots, vectors, head, partner, chain, found)):
                    R_IS = _attitude(obs, tri, found[t], vectors)
                    if _fourth_star(R_IS, obs, tri, n, field, near, direction) >= 0:
                        result = verify_near(obs, R_IS, field, float(n_h), TRIANGLE_SEEDS)
                        if result[0]:
                            return result, n_h, kept
                    elif kept < triangles.shape[0]:
                        triangles[kept, :3] = tri
                        triangles[kept, 3:] = found[t]
                        kept += 1
    return no_result(), n_h, kept


@njit
def verify_triangles(obs, triangles, kept, vectors, field, n_h):  # pragma: no cover  (compiled)
    """The first of the ``kept`` triangles (rows of ``triangles``) whose SVD attitude verifies."""
    for t in range(kept):
        result = verify_near(obs, _attitude(obs, triangles[t, :3], triangles[t, 3:], vectors), field, float(n_h), TRIANGLE_SEEDS)
        if result[0]:
            return result
    return no_result()
