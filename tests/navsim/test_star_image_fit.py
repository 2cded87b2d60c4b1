"""The image-fidelity star sensor fuses each identified star with the covariance of its position fit
(startrack.psf_fit): at the bound, correlated along the smear trail the body rate draws."""

from pathlib import Path

import numpy as np

from navsim.closed_loop import FrameGrid
from navsim.sensors.star_sensor import FrameRequest
from navsim.simulation import prepare
from startrack import rotation as rot

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
