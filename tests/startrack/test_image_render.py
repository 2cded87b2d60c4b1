"""Rendering: flux vs photometry closed form, erf pixel integral, smear, noise levels, seeds, windows."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from scipy.special import erf
from scipy.stats import norm

from startrack.base.errors import InputError
from startrack.camera.model import Camera
from startrack.image.render import (
    SMEAR_STEP_SIGMA,
    SensorModel,
    Sources,
    Windows,
    cosmic_ray,
    expected_charge,
    planet,
    render,
    render_star_field,
    star_sources,
    stray_light,
)
from startrack.photometry.star_signal import (
    centred_peak_fraction,
    magnitude_for_electrons,
    pixel_fraction,
    star_electrons,
)

DEG = np.pi / 180.0
#: The charge a source may lose beyond the renderer's footprint, PSF_EXTENT_SIGMA = 5 sigma from its centre
#: in u and v: 1 - (1 - 2 Phi(-5))² < 4 Phi(-5) = 1.15e-6 of it (0.2 e- of 2e5, far below the shot noise).
FOOTPRINT_LOSS = 4.0 * norm.sf(5.0)


def test_star_electrons_pogson_closed_form():
    sensor = SensorModel(zero_point_e_per_s=4.0e6, exposure_s=0.12, transmission=0.7)  # rounding level: closed forms
    assert sensor.star_electrons(0.0) == pytest.approx(4.0e6 * 0.12 * 0.7)
    assert sensor.star_electrons(5.0) == pytest.approx(4.0e6 * 0.12 * 0.7 / 100.0)
    ratio = star_electrons(2.0, 1.0, 1.0) / star_electrons(3.0, 1.0, 1.0)
    assert ratio == pytest.approx(10**0.4)
    assert magnitude_for_electrons(sensor.star_electrons(6.3), 4.0e6, 0.12, 0.7) == pytest.approx(6.3)
    with pytest.raises(InputError):
        star_electrons(1.0, -1.0, 0.1)


def test_rendered_total_flux_equals_photometry():
    sensor = SensorModel()
    mags = np.array([2.0, 4.5, 6.0])
    uv = np.array([[100.3, 200.7], [400.5, 50.5], [600.9, 610.1]])
    sources = Sources(uv, sensor.star_electrons(mags), sensor.psf_sigma_px)
    charge = expected_charge(sensor, 700, 700, [sources])
    for (u, v), n_e in zip(uv, sensor.star_electrons(mags)):
        r, c = int(round(v)), int(round(u))
        assert charge[r - 8 : r + 9, c - 8 : c + 9].sum() == pytest.approx(n_e, rel=FOOTPRINT_LOSS)  # 2.5e-9 seen
    assert charge.sum() == pytest.approx(sensor.star_electrons(mags).sum(), rel=FOOTPRINT_LOSS)


def test_pixel_integral_matches_supersampled_psf():
    sigma = 0.671
    u0, v0 = 10.37, 9.81
    charge = expected_charge(SensorModel(psf_sigma_px=sigma), 20, 20, [Sources([[u0, v0]], [1.0], sigma)])
    sub = (np.arange(64) + 0.5) / 64 - 0.5
    rows, cols = np.mgrid[6:14, 6:15]
    uu = cols[..., None, None] + sub[None, None, None, :] - u0
    vv = rows[..., None, None] + sub[None, None, :, None] - v0
    brute = np.exp(-(uu**2 + vv**2) / (2 * sigma**2)).mean(axis=(2, 3)) / (2 * np.pi * sigma**2)
    # the 64 x 64 midpoint rule's error bound h²/24 (max |f_uu| + max |f_vv|), h = 1/64, max |f_uu| = 1/(2π σ⁴) at
    # the peak: 1.6e-5 of the star's charge (8e-6 seen)
    np.testing.assert_allclose(charge[6:14, 6:15], brute, atol=(1 / 64) ** 2 / 24 * 2 / (2 * np.pi * sigma**4))
    # rounding level: the renderer's pixel integral is this function
    assert charge[10, 10] == pytest.approx(pixel_fraction(10 - u0, 10 - v0, sigma), rel=1e-12)


def test_smear_profile_matches_box_convolved_gaussian():
    """A star moving uniformly along u: column sums are the pixel integral of a box * Gaussian.

    Sampled at the renderer's step (SMEAR_STEP_SIGMA sigma), the midpoint rule is within 1e-4 of
    the star's charge per pixel.
    """
    sigma, u0, u1, v0 = 0.671, 20.2, 31.7, 15.4
    k = int(np.ceil((u1 - u0) / (SMEAR_STEP_SIGMA * sigma)))
    s = (np.arange(k) + 0.5) / k
    track = np.stack([u0 + s * (u1 - u0), np.full(k, v0)], axis=-1)
    charge = expected_charge(SensorModel(), 32, 52, [Sources(track[None], [1000.0], sigma)])

    def antiderivative(x):  # integral of Phi(x / sigma)
        return x * norm.cdf(x / sigma) + sigma * norm.pdf(x / sigma)

    c = np.arange(52)
    edges_hi, edges_lo = c + 0.5, c - 0.5
    profile = (antiderivative(edges_hi - u0) - antiderivative(edges_hi - u1)
               - antiderivative(edges_lo - u0) + antiderivative(edges_lo - u1)) / (u1 - u0)
    np.testing.assert_allclose(charge.sum(axis=0), 1000.0 * profile, atol=0.1)


def test_empty_frame_noise_statistics():
    rng = np.random.default_rng(5)
    gauss = SensorModel(shot_noise=False, bias_dn=100.0, read_noise_e=20.0, gain_e_per_dn=2.0, dark_e_per_px_s=0.0)
    frame = render(gauss, 256, 256, [], rng)
    assert frame.dtype == np.uint16 and frame.shape == (256, 256)
    assert frame.mean() == pytest.approx(100.0, abs=0.05)
    assert frame.std() == pytest.approx(np.sqrt(10.0**2 + 1 / 12), rel=0.02)
    shot = SensorModel(dark_e_per_px_s=4000.0, exposure_s=0.1, read_noise_e=10.0, gain_e_per_dn=1.0)
    frame = render(shot, 256, 256, [], rng)
    assert frame.mean() == pytest.approx(100.0 + 400.0, abs=0.1)
    assert frame.std() == pytest.approx(np.sqrt(400.0 + 100.0 + 1 / 12), rel=0.02)
    assert shot.noise_dn == pytest.approx(np.sqrt(500.0))


def test_star_shot_noise_is_poisson():
    sensor = SensorModel(read_noise_e=0.0, dark_e_per_px_s=0.0, gain_e_per_dn=1.0, bias_dn=0.0)
    rng = np.random.default_rng(6)
    n_e = 800.0
    stars = Sources(np.column_stack([np.arange(400) % 20 * 10 + 5.0, np.arange(400) // 20 * 10 + 5.0]),
                    np.full(400, n_e), sensor.psf_sigma_px)
    frame = render(sensor, 200, 200, [stars], rng).astype(float)
    totals = frame.reshape(20, 10, 20, 10).sum(axis=(1, 3)).ravel()
    assert totals.mean() == pytest.approx(n_e, abs=4 * np.sqrt(n_e / 400) + 0.5)
    assert totals.var() == pytest.approx(n_e, rel=0.25)


def test_saturation_and_adc_range():
    sensor = SensorModel()
    frame = render(sensor, 64, 64, [Sources([[32.0, 32.0]], [1e7], sensor.psf_sigma_px)], np.random.default_rng(0))
    assert frame.max() == sensor.saturation_dn == 4095
    low_well = SensorModel(full_well_e=2000.0, gain_e_per_dn=2.0)
    assert low_well.saturation_dn == 100 + 1000
    frame = render(low_well, 64, 64, [Sources([[32.0, 32.0]], [1e7], 0.671)], np.random.default_rng(0))
    assert frame.max() == 1100


def test_same_seed_same_frame_and_spawned_streams_differ():
    sensor = SensorModel(hot_pixel_count=20)
    stars = Sources([[30.2, 40.6], [80.0, 10.5]], [5000.0, 800.0], sensor.psf_sigma_px)
    a = render(sensor, 100, 120, [stars], np.random.default_rng(np.random.SeedSequence(42)))
    b = render(sensor, 100, 120, [stars], np.random.default_rng(np.random.SeedSequence(42)))
    c, d = (render(sensor, 100, 120, [stars], np.random.default_rng(s)) for s in np.random.SeedSequence(42).spawn(2))
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(c, d)


def test_windows_are_the_full_frame_pixels():
    sensor = SensorModel()
    rng = np.random.default_rng(7)
    stars = Sources(rng.uniform(5, 250, (30, 2)), rng.uniform(100, 5000, 30), sensor.psf_sigma_px)
    full = expected_charge(sensor, 256, 256, [stars])
    windows = Windows.around(stars.centroids[:8], 5, 256, 256)
    win = expected_charge(sensor, 256, 256, [stars], windows)
    for m in range(8):
        r, c = windows.row0[m], windows.col0[m]
        # rounding level: the same kernel on the same pixels (one code path for frames and windows)
        np.testing.assert_allclose(win[m], full[r : r + 11, c : c + 11], rtol=1e-12, atol=1e-12)
    noisy = render(sensor, 256, 256, [stars], rng, windows)
    assert noisy.shape == (8, 11, 11) and noisy.dtype == np.uint16


def test_hot_pixels_are_fixed_pattern():
    sensor = SensorModel(hot_pixel_count=5, hot_pixel_e_per_s=1e5, exposure_s=0.1)
    rows, cols = sensor.hot_pixels(64, 64)
    for seed in (1, 2):
        frame = render(sensor, 64, 64, [], np.random.default_rng(seed))
        assert np.all(frame[rows, cols] > sensor.background_dn + 1000)
        others = np.ones((64, 64), bool)
        others[rows, cols] = False
        assert frame[others].max() < sensor.background_dn + 8 * sensor.noise_dn


def test_false_sources_deposit_their_charge():
    sensor = SensorModel()
    blob = stray_light(50.0, 40.0, 8.0, 2.0e5)
    ray = cosmic_ray(10.0, 10.0, 30.0, 18.0, 3000.0)
    body = planet(70.0, 70.0, 4.0e4, sensor.psf_sigma_px)
    for source, n_e in ((blob, 2.0e5), (ray, 3000.0), (body, 4.0e4)):
        # the blob (radius 8 px) loses 8.3e-7 beyond its 5-sigma footprint, the others < 1e-10
        assert expected_charge(sensor, 100, 100, [source]).sum() == pytest.approx(n_e, rel=FOOTPRINT_LOSS)
    track = expected_charge(sensor, 100, 100, [ray])
    # 3 of the 20 columns crossed by the track hold 3/20 of its charge
    assert track[:, 19:22].sum() == pytest.approx(3000.0 * 3 / 20, rel=0.02)


def test_star_field_truth_follows_camera_projection():
    camera = Camera.from_fov(20 * DEG, 512, 512)
    sensor = SensorModel()
    rng = np.random.default_rng(8)
    q = Rotation.random(random_state=9).as_quat()
    boresight = Rotation.from_quat(q).apply([0, 0, 1])
    dirs = boresight + rng.normal(0, 0.1, (300, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    mags = rng.uniform(2, 7, 300)
    frame = render_star_field(camera, sensor, q, dirs, mags, rng)
    uv, _ = camera.project(q, dirs[frame.star_index])
    # rounding level: the same projection and photometry
    np.testing.assert_allclose(frame.uv_true, uv, atol=1e-9)
    np.testing.assert_allclose(frame.electrons, sensor.star_electrons(mags[frame.star_index]))
    inside = camera.stars_in_field(q, dirs)
    assert set(inside) <= set(frame.star_index)
    # a body rate smears the stars: the true centroid is the track average
    stars, _ = star_sources(camera, sensor, q, dirs, mags, omega_S=(0.0, 0.05, 0.0))
    assert stars.tracks.shape[1] > 1
    length = np.hypot(*(stars.tracks[0, -1] - stars.tracks[0, 0]))
    assert length == pytest.approx(camera.focal_px * 0.05 * sensor.exposure_s, rel=0.05)


def test_render_bad_input():
    sensor = SensorModel()
    with pytest.raises(InputError, match="Generator"):
        render(sensor, 10, 10, [], rng=42)
    with pytest.raises(InputError, match="radius"):
        Sources([[1.0, 1.0]], [1.0], 0.0)
    with pytest.raises(InputError, match="non-negative"):
        Sources([[1.0, np.nan]], [1.0], 0.6)
    with pytest.raises(InputError, match="transmission"):
        SensorModel(transmission=1.5)
    with pytest.raises(InputError, match="window"):
        Windows.around([[5.0, 5.0]], 10, 8, 8)


def test_peak_fraction_closed_form():
    sigma = 0.671  # rounding level: closed forms (the PSF beyond ±8.5 px is erfc(12.7) ~ 1e-72 of it)
    assert centred_peak_fraction(sigma) == pytest.approx(erf(0.5 / (np.sqrt(2) * sigma)) ** 2)
    assert pixel_fraction(0.0, 0.0, sigma) == pytest.approx(centred_peak_fraction(sigma))
    d = np.arange(-8, 9)
    assert pixel_fraction(d[:, None] + 0.3, d[None, :] - 0.2, sigma).sum() == pytest.approx(1.0, abs=1e-12)
