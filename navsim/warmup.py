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

#: The lanes of an attitude run at image fidelity, balanced on two cores (~30 s each on the test
#: machine): the identifier's pattern searches, against the inertial sensor, the filter and tracking
#: (whose verification kernel the first lane compiles early and the second then loads).
ATTITUDE_IMAGE = (("startrack.identify.warmup:pattern_search",),
                  ("navsim.warmup:inertial_sensors", "navsim.warmup:attitude_filter", "startrack.identify.warmup:star_tracking"))
#: A navigation run at image fidelity: the identifier's lanes (the INS's kernels compile at first call).
NAVIGATION_IMAGE = (("startrack.identify.warmup:pattern_search",),
                    ("navsim.warmup:inertial_sensors", "startrack.identify.warmup:star_tracking"))
#: At vector fidelity: one lane (compiling ahead then only says what is compiled, once).
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


def kernel_lanes(scenario):
    """The compile-ahead lanes of a run of ``scenario``."""
    image = scenario.data.get("star_sensor", {}).get("fidelity") == "image"
    if scenario.is_navigation:
        return NAVIGATION_IMAGE if image else ()
    return ATTITUDE_IMAGE if image else ATTITUDE_VECTOR
