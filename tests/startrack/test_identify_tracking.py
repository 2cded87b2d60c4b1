"""Tracking from a prior attitude and rate: windows around predicted stars, entering, leaving and lost stars."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from startrack.camera.model import Camera
from startrack.catalog.hipparcos import load_star_catalog
from startrack.catalog.navigation import load_navigation_catalog
from startrack.identify import Prior, StarIdentifier
from startrack.image.synthetic import centroid_frame

DEG = np.pi / 180.0


@pytest.fixture(scope="module")
def setup():
    catalog = load_navigation_catalog()
    camera = Camera.from_fov(16.0 * DEG, 1024, 1024)
    stars = load_star_catalog(2000.0).brighter_than(6.0)
    return catalog, camera, stars, StarIdentifier(catalog, camera, centroid_sigma_px=0.1)


def test_tracking_a_slew_with_entering_and_leaving_stars(setup):
    """A 2 deg/s slew sampled at 2 Hz for 15 s (30 deg): every frame tracked from the previous fix and
    rate; stars enter and leave the field and are reported as such."""
    catalog, camera, stars, identifier = setup
    rng = np.random.default_rng(15)
    rate_S = 2.0 * DEG * np.array([2.0, 1.0, 0.5]) / np.linalg.norm([2.0, 1.0, 0.5])
    q0 = Rotation.from_euler("zyx", [30.0, -20.0, 10.0], degrees=True)
    dt = 0.5
    previous = None
    entered_total = 0
    for k in range(31):
        q_true = (q0 * Rotation.from_rotvec(rate_S * dt * k)).as_quat()
        frame = centroid_frame(camera, stars.vectors, stars.hip, stars.v_mag, q_true, rng, 0.1, n_missing=1)
        prior = None if previous is None else Prior(q_IS=previous.q_IS, rate_S=rate_S, dt=dt,
                                                    tracked_hip=previous.matched_hip)
        result = identifier.solve(frame.uv, frame.flux, prior)
        assert result.ok, result.reason
        assert result.method == ("lost_in_space" if previous is None else "tracking")
        np.testing.assert_array_equal(frame.hip[result.matches[:, 0]], result.matches[:, 1])
        if previous is not None:
            new = np.setdiff1d(result.matched_hip, previous.matched_hip)
            np.testing.assert_array_equal(result.entered_hip, new)
            # a lost star was tracked, is predicted in the field and was not found (here: the missing star)
            assert set(result.lost_hip.tolist()) <= set(previous.matched_hip.tolist()) - set(result.matched_hip.tolist())
            for hip in set(result.lost_hip.tolist()) - set(frame.missing_hip.tolist()):
                uv, _ = camera.project(q_true, stars.vectors[stars.hip == hip])  # otherwise: at the border
                assert min(uv[0, 0] + 0.5, uv[0, 1] + 0.5, camera.width - 0.5 - uv[0, 0],
                           camera.height - 0.5 - uv[0, 1]) < 1.0
            entered_total += len(new)
        previous = result
    assert entered_total > 20  # the field moved by 30 deg: stars entered (and others left)


def test_a_removed_tracked_star_is_reported_lost(setup):
    catalog, camera, stars, identifier = setup
    rng = np.random.default_rng(16)
    q = Rotation.from_euler("zyx", [100.0, 35.0, -40.0], degrees=True).as_quat()
    frame = centroid_frame(camera, stars.vectors, stars.hip, stars.v_mag, q, rng, 0.1)
    first = identifier.solve(frame.uv, frame.flux)
    gone = first.matches[0]
    keep = np.arange(len(frame.uv)) != gone[0]
    second = identifier.solve(frame.uv[keep], frame.flux[keep], Prior(q_IS=first.q_IS, tracked_hip=first.matched_hip))
    assert second.method == "tracking"
    np.testing.assert_array_equal(second.lost_hip, [gone[1]])
    assert len(second.entered_hip) == 0
    untracked = identifier.solve(frame.uv[keep], frame.flux[keep], Prior(q_IS=first.q_IS))  # nothing tracked before
    assert untracked.method == "tracking" and len(untracked.lost_hip) == 0
    np.testing.assert_array_equal(untracked.entered_hip, np.sort(untracked.matched_hip))


def test_a_prior_beyond_the_window_hands_over_to_the_sub_catalog(setup):
    catalog, camera, stars, identifier = setup
    rng = np.random.default_rng(17)
    q = Rotation.from_euler("zyx", [200.0, -50.0, 60.0], degrees=True)
    frame = centroid_frame(camera, stars.vectors, stars.hip, stars.v_mag, q.as_quat(), rng, 0.1)
    off = (q * Rotation.from_rotvec([1.0 * DEG, 0.0, 0.0])).as_quat()  # 1 deg ~ 64 px, beyond the 20 px window
    result = identifier.solve(frame.uv, frame.flux, Prior(q_IS=off))
    assert result.ok and result.method == "subcatalog"
    near = (q * Rotation.from_rotvec([0.05 * DEG, 0.0, 0.1 * DEG])).as_quat()  # 3 px: tracked
    assert identifier.solve(frame.uv, frame.flux, Prior(q_IS=near)).method == "tracking"


@pytest.mark.parametrize("kwargs", [{"q_IS": [0.0, 0.0, 0.0, 0.0]}, {"q_IS": [np.nan, 0, 0, 1]}, {"q_IS": [0, 0, 1]},
                                    {"rate_S": [0.0, 1.0]}, {"dt": float("inf")}, {"boresight": (0.0, 2.0)}])
def test_bad_priors_are_refused(kwargs):
    from startrack.base.errors import InputError

    with pytest.raises(InputError):
        Prior(**kwargs)
