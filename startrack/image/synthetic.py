"""Synthetic frames for identification tests, benchmarks and experiments.

Centroid frames (vector level, no rendering): every star of a catalog that projects inside the
camera's field for the true attitude, centroids with Gaussian noise sigma [px] per axis, flux 10^(-0.4 V)
(brightest first), some stars removed (missing) and false stars added uniformly over the image with
magnitudes drawn from the frame's own range.  Rendered frames (:func:`rendered_sky`) through any
camera (field of view, distortion), their JPEG-compressed versions (:func:`as_jpeg`) and crowds of
false detections (:func:`noise_crowd`).  All draws come from the caller's numpy Generator.
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


@dataclass(frozen=True)
class RenderedSky:
    """A rendered frame and its truth: ``image`` (H, W) [DN], ``full_scale`` [DN], ``camera`` and ``q_IS``
    the truth, ``uv`` (m, 2) and ``hip`` (m,) the true centroids of the rendered stars."""

    image: np.ndarray
    full_scale: float
    camera: object
    q_IS: np.ndarray
    uv: np.ndarray
    hip: np.ndarray


def rendered_sky(camera, stars, rng, sensor=None, q_IS=None) -> RenderedSky:
    """A frame of the catalog ``stars`` (a :class:`startrack.catalog.hipparcos.StarCatalog`) rendered by
    :func:`startrack.image.render.render_star_field` through ``camera`` at ``q_IS`` (default: a uniformly random
    attitude) with ``sensor`` (default: a 0.2 s exposure of the default :class:`startrack.image.render.SensorModel`)."""
    from startrack.image.render import SensorModel, render_star_field

    sensor = SensorModel(exposure_s=0.2) if sensor is None else sensor
    q_IS = random_attitude(rng) if q_IS is None else np.asarray(q_IS, float)
    frame = render_star_field(camera, sensor, q_IS, stars.vectors, stars.v_mag, rng)
    return RenderedSky(frame.image, float(sensor.saturation_dn), camera, q_IS, frame.uv_true,
                       np.asarray(stars.hip)[frame.star_index])


def as_jpeg(image, full_scale, quality):
    """``image`` scaled to 8 bits (0..full_scale -> 0..255), JPEG-compressed at ``quality`` and read back as a
    float luminance frame (compression noise and block artefacts of an ordinary camera's JPEG)."""
    import io

    from PIL import Image

    data = np.clip(np.rint(np.asarray(image, float) * (255.0 / full_scale)), 0, 255).astype(np.uint8)
    buffer = io.BytesIO()
    Image.fromarray(data).save(buffer, format="JPEG", quality=int(quality))
    buffer.seek(0)
    with Image.open(buffer) as decoded:
        return np.asarray(decoded.convert("L"), dtype=float)


def noise_crowd(n, width, height, rng, clusters=0):
    """(uv (n, 2), flux (n,)) of ``n`` false detections over a width x height image: uniform, or gathered
    around ``clusters`` random centres (Gaussian, 20 px) like compression noise around bright regions;
    fluxes from a Pareto law (many faint, a few bright)."""
    if clusters:
        centres = rng.uniform([0.0, 0.0], [width, height], (clusters, 2))
        uv = centres[rng.integers(0, clusters, n)] + rng.normal(0.0, 20.0, (n, 2))
        uv = np.clip(uv, -0.5, [width - 0.5, height - 0.5])
    else:
        uv = rng.uniform([-0.5, -0.5], [width - 0.5, height - 0.5], (n, 2))
    return uv, rng.pareto(1.5, n) + 1.0
