"""Known-camera search by four-star patterns looked up by their edge ratios (before the pyramid search).

The full-sky search of a calibrated camera first tries tetra3's geometric hash (docs/references.md):
one level of the pattern catalog (:func:`startrack.identify.pattern_catalog.build_level`) over the
identifier's field stars, for the camera's field of view F (lattice circles of diameter F, the 7
brightest pattern stars of each, pattern stars thinned to F / 20).  A frame's brightest stars usually
form one of its patterns: measured on the benchmark frames (16 deg, V <= 6), the first true pattern
is the first combination on clean frames (median; p95 the fifth) and the fourth with 0-3 false stars.

For the brightest centroids thinned to F / 20 (the catalog's thinning), the four-star combinations of
the first few are taken breadth first (:data:`startrack.identify.scale_free.COMBINATIONS`):

1. the six angles of the combination and their error bounds e (001 §4.3.1, the frame's features)
   sorted ascending, the ratios r_k = beta_(k) / beta_(6) and their tolerance eps = 2 max e / beta_(6)
   (sorting moves no angle by more than the largest bound); a combination whose eps exceeds half a bin
   is left to the pyramid search;
2. every key of the bins within +-eps (:mod:`startrack.identify.pattern_catalog`); a catalog pattern
   is a candidate when each of its six sorted angles lies within max e of the observed one (the known
   scale: far tighter than the ratios alone);
3. the star correspondence (the 24 assignments, :func:`startrack.identify.scale_free.correspondence`),
   the SVD attitude of the four (Markley 1988), kept when each of them lies within the first
   verification gate (a mirror image does not);
4. :func:`startrack.identify.verify.verify_near` with 4 seed stars and N_h = the combinations searched
   x the expected catalog patterns per look-up (:attr:`startrack.identify.pattern_catalog.PatternLevel.per_lookup`).

The first accepted hypothesis ends the search; otherwise the pyramid search follows, its N_h increased
by this one's (:func:`startrack.identify.lost_in_space.search_tables`).
"""

from __future__ import annotations

import math

import numpy as np

from startrack.base.errors import InputError
from startrack.compiled.numba_setup import njit
from startrack.geometry.rotation_kernels import wahba_svd, worst_cosine
from startrack.identify.features import apart, fill_features
from startrack.identify.pattern_catalog import (
    SEPARATION_PER_FOV,
    PatternCatalogParams,
    bin_ranges,
    build_level,
    edge_ratios,
    next_bins,
    pack_key,
    run_start,
)
from startrack.identify.pyramid import no_result
from startrack.identify.scale_free import (
    COMBINATIONS,
    COMBINATIONS_BELOW,
    MAX_CANDIDATES,
    angle_matrix,
    correspondence,
)
from startrack.identify.verify import PATTERN_SEEDS, verify_near

#: Brightest thinned centroids whose four-star combinations are looked up (7: 35 combinations).  Median
#: solve [us] on the benchmark frames (16 deg, 300 per set, solved in turn in one process) with 6 / 7 / 8:
#: 54 / 37 / 37 with 0-10 false stars, 29 / 29 / 28 with 0-3, 23 / 23 / 23 with none (pyramid alone: 59,
#: 46, 38): with 6 about half of the frames of the first set fall through to the pyramid.
HASH_STARS = 7

#: ``patterns`` of the search kernels when there is no pattern level (nothing is looked up).
NO_PATTERNS = (np.zeros((0, 4), np.int32), np.zeros(0, np.int64), np.full(16, -1, np.int32), 1.0, 2, 0, 1.0, 0.0)


def pattern_arrays(field, hash_stars: int = HASH_STARS):
    """The tuple the search kernels take for the field stars of an identifier
    (:class:`~startrack.identify.verify.FieldStars`): (pattern stars (P, 4) int32 into the field stars,
    keys, hash slots, bin width, bins per ratio, combinations searched, cos of the thinning separation,
    N_h); :data:`NO_PATTERNS` when the camera's field lies outside the pattern catalog's 0.5-90 deg.

    The bins are the pattern catalog's for that field (2 x its model tolerance + noise allowance,
    0.013 at 16 deg): with wider bins the patterns per key grow as the fifth power of the width (measured
    at 16 deg, V <= 6: 7x wider bins, 100x more candidates per look-up, 2 ms per frame), so frames whose
    centroid errors are too large for them (eps > half a bin) are left to the pyramid search."""
    fov = float(field.camera.fov_x)
    try:
        params = PatternCatalogParams(fov_min=fov, fov_max=fov)
    except InputError:
        return NO_PATTERNS
    level = build_level(field.vectors, field.v_mag, fov, params)
    n_combinations = int(COMBINATIONS_BELOW[min(hash_stars, MAX_CANDIDATES)])
    n_h = n_combinations * level.per_lookup
    return (np.ascontiguousarray(level.stars, np.int32), np.ascontiguousarray(level.keys, np.int64),
            np.ascontiguousarray(level.slots, np.int32), float(level.width), int(level.base), n_combinations,
            math.cos(SEPARATION_PER_FOV * fov), float(n_h))


@njit(_nrt=False)
def _sorted_angles(beta, gate, stars, angles):  # pragma: no cover  (compiled)
    """The six angles of the four centroids ``stars`` ascending into ``angles``; returns their largest bound."""
    e, worst = 0, 0.0
    for i in range(4):
        for j in range(i + 1, 4):
            angles[e] = beta[stars[i], stars[j]]
            worst = max(worst, gate[stars[i], stars[j]])
            e += 1
    for k in range(1, 6):  # insertion sort of six angles
        j = k
        while j > 0 and angles[j - 1] > angles[j]:
            angles[j - 1], angles[j] = angles[j], angles[j - 1]
            j -= 1
    return worst


@njit
def _candidate(obs, stars, cat, vectors, angles, bound, region, first_gate):  # pragma: no cover  (compiled)
    """(ok, R_IS): steps 2-3 of the module text for the catalog pattern ``cat`` (indices into ``vectors``)."""
    axis, cos_radius = region
    for i in range(4):
        v = vectors[cat[i]]
        if v[0] * axis[0] + v[1] * axis[1] + v[2] * axis[2] < cos_radius:
            return False, np.eye(3)
    ratios, largest, order = edge_ratios(vectors, cat)
    if abs(largest - angles[5]) > bound:
        return False, np.eye(3)
    for k in range(5):
        if abs(ratios[k] * largest - angles[k]) > bound:
            return False, np.eye(3)
    perm, _ = correspondence(angle_matrix(obs, stars), angle_matrix(vectors, cat))
    ref = np.empty((4, 3))
    seen = np.empty((4, 3))
    for i in range(4):
        ref[i] = vectors[cat[perm[i]]]
        seen[i] = obs[stars[i]]
    R_IS = wahba_svd(ref, seen)
    return worst_cosine(ref, seen, R_IS) >= math.cos(first_gate), R_IS


@njit
def hash_search(obs, beta, gate, filled, focal_px, delta_px, patterns, region, field):  # pragma: no cover
    """The first verified hypothesis of the pattern look-ups (module text; verify_near's tuple).

    ``obs`` (n, 3) directions brightest first with their features ``beta``, ``gate`` (filled here as
    needed); ``patterns``: :func:`pattern_arrays`; ``region`` (axis, cos rho): every star of a pattern
    within rho of the axis; ``field``: verify_near's tuple (its vectors are the pattern stars' index)."""
    cat_stars, keys, slots, width, base, n_combinations, cos_separation, n_h = patterns
    if n_combinations == 0:
        return no_result()
    vectors, first_gate = field[0], field[4][0]
    candidates = np.empty(MAX_CANDIDATES, np.int64)
    n_candidates = apart(obs, beta.shape[0], cos_separation, candidates)
    stop = min(n_combinations, COMBINATIONS_BELOW[n_candidates])
    if stop == 0:
        return no_result()
    fill_features(obs, candidates[COMBINATIONS[stop - 1, 3]] + 1, focal_px, delta_px, beta, gate, filled)
    stars = np.empty(4, np.int64)
    angles = np.empty(6)
    low = np.empty(5, np.int64)
    high = np.empty(5, np.int64)
    bins = np.empty(5, np.int64)
    for c in range(stop):
        for i in range(4):
            stars[i] = candidates[COMBINATIONS[c, i]]
        bound = _sorted_angles(beta, gate, stars, angles)
        eps = 2.0 * bound / angles[5]
        if eps > 0.5 * width:
            continue
        bin_ranges(angles, angles[5], eps, width, base, low, high)
        bins[:] = low
        while True:
            key = pack_key(bins, base)
            e = run_start(key, keys, slots)
            while 0 <= e < keys.size and keys[e] == key:
                ok, R_IS = _candidate(obs, stars, cat_stars[e], vectors, angles, bound, region, first_gate)
                if ok:
                    result = verify_near(obs, R_IS, field, n_h, PATTERN_SEEDS)
                    if result[0]:
                        return result
                e += 1
            if not next_bins(bins, low, high):
                break
    return no_result()
