"""Verification of an attitude hypothesis against every star that can appear in the field.

Steps (the verification of the issue; the same for lost-in-space, sub-catalog and tracking):

1. predict: rotate the field stars near the hypothesised boresight into the sensor frame and keep
   those that project inside the image (:class:`FieldStars`);
2. match: each centroid to its nearest predicted star and back (mutual nearest neighbours, so the
   matching is one-to-one), kept only within the gate; outliers are the centroids outside it;
3. refit: match within 3 r of the hypothesis and refit the attitude by SVD (Wahba's problem,
   Markley 1988) with every matched star, then match within r and refit again, repeated while it
   adds stars; matches the last refit puts outside r are dropped and the attitude refitted once
   more (tracking first matches within its window);
4. accept: only if the false-match probability (:func:`false_match_probability`) is below a threshold.

Probability model.  Under a *wrong* attitude hypothesis the centroids are unrelated to the predicted
stars.  The predicted stars form a Poisson field of density rho = n_field / Omega_field on the sky
(n_field predicted stars in the field's solid angle Omega_field, i.e. the local density), so a given
centroid falls within the gate r of some predicted star with probability

    p = 1 - exp(-rho * 2 pi (1 - cos r)).

The two stars that seeded the hypothesis match by construction; each of the other n_other centroids
matches independently with probability p, so the number K of chance matches is Binomial(n_other, p).
A search that generated N_h hypotheses (every catalog pair that matched an observed pair within its
gate, both orientations) can be fooled by any of them, hence (Bonferroni)

    P_false = min(1, N_h * P[Binomial(n_other, p) >= K]).

The radius is the one the matches reached: d_K, the largest angle between a matched centroid and its
star after the final refit (never below the centroid noise sigma, never above the gate r).  P[Binomial
(n_other, p(d)) >= K] is the probability that the K-th closest chance match lies within d, i.e. the
exact tail of the observed order statistic, so it is as valid as the fixed gate and far sharper for
frames with few stars (4 true stars among false ones: p(2 sigma) is 6x smaller than p(5 sigma) per
star).  A hypothesis is accepted when P_false <= threshold (default 1e-6).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from startrack.camera.projection_kernels import camera_array, fold_radius_squared_jit, image_point, in_view
from startrack.catalog.navigation import chord
from startrack.compiled.numba_setup import njit
from startrack.compiled.sorts import argsort
from startrack.geometry.rotation_kernels import wahba_svd
from startrack.identify.zones import stars_near, zone_index

#: Default acceptance threshold of the false-match probability.
DEFAULT_FALSE_MATCH_THRESHOLD = 1e-6


@njit
def binomial_tail(n, k, p):
    """P[Binomial(n, p) >= k], summed term by term from k upwards (accurate for tiny p)."""
    if k <= 0:
        return 1.0
    if k > n or p <= 0.0:
        return 0.0
    if p >= 1.0:
        return 1.0
    log_term = math.lgamma(n + 1) - math.lgamma(k + 1) - math.lgamma(n - k + 1) + k * math.log(p)\
        + (n - k) * math.log1p(-p)
    term = math.exp(log_term)
    total = term
    ratio = p / (1.0 - p)
    for j in range(k, n):
        term *= (n - j) / (j + 1) * ratio
        total += term
        if term < 1e-17 * total:
            break
    return min(total, 1.0)


@njit
def false_match_probability(n_other, n_matched_other, gate, density, n_hypotheses):
    """P_false of the module model: min(1, N_h P[Binomial(n_other, p) >= K]).

    n_other: centroids besides the two seed stars; n_matched_other: K, those matched; gate: r [rad];
    density: rho, predicted stars per steradian; n_hypotheses: N_h.
    """
    p = -math.expm1(-density * 2.0 * math.pi * (1.0 - math.cos(gate)))
    return min(1.0, max(n_hypotheses, 1) * binomial_tail(n_other, n_matched_other, p))


#: Stars that seed a hypothesis of each strategy: tracking, the pyramid's triangle, a four-star pattern.
#: Numpy integers, so that every caller passes verify_near the same types (one compiled version, not one
#: per literal).
NO_SEEDS, TRIANGLE_SEEDS, PATTERN_SEEDS = np.int64(0), np.int64(2), np.int64(4)


@njit
def verify_near(obs_S, R_IS, field, n_hypotheses, n_seed):  # pragma: no cover  (compiled)
    """Verification (module text) of the attitude hypothesis R_IS for the centroid directions ``obs_S``
    (n, 3) in one compiled call.  ``field`` = (vectors, zone index (:mod:`startrack.identify.zones`),
    radius [rad] around the boresight holding every star the image can show, camera parameters, pass
    gates [rad], f [px], field solid angle [sr], threshold, centroid noise sigma [rad]); ``n_seed`` stars
    seeded the hypothesis, ``n_hypotheses`` N_h.  Returns (ok, R_IS, obs indices, star indices into
    the vectors, P_false, stars predicted in the field)."""
    vectors, zones, radius, camera_params, pass_gates, focal_px, solid_angle, threshold, sigma = field
    near = np.empty(vectors.shape[0], np.int64)
    near = near[:stars_near(zones, vectors, R_IS[:, 2].copy(), radius, near)]
    stars = vectors[near]
    ok, R_IS, obs_index, star_index, n_predicted = _match_and_refit(obs_S, stars, R_IS, camera_params, pass_gates,
                                                                   focal_px)
    if not ok:
        return False, R_IS, obs_index, star_index, 1.0, n_predicted
    reached = 1.0
    for m in range(obs_index.size):  # cosine of the largest residual
        star = stars[star_index[m]]
        cosine = 0.0
        for c in range(3):
            cosine += (star[0] * R_IS[0, c] + star[1] * R_IS[1, c] + star[2] * R_IS[2, c]) * obs_S[obs_index[m], c]
        reached = min(reached, cosine)
    gate = min(max(np.arccos(min(reached, 1.0)), sigma), pass_gates[-1])
    probability = false_match_probability(max(obs_S.shape[0] - n_seed, 0), max(obs_index.size - n_seed, 0),
                                          gate, max(n_predicted, 1) / solid_angle, n_hypotheses)
    return probability <= threshold, R_IS, obs_index, near[star_index], probability, n_predicted


@njit
def match_nearest(obs_S, pred_S, gate):  # pragma: no cover  (compiled)
    """One-to-one matches (obs index, pred index) of mutual nearest neighbours within ``gate`` [rad].

    Only pairs whose x components differ by at most the chord of the gate, 2 sin(gate / 2), can lie
    within it; the predictions are sorted by x and each centroid compares those in its window.  A
    nearest neighbour outside the window lies outside the gate, so the matches are those of the
    comparison of every pair.
    """
    n, m = obs_S.shape[0], pred_S.shape[0]
    cos_gate = np.cos(gate)
    width = 2.0 * np.sin(0.5 * min(gate, np.pi)) * (1.0 + 1e-12)
    order = argsort(np.ascontiguousarray(pred_S[:, 0]))
    x = pred_S[order, 0]
    best_pred = np.full(n, -1, np.int64)
    best_pred_cos = np.full(n, -2.0)
    best_obs = np.full(m, -1, np.int64)
    best_obs_cos = np.full(m, -2.0)
    for i in range(n):
        for e in range(np.searchsorted(x, obs_S[i, 0] - width), np.searchsorted(x, obs_S[i, 0] + width, side="right")):
            j = order[e]
            c = obs_S[i, 0] * pred_S[j, 0] + obs_S[i, 1] * pred_S[j, 1] + obs_S[i, 2] * pred_S[j, 2]
            if c > best_pred_cos[i]:
                best_pred_cos[i] = c
                best_pred[i] = j
            if c > best_obs_cos[j]:
                best_obs_cos[j] = c
                best_obs[j] = i
    count = 0
    obs_index = np.empty(n, np.int64)
    pred_index = np.empty(n, np.int64)
    for i in range(n):
        j = best_pred[i]
        if j >= 0 and best_obs[j] == i and best_pred_cos[i] >= cos_gate:
            obs_index[count] = i
            pred_index[count] = j
            count += 1
    return obs_index[:count], pred_index[:count]


@njit
def predict(stars_I, R_IS, camera_params, margin_px):  # pragma: no cover  (compiled)
    """(indices, directions in S (m, 3)) of the stars ``stars_I`` (N, 3) imaged inside the field for R_IS.

    ``camera_params`` (:func:`startrack.camera.projection_kernels.camera_array`) [px]; the image (and, if circular, the
    inscribed circle of the width) is grown by ``margin_px``; the projection and radial distortion of
    :class:`startrack.camera.model.Camera`.
    """
    cx, cy, width, height, circular = camera_params[1], camera_params[2], camera_params[3], camera_params[4], camera_params[7]
    fold = fold_radius_squared_jit(camera_params[5], camera_params[6])
    v_S = np.empty_like(stars_I)
    for s in range(stars_I.shape[0]):
        for c in range(3):
            v_S[s, c] = stars_I[s, 0] * R_IS[0, c] + stars_I[s, 1] * R_IS[1, c] + stars_I[s, 2] * R_IS[2, c]
    keep = np.empty(v_S.shape[0], np.int64)
    count = 0
    radius = width / 2.0 + margin_px
    for s in range(v_S.shape[0]):
        seen, x, y = in_view(v_S[s, 0], v_S[s, 1], v_S[s, 2], camera_params, fold)
        if not seen:
            continue  # not imaged, or beyond the fold of the distortion polynomial
        u, v = image_point(x, y, camera_params)
        if u < -0.5 - margin_px or u > width - 0.5 + margin_px or v < -0.5 - margin_px or v > height - 0.5 + margin_px:
            continue
        if circular > 0.0 and (u - cx) ** 2 + (v - cy) ** 2 > radius * radius:
            continue
        keep[count] = s
        count += 1
    return keep[:count], v_S[keep[:count]]


#: Repetitions of the final-gate pass of :func:`_match_and_refit` allowed while they add stars.
_EXTRA_PASSES = 3


@njit
def _match_and_refit(obs_S, stars_I, R_IS, camera_params, pass_gates, focal_px):  # pragma: no cover  (compiled)
    """Predict, match (mutual nearest within each gate of ``pass_gates`` [rad] in turn) and refit by SVD.

    Each pass predicts with the field grown by its gate, matches, and refits with every match; the
    final gate is repeated (up to ``_EXTRA_PASSES`` times) while it adds stars, since a first fit from
    a few stars may leave distant ones outside the gate; once every centroid is matched no further
    pass is made; a last check drops matches outside the final gate and refits.  Returns (ok, R_IS, obs indices, star
    indices, number of stars predicted in the field); ok is False below 3 matches.
    """
    empty = np.zeros(0, np.int64)
    n_predicted = 0
    obs_index = empty
    star_index = empty
    n_passes = pass_gates.size + _EXTRA_PASSES
    for p in range(n_passes):
        gate = pass_gates[min(p, pass_gates.size - 1)]
        index, pred_S = predict(stars_I, R_IS, camera_params, gate * focal_px)
        n_predicted = index.size
        previous = obs_index.size
        obs_index, pred_index = match_nearest(obs_S, pred_S, gate)
        if obs_index.size < 3:
            return False, R_IS, empty, empty, n_predicted
        star_index = index[pred_index]
        R_IS = wahba_svd(stars_I[star_index], obs_S[obs_index])
        if obs_index.size == obs_S.shape[0] or (p >= pass_gates.size - 1 and obs_index.size <= previous):
            break  # every centroid matched (later passes could only drop some, as the last check does), or
            # the final gate no longer adds stars
    cos_gate = np.cos(pass_gates[-1])
    keep = np.empty(obs_index.size, np.bool_)
    for m in range(obs_index.size):
        star, obs = star_index[m], obs_index[m]
        cosine = 0.0
        for c in range(3):
            cosine += (stars_I[star, 0] * R_IS[0, c] + stars_I[star, 1] * R_IS[1, c]
                       + stars_I[star, 2] * R_IS[2, c]) * obs_S[obs, c]
        keep[m] = cosine >= cos_gate
    if not keep.all():
        obs_index, star_index = obs_index[keep], star_index[keep]
        if obs_index.size < 3:
            return False, R_IS, empty, empty, n_predicted
        R_IS = wahba_svd(stars_I[star_index], obs_S[obs_index])
    return True, R_IS, obs_index, star_index, n_predicted


#: Margin [rad] around the field radius within which :func:`verify_near` projects the field stars.
_FIELD_MARGIN = 0.01


def _field_radius(camera) -> float:
    """Largest angle [rad] between the boresight and an image corner (pixel edges included)."""
    corners = np.array([[-0.5, -0.5], [camera.width - 0.5, -0.5], [-0.5, camera.height - 0.5],
                        [camera.width - 0.5, camera.height - 0.5]])
    return float(np.arccos(np.min(camera.unproject(corners)[:, 2])))


def field_solid_angle(camera, blocks: int = 128) -> float:
    """Solid angle [sr] of the sensor's field: the sum over a grid of image blocks of |dv/du x dv/dv| dA
    (the directions' derivatives by central differences of 0.01 block; any projection)."""
    u = (np.arange(blocks) + 0.5) * camera.width / blocks - 0.5
    v = (np.arange(blocks) + 0.5) * camera.height / blocks - 0.5
    uv = np.stack(np.meshgrid(u, v), axis=-1).reshape(-1, 2)
    du, dv = 0.01 * camera.width / blocks, 0.01 * camera.height / blocks
    d_u = camera.unproject(uv + [du, 0.0]) - camera.unproject(uv - [du, 0.0])
    d_v = camera.unproject(uv + [0.0, dv]) - camera.unproject(uv - [0.0, dv])
    density = np.linalg.norm(np.cross(d_u, d_v), axis=1) / (4.0 * du * dv)  # sr / px^2
    inside = np.ones(len(uv), bool)
    if camera.circular_fov:
        inside = camera.unproject(uv)[:, 2] >= math.cos(camera.fov_x / 2.0)
    area = camera.width * camera.height / blocks**2
    return float(np.sum(density[inside]) * area)


class FieldStars:
    """The stars a frame can show (every star to the sensor's magnitude limit), indexed by sky cell.

    ``vectors`` (N, 3) ICRS unit vectors, ``hip``, ``v_mag``.  Cells are the sub-catalogs' base points of the navigation catalog: cell ``b`` lists the stars
    within the field radius (boresight to image corner) plus ``s_max`` (the largest base-point
    spacing, which bounds the distance from a boresight to the base point eq. 7-8 assigns to it) of
    base point ``b``; a boresight's cell is its eq. 7-8 address.
    """

    def __init__(self, catalog, camera, vectors, hip, v_mag):
        self.catalog = catalog
        self.camera = camera
        self.vectors = np.ascontiguousarray(vectors, dtype=float)
        self.hip = np.asarray(hip, dtype=np.int64)
        self.v_mag = np.asarray(v_mag, dtype=float)
        self.field_radius = _field_radius(camera)
        self.search_radius = self.field_radius + _FIELD_MARGIN  # the stars verify_near projects
        self.zones = zone_index(self.vectors)
        self.solid_angle = field_solid_angle(camera)
        radius = self.field_radius + catalog.s_max
        pairs = cKDTree(catalog.base_vectors).sparse_distance_matrix(
            cKDTree(self.vectors), float(chord(radius)), output_type="ndarray")
        order = np.lexsort((pairs["j"], pairs["i"]))
        self._cell_star = pairs["j"][order].astype(np.int64)
        self._cell_offsets = np.concatenate(
            [[0], np.cumsum(np.bincount(pairs["i"], minlength=catalog.n_base))]).astype(np.int64)
        self.camera_params = camera_array(camera)

    @classmethod
    def from_star_catalog(cls, catalog, camera, stars, mag_limit: float, resolution_px: float = 3.0):
        """Field stars of ``stars`` (a :class:`startrack.catalog.hipparcos.StarCatalog`) to ``mag_limit`` in its band.

        Stars closer than ``resolution_px`` [px] to another such star are left out: their images merge
        into one centroid that matches neither, and a match to either would be a guess.
        """
        keep = np.flatnonzero(stars.mag <= mag_limit)
        vectors = stars.vectors[keep]
        close = cKDTree(vectors).query_pairs(float(chord(resolution_px / camera.focal_px)), output_type="ndarray")
        keep = np.delete(keep, np.unique(close))
        return cls(catalog, camera, stars.vectors[keep], stars.hip[keep], stars.mag[keep])

    def __len__(self):
        return int(self.hip.size)

    def cell(self, boresight_I) -> np.ndarray:
        """Indices of the stars listed for the cell of the boresight direction (3,) in I."""
        x, y, z = boresight_I
        ra = math.atan2(y, x) % (2.0 * math.pi)
        dec = math.asin(max(-1.0, min(1.0, z)))
        b = self.catalog.sub_catalog_index(ra, dec)
        return self._cell_star[self._cell_offsets[b]:self._cell_offsets[b + 1]]

    def in_field(self, R_IS, margin_px: float = 0.0):
        """(star indices, their directions in S (m, 3)) of the stars imaged inside the field for R_IS."""
        cell = self.cell(R_IS[:, 2])
        index, v_S = predict(self.vectors[cell], np.ascontiguousarray(R_IS), self.camera_params, float(margin_px))
        return cell[index], v_S


@dataclass(frozen=True)
class Verified:
    """An accepted hypothesis: refitted R_IS, matched (centroid, field-star) indices, P_false."""

    R_IS: np.ndarray
    obs_index: np.ndarray
    star_index: np.ndarray
    false_match_probability: float
    n_predicted: int
