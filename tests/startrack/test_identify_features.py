"""Angular-distance features and the error gate e_ij of 001 §4.3.1, against brute force."""

import numpy as np
import pytest

from startrack.camera.model import Camera
from startrack.identify.features import FrameFeatures, pair_features

FOCAL_PX = 512.0 / np.tan(np.radians(8.0))  # 16 deg over 1024 px


def _random_pixels(rng, n):
    return rng.uniform(0.0, 1023.0, (n, 2))


def _directions(camera, uv):
    return camera.unproject(uv)


@pytest.fixture(scope="module")
def camera():
    return Camera.from_fov(np.radians(16.0), 1024, 1024)


def test_angles_match_brute_force(camera):
    rng = np.random.default_rng(1)
    obs = _directions(camera, _random_pixels(rng, 12))
    beta, gate = pair_features(obs, camera.focal_px, 0.3)
    expected = np.arctan2(np.linalg.norm(np.cross(obs[:, None], obs[None, :]), axis=-1), obs @ obs.T)
    off = ~np.eye(len(obs), dtype=bool)
    # rounding level: arccos's rounding, eps / sin β, is below 1e-11 rad (5e-9 px) for stars > 0.1 px apart
    np.testing.assert_allclose(beta[off], expected[off], rtol=0, atol=1e-11)
    assert np.all(np.isinf(np.diag(gate)))
    assert np.allclose(gate, gate.T)


def test_gate_bounds_every_corner_of_the_error_box(camera):
    """Moving every centroid to a corner of its +-delta box never changes beta by more than e_ij."""
    rng = np.random.default_rng(2)
    delta = 0.3
    uv = _random_pixels(rng, 10)
    obs = _directions(camera, uv)
    beta, gate = pair_features(obs, camera.focal_px, delta)
    worst = 0.0
    for _ in range(400):
        moved = uv + delta * rng.choice([-1.0, 1.0], uv.shape)
        beta_moved, _ = pair_features(_directions(camera, moved), camera.focal_px, delta)
        off = ~np.eye(len(uv), dtype=bool)
        worst = max(worst, np.max(np.abs(beta_moved - beta)[off] / gate[off]))
    assert worst <= 1.01  # the bound is first order; second-order terms are < 1 % of it
    assert worst > 0.5  # and the bound is not loose by a large factor


def test_gate_is_tighter_than_001_absolute_jacobian_bound(camera):
    """001's e sums |dv/dX| entries (|v_m| <= 1); the tightened bound keeps v^T and is never larger."""
    rng = np.random.default_rng(3)
    delta = 0.05
    uv = _random_pixels(rng, 8)
    obs = _directions(camera, uv)
    _, gate = pair_features(obs, camera.focal_px, delta)
    step = 1e-4
    jac = np.stack([(_directions(camera, uv + [step, 0.0]) - _directions(camera, uv - [step, 0.0])) / (2 * step),
                    (_directions(camera, uv + [0.0, step]) - _directions(camera, uv - [0.0, step])) / (2 * step)], -1)
    spread = np.abs(jac).sum(axis=(1, 2))
    sine = np.sqrt(1.0 - np.clip(obs @ obs.T, -1, 1) ** 2)
    with np.errstate(divide="ignore"):
        e_001 = delta * (spread[:, None] + spread[None, :]) / sine
    off = ~np.eye(len(uv), dtype=bool)
    assert np.all(gate[off] <= e_001[off] * (1.0 + 1e-6))


def test_three_sigma_gate_holds_gaussian_noise(camera):
    """delta = 3 sigma: |d beta| > e_ij for at most ~0.3 % of pairs under Gaussian centroid noise."""
    rng = np.random.default_rng(4)
    sigma = 0.1
    uv = _random_pixels(rng, 12)
    beta, gate = pair_features(_directions(camera, uv), camera.focal_px, 3.0 * sigma)
    off = ~np.eye(len(uv), dtype=bool)
    exceed = []
    for _ in range(300):
        noisy, _ = pair_features(_directions(camera, uv + rng.normal(0, sigma, uv.shape)), camera.focal_px, 0.3)
        exceed.append(np.mean(np.abs(noisy - beta)[off] > gate[off]))
    assert np.mean(exceed) < 0.003


def test_frame_features_keep_the_brightest_pattern_stars(camera):
    rng = np.random.default_rng(5)
    obs = _directions(camera, _random_pixels(rng, 20))
    frame = FrameFeatures.build(obs, np.arange(20), camera.focal_px, 0.3, 1e-4, 6)
    assert frame.beta.shape == (6, 6) and len(frame) == 20
    np.testing.assert_allclose(frame.beta, pair_features(obs[:6], camera.focal_px, 0.3)[0])  # the same kernel
