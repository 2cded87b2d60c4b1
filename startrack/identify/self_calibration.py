"""Verification of a field-of-view-free hypothesis that calibrates the camera as it matches (compiled).

A hypothesis of the pattern search (:mod:`startrack.identify.scale_free`) is an attitude and a focal
length from four stars; the principal point is taken at the image centre and the distortion as zero.
Its predictions are good near the pattern and drift with the distance from it (focal-length error,
distortion), so the verification matches in passes with shrinking gates [px], each followed by the
least-squares fit of the attitude and the intrinsics (:func:`startrack.camera.fit.fit`):

1. the brightest ``first_stars`` detections against the brightest predicted stars, gate g_1 (the
   pattern's tolerance scaled to the image), attitude and focal length free;
2. every detection against the ``n_predicted`` brightest stars predicted in the image, gate g_2,
   every intrinsic of ``free`` with its prior; repeated (up to ``WIDE_PASSES`` times) while it matches
   ``GROWTH`` times the stars of the pass before;
3. the same at the final gate r, repeated (up to ``_EXTRA_PASSES`` times) while it adds stars; a
   hypothesis whose first pass there matches no more stars than chance would (:data:`HOPELESS`) is
   dropped at once (a wrong one: its last passes cost a crowded frame a third of its verification);
4. the depth of the catalog the frame shows (:func:`_detected_depth`: where the matched fraction of the
   predicted stars, brightest first, falls to the level of chance): matches of fainter stars are
   dropped (in a crowd of false detections they are chance neighbours); then matches the fit puts
   outside r, or beyond _OUTLIER (4) times their sigma scaled by the fit's sqrt(chi^2 / dof) (a
   compression artefact next to a star), are dropped and the fit repeated (up to _OUTLIER_ROUNDS times;
   the answer is always the fit of the matches it reports: a wrong match at a wide field's corner bends
   the distortion terms until it is dropped).

Matches are mutual nearest neighbours in the image (one-to-one).  The false-match probability of the
result is :func:`startrack.identify.chance.chance_match_probability` with the local density of the
detections around each predicted star (a density grid of the frame), the four seed stars removed,
and the Bonferroni factor N_h (g_1 / d)^n of the hypotheses the search and the n fitted parameters
could have produced (d the radius the matches reached, :mod:`startrack.identify.chance`); the chance
matches are counted over every predicted star, not only those above the detected depth (the depth is
chosen from the matches, so the count over all of them keeps the probability an upper bound).
"""

from __future__ import annotations

import math

import numpy as np

from startrack.camera.fit import fit
from startrack.camera.projection_kernels import (
    fold_radius_squared_jit,
    folds_inside,
    image_point,
    in_view,
    off_axis_angle,
    project,
)
from startrack.compiled.numba_setup import njit
from startrack.compiled.sorts import argsort, median, unique
from startrack.identify.chance import chance_match_probability, poisson_tail
from startrack.identify.zones import stars_near

#: Seed stars of a pattern hypothesis (matched by construction).
SEEDS = 4
#: Passes at the final gate beyond the first, made while they add stars.
_EXTRA_PASSES = 2
#: Passes at the second gate beyond the first, made while each matches GROWTH times the stars of the last: the
#: fit spreads from the pattern outwards over a strongly distorted field (a fisheye's corners).
WIDE_PASSES, GROWTH = 3, 1.1
#: Chance (the Poisson tail of the matches of the first pass at the final gate) above which a hypothesis
#: is dropped before its last passes: it matched about as many stars as a wrong one does.
HOPELESS = 0.5
#: A match whose residual exceeds this many of its sigma (scaled by the fit's sqrt(chi^2 / dof)) is dropped.
_OUTLIER = 4.0
#: Rounds of dropping outliers, each followed by the fit of the matches left.
_OUTLIER_ROUNDS = 3
#: Predicted stars this close to a detection [px] are one blend to it: the brightest of them is its match
#: (a double that Hipparcos-2 lists as one star and Gaia DR3 resolves, e.g. HIP 8544, G 5.9 and 7.2 at 2.9").
BLEND_PX = 1.0


@njit
def _match_pixels(obs_uv, n_obs, pred_uv, gate):  # pragma: no cover  (compiled)
    """One-to-one matches (obs index, pred index) of mutual nearest neighbours within ``gate`` [px] among
    the first ``n_obs`` observed points, the predictions brightest first: a point's neighbour is the
    brightest prediction within :data:`BLEND_PX` of it, else the nearest.  Predictions sorted by u, each
    point compares those within +-gate in u (a nearest neighbour outside that window lies outside the gate)."""
    m = pred_uv.shape[0]
    order = argsort(np.ascontiguousarray(pred_uv[:, 0]))
    u_sorted = pred_uv[order, 0]
    best_pred = np.full(n_obs, -1, np.int64)
    best_pred_d = np.full(n_obs, np.inf)
    best_obs = np.full(m, -1, np.int64)
    best_obs_d = np.full(m, np.inf)
    blend = BLEND_PX * BLEND_PX
    for i in range(n_obs):
        for e in range(np.searchsorted(u_sorted, obs_uv[i, 0] - gate), np.searchsorted(u_sorted, obs_uv[i, 0] + gate,
                                                                                        side="right")):
            j = order[e]
            d2 = (obs_uv[i, 0] - pred_uv[j, 0]) ** 2 + (obs_uv[i, 1] - pred_uv[j, 1]) ** 2
            blended = d2 <= blend and best_pred_d[i] <= blend
            if (j < best_pred[i]) if blended else d2 < best_pred_d[i]:
                best_pred_d[i], best_pred[i] = d2, j
            if d2 < best_obs_d[j]:
                best_obs_d[j], best_obs[j] = d2, i
    obs_index = np.empty(n_obs, np.int64)
    pred_index = np.empty(n_obs, np.int64)
    count = 0
    for i in range(n_obs):
        j = best_pred[i]
        if j >= 0 and best_obs[j] == i and best_pred_d[i] <= gate * gate:
            obs_index[count], pred_index[count] = i, j
            count += 1
    return obs_index[:count], pred_index[:count]


@njit
def brightest_in_field(expected, params, n_stars):  # pragma: no cover  (compiled)
    """How many of the ``n_stars`` catalog stars (brightest first, spread over the sky) to take so that
    about ``expected`` of them fall in the W x H field of the camera ``params`` (solid angle ~ W H / f^2)."""
    solid_angle = params[3] * params[4] / params[0] ** 2
    return int(min(n_stars, max(expected * 4.0 * math.pi / solid_angle, 1.0)))


@njit
def _stars_around(R_IS, params, field, max_star):  # pragma: no cover  (compiled)
    """Indices below ``max_star`` of the field stars within 1.2 times the image's corner angle of the
    boresight of R_IS for the camera ``params``, brightest first (ascending: the field stars are ordered
    brightest first); ``field`` = (vectors, v_mag, zones, number of stars within the magnitude cap).
    Gathered once per depth and hypothesis: the fits move the boresight and the scale by far less."""
    vectors, zones = field[0], field[2]
    f, cx, cy, width, height = params[0], params[1], params[2], params[3], params[4]
    half = math.hypot(max(cx + 0.5, width - 0.5 - cx), max(cy + 0.5, height - 0.5 - cy)) / f
    near = np.empty(vectors.shape[0], np.int64)
    radius = 1.2 * off_axis_angle(half, params[8]) + 0.005
    near = near[:stars_near(zones, vectors, R_IS[:, 2].copy(), radius, near, max_star)]
    return unique(near)


@njit
def _predicted_stars(R_IS, params, vectors, around, limit):  # pragma: no cover  (compiled)
    """(star indices, uv (m, 2)) of the first ``limit`` stars of ``around`` (brightest first) imaged inside
    the frame for R_IS and the camera ``params`` (:func:`startrack.camera.projection_kernels.camera_array`): imaged by
    its projection, within the fold radius of the distortion (:func:`startrack.camera.model.fold_radius_squared`)."""
    width, height = params[3], params[4]
    fold = fold_radius_squared_jit(params[5], params[6])
    keep = np.empty(min(limit, around.size), np.int64)
    uv = np.empty((keep.size, 2))
    count = 0
    for s in around:
        if count == keep.size:
            break
        vx = R_IS[0, 0] * vectors[s, 0] + R_IS[1, 0] * vectors[s, 1] + R_IS[2, 0] * vectors[s, 2]
        vy = R_IS[0, 1] * vectors[s, 0] + R_IS[1, 1] * vectors[s, 1] + R_IS[2, 1] * vectors[s, 2]
        vz = R_IS[0, 2] * vectors[s, 0] + R_IS[1, 2] * vectors[s, 1] + R_IS[2, 2] * vectors[s, 2]
        seen, x, y = in_view(vx, vy, vz, params, fold)
        if not seen:
            continue
        u, v = image_point(x, y, params)
        if -0.5 <= u <= width - 0.5 and -0.5 <= v <= height - 0.5:
            keep[count] = s
            uv[count, 0], uv[count, 1] = u, v
            count += 1
    return keep[:count], uv[:count]


@njit
def _residuals(uv, obs_index, model_uv):  # pragma: no cover  (compiled)
    """Distance [px] of each matched detection from its star's model position (``model_uv`` per match)."""
    out = np.empty(obs_index.size)
    for m in range(obs_index.size):
        out[m] = math.hypot(uv[obs_index[m], 0] - model_uv[m, 0], uv[obs_index[m], 1] - model_uv[m, 1])
    return out


@njit
def _fit_stars(uv, sigma, vectors, obs_index, star_index, R_IS, params, free, prior):  # pragma: no cover
    """:func:`startrack.camera.fit.fit` of the detections ``obs_index`` to the field stars ``star_index``."""
    ref = np.empty((obs_index.size, 3))
    seen = np.empty((obs_index.size, 2))
    weight_sigma = np.empty(obs_index.size)
    for m in range(obs_index.size):
        ref[m] = vectors[star_index[m]]
        seen[m] = uv[obs_index[m]]
        weight_sigma[m] = sigma[obs_index[m]]
    return fit(seen, weight_sigma, ref, R_IS, params, free, prior[0], prior[1])


@njit
def _fit_matches(uv, sigma, vectors, stars, obs_index, pred_index, R_IS, params, free, prior):  # pragma: no cover
    """:func:`_fit_stars` of the matches (obs_index, pred_index) to the predicted ``stars``."""
    return _fit_stars(uv, sigma, vectors, obs_index, stars[pred_index], R_IS, params, free, prior)


@njit
def _local_density(uv_points, grid):  # pragma: no cover  (compiled)
    """Detections per px^2 at each point (m, 2) from ``grid`` = (density map (gy, gx), cell width, cell
    height) [px^-2]."""
    density, cell_w, cell_h = grid
    out = np.empty(uv_points.shape[0])
    for m in range(uv_points.shape[0]):
        gx = min(max(int((uv_points[m, 0] + 0.5) / cell_w), 0), density.shape[1] - 1)
        gy = min(max(int((uv_points[m, 1] + 0.5) / cell_h), 0), density.shape[0] - 1)
        out[m] = density[gy, gx]
    return out


@njit
def verify_calibrate(uv, sigma, R_IS, params, field, settings, gates, n_hypotheses):  # pragma: no cover  (compiled)
    """Verification of the hypothesis (R_IS, params) of a pattern (module text).

    uv (n, 2) detections brightest first [px], sigma (n,) their centroid sigma [px]; ``params`` the
    camera (:func:`startrack.camera.projection_kernels.camera_array`); ``field`` for :func:`_stars_around`; ``settings`` =
    (final gate r [px], first_stars, n_predicted, free (5,) bool, prior (mean (5,), sigma (5,)), density
    grid, threshold); ``gates`` (3,) [px] g_1, g_2, r.  Returns (ok, R_IS, params, covariance (8, 8), obs
    indices, star indices, P_false, stars predicted, radius reached [px], chi^2 / dof).
    """
    _, first_stars, n_predicted, free, prior, _, _ = settings
    vectors = field[0]
    around = _stars_around(R_IS, params, field, brightest_in_field(4.0 * first_stars, params, field[3]))
    empty = np.zeros(0, np.int64)
    covariance = np.zeros((8, 8))
    reduced = 0.0
    first_free = np.zeros(5, np.bool_)
    first_free[0] = free[0]
    stage, runs, previous = 0, 0, 0  # the gate's index, the passes made at it, the stars the last pass matched
    for p in range(3 + WIDE_PASSES + _EXTRA_PASSES):
        gate = gates[stage]
        if p == 1:  # as deep as needed for about 4 n_predicted stars in the field, at most the magnitude cap
            around = _stars_around(R_IS, params, field, brightest_in_field(4.0 * n_predicted, params, field[3]))
        stars, pred_uv = _predicted_stars(R_IS, params, vectors, around, first_stars if p == 0 else n_predicted)
        obs_index, pred_index = _match_pixels(uv, min(first_stars, uv.shape[0]) if p == 0 else uv.shape[0], pred_uv, gate)
        if stage == 2 and runs > 0 and obs_index.size <= previous:
            break  # the final gate adds no more stars
        if obs_index.size < SEEDS + 1 or (stage == 2 and runs == 0 and _hopeless(pred_uv, settings[5], gate, obs_index.size)):
            return False, R_IS, params, covariance, empty, empty, 1.0, stars.size, gate, reduced
        ok, R_IS, params, covariance, reduced = _fit_matches(uv, sigma, vectors, stars, obs_index, pred_index, R_IS,
                                                             params, first_free if p == 0 else free, prior)
        if not ok:
            return False, R_IS, params, covariance, empty, empty, 1.0, stars.size, gate, reduced
        runs, grew, previous = runs + 1, obs_index.size > GROWTH * previous, obs_index.size
        if stage == 0 or (stage == 1 and (runs > WIDE_PASSES or not grew)):
            stage, runs = stage + 1, 0
        elif stage == 2 and runs > _EXTRA_PASSES:
            break
    return _conclude(uv, sigma, R_IS, params, vectors, around, settings, gates, n_hypotheses, covariance, reduced)


@njit
def _hopeless(pred_uv, grid, gate, n_matches):  # pragma: no cover  (compiled)
    """Whether the first pass at the final gate matched no more stars than chance would (the Poisson tail of
    its matches beyond the seeds above HOPELESS): a wrong hypothesis, not worth the passes left."""
    expected = -np.expm1(-_local_density(pred_uv, grid) * math.pi * gate * gate)
    return poisson_tail(np.sum(expected), n_matches - SEEDS) > HOPELESS


@njit
def _conclude(uv, sigma, R_IS, params, vectors, around, settings, gates, n_hypotheses, covariance,
              reduced):  # pragma: no cover  (compiled)
    """The last step of :func:`verify_calibrate` (module text, step 4) and its false-match probability;
    returns verify_calibrate's tuple."""
    _, _, n_predicted, free, prior, grid, threshold = settings
    empty = np.zeros(0, np.int64)
    stars, pred_uv = _predicted_stars(R_IS, params, vectors, around, n_predicted)
    obs_index, pred_index = _match_pixels(uv, uv.shape[0], pred_uv, gates[2])
    chance = -np.expm1(-_local_density(pred_uv, grid) * math.pi * gates[2] ** 2)
    deep = pred_index < _detected_depth(pred_index, stars.size, chance)
    obs_index, star_index = obs_index[deep], stars[pred_index[deep]]
    for rounds in range(_OUTLIER_ROUNDS + 1):
        if obs_index.size < SEEDS + 1:
            return False, R_IS, params, covariance, empty, empty, 1.0, stars.size, gates[2], reduced
        ok, R_IS, params, covariance, reduced = _fit_stars(uv, sigma, vectors, obs_index, star_index, R_IS, params,
                                                           free, prior)
        if not ok:
            return False, R_IS, params, covariance, empty, empty, 1.0, stars.size, gates[2], reduced
        if rounds == _OUTLIER_ROUNDS:
            break  # the answer is the fit of the matches it reports
        residual = _residuals(uv, obs_index, project(_sensor(vectors, star_index, R_IS), params))
        keep = (residual <= gates[2]) & (residual <= _OUTLIER * math.sqrt(max(reduced, 1.0)) * sigma[obs_index])
        if keep.all():
            break
        obs_index, star_index = obs_index[keep], star_index[keep]
    if folds_inside(params):  # not a lens: its image would fold back on itself
        return False, R_IS, params, covariance, empty, empty, 1.0, stars.size, gates[2], reduced
    reached = _residuals(uv, obs_index, project(_sensor(vectors, star_index, R_IS), params)).max()
    reached = min(max(reached, median(sigma)), gates[2])
    q = _local_density(pred_uv, grid) * math.pi * reached * reached
    bonferroni = n_hypotheses * (gates[0] / reached) ** (3 + int(np.sum(free)))
    probability = chance_match_probability(q, obs_index.size - SEEDS, bonferroni)
    return (probability <= threshold, R_IS, params, covariance, obs_index, star_index, probability, stars.size,
            reached, reduced)


#: Predicted stars per window of :func:`_detected_depth`.
_DEPTH_WINDOW = 20


@njit
def _detected_depth(pred_index, n_predicted, chance):  # pragma: no cover  (compiled)
    """How many of the ``n_predicted`` stars (brightest first) the frame shows: the end of the last
    window of _DEPTH_WINDOW consecutive stars of which at least max(1/4, 4 x the mean chance of a
    detection within the gate) are matched (``pred_index`` the matched ones); all of them for fewer
    than _DEPTH_WINDOW.  Fainter stars than that are not in the image (its catalog depth): their
    matches are detections near them by chance."""
    if n_predicted <= _DEPTH_WINDOW:
        return n_predicted
    matched = np.zeros(n_predicted, np.int64)
    matched[pred_index] = 1
    floor = max(0.25, 4.0 * chance.mean()) * _DEPTH_WINDOW
    running = matched[:_DEPTH_WINDOW].sum()
    depth = _DEPTH_WINDOW if running >= floor else 0
    for end in range(_DEPTH_WINDOW, n_predicted):
        running += matched[end] - matched[end - _DEPTH_WINDOW]
        if running >= floor:
            depth = end + 1
    return max(depth, _DEPTH_WINDOW)


@njit
def _sensor(vectors, star_index, R_IS):  # pragma: no cover  (compiled)
    v_S = np.empty((star_index.size, 3))
    for m in range(star_index.size):
        for c in range(3):
            v_S[m, c] = (R_IS[0, c] * vectors[star_index[m], 0] + R_IS[1, c] * vectors[star_index[m], 1]
                         + R_IS[2, c] * vectors[star_index[m], 2])
    return v_S
