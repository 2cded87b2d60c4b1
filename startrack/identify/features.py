"""Star-pattern features of a frame: angular distances and their error bounds (001 §4.3.1).

The per-pair error gate is the bound e_ij of 001 §4.3.1.  A centroid (X_i, Y_i) [px] on a pinhole of
focal length f [px] has the direction v_i = (X_i, Y_i, f) / |(X_i, Y_i, f)|, whose Jacobian columns are

    dv_i/dX_i = (e_x - v_i v_ix) / rho_i,   dv_i/dY_i = (e_y - v_i v_iy) / rho_i,   rho_i = f / v_iz.

Differentiating cos(beta_ij) = v_i^T v_j gives (001 §4.3.1)

    -sin(beta_ij) d beta_ij = v_j^T dv_i + v_i^T dv_j,

so, with every centroid coordinate wrong by at most delta [px],

    |d beta_ij| <= e_ij = delta (|v_j^T dv_i/dX_i| + |v_j^T dv_i/dY_i|
                                 + |v_i^T dv_j/dX_j| + |v_i^T dv_j/dY_j|) / sin(beta_ij).

001 bounds each |v_jm| by 1 (the sum of the absolute Jacobian entries); keeping the factor v_j^T, as
here, gives the tight bound of the same linearisation (001's is 2-3 times wider for the pairs of a
16 deg field).  For a Gaussian centroid error of standard deviation sigma per axis, delta = 3 sigma
makes e_ij at least a 3-sigma gate on beta_ij (the 1-norm bounds the 2-norm).

:func:`centroid_directions` turns a frame's centroids into these directions in one compiled call:
checks, brightest first, the camera model of :class:`startrack.camera.model.Camera` (pinhole, Brown radial
distortion inverted by Newton's method on the radius, as ``Camera.unproject``).
"""

from __future__ import annotations

import numpy as np

from startrack.camera.projection_kernels import ray_one
from startrack.compiled.numba_setup import njit
from startrack.compiled.sorts import argsort


@njit
def pair_features(obs, focal_px, delta_px):  # pragma: no cover  (compiled)
    """(beta (n, n) [rad], e (n, n) [rad]) of every pair of the unit vectors ``obs`` (n, 3).

    beta_ij = arccos(v_i . v_j); e_ij the bound of 001 §4.3.1 (tightened, module text) for centroid
    errors up to ``delta_px`` [px] per axis on a pinhole of focal length ``focal_px`` [px].  The
    diagonal holds beta = 0, e = +inf.
    """
    n = obs.shape[0]
    beta = np.zeros((n, n))
    gate = np.full((n, n), np.inf)
    fill_features(obs, n, focal_px, delta_px, beta, gate, np.zeros(1, np.int64))
    return beta, gate


@njit(_nrt=False)
def fill_features(obs, n, focal_px, delta_px, beta, gate, filled):  # pragma: no cover  (compiled)
    """:func:`pair_features` in place, for the pairs of the first n stars not yet filled: ``filled[0]``
    is the number of leading stars whose pairs are (updated to n, at most the size of ``beta``)."""
    n = min(n, beta.shape[0], obs.shape[0])
    for j in range(filled[0], n):
        for i in range(j):
            c = obs[i, 0] * obs[j, 0] + obs[i, 1] * obs[j, 1] + obs[i, 2] * obs[j, 2]
            c = min(1.0, max(-1.0, c))
            s_ij = abs(obs[j, 0] - c * obs[i, 0]) + abs(obs[j, 1] - c * obs[i, 1])
            s_ji = abs(obs[i, 0] - c * obs[j, 0]) + abs(obs[i, 1] - c * obs[j, 1])
            sine = np.sqrt(max(1.0 - c * c, 0.0))
            e = np.inf
            if sine > 0.0:
                e = delta_px * (s_ij * obs[i, 2] + s_ji * obs[j, 2]) / (focal_px * sine)
            beta[i, j] = beta[j, i] = np.arccos(c)
            gate[i, j] = gate[j, i] = e
    filled[0] = max(filled[0], n)


#: Status codes of :func:`centroid_directions`.
DIRECTIONS_OK, BAD_COORDINATE, BAD_FLUX, ALL_OUTSIDE = 0, 1, 2, 3

_NEWTON_ITERATIONS = 12


@njit
def brightest_first(flux, count, max_stars):  # pragma: no cover  (compiled)
    """Indices of the first ``count`` entries ordered by decreasing ``flux`` (stable; given order when
    ``flux`` is empty), at most ``max_stars`` (< 0: all)."""
    order = np.arange(count) if flux.size == 0 else argsort(-flux[:count])
    return order if max_stars < 0 else order[:max_stars]


@njit
def _unproject(u, v, camera_params):  # pragma: no cover  (compiled)
    """Unit vector in S of the image point (u, v) [px]: radial distortion removed by Newton's method on the
    radius (r_d = r (1 + k1 r^2 + k2 r^4)), then the projection's ray, as
    :meth:`startrack.camera.model.Camera.unproject`."""
    focal, cx, cy, k1, k2 = camera_params[0], camera_params[1], camera_params[2], camera_params[5], camera_params[6]
    x, y = (u - cx) / focal, (v - cy) / focal
    if k1 != 0.0 or k2 != 0.0:
        rd = np.sqrt(x * x + y * y)
        r = rd
        for _ in range(_NEWTON_ITERATIONS):
            r2 = r * r
            step = (r * (1.0 + k1 * r2 + k2 * r2 * r2) - rd) / (1.0 + 3.0 * k1 * r2 + 5.0 * k2 * r2 * r2)
            r -= step
            if abs(step) <= 1e-16 * max(r, 1.0):
                break
        if rd > 0.0:
            x, y = x * r / rd, y * r / rd
    return ray_one(x, y, camera_params[8])


@njit
def _feature_arrays(n_stars, n_pattern):  # pragma: no cover  (compiled)
    """Empty features of a frame: (beta (m, m) zeros, gate (m, m) +inf, filled (1,) zero), m = min(n_stars,
    n_pattern)."""
    m = min(n_stars, n_pattern)
    return np.zeros((m, m)), np.full((m, m), np.inf), np.zeros(1, np.int64)


@njit
def centroid_directions(uv, flux, camera_params, max_stars, n_pattern, cos_merge):  # pragma: no cover  (compiled)
    """(status, obs_S (m, 3), index (m,), beta, gate, filled): the unit vectors in S of the centroids ``uv``
    (n, 2) [px] that lie on the sensor (pixel edges included), brightest first by ``flux`` (n,) (empty:
    given order), a centroid within the merge radius (cosine ``cos_merge``) of a brighter one left out
    (:func:`separated`), at most ``max_stars`` (< 0: all); ``index`` their positions in ``uv``; empty
    features for ``n_pattern`` stars (:func:`_feature_arrays`).  status: DIRECTIONS_OK, BAD_COORDINATE
    (NaN or infinite), BAD_FLUX (NaN or infinite) or ALL_OUTSIDE."""
    n = uv.shape[0]
    beta, gate, filled = _feature_arrays(0, n_pattern)
    width, height = camera_params[3], camera_params[4]
    inside = np.empty(n, np.int64)
    count = 0
    for i in range(n):
        u, v = uv[i, 0], uv[i, 1]
        if not (np.isfinite(u) and np.isfinite(v)):
            return BAD_COORDINATE, np.empty((0, 3)), inside[:0], beta, gate, filled
        if -0.5 <= u <= width - 0.5 and -0.5 <= v <= height - 0.5:
            inside[count] = i
            count += 1
    for i in range(flux.size):
        if not np.isfinite(flux[i]):
            return BAD_FLUX, np.empty((0, 3)), inside[:0], beta, gate, filled
    if count == 0 and n > 0:
        return ALL_OUTSIDE, np.empty((0, 3)), inside[:0], beta, gate, filled
    index = inside[:count]
    kept = flux.copy() if flux.size == 0 else flux[index]
    index = index[brightest_first(kept, count, -1)]
    obs = np.empty((index.size, 3))
    for m in range(index.size):
        obs[m, 0], obs[m, 1], obs[m, 2] = _unproject(uv[index[m], 0], uv[index[m], 1], camera_params)
    obs, index = separated(obs, index, cos_merge, max_stars)
    beta, gate, filled = _feature_arrays(index.size, n_pattern)
    return DIRECTIONS_OK, obs, index, beta, gate, filled


@njit
def separated(obs, index, cos_merge, max_stars):  # pragma: no cover  (compiled)
    """(obs, index) without the directions (brightest first) closer than the merge radius (cosine
    ``cos_merge``) to a brighter one kept: a repeated or split centroid counts once, so it can neither
    stand for several stars nor multiply the patterns searched. At most ``max_stars`` (< 0: all)."""
    n = obs.shape[0]
    keep = np.empty(n if max_stars < 0 else min(n, max_stars), np.int64)
    count = apart(obs, n, cos_merge, keep)
    return obs[keep[:count]], index[keep[:count]]


@njit(_nrt=False)
def apart(obs, n, cos_limit, keep):  # pragma: no cover  (compiled)
    """Write to ``keep`` (at most its size) the indices, brightest first, of the first n directions
    ``obs`` whose cosine with every one kept before is at most ``cos_limit``; returns their number."""
    count = 0
    for m in range(n):
        if count == keep.size:
            break
        alone = True
        for k in range(count):
            j = keep[k]
            if obs[m, 0] * obs[j, 0] + obs[m, 1] * obs[j, 1] + obs[m, 2] * obs[j, 2] > cos_limit:
                alone = False
                break
        if alone:
            keep[count] = m
            count += 1
    return count


class FrameFeatures:
    """A frame prepared for identification.

    ``obs_S`` (n, 3) centroid directions in the sensor frame, brightest first; ``index`` (n,) their
    positions in the caller's list; ``beta`` and ``gate`` (m, m) the angular distances and bounds
    e_ij [rad] of the first m (brightest) stars, filled for the pairs of the first ``filled[0]`` of them
    (the search fills more as it widens, :func:`fill_features`); ``focal_px``, ``delta_px`` their
    camera and error bound; ``verify_gate`` the verification match radius [rad].  (A plain class with
    slots: one is made per frame, and a frozen dataclass takes three times as long to build.)
    """

    __slots__ = ("obs_S", "index", "beta", "gate", "filled", "focal_px", "delta_px", "verify_gate")

    def __init__(self, obs_S, index, beta, gate, filled, focal_px: float, delta_px: float, verify_gate: float):
        self.obs_S, self.index, self.beta, self.gate, self.filled = obs_S, index, beta, gate, filled
        self.focal_px, self.delta_px, self.verify_gate = focal_px, delta_px, verify_gate

    @classmethod
    def build(cls, obs_S, index, focal_px: float, delta_px: float, verify_gate: float, n_pattern: int,
              n_filled: int | None = None):
        """Features of ``obs_S`` (already brightest first) for at most ``n_pattern`` pattern stars, the
        pairs of the first ``n_filled`` (default: all of them) computed now."""
        obs_S = np.ascontiguousarray(obs_S, dtype=float)
        beta, gate, filled = _feature_arrays(len(obs_S), n_pattern)
        fill_features(obs_S, n_pattern if n_filled is None else n_filled, float(focal_px), float(delta_px), beta, gate,
                      filled)
        return cls(obs_S, index, beta, gate, filled, float(focal_px), float(delta_px), verify_gate)

    @property
    def arrays(self):
        """The tuple the search kernels take: (obs_S, beta, gate, filled, focal_px, delta_px)."""
        return self.obs_S, self.beta, self.gate, self.filled, self.focal_px, self.delta_px

    def __len__(self):
        return int(self.obs_S.shape[0])
