"""The vector star sensor reports, per frame, the brightest stars within half its field of the boresight, the
same as a search of the whole catalog frame by frame, however the boresights of a chunk of frames spread
(navsim.sensors.star_vector: a chunk searches only the cap around its boresights)."""

import numpy as np
import pytest

from navsim.sensors.star_vector import StarVectorSensor
from startrack.geometry import rotation as rot

FOV = np.radians(12.0)


def _sensor(rng, stars=4000, max_stars=8):
    vectors = rng.standard_normal((stars, 3))
    vectors /= np.linalg.norm(vectors, axis=1, keepdims=True)
    mags = np.round(rng.uniform(0.0, 6.0, stars), 1)  # ties: the order among equal magnitudes is the catalog's
    return StarVectorSensor(star_vectors=vectors, star_ids=np.arange(stars), star_mags=mags, fov=FOV, sigma=0.0,
                            max_stars=max_stars, q_BS_true=np.array([0.0, 0.0, 0.0, 1.0]), faults=None)


def _whole_catalog(sensor, q_IB):
    """The ids of each frame's stars by a search of the whole catalog."""
    order = np.argsort(sensor.star_mags, kind="stable")
    boresight = rot.rotate(q_IB, np.array([0.0, 0.0, 1.0]))
    out = []
    for axis in boresight:
        seen = order[sensor.star_vectors[order] @ axis >= np.cos(0.5 * FOV)]
        out.append(sensor.star_ids[seen[: sensor.max_stars]])
    return out


def _attitudes(kind, rng, frames=1500):
    if kind == "slow turn":  # an aircraft: the boresight sweeps 90 deg over the run
        angles = np.linspace(0.0, np.pi / 2, frames)[:, None] * np.array([0.0, 1.0, 0.3])
        return rot.multiply(rot.from_rotation_vector(angles), rot.from_rotation_vector(np.array([0.4, -0.2, 1.0])))
    if kind == "tumble":  # a chunk's boresights spread over more than a hemisphere
        return rot.from_rotation_vector(np.linspace(0.0, 3 * np.pi, frames)[:, None] * np.array([1.0, 0.0, 0.0]))
    q = rng.standard_normal((frames, 4))  # every frame anywhere
    return q / np.linalg.norm(q, axis=1, keepdims=True)


@pytest.mark.parametrize("kind", ["slow turn", "tumble", "random"])
def test_each_frame_reports_the_brightest_stars_in_its_field(kind):
    rng = np.random.default_rng(7)
    sensor = _sensor(rng)
    q_IB = _attitudes(kind, rng)
    frames = sensor.observe_frames(q_IB, np.random.default_rng(1))
    expected = _whole_catalog(sensor, q_IB)
    assert sum(len(ids) for ids in expected) > len(q_IB)  # the field holds stars
    for f, ids in enumerate(expected):
        assert np.array_equal(frames.ids[frames.offsets[f]:frames.offsets[f + 1]], ids), f
