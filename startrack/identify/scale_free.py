"""Field-of-view-free star identification: observed four-star patterns looked up by their edge ratios.

For the brightest detections (thinned to a minimum separation, :func:`pattern_candidates`), the
four-star combinations are taken breadth first -- every combination of the first n stars before any
with star n + 1 (:data:`COMBINATIONS`) -- and each is looked up in every level of the pattern catalog
(:mod:`startrack.identify.pattern_catalog`), the levels nearest a field-of-view hint first:

1. unit vectors with the level's focal length f_l (principal point at the image centre), the five
   edge ratios and their tolerance eps = level tolerance + 4 sqrt 2 sigma / e_6 (e_6 the largest edge
   [px], sigma the largest centroid sigma of the four);
2. every key of the bins within +-eps of the ratios; each catalog pattern of those keys whose ratios
   all lie within eps is a candidate;
3. the star correspondence: of the 24 assignments of the catalog stars to the observed ones, the one
   with the smallest sum of squared ratio differences over the six edges;
4. the focal length f with the observed angles' sum equal to the catalog's (fixed-point iteration
   f <- f S(f) / S_cat, S the sum of the six angles: the angles scale as 1/f to first order), kept
   when the field of view lies in the allowed range;
5. the attitude by SVD (Wahba's problem, Markley 1988) of the four stars; a mirror image of the
   pattern (same edges, other handedness) leaves residuals of the pattern's own size and is dropped;
6. in a rich frame, a screen: :func:`startrack.identify.self_calibration.verify_calibrate` against the
   brightest ``screen`` predicted stars (150 of up to 1000: a third of the cost, so that a crowded frame
   tries three times the hypotheses in its budget) with a loose test (the chance of its matches alone,
   without the look-elsewhere factor, below the screen's threshold); then the hypotheses it passes, and every
   hypothesis of a frame no richer than the screen, are verified at the full depth of ``settings`` (the
   answer is that verification's, as without the screen); the first accepted hypothesis ends the search.

One compiled call searches the combinations [start, stop), from candidate ``skip`` of the first, and
returns after at most ``max_tried`` verified hypotheses with the place to resume (the same order of
hypotheses whatever the calls' sizes); the caller checks the time budget between calls.  N_h, the
hypotheses the search can make, counts every combination of the candidates times
the expected catalog candidates per look-up of each level
(:attr:`~startrack.identify.pattern_catalog.PatternLevel.per_lookup`).
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from startrack.camera.projection_kernels import ray_one
from startrack.compiled.numba_setup import njit
from startrack.compiled.sorts import argsort
from startrack.geometry.rotation_kernels import wahba_svd, worst_cosine
from startrack.identify.pattern_catalog import bin_ranges, edge_ratios, next_bins, pack_key, run_start
from startrack.identify.self_calibration import brightest_in_field, verify_calibrate
from startrack.identify.zones import stars_near

#: Most detections whose combinations are searched.
MAX_CANDIDATES = 24
#: Four-star combinations of range(MAX_CANDIDATES), breadth first (largest member ascending, then lexical).
COMBINATIONS = np.array(sorted(itertools.combinations(range(MAX_CANDIDATES), 4), key=lambda c: (c[3], c)), np.int64)
#: The 24 assignments of four catalog stars to four observed ones.
_PERMUTATIONS = np.array(list(itertools.permutations(range(4))), np.int64)
#: Combinations whose largest member is below n, for n = 0 .. MAX_CANDIDATES.
COMBINATIONS_BELOW = np.searchsorted(COMBINATIONS[:, 3], np.arange(MAX_CANDIDATES + 1)).astype(np.int64)


def pattern_candidates(uv, separation_px: float, limit: int = MAX_CANDIDATES) -> np.ndarray:
    """Indices of the first ``limit`` detections (brightest first) kept by thinning to a minimum
    separation [px] (the pattern catalog's thinning in the image)."""
    kept = []
    for i in range(len(uv)):
        if all((uv[i, 0] - uv[j, 0]) ** 2 + (uv[i, 1] - uv[j, 1]) ** 2 >= separation_px**2 for j in kept):
            kept.append(i)
            if len(kept) == limit:
                break
    return np.array(kept, np.int64)


@njit
def _unit_vectors(uv, stars, focal, cx, cy, projection):  # pragma: no cover  (compiled)
    """(4, 3) directions in S of the detections ``uv[stars]`` through an undistorted camera of focal length
    ``focal`` [px], principal point (cx, cy) and the projection code."""
    out = np.empty((4, 3))
    for i in range(4):
        out[i, 0], out[i, 1], out[i, 2] = ray_one((uv[stars[i], 0] - cx) / focal, (uv[stars[i], 1] - cy) / focal,
                                                  projection)
    return out


@njit
def angle_matrix(vectors, stars):  # pragma: no cover  (compiled)
    """(4, 4) angular distances [rad] of the four unit vectors ``vectors[stars]``."""
    out = np.zeros((4, 4))
    for i in range(4):
        for j in range(i + 1, 4):
            a, b = vectors[stars[i]], vectors[stars[j]]
            c = min(1.0, max(-1.0, a[0] * b[0] + a[1] * b[1] + a[2] * b[2]))
            out[i, j] = out[j, i] = math.acos(c)
    return out


@njit
def correspondence(observed, catalog):  # pragma: no cover  (compiled)
    """(permutation p, cost): catalog star p[i] for observed star i minimising the sum of squared
    differences of the six normalised angles (``observed``, ``catalog``: (4, 4) angle matrices)."""
    scale_o, scale_c = observed.max(), catalog.max()
    best, best_cost = 0, np.inf
    for k in range(_PERMUTATIONS.shape[0]):
        p = _PERMUTATIONS[k]
        cost = 0.0
        for i in range(4):
            for j in range(i + 1, 4):
                cost += (observed[i, j] / scale_o - catalog[p[i], p[j]] / scale_c) ** 2
        if cost < best_cost:
            best, best_cost = k, cost
    return _PERMUTATIONS[best], best_cost


@njit
def _focal_length(uv, stars, cx, cy, projection, focal, catalog_sum):  # pragma: no cover  (compiled)
    """f [px] with the six observed angles summing to ``catalog_sum`` (module text, step 4)."""
    index = np.arange(4)
    for _ in range(4):
        vectors = _unit_vectors(uv, stars, focal, cx, cy, projection)
        focal *= angle_matrix(vectors, index).sum() / (2.0 * catalog_sum)
    return focal


@njit
def _hypothesis(uv, stars, cat, vectors, cx, cy, projection, f_start, f_range, eps):  # pragma: no cover  (compiled)
    """(ok, R_IS, f) of the observed pattern ``stars`` (indices into uv) matched to the catalog pattern
    ``cat`` (indices into vectors) under the projection code: correspondence, focal length, attitude and
    the mirror check."""
    catalog = angle_matrix(vectors, cat)
    observed = angle_matrix(_unit_vectors(uv, stars, f_start, cx, cy, projection), np.arange(4))
    perm, cost = correspondence(observed, catalog)
    if cost > 6.0 * eps * eps:
        return False, np.eye(3), 0.0
    focal = _focal_length(uv, stars, cx, cy, projection, f_start, catalog.sum() / 2.0)
    if not f_range[0] <= focal <= f_range[1]:
        return False, np.eye(3), 0.0
    seen = _unit_vectors(uv, stars, focal, cx, cy, projection)
    ref = np.empty((4, 3))
    for i in range(4):
        ref[i] = vectors[cat[perm[i]]]
    R_IS = wahba_svd(ref, seen)
    worst = math.acos(min(1.0, worst_cosine(ref, seen, R_IS)))
    return worst <= 3.0 * eps * catalog.max(), R_IS, focal


#: Brightest candidates beyond a pattern's four that :func:`_more_stars` looks up, and how many must be found.
EXTRA_LOOKUPS, EXTRA_FOUND = 8, 2


@njit
def _more_stars(uv, candidates, members, R_IS, focal, cx, cy, projection, gate, field, near):  # pragma: no cover
    """Whether at least EXTRA_FOUND (or all, if fewer remain) of the next EXTRA_LOOKUPS brightest
    candidates outside the pattern ``members`` fall within ``gate`` [rad] of a field star under the
    hypothesis (R_IS, undistorted f and projection): the fifth-star check of the pyramid search
    (001 §4.4.3) before the costly verification."""
    vectors, zones = field[0], field[2]
    params = np.array([focal, cx, cy, 2.0 * cx + 1.0, 2.0 * cy + 1.0])
    max_star = brightest_in_field(3.0 * (4 + EXTRA_LOOKUPS), params, field[3])
    direction = np.empty(3)
    looked, found = 0, 0
    for i in range(candidates.size):
        if looked == EXTRA_LOOKUPS or found == EXTRA_FOUND:
            break
        if i == members[0] or i == members[1] or i == members[2] or i == members[3]:
            continue
        looked += 1
        x, y, z = ray_one((uv[candidates[i], 0] - cx) / focal, (uv[candidates[i], 1] - cy) / focal, projection)
        for k in range(3):
            direction[k] = R_IS[k, 0] * x + R_IS[k, 1] * y + R_IS[k, 2] * z
        if stars_near(zones, vectors, direction, gate, near, max_star) > 0:
            found += 1
    return found >= min(EXTRA_FOUND, looked)


@njit
def _gates(eps, width, final):  # pragma: no cover  (compiled)
    """(g_1, g_2, r) [px]: the first gate covers the pattern's relative error eps across the image width
    (twice over), within [4 r, width / 20]; the second is a quarter of it, at least 2 r."""
    first = min(max(2.0 * eps * width, 4.0 * final), max(width / 20.0, 4.0 * final))
    return np.array([first, max(first / 4.0, 2.0 * final), final])


#: Most ratio bins one look-up visits (a clean pattern visits 2^5): a pattern whose centroid sigma makes its
#: tolerance wider is skipped at that level, so that no look-up runs past the time budget (a defocused
#: star's 7 px sigma took one 7 deg look-up to ~10^9 bins, 16 s).
_MAX_BINS = 4096
#: Catalog candidates gathered per observed pattern (over every level) before they are verified.
_CANDIDATE_BUFFER = 256


@njit
def _gather(uv, stars, largest_px, worst_sigma, levels, entries, vectors, cx, cy, region, found):  # pragma: no cover
    """Catalog patterns matching the observed ``stars`` in every entry (level and projection) of
    ``entries``, with their first star inside ``region`` = (axis (3,), cos rho) (cos rho = -2: the whole
    sky): rows (entry, pattern row) of ``found`` and their ratio mismatch max_k |r_k - r_k,cat| and
    tolerance eps; returns (count, mismatch, eps) (module text, steps 1-2)."""
    entry_level, entry_projection, entry_focal, entry_tolerance = entries
    axis, cos_radius = region
    bins = np.empty(5, np.int64)
    low = np.empty(5, np.int64)
    high = np.empty(5, np.int64)
    mismatch = np.empty(found.shape[0])
    tolerance_of = np.empty(found.shape[0])
    count = 0
    for n in range(entry_level.size):
        cat_stars, keys, slots, width, base, _ = levels[entry_level[n]]
        seen = _unit_vectors(uv, stars, entry_focal[n], cx, cy, entry_projection[n])
        ratios, _, _ = edge_ratios(seen, np.arange(4))
        eps = entry_tolerance[n] + 4.0 * math.sqrt(2.0) * worst_sigma / largest_px
        bin_ranges(ratios, 1.0, eps, width, base, low, high)
        if np.prod(high - low + 1) > _MAX_BINS:
            continue  # ratios this uncertain (a blurred star's sigma) would match most of the level
        bins[:] = low
        while True:
            key = pack_key(bins, base)
            e = run_start(key, keys, slots)
            while 0 <= e < keys.size and keys[e] == key and count < found.shape[0]:
                first = vectors[cat_stars[e, 0]]
                if first[0] * axis[0] + first[1] * axis[1] + first[2] * axis[2] < cos_radius:
                    e += 1
                    continue
                cat_ratios, _, _ = edge_ratios(vectors, cat_stars[e])
                worst = np.abs(cat_ratios - ratios).max()
                if worst <= eps:
                    found[count, 0], found[count, 1] = n, e
                    mismatch[count], tolerance_of[count] = worst, eps
                    count += 1
                e += 1
            if not next_bins(bins, low, high):
                break
    return count, mismatch[:count], tolerance_of[:count]


@njit
def search(uv, sigma, candidates, start, stop, skip, max_tried, levels, entries, vectors, f_range, camera, region, field,
           settings, screen, n_hypotheses):  # pragma: no cover  (compiled)
    """Search the combinations [start, stop) of :data:`COMBINATIONS` over ``candidates`` (module text),
    the first from its ``skip``-th catalog candidate; the catalog candidates of a combination are verified
    in order of their ratio mismatch, at most ``max_tried`` of them in this call.

    uv (n, 2), sigma (n,): detections brightest first [px]; ``levels``: tuple of
    :attr:`~startrack.identify.pattern_catalog.PatternLevel.arrays`; ``entries`` = (level (e,), projection
    code (e,), focal length (e,) [px], ratio tolerance (e,)): the look-ups of each observed pattern, in
    order; ``vectors`` the pattern stars' unit vectors; f_range (2, 2) [px] the focal lengths allowed
    per projection code; ``camera`` (:func:`startrack.camera.projection_kernels.camera_array`) the start of the
    calibration (f and the projection replaced); ``region`` for :func:`_gather`; ``settings`` per
    projection code (:func:`verify_calibrate`'s), ``screen`` the same with fewer predicted stars (step 6).
    Returns (verify_calibrate's tuple, hypotheses verified, the combination and candidate to resume at)."""
    cx, cy = camera[1], camera[2]
    near = np.empty(field[0].shape[0], np.int64)
    stars = np.empty(4, np.int64)
    found = np.empty((_CANDIDATE_BUFFER, 2), np.int64)
    tried = 0
    stop = min(stop, COMBINATIONS_BELOW[candidates.size])
    for c in range(start, stop):
        for i in range(4):
            stars[i] = candidates[COMBINATIONS[c, i]]
        largest_px, worst_sigma = 0.0, 0.0
        for i in range(4):
            worst_sigma = max(worst_sigma, sigma[stars[i]])
            for j in range(i + 1, 4):
                largest_px = max(largest_px, math.hypot(uv[stars[i], 0] - uv[stars[j], 0], uv[stars[i], 1] - uv[stars[j], 1]))
        count, mismatch, eps_of = _gather(uv, stars, largest_px, worst_sigma, levels, entries, vectors, cx, cy, region,
                                          found)
        ranked = argsort(mismatch)
        for n in range(skip if c == start else 0, ranked.size):
            k = ranked[n]
            e, eps = found[k, 0], eps_of[k]
            projection = entries[1][e]
            p = int(projection)
            cat = levels[entries[0][e]][0][found[k, 1]]
            ok, R_IS, focal = _hypothesis(uv, stars, cat, vectors, cx, cy, projection, entries[2][e], f_range[p], eps)
            if not ok:
                continue
            gates = _gates(eps, camera[3], settings[p][0])
            if not _more_stars(uv, candidates, COMBINATIONS[c], R_IS, focal, cx, cy, projection, gates[0] / focal, field,
                               near):
                continue
            tried += 1
            params = camera.copy()
            params[0], params[8] = focal, projection
            screened_out = screen[p][2] < settings[p][2] and not verify_calibrate(uv, sigma, R_IS, params.copy(), field,
                                                                                  screen[p], gates, 0.0)[0]
            if not screened_out:
                result = verify_calibrate(uv, sigma, R_IS, params, field, settings[p], gates, n_hypotheses)
                if result[0]:
                    return result, tried, c + 1, 0
            if tried >= max_tried:
                return _nothing(camera), tried, c, n + 1
    return _nothing(camera), tried, stop, 0


@njit
def _nothing(camera):  # pragma: no cover  (compiled)
    empty = np.zeros(0, np.int64)
    return False, np.eye(3), camera.copy(), np.zeros((8, 8)), empty, empty, 1.0, 0, 0.0, 0.0
