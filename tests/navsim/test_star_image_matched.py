"""The image-fidelity star sensor's full-frame detector chosen by ``star_sensor.image.detection``: the matched
filter for the trail the predicted rate draws (startrack.image.trail_detection) finds the faint trailed stars
004's threshold misses, and they are stars."""

from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

from navsim.scenario.star_sensor_fields import STAR_SENSOR
from navsim.sensors.frame_detection import FULL_FRAME_DETECTORS
from navsim.sensors.star_sensor import FrameRequest
from navsim.simulation import prepare
from startrack.geometry import rotation as rot

DEMO = Path(__file__).resolve().parents[2] / "scenarios" / "demo.toml"


def _first_frame(detection):
    """(frame, sensor, trail length [px]) of the demo's first (full, lost-in-space) frame turning at 15 deg/s about
    x_S, read with ``detection``."""
    prepared = prepare(DEMO, {"duration_s": 2.0, "faults.attitude_jumps": [], "faults.outages": [],
                              "star_sensor.image.detection": detection})
    sensor, q_BS = prepared.sensor, prepared.sensor.q_BS_true
    run = sensor.start(np.random.default_rng(1), np.random.default_rng(2), 4)
    omega_S = np.radians([15.0, 0.0, 0.0])
    q_IB = prepared.truth.q_IB[0]
    truth = type(prepared.truth.at(1))(q_IB=q_IB, omega_B=rot.rotate(q_BS, omega_S))
    request = FrameRequest(index=0, t=0.0, truth=truth, q_IS_pred=rot.multiply(q_IB, q_BS), omega_S_pred=omega_S)
    trail_px = omega_S[0] * sensor.frame_model(0).exposure_s * sensor.camera.focal_px
    return run.observe(request), sensor, trail_px


def test_the_matched_filter_finds_more_trailed_stars_and_identifies_the_frame():
    """The same frame (same seeds) read both ways: the matched filter detects more, every one of its detections
    within 1.5 px + L/2 of a drawn star's image (in the frame or just beyond its border, whose light reaches
    in; the default 0.01 false detections per frame), and the frame
    is identified with as many stars as by the threshold."""
    threshold, _, _ = _first_frame("threshold")
    matched, sensor, trail_px = _first_frame("matched")
    assert matched.info["n_detected"] > threshold.info["n_detected"]
    assert len(matched.ref_I) >= len(threshold.ref_I) >= 3
    q_IS_true = matched.diagnostics["q_IS_true"]
    directions, _ = sensor.drawn_stars(q_IS_true, None, 0)
    uv, _ = sensor.camera.project(q_IS_true, directions)
    in_front = np.all(np.isfinite(uv), axis=1) & (sensor.camera.to_sensor(q_IS_true, directions)[:, 2] > 0)
    distance, _ = cKDTree(uv[in_front]).query(matched.diagnostics["detections"].uv)
    assert np.all(distance <= 1.5 + 0.5 * trail_px), np.round(distance, 1)


def test_every_detector_the_schema_offers_is_a_strategy_of_the_registry():
    """``star_sensor.image.detection``'s choices are the keys of navsim.sensors.frame_detection's registry (the
    scenario layer, a floor below, cannot import it), and each builds a detector from the image table."""
    choices = STAR_SENSOR["image"].entries["detection"].choices
    assert set(choices) == set(FULL_FRAME_DETECTORS)
    for name in choices:
        assert callable(FULL_FRAME_DETECTORS[name]({"detection_sigmas": 5.0}).find)
