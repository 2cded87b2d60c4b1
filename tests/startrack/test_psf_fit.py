"""Star positions at the Cramér-Rao bound (startrack.image.psf_fit): the bound against its closed forms, the fit
against the bound on frames rendered without the project's renderer (tests/star_images.py), its
covariance against the errors, and the flags of what the model cannot explain."""

import json

import numpy as np
import pytest

from startrack.base.errors import InputError
from startrack.image.psf_fit import PixelNoise, centroid_bound, fit_stars
from tests.star_images import noisy_frame


def test_the_bound_of_a_bright_star_is_the_psf_variance_over_its_photons():
    """No background, a PSF wide against the pixel: σ_u² = (σ² + 1/12)/N_e (the pixel-integrated PSF's
    variance; its higher-order terms ~e^(−2π²σ²) vanish at σ = 3 px)."""
    sigma, photons = 3.0, 1e6
    bound = centroid_bound((10.3, 20.7), photons, sigma, PixelNoise(1e-3, gain_e_per_dn=1.0, quantised=False))
    assert bound[0, 0] == pytest.approx((sigma**2 + 1 / 12) / photons, rel=1e-4)
    assert bound[1, 1] == pytest.approx(bound[0, 0], rel=1e-4) and abs(bound[0, 1]) < 1e-4 * bound[0, 0]


def test_the_bound_of_a_faint_star_on_a_bright_sky_is_background_limited():
    """B = 10⁴ e² per pixel against 300 e-: σ_u² = 8π s⁴ B / N_e² with s² = σ² + 1/12 (0.5 %: the
    pixel-integrated PSF as a Gaussian of variance s², exact to second order in 1/σ²; the star's own shot
    noise adds 300/(2π s² B) ~ 5e-4)."""
    sigma, photons, background = 3.0, 300.0, 1e4
    bound = centroid_bound((10.3, 20.7), photons, sigma, PixelNoise(np.sqrt(background), gain_e_per_dn=1.0,
                                                                    quantised=False))
    s2 = sigma**2 + 1 / 12
    assert bound[0, 0] == pytest.approx(8 * np.pi * s2**2 * background / photons**2, rel=5e-3)


def test_smear_correlates_the_axes_along_the_trail():
    """A trail along (2, 1): the bound's long axis lies along it and u, v are positively correlated."""
    bound = centroid_bound((10.3, 20.7), 5000.0, 0.7, PixelNoise(5.0, gain_e_per_dn=2.0), smear_px=(6.0, 3.0))
    values, vectors = np.linalg.eigh(bound)
    along = vectors[:, 1] * np.sign(vectors[0, 1])
    assert bound[0, 1] > 0 and values[1] > 3 * values[0]
    assert np.degrees(np.arccos(along @ np.array([2.0, 1.0]) / np.sqrt(5.0))) < 5.0


SKY, READ, GAIN, BIAS, SIGMA = 100.0, 5.0, 1.0, 100.0, 0.8
NOISE = PixelNoise(np.sqrt(SKY + READ**2) / GAIN, gain_e_per_dn=GAIN)


@pytest.mark.parametrize("photons, smear", [(1000.0, (0.0, 0.0)), (30000.0, (0.0, 0.0)), (3000.0, (5.2, 3.0))])
def test_the_fit_reaches_the_bound_with_an_honest_covariance(photons, smear):
    """300 stars at random sub-pixel phases (integrated SNR 20-200): the RMS error per axis is the bound's
    within 14 % (the RMS of 300 draws scatters by 1/√600 = 4 %: 3.5σ), and the Mahalanobis distance of each
    error under the fit's own covariance averages 2 (χ² of 2 dof) within 0.35 (3σ of the mean of 300)."""
    rng = np.random.default_rng(11)
    errors, covariances, bounds = [], [], []
    for _ in range(300):
        u, v = 12.0 + rng.uniform(-0.5, 0.5, 2)
        image = noisy_frame(rng, (25, 25), [(u, v, photons, smear)], SIGMA, SKY, READ, GAIN, BIAS)
        fits = fit_stars(image, [[u + rng.normal(0, 0.3), v + rng.normal(0, 0.3)]], SIGMA, NOISE, BIAS + SKY / GAIN,
                         smear_px=smear)
        assert not fits.failed[0] and not fits.edge[0]
        errors.append(fits.uv[0] - (u, v))
        covariances.append(fits.cov[0])
        bounds.append(centroid_bound((u, v), photons / GAIN, SIGMA, NOISE, smear))
    errors, covariances, bounds = np.array(errors), np.array(covariances), np.array(bounds)
    ratio = np.sqrt(np.mean(errors**2, axis=0) / np.mean(bounds[:, [0, 1], [0, 1]], axis=0))
    assert np.all(np.abs(ratio - 1.0) < 0.14), ratio
    mahalanobis = np.einsum("ni,nij,nj->n", errors, np.linalg.inv(covariances), errors)
    assert mahalanobis.mean() == pytest.approx(2.0, abs=0.35)


def test_a_hot_pixel_and_a_blend_are_outliers_and_their_covariance_grows():
    rng = np.random.default_rng(3)
    clean = noisy_frame(rng, (25, 25), [(12.3, 11.8, 5000.0, (0.0, 0.0))], SIGMA, SKY, READ, GAIN, BIAS)
    hot = clean.copy()
    hot[13, 14] += 800.0  # one pixel 2 px from the star's centre
    blend = noisy_frame(rng, (25, 25), [(12.3, 11.8, 5000.0, (0.0, 0.0)), (13.9, 12.6, 2500.0, (0.0, 0.0))],
                        SIGMA, SKY, READ, GAIN, BIAS)
    fits = [fit_stars(image, [[12.3, 11.8]], SIGMA, NOISE, BIAS + SKY) for image in (clean, hot, blend)]
    assert not fits[0].outlier[0] and fits[1].outlier[0] and fits[2].outlier[0]
    for flagged in fits[1:]:
        assert flagged.chi2[0] / flagged.dof[0] > 2.0
        assert np.trace(flagged.cov[0]) > 2.0 * np.trace(fits[0].cov[0])  # scaled by the measured χ²/dof


def test_overlapping_trails_fool_the_chi2_so_a_known_neighbour_flags_the_blend():
    """Two stars of a fast-turning camera, 40 px trails along v, 6 px apart along them (a pair or a cluster
    seen by a sensor rolling into a turn): each pixel holds little of either, the pair looks like one longer
    trail and the fit slides along it with a χ²/dof near 1 -- errors far beyond the covariance. Told where the
    other star is (a catalog's prediction), the fit flags the star ``blended`` and not usable."""
    rng = np.random.default_rng(12)
    smear = (0.0, 40.0)
    mahalanobis, blended = [], []
    for _ in range(20):
        u, v = 30.0 + rng.uniform(-0.5, 0.5, 2)
        image = noisy_frame(rng, (100, 60), [(u, v + 20.0, 3000.0, smear), (u + 0.5, v + 26.0, 3000.0, smear)],
                            SIGMA, SKY, READ, GAIN, BIAS)
        start = [[u + rng.normal(0, 0.5), v + 20.0 + rng.normal(0, 3.0)]]
        alone = fit_stars(image, start, SIGMA, NOISE, BIAS + SKY, smear_px=smear)
        if alone.usable[0]:
            error = alone.uv[0] - (u, v + 20.0)
            mahalanobis.append(error @ np.linalg.inv(alone.cov[0]) @ error)
        told = fit_stars(image, start, SIGMA, NOISE, BIAS + SKY, smear_px=smear, neighbours=[[(u + 0.5, v + 26.0)]])
        blended.append(told.blended[0] and not told.usable[0])
    assert len(mahalanobis) >= 5 and np.median(mahalanobis) > 20.0  # χ² of 2 dof: 13.8 at 99.9 %
    assert all(blended)


def test_a_bright_neighbour_just_beyond_the_reach_leaves_the_fit_unbiased():
    """A neighbour 100 times brighter 8.6 px from the centre of the fit window (the reach of a 0.8 px PSF's
    9 x 9 window is 8.5 px): not flagged, and its light does not reach the fit (300 draws: mean error within
    3σ of the mean, Mahalanobis mean 2 within 0.35); 0.2 px closer it is flagged."""
    rng = np.random.default_rng(13)
    errors, covariances = [], []
    for _ in range(300):
        u, v = 20.0 + rng.uniform(-0.45, 0.45, 2)  # the window centred on pixel (20, 20)
        image = noisy_frame(rng, (40, 40), [(u, v, 5000.0, (0.0, 0.0)), (28.6, v, 5e5, (0.0, 0.0))],
                            SIGMA, SKY, READ, GAIN, BIAS)
        fits = fit_stars(image, [[20.0, 20.0]], SIGMA, NOISE, BIAS + SKY, neighbours=[[(28.6, v)]])
        assert fits.usable[0] and not fits.outlier[0]
        errors.append(fits.uv[0] - (u, v))
        covariances.append(fits.cov[0])
    assert_unbiased_and_honest(errors, covariances, 0.35)
    closer = fit_stars(image, [[20.0, 20.0]], SIGMA, NOISE, BIAS + SKY, neighbours=[[(28.4, v)]])
    assert closer.blended[0] and not closer.usable[0]


def test_edge_saturation_and_an_empty_window_are_flagged():
    rng = np.random.default_rng(4)
    image = noisy_frame(rng, (25, 25), [(1.2, 12.0, 5000.0, (0.0, 0.0)), (15.0, 12.0, 2e5, (0.0, 0.0))],
                        SIGMA, SKY, READ, GAIN, BIAS)
    saturation = 4000.0
    fits = fit_stars(np.minimum(image, saturation), [[1.2, 12.0], [15.0, 12.0], [20.0, 3.0]], SIGMA, NOISE,
                     BIAS + SKY, saturation_dn=saturation)
    assert fits.edge[0] and fits.usable[0] and np.hypot(*(fits.uv[0] - (1.2, 12.0))) < 5.0 * np.sqrt(np.trace(fits.cov[0]))
    assert fits.saturated[1] and not fits.failed[1] and np.hypot(*(fits.uv[1] - (15.0, 12.0))) < 0.05
    assert fits.failed[2] and not fits.usable[2]  # nothing there: no position, no crash


def test_a_star_cut_by_the_border_stays_unbiased():
    """Centres in the first column (a third to a half of the light outside the frame), 300 draws: the model
    knows which pixels it has, so the mean error is zero within 3σ of the mean (σ/√300) and the Mahalanobis
    distance averages 2 within 0.4 (3σ of the mean of 300 χ²(2); measured 1.83-1.88: the covariance at
    the estimate is slightly wider than the errors across the border)."""
    rng = np.random.default_rng(8)
    errors, covariances = [], []
    for _ in range(300):
        u, v = rng.uniform(0.0, 0.6), 12.0 + rng.uniform(-0.5, 0.5)
        image = noisy_frame(rng, (25, 25), [(u, v, 5000.0, (0.0, 0.0))], SIGMA, SKY, READ, GAIN, BIAS)
        fits = fit_stars(image, [[u + rng.normal(0, 0.2), v + rng.normal(0, 0.2)]], SIGMA, NOISE, BIAS + SKY)
        assert fits.edge[0] and fits.usable[0]
        errors.append(fits.uv[0] - (u, v))
        covariances.append(fits.cov[0])
    assert_unbiased_and_honest(errors, covariances, 0.4)


def assert_unbiased_and_honest(errors, covariances, mahalanobis_tolerance):
    """The mean of the errors (N, 2) [px] is zero within 3σ of the mean (σ/√N), and their Mahalanobis
    distance under the fits' covariances (N, 2, 2) averages 2 (χ² of 2 dof) within the tolerance."""
    errors, covariances = np.array(errors), np.array(covariances)
    limit = 3.0 * np.sqrt(covariances[:, [0, 1], [0, 1]].mean(axis=0) / len(errors))
    assert np.all(np.abs(errors.mean(axis=0)) < limit)
    mahalanobis = np.einsum("ni,nij,nj->n", errors, np.linalg.inv(covariances), errors)
    assert mahalanobis.mean() == pytest.approx(2.0, abs=mahalanobis_tolerance)


def test_a_window_of_the_frame_fits_in_image_coordinates():
    rng = np.random.default_rng(5)
    image = noisy_frame(rng, (40, 60), [(41.4, 27.6, 8000.0, (0.0, 0.0))], SIGMA, SKY, READ, GAIN, BIAS)
    whole = fit_stars(image, [[41.0, 28.0]], SIGMA, NOISE, BIAS + SKY)
    window = fit_stars(image[20:35, 33:50], [[41.0, 28.0]], SIGMA, NOISE, BIAS + SKY, origin=(20, 33))
    np.testing.assert_allclose(window.uv, whole.uv, atol=1e-9)  # the same pixels: rounding level


def test_the_command_line_fits_and_reports_the_covariance(tmp_path, capsys):
    """``startrack detect --psf-sigma-px`` adds each star's fitted position, 2 x 2 covariance and flags."""
    from startrack import cli

    rng = np.random.default_rng(6)
    image = noisy_frame(rng, (64, 64), [(20.3, 30.6, 5000.0, (0.0, 0.0)), (45.1, 12.4, 20000.0, (0.0, 0.0))], SIGMA,
                        SKY, READ, GAIN, BIAS)
    np.save(tmp_path / "frame.npy", image.astype(np.uint16))
    assert cli.main(["detect", str(tmp_path / "frame.npy"), "--psf-sigma-px", "0.8", "--gain-e-per-dn", "1",
                     "--mesh-px", "0", "--json"]) == 0
    stars = json.loads(capsys.readouterr().out)["stars"]
    truth = {45: (45.1, 12.4, 20000.0), 20: (20.3, 30.6, 5000.0)}
    for star in stars:
        fit = star["psf_fit"]
        u, v, photons = truth[int(round(star["u"]))]
        bound = centroid_bound((u, v), photons, SIGMA, NOISE)
        assert not any(fit[flag] for flag in ("outlier", "edge", "saturated", "failed"))
        assert np.sqrt(np.diag(fit["cov_uv_px2"])) == pytest.approx(np.sqrt(np.diag(bound)), rel=0.1)
        assert np.hypot(fit["u"] - u, fit["v"] - v) < 5.0 * np.sqrt(np.trace(bound))
    assert cli.main(["detect", str(tmp_path / "frame.npy"), "--gain-e-per-dn", "1"]) == 2
    assert "--gain-e-per-dn given without --psf-sigma-px" in capsys.readouterr().err


@pytest.mark.parametrize("call, message", [
    (lambda: fit_stars(np.zeros(5), [[1.0, 1.0]], 0.8, NOISE, 100.0), "2-D image"),
    (lambda: fit_stars(np.zeros((9, 9)), [[4.0, 4.0]], -1.0, NOISE, 100.0), "PSF radius"),
    (lambda: fit_stars(np.zeros((9, 9)), [[4.0, 4.0]], 0.8, NOISE, 100.0, neighbours=[]), "neighbours for 0 stars"),
    (lambda: PixelNoise(float("nan")), "sigma_n"),
    (lambda: PixelNoise(1.0, gain_e_per_dn=0.0), "gain"),
    (lambda: centroid_bound((1.0, 1.0), -5.0, 0.8, NOISE), "positive flux"),
])
def test_bad_input_is_one_clear_error(call, message):
    with pytest.raises(InputError, match=message):
        call()
