"""Full-sky lost-in-space identification on random sky frames from the real catalog.

Frames: every Hipparcos star with V <= 6 in a 16 deg, 1024 x 1024 pinhole field at a uniformly random
attitude, 0.1 px centroid noise, missing and false stars (startrack.image.synthetic).  Truth is the
star each centroid came from and the attitude drawn.
"""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from startrack.camera.model import Camera
from startrack.catalog.hipparcos import load_star_catalog
from startrack.catalog.navigation import NavigationCatalogParams, load_navigation_catalog
from startrack.identify import StarIdentifier
from startrack.image.synthetic import centroid_frame, random_attitude

SIGMA_PX = 0.1


@pytest.fixture(scope="module")
def setup():
    catalog = load_navigation_catalog()
    camera = Camera.from_fov(np.radians(16.0), 1024, 1024)
    stars = load_star_catalog(2000.0).brighter_than(6.0)
    return catalog, camera, stars, StarIdentifier(catalog, camera, centroid_sigma_px=SIGMA_PX)


def _attitude_error_S(q_true, q_est):
    """Rotation vector of R_est^T R_true in sensor axes [rad] (q_true = q_est (x) dq)."""
    return (Rotation.from_quat(q_est).inv() * Rotation.from_quat(q_true)).as_rotvec()


def test_random_frames_with_false_and_missing_stars(setup):
    catalog, camera, stars, identifier = setup
    rng = np.random.default_rng(2024)
    nees, cross, roll, cross_bound, roll_bound = [], [], [], [], []
    for _ in range(60):
        frame = centroid_frame(camera, stars.vectors, stars.hip, stars.v_mag, random_attitude(rng), rng, SIGMA_PX,
                               n_false=rng.integers(0, 4), n_missing=rng.integers(0, 3))
        result = identifier.solve(frame.uv, frame.flux)
        assert result.ok, result.reason
        assert result.method == "lost_in_space"
        truth = frame.hip[result.matches[:, 0]]
        np.testing.assert_array_equal(truth, result.matches[:, 1])  # zero false matches, no false star used
        assert len(result.matches) >= 0.8 * np.count_nonzero(frame.hip)
        assert result.false_match_probability < 1e-6
        error = _attitude_error_S(frame.q_IS, result.q_IS)
        P = result.covariance
        nees.append(error @ np.linalg.solve(P, error))
        cross.append(error[:2] @ error[:2])
        cross_bound.append(P[0, 0] + P[1, 1])
        roll.append(error[2] ** 2)
        roll_bound.append(P[2, 2])
        assert np.all(result.residuals < 5 * SIGMA_PX / camera.focal_px)
    # NEES of 60 frames ~ chi2(180)/60: mean 3 +- 0.32 (1 sigma); the SVD refit reaches the bound.
    assert 2.2 < np.mean(nees) < 3.9
    assert np.sqrt(np.mean(cross) / np.mean(cross_bound)) == pytest.approx(1.0, abs=0.2)
    assert np.sqrt(np.mean(roll) / np.mean(roll_bound)) == pytest.approx(1.0, abs=0.2)


def test_mirror_image_and_random_points_are_not_identified(setup):
    """No sky looks like a mirrored frame or like random points: no answer rather than a wrong one."""
    catalog, camera, stars, identifier = setup
    rng = np.random.default_rng(7)
    for _ in range(10):
        frame = centroid_frame(camera, stars.vectors, stars.hip, stars.v_mag, random_attitude(rng), rng, SIGMA_PX)
        mirrored = frame.uv * [-1.0, 1.0] + [camera.width - 1.0, 0.0]
        assert identifier.solve(mirrored, frame.flux).status == "no_match"
        noise = rng.uniform(0, 1023, (30, 2))
        assert identifier.solve(noise, rng.uniform(1, 10, 30)).status == "no_match"


def test_bad_frames_give_a_status_and_a_reason(setup):
    _, camera, _, identifier = setup
    cases = {
        "error": [np.array([[1.0, 2.0], [np.nan, 3.0], [4.0, 5.0]]), np.full((4, 2), 5000.0), np.zeros((3, 3)),
                  [["a", "b"]]],
        "too_few": [np.array([[1.0, 2.0], [3.0, 4.0]]), np.zeros((0, 2)),
                    np.array([[1.0, 2.0], [3.0, 4.0], [-50.0, 4.0]])],
    }
    for status, frames in cases.items():
        for uv in frames:
            result = identifier.solve(uv)
            assert result.status == status and result.reason and not result.ok
            assert np.all(np.isnan(result.q_IS)) and len(result.matches) == 0
    assert identifier.solve(np.zeros((3, 2)), flux=[1.0, np.inf, 2.0]).status == "error"
    assert identifier.solve_vectors(np.zeros((3, 3))).status == "error"


def test_solve_vectors_agrees_with_solve(setup):
    catalog, camera, stars, identifier = setup
    rng = np.random.default_rng(3)
    frame = centroid_frame(camera, stars.vectors, stars.hip, stars.v_mag, random_attitude(rng), rng, SIGMA_PX)
    by_pixels = identifier.solve(frame.uv, frame.flux)
    by_vectors = identifier.solve_vectors(camera.unproject(frame.uv), frame.flux)
    np.testing.assert_array_equal(by_pixels.matches, by_vectors.matches)
    np.testing.assert_allclose(by_pixels.q_IS, by_vectors.q_IS, atol=1e-12)  # rounding level: the same fit, same vectors


def test_contest_star_maps_of_001():
    """001 §5.4 (fast version of the identification part of scenarios/contest_starmap.toml): 12 x 12 deg, 512 x 512,
    sigma = 0.05 px, random maps with false stars: every map identified, no false match."""
    fov = np.radians(12.0)
    catalog = load_navigation_catalog(NavigationCatalogParams(fov=fov))
    camera = Camera.from_fov(fov, 512, 512)
    stars = load_star_catalog(2000.0).brighter_than(6.0)
    identifier = StarIdentifier(catalog, camera, centroid_sigma_px=0.05)
    rng = np.random.default_rng(54)
    for _ in range(30):
        frame = centroid_frame(camera, stars.vectors, stars.hip, stars.v_mag, random_attitude(rng), rng, 0.05,
                               n_false=rng.integers(1, 4))
        result = identifier.solve(frame.uv, frame.flux)
        assert result.ok, result.reason
        np.testing.assert_array_equal(frame.hip[result.matches[:, 0]], result.matches[:, 1])


def test_frames_with_two_guide_stars_need_the_dense_fall_back(setup):
    """Keep only 2 guide stars of each frame: the guide catalog cannot identify it, the field stars can."""
    catalog, camera, stars, identifier = setup
    no_fallback = StarIdentifier(catalog, camera, centroid_sigma_px=SIGMA_PX, dense_fallback=False)
    guide = set(catalog.guide_hip.tolist())
    rng = np.random.default_rng(22)
    for _ in range(5):
        frame = centroid_frame(camera, stars.vectors, stars.hip, stars.v_mag, random_attitude(rng), rng, SIGMA_PX,
                               n_false=2)
        is_guide = np.array([h in guide for h in frame.hip])
        keep = ~is_guide | (np.cumsum(is_guide) <= 2)
        uv, flux, hip = frame.uv[keep], frame.flux[keep], frame.hip[keep]
        assert no_fallback.solve(uv, flux).status == "no_match"
        result = identifier.solve(uv, flux)
        assert result.ok and result.method == "lost_in_space"
        np.testing.assert_array_equal(hip[result.matches[:, 0]], result.matches[:, 1])


@pytest.mark.parametrize("copies", [5, 20])
def test_repeated_centroids_count_once(setup, copies):
    """Every centroid repeated (jittered by 0.05 px) ``copies`` times: the same stars are identified as
    from the frame itself, at the attitude the frame gives, and pure repeats of one point are too few stars — never a
    search that explodes with the repeats (issue 14: 20 copies used never to finish)."""
    catalog, camera, stars, identifier = setup
    rng = np.random.default_rng(7)
    frame = centroid_frame(camera, stars.vectors, stars.hip, stars.v_mag, random_attitude(rng), rng, SIGMA_PX)
    single = identifier.solve(frame.uv, frame.flux)
    uv = np.repeat(frame.uv, copies, axis=0) + rng.normal(0.0, 0.05, (len(frame.uv) * copies, 2))
    repeated = identifier.solve(uv, np.repeat(frame.flux, copies))
    assert single.ok and repeated.ok
    assert set(repeated.matches[:, 1]) == set(single.matches[:, 1])
    # the brightest copy stands for each star, 0.05 px off: the attitude moves by as much, not by degrees
    assert np.degrees(np.linalg.norm(_attitude_error_S(frame.q_IS, repeated.q_IS))) * 3600 < 30.0
    assert identifier.solve(np.repeat([[500.0, 500.0]], 20, axis=0)).status == "too_few"
