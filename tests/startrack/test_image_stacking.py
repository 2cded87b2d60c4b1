"""004's dim-star stacking: thresholds eq. 4-7, shifts eq. 13, centroid identity eq. 14-18, cache."""

import numpy as np
import pytest

from startrack.base.errors import InputError
from startrack.image.detection import detect
from startrack.image.render import SensorModel, Sources, expected_charge, render
from startrack.image.stacking import (
    DimStarCache,
    cut_window,
    grey_centroid,
    stack,
    stacked_centroid_direct,
    stacked_centroid_from_frames,
    window_centre,
    window_shifts,
)
from startrack.photometry.star_signal import (
    detection_threshold,
    snr,
    stackable_snr_range,
    stacked_snr,
    stacked_threshold,
    static_stacking_gain,
)

GAUSS = SensorModel(shot_noise=False, gain_e_per_dn=1.0, read_noise_e=10.0, dark_e_per_px_s=0.0, bias_dn=100.0)


def test_thresholds_of_004():
    """b = 100, sigma_n = 10, a = 5: V_th = 150 (eq. 4), V_th' = 500 for 4 frames (eq. 5)."""
    assert detection_threshold(100.0, 10.0) == 150.0
    assert stacked_threshold(100.0, 10.0, 4) == 500.0
    assert stacked_threshold(100.0, 10.0, 1) == detection_threshold(100.0, 10.0)
    low, high = stackable_snr_range(4)
    assert (low, high) == (2.5, 5.0)
    # eq. 6 <=> eq. 7: a peak with SNR in [a/sqrt(n), a) is below V_th and n * peak reaches V_th'
    for peak in np.linspace(100.0, 170.0, 141):
        in_range = low <= snr(peak, 100.0, 10.0) < high
        assert in_range == (peak < 150.0 and 4 * peak >= stacked_threshold(100.0, 10.0, 4))
    assert static_stacking_gain(4) == 2.0
    assert stacked_snr(4 * 140.0, 100.0, 10.0, 4) / snr(140.0, 100.0, 10.0) == pytest.approx(2.0)  # rounding level
    with pytest.raises(InputError):
        stackable_snr_range(0)


def test_shifts_of_eq_13():
    centres = np.array([[500, 300], [512, 290], [525, 281], [537, 270]])
    np.testing.assert_array_equal(window_shifts(centres), [[0, 0], [12, -10], [25, -19], [37, -30]])
    assert tuple(window_centre([290.49, 512.5])) == (512, 290)


def test_stacked_centroid_identity_eq_17_18():
    """Eq. 14 on the stacked window equals eq. 17 from the frames' centroids (weighted by the
    window sums), and eq. 18 (plain mean) when the sums are equal (eq. 16)."""
    rng = np.random.default_rng(21)
    windows = rng.uniform(0.0, 50.0, (4, 5, 5)) + 100.0
    centres = np.array([[600, 400], [589, 410], [577, 421], [566, 433]])
    frame_uv, sums = [], []
    for w, c in zip(windows, centres):
        u, v, s = grey_centroid(w, c, background=100.0)
        frame_uv.append((u, v))
        sums.append(s)
    direct = stacked_centroid_direct(windows, centres, background=100.0)  # rounding level below: exact identities
    np.testing.assert_allclose(stacked_centroid_from_frames(frame_uv, centres, sums), direct, atol=1e-12)
    equal = 100.0 + (windows - 100.0) / (windows - 100.0).sum(axis=(1, 2), keepdims=True) * 500.0
    frame_uv = [grey_centroid(w, c, 100.0)[:2] for w, c in zip(equal, centres)]
    np.testing.assert_allclose(stacked_centroid_from_frames(frame_uv, centres),
                               stacked_centroid_direct(equal, centres, 100.0), atol=1e-12)
    # eq. 17 written out for two frames, row coordinate: x_sp = (x_0 + x_1 - N_r1) / 2
    x0, x1 = frame_uv[0][1], frame_uv[1][1]
    n_r1 = centres[1, 0] - centres[0, 0]
    assert stacked_centroid_direct(equal[:2], centres[:2], 100.0)[1] == pytest.approx((x0 + x1 - n_r1) / 2, abs=1e-12)


def _moving_dim_star(peak_dn, rng, n=4, frame_size=64):
    """n frames of one star moving ~7 px per frame with noise-free peak ``peak_dn``."""
    start = np.array([20.3, 25.8])
    step = np.array([6.6, 4.2])
    frames, truth = [], []
    for k in range(n):
        uv = start + k * step
        unit = expected_charge(GAUSS, frame_size, frame_size, [Sources([uv], [1.0], GAUSS.psf_sigma_px)])
        electrons = (peak_dn - GAUSS.bias_dn) / unit.max()
        frames.append(render(GAUSS, frame_size, frame_size, [Sources([uv], [electrons], GAUSS.psf_sigma_px)], rng))
        truth.append(uv)
    return frames, np.array(truth)


def test_dim_star_detected_only_after_stacking():
    """Peak 138 DN: SNR 3.8 inside eq. 7's range [2.5, 5), below V_th alone, above V_th' stacked."""
    rng = np.random.default_rng(22)
    single = stacked = 0
    for trial in range(20):
        frames, truth = _moving_dim_star(138.0, rng)
        cache = DimStarCache(half_width=2, depth=4)
        for frame, uv in zip(frames, truth):
            assert cache.push(frame, uv + rng.uniform(-0.3, 0.3, 2), star_id=7)
        assert cache.full
        single += len(detect(cut_window(frames[-1], window_centre(truth[-1]), 2), background=100.0, sigma_n=10.0)) > 0
        result = cache.stack(GAUSS.bias_dn, GAUSS.read_noise_e)
        assert result.threshold == 500.0 and result.star_id == 7
        np.testing.assert_allclose(result.grey_uv_direct, result.grey_uv_eq17, atol=1e-9)  # rounding level: eq. 17
        if result.detected:
            stacked += 1
            assert np.hypot(result.u - truth[-1, 0], result.v - truth[-1, 1]) < 1.5
    # P(138 + N(0, 10^2) > 150) ~ 0.12 per pixel: a few single-frame detections by noise at most
    assert single <= 8
    assert stacked >= 17


def test_phase_correction_recovers_current_position():
    """Noise-free frames: the eq. 18 centroid sits at the mean sub-pixel phase; the correction
    with exact predictions moves it to the current-frame star within the CoG's own bias."""
    frames, truth = _moving_dim_star(400.0, np.random.default_rng(24))
    clean = []
    for uv in truth:
        unit = expected_charge(GAUSS, 64, 64, [Sources([uv], [1.0], GAUSS.psf_sigma_px)])
        clean.append(unit / unit.max() * 300.0 + 100.0)
    cache = DimStarCache(half_width=2, depth=4)
    for frame, uv in zip(clean, truth):
        cache.push(frame, uv, star_id="x")
    result = cache.stack(100.0, 10.0, centroider="grey")
    phase = truth - np.rint(truth)
    delta = phase[-1] - phase.mean(axis=0)
    # rounding level: the correction is this difference of phases
    np.testing.assert_allclose([result.u_corrected - result.u, result.v_corrected - result.v], delta, atol=1e-12)
    assert np.hypot(result.u_corrected - truth[-1, 0], result.v_corrected - truth[-1, 1]) < 0.06
    assert np.hypot(result.u - truth[-1, 0], result.v - truth[-1, 1]) > 0.1
    with pytest.raises(InputError, match="5 x 5"):
        cache.push_window(np.zeros((3, 3)), (10.0, 10.0), star_id="x")


def test_cache_resets_on_new_candidate_and_at_image_edge():
    image = np.zeros((20, 20))
    cache = DimStarCache(half_width=2, depth=2)
    assert cache.push(image, (10.0, 10.0), star_id=1)
    assert cache.push(image, (11.0, 10.0), star_id=2)
    assert len(cache) == 1 and not cache.full
    with pytest.raises(InputError, match="holds 1 of the 2"):
        cache.stack(100.0, 10.0)
    assert not cache.push(image, (1.0, 10.0), star_id=2)
    assert len(cache) == 0
    assert cut_window(image, (18, 10), 2) is None
    with pytest.raises(InputError):
        DimStarCache(half_width=0)
    with pytest.raises(InputError, match="odd side"):
        stack(np.zeros((4, 4, 4)), np.zeros((4, 2)), 100.0, 10.0)


def test_stacked_detection_matches_detect_on_sum():
    rng = np.random.default_rng(23)
    frames, truth = _moving_dim_star(145.0, rng)
    centres = np.array([window_centre(uv) for uv in truth])[::-1]
    windows = np.array([cut_window(f, c, 2) for f, c in zip(frames[::-1], centres)])
    result = stack(windows, centres, 100.0, 10.0)
    direct = detect(windows.sum(axis=0), background=400.0, sigma_n=20.0)
    assert result.detected and len(direct) >= 1
    assert result.u == pytest.approx(centres[0, 1] - 2 + direct.u[0], abs=1e-12)  # rounding level: the same detect
    assert result.peak == windows.sum(axis=0).max()
