"""Impaired night-sky frames for ``benchmarks/plate_solve_robustness.py`` (a helper module, no ``__main__``).

A *scene* is a camera (1024 x 768, field of view across the width uniform in the benchmark's range,
Brown radial distortion k1 uniform in +-0.1, principal point at the centre), a uniformly random
attitude and a sensor (:class:`startrack.image.render.SensorModel`, 0.2 s) under a faint uniform sky of
200 e-/px/s.  Frame k of every bin is the same scene (paired comparison between levels); each impairment
draws from its own stream ``SeedSequence([seed, k, impairment, level])``.

Pixel impairments change the exposure before the noise (:func:`expose`): the noise-free star charge
(:func:`startrack.image.render.expected_charge`) times a transmission map (cloud, trees), plus a sky map
(light pollution, moonlight, cloud glow) and extra charge (streaks); hot pixels and defocus through
the sensor model; JPEG after it.  Centroid impairments change the detected list (positions, fluxes,
false stars).  The units of each level are in :data:`IMPAIRMENTS`.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy import ndimage

from startrack.base.units import DEG
from startrack.camera.model import Camera
from startrack.image.render import SensorModel, expected_charge, star_sources
from startrack.image.synthetic import as_jpeg, random_attitude

WIDTH, HEIGHT = 1024, 768
#: The night sky of every scene [e-/px/s]: faint, but trees are darker.
SKY_E_PER_S = 200.0
K1_MAX = 0.1
#: Blur of the out-of-focus trees' silhouette [px] (sigma).
TREE_BLUR_PX = 3.0


@dataclasses.dataclass(frozen=True)
class Scene:
    camera: Camera
    q_IS: np.ndarray
    sensor: SensorModel


@dataclasses.dataclass
class Exposure:
    """What reaches the detector: the sky's transmission, extra charge (streaks) and sky [e- per exposure]
    maps, JPEG quality."""

    sensor: SensorModel
    charge_e: np.ndarray | float = 0.0
    transmission: np.ndarray | float = 1.0
    sky_e: np.ndarray | float = 0.0
    jpeg_quality: int | None = None


def scene(seed, k, fov_range_deg):
    """Scene k of the benchmark (same for every impairment bin)."""
    rng = np.random.default_rng(np.random.SeedSequence([seed, k]))
    fov = rng.uniform(*fov_range_deg)
    camera = Camera.from_fov(fov * DEG, WIDTH, HEIGHT, k1=rng.uniform(-K1_MAX, K1_MAX))
    return Scene(camera, random_attitude(rng), SensorModel(exposure_s=0.2))


def exposure_of(scene_):
    """The unimpaired exposure of a scene: its sensor under the night sky."""
    return Exposure(scene_.sensor, sky_e=SKY_E_PER_S * scene_.sensor.exposure_s)


def expose(scene_, stars, exposure, rng):
    """(image, full scale) of the scene's stars through ``exposure`` (noise model of startrack.image.render)."""
    sensor, camera = exposure.sensor, scene_.camera
    sources, _ = star_sources(camera, sensor, scene_.q_IS, stars.vectors, stars.v_mag)
    charge = expected_charge(sensor, HEIGHT, WIDTH, (sources,)) * exposure.transmission + exposure.charge_e
    if sensor.hot_pixel_count:
        rows, cols = sensor.hot_pixels(HEIGHT, WIDTH)
        charge[rows, cols] += sensor.hot_pixel_e_per_s * sensor.exposure_s
    background = sensor.dark_e_per_px_s * sensor.exposure_s + exposure.sky_e
    electrons = rng.poisson(charge + background) + rng.normal(0.0, sensor.read_noise_e, charge.shape)
    dn = np.clip(np.rint(sensor.bias_dn + electrons / sensor.gain_e_per_dn), 0, sensor.saturation_dn)
    if exposure.jpeg_quality is not None:
        return as_jpeg(dn, sensor.saturation_dn, exposure.jpeg_quality), 255.0
    return dn.astype(np.uint16), float(sensor.saturation_dn)


def _grid():
    v, u = np.mgrid[0:HEIGHT, 0:WIDTH].astype(float)
    return u, v


def _smooth_field(rng, cells, roughness=0.0):
    """A random field over the image, unit variance: white noise on a coarse grid, cubic-upsampled."""
    coarse = rng.standard_normal((cells * 3 // 4 + 2, cells + 2))
    field = ndimage.zoom(coarse, (HEIGHT / coarse.shape[0], WIDTH / coarse.shape[1]), order=3)[:HEIGHT, :WIDTH]
    if roughness:
        field = field + roughness * ndimage.zoom(rng.standard_normal((HEIGHT // 16, WIDTH // 16)), 16, order=3)
    return (field - field.mean()) / field.std()


# ------------------------------------------------------------------------------ pixel impairments
def hot_pixels(exposure, level, rng):
    """``level`` hot pixels (single, 5e4 e-/s: saturated in 0.2 s)."""
    exposure.sensor = dataclasses.replace(exposure.sensor, hot_pixel_count=int(level),
                                          fixed_pattern_seed=int(rng.integers(2**31)))


def _line_charge(u0, v0, u1, v1, e_per_px, width_px):
    """Noise-free charge map [e-] of a straight track: e_per_px along it, Gaussian across (sigma width_px)."""
    length = math.hypot(u1 - u0, v1 - v0)
    s = (np.arange(int(length * 4) + 1) + 0.5) / (int(length * 4) + 1)
    u, v = u0 + s * (u1 - u0), v0 + s * (v1 - v0)
    inside = (u >= 0) & (u < WIDTH - 1) & (v >= 0) & (v < HEIGHT - 1)
    u, v = u[inside], v[inside]
    c, r = np.floor(u).astype(int), np.floor(v).astype(int)
    fu, fv = u - c, v - r
    charge = np.zeros((HEIGHT, WIDTH))
    per_sample = e_per_px * length / len(s)
    for dr, dc, weight in ((0, 0, (1 - fu) * (1 - fv)), (0, 1, fu * (1 - fv)), (1, 0, (1 - fu) * fv), (1, 1, fu * fv)):
        np.add.at(charge, (r + dr, c + dc), per_sample * weight)
    return ndimage.gaussian_filter(charge, width_px)


def streaks(exposure, level, rng):
    """``level`` streaks across the frame: satellites (continuous) and, every other one, aircraft
    (navigation lights blinking: 15 px dashes every 60 px); 500-5000 e- per px of track, 0.7-1.5 px wide."""
    for n in range(int(level)):
        u0, u1 = rng.uniform(-50, WIDTH + 50, 2)
        v0, v1 = -50.0, HEIGHT + 50.0
        if rng.random() < 0.5:
            (u0, v0), (u1, v1) = (-50.0, u0 * HEIGHT / WIDTH), (WIDTH + 50.0, u1 * HEIGHT / WIDTH)
        brightness, width = rng.uniform(500, 5000), rng.uniform(0.7, 1.5)
        length = math.hypot(u1 - u0, v1 - v0)
        pieces = [(0.0, 1.0)] if n % 2 == 0 else [(s, s + 15.0 / length) for s in np.arange(0.0, 1.0, 60.0 / length)]
        for a, b in pieces:
            exposure.charge_e = exposure.charge_e + _line_charge(
                u0 + a * (u1 - u0), v0 + a * (v1 - v0), u0 + b * (u1 - u0), v0 + b * (v1 - v0), brightness, width)


def cloud(exposure, level, rng):
    """A cloud over a fraction ``level`` of the frame: transmission down to 2 % inside, soft edges, lit
    from below by a town (glow up to 20 times the sky)."""
    field = _smooth_field(rng, 4, roughness=0.3)
    edge = np.quantile(field, 1.0 - level)
    opacity = np.clip((field - edge) / 0.5 + 0.5, 0.0, 1.0)
    exposure.transmission = exposure.transmission * (1.0 - 0.98 * opacity)
    exposure.sky_e = exposure.sky_e + 20.0 * SKY_E_PER_S * exposure.sensor.exposure_s * opacity


def _saturation_e(sensor):
    """Charge [e-] that brings a pixel from the bias to the saturation level."""
    return (sensor.saturation_dn - sensor.bias_dn) * sensor.gain_e_per_dn


def light_pollution(exposure, level, rng):
    """A town's glow rising to ``level`` x the saturation charge at the frame edge nearest the horizon (a
    random side), falling quadratically across the frame."""
    u, v = _grid()
    angle = rng.uniform(0.0, 2.0 * math.pi)
    s = (np.cos(angle) * (u - WIDTH / 2) + np.sin(angle) * (v - HEIGHT / 2))
    s = (s - s.min()) / (s.max() - s.min())
    exposure.sky_e = exposure.sky_e + level * _saturation_e(exposure.sensor) * s**2


def moonlight(exposure, level, rng):
    """A bright sky of ``level`` x the saturation charge at the frame centre, with the glare of a Moon just
    outside the frame (a random side) rising to 3 times that at the nearest edge."""
    u, v = _grid()
    angle = rng.uniform(0.0, 2.0 * math.pi)
    mu, mv = WIDTH / 2 + 0.7 * WIDTH * math.cos(angle), HEIGHT / 2 + 0.7 * WIDTH * math.sin(angle)
    distance = np.hypot(u - mu, v - mv)
    glare = (distance.min() / distance) ** 2
    sky = 1.0 + 2.0 * glare
    exposure.sky_e = exposure.sky_e + level * _saturation_e(exposure.sensor) * sky / sky[HEIGHT // 2, WIDTH // 2]


def defocus(exposure, level, rng):
    """The point-spread function's Gaussian sigma ``level`` [px] (in focus: 0.67)."""
    exposure.sensor = dataclasses.replace(exposure.sensor, psf_sigma_px=float(level))


def trees(exposure, level, rng):
    """Tree silhouettes from the bottom over a fraction ``level`` of the frame: crowns of random height,
    ragged edges and gaps of sky between branches; no starlight and no sky inside.  The trees are out of
    focus (a lens focused at infinity blurs a tree 20 m away over ~10 px): the silhouette's edges are
    softened by a Gaussian of :data:`TREE_BLUR_PX`."""
    profile = level * HEIGHT * (1.0 + 0.35 * _smooth_field(rng, 6)[0] + 0.08 * rng.standard_normal(WIDTH))
    _, v = _grid()
    foreground = v > HEIGHT - profile[None, :]
    gaps = _smooth_field(rng, 60) > 1.6
    crown = v > HEIGHT - profile[None, :] + 0.25 * profile[None, :]
    clear = 1.0 - ndimage.gaussian_filter((foreground & ~(gaps & ~crown)).astype(float), TREE_BLUR_PX)
    exposure.transmission = exposure.transmission * clear
    exposure.sky_e = exposure.sky_e * clear


def jpeg(exposure, level, rng):
    """JPEG quality ``level`` (8-bit, the full scale of the sensor to 255)."""
    exposure.jpeg_quality = int(level)


# ------------------------------------------------------------------------------ centroid impairments
def centroid_noise(centroids, level, rng):
    """Gaussian noise of ``level`` [px] per axis on every centroid."""
    centroids[:, :2] += rng.normal(0.0, level, (len(centroids), 2))
    return centroids


def brightness_noise(centroids, level, rng):
    """Fluxes scattered by ``level`` [mag] (log-normal), the list re-sorted brightest first."""
    centroids[:, 2] *= 10.0 ** (-0.4 * rng.normal(0.0, level, len(centroids)))
    return centroids[np.argsort(-centroids[:, 2], kind="stable")]


def false_stars(centroids, level, rng):
    """``level`` false stars, uniform over the frame, fluxes drawn from the frame's own."""
    n = int(level)
    fluxes = rng.choice(centroids[:, 2], n) if len(centroids) else np.ones(n)
    extra = np.column_stack([rng.uniform([-0.5, -0.5], [WIDTH - 0.5, HEIGHT - 0.5], (n, 2)), fluxes,
                             np.full(n, np.median(centroids[:, 3]) if len(centroids) else 0.3)])
    merged = np.vstack([centroids, extra])
    return merged[np.argsort(-merged[:, 2], kind="stable")]


@dataclasses.dataclass(frozen=True)
class Impairment:
    """``stage`` 'pixels' (function of the Exposure) or 'centroids' (function of the (n, 4) list)."""

    stage: str
    function: object
    unit: str
    levels: tuple


#: Impairments and their levels (the benchmark's bins); 'none' is the unimpaired reference.
IMPAIRMENTS = {
    "none": Impairment("pixels", lambda exposure, level, rng: None, "-", (0,)),
    "centroid_noise": Impairment("centroids", centroid_noise, "px per axis", (0.5, 1.0, 2.0, 4.0)),
    "brightness_noise": Impairment("centroids", brightness_noise, "mag", (0.3, 0.6, 1.0, 2.0)),
    "false_stars": Impairment("centroids", false_stars, "stars", (10, 30, 100, 300)),
    "hot_pixels": Impairment("pixels", hot_pixels, "pixels", (100, 1000, 10000)),
    "streaks": Impairment("pixels", streaks, "streaks", (1, 3, 10)),
    "cloud": Impairment("pixels", cloud, "fraction covered", (0.25, 0.5, 0.75)),
    "light_pollution": Impairment("pixels", light_pollution, "edge sky / saturation", (0.1, 0.3, 0.6)),
    "moonlight": Impairment("pixels", moonlight, "centre sky / saturation", (0.03, 0.1, 0.25)),
    "defocus": Impairment("pixels", defocus, "PSF sigma px", (1.5, 3.0, 5.0)),
    "trees": Impairment("pixels", trees, "fraction covered", (0.2, 0.4, 0.6)),
    "jpeg": Impairment("pixels", jpeg, "quality", (90, 70, 50, 30, 10)),
}
