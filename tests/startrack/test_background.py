"""Mesh background (startrack.image.background) and the detection of real-frame features: vignetting and
nebulosity, hot pixels (single-pixel events), full scale."""

import numpy as np
import pytest

from startrack.image.background import estimate_background, mesh_background
from startrack.image.detection import detect
from startrack.image.render import SensorModel, Sources, render


def _vignetted(rng, shape=(480, 640), sigma=7.0):
    """A background falling from 150 DN at the centre to ~90 DN in the corners, Gaussian noise ``sigma``."""
    rows, cols = np.mgrid[0:shape[0], 0:shape[1]]
    r2 = ((rows - shape[0] / 2) / shape[0]) ** 2 + ((cols - shape[1] / 2) / shape[1]) ** 2
    level = 150.0 - 120.0 * r2
    return level, level + rng.normal(0.0, sigma, shape)


def test_mesh_follows_vignetting_the_global_level_does_not():
    rng = np.random.default_rng(31)
    level, frame = _vignetted(rng)
    background = mesh_background(frame, 64)
    rows, cols = np.mgrid[0:480:7, 0:640:7]
    b, s = background.at(rows.ravel(), cols.ravel())
    error = np.abs(b - level[rows, cols].ravel())
    assert np.median(error) < 0.15 * 7.0 and error.max() < 7.0  # within sigma up to the corners
    assert np.median(s) == pytest.approx(7.0, rel=0.12)  # the gradient across a 64 px cell adds a little
    _, global_sigma = estimate_background(frame)
    assert global_sigma > 1.3 * 7.0  # the gradient inflates one level's noise


def test_nebulous_8_bit_frame_keeps_its_stars_with_a_mesh():
    """A bright nebula near the 8-bit full scale: one level puts the threshold out of reach (no star),
    the mesh follows the nebula and finds the stars on both sides of it."""
    rng = np.random.default_rng(32)
    rows, cols = np.mgrid[0:300, 0:400]
    nebula = 140.0 + 90.0 * np.sin(cols / 100.0) * np.cos(rows / 120.0)
    stars = [(63.0, 120.0), (250.0, 150.0), (330.0, 40.0), (190.0, 260.0), (20.0, 20.0)]
    frame = nebula + rng.normal(0.0, 2.0, nebula.shape)
    for u, v in stars:
        frame += 40.0 * np.exp(-((cols - u) ** 2 + (rows - v) ** 2) / (2 * 0.8**2))
    frame = np.clip(np.rint(frame), 0, 255)
    assert len(detect(frame, saturation_dn=255)) == 0
    found = detect(frame, mesh_px=32, saturation_dn=255)
    near = [np.min(np.hypot(found.u - u, found.v - v)) < 1.0 for u, v in stars]
    assert all(near)


def test_hot_pixels_are_single_pixel_events_stars_are_not():
    sensor = SensorModel(hot_pixel_count=40, hot_pixel_e_per_s=3.0e5)
    rng = np.random.default_rng(33)
    uv = rng.uniform(20, 492, (60, 2))
    frame = render(sensor, 512, 512, [Sources(uv, rng.uniform(2e3, 5e4, 60), sensor.psf_sigma_px)], rng)
    found = detect(frame, mesh_px=64, saturation_dn=sensor.saturation_dn)
    hot_r, hot_c = sensor.hot_pixels(512, 512)
    is_hot = np.array([np.min(np.hypot(hot_c - u, hot_r - v)) < 0.5 for u, v in found.uv])
    is_star = np.array([np.min(np.hypot(*(uv - p).T)) < 1.0 for p in found.uv])
    assert found.single_pixel[is_hot & ~is_star].mean() > 0.9  # bright hot pixels are told apart
    assert not found.single_pixel[is_star & ~is_hot].any()
    kept = detect(frame, mesh_px=64, reject_single_pixels=True)
    assert len(kept) == int(np.count_nonzero(~found.single_pixel))


def test_uniform_background_detection_is_unchanged_by_a_given_level():
    rng = np.random.default_rng(34)
    sensor = SensorModel()
    frame = render(sensor, 256, 256, [Sources(rng.uniform(10, 246, (20, 2)), rng.uniform(5e3, 5e4, 20),
                                              sensor.psf_sigma_px)], rng)
    given = detect(frame, background=sensor.background_dn, sigma_n=sensor.noise_dn)
    assert given.background == sensor.background_dn and given.sigma_n == sensor.noise_dn
    assert len(given) >= 15


def _gaussian(shape, u, v, sigma_u, sigma_v, peak):
    rows, cols = np.mgrid[0:shape[0], 0:shape[1]]
    return peak * np.exp(-0.5 * (((cols - u) / sigma_u) ** 2 + ((rows - v) / sigma_v) ** 2))


def test_second_moments_give_a_gaussian_image_its_sigma_and_axis_ratio():
    """Noise 1 DN, peaks 1e5 DN: the threshold cuts the wings beyond ~4.3 sigma, so the moments give sigma and
    the axis ratio to within 1 %."""
    rng = np.random.default_rng(34)
    frame = 100.0 + _gaussian((200, 300), 80.3, 100.6, 2.0, 2.0, 1e5) + _gaussian((200, 300), 200.2, 90.1, 3.0, 1.0, 1e5)
    found = detect(frame + rng.normal(0.0, 1.0, frame.shape), background=100.0, sigma_n=1.0)
    round_ = int(np.argmin(np.hypot(found.u - 80.3, found.v - 100.6)))
    long_ = 1 - round_
    assert len(found) == 2 and found.size[round_] == pytest.approx(2.0, rel=0.01)
    assert found.elongation[round_] == pytest.approx(1.0, abs=0.01)
    assert found.size[long_] == pytest.approx(np.sqrt((9.0 + 1.0) / 2.0), rel=0.01)
    assert found.elongation[long_] == pytest.approx(3.0, rel=0.01)


def test_streaks_and_cloud_lumps_are_extended_stars_even_saturated_are_not():
    """60 stars (PSF sigma 0.8 px, 8 of them 20-200 times the saturation level), a satellite streak across
    the frame, three aircraft dashes (sigma 6 x 0.8 px) and three lumps of lit cloud (sigma 12 px): every
    streak, dash and lump is flagged ``extended``, no star is, and reject_extended drops exactly those."""
    sensor = SensorModel()
    rng = np.random.default_rng(35)
    uv = rng.uniform(40, 472, (60, 2))
    flux = np.r_[rng.uniform(2e3, 5e4, 52), rng.uniform(20.0, 200.0, 8) * 2 * np.pi * 0.8**2 * sensor.full_well_e]
    frame = render(sensor, 512, 512, [Sources(uv, flux, 0.8)], rng).astype(float)
    rows, cols = np.mgrid[0:512, 0:512]
    streak = np.where((rows > 20) & (rows < 490), 150.0 * np.exp(-0.5 * (cols - 256.0) ** 2), 0.0)
    shape = frame.shape
    dashes = sum(_gaussian(shape, u, v, 6.0, 0.8, 600.0) for u, v in ((100.0, 60.0), (160.0, 200.0), (420.0, 330.0)))
    lumps = sum(_gaussian(shape, u, v, 12.0, 12.0, 300.0) for u, v in ((80.0, 420.0), (330.0, 120.0), (440.0, 460.0)))
    frame = np.minimum(frame + streak + dashes + lumps, sensor.saturation_dn)
    found = detect(frame, mesh_px=64, saturation_dn=sensor.saturation_dn)
    is_star = np.array([np.min(np.hypot(*(uv - p).T)) < 1.5 and abs(p[0] - 256.0) > 6 for p in found.uv])
    assert np.count_nonzero(is_star & found.saturated) >= 6
    assert not found.extended[is_star].any()
    objects = ~is_star & (found.npix >= 30)  # the streak, dashes and lumps; the rest: noise around the lumps
    assert found.extended[objects].all() and np.count_nonzero(objects) == 7
    kept = detect(frame, mesh_px=64, saturation_dn=sensor.saturation_dn, reject_extended=True)
    assert len(kept) == np.count_nonzero(~found.extended)


@pytest.mark.parametrize("psf_sigma_px", [0.45, 0.671, 1.2])
def test_pairs_of_hot_pixels_are_single_pixel_events_too(psf_sigma_px):
    """40 pairs of adjacent hot pixels (side by side or diagonal, saturated or 20 % of it) among 80 stars of SNR
    20-2000: each pair is flagged, no star is -- the ring without its brightest pixel (the twin) holds no light."""
    sensor = SensorModel(psf_sigma_px=psf_sigma_px)
    rng = np.random.default_rng(36)
    uv = rng.uniform(20, 492, (80, 2))
    frame = render(sensor, 512, 512, [Sources(uv, rng.uniform(2e3, 2e5, 80), psf_sigma_px)], rng).astype(float)
    hot, steps = rng.integers(10, 500, (40, 2)), np.array([(1, 0), (0, 1), (1, 1), (-1, 1)])[rng.integers(0, 4, 40)]
    far = np.array([np.min(np.hypot(*(uv - h).T)) > 6 for h in hot])
    for (col, row), (dc, dr), level in zip(hot[far], steps[far], rng.choice([1.0, 0.2], 40)):
        frame[[row, row + dr], [col, col + dc]] = sensor.bias_dn + level * (sensor.saturation_dn - sensor.bias_dn)
    found = detect(frame, mesh_px=64, saturation_dn=sensor.saturation_dn)
    pairs = hot[far] + 0.5 * steps[far]
    is_hot = np.array([np.min(np.hypot(*(pairs - p).T)) < 1.0 for p in found.uv])  # two pairs may touch
    is_star = np.array([np.min(np.hypot(*(uv - p).T)) < 1.0 for p in found.uv])
    assert np.count_nonzero(is_hot) >= np.count_nonzero(far) - 2 and found.single_pixel[is_hot].all()
    assert is_star.sum() >= 60 and not found.single_pixel[is_star].any()
