"""The compile-ahead tasks of navsim's components and the lanes of each kind of run
(:mod:`startrack.precompile`).

Each task calls one component's kernels through the constructor and the methods a run calls, on made-up
inputs of a run's shapes and types (the methods convert what they are given, so the kernels see the
run's types); ``tests/navsim/test_compile_ahead.py`` checks that a run compiles nothing after its lanes.
"""

import numpy as np

from navsim.estimation.attitude_filter import AttitudeFilter
from navsim.estimation.consistency import nees
from navsim.sensors.gyro import GyroModel
from startrack import rotation as rot

#: The lanes of an attitude run at image fidelity, balanced on two cores (40-46 s each on the test
#: machine, benchmarks/cold_start.py): the identifier's pattern searches, against the inertial sensor,
#: the filter and tracking (which loads what the first lane compiled before it gets there).
ATTITUDE_IMAGE = (("startrack.identify.warmup:pattern_search",),
                  ("navsim.warmup:inertial_sensors", "navsim.warmup:attitude_filter", "startrack.identify.warmup:star_tracking"))
#: A navigation run at image fidelity: the identifier's lanes (the INS's kernels compile at first call).
NAVIGATION_IMAGE = (("startrack.identify.warmup:pattern_search",),
                    ("navsim.warmup:inertial_sensors", "startrack.identify.warmup:star_tracking"))
#: A navigation run at vector fidelity: one lane (a campaign's parent compiles it once for its workers).
NAVIGATION_VECTOR = (("navsim.warmup:navigation_run",),)
#: An attitude run at vector fidelity: one lane (compiling ahead then only says what is compiled, once).
ATTITUDE_VECTOR = (("navsim.warmup:inertial_sensors", "navsim.warmup:attitude_filter"),)


def inertial_sensors():
    """Task: the noise synthesis of the inertial sensors (a second of a tactical gyro, every error on)."""
    GyroModel.preset("tactical", 100.0).measure(np.zeros((100, 3)), 0)


def attitude_filter():
    """Task: the MEKF's steps -- prediction, the sensor's predicted attitude, star and attitude-fix updates
    and their statistics -- with every calibration group estimated, and NEES."""
    n = 21
    filt = AttitudeFilter([0.0, 0.0, 0.0, 1.0], np.zeros(3), np.eye(n) * 1e-6, 1e-6, 1e-9,
                          bias_instability="estimate", scale_factor="estimate", gyro_misalignment="estimate",
                          mounting="estimate", bias_instability_sigma=1e-6, bias_correlation_time=300.0)
    filt.predict(np.zeros((5, 3)), 0.01)
    q_IS, _ = filt.sensor_prediction(np.zeros(3))
    ref_I = rot.rotate(q_IS, np.array([[0.0, 0.0, 1.0], [0.1, 0.0, 1.0], [0.0, 0.1, 1.0]]) / np.sqrt([[1.0], [1.01], [1.01]]))
    filt.update_stars(ref_I, rot.rotate(rot.conjugate(q_IS), ref_I), np.full(3, 1e-5)).statistics()
    filt.update_attitude(q_IS, np.eye(3) * 1e-10).statistics()
    nees(filt.P[None, :6, :6], np.zeros((1, 6)))


#: 20 s of level flight of a SINS/CNS at vector fidelity with a baro and the random gravity field: the
#: kernels of the truth, the INS, its filter and its star, baro and summary steps.
_NAVIGATION = {
    "name": "compile-ahead", "seed": 0, "epoch_utc": "2024-01-15T20:00:00",
    "trajectory": {"start": {"lat_deg": 45.0, "lon_deg": 7.0, "height_m": 11000.0, "speed_m_per_s": 250.0,
                             "heading_deg": 90.0},
                   "segments": [{"kind": "straight", "duration_s": 10.0},
                                {"kind": "turn", "heading_change_deg": 15.0, "rate_deg_per_s": 1.5}]},
    "imu": {"rate_hz": 100.0, "gyro": {"preset": "navigation"}, "accelerometer": {"preset": "navigation"}},
    "baro": {"rate_hz": 1.0, "noise_sigma_m": 5.0},
    "star_sensor": {"measurement": "stars", "rate_hz": 1.0, "fov_deg": 16.0, "mag_limit": 6.0, "max_stars": 10,
                    "star_sigma_arcsec": 5.0, "mounting_rotvec_deg": [180.0, 0.0, 0.0]},
    "gravity": {"model": "random", "xi_arcsec": 3.0, "eta_arcsec": 3.0, "anomaly_mgal": 20.0,
                "correlation_length_m": 100000.0},
}


def navigation_run():
    """Task: a short SINS/CNS run at vector fidelity, step by step and by the compiled record path."""
    from navsim.ins import simulation
    from navsim.scenario import resolve_scenario

    prepared = simulation.prepare(resolve_scenario(_NAVIGATION))
    simulation.simulate(prepared, 0)
    simulation.simulate(prepared, 0, compiled=False)


def kernel_lanes(scenario):
    """The compile-ahead lanes of a run of ``scenario``."""
    image = scenario.data.get("star_sensor", {}).get("fidelity") == "image"
    if scenario.is_navigation:
        return NAVIGATION_IMAGE if image else NAVIGATION_VECTOR
    return ATTITUDE_IMAGE if image else ATTITUDE_VECTOR
