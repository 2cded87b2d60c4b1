"""The image-fidelity star sensor fuses each identified star with the covariance of its position fit
(startrack.image.psf_fit): at the bound, correlated along the smear trail the body rate draws."""

from pathlib import Path

import numpy as np

from navsim.closed_loop import FrameGrid
from navsim.sensors.star_sensor import FrameRequest
from navsim.simulation import prepare
from startrack.geometry import rotation as rot

DEMO = Path(__file__).resolve().parents[2] / "scenarios" / "demo.toml"


def test_a_fast_roll_makes_each_star_covariance_long_along_its_trail():
    """The demo's sensor (5 ms exposures) turning at 15 deg/s about its x axis (a trail of ~5 px along the
    image rows): every
    fused star's covariance in S is stretched along y_S (the trail) at least threefold, its long axis within
    10 deg of it, and the stars' σ across the trail stays below 0.2 px."""
    prepared = prepare(DEMO, {"duration_s": 2.0, "faults.attitude_jumps": [], "faults.outages": []})
    sensor, q_BS = prepared.sensor, prepared.sensor.q_BS_true
    run = sensor.start(np.random.default_rng(1), np.random.default_rng(2), 4)
    omega_S = np.radians([15.0, 0.0, 0.0])
    q_IB = prepared.truth.q_IB[0]
    omega_B = rot.rotate(q_BS, omega_S)
    truth = type(prepared.truth.at(1))(q_IB=q_IB, omega_B=omega_B)
    frame = run.observe(FrameRequest(index=0, t=0.0, truth=truth, q_IS_pred=rot.multiply(q_IB, q_BS), omega_S_pred=omega_S))
    assert len(frame.ref_I) >= 3 and frame.n_stacked == 0
    focal = sensor.camera.focal_px
    for cov, s in zip(frame.cov_S, frame.obs_S):
        values, vectors = np.linalg.eigh(cov)
        long_axis = vectors[:, 2]
        assert values[2] > 3.0 * values[1] and abs(long_axis @ s) < 1e-6
        assert np.degrees(np.arccos(abs(long_axis[1]) / np.hypot(long_axis[0], long_axis[1]))) < 10.0
        assert np.sqrt(values[1]) * focal < 0.2
    assert isinstance(prepared.grid, FrameGrid)


def test_a_camera_rolling_fast_over_the_pleiades_fuses_no_blended_trail():
    """50 ms exposures rolling at 15 deg/s about x_S (48 px trails along the columns) over the Pleiades, whose
    members lie 20-70 px apart: the trails overlap, which the fits' χ² cannot see; the catalog's predicted
    neighbours flag them ``blended`` and they are not fused, and every star that is fused lies within its
    covariance (Mahalanobis distance below 27.6, χ² of 2 dof at 1e-6)."""
    prepared = prepare(DEMO, {"duration_s": 2.0, "faults.attitude_jumps": [], "faults.outages": [],
                              "star_sensor.image.exposure_s": 0.05, "star_sensor.image.zero_point_e_per_s": 4.0e7,
                              "star_sensor.image.start_tracking": True})
    sensor, q_BS = prepared.sensor, prepared.sensor.q_BS_true
    run = sensor.start(np.random.default_rng(3), np.random.default_rng(4), 4)
    ra, dec = np.radians(56.87), np.radians(24.12 - 4.0)  # the Pleiades 4 deg above the centre
    q_IS = rot.multiply(rot.from_rotation_vector(np.array([0.0, 0.0, ra])),
                        rot.from_rotation_vector(np.array([0.0, np.pi / 2 - dec, 0.0])))
    q_IB = rot.multiply(q_IS, rot.conjugate(q_BS))
    omega_S = np.radians([15.0, 0.0, 0.0])
    truth = type(prepared.truth.at(1))(q_IB=q_IB, omega_B=rot.rotate(q_BS, omega_S))
    frame = run.observe(FrameRequest(index=0, t=0.0, truth=truth, q_IS_pred=q_IS, omega_S_pred=omega_S))
    assert len(frame.ref_I) >= 10 and frame.n_stacked == 0
    errors = frame.obs_S - sensor.camera.to_sensor(q_IS, frame.ref_I)
    mahalanobis = [e @ np.linalg.pinv(c, rcond=1e-12) @ e for e, c in zip(errors, frame.cov_S)]
    assert max(mahalanobis) < 27.6, np.round(mahalanobis, 1)
    assert frame.diagnostics["fits"].blended.sum() >= 2
