"""Centroid frames of an ideal pinhole star camera, made without the project's camera, projection or
identification helpers: numpy and scipy's Rotation on the Hipparcos-2 directions of
:func:`startrack.catalog.hipparcos.load_star_catalog` (the catalog is the one thing shared with the solver).

Camera: ``fov_deg`` across the width of a ``width`` x ``height`` image, f = (W/2) / tan(fov/2) [px],
principal point ((W-1)/2, (H-1)/2), u = cx + f x/z, v = cy + f y/z in the sensor frame S (+z boresight,
+x along u, +y along v; docs/design.md).  Per frame: a uniformly random attitude q_IS (S -> I); every
star with V <= ``v_max`` imaged inside the pixel grid; images closer than ``BLEND_PX`` merged into one
flux-weighted centroid (either member is a right match); Gaussian noise ``sigma_px`` per axis; 0 to
``max_false`` false stars at uniform pixels at least ``CLEARANCE_PX`` from every star, V uniform in
[2, 6].  Flux 10^(-0.4 (V - 6)), brightest first.

The Cramér-Rao bound of a frame's attitude error dtheta (S axes, R_true = R_est exp([dtheta x])) is the
pixel-noise Fisher information F = sum_i J_i^T J_i / sigma_px^2 of the stars a solver matched, J_i =
d(u_i, v_i) / d dtheta by central differences of this module's projection.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

BLEND_PX = 2.0
CLEARANCE_PX = 5.0


@dataclass(frozen=True)
class Pinhole:
    """The ideal camera: field of view across the width [deg], image size [px]."""

    fov_deg: float
    width: int
    height: int

    @property
    def focal_px(self):
        return self.width / 2.0 / np.tan(np.radians(self.fov_deg) / 2.0)

    def pixels(self, v_S):
        """(u, v) (n, 2) [px] of sensor-frame directions (n, 3) with z > 0."""
        f = self.focal_px
        return np.column_stack([(self.width - 1) / 2.0 + f * v_S[:, 0] / v_S[:, 2],
                                (self.height - 1) / 2.0 + f * v_S[:, 1] / v_S[:, 2]])

    def inside(self, uv):
        return (uv[:, 0] >= -0.5) & (uv[:, 0] <= self.width - 0.5) & (uv[:, 1] >= -0.5) & (uv[:, 1] <= self.height - 0.5)


@dataclass(frozen=True)
class Frame:
    """One frame: centroids ``uv`` (n, 2) [px] and ``flux`` brightest first, the HIP numbers each centroid
    may be matched to (``members``; empty for a false star), the true attitude ``q_IS``."""

    uv: np.ndarray
    flux: np.ndarray
    members: list
    q_IS: np.ndarray


def make_frame(camera, stars, rng, sigma_px, max_false, v_max=6.0):
    """A :class:`Frame` of ``stars`` (a StarCatalog) seen by ``camera`` (a :class:`Pinhole`)."""
    rotation = Rotation.random(random_state=rng)
    bright = stars.v_mag <= v_max
    v_S = rotation.inv().apply(stars.vectors[bright])
    front = v_S[:, 2] > 0.0
    uv = camera.pixels(v_S[front])
    seen = camera.inside(uv)
    uv, hip = uv[seen], stars.hip[bright][front][seen]
    flux = 10.0 ** (-0.4 * (stars.v_mag[bright][front][seen] - 6.0))
    uv, flux, members = _blended(uv, flux, hip)
    uv = uv + rng.normal(0.0, sigma_px, uv.shape)
    false_uv = _false_stars(camera, uv, int(rng.integers(0, max_false + 1)), rng)
    uv = np.vstack([uv, false_uv])
    flux = np.concatenate([flux, 10.0 ** (-0.4 * (rng.uniform(2.0, 6.0, len(false_uv)) - 6.0))])
    members = members + [[] for _ in range(len(false_uv))]
    order = np.argsort(-flux, kind="stable")
    return Frame(uv[order], flux[order], [members[k] for k in order], rotation.as_quat())


def _blended(uv, flux, hip):
    """Star images within BLEND_PX merged: flux-weighted position, summed flux, every member listed."""
    groups = list(range(len(uv)))
    for i, j in sorted(cKDTree(uv).query_pairs(BLEND_PX)):
        root_i, root_j = _root(groups, i), _root(groups, j)
        groups[max(root_i, root_j)] = min(root_i, root_j)
    roots = np.array([_root(groups, k) for k in range(len(uv))], dtype=int)
    out_uv, out_flux, members = [], [], []
    for root in np.unique(roots):
        part = roots == root
        out_uv.append(np.average(uv[part], axis=0, weights=flux[part]))
        out_flux.append(flux[part].sum())
        members.append([int(h) for h in hip[part]])
    return np.array(out_uv).reshape(-1, 2), np.array(out_flux), members


def _root(groups, k):
    while groups[k] != k:
        k = groups[k]
    return k


def _false_stars(camera, uv, n, rng):
    tree, found = cKDTree(uv), []
    while len(found) < n:
        point = rng.uniform([-0.5, -0.5], [camera.width - 0.5, camera.height - 0.5])
        if not tree.query_ball_point(point, CLEARANCE_PX):
            found.append(point)
    return np.array(found).reshape(-1, 2)


def attitude_error(q_true, q_est):
    """dtheta (3,) [rad] in S axes with R_true = R_est exp([dtheta x])."""
    return (Rotation.from_quat(q_est).inv() * Rotation.from_quat(q_true)).as_rotvec()


def pixel_crb(camera, q_IS, ref_I, sigma_px, step=1e-7):
    """(3, 3) Cramér-Rao covariance [rad^2] of dtheta from the stars ``ref_I`` (n, 3) at pixel noise sigma_px."""
    base = Rotation.from_quat(q_IS)
    jacobian = np.empty((len(ref_I), 2, 3))
    for axis in range(3):
        turn = np.zeros(3)
        turn[axis] = step
        plus = camera.pixels((base * Rotation.from_rotvec(turn)).inv().apply(ref_I))
        minus = camera.pixels((base * Rotation.from_rotvec(-turn)).inv().apply(ref_I))
        jacobian[:, :, axis] = (plus - minus) / (2.0 * step)
    return np.linalg.inv(np.einsum("nki,nkj->ij", jacobian, jacobian)) * sigma_px**2


def efficient_attitude(camera, uv, ref_I):
    """q_IS (4,) minimising Wahba's loss over the centroids ``uv`` (n, 2) and their stars ``ref_I`` (n, 3) with
    equal weights (scipy's ``align_vectors``): the efficient estimate for equal centroid noise."""
    f = camera.focal_px
    seen = np.column_stack([(uv[:, 0] - (camera.width - 1) / 2.0) / f, (uv[:, 1] - (camera.height - 1) / 2.0) / f,
                            np.ones(len(uv))])
    rotation, _ = Rotation.align_vectors(ref_I, seen / np.linalg.norm(seen, axis=1)[:, None])
    return rotation.as_quat()
