"""Synthetic centroid frames for identification tests and experiments (vector level, no rendering).

A frame: every star of a catalog that projects inside the camera's field for the true attitude,
centroids with Gaussian noise sigma [px] per axis, flux 10^(-0.4 V) (brightest first), some stars
removed (missing) and false stars added uniformly over the image with magnitudes drawn from the
frame's own range.  All draws come from the caller's numpy Generator.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation


def random_attitude(rng) -> np.ndarray:
    """Uniformly distributed attitude q_IS (4,) (scalar-last)."""
    return Rotation.random(random_state=rng).as_quat()


@dataclass(frozen=True)
class SyntheticFrame:
    """Centroids ``uv`` (n, 2) [px] and ``flux`` (n,), brightest first; ``hip`` (n,) the true star of each
    centroid (0 for a false star); ``q_IS`` the true attitude; ``missing_hip`` the stars removed."""

    uv: np.ndarray
    flux: np.ndarray
    hip: np.ndarray
    q_IS: np.ndarray
    missing_hip: np.ndarray


def centroid_frame(camera, vectors_I, hip, v_mag, q_IS, rng, sigma_px=0.1, n_false=0, n_missing=0):
    """A :class:`SyntheticFrame` of the stars (vectors_I (N, 3), hip, v_mag) seen with attitude q_IS."""
    index = camera.stars_in_field(q_IS, vectors_I)
    uv, _ = camera.project(q_IS, vectors_I[index])
    uv = uv + rng.normal(0.0, sigma_px, uv.shape)
    mags, hips = np.asarray(v_mag)[index], np.asarray(hip)[index]
    inside = (uv[:, 0] >= -0.5) & (uv[:, 0] <= camera.width - 0.5) & (uv[:, 1] >= -0.5) & (uv[:, 1] <= camera.height - 0.5)
    uv, mags, hips = uv[inside], mags[inside], hips[inside]
    n_missing = min(int(n_missing), len(hips))
    drop = rng.choice(len(hips), size=n_missing, replace=False)
    missing = hips[drop]
    keep = np.setdiff1d(np.arange(len(hips)), drop)
    uv, mags, hips = uv[keep], mags[keep], hips[keep]
    if n_false:
        low, high = (mags.min(), mags.max()) if mags.size else (0.0, 6.0)
        false_uv = rng.uniform([-0.5, -0.5], [camera.width - 0.5, camera.height - 0.5], (int(n_false), 2))
        uv = np.concatenate([uv, false_uv])
        mags = np.concatenate([mags, rng.uniform(low, high, int(n_false))])
        hips = np.concatenate([hips, np.zeros(int(n_false), hips.dtype)])
    flux = 10.0 ** (-0.4 * mags)
    order = np.argsort(-flux, kind="stable")
    return SyntheticFrame(uv[order], flux[order], hips[order].astype(np.int64), np.asarray(q_IS, float), missing)
