"""The track gate of a star sensor that names its stars with the INS's prior (navsim.sensors.star_prior, eq. 1):
once the filter has accepted a star it is gated on where it was last measured, carried by the INS's own relative
attitude, so the filter's corrections between the frames (its attitude's error changing) do not move the gate."""

from types import SimpleNamespace

import numpy as np
import pytest

from navsim.sensors.star_prior import TRACK_LIFETIME, Detections, PriorIdentifiedRun
from navsim.sensors.star_sensor import FrameRequest, SensorPrior
from startrack import PriorMatch, units
from startrack import rotation as rot

#: Three stars of a 3-deg field, 1" centroids, the prior's error 100" wide and corrected by 20" every frame.
CENTROID, PRIOR_SIGMA, CORRECTION = 1.0 * units.ARCSEC, 100.0 * units.ARCSEC, 20.0 * units.ARCSEC
STARS = np.array([[0.0, 0.0, 1.0], [0.01, 0.004, 1.0], [-0.008, 0.012, 1.0]])
STARS /= np.linalg.norm(STARS, axis=1, keepdims=True)
MAGS = np.array([3.0, 3.5, 4.0])
FRAMES = 140
RATE = np.array([1e-5, -1e-5, 3e-3])  # the sensor's turn [rad/s] (a roll about its boresight), a frame a second


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _detections(rng, q_true, missed=(), distractor=None):
    """Every frame's detections of the three stars (1" noise), without the (frame, star) pairs ``missed``; with
    ``distractor`` = (frame, star, offset [rad]) a false detection of that star's magnitude that far from it."""
    obs, truth, offsets = [], [], [0]
    for j, q in enumerate(q_true):
        s = STARS @ rot.to_matrix(q)  # catalog directions in S
        for i in range(len(STARS)):
            if (j, i) not in missed:
                obs.append(_unit(s[i] + CENTROID * rng.standard_normal(3)))
                truth.append(i)
        if distractor is not None and distractor[0] == j:
            obs.append(_unit(s[distractor[1]] + np.array([distractor[2], 0.0, 0.0])))
            truth.append(-1)
        offsets.append(len(obs))
    n = len(obs)
    return Detections(offsets=np.array(offsets), obs_S=np.array(obs), sigma=np.full(n, CENTROID),
                      mag=MAGS[np.maximum(truth, 0)], mag_sigma=np.full(n, 0.05), truth=np.array(truth),
                      available=np.ones(FRAMES, bool), limiting_mag=np.full(FRAMES, 5.0))


def _run(detections, q_true, rng):
    """Run the sensor over the frames against a filter whose attitude error is 100" wide and that corrects it by a
    20" rotation after every frame (its INS drifting by the gyro's white noise only); the run's per-frame info."""
    matcher = PriorMatch(STARS, MAGS, np.radians(1.5), false_per_frame=0.5)
    run = PriorIdentifiedRun(detections, matcher, STARS)
    error = rot.from_rotation_vector(PRIOR_SIGMA * rng.standard_normal(3) / np.sqrt(3))
    arw = 1e-7  # rad/√s
    infos = []
    for j, q in enumerate(q_true):
        error = rot.multiply(error, rot.from_rotation_vector(arw * rng.standard_normal(3)))
        prior = SensorPrior(q_IS=rot.multiply(q, error), P_theta=PRIOR_SIGMA**2 * np.eye(3), apparent=lambda u: u,
                            arw=arw, P_bias=np.zeros((3, 3)))
        frame = run.observe(FrameRequest(index=j, t=float(j), truth=None, prior=prior))
        infos.append(frame.info)
        update = SimpleNamespace(accepted=np.ones(len(frame.obs_S) if frame.obs_S is not None else 0, bool))
        correction = rot.from_rotation_vector(CORRECTION * _unit(rng.standard_normal(3)))
        error = rot.multiply(rot.conjugate(q), rot.multiply(correction, rot.multiply(q, error)))  # q_post = c ⊗ q_prior
        posterior = SensorPrior(q_IS=rot.multiply(q, error), P_theta=prior.P_theta, apparent=lambda u: u, arw=arw,
                                P_bias=np.zeros((3, 3)))
        run.after_update(update if frame.obs_S is not None else None, posterior)
    return infos


@pytest.fixture(scope="module")
def q_true():
    q0 = rot.from_rotation_vector(np.array([0.0, 0.0, 0.5]))
    return np.array([rot.multiply(q0, rot.from_rotation_vector(RATE * j)) for j in range(FRAMES)])


def test_the_stars_stay_on_their_tracks_while_the_filter_corrects_its_attitude(q_true):
    """Every star after the first frame is named on its track though the attitude moves 20" (20 centroid σ) between
    frames: the gate holds the INS's relative attitude, not the prior's; the tracked matches state the false
    detections' chance only (module docstring of startrack.identify.prior_match): the median tracked frame's sum of
    eq. (2) far below the first frame's."""
    rng = np.random.default_rng(53)
    infos = _run(_detections(rng, q_true), q_true, rng)
    assert all(info["n_identified"] == 3 and info["n_wrong"] == 0 for info in infos)
    assert infos[0]["n_tracked"] == 0 and all(info["n_tracked"] == 3 for info in infos[1:])
    tracked = np.median([info["wrong_expected"] for info in infos[1:]])
    assert tracked < 1e-2 * infos[0]["wrong_expected"]  # measured 2.8e-4: the gates' areas, 2 σ_c² against P_θ


def test_a_false_detection_beside_a_missed_tracked_star_is_not_named(q_true):
    """The first star missed at frame 60 and a false detection of its magnitude 15" (15 σ) from it: inside the
    prior's 100" gate but outside the track's (radius ~6 σ), so it is not named; the star is named again at frame 61
    on its track, and after a gap longer than the track's lifetime it is named on the prior again."""
    rng = np.random.default_rng(54)
    gap = range(70, 70 + int(TRACK_LIFETIME) + 2)
    missed = {(60, 0)} | {(j, 1) for j in gap}
    infos = _run(_detections(rng, q_true, missed, distractor=(60, 0, 15.0 * units.ARCSEC)), q_true, rng)
    assert all(info["n_wrong"] == 0 for info in infos)
    assert infos[60]["n_identified"] == 2 and infos[60]["n_detected"] == 3
    assert infos[61]["n_identified"] == 3 and infos[61]["n_tracked"] == 3
    back = gap.stop
    assert infos[back]["n_identified"] == 3 and infos[back]["n_tracked"] == 2
